/*
 * Trimmed domains: the in-domain test against exact answers (squares,
 * rational circles) and a brute-force polygon test on dense polylines
 * of free-form loops, near the loops on both sides and on them; box
 * classification against exact and sampled answers; the refusals; no
 * heap calls in queries.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "arc_gen.h"
#include "px_alloc_count.h"
#include "px_test.h"
#include "px_trim.h"

#define MAXC 16
#define MAXP 64

/* One loop's curves, with their arrays. */
struct shape {
	struct px_nurbs_curve c[MAXC];
	unsigned char rev[MAXC];
	double knots[MAXC][MAXP + 12];
	double pw[MAXC][4 * MAXP];
	int n;
};

struct dom {
	struct shape s[8];
	int n;
	struct px_trim_loop loops[8];
};

static void add_curve(struct shape *s, int p, int n, const double *xy,
		      const double *w, const double *U)
{
	struct px_nurbs_error e;
	int i, k = s->n++;
	PX_CHECK(k < MAXC && n <= MAXP);
	for (i = 0; i < n; i++) {
		double wi = w ? w[i] : 1.0;
		s->pw[k][4 * i] = xy[2 * i] * wi;
		s->pw[k][4 * i + 1] = xy[2 * i + 1] * wi;
		s->pw[k][4 * i + 2] = 0.0;
		s->pw[k][4 * i + 3] = wi;
	}
	memcpy(s->knots[k], U, (size_t)(n + p + 1) * sizeof(double));
	PX_CHECK_MSG(px_nurbs_curve_view(&s->c[k], p, n, s->knots[k], n + p + 1,
					 s->pw[k], &e) == PX_OK,
		     "curve: %s", e.msg);
	s->rev[k] = 0;
}

static void add_line(struct shape *s, double x0, double y0, double x1,
		     double y1)
{
	double xy[4] = {x0, y0, x1, y1}, U[4] = {0, 0, 1, 1};
	add_curve(s, 1, 2, xy, NULL, U);
}

/* Polygon through n points, closed. */
static void add_polygon(struct shape *s, const double *xy, int n)
{
	int i;
	for (i = 0; i < n; i++)
		add_line(s, xy[2 * i], xy[2 * i + 1], xy[2 * ((i + 1) % n)],
			 xy[2 * ((i + 1) % n) + 1]);
}

/* Exact circle: 4 rational quadratic spans, counter-clockwise when
 * sweep > 0. */
static void add_circle(struct shape *s, double cx, double cy, double r,
		       double sweep)
{
	double xy[18], w[9], U[12];
	int n = arc2d(0.3, sweep, 4, xy, w, U), i;
	for (i = 0; i < n; i++)
		xy[2 * i] = cx + r * xy[2 * i], xy[2 * i + 1] = cy + r * xy[2 * i + 1];
	add_curve(s, 2, n, xy, w, U);
}

/* Closed clamped B-spline of degree p through a star of m control points
 * around (cx, cy) (the first repeated at the end). */
static void add_blob(struct shape *s, double cx, double cy, double r, int m,
		     int p, double wobble, double sign)
{
	double xy[2 * MAXP] = {0}, U[MAXP + 12];
	int i, n = m + 1, k = 0;
	for (i = 0; i < m; i++) {
		double a = sign * 2.0 * M_PI * i / m;
		double rr = r * (1.0 - wobble * px_rand_unit());
		xy[2 * i] = cx + rr * cos(a), xy[2 * i + 1] = cy + rr * sin(a);
	}
	xy[2 * m] = xy[0], xy[2 * m + 1] = xy[1];
	for (i = 0; i <= p; i++)
		U[k++] = 0;
	for (i = 1; i < n - p; i++)
		U[k++] = (double)i / (n - p);
	for (i = 0; i <= p; i++)
		U[k++] = 1;
	add_curve(s, p, n, xy, NULL, U);
}

static struct px_trim *build(struct dom *d, struct px_trim_error *e)
{
	struct px_trim *t = NULL;
	int k, rc;
	for (k = 0; k < d->n; k++) {
		d->loops[k].curves = d->s[k].c;
		d->loops[k].n_curves = d->s[k].n;
		d->loops[k].reversed = d->s[k].rev;
	}
	rc = px_trim_create(d->loops, d->n, NULL, e, &t);
	PX_CHECK_MSG(rc == PX_OK, "create: %s (%s)", px_strerror(rc), e->msg);
	return t;
}

/* ---- the exact domain: square minus a disc ------------------------- */

struct sqdisc {
	double x0, y0, side, cx, cy, r;
};

static int sq_inside(const struct sqdisc *g, double u, double v)
{
	return u > g->x0 && u < g->x0 + g->side && v > g->y0 &&
	       v < g->y0 + g->side && hypot(u - g->cx, v - g->cy) > g->r;
}

/* distance from (u, v) to the boundary of the square-minus-disc */
static double sq_dist(const struct sqdisc *g, double u, double v)
{
	double dc = fabs(hypot(u - g->cx, v - g->cy) - g->r);
	double x1 = g->x0 + g->side, y1 = g->y0 + g->side;
	double ex = fmax(fmax(g->x0 - u, u - x1), 0.0);
	double ey = fmax(fmax(g->y0 - v, v - y1), 0.0);
	double ds;
	if (ex > 0 || ey > 0)
		ds = hypot(ex, ey);
	else
		ds = fmin(fmin(u - g->x0, x1 - u), fmin(v - g->y0, y1 - v));
	return fmin(dc, ds);
}

