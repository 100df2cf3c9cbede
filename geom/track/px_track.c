/*
 * px_track.c - coherent tracking of point-curve critical distances.
 *
 * Notation: for a span with homogeneous Bezier form H = (xw, yw, zw, w) in
 * the local parameter t, g(t; p) = (H - w p) . (H' w - H w') = w^3 (C - p)
 * . C_t has the sign of f' and Bernstein coefficients a_i - p . b_i
 * (px_cpiece.h). Its critical points are the simple roots of g; the
 * transition set is where g has a double root (g = g_t = 0: with w > 0
 * this is f' = f'' = 0, i.e. D = 0 on a critical point, the evolute of
 * Chen-Cohen-Riesenfeld section 5). Because the coefficients are affine
 * in p, three exact facts drive everything:
 *  - over a box of points the range of each coefficient is exact, so a
 *    box where the coefficients of g (or of g_t) keep one sign holds no
 *    event (this builds the per-leaf event boxes at setup);
 *  - along the segment p0 -> p1 each coefficient is affine in the segment
 *    parameter, so one sign at both ends is one sign on the whole segment
 *    (the exact second stage of the detection, replacing the paper's
 *    box-diagonal interpolation by a proof);
 *  - g at a leaf boundary is affine along the segment, so a root crosses
 *    that boundary during the step iff the end values differ in sign.
 * A cusp (C' = 0) is a root of g for every p; leaves ending at a cusp
 * carry g divided by (t) or (1 - t) (exact in Bernstein form), and the
 * cusp itself is a candidate like a C0 corner (the paper's zero-radius
 * arc, section 8). C1 breaks (knots of multiplicity degree - 1, where D
 * jumps) and C0 breaks flag their leaves so a root crossing them is an
 * event: that is where the extended evolute lies (inside the normal
 * planes at the break).
 *
 * Surfaces are tracked by px_strack.c, which hands their edges and creases
 * to this file as curves.
 */
#include "px_track.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "gov_internal.h"
#include "math_internal.h"
#include "track_internal.h"
#include "px_bern.h"

#define TRK_MAXD PX_NURBS_MAX_DEGREE
#define TRK_NG (3 * TRK_MAXD)          /* coefficients of g: degree 3p-1 */
#define TRK_DEPTH 52                    /* root isolation depth */
#define TRK_NEWTON 10
#define TRK_GROUP 8     /* leaves per group of the expiry scan */
/* A Newton step below this fraction of its span is accepted without
 * another evaluation (the root error left is O(step^2), ~1e-9 span). */
#define TRK_QUICK 3e-5
#define TRK_QUICK_ITERS 3 /* Newton evaluations of the quick evolution */
/* A due leaf whose ball still holds the new point with this share of its
 * radius to spare keeps it (the path wound about inside it: an expiry
 * counts the path, not the way from the centre). p0 is in the ball too:
 * every leaf's expiry less the travel is at most its radius less the
 * point's distance from the centre (by induction over the steps), so
 * the ball, convex, holds the segment, and the expiry becomes the travel
 * plus what is left beyond p1, the same bound. */
#define TRK_REKEY 0.1

/* leaf flags */
#define LF_EV0 0x1u   /* start is a break: a root crossing it is an event */
#define LF_EV1 0x2u
#define LF_SB0 0x4u   /* start is a stretch boundary (C0, cusp, open end) */
#define LF_SB1 0x8u
#define LF_CUSP0 0x10u
#define LF_CUSP1 0x20u

/* split-point kinds */
#define K_SMOOTH 0
#define K_C1 1
#define K_C0 2
#define K_CUSP 3

/* Span evaluation in pairs of coordinates where the compiler has generic
 * vectors (GCC, clang); the scalar form elsewhere. */
#if defined(__GNUC__) && !defined(PX_TRACK_NO_VEC)
#define TRK_VEC 1
typedef double trk_v2 __attribute__((vector_size(16)));
#else
#define TRK_VEC 0
#endif

struct span {
	double u0, u1, inv;
	int deg;
	int rat;        /* rational (w not constant 1) */
	double pc[4][TRK_MAXD + 1]; /* power basis in t of x w, y w, z w, w */
	/* the same in tau = u - u0 (derivatives come out in u directly);
	 * zero-padded to degree 3 so low degrees share one unrolled path */
	double pu[4][TRK_MAXD + 1];
#if TRK_VEC
	/* degree <= 3 again, by coefficient with the four coordinates of a
	 * coefficient in two vectors (x w, y w | z w, w) and the derivative
	 * factors applied (value q0..q3; first derivative q1, 2 q2, 3 q3;
	 * second 2 q2, 6 q3: the products the scalar form makes, so the
	 * results are the same to the bit) */
	trk_v2 hv[4][2], hd1[3][2], hd2[2][2];
#endif
};

struct leaf {
	double u0, u1;
	int ent, span;
	int n;          /* degree of the (divided) g */
	size_t off;     /* pool: a[n+1], b[3][n+1], da[n], db[3][n] */
	unsigned flags;
	double tol_g, tol_d;
	px_aabb box;    /* union of its event cells */
	int boxed;
	uint32_t mark;  /* re-solved this update */
	uint32_t tested; /* event test done this update */
	size_t ioff;    /* ipool: 1/|b_i| (n+1), 1/|db_i| (n) */
};

/* An event cell of one leaf: an octree cell of the working volume where
 * the leaf may have an event (setup only). */
struct prim {
	px_aabb box;
	int leaf;
};

struct zero {
	double u;
	int type;       /* +1 min, -1 max */
	int leaf;       /* global leaf index */
	uint32_t id;
	px_vec3 c, d1;  /* point and C' at u (last evaluation) */
	double D;       /* (C - p) . C'' + |C'|^2 there */
	/* laziness: state of the last correction */
	px_vec3 p;      /* query point then */
	double trav;    /* path length travelled then */
	double dist;    /* |c - p| then */
	double until;   /* travel below which it provably stays in its leaf */
	uint32_t ep;    /* update (epoch) of the last correction */
	/* cert_roots: travel below which its share of a rest or hot
	 * certificate holds (leaf certificate and distance margin, as
	 * proven when it was last computed) */
	double hexp;
};

struct ent {
	double u0, u1, len;
	int cyclic;     /* closed with a smooth seam: parameters wrap */
	int first_span, n_spans, first_leaf, n_leaves;
	int n_sb;       /* stretch boundaries (leaf starts with LF_SB0) */
	struct zero *z, *old;
	int nz, nold, cap;
	int first_cand, n_cand;
	int stale;
	int touched;
	int full;       /* every root must be current (no laziness) */
	int moved;      /* a root of it was corrected this update */
	uint32_t hit;   /* epoch in which a leaf of it was re-solved */
	/* entity rest certificate: while the travelled path stays below
	 * rest_until every root of it provably rests (each is alone in its
	 * leaf and rest_until is below each leaf certificate) and none of
	 * its minima can be the closest point, so an update passes the
	 * entity with one comparison; -1 when not certified */
	double rest_until;
	int resting;    /* it rested whole in the last update */
	int nmin;       /* minima among its roots (for the answer counts) */
};

struct cand {
	px_vec3 q;
	double u;
	int ent, kind; /* PX_TRACK_END or PX_TRACK_BREAK */
};

struct px_track {
	struct px_track_opts opts;
	struct px_dist_model *dist;
	int n_ent, n_spans, n_leaves, n_cand, n_boxed, n_prim;
	int n_cusps, n_breaks;
	struct ent *ent;
	struct span *span;
	struct leaf *leaf;
	double *pool;
	size_t pool_len;
	struct cand *cand;
	double *cexp;        /* hot_cert: expiry of each candidate's margin */
	int *hits;           /* scratch: leaves of this update */
	/* lazy event tests: leaf l cannot have an event while the path
	 * length travelled stays below expiry[l] (a safe radius around the
	 * point of its last test); next_due (the smallest expiry) makes the
	 * usual update one comparison, and an update with due leaves scans
	 * the contiguous expiries once (cheaper than heap sifts as soon as
	 * two or three leaves are due) */
	double *expiry;
	/* the ball each expiry is of (centre, radius): a due leaf whose
	 * ball still holds the new point well inside keeps it, without a
	 * test (collect_events()) */
	px_vec3 *ectr;
	double *erad;
	double *gdue;        /* smallest expiry of each group of TRK_GROUP */
	double next_due;
	double travel;
	int heap_ok;         /* expiries valid */
	double *ipool;
	px_aabb work;
	double scale;        /* model diagonal */
	px_vec3 p;
	int init;
	uint32_t epoch, next_id, best_id;
	int fault;           /* test hook: px__track_set_fault() */
	int n_crit_cap;      /* critical points all entities can hold */
	int *rmin;           /* resting minima of this update: entity, index */
	int n_rmin;
	double best_now;     /* wake_minima: distance to a real curve point */
	/* hot certificate (armed by hot_arm after a tracked update): while
	 * the travelled path stays below hot_until and no leaf has an event,
	 * the answer is root hot_z of entity hot_ent, every other root rests
	 * in its leaf and cannot be the closest point, so an update evolves
	 * that one root and nothing else; hot_ent -1 when not armed */
	int hot_ent, hot_z;
	double hot_until, hot_other;
	int hot_nc, hot_nm;
	uint64_t hot_rested, hot_rest_ent; /* stats per hot update */
	int ans_z;           /* answer(): index of the answering root, -1 */
	int p_in;            /* p inside the working volume */
	int ans_c;           /* answer(): answering candidate, -1 */
	int hot_c;           /* hot: answering candidate (hot_z -1), -1 */
	struct px_track_stats st;
	size_t bytes;
	/* cold switch (gov_internal.h) and the last answer, whose
	 * continuation tells a cold answer's jumped */
	struct px_gov gov;
	px_vec3 cur_d1;      /* continued(): C' and D at the new answer */
	double cur_D;
	struct {
		int ent, fixed; /* fixed: an end, break or cusp */
		double u;
		px_vec3 point, p; /* the closest point, the query point */
		px_vec3 d1;       /* C' there (D > 0: known) */
		double D;
	} prev;
};

/* ------------------------------------------------------------------ */
/* evaluation                                                          */

/* C, C', C'' at u from the span's power-basis table: for degree <= 3 one
 * unrolled Horner per coordinate (a few dozen flops), homogeneous
 * quotient rule only for rational spans. */
static inline __attribute__((always_inline)) void span_eval(const struct span *s, double u, px_vec3 *c,
			     px_vec3 *d1, px_vec3 *d2)
{
	double x = u - s->u0, h[4][3];
	int k, j, p = s->deg, nk = s->rat ? 4 : 3;

#if TRK_VEC
	if (p <= 3) {
		trk_v2 X = {x, x}, a0, a1, b0, b1, c0, c1;
		a0 = ((s->hv[3][0] * X + s->hv[2][0]) * X + s->hv[1][0]) * X +
		     s->hv[0][0];
		a1 = ((s->hv[3][1] * X + s->hv[2][1]) * X + s->hv[1][1]) * X +
		     s->hv[0][1];
		b0 = (s->hd1[2][0] * X + s->hd1[1][0]) * X + s->hd1[0][0];
		b1 = (s->hd1[2][1] * X + s->hd1[1][1]) * X + s->hd1[0][1];
		c0 = s->hd2[1][0] * X + s->hd2[0][0];
		c1 = s->hd2[1][1] * X + s->hd2[0][1];
		if (!s->rat) {
			*c = px_v3(a0[0], a0[1], a1[0]);
			*d1 = px_v3(b0[0], b0[1], b1[0]);
			*d2 = px_v3(c0[0], c0[1], c1[0]);
			return;
		}
		h[0][0] = a0[0], h[1][0] = a0[1], h[2][0] = a1[0], h[3][0] = a1[1];
		h[0][1] = b0[0], h[1][1] = b0[1], h[2][1] = b1[0], h[3][1] = b1[1];
		h[0][2] = c0[0], h[1][2] = c0[1], h[2][2] = c1[0], h[3][2] = c1[1];
	} else
#endif
	if (p <= 3) {
		for (k = 0; k < nk; k++) {
			const double *q = s->pu[k];
			h[k][0] = ((q[3] * x + q[2]) * x + q[1]) * x + q[0];
			h[k][1] = (3.0 * q[3] * x + 2.0 * q[2]) * x + q[1];
			h[k][2] = 6.0 * q[3] * x + 2.0 * q[2];
		}
	} else {
		for (k = 0; k < nk; k++) {
			double v = s->pu[k][p], v1 = 0.0, v2 = 0.0;
			for (j = p - 1; j >= 0; j--) {
				v2 = v2 * x + 2.0 * v1;
				v1 = v1 * x + v;
				v = v * x + s->pu[k][j];
			}
			h[k][0] = v;
			h[k][1] = v1;
			h[k][2] = v2;
		}
	}
	if (!s->rat) {
		*c = px_v3(h[0][0], h[1][0], h[2][0]);
		*d1 = px_v3(h[0][1], h[1][1], h[2][1]);
		*d2 = px_v3(h[0][2], h[1][2], h[2][2]);
		return;
	}
	{
		double w = h[3][0], w1 = h[3][1], w2 = h[3][2], iw = 1.0 / w;
		px_vec3 C = px_v3(h[0][0] * iw, h[1][0] * iw, h[2][0] * iw);
		px_vec3 C1 = px_v3((h[0][1] - w1 * C.x) * iw,
				   (h[1][1] - w1 * C.y) * iw,
				   (h[2][1] - w1 * C.z) * iw);
		*c = C;
		*d1 = C1;
		*d2 = px_v3((h[0][2] - 2.0 * w1 * C1.x - w2 * C.x) * iw,
			    (h[1][2] - 2.0 * w1 * C1.y - w2 * C.y) * iw,
			    (h[2][2] - 2.0 * w1 * C1.z - w2 * C.z) * iw);
	}
}

/* Span of entity e holding u (clamped to the entity's spans). */
static const struct span *find_span(const struct px_track *t,
				    const struct ent *e, double u)
{
	int lo = e->first_span, hi = e->first_span + e->n_spans - 1;
	while (lo < hi) {
		int mid = (lo + hi + 1) / 2;
		if (t->span[mid].u0 <= u)
			lo = mid;
		else
			hi = mid - 1;
	}
	return &t->span[lo];
}

static inline const double *leaf_a(const struct px_track *t,
				   const struct leaf *l)
{
	return t->pool + l->off;
}

/* g coefficient i of a leaf at p. */
static inline double gco(const double *a, int n, int i, px_vec3 p)
{
	const double *b = a + n + 1;
	return a[i] - (p.x * b[i] + p.y * b[n + 1 + i] +
		       p.z * b[2 * (n + 1) + i]);
}

/* ------------------------------------------------------------------ */
/* root isolation on one leaf                                          */

/* Bernstein polynomial and its derivative at x by de Casteljau (exact
 * enough near the ends, no library call): the last level's two values
 * give f = (1-x) b0 + x b1 and f' = n (b1 - b0). */
