/*
 * px_mesh_pair.c - exact distance between two posed triangle meshes, and
 * a lower-bounded search of a mesh against any other model.
 *
 * Mesh against mesh: both hierarchies (mesh_internal.h: four-child float
 * boxes, triangles in leaf order) are walked together, depth first,
 * nearer pairs first, with the best triangle pair so far as the bound
 * (the scheme of the bounding-volume-tree distance queries of Larsen,
 * Gottschalk, Lin and Manocha, 1999). The work happens in A's model
 * frame: a box of B becomes an oriented box there, and the lower bound
 * of a box pair is the larger of two axis-aligned gaps: B's box, rotated
 * into A's frame and enclosed by an axis-aligned box, against A's box;
 * and the same from B's side. Each encloses the true box, so each gap is
 * at most the true box distance, and the box distance is at most the
 * distance of any two triangles inside. Once a pair is found, its own
 * direction is a separating axis too (box pairs, and each leaf's
 * triangles exactly): near a contact where both models are locally
 * convex every other pair projects farther apart than the best along
 * it, so a good first pair (last cycle's in coherent use, else a greedy
 * guess down both hierarchies) ends the search after few triangle
 * tests. Triangle pairs are measured exactly
 * (px__tri_tri). So the answer is the minimum over all triangle pairs,
 * up to rounding (a gap is reduced by a slack of 1e-14 of the
 * coordinate scale before it prunes; along the best pair's direction a
 * pair within twice that slack of the best is a tie and is not
 * measured).
 *
 * Memory and real-time rules: no allocation; a fixed stack of MP_STACK
 * entries on the call stack. Every node pair is expanded at most once,
 * so the work is bounded by the product of the node counts (and in
 * practice a small multiple of the nodes near the closest pair).
 */
#include <limits.h>
#include <math.h>
#include <string.h>

#include "mesh_internal.h"
#include "px_mesh.h"
#include "px_model.h"

/* ---- triangle against triangle ------------------------------------------- */

/*
 * Closest points of segments p1q1 and p2q2 (squared distance). The line
 * parameter comes from cross products: s = ((d1 x d2) . (d2 x r)) /
 * |d1 x d2|^2 equals the usual (b f - c e) / (a e - b^2) by Lagrange's
 * identity, but without the cancellation of a e - b^2 for nearly
 * parallel segments (relative error eps / sin(angle) instead of
 * eps / sin^2). Then the clamping order of Ericson (2005, 5.1.9), which
 * is exact for any s in [0, 1].
 */
static double seg_seg(px_vec3 p1, px_vec3 q1, px_vec3 p2, px_vec3 q2,
		      px_vec3 *c1, px_vec3 *c2)
{
	px_vec3 d1 = px_v3_sub(q1, p1), d2 = px_v3_sub(q2, p2), r = px_v3_sub(p1, p2);
	double a = px_v3_norm2(d1), e = px_v3_norm2(d2), f = px_v3_dot(d2, r);
	double s, t;

	if (a <= 0.0 && e <= 0.0) {
		s = t = 0.0;
	} else if (a <= 0.0) {
		s = 0.0;
		t = f / e;
		t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
	} else {
		double c = px_v3_dot(d1, r);
		if (e <= 0.0) {
			t = 0.0;
			s = -c / a;
			s = s < 0.0 ? 0.0 : (s > 1.0 ? 1.0 : s);
		} else {
			double b = px_v3_dot(d1, d2);
			px_vec3 n = px_v3_cross(d1, d2);
			double nn = px_v3_norm2(n);
			s = 0.0;
			if (nn > 0.0) {
				s = px_v3_dot(n, px_v3_cross(d2, r)) / nn;
				s = s < 0.0 ? 0.0 : (s > 1.0 ? 1.0 : s);
			}
			t = (b * s + f) / e;
			if (t < 0.0) {
				t = 0.0;
				s = -c / a;
				s = s < 0.0 ? 0.0 : (s > 1.0 ? 1.0 : s);
			} else if (t > 1.0) {
				t = 1.0;
				s = (b - c) / a;
				s = s < 0.0 ? 0.0 : (s > 1.0 ? 1.0 : s);
			}
		}
	}
	*c1 = px_v3_madd(p1, d1, s);
	*c2 = px_v3_madd(p2, d2, t);
	return px_v3_dist2(*c1, *c2);
}

/*
 * Does edge pq of one triangle pass through triangle T (normal n = (T1 -
 * T0) x (T2 - T0))? dp, dq: n . (p - T0) and n . (q - T0). Writes the
 * crossing point. An edge lying in T's plane is left to the edge-edge
 * and vertex-triangle distances, which are 0 for any coplanar contact.
 */
static int seg_crosses(px_vec3 p, px_vec3 q, double dp, double dq,
		       const px_vec3 T[3], px_vec3 n, px_vec3 *x)
{
	px_vec3 y;
	int k;

	if ((dp > 0.0 && dq > 0.0) || (dp < 0.0 && dq < 0.0) || dp == dq)
		return 0;
	y = px_v3_madd(p, px_v3_sub(q, p), dp / (dp - dq));
	/* inside: on the inner side of all three edges (the side n turns
	 * them to) */
	for (k = 0; k < 3; k++) {
		px_vec3 e = px_v3_sub(T[(k + 1) % 3], T[k]);
		if (px_v3_dot(px_v3_cross(e, px_v3_sub(y, T[k])), n) < 0.0)
			return 0;
	}
	*x = y;
	return 1;
}

/* Does the projection of p onto T's plane fall inside T (closed)? */
static int projects_inside(px_vec3 p, const px_vec3 T[3], px_vec3 n)
{
	int k;
	for (k = 0; k < 3; k++) {
		px_vec3 e = px_v3_sub(T[(k + 1) % 3], T[k]);
		if (px_v3_dot(px_v3_cross(e, px_v3_sub(p, T[k])), n) < 0.0)
			return 0;
	}
	return 1;
}

int px__pair_frame(const px_vec3 *P, int n, px_vec3 o, double *s, int *e)
{
	double ext = 0.0, mag = 0.0;
	int i;
	/* compares, not fmax (a library call); a NaN fails the range test */
	for (i = 0; i < n; i++) {
		px_vec3 d = px_v3_sub(P[i], o);
		double x[6] = {fabs(d.x), fabs(d.y), fabs(d.z), fabs(P[i].x), fabs(P[i].y),
			       fabs(P[i].z)};
		int k;
		for (k = 0; k < 3; k++) {
			ext = x[k] > ext ? x[k] : ext;
			mag = x[3 + k] > mag ? x[3 + k] : mag;
		}
	}
	if (!(ext > 0.0)) {
		*e = INT_MIN;
		*s = 1.0;
		return 0;
	}
	if (ext >= 0x1p-100 && ext <= 0x1p100 && mag <= 0x1p26 * ext)
		return 0;
	(void)frexp(ext, e);
	*s = ldexp(1.0, -*e);
	return 1;
}

