/*
 * px_nurbs_surf.c - NURBS tensor-product surfaces: construction,
 * evaluation with partial derivatives up to third order (quotient rule
 * on the homogeneous surface), closed/collapsed boundary detection, knot
 * insertion, sub-patch extraction.
 */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "nurbs_internal.h"
#include "px_nurbs.h"

size_t px_nurbs_surf_bytes(int degree_u, int degree_v, int n_u, int n_v)
{
	size_t a, b, c;
	if (degree_u < 0 || degree_v < 0 || n_u < 0 || n_v < 0)
		return 0;
	if (n_v && (size_t)n_u > SIZE_MAX / 8 / (size_t)n_v)
		return 0;
	a = px__nurbs_padded((size_t)n_u + (size_t)degree_u + 1);
	b = px__nurbs_padded((size_t)n_v + (size_t)degree_v + 1);
	c = px__nurbs_padded(4 * (size_t)n_u * (size_t)n_v);
	if (!a || !b || !c)
		return 0;
	return a + b + c;
}

static int check_surf(int pu, int pv, int nu, int nv, const double *ku,
		      int nku, const double *kv, int nkv, const double *xyz,
		      const double *w, const double *pw,
		      struct px_nurbs_error *err)
{
	int rc;

	px__nurbs_ok(err);
	rc = px__nurbs_check_knots(pu, nu, ku, nku, 0, err);
	if (!rc)
		rc = px__nurbs_check_knots(pv, nv, kv, nkv, 1, err);
	if (!rc && (size_t)nu * (size_t)nv > (size_t)INT32_MAX / 4) {
		px__nurbs_err(err, PX_E_OVERFLOW, PX_NURBS_FAULT_ARG, 0, -1, nu,
			      nv, "control net %d x %d too large", nu, nv);
		rc = PX_E_OVERFLOW;
	}
	if (!rc)
		rc = px__nurbs_check_points(nu * nv, nu, xyz, w, pw, err);
	return rc;
}

int px_nurbs_surf_validate(int degree_u, int degree_v, int n_u, int n_v,
			   const double *knots_u, int n_knots_u,
			   const double *knots_v, int n_knots_v,
			   const double *xyz, const double *w,
			   struct px_nurbs_error *err)
{
	return check_surf(degree_u, degree_v, n_u, n_v, knots_u, n_knots_u,
			  knots_v, n_knots_v, xyz, w, NULL, err);
}

static void fill(struct px_nurbs_surf *s, int pu, int pv, int nu, int nv,
		 const double *ku, const double *kv, const double *pw)
{
	s->degree[0] = pu;
	s->degree[1] = pv;
	s->n_ctrl[0] = nu;
	s->n_ctrl[1] = nv;
	s->n_knots[0] = nu + pu + 1;
	s->n_knots[1] = nv + pv + 1;
	s->knots[0] = ku;
	s->knots[1] = kv;
	s->pw = pw;
	s->rational = !px__nurbs_unit_weights(pw, (size_t)nu * (size_t)nv);
}

int px_nurbs_surf_init(struct px_nurbs_surf *s, struct px_arena *a,
		       int degree_u, int degree_v, int n_u, int n_v,
		       const double *knots_u, int n_knots_u,
		       const double *knots_v, int n_knots_v,
		       const double *xyz, const double *w,
		       struct px_nurbs_error *err)
{
	double *ku, *kv, *P;
	size_t count;
	int rc;

