/*
 * px_world.h - the world an application's loop lives in: the `scene`
 * section of a proxima config turned into a fixed list of named, posed
 * models (primitives, meshes, point clouds, NURBS), the nearest surface
 * to a point with a broad phase, and that answer as the control module's
 * query interface. (geom/scene/px_scene.h is the general scene with a
 * hierarchy, within-distance and tool queries; this module is the
 * runner's view of a config. Building it on px_scene is planned.)
 *
 * Nearest query. The answer is the smallest signed distance over the
 * models (closed models: negative inside; open ones, e.g. NURBS
 * surfaces and open meshes, unsigned). For a union of solids this is the
 * exact distance outside every solid and never more than the true
 * penetration depth inside (any point of the union's boundary is outside
 * every solid). Broad phase: each model's world oriented box (its local
 * bounding box under the current pose) gives a lower bound of its
 * distance; models are visited in increasing bound and the search stops
 * at the first bound not below the best distance found, so far models
 * cost one box test each. A point inside a model's box has bound
 * -infinity for closed models (it may be inside) and 0 for open ones.
 *
 * Coherent queries. A point that moves a little between queries (a
 * haptic proxy, a point on a robot link) finds its nearest feature near
 * last time's: px_world_nearest_coherent() passes each model the feature
 * it answered last (struct px_world_hints, caller-owned) as the start of
 * its search (px_model_query_ex with PX_QUERY_COHERENT). The answer is
 * the same global nearest surface; a stale hint only costs time.
 *
 * Tracked queries. px_world_nearest_tracked() follows one moving point
 * with a stream per NURBS model (px_model.h: every critical distance
 * followed, pairs born and dying detected) and hints for the rest: the
 * same exact answer at a fraction of the cost, and a word on whether the
 * closest point jumped. The loop's haptic renderer uses it.
 *
 * As the control module's query (px_world_control_query): the hit is
 * the nearest answer with two_sided = the model is unsigned. Answers a
 * model does not certify (a bound cut its search short) report distance
 * - gap, so the reported |distance| never exceeds the true one, as
 * px_control.h requires. Unsigned models (NURBS surfaces, open meshes,
 * clouds) are thin shells to the haptic proxy: it never crosses them,
 * whichever side it started on, because every proxy step is shorter
 * than the distance at its start.
 *
 * Memory and real-time rules: px_world_create() takes one allocation of
 * the fixed capacity; px_world_add() takes ownership of a model. Adding,
 * loading and freeing are setup-time. px_world_nearest(), the control
 * adapter's callback and px_world_set_pose() are RT-safe (no allocation,
 * no locks, bounded by the capacity and the models' own bounds). Queries
 * only read the scene; poses must not change while another thread
 * queries.
 */
#ifndef PX_WORLD_H
#define PX_WORLD_H

#include <stdbool.h>
#include <stddef.h>

#include "px_base.h"
#include "px_math.h"
#include "px_model.h"

