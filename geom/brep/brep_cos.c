/*
 * brep_cos.c - curve-on-surface edge candidates: the image S(c(t)) of a
 * loop curve whose exact NURBS image (brep_compose.c) would exceed the
 * kernel's degree (a cubic trim on a bicubic surface: 18), kept as its
 * own rational Bezier pieces of degree up to BREP_COS_MAX_DEGREE and
 * solved here with the distance core's certified scheme.
 *
 * For a piece C = H / w (homogeneous H of degree D, weight w > 0) and a
 * query point P, with E = H - w P:
 *   F = |E|^2 = w^2 |C - P|^2        (degree 2D)
 *   g = E . (H' w - H w') = w^3 (C - P) . C'   (degree 3D - 1)
 * (2D - 1 and g = E . H' when every weight is equal: w is divided out).
 * K = H' w - H w' is made once at setup; a query forms E, F and g by
 * Bernstein products (binomial-scaled convolutions) from it. An interval
 * of the piece is pruned when min F_i / W_i (W = w^2; a convex
 * combination bounds F / W from below) reaches the best; else the sign
 * changes of g restricted to it decide: none, or one from + to -, leave
 * the minimum at an end of the interval (taken); one from - to + is one
 * interior minimum (found by a bracketed secant iteration on g); more
 * are split. The pieces' end points are always candidates. Work is
 * bounded by depth and node counts; an interval cut short marks the
 * answer uncertified with its gap, as the core's solvers do.
 *
 * Setup allocates (px__brep_cos_add()); queries use a fixed stack and
 * never touch the heap.
 */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "brep_internal.h"
#include "px_bern.h"

#ifdef PX_TEST_HOOKS
int px__brep_force_cos = 0;
#endif

#define CD BREP_COS_MAX_DEGREE
#define CG (3 * CD - 1)         /* highest degree of g */
#define CF (2 * CD)             /* degree of F and W at CD */
#define COS_MAX_DEPTH 46
#define COS_MAX_NODES 400
#define COS_MAX_ITERS 80

/* Per piece in coef (at off), in this order: hx, hy, hz, w (deg + 1
 * each, homogeneous Bernstein coefficients); kb (3 runs of gdeg - deg +
 * 1: K times C(gdeg - deg, j)); W (2 deg + 1; rational pieces only);
 * bd (C(deg, i)); ibf (1 / C(2 deg, k)); ibg (1 / C(gdeg, k)); gbin
 * (C(gdeg, k), for evaluating g). */
static size_t piece_doubles(int deg, int gdeg, int wconst)
{
	return 4 * (size_t)(deg + 1) + 3 * (size_t)(gdeg - deg + 1) +
	       (wconst ? 0 : (size_t)(2 * deg + 1)) + (size_t)(deg + 1) +
	       (size_t)(2 * deg + 1) + 2 * (size_t)(gdeg + 1);
}

static double binom(int n, int k)
{
	double r = 1.0;
	int i;
	if (k < 0 || k > n)
		return 0.0;
	if (k > n - k)
		k = n - k;
	for (i = 1; i <= k; i++)
		r = r * (double)(n - k + i) / (double)i;
	return r;
}

/* Bernstein product (setup only; degrees within CG). */
static void bmul(const double *a, int na, const double *b, int nb, double *out)
{
	int i, j;
	for (i = 0; i <= na + nb; i++)
		out[i] = 0.0;
	for (i = 0; i <= na; i++)
		for (j = 0; j <= nb; j++)
			out[i + j] += binom(na, i) * binom(nb, j) * a[i] * b[j];
	for (i = 0; i <= na + nb; i++)
		out[i] /= binom(na + nb, i);
}

void px__brep_cos_free(struct brep_cos_set *s)
{
	if (!s)
		return;
	free(s->cos);
	free(s->pc);
	free(s->coef);
	free(s);
}

/* Room for one more piece of n doubles and one more edge. */
static int grow(struct brep_cos_set *s, size_t n)
{
	if (s->n_pc == s->cap_pc) {
		int cap = s->cap_pc ? 2 * s->cap_pc : 16;
		struct brep_cos_piece *pc = realloc(s->pc, (size_t)cap * sizeof(*pc));
		if (!pc)
			return PX_E_NOMEM;
		s->pc = pc;
		s->cap_pc = cap;
	}
	if (s->n_coef + n > s->cap_coef) {
		size_t cap = 2 * (s->cap_coef + n);
		double *c = realloc(s->coef, cap * sizeof(double));
		if (!c)
			return PX_E_NOMEM;
		s->coef = c;
		s->cap_coef = cap;
	}
	return PX_OK;
}

