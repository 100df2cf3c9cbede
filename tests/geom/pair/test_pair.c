/*
 * Model-to-model distance by alternating projections.
 *
 * References: for mesh pairs, the exact minimum over all triangle pairs
 * (for separated triangles, the minimum of the six vertex-triangle and
 * nine edge-edge distances); for a cloud, the minimum over its points of
 * the exact point distance; for sphere and capsule pairs, closed forms.
 * The global-hit rate over random pairs is printed; every miss must be
 * flagged local_only, and convex pairs must never miss.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mesh_gen.h"
#include "px_alloc_count.h"
#include "px_cloud.h"
#include "px_mesh.h"
#include "px_pair.h"
#include "px_prim.h"
#include "px_test.h"
#include "px_test_geom.h"

static px_pose rand_rot_pose(px_vec3 t)
{
	px_pose P;
	P.q = px_test_rand_quat();
	P.t = t;
	return P;
}

static px_vec3 rand_dir(void)
{
	px_vec3 v = px_v3(px_rand_normal(), px_rand_normal(), px_rand_normal());
	return px_v3_scale(v, 1.0 / px_v3_norm(v));
}

/* Closest points of segments p1q1 and p2q2 (Ericson 5.1.9); squared
 * distance. */
static double seg_seg(px_vec3 p1, px_vec3 q1, px_vec3 p2, px_vec3 q2)
{
	px_vec3 d1 = px_v3_sub(q1, p1), d2 = px_v3_sub(q2, p2), r = px_v3_sub(p1, p2);
	double a = px_v3_dot(d1, d1), e = px_v3_dot(d2, d2), f = px_v3_dot(d2, r);
	double s, t;
	if (a <= 1e-30 && e <= 1e-30)
		return px_v3_dist2(p1, p2);
	if (a <= 1e-30) {
		s = 0;
		t = fmin(1, fmax(0, f / e));
	} else {
		double c = px_v3_dot(d1, r);
		if (e <= 1e-30) {
			t = 0;
			s = fmin(1, fmax(0, -c / a));
		} else {
			double b = px_v3_dot(d1, d2), den = a * e - b * b;
			s = den > 0 ? fmin(1, fmax(0, (b * f - c * e) / den)) : 0;
			t = (b * s + f) / e;
			if (t < 0) {
				t = 0;
				s = fmin(1, fmax(0, -c / a));
			} else if (t > 1) {
				t = 1;
				s = fmin(1, fmax(0, (b - c) / a));
			}
		}
	}
	return px_v3_dist2(px_v3_madd(p1, d1, s), px_v3_madd(p2, d2, t));
}

/* Exact distance between two meshes in their poses (separated). */
static double brute_mesh_mesh(const struct px_model *a, const struct px_model *b)
{
	size_t na = px_mesh_triangle_count(a), nb = px_mesh_triangle_count(b), i, j;
	px_vec3 *A = malloc(3 * na * sizeof(px_vec3)), *B = malloc(3 * nb * sizeof(px_vec3));
	double best = INFINITY;
	int k, l;
	for (i = 0; i < na; i++) {
		px_mesh_triangle(a, i, A + 3 * i);
		for (k = 0; k < 3; k++)
			A[3 * i + k] = px_pose_transform_point(px_model_pose(a), A[3 * i + k]);
	}
	for (j = 0; j < nb; j++) {
		px_mesh_triangle(b, j, B + 3 * j);
		for (k = 0; k < 3; k++)
			B[3 * j + k] = px_pose_transform_point(px_model_pose(b), B[3 * j + k]);
	}
	for (i = 0; i < na; i++)
		for (j = 0; j < nb; j++) {
			const px_vec3 *T = A + 3 * i, *U = B + 3 * j;
			for (k = 0; k < 3; k++) {
				best = fmin(best, px_tri_closest(T[k], U[0], U[1], U[2], NULL, NULL, NULL, NULL, NULL));
				best = fmin(best, px_tri_closest(U[k], T[0], T[1], T[2], NULL, NULL, NULL, NULL, NULL));
				for (l = 0; l < 3; l++)
					best = fmin(best, seg_seg(T[k], T[(k + 1) % 3], U[l], U[(l + 1) % 3]));
			}
		}
	free(A);
	free(B);
	return sqrt(best);
}

static void check_pair_result(const struct px_model *a, const struct px_model *b,
			      const struct px_pair_result *r)
{
	struct px_model_result qa, qb;
	PX_CHECK_NEAR(px_v3_dist(r->point_a, r->point_b), r->distance, 1e-9);
	px_model_query_ex(a, r->point_a, INFINITY, -1, PX_QUERY_UNSIGNED, &qa);
	px_model_query_ex(b, r->point_b, INFINITY, -1, PX_QUERY_UNSIGNED, &qb);
	PX_CHECK_NEAR(qa.distance, 0.0, 1e-9);
	PX_CHECK_NEAR(qb.distance, 0.0, 1e-9);
}

