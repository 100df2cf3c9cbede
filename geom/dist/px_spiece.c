#include "px_spiece.h"

#include <float.h>
#include <math.h>
#include <string.h>

#include "dist_internal.h"
#include "px_bern.h"

#define MD PX_SPIECE_MAX_DEGREE
/* Largest tensor: gu of degree (3p - 1, 3q), or F of (2p, 2q). */
#define TMAX ((3 * MD + 1) * (3 * MD + 1))

/* Tensor sizes for degrees (p, q). */
static int nf_s(int p) { return 2 * p; }
static int ngu_s(int p) { return 3 * p - 1; }
static int ngu_t(int q) { return 3 * q; }
static int ngv_s(int p) { return 3 * p; }
static int ngv_t(int q) { return 3 * q - 1; }

static size_t tsize(int n, int m)
{
	return (size_t)(n + 1) * (size_t)(m + 1);
}

size_t px_spiece_doubles(int p, int q)
{
	if (p < 1 || q < 1 || p > MD || q > MD)
		return 0;
	return 4 * tsize(p, q) + 5 * tsize(nf_s(p), nf_s(q)) +
	       4 * tsize(ngu_s(p), ngu_t(q)) + 4 * tsize(ngv_s(p), ngv_t(q));
}

/* Every weight equal: the patch is polynomial once they are divided out,
 * and its critical-point tensors have the lower degrees. */
static int equal_weights(const double (*hw)[4], size_t np)
{
	size_t i;
	for (i = 1; i < np; i++)
		if (hw[i][3] != hw[0][3])
			return 0;
	return 1;
}

size_t px_spiece_doubles_hw(int p, int q, const double (*hw)[4])
{
	if (p < 1 || q < 1 || p > MD || q > MD || !hw)
		return 0;
	if (!equal_weights(hw, tsize(p, q)))
		return px_spiece_doubles(p, q);
	return 4 * tsize(p, q) + 5 * tsize(nf_s(p), nf_s(q)) +
	       4 * tsize(2 * p - 1, 2 * q) + 4 * tsize(2 * p, 2 * q - 1);
}

/* ---- tensor Bernstein helpers (row i along s, column j along t) ---------- */

static void binom_row(int n, double *row)
{
	int i;
	for (i = 0; i <= n; i++)
		row[i] = px_bern_binom(n, i);
}

/* a (na, ma) times b (nb, mb) into out (na + nb, ma + mb). */
static void t_mul(const double *a, int na, int ma, const double *b, int nb,
		  int mb, double *out)
{
	double ba[3 * MD + 2], bma[3 * MD + 2], bb[3 * MD + 2], bmb[3 * MD + 2];
	double bn[3 * MD + 2], bm[3 * MD + 2];
	int n = na + nb, m = ma + mb, i, j, k, l;

	binom_row(na, ba);
	binom_row(ma, bma);
	binom_row(nb, bb);
	binom_row(mb, bmb);
	binom_row(n, bn);
	binom_row(m, bm);
	for (i = 0; i <= n; i++)
		for (j = 0; j <= m; j++)
			out[i * (m + 1) + j] = 0.0;
	for (i = 0; i <= na; i++)
		for (j = 0; j <= ma; j++) {
			double av = a[i * (ma + 1) + j] * ba[i] * bma[j];
			if (av == 0.0)
				continue;
			for (k = 0; k <= nb; k++) {
				double avk = av * bb[k];
				double *o = out + (i + k) * (m + 1) + j;
				const double *br = b + k * (mb + 1);
				for (l = 0; l <= mb; l++)
					o[l] += avk * br[l] * bmb[l];
			}
		}
	for (i = 0; i <= n; i++)
		for (j = 0; j <= m; j++)
			out[i * (m + 1) + j] /= bn[i] * bm[j];
}

/* Derivative along s (degree n - 1, m) or along t (n, m - 1). */
static void t_deriv_s(const double *c, int n, int m, double *out)
{
	int i, j;
	for (i = 0; i < n; i++)
		for (j = 0; j <= m; j++)
			out[i * (m + 1) + j] =
				n * (c[(i + 1) * (m + 1) + j] - c[i * (m + 1) + j]);
}

static void t_deriv_t(const double *c, int n, int m, double *out)
{
	int i, j;
	for (i = 0; i <= n; i++)
		for (j = 0; j < m; j++)
			out[i * m + j] =
				m * (c[i * (m + 1) + j + 1] - c[i * (m + 1) + j]);
}

/*
 * De Casteljau on a tensor in place, a whole row of m + 1 coefficients
 * per step along s (contiguous, so the compiler vectorises it) and one
 * row at a time along t: no gathering of columns, no copies per line.
 * Each keeps the arithmetic of px_bern_split() term for term (s * w_i +
 * t * w_i+1, the left piece by the mirrored sweep), so results are the
 * same to the bit.
 */

/* Keep [0, b] along s. */
static void s_keep_left(double *c, int n, int m, double b)
{
	const int w = m + 1;
	const double a = 1.0 - b;
	int i, j, k;
	for (k = 1; k <= n; k++)
		for (i = n; i >= k; i--) {
			double *ri = c + i * w;
			const double *rp = ri - w;
			for (j = 0; j < w; j++)
				ri[j] = a * rp[j] + b * ri[j];
		}
}

/* Keep [t, 1] along s. */
static void s_keep_right(double *c, int n, int m, double t)
{
	const int w = m + 1;
	const double a = 1.0 - t;
	int i, j, k;
	for (k = n; k > 0; k--)
		for (i = 0; i < k; i++) {
			double *ri = c + i * w;
			const double *rn = ri + w;
			for (j = 0; j < w; j++)
				ri[j] = a * ri[j] + t * rn[j];
		}
}

