/* NURBS curves and surfaces: basis functions, evaluation, derivatives,
 * validation, knot insertion, extraction and guaranteed boxes, all
 * against references written here (Cox-de Boor recursion, direct sums,
 * Richardson-extrapolated finite differences). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "px_alloc_count.h"
#include "px_arena.h"
#include "px_nurbs.h"
#include "px_test.h"

#define MAXN 64
#define MAXK (MAXN + PX_NURBS_MAX_DEGREE + 1)

/* ---- references ------------------------------------------------------- */

/* Cox-de Boor by its definition; left selects the left-continuous
 * degree-0 functions (for the domain end). */
static double ref_N(const double *U, int i, int p, double u, int left)
{
	double a = 0, b = 0;
	if (p == 0) {
		if (left)
			return (U[i] < u && u <= U[i + 1]) ? 1.0 : 0.0;
		return (U[i] <= u && u < U[i + 1]) ? 1.0 : 0.0;
	}
	if (U[i + p] > U[i])
		a = (u - U[i]) / (U[i + p] - U[i]) * ref_N(U, i, p - 1, u, left);
	if (U[i + p + 1] > U[i + 1])
		b = (U[i + p + 1] - u) / (U[i + p + 1] - U[i + 1]) *
		    ref_N(U, i + 1, p - 1, u, left);
	return a + b;
}

/* Derivative of order k of N_{i,p} by the textbook recursion, written
 * on full indices (independent of the span-local code). */
static double ref_dN(const double *U, int i, int p, double u, int k, int left)
{
	double a = 0, b = 0;
	if (k == 0)
		return ref_N(U, i, p, u, left);
	if (p == 0)
		return 0.0;
	if (U[i + p] > U[i])
		a = p / (U[i + p] - U[i]) * ref_dN(U, i, p - 1, u, k - 1, left);
	if (U[i + p + 1] > U[i + 1])
		b = p / (U[i + p + 1] - U[i + 1]) *
		    ref_dN(U, i + 1, p - 1, u, k - 1, left);
	return a - b;
}

struct tcurve {
	int p, n, nk;
	double U[MAXK];
	double xyz[3 * MAXN];
	double w[MAXN];
};

static px_vec3 ref_curve_point(const struct tcurve *t, double u)
{
	double sx = 0, sy = 0, sz = 0, sw = 0;
	int i, left = u >= t->U[t->n];
	for (i = 0; i < t->n; i++) {
		double b = ref_N(t->U, i, t->p, u, left) * t->w[i];
		sx += b * t->xyz[3 * i];
		sy += b * t->xyz[3 * i + 1];
		sz += b * t->xyz[3 * i + 2];
		sw += b;
	}
	return px_v3(sx / sw, sy / sw, sz / sw);
}

/* Knot vector with gaps that are zero (repeated knot), tiny (clustered)
 * or normal; runs never exceed max_run. */
static void gen_knots(double *U, int count, int start, double t0, int max_run)
{
	int i, run = 1;
	U[start] = t0;
	for (i = start + 1; i < start + count; i++) {
		double r = px_rand_unit(), g;
		if (r < 0.2 && run < max_run)
			g = 0.0;
		else if (r < 0.45)
			g = px_rand_range(0.001, 0.01);
		else
			g = px_rand_range(0.1, 1.0);
		U[i] = U[i - 1] + g;
		run = g == 0.0 ? run + 1 : 1;
	}
}

static void gen_curve(struct tcurve *t, int p, int clamped, int rational)
{
	int i;
	t->p = p;
	t->n = p + 1 + px_rand_int(0, 8);
	t->nk = t->n + p + 1;
	if (clamped) {
		int m = t->n - p - 1; /* interior knots */
		double end;
		for (i = 0; i <= p; i++)
			t->U[i] = 0.0;
		if (m > 0) {
			gen_knots(t->U, m, p + 1, px_rand_range(0.001, 0.5), p);
			end = t->U[p + m] + px_rand_range(0.001, 0.5);
		} else {
			end = px_rand_range(0.5, 2.0);
		}
		for (i = 0; i <= p; i++)
			t->U[t->n + i] = end;
	} else {
		gen_knots(t->U, t->nk, 0, px_rand_range(-1, 1), p);
		/* the domain must not be empty */
		if (!(t->U[p] < t->U[t->n]))
			for (i = t->n; i < t->nk; i++)
				t->U[i] += 0.5;
	}
	for (i = 0; i < 3 * t->n; i++)
		t->xyz[i] = px_rand_range(-1, 1);
	for (i = 0; i < t->n; i++)
		t->w[i] = rational ? exp(px_rand_range(log(0.2), log(5.0)))
				   : 1.0;
}

static unsigned char arena_buf[1 << 22];

static void make_curve(struct px_arena *a, const struct tcurve *t,
		       struct px_nurbs_curve *c)
{
	struct px_nurbs_error e;
	int rc = px_nurbs_curve_init(c, a, t->p, t->n, t->U, t->nk, t->xyz,
				     t->w, &e);
	PX_CHECK_MSG(rc == PX_OK, "init failed: %s", e.msg);
}

/* A parameter strictly inside a random non-empty span, with margin. */
static double inside_span(const double *U, int p, int n, double *width)
{
	int k;
	do
		k = px_rand_int(p, n - 1);
	while (!(U[k] < U[k + 1]));
	*width = U[k + 1] - U[k];
	return U[k] + *width * px_rand_range(0.25, 0.75);
}

static double vmax(px_vec3 a)
{
	return fmax(fabs(a.x), fmax(fabs(a.y), fabs(a.z)));
}

/* Richardson-extrapolated central difference of f at u, step h. */
typedef px_vec3 (*vfun)(void *ctx, double u);

static px_vec3 rich_diff(vfun f, void *ctx, double u, double h)
{
	px_vec3 d1 = px_v3_scale(px_v3_sub(f(ctx, u + h), f(ctx, u - h)),
				 0.5 / h);
	px_vec3 d2 = px_v3_scale(
		px_v3_sub(f(ctx, u + h / 2), f(ctx, u - h / 2)), 1.0 / h);
	return px_v3_scale(px_v3_sub(px_v3_scale(d2, 4.0), d1), 1.0 / 3.0);
}

/* ---- basis -------------------------------------------------------------- */

static void test_basis_vs_cox_de_boor(void)
{
	int trial;
	for (trial = 0; trial < 400; trial++) {
		struct tcurve t;
		struct px_nurbs_curve c = {0};
		double B[(PX_NURBS_MAX_DERIV + 1) * (PX_NURBS_MAX_DEGREE + 1)];
		int p = 1 + trial % PX_NURBS_MAX_DEGREE, k, r, kd, i;
		double u0, u1, u;
		gen_curve(&t, p, trial % 3 != 0, 0);
		c.degree = p;
		c.n_ctrl = t.n;
		c.n_knots = t.nk;
		c.knots = t.U;
		u0 = t.U[p];
		u1 = t.U[t.n];
		u = px_rand_range(u0, u1);
		if (trial % 7 == 0)
			u = t.U[px_rand_int(p, t.n - 1)]; /* exactly a knot */
		k = px_nurbs_curve_find_span(&c, u, 1);
		PX_CHECK(k >= p && k <= t.n - 1);
		PX_CHECK(t.U[k] <= u && u < t.U[k + 1]);
		px_nurbs_basis_ders(t.U, p, k, u, 3, B);
		for (kd = 0; kd <= 3; kd++) {
			double sum = 0, scale = 1;
			for (r = 0; r <= p; r++) {
				double ref = ref_dN(t.U, k - p + r, p, u, kd, 0);
				scale = fmax(scale, fabs(ref));
			}
			for (r = 0; r <= p; r++) {
				double ref = ref_dN(t.U, k - p + r, p, u, kd, 0);
				PX_CHECK_MSG(fabs(B[kd * (p + 1) + r] - ref) <=
						     1e-10 * scale,
					     "p=%d k=%d r=%d der=%d: %.17g vs %.17g",
					     p, k, r, kd, B[kd * (p + 1) + r],
					     ref);
				sum += B[kd * (p + 1) + r];
			}
			/* partition of unity and its derivatives */
			PX_CHECK_NEAR(sum, kd == 0 ? 1.0 : 0.0, 1e-9 * scale);
			if (kd == 0)
				for (r = 0; r <= p; r++)
					PX_CHECK(B[r] >= -1e-15);
		}
		/* Functions outside the span are zero there. */
		for (i = 0; i < t.n; i++)
			if (i < k - p || i > k)
				PX_CHECK(ref_N(t.U, i, p, u, 0) == 0.0);
	}
}