double px__tri_tri(const px_vec3 A[3], const px_vec3 B[3], px_vec3 *pa,
		   px_vec3 *pb, int *crossing)
{
	/* Unit normals, accurate for needles and slivers too (the plain
	 * cross product of a needle's edges tilts by u / sin(angle), enough
	 * to miss a crossing or skip the nearest vertex-face pair); a
	 * triangle without area has none and is its edges. */
	px_vec3 na = px__tri_unit_normal(A[0], A[1], A[2]);
	px_vec3 nb = px__tri_unit_normal(B[0], B[1], B[2]);
	px_vec3 x, c1, c2;
	double best = INFINITY, d2, ha[3], hb[3];
	int i, j, fa = px_v3_norm2(na) > 0.0, fb = px_v3_norm2(nb) > 0.0;
	int sep;

	{
		/* tiny, huge or far from the origin: the same in a frame at
		 * A[0] scaled to a unit extent (the products of four
		 * differences in seg_seg would underflow or overflow) */
		px_vec3 P[6] = {A[0], A[1], A[2], B[0], B[1], B[2]}, A2[3], B2[3];
		double sc;
		int e;
		if (px__pair_frame(P, 6, A[0], &sc, &e)) {
			for (i = 0; i < 3; i++) {
				A2[i] = px_v3_scale(px_v3_sub(A[i], A[0]), sc);
				B2[i] = px_v3_scale(px_v3_sub(B[i], A[0]), sc);
			}
			d2 = px__tri_tri(A2, B2, &c1, &c2, crossing);
			*pa = px_v3_madd(A[0], c1, 1.0 / sc);
			*pb = px_v3_madd(A[0], c2, 1.0 / sc);
			return ldexp(d2, 2 * e);
		}
	}

	*crossing = 0;
	for (i = 0; i < 3; i++) {
		hb[i] = px_v3_dot(na, px_v3_sub(B[i], A[0])); /* B against A's plane */
		ha[i] = px_v3_dot(nb, px_v3_sub(A[i], B[0]));
	}
	/* one triangle strictly on one side of the other's plane: no
	 * crossing possible */
	sep = (hb[0] > 0.0 && hb[1] > 0.0 && hb[2] > 0.0) ||
	      (hb[0] < 0.0 && hb[1] < 0.0 && hb[2] < 0.0) ||
	      (ha[0] > 0.0 && ha[1] > 0.0 && ha[2] > 0.0) ||
	      (ha[0] < 0.0 && ha[1] < 0.0 && ha[2] < 0.0);
	/* Two triangles that cross meet along a segment whose ends lie on
	 * edges: some edge of one passes through the other. A degenerate
	 * triangle (zero normal) is crossed only through its partner's
	 * test, or touched, which the distances below see as 0. */
	for (i = 0; i < 3 && !sep; i++) {
		int i1 = (i + 1) % 3;
		if (px_v3_norm2(nb) > 0.0 &&
		    seg_crosses(A[i], A[i1], ha[i], ha[i1], B, nb, &x)) {
			*pa = *pb = x;
			*crossing = 1;
			return 0.0;
		}
		if (px_v3_norm2(na) > 0.0 &&
		    seg_crosses(B[i], B[i1], hb[i], hb[i1], A, na, &x)) {
			*pa = *pb = x;
			*crossing = 1;
			return 0.0;
		}
	}
	/* Apart: the closest pair has a vertex or an edge-edge pair on it
	 * (the minimum of a distance between two polygons is reached on a
	 * boundary of one of them, and for two segments of boundary). A
	 * vertex whose projection misses the other face is nearest to an
	 * edge of it, which the edge pairs cover. */
	for (i = 0; i < 3; i++)
		for (j = 0; j < 3; j++) {
			d2 = seg_seg(A[i], A[(i + 1) % 3], B[j], B[(j + 1) % 3], &c1, &c2);
			if (d2 < best) {
				best = d2;
				*pa = c1;
				*pb = c2;
			}
		}
	for (i = 0; i < 3; i++) {
		if (fb && ha[i] * ha[i] < best &&
		    projects_inside(A[i], B, nb)) {
			d2 = px_tri_closest(A[i], B[0], B[1], B[2], &c2, NULL, NULL, NULL, NULL);
			if (d2 < best) {
				best = d2;
				*pa = A[i];
				*pb = c2;
			}
		}
		if (fa && hb[i] * hb[i] < best &&
		    projects_inside(B[i], A, na)) {
			d2 = px_tri_closest(B[i], A[0], A[1], A[2], &c1, NULL, NULL, NULL, NULL);
			if (d2 < best) {
				best = d2;
				*pa = c1;
				*pb = B[i];
			}
		}
	}
	return best;
}

/* ---- mesh against mesh ---------------------------------------------------- */

/* Deepest descent: each expansion replaces one entry by at most four,
 * along a path of at most (binary depth / 2 + 1) four-child levels per
 * mesh. */
#define MP_STACK (3 * (PX_MESH_MAX_DEPTH + 4) + 4)
#define ROOT_SLOT 4

struct mp_ent {
	uint32_t na, nb; /* parent node4 of each side (0 with ROOT_SLOT) */
	uint8_t sa, sb;  /* child slot in the parent, ROOT_SLOT for the root */
	double lb2;
};

/* Projections of leaves onto the best pair's direction (a leaf meets
 * several leaves of the other side): direct mapped by the leaf's first
 * element, valid while the direction is the one of stamp. */
#define WC_SLOTS 32

struct wcache {
	uint32_t key[WC_SLOTS]; /* first element + 1; 0: empty */
	double stamp[WC_SLOTS], val[WC_SLOTS];
};

/* One side's hierarchy: a mesh's or a cloud's (the same layout). */
struct tree {
	const struct node4 *n4;
	px_aabb box;
};

struct mp_ctx {
	const struct mesh *A, *B; /* B: NULL against a cloud */
	struct tree ta, tb;
	const px_vec3 *cpt;       /* the cloud's points (leaf order) */
	/* a small A's vertices (its support function, which bounds any
	 * part of it) and its box centre; n_sv 0: none */
	const px_vec3 *sv;
	size_t n_sv;
	px_vec3 sc;
	double R[3][3], Ra[3][3]; /* B frame -> A frame: p_A = R p_B + t */
	px_vec3 t;
	double slack;
	double best2;
	/* the best pair's unit direction pb - pa in A's frame (wu) and in
	 * B's (wub), with wu . t, as of best2 == wbest2 (wok: one exists) */
	double wu[3], wub[3], wut, wbest2;
	int wok;
	struct wcache wca, wcb; /* leaf projections on it, A's and B's */
	long la, lb;
	px_vec3 pa, pb; /* A frame */
	int crossing;
	int nodes, tests;
};

static const struct mesh *mesh_of(const struct px_model *m)
{
	/* px_mesh_triangle_count() answers only for the mesh's own ops */
	return px_mesh_triangle_count(m) > 0 ? px_model_impl(m) : NULL;
}

