/*
 * Trimmed-domain benchmark: px_trim_contains() and
 * px_trim_classify_box() on a face domain (a square with a circular hole
 * and two free-form cubic holes), uniform points and points within 1e-9
 * of the loops, next to an even-odd polygon test on a polyline of the
 * same loops (256 segments per span, still only an approximation) on the
 * same points in the same run, with the ratio and how often the two
 * disagree. Prints figures only; nothing here is a pass/fail test.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "px_trim.h"

#include "arc_gen.h"
#include "bench_util.h"

#define NQ 200000
#define SEG 256

struct crv {
	struct px_nurbs_curve c;
	double U[32], pw[4 * 24];
};

static struct crv cv[8];
static int ncv;

static struct px_nurbs_curve *mk(int p, int n, const double *xy,
				 const double *w, const double *U)
{
	struct crv *c = &cv[ncv++];
	struct px_nurbs_error e;
	int i;
	for (i = 0; i < n; i++) {
		double wi = w ? w[i] : 1.0;
		c->pw[4 * i] = xy[2 * i] * wi, c->pw[4 * i + 1] = xy[2 * i + 1] * wi;
		c->pw[4 * i + 2] = 0, c->pw[4 * i + 3] = wi;
	}
	memcpy(c->U, U, (size_t)(n + p + 1) * sizeof(double));
	if (px_nurbs_curve_view(&c->c, p, n, c->U, n + p + 1, c->pw, &e) != PX_OK) {
		fprintf(stderr, "bench_trim: %s\n", e.msg);
		exit(1);
	}
	return &c->c;
}

static struct px_nurbs_curve *blob(double cx, double cy, double r, int m)
{
	double xy[48], U[32];
	int i, n = m + 1, k = 0;
	for (i = 0; i < m; i++) {
		double a = -2 * M_PI * i / m, rr = r * (1 - 0.2 * urand());
		xy[2 * i] = cx + rr * cos(a), xy[2 * i + 1] = cy + rr * sin(a);
	}
	xy[2 * m] = xy[0], xy[2 * m + 1] = xy[1];
	for (i = 0; i < 4; i++)
		U[k++] = 0;
	for (i = 1; i < n - 3; i++)
		U[k++] = (double)i / (n - 3);
	for (i = 0; i < 4; i++)
		U[k++] = 1;
	return mk(3, n, xy, NULL, U);
}

/* polyline of the loops, closing points repeated */
static double *px_, *py_;
static int np_, lstart[8], nl;

static void poly_add_loop(const struct px_nurbs_curve *c, int nc)
{
	int i, j;
	lstart[nl++] = np_;
	for (i = 0; i < nc; i++) {
		double t0, t1;
		int m = SEG * (c[i].n_ctrl - c[i].degree);
		px_nurbs_curve_domain(&c[i], &t0, &t1);
		for (j = 0; j < m; j++) {
			px_vec3 p = px_nurbs_curve_point(&c[i], t0 + (t1 - t0) * j / m);
			px_[np_] = p.x, py_[np_++] = p.y;
		}
	}
	px_[np_] = px_[lstart[nl - 1]], py_[np_] = py_[lstart[nl - 1]], np_++;
	lstart[nl] = np_;
}

static int poly_inside(double u, double v)
{
	int k, i, c = 0;
	for (k = 0; k < nl; k++)
		for (i = lstart[k]; i + 1 < lstart[k + 1]; i++)
			if ((py_[i] >= v) != (py_[i + 1] >= v) &&
			    px_[i] + (v - py_[i]) * (px_[i + 1] - px_[i]) /
					     (py_[i + 1] - py_[i]) > u)
				c ^= 1;
	return c;
}

static void report(const char *what, int64_t *t, int n)
{
	qsort(t, (size_t)n, sizeof(t[0]), cmp_i64);
	printf("  %-34s ns/query median %6lld  p99 %7lld  max %8lld\n", what,
	       (long long)t[n / 2], (long long)t[n * 99 / 100], (long long)t[n - 1]);
}