static inline double bern_val_d(const double *c, int n, double x, double *d)
{
	double b[TRK_NG + 1], y = 1.0 - x;
	int i, k;
	if (n == 0) {
		*d = 0.0;
		return c[0];
	}
	for (i = 0; i <= n; i++)
		b[i] = c[i];
	for (k = n; k > 1; k--)
		for (i = 0; i < k; i++)
			b[i] = y * b[i] + x * b[i + 1];
	*d = n * (b[1] - b[0]);
	return y * b[0] + x * b[1];
}

static double bern_root(const double *c, int n)
{
	double lo = 0.0, hi = 1.0, x = 0.5, flo = c[0], fe;
	int k, i;
	/* start where the control polygon crosses zero (it converges to
	 * the curve quadratically under subdivision) */
	for (i = 0; i < n; i++)
		if ((c[i] < 0.0) != (c[i + 1] < 0.0)) {
			x = (i + c[i] / (c[i] - c[i + 1])) / n;
			break;
		}
	if (!(x > 0.0 && x < 1.0))
		x = 0.5;
	/* rounding level of an evaluation: below it f carries no sign
	 * information and the iterate is as good as it gets */
	{
		double cm = 0.0;
		for (i = 0; i <= n; i++)
			if (fabs(c[i]) > cm)
				cm = fabs(c[i]);
		fe = 4.0 * (n + 1) * 2.2e-16 * cm;
	}
	for (k = 0; k < 100; k++) {
		double d, f = bern_val_d(c, n, x, &d), nx;
		if (fabs(f) <= fe)
			return x;
		if ((f < 0.0) == (flo < 0.0)) {
			lo = x;
			flo = f;
		} else {
			hi = x;
		}
		nx = (d != 0.0) ? x - f / d : 0.5 * (lo + hi);
		if (!(nx > lo && nx < hi))
			nx = 0.5 * (lo + hi);
		/* a Newton step of 1e-14 leaves an error far below rounding;
		 * smaller steps are rounding noise (waiting for an exact 0
		 * step can take dozens of bisections) */
		if (fabs(nx - x) <= 1e-14 || hi - lo <= 1e-16)
			return nx;
		x = nx;
	}
	return x;
}

/* Divide a Bernstein polynomial of degree n with a root at t = 0 (end 0)
 * or t = 1 (end 1) by t or (1 - t): degree n - 1. */
static void bern_divide(double *c, int n, int end)
{
	int i;
	if (end == 0) {
		for (i = 1; i <= n; i++)
			c[i - 1] = c[i] * n / i;
	} else {
		for (i = 0; i < n; i++)
			c[i] = c[i] * n / (n - i);
	}
}

/* Halves of a Bernstein polynomial of degree n: c becomes [0, 1/2], r
 * gets [1/2, 1] (de Casteljau at the middle, in place). */
static inline void bern_halves(double *c, int n, double *r)
{
	double w[TRK_NG + 1];
	int i, k;
	r[n] = c[n];
	for (i = 0; i <= n; i++)
		w[i] = c[i];
	for (k = 1; k <= n; k++) {
		for (i = 0; i <= n - k; i++)
			w[i] = 0.5 * (w[i] + w[i + 1]);
		c[k] = w[0];
		r[n - k] = w[n - k];
	}
}

struct iso_item {
	double c[TRK_NG + 1];
	double min, max;
	int depth;
};

/*
 * All roots of the leaf's g at p, in increasing order, into u/type (cap).
 * Returns the count, PX_E_NOSPC (more than cap) or PX_E_RANGE (a cluster
 * not separated at the depth bound: not certified).
 */
static int leaf_roots(const struct px_track *t, const struct leaf *l,
		      px_vec3 p, double *u, int *type, int cap)
{
	struct iso_item st[TRK_DEPTH + 3];
	const double *a = leaf_a(t, l);
	int n = l->n, sp = 1, nr = 0, i;

	for (i = 0; i <= n; i++)
		st[0].c[i] = gco(a, n, i, p);
	/* A root on a leaf boundary (the point on a normal plane there, e.g.
	 * exactly on the curve at a knot) belongs to the leaf it starts:
	 * claimed here unless the start is a stretch boundary (a candidate
	 * already), and divided out of both neighbours so the sign counts
	 * below stay exact. */
	if (n >= 1 && fabs(st[0].c[0]) <= l->tol_g) {
		if (!(l->flags & LF_SB0)) {
			for (i = 1; i <= n; i++)
				if (fabs(st[0].c[i]) > l->tol_g)
					break;
			if (i <= n) {
				if (nr >= cap)
					return PX_E_NOSPC;
				u[nr] = l->u0;
				type[nr] = st[0].c[i] > 0.0 ? 1 : -1;
				nr++;
			}
		}
		st[0].c[0] = 0.0;
		bern_divide(st[0].c, n, 0);
		n--;
	}
	if (n >= 1 && fabs(st[0].c[n]) <= l->tol_g) {
		st[0].c[n] = 0.0;
		bern_divide(st[0].c, n, 1);
		n--;
	}
	st[0].min = 0.0;
	st[0].max = 1.0;
	st[0].depth = 0;
	while (sp > 0) {
		struct iso_item it = st[--sp];
		int v = px_bern_sign_changes(it.c, n, 0.0);
		if (v == 0)
			continue;
		if (v == 1) {
			double x = bern_root(it.c, n), first = 0.0;
			for (i = 0; i <= n && first == 0.0; i++)
				first = it.c[i];
			if (nr >= cap)
				return PX_E_NOSPC;
			u[nr] = l->u0 + (l->u1 - l->u0) *
					(it.min + x * (it.max - it.min));
			type[nr] = first < 0.0 ? 1 : -1;
			nr++;
			continue;
		}
		if (it.depth >= TRK_DEPTH)
			return PX_E_RANGE;
		{
			/* right half below the left one: roots come out sorted */
			struct iso_item *r = &st[sp], *lf = &st[sp + 1];
			double mid = 0.5 * (it.min + it.max);
			memcpy(lf->c, it.c, (size_t)(n + 1) * sizeof(double));
			bern_halves(lf->c, n, r->c);
			r->min = mid;
			r->max = it.max;
			lf->min = it.min;
			lf->max = mid;
			r->depth = lf->depth = it.depth + 1;
			sp += 2;
		}
	}
	return nr;
}

/* ------------------------------------------------------------------ */
/* entity state                                                        */

/* Travel (path length) the point may still cover from p before a root
 * of leaf l can leave it through an end: the end values of g are affine
 * in p, so none changes sign within |value| / |p-gradient| (0 when an
 * end value is too close to zero to tell). With no event inside the leaf
 * (it is not re-solved) its roots keep their number and stay in it. */
static double leaf_end_radius(const struct px_track *t, const struct leaf *l,
			      px_vec3 p)
{
	const double *a = leaf_a(t, l), *ib = t->ipool + l->ioff;
	double v0 = fabs(gco(a, l->n, 0, p)) - l->tol_g;
	if (t->fault & 8)
		return INFINITY;
	double v1 = fabs(gco(a, l->n, l->n, p)) - l->tol_g;
	if (!(v0 > 0.0) || !(v1 > 0.0))
		return 0.0;
	v0 *= ib[0];
	v1 *= ib[l->n];
	return v0 < v1 ? v0 : v1;
}

/* Record a correction of z at p (now). */
static void zero_stamp(const struct px_track *t, struct zero *z, px_vec3 p)
{
	z->p = p;
	z->trav = t->travel;
	z->dist = px_v3_dist(z->c, p);
	z->ep = t->epoch;
	z->until = t->opts.lazy
			   ? t->travel + leaf_end_radius(t, &t->leaf[z->leaf], p) *
						 (1.0 - 1e-9)
			   : -1.0;
}

static void zero_eval(const struct px_track *t, const struct ent *e,
		      struct zero *z, px_vec3 p)
{
	px_vec3 c, d1, d2;
	span_eval(find_span(t, e, z->u), z->u, &c, &d1, &d2);
	z->c = c;
	z->d1 = d1;
	z->D = px_v3_dot(px_v3_sub(c, p), d2) + px_v3_dot(d1, d1);
	zero_stamp(t, z, p);
}

static int cmp_zero(const struct zero *a, const struct zero *b)
{
	return a->u > b->u;
}

static void sort_zeros(struct ent *e)
{
	int i, j;
	/* usually still sorted: one pass of comparisons, no copies */
	for (i = 1; i < e->nz; i++)
		if (e->z[i - 1].u > e->z[i].u)
			break;
	for (; i < e->nz; i++) {
		struct zero z = e->z[i];
		for (j = i; j > 0 && cmp_zero(&e->z[j - 1], &z); j--)
			e->z[j] = e->z[j - 1];
		e->z[j] = z;
	}
}

/* Give a new root the id of the nearest dropped root of the same type. */
static uint32_t inherit_id(struct px_track *t, struct ent *e, double u,
			   int type)
{
	int i, best = -1;
	double bd = 0.05 * e->len;
	for (i = 0; i < e->nold; i++) {
		double d;
		if (e->old[i].type != type || e->old[i].id == 0)
			continue;
		d = fabs(e->old[i].u - u);
		if (e->cyclic)
			d = fmin(d, e->len - d);
		if (d <= bd) {
			bd = d;
			best = i;
		}
	}
	if (best >= 0) {
		uint32_t id = e->old[best].id;
		e->old[best].id = 0;
		return id;
	}
	if (++t->next_id >= 0x7fffffffu)
		t->next_id = 1;
	return t->next_id;
}

/* Append the roots of leaf li at p. Returns the count or an error. */
static int add_leaf_roots(struct px_track *t, struct ent *e, int li, px_vec3 p)
{
	double u[TRK_NG + 1];
	int ty[TRK_NG + 1], n, i;
	n = leaf_roots(t, &t->leaf[li], p, u, ty, TRK_NG + 1);
	if (n < 0)
		return n;
	if (e->nz + n > e->cap)
		return PX_E_NOSPC;
	for (i = 0; i < n; i++) {
		struct zero *z = &e->z[e->nz++];
		z->u = u[i];
		z->type = ty[i];
		z->leaf = li;
		z->id = inherit_id(t, e, u[i], ty[i]);
		zero_eval(t, e, z, p);
	}
	return n;
}

/* Sign of g at the start (side 0) or end (side 1) of leaf li at p, with
 * 0 for "too close to tell". */
static int leaf_end_sign(const struct px_track *t, int li, int side, px_vec3 p)
{
	const struct leaf *l = &t->leaf[li];
	double v = gco(leaf_a(t, l), l->n, side ? l->n : 0, p);
	if (fabs(v) <= l->tol_g)
		return 0;
	return v > 0.0 ? 1 : -1;
}

static int ent_dups(const struct ent *e)
{
	int i;
	double dtol = 1e-11 * e->len;
	for (i = 1; i < e->nz; i++)
		if (e->z[i].u - e->z[i - 1].u <= dtol)
			return 1;
	if (e->cyclic && e->nz >= 2 &&
	    e->z[0].u + e->len - e->z[e->nz - 1].u <= dtol)
		return 1;
	return 0;
}

/*
 * Structure check at p: sorted, no duplicates, types alternate inside
 * every C1 stretch and agree with the sign of f' at the stretch ends.
 * Returns 0 when consistent.
 */
static int ent_check(const struct px_track *t, const struct ent *e, px_vec3 p)
{
	int i, j, k0 = -1, zi, n = e->n_leaves;

	if (ent_dups(e))
		return 1;
	if (e->n_sb == 0) {
		/* one closed stretch: even count, alternating cyclically */
		if (e->nz & 1)
			return 1;
		for (i = 0; i < e->nz; i++)
			if (e->z[i].type == e->z[(i + 1) % e->nz].type)
				return 1;
		return 0;
	}
	for (j = 0; j < n; j++)
		if (t->leaf[e->first_leaf + j].flags & LF_SB0) {
			k0 = j;
			break;
		}
	if (k0 < 0)
		return 1;
	/* first zero at or after leaf k0 (cyclic order) */
	zi = 0;
	while (zi < e->nz && e->z[zi].leaf - e->first_leaf < k0)
		zi++;
	{
		int expect = 0, seen = 0;
		for (j = 0; j < n; j++) {
			int lj = (k0 + j) % n, li = e->first_leaf + lj;
			const struct leaf *l = &t->leaf[li];
			if (l->flags & LF_SB0) {
				int s = leaf_end_sign(t, li, 0, p);
				expect = s < 0 ? 1 : (s > 0 ? -1 : 0);
			}
			while (seen < e->nz) {
				const struct zero *z = &e->z[zi % e->nz];
				if (z->leaf != li)
					break;
				if (expect && z->type != expect)
					return 1;
				expect = -z->type;
				zi++;
				seen++;
			}
			if (l->flags & LF_SB1) {
				int s = leaf_end_sign(t, li, 1, p);
				/* after a minimum g > 0, after a maximum g < 0 */
				if (s && expect && s != -expect)
					return 1;
			}
		}
		if (seen != e->nz)
			return 1;
	}
	return 0;
}

/* Rebuild one entity at p. Returns 0, PX_E_NOSPC or PX_E_RANGE. */
static int ent_reinit(struct px_track *t, struct ent *e, px_vec3 p)
{
	int i, rc;
	e->rest_until = -1.0;
	e->resting = 0;
	memcpy(e->old, e->z, (size_t)e->nz * sizeof(*e->z));
	e->nold = e->nz;
	e->nz = 0;
	for (i = 0; i < e->n_leaves; i++) {
		rc = add_leaf_roots(t, e, e->first_leaf + i, p);
		if (rc < 0) {
			e->nz = 0;
			e->stale = 1;
			return rc;
		}
	}
	e->stale = 0;
	return 0;
}

/*
 * Newton on (C - p) . C' = 0 with p fixed from the unwrapped parameter
 * *unw (updated); the root must keep its type. Returns 0 or 1.
 */
