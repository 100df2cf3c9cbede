/*
 * px_recog.c - recognition of exact primitives among NURBS entities and
 * closed-form closest points on the recognised pieces (see px_recog.h for
 * what is proved).
 */
#include <float.h>
#include <math.h>
#include <string.h>

#include "px_bern.h"
#include "px_nurbs.h"
#include "px_recog.h"

#define TWO_PI 6.283185307179586476925286766559
#define PI_ 3.1415926535897932384626433832795

/* Work for extracting one Bezier span of the largest curve examined. */
#define CWORK PX_NURBS_CURVE_WORK_LEN(PX_NURBS_MAX_DEGREE, PX_RECOG_MAX_CTRL)
/* Depth bound of the half-plane subdivision of a span (sweep count). */
#define SWEEP_DEPTH 10

enum { INV_CURVE, INV_REV_ANG, INV_REV_PROF, INV_QUAD_X, INV_QUAD_Y };

/* What a curve recogniser proves: kind SEGMENT or ARC, the piece, and
 * the Hausdorff bound hd. */
struct crec {
	int kind;
	struct px_recog_seg seg;
	struct px_recog_arc arc;
	double hd;
	int linear;
	struct px_recog_qarc qa;
};

static px_vec3 hpt(const double *pw)
{
	return px_v3(pw[0] / pw[3], pw[1] / pw[3], pw[2] / pw[3]);
}

static px_vec3 unit_or_zero(px_vec3 a)
{
	double n = px_v3_norm(a);
	return n > 0 ? px_v3_scale(a, 1.0 / n) : px_v3(0, 0, 0);
}

static double box_diag(px_aabb b)
{
	return px_v3_dist(b.min, b.max);
}

static void box_add(px_aabb *b, px_vec3 p)
{
	b->min = px_v3_min(b->min, p);
	b->max = px_v3_max(b->max, p);
}

static px_aabb box_empty(void)
{
	px_aabb b;
	b.min = px_v3(INFINITY, INFINITY, INFINITY);
	b.max = px_v3(-INFINITY, -INFINITY, -INFINITY);
	return b;
}

/* Largest absolute Cartesian coordinate of n homogeneous points: the
 * scale of rounding errors. */
static double coord_scale(const double *pw, int n)
{
	double m = 0;
	int i, k;
	for (i = 0; i < n; i++)
		for (k = 0; k < 3; k++) {
			double a = fabs(pw[4 * i + k] / pw[4 * i + 3]);
			if (a > m)
				m = a;
		}
	return m;
}

/* Control values monotone (non-strict), either way: +1 rising, -1
 * falling, 0 neither (constant counts as rising). */
static int monotone(const double *x, int n, size_t stride)
{
	int up = 1, down = 1, i;
	for (i = 1; i < n; i++) {
		if (x[i * stride] < x[(i - 1) * stride])
			up = 0;
		if (x[i * stride] > x[(i - 1) * stride])
			down = 0;
	}
	return up ? 1 : (down ? -1 : 0);
}

/* Values x_i (stride apart) an affine function of the Greville abscissae
 * of (U, p) with x(u0) = xa, x(u1) = xb, within 1e-13 of |xb - xa|: with
 * equal weights the B-spline function is then that affine function
 * (linear precision), so parameters invert in closed form. */
static int greville_affine(const double *x, size_t stride, int n,
			   const double *U, int p, double u0, double u1,
			   double xa, double xb)
{
	int i, k;
	double span = fabs(xb - xa);
	for (i = 0; i < n; i++) {
		double g = 0;
		for (k = 1; k <= p; k++)
			g += U[i + k];
		g /= p;
		if (fabs(x[i * stride] - (xa + (xb - xa) * (g - u0) / (u1 - u0))) >
		    1e-13 * span)
			return 0;
	}
	return 1;
}

/* ---- curves -------------------------------------------------------------- */

static int rec_line(const struct px_nurbs_curve *c, double tol, double margin,
		    struct crec *r)
{
	double u0, u1, L, dev = 0, t[PX_RECOG_MAX_CTRL];
	px_vec3 A, B, d;
	int i, eq_w = 1;

	px_nurbs_curve_domain(c, &u0, &u1);
	A = px_nurbs_curve_point(c, u0);
	B = px_nurbs_curve_point(c, u1);
	L = px_v3_dist(A, B);
	if (!(L > 0) || L <= tol)
		return 0;
	d = px_v3_scale(px_v3_sub(B, A), 1.0 / L);
	for (i = 0; i < c->n_ctrl; i++) {
		px_vec3 w = px_v3_sub(hpt(c->pw + 4 * i), A);
		double off;
		t[i] = px_v3_dot(w, d);
		off = px_v3_norm(px_v3_madd(w, d, -t[i]));
		if (off > dev)
			dev = off;
		if (c->pw[4 * i + 3] != c->pw[3])
			eq_w = 0;
	}
	if (dev + margin > tol)
		return 0;
	/* Monotone control values => monotone projection (variation
	 * diminishing, weights > 0), so the image is exactly [A, B]. */
	if (monotone(t, c->n_ctrl, 1) != 1)
		return 0;
	memset(r, 0, sizeof(*r));
	r->kind = PX_RECOG_SEGMENT;
	r->seg.p0 = A;
	r->seg.dir = d;
	r->seg.len = L;
	r->hd = dev + margin;
	r->linear = eq_w &&
		    greville_affine(t, 1, c->n_ctrl, c->knots, c->degree, u0, u1,
				    0.0, L);
	return 1;
}

/* Extract [a, b] (inside one span) as a Bezier piece. */
static int bezier_piece(const struct px_nurbs_curve *c, double a, double b,
			double *work, struct px_nurbs_curve *bz)
{
	if (px_nurbs_curve_extract_work(c, a, b, work, CWORK, bz) != PX_OK)
		return 0;
	return bz->n_ctrl == c->degree + 1;
}

/* Signed turn about n of the piece [a, b] of the curve, proved to be
 * below pi in magnitude by an open half-plane through the centre that
 * holds the piece's control points; subdivides when needed. Adds to
 * *sweep; returns 0 when the proof fails within the depth bound. */
static int sweep_piece(const struct px_nurbs_curve *c, double a, double b,
		       const struct px_recog_arc *ar, int depth, double *work,
		       double *sweep)
{
	struct px_nurbs_curve bz;
	px_vec3 pa, pb, m;
	int i, ok = 1;

	if (!bezier_piece(c, a, b, work, &bz))
		return 0;
	pa = px_v3_sub(hpt(bz.pw), ar->center);
	pb = px_v3_sub(hpt(bz.pw + 4 * c->degree), ar->center);
	m = px_v3_sub(px_nurbs_curve_point(c, 0.5 * (a + b)), ar->center);
	m = unit_or_zero(px_v3_madd(m, ar->normal, -px_v3_dot(m, ar->normal)));
	for (i = 0; i <= c->degree && ok; i++) {
		px_vec3 q = px_v3_sub(hpt(bz.pw + 4 * i), ar->center);
		if (!(px_v3_dot(m, q) > 1e-9 * ar->radius))
			ok = 0;
	}
	if (ok) {
		double turn = atan2(px_v3_dot(ar->normal, px_v3_cross(pa, pb)),
				    px_v3_dot(pa, pb));
		/* The angle is proved non-decreasing: a negative turn is
		 * rounding of a zero turn only. */
		if (turn < -1e-12)
			return 0;
		*sweep += turn > 0 ? turn : 0;
		return 1;
	}
	if (depth >= SWEEP_DEPTH)
		return 0;
	return sweep_piece(c, a, 0.5 * (a + b), ar, depth + 1, work, sweep) &&
	       sweep_piece(c, 0.5 * (a + b), b, ar, depth + 1, work, sweep);
}