static void test_find_span_edges(void)
{
	static const double U[] = {0, 0, 0, 0.3, 0.3, 0.7, 1, 1, 1};
	struct px_nurbs_curve c = {2, 6, 9, U, NULL, 0};
	PX_CHECK_INT_EQ(px_nurbs_curve_find_span(&c, 0.0, 1), 2);
	PX_CHECK_INT_EQ(px_nurbs_curve_find_span(&c, -5.0, 1), 2);
	PX_CHECK_INT_EQ(px_nurbs_curve_find_span(&c, -5.0, -1), 2);
	PX_CHECK_INT_EQ(px_nurbs_curve_find_span(&c, 0.1, 1), 2);
	PX_CHECK_INT_EQ(px_nurbs_curve_find_span(&c, 0.3, 1), 4);
	PX_CHECK_INT_EQ(px_nurbs_curve_find_span(&c, 0.3, -1), 2);
	PX_CHECK_INT_EQ(px_nurbs_curve_find_span(&c, 0.5, -1), 4);
	PX_CHECK_INT_EQ(px_nurbs_curve_find_span(&c, 0.7, 1), 5);
	PX_CHECK_INT_EQ(px_nurbs_curve_find_span(&c, 0.7, -1), 4);
	PX_CHECK_INT_EQ(px_nurbs_curve_find_span(&c, 1.0, 1), 5);
	PX_CHECK_INT_EQ(px_nurbs_curve_find_span(&c, 7.0, 1), 5);
	PX_CHECK_INT_EQ(px_nurbs_curve_find_span(&c, NAN, 1), 2);
	PX_CHECK_INT_EQ(px_nurbs_curve_find_span(NULL, 0.5, 1), -1);
}

/* ---- curves --------------------------------------------------------------- */

struct cctx {
	const struct px_nurbs_curve *c;
	int order;
};

static px_vec3 curve_der(void *ctx, double u)
{
	struct cctx *x = ctx;
	px_vec3 d[4];
	px_nurbs_curve_eval(x->c, u, x->order, d);
	return d[x->order];
}

static void test_curve_eval_vs_reference(void)
{
	int trial;
	for (trial = 0; trial < 300; trial++) {
		struct px_arena a;
		struct tcurve t;
		struct px_nurbs_curve c;
		int p = 1 + trial % PX_NURBS_MAX_DEGREE, j;
		px_arena_init(&a, arena_buf, sizeof(arena_buf));
		gen_curve(&t, p, trial % 4 != 0, trial % 5 != 0);
		make_curve(&a, &t, &c);
		for (j = 0; j < 10; j++) {
			double w, u = inside_span(t.U, p, t.n, &w);
			px_vec3 d[4], ref;
			int kd;
			if (j == 0)
				u = t.U[p];
			if (j == 1)
				u = t.U[t.n];
			ref = ref_curve_point(&t, u);
			PX_CHECK_INT_EQ(px_nurbs_curve_eval(&c, u, 3, d), PX_OK);
			PX_CHECK_MSG(px_v3_dist(d[0], ref) <= 1e-12 * (1 + vmax(ref)),
				     "p=%d u=%.17g dist %.3g", p, u,
				     px_v3_dist(d[0], ref));
			PX_CHECK(px_v3_dist(px_nurbs_curve_point(&c, u), d[0]) <=
				 1e-15 * (1 + vmax(ref)));
			if (j < 2)
				continue;
			/* Each derivative is the derivative of the one below. */
			for (kd = 1; kd <= 3; kd++) {
				struct cctx x = {&c, kd - 1};
				px_vec3 fd = rich_diff(curve_der, &x, u, 0.005 * w);
				double scale = vmax(d[kd]) + vmax(d[kd - 1]) / w +
					       vmax(d[0]) / pow(w, kd) + 1e-3;
				PX_CHECK_MSG(px_v3_dist(fd, d[kd]) <= 2e-6 * scale,
					     "p=%d der %d: |fd-d|=%.3g scale %.3g",
					     p, kd, px_v3_dist(fd, d[kd]), scale);
			}
			if (p < 3 && !c.rational)
				PX_CHECK(vmax(d[3]) == 0.0);
		}
		/* Outside the domain: clamped. */
		{
			px_vec3 d0[1], d1[1];
			px_nurbs_curve_eval(&c, t.U[p] - 3.0, 0, d0);
			px_nurbs_curve_eval(&c, t.U[p], 0, d1);
			PX_CHECK(px_v3_dist(d0[0], d1[0]) == 0.0);
			px_nurbs_curve_eval(&c, t.U[t.n] + 3.0, 0, d0);
			px_nurbs_curve_eval(&c, t.U[t.n], 0, d1);
			PX_CHECK(px_v3_dist(d0[0], d1[0]) == 0.0);
		}
	}
}

static void test_curve_bad_eval_args(void)
{
	static const double U[] = {0, 0, 1, 1};
	static const double pw[] = {0, 0, 0, 1, 1, 0, 0, 1};
	struct px_nurbs_curve c;
	px_vec3 d[5];
	PX_CHECK_INT_EQ(px_nurbs_curve_view(&c, 1, 2, U, 4, pw, NULL), PX_OK);
	PX_CHECK_INT_EQ(px_nurbs_curve_eval(&c, NAN, 0, d), PX_E_NAN);
	PX_CHECK_INT_EQ(px_nurbs_curve_eval(&c, 0.5, 4, d), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_nurbs_curve_eval(&c, 0.5, -1, d), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_nurbs_curve_eval(NULL, 0.5, 0, d), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_nurbs_curve_eval(&c, 0.5, 0, NULL), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_nurbs_curve_eval(&c, 0.25, 3, d), PX_OK);
	PX_CHECK_NEAR(d[0].x, 0.25, 1e-15);
	PX_CHECK_NEAR(d[1].x, 1.0, 1e-15);
	PX_CHECK(d[2].x == 0.0 && d[3].x == 0.0);
}

/* The rational quadratic full circle with 9 control points. */
static void circle_data(double r, double *U, double *xyz, double *w)
{
	static const double k[12] = {0, 0, 0, .25, .25, .5, .5, .75, .75, 1, 1, 1};
	static const double cx[9] = {1, 1, 0, -1, -1, -1, 0, 1, 1};
	static const double cy[9] = {0, 1, 1, 1, 0, -1, -1, -1, 0};
	int i;
	for (i = 0; i < 12; i++)
		U[i] = k[i];
	for (i = 0; i < 9; i++) {
		xyz[3 * i] = r * cx[i];
		xyz[3 * i + 1] = r * cy[i];
		xyz[3 * i + 2] = 0.0;
		w[i] = (i % 2) ? sqrt(0.5) : 1.0;
	}
}

static void test_nurbs_circle(void)
{
	struct px_arena a;
	struct px_nurbs_curve c;
	double U[12], xyz[27], w[9];
	int i;
	px_arena_init(&a, arena_buf, sizeof(arena_buf));
	circle_data(2.5, U, xyz, w);
	PX_CHECK_INT_EQ(px_nurbs_curve_init(&c, &a, 2, 9, U, 12, xyz, w, NULL),
			PX_OK);
	PX_CHECK(c.rational);
	for (i = 0; i <= 1000; i++) {
		double u = i / 1000.0;
		px_vec3 d[4];
		px_nurbs_curve_eval(&c, u, 3, d);
		PX_CHECK_NEAR(px_v3_norm(d[0]), 2.5, 1e-14);
		PX_CHECK_NEAR(d[0].z, 0.0, 0.0);
		/* tangent perpendicular to the radius, and |C|^2 constant
		 * means C.C'' = -|C'|^2 */
		PX_CHECK_NEAR(px_v3_dot(d[0], d[1]), 0.0, 1e-11 * px_v3_norm(d[1]));
		PX_CHECK_CLOSE(px_v3_dot(d[0], d[2]), -px_v3_norm2(d[1]),
			       1e-9, 1e-9);
	}
	/* quarter points */
	PX_CHECK(px_v3_dist(px_nurbs_curve_point(&c, 0.25), px_v3(0, 2.5, 0)) <
		 1e-15);
	PX_CHECK(px_nurbs_curve_seam(&c, 1e-12, 1e-9) >= 1);
	/* The double knots are C0 by the knot structure; the circle is
	 * still smooth there: left and right tangents agree. */
	{
		double br[3];
		PX_CHECK_INT_EQ(px_nurbs_curve_breaks(&c, br, 3), 3);
		for (i = 0; i < 3; i++) {
			px_vec3 l[2], r[2];
			PX_CHECK_NEAR(br[i], 0.25 * (i + 1), 0);
			px_nurbs_curve_eval_side(&c, br[i], -1, 1, l);
			px_nurbs_curve_eval_side(&c, br[i], 1, 1, r);
			PX_CHECK(px_v3_dist(l[0], r[0]) < 1e-15);
			PX_CHECK(px_v3_dist(l[1], r[1]) < 1e-12);
		}
	}
	{
		px_aabb b = px_nurbs_curve_aabb(&c);
		PX_CHECK_NEAR(b.min.x, -2.5, 0);
		PX_CHECK_NEAR(b.max.y, 2.5, 0);
	}
}

