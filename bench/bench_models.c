/*
 * bench_models - point-to-model query costs: a 70,490-triangle mesh (cold
 * and coherent), a 100,000-point cloud, primitives; and FCL 0.7 (OBBRSS
 * hierarchy, sphere of radius 0 as the point) on the same mesh queries
 * when the reference program bench/fcl_models.cpp was built (it is when
 * Debian's libfcl-dev is installed; without it this benchmark says so and
 * runs alone).
 *
 * Every query is timed on its own with CLOCK_MONOTONIC; the timer's own
 * cost (median of empty intervals) is printed and subtracted. Cold
 * queries are independent points (half near the surface, half anywhere
 * in the grown bounding box); coherent queries follow a haptic probe
 * sliding over the surface at 0.1 mm per query, each starting from the
 * last closest triangle.
 *
 * Environment: PX_BENCH_MODELS_FCL (path of the FCL program; default
 * fcl_models next to this binary).
 */
#include <libgen.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "models_common.h"
#include "px_cloud.h"
#include "px_mesh.h"
#include "px_model.h"
#include "px_prim.h"

static int64_t now_ns(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

static int cmp_d(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return x < y ? -1 : x > y;
}

struct stats {
	double median, p90, p99, max, mean;
};

static struct stats summarize(double *t, int n, double overhead)
{
	struct stats s;
	double sum = 0;
	int i;
	for (i = 0; i < n; i++) {
		t[i] = fmax(0.0, t[i] - overhead);
		sum += t[i];
	}
	qsort(t, (size_t)n, sizeof(double), cmp_d);
	s.median = t[n / 2];
	s.p90 = t[(int)(0.90 * n)];
	s.p99 = t[(int)(0.99 * n)];
	s.max = t[n - 1];
	s.mean = sum / n;
	return s;
}

static void print_stats(const char *what, struct stats s)
{
	printf("  %-34s median %8.3f us  p90 %8.3f  p99 %8.3f  max %8.3f  mean %8.3f\n",
	       what, s.median / 1e3, s.p90 / 1e3, s.p99 / 1e3, s.max / 1e3, s.mean / 1e3);
}

static double timer_overhead(void)
{
	static double t[10001];
	int i;
	for (i = 0; i < 10001; i++) {
		int64_t a = now_ns();
		int64_t b = now_ns();
		t[i] = (double)(b - a);
	}
	qsort(t, 10001, sizeof(double), cmp_d);
	return t[5000];
}

static double *times;

/* Cold: independent queries; coherent: trajectory with the hint. */
static struct stats run_queries(const struct px_model *m, const double *pts,
				int n, int coherent, double overhead,
				double *sum_abs)
{
	struct px_model_result r;
	int i, hint = -1;
	double s = 0;
	for (i = 0; i < n; i++) {
		px_vec3 p = px_v3(pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]);
		int64_t a = now_ns();
		if (coherent)
			px_model_query_ex(m, p, INFINITY, hint, PX_QUERY_COHERENT, &r);
		else
			px_model_query(m, p, &r);
		times[i] = (double)(now_ns() - a);
		hint = r.index;
		s += fabs(r.distance);
	}
	if (sum_abs)
		*sum_abs = s;
	return summarize(times, n, overhead);
}

struct fcl_out {
	int ok;
	double cold_median, traj_median, cold_sum, traj_sum, build_ms;
};

static struct fcl_out run_fcl(const char *argv0)
{
	struct fcl_out o = {0, 0, 0, 0, 0, 0};
	char path[4096], dir[4096], line[256];
	const char *env = getenv("PX_BENCH_MODELS_FCL");
	FILE *f;
	if (env && *env) {
		snprintf(path, sizeof(path), "%s", env);
	} else {
		snprintf(dir, sizeof(dir), "%s", argv0);
		snprintf(path, sizeof(path), "%s/fcl_models", dirname(dir));
	}
	if (access(path, X_OK) != 0) {
		printf("  FCL: reference program %s not built (Debian libfcl-dev not "
		       "installed): no comparison\n", path);
		return o;
	}
	f = popen(path, "r");
	if (!f) {
		printf("  FCL: cannot run %s\n", path);
		return o;
	}
	while (fgets(line, sizeof(line), f)) {
		sscanf(line, "cold_median_ns %lf", &o.cold_median);
		sscanf(line, "traj_median_ns %lf", &o.traj_median);
		sscanf(line, "cold_sum %lf", &o.cold_sum);
		sscanf(line, "traj_sum %lf", &o.traj_sum);
		sscanf(line, "build_ms %lf", &o.build_ms);
	}
	o.ok = pclose(f) == 0 && o.cold_median > 0;
	if (!o.ok)
		printf("  FCL: %s failed\n", path);
	return o;
}