/* One piece: deg + 1 homogeneous points hw (x w, y w, z w, w) on the
 * loop-curve parameters [t0, t1]. */
static int add_piece(struct brep_cos_set *s, int deg, const double *hw,
		     double scale, double t0, double t1)
{
	double k[3][2 * CD], hd[4][CD], t[CG + 1];
	struct brep_cos_piece *p;
	double *h, *kb, *W, *bd, *ibf, *ibg, *gb, w0 = hw[3];
	int i, c, j, wconst = 1, gdeg, kd, rc;

	for (i = 0; i <= deg; i++) {
		if (!(hw[4 * i + 3] > 0.0) || !isfinite(hw[4 * i]) ||
		    !isfinite(hw[4 * i + 1]) || !isfinite(hw[4 * i + 2]))
			return PX_E_RANGE;
		wconst &= hw[4 * i + 3] == w0;
	}
	gdeg = wconst ? 2 * deg - 1 : 3 * deg - 1;
	kd = gdeg - deg;
	rc = grow(s, piece_doubles(deg, gdeg, wconst));
	if (rc)
		return rc;
	p = &s->pc[s->n_pc];
	memset(p, 0, sizeof(*p));
	p->deg = deg;
	p->gdeg = gdeg;
	p->wconst = wconst;
	p->t0 = t0;
	p->t1 = t1;
	p->cos = s->n_cos;
	p->off = s->n_coef;
	h = s->coef + p->off;
	kb = h + 4 * (deg + 1);
	W = kb + 3 * (kd + 1);
	bd = W + (wconst ? 0 : 2 * deg + 1);
	ibf = bd + deg + 1;
	ibg = ibf + 2 * deg + 1;
	gb = ibg + gdeg + 1;
	p->box = px_aabb_empty();
	for (i = 0; i <= deg; i++) {
		double wi = wconst ? 1.0 : hw[4 * i + 3], f = wconst ? scale / w0 : scale;
		for (c = 0; c < 3; c++)
			h[c * (deg + 1) + i] = hw[4 * i + c] * f;
		h[3 * (deg + 1) + i] = wi;
		px_aabb_extend(&p->box, px_v3(h[i] / wi, h[deg + 1 + i] / wi,
					      h[2 * (deg + 1) + i] / wi));
	}
	for (c = 0; c < 4; c++)
		px_bern_deriv(h + c * (deg + 1), deg, hd[c]);
	/* K = H' w - H w' (H' when w is 1) */
	for (c = 0; c < 3; c++) {
		if (wconst) {
			memcpy(k[c], hd[c], (size_t)deg * sizeof(double));
			continue;
		}
		bmul(hd[c], deg - 1, h + 3 * (deg + 1), deg, k[c]);
		bmul(h + c * (deg + 1), deg, hd[3], deg - 1, t);
		for (j = 0; j <= kd; j++)
			k[c][j] -= t[j];
	}
	for (c = 0; c < 3; c++)
		for (j = 0; j <= kd; j++)
			kb[c * (kd + 1) + j] = k[c][j] * binom(kd, j);
	if (!wconst)
		bmul(h + 3 * (deg + 1), deg, h + 3 * (deg + 1), deg, W);
	for (i = 0; i <= deg; i++)
		bd[i] = binom(deg, i);
	for (i = 0; i <= 2 * deg; i++)
		ibf[i] = 1.0 / binom(2 * deg, i);
	for (i = 0; i <= gdeg; i++) {
		gb[i] = binom(gdeg, i);
		ibg[i] = 1.0 / gb[i];
	}
	s->n_coef += piece_doubles(deg, gdeg, wconst);
	s->n_pc++;
	return PX_OK;
}

int px__brep_cos_add(struct brep_cos_set *s, int face, int co, int deg,
		     int n_pc, const double *pw, const double *brk, double scale)
{
	int i, rc;
	if (deg < 1 || deg > CD || n_pc < 1)
		return PX_E_RANGE;
	if (s->n_cos == s->cap_cos) {
		int cap = s->cap_cos ? 2 * s->cap_cos : 8;
		struct brep_cos *c = realloc(s->cos, (size_t)cap * sizeof(*c));
		if (!c)
			return PX_E_NOMEM;
		s->cos = c;
		s->cap_cos = cap;
	}
	s->cos[s->n_cos].face = face;
	s->cos[s->n_cos].co = co;
	s->cos[s->n_cos].first = s->n_pc;
	for (i = 0; i < n_pc; i++) {
		rc = add_piece(s, deg, pw + 4 * (size_t)i * deg, scale, brk[i],
			       brk[i + 1]);
		if (rc)
			return rc;
	}
	s->cos[s->n_cos].n = n_pc;
	s->cos[s->n_cos].t0 = brk[0];
	s->cos[s->n_cos].t1 = brk[n_pc];
	s->n_cos++;
	return PX_OK;
}