static int newton(const struct px_track *t, const struct ent *e, int type,
		  double *unw, px_vec3 p, double lim, px_vec3 *c, px_vec3 *d1,
		  double *D, double *u_out, int hint)
{
	double u, step, tol = 1e-8 * e->len, quick = TRK_QUICK;
	int k;
	px_vec3 d2;
	for (k = 0;; k++) {
		double f1;
		const struct span *sp = hint >= 0 ? &t->span[hint] : NULL;
		u = *unw;
		if (e->cyclic) {
			if (u < e->u0 || u >= e->u1) {
				u = fmod(u - e->u0, e->len);
				if (u < 0)
					u += e->len;
				u += e->u0;
			}
		} else if (u < e->u0 || u > e->u1) {
			/* an iterate beyond an open end: come back to it */
			u = u < e->u0 ? e->u0 : e->u1;
			*unw = u;
		}
		if (!sp || u < sp->u0 || u > sp->u1)
			sp = find_span(t, e, u);
		span_eval(sp, u, c, d1, &d2);
		f1 = px_v3_dot(px_v3_sub(*c, p), *d1);
		*D = px_v3_dot(px_v3_sub(*c, p), d2) + px_v3_dot(*d1, *d1);
		if (!(*D != 0.0))
			return 1;
		step = -f1 / *D;
		if (!isfinite(step))
			return 1;
		if (fabs(step) <= tol)
			break;
		if (fabs(step) <= quick * (sp->u1 - sp->u0) &&
		    u + step >= sp->u0 && u + step <= sp->u1) {
			/* quadratic convergence: the root error after this
			 * step is O(step^2) (below 1e-9 of the span), so the
			 * point is moved by its Taylor expansion instead of
			 * another evaluation: second order in C (error
			 * O(step^3), far below the answer tolerance), first
			 * order in C' (only the next predictor uses it) */
			px_vec3 pc;
			*unw += step;
			u += step;
			*c = px_v3_add(*c, px_v3_scale(px_v3_add(*d1,
					px_v3_scale(d2, 0.5 * step)), step));
			*d1 = px_v3_add(*d1, px_v3_scale(d2, step));
			pc = px_v3_sub(*c, p);
			*D = px_v3_dot(pc, d2) + px_v3_dot(*d1, *d1);
			break;
		}
		if (k >= TRK_NEWTON)
			return 1;
		if (fabs(step) > lim)
			step = step > 0 ? lim : -lim;
		*unw += step;
	}
	if ((*D > 0.0 ? 1 : -1) != type)
		return 1;
	*u_out = u;
	return 0;
}

/*
 * The usual evolution of a root, in a few dozen flops: from the predicted
 * parameter ua, up to iters Newton steps with p fixed (one evaluation
 * each, from the span table) until one is small enough to be accepted,
 * every iterate inside the given leaf, same type at the end. Writes
 * nothing into z. Returns 0 (accepted: *u, *c, *d1, *D), 1 (not
 * accepted: *ua is the last iterate, inside the leaf, and *st its finite
 * Newton step) or 2 (nothing usable: ua outside the leaf, a non-finite
 * step or the wrong type).
 */
static inline __attribute__((always_inline)) int
quick_evolve(const struct px_track *t, const struct zero *z, int leaf,
	     double ua, px_vec3 p, int iters, px_vec3 *c, px_vec3 *d1,
	     double *D, double *u, double *ua_out, double *st_out)
{
	const struct leaf *l = &t->leaf[leaf];
	const struct span *sp = &t->span[l->span];
	double f1, st, Dn, quick = TRK_QUICK * (sp->u1 - sp->u0);
	px_vec3 d2, pc, cc, dd;
	int k;
	*ua_out = ua;
	if (!(ua >= l->u0 && ua <= l->u1))
		return 2;
	for (k = 1;; k++) {
		span_eval(sp, ua, &cc, &dd, &d2);
		pc = px_v3_sub(cc, p);
		f1 = px_v3_dot(pc, dd);
		Dn = px_v3_dot(pc, d2) + px_v3_dot(dd, dd);
		st = -f1 / Dn;
		if (fabs(st) <= quick && ua + st >= l->u0 && ua + st <= l->u1)
			break;
		*ua_out = ua;
		*st_out = st;
		if (!isfinite(st))
			return 2;
		if (k >= iters || !(ua + st >= l->u0 && ua + st <= l->u1))
			return 1;
		ua += st;
	}
	/* quadratic convergence: the root error after this step is
	 * O(st^2) (below 1e-9 of the span), so the point is moved by its
	 * Taylor expansion instead of another evaluation: second order in
	 * C (error O(st^3), far below the answer tolerance), first order in
	 * C' (only the next predictor uses it) */
	cc = px_v3_add(cc, px_v3_scale(px_v3_add(dd, px_v3_scale(d2, 0.5 * st)),
				       st));
	dd = px_v3_add(dd, px_v3_scale(d2, st));
	pc = px_v3_sub(cc, p);
	Dn = px_v3_dot(pc, d2) + px_v3_dot(dd, dd);
	if ((Dn > 0.0 ? 1 : -1) != z->type)
		return 2;
	*c = cc;
	*d1 = dd;
	*D = Dn;
	*u = ua + st;
	return 0;
}

/* A corrected root: its new state at p, stamped. */
static void zero_commit(struct px_track *t, struct ent *e, struct zero *z,
			double u, int leaf, px_vec3 c, px_vec3 d1, double D,
			px_vec3 p)
{
	z->u = u;
	z->leaf = leaf;
	z->c = c;
	z->d1 = d1;
	z->D = D;
	zero_stamp(t, z, p);
	e->moved = 1;
}

/*
 * Evolve one root from p0 to p0 + dp: predictor (dp . C') / D (Eq. 6),
 * then Newton with the point held fixed. When that fails (a long step
 * near a fold), the same in four sub-steps along the segment. Then the
 * leaf walk: no stretch boundary may be crossed and no re-solved leaf
 * entered. Returns 0, or 1 for an anomaly.
 */
static int evolve(struct px_track *t, struct ent *e, struct zero *z,
		  px_vec3 p0, px_vec3 dp, px_vec3 p)
{
	double lim, unw, u = z->u, step, D = 0.0, next = 0.0;
	int li, guard, k, ok, have = 0;
	px_vec3 c, d1;

	{
		/* the usual case, in a few dozen flops */
		double ua;
		int q = quick_evolve(t, z, z->leaf,
				     z->u + px_v3_dot(dp, z->d1) / z->D, p,
				     TRK_QUICK_ITERS, &c, &d1, &D, &u, &ua,
				     &next);
		if (q == 0) {
			zero_commit(t, e, z, u, z->leaf, c, d1, D, p);
			return 0;
		}
		if (q == 1) {
			/* the general iteration goes on from this Newton
			 * step instead of evaluating ua again */
			have = 1;
			lim = e->len / (e->n_leaves > 0 ? e->n_leaves : 1);
			if (fabs(next) > lim)
				next = next > 0 ? lim : -lim;
			next += ua;
		}
	}
	lim = e->len / (e->n_leaves > 0 ? e->n_leaves : 1);
	step = (z->D != 0.0) ? px_v3_dot(dp, z->d1) / z->D : 0.0;
	if (!isfinite(step))
		step = 0.0;
	if (fabs(step) > lim)
		step = step > 0 ? lim : -lim;
	unw = have ? next : z->u + step;
	ok = !newton(t, e, z->type, &unw, p, lim, &c, &d1, &D, &u,
		     t->leaf[z->leaf].span);
	if (!ok) {
		/* continuation in sub-steps */
		px_vec3 sd = px_v3_scale(dp, 0.25), dk = z->d1;
		double Dk = z->D;
		unw = z->u;
		for (k = 1; k <= 4; k++) {
			px_vec3 pk = k == 4 ? p : px_v3_add(p0, px_v3_scale(dp, 0.25 * k));
			step = (Dk != 0.0) ? px_v3_dot(sd, dk) / Dk : 0.0;
			if (!isfinite(step))
				step = 0.0;
			if (fabs(step) > lim)
				step = step > 0 ? lim : -lim;
			unw += step;
			if (newton(t, e, z->type, &unw, pk, lim, &c, &d1, &D, &u,
				   t->leaf[z->leaf].span))
				return 1;
			dk = d1;
			Dk = D;
		}
	}
	li = z->leaf - e->first_leaf;
	{
		double off = 0.0; /* unwrapped offset of the leaf walk */
		for (guard = 0; guard <= e->n_leaves + 1; guard++) {
			const struct leaf *l = &t->leaf[e->first_leaf + li];
			if (unw >= l->u0 + off && unw <= l->u1 + off)
				break;
			if (unw > l->u1 + off) {
				if (l->flags & LF_SB1)
					return 1;
				if (++li == e->n_leaves) {
					if (!e->cyclic)
						return 1;
					li = 0;
					off += e->len;
				}
			} else {
				if (l->flags & LF_SB0)
					return 1;
				if (--li < 0) {
					if (!e->cyclic)
						return 1;
					li = e->n_leaves - 1;
					off -= e->len;
				}
			}
		}
		if (guard > e->n_leaves + 1)
			return 1;
	}
	li += e->first_leaf;
	if (t->leaf[li].mark == t->epoch)
		return 1;
	zero_commit(t, e, z, u, li, c, d1, D, p);
	return 0;
}

/* ------------------------------------------------------------------ */
/* event detection                                                     */

/* Coefficients a - p.b (count m, stride m) sign-definite along p0 -> p1. */
static int definite_seg(const double *a, int m, px_vec3 p0, px_vec3 p1,
			double tol)
{
	const double *bx = a + m, *by = bx + m, *bz = by + m;
	int i, pos = 0, neg = 0;
	for (i = 0; i < m; i++) {
		double v0 = a[i] - (p0.x * bx[i] + p0.y * by[i] + p0.z * bz[i]);
		double v1 = a[i] - (p1.x * bx[i] + p1.y * by[i] + p1.z * bz[i]);
		if (v0 > tol && v1 > tol)
			pos++;
		else if (v0 < -tol && v1 < -tol)
			neg++;
		else
			return 0;
		if (pos && neg)
			return 0;
	}
	return 1;
}

/* r, lowered to the radius within which g keeps its sign at each break
 * end of leaf l around p (a root crossing a break is an event). */
static double break_end_radius(const struct px_track *t, const struct leaf *l,
			       px_vec3 p, double r)
{
	const double *a = leaf_a(t, l), *ib = t->ipool + l->ioff;
	int n = l->n, i;
	for (i = 0; i < 2 && r > 0.0; i++) {
		double v;
		int e = i ? n : 0;
		if (!(l->flags & (i ? LF_EV1 : LF_EV0)))
			continue;
		v = fabs(gco(a, n, e, p));
		v = v > l->tol_g ? (v - l->tol_g) * ib[e] : 0.0;
		if (v < r)
			r = v;
	}
	return r;
}

/* Signs of c0[0..m-1] and c1[0..m-1] all one, beyond tol. */
static int definite2(const double *c0, const double *c1, int m, double tol)
{
	int i, pos = 0, neg = 0;
	for (i = 0; i < m; i++) {
		if (c0[i] > tol && c1[i] > tol)
			pos = 1;
		else if (c0[i] < -tol && c1[i] < -tol)
			neg = 1;
		else
			return 0;
	}
	return !(pos && neg);
}

#define TRK_FINE_DEPTH 3
/*
 * The leaf's proof by pieces, where the whole-leaf proof failed: an event
 * is a double root, g = dg/ds = 0 at one (s, point), so the leaf is free
 * of events along p0 -> p1 when each piece of it in s is free of them:
 * g of one sign there (no root) or dg/ds of one sign (one simple root at
 * most). Both are Bernstein polynomials in s with coefficients affine in
 * the point, so a piece's coefficients taken at p0 and at p1 (split the
 * same way: subdivision is linear) of one sign prove it for the whole
 * segment. Halves down to TRK_FINE_DEPTH levels; a piece still unproven
 * there counts as an event (the leaf is solved again, as before).
 * Saves most of the root isolations that the whole-leaf bound asked for
 * without a transition.
 */
static int leaf_event_fine(const double *a, const double *ib, int n,
			   px_vec3 p0, px_vec3 p1, double tol_g, double tol_d,
			   double *rad)
{
	struct piece {
		double g0[TRK_NG + 1], g1[TRK_NG + 1], d0[TRK_NG], d1[TRK_NG];
		int depth;
	} st[TRK_FINE_DEPTH + 2];
	const double *da = a + 4 * (n + 1);
	double ig = INFINITY, id = INFINITY, r1 = INFINITY;
	int sp = 1, i;
	/* a piece's coefficients are convex combinations of the leaf's, so
	 * their gradients in the point are no longer than the longest of the
	 * leaf's: 1 / max |b| bounds how fast any of them changes */
	for (i = 0; i <= n; i++)
		ig = ib[i] < ig ? ib[i] : ig;
	for (i = 0; i < n; i++)
		id = ib[n + 1 + i] < id ? ib[n + 1 + i] : id;
	for (i = 0; i <= n; i++) {
		st[0].g0[i] = gco(a, n, i, p0);
		st[0].g1[i] = gco(a, n, i, p1);
	}
	for (i = 0; i < n; i++) {
		st[0].d0[i] = gco(da, n - 1, i, p0);
		st[0].d1[i] = gco(da, n - 1, i, p1);
	}
	st[0].depth = 0;
	*rad = 0.0;
	while (sp > 0) {
		struct piece *q = &st[sp - 1], *r;
		int pg = definite2(q->g0, q->g1, n + 1, tol_g);
		int pd = definite2(q->d0, q->d1, n, tol_d);
		if (pg || pd) {
			/* the piece's radius at p1: the exclusion that holds
			 * (the larger when both do) */
			double rg = 0.0, rd = 0.0, m = INFINITY;
			if (pg) {
				for (i = 0; i <= n; i++)
					m = fabs(q->g1[i]) < m ? fabs(q->g1[i]) : m;
				rg = (m - tol_g) * ig;
			}
			if (pd) {
				m = INFINITY;
				for (i = 0; i < n; i++)
					m = fabs(q->d1[i]) < m ? fabs(q->d1[i]) : m;
				rd = (m - tol_d) * id;
			}
			m = rg > rd ? rg : rd;
			if (m < r1)
				r1 = m;
			sp--;
			continue;
		}
		if (q->depth >= TRK_FINE_DEPTH)
			return 1;
		/* q becomes the left half, the right half goes above it */
		r = &st[sp++];
		bern_halves(q->g0, n, r->g0);
		bern_halves(q->g1, n, r->g1);
		bern_halves(q->d0, n - 1, r->d0);
		bern_halves(q->d1, n - 1, r->d1);
		r->depth = ++q->depth;
	}
	*rad = r1 > 0.0 ? r1 : 0.0;
	return 0;
}

/* May leaf l hold an event while the point runs p0 -> p1? */
static int leaf_event(const struct px_track *t, const struct leaf *l,
		      px_vec3 p0, px_vec3 p1, double *rfine)
{
	const double *a = leaf_a(t, l);
	int n = l->n;
	*rfine = 0.0;
	if (definite_seg(a, n + 1, p0, p1, l->tol_g))
		return 0;
	if (l->flags & (LF_EV0 | LF_EV1)) {
		int i;
		for (i = 0; i < 2; i++) {
			double v0, v1;
			if (!(l->flags & (i ? LF_EV1 : LF_EV0)))
				continue;
			v0 = gco(a, n, i ? n : 0, p0);
			v1 = gco(a, n, i ? n : 0, p1);
			if (!((v0 > l->tol_g && v1 > l->tol_g) ||
			      (v0 < -l->tol_g && v1 < -l->tol_g)))
				return 1;
		}
	}
	if (n < 1)
		return 0;
	if (definite_seg(a + 4 * (n + 1), n, p0, p1, l->tol_d))
		return 0;
	if (leaf_event_fine(a, t->ipool + l->ioff, n, p0, p1, l->tol_g, l->tol_d,
			    rfine))
		return 1;
	/* a break end's sign bounds it too (the whole-leaf radius holds
	 * that term already) */
	*rfine = break_end_radius(t, l, p1, *rfine);
	return 0;
}


