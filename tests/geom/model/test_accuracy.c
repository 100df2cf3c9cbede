/*
 * Accuracy of the exact distance tests against a higher-precision
 * reference, on the inputs that break naive formulas: needles and
 * slivers (aspect 1e3 to 1e9), degenerate triangles (zero area,
 * collinear, repeated vertices), points far away (1e6 times the size)
 * and very close to the surface (1e-12 of it), and scales from 1e-100
 * to 1e100; and the accepted ranges of meshes and primitives (refused
 * at setup beyond them, with the place named).
 *
 * The reference is independent of the code under test: the point-
 * triangle distance as the least of the face-interior projection (when
 * the projection lies inside) and the three edges, evaluated in
 * __float128 (113-bit significand: products of two doubles are exact,
 * so the normal of a 1e9 needle is still right to 1e-25), and the
 * primitives' closed forms in long double. Every comparison asserts the
 * bound the headers document, in units of u = 2^-53:
 *   px_tri_closest, mesh queries: |d - d*| <= PX_TRI_ERR_ULPS u (d* + l)
 *     + 1e-160, l the triangle's longest edge;
 *   px_prim_closest: |d - d*| <= PX_PRIM_ERR_ULPS u (|q| + size).
 * Seeds are printed by the harness (PX_TEST_SEED replays a failure).
 * Here under geom/model/: every query goes through the model interface
 * (px_model_*), over meshes and primitives.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mesh_internal.h"
#include "pair_internal.h"
#include "px_mesh.h"
#include "px_model.h"
#include "px_prim.h"
#include "px_test.h"


#define U 0x1p-53

typedef __float128 q128;

struct qv {
	q128 x, y, z;
};

static struct qv qv_of(px_vec3 v)
{
	struct qv r = {v.x, v.y, v.z};
	return r;
}

static struct qv qsub(struct qv a, struct qv b)
{
	struct qv r = {a.x - b.x, a.y - b.y, a.z - b.z};
	return r;
}

static q128 qdot(struct qv a, struct qv b)
{
	return a.x * b.x + a.y * b.y + a.z * b.z;
}

static struct qv qcross(struct qv a, struct qv b)
{
	struct qv r = {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z,
		       a.x * b.y - a.y * b.x};
	return r;
}

/* squared distance from w (relative to the segment start) to segment e */
static q128 qseg(struct qv w, struct qv e)
{
	q128 l2 = qdot(e, e), t = 0;
	struct qv d;
	if (l2 > 0) {
		t = qdot(w, e) / l2;
		t = t < 0 ? 0 : (t > 1 ? 1 : t);
	}
	d.x = w.x - t * e.x;
	d.y = w.y - t * e.y;
	d.z = w.z - t * e.z;
	return qdot(d, d);
}

/* Reference distance from p to triangle abc. */
static long double ref_tri(px_vec3 p, px_vec3 a, px_vec3 b, px_vec3 c)
{
	struct qv P[3] = {qv_of(a), qv_of(b), qv_of(c)}, Q = qv_of(p), n;
	q128 best = -1, nn;
	int k, inside = 1;

	n = qcross(qsub(P[1], P[0]), qsub(P[2], P[0]));
	nn = qdot(n, n);
	for (k = 0; k < 3; k++) {
		struct qv e = qsub(P[(k + 1) % 3], P[k]), w = qsub(Q, P[k]);
		q128 d2 = qseg(w, e);
		if (best < 0 || d2 < best)
			best = d2;
		if (qdot(qcross(e, w), n) < 0)
			inside = 0;
	}
	if (inside && nn > 0) {
		q128 h = qdot(n, qsub(Q, P[0]));
		q128 d2 = h * h / nn;
		if (d2 < best)
			best = d2;
	}
	return sqrtl((long double)best);
}

static double longest_edge(px_vec3 a, px_vec3 b, px_vec3 c)
{
	return fmax(px_v3_dist(a, b), fmax(px_v3_dist(b, c), px_v3_dist(c, a)));
}

static px_vec3 rand_unit(void)
{
	px_vec3 v;
	do
		v = px_v3(px_rand_normal(), px_rand_normal(), px_rand_normal());
	while (px_v3_norm2(v) < 1e-6);
	return px_v3_scale(v, 1.0 / px_v3_norm(v));
}

/* a unit vector perpendicular to unit d */
static px_vec3 perp(px_vec3 d)
{
	px_vec3 r = px_v3_cross(d, rand_unit());
	return px_v3_scale(r, 1.0 / px_v3_norm(r));
}

/*
 * A hard triangle of about unit size at the origin, kind 0..7: 0 well
 * shaped; 1 a needle whose third vertex sits near the middle of the long
 * edge (aspect 1e3..1e9); 2 a needle sharp at one vertex; 3 a sliver
 * (three nearly collinear points spread along a line); 4 exactly
 * collinear (axis-aligned, representable); 5 two repeated vertices; 6
 * all three the same; 7 a needle with a random vertex order.
 */
static void hard_tri(int kind, px_vec3 v[3])
{
	px_vec3 d = rand_unit(), n = perp(d);
	double asp = pow(10.0, px_rand_range(3.0, 9.0)), h = 1.0 / asp;
	px_vec3 o = px_v3(px_rand_range(-0.5, 0.5), px_rand_range(-0.5, 0.5),
			  px_rand_range(-0.5, 0.5));
	switch (kind) {
	case 0:
		v[0] = o;
		v[1] = px_v3_add(o, rand_unit());
		v[2] = px_v3_add(o, rand_unit());
		break;
	case 1:
	case 7:
		v[0] = o;
		v[1] = px_v3_madd(o, d, 1.0);
		v[2] = px_v3_madd(px_v3_madd(o, d, px_rand_range(0.05, 0.95)), n, h);
		if (kind == 7) {
			px_vec3 t = v[0];
			int r = px_rand_int(0, 2);
			if (r == 1) {
				v[0] = v[2];
				v[2] = t;
			} else if (r == 2) {
				v[0] = v[1];
				v[1] = t;
			}
		}
		break;
	case 2:
		v[0] = o;
		v[1] = px_v3_madd(o, d, 1.0);
		v[2] = px_v3_madd(px_v3_madd(o, d, 1.0), n, h);
		break;
	case 3:
		v[0] = o;
		v[1] = px_v3_madd(px_v3_madd(o, d, px_rand_range(0.3, 0.7)), n, h * px_rand_range(-1, 1));
		v[2] = px_v3_madd(o, d, 1.0);
		break;
	case 4: {
		double x = (double)px_rand_int(-4, 4) / 4.0;
		v[0] = px_v3(x, 0.25, -0.5);
		v[1] = px_v3(x + 0.5, 0.25, -0.5);
		v[2] = px_v3(x + 1.0, 0.25, -0.5);
		break;
	}
	case 5:
		v[0] = o;
		v[1] = px_v3_add(o, rand_unit());
		v[2] = v[1];
		break;
	default:
		v[0] = v[1] = v[2] = o;
		break;
	}
}

/* A query point for triangle v of kind 0..4: 0 random near it; 1 just
 * above an interior point (1e-12 .. 1e-3 of its size); 2 near an edge;
 * 3 far away (1e6 times its size); 4 in the plane, inside or out. */
