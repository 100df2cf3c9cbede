#include "px_bern.h"

#include <math.h>
#include <stdint.h>
#include <string.h>

double px_bern_binom(int n, int k)
{
	/* Exact in 64-bit integers: r * (n - i) equals C(n, i + 1) * (i + 1),
	 * so each division is exact, and values stay far below 2^53. No
	 * table, so no shared mutable state between threads. */
	uint64_t r = 1;
	int i;

	if (n < 0 || n > PX_BERN_MAX_DEGREE || k < 0 || k > n)
		return 0.0;
	if (k > n - k)
		k = n - k;
	for (i = 0; i < k; i++)
		r = r * (uint64_t)(n - i) / (uint64_t)(i + 1);
	return (double)r;
}

void px_bern_scale(const double *c, int n, double *out)
{
	double b = 1.0;
	int i;
	/* C(n, i + 1) = C(n, i) (n - i) / (i + 1): an exact integer
	 * division for n <= 32. */
	for (i = 0; i <= n; i++) {
		out[i] = c[i] * b;
		b = b * (n - i) / (i + 1);
	}
}

/*
 * Horner-like evaluation in O(n) (Schumaker and Volk) on coefficients
 * already multiplied by their binomials: for t <= 1/2,
 * B(t) = (1 - t)^n sum cb_i (t / (1 - t))^i, mirrored for t > 1/2 so the
 * ratio stays at most 1. Accurate to a few ulps of max |c_i| times n,
 * which is what root finding needs; px_bern_split() keeps de Casteljau
 * for subdivision, where stability over many levels matters.
 */
double px_bern_eval_scaled(const double *cb, int n, double t)
{
	double s, acc, scale = 1.0, base;
	int i;

	if (n == 0)
		return cb[0];
	if (t <= 0.5) {
		base = 1.0 - t;
		s = t / base;
		acc = cb[n];
		for (i = n - 1; i >= 0; i--)
			acc = acc * s + cb[i];
	} else {
		base = t;
		s = (1.0 - t) / t;
		acc = cb[0];
		for (i = 1; i <= n; i++)
			acc = acc * s + cb[i];
	}
	for (i = 0; i < n; i++)
		scale *= base;
	return acc * scale;
}

double px_bern_eval(const double *c, int n, double t)
{
	double cb[PX_BERN_MAX_DEGREE + 1];
	px_bern_scale(c, n, cb);
	return px_bern_eval_scaled(cb, n, t);
}

double px_bern_eval_d(const double *c, int n, double t, double *dt)
{
	double d[PX_BERN_MAX_DEGREE + 1];
	int i;

	if (dt) {
		if (n == 0) {
			*dt = 0.0;
		} else {
			for (i = 0; i < n; i++)
				d[i] = n * (c[i + 1] - c[i]);
			*dt = px_bern_eval(d, n - 1, t);
		}
	}
	return px_bern_eval(c, n, t);
}

void px_bern_split(const double *c, int n, double t, double *left,
		   double *right)
{
	double w[PX_BERN_MAX_DEGREE + 1];
	double l[PX_BERN_MAX_DEGREE + 1];
	double s = 1.0 - t;
	int i, k;

	memcpy(w, c, (size_t)(n + 1) * sizeof(double));
	l[0] = w[0];
	for (k = n; k > 0; k--) {
		for (i = 0; i < k; i++)
			w[i] = s * w[i] + t * w[i + 1];
		l[n - k + 1] = w[0];
	}
	/* w now holds the right piece's coefficients. */
	if (left)
		memcpy(left, l, (size_t)(n + 1) * sizeof(double));
	if (right)
		memcpy(right, w, (size_t)(n + 1) * sizeof(double));
}

void px_bern_restrict(const double *c, int n, double a, double b, double *out)
{
	double tmp[PX_BERN_MAX_DEGREE + 1];

	if (b < 1.0) {
		px_bern_split(c, n, b, tmp, NULL);
		a = a / b;
	} else {
		memcpy(tmp, c, (size_t)(n + 1) * sizeof(double));
	}
	if (a > 0.0)
		px_bern_split(tmp, n, a, NULL, tmp);
	memcpy(out, tmp, (size_t)(n + 1) * sizeof(double));
}

void px_bern_deriv(const double *c, int n, double *out)
{
	int i;
	if (n == 0) {
		out[0] = 0.0;
		return;
	}
	for (i = 0; i < n; i++)
		out[i] = n * (c[i + 1] - c[i]);
}

int px_bern_mul(const double *a, int na, const double *b, int nb, double *out)
{
	int n = na + nb, i, j;

	if (na < 0 || nb < 0 || n > PX_BERN_MAX_DEGREE)
		return PX_E_RANGE;
	for (i = 0; i <= n; i++)
		out[i] = 0.0;
	for (i = 0; i <= na; i++) {
		double ai = a[i] * px_bern_binom(na, i);
		for (j = 0; j <= nb; j++)
			out[i + j] += ai * b[j] * px_bern_binom(nb, j);
	}
	for (i = 0; i <= n; i++)
		out[i] /= px_bern_binom(n, i);
	return PX_OK;
}

void px_bern_elevate(const double *c, int n, double *out)
{
	int i;
	out[0] = c[0];
	out[n + 1] = c[n];
	for (i = 1; i <= n; i++) {
		double a = (double)i / (n + 1);
		out[i] = a * c[i - 1] + (1.0 - a) * c[i];
	}
}

int px_bern_sign_changes(const double *c, int n, double zero_tol)
{
	int i, changes = 0, last = 0;
	for (i = 0; i <= n; i++) {
		int s = c[i] > zero_tol ? 1 : (c[i] < -zero_tol ? -1 : 0);
		if (s == 0)
			continue;
		if (last && s != last)
			changes++;
		last = s;
	}
	return changes;
}