/* Radius within which coefficients a - p.b (count m, stride m; inverse
 * norms ib) keep their signs around p: 0 when they are not
 * sign-definite at p (the linear bound |dp . b_i| <= |dp| |b_i|). */
static double definite_radius(const double *a, const double *ib, int m,
			      px_vec3 p, double tol)
{
	const double *bx = a + m, *by = bx + m, *bz = by + m;
	double r = INFINITY;
	int i, sg = 0;
	for (i = 0; i < m; i++) {
		double v = a[i] - (p.x * bx[i] + p.y * by[i] + p.z * bz[i]);
		int s = v > tol ? 1 : (v < -tol ? -1 : 0);
		if (!s || (sg && s != sg))
			return 0.0;
		sg = s;
		{
			double ri = ((v > 0.0 ? v : -v) - tol) * ib[i];
			if (ri < r)
				r = ri;
		}
	}
	return r;
}

static double box_dist(const px_aabb *b, px_vec3 p)
{
	double dx = b->min.x - p.x > 0.0 ? b->min.x - p.x
					: (p.x - b->max.x > 0.0 ? p.x - b->max.x : 0.0);
	double dy = b->min.y - p.y > 0.0 ? b->min.y - p.y
					: (p.y - b->max.y > 0.0 ? p.y - b->max.y : 0.0);
	double dz = b->min.z - p.z > 0.0 ? b->min.z - p.z
					: (p.z - b->max.z > 0.0 ? p.z - b->max.z : 0.0);
	return sqrt(dx * dx + dy * dy + dz * dz);
}

/* Radius within which dg/ds of leaf l keeps its sign around p (at most
 * one simple root in the leaf: no event) and g keeps its sign at a break
 * end of it (no root through it); 0 when not proven at p. */
static double leaf_dradius(const struct px_track *t, const struct leaf *l,
			   px_vec3 p)
{
	const double *a = leaf_a(t, l), *ib = t->ipool + l->ioff;
	int n = l->n;
	double r = n >= 1 ? definite_radius(a + 4 * (n + 1), ib + n + 1, n, p,
					    l->tol_d)
			  : INFINITY;
	return break_end_radius(t, l, p, r);
}

/* Distance p may travel (inside the working volume) before leaf l can
 * have an event: the distance to its event cells, or the radius where
 * one of the two exclusions of leaf_event() still holds (g of one sign:
 * no root at all; dg/ds of one sign: one simple root at most), whichever
 * is largest. */
static double leaf_radius(const struct px_track *t, const struct leaf *l,
			  px_vec3 p)
{
	const double *a = leaf_a(t, l), *ib = t->ipool + l->ioff;
	double r, rd, rb;
	if (!l->boxed || (t->fault & 4))
		return INFINITY;
	rb = box_dist(&l->box, p);
	r = definite_radius(a, ib, l->n + 1, p, l->tol_g);
	rd = leaf_dradius(t, l, p);
	if (rd > r)
		r = rd;
	return r > rb ? r : rb;
}

/*
 * The exact test of leaf l along p0 -> p1 (*event: 1 when it may hold an
 * event, as leaf_event()) and its safe radius at p1 (as leaf_radius()).
 * The usual leaf - no root, coefficients of g of one sign along the
 * whole step - is done in one pass over its coefficients.
 */
static double leaf_test(const struct px_track *t, const struct leaf *l,
			px_vec3 p0, px_vec3 p1, int *event)
{
	const double *a = leaf_a(t, l), *ib = t->ipool + l->ioff;
	int m = l->n + 1, i, sg = 0;
	const double *bx = a + m, *by = bx + m, *bz = by + m;
	double r = INFINITY, rb, tol = l->tol_g;
	for (i = 0; i < m; i++) {
		double v0 = a[i] - (p0.x * bx[i] + p0.y * by[i] + p0.z * bz[i]);
		double v1 = a[i] - (p1.x * bx[i] + p1.y * by[i] + p1.z * bz[i]);
		int s0 = v0 > tol ? 1 : (v0 < -tol ? -1 : 0);
		int s1 = v1 > tol ? 1 : (v1 < -tol ? -1 : 0);
		double ri;
		if (!s0 || s1 != s0 || (sg && s0 != sg))
			break;
		sg = s0;
		ri = ((v1 > 0.0 ? v1 : -v1) - tol) * ib[i];
		if (ri < r)
			r = ri;
	}
	if (i == m) {
		double rd;
		*event = 0;
		if (!l->boxed || (t->fault & 4))
			return INFINITY;
		rb = box_dist(&l->box, p1);
		if (rb > r)
			r = rb;
		rd = leaf_dradius(t, l, p1);
		return rd > r ? rd : r;
	}
	{
		double rf, rr;
		*event = leaf_event(t, l, p0, p1, &rf);
		rr = leaf_radius(t, l, p1);
		return (t->fault & 4) || rf < rr ? rr : rf;
	}
}

/* Safe radii of all leaves at p (inside the working volume). */
static void heap_rebuild(struct px_track *t, px_vec3 p)
{
	int i;
	double nd = INFINITY;
	for (i = 0; i < t->n_leaves; i++) {
		double rad = leaf_radius(t, &t->leaf[i], p) * (1.0 - 1e-9);
		double x = t->travel + rad;
		t->expiry[i] = x;
		t->ectr[i] = p;
		t->erad[i] = rad;
		if (i % TRK_GROUP == 0)
			t->gdue[i / TRK_GROUP] = x;
		else if (x < t->gdue[i / TRK_GROUP])
			t->gdue[i / TRK_GROUP] = x;
		if (x < nd)
			nd = x;
	}
	t->next_due = nd;
	t->heap_ok = 1;
}

static void mark_leaf(struct px_track *t, int li, int *nh)
{
	if (t->leaf[li].mark == t->epoch)
		return;
	t->leaf[li].mark = t->epoch;
	t->hits[(*nh)++] = li;
}

/* Leaves that may hold an event along p0 -> p1, grown while a root
 * crosses the outer boundary of the region. Returns their count. Only
 * leaves whose safe radius the travelled path has used up are tested
 * (exactly, along the segment), then given a new radius at p1; len is
 * |p1 - p0| (the update measured it once). */
static int collect_events(struct px_track *t, px_vec3 p0, px_vec3 p1,
			  double len)
{
	int nh = 0, k, n = t->n_leaves;

	if (!t->heap_ok)
		heap_rebuild(t, p0);
	t->travel += len;
	/* A due leaf is tested and gets its new expiry. A radius of 0 gives
	 * expiry == travel: due at the next update with any motion (the
	 * comparisons are strict). */
	if (t->next_due < t->travel) {
		double nd = INFINITY, tr = t->travel;
		double *ex = t->expiry;
		int g, ng = (n + TRK_GROUP - 1) / TRK_GROUP;
		for (g = 0; g < ng; g++) {
			int k1 = (g + 1) * TRK_GROUP < n ? (g + 1) * TRK_GROUP : n;
			double gd = INFINITY;
			if (!(t->gdue[g] < tr)) {
				if (t->gdue[g] < nd)
					nd = t->gdue[g];
				continue;
			}
			for (k = g * TRK_GROUP; k < k1; k++) {
				if (ex[k] < tr) {
					struct leaf *l = &t->leaf[k];
					int ev;
					double rad, left;
					left = t->erad[k] * ((t->fault & 256) ? 2.0 : 1.0) -
					       px_v3_dist(p1, t->ectr[k]);
					if (left > TRK_REKEY * t->erad[k]) {
						ex[k] = tr + left;
						t->st.rekeys++;
					} else {
						t->st.box_hits++;
						rad = leaf_test(t, l, p0, p1, &ev);
						if (ev)
							mark_leaf(t, k, &nh);
						rad *= 1.0 - 1e-9;
						ex[k] = tr + rad;
						t->ectr[k] = p1;
						t->erad[k] = rad;
					}
				}
				if (ex[k] < gd)
					gd = ex[k];
			}
			t->gdue[g] = gd;
			if (gd < nd)
				nd = gd;
		}
		t->next_due = nd;
	}
	for (k = 0; k < nh; k++) {
		int li = t->hits[k], side;
		const struct leaf *l = &t->leaf[li];
		const struct ent *e = &t->ent[l->ent];
		for (side = 0; side < 2; side++) {
			int nb;
			double v0, v1;
			if (l->flags & (side ? LF_SB1 : LF_SB0))
				continue;
			nb = li - e->first_leaf + (side ? 1 : -1);
			if (nb < 0 || nb >= e->n_leaves) {
				if (!e->cyclic)
					continue;
				nb = (nb + e->n_leaves) % e->n_leaves;
			}
			nb += e->first_leaf;
			if (t->leaf[nb].mark == t->epoch)
				continue;
			v0 = gco(leaf_a(t, l), l->n, side ? l->n : 0, p0);
			v1 = gco(leaf_a(t, l), l->n, side ? l->n : 0, p1);
			if ((v0 > l->tol_g && v1 > l->tol_g) ||
			    (v0 < -l->tol_g && v1 < -l->tol_g))
				continue;
			mark_leaf(t, nb, &nh);
		}
	}
	return nh;
}

/* ------------------------------------------------------------------ */
/* answer                                                              */

/* May root j of e (outside any re-solved leaf) skip its correction this
 * update? Only when its leaf certificate holds (it is provably still in
 * its leaf: no event there, end values of g kept their signs) and it is
 * alone there (a neighbour converging onto its branch would otherwise go
 * unseen by the duplicate check). */
static int can_rest(const struct px_track *t, const struct ent *e, int j)
{
	const struct zero *z = &e->z[j];
	if (t->fault & 1)
		return 1;
	if (!(t->travel < z->until))
		return 0;
	if (j > 0 && e->z[j - 1].leaf == z->leaf)
		return 0;
	if (j + 1 < e->nz && e->z[j + 1].leaf == z->leaf)
		return 0;
	return 1;
}

/* Correct every resting root of e at p. Returns 0 or 1 (anomaly). */
static int catch_up(struct px_track *t, struct ent *e, px_vec3 p)
{
	int j;
	for (j = 0; j < e->nz; j++) {
		struct zero *z = &e->z[j];
		if (z->ep == t->epoch)
			continue;
		if (evolve(t, e, z, z->p, px_v3_sub(p, z->p), p))
			return 1;
	}
	return 0;
}

/*
 * Correct the resting minima that could be the closest point. A critical
 * distance is 1-Lipschitz in the query point along its branch (its
 * gradient is the unit vector from the foot point), so after a path of
 * length L since its last correction a minimum is at least dist - L
 * away; best (the distance to a real curve point: a current minimum or a
 * candidate) bounds the global minimum from above, and a minimum whose
 * bound exceeds it cannot be the closest point. Maxima never answer and
 * rest on their leaf certificates.
 */
static void wake_minima(struct px_track *t, px_vec3 p)
{
	double best2 = INFINITY, best;
	int i, j, round;
	for (i = 0; i < t->n_cand; i++) {
		double d2 = px_v3_dist2(t->cand[i].q, p);
		if (d2 < best2)
			best2 = d2;
	}
	for (i = 0; i < t->n_ent; i++) {
		const struct ent *e = &t->ent[i];
		if (e->stale || e->resting)
			continue;
		for (j = 0; j < e->nz; j++) {
			const struct zero *z = &e->z[j];
			double d2;
			if (z->type < 0 || z->ep != t->epoch)
				continue;
			d2 = px_v3_dist2(z->c, p);
			if (d2 < best2)
				best2 = d2;
		}
	}
	best = sqrt(best2);
	t->best_now = best;
	if (t->fault & 2)
		return;
	/* wake the resting minimum with the smallest bound first: it is
	 * usually the closest point and then excludes the others (bounded:
	 * each round corrects one root or ends) */
	for (round = 0; round <= t->n_rmin; round++) {
		struct ent *we = NULL;
		struct zero *wz = NULL;
		double wlb = INFINITY, d;
		int leaf0, k;
		/* the resting minima listed by the evolution pass (those of
		 * an entity caught up since are current now) */
		for (k = 0; k < t->n_rmin; k++) {
			struct ent *e = &t->ent[t->rmin[2 * k]];
			struct zero *z = &e->z[t->rmin[2 * k + 1]];
			double lb;
			if (e->stale || z->ep == t->epoch)
				continue;
			lb = z->dist - (t->travel - z->trav);
			if (lb < wlb) {
				wlb = lb;
				wz = z;
				we = e;
			}
		}
		if (!wz || wlb > best + 1e-9 * (best + t->scale))
			break;
		leaf0 = wz->leaf;
		if (evolve(t, we, wz, wz->p, px_v3_sub(p, wz->p), p)) {
			we->stale = 1;
			continue;
		}
		if (wz->leaf != leaf0 && !we->full) {
			we->full = 1;
			if (catch_up(t, we, p)) {
				we->stale = 1;
				continue;
			}
			/* caught-up minima may be closer */
			for (j = 0; j < we->nz; j++)
				if (we->z[j].type > 0) {
					d = px_v3_dist(we->z[j].c, p);
					if (d < best)
						best = d;
				}
		}
		d = px_v3_dist(wz->c, p);
		if (d < best)
			best = d;
	}
	t->best_now = best;
}

/*
 * A resting root's leaf certificate (z->until) renewed at t->p without
 * correcting the root, when its distance share still holds. Sound where
 * the certificate held at the previous update (renewals come at the
 * first update past the least expiry, hot_cert()): from there to t->p
 * the path is one straight step, along which the leaf's end values of g
 * (affine in p) are linear, so where each has at t->p the sign it had at
 * the root's last correction z->p it kept that sign the whole way and no
 * root left the leaf; the new certificate is leaf_end_radius() at t->p.
 * Returns 1 when renewed, 0 when the root must be corrected (an end
 * value changed sign or is too close to zero to tell).
 */
static int renew_until(struct px_track *t, struct zero *z)
{
	const struct leaf *l = &t->leaf[z->leaf];
	const double *a = leaf_a(t, l);
	double r, g0 = gco(a, l->n, 0, t->p), g1 = gco(a, l->n, l->n, t->p);
	if (!t->opts.lazy)
		return 0;
	if (!(t->fault & 512)) {
		double h0 = gco(a, l->n, 0, z->p), h1 = gco(a, l->n, l->n, z->p);
		if (!(fabs(h0) > l->tol_g) || !(fabs(h1) > l->tol_g) || !(g0 * h0 > 0.0) ||
		    !(g1 * h1 > 0.0))
			return 0;
	}
	r = leaf_end_radius(t, l, t->p);
	if (!(r > 0.0))
		return 0;
	z->until = t->travel + r * (1.0 - 1e-9);
	t->st.renewals++;
	return 1;
}

