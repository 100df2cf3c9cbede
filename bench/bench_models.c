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
#include "px_pair.h"
#include "px_prim.h"
#include "px_scene.h"

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
	double cpu_mean; /* thread CPU time per query, < 0 when not measured */
};

/* Thread CPU time: on a shared machine the wall-clock figures include
 * time the thread spent preempted; this one does not. */
static int64_t cpu_ns(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
	return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

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
	s.cpu_mean = -1.0;
	return s;
}

static void print_stats(const char *what, struct stats s)
{
	printf("  %-34s median %8.3f us  p90 %8.3f  p99 %8.3f  max %8.3f  mean %8.3f",
	       what, s.median / 1e3, s.p90 / 1e3, s.p99 / 1e3, s.max / 1e3, s.mean / 1e3);
	if (s.cpu_mean >= 0.0)
		printf("  cpu mean %.3f", s.cpu_mean / 1e3);
	printf("\n");
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
	struct stats st;
	int i, hint = -1;
	double s = 0;
	int64_t c0 = cpu_ns(), c1;
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
	c1 = cpu_ns();
	if (sum_abs)
		*sum_abs = s;
	st = summarize(times, n, overhead);
	st.cpu_mean = fmax(0.0, (double)(c1 - c0) / n - 2.0 * overhead);
	return st;
}

/*
 * Two models on the same cold points in one pass, each point put to both
 * in an order drawn at random: the load of the machine falls on both
 * alike, so the ratio of their medians is far steadier than two passes
 * one after the other (on this shared machine those differ by 10-20 %
 * from run to run). Both working sets are in memory together, so each
 * median is above a lone run's.
 */
static void run_ab(const struct px_model *m0, const struct px_model *m1, const double *pts,
		   int n, double overhead, struct stats *s0, struct stats *s1)
{
	double *t1 = malloc((size_t)n * sizeof(double));
	uint64_t rs = 0x2545f4914f6cdd1dull;
	int i;
	if (!t1)
		return;
	for (i = 0; i < n; i++) {
		px_vec3 p = px_v3(pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]);
		struct px_model_result r;
		int first = (int)(bm_next(&rs) & 1), k;
		for (k = 0; k < 2; k++) {
			int which = k ^ first;
			int64_t a = now_ns();
			px_model_query(which ? m1 : m0, p, &r);
			(which ? t1 : times)[i] = (double)(now_ns() - a);
		}
	}
	*s0 = summarize(times, n, overhead);
	*s1 = summarize(t1, n, overhead);
	s0->cpu_mean = s1->cpu_mean = -1.0;
	free(t1);
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

/* FCL's mesh-to-mesh distance on the pair workload (fcl_models pair). */
struct fcl_pair_out {
	int ok;
	double median, p99, sum;
};

static struct fcl_pair_out run_fcl_pair(const char *argv0)
{
	struct fcl_pair_out o;
	char path[4096], dir[4096], line[256];
	const char *env = getenv("PX_BENCH_MODELS_FCL");
	FILE *f;
	memset(&o, 0, sizeof(o));
	if (env && *env) {
		snprintf(path, sizeof(path), "%s pair", env);
	} else {
		snprintf(dir, sizeof(dir), "%s", argv0);
		snprintf(path, sizeof(path), "%s/fcl_models", dirname(dir));
		if (access(path, X_OK) != 0)
			return o;
		snprintf(path + strlen(path), sizeof(path) - strlen(path), " pair");
	}
	f = popen(path, "r");
	if (!f)
		return o;
	while (fgets(line, sizeof(line), f)) {
		sscanf(line, "pair_median_ns %lf", &o.median);
		sscanf(line, "pair_p99_ns %lf", &o.p99);
		sscanf(line, "pair_sum %lf", &o.sum);
	}
	o.ok = pclose(f) == 0 && o.median > 0;
	return o;
}