/* Square (counter-clockwise unless cw) with some edges given reversed,
 * and a circular hole. */
static void make_sqdisc(struct dom *d, const struct sqdisc *g, int cw,
			int hole_ccw)
{
	double x1 = g->x0 + g->side, y1 = g->y0 + g->side;
	double sq[8] = {g->x0, g->y0, x1, g->y0, x1, y1, g->x0, y1};
	double rs[8];
	int i;
	memset(d, 0, sizeof(*d));
	d->n = 2;
	if (cw) {
		for (i = 0; i < 4; i++)
			rs[2 * i] = sq[2 * (3 - i)], rs[2 * i + 1] = sq[2 * (3 - i) + 1];
		add_polygon(&d->s[0], rs, 4);
	} else {
		/* edge 1 stored backwards and run reversed */
		add_line(&d->s[0], g->x0, g->y0, x1, g->y0);
		add_line(&d->s[0], x1, y1, x1, g->y0);
		d->s[0].rev[1] = 1;
		add_line(&d->s[0], x1, y1, g->x0, y1);
		add_line(&d->s[0], g->x0, y1, g->x0, g->y0);
	}
	add_circle(&d->s[1], g->cx, g->cy, g->r, hole_ccw ? 2 * M_PI : -2 * M_PI);
}

/* Random points: uniform, near the square's edges and the circle within
 * 1e-12..1e-6 of the size on both sides, and on the circle. */
static void check_sqdisc(const struct sqdisc *g, int cw, int hole_ccw)
{
	struct dom d;
	struct px_trim_error e;
	struct px_trim *t;
	double on_tol, dmin;
	int i, n_near = 0, n_bound = 0;

	make_sqdisc(&d, g, cw, hole_ccw);
	t = build(&d, &e);
	px_trim_tolerances(t, NULL, &on_tol);
	PX_CHECK_INT_EQ(px_trim_loop_reversed(t, 0), cw);
	PX_CHECK_INT_EQ(px_trim_loop_reversed(t, 1), hole_ccw);
	PX_CHECK(px_trim_loop_area(t, 0) > 0 && px_trim_loop_area(t, 1) < 0);
	PX_CHECK_CLOSE(px_trim_loop_area(t, 1), -M_PI * g->r * g->r, 0, 1e-12);
	PX_CHECK_CLOSE(px_trim_loop_area(t, 0), g->side * g->side, 0, 1e-12);
	/* near points: never closer than a thousand boundary tolerances */
	dmin = fmax(1e-12 * g->side, 1e3 * on_tol);
	for (i = 0; i < 60000; i++) {
		double u, v, dist;
		struct px_trim_hit h;
		int kind = i % 4, want, got;
		if (kind == 0) {
			u = g->x0 + px_rand_range(-0.2, 1.2) * g->side;
			v = g->y0 + px_rand_range(-0.2, 1.2) * g->side;
		} else {
			double dd = dmin * pow(1e-6 * g->side / dmin, px_rand_unit());
			double s = px_rand_unit() < 0.5 ? -1 : 1;
			if (kind == 1) {
				double a = px_rand_range(0, 2 * M_PI);
				u = g->cx + (g->r + s * dd) * cos(a);
				v = g->cy + (g->r + s * dd) * sin(a);
			} else {
				double a = px_rand_range(0.001, 0.999) * g->side;
				int edge = px_rand_int(0, 3);
				u = edge < 2 ? g->x0 + a : (edge == 2 ? g->x0 : g->x0 + g->side) + s * dd;
				v = edge < 2 ? (edge ? g->y0 + g->side : g->y0) + s * dd : g->y0 + a;
			}
			n_near++;
		}
		dist = sq_dist(g, u, v);
		want = sq_inside(g, u, v);
		got = px_trim_contains(t, u, v, &h);
		if (got == PX_TRIM_BOUNDARY) {
			n_bound++;
			PX_CHECK_MSG(dist <= 4 * on_tol,
				     "(%.17g, %.17g) at %.3g from the loops called "
				     "boundary (tol %.3g)", u, v, dist, on_tol);
			continue;
		}
		if (dist < dmin * 0.5)
			continue; /* rounding of the exact answer itself */
		PX_CHECK_MSG(got == want,
			     "(%.17g, %.17g) at %.3g from the loops: got %d "
			     "want %d (winding %d)", u, v, dist, got, want,
			     h.winding);
		PX_CHECK_INT_EQ(h.winding, want);
	}
	PX_CHECK(n_near > 40000);
	PX_CHECK_INT_EQ(n_bound, 0);
	/* on the circle and on the square's edges: boundary */
	for (i = 0; i < 2000; i++) {
		struct px_trim_hit h;
		double a = px_rand_range(0, 2 * M_PI), x, y;
		px_vec3 p = px_nurbs_curve_point(&d.s[1].c[0], px_rand_unit());
		if (i % 2) {
			x = p.x, y = p.y;
		} else {
			x = g->x0 + px_rand_unit() * g->side, y = g->y0;
			(void)a;
		}
		PX_CHECK_MSG(px_trim_contains(t, x, y, &h) == PX_TRIM_BOUNDARY,
			     "(%.17g, %.17g) on loop %d: %d", x, y, i % 2, h.where);
		PX_CHECK_INT_EQ(h.loop, i % 2 ? 1 : 0);
		if (i % 2) {
			px_vec3 q = px_nurbs_curve_point(&d.s[1].c[0], h.t);
			PX_CHECK(hypot(q.x - x, q.y - y) < 1e-9 * g->side);
		}
	}
	px_trim_free(t);
}