/* Angle -> parameter table of a degree-2 arc (struct px_recog_qarc);
 * q->n = 0 when the curve is not quadratic, has too many spans, or a
 * span's weights disagree with its turn (then parameters are solved). */
static void qarc_table(const struct px_nurbs_curve *c,
		       const struct px_recog_arc *ar, double *work,
		       struct px_recog_qarc *q)
{
	int k, n = 0;
	double acc = 0;
	q->n = 0;
	if (c->degree != 2)
		return;
	for (k = 2; k < c->n_ctrl; k++) {
		struct px_nurbs_curve bz;
		double w0, w1, w2, wn, turn, half;
		px_vec3 pa, pb;
		if (!(c->knots[k] < c->knots[k + 1]))
			continue;
		if (n >= PX_RECOG_QSPANS || !bezier_piece(c, c->knots[k],
							 c->knots[k + 1], work, &bz))
			return;
		w0 = bz.pw[3], w1 = bz.pw[7], w2 = bz.pw[11];
		wn = w1 / sqrt(w0 * w2);
		if (!(wn > 0 && wn < 1))
			return;
		half = acos(wn);
		pa = px_v3_sub(hpt(bz.pw), ar->center);
		pb = px_v3_sub(hpt(bz.pw + 8), ar->center);
		turn = atan2(px_v3_dot(ar->normal, px_v3_cross(pa, pb)),
			     px_v3_dot(pa, pb));
		if (!(fabs(turn - 2 * half) <= 1e-9))
			return;
		q->u[n] = c->knots[k];
		q->a[n] = acc;
		q->lam[n] = sqrt(w0 / w2);
		q->half[n] = half;
		q->mid[n][0] = cos(acc + half);
		q->mid[n][1] = sin(acc + half);
		q->chalf[n] = wn;
		q->tquart[n] = tan(0.5 * half);
		acc += turn;
		n++;
		q->u[n] = c->knots[k + 1];
	}
	q->a[n] = acc;
	if (n > 0 && fabs(acc - ar->sweep) <= 1e-9)
		q->n = n;
}

/* struct px_recog_arc's trig of a sweep. */
static void sweep_trig(double sweep, double t[5])
{
	t[0] = cos(0.5 * sweep);
	t[1] = sin(0.5 * sweep);
	t[2] = sweep >= TWO_PI ? -2.0 : t[0];
	t[3] = cos(sweep);
	t[4] = sin(sweep);
}

static int rec_arc(const struct px_nurbs_curve *c, double tol, double margin,
		   struct crec *r)
{
	double u0, u1, rad, dz = 0, eF = 0, sweep = 0;
	px_vec3 A, M1, M2, a, b, axb, cen, n, e0, e1;
	double work[CWORK];
	int p = c->degree, k, i, orient = 0;
	struct px_recog_arc ar;

	if (2 * p > PX_BERN_MAX_DEGREE)
		return 0;
	px_nurbs_curve_domain(c, &u0, &u1);
	A = px_nurbs_curve_point(c, u0);
	M1 = px_nurbs_curve_point(c, u0 + (u1 - u0) / 3.0);
	M2 = px_nurbs_curve_point(c, u0 + 2.0 * (u1 - u0) / 3.0);
	a = px_v3_sub(M1, A);
	b = px_v3_sub(M2, A);
	axb = px_v3_cross(a, b);
	if (!(px_v3_norm(axb) > 1e-9 * px_v3_norm(a) * px_v3_norm(b)))
		return 0;
	/* Circumcentre of the three points. */
	cen = px_v3_add(
		A, px_v3_scale(
			   px_v3_add(px_v3_scale(px_v3_cross(b, axb), px_v3_norm2(a)),
				     px_v3_scale(px_v3_cross(axb, a), px_v3_norm2(b))),
			   0.5 / px_v3_norm2(axb)));
	n = unit_or_zero(axb);
	rad = px_v3_dist(A, cen);
	if (!(rad > tol))
		return 0;
	for (i = 0; i < c->n_ctrl; i++) {
		double z = fabs(px_v3_dot(n, px_v3_sub(hpt(c->pw + 4 * i), cen)));
		if (z > dz)
			dz = z;
	}
	if (2 * dz + margin > tol)
		return 0;
	e0 = unit_or_zero(px_v3_madd(px_v3_sub(A, cen), n,
				     -px_v3_dot(n, px_v3_sub(A, cen))));
	e1 = px_v3_cross(n, e0);

	/* Per Bezier span: radial residual and sign of the angular speed. */
	for (k = p; k < c->n_ctrl; k++) {
		double y[3][PX_NURBS_MAX_DEGREE + 1], ya[3][PX_NURBS_MAX_DEGREE + 1];
		double W[PX_NURBS_MAX_DEGREE + 1], d1[PX_NURBS_MAX_DEGREE + 1],
			d2[PX_NURBS_MAX_DEGREE + 1];
		double F[PX_BERN_MAX_DEGREE + 1], Fa[PX_BERN_MAX_DEGREE + 1],
			WW[PX_BERN_MAX_DEGREE + 1],
			tmp[PX_BERN_MAX_DEGREE + 1], g[PX_BERN_MAX_DEGREE + 1];
		double fmax = 0;
		struct px_nurbs_curve bz;
		int j, m, pos = 0, neg = 0;

		if (!(c->knots[k] < c->knots[k + 1]))
			continue;
		if (!bezier_piece(c, c->knots[k], c->knots[k + 1], work, &bz))
			return 0;
		for (i = 0; i <= p; i++) {
			const double *q = bz.pw + 4 * i;
			px_vec3 Y = px_v3_madd(px_v3(q[0], q[1], q[2]), cen, -q[3]);
			y[0][i] = px_v3_dot(e0, Y);
			y[1][i] = px_v3_dot(e1, Y);
			y[2][i] = px_v3_dot(n, Y);
			for (j = 0; j < 3; j++)
				ya[j][i] = fabs(y[j][i]);
			W[i] = q[3];
		}
		/* F = |Y|^2 - r^2 W^2 (degree 2p); Fa bounds its rounding. */
		px_bern_mul(W, p, W, p, WW);
		for (m = 0; m <= 2 * p; m++)
			Fa[m] = rad * rad * WW[m], F[m] = -Fa[m];
		for (j = 0; j < 3; j++) {
			px_bern_mul(y[j], p, y[j], p, tmp);
			for (m = 0; m <= 2 * p; m++)
				F[m] += tmp[m];
			px_bern_mul(ya[j], p, ya[j], p, tmp);
			for (m = 0; m <= 2 * p; m++)
				Fa[m] += tmp[m];
		}
		/* |F| <= sum |F_m| B_m <= max_m (|F_m| / WW_m) W^2, WW the
		 * (positive) coefficients of W^2: so |F| / W^2 is bounded
		 * coefficient by coefficient, which stays tight when the
		 * weights vary widely. */
		for (m = 0; m <= 2 * p; m++) {
			double e = (fabs(F[m]) + 16.0 * (2 * p + 4) * DBL_EPSILON * Fa[m]) /
				   WW[m];
			if (e > fmax)
				fmax = e;
		}
		if (fmax > eF)
			eF = fmax;
		/* g = y1 y2' - y2 y1' (degree 2p - 1): the angle's speed
		 * times W^2 rho^2. One sign on every span => monotone. */
		if (p >= 1) {
			px_bern_deriv(y[0], p, d1);
			px_bern_deriv(y[1], p, d2);
			px_bern_mul(y[0], p, d2, p - 1, g);
			px_bern_mul(y[1], p, d1, p - 1, tmp);
			for (m = 0; m <= 2 * p - 1; m++) {
				double v = g[m] - tmp[m];
				if (v > 0)
					pos = 1;
				else if (v < 0)
					neg = 1;
				else
					pos = neg = 1; /* exact zero: refuse */
			}
		}
		if (pos == neg)
			return 0;
		if (orient == 0)
			orient = pos ? 1 : -1;
		else if (orient != (pos ? 1 : -1))
			return 0;
	}
	if (orient == 0)
		return 0;
	if (orient < 0) {
		n = px_v3_neg(n);
		e1 = px_v3_cross(n, e0);
	}
	r->hd = eF / rad + 2 * dz + margin;
	if (!(r->hd <= tol))
		return 0;