	rc = px__nurbs_start(err, s, sizeof(*s), !s || !a || !xyz,
			     "NULL surface, arena or control points");
	if (!rc)
		rc = check_surf(degree_u, degree_v, n_u, n_v, knots_u, n_knots_u,
				knots_v, n_knots_v, xyz, w, NULL, err);
	if (rc)
		return rc;
	count = (size_t)n_u * (size_t)n_v;
	ku = px_arena_alloc(a, (size_t)n_knots_u * sizeof(double), 0);
	kv = px_arena_alloc(a, (size_t)n_knots_v * sizeof(double), 0);
	P = px_arena_alloc(a, 4 * count * sizeof(double), 0);
	if (!ku || !kv || !P) {
		px__nurbs_err(err, PX_E_NOSPC, PX_NURBS_FAULT_NOSPC, 0, -1, 0,
			      0, "arena too small for the surface (%zu bytes)",
			      px_nurbs_surf_bytes(degree_u, degree_v, n_u,
						  n_v));
		return PX_E_NOSPC;
	}
	memcpy(ku, knots_u, (size_t)n_knots_u * sizeof(double));
	memcpy(kv, knots_v, (size_t)n_knots_v * sizeof(double));
	px__nurbs_homogeneous(P, xyz, w, count);
	fill(s, degree_u, degree_v, n_u, n_v, ku, kv, P);
	return PX_OK;
}

int px_nurbs_surf_view(struct px_nurbs_surf *s, int degree_u, int degree_v,
		       int n_u, int n_v, const double *knots_u, int n_knots_u,
		       const double *knots_v, int n_knots_v, const double *pw,
		       struct px_nurbs_error *err)
{
	int rc;

	rc = px__nurbs_start(err, s, sizeof(*s), !s || !pw,
			     "NULL surface or control points");
	if (!rc)
		rc = check_surf(degree_u, degree_v, n_u, n_v, knots_u, n_knots_u,
				knots_v, n_knots_v, NULL, NULL, pw, err);
	if (rc)
		return rc;
	fill(s, degree_u, degree_v, n_u, n_v, knots_u, knots_v, pw);
	return PX_OK;
}

void px_nurbs_surf_domain(const struct px_nurbs_surf *s, double *u0,
			  double *u1, double *v0, double *v1)
{
	if (u0)
		*u0 = s->knots[0][s->degree[0]];
	if (u1)
		*u1 = s->knots[0][s->n_ctrl[0]];
	if (v0)
		*v0 = s->knots[1][s->degree[1]];
	if (v1)
		*v1 = s->knots[1][s->n_ctrl[1]];
}

int px_nurbs_surf_find_span(const struct px_nurbs_surf *s, int dir, double t,
			    int side)
{
	if (!s || dir < 0 || dir > 1 || !s->knots[dir])
		return -1;
	if (isnan(t))
		t = s->knots[dir][s->degree[dir]];
	return px__nurbs_span(s->knots[dir], s->degree[dir], s->n_ctrl[dir], t,
			      side);
}

