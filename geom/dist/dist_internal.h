/*
 * dist_internal.h - private declarations of the distance core: the
 * prepared model's layout (px_dist.c queries it, dist_build.c makes it),
 * the decomposition of entities into pieces (dist_decomp.c), the
 * Bernstein tensor kernels of the surface pieces (spiece_tensor.c), and
 * the test hooks of their certified solver (spiece_solve.c). Not
 * installed, not part of the API.
 */
#ifndef PX_DIST_INTERNAL_H
#define PX_DIST_INTERNAL_H

#include <stdint.h>

#include "math_internal.h"
#include "px_arena.h"
#include "px_cpiece.h"
#include "px_dist.h"
#include "px_math.h"
#include "px_nurbs.h"
#include "px_recog.h"
#include "px_spiece.h"

/* ---- trimmed surfaces ---------------------------------------------------- */

/*
 * A trimmed surface's domain as the core sees it (geom/brep fills it
 * from its px_trim, so the core does not depend on that module).
 * classify: 0 when the parameter box lies wholly outside the domain, 1
 * wholly inside, 2 when a loop may cross it (never wrong for 0 and 1).
 * inside: 1 when (u, v) lies strictly inside (not on a loop). Both are
 * RT-safe and read-only. A surface whose inside is NULL is untrimmed.
 * edged: 1 when every point of the domain's boundary maps onto one of
 * the model's curves or a point the caller answers itself; then a
 * closed-form surface (whose only interior local minimum is its global
 * one) whose closest point lies outside the domain has nothing nearer
 * in it than its boundary, and is answered whole by the closed form.
 */
struct px__dist_trim {
	const void *ctx;
	int (*inside)(const void *ctx, double u, double v);
	int (*classify)(const void *ctx, double u0, double u1, double v0,
			double v1);
	int edged;
};

/* What a piece solver checks a candidate against: the domain, and for a
 * curve piece on a surface the iso line it runs along (iso_dir 1: u =
 * iso_t and the piece's parameter is v; 0: v = iso_t). */
struct px__uv_filter {
	int (*inside)(const void *ctx, double u, double v);
	const void *ctx;
	int iso_dir;
	double iso_t;
};

/* The piece solvers restricted to a trimmed domain: a candidate outside
 * it neither answers nor lowers *best_d2 (so the minima inside are still
 * all examined); filter NULL is the plain solver. @note RT-safe. */
int px__cpiece_closest_in(const struct px_cpiece *pc, px_vec3 p,
			  const struct px__uv_filter *flt, double *best_d2,
			  struct px_cpiece_hit *hit);
int px__spiece_closest_in(const struct px_spiece *sp, px_vec3 p, double hint_s,
			  double hint_t, const struct px__uv_filter *flt,
			  double *best_d2, struct px_spiece_hit *hit);

/*
 * px_dist_model_create() with trimmed surfaces: trims[i] (n_surfs
 * entries, or NULL for none) is surface i's domain. The trimmed
 * domain must lie in the surface's parameter domain. Per trimmed
 * surface, patches outside the domain are never binned, patches a loop
 * crosses are solved with the filter and give no pre-samples (a sample
 * outside the domain is no upper bound), the domain edges are not
 * candidates (the caller adds the trimming edges as curves) and creases
 * are classified like patches; a closed-form shape answers it only
 * where the whole surface's closest point lies inside the domain. Setup
 * only.
 */
int px__dist_model_create_trimmed(const struct px_nurbs_curve *curves,
				  int n_curves, const struct px_nurbs_surf *surfs,
				  int n_surfs, const struct px__dist_trim *trims,
				  const struct px_dist_opts *opts,
				  struct px_dist_model **out);

/* px_dist_query_ws() below an upper bound bound2 on the squared
 * distance (the caller's own candidate): PX_OK with the answer, 1 when
 * nothing of the model is nearer than the bound (r->dist its root,
 * r->piece -1; certified and gap still describe the proof), or the
 * same errors. A model whose pieces give no sample (trimmed faces that
 * only crossed patches reach) still answers. @note RT-safe. */
int px__dist_query_below(const struct px_dist_model *m, struct px_dist_ws *ws,
			 px_vec3 p, double bound2, struct px_dist_result *r);

