/*
 * px_nurbs_basis.c - what NURBS curves and surfaces share: knot span
 * search, basis functions with derivatives, validation, single knot
 * insertion on a grid of homogeneous points.
 */
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "nurbs_internal.h"
#include "px_nurbs.h"

void px__nurbs_ok(struct px_nurbs_error *err)
{
	if (!err)
		return;
	memset(err, 0, sizeof(*err));
	err->index = err->index_i = err->index_j = -1;
}

void px__nurbs_err(struct px_nurbs_error *err, int code,
		   enum px_nurbs_fault fault, int dir, int index, double v1,
		   double v2, const char *fmt, ...)
{
	va_list ap;

	if (!err)
		return;
	err->code = code;
	err->fault = fault;
	err->dir = dir;
	err->index = index;
	err->index_i = err->index_j = -1;
	err->value = v1;
	err->value2 = v2;
	va_start(ap, fmt);
	vsnprintf(err->msg, sizeof(err->msg), fmt, ap);
	va_end(ap);
}

int px__nurbs_start(struct px_nurbs_error *err, void *obj, size_t size,
		    int null_arg, const char *msg)
{
	if (obj)
		memset(obj, 0, size);
	if (!null_arg)
		return PX_OK;
	px__nurbs_ok(err);
	px__nurbs_err(err, PX_E_INVAL, PX_NURBS_FAULT_ARG, 0, -1, 0, 0, "%s", msg);
	return PX_E_INVAL;
}

double px__nurbs_clamp(const double *U, int p, int n, double t)
{
	if (t < U[p])
		return U[p];
	if (t > U[n])
		return U[n];
	return t;
}

int px__nurbs_span(const double *U, int p, int n, double u, int side)
{
	int lo = p, hi = n - 1;

	if (!(u > U[p])) {
		u = U[p];
		side = 1;
	} else if (u >= U[n]) {
		u = U[n];
		side = -1;
	}
	if (side >= 0) {
		/* Largest k with U[k] <= u: the span that is non-empty to the
		 * right of u even when u is a repeated knot. */
		while (lo < hi) {
			int mid = lo + (hi - lo + 1) / 2;
			if (U[mid] <= u)
				lo = mid;
			else
				hi = mid - 1;
		}
	} else {
		/* Smallest k with U[k+1] >= u: non-empty to the left. */
		while (lo < hi) {
			int mid = lo + (hi - lo) / 2;
			if (U[mid + 1] >= u)
				hi = mid;
			else
				lo = mid + 1;
		}
	}
	return lo;
}

int px_nurbs_curve_find_span(const struct px_nurbs_curve *c, double u,
			     int side)
{
	if (!c || !c->knots)
		return -1;
	if (isnan(u))
		u = c->knots[c->degree];
	return px__nurbs_span(c->knots, c->degree, c->n_ctrl, u, side);
}

