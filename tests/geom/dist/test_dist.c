/* Global point-to-NURBS-curve distance against a brute-force oracle. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "px_alloc_count.h"
#include "px_arena.h"
#include "px_dist.h"
#include "px_nurbs.h"
#include "px_recog.h"
#include "px_test.h"

#define MAXC 40

struct curve_buf {
	double knots[MAXC + 12];
	double xyz[3 * MAXC];
	double w[MAXC];
	int degree, n;
};

static struct px_arena arena;
static unsigned char arena_mem[1 << 22];

static void arena_reset(void)
{
	px_arena_init(&arena, arena_mem, sizeof(arena_mem));
}

static void random_points(struct curve_buf *b, int rational, int planar)
{
	int i;
	for (i = 0; i < b->n; i++) {
		b->xyz[3 * i] = px_rand_range(-1, 1);
		b->xyz[3 * i + 1] = px_rand_range(-1, 1);
		b->xyz[3 * i + 2] = planar ? 0.0 : px_rand_range(-1, 1);
		b->w[i] = rational ? exp(px_rand_range(log(0.2), log(5.0))) : 1.0;
	}
}

/* Clamped knots with random interior values, optionally clustered or
 * with a C0 break (multiplicity = degree). */
static void clamped_knots(struct curve_buf *b, int style)
{
	int p = b->degree, n = b->n, m = n + p + 1, i, nin = n - p - 1;
	for (i = 0; i <= p; i++) {
		b->knots[i] = 0.0;
		b->knots[m - 1 - i] = 1.0;
	}
	for (i = 0; i < nin; i++) {
		double t = (i + 1.0) / (nin + 1.0);
		if (style == 1) /* clustered near the ends */
			t = i < nin / 2 ? 0.01 * (i + 1) : 1.0 - 0.01 * (nin - i);
		else if (style == 2)
			t = px_rand_unit();
		b->knots[p + 1 + i] = t;
	}
	/* sort interior */
	for (i = p + 1; i < m - p - 1; i++) {
		int j = i;
		while (j > p + 1 && b->knots[j - 1] > b->knots[j]) {
			double t = b->knots[j];
			b->knots[j] = b->knots[j - 1];
			b->knots[j - 1] = t;
			j--;
		}
	}
	if (style == 3 && nin >= p) { /* C0 corner in the middle */
		for (i = 0; i < p; i++)
			b->knots[p + 1 + i] = 0.5;
		for (i = p; i < nin; i++)
			b->knots[p + 1 + i] = 0.5 + 0.4 * (i - p + 1) / (nin - p + 1);
	}
}

static int make_curve(struct px_nurbs_curve *c, struct curve_buf *b)
{
	struct px_nurbs_error err;
	int rc = px_nurbs_curve_init(c, &arena, b->degree, b->n, b->knots,
				     b->n + b->degree + 1, b->xyz, b->w, &err);
	if (rc)
		printf("    curve rejected: %s\n", err.msg);
	return rc;
}

/* Periodic: uniform knots, first p points repeated at the end. */
static void periodic_curve(struct curve_buf *b, int p, int n_unique, int rational)
{
	int i;
	b->degree = p;
	b->n = n_unique + p;
	random_points(b, rational, 0);
	for (i = 0; i < p; i++) {
		memcpy(&b->xyz[3 * (n_unique + i)], &b->xyz[3 * i], 3 * sizeof(double));
		b->w[n_unique + i] = b->w[i];
	}
	for (i = 0; i < b->n + p + 1; i++)
		b->knots[i] = i;
}

/* Oracle: dense sampling of every knot span on its own (a span is
 * smooth, so a bracket of three samples around a sampled minimum holds a
 * local minimum), golden-section polish of each, span ends included. */