static void test_mesh_pairs_hit_rate(void)
{
	int trial, hits = 0, misses = 0, flagged_hits = 0, n = 240;
	struct px_pair_opts o = {8, 64, 1e-12, 0, 0, 0};
	for (trial = 0; trial < n; trial++) {
		double ra, rb, ref, sep;
		struct px_model *a = px_test_mesh_shape(trial % 4, 1, &ra);
		struct px_model *b = px_test_mesh_shape((trial / 4) % 4, 1, &rb);
		struct px_pair_result r;
		px_vec3 dir = rand_dir();
		memset(&r, 0, sizeof(r));
		sep = ra + rb + px_rand_range(0.01, 0.8);
		px_model_set_pose(a, rand_rot_pose(px_v3(0, 0, 0)));
		px_model_set_pose(b, rand_rot_pose(px_v3_scale(dir, sep)));
		PX_CHECK_INT_EQ(px_pair_distance(a, b, &o, &r), PX_OK);
		ref = brute_mesh_mesh(a, b);
		check_pair_result(a, b, &r);
		PX_CHECK_MSG(r.distance >= ref - 1e-9, "below the true minimum: %.15g < %.15g",
			     r.distance, ref);
		PX_CHECK(!r.intersecting);
		/* mesh pairs are exact now: equal within 1e-9 relative */
		PX_CHECK_MSG(fabs(r.distance - ref) <= 1e-9 * ref, "mesh pair %.17g vs %.17g",
			     r.distance, ref);
		PX_CHECK(!r.local_only);
		if (r.distance <= ref + 1e-6) {
			hits++;
			flagged_hits += r.local_only;
		} else {
			misses++;
			PX_CHECK_MSG(r.local_only, "unflagged miss: %.9g vs %.9g", r.distance, ref);
		}
		if ((trial % 4) == 2 && ((trial / 4) % 4) == 2) /* box-box: convex */
			PX_CHECK_MSG(r.distance <= ref + 1e-6, "convex pair missed: %.12g vs %.12g",
				     r.distance, ref);
		px_model_free(a);
		px_model_free(b);
	}
	printf("    mesh pairs: %d of %d global (%.1f %%), %d local minima (all flagged); "
	       "%d global hits flagged as possibly local\n",
	       hits, n, 100.0 * hits / n, misses, flagged_hits);
	PX_CHECK_MSG(hits == n, "global-hit rate %.3f", (double)hits / n);
}

static double seg_pt_dist(px_vec3 a, px_vec3 b, px_vec3 p)
{
	return sqrt(seg_seg(a, b, p, p));
}

static void test_convex_primitive_pairs(void)
{
	int trial, pen_checked = 0, pen_approx = 0;
	for (trial = 0; trial < 300; trial++) {
		struct px_prim s1 = {PX_PRIM_SPHERE, px_rand_range(0.1, 1), 0, 0};
		struct px_prim c1 = {PX_PRIM_CAPSULE, px_rand_range(0.05, 0.5), px_rand_range(0.1, 1), 0};
		struct px_prim c2 = {PX_PRIM_CAPSULE, px_rand_range(0.05, 0.5), px_rand_range(0.1, 1), 0};
		struct px_prim bx = {PX_PRIM_BOX, px_rand_range(0.1, 1), px_rand_range(0.1, 1), px_rand_range(0.1, 1)};
		struct px_model *a, *b;
		struct px_pair_result r;
		px_pose Pa = rand_rot_pose(px_v3(0, 0, 0)), Pb;
		double ref;
		int kind = trial % 3;
		memset(&r, 0, sizeof(r));
		Pb = rand_rot_pose(px_v3_scale(rand_dir(), px_rand_range(0.2, 4)));
		if (kind == 0) {
			px_prim_model(&s1, &a);
			px_prim_model(&bx, &b);
		} else if (kind == 1) {
			px_prim_model(&c1, &a);
			px_prim_model(&c2, &b);
		} else {
			px_prim_model(&s1, &a);
			px_prim_model(&c2, &b);
		}
		px_model_set_pose(a, Pa);
		px_model_set_pose(b, Pb);
		if (kind == 0) {
			struct px_model_result q;
			px_model_query(b, Pa.t, &q);
			ref = q.distance - s1.a;
		} else if (kind == 1) {
			px_vec3 a0 = px_pose_transform_point(Pa, px_v3(0, 0, -c1.b));
			px_vec3 a1 = px_pose_transform_point(Pa, px_v3(0, 0, c1.b));
			px_vec3 b0 = px_pose_transform_point(Pb, px_v3(0, 0, -c2.b));
			px_vec3 b1 = px_pose_transform_point(Pb, px_v3(0, 0, c2.b));
			ref = sqrt(seg_seg(a0, a1, b0, b1)) - c1.a - c2.a;
		} else {
			px_vec3 b0 = px_pose_transform_point(Pb, px_v3(0, 0, -c2.b));
			px_vec3 b1 = px_pose_transform_point(Pb, px_v3(0, 0, c2.b));
			ref = seg_pt_dist(b0, b1, Pa.t) - s1.a - c2.a;
		}
		PX_CHECK_INT_EQ(px_pair_distance(a, b, NULL, &r), PX_OK);
		if (ref <= 0) {
			/* penetration depth: the closed forms hold inside too
			 * (radius sums minus the core distance) */
			PX_CHECK_MSG(r.intersecting, "kind %d: overlap missed (%g)", kind, ref);
			PX_CHECK(!r.local_only);
			PX_CHECK_MSG(fabs(r.distance - ref) <= (r.depth_approx ? 2e-3 : 1e-6),
				     "kind %d: depth %.12g vs %.12g (approx %d)", kind, -r.distance,
				     -ref, r.depth_approx);
			pen_checked++;
			pen_approx += r.depth_approx;
			PX_CHECK_NEAR(r.depth, -r.distance, 0.0);
			PX_CHECK_NEAR(px_v3_norm(r.normal), 1.0, 1e-9);
			PX_CHECK_MSG(px_v3_dist(px_v3_sub(r.point_a, r.point_b),
						px_v3_scale(r.normal, r.depth)) <= 1e-6,
				     "kind %d: witness points do not span the depth", kind);
		} else {
			PX_CHECK_MSG(!r.intersecting, "kind %d: intersecting, reference %g", kind, ref);
			check_pair_result(a, b, &r);
			PX_CHECK_MSG(fabs(r.distance - ref) <= 1e-6, "kind %d: %.12g vs %.12g",
				     kind, r.distance, ref);
			if (r.converged)
				PX_CHECK(!r.local_only);
		}
		px_model_free(a);
		px_model_free(b);
	}
	printf("    %d overlapping pairs, depth exact in %d\n", pen_checked,
	       pen_checked - pen_approx);
}

