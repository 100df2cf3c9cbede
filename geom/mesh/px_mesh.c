/*
 * px_mesh.c - triangle mesh model: validation, topology, pseudo-normals,
 * AABB hierarchy, exact point-triangle distance.
 */
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mesh_internal.h"
#include "model_internal.h"
#include "px_mesh.h"

/* ---- point-triangle distance ------------------------------------------ */

/*
 * Accuracy (px_mesh.h states the bound): the answer is the distance to
 * a triangle whose vertices lie within a few units of rounding of the
 * given ones, and that distance moves by at most as much as a vertex
 * does, so it is right to a small multiple of u (d + l) (u = 2^-53, d
 * the distance, l the longest edge). Two computations reach it:
 *
 * - The fast one (tri_core: Ericson's Voronoi-region walk on the dot
 *   products at vertex a, the face point by the plain cross-product
 *   normal) errs by about u (d + l) / sin(A), A the angle at a: the
 *   normal's rounding is u |ab| |ac| per component against |n| = |ab|
 *   |ac| sin(A), and the region tests vc, vb, va (Lagrange: vc = n .
 *   (ab x ap)) carry the same factor. It is used where sin^2(A) >=
 *   FAST_SIN2, which keeps that factor at 8 at most, and where no
 *   product of four differences can overflow or sink into subnormals
 *   (edges between 2^-100 and 2^100, |p - a| below 2^100).
 * - The robust one (tri_exact) everywhere else: differences scaled by a
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

/* compares, not fmax (a library call); NaN gives NaN or a smaller
 * value, which the callers' range tests (written to fail on NaN) see */
static inline double mx2(double a, double b)
{
	return a > b ? a : b;
}

static inline double amax3(px_vec3 v)
{
	return mx2(fabs(v.x), mx2(fabs(v.y), fabs(v.z)));
}

/* 2^-e with 2^e > x >= 2^(e-1) (x > 0 finite): multiplying by it is
 * exact and brings x into [0.5, 1). */
static double pow2_scale(double x, int *e)
{
	(void)frexp(x, e);
	return ldexp(1.0, -*e);
}

/* The accurate normal (b - a) x (c - a), as a unit vector (zero when
 * the scaled cross product vanishes). Setup and the robust path. */
static px_vec3 unit_normal_acc(px_vec3 a, px_vec3 b, px_vec3 c)
{
	px_vec3 ab = px_v3_sub(b, a), ac = px_v3_sub(c, a), n;
	double m = mx2(amax3(ab), amax3(ac)), s, l;
	int e;
	if (!(m > 0.0) || !isfinite(m))
		return px_v3(0, 0, 0);
	s = pow2_scale(m, &e);
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

/* The robust path (see the top of this section). RT-safe, bounded (it
 * calls itself at most once, for a far point). */
static double tri_exact(px_vec3 p, px_vec3 a, px_vec3 b, px_vec3 c, px_vec3 *q,
			int *feature, int *sub, double *u, double *v)
{
	px_vec3 P[3] = {a, b, c}, E[3], W[3], n;
	double m, wm, s, d2[3], t[3], best, nn;
	int k, e, bk;

	for (k = 0; k < 3; k++) {
		E[k] = px_v3_sub(P[(k + 1) % 3], P[k]);
		W[k] = px_v3_sub(p, P[k]);
	}
	m = mx2(amax3(E[0]), mx2(amax3(E[1]), amax3(E[2])));
	wm = amax3(W[0]);
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
		(void)tri_exact(pn, a, b, c, q, feature, sub, u, v);
		return px_v3_dist2(p, *q);
	}
	s = pow2_scale(m, &e);
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

/*
 * Voronoi-region walk (the vertex, edge and face regions are decided by
 * the signs of dot products of p - vertex with the edges, as in Ericson,
 * Real-Time Collision Detection 5.1.5). The face point is taken by
 * projecting onto the plane along the cross-product normal rather than
 * from the barycentric ratios, which lose accuracy on thin triangles;
 * edge distances from p - a and the edge (no absolute coordinate).
 * n = (b - a) x (c - a), nn = |n|^2; robust: the fast path's bound does
 * not hold for this triangle or point (tri_exact instead).
 */
static inline __attribute__((always_inline)) double
tri_core(px_vec3 p, px_vec3 a, px_vec3 b, px_vec3 c,
			      px_vec3 n, double nn, int robust, px_vec3 *q,
			      int *feature, int *sub, double *u, double *v)
{
	px_vec3 ab = px_v3_sub(b, a), ac = px_v3_sub(c, a), ap = px_v3_sub(p, a);
	px_vec3 bp, cp;
	double d1, d2, d3, d4, d5, d6, va, vb, vc, t;

	if (robust)
		return tri_exact(p, a, b, c, q, feature, sub, u, v);

	d1 = px_v3_dot(ab, ap);
	d2 = px_v3_dot(ac, ap);
	if (d1 <= 0.0 && d2 <= 0.0) {
		*q = a;
		*feature = PX_FEATURE_VERTEX;
		*sub = 0;
		*u = *v = 0.0;
		return px_v3_norm2(ap);
	}
	bp = px_v3_sub(p, b);
	d3 = px_v3_dot(ab, bp);
	d4 = px_v3_dot(ac, bp);
	if (d3 >= 0.0 && d4 <= d3) {
		*q = b;
		*feature = PX_FEATURE_VERTEX;
		*sub = 1;
		*u = 1.0;
		*v = 0.0;
		return px_v3_norm2(bp);
	}
	vc = d1 * d4 - d3 * d2;
	if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
		t = d1 / (d1 - d3);
		*q = px_v3_madd(a, ab, t);
		*feature = PX_FEATURE_EDGE;
		*sub = 0;
		*u = t;
		*v = 0.0;
		return px_v3_norm2(px_v3_madd(ap, ab, -t));
	}
	cp = px_v3_sub(p, c);
	d5 = px_v3_dot(ab, cp);
	d6 = px_v3_dot(ac, cp);
	if (d6 >= 0.0 && d5 <= d6) {
		*q = c;
		*feature = PX_FEATURE_VERTEX;
		*sub = 2;
		*u = 0.0;
		*v = 1.0;
		return px_v3_norm2(cp);
	}
	vb = d5 * d2 - d1 * d6;
	if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
		t = d2 / (d2 - d6);
		*q = px_v3_madd(a, ac, t);
		*feature = PX_FEATURE_EDGE;
		*sub = 2;
		*u = 0.0;
		*v = t;
		return px_v3_norm2(px_v3_madd(ap, ac, -t));
	}
	va = d3 * d6 - d5 * d4;
	if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
		px_vec3 bc = px_v3_sub(c, b);
		t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
		*q = px_v3_madd(b, bc, t);
		*feature = PX_FEATURE_EDGE;
		*sub = 1;
		*u = 1.0 - t;
		*v = t;
		return px_v3_norm2(px_v3_madd(bp, bc, -t));
	}
	/* face region */
	{
		double s = px_v3_dot(n, ap) / nn;
		double den = va + vb + vc;
		*q = px_v3_madd(p, n, -s);
		*feature = PX_FEATURE_FACE;
		*sub = -1;
		*u = den != 0.0 ? vb / den : 0.0;
		*v = den != 0.0 ? vc / den : 0.0;
		return s * s * nn;
	}
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

/*
 * Mesh setup's view of a triangle: its edges ab, ac, bc scaled by a
 * power of two to a largest component in [0.5, 1) (zero when all three
 * vertices coincide); *needle when its height is below sqrt(NEEDLE_SIN2)
 * of its edges (degenerate for topology and signs: no face normal; its
 * distance is still exact, by tri_exact); *fast when the fast test's
 * bound holds for it (fast_shape) at vertex *rot (0: a, 1: b, 2: c).
 */
static void tri_shape(px_vec3 a, px_vec3 b, px_vec3 c, px_vec3 *ab, px_vec3 *ac,
		      px_vec3 *bc, int *needle, int *fast, int *rot)
{
	px_vec3 e0 = px_v3_sub(b, a), e1 = px_v3_sub(c, a), e2 = px_v3_sub(c, b), n;
	double m = mx2(amax3(e0), mx2(amax3(e1), amax3(e2))), s, la, lc, lb;
	int e;
	if (!(m > 0.0)) {
		*ab = *ac = *bc = px_v3(0, 0, 0);
		*needle = 1;
		*fast = 0;
		*rot = 0;
		return;
	}
	s = pow2_scale(m, &e);
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
	return unit_normal_acc(a, b, c);
}

/* The fast test with the vertices rotated by r (1 or 2: a' = P[r], b',
 * c' following): outputs mapped back to the caller's order. Out of
 * line: the rare path, kept out of the mesh walk's inlined common one. */
