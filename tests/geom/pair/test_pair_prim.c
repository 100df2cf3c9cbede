/*
 * Closed-form pairs (geom/pair/px_pair_prim.c): segment/segment and
 * segment/box closest points against brute-force minimisation, and
 * capsule/capsule and capsule/box pair distances, penetration depths,
 * normals and witnesses through px_pair_distance().
 *
 * References: the squared distance of two segments, or of a segment and
 * a box, is convex in the parameters, so a dense grid followed by a
 * golden-section search along the best line finds its minimum to far
 * below the tolerances used here; the depth of an overlapping pair is
 * checked by moving B along the normal by the depth (then the pair just
 * touches) and by less (then it still overlaps). Hard cases on purpose:
 * parallel and collinear segments, segments collapsed to points,
 * crossing axes, segments through the box, axes parallel to box faces.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "mesh_gen.h"
#include "pair_internal.h"
#include "px_mesh.h"
#include "px_alloc_count.h"
#include "px_pair.h"
#include "px_prim.h"
#include "px_test.h"
#include "px_test_geom.h"

static px_vec3 rand_v(double s)
{
	return px_v3(px_rand_range(-s, s), px_rand_range(-s, s), px_rand_range(-s, s));
}

/* min over u in [0, 1] of f(u), f convex: grid then golden section */
static double min_convex(double (*f)(const void *, double), const void *ctx,
			 double *arg)
{
	double best = INFINITY, bu = 0.0, lo, hi;
	int i;
	for (i = 0; i <= 400; i++) {
		double u = i / 400.0, v = f(ctx, u);
		if (v < best) {
			best = v;
			bu = u;
		}
	}
	lo = fmax(0.0, bu - 1.0 / 400);
	hi = fmin(1.0, bu + 1.0 / 400);
	for (i = 0; i < 100; i++) {
		double m1 = hi - 0.618033988749895 * (hi - lo), m2 = lo + 0.618033988749895 * (hi - lo);
		if (f(ctx, m1) < f(ctx, m2))
			hi = m2;
		else
			lo = m1;
	}
	if (f(ctx, 0.5 * (lo + hi)) < best) {
		bu = 0.5 * (lo + hi);
		best = f(ctx, bu);
	}
	*arg = bu;
	return best;
}

struct segs {
	px_vec3 p0, p1, q0, q1;
};

/* distance from the point at s on P to segment Q (closed form along Q
 * by its own convex search would be circular: sample it) */
static double point_seg(px_vec3 x, px_vec3 a, px_vec3 b)
{
	px_vec3 d = px_v3_sub(b, a);
	double dd = px_v3_norm2(d), u = dd > 0 ? px_v3_dot(px_v3_sub(x, a), d) / dd : 0.0;
	u = u < 0 ? 0 : (u > 1 ? 1 : u);
	return px_v3_dist(x, px_v3_madd(a, d, u));
}

static double f_segs(const void *ctx, double s)
{
	const struct segs *S = ctx;
	return point_seg(px_v3_lerp(S->p0, S->p1, s), S->q0, S->q1);
}

static void test_seg_seg(void)
{
	int i, hard = 0;
	for (i = 0; i < 4000; i++) {
		struct segs S;
		double s, t, d2, ref, arg;
		int kind = i % 6;
		S.p0 = rand_v(1.0);
		S.p1 = rand_v(1.0);
		S.q0 = rand_v(1.0);
		S.q1 = rand_v(1.0);
		if (kind == 1) { /* parallel */
			px_vec3 off = rand_v(0.3);
			S.q0 = px_v3_add(S.p0, off);
			S.q1 = px_v3_add(S.q0, px_v3_scale(px_v3_sub(S.p1, S.p0), px_rand_range(-2, 2)));
			hard++;
		} else if (kind == 2) { /* collinear, overlapping or not */
			px_vec3 d = px_v3_sub(S.p1, S.p0);
			S.q0 = px_v3_madd(S.p0, d, px_rand_range(-1.5, 1.5));
			S.q1 = px_v3_madd(S.p0, d, px_rand_range(-1.5, 1.5));
			hard++;
		} else if (kind == 3) { /* one or both collapsed to a point */
			S.q1 = S.q0;
			if (i % 12 == 3)
				S.p1 = S.p0;
			hard++;
		} else if (kind == 4) { /* crossing: q passes through a point of p */
			px_vec3 x = px_v3_lerp(S.p0, S.p1, px_rand_unit()), d = rand_v(1.0);
			S.q0 = px_v3_madd(x, d, -px_rand_unit());
			S.q1 = px_v3_madd(x, d, px_rand_unit());
			hard++;
		} else if (kind == 5) { /* nearly parallel */
			S.q0 = px_v3_add(S.p0, rand_v(0.3));
			S.q1 = px_v3_add(px_v3_add(S.q0, px_v3_sub(S.p1, S.p0)), rand_v(1e-7));
			hard++;
		}
		d2 = px__seg_seg(S.p0, S.p1, S.q0, S.q1, &s, &t);
		ref = min_convex(f_segs, &S, &arg);
		PX_CHECK(s >= 0.0 && s <= 1.0 && t >= 0.0 && t <= 1.0);
		/* the parameters realise the distance returned */
		PX_CHECK_NEAR(px_v3_dist2(px_v3_lerp(S.p0, S.p1, s), px_v3_lerp(S.q0, S.q1, t)), d2,
			      1e-14);
		PX_CHECK_MSG(fabs(sqrt(d2) - ref) <= 1e-9, "case %d (kind %d): %.15g vs %.15g", i,
			     kind, sqrt(d2), ref);
	}
	printf("    4000 segment pairs (%d parallel, collinear, collapsed, crossing or nearly parallel)\n",
	       hard);
}