static void surf_eval_core(const struct px_nurbs_surf *s, double u, double v,
			   int su, int sv, int order,
			   px_vec3 S[PX_NURBS_MAX_DERIV + 1]
				    [PX_NURBS_MAX_DERIV + 1])
{
	double Bu[(PX_NURBS_MAX_DERIV + 1) * (PX_NURBS_MAX_DEGREE + 1)];
	double Bv[(PX_NURBS_MAX_DERIV + 1) * (PX_NURBS_MAX_DEGREE + 1)];
	double T[PX_NURBS_MAX_DERIV + 1][PX_NURBS_MAX_DEGREE + 1][4];
	double A[PX_NURBS_MAX_DERIV + 1][PX_NURBS_MAX_DERIV + 1][4];
	const int pu = s->degree[0], pv = s->degree[1];
	const int nu = s->n_ctrl[0], nv = s->n_ctrl[1];
	const double *U = s->knots[0], *V = s->knots[1];
	int ku, kv, du, dv, k, l, r, q, i, j;

	u = px__nurbs_clamp(U, pu, nu, u);
	v = px__nurbs_clamp(V, pv, nv, v);
	ku = px__nurbs_span(U, pu, nu, u, su);
	kv = px__nurbs_span(V, pv, nv, v, sv);
	du = order < pu ? order : pu;
	dv = order < pv ? order : pv;
	px_nurbs_basis_ders(U, pu, ku, u, du, Bu);
	px_nurbs_basis_ders(V, pv, kv, v, dv, Bv);
	/* Rows first: T[k][q] = sum_r dNu^k_r P[kv-pv+q][ku-pu+r]. */
	for (q = 0; q <= pv; q++) {
		const double *row =
			s->pw + 4 * ((size_t)(kv - pv + q) * (size_t)nu +
				     (size_t)(ku - pu));
		for (k = 0; k <= du; k++) {
			const double *b = Bu + k * (pu + 1);
			double t0 = 0, t1 = 0, t2 = 0, t3 = 0;
			const double *P = row;
			for (r = 0; r <= pu; r++, P += 4) {
				t0 += b[r] * P[0];
				t1 += b[r] * P[1];
				t2 += b[r] * P[2];
				t3 += b[r] * P[3];
			}
			T[k][q][0] = t0;
			T[k][q][1] = t1;
			T[k][q][2] = t2;
			T[k][q][3] = t3;
		}
	}
	for (k = 0; k <= order; k++) {
		for (l = 0; k + l <= order; l++) {
			/* local sums: accumulating in A itself stalls on
			 * store-to-load forwarding */
			double a0 = 0, a1 = 0, a2 = 0, a3 = 0;
			if (k <= du && l <= dv) {
				const double *b = Bv + l * (pv + 1);
				for (q = 0; q <= pv; q++) {
					a0 += b[q] * T[k][q][0];
					a1 += b[q] * T[k][q][1];
					a2 += b[q] * T[k][q][2];
					a3 += b[q] * T[k][q][3];
				}
			}
			A[k][l][0] = a0;
			A[k][l][1] = a1;
			A[k][l][2] = a2;
			A[k][l][3] = a3;
		}
	}
	if (!s->rational) {
		for (k = 0; k <= order; k++)
			for (l = 0; k + l <= order; l++)
				S[k][l] = px_v3(A[k][l][0], A[k][l][1],
						A[k][l][2]);
		return;
	}
	/* S^(k,l) = (A^(k,l) - sum_{j=1..l} C(l,j) w^(0,j) S^(k,l-j)
	 *   - sum_{i=1..k} C(k,i) (w^(i,0) S^(k-i,l)
	 *     + sum_{j=1..l} C(l,j) w^(i,j) S^(k-i,l-j))) / w */
	for (k = 0; k <= order; k++) {
		for (l = 0; k + l <= order; l++) {
			px_vec3 x = px_v3(A[k][l][0], A[k][l][1], A[k][l][2]);
			for (j = 1; j <= l; j++)
				x = px_v3_madd(x, S[k][l - j],
					       -px__nurbs_binom(l, j) *
						       A[0][j][3]);
			for (i = 1; i <= k; i++) {
				x = px_v3_madd(x, S[k - i][l],
					       -px__nurbs_binom(k, i) *
						       A[i][0][3]);
				for (j = 1; j <= l; j++)
					x = px_v3_madd(x, S[k - i][l - j],
						       -px__nurbs_binom(k, i) *
							       px__nurbs_binom(l, j) *
							       A[i][j][3]);
			}
			S[k][l] = px_v3_scale(x, 1.0 / A[0][0][3]);
		}
	}
}

int px_nurbs_surf_eval_side(const struct px_nurbs_surf *s, double u,
			    double v, int side_u, int side_v, int order,
			    struct px_nurbs_surf_derivs *d)
{
	px_vec3 S[PX_NURBS_MAX_DERIV + 1][PX_NURBS_MAX_DERIV + 1];

