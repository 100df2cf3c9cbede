/*
 * bench_pair_nurbs - a NURBS part against a link mesh and against
 * another NURBS part (px_pair_distance, geom/pair/pair_nurbs.c): the
 * certified descent of both hierarchies, cold over random separated
 * poses and coherent along a smooth path (1 mm steps), with the general
 * search by alternating projections (8 starts cold, last pair only
 * coherent) on the same poses in the same run as the peer. The part: a
 * rational bicubic sheet of 16 patches, 0.2 m across; the second part a
 * polynomial bicubic sheet of 4 patches, 0.16 m; the link: a torus mesh
 * (radii 0.06 and 0.02 m, 1,024 triangles). Figures: median and p99 in
 * microseconds (each pose's least of three identical calls), results
 * flagged possibly local, the median work (px_pair_result.iterations), and the poses where the
 * peer's answer lies more than 1 um above the certified one (missed the
 * global minimum). PX_BENCH_PAIR_N sets the poses (default 400).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "mesh_gen.h"
#include "pair_internal.h"
#include "px_arena.h"
#include "px_dist.h"
#include "px_mesh.h"
#include "px_nurbs.h"
#include "px_pair.h"
#include "sheet_gen.h"

static unsigned char arena_mem[1 << 20];

/* A wavy bicubic sheet of n x n control points over [-s, s]^2. */
static struct px_model *sheet(int n, double s, double amp, int rational)
{
	struct px_arena arena;
	struct px_nurbs_surf sf;
	struct px_model *m = NULL;
	double U[16], xyz[3 * 49], w[49];
	px_arena_init(&arena, arena_mem, sizeof(arena_mem));
	sheet_net(n, s, amp, U, xyz, w);
	if (px_nurbs_surf_init(&sf, &arena, 3, 3, n, n, U, n + 4, U, n + 4, xyz,
			       rational ? w : NULL, NULL) != PX_OK ||
	    px_nurbs_model_create(NULL, 0, &sf, 1, NULL, &m) != PX_OK)
		return NULL;
	return m;
}

static px_vec3 unit(double x, double y, double z)
{
	double l = sqrt(x * x + y * y + z * z);
	return px_v3(x / l, y / l, z / l);
}

static int cmp_d(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

/* Pose i: random separated (cold) or a step of the smooth path. */
static px_pose pose_at(int i, int path, double reach)
{
	px_pose P;
	if (path) {
		double t = 0.004 * i;
		px_quat_from_axis_angle(unit(1, 0.3, 0.2), 0.7 * t, &P.q);
		P.t = px_v3_scale(unit(cos(t), sin(t), 0.5 + 0.3 * sin(0.7 * t)), reach);
		return P;
	}
	px_quat_from_axis_angle(unit(urand() - 0.5, urand() - 0.5, urand() - 0.5), 6.3 * urand(),
				&P.q);
	P.t = px_v3_scale(unit(urand() - 0.5, urand() - 0.5, urand() - 0.5),
			  reach * (0.9 + 0.5 * urand()));
	return P;
}

struct run_out {
	double median, p99, work;
	int local, inter;
	double *d;
};

static void run(struct px_model *a, struct px_model *b, int n, int path, double reach,
		int old, double *t, struct run_out *o)
{
	struct px_pair_opts co = {1, 0, 0, 1, 0, 0};
	struct px_pair_result r;
	uint64_t save = rng;
	double *w = malloc((size_t)n * sizeof(double));
	int i;
	memset(&r, 0, sizeof(r));
	o->local = o->inter = 0;
	px__pair_nurbs_off = old;
	for (i = 0; i < n; i++) {
		int64_t t0;
		struct px_pair_result r0 = r;
		int rep;
		px_model_set_pose(b, pose_at(i, path, reach));
		/* the least of three identical calls (the same start state):
		 * the other processes' share of the machine mostly falls out */
		for (rep = 0; rep < 3; rep++) {
			r = r0;
			t0 = now_ns();
			px_pair_distance(a, b, path ? &co : NULL, &r);
			t0 = now_ns() - t0;
			if (rep == 0 || (double)t0 * 1e-3 < t[i])
				t[i] = (double)t0 * 1e-3;
		}
		o->local += r.local_only;
		o->inter += r.intersecting;
		o->d[i] = r.intersecting ? NAN : r.distance;
		w[i] = r.iterations;
	}
	px__pair_nurbs_off = 0;
	rng = save;
	qsort(t, (size_t)n, sizeof(*t), cmp_d);
	o->median = t[n / 2];
	o->p99 = t[(n * 99) / 100];
	qsort(w, (size_t)n, sizeof(*w), cmp_d);
	o->work = w[n / 2];
	free(w);
}

static void section(const char *name, struct px_model *a, struct px_model *b, int n,
		    double reach, double *t, double *d_new, double *d_old)
{
	int path;
	for (path = 0; path < 2; path++) {
		struct run_out on = {0, 0, 0, 0, 0, d_new}, oo = {0, 0, 0, 0, 0, d_old};
		int i, miss = 0;
		run(a, b, n, path, reach, 0, t, &on);
		run(a, b, n, path, reach, 1, t, &oo);
		for (i = 0; i < n; i++)
			miss += d_old[i] > d_new[i] + 1e-6;
		printf("%s, %s:\n", name, path ? "coherent (1 mm steps)" : "cold (random poses)");
		printf("  certified descent      median %8.2f us  p99 %8.2f us  local %d of %d; "
		       "work %.0f\n",
		       on.median, on.p99, on.local, n - on.inter, on.work);
		printf("  general search (peer)  median %8.2f us  p99 %8.2f us  local %d of %d; "
		       "%d poses above the certified distance; work %.0f\n",
		       oo.median, oo.p99, oo.local, n - oo.inter, miss, oo.work);
		printf("  median ratio peer / descent %.2f; %d poses overlapping\n",
		       oo.median / on.median, on.inter);
	}
}

int main(void)
{
	int n = (int)bench_env_long("bench_pair_nurbs", "PX_BENCH_PAIR_N", 400, 10, 100000);
	struct px_model *part = sheet(7, 0.1, 0.35, 1), *part2 = sheet(5, 0.08, 0.3, 0);
	struct px_model *link = NULL;
	struct gen_mesh g;
	double *t = malloc((size_t)n * sizeof(double)), *d1 = malloc((size_t)n * sizeof(double)),
	       *d2 = malloc((size_t)n * sizeof(double));

	memset(&g, 0, sizeof(g));
	if (!part || !part2 || !t || !d1 || !d2 || gen_torus(0.06, 0.02, 32, 16, &g) != 0 ||
	    px_mesh_model(g.xyz, g.nv, g.tri, g.nt, NULL, NULL, &link) != PX_OK) {
		printf("setup failed\n");
		return 1;
	}
	printf("NURBS pairs (%d poses): part = rational bicubic sheet, 16 patches, 0.2 m; "
	       "link = torus mesh, %zu triangles; part 2 = bicubic sheet, 4 patches\n",
	       n, g.nt);
	section("part / link mesh", part, link, n, 0.16, t, d1, d2);
	section("part / part 2", part, part2, n, 0.18, t, d1, d2);
	px_model_free(part);
	px_model_free(part2);
	px_model_free(link);
	gen_free(&g);
	free(t);
	free(d1);
	free(d2);
	return 0;
}