/*
 * The certificate shared by resting roots: the travelled path below which
 * every root of e but skip provably stays in its leaf (each leaf
 * certificate; the caller checked that each is alone there) and no
 * minimum of them can be the closest point. best is the distance to a
 * real curve point followed continuously; the global distance d* is
 * 1-Lipschitz, so after a further path L, d* <= best + L, while a
 * minimum is at least lb - L away (lb its lower bound now); it cannot be
 * the closest while lb - L > best + L, i.e. L < (lb - best) / 2 (with the
 * same tolerance as wake_minima). With fix set, a root whose certificate
 * ran out is corrected first, on a copy kept only when it stayed in its
 * leaf. Lowers *until; returns 0, or 1 when there is no certificate.
 */
static int cert_roots(struct px_track *t, struct ent *e, int skip,
		      double best, int fix, double *until)
{
	double tol = 1e-9 * (best + t->scale), m, x;
	int j, margin = !(t->fault & 32);
	for (j = 0; j < e->nz; j++) {
		struct zero *z = &e->z[j];
		if (j == skip)
			continue;
		/* renewing (fix): a root whose share still runs keeps it - a
		 * proof made earlier stays a proof */
		if (fix && z->hexp > t->travel) {
			if (z->hexp < *until)
				*until = z->hexp;
			continue;
		}
		if (fix && (!(z->until > t->travel) ||
			    (z->type > 0 &&
			     !(z->dist - (t->travel - z->trav) - best - tol > 0.0))) &&
		    !(z->until <= t->travel &&
		      (z->type < 0 || z->dist - (t->travel - z->trav) - best - tol > 0.0) &&
		      renew_until(t, z))) {
			struct zero zc = *z;
			if (evolve(t, e, &zc, zc.p, px_v3_sub(t->p, zc.p), t->p) ||
			    zc.leaf != z->leaf)
				return 1;
			*z = zc;
		}
		if (!(z->until > t->travel))
			return 1;
		x = z->until;
		if (z->type > 0 && margin) {
			m = z->dist - (t->travel - z->trav) - best - tol;
			if (!(m > 0.0))
				return 1;
			m = t->travel + 0.5 * m * (1.0 - 1e-9);
			if (m < x)
				x = m;
		}
		z->hexp = x;
		if (x < *until)
			*until = x;
	}
	return 0;
}

/* Each root of e alone in its leaf (the roots sorted: neighbours
 * compared); *nmin its minima. */
static int ent_alone(const struct ent *e, int *nmin)
{
	int j, n = 0;
	for (j = 0; j < e->nz; j++) {
		if (j > 0 && e->z[j - 1].leaf == e->z[j].leaf)
			return 0;
		n += e->z[j].type > 0;
	}
	*nmin = n;
	return 1;
}

/* Certify e to rest whole from now on (after its checks of this update):
 * each root alone in its leaf (can_rest), cert_roots against the best
 * distance of this update. */
static void ent_certify(struct px_track *t, struct ent *e)
{
	double until = INFINITY;
	int nmin;
	e->rest_until = -1.0;
	if (!ent_alone(e, &nmin))
		return;
	e->nmin = nmin;
	if (cert_roots(t, e, -1, t->best_now, 0, &until))
		return;
	e->rest_until = (t->fault & 16) ? INFINITY : until;
}

static int in_work(const struct px_track *t, px_vec3 p)
{
	return p.x >= t->work.min.x && p.x <= t->work.max.x &&
	       p.y >= t->work.min.y && p.y <= t->work.max.y &&
	       p.z >= t->work.min.z && p.z <= t->work.max.z;
}

static void fill_dir(struct px_track_result *r, px_vec3 p)
{
	px_vec3 d = px_v3_sub(p, r->point);
	double n = px_v3_norm(d);
	r->dist = n;
	r->dir = n > 0.0 ? px_v3_scale(d, 1.0 / n) : px_v3(0, 0, 0);
}

static void answer(struct px_track *t, px_vec3 p, struct px_track_result *r)
{
	double best = INFINITY;
	uint32_t id = 0;
	int i, j, nc = 0, nm = 0;

	t->ans_z = -1;
	t->ans_c = -1;
	for (i = 0; i < t->n_ent; i++) {
		const struct ent *e = &t->ent[i];
		nc += e->nz;
		if (e->resting) {
			/* rests whole: its minima provably not the closest */
			t->st.rested += (uint64_t)e->nz;
			nm += e->nmin;
			continue;
		}
		for (j = 0; j < e->nz; j++) {
			const struct zero *z = &e->z[j];
			double d2;
			if (z->ep != t->epoch)
				t->st.rested++;
			if (z->type < 0)
				continue;
			nm++;
			if (z->ep != t->epoch)
				continue; /* resting: provably not the closest */
			d2 = px_v3_dist2(z->c, p);
			if (d2 < best) {
				best = d2;
				id = z->id;
				r->point = z->c;
				r->u = z->u;
				r->entity = i;
				r->feature = PX_TRACK_MIN;
				t->ans_z = j;
				t->ans_c = -1;
			}
		}
	}
	for (i = 0; i < t->n_cand; i++) {
		double d2 = px_v3_dist2(t->cand[i].q, p);
		if (d2 < best) {
			best = d2;
			id = 0x80000000u | (uint32_t)i;
			r->point = t->cand[i].q;
			r->u = t->cand[i].u;
			r->entity = t->cand[i].ent;
			r->feature = t->cand[i].kind;
			t->ans_z = -1;
			t->ans_c = i;
		}
	}
	fill_dir(r, p);
	r->n_crit = nc;
	r->n_min = nm;
	r->jumped = t->best_id != 0 && id != t->best_id;
	t->best_id = id;
}

/*
 * The hot certificate over entity E answered by its minimum a (or, a -1,
 * by candidate hot_c), at the current point with best the distance of
 * the answer (current): cert_roots over the other roots of E (each alone
 * in its leaf, checked when armed) and over the other candidates (fixed
 * points, 1-Lipschitz distances: the same margin), every other entity
 * resting whole under its own certificate
 * (hot_other, their smallest). With fix set (from the hot path) the roots
 * whose certificates ran out are corrected and an entity whose rest ran
 * out is certified again the same way. Returns 0 (hot_until set) or 1
 * (no certificate: the full update runs).
 */
static int hot_cert(struct px_track *t, struct ent *E, int a, double best,
		    int fix)
{
	double until, tol = 1e-9 * (best + t->scale), m;
	int i;
	if (fix && !(t->travel < t->hot_other)) {
		double other = INFINITY;
		for (i = 0; i < t->n_ent; i++) {
			struct ent *e = &t->ent[i];
			if (e == E)
				continue;
			if (!(t->travel < e->rest_until)) {
				double u2 = INFINITY;
				if ((t->fault & 16) ||
				    cert_roots(t, e, -1, best, 1, &u2))
					return 1;
				e->rest_until = u2;
			}
			if (e->rest_until < other)
				other = e->rest_until;
		}
		t->hot_other = other;
	}
	until = t->hot_other;
	if (!(t->travel < until) || cert_roots(t, E, a, best, fix, &until))
		return 1;
	for (i = 0; i < t->n_cand; i++) {
		if (i == t->hot_c)
			continue;
		if (!fix || !(t->cexp[i] > t->travel)) {
			m = px_v3_dist(t->cand[i].q, t->p) - best - tol;
			if (!(m > 0.0))
				return 1;
			t->cexp[i] = t->travel + 0.5 * m * (1.0 - 1e-9);
		}
		if (t->cexp[i] < until)
			until = t->cexp[i];
	}
	t->hot_until = (t->fault & 64) ? INFINITY : until;
	return 0;
}

/*
 * Arm the hot certificate after a tracked update answered by an interior
 * minimum or a candidate. Every other entity must rest whole, and every
 * root of the
 * answer's entity must be alone in its leaf: with no event anywhere and
 * every other root held in its leaf, the root Newton converges to inside
 * the answering root's leaf is its continuation.
 */
static void hot_arm(struct px_track *t, const struct px_track_result *r)
{
	struct ent *E;
	double other = INFINITY;
	int a, i, ne, nc = 0, nm = 0, nre = 0;

	t->hot_ent = -1;
	if (!t->opts.lazy || r->source != PX_TRACK_TRACKED ||
	    (t->ans_z < 0) == (t->ans_c < 0) || r->entity < 0)
		return;
	E = &t->ent[r->entity];
	a = t->ans_z;
	if (E->stale || a >= E->nz || (a >= 0 && E->z[a].ep != t->epoch))
		return;
	for (i = 0; i < t->n_ent; i++) {
		const struct ent *e = &t->ent[i];
		nc += e->nz;
		if (e == E)
			continue;
		if (e->stale || !(e->rest_until > t->travel))
			return;
		if (e->rest_until < other)
			other = e->rest_until;
		nm += e->nmin;
		nre++;
	}
	if (!ent_alone(E, &ne))
		return;
	nm += ne;
	if (E->nz >= 2 && E->z[0].leaf == E->z[E->nz - 1].leaf)
		return;
	t->hot_other = other;
	t->hot_c = t->ans_c;
	if (hot_cert(t, E, a, r->dist, 0))
		return;
	t->hot_ent = r->entity;
	t->hot_z = a;
	t->hot_nc = nc;
	t->hot_nm = nm;
	t->hot_rest_ent = (uint64_t)nre;
	t->hot_rested = (uint64_t)(nc - (a >= 0));
}

/*
 * An update under the hot certificate (no leaf had an event on the way
 * here): the answering root by quick_evolve, into a neighbouring leaf of
 * the same stretch when that leaf holds no other root, then the
 * certificate renewed in place when the path has used it up. Returns 0
 * when answered, 1 when the full update must run (the state is then one
 * it can start from: only corrections it would make itself were kept).
 */
static int hot_update(struct px_track *t, px_vec3 p, struct px_track_result *r)
{
	struct ent *e = &t->ent[t->hot_ent];
	struct zero *z;
	px_vec3 c, d1;
	double D, u, ua, st;
	int li, j, q;
	if (t->hot_z < 0) {
		/* a candidate answers: a fixed point */
		const struct cand *cd = &t->cand[t->hot_c];
		if (!(t->travel < t->hot_until) &&
		    hot_cert(t, e, -1, px_v3_dist(cd->q, p), 1))
			return 1;
		r->point = cd->q;
		r->u = cd->u;
		r->entity = cd->ent;
		r->feature = cd->kind;
		goto done;
	}
	z = &e->z[t->hot_z];
	li = z->leaf;
	q = quick_evolve(t, z, li, z->u + px_v3_dot(px_v3_sub(p, z->p), z->d1) / z->D,
			 p, TRK_QUICK_ITERS, &c, &d1, &D, &u, &ua, &st);
	if (q) {
		/* the iteration left the leaf: on into the neighbour on that
		 * side, unless a stretch boundary, a break or another root
		 * is there */
		const struct leaf *l = &t->leaf[li];
		int side;
		if (q == 1)
			ua += st;
		side = ua > l->u1;
		if (!(ua < l->u0 || ua > l->u1) ||
		    (l->flags & (side ? (LF_SB1 | LF_EV1) : (LF_SB0 | LF_EV0))))
			return 1;
		li += side ? 1 : -1;
		if (li < e->first_leaf || li >= e->first_leaf + e->n_leaves ||
		    (t->leaf[li].flags &
		     (side ? (LF_SB0 | LF_EV0) : (LF_SB1 | LF_EV1))))
			return 1;
		for (j = 0; j < e->nz; j++)
			if (e->z[j].leaf == li)
				return 1;
		if (quick_evolve(t, z, li, ua, p, TRK_QUICK_ITERS, &c, &d1, &D,
				 &u, &ua, &st))
			return 1;
	}
	z->u = u;
	z->leaf = li;
	z->c = c;
	z->d1 = d1;
	z->D = D;
	z->p = p;
	z->trav = t->travel;
	z->ep = t->epoch;
	/* its leaf certificate is not kept up here: the full update that
	 * follows corrects it first */
	z->until = -1.0;
	{
		/* the distance once, for the root and the answer */
		px_vec3 d = px_v3_sub(p, c);
		double n = sqrt(px_v3_dot(d, d));
		z->dist = n;
		if (!(t->travel < t->hot_until) &&
		    hot_cert(t, e, t->hot_z, n, 1))
			return 1;
		r->dist = n;
		r->dir = n > 0.0 ? px_v3_scale(d, 1.0 / n) : px_v3(0, 0, 0);
	}
	r->point = c;
	r->u = u;
	r->entity = t->hot_ent;
	r->feature = PX_TRACK_MIN;
	goto counts;
done:
	fill_dir(r, p);
counts:
	r->n_crit = t->hot_nc;
	r->n_min = t->hot_nm;
	t->st.hot++;
	t->st.rested += t->hot_rested;
	t->st.rested_entities += t->hot_rest_ent;
	return 0;
}

static void answer_global(struct px_track *t, px_vec3 p,
			  struct px_track_result *r)
{
	struct px_dist_result g;
	int i, nc = 0, nm = 0, j;
	px_dist_query(t->dist, p, &g);
	r->point = g.point;
	r->u = g.u;
	r->entity = g.entity;
	r->feature = PX_TRACK_FROM_GLOBAL;
	fill_dir(r, p);
	for (i = 0; i < t->n_ent; i++) {
		nc += t->ent[i].nz;
		for (j = 0; j < t->ent[i].nz; j++)
			nm += t->ent[i].z[j].type > 0;
	}
	r->n_crit = nc;
	r->n_min = nm;
	r->jumped = 1;
	t->best_id = 0;
	r->source = PX_TRACK_GLOBAL;
	t->st.fallbacks++;
}

static void result_clear(struct px_track_result *r)
{
	memset(r, 0, sizeof(*r));
	r->entity = -1;
}

/* Rebuild every entity; returns 0 or the first error. */
static int reinit_all(struct px_track *t, px_vec3 p)
{
	int i, rc = 0;
	for (i = 0; i < t->n_ent; i++) {
		int r2 = ent_reinit(t, &t->ent[i], p);
		if (r2 && !rc)
			rc = r2;
	}
	return rc;
}

static void count_fail(struct px_track *t, int rc)
{
	if (rc == PX_E_NOSPC)
		t->st.overflows++;
	else
		t->st.unresolved++;
}

static void verify(struct px_track *t, px_vec3 p, struct px_track_result *r)
{
	struct px_dist_result g;
	if (t->opts.verify_every <= 0 ||
	    t->st.updates % (uint64_t)t->opts.verify_every != 0)
		return;
	if (px_dist_query(t->dist, p, &g))
		return;
	t->st.verifications++;
	r->verified = 1;
	if (r->dist > g.dist + 1e-9 * (t->scale + g.dist)) {
		int rc;
		t->st.disagreements++;
		rc = reinit_all(t, p);
		if (rc)
			count_fail(t, rc);
		answer_global(t, p, r);
		r->verified = 1;
	}
}

