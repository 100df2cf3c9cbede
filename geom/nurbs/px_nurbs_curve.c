/*
 * px_nurbs_curve.c - NURBS curves: construction, evaluation with
 * derivatives (quotient rule on the homogeneous curve), seams and
 * breaks, knot insertion, sub-curve extraction.
 */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "nurbs_internal.h"
#include "px_nurbs.h"

size_t px_nurbs_curve_bytes(int degree, int n_ctrl)
{
	size_t a, b;
	if (degree < 0 || n_ctrl < 0)
		return 0;
	a = px__nurbs_padded((size_t)n_ctrl + (size_t)degree + 1);
	b = px__nurbs_padded(4 * (size_t)n_ctrl);
	if (!a || !b)
		return 0;
	return a + b;
}

int px_nurbs_curve_validate(int degree, int n_ctrl, const double *knots,
			    int n_knots, const double *xyz, const double *w,
			    struct px_nurbs_error *err)
{
	int rc;

	px__nurbs_ok(err);
	rc = px__nurbs_check_knots(degree, n_ctrl, knots, n_knots, -1, err);
	if (rc)
		return rc;
	return px__nurbs_check_points(n_ctrl, 0, xyz, w, NULL, err);
}

/* The curve's fields over its (validated) knots U and points pw. */
static void fill(struct px_nurbs_curve *c, int degree, int n_ctrl,
		 const double *U, int n_knots, const double *pw)
{
	c->degree = degree;
	c->n_ctrl = n_ctrl;
	c->n_knots = n_knots;
	c->knots = U;
	c->pw = pw;
	c->rational = !px__nurbs_unit_weights(pw, (size_t)n_ctrl);
}

int px_nurbs_curve_init(struct px_nurbs_curve *c, struct px_arena *a,
			int degree, int n_ctrl, const double *knots,
			int n_knots, const double *xyz, const double *w,
			struct px_nurbs_error *err)
{
	double *U, *P;
	int rc;

	rc = px__nurbs_start(err, c, sizeof(*c), !c || !a || !xyz,
			     "NULL curve, arena or control points");
	if (!rc)
		rc = px_nurbs_curve_validate(degree, n_ctrl, knots, n_knots, xyz,
					     w, err);
	if (rc)
		return rc;
	U = px_arena_alloc(a, (size_t)n_knots * sizeof(double), 0);
	P = px_arena_alloc(a, 4 * (size_t)n_ctrl * sizeof(double), 0);
	if (!U || !P) {
		px__nurbs_err(err, PX_E_NOSPC, PX_NURBS_FAULT_NOSPC, 0, -1, 0,
			      0, "arena too small for the curve (%zu bytes)",
			      px_nurbs_curve_bytes(degree, n_ctrl));
		return PX_E_NOSPC;
	}
	memcpy(U, knots, (size_t)n_knots * sizeof(double));
	px__nurbs_homogeneous(P, xyz, w, (size_t)n_ctrl);
	fill(c, degree, n_ctrl, U, n_knots, P);
	return PX_OK;
}

int px_nurbs_curve_view(struct px_nurbs_curve *c, int degree, int n_ctrl,
			const double *knots, int n_knots, const double *pw,
			struct px_nurbs_error *err)
{
	int rc;

	px__nurbs_ok(err);
	rc = px__nurbs_start(err, c, sizeof(*c), !c || !pw,
			     "NULL curve or control points");
	if (!rc)
		rc = px__nurbs_check_knots(degree, n_ctrl, knots, n_knots, -1, err);
	if (!rc)
		rc = px__nurbs_check_points(n_ctrl, 0, NULL, NULL, pw, err);
	if (rc)
		return rc;
	fill(c, degree, n_ctrl, knots, n_knots, pw);
	return PX_OK;
}

void px_nurbs_curve_domain(const struct px_nurbs_curve *c, double *u0,
			   double *u1)
{
	if (u0)
		*u0 = c->knots[c->degree];
	if (u1)
		*u1 = c->knots[c->n_ctrl];
}

