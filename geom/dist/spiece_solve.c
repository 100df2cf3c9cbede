/*
 * spiece_solve.c - the certified closest-point query of a surface piece
 * (px_spiece_closest_hint()): subdivision of the parameter square by
 * Bernstein bounds of the squared distance, sign and monotonicity
 * proofs of its gradient (with a preconditioned test where the plain
 * one fails), Newton inside the rectangles where one minimum is proved,
 * and a pool of restricted tensors so children restrict from their
 * parent. The test hooks of dist_internal.h live here.
 */
#include "px_spiece.h"

#include <float.h>
#include <math.h>
#include <string.h>

#include "dist_internal.h"

#define MD PX__SP_MD
#define TMAX PX__SP_TMAX

#ifdef PX_TEST_HOOKS
int px__spiece_pool_cap = -1;
int px__spiece_no_precond = 0;
#endif

static int nf_s(int p) { return 2 * p; }

/*
 * 1 when every coefficient is > eps, -1 when every one is < -eps, else 0.
 * eps covers the rounding of restrictions: two rectangles sharing an edge
 * restrict the same polynomial separately, and a zero lying exactly on
 * that edge (a symmetry line, a split through the critical point) could
 * otherwise come out slightly positive on one side and slightly negative
 * on the other, and both sides would be pruned.
 */
static int strict_sign(const double *c, size_t k, double eps)
{
	size_t i;
	int pos = 1, neg = 1;
	for (i = 0; i < k; i++) {
		pos &= c[i] > eps;
		neg &= c[i] < -eps;
		if (!(pos | neg))
			return 0; /* mixed: most rectangles worth a look are */
	}
	return pos ? 1 : (neg ? -1 : 0);
}

static double max_abs(const double *c, size_t k)
{
	double m = 0.0;
	size_t i;
	for (i = 0; i < k; i++)
		m = fabs(c[i]) > m ? fabs(c[i]) : m;
	return m;
}


/* Element (i, j), i along s, of a tensor of degrees (n, m) stored in
 * orientation o (0: rows along s; 1: the transpose). */
static inline double t_at(const double *c, int n, int m, int o, int i, int j)
{
	return o ? c[(size_t)j * (size_t)(n + 1) + (size_t)i]
		 : c[(size_t)i * (size_t)(m + 1) + (size_t)j];
}


/*
 * The monotonicity test again, preconditioned, where the plain one
 * failed with a positive diagonal. The symmetric part S of the Jacobian
 * J of G = (gu, gv) (in the piece's scale: S11 in [a_lo, a_hi], S22 in
 * [d_lo, d_hi], the off-diagonal in [o_lo, o_hi]) is positive definite
 * on the rectangle iff K = M^T S M is, for any invertible M. The plain
 * test bounds S11, S22 and the off-diagonal each on its own, so a cross
 * term near the size of the diagonal (a skewed parametrization, a twist)
 * fails it however small the rectangle. With M = L^-T from the Cholesky
 * factor of S at the ranges' midpoints (columns m1 = (m11, 0), m2 =
 * (m12, m22)), K is near the identity there, and its entries are formed
 * as polynomials before their ranges are taken, so they vary only as S
 * does over the rectangle:
 *   K11 = m11^2 S11,
 *   K22 = m2^T J m2 = D_m2 h,            h = m12 gu + m22 gv,
 *   K12 = (m1^T J m2 + m2^T J m1) / 2 = m11 (D_m2 gu + dh/ds) / 2,
 * D_m2 the derivative along m2 (scaled by the rectangle's widths). gu is
 * elevated along s and gv along t to the common degree (un + 1, um), and
 * each derivative is written back at that degree (px__sp_d_rows(), px__sp_d_cols()).
 * The margins cover the coefficients' rounding rnd (point_rounding())
 * through the differences and the sums. Returns 1 with *mu a modulus of
 * S (v^T S v >= mu |v|^2: K's least eigenvalue bound over |M|_F^2), 0
 * when K is not proven positive definite either. rg, rv in orientation
 * o.
 */