int px_track_reset(struct px_track *t, px_vec3 p, struct px_track_result *r)
{
	int rc;
	if (!t || !r)
		return PX_E_INVAL;
	if (!isfinite(p.x) || !isfinite(p.y) || !isfinite(p.z))
		return PX_E_NAN;
	result_clear(r);
	t->st.updates++;
	t->p = p;
	t->p_in = in_work(t, p);
	t->init = 1;
	t->best_id = 0;
	t->hot_ent = -1;
	t->heap_ok = 0;
	if (t->gov.cold)
		t->st.cold_left++;
	px__gov_restart(&t->gov);
	rc = reinit_all(t, p);
	/* the leaves' safe radii here too, so that the next update costs
	 * what an update costs */
	if (t->p_in)
		heap_rebuild(t, p);
	r->source = PX_TRACK_REINIT;
	if (rc) {
		count_fail(t, rc);
		answer_global(t, p, r);
	} else {
		answer(t, p, r);
		r->jumped = 1;
		verify(t, p, r);
	}
	return PX_OK;
}

static __attribute__((noinline)) int update_full(struct px_track *t, px_vec3 p, int nh,
		       struct px_track_result *r);

/*
 * Is the closest point (entity ent, parameter u, point) the continuation
 * of the last answer kept in t->prev? Used where no critical point was
 * followed: cold answers and the return from them. The same point (an
 * end, a break, no motion) is; otherwise the answer must be a minimum of
 * the same curve whose backward predictor (Eq. 6 from the new point to
 * the last one) lands nearer the last parameter than half the parameter
 * moved - on one branch the predictor's error is second order in the
 * step, a jump to another branch lands it near the new parameter.
 */
static int continued(struct px_track *t, px_vec3 p, int ent, double u,
		     px_vec3 point, double dist)
{
	const struct ent *e;
	double D, ub, du, dub, duf = 0.0;
	px_vec3 c, d1, d2;
	t->cur_D = 0.0;
	if (ent < 0 || ent >= t->n_ent)
		return 0;
	e = &t->ent[ent];
	span_eval(find_span(t, e, u), u, &c, &d1, &d2);
	D = px_v3_dot(px_v3_sub(c, p), d2) + px_v3_dot(d1, d1);
	t->cur_d1 = d1;
	t->cur_D = D;
	if (t->prev.ent < 0 || ent != t->prev.ent)
		return 0;
	if (px_v3_dist(point, t->prev.point) <= 1e-9 * (t->scale + dist))
		return 1;
	if (t->prev.fixed || !(D > 0.0))
		return 0;
	ub = u + px_v3_dot(px_v3_sub(t->prev.p, p), d1) / D;
	du = u - t->prev.u;
	dub = ub - t->prev.u;
	if (t->prev.D > 0.0)
		/* and forward from the last answer (Eq. 6 itself) */
		duf = t->prev.u + px_v3_dot(px_v3_sub(p, t->prev.p), t->prev.d1) /
					  t->prev.D - u;
	if (e->cyclic) {
		/* the shorter way round the seam */
		du = px__wrap_half(du, e->len);
		dub = px__wrap_half(dub, e->len);
		duf = px__wrap_half(duf, e->len);
	}
	return fabs(dub) <= 0.5 * fabs(du) && fabs(duf) <= 0.5 * fabs(du);
}

static void prev_keep(struct px_track *t, const struct px_track_result *r)
{
	t->prev.ent = r->entity;
	t->prev.fixed = r->feature == PX_TRACK_END || r->feature == PX_TRACK_BREAK;
	t->prev.u = r->u;
	t->prev.point = r->point;
	t->prev.p = t->p;
	t->prev.d1 = t->cur_d1;
	t->prev.D = t->cur_D;
}

/* An update answered cold (gov.cold): the global query alone; the
 * critical points wait for the return. Returns 0 or the query's error
 * (the caller then tracks instead). */
static int cold_update(struct px_track *t, px_vec3 p, struct px_track_result *r)
{
	struct px_dist_result g;
	int rc = px__gov_cold_query(&t->gov, t->dist, p, &g);
	if (rc)
		return rc;
	result_clear(r);
	t->st.updates++;
	t->st.cold++;
	r->dist = g.dist;
	r->point = g.point;
	r->u = g.u;
	r->entity = g.entity;
	r->dir = g.dir;
	r->feature = PX_TRACK_FROM_GLOBAL;
	r->n_crit = r->n_min = -1;
	r->source = PX_TRACK_COLD;
	r->jumped = !continued(t, p, g.entity, g.u, g.point, g.dist);
	t->p = p;
	prev_keep(t, r);
	return 0;
}

static int track_update(struct px_track *t, px_vec3 p, double len, int fresh,
			struct px_track_result *r);

int px_track_update(struct px_track *t, px_vec3 p, struct px_track_result *r)
{
	int64_t t0;
	int rc, fresh = 0;
	double len;

	if (!t || !r)
		return PX_E_INVAL;
	if (!isfinite(p.x) || !isfinite(p.y) || !isfinite(p.z))
		return PX_E_NAN;
	if (!t->init)
		return px_track_reset(t, p, r);
	/* the step's length, for the travelled path and the cold switch */
	len = px_v3_dist(t->p, p);
	if (t->gov.on) {
		px__gov_step(&t->gov, len);
		if (t->gov.cold) {
			if (!px__gov_leave(&t->gov)) {
				if (cold_update(t, p, r) == 0)
					return PX_OK;
				/* no global answer here (far away): track */
				px__gov_restart(&t->gov);
			}
			t->st.cold_left++;
			fresh = 1;
		}
	}
	t0 = px__gov_start(&t->gov);
	rc = track_update(t, p, len, fresh, r);
	if (px__gov_stop(&t->gov, t0)) {
		/* cold from the next update on */
		t->st.cold_entered++;
		t->hot_ent = -1;
		t->cur_D = 0.0;
		prev_keep(t, r);
	}
	if (fresh && rc == PX_OK)
		r->jumped = !continued(t, p, r->entity, r->u, r->point, r->dist);
	return rc;
}

/* The tracked update; len: |p - t->p|; fresh: every critical point found
 * again at p (the return from cold answers). */
static int track_update(struct px_track *t, px_vec3 p, double len, int fresh,
			struct px_track_result *r)
{
	int i, j, nh, rc, in;
	px_vec3 p0;

	result_clear(r);
	t->st.updates++;
	p0 = t->p;
	t->p = p;
	r->source = PX_TRACK_TRACKED;
	if (++t->epoch == 0) {
		/* wrapped: no stale mark or correction stamp may look current */
		for (i = 0; i < t->n_leaves; i++)
			t->leaf[i].mark = t->leaf[i].tested = 0;
		for (i = 0; i < t->n_ent; i++) {
			t->ent[i].hit = 0;
			for (j = 0; j < t->ent[i].nz; j++)
				t->ent[i].z[j].ep = 0;
		}
		t->epoch = 1;
	}

	/* (whether p0 was inside was found by the last update) */
	in = in_work(t, p);
	if (!in || !t->p_in || fresh) {
		if (!in || !t->p_in)
			t->st.outside++;
		t->p_in = in;
		t->hot_ent = -1;
		t->heap_ok = 0;
		r->source = PX_TRACK_REINIT;
		rc = reinit_all(t, p);
		/* back inside: the radii at p in this update (a re-start
		 * already), not in the next */
		if (in)
			heap_rebuild(t, p);
		if (rc) {
			count_fail(t, rc);
			answer_global(t, p, r);
			return PX_OK;
		}
		answer(t, p, r);
		verify(t, p, r);
		return PX_OK;
	}

	nh = collect_events(t, p0, p, len);
	if (t->hot_ent >= 0) {
		if (nh == 0 && !hot_update(t, p, r)) {
			if (t->opts.verify_every > 0) {
				verify(t, p, r);
				if (r->source != PX_TRACK_TRACKED)
					t->hot_ent = -1;
			}
			return PX_OK;
		}
		t->hot_ent = -1;
	}
	return update_full(t, p, nh, r);
}

/* The update beyond the hot path: evolution of every root that cannot
 * rest, the re-solved leaves, the checks, the answer. */
static __attribute__((noinline)) int update_full(struct px_track *t, px_vec3 p, int nh,
		       struct px_track_result *r)
{
	int i, j, rc = 0, fail = 0, added = 0;

	r->leaves_solved = nh;
	t->st.leaf_solves += (uint64_t)nh;

	for (i = 0; i < nh; i++)
		t->ent[t->leaf[t->hits[i]].ent].hit = t->epoch;
	t->n_rmin = 0;
	/* evolve every root outside the re-solved leaves; in an entity
	 * without re-solved leaves a root whose leaf certificate holds may
	 * rest (can_rest) until the answer needs it */
	for (i = 0; i < t->n_ent; i++) {
		struct ent *e = &t->ent[i];
		int w = 0;
		e->nold = 0;
		e->touched = 0;
		e->full = !t->opts.lazy || e->hit == t->epoch;
		e->moved = 0;
		e->resting = 0;
		if (e->stale)
			continue;
		if (!e->full && t->travel < e->rest_until) {
			e->resting = 1;
			t->st.rested_entities++;
			continue;
		}
		e->rest_until = -1.0;
		for (j = 0; j < e->nz; j++) {
			struct zero *zj = &e->z[j];
			int leaf0;
			if (t->leaf[zj->leaf].mark == t->epoch) {
				e->old[e->nold++] = *zj;
				e->touched = 1;
				continue;
			}
			/* without a re-solved leaf nothing is dropped: w == j */
			if (!e->full && can_rest(t, e, j)) {
				if (zj->type > 0) {
					t->rmin[2 * t->n_rmin] = i;
					t->rmin[2 * t->n_rmin + 1] = j;
					t->n_rmin++;
				}
				w++;
				continue;
			}
			leaf0 = zj->leaf;
			if (w != j)
				e->z[w] = *zj;
			if (evolve(t, e, &e->z[w], e->z[w].p, px_v3_sub(p, e->z[w].p),
				   p)) {
				e->stale = 1;
				break;
			}
			if (e->z[w].leaf != leaf0)
				e->full = 1;
			w++;
		}
		if (!e->stale) {
			e->nz = w;
			if (e->full && catch_up(t, e, p))
				e->stale = 1;
		}
	}
	/* re-solve the event leaves at the new point */
	for (i = 0; i < nh; i++) {
		int li = t->hits[i];
		struct ent *e = &t->ent[t->leaf[li].ent];
		int n;
		if (e->stale)
			continue;
		n = add_leaf_roots(t, e, li, p);
		if (n < 0) {
			rc = n;
			e->stale = 1;
			fail = 1;
			break;
		}
		added += n;
		e->touched = 1;
	}
	if (!fail && t->opts.lazy)
		wake_minima(t, p);
	if (!fail) {
		for (i = 0; i < t->n_ent; i++) {
			struct ent *e = &t->ent[i];
			if (!e->stale && e->touched) {
				sort_zeros(e);
				if (ent_check(t, e, p))
					e->stale = 1;
			}
		}
		for (i = 0; i < t->n_ent; i++) {
			struct ent *e = &t->ent[i];
			if (!e->stale && !e->touched && e->moved) {
				/* evolved roots kept type and stretch; two
				 * converging to one root shows as a duplicate
				 * (an entity whose roots all rest is unchanged) */
				sort_zeros(e);
				if (ent_dups(e))
					e->stale = 1;
			}
		}
	}
	/* anomalies: rebuild those entities here */
	for (i = 0; i < t->n_ent && !fail; i++) {
		struct ent *e = &t->ent[i];
		if (!e->stale)
			continue;
		t->st.reinits++;
		r->source = PX_TRACK_REINIT;
		rc = ent_reinit(t, e, p);
		if (rc)
			fail = 1;
	}
	if (!fail && t->opts.lazy) {
		for (i = 0; i < t->n_ent; i++) {
			struct ent *e = &t->ent[i];
			/* corrected roots too: their certificates were made
			 * at this point (the hot path needs every entity
			 * but the answer's resting whole) */
			if (!e->resting && !e->stale &&
			    r->source == PX_TRACK_TRACKED)
				ent_certify(t, e);
		}
	}
	if (fail) {
		count_fail(t, rc);
		for (i = 0; i < t->n_ent; i++)
			t->ent[i].stale = 1;
		answer_global(t, p, r);
		return PX_OK;
	}
	if (r->source == PX_TRACK_TRACKED) {
		/* creation / annihilation: roots the re-solved leaves gained */
		int before = 0;
		for (i = 0; i < t->n_ent; i++)
			before += t->ent[i].nold;
		if (added > before) {
			r->created = (added - before) / 2;
			t->st.creations += (uint64_t)r->created;
		} else if (added < before) {
			r->annihilated = (before - added) / 2;
			t->st.annihilations += (uint64_t)r->annihilated;
		}
	}
	answer(t, p, r);
	r->leaves_solved = nh;
	verify(t, p, r);
	hot_arm(t, r);
	return PX_OK;
}

/* Bring the resting roots of e up to date at the current point (for
 * px_track_critical: the caller sees every root where it is now). */
static void ent_refresh(struct px_track *t, struct ent *e)
{
	int j, rest = 0;
	if (!t->init || e->stale)
		return;
	if (t->gov.cold) {
		/* not followed while cold: found afresh at the point */
		if (ent_reinit(t, e, t->p))
			count_fail(t, PX_E_RANGE);
		return;
	}
	t->hot_ent = -1; /* the roots are corrected and re-sorted here */
	e->rest_until = -1.0;
	e->resting = 0;
	for (j = 0; j < e->nz; j++)
		rest |= e->z[j].ep != t->epoch;
	if (!rest)
		return;
	if (catch_up(t, e, t->p) || (sort_zeros(e), ent_check(t, e, t->p))) {
		t->st.reinits++;
		if (ent_reinit(t, e, t->p))
			count_fail(t, PX_E_RANGE);
	}
}

void px__track_set_fault(struct px_track *t, int fault)
{
	if (t) {
		t->fault = fault;
		t->heap_ok = 0; /* radii of the new regime */
		t->hot_ent = -1;
	}
}

void px__track_set_clock(struct px_track *t, int64_t (*fn)(void *), void *ctx)
{
	if (t)
		px__gov_set_clock(&t->gov, fn, ctx);
}

struct px_gov *px__track_gov(struct px_track *t)
{
	return t ? &t->gov : NULL;
}

double px__track_leaf_cert(const struct px_track *t, int leaf, px_vec3 p,
			   int which, int *ent, double *u0, double *u1,
			   unsigned *flags)
{
	const struct leaf *l;
	if (!t || leaf < 0 || leaf >= t->n_leaves)
		return -1.0;
	l = &t->leaf[leaf];
	*ent = l->ent;
	*u0 = l->u0;
	*u1 = l->u1;
	*flags = (l->flags & (LF_CUSP0 | LF_CUSP1)) ? 1u : 0u;
	if (which == 2) {
		/* the radius leaf_test() gives at the end of a step of
		 * length 0: the larger of the whole-leaf one and the one
		 * the piecewise proof gives (0 when that fails) */
		double rf = 0.0, rr = leaf_radius(t, l, p);
		if (leaf_event(t, l, p, p, &rf))
			rf = 0.0;
		if (t->fault & 128)
			rf *= 4.0;
		return rf > rr ? rf : rr;
	}
	return which ? leaf_end_radius(t, l, p) : leaf_radius(t, l, p);
}