/* ---- the prepared model ------------------------------------------------- */

struct cand {
	double lb; /* squared lower bound */
	int piece;
};

/*
 * What the wave's bound on a closed-form shape's distance reads besides
 * the shape (dist_build.c fills it at setup), so that the bound needs no
 * angle function: for the turn of an arc or a surface of revolution
 * (about its axis) the unit direction of its middle and the cosine of
 * half its sweep (below -1 for a full turn), which decide whether a
 * query's angle lies in the sweep by one comparison; the direction of
 * the sweep's end; the same wedge for a profile arc; the end points of
 * the arc (a curve) or of the profile arc (meridian coordinates); for a
 * parallelogram whose sides are square to each other, their squared
 * lengths (else zero).
 */
struct px__shape_fast {
	double wedge[3], end[2], pwedge[3];
	px_vec3 a0, a1;
	double side2[2];
};

/* Up to this many PK_SHAPE items are scanned by their boxes before the
 * wave instead of being binned (px_dist.c: scan_shapes()). */
#define PX__DIST_SCAN_ITEMS 40

/* The boxes of scanned items 2 j and 2 j + 1, lane by lane (axis d of
 * item i in c[d][i & 1]), as centres and half extents, so that two
 * bounds are a few vector operations per axis; the extents are rounded
 * up so that a bound never exceeds the box's. An odd count's last lane
 * is infinitely far. */
struct px__dist_sbox {
	double c[3][2], e[3][2];
};

/* PK_SHAPE: a whole closed-form entity in the grid (trimmed models). */
enum { PK_CURVE = 0, PK_PATCH = 1, PK_SHAPE = 2 };
/* PIECE_SHAPE: a piece of an entity the grid holds as one PK_SHAPE item
 * (never binned). */
enum { PIECE_WHOLE = 0, PIECE_CROSSED = 1, PIECE_PRUNED = 2, PIECE_SHAPE = 3 };

/* What one query in flight needs besides the read-only model: per-piece
 * visit stamps (an epoch, so nothing is cleared per query) and the
 * candidate list. */
struct px_dist_ws {
	uint32_t epoch;
	uint32_t *stamp;
	uint32_t *ent_stamp; /* entities answered in closed form */
	struct cand *cand;
	int n_pieces, n_ent;
	int owned; /* allocated by px_dist_ws_create() */
	double bound2; /* INFINITY but inside px__dist_query_below() */
};

/* One entry of the grid's index space: a curve piece or a patch. */
struct piece {
	px_aabb box;
	int kind;    /* PK_CURVE, PK_PATCH or PK_SHAPE */
	int idx;     /* into cp or spc; PK_SHAPE: the entity's first piece */
	int ent;     /* entity */
	/* Boundary curve of a surface: the curve runs along u (iso_dir 0,
	 * v fixed at iso_t) or along v (iso_dir 1); -1 for an entity's own
	 * curve pieces and patches. */
	int iso_dir;
	double iso_t;
	int sample_start;
	int ns, nt; /* samples: ns along the piece (curves) or ns x nt */
	/* Trimmed surfaces: PIECE_WHOLE, PIECE_CROSSED (solved with the
	 * domain's filter) or PIECE_PRUNED (outside, never binned); any
	 * piece of a trimmed model: PIECE_SHAPE. */
	int trim;
	/* Oriented box around the control net (so around the piece):
	 * candidates the axis-aligned box kept are dropped by it before
	 * their solve reads the coefficient tables (most neighbours of the
	 * foot point are nearly flat slabs that it bounds tightly). */
	px_obb obb;
};