static void test_square_disc(void)
{
	struct sqdisc g = {0, 0, 1, 0.4, 0.55, 0.3};
	int cw, ccw;
	for (cw = 0; cw < 2; cw++)
		for (ccw = 0; ccw < 2; ccw++)
			check_sqdisc(&g, cw, ccw);
}

/* Far from the origin, tiny and huge: the tolerances follow the
 * coordinates. */
static void test_scales(void)
{
	struct sqdisc a = {1000, -2000, 3, 1001.5, -1998.2, 0.9};
	struct sqdisc b = {1e-6, 2e-6, 1e-6, 1.6e-6, 2.5e-6, 0.3e-6};
	struct sqdisc c = {-3e5, 1e5, 7e5, 0.2e5, 4e5, 2.5e5};
	check_sqdisc(&a, 0, 0);
	check_sqdisc(&b, 1, 0);
	check_sqdisc(&c, 0, 1);
}

/* ---- free-form loops against dense polylines ---------------------- */

struct poly {
	double *x, *y;
	int *start; /* per loop, closing point repeated */
	int n_loops, n;
	double dev;  /* largest distance from the curve to its polyline */
};

static void poly_build(struct poly *P, const struct dom *d, int per_span)
{
	int k, i, j, cap = 0;
	for (k = 0; k < d->n; k++)
		for (i = 0; i < d->s[k].n; i++)
			cap += per_span * d->s[k].c[i].n_ctrl + 1;
	P->x = malloc((size_t)cap * sizeof(double));
	P->y = malloc((size_t)cap * sizeof(double));
	P->start = malloc((size_t)(d->n + 1) * sizeof(int));
	P->n = 0, P->n_loops = d->n, P->dev = 0;
	for (k = 0; k < d->n; k++) {
		P->start[k] = P->n;
		for (i = 0; i < d->s[k].n; i++) {
			const struct px_nurbs_curve *c = &d->s[k].c[i];
			double t0, t1;
			int m = per_span * c->n_ctrl;
			px_nurbs_curve_domain(c, &t0, &t1);
			for (j = 0; j < m; j++) {
				double s = (double)j / m, tm;
				px_vec3 p, q, r;
				if (d->s[k].rev[i])
					s = 1 - s;
				p = px_nurbs_curve_point(c, t0 + s * (t1 - t0));
				P->x[P->n] = p.x, P->y[P->n] = p.y, P->n++;
				tm = t0 + (s + (d->s[k].rev[i] ? -0.5 : 0.5) / m) * (t1 - t0);
				q = px_nurbs_curve_point(c, tm);
				r = px_nurbs_curve_point(c, t0 + (s + (d->s[k].rev[i] ? -1.0 : 1.0) / m) * (t1 - t0));
				P->dev = fmax(P->dev, hypot(q.x - 0.5 * (p.x + r.x),
							    q.y - 0.5 * (p.y + r.y)));
			}
		}
		P->x[P->n] = P->x[P->start[k]], P->y[P->n] = P->y[P->start[k]];
		P->n++;
	}
	P->start[d->n] = P->n;
}

static void poly_free(struct poly *P)
{
	free(P->x), free(P->y), free(P->start);
}

/* Even-odd over all loops (the domain's loops do not cross). */
static int poly_inside(const struct poly *P, double u, double v)
{
	int k, i, c = 0;
	for (k = 0; k < P->n_loops; k++)
		for (i = P->start[k]; i + 1 < P->start[k + 1]; i++) {
			double ya = P->y[i], yb = P->y[i + 1];
			if ((ya >= v) != (yb >= v)) {
				double x = P->x[i] + (v - ya) * (P->x[i + 1] - P->x[i]) / (yb - ya);
				if (x > u)
					c ^= 1;
			}
		}
	return c;
}

static double poly_dist(const struct poly *P, double u, double v)
{
	double best = INFINITY;
	int k, i;
	for (k = 0; k < P->n_loops; k++)
		for (i = P->start[k]; i + 1 < P->start[k + 1]; i++) {
			double ax = P->x[i], ay = P->y[i];
			double dx = P->x[i + 1] - ax, dy = P->y[i + 1] - ay;
			double l2 = dx * dx + dy * dy, s = 0;
			if (l2 > 0)
				s = fmin(1, fmax(0, ((u - ax) * dx + (v - ay) * dy) / l2));
			best = fmin(best, hypot(u - ax - s * dx, v - ay - s * dy));
		}
	return best;
}

/* A blob with two blob holes and a circle hole, random shapes. */
static void make_blobs(struct dom *d, int p, int reversed_holes)
{
	memset(d, 0, sizeof(*d));
	d->n = 4;
	add_blob(&d->s[0], 0, 0, 1.0, px_rand_int(10, 24), p, 0.15, 1);
	add_blob(&d->s[1], -0.35, 0.1, 0.22, px_rand_int(6, 14), p, 0.2,
		 reversed_holes ? 1 : -1);
	add_blob(&d->s[2], 0.35, -0.05, 0.2, px_rand_int(6, 14), p, 0.2, -1);
	add_circle(&d->s[3], 0.05, -0.5, 0.12, -2 * M_PI);
}