static __attribute__((noinline)) int
precond_monotone(const double *rg, const double *rv, int un, int um, int o,
		 double ws, double wt, double a_lo, double a_hi, double d_lo,
		 double d_hi, double o_lo, double o_hi, double rnd, double *mu)
{
	/* gv's degrees are gu's plus one along s and minus one along t
	 * (both rational and polynomial patches) */
	const int vn = un + 1, vm = um - 1, N = un + 1, Mx = um;
	/* stored layout: R rows of C; the rows run along s when o = 0 */
	const int R = (o ? Mx : N) + 1, C = (o ? N : Mx) + 1;
	const size_t nk = (size_t)R * (size_t)C;
	double eg[TMAX], h[TMAX], hr[TMAX], hc[TMAX], gr[TMAX], gc[TMAX];
	double al = 0.5 * (a_lo + a_hi), de = 0.5 * (d_lo + d_hi),
	       be = 0.5 * (o_lo + o_hi), l11, l21, l22, m11, m12, m22;
	double k2 = INFINITY, k12 = 0.0, k1, lam, gmax = 0.0, vmax = 0.0;
	double cr, cc, er, ec, fr, fc, hm, eh, nr2, nc2;
	size_t k;
	if (!(al > 0.0) || !(al * de > be * be))
		return 0; /* S at the midpoint not definite: nor all of it */
	/* Where S is not definite at a corner (its value there: the corner
	 * coefficients' differences) no M can prove it on the rectangle. */
	for (k = 0; k < 4; k++) {
		const int ei = k & 1, ej = k >> 1;
		const int i0 = ei ? un - 1 : 0, j0 = ej ? um - 1 : 0;
		const int iv = ei ? vn : 0, jv = ej ? vm : 0;
		const int ig = ei ? un : 0, jg = ej ? um : 0;
		const int i1 = ei ? vn - 1 : 0, j1 = ej ? vm - 1 : 0;
		double s11 = un * (t_at(rg, un, um, o, i0 + 1, jg) - t_at(rg, un, um, o, i0, jg)) / ws;
		double gut = um * (t_at(rg, un, um, o, ig, j0 + 1) - t_at(rg, un, um, o, ig, j0)) / wt;
		double gvs = vn * (t_at(rv, vn, vm, o, i1 + 1, jv) - t_at(rv, vn, vm, o, i1, jv)) / ws;
		double s22 = vm * (t_at(rv, vn, vm, o, iv, j1 + 1) - t_at(rv, vn, vm, o, iv, j1)) / wt;
		double s12 = 0.5 * (gut + gvs);
		if (!(s11 > 0.0) || !(s11 * s22 > s12 * s12))
			return 0;
	}
	l11 = sqrt(al);
	l21 = be / l11;
	l22 = sqrt(de - l21 * l21);
	if (!(l22 > 0.0))
		return 0;
	m11 = 1.0 / l11;
	m12 = -l21 / (l11 * l22);
	m22 = 1.0 / l22;
	/* gu along s, gv along t, in their stored orientation */
	if (o) {
		px__sp_elevate(rg, um, un, 1, eg);
		px__sp_elevate(rv, vm, vn, 0, h);
	} else {
		px__sp_elevate(rg, un, um, 0, eg);
		px__sp_elevate(rv, vn, vm, 1, h);
	}
	for (k = 0; k < nk; k++) {
		double g = fabs(eg[k]), v = fabs(h[k]);
		gmax = g > gmax ? g : gmax;
		vmax = v > vmax ? v : vmax;
		h[k] = m12 * eg[k] + m22 * h[k];
	}
	px__sp_d_rows(h, R, C, hr);
	px__sp_d_cols(h, R, C, hc);
	px__sp_d_rows(eg, R, C, gr);
	px__sp_d_cols(eg, R, C, gc);
	/* K22 = cr hr + cc hc, K12 = er hr + ec hc + fr gr + fc gc: the
	 * derivatives along s carry 1 / ws, along t 1 / wt */
	if (o) {
		cr = m22 / wt;
		cc = m12 / ws;
		er = 0.0;
		ec = 0.5 * m11 / ws;
		fr = 0.5 * m11 * m22 / wt;
		fc = 0.5 * m11 * m12 / ws;
	} else {
		cr = m12 / ws;
		cc = m22 / wt;
		er = 0.5 * m11 / ws;
		ec = 0.0;
		fr = 0.5 * m11 * m12 / ws;
		fc = 0.5 * m11 * m22 / wt;
	}
	for (k = 0; k < nk; k++) {
		double v2 = cr * hr[k] + cc * hc[k];
		double v12 = fabs(er * hr[k] + ec * hc[k] + fr * gr[k] + fc * gc[k]);
		k2 = v2 < k2 ? v2 : k2;
		k12 = v12 > k12 ? v12 : k12;
	}
	/* Margins: a derivative coefficient is at most 2 n times its
	 * tensor's largest (n its degree), and its error 2 n times the
	 * tensor's; 1e-12 of those sizes covers the rounding of the sums,
	 * rnd (with h's |m12| + |m22| times it) that of the coefficients */
	nr2 = 2.0 * (R - 1);
	nc2 = 2.0 * (C - 1);
	hm = fabs(m12) * gmax + fabs(m22) * vmax;
	eh = (fabs(m12) + fabs(m22)) * rnd;
	k2 -= (fabs(cr) * nr2 + fabs(cc) * nc2) * (1e-12 * hm + eh);
	k12 += (fabs(er) * nr2 + fabs(ec) * nc2) * (1e-12 * hm + eh) +
	       (fabs(fr) * nr2 + fabs(fc) * nc2) * (1e-12 * gmax + rnd);
	k1 = m11 * m11 * (a_lo - 2.0 * un * rnd / ws);
	if (!(k1 > 0.0) || !(k2 > 0.0) || !(k1 * k2 > k12 * k12))
		return 0;
	lam = 0.5 * (k1 + k2) - sqrt(0.25 * (k1 - k2) * (k1 - k2) + k12 * k12);
	*mu = lam / (m11 * m11 + m12 * m12 + m22 * m22);
	return *mu > 0.0;
}

/* ---- query ---------------------------------------------------------------------- */

struct rect {
	double s0, s1, t0, t1;
	double lb; /* lower bound of f on the rectangle */
	int depth;
	/* Slot holding the parent's restricted tensors (-1: none), and
	 * which quarter of the parent this is (bit 0: s high, bit 1: t
	 * high). */
	int parent, quad;
};

struct qctx {
	const struct px_spiece *sp;
	px_vec3 p;
	double hint_s, hint_t; /* Newton start, or NaN */
	double best, slack;
	struct px_spiece_hit *hit;
	const struct px__uv_filter *flt; /* trimmed domain, or NULL */
	int improved;
};

/* The point at (s, t) lowers the bound when it is nearer and, with a
 * filter, inside its trimmed domain. */
static inline __attribute__((always_inline)) void
consider(struct qctx *x, double s, double t)
{
	px_vec3 q = px__sp_point(x->sp, s, t);
	double d2 = px_v3_dist2(q, x->p);
	if (d2 < x->best) {
		double u = x->sp->u0_ + s * (x->sp->u1_ - x->sp->u0_);
		double v = x->sp->v0_ + t * (x->sp->v1_ - x->sp->v0_);
		if (x->flt && !x->flt->inside(x->flt->ctx, u, v))
			return;
		x->best = d2;
		x->hit->d2 = d2;
		x->hit->point = q;
		x->hit->u = u;
		x->hit->v = v;
		x->improved = 1;
	}
}

/* Hot-path clamp: fmin/fmax are library calls without -ffast-math. */
static inline double clampd(double v, double lo, double hi)
{
	return v > lo ? (v < hi ? v : hi) : lo;
}

/*
 * The minimum of f inside a rectangle where the caller proved that there
 * is at most one critical point, and that it is a minimum: Newton on
 * grad f (gradient descent where the Hessian is not positive definite),
 * with backtracking on f, every step clipped to the rectangle. Returns 1
 * with the point when it converges to a vanishing gradient strictly
 * inside; 0 otherwise (the minimum is not here, or not reached yet: the
 * caller subdivides, so giving up is always safe).
 */