static void ref_get(const struct tree *M, uint32_t node, int slot, px_vec3 *c,
		    px_vec3 *h, uint32_t *idx, uint32_t *cnt)
{
	if (slot == ROOT_SLOT) {
		*c = px_v3_scale(px_v3_add(M->box.min, M->box.max), 0.5);
		*h = px_v3_scale(px_v3_sub(M->box.max, M->box.min), 0.5);
		*idx = 0;
		*cnt = 0;
		return;
	}
	{
		const struct node4 *nd = &M->n4[node];
		double lo[3], hi[3];
		int k;
		for (k = 0; k < 3; k++) {
			lo[k] = nd->lo[k][slot];
			hi[k] = nd->hi[k][slot];
		}
		*c = px_v3(0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2]));
		/* the half extents are rounded up so the box still encloses */
		*h = px_v3(0.5 * (hi[0] - lo[0]), 0.5 * (hi[1] - lo[1]), 0.5 * (hi[2] - lo[2]));
		*idx = nd->idx[slot];
		*cnt = nd->cnt[slot];
	}
}

static inline double gap_pos(double g)
{
	return g > 0.0 ? g : 0.0;
}

/* A node box seen from both frames: centre and half extents in A's
 * frame and in B's frame (exact in its own mesh's frame, the enclosing
 * axis-aligned box of the rotated box in the other). */
struct bx {
	double cA[3], eA[3], cB[3], eB[3];
};

static void bx_of_a(const struct mp_ctx *X, px_vec3 c, px_vec3 h, struct bx *o)
{
	double u[3] = {c.x - X->t.x, c.y - X->t.y, c.z - X->t.z};
	int k;
	o->cA[0] = c.x, o->cA[1] = c.y, o->cA[2] = c.z;
	o->eA[0] = h.x, o->eA[1] = h.y, o->eA[2] = h.z;
	for (k = 0; k < 3; k++) {
		o->cB[k] = X->R[0][k] * u[0] + X->R[1][k] * u[1] + X->R[2][k] * u[2];
		o->eB[k] = X->Ra[0][k] * h.x + X->Ra[1][k] * h.y + X->Ra[2][k] * h.z;
	}
}

static void bx_of_b(const struct mp_ctx *X, px_vec3 c, px_vec3 h, struct bx *o)
{
	int k;
	o->cB[0] = c.x, o->cB[1] = c.y, o->cB[2] = c.z;
	o->eB[0] = h.x, o->eB[1] = h.y, o->eB[2] = h.z;
	for (k = 0; k < 3; k++) {
		o->cA[k] = X->R[k][0] * c.x + X->R[k][1] * c.y + X->R[k][2] * c.z +
			   px_v3_comp(X->t, k);
		o->eA[k] = X->Ra[k][0] * h.x + X->Ra[k][1] * h.y + X->Ra[k][2] * h.z;
	}
}

/* A box (centre c, half extents h) of A (side 0) or of B (side 1), in
 * its own model's frame, projected exactly onto the best pair's
 * direction: centre *p and radius *r, on A's frame's line. */
static inline void wax_box(const struct mp_ctx *X, int side, px_vec3 c, px_vec3 h, double *p,
			   double *r)
{
	const double *u = side ? X->wub : X->wu;
	*p = u[0] * c.x + u[1] * c.y + u[2] * c.z + (side ? X->wut : 0.0);
	*r = fabs(u[0]) * h.x + fabs(u[1]) * h.y + fabs(u[2]) * h.z;
}

/* The squared gap of two boxes so projected (0 without a direction);
 * the slack, doubled, covers the sums of up to six products of a unit
 * vector. */
static inline double wax_gap2(const struct mp_ctx *X, double p1, double r1, double p2, double r2)
{
	double g = fabs(p1 - p2) - r1 - r2 - 2.0 * X->slack;
	return X->wok && g > 0.0 ? g * g : 0.0;
}

/*
 * Lower bound of the squared distance between box a of A and box b of
 * B (see the top of the file): the axis-aligned gaps in A's frame and in
 * B's frame, and the gap along the line of centres w, where the boxes
 * project to intervals of half lengths sum |w_k| h_k (each box in its
 * own frame) around centres |w| apart; that one is tight when the boxes
 * face each other diagonally, where the axis-aligned gaps lose most. sw:
 * the gap along the best pair's direction (wax_gap2), the first and
 * cheapest bound, which the caller has tried alone.
 */
static double box_lb2(const struct mp_ctx *X, const struct bx *a, const struct bx *b, double sw)
{
	double s1 = 0.0, s2 = 0.0, ww = 0.0, ext = 0.0, w1 = 0.0;
	int k;

	for (k = 0; k < 3; k++) {
		double w = b->cA[k] - a->cA[k], wb = b->cB[k] - a->cB[k];
		double g1 = gap_pos(fabs(w) - a->eA[k] - b->eA[k] - X->slack);
		double g2 = gap_pos(fabs(wb) - a->eB[k] - b->eB[k] - X->slack);
		s1 += g1 * g1;
		s2 += g2 * g2;
		ww += w * w;
		w1 += fabs(w);
		ext += fabs(w) * a->eA[k] + fabs(wb) * b->eB[k];
	}
	s1 = s1 > s2 ? s1 : s2;
	s1 = s1 > sw ? s1 : sw;
	/* (|w|^2 - ext) / |w| is the gap; the slack, scaled by |w|_1 >=
	 * |w|, keeps it a lower bound under rounding */
	ext += X->slack * w1;
	if (ww > ext) {
		double g = ww - ext;
		g = g * g / ww;
		if (g > s1)
			s1 = g;
	}
	return s1;
}

static inline px_vec3 to_a(const struct mp_ctx *X, px_vec3 p)
{
	return px_v3(X->R[0][0] * p.x + X->R[0][1] * p.y + X->R[0][2] * p.z + X->t.x,
		     X->R[1][0] * p.x + X->R[1][1] * p.y + X->R[1][2] * p.z + X->t.y,
		     X->R[2][0] * p.x + X->R[2][1] * p.y + X->R[2][2] * p.z + X->t.z);
}

static inline double mn3(double a, double b, double c)
{
	double m = a < b ? a : b;
	return m < c ? m : c;
}

static inline double mx3(double a, double b, double c)
{
	double m = a > b ? a : b;
	return m > c ? m : c;
}

/* Lower bound of a triangle pair along any direction u (not unit): the
 * gap between the triangles' projections onto it, at most their
 * distance. Returns 1 when that gap alone exceeds the best distance. */
static inline int axis_apart(const struct mp_ctx *X, px_vec3 u, const px_vec3 T[3],
			     const px_vec3 V[3])
{
	double uu = px_v3_norm2(u);
	double t0 = px_v3_dot(u, T[0]), t1 = px_v3_dot(u, T[1]), t2 = px_v3_dot(u, T[2]);
	double v0 = px_v3_dot(u, V[0]), v1 = px_v3_dot(u, V[1]), v2 = px_v3_dot(u, V[2]);
	double g = mn3(v0, v1, v2) - mx3(t0, t1, t2), g2 = mn3(t0, t1, t2) - mx3(v0, v1, v2);
	g = g > g2 ? g : g2;
	if (!(g > 0.0) || !(uu > 0.0))
		return 0;
	g = g / sqrt(uu) - X->slack;
	return g > 0.0 && g * g > X->best2;
}