struct sbox {
	px_vec3 p0, p1;
	double h[3];
};

static double f_sbox(const void *ctx, double u)
{
	const struct sbox *B = ctx;
	px_vec3 x = px_v3_lerp(B->p0, B->p1, u);
	double X[3] = {x.x, x.y, x.z}, s = 0;
	int k;
	for (k = 0; k < 3; k++) {
		double g = fabs(X[k]) - B->h[k];
		s += g > 0 ? g * g : 0;
	}
	return sqrt(s);
}

static void test_seg_box(void)
{
	int i, through = 0;
	for (i = 0; i < 4000; i++) {
		struct sbox B;
		double t, d2, ref, arg;
		px_vec3 q;
		int kind = i % 5, k;
		for (k = 0; k < 3; k++)
			B.h[k] = px_rand_range(0.05, 0.6);
		B.p0 = rand_v(1.5);
		B.p1 = rand_v(1.5);
		if (kind == 1) { /* parallel to a face */
			B.p1 = B.p0;
			B.p1.x += px_rand_range(-2, 2);
		} else if (kind == 2) { /* a point */
			B.p1 = B.p0;
		} else if (kind == 3) { /* through the box */
			B.p0 = px_v3(B.h[0] * px_rand_range(-0.9, 0.9), B.h[1] * px_rand_range(-0.9, 0.9),
				     B.h[2] * px_rand_range(-0.9, 0.9));
		} else if (kind == 4) { /* along a face plane, just outside */
			B.p0.z = B.p1.z = B.h[2] * (1 + 1e-9);
		}
		d2 = px__seg_box(B.p0, B.p1, B.h, &t, &q);
		ref = min_convex(f_sbox, &B, &arg);
		PX_CHECK(t >= 0.0 && t <= 1.0);
		PX_CHECK(fabs(q.x) <= B.h[0] && fabs(q.y) <= B.h[1] && fabs(q.z) <= B.h[2]);
		PX_CHECK_NEAR(px_v3_dist2(px_v3_lerp(B.p0, B.p1, t), q), d2, 1e-14);
		PX_CHECK_MSG(fabs(sqrt(d2) - ref) <= 1e-9, "case %d (kind %d): %.15g vs %.15g", i,
			     kind, sqrt(d2), ref);
		through += d2 == 0.0;
	}
	printf("    4000 segment/box pairs, %d meeting the box\n", through);
	PX_CHECK(through > 400);
}

/* Distance of two posed capsules by the segment brute force. */
static double capsule_ref(const struct px_prim *c1, px_pose P1, const struct px_prim *c2,
			  px_pose P2)
{
	struct segs S;
	double arg;
	S.p0 = px_pose_transform_point(P1, px_v3(0, 0, -c1->b));
	S.p1 = px_pose_transform_point(P1, px_v3(0, 0, c1->b));
	S.q0 = px_pose_transform_point(P2, px_v3(0, 0, -c2->b));
	S.q1 = px_pose_transform_point(P2, px_v3(0, 0, c2->b));
	return min_convex(f_segs, &S, &arg) - c1->a - c2->a;
}

static double capsule_box_ref(const struct px_prim *c, px_pose Pc, const struct px_prim *bx,
			      px_pose Pb)
{
	struct sbox B;
	double arg;
	B.p0 = px_pose_inverse_transform_point(
		Pb, px_pose_transform_point(Pc, px_v3(0, 0, -c->b)));
	B.p1 = px_pose_inverse_transform_point(
		Pb, px_pose_transform_point(Pc, px_v3(0, 0, c->b)));
	B.h[0] = bx->a;
	B.h[1] = bx->b;
	B.h[2] = bx->c;
	return min_convex(f_sbox, &B, &arg) - c->a;
}

