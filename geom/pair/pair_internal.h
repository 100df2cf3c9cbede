/*
 * pair_internal.h - the methods px_pair_distance (px_pair.c) chooses
 * from: closed-form pairs (capsule against capsule or box:
 * px_pair_prim.c), GJK and EPA for convex models (pair_gjk.c), the exact
 * mesh paths (pair_mesh.c), a cloud against a mesh or a primitive
 * (pair_cloud.c) and the general search by alternating projections
 * (pair_search.c). Not part of the public API.
 *
 * Memory and real-time rules: no allocation, fixed stacks and buffers,
 * bounded steps; RT-safe.
 */
#ifndef PX_PAIR_INTERNAL_H
#define PX_PAIR_INTERNAL_H

#include "math_internal.h"
#include "px_math.h"
#include "px_model.h"
#include "px_pair.h"

/*
 * Closest points of segments p0-p1 and q0-q1 (either may be a point):
 * the parameters *s, *t in [0, 1] and the squared distance. Exact up to
 * rounding, also for parallel segments (then one closest pair of the
 * many). RT-safe.
 */
double px__seg_seg(px_vec3 p0, px_vec3 p1, px_vec3 q0, px_vec3 q1, double *s,
		   double *t);

/*
 * Closest points of segment p0-p1 and the solid box |x_k| <= h[k]
 * (box frame): the segment parameter *t, the box point *q, and the
 * squared distance (0 when the segment meets the box). The squared
 * distance is a convex piecewise quadratic in t with breaks where the
 * segment crosses a face plane; each piece is minimised exactly.
 * RT-safe.
 */
double px__seg_box(px_vec3 p0, px_vec3 p1, const double h[3], double *t,
		   px_vec3 *q);

/*
 * Closest points of segment p0-p1 and triangle v[0..2] (any shape, also
 * collapsed): the segment parameter *s, the triangle point *q and the
 * squared distance. The least over the segment's end points and its
 * crossing of the triangle's plane against the triangle, and the
 * triangle's edges against the segment: a disjoint pair has its closest
 * points on one of these, and every candidate is a real pair of points.
 * RT-safe.
 */
double px__seg_tri(px_vec3 p0, px_vec3 p1, const px_vec3 v[3], double *s,
		   px_vec3 *q);

/* When m is a capsule primitive: its world-frame axis e0-e1 and radius,
 * returning 1; else 0. RT-safe. */
int px__capsule_axis(const struct px_model *m, px_vec3 *e0, px_vec3 *e1,
		     double *radius);

/*
 * The pair in closed form when it is a capsule against a capsule, or a
 * capsule against a box whose axis segment stays outside the box (the
 * axis inside the box is left to EPA). Fills res (distance, points,
 * depth and normal when the pair overlaps, converged, local_only = 0)
 * as px_pair_distance() documents and returns 1; returns 0 when the
 * pair is not one of these (res untouched), or a negative error.
 * RT-safe.
 */
int px__pair_closed(const struct px_model *a, const struct px_model *b,
		    struct px_pair_result *res);

/* ---- GJK and EPA (pair_gjk.c) ---------------------------------------------- */

#define GJK_MAX_ITERS 128

/* A point of the Minkowski difference with the support points of A and B
 * that made it. */
struct gjk_vert {
	px_vec3 w, a, b; /* w = a - b */
};

/* A convex shape for GJK: a model with a support function, a
 * triangle (world-frame vertices) of a mesh, or the convex hull of a
 * point set (a Bezier patch's control net). */
struct shp {
	const struct px_model *m;
	const px_vec3 *v; /* 3 vertices, or NULL for m */
	int nv;           /* points at v (their convex hull); 0 means 3 */
};

/*
 * Distance of convex shapes a and b (Gilbert, Johnson and Keerthi):
 * returns 1 with *dist and the witness points, 0 when they intersect,
 * negative when a model has no support function. *iters: the steps (at
 * most GJK_MAX_ITERS: then *dist is only an upper bound); S[0..*n_out-1]
 * the final simplex (EPA's start). *vout (may be NULL): the point of
 * A - B nearest the origin found; *lower (may be NULL): the best lower
 * bound of the distance seen (the support plane's distance v . w / |v|),
 * which certifies *dist. RT-safe.
 */