static void curve_eval_core(const struct px_nurbs_curve *c, double u,
			    int side, int nder, px_vec3 *ders)
{
	double B[(PX_NURBS_MAX_DERIV + 1) * (PX_NURBS_MAX_DEGREE + 1)];
	double A[PX_NURBS_MAX_DERIV + 1][4];
	const int p = c->degree;
	const double *U = c->knots;
	int k, nd, kd, r, i;

	u = px__nurbs_clamp(U, p, c->n_ctrl, u);
	k = px__nurbs_span(U, p, c->n_ctrl, u, side);
	nd = nder < p ? nder : p; /* higher derivatives of the pieces vanish */
	px_nurbs_basis_ders(U, p, k, u, nd, B);
	for (kd = 0; kd <= nder; kd++) {
		double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
		if (kd <= nd) {
			const double *b = B + kd * (p + 1);
			const double *P = c->pw + 4 * (size_t)(k - p);
			for (r = 0; r <= p; r++, P += 4) {
				s0 += b[r] * P[0];
				s1 += b[r] * P[1];
				s2 += b[r] * P[2];
				s3 += b[r] * P[3];
			}
		}
		A[kd][0] = s0;
		A[kd][1] = s1;
		A[kd][2] = s2;
		A[kd][3] = s3;
	}
	if (!c->rational) {
		for (kd = 0; kd <= nder; kd++)
			ders[kd] = px_v3(A[kd][0], A[kd][1], A[kd][2]);
		return;
	}
	/* C^(k) = (A^(k) - sum_{i=1..k} binom(k,i) w^(i) C^(k-i)) / w */
	for (kd = 0; kd <= nder; kd++) {
		px_vec3 v = px_v3(A[kd][0], A[kd][1], A[kd][2]);
		for (i = 1; i <= kd; i++)
			v = px_v3_madd(v, ders[kd - i],
				       -px__nurbs_binom(kd, i) * A[i][3]);
		ders[kd] = px_v3_scale(v, 1.0 / A[0][3]);
	}
}

int px_nurbs_curve_eval_side(const struct px_nurbs_curve *c, double u,
			     int side, int nder, px_vec3 *ders)
{
	if (!c || !c->knots || !c->pw || !ders || nder < 0 ||
	    nder > PX_NURBS_MAX_DERIV)
		return PX_E_INVAL;
	if (isnan(u))
		return PX_E_NAN;
	curve_eval_core(c, u, side, nder, ders);
	return PX_OK;
}

int px_nurbs_curve_eval(const struct px_nurbs_curve *c, double u, int nder,
			px_vec3 *ders)
{
	return px_nurbs_curve_eval_side(c, u, 1, nder, ders);
}

px_vec3 px_nurbs_curve_point(const struct px_nurbs_curve *c, double u)
{
	px_vec3 p;
	if (isnan(u))
		u = c->knots[c->degree];
	curve_eval_core(c, u, 1, 0, &p);
	return p;
}

px_aabb px_nurbs_curve_aabb(const struct px_nurbs_curve *c)
{
	px_aabb b = px__nurbs_box_empty();
	int i;
	for (i = 0; i < c->n_ctrl; i++)
		px__nurbs_box_add(&b, c->pw + 4 * i);
	return b;
}

px_vec3 px_nurbs_curve_ctrl(const struct px_nurbs_curve *c, int i, double *w)
{
	const double *P = c->pw + 4 * (size_t)i;
	if (w)
		*w = P[3];
	return px_v3(P[0] / P[3], P[1] / P[3], P[2] / P[3]);
}

int px_nurbs_curve_seam(const struct px_nurbs_curve *c, double tol,
			double tol_rel)
{
	px_vec3 s[PX_NURBS_MAX_DERIV + 1], e[PX_NURBS_MAX_DERIV + 1];
	double u0, u1;
	int kmax = c->degree - 1, k;

	if (kmax > PX_NURBS_MAX_DERIV)
		kmax = PX_NURBS_MAX_DERIV;
	px_nurbs_curve_domain(c, &u0, &u1);
	curve_eval_core(c, u0, 1, kmax, s);
	curve_eval_core(c, u1, -1, kmax, e);
	if (!(px_v3_dist(s[0], e[0]) <= tol))
		return -1;
	for (k = 1; k <= kmax; k++) {
		double m = fmax(fmax(px_v3_norm(s[k]), px_v3_norm(e[k])),
				1e-300);
		if (!(px_v3_dist(s[k], e[k]) <= tol_rel * m))
			return k - 1;
	}
	return kmax;
}

/* Interior knot values of multiplicity >= p (shared with surfaces). */
int px__nurbs_breaks(const double *U, int p, int n, double *out, int cap)
{
	int i = p + 1, count = 0;
	while (i < n) {
		int j = i;
		while (j + 1 < n && U[j + 1] == U[i])
			j++;
		if (U[i] > U[p] && U[i] < U[n] && j - i + 1 >= p) {
			if (out && count < cap)
				out[count] = U[i];
			count++;
		}
		i = j + 1;
	}
	return count;
}

int px_nurbs_curve_breaks(const struct px_nurbs_curve *c, double *breaks,
			  int cap)
{
	return px__nurbs_breaks(c->knots, c->degree, c->n_ctrl, breaks, cap);
}

int px_nurbs_curve_insert_knot(const struct px_nurbs_curve *c, double u,
			       int times, struct px_arena *a,
			       struct px_nurbs_curve *out)
{
	const int p = c ? c->degree : 0;
	double *U, *P;
	int nk, cnt, t, s;

