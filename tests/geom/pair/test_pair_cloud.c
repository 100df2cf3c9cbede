/*
 * test_pair_cloud.c - a point cloud against a mesh or a primitive
 * (geom/pair/pair_cloud.c, geom/mesh/px_mesh_pair.c): the pair's
 * distance against brute force (every point against every triangle,
 * the sign from the closed mesh's own point query; every point's
 * primitive query), on random poses with clouds apart, touching and
 * reaching inside; coherent calls equal cold ones along random paths;
 * through a cut cache (px_pair_distance_cached) the same, also along
 * paths with the cloud replaced (a new model, maybe at the old one's
 * address); no heap call in the calls.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "px_alloc_count.h"
#include "px_cloud.h"
#include "px_mesh.h"
#include "px_pair.h"
#include "px_prim.h"
#include "px_test.h"
#include "px_test_geom.h"

#define NP 300

static px_vec3 rand_dir(void)
{
	px_vec3 v = px_v3(px_rand_normal(), px_rand_normal(), px_rand_normal());
	return px_v3_scale(v, 1.0 / px_v3_norm(v));
}

/* Brute force: the least distance of the mesh over the points (world),
 * negative for a point inside a closed mesh. */
static double brute_mesh(const struct px_model *m, const px_vec3 *w, int n)
{
	double best = INFINITY;
	int i;
	for (i = 0; i < n; i++) {
		px_vec3 l = px_pose_inverse_transform_point(px_model_pose(m), w[i]);
		double d = px_test_mesh_brute(m, l);
		struct px_model_result q;
		PX_CHECK_INT_EQ(px_model_query(m, w[i], &q), 1);
		if (q.is_signed && q.distance < 0.0)
			d = -d;
		best = fmin(best, d);
	}
	return best;
}

/* The result's own consistency: witnesses realise the distance, and an
 * overlap's normal separates (point_a - point_b = depth * normal). */
static void check_result(const struct px_pair_result *r)
{
	PX_CHECK(!r->local_only);
	if (r->distance > 0.0) {
		PX_CHECK(!r->intersecting);
		PX_CHECK(fabs(px_v3_dist(r->point_a, r->point_b) - r->distance) <= 1e-9);
	} else {
		PX_CHECK(r->intersecting);
	}
	if (r->distance < 0.0) {
		px_vec3 e = px_v3_sub(px_v3_sub(r->point_a, r->point_b),
				      px_v3_scale(r->normal, r->depth));
		PX_CHECK(fabs(r->depth + r->distance) <= 1e-15);
		PX_CHECK_MSG(px_v3_norm(e) <= 1e-9, "witnesses off the normal by %g", px_v3_norm(e));
	}
}

/* Cloud points about centre c: half a shell, half a blob; some put on
 * the mesh's surface (touching) when touch. */
static void make_points(const struct px_model *m, px_vec3 c, double rr, int touch, px_vec3 *w,
			double *xyz)
{
	int i;
	for (i = 0; i < NP; i++) {
		px_vec3 d = rand_dir();
		if (i % 2)
			d = px_v3_scale(d, px_rand_unit());
		w[i] = px_v3_madd(c, d, rr);
		if (touch && i < 3) {
			struct px_model_result q;
			PX_CHECK_INT_EQ(px_model_query(m, w[i], &q), 1);
			w[i] = q.point;
		}
		xyz[3 * i] = w[i].x;
		xyz[3 * i + 1] = w[i].y;
		xyz[3 * i + 2] = w[i].z;
	}
}

/* Trial k of the reference tests: a posed mesh (returned) and a cloud
 * *c of NP points (w, xyz) apart from it (k % 3 == 0), through its
 * surface (1) or touching it (2); *ref the brute-force distance. */
static struct px_model *reference_case(int k, px_vec3 *w, double *xyz, struct px_model **c,
				       double *ref)
{
	double rm;
	struct px_model *m = px_test_mesh_shape(k % 4, 1, &rm);
	int mode = k % 3;
	double off = mode == 0 ? rm + px_rand_range(0.35, 1.0) : px_rand_range(0.0, rm);
	px_vec3 cen = px_v3_scale(rand_dir(), off);
	px_model_set_pose(m, px_test_rand_pose(0.5));
	cen = px_pose_transform_point(px_model_pose(m), cen);
	make_points(m, cen, px_rand_range(0.1, 0.3), mode == 2, w, xyz);
	PX_CHECK_INT_EQ(px_cloud_model(xyz, NP, 0.0, NULL, c), PX_OK);
	*ref = brute_mesh(m, w, NP);
	return m;
}