static px_vec3 hard_point(int kind, const px_vec3 v[3])
{
	double w0 = px_rand_unit(), w1 = px_rand_unit() * (1.0 - w0);
	px_vec3 in = px_v3_add(px_v3_scale(v[0], 1.0 - w0 - w1),
			       px_v3_add(px_v3_scale(v[1], w0), px_v3_scale(v[2], w1)));
	px_vec3 n = px_v3_cross(px_v3_sub(v[1], v[0]), px_v3_sub(v[2], v[0]));
	double l = longest_edge(v[0], v[1], v[2]);
	if (!(l > 0.0))
		l = 1.0;
	if (px_v3_norm2(n) > 0.0)
		n = px_v3_scale(n, 1.0 / px_v3_norm(n));
	else
		n = rand_unit();
	switch (kind) {
	case 0:
		return px_v3_madd(in, rand_unit(), l * px_rand_range(0.0, 2.0));
	case 1:
		return px_v3_madd(in, n, l * pow(10.0, px_rand_range(-12.0, -3.0)) *
					      (px_rand_unit() < 0.5 ? -1 : 1));
	case 2: {
		int e = px_rand_int(0, 2);
		px_vec3 x = px_v3_lerp(v[e], v[(e + 1) % 3], px_rand_unit());
		return px_v3_madd(x, rand_unit(), l * pow(10.0, px_rand_range(-12.0, -1.0)));
	}
	case 3:
		return px_v3_madd(in, rand_unit(), l * 1e6 * px_rand_range(1.0, 2.0));
	default:
		return px_v3_madd(in, perp(n), l * px_rand_range(-0.3, 0.3));
	}
}

static px_vec3 scaled(px_vec3 v, double s, px_vec3 off)
{
	return px_v3_add(px_v3_scale(v, s), off);
}

/* error of one px_tri_closest answer in units of u (d* + l); checks
 * that the point, feature and weights it reports agree with each other
 * and with the distance */
static double tri_err(px_vec3 p, const px_vec3 v[3], double *got, long double *want)
{
	px_vec3 q, qw;
	int f, s;
	double u, w, il, an, cond;
	double d2 = px_tri_closest(p, v[0], v[1], v[2], &q, &f, &s, &u, &w);
	long double ref = ref_tri(p, v[0], v[1], v[2]);
	double l = longest_edge(v[0], v[1], v[2]), d = sqrt(d2), tol;
	*got = d;
	*want = ref;
	tol = PX_TRI_ERR_ULPS * U * ((double)ref + l) + 1e-160;
	/* the aspect ratio l^2 / (2 area) (edges divided by l first: their
	 * squares would underflow) */
	il = l > 0.0 ? 1.0 / l : 1.0;
	an = px_v3_norm(px_v3_cross(px_v3_scale(px_v3_sub(v[1], v[0]), il),
				    px_v3_scale(px_v3_sub(v[2], v[0]), il)));
	cond = an > 0.0 ? fmax(1.0, 1.0 / an) : 1.0;
	/* the point at the distance (to its own rounding as a point:
	 * u |q|), and where its weights put it */
	PX_CHECK_MSG(fabs(px_v3_dist(p, q) - d) <= tol + 4 * U * (px_v3_norm(q) + px_v3_norm(p)),
		     "point at %.17g, distance %.17g", px_v3_dist(p, q), d);
	/* the weights of a thin triangle's point are conditioned by l^2 /
	 * (2 area), the aspect ratio (moving a vertex by rounding moves the
	 * weights of a fixed point by that much more), and those of a far
	 * point's foot by its distance (p's own rounding moves the foot) */
	qw = px_v3_add(px_v3_scale(v[0], 1.0 - u - w),
		       px_v3_add(px_v3_scale(v[1], u), px_v3_scale(v[2], w)));
	{
		if (f == PX_FEATURE_FACE)
			PX_CHECK_MSG(px_v3_dist(q, qw) <=
					     tol + 16 * U * (l * cond + d + px_v3_norm(q)),
				     "face weights (%.17g %.17g) put the point %.3g off (l %.3g, "
				     "aspect %.3g, d %.3g)",
				     u, w, px_v3_dist(q, qw), l, cond, d);
		else
			PX_CHECK_MSG(px_v3_dist(q, qw) <= tol + 16 * U * (l + px_v3_norm(q)),
				     "weights (%.17g %.17g) put the point %.3g off", u, w,
				     px_v3_dist(q, qw));
	}
	PX_CHECK_MSG(u >= -16 * U * cond && w >= -16 * U * cond && u + w <= 1.0 + 16 * U * cond,
		     "weights %.17g %.17g (aspect %.3g)", u, w, cond);
	if (f == PX_FEATURE_VERTEX) {
		PX_CHECK(s >= 0 && s <= 2);
		PX_CHECK_MSG(px_v3_dist(q, v[s]) == 0.0, "vertex %d, point %.3g off it", s,
			     px_v3_dist(q, v[s]));
	} else if (f == PX_FEATURE_EDGE) {
		/* the weight of the vertex opposite edge s is 0 */
		double wt[3] = {1.0 - u - w, u, w};
		PX_CHECK(s >= 0 && s <= 2);
		/* (the weight of a is 1 - u - v: zero to rounding on edge 1) */
		PX_CHECK_MSG(fabs(wt[(s + 2) % 3]) <= 2 * U, "edge %d with weights %.3g %.3g %.3g",
			     s, wt[0], wt[1], wt[2]);
	} else {
		PX_CHECK_INT_EQ(f, PX_FEATURE_FACE);
	}
	return (double)(fabsl((long double)d - ref) - 1e-160L) / (U * ((double)ref + l));
}

/*
 * px_tri_closest over every kind of triangle and point, at scales 1e-100
 * to 1e100 and translated by up to 1e3 times the size: the documented
 * bound holds for every answer, and the closest point it reports lies
 * at the reported distance.
 */
static void test_tri_bound(void)
{
	static const double scales[] = {1e-100, 1e-50, 1e-8, 1.0, 1e8, 1e50, 1e100};
	double worst = 0.0;
	int it, kinds[8] = {0};

	for (it = 0; it < 60000; it++) {
		px_vec3 v0[3], v[3], p, off;
		int tk = it % 8, pk = (it / 8) % 5;
		double s = scales[(it / 40) % 7], got, e;
		long double want;
		hard_tri(tk, v0);
		p = hard_point(pk, v0);
		off = px_rand_unit() < 0.5 ? px_v3(0, 0, 0)
					   : px_v3_scale(rand_unit(), s * px_rand_range(0, 1e3));
		v[0] = scaled(v0[0], s, off);
		v[1] = scaled(v0[1], s, off);
		v[2] = scaled(v0[2], s, off);
		p = scaled(p, s, off);
		e = tri_err(p, v, &got, &want);
		if (e > worst)
			worst = e;
		if (e > PX_TRI_ERR_ULPS)
			kinds[tk]++;
		PX_CHECK_MSG(e <= PX_TRI_ERR_ULPS,
			     "triangle kind %d, point kind %d, scale %g: distance %.17g, reference "
			     "%.17Lg (%.1f u (d + l))",
			     tk, pk, s, got, want, e);
	}
	printf("  px_tri_closest: worst error %.2f u (d + l) over 60000 answers (bound %g)\n",
	       worst, PX_TRI_ERR_ULPS);
	(void)kinds;
}

