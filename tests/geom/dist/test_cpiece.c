/* Certified closest point on rational Bezier pieces vs brute force. */
#include <math.h>
#include <stdio.h>

#include "px_alloc_count.h"
#include "px_bern.h"
#include "px_cpiece.h"
#include "px_test.h"

/* ---- Bernstein toolkit against the power basis -------------------------- */

static double power_eval_bern(const double *c, int n, double t)
{
	/* Direct sum of c_i C(n,i) t^i (1-t)^(n-i), independent of de
	 * Casteljau. */
	double s = 0.0;
	int i;
	for (i = 0; i <= n; i++)
		s += c[i] * px_bern_binom(n, i) * pow(t, i) * pow(1.0 - t, n - i);
	return s;
}

static void test_bern_eval_split_mul(void)
{
	double a[PX_BERN_MAX_DEGREE + 1], b[PX_BERN_MAX_DEGREE + 1];
	double l[PX_BERN_MAX_DEGREE + 1], r[PX_BERN_MAX_DEGREE + 1];
	double m[PX_BERN_MAX_DEGREE + 1], d[PX_BERN_MAX_DEGREE + 1];
	double e[PX_BERN_MAX_DEGREE + 2];
	int trial, i;

	PX_CHECK(px_bern_binom(32, 16) == 601080390.0);
	PX_CHECK(px_bern_binom(5, 6) == 0.0);
	for (trial = 0; trial < 500; trial++) {
		int na = px_rand_int(0, 12), nb = px_rand_int(0, 12);
		double t = px_rand_unit(), x = px_rand_unit(), dv, h = 1e-6;
		for (i = 0; i <= na; i++)
			a[i] = px_rand_range(-2, 2);
		for (i = 0; i <= nb; i++)
			b[i] = px_rand_range(-2, 2);
		PX_CHECK_CLOSE(px_bern_eval(a, na, x), power_eval_bern(a, na, x),
			       1e-12, 0);
		/* Split: left piece at x/t equals the whole at x (x < t). */
		px_bern_split(a, na, t, l, r);
		PX_CHECK_CLOSE(px_bern_eval(l, na, x), px_bern_eval(a, na, x * t),
			       1e-12, 0);
		PX_CHECK_CLOSE(px_bern_eval(r, na, x),
			       px_bern_eval(a, na, t + x * (1 - t)), 1e-12, 0);
		/* Restrict to [lo, hi]. */
		{
			double lo = px_rand_range(0, 0.5), hi = px_rand_range(0.6, 1);
			px_bern_restrict(a, na, lo, hi, m);
			PX_CHECK_CLOSE(px_bern_eval(m, na, x),
				       px_bern_eval(a, na, lo + x * (hi - lo)),
				       1e-11, 0);
		}
		/* Product. */
		PX_CHECK_INT_EQ(px_bern_mul(a, na, b, nb, m), PX_OK);
		PX_CHECK_CLOSE(px_bern_eval(m, na + nb, x),
			       px_bern_eval(a, na, x) * px_bern_eval(b, nb, x),
			       1e-11, 0);
		/* Derivative against a central difference. */
		px_bern_deriv(a, na, d);
		PX_CHECK_CLOSE(px_bern_eval(d, na > 0 ? na - 1 : 0, x),
			       (px_bern_eval(a, na, x + h) -
				px_bern_eval(a, na, x - h)) / (2 * h),
			       1e-6, 0);
		PX_CHECK_CLOSE(px_bern_eval_d(a, na, x, &dv),
			       px_bern_eval(a, na, x), 1e-12, 0);
		PX_CHECK_CLOSE(dv, px_bern_eval(d, na > 0 ? na - 1 : 0, x), 1e-10,
			       0);
		/* Elevation keeps the polynomial. */
		px_bern_elevate(a, na, e);
		PX_CHECK_CLOSE(px_bern_eval(e, na + 1, x), px_bern_eval(a, na, x),
			       1e-12, 0);
	}
	PX_CHECK_INT_EQ(px_bern_mul(a, 20, b, 20, m), PX_E_RANGE);
}