struct px_dist_model {
	struct px_arena arena;
	struct px_dist_opts opts;
	int n_ent;
	struct px_dist_entity_info *ent;
	/* Knowledge step: entities that are exactly a primitive (with the
	 * arrays their parameter inversion reads, copied here). */
	struct px_recog_shape *shape;
	/* Per entity: the trimmed domain (inside NULL: untrimmed), or NULL
	 * for a model without trimmed surfaces. */
	struct px__dist_trim *trim;
	int n_pieces;
	struct piece *pieces;
	/* Trimmed models: entities answered whole in closed form sit in the
	 * grid as one PK_SHAPE item each (the last n_shape_items pieces)
	 * instead of their pieces: the wave answers them as it meets them. */
	int n_shape_items;
	int n_cp, n_sp;
	struct px_cpiece *cp;
	struct px_spiece *spc;
	int n_samples;
	px_vec3 *samples;
	/* grid */
	px_aabb bounds;
	double h, inv_h;
	int nx, ny, nz;
	long n_cells, n_spill;
	int cap;
	int *cell_count;
	/* Chebyshev distance (in cells) to the nearest non-empty cell: the
	 * wave starts at that shell, all nearer ones being empty. */
	uint16_t *cell_empty_r;
	int *cell_slot;  /* n_cells * cap */
	int *cell_spill; /* first spill index of each cell */
	int *spill;
	/* the workspace of px_dist_query() */
	struct px_dist_ws ws;
	/* Per entity, beside shape (trimmed models' closed forms). */
	struct px__shape_fast *sfast;
	/* Models with few PK_SHAPE items: their boxes in one array (else
	 * NULL), scanned before the wave; wave_pieces: the grid's other
	 * pieces (0: no wave). */
	struct px__dist_sbox *shape_box;
	int wave_pieces;
};

/* Squared distance from (a, b) to a profile segment in meridian
 * coordinates (struct px_recog_rev). */
static inline double px__dist_pseg_d2(const struct px_recog_seg *s, double a,
				      double b)
{
	double c;
	a -= s->p0.x;
	b -= s->p0.y;
	c = a * s->dir.x + b * s->dir.y;
	c = c < 0.0 ? 0.0 : (c > s->len ? s->len : c);
	a -= c * s->dir.x;
	b -= c * s->dir.y;
	return a * a + b * b;
}

/*
 * A lower bound on the squared distance from p to a closed-form shape,
 * far cheaper than its closest point (no angles): the whole circle of
 * an arc; for a surface of revolution the profile's whole circle (or
 * its segment) in p's meridian half-plane, which no point of the swept
 * profile (rho >= 0) is nearer than; a parallelogram's plane. 0 for a
 * segment (its closest point costs no more). The distance core's wave
 * and the B-rep streams' bounds use it. @note RT-safe.
 */
static inline double px__dist_shape_lb2(const struct px_recog_shape *sh, px_vec3 p)
{
	const struct px_recog_rev *rv = &sh->rev;
	px_vec3 w;
	double a, b, c, l;

	switch (sh->kind) {
	case PX_RECOG_ARC:
		w = px_v3_sub(p, sh->arc.center);
		a = px_v3_dot(sh->arc.normal, w);
		b = px_v3_dot(sh->arc.e0, w);
		c = px_v3_dot(sh->arc.e1, w);
		l = sqrt(b * b + c * c) - sh->arc.radius;
		return a * a + l * l;
	case PX_RECOG_PARALLELOGRAM:
		a = px_v3_dot(sh->quad.normal, px_v3_sub(p, sh->quad.origin));
		return a * a / px_v3_dot(sh->quad.normal, sh->quad.normal);
	case PX_RECOG_CYLINDER:
	case PX_RECOG_CONE:
	case PX_RECOG_ANNULUS:
	case PX_RECOG_SPHERE:
	case PX_RECOG_TORUS:
		w = px_v3_sub(p, rv->origin);
		a = px_v3_dot(rv->axis, w); /* meridian (a, b) */
		b = px_v3_dot(w, w) - a * a;
		b = b > 0.0 ? sqrt(b) : 0.0;
		if (rv->profile_is_arc) {
			a -= rv->parc.center.x;
			b -= rv->parc.center.y;
			l = sqrt(a * a + b * b) - rv->parc.radius;
			return l * l;
		}
		return px__dist_pseg_d2(&rv->pseg, a, b);
	default:
		return 0.0;
	}
}

/* Index of cell (i, j, k) of the model's grid. */
static inline long px__dist_cell_index(const struct px_dist_model *m, int i,
				       int j, int k)
{
	return ((long)k * m->ny + j) * m->nx + i;
}

/* ---- decomposition (dist_decomp.c) -------------------------------------- */

/* Growing list of cut parameters (heap, setup only). */
struct px__dist_cuts {
	double *u;
	int n, cap;
};