void px_nurbs_basis_ders(const double *U, int p, int k, double u, int nder,
			 double *out)
{
	/* N[q][r]: degree-q function number k-q+r on span k.
	 * inv[q][r] = 1 / (U[k+r+1] - U[k+1-q+r]), r < q: the knot
	 * differences of the degree-q step. On a non-empty span
	 * (U[k] < U[k+1]) every one of them is positive, so no 0/0 guard is
	 * needed, and they are also the denominators of the derivative
	 * recursion, which therefore needs no division at all. */
	double N[PX_NURBS_MAX_DEGREE + 1][PX_NURBS_MAX_DEGREE + 1];
	double inv[PX_NURBS_MAX_DEGREE + 1][PX_NURBS_MAX_DEGREE + 1];
	double left[PX_NURBS_MAX_DEGREE + 1], right[PX_NURBS_MAX_DEGREE + 1];
	double D[2][PX_NURBS_MAX_DEGREE + 1][PX_NURBS_MAX_DEGREE + 1];
	int q, r, kd;

	/* The degree-p rows are written straight into out (a copy loop here
	 * would be turned into a memcpy call, a quarter of the cost). */
	N[0][0] = 1.0;
	if (p == 0)
		out[0] = 1.0;
	for (q = 1; q <= p; q++) {
		double saved = 0.0;
		double *Nq = q == p ? out : N[q];
		left[q] = u - U[k + 1 - q];
		right[q] = U[k + q] - u;
		for (r = 0; r < q; r++) {
			double iv = 1.0 / (right[r + 1] + left[q - r]);
			double t = N[q - 1][r] * iv;
			inv[q][r] = iv;
			Nq[r] = saved + right[r + 1] * t;
			saved = left[q - r] * t;
		}
		Nq[q] = saved;
	}
	if (nder <= 0)
		return;
	if (nder > p) {
		for (kd = p + 1; kd <= nder; kd++)
			for (r = 0; r <= p; r++)
				out[kd * (p + 1) + r] = 0.0;
		nder = p;
	}
	/* d/du N_{j,q} = q (N_{j,q-1} / (U[j+q]-U[j])
	 *                   - N_{j+1,q-1} / (U[j+q+1]-U[j+1])),
	 * applied order by order on the lower-degree tables; with
	 * j = k-q+r both differences are inv[q][r-1] and inv[q][r]. Rows of
	 * degree < p are all the next order needs. */
	{
		const double(*E)[PX_NURBS_MAX_DEGREE + 1] = N;
		for (kd = 1; kd <= nder; kd++) {
			double(*C)[PX_NURBS_MAX_DEGREE + 1] = D[kd & 1];
			int qmin = p - nder + kd;
			for (q = qmin; q <= p; q++) {
				double *Cq = q == p ? out + kd * (p + 1) : C[q];
				double prev = 0.0;
				for (r = 0; r < q; r++) {
					double t = E[q - 1][r] * inv[q][r];
					Cq[r] = q * (prev - t);
					prev = t;
				}
				Cq[q] = q * prev;
			}
			E = (const double(*)[PX_NURBS_MAX_DEGREE + 1])C;
		}
	}
}

int px__nurbs_check_knots(int p, int n, const double *U, int n_knots,
			  int dir, struct px_nurbs_error *err)
{
	const char *what = dir < 0 ? "knot" : (dir == 0 ? "u knot" : "v knot");
	int d = dir < 0 ? 0 : dir;
	int i;

	if (p < 1 || p > PX_NURBS_MAX_DEGREE) {
		px__nurbs_err(err, PX_E_RANGE, PX_NURBS_FAULT_DEGREE, d, -1, p,
			      PX_NURBS_MAX_DEGREE,
			      "%sdegree %d outside 1..%d", dir == 1 ? "v " :
			      (dir == 0 ? "u " : ""), p, PX_NURBS_MAX_DEGREE);
		return PX_E_RANGE;
	}
	if (n < p + 1) {
		px__nurbs_err(err, PX_E_INVAL, PX_NURBS_FAULT_TOO_FEW, d, -1, n,
			      p + 1,
			      "%d control points%s, degree %d needs at least %d",
			      n, dir == 1 ? " along v" : (dir == 0 ? " along u"
							: ""), p, p + 1);
		return PX_E_INVAL;
	}
	if (!U) {
		px__nurbs_err(err, PX_E_INVAL, PX_NURBS_FAULT_ARG, d, -1, 0, 0,
			      "no %ss", what);
		return PX_E_INVAL;
	}
	if (n_knots != n + p + 1) {
		px__nurbs_err(err, PX_E_INVAL, PX_NURBS_FAULT_KNOT_COUNT, d, -1,
			      n_knots, n + p + 1,
			      "%d %ss, %d control points of degree %d need %d",
			      n_knots, what, n, p, n + p + 1);
		return PX_E_INVAL;
	}
	for (i = 0; i < n_knots; i++) {
		if (!isfinite(U[i])) {
			px__nurbs_err(err, PX_E_NAN, PX_NURBS_FAULT_KNOT_NAN, d,
				      i, U[i], 0, "%s %d is not finite (%g)",
				      what, i, U[i]);
			return PX_E_NAN;
		}
		if (i > 0 && U[i] < U[i - 1]) {
			px__nurbs_err(err, PX_E_INVAL, PX_NURBS_FAULT_KNOT_ORDER,
				      d, i, U[i], U[i - 1],
				      "%s %d decreases (%.17g < %.17g)", what,
				      i, U[i], U[i - 1]);
			return PX_E_INVAL;
		}
	}
	if (!(U[p] < U[n])) {
		px__nurbs_err(err, PX_E_DEGENERATE, PX_NURBS_FAULT_DOMAIN, d, p,
			      U[p], U[n],
			      "empty parameter domain: %s %d = %s %d = %.17g",
			      what, p, what, n, U[p]);
		return PX_E_DEGENERATE;
	}
	for (i = 0; i < n_knots;) {
		int j = i;
		while (j + 1 < n_knots && U[j + 1] == U[i])
			j++;
		int m = j - i + 1;
		if (m > p + 1) {
			px__nurbs_err(err, PX_E_INVAL, PX_NURBS_FAULT_KNOT_MULT,
				      d, i, U[i], m,
				      "%s %d (%.17g) has multiplicity %d > "
				      "degree+1 = %d",
				      what, i, U[i], m, p + 1);
			return PX_E_INVAL;
		}
		if (m > p && U[i] > U[p] && U[i] < U[n]) {
			px__nurbs_err(err, PX_E_INVAL, PX_NURBS_FAULT_KNOT_MULT,
				      d, i, U[i], m,
				      "interior %s %d (%.17g) has multiplicity "
				      "%d > degree %d (entity would break "
				      "apart; split it)",
				      what, i, U[i], m, p);
			return PX_E_INVAL;
		}
		i = j + 1;
	}
	return PX_OK;
}