/* The same along the triangles' line of centres. */
static inline int centres_apart(const struct mp_ctx *X, const px_vec3 T[3],
				const px_vec3 V[3])
{
	px_vec3 ct = px_v3_add(T[0], px_v3_add(T[1], T[2]));
	px_vec3 cv = px_v3_add(V[0], px_v3_add(V[1], V[2]));
	return axis_apart(X, px_v3_sub(cv, ct), T, V);
}

static void pair_test(struct mp_ctx *X, uint32_t ia, const px_vec3 V[3], uint32_t ib)
{
	const struct mtri ta_ = px__mtri_get(X->A, ia), *ta = &ta_;
	px_vec3 T[3] = {ta->a, ta->b, ta->c}, pa, pb;
	double d2;
	int cr;

	if (ta->inv_nn != 0.0 && X->best2 < INFINITY) {
		/* B's triangle wholly on one side of A's plane and farther
		 * than the best: its distance is at least the nearest vertex's
		 * plane distance */
		double h0 = px_v3_dot(ta->n, px_v3_sub(V[0], ta->a));
		double h1 = px_v3_dot(ta->n, px_v3_sub(V[1], ta->a));
		double h2 = px_v3_dot(ta->n, px_v3_sub(V[2], ta->a));
		double m = INFINITY;
		if (h0 > 0.0 && h1 > 0.0 && h2 > 0.0)
			m = mn3(h0, h1, h2);
		else if (h0 < 0.0 && h1 < 0.0 && h2 < 0.0)
			m = -mx3(h0, h1, h2);
		if (m < INFINITY) {
			m = m * sqrt(ta->inv_nn) - X->slack;
			if (m > 0.0 && m * m > X->best2)
				return;
		}
		/* and the same from B's side: A's triangle against B's
		 * plane */
		if (axis_apart(X, px_v3_cross(px_v3_sub(V[1], V[0]), px_v3_sub(V[2], V[0])), T, V))
			return;
	}
	X->tests++;
	d2 = px__tri_tri(T, V, &pa, &pb, &cr);
	if (d2 < X->best2 || X->la < 0) {
		X->best2 = d2;
		X->la = (long)ia;
		X->lb = (long)ib;
		X->pa = pa;
		X->pb = pb;
		X->crossing = cr;
	}
}

/* A leaf of A with its triangles' boxes (A frame), set up once per
 * leaf pair. */
#define LEAF_MAX 16

/* The best pair's direction for box_lb2, remade when the best moved. */
static void mp_axis(struct mp_ctx *X)
{
	px_vec3 u = px_v3_sub(X->pb, X->pa);
	double n = px_v3_norm(u);
	int k;
	X->wbest2 = X->best2;
	/* not against a cloud: its nodes' own bounds prune as well there */
	X->wok = n > 0.0 && X->la >= 0 && !X->cpt;
	if (!X->wok)
		return;
	u = px_v3_scale(u, 1.0 / n);
	X->wu[0] = u.x, X->wu[1] = u.y, X->wu[2] = u.z;
	X->wut = px_v3_dot(u, X->t);
	for (k = 0; k < 3; k++)
		X->wub[k] = X->R[0][k] * u.x + X->R[1][k] * u.y + X->R[2][k] * u.z;
}

/*
 * The best pair's own direction u = pb - pa as a separating axis: the
 * gap between a triangle pair's projections onto u is at most its
 * distance, and near a contact where both models are locally convex it
 * exceeds the best distance for every triangle pair but those touching
 * the two supporting planes: the bound that ends a search whose best is
 * already the answer (a coherent start, a far pair whose nearest
 * features are found early). Per leaf pair: each triangle's extreme
 * projection, remade whenever the best changes.
 */
struct wax {
	double best2;
	double amax[LEAF_MAX], bmin[LEAF_MAX];
};

/* B's projections from its own frame (u . (R p + t) = (R^T u) . p + u .
 * t): no triangle of B need be moved into A's frame for the test. */
static void wax_update(struct mp_ctx *X, struct wax *W, uint32_t ia, uint32_t na, uint32_t ib,
		       uint32_t nb)
{
	px_vec3 u, ub;
	uint32_t i;
	if (X->best2 != X->wbest2)
		mp_axis(X);
	u = px_v3(X->wu[0], X->wu[1], X->wu[2]);
	ub = px_v3(X->wub[0], X->wub[1], X->wub[2]);
	W->best2 = X->best2;
	for (i = 0; i < na; i++) {
		const struct mtri3 t = px__tri3_get(X->A, ia + i);
		W->amax[i] = mx3(px_v3_dot(u, t.a), px_v3_dot(u, t.b), px_v3_dot(u, t.c));
	}
	for (i = 0; i < nb; i++) {
		const struct mtri3 t = px__tri3_get(X->B, ib + i);
		W->bmin[i] = mn3(px_v3_dot(ub, t.a), px_v3_dot(ub, t.b), px_v3_dot(ub, t.c)) +
			     X->wut;
	}
}

/* Does the best pair's axis rule out a part of A whose projections
 * reach up to amax against a part of B whose projections start at bmin?
 * A pair whose bound comes within twice the slack of the best is a tie:
 * it cannot lower the answer by more than rounding. */
static inline int wax_prunes(const struct mp_ctx *X, double amax, double bmin)
{
	double g = bmin - amax + X->slack;
	return g > 0.0 && g * g >= X->best2;
}

/* The largest projection of A's leaf [i0, i0 + n) onto the best pair's
 * direction (side 0), or the least of B's (side 1), cached. */
static double leaf_proj(struct mp_ctx *X, int side, uint32_t i0, uint32_t n)
{
	struct wcache *C = side ? &X->wcb : &X->wca;
	uint32_t s = (i0 * 2654435761u) >> 27, i; /* 32 slots */
	px_vec3 u = side ? px_v3(X->wub[0], X->wub[1], X->wub[2])
			 : px_v3(X->wu[0], X->wu[1], X->wu[2]);
	double v = 0.0;
	if (C->key[s] == i0 + 1 && C->stamp[s] == X->wbest2)
		return C->val[s];
	for (i = 0; i < n; i++) {
		const struct mtri3 t = px__tri3_get(side ? X->B : X->A, i0 + i);
		double a = px_v3_dot(u, t.a), b = px_v3_dot(u, t.b), c = px_v3_dot(u, t.c);
		double x = side ? mn3(a, b, c) : mx3(a, b, c);
		v = i == 0 || (side ? x < v : x > v) ? x : v;
	}
	if (side)
		v += X->wut;
	C->key[s] = i0 + 1;
	C->stamp[s] = X->wbest2;
	C->val[s] = v;
	return v;
}