static int newton_f(struct qctx *x, const struct rect *r, int *iters,
		    double *s_out, double *t_out)
{
	const struct px_spiece *sp = x->sp;
	double s = 0.5 * (r->s0 + r->s1), t = 0.5 * (r->t0 + r->t1);
	double ks = sp->u1_ - sp->u0_, kt = sp->v1_ - sp->v0_;
	double wmax = fmax(r->s1 - r->s0, r->t1 - r->t0), fcur;
	int it, floor_steps = 0;

	if (x->hint_s >= r->s0 && x->hint_s <= r->s1 && x->hint_t >= r->t0 &&
	    x->hint_t <= r->t1) {
		s = x->hint_s;
		t = x->hint_t;
	}
	fcur = px_v3_dist2(px__sp_point(sp, s, t), x->p);
	for (it = 0; it < PX_SPIECE_MAX_ITERS; it++) {
		px_vec3 su, sv, suu, suv, svv, d, S;
		double gs, gt, a, b, c, det, ds, dt, al;
		int k, out_s, out_t, newton_step = 1;

		(*iters)++;
		S = px_spiece_eval(sp, s, t, &su, &sv, &suu, &suv, &svv);
		/* Derivatives with respect to the local (s, t). */
		su = px_v3_scale(su, ks);
		sv = px_v3_scale(sv, kt);
		suu = px_v3_scale(suu, ks * ks);
		suv = px_v3_scale(suv, ks * kt);
		svv = px_v3_scale(svv, kt * kt);
		d = px_v3_sub(S, x->p);
		gs = px_v3_dot(d, su);
		gt = px_v3_dot(d, sv);
		a = px_v3_dot(su, su) + px_v3_dot(d, suu);
		b = px_v3_dot(su, sv) + px_v3_dot(d, suv);
		c = px_v3_dot(sv, sv) + px_v3_dot(d, svv);
		det = a * c - b * b;
		if (gs == 0.0 && gt == 0.0)
			break;
		/* On the border with descent pointing out through it: that
		 * coordinate stays (projected Newton), the other one goes on
		 * in 1D, so that the point ends at the rectangle's constrained
		 * minimum; the caller can then prove from it that no critical
		 * point lies inside (monotone_settles()). */
		out_s = (s <= r->s0 && gs > 0.0) || (s >= r->s1 && gs < 0.0);
		out_t = (t <= r->t0 && gt > 0.0) || (t >= r->t1 && gt < 0.0);
		if (out_s && out_t)
			goto done; /* a corner with descent pointing out */
		if (out_s) {
			ds = 0.0;
			newton_step = c > 0.0;
			dt = newton_step ? -gt / c : -copysign(wmax, gt);
		} else if (out_t) {
			dt = 0.0;
			newton_step = a > 0.0;
			ds = newton_step ? -gs / a : -copysign(wmax, gs);
		} else if (a > 0.0 && det > 0.0) {
			ds = -(c * gs - b * gt) / det;
			dt = -(a * gt - b * gs) / det;
		} else {
			double g = sqrt(gs * gs + gt * gt);
			newton_step = 0;
			ds = -gs / g * wmax;
			dt = -gt / g * wmax;
		}
		/* A step already below the resolution we need is the end:
		 * near the minimum f changes only by rounding, and a line
		 * search there would halve the step to nothing. */
		if (fabs(ds) <= 1e-13 && fabs(dt) <= 1e-13)
			goto done;
		/* Sitting on the border with the Newton step pushed out
		 * through it while the gradient points in (the cross term):
		 * the diagonal step, a descent direction whose components
		 * point where the gradient's do, so inward. Giving up here
		 * left the rectangle to be cut with no point to settle it
		 * from. */
		if ((s <= r->s0 && ds < 0.0) || (s >= r->s1 && ds > 0.0) ||
		    (t <= r->t0 && dt < 0.0) || (t >= r->t1 && dt > 0.0)) {
			if (!(a > 0.0 && c > 0.0))
				goto done;
			ds = out_s ? 0.0 : -gs / a;
			dt = out_t ? 0.0 : -gt / c;
			newton_step = 0;
		}
		/* A Newton step whose model decrease, -(g . step) / 2, is
		 * below a few ulps of f cannot be judged by comparing f: f is
		 * at its rounding floor and the line search would halve the
		 * step at random, crawling (along a border, where the
		 * gradient across it stays large, for the whole iteration
		 * bound, subdividing towards the border at every level). The
		 * model is right there (quadratic convergence): take it
		 * whole, twice at most - after that the step is rounding
		 * noise too and the point is as good as it gets. */
		if (newton_step &&
		    -(gs * ds + gt * dt) <= 8.0 * DBL_EPSILON * fcur) {
			if (floor_steps++ >= 2)
				goto done;
			s = clampd(s + ds, r->s0, r->s1);
			t = clampd(t + dt, r->t0, r->t1);
			fcur = px_v3_dist2(px__sp_point(sp, s, t), x->p);
			continue;
		}
		for (al = 1.0, k = 0; k < 12; k++, al *= 0.5) {
			double ns = clampd(s + al * ds, r->s0, r->s1);
			double nt = clampd(t + al * dt, r->t0, r->t1);
			double fn = px_v3_dist2(px__sp_point(sp, ns, nt), x->p);
			double moved = fabs(ns - s) > fabs(nt - t) ? fabs(ns - s) : fabs(nt - t);
			if (fn <= fcur || moved <= 1e-15) {
				s = ns;
				t = nt;
				fcur = fn < fcur ? fn : fcur;
				if (moved <= 1e-13)
					goto done;
				break;
			}
		}
		if (k == 12)
			goto done;
	}
done:
	if (it >= PX_SPIECE_MAX_ITERS)
		return 0;
	*s_out = s;
	*t_out = t;
	/* On the rectangle's border the point may be only this
	 * rectangle's constrained minimum; it is the patch's critical
	 * point (the one the certificate allows) only if the gradient
	 * vanishes there too. */
	if (s <= r->s0 || s >= r->s1 || t <= r->t0 || t >= r->t1) {
		px_vec3 su, sv, S = px_spiece_eval(sp, s, t, &su, &sv, NULL, NULL, NULL);
		px_vec3 d = px_v3_sub(S, x->p);
		double gs = px_v3_dot(d, su) * ks, gt = px_v3_dot(d, sv) * kt;
		double scale = px_v3_norm(d) * (px_v3_norm(su) * ks + px_v3_norm(sv) * kt);
		return sqrt(gs * gs + gt * gt) <= 1e-10 * scale + 1e-300;
	}
	return 1;
}

/* min f_i / w_i, or min f_i when w is NULL (constant weight 1). */
static double ratio_min(const double *f, const double *w, size_t k)
{
	double lb = INFINITY;
	size_t i;
	for (i = 0; i < k; i++) {
		double q = w ? f[i] / w[i] : f[i];
		lb = q < lb ? q : lb;
	}
	return lb;
}

/*
 * Kernels of the subdivision. A tensor is stored row by row; "rows" is
 * whichever parameter its rows run along (s at the root). Splitting
 * along the rows is a de Casteljau sweep whose every level is one flat
 * loop over contiguous memory (rows below the level, all their
 * entries), which vectorises and has no per-row overhead; the other
 * parameter is split by transposing first, so a rectangle's quarter is
 * split, transpose, split, and its tensors come out with the other
 * orientation (tracked per rectangle, see struct rect). Halving with
 * 0.5 (a + b) is bit for bit 0.5 a + 0.5 b (scaling by 2 is exact), so
 * the orientation changes no value.
 */

/* Two doubles in one register (SSE2 on x86-64, NEON on arm64; scalar
 * pairs elsewhere): GNU C vector extension, which GCC and Clang share. */
