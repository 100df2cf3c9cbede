/*
 * px_ring.h - lock-free single-producer single-consumer ring of
 * fixed-size records, for handing telemetry (and faults) from the
 * real-time cycle to a non-real-time thread.
 *
 * The producer is the cycle; it never blocks and never waits: when the
 * ring is full, the record being pushed (the newest) is dropped and
 * counted, so what the consumer sees is always a gap-free prefix of the
 * stream followed by counted losses, never a mix of old and new. The
 * consumer may lag arbitrarily.
 *
 * Exactly one thread pushes and exactly one thread pops at a time (they
 * may be the same thread). Records are copied in and out with memcpy.
 *
 * Memory: one block from a setup-time arena (px_ring_size() bytes); the
 * arena owns it. Capacity is rounded up to a power of two.
 */
#ifndef PX_RING_H
#define PX_RING_H

#include <stddef.h>
#include <stdint.h>

#include "px_arena.h"
#include "px_base.h"

#ifdef __cplusplus
extern "C" {
#endif

struct px_ring;

/*
 * Create a ring of at least capacity records (2 .. 2^30) of record_size
 * bytes (1 .. 65536) in arena a.
 * Returns PX_OK, PX_E_INVAL (NULL, size out of range) or PX_E_NOSPC.
 */
PX_API int px_ring_create(struct px_arena *a, size_t capacity,
			  size_t record_size, struct px_ring **out);

/* Arena bytes px_ring_create() needs (upper bound). */
PX_API size_t px_ring_size(size_t capacity, size_t record_size);

/*
 * Copy one record (record_size bytes from rec) in. Producer only.
 * Returns PX_OK, or PX_E_NOSPC when full (the record is dropped and
 * counted in px_ring_dropped()).
 * @note RT-safe, wait-free.
 */
PX_API int px_ring_push(struct px_ring *r, const void *rec);

/*
 * Copy the oldest record out into rec (record_size bytes). Consumer only.
 * Returns PX_OK or PX_E_AGAIN when empty.
 * @note RT-safe, wait-free.
 */
PX_API int px_ring_pop(struct px_ring *r, void *rec);

/* Records waiting now (exact from either side's thread when the other
 * is idle; otherwise a value that was true at some instant).
 * @note RT-safe. */
PX_API size_t px_ring_count(const struct px_ring *r);

/* Records accepted and records dropped since creation. Any thread.
 * @note RT-safe. */
PX_API uint64_t px_ring_pushed(const struct px_ring *r);
PX_API uint64_t px_ring_dropped(const struct px_ring *r);

PX_API size_t px_ring_capacity(const struct px_ring *r);
PX_API size_t px_ring_record_size(const struct px_ring *r);

#ifdef __cplusplus
}
#endif

#endif