static double oracle(const struct px_nurbs_curve *const *cs, int nc, px_vec3 q)
{
	double best = INFINITY;
	int e, k;
	for (e = 0; e < nc; e++) {
		const struct px_nurbs_curve *c = cs[e];
		enum { N = 400 };
		double d2[N + 1], a, b;
		px_nurbs_curve_domain(c, &a, &b);
		for (k = c->degree; k < c->n_ctrl; k++) {
			double s0 = fmax(a, c->knots[k]), s1 = fmin(b, c->knots[k + 1]);
			int i, it;
			if (!(s1 > s0))
				continue;
			for (i = 0; i <= N; i++) {
				double u = s0 + (s1 - s0) * i / N;
				/* Left limit at the span end: C0 corners. */
				px_vec3 pt;
				px_nurbs_curve_eval_side(c, u, i == N ? -1 : 1, 0, &pt);
				d2[i] = px_v3_dist2(pt, q);
				best = fmin(best, d2[i]);
			}
			for (i = 0; i <= N; i++) {
				double lo, hi;
				if ((i > 0 && d2[i - 1] < d2[i]) ||
				    (i < N && d2[i + 1] < d2[i]))
					continue;
				lo = s0 + (s1 - s0) * (i > 0 ? i - 1 : 0) / N;
				hi = s0 + (s1 - s0) * (i < N ? i + 1 : N) / N;
				for (it = 0; it < 90; it++) {
					double x1 = hi - (hi - lo) * 0.6180339887498949;
					double x2 = lo + (hi - lo) * 0.6180339887498949;
					if (px_v3_dist2(px_nurbs_curve_point(c, x1), q) <
					    px_v3_dist2(px_nurbs_curve_point(c, x2), q))
						hi = x2;
					else
						lo = x1;
				}
				best = fmin(best, px_v3_dist2(px_nurbs_curve_point(c, 0.5 * (lo + hi)), q));
			}
		}
	}
	return sqrt(best);
}

struct tally {
	int queries, uncertified;
	double worst_rel;
};

static void check_query(struct px_dist_model *m, const struct px_nurbs_curve *const *cs,
			int nc, px_vec3 q, double diag, struct tally *t)
{
	struct px_dist_result r;
	double ref = oracle(cs, nc, q), tol = 1e-9 * diag;
	px_vec3 on;

	PX_CHECK_INT_EQ(px_dist_query(m, q, &r), PX_OK);
	t->queries++;
	PX_CHECK_MSG(r.dist <= ref + tol,
		     "wrong branch: %.17g vs oracle %.17g at (%.17g, %.17g, %.17g)",
		     r.dist, ref, q.x, q.y, q.z);
	PX_CHECK_MSG(r.dist >= ref - tol - 1e-9 * ref,
		     "below the oracle: %.17g vs %.17g", r.dist, ref);
	/* The reported point is the curve point at the reported parameter
	 * of the reported entity, and dist/dir agree with it. */
	PX_CHECK(r.entity >= 0 && r.entity < nc);
	on = px_nurbs_curve_point(cs[r.entity], r.u);
	PX_CHECK_MSG(px_v3_dist(on, r.point) <= 1e-10 * (1 + diag),
		     "point %.3g off its parameter", px_v3_dist(on, r.point));
	PX_CHECK_CLOSE(r.dist, px_v3_dist(q, r.point), 1e-12, 1e-12);
	if (r.dist > 1e-12)
		PX_CHECK_CLOSE(px_v3_norm(r.dir), 1.0, 1e-12, 0);
	if (!r.certified)
		t->uncertified++;
	if (ref > 0)
		t->worst_rel = fmax(t->worst_rel, (r.dist - ref) / diag);
}