	if (!s || !s->pw || !d || order < 0 || order > PX_NURBS_MAX_DERIV)
		return PX_E_INVAL;
	if (isnan(u) || isnan(v))
		return PX_E_NAN;
	surf_eval_core(s, u, v, side_u, side_v, order, S);
	memset(d, 0, sizeof(*d));
	d->s = S[0][0];
	if (order >= 1) {
		d->su = S[1][0];
		d->sv = S[0][1];
	}
	if (order >= 2) {
		d->suu = S[2][0];
		d->suv = S[1][1];
		d->svv = S[0][2];
	}
	if (order >= 3) {
		d->suuu = S[3][0];
		d->suuv = S[2][1];
		d->suvv = S[1][2];
		d->svvv = S[0][3];
	}
	return PX_OK;
}

int px_nurbs_surf_eval(const struct px_nurbs_surf *s, double u, double v,
		       int order, struct px_nurbs_surf_derivs *d)
{
	return px_nurbs_surf_eval_side(s, u, v, 1, 1, order, d);
}

px_vec3 px_nurbs_surf_point(const struct px_nurbs_surf *s, double u,
			    double v)
{
	px_vec3 S[PX_NURBS_MAX_DERIV + 1][PX_NURBS_MAX_DERIV + 1];
	if (isnan(u))
		u = s->knots[0][s->degree[0]];
	if (isnan(v))
		v = s->knots[1][s->degree[1]];
	surf_eval_core(s, u, v, 1, 1, 0, S);
	return S[0][0];
}

px_aabb px_nurbs_surf_aabb(const struct px_nurbs_surf *s)
{
	px_aabb b = px__nurbs_box_empty();
	size_t i, n = (size_t)s->n_ctrl[0] * (size_t)s->n_ctrl[1];
	for (i = 0; i < n; i++)
		px__nurbs_box_add(&b, s->pw + 4 * i);
	return b;
}

px_vec3 px_nurbs_surf_ctrl(const struct px_nurbs_surf *s, int i, int j,
			   double *w)
{
	const double *P =
		s->pw + 4 * ((size_t)j * (size_t)s->n_ctrl[0] + (size_t)i);
	if (w)
		*w = P[3];
	return px_v3(P[0] / P[3], P[1] / P[3], P[2] / P[3]);
}

/* Calls visit(t) at 2p+1 parameters per non-empty span of direction o;
 * stops early when visit returns 0. Returns 0 if stopped. */
static int boundary_test(const struct px_nurbs_surf *s, int dir, int end_a,
			 int end_b, double tol, int collapsed)
{
	const int o = 1 - dir, po = s->degree[o], no = s->n_ctrl[o];
	const double *T = s->knots[o];
	const double *D = s->knots[dir];
	double ta = end_a ? D[s->n_ctrl[dir]] : D[s->degree[dir]];
	double tb = end_b ? D[s->n_ctrl[dir]] : D[s->degree[dir]];
	px_vec3 first = px_v3(0, 0, 0);
	int k, i, have = 0;

	for (k = po; k < no; k++) {
		if (!(T[k] < T[k + 1]))
			continue;
		for (i = 0; i <= 2 * po; i++) {
			double t = T[k] + (T[k + 1] - T[k]) * i / (2.0 * po);
			px_vec3 pa, pb;
			pa = dir == 0 ? px_nurbs_surf_point(s, ta, t)
				      : px_nurbs_surf_point(s, t, ta);
			if (collapsed) {
				if (!have) {
					first = pa;
					have = 1;
				}
				pb = first;
			} else {
				pb = dir == 0 ? px_nurbs_surf_point(s, tb, t)
					      : px_nurbs_surf_point(s, t, tb);
			}
			if (!(px_v3_dist(pa, pb) <= tol))
				return 0;
		}
	}
	return 1;
}

int px_nurbs_surf_iso_curve(const struct px_nurbs_surf *s, int dir, double t,
			    double *pw_out, size_t pw_len,
			    struct px_nurbs_curve *out)
{
	double N[PX_NURBS_MAX_DEGREE + 1];
	int o, po, k, n, i, r, c;
	size_t st_dir, st_o;