int px__nurbs_check_points(int count, int n_u, const double *xyz,
			   const double *w, const double *pw,
			   struct px_nurbs_error *err)
{
	int i, i_lo = 0, i_hi = 0;
	double w_lo = INFINITY, w_hi = 0.0;

	if (!xyz && !pw) {
		px__nurbs_err(err, PX_E_INVAL, PX_NURBS_FAULT_ARG, 0, -1, 0, 0,
			      "no control points");
		return PX_E_INVAL;
	}
	for (i = 0; i < count; i++) {
		double x, y, z, wi;
		int rc = 0;
		if (xyz) {
			x = xyz[3 * i];
			y = xyz[3 * i + 1];
			z = xyz[3 * i + 2];
			wi = w ? w[i] : 1.0;
		} else {
			wi = pw[4 * i + 3];
			x = pw[4 * i] / wi;
			y = pw[4 * i + 1] / wi;
			z = pw[4 * i + 2] / wi;
		}
		if (!isfinite(wi) || !(wi > 0.0)) {
			px__nurbs_err(err, PX_E_RANGE, PX_NURBS_FAULT_WEIGHT, 0,
				      i, wi, 0,
				      "control point %d has weight %g (must be "
				      "finite and > 0)",
				      i, wi);
			rc = PX_E_RANGE;
		} else if (!isfinite(x) || !isfinite(y) || !isfinite(z)) {
			px__nurbs_err(err, PX_E_NAN, PX_NURBS_FAULT_COORD_NAN, 0,
				      i, isfinite(x) ? (isfinite(y) ? z : y) : x,
				      0,
				      "control point %d has a non-finite "
				      "coordinate (%g, %g, %g)",
				      i, x, y, z);
			rc = PX_E_NAN;
		} else if (wi < PX_NURBS_MIN_WEIGHT || wi > PX_NURBS_MAX_WEIGHT) {
			px__nurbs_err(err, PX_E_RANGE, PX_NURBS_FAULT_COORD_RANGE, 0,
				      i, wi, 0,
				      "control point %d has weight %g (outside %g .. %g: "
				      "the rational sums would overflow or vanish)",
				      i, wi, PX_NURBS_MIN_WEIGHT, PX_NURBS_MAX_WEIGHT);
			rc = PX_E_RANGE;
		} else if (fabs(x) > PX_NURBS_MAX_COORD || fabs(y) > PX_NURBS_MAX_COORD ||
			   fabs(z) > PX_NURBS_MAX_COORD) {
			double v = fabs(x) > PX_NURBS_MAX_COORD ? x
				   : fabs(y) > PX_NURBS_MAX_COORD ? y : z;
			px__nurbs_err(err, PX_E_RANGE, PX_NURBS_FAULT_COORD_RANGE, 0,
				      i, v, 0,
				      "control point %d has coordinate %g beyond +-%g "
				      "(squared distances would overflow)",
				      i, v, PX_NURBS_MAX_COORD);
			rc = PX_E_RANGE;
		}
		if (rc) {
			if (err && n_u > 0) {
				err->index_i = i % n_u;
				err->index_j = i / n_u;
			}
			return rc;
		}
		if (wi < w_lo) {
			w_lo = wi;
			i_lo = i;
		}
		if (wi > w_hi) {
			w_hi = wi;
			i_hi = i;
		}
	}
	/* Weights further apart than this pull the curve so hard towards a
	 * control point that the distance search's bounds stop holding: a
	 * cubic with weights 1e7 and 1e-7 answered up to 0.3 % too far. */
	if (w_hi > PX_NURBS_MAX_WEIGHT_RATIO * w_lo) {
		px__nurbs_err(err, PX_E_RANGE, PX_NURBS_FAULT_WEIGHT, 0, i_hi, w_hi,
			      w_lo,
			      "control point %d has weight %g, more than %g times "
			      "the weight %g of control point %d",
			      i_hi, w_hi, PX_NURBS_MAX_WEIGHT_RATIO, w_lo, i_lo);
		if (err && n_u > 0) {
			err->index_i = i_hi % n_u;
			err->index_j = i_hi / n_u;
		}
		return PX_E_RANGE;
	}
	return PX_OK;
}

