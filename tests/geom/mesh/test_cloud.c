/*
 * Point clouds: k-d tree against a linear scan, balls, coherence, files,
 * the hint grid of cold queries.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "mesh_internal.h"
#include "px_alloc_count.h"
#include "px_cloud.h"
#include "px_test.h"
#include "px_test_geom.h"

static px_pose rand_pose(void)
{
	return px_test_rand_pose(2);
}

/* Clouds of several shapes: uniform, clustered, on a plane, on a line,
 * with many duplicates, all one point. */
static double *make_cloud(size_t n, int kind)
{
	double *x = malloc(3 * n * sizeof(double));
	size_t i;
	for (i = 0; i < n; i++) {
		double *p = x + 3 * i;
		switch (kind) {
		case 0:
			p[0] = px_rand_range(-1, 1), p[1] = px_rand_range(-1, 1),
			p[2] = px_rand_range(-1, 1);
			break;
		case 1: { /* clusters */
			double c = (double)(i % 5) - 2;
			p[0] = c + 0.05 * px_rand_normal(), p[1] = 0.05 * px_rand_normal(),
			p[2] = c * 0.3 + 0.05 * px_rand_normal();
			break;
		}
		case 2:
			p[0] = px_rand_range(-1, 1), p[1] = px_rand_range(-1, 1), p[2] = 0.25;
			break;
		case 3:
			p[0] = px_rand_range(-1, 1), p[1] = 0.5 * p[0], p[2] = -p[0];
			break;
		case 4: /* duplicates on a coarse lattice */
			p[0] = px_rand_int(0, 3), p[1] = px_rand_int(0, 3), p[2] = px_rand_int(0, 3);
			break;
		default:
			p[0] = 0.3, p[1] = -0.2, p[2] = 0.1;
			break;
		}
	}
	return x;
}

static void test_vs_brute(void)
{
	int kind, rep, i;
	for (kind = 0; kind < 6; kind++)
		for (rep = 0; rep < 3; rep++) {
			size_t n = rep == 0 ? (size_t)px_rand_int(1, 9) : (size_t)px_rand_int(10, 3000);
			double *x = make_cloud(n, kind);
			double radius = rep == 2 ? px_rand_range(0.01, 0.2) : 0.0;
			struct px_model *m;
			px_pose P = rand_pose();
			PX_CHECK_INT_EQ(px_cloud_model(x, n, radius, NULL, &m), PX_OK);
			PX_CHECK_INT_EQ(px_cloud_point_count(m), n);
			px_model_set_pose(m, P);
			for (i = 0; i < 200; i++) {
				px_vec3 pl = px_v3(px_rand_range(-2.5, 2.5), px_rand_range(-2.5, 2.5),
						   px_rand_range(-2.5, 2.5));
				struct px_model_result r;
				double best = INFINITY;
				size_t k;
				px_vec3 c;
				if (i % 10 == 0) /* exactly on a point */
					pl = px_v3(x[0], x[1], x[2]);
				for (k = 0; k < n; k++) {
					double d2 = px_v3_dist2(pl, px_v3(x[3 * k], x[3 * k + 1], x[3 * k + 2]));
					if (d2 < best)
						best = d2;
				}
				best = sqrt(best) - radius;
				PX_CHECK_INT_EQ(px_model_query(m,
							       px_pose_transform_point(P, pl), &r), 1);
				PX_CHECK_MSG(fabs(r.distance - best) <= 1e-12,
					     "kind %d n %zu: %.17g vs scan %.17g", kind, n, r.distance, best);
				PX_CHECK(r.index >= 0 && (size_t)r.index < n);
				c = px_v3(x[3 * r.index], x[3 * r.index + 1], x[3 * r.index + 2]);
				PX_CHECK_NEAR(px_v3_dist(pl, c) - radius, best, 1e-12);
				PX_CHECK_INT_EQ(r.feature, PX_FEATURE_POINT);
				PX_CHECK_INT_EQ(r.is_signed, radius > 0);
				PX_CHECK_INT_EQ(r.inside, best < 0);
				PX_CHECK_NEAR(px_v3_dist(px_v3_madd(r.point, r.direction, r.distance),
							 px_pose_transform_point(P, pl)), 0, 1e-9);
				PX_CHECK_NEAR(px_v3_dist(px_pose_inverse_transform_point(P, r.point), c),
					      radius, 1e-9);
			}
			px_model_free(m);
			free(x);
		}
}

