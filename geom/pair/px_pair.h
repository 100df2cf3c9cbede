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
 * says whether it is proven global (local_only, see below).
 *
 * Exact paths come first, in this order, all with local_only = 0:
 * - a sphere primitive against any model: one point query of its
 *   centre;
 * - a capsule against a capsule or a box: closed forms on the axis
 *   segment (segment/segment and segment/box distances, each a convex
 *   piecewise quadratic minimised exactly; geom/pair/px_pair_prim.c), with
 *   the depth, normal and witnesses of an overlap; only a capsule whose
 *   axis meets the box goes on to GJK and EPA;
 * - two convex models with support functions (convex primitives, convex
 *   meshes): GJK on their Minkowski difference (the GJK of libccd, which
 *   Debian ships, offers intersection and penetration but no separation
 *   distance, so it is implemented here), its witness points polished by
 *   two exact projections onto the surfaces;
 * - two triangle meshes (any, closed or open, convex or not): the exact
 *   minimum over all triangle pairs, by a simultaneous traversal of both
 *   hierarchies (geom/mesh/px_mesh_pair.c: box pairs bounded below in both
 *   frames, along the line of centres and along the best pair's own
 *   direction, exact triangle-triangle distances with a crossing test);
 *   index_a/index_b are the triangles. In coherent mode last cycle's
 *   triangle pair is the starting bound;
 * - a mesh against a convex model with a support function (box,
 *   capsule, cylinder, cone): the mesh hierarchy bounded below by the
 *   other model's point queries (distance of a node box's centre minus
 *   its half diagonal), each remaining triangle measured by GJK (exact to
 *   a relative 1e-10; a capsule by the closed form of its axis against
 *   the triangle, px_pair_prim.c), the pair then projected onto both
 *   surfaces. If
 *   its budget of 4096 point queries runs out (very fine meshes close
 *   to a large primitive) the best pair found joins the projections
 *   below and the flag stays.
 * - a point cloud against a mesh (closed or open): the least distance
 *   over the cloud's points, by both hierarchies at once (box pairs
 *   bounded below as for two meshes, each remaining point against the
 *   triangles its plane and edge bounds leave, exactly;
 *   geom/mesh/px_mesh_pair.c); against a closed mesh a point inside is
 *   at minus its distance to the surface, so the pair's distance is the
 *   least signed distance over the points (the deepest point's, with
 *   its depth, when one is inside: found by the cloud's hierarchy
 *   bounded by the mesh's signed queries, pair_cloud.c), the same in
 *   cold and coherent calls. In coherent mode last cycle's triangle and
 *   point are the starting bound. Through px_pair_distance_cached() a
 *   mesh of at most PX_PAIR_PLANES_MAX_TRIS triangles (a robot link)
 *   takes the cloud's hierarchy alone, bounded by the mesh's planes, and
 *   coherent calls keep a cut of it (see there). index_a/index_b: the
 *   triangle (the mesh's feature for a point inside) and the point; a
 *   cloud radius is subtracted;
 * - a point cloud against any primitive: the least of the primitive's
 *   exact (signed) point queries over the points, by the cloud's
 *   hierarchy bounded by one query per node (the distance is
 *   1-Lipschitz: a node's centre minus its half diagonal);
 * - a NURBS model of untrimmed surfaces against a mesh, another such
 *   model or a convex primitive with a support function: both models
 *   descended at once (geom/pair/pair_nurbs.c: the distance core's
 *   Bezier patches and their sub-patches, bounded below by their
 *   control nets' hulls, GJK per node pair; the mesh hierarchy; Newton
 *   on the best pair's parameters for the upper bound), the answer a
 *   real pair of surface points at most 1e-6 of the NURBS model's box
 *   diagonal (the smaller of two) above the global minimum; in coherent
 *   mode last cycle's pair is the starting bound. Overlapping pairs go
 *   on to the projections and the depth search below.
 * Surfaces apart but one closed model holding the other whole (its
 * signed distance at the other's closest point is negative) counts as
 * intersecting.
 *
 * Everything else runs the projections. Then two convex models that
 * converged are certified (projections onto convex sets converge to the
 * global minimum).
 * local_only = 1 remains exactly for: NURBS models with curves or
 * trimmed faces (B-rep parts), or with more than 256 patches or a
 * degree above 5, against anything but a sphere; NURBS surfaces against
 * clouds and non-convex primitives; a NURBS descent that ran out of its
 * budget (20,000 node pairs); clouds against NURBS, B-rep parts and other clouds; the
 * torus primitive against anything but a sphere or a cloud; the
 * half-space against anything not convex but a cloud (meshes that are
 * not convex, NURBS, the torus); convex pairs whose projections did not
 * converge; and the budget case above.
 *
 * Coherent mode: the previous result's points (kept in the result, in
 * each model's own frame, so they follow the models' new poses) are the
 * first start; with a slowly moving pair one or two steps suffice. Two
 * meshes stay exact in coherent mode unless opt->local_ok is set: then
 * they take the projections from last cycle's pair (local_only = 1), a
 * few microseconds instead of the exact proof's hundreds.
 *
 * Intersection: when a projection lands inside a closed model (signed
 * distance <= 0) or the distance reaches 0, the models touch or overlap:
 * intersecting = 1, and the penetration comes out of the same call:
 * depth > 0, distance = -depth, and normal such that translating B by
 * depth * normal (or A by -depth * normal) separates the pair, with
 * point_a - point_b = depth * normal. Convex pairs with support functions
 * get the exact depth (EPA on the Minkowski difference from GJK's final
 * simplex, fixed buffers; depth_approx = 1 only if a curved pair runs
 * out of them, then depth is an upper bound within about 1e-3), with
 * both witnesses on their surfaces (the deepest points; when converged,
 * else point_a on A and point_b = point_a - depth * normal). A sphere
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
 * simplex and polytope in fixed arrays on the stack, about 14 kB; the
 * mesh traversals a fixed stack of about 4 kB; the NURBS descent about
 * 150 kB, its work bounded by its 20,000 node pairs); work bounded by starts *
 * max_iters point queries, by the node pairs of the two hierarchies for
 * mesh pairs (in practice the node pairs near the closest pair, fewer
 * from a good first pair such as coherent mode's), by the query budget above for the mesh/convex path
 * (bench_models: a 4k-triangle torus against a box about 0.1 ms), by
 * the node pairs of both hierarchies and, against a closed mesh, the
 * cloud nodes within the mesh's box for the mesh/cloud path
 * (bench_arm), by the cloud's nodes for cloud/primitive pairs,
 * plus for overlapping non-convex pairs 2 (starts + 4) (2 + 80) queries
 * of the depth search (points deep inside a mesh are its slowest
 * queries: budget for it, or lower starts), each RT-safe. @note RT-safe.
 */
#ifndef PX_PAIR_H
#define PX_PAIR_H

#include <stdint.h>

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
	/* With coherent = 1 and a valid previous result: 1 lets a pair of
	 * meshes skip the exact traversal (whose proof still visits the
	 * node pairs near the closest pair) and run the projections from
	 * last cycle's pair instead, answering
	 * with local_only = 1 (also when one mesh is convex, which would
	 * otherwise take the mesh/convex path; two convex meshes keep GJK,
	 * which is exact and cheap). Use with starts = 1 for a cheap tracking
	 * step; run a cold exact call now and then (or when the pair may
	 * have jumped) to recover the global pair. 0 = always exact. */
	int local_ok;
};

struct px_pair_result {
	/* >= 0 apart; -depth when intersecting (0 when the depth is unknown
	 * or zero) */
	double distance;
	px_vec3 point_a;     /* on A, world frame */
	px_vec3 point_b;     /* on B, world frame */
	int index_a, index_b; /* feature indices (px_model_result.index) */
	/* work: point-to-model queries made (mesh pairs: node pairs
	 * expanded plus triangle pairs measured; GJK steps included) */
	int iterations;
	int starts;          /* starts run */
	int converged;       /* the best start met the tolerance */
	int intersecting;
	/* 0 when the answer is proven global (exact paths, certified
	 * mesh/cloud pairs, converged convex pairs, intersecting); 1 when it
	 * may be a local minimum (the cases listed at the top). */
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
	/* |point_a - point_b| - distance when apart (0 when the witness
	 * points realise the distance, as they do but for convex pairs with
	 * flat and curved parts in near contact, where GJK's distance is
	 * certified while its witnesses, polished on the surfaces, may stay
	 * a few micrometres longer) */
	double witness_gap;
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

/* ---- coherent cut of a mesh against a point cloud -------------------------
 *
 * A mesh (a robot link) against a large cloud, cycle after cycle, can
 * skip most of the cloud: a full call records the cut of the cloud's
 * hierarchy its walk made (every subtree it pruned and every leaf it
 * measured, with its lower bound: at most PX_PAIR_CACHE_CAP of them);
 * later calls bound how far the mesh has moved relative to the cloud
 * since (its box centre's displacement and its rotation's change times
 * its box radius), walk again only the entries whose bound that motion
 * may have brought below the best point (last cycle's, measured first),
 * and are as exact as the full call. A cut that leaves more than an
 * eighth of its entries to walk again is made anew at the next call;
 * another model, a cloud replaced (even at the same address), or what
 * the cut could not hold coming within reach also make it anew. The
 * cache also keeps bounding planes of the mesh (up to
 * PX_PAIR_CACHE_PLANES of its face normals, each at the mesh's support
 * along it: valid for any mesh, tight for convex ones) and the radius
 * of the mesh about its box's core (the box shrunk by its least half
 * extent: the axis of a long link), which bound the cloud's boxes and
 * points far more tightly than the mesh's box; cold calls through a
 * cache use them too.
 */
#define PX_PAIR_CACHE_CAP 1024
#define PX_PAIR_CACHE_PLANES 64
#define PX_PAIR_CACHE_CELLS (6 * 8 * 8)
#define PX_PAIR_PLANES_MAX_TRIS 256

struct px_pair_cache_ent {
	uint32_t idx, cnt; /* a node (cnt 0) or a leaf range of the cloud */
	float lb;          /* lower bound of the distance over it when made */
};

/* The bounding planes of a mesh (below); members private. */
struct px_pair_planes {
	const struct px_model *model_;
	unsigned long serial_;
	int n_;
	double rho_;
	double plane_[PX_PAIR_CACHE_PLANES][4];
	uint8_t cell_[PX_PAIR_CACHE_CELLS];
};

/* Caller-owned state of one mesh/cloud pair; plain struct, members
 * private (zeroed, or px_pair_cache_init(), before the first use). */
struct px_pair_cache {
	const struct px_model *cloud_, *model_;
	unsigned long serial_;
	int valid_, n_;
	uint32_t witness_;
	double far_;
	px_mat3 rot_;
	px_vec3 centre_;
	unsigned long made_, reused_;
	struct px_pair_cache_ent ent_[PX_PAIR_CACHE_CAP];
	struct px_pair_planes planes_;
};

/* Empty the cache (the next call is a full one). @note RT-safe. */
PX_API void px_pair_cache_init(struct px_pair_cache *c);

/* Make mesh's bounding planes in c now (setup time), so that the first
 * px_pair_distance_cached() of mesh against a cloud does not (up to a
 * millisecond for PX_PAIR_PLANES_MAX_TRIS triangles). Nothing for other
 * models. After px_pair_cache_init(), which empties c. */
PX_API void px_pair_cache_prepare(struct px_pair_cache *c, const struct px_model *mesh);

/*
 * px_pair_distance() through cache c (may be NULL: then exactly
 * px_pair_distance()). A mesh against a point cloud with opt->coherent
 * set uses and keeps the cut; every other pair ignores c. Answers are
 * those of px_pair_distance() (among equidistant points another may be
 * reported). @note RT-safe.
 */
PX_API int px_pair_distance_cached(const struct px_model *a, const struct px_model *b,
				   const struct px_pair_opts *opt, struct px_pair_cache *c,
				   struct px_pair_result *res);

/* Full calls made and cuts reused through c. @note RT-safe. */
PX_API unsigned long px_pair_cache_full(const struct px_pair_cache *c);
PX_API unsigned long px_pair_cache_reused(const struct px_pair_cache *c);

#ifdef __cplusplus
}
#endif

#endif
