/*
 * px_dist.h - global minimum distance from a point to a set of NURBS
 * curves and surfaces (the distance core).
 *
 * A model is prepared once from any number of curve and surface
 * entities; their union is what a query measures against. Preparation follows the
 * knowledge-guided scheme: each entity's parametrization factor
 * pf = (Dmax - Dmin) / Dmax (from derivative magnitudes) picks the
 * decomposition tolerance and jitter from a table; the entity is cut by
 * nearly uniform parameter stepping, at every knot and at cusps (vanishing
 * derivative) into rational Bezier pieces whose control-net boxes are
 * guaranteed to contain them (surfaces: the same stepping along their
 * longest iso-curves in u and in v gives a grid of Bezier patches); every piece is pre-sampled (1 % of the arc
 * length by default); and the pieces are binned by their boxes into a
 * uniform grid whose cells hold a fixed number of references (15 by
 * default) with overflow moved to a spill table at setup.
 *
 * A query sends a cubic wave of cells out from the query point: pieces
 * met for the first time (epoch stamps, nothing is cleared per query) are
 * bounded below by their boxes and above by their samples, and the wave
 * stops once the best sample distance is no larger than the distance to
 * every cell not yet reached. Every piece whose lower bound is still below
 * the best (axis-aligned box, then an oriented box around its control
 * net, tight for the nearly flat neighbours of the foot point) is then
 * solved exactly
 * by px_cpiece_closest() or px_spiece_closest(), which prove where the
 * piece's minimum lies instead of trusting one Newton start.
 * Open ends, C0 corners, closed-curve seams and cusps are piece end points
 * and so always candidates; no parameter wraps across a seam. A surface
 * also contributes its boundary curves (the four domain edges that do not
 * collapse to a point, and every interior C0 crease) as curve pieces, so
 * minima on a patch boundary, at corners and on creases are found by the
 * curve solver while the patch solver looks for interior minima only.
 *
 * Memory and real-time rules: px_dist_model_create() allocates once (one
 * block whose size px_dist_model_info() reports) and may take long; after
 * it, px_dist_query() and px_dist_query_batch() use only that block, never
 * allocate, lock or print, and every loop in them has a bound. A model
 * holds one query workspace for px_dist_query(), so those calls on one
 * model must not run concurrently; threads that query the same model at
 * once each use their own workspace (px_dist_ws_create(),
 * px_dist_query_ws()), the model itself is then only read.
 */
#ifndef PX_DIST_H
#define PX_DIST_H

#include <stddef.h>

#include "px_base.h"
#include "px_math.h"
#include "px_nurbs.h"