static void test_curve_breaks_and_seams(void)
{
	/* Cubic with a C0 knot at 0.5: left and right tangents differ. */
	static const double U[] = {0, 0, 0, 0, 0.5, 0.5, 0.5, 1, 1, 1, 1};
	double xyz[21] = {0, 0, 0, 1, 0, 0, 2, 0, 0, 3, 0, 0,
			  3, 1, 0, 3, 2, 0, 3, 3, 0};
	struct px_arena a;
	struct px_nurbs_curve c;
	double br[4];
	px_vec3 dl[2], dr[2];
	px_arena_init(&a, arena_buf, sizeof(arena_buf));
	PX_CHECK_INT_EQ(px_nurbs_curve_init(&c, &a, 3, 7, U, 11, xyz, NULL, NULL),
			PX_OK);
	PX_CHECK(!c.rational);
	PX_CHECK_INT_EQ(px_nurbs_curve_breaks(&c, br, 4), 1);
	PX_CHECK_NEAR(br[0], 0.5, 0);
	px_nurbs_curve_eval_side(&c, 0.5, -1, 1, dl);
	px_nurbs_curve_eval_side(&c, 0.5, 1, 1, dr);
	PX_CHECK(px_v3_dist(dl[0], px_v3(3, 0, 0)) < 1e-15);
	PX_CHECK(px_v3_dist(dr[0], px_v3(3, 0, 0)) < 1e-15);
	PX_CHECK(dl[1].x > 1 && fabs(dl[1].y) < 1e-12);
	PX_CHECK(dr[1].y > 1 && fabs(dr[1].x) < 1e-12);
	PX_CHECK_INT_EQ(px_nurbs_curve_seam(&c, 1e-9, 1e-9), -1);

	/* Uniform periodic cubic: control polygon wrapped by 3 points. */
	{
		double K[14], P[30];
		struct px_nurbs_curve pc;
		int i;
		for (i = 0; i < 14; i++)
			K[i] = i;
		for (i = 0; i < 7; i++) {
			double t = 2 * M_PI * i / 7.0;
			P[3 * i] = cos(t) * (1 + 0.3 * (i % 2));
			P[3 * i + 1] = sin(t);
			P[3 * i + 2] = 0.1 * i;
		}
		for (i = 7; i < 10; i++) {
			P[3 * i] = P[3 * (i - 7)];
			P[3 * i + 1] = P[3 * (i - 7) + 1];
			P[3 * i + 2] = P[3 * (i - 7) + 2];
		}
		PX_CHECK_INT_EQ(px_nurbs_curve_init(&pc, &a, 3, 10, K, 14, P,
						    NULL, NULL),
				PX_OK);
		{
			double u0, u1;
			px_nurbs_curve_domain(&pc, &u0, &u1);
			PX_CHECK_NEAR(u0, 3, 0);
			PX_CHECK_NEAR(u1, 10, 0);
		}
		PX_CHECK_INT_EQ(px_nurbs_curve_seam(&pc, 1e-12, 1e-9), 2);
		/* Break the wrap: no longer closed. */
		P[3 * 9] += 0.5;
		PX_CHECK_INT_EQ(px_nurbs_curve_init(&pc, &a, 3, 10, K, 14, P,
						    NULL, NULL),
				PX_OK);
		PX_CHECK_INT_EQ(px_nurbs_curve_seam(&pc, 1e-6, 1e-9), -1);
	}
}

static void check_err(int rc, const struct px_nurbs_error *e, int code,
		      enum px_nurbs_fault fault, int index, const char *needle)
{
	PX_CHECK_MSG(rc == code, "rc %d (%s) expected %d: %s", rc,
		     px_strerror_name(rc), code, e->msg);
	PX_CHECK_INT_EQ(e->code, code);
	PX_CHECK_MSG(e->fault == fault, "fault %d expected %d: %s", e->fault,
		     fault, e->msg);
	PX_CHECK_INT_EQ(e->index, index);
	PX_CHECK_MSG(strstr(e->msg, needle) != NULL, "'%s' lacks '%s'",
		     e->msg, needle);
}