/* The checks every closed-form pair result must pass. */
static void check_pair(struct px_model *ma, struct px_model *mb, double ref, int trial,
		       int *n_over)
{
	struct px_pair_result r;
	struct px_model_result qa, qb;
	uint64_t a0;
	memset(&r, 0, sizeof(r));
	a0 = px_alloc_region_begin();
	PX_CHECK_INT_EQ(px_pair_distance(ma, mb, NULL, &r), PX_OK);
	PX_CHECK_INT_EQ(px_alloc_region_end(a0), 0);
	PX_CHECK(r.converged && !r.local_only && r.iterations == 1);
	PX_CHECK_MSG(fabs(r.distance - ref) <= 1e-9, "trial %d: %.15g vs %.15g", trial,
		     r.distance, ref);
	PX_CHECK(r.intersecting == (r.distance <= 0.0));
	/* witnesses on the surfaces, spanning the distance or the depth */
	PX_CHECK(px_model_query(ma, r.point_a, &qa) >= 0);
	PX_CHECK(px_model_query(mb, r.point_b, &qb) >= 0);
	PX_CHECK_MSG(fabs(qa.distance) <= 1e-9 && fabs(qb.distance) <= 1e-9,
		     "trial %d: witnesses %.3g and %.3g off", trial, qa.distance, qb.distance);
	PX_CHECK(qa.index == r.index_a && qb.index == r.index_b);
	if (r.distance >= 0.0) {
		PX_CHECK_NEAR(px_v3_dist(r.point_a, r.point_b), r.distance, 1e-12);
	} else {
		struct px_pair_result s2;
		px_pose P = px_model_pose(mb), P2 = P;
		(*n_over)++;
		PX_CHECK_NEAR(r.depth, -r.distance, 0.0);
		PX_CHECK_NEAR(px_v3_norm(r.normal), 1.0, 1e-12);
		PX_CHECK(px_v3_dist(px_v3_sub(r.point_a, r.point_b),
				    px_v3_scale(r.normal, r.depth)) <= 1e-12);
		/* B moved by the depth along the normal just touches */
		P2.t = px_v3_madd(P.t, r.normal, r.depth);
		px_model_set_pose(mb, P2);
		memset(&s2, 0, sizeof(s2));
		PX_CHECK_INT_EQ(px_pair_distance(ma, mb, NULL, &s2), PX_OK);
		PX_CHECK_MSG(fabs(s2.distance) <= 1e-9, "trial %d: moved by the depth, distance %.3g",
			     trial, s2.distance);
		P2.t = px_v3_madd(P.t, r.normal, 0.9 * r.depth);
		px_model_set_pose(mb, P2);
		PX_CHECK_INT_EQ(px_pair_distance(ma, mb, NULL, &s2), PX_OK);
		PX_CHECK(s2.intersecting);
		px_model_set_pose(mb, P);
	}
}

static void test_capsule_pairs(void)
{
	int trial, n_over = 0, n_cross = 0;
	for (trial = 0; trial < 600; trial++) {
		struct px_prim c1 = {PX_PRIM_CAPSULE, px_rand_range(0.02, 0.2), px_rand_range(0.01, 0.5), 0};
		struct px_prim c2 = {PX_PRIM_CAPSULE, px_rand_range(0.02, 0.2), px_rand_range(0.01, 0.5), 0};
		px_pose P1 = px_test_rand_pose(0.3), P2 = px_test_rand_pose(0.6);
		struct px_model *ma, *mb;
		if (trial % 7 == 1) /* parallel axes */
			P2.q = P1.q;
		if (trial % 7 == 2) { /* crossing axes: both centres on one point */
			P2.t = P1.t;
			n_cross++;
		}
		if (trial % 11 == 3)
			c2.b = 1e-7; /* almost a sphere: the axis nearly a point */
		PX_CHECK_INT_EQ(px_prim_model(&c1, &ma), PX_OK);
		PX_CHECK_INT_EQ(px_prim_model(&c2, &mb), PX_OK);
		px_model_set_pose(ma, P1);
		px_model_set_pose(mb, P2);
		check_pair(ma, mb, capsule_ref(&c1, P1, &c2, P2), trial, &n_over);
		px_model_free(ma);
		px_model_free(mb);
	}
	printf("    600 capsule pairs, %d overlapping (%d with crossing axes)\n", n_over, n_cross);
	PX_CHECK(n_over > 60);
}

