/*
 * mesh_tri.c - exact point-triangle distance (px_tri_closest, and the
 * mesh walk's test through tri_core in mesh_internal.h), the accurate
 * unit normal, and the triangle shape tests of mesh setup.
 */
#include <math.h>

#include "mesh_internal.h"
#include "px_mesh.h"

/*
 * Accuracy (px_mesh.h states the bound): the answer is the distance to
 * a triangle whose vertices lie within a few units of rounding of the
 * given ones, and that distance moves by at most as much as a vertex
 * does, so it is right to a small multiple of u (d + l) (u = 2^-53, d
 * the distance, l the longest edge). Two computations reach it:
 *
 * - The fast one (px__tri_core: Ericson's Voronoi-region walk on the dot
 *   products at vertex a, the face point by the plain cross-product
 *   normal) errs by about u (d + l) / sin(A), A the angle at a: the
 *   normal's rounding is u |ab| |ac| per component against |n| = |ab|
 *   |ac| sin(A), and the region tests vc, vb, va (Lagrange: vc = n .
 *   (ab x ap)) carry the same factor. It is used where sin^2(A) >=
 *   FAST_SIN2, which keeps that factor at 8 at most, and where no
 *   product of four differences can overflow or sink into subnormals
 *   (edges between 2^-100 and 2^100, |p - a| below 2^100).
 * - The robust one (px__tri_exact) everywhere else: differences scaled by a
 *   power of two (exact) so that the longest edge is about 1, the
 *   normal by an error-free difference of products (fma), the face
 *   point when its projection lies inside all three edges (side tests
 *   n . (e x w), which carry the rounding of w only), and else the
 *   nearest of the three edges. Its error does not depend on the shape
 *   (needles of any aspect ratio) or on the scale.
 */
#define FAST_SIN2 (1.0 / 64.0)

/* a * b - c * d with one rounding error (Kahan: the rounding error of
 * c * d is recovered exactly by the fma). */
static inline double dop(double a, double b, double c, double d)
{
	double w = c * d;
	double e = fma(-c, d, w);
	return fma(a, b, -w) + e;
}

px_vec3 px__cross_acc(px_vec3 u, px_vec3 w)
{
	return px_v3(dop(u.y, w.z, u.z, w.y), dop(u.z, w.x, u.x, w.z),
		     dop(u.x, w.y, u.y, w.x));
}

px_vec3 px__unit_normal_acc(px_vec3 a, px_vec3 b, px_vec3 c)
{
	px_vec3 ab = px_v3_sub(b, a), ac = px_v3_sub(c, a), n;
	double m = px__mx2(px__amax3(ab), px__amax3(ac)), s, l;
	int e;
	if (!(m > 0.0) || !isfinite(m))
		return px_v3(0, 0, 0);
	s = px__pow2_scale(m, &e);
	n = px__cross_acc(px_v3_scale(ab, s), px_v3_scale(ac, s));
	l = sqrt(px_v3_norm2(n));
	return l > 0.0 ? px_v3_scale(n, 1.0 / l) : px_v3(0, 0, 0);
}

/* Closest point of segment P + t E (t in [0, 1]) to the point at W from
 * P: squared distance and t, computed from the differences only (no
 * absolute coordinate enters, so the error is relative to |W| + |E|). An
 * edge whose squared length underflows is its start point (it is then
 * shorter than any rounding of the answer). */
static inline double seg_d2(px_vec3 W, px_vec3 E, double *t)
{
	double l2 = px_v3_norm2(E), s = 0.0;
	if (l2 > 0x1p-1000) {
		s = px_v3_dot(W, E) / l2;
		s = s < 0.0 ? 0.0 : (s > 1.0 ? 1.0 : s);
	}
	*t = s;
	return px_v3_norm2(px_v3_madd(W, E, -s));
}

