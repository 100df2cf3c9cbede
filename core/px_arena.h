/*
 * px_arena.h - setup-time memory.
 *
 * Every proxima object that runs inside a control cycle takes all of its
 * memory here, once, while the application is setting up. An arena is a
 * bump allocator over one contiguous block: either a buffer the caller
 * owns (static storage, a locked page, shared memory) or a single
 * allocation made by px_arena_init_alloc(). Objects carve fixed-size
 * pieces out of it and never return them one by one; the whole arena is
 * released at shutdown.
 *
 * The real-time rule of the library: nothing a running cycle calls may
 * allocate or free heap memory (malloc, calloc, realloc, free,
 * posix_memalign, or anything that calls them). Capacities are chosen at
 * setup; when they are too small the call fails with PX_E_NOSPC rather
 * than growing. Functions that a cycle may call are marked
 * "@note RT-safe" in their headers; the test suite checks them with an
 * allocation counter (tests/support/px_alloc_count.h).
 *
 * px_arena_alloc() itself never touches the heap, so it may also be used
 * from a cycle on a scratch arena that is reset with px_arena_reset_to()
 * each cycle. The arena is not thread-safe: one owner at a time.
 */
#ifndef PX_ARENA_H
#define PX_ARENA_H

#include <stddef.h>
#include "px_base.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Default alignment: enough for any scalar type and for SSE/AVX loads. */
#define PX_ARENA_ALIGN 32u

/*
 * Plain struct so it can live in caller memory; members are private:
 * use the accessors.
 */
struct px_arena {
	unsigned char *base_; /* start of the block */
	size_t cap_;          /* bytes in the block */
	size_t used_;         /* bytes handed out (including padding) */
	size_t high_water_;   /* largest used_ ever seen */
	size_t failed_;       /* requests refused for lack of space */
	int owned_;           /* block came from px_arena_init_alloc() */
};

/*
 * Use a caller-owned buffer of cap bytes. The buffer must outlive the
 * arena. buf may be NULL only when cap is 0 (an arena that refuses every
 * request, useful to test PX_E_NOSPC paths).
 * Returns PX_OK or PX_E_INVAL.
 */
PX_API int px_arena_init(struct px_arena *a, void *buf, size_t cap);

/*
 * Make one allocation of cap bytes (zero-filled, so the pages are
 * touched now rather than faulted in during a cycle) and use it.
 * Setup only. Returns PX_OK, PX_E_INVAL or PX_E_NOMEM.
 */
PX_API int px_arena_init_alloc(struct px_arena *a, size_t cap);

/* Release the block if the arena owns it. Safe on a zeroed struct. */
PX_API void px_arena_fini(struct px_arena *a);

/*
 * Take size bytes aligned to align (a power of two, or 0 for
 * PX_ARENA_ALIGN). Returns NULL when the arena lacks space (counted in
 * px_arena_failed()) or on a bad alignment. size 0 returns a valid
 * unique-position pointer that must not be dereferenced.
 * @note RT-safe.
 */
PX_API void *px_arena_alloc(struct px_arena *a, size_t size, size_t align);

/* As px_arena_alloc() for n elements of elem_size, zero-filled, with an
 * overflow check on n * elem_size. @note RT-safe. */
PX_API void *px_arena_calloc(struct px_arena *a, size_t n, size_t elem_size,
			     size_t align);

/* Current fill level, to be passed to px_arena_reset_to(). @note RT-safe. */
PX_API size_t px_arena_mark(const struct px_arena *a);

/* Give back everything taken since mark (which must come from
 * px_arena_mark() on the same arena). @note RT-safe. */
PX_API void px_arena_reset_to(struct px_arena *a, size_t mark);

/* Bytes handed out now, largest ever, capacity, refused requests.
 * @note RT-safe. */
PX_API size_t px_arena_used(const struct px_arena *a);
PX_API size_t px_arena_high_water(const struct px_arena *a);
PX_API size_t px_arena_capacity(const struct px_arena *a);
PX_API size_t px_arena_failed(const struct px_arena *a);

#ifdef __cplusplus
}
#endif

#endif
