/*
 * px_dist.h - global minimum distance from a point to a set of NURBS
 * curves (the distance core).
 *
 * A model is prepared once from any number of curve entities; their union
 * is what a query measures against. Preparation follows the
 * knowledge-guided scheme: each entity's parametrization factor
 * pf = (Dmax - Dmin) / Dmax (from derivative magnitudes) picks the
 * decomposition tolerance and jitter from a table; the entity is cut by
 * nearly uniform parameter stepping, at every knot and at cusps (vanishing
 * derivative) into rational Bezier pieces whose control-net boxes are
 * guaranteed to contain them; every piece is pre-sampled (1 % of the arc
 * length by default); and the pieces are binned by their boxes into a
 * uniform grid whose cells hold a fixed number of references (15 by
 * default) with overflow moved to a spill table at setup.
 *
 * A query sends a cubic wave of cells out from the query point: pieces
 * met for the first time (epoch stamps, nothing is cleared per query) are
 * bounded below by their boxes and above by their samples, and the wave
 * stops once the best sample distance is no larger than the distance to
 * every cell not yet reached. Every piece whose lower bound is still below
 * the best is then solved exactly by px_cpiece_closest(), which proves
 * where the piece's minimum lies instead of trusting one Newton start.
 * Open ends, C0 corners, closed-curve seams and cusps are piece end points
 * and so always candidates; no parameter wraps across a seam.
 *
 * Memory and real-time rules: px_dist_model_create() allocates once (one
 * block whose size px_dist_model_info() reports) and may take long; after
 * it, px_dist_query() and px_dist_query_batch() use only that block, never
 * allocate, lock or print, and every loop in them has a bound. A model
 * holds one query workspace: queries on one model must not run
 * concurrently.
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

struct px_dist_opts {
	/* Decomposition piece length as a fraction of the arc length and
	 * the jitter factor (lower bound / upper bound); 0 picks both from
	 * the parametrization-factor table (paper table in px_dist.c). */
	double decomp_tol;
	double jitter;
	/* Pre-sample spacing as a fraction of the arc length. */
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
	int entity;      /* index of the entity in the input order */
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
	double pf;          /* parametrization factor */
	double tol, jitter; /* decomposition settings used */
	double arc_length;  /* approximate */
	int first_piece, n_pieces;
	int closed;         /* end points coincide */
	int n_breaks;       /* interior C0 knots */
	int n_cusps;        /* interior points of vanishing derivative */
};

struct px_dist_info {
	int n_entities, n_pieces, n_samples;
	int grid[3];
	double cell_size;
	long cells, spill;
	size_t bytes; /* everything the model holds */
	px_aabb bounds;
};

struct px_dist_model;

/*
 * Prepare a model from n_curves curves (valid, e.g. from
 * px_nurbs_curve_init(); they are copied, the caller's arrays may go
 * away). opts may be NULL for defaults. Setup only: allocates.
 * Returns PX_OK, PX_E_INVAL (NULL, n_curves < 1, bad options),
 * PX_E_NOMEM, PX_E_NOSPC (an entity needs more than
 * max_pieces_per_entity pieces), PX_E_DEGENERATE (all geometry in one
 * point is still accepted; this is for NaN-free but unusable input).
 */
PX_API int px_dist_model_create(const struct px_nurbs_curve *curves,
				int n_curves, const struct px_dist_opts *opts,
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
 * (NULL) or PX_E_NAN (p not finite; r untouched). @note RT-safe.
 */
PX_API int px_dist_query(struct px_dist_model *m, px_vec3 p,
			 struct px_dist_result *r);

/* n queries; stops at the first error and returns it. @note RT-safe. */
PX_API int px_dist_query_batch(struct px_dist_model *m, const px_vec3 *p,
			       size_t n, struct px_dist_result *r);

#ifdef __cplusplus
}
#endif

#endif