double px__tri_exact(px_vec3 p, px_vec3 a, px_vec3 b, px_vec3 c, px_vec3 *q,
		     int *feature, int *sub, double *u, double *v)
{
	px_vec3 P[3] = {a, b, c}, E[3], W[3], n;
	double m, wm, s, d2[3], t[3], best, nn;
	int k, e, bk;

	for (k = 0; k < 3; k++) {
		E[k] = px_v3_sub(P[(k + 1) % 3], P[k]);
		W[k] = px_v3_sub(p, P[k]);
	}
	m = px__mx2(px__amax3(E[0]), px__mx2(px__amax3(E[1]), px__amax3(E[2])));
	wm = px__amax3(W[0]);
	if (!(m > 0.0)) {
		/* one point */
		*q = a;
		*feature = PX_FEATURE_VERTEX;
		*sub = 0;
		*u = *v = 0.0;
		return px_v3_norm2(W[0]);
	}
	if (wm > 0x1p400 * m) {
		/* So far away that the scaled squares below could overflow:
		 * the closest feature is that of the point moved along the
		 * ray from a to 2^399 times the triangle's size (the feature
		 * of a receding point settles long before: the differences
		 * are 2^-399 of the distance), the distance p's own. */
		px_vec3 pn = px_v3_madd(a, W[0], 0x1p399 * m / wm);
		(void)px__tri_exact(pn, a, b, c, q, feature, sub, u, v);
		return px_v3_dist2(p, *q);
	}
	s = px__pow2_scale(m, &e);
	for (k = 0; k < 3; k++) {
		E[k] = px_v3_scale(E[k], s);
		W[k] = px_v3_scale(W[k], s);
	}
	/* n = ab x ac = E0 x -E2, to one rounding per component */
	n = px__cross_acc(E[0], px_v3_neg(E[2]));
	nn = px_v3_norm2(n);
	/* Face: |n| above 2^-80 (the longest edge is about 1 here, so the
	 * height is above 2^-81: below it the edges are the answer to far
	 * below rounding) and the projection inside or on all three edges.
	 * sigma_k / |n|^2 are the barycentric weights. */
	if (nn > 0x1p-160) {
		double sg[3];
		for (k = 0; k < 3; k++)
			sg[k] = px_v3_dot(px_v3_cross(E[k], W[k]), n);
		if (sg[0] >= 0.0 && sg[1] >= 0.0 && sg[2] >= 0.0) {
			double h = px_v3_dot(n, W[0]) / nn; /* scaled units / |n| */
			*q = px_v3_madd(p, n, -h / s);
			*feature = PX_FEATURE_FACE;
			*sub = -1;
			*u = sg[2] / nn;
			*v = sg[0] / nn;
			return ldexp(h * h * nn, 2 * e);
		}
	}
	/* The nearest edge; for a point farther than 2^26 times the size,
	 * by |x - a|^2 - 2 (p - a) . (x - a) (= |p - x|^2 - |p - a|^2, x
	 * the edge's point) instead: there the squared distances round to
	 * nearly one value, and the wrong edge could win, which the sign
	 * of a closed mesh at the feature then inherits. Nearer, that key
	 * carries the rounding of |p - a|^2 and the distances are better. */
	{
		px_vec3 O[3] = {px_v3(0, 0, 0), E[0], px_v3_neg(E[2])};
		double key[3];
		int far = wm * s > 0x1p26;
		bk = 0;
		for (k = 0; k < 3; k++) {
			d2[k] = seg_d2(W[k], E[k], &t[k]);
			if (far) {
				px_vec3 x = px_v3_madd(O[k], E[k], t[k]);
				key[k] = px_v3_norm2(x) - 2.0 * px_v3_dot(W[0], x);
			} else {
				key[k] = d2[k];
			}
			if (key[k] < key[bk])
				bk = k;
		}
	}
	best = d2[bk];
	{
		double w[3] = {0, 0, 0};
		w[bk] = 1.0 - t[bk];
		w[(bk + 1) % 3] = t[bk];
		*u = w[1];
		*v = w[2];
	}
	/* the point from the scaled edge, back in the model's units */
	*q = px_v3_madd(P[bk], E[bk], t[bk] / s);
	if (t[bk] <= 0.0 || t[bk] >= 1.0) {
		*feature = PX_FEATURE_VERTEX;
		*sub = t[bk] <= 0.0 ? bk : (bk + 1) % 3;
		*q = P[*sub];
	} else {
		*feature = PX_FEATURE_EDGE;
		*sub = bk;
	}
	return ldexp(best, 2 * e);
}

/* 1 when the fast path's bound holds for the triangle's shape and size
 * (see the top of this section): sin^2 of the angle at a at least
 * FAST_SIN2, edges ab and ac between 2^-100 and 2^100. The point's part
 * (|p - a| below 2^100) is the caller's. */
static inline int fast_size(double lab, double lac)
{
	return lab >= 0x1p-200 && lab <= 0x1p200 && lac >= 0x1p-200 && lac <= 0x1p200;
}

static inline int fast_shape(double lab, double lac, double nn)
{
	return fast_size(lab, lac) && nn >= FAST_SIN2 * (lab * lac);
}