static __attribute__((noinline)) double
tri_core_rot(px_vec3 p, const px_vec3 P[3], int r, px_vec3 *q, int *feature, int *sub,
	     double *u, double *v)
{
	px_vec3 a = P[r], b = P[r == 1 ? 2 : 0], c = P[r == 1 ? 0 : 1];
	px_vec3 n = px_v3_cross(px_v3_sub(b, a), px_v3_sub(c, a));
	double d2, u2, v2, w0;
	int f, s2;
	d2 = tri_core(p, a, b, c, n, px_v3_norm2(n), 0, q, &f, &s2, &u2, &v2);
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
				return tri_core_rot(p, P, r, q, feature, sub, u, v);
		}
	}
	/* (the fast test's differences and products are finite by its
	 * own conditions, which NaN and infinity fail) */
	if (robust && !(amax3(p) <= PX_TRI_MAX_COORD && amax3(a) <= PX_TRI_MAX_COORD &&
			amax3(b) <= PX_TRI_MAX_COORD && amax3(c) <= PX_TRI_MAX_COORD)) {
		/* out of range or not finite: no answer rather than a wrong one */
		*q = p;
		*feature = PX_FEATURE_NONE;
		*sub = -1;
		*u = *v = 0.0;
		return NAN;
	}
	return tri_core(p, a, b, c, n, nn, robust, q, feature, sub, u, v);
}

/* ---- setup helpers ------------------------------------------------------ */

static void rep_msg(struct px_mesh_report *rep, const char *fmt, ...)
	__attribute__((format(printf, 2, 3)));
static void rep_msg(struct px_mesh_report *rep, const char *fmt, ...)
{
	va_list ap;
	if (!rep || rep->message[0])
		return;
	va_start(ap, fmt);
	vsnprintf(rep->message, sizeof(rep->message), fmt, ap);
	va_end(ap);
}

static int cmp_xyz(const void *x, const void *y, void *ctx)
{
	const double *P = ctx;
	const double *a = P + 3 * (size_t)*(const uint32_t *)x;
	const double *b = P + 3 * (size_t)*(const uint32_t *)y;
	int k;
	for (k = 0; k < 3; k++) {
		if (a[k] < b[k])
			return -1;
		if (a[k] > b[k])
			return 1;
	}
	return 0;
}

struct edge {
	uint32_t lo, hi; /* canonical vertex ids */
	uint32_t tri;
	uint8_t e;       /* local edge 0..2 */
	uint8_t fwd;     /* lo -> hi in the triangle's order */
};

static int cmp_edge(const void *x, const void *y)
{
	const struct edge *a = x, *b = y;
	if (a->lo != b->lo)
		return a->lo < b->lo ? -1 : 1;
	if (a->hi != b->hi)
		return a->hi < b->hi ? -1 : 1;
	return a->tri < b->tri ? -1 : (a->tri > b->tri);
}

static double ang(px_vec3 u, px_vec3 w)
{
	return atan2(px_v3_norm(px_v3_cross(u, w)), px_v3_dot(u, w));
}

struct build {
	uint32_t *perm;
	const double *cen;  /* 3 per input triangle */
	const double *tlo, *thi; /* 3 each per input triangle */
	struct node *nodes;
	size_t n_nodes;
	int leaf;
	int depth;
};

/* Compares rather than fmin/fmax (library calls, a fifth of the build
 * time): the coordinates are finite here. */
static inline double mn(double a, double b)
{
	return a < b ? a : b;
}

static inline double mx(double a, double b)
{
	return a > b ? a : b;
}

static void range_box(const struct build *B, size_t s, size_t n, float lo[3],
		      float hi[3])
{
	double l[3] = {INFINITY, INFINITY, INFINITY},
	       h[3] = {-INFINITY, -INFINITY, -INFINITY};
	size_t i;
	int k;
	for (i = s; i < s + n; i++) {
		size_t t = B->perm[i];
		for (k = 0; k < 3; k++) {
			l[k] = mn(l[k], B->tlo[3 * t + k]);
			h[k] = mx(h[k], B->thi[3 * t + k]);
		}
	}
	for (k = 0; k < 3; k++) {
		lo[k] = px__f_down(l[k]);
		hi[k] = px__f_up(h[k]);
	}
}

/* Build the node for range [s, s + n) (n > leaf); returns its index. */
static int log2ceil(size_t n)
{
	int k = 0;
	while (((size_t)1 << k) < n)
		k++;
	return k;
}

static double half_area(const double lo[3], const double hi[3])
{
	double x = hi[0] - lo[0], y = hi[1] - lo[1], z = hi[2] - lo[2];
	return x * y + y * z + z * x;
}

#define SAH_BINS 16

/*
 * Binned surface-area split (the usual 16 bins per axis over the
 * centroid bounds); returns the size of the left part after partitioning
 * [s, s + n), or 0 when no split beats the others (then the caller takes
 * the median).
 */
static size_t sah_split(struct build *B, size_t s, size_t n, const double clo[3],
			const double chi[3])
{
	double best = INFINITY;
	int bax = -1, bbin = 0, k, j;
	size_t i, left;

	for (k = 0; k < 3; k++) {
		double ext = chi[k] - clo[k], blo[SAH_BINS][3], bhi[SAH_BINS][3];
		size_t cnt[SAH_BINS] = {0};
		double llo[3], lhi[3], rlo[3], rhi[3], la[SAH_BINS];
		size_t lc[SAH_BINS], acc;
		int m;
		if (!(ext > 0.0))
			continue;
		for (j = 0; j < SAH_BINS; j++)
			for (m = 0; m < 3; m++) {
				blo[j][m] = INFINITY;
				bhi[j][m] = -INFINITY;
			}
		for (i = s; i < s + n; i++) {
			size_t t = B->perm[i];
			int b = (int)(SAH_BINS * (B->cen[3 * t + k] - clo[k]) / ext);
			b = b < 0 ? 0 : (b >= SAH_BINS ? SAH_BINS - 1 : b);
			cnt[b]++;
			for (m = 0; m < 3; m++) {
				blo[b][m] = mn(blo[b][m], B->tlo[3 * t + m]);
				bhi[b][m] = mx(bhi[b][m], B->thi[3 * t + m]);
			}
		}
		for (m = 0; m < 3; m++) {
			llo[m] = rlo[m] = INFINITY;
			lhi[m] = rhi[m] = -INFINITY;
		}
		acc = 0;
		for (j = 0; j < SAH_BINS - 1; j++) {
			acc += cnt[j];
			for (m = 0; m < 3; m++) {
				llo[m] = mn(llo[m], blo[j][m]);
				lhi[m] = mx(lhi[m], bhi[j][m]);
			}
			lc[j] = acc;
			la[j] = acc ? half_area(llo, lhi) : 0.0;
		}
		acc = 0;
		for (j = SAH_BINS - 1; j > 0; j--) {
			double cost;
			acc += cnt[j];
			for (m = 0; m < 3; m++) {
				rlo[m] = mn(rlo[m], blo[j][m]);
				rhi[m] = mx(rhi[m], bhi[j][m]);
			}
			if (lc[j - 1] == 0 || acc == 0)
				continue;
			cost = la[j - 1] * (double)lc[j - 1] + half_area(rlo, rhi) * (double)acc;
			if (cost < best) {
				best = cost;
				bax = k;
				bbin = j; /* bins < j go left */
			}
		}
	}
	if (bax < 0)
		return 0;
	/* partition: bins < bbin to the left */
	{
		double ext = chi[bax] - clo[bax];
		size_t a = s, b = s + n;
		while (a < b) {
			size_t t = B->perm[a];
			int bin = (int)(SAH_BINS * (B->cen[3 * t + bax] - clo[bax]) / ext);
			bin = bin < 0 ? 0 : (bin >= SAH_BINS ? SAH_BINS - 1 : bin);
			if (bin < bbin) {
				a++;
			} else {
				uint32_t x = B->perm[a];
				B->perm[a] = B->perm[--b];
				B->perm[b] = x;
			}
		}
		left = a - s;
	}
	return (left > 0 && left < n) ? left : 0;
}

/* Build the node for range [s, s + n) (n > leaf); returns its index.
 * Surface-area splits while the depth leaves room for the rest of the
 * range to be finished by median splits within PX_MESH_MAX_DEPTH. */
