/*
 * Arm benchmark: every link-obstacle clearance of the 6-joint URDF arm
 * (config/examples/robots/arm6, 7 link meshes) per 1 ms cycle along a
 * smooth joint path (px_urdf_robot_clearances(): exact model pairs),
 * against (a) a 100,000-point cloud (a table, a box and a ball sampled
 * with 1 mm noise), cold and coherent; (b) 20 mesh obstacles (spheres,
 * tori, boxes, L-prisms) around the arm, cold and coherent, and FCL
 * 0.7's distance() (OBBRSS) on the same pairs at the same poses in the
 * same run, with the ratio and the distances compared; (c) the cloud
 * replaced every 33 cycles (a 30 Hz camera) by a new frame of the same
 * scene with other noise: the first cycle after each swap. Median, p99
 * and max per cycle, in the thread's CPU time (the machine may be
 * shared: time spent preempted is not the cycle's). Run from the source
 * tree (reads the URDF).
 *
 * Environment: PX_BENCH_MODELS_FCL (path of bench/fcl_models.cpp's
 * program; default fcl_models next to this binary); PX_BENCH_ARM_PARTS
 * (the parts to run, default "abc": "b" alone profiles the mesh pairs);
 * PX_BENCH_ARM_MESH_CYCLES (cycles of part (b), default 400);
 * PX_BENCH_ARM_CLOUD_CYCLES (of parts (a) and (c), default 5000).
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "mesh_gen.h"
#include "px_cloud.h"
#include "px_mesh.h"
#include "px_pair.h"
#include "px_urdf.h"

#include "bench_util.h"

#define ARM "config/examples/robots/arm6/arm6.urdf"
#define NCYC 5000   /* cycles of the cloud runs */
#define NMESH 20
#define MCYC 400    /* cycles of the mesh runs (FCL's too), at most NCYC */
#define NPTS 100000
#define SWAP_EVERY 33
#define MAXB 16

static int64_t t_ns[NCYC];
static struct px_urdf_clearance cl[MAXB * NMESH];