#ifdef __cplusplus
extern "C" {
#endif

#define PX_DIST_CELL_CAP_DEFAULT 15

enum px_dist_kind { PX_DIST_CURVE = 0, PX_DIST_SURFACE = 1 };

struct px_dist_opts {
	/* Decomposition piece length as a fraction of the arc length and
	 * the jitter factor (lower bound / upper bound); 0 picks both from
	 * the parametrization-factor table (paper table in dist_decomp.c). */
	double decomp_tol;
	double jitter;
	/* Pre-sample spacing as a fraction of the arc length (curve pieces
	 * take 2 to 64 samples, patches 2x2 to 4x4: samples only give the
	 * wave its first upper bound and the best piece its Newton start;
	 * the piece solvers prove the rest, so the cap costs no correctness.
	 * Denser caps solve the same pieces and only add sample scans; the
	 * paper's 1 % (about 26x26 per patch) would scan hundreds of
	 * samples per visited piece). */
	double sample_tol;
	/* References a grid cell holds before spilling. */
	int cell_cap;
	/* Upper bound on grid cells (memory); the cell size grows to fit. */
	long max_cells;
	/* Upper bound on pieces per entity. */
	int max_pieces_per_entity;
};

/* Defaults: table-driven tolerance, 1 % sampling, 15 per cell,
 * 2^18 cells, 4096 pieces per entity. */
PX_API void px_dist_opts_default(struct px_dist_opts *o);

struct px_dist_result {
	double dist;     /* distance, metres (model units) */
	px_vec3 point;   /* closest point on the model */
	double u, v;     /* parameter(s) of the closest point (v = 0: curve) */
	int entity;      /* index of the entity: curves first, then surfaces */
	int kind;        /* PX_DIST_CURVE or PX_DIST_SURFACE */
	int piece;       /* index of the piece within the model */
	px_vec3 dir;     /* unit vector from point to the query; zero when
			  * the query lies on the model */
	int iters;       /* root-refinement iterations spent */
	int pieces_solved;
	int cells_visited;
	/* 1 when the answer is proved to be the global minimum to rounding;
	 * 0 when a work bound cut the proof short, with gap bounding how far
	 * below dist the true minimum could be. */
	int certified;
	double gap;
};

struct px_dist_entity_info {
	int kind;           /* PX_DIST_CURVE or PX_DIST_SURFACE */
	double pf;          /* parametrization factor (max over u and v) */
	double tol, jitter; /* decomposition settings used */
	double arc_length;  /* approximate */
	int first_piece, n_pieces; /* own pieces: curve pieces or patches */
	int n_boundary_pieces;     /* surfaces: curve pieces of edges/creases */
	int closed;         /* curves: end points coincide; surfaces: bit 0
			     * closed in u, bit 1 closed in v */
	int n_breaks;       /* interior C0 knots (surfaces: both directions) */
	int n_cusps;        /* interior points of vanishing derivative */
	int n_collapsed;    /* surfaces: domain edges collapsed to a point */
	/* Knowledge step: enum px_recog_kind (px_recog.h) when the entity is
	 * exactly a primitive answered in closed form, 0 otherwise; then the
	 * proved bound on the entity's distance from that primitive. */
	int shape;
	double hausdorff;
};

struct px_dist_info {
	int n_entities, n_pieces, n_samples;
	int n_curve_pieces, n_patches;
	int grid[3];
	double cell_size;
	long cells, spill;
	size_t bytes; /* everything the model holds */
	px_aabb bounds;
};

struct px_dist_model;

/*
 * Prepare a model from n_curves curves and n_surfs surfaces (valid, e.g.
 * from px_nurbs_curve_init() / px_nurbs_surf_init(); everything needed is
 * copied, the caller's arrays may go away). Either array may be NULL when
 * its count is 0, but not both counts. Entity indices in results are
 * 0..n_curves-1 for the curves, then n_curves.. for the surfaces. opts
 * may be NULL for defaults. Setup only: allocates.
 * Returns PX_OK, PX_E_INVAL (NULL, no entity, bad options), PX_E_RANGE
 * (degree above PX_NURBS_MAX_DEGREE), PX_E_NOMEM, PX_E_NOSPC (an entity
 * needs more than max_pieces_per_entity pieces).
 */
PX_API int px_dist_model_create(const struct px_nurbs_curve *curves,
				int n_curves, const struct px_nurbs_surf *surfs,
				int n_surfs, const struct px_dist_opts *opts,
				struct px_dist_model **out);

/* NULL is a no-op. */
PX_API void px_dist_model_free(struct px_dist_model *m);

PX_API void px_dist_model_info(const struct px_dist_model *m,
			       struct px_dist_info *info);

/* Returns PX_OK or PX_E_RANGE for a bad index. */
PX_API int px_dist_entity_info(const struct px_dist_model *m, int entity,
			       struct px_dist_entity_info *info);

/*
 * Global minimum distance from p to the model. Returns PX_OK, PX_E_INVAL
 * (NULL), PX_E_NAN (p not finite; r untouched) or PX_E_RANGE (p more
 * than 1e150 model units outside the model's box, or a model so large
 * that squared distances overflow: no answer rather than an infinite
 * one). @note RT-safe.
 */
PX_API int px_dist_query(struct px_dist_model *m, px_vec3 p,
			 struct px_dist_result *r);

/* A query workspace for another thread (setup: allocates once, about
 * 16 bytes per piece). Returns PX_OK, PX_E_INVAL or PX_E_NOMEM. */
struct px_dist_ws;
PX_API int px_dist_ws_create(const struct px_dist_model *m,
			     struct px_dist_ws **out);
/* NULL is a no-op. */
PX_API void px_dist_ws_free(struct px_dist_ws *ws);

/* As px_dist_query() with the caller's workspace (made for this model);
 * the model is only read. @note RT-safe. */
PX_API int px_dist_query_ws(const struct px_dist_model *m,
			    struct px_dist_ws *ws, px_vec3 p,
			    struct px_dist_result *r);

/*
 * The same model behind the point-to-model interface (px_model.h), for
 * scenes and model-to-model queries: distance (signed for closed
 * surface shells, see below), entity index and
 * piece in index/sub, (u, v) of the foot point, certified flag and gap.
 * Up to four threads may query it at once (each borrows a workspace
 * without waiting; a fifth gets PX_E_BUSY). Setup only. Returns as
 * px_dist_model_create().
 */
struct px_model;
PX_API int px_nurbs_model_create(const struct px_nurbs_curve *curves,
				 int n_curves, const struct px_nurbs_surf *surfs,
				 int n_surfs, const struct px_dist_opts *opts,
				 struct px_model **out);

/*
 * Signed distance. A model of surfaces only that form a closed,
 * consistently oriented shell gets PX_MODEL_CAP_SIGNED: its answers carry
 * is_signed, negative distance and inside = 1 for points inside, with
 * direction pointing out of the solid. Setup checks (px_model_nurbs.c
 * tells the details): every edge sample of every surface edge that is
 * not a pole nor a seam lies within tol (1e-6 of the box diagonal) on an
 * edge of another surface, run in the opposite direction (consistent
 * orientation); the enclosed volume (divergence theorem, Gauss-Legendre)
 * is not zero and its sign fixes which side is out. Any model failing a
 * check stays unsigned and why says which check and where. Queries sign
 * by the normal at smooth foot points and by the angle-weighted
 * pseudo-normal on edges, corners, seams, creases and poles; a point on
 * the surface (distance 0) is outside.
 */
struct px_nurbs_sign_info {
	int closed;        /* 1: signed queries */
	double volume;     /* enclosed volume (closed only) */
	int edge_samples;  /* edge samples checked */
	double tol;        /* matching tolerance used */
	char why[160];     /* outcome in a sentence */
};

/* Fill info for a model from px_nurbs_model_create(). Returns PX_OK or
 * PX_E_INVAL (NULL, or not such a model). @note RT-safe. */
PX_API int px_nurbs_model_sign_info(const struct px_model *m,
				    struct px_nurbs_sign_info *info);

/* The surfaces of a model from px_nurbs_model_create() (its own copy, in
 * the model's frame; valid while the model lives): their count and, in
 * *surfs, the array; PX_E_INVAL for NULL or another kind of model (for
 * display, px_tess.h). @note RT-safe. */
PX_API int px_nurbs_model_surfaces(const struct px_model *m,
				   const struct px_nurbs_surf **surfs);

/* n queries; stops at the first error and returns it. @note RT-safe. */
PX_API int px_dist_query_batch(struct px_dist_model *m, const px_vec3 *p,
			       size_t n, struct px_dist_result *r);

#ifdef __cplusplus
}
#endif

#endif