typedef double v2d __attribute__((vector_size(16)));

/* Along the rows (0..n, w wide): lo gets the half [0, 1/2] and hi the
 * half [1/2, 1]; either may be NULL. Neither may alias c. */
static void rows_half(const double *c, int n, int w, double *lo, double *hi)
{
	double work[TMAX];
	double *h = hi ? hi : work;
	const size_t W = (size_t)w;
	int k;

	memcpy(h, c, (size_t)(n + 1) * W * sizeof(double));
	if (lo)
		memcpy(lo, c, W * sizeof(double));
	for (k = 1; k <= n; k++) {
		const size_t e = (size_t)(n - k + 1) * W;
		size_t i;
		/* Two at a time: each pair is loaded before it is stored,
		 * and what is read ahead (i + W >= i + 1) is not yet written,
		 * so this is the scalar sweep's arithmetic exactly. */
		for (i = 0; i + 2 <= e; i += 2) {
			v2d a, b;
			memcpy(&a, h + i, sizeof(a));
			memcpy(&b, h + i + W, sizeof(b));
			a = 0.5 * (a + b);
			memcpy(h + i, &a, sizeof(a));
		}
		if (i < e)
			h[i] = 0.5 * (h[i] + h[i + W]);
		if (lo)
			memcpy(lo + (size_t)k * W, h, W * sizeof(double));
	}
}

/* c (rows x cols) to out (cols x rows). */
static void transpose(const double *c, int rows, int cols, double *out)
{
	int i, j;
	for (i = 0; i < rows; i++)
		for (j = 0; j < cols; j++)
			out[j * rows + i] = c[i * cols + j];
}

/* The quarter of c (rows x cols) keeping half a (1: upper) along the
 * rows and half b along the columns, into out (cols x rows). */
static void t_quarter(const double *c, int rows, int cols, int a, int b,
		      double *out)
{
	double h[TMAX], t[TMAX];
	rows_half(c, rows - 1, cols, a ? NULL : h, a ? h : NULL);
	transpose(h, rows, cols, t);
	rows_half(t, cols - 1, rows, b ? NULL : out, b ? out : NULL);
}

/* Quarter number (bit 0: s high, bit 1: t high) of the half a along the
 * rows and b along the columns, for a tensor of orientation o (0: rows
 * along s). */
static int quad_of(int o, int a, int b)
{
	return o ? (b | a << 1) : (a | b << 1);
}

/* The inverse: which halves along the rows (*a) and the columns (*b) of
 * a tensor of orientation o make quarter quad. */
static void quad_halves(int o, int quad, int *a, int *b)
{
	int s_hi = quad & 1, t_hi = (quad >> 1) & 1;
	*a = o ? t_hi : s_hi;
	*b = o ? s_hi : t_hi;
}

/*
 * Restricted tensors of split rectangles, kept for their children: the
 * rectangle's gu and gv, and F and W already cut into its four quarters
 * (their lower bounds needed them anyway). A child restricted from its
 * parent needs one half split per direction instead of two full
 * restrictions from the root (one to each end), and its F and W are
 * copied, not recomputed. The pool is a fixed stack buffer cut into
 * slots of the actual degrees' size; when it is full a child is
 * restricted from the root as before (orientation 0). Both are the same
 * restriction up to rounding, which the sign margins cover, so the
 * pool's size changes the cost, not what is proved
 * (test_pool_matches_root_restriction).
 */
#define POOL_DOUBLES 8192
#define POOL_SLOTS 64

struct pool {
	double mem[POOL_DOUBLES];
	size_t ngu, ngv, nf;  /* tensor sizes */
	size_t per;           /* doubles a slot: gu, gv, 4 F, 4 W */
	int refs[POOL_SLOTS]; /* children still queued */
	int orient[POOL_SLOTS]; /* of the slot's gu and gv */
	int free_[POOL_SLOTS], nfree, fresh, nslots;
};

static void pool_init(struct pool *pl, size_t ngu, size_t ngv, size_t nf,
		      int have_w)
{
	size_t n;
	pl->ngu = ngu;
	pl->ngv = ngv;
	pl->nf = nf;
	pl->per = ngu + ngv + 4 * nf * (have_w ? 2u : 1u);
	n = POOL_DOUBLES / pl->per;
	pl->nslots = n < POOL_SLOTS ? (int)n : POOL_SLOTS;
	if (px__spiece_pool_cap >= 0 && pl->nslots > px__spiece_pool_cap)
		pl->nslots = px__spiece_pool_cap;
	pl->nfree = 0;
	pl->fresh = 0;
}

static double *slot_gu(struct pool *pl, int k)
{
	return pl->mem + (size_t)k * pl->per;
}
static double *slot_gv(struct pool *pl, int k) { return slot_gu(pl, k) + pl->ngu; }
/* Quarter q of F, and of W. */
static double *slot_f(struct pool *pl, int k, int q)
{
	return slot_gv(pl, k) + pl->ngv + (size_t)q * pl->nf;
}
static double *slot_w(struct pool *pl, int k, int q) { return slot_f(pl, k, 4 + q); }

static void pool_give(struct pool *pl, int k)
{
	pl->free_[pl->nfree++] = k;
}

/* A child is done with its parent's slot: freed with the last one. The
 * query drops a rectangle's parent only when the next rectangle is
 * popped, so a slot taken while splitting is never the one being read. */
static void pool_drop(struct pool *pl, int k)
{
	if (k >= 0 && --pl->refs[k] == 0)
		pool_give(pl, k);
}

static int pool_take(struct pool *pl)
{
	if (pl->nfree > 0)
		return pl->free_[--pl->nfree];
	return pl->fresh < pl->nslots ? pl->fresh++ : -1;
}

/*
 * Lower bounds of the four quarters of a rectangle from F and W
 * restricted to it (orientation o, pw NULL: constant weight), and the
 * quarters themselves into the slot when there is one: halve along the
 * rows, transpose, halve again.
 */
static void children_lb(const double *pf, const double *pw, int fn, int fm,
			int o, struct pool *pl, int slot, struct rect ch[4])
{
	const int rows = (o ? fm : fn) + 1, cols = (o ? fn : fm) + 1;
	const size_t k = px__sp_tsize(fn, fm);
	double half[2][2][TMAX], tr[TMAX], q[2][2][TMAX];
	int a, b, c;

	for (c = 0; c < (pw ? 2 : 1); c++)
		rows_half(c ? pw : pf, rows - 1, cols, half[c][0], half[c][1]);
	for (a = 0; a < 2; a++) {
		for (c = 0; c < (pw ? 2 : 1); c++) {
			transpose(half[c][a], rows, cols, tr);
			rows_half(tr, cols - 1, rows, q[c][0], q[c][1]);
		}
		for (b = 0; b < 2; b++) {
			int n = quad_of(o, a, b);
			const double *w = pw ? q[1][b] : NULL;
			ch[n].lb = ratio_min(q[0][b], w, k);
			if (slot >= 0) {
				memcpy(slot_f(pl, slot, n), q[0][b], k * sizeof(double));
				if (w)
					memcpy(slot_w(pl, slot, n), w, k * sizeof(double));
			}
		}
	}
}