static uint32_t build_node(struct build *B, size_t s, size_t n, int depth)
{
	uint32_t me = (uint32_t)B->n_nodes++;
	double clo[3], chi[3];
	size_t half = 0, part[2][2];
	int c;

	if (depth > B->depth)
		B->depth = depth;
	px__key_bounds(B->perm + s, n, B->cen, clo, chi);
	if (depth + 2 + log2ceil(n) <= PX_MESH_MAX_DEPTH - 2)
		half = sah_split(B, s, n, clo, chi);
	if (half == 0)
		half = px__median_split(B->perm + s, n, B->cen, clo, chi);
	part[0][0] = s;
	part[0][1] = half;
	part[1][0] = s + half;
	part[1][1] = n - half;
	for (c = 0; c < 2; c++) {
		struct node *nd = &B->nodes[me];
		range_box(B, part[c][0], part[c][1], nd->lo[c], nd->hi[c]);
		if (part[c][1] <= (size_t)B->leaf) {
			nd->idx[c] = (uint32_t)part[c][0];
			nd->cnt[c] = (uint32_t)part[c][1];
		} else {
			uint32_t ch = build_node(B, part[c][0], part[c][1],
						 depth + 1);
			B->nodes[me].idx[c] = ch;
			B->nodes[me].cnt[c] = 0;
		}
	}
	return me;
}

uint32_t px__node4_collapse(const struct node *bn, struct node4 *n4,
			    size_t *n_n4, uint32_t b)
{
	uint32_t me = (uint32_t)(*n_n4)++;
	struct node4 *o = &n4[me];
	int s = 0, c, g, j, k;
	const struct node *nb = &bn[b];

	for (j = 0; j < 4; j++) {
		for (k = 0; k < 3; k++) {
			o->lo[k][j] = INFINITY;
			o->hi[k][j] = -INFINITY;
		}
		o->idx[j] = EMPTY;
		o->cnt[j] = 0;
	}
	for (c = 0; c < 2; c++) {
		if (nb->idx[c] == EMPTY)
			continue;
		if (nb->cnt[c] > 0) {
			for (k = 0; k < 3; k++) {
				o->lo[k][s] = nb->lo[c][k];
				o->hi[k][s] = nb->hi[c][k];
			}
			o->idx[s] = nb->idx[c];
			o->cnt[s] = nb->cnt[c];
			s++;
			continue;
		}
		for (g = 0; g < 2; g++) {
			const struct node *gn = &bn[nb->idx[c]];
			if (gn->idx[g] == EMPTY)
				continue;
			for (k = 0; k < 3; k++) {
				o->lo[k][s] = gn->lo[g][k];
				o->hi[k][s] = gn->hi[g][k];
			}
			o->idx[s] = gn->idx[g]; /* binary index until collapsed below */
			o->cnt[s] = gn->cnt[g];
			s++;
		}
	}
	for (j = 0; j < s; j++)
		if (n4[me].cnt[j] == 0) {
			uint32_t ch = px__node4_collapse(bn, n4, n_n4, n4[me].idx[j]);
			n4[me].idx[j] = ch;
		}
	return me;
}

static void mesh_free(void *impl)
{
	struct mesh *M = impl;
	if (!M)
		return;
	free(M->vx);
	free(M->tv);
	free(M->lb);
	free(M->orig);
	free(M->leaf_of);
	free(M->fn);
	free(M->en);
	free(M->vnt);
	free(M->degen);
	free(M->nodes);
	free(M->n4);
	free(M->hull);
	free(M->adj_start);
	free(M->adj);
	free(M->grid);
	free(M);
}

/* ---- query --------------------------------------------------------------- */

struct best {
	double d2;
	long li;
	px_vec3 q;
	int feature, sub;
	double u, v;
};

/* Query point in single precision with the slack that covers the
 * rounding of the float bounds (px__box4_d2f, tri_lb); use = 0 when p or the
 * mesh is too far out for floats (then only exact tests are made). */
struct pq {
	float pf[3];
	float slack_box, slack_tri;
	int use;
	int fast; /* p and the mesh in the fast triangle test's range */
};

static inline void pq_init(const struct mesh *M, px_vec3 p, struct pq *q)
{
	double pmax = fmax(fabs(p.x), fmax(fabs(p.y), fabs(p.z)));
	/* Differences stay below 4e18 and their squares (and sums of three)
	 * far below FLT_MAX; beyond that a float square overflows to inf,
	 * which would prune the closest box or triangle. */
	q->fast = pmax < 1e18 && M->absmax < 1e18;
	/* and above 2^-40: a float square below 2^-126 rounds by up to
	 * 2^-150 absolute, which only the slack's margin over the real
	 * rounding (at least 2^-24 (|p| + |mesh|), squared) absorbs; at
	 * 1e-20 scale a bound overstated that way pruned the closest
	 * needle of test_accuracy's meshes */
	q->use = q->fast && M->absmax + pmax >= 0x1p-40;
	q->pf[0] = (float)p.x;
	q->pf[1] = (float)p.y;
	q->pf[2] = (float)p.z;
	q->slack_box = (float)(0x1p-22 * (M->absmax + pmax));
	/* plane and edge values: unit vectors and offsets rounded to float
	 * (2^-24 relative each), three products and sums, the rounded p:
	 * together below 16 * 2^-24 (|p| + |mesh|); twice that here */
	q->slack_tri = (float)(0x1p-19 * (M->absmax + pmax));
}

/* Lower bound of the squared distance to leaf triangle li (see struct
 * tlb); only when q->use. */
static inline double tri_lb(const struct tlb *L, const struct pq *q)
{
	const float *P = q->pf;
	float h, e;
#ifdef __SSE__
	/* the four values in one pass, in the scalar order of operations
	 * (((x P0 + y P1) + z P2) - w), so the rounding argument holds */
	__m128 v = _mm_sub_ps(
		_mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_load_ps(L->c[0]), _mm_set1_ps(P[0])),
				      _mm_mul_ps(_mm_load_ps(L->c[1]), _mm_set1_ps(P[1]))),
			   _mm_mul_ps(_mm_load_ps(L->c[2]), _mm_set1_ps(P[2]))),
		_mm_load_ps(L->c[3]));
	__m128 s1 = _mm_shuffle_ps(v, v, _MM_SHUFFLE(3, 3, 2, 1)); /* e0 e1 e2 e2 */
	__m128 mx = _mm_max_ps(s1, _mm_movehl_ps(s1, s1));        /* max(e0,e2) max(e1,e2) */
	mx = _mm_max_ss(mx, _mm_shuffle_ps(mx, mx, _MM_SHUFFLE(1, 1, 1, 1)));
	h = _mm_cvtss_f32(v);
	e = _mm_cvtss_f32(mx) - q->slack_tri;
#else
	float v[4];
	int j;
	for (j = 0; j < 4; j++)
		v[j] = L->c[0][j] * P[0] + L->c[1][j] * P[1] + L->c[2][j] * P[2] - L->c[3][j];
	h = v[0];
	e = v[1] > v[2] ? v[1] : v[2];
	e = (e > v[3] ? e : v[3]) - q->slack_tri;
#endif
	h = (h < 0.0f ? -h : h) - q->slack_tri;
	e = e > 0.0f ? e : 0.0f;
	h = h > 0.0f ? h : 0.0f;
	return (double)(h * h + e * e) * (1.0 - 0x1p-18);
}

/*
 * A degenerate triangle (needle: no face normal, so no face feature for
 * the sign) whose exact closest point lies inside it: the edge nearest
 * that point names the feature (its pseudo-normal gives the sign). The
 * distance from the point with barycentric weights w to the line of the
 * edge opposite vertex k is w[k] times that vertex's height, 2 area /
 * |edge|: so the least w[k] / |edge k'| wins. RT-safe.
 */
static int face_as_edge(px_vec3 a, px_vec3 b, px_vec3 c, double u, double v,
			int *sub)
{
	/* edge e (0: ab, 1: bc, 2: ca) is opposite vertex (e + 2) % 3 */
	double w[3] = {1.0 - u - v, u, v};
	double l[3] = {px_v3_dist(a, b), px_v3_dist(b, c), px_v3_dist(c, a)};
	int e, be = 0;
	for (e = 1; e < 3; e++)
		if (w[(e + 2) % 3] * l[be] < w[(be + 2) % 3] * l[e])
			be = e;
	*sub = be;
	return PX_FEATURE_EDGE;
}

/* A tie of squared distances (a far point: they round to one value)
 * decided by |q - r|^2 - 2 (p - r) . (q - r) < 0, r the best point so
 * far (= |p - q|^2 - |p - r|^2, without the rounding of the squares):
 * the truly nearer feature then holds the answer and gives the sign. */
static int nearer_than_best(px_vec3 p, px_vec3 q, const struct best *b)
{
	px_vec3 x = px_v3_sub(q, b->q);
	return px_v3_norm2(x) - 2.0 * px_v3_dot(px_v3_sub(p, b->q), x) < 0.0;
}

/* plane_done: the caller's float bound (tri_lb) already compared the
 * plane distance, so the double one here would repeat it. */
