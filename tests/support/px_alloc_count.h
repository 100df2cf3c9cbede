/*
 * px_alloc_count.h - count heap calls so a test can prove that a region
 * of code (a running cycle, a query) allocates nothing.
 *
 * Counted: malloc, calloc, realloc, free, posix_memalign, aligned_alloc,
 * memalign. Counts are per thread, so a device reader thread that
 * allocates legitimately does not disturb the loop thread's count; a
 * process-wide total is kept as well.
 *
 * Two mechanisms, chosen at build time; both see every call in the
 * process, including those made inside libc or a device library on
 * behalf of our code:
 *  - normal builds interpose the allocator symbols in the binary and
 *    forward to glibc's __libc_* entry points;
 *  - AddressSanitizer builds (where the sanitizer runtime owns malloc)
 *    install its malloc/free hooks before main().
 * Used by the tests and by proxima-run (allocations after setup).
 */
#ifndef PX_ALLOC_COUNT_H
#define PX_ALLOC_COUNT_H

#include <stdint.h>

/* Heap calls made by the calling thread since it started. */
uint64_t px_alloc_count_thread(void);
/* Heap calls made by all threads. */
uint64_t px_alloc_count_total(void);
/* Name of the mechanism in use ("interpose" or "sanitizer hooks"). */
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
