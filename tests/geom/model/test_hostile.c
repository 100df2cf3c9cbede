/*
 * Hostile geometry: data that breaks naive geometry code must give a
 * clear error (code and place) or a correct answer, never a crash or a
 * hang. Zero, negative and non-finite weights; knots out of order;
 * repeated control points (collapsed curves, cusps, a curve that is one
 * point); models at 1e-6 and 1e6 scale compared with brute-force
 * references; NaN and infinite coordinates and query points; a
 * 1e6-triangle mesh, a 1e6-point cloud and a million-entity OBJ file
 * written at test time (PX_STRESS=1 adds larger and slower cases).
 *
 * The brute-force references: meshes and clouds by scanning every
 * triangle or point; NURBS by dense sampling, which bounds the true
 * minimum from above, while the answer's own point (re-evaluated on the
 * entity) bounds it from below - a correct answer lies between.
 * Here under geom/model/: the queries go through the model interface
 * (px_model_*) over every kind of model.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "mesh_gen.h"
#include "px_alloc_count.h"
#include "px_arena.h"
#include "px_cloud.h"
#include "px_dist.h"
#include "px_mesh.h"
#include "px_model.h"
#include "px_nurbs.h"
#include "px_obj.h"
#include "px_test.h"

static int stress(void)
{
	const char *s = getenv("PX_STRESS");
	return s && *s && strcmp(s, "0") != 0;
}

/* ---- NURBS data errors ------------------------------------------------- */

static void test_weights_zero_negative_nan(void)
{
	static const double knots[] = {0, 0, 0, 1, 1, 1};
	static const double xyz[] = {0, 0, 0, 1, 1, 0, 2, 0, 0};
	const double bad[] = {0.0, -1.0, -1e-300, NAN, INFINITY, -INFINITY};
	struct px_nurbs_error err;
	size_t i;
	for (i = 0; i < sizeof bad / sizeof bad[0]; i++) {
		double w[3] = {1.0, bad[i], 1.0};
		int rc = px_nurbs_curve_validate(2, 3, knots, 6, xyz, w, &err);
		PX_CHECK_MSG(rc == PX_E_RANGE || rc == PX_E_NAN,
			     "weight %g accepted (rc %d)", bad[i], rc);
		PX_CHECK_INT_EQ(err.fault, PX_NURBS_FAULT_WEIGHT);
		PX_CHECK_INT_EQ(err.index, 1);
		PX_CHECK(err.msg[0] != '\0');
	}
	/* surfaces: the flat index and (i, j) of the bad weight */
	{
		static const double ku[] = {0, 0, 1, 1}, kv[] = {0, 0, 0, 1, 1, 1};
		double sx[3 * 6], sw[6];
		int rc;
		for (i = 0; i < 6; i++) {
			sx[3 * i] = (double)(i % 2);
			sx[3 * i + 1] = (double)(i / 2);
			sx[3 * i + 2] = 0.0;
			sw[i] = 1.0;
		}
		sw[5] = 0.0;
		rc = px_nurbs_surf_validate(1, 2, 2, 3, ku, 4, kv, 6, sx, sw, &err);
		PX_CHECK_INT_EQ(rc, PX_E_RANGE);
		PX_CHECK_INT_EQ(err.fault, PX_NURBS_FAULT_WEIGHT);
		PX_CHECK_INT_EQ(err.index_i, 1);
		PX_CHECK_INT_EQ(err.index_j, 2);
	}
}