static inline void test_tri_x(const struct mesh *M, size_t li, px_vec3 p,
			      struct best *b, int plane_done, int fast)
{
	const uint32_t *vi = M->tv + 3 * li;
	px_vec3 ta = M->vx[vi[0]], tb = M->vx[vi[1]], tc = M->vx[vi[2]], n, q;
	int f, s, robust, rot;
	double u, v, d2, nn;

	n = px_v3_cross(px_v3_sub(tb, ta), px_v3_sub(tc, ta));
	/* |n|^2 as px_tri_closest computes it (a product, not a division);
	 * 1 / |n|^2 (px__mtri_get) is 0 exactly for these */
	nn = px_v3_norm2(n);
	/* degenerate, or a shape or size outside the fast test's bound
	 * (set at setup, DEGEN_*), or a point too far out for it; a
	 * triangle thin only at a takes the fast test from another vertex */
	robust = (M->degen[li] & (DEGEN_ZERO | DEGEN_SLOW)) || !fast;
	rot = M->degen[li] >> DEGEN_ROT_SHIFT;
	if (!plane_done && !robust && !rot) {
		/* the distance to the plane is a lower bound (compared
		 * without a division; the factor keeps rounding from ever
		 * rejecting a triangle whose plane distance equals the bound) */
		double h = px_v3_dot(n, px_v3_sub(p, ta));
		if (h * h > b->d2 * nn * (1.0 + 1e-12))
			return;
	}
	if (rot && !robust) {
		px_vec3 P[3] = {ta, tb, tc};
		d2 = tri_core_rot(p, P, rot, &q, &f, &s, &u, &v);
	} else {
		d2 = tri_core(p, ta, tb, tc, n, nn, robust, &q, &f, &s, &u, &v);
	}
	if ((M->degen[li] & DEGEN_ZERO) && f == PX_FEATURE_FACE)
		f = face_as_edge(ta, tb, tc, u, v, &s);
	if (d2 < b->d2 ||
	    (d2 == b->d2 && (b->li < 0 || ((M->degen[b->li] & DEGEN_ZERO) &&
					   !(M->degen[li] & DEGEN_ZERO)) ||
			     nearer_than_best(p, q, b)))) {
		b->d2 = d2;
		b->li = (long)li;
		b->q = q;
		b->feature = f;
		b->sub = s;
		/* what mesh_finish reads if this stays the answer: fetched
		 * while the walk goes on, not after it */
		__builtin_prefetch(&M->orig[li]);
		__builtin_prefetch(f == PX_FEATURE_FACE   ? &M->fn[li]
				   : f == PX_FEATURE_EDGE ? &M->en[3 * li + (size_t)s]
							  : &M->vnt[3 * li + (size_t)s]);
		b->u = u;
		b->v = v;
	}
}

/* 1 when p and the mesh are in the fast triangle test's range (struct
 * pq's fast, for callers without one). */
static inline int fast_range(const struct mesh *M, px_vec3 p)
{
	return M->absmax < 1e18 && amax3(p) < 1e18;
}

static inline void test_tri(const struct mesh *M, size_t li, px_vec3 p,
			    struct best *b)
{
	test_tri_x(M, li, p, b, 0, fast_range(M, p));
}

/* Fill a result from the best triangle: the sign from the pseudo-normal
 * of the feature holding the closest point. */
static void mesh_finish(const struct mesh *M, px_vec3 p, const struct best *bp,
			unsigned flags, int iters, int certified,
			struct px_model_result *r)
{
	struct best b = *bp;
	px_vec3 n, dv;
	double d;

	r->point = b.q;
	r->index = (int)M->orig[b.li];
	r->sub = b.sub;
	r->feature = b.feature;
	r->u = b.u;
	r->v = b.v;
	r->iterations = iters;
	r->certified = certified;
	r->gap = 0.0;
	if (b.feature == PX_FEATURE_FACE)
		n = M->fn[b.li];
	else if (b.feature == PX_FEATURE_EDGE)
		n = M->en[3 * b.li + b.sub];
	else
		n = M->vnt[3 * b.li + b.sub];
	d = sqrt(b.d2);
	dv = px_v3_sub(p, b.q);
	r->is_signed = M->closed && !(flags & PX_QUERY_UNSIGNED);
	r->inside = 0;
	if (d > 0.0) {
		r->direction = px_v3_scale(dv, 1.0 / d);
		r->distance = d;
		if (r->is_signed && px_v3_dot(dv, n) < 0.0) {
			r->inside = 1;
			r->distance = -d;
			r->direction = px_v3_neg(r->direction);
		}
	} else {
		px_vec3 f = M->fn[b.li];
		r->distance = 0.0;
		if (px_v3_normalize(n, f, &r->direction) != PX_OK)
			px_v3_normalize(f, px_v3(0, 0, 1), &r->direction);
	}
}


/* The hierarchy walk: improves *b (which may already hold a bound from
 * a hint) to the exact closest triangle within its bound. RT-safe. */
static void mesh_walk(const struct mesh *M, px_vec3 p, struct best *b,
		      int *iters_io, int *certified_io)
{
	struct {
		uint32_t idx, cnt;
		double d2;
	} st[STACK4];
	int sp = 0, iters = *iters_io, certified = 1;
	struct pq pq;

	pq_init(M, p, &pq);
	st[sp].idx = 0;
	st[sp].cnt = 0;
	st[sp].d2 = 0.0;
	sp++;
	while (sp > 0) {
		const struct node4 *nd;
		double dc[4];
		int ord[4], no = 0, j, c;

		sp--;
		if (st[sp].d2 > b->d2 || (st[sp].d2 == b->d2 && b->li >= 0))
			continue;
		iters++;
		if (st[sp].cnt > 0) {
			uint32_t i0 = st[sp].idx, n = st[sp].cnt, k;
			double lb[16];
			if (!pq.use) {
				for (k = 0; k < n; k++)
					test_tri(M, i0 + k, p, b);
				continue;
			}
			/* all bounds of the leaf first, then the vertex fetches
			 * of the triangles they keep at once, then the exact
			 * tests: the fetches overlap instead of queueing */
			for (k = 0; k < n; k++) {
				lb[k] = tri_lb(&M->lb[i0 + k], &pq);
				if (!(lb[k] > b->d2)) {
					const uint32_t *v = M->tv + 3 * (i0 + k);
					__builtin_prefetch(M->vx + v[0]);
					__builtin_prefetch(M->vx + v[1]);
					__builtin_prefetch(M->vx + v[2]);
				}
			}
			for (k = 0; k < n; k++)
				if (!(lb[k] > b->d2))
					test_tri_x(M, i0 + k, p, b, 1, pq.fast);
			continue;
		}
		nd = &M->n4[st[sp].idx];
		if (pq.use)
			px__box4_d2f(nd, pq.pf, pq.slack_box, dc);
		else
			px__box4_d2(nd, p, dc);
		/* children that can still win, nearest first */
		for (j = 0; j < 4; j++) {
			if (nd->idx[j] == EMPTY || dc[j] > b->d2)
				continue;
			for (c = no; c > 0 && dc[ord[c - 1]] > dc[j]; c--)
				ord[c] = ord[c - 1];
			ord[c] = j;
			no++;
		}
		/* push the farthest first so the nearest is expanded first */
		for (c = no - 1; c >= 0; c--) {
			j = ord[c];
			if (sp >= STACK4) {
				certified = 0; /* cannot happen: depth checked at setup */
				continue;
			}
			st[sp].idx = nd->idx[j];
			st[sp].cnt = nd->cnt[j];
			st[sp].d2 = dc[j];
			/* start the memory fetch now: the node or the leaf's
			 * triangles are needed within a few steps */
			if (st[sp].cnt) {
				/* one line per triangle */
				const struct tlb *L = &M->lb[st[sp].idx];
				uint32_t k;
				for (k = 0; k < st[sp].cnt; k++)
					__builtin_prefetch(L + k);
				__builtin_prefetch(M->tv + 3 * st[sp].idx);
			} else {
				/* a node spans two lines */
				const char *q = (const char *)&M->n4[st[sp].idx];
				__builtin_prefetch(q);
				__builtin_prefetch(q + 64);
			}
			sp++;
		}
	}
	*iters_io = iters;
	if (!certified)
		*certified_io = 0;
}

static void best_init(struct best *b, px_vec3 p, double max_dist)
{
	b->d2 = isinf(max_dist) ? INFINITY : max_dist * max_dist;
	b->li = -1;
	b->q = p;
	b->feature = PX_FEATURE_NONE;
	b->sub = 0;
	b->u = b->v = 0.0;
}

static int mesh_closest(const void *impl, const struct px_model_query *qq,
			struct px_model_result *r)
{
	const struct mesh *M = impl;
	int iters = 0, certified = 1;
	struct best b;
	px_vec3 p = qq->p;

