/*
 * Distance core benchmark: per-query time (median, p99, max) for random
 * points in the enlarged bounding box of representative curves, the
 * root-iteration histogram, pieces solved per query, and model memory.
 * Prints figures only; nothing here is a pass/fail test.
 *
 *   bench_dist [PREFIX [N [tail]]]
 * runs only the models whose name starts with PREFIX, N queries each
 * (repeatable instruction counts: valgrind --tool=callgrind
 * --toggle-collect=px_dist_query_ws build/bench/bench_dist "bicubic patch"
 * 4000, which counts the 1000 warm-up queries too), and with "tail" lists
 * the slowest points (best of five runs each) with what they cost.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "px_arena.h"
#include "px_dist.h"
#include "px_nurbs.h"

#include "bench_util.h"

#define NQ_MAX 20000

/* Optional arguments: a name prefix, the query count (for instruction
 * counts under callgrind), and "tail" to list the slowest queries. */
static const char *filter;
static int NQ = NQ_MAX;
static int show_tail;

struct slow {
	int64_t ns;
	int i;
};

static int cmp_slow(const void *a, const void *b)
{
	int64_t x = ((const struct slow *)a)->ns, y = ((const struct slow *)b)->ns;
	return (x < y) - (x > y);
}

static void run(const char *name, const struct px_nurbs_curve *c, int nc,
		const struct px_nurbs_surf *sf, int ns, const struct px_dist_opts *o)
{
	static int64_t t[NQ_MAX];
	static px_vec3 q[NQ_MAX];
	static struct slow sl[NQ_MAX];
	struct px_dist_model *m;
	struct px_dist_info info;
	struct px_dist_result r;
	long hist[8] = {0};
	long solved = 0, unc = 0;
	double mean_ns;
	int64_t t0;
	int i, rc;

	t0 = now_ns();
	rc = px_dist_model_create(c, nc, sf, ns, o, &m);
	if (rc) {
		printf("%s: prepare failed: %s\n", name, px_strerror(rc));
		return;
	}
	t0 = now_ns() - t0;
	px_dist_model_info(m, &info);
	{
		px_vec3 lo = info.bounds.min, hi = info.bounds.max;
		px_vec3 e = px_v3_scale(px_v3_sub(hi, lo), 0.25);
		lo = px_v3_sub(lo, e);
		hi = px_v3_add(hi, e);
		for (i = 0; i < NQ_MAX; i++)
			q[i] = px_v3(lo.x + (hi.x - lo.x) * urand(),
				     lo.y + (hi.y - lo.y) * urand(),
				     lo.z + (hi.z - lo.z) * urand());
	}
	/* Filtered out: the points were still drawn, so that the models
	 * after this one are the same as in a full run. */
	if (filter && strncmp(name, filter, strlen(filter))) {
		px_dist_model_free(m);
		return;
	}
	for (i = 0; i < 1000 && i < NQ; i++) /* warm the caches */
		px_dist_query(m, q[i], &r);
	for (i = 0; i < NQ; i++) {
		int64_t a = now_ns();
		px_dist_query(m, q[i], &r);
		t[i] = now_ns() - a;
		hist[r.iters < 7 ? r.iters : 7]++;
		solved += r.pieces_solved;
		unc += !r.certified;
	}
	if (show_tail) {
		/* Best of five per point: what is left is the point's own
		 * cost, not the machine's noise. */
		for (i = 0; i < NQ; i++) {
			int k;
			sl[i].i = i;
			sl[i].ns = INT64_MAX;
			for (k = 0; k < 5; k++) {
				int64_t a = now_ns();
				px_dist_query(m, q[i], &r);
				a = now_ns() - a;
				sl[i].ns = a < sl[i].ns ? a : sl[i].ns;
			}
		}
		qsort(sl, NQ, sizeof(sl[0]), cmp_slow);
		printf("%-28s slowest (best of 5): ns, point, dist, pieces solved, "
		       "root iterations, cells\n", name);
		for (i = 0; i < 12 && i < NQ; i++) {
			px_vec3 x = q[sl[i].i];
			px_dist_query(m, x, &r);
			printf("  %7lld  (%.6f, %.6f, %.6f)  d %.6f  solved %d  iters %d  cells %d  piece %d (u %.9f v %.9f)\n",
			       (long long)sl[i].ns, x.x, x.y, x.z, r.dist, r.pieces_solved,
			       r.iters, r.cells_visited, r.piece, r.u, r.v);
		}
		printf("%-28s best-of-5 p50 %lld  p99 %lld\n", "",
		       (long long)sl[NQ / 2].ns, (long long)sl[NQ / 100].ns);
	}
	qsort(t, NQ, sizeof(t[0]), cmp_i64);
	{
		/* Mean of all but the slowest 0.1 %: those are the machine's
		 * (preemption), not the query's. */
		int64_t sum = 0;
		int nm = NQ - NQ / 1000;
		for (i = 0; i < nm; i++)
			sum += t[i];
		mean_ns = (double)sum / nm;
	}
	printf("%-28s prepare %.2f ms, %d pieces, grid %dx%dx%d, %zu bytes\n",
	       name, t0 / 1e6, info.n_pieces, info.grid[0], info.grid[1],
	       info.grid[2], info.bytes);
	printf("%-28s per query ns: median %lld  p99 %lld  max %lld  mean %.0f; "
	       "pieces solved %.2f/query; uncertified %ld\n",
	       "", (long long)t[NQ / 2], (long long)t[NQ * 99 / 100],
	       (long long)t[NQ - 1], mean_ns, (double)solved / NQ, unc);
	printf("%-28s root iterations per query:", "");
	for (i = 0; i < 8; i++)
		printf(" %s%d:%.1f%%", i == 7 ? ">=" : "", i, 100.0 * hist[i] / NQ);
	printf("\n");
	px_dist_model_free(m);
}