/*
 * The reported case: needles of aspect 1e7..1e8 with the point just
 * above the face. The distance is the height, not the in-plane distance
 * to an edge (up to 30 times too large before).
 */
static void test_needle_face(void)
{
	int it, bad = 0;
	double worst = 0.0;
	for (it = 0; it < 20000; it++) {
		px_vec3 d = rand_unit(), n = perp(d), v[3], p, base;
		double asp = pow(10.0, px_rand_range(7.0, 8.0)), got, e;
		double t = px_rand_range(0.2, 0.8), z = pow(10.0, px_rand_range(-12, -9));
		long double want;
		v[0] = px_v3(0, 0, 0);
		v[1] = d;
		v[2] = px_v3_madd(px_v3_scale(d, t), n, 1.0 / asp);
		/* above a point inside, at a height below the needle's width */
		base = px_v3_madd(px_v3_scale(d, t * px_rand_range(0.3, 0.9)), n,
				  0.5 / asp * px_rand_range(0.2, 0.8));
		p = px_v3_madd(base, px_v3_cross(d, n), z);
		e = tri_err(p, v, &got, &want);
		bad += e > PX_TRI_ERR_ULPS;
		worst = fmax(worst, (double)(got / want));
		PX_CHECK_MSG(e <= PX_TRI_ERR_ULPS,
			     "needle aspect %.3g, height %.3g: distance %.17g, reference %.17Lg "
			     "(%.3g times)",
			     asp, z, got, want, (double)(got / want));
	}
	printf("  needles 1e7..1e8: largest distance / reference %.6f\n", worst);
	(void)bad;
}

/*
 * The fast test at the edge of its filter: the angle at a just above
 * asin(1/8) (sin^2 = FAST_SIN2 = 1/64) or its supplement, points on,
 * above and beside the face and anywhere near: within the bound (its
 * error grows as 1 / sin of that angle, so this is where it is largest).
 */
static void test_fast_filter_edge(void)
{
	double worst = 0.0, got;
	long double want;
	int it;
	for (it = 0; it < 100000; it++) {
		double ang = asin(0.125) * (1.0 + 0.05 * px_rand_unit());
		double l1 = px_rand_range(0.1, 1.1), l2 = px_rand_range(0.1, 1.1), e;
		px_vec3 d = rand_unit(), n = perp(d), m = px_v3_cross(d, n), v[3], p;
		if (px_rand_unit() < 0.5)
			ang = 3.14159265358979323846 - ang;
		v[0] = px_v3(px_rand_range(-0.5, 0.5), px_rand_range(-0.5, 0.5), px_rand_range(-0.5, 0.5));
		v[1] = px_v3_madd(v[0], d, l1);
		v[2] = px_v3_madd(px_v3_madd(v[0], d, l2 * cos(ang)), n, l2 * sin(ang));
		p = hard_point(it % 5, v);
		if (it % 7 == 0) /* in the plane, just off the face */
			p = px_v3_madd(p, m, 1e-9 * px_rand_range(-1, 1));
		e = tri_err(p, v, &got, &want);
		worst = fmax(worst, e);
		PX_CHECK_MSG(e <= PX_TRI_ERR_ULPS, "angle %.17g: %.17g vs %.17Lg (%.1f u)", ang, got,
			     want, e);
	}
	printf("  fast test at its filter's edge: worst %.2f u (d + l)\n", worst);
}

/* ---- triangle pairs and segments ------------------------------------------ */

/* Reference squared distance of segments p0p1 and q0q1: the least of the
 * interior stationary point (when it lies in the unit square) and the
 * four end-point-to-segment distances. */
static q128 qsegseg(struct qv p0, struct qv p1, struct qv q0, struct qv q1)
{
	struct qv d1 = qsub(p1, p0), d2 = qsub(q1, q0), r = qsub(p0, q0);
	q128 a = qdot(d1, d1), e = qdot(d2, d2), b = qdot(d1, d2), c = qdot(d1, r),
	     f = qdot(d2, r), den = a * e - b * b, best, x;
	best = qseg(qsub(p0, q0), d2);
	x = qseg(qsub(p1, q0), d2);
	best = x < best ? x : best;
	x = qseg(qsub(q0, p0), d1);
	best = x < best ? x : best;
	x = qseg(qsub(q1, p0), d1);
	best = x < best ? x : best;
	if (den > 0) {
		q128 sv = (b * f - c * e) / den, tv = (a * f - b * c) / den;
		if (sv >= 0 && sv <= 1 && tv >= 0 && tv <= 1) {
			struct qv w = {r.x + sv * d1.x - tv * d2.x, r.y + sv * d1.y - tv * d2.y,
				       r.z + sv * d1.z - tv * d2.z};
			x = qdot(w, w);
			best = x < best ? x : best;
		}
	}
	return best;
}

/* does segment pq pass through triangle T (reference)? */
static int qcrosses(struct qv p, struct qv q, const struct qv T[3])
{
	struct qv n = qcross(qsub(T[1], T[0]), qsub(T[2], T[0])), x;
	q128 dp = qdot(n, qsub(p, T[0])), dq = qdot(n, qsub(q, T[0])), t;
	int k;
	if ((dp > 0 && dq > 0) || (dp < 0 && dq < 0) || dp == dq || qdot(n, n) == 0)
		return 0;
	t = dp / (dp - dq);
	x.x = p.x + t * (q.x - p.x);
	x.y = p.y + t * (q.y - p.y);
	x.z = p.z + t * (q.z - p.z);
	for (k = 0; k < 3; k++)
		if (qdot(qcross(qsub(T[(k + 1) % 3], T[k]), qsub(x, T[k])), n) < 0)
			return 0;
	return 1;
}

/* Reference distance of triangles A and B: 0 when an edge of one passes
 * through the other, else the least of the six vertex-triangle and nine
 * edge-edge distances. */
static long double ref_tri_tri(const px_vec3 A[3], const px_vec3 B[3])
{
	struct qv a[3], b[3];
	long double best = INFINITY;
	int i, j;
	for (i = 0; i < 3; i++) {
		a[i] = qv_of(A[i]);
		b[i] = qv_of(B[i]);
	}
	for (i = 0; i < 3; i++)
		if (qcrosses(a[i], a[(i + 1) % 3], b) || qcrosses(b[i], b[(i + 1) % 3], a))
			return 0.0L;
	for (i = 0; i < 3; i++) {
		long double d = ref_tri(A[i], B[0], B[1], B[2]);
		best = d < best ? d : best;
		d = ref_tri(B[i], A[0], A[1], A[2]);
		best = d < best ? d : best;
		for (j = 0; j < 3; j++) {
			d = sqrtl((long double)qsegseg(a[i], a[(i + 1) % 3], b[j], b[(j + 1) % 3]));
			best = d < best ? d : best;
		}
	}
	return best;
}

/*
 * Triangle pairs (the mesh-pair and mesh-primitive core): hard triangles
 * against hard triangles nearby (needles beside needles, slivers across
 * faces, nearly parallel and nearly touching pairs), at scales 1e-100 ..
 * 1e100: px__tri_tri within PX_TRI_ERR_ULPS u (d + l) of the reference,
 * l the longest edge of the two.
 */