	best_init(&b, p, qq->max_dist);
	/* a starting bound: last cycle's triangle, else the grid's */
	if (qq->hint >= 0 && (size_t)qq->hint < M->nt) {
		test_tri(M, M->leaf_of[qq->hint], p, &b);
		iters++;
	} else if (M->grid) {
		test_tri(M, px__mesh_grid_hint(M, p), p, &b);
		iters++;
	}
	mesh_walk(M, p, &b, &iters, &certified);
	if (b.li < 0)
		return 0;
	mesh_finish(M, p, &b, qq->flags, iters, certified, r);
	return 1;
}

/* Exact closest point among the given leaf-order triangles (coherence
 * caches: px_model_query_cached() decides when that set is enough). */
static int mesh_closest_among(const void *impl, const struct px_model_query *qq,
			      const int *idx, int n, struct px_model_result *r)
{
	const struct mesh *M = impl;
	struct best b;
	struct pq pq;
	int i;

	best_init(&b, qq->p, qq->max_dist);
	pq_init(M, qq->p, &pq);
	for (i = 0; i < n; i++) {
		size_t li = (size_t)idx[i];
		if (idx[i] < 0 || li >= M->nt)
			continue;
		/* the float bound first, as the walk does: most of the set
		 * is farther than the best so far */
		if (!pq.use)
			test_tri(M, li, qq->p, &b);
		else if (!(tri_lb(&M->lb[li], &pq) > b.d2))
			test_tri_x(M, li, qq->p, &b, 1, pq.fast);
	}
	if (b.li < 0)
		return 0;
	mesh_finish(M, qq->p, &b, qq->flags, n, 1, r);
	return 1;
}

/* mesh_collect()'s leaf: the triangles of [i0, i0 + n) within the
 * radius. */
struct mesh_within {
	const struct mesh *M;
	px_vec3 p;
	double r2;
	struct pq pq;
	int *idx, cap, n;
};

static int mesh_within_leaf(void *ctx, uint32_t i0, uint32_t n)
{
	struct mesh_within *w = ctx;
	const struct mesh *M = w->M;
	uint32_t i;
	for (i = i0; i < i0 + n; i++) {
		const uint32_t *v = M->tv + 3 * i;
		if (w->pq.use && tri_lb(&M->lb[i], &w->pq) > w->r2)
			continue;
		if (px_tri_closest(w->p, M->vx[v[0]], M->vx[v[1]], M->vx[v[2]], NULL,
				   NULL, NULL, NULL, NULL) <= w->r2) {
			if (w->n == w->cap)
				return PX_E_NOSPC;
			w->idx[w->n++] = (int)i;
		}
	}
	return 0;
}

/* Leaf-order indices of every triangle within radius of p: the count,
 * or PX_E_NOSPC when there are more than cap. */
static int mesh_collect(const void *impl, px_vec3 p, double radius, int *idx,
			int cap)
{
	const struct mesh *M = impl;
	struct px__walk4 st[STACK4];
	struct mesh_within w;
	int rc;

	w.M = M;
	w.p = p;
	w.r2 = radius * radius;
	w.idx = idx;
	w.cap = cap;
	w.n = 0;
	pq_init(M, p, &w.pq);
	rc = px__box4_within(M->n4, p, w.r2, st, STACK4, mesh_within_leaf, &w);
	return rc < 0 ? rc : w.n;
}

static px_aabb mesh_aabb(const void *impl)
{
	return ((const struct mesh *)impl)->box;
}

static size_t mesh_bytes(const void *impl)
{
	return ((const struct mesh *)impl)->bytes;
}

/* Convex meshes: the vertex farthest along d (a linear scan: convex
 * meshes in this role are small, e.g. a tool or a hull). */
/*
 * Convex meshes: the vertex farthest along d. Small meshes are scanned;
 * larger ones are climbed along the vertex graph from the best of the
 * six axis-extreme vertices, always to a strictly better neighbour. On a
 * convex solid a vertex with no better neighbour is a global maximum:
 * along a polytope edge or across a facet the objective rises wherever
 * the vertex is not optimal, and the mesh edges follow those edges and
 * fan across those facets. The one trap, a vertex inside a facet whose
 * normal is -d, cannot be reached by strict climbing (that facet is the
 * minimum) and is not a start unless all six extremes lie on one facet,
 * which the volume required of convex meshes excludes. Each step
 * strictly increases the objective, so at most n_hull steps.
 */
static px_vec3 mesh_support(const void *impl, px_vec3 d)
{
	const struct mesh *M = impl;
	size_t i, bi = 0, steps;
	double best = -INFINITY;
	if (!M->adj_start) {
		for (i = 0; i < M->n_hull; i++) {
			double s = px_v3_dot(M->hull[i], d);
			if (s > best) {
				best = s;
				bi = i;
			}
		}
		return M->hull[bi];
	}
	for (i = 0; i < 6; i++) {
		double s = px_v3_dot(M->hull[M->ext[i]], d);
		if (s > best) {
			best = s;
			bi = M->ext[i];
		}
	}
	for (steps = 0; steps < M->n_hull; steps++) {
		size_t nb = bi;
		uint32_t k;
		for (k = M->adj_start[bi]; k < M->adj_start[bi + 1]; k++) {
			double s = px_v3_dot(M->hull[M->adj[k]], d);
			if (s > best) {
				best = s;
				nb = M->adj[k];
			}
		}
		if (nb == bi)
			break;
		bi = nb;
	}
	return M->hull[bi];
}

static const struct px_model_ops mesh_ops = {
	.name = "mesh", .kind = PX_MODEL_MESH, .closest = mesh_closest,
	.aabb = mesh_aabb, .memory_bytes = mesh_bytes, .free = mesh_free,
	.closest_among = mesh_closest_among, .collect = mesh_collect};
static const struct px_model_ops mesh_ops_convex = {
	.name = "mesh", .kind = PX_MODEL_MESH, .closest = mesh_closest,
	.aabb = mesh_aabb, .memory_bytes = mesh_bytes, .free = mesh_free,
	.support = mesh_support, .closest_among = mesh_closest_among,
	.collect = mesh_collect};

/* ---- build ----------------------------------------------------------------- */

/*
 * The hint grid (struct mesh): cubic cells over the box grown by an
 * eighth of its largest extent, as many as the budget allows (at most
 * one per 8 triangles). Cells are filled in a serpentine order so that each
 * exact query starts from its neighbour's answer, which keeps the build
 * near the cost of coherent queries. Setup only.
 */
void px__grid_layout(px_aabb box, long cap, int d[3], px_vec3 *org, double *h_out)
{
	double ext[3] = {box.max.x - box.min.x, box.max.y - box.min.y,
			 box.max.z - box.min.z};
	double len = fmax(ext[0], fmax(ext[1], ext[2])), margin, h, vol;
	int k, it;

	if (cap < 1)
		cap = 1;
	/* a model collapsed to one point still gets a (one-cell) grid */
	margin = len > 0.0 ? 0.125 * len : 1.0;
	vol = (ext[0] + 2 * margin) * (ext[1] + 2 * margin) * (ext[2] + 2 * margin);
	h = cbrt(vol / (double)cap);
	/* a model wider than about 1e102 overflows the volume, one
	 * smaller than about 1e-103 underflows it to 0; neither its cube
	 * root */
	if (!isfinite(h) || !(h > 0.0))
		h = cbrt(ext[0] + 2 * margin) * cbrt(ext[1] + 2 * margin) *
		    cbrt(ext[2] + 2 * margin) / cbrt((double)cap);
	for (it = 0;; it++) {
		double cells = 1.0;
		for (k = 0; k < 3; k++) {
			double n = ceil((ext[k] + 2 * margin) / h);
			/* clamped before the cast (undefined past INT_MAX) to
			 * cap + 1, which still fails the test below */
			double nmax = cap < INT_MAX ? (double)cap + 1.0 : (double)INT_MAX;
			d[k] = !(n >= 1.0) ? 1 : (n > nmax ? (int)nmax : (int)n);
			cells *= d[k];
		}
		if (cells <= (double)cap || it > 200)
			break;
		h *= 1.02;
	}
	if ((double)d[0] * d[1] * d[2] > (double)cap) {
		d[0] = d[1] = d[2] = 1;
		h = len + 2 * margin;
	}
	*h_out = h;
	*org = px_v3(0.5 * (box.min.x + box.max.x - d[0] * h),
		     0.5 * (box.min.y + box.max.y - d[1] * h),
		     0.5 * (box.min.z + box.max.z - d[2] * h));
}