#ifdef __cplusplus
extern "C" {
#endif

#define PX_WORLD_MAX_MODELS 256 /* largest capacity */
#define PX_WORLD_NAME_LEN 32

struct px_world;
struct px_control_query;

/*
 * An empty scene for up to capacity (1 .. PX_WORLD_MAX_MODELS) models.
 * Setup only. Returns PX_OK, PX_E_INVAL, PX_E_NOMEM. Free with
 * px_world_free().
 */
PX_API int px_world_create(size_t capacity, struct px_world **out);

/* Free the scene and every model it owns. NULL is a no-op. */
PX_API void px_world_free(struct px_world *s);

/*
 * Add model m (its pose as set) under name (may be NULL; copied, up to
 * 31 bytes). The scene owns m from now on, also on failure (then m is
 * freed). Setup only. Returns the model's index, PX_E_INVAL,
 * PX_E_NOSPC (capacity reached) or PX_E_RANGE (the model's box reaches
 * beyond +-PX_MODEL_MAX_COORD in its own frame: an unbounded model, as a
 * plane, is fine).
 */
PX_API int px_world_add(struct px_world *s, struct px_model *m,
			const char *name);

/* Number of models, model i (NULL for a bad index), its name ("" for a
 * bad index). @note RT-safe. */
PX_API size_t px_world_count(const struct px_world *s);
PX_API struct px_model *px_world_model(const struct px_world *s, size_t i);
PX_API const char *px_world_name(const struct px_world *s, size_t i);

/* Set the pose of model i. Returns px_model_set_pose()'s codes or
 * PX_E_INVAL for a bad index. @note RT-safe. */
PX_API int px_world_set_pose(struct px_world *s, size_t i, px_pose pose);

/* Nearest answer. */
struct px_world_hit {
	int model;                   /* index, -1 when nothing in range */
	struct px_model_result r;    /* that model's answer, world frame */
	/* r.distance, lowered by r.gap when not certified (see above) */
	double distance_m;
	int models_queried;          /* narrow-phase queries made */
	/* Tracked queries only (px_world_nearest_tracked), 0 otherwise:
	 * the closest point jumped since the last answer (another model,
	 * or another branch of the same model's distance). */
	int jumped;
};

/*
 * Nearest surface to the world point p within max_distance_m (>= 0,
 * INFINITY for none). Returns 1 with *out filled, 0 when nothing lies
 * within range (out->model = -1, distance INFINITY), PX_E_INVAL (NULL,
 * bad range), PX_E_NAN (p not finite) or a model's error.
 * @note RT-safe.
 */
PX_API int px_world_nearest(const struct px_world *s, px_vec3 p,
			    double max_distance_m, struct px_world_hit *out);

/* Coherence state of one stream of queries: the feature index each
 * model answered last (-1 none). Plain struct, caller-owned; used by one
 * thread at a time. */
struct px_world_hints {
	int index[PX_WORLD_MAX_MODELS];
	const struct px_world *world_; /* set by px_world_control_query_coherent */
};

/* Forget every hint (before first use, or after a jump). @note RT-safe. */
PX_API void px_world_hints_reset(struct px_world_hints *h);

/*
 * As px_world_nearest(), each model's query starting from h's hint for
 * it; h is updated with the answers. Same answer as px_world_nearest()
 * for any hints. Returns as px_world_nearest() (PX_E_INVAL also for a
 * NULL h). @note RT-safe.
 */
PX_API int px_world_nearest_coherent(const struct px_world *s, px_vec3 p,
				     double max_distance_m,
				     struct px_world_hints *h,
				     struct px_world_hit *out);

/*
 * Fill q so that the control module queries scene s (point callback;
 * segment left NULL: the control module's certified bisection over
 * point queries is used). s must outlive q's use. The callback is
 * RT-safe. Returns PX_OK or PX_E_INVAL.
 */
PX_API int px_world_control_query(const struct px_world *s,
				  struct px_control_query *q);

/*
 * As px_world_control_query(), with coherent queries through h (reset
 * here; it must outlive q's use, and one thread at a time uses q): for
 * the loop's renderer or avoidance, whose queries follow a moving
 * point. Returns PX_OK or PX_E_INVAL.
 */
PX_API int px_world_control_query_coherent(const struct px_world *s,
					   struct px_world_hints *h,
					   struct px_control_query *q);

/* ---- tracked queries ----------------------------------------------
 *
 * One moving point (a haptic proxy or tool tip) followed through the
 * scene: every model that can track (NURBS models: px_model.h's
 * streams) gets a stream that follows the point's critical distances
 * instead of searching from scratch, the others are queried with
 * coherence hints. Answers are the same exact nearest surface as
 * px_world_nearest(); a model the broad phase passes over is not
 * followed that time and catches up when next asked (a longer step
 * costs more work, never a wrong answer).
 *
 * Memory and real-time rules: px_world_tracking_create() allocates every
 * stream (setup; NURBS surfaces take some milliseconds and megabytes
 * each); the queries and the statistics are RT-safe. One thread uses a
 * tracking state; the world must outlive it and keep its models (models
 * added later are queried with hints).
 */
struct px_world_tracking;
struct px_model_stream_opts;
struct px_model_stream_stats;

/*
 * Streams for the models of s (o: px_model_stream_opts, NULL for the
 * scene's own, px_world_get_tracking(): by default verification off, as
 * in a loop). Models whose representation
 * cannot track are not an error. Returns PX_OK, PX_E_INVAL, PX_E_NOMEM
 * or a stream's error (then *out is NULL).
 */
PX_API int px_world_tracking_create(const struct px_world *s,
				    const struct px_model_stream_opts *o,
				    struct px_world_tracking **out);

/* NULL is a no-op. Setup only. */
PX_API void px_world_tracking_free(struct px_world_tracking *t);

/*
 * As px_world_nearest(), following the point through t (made for s):
 * out->jumped says whether the closest point jumped. Returns as
 * px_world_nearest() (PX_E_INVAL also for a NULL t or one made for
 * another world). @note RT-safe.
 */
PX_API int px_world_nearest_tracked(const struct px_world *s, px_vec3 p,
				    double max_distance_m,
				    struct px_world_tracking *t,
				    struct px_world_hit *out);

/*
 * Counters of t's streams, summed (zeroed for NULL); returns the number
 * of models followed by a stream. @note RT-safe.
 */
PX_API int px_world_tracking_stats(const struct px_world_tracking *t,
				   struct px_model_stream_stats *sum);

/*
 * The scene's tracking settings (the config's scene.tracking; a new
 * world: enabled, defaults): whether a loop should follow its point with
 * tracked queries, and the streams' options. set: setup only, o NULL for
 * the defaults; PX_OK or PX_E_INVAL. get: 1 when enabled, 0 when not,
 * PX_E_INVAL; o (may be NULL) gets the options.
 */
PX_API int px_world_set_tracking(struct px_world *s, bool enabled,
				 const struct px_model_stream_opts *o);
PX_API int px_world_get_tracking(const struct px_world *s,
				 struct px_model_stream_opts *o);

/*
 * As px_world_control_query_coherent(), with tracked queries through t:
 * the renderer's queries follow one moving point. Returns PX_OK or
 * PX_E_INVAL.
 */
PX_API int px_world_control_query_tracked(const struct px_world *s,
					  struct px_world_tracking *t,
					  struct px_control_query *q);

/* ---- configuration (setup time) --------------------------------- */

struct px_config;
struct px_config_diag;
struct px_config_schema;

/*
 * Build the scene described by cfg->scene (absent: an empty scene with
 * capacity 1). Model files are read relative to the directory of the
 * config file (absolute paths as given). Problems (keys, values, files
 * that cannot be read, geometry errors) are appended to diag as
 * "file:line:column: scene.key: what", and *out is then NULL.
 * Returns PX_OK, PX_E_PARSE (problems found), PX_E_NOMEM, PX_E_INVAL.
 */
PX_API int px_world_config_load(const struct px_config *cfg,
				struct px_world **out,
				struct px_config_diag *diag);

/* Schema of the scene section (for tools and the docs check). */
PX_API const struct px_config_schema *px_world_config_schema(void);

#ifdef __cplusplus
}
#endif

#endif