/* Rings over the profile of a cylinder or cone, arc spacing <= h. */
static int sample_frustum(const struct px_prim *p, double h, px_vec3 *out, int cap)
{
	double r0 = p->a, r1 = p->type == PX_PRIM_CONE ? p->c : p->a;
	double P[4][2] = {{0, -p->b}, {r0, -p->b}, {r1, p->b}, {0, p->b}};
	int e, n = 0;
	for (e = 0; e < 3; e++) {
		double L = hypot(P[e + 1][0] - P[e][0], P[e + 1][1] - P[e][1]);
		int ns = (int)ceil(L / h), i;
		for (i = 0; i <= ns; i++) {
			double t = (double)i / ns, rr = P[e][0] + t * (P[e + 1][0] - P[e][0]);
			double z = P[e][1] + t * (P[e + 1][1] - P[e][1]);
			int na = rr > 0 ? (int)ceil(2 * M_PI * rr / h) : 1, j;
			for (j = 0; j < na && n < cap; j++)
				out[n++] = px_v3(rr * cos(2 * M_PI * j / na), rr * sin(2 * M_PI * j / na), z);
		}
	}
	return n;
}

static void test_gjk_convex_primitives(void)
{
	/* GJK through support functions against the densest reference we
	 * can afford: every sample of A's surface queried exactly on B. */
	const double h = 0.01;
	int cap = 200000, trial;
	px_vec3 *S = malloc((size_t)cap * sizeof(px_vec3));
	for (trial = 0; trial < 60; trial++) {
		struct px_prim A = {trial % 2 ? PX_PRIM_CONE : PX_PRIM_CYLINDER,
				    px_rand_range(0.1, 0.4), px_rand_range(0.1, 0.4), 0};
		struct px_prim Bs[4] = {{PX_PRIM_BOX, px_rand_range(0.1, 0.4), px_rand_range(0.1, 0.4), px_rand_range(0.1, 0.4)},
					{PX_PRIM_CAPSULE, px_rand_range(0.05, 0.3), px_rand_range(0.1, 0.4), 0},
					{PX_PRIM_CYLINDER, px_rand_range(0.05, 0.3), px_rand_range(0.1, 0.4), 0},
					{PX_PRIM_CONE, px_rand_range(0.05, 0.3), px_rand_range(0.1, 0.4), px_rand_range(0.0, 0.2)}};
		struct px_prim B = Bs[(trial / 2) % 4];
		struct px_model *ma, *mb;
		struct px_pair_result r;
		px_pose Pa = rand_rot_pose(px_v3(0, 0, 0));
		double ref = INFINITY;
		int n, i;
		if (A.type == PX_PRIM_CONE)
			A.c = trial % 4 == 1 ? 0.0 : px_rand_range(0.0, 0.3);
		memset(&r, 0, sizeof(r));
		PX_CHECK_INT_EQ(px_prim_model(&A, &ma), PX_OK);
		PX_CHECK_INT_EQ(px_prim_model(&B, &mb), PX_OK);
		px_model_set_pose(ma, Pa);
		px_model_set_pose(mb, rand_rot_pose(px_v3_scale(rand_dir(), px_rand_range(0.3, 1.5))));
		n = sample_frustum(&A, h, S, cap);
		for (i = 0; i < n; i++) {
			struct px_model_result q;
			px_model_query(mb, px_pose_transform_point(Pa, S[i]), &q);
			ref = fmin(ref, q.distance);
		}
		PX_CHECK_INT_EQ(px_pair_distance(ma, mb, NULL, &r), PX_OK);
		if (ref <= -h) {
			PX_CHECK_MSG(r.intersecting, "trial %d: overlap (%g) missed", trial, ref);
		} else if (ref > h) {
			PX_CHECK_MSG(!r.intersecting, "trial %d (%d vs %d): intersecting, sampled %g, %d iterations",
				     trial, A.type, B.type, ref, r.iterations);
			check_pair_result(ma, mb, &r);
			PX_CHECK_MSG(r.distance <= ref + 1e-9 && r.distance >= ref - h,
				     "trial %d (%d vs %d): %.12g vs sampled %.12g", trial, A.type,
				     B.type, r.distance, ref);
			PX_CHECK(!r.local_only);
		}
		px_model_free(ma);
		px_model_free(mb);
	}
	free(S);
}

