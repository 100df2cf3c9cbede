/* Global point-to-NURBS-surface distance against a brute-force oracle:
 * random B-spline and NURBS surfaces, creases, poles, seams, boundary
 * minima, focal points, and mixed curve/surface models. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "px_alloc_count.h"
#include "px_arena.h"
#include "px_dist.h"
#include "px_model.h"
#include "px_nurbs.h"
#include "px_recog.h"
#include "px_test.h"

#define MAXN 12

struct surf_buf {
	int p, q, nu, nv;
	double ku[MAXN + 8], kv[MAXN + 8];
	double xyz[3 * MAXN * MAXN], w[MAXN * MAXN];
};

static unsigned char arena_mem[1 << 22];
static struct px_arena arena;

static void arena_reset(void)
{
	px_arena_init(&arena, arena_mem, sizeof(arena_mem));
}

static void knots(double *k, int p, int n, int style)
{
	int m = n + p + 1, i, nin = n - p - 1;
	if (style == 2) { /* unclamped uniform */
		for (i = 0; i < m; i++)
			k[i] = i;
		return;
	}
	for (i = 0; i <= p; i++) {
		k[i] = 0.0;
		k[m - 1 - i] = 1.0;
	}
	for (i = 0; i < nin; i++)
		k[p + 1 + i] = (i + 1.0) / (nin + 1.0);
	if (style == 3) { /* clustered near both ends */
		for (i = 0; i < nin; i++)
			k[p + 1 + i] = i < nin / 2 ? 0.01 * (i + 1) : 1.0 - 0.01 * (nin - i);
		return;
	}
	if (style == 1 && nin >= p) /* C0 crease in the middle */
		for (i = 0; i < p; i++)
			k[p + 1 + i] = 0.5;
	if (style == 1 && nin >= p)
		for (i = p; i < nin; i++)
			k[p + 1 + i] = 0.5 + 0.4 * (i - p + 1) / (nin - p + 1);
}

static int random_surface(struct px_nurbs_surf *s, struct surf_buf *b,
			  int rational)
{
	struct px_nurbs_error err;
	int i, j, rc;
	b->p = px_rand_int(1, 5);
	b->q = px_rand_int(1, 5);
	b->nu = b->p + 1 + px_rand_int(0, 3);
	b->nv = b->q + 1 + px_rand_int(0, 3);
	knots(b->ku, b->p, b->nu, px_rand_int(0, 3));
	knots(b->kv, b->q, b->nv, px_rand_int(0, 3));
	for (j = 0; j < b->nv; j++)
		for (i = 0; i < b->nu; i++) {
			int k = j * b->nu + i;
			b->xyz[3 * k] = (double)i / (b->nu - 1) + 0.1 * px_rand_normal();
			b->xyz[3 * k + 1] = (double)j / (b->nv - 1) + 0.1 * px_rand_normal();
			b->xyz[3 * k + 2] = 0.3 * px_rand_normal();
			b->w[k] = rational ? exp(px_rand_range(log(0.2), log(5.0))) : 1.0;
		}
	rc = px_nurbs_surf_init(s, &arena, b->p, b->q, b->nu, b->nv, b->ku,
				b->nu + b->p + 1, b->kv, b->nv + b->q + 1, b->xyz,
				b->w, &err);
	if (rc)
		printf("    surface rejected: %s\n", err.msg);
	return rc;
}

/* Oracle: per knot rectangle a 40 x 40 sample grid (left limits at the
 * upper edges so creases are sampled on both sides), every sampled local
 * minimum refined by a walking, shrinking 5 x 5 pattern search. */