/* The same along t, row by row. */
static void t_keep_left(double *c, int n, int m, double b)
{
	const double a = 1.0 - b;
	int i, j, k;
	for (i = 0; i <= n; i++) {
		double *r = c + i * (m + 1);
		for (k = 1; k <= m; k++)
			for (j = m; j >= k; j--)
				r[j] = a * r[j - 1] + b * r[j];
	}
}

static void t_keep_right(double *c, int n, int m, double t)
{
	const double a = 1.0 - t;
	int i, j, k;
	for (i = 0; i <= n; i++) {
		double *r = c + i * (m + 1);
		for (k = m; k > 0; k--)
			for (j = 0; j < k; j++)
				r[j] = a * r[j] + t * r[j + 1];
	}
}

/* Restriction to [s0, s1] x [t0, t1], as px_bern_restrict() per line:
 * the left piece at the upper end, then the right piece of that at the
 * lower end rescaled. out may alias c. */
static void t_restrict(const double *c, int n, int m, double s0, double s1,
		       double t0, double t1, double *out)
{
	if (out != c)
		memcpy(out, c, tsize(n, m) * sizeof(double));
	if (s1 < 1.0) {
		s_keep_left(out, n, m, s1);
		s0 = s0 / s1;
	}
	if (s0 > 0.0)
		s_keep_right(out, n, m, s0);
	if (t1 < 1.0) {
		t_keep_left(out, n, m, t1);
		t0 = t0 / t1;
	}
	if (t0 > 0.0)
		t_keep_right(out, n, m, t0);
}

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

/* Ranges of the coefficients of the derivatives of c (n + 1 rows of
 * m + 1) along its rows (lo[0], hi[0]: differences between rows, times
 * n) and along its columns (lo[1], hi[1], times m), without storing
 * them: the Jacobian bounds. One pass for both, two independent chains
 * per bound (the loop is bound by the latency of the min and max, not by
 * the loads). */
static void t_jac_range(const double *c, int n, int m, double lo[2],
			double hi[2])
{
	const int w = m + 1;
	double ra = INFINITY, rb = -INFINITY, rc = INFINITY, rd = -INFINITY;
	double ca = INFINITY, cb = -INFINITY, cc = INFINITY, cd = -INFINITY;
	int i, j;
	for (i = 0; i <= n; i++) {
		const double *row = c + (size_t)i * (size_t)w;
		const double *nxt = row + w;
		for (j = 0; j + 1 < m; j += 2) {
			double d0 = row[j + 1] - row[j], d1 = row[j + 2] - row[j + 1];
			ca = d0 < ca ? d0 : ca;
			cb = d0 > cb ? d0 : cb;
			cc = d1 < cc ? d1 : cc;
			cd = d1 > cd ? d1 : cd;
		}
		if (j < m) {
			double d0 = row[j + 1] - row[j];
			ca = d0 < ca ? d0 : ca;
			cb = d0 > cb ? d0 : cb;
		}
		if (i == n)
			break;
		for (j = 0; j + 1 <= m; j += 2) {
			double d0 = nxt[j] - row[j], d1 = nxt[j + 1] - row[j + 1];
			ra = d0 < ra ? d0 : ra;
			rb = d0 > rb ? d0 : rb;
			rc = d1 < rc ? d1 : rc;
			rd = d1 > rd ? d1 : rd;
		}
		if (j <= m) {
			double d0 = nxt[j] - row[j];
			ra = d0 < ra ? d0 : ra;
			rb = d0 > rb ? d0 : rb;
		}
	}
	/* (an order of the same values: only the sign of a zero bound can
	 * differ, which no test below reads) */
	lo[0] = n * (rc < ra ? rc : ra);
	hi[0] = n * (rd > rb ? rd : rb);
	lo[1] = m * (cc < ca ? cc : ca);
	hi[1] = m * (cd > cb ? cd : cb);
}

/* Element (i, j), i along s, of a tensor of degrees (n, m) stored in
 * orientation o (0: rows along s; 1: the transpose). */
static inline double t_at(const double *c, int n, int m, int o, int i, int j)
{
	return o ? c[(size_t)j * (size_t)(n + 1) + (size_t)i]
		 : c[(size_t)i * (size_t)(m + 1) + (size_t)j];
}

/* Degree elevation by one along the rows (dir 0) or the columns (dir 1)
 * of x ((n + 1) rows of m + 1) into y ((n + 2) rows of m + 1, or n + 1
 * rows of m + 2): y_i = (i x_i-1 + (N - i) x_i) / N, N the new degree. */
static void t_elevate(const double *x, int n, int m, int dir, double *y)
{
	const size_t w = (size_t)(m + 1);
	int i, j;
	if (dir == 0) {
		const double inv = 1.0 / (n + 1);
		memcpy(y, x, w * sizeof(double));
		for (i = 1; i <= n; i++) {
			const double a = i * inv, b = 1.0 - a;
			const double *x0 = x + (size_t)(i - 1) * w, *x1 = x0 + w;
			double *yi = y + (size_t)i * w;
			for (j = 0; j <= m; j++)
				yi[j] = a * x0[j] + b * x1[j];
		}
		memcpy(y + (size_t)(n + 1) * w, x + (size_t)n * w, w * sizeof(double));
	} else {
		double a[3 * MD + 3];
		const double inv = 1.0 / (m + 1);
		for (j = 1; j <= m; j++)
			a[j] = j * inv;
		for (i = 0; i <= n; i++) {
			const double *xi = x + (size_t)i * w;
			double *yi = y + (size_t)i * (w + 1);
			yi[0] = xi[0];
			for (j = 1; j <= m; j++)
				yi[j] = a[j] * xi[j - 1] + (1.0 - a[j]) * xi[j];
			yi[m + 1] = xi[m];
		}
	}
}