int main(int argc, char **argv)
{
	static unsigned char mem[1 << 20];
	struct px_arena a;
	struct px_nurbs_curve c[2];
	struct px_dist_opts paper, coarse, surf_paper;
	int k2;
	const double s = sqrt(0.5);
	double k8[12] = {0, 0, 0, 0, 0.2, 0.4, 0.6, 0.8, 1, 1, 1, 1};
	double xyz8[24], w8[8];
	double kc[12] = {0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1};
	double xyzc[27] = {1, 0, 0, 1, 1, 0, 0, 1, 0, -1, 1, 0, -1, 0, 0,
			   -1, -1, 0, 0, -1, 0, 1, -1, 0, 1, 0, 0};
	double wc[9] = {1, s, 1, s, 1, s, 1, s, 1};
	int i;

	if (argc > 1 && argv[1][0])
		filter = argv[1];
	if (argc > 2) {
		NQ = atoi(argv[2]);
		NQ = NQ < 100 ? 100 : (NQ > NQ_MAX ? NQ_MAX : NQ);
	}
	show_tail = argc > 3 && !strcmp(argv[3], "tail");
	px_arena_init(&a, mem, sizeof(mem));
	for (i = 0; i < 8; i++) {
		xyz8[3 * i] = i / 7.0;
		xyz8[3 * i + 1] = urand() - 0.5;
		xyz8[3 * i + 2] = 0.5 * (urand() - 0.5);
		w8[i] = 1.0;
	}
	px_nurbs_curve_init(&c[0], &a, 3, 8, k8, 12, xyz8, w8, NULL);
	px_dist_opts_default(&paper);
	paper.decomp_tol = 0.05; /* the paper's recommended curve setting */
	paper.jitter = 0.8;
	px_dist_opts_default(&surf_paper);
	surf_paper.decomp_tol = 0.1; /* the paper's surface setting */
	surf_paper.jitter = 0.8;
	px_dist_opts_default(&coarse);
	coarse.decomp_tol = 0.25;
	run("cubic B-spline (8 ctrl)", &c[0], 1, NULL, 0, NULL);
	run("  paper settings 5%/1%", &c[0], 1, NULL, 0, &paper);
	run("  coarse 25%/1%", &c[0], 1, NULL, 0, &coarse);
	for (i = 0; i < 8; i++)
		w8[i] = 0.3 + 3.0 * urand();
	px_nurbs_curve_init(&c[1], &a, 3, 8, k8, 12, xyz8, w8, NULL);
	run("rational cubic (8 ctrl)", &c[1], 1, NULL, 0, NULL);
	run("  paper settings 5%/1%", &c[1], 1, NULL, 0, &paper);
	px_nurbs_curve_init(&c[0], &a, 2, 9, kc, 12, xyzc, wc, NULL);
	run("NURBS circle (9 ctrl)", &c[0], 1, NULL, 0, NULL);
	{
		/* Bicubic Bezier patch: a gently curved sheet. */
		double ku[8] = {0, 0, 0, 0, 1, 1, 1, 1}, xyz[48], w[16];
		struct px_nurbs_surf sf;
		int j;
		for (j = 0; j < 4; j++)
			for (i = 0; i < 4; i++) {
				int k = j * 4 + i;
				xyz[3 * k] = i / 3.0;
				xyz[3 * k + 1] = j / 3.0;
				xyz[3 * k + 2] = 0.4 * (urand() - 0.5);
				w[k] = 1.0;
			}
		px_nurbs_surf_init(&sf, &a, 3, 3, 4, 4, ku, 8, ku, 8, xyz, w, NULL);
		run("bicubic patch", NULL, 0, &sf, 1, NULL);
		run("  paper settings 10%/1%", NULL, 0, &sf, 1, &surf_paper);
		for (k2 = 0; k2 < 16; k2++)
			w[k2] = 0.5 + 2.0 * urand();
		px_nurbs_surf_init(&sf, &a, 3, 3, 4, 4, ku, 8, ku, 8, xyz, w, NULL);
		run("rational bicubic patch", NULL, 0, &sf, 1, NULL);
	}
	return 0;
}