int px_track_critical(const struct px_track *t, int entity, double *u,
		      int *type, int cap)
{
	const struct ent *e;
	int i;
	if (!t || (cap > 0 && (!u || !type)))
		return PX_E_INVAL;
	if (entity < 0 || entity >= t->n_ent)
		return PX_E_RANGE;
	ent_refresh((struct px_track *)t, &t->ent[entity]);
	e = &t->ent[entity];
	for (i = 0; i < e->nz && i < cap; i++) {
		u[i] = e->z[i].u;
		type[i] = e->z[i].type;
	}
	return e->nz;
}

void px_track_get_stats(const struct px_track *t, struct px_track_stats *s)
{
	if (!s)
		return;
	if (!t) {
		memset(s, 0, sizeof(*s));
		return;
	}
	*s = t->st;
	s->tracked_ns = t->gov.trk_ns;
	s->cold_ns = t->gov.cold_ns;
}

void px_track_get_info(const struct px_track *t, struct px_track_info *info)
{
	if (!info)
		return;
	memset(info, 0, sizeof(*info));
	if (!t)
		return;
	info->n_entities = t->n_ent;
	info->n_spans = t->n_spans;
	info->n_leaves = t->n_leaves;
	info->n_boxed_leaves = t->n_boxed;
	info->n_cells = t->n_prim;
	info->n_cusps = t->n_cusps;
	info->n_breaks = t->n_breaks;
	info->work = t->work;
	info->bytes = t->bytes;
}

struct px_dist_model *px_track_dist_model(struct px_track *t)
{
	return t ? t->dist : NULL;
}

/* ------------------------------------------------------------------ */
/* setup                                                               */

void px_track_opts_default(struct px_track_opts *o)
{
	if (!o)
		return;
	memset(o, 0, sizeof(*o));
	o->work.min = px_v3(1, 1, 1);
	o->work.max = px_v3(-1, -1, -1);
	o->work_margin = 1.0;
	o->max_crit = 64;
	o->leaves_per_span = 4;
	o->box_depth = 4;
	o->verify_every = 0;
	o->dist = NULL;
	o->lazy = 1;
	o->cold_switch = 1;
}

struct split {
	double u;
	int kind;
};

static double speed_at(const struct px_nurbs_curve *c, double u, int side)
{
	px_vec3 d[2];
	px_nurbs_curve_eval_side(c, u, side, 1, d);
	return px_v3_norm(d[1]);
}

/* Split points of one curve (interior knots with their continuity and
 * interior cusps), sorted, into out (cap). Returns the count. */
static int curve_splits(const struct px_nurbs_curve *c, struct split *out,
			int cap, int *n_cusps)
{
	int p = c->degree, n = c->n_ctrl, i, ns = 0, k;
	double a, b, vmax = 0.0;
	const double *U = c->knots;

	px_nurbs_curve_domain(c, &a, &b);
	for (i = p + 1; i < n; i++) {
		int m = 1;
		if (U[i] <= a || U[i] >= b || U[i] == U[i - 1])
			continue;
		while (i + m < n + p + 1 && U[i + m] == U[i])
			m++;
		if (ns < cap) {
			out[ns].u = U[i];
			out[ns].kind = m >= p ? K_C0 : (m == p - 1 ? K_C1 : K_SMOOTH);
			ns++;
		}
	}
	/* speed scale */
	for (k = 0; k <= ns; k++) {
		double s0 = k == 0 ? a : out[k - 1].u, s1 = k == ns ? b : out[k].u;
		for (i = 0; i <= 32; i++)
			vmax = fmax(vmax, speed_at(c, s0 + (s1 - s0) * i / 32.0,
						   i == 32 ? -1 : 1));
	}
	/* cusps: speed (almost) vanishing, at knots or inside spans */
	{
		int nsp = ns;
		for (k = 0; k <= nsp; k++) {
			double s0 = k == 0 ? a : out[k - 1].u,
			       s1 = k == nsp ? b : out[k].u, sp[33];
			for (i = 0; i <= 32; i++)
				sp[i] = speed_at(c, s0 + (s1 - s0) * i / 32.0,
						 i == 32 ? -1 : 1);
			if (k < nsp && (sp[32] <= 1e-7 * vmax ||
					speed_at(c, s1, 1) <= 1e-7 * vmax))
				out[k].kind = K_CUSP;
			for (i = 1; i < 32; i++) {
				double lo, hi, x1, x2, g = 0.6180339887498949;
				int it;
				if (!(sp[i] <= sp[i - 1] && sp[i] <= sp[i + 1] &&
				      sp[i] <= 1e-3 * vmax))
					continue;
				lo = s0 + (s1 - s0) * (i - 1) / 32.0;
				hi = s0 + (s1 - s0) * (i + 1) / 32.0;
				for (it = 0; it < 100; it++) {
					x1 = hi - g * (hi - lo);
					x2 = lo + g * (hi - lo);
					if (speed_at(c, x1, 1) < speed_at(c, x2, 1))
						hi = x2;
					else
						lo = x1;
				}
				x1 = 0.5 * (lo + hi);
				if (speed_at(c, x1, 1) <= 1e-7 * vmax &&
				    x1 > s0 + 1e-9 * (s1 - s0) &&
				    x1 < s1 - 1e-9 * (s1 - s0) && ns < cap) {
					out[ns].u = x1;
					out[ns].kind = K_CUSP;
					ns++;
				}
			}
		}
		/* sort */
		for (i = 1; i < ns; i++) {
			struct split s = out[i];
			for (k = i; k > 0 && out[k - 1].u > s.u; k--)
				out[k] = out[k - 1];
			out[k] = s;
		}
	}
	for (i = 0; i < ns; i++)
		if (out[i].kind == K_CUSP)
			(*n_cusps)++;
	return ns;
}

/* Bernstein g (a, b[3]) of a span's Bezier net hb[4][p+1]; degree 3p-1. */
static void span_g(int p, double hb[4][TRK_MAXD + 1], double *a,
		   double b[3][TRK_NG])
{
	double hd[4][TRK_MAXD + 1], k[3][2 * TRK_MAXD];
	double t1[PX_BERN_MAX_DEGREE + 1], t2[PX_BERN_MAX_DEGREE + 1];
	int c, j, n = 3 * p - 1;
	for (c = 0; c < 4; c++)
		px_bern_deriv(hb[c], p, hd[c]);
	for (c = 0; c < 3; c++) {
		px_bern_mul(hd[c], p - 1, hb[3], p, t1);
		px_bern_mul(hb[c], p, hd[3], p - 1, t2);
		for (j = 0; j < 2 * p; j++)
			k[c][j] = t1[j] - t2[j];
	}
	for (j = 0; j <= n; j++)
		a[j] = 0.0;
	for (c = 0; c < 3; c++) {
		px_bern_mul(hb[c], p, k[c], 2 * p - 1, t1);
		for (j = 0; j <= n; j++)
			a[j] += t1[j];
		px_bern_mul(hb[3], p, k[c], 2 * p - 1, b[c]);
	}
}

/* Octree exclusion: can the leaf have an event for some p in the cell? */
static int cell_range(const double *a, int m, px_vec3 c, px_vec3 r, int i,
		      double tol, double *lo, double *hi)
{
	const double *bx = a + m, *by = bx + m, *bz = by + m;
	double v = a[i] - (c.x * bx[i] + c.y * by[i] + c.z * bz[i]);
	double e = fabs(bx[i]) * r.x + fabs(by[i]) * r.y + fabs(bz[i]) * r.z;
	*lo = v - e - tol;
	*hi = v + e + tol;
	return 0;
}

static int cell_definite(const double *a, int m, px_vec3 c, px_vec3 r,
			 double tol)
{
	int i, pos = 0, neg = 0;
	for (i = 0; i < m; i++) {
		double lo, hi;
		cell_range(a, m, c, r, i, tol, &lo, &hi);
		if (lo > 0.0)
			pos++;
		else if (hi < 0.0)
			neg++;
		else
			return 0;
		if (pos && neg)
			return 0;
	}
	return 1;
}

static int cell_event(const struct px_track *t, const struct leaf *l,
		      px_vec3 c, px_vec3 r)
{
	const double *a = leaf_a(t, l);
	int n = l->n, i;
	if (cell_definite(a, n + 1, c, r, l->tol_g))
		return 0;
	for (i = 0; i < 2; i++) {
		double lo, hi;
		if (!(l->flags & (i ? LF_EV1 : LF_EV0)))
			continue;
		cell_range(a, n + 1, c, r, i ? n : 0, l->tol_g, &lo, &hi);
		if (lo <= 0.0 && hi >= 0.0)
			return 1;
	}
	if (n < 1)
		return 0;
	return !cell_definite(a + 4 * (n + 1), n, c, r, l->tol_d);
}

struct cellbuf {
	struct prim *p;
	long n, cap;
	int fail;
};

static void cell_push(struct cellbuf *cb, px_aabb box, int leaf)
{
	if (cb->n == cb->cap) {
		long nc = cb->cap ? 2 * cb->cap : 1024;
		struct prim *np = realloc(cb->p, (size_t)nc * sizeof(*np));
		if (!np) {
			cb->fail = 1;
			return;
		}
		cb->p = np;
		cb->cap = nc;
	}
	cb->p[cb->n].box = box;
	cb->p[cb->n].leaf = leaf;
	cb->n++;
}

/* Octree exclusion over the working volume: the cells at max_depth
 * where leaf li may have an event (a cell is also kept whole when the
 * budget runs out, which only makes the cover coarser). */
static void leaf_cells_rec(const struct px_track *t, int li, px_aabb cell,
			   int depth, int max_depth, struct cellbuf *cb,
			   long *budget)
{
	const struct leaf *l = &t->leaf[li];
	px_vec3 c = px_aabb_center(&cell);
	px_vec3 r = px_v3_scale(px_v3_sub(cell.max, cell.min), 0.5);
	int k;
	if (!cell_event(t, l, c, r))
		return;
	if (depth >= max_depth || --(*budget) <= 0) {
		cell_push(cb, cell, li);
		return;
	}
	for (k = 0; k < 8; k++) {
		px_aabb ch;
		ch.min = px_v3(k & 1 ? c.x : cell.min.x, k & 2 ? c.y : cell.min.y,
			       k & 4 ? c.z : cell.min.z);
		ch.max = px_v3(k & 1 ? cell.max.x : c.x, k & 2 ? cell.max.y : c.y,
			       k & 4 ? cell.max.z : c.z);
		leaf_cells_rec(t, li, ch, depth + 1, max_depth, cb, budget);
	}
}


void px_track_free(struct px_track *t)
{
	int i;
	if (!t)
		return;
	px_dist_model_free(t->dist);
	if (t->ent)
		for (i = 0; i < t->n_ent; i++) {
			free(t->ent[i].z);
			free(t->ent[i].old);
		}
	free(t->ent);
	free(t->span);
	free(t->leaf);
	free(t->pool);
	free(t->cand);
	free(t->cexp);
	free(t->hits);
	free(t->expiry);
	free(t->ectr);
	free(t->erad);
	free(t->rmin);
	free(t->gdue);
	free(t->ipool);
	free(t);
}