static px_vec3 query_point(const struct px_nurbs_curve *c, px_aabb box, int kind)
{
	px_vec3 ctr = px_aabb_center(&box);
	double diag = px_aabb_diagonal(&box), a, b;
	px_nurbs_curve_domain(c, &a, &b);
	switch (kind % 5) {
	case 0: /* near, in the enlarged box */
		return px_v3(px_rand_range(box.min.x - 0.3 * diag, box.max.x + 0.3 * diag),
			     px_rand_range(box.min.y - 0.3 * diag, box.max.y + 0.3 * diag),
			     px_rand_range(box.min.z - 0.3 * diag, box.max.z + 0.3 * diag));
	case 1: /* far: 100 times the model size */
		return px_v3_add(ctr, px_v3_scale(px_v3(px_rand_normal(), px_rand_normal(),
							px_rand_normal()),
						  100 * diag));
	case 2: /* on the curve */
		return px_nurbs_curve_point(c, px_rand_range(a, b));
	case 3: /* at a knot value */
	{
		int k = px_rand_int(c->degree, c->n_ctrl);
		px_vec3 on = px_nurbs_curve_point(c, c->knots[k]);
		return px_v3_add(on, px_v3(0.01 * px_rand_normal(), 0.01 * px_rand_normal(),
					   0.01 * px_rand_normal()));
	}
	default: /* beyond the open ends */
	{
		px_vec3 d[2];
		int end = px_rand_int(0, 1);
		px_nurbs_curve_eval(c, end ? b : a, 1, d);
		return px_v3_madd(d[0], d[1], (end ? 1 : -1) * px_rand_range(0.01, 0.5) /
					       (px_v3_norm(d[1]) + 1e-300));
	}
	}
}

static void run_random_family(int periodic, struct tally *t)
{
	int trial;
	for (trial = 0; trial < 60; trial++) {
		struct curve_buf b;
		struct px_nurbs_curve c;
		const struct px_nurbs_curve *cs[1] = {&c};
		struct px_dist_model *m = NULL;
		struct px_dist_info info;
		double diag;
		int i;

		arena_reset();
		if (periodic) {
			periodic_curve(&b, px_rand_int(2, 5), px_rand_int(4, 9), trial % 2);
		} else {
			b.degree = px_rand_int(1, 5);
			b.n = b.degree + 1 + px_rand_int(0, 8);
			random_points(&b, trial % 2, trial % 3 == 0);
			clamped_knots(&b, trial % 4);
		}
		PX_CHECK_INT_EQ(make_curve(&c, &b), PX_OK);
		PX_CHECK_INT_EQ(px_dist_model_create(&c, 1, NULL, 0, NULL, &m), PX_OK);
		px_dist_model_info(m, &info);
		diag = px_aabb_diagonal(&info.bounds);
		for (i = 0; i < 25; i++)
			check_query(m, cs, 1, query_point(&c, info.bounds, i), diag, t);
		px_dist_model_free(m);
	}
}

static void test_random_clamped_curves(void)
{
	struct tally t = {0, 0, 0};
	run_random_family(0, &t);
	printf("    %d queries, %d uncertified, worst excess %.3g of diag\n",
	       t.queries, t.uncertified, t.worst_rel);
}

static void test_random_periodic_curves(void)
{
	struct tally t = {0, 0, 0};
	run_random_family(1, &t);
	printf("    %d queries, %d uncertified, worst excess %.3g of diag\n",
	       t.queries, t.uncertified, t.worst_rel);
}