static void test_knots_out_of_order(void)
{
	static const double xyz[] = {0, 0, 0, 1, 1, 0, 2, 0, 0, 3, 1, 0};
	struct px_nurbs_error err;
	int trial;
	/* random knot vectors with one inversion; also NaN and repeated */
	for (trial = 0; trial < 200; trial++) {
		double k[8] = {0, 0, 0, 0.5, 1, 1, 1, 1};
		int at = px_rand_int(1, 6), rc;
		double v = k[at - 1] - px_rand_range(1e-12, 2.0);
		k[at] = v;
		rc = px_nurbs_curve_validate(3, 4, k, 8, xyz, NULL, &err);
		PX_CHECK_MSG(rc == PX_E_INVAL, "knot %d = %g accepted", at, v);
		PX_CHECK_INT_EQ(err.fault, PX_NURBS_FAULT_KNOT_ORDER);
		PX_CHECK_INT_EQ(err.index, at);
	}
	{
		double k[8] = {0, 0, 0, NAN, 1, 1, 1, 1};
		PX_CHECK_INT_EQ(px_nurbs_curve_validate(3, 4, k, 8, xyz, NULL, &err),
				PX_E_NAN);
		PX_CHECK_INT_EQ(err.fault, PX_NURBS_FAULT_KNOT_NAN);
		k[3] = INFINITY;
		PX_CHECK(px_nurbs_curve_validate(3, 4, k, 8, xyz, NULL, &err) != PX_OK);
	}
	{
		/* all knots equal: empty domain */
		double k[8] = {1, 1, 1, 1, 1, 1, 1, 1};
		PX_CHECK(px_nurbs_curve_validate(3, 4, k, 8, xyz, NULL, &err) != PX_OK);
		PX_CHECK(err.fault == PX_NURBS_FAULT_KNOT_MULT ||
			 err.fault == PX_NURBS_FAULT_DOMAIN);
	}
	{
		/* interior multiplicity above the degree */
		double k[9] = {0, 0, 0, 0.5, 0.5, 0.5, 1, 1, 1};
		double x5[15] = {0};
		PX_CHECK(px_nurbs_curve_validate(2, 6, k, 9, x5, NULL, &err) != PX_OK);
		PX_CHECK_INT_EQ(err.fault, PX_NURBS_FAULT_KNOT_MULT);
	}
}

/* The same faults in an OBJ file are errors with their line. */
static void test_obj_hostile_files(void)
{
	static const struct {
		const char *text;
		int line;
	} cases[] = {
		{"v 0 0 0\nv 1 1 0 0\nv 2 0 0\ncstype rat bspline\ndeg 2\n"
		 "curv 0 1 1 2 3\nparm u 0 0 0 1 1 1\nend\n", 6},
		{"v 0 0 0\nv 1 1 0 -2\nv 2 0 0\ncstype rat bspline\ndeg 2\n"
		 "curv 0 1 1 2 3\nparm u 0 0 0 1 1 1\nend\n", 6},
		{"v 0 0 0\nv 1 1 0\nv 2 0 0\ncstype bspline\ndeg 2\n"
		 "curv 0 1 1 2 3\nparm u 0 0 1 0.5 1 1\nend\n", 7},
		{"v 0 0 0\nv 1 nan 0\nv 2 0 0\ncstype bspline\ndeg 2\n"
		 "curv 0 1 1 2 3\nparm u 0 0 0 1 1 1\nend\n", 2},
		{"v 0 0 0\nv 1 inf 0\nv 2 0 0\nf 1 2 3\n", 2},
		{"v 1e400 0 0\nv 1 1 0\nv 2 0 0\nf 1 2 3\n", 1},
		{"v 0 0 0\nv 1 1 0\nv 2 0 0\nf 1 2 4\n", 4},
		{"v 0 0 0\nv 1 1 0\nv 2 0 0\nf 1 2 -4\n", 4},
		{"v 0 0 0\nv 1 1 0\nv 2 0 0\ncstype bspline\ndeg 2\n"
		 "curv 0 1 1 2 99\nparm u 0 0 0 1 1 1\nend\n", 6},
	};
	size_t i;
	for (i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		struct px_obj_model *m = NULL;
		struct px_obj_error e;
		int rc = px_obj_load_mem("hostile.obj", cases[i].text,
					 strlen(cases[i].text), &m, &e);
		PX_CHECK_MSG(rc != PX_OK, "case %zu loaded", i);
		PX_CHECK(m == NULL);
		PX_CHECK_MSG(e.line >= 1 && e.line <= cases[i].line + 1,
			     "case %zu: error at line %d, expected about %d (%s)",
			     i, e.line, cases[i].line, e.msg);
		PX_CHECK(e.msg[0] != '\0');
		px_obj_free(m);
	}
}