static void test_capsule_box_pairs(void)
{
	int trial, n_over = 0, n_epa = 0, n_apart = 0;
	for (trial = 0; trial < 600; trial++) {
		struct px_prim c = {PX_PRIM_CAPSULE, px_rand_range(0.02, 0.2), px_rand_range(0.01, 0.5), 0};
		struct px_prim bx = {PX_PRIM_BOX, px_rand_range(0.05, 0.4), px_rand_range(0.05, 0.4),
				     px_rand_range(0.05, 0.4)};
		px_pose Pc = px_test_rand_pose(0.7), Pb = px_test_rand_pose(0.2);
		struct px_model *mc, *mb;
		double ref;
		int cap_first = trial % 2;
		if (trial % 5 == 1) /* axis parallel to the box's faces */
			Pc.q = Pb.q;
		PX_CHECK_INT_EQ(px_prim_model(&c, &mc), PX_OK);
		PX_CHECK_INT_EQ(px_prim_model(&bx, &mb), PX_OK);
		px_model_set_pose(mc, Pc);
		px_model_set_pose(mb, Pb);
		ref = capsule_box_ref(&c, Pc, &bx, Pb);
		if (ref + c.a <= 1e-9) {
			/* the axis meets the box: left to EPA (exact there,
			 * tested with the convex pairs) */
			struct px_pair_result r;
			memset(&r, 0, sizeof(r));
			PX_CHECK_INT_EQ(px_pair_distance(mc, mb, NULL, &r), PX_OK);
			PX_CHECK_MSG(r.intersecting && r.depth >= c.a - 2e-9,
				     "trial %d: axis %.3g from the box, depth %.12g, radius %.12g", trial,
				     ref + c.a, r.depth, c.a);
			n_epa++;
		} else if (cap_first) {
			check_pair(mc, mb, ref, trial, &n_over);
		} else {
			check_pair(mb, mc, ref, trial, &n_over);
		}
		n_apart += ref > 0.0;
		px_model_free(mc);
		px_model_free(mb);
	}
	printf("    600 capsule/box pairs: %d apart, %d overlapping in closed form, %d with the axis in the box\n",
	       n_apart, n_over, n_epa);
	PX_CHECK(n_over > 30 && n_apart > 100 && n_epa > 10);
}

struct stri {
	px_vec3 p0, p1, v[3];
};

static double f_stri(const void *ctx, double u)
{
	const struct stri *T = ctx;
	return sqrt(px_tri_closest(px_v3_lerp(T->p0, T->p1, u), T->v[0], T->v[1], T->v[2], NULL,
				   NULL, NULL, NULL, NULL));
}

static void test_seg_tri(void)
{
	int i, hit = 0;
	for (i = 0; i < 4000; i++) {
		struct stri T;
		double s, d2, ref, arg;
		px_vec3 q;
		int kind = i % 6;
		T.v[0] = rand_v(1.0);
		T.v[1] = rand_v(1.0);
		T.v[2] = rand_v(1.0);
		T.p0 = rand_v(1.5);
		T.p1 = rand_v(1.5);
		if (kind == 1) { /* through the triangle */
			px_vec3 x = px_v3_add(px_v3_scale(T.v[0], 0.3),
					      px_v3_add(px_v3_scale(T.v[1], 0.3), px_v3_scale(T.v[2], 0.4)));
			px_vec3 d = rand_v(1.0);
			T.p0 = px_v3_madd(x, d, -px_rand_unit());
			T.p1 = px_v3_madd(x, d, px_rand_unit());
		} else if (kind == 2) { /* in the triangle's plane */
			T.p0 = px_v3_lerp(T.v[0], T.v[1], px_rand_range(-1, 2));
			T.p1 = px_v3_lerp(T.v[0], T.v[2], px_rand_range(-1, 2));
		} else if (kind == 3) { /* parallel to the plane, above it */
			px_vec3 n, off;
			px_v3_normalize(px_v3_cross(px_v3_sub(T.v[1], T.v[0]), px_v3_sub(T.v[2], T.v[0])),
					px_v3(0, 0, 1), &n);
			off = px_v3_scale(n, px_rand_range(0.01, 0.3));
			T.p0 = px_v3_add(px_v3_lerp(T.v[0], T.v[1], px_rand_range(-1, 2)), off);
			T.p1 = px_v3_add(px_v3_lerp(T.v[1], T.v[2], px_rand_range(-1, 2)), off);
		} else if (kind == 4) { /* a collapsed triangle (a segment) */
			T.v[2] = px_v3_lerp(T.v[0], T.v[1], px_rand_unit());
		} else if (kind == 5) { /* the segment a point */
			T.p1 = T.p0;
		}
		d2 = px__seg_tri(T.p0, T.p1, T.v, &s, &q);
		ref = min_convex(f_stri, &T, &arg);
		PX_CHECK(s >= 0.0 && s <= 1.0);
		PX_CHECK_NEAR(px_v3_dist2(px_v3_lerp(T.p0, T.p1, s), q), d2, 1e-14);
		/* q is a point of the triangle */
		PX_CHECK(px_tri_closest(q, T.v[0], T.v[1], T.v[2], NULL, NULL, NULL, NULL, NULL) <=
			 1e-24);
		PX_CHECK_MSG(fabs(sqrt(d2) - ref) <= 1e-9, "case %d (kind %d): %.15g vs %.15g", i,
			     kind, sqrt(d2), ref);
		hit += d2 <= 1e-24;
	}
	printf("    4000 segment/triangle pairs, %d meeting\n", hit);
	PX_CHECK(hit > 500);
}