void px__tri_shape(px_vec3 a, px_vec3 b, px_vec3 c, px_vec3 *ab, px_vec3 *ac,
		   px_vec3 *bc, int *needle, int *fast, int *rot)
{
	px_vec3 e0 = px_v3_sub(b, a), e1 = px_v3_sub(c, a), e2 = px_v3_sub(c, b), n;
	double m = px__mx2(px__amax3(e0), px__mx2(px__amax3(e1), px__amax3(e2))), s, la, lc, lb;
	int e;
	if (!(m > 0.0)) {
		*ab = *ac = *bc = px_v3(0, 0, 0);
		*needle = 1;
		*fast = 0;
		*rot = 0;
		return;
	}
	s = px__pow2_scale(m, &e);
	*ab = px_v3_scale(e0, s);
	*ac = px_v3_scale(e1, s);
	*bc = px_v3_scale(e2, s);
	n = px__cross_acc(*ab, *ac);
	la = px_v3_norm2(*ab);
	lc = px_v3_norm2(*ac);
	lb = px_v3_norm2(*bc);
	*needle = !(px_v3_norm2(n) > NEEDLE_SIN2 * fmax(la * lc, fmax(la * lb, lc * lb)));
	/* the size from the edges as given, the shape from the scaled ones;
	 * a triangle thin at a but not at its widest vertex (opposite the
	 * longest edge) takes the fast test from there */
	*rot = 0;
	*fast = fast_size(px_v3_norm2(e0), px_v3_norm2(e1)) &&
		px_v3_norm2(n) >= FAST_SIN2 * la * lc;
	if (!*fast && !(lb >= la && lb >= lc)) {
		int r = lc >= la ? 1 : 2;
		double l1 = r == 1 ? la : lc, u1 = r == 1 ? px_v3_norm2(e0) : px_v3_norm2(e1);
		if (fast_size(u1, px_v3_norm2(e2)) && px_v3_norm2(n) >= FAST_SIN2 * l1 * lb) {
			*fast = 1;
			*rot = r;
		}
	}
}

px_vec3 px__tri_unit_normal(px_vec3 a, px_vec3 b, px_vec3 c)
{
	px_vec3 ab = px_v3_sub(b, a), ac = px_v3_sub(c, a);
	px_vec3 n = px_v3_cross(ab, ac);
	double nn = px_v3_norm2(n);
	if (fast_shape(px_v3_norm2(ab), px_v3_norm2(ac), nn))
		return px_v3_scale(n, 1.0 / sqrt(nn));
	return px__unit_normal_acc(a, b, c);
}

double px__tri_core_rot(px_vec3 p, const px_vec3 P[3], int r, px_vec3 *q, int *feature,
			int *sub, double *u, double *v)
{
	px_vec3 a = P[r], b = P[r == 1 ? 2 : 0], c = P[r == 1 ? 0 : 1];
	px_vec3 n = px_v3_cross(px_v3_sub(b, a), px_v3_sub(c, a));
	double d2, u2, v2, w0;
	int f, s2;
	d2 = px__tri_core(p, a, b, c, n, px_v3_norm2(n), 0, q, &f, &s2, &u2, &v2);
	/* the weight of a' (none on edge b'c', exactly) */
	w0 = (f == PX_FEATURE_EDGE && s2 == 1) ? 0.0 : 1.0 - u2 - v2;
	*feature = f;
	if (f != PX_FEATURE_FACE) {
		s2 += r;
		*sub = s2 >= 3 ? s2 - 3 : s2;
	} else {
		*sub = s2;
	}
	/* r = 1: (a, b, c) = (c', a', b'); r = 2: (b', c', a') */
	*u = r == 1 ? w0 : v2;
	*v = r == 1 ? u2 : w0;
	return d2;
}

double px_tri_closest(px_vec3 p, px_vec3 a, px_vec3 b, px_vec3 c,
		      px_vec3 *q, int *feature, int *sub, double *u, double *v)
{
	px_vec3 ab = px_v3_sub(b, a), ac = px_v3_sub(c, a);
	px_vec3 n = px_v3_cross(ab, ac), qq;
	double nn = px_v3_norm2(n), lab = px_v3_norm2(ab), lac = px_v3_norm2(ac);
	int f_, s_, robust;
	double u_, v_;

	if (!feature)
		feature = &f_;
	if (!sub)
		sub = &s_;
	if (!u)
		u = &u_;
	if (!v)
		v = &v_;
	if (!q)
		q = &qq;
	robust = !fast_shape(lab, lac, nn) || !(px_v3_dist2(p, a) <= 0x1p200);
	if (robust) {
		/* A triangle thin only at a (GJK's simplices often are)
		 * takes the fast test from the vertex opposite its longest
		 * edge, where the angle is widest. */
		px_vec3 P[3] = {a, b, c};
		double lbc = px_v3_dist2(b, c);
		int r = lbc >= lab && lbc >= lac ? 0 : (lac >= lab ? 1 : 2);
		if (r != 0) {
			double l1 = r == 1 ? lab : lac, l2 = lbc;
			if (fast_shape(l1, l2, nn) && px_v3_dist2(p, P[r]) <= 0x1p200)
				return px__tri_core_rot(p, P, r, q, feature, sub, u, v);
		}
	}
	/* (the fast test's differences and products are finite by its
	 * own conditions, which NaN and infinity fail) */
	if (robust && !(px__amax3(p) <= PX_TRI_MAX_COORD && px__amax3(a) <= PX_TRI_MAX_COORD &&
			px__amax3(b) <= PX_TRI_MAX_COORD && px__amax3(c) <= PX_TRI_MAX_COORD)) {
		/* out of range or not finite: no answer rather than a wrong one */
		*q = p;
		*feature = PX_FEATURE_NONE;
		*sub = -1;
		*u = *v = 0.0;
		return NAN;
	}
	return px__tri_core(p, a, b, c, n, nn, robust, q, feature, sub, u, v);
}