static void test_nurbs_circle_and_evolute(void)
{
	/* Full circle, radius 3 in the plane z = 1: 9 points, degree 2. */
	const double s = sqrt(0.5);
	struct curve_buf b = {
		{0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1},
		{3, 0, 1, 3, 3, 1, 0, 3, 1, -3, 3, 1, -3, 0, 1, -3, -3, 1, 0, -3, 1, 3, -3, 1, 3, 0, 1},
		{1, s, 1, s, 1, s, 1, s, 1},
		2, 9};
	struct px_nurbs_curve c;
	struct px_dist_model *m;
	struct px_dist_result r;
	struct px_dist_entity_info ei;
	int i;

	arena_reset();
	PX_CHECK_INT_EQ(make_curve(&c, &b), PX_OK);
	PX_CHECK_INT_EQ(px_dist_model_create(&c, 1, NULL, 0, NULL, &m), PX_OK);
	PX_CHECK_INT_EQ(px_dist_entity_info(m, 0, &ei), PX_OK);
	PX_CHECK(ei.closed);
	/* Knowledge step: answered in closed form. */
	PX_CHECK_INT_EQ(ei.shape, PX_RECOG_ARC);
	PX_CHECK(ei.hausdorff < 1e-12);
	/* The centre and the axis are the evolute of a circle: every
	 * point is a foot point, all at the same distance. */
	PX_CHECK_INT_EQ(px_dist_query(m, px_v3(0, 0, 1), &r), PX_OK);
	PX_CHECK_CLOSE(r.dist, 3.0, 1e-12, 1e-12);
	PX_CHECK(r.certified);
	PX_CHECK_INT_EQ(px_dist_query(m, px_v3(0, 0, 5), &r), PX_OK);
	PX_CHECK_CLOSE(r.dist, 5.0, 1e-12, 1e-12);
	for (i = 0; i < 500; i++) {
		px_vec3 q = px_v3(px_rand_range(-8, 8), px_rand_range(-8, 8),
				  px_rand_range(-3, 5));
		double expect = hypot(hypot(q.x, q.y) - 3.0, q.z - 1.0);
		PX_CHECK_INT_EQ(px_dist_query(m, q, &r), PX_OK);
		PX_CHECK_CLOSE(r.dist, expect, 1e-12, 1e-12);
		PX_CHECK_CLOSE(hypot(r.point.x, r.point.y), 3.0, 1e-12, 0);
	}
	/* Seam: points near parameter 0 = 1 from both sides. */
	for (i = 0; i < 100; i++) {
		double ang = px_rand_range(-0.01, 0.01), rad = px_rand_range(0, 6);
		px_vec3 q = px_v3(rad * cos(ang), rad * sin(ang), 1.0);
		PX_CHECK_INT_EQ(px_dist_query(m, q, &r), PX_OK);
		PX_CHECK_CLOSE(r.dist, fabs(rad - 3.0), 1e-12, 1e-12);
	}
	px_dist_model_free(m);
}

static void test_cusp_curve(void)
{
	/* Cubic Bezier with a cusp at u = 1/2 (a planar closed loop's
	 * limiting case) plus a linear tail: the cusp must be found and the
	 * answers must stay right around it. */
	struct curve_buf b = {
		{0, 0, 0, 0, 1, 1, 1, 1},
		{0, 0, 0, 1, 1, 0, 0, 1, 0, 1, 0, 0},
		{1, 1, 1, 1},
		3, 4};
	struct px_nurbs_curve c;
	const struct px_nurbs_curve *cs[1] = {&c};
	struct px_dist_model *m;
	struct px_dist_entity_info ei;
	struct px_dist_info info;
	struct tally t = {0, 0, 0};
	int i;

	arena_reset();
	PX_CHECK_INT_EQ(make_curve(&c, &b), PX_OK);
	PX_CHECK_INT_EQ(px_dist_model_create(&c, 1, NULL, 0, NULL, &m), PX_OK);
	PX_CHECK_INT_EQ(px_dist_entity_info(m, 0, &ei), PX_OK);
	PX_CHECK_INT_EQ(ei.n_cusps, 1);
	px_dist_model_info(m, &info);
	for (i = 0; i < 300; i++) {
		px_vec3 q = px_v3(px_rand_range(0.2, 0.8), px_rand_range(0.5, 1.2),
				  px_rand_range(-0.1, 0.1));
		check_query(m, cs, 1, q, px_aabb_diagonal(&info.bounds), &t);
	}
	px_dist_model_free(m);
}