static void test_blobs_vs_polygon(void)
{
	int round, n_amb = 0, n_pts = 0;
	for (round = 0; round < 12; round++) {
		struct dom d;
		struct px_trim_error e;
		struct px_trim *t;
		struct poly P;
		int i, p = 2 + round % 4;
		double on_tol;

		make_blobs(&d, p, round % 2);
		t = build(&d, &e);
		px_trim_tolerances(t, NULL, &on_tol);
		poly_build(&P, &d, 400);
		PX_CHECK(P.dev < 1e-5);
		for (i = 0; i < 3000; i++) {
			double u = px_rand_range(-1.1, 1.1), v = px_rand_range(-1.1, 1.1);
			int want = poly_inside(&P, u, v);
			int got = px_trim_contains(t, u, v, NULL);
			n_pts++;
			if (got == want)
				continue;
			/* only where the polyline is not a faithful reference */
			PX_CHECK_MSG(poly_dist(&P, u, v) <= 2 * P.dev,
				     "round %d (%.17g, %.17g): got %d, polygon says %d "
				     "at %.3g from it", round, u, v, got, want,
				     poly_dist(&P, u, v));
			n_amb++;
		}
		/* near the loops, both sides: the side is that of the normal */
		for (i = 0; i < 4000; i++) {
			int k = px_rand_int(0, d.n - 1), want, got;
			const struct px_nurbs_curve *c = &d.s[k].c[0];
			double t0, t1, s, dd, sg = px_rand_unit() < 0.5 ? -1 : 1, nl;
			px_vec3 der[2];
			px_nurbs_curve_domain(c, &t0, &t1);
			s = t0 + px_rand_range(0.002, 0.998) * (t1 - t0);
			px_nurbs_curve_eval(c, s, 1, der);
			nl = hypot(der[1].x, der[1].y);
			if (nl < 1e-3)
				continue;
			dd = pow(10.0, px_rand_range(-12, -6));
			if (dd < 1e3 * on_tol)
				dd = 1e3 * on_tol;
			/* left of the curve as given; inside on the left when the
			 * loop's given direction is the domain's */
			want = (sg > 0) == (px_trim_loop_reversed(t, k) == 0);
			got = px_trim_contains(t, der[0].x - sg * dd * der[1].y / nl,
					       der[0].y + sg * dd * der[1].x / nl, NULL);
			PX_CHECK_MSG(got == want, "round %d loop %d s %.17g at %.3g "
				     "side %g: got %d want %d", round, k, s, dd, sg,
				     got, want);
			/* on the curve itself */
			PX_CHECK_INT_EQ(px_trim_contains(t, der[0].x, der[0].y, NULL),
					PX_TRIM_BOUNDARY);
		}
		poly_free(&P);
		px_trim_free(t);
	}
	printf("  %d random points, %d within the polyline's deviation\n",
	       n_pts, n_amb);
	PX_CHECK(n_amb * 100 < n_pts);
}

/* ---- boxes -------------------------------------------------------- */

/* 1 when the square's or the circle's boundary meets the box */
static int sq_box_crossed(const struct sqdisc *g, const double b[4])
{
	double nx = fmin(fmax(g->cx, b[0]), b[1]), ny = fmin(fmax(g->cy, b[2]), b[3]);
	double fx = fmax(fabs(b[0] - g->cx), fabs(b[1] - g->cx));
	double fy = fmax(fabs(b[2] - g->cy), fabs(b[3] - g->cy));
	double x1 = g->x0 + g->side, y1 = g->y0 + g->side;
	int circ = hypot(nx - g->cx, ny - g->cy) <= g->r && hypot(fx, fy) >= g->r;
	int in_sq = b[0] > g->x0 && b[1] < x1 && b[2] > g->y0 && b[3] < y1;
	int out_sq = b[1] < g->x0 || b[0] > x1 || b[3] < g->y0 || b[2] > y1;
	return circ || !(in_sq || out_sq);
}

