/*
 * spiece_tensor.c - Bernstein tensor algebra of the surface pieces
 * (row i along s, column j along t): products and derivatives for the
 * setup's critical-point tensors, and for the solver restriction to a
 * rectangle, the Jacobian's coefficient ranges, degree elevation and
 * evaluation at a point.
 */
#include <math.h>
#include <string.h>

#include "dist_internal.h"
#include "px_bern.h"

#define MD PX__SP_MD

static void binom_row(int n, double *row)
{
	int i;
	for (i = 0; i <= n; i++)
		row[i] = px_bern_binom(n, i);
}

/* a (na, ma) times b (nb, mb) into out (na + nb, ma + mb). */
void px__sp_mul(const double *a, int na, int ma, const double *b, int nb,
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
void px__sp_deriv_s(const double *c, int n, int m, double *out)
{
	int i, j;
	for (i = 0; i < n; i++)
		for (j = 0; j <= m; j++)
			out[i * (m + 1) + j] =
				n * (c[(i + 1) * (m + 1) + j] - c[i * (m + 1) + j]);
}

void px__sp_deriv_t(const double *c, int n, int m, double *out)
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
void px__sp_restrict(const double *c, int n, int m, double s0, double s1,
		       double t0, double t1, double *out)
{
	if (out != c)
		memcpy(out, c, px__sp_tsize(n, m) * sizeof(double));
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

/* Ranges of the coefficients of the derivatives of c (n + 1 rows of
 * m + 1) along its rows (lo[0], hi[0]: differences between rows, times
 * n) and along its columns (lo[1], hi[1], times m), without storing
 * them: the Jacobian bounds. One pass for both, two independent chains
 * per bound (the loop is bound by the latency of the min and max, not by
 * the loads). */
void px__sp_jac_range(const double *c, int n, int m, double lo[2],
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

/* Degree elevation by one along the rows (dir 0) or the columns (dir 1)
 * of x ((n + 1) rows of m + 1) into y ((n + 2) rows of m + 1, or n + 1
 * rows of m + 2): y_i = (i x_i-1 + (N - i) x_i) / N, N the new degree. */
void px__sp_elevate(const double *x, int n, int m, int dir, double *y)
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
void px__sp_d_rows(const double *x, int R, int C, double *out)
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
void px__sp_d_cols(const double *x, int R, int C, double *out)
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

/* Value of a tensor at (s, t) from its Bernstein basis values. */
double px__sp_eval(const double *c, int n, int m, double s, double t)
{
	double bs[3 * MD + 2], bt[3 * MD + 2], acc = 0.0;
	int i, j, k;

	bs[0] = 1.0;
	for (k = 1; k <= n; k++)
		px__sp_raise(bs, k, s, 1.0 - s);
	bt[0] = 1.0;
	for (k = 1; k <= m; k++)
		px__sp_raise(bt, k, t, 1.0 - t);
	for (i = 0; i <= n; i++) {
		double row = 0.0;
		for (j = 0; j <= m; j++)
			row += c[i * (m + 1) + j] * bt[j];
		acc += row * bs[i];
	}
	return acc;
}