static void test_many_entities(void)
{
	struct curve_buf b[6];
	struct px_nurbs_curve c[6];
	const struct px_nurbs_curve *cs[6];
	struct px_dist_model *m;
	struct px_dist_info info;
	struct tally t = {0, 0, 0};
	int e, i;

	arena_reset();
	for (e = 0; e < 6; e++) {
		b[e].degree = px_rand_int(1, 4);
		b[e].n = b[e].degree + 1 + px_rand_int(0, 6);
		random_points(&b[e], e % 2, 0);
		for (i = 0; i < b[e].n; i++) /* spread entities apart */
			b[e].xyz[3 * i] += 2.5 * e;
		clamped_knots(&b[e], e % 4);
		PX_CHECK_INT_EQ(make_curve(&c[e], &b[e]), PX_OK);
		cs[e] = &c[e];
	}
	PX_CHECK_INT_EQ(px_dist_model_create(c, 6, NULL, 0, NULL, &m), PX_OK);
	px_dist_model_info(m, &info);
	PX_CHECK_INT_EQ(info.n_entities, 6);
	for (i = 0; i < 200; i++)
		check_query(m, cs, 6, query_point(&c[i % 6], info.bounds, i),
			    px_aabb_diagonal(&info.bounds), &t);
	px_dist_model_free(m);
}

static void test_tiny_cells_spill(void)
{
	/* One cell reference per cell forces the spill table into use. */
	struct curve_buf b;
	struct px_nurbs_curve c;
	const struct px_nurbs_curve *cs[1] = {&c};
	struct px_dist_opts o;
	struct px_dist_model *m;
	struct px_dist_info info;
	struct tally t = {0, 0, 0};
	int i;

	arena_reset();
	b.degree = 3;
	b.n = 20;
	random_points(&b, 1, 0);
	clamped_knots(&b, 0);
	PX_CHECK_INT_EQ(make_curve(&c, &b), PX_OK);
	px_dist_opts_default(&o);
	o.cell_cap = 1;
	o.decomp_tol = 0.01;
	PX_CHECK_INT_EQ(px_dist_model_create(&c, 1, NULL, 0, &o, &m), PX_OK);
	px_dist_model_info(m, &info);
	PX_CHECK(info.spill > 0);
	for (i = 0; i < 100; i++)
		check_query(m, cs, 1, query_point(&c, info.bounds, i),
			    px_aabb_diagonal(&info.bounds), &t);
	px_dist_model_free(m);
}

static void test_bad_input_and_no_alloc(void)
{
	struct curve_buf b;
	struct px_nurbs_curve c;
	struct px_dist_model *m;
	struct px_dist_result r[64];
	px_vec3 q[64];
	struct px_dist_opts o;
	uint64_t a;
	int i;

	arena_reset();
	b.degree = 3;
	b.n = 8;
	random_points(&b, 1, 0);
	clamped_knots(&b, 2);
	PX_CHECK_INT_EQ(make_curve(&c, &b), PX_OK);
	PX_CHECK_INT_EQ(px_dist_model_create(NULL, 1, NULL, 0, NULL, &m), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_dist_model_create(&c, 0, NULL, 0, NULL, &m), PX_E_INVAL);
	px_dist_opts_default(&o);
	o.jitter = 1.5;
	PX_CHECK_INT_EQ(px_dist_model_create(&c, 1, NULL, 0, &o, &m), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_dist_model_create(&c, 1, NULL, 0, NULL, &m), PX_OK);
	PX_CHECK_INT_EQ(px_dist_query(m, px_v3(NAN, 0, 0), &r[0]), PX_E_NAN);
	PX_CHECK_INT_EQ(px_dist_query(m, px_v3(0, INFINITY, 0), &r[0]), PX_E_NAN);
	for (i = 0; i < 64; i++)
		q[i] = px_v3(px_rand_normal(), px_rand_normal(), px_rand_normal());
	a = px_alloc_region_begin();
	for (i = 0; i < 100; i++)
		PX_CHECK_INT_EQ(px_dist_query_batch(m, q, 64, r), PX_OK);
	PX_CHECK_INT_EQ(px_alloc_region_end(a), 0);
	px_dist_model_free(m);
	px_dist_model_free(NULL);
}

static const struct px_test tests[] = {
	PX_T(test_random_clamped_curves),
	PX_T(test_random_periodic_curves),
	PX_T(test_nurbs_circle_and_evolute),
	PX_T(test_cusp_curve),
	PX_T(test_many_entities),
	PX_T(test_tiny_cells_spill),
	PX_T(test_bad_input_and_no_alloc),
};

PX_TEST_MAIN(tests)