int px__gjk(const struct shp *a, const struct shp *b, double *dist, px_vec3 *pa,
	    px_vec3 *pb, int *iters, struct gjk_vert S[4], int *n_out, px_vec3 *vout,
	    double *lower);

/*
 * Penetration of overlapping convex models a and b from GJK's simplex
 * S[0..ns-1] (expanding polytope): the depth, the normal (translate B by
 * depth * normal to separate) and the witness points (pa - pb = depth *
 * normal); *iters grows by the steps. Returns 1 converged, 0 when the
 * fixed buffers ran out (an upper bound returned), -1 when no polytope
 * could be built (flat Minkowski difference: depth 0). RT-safe.
 */
int px__epa(const struct px_model *a, const struct px_model *b,
	    const struct gjk_vert *S, int ns, double *depth, px_vec3 *normal,
	    px_vec3 *pa, px_vec3 *pb, int *iters);

/* ---- the general search (pair_search.c) ---------------------------------- */

/* A pair of points, one on each model, and how it was reached. */
struct pair_run {
	double d;
	px_vec3 pa, pb;
	int ia, ib;
	int iters;
	int converged;
	int intersecting;
};

/*
 * One start of the alternating projections. seed is a point to project
 * onto A first (any point: a box corner, last cycle's pair), so every
 * pair compared is (a point of A, the point of B closest to it) or the
 * reverse, real surface points. Fills o; returns 0 or an error.
 */
int px__pair_run(const struct px_model *a, const struct px_model *b, px_vec3 seed,
		 int max_iters, double tol, double rel, struct pair_run *o);

/*
 * Neighbourhood step on side x: every feature of x within the current
 * distance of x's point (as many as a fixed buffer allows, shrinking the
 * radius otherwise), each taken at its point nearest y's point and
 * projected onto y. Discrete models (clouds, fine meshes) have many
 * shallow local minima next to the global one; this jumps over them.
 * Every pair tried is a real pair, so the distance can only drop.
 * Returns 1 when it improved, 0 when not, a negative error.
 */
int px__pair_refine_side(const struct px_model *x, const struct px_model *y,
			 px_vec3 *px, px_vec3 *py, int *ix, int *iy, double *d,
			 int *iters);

/* Seed k: 0 = closest point of A's box to B's box (alternating between
 * the two convex boxes), then B's box corners and face centres, then
 * A's (each later projected onto A by px__pair_run). Returns 0 past the
 * last. */
int px__pair_seed(const struct px_model *a, const struct px_model *b, int k, px_vec3 *out);

/* 1 when box b is neither empty nor infinite. */
int px__finite_box(const px_aabb *b);

/*
 * For closed models without an exact method: the point of x's surface
 * deepest inside y (most negative signed distance to y), by projected
 * descent from a start on x: step against y's distance gradient,
 * project back onto x, keep the step when it went deeper (the step
 * grows after a success and halves after a failure). A local search:
 * results are flagged approximate. Returns 1 with *d (< 0) and the
 * points when a point of x inside y was found, 0 when none, or an error.
 */
int px__pair_deepest(const struct px_model *x, const struct px_model *y, px_vec3 start,
		     double scale, double *d, px_vec3 *px_, px_vec3 *qy, px_vec3 *dir,
		     int *iters);

/* ---- exact paths with a mesh (pair_mesh.c) ---------------------------------- */

/* World-frame vertices of triangle t of mesh m (seeds for the depth
 * search); all at m's origin when t is not a triangle of m. */
void px__tri_world(const struct px_model *m, int t, px_vec3 v[3]);

/*
 * The surfaces are apart (best->d > 0), yet a closed model may hold the
 * other whole: then the other's closest point lies inside it, which its
 * signed distance tells. Marks best intersecting (that point as the
 * overlap) and returns 1, else 0, or an error.
 */
int px__pair_contained(const struct px_model *a, const struct px_model *b,
		       struct pair_run *best, int *total);

/*
 * Exact distance of mesh m to convex model o (support function): the
 * mesh hierarchy bounded from below by o's point queries
 * (px__mesh_vs_model), each remaining triangle measured by GJK (by a
 * closed form for a capsule). The start bound is the triangle of hint
 * (last cycle's) or of the mesh point nearest o's origin. Fills best
 * (points polished by two exact projections) and returns 1 when proven
 * global, 0 when the query budget ran out (best is then only the best
 * found), or an error.
 */