static void test_curve_validation(void)
{
	double U[] = {0, 0, 0, 0.2, 0.4, 0.6, 0.5, 1, 1, 1};
	double xyz[21] = {0};
	double w[7] = {1, 1, 1, 1, 1, 1, 1};
	struct px_nurbs_error e;
	struct px_arena a;
	struct px_nurbs_curve c;
	int rc;

	rc = px_nurbs_curve_validate(2, 7, U, 10, xyz, w, &e);
	check_err(rc, &e, PX_E_INVAL, PX_NURBS_FAULT_KNOT_ORDER, 6,
		  "knot 6 decreases (0.5 < 0.59999");
	PX_CHECK_NEAR(e.value, 0.5, 0);
	PX_CHECK_NEAR(e.value2, 0.6, 0);
	U[6] = 0.6;
	PX_CHECK_INT_EQ(px_nurbs_curve_validate(2, 7, U, 10, xyz, w, &e), PX_OK);
	PX_CHECK_INT_EQ(e.fault, PX_NURBS_FAULT_NONE);

	rc = px_nurbs_curve_validate(2, 7, U, 9, xyz, w, &e);
	check_err(rc, &e, PX_E_INVAL, PX_NURBS_FAULT_KNOT_COUNT, -1, "need 10");
	rc = px_nurbs_curve_validate(0, 7, U, 10, xyz, w, &e);
	check_err(rc, &e, PX_E_RANGE, PX_NURBS_FAULT_DEGREE, -1, "degree 0");
	rc = px_nurbs_curve_validate(PX_NURBS_MAX_DEGREE + 1, 20, U, 10, xyz, w,
				     &e);
	check_err(rc, &e, PX_E_RANGE, PX_NURBS_FAULT_DEGREE, -1, "outside");
	rc = px_nurbs_curve_validate(2, 2, U, 5, xyz, w, &e);
	check_err(rc, &e, PX_E_INVAL, PX_NURBS_FAULT_TOO_FEW, -1, "at least 3");
	U[4] = NAN;
	rc = px_nurbs_curve_validate(2, 7, U, 10, xyz, w, &e);
	check_err(rc, &e, PX_E_NAN, PX_NURBS_FAULT_KNOT_NAN, 4, "knot 4");
	U[4] = 0.4;
	w[3] = 0.0;
	rc = px_nurbs_curve_validate(2, 7, U, 10, xyz, w, &e);
	check_err(rc, &e, PX_E_RANGE, PX_NURBS_FAULT_WEIGHT, 3, "weight 0");
	w[3] = -2;
	rc = px_nurbs_curve_validate(2, 7, U, 10, xyz, w, &e);
	check_err(rc, &e, PX_E_RANGE, PX_NURBS_FAULT_WEIGHT, 3, "weight -2");
	w[3] = INFINITY;
	rc = px_nurbs_curve_validate(2, 7, U, 10, xyz, w, &e);
	check_err(rc, &e, PX_E_RANGE, PX_NURBS_FAULT_WEIGHT, 3, "control point 3");
	w[3] = 1;
	xyz[3 * 5 + 1] = NAN;
	rc = px_nurbs_curve_validate(2, 7, U, 10, xyz, w, &e);
	check_err(rc, &e, PX_E_NAN, PX_NURBS_FAULT_COORD_NAN, 5,
		  "control point 5");
	xyz[3 * 5 + 1] = 0;
	{
		/* interior multiplicity degree+1 = 3 */
		double V[] = {0, 0, 0, 0.3, 0.3, 0.3, 0.6, 1, 1, 1};
		rc = px_nurbs_curve_validate(2, 7, V, 10, xyz, w, &e);
		check_err(rc, &e, PX_E_INVAL, PX_NURBS_FAULT_KNOT_MULT, 3,
			  "multiplicity 3 > degree 2");
	}
	{
		/* end multiplicity degree+2 */
		double V[] = {0, 0, 0, 0, 0.3, 0.6, 1, 1, 1, 1};
		rc = px_nurbs_curve_validate(2, 7, V, 10, xyz, w, &e);
		check_err(rc, &e, PX_E_INVAL, PX_NURBS_FAULT_KNOT_MULT, 0,
			  "multiplicity 4 > degree+1");
	}
	{
		/* multiplicity degree in the interior is allowed (C0) */
		double V[] = {0, 0, 0, 0.3, 0.3, 0.6, 0.7, 1, 1, 1};
		PX_CHECK_INT_EQ(px_nurbs_curve_validate(2, 7, V, 10, xyz, w, &e),
				PX_OK);
	}
	{
		/* empty domain: U[p] == U[n] */
		{
			double V2[] = {0, 1, 1, 1, 2, 3};
			/* p=2, n=3: domain [U2, U3] = [1, 1] */
			rc = px_nurbs_curve_validate(2, 3, V2, 6, xyz, w, &e);
			check_err(rc, &e, PX_E_DEGENERATE,
				  PX_NURBS_FAULT_DOMAIN, 2, "empty");
		}
	}
	rc = px_nurbs_curve_validate(2, 7, NULL, 10, xyz, w, &e);
	PX_CHECK_INT_EQ(rc, PX_E_INVAL);
	PX_CHECK_INT_EQ(e.fault, PX_NURBS_FAULT_ARG);
	/* Arena too small. */
	{
		static unsigned char small[64];
		px_arena_init(&a, small, sizeof(small));
		rc = px_nurbs_curve_init(&c, &a, 2, 7, U, 10, xyz, w, &e);
		PX_CHECK_INT_EQ(rc, PX_E_NOSPC);
		PX_CHECK_INT_EQ(e.fault, PX_NURBS_FAULT_NOSPC);
		PX_CHECK(c.knots == NULL);
	}
	/* Exactly px_nurbs_curve_bytes() suffices, even misaligned. */
	{
		static unsigned char buf[4096];
		size_t need = px_nurbs_curve_bytes(2, 7);
		px_arena_init(&a, buf + 5, need);
		PX_CHECK_INT_EQ(px_nurbs_curve_init(&c, &a, 2, 7, U, 10, xyz, w,
						    &e),
				PX_OK);
	}
	/* view of homogeneous data checks the weights too */
	{
		double pw[28] = {0};
		int i;
		for (i = 0; i < 7; i++)
			pw[4 * i + 3] = 1;
		PX_CHECK_INT_EQ(px_nurbs_curve_view(&c, 2, 7, U, 10, pw, &e),
				PX_OK);
		pw[4 * 2 + 3] = -1;
		rc = px_nurbs_curve_view(&c, 2, 7, U, 10, pw, &e);
		check_err(rc, &e, PX_E_RANGE, PX_NURBS_FAULT_WEIGHT, 2,
			  "control point 2");
	}
}

static void test_curve_knot_insertion(void)
{
	int trial;
	for (trial = 0; trial < 300; trial++) {
		struct px_arena a;
		struct tcurve t;
		struct px_nurbs_curve c, d, d2;
		int p = 1 + trial % 9, j, s, times, rc;
		double u, u0, u1, diag;
		px_aabb box;
		px_arena_init(&a, arena_buf, sizeof(arena_buf));
		gen_curve(&t, p, trial % 3 != 0, trial % 4 != 0);
		make_curve(&a, &t, &c);
		px_nurbs_curve_domain(&c, &u0, &u1);
		u = px_rand_range(u0, u1);
		if (trial % 5 == 0)
			u = t.U[px_rand_int(p, t.n)]; /* existing knot or end */
		s = 0;
		for (j = 0; j < t.nk; j++)
			s += t.U[j] == u;
		if (s >= p) {
			PX_CHECK_INT_EQ(px_nurbs_curve_insert_knot(&c, u, 1, &a,
								   &d),
					PX_E_RANGE);
			continue;
		}
		times = px_rand_int(1, p - s);
		rc = px_nurbs_curve_insert_knot(&c, u, times, &a, &d);
		PX_CHECK_INT_EQ(rc, PX_OK);
		PX_CHECK_INT_EQ(d.n_ctrl, c.n_ctrl + times);
		PX_CHECK_INT_EQ(d.n_knots, c.n_knots + times);
		for (j = 1; j < d.n_knots; j++)
			PX_CHECK(d.knots[j] >= d.knots[j - 1]);
		PX_CHECK_INT_EQ(px_nurbs_curve_view(&d2, d.degree, d.n_ctrl,
						    d.knots, d.n_knots, d.pw,
						    NULL),
				PX_OK);
		box = px_nurbs_curve_aabb(&c);
		diag = px_v3_dist(box.min, box.max);
		for (j = 0; j < 20; j++) {
			double x = j == 0 ? u : px_rand_range(u0, u1);
			px_vec3 e0[3], e1[3];
			px_nurbs_curve_eval(&c, x, 2, e0);
			px_nurbs_curve_eval(&d, x, 2, e1);
			PX_CHECK_MSG(px_v3_dist(e0[0], e1[0]) <= 1e-12 * diag,
				     "p=%d u=%g times=%d x=%g: %.3g", p, u,
				     times, x, px_v3_dist(e0[0], e1[0]));
			if (x != u)
				PX_CHECK(px_v3_dist(e0[1], e1[1]) <=
					 1e-7 * (px_v3_norm(e0[1]) + diag));
		}
		/* At multiplicity p the curve interpolates a control point. */
		if (s + times == p && u > u0 && u < u1) {
			px_vec3 cu = px_nurbs_curve_point(&c, u);
			double best = INFINITY;
			for (j = 0; j < d.n_ctrl; j++)
				best = fmin(best, px_v3_dist(cu,
							    px_nurbs_curve_ctrl(&d, j, NULL)));
			PX_CHECK(best <= 1e-12 * diag);
		}
	}
	{
		struct px_arena a;
		struct tcurve t;
		struct px_nurbs_curve c, d;
		px_arena_init(&a, arena_buf, sizeof(arena_buf));
		gen_curve(&t, 3, 1, 1);
		make_curve(&a, &t, &c);
		PX_CHECK_INT_EQ(px_nurbs_curve_insert_knot(&c, -1, 1, &a, &d),
				PX_E_RANGE);
		PX_CHECK_INT_EQ(px_nurbs_curve_insert_knot(&c, NAN, 1, &a, &d),
				PX_E_NAN);
		PX_CHECK_INT_EQ(px_nurbs_curve_insert_knot(&c, 0.1, -1, &a, &d),
				PX_E_INVAL);
		px_arena_init(&a, arena_buf, 16);
		PX_CHECK_INT_EQ(px_nurbs_curve_insert_knot(&c, t.U[3] * 0.5 +
								   t.U[t.n] * 0.5,
							   1, &a, &d),
				PX_E_NOSPC);
	}
}

static double work_buf[1 << 18];