static void test_coherent_and_bounded(void)
{
	size_t n = 5000;
	double *x = make_cloud(n, 0);
	struct px_model *m;
	px_vec3 p = px_v3(0, 0, 0);
	int i, hint = -1;

	PX_CHECK_INT_EQ(px_cloud_model(x, n, 0.0, NULL, &m), PX_OK);
	for (i = 0; i < 500; i++) {
		struct px_model_result a, b, c, d;
		double lim = px_rand_range(0, 0.1);
		int rc;
		p = px_v3_add(p, px_v3(px_rand_range(-0.02, 0.02), px_rand_range(-0.02, 0.02),
				       px_rand_range(-0.02, 0.02)));
		px_model_query(m, p, &a);
		px_model_query_ex(m, p, INFINITY, hint, PX_QUERY_COHERENT, &b);
		px_model_query_ex(m, p, INFINITY, px_rand_int(-3, (int)n + 3), PX_QUERY_COHERENT, &c);
		PX_CHECK(a.distance == b.distance && a.distance == c.distance);
		rc = px_model_query_ex(m, p, lim, hint, PX_QUERY_COHERENT, &d);
		PX_CHECK_INT_EQ(rc, a.distance <= lim);
		if (rc == 1)
			PX_CHECK(d.distance == a.distance);
		hint = b.index;
	}
	px_model_free(m);
	free(x);
}

static void test_cache(void)
{
	/* cached answers equal full ones, with a radius (fallback path) and
	 * without (cache path), along a path with jumps */
	size_t n = 4000;
	double *x = make_cloud(n, 1);
	int rad;
	for (rad = 0; rad < 2; rad++) {
		struct px_model *m;
		struct px_model_cache c;
		px_vec3 p = px_v3(0, 0, 0);
		int i;
		uint64_t a;
		PX_CHECK_INT_EQ(px_cloud_model(x, n, rad ? 0.02 : 0.0, NULL, &m), PX_OK);
		px_model_cache_init(&c, 0.0);
		a = px_alloc_region_begin();
		for (i = 0; i < 3000; i++) {
			struct px_model_result rc, rf;
			p = px_v3_add(p, px_v3(px_rand_range(-0.01, 0.01), px_rand_range(-0.01, 0.01),
					       px_rand_range(-0.01, 0.01)));
			if (i % 500 == 499)
				p = px_v3(px_rand_range(-3, 3), px_rand_range(-1, 1), px_rand_range(-1, 1));
			PX_CHECK_INT_EQ(px_model_query_cached(m, p, &c, &rc), 1);
			PX_CHECK_INT_EQ(px_model_query(m, p, &rf), 1);
			PX_CHECK_MSG(rc.distance == rf.distance, "step %d: %.17g vs %.17g", i,
				     rc.distance, rf.distance);
		}
		PX_CHECK_INT_EQ(px_alloc_region_end(a), 0);
		if (!rad)
			PX_CHECK(px_model_cache_refills(&c) < 3000);
		px_model_free(m);
	}
	free(x);
}

static void test_invalid(void)
{
	double x[] = {0, 0, 0, 1, INFINITY, 0};
	struct px_cloud_report rp;
	struct px_model *m = (struct px_model *)1;
	PX_CHECK_INT_EQ(px_cloud_model(x, 2, 0.0, &rp, &m), PX_E_NAN);
	PX_CHECK(m == NULL);
	PX_CHECK_MSG(strstr(rp.message, "point 1") != NULL, "%s", rp.message);
	PX_CHECK_INT_EQ(px_cloud_model(x, 1, -1.0, &rp, &m), PX_E_RANGE);
	PX_CHECK_INT_EQ(px_cloud_model(x, 1, NAN, &rp, &m), PX_E_RANGE);
	PX_CHECK_INT_EQ(px_cloud_model(x, 0, 0.0, &rp, &m), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_cloud_model(NULL, 1, 0.0, &rp, &m), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_cloud_point_count(NULL), 0);
}

/* ---- files ------------------------------------------------------------------- */

