/*
 * px_scene.h - named, posed models (primitives, meshes, clouds, NURBS)
 * and the distance queries over them: the nearest surface to a point
 * (plain, coherent or tracked), every model within a distance, a tool
 * against the whole scene; the nearest query as the control module's
 * query interface; and the `scene` section of a config.
 *
 * Nearest: the smallest signed distance over the models (closed models
 * negative inside, open ones unsigned). An answer a model does not
 * certify is lowered by its gap (distance_m never farther from the
 * surface than the truth). Broad phase: each model's oriented box under
 * its pose bounds its distance; up to PX_SCENE_SMALL models are visited
 * in increasing bound, larger scenes descend a box hierarchy nearest
 * child first; far models cost one box test, far subtrees none.
 *
 * Models and poses: px_scene_add() gives the scene a model (freed with
 * it); px_scene_add_kept() lends one the caller keeps and frees. Poses
 * change through px_scene_set_pose() (seen by the next query: that
 * model's box and its ancestors' are refit) or on the model itself
 * followed by px_scene_update() (every box refreshed, the hierarchy
 * refit or rebuilt); after px_scene_add_kept() queries answer
 * PX_E_STATE until px_scene_update() has run.
 *
 * Memory: create() takes every byte of the capacity; tracking states
 * take their streams' memory at creation; queries use the stack.
 * Threads: queries only read the scene and may run in several threads
 * (hints and tracking states are per thread); poses and updates must not
 * race with queries. Real time: create, add, free, config loading and
 * tracking_create are setup-time; set_pose, update and every query are
 * RT-safe (no heap, no locks, bounded by the capacity).
 */
#ifndef PX_SCENE_H
#define PX_SCENE_H

#include <stdbool.h>
#include <stddef.h>

#include "px_base.h"
#include "px_math.h"
#include "px_model.h"
#include "px_pair.h"