/* The derivative of x (R rows of C, a Bernstein tensor of degree R - 1
 * along its rows) along the rows, written back at the same degree (the
 * difference tensor elevated once): i (x_i - x_i-1) + (n - i) (x_i+1 -
 * x_i), n = R - 1. */
static void d_rows(const double *x, int R, int C, double *out)
{
	const int n = R - 1;
	int i, j;
	for (j = 0; j < C; j++)
		out[j] = n * (x[C + j] - x[j]);
	for (i = 1; i < n; i++) {
		const double *r = x + (size_t)i * (size_t)C;
		double *o = out + (size_t)i * (size_t)C;
		const double a = n - i, b = i;
		for (j = 0; j < C; j++)
			o[j] = a * (r[C + j] - r[j]) + b * (r[j] - r[j - C]);
	}
	for (j = 0; j < C; j++)
		out[(size_t)n * C + j] = n * (x[(size_t)n * C + j] - x[(size_t)(n - 1) * C + j]);
}

/* The same along the columns (degree C - 1). */
static void d_cols(const double *x, int R, int C, double *out)
{
	const int n = C - 1;
	double wa[3 * MD + 3], wb[3 * MD + 3];
	int i, j;
	for (j = 1; j < n; j++) {
		wa[j] = n - j;
		wb[j] = j;
	}
	for (i = 0; i < R; i++) {
		const double *r = x + (size_t)i * (size_t)C;
		double *o = out + (size_t)i * (size_t)C;
		double dl = r[1] - r[0];
		o[0] = n * dl;
		for (j = 1; j < n; j++) {
			double dr = r[j + 1] - r[j];
			o[j] = wa[j] * dr + wb[j] * dl;
			dl = dr;
		}
		o[n] = n * dl;
	}
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
 * each derivative is written back at that degree (d_rows(), d_cols()).
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
		t_elevate(rg, um, un, 1, eg);
		t_elevate(rv, vm, vn, 0, h);
	} else {
		t_elevate(rg, un, um, 0, eg);
		t_elevate(rv, vn, vm, 1, h);
	}
	for (k = 0; k < nk; k++) {
		double g = fabs(eg[k]), v = fabs(h[k]);
		gmax = g > gmax ? g : gmax;
		vmax = v > vmax ? v : vmax;
		h[k] = m12 * eg[k] + m22 * h[k];
	}
	d_rows(h, R, C, hr);
	d_cols(h, R, C, hc);
	d_rows(eg, R, C, gr);
	d_cols(eg, R, C, gc);
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

/* ---- setup ------------------------------------------------------------------ */