static void test_boxes(void)
{
	struct sqdisc g = {0, 0, 1, 0.4, 0.55, 0.3};
	struct dom d, bd;
	struct px_trim_error e;
	struct px_trim *t, *tb;
	struct poly P;
	int i, j, decided = 0, free_boxes = 0;

	make_sqdisc(&d, &g, 0, 0);
	t = build(&d, &e);
	for (i = 0; i < 20000; i++) {
		double w = pow(10.0, px_rand_range(-9, 0)), h = w * px_rand_range(0.2, 5);
		double u = px_rand_range(-0.2, 1.2), v = px_rand_range(-0.2, 1.2);
		double b[4] = {u, u + w, v, v + h};
		int c = px_trim_classify_box(t, b[0], b[1], b[2], b[3]);
		int crossed = sq_box_crossed(&g, b);
		PX_CHECK(c >= 0);
		if (!crossed)
			free_boxes++;
		if (c == PX_TRIM_BOX_CROSSED)
			continue;
		decided++;
		PX_CHECK_MSG(!crossed, "box [%.17g %.17g]x[%.17g %.17g] meets a "
			     "loop, classified %d", b[0], b[1], b[2], b[3], c);
		PX_CHECK_INT_EQ(c, sq_inside(&g, 0.5 * (b[0] + b[1]), 0.5 * (b[2] + b[3])));
	}
	printf("  %d of %d boxes clear of the loops decided\n", decided, free_boxes);
	PX_CHECK(decided * 10 > free_boxes * 9);
	/* free-form: sampled */
	make_blobs(&bd, 3, 0);
	tb = build(&bd, &e);
	poly_build(&P, &bd, 400);
	for (i = 0; i < 3000; i++) {
		double w = pow(10.0, px_rand_range(-4, 0)), h = w * px_rand_range(0.2, 5);
		double u = px_rand_range(-1.2, 1.1), v = px_rand_range(-1.2, 1.1);
		int c = px_trim_classify_box(tb, u, u + w, v, v + h);
		if (c == PX_TRIM_BOX_CROSSED)
			continue;
		for (j = 0; j < 64; j++) {
			double x = u + w * (j % 8) / 7.0, y = v + h * (j / 8) / 7.0;
			PX_CHECK_MSG(px_trim_contains(tb, x, y, NULL) == c,
				     "box at (%g, %g) %g x %g said %d", u, v, w, h, c);
			if (poly_inside(&P, x, y) != c)
				PX_CHECK_MSG(poly_dist(&P, x, y) <= 2 * P.dev,
					     "box at (%g, %g) %g x %g said %d, the "
					     "polygon differs at (%g, %g)", u, v, w,
					     h, c, x, y);
		}
	}
	/* boxes around the whole domain, and degenerate ones */
	PX_CHECK_INT_EQ(px_trim_classify_box(t, -1, 2, -1, 2), PX_TRIM_BOX_CROSSED);
	PX_CHECK_INT_EQ(px_trim_classify_box(t, 5, 6, 5, 6), PX_TRIM_BOX_OUTSIDE);
	PX_CHECK_INT_EQ(px_trim_classify_box(t, 0.05, 0.05, 0.05, 0.05), PX_TRIM_BOX_INSIDE);
	PX_CHECK_INT_EQ(px_trim_classify_box(t, 0.5, 0.4, 0, 1), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_trim_classify_box(t, NAN, 0.4, 0, 1), PX_E_NAN);
	poly_free(&P);
	px_trim_free(tb);
	px_trim_free(t);
}

/* ---- refusals ----------------------------------------------------- */

static void expect_refusal(struct dom *d, int code, enum px_trim_fault f,
			   const char *part1, const char *part2)
{
	struct px_trim_error e;
	struct px_trim *t = (struct px_trim *)&e;
	int k, rc;
	for (k = 0; k < d->n; k++) {
		d->loops[k].curves = d->s[k].c;
		d->loops[k].n_curves = d->s[k].n;
		d->loops[k].reversed = d->s[k].rev;
	}
	rc = px_trim_create(d->loops, d->n, NULL, &e, &t);
	printf("  refused: %s\n", e.msg);
	PX_CHECK_MSG(rc == code, "rc %d (%s), want %d: %s", rc, px_strerror(rc), code, e.msg);
	PX_CHECK(t == NULL);
	PX_CHECK_INT_EQ(e.fault, f);
	PX_CHECK_INT_EQ(e.code, code);
	PX_CHECK_MSG(strstr(e.msg, part1) != NULL, "'%s' lacks '%s'", e.msg, part1);
	PX_CHECK_MSG(!part2 || strstr(e.msg, part2) != NULL, "'%s' lacks '%s'", e.msg, part2);
}