	ar.center = cen;
	ar.normal = n;
	ar.e0 = e0;
	ar.e1 = e1;
	ar.radius = rad;
	ar.sweep = 0;
	for (k = p; k < c->n_ctrl; k++) {
		if (!(c->knots[k] < c->knots[k + 1]))
			continue;
		if (!sweep_piece(c, c->knots[k], c->knots[k + 1], &ar, 0, work,
				 &sweep))
			return 0;
	}
	/* More than one turn is refused; a full turn is clamped to 2 pi. */
	if (!(sweep > 0) || sweep > TWO_PI + 1e-9)
		return 0;
	ar.sweep = sweep > TWO_PI ? TWO_PI : sweep;
	sweep_trig(ar.sweep, ar.trig);
	r->kind = PX_RECOG_ARC;
	r->arc = ar;
	r->linear = 0;
	qarc_table(c, &ar, work, &r->qa);
	return 1;
}

static double curve_size(const struct px_nurbs_curve *c)
{
	double u0, u1;
	px_aabb b = box_empty();
	int i;
	px_nurbs_curve_domain(c, &u0, &u1);
	for (i = 0; i <= 64; i++)
		box_add(&b, px_nurbs_curve_point(c, u0 + (u1 - u0) * i / 64.0));
	return box_diag(b);
}

static int rec_curve_any(const struct px_nurbs_curve *c, double tol,
			 double margin, struct crec *r)
{
	if (c->n_ctrl > PX_RECOG_MAX_CTRL)
		return 0;
	if (rec_line(c, tol, margin, r))
		return 1;
	return rec_arc(c, tol, margin, r);
}

static void prim_clear(struct px_recog_shape *out)
{
	memset(out, 0, sizeof(*out));
	out->kind = PX_RECOG_NONE;
}

int px_recog_curve(const struct px_nurbs_curve *c, double rel_tol,
		   struct px_recog_shape *out)
{
	struct crec r;
	double size, tol, margin;

	if (!c || !out || !c->pw || !c->knots)
		return PX_E_INVAL;
	prim_clear(out);
	if (rel_tol <= 0 || !(rel_tol < 1))
		rel_tol = PX_RECOG_REL_TOL_DEFAULT;
	if (c->n_ctrl > PX_RECOG_MAX_CTRL)
		return 0;
	size = curve_size(c);
	if (!(size > 0) || !isfinite(size))
		return 0;
	tol = rel_tol * size;
	margin = 64 * DBL_EPSILON * (coord_scale(c->pw, c->n_ctrl) + size);
	if (!rec_curve_any(c, tol, margin, &r))
		return 0;
	out->kind = (enum px_recog_kind)r.kind;
	out->is_surface = 0;
	out->hausdorff = r.hd;
	out->size = size;
	out->seg = r.seg;
	out->arc = r.arc;
	out->linear = r.linear;
	if (r.kind == PX_RECOG_ARC)
		out->qarc[0] = r.qa;
	if (r.kind == PX_RECOG_ARC) {
		out->center = r.arc.center;
		out->normal = r.arc.normal;
		out->radius = r.arc.radius;
	} else {
		out->center = r.seg.p0;
		out->normal = r.seg.dir;
	}
	out->curve = *c;
	px_nurbs_curve_domain(c, &out->dom[0], &out->dom[1]);
	return 1;
}

/* ---- surfaces ------------------------------------------------------------ */

/* Homogeneous control point (i along direction d, j along the other). */
static const double *net(const struct px_nurbs_surf *s, int d, int i, int j)
{
	int nu = s->n_ctrl[0];
	return d == 0 ? s->pw + 4 * ((size_t)j * nu + i)
		      : s->pw + 4 * ((size_t)i * nu + j);
}

static double surf_size(const struct px_nurbs_surf *s)
{
	double u0, u1, v0, v1;
	px_aabb b = box_empty();
	int i, j;
	px_nurbs_surf_domain(s, &u0, &u1, &v0, &v1);
	for (i = 0; i <= 16; i++)
		for (j = 0; j <= 16; j++)
			box_add(&b, px_nurbs_surf_point(s, u0 + (u1 - u0) * i / 16.0,
							v0 + (v1 - v0) * j / 16.0));
	return box_diag(b);
}

/* Half diagonal of the control net's box: |P - centre| for every
 * control point, the lever of a weight mismatch. */
static double net_radius(const struct px_nurbs_surf *s)
{
	px_aabb b = box_empty();
	int i, n = s->n_ctrl[0] * s->n_ctrl[1];
	for (i = 0; i < n; i++)
		box_add(&b, hpt(s->pw + 4 * i));
	return 0.5 * box_diag(b);
}

/* Weights w_ij = alpha_i beta_j within relative eps (returned; alpha
 * from row j = jref, beta_j averaged). Proof term: replacing the weights
 * moves every surface point by at most 2 eps / (1 - eps) times
 * net_radius() (the convex-combination coefficients change by at most
 * that in sum). */
static double weight_factor(const struct px_nurbs_surf *s, int d, int jref,
			    double *alpha, double *beta)
{
	int na = s->n_ctrl[d], nb = s->n_ctrl[1 - d], i, j;
	double eps = 0;
	for (i = 0; i < na; i++)
		alpha[i] = net(s, d, i, jref)[3];
	for (j = 0; j < nb; j++) {
		double sum = 0;
		for (i = 0; i < na; i++)
			sum += net(s, d, i, j)[3] / alpha[i];
		beta[j] = sum / na;
	}
	for (j = 0; j < nb; j++)
		for (i = 0; i < na; i++) {
			double e = fabs(net(s, d, i, j)[3] / (alpha[i] * beta[j]) - 1);
			if (e > eps)
				eps = e;
		}
	return eps;
}

/* The control row (along d) with the largest extent, viewed as a curve
 * over rowpw: it fixes the axis and the sweep. 0 when it is not an arc. */
static int rev_row(const struct px_nurbs_surf *s, int d, double tol,
		   double margin, double *rowpw, struct px_nurbs_curve *row,
		   struct crec *rr, int *jstar)
{
	int na = s->n_ctrl[d], nb = s->n_ctrl[1 - d], i, j;
	double best = -1;

	*jstar = 0;
	for (j = 0; j < nb; j++) {
		px_aabb b = box_empty();
		for (i = 0; i < na; i++)
			box_add(&b, hpt(net(s, d, i, j)));
		if (box_diag(b) > best)
			best = box_diag(b), *jstar = j;
	}
	for (i = 0; i < na; i++)
		memcpy(rowpw + 4 * i, net(s, d, i, *jstar), 4 * sizeof(double));
	if (px_nurbs_curve_view(row, s->degree[d], na, s->knots[d],
				s->n_knots[d], rowpw, NULL) != PX_OK)
		return 0;
	return rec_arc(row, tol, margin, rr);
}

