/*
 * px_model.h - one point-to-model distance query for every representation.
 *
 * Users bring what they have: NURBS surfaces from CAD, STL meshes of robot
 * links, scanned point clouds, simple primitives. Each representation
 * implements a single operation, "closest point of the model to a point
 * given in the model's own frame", behind a const table of function
 * pointers (struct px_model_ops). Everything built on top (model-to-model
 * distance by alternating projections, scenes) only talks to this table,
 * so the number of distance routines grows linearly with the number of
 * representations (Johnson and Cohen, "Unified distance queries in a
 * heterogeneous model environment", 2004).
 *
 * A model handle carries a rigid pose (model frame to world frame) that
 * may change every cycle: a query transforms the point into the model
 * frame and the answer back to the world frame; the geometry and its
 * acceleration structures are never touched after setup.
 *
 * Results (struct px_model_result) are in the world frame. The distance is
 * signed for closed models (inside negative; penetration depth and
 * direction come out of the same query) and unsigned otherwise, which
 * is_signed says. direction is the unit gradient of that distance field:
 * query = point + distance * direction. Outside it points from the model
 * to the query point, inside it points outwards (the way to push the
 * point out), and on the surface it is the outward normal where one is
 * defined.
 *
 * Representations that can follow a moving point (NURBS, B-rep) also hand out
 * tracked streams (px_model_stream_create(), below): per-point state made
 * at setup whose answers are the same as a query's, at a fraction of the
 * cost when the point moves a little between them.
 *
 * Memory and real-time rules: creating a model (px_model_create and the
 * per-representation constructors) is setup-time and allocates; the
 * handle owns its implementation and px_model_free() releases both.
 * px_model_set_pose() and all queries are RT-safe: no allocation, no
 * locks, bounded work. Queries take a const model, so several threads
 * may query one model at once; px_model_set_pose() must not race with
 * queries of the same model (the owner of the cycle sets the pose, then
 * queries).
 */
#ifndef PX_MODEL_H
#define PX_MODEL_H

#include <stddef.h>
#include <stdint.h>

#include "px_base.h"
#include "px_math.h"