static char tmpdir[64];

static const char *tpath(const char *name)
{
	static char buf[4][160];
	static int k;
	k = (k + 1) % 4;
	snprintf(buf[k], sizeof(buf[k]), "%s/%s", tmpdir, name);
	return buf[k];
}

static void put(const char *name, const char *text)
{
	FILE *f = fopen(tpath(name), "w");
	PX_CHECK(f != NULL);
	fputs(text, f);
	fclose(f);
}

static void check_points(const char *name, const double *ref, size_t n)
{
	struct px_cloud_report rp;
	struct px_model *m;
	size_t i;
	int rc = px_cloud_load(tpath(name), 0.0, &rp, &m);
	PX_CHECK_MSG(rc == PX_OK, "%s: %s: %s", name, px_strerror(rc), rp.message);
	PX_CHECK_INT_EQ(px_cloud_point_count(m), n);
	for (i = 0; i < n; i++) {
		px_vec3 p;
		PX_CHECK_INT_EQ(px_cloud_point(m, i, &p), PX_OK);
		PX_CHECK(p.x == ref[3 * i] && p.y == ref[3 * i + 1] && p.z == ref[3 * i + 2]);
	}
	px_model_free(m);
}

static void check_error(const char *name, int code, const char *what, long line)
{
	struct px_cloud_report rp;
	struct px_model *m = (struct px_model *)1;
	int rc = px_cloud_load(tpath(name), 0.0, &rp, &m);
	PX_CHECK_MSG(rc == code, "%s: %s (%s), expected %s", name, px_strerror_name(rc),
		     rp.message, px_strerror_name(code));
	PX_CHECK(m == NULL);
	PX_CHECK_MSG(strstr(rp.message, name) && strstr(rp.message, what), "%s: '%s'",
		     name, rp.message);
	PX_CHECK_INT_EQ(rp.line, line);
}

static void test_files(void)
{
	const double ref[] = {1, 2, 3, -0.5, 0.25, 1e-3, 4, 5, 6};
	const char *names[] = {"a.xyz", "b.csv", "c.txt", "d.ply", "e.ply", "bad1.xyz",
			       "bad2.csv", "bad3.xyz", "empty.xyz", "bad.ply", "trunc.ply",
			       "trunc_b.ply", "extra.ply"};
	size_t k;
	FILE *f;

	snprintf(tmpdir, sizeof(tmpdir), "/tmp/px_cloud_XXXXXX");
	PX_CHECK(mkdtemp(tmpdir) != NULL);
	put("a.xyz", "# scan\n1 2 3\n\n-0.5\t0.25 1e-3 255 0 0\r\n// more\n4 5 6\n");
	put("b.csv", "x,y,z,intensity\n1,2,3,7\n-0.5, 0.25, 0.001,7\n4;5;6\n");
	put("c.txt", "1 2 3\n-0.5 0.25 0.001\n4 5 6");
	put("d.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
		     "property float y\nproperty float z\nend_header\n1 2 3\n-0.5 0.25 0.0009765625\n4 5 6\n");
	f = fopen(tpath("e.ply"), "wb");
	PX_CHECK(f != NULL);
	fprintf(f, "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
		   "property float y\nproperty float z\nend_header\n");
	{
		float v[9] = {1, 2, 3, -0.5f, 0.25f, 0.0009765625f, 4, 5, 6};
		fwrite(v, sizeof(float), 9, f);
	}
	fclose(f);
	put("bad1.xyz", "1 2 3\n4 5\n");
	put("bad2.csv", "x,y,z\n1,2,3\n1,abc,3\n");
	put("bad3.xyz", "1 2 3\n1 nan 3\n");
	put("empty.xyz", "# nothing\n\n");
	put("bad.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n");

	/* the importer would pad these with repeated values: refused here */
	put("trunc.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
			 "property float y\nproperty float z\nend_header\n1 2 3\n4 5\n");
	put("extra.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
			 "property float y\nproperty float z\nend_header\n1 2 3\n4 5 6\n");
	f = fopen(tpath("trunc_b.ply"), "wb");
	PX_CHECK(f != NULL);
	fprintf(f, "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty double x\n"
		   "property double y\nproperty double z\nend_header\n");
	{
		double v[8] = {0};
		fwrite(v, sizeof(double), 8, f);
	}
	fclose(f);
	check_error("trunc.ply", PX_E_PARSE, "ends early", -1);
	check_error("trunc_b.ply", PX_E_PARSE, "ends early", -1);
	check_error("extra.ply", PX_E_PARSE, "after the last", -1);
	check_points("a.xyz", ref, 3);
	check_points("b.csv", ref, 3);
	check_points("c.txt", ref, 3);
	{
		double r2[9];
		memcpy(r2, ref, sizeof(r2));
		r2[5] = 0.0009765625; /* exact in float */
		check_points("d.ply", r2, 3);
		check_points("e.ply", r2, 3);
	}
	check_error("bad1.xyz", PX_E_PARSE, ":2:", 2);
	check_error("bad2.csv", PX_E_PARSE, ":3:3:", 3);
	check_error("bad3.xyz", PX_E_NAN, ":2:", 2);
	check_error("empty.xyz", PX_E_PARSE, "no points", -1);
	check_error("missing.xyz", PX_E_NOTFOUND, "missing.xyz", -1);
	check_error("bad.ply", PX_E_PARSE, "bad.ply", -1);
	for (k = 0; k < sizeof(names) / sizeof(names[0]); k++)
		unlink(tpath(names[k]));
	rmdir(tmpdir);
}