static double oracle(const struct px_nurbs_surf *s, px_vec3 x)
{
	enum { N = 40 };
	double best = INFINITY, a, b, c, d;
	int ku, kv;
	px_nurbs_surf_domain(s, &a, &b, &c, &d);
	for (ku = s->degree[0]; ku < s->n_ctrl[0]; ku++) {
		double u0 = fmax(a, s->knots[0][ku]), u1 = fmin(b, s->knots[0][ku + 1]);
		if (!(u1 > u0))
			continue;
		for (kv = s->degree[1]; kv < s->n_ctrl[1]; kv++) {
			double v0 = fmax(c, s->knots[1][kv]), v1 = fmin(d, s->knots[1][kv + 1]);
			static double d2[N + 1][N + 1];
			int i, j;
			if (!(v1 > v0))
				continue;
			for (i = 0; i <= N; i++)
				for (j = 0; j <= N; j++) {
					struct px_nurbs_surf_derivs dv;
					px_nurbs_surf_eval_side(s, u0 + (u1 - u0) * i / N,
								v0 + (v1 - v0) * j / N,
								i == N ? -1 : 1, j == N ? -1 : 1,
								0, &dv);
					d2[i][j] = px_v3_dist2(dv.s, x);
					best = fmin(best, d2[i][j]);
				}
			for (i = 0; i <= N; i++)
				for (j = 0; j <= N; j++) {
					int ia, jb, ok = 1, it;
					double cu, cv, hu = (u1 - u0) / N, hv = (v1 - v0) / N;
					for (ia = -1; ia <= 1 && ok; ia++)
						for (jb = -1; jb <= 1; jb++)
							if (i + ia >= 0 && i + ia <= N && j + jb >= 0 &&
							    j + jb <= N && d2[i + ia][j + jb] < d2[i][j])
								ok = 0;
					if (!ok)
						continue;
					cu = u0 + (u1 - u0) * i / N;
					cv = v0 + (v1 - v0) * j / N;
					for (it = 0; it < 400 && (hu > 1e-15 || hv > 1e-15); it++) {
						double bu = cu, bv = cv, bd = INFINITY;
						for (ia = -2; ia <= 2; ia++)
							for (jb = -2; jb <= 2; jb++) {
								double uu = fmin(u1, fmax(u0, cu + ia * hu / 2));
								double vv = fmin(v1, fmax(v0, cv + jb * hv / 2));
								double dd = px_v3_dist2(px_nurbs_surf_point(s, uu, vv), x);
								if (dd < bd) {
									bd = dd;
									bu = uu;
									bv = vv;
								}
							}
						if (bu == cu && bv == cv) {
							hu *= 0.6;
							hv *= 0.6;
						}
						cu = bu;
						cv = bv;
						best = fmin(best, bd);
					}
				}
		}
	}
	return sqrt(best);
}

struct tally {
	int queries, uncertified, boundary, oracle_missed;
};

static void check(struct px_dist_model *m, const struct px_nurbs_surf *s,
		  int ent, px_vec3 x, double diag, struct tally *t)
{
	struct px_dist_result r;
	double ref = oracle(s, x);
	px_vec3 on;
	double a, b, c, d;

	PX_CHECK_INT_EQ(px_dist_query(m, x, &r), PX_OK);
	t->queries++;
	PX_CHECK_MSG(r.dist <= ref + 1e-9 * diag,
		     "wrong branch: %.17g vs oracle %.17g at (%.17g, %.17g, %.17g)",
		     r.dist, ref, x.x, x.y, x.z);
	/* Below the oracle is fine when the answer is a real surface point
	 * (checked next): then the sampling oracle missed a narrow minimum,
	 * and the answer is its own witness. */
	if (r.dist < ref - 1e-7 * diag)
		t->oracle_missed++;
	PX_CHECK_INT_EQ(r.entity, ent);
	PX_CHECK_INT_EQ(r.kind, PX_DIST_SURFACE);
	on = px_nurbs_surf_point(s, r.u, r.v);
	PX_CHECK_MSG(px_v3_dist(on, r.point) <= 1e-9 * (1 + diag),
		     "point off its parameters by %.3g", px_v3_dist(on, r.point));
	PX_CHECK_CLOSE(r.dist, px_v3_dist(x, r.point), 1e-12, 1e-12);
	px_nurbs_surf_domain(s, &a, &b, &c, &d);
	t->boundary += r.u <= a || r.u >= b || r.v <= c || r.v >= d;
	t->uncertified += !r.certified;
}