static void test_refusals(void)
{
	static struct dom d;
	struct px_trim_error e;
	double sq[8] = {0, 0, 1, 0, 1, 1, 0, 1};
	double bow[8] = {0, 0, 2, 1.5, 2, 0, 0, 1};
	struct px_trim *t = NULL;

	/* open: the top edge stops short */
	memset(&d, 0, sizeof(d));
	d.n = 1;
	add_line(&d.s[0], 0, 0, 1, 0);
	add_line(&d.s[0], 1, 0, 1, 1);
	add_line(&d.s[0], 1, 1, 0.001, 1);
	add_line(&d.s[0], 0, 1, 0, 0);
	expect_refusal(&d, PX_E_INVAL, PX_TRIM_FAULT_OPEN, "outer loop is open",
		       "curve 2 ends at");
	/* a gap within the tolerance is closed */
	memset(&d, 0, sizeof(d));
	d.n = 1;
	add_line(&d.s[0], 0, 0, 1, 0);
	add_line(&d.s[0], 1, 0, 1, 1);
	add_line(&d.s[0], 1, 1, 1e-8, 1);
	add_line(&d.s[0], 0, 1, 0, 0);
	t = build(&d, &e);
	PX_CHECK_INT_EQ(px_trim_contains(t, 0.5, 0.5, NULL), PX_TRIM_INSIDE);
	px_trim_free(t);
	/* figure-eight (lobes of different size) */
	memset(&d, 0, sizeof(d));
	d.n = 1;
	add_polygon(&d.s[0], bow, 4);
	expect_refusal(&d, PX_E_INVAL, PX_TRIM_FAULT_CROSS,
		       "outer loop crosses or touches itself", "near (");
	/* a smooth figure-eight in one cubic curve */
	{
		double xy[14] = {0, 0, 1, 1, 2, 0.2, 1.2, -1, 0.3, 0.8, -1, 0.5, 0, 0};
		double U[11] = {0, 0, 0, 0, 0.25, 0.5, 0.75, 1, 1, 1, 1};
		memset(&d, 0, sizeof(d));
		d.n = 1;
		add_curve(&d.s[0], 3, 7, xy, NULL, U);
		expect_refusal(&d, PX_E_INVAL, PX_TRIM_FAULT_CROSS,
			       "outer loop crosses or touches itself", "curve 0 meets curve 0");
	}
	/* two crossing holes */
	memset(&d, 0, sizeof(d));
	d.n = 3;
	add_polygon(&d.s[0], (double[]){0, 0, 4, 0, 4, 4, 0, 4}, 4);
	add_circle(&d.s[1], 1.5, 2, 1, -2 * M_PI);
	add_circle(&d.s[2], 2.5, 2, 1, -2 * M_PI);
	expect_refusal(&d, PX_E_INVAL, PX_TRIM_FAULT_CROSS, "hole 1 curve 0 and hole 2 curve 0",
		       "cross or touch near (2,");
	/* a hole crossing the outer loop */
	memset(&d, 0, sizeof(d));
	d.n = 2;
	add_polygon(&d.s[0], sq, 4);
	add_circle(&d.s[1], 1, 0.5, 0.2, -2 * M_PI);
	expect_refusal(&d, PX_E_INVAL, PX_TRIM_FAULT_CROSS, "outer loop curve 1 and hole 1 curve 0", NULL);
	/* a hole outside the outer loop */
	memset(&d, 0, sizeof(d));
	d.n = 2;
	add_polygon(&d.s[0], sq, 4);
	add_circle(&d.s[1], 3, 3, 0.5, -2 * M_PI);
	expect_refusal(&d, PX_E_INVAL, PX_TRIM_FAULT_NESTING,
		       "hole 1 lies outside the outer loop", NULL);
	/* a hole inside a hole */
	memset(&d, 0, sizeof(d));
	d.n = 3;
	add_polygon(&d.s[0], (double[]){0, 0, 4, 0, 4, 4, 0, 4}, 4);
	add_circle(&d.s[1], 2, 2, 1.5, -2 * M_PI);
	add_circle(&d.s[2], 2, 2, 0.5, -2 * M_PI);
	expect_refusal(&d, PX_E_INVAL, PX_TRIM_FAULT_NESTING, "hole 2 lies inside hole 1", NULL);
	/* zero area: there and back */
	memset(&d, 0, sizeof(d));
	d.n = 2;
	add_polygon(&d.s[0], sq, 4);
	add_line(&d.s[1], 0.2, 0.5, 0.8, 0.5);
	add_line(&d.s[1], 0.8, 0.5, 0.2, 0.5);
	expect_refusal(&d, PX_E_DEGENERATE, PX_TRIM_FAULT_AREA, "hole 1 encloses zero area", NULL);
	/* zero area: collinear, one way and back over three curves */
	memset(&d, 0, sizeof(d));
	d.n = 1;
	add_line(&d.s[0], 0, 0, 1, 1);
	add_line(&d.s[0], 1, 1, 2, 2);
	add_line(&d.s[0], 2, 2, 0, 0);
	expect_refusal(&d, PX_E_DEGENERATE, PX_TRIM_FAULT_AREA, "outer loop encloses zero area", NULL);
	/* everything at one point */
	memset(&d, 0, sizeof(d));
	d.n = 1;
	add_line(&d.s[0], 0.5, 0.5, 0.5, 0.5);
	expect_refusal(&d, PX_E_DEGENERATE, PX_TRIM_FAULT_EMPTY, "no extent", NULL);
	/* a curve the kernel refuses, named */
	memset(&d, 0, sizeof(d));
	d.n = 2;
	add_polygon(&d.s[0], sq, 4);
	add_circle(&d.s[1], 0.5, 0.5, 0.2, -2 * M_PI);
	d.s[1].knots[0][5] = 0.1; /* decreasing knot */
	expect_refusal(&d, PX_E_INVAL, PX_TRIM_FAULT_CURVE, "hole 1 curve 0: knot", NULL);
	/* arguments */
	PX_CHECK_INT_EQ(px_trim_create(NULL, 1, NULL, &e, &t), PX_E_INVAL);
	PX_CHECK_INT_EQ(e.fault, PX_TRIM_FAULT_ARG);
	PX_CHECK_INT_EQ(px_trim_contains(NULL, 0, 0, NULL), PX_E_INVAL);
	px_trim_free(NULL);
}

/* Touching within tolerance but not crossing, tangent joints, a loop of
 * one closed curve, many curves: all accepted. */
static void test_accepts(void)
{
	static struct dom d;
	struct px_trim_error e;
	struct px_trim *t;
	int i;
	double xy[2 * 41], U[43];

	/* a 40-gon as one degree-1 curve, a circle hole close to it */
	memset(&d, 0, sizeof(d));
	d.n = 2;
	for (i = 0; i <= 40; i++) {
		double a = 2 * M_PI * (i % 40) / 40;
		xy[2 * i] = cos(a), xy[2 * i + 1] = sin(a);
		U[i + 1] = i / 40.0;
	}
	U[0] = 0, U[42] = 1;
	add_curve(&d.s[0], 1, 41, xy, NULL, U);
	add_circle(&d.s[1], 0.0, 0.0, 0.99, 2 * M_PI);
	t = build(&d, &e);
	PX_CHECK_INT_EQ(px_trim_contains(t, 0, 0, NULL), PX_TRIM_OUTSIDE);
	PX_CHECK_INT_EQ(px_trim_contains(t, 0.0, 0.991, NULL), PX_TRIM_INSIDE);
	PX_CHECK_INT_EQ(px_trim_contains(t, 0.0, 0.989, NULL), PX_TRIM_OUTSIDE);
	PX_CHECK_INT_EQ(px_trim_loop_reversed(t, 1), 1);
	PX_CHECK(px_trim_piece_count(t) >= 20);
	PX_CHECK(px_trim_grid_size(t) >= 16);
	PX_CHECK_INT_EQ(px_trim_loop_count(t), 2);
	px_trim_free(t);
}