static void test_curve_extraction_and_boxes(void)
{
	int trial;
	for (trial = 0; trial < 300; trial++) {
		struct px_arena a;
		struct tcurve t;
		struct px_nurbs_curve c, sub, sub2;
		int p = 1 + trial % 9, j, rc;
		double u0, u1, lo, hi, diag;
		px_aabb box, full;
		size_t len;
		px_arena_init(&a, arena_buf, sizeof(arena_buf));
		gen_curve(&t, p, trial % 3 != 0, trial % 4 != 0);
		make_curve(&a, &t, &c);
		px_nurbs_curve_domain(&c, &u0, &u1);
		lo = px_rand_range(u0, u1);
		hi = px_rand_range(u0, u1);
		if (trial % 6 == 0)
			lo = t.U[px_rand_int(p, t.n - 1)];
		if (trial % 7 == 0)
			hi = t.U[px_rand_int(p + 1, t.n)];
		if (trial % 11 == 0) {
			lo = u0;
			hi = u1;
		}
		if (lo > hi) {
			double x = lo;
			lo = hi;
			hi = x;
		}
		if (!(lo < hi))
			continue;
		len = PX_NURBS_CURVE_WORK_LEN(p, c.n_ctrl);
		rc = px_nurbs_curve_extract_work(&c, lo, hi, work_buf, len, &sub);
		PX_CHECK_MSG(rc == PX_OK, "rc %d", rc);
		PX_CHECK_INT_EQ(px_nurbs_curve_extract_work(&c, lo, hi, work_buf,
							    len - 1, &sub2),
				PX_E_NOSPC);
		rc = px_nurbs_curve_extract_work(&c, lo, hi, work_buf, len, &sub);
		PX_CHECK_INT_EQ(rc, PX_OK);
		/* The result is a valid clamped curve on [lo, hi]. */
		PX_CHECK_INT_EQ(px_nurbs_curve_view(&sub2, sub.degree, sub.n_ctrl,
						    sub.knots, sub.n_knots,
						    sub.pw, NULL),
				PX_OK);
		PX_CHECK(sub.knots[0] == lo && sub.knots[p] == lo);
		PX_CHECK(sub.knots[sub.n_ctrl] == hi &&
			 sub.knots[sub.n_knots - 1] == hi);
		full = px_nurbs_curve_aabb(&c);
		diag = px_v3_dist(full.min, full.max);
		box = px_nurbs_curve_aabb(&sub);
		/* sub box inside the full box */
		PX_CHECK(box.min.x >= full.min.x - 1e-12 * diag &&
			 box.max.z <= full.max.z + 1e-12 * diag);
		for (j = 0; j <= 200; j++) {
			double x = j == 200 ? hi : lo + (hi - lo) * j / 200.0;
			px_vec3 e0[2], e1[2];
			if (j % 10 == 5)
				x = px_rand_range(lo, hi);
			px_nurbs_curve_eval_side(&c, x, j == 200 ? -1 : 1, 1, e0);
			px_nurbs_curve_eval(&sub, x, 1, e1);
			PX_CHECK_MSG(px_v3_dist(e0[0], e1[0]) <= 1e-12 * diag,
				     "p=%d [%g,%g] x=%g: %.3g", p, lo, hi, x,
				     px_v3_dist(e0[0], e1[0]));
			PX_CHECK_MSG(px_v3_dist(e0[1], e1[1]) <=
				 1e-7 * (px_v3_norm(e0[1]) + diag / (hi - lo)),
				 "p=%d [%.17g,%.17g] x=%.17g j=%d d1 %g %g %g vs %g %g %g", p, lo, hi, x, j,
				 e0[1].x, e0[1].y, e0[1].z, e1[1].x, e1[1].y, e1[1].z);
			/* the guaranteed box holds every sampled point */
			PX_CHECK_MSG(e0[0].x >= box.min.x - 1e-13 * diag &&
					     e0[0].x <= box.max.x + 1e-13 * diag &&
					     e0[0].y >= box.min.y - 1e-13 * diag &&
					     e0[0].y <= box.max.y + 1e-13 * diag &&
					     e0[0].z >= box.min.z - 1e-13 * diag &&
					     e0[0].z <= box.max.z + 1e-13 * diag,
				     "point outside sub box at %g", x);
		}
		{
			px_aabb b2;
			PX_CHECK_INT_EQ(px_nurbs_curve_sub_aabb(&c, lo, hi, work_buf,
								len, &b2),
					PX_OK);
			PX_CHECK(b2.min.x == box.min.x && b2.max.y == box.max.y);
		}
		/* arena version gives the same curve */
		{
			size_t before = px_arena_used(&a);
			rc = px_nurbs_curve_extract(&c, lo, hi, &a, &sub2);
			PX_CHECK_INT_EQ(rc, PX_OK);
			PX_CHECK_INT_EQ(sub2.n_ctrl, sub.n_ctrl);
			PX_CHECK(px_arena_used(&a) - before <=
				 px_nurbs_curve_extract_bytes(&c));
			PX_CHECK(px_arena_high_water(&a) - before <=
				 px_nurbs_curve_extract_bytes(&c));
			PX_CHECK(memcmp(sub2.pw, sub.pw,
					4 * sizeof(double) * sub.n_ctrl) == 0);
		}
	}
	{
		struct px_arena a;
		struct tcurve t;
		struct px_nurbs_curve c, sub;
		size_t len;
		px_arena_init(&a, arena_buf, sizeof(arena_buf));
		gen_curve(&t, 3, 1, 1);
		make_curve(&a, &t, &c);
		len = PX_NURBS_CURVE_WORK_LEN(3, c.n_ctrl);
		PX_CHECK_INT_EQ(px_nurbs_curve_extract_work(&c, 0.5, 0.5, work_buf,
							    len, &sub),
				PX_E_RANGE);
		PX_CHECK_INT_EQ(px_nurbs_curve_extract_work(&c, -1, 0.5, work_buf,
							    len, &sub),
				PX_E_RANGE);
		PX_CHECK_INT_EQ(px_nurbs_curve_extract_work(&c, NAN, 0.5,
							    work_buf, len, &sub),
				PX_E_NAN);
		PX_CHECK_INT_EQ(px_nurbs_curve_extract(&c, 0.6, 0.5, &a, &sub),
				PX_E_RANGE);
	}
}

/* ---- surfaces ------------------------------------------------------------- */

struct tsurf {
	int p[2], n[2], nk[2];
	double U[2][MAXK];
	double xyz[3 * 16 * 16];
	double w[16 * 16];
};

static void gen_surf(struct tsurf *s, int pu, int pv, int clamped,
		     int rational)
{
	struct tcurve t;
	int d, i;
	for (d = 0; d < 2; d++) {
		gen_curve(&t, d ? pv : pu, clamped, 0);
		if (t.n > 16)
			t.n = 16; /* gen_curve keeps n <= p + 9 */
		s->p[d] = t.p;
		s->n[d] = t.n;
		s->nk[d] = t.nk;
		memcpy(s->U[d], t.U, sizeof(double) * (size_t)t.nk);
	}
	for (i = 0; i < 3 * s->n[0] * s->n[1]; i++)
		s->xyz[i] = px_rand_range(-1, 1);
	for (i = 0; i < s->n[0] * s->n[1]; i++)
		s->w[i] = rational ? exp(px_rand_range(log(0.2), log(5.0))) : 1.0;
}

static px_vec3 ref_surf_point(const struct tsurf *s, double u, double v)
{
	double sx = 0, sy = 0, sz = 0, sw = 0;
	int i, j, lu = u >= s->U[0][s->n[0]], lv = v >= s->U[1][s->n[1]];
	for (j = 0; j < s->n[1]; j++) {
		double nv = ref_N(s->U[1], j, s->p[1], v, lv);
		if (nv == 0)
			continue;
		for (i = 0; i < s->n[0]; i++) {
			int idx = j * s->n[0] + i;
			double b = nv * ref_N(s->U[0], i, s->p[0], u, lu) * s->w[idx];
			sx += b * s->xyz[3 * idx];
			sy += b * s->xyz[3 * idx + 1];
			sz += b * s->xyz[3 * idx + 2];
			sw += b;
		}
	}
	return px_v3(sx / sw, sy / sw, sz / sw);
}

static void make_surf(struct px_arena *a, const struct tsurf *t,
		      struct px_nurbs_surf *s)
{
	struct px_nurbs_error e;
	int rc = px_nurbs_surf_init(s, a, t->p[0], t->p[1], t->n[0], t->n[1],
				    t->U[0], t->nk[0], t->U[1], t->nk[1],
				    t->xyz, t->w, &e);
	PX_CHECK_MSG(rc == PX_OK, "surf init: %s", e.msg);
}

/* Partial derivative fields, by (k, l) index. */
static px_vec3 sd_get(const struct px_nurbs_surf_derivs *d, int k, int l)
{
	switch (k * 10 + l) {
	case 0: return d->s;
	case 10: return d->su;
	case 1: return d->sv;
	case 20: return d->suu;
	case 11: return d->suv;
	case 2: return d->svv;
	case 30: return d->suuu;
	case 21: return d->suuv;
	case 12: return d->suvv;
	case 3: return d->svvv;
	}
	return px_v3(NAN, NAN, NAN);
}

