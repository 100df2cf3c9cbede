/*
 * Knowledge-step benchmark: recognition time (setup) and closed-form
 * closest-point time per query, with and without parameter inversion,
 * for a NURBS circle, a sphere and a torus patch built as surfaces of
 * revolution. Prints figures only; nothing here is a pass/fail test.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "px_nurbs.h"
#include "px_recog.h"

#include "arc_gen.h"
#include "bench_util.h"

#define NQ 20000

static void time_queries(const char *name, const struct px_recog_shape *pr, int flags)
{
	static int64_t t[NQ];
	struct px_recog_hit h;
	double s = 2 * pr->size, sink = 0;
	int i;
	for (i = 0; i < NQ; i++) {
		px_vec3 p = px_v3(s * (urand() - 0.5), s * (urand() - 0.5),
				  s * (urand() - 0.5));
		int64_t t0 = now_ns();
		px_recog_closest(pr, p, flags, &h);
		t[i] = now_ns() - t0;
		sink += h.dist;
	}
	qsort(t, NQ, sizeof(t[0]), cmp_i64);
	printf("%-8s %-13s %-10s ns/query median %5lld  p99 %6lld  max %7lld  (%g)\n",
	       name, px_recog_kind_name(pr->kind),
	       flags & PX_RECOG_WANT_PARAMS ? "+params" : "point", (long long)t[NQ / 2],
	       (long long)t[NQ * 99 / 100], (long long)t[NQ - 1], sink / NQ);
}

static void bench_rev(const char *name, double hc, double rc, double r,
		      double psweep, double sweep)
{
	static double pw[4 * 9 * 9];
	double axy[18], aw[9], AU[12], pxy[18], pwt[9], PU[12];
	int na = arc2d(0, sweep, (int)ceil(sweep / (M_PI / 2) - 1e-9), axy, aw,
		       AU);
	int np = arc2d(0, psweep, (int)ceil(psweep / (M_PI / 2) - 1e-9), pxy,
		       pwt, PU);
	struct px_nurbs_surf s;
	struct px_recog_shape pr;
	int i, j, rc_;
	int64_t t0;
	for (j = 0; j < np; j++)
		for (i = 0; i < na; i++) {
			double h = hc + r * pxy[2 * j], rho = rc + r * pxy[2 * j + 1];
			double w = aw[i] * pwt[j], *q = pw + 4 * (j * na + i);
			q[0] = rho * axy[2 * i] * w;
			q[1] = rho * axy[2 * i + 1] * w;
			q[2] = h * w;
			q[3] = w;
		}
	if (px_nurbs_surf_view(&s, 2, 2, na, np, AU, na + 3, PU, np + 3, pw, NULL))
		return;
	t0 = now_ns();
	rc_ = px_recog_surf(&s, 0, &pr);
	printf("%-8s recognised %d as %s in %lld us, H = %.3g (size %.3g)\n", name,
	       rc_, px_recog_kind_name(pr.kind), (long long)(now_ns() - t0) / 1000,
	       pr.hausdorff, pr.size);
	if (rc_ == 1) {
		time_queries(name, &pr, 0);
		time_queries(name, &pr, PX_RECOG_WANT_PARAMS);
	}
}

int main(void)
{
	double xy[18], w[9], U[12], pw[36];
	struct px_nurbs_curve c;
	struct px_recog_shape pr;
	int n = arc2d(0, 2 * M_PI, 4, xy, w, U), i, rc;
	int64_t t0;
	for (i = 0; i < n; i++) {
		pw[4 * i] = xy[2 * i] * w[i];
		pw[4 * i + 1] = xy[2 * i + 1] * w[i];
		pw[4 * i + 2] = 0;
		pw[4 * i + 3] = w[i];
	}
	if (px_nurbs_curve_view(&c, 2, n, U, n + 3, pw, NULL))
		return 1;
	t0 = now_ns();
	rc = px_recog_curve(&c, 0, &pr);
	printf("circle   recognised %d as %s in %lld us, H = %.3g\n", rc,
	       px_recog_kind_name(pr.kind), (long long)(now_ns() - t0) / 1000,
	       pr.hausdorff);
	if (rc == 1) {
		time_queries("circle", &pr, 0);
		time_queries("circle", &pr, PX_RECOG_WANT_PARAMS);
	}
	bench_rev("sphere", 0, 0, 1, M_PI, 2 * M_PI);
	bench_rev("torus", 0, 2, 0.5, 2 * M_PI, 1.5 * M_PI);
	return 0;
}