int px_spiece_init(struct px_spiece *sp, int p, int q, const double (*hw)[4],
		   double u0, double u1, double v0, double v1, double *mem)
{
	double hs[4][(MD) * (MD + 1)], ht[4][(MD + 1) * (MD)];
	double k1[TMAX], k2[TMAX], ku[3][TMAX], kv[3][TMAX], tmp[TMAX];
	size_t np = tsize(p, q), i, nfs, ngu, ngv;
	int wp, wq;
	double *cur = mem;
	int c;

	if (!sp || !hw || !mem)
		return PX_E_INVAL;
	if (p < 1 || q < 1 || p > MD || q > MD)
		return PX_E_RANGE;
	if (!isfinite(u0) || !isfinite(u1) || !isfinite(v0) || !isfinite(v1))
		return PX_E_NAN;
	if (!(u0 < u1) || !(v0 < v1))
		return PX_E_INVAL;
	memset(sp, 0, sizeof(*sp));
	sp->p_ = p;
	sp->q_ = q;
	sp->u0_ = u0;
	sp->u1_ = u1;
	sp->v0_ = v0;
	sp->v1_ = v1;
	nfs = tsize(nf_s(p), nf_s(q));
	/* Blocks packed at the degrees the weights give (see
	 * px_spiece_doubles_hw()). */
	if (equal_weights(hw, np)) {
		ngu = tsize(2 * p - 1, 2 * q);
		ngv = tsize(2 * p, 2 * q - 1);
	} else {
		ngu = tsize(ngu_s(p), ngu_t(q));
		ngv = tsize(ngv_s(p), ngv_t(q));
	}
	sp->h_ = cur;
	cur += 4 * np;
	sp->fa_ = cur;
	cur += nfs;
	sp->fb_ = cur;
	cur += 3 * nfs;
	sp->fw_ = cur;
	cur += nfs;
	sp->gua_ = cur;
	cur += ngu;
	sp->gub_ = cur;
	cur += 3 * ngu;
	sp->gva_ = cur;
	cur += ngv;
	sp->gvb_ = cur;
	sp->box_ = px_aabb_empty();
	for (i = 0; i < np; i++) {
		for (c = 0; c < 4; c++) {
			if (!isfinite(hw[i][c]))
				return PX_E_NAN;
			sp->h_[c * np + i] = hw[i][c];
		}
		if (!(hw[i][3] > 0.0))
			return PX_E_INVAL;
		px_aabb_extend(&sp->box_, px_v3(hw[i][0] / hw[i][3],
						hw[i][1] / hw[i][3],
						hw[i][2] / hw[i][3]));
	}
	sp->center_ = px_aabb_center(&sp->box_);
	sp->radius_ = 0.5 * px_aabb_diagonal(&sp->box_);
	/* Equal weights: divide them out, and w becomes the degree-0
	 * constant 1. The critical-point tensors then drop from degree
	 * 3p - 1 to 2p - 1, which is most of the query's work. */
	sp->wconst_ = 1;
	for (i = 1; i < np; i++)
		if (sp->h_[3 * np + i] != sp->h_[3 * np])
			sp->wconst_ = 0;
	if (sp->wconst_) {
		double w0 = sp->h_[3 * np];
		for (i = 0; i < 4 * np; i++)
			sp->h_[i] /= w0;
	}
	wp = sp->wconst_ ? 0 : p;
	wq = sp->wconst_ ? 0 : q;
	sp->gun_ = 2 * p + wp - 1;
	sp->gum_ = 2 * q + wq;
	sp->gvn_ = 2 * p + wp;
	sp->gvm_ = 2 * q + wq - 1;
	/* The same decision as the layout above (the same weights). */
	ngu = tsize(sp->gun_, sp->gum_);
	ngv = tsize(sp->gvn_, sp->gvm_);
	{
		const double *w = sp->h_ + 3 * np;
		double one[TMAX];
		size_t nk;

		for (i = 0; i < TMAX; i++)
			one[i] = 1.0; /* Bernstein coefficients of 1: elevation */
		for (c = 0; c < 4; c++) {
			t_deriv_s(sp->h_ + c * np, p, q, hs[c]);
			t_deriv_t(sp->h_ + c * np, p, q, ht[c]);
		}
		/* K_s = H_s w - H w_s and K_t = H_t w - H w_t; with a constant
		 * w they are H_s and H_t. */
		for (c = 0; c < 3; c++) {
			const double *h = sp->h_ + c * np;
			if (sp->wconst_) {
				memcpy(ku[c], hs[c], tsize(p - 1, q) * sizeof(double));
				memcpy(kv[c], ht[c], tsize(p, q - 1) * sizeof(double));
				continue;
			}
			t_mul(hs[c], p - 1, q, w, p, q, k1);
			t_mul(h, p, q, hs[3], p - 1, q, k2);
			for (i = 0; i < tsize(2 * p - 1, 2 * q); i++)
				ku[c][i] = k1[i] - k2[i];
			t_mul(ht[c], p, q - 1, w, p, q, k1);
			t_mul(h, p, q, ht[3], p, q - 1, k2);
			for (i = 0; i < tsize(2 * p, 2 * q - 1); i++)
				kv[c][i] = k1[i] - k2[i];
		}
		memset(sp->gua_, 0, ngu * sizeof(double));
		memset(sp->gva_, 0, ngv * sizeof(double));
		memset(sp->fa_, 0, nfs * sizeof(double));
		for (c = 0; c < 3; c++) {
			const double *h = sp->h_ + c * np;
			/* a = H . K (degree of gu), b = w K raised to it. */
			t_mul(h, p, q, ku[c], p + wp - 1, q + wq, tmp);
			nk = tsize(sp->gun_, sp->gum_);
			for (i = 0; i < nk; i++)
				sp->gua_[i] += tmp[i];
			t_mul(w, wp, wq, ku[c], p + wp - 1, q + wq, k1);
			t_mul(one, p - wp, q - wq, k1, p + 2 * wp - 1, q + 2 * wq,
			      sp->gub_ + c * ngu);
			t_mul(h, p, q, kv[c], p + wp, q + wq - 1, tmp);
			nk = tsize(sp->gvn_, sp->gvm_);
			for (i = 0; i < nk; i++)
				sp->gva_[i] += tmp[i];
			t_mul(w, wp, wq, kv[c], p + wp, q + wq - 1, k1);
			t_mul(one, p - wp, q - wq, k1, p + 2 * wp, q + 2 * wq - 1,
			      sp->gvb_ + c * ngv);
			/* w^2 f = |H|^2 - 2 P . (w H) + |P|^2 w^2, all raised
			 * to degree (2p, 2q). */
			t_mul(h, p, q, h, p, q, tmp);
			for (i = 0; i < nfs; i++)
				sp->fa_[i] += tmp[i];
			t_mul(w, wp, wq, h, p, q, k1);
			t_mul(one, p - wp, q - wq, k1, p + wp, q + wq, sp->fb_ + c * nfs);
		}
		t_mul(w, wp, wq, w, wp, wq, k1);
		t_mul(one, 2 * (p - wp), 2 * (q - wq), k1, 2 * wp, 2 * wq, sp->fw_);
	}
	return PX_OK;
}

/* ---- evaluation --------------------------------------------------------------- */

/* Raise Bernstein basis values of degree k - 1 to degree k in place. */
static inline void raise(double *b, int k, double t, double u)
{
	int i;
	b[k] = t * b[k - 1];
	for (i = k - 1; i > 0; i--)
		b[i] = u * b[i] + t * b[i - 1];
	b[0] = u * b[0];
}

/* Bernstein basis of degree n (<= MD) at t, with first and second
 * derivatives when b1 / b2 are not NULL (both need n >= 1). */
static void basis(int n, double t, double *b0, double *b1, double *b2)
{
	double lo[MD + 1], u = 1.0 - t;
	int k, i;

	b0[0] = 1.0;
	if (!b1 && !b2) {
		for (k = 1; k <= n; k++)
			raise(b0, k, t, u);
		return;
	}
	for (k = 1; k <= n - 2; k++)
		raise(b0, k, t, u);
	if (b2) {
		/* Degree n - 2 values give the second derivative. */
		for (i = 0; i <= n; i++) {
			double a = (n >= 2 && i >= 2) ? b0[i - 2] : 0.0;
			double m = (n >= 2 && i >= 1 && i - 1 <= n - 2) ? b0[i - 1] : 0.0;
			double c = (n >= 2 && i <= n - 2) ? b0[i] : 0.0;
			b2[i] = n * (n - 1) * (a - 2.0 * m + c);
		}
	}
	if (n >= 2)
		raise(b0, n - 1, t, u);
	for (i = 0; i < n; i++)
		lo[i] = b0[i];
	raise(b0, n, t, u);
	if (b1)
		for (i = 0; i <= n; i++)
			b1[i] = n * ((i >= 1 ? lo[i - 1] : 0.0) - (i < n ? lo[i] : 0.0));
}

