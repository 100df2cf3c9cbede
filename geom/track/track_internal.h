/*
 * track_internal.h - the curve tracker's private layout, shared by its
 * files (geom/track/track_*.c). Not installed, not part of the API.
 *
 * How it tracks the point-curve critical distances:
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
 * Surfaces are tracked by strack_*.c, which hand their edges and creases
 * to this tracker as curves.
 */
#ifndef PX_TRACK_INTERNAL_H
#define PX_TRACK_INTERNAL_H

#include "px_track.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "gov_internal.h"
#include "math_internal.h"
#include "track_hooks.h"
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

/* ---- functions shared between the files, by the file that defines them ---- */

/* track_eval.c */
void px__tk_bern_divide(double *c, int n, int end);
int px__tk_leaf_roots(const struct px_track *t, const struct leaf *l,
		      px_vec3 p, double *u, int *type, int cap);

/* track_crit.c */
int px__tk_add_leaf_roots(struct px_track *t, struct ent *e, int li, px_vec3 p);
int px__tk_ent_check(const struct px_track *t, const struct ent *e, px_vec3 p);
int px__tk_ent_dups(const struct ent *e);
int px__tk_ent_reinit(struct px_track *t, struct ent *e, px_vec3 p);
int px__tk_evolve(struct px_track *t, struct ent *e, struct zero *z,
		  px_vec3 p0, px_vec3 dp, px_vec3 p);
double px__tk_leaf_end_radius(const struct px_track *t, const struct leaf *l,
			      px_vec3 p);
void px__tk_sort_zeros(struct ent *e);

/* track_event.c */
double px__tk_box_dist(const px_aabb *b, px_vec3 p);
void px__tk_heap_rebuild(struct px_track *t, px_vec3 p);
double px__tk_leaf_dradius(const struct px_track *t, const struct leaf *l,
			   px_vec3 p);
int px__tk_leaf_event(const struct px_track *t, const struct leaf *l,
		      px_vec3 p0, px_vec3 p1, double *rfine);
double px__tk_leaf_radius(const struct px_track *t, const struct leaf *l,
			  px_vec3 p);

/* track_update.c */
void px__tk_ent_refresh(struct px_track *t, struct ent *e);

/* ---- functions of the hot path, inline in every file that calls them ---- */

/* C, C', C'' at u from the span's power-basis table: for degree <= 3 one
 * unrolled Horner per coordinate (a few dozen flops), homogeneous
 * quotient rule only for rational spans. */
static inline __attribute__((always_inline)) void
span_eval(const struct span *s, double u, px_vec3 *c, px_vec3 *d1, px_vec3 *d2)
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
static inline const struct span *find_span(const struct px_track *t,
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

/*
 * The exact test of leaf l along p0 -> p1 (*event: 1 when it may hold an
 * event, as leaf_event()) and its safe radius at p1 (as leaf_radius()).
 * The usual leaf - no root, coefficients of g of one sign along the
 * whole step - is done in one pass over its coefficients.
 */
static inline double leaf_test(const struct px_track *t, const struct leaf *l,
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
		rb = px__tk_box_dist(&l->box, p1);
		if (rb > r)
			r = rb;
		rd = px__tk_leaf_dradius(t, l, p1);
		return rd > r ? rd : r;
	}
	{
		double rf, rr;
		*event = px__tk_leaf_event(t, l, p0, p1, &rf);
		rr = px__tk_leaf_radius(t, l, p1);
		return (t->fault & 4) || rf < rr ? rr : rf;
	}
}

static inline void mark_leaf(struct px_track *t, int li, int *nh)
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
static inline int collect_events(struct px_track *t, px_vec3 p0, px_vec3 p1,
			  double len)
{
	int nh = 0, k, n = t->n_leaves;

	if (!t->heap_ok)
		px__tk_heap_rebuild(t, p0);
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

#endif