static int grid_build(struct mesh *M, long budget)
{
	long cap = budget;
	int d[3], k, iz, jx, jy;
	size_t ncell;
	long prev = -1;
	double h;

	if (budget <= 0)
		return PX_OK;
	/* measured on a 70k-triangle torus: one cell per 8 triangles gives
	 * most of the gain of 30 times more cells at a fifth of the setup */
	if ((double)cap > (double)(M->nt / 8))
		cap = (long)(M->nt / 8);
	px__grid_layout(M->box, cap, d, &M->gorg, &h);
	ncell = (size_t)d[0] * (size_t)d[1] * (size_t)d[2];
	M->grid = malloc(ncell * sizeof(*M->grid));
	if (!M->grid)
		return PX_E_NOMEM;
	for (k = 0; k < 3; k++)
		M->gdim[k] = d[k];
	M->gcell = h;
	M->ginv = 1.0 / h;
	for (iz = 0; iz < d[2]; iz++)
		for (jy = 0; jy < d[1]; jy++) {
			int y = (iz & 1) ? d[1] - 1 - jy : jy;
			int back = ((iz * d[1] + jy) & 1) != 0;
			for (jx = 0; jx < d[0]; jx++) {
				int x = back ? d[0] - 1 - jx : jx;
				px_vec3 c = px_v3(M->gorg.x + (x + 0.5) * h, M->gorg.y + (y + 0.5) * h,
						  M->gorg.z + (iz + 0.5) * h);
				struct best b;
				int iters = 0, cert = 1;
				best_init(&b, c, INFINITY);
				if (prev >= 0)
					test_tri(M, (size_t)prev, c, &b);
				mesh_walk(M, c, &b, &iters, &cert);
				if (b.li < 0)
					b.li = prev >= 0 ? prev : 0;
				prev = b.li;
				M->grid[((size_t)iz * (size_t)d[1] + (size_t)y) * (size_t)d[0] +
					(size_t)x] = (uint32_t)b.li;
			}
		}
	M->bytes += ncell * sizeof(*M->grid);
	return PX_OK;
}

int px_mesh_model(const double *xyz, size_t nv, const uint32_t *tri,
		  size_t nt, const struct px_mesh_opts *opt,
		  struct px_mesh_report *rep, struct px_model **out)
{
	struct px_mesh_report lrep;
	struct mesh *M = NULL;
	uint32_t *order = NULL, *canon = NULL, *perm = NULL, *vmap = NULL;
	struct edge *E = NULL;
	size_t ne = 0, i, j;
	int32_t *nb = NULL;
	px_vec3 *fn = NULL, *vn = NULL;
	double *cen = NULL, *tlo = NULL, *thi = NULL;
	uint8_t *deg = NULL, *used = NULL;
	unsigned flags = opt ? opt->flags : 0u;
	int leaf = (opt && opt->leaf_size) ? opt->leaf_size : 6;
	int rc = PX_E_NOMEM, k, vexp = 0;
	double vsc = 1.0, vol_s = 0.0; /* the volume in units of 2^(3 vexp) */
	struct build B;

	if (!rep)
		rep = &lrep;
	memset(rep, 0, sizeof(*rep));
	rep->first_degenerate = -1;
	rep->first_bad_edge_triangle = -1;
	rep->n_vertices = nv;
	rep->n_triangles = nt;
	if (out)
		*out = NULL;
	if (!out || !xyz || !tri || nt == 0 || nv == 0 || leaf < 1 || leaf > 16 ||
	    (opt && opt->grid_cells > PX_MESH_MAX_GRID_CELLS)) {
		rep_msg(rep, "%s", nt == 0 || nv == 0 ? "mesh has no triangles"
						    : "invalid arguments");
		return PX_E_INVAL;
	}
	if (nt > PX_MESH_MAX_TRIANGLES || nv > 0xfffffffeu) {
		rep_msg(rep, "mesh too large (%zu triangles, %zu vertices)", nt, nv);
		return PX_E_RANGE;
	}
	/* indices, then finiteness of the vertices actually used */
	used = calloc(nv, 1);
	if (!used)
		goto fail;
	for (i = 0; i < nt; i++)
		for (k = 0; k < 3; k++) {
			uint32_t vi = tri[3 * i + k];
			if (vi >= nv) {
				rep_msg(rep, "triangle %zu: vertex index %u out of range (%zu vertices)",
					i, vi, nv);
				rc = PX_E_RANGE;
				goto fail;
			}
			used[vi] = 1;
		}
	for (i = 0; i < nv; i++)
		if (used[i] && !(isfinite(xyz[3 * i]) && isfinite(xyz[3 * i + 1]) &&
				 isfinite(xyz[3 * i + 2]))) {
			rep_msg(rep, "vertex %zu: non-finite coordinate (%g %g %g)", i,
				xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
			rc = PX_E_NAN;
			goto fail;
		}
	/* The accepted range (px_mesh.h): squared distances and the
	 * hierarchy's and hint grid's arithmetic stay finite and normal. */
	{
		double lo[3] = {INFINITY, INFINITY, INFINITY},
		       hi[3] = {-INFINITY, -INFINITY, -INFINITY}, ext = 0.0, amax = 0.0;
		for (i = 0; i < nv; i++) {
			if (!used[i])
				continue;
			for (k = 0; k < 3; k++) {
				double x = xyz[3 * i + (size_t)k];
				if (!(fabs(x) <= PX_MESH_MAX_COORD)) {
					rep_msg(rep, "mesh: vertex %zu coordinate %.17g outside the "
						     "accepted range (|x| <= %g)",
						i, x, PX_MESH_MAX_COORD);
					rc = PX_E_RANGE;
					goto fail;
				}
				lo[k] = fmin(lo[k], x);
				hi[k] = fmax(hi[k], x);
			}
		}
		for (k = 0; k < 3; k++) {
			ext = fmax(ext, hi[k] - lo[k]);
			amax = fmax(amax, fmax(fabs(lo[k]), fabs(hi[k])));
		}
		if (amax > 0.0)
			vsc = pow2_scale(amax, &vexp);
		if (ext > 0.0 && ext < PX_MESH_MIN_EXTENT) {
			rep_msg(rep, "mesh: extent %.17g below the accepted range (>= %g, or "
				     "0): its squared distances would underflow",
				ext, PX_MESH_MIN_EXTENT);
			rc = PX_E_RANGE;
			goto fail;
		}
	}

	/* weld identical positions */
	order = malloc(nv * sizeof(*order));
	canon = malloc(nv * sizeof(*canon));
	if (!order || !canon)
		goto fail;
	for (i = 0; i < nv; i++)
		order[i] = (uint32_t)i;
	qsort_r(order, nv, sizeof(*order), cmp_xyz, (void *)xyz);
	for (i = 0; i < nv; i++) {
		if (i > 0 && cmp_xyz(&order[i - 1], &order[i], (void *)xyz) == 0)
			canon[order[i]] = canon[order[i - 1]];
		else {
			canon[order[i]] = order[i];
			if (used[order[i]])
				rep->n_welded++;
		}
	}

	/* per triangle: degeneracy, normal, boxes, centroid */
	deg = calloc(nt, 1);
	fn = calloc(nt, sizeof(*fn));
	cen = malloc(nt * 3 * sizeof(double));
	tlo = malloc(nt * 3 * sizeof(double));
	thi = malloc(nt * 3 * sizeof(double));
	E = malloc(nt * 3 * sizeof(*E));
	nb = malloc(nt * 3 * sizeof(*nb));
	vn = calloc(nv, sizeof(*vn));
	if (!deg || !fn || !cen || !tlo || !thi || !E || !nb || !vn)
		goto fail;
	for (i = 0; i < nt; i++) {
		uint32_t c0 = canon[tri[3 * i]], c1 = canon[tri[3 * i + 1]],
			 c2 = canon[tri[3 * i + 2]];
		const double *A = xyz + 3 * (size_t)c0, *Bv = xyz + 3 * (size_t)c1,
			     *C = xyz + 3 * (size_t)c2;
		px_vec3 a = px_v3(A[0], A[1], A[2]), b = px_v3(Bv[0], Bv[1], Bv[2]),
			c = px_v3(C[0], C[1], C[2]);
		/* edges scaled by a power of two (exact) to a largest
		 * component near 1: the shape tests, angles and normal are
		 * scale-free, and nothing overflows at 1e150 or underflows at
		 * 1e-140 */
		px_vec3 ab, ac, bc;
		int collapsed = c0 == c1 || c1 == c2 || c0 == c2, needle, fast, rot;

		tri_shape(a, b, c, &ab, &ac, &bc, &needle, &fast, &rot);
		nb[3 * i] = nb[3 * i + 1] = nb[3 * i + 2] = -1;
		if (collapsed || needle) {
			deg[i] = DEGEN_ZERO;
			if (rep->n_degenerate++ == 0)
				rep->first_degenerate = (long)i;
		} else {
			/* the accurate normal: the plain cross product of a
			 * thin triangle's edges is off by u / sin(angle) */
			fn[i] = unit_normal_acc(a, b, c);
			deg[i] = !fast ? DEGEN_SLOW : (uint8_t)(rot << DEGEN_ROT_SHIFT);
			/* in units of 2^vexp: a 1e150 mesh's volume overflows */
			vol_s += px_v3_dot(px_v3_scale(a, vsc),
					   px_v3_cross(px_v3_scale(b, vsc), px_v3_scale(c, vsc))) /
				 6.0;
			/* angle-weighted vertex pseudo-normals */
			vn[c0] = px_v3_madd(vn[c0], fn[i], ang(ab, ac));
			vn[c1] = px_v3_madd(vn[c1], fn[i], ang(px_v3_neg(ab), bc));
			vn[c2] = px_v3_madd(vn[c2], fn[i], ang(px_v3_neg(ac), px_v3_neg(bc)));
		}
		for (k = 0; k < 3; k++) {
			double lo = fmin(fmin(A[k], Bv[k]), C[k]);
			double hi = fmax(fmax(A[k], Bv[k]), C[k]);
			tlo[3 * i + k] = lo;
			thi[3 * i + k] = hi;
			cen[3 * i + k] = 0.5 * (lo + hi);
		}
		if (!collapsed) {
			uint32_t cv[3] = {c0, c1, c2};
			for (k = 0; k < 3; k++) {
				uint32_t s = cv[k], e = cv[(k + 1) % 3];
				struct edge *ed = &E[ne++];
				ed->lo = s < e ? s : e;
				ed->hi = s < e ? e : s;
				ed->fwd = s < e;
				ed->tri = (uint32_t)i;
				ed->e = (uint8_t)k;
			}
		}
	}
	if (rep->n_degenerate)
		rep_msg(rep, "triangle %ld is degenerate (zero area)%s",
			rep->first_degenerate,
			rep->n_degenerate > 1 ? ", and others" : "");
	if ((flags & PX_MESH_REJECT_DEGENERATE) && rep->n_degenerate) {
		rc = PX_E_DEGENERATE;
		goto fail;
	}

	/* edge topology */
	qsort(E, ne, sizeof(*E), cmp_edge);
	for (i = 0; i < ne; i = j) {
		for (j = i + 1; j < ne && E[j].lo == E[i].lo && E[j].hi == E[i].hi; j++)
			;
		if (j - i == 2 && E[i].fwd != E[i + 1].fwd) {
			nb[3 * E[i].tri + E[i].e] = (int32_t)E[i + 1].tri;
			nb[3 * E[i + 1].tri + E[i + 1].e] = (int32_t)E[i].tri;
			continue;
		}
		if (j - i == 1)
			rep->n_boundary_edges++;
		else if (j - i == 2)
			rep->n_misoriented_edges++;
		else
			rep->n_nonmanifold_edges++;
		if (rep->first_bad_edge_triangle < 0) {
			rep->first_bad_edge_triangle = (long)E[i].tri;
			rep_msg(rep, "triangle %u edge %d: %s edge (shared by %zu triangles%s)",
				E[i].tri, E[i].e,
				j - i == 1 ? "boundary" : (j - i == 2 ? "inconsistently oriented" : "non-manifold"),
				j - i, j - i == 2 ? " in the same direction" : "");
		}
	}
	rep->closed = rep->n_boundary_edges == 0 && rep->n_nonmanifold_edges == 0 &&
		      rep->n_misoriented_edges == 0 && ne > 0;
	if ((flags & PX_MESH_REQUIRE_CLOSED) && !rep->closed) {
		rc = PX_E_DEGENERATE;
		goto fail;
	}
	rep->volume = rep->closed ? ldexp(vol_s, 3 * vexp) : 0.0;
	if (rep->closed && vol_s < 0.0 && !(flags & PX_MESH_NO_FLIP)) {
		rep->flipped = 1;
		rep->volume = -rep->volume;
		vol_s = -vol_s;
		for (i = 0; i < nt; i++)
			fn[i] = px_v3_neg(fn[i]);
		for (i = 0; i < nv; i++)
			vn[i] = px_v3_neg(vn[i]);
	}

	/* convexity: closed, and across every edge the neighbour's far
	 * vertex lies on or below this triangle's plane */
	if (rep->closed) {
		double ext = 0.0;
		rep->convex = 1;
		{
			/* a solid, not a flat double-sided sheet */
			px_aabb bb = px_aabb_empty();
			double dg;
			for (i = 0; i < nv; i++)
				if (used[i])
					px_aabb_extend(&bb, px_v3(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]));
			dg = px_aabb_diagonal(&bb) * vsc;
			if (!(vol_s > 1e-9 * dg * dg * dg))
				rep->convex = 0;
		}
		for (i = 0; i < nv; i++)
			if (used[i])
				ext = fmax(ext, fmax(fabs(xyz[3 * i]),
						     fmax(fabs(xyz[3 * i + 1]), fabs(xyz[3 * i + 2]))));
		for (i = 0; i < nt && rep->convex; i++) {
			const double *A = xyz + 3 * (size_t)canon[tri[3 * i]];
			if (deg[i] & DEGEN_ZERO)
				continue;
			for (k = 0; k < 3; k++) {
				int32_t o = nb[3 * i + k];
				int w;
				if (o < 0)
					continue;
				for (w = 0; w < 3; w++) {
					const double *W = xyz + 3 * (size_t)canon[tri[3 * (size_t)o + w]];
					double h = fn[i].x * (W[0] - A[0]) + fn[i].y * (W[1] - A[1]) +
						   fn[i].z * (W[2] - A[2]);
					if (h > 1e-12 * ext) {
						rep->convex = 0;
						break;
					}
				}
			}
		}
	}