int px_track_create(const struct px_nurbs_curve *curves, int n_curves,
		    const struct px_track_opts *opts, struct px_track **out)
{
	struct px_track *t;
	struct px_track_opts o;
	struct split *spl = NULL;
	double *work = NULL;
	size_t work_len = 0, pool_cap = 0;
	int rc, i, j, k, span_cap = 0, leaf_cap = 0, cand_cap = 0, max_ctrl = 0;
	px_aabb bounds;

	if (!out || !curves || n_curves <= 0)
		return PX_E_INVAL;
	*out = NULL;
	if (opts)
		o = *opts;
	else
		px_track_opts_default(&o);
	if (o.max_crit < 2 || o.max_crit > 1 << 20 || o.leaves_per_span < 1 ||
	    o.leaves_per_span > 64 || o.box_depth < 0 || o.box_depth > 7 ||
	    o.verify_every < 0 || !(o.work_margin >= 0.0))
		return PX_E_INVAL;
	for (i = 0; i < n_curves; i++) {
		if (curves[i].degree < 1 || curves[i].degree > TRK_MAXD)
			return PX_E_RANGE;
		if (!curves[i].knots || !curves[i].pw)
			return PX_E_INVAL;
		if (curves[i].n_ctrl > max_ctrl)
			max_ctrl = curves[i].n_ctrl;
		/* spans: knots + cusps (bounded by 32 per span) */
		span_cap += (curves[i].n_ctrl + 1) * 34 + 2;
	}
	t = calloc(1, sizeof(*t));
	if (!t)
		return PX_E_NOMEM;
	t->opts = o;
	rc = px_dist_model_create(curves, n_curves, NULL, 0, o.dist, &t->dist);
	if (rc) {
		free(t);
		return rc;
	}
	t->n_ent = n_curves;
	t->ent = calloc((size_t)n_curves, sizeof(*t->ent));
	t->span = calloc((size_t)span_cap, sizeof(*t->span));
	spl = calloc((size_t)span_cap, sizeof(*spl));
	work_len = PX_NURBS_CURVE_WORK_LEN(TRK_MAXD, max_ctrl);
	work = calloc(work_len, sizeof(double));
	if (!t->ent || !t->span || !spl || !work) {
		rc = PX_E_NOMEM;
		goto fail;
	}

	/* spans and entity layout */
	bounds = px_aabb_empty();
	for (i = 0; i < n_curves; i++) {
		const struct px_nurbs_curve *c = &curves[i];
		struct ent *e = &t->ent[i];
		int ns, seam, p = c->degree;
		px_aabb hull = px_nurbs_curve_aabb(c);
		double a, b;

		px_aabb_extend(&bounds, hull.min);
		px_aabb_extend(&bounds, hull.max);
		px_nurbs_curve_domain(c, &a, &b);
		e->u0 = a;
		e->u1 = b;
		e->len = b - a;
		seam = px_nurbs_curve_seam(c, 1e-12 * (1.0 + px_aabb_diagonal(&hull)),
					   1e-9);
		e->cyclic = seam >= 1;
		ns = curve_splits(c, spl, span_cap - t->n_spans - 2, &t->n_cusps);
		e->first_span = t->n_spans;
		for (k = 0; k <= ns; k++) {
			double s0 = k == 0 ? a : spl[k - 1].u, s1 = k == ns ? b : spl[k].u;
			struct px_nurbs_curve sub;
			struct span *s = &t->span[t->n_spans];
			double hb[4][TRK_MAXD + 1];
			int q, jj;
			if (!(s1 > s0))
				continue;
			rc = px_nurbs_curve_extract_work(c, s0, s1, work, work_len, &sub);
			if (rc)
				goto fail;
			if (sub.n_ctrl != p + 1) {
				rc = PX_E_INVAL;
				goto fail;
			}
			s->u0 = s0;
			s->u1 = s1;
			s->inv = 1.0 / (s1 - s0);
			s->deg = p;
			for (q = 0; q <= p; q++)
				for (jj = 0; jj < 4; jj++)
					hb[jj][q] = sub.pw[4 * q + jj];
			for (jj = 0; jj < 4; jj++)
				for (q = 0; q <= p; q++) {
					double v = 0.0;
					int r;
					for (r = 0; r <= q; r++)
						v += (((q - r) & 1) ? -1.0 : 1.0) *
						     px_bern_binom(q, r) * hb[jj][r];
					s->pc[jj][q] = px_bern_binom(p, q) * v;
				}
			{
				double sc = 1.0;
				for (q = 0; q <= p; q++) {
					for (jj = 0; jj < 4; jj++)
						s->pu[jj][q] = s->pc[jj][q] * sc;
					sc *= s->inv;
				}
				s->rat = 0;
				for (q = 0; q <= p; q++)
					if (s->pc[3][q] != (q == 0 ? 1.0 : 0.0))
						s->rat = 1;
#if TRK_VEC
				for (jj = 0; jj < 4; jj++) {
					const double *w = s->pu[jj];
					int m = jj / 2, l2 = jj % 2;
					for (q = 0; q < 4; q++)
						s->hv[q][m][l2] = w[q];
					s->hd1[0][m][l2] = w[1];
					s->hd1[1][m][l2] = 2.0 * w[2];
					s->hd1[2][m][l2] = 3.0 * w[3];
					s->hd2[0][m][l2] = 2.0 * w[2];
					s->hd2[1][m][l2] = 6.0 * w[3];
				}
#endif
			}
			t->n_spans++;
		}
		e->n_spans = t->n_spans - e->first_span;
		/* kinds at span starts: record in a parallel pass below */
		(void)seam;
		e->cap = o.max_crit;
		e->z = calloc((size_t)o.max_crit, sizeof(*e->z));
		e->old = calloc((size_t)o.max_crit, sizeof(*e->old));
		if (!e->z || !e->old) {
			rc = PX_E_NOMEM;
			goto fail;
		}
		leaf_cap += e->n_spans * o.leaves_per_span;
		cand_cap += ns + 2;
		for (k = 0; k < e->n_spans; k++) {
			int n = 3 * p - 1;
			pool_cap += (size_t)o.leaves_per_span *
				    (size_t)(4 * (n + 1) + 4 * n);
		}
	}
	t->scale = px_aabb_diagonal(&bounds);
	if (!(t->scale > 0.0))
		t->scale = 1.0;
	if (o.work.min.x <= o.work.max.x && o.work.min.y <= o.work.max.y &&
	    o.work.min.z <= o.work.max.z) {
		t->work = o.work;
	} else {
		double m = o.work_margin * t->scale;
		t->work.min = px_v3_sub(bounds.min, px_v3(m, m, m));
		t->work.max = px_v3_add(bounds.max, px_v3(m, m, m));
	}

	t->leaf = calloc((size_t)leaf_cap, sizeof(*t->leaf));
	t->pool = calloc(pool_cap ? pool_cap : 1, sizeof(double));
	t->cand = calloc((size_t)cand_cap + 1, sizeof(*t->cand));
	t->cexp = calloc((size_t)cand_cap + 1, sizeof(*t->cexp));
	t->hits = calloc((size_t)leaf_cap + 1, sizeof(int));
	t->expiry = calloc((size_t)leaf_cap + 1, sizeof(double));
	t->ectr = calloc((size_t)leaf_cap + 1, sizeof(*t->ectr));
	t->erad = calloc((size_t)leaf_cap + 1, sizeof(double));
	t->gdue = calloc((size_t)leaf_cap / TRK_GROUP + 2, sizeof(double));
	t->ipool = calloc((size_t)leaf_cap * (2 * TRK_NG + 2) + 1, sizeof(double));
	if (!t->leaf || !t->pool || !t->cand || !t->cexp || !t->hits ||
	    !t->expiry || !t->ectr || !t->erad || !t->gdue ||
	    !t->ipool) {
		rc = PX_E_NOMEM;
		goto fail;
	}

	/* leaves, candidates */
	for (i = 0; i < n_curves; i++) {
		const struct px_nurbs_curve *c = &curves[i];
		struct ent *e = &t->ent[i];
		int ns, p = c->degree, seam, nc0 = 0;
		px_aabb hull = px_nurbs_curve_aabb(c);
		double wmax = fmax(fmax(fabs(t->work.min.x), fabs(t->work.max.x)),
				   fmax(fmax(fabs(t->work.min.y), fabs(t->work.max.y)),
					fmax(fabs(t->work.min.z), fabs(t->work.max.z))));

		ns = curve_splits(c, spl, span_cap, &nc0);
		seam = px_nurbs_curve_seam(c, 1e-12 * (1.0 + px_aabb_diagonal(&hull)),
					   1e-9);
		e->first_leaf = t->n_leaves;
		e->first_cand = t->n_cand;
		/* candidates: open ends, cornered seam, C0 breaks, cusps */
		if (seam < 0) {
			struct cand *cd = &t->cand[t->n_cand++];
			cd->q = px_nurbs_curve_point(c, e->u0);
			cd->u = e->u0;
			cd->ent = i;
			cd->kind = PX_TRACK_END;
			cd = &t->cand[t->n_cand++];
			cd->q = px_nurbs_curve_point(c, e->u1);
			cd->u = e->u1;
			cd->ent = i;
			cd->kind = PX_TRACK_END;
		} else if (seam == 0) {
			struct cand *cd = &t->cand[t->n_cand++];
			cd->q = px_nurbs_curve_point(c, e->u0);
			cd->u = e->u0;
			cd->ent = i;
			cd->kind = PX_TRACK_BREAK;
		}
		for (k = 0; k < ns; k++) {
			if (spl[k].kind == K_C0 || spl[k].kind == K_CUSP) {
				struct cand *cd = &t->cand[t->n_cand++];
				cd->q = px_nurbs_curve_point(c, spl[k].u);
				cd->u = spl[k].u;
				cd->ent = i;
				cd->kind = PX_TRACK_BREAK;
			}
			if (spl[k].kind != K_SMOOTH)
				t->n_breaks++;
		}
		e->n_cand = t->n_cand - e->first_cand;

		for (k = 0; k < e->n_spans; k++) {
			const struct span *s = &t->span[e->first_span + k];
			int kind0 = K_SMOOTH, kind1 = K_SMOOTH, q, jj, L;
			double hb[4][TRK_MAXD + 1], ga[TRK_NG], gb[3][TRK_NG];
			int n = 3 * p - 1;
			/* kinds of the span's ends */
			for (q = 0; q < ns; q++) {
				if (spl[q].u == s->u0)
					kind0 = spl[q].kind;
				if (spl[q].u == s->u1)
					kind1 = spl[q].kind;
			}
			if (k == 0)
				kind0 = seam >= 2 ? K_SMOOTH : seam == 1 ? K_C1 : K_C0;
			if (k == e->n_spans - 1)
				kind1 = seam >= 2 ? K_SMOOTH : seam == 1 ? K_C1 : K_C0;
			/* Bernstein net back from the power basis */
			for (jj = 0; jj < 4; jj++)
				for (q = 0; q <= p; q++) {
					double v = 0.0;
					int r;
					for (r = 0; r <= q; r++)
						v += px_bern_binom(q, r) /
						     px_bern_binom(p, r) * s->pc[jj][r];
					hb[jj][q] = v;
				}
			span_g(p, hb, ga, gb);
			for (L = 0; L < o.leaves_per_span; L++) {
				struct leaf *l = &t->leaf[t->n_leaves];
				double t0 = (double)L / o.leaves_per_span,
				       t1 = (double)(L + 1) / o.leaves_per_span;
				double *a = t->pool + t->pool_len, *b;
				int m = n, cc;
				l->u0 = s->u0 + (s->u1 - s->u0) * t0;
				l->u1 = L == o.leaves_per_span - 1
						? s->u1
						: s->u0 + (s->u1 - s->u0) * t1;
				l->ent = i;
				l->span = e->first_span + k;
				l->off = t->pool_len;
				b = a + n + 1;
				px_bern_restrict(ga, n, t0, t1, a);
				for (cc = 0; cc < 3; cc++)
					px_bern_restrict(gb[cc], n, t0, t1,
							 b + cc * (n + 1));
				if (L == 0 && kind0 == K_CUSP) {
					l->flags |= LF_CUSP0;
					bern_divide(a, m, 0);
					for (cc = 0; cc < 3; cc++)
						bern_divide(b + cc * (n + 1), m, 0);
					m--;
				}
				if (L == o.leaves_per_span - 1 && kind1 == K_CUSP &&
				    m >= 1) {
					l->flags |= LF_CUSP1;
					bern_divide(a, m, 1);
					for (cc = 0; cc < 3; cc++)
						bern_divide(b + cc * (n + 1), m, 1);
					m--;
				}
				/* compact to stride m + 1 */
				if (m != n) {
					double tmp[4 * (TRK_NG + 1)];
					for (cc = 0; cc < 4; cc++)
						memcpy(tmp + cc * (m + 1),
						       a + cc * (n + 1),
						       (size_t)(m + 1) * sizeof(double));
					memcpy(a, tmp, (size_t)(4 * (m + 1)) * sizeof(double));
				}
				l->n = m;
				/* derivative coefficients */
				{
					double *da = a + 4 * (m + 1);
					if (m >= 1)
						for (cc = 0; cc < 4; cc++)
							px_bern_deriv(a + cc * (m + 1), m,
								      da + cc * m);
				}
				/* tolerances: rounding of the affine forms */
				{
					double tg = 0.0, td = 0.0;
					for (q = 0; q <= m; q++) {
						double s2 = fabs(a[q]) +
							    wmax * (fabs(a[m + 1 + q]) +
								    fabs(a[2 * (m + 1) + q]) +
								    fabs(a[3 * (m + 1) + q]));
						tg = fmax(tg, s2);
					}
					for (q = 0; q < m; q++) {
						const double *da = a + 4 * (m + 1);
						double s2 = fabs(da[q]) +
							    wmax * (fabs(da[m + q]) +
								    fabs(da[2 * m + q]) +
								    fabs(da[3 * m + q]));
						td = fmax(td, s2);
					}
					l->tol_g = 1e-12 * tg;
					l->tol_d = 1e-12 * td;
				}
				/* inverse norms of the p-gradients of the
				 * coefficients (safe radii); 0 for a constant */
				{
					double *ib = t->ipool + (size_t)t->n_leaves *
								       (2 * TRK_NG + 2);
					const double *da = a + 4 * (m + 1);
					l->ioff = (size_t)t->n_leaves * (2 * TRK_NG + 2);
					for (q = 0; q <= m; q++) {
						double nb = sqrt(a[m + 1 + q] * a[m + 1 + q] +
								 a[2 * (m + 1) + q] * a[2 * (m + 1) + q] +
								 a[3 * (m + 1) + q] * a[3 * (m + 1) + q]);
						ib[q] = nb > 0.0 ? 1.0 / nb : INFINITY;
					}
					for (q = 0; q < m; q++) {
						double nb = sqrt(da[m + q] * da[m + q] +
								 da[2 * m + q] * da[2 * m + q] +
								 da[3 * m + q] * da[3 * m + q]);
						ib[m + 1 + q] = nb > 0.0 ? 1.0 / nb : INFINITY;
					}
				}
				t->pool_len += (size_t)(4 * (m + 1) + 4 * m);
				if (L == 0 && kind0 != K_SMOOTH)
					l->flags |= LF_EV0;
				if (L == o.leaves_per_span - 1 && kind1 != K_SMOOTH)
					l->flags |= LF_EV1;
				if (L == 0 && (kind0 == K_C0 || kind0 == K_CUSP))
					l->flags |= LF_SB0;
				if (L == o.leaves_per_span - 1 &&
				    (kind1 == K_C0 || kind1 == K_CUSP))
					l->flags |= LF_SB1;
				t->n_leaves++;
			}
		}
		e->n_leaves = t->n_leaves - e->first_leaf;
		if (!e->cyclic) {
			/* open or cornered: parameters do not wrap */
			t->leaf[e->first_leaf].flags |= LF_EV0 | LF_SB0;
			t->leaf[t->n_leaves - 1].flags |= LF_EV1 | LF_SB1;
		}
		for (k = 0; k < e->n_leaves; k++)
			if (t->leaf[e->first_leaf + k].flags & LF_SB0)
				e->n_sb++;
	}

	/* event cells: octree exclusion per leaf down to box_depth; their
	 * union box per leaf bounds its safe radius */
	{
		struct cellbuf cb = {0};
		long q;
		for (i = 0; i < t->n_leaves; i++) {
			long budget = 1L << 14, first = cb.n;
			struct leaf *l = &t->leaf[i];
			leaf_cells_rec(t, i, t->work, 0, o.box_depth, &cb, &budget);
			if (cb.fail) {
				free(cb.p);
				rc = PX_E_NOMEM;
				goto fail;
			}
			l->box = px_aabb_empty();
			for (q = first; q < cb.n; q++) {
				px_aabb_extend(&l->box, cb.p[q].box.min);
				px_aabb_extend(&l->box, cb.p[q].box.max);
			}
			if (cb.n > first) {
				l->boxed = 1;
				t->n_boxed++;
			}
		}
		t->n_prim = (int)cb.n;
		free(cb.p);
	}

	t->bytes = sizeof(*t) + (size_t)t->n_ent * sizeof(*t->ent) +
		   (size_t)t->n_ent * 2 * (size_t)o.max_crit * sizeof(struct zero) +
		   (size_t)span_cap * sizeof(*t->span) +
		   (size_t)leaf_cap * (sizeof(*t->leaf) + 2 * sizeof(int) +
				       (2 * TRK_NG + 2) * sizeof(double)) +
		   pool_cap * sizeof(double) +
		   (size_t)(cand_cap + 1) * (sizeof(*t->cand) + sizeof(double));
	t->epoch = 1;
	t->hot_ent = -1;
	t->ans_z = -1;
	t->ans_c = -1;
	t->hot_c = -1;
	t->n_crit_cap = n_curves * o.max_crit;
	t->rmin = calloc((size_t)t->n_crit_cap * 2 + 2, sizeof(int));
	if (!t->rmin) {
		rc = PX_E_NOMEM;
		goto fail;
	}
	t->prev.ent = -1;
	{
		/* the cold query's cost where a tool works: about the
		 * model, not the whole working volume */
		px_aabb cb = bounds;
		double m = 0.3 * t->scale;
		cb.min = px_v3_sub(cb.min, px_v3(m, m, m));
		cb.max = px_v3_add(cb.max, px_v3(m, m, m));
		px__gov_init(&t->gov, o.cold_switch != 0,
			     o.cold_switch ? px__gov_calibrate(t->dist, cb) : 1.0);
	}
	free(spl);
	free(work);
	(void)j;
	*out = t;
	return PX_OK;
fail:
	free(spl);
	free(work);
	px_track_free(t);
	return rc;
}