/* Support value of a world-posed model along n. */
static double hsup(const struct px_model *m, px_vec3 n)
{
	px_vec3 s;
	px_model_support(m, n, &s);
	return px_v3_dot(s, n);
}

/* Penetration depth of two convex models: the smallest h_A(n) + h_B(-n)
 * over directions n (the origin's distance to the boundary of A - B).
 * For boxes the candidates of the separating-axis theorem (3 + 3 face
 * normals, 9 edge cross products) contain the minimiser: exact. */
static double sat_depth(const struct px_model *a, const struct px_model *b,
			const px_vec3 *axes, int n)
{
	double best = INFINITY;
	int i;
	for (i = 0; i < n; i++) {
		px_vec3 u;
		if (px_v3_normalize(axes[i], px_v3(0, 0, 0), &u) != PX_OK)
			continue;
		best = fmin(best, fmin(hsup(a, u) + hsup(b, px_v3_neg(u)),
				       hsup(a, px_v3_neg(u)) + hsup(b, u)));
	}
	return best;
}

static void test_penetration_convex(void)
{
	/* Boxes: EPA against the separating-axis reference (exact). Then
	 * cylinders and cones (curved): against a dense direction search,
	 * and by moving B along the normal: depth + 1e-6 separates, depth -
	 * 1e-3 does not. */
	int trial, n_box = 0, n_curved = 0, n_gap = 0;
	for (trial = 0; trial < 200; trial++) {
		int curved = trial >= 120;
		struct px_prim A = {PX_PRIM_BOX, px_rand_range(0.1, 0.5), px_rand_range(0.1, 0.5), px_rand_range(0.1, 0.5)};
		struct px_prim B = {PX_PRIM_BOX, px_rand_range(0.1, 0.5), px_rand_range(0.1, 0.5), px_rand_range(0.1, 0.5)};
		struct px_model *ma, *mb;
		struct px_pair_result r;
		px_pose Pa = rand_rot_pose(px_v3(0, 0, 0)), Pb;
		double ref;
		if (curved) {
			A.type = trial % 2 ? PX_PRIM_CYLINDER : PX_PRIM_CONE;
			B.type = trial % 3 ? PX_PRIM_CYLINDER : PX_PRIM_BOX;
			if (A.type == PX_PRIM_CONE)
				A.c = px_rand_range(0.0, 0.2);
		}
		Pb = rand_rot_pose(px_v3_scale(rand_dir(), px_rand_range(0.0, 0.4)));
		PX_CHECK_INT_EQ(px_prim_model(&A, &ma), PX_OK);
		PX_CHECK_INT_EQ(px_prim_model(&B, &mb), PX_OK);
		px_model_set_pose(ma, Pa);
		px_model_set_pose(mb, Pb);
		memset(&r, 0, sizeof(r));
		{
			uint64_t a0 = px_alloc_region_begin();
			PX_CHECK_INT_EQ(px_pair_distance(ma, mb, NULL, &r), PX_OK);
			PX_CHECK_INT_EQ(px_alloc_region_end(a0), 0);
		}
		if (!r.intersecting) {
			PX_CHECK(r.distance > 0.0 && r.depth == 0.0);
			px_model_free(ma);
			px_model_free(mb);
			continue;
		}
		PX_CHECK(!r.local_only);
		PX_CHECK_NEAR(r.depth, -r.distance, 0.0);
		PX_CHECK_NEAR(px_v3_norm(r.normal), 1.0, 1e-9);
		PX_CHECK(px_v3_dist(px_v3_sub(r.point_a, r.point_b),
				    px_v3_scale(r.normal, r.depth)) <= 1e-6);
		if (!r.depth_approx) {
			/* converged: the witnesses lie on their own surfaces
			 * (px_pair.h) */
			struct px_model_result qa, qb;
			PX_CHECK(px_model_query(ma, r.point_a, &qa) >= 0);
			PX_CHECK(px_model_query(mb, r.point_b, &qb) >= 0);
			PX_CHECK_MSG(fabs(qa.distance) <= 1e-7 && fabs(qb.distance) <= 1e-7,
				     "pair %d (curved %d, approx %d): witnesses %.3g and %.3g off their surfaces",
				     trial, curved, r.depth_approx, qa.distance, qb.distance);
		}
		if (!curved) {
			px_vec3 ax[15];
			int i, j, k = 0;
			for (i = 0; i < 3; i++) {
				px_vec3 e = px_v3(i == 0, i == 1, i == 2);
				ax[k++] = px_quat_rotate(Pa.q, e);
				ax[k++] = px_quat_rotate(Pb.q, e);
			}
			for (i = 0; i < 3; i++)
				for (j = 0; j < 3; j++)
					ax[k++] = px_v3_cross(ax[2 * i], ax[2 * j + 1]);
			ref = sat_depth(ma, mb, ax, k);
			PX_CHECK_MSG(fabs(r.depth - ref) <= 1e-9 && !r.depth_approx,
				     "box pair %d: depth %.15g vs SAT %.15g (approx %d)", trial,
				     r.depth, ref, r.depth_approx);
			n_box++;
		} else {
			/* dense directions, then the normal found: the reference
			 * is an upper bound of the true depth */
			static px_vec3 dirs[4000];
			int i;
			for (i = 0; i < 4000; i++)
				dirs[i] = rand_dir();
			dirs[0] = r.normal;
			ref = sat_depth(ma, mb, dirs, 4000);
			PX_CHECK_MSG(r.depth <= ref + 1e-9,
				     "pair %d: depth %.12g above a direction's %.12g", trial, r.depth, ref);
			PX_CHECK_MSG(r.depth >= ref - 0.02 * ref - 1e-9,
				     "pair %d: depth %.12g far below the sampled %.12g", trial, r.depth,
				     ref);
			n_curved++;
		}
		{
			/* moving B out along the normal by the depth separates */
			struct px_pair_result s2;
			px_pose P2 = Pb;
			P2.t = px_v3_madd(Pb.t, r.normal, r.depth + 1e-6);
			px_model_set_pose(mb, P2);
			memset(&s2, 0, sizeof(s2));
			PX_CHECK_INT_EQ(px_pair_distance(ma, mb, NULL, &s2), PX_OK);
			/* converged: depth within 1e-9 relative; otherwise an
			 * upper bound within a few 1e-3. (The pair distance of
			 * curved bodies almost in contact is itself good to
			 * about 1e-6: alternating projections slow down there.) */
			PX_CHECK_MSG(!s2.intersecting &&
					     s2.distance <= 3e-6 + (r.depth_approx ? 5e-3 : 1e-8) * r.depth,
				     "pair %d: moved by depth %.9g (approx %d): intersecting %d, distance %.3g",
				     trial, r.depth, r.depth_approx, s2.intersecting, s2.distance);
			/* near contact the distance is certified by GJK's
			 * bounds, and the witnesses are on the surfaces, at
			 * most witness_gap longer than it */
			PX_CHECK_MSG(s2.converged && !s2.local_only && s2.witness_gap >= 0.0 &&
					     fabs(px_v3_dist(s2.point_a, s2.point_b) -
						  (s2.distance + s2.witness_gap)) <= 1e-12,
				     "pair %d: converged %d, gap %.3g", trial, s2.converged,
				     s2.witness_gap);
			if (s2.witness_gap > 0.0)
				n_gap++;
			P2.t = px_v3_madd(Pb.t, r.normal, r.depth - 1e-3);
			px_model_set_pose(mb, P2);
			PX_CHECK_INT_EQ(px_pair_distance(ma, mb, NULL, &s2), PX_OK);
			PX_CHECK_MSG(s2.intersecting || r.depth < 1e-3,
				     "pair %d: moved by less than the depth, yet apart", trial);
		}
		px_model_free(ma);
		px_model_free(mb);
	}
	printf("    penetration: %d box pairs against SAT, %d curved pairs; %d separated pairs "
	       "with witnesses longer than the distance\n", n_box, n_curved, n_gap);
	PX_CHECK(n_box > 20 && n_curved > 10);
}