/* Rays through vertices, along horizontal edges, points on corners and
 * on grid lines: the half-open crossing rule must hold everywhere. */
static void test_degenerate_rays(void)
{
	static struct dom d;
	struct px_trim_error e;
	struct px_trim *t;
	double sq[8] = {0, 0, 1, 0, 1, 1, 0, 1};
	double dia[8] = {0.5, 0.1, 0.7, 0.3, 0.5, 0.5, 0.3, 0.3};
	double rect[8] = {0.25, 0.6, 0.25, 0.8, 0.75, 0.8, 0.75, 0.6};
	int g, i;

	for (g = 0; g <= 5; g++) {
		struct px_trim_opts o;
		int k;
		memset(&d, 0, sizeof(d));
		d.n = 3;
		add_polygon(&d.s[0], sq, 4);
		add_polygon(&d.s[1], dia, 4);  /* counter-clockwise: reversed */
		add_polygon(&d.s[2], rect, 4); /* clockwise */
		for (k = 0; k < 3; k++) {
			d.loops[k].curves = d.s[k].c;
			d.loops[k].n_curves = d.s[k].n;
			d.loops[k].reversed = NULL;
		}
		px_trim_opts_default(&o);
		o.grid = g == 0 ? 0 : (int[]){1, 2, 4, 5, 256}[g - 1];
		PX_CHECK_MSG(px_trim_create(d.loops, 3, &o, &e, &t) == PX_OK, "%s", e.msg);
		PX_CHECK_INT_EQ(px_trim_loop_reversed(t, 1), 1);
		PX_CHECK_INT_EQ(px_trim_loop_reversed(t, 2), 0);
		/* through the diamond's vertices */
		PX_CHECK_INT_EQ(px_trim_contains(t, 0.1, 0.3, NULL), PX_TRIM_INSIDE);
		PX_CHECK_INT_EQ(px_trim_contains(t, 0.1, 0.1, NULL), PX_TRIM_INSIDE);
		PX_CHECK_INT_EQ(px_trim_contains(t, 0.1, 0.5, NULL), PX_TRIM_INSIDE);
		PX_CHECK_INT_EQ(px_trim_contains(t, 0.5, 0.3, NULL), PX_TRIM_OUTSIDE);
		PX_CHECK_INT_EQ(px_trim_contains(t, 0.8, 0.3, NULL), PX_TRIM_INSIDE);
		PX_CHECK_INT_EQ(px_trim_contains(t, 0.5, 0.1, NULL), PX_TRIM_BOUNDARY);
		PX_CHECK_INT_EQ(px_trim_contains(t, 0.7, 0.3, NULL), PX_TRIM_BOUNDARY);
		/* along the rectangle's horizontal edges */
		PX_CHECK_INT_EQ(px_trim_contains(t, 0.1, 0.6, NULL), PX_TRIM_INSIDE);
		PX_CHECK_INT_EQ(px_trim_contains(t, 0.1, 0.8, NULL), PX_TRIM_INSIDE);
		PX_CHECK_INT_EQ(px_trim_contains(t, 0.9, 0.8, NULL), PX_TRIM_INSIDE);
		PX_CHECK_INT_EQ(px_trim_contains(t, 0.5, 0.6, NULL), PX_TRIM_BOUNDARY);
		PX_CHECK_INT_EQ(px_trim_contains(t, 0.25, 0.8, NULL), PX_TRIM_BOUNDARY);
		PX_CHECK_INT_EQ(px_trim_contains(t, 0.5, 0.7, NULL), PX_TRIM_OUTSIDE);
		/* the outer corners and edges, just in and out */
		PX_CHECK_INT_EQ(px_trim_contains(t, 0, 0, NULL), PX_TRIM_BOUNDARY);
		PX_CHECK_INT_EQ(px_trim_contains(t, 1, 1, NULL), PX_TRIM_BOUNDARY);
		PX_CHECK_INT_EQ(px_trim_contains(t, 1e-12, 1e-12, NULL), PX_TRIM_INSIDE);
		PX_CHECK_INT_EQ(px_trim_contains(t, -1e-12, 0.5, NULL), PX_TRIM_OUTSIDE);
		PX_CHECK_INT_EQ(px_trim_contains(t, 0.5, 1 + 1e-12, NULL), PX_TRIM_OUTSIDE);
		/* every grid line and random points against the exact answer */
		for (i = 0; i < 20000; i++) {
			int kind = i % 3;
			double u = px_rand_range(-0.05, 1.05), v = px_rand_range(-0.05, 1.05);
			int want, got, on;
			if (kind == 1) /* on a grid line or a vertex's height */
				v = (double)px_rand_int(0, 20) / 20;
			if (kind == 2)
				u = (double)px_rand_int(0, 20) / 20;
			{
				double ax = fabs(u - 0.5), ay = fabs(v - 0.3);
				int in_sq = u > 0 && u < 1 && v > 0 && v < 1;
				int in_dia = ax + ay < 0.2;
				int in_rect = u > 0.25 && u < 0.75 && v > 0.6 && v < 0.8;
				on = (u >= 0 && u <= 1 && v >= 0 && v <= 1 && !in_sq) ||
				     fabs(ax + ay - 0.2) < 1e-9 ||
				     (u >= 0.25 && u <= 0.75 && v >= 0.6 && v <= 0.8 && !in_rect);
				want = in_sq && !in_dia && !in_rect;
			}
			got = px_trim_contains(t, u, v, NULL);
			if (on)
				continue;
			PX_CHECK_MSG(got == want, "grid %d (%.17g, %.17g): got %d want %d",
				     px_trim_grid_size(t), u, v, got, want);
		}
		px_trim_free(t);
	}
}