static void test_no_alloc(void)
{
	size_t n = 20000;
	double *x = make_cloud(n, 1);
	struct px_model *m;
	struct px_model_result r;
	uint64_t a;
	int i, hint = -1;
	PX_CHECK_INT_EQ(px_cloud_model(x, n, 0.01, NULL, &m), PX_OK);
	a = px_alloc_region_begin();
	for (i = 0; i < 3000; i++) {
		px_vec3 p = px_v3(2 * cos(0.01 * i), sin(0.013 * i), 0.1);
		px_model_query(m, p, &r);
		px_model_query_ex(m, p, 0.05, hint, PX_QUERY_COHERENT | PX_QUERY_UNSIGNED, &r);
		hint = r.index;
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(a), 0);
	px_model_free(m);
	free(x);
}

static double scan(const double *x, size_t n, px_vec3 p)
{
	double best = INFINITY;
	size_t k;
	for (k = 0; k < n; k++) {
		double d2 = px_v3_dist2(p, px_v3(x[3 * k], x[3 * k + 1], x[3 * k + 2]));
		if (d2 < best)
			best = d2;
	}
	return sqrt(best);
}

/* Cold queries (no hint) start from the grid's point for the query's
 * cell: answers equal the scan inside, just outside and far outside the
 * grid; the hint's distance is never below the answer and within twice
 * the distance to the cell centre above it (the grid holds the exact
 * nearest point of every centre); queries allocate nothing. */
static void test_grid_hints(void)
{
	int kind, rep, i;
	for (kind = 0; kind < 6; kind++)
		for (rep = 0; rep < 2; rep++) {
			size_t n = rep == 0 ? (size_t)px_rand_int(1, 40) : (size_t)px_rand_int(200, 4000);
			double *x = make_cloud(n, kind);
			struct px_model *m;
			uint64_t a;
			double sum = 0;
			PX_CHECK_INT_EQ(px_cloud_model(x, n, 0.0, NULL, &m), PX_OK);
			for (i = 0; i < 150; i++) {
				double f = i % 3 == 0 ? 1.2 : (i % 3 == 1 ? 3.0 : 1e4);
				px_vec3 p = px_v3(f * px_rand_range(-1.5, 1.5), f * px_rand_range(-1.5, 1.5),
						  f * px_rand_range(-1.5, 1.5)),
					c, h;
				struct px_model_result r;
				double ref = scan(x, n, p), dh, L = 1 + px_v3_norm(p);
				long hi;
				PX_CHECK_INT_EQ(px_model_query_ex(m, p, INFINITY, -1, 0, &r), 1);
				PX_CHECK_MSG(fabs(r.distance - ref) <= 1e-12 * L,
					     "kind %d n %zu: %.17g vs scan %.17g", kind, n, r.distance, ref);
				hi = px__cloud_grid_hint(m, p, &c);
				PX_CHECK(hi >= 0 && (size_t)hi < n);
				if (hi < 0 || (size_t)hi >= n)
					continue;
				h = px_v3(x[3 * hi], x[3 * hi + 1], x[3 * hi + 2]);
				dh = px_v3_dist(p, h);
				PX_CHECK_MSG(dh >= ref - 1e-12 * L, "hint %.17g below exact %.17g", dh, ref);
				PX_CHECK_MSG(dh <= ref + 2 * px_v3_dist(p, c) + 1e-12 * L,
					     "hint %.17g, exact %.17g, %g from the cell centre", dh, ref,
					     px_v3_dist(p, c));
				/* at the centre itself the hint is the nearest point */
				PX_CHECK_NEAR(px_v3_dist(c, h), scan(x, n, c), 1e-12 * (1 + px_v3_norm(c)));
			}
			a = px_alloc_region_begin();
			for (i = 0; i < 300; i++) {
				struct px_model_result r;
				px_model_query(m, px_v3(3 * sin(i), 2 * cos(0.3 * i), sin(0.7 * i)), &r);
				sum += r.distance;
			}
			PX_CHECK_INT_EQ(px_alloc_region_end(a), 0);
			PX_CHECK(sum >= 0);
			px_model_free(m);
			free(x);
		}
}