	if (!s || !s->pw || !out || dir < 0 || dir > 1)
		return PX_E_INVAL;
	if (isnan(t))
		return PX_E_NAN;
	n = s->n_ctrl[dir];
	if (!pw_out || pw_len < 4 * (size_t)n)
		return PX_E_NOSPC;
	o = 1 - dir;
	po = s->degree[o];
	t = px__nurbs_clamp(s->knots[o], po, s->n_ctrl[o], t);
	k = px__nurbs_span(s->knots[o], po, s->n_ctrl[o], t, 1);
	px_nurbs_basis_ders(s->knots[o], po, k, t, 0, N);
	/* point (a along dir, b along o) is at pw + 4 * (a*st_dir + b*st_o) */
	st_dir = dir == 0 ? 1 : (size_t)s->n_ctrl[0];
	st_o = dir == 0 ? (size_t)s->n_ctrl[0] : 1;
	for (i = 0; i < n; i++) {
		double q[4] = {0, 0, 0, 0};
		for (r = 0; r <= po; r++) {
			const double *P = s->pw + 4 * ((size_t)i * st_dir +
						       (size_t)(k - po + r) * st_o);
			for (c = 0; c < 4; c++)
				q[c] += N[r] * P[c];
		}
		for (c = 0; c < 4; c++)
			pw_out[4 * (size_t)i + c] = q[c];
	}
	out->degree = s->degree[dir];
	out->n_ctrl = n;
	out->n_knots = s->n_knots[dir];
	out->knots = s->knots[dir];
	out->pw = pw_out;
	out->rational = s->rational;
	return PX_OK;
}

int px_nurbs_surf_closed(const struct px_nurbs_surf *s, int dir, double tol)
{
	if (!s || dir < 0 || dir > 1)
		return 0;
	return boundary_test(s, dir, 0, 1, tol, 0);
}

int px_nurbs_surf_seam(const struct px_nurbs_surf *s, int dir, double tol,
		       double tol_rel)
{
	px_vec3 A[PX_NURBS_MAX_DERIV + 1][PX_NURBS_MAX_DERIV + 1];
	px_vec3 B[PX_NURBS_MAX_DERIV + 1][PX_NURBS_MAX_DERIV + 1];
	double scale[PX_NURBS_MAX_DERIV + 1] = {0};
	int o, po, no, kmax, best, k, i, j, pass;
	const double *T, *D;
	double t0, t1;

	if (!s || dir < 0 || dir > 1)
		return -1;
	o = 1 - dir;
	po = s->degree[o];
	no = s->n_ctrl[o];
	T = s->knots[o];
	D = s->knots[dir];
	t0 = D[s->degree[dir]];
	t1 = D[s->n_ctrl[dir]];
	kmax = s->degree[dir] - 1;
	if (kmax > PX_NURBS_MAX_DERIV)
		kmax = PX_NURBS_MAX_DERIV;
	best = kmax;
	/* Pass 0 finds the largest derivative of each order along the seam,
	 * pass 1 compares against tol_rel times it: at a pole the
	 * derivatives vanish and their directions are rounding noise. */
	for (pass = 0; pass < 2; pass++) {
		for (k = po; k < no; k++) {
			if (!(T[k] < T[k + 1]))
				continue;
			for (i = 0; i <= 2 * po; i++) {
				double t = T[k] + (T[k + 1] - T[k]) * i / (2.0 * po);
				if (dir == 0) {
					surf_eval_core(s, t0, t, 1, 1, kmax, A);
					surf_eval_core(s, t1, t, -1, 1, kmax, B);
				} else {
					surf_eval_core(s, t, t0, 1, 1, kmax, A);
					surf_eval_core(s, t, t1, 1, -1, kmax, B);
				}
				if (!(px_v3_dist(A[0][0], B[0][0]) <= tol))
					return -1;
				for (j = 1; j <= best; j++) {
					px_vec3 a = dir == 0 ? A[j][0] : A[0][j];
					px_vec3 b = dir == 0 ? B[j][0] : B[0][j];
					if (pass == 0) {
						scale[j] = fmax(scale[j],
								fmax(px_v3_norm(a),
								     px_v3_norm(b)));
					} else if (!(px_v3_dist(a, b) <=
						     tol_rel * scale[j])) {
						best = j - 1;
						break;
					}
				}
			}
		}
	}
	return best;
}

