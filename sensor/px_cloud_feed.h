/*
 * px_cloud_feed.h - point clouds handed from a producer thread to the
 * real-time cycle: a depth camera's frames (or a simulated one's,
 * px_depth_sim.h) become distance models outside the cycle and are
 * swapped in between two cycles with no allocation, lock or wait.
 *
 * The feed is a ring of slots, each holding one built cloud model
 * (px_cloud.h) and its time stamp. The producer (one thread, not real
 * time) builds a frame's model into a free slot (px_cloud_model:
 * allocation, the k-d tree) and publishes it by an atomic counter; the
 * consumer (the cycle) takes the newest published frame whose stamp is
 * not in its future, by atomics only, and says so by another atomic
 * counter. A slot is rebuilt only when its frame is older than the one
 * the consumer holds, so a model the cycle uses is never touched; the
 * old model is freed by the producer, in its own thread. Frames must be
 * published in order of their stamps. A producer that runs ahead (a
 * simulated sensor on the virtual clock) fills the ring and waits for
 * space; a consumer that takes nothing new keeps its frame, and a stale
 * stamp is the caller's to report (the runner feeds it to the loop's
 * watchdog as a device's feedback).
 *
 * A frame without points (nothing in view) stands as one point
 * PX_CLOUD_FEED_FAR_M away from the origin along z: a model the pairs
 * can measure, farther than any influence distance.
 *
 * A third party (one non-real-time thread, e.g. a view drawing the
 * cloud) may read the frame the consumer holds: px_cloud_feed_pin()
 * keeps its slot from being rebuilt until px_cloud_feed_unpin(), even
 * after the consumer has taken newer frames (the producer then waits
 * for space as for a held frame).
 *
 * Memory and real-time rules: create, free and publish allocate
 * (producer side and setup); take and the accessors are RT-safe
 * (atomics, at most PX_CLOUD_FEED_MAX_SLOTS steps). One producer thread,
 * one consumer thread and one pinning thread at a time.
 */
#ifndef PX_CLOUD_FEED_H
#define PX_CLOUD_FEED_H

#include <stddef.h>
#include <stdint.h>

#include "px_base.h"
#include "px_model.h"

#ifdef __cplusplus
extern "C" {
#endif

#define PX_CLOUD_FEED_MAX_SLOTS 16
#define PX_CLOUD_FEED_FAR_M 1e6

struct px_cloud_feed;

/* A feed of slots (3 .. PX_CLOUD_FEED_MAX_SLOTS) of clouds of at most
 * max_points points each (1 .. PX_CLOUD_MAX_POINTS), every point a ball
 * of radius_m >= 0 (px_cloud_model()). Returns PX_OK, PX_E_INVAL,
 * PX_E_RANGE, PX_E_NOMEM. Setup. */
PX_API int px_cloud_feed_create(int slots, size_t max_points, double radius_m,
				struct px_cloud_feed **out);
/* Frees every model: the consumer must be done with them. */
PX_API void px_cloud_feed_free(struct px_cloud_feed *f);

/* ---- producer side (one thread; allocates) ------------------------------- */

/* Frames that may be published now without waiting for the consumer. */
PX_API int px_cloud_feed_space(const struct px_cloud_feed *f);

/*
 * Build the cloud of n points (xyz world coordinates, 3 per point;
 * n <= max_points, 0: nothing in view) stamped stamp_ns (not before the
 * last published stamp) and publish it. Returns PX_OK, PX_E_AGAIN (no
 * free slot: the consumer holds or has yet to see every other one; try
 * again later), PX_E_INVAL, PX_E_RANGE (too many points, an earlier
 * stamp), or px_cloud_model()'s error (the frame is then dropped).
 */
PX_API int px_cloud_feed_publish(struct px_cloud_feed *f, const double *xyz, size_t n,
				 int64_t stamp_ns);

/* ---- consumer side (the cycle; RT-safe) ----------------------------------- */

/*
 * Take the newest published frame stamped at or before now_ns, when it
 * is newer than the one held: *model (its model: valid until a later
 * take returns 1 and the producer then reuses its slot) and *stamp_ns
 * (either may be NULL). Returns 1 when a newer frame was taken, 0 when
 * the held one stays (or none was ever published: *model NULL),
 * PX_E_INVAL. @note RT-safe.
 */
PX_API int px_cloud_feed_take(struct px_cloud_feed *f, int64_t now_ns,
			      struct px_model **model, int64_t *stamp_ns);

/* The held frame's model (NULL before the first take), stamp and point
 * count, and the counts of frames published and taken. @note RT-safe. */
struct px_cloud_feed_stats {
	uint64_t published, taken, refused; /* refused: PX_E_AGAIN answers */
	int64_t stamp_ns;
	size_t points;
};
PX_API struct px_model *px_cloud_feed_model(const struct px_cloud_feed *f);
PX_API void px_cloud_feed_stats(const struct px_cloud_feed *f,
				struct px_cloud_feed_stats *out);

/* ---- a reader beside the consumer (one thread, not real time) ----------- */

/*
 * Pin the frame the consumer holds: its model (NULL when none is held)
 * stays valid, and is not rebuilt by the producer, until
 * px_cloud_feed_unpin(); *frame (may be NULL) gets its number (1 for
 * the first frame published, growing with every newer frame taken; 0:
 * none), which tells a reader whether it has seen it. One pin at a time.
 */
PX_API struct px_model *px_cloud_feed_pin(struct px_cloud_feed *f, uint64_t *frame);
PX_API void px_cloud_feed_unpin(struct px_cloud_feed *f);

#ifdef __cplusplus
}
#endif

#endif