static void test_tri_tri_bound(void)
{
	static const double scales[] = {1e-100, 1e-8, 1.0, 1e8, 1e100};
	double worst = 0.0;
	int it;
	for (it = 0; it < 20000; it++) {
		px_vec3 A[3], B[3], pa, pb, off;
		double s = scales[it % 5], l, d, e;
		long double ref;
		int k, cr;
		hard_tri(px_rand_int(0, 7), A);
		hard_tri(px_rand_int(0, 7), B);
		/* B moved next to a point of A: just above its face (1e-12 ..
		 * 1e-3), or anywhere near */
		off = px_v3_sub(hard_point(px_rand_int(0, 4) == 3 ? 0 : px_rand_int(0, 2), A), B[0]);
		for (k = 0; k < 3; k++) {
			B[k] = px_v3_scale(px_v3_add(B[k], off), s);
			A[k] = px_v3_scale(A[k], s);
		}
		d = sqrt(px__tri_tri(A, B, &pa, &pb, &cr));
		ref = ref_tri_tri(A, B);
		l = fmax(longest_edge(A[0], A[1], A[2]), longest_edge(B[0], B[1], B[2]));
		e = (double)(fabsl((long double)d - ref) - 1e-160L) / (U * ((double)ref + l));
		worst = fmax(worst, e);
		PX_CHECK_MSG(e <= PX_TRI_ERR_ULPS,
			     "pair %d scale %g: %.17g vs %.17Lg (%.1f u (d + l)), crossing %d", it, s,
			     d, ref, e, cr);
	}
	printf("  px__tri_tri: worst error %.2f u (d + l) over 20000 pairs\n", worst);
}

/*
 * The reported case for pairs: a small triangle whose lowest vertex is
 * 1e-12 .. 1e-9 above the face of a needle (aspect 1e7 .. 1e9) and rises
 * away from it; the distance is that height (the mesh pair used to
 * answer the needle's edge instead, up to 3487 times as far).
 */
static void test_needle_pair(void)
{
	double worst = 1.0;
	int it;
	for (it = 0; it < 20000; it++) {
		double asp = pow(10.0, px_rand_range(7.0, 9.0)), t = px_rand_range(0.2, 0.8);
		double z = pow(10.0, px_rand_range(-12.0, -9.0)), g = px_rand_range(0.3, 0.9), d, e;
		px_vec3 dir = rand_unit(), n = perp(dir), up = px_v3_cross(dir, n), pa, pb, tip;
		px_vec3 A[3], B[3];
		long double ref;
		int cr;
		A[0] = px_v3(0, 0, 0);
		A[1] = dir;
		A[2] = px_v3_madd(px_v3_scale(dir, t), n, 1.0 / asp);
		/* above a point inside the needle */
		tip = px_v3_madd(px_v3_madd(px_v3_scale(dir, t * g), n, g / asp * px_rand_range(0.2, 0.8)),
				 up, z);
		B[0] = tip;
		B[1] = px_v3_madd(tip, up, 0.3);
		B[2] = px_v3_madd(B[1], dir, 0.2);
		d = sqrt(px__tri_tri(A, B, &pa, &pb, &cr));
		ref = ref_tri_tri(A, B);
		e = (double)fabsl((long double)d - ref) / (U * ((double)ref + 1.0));
		worst = fmax(worst, d / (double)ref);
		PX_CHECK_MSG(e <= PX_TRI_ERR_ULPS,
			     "needle aspect %.3g, height %.3g: %.17g vs %.17Lg (%.3g times)", asp, z, d,
			     ref, d / (double)ref);
	}
	printf("  needle pairs: largest distance / reference %.6f\n", worst);
}

/*
 * Segments against segments and against triangles (capsule pairs and
 * capsule-mesh pairs): nearly parallel segments (angles 1e-3 .. 1e-9),
 * crossing and touching ones, at scales 1e-100 .. 1e100.
 */
static void test_seg_bound(void)
{
	static const double scales[] = {1e-100, 1e-8, 1.0, 1e8, 1e100};
	double worst = 0.0, worst_t = 0.0;
	int it;
	for (it = 0; it < 20000; it++) {
		double s = scales[it % 5], a, b, l, e, d;
		px_vec3 dir = rand_unit(), n = perp(dir), p0, p1, q0, q1, v[3], qq;
		long double ref;
		int k;
		p0 = px_v3_scale(rand_unit(), px_rand_range(0, 1));
		p1 = px_v3_madd(p0, dir, px_rand_range(0.1, 2));
		q0 = px_v3_madd(px_v3_madd(p0, dir, px_rand_range(-1, 1)), n,
				pow(10.0, px_rand_range(-12, 0)));
		q1 = px_v3_madd(q0, px_v3_add(dir, px_v3_scale(perp(dir), pow(10.0, px_rand_range(-9, -3)))),
				px_rand_range(0.1, 2) * (px_rand_unit() < 0.5 ? -1 : 1));
		p0 = px_v3_scale(p0, s);
		p1 = px_v3_scale(p1, s);
		q0 = px_v3_scale(q0, s);
		q1 = px_v3_scale(q1, s);
		d = sqrt(px__seg_seg(p0, p1, q0, q1, &a, &b));
		ref = sqrtl((long double)qsegseg(qv_of(p0), qv_of(p1), qv_of(q0), qv_of(q1)));
		l = fmax(px_v3_dist(p0, p1), px_v3_dist(q0, q1));
		e = (double)(fabsl((long double)d - ref) - 1e-160L) / (U * ((double)ref + l));
		worst = fmax(worst, e);
		PX_CHECK_MSG(e <= PX_TRI_ERR_ULPS,
			     "segments %d scale %g: %.17g vs %.17Lg (%.1f u): (%.17g %.17g %.17g) "
			     "(%.17g %.17g %.17g) (%.17g %.17g %.17g) (%.17g %.17g %.17g)",
			     it, s, d, ref, e, p0.x, p0.y, p0.z, p1.x, p1.y, p1.z, q0.x, q0.y, q0.z,
			     q1.x, q1.y, q1.z);
		/* the same pair as two collapsed triangles (the mesh pair's
		 * edge-edge distance) */
		{
			px_vec3 T1[3] = {p0, p1, p1}, T2[3] = {q0, q1, q1}, x1, x2;
			int cr;
			d = sqrt(px__tri_tri(T1, T2, &x1, &x2, &cr));
			e = (double)(fabsl((long double)d - ref) - 1e-160L) / (U * ((double)ref + l));
			worst = fmax(worst, e);
			PX_CHECK_MSG(e <= PX_TRI_ERR_ULPS,
				     "edges as triangles %d scale %g: %.17g vs %.17Lg (%.1f u)", it, s, d,
				     ref, e);
		}
		/* the segment against a hard triangle placed at it */
		hard_tri(px_rand_int(0, 7), v);
		for (k = 0; k < 3; k++)
			v[k] = px_v3_add(px_v3_scale(v[k], s), px_v3_scale(px_v3_sub(p0, p1), 0.5 * px_rand_unit()));
		d = sqrt(px__seg_tri(p0, p1, v, &a, &qq));
		{
			px_vec3 T[3] = {p0, p1, p1};
			ref = ref_tri_tri(T, v);
		}
		l = fmax(px_v3_dist(p0, p1), longest_edge(v[0], v[1], v[2]));
		e = (double)(fabsl((long double)d - ref) - 1e-160L) / (U * ((double)ref + l));
		worst_t = fmax(worst_t, e);
		PX_CHECK_MSG(e <= PX_TRI_ERR_ULPS,
			     "segment-triangle %d scale %g: %.17g vs %.17Lg (%.1f u)", it, s, d, ref, e);
	}
	printf("  px__seg_seg: worst %.2f u (d + l); px__seg_tri: worst %.2f\n", worst, worst_t);
}