/* ---- NURBS answers on hostile but valid data ----------------------------- */

/* Closest distance by dense sampling plus golden-section refinement
 * around the best samples: an upper bound of the true minimum. */
static double curve_sampled(const struct px_nurbs_curve *c, px_vec3 p)
{
	double u0, u1, best = INFINITY;
	int i, n = 4000;
	px_nurbs_curve_domain(c, &u0, &u1);
	for (i = 0; i <= n; i++) {
		double u = u0 + (u1 - u0) * i / n;
		double d = px_v3_dist(p, px_nurbs_curve_point(c, u));
		if (d < best)
			best = d;
	}
	return best;
}

static void check_curve_answer(const struct px_nurbs_curve *c, double scale,
			       int trials)
{
	struct px_dist_model *dm = NULL;
	int t, rc;
	rc = px_dist_model_create(c, 1, NULL, 0, NULL, &dm);
	PX_CHECK_INT_EQ(rc, PX_OK);
	if (rc != PX_OK)
		return;
	for (t = 0; t < trials; t++) {
		struct px_dist_result r;
		px_vec3 p = px_v3(px_rand_range(-2, 3) * scale,
				  px_rand_range(-2, 3) * scale,
				  px_rand_range(-1, 1) * scale);
		double up, on;
		PX_CHECK_INT_EQ(px_dist_query(dm, p, &r), PX_OK);
		PX_CHECK(isfinite(r.dist) && r.dist >= 0.0);
		/* the answer's point is on the curve, at the reported distance */
		on = px_v3_dist(p, px_nurbs_curve_point(c, r.u));
		PX_CHECK_CLOSE(on, r.dist, 1e-9 * scale, 1e-9);
		/* and not farther than any sample */
		up = curve_sampled(c, p);
		PX_CHECK_MSG(r.dist <= up + 1e-9 * scale,
			     "dist %.17g above sampled %.17g (scale %g)", r.dist,
			     up, scale);
	}
	px_dist_model_free(dm);
}

static void make_curve(struct px_nurbs_curve *c, struct px_arena *a, int deg,
		       int n, const double *xyz, const double *w)
{
	double k[64];
	int i, rc;
	for (i = 0; i < n + deg + 1; i++)
		k[i] = i <= deg ? 0.0 : i >= n ? 1.0 : (double)(i - deg) / (n - deg);
	rc = px_nurbs_curve_init(c, a, deg, n, k, n + deg + 1, xyz, w, NULL);
	PX_CHECK_INT_EQ(rc, PX_OK);
}

static void test_repeated_control_points(void)
{
	static unsigned char mem[1 << 16];
	struct px_arena a;
	struct px_nurbs_curve c;
	double xyz[3 * 8];
	int i;

	px_arena_init(&a, mem, sizeof mem);
	/* a cubic whose every control point is the same: a single point */
	for (i = 0; i < 8; i++) {
		xyz[3 * i] = 0.25;
		xyz[3 * i + 1] = -0.5;
		xyz[3 * i + 2] = 0.125;
	}
	make_curve(&c, &a, 3, 6, xyz, NULL);
	{
		struct px_dist_model *dm = NULL;
		int rc = px_dist_model_create(&c, 1, NULL, 0, NULL, &dm);
		PX_CHECK_MSG(rc == PX_OK || rc == PX_E_DEGENERATE || rc == PX_E_INVAL,
			     "point curve: rc %d", rc);
		if (rc == PX_OK) {
			struct px_dist_result r;
			px_vec3 p = px_v3(1, 2, 3);
			PX_CHECK_INT_EQ(px_dist_query(dm, p, &r), PX_OK);
			PX_CHECK_CLOSE(r.dist, px_v3_dist(p, px_v3(0.25, -0.5, 0.125)),
				       1e-12, 1e-12);
		}
		px_dist_model_free(dm);
	}
	/* doubled and tripled points inside (cusps, flat spots) */
	for (i = 0; i < 7; i++) {
		int j = i < 2 ? 0 : i < 5 ? 1 : 2;
		xyz[3 * i] = (double)j;
		xyz[3 * i + 1] = j == 1 ? 1.0 : 0.0;
		xyz[3 * i + 2] = 0.0;
	}
	make_curve(&c, &a, 3, 7, xyz, NULL);
	check_curve_answer(&c, 1.0, 40);
	/* a quadratic with the middle point on an end point */
	xyz[0] = 0, xyz[1] = 0, xyz[2] = 0;
	xyz[3] = 0, xyz[4] = 0, xyz[5] = 0;
	xyz[6] = 1, xyz[7] = 1, xyz[8] = 0;
	make_curve(&c, &a, 2, 3, xyz, NULL);
	check_curve_answer(&c, 1.0, 40);
}