int main(int argc, char **argv)
{
	struct gen_mesh g;
	struct px_model *mesh, *cloud, *prim;
	struct px_mesh_report rp;
	double overhead, *cold, *traj, *cpts, sum_cold = 0, sum_traj = 0;
	struct stats sc, st, stc;
	uint64_t seed = 12345;
	int64_t t0;
	int i;
	const size_t NC = 100000;

	(void)argc;
	times = malloc(BM_NQ * sizeof(double));
	cold = malloc(3 * BM_NQ * sizeof(double));
	traj = malloc(3 * BM_NQ * sizeof(double));
	cpts = malloc(3 * NC * sizeof(double));
	if (!times || !cold || !traj || !cpts)
		return 1;
	for (i = 0; i < BM_NQ; i++) {
		bm_cold_point(&seed, i, cold + 3 * i);
		bm_traj_point(i, traj + 3 * i);
	}
	overhead = timer_overhead();
	printf("bench_models: timer overhead %.0f ns per query (subtracted)\n", overhead);

	/* ---- mesh ---- */
	if (gen_torus(BM_R, BM_r, BM_NU, BM_NV, &g) != 0)
		return 1;
	t0 = now_ns();
	if (px_mesh_model(g.xyz, g.nv, g.tri, g.nt, NULL, &rp, &mesh) != PX_OK) {
		printf("mesh build failed: %s\n", rp.message);
		return 1;
	}
	printf("mesh: torus, %zu triangles, closed %d, depth %d, %.1f MB, built in %.1f ms\n",
	       rp.n_triangles, rp.closed, rp.depth, px_model_memory_bytes(mesh) / 1e6,
	       (now_ns() - t0) / 1e6);
	sc = run_queries(mesh, cold, BM_NQ, 0, overhead, &sum_cold);
	print_stats("cold (independent points)", sc);
	stc = run_queries(mesh, traj, BM_NQ, 0, overhead, NULL);
	print_stats("trajectory, cold", stc);
	st = run_queries(mesh, traj, BM_NQ, 1, overhead, &sum_traj);
	print_stats("trajectory, coherent", st);
	printf("  targets: cold median <= 2 us: %s; coherent median <= 0.5 us: %s\n",
	       sc.median <= 2000 ? "met" : "NOT met", st.median <= 500 ? "met" : "NOT met");
	{
		struct fcl_out fo = run_fcl(argv[0]);
		if (fo.ok) {
			printf("  FCL 0.7 OBBRSS: built in %.1f ms; cold median %.3f us, "
			       "trajectory median %.3f us\n",
			       fo.build_ms, fo.cold_median / 1e3, fo.traj_median / 1e3);
			printf("  same answers: sum of |distance| cold %.12g vs FCL %.12g, "
			       "trajectory %.12g vs FCL %.12g\n",
			       sum_cold, fo.cold_sum, sum_traj, fo.traj_sum);
			printf("  speed-up over FCL: cold %.1fx, coherent %.1fx (target >= 5x)\n",
			       fo.cold_median / fmax(sc.median, 1.0),
			       fo.traj_median / fmax(st.median, 1.0));
		}
	}
	px_model_free(mesh);
	gen_free(&g);

	/* ---- cloud ---- */
	seed = 777;
	for (i = 0; i < (int)NC; i++) {
		double z = 2 * bm_unit(&seed) - 1, ph = 2 * M_PI * bm_unit(&seed);
		double rr = 0.5 + 0.001 * (bm_unit(&seed) - 0.5), s = sqrt(1 - z * z);
		cpts[3 * i] = rr * s * cos(ph);
		cpts[3 * i + 1] = rr * s * sin(ph);
		cpts[3 * i + 2] = rr * z;
	}
	t0 = now_ns();
	if (px_cloud_model(cpts, NC, 0.0, NULL, &cloud) != PX_OK)
		return 1;
	printf("cloud: %zu points on a 0.5 m sphere, %.1f MB, built in %.1f ms\n", NC,
	       px_model_memory_bytes(cloud) / 1e6, (now_ns() - t0) / 1e6);
	for (i = 0; i < BM_NQ; i++) { /* the probe path, scaled to the sphere */
		double *p = traj + 3 * i;
		double n = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
		double rr = 0.5 + 0.005 * sin(3e-3 * i);
		p[0] *= rr / n, p[1] *= rr / n, p[2] *= rr / n;
	}
	print_stats("cold (independent points)", run_queries(cloud, cold, BM_NQ, 0, overhead, NULL));
	print_stats("trajectory, coherent", run_queries(cloud, traj, BM_NQ, 1, overhead, NULL));
	px_model_free(cloud);

	/* ---- primitives ---- */
	{
		const struct px_prim ps[] = {{PX_PRIM_SPHERE, 0.2, 0, 0}, {PX_PRIM_BOX, 0.1, 0.2, 0.3},
					     {PX_PRIM_CAPSULE, 0.05, 0.2, 0}, {PX_PRIM_CYLINDER, 0.1, 0.2, 0},
					     {PX_PRIM_CONE, 0.1, 0.2, 0.0}, {PX_PRIM_TORUS, 0.3, 0.1, 0}};
		const char *names[] = {"sphere", "box", "capsule", "cylinder", "cone", "torus"};
		size_t k;
		printf("primitives (posed):\n");
		for (k = 0; k < sizeof(ps) / sizeof(ps[0]); k++) {
			px_pose P = px_pose_identity();
			char what[64];
			P.t = px_v3(0.01, 0.02, 0.03);
			px_quat_from_axis_angle(px_v3(1, 2, 3), 0.7, &P.q);
			px_prim_model(&ps[k], &prim);
			px_model_set_pose(prim, P);
			snprintf(what, sizeof(what), "%s", names[k]);
			print_stats(what, run_queries(prim, cold, BM_NQ, 0, overhead, NULL));
			px_model_free(prim);
		}
	}
	free(times);
	free(cold);
	free(traj);
	free(cpts);
	return 0;
}