/*
 * Least-squares h_j, rho_j of P_ij - c = h_j a + rho_j E_i for every
 * row j (E_i: the unit directions of the arc row's points from the axis
 * point c), with the largest rho in *rmax and the largest residual in
 * *dev. 0 when a row is degenerate or crosses the axis.
 */
static int rev_meridian(const struct px_nurbs_surf *s, int d, double tol,
			px_vec3 c, px_vec3 a, const px_vec3 *E, double *h,
			double *rho, double *rmax, double *dev)
{
	int na = s->n_ctrl[d], nb = s->n_ctrl[1 - d], i, j;

	*rmax = 0;
	*dev = 0;
	for (j = 0; j < nb; j++) {
		double s11 = na, s12 = 0, s22 = 0, b1 = 0, b2 = 0, det;
		for (i = 0; i < na; i++) {
			px_vec3 q = px_v3_sub(hpt(net(s, d, i, j)), c);
			s12 += px_v3_dot(a, E[i]);
			s22 += px_v3_norm2(E[i]);
			b1 += px_v3_dot(a, q);
			b2 += px_v3_dot(E[i], q);
		}
		det = s11 * s22 - s12 * s12;
		if (!(det > 1e-12 * s11 * s22))
			return 0;
		h[j] = (s22 * b1 - s12 * b2) / det;
		rho[j] = (s11 * b2 - s12 * b1) / det;
		if (rho[j] < 0) {
			if (rho[j] < -tol)
				return 0; /* crosses the axis */
			rho[j] = 0;
		}
		if (rho[j] > *rmax)
			*rmax = rho[j];
		for (i = 0; i < na; i++) {
			px_vec3 q = px_v3_sub(hpt(net(s, d, i, j)), c);
			double e = px_v3_norm(px_v3_sub(
				q, px_v3_add(px_v3_scale(a, h[j]),
					     px_v3_scale(E[i], rho[j]))));
			if (e > *dev)
				*dev = e;
		}
	}
	return 1;
}

/* Lowest rho of the ideal profile (meridian coordinates (h, rho, 0)):
 * below zero it would leave the half-plane the reduction assumes. */
static double profile_rho_min(const struct crec *pr)
{
	double f, rhomin;
	px_vec3 q0, q1;

	if (pr->kind == PX_RECOG_SEGMENT) {
		q1 = px_v3_madd(pr->seg.p0, pr->seg.dir, pr->seg.len);
		return fmin(pr->seg.p0.y, q1.y);
	}
	/* Direction -rho lies at angle f with cos f = -e0.y, sin f = -e1.y. */
	f = atan2(-pr->arc.e1.y, -pr->arc.e0.y);
	q0 = px_v3_madd(pr->arc.center, pr->arc.e0, pr->arc.radius);
	q1 = px_v3_add(pr->arc.center,
		       px_v3_add(px_v3_scale(pr->arc.e0,
					     pr->arc.radius * cos(pr->arc.sweep)),
				 px_v3_scale(pr->arc.e1,
					     pr->arc.radius * sin(pr->arc.sweep))));
	if (f < 0)
		f += TWO_PI;
	rhomin = fmin(q0.y, q1.y);
	if (f <= pr->arc.sweep)
		rhomin = pr->arc.center.y - pr->arc.radius;
	return rhomin;
}

/* Kind and shape parameters of a surface of revolution about the axis
 * (c, a) from its profile pr. */
static void rev_kind(const struct crec *pr, px_vec3 c, px_vec3 a, double tol,
		     struct px_recog_shape *out)
{
	if (pr->kind == PX_RECOG_SEGMENT) {
		double dh = pr->seg.dir.x, dr = pr->seg.dir.y, L = pr->seg.len;
		if (fabs(dr) * L <= tol) {
			out->kind = PX_RECOG_CYLINDER;
			out->radius = pr->seg.p0.y + 0.5 * dr * L;
			out->center = px_v3_madd(c, a, pr->seg.p0.x);
		} else if (fabs(dh) * L <= tol) {
			out->kind = PX_RECOG_ANNULUS;
			out->center = px_v3_madd(c, a, pr->seg.p0.x);
		} else {
			out->kind = PX_RECOG_CONE;
			out->center = px_v3_madd(c, a,
						 pr->seg.p0.x - pr->seg.p0.y * dh / dr);
			out->half_angle = atan2(fabs(dr), fabs(dh));
		}
	} else {
		out->center = px_v3_madd(c, a, pr->arc.center.x);
		if (fabs(pr->arc.center.y) <= tol) {
			out->kind = PX_RECOG_SPHERE;
			out->radius = pr->arc.radius;
		} else {
			out->kind = PX_RECOG_TORUS;
			out->radius = pr->arc.center.y;
			out->radius2 = pr->arc.radius;
		}
	}
}

/*
 * The shape of a surface of revolution (angle along d): the arc row rr
 * (axis point c, axis a), the profile pr over the curve prof, the row
 * curve row, and the proved bound hd.
 */
static void rev_fill(int d, double hd, double size, double tol,
		     const struct crec *rr, const struct crec *pr,
		     const struct px_nurbs_curve *row,
		     const struct px_nurbs_curve *prof,
		     struct px_recog_shape *out)
{
	px_vec3 c = rr->arc.center, a = rr->arc.normal;
	double v0, v1, bestr = -1, bestv, u0, u1;
	int i;

	prim_clear(out);
	out->is_surface = 1;
	out->hausdorff = hd;
	out->size = size;
	out->rev.origin = c;
	out->rev.axis = a;
	out->rev.e0 = rr->arc.e0;
	out->rev.e1 = rr->arc.e1;
	out->rev.sweep = rr->arc.sweep;
	memcpy(out->rev.trig, rr->arc.trig, sizeof(out->rev.trig));
	out->rev.profile_is_arc = pr->kind == PX_RECOG_ARC;
	out->rev.pseg = pr->seg;
	out->rev.parc = pr->arc;
	out->rev.dir_angle = d;
	out->normal = a;
	out->qarc[0] = rr->qa;
	if (pr->kind == PX_RECOG_ARC)
		out->qarc[1] = pr->qa;
	else if (pr->linear)
		out->linear = 1 << (1 - d);
	/* Fixed parameters for inversion: the angle is read where the
	 * profile is farthest from the axis; the profile at the start of
	 * the angular range. */
	px_nurbs_curve_domain(prof, &v0, &v1);
	bestv = v0;
	for (i = 0; i <= 32; i++) {
		double v = v0 + (v1 - v0) * i / 32.0;
		px_vec3 q = px_nurbs_curve_point(prof, v);
		if (q.y > bestr)
			bestr = q.y, bestv = v;
	}
	px_nurbs_curve_domain(row, &u0, &u1);
	out->rev.ref_param[d] = bestv;
	out->rev.ref_param[1 - d] = u0;
	rev_kind(pr, c, a, tol, out);
}