#ifdef __cplusplus
extern "C" {
#endif

#define PX_SCENE_MAX_CAPACITY 65536 /* largest capacity */
#define PX_SCENE_SMALL 8            /* up to this many: no hierarchy walk */
#define PX_SCENE_HINT_MODELS 256    /* models that keep a coherence hint */
#define PX_SCENE_NAME_LEN 32

struct px_scene;
struct px_control_query;

/* An empty scene for up to capacity (1 .. PX_SCENE_MAX_CAPACITY) models.
 * Returns PX_OK, PX_E_INVAL, PX_E_RANGE (too large), PX_E_NOMEM. */
PX_API int px_scene_create(size_t capacity, struct px_scene **out);

/* Free the scene and the models it owns (not kept ones). NULL: no-op. */
PX_API void px_scene_free(struct px_scene *s);

/*
 * Add model m (its pose as set) under name (may be NULL; copied, up to
 * 31 bytes); the scene owns m from now on, also on failure (then m is
 * freed). Queries see it at once. Returns the model's index, PX_E_INVAL,
 * PX_E_NOSPC (capacity reached) or PX_E_RANGE (the model's box reaches
 * beyond +-PX_MODEL_MAX_COORD in its own frame; unbounded is fine).
 */
PX_API int px_scene_add(struct px_scene *s, struct px_model *m,
			const char *name);

/*
 * Add model m, which the caller keeps (it must outlive the scene and is
 * not freed by it); *id (may be NULL) gets its index. Call
 * px_scene_update() before the next query. Returns PX_OK or as
 * px_scene_add() (m is never freed).
 */
PX_API int px_scene_add_kept(struct px_scene *s, struct px_model *m,
			     int *id);

/* Number of models, model i (NULL for a bad index), its name ("" for a
 * bad index or none). @note RT-safe. */
PX_API size_t px_scene_count(const struct px_scene *s);
PX_API struct px_model *px_scene_model(const struct px_scene *s, size_t i);
PX_API const char *px_scene_name(const struct px_scene *s, size_t i);

/* Set the pose of model i, seen by the next query. Returns
 * px_model_set_pose()'s codes or PX_E_INVAL (bad index). @note RT-safe. */
PX_API int px_scene_set_pose(struct px_scene *s, size_t i, px_pose pose);

/* Refresh every box from the models' current poses and refit the
 * hierarchy (every 16th call, or after adds, rebuild it). Returns PX_OK
 * or PX_E_INVAL. @note RT-safe. */
PX_API int px_scene_update(struct px_scene *s);

/* One answer of any query. */
struct px_scene_hit {
	int model;           /* index, -1 when nothing in range */
	/* signed: the model's answer lowered by its gap when not certified
	 * (point queries); the pair's distance, -depth when overlapping
	 * (tool queries) */
	double distance_m;
	px_vec3 point;       /* on the model (world) */
	px_vec3 tool_point;  /* on the tool (tool queries), else the point */
	int feature_index;   /* px_model_result.index of the model */
	int intersecting;    /* inside or touching */
	int local_only;      /* may be only a local minimum (not certified) */
	struct px_model_result r; /* point queries: the model's whole answer */
	int models_queried;  /* nearest: narrow-phase queries made */
	/* tracked nearest only: the closest point jumped since the last
	 * answer (another model, or another branch of the same model) */
	int jumped;
};

/*
 * Nearest surface to p within max_distance_m (|distance| <= it; >= 0,
 * INFINITY for none). Returns 1 with *out filled, 0 when nothing lies in
 * range (out->model -1, distance INFINITY), PX_E_INVAL, PX_E_NAN,
 * PX_E_STATE or a model's error. @note RT-safe.
 */
PX_API int px_scene_nearest(const struct px_scene *s, px_vec3 p,
			    double max_distance_m, struct px_scene_hit *out);

/*
 * Every model whose (signed) distance to p is at most dist (>= 0), in no
 * particular order. Up to cap hits are written; *n_found (may be NULL)
 * gets the number found, which may exceed cap: then the return is
 * PX_E_NOSPC (the first cap are valid). Returns the count (>= 0),
 * PX_E_INVAL, PX_E_NAN, PX_E_STATE, PX_E_NOSPC. @note RT-safe.
 */
PX_API int px_scene_within(const struct px_scene *s, px_vec3 p, double dist,
			   struct px_scene_hit *hits, size_t cap,
			   size_t *n_found);

/*
 * A tool model (at its own pose; it need not belong to the scene and is
 * skipped if it does) against every model within max_dist, each through
 * px_pair_distance() with opt (may be NULL). Hits and returns as
 * px_scene_within(). @note RT-safe.
 */
PX_API int px_scene_tool(const struct px_scene *s, const struct px_model *tool,
			 double max_dist, const struct px_pair_opts *opt,
			 struct px_scene_hit *hits, size_t cap, size_t *n_found);

/* ---- coherent queries ---------------------------------------------
 *
 * A point that moves a little between queries finds its nearest feature
 * near last time's: each model's query starts from the feature it
 * answered last (PX_QUERY_COHERENT). Same answers; a stale hint only
 * costs time. Models past PX_SCENE_HINT_MODELS are queried without one.
 */
struct px_scene_hints {
	int index[PX_SCENE_HINT_MODELS];
	const struct px_scene *scene_; /* set by the control adapter */
};

/* Forget every hint (before first use, or after a jump). @note RT-safe. */
PX_API void px_scene_hints_reset(struct px_scene_hints *h);

/* As px_scene_nearest() through h (PX_E_INVAL also for NULL h). */
PX_API int px_scene_nearest_coherent(const struct px_scene *s, px_vec3 p,
				     double max_distance_m,
				     struct px_scene_hints *h,
				     struct px_scene_hit *out);

/* ---- tracked queries ----------------------------------------------
 *
 * One moving point followed through the scene: each model that can
 * track (NURBS, B-rep: px_model.h's streams) gets a stream, the others
 * hints.
 * Same exact answers as px_scene_nearest(); a model the broad phase
 * passes over catches up when next asked. Streams are made for the
 * models present at creation; later ones are queried with hints.
 */
struct px_scene_tracking;
struct px_model_stream_opts;
struct px_model_stream_stats;

/* Streams for the models of s (o NULL: the scene's settings). Setup.
 * Returns PX_OK, PX_E_INVAL, PX_E_NOMEM or a stream's error. */
PX_API int px_scene_tracking_create(const struct px_scene *s,
				    const struct px_model_stream_opts *o,
				    struct px_scene_tracking **out);
PX_API void px_scene_tracking_free(struct px_scene_tracking *t);

/* As px_scene_nearest() through t (made for s; else PX_E_INVAL);
 * out->jumped says whether the closest point jumped. @note RT-safe. */
PX_API int px_scene_nearest_tracked(const struct px_scene *s, px_vec3 p,
				    double max_distance_m,
				    struct px_scene_tracking *t,
				    struct px_scene_hit *out);

/* t's streams' counters summed into sum (zeroed for NULL t); returns the
 * number of models with a stream. @note RT-safe. */
PX_API int px_scene_tracking_stats(const struct px_scene_tracking *t,
				   struct px_model_stream_stats *sum);

/* The scene's tracking settings (the config's scene.tracking; new scene:
 * enabled, defaults). set: setup, o NULL for defaults; PX_OK or
 * PX_E_INVAL. get: 1 enabled, 0 not, PX_E_INVAL; o (may be NULL) gets
 * the options. */
PX_API int px_scene_set_tracking(struct px_scene *s, bool enabled,
				 const struct px_model_stream_opts *o);
PX_API int px_scene_get_tracking(const struct px_scene *s,
				 struct px_model_stream_opts *o);

/* ---- the control module's query ------------------------------------
 *
 * q answers with the nearest surface (two_sided: the model is unsigned;
 * uncertified answers lowered, as px_control.h requires). Unsigned
 * models are thin shells the haptic proxy never crosses. Plain, through
 * hints h (reset here) or tracking t; s, h, t must outlive q's use, and
 * one thread uses a coherent or tracked q. Returns PX_OK or PX_E_INVAL.
 */
PX_API int px_scene_control_query(const struct px_scene *s,
				  struct px_control_query *q);
PX_API int px_scene_control_query_coherent(const struct px_scene *s,
					   struct px_scene_hints *h,
					   struct px_control_query *q);
PX_API int px_scene_control_query_tracked(const struct px_scene *s,
					  struct px_scene_tracking *t,
					  struct px_control_query *q);

/* ---- configuration (setup time) --------------------------------- */

struct px_config;
struct px_config_diag;
struct px_config_schema;

/*
 * The scene described by cfg->scene (absent: empty, capacity 1). Files
 * are read relative to the config file's directory. Problems go to diag
 * as "file:line:column: scene.key: what", and *out is then NULL.
 * Returns PX_OK, PX_E_PARSE, PX_E_NOMEM, PX_E_INVAL.
 */
PX_API int px_scene_config_load(const struct px_config *cfg,
				struct px_scene **out,
				struct px_config_diag *diag);

/* A config's model with a scale other than 1 is the file's model seen
 * at that scale about its origin: *inner gets the file's model and the
 * scale is returned; any other model is its own inner at scale 1 (for
 * drawing it, px_tess.h). @note RT-safe. */
PX_API double px_scene_model_scale(const struct px_model *m,
				   const struct px_model **inner);

/* Schema of the scene section (tools, the docs check). */
PX_API const struct px_config_schema *px_scene_config_schema(void);

#ifdef __cplusplus
}
#endif

#endif