static void test_bern_sign_changes_bound_roots(void)
{
	/* Polynomials with known roots r_k in (0,1): the count is never
	 * below the number of roots, and has the same parity. */
	int trial;
	for (trial = 0; trial < 300; trial++) {
		double c[PX_BERN_MAX_DEGREE + 1] = {1.0}, f[2], tmp[PX_BERN_MAX_DEGREE + 1];
		int n = 0, k, roots = px_rand_int(0, 5), i;
		for (k = 0; k < roots; k++) {
			double r = px_rand_range(0.01, 0.99);
			/* factor (t - r) in Bernstein degree 1: [-r, 1 - r] */
			f[0] = -r;
			f[1] = 1 - r;
			px_bern_mul(c, n, f, 1, tmp);
			n++;
			for (i = 0; i <= n; i++)
				c[i] = tmp[i];
		}
		/* Multiply by a positive factor to hide the roots a little. */
		f[0] = px_rand_range(0.1, 2);
		f[1] = px_rand_range(0.1, 2);
		px_bern_mul(c, n, f, 1, tmp);
		n++;
		k = px_bern_sign_changes(tmp, n, 0.0);
		PX_CHECK_MSG(k >= roots && (k - roots) % 2 == 0,
			     "%d roots, %d sign changes", roots, k);
	}
}

/* ---- curve pieces ---------------------------------------------------------- */

static px_vec3 eval_ref(const double (*hw)[4], int p, double t)
{
	/* Rational Bezier by the explicit Bernstein sum. */
	double s[4] = {0, 0, 0, 0};
	int i, c;
	for (i = 0; i <= p; i++) {
		double b = px_bern_binom(p, i) * pow(t, i) * pow(1 - t, p - i);
		for (c = 0; c < 4; c++)
			s[c] += b * hw[i][c];
	}
	return px_v3(s[0] / s[3], s[1] / s[3], s[2] / s[3]);
}

/* Dense sampling, then golden-section polish of every sampled local
 * minimum: an oracle that shares no code with the piece solver. */
static double brute_d2(const double (*hw)[4], int p, px_vec3 q, double *t_best)
{
	enum { N = 6000 };
	static double d2s[N + 1];
	double best = INFINITY;
	int i;

	for (i = 0; i <= N; i++)
		d2s[i] = px_v3_dist2(eval_ref(hw, p, (double)i / N), q);
	for (i = 0; i <= N; i++) {
		double lo, hi;
		int k;
		if ((i > 0 && d2s[i - 1] < d2s[i]) || (i < N && d2s[i + 1] < d2s[i]))
			continue;
		lo = (i > 0 ? i - 1 : 0) / (double)N;
		hi = (i < N ? i + 1 : N) / (double)N;
		for (k = 0; k < 100; k++) {
			double a = hi - (hi - lo) * 0.6180339887498949;
			double b = lo + (hi - lo) * 0.6180339887498949;
			if (px_v3_dist2(eval_ref(hw, p, a), q) <
			    px_v3_dist2(eval_ref(hw, p, b), q))
				hi = b;
			else
				lo = a;
		}
		{
			double t = 0.5 * (lo + hi);
			double d2 = px_v3_dist2(eval_ref(hw, p, t), q);
			if (d2 < best) {
				best = d2;
				*t_best = t;
			}
		}
	}
	return best;
}

static void random_piece(double (*hw)[4], int p, int planar)
{
	int i;
	for (i = 0; i <= p; i++) {
		double w = exp(px_rand_range(log(0.2), log(5.0)));
		hw[i][0] = px_rand_range(-1, 1) * w;
		hw[i][1] = px_rand_range(-1, 1) * w;
		hw[i][2] = planar ? 0.0 : px_rand_range(-1, 1) * w;
		hw[i][3] = w;
	}
}

static void check_against_brute(const double (*hw)[4], int p, px_vec3 q,
				int *uncertified)
{
	struct px_cpiece pc;
	struct px_cpiece_hit hit;
	double best = INFINITY, tref = 0, ref, diag;
	px_vec3 on;

	PX_CHECK_INT_EQ(px_cpiece_init(&pc, p, hw, 2.0, 5.0), PX_OK);
	PX_CHECK_INT_EQ(px_cpiece_closest(&pc, q, &best, &hit), 1);
	ref = brute_d2(hw, p, q, &tref);
	{
		px_aabb b = px_cpiece_box(&pc);
		diag = px_aabb_diagonal(&b);
	}
	/* Never farther than the oracle (a missed global minimum)... */
	PX_CHECK_MSG(sqrt(hit.d2) <= sqrt(ref) + 1e-9 * diag,
		     "wrong branch: got %.17g (u=%.17g), oracle %.17g (t=%.17g) "
		     "degree %d",
		     sqrt(hit.d2), hit.u, sqrt(ref), tref, p);
	/* ...and the answer is a real point of the curve at its parameter. */
	on = eval_ref(hw, p, (hit.u - 2.0) / 3.0);
	PX_CHECK_CLOSE(px_v3_dist(on, hit.point), 0.0, 1e-12 * (1 + diag), 0);
	PX_CHECK_CLOSE(sqrt(hit.d2), px_v3_dist(hit.point, q), 1e-12, 1e-12);
	PX_CHECK(sqrt(hit.d2) >= sqrt(ref) - 1e-9 * diag - 1e-12);
	if (!hit.certified) {
		(*uncertified)++;
		PX_CHECK(hit.gap >= 0.0 && hit.gap < 1e-9 * diag);
	}
}

