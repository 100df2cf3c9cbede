/*
 * px_param.h - parameter hand-off from a non-real-time thread to the
 * real-time cycle (gains, stiffness, model poses), never seen torn.
 *
 * A triple buffer: the writer fills a private back buffer and publishes
 * it with one atomic exchange; the reader (the cycle) takes the newest
 * published buffer with one atomic exchange when something new is there.
 * Neither side ever waits for the other, and the reader always sees a
 * whole parameter set as written by one px_param_write() call: never
 * part of one and part of another. Intermediate sets may be skipped when
 * the writer is faster than the cycle (the reader gets the newest).
 *
 * One writer thread and one reader thread (several writers must
 * serialise among themselves). The block is size bytes of plain data
 * (no pointers into the non-RT heap that the writer may free).
 *
 * Memory: three copies of the block from a setup-time arena.
 */
#ifndef PX_PARAM_H
#define PX_PARAM_H

#include <stddef.h>
#include <stdint.h>

#include "px_arena.h"
#include "px_base.h"

#ifdef __cplusplus
extern "C" {
#endif

struct px_param;

/*
 * Create a parameter block of size bytes (>= 1) in arena a, every copy
 * initialised from init (size bytes; NULL gives zeros).
 * Returns PX_OK, PX_E_INVAL or PX_E_NOSPC.
 */
PX_API int px_param_create(struct px_arena *a, size_t size, const void *init,
			   struct px_param **out);

/* Arena bytes px_param_create() needs (upper bound). */
PX_API size_t px_param_size(size_t size);

/*
 * Publish a new set: copy size bytes from src. Writer thread only.
 * Returns PX_OK or PX_E_INVAL.
 * @note RT-safe (wait-free) too, though meant for the non-RT side.
 */
PX_API int px_param_write(struct px_param *p, const void *src);

/*
 * The newest published set. Reader thread only. The pointer stays valid
 * and unchanged until this thread's next px_param_read(); *fresh (may be
 * NULL) is set to 1 when this call picked up a newer set, else 0.
 * @note RT-safe, wait-free.
 */
PX_API const void *px_param_read(struct px_param *p, int *fresh);

/* Sets published since creation. Any thread. @note RT-safe. */
PX_API uint64_t px_param_writes(const struct px_param *p);

#ifdef __cplusplus
}
#endif

#endif
