/*
 * B-rep benchmark: the cold query of trimmed B-rep models built in C
 * (tests/support/brep_gen.h: a sheet with a round hole, a drilled cube,
 * a free-form sheet trimmed by a spline loop with a hole, a closed box
 * with 1 mm walls) next to the untrimmed NURBS model of the same
 * surfaces (px_nurbs_model_create()) on the same points, so the ratio is
 * what trimming (the in-domain filter, the edges as curves, the sign
 * from the faces) costs. Per-query median, p99 and max in ns for random
 * points in the part's box enlarged by 25 % per side; signed where the
 * part is closed. Prints figures only; nothing here is a pass/fail test.
 *
 *   bench_brep [PREFIX [N]]
 * runs the parts whose name starts with PREFIX, N queries each.
 *   bench_brep --file PATH [N]
 * times a STEP / IGES / OBJ part read by px_model_load() alone (signed
 * where it is closed) on the same kind of points; the plain run ends
 * with the shipped STEP block (config/examples/parts, when run from the
 * source tree and built with OpenCASCADE).
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "brep_gen.h"
#include "px_brep.h"
#include "px_load.h"
#include "px_dist.h"
#include "px_model.h"

#include "bench_util.h"

#define NQ_MAX 20000

static const char *filter;
static int NQ = 10000;

struct stats {
	int64_t med, p99, max;
};

static struct stats time_model(const struct px_model *m, const px_vec3 *q, int n,
			       long *uncertified)
{
	static int64_t t[NQ_MAX];
	struct px_model_result r;
	struct stats s;
	int i;
	*uncertified = 0;
	for (i = 0; i < 500 && i < n; i++) /* warm the caches */
		px_model_query(m, q[i], &r);
	for (i = 0; i < n; i++) {
		int64_t a = now_ns();
		px_model_query(m, q[i], &r);
		t[i] = now_ns() - a;
		*uncertified += !r.certified;
	}
	qsort(t, (size_t)n, sizeof(t[0]), cmp_i64);
	s.med = t[n / 2];
	s.p99 = t[n * 99 / 100];
	s.max = t[n - 1];
	return s;
}

/* Random points in box b enlarged by 25 % per side. */
static void box_points(px_aabb b, px_vec3 *q, int n)
{
	px_vec3 lo = b.min, hi = b.max;
	px_vec3 e = px_v3_scale(px_v3_sub(hi, lo), 0.25);
	int i;
	lo = px_v3_sub(lo, e);
	hi = px_v3_add(hi, e);
	for (i = 0; i < n; i++)
		q[i] = px_v3(lo.x + (hi.x - lo.x) * urand(), lo.y + (hi.y - lo.y) * urand(),
			     lo.z + (hi.z - lo.z) * urand());
}

static int run_file(const char *path)
{
	static px_vec3 q[NQ_MAX];
	struct px_brep_info info;
	const struct px_brep *b;
	struct px_model *m;
	struct stats s;
	char msg[256];
	long unc;
	int64_t t0 = now_ns();
	int rc = px_model_load(path, 0.0, &m, msg, sizeof msg);

	t0 = now_ns() - t0;
	if (rc != PX_OK) {
		printf("%s: %s (%s)\n", path, px_strerror(rc), msg);
		return 1;
	}
	b = px_model_brep(m);
	if (!b || px_brep_get_info(b, &info) != PX_OK) {
		printf("%s: not a B-rep\n", path);
		px_model_free(m);
		return 1;
	}
	box_points(info.bounds, q, NQ);
	s = time_model(m, q, NQ, &unc);
	printf("%-12s %d faces %d edges %d vertices, %s; load %.2f ms, %zu bytes\n",
	       path, info.n_faces, info.n_edges, info.n_vertices,
	       info.closed ? "closed: signed" : "open: unsigned", t0 / 1e6, info.bytes);
	printf("%-12s per query ns: median %lld p99 %lld max %lld; uncertified %ld / %d\n",
	       "", (long long)s.med, (long long)s.p99, (long long)s.max, unc, NQ);
	px_model_free(m);
	return 0;
}

static void run(struct brep_gen *g)
{
	static px_vec3 q[NQ_MAX];
	struct px_nurbs_surf sf[BG_MAXF];
	struct px_brep_error err;
	struct px_brep_info info;
	struct px_brep *b;
	struct px_model *mb, *mn;
	struct stats sb, sn;
	long ub, un;
	int64_t t0, t1;
	int i, rc;

	t0 = now_ns();
	rc = px_brep_create(&g->d, NULL, &err, &b);
	if (rc) {
		printf("%s: setup failed: %s\n", g->d.name, err.msg);
		return;
	}
	t0 = now_ns() - t0;
	px_brep_get_info(b, &info);
	if (px_model_from_brep(b, &mb) != PX_OK) {
		printf("%s: model failed\n", g->d.name);
		return;
	}
	for (i = 0; i < g->nf; i++)
		sf[i] = g->faces[i].surf;
	t1 = now_ns();
	rc = px_nurbs_model_create(NULL, 0, sf, g->nf, NULL, &mn);
	t1 = now_ns() - t1;
	if (rc) {
		printf("%s: untrimmed model failed: %s\n", g->d.name, px_strerror(rc));
		px_model_free(mb);
		return;
	}
	box_points(info.bounds, q, NQ);
	if (!filter || !strncmp(g->d.name, filter, strlen(filter))) {
		sb = time_model(mb, q, NQ, &ub);
		sn = time_model(mn, q, NQ, &un);
		printf("%-12s %d faces %d edges %d vertices, %s; setup %.2f ms (untrimmed "
		       "%.2f ms), %zu bytes\n",
		       g->d.name, info.n_faces, info.n_edges, info.n_vertices,
		       info.closed ? "closed: signed" : "open: unsigned", t0 / 1e6, t1 / 1e6,
		       info.bytes);
		printf("%-12s per query ns: B-rep median %lld p99 %lld max %lld; untrimmed "
		       "median %lld p99 %lld max %lld; ratio median %.2f p99 %.2f; "
		       "uncertified %ld / %ld\n",
		       "", (long long)sb.med, (long long)sb.p99, (long long)sb.max,
		       (long long)sn.med, (long long)sn.p99, (long long)sn.max,
		       (double)sb.med / (double)sn.med, (double)sb.p99 / (double)sn.p99, ub, un);
	}
	px_model_free(mb);
	px_model_free(mn);
}

int main(int argc, char **argv)
{
	struct brep_gen *(*parts[])(void) = {brep_gen_sheet_hole, brep_gen_cube_hole,
					     brep_gen_freeform, brep_gen_thin_box};
	size_t i;
	if (argc > 2 && !strcmp(argv[1], "--file")) {
		if (argc > 3)
			NQ = atoi(argv[3]);
		if (NQ < 1 || NQ > NQ_MAX)
			NQ = NQ_MAX;
		return run_file(argv[2]);
	}
	if (argc > 1 && argv[1][0])
		filter = argv[1];
	if (argc > 2)
		NQ = atoi(argv[2]);
	if (NQ < 1 || NQ > NQ_MAX)
		NQ = NQ_MAX;
	for (i = 0; i < sizeof(parts) / sizeof(parts[0]); i++) {
		struct brep_gen *g = parts[i]();
		run(g);
		free(g);
	}
	if (!filter || !strncmp("filleted_block", filter, strlen(filter))) {
		const char *step = "config/examples/parts/filleted_block.step";
		FILE *f = fopen(step, "r");
		if (f) {
			fclose(f);
			run_file(step);
		}
	}
	return 0;
}
