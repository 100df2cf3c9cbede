/*
 * px_scene.h - many posed models: nearest model to a point, every model
 * within a distance, a tool (sphere, capsule or any model) against the
 * whole scene.
 *
 * A robot cell or a haptic workspace holds up to a fixed capacity of
 * models (any representations) whose poses change every cycle. Each
 * cycle the owner sets the poses (px_model_set_pose) and calls
 * px_scene_update(), which recomputes every world box and rebuilds a
 * small bounding-box hierarchy over them in memory taken at creation
 * (median splits, O(n log n), no allocation). Queries descend it nearest
 * box first and hand only the models whose boxes can still beat the best
 * answer to the exact point-to-model or model-to-model query, so their
 * cost grows with the models near the query, not with the model count.
 *
 * The scene does not own its models: they must outlive it, and
 * px_scene_free() leaves them alone.
 *
 * Memory and real-time rules: px_scene_create/px_scene_add/px_scene_free
 * are setup-time; px_scene_update and the queries are RT-safe (no heap,
 * bounded by the capacity; queries take a const scene and may run in
 * several threads, update must not race with them).
 */
#ifndef PX_SCENE_H
#define PX_SCENE_H

#include <stddef.h>

#include "px_base.h"
#include "px_model.h"
#include "px_pair.h"

#ifdef __cplusplus
extern "C" {
#endif

#define PX_SCENE_MAX_CAPACITY 65536

struct px_scene; /* opaque */

/* One answer: which model, how far, where. */
struct px_scene_hit {
	int model;          /* id from px_scene_add() */
	/* signed: point queries on closed models, and tool queries whose
	 * pair overlaps (-penetration depth, see px_pair.h) */
	double distance;
	px_vec3 point;      /* on the model (world) */
	px_vec3 tool_point; /* on the tool (tool queries), else the query point */
	int feature_index;  /* px_model_result.index of the model */
	int intersecting;   /* tool queries: the tool touches the model */
	int local_only;     /* tool queries: may be only a local minimum */
};

/* A scene for up to capacity models (1..PX_SCENE_MAX_CAPACITY).
 * Returns PX_OK, PX_E_INVAL, PX_E_RANGE, PX_E_NOMEM. Setup only. */
PX_API int px_scene_create(size_t capacity, struct px_scene **out);
/* Release the scene (not its models). NULL is a no-op. */
PX_API void px_scene_free(struct px_scene *s);

/* Add a model (not owned); *id (may be NULL) gets its index 0, 1, ...
 * Call px_scene_update() before querying. Returns PX_OK, PX_E_INVAL,
 * PX_E_NOSPC (capacity reached). Setup only. */
PX_API int px_scene_add(struct px_scene *s, struct px_model *m, int *id);

/* Number of models. @note RT-safe. */
PX_API size_t px_scene_count(const struct px_scene *s);

/* Refresh world boxes from the models' current poses and rebuild the
 * hierarchy. Returns PX_OK or PX_E_INVAL. @note RT-safe. */
PX_API int px_scene_update(struct px_scene *s);

/*
 * Nearest model to p (the smallest signed distance: a point inside a
 * closed model is nearest to it). Only models within max_dist count
 * (INFINITY for all). Returns 1 with *hit filled, 0 when no model is
 * within max_dist, PX_E_INVAL, PX_E_NAN, PX_E_STATE (not updated since
 * the last add). @note RT-safe.
 */
PX_API int px_scene_nearest(const struct px_scene *s, px_vec3 p,
			    double max_dist, struct px_scene_hit *hit);

/*
 * Every model whose distance to p is at most dist (dist >= 0), in no
 * particular order. Up to cap hits are written; *n_found (may be NULL)
 * gets the number found, which may exceed cap: then the return is
 * PX_E_NOSPC (the first cap are valid). Returns the count found (>= 0)
 * or PX_E_INVAL, PX_E_NAN, PX_E_STATE, PX_E_NOSPC. @note RT-safe.
 */
PX_API int px_scene_within(const struct px_scene *s, px_vec3 p, double dist,
			   struct px_scene_hit *hits, size_t cap,
			   size_t *n_found);

/*
 * A tool model (at its own current pose; it need not belong to the
 * scene, and if it does, it is skipped) against every scene model whose
 * distance is at most max_dist, each through px_pair_distance() with
 * opt (may be NULL). Spheres and convex tools take the exact paths.
 * Hits as for px_scene_within(). @note RT-safe.
 */
PX_API int px_scene_tool(const struct px_scene *s, const struct px_model *tool,
			 double max_dist, const struct px_pair_opts *opt,
			 struct px_scene_hit *hits, size_t cap, size_t *n_found);

#ifdef __cplusplus
}
#endif

#endif