/* The single-precision box and slab bounds must stay lower bounds at
 * every scale: thin curved shells (where the slabs prune most), tiny
 * clouds far from the origin (float spacing near the cloud's size), huge
 * clouds, and query points beyond the float range (exact path only). */
static void test_scales(void)
{
	int rep, i;
	for (rep = 0; rep < 6; rep++) {
		size_t n = (size_t)px_rand_int(500, 3000), k;
		double *x = malloc(3 * n * sizeof(double));
		double off = rep < 2 ? 0.0 : (rep < 4 ? 1e7 : -3e12), sc = rep % 2 ? 1e-3 : 1.0;
		struct px_model *m;
		if (rep >= 4)
			sc = 1e9;
		for (k = 0; k < n; k++) {
			/* a sphere shell 1e-3 thick, as a scan would give */
			double z = px_rand_range(-1, 1), ph = px_rand_range(0, 2 * M_PI);
			double rr = sc * (1 + 1e-3 * px_rand_range(-0.5, 0.5)), s = sqrt(1 - z * z);
			x[3 * k] = off + rr * s * cos(ph);
			x[3 * k + 1] = -off + rr * s * sin(ph);
			x[3 * k + 2] = off + rr * z;
		}
		PX_CHECK_INT_EQ(px_cloud_model(x, n, 0.0, NULL, &m), PX_OK);
		for (i = 0; i < 200; i++) {
			double f = i % 4 == 3 ? (i % 8 == 3 ? 1e3 : 1e20) : px_rand_range(0, 1.5);
			px_vec3 d = px_v3(px_rand_normal(), px_rand_normal(), px_rand_normal());
			px_vec3 p = px_v3_add(px_v3(off, -off, off), px_v3_scale(d, sc * f / px_v3_norm(d)));
			struct px_model_result r;
			double ref = scan(x, n, p);
			PX_CHECK_INT_EQ(px_model_query_ex(m, p, INFINITY, -1, 0, &r), 1);
			PX_CHECK_MSG(fabs(r.distance - ref) <= 1e-12 * (ref + fabs(off) + sc),
				     "rep %d: %.17g vs scan %.17g", rep, r.distance, ref);
			/* the same through the hint path */
			PX_CHECK_INT_EQ(px_model_query_ex(m, p, INFINITY, px_rand_int(0, (int)n - 1),
							  PX_QUERY_COHERENT, &r), 1);
			PX_CHECK_MSG(fabs(r.distance - ref) <= 1e-12 * (ref + fabs(off) + sc),
				     "rep %d (hint): %.17g vs scan %.17g", rep, r.distance, ref);
		}
		px_model_free(m);
		free(x);
	}
}

static const struct px_test tests[] = {
	PX_T(test_vs_brute), PX_T(test_coherent_and_bounded), PX_T(test_cache), PX_T(test_invalid),
	PX_T(test_files), PX_T(test_no_alloc), PX_T(test_grid_hints), PX_T(test_scales)};
PX_TEST_MAIN(tests)
