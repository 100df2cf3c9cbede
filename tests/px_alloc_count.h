/*
 * px_alloc_count.h - count heap calls so a test can prove that a region
 * of code (a running cycle, a query) allocates nothing.
 *
 * Counted: malloc, calloc, realloc, free, posix_memalign, aligned_alloc,
 * memalign. Counts are per thread, so a device reader thread that
 * allocates legitimately does not disturb the loop thread's count; a
 * process-wide total is kept as well.
 *
 * Two mechanisms, chosen at build time:
 *  - normal builds interpose the allocator symbols in the test binary and
 *    forward to glibc's __libc_* entry points, so every call in the
 *    process is seen, including those made inside libc or a device
 *    library on behalf of our code;
 *  - sanitizer builds (where the sanitizer runtime owns malloc) use
 *    -Wl,--wrap, which sees every call made from proxima's and the
 *    test's own object files.
 */
#ifndef PX_ALLOC_COUNT_H
#define PX_ALLOC_COUNT_H

#include <stdint.h>

/* Heap calls made by the calling thread since it started. */
uint64_t px_alloc_count_thread(void);
/* Heap calls made by all threads. */
uint64_t px_alloc_count_total(void);
/* Name of the mechanism in use ("interpose" or "wrap"). */
const char *px_alloc_count_mode(void);

/* Region helpers: begin returns the thread's count, end the difference. */
static inline uint64_t px_alloc_region_begin(void)
{
	return px_alloc_count_thread();
}

static inline uint64_t px_alloc_region_end(uint64_t begin)
{
	return px_alloc_count_thread() - begin;
}

#endif