/* A random rational cubic scaled by s: answers correct relative to s. */
static void test_scales_nurbs(void)
{
	static unsigned char mem[1 << 16];
	const double scales[] = {1e-6, 1e-3, 1.0, 1e3, 1e6};
	size_t k;
	for (k = 0; k < sizeof scales / sizeof scales[0]; k++) {
		struct px_arena a;
		struct px_nurbs_curve c;
		double xyz[3 * 7], w[7];
		int i;
		px_arena_init(&a, mem, sizeof mem);
		for (i = 0; i < 7; i++) {
			xyz[3 * i] = ((double)i / 6.0 + 0.1 * px_rand_normal()) * scales[k];
			xyz[3 * i + 1] = px_rand_range(-0.5, 0.5) * scales[k];
			xyz[3 * i + 2] = px_rand_range(-0.2, 0.2) * scales[k];
			w[i] = px_rand_range(0.2, 3.0);
		}
		make_curve(&c, &a, 3, 7, xyz, w);
		check_curve_answer(&c, scales[k], 25);
	}
}

/* ---- meshes and clouds --------------------------------------------------- */

static double mesh_brute(const double *xyz, const uint32_t *tri, size_t nt,
			 px_vec3 p)
{
	double best = INFINITY;
	size_t i;
	for (i = 0; i < nt; i++) {
		const double *a = xyz + 3 * tri[3 * i], *b = xyz + 3 * tri[3 * i + 1],
			     *c = xyz + 3 * tri[3 * i + 2];
		double d2 = px_tri_closest(p, px_v3(a[0], a[1], a[2]),
					   px_v3(b[0], b[1], b[2]),
					   px_v3(c[0], c[1], c[2]), NULL, NULL,
					   NULL, NULL, NULL);
		if (d2 < best)
			best = d2;
	}
	return sqrt(best);
}

static double cloud_brute(const double *xyz, size_t n, px_vec3 p)
{
	double best = INFINITY;
	size_t i;
	for (i = 0; i < n; i++) {
		double d2 = px_v3_dist2(p, px_v3(xyz[3 * i], xyz[3 * i + 1],
						 xyz[3 * i + 2]));
		if (d2 < best)
			best = d2;
	}
	return sqrt(best);
}