struct sctx {
	const struct px_nurbs_surf *s;
	int k, l, dir;
	double fixed;
};

static px_vec3 surf_partial(void *ctx, double t)
{
	struct sctx *x = ctx;
	struct px_nurbs_surf_derivs d;
	if (x->dir == 0)
		px_nurbs_surf_eval(x->s, t, x->fixed, 3, &d);
	else
		px_nurbs_surf_eval(x->s, x->fixed, t, 3, &d);
	return sd_get(&d, x->k, x->l);
}

static void test_surf_eval_vs_reference(void)
{
	int trial;
	for (trial = 0; trial < 120; trial++) {
		static struct tsurf t;
		struct px_arena a;
		struct px_nurbs_surf s;
		int pu = 1 + trial % 6, pv = 1 + (trial / 6) % 5, j;
		px_arena_init(&a, arena_buf, sizeof(arena_buf));
		gen_surf(&t, pu, pv, trial % 4 != 0, trial % 3 != 0);
		make_surf(&a, &t, &s);
		for (j = 0; j < 6; j++) {
			double wu, wv;
			double u = inside_span(t.U[0], pu, t.n[0], &wu);
			double v = inside_span(t.U[1], pv, t.n[1], &wv);
			struct px_nurbs_surf_derivs d;
			px_vec3 ref;
			int k, l;
			if (j == 0) {
				u = t.U[0][t.n[0]];
				v = t.U[1][pv];
			}
			ref = ref_surf_point(&t, u, v);
			PX_CHECK_INT_EQ(px_nurbs_surf_eval(&s, u, v, 3, &d), PX_OK);
			PX_CHECK_MSG(px_v3_dist(d.s, ref) <= 1e-12 * (1 + vmax(ref)),
				     "pu=%d pv=%d: %.3g", pu, pv,
				     px_v3_dist(d.s, ref));
			PX_CHECK(px_v3_dist(px_nurbs_surf_point(&s, u, v), d.s) <=
				 1e-14 * (1 + vmax(ref)));
			if (j == 0)
				continue;
			/* every partial of order 1..3 from one of order one
			 * less, in u when k > 0, otherwise in v */
			for (k = 0; k <= 3; k++) {
				for (l = 0; k + l <= 3; l++) {
					struct sctx x;
					px_vec3 fd, an;
					double h, scale;
					if (k + l == 0)
						continue;
					x.s = &s;
					if (k > 0) {
						x.k = k - 1;
						x.l = l;
						x.dir = 0;
						x.fixed = v;
						h = 0.005 * wu;
						fd = rich_diff(surf_partial, &x, u, h);
					} else {
						x.k = 0;
						x.l = l - 1;
						x.dir = 1;
						x.fixed = u;
						h = 0.005 * wv;
						fd = rich_diff(surf_partial, &x, v, h);
					}
					an = sd_get(&d, k, l);
					scale = vmax(an) +
						vmax(sd_get(&d, x.k, x.l)) / (h * 200) +
						vmax(d.s) / (pow(wu, k) * pow(wv, l)) +
						1e-3;
					PX_CHECK_MSG(px_v3_dist(fd, an) <= 2e-6 * scale,
						     "pu=%d pv=%d S(%d,%d): %.3g "
						     "scale %.3g",
						     pu, pv, k, l, px_v3_dist(fd, an),
						     scale);
				}
			}
		}
	}
}

/* Sphere of radius r: semicircle profile (x, z) revolved by the 9-point
 * circle; u runs around the axis, v from pole to pole. */
static void sphere_data(double r, double *Uu, double *Uv, double *xyz,
			double *w)
{
	double cU[12], cxyz[27], cw[9];
	static const double px[5] = {0, 1, 1, 1, 0};
	static const double pz[5] = {-1, -1, 0, 1, 1};
	static const double pw[5] = {1, 0.70710678118654757, 1,
				     0.70710678118654757, 1};
	static const double kv[8] = {0, 0, 0, .5, .5, 1, 1, 1};
	int i, j;
	circle_data(1.0, cU, cxyz, cw);
	memcpy(Uu, cU, sizeof(cU));
	memcpy(Uv, kv, sizeof(kv));
	for (j = 0; j < 5; j++)
		for (i = 0; i < 9; i++) {
			int idx = j * 9 + i;
			xyz[3 * idx] = r * px[j] * cxyz[3 * i];
			xyz[3 * idx + 1] = r * px[j] * cxyz[3 * i + 1];
			xyz[3 * idx + 2] = r * pz[j];
			w[idx] = pw[j] * cw[i];
		}
}

static void test_rational_sphere(void)
{
	double Uu[12], Uv[8], xyz[3 * 45], w[45];
	struct px_arena a;
	struct px_nurbs_surf s;
	int i, j;
	px_arena_init(&a, arena_buf, sizeof(arena_buf));
	sphere_data(1.5, Uu, Uv, xyz, w);
	PX_CHECK_INT_EQ(px_nurbs_surf_init(&s, &a, 2, 2, 9, 5, Uu, 12, Uv, 8,
					   xyz, w, NULL),
			PX_OK);
	for (i = 0; i <= 40; i++)
		for (j = 0; j <= 40; j++) {
			struct px_nurbs_surf_derivs d;
			px_nurbs_surf_eval(&s, i / 40.0, j / 40.0, 2, &d);
			PX_CHECK_NEAR(px_v3_norm(d.s), 1.5, 1e-14);
			/* tangents perpendicular to the radius */
			PX_CHECK_NEAR(px_v3_dot(d.s, d.su), 0, 1e-11);
			PX_CHECK_NEAR(px_v3_dot(d.s, d.sv), 0, 1e-11);
			/* |S|^2 const: S.Suv + Su.Sv = 0 */
			PX_CHECK_NEAR(px_v3_dot(d.s, d.suv) +
					      px_v3_dot(d.su, d.sv),
				      0, 1e-9);
		}
	PX_CHECK(px_nurbs_surf_closed(&s, 0, 1e-12));
	PX_CHECK(!px_nurbs_surf_closed(&s, 1, 1e-12));
	PX_CHECK_INT_EQ(px_nurbs_surf_seam(&s, 0, 1e-12, 1e-9), 1);
	PX_CHECK_INT_EQ(px_nurbs_surf_seam(&s, 1, 1e-12, 1e-9), -1);
	PX_CHECK(px_nurbs_surf_edge_collapsed(&s, 2, 1e-12));
	PX_CHECK(px_nurbs_surf_edge_collapsed(&s, 3, 1e-12));
	PX_CHECK(!px_nurbs_surf_edge_collapsed(&s, 0, 1e-12));
	PX_CHECK(!px_nurbs_surf_edge_collapsed(&s, 1, 1e-12));
	/* at the pole Su vanishes: evaluation stays finite */
	{
		struct px_nurbs_surf_derivs d;
		px_nurbs_surf_eval(&s, 0.3, 0.0, 3, &d);
		PX_CHECK(px_v3_norm(d.su) < 1e-14);
		PX_CHECK(px_v3_isfinite(d.suuu) && px_v3_isfinite(d.svvv));
	}
	PX_CHECK_INT_EQ(px_nurbs_surf_breaks(&s, 0, NULL, 0), 3);
	PX_CHECK_INT_EQ(px_nurbs_surf_breaks(&s, 1, NULL, 0), 1);
}

/* A periodic tube: uniform cubic closed curve (control polygon wrapped
 * by 3 points) swept linearly along z. */
static void test_periodic_tube_seam(void)
{
	double K[14], V[4] = {0, 0, 1, 1}, P[3 * 20];
	struct px_arena a;
	struct px_nurbs_surf s;
	int i, j;
	px_arena_init(&a, arena_buf, sizeof(arena_buf));
	for (i = 0; i < 14; i++)
		K[i] = i;
	for (j = 0; j < 2; j++)
		for (i = 0; i < 10; i++) {
			double t = 2 * M_PI * (i % 7) / 7.0;
			double r = 1 + 0.3 * ((i % 7) % 2);
			P[3 * (j * 10 + i)] = r * cos(t);
			P[3 * (j * 10 + i) + 1] = r * sin(t);
			P[3 * (j * 10 + i) + 2] = 2.0 * j + 0.1 * (i % 7);
		}
	PX_CHECK_INT_EQ(px_nurbs_surf_init(&s, &a, 3, 1, 10, 2, K, 14, V, 4, P,
					   NULL, NULL),
			PX_OK);
	PX_CHECK_INT_EQ(px_nurbs_surf_seam(&s, 0, 1e-12, 1e-9), 2);
	PX_CHECK(px_nurbs_surf_closed(&s, 0, 1e-12));
	PX_CHECK_INT_EQ(px_nurbs_surf_seam(&s, 1, 1e-12, 1e-9), -1);
	/* open the tube at the top only: no longer closed */
	P[3 * 19 + 2] += 0.25;
	PX_CHECK_INT_EQ(px_nurbs_surf_init(&s, &a, 3, 1, 10, 2, K, 14, V, 4, P,
					   NULL, NULL),
			PX_OK);
	PX_CHECK_INT_EQ(px_nurbs_surf_seam(&s, 0, 1e-9, 1e-9), -1);
	PX_CHECK(!px_nurbs_surf_closed(&s, 0, 1e-9));
}