static void test_mesh_cloud_reference(void)
{
	static px_vec3 w[NP];
	static double xyz[3 * NP];
	int trial, apart = 0, inside = 0, touching = 0;
	for (trial = 0; trial < 80; trial++) {
		double ref;
		struct px_model *c, *m = reference_case(trial, w, xyz, &c, &ref);
		struct px_pair_result r, rs;
		memset(&r, 0, sizeof(r));
		memset(&rs, 0, sizeof(rs));
		PX_CHECK_INT_EQ(px_pair_distance(m, c, NULL, &r), PX_OK);
		PX_CHECK_INT_EQ(px_pair_distance(c, m, NULL, &rs), PX_OK);
		PX_CHECK_MSG(fabs(r.distance - ref) <= 1e-9 * (1 + fabs(ref)),
			     "trial %d: %.17g vs brute force %.17g", trial, r.distance, ref);
		PX_CHECK_MSG(fabs(rs.distance - ref) <= 1e-9 * (1 + fabs(ref)),
			     "trial %d (swapped): %.17g vs brute force %.17g", trial, rs.distance, ref);
		check_result(&r);
		check_result(&rs);
		apart += ref > 1e-9;
		inside += ref < -1e-9;
		touching += fabs(ref) <= 1e-9;
		px_model_free(m);
		px_model_free(c);
	}
	PX_CHECK_MSG(apart >= 20 && inside >= 10 && touching >= 5,
		     "%d apart, %d inside, %d touching", apart, inside, touching);
}

/* An open mesh (one square) has no inside: the least unsigned
 * distance, 0 where a point lies on it. */
static void test_open_mesh_cloud(void)
{
	const double v[] = {-0.5, -0.5, 0, 0.5, -0.5, 0, 0.5, 0.5, 0, -0.5, 0.5, 0};
	const uint32_t t[] = {0, 1, 2, 0, 2, 3};
	static px_vec3 w[NP];
	static double xyz[3 * NP];
	struct px_model *m, *c;
	int trial, i;
	PX_CHECK_INT_EQ(px_mesh_model(v, 4, t, 2, NULL, NULL, &m), PX_OK);
	for (trial = 0; trial < 20; trial++) {
		struct px_pair_result r;
		double ref = INFINITY;
		px_model_set_pose(m, px_test_rand_pose(0.3));
		make_points(m, px_v3(px_rand_range(-0.3, 0.3), 0, 0), 0.3, trial % 2, w, xyz);
		PX_CHECK_INT_EQ(px_cloud_model(xyz, NP, 0.0, NULL, &c), PX_OK);
		for (i = 0; i < NP; i++)
			ref = fmin(ref, px_test_mesh_brute(m, px_pose_inverse_transform_point(
								     px_model_pose(m), w[i])));
		memset(&r, 0, sizeof(r));
		PX_CHECK_INT_EQ(px_pair_distance(c, m, NULL, &r), PX_OK);
		PX_CHECK(fabs(r.distance - ref) <= 1e-12);
		check_result(&r);
		px_model_free(c);
	}
	px_model_free(m);
}

/* Coherent (from last call's pair) equals cold along random paths of
 * the mesh through and around the cloud; no heap call. */