/* Min-heap of rectangles by lower bound: nearest first, so the best
 * bound drops early and prunes the rest. */
static void heap_push(struct rect *h, int *n, struct rect r)
{
	int i = (*n)++;
	while (i > 0) {
		int parent = (i - 1) / 2;
		if (h[parent].lb <= r.lb)
			break;
		h[i] = h[parent];
		i = parent;
	}
	h[i] = r;
}

static struct rect heap_pop(struct rect *h, int *n)
{
	struct rect top = h[0], last = h[--(*n)];
	int i = 0;
	for (;;) {
		int l = 2 * i + 1, m = i;
		if (l < *n && h[l].lb < last.lb)
			m = l;
		if (l + 1 < *n && h[l + 1].lb < (m == i ? last.lb : h[m].lb))
			m = l + 1;
		if (m == i)
			break;
		h[i] = h[m];
		i = m;
	}
	if (*n > 0)
		h[i] = last;
	return top;
}

static double rect_lb(const double *F, const double *W, int fn, int fm,
		      const struct rect *r, double *rf, double *rw)
{
	px__sp_restrict(F, fn, fm, r->s0, r->s1, r->t0, r->t1, rf);
	if (W)
		px__sp_restrict(W, fn, fm, r->s0, r->s1, r->t0, r->t1, rw);
	return ratio_min(rf, W ? rw : NULL, px__sp_tsize(fn, fm));
}


/*
 * Rounding bound of gu or gv evaluated at one point: each coefficient
 * a - P . b is formed with an error of a few ulps of |a| + |P| |b|
 * (cancellation included), the convex combination of the basis keeps the
 * largest, and the summation adds a few ulps per term.
 */
/* Largest |a_i| + |P| |b_i| (b: three blocks of k), at least m. */
static double coef_size(const double *a, const double *b, size_t k, px_vec3 p,
			double m)
{
	double ax = fabs(p.x), ay = fabs(p.y), az = fabs(p.z);
	size_t i;
	for (i = 0; i < k; i++) {
		double e = fabs(a[i]) + ax * fabs(b[i]) + ay * fabs(b[k + i]) +
			   az * fabs(b[2 * k + i]);
		m = e > m ? e : m;
	}
	return m;
}

static double point_rounding(const struct px_spiece *sp, px_vec3 p, size_t ngu,
			     size_t ngv)
{
	double m = coef_size(sp->gua_, sp->gub_, ngu, p, 0.0);
	m = coef_size(sp->gva_, sp->gvb_, ngv, p, m);
	/* 8 ulps per coefficient plus 2 per term of a sum of at most
	 * (3 MD + 1)^2 terms, rounded up generously. */
	return (8.0 + 2.0 * (6 * MD + 2)) * 0x1p-52 * m;
}

/* What monotone_settles() needs besides the rectangle and the point. */
struct mono {
	double mu;             /* lower bound of the symmetric Jacobian part */
	double gu, gv;         /* (gu, gv) at the point */
	double eps_gu, eps_gv; /* their rounding */
	double gmax;           /* bound of |grad f| on the rectangle */
	double gscale;         /* 2 / wmin^3: |grad f| <= gscale |G| */
};

/*
 * Proof that a rectangle whose (gu, gv) is strongly monotone (modulus mu,
 * from the Jacobian bounds) holds no critical point closer than the point
 * x* = (s, t) the projected Newton ended at (on the border, its descent
 * pointing out). For a zero z in the rectangle, monotonicity gives
 *     mu |z - x*|^2 <= (G(z) - G(x*)) . (z - x*) = -G(x*) . (z - x*).
 * A component of G(x*) pointing out through a border x* lies on makes
 * its term <= 0 (z lies inside), so |z - x*| <= |G_rest| / mu = rho, and
 * f(z) >= f(x*) - rho * max |grad f|. Sharper, as for strongly convex
 * functions: along y = x* + tau (z - x*), grad f = (2 / w^3) G(y) and
 *     G(y) . (z - x*) >= G(x*) . (z - x*) >= -|G_rest| rho
 * (monotonicity again, then the same sign argument), so
 * f(z) >= f(x*) - (2 / wmin^3) |G_rest| rho: quadratic in |G_rest|, which
 * near the border's constrained minimum is rounding. With the first bound
 * alone, rounding in G times the whole gradient's size was more than the
 * slack wherever the gradient across the border is large, and the
 * rectangle was cut towards the border level after level. When the
 * smaller bound is within the rounding slack, x* (already considered) is
 * as good as any interior minimum and the rectangle is settled without
 * subdividing around the border.
 */
static int monotone_settles(const struct qctx *x, const struct rect *r,
			    double s, double t, const struct mono *mo)
{
	int out_s = (s <= r->s0 && mo->gu > mo->eps_gu) ||
		    (s >= r->s1 && mo->gu < -mo->eps_gu);
	int out_t = (t <= r->t0 && mo->gv > mo->eps_gv) ||
		    (t >= r->t1 && mo->gv < -mo->eps_gv);
	double rs = out_s ? 0.0 : fabs(mo->gu) + mo->eps_gu;
	double rt = out_t ? 0.0 : fabs(mo->gv) + mo->eps_gv;
	double g = sqrt(rs * rs + rt * rt), rho = g / mo->mu;
	double drop = rho * (g * mo->gscale < mo->gmax ? g * mo->gscale : mo->gmax);

	return drop <= x->slack;
}

int px_spiece_closest(const struct px_spiece *sp, px_vec3 p, double *best_d2,
		      struct px_spiece_hit *hit)
{
	return px_spiece_closest_hint(sp, p, NAN, NAN, best_d2, hit);
}

/* gu or gv of the query point: a - p . b, formed on first use (most
 * candidate patches are settled by the bound or by gu's sign alone). */
struct gtens {
	const double *a, *b; /* the piece's tensors (b: three blocks) */
	int n, m;            /* degrees */
	size_t k;            /* coefficients */
	int have;
	double eps;          /* sign margin: 1e-12 of the largest */
	double c[TMAX];
};