static int rec_rev(const struct px_nurbs_surf *s, int d, double tol,
		   double margin, double size, struct px_recog_shape *out)
{
	int na = s->n_ctrl[d], nb = s->n_ctrl[1 - d], i, j, jstar;
	double rowpw[4 * PX_RECOG_MAX_CTRL], profpw[4 * PX_RECOG_MAX_CTRL];
	double alpha[PX_RECOG_MAX_CTRL], beta[PX_RECOG_MAX_CTRL];
	double h[PX_RECOG_MAX_CTRL], rho[PX_RECOG_MAX_CTRL];
	px_vec3 E[PX_RECOG_MAX_CTRL];
	double rstar, dev, weps, rmax, hd, wterm;
	struct px_nurbs_curve row, prof;
	struct crec rr, pr;

	if (na > PX_RECOG_MAX_CTRL || nb > PX_RECOG_MAX_CTRL)
		return 0;
	if (!rev_row(s, d, tol, margin, rowpw, &row, &rr, &jstar))
		return 0;
	rstar = rr.arc.radius;
	weps = weight_factor(s, d, jstar, alpha, beta);
	if (!(weps < 0.25))
		return 0;
	for (i = 0; i < na; i++)
		E[i] = px_v3_scale(px_v3_sub(hpt(rowpw + 4 * i), rr.arc.center),
				   1.0 / rstar);
	if (!rev_meridian(s, d, tol, rr.arc.center, rr.arc.normal, E, h, rho,
			  &rmax, &dev))
		return 0;
	wterm = 2 * weps / (1 - weps) * net_radius(s);
	if (dev + wterm > tol)
		return 0;
	/* Profile in meridian coordinates (h, rho, 0) with weights beta. */
	for (j = 0; j < nb; j++) {
		profpw[4 * j + 0] = h[j] * beta[j];
		profpw[4 * j + 1] = rho[j] * beta[j];
		profpw[4 * j + 2] = 0;
		profpw[4 * j + 3] = beta[j];
	}
	if (px_nurbs_curve_view(&prof, s->degree[1 - d], nb, s->knots[1 - d],
				s->n_knots[1 - d], profpw, NULL) != PX_OK)
		return 0;
	if (!rec_curve_any(&prof, tol, margin, &pr))
		return 0;
	/* Tiny dips of the profile below the axis are charged to H. */
	hd = dev + wterm + 2 * pr.hd + rmax * rr.hd / rstar +
	     2 * fmax(0.0, -profile_rho_min(&pr)) + margin;
	if (!(hd <= tol))
		return 0;
	rev_fill(d, hd, size, tol, &rr, &pr, &row, &prof, out);
	return 1;
}

/* 1D rational B-spline function with values x_i (stride apart) and
 * weights wt at the domain ends (exact image of a monotone one). */
static void fn_ends(const double *x, size_t stride, const double *wt, int n,
		    const double *U, int nk, int p, double *e0, double *e1)
{
	double pw[4 * PX_RECOG_MAX_CTRL], a, b;
	struct px_nurbs_curve f;
	int i;
	for (i = 0; i < n; i++) {
		pw[4 * i] = x[i * stride] * wt[i];
		pw[4 * i + 1] = pw[4 * i + 2] = 0;
		pw[4 * i + 3] = wt[i];
	}
	*e0 = *e1 = NAN;
	if (px_nurbs_curve_view(&f, p, n, U, nk, pw, NULL) != PX_OK)
		return;
	px_nurbs_curve_domain(&f, &a, &b);
	*e0 = px_nurbs_curve_point(&f, a).x;
	*e1 = px_nurbs_curve_point(&f, b).x;
}

static int rec_plane(const struct px_nurbs_surf *s, double tol, double margin,
		     double size, struct px_recog_shape *out)
{
	int nu = s->n_ctrl[0], nv = s->n_ctrl[1], i, j, eqa = 1, eqb = 1;
	double u0, u1, v0, v1, dz = 0, dev = 0, weps, wterm;
	double x[PX_RECOG_MAX_CTRL], y[PX_RECOG_MAX_CTRL];
	double alpha[PX_RECOG_MAX_CTRL], beta[PX_RECOG_MAX_CTRL];
	px_vec3 S00, S10, S01, S11, n, A, A0, e1, e2, f1, f2;

	if (nu > PX_RECOG_MAX_CTRL || nv > PX_RECOG_MAX_CTRL)
		return 0;
	px_nurbs_surf_domain(s, &u0, &u1, &v0, &v1);
	S00 = px_nurbs_surf_point(s, u0, v0);
	S10 = px_nurbs_surf_point(s, u1, v0);
	S01 = px_nurbs_surf_point(s, u0, v1);
	S11 = px_nurbs_surf_point(s, u1, v1);
	n = unit_or_zero(px_v3_cross(px_v3_sub(S11, S00), px_v3_sub(S01, S10)));
	if (px_v3_norm2(n) == 0)
		return 0;
	A = px_v3_scale(px_v3_add(px_v3_add(S00, S10), px_v3_add(S01, S11)), 0.25);
	for (i = 0; i < nu * nv; i++) {
		double z = fabs(px_v3_dot(n, px_v3_sub(hpt(s->pw + 4 * i), A)));
		if (z > dz)
			dz = z;
	}
	if (dz + margin > tol)
		return 0;
	prim_clear(out);
	out->kind = PX_RECOG_PLANE;
	out->is_surface = 1;
	out->hausdorff = dz + margin; /* distance to the plane only */
	out->size = size;
	out->center = A;
	out->normal = n;

	/* Parallelogram: P_ij = A0 + x_i e1 + y_j e2, rank-1 weights,
	 * monotone x and y => S = A0 + X(u) e1 + Y(v) e2 with X, Y monotone
	 * rational functions: the image is the parallelogram of their end
	 * values. */
	A0 = hpt(net(s, 0, 0, 0));
	e1 = px_v3_sub(hpt(net(s, 0, nu - 1, 0)), A0);
	e2 = px_v3_sub(hpt(net(s, 0, 0, nv - 1)), A0);
	e1 = unit_or_zero(px_v3_madd(e1, n, -px_v3_dot(e1, n)));
	e2 = unit_or_zero(px_v3_madd(e2, n, -px_v3_dot(e2, n)));
	if (!(px_v3_norm(px_v3_cross(e1, e2)) > 1e-6))
		return 1;
	f1 = px_v3_cross(e2, n);
	f1 = px_v3_scale(f1, 1.0 / px_v3_dot(f1, e1));
	f2 = px_v3_cross(e1, n);
	f2 = px_v3_scale(f2, 1.0 / px_v3_dot(f2, e2));
	for (i = 0; i < nu; i++) {
		double sum = 0;
		for (j = 0; j < nv; j++)
			sum += px_v3_dot(f1, px_v3_sub(hpt(net(s, 0, i, j)), A0));
		x[i] = sum / nv;
	}
	for (j = 0; j < nv; j++) {
		double sum = 0;
		for (i = 0; i < nu; i++)
			sum += px_v3_dot(f2, px_v3_sub(hpt(net(s, 0, i, j)), A0));
		y[j] = sum / nu;
	}
	for (j = 0; j < nv; j++)
		for (i = 0; i < nu; i++) {
			px_vec3 m = px_v3_add(A0, px_v3_add(px_v3_scale(e1, x[i]),
							    px_v3_scale(e2, y[j])));
			double e = px_v3_dist(m, hpt(net(s, 0, i, j)));
			if (e > dev)
				dev = e;
		}
	weps = weight_factor(s, 0, 0, alpha, beta);
	if (!(weps < 0.25))
		return 1;
	wterm = 2 * weps / (1 - weps) * net_radius(s);
	if (dev + wterm + margin > tol || !monotone(x, nu, 1) ||
	    !monotone(y, nv, 1))
		return 1;
	fn_ends(x, 1, alpha, nu, s->knots[0], s->n_knots[0], s->degree[0],
		&out->quad.x0, &out->quad.x1);
	fn_ends(y, 1, beta, nv, s->knots[1], s->n_knots[1], s->degree[1],
		&out->quad.y0, &out->quad.y1);
	if (!(fabs(out->quad.x1 - out->quad.x0) > tol) ||
	    !(fabs(out->quad.y1 - out->quad.y0) > tol))
		return 1;
	/* Equal weights along a direction make X (or Y) polynomial. */
	for (i = 1; i < nu; i++)
		if (alpha[i] != alpha[0] || weps > 0)
			eqa = 0;
	for (j = 1; j < nv; j++)
		if (beta[j] != beta[0] || weps > 0)
			eqb = 0;
	out->kind = PX_RECOG_PARALLELOGRAM;
	out->hausdorff = dev + wterm + margin;
	out->quad.origin = A0;
	out->quad.e1 = e1;
	out->quad.e2 = e2;
	out->quad.f1 = f1;
	out->quad.f2 = f2;
	out->quad.normal = n;
	out->linear = 0;
	if (eqa && eqb) {
		if (greville_affine(x, 1, nu, s->knots[0], s->degree[0], u0, u1,
				    out->quad.x0, out->quad.x1))
			out->linear |= 1;
		if (greville_affine(y, 1, nv, s->knots[1], s->degree[1], v0, v1,
				    out->quad.y0, out->quad.y1))
			out->linear |= 2;
	}
	return 1;
}