/* Smallest signed distance to m of points spread over every triangle of
 * mesh src (k + 1 choose 2 barycentric samples each). */
static double min_over_surface(const struct px_model *src, const struct px_model *m,
			       int k)
{
	size_t t, n = px_mesh_triangle_count(src);
	px_pose P = px_model_pose(src);
	double best = INFINITY;
	for (t = 0; t < n; t++) {
		px_vec3 v[3];
		int i, j;
		px_mesh_triangle(src, t, v);
		for (i = 0; i < 3; i++)
			v[i] = px_pose_transform_point(P, v[i]);
		for (i = 0; i <= k; i++)
			for (j = 0; i + j <= k; j++) {
				struct px_model_result q;
				double u = (double)i / k, w = (double)j / k;
				px_vec3 x = px_v3_add(px_v3_scale(v[0], 1 - u - w),
						      px_v3_add(px_v3_scale(v[1], u),
								px_v3_scale(v[2], w)));
				px_model_query(m, x, &q);
				best = fmin(best, q.distance);
			}
	}
	return best;
}

static void test_penetration_meshes(void)
{
	/* Non-convex closed pairs (torus mesh against sphere and box meshes):
	 * the deepest point of either surface inside the other, against
	 * the brute force over points spread over every triangle of both (a
	 * lower bound of the true deepest point). */
	struct gen_mesh gt, gs, gb;
	struct px_model *tor, *sph, *box;
	const double hb[3] = {0.08, 0.05, 0.12};
	int trial, hits = 0, total = 0;
	PX_CHECK(gen_torus(0.3, 0.1, 64, 32, &gt) == 0);
	PX_CHECK(gen_sphere(0.12, 24, 48, &gs) == 0);
	PX_CHECK(gen_box(hb, 6, &gb) == 0);
	PX_CHECK_INT_EQ(px_mesh_model(gt.xyz, gt.nv, gt.tri, gt.nt, NULL, NULL, &tor), PX_OK);
	PX_CHECK_INT_EQ(px_mesh_model(gs.xyz, gs.nv, gs.tri, gs.nt, NULL, NULL, &sph), PX_OK);
	PX_CHECK_INT_EQ(px_mesh_model(gb.xyz, gb.nv, gb.tri, gb.nt, NULL, NULL, &box), PX_OK);
	for (trial = 0; trial < 30; trial++) {
		struct px_model *b = trial % 2 ? sph : box;
		struct px_pair_result r;
		double ang = px_rand_range(0, 2 * M_PI), rad = 0.3 + px_rand_range(-0.12, 0.12);
		px_pose Pb = rand_rot_pose(px_v3(rad * cos(ang), rad * sin(ang), px_rand_range(-0.1, 0.1)));
		double ref;
		uint64_t a0 = 0;
		px_model_set_pose(tor, px_pose_identity());
		px_model_set_pose(b, Pb);
		ref = fmin(0.0, fmin(min_over_surface(tor, b, 5), min_over_surface(b, tor, 4)));
		memset(&r, 0, sizeof(r));
		a0 = px_alloc_region_begin();
		PX_CHECK_INT_EQ(px_pair_distance(tor, b, NULL, &r), PX_OK);
		PX_CHECK_INT_EQ(px_alloc_region_end(a0), 0);
		if (ref >= -1e-3)
			continue; /* barely touching: the sign of a sliver */
		total++;
		PX_CHECK_MSG(r.intersecting && r.depth > 0.0 && r.depth_approx,
			     "trial %d: overlap %.6g not reported (distance %.6g)", trial, -ref,
			     r.distance);
		PX_CHECK_NEAR(r.depth, -r.distance, 0.0);
		PX_CHECK(px_v3_dist(px_v3_sub(r.point_a, r.point_b),
				    px_v3_scale(r.normal, r.depth)) <= 1e-9 + 1e-9 * r.depth);
		/* not deeper than a point can be: the samples are surface
		 * points at most 8 mm apart, and the signed distance changes
		 * by at most the distance moved (1-Lipschitz), so the true
		 * deepest point is at most 8 mm below the sampled one (the
		 * certificate below shows the depth is really attained) */
		PX_CHECK_MSG(r.depth <= -ref + 8e-3, "trial %d: depth %.6g beyond %.6g", trial,
			     r.depth, -ref);
		{
			/* the depth is attained: one of the two points lies
			 * that deep inside the other model */
			struct px_model_result qa, qb;
			px_model_query(b, r.point_a, &qa);
			px_model_query(tor, r.point_b, &qb);
			PX_CHECK_MSG(fabs(qa.distance + r.depth) <= 1e-9 ||
					     fabs(qb.distance + r.depth) <= 1e-9,
				     "trial %d: depth %.9g not attained (%.9g, %.9g)", trial, r.depth,
				     qa.distance, qb.distance);
		}
		hits += r.depth >= -ref - 1e-3;
	}
	printf("    mesh penetration: %d of %d overlapping pairs within 1 mm of the brute-force depth\n",
	       hits, total);
	PX_CHECK(total >= 10);
	PX_CHECK_MSG(hits >= total * 9 / 10, "%d of %d", hits, total);
	px_model_free(tor);
	px_model_free(sph);
	px_model_free(box);
	gen_free(&gt);
	gen_free(&gs);
	gen_free(&gb);
}