static void leaf_pair(struct mp_ctx *X, uint32_t ia, uint32_t na, uint32_t ib,
		      uint32_t nb, px_vec3 ca, px_vec3 ha, px_vec3 cb, px_vec3 hb)
{
	double alo[LEAF_MAX][3], ahi[LEAF_MAX][3];
	px_vec3 VB[LEAF_MAX][3], ga = px_v3(0, 0, 0), gb = px_v3(0, 0, 0), u;
	struct wax W;
	uint8_t near_b[LEAF_MAX];
	px_vec3 cbA = to_a(X, cb);
	double eb[3], uu, mxa = -INFINITY, mnb = INFINITY;
	uint32_t j, i;
	int k, any = 0;

	W.best2 = -1.0; /* no axis yet */
	na = na > LEAF_MAX ? LEAF_MAX : na; /* leaves hold at most 16 */
	nb = nb > LEAF_MAX ? LEAF_MAX : nb;
	if (X->best2 < INFINITY && X->la >= 0) {
		/* the best pair's axis against the leaves' triangles, then
		 * each triangle's projection for the pairs below */
		if (X->best2 != X->wbest2)
			mp_axis(X);
		if (X->wok && wax_prunes(X, leaf_proj(X, 0, ia, na), leaf_proj(X, 1, ib, nb)))
			return;
		wax_update(X, &W, ia, na, ib, nb);
	}
	for (j = 0; j < nb; j++) {
		const struct mtri3 tb_ = px__tri3_get(X->B, ib + j), *tb = &tb_;
		VB[j][0] = to_a(X, tb->a);
		VB[j][1] = to_a(X, tb->b);
		VB[j][2] = to_a(X, tb->c);
		gb = px_v3_add(gb, px_v3_add(VB[j][0], px_v3_add(VB[j][1], VB[j][2])));
	}
	for (i = 0; i < na; i++) {
		const struct mtri3 ta_ = px__tri3_get(X->A, ia + i), *ta = &ta_;
		ga = px_v3_add(ga, px_v3_add(ta->a, px_v3_add(ta->b, ta->c)));
	}
	if (X->best2 < INFINITY) {
		/* the two leaves' vertices on their line of centres: a gap
		 * there bounds every triangle pair of the leaves at once */
		u = px_v3_sub(px_v3_scale(gb, 1.0 / (3.0 * nb)), px_v3_scale(ga, 1.0 / (3.0 * na)));
		uu = px_v3_norm2(u);
		for (i = 0; i < na; i++) {
			const struct mtri3 ta_ = px__tri3_get(X->A, ia + i), *ta = &ta_;
			mxa = fmax(mxa, mx3(px_v3_dot(u, ta->a), px_v3_dot(u, ta->b), px_v3_dot(u, ta->c)));
		}
		for (j = 0; j < nb; j++)
			mnb = fmin(mnb, mn3(px_v3_dot(u, VB[j][0]), px_v3_dot(u, VB[j][1]),
					    px_v3_dot(u, VB[j][2])));
		if (mnb > mxa && uu > 0.0) {
			double g = (mnb - mxa) / sqrt(uu) - X->slack;
			if (g > 0.0 && g * g > X->best2)
				return;
		}
	}
	for (k = 0; k < 3; k++)
		eb[k] = X->Ra[k][0] * hb.x + X->Ra[k][1] * hb.y + X->Ra[k][2] * hb.z;
	for (i = 0; i < na; i++) {
		const struct mtri3 ta_ = px__tri3_get(X->A, ia + i), *ta = &ta_;
		double g2 = 0.0;
		for (k = 0; k < 3; k++) {
			double a = px_v3_comp(ta->a, k), b = px_v3_comp(ta->b, k),
			       c = px_v3_comp(ta->c, k), cc = px_v3_comp(cbA, k), g;
			alo[i][k] = mn3(a, b, c);
			ahi[i][k] = mx3(a, b, c);
			g = alo[i][k] - (cc + eb[k]);
			if (cc - eb[k] - ahi[i][k] > g)
				g = cc - eb[k] - ahi[i][k];
			g = gap_pos(g - X->slack);
			g2 += g * g;
		}
		near_b[i] = !(g2 > X->best2);
		any |= near_b[i];
	}
	if (!any)
		return;
	for (j = 0; j < nb; j++) {
		const px_vec3 *V = VB[j];
		double lo[3] = {mn3(V[0].x, V[1].x, V[2].x), mn3(V[0].y, V[1].y, V[2].y),
				mn3(V[0].z, V[1].z, V[2].z)};
		double hi[3] = {mx3(V[0].x, V[1].x, V[2].x), mx3(V[0].y, V[1].y, V[2].y),
				mx3(V[0].z, V[1].z, V[2].z)};
		double gb2 = 0.0;
		for (k = 0; k < 3; k++) {
			/* this triangle of B against A's whole leaf box */
			double c = px_v3_comp(ca, k), h = px_v3_comp(ha, k);
			double a = c - h - hi[k], b = lo[k] - c - h;
			double g = gap_pos((a > b ? a : b) - X->slack);
			gb2 += g * g;
		}
		if (gb2 > X->best2)
			continue;
		for (i = 0; i < na; i++) {
			const struct mtri3 ta_ = px__tri3_get(X->A, ia + i), *ta = &ta_;
			px_vec3 T[3];
			double g2 = 0.0;
			if (!near_b[i])
				continue;
			for (k = 0; k < 3; k++) {
				double a = alo[i][k] - hi[k], b = lo[k] - ahi[i][k];
				double g = gap_pos((a > b ? a : b) - X->slack);
				g2 += g * g;
			}
			if (g2 > X->best2)
				continue;
			if (X->best2 < INFINITY) {
				if (W.best2 != X->best2)
					wax_update(X, &W, ia, na, ib, nb);
				if (X->wok && wax_prunes(X, W.amax[i], W.bmin[j]))
					continue;
			}
			T[0] = ta->a;
			T[1] = ta->b;
			T[2] = ta->c;
			if (X->best2 < INFINITY && centres_apart(X, T, V))
				continue;
			pair_test(X, ia + i, V, ib + j);
			if (X->best2 == 0.0)
				return;
		}
	}
}

/* Lower bound of the squared distance from p (A's frame) to leaf
 * triangle li of A from its float plane and edge data (struct tlb: the
 * plane distance and the largest edge-line excess, exact in the face
 * and edge regions), in double; slack covers the float data's rounding
 * (16 * 2^-24 of the coordinates, doubled, as the point query's). */
static inline double tlb_d2(const struct mesh *A, uint32_t li, px_vec3 p, double slack)
{
	const struct tlb *L = &A->lb[li];
	double v[4], h, e;
	int j;
	for (j = 0; j < 4; j++)
		v[j] = (double)L->c[0][j] * p.x + (double)L->c[1][j] * p.y +
		       (double)L->c[2][j] * p.z - (double)L->c[3][j];
	h = gap_pos(fabs(v[0]) - slack);
	e = gap_pos(mx3(v[1], v[2], v[3]) - slack);
	return h * h + e * e;
}

/* Lower bound of the squared distance between a box of B (centre c,
 * half extents h, B's frame) and a part of A with vertices sv (A's
 * frame), along the unit vector u from sc towards the box: the gap
 * between the box's projection and the part's support along u (the
 * largest projection of its vertices). Tight for a far box, where the
 * two boxes' own bound loses what A's box sticks out beyond A. */
