/*
 * test_pair_nurbs.c - certified pairs with NURBS surface models
 * (geom/pair/pair_nurbs.c): a bicubic sheet (polynomial and rational)
 * against a mesh, against another sheet and against convex primitives.
 *
 * Reference: dense sampling. Each NURBS surface is sampled on a
 * G x G parameter grid and every sample measured exactly against the
 * other model (mesh: point-triangle over every triangle; primitive: its
 * closed-form query; NURBS: the distance core's certified point query),
 * and every mesh vertex against the NURBS model. Each sample pair is a
 * real pair, so the reference ref is at least the true minimum dmin, and
 * at most dmin + delta, delta the largest distance of a surface point
 * from its nearest sample (bounded by the largest sample cell's
 * diagonal, computed and printed). A certified answer is a real pair
 * (both witnesses on their surfaces, at the reported distance) that is
 * at most eps (1e-6 of the sheet's box diagonal) above dmin, so it must
 * satisfy ref - delta <= distance <= ref + eps; a local minimum in the
 * wrong basin lands far above ref and fails. Random poses include
 * touching and near-parallel sheets; coherent calls along random paths
 * equal cold ones within 2 eps, with no heap call.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mesh_gen.h"
#include "px_alloc_count.h"
#include "px_arena.h"
#include "px_dist.h"
#include "px_mesh.h"
#include "px_nurbs.h"
#include "px_pair.h"
#include "sheet_gen.h"
#include "px_prim.h"
#include "px_test.h"
#include "px_test_geom.h"

#define G 81

static unsigned char arena_mem[1 << 20];
static struct px_arena arena;

/* A wavy bicubic sheet over about [-s, s]^2 with n x n control points,
 * amplitude amp; rational: weights 0.6 to 1.5 over the net. */
static struct px_model *sheet(int n, double s, double amp, int rational,
			      struct px_nurbs_surf *out)
{
	double U[16], xyz[3 * 49], w[49];
	struct px_model *m = NULL;
	px_arena_init(&arena, arena_mem, sizeof(arena_mem));
	sheet_net(n, s, amp, U, xyz, w);
	PX_CHECK_INT_EQ(px_nurbs_surf_init(out, &arena, 3, 3, n, n, U, n + 4, U, n + 4, xyz,
					   rational ? w : NULL, NULL),
			PX_OK);
	PX_CHECK_INT_EQ(px_nurbs_model_create(NULL, 0, out, 1, NULL, &m), PX_OK);
	return m;
}

/* World samples of the sheet (model m, surface s) on a G x G grid, and
 * the largest cell diagonal (delta). */
static double samples(const struct px_model *m, const struct px_nurbs_surf *s, px_vec3 *w)
{
	double u0 = s->knots[0][s->degree[0]], u1 = s->knots[0][s->n_ctrl[0]];
	double v0 = s->knots[1][s->degree[1]], v1 = s->knots[1][s->n_ctrl[1]], delta = 0.0;
	int i, j;
	for (i = 0; i < G; i++)
		for (j = 0; j < G; j++) {
			struct px_nurbs_surf_derivs d;
			PX_CHECK_INT_EQ(px_nurbs_surf_eval(s, u0 + (u1 - u0) * i / (G - 1),
							   v0 + (v1 - v0) * j / (G - 1), 0, &d),
					PX_OK);
			w[i * G + j] = px_pose_transform_point(px_model_pose(m), d.s);
		}
	for (i = 0; i + 1 < G; i++)
		for (j = 0; j + 1 < G; j++)
			delta = fmax(delta, fmax(px_v3_dist(w[i * G + j], w[(i + 1) * G + j + 1]),
						 px_v3_dist(w[(i + 1) * G + j], w[i * G + j + 1])));
	return delta;
}

/* The least distance of model o over world points w[0..n). */
static double min_over(const struct px_model *o, const px_vec3 *w, int n)
{
	double best = INFINITY;
	int i;
	for (i = 0; i < n; i++) {
		struct px_model_result q;
		PX_CHECK_INT_EQ(px_model_query_ex(o, w[i], INFINITY, -1, PX_QUERY_UNSIGNED, &q),
				1);
		best = fmin(best, q.distance);
	}
	return best;
}

/* The answer's witnesses lie on their surfaces at the reported
 * distance. */
static void check_real_pair(const struct px_model *a, const struct px_model *b,
			    const struct px_pair_result *r)
{
	struct px_model_result qa, qb;
	PX_CHECK_INT_EQ(px_model_query_ex(a, r->point_a, INFINITY, -1, PX_QUERY_UNSIGNED, &qa),
			1);
	PX_CHECK_INT_EQ(px_model_query_ex(b, r->point_b, INFINITY, -1, PX_QUERY_UNSIGNED, &qb),
			1);
	PX_CHECK_MSG(qa.distance < 1e-9 && qb.distance < 1e-9, "witnesses off: %.3g %.3g",
		     qa.distance, qb.distance);
	PX_CHECK(fabs(px_v3_dist(r->point_a, r->point_b) - r->distance) <= 1e-12);
}