int px_nurbs_surf_edge_collapsed(const struct px_nurbs_surf *s, int edge,
				 double tol)
{
	if (!s || edge < 0 || edge > 3)
		return 0;
	return boundary_test(s, edge / 2, edge & 1, edge & 1, tol, 1);
}

int px_nurbs_surf_breaks(const struct px_nurbs_surf *s, int dir,
			 double *breaks, int cap)
{
	if (!s || dir < 0 || dir > 1)
		return 0;
	return px__nurbs_breaks(s->knots[dir], s->degree[dir], s->n_ctrl[dir],
				breaks, cap);
}

int px_nurbs_surf_insert_knot(const struct px_nurbs_surf *s, int dir,
			      double t, int times, struct px_arena *a,
			      struct px_nurbs_surf *out)
{
	int p, n[2], nk, cnt, i, j;
	double *K[2], *P;
	size_t cap0;

	if (!s || !a || !out || dir < 0 || dir > 1 || times < 0)
		return PX_E_INVAL;
	if (isnan(t))
		return PX_E_NAN;
	p = s->degree[dir];
	if (t < s->knots[dir][p] || t > s->knots[dir][s->n_ctrl[dir]])
		return PX_E_RANGE;
	if (times > 0 &&
	    px__nurbs_mult(s->knots[dir], s->n_knots[dir], t) + times > p)
		return PX_E_RANGE;
	n[0] = s->n_ctrl[0];
	n[1] = s->n_ctrl[1];
	for (i = 0; i < 2; i++) {
		int extra = i == dir ? times : 0;
		K[i] = px_arena_alloc(
			a, (size_t)(s->n_knots[i] + extra) * sizeof(double), 0);
		if (!K[i])
			return PX_E_NOSPC;
		memcpy(K[i], s->knots[i],
		       (size_t)s->n_knots[i] * sizeof(double));
	}
	cap0 = (size_t)n[0] + (dir == 0 ? (size_t)times : 0);
	P = px_arena_alloc(a,
			   4 * cap0 * ((size_t)n[1] + (dir == 1 ? times : 0)) *
				   sizeof(double),
			   0);
	if (!P)
		return PX_E_NOSPC;
	for (j = 0; j < n[1]; j++)
		memcpy(P + 4 * (size_t)j * cap0,
		       s->pw + 4 * (size_t)j * (size_t)n[0],
		       4 * (size_t)n[0] * sizeof(double));
	nk = s->n_knots[dir];
	cnt = n[dir];
	for (i = 0; i < times; i++) {
		if (dir == 0)
			px__nurbs_insert_once(p, K[0], &nk, P, &cnt, n[1], 1,
					      cap0, t);
		else
			px__nurbs_insert_once(p, K[1], &nk, P, &cnt, n[0], cap0,
					      1, t);
	}
	n[dir] = cnt;
	*out = *s;
	out->n_ctrl[0] = n[0];
	out->n_ctrl[1] = n[1];
	out->n_knots[dir] = nk;
	out->knots[0] = K[0];
	out->knots[1] = K[1];
	out->pw = P;
	return PX_OK;
}

int px_nurbs_surf_extract_work(const struct px_nurbs_surf *s, double u0,
			       double u1, double v0, double v1, double *work,
			       size_t work_len, struct px_nurbs_surf *out)
{
	double a[2] = {u0, v0}, b[2] = {u1, v1};
	double *U_out[2], *pw_out;
	const double *U[2];
	int n_out[2], rc, d;

	if (!s || !out || !s->pw)
		return PX_E_INVAL;
	U[0] = s->knots[0];
	U[1] = s->knots[1];
	rc = px__nurbs_extract(2, s->degree, s->n_ctrl, U, s->pw, a, b, work,
			       work_len, n_out, U_out, &pw_out);
	if (rc)
		return rc;
	*out = *s;
	for (d = 0; d < 2; d++) {
		out->n_ctrl[d] = n_out[d];
		out->n_knots[d] = n_out[d] + s->degree[d] + 1;
		out->knots[d] = U_out[d];
	}
	out->pw = pw_out;
	return PX_OK;
}