static double support_lb2(const struct mp_ctx *X, const px_vec3 *sv, size_t n_sv, px_vec3 sc,
			  px_vec3 c, px_vec3 h)
{
	px_vec3 cA = to_a(X, c), u = px_v3_sub(cA, sc);
	double n = px_v3_norm(u), top = -INFINITY, r = 0.0, g;
	size_t i;
	int k;
	if (!(n > 0.0))
		return 0.0;
	u = px_v3_scale(u, 1.0 / n);
	for (i = 0; i < n_sv; i++) {
		double v = px_v3_dot(u, sv[i]);
		top = v > top ? v : top;
	}
	/* the box's projection radius: u in B's frame against h */
	for (k = 0; k < 3; k++)
		r += fabs(X->R[0][k] * u.x + X->R[1][k] * u.y + X->R[2][k] * u.z) *
		     px_v3_comp(h, k);
	g = px_v3_dot(u, cA) - r - top - X->slack -
	    1e-14 * (fabs(top) + fabs(px_v3_dot(u, cA)) + r);
	return g > 0.0 ? g * g : 0.0;
}

/* A leaf of A against a leaf of cloud points: every point not bounded
 * out by A's leaf box, against every triangle not bounded out by its
 * plane and edges, exactly. */
static void leaf_points(struct mp_ctx *X, uint32_t ia, uint32_t na, uint32_t ib,
			uint32_t nb, px_vec3 ca, px_vec3 ha)
{
	double alo[LEAF_MAX][3], ahi[LEAF_MAX][3];
	uint32_t i, j;
	int k, have = 0;

	na = na > LEAF_MAX ? LEAF_MAX : na; /* leaves hold at most 16 */
	for (j = 0; j < nb; j++) {
		px_vec3 p = to_a(X, X->cpt[ib + j]);
		double g2 = 0.0, slack;
		for (k = 0; k < 3; k++) {
			double g = gap_pos(fabs(px_v3_comp(p, k) - px_v3_comp(ca, k)) -
					   px_v3_comp(ha, k) - X->slack);
			g2 += g * g;
		}
		if (g2 > X->best2)
			continue;
		if (!have) {
			/* the triangles' boxes, once per leaf pair */
			for (i = 0; i < na; i++) {
				const struct mtri3 t = px__tri3_get(X->A, ia + i);
				for (k = 0; k < 3; k++) {
					double a = px_v3_comp(t.a, k), b = px_v3_comp(t.b, k),
					       c = px_v3_comp(t.c, k);
					alo[i][k] = mn3(a, b, c);
					ahi[i][k] = mx3(a, b, c);
				}
			}
			have = 1;
		}
		slack = 0x1p-19 * (X->A->absmax + px__amax3(p));
		for (i = 0; i < na; i++) {
			struct mtri3 t;
			px_vec3 q;
			double d2;
			/* the triangle's box (tight beyond its corners), then
			 * its plane and edges (tight beside its face) */
			g2 = 0.0;
			for (k = 0; k < 3; k++) {
				double x = px_v3_comp(p, k), lo = alo[i][k] - x, hi = x - ahi[i][k];
				double g = gap_pos((lo > hi ? lo : hi) - X->slack);
				g2 += g * g;
			}
			if (g2 > X->best2 || (g2 == X->best2 && X->la >= 0))
				continue;
			g2 = tlb_d2(X->A, ia + i, p, slack);
			if (g2 > X->best2 || (g2 == X->best2 && X->la >= 0))
				continue;
			t = px__tri3_get(X->A, ia + i);
			X->tests++;
			d2 = px_tri_closest(p, t.a, t.b, t.c, &q, NULL, NULL, NULL, NULL);
			if (d2 < X->best2 || X->la < 0) {
				X->best2 = d2;
				X->la = (long)(ia + i);
				X->lb = (long)(ib + j);
				X->pa = q;
				X->pb = p;
				X->crossing = 0;
				if (d2 == 0.0)
					return;
			}
		}
	}
}

static void mat_of(px_quat q, double R[3][3])
{
	px_mat3 m = px_quat_to_mat3(q);
	memcpy(R, m.m, sizeof(m.m));
}

/* The context of a traversal of A (mesh model a) against model b:
 * b's frame seen from a's, nothing found yet. */
static void mp_setup(struct mp_ctx *X, const struct px_model *a, const struct px_model *b,
		     double absmax)
{
	px_pose Pa = px_model_pose(a), Pb = px_model_pose(b);
	double RA[3][3], RB[3][3];
	int i, j, k;

	mat_of(Pa.q, RA);
	mat_of(Pb.q, RB);
	memset(X, 0, sizeof(*X));
	/* R = RA^T RB, t = RA^T (tB - tA) */
	for (i = 0; i < 3; i++)
		for (j = 0; j < 3; j++) {
			double s = 0.0;
			for (k = 0; k < 3; k++)
				s += RA[k][i] * RB[k][j];
			X->R[i][j] = s;
			X->Ra[i][j] = fabs(s);
		}
	X->t = px_pose_inverse_transform_vector(Pa, px_v3_sub(Pb.t, Pa.t));
	X->slack = 1e-14 * (absmax + px_v3_norm(X->t));
	X->best2 = INFINITY;
	X->la = X->lb = -1;
}

/* A small A (a robot link, say) bounds B's boxes by its support too
 * (support_lb2): worth its vertices' dot products up to 64 of them. */
static void mp_support(struct mp_ctx *X, const struct mesh *A)
{
	if (A->n_vx <= 64) {
		X->sv = A->vx;
		X->n_sv = A->n_vx;
		X->sc = px_aabb_center(&A->box);
	}
}

/* The traversal itself; returns 0 only if the fixed stack ran out. */
static int mp_descend(struct mp_ctx *X);

/* Run the traversal and fill out (A's frame is pose Pa; B's elements
 * numbered back to input order by orig_b). */
static int mp_finish(struct mp_ctx *X, px_pose Pa, const uint32_t *orig_b,
		     struct px__mesh_pair *out)
{
	int certified = mp_descend(X);
	if (X->la < 0)
		return PX_E_DEGENERATE; /* cannot happen: both have elements */
	out->distance = sqrt(X->best2);
	out->point_a = px_pose_transform_point(Pa, X->pa);
	out->point_b = px_pose_transform_point(Pa, X->pb);
	out->tri_a = (int)X->A->orig[X->la];
	out->tri_b = (int)orig_b[X->lb];
	out->intersecting = X->best2 == 0.0;
	out->nodes = X->nodes;
	out->tri_tests = X->tests;
	out->certified = certified;
	return PX_OK;
}

/* A triangle of M (leaf order) near p (M's frame), cheaply: down the
 * hierarchy by the child box nearest p, then the leaf's triangle whose
 * centroid is nearest. Only a guess. */