static void test_piece_random_vs_brute(void)
{
	double hw[PX_CPIECE_MAX_DEGREE + 1][4];
	int trial, uncertified = 0;

	for (trial = 0; trial < 400; trial++) {
		int p = px_rand_int(1, PX_CPIECE_MAX_DEGREE);
		px_vec3 q;
		random_piece(hw, p, trial % 3 == 0);
		switch (trial % 4) {
		case 0: /* near */
			q = px_v3(px_rand_range(-1.5, 1.5), px_rand_range(-1.5, 1.5),
				  px_rand_range(-1.5, 1.5));
			break;
		case 1: /* far: 100 times the model size */
			q = px_v3_scale(px_v3(px_rand_normal(), px_rand_normal(),
					      px_rand_normal()),
					100.0);
			break;
		case 2: /* exactly on the curve */
			q = eval_ref((const double(*)[4])hw, p, px_rand_unit());
			break;
		default: /* slightly off a point of the curve */
			q = px_v3_add(eval_ref((const double(*)[4])hw, p,
					       px_rand_unit()),
				      px_v3(1e-3 * px_rand_normal(),
					    1e-3 * px_rand_normal(),
					    1e-3 * px_rand_normal()));
		}
		check_against_brute((const double(*)[4])hw, p, q, &uncertified);
	}
	printf("    uncertified answers: %d of 400\n", uncertified);
}

static void test_piece_cusp_and_circle(void)
{
	/* Cubic with a cusp at t = 1/2. */
	static const double cusp[4][4] = {
		{0, 0, 0, 1}, {1, 1, 0, 1}, {0, 1, 0, 1}, {1, 0, 0, 1}};
	/* Quarter circle, radius 2, centre origin: rational quadratic. */
	const double w = sqrt(0.5);
	const double arc[3][4] = {{2, 0, 0, 1}, {2 * w, 2 * w, 0, w}, {0, 2, 0, 1}};
	struct px_cpiece pc;
	struct px_cpiece_hit hit;
	double best;
	int i, unc = 0;

	for (i = 0; i < 200; i++) {
		px_vec3 q = px_v3(px_rand_range(0.3, 0.7), px_rand_range(0.5, 1.0),
				  px_rand_range(-0.2, 0.2));
		check_against_brute(cusp, 3, q, &unc);
	}
	PX_CHECK_INT_EQ(px_cpiece_init(&pc, 2, arc, 0, 1), PX_OK);
	/* Centre: every point is a minimum at exactly the radius. */
	best = INFINITY;
	px_cpiece_closest(&pc, px_v3(0, 0, 0), &best, &hit);
	PX_CHECK_CLOSE(sqrt(best), 2.0, 1e-12, 0);
	/* The coefficient lower bound settles it without subdividing. */
	PX_CHECK_MSG(hit.nodes <= 3 && hit.certified, "nodes %d", hit.nodes);
	/* On the evolute off-plane: still equidistant. */
	best = INFINITY;
	px_cpiece_closest(&pc, px_v3(0, 0, 1.5), &best, &hit);
	PX_CHECK_CLOSE(sqrt(best), 2.5, 1e-12, 0);
	/* Outside along the bisector: foot at the arc's middle. */
	best = INFINITY;
	px_cpiece_closest(&pc, px_v3(3, 3, 0), &best, &hit);
	PX_CHECK_CLOSE(sqrt(best), 3 * sqrt(2.0) - 2.0, 1e-12, 0);
	PX_CHECK_CLOSE(hit.point.x, sqrt(2.0), 1e-12, 0);
	for (i = 0; i < 200; i++) {
		px_vec3 q = px_v3(px_rand_range(-3, 3), px_rand_range(-3, 3),
				  px_rand_range(-1, 1));
		double r = hypot(q.x, q.y), ang = atan2(q.y, q.x), expect;
		best = INFINITY;
		px_cpiece_closest(&pc, q, &best, &hit);
		if (ang >= 0 && ang <= M_PI / 2)
			expect = hypot(r - 2.0, q.z);
		else
			expect = sqrt(fmin(px_v3_dist2(q, px_v3(2, 0, 0)),
					   px_v3_dist2(q, px_v3(0, 2, 0))));
		PX_CHECK_CLOSE(sqrt(best), expect, 1e-12, 1e-12);
	}
	PX_CHECK_INT_EQ(unc, 0);
}