static px_vec3 query_point(const struct px_nurbs_surf *s, px_aabb box, int kind)
{
	double a, b, c, d, diag = px_aabb_diagonal(&box);
	px_nurbs_surf_domain(s, &a, &b, &c, &d);
	switch (kind % 5) {
	case 0:
		return px_v3(px_rand_range(box.min.x - 0.3 * diag, box.max.x + 0.3 * diag),
			     px_rand_range(box.min.y - 0.3 * diag, box.max.y + 0.3 * diag),
			     px_rand_range(box.min.z - 0.3 * diag, box.max.z + 0.3 * diag));
	case 1: /* far */
		return px_v3_add(px_aabb_center(&box),
				 px_v3_scale(px_v3(px_rand_normal(), px_rand_normal(),
						   px_rand_normal()), 100 * diag));
	case 2: /* on the surface */
		return px_nurbs_surf_point(s, px_rand_range(a, b), px_rand_range(c, d));
	case 3: /* near a knot line */
	{
		int k = px_rand_int(s->degree[0], s->n_ctrl[0]);
		px_vec3 on = px_nurbs_surf_point(s, s->knots[0][k], px_rand_range(c, d));
		return px_v3_add(on, px_v3_scale(px_v3(px_rand_normal(), px_rand_normal(),
						       px_rand_normal()), 0.05));
	}
	default: /* beside an edge: boundary minima */
	{
		struct px_nurbs_surf_derivs dv;
		double u = px_rand_int(0, 1) ? a : b, v = px_rand_range(c, d);
		px_nurbs_surf_eval(s, u, v, 1, &dv);
		return px_v3_madd(dv.s, dv.su, (u == a ? -1 : 1) * 0.2 /
						  (px_v3_norm(dv.su) + 1e-300));
	}
	}
}

static void test_random_surfaces(void)
{
	struct tally t = {0, 0, 0, 0};
	int trial;
	for (trial = 0; trial < 100; trial++) {
		struct surf_buf b;
		struct px_nurbs_surf s;
		struct px_dist_model *m = NULL;
		struct px_dist_info info;
		int i;
		arena_reset();
		PX_CHECK_INT_EQ(random_surface(&s, &b, trial % 2), PX_OK);
		PX_CHECK_INT_EQ(px_dist_model_create(NULL, 0, &s, 1, NULL, &m), PX_OK);
		px_dist_model_info(m, &info);
		for (i = 0; i < 5; i++)
			check(m, &s, 0, query_point(&s, info.bounds, trial + i),
			      px_aabb_diagonal(&info.bounds), &t);
		px_dist_model_free(m);
	}
	printf("    %d queries, %d on the boundary, %d uncertified, %d below the "
	       "sampling oracle (answer verified on the surface)\n",
	       t.queries, t.boundary, t.uncertified, t.oracle_missed);
	PX_CHECK(t.boundary > 20);
}

/* Full sphere of radius R as a rational biquadratic surface of
 * revolution: 9 x 5 control points, poles collapse two edges. */
static void sphere(struct px_nurbs_surf *s, double R, px_vec3 c)
{
	static double ku[12] = {0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1};
	static double kv[8] = {0, 0, 0, 0.5, 0.5, 1, 1, 1};
	static const double circ[9][3] = {{1, 0, 1}, {1, 1, 0}, {0, 1, 1}, {-1, 1, 0},
					  {-1, 0, 1}, {-1, -1, 0}, {0, -1, 1},
					  {1, -1, 0}, {1, 0, 1}};
	static const double prof[5][3] = {{0, -1, 1}, {1, -1, 0}, {1, 0, 1},
					  {1, 1, 0}, {0, 1, 1}};
	double xyz[3 * 45], w[45];
	const double r2 = sqrt(0.5);
	int i, j;
	for (j = 0; j < 5; j++)
		for (i = 0; i < 9; i++) {
			int k = j * 9 + i;
			/* profile (rho, z), revolved */
			double rho = prof[j][0], z = prof[j][1];
			xyz[3 * k] = c.x + R * rho * circ[i][0];
			xyz[3 * k + 1] = c.y + R * rho * circ[i][1];
			xyz[3 * k + 2] = c.z + R * z;
			w[k] = (circ[i][2] ? 1.0 : r2) * (prof[j][2] ? 1.0 : r2);
		}
	PX_CHECK_INT_EQ(px_nurbs_surf_init(s, &arena, 2, 2, 9, 5, ku, 12, kv, 8, xyz,
					   w, NULL),
			PX_OK);
}