static void test_cloud_vs_box(void)
{
	/* heterogeneous: a scanned sphere against a box; exact reference is
	 * the minimum over the points */
	size_t n = 3000, i;
	double *x = malloc(3 * n * sizeof(double));
	struct px_prim bx = {PX_PRIM_BOX, 0.4, 0.3, 0.2};
	struct px_model *c, *b;
	int trial, hits = 0, flagged = 0;
	for (i = 0; i < n; i++) {
		px_vec3 d = rand_dir();
		x[3 * i] = 0.5 * d.x, x[3 * i + 1] = 0.5 * d.y, x[3 * i + 2] = 0.5 * d.z;
	}
	PX_CHECK_INT_EQ(px_cloud_model(x, n, 0.0, NULL, &c), PX_OK);
	PX_CHECK_INT_EQ(px_prim_model(&bx, &b), PX_OK);
	for (trial = 0; trial < 50; trial++) {
		struct px_pair_result r;
		double ref = INFINITY;
		px_pose Pc = rand_rot_pose(px_v3(0, 0, 0));
		memset(&r, 0, sizeof(r));
		px_model_set_pose(c, Pc);
		px_model_set_pose(b, rand_rot_pose(px_v3_scale(rand_dir(), px_rand_range(1.1, 2))));
		for (i = 0; i < n; i++) {
			struct px_model_result q;
			px_model_query(b, px_pose_transform_point(Pc, px_v3(x[3 * i], x[3 * i + 1], x[3 * i + 2])), &q);
			ref = fmin(ref, q.distance);
		}
		PX_CHECK_INT_EQ(px_pair_distance(c, b, NULL, &r), PX_OK);
		check_pair_result(c, b, &r);
		PX_CHECK(r.distance >= ref - 1e-12);
		if (r.distance <= ref + 1e-12)
			hits++;
		else
			PX_CHECK(r.local_only);
		flagged += r.local_only;
	}
	/* clouds against primitives are exact (px_pair.h): none flagged */
	printf("    cloud-box pairs: %d of 50 global, %d flagged possibly local\n", hits, flagged);
	PX_CHECK_MSG(hits >= 49, "cloud-box global-hit rate %d of 50", hits);
	px_model_free(c);
	px_model_free(b);
	free(x);
}