/* Curves symmetric about t = 1/2 queried on their symmetry plane: the
 * root of g lies exactly on the first split point. */
static void test_piece_symmetric_split_point(void)
{
	double hw[6][4];
	int trial, p, i, unc = 0;
	for (trial = 0; trial < 300; trial++) {
		p = px_rand_int(2, 5);
		for (i = 0; i <= p; i++) {
			int k = i <= p - i ? i : p - i;
			double w = 1.0 + 0.3 * k;
			hw[i][0] = (double)i / p * w;
			hw[i][1] = (k == 0 ? 0.0 : (trial % 2 ? 1.0 : -1.0) * (0.3 + 0.2 * k)) * w;
			hw[i][2] = 0.0;
			hw[i][3] = trial % 3 ? w : 1.0;
		}
		check_against_brute((const double(*)[4])hw, p,
				    px_v3(0.5, px_rand_range(-2, 2), px_rand_range(-0.5, 0.5)),
				    &unc);
	}
}

static void test_piece_bound_respected(void)
{
	double hw[4][4];
	struct px_cpiece pc;
	struct px_cpiece_hit hit;
	double best = 1e-30;
	random_piece(hw, 3, 0);
	PX_CHECK_INT_EQ(px_cpiece_init(&pc, 3, (const double(*)[4])hw, 0, 1),
			PX_OK);
	/* An upper bound below anything on the piece: no hit, bound kept. */
	PX_CHECK_INT_EQ(px_cpiece_closest(&pc, px_v3(10, 10, 10), &best, &hit),
			0);
	PX_CHECK(best == 1e-30);
}

static void test_piece_bad_input(void)
{
	struct px_cpiece pc;
	double hw[3][4] = {{0, 0, 0, 1}, {1, 1, 0, 1}, {2, 0, 0, 1}};
	PX_CHECK_INT_EQ(px_cpiece_init(&pc, 0, (const double(*)[4])hw, 0, 1),
			PX_E_RANGE);
	PX_CHECK_INT_EQ(px_cpiece_init(&pc, 2, (const double(*)[4])hw, 1, 1),
			PX_E_INVAL);
	hw[1][3] = 0.0;
	PX_CHECK_INT_EQ(px_cpiece_init(&pc, 2, (const double(*)[4])hw, 0, 1),
			PX_E_INVAL);
	hw[1][3] = 1.0;
	hw[2][1] = NAN;
	PX_CHECK_INT_EQ(px_cpiece_init(&pc, 2, (const double(*)[4])hw, 0, 1),
			PX_E_NAN);
}

static void test_piece_query_allocates_nothing(void)
{
	double hw[8][4];
	struct px_cpiece pc;
	struct px_cpiece_hit hit;
	uint64_t r;
	int i;
	random_piece(hw, 7, 0);
	PX_CHECK_INT_EQ(px_cpiece_init(&pc, 7, (const double(*)[4])hw, 0, 1),
			PX_OK);
	r = px_alloc_region_begin();
	for (i = 0; i < 2000; i++) {
		double best = INFINITY;
		px_cpiece_closest(&pc, px_v3(px_rand_normal(), px_rand_normal(),
					     px_rand_normal()),
				  &best, &hit);
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(r), 0);
}

static const struct px_test tests[] = {
	PX_T(test_bern_eval_split_mul),
	PX_T(test_bern_sign_changes_bound_roots),
	PX_T(test_piece_random_vs_brute),
	PX_T(test_piece_cusp_and_circle),
	PX_T(test_piece_symmetric_split_point),
	PX_T(test_piece_bound_respected),
	PX_T(test_piece_bad_input),
	PX_T(test_piece_query_allocates_nothing),
};

PX_TEST_MAIN(tests)