static uint32_t greedy_tri(const struct tree *T, const struct mesh *M, px_vec3 p)
{
	uint32_t node = 0, idx = 0, cnt = 0, i, best = 0;
	int depth, j;
	double bd = INFINITY;
	for (depth = 0; depth < 64 && cnt == 0; depth++) {
		const struct node4 *nd = &T->n4[node];
		int pick = -1;
		for (j = 0; j < 4; j++) {
			double d2 = 0.0;
			int k;
			if (nd->idx[j] == EMPTY)
				continue;
			for (k = 0; k < 3; k++) {
				double x = px_v3_comp(p, k), g = nd->lo[k][j] - x;
				g = g > x - nd->hi[k][j] ? g : x - nd->hi[k][j];
				d2 += g > 0.0 ? g * g : 0.0;
			}
			if (pick < 0 || d2 < bd) {
				bd = d2;
				pick = j;
			}
		}
		if (pick < 0)
			return 0;
		idx = nd->idx[pick];
		cnt = nd->cnt[pick];
		node = idx;
		bd = INFINITY;
	}
	for (i = 0; i < cnt && i < LEAF_MAX; i++) {
		const struct mtri3 t = px__tri3_get(M, idx + i);
		double d2 = px_v3_dist2(px_v3_scale(px_v3_add(t.a, px_v3_add(t.b, t.c)), 1.0 / 3.0), p);
		if (i == 0 || d2 < bd) {
			bd = d2;
			best = idx + i;
		}
	}
	return cnt > 0 ? best : 0;
}

/* Triangles la of A and lb of B (leaf order) as the first pair. */
static void mp_first(struct mp_ctx *X, uint32_t la, uint32_t lb)
{
	const struct mtri3 tb = px__tri3_get(X->B, lb);
	px_vec3 V[3] = {to_a(X, tb.a), to_a(X, tb.b), to_a(X, tb.c)};
	pair_test(X, la, V, lb);
}

int px__mesh_pair(const struct px_model *a, const struct px_model *b,
		  int hint_a, int hint_b, struct px__mesh_pair *out)
{
	const struct mesh *A = mesh_of(a), *B = mesh_of(b);
	struct mp_ctx X;
	px_pose Pa;

	if (!A || !B || !out)
		return PX_E_INVAL;
	Pa = px_model_pose(a);
	mp_setup(&X, a, b, A->absmax + B->absmax);
	X.A = A;
	X.B = B;
	X.ta.n4 = A->n4;
	X.ta.box = A->box;
	X.tb.n4 = B->n4;
	X.tb.box = B->box;
	mp_support(&X, A);
	if (hint_a >= 0 && (size_t)hint_a < A->nt && hint_b >= 0 && (size_t)hint_b < B->nt) {
		mp_first(&X, A->leaf_of[hint_a], B->leaf_of[hint_b]);
	} else {
		/* cold: a greedy guess as the first bound, A's triangle
		 * nearest B's centre and B's nearest that one */
		uint32_t la = greedy_tri(&X.ta, A, to_a(&X, px_aabb_center(&B->box)));
		const struct mtri3 t = px__tri3_get(A, la);
		px_vec3 d = px_v3_sub(px_v3_scale(px_v3_add(t.a, px_v3_add(t.b, t.c)), 1.0 / 3.0), X.t);
		d = px_v3(X.R[0][0] * d.x + X.R[1][0] * d.y + X.R[2][0] * d.z,
			  X.R[0][1] * d.x + X.R[1][1] * d.y + X.R[2][1] * d.z,
			  X.R[0][2] * d.x + X.R[1][2] * d.y + X.R[2][2] * d.z);
		mp_first(&X, la, greedy_tri(&X.tb, B, d));
	}
	return mp_finish(&X, Pa, B->orig, out);
}

int px__mesh_cloud_pair(const struct px_model *a, const struct px_model *c, int hint_tri,
			int hint_pt, struct px__mesh_pair *out)
{
	const struct mesh *A = mesh_of(a);
	struct px__cloud_view V;
	struct mp_ctx X;
	px_pose Pa;

	if (!A || !out || !px__cloud_view(c, &V))
		return PX_E_INVAL;
	Pa = px_model_pose(a);
	mp_setup(&X, a, c, A->absmax + V.absmax);
	X.A = A;
	X.ta.n4 = A->n4;
	X.ta.box = A->box;
	X.tb.n4 = V.n4;
	X.tb.box = V.box;
	X.cpt = V.pt;
	mp_support(&X, A);
	if (hint_tri >= 0 && (size_t)hint_tri < A->nt && hint_pt >= 0 && (size_t)hint_pt < V.n) {
		/* last cycle's pair: a tight first bound, so the traversal
		 * prunes almost everything else */
		uint32_t la = A->leaf_of[hint_tri], lb = V.leaf_of[hint_pt];
		const struct mtri3 t = px__tri3_get(A, la);
		px_vec3 p = to_a(&X, V.pt[lb]), q;
		X.best2 = px_tri_closest(p, t.a, t.b, t.c, &q, NULL, NULL, NULL, NULL);
		X.la = (long)la;
		X.lb = (long)lb;
		X.pa = q;
		X.pb = p;
	}
	return mp_finish(&X, Pa, V.orig, out);
}

/* The best pair's direction with B beyond A: does it rule out child
 * (c, h, its elements ic, nc: a leaf when nc > 0) of A (da) or of B,
 * against the fixed side's extreme fx (B's least projection when da,
 * else A's largest; exact when fexact)? A leaf's extreme is its
 * triangles' own, tighter than its box; two exact sides take the tie
 * rule of the triangles. */
static int wax_directed(struct mp_ctx *X, int da, px_vec3 c, px_vec3 h, uint32_t ic,
			uint32_t nc, double fx, int fexact)
{
	double x, p, r, g;
	if (nc > 0) {
		x = leaf_proj(X, !da, ic, nc);
		if (fexact)
			return da ? wax_prunes(X, x, fx) : wax_prunes(X, fx, x);
	} else {
		wax_box(X, !da, c, h, &p, &r);
		x = da ? p + r : p - r;
	}
	g = (da ? fx - x : x - fx) - 2.0 * X->slack;
	return g > 0.0 && g * g > X->best2;
}