static void test_surf_validation(void)
{
	double Uu[] = {0, 0, 0, 1, 1, 1};
	double Uv[] = {0, 0, 0.5, 0.4, 1, 1};
	double xyz[3 * 12] = {0}, w[12];
	struct px_nurbs_error e;
	int rc, i;
	for (i = 0; i < 12; i++)
		w[i] = 1;
	rc = px_nurbs_surf_validate(2, 1, 3, 4, Uu, 6, Uv, 6, xyz, w, &e);
	check_err(rc, &e, PX_E_INVAL, PX_NURBS_FAULT_KNOT_ORDER, 3,
		  "v knot 3 decreases");
	PX_CHECK_INT_EQ(e.dir, 1);
	Uv[3] = 0.6;
	PX_CHECK_INT_EQ(px_nurbs_surf_validate(2, 1, 3, 4, Uu, 6, Uv, 6, xyz, w,
					       &e),
			PX_OK);
	w[7] = 0;
	rc = px_nurbs_surf_validate(2, 1, 3, 4, Uu, 6, Uv, 6, xyz, w, &e);
	check_err(rc, &e, PX_E_RANGE, PX_NURBS_FAULT_WEIGHT, 7, "weight");
	PX_CHECK_INT_EQ(e.index_i, 1);
	PX_CHECK_INT_EQ(e.index_j, 2);
	w[7] = 1;
	rc = px_nurbs_surf_validate(2, 1, 3, 4, Uu, 5, Uv, 6, xyz, w, &e);
	check_err(rc, &e, PX_E_INVAL, PX_NURBS_FAULT_KNOT_COUNT, -1, "u knot");
	PX_CHECK_INT_EQ(e.dir, 0);
	rc = px_nurbs_surf_validate(2, 12, 3, 4, Uu, 6, Uv, 6, xyz, w, &e);
	check_err(rc, &e, PX_E_RANGE, PX_NURBS_FAULT_DEGREE, -1, "v degree 12");
	xyz[3 * 11 + 2] = INFINITY;
	rc = px_nurbs_surf_validate(2, 1, 3, 4, Uu, 6, Uv, 6, xyz, w, &e);
	check_err(rc, &e, PX_E_NAN, PX_NURBS_FAULT_COORD_NAN, 11, "11");
	PX_CHECK_INT_EQ(e.index_i, 2);
	PX_CHECK_INT_EQ(e.index_j, 3);
}

static int in_box(px_aabb b, px_vec3 p, double slack)
{
	return p.x >= b.min.x - slack && p.x <= b.max.x + slack &&
	       p.y >= b.min.y - slack && p.y <= b.max.y + slack &&
	       p.z >= b.min.z - slack && p.z <= b.max.z + slack;
}

static void test_surf_insertion_and_extraction(void)
{
	int trial;
	for (trial = 0; trial < 120; trial++) {
		static struct tsurf t;
		struct px_arena a;
		struct px_nurbs_surf s, ins, sub, sub2;
		int pu = 1 + trial % 5, pv = 1 + (trial / 5) % 5, j, rc, dir;
		double lo[2], hi[2], dom[4], diag, x;
		px_aabb full, box;
		size_t len;
		px_arena_init(&a, arena_buf, sizeof(arena_buf));
		gen_surf(&t, pu, pv, trial % 3 != 0, trial % 4 != 0);
		make_surf(&a, &t, &s);
		px_nurbs_surf_domain(&s, &dom[0], &dom[1], &dom[2], &dom[3]);
		full = px_nurbs_surf_aabb(&s);
		diag = px_v3_dist(full.min, full.max);
		/* insertion in both directions */
		for (dir = 0; dir < 2; dir++) {
			int m;
			x = px_rand_range(dom[2 * dir], dom[2 * dir + 1]);
			m = 0;
			for (j = 0; j < t.nk[dir]; j++)
				m += t.U[dir][j] == x;
			rc = px_nurbs_surf_insert_knot(&s, dir, x, t.p[dir] - m,
						       &a, &ins);
			PX_CHECK_INT_EQ(rc, PX_OK);
			PX_CHECK_INT_EQ(ins.n_ctrl[dir],
					s.n_ctrl[dir] + t.p[dir] - m);
			PX_CHECK_INT_EQ(ins.n_ctrl[1 - dir], s.n_ctrl[1 - dir]);
			for (j = 0; j < 20; j++) {
				double u = px_rand_range(dom[0], dom[1]);
				double v = px_rand_range(dom[2], dom[3]);
				PX_CHECK(px_v3_dist(px_nurbs_surf_point(&s, u, v),
						    px_nurbs_surf_point(&ins, u, v)) <=
					 1e-12 * diag);
			}
		}
		for (dir = 0; dir < 2; dir++) {
			double p0 = px_rand_range(dom[2 * dir], dom[2 * dir + 1]);
			double p1 = px_rand_range(dom[2 * dir], dom[2 * dir + 1]);
			if (trial % 5 == dir)
				p0 = t.U[dir][px_rand_int(t.p[dir], t.n[dir] - 1)];
			if (trial % 7 == 0) {
				p0 = dom[2 * dir];
				p1 = dom[2 * dir + 1];
			}
			lo[dir] = fmin(p0, p1);
			hi[dir] = fmax(p0, p1);
		}
		if (!(lo[0] < hi[0] && lo[1] < hi[1]))
			continue;
		len = PX_NURBS_SURF_WORK_LEN(pu, pv, s.n_ctrl[0], s.n_ctrl[1]);
		PX_CHECK_INT_EQ(px_nurbs_surf_extract_work(&s, lo[0], hi[0], lo[1],
							   hi[1], work_buf,
							   len - 1, &sub),
				PX_E_NOSPC);
		rc = px_nurbs_surf_extract_work(&s, lo[0], hi[0], lo[1], hi[1],
						work_buf, len, &sub);
		PX_CHECK_INT_EQ(rc, PX_OK);
		PX_CHECK_INT_EQ(px_nurbs_surf_view(&sub2, pu, pv, sub.n_ctrl[0],
						   sub.n_ctrl[1], sub.knots[0],
						   sub.n_knots[0], sub.knots[1],
						   sub.n_knots[1], sub.pw, NULL),
				PX_OK);
		box = px_nurbs_surf_aabb(&sub);
		for (j = 0; j < 300; j++) {
			double u = lo[0] + (hi[0] - lo[0]) * (j % 17) / 16.0;
			double v = lo[1] + (hi[1] - lo[1]) * (j / 17) / 16.0;
			struct px_nurbs_surf_derivs d0, d1;
			if (j >= 17 * 17) {
				u = px_rand_range(lo[0], hi[0]);
				v = px_rand_range(lo[1], hi[1]);
			}
			px_nurbs_surf_eval_side(&s, u, v, u == hi[0] ? -1 : 1,
						v == hi[1] ? -1 : 1, 1, &d0);
			px_nurbs_surf_eval(&sub, u, v, 1, &d1);
			PX_CHECK_MSG(px_v3_dist(d0.s, d1.s) <= 1e-12 * diag,
				     "sub-patch differs at (%g,%g): %.3g", u, v,
				     px_v3_dist(d0.s, d1.s));
			PX_CHECK(px_v3_dist(d0.su, d1.su) <=
				 1e-7 * (px_v3_norm(d0.su) + diag / (hi[0] - lo[0])));
			PX_CHECK_MSG(in_box(box, d0.s, 1e-13 * diag),
				     "point outside sub-patch box");
		}
		{
			px_aabb b2;
			PX_CHECK_INT_EQ(px_nurbs_surf_sub_aabb(&s, lo[0], hi[0],
							       lo[1], hi[1],
							       work_buf, len, &b2),
					PX_OK);
			PX_CHECK(b2.min.y == box.min.y && b2.max.z == box.max.z);
		}
		{
			size_t before = px_arena_used(&a);
			rc = px_nurbs_surf_extract(&s, lo[0], hi[0], lo[1], hi[1],
						   &a, &sub2);
			PX_CHECK_INT_EQ(rc, PX_OK);
			PX_CHECK(px_arena_high_water(&a) - before <=
				 px_nurbs_surf_extract_bytes(&s));
			PX_CHECK_INT_EQ(sub2.n_ctrl[0], sub.n_ctrl[0]);
			PX_CHECK_INT_EQ(sub2.n_ctrl[1], sub.n_ctrl[1]);
			PX_CHECK(memcmp(sub2.pw, sub.pw,
					4 * sizeof(double) * sub.n_ctrl[0] *
						sub.n_ctrl[1]) == 0);
		}
	}
}

