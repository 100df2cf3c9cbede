#include "px_alloc_count.h"

#include <errno.h>
#include <stdatomic.h>
#include <stddef.h>

static _Thread_local uint64_t thread_calls;
static _Atomic uint64_t total_calls;

static void count(void)
{
	thread_calls++;
	atomic_fetch_add_explicit(&total_calls, 1, memory_order_relaxed);
}

uint64_t px_alloc_count_thread(void)
{
	return thread_calls;
}

uint64_t px_alloc_count_total(void)
{
	return atomic_load_explicit(&total_calls, memory_order_relaxed);
}

#if defined(__SANITIZE_ADDRESS__)

/* The sanitizer owns malloc; it calls these hooks on every allocation
 * and every release made through it (realloc counts as both), in the
 * calling thread, whoever the caller is. Installed before main(). */
int __sanitizer_install_malloc_and_free_hooks(
	void (*malloc_hook)(const volatile void *, size_t),
	void (*free_hook)(const volatile void *));

static void on_malloc(const volatile void *p, size_t n)
{
	(void)p;
	(void)n;
	count();
}

static void on_free(const volatile void *p)
{
	(void)p;
	count();
}

__attribute__((constructor)) static void install_hooks(void)
{
	__sanitizer_install_malloc_and_free_hooks(on_malloc, on_free);
}

const char *px_alloc_count_mode(void)
{
	return "sanitizer hooks";
}

#else

/* glibc's own entry points, exported for exactly this purpose. */
extern void *__libc_malloc(size_t n);
extern void *__libc_calloc(size_t n, size_t m);
extern void *__libc_realloc(void *p, size_t n);
extern void __libc_free(void *p);
extern void *__libc_memalign(size_t a, size_t n);

void *malloc(size_t n);
void *calloc(size_t n, size_t m);
void *realloc(void *p, size_t n);
void free(void *p);
int posix_memalign(void **p, size_t a, size_t n);
void *aligned_alloc(size_t a, size_t n);
void *memalign(size_t a, size_t n);

void *malloc(size_t n)
{
	count();
	return __libc_malloc(n);
}

void *calloc(size_t n, size_t m)
{
	count();
	return __libc_calloc(n, m);
}

void *realloc(void *p, size_t n)
{
	count();
	return __libc_realloc(p, n);
}

void free(void *p)
{
	count();
	__libc_free(p);
}

int posix_memalign(void **p, size_t a, size_t n)
{
	void *r;
	count();
	if (a < sizeof(void *) || (a & (a - 1)))
		return EINVAL;
	r = __libc_memalign(a, n);
	if (!r && n)
		return ENOMEM;
	*p = r;
	return 0;
}

void *aligned_alloc(size_t a, size_t n)
{
	count();
	return __libc_memalign(a, n);
}

void *memalign(size_t a, size_t n)
{
	count();
	return __libc_memalign(a, n);
}

const char *px_alloc_count_mode(void)
{
	return "interpose";
}

#endif
