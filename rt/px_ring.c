#include "px_ring.h"

#include <stdatomic.h>
#include <string.h>

_Static_assert(ATOMIC_LLONG_LOCK_FREE == 2 && ATOMIC_LONG_LOCK_FREE == 2,
	       "px_ring needs lock-free 64-bit atomics");

#define CACHE_LINE 64
#define MAX_CAP ((size_t)1 << 30)
#define MAX_REC ((size_t)65536)

/* Producer and consumer fields on separate cache lines, each side with a
 * private copy of the other's index so that the shared line is read only
 * when the cached view says full (producer) or empty (consumer). */
struct px_ring {
	_Alignas(CACHE_LINE) _Atomic size_t head; /* next slot to write */
	size_t tail_cache;
	_Atomic uint64_t dropped;
	_Alignas(CACHE_LINE) _Atomic size_t tail; /* next slot to read */
	size_t head_cache;
	_Alignas(CACHE_LINE) size_t cap, mask, rec_size;
	unsigned char *data;
};

static size_t round_cap(size_t c)
{
	size_t p = 2;
	while (p < c)
		p <<= 1;
	return p;
}

size_t px_ring_size(size_t capacity, size_t record_size)
{
	if (capacity < 2 || capacity > MAX_CAP || record_size < 1 ||
	    record_size > MAX_REC)
		return 0;
	return sizeof(struct px_ring) + round_cap(capacity) * record_size +
	       2 * CACHE_LINE;
}

int px_ring_create(struct px_arena *a, size_t capacity, size_t record_size,
		   struct px_ring **out)
{
	struct px_ring *r;
	size_t cap;

	if (!out)
		return PX_E_INVAL;
	*out = NULL;
	if (!a || capacity < 2 || capacity > MAX_CAP || record_size < 1 ||
	    record_size > MAX_REC)
		return PX_E_INVAL;
	cap = round_cap(capacity);
	r = px_arena_alloc(a, sizeof(*r), CACHE_LINE);
	if (!r)
		return PX_E_NOSPC;
	r->data = px_arena_calloc(a, cap, record_size, CACHE_LINE);
	if (!r->data)
		return PX_E_NOSPC;
	atomic_init(&r->head, 0);
	atomic_init(&r->tail, 0);
	atomic_init(&r->dropped, 0);
	r->tail_cache = r->head_cache = 0;
	r->cap = cap;
	r->mask = cap - 1;
	r->rec_size = record_size;
	*out = r;
	return PX_OK;
}

int px_ring_push(struct px_ring *r, const void *rec)
{
	size_t h = atomic_load_explicit(&r->head, memory_order_relaxed);

	if (h - r->tail_cache >= r->cap) {
		r->tail_cache = atomic_load_explicit(&r->tail,
						     memory_order_acquire);
		if (h - r->tail_cache >= r->cap) {
			/* Only the producer writes this counter. */
			atomic_store_explicit(
				&r->dropped,
				atomic_load_explicit(&r->dropped,
						     memory_order_relaxed) + 1,
				memory_order_relaxed);
			return PX_E_NOSPC;
		}
	}
	memcpy(r->data + (h & r->mask) * r->rec_size, rec, r->rec_size);
	atomic_store_explicit(&r->head, h + 1, memory_order_release);
	return PX_OK;
}

int px_ring_pop(struct px_ring *r, void *rec)
{
	size_t t = atomic_load_explicit(&r->tail, memory_order_relaxed);

	if (t == r->head_cache) {
		r->head_cache = atomic_load_explicit(&r->head,
						     memory_order_acquire);
		if (t == r->head_cache)
			return PX_E_AGAIN;
	}
	memcpy(rec, r->data + (t & r->mask) * r->rec_size, r->rec_size);
	atomic_store_explicit(&r->tail, t + 1, memory_order_release);
	return PX_OK;
}

size_t px_ring_count(const struct px_ring *r_)
{
	struct px_ring *r = (struct px_ring *)r_;
	size_t t, h;

	if (!r)
		return 0;
	t = atomic_load_explicit(&r->tail, memory_order_acquire);
	h = atomic_load_explicit(&r->head, memory_order_acquire);
	/* Read tail first: head only grows, so h - t never underflows. */
	return h - t > r->cap ? r->cap : h - t;
}

uint64_t px_ring_pushed(const struct px_ring *r)
{
	return r ? atomic_load_explicit(&((struct px_ring *)r)->head,
					memory_order_relaxed)
		 : 0;
}

uint64_t px_ring_dropped(const struct px_ring *r)
{
	return r ? atomic_load_explicit(&((struct px_ring *)r)->dropped,
					memory_order_relaxed)
		 : 0;
}

size_t px_ring_capacity(const struct px_ring *r)
{
	return r ? r->cap : 0;
}

size_t px_ring_record_size(const struct px_ring *r)
{
	return r ? r->rec_size : 0;
}