#ifdef __cplusplus
extern "C" {
#endif

/* What a model is made of. */
enum px_model_kind {
	PX_MODEL_PRIMITIVE = 1,
	PX_MODEL_MESH = 2,
	PX_MODEL_CLOUD = 3,
	PX_MODEL_NURBS = 4,
	PX_MODEL_CUSTOM = 5,
	PX_MODEL_BREP = 6 /* trimmed NURBS faces, edges, vertices (px_brep.h) */
};

/* The kind of feature the closest point lies on. */
enum px_feature {
	PX_FEATURE_NONE = 0,
	PX_FEATURE_FACE = 1,    /* triangle interior, primitive face/side */
	PX_FEATURE_EDGE = 2,    /* triangle edge, box edge, cylinder rim */
	PX_FEATURE_VERTEX = 3,  /* triangle vertex, box corner, cone apex */
	PX_FEATURE_POINT = 4,   /* a point (or ball) of a cloud */
	PX_FEATURE_CURVE = 5,   /* a NURBS curve */
	PX_FEATURE_SURFACE = 6  /* a NURBS surface */
};

/* Query flags. */
#define PX_QUERY_COHERENT 0x1u /* start from hint (last cycle's index) */
#define PX_QUERY_UNSIGNED 0x2u /* skip the sign even on closed models */

/* Model capability flags (px_model_caps()). */
#define PX_MODEL_CAP_SIGNED 0x1u    /* closed: inside gets negative distance */
#define PX_MODEL_CAP_EXACT 0x2u     /* every answer is the exact global one */
#define PX_MODEL_CAP_COHERENT 0x4u  /* uses the hint of coherent queries */
#define PX_MODEL_CAP_CONVEX 0x8u    /* the solid is convex (closed models) */

/* What a query asks, in the model frame (implementations see this). */
struct px_model_query {
	px_vec3 p;        /* query point, model frame */
	double max_dist;  /* report nothing farther than this (INFINITY: no bound) */
	int hint;         /* index from last cycle's result, or -1 */
	unsigned flags;   /* PX_QUERY_* */
};

/*
 * Answer of a point-to-model query. The model's ops fill it in the model
 * frame; px_model_query() turns point and direction into the world frame.
 */
struct px_model_result {
	double distance;   /* signed if is_signed (< 0 inside), else >= 0 */
	px_vec3 point;     /* closest point on the model */
	px_vec3 direction; /* unit: query = point + distance * direction */
	/* Which part of the model: triangle index (mesh), point index
	 * (cloud), face id (primitive, see px_prim.h), entity id (NURBS). */
	int index;
	/* Detail within index: the edge (0: v0v1, 1: v1v2, 2: v2v0) or the
	 * vertex (0..2) of a triangle, the NURBS piece; -1 when none. */
	int sub;
	int feature;       /* enum px_feature */
	/* Parameters where meaningful: barycentric weights of vertices 1
	 * and 2 (mesh), (u, v) of a NURBS surface, u of a curve (v = 0),
	 * primitive surface coordinates (px_prim.h); 0 otherwise. */
	double u, v;
	int is_signed;     /* distance carries a sign */
	int inside;        /* is_signed and the point is strictly inside */
	int iterations;    /* work spent: nodes visited, solver steps */
	/* 1 when the answer is proven to be the global closest point (within
	 * gap); 0 when a bound cut the search short. */
	int certified;
	double gap;        /* how much closer the true answer may be (>= 0) */
};

/* ---- tracked streams: declarations the ops table needs (API below) ---- */

/* Options of a tracked stream (px_model_stream_opts_default()). */
struct px_model_stream_opts {
	/* Compare the tracked answer with the global query every
	 * verify_every answers (0: never, the default in a loop); a
	 * disagreement re-initialises the tracked set and is counted. */
	int verify_every;
	/* Transition work of one answer, in cell solves (surfaces; default
	 * 4, 0: unbounded): more is answered by the global query and caught
	 * up over the following answers (px_strack_opts.max_solves). */
	int max_solves;
	/* 1 (default): while the point moves so fast that following its
	 * critical points costs more than the global query, answer with
	 * the global query (px_track_opts.cold_switch). */
	int cold_switch;
};

/* How one stream answer came about. */
struct px_model_stream_note {
	int source;  /* enum px_track_source (px_track.h) */
	int jumped;  /* the closest point jumped (another branch, entity or
		      * feature: a haptic renderer must not smooth across) */
	int n_crit;  /* live critical points followed; -1 while cold */
};

/* Counters of a stream since its creation. */
struct px_model_stream_stats {
	uint64_t queries;       /* answered (in range or not) */
	uint64_t tracked;       /* from the tracked critical points */
	uint64_t hot;           /* of which by the answering point alone */
	uint64_t global;        /* by the global query: over the work
				 * budget, catching up, re-initialised,
				 * outside the working volume */
	uint64_t cold;          /* by the global query, motion too fast */
	uint64_t jumps;         /* answers whose closest point jumped */
	uint64_t reinits;       /* tracked set rebuilt (anomalies, capacity) */
	uint64_t verifications, disagreements;
};

/*
 * One representation's implementation. Every function receives the impl
 * pointer given to px_model_create(). All but free must be RT-safe.
 */
struct px_model_ops {
	const char *name;          /* "sphere", "mesh", "cloud", ... */
	enum px_model_kind kind;
	/*
	 * Closest point of the model to q->p (model frame). Returns 1 and
	 * fills r (model frame) when a point within q->max_dist exists, 0
	 * when none does, a negative px_err on failure. Must honour
	 * PX_QUERY_UNSIGNED, may use q->hint when PX_QUERY_COHERENT is set
	 * (an out-of-range hint must be ignored, never trusted).
	 */
	int (*closest)(const void *impl, const struct px_model_query *q,
		       struct px_model_result *r);
	/* Bounding box of the model in its own frame (may be infinite, e.g.
	 * a half-space). */
	px_aabb (*aabb)(const void *impl);
	/* Bytes owned by the implementation. */
	size_t (*memory_bytes)(const void *impl);
	/* Release the implementation (setup-time, may free). */
	void (*free)(void *impl);
	/* Optional, for convex models (NULL otherwise): a point of the
	 * model farthest along dir (model frame; dir need not be unit, and
	 * a zero dir may give any point of the model). Used by the exact
	 * convex-pair distance (GJK). Must be RT-safe. */
	px_vec3 (*support)(const void *impl, px_vec3 dir);
	/* Optional pair for coherence caches (both or neither; NULL
	 * otherwise). Features are numbered by the model (any ints >= 0).
	 * closest_among: as closest, over the listed features only.
	 * collect: every feature within radius of p (model frame), written
	 * to idx; returns the count, or PX_E_NOSPC when more than cap.
	 * Both must be RT-safe. */
	int (*closest_among)(const void *impl, const struct px_model_query *q,
			     const int *idx, int n, struct px_model_result *r);
	int (*collect)(const void *impl, px_vec3 p, double radius, int *idx,
		       int cap);
	/* Optional tracked streams (see px_model_stream_create(); all four
	 * or none; NULL otherwise). stream_create builds the state of one
	 * moving point (setup: may allocate); stream_query answers as
	 * closest does, in the model frame, and fills note; stream_stats
	 * adds the state's counters; stream_free releases it. Query and
	 * stats must be RT-safe. */
	int (*stream_create)(const void *impl,
			     const struct px_model_stream_opts *o,
			     void **state);
	int (*stream_query)(const void *impl, void *state,
			    const struct px_model_query *q,
			    struct px_model_result *r,
			    struct px_model_stream_note *note);
	void (*stream_stats)(const void *state,
			     struct px_model_stream_stats *s);
	void (*stream_free)(void *state);
};

struct px_model; /* opaque handle */

/*
 * Wrap an implementation into a model handle with the identity pose.
 * ops must outlive the model (normally a static const table); impl is
 * owned by the model from now on, also on failure (ops->free(impl) is
 * called then). caps: PX_MODEL_CAP_* bits. Setup only (allocates).
 * Returns PX_OK, PX_E_INVAL (NULL ops/closest/aabb/out), PX_E_NOMEM.
 */
PX_API int px_model_create(const struct px_model_ops *ops, void *impl,
			   unsigned caps, struct px_model **out);

/* Release a model and its implementation. NULL is a no-op. */
PX_API void px_model_free(struct px_model *m);

/* Largest |coordinate| of a model's box in its own frame and of a pose's
 * translation (model units): squared distances of every query within
 * reach (1e150 beyond the box, see px_model_query) then stay finite. */
#define PX_MODEL_MAX_COORD 1e150

/*
 * Set the model-to-world pose. The pose is checked and its quaternion
 * renormalized (px_pose_sanitize); on error the pose is left unchanged.
 * Returns PX_OK, PX_E_INVAL, PX_E_NAN, PX_E_DEGENERATE, PX_E_RANGE (also
 * a translation beyond +-PX_MODEL_MAX_COORD). @note RT-safe.
 */
PX_API int px_model_set_pose(struct px_model *m, px_pose pose);

/* Current pose (identity for NULL). @note RT-safe. */
PX_API px_pose px_model_pose(const struct px_model *m);

/*
 * Closest point of the model to the world point p.
 * Returns 1 with *out filled (world frame); PX_E_INVAL for NULL
 * arguments, PX_E_NAN for a non-finite p, PX_E_RANGE when p lies more
 * than 1e150 model units outside the model's box or the distance
 * overflows (squared distances pass 1e300 there). @note RT-safe.
 */
PX_API int px_model_query(const struct px_model *m, px_vec3 p,
			  struct px_model_result *out);

/*
 * As px_model_query() with a distance bound, flags and a coherence hint.
 * max_dist >= 0 (INFINITY for none) bounds |distance|: returns 0 with
 * out->distance = INFINITY and out->index = -1 when nothing of the model
 * is that close. With PX_QUERY_COHERENT, hint is the index of last
 * cycle's result (the last closest triangle or point), which gives the
 * search an immediate upper bound; any hint value is safe (a wrong one
 * only costs time). Returns 1, 0, PX_E_INVAL (NULL, max_dist < 0 or NaN),
 * PX_E_NAN (non-finite p), PX_E_RANGE (as px_model_query()), or an
 * implementation's error. @note RT-safe.
 */
PX_API int px_model_query_ex(const struct px_model *m, px_vec3 p,
			     double max_dist, int hint, unsigned flags,
			     struct px_model_result *out);

/* ---- coherence cache ---------------------------------------------------------
 *
 * A point that moves a little each cycle (a haptic probe, a link point)
 * can skip the hierarchy most cycles: on a refill the cache records every
 * feature within R = d + 2 margin of the point (d its distance then);
 * later, with the point at distance m from that anchor, the best cached
 * feature at distance U is proven the global closest whenever U + m <= R
 * (any feature at most U away from the point is at most U + m <= R from
 * the anchor, hence cached). Otherwise the cache refills with a full
 * query. So every answer stays exact; the margin only trades refill
 * frequency against scan length. Models without closest_among/collect
 * fall back to hint-coherent queries.
 */
#define PX_MODEL_CACHE_CAP 64

/* Caller-owned state for one moving point against one model; plain
 * struct, members private (read the counters through the accessors). */
struct px_model_cache {
	const struct px_model *model_;
	px_vec3 anchor_;
	double radius_;
	double margin_;
	int n_;
	int last_;
	unsigned long queries_, refills_;
	int idx_[PX_MODEL_CACHE_CAP];
};

/* Reset a cache. margin_m > 0 fixes how far (model frame units) the
 * point may move before a refill; 0 chooses it from the distance at each
 * refill (half of it, at least 1e-3 of the model's box diagonal).
 * @note RT-safe. */
PX_API void px_model_cache_init(struct px_model_cache *c, double margin_m);

/*
 * As px_model_query(), through the cache c (which follows whichever model
 * it is used with: using it with another model refills it). Answers are
 * exact as from px_model_query(), except that among equidistant features
 * another may be reported. Returns 1, or px_model_query()'s errors.
 * @note RT-safe.
 */
PX_API int px_model_query_cached(const struct px_model *m, px_vec3 p,
				 struct px_model_cache *c,
				 struct px_model_result *out);

/* Queries answered and refills made through c. @note RT-safe. */
PX_API unsigned long px_model_cache_queries(const struct px_model_cache *c);
PX_API unsigned long px_model_cache_refills(const struct px_model_cache *c);

/* ---- tracked streams -----------------------------------------------------
 *
 * A point that moves a little each cycle (a haptic proxy, a tool tip)
 * can be followed instead of searched for: a stream keeps every critical
 * distance of the model from that point and detects where pairs of them
 * are born or die as the point moves (NURBS models: px_strack for
 * surfaces, px_track for curves alone; B-rep models: px_strack over the
 * faces' surfaces answering inside the trimmed domains, brep_stream.c),
 * so most answers cost a fraction
 * of a global query, and each is still the exact global closest point
 * (the same as px_model_query_ex(); where the tracked set cannot prove
 * it, the global query answers). The stream follows the point in the
 * model frame: the model's pose may change between answers.
 *
 * Memory and real-time rules: px_model_stream_create() allocates all of
 * the stream's memory (setup; for NURBS surfaces it may take a few
 * hundred milliseconds and some megabytes); px_model_stream_query() and
 * px_model_stream_get_stats() are RT-safe. One stream belongs to one
 * thread; several streams may follow one model.
 */
struct px_model_stream;

/* Defaults: verify_every 0, max_solves 4, cold_switch 1. */
PX_API void px_model_stream_opts_default(struct px_model_stream_opts *o);

/* PX_OK when o holds options a stream takes (verify_every >= 0,
 * max_solves >= 0, cold_switch 0 or 1), else PX_E_INVAL (also NULL). */
PX_API int px_model_stream_opts_check(const struct px_model_stream_opts *o);

/*
 * A stream following one point through model m (m must outlive it);
 * o may be NULL for defaults. Setup only. Returns PX_OK, PX_E_INVAL (NULL
 * m or out, bad options), PX_E_UNSUPPORTED (the representation cannot
 * track: use px_model_query_ex() with hints or a px_model_cache),
 * PX_E_NOMEM, or the tracker's errors.
 */
PX_API int px_model_stream_create(const struct px_model *m,
				  const struct px_model_stream_opts *o,
				  struct px_model_stream **out);

/* NULL is a no-op. Setup only. */
PX_API void px_model_stream_free(struct px_model_stream *s);

/*
 * Move the stream's point to p (world frame) and answer as
 * px_model_query_ex() (no hint: the stream is its own coherence):
 * returns 1 with out filled, 0 when the closest point is farther than
 * max_dist (the point is followed all the same), PX_E_INVAL (NULL,
 * max_dist < 0 or NaN), PX_E_NAN (p not finite: the stream is left as
 * it was), PX_E_RANGE, or an implementation's error. note (may be NULL)
 * says how the answer came about. @note RT-safe.
 */
PX_API int px_model_stream_query(struct px_model_stream *s, px_vec3 p,
				 double max_dist, unsigned flags,
				 struct px_model_result *out,
				 struct px_model_stream_note *note);

/* The stream's counters (zeroed for NULL). @note RT-safe. */
PX_API void px_model_stream_get_stats(const struct px_model_stream *s,
				      struct px_model_stream_stats *st);

/* Bounding box in the model frame / in the world frame (the model-frame
 * box transformed by the current pose). Empty box for NULL.
 * @note RT-safe. */
PX_API px_aabb px_model_local_aabb(const struct px_model *m);
PX_API px_aabb px_model_world_aabb(const struct px_model *m);
/* Oriented box in the world frame: the model-frame box under the pose.
 * @note RT-safe. */
PX_API px_obb px_model_world_obb(const struct px_model *m);

/* Kind, name, PX_MODEL_CAP_* bits, bytes owned (handle + geometry).
 * @note RT-safe. */
PX_API enum px_model_kind px_model_kind(const struct px_model *m);
PX_API const char *px_model_name(const struct px_model *m);
PX_API unsigned px_model_caps(const struct px_model *m);
PX_API size_t px_model_memory_bytes(const struct px_model *m);
/* Point of the model farthest along the world direction dir, in the
 * world frame. Returns PX_OK, PX_E_INVAL (NULL), PX_E_UNSUPPORTED (the
 * model has no support function: not convex or unbounded).
 * @note RT-safe. */
PX_API int px_model_support(const struct px_model *m, px_vec3 dir,
			    px_vec3 *out);

/* The implementation pointer and ops table (for representation-specific
 * accessors, which check the ops to know the model is theirs).
 * @note RT-safe. */
PX_API const void *px_model_impl(const struct px_model *m);
PX_API const struct px_model_ops *px_model_get_ops(const struct px_model *m);

#ifdef __cplusplus
}
#endif

#endif