int px_recog_surf(const struct px_nurbs_surf *s, double rel_tol,
		  struct px_recog_shape *out)
{
	double size, tol, margin;
	int planar;
	struct px_recog_shape tmp;

	if (!s || !out || !s->pw || !s->knots[0] || !s->knots[1])
		return PX_E_INVAL;
	prim_clear(out);
	if (rel_tol <= 0 || !(rel_tol < 1))
		rel_tol = PX_RECOG_REL_TOL_DEFAULT;
	if (s->n_ctrl[0] > PX_RECOG_MAX_CTRL || s->n_ctrl[1] > PX_RECOG_MAX_CTRL)
		return 0;
	size = surf_size(s);
	if (!(size > 0) || !isfinite(size))
		return 0;
	tol = rel_tol * size;
	margin = 64 * DBL_EPSILON *
		 (coord_scale(s->pw, s->n_ctrl[0] * s->n_ctrl[1]) + size);
	planar = rec_plane(s, tol, margin, size, &tmp);
	if (planar && tmp.kind == PX_RECOG_PARALLELOGRAM)
		goto done;
	if (rec_rev(s, 0, tol, margin, size, out) ||
	    rec_rev(s, 1, tol, margin, size, out))
		goto found;
	if (!planar) {
		prim_clear(out);
		return 0;
	}
done:
	*out = tmp;
found:
	out->surf = *s;
	px_nurbs_surf_domain(s, &out->dom[0], &out->dom[1], &out->dom[2],
			     &out->dom[3]);
	return 1;
}

/* ---- closed-form closest points ------------------------------------------- */

static px_vec3 seg_closest(const struct px_recog_seg *sg, px_vec3 p, double *t)
{
	double s = px_v3_dot(px_v3_sub(p, sg->p0), sg->dir);
	s = s < 0 ? 0 : (s > sg->len ? sg->len : s);
	*t = s;
	return px_v3_madd(sg->p0, sg->dir, s);
}

/* The direction of a closest point on an arc or about an axis: the unit
 * vector (c, s) in the (e0, e1) frame, and end 0 inside the sweep, 1 at
 * its start, 2 at its end (the angle is only computed when a parameter
 * inversion needs it: dir_angle()). */
struct adir {
	double c, s;
	int end;
};

static px_vec3 arc_at(const struct px_recog_arc *ar, double c, double s)
{
	return px_v3_add(ar->center,
			 px_v3_add(px_v3_scale(ar->e0, ar->radius * c),
				   px_v3_scale(ar->e1, ar->radius * s)));
}

/* 1 when the direction (x, y) of length r lies in the sweep of trig
 * (struct px_recog_arc): its angle from the middle is at most half the
 * sweep. */
static int in_sweep(double x, double y, double r, const double *trig)
{
	return x * trig[0] + y * trig[1] >= r * trig[2];
}

/* Angle of (x, y) in [mid - pi, mid + pi). */
static double angle_near(double y, double x, double mid)
{
	double f = atan2(y, x);
	if (f < mid - PI_)
		f += TWO_PI;
	else if (f >= mid + PI_)
		f -= TWO_PI;
	return f;
}

static double dir_angle(const struct adir *d, double sweep)
{
	return d->end == 1 ? 0.0 : d->end == 2 ? sweep : angle_near(d->s, d->c, 0.5 * sweep);
}

static px_vec3 arc_closest(const struct px_recog_arc *ar, px_vec3 p, struct adir *d,
			   int *tie)
{
	px_vec3 w = px_v3_sub(p, ar->center);
	double x = px_v3_dot(ar->e0, w), y = px_v3_dot(ar->e1, w);
	double r = sqrt(x * x + y * y);
	px_vec3 q0, q1;
	double d0, d1;

	/* On the axis every circle point is equally near. */
	if (r <= 1e-12 * ar->radius)
		*tie = 1;
	if (x == 0 && y == 0) {
		d->c = 1, d->s = 0, d->end = 1;
		return arc_at(ar, 1, 0);
	}
	if (in_sweep(x, y, r, ar->trig)) {
		d->c = x / r, d->s = y / r, d->end = 0;
		return arc_at(ar, d->c, d->s);
	}
	/* Outside the arc the distance grows with the angular distance, so
	 * one end point is the answer. */
	q0 = arc_at(ar, 1, 0);
	q1 = arc_at(ar, ar->trig[3], ar->trig[4]);
	d0 = px_v3_dist2(p, q0);
	d1 = px_v3_dist2(p, q1);
	if (fabs(d0 - d1) <= 1e-14 * (d0 + d1))
		*tie = 1;
	if (d0 <= d1) {
		d->c = 1, d->s = 0, d->end = 1;
		return q0;
	}
	d->c = ar->trig[3], d->s = ar->trig[4], d->end = 2;
	return q1;
}

static px_vec3 rev_closest(const struct px_recog_rev *rv, px_vec3 p, struct adir *da,
			   struct adir *dp, double *prof_t, int *tie)
{
	px_vec3 w = px_v3_sub(p, rv->origin), q2, m;
	double hq = px_v3_dot(rv->axis, w), x = px_v3_dot(rv->e0, w),
	       y = px_v3_dot(rv->e1, w), rq = sqrt(x * x + y * y);

	if (rq <= 1e-12 * px_v3_norm(w))
		*tie = 1;
	da->c = 1, da->s = 0, da->end = 1;
	if (rq == 0) {
		q2 = px_v3(hq, 0, 0);
	} else if (in_sweep(x, y, rq, rv->trig)) {
		da->c = x / rq, da->s = y / rq, da->end = 0;
		q2 = px_v3(hq, rq, 0);
	} else {
		/* Nearer end meridian (the same for every profile point since
		 * rho >= 0): the larger projection on the end directions. */
		double b1 = x * rv->trig[3] + y * rv->trig[4];
		if (fabs(x - b1) <= 1e-14 * rq)
			*tie = 1;
		if (x >= b1) {
			q2 = px_v3(hq, x, 0);
		} else {
			da->c = rv->trig[3], da->s = rv->trig[4], da->end = 2;
			q2 = px_v3(hq, b1, 0);
		}
	}
	dp->c = 1, dp->s = 0, dp->end = 1;
	if (rv->profile_is_arc)
		m = arc_closest(&rv->parc, q2, dp, tie);
	else
		m = seg_closest(&rv->pseg, q2, prof_t);
	return px_v3_add(px_v3_madd(rv->origin, rv->axis, m.x),
			 px_v3_scale(px_v3_add(px_v3_scale(rv->e0, da->c),
					       px_v3_scale(rv->e1, da->s)),
				     m.y));
}