static void test_coherent_equals_cold(void)
{
	static px_vec3 w[NP];
	static double xyz[3 * NP];
	struct px_pair_opts co = {1, 0, 0, 1, 0, 0};
	int path, k, neg = 0;
	for (path = 0; path < 8; path++) {
		double rm;
		struct px_model *m = px_test_mesh_shape(path % 4, 1, &rm), *c;
		struct px_pair_result rc, rf;
		px_pose P0 = px_test_rand_pose(0.0), P1 = px_test_rand_pose(0.0);
		px_vec3 a = px_v3_scale(rand_dir(), rm + 0.5), b = px_v3_scale(a, -0.2);
		uint64_t al;
		make_points(m, px_v3(0, 0, 0), 0.25, 0, w, xyz);
		PX_CHECK_INT_EQ(px_cloud_model(xyz, NP, 0.0, NULL, &c), PX_OK);
		memset(&rc, 0, sizeof(rc));
		al = px_alloc_region_begin();
		for (k = 0; k <= 100; k++) {
			double s = k / 100.0;
			px_pose P;
			P.q = px_quat_slerp(P0.q, P1.q, s);
			P.t = px_v3_lerp(a, b, s);
			px_model_set_pose(m, P);
			PX_CHECK_INT_EQ(px_pair_distance(m, c, &co, &rc), PX_OK);
			memset(&rf, 0, sizeof(rf));
			PX_CHECK_INT_EQ(px_pair_distance(m, c, NULL, &rf), PX_OK);
			PX_CHECK_MSG(rc.distance == rf.distance, "path %d step %d: %.17g vs %.17g",
				     path, k, rc.distance, rf.distance);
			PX_CHECK(!rc.local_only);
			neg += rc.distance < 0.0;
		}
		PX_CHECK_INT_EQ(px_alloc_region_end(al), 0);
		px_model_free(m);
		px_model_free(c);
	}
	PX_CHECK_MSG(neg >= 20, "only %d steps with points inside", neg);
}

/* A cloud against primitives: the least of the primitive's exact
 * (signed) point queries over the points, certified. */
static void test_cloud_primitives(void)
{
	static px_vec3 w[NP];
	static double xyz[3 * NP];
	struct px_prim prims[3] = {{PX_PRIM_BOX, 0.3, 0.2, 0.1},
				   {PX_PRIM_CAPSULE, 0.1, 0.3, 0},
				   {PX_PRIM_CYLINDER, 0.15, 0.3, 0}};
	int trial, i, inside = 0;
	for (trial = 0; trial < 60; trial++) {
		struct px_model *o, *c;
		struct px_pair_result r, rs;
		double ref = INFINITY;
		PX_CHECK_INT_EQ(px_prim_model(&prims[trial % 3], &o), PX_OK);
		px_model_set_pose(o, px_test_rand_pose(0.2));
		make_points(o, px_v3_scale(rand_dir(), px_rand_range(0.0, 0.8)), 0.25, trial % 5 == 0,
			    w, xyz);
		PX_CHECK_INT_EQ(px_cloud_model(xyz, NP, 0.0, NULL, &c), PX_OK);
		for (i = 0; i < NP; i++) {
			struct px_model_result q;
			PX_CHECK_INT_EQ(px_model_query(o, w[i], &q), 1);
			ref = fmin(ref, q.distance);
		}
		memset(&r, 0, sizeof(r));
		memset(&rs, 0, sizeof(rs));
		PX_CHECK_INT_EQ(px_pair_distance(c, o, NULL, &r), PX_OK);
		PX_CHECK_INT_EQ(px_pair_distance(o, c, NULL, &rs), PX_OK);
		PX_CHECK_MSG(r.distance == ref && rs.distance == ref, "trial %d: %.17g %.17g vs %.17g",
			     trial, r.distance, rs.distance, ref);
		check_result(&r);
		check_result(&rs);
		inside += ref < 0.0;
		px_model_free(o);
		px_model_free(c);
	}
	PX_CHECK_MSG(inside >= 10, "only %d clouds reaching inside", inside);
}

/* Through a cache, cold and coherent: brute force's distance on random
 * poses with clouds apart, touching and reaching inside (convex and
 * non-convex meshes: the cache's planes bound both). */