static void test_coherent_and_alloc(void)
{
	double ra, rb;
	struct px_model *a = px_test_mesh_shape(0, 1, &ra), *b = px_test_mesh_shape(1, 1, &rb);
	struct px_pair_result rc, rf;
	struct px_pair_opts co = {1, 64, 1e-12, 1, 0, 0}, fo = {8, 64, 1e-12, 0, 0, 0};
	uint64_t al;
	int i, agree = 0;
	memset(&rc, 0, sizeof(rc));
	memset(&rf, 0, sizeof(rf));
	al = px_alloc_region_begin();
	for (i = 0; i < 200; i++) {
		px_pose Pb = px_pose_identity();
		Pb.t = px_v3(1.6 * cos(0.01 * i), 1.6 * sin(0.01 * i), 0.3);
		px_model_set_pose(b, Pb);
		PX_CHECK_INT_EQ(px_pair_distance(a, b, &co, &rc), PX_OK);
		PX_CHECK_INT_EQ(px_pair_distance(a, b, &fo, &rf), PX_OK);
		/* mesh pairs are exact: coherent (hinted) and cold agree */
		PX_CHECK(!rc.local_only && !rf.local_only);
		agree += fabs(rc.distance - rf.distance) <= 1e-12;
		PX_CHECK(rc.starts == 0);
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(al), 0);
	PX_CHECK_MSG(agree == 200, "coherent agreed %d of 200", agree);
	PX_CHECK_INT_EQ(px_pair_distance(NULL, b, NULL, &rc), PX_E_INVAL);
	fo.starts = PX_PAIR_MAX_STARTS + 1;
	PX_CHECK_INT_EQ(px_pair_distance(a, b, &fo, &rc), PX_E_INVAL);
	px_model_free(a);
	px_model_free(b);
}