/* ---- queries ------------------------------------------------------------- */

/* Restriction of c (degree n) to [a, b] within [0, 1] into out (two de
 * Casteljau passes). */
static void restrict_to(const double *c, int n, double a, double b, double *out)
{
	int i, k;
	memcpy(out, c, (size_t)(n + 1) * sizeof(double));
	if (b < 1.0) /* left part of the split at b, in place */
		for (k = 1; k <= n; k++)
			for (i = n; i >= k; i--)
				out[i] = (1.0 - b) * out[i - 1] + b * out[i];
	if (a > 0.0) {
		double s = b < 1.0 ? a / b : a;
		for (k = 1; k <= n; k++)
			for (i = 0; i <= n - k; i++)
				out[i] = (1.0 - s) * out[i] + s * out[i + 1];
	}
}

/* Value of c (degree n, binomials bn) at s: scaled Horner. */
static double eval_at(const double *c, const double *bn, int n, double s)
{
	double base, r, acc, sc = 1.0;
	int i;
	if (s <= 0.5) {
		base = 1.0 - s;
		r = s / base;
		acc = c[n] * bn[n];
		for (i = n - 1; i >= 0; i--)
			acc = acc * r + c[i] * bn[i];
	} else {
		base = s;
		r = (1.0 - s) / s;
		acc = c[0] * bn[0];
		for (i = 1; i <= n; i++)
			acc = acc * r + c[i] * bn[i];
	}
	for (i = 0; i < n; i++)
		sc *= base;
	return acc * sc;
}

/* Cartesian point of piece p at local s. */
static px_vec3 piece_point(const struct brep_cos_set *s,
			   const struct brep_cos_piece *p, double t)
{
	const double *h = s->coef + p->off;
	int n = p->deg;
	double w = px_bern_eval(h + 3 * (n + 1), n, t);
	return px_v3(px_bern_eval(h, n, t) / w, px_bern_eval(h + n + 1, n, t) / w,
		     px_bern_eval(h + 2 * (n + 1), n, t) / w);
}

/* What one piece's solve keeps: the best squared distance and where. */
struct cos_best {
	double d2, s;
	int found, certified;
	double gap2;
};

static void take(const struct brep_cos_set *s, const struct brep_cos_piece *p,
		 px_vec3 q, double t, struct cos_best *b)
{
	double d2 = px_v3_dist2(piece_point(s, p, t), q);
	if (d2 < b->d2) {
		b->d2 = d2;
		b->s = t;
		b->found = 1;
	}
}

/* The one root of g (degree n, g[0] < 0 < g[n]) in (0, 1): Illinois
 * steps on the bracket. */
static double root_of(const double *g, const double *bn, int n)
{
	double lo = 0.0, hi = 1.0, flo = g[0], fhi = g[n], x = 0.5;
	int it, side = 0;
	for (it = 0; it < COS_MAX_ITERS && hi - lo > 4.0 * DBL_EPSILON; it++) {
		double fx;
		x = (lo * fhi - hi * flo) / (fhi - flo);
		if (!(x > lo && x < hi))
			x = 0.5 * (lo + hi);
		fx = eval_at(g, bn, n, x);
		if (fx == 0.0)
			break;
		if (fx < 0.0) {
			lo = x;
			flo = fx;
			if (side == -1)
				fhi *= 0.5;
			side = -1;
		} else {
			hi = x;
			fhi = fx;
			if (side == 1)
				flo *= 0.5;
			side = 1;
		}
	}
	return x;
}

/* Sign changes of c[0..n] (zeros skipped); *first, *last the first and
 * last nonzero signs. */
static int sign_changes(const double *c, int n, int *first, int *last)
{
	int i, sc = 0, prev = 0;
	*first = 0;
	for (i = 0; i <= n; i++) {
		int sg = (c[i] > 0.0) - (c[i] < 0.0);
		if (!sg)
			continue;
		if (!*first)
			*first = sg;
		if (prev && sg != prev)
			sc++;
		prev = sg;
	}
	*last = prev;
	return sc;
}