/* The thread's CPU time in ns. */
static int64_t cpu_ns(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
	return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

static double gauss(void)
{
	double u = urand() + 1e-300, v = urand();
	return sqrt(-2.0 * log(u)) * cos(2.0 * M_PI * v);
}

/* Joint positions at cycle k (1 ms): slow sines, the pan sweeping the
 * arm past the obstacles. */
static void path_q(int k, double q[6])
{
	static const double amp[6] = {1.3, 0.35, 0.6, 0.8, 1.0, 1.2};
	static const double mid[6] = {0.0, -0.25, 0.9, -0.4, 0.3, 0.0};
	static const double hz[6] = {0.11, 0.17, 0.13, 0.23, 0.19, 0.29};
	double t = k * 1e-3;
	int j;
	for (j = 0; j < 6; j++)
		q[j] = mid[j] + amp[j] * sin(2.0 * M_PI * hz[j] * t + j);
}

/* The cloud scene's points: a table top below the reach, a box (a
 * person's torso) beside it, a ball above it; 1 mm Gaussian noise. */
static void scene_points(double *x)
{
	int i;
	for (i = 0; i < NPTS; i++) {
		double *p = x + 3 * (size_t)i, u = urand(), v = urand();
		if (i < 40000) { /* table: z = -0.1 over x 0.35..1.2, y -0.7..0.7 */
			p[0] = 0.35 + 0.85 * u;
			p[1] = -0.7 + 1.4 * v;
			p[2] = -0.1;
		} else if (i < 70000) { /* box 0.3 x 0.2 x 0.9 at (0.8, 0.75) */
			int f = (int)(urand() * 4);
			double s = -1.0 + 2.0 * u;
			p[2] = -0.1 + 0.9 * v;
			p[0] = 0.8 + (f < 2 ? (f ? 0.15 : -0.15) : 0.15 * s);
			p[1] = 0.75 + (f < 2 ? 0.1 * s : (f == 2 ? 0.1 : -0.1));
		} else { /* ball r 0.1 at (0.6, -0.55, 0.85) */
			double z = 2.0 * u - 1.0, ph = 2.0 * M_PI * v, rr = sqrt(1.0 - z * z);
			p[0] = 0.6 + 0.1 * rr * cos(ph);
			p[1] = -0.55 + 0.1 * rr * sin(ph);
			p[2] = 0.85 + 0.1 * z;
		}
		p[0] += 0.001 * gauss();
		p[1] += 0.001 * gauss();
		p[2] += 0.001 * gauss();
	}
}

/* The cloud scene as a model; build 0: the points only (the random
 * numbers drawn, so the mesh obstacles land where they do after the
 * cloud runs). */
static struct px_model *scene_cloud(int build)
{
	double *x = malloc(3 * (size_t)NPTS * sizeof(double));
	struct px_model *m = NULL;
	if (!x)
		return NULL;
	scene_points(x);
	if (build && px_cloud_model(x, NPTS, 0.0, NULL, &m) != PX_OK)
		m = NULL;
	free(x);
	return m;
}

static struct px_model *gen_model(int k, struct gen_mesh *g)
{
	struct px_model *m = NULL;
	static const double hb[3] = {0.08, 0.05, 0.12};
	int rc;
	switch (k % 4) {
	case 0:
		rc = gen_sphere(0.09, 16, 24, g);
		break;
	case 1:
		rc = gen_torus(0.1, 0.03, 32, 16, g);
		break;
	case 2:
		rc = gen_box(hb, 4, g);
		break;
	default:
		rc = gen_lprism(0.12, 0.08, g);
		break;
	}
	if (rc != 0 || px_mesh_model(g->xyz, g->nv, g->tri, g->nt, NULL, NULL, &m) != PX_OK)
		return NULL;
	return m;
}

static void report(const char *what, int n)
{
	qsort(t_ns, (size_t)n, sizeof(t_ns[0]), cmp_i64);
	printf("  %-44s median %8.2f us  p99 %8.2f  max %8.2f\n", what, t_ns[n / 2] / 1e3,
	       t_ns[(int)(0.99 * n)] / 1e3, t_ns[n - 1] / 1e3);
}

/* One cycle: pose, every pair; returns the time and adds the distances. */
static int64_t cycle(struct px_urdf_robot *r, int k, int coherent, int npairs, double *sum,
		     int *local)
{
	double q[6];
	int64_t t0;
	int n, i;
	path_q(k, q);
	t0 = cpu_ns();
	px_urdf_robot_set_q(r, q, NULL, 0);
	n = px_urdf_robot_clearances(r, NULL, coherent, cl, sizeof(cl) / sizeof(cl[0]), NULL);
	t0 = cpu_ns() - t0;
	if (n != npairs) {
		fprintf(stderr, "bench_arm: clearances: %d\n", n);
		exit(1);
	}
	for (i = 0; i < n; i++) {
		/* apart pairs only: an overlap's depth is no distance FCL
		 * reports alike */
		*sum += cl[i].distance_m > 0.0 ? cl[i].distance_m : 0.0;
		*local += cl[i].local_only;
	}
	return t0;
}

static void cloud_runs(struct px_urdf_robot *r, int nb, int ncyc)
{
	struct px_model *c[2];
	double sum = 0.0, mn = INFINITY;
	int k, local = 0, n = 0, coherent, over = 0;
	c[0] = scene_cloud(1);
	c[1] = scene_cloud(1);
	if (!c[0] || !c[1] || px_urdf_robot_set_obstacles(r, c, 1) != PX_OK) {
		fprintf(stderr, "bench_arm: cloud setup failed\n");
		exit(1);
	}
	printf("(a) %d bodies against a %d-point cloud, %d cycles along the path:\n", nb, NPTS, ncyc);
	for (coherent = 0; coherent < 2; coherent++) {
		for (k = 0; k < ncyc; k++) {
			int i;
			t_ns[k] = cycle(r, k, coherent && k > 0, nb, &sum, &local);
			for (i = 0; i < nb; i++) {
				mn = cl[i].distance_m < mn ? cl[i].distance_m : mn;
				over += cl[i].distance_m < 0.0;
			}
		}
		report(coherent ? "coherent (last cycle's pairs)" : "cold", ncyc);
	}
	printf("  pairs flagged local_only: %d; least clearance %.4f m; pairs with a point inside a "
	       "link: %d of %d\n", local, mn, over, 2 * ncyc * nb);
	printf("(c) the cloud replaced every %d cycles by a new frame (other noise):\n", SWAP_EVERY);
	for (k = 0; k < ncyc; k++) {
		int64_t t;
		if (k % SWAP_EVERY == 0)
			px_urdf_robot_replace_obstacle(r, 0, c[(k / SWAP_EVERY) % 2]);
		t = cycle(r, k, 1, nb, &sum, &local);
		if (k % SWAP_EVERY == 0)
			t_ns[n++] = t;
	}
	report("first cycle after a swap", n);
	px_model_free(c[0]);
	px_model_free(c[1]);
}

/* FCL on the same pairs: the meshes and every cycle's poses to a file,
 * fcl_models arm FILE times them. */
static int fcl_arm(const char *argv0, const char *file, double *med, double *p99, double *mx,
		   double *sum, int *overlaps)
{
	char path[4096], line[256];
	FILE *f;
	int ok;
	fcl_path(argv0, path, sizeof(path));
	if (access(path, X_OK) != 0) {
		printf("  FCL: reference program %s not built (Debian libfcl-dev not installed): "
		       "no comparison\n", path);
		return 0;
	}
	snprintf(path + strlen(path), sizeof(path) - strlen(path), " arm %s", file);
	f = popen(path, "r");
	if (!f)
		return 0;
	while (fgets(line, sizeof(line), f)) {
		sscanf(line, "arm_median_ns %lf", med);
		sscanf(line, "arm_p99_ns %lf", p99);
		sscanf(line, "arm_max_ns %lf", mx);
		sscanf(line, "arm_sum %lf", sum);
		sscanf(line, "arm_overlaps %d", overlaps);
	}
	ok = pclose(f) == 0 && *med > 0;
	if (!ok)
		printf("  FCL: %s failed\n", path);
	return ok;
}

static void write_model(FILE *f, const struct px_model *m)
{
	size_t nt = px_mesh_triangle_count(m), t;
	fprintf(f, "%zu\n", nt);
	for (t = 0; t < nt; t++) {
		px_vec3 v[3];
		int k;
		px_mesh_triangle(m, t, v);
		for (k = 0; k < 3; k++)
			fprintf(f, "%.17g %.17g %.17g\n", v[k].x, v[k].y, v[k].z);
	}
}

static void write_pose(FILE *f, px_pose P)
{
	fprintf(f, "%.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", P.t.x, P.t.y, P.t.z, P.q.w, P.q.x,
		P.q.y, P.q.z);
}

static void mesh_runs(struct px_urdf_robot *r, int nb, const char *argv0, int mcyc)
{
	struct px_model *obs[NMESH];
	struct gen_mesh g[NMESH];
	double sum[2] = {0, 0}, fmed = 0, fp99 = 0, fmax = 0, fsum = 0, med[2];
	char file[] = "/tmp/px-bench-arm.XXXXXX";
	int i, k, coherent, local = 0, fd, fover = 0, over = 0;
	FILE *f;
	for (i = 0; i < NMESH; i++) {
		/* a ring around the arm: 0.55 to 0.95 m out, 0.1 to 0.9 m up */
		double a = 2.0 * M_PI * i / NMESH, rad = 0.55 + 0.4 * urand();
		px_pose P;
		memset(&g[i], 0, sizeof(g[i]));
		obs[i] = gen_model(i, &g[i]);
		if (!obs[i]) {
			fprintf(stderr, "bench_arm: mesh setup failed\n");
			exit(1);
		}
		P.t = px_v3(rad * cos(a), rad * sin(a), 0.1 + 0.8 * urand());
		{
			px_quat q0 = {gauss(), gauss(), gauss(), gauss()};
			if (px_quat_normalize(q0, &P.q) != PX_OK)
				P.q = px_quat_identity();
		}
		px_model_set_pose(obs[i], P);
	}
	if (px_urdf_robot_set_obstacles(r, obs, NMESH) != PX_OK) {
		fprintf(stderr, "bench_arm: obstacles\n");
		exit(1);
	}
	printf("(b) %d bodies against %d mesh obstacles (%d pairs), %d cycles:\n", nb, NMESH,
	       nb * NMESH, mcyc);
	for (coherent = 0; coherent < 2; coherent++) {
		for (k = 0; k < mcyc; k++) {
			t_ns[k] = cycle(r, 10 * k, coherent && k > 0, nb * NMESH, &sum[coherent], &local);
			for (i = 0; i < nb * NMESH && !coherent; i++)
				over += cl[i].distance_m <= 0.0;
		}
		report(coherent ? "coherent (last cycle's pairs)" : "cold", mcyc);
		med[coherent] = t_ns[mcyc / 2];
	}
	fd = mkstemp(file);
	f = fd >= 0 ? fdopen(fd, "w") : NULL;
	if (!f) {
		printf("  FCL: cannot write the workload\n");
	} else {
		fprintf(f, "%d %d %d\n", nb, NMESH, mcyc);
		for (i = 0; i < nb; i++)
			write_model(f, px_urdf_robot_body(r, i)->model);
		for (i = 0; i < NMESH; i++)
			write_model(f, obs[i]);
		for (i = 0; i < NMESH; i++)
			write_pose(f, px_model_pose(obs[i]));
		for (k = 0; k < mcyc; k++) {
			double q[6];
			path_q(10 * k, q);
			px_urdf_robot_set_q(r, q, NULL, 0);
			for (i = 0; i < nb; i++)
				write_pose(f, px_model_pose(px_urdf_robot_body(r, i)->model));
		}
		fclose(f);
		if (fcl_arm(argv0, file, &fmed, &fp99, &fmax, &fsum, &fover)) {
			printf("  %-44s median %8.2f us  p99 %8.2f  max %8.2f\n",
			       "FCL 0.7 OBBRSS distance(), same pairs", fmed / 1e3, fp99 / 1e3,
			       fmax / 1e3);
			printf("  FCL / proxima per cycle (median): cold %.1fx, coherent %.1fx\n",
			       fmed / (double)med[0], fmed / (double)med[1]);
			printf("  sum of the distances of apart pairs: proxima cold %.12g, coherent "
			       "%.12g, FCL %.12g; overlapping pairs: %d, FCL %d\n",
			       sum[0], sum[1], fsum, over, fover);
		}
		unlink(file);
	}
	printf("  pairs flagged local_only: %d\n", local);
	for (i = 0; i < NMESH; i++) {
		px_model_free(obs[i]);
		gen_free(&g[i]);
	}
}

int main(int argc, char **argv)
{
	const char *pk[1] = {"config/examples/robots"};
	struct px_urdf_opts o;
	struct px_urdf_error e;
	struct px_urdf *u = NULL;
	struct px_urdf_robot *r = NULL;
	const char *parts = getenv("PX_BENCH_ARM_PARTS"), *mc = getenv("PX_BENCH_ARM_MESH_CYCLES");
	const char *cc = getenv("PX_BENCH_ARM_CLOUD_CYCLES");
	int nb, mcyc = mc ? atoi(mc) : MCYC, ccyc = cc ? atoi(cc) : NCYC;
	(void)argc;
	memset(&o, 0, sizeof(o));
	o.package_paths = pk;
	o.n_package_paths = 1;
	if (px_urdf_load(ARM, &o, &u, &e) != PX_OK ||
	    px_urdf_robot_create(u, "base_link", "tool0", px_pose_identity(), &r, &e) != PX_OK) {
		printf("bench_arm: %s (run from the source tree, built with libxml2 and assimp)\n",
		       e.msg);
		px_urdf_free(u);
		return 0;
	}
	px_urdf_free(u);
	nb = px_urdf_robot_body_count(r);
	if (nb > MAXB)
		return 1;
	if (!parts)
		parts = "abc";
	if (mcyc < 1 || mcyc > NCYC)
		mcyc = MCYC;
	if (ccyc < 1 || ccyc > NCYC)
		ccyc = NCYC;
	if (strchr(parts, 'a') || strchr(parts, 'c')) {
		cloud_runs(r, nb, ccyc);
	} else {
		scene_cloud(0);
		scene_cloud(0);
	}
	if (strchr(parts, 'b'))
		mesh_runs(r, nb, argv[0], mcyc);
	px_urdf_robot_free(r);
	return 0;
}