/* The point's tensors of one query and what the proofs read besides. */
struct ptens {
	const struct px_spiece *sp;
	px_vec3 p;
	int fn, fm;
	size_t nfs;
	const double *W; /* w^2, NULL when the weight is constant */
	double wmin;     /* smallest weight coefficient: w >= wmin */
	double rnd;      /* point_rounding(), on first use (< 0 before) */
	struct gtens gu, gv;
	double F[TMAX];  /* w^2 f */
};

/* a - p . b over k coefficients into out. */
static inline void form_g(const double *a, const double *b, size_t k, px_vec3 p,
		   double *out)
{
	size_t i;
	for (i = 0; i < k; i++)
		out[i] = a[i] - (p.x * b[i] + p.y * b[k + i] + p.z * b[2 * k + i]);
}

static void gtens_init(struct gtens *g, const double *a, const double *b,
		       int n, int m)
{
	g->a = a;
	g->b = b;
	g->n = n;
	g->m = m;
	g->k = px__sp_tsize(n, m);
	g->have = 0;
	g->eps = 0.0;
}

/*
 * g restricted to the rectangle r into out: a quarter of the parent's
 * (slot, orientation !o, halves ha and hb) when it has one, else from
 * the root. 1 when it has one strict sign there: that derivative of f
 * never vanishes in r. Forced inline at both calls: once per node on
 * the query's hot path, where a call costs measurable instructions.
 */
static inline __attribute__((always_inline)) int
g_signed(struct gtens *g, px_vec3 p, const double *slot, int o, int ha, int hb,
	 const struct rect *r, double *out)
{
	if (!g->have) {
		form_g(g->a, g->b, g->k, p, g->c);
		g->eps = 1e-12 * max_abs(g->c, g->k);
		g->have = 1;
	}
	if (slot)
		t_quarter(slot, (o ? g->n : g->m) + 1, (o ? g->m : g->n) + 1, ha,
			  hb, out);
	else
		px__sp_restrict(g->c, g->n, g->m, r->s0, r->s1, r->t0, r->t1, out);
	return strict_sign(out, g->k, g->eps);
}

static double query_rounding(struct ptens *pt)
{
	if (pt->rnd < 0.0)
		pt->rnd = point_rounding(pt->sp, pt->p, pt->gu.k, pt->gv.k);
	return pt->rnd;
}

/* Bernstein bounds of the Jacobian of (gu, gv) on a rectangle, in the
 * piece's local scale. */
struct jac {
	double a_lo, a_hi; /* d gu / ds */
	double d_lo, d_hi; /* d gv / dt */
	double o_lo, o_hi; /* the symmetric part's off-diagonal */
	double off;        /* its largest magnitude */
};

/* rg, rv: gu and gv restricted to a rectangle of widths ws, wt in
 * orientation o (d/ds = (1/ws) d/ds_sub). */
static void jac_bounds(const double *rg, const double *rv, int un, int um,
		       int vn, int vm, int o, double ws, double wt,
		       struct jac *j)
{
	double b_lo, b_hi, c_lo, c_hi, glo[2], ghi[2], vlo[2], vhi[2];
	/* o: the rows run along t, so the s-derivative is along the
	 * columns */
	px__sp_jac_range(rg, o ? um : un, o ? un : um, glo, ghi);
	px__sp_jac_range(rv, o ? vm : vn, o ? vn : vm, vlo, vhi);
	j->a_lo = glo[o] / ws;
	j->a_hi = ghi[o] / ws;
	b_lo = glo[!o] / wt;
	b_hi = ghi[!o] / wt;
	c_lo = vlo[o] / ws;
	c_hi = vhi[o] / ws;
	j->d_lo = vlo[!o] / wt;
	j->d_hi = vhi[!o] / wt;
	j->off = 0.5 * fmax(fabs(b_lo + c_lo), fabs(b_hi + c_hi));
	j->o_lo = 0.5 * (b_lo + c_lo);
	j->o_hi = 0.5 * (b_hi + c_hi);
}

/*
 * The Jacobian's verdict on a rectangle (rg, rv, orientation o, widths
 * ws, wt): 1 when (gu, gv) is proved monotone there (one zero at most, a
 * minimum), with its modulus in *mu; -1 when it has one zero at most, a
 * maximum; 0 when neither is proved.
 */
static int jac_verdict(struct ptens *pt, const double *rg, const double *rv,
		       int o, double ws, double wt, double *mu)
{
	struct jac j;
	jac_bounds(rg, rv, pt->gu.n, pt->gu.m, pt->gv.n, pt->gv.m, o, ws, wt, &j);
	if (j.a_lo > 0.0 && j.d_lo > 0.0 && j.a_lo * j.d_lo > j.off * j.off) {
		/* Its modulus: the smallest eigenvalue of the symmetric part
		 * grows with a and d and falls with |off|, so the corner
		 * values bound it. */
		*mu = 0.5 * (j.a_lo + j.d_lo) -
		      sqrt(0.25 * (j.a_lo - j.d_lo) * (j.a_lo - j.d_lo) + j.off * j.off);
		return 1;
	}
	if (j.a_hi < 0.0 && j.d_hi < 0.0 && j.a_hi * j.d_hi > j.off * j.off)
		return -1;
	if (j.a_lo > 0.0 && j.d_lo > 0.0 && !px__spiece_no_precond)
		return precond_monotone(rg, rv, pt->gu.n, pt->gu.m, o, ws, wt, j.a_lo,
					j.a_hi, j.d_lo, j.d_hi, j.o_lo, j.o_hi,
					query_rounding(pt), mu);
	return 0;
}

/*
 * A rectangle with one critical point at most, a minimum (modulus mu):
 * 1 when Newton finds it, or ends on the border at a point from which
 * monotone_settles() proves that nothing inside is closer; 0 when the
 * rectangle must be split. Either way the point reached is considered.
 */
static int settle_monotone(struct qctx *x, struct ptens *pt,
			   const struct rect *r, const double *rg,
			   const double *rv, double mu, int *iters)
{
	double s = NAN, t = NAN;
	int found = newton_f(x, r, iters, &s, &t);
	struct mono mo;
	double mg, mv;

	if (s == s)
		consider(x, s, t); /* a real point: a valid bound */
	if (found)
		return 1;
	if (!(s == s && mu > 0.0))
		return 0;
	mg = max_abs(rg, pt->gu.k);
	mv = max_abs(rv, pt->gv.k);
	mo.mu = mu;
	mo.gu = px__sp_eval(pt->gu.c, pt->gu.n, pt->gu.m, s, t);
	mo.gv = px__sp_eval(pt->gv.c, pt->gv.n, pt->gv.m, s, t);
	mo.eps_gu = query_rounding(pt);
	mo.eps_gv = mo.eps_gu;
	mo.gscale = 2.0 / (pt->wmin * pt->wmin * pt->wmin);
	mo.gmax = mo.gscale * sqrt(mg * mg + mv * mv);
	return monotone_settles(x, r, s, t, &mo);
}