static void comp_set(px_vec3 *v, int i, double x)
{
	if (i == 0)
		v->x = x;
	else if (i == 1)
		v->y = x;
	else
		v->z = x;
}

/* squared distance of x to the box |x_k| <= h_k, long double */
static long double ld_box_d2(const long double x[3], const double h[3])
{
	long double s = 0;
	int k;
	for (k = 0; k < 3; k++) {
		long double o = fabsl(x[k]) - h[k];
		if (o > 0)
			s += o * o;
	}
	return s;
}

/* Reference segment-box distance: the squared distance along the
 * segment is convex, so a golden-section search in long double finds
 * its least value (200 steps: the bracket shrinks far below rounding). */
static long double ref_seg_box(px_vec3 p0, px_vec3 p1, const double h[3])
{
	long double lo = 0, hi = 1, g = 0.6180339887498948482L, best;
	long double P[3] = {p0.x, p0.y, p0.z}, D[3] = {(long double)p1.x - p0.x,
							(long double)p1.y - p0.y,
							(long double)p1.z - p0.z};
	int it, k;
	for (it = 0; it < 200; it++) {
		long double t1 = hi - g * (hi - lo), t2 = lo + g * (hi - lo), x1[3], x2[3];
		for (k = 0; k < 3; k++) {
			x1[k] = P[k] + t1 * D[k];
			x2[k] = P[k] + t2 * D[k];
		}
		if (ld_box_d2(x1, h) <= ld_box_d2(x2, h))
			hi = t2;
		else
			lo = t1;
	}
	{
		long double x[3], e[3], t = 0.5L * (lo + hi);
		for (k = 0; k < 3; k++) {
			x[k] = P[k] + t * D[k];
			e[k] = P[k];
		}
		best = ld_box_d2(x, h);
		/* and the end points, where a search bracket may stop short */
		x[0] = e[0] + D[0];
		x[1] = e[1] + D[1];
		x[2] = e[2] + D[2];
		if (ld_box_d2(e, h) < best)
			best = ld_box_d2(e, h);
		if (ld_box_d2(x, h) < best)
			best = ld_box_d2(x, h);
	}
	return sqrtl(best);
}

/*
 * Segments against boxes (capsule-box pairs): segments nearly parallel
 * to a face or an edge, grazing a corner, crossing, at scales 1e-100 ..
 * 1e100: px__seg_box within PX_TRI_ERR_ULPS u (d + size).
 */
static void test_seg_box_bound(void)
{
	static const double scales[] = {1e-100, 1e-8, 1.0, 1e8, 1e100};
	double worst = 0.0;
	int it;
	for (it = 0; it < 20000; it++) {
		double s = scales[it % 5], h[3], t, size, e, d;
		px_vec3 p0, p1, q, dir;
		long double ref;
		int k;
		for (k = 0; k < 3; k++)
			h[k] = s * px_rand_range(0.1, 1.0) / (px_rand_unit() < 0.2 ? 1e6 : 1.0);
		/* start near a face, an edge or a corner, run nearly along it */
		p0 = px_v3(h[0] * px_rand_range(-1.2, 1.2), h[1] * px_rand_range(-1.2, 1.2),
			   h[2] * px_rand_range(-1.2, 1.2));
		comp_set(&p0, it % 3, h[it % 3] * (1.0 + pow(10.0, px_rand_range(-12, 0))));
		dir = rand_unit();
		comp_set(&dir, it % 3, px_v3_comp(dir, it % 3) * pow(10.0, px_rand_range(-9, 0)));
		p1 = px_v3_madd(p0, dir, s * px_rand_range(0.1, 3.0));
		d = sqrt(px__seg_box(p0, p1, h, &t, &q));
		ref = ref_seg_box(p0, p1, h);
		size = fmax(h[0], fmax(h[1], fmax(h[2], px_v3_dist(p0, p1))));
		e = (double)(fabsl((long double)d - ref) - 1e-160L) / (U * ((double)ref + size));
		worst = fmax(worst, e);
		PX_CHECK_MSG(e <= PX_TRI_ERR_ULPS, "segment-box %d scale %g: %.17g vs %.17Lg (%.1f u)",
			     it, s, d, ref, e);
	}
	printf("  px__seg_box: worst %.2f u (d + size)\n", worst);
}

/* ---- meshes ---------------------------------------------------------------- */

/* least reference distance over every triangle of the arrays */
static long double ref_mesh(const double *xyz, const uint32_t *tri, size_t nt, px_vec3 p,
			    double *lmax)
{
	long double best = INFINITY;
	size_t i;
	*lmax = 0.0;
	for (i = 0; i < nt; i++) {
		px_vec3 v[3];
		long double d;
		int k;
		for (k = 0; k < 3; k++) {
			const double *X = xyz + 3 * tri[3 * i + k];
			v[k] = px_v3(X[0], X[1], X[2]);
		}
		d = ref_tri(p, v[0], v[1], v[2]);
		if (d < best)
			best = d;
		*lmax = fmax(*lmax, longest_edge(v[0], v[1], v[2]));
	}
	return best;
}

/*
 * A closed thin prism (a needle solid: a triangle of width 1e-7 .. 1e-9
 * swept along 1 m, capped; every side triangle a needle) and an open fan
 * of needles, at scales 1e-100 .. 1e100, with and without a hint grid:
 * every query answers within the bound of the linear reference, and
 * coherent queries agree.
 */