static void test_cached_reference(void)
{
	static px_vec3 w[NP];
	static double xyz[3 * NP];
	static struct px_pair_cache pc;
	struct px_pair_opts co = {1, 0, 0, 1, 0, 0};
	int trial, apart = 0, inside = 0;
	for (trial = 0; trial < 60; trial++) {
		double ref;
		struct px_model *c, *m = reference_case(trial, w, xyz, &c, &ref);
		struct px_pair_result r, rs;
		px_pair_cache_init(&pc);
		memset(&r, 0, sizeof(r));
		memset(&rs, 0, sizeof(rs));
		PX_CHECK_INT_EQ(px_pair_distance_cached(c, m, NULL, &pc, &r), PX_OK);
		PX_CHECK_INT_EQ(px_pair_distance_cached(m, c, &co, &pc, &rs), PX_OK);
		PX_CHECK_MSG(fabs(r.distance - ref) <= 1e-9 * (1 + fabs(ref)) &&
				     fabs(rs.distance - ref) <= 1e-9 * (1 + fabs(ref)),
			     "trial %d: %.17g, %.17g vs brute force %.17g", trial, r.distance,
			     rs.distance, ref);
		check_result(&r);
		check_result(&rs);
		apart += ref > 1e-9;
		inside += ref < -1e-9;
		px_model_free(m);
		px_model_free(c);
	}
	PX_CHECK_MSG(apart >= 15 && inside >= 10, "%d apart, %d inside", apart, inside);
}

/* Coherent calls through a cache along random paths of the mesh
 * through and around the cloud, the cloud replaced every 16 steps by a
 * new one (freed first, so the new one may take its address): brute
 * force's distance at every step, the cut reused most steps, no heap
 * call in the calls. */
static void test_cached_paths(void)
{
	static px_vec3 w[NP];
	static double xyz[3 * NP];
	static struct px_pair_cache pc;
	struct px_pair_opts co = {1, 0, 0, 1, 0, 0};
	int path, k, neg = 0;
	uint64_t allocs = 0;
	for (path = 0; path < 8; path++) {
		double rm;
		struct px_model *m = px_test_mesh_shape(path % 4, 1, &rm), *c = NULL;
		struct px_pair_result rc;
		px_pose P0 = px_test_rand_pose(0.0), P1 = px_test_rand_pose(0.0);
		px_vec3 a = px_v3_scale(rand_dir(), rm + 0.5), b = px_v3_scale(a, -0.2);
		px_pair_cache_init(&pc);
		/* half the paths with the planes made at setup */
		if (path % 2)
			px_pair_cache_prepare(&pc, m);
		memset(&rc, 0, sizeof(rc));
		for (k = 0; k <= 160; k++) {
			double s = k / 160.0, ref;
			px_pose P;
			uint64_t al;
			if (k % 16 == 0) {
				px_model_free(c);
				make_points(m, px_v3(0, 0, 0), 0.25, 0, w, xyz);
				PX_CHECK_INT_EQ(px_cloud_model(xyz, NP, 0.0, NULL, &c), PX_OK);
			}
			/* small steps: the cut stays valid over several */
			P.q = px_quat_slerp(P0.q, P1.q, 0.3 * s);
			P.t = px_v3_lerp(a, b, s);
			px_model_set_pose(m, P);
			al = px_alloc_region_begin();
			PX_CHECK_INT_EQ(px_pair_distance_cached(m, c, &co, &pc, &rc), PX_OK);
			allocs += px_alloc_region_end(al);
			ref = brute_mesh(m, w, NP);
			PX_CHECK_MSG(fabs(rc.distance - ref) <= 1e-9 * (1 + fabs(ref)),
				     "path %d step %d: %.17g vs brute force %.17g", path, k,
				     rc.distance, ref);
			PX_CHECK(!rc.local_only);
			neg += rc.distance < 0.0;
		}
		PX_CHECK_MSG(px_pair_cache_reused(&pc) > px_pair_cache_full(&pc),
			     "path %d: cut reused %lu times, made %lu", path,
			     px_pair_cache_reused(&pc), px_pair_cache_full(&pc));
		px_model_free(m);
		px_model_free(c);
	}
	PX_CHECK_INT_EQ(allocs, 0);
	PX_CHECK_MSG(neg >= 20, "only %d steps with points inside", neg);
}

static const struct px_test tests[] = {PX_T(test_mesh_cloud_reference), PX_T(test_open_mesh_cloud),
				       PX_T(test_coherent_equals_cold), PX_T(test_cloud_primitives),
				       PX_T(test_cached_reference), PX_T(test_cached_paths)};
PX_TEST_MAIN(tests)