	if (!c || !a || !out || times < 0)
		return PX_E_INVAL;
	if (isnan(u))
		return PX_E_NAN;
	if (u < c->knots[p] || u > c->knots[c->n_ctrl])
		return PX_E_RANGE;
	s = px__nurbs_mult(c->knots, c->n_knots, u);
	if (times > 0 && s + times > p)
		return PX_E_RANGE;
	U = px_arena_alloc(a, (size_t)(c->n_knots + times) * sizeof(double),
			   0);
	P = px_arena_alloc(a, 4 * (size_t)(c->n_ctrl + times) * sizeof(double),
			   0);
	if (!U || !P)
		return PX_E_NOSPC;
	memcpy(U, c->knots, (size_t)c->n_knots * sizeof(double));
	memcpy(P, c->pw, 4 * (size_t)c->n_ctrl * sizeof(double));
	nk = c->n_knots;
	cnt = c->n_ctrl;
	for (t = 0; t < times; t++)
		px__nurbs_insert_once(p, U, &nk, P, &cnt, 1, 1, 1, u);
	*out = *c;
	out->n_ctrl = cnt;
	out->n_knots = nk;
	out->knots = U;
	out->pw = P;
	return PX_OK;
}

int px_nurbs_curve_extract_work(const struct px_nurbs_curve *c, double a,
				double b, double *work, size_t work_len,
				struct px_nurbs_curve *out)
{
	int n_out[2];
	double *U_out[2], *pw_out;
	const double *U[1];
	int rc;

	if (!c || !out || !c->knots)
		return PX_E_INVAL;
	U[0] = c->knots;
	rc = px__nurbs_extract(1, &c->degree, &c->n_ctrl, U, c->pw, &a, &b,
			       work, work_len, n_out, U_out, &pw_out);
	if (rc)
		return rc;
	out->degree = c->degree;
	out->n_ctrl = n_out[0];
	out->n_knots = n_out[0] + c->degree + 1;
	out->knots = U_out[0];
	out->pw = pw_out;
	out->rational = c->rational;
	return PX_OK;
}

size_t px_nurbs_curve_extract_bytes(const struct px_nurbs_curve *c)
{
	return px_nurbs_curve_bytes(c->degree, c->n_ctrl + c->degree) +
	       px__nurbs_padded(PX_NURBS_CURVE_WORK_LEN(c->degree, c->n_ctrl));
}

int px_nurbs_curve_extract(const struct px_nurbs_curve *c, double a,
			   double b, struct px_arena *arena,
			   struct px_nurbs_curve *out)
{
	size_t len, mark;
	double *U, *P, *work;
	struct px_nurbs_curve tmp;
	int n, rc;

	if (!c || !arena || !out)
		return PX_E_INVAL;
	if (isnan(a) || isnan(b))
		return PX_E_NAN;
	if (!(a < b) || a < c->knots[c->degree] || b > c->knots[c->n_ctrl])
		return PX_E_RANGE;
	/* Result first, so that the scratch above it can be given back. */
	n = px__nurbs_count_inside(c->knots, c->n_knots, a, b) + c->degree + 1;
	U = px_arena_alloc(arena, (size_t)(n + c->degree + 1) * sizeof(double),
			   0);
	P = px_arena_alloc(arena, 4 * (size_t)n * sizeof(double), 0);
	if (!U || !P)
		return PX_E_NOSPC;
	mark = px_arena_mark(arena);
	len = PX_NURBS_CURVE_WORK_LEN(c->degree, c->n_ctrl);
	work = px_arena_alloc(arena, len * sizeof(double), 0);
	if (!work)
		return PX_E_NOSPC;
	rc = px_nurbs_curve_extract_work(c, a, b, work, len, &tmp);
	if (!rc && tmp.n_ctrl != n)
		rc = PX_E_STATE; /* cannot happen: counts are exact */
	if (!rc) {
		memcpy(U, tmp.knots, (size_t)tmp.n_knots * sizeof(double));
		memcpy(P, tmp.pw, 4 * (size_t)n * sizeof(double));
		*out = tmp;
		out->knots = U;
		out->pw = P;
	}
	px_arena_reset_to(arena, mark);
	return rc;
}

int px_nurbs_curve_sub_aabb(const struct px_nurbs_curve *c, double a,
			    double b, double *work, size_t work_len,
			    px_aabb *box)
{
	struct px_nurbs_curve sub;
	int rc;

	if (!box)
		return PX_E_INVAL;
	rc = px_nurbs_curve_extract_work(c, a, b, work, work_len, &sub);
	if (rc)
		return rc;
	*box = px_nurbs_curve_aabb(&sub);
	return PX_OK;
}