/* F, W and g of piece p for the query q (binomial-scaled products). */
static void forms(const struct brep_cos_set *s, const struct brep_cos_piece *p,
		  px_vec3 q, double *F, double *g)
{
	const double *h = s->coef + p->off;
	int n = p->deg, G = p->gdeg, kd = G - n, i, j, c;
	const double *kb = h + 4 * (n + 1);
	const double *bd = kb + 3 * (kd + 1) + (p->wconst ? 0 : 2 * n + 1);
	const double *ibf = bd + n + 1, *ibg = ibf + 2 * n + 1;
	double e[3][CD + 1], pc[3] = {q.x, q.y, q.z};

	for (c = 0; c < 3; c++)
		for (i = 0; i <= n; i++)
			e[c][i] = (h[c * (n + 1) + i] - h[3 * (n + 1) + i] * pc[c]) * bd[i];
	for (i = 0; i <= 2 * n; i++)
		F[i] = 0.0;
	for (i = 0; i <= G; i++)
		g[i] = 0.0;
	for (c = 0; c < 3; c++)
		for (i = 0; i <= n; i++) {
			double ei = e[c][i];
			const double *k = kb + c * (kd + 1);
			for (j = 0; j <= n; j++)
				F[i + j] += ei * e[c][j];
			for (j = 0; j <= kd; j++)
				g[i + j] += ei * k[j];
		}
	for (i = 0; i <= 2 * n; i++)
		F[i] *= ibf[i];
	for (i = 0; i <= G; i++)
		g[i] *= ibg[i];
}

/* The certified minimum of |C - q|^2 over piece p below b->d2. */
static void solve_piece(const struct brep_cos_set *s, const struct brep_cos_piece *p,
			px_vec3 q, struct cos_best *b)
{
	const double *h = s->coef + p->off;
	int n = p->deg, G = p->gdeg, kd = G - n, top = 0, nodes = 0, k;
	const double *W = p->wconst ? NULL : h + 4 * (n + 1) + 3 * (kd + 1);
	/* after kb, W, bd, ibf and ibg (see piece_doubles()) */
	const double *gbin = h + piece_doubles(n, G, p->wconst) - (G + 1);
	double F[CF + 1], g[CG + 1], Fr[CF + 1], Wr[CF + 1], gr[CG + 1];
	double sa[COS_MAX_DEPTH + 2], sb[COS_MAX_DEPTH + 2], slack, eps_g;
	int sd[COS_MAX_DEPTH + 2];

	take(s, p, q, 0.0, b);
	take(s, p, q, 1.0, b);
	for (k = 1; k < 4; k++)
		take(s, p, q, 0.25 * k, b);
	forms(s, p, q, F, g);
	/* Rounding in F is about 1e-16 of the squared reach of the piece
	 * from q: a bound within a thousand times that of the best can
	 * only improve it by noise (a circle seen from its centre would
	 * else split to the depth bound); values of g within 1e-13 of its
	 * largest coefficient count as zero. */
	{
		px_vec3 c = px_v3_scale(px_v3_add(p->box.min, p->box.max), 0.5);
		double r = px_v3_dist(c, q) + px_aabb_diagonal(&p->box), gmax = 0.0;
		slack = 1e-13 * r * r;
		for (k = 0; k <= G; k++)
			gmax = fabs(g[k]) > gmax ? fabs(g[k]) : gmax;
		eps_g = 1e-13 * gmax;
	}
	sa[0] = 0.0;
	sb[0] = 1.0;
	sd[0] = 0;
	top = 1;
	while (top > 0) {
		double a, e, lb = INFINITY;
		int d, i, sc, first, last;
		top--;
		a = sa[top];
		e = sb[top];
		d = sd[top];
		restrict_to(F, 2 * n, a, e, Fr);
		if (W)
			restrict_to(W, 2 * n, a, e, Wr);
		for (i = 0; i <= 2 * n; i++) {
			double r = W ? Fr[i] / Wr[i] : Fr[i];
			lb = r < lb ? r : lb;
		}
		if (lb >= b->d2 - slack)
			continue;
		restrict_to(g, G, a, e, gr);
		/* a root at an end (to rounding) is invisible to the count:
		 * the end is the candidate */
		if (fabs(gr[0]) <= eps_g) {
			take(s, p, q, a, b);
			gr[0] = 0.0;
		}
		if (fabs(gr[G]) <= eps_g) {
			take(s, p, q, e, b);
			gr[G] = 0.0;
		}
		sc = sign_changes(gr, G, &first, &last);
		if (sc == 0 || (sc == 1 && first > 0)) {
			/* the minimum on [a, e] is at an end */
			double fa = W ? Fr[0] / Wr[0] : Fr[0];
			double fe = W ? Fr[2 * n] / Wr[2 * n] : Fr[2 * n];
			take(s, p, q, fa <= fe ? a : e, b);
			continue;
		}
		if (sc == 1) {
			take(s, p, q, a + (e - a) * root_of(gr, gbin, G), b);
			continue;
		}
		if (d >= COS_MAX_DEPTH || ++nodes > COS_MAX_NODES ||
		    top + 2 > COS_MAX_DEPTH + 2) {
			/* cut short: the ends and the middle, uncertified */

			take(s, p, q, a, b);
			take(s, p, q, e, b);
			take(s, p, q, 0.5 * (a + e), b);
			if (lb < b->d2 - slack) {
				b->certified = 0;
				b->gap2 = fmax(b->gap2, b->d2 - lb);
			}
			continue;
		}
		/* the half that holds the best so far is popped first */
		{
			double m = 0.5 * (a + e);
			int right = b->s > m && b->s <= e;
			sa[top] = right ? a : m;
			sb[top] = right ? m : e;
			sd[top++] = d + 1;
			sa[top] = right ? m : a;
			sb[top] = right ? e : m;
			sd[top++] = d + 1;
		}
	}
}