size_t px_nurbs_surf_extract_bytes(const struct px_nurbs_surf *s)
{
	return px_nurbs_surf_bytes(s->degree[0], s->degree[1],
				   s->n_ctrl[0] + s->degree[0],
				   s->n_ctrl[1] + s->degree[1]) +
	       px__nurbs_padded(PX_NURBS_SURF_WORK_LEN(s->degree[0], s->degree[1],
					     s->n_ctrl[0], s->n_ctrl[1]));
}

int px_nurbs_surf_extract(const struct px_nurbs_surf *s, double u0,
			  double u1, double v0, double v1,
			  struct px_arena *arena, struct px_nurbs_surf *out)
{
	double a[2] = {u0, v0}, b[2] = {u1, v1};
	double *K[2], *P, *work;
	struct px_nurbs_surf tmp;
	size_t len, mark;
	int n[2], d, rc;

	if (!s || !arena || !out)
		return PX_E_INVAL;
	for (d = 0; d < 2; d++) {
		if (isnan(a[d]) || isnan(b[d]))
			return PX_E_NAN;
		if (!(a[d] < b[d]) || a[d] < s->knots[d][s->degree[d]] ||
		    b[d] > s->knots[d][s->n_ctrl[d]])
			return PX_E_RANGE;
		n[d] = px__nurbs_count_inside(s->knots[d], s->n_knots[d], a[d],
					      b[d]) +
		       s->degree[d] + 1;
		K[d] = px_arena_alloc(
			arena,
			(size_t)(n[d] + s->degree[d] + 1) * sizeof(double), 0);
		if (!K[d])
			return PX_E_NOSPC;
	}
	P = px_arena_alloc(arena, 4 * (size_t)n[0] * (size_t)n[1] *
					  sizeof(double),
			   0);
	if (!P)
		return PX_E_NOSPC;
	mark = px_arena_mark(arena);
	len = PX_NURBS_SURF_WORK_LEN(s->degree[0], s->degree[1], s->n_ctrl[0],
				     s->n_ctrl[1]);
	work = px_arena_alloc(arena, len * sizeof(double), 0);
	if (!work)
		return PX_E_NOSPC;
	rc = px_nurbs_surf_extract_work(s, u0, u1, v0, v1, work, len, &tmp);
	if (!rc && (tmp.n_ctrl[0] != n[0] || tmp.n_ctrl[1] != n[1]))
		rc = PX_E_STATE;
	if (!rc) {
		for (d = 0; d < 2; d++) {
			memcpy(K[d], tmp.knots[d],
			       (size_t)tmp.n_knots[d] * sizeof(double));
			tmp.knots[d] = K[d];
		}
		memcpy(P, tmp.pw,
		       4 * (size_t)n[0] * (size_t)n[1] * sizeof(double));
		tmp.pw = P;
		*out = tmp;
	}
	px_arena_reset_to(arena, mark);
	return rc;
}

int px_nurbs_surf_sub_aabb(const struct px_nurbs_surf *s, double u0,
			   double u1, double v0, double v1, double *work,
			   size_t work_len, px_aabb *box)
{
	struct px_nurbs_surf sub;
	int rc;

	if (!box)
		return PX_E_INVAL;
	rc = px_nurbs_surf_extract_work(s, u0, u1, v0, v1, work, work_len,
					&sub);
	if (rc)
		return rc;
	*box = px_nurbs_surf_aabb(&sub);
	return PX_OK;
}