/*
 * Parameters that cut one curve into pieces (sorted, distinct, both
 * domain ends included), and its info: pf, tol, jitter, arc length,
 * closed, breaks, cusps. Returns PX_OK, PX_E_NOMEM or PX_E_NOSPC.
 */
int px__dist_decompose(const struct px_nurbs_curve *c,
		       const struct px_dist_opts *o,
		       struct px_dist_entity_info *info,
		       struct px__dist_cuts *out);

/* Decomposition tolerance and jitter into info from its pf: the paper's
 * table floored at floor_tol, unless the options fix them. */
void px__dist_decomp_settings(struct px_dist_entity_info *info,
			      double floor_tol, const struct px_dist_opts *o);

/* Parametrization factor of a surface (max over u and v). */
double px__dist_surf_pf(const struct px_nurbs_surf *s);

/* Cut parameters of a surface in direction dir and the length of the
 * iso-curve they come from (*len_out). */
int px__dist_surf_cuts(const struct px_nurbs_surf *s, int dir,
		       const struct px_dist_opts *o, double *len_out,
		       struct px__dist_cuts *out);

/* ---- surface pieces: Bernstein tensors (spiece_tensor.c) ---------------- */

#define PX__SP_MD PX_SPIECE_MAX_DEGREE
/* Largest tensor: gu of degree (3p - 1, 3q), or F of (2p, 2q). */
#define PX__SP_TMAX ((3 * PX__SP_MD + 1) * (3 * PX__SP_MD + 1))

/* Coefficients of a tensor of degrees (n, m). */
static inline size_t px__sp_tsize(int n, int m)
{
	return (size_t)(n + 1) * (size_t)(m + 1);
}

/* Raise Bernstein basis values of degree k - 1 to degree k in place. */
static inline void px__sp_raise(double *b, int k, double t, double u)
{
	int i;
	b[k] = t * b[k - 1];
	for (i = k - 1; i > 0; i--)
		b[i] = u * b[i] + t * b[i - 1];
	b[0] = u * b[0];
}

/* a (na, ma) times b (nb, mb) into out (na + nb, ma + mb). */
void px__sp_mul(const double *a, int na, int ma, const double *b, int nb,
		int mb, double *out);
/* Derivative along s (degree n - 1, m) or along t (n, m - 1). */
void px__sp_deriv_s(const double *c, int n, int m, double *out);
void px__sp_deriv_t(const double *c, int n, int m, double *out);
/* Restriction to [s0, s1] x [t0, t1]; out may alias c. */
void px__sp_restrict(const double *c, int n, int m, double s0, double s1,
		     double t0, double t1, double *out);
/* Coefficient ranges of the derivatives along the rows (lo[0], hi[0])
 * and along the columns (lo[1], hi[1]). */
void px__sp_jac_range(const double *c, int n, int m, double lo[2],
		      double hi[2]);
/* Degree elevation by one along the rows (dir 0) or the columns. */
void px__sp_elevate(const double *x, int n, int m, int dir, double *y);
/* Derivative along the rows (columns) written back at the same degree. */
void px__sp_d_rows(const double *x, int R, int C, double *out);
void px__sp_d_cols(const double *x, int R, int C, double *out);
/* Value at (s, t). */
double px__sp_eval(const double *c, int n, int m, double s, double t);

/* Point of a piece at local (s, t) (px_spiece.c). */
px_vec3 px__sp_point(const struct px_spiece *sp, double s, double t);

/* ---- test hooks of the surface piece solver (spiece_solve.c) ------------- */

/* px_spiece: at most this many slots in a query's pool of parent
 * tensors (-1: as many as fit), so tests can run the restriction from
 * the root and compare. */
PX__TEST_SWITCH(int, px__spiece_pool_cap, -1);
/* px_spiece: 1 leaves the preconditioned monotonicity test out (a
 * rectangle is then split where only it would prove one minimum). */
PX__TEST_SWITCH(int, px__spiece_no_precond, 0);
/* px_spiece: the preconditioned monotonicity test on one rectangle, and
 * the symmetric Jacobian part's least eigenvalue sampled there (see
 * spiece_solve.c). */
struct px_spiece;
int px__spiece_precond_probe(const struct px_spiece *sp, px_vec3 p, double s0,
			     double s1, double t0, double t1, int o, int grid,
			     double *mu, double *sampled);

#endif