int px__nurbs_mult(const double *U, int n_knots, double u)
{
	int i, m = 0;
	for (i = 0; i < n_knots; i++)
		m += U[i] == u;
	return m;
}

int px__nurbs_count_inside(const double *U, int n_knots, double a, double b)
{
	int i, m = 0;
	for (i = 0; i < n_knots; i++)
		m += U[i] > a && U[i] < b;
	return m;
}

void px__nurbs_insert_once(int p, double *U, int *nk, double *P, int *cnt,
			   int other, size_t s_along, size_t s_across,
			   double u)
{
	int n = *cnt;
	int k = px__nurbs_span(U, p, n, u, 1);
	int i, b, c;

	/* Boehm: Q_i = a_i P_i + (1 - a_i) P_{i-1} for k-p < i <= k,
	 * a_i = (u - U_i) / (U_{i+p} - U_i); points after k move up one.
	 * Descending order keeps the originals that are still needed. */
	for (b = 0; b < other; b++) {
		double *L = P + 4 * (size_t)b * s_across;
		for (i = n; i >= k + 1; i--)
			for (c = 0; c < 4; c++)
				L[4 * (size_t)i * s_along + c] =
					L[4 * (size_t)(i - 1) * s_along + c];
		for (i = k; i >= k - p + 1; i--) {
			double a = (u - U[i]) / (U[i + p] - U[i]);
			double *qi = L + 4 * (size_t)i * s_along;
			const double *pm = L + 4 * (size_t)(i - 1) * s_along;
			for (c = 0; c < 4; c++)
				qi[c] = a * qi[c] + (1.0 - a) * pm[c];
		}
	}
	for (i = *nk; i >= k + 2; i--)
		U[i] = U[i - 1];
	U[k + 1] = u;
	(*nk)++;
	(*cnt)++;
}

/* Box helpers kept local: the distance core must not depend on the
 * out-of-line px_aabb functions for its hot paths. */
px_aabb px__nurbs_box_empty(void)
{
	px_aabb b;
	b.min = px_v3(INFINITY, INFINITY, INFINITY);
	b.max = px_v3(-INFINITY, -INFINITY, -INFINITY);
	return b;
}

void px__nurbs_box_add(px_aabb *box, const double *pw)
{
	double w = pw[3];
	px_vec3 p = px_v3(pw[0] / w, pw[1] / w, pw[2] / w);
	box->min = px_v3_min(box->min, p);
	box->max = px_v3_max(box->max, p);
}

/* Last index of the run of value a in W[0..nw-1] (a present). */
static int last_index(const double *W, int nw, double a)
{
	int i = nw - 1;
	while (i > 0 && W[i] != a)
		i--;
	return i;
}

static int first_index(const double *W, int nw, double b)
{
	int i = 0;
	while (i < nw - 1 && W[i] != b)
		i++;
	return i;
}