/*
 * Split r (orientation o, its gu and gv restricted in rg and rv) into
 * its quarters, queueing those whose bound beats the best. The quarters'
 * F and W bounds come from r's own (its parent's slot, else restricted
 * from the root through rf and rw); r's tensors go into a free slot for
 * the quarters to restrict from.
 */
static void split_rect(struct ptens *pt, const struct qctx *x, struct pool *pl,
		       const struct rect *r, int o, const double *rg,
		       const double *rv, double *rf, double *rw,
		       struct rect *heap, int *hn)
{
	double sm = 0.5 * (r->s0 + r->s1), tm = 0.5 * (r->t0 + r->t1);
	const double *W = pt->W;
	struct rect ch[4] = {{r->s0, sm, r->t0, tm, 0.0, r->depth + 1, -1, 0},
			     {sm, r->s1, r->t0, tm, 0.0, r->depth + 1, -1, 1},
			     {r->s0, sm, tm, r->t1, 0.0, r->depth + 1, -1, 2},
			     {sm, r->s1, tm, r->t1, 0.0, r->depth + 1, -1, 3}};
	int k, kept = 0, up = r->parent, slot = pool_take(pl);
	const double *pf = rf, *pw = rw;

	if (up >= 0) {
		pf = slot_f(pl, up, r->quad);
		pw = W ? slot_w(pl, up, r->quad) : NULL;
	} else {
		px__sp_restrict(pt->F, pt->fn, pt->fm, r->s0, r->s1, r->t0, r->t1, rf);
		if (W)
			px__sp_restrict(W, pt->fn, pt->fm, r->s0, r->s1, r->t0, r->t1, rw);
	}
	children_lb(pf, W ? pw : NULL, pt->fn, pt->fm, o, pl, slot, ch);
	for (k = 0; k < 4; k++)
		kept += ch[k].lb < x->best - x->slack;
	if (slot >= 0 && !kept) {
		pool_give(pl, slot);
	} else if (slot >= 0) {
		memcpy(slot_gu(pl, slot), rg, pt->gu.k * sizeof(double));
		memcpy(slot_gv(pl, slot), rv, pt->gv.k * sizeof(double));
		pl->refs[slot] = kept;
		pl->orient[slot] = o;
	}
	if (!kept)
		slot = -1;
	for (k = 0; k < 4; k++)
		if (ch[k].lb < x->best - x->slack) {
			ch[k].parent = slot;
			heap_push(heap, hn, ch[k]);
		}
}

/*
 * The query's set-up: the point's F (gu and gv wait for first use), the
 * rounding slack, and the root's bound into root->lb. 0 when the piece's
 * bounding sphere or that bound already shows nothing nearer than the
 * best.
 */
static inline __attribute__((always_inline)) int
query_start(struct ptens *pt, struct qctx *x, const struct px_spiece *sp,
		       px_vec3 p, double *rf, double *rw, struct rect *root)
{
	const int P = sp->p_, Q = sp->q_;
	double pp = px_v3_dot(p, p), dc, r;
	size_t i, nfs;

	pt->sp = sp;
	pt->p = p;
	pt->fn = nf_s(P);
	pt->fm = nf_s(Q);
	pt->nfs = nfs = px__sp_tsize(pt->fn, pt->fm);
	pt->W = sp->wconst_ ? NULL : sp->fw_;
	pt->rnd = -1.0;
	gtens_init(&pt->gu, sp->gua_, sp->gub_, sp->gun_, sp->gum_);
	gtens_init(&pt->gv, sp->gva_, sp->gvb_, sp->gvn_, sp->gvm_);
	/* w on the patch is at least the smallest weight coefficient
	 * (convex combination). */
	pt->wmin = INFINITY;
	if (sp->wconst_) {
		pt->wmin = 1.0; /* divided out at setup */
	} else {
		const double *w = sp->h_ + 3 * px__sp_tsize(P, Q);
		for (i = 0; i < px__sp_tsize(P, Q); i++)
			pt->wmin = w[i] < pt->wmin ? w[i] : pt->wmin;
	}
	dc = px_v3_dist(p, sp->center_) - sp->radius_;
	if (dc > 0.0 && dc * dc >= x->best)
		return 0;
	/* Equal weights: W is the constant 1 and need not be read. */
	for (i = 0; i < nfs; i++)
		pt->F[i] = sp->fa_[i] -
			   2.0 * (p.x * sp->fb_[i] + p.y * sp->fb_[nfs + i] +
				  p.z * sp->fb_[2 * nfs + i]) +
			   pp * (sp->wconst_ ? 1.0 : sp->fw_[i]);
	r = px_v3_dist(sp->center_, p) + 2.0 * sp->radius_;
	x->slack = 1e-13 * (r * r + px_v3_dot(sp->center_, sp->center_));
	root->lb = rect_lb(pt->F, pt->W, pt->fn, pt->fm, root, rf, rw);
	return root->lb < x->best - x->slack;
}

/* The solver, inlined into both entry points so that the plain one
 * (flt NULL) compiles without the filter. */
static inline __attribute__((always_inline)) int
closest(const struct px_spiece *sp, px_vec3 p, double hint_s, double hint_t,
	const struct px__uv_filter *flt, double *best_d2,
	struct px_spiece_hit *hit)
{
	struct ptens pt;
	double rf[TMAX], rw[TMAX], rg[TMAX], rv[TMAX];
	/* Each split replaces one rectangle by four: the heap never holds
	 * more than 3 * nodes + 1. */
	struct rect heap[3 * PX_SPIECE_MAX_NODES + 4];
	struct rect root = {0.0, 1.0, 0.0, 1.0, 0.0, 0, -1, 0};
	struct pool pl;
	struct qctx x;
	double lb_unresolved = INFINITY;
	int hn = 0, k, last_parent = -1;