/* Point only: the hot path of sampling and candidate checks. */
static px_vec3 spiece_point(const struct px_spiece *sp, double s, double t)
{
	double bs[MD + 1], bt[MD + 1], acc[4] = {0, 0, 0, 0};
	int p = sp->p_, q = sp->q_, i, j;
	size_t np = tsize(p, q);
	const double *h = sp->h_;

	basis(p, s, bs, NULL, NULL);
	basis(q, t, bt, NULL, NULL);
	for (i = 0; i <= p; i++)
		for (j = 0; j <= q; j++) {
			size_t k = (size_t)i * (q + 1) + j;
			double w = bs[i] * bt[j];
			acc[0] += w * h[k];
			acc[1] += w * h[np + k];
			acc[2] += w * h[2 * np + k];
			acc[3] += w * h[3 * np + k];
		}
	return px_v3(acc[0] / acc[3], acc[1] / acc[3], acc[2] / acc[3]);
}

px_vec3 px_spiece_eval(const struct px_spiece *sp, double s, double t,
		       px_vec3 *su, px_vec3 *sv, px_vec3 *suu, px_vec3 *suv,
		       px_vec3 *svv)
{
	double bs[3][MD + 1], bt[3][MD + 1];
	/* d[a][b][c]: derivative a in s, b in t of homogeneous component c */
	double d[3][3][4];
	int p = sp->p_, q = sp->q_, i, j, c;
	size_t np = tsize(p, q);
	double ks = 1.0 / (sp->u1_ - sp->u0_), kt = 1.0 / (sp->v1_ - sp->v0_);
	px_vec3 S;

	if (!su && !sv && !suu && !suv && !svv)
		return spiece_point(sp, s, t);
	basis(p, s, bs[0], bs[1], bs[2]);
	basis(q, t, bt[0], bt[1], bt[2]);
	memset(d, 0, sizeof(d));
	/* Row by row: the t-sums of a row (value, first and second
	 * derivative) first, then their s-weights; fewer products than
	 * weighting every control point six times. */
	for (c = 0; c < 4; c++) {
		const double *h = sp->h_ + c * np;
		for (i = 0; i <= p; i++) {
			const double *row = h + (size_t)i * (q + 1);
			double r0 = 0.0, r1 = 0.0, r2 = 0.0;
			for (j = 0; j <= q; j++) {
				r0 += bt[0][j] * row[j];
				r1 += bt[1][j] * row[j];
				r2 += bt[2][j] * row[j];
			}
			d[0][0][c] += bs[0][i] * r0;
			d[1][0][c] += bs[1][i] * r0;
			d[2][0][c] += bs[2][i] * r0;
			d[0][1][c] += bs[0][i] * r1;
			d[1][1][c] += bs[1][i] * r1;
			d[0][2][c] += bs[0][i] * r2;
		}
	}
	{
		/* Quotient rule for S = H / w up to second order. */
		double w = d[0][0][3], iw = 1.0 / w;
		double S0[3], Ss[3], St[3], Sss[3], Sst[3], Stt[3];
		double ws = d[1][0][3], wt = d[0][1][3], wss = d[2][0][3],
		       wst = d[1][1][3], wtt = d[0][2][3];
		for (c = 0; c < 3; c++) {
			S0[c] = d[0][0][c] * iw;
			Ss[c] = (d[1][0][c] - ws * S0[c]) * iw;
			St[c] = (d[0][1][c] - wt * S0[c]) * iw;
			Sss[c] = (d[2][0][c] - 2.0 * ws * Ss[c] - wss * S0[c]) * iw;
			Sst[c] = (d[1][1][c] - ws * St[c] - wt * Ss[c] - wst * S0[c]) * iw;
			Stt[c] = (d[0][2][c] - 2.0 * wt * St[c] - wtt * S0[c]) * iw;
		}
		S = px_v3(S0[0], S0[1], S0[2]);
		if (su)
			*su = px_v3(Ss[0] * ks, Ss[1] * ks, Ss[2] * ks);
		if (sv)
			*sv = px_v3(St[0] * kt, St[1] * kt, St[2] * kt);
		if (suu)
			*suu = px_v3(Sss[0] * ks * ks, Sss[1] * ks * ks, Sss[2] * ks * ks);
		if (suv)
			*suv = px_v3(Sst[0] * ks * kt, Sst[1] * ks * kt, Sst[2] * ks * kt);
		if (svv)
			*svv = px_v3(Stt[0] * kt * kt, Stt[1] * kt * kt, Stt[2] * kt * kt);
	}
	return S;
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
	int improved;
};