int px__pair_mesh_convex(const struct px_model *m, const struct px_model *o, int hint,
			 struct pair_run *best, int *total);

/* ---- a point cloud against a model (pair_cloud.c) -------------------------- */

/* The least distance of a model over a cloud's points (centres). */
struct px__cloud_min {
	double s;        /* the least distance found (the limit if none) */
	px_vec3 p, q;    /* the cloud point, its closest point on the model */
	int pi, oi;      /* the point (input order), the model's feature */
	int found;       /* a point at or below the limit was found */
	int certified;   /* every query was exact and the stack sufficed */
	int queries;     /* point queries of the model made */
	int nodes;       /* cloud nodes expanded (px__cloud_mesh_min) */
};

/*
 * The least distance s_o(p) of model o (signed when o has an inside)
 * over the points p of cloud c, where it is at most limit (INFINITY:
 * the minimum itself): the cloud's hierarchy bounded below by one query
 * of o per node (its box centre's distance minus the half diagonal; the
 * distance is 1-Lipschitz). inside_only: only points inside o (s < 0)
 * count, and nodes whose box misses o's box are skipped unqueried.
 * Fills out (found = 0 when no point qualifies); returns PX_OK or an
 * error (c not a cloud: PX_E_INVAL). RT-safe: no allocation, a fixed
 * stack; work bounded by the cloud's node count.
 */
int px__cloud_min_model(const struct px_model *c, const struct px_model *o, double limit,
			int inside_only, struct px__cloud_min *out);

/*
 * The least distance of mesh o (signed when closed) over the points of
 * cloud c, exactly, by the cloud's hierarchy bounded by o's box
 * (pair_cloud_mesh.c); hint: a point (input order) measured first as
 * the first bound (-1: none). C (may be NULL) lends its bounding planes
 * of o (made for o when missing); with coherent and its cut valid for
 * the pair, only the part of the cloud the motion since may have
 * brought within reach is walked, and a full coherent walk records its
 * cut into C. Fills out
 * (found = 1 unless an error); returns PX_OK or an error. RT-safe.
 */
int px__cloud_mesh_min(const struct px_model *c, const struct px_model *o, struct px_pair_cache *C,
		       int coherent, int hint, struct px__cloud_min *out);

/*
 * A point cloud against a mesh or a primitive, exactly: the least
 * distance of the other model over the cloud's points minus the point
 * radius, negative (with its depth) where a point lies inside a closed
 * model. A mesh by both hierarchies at once (px__mesh_cloud_pair; with
 * coherent, res's last triangle and point are the first bound), then
 * for a closed mesh its points inside (px__cloud_min_model); a
 * primitive by its point queries over the cloud's hierarchy. cache (may
 * be NULL): a small mesh takes px__cloud_mesh_min() instead, keeping
 * the cut when keep_cut (the caller asked for coherence, even where
 * res holds no valid last answer: a cloud just swapped in). Fills res
 * as px_pair_distance() does (local_only only if a query was not exact)
 * and returns 1 (the normal from the points is the caller's), 2 (with
 * its normal: an overlap with depth), 0 when the pair is not one of
 * these, or an error. RT-safe.
 */
int px__pair_cloud(const struct px_model *a, const struct px_model *b, int coherent,
		   struct px_pair_cache *cache, int keep_cut, struct px_pair_result *res);

/* ---- NURBS surface models (pair_nurbs.c) ---------------------------------- */

/*
 * A NURBS surface model against a mesh, another NURBS surface model or a
 * convex primitive with a support function, certified: both models'
 * hierarchies descended at once (sub-patches bounded by their control
 * nets' hulls, GJK per node pair), the answer a real pair of surface
 * points within 1e-6 of the NURBS box diagonal of the global minimum.
 * With coherent, res's last pair (not intersecting) is the first bound.
 * Fills res as px_pair_distance() does (local_only = 1 only when the
 * descent's budget ran out) and returns 1; returns 0 when the pair is
 * not one of these or overlaps (the general search then answers, with
 * its depth), or an error. RT-safe.
 */
int px__pair_nurbs(const struct px_model *a, const struct px_model *b, int coherent,
		   struct px_pair_result *res);

/* Test switch (math_internal.h): 1 sends every NURBS pair to the general
 * search, the peer the benchmark times the descent against. */
PX__TEST_SWITCH(int, px__pair_nurbs_off, 0);

#endif