static px_vec3 quad_corner(const struct px_recog_quad *q, double x, double y)
{
	return px_v3_add(q->origin,
			 px_v3_add(px_v3_scale(q->e1, x), px_v3_scale(q->e2, y)));
}

static px_vec3 quad_closest(const struct px_recog_quad *q, px_vec3 p, double *xs,
			    double *ys)
{
	px_vec3 w = px_v3_sub(p, q->origin), best = q->origin;
	double s = px_v3_dot(q->f1, w), t = px_v3_dot(q->f2, w);
	double xa = fmin(q->x0, q->x1), xb = fmax(q->x0, q->x1);
	double ya = fmin(q->y0, q->y1), yb = fmax(q->y0, q->y1), bd = INFINITY;
	px_vec3 c[4];
	int k;

	if (s >= xa && s <= xb && t >= ya && t <= yb) {
		*xs = s;
		*ys = t;
		return quad_corner(q, s, t);
	}
	/* Outside a convex polygon the nearest point is on its boundary. */
	c[0] = quad_corner(q, xa, ya);
	c[1] = quad_corner(q, xb, ya);
	c[2] = quad_corner(q, xb, yb);
	c[3] = quad_corner(q, xa, yb);
	for (k = 0; k < 4; k++) {
		struct px_recog_seg sg;
		px_vec3 d = px_v3_sub(c[(k + 1) & 3], c[k]), x;
		double tt;
		sg.p0 = c[k];
		sg.len = px_v3_norm(d);
		sg.dir = px_v3_scale(d, 1.0 / sg.len);
		x = seg_closest(&sg, p, &tt);
		if (px_v3_dist2(p, x) < bd)
			bd = px_v3_dist2(p, x), best = x;
	}
	w = px_v3_sub(best, q->origin);
	*xs = fmin(xb, fmax(xa, px_v3_dot(q->f1, w)));
	*ys = fmin(yb, fmax(ya, px_v3_dot(q->f2, w)));
	return best;
}

/* ---- parameter inversion --------------------------------------------------- */

/* Value (position along the segment, angle, coordinate) of the monotone
 * map being inverted at parameter s, and its derivative. */
static void inv_eval(const struct px_recog_shape *pr, int which, double s, double *f,
		     double *df)
{
	px_vec3 P, D;
	if (which == INV_CURVE) {
		px_vec3 ders[2];
		px_nurbs_curve_eval(&pr->curve, s, 1, ders);
		P = ders[0];
		D = ders[1];
		if (pr->kind == PX_RECOG_SEGMENT) {
			*f = px_v3_dot(pr->seg.dir, px_v3_sub(P, pr->seg.p0));
			*df = px_v3_dot(pr->seg.dir, D);
			return;
		}
		{
			px_vec3 w = px_v3_sub(P, pr->arc.center);
			double x = px_v3_dot(pr->arc.e0, w), y = px_v3_dot(pr->arc.e1, w);
			*f = atan2(y, x);
			*df = (x * px_v3_dot(pr->arc.e1, D) - y * px_v3_dot(pr->arc.e0, D)) /
			      (x * x + y * y);
		}
		return;
	} else {
		struct px_nurbs_surf_derivs sd;
		int dir = which == INV_REV_ANG ? pr->rev.dir_angle
			  : which == INV_REV_PROF ? 1 - pr->rev.dir_angle
			  : which == INV_QUAD_X ? 0
						: 1;
		double other = (which == INV_REV_ANG || which == INV_REV_PROF)
				       ? pr->rev.ref_param[dir]
				       : (dir == 0 ? pr->dom[2] : pr->dom[0]);
		px_nurbs_surf_eval(&pr->surf, dir == 0 ? s : other,
				   dir == 0 ? other : s, 1, &sd);
		P = sd.s;
		D = dir == 0 ? sd.su : sd.sv;
	}
	if (which == INV_QUAD_X || which == INV_QUAD_Y) {
		px_vec3 fv = which == INV_QUAD_X ? pr->quad.f1 : pr->quad.f2;
		*f = px_v3_dot(fv, px_v3_sub(P, pr->quad.origin));
		*df = px_v3_dot(fv, D);
		return;
	}
	{
		const struct px_recog_rev *rv = &pr->rev;
		px_vec3 w = px_v3_sub(P, rv->origin);
		if (which == INV_REV_ANG) {
			double x = px_v3_dot(rv->e0, w), y = px_v3_dot(rv->e1, w);
			*f = atan2(y, x);
			*df = (x * px_v3_dot(rv->e1, D) - y * px_v3_dot(rv->e0, D)) /
			      (x * x + y * y);
		} else {
			double hh = px_v3_dot(rv->axis, w), dh = px_v3_dot(rv->axis, D);
			px_vec3 perp = px_v3_madd(w, rv->axis, -hh);
			double r = px_v3_norm(perp);
			double dr = r > 0 ? px_v3_dot(perp, D) / r
					  : px_v3_norm(px_v3_madd(D, rv->axis, -dh));
			px_vec3 m = px_v3(hh, r, 0), dm = px_v3(dh, dr, 0);
			if (!rv->profile_is_arc) {
				*f = px_v3_dot(rv->pseg.dir, px_v3_sub(m, rv->pseg.p0));
				*df = px_v3_dot(rv->pseg.dir, dm);
			} else {
				px_vec3 q = px_v3_sub(m, rv->parc.center);
				double x = px_v3_dot(rv->parc.e0, q),
				       y = px_v3_dot(rv->parc.e1, q);
				*f = atan2(y, x);
				*df = (x * px_v3_dot(rv->parc.e1, dm) -
				       y * px_v3_dot(rv->parc.e0, dm)) /
				      (x * x + y * y);
			}
		}
	}
}

/*
 * Parameter s in [lo, hi] where the monotone map reaches target; flo,
 * fhi its values at the ends (the map is proved monotone at
 * recognition). Safeguarded Newton inside a shrinking bracket; angles
 * are unwrapped against the bracket's lower value (the map spans at most
 * 2 pi). At most PX_RECOG_INV_ITERS evaluations.
 */
static double inv_solve(const struct px_recog_shape *pr, int which, double lo,
			double hi, double flo, double fhi, double target,
			int is_angle)
{
	double sgn = flo <= fhi ? 1.0 : -1.0, a = lo, b = hi, fa, fb, s;
	int it;

	fa = sgn * flo;
	fb = sgn * fhi;
	target *= sgn;
	if (!(target > fa))
		return lo;
	if (!(target < fb))
		return hi;
	s = a + (b - a) * (target - fa) / (fb - fa);
	for (it = 0; it < PX_RECOG_INV_ITERS; it++) {
		double f, df, r, sn;
		inv_eval(pr, which, s, &f, &df);
		f *= sgn;
		df *= sgn;
		if (is_angle) {
			double base = fa - 1e-9;
			f -= TWO_PI * floor((f - base) / TWO_PI);
		}
		r = f - target;
		if (r == 0)
			return s;
		if (r < 0)
			a = s, fa = f;
		else
			b = s, fb = f;
		sn = df != 0 ? s - r / df : NAN;
		if (!(sn > a && sn < b) || (it & 7) == 7)
			sn = 0.5 * (a + b);
		if (fabs(sn - s) <= 2 * DBL_EPSILON * (fabs(s) + (hi - lo)) ||
		    b - a <= 4 * DBL_EPSILON * (fabs(a) + fabs(b) + (hi - lo)))
			return sn;
		s = sn;
	}
	return s;
}