int px__brep_cos_closest(const struct brep_cos_set *s, px_vec3 q,
			 struct px_dist_result *d, double *edge_gap)
{
	struct cos_best b;
	int i, bi = -1, certified = 1;
	double bs = 0.0, gap2 = 0.0, lb_in;

	if (edge_gap)
		*edge_gap = -1.0;
	if (!s || s->n_pc == 0)
		return 0;
	/* what d's proof leaves: its entities are no nearer than lb_in */
	lb_in = d->certified ? d->dist : d->dist - d->gap;
	b.d2 = d->dist * d->dist;
	for (i = 0; i < s->n_pc; i++) {
		const struct brep_cos_piece *p = &s->pc[i];
		if (px_aabb_dist2(&p->box, q) >= b.d2)
			continue;
		b.found = 0;
		b.certified = 1;
		b.gap2 = 0.0;
		b.s = -1.0;
		solve_piece(s, p, q, &b);
		certified &= b.certified;
		gap2 = fmax(gap2, b.gap2);
		if (b.found) {
			bi = i;
			bs = b.s;
		}
	}
	if (bi >= 0) {
		const struct brep_cos_piece *p = &s->pc[bi];
		px_vec3 pt = piece_point(s, p, bs), v = px_v3_sub(q, pt);
		d->dist = px_v3_norm(v);
		d->point = pt;
		d->dir = d->dist > 0.0 ? px_v3_scale(v, 1.0 / d->dist) : px_v3(0, 0, 0);
		d->u = p->t0 + (p->t1 - p->t0) * bs;
		d->v = 0.0;
		d->entity = p->cos;
		d->kind = BREP_COS;
		d->piece = bi;
		/* a nearer edge point settles what d's proof left open */
		if (!d->certified && d->dist <= lb_in) {
			d->certified = 1;
			d->gap = 0.0;
		} else if (!d->certified)
			d->gap = d->dist - lb_in;
	}
	if (!certified) {
		/* gap2 bounds how far below the best (squared) a cut
		 * interval may reach: as a distance, at most its root */
		d->certified = 0;
		d->gap = fmax(d->gap, sqrt(gap2));
		if (edge_gap)
			*edge_gap = sqrt(gap2);
	}
	return bi >= 0;
}

double px__brep_cos_bound2(const struct brep_cos_set *s, px_vec3 q)
{
	double best = INFINITY;
	int i;
	for (i = 0; i < s->n_pc; i++) {
		const double *h = s->coef + s->pc[i].off;
		int n = s->pc[i].deg;
		double w = h[3 * (n + 1)];
		double d2 = px_v3_dist2(px_v3(h[0] / w, h[n + 1] / w, h[2 * (n + 1)] / w), q);
		best = d2 < best ? d2 : best;
	}
	/* the end point itself must beat it */
	return best * (1.0 + 1e-12) + 1e-300;
}

int px__brep_cos_on(const struct brep_cos_set *s, int co)
{
	int i;
	for (i = 0; s && i < s->n_cos; i++)
		if (s->cos[i].co == co)
			return 1;
	return 0;
}