int main(int argc, char **argv)
{
	struct gen_mesh g;
	struct px_model *mesh, *cloud, *prim;
	struct px_mesh_report rp;
	double overhead, *cold, *traj, *cpts, sum_cold = 0, sum_traj = 0;
	struct stats sc, st, stc, stcache;
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
	printf("bench_models: timer overhead %.0f ns per query (subtracted); 'cpu mean' is "
	       "thread CPU time per query,\n  which leaves out time preempted by other "
	       "processes on a shared machine\n", overhead);

	/* ---- mesh ---- */
	if (gen_torus(BM_R, BM_r, BM_NU, BM_NV, &g) != 0)
		return 1;
	{
		/* the same mesh with the optional hint grid, for its cost and
		 * gain (off by default: see px_mesh.h) */
		struct px_mesh_opts nog;
		struct px_model *m0;
		double ms0;
		memset(&nog, 0, sizeof(nog));
		nog.grid_cells = 64L * 64 * 64;
		t0 = now_ns();
		if (px_mesh_model(g.xyz, g.nv, g.tri, g.nt, &nog, &rp, &m0) != PX_OK)
			return 1;
		ms0 = (now_ns() - t0) / 1e6;
		t0 = now_ns();
		if (px_mesh_model(g.xyz, g.nv, g.tri, g.nt, NULL, &rp, &mesh) != PX_OK) {
			printf("mesh build failed: %s\n", rp.message);
			return 1;
		}
		printf("mesh: torus, %zu triangles, closed %d, depth %d, %.1f MB, built in %.1f ms\n",
		       rp.n_triangles, rp.closed, rp.depth, px_model_memory_bytes(mesh) / 1e6,
		       (now_ns() - t0) / 1e6);
		/* two build times rather than their difference, which the
		 * noise of a shared machine can make negative */
		printf("  the same mesh with a hint grid (grid_cells = 64^3): %.1f MB (grid %.0f kB), "
		       "built in %.1f ms\n",
		       px_model_memory_bytes(m0) / 1e6,
		       (double)(px_model_memory_bytes(m0) - px_model_memory_bytes(mesh)) / 1e3, ms0);
		sc = run_queries(mesh, cold, BM_NQ, 0, overhead, &sum_cold);
		print_stats("cold (independent points)", sc);
		print_stats("cold, with the hint grid", run_queries(m0, cold, BM_NQ, 0, overhead, NULL));
		{
			struct stats a = {0}, b = {0};
			run_ab(mesh, m0, cold, BM_NQ, overhead, &a, &b);
			printf("  the same two interleaved point by point (one pass, random order): "
			       "median %.3f us without the grid, %.3f us with it (%.2fx)\n",
			       a.median / 1e3, b.median / 1e3, b.median / fmax(a.median, 1.0));
		}
		px_model_free(m0);
	}
	{
		/* the two halves of the cold set on their own */
		double *half = malloc(3 * (BM_NQ / 2) * sizeof(double));
		int h;
		if (!half)
			return 1;
		for (h = 0; h < 2; h++) {
			for (i = 0; i < BM_NQ / 2; i++)
				memcpy(half + 3 * i, cold + 3 * (2 * i + h), 3 * sizeof(double));
			print_stats(h ? "  of which free space" : "  of which near the surface",
				    run_queries(mesh, half, BM_NQ / 2, 0, overhead, NULL));
		}
		free(half);
	}
	stc = run_queries(mesh, traj, BM_NQ, 0, overhead, NULL);
	print_stats("trajectory, cold", stc);
	st = run_queries(mesh, traj, BM_NQ, 1, overhead, &sum_traj);
	print_stats("trajectory, coherent (hint)", st);
	{
		struct px_model_cache cache;
		struct px_model_result r;
		double s2 = 0;
		px_model_cache_init(&cache, 0.0);
		for (i = 0; i < BM_NQ; i++) {
			px_vec3 p = px_v3(traj[3 * i], traj[3 * i + 1], traj[3 * i + 2]);
			int64_t a = now_ns();
			px_model_query_cached(mesh, p, &cache, &r);
			times[i] = (double)(now_ns() - a);
			s2 += fabs(r.distance);
		}
		stcache = summarize(times, BM_NQ, overhead);
		print_stats("trajectory, coherent (cache)", stcache);
		printf("  %-34s %lu refills in %d queries; sum of |distance| %.12g (hint path %.12g)\n",
		       "", px_model_cache_refills(&cache), BM_NQ, s2, sum_traj);
	}
	printf("  targets: cold median <= 2 us: %s; coherent median <= 0.5 us: %s\n",
	       sc.median <= 2000 ? "met" : "NOT met",
	       fmin(st.median, stcache.median) <= 500 ? "met" : "NOT met");
	{
		struct fcl_out fo = run_fcl(argv[0]);
		if (fo.ok) {
			printf("  FCL 0.7 OBBRSS: built in %.1f ms; cold median %.3f us, "
			       "trajectory median %.3f us\n",
			       fo.build_ms, fo.cold_median / 1e3, fo.traj_median / 1e3);
			printf("  same answers: sum of |distance| cold %.12g vs FCL %.12g, "
			       "trajectory %.12g vs FCL %.12g\n",
			       sum_cold, fo.cold_sum, sum_traj, fo.traj_sum);
			printf("  speed-up over FCL: cold %.1fx, coherent %.1fx (hint) %.1fx (cache) "
			       "(target >= 5x)\n",
			       fo.cold_median / fmax(sc.median, 1.0),
			       fo.traj_median / fmax(st.median, 1.0),
			       fo.traj_median / fmax(stcache.median, 1.0));
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
	print_stats("trajectory, coherent (hint)", run_queries(cloud, traj, BM_NQ, 1, overhead, NULL));
	{
		struct px_model_cache cache;
		struct px_model_result r;
		px_model_cache_init(&cache, 0.0);
		for (i = 0; i < BM_NQ; i++) {
			px_vec3 p = px_v3(traj[3 * i], traj[3 * i + 1], traj[3 * i + 2]);
			int64_t a = now_ns();
			px_model_query_cached(cloud, p, &cache, &r);
			times[i] = (double)(now_ns() - a);
		}
		print_stats("trajectory, coherent (cache)", summarize(times, BM_NQ, overhead));
	}
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
	/* ---- model to model ---- */
	{
		struct gen_mesh g1, g2;
		struct px_model *ma, *mb, *ca, *cb, *sp, *cl, *k1, *k2;
		struct px_prim cap1 = {PX_PRIM_CAPSULE, 0.04, 0.1, 0}, cap2 = {PX_PRIM_CAPSULE, 0.03, 0.08, 0};
		struct px_prim cyl = {PX_PRIM_CYLINDER, 0.05, 0.1, 0}, box = {PX_PRIM_BOX, 0.05, 0.08, 0.1};
		struct px_prim sph = {PX_PRIM_SPHERE, 0.05, 0, 0};
		struct px_pair_opts o1 = {1, 64, 1e-12, 1, 0, 0}, o8 = {8, 64, 1e-12, 0, 0, 0};
		struct px_pair_opts o1l = {1, 64, 1e-12, 1, 0, 1};
		struct px_pair_result r;
		const int NP = BM_PAIR_N;
		double mesh_sum = 0.0, mesh_median = 0.0;
		gen_torus(0.1, 0.03, 64, 32, &g1);
		gen_sphere(0.08, 32, 64, &g2);
		px_mesh_model(g1.xyz, g1.nv, g1.tri, g1.nt, NULL, NULL, &ma);
		px_mesh_model(g2.xyz, g2.nv, g2.tri, g2.nt, NULL, NULL, &mb);
		/* the sphere mesh's vertices as a scanned cloud */
		px_cloud_model(g2.xyz, g2.nv, 0.0, NULL, &cl);
		px_prim_model(&cyl, &ca);
		px_prim_model(&box, &cb);
		px_prim_model(&sph, &sp);
		px_prim_model(&cap1, &k1);
		px_prim_model(&cap2, &k2);
		printf("model to model (%d poses on a circle, 1 mm apart):\n", NP);
		{
			const struct {
				const char *name;
				struct px_model *a, *b;
				const struct px_pair_opts *o;
			} P[] = {{"mesh torus 4k / mesh sphere 4k exact", ma, mb, &o8},
				 {"same, coherent (last pair first)", ma, mb, &o1},
				 {"same, coherent, local_ok (tracking)", ma, mb, &o1l},
				 {"mesh torus 4k / box (BVH + GJK)", ma, cb, &o8},
				 {"same, coherent", ma, cb, &o1},
				 {"mesh torus 4k / capsule (closed form)", ma, k1, &o8},
				 {"mesh torus 4k / cloud 2k, 8 starts", ma, cl, &o8},
				 {"sphere / mesh torus (exact)", sp, ma, &o8},
				 {"cylinder / box (GJK)", ca, cb, &o8},
				 {"capsule / capsule (closed form)", k1, k2, &o8},
				 {"capsule / box (closed form)", k1, cb, &o8}};
			size_t k;
			for (k = 0; k < sizeof(P) / sizeof(P[0]); k++) {
				int local = 0;
				double sum = 0.0;
				struct stats s;
				memset(&r, 0, sizeof(r));
				for (i = 0; i < NP; i++) {
					px_pose Pb = px_pose_identity();
					double tr[3], ax[3], ang;
					int64_t a;
					bm_pair_pose(i, tr, ax, &ang);
					Pb.t = px_v3(tr[0], tr[1], tr[2]);
					px_quat_from_axis_angle(px_v3(ax[0], ax[1], ax[2]), ang, &Pb.q);
					px_model_set_pose(P[k].b, Pb);
					a = now_ns();
					px_pair_distance(P[k].a, P[k].b, P[k].o, &r);
					times[i] = (double)(now_ns() - a);
					local += r.local_only;
					sum += r.distance;
				}
				s = summarize(times, NP, overhead);
				print_stats(P[k].name, s);
				printf("  %-34s %d of %d results flagged possibly local\n", "", local, NP);
				if (k == 0) {
					mesh_sum = sum;
					mesh_median = s.median;
				}
			}
		}
		{
			struct fcl_pair_out fp = run_fcl_pair(argv[0]);
			if (!fp.ok) {
				printf("  FCL mesh-mesh distance: reference program not built or failed: no "
				       "comparison\n");
			} else {
				printf("  %-34s median %8.3f us  p99 %8.3f\n", "FCL 0.7 OBBRSS, same mesh pairs",
				       fp.median / 1e3, fp.p99 / 1e3);
				printf("  %-34s FCL / proxima median %.1fx; distance sums %.12g vs %.12g (%s)\n",
				       "", fp.median / fmax(mesh_median, 1.0), fp.sum, mesh_sum,
				       fabs(fp.sum - mesh_sum) <= 1e-6 * fabs(mesh_sum) ? "agree" : "DIFFER");
			}
		}
		{
			/* overlapping pairs: penetration depth out of the same call */
			const struct {
				const char *name;
				struct px_model *a, *b;
			} P[] = {{"overlap: cylinder / box (EPA)", ca, cb},
				 {"overlap: mesh torus / sphere (deepest pt)", ma, mb}};
			size_t k;
			px_model_set_pose(ma, px_pose_identity()); /* moved above */
			for (k = 0; k < sizeof(P) / sizeof(P[0]); k++) {
				int pen = 0, approx = 0;
				double dsum = 0;
				memset(&r, 0, sizeof(r));
				for (i = 0; i < NP; i++) {
					px_pose Pb = px_pose_identity();
					int64_t a;
					double rr = k ? 0.1 : 0.06;
					Pb.t = px_v3(rr * cos(4e-3 * i), rr * sin(4e-3 * i), 0.01);
					px_quat_from_axis_angle(px_v3(1, 1, 0), 2e-3 * i, &Pb.q);
					px_model_set_pose(P[k].b, Pb);
					a = now_ns();
					px_pair_distance(P[k].a, P[k].b, &o8, &r);
					times[i] = (double)(now_ns() - a);
					pen += r.intersecting && r.depth > 0.0;
					approx += r.depth_approx;
					dsum += r.depth;
				}
				print_stats(P[k].name, summarize(times, NP, overhead));
				printf("  %-34s %d of %d with a depth (mean %.2f mm), %d approximate\n", "",
				       pen, NP, 1e3 * dsum / NP, approx);
			}
		}
		px_model_free(ma);
		px_model_free(mb);
		px_model_free(ca);
		px_model_free(cb);
		px_model_free(k1);
		px_model_free(k2);
		px_model_free(sp);
		px_model_free(cl);
		gen_free(&g1);
		gen_free(&g2);
	}

	/* ---- scenes ---- */
	{
		int sizes[2] = {20, 200}, si;
		for (si = 0; si < 2; si++) {
			int nm = sizes[si], k;
			struct px_scene *scn;
			struct px_model **ms = calloc((size_t)nm, sizeof(*ms));
			struct px_model *tool;
			struct px_prim cap = {PX_PRIM_CAPSULE, 0.02, 0.05, 0};
			struct px_scene_hit hits[64];
			struct gen_mesh gs;
			struct stats su, stool, sn;
			double *t2 = malloc(BM_NQ * sizeof(double)), *t3 = malloc(BM_NQ * sizeof(double));
			uint64_t sd = 99;
			const int NQ = 5000;
			gen_sphere(0.05, 16, 32, &gs); /* 960 triangles */
			px_scene_create((size_t)nm, &scn);
			for (k = 0; k < nm; k++) {
				px_pose P = px_pose_identity();
				/* models spread in a cube whose volume grows with
				 * their number (constant density) */
				double e = 0.5 * cbrt(nm / 20.0);
				if (k % 3 == 2) {
					px_mesh_model(gs.xyz, gs.nv, gs.tri, gs.nt, NULL, NULL, &ms[k]);
				} else {
					struct px_prim pr = {k % 3 ? PX_PRIM_BOX : PX_PRIM_CYLINDER, 0.04, 0.06, 0.05};
					px_prim_model(&pr, &ms[k]);
				}
				P.t = px_v3(e * (2 * bm_unit(&sd) - 1), e * (2 * bm_unit(&sd) - 1),
					    e * (2 * bm_unit(&sd) - 1));
				px_quat_from_axis_angle(px_v3(bm_unit(&sd), bm_unit(&sd), 1), 3 * bm_unit(&sd), &P.q);
				px_model_set_pose(ms[k], P);
				px_scene_add_kept(scn, ms[k], NULL);
			}
			px_prim_model(&cap, &tool);
			for (i = 0; i < NQ; i++) {
				px_pose P = px_pose_identity();
				double e = 0.5 * cbrt(nm / 20.0);
				int64_t a;
				/* every cycle: one model moves, the scene updates */
				px_pose Q = px_model_pose(ms[i % nm]);
				Q.t.x += 1e-4;
				px_model_set_pose(ms[i % nm], Q);
				a = now_ns();
				px_scene_update(scn);
				times[i] = (double)(now_ns() - a);
				P.t = px_v3(e * cos(1e-3 * i), e * sin(1.3e-3 * i), 0.5 * e * sin(0.7e-3 * i));
				px_model_set_pose(tool, P);
				a = now_ns();
				px_scene_tool(scn, tool, 0.05, NULL, hits, 64, NULL);
				t2[i] = (double)(now_ns() - a);
				a = now_ns();
				px_scene_nearest(scn, P.t, INFINITY, hits);
				t3[i] = (double)(now_ns() - a);
			}
			printf("scene of %d models (1/3 meshes of 960 triangles, boxes, cylinders):\n", nm);
			su = summarize(times, NQ, overhead);
			stool = summarize(t2, NQ, overhead);
			sn = summarize(t3, NQ, overhead);
			print_stats("update (poses -> hierarchy)", su);
			print_stats("capsule tool, within 5 cm", stool);
			print_stats("nearest model to a point", sn);
			if (nm == 20)
				printf("  target: tool against a 20-model scene <= 20 us: %s\n",
				       stool.median + su.median <= 20000 ? "met (update + query)" : "NOT met");
			px_scene_free(scn);
			for (k = 0; k < nm; k++)
				px_model_free(ms[k]);
			px_model_free(tool);
			free(ms);
			free(t2);
			free(t3);
			gen_free(&gs);
		}
	}

	free(times);
	free(cold);
	free(traj);
	free(cpts);
	return 0;
}