static int mp_descend(struct mp_ctx *X)
{
	struct mp_ent st[MP_STACK];
	int sp = 0, j, k, certified = 1;

	st[0].na = st[0].nb = 0;
	st[0].sa = st[0].sb = ROOT_SLOT;
	st[0].lb2 = 0.0;
	sp = 1;
	while (sp > 0 && X->best2 > 0.0) {
		struct mp_ent e = st[--sp];
		px_vec3 ca, ha, cb, hb;
		uint32_t ia, na, ib, nb;
		const struct node4 *nd;
		struct mp_ent kid[4];
		struct bx fixed;
		px_vec3 lv[3 * LEAF_MAX];
		size_t nlv = 0;
		double fp = 0.0, fr = 0.0, fx = 0.0;
		uint32_t fn = 0;
		int nk = 0, da;

		if (e.lb2 > X->best2 || (e.lb2 == X->best2 && X->la >= 0))
			continue;
		if (X->best2 != X->wbest2)
			mp_axis(X);
		ref_get(&X->ta, e.na, e.sa, &ca, &ha, &ia, &na);
		ref_get(&X->tb, e.nb, e.sb, &cb, &hb, &ib, &nb);
		X->nodes++;
		if (na > 0 && nb > 0) {
			if (X->cpt)
				leaf_points(X, ia, na, ib, nb, ca, ha);
			else
				leaf_pair(X, ia, na, ib, nb, ca, ha, cb, hb);
			continue;
		}
		/* split the inner node with the larger box (a leaf cannot be
		 * split) */
		da = na == 0 && (nb > 0 || px_v3_norm2(ha) >= px_v3_norm2(hb));
		nd = da ? &X->ta.n4[ia] : &X->tb.n4[ib];
		if (da)
			bx_of_b(X, cb, hb, &fixed);
		else
			bx_of_a(X, ca, ha, &fixed);
		if (X->wok) {
			/* the fixed side's extreme towards the other: its
			 * triangles' own when it is a leaf */
			uint32_t fi = da ? ib : ia;
			fn = da ? nb : na;
			wax_box(X, da, da ? cb : ca, da ? hb : ha, &fp, &fr);
			fx = fn > 0 ? leaf_proj(X, da, fi, fn) : (da ? fp - fr : fp + fr);
		}
		for (j = 0; j < 4; j++) {
			px_vec3 cc, hc;
			uint32_t ic, nc;
			struct mp_ent c;
			struct bx kb;
			double sw = 0.0;
			if (nd->idx[j] == EMPTY)
				continue;
			ref_get(da ? &X->ta : &X->tb, da ? ia : ib, j, &cc, &hc, &ic, &nc);
			if (X->wok) {
				/* the child on the best pair's direction alone */
				double cp, cr;
				wax_box(X, !da, cc, hc, &cp, &cr);
				sw = wax_gap2(X, fp, fr, cp, cr);
				if (sw > X->best2)
					continue;
				if (wax_directed(X, da, cc, hc, ic, nc, fx, fn > 0))
					continue;
			}
			if (da) {
				bx_of_a(X, cc, hc, &kb);
				c.lb2 = box_lb2(X, &kb, &fixed, sw);
				c.na = ia;
				c.sa = (uint8_t)j;
				c.nb = e.nb;
				c.sb = e.sb;
			} else {
				bx_of_b(X, cc, hc, &kb);
				c.lb2 = box_lb2(X, &fixed, &kb, sw);
				if (X->n_sv && !(c.lb2 > X->best2)) {
					double ls;
					if (na > 0 && !nlv) {
						/* A is a leaf: its own vertices,
						 * once per expansion */
						uint32_t t;
						for (t = 0; t < na && t < LEAF_MAX; t++) {
							const struct mtri3 v = px__tri3_get(X->A, ia + t);
							lv[nlv++] = v.a;
							lv[nlv++] = v.b;
							lv[nlv++] = v.c;
						}
					}
					ls = na > 0 ? support_lb2(X, lv, nlv, ca, cc, hc)
						    : support_lb2(X, X->sv, X->n_sv, X->sc, cc, hc);
					c.lb2 = ls > c.lb2 ? ls : c.lb2;
				}
				c.na = e.na;
				c.sa = e.sa;
				c.nb = ib;
				c.sb = (uint8_t)j;
			}
			if (c.lb2 > X->best2)
				continue;
			/* insertion by bound, farthest first */
			for (k = nk; k > 0 && kid[k - 1].lb2 < c.lb2; k--)
				kid[k] = kid[k - 1];
			kid[k] = c;
			nk++;
		}
		for (k = 0; k < nk; k++) {
			if (sp >= MP_STACK) {
				certified = 0;
				continue;
			}
			st[sp++] = kid[k];
		}
	}
	return certified;
}

/* ---- mesh against any model ------------------------------------------------ */

struct mv_ent {
	uint32_t node;
	uint8_t slot;
	double lb;
};

#define MV_STACK (3 * PX_MESH_MAX_DEPTH + 8)

int px__mesh_vs_model(const struct px_model *m, const struct px_model *o,
		      int (*tri)(void *ctx, const px_vec3 v[3], int index,
				 double *d),
		      void *ctx, int max_queries, double *best, int *best_tri,
		      int *queries)
{
	const struct mesh *M = mesh_of(m);
	struct mv_ent st[MV_STACK];
	struct tree T;
	px_pose P;
	int sp, exact = 1, rc, j, k;

	if (!M || !o || !tri || !best || !best_tri || !queries)
		return PX_E_INVAL;
	T.n4 = M->n4;
	T.box = M->box;
	P = px_model_pose(m);
	st[0].node = 0;
	st[0].slot = ROOT_SLOT;
	st[0].lb = 0.0;
	sp = 1;
	while (sp > 0 && *best > 0.0) {
		struct mv_ent e = st[--sp], kid[4];
		px_vec3 c, h;
		uint32_t idx, cnt;
		const struct node4 *nd;
		int nk = 0;

		/* prune with a relative margin: bounds and distances carry
		 * rounding, and a tie cannot improve the answer */
		if (e.lb >= *best * (1.0 - 1e-12))
			continue;
		ref_get(&T, e.node, e.slot, &c, &h, &idx, &cnt);
		if (cnt > 0) {
			uint32_t i;
			for (i = idx; i < idx + cnt; i++) {
				const struct mtri3 t_ = px__tri3_get(M, i), *t = &t_;
				px_vec3 v[3] = {px_pose_transform_point(P, t->a),
						px_pose_transform_point(P, t->b),
						px_pose_transform_point(P, t->c)};
				double d = INFINITY;
				if ((rc = tri(ctx, v, (int)M->orig[i], &d)) < 0)
					return rc;
				if (!(d < INFINITY))
					exact = 0;
				else if (d < *best) {
					*best = d;
					*best_tri = (int)M->orig[i];
				}
			}
			continue;
		}
		nd = &M->n4[idx];
		for (j = 0; j < 4; j++) {
			px_vec3 cc, hc;
			uint32_t ic, nc;
			struct px_model_result q;
			struct mv_ent ch;
			if (nd->idx[j] == EMPTY)
				continue;
			if (*queries >= max_queries)
				return 0;
			ref_get(&T, idx, j, &cc, &hc, &ic, &nc);
			rc = px_model_query_ex(o, px_pose_transform_point(P, cc), INFINITY, -1,
					       0, &q);
			(*queries)++;
			if (rc < 0)
				return rc;
			if (rc == 0)
				continue; /* nothing of o anywhere: cannot happen */
			/* any point of the box is within |hc| of its centre;
			 * inside a closed o the solid's distance is 0 */
			ch.lb = fmax(q.distance, 0.0) - px_v3_norm(hc);
			if (ch.lb >= *best * (1.0 - 1e-12))
				continue;
			ch.node = idx;
			ch.slot = (uint8_t)j;
			for (k = nk; k > 0 && kid[k - 1].lb < ch.lb; k--)
				kid[k] = kid[k - 1];
			kid[k] = ch;
			nk++;
		}
		for (k = 0; k < nk; k++) {
			if (sp >= MV_STACK) {
				exact = 0;
				continue;
			}
			st[sp++] = kid[k];
		}
	}
	return exact;
}