static void test_scales_mesh_cloud(void)
{
	const double scales[] = {1e-6, 1e-3, 1.0, 1e3, 1e6};
	size_t k;
	for (k = 0; k < sizeof scales / sizeof scales[0]; k++) {
		struct gen_mesh g;
		struct px_model *m = NULL, *cl = NULL;
		struct px_mesh_report rep;
		double s = scales[k];
		size_t i;
		int t;
		PX_CHECK_INT_EQ(gen_torus(1.0, 0.3, 40, 20, &g), 0);
		for (i = 0; i < 3 * g.nv; i++)
			g.xyz[i] *= s;
		PX_CHECK_INT_EQ(px_mesh_model(g.xyz, g.nv, g.tri, g.nt, NULL, &rep, &m),
				PX_OK);
		PX_CHECK_MSG(rep.closed, "torus at scale %g not closed: %s", s,
			     rep.message);
		PX_CHECK_INT_EQ(px_cloud_model(g.xyz, g.nv, 0.0, NULL, &cl), PX_OK);
		for (t = 0; t < 50; t++) {
			struct px_model_result r;
			px_vec3 p = px_v3(px_rand_range(-2, 2) * s,
					  px_rand_range(-2, 2) * s,
					  px_rand_range(-1, 1) * s);
			double want = mesh_brute(g.xyz, g.tri, g.nt, p);
			PX_CHECK_INT_EQ(px_model_query(m, p, &r), 1);
			PX_CHECK_CLOSE(fabs(r.distance), want, 1e-12 * s, 1e-10);
			PX_CHECK_CLOSE(px_v3_dist(p, r.point), want, 1e-12 * s, 1e-10);
			want = cloud_brute(g.xyz, g.nv, p);
			PX_CHECK_INT_EQ(px_model_query(cl, p, &r), 1);
			PX_CHECK_CLOSE(r.distance, want, 1e-12 * s, 1e-10);
		}
		px_model_free(m);
		px_model_free(cl);
		gen_free(&g);
	}
}

/* Coordinates spanning 1e-6 to 1e6 in one model: a tiny triangle next to
 * a huge one, and a tiny cluster in a huge cloud. */
static void test_mixed_scales(void)
{
	double xyz[] = {0, 0, 0, 1e-6, 0, 0, 0, 1e-6, 0,
			-1e6, -1e6, 5, 1e6, -1e6, 5, 0, 1e6, 5};
	uint32_t tri[] = {0, 1, 2, 3, 4, 5};
	struct px_model *m = NULL;
	int t;
	PX_CHECK_INT_EQ(px_mesh_model(xyz, 6, tri, 2, NULL, NULL, &m), PX_OK);
	for (t = 0; t < 200; t++) {
		struct px_model_result r;
		double s = pow(10.0, px_rand_range(-7, 6));
		px_vec3 p = px_v3(px_rand_range(-1, 1) * s, px_rand_range(-1, 1) * s,
				  px_rand_range(-1, 1) * s);
		double want = mesh_brute(xyz, tri, 2, p);
		PX_CHECK_INT_EQ(px_model_query(m, p, &r), 1);
		PX_CHECK_CLOSE(fabs(r.distance), want, 1e-18, 1e-9);
	}
	px_model_free(m);
}