static void test_mesh_needles(void)
{
	static const double scales[] = {1e-100, 1e-20, 1.0, 1e20, 1e100};
	double worst = 0.0;
	int sc, g;
	for (sc = 0; sc < 5; sc++)
		for (g = 0; g < 2; g++) {
			double s = scales[sc], w = pow(10.0, -px_rand_range(7.0, 9.0));
			/* prism: triangle (0,0) (w,0) (w/2, w) in yz, x from 0 to 1 */
			double xyz[3 * 6 + 3 * 12];
			uint32_t tri[3 * 8 + 3 * 10];
			static const uint32_t pt[] = {0, 2, 1, 3, 4, 5, 0, 1, 4, 0, 4, 3,
						      1, 2, 5, 1, 5, 4, 2, 0, 3, 2, 3, 5};
			struct px_mesh_opts opt;
			struct px_mesh_report rp;
			struct px_model *m;
			size_t nv = 6, nt = 8, i;
			int k, it;
			double yz[3][2] = {{0, 0}, {w, 0}, {w / 2, w}};
			for (i = 0; i < 3; i++) {
				xyz[3 * i] = 0.0;
				xyz[3 * i + 1] = yz[i][0] * s;
				xyz[3 * i + 2] = yz[i][1] * s;
				xyz[3 * (i + 3)] = s;
				xyz[3 * (i + 3) + 1] = yz[i][0] * s;
				xyz[3 * (i + 3) + 2] = yz[i][1] * s;
			}
			memcpy(tri, pt, sizeof(pt));
			/* fan of needles beside it (z = 2 w s), 12 vertices */
			for (i = 0; i < 12; i++) {
				xyz[3 * (nv + i)] = s * (double)i / 11.0;
				xyz[3 * (nv + i) + 1] = s * (i % 2 ? w : 0.0) + 3 * w * s;
				xyz[3 * (nv + i) + 2] = 2 * w * s;
			}
			for (i = 0; i < 10; i++) {
				tri[3 * (nt + i)] = (uint32_t)(nv + i);
				tri[3 * (nt + i) + 1] = (uint32_t)(nv + i + 1);
				tri[3 * (nt + i) + 2] = (uint32_t)(nv + i + 2);
			}
			nv += 12;
			nt += 10;
			memset(&opt, 0, sizeof(opt));
			opt.grid_cells = g ? 64 : 0;
			PX_CHECK_INT_EQ(px_mesh_model(xyz, nv, tri, nt, &opt, &rp, &m), PX_OK);
			for (it = 0; it < 400; it++) {
				struct px_model_result r;
				long double ref;
				double lmax, e;
				px_vec3 p = px_v3(px_rand_range(-0.1, 1.1) * s,
						  px_rand_range(-2, 6) * w * s, px_rand_range(-2, 4) * w * s);
				if (it % 4 == 1) /* far */
					p = px_v3_madd(p, rand_unit(), 1e6 * s);
				if (it % 4 == 2) /* on a side face, 1e-12 of w off */
					p = px_v3(px_rand_range(0.1, 0.9) * s, px_rand_range(0.3, 0.7) * w * s,
						  -1e-12 * w * s * px_rand_range(-1, 1));
				ref = ref_mesh(xyz, tri, nt, p, &lmax);
				PX_CHECK_INT_EQ(px_model_query(m, p, &r), 1);
				e = (double)(fabsl((long double)fabs(r.distance) - ref) - 1e-160L) /
				    (U * ((double)ref + lmax));
				worst = fmax(worst, e);
				PX_CHECK_MSG(e <= PX_TRI_ERR_ULPS,
					     "scale %g width %.3g grid %d point %d: %.17g vs %.17Lg "
					     "(%.1f u)",
					     s, w, g, it, r.distance, ref, e);
				for (k = 0; k < 1; k++) {
					struct px_model_result r2;
					PX_CHECK_INT_EQ(px_model_query_ex(m, p, INFINITY, PX_QUERY_COHERENT,
									  r.index, &r2),
							1);
					PX_CHECK(fabs(fabs(r2.distance) - fabs(r.distance)) <=
						 PX_TRI_ERR_ULPS * U * ((double)ref + lmax));
				}
			}
			px_model_free(m);
		}
	printf("  needle meshes: worst error %.2f u (d + l)\n", worst);
}

/*
 * A closed needle solid alone (the prism above: side triangles of aspect
 * 1e7..1e9, all taking the robust test): watertight, and the sign right
 * for points inside its thin cross-section and just outside it, at
 * scales 1e-100 .. 1e100, with distances within the bound.
 */
static void test_needle_solid_sign(void)
{
	static const double scales[] = {1e-100, 1.0, 1e100};
	static const uint32_t pt[] = {0, 2, 1, 3, 4, 5, 0, 1, 4, 0, 4, 3,
				      1, 2, 5, 1, 5, 4, 2, 0, 3, 2, 3, 5};
	int sc, it;
	for (sc = 0; sc < 3; sc++) {
		double s = scales[sc], w = pow(10.0, -px_rand_range(7.0, 9.0)), xyz[18];
		double yz[3][2] = {{0, 0}, {w, 0}, {w / 2, w}};
		struct px_mesh_report rp;
		struct px_model *m;
		size_t i;
		for (i = 0; i < 3; i++) {
			xyz[3 * i] = 0.0;
			xyz[3 * (i + 3)] = s;
			xyz[3 * i + 1] = xyz[3 * (i + 3) + 1] = yz[i][0] * s;
			xyz[3 * i + 2] = xyz[3 * (i + 3) + 2] = yz[i][1] * s;
		}
		PX_CHECK_MSG(px_mesh_model(xyz, 6, pt, 8, NULL, &rp, &m) == PX_OK, "%s", rp.message);
		PX_CHECK_MSG(rp.closed, "needle prism not closed: %s", rp.message);
		for (it = 0; it < 300; it++) {
			struct px_model_result r;
			/* inside: a point of the cross-section's interior; outside:
			 * beyond one of its sides by up to w */
			double x = px_rand_range(0.05, 0.95) * s;
			double a0 = px_rand_range(0.1, 0.8), a1 = px_rand_range(0.1, 0.9) * (1 - a0);
			double y = (a0 * yz[1][0] + a1 * yz[2][0]) * s, z = (a0 * yz[1][1] + a1 * yz[2][1]) * s;
			int inside = it % 2 == 0;
			double lmax, e;
			long double ref;
			px_vec3 p;
			if (!inside)
				z = -px_rand_range(1e-6, 1.0) * w * s; /* below the bottom side */
			p = px_v3(x, y, z);
			ref = ref_mesh(xyz, pt, 8, p, &lmax);
			PX_CHECK_INT_EQ(px_model_query(m, p, &r), 1);
			PX_CHECK(r.is_signed);
			PX_CHECK_MSG(r.inside == inside,
				     "scale %g width %.3g: point %s reported %s (distance %.17g)", s, w,
				     inside ? "inside" : "outside", r.inside ? "inside" : "outside",
				     r.distance);
			e = (double)(fabsl((long double)fabs(r.distance) - ref) - 1e-160L) /
			    (U * ((double)ref + lmax));
			PX_CHECK_MSG(e <= PX_TRI_ERR_ULPS, "scale %g: %.17g vs %.17Lg (%.1f u)", s,
				     r.distance, ref, e);
		}
		px_model_free(m);
	}
}

/*
 * The accepted range: a vertex beyond 1e150 (and 1e250, 1e308: where
 * answers used to go wrong) is refused with PX_E_RANGE and a message
 * naming the vertex; so is a mesh smaller than 1e-140. At 1e150 itself
 * the mesh builds, also with a hint grid, and answers within the bound;
 * a query point beyond the query reach is refused.
 */