static void test_sphere_poles_seam_focal(void)
{
	struct px_nurbs_surf s;
	struct px_dist_model *m;
	struct px_dist_result r;
	struct px_dist_entity_info ei;
	px_vec3 c = px_v3(0.5, -1, 2);
	int i;

	arena_reset();
	sphere(&s, 2.0, c);
	PX_CHECK_INT_EQ(px_dist_model_create(NULL, 0, &s, 1, NULL, &m), PX_OK);
	PX_CHECK_INT_EQ(px_dist_entity_info(m, 0, &ei), PX_OK);
	PX_CHECK_INT_EQ(ei.n_collapsed, 2);
	PX_CHECK_INT_EQ(ei.shape, PX_RECOG_SPHERE); /* closed form */
	PX_CHECK(ei.closed & 1);
	/* The centre is the focal point of every patch. */
	PX_CHECK_INT_EQ(px_dist_query(m, c, &r), PX_OK);
	PX_CHECK_CLOSE(r.dist, 2.0, 1e-12, 1e-12);
	PX_CHECK(r.certified);
	for (i = 0; i < 400; i++) {
		px_vec3 dir = px_v3(px_rand_normal(), px_rand_normal(), px_rand_normal());
		double rad = i % 4 == 0 ? px_rand_range(0, 1e-6) : px_rand_range(0, 6);
		px_vec3 x;
		if (i % 10 == 1) /* on the axis through the poles */
			dir = px_v3(0, 0, px_rand_int(0, 1) ? 1 : -1);
		if (i % 10 == 2) /* on the seam plane */
			dir = px_v3(fabs(dir.x), 0, dir.z);
		x = px_v3_add(c, px_v3_scale(dir, rad / px_v3_norm(dir)));
		PX_CHECK_INT_EQ(px_dist_query(m, x, &r), PX_OK);
		PX_CHECK_CLOSE(r.dist, fabs(rad - 2.0), 1e-10, 1e-10);
		PX_CHECK_CLOSE(px_v3_dist(r.point, c), 2.0, 1e-10, 0);
	}
	px_dist_model_free(m);
}

static void test_mixed_model(void)
{
	struct surf_buf b;
	struct px_nurbs_surf s[2];
	struct px_nurbs_curve cv;
	struct px_dist_model *m;
	struct px_dist_result r;
	struct px_dist_info info;
	double ck[8] = {0, 0, 0, 0, 1, 1, 1, 1};
	double cxyz[12] = {0, 0, 1, 1, 0.5, 2, 2, -0.5, 1, 3, 0, 1};
	int i;

	arena_reset();
	PX_CHECK_INT_EQ(random_surface(&s[0], &b, 1), PX_OK);
	sphere(&s[1], 0.5, px_v3(3, 3, 0));
	PX_CHECK_INT_EQ(px_nurbs_curve_init(&cv, &arena, 3, 4, ck, 8, cxyz, NULL, NULL),
			PX_OK);
	PX_CHECK_INT_EQ(px_dist_model_create(&cv, 1, s, 2, NULL, &m), PX_OK);
	px_dist_model_info(m, &info);
	PX_CHECK_INT_EQ(info.n_entities, 3);
	PX_CHECK(info.n_patches > 0 && info.n_curve_pieces > 0);
	for (i = 0; i < 150; i++) {
		px_vec3 x = px_v3(px_rand_range(-1, 4), px_rand_range(-1, 4),
				  px_rand_range(-1, 2));
		double ref = fmin(oracle(&s[0], x),
				  fabs(px_v3_dist(x, px_v3(3, 3, 0)) - 0.5));
		double a, bb;
		int k;
		/* the curve by dense sampling */
		px_nurbs_curve_domain(&cv, &a, &bb);
		for (k = 0; k <= 20000; k++)
			ref = fmin(ref, px_v3_dist(x, px_nurbs_curve_point(&cv, a + (bb - a) * k / 20000)));
		PX_CHECK_INT_EQ(px_dist_query(m, x, &r), PX_OK);
		PX_CHECK_MSG(r.dist <= ref + 1e-9, "wrong branch %.17g vs %.17g", r.dist, ref);
		PX_CHECK(r.dist >= ref - 1e-6);
		PX_CHECK_INT_EQ(r.kind, r.entity == 0 ? PX_DIST_CURVE : PX_DIST_SURFACE);
	}
	px_dist_model_free(m);
}

/* Two parallel sheets z = 0 and z = 1 (bilinear patches over the unit
 * square): on the mid-plane both foot points are equally near, the
 * medial axis where the closest point jumps. */