static void consider(struct qctx *x, double s, double t)
{
	px_vec3 q = spiece_point(x->sp, s, t);
	double d2 = px_v3_dist2(q, x->p);
	if (d2 < x->best) {
		x->best = d2;
		x->hit->d2 = d2;
		x->hit->point = q;
		x->hit->u = x->sp->u0_ + s * (x->sp->u1_ - x->sp->u0_);
		x->hit->v = x->sp->v0_ + t * (x->sp->v1_ - x->sp->v0_);
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
	fcur = px_v3_dist2(spiece_point(sp, s, t), x->p);
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
			fcur = px_v3_dist2(spiece_point(sp, s, t), x->p);
			continue;
		}
		for (al = 1.0, k = 0; k < 12; k++, al *= 0.5) {
			double ns = clampd(s + al * ds, r->s0, r->s1);
			double nt = clampd(t + al * dt, r->t0, r->t1);
			double fn = px_v3_dist2(spiece_point(sp, ns, nt), x->p);
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
#ifdef PX_TEST_HOOKS
int px__spiece_pool_cap = -1;
#endif
/* Test hook (dist_internal.h): 1 leaves the preconditioned monotonicity test
 * out (precond_monotone()). */
#ifdef PX_TEST_HOOKS
int px__spiece_no_precond = 0;
#endif
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
	const size_t k = tsize(fn, fm);
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
	t_restrict(F, fn, fm, r->s0, r->s1, r->t0, r->t1, rf);
	if (W)
		t_restrict(W, fn, fm, r->s0, r->s1, r->t0, r->t1, rw);
	return ratio_min(rf, W ? rw : NULL, tsize(fn, fm));
}

/* Value of a tensor at (s, t) from its Bernstein basis values. */
static double t_eval(const double *c, int n, int m, double s, double t)
{
	double bs[3 * MD + 2], bt[3 * MD + 2], acc = 0.0;
	int i, j, k;

	bs[0] = 1.0;
	for (k = 1; k <= n; k++)
		raise(bs, k, s, 1.0 - s);
	bt[0] = 1.0;
	for (k = 1; k <= m; k++)
		raise(bt, k, t, 1.0 - t);
	for (i = 0; i <= n; i++) {
		double row = 0.0;
		for (j = 0; j <= m; j++)
			row += c[i * (m + 1) + j] * bt[j];
		acc += row * bs[i];
	}
	return acc;
}

/*
 * Rounding bound of gu or gv evaluated at one point: each coefficient
 * a - P . b is formed with an error of a few ulps of |a| + |P| |b|
 * (cancellation included), the convex combination of the basis keeps the
 * largest, and the summation adds a few ulps per term.
 */
static double point_rounding(const struct px_spiece *sp, px_vec3 p, size_t ngu,
			     size_t ngv)
{
	double m = 0.0, ax = fabs(p.x), ay = fabs(p.y), az = fabs(p.z);
	size_t i;
	for (i = 0; i < ngu; i++) {
		double e = fabs(sp->gua_[i]) + ax * fabs(sp->gub_[i]) +
			   ay * fabs(sp->gub_[ngu + i]) + az * fabs(sp->gub_[2 * ngu + i]);
		m = e > m ? e : m;
	}
	for (i = 0; i < ngv; i++) {
		double e = fabs(sp->gva_[i]) + ax * fabs(sp->gvb_[i]) +
			   ay * fabs(sp->gvb_[ngv + i]) + az * fabs(sp->gvb_[2 * ngv + i]);
		m = e > m ? e : m;
	}
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

int px_spiece_closest_hint(const struct px_spiece *sp, px_vec3 p,
			   double hint_s, double hint_t, double *best_d2,
			   struct px_spiece_hit *hit)
{
	const int P = sp->p_, Q = sp->q_;
	const int fn = nf_s(P), fm = nf_s(Q);
	const int un = sp->gun_, um = sp->gum_, vn = sp->gvn_, vm = sp->gvm_;
	const size_t nfs = tsize(fn, fm), ngu = tsize(un, um), ngv = tsize(vn, vm);
	double F[TMAX], GU[TMAX], GV[TMAX];
	double rf[TMAX], rw[TMAX], rg[TMAX], rv[TMAX];
	/* Each split replaces one rectangle by four: the heap never holds
	 * more than 3 * nodes + 1. */
	struct rect heap[3 * PX_SPIECE_MAX_NODES + 4];
	struct pool pl;
	struct qctx x;
	double pp = px_v3_dot(p, p), lb_unresolved = INFINITY;
	int hn = 0, k, have_gu = 0, have_gv = 0, last_parent = -1;
	double eps_gu = 0.0, eps_gv = 0.0;
	/* Smallest weight: w on the patch is at least the smallest weight
	 * coefficient (convex combination). */
	double wmin = INFINITY;
	double rnd_g = -1.0; /* point_rounding(), on first use */
	size_t i;

	if (sp->wconst_) {
		wmin = 1.0; /* divided out at setup */
	} else {
		const double *w = sp->h_ + 3 * tsize(P, Q);
		for (i = 0; i < tsize(P, Q); i++)
			wmin = w[i] < wmin ? w[i] : wmin;
	}
	x.sp = sp;
	x.p = p;
	x.hint_s = hint_s;
	x.hint_t = hint_t;
	x.best = *best_d2;
	x.hit = hit;
	x.improved = 0;
	hit->iters = 0;
	hit->nodes = 0;
	hit->pool_misses = 0;
	hit->certified = 1;
	hit->gap = 0.0;
	{
		double dc = px_v3_dist(p, sp->center_) - sp->radius_;
		if (dc > 0.0 && dc * dc >= x.best)
			goto out;
	}
	/* Equal weights: W is the constant 1 and need not be read. */
	for (i = 0; i < nfs; i++)
		F[i] = sp->fa_[i] -
		       2.0 * (p.x * sp->fb_[i] + p.y * sp->fb_[nfs + i] +
			      p.z * sp->fb_[2 * nfs + i]) +
		       pp * (sp->wconst_ ? 1.0 : sp->fw_[i]);
	{
		double r = px_v3_dist(sp->center_, p) + 2.0 * sp->radius_;
		x.slack = 1e-13 * (r * r + px_v3_dot(sp->center_, sp->center_));
	}
	{
		struct rect root = {0.0, 1.0, 0.0, 1.0, 0.0, 0, -1, 0};
		root.lb = rect_lb(F, sp->wconst_ ? NULL : sp->fw_, fn, fm, &root, rf, rw);
		if (root.lb >= x.best - x.slack)
			goto out;
		heap_push(heap, &hn, root);
	}
	/* gu and gv are formed on first use: most candidate patches are
	 * settled by the bound or by gu's sign alone. */
	/* An upper bound before subdividing: without one, a patch whose
	 * every point is equally near (a sphere seen from its centre) could
	 * not be settled by the F / W bound. */
	consider(&x, 0.5, 0.5);
	pool_init(&pl, ngu, ngv, nfs, !sp->wconst_);
	while (hn > 0 && hit->nodes < PX_SPIECE_MAX_NODES) {
		struct rect r;
		double ws, wt, mu = 0.0;
		int certain = 0, up, o, ha = 0, hb = 0;

		pool_drop(&pl, last_parent); /* the previous rectangle's */
		r = heap_pop(heap, &hn);
		ws = r.s1 - r.s0;
		wt = r.t1 - r.t0;
		up = last_parent = r.parent;
		/* Orientation of this rectangle's tensors: a quarter of its
		 * parent's has the other one; from the root, rows along s. */
		o = up >= 0 ? !pl.orient[up] : 0;
		if (up >= 0)
			quad_halves(!o, r.quad, &ha, &hb);
		if (r.lb >= x.best - x.slack)
			continue; /* the best dropped since it was queued */
		hit->nodes++;
		hit->pool_misses += up < 0 && r.depth > 0;
		if (!have_gu) {
			for (i = 0; i < ngu; i++)
				GU[i] = sp->gua_[i] -
					(p.x * sp->gub_[i] + p.y * sp->gub_[ngu + i] +
					 p.z * sp->gub_[2 * ngu + i]);
			eps_gu = 1e-12 * max_abs(GU, ngu);
			have_gu = 1;
		}
		/* The parent's tensors have orientation !o (rows along s
		 * when o is 1). */
		if (up >= 0)
			t_quarter(slot_gu(&pl, up), (o ? un : um) + 1, (o ? um : un) + 1,
				  ha, hb, rg);
		else
			t_restrict(GU, un, um, r.s0, r.s1, r.t0, r.t1, rg);
		if (strict_sign(rg, ngu, eps_gu))
			continue; /* df/ds never vanishes here */
		if (!have_gv) {
			for (i = 0; i < ngv; i++)
				GV[i] = sp->gva_[i] -
					(p.x * sp->gvb_[i] + p.y * sp->gvb_[ngv + i] +
					 p.z * sp->gvb_[2 * ngv + i]);
			eps_gv = 1e-12 * max_abs(GV, ngv);
			have_gv = 1;
		}
		if (up >= 0)
			t_quarter(slot_gv(&pl, up), (o ? vn : vm) + 1, (o ? vm : vn) + 1,
				  ha, hb, rv);
		else
			t_restrict(GV, vn, vm, r.s0, r.s1, r.t0, r.t1, rv);
		if (strict_sign(rv, ngv, eps_gv))
			continue; /* df/dt never vanishes here */
		{
			/* Bernstein bounds of the Jacobian of (gu, gv), in the
			 * piece's local scale (d/ds = (1/ws) d/ds_sub). */
			double a_lo, a_hi, b_lo, b_hi, c_lo, c_hi, d_lo, d_hi, off;
			double glo[2], ghi[2], vlo[2], vhi[2];
			/* o: the rows run along t, so the s-derivative is
			 * along the columns */
			t_jac_range(rg, o ? um : un, o ? un : um, glo, ghi);
			t_jac_range(rv, o ? vm : vn, o ? vn : vm, vlo, vhi);
			a_lo = glo[o];
			a_hi = ghi[o];
			b_lo = glo[!o];
			b_hi = ghi[!o];
			c_lo = vlo[o];
			c_hi = vhi[o];
			d_lo = vlo[!o];
			d_hi = vhi[!o];
			a_lo /= ws;
			a_hi /= ws;
			c_lo /= ws;
			c_hi /= ws;
			b_lo /= wt;
			b_hi /= wt;
			d_lo /= wt;
			d_hi /= wt;
			off = 0.5 * fmax(fabs(b_lo + c_lo), fabs(b_hi + c_hi));
			if (a_lo > 0.0 && d_lo > 0.0 && a_lo * d_lo > off * off) {
				certain = 1; /* monotone: one zero at most, a minimum */
				/* Its modulus: the smallest eigenvalue of the
				 * symmetric part grows with a and d and falls
				 * with |off|, so the corner values bound it. */
				mu = 0.5 * (a_lo + d_lo) -
				     sqrt(0.25 * (a_lo - d_lo) * (a_lo - d_lo) + off * off);
			} else if (a_hi < 0.0 && d_hi < 0.0 && a_hi * d_hi > off * off)
				continue; /* at most one zero, and a maximum */
			else if (a_lo > 0.0 && d_lo > 0.0 && !px__spiece_no_precond) {
				if (rnd_g < 0.0)
					rnd_g = point_rounding(sp, p, ngu, ngv);
				certain = precond_monotone(rg, rv, un, um, o, ws, wt, a_lo,
							   a_hi, d_lo, d_hi,
							   0.5 * (b_lo + c_lo),
							   0.5 * (b_hi + c_hi), rnd_g, &mu);
			}
		}
		if (certain) {
			double s = NAN, t = NAN;
			int found = newton_f(&x, &r, &hit->iters, &s, &t);
			if (s == s)
				consider(&x, s, t); /* a real point: a valid bound */
			if (found)
				continue;
			if (s == s && mu > 0.0) {
				struct mono mo;
				double mg = max_abs(rg, ngu), mv = max_abs(rv, ngv);
				mo.mu = mu;
				mo.gu = t_eval(GU, un, um, s, t);
				mo.gv = t_eval(GV, vn, vm, s, t);
				if (rnd_g < 0.0)
					rnd_g = point_rounding(sp, p, ngu, ngv);
				mo.eps_gu = rnd_g;
				mo.eps_gv = rnd_g;
				mo.gscale = 2.0 / (wmin * wmin * wmin);
				mo.gmax = mo.gscale * sqrt(mg * mg + mv * mv);
				if (monotone_settles(&x, &r, s, t, &mo))
					continue;
			}
		} else {
			/* Keep the upper bound moving while we subdivide. */
			consider(&x, 0.5 * (r.s0 + r.s1), 0.5 * (r.t0 + r.t1));
		}
		if (r.depth >= PX_SPIECE_MAX_DEPTH) {
			lb_unresolved = fmin(lb_unresolved, r.lb);
			continue;
		}
		{
			double sm = 0.5 * (r.s0 + r.s1), tm = 0.5 * (r.t0 + r.t1);
			const double *W = sp->wconst_ ? NULL : sp->fw_;
			struct rect ch[4] = {{r.s0, sm, r.t0, tm, 0.0, r.depth + 1, -1, 0},
					     {sm, r.s1, r.t0, tm, 0.0, r.depth + 1, -1, 1},
					     {r.s0, sm, tm, r.t1, 0.0, r.depth + 1, -1, 2},
					     {sm, r.s1, tm, r.t1, 0.0, r.depth + 1, -1, 3}};
			int kept = 0, slot = pool_take(&pl);
			const double *pf = rf, *pw = rw;
			/* This rectangle's F and W: its parent cut them out
			 * already, or from the root. */
			if (up >= 0) {
				pf = slot_f(&pl, up, r.quad);
				pw = W ? slot_w(&pl, up, r.quad) : NULL;
			} else {
				t_restrict(F, fn, fm, r.s0, r.s1, r.t0, r.t1, rf);
				if (W)
					t_restrict(W, fn, fm, r.s0, r.s1, r.t0, r.t1, rw);
			}
			children_lb(pf, W ? pw : NULL, fn, fm, o, &pl, slot, ch);
			for (k = 0; k < 4; k++)
				kept += ch[k].lb < x.best - x.slack;
			if (slot >= 0 && !kept)
				pool_give(&pl, slot);
			else if (slot >= 0) {
				memcpy(slot_gu(&pl, slot), rg, ngu * sizeof(double));
				memcpy(slot_gv(&pl, slot), rv, ngv * sizeof(double));
				pl.refs[slot] = kept;
				pl.orient[slot] = o;
			}
			if (!kept)
				slot = -1;
			for (k = 0; k < 4; k++)
				if (ch[k].lb < x.best - x.slack) {
					ch[k].parent = slot;
					heap_push(heap, &hn, ch[k]);
				}
		}
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
	const size_t ngu = tsize(un, um), ngv = tsize(vn, vm);
	static double GU[TMAX], GV[TMAX], rg[TMAX], rv[TMAX], tr[TMAX];
	static double gs[TMAX], gt[TMAX], vs[TMAX], vt[TMAX];
	double ws = s1 - s0, wt = t1 - t0, glo[2], ghi[2], vlo[2], vhi[2];
	double a_lo, a_hi, b_lo, b_hi, c_lo, c_hi, d_lo, d_hi, off, least = INFINITY;
	size_t i;
	int j, k, rc;
	for (i = 0; i < ngu; i++)
		GU[i] = sp->gua_[i] - (p.x * sp->gub_[i] + p.y * sp->gub_[ngu + i] +
				       p.z * sp->gub_[2 * ngu + i]);
	for (i = 0; i < ngv; i++)
		GV[i] = sp->gva_[i] - (p.x * sp->gvb_[i] + p.y * sp->gvb_[ngv + i] +
				       p.z * sp->gvb_[2 * ngv + i]);
	t_restrict(GU, un, um, s0, s1, t0, t1, rg);
	t_restrict(GV, vn, vm, s0, s1, t0, t1, rv);
	if (o) {
		transpose(rg, un + 1, um + 1, tr);
		memcpy(rg, tr, ngu * sizeof(double));
		transpose(rv, vn + 1, vm + 1, tr);
		memcpy(rv, tr, ngv * sizeof(double));
	}
	t_jac_range(rg, o ? um : un, o ? un : um, glo, ghi);
	t_jac_range(rv, o ? vm : vn, o ? vn : vm, vlo, vhi);
	a_lo = glo[o] / ws;
	a_hi = ghi[o] / ws;
	b_lo = glo[!o] / wt;
	b_hi = ghi[!o] / wt;
	c_lo = vlo[o] / ws;
	c_hi = vhi[o] / ws;
	d_lo = vlo[!o] / wt;
	d_hi = vhi[!o] / wt;
	off = 0.5 * fmax(fabs(b_lo + c_lo), fabs(b_hi + c_hi));
	if (!(a_lo > 0.0 && d_lo > 0.0) || a_lo * d_lo > off * off)
		return -1;
	rc = precond_monotone(rg, rv, un, um, o, ws, wt, a_lo, a_hi, d_lo, d_hi,
			      0.5 * (b_lo + c_lo), 0.5 * (b_hi + c_hi),
			      point_rounding(sp, p, ngu, ngv), mu);
	/* the derivative tensors of the whole patch, rows along s */
	t_deriv_s(GU, un, um, gs);
	t_deriv_t(GU, un, um, gt);
	t_deriv_s(GV, vn, vm, vs);
	t_deriv_t(GV, vn, vm, vt);
	for (j = 0; j < grid; j++)
		for (k = 0; k < grid; k++) {
			double s = s0 + ws * j / (grid - 1), t = t0 + wt * k / (grid - 1);
			double a = t_eval(gs, un - 1, um, s, t), d = t_eval(vt, vn, vm - 1, s, t);
			double b = 0.5 * (t_eval(gt, un, um - 1, s, t) + t_eval(vs, vn - 1, vm, s, t));
			double l = 0.5 * (a + d) - sqrt(0.25 * (a - d) * (a - d) + b * b);
			least = l < least ? l : least;
		}
	*sampled = least;
	return rc;
}
#endif