	/* hierarchy */
	M = calloc(1, sizeof(*M));
	if (!M)
		goto fail;
	M->nt = nt;
	M->nv = nv;
	M->closed = rep->closed;
	perm = malloc(nt * sizeof(*perm));
	/* cache-line aligned: a 64-byte node then costs one line, not two */
	M->nodes = aligned_alloc(64, (nt + 1) * sizeof(*M->nodes));
	if (M->nodes)
		memset(M->nodes, 0, (nt + 1) * sizeof(*M->nodes));
	if (!perm || !M->nodes)
		goto fail;
	for (i = 0; i < nt; i++)
		perm[i] = (uint32_t)i;
	B.perm = perm;
	B.cen = cen;
	B.tlo = tlo;
	B.thi = thi;
	B.nodes = M->nodes;
	B.n_nodes = 0;
	B.leaf = leaf;
	B.depth = 0;
	if (nt <= (size_t)leaf) {
		struct node *nd = &M->nodes[0];
		B.n_nodes = 1;
		range_box(&B, 0, nt, nd->lo[0], nd->hi[0]);
		nd->idx[0] = 0;
		nd->cnt[0] = (uint32_t)nt;
		for (k = 0; k < 3; k++) {
			nd->lo[1][k] = INFINITY;
			nd->hi[1][k] = -INFINITY;
		}
		nd->idx[1] = EMPTY;
		nd->cnt[1] = 0;
	} else {
		build_node(&B, 0, nt, 0);
	}
	M->n_nodes = B.n_nodes;
	M->depth = B.depth + 1;
	rep->depth = M->depth;
	if (M->depth > PX_MESH_MAX_DEPTH) {
		rep_msg(rep, "hierarchy too deep (%d)", M->depth);
		rc = PX_E_RANGE;
		goto fail;
	}
	M->n4 = aligned_alloc(64, M->n_nodes * sizeof(*M->n4));
	if (!M->n4)
		goto fail;
	M->n_n4 = 0;
	px__node4_collapse(M->nodes, M->n4, &M->n_n4, 0);
	free(M->nodes);
	M->nodes = NULL;