static px_vec3 rand_dir(void)
{
	px_vec3 v = px_v3(px_rand_normal(), px_rand_normal(), px_rand_normal());
	return px_v3_scale(v, 1.0 / px_v3_norm(v));
}

static px_vec3 sw[G * G], sw2[G * G];

/* One pose: the pair answered, compared with the reference. Returns 1
 * when it was a separated certified pair. */
static int check_pair(const struct px_model *a, const struct px_model *b, double ref,
		      double delta, double eps, const char *what, int trial)
{
	struct px_pair_result r;
	memset(&r, 0, sizeof(r));
	PX_CHECK_INT_EQ(px_pair_distance(a, b, NULL, &r), PX_OK);
	if (ref <= delta)
		return 0; /* touching or overlapping within the sampling */
	PX_CHECK_MSG(!r.intersecting && !r.local_only, "%s %d: intersecting %d local_only %d",
		     what, trial, r.intersecting, r.local_only);
	PX_CHECK_MSG(r.distance <= ref + eps && r.distance >= ref - delta,
		     "%s %d: %.12g vs reference %.12g (delta %.3g)", what, trial, r.distance, ref,
		     delta);
	check_real_pair(a, b, &r);
	return 1;
}

static void test_sheet_vs_mesh(void)
{
	struct px_nurbs_surf s;
	int rational, trial, ok = 0;
	double dmax = 0.0;
	for (rational = 0; rational < 2; rational++) {
		struct px_model *a = sheet(7, 0.5, 0.35, rational, &s);
		px_aabb box = px_model_local_aabb(a);
		double eps = 1e-6 * px_aabb_diagonal(&box);
		for (trial = 0; trial < 12; trial++) {
			double rad, delta, ref;
			struct px_model *b = px_test_mesh_shape(trial % 4, 2, &rad);
			size_t nt = px_mesh_triangle_count(b), k;
			px_pose pb = px_test_rand_pose(0.0);
			pb.t = px_v3_scale(rand_dir(), 0.5 + rad * (0.8 + 0.8 * px_rand_unit()));
			if (trial % 3 == 0) /* just above the sheet */
				pb.t = px_v3(0.1 * px_rand_normal(), 0.1 * px_rand_normal(),
					     0.2 + rad);
			px_model_set_pose(b, pb);
			px_model_set_pose(a, px_test_rand_pose(0.05));
			delta = samples(a, &s, sw);
			ref = min_over(b, sw, G * G);
			for (k = 0; k < nt; k++) {
				px_vec3 v[3];
				int c;
				PX_CHECK_INT_EQ(px_mesh_triangle(b, k, v), PX_OK);
				for (c = 0; c < 3; c++)
					v[c] = px_pose_transform_point(pb, v[c]);
				ref = fmin(ref, min_over(a, v, 3));
			}
			dmax = fmax(dmax, delta);
			if (trial == 0)
				printf("rational %d delta %.4g\n", rational, delta);
			ok += check_pair(a, b, ref, delta, eps, "sheet/mesh", trial);
			ok += check_pair(b, a, ref, delta, eps, "mesh/sheet", trial);
			px_model_free(b);
		}
		px_model_free(a);
	}
	printf("sheet/mesh: %d separated pairs certified; sampling bound delta <= %.3g\n", ok, dmax);
	PX_CHECK_MSG(ok >= 30, "only %d separated pairs", ok);
}

static void test_sheet_vs_sheet(void)
{
	struct px_nurbs_surf sa, sb;
	int trial, ok = 0;
	for (trial = 0; trial < 16; trial++) {
		/* each model copies its surface: the arena is reused */
		struct px_model *a = sheet(7, 0.5, 0.35, trial & 1, &sa);
		struct px_model *b;
		px_aabb box = px_model_local_aabb(a);
		double eps = 1e-6 * px_aabb_diagonal(&box), delta, ref;
		px_pose pb = px_test_rand_pose(0.0);
		delta = samples(a, &sa, sw);
		b = sheet(5, 0.4, trial % 4 == 3 ? 0.02 : 0.3, 0, &sb);
		if (trial % 4 == 0) {
			/* near-parallel: tilted by a few degrees, a small gap */
			px_quat_from_axis_angle(rand_dir(), 0.05 * px_rand_unit(), &pb.q);
			pb.t = px_v3(0.1 * px_rand_normal(), 0.1 * px_rand_normal(),
				     0.2 + 0.05 * px_rand_unit());
		} else if (trial % 4 == 1) {
			/* nearly touching */
			pb.t = px_v3_scale(rand_dir(), 0.6);
		} else {
			pb.t = px_v3_scale(rand_dir(), 0.5 + 0.8 * px_rand_unit());
		}
		px_model_set_pose(b, pb);
		delta = fmax(delta, samples(b, &sb, sw2));
		ref = fmin(min_over(b, sw, G * G), min_over(a, sw2, G * G));
		ok += check_pair(a, b, ref, delta, eps, "sheet/sheet", trial);
		px_model_free(a);
		px_model_free(b);
	}
	printf("sheet/sheet: %d separated pairs certified\n", ok);
	PX_CHECK_MSG(ok >= 8, "only %d separated pairs", ok);
}