int px__nurbs_extract(int nd, const int *p, const int *n,
		      const double *const *U, const double *pw,
		      const double *a, const double *b, double *work,
		      size_t work_len, int *n_out, double **U_out,
		      double **pw_out)
{
	size_t cap[2] = {1, 1}, need, off;
	int lo[2] = {0, 0}, cnt[2] = {1, 1}, nk[2] = {0, 0};
	int first[2] = {0, 0}, d, i, j, r;
	double *K[2] = {NULL, NULL};

	for (d = 0; d < nd; d++)
		cap[d] = (size_t)n[d] + 2 * (size_t)p[d];
	need = 4 * cap[0] * cap[1];
	for (d = 0; d < nd; d++)
		need += (size_t)n[d] + 3 * (size_t)p[d] + 1;
	if (!work || work_len < need)
		return PX_E_NOSPC;
	off = 4 * cap[0] * cap[1];
	for (d = 0; d < nd; d++) {
		int ka, kb;
		if (isnan(a[d]) || isnan(b[d]))
			return PX_E_NAN;
		if (!(a[d] < b[d]) || a[d] < U[d][p[d]] || b[d] > U[d][n[d]])
			return PX_E_RANGE;
		/* Only the spans that meet [a, b] matter: copy that window
		 * (a valid B-spline whose domain contains [a, b]). */
		ka = px__nurbs_span(U[d], p[d], n[d], a[d], 1);
		kb = px__nurbs_span(U[d], p[d], n[d], b[d], -1);
		lo[d] = ka - p[d];
		cnt[d] = kb - ka + p[d] + 1;
		nk[d] = cnt[d] + p[d] + 1;
		K[d] = work + off;
		off += (size_t)n[d] + 3 * (size_t)p[d] + 1;
		memcpy(K[d], U[d] + lo[d], (size_t)nk[d] * sizeof(double));
	}
	for (j = 0; j < cnt[1]; j++)
		memcpy(work + 4 * (size_t)j * cap[0],
		       pw + 4 * ((size_t)(lo[1] + j) * (size_t)n[0] +
				 (size_t)lo[0]),
		       4 * (size_t)cnt[0] * sizeof(double));
	for (d = 0; d < nd; d++) {
		size_t s_along = d == 0 ? 1 : cap[0];
		size_t s_across = d == 0 ? cap[0] : 1;
		double e[2] = {a[d], b[d]};
		int t;
		for (t = 0; t < 2; t++) {
			int m = px__nurbs_mult(K[d], nk[d], e[t]);
			for (r = m; r < p[d]; r++)
				px__nurbs_insert_once(p[d], K[d], &nk[d], work,
						      &cnt[d], cnt[1 - d],
						      s_along, s_across, e[t]);
		}
	}
	for (d = 0; d < nd; d++) {
		/* a now has multiplicity >= p: the curve starts at control
		 * point L-p (L its last index) and ends at F-1 (F the first
		 * index of b). */
		int L = last_index(K[d], nk[d], a[d]);
		int F = first_index(K[d], nk[d], b[d]);
		int m = F - L + p[d], t = 0;
		first[d] = L - p[d];
		for (i = 0; i <= p[d]; i++)
			K[d][t++] = a[d];
		for (i = L + 1; i <= F - 1; i++)
			K[d][t++] = K[d][i];
		for (i = 0; i <= p[d]; i++)
			K[d][t++] = b[d];
		n_out[d] = m;
		U_out[d] = K[d];
	}
	if (nd == 1)
		n_out[1] = 1;
	for (j = 0; j < n_out[1]; j++)
		memmove(work + 4 * (size_t)j * (size_t)n_out[0],
			work + 4 * ((size_t)(j + first[1]) * cap[0] +
				    (size_t)first[0]),
			4 * (size_t)n_out[0] * sizeof(double));
	*pw_out = work;
	return PX_OK;
}

size_t px__nurbs_padded(size_t n_doubles)
{
	if (n_doubles > (SIZE_MAX - PX_ARENA_ALIGN) / sizeof(double))
		return 0;
	return n_doubles * sizeof(double) + PX_ARENA_ALIGN - 1;
}

void px__nurbs_homogeneous(double *P, const double *xyz, const double *w,
			   size_t count)
{
	size_t i;
	for (i = 0; i < count; i++) {
		double wi = w ? w[i] : 1.0;
		P[4 * i] = xyz[3 * i] * wi;
		P[4 * i + 1] = xyz[3 * i + 1] * wi;
		P[4 * i + 2] = xyz[3 * i + 2] * wi;
		P[4 * i + 3] = wi;
	}
}

int px__nurbs_unit_weights(const double *pw, size_t count)
{
	size_t i;
	for (i = 0; i < count; i++)
		if (pw[4 * i + 3] != 1.0)
			return 0;
	return 1;
}