	/* reorder into leaf order */
	/* at most this many distinct vertices; trimmed once they are known */
	M->vx = malloc((nv < 3 * nt ? nv : 3 * nt) * sizeof(*M->vx));
	M->tv = malloc(3 * nt * sizeof(*M->tv));
	M->lb = aligned_alloc(64, nt * sizeof(*M->lb));
	M->orig = malloc(nt * sizeof(*M->orig));
	M->leaf_of = malloc(nt * sizeof(*M->leaf_of));
	M->fn = malloc(nt * sizeof(*M->fn));
	M->en = malloc(3 * nt * sizeof(*M->en));
	M->vnt = malloc(3 * nt * sizeof(*M->vnt));
	M->degen = malloc(nt);
	if (!M->vx || !M->tv || !M->lb || !M->orig || !M->leaf_of || !M->fn || !M->en || !M->vnt ||
	    !M->degen)
		goto fail;
	vmap = malloc(nv * sizeof(*vmap));
	if (!vmap)
		goto fail;
	for (i = 0; i < nv; i++)
		vmap[i] = UINT32_MAX;
	M->n_vx = 0;
	M->box = px_aabb_empty();
	for (i = 0; i < nt; i++) {
		uint32_t t = perm[i];
		px_vec3 P[3];
		for (k = 0; k < 3; k++) {
			const double *X = xyz + 3 * (size_t)canon[tri[3 * t + k]];
			P[k] = px_v3(X[0], X[1], X[2]);
			px_aabb_extend(&M->box, P[k]);
			M->vnt[3 * i + k] = vn[canon[tri[3 * t + k]]];
			M->en[3 * i + k] = nb[3 * t + k] >= 0
						   ? px_v3_add(fn[t], fn[nb[3 * t + k]])
						   : fn[t];
		}
		for (k = 0; k < 3; k++) {
			/* welded vertices numbered in order of first use */
			uint32_t c = canon[tri[3 * t + k]];
			if (vmap[c] == UINT32_MAX) {
				vmap[c] = (uint32_t)M->n_vx;
				M->vx[M->n_vx++] = P[k];
			}
			M->tv[3 * i + k] = vmap[c];
		}
		memset(&M->lb[i], 0, sizeof(M->lb[i]));
		if (!(deg[t] & DEGEN_ZERO)) {
			/* the accurate normal (a thin triangle's plain one could
			 * tilt past the slack), in the vertex order, which the
			 * edges' outward normals below need: unflipped */
			struct tlb *L = &M->lb[i];
			px_vec3 nu = rep->flipped ? px_v3_neg(fn[t]) : fn[t];
			L->c[0][0] = (float)nu.x;
			L->c[1][0] = (float)nu.y;
			L->c[2][0] = (float)nu.z;
			L->c[3][0] = (float)px_v3_dot(nu, P[0]);
			for (k = 0; k < 3; k++) {
				px_vec3 e = px_v3_sub(P[(k + 1) % 3], P[k]), mm;
				if (px_v3_normalize(px_v3_cross(e, nu), px_v3(0, 0, 0), &mm) != PX_OK)
					continue;
				L->c[0][1 + k] = (float)mm.x;
				L->c[1][1 + k] = (float)mm.y;
				L->c[2][1 + k] = (float)mm.z;
				L->c[3][1 + k] = (float)px_v3_dot(mm, P[k]);
			}
		}
		M->orig[i] = t;
		M->leaf_of[t] = (uint32_t)i;
		M->fn[i] = fn[t];
		M->degen[i] = deg[t];
	}
	{
		px_vec3 *vx = realloc(M->vx, M->n_vx * sizeof(*M->vx));
		if (vx)
			M->vx = vx;
	}
	M->absmax = fmax(fmax(fabs(M->box.min.x), fabs(M->box.max.x)),
			 fmax(fmax(fabs(M->box.min.y), fabs(M->box.max.y)),
			      fmax(fabs(M->box.min.z), fabs(M->box.max.z))));
	M->bytes = sizeof(*M) + M->n_vx * sizeof(px_vec3) +
		   nt * (3 * sizeof(uint32_t) + sizeof(struct tlb) + 2 * sizeof(uint32_t) +
				      7 * sizeof(px_vec3) + 1) +
		   M->n_n4 * sizeof(struct node4);
	if (grid_build(M, opt ? opt->grid_cells : 0) != PX_OK)
		goto fail;
	if (rep->convex) {
		size_t h = 0;
		M->hull = malloc(rep->n_welded * sizeof(*M->hull));
		if (!M->hull)
			goto fail;
		for (i = 0; i < nv; i++)
			if (used[i] && canon[i] == i && h < rep->n_welded) {
				order[i] = (uint32_t)h; /* order[] reused: canon id -> hull index */
				M->hull[h++] = px_v3(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
			}
		M->n_hull = h;
		M->bytes += h * sizeof(*M->hull);
		if (h > 32) {
			/* vertex graph (CSR) from the distinct edges, sorted in E */
			size_t ne2 = 0, j2;
			M->adj_start = calloc(h + 1, sizeof(uint32_t));
			M->adj = malloc(2 * ne * sizeof(uint32_t));
			if (!M->adj_start || !M->adj)
				goto fail;
			for (j2 = 0; j2 < ne; j2++)
				if (j2 == 0 || E[j2].lo != E[j2 - 1].lo || E[j2].hi != E[j2 - 1].hi) {
					M->adj_start[order[E[j2].lo] + 1]++;
					M->adj_start[order[E[j2].hi] + 1]++;
				}
			for (j2 = 0; j2 < h; j2++)
				M->adj_start[j2 + 1] += M->adj_start[j2];
			{
				uint32_t *fill = calloc(h, sizeof(uint32_t));
				if (!fill)
					goto fail;
				for (j2 = 0; j2 < ne; j2++)
					if (j2 == 0 || E[j2].lo != E[j2 - 1].lo || E[j2].hi != E[j2 - 1].hi) {
						uint32_t a = order[E[j2].lo], b = order[E[j2].hi];
						M->adj[M->adj_start[a] + fill[a]++] = b;
						M->adj[M->adj_start[b] + fill[b]++] = a;
						ne2 += 2;
					}
				free(fill);
			}
			for (k = 0; k < 6; k++) {
				double bs = -INFINITY;
				for (j2 = 0; j2 < h; j2++) {
					double v = px_v3_comp(M->hull[j2], k / 2) * (k % 2 ? 1.0 : -1.0);
					if (v > bs) {
						bs = v;
						M->ext[k] = (uint32_t)j2;
					}
				}
			}
			M->bytes += (h + 1 + ne2) * sizeof(uint32_t);
		}
	}
	rc = px_model_create(rep->convex ? &mesh_ops_convex : &mesh_ops, M,
			     PX_MODEL_CAP_EXACT | PX_MODEL_CAP_COHERENT |
				     (M->closed ? PX_MODEL_CAP_SIGNED : 0u) |
				     (rep->convex ? PX_MODEL_CAP_CONVEX : 0u),
			     out);
	M = NULL; /* owned by the model now, also on failure */
	if (rc != PX_OK)
		rep_msg(rep, "out of memory");
	goto done;
fail:
	if (rc == PX_E_NOMEM)
		rep_msg(rep, "out of memory");
	mesh_free(M);
done:
	free(used);
	free(order);
	free(canon);
	free(perm);
	free(E);
	free(nb);
	free(fn);
	free(vn);
	free(cen);
	free(tlo);
	free(thi);
	free(deg);
	free(vmap);
	return rc;
}

/* ---- accessors ------------------------------------------------------------- */

static const struct mesh *as_mesh(const struct px_model *m)
{
	const struct px_model_ops *o = px_model_get_ops(m);
	if (o != &mesh_ops && o != &mesh_ops_convex)
		return NULL;
	return px_model_impl(m);
}

size_t px_mesh_triangle_count(const struct px_model *m)
{
	const struct mesh *M = as_mesh(m);
	return M ? M->nt : 0;
}

int px_mesh_triangle(const struct px_model *m, size_t i, px_vec3 v[3])
{
	const struct mesh *M = as_mesh(m);
	const uint32_t *t;
	if (!M || !v || i >= M->nt)
		return PX_E_INVAL;
	t = M->tv + 3 * (size_t)M->leaf_of[i];
	v[0] = M->vx[t[0]];
	v[1] = M->vx[t[1]];
	v[2] = M->vx[t[2]];
	return PX_OK;
}

int px_mesh_is_closed(const struct px_model *m)
{
	const struct mesh *M = as_mesh(m);
	return M ? M->closed : 0;
}

/* ---- files ------------------------------------------------------------------ */

int px_mesh_load(const char *path, const struct px_mesh_opts *opt,
		 struct px_mesh_report *rep, struct px_model **out)
{
	struct px_mesh_report lrep;
	double *xyz = NULL;
	uint32_t *tri = NULL;
	size_t nv = 0, nt = 0, skipped = 0;
	char msg[sizeof(rep->message)];
	int rc;

	if (!rep)
		rep = &lrep;
	memset(rep, 0, sizeof(*rep));
	rep->first_degenerate = -1;
	rep->first_bad_edge_triangle = -1;
	if (out)
		*out = NULL;
	if (!out || !path) {
		rep_msg(rep, "invalid arguments");
		return PX_E_INVAL;
	}
	rc = px__import_file(path, 1, &xyz, &nv, &tri, &nt, &skipped, msg,
			     sizeof(msg));
	if (rc != PX_OK) {
		snprintf(rep->message, sizeof(rep->message), "%s", msg);
		return rc;
	}
	rc = px_mesh_model(xyz, nv, tri, nt, opt, rep, out);
	if (rep->message[0]) {
		px__prefix_path(rep->message, sizeof(rep->message), path);
	}
	free(xyz);
	free(tri);
	return rc;
}