static void test_surf_iso_curves(void)
{
	int trial;
	for (trial = 0; trial < 100; trial++) {
		static struct tsurf t;
		static double pw[4 * MAXN];
		struct px_arena a;
		struct px_nurbs_surf s;
		struct px_nurbs_curve c;
		int dir, j;
		double dom[4], diag;
		px_aabb b;
		px_arena_init(&a, arena_buf, sizeof(arena_buf));
		gen_surf(&t, 1 + trial % 5, 1 + (trial / 5) % 4, trial % 3 != 0,
			 trial % 2);
		make_surf(&a, &t, &s);
		px_nurbs_surf_domain(&s, &dom[0], &dom[1], &dom[2], &dom[3]);
		b = px_nurbs_surf_aabb(&s);
		diag = px_v3_dist(b.min, b.max);
		for (dir = 0; dir < 2; dir++) {
			int o = 1 - dir;
			double x = px_rand_range(dom[2 * o], dom[2 * o + 1]);
			if (trial % 4 == 1)
				x = dom[2 * o + (trial & 1)]; /* a boundary */
			PX_CHECK_INT_EQ(px_nurbs_surf_iso_curve(&s, dir, x, pw,
								4 * s.n_ctrl[dir] - 1,
								&c),
					PX_E_NOSPC);
			PX_CHECK_INT_EQ(px_nurbs_surf_iso_curve(&s, dir, x, pw,
								sizeof(pw) / sizeof(pw[0]),
								&c),
					PX_OK);
			for (j = 0; j < 30; j++) {
				double y = px_rand_range(dom[2 * dir], dom[2 * dir + 1]);
				struct px_nurbs_surf_derivs d;
				px_vec3 cd[2];
				px_nurbs_surf_eval(&s, dir ? x : y, dir ? y : x, 1, &d);
				px_nurbs_curve_eval(&c, y, 1, cd);
				PX_CHECK(px_v3_dist(cd[0], d.s) <= 1e-12 * diag);
				PX_CHECK(px_v3_dist(cd[1], dir ? d.sv : d.su) <=
					 1e-9 * (diag + px_v3_norm(cd[1])));
			}
		}
	}
}

/* Decomposition-style use: a grid of sub-patches whose boxes cover every
 * sampled point of the patch. */
static void test_sub_patch_boxes_cover_sphere(void)
{
	double Uu[12], Uv[8], xyz[3 * 45], w[45];
	struct px_arena a;
	struct px_nurbs_surf s;
	int i, j, k;
	px_arena_init(&a, arena_buf, sizeof(arena_buf));
	sphere_data(1.0, Uu, Uv, xyz, w);
	PX_CHECK_INT_EQ(px_nurbs_surf_init(&s, &a, 2, 2, 9, 5, Uu, 12, Uv, 8,
					   xyz, w, NULL),
			PX_OK);
	for (i = 0; i < 7; i++)
		for (j = 0; j < 5; j++) {
			double u0 = i / 7.0, u1 = (i + 1) / 7.0;
			double v0 = j / 5.0, v1 = (j + 1) / 5.0;
			px_aabb b;
			PX_CHECK_INT_EQ(px_nurbs_surf_sub_aabb(
						&s, u0, u1, v0, v1, work_buf,
						sizeof(work_buf) / sizeof(double), &b),
					PX_OK);
			for (k = 0; k < 100; k++) {
				double u = u0 + (u1 - u0) * px_rand_unit();
				double v = v0 + (v1 - v0) * px_rand_unit();
				PX_CHECK(in_box(b, px_nurbs_surf_point(&s, u, v),
						1e-14));
			}
			/* and the box is much tighter than the whole sphere */
			PX_CHECK(b.max.x - b.min.x < 1.5);
		}
}

static void test_evaluation_allocates_nothing(void)
{
	static struct tsurf ts;
	struct px_arena a, scratch;
	struct tcurve t;
	struct px_nurbs_curve c, cs;
	struct px_nurbs_surf s, ss;
	static unsigned char sbuf[1 << 16];
	uint64_t r;
	int i;
	px_arena_init(&a, arena_buf, sizeof(arena_buf));
	gen_curve(&t, 9, 1, 1);
	make_curve(&a, &t, &c);
	gen_surf(&ts, 3, 3, 0, 1);
	make_surf(&a, &ts, &s);
	r = px_alloc_region_begin();
	for (i = 0; i < 1000; i++) {
		px_vec3 d[4];
		struct px_nurbs_surf_derivs sd;
		px_aabb b;
		double u = px_rand_range(-0.5, 10.0), v = px_rand_range(-1, 10);
		double u0, u1, v0, v1;
		px_nurbs_curve_eval(&c, u, 3, d);
		px_nurbs_curve_eval_side(&c, u, -1, 2, d);
		(void)px_nurbs_curve_point(&c, u);
		px_nurbs_surf_eval(&s, u, v, 3, &sd);
		(void)px_nurbs_surf_point(&s, u, v);
		px_nurbs_curve_domain(&c, &u0, &u1);
		px_nurbs_curve_sub_aabb(&c, u0, 0.5 * (u0 + u1), work_buf,
					sizeof(work_buf) / sizeof(double), &b);
		px_nurbs_surf_domain(&s, &u0, &u1, &v0, &v1);
		px_nurbs_surf_sub_aabb(&s, u0, 0.5 * (u0 + u1), v0, v1, work_buf,
				       sizeof(work_buf) / sizeof(double), &b);
		px_arena_init(&scratch, sbuf, sizeof(sbuf));
		px_nurbs_curve_insert_knot(&c, 0.5 * (u0 + u1), 1, &scratch, &cs);
		px_nurbs_curve_extract(&c, t.U[9], t.U[t.n], &scratch, &cs);
		px_nurbs_surf_extract(&s, u0, u1, v0, 0.5 * (v0 + v1), &scratch,
				      &ss);
		(void)px_nurbs_curve_aabb(&c);
		(void)px_nurbs_surf_aabb(&s);
		px_nurbs_surf_iso_curve(&s, i & 1, v, work_buf,
					sizeof(work_buf) / sizeof(double), &cs);
		(void)px_nurbs_curve_point(&cs, u);
		(void)px_nurbs_curve_seam(&c, 1e-9, 1e-9);
		(void)px_nurbs_curve_breaks(&c, NULL, 0);
		(void)px_nurbs_curve_find_span(&c, u, -1);
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(r), 0);
}

static const struct px_test tests[] = {
	PX_T(test_basis_vs_cox_de_boor),
	PX_T(test_find_span_edges),
	PX_T(test_curve_eval_vs_reference),
	PX_T(test_curve_bad_eval_args),
	PX_T(test_nurbs_circle),
	PX_T(test_curve_breaks_and_seams),
	PX_T(test_curve_validation),
	PX_T(test_curve_knot_insertion),
	PX_T(test_curve_extraction_and_boxes),
	PX_T(test_surf_eval_vs_reference),
	PX_T(test_rational_sphere),
	PX_T(test_periodic_tube_seam),
	PX_T(test_surf_validation),
	PX_T(test_surf_insertion_and_extraction),
	PX_T(test_surf_iso_curves),
	PX_T(test_sub_patch_boxes_cover_sphere),
	PX_T(test_evaluation_allocates_nothing),
};

PX_TEST_MAIN(tests)