static void test_convex_mesh_flag(void)
{
	double r;
	struct px_model *t = px_test_mesh_shape(0, 1, &r), *s = px_test_mesh_shape(1, 1, &r);
	struct px_model *bx = px_test_mesh_shape(2, 1, &r), *l = px_test_mesh_shape(3, 1, &r);
	PX_CHECK(!(px_model_caps(t) & PX_MODEL_CAP_CONVEX));
	PX_CHECK(px_model_caps(s) & PX_MODEL_CAP_CONVEX);
	PX_CHECK(px_model_caps(bx) & PX_MODEL_CAP_CONVEX);
	PX_CHECK(!(px_model_caps(l) & PX_MODEL_CAP_CONVEX));
	px_model_free(t);
	px_model_free(s);
	px_model_free(bx);
	px_model_free(l);
}

/* Mesh against cloud: the answer is certified by the mesh hierarchy
 * with the cloud's point queries as lower bounds and the points near
 * each remaining triangle measured exactly; the reference is the least
 * exact point-to-mesh distance over the cloud's points. */
static void test_mesh_vs_cloud_certified(void)
{
	int trial, n = 60, hits = 0, cert = 0, poor_cert = 0;
	size_t np = 400, i;
	double *x = malloc(3 * np * sizeof(double));
	for (trial = 0; trial < n; trial++) {
		double rm, ref = INFINITY;
		struct px_model *m = px_test_mesh_shape(trial % 4, 1, &rm), *c;
		struct px_pair_result r;
		px_pose Pc = rand_rot_pose(px_v3_scale(rand_dir(), rm + px_rand_range(0.35, 1.2)));
		double rr = px_rand_range(0.1, 0.3);
		for (i = 0; i < np; i++) {
			px_vec3 d = rand_dir();
			/* half a shell, half a random blob */
			if (i % 2)
				d = px_v3_scale(d, px_rand_unit());
			x[3 * i] = rr * d.x, x[3 * i + 1] = rr * d.y, x[3 * i + 2] = rr * d.z;
		}
		PX_CHECK_INT_EQ(px_cloud_model(x, np, 0.0, NULL, &c), PX_OK);
		px_model_set_pose(m, rand_rot_pose(px_v3(0, 0, 0)));
		px_model_set_pose(c, Pc);
		for (i = 0; i < np; i++) {
			struct px_model_result q;
			px_model_query_ex(m, px_pose_transform_point(Pc, px_v3(x[3 * i], x[3 * i + 1], x[3 * i + 2])),
					  INFINITY, -1, PX_QUERY_UNSIGNED, &q);
			ref = fmin(ref, q.distance);
		}
		memset(&r, 0, sizeof(r));
		PX_CHECK_INT_EQ(trial % 2 ? px_pair_distance(c, m, NULL, &r) : px_pair_distance(m, c, NULL, &r),
				PX_OK);
		if (trial % 2)
			check_pair_result(c, m, &r);
		else
			check_pair_result(m, c, &r);
		PX_CHECK(r.distance >= ref - 1e-12);
		cert += !r.local_only;
		if (r.distance <= ref + 1e-12 * (1 + ref))
			hits++;
		else
			PX_CHECK_MSG(r.local_only, "unflagged miss %.17g vs %.17g", r.distance, ref);
		{
			/* a poor start (one start, one projection): the
			 * certification must repair it or keep the flag */
			struct px_pair_opts po = {1, 1, 1e-12, 1, 0, 0};
			memset(&r, 0, sizeof(r));
			/* coherent from a "last pair" on the far side of the
			 * mesh: one projection, no neighbourhood steps */
			r.valid = 1;
			r.local_a = px_pose_inverse_transform_point(px_model_pose(m),
								    px_v3_scale(Pc.t, -3.0));
			PX_CHECK_INT_EQ(px_pair_distance(m, c, &po, &r), PX_OK);
			PX_CHECK(r.distance >= ref - 1e-12);
			PX_CHECK_MSG(r.local_only || r.distance <= ref + 1e-12 * (1 + ref),
				     "certified but %.17g vs %.17g", r.distance, ref);
			poor_cert += !r.local_only;
		}
		px_model_free(m);
		px_model_free(c);
	}
	printf("    mesh-cloud pairs: %d of %d global, %d certified global (local_only = 0); from a "
	       "poor start %d certified\n",
	       hits, n, cert, poor_cert);
	PX_CHECK_MSG(cert >= n * 9 / 10, "only %d of %d certified", cert, n);
	free(x);
}

static const struct px_test tests[] = {
	PX_T(test_mesh_pairs_hit_rate), PX_T(test_convex_primitive_pairs),
	PX_T(test_gjk_convex_primitives),
	PX_T(test_cloud_vs_box), PX_T(test_coherent_and_alloc),
	PX_T(test_convex_mesh_flag), PX_T(test_penetration_convex),
	PX_T(test_penetration_meshes), PX_T(test_mesh_vs_cloud_certified)};
PX_TEST_MAIN(tests)