/* The grid changes the speed, never an answer. */
static void test_grid_sizes(void)
{
	struct dom d;
	struct px_trim_error e;
	struct px_trim *ref, *t;
	int gs[] = {1, 2, 3, 7, 40, 256}, gi, i, k;

	make_blobs(&d, 3, 0);
	ref = build(&d, &e);
	for (gi = 0; gi < 6; gi++) {
		struct px_trim_opts o;
		px_trim_opts_default(&o);
		o.grid = gs[gi];
		for (k = 0; k < d.n; k++) {
			d.loops[k].curves = d.s[k].c;
			d.loops[k].n_curves = d.s[k].n;
			d.loops[k].reversed = d.s[k].rev;
		}
		PX_CHECK_MSG(px_trim_create(d.loops, d.n, &o, &e, &t) == PX_OK, "%s", e.msg);
		PX_CHECK_INT_EQ(px_trim_grid_size(t), gs[gi]);
		for (i = 0; i < 20000; i++) {
			double u = px_rand_range(-1.1, 1.1), v = px_rand_range(-1.1, 1.1);
			int a = px_trim_contains(ref, u, v, NULL), b = px_trim_contains(t, u, v, NULL);
			PX_CHECK_MSG(a == b, "grid %d (%.17g, %.17g): %d vs %d", gs[gi], u, v, b, a);
			if (i % 8 == 0) {
				double s = pow(10, px_rand_range(-6, 0));
				int ca = px_trim_classify_box(ref, u, u + s, v, v + s);
				int cb = px_trim_classify_box(t, u, u + s, v, v + s);
				PX_CHECK(ca == cb || ca == PX_TRIM_BOX_CROSSED || cb == PX_TRIM_BOX_CROSSED);
			}
		}
		px_trim_free(t);
	}
	px_trim_free(ref);
}

/* Loops near each other but apart are accepted; closer than the
 * touching tolerance they are refused. */
static void test_near_loops(void)
{
	static struct dom d;
	double sq[8] = {0, 0, 1, 0, 1, 1, 0, 1};
	double gaps[] = {1e-3, 1e-6, 1e-8};
	int i;

	for (i = 0; i < 3; i++) {
		struct px_trim_error e;
		struct px_trim *t = NULL;
		int rc;
		memset(&d, 0, sizeof(d));
		d.n = 2;
		add_polygon(&d.s[0], sq, 4);
		add_circle(&d.s[1], 0.5, 0.3 + gaps[i], 0.3, -2 * M_PI);
		d.loops[0] = (struct px_trim_loop){d.s[0].c, 4, NULL};
		d.loops[1] = (struct px_trim_loop){d.s[1].c, 1, NULL};
		rc = px_trim_create(d.loops, 2, NULL, &e, &t);
		PX_CHECK_MSG(rc == PX_OK, "gap %g: %s", gaps[i], e.msg);
		PX_CHECK_INT_EQ(px_trim_contains(t, 0.5, 0.5 * gaps[i], NULL), PX_TRIM_INSIDE);
		PX_CHECK_INT_EQ(px_trim_contains(t, 0.5, 2 * gaps[i], NULL), PX_TRIM_OUTSIDE);
		px_trim_free(t);
	}
	memset(&d, 0, sizeof(d));
	d.n = 2;
	add_polygon(&d.s[0], sq, 4);
	add_circle(&d.s[1], 0.5, 0.3 + 1e-13, 0.3, -2 * M_PI);
	expect_refusal(&d, PX_E_INVAL, PX_TRIM_FAULT_CROSS,
		       "outer loop curve 0 and hole 1 curve 0 cross or touch", NULL);
}

/* Queries make no heap calls. */
static void test_no_alloc(void)
{
	struct dom d;
	struct px_trim_error e;
	struct px_trim *t;
	uint64_t a;
	int i, sum = 0;

	make_blobs(&d, 3, 1);
	t = build(&d, &e);
	a = px_alloc_region_begin();
	for (i = 0; i < 20000; i++) {
		double u = px_rand_range(-1.1, 1.1), v = px_rand_range(-1.1, 1.1);
		struct px_trim_hit h;
		sum += px_trim_contains(t, u, v, &h);
		sum += px_trim_classify_box(t, u, u + 0.05, v, v + 0.02);
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(a), 0);
	PX_CHECK(sum > 0);
	px_trim_free(t);
}

static const struct px_test tests[] = {
	PX_T(test_square_disc), PX_T(test_scales), PX_T(test_blobs_vs_polygon),
	PX_T(test_boxes), PX_T(test_refusals), PX_T(test_accepts),
	PX_T(test_degenerate_rays), PX_T(test_grid_sizes), PX_T(test_near_loops),
	PX_T(test_no_alloc)};
PX_TEST_MAIN(tests)
