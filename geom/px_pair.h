/*
 * px_pair.h - distance between two models of any representations, by
 * alternating point-to-model projections.
 *
 * Johnson and Cohen (2004): from a point on model A, the closest point of
 * B; from that, the closest point of A; and so on. Every step is one
 * px_model_query(), so any pair of representations works (mesh against
 * cloud, primitive against NURBS...), and the distance never increases
 * from one step to the next, because each projection is the minimum
 * over a set that contains the previous point. The iteration stops when
 * the distance decreases by less than the tolerance. It converges to a
 * local minimum of the distance; the paper starts it from the closest
 * points of the two oriented bounding boxes, and reports about 95 % global
 * hits on bunny pairs with that single start. Here several starts are
 * run (the box pair, then the corners and face centres of each box
 * projected onto the other model), the best pair wins. Discrete models
 * (clouds, fine meshes) have many shallow local minima right next to the
 * global one, so the best pair then gets neighbourhood steps: every
 * feature of either model within the current distance of its point (up
 * to 16, through the models' cache operations) is tried against the
 * other model, and any improvement is polished by another round of
 * projections (two such rounds; none in coherent mode with one start,
 * which is meant to be cheap). The result
 * says whether it is proven global: for two convex models alternating
 * projections converge to the global minimum (projections onto convex
 * sets), so convex pairs (px_model_caps() & PX_MODEL_CAP_CONVEX) that
 * converged are certified; every other result carries local_only = 1.
 *
 * Exact paths come first: a sphere primitive against any model is one
 * point query of its centre (exact, also for meshes and clouds); two
 * convex models that have support functions (convex primitives, convex
 * meshes) go through GJK on their Minkowski difference (the GJK of
 * libccd, which Debian ships, offers intersection and penetration but
 * no separation distance, so it is implemented here), its witness
 * points polished by two exact projections onto the surfaces. Both give
 * local_only = 0.
 *
 * Coherent mode: the previous result's points (kept in the result, in
 * each model's own frame, so they follow the models' new poses) are the
 * first start; with a slowly moving pair one or two steps suffice.
 *
 * Intersection: when a projection lands inside a closed model (signed
 * distance <= 0) or the distance reaches 0, the models touch or overlap:
 * intersecting = 1, and the penetration comes out of the same call:
 * depth > 0, distance = -depth, and normal such that translating B by
 * depth * normal (or A by -depth * normal) separates the pair, with
 * point_a - point_b = depth * normal. Convex pairs with support functions
 * get the exact depth (EPA on the Minkowski difference from GJK's final
 * simplex, fixed buffers; depth_approx = 1 only if a curved pair runs
 * out of them, then depth is an upper bound within about 1e-3). A sphere
 * against any closed model is exact (radius minus the signed distance of
 * its centre). Other closed pairs (meshes, NURBS shells, the torus) get
 * the deepest point of either model inside the other by a local descent
 * of the signed point-to-model distance along the surface, from the
 * overlap found and from each seed (opt->starts; depth_approx = 1: a lower bound of
 * the deepest point's depth, which for convex shapes is itself at most
 * the translational depth). Unsigned models (clouds, open meshes) have
 * no inside: touching reports distance 0 and depth 0.
 *
 * Memory and real-time rules: no allocation (GJK and EPA keep their
 * simplex and polytope in fixed arrays on the stack, about 14 kB); work
 * bounded by starts * max_iters point queries, plus for overlapping
 * non-convex pairs 2 (starts + 1) (2 + 80) queries of the depth search
 * (points deep inside a mesh are its slowest queries: budget for it, or
 * lower starts), each RT-safe. @note RT-safe.
 */
#ifndef PX_PAIR_H
#define PX_PAIR_H

#include "px_base.h"
#include "px_math.h"
#include "px_model.h"

#ifdef __cplusplus
extern "C" {
#endif

#define PX_PAIR_MAX_STARTS 32

struct px_pair_opts {
	int starts;       /* 1..PX_PAIR_MAX_STARTS; 0 = 8 */
	int max_iters;    /* projections per start (each = 2 queries); 0 = 64 */
	/* stop when one round of projections lowers the distance d by at
	 * most tol + rel_tol * d (0 = 1e-12 and 1e-9) */
	double tol;
	int coherent;     /* start from the previous result's pair */
	double rel_tol;
};

struct px_pair_result {
	/* >= 0 apart; -depth when intersecting (0 when the depth is unknown
	 * or zero) */
	double distance;
	px_vec3 point_a;     /* on A, world frame */
	px_vec3 point_b;     /* on B, world frame */
	int index_a, index_b; /* feature indices (px_model_result.index) */
	int iterations;      /* point-to-model queries made */
	int starts;          /* starts run */
	int converged;       /* the best start met the tolerance */
	int intersecting;
	/* 1 unless the answer is proven global (both models convex and
	 * converged, or intersecting). */
	int local_only;
	/* Coherence state: the best pair in each model's own frame, valid
	 * after a successful call. */
	px_vec3 local_a, local_b;
	int valid;
	/* Penetration (intersecting): depth >= 0 and the unit normal along
	 * which B leaves A; apart: depth 0 and normal the unit vector from
	 * point_a to point_b (zero when they coincide). */
	double depth;
	px_vec3 normal;
	int depth_approx; /* 1: depth from a local search (see above) */
};

/*
 * Distance between models a and b at their current poses. opt may be
 * NULL (defaults). res is in/out: with opt->coherent its local_a/local_b
 * from the last call are the first start (ignored unless res->valid).
 * Returns PX_OK; PX_E_INVAL (NULL, bad options), or a query's error.
 * @note RT-safe.
 */
PX_API int px_pair_distance(const struct px_model *a, const struct px_model *b,
			    const struct px_pair_opts *opt,
			    struct px_pair_result *res);

#ifdef __cplusplus
}
#endif

#endif