/* A capsule against a closed mesh through px_pair_distance (the mesh
 * hierarchy with the closed form per triangle) against a scan over
 * every triangle with the brute-force segment minimisation. */
static void test_capsule_mesh(void)
{
	struct gen_mesh g;
	struct px_model *mm;
	int trial, n_touch = 0, n_inside = 0;
	PX_CHECK_INT_EQ(gen_torus(0.3, 0.1, 24, 12, &g), 0);
	PX_CHECK_INT_EQ(px_mesh_model(g.xyz, g.nv, g.tri, g.nt, NULL, NULL, &mm), PX_OK);
	for (trial = 0; trial < 80; trial++) {
		struct px_prim c = {PX_PRIM_CAPSULE, px_rand_range(0.01, 0.08), px_rand_range(0.02, 0.3), 0};
		px_pose Pc = px_test_rand_pose(0.5);
		struct px_model *mc;
		struct px_pair_result r;
		struct stri T;
		double ref = INFINITY, arg;
		size_t i;
		uint64_t a0;
		PX_CHECK_INT_EQ(px_prim_model(&c, &mc), PX_OK);
		px_model_set_pose(mc, Pc);
		T.p0 = px_pose_transform_point(Pc, px_v3(0, 0, -c.b));
		T.p1 = px_pose_transform_point(Pc, px_v3(0, 0, c.b));
		for (i = 0; i < g.nt; i++) {
			int k;
			for (k = 0; k < 3; k++) {
				const double *X = g.xyz + 3 * g.tri[3 * i + k];
				T.v[k] = px_v3(X[0], X[1], X[2]);
			}
			ref = fmin(ref, min_convex(f_stri, &T, &arg));
		}
		ref -= c.a;
		memset(&r, 0, sizeof(r));
		a0 = px_alloc_region_begin();
		PX_CHECK_INT_EQ(px_pair_distance(mm, mc, NULL, &r), PX_OK);
		PX_CHECK_INT_EQ(px_alloc_region_end(a0), 0);
		{
			/* a capsule whose surface is apart from the torus's but
			 * inside it is held whole: intersecting too */
			struct px_model_result q;
			PX_CHECK(px_model_query(mm, Pc.t, &q) >= 0);
			if (ref > 1e-9 && q.distance < 0.0) {
				PX_CHECK(r.intersecting);
				n_inside++;
				px_model_free(mc);
				continue;
			}
		}
		if (ref <= 1e-9) {
			/* the surfaces touch or cross */
			PX_CHECK(r.intersecting);
			n_touch++;
		} else {
			PX_CHECK(!r.intersecting && !r.local_only);
			PX_CHECK_MSG(fabs(r.distance - ref) <= 1e-9, "trial %d: %.15g vs %.15g", trial,
				     r.distance, ref);
			PX_CHECK_NEAR(px_v3_dist(r.point_a, r.point_b), r.distance, 1e-9);
		}
		px_model_free(mc);
	}
	printf("    80 capsules against a 576-triangle torus, %d touching, %d held inside\n", n_touch,
	       n_inside);
	px_model_free(mm);
	gen_free(&g);
}

static const struct px_test tests[] = {
	PX_T(test_seg_tri),
	PX_T(test_capsule_mesh),
	PX_T(test_seg_seg),
	PX_T(test_seg_box),
	PX_T(test_capsule_pairs),
	PX_T(test_capsule_box_pairs),
};
PX_TEST_MAIN(tests)