static void test_medial_plane_of_two_sheets(void)
{
	double k[4] = {0, 0, 1, 1};
	double a[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
	double b[12] = {0, 0, 1, 1, 0, 1, 0, 1, 1, 1, 1, 1};
	struct px_nurbs_surf s[2];
	struct px_dist_model *m;
	struct px_dist_result r;
	int i;

	arena_reset();
	PX_CHECK_INT_EQ(px_nurbs_surf_init(&s[0], &arena, 1, 1, 2, 2, k, 4, k, 4, a, NULL, NULL), PX_OK);
	PX_CHECK_INT_EQ(px_nurbs_surf_init(&s[1], &arena, 1, 1, 2, 2, k, 4, k, 4, b, NULL, NULL), PX_OK);
	PX_CHECK_INT_EQ(px_dist_model_create(NULL, 0, s, 2, NULL, &m), PX_OK);
	for (i = 0; i < 300; i++) {
		double x = px_rand_range(-0.5, 1.5), y = px_rand_range(-0.5, 1.5);
		double z = i % 3 ? 0.5 : px_rand_range(-1, 2);
		double dx = x < 0 ? -x : (x > 1 ? x - 1 : 0);
		double dy = y < 0 ? -y : (y > 1 ? y - 1 : 0);
		double dz = fmin(fabs(z), fabs(z - 1));
		PX_CHECK_INT_EQ(px_dist_query(m, px_v3(x, y, z), &r), PX_OK);
		PX_CHECK_CLOSE(r.dist, sqrt(dx * dx + dy * dy + dz * dz), 1e-12, 1e-12);
		PX_CHECK(r.point.z == 0.0 || r.point.z == 1.0);
		PX_CHECK(r.certified);
	}
	px_dist_model_free(m);
}

/* The same sphere behind the point-to-model interface, posed. */
static void test_as_posed_model(void)
{
	struct px_nurbs_surf s;
	struct px_model *m;
	struct px_model_result r;
	px_pose pose;
	uint64_t a;
	int i;

	arena_reset();
	sphere(&s, 1.5, px_v3(0, 0, 0));
	PX_CHECK_INT_EQ(px_nurbs_model_create(NULL, 0, &s, 1, NULL, &m), PX_OK);
	PX_CHECK_INT_EQ(px_model_kind(m), PX_MODEL_NURBS);
	PX_CHECK(px_quat_from_axis_angle(px_v3(1, 2, 3), 0.7, &pose.q) == PX_OK);
	pose.t = px_v3(3, -1, 2);
	PX_CHECK_INT_EQ(px_model_set_pose(m, pose), PX_OK);
	a = px_alloc_region_begin();
	for (i = 0; i < 200; i++) {
		px_vec3 x = px_v3(px_rand_range(-2, 8), px_rand_range(-6, 4), px_rand_range(-3, 7));
		PX_CHECK_INT_EQ(px_model_query(m, x, &r), 1);
		/* A closed shell: signed, inside negative. */
		PX_CHECK_CLOSE(r.distance, px_v3_dist(x, pose.t) - 1.5, 1e-10, 1e-10);
		PX_CHECK_CLOSE(px_v3_dist(r.point, pose.t), 1.5, 1e-10, 0);
		PX_CHECK_CLOSE(px_v3_dist(px_v3_madd(r.point, r.direction, r.distance), x), 0.0, 1e-9, 0);
		PX_CHECK(r.certified && r.is_signed);
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(a), 0);
	px_model_free(m);
}

static void test_surface_queries_allocate_nothing(void)
{
	struct px_nurbs_surf s;
	struct px_dist_model *m;
	struct px_dist_result r[32];
	px_vec3 q[32];
	uint64_t a;
	int i;
	arena_reset();
	sphere(&s, 1.0, px_v3(0, 0, 0));
	PX_CHECK_INT_EQ(px_dist_model_create(NULL, 0, &s, 1, NULL, &m), PX_OK);
	for (i = 0; i < 32; i++)
		q[i] = px_v3(px_rand_normal(), px_rand_normal(), px_rand_normal());
	a = px_alloc_region_begin();
	for (i = 0; i < 20; i++)
		PX_CHECK_INT_EQ(px_dist_query_batch(m, q, 32, r), PX_OK);
	PX_CHECK_INT_EQ(px_alloc_region_end(a), 0);
	px_dist_model_free(m);
}

static const struct px_test tests[] = {
	PX_T(test_random_surfaces),
	PX_T(test_sphere_poles_seam_focal),
	PX_T(test_mixed_model),
	PX_T(test_medial_plane_of_two_sheets),
	PX_T(test_as_posed_model),
	PX_T(test_surface_queries_allocate_nothing),
};

PX_TEST_MAIN(tests)