static void test_sheet_vs_primitive(void)
{
	struct px_nurbs_surf s;
	int trial, ok = 0;
	struct px_model *a = sheet(7, 0.5, 0.35, 0, &s);
	px_aabb box = px_model_local_aabb(a);
	double eps = 1e-6 * px_aabb_diagonal(&box);
	for (trial = 0; trial < 16; trial++) {
		static const struct px_prim prims[3] = {{PX_PRIM_BOX, 0.1, 0.2, 0.15},
							{PX_PRIM_CAPSULE, 0.08, 0.3, 0},
							{PX_PRIM_CYLINDER, 0.1, 0.25, 0}};
		struct px_model *b = NULL;
		double delta, ref;
		px_pose pb = px_test_rand_pose(0.0);
		PX_CHECK_INT_EQ(px_prim_model(&prims[trial % 3], &b), PX_OK);
		pb.t = px_v3_scale(rand_dir(), 0.5 + 0.6 * px_rand_unit());
		px_model_set_pose(b, pb);
		delta = samples(a, &s, sw);
		ref = min_over(b, sw, G * G);
		ok += check_pair(a, b, ref, delta, eps, "sheet/primitive", trial);
		ok += check_pair(b, a, ref, delta, eps, "primitive/sheet", trial);
		px_model_free(b);
	}
	px_model_free(a);
	printf("sheet/primitive: %d separated pairs certified\n", ok);
	PX_CHECK_MSG(ok >= 16, "only %d separated pairs", ok);
}

/* Coherent calls along random paths equal cold ones (both within eps
 * of the minimum), certified, with no heap call. */
static void test_coherent_equals_cold(void)
{
	struct px_nurbs_surf sa, sb;
	struct px_model *a = sheet(7, 0.5, 0.35, 1, &sa), *b = sheet(5, 0.4, 0.3, 0, &sb);
	struct px_model *m;
	px_aabb box = px_model_local_aabb(a);
	double eps = 1e-6 * px_aabb_diagonal(&box), rad;
	struct px_pair_opts co = {1, 0, 0, 1, 0, 0};
	int side, i, agree = 0, n = 0;
	m = px_test_mesh_shape(0, 2, &rad);
	for (side = 0; side < 2; side++) {
		struct px_model *o = side ? m : b;
		struct px_pair_result rc, rf;
		px_vec3 dir = rand_dir(), axis = rand_dir();
		uint64_t al;
		memset(&rc, 0, sizeof(rc));
		memset(&rf, 0, sizeof(rf));
		for (i = 0; i < 150; i++) {
			px_pose P;
			double t = 0.02 * i;
			px_quat_from_axis_angle(axis, 0.5 * t, &P.q);
			P.t = px_v3_scale(px_v3_add(dir, px_v3(0.3 * sin(t), 0.2 * cos(1.3 * t), 0.0)),
					  (side ? 0.5 + rad : 0.75) + 0.1 * sin(2.0 * t));
			px_model_set_pose(o, P);
			al = px_alloc_region_begin();
			PX_CHECK_INT_EQ(px_pair_distance(a, o, &co, &rc), PX_OK);
			PX_CHECK_INT_EQ(px_alloc_region_end(al), 0);
			PX_CHECK_INT_EQ(px_pair_distance(a, o, NULL, &rf), PX_OK);
			if (rf.intersecting)
				continue;
			n++;
			PX_CHECK(!rc.local_only && !rf.local_only);
			agree += fabs(rc.distance - rf.distance) <= 2.0 * eps;
		}
	}
	PX_CHECK_MSG(agree == n && n >= 200, "coherent agreed %d of %d", agree, n);
	px_model_free(a);
	px_model_free(b);
	px_model_free(m);
}

static const struct px_test tests[] = {PX_T(test_sheet_vs_mesh), PX_T(test_sheet_vs_sheet),
				       PX_T(test_sheet_vs_primitive),
				       PX_T(test_coherent_equals_cold)};
PX_TEST_MAIN(tests)