/* Closed-form parameter of the direction d on a degree-2 arc table:
 * its span is the one whose bisector is nearest in angle (the one
 * holding it), its angle from that bisector psi by its sine and cosine,
 * tan(psi / 2) = sin psi / (1 + cos psi) (|psi| <= half < pi / 2). */
static double qarc_param(const struct px_recog_qarc *q, const struct adir *d)
{
	int k, best = 0;
	double bv = -INFINITY, cp, sp, s, t;
	if (d->end)
		return d->end == 1 ? q->u[0] : q->u[q->n];
	for (k = 0; k < q->n; k++) {
		double v = d->c * q->mid[k][0] + d->s * q->mid[k][1] - q->chalf[k];
		if (v > bv)
			bv = v, best = k;
		if (v >= 0)
			break;
	}
	k = best;
	cp = d->c * q->mid[k][0] + d->s * q->mid[k][1];
	sp = q->mid[k][0] * d->s - q->mid[k][1] * d->c;
	if (cp < q->chalf[k])
		sp = sp < 0 ? -1 : 1;
	else
		sp = sp / ((1 + cp) * q->tquart[k]);
	sp = sp < -1 ? -1 : (sp > 1 ? 1 : sp);
	s = 0.5 * (sp + 1);
	t = q->lam[k] * s / ((1 - s) + q->lam[k] * s);
	return q->u[k] + t * (q->u[k + 1] - q->u[k]);
}

static double lin_param(double lo, double hi, double x0, double x1, double x)
{
	double t = (x - x0) / (x1 - x0);
	t = t < 0 ? 0 : (t > 1 ? 1 : t);
	return lo + (hi - lo) * t;
}

int px_recog_closest(const struct px_recog_shape *pr, px_vec3 p, int flags,
		    struct px_recog_hit *hit)
{
	int want = flags & PX_RECOG_WANT_PARAMS;
	px_vec3 x;

	if (!pr || !hit)
		return PX_E_INVAL;
	if (!px_v3_isfinite(p))
		return PX_E_NAN;
	memset(hit, 0, sizeof(*hit));
	switch (pr->kind) {
	case PX_RECOG_SEGMENT: {
		double t;
		x = seg_closest(&pr->seg, p, &t);
		if (want) {
			if (pr->linear) {
				hit->u = lin_param(pr->dom[0], pr->dom[1], 0,
						   pr->seg.len, t);
				hit->param = PX_RECOG_PARAM_EXACT;
			} else {
				hit->u = inv_solve(pr, INV_CURVE, pr->dom[0],
						   pr->dom[1], 0, pr->seg.len, t, 0);
				hit->param = PX_RECOG_PARAM_SOLVED;
			}
		}
		break;
	}
	case PX_RECOG_ARC: {
		struct adir d;
		x = arc_closest(&pr->arc, p, &d, &hit->tie);
		if (want && pr->qarc[0].n) {
			hit->u = qarc_param(&pr->qarc[0], &d);
			hit->param = PX_RECOG_PARAM_EXACT;
		} else if (want) {
			hit->u = inv_solve(pr, INV_CURVE, pr->dom[0], pr->dom[1], 0,
					   pr->arc.sweep, dir_angle(&d, pr->arc.sweep), 1);
			hit->param = PX_RECOG_PARAM_SOLVED;
		}
		break;
	}
	case PX_RECOG_CYLINDER:
	case PX_RECOG_CONE:
	case PX_RECOG_ANNULUS:
	case PX_RECOG_SPHERE:
	case PX_RECOG_TORUS: {
		const struct px_recog_rev *rv = &pr->rev;
		double pt = 0, pa, pp;
		struct adir dang, dprof;
		int da = rv->dir_angle;
		x = rev_closest(rv, p, &dang, &dprof, &pt, &hit->tie);
		if (want) {
			int exact = 1;
			double lo = pr->dom[2 - 2 * da], hi = pr->dom[3 - 2 * da];
			if (pr->qarc[0].n) {
				pa = qarc_param(&pr->qarc[0], &dang);
			} else {
				pa = inv_solve(pr, INV_REV_ANG, pr->dom[2 * da],
					       pr->dom[2 * da + 1], 0, rv->sweep,
					       dir_angle(&dang, rv->sweep), 1);
				exact = 0;
			}
			if (rv->profile_is_arc && pr->qarc[1].n) {
				pp = qarc_param(&pr->qarc[1], &dprof);
			} else if (rv->profile_is_arc) {
				pp = inv_solve(pr, INV_REV_PROF, lo, hi, 0, rv->parc.sweep,
					       dir_angle(&dprof, rv->parc.sweep), 1);
				exact = 0;
			} else if (pr->linear & (1 << (1 - da))) {
				pp = lin_param(lo, hi, 0, rv->pseg.len, pt);
			} else {
				pp = inv_solve(pr, INV_REV_PROF, lo, hi, 0,
					       rv->pseg.len, pt, 0);
				exact = 0;
			}
			hit->u = da == 0 ? pa : pp;
			hit->v = da == 0 ? pp : pa;
			hit->param = exact ? PX_RECOG_PARAM_EXACT : PX_RECOG_PARAM_SOLVED;
		}
		break;
	}
	case PX_RECOG_PARALLELOGRAM: {
		const struct px_recog_quad *q = &pr->quad;
		double xs, ys;
		x = quad_closest(q, p, &xs, &ys);
		if (want) {
			hit->u = (pr->linear & 1)
					 ? lin_param(pr->dom[0], pr->dom[1], q->x0, q->x1, xs)
					 : inv_solve(pr, INV_QUAD_X, pr->dom[0], pr->dom[1],
						     q->x0, q->x1, xs, 0);
			hit->v = (pr->linear & 2)
					 ? lin_param(pr->dom[2], pr->dom[3], q->y0, q->y1, ys)
					 : inv_solve(pr, INV_QUAD_Y, pr->dom[2], pr->dom[3],
						     q->y0, q->y1, ys, 0);
			hit->param = (pr->linear & 3) == 3 ? PX_RECOG_PARAM_EXACT
							   : PX_RECOG_PARAM_SOLVED;
		}
		break;
	}
	default:
		return PX_E_UNSUPPORTED;
	}
	hit->point = x;
	hit->dist = px_v3_dist(p, x);
	if (hit->dist > 0)
		hit->dir = px_v3_scale(px_v3_sub(p, x), 1.0 / hit->dist);
	return PX_OK;
}

const char *px_recog_kind_name(enum px_recog_kind k)
{
	switch (k) {
	case PX_RECOG_SEGMENT: return "segment";
	case PX_RECOG_ARC: return "arc";
	case PX_RECOG_PLANE: return "plane";
	case PX_RECOG_PARALLELOGRAM: return "parallelogram";
	case PX_RECOG_CYLINDER: return "cylinder";
	case PX_RECOG_CONE: return "cone";
	case PX_RECOG_ANNULUS: return "annulus";
	case PX_RECOG_SPHERE: return "sphere";
	case PX_RECOG_TORUS: return "torus";
	default: return "none";
	}
}