static void test_mesh_range(void)
{
	static const double big[] = {1.01e150, 1e200, 1e250, 1e308, -1e300};
	double xyz[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
	uint32_t tri[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
	struct px_mesh_report rp;
	struct px_mesh_opts opt;
	struct px_model *m = NULL;
	int i, it;

	for (i = 0; i < 5; i++) {
		double x[12];
		memcpy(x, xyz, sizeof(x));
		x[3 * 2 + 1] = big[i];
		PX_CHECK_INT_EQ(px_mesh_model(x, 4, tri, 4, NULL, &rp, &m), PX_E_RANGE);
		PX_CHECK(m == NULL);
		PX_CHECK_MSG(strstr(rp.message, "vertex 2") != NULL && strstr(rp.message, "range"),
			     "%s", rp.message);
	}
	{
		double x[12];
		for (i = 0; i < 12; i++)
			x[i] = xyz[i] * 1e-200 + 1.0;
		/* extent 1e-200 (the coordinates round to 1: extent 0, accepted) */
		PX_CHECK_INT_EQ(px_mesh_model(x, 4, tri, 4, NULL, &rp, &m), PX_OK);
		px_model_free(m);
		for (i = 0; i < 12; i++)
			x[i] = xyz[i] * 1e-200;
		PX_CHECK_INT_EQ(px_mesh_model(x, 4, tri, 4, NULL, &rp, &m), PX_E_RANGE);
		PX_CHECK_MSG(strstr(rp.message, "extent") != NULL, "%s", rp.message);
	}
	/* 1e150 and -1e150: the largest accepted, with and without a grid */
	for (i = 0; i < 2; i++) {
		double x[3 * 40];
		uint32_t t[3 * 38];
		size_t nt = 38, k;
		for (k = 0; k < 40; k++) {
			x[3 * k] = 1e150 * cos(0.3 * (double)k) * (k % 2 ? 1 : -1);
			x[3 * k + 1] = 1e150 * sin(0.7 * (double)k);
			x[3 * k + 2] = 1e150 * ((double)(k % 3) - 1.0) * 0.9;
		}
		for (k = 0; k < nt; k++) {
			t[3 * k] = (uint32_t)k;
			t[3 * k + 1] = (uint32_t)k + 1;
			t[3 * k + 2] = (uint32_t)k + 2;
		}
		memset(&opt, 0, sizeof(opt));
		opt.grid_cells = i ? PX_MESH_MAX_GRID_CELLS : 0;
		PX_CHECK_MSG(px_mesh_model(x, 40, t, nt, &opt, &rp, &m) == PX_OK, "%s", rp.message);
		for (it = 0; it < 200; it++) {
			struct px_model_result r;
			px_vec3 p = px_v3(px_rand_range(-1.5e150, 1.5e150), px_rand_range(-1.5e150, 1.5e150),
					  px_rand_range(-1.5e150, 1.5e150));
			double lmax, e;
			long double ref = ref_mesh(x, t, nt, p, &lmax);
			PX_CHECK_INT_EQ(px_model_query(m, p, &r), 1);
			PX_CHECK(isfinite(r.distance));
			e = (double)(fabsl((long double)fabs(r.distance) - ref)) / (U * ((double)ref + lmax));
			PX_CHECK_MSG(e <= PX_TRI_ERR_ULPS, "1e150 mesh: %.17g vs %.17Lg (%.1f u)",
				     r.distance, ref, e);
		}
		{
			struct px_model_result r;
			PX_CHECK_INT_EQ(px_model_query(m, px_v3(0, 0, 5e150), &r), PX_E_RANGE);
		}
		px_model_free(m);
	}
}

/*
 * Hint grids at the ends of the accepted range: meshes of extent 1e-139
 * (the volume of the grown box underflows to 0 there), 1e-100, 1 and
 * 2e150, flat ones among them, with the largest grid budget: setup
 * neither crashes nor overflows a cell count, and every answer agrees
 * with the one without the grid.
 */
static void test_grid_extremes(void)
{
	static const double scales[] = {1e-139, 1e-100, 1.0, 1e150};
	int sc, flat;
	for (sc = 0; sc < 4; sc++)
		for (flat = 0; flat < 2; flat++) {
			enum { N = 300 };
			double *xyz = malloc(9 * N * sizeof(double));
			uint32_t *tri = malloc(3 * N * sizeof(uint32_t));
			struct px_mesh_opts opt;
			struct px_mesh_report rp;
			struct px_model *mg, *m0;
			double s = scales[sc];
			size_t i;
			int it;
			PX_CHECK(xyz && tri);
			for (i = 0; i < 9 * N; i++)
				xyz[i] = (i % 3 == 2 && flat) ? 0.0 : s * px_rand_range(-1, 1);
			for (i = 0; i < 3 * N; i++)
				tri[i] = (uint32_t)i;
			memset(&opt, 0, sizeof(opt));
			PX_CHECK_MSG(px_mesh_model(xyz, 3 * N, tri, N, &opt, &rp, &m0) == PX_OK, "%s",
				     rp.message);
			opt.grid_cells = PX_MESH_MAX_GRID_CELLS;
			PX_CHECK_MSG(px_mesh_model(xyz, 3 * N, tri, N, &opt, &rp, &mg) == PX_OK, "%s",
				     rp.message);
			for (it = 0; it < 200; it++) {
				struct px_model_result a, b;
				/* within the query reach (1e150 beyond the box) at 1e150 */
				px_vec3 p = px_v3_scale(rand_unit(), s * px_rand_range(0, sc == 3 ? 0.99 : 3.0));
				PX_CHECK_INT_EQ(px_model_query(m0, p, &a), 1);
				PX_CHECK_INT_EQ(px_model_query(mg, p, &b), 1);
				/* both exact: equal within the bound (ties of
				 * triangles may be broken differently) */
				PX_CHECK_MSG(fabs(a.distance - b.distance) <=
						     PX_TRI_ERR_ULPS * U * (fabs(a.distance) + 4 * s),
					     "scale %g flat %d: grid %.17g, none %.17g", s, flat,
					     b.distance, a.distance);
			}
			px_model_free(m0);
			px_model_free(mg);
			free(xyz);
			free(tri);
		}
}

/* px_tri_closest refuses coordinates beyond its range (NaN: no answer
 * rather than an overflowed one) and non-finite ones. */
static void test_tri_range(void)
{
	px_vec3 a = px_v3(0, 0, 0), b = px_v3(1, 0, 0), c = px_v3(0, 1, 0), q;
	int f, s;
	double d2 = px_tri_closest(px_v3(0, 0, 1e200), a, b, c, &q, &f, &s, NULL, NULL);
	PX_CHECK(isnan(d2));
	PX_CHECK_INT_EQ(f, PX_FEATURE_NONE);
	d2 = px_tri_closest(px_v3(0, 0, 1), a, px_v3(1e300, 0, 0), c, &q, &f, &s, NULL, NULL);
	PX_CHECK(isnan(d2));
	d2 = px_tri_closest(px_v3(0, 0, NAN), a, b, c, &q, &f, &s, NULL, NULL);
	PX_CHECK(isnan(d2));
	/* the largest accepted: finite and right */
	d2 = px_tri_closest(px_v3(0.25e152, 0.25e152, 1e152), px_v3(0, 0, 0),
			    px_v3(1e152, 0, 0), px_v3(0, 1e152, 0), &q, &f, &s, NULL, NULL);
	PX_CHECK_CLOSE(sqrt(d2), 1e152, 0.0, 4 * U);
	PX_CHECK_INT_EQ(f, PX_FEATURE_FACE);
}

/* ---- primitives ------------------------------------------------------------ */

/* long double reference: signed distance of q to primitive p */
static long double ld_seg2(long double px, long double pz, long double ax, long double az,
			   long double bx, long double bz)
{
	long double dx = bx - ax, dz = bz - az, l2 = dx * dx + dz * dz, t = 0;
	if (l2 > 0) {
		t = ((px - ax) * dx + (pz - az) * dz) / l2;
		t = t < 0 ? 0 : (t > 1 ? 1 : t);
	}
	dx = px - (ax + t * dx);
	dz = pz - (az + t * dz);
	return sqrtl(dx * dx + dz * dz);
}

static long double ref_prim(const struct px_prim *p, px_vec3 q)
{
	long double x = q.x, y = q.y, z = q.z, rho = sqrtl(x * x + y * y);
	long double a = p->a, b = p->b, c = p->c;
	switch (p->type) {
	case PX_PRIM_SPHERE:
		return sqrtl(x * x + y * y + z * z) - a;
	case PX_PRIM_BOX: {
		long double o[3] = {fabsl(x) - a, fabsl(y) - b, fabsl(z) - c}, s = 0, m = o[0];
		int k;
		for (k = 0; k < 3; k++) {
			if (o[k] > 0)
				s += o[k] * o[k];
			if (o[k] > m)
				m = o[k];
		}
		return m > 0 ? sqrtl(s) : m;
	}
	case PX_PRIM_CAPSULE: {
		long double zc = z < -b ? -b : (z > b ? b : z);
		return sqrtl(rho * rho + (z - zc) * (z - zc)) - a;
	}
	case PX_PRIM_CYLINDER:
	case PX_PRIM_CONE: {
		long double r0 = a, r1 = p->type == PX_PRIM_CONE ? c : a, h = b;
		long double d = ld_seg2(rho, z, 0, -h, r0, -h), e;
		int inside;
		e = ld_seg2(rho, z, r0, -h, r1, h);
		d = e < d ? e : d;
		e = ld_seg2(rho, z, r1, h, 0, h);
		d = e < d ? e : d;
		inside = fabsl(z) <= h && rho <= r0 + (r1 - r0) * (z + h) / (2 * h);
		return inside ? -d : d;
	}
	case PX_PRIM_TORUS:
		return sqrtl((rho - a) * (rho - a) + z * z) - b;
	default:
		return z;
	}
}

static double prim_size(const struct px_prim *p)
{
	return fmax(fabs(p->a), fmax(fabs(p->b), fabs(p->c)));
}

/*
 * Every primitive at scales 1e-100 .. 1e100 with thin and flat shapes
 * (aspect up to 1e9), points near the surface (1e-12 of the size),
 * inside, and far away (1e6 times the size): the signed distance within
 * the documented bound of the long double reference, and the reported
 * point at the reported distance.
 */
static void test_prim_bound(void)
{
	static const double scales[] = {1e-100, 1e-30, 1e-3, 1.0, 1e3, 1e30, 1e100};
	double worst = 0.0;
	int it;
	for (it = 0; it < 40000; it++) {
		struct px_prim p;
		struct px_model_result r;
		double s = scales[it % 7], asp = pow(10.0, px_rand_range(0, 9)), e, size;
		long double ref;
		px_vec3 q;
		memset(&p, 0, sizeof(p));
		p.type = (enum px_prim_type)(1 + (it / 7) % 7);
		p.a = s * px_rand_range(0.5, 1.5);
		p.b = s * px_rand_range(0.5, 1.5) / (px_rand_unit() < 0.3 ? asp : 1.0);
		p.c = s * px_rand_range(0.5, 1.5) * (px_rand_unit() < 0.3 ? asp : 1.0);
		if (p.type == PX_PRIM_TORUS && !(p.b < p.a))
			p.b = p.a * 0.5;
		if (p.type == PX_PRIM_CONE && px_rand_unit() < 0.3)
			p.c = 0.0;
		if (p.type == PX_PRIM_CAPSULE || p.type == PX_PRIM_CYLINDER)
			p.a = p.a / (px_rand_unit() < 0.3 ? asp : 1.0);
		PX_CHECK_INT_EQ(px_prim_check(&p), PX_OK);
		size = prim_size(&p);
		q = px_v3_scale(rand_unit(), size * px_rand_range(0, 2));
		if (it % 3 == 1) {
			/* near the surface: step from the closest point along
			 * the normal by 1e-12 .. 1e-3 of the size */
			PX_CHECK_INT_EQ(px_prim_closest(&p, q, 0, &r), PX_OK);
			q = px_v3_madd(r.point, r.direction,
				       size * pow(10.0, px_rand_range(-12, -3)) *
					       (px_rand_unit() < 0.5 ? -1 : 1));
		} else if (it % 3 == 2) {
			q = px_v3_scale(rand_unit(), size * 1e6 * px_rand_range(1, 2));
		}
		PX_CHECK_INT_EQ(px_prim_closest(&p, q, 0, &r), PX_OK);
		ref = ref_prim(&p, q);
		e = (double)fabsl((long double)r.distance - ref) / (U * (px_v3_norm(q) + size));
		worst = fmax(worst, e);
		PX_CHECK_MSG(e <= PX_PRIM_ERR_ULPS,
			     "primitive %d (%g %g %g) at (%g %g %g): %.17g vs %.17Lg (%.1f u)",
			     p.type, p.a, p.b, p.c, q.x, q.y, q.z, r.distance, ref, e);
		PX_CHECK_MSG(fabs(px_v3_dist(q, r.point) - fabs(r.distance)) <=
				     PX_PRIM_ERR_ULPS * U * (px_v3_norm(q) + size),
			     "primitive %d: point at %.17g, distance %.17g", p.type,
			     px_v3_dist(q, r.point), r.distance);
	}
	printf("  primitives: worst error %.2f u (|q| + size)\n", worst);
}

/* Lengths beyond the accepted range are refused (PX_E_RANGE) by the
 * check and by the model; at the limits the answers are finite. */
static void test_prim_range(void)
{
	static const enum px_prim_type ty[] = {PX_PRIM_SPHERE, PX_PRIM_BOX, PX_PRIM_CAPSULE,
					       PX_PRIM_CYLINDER, PX_PRIM_CONE, PX_PRIM_TORUS};
	int i;
	for (i = 0; i < 6; i++) {
		struct px_prim p = {ty[i], 1e200, 1e199, 1e199};
		struct px_model *m = NULL;
		struct px_model_result r;
		PX_CHECK_INT_EQ(px_prim_check(&p), PX_E_RANGE);
		PX_CHECK_INT_EQ(px_prim_model(&p, &m), PX_E_RANGE);
		PX_CHECK(m == NULL);
		p.a = 2e-150;
		p.b = 1e-150;
		p.c = 1e-150;
		PX_CHECK_INT_EQ(px_prim_check(&p), PX_E_RANGE);
		p.a = PX_PRIM_MAX_LENGTH;
		p.b = PX_PRIM_MAX_LENGTH / 2;
		p.c = PX_PRIM_MAX_LENGTH / 2;
		PX_CHECK_INT_EQ(px_prim_check(&p), PX_OK);
		PX_CHECK_INT_EQ(px_prim_closest(&p, px_v3(3e150, -2e150, 1e150), 0, &r), PX_OK);
		PX_CHECK(isfinite(r.distance) && px_v3_isfinite(r.point));
		PX_CHECK_MSG((double)fabsl((long double)r.distance -
					   ref_prim(&p, px_v3(3e150, -2e150, 1e150))) <=
				     PX_PRIM_ERR_ULPS * U * 5e150,
			     "type %d at the limit: %.17g", ty[i], r.distance);
	}
}

static const struct px_test tests[] = {
	PX_T(test_tri_bound),   PX_T(test_needle_face), PX_T(test_fast_filter_edge),
	PX_T(test_tri_range),
	PX_T(test_tri_tri_bound), PX_T(test_needle_pair), PX_T(test_seg_bound),
	PX_T(test_seg_box_bound),
	PX_T(test_mesh_needles), PX_T(test_needle_solid_sign), PX_T(test_mesh_range), PX_T(test_grid_extremes),
	PX_T(test_prim_bound),
	PX_T(test_prim_range),
};

PX_TEST_MAIN(tests)