int main(void)
{
	static double qu[NQ], qv[NQ];
	static int64_t ta[NQ], tb[NQ];
	struct px_nurbs_curve sq[4], *circ, *b1, *b2;
	struct px_trim_loop loops[4];
	struct px_trim_error e;
	struct px_trim *t;
	double xy[18], w[9], U[12], sqp[4][4] = {{0, 0, 1, 0}, {1, 0, 1, 1}, {1, 1, 0, 1}, {0, 1, 0, 0}};
	double UL[4] = {0, 0, 1, 1};
	int i, n, kind, differ;
	int64_t sum_a, sum_b;

	for (i = 0; i < 4; i++)
		sq[i] = *mk(1, 2, sqp[i], NULL, UL);
	n = arc2d(0, -2 * M_PI, 4, xy, w, U);
	for (i = 0; i < n; i++)
		xy[2 * i] = 0.3 + 0.15 * xy[2 * i], xy[2 * i + 1] = 0.3 + 0.15 * xy[2 * i + 1];
	circ = mk(2, n, xy, w, U);
	b1 = blob(0.7, 0.3, 0.2, 12);
	b2 = blob(0.5, 0.72, 0.22, 16);
	loops[0] = (struct px_trim_loop){sq, 4, NULL};
	loops[1] = (struct px_trim_loop){circ, 1, NULL};
	loops[2] = (struct px_trim_loop){b1, 1, NULL};
	loops[3] = (struct px_trim_loop){b2, 1, NULL};
	{
		int64_t t0 = now_ns();
		if (px_trim_create(loops, 4, NULL, &e, &t) != PX_OK) {
			fprintf(stderr, "bench_trim: %s\n", e.msg);
			return 1;
		}
		printf("domain: square, circle hole, two cubic holes: %d pieces, grid "
		       "%d x %d, setup %.2f ms\n", px_trim_piece_count(t),
		       px_trim_grid_size(t), px_trim_grid_size(t), (now_ns() - t0) / 1e6);
	}
	px_ = malloc(SEG * 64 * sizeof(double)), py_ = malloc(SEG * 64 * sizeof(double));
	poly_add_loop(sq, 4), poly_add_loop(circ, 1), poly_add_loop(b1, 1), poly_add_loop(b2, 1);
	printf("polygon reference: %d segments\n", np_ - nl);
	for (kind = 0; kind < 2; kind++) {
		for (i = 0; i < NQ; i++) {
			if (kind == 0) {
				qu[i] = urand() * 1.2 - 0.1, qv[i] = urand() * 1.2 - 0.1;
			} else {
				const struct px_nurbs_curve *c = i % 3 == 0 ? circ : (i % 3 == 1 ? b1 : b2);
				px_vec3 d[2];
				double nn, s = (urand() < 0.5 ? -1 : 1) * 1e-9;
				px_nurbs_curve_eval(c, urand(), 1, d);
				nn = hypot(d[1].x, d[1].y);
				qu[i] = d[0].x - s * d[1].y / nn, qv[i] = d[0].y + s * d[1].x / nn;
			}
		}
		sum_a = sum_b = 0, differ = 0;
		for (i = 0; i < NQ; i++) {
			int64_t t0 = now_ns();
			int a = px_trim_contains(t, qu[i], qv[i], NULL), b;
			int64_t t1 = now_ns();
			b = poly_inside(qu[i], qv[i]);
			tb[i] = now_ns() - t1, ta[i] = t1 - t0;
			sum_a += ta[i], sum_b += tb[i];
			differ += a != b;
		}
		printf("%s points (%d):\n", kind ? "within 1e-9 of a loop" : "uniform", NQ);
		report("px_trim_contains", ta, NQ);
		report("polygon test", tb, NQ);
		printf("  mean ratio polygon / px_trim %.1f, answers differing %d "
		       "(the polygon's)\n", (double)sum_b / (double)sum_a, differ);
	}
	for (i = 0; i < NQ; i++) {
		double u = urand() * 1.2 - 0.1, v = urand() * 1.2 - 0.1, s = 0.002 + 0.05 * urand();
		int64_t t0 = now_ns();
		volatile int c = px_trim_classify_box(t, u, u + s, v, v + s);
		(void)c;
		ta[i] = now_ns() - t0;
	}
	printf("boxes of side 0.002 to 0.052:\n");
	report("px_trim_classify_box", ta, NQ);
	px_trim_free(t);
	free(px_), free(py_);
	return 0;
}