static void test_nan_inf(void)
{
	const double bad[] = {NAN, INFINITY, -INFINITY};
	size_t i;
	for (i = 0; i < 3; i++) {
		double xyz[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
		uint32_t tri[] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
		struct px_model *m = NULL;
		struct px_mesh_report rep;
		struct px_cloud_report crep;
		struct px_model_result r;
		int rc;
		/* a bad vertex: PX_E_NAN naming it */
		xyz[4] = bad[i];
		rc = px_mesh_model(xyz, 4, tri, 4, NULL, &rep, &m);
		PX_CHECK_INT_EQ(rc, PX_E_NAN);
		PX_CHECK(m == NULL && rep.message[0] != '\0');
		rc = px_cloud_model(xyz, 4, 0.0, &crep, &m);
		PX_CHECK_INT_EQ(rc, PX_E_NAN);
		PX_CHECK(m == NULL && strstr(crep.message, "1") != NULL);
		/* a cloud: far points get PX_E_RANGE, not a tie of infinities */
		xyz[4] = 0.0;
		PX_CHECK_INT_EQ(px_cloud_model(xyz, 4, 0.0, NULL, &m), PX_OK);
		PX_CHECK_INT_EQ(px_model_query(m, px_v3(1e160, 0, 0), &r), PX_E_RANGE);
		PX_CHECK_INT_EQ(px_model_query(m, px_v3(1e140, 0, 0), &r), 1);
		PX_CHECK_CLOSE(r.distance, 1e140, 0, 1e-15);
		PX_CHECK_INT_EQ(px_model_query(m, px_v3(1e7, 0, 0), &r), 1);
		PX_CHECK_INT_EQ(r.index, 1);
		px_model_free(m);
		m = NULL;
		/* a bad radius */
		xyz[4] = 0.0;
		PX_CHECK_INT_EQ(px_cloud_model(xyz, 4, bad[i], NULL, &m), PX_E_RANGE);
		/* a bad query point */
		PX_CHECK_INT_EQ(px_mesh_model(xyz, 4, tri, 4, NULL, NULL, &m), PX_OK);
		PX_CHECK_INT_EQ(px_model_query(m, px_v3(0.1, bad[i], 0.2), &r), PX_E_NAN);
		PX_CHECK_INT_EQ(px_model_query(m, px_v3(bad[i], bad[i], bad[i]), &r),
				PX_E_NAN);
		/* far points: exact up to 1e150, PX_E_RANGE beyond */
		PX_CHECK_INT_EQ(px_model_query(m, px_v3(1e120, 0, 0), &r), 1);
		PX_CHECK_CLOSE(r.distance, 1e120, 0, 1e-15);
		PX_CHECK_INT_EQ(px_model_query(m, px_v3(0, 1e200, 0), &r), PX_E_RANGE);
		PX_CHECK_INT_EQ(px_model_query(m, px_v3(0, 0, -1e300), &r), PX_E_RANGE);
		/* and the model still answers */
		PX_CHECK_INT_EQ(px_model_query(m, px_v3(2, 2, 2), &r), 1);
		PX_CHECK(isfinite(r.distance));
		px_model_free(m);
	}
	/* NURBS queries */
	{
		static unsigned char mem[4096];
		static const double k[] = {0, 0, 1, 1};
		static const double x[] = {0, 0, 0, 1, 0, 0};
		struct px_arena a;
		struct px_nurbs_curve c;
		struct px_dist_model *dm = NULL;
		struct px_dist_result r;
		px_arena_init(&a, mem, sizeof mem);
		PX_CHECK_INT_EQ(px_nurbs_curve_init(&c, &a, 1, 2, k, 4, x, NULL, NULL),
				PX_OK);
		PX_CHECK_INT_EQ(px_dist_model_create(&c, 1, NULL, 0, NULL, &dm), PX_OK);
		for (i = 0; i < 3; i++)
			PX_CHECK_INT_EQ(px_dist_query(dm, px_v3(bad[i], 0, 0), &r),
					PX_E_NAN);
		/* far but finite points: an exact answer up to 1e150 away,
		 * beyond that (squared distances overflow) PX_E_RANGE */
		PX_CHECK_INT_EQ(px_dist_query(dm, px_v3(1e100, 0, 0), &r), PX_OK);
		PX_CHECK_CLOSE(r.dist, 1e100 - 1.0, 0, 1e-15);
		PX_CHECK_INT_EQ(px_dist_query(dm, px_v3(1e300, 0, 0), &r), PX_E_RANGE);
		PX_CHECK_INT_EQ(px_dist_query(dm, px_v3(0, -1e200, 0), &r), PX_E_RANGE);
		PX_CHECK_INT_EQ(px_dist_query(dm, px_v3(0.5, 1e-300, 0), &r), PX_OK);
		PX_CHECK_NEAR(r.dist, 1e-300, 1e-150); /* squares underflow */
		px_dist_model_free(dm);
	}
}

/* ---- size ----------------------------------------------------------------- */

/* A wavy height field of nx * ny quads, 2 nx ny triangles. */
static void grid_mesh(int nx, int ny, struct gen_mesh *g)
{
	int i, j;
	g->nv = (size_t)(nx + 1) * (ny + 1);
	g->xyz = malloc(3 * g->nv * sizeof(double));
	g->tri = malloc(6 * (size_t)nx * ny * sizeof(uint32_t));
	g->nt = 0;
	if (!g->xyz || !g->tri)
		abort();
	for (j = 0; j <= ny; j++)
		for (i = 0; i <= nx; i++) {
			double *v = g->xyz + 3 * ((size_t)j * (nx + 1) + i);
			v[0] = (double)i / nx;
			v[1] = (double)j / ny;
			v[2] = 0.02 * sin(40.0 * v[0]) * cos(30.0 * v[1]);
		}
	for (j = 0; j < ny; j++)
		for (i = 0; i < nx; i++) {
			uint32_t a = (uint32_t)(j * (nx + 1) + i);
			gen_quad(g, a, a + 1, a + 1 + (uint32_t)(nx + 1),
				 a + (uint32_t)(nx + 1));
		}
}

static void test_mesh_1e6_triangles(void)
{
	struct gen_mesh g;
	struct px_model *m = NULL;
	struct px_mesh_report rep;
	int t, rc;
	uint64_t a0;
	grid_mesh(1000, 500, &g);
	PX_CHECK_INT_EQ(g.nt, 1000000);
	rc = px_mesh_model(g.xyz, g.nv, g.tri, g.nt, NULL, &rep, &m);
	PX_CHECK_INT_EQ(rc, PX_OK);
	PX_CHECK(rep.depth <= PX_MESH_MAX_DEPTH);
	a0 = px_alloc_region_begin();
	for (t = 0; t < 4; t++) {
		struct px_model_result r;
		px_vec3 p = px_v3(px_rand_range(-0.2, 1.2), px_rand_range(-0.2, 1.2),
				  px_rand_range(-0.3, 0.3));
		double want;
		PX_CHECK_INT_EQ(px_model_query(m, p, &r), 1);
		want = mesh_brute(g.xyz, g.tri, g.nt, p);
		PX_CHECK_CLOSE(fabs(r.distance), want, 1e-15, 1e-12);
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(a0), 0);
	px_model_free(m);
	gen_free(&g);
}

static void test_cloud_1e6_points(void)
{
	size_t n = 1000000, i;
	double *xyz = malloc(3 * n * sizeof(double));
	struct px_model *m = NULL;
	int t;
	uint64_t a0;
	PX_CHECK(xyz != NULL);
	/* clustered: most points in a few tight blobs, some duplicates */
	for (i = 0; i < n; i++) {
		double c = (double)(i % 7);
		xyz[3 * i] = c + 1e-3 * px_rand_normal();
		xyz[3 * i + 1] = 1e-3 * px_rand_normal();
		xyz[3 * i + 2] = i % 1000 == 0 ? 0.0 : 1e-3 * px_rand_normal();
	}
	memcpy(xyz + 3 * 10, xyz + 3 * 20, 3 * sizeof(double));
	PX_CHECK_INT_EQ(px_cloud_model(xyz, n, 0.0, NULL, &m), PX_OK);
	a0 = px_alloc_region_begin();
	for (t = 0; t < 10; t++) {
		struct px_model_result r;
		px_vec3 p = px_v3(px_rand_range(-1, 8), px_rand_range(-0.01, 0.01),
				  px_rand_range(-0.01, 0.01));
		PX_CHECK_INT_EQ(px_model_query(m, p, &r), 1);
		PX_CHECK_CLOSE(r.distance, cloud_brute(xyz, n, p), 1e-15, 1e-12);
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(a0), 0);
	px_model_free(m);
	free(xyz);
}

/* A million entities in one OBJ file: 1e6 faces (PX_STRESS: also 1e6
 * free-form curves), written to a temporary file and loaded. */
static void test_obj_million_entities(void)
{
	char path[] = "/tmp/px_hostile_XXXXXX";
	int fd = mkstemp(path), nx = 1000, ny = 500, i, j, rc;
	FILE *f;
	struct px_obj_model *m = NULL;
	struct px_obj_error e;
	PX_CHECK(fd >= 0);
	f = fdopen(fd, "w");
	PX_CHECK(f != NULL);
	for (j = 0; j <= ny; j++)
		for (i = 0; i <= nx; i++)
			fprintf(f, "v %d %d 0\n", i, j);
	for (j = 0; j < ny; j++)
		for (i = 0; i < nx; i++) {
			int a = j * (nx + 1) + i + 1;
			if ((i + j) & 1)
				fprintf(f, "f %d %d %d\nf %d %d %d\n", a, a + 1,
					a + nx + 2, a, a + nx + 2, a + nx + 1);
			else
				fprintf(f, "f %d %d %d %d\n", a, a + 1, a + nx + 2,
					a + nx + 1);
		}
	if (stress()) {
		/* and a million degree-1 curves over the same vertices */
		fprintf(f, "cstype bspline\ndeg 1\n");
		for (i = 0; i < 1000000; i++)
			fprintf(f, "curv 0 1 %d %d\nparm u 0 0 1 1\nend\n",
				i % 400000 + 1, i % 400000 + 2);
	}
	PX_CHECK_INT_EQ(fclose(f), 0);
	rc = px_obj_load_file(path, &m, &e);
	unlink(path);
	PX_CHECK_MSG(rc == PX_OK, "load: %s:%d:%d: %s", e.file, e.line, e.column,
		     e.msg);
	PX_CHECK_INT_EQ(m->n_triangles, 1000000);
	PX_CHECK_INT_EQ(m->n_vertices, (nx + 1) * (ny + 1));
	if (stress())
		PX_CHECK_INT_EQ(m->n_entities, 1000000);
	for (i = 0; i < 3 * m->n_triangles; i++)
		if (m->triangles[i] < 0 || m->triangles[i] >= m->n_vertices)
			break;
	PX_CHECK_INT_EQ(i, 3 * m->n_triangles);
	px_obj_free(m);
}

/* A line whose index overflows int, a face with 1e5 corners, and a
 * 10 MB line: errors or answers, in bounded time. */
static void test_obj_extremes(void)
{
	size_t big = 10u << 20, i;
	char *s = malloc(big + 64);
	struct px_obj_model *m = NULL;
	struct px_obj_error e;
	int rc;
	PX_CHECK(s != NULL);
	strcpy(s, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999999999999\n");
	rc = px_obj_load_mem("x.obj", s, strlen(s), &m, &e);
	PX_CHECK(rc != PX_OK && m == NULL && e.line == 4);
	/* a polygon of 100000 corners over 3 vertices */
	{
		size_t n = 0;
		n += (size_t)sprintf(s, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf");
		for (i = 0; i < 100000; i++)
			n += (size_t)sprintf(s + n, " %d", (int)(i % 3) + 1);
		s[n++] = '\n';
		rc = px_obj_load_mem("x.obj", s, n, &m, &e);
		PX_CHECK_MSG(rc == PX_OK || (m == NULL && e.line == 4),
			     "rc %d line %d", rc, e.line);
		px_obj_free(m);
		m = NULL;
	}
	/* one 10 MB comment line, then a valid face */
	s[0] = '#';
	memset(s + 1, 'x', big - 1);
	strcpy(s + big, "\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
	rc = px_obj_load_mem("x.obj", s, strlen(s), &m, &e);
	PX_CHECK_MSG(rc == PX_OK, "%d:%d: %s", e.line, e.column, e.msg);
	if (rc == PX_OK)
		PX_CHECK_INT_EQ(m->n_triangles, 1);
	px_obj_free(m);
	free(s);
}

static const struct px_test tests[] = {
	PX_T(test_weights_zero_negative_nan),
	PX_T(test_knots_out_of_order),
	PX_T(test_obj_hostile_files),
	PX_T(test_repeated_control_points),
	PX_T(test_scales_nurbs),
	PX_T(test_scales_mesh_cloud),
	PX_T(test_mixed_scales),
	PX_T(test_nan_inf),
	PX_T(test_mesh_1e6_triangles),
	PX_T(test_cloud_1e6_points),
	PX_T(test_obj_million_entities),
	PX_T(test_obj_extremes),
};
PX_TEST_MAIN(tests)