	x.sp = sp;
	x.p = p;
	x.hint_s = hint_s;
	x.hint_t = hint_t;
	x.best = *best_d2;
	x.hit = hit;
	x.flt = flt;
	x.improved = 0;
	hit->iters = 0;
	hit->nodes = 0;
	hit->pool_misses = 0;
	hit->certified = 1;
	hit->gap = 0.0;
	if (!query_start(&pt, &x, sp, p, rf, rw, &root))
		goto out;
	heap_push(heap, &hn, root);
	/* An upper bound before subdividing: without one, a patch whose
	 * every point is equally near (a sphere seen from its centre) could
	 * not be settled by the F / W bound. */
	consider(&x, 0.5, 0.5);
	pool_init(&pl, pt.gu.k, pt.gv.k, pt.nfs, !sp->wconst_);
	while (hn > 0 && hit->nodes < PX_SPIECE_MAX_NODES) {
		struct rect r;
		const double *sg = NULL, *sv = NULL;
		double mu = 0.0;
		int verdict, up, o, ha = 0, hb = 0;

		pool_drop(&pl, last_parent); /* the previous rectangle's */
		r = heap_pop(heap, &hn);
		up = last_parent = r.parent;
		/* Orientation of this rectangle's tensors: a quarter of its
		 * parent's has the other one; from the root, rows along s. */
		o = up >= 0 ? !pl.orient[up] : 0;
		if (up >= 0) {
			quad_halves(!o, r.quad, &ha, &hb);
			sg = slot_gu(&pl, up);
			sv = slot_gv(&pl, up);
		}
		if (r.lb >= x.best - x.slack)
			continue; /* the best dropped since it was queued */
		hit->nodes++;
		hit->pool_misses += up < 0 && r.depth > 0;
		if (g_signed(&pt.gu, p, sg, o, ha, hb, &r, rg))
			continue; /* df/ds never vanishes here */
		if (g_signed(&pt.gv, p, sv, o, ha, hb, &r, rv))
			continue; /* df/dt never vanishes here */
		verdict = jac_verdict(&pt, rg, rv, o, r.s1 - r.s0, r.t1 - r.t0, &mu);
		if (verdict < 0)
			continue; /* at most one zero, and a maximum */
		if (verdict > 0) {
			if (settle_monotone(&x, &pt, &r, rg, rv, mu, &hit->iters))
				continue;
		} else {
			/* Keep the upper bound moving while we subdivide. */
			consider(&x, 0.5 * (r.s0 + r.s1), 0.5 * (r.t0 + r.t1));
		}
		if (r.depth >= PX_SPIECE_MAX_DEPTH) {
			lb_unresolved = fmin(lb_unresolved, r.lb);
			continue;
		}
		split_rect(&pt, &x, &pl, &r, o, rg, rv, rf, rw, heap, &hn);
	}
	/* What the node bound left queued bounds what may have been missed. */
	for (k = 0; k < hn; k++)
		lb_unresolved = fmin(lb_unresolved, heap[k].lb);
	if (lb_unresolved < x.best - x.slack) {
		hit->certified = 0;
		hit->gap = sqrt(x.best) - sqrt(fmax(lb_unresolved, 0.0));
	}
out:
	*best_d2 = x.best;
	return x.improved;
}

int px_spiece_closest_hint(const struct px_spiece *sp, px_vec3 p,
			   double hint_s, double hint_t, double *best_d2,
			   struct px_spiece_hit *hit)
{
	return closest(sp, p, hint_s, hint_t, NULL, best_d2, hit);
}

int px__spiece_closest_in(const struct px_spiece *sp, px_vec3 p, double hint_s,
			  double hint_t, const struct px__uv_filter *flt,
			  double *best_d2, struct px_spiece_hit *hit)
{
	return closest(sp, p, hint_s, hint_t, flt, best_d2, hit);
}

#ifdef PX_TEST_HOOKS
/*
 * Test hook (dist_internal.h): the preconditioned monotonicity test on the
 * rectangle [s0, s1] x [t0, t1] (local coordinates) of sp for the point
 * p, its tensors in orientation o, as the query makes it; and, apart
 * from it, the least eigenvalue of the symmetric Jacobian part sampled
 * on a grid x grid lattice of the rectangle from the whole patch's
 * derivative tensors (no restriction, elevation or preconditioning).
 * Returns -1 where the plain test decides (or the diagonal has no one
 * sign), else precond_monotone()'s verdict with *mu.
 */
int px__spiece_precond_probe(const struct px_spiece *sp, px_vec3 p, double s0,
			     double s1, double t0, double t1, int o, int grid,
			     double *mu, double *sampled)
{
	const int un = sp->gun_, um = sp->gum_, vn = sp->gvn_, vm = sp->gvm_;
	const size_t ngu = px__sp_tsize(un, um), ngv = px__sp_tsize(vn, vm);
	static double GU[TMAX], GV[TMAX], rg[TMAX], rv[TMAX], tr[TMAX];
	static double gs[TMAX], gt[TMAX], vs[TMAX], vt[TMAX];
	double ws = s1 - s0, wt = t1 - t0, least = INFINITY;
	struct jac jb;
	int j, k, rc;
	form_g(sp->gua_, sp->gub_, ngu, p, GU);
	form_g(sp->gva_, sp->gvb_, ngv, p, GV);
	px__sp_restrict(GU, un, um, s0, s1, t0, t1, rg);
	px__sp_restrict(GV, vn, vm, s0, s1, t0, t1, rv);
	if (o) {
		transpose(rg, un + 1, um + 1, tr);
		memcpy(rg, tr, ngu * sizeof(double));
		transpose(rv, vn + 1, vm + 1, tr);
		memcpy(rv, tr, ngv * sizeof(double));
	}
	jac_bounds(rg, rv, un, um, vn, vm, o, ws, wt, &jb);
	if (!(jb.a_lo > 0.0 && jb.d_lo > 0.0) || jb.a_lo * jb.d_lo > jb.off * jb.off)
		return -1;
	rc = precond_monotone(rg, rv, un, um, o, ws, wt, jb.a_lo, jb.a_hi, jb.d_lo,
			      jb.d_hi, jb.o_lo, jb.o_hi,
			      point_rounding(sp, p, ngu, ngv), mu);
	/* the derivative tensors of the whole patch, rows along s */
	px__sp_deriv_s(GU, un, um, gs);
	px__sp_deriv_t(GU, un, um, gt);
	px__sp_deriv_s(GV, vn, vm, vs);
	px__sp_deriv_t(GV, vn, vm, vt);
	for (j = 0; j < grid; j++)
		for (k = 0; k < grid; k++) {
			double s = s0 + ws * j / (grid - 1), t = t0 + wt * k / (grid - 1);
			double a = px__sp_eval(gs, un - 1, um, s, t), d = px__sp_eval(vt, vn, vm - 1, s, t);
			double b = 0.5 * (px__sp_eval(gt, un, um - 1, s, t) + px__sp_eval(vs, vn - 1, vm, s, t));
			double l = 0.5 * (a + d) - sqrt(0.25 * (a - d) * (a - d) + b * b);
			least = l < least ? l : least;
		}
	*sampled = least;
	return rc;
}
#endif
