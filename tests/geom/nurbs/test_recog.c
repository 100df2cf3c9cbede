/* Recognition of exact primitives and closed-form closest points vs brute
 * force over the entity's own parameter domain. */
#include <math.h>
#include <string.h>

#include <stdio.h>

#include "arc_gen.h"
#include "px_alloc_count.h"
#include "px_obj.h"
#include "px_recog.h"
#include "px_test.h"

#define PI 3.14159265358979323846
#define MAXC 96

struct tcurve {
	double U[MAXC + 16], pw[4 * MAXC];
	struct px_nurbs_curve c;
};

struct tsurf {
	double U[MAXC + 16], V[MAXC + 16], pw[4 * MAXC * MAXC / 4];
	struct px_nurbs_surf s;
};

struct frame {
	px_vec3 o, x, y, z;
};

static px_vec3 rand_unit(void)
{
	px_vec3 v;
	do
		v = px_v3(px_rand_normal(), px_rand_normal(), px_rand_normal());
	while (px_v3_norm(v) < 1e-3);
	return px_v3_scale(v, 1.0 / px_v3_norm(v));
}

static struct frame rand_frame(void)
{
	struct frame f;
	px_vec3 t;
	f.o = px_v3(px_rand_range(-3, 3), px_rand_range(-3, 3), px_rand_range(-3, 3));
	f.x = rand_unit();
	do {
		t = rand_unit();
		t = px_v3_madd(t, f.x, -px_v3_dot(t, f.x));
	} while (px_v3_norm(t) < 1e-2);
	f.y = px_v3_scale(t, 1.0 / px_v3_norm(t));
	f.z = px_v3_cross(f.x, f.y);
	return f;
}

static px_vec3 fr(const struct frame *f, double x, double y, double z)
{
	return px_v3_add(f->o, px_v3_add(px_v3_scale(f->x, x),
					 px_v3_add(px_v3_scale(f->y, y),
						   px_v3_scale(f->z, z))));
}

static void set_pw(double *pw, px_vec3 p, double w)
{
	pw[0] = p.x * w;
	pw[1] = p.y * w;
	pw[2] = p.z * w;
	pw[3] = w;
}

static int view_curve(struct tcurve *t, int p, int n)
{
	return px_nurbs_curve_view(&t->c, p, n, t->U, n + p + 1, t->pw, NULL);
}

/* Circle arc of radius r in frame f: sweep over nseg spans, degree
 * elevated by elev (each span on its own, C0 joins). */
static int make_arc(struct tcurve *t, const struct frame *f, double r,
		    double sweep, int nseg, int elev)
{
	double xy[2 * MAXC], w[MAXC], U[MAXC];
	double bz[12][4];
	int s, i, k, q = 2 + elev, np = 0, nk = 0;
	arc2d(0, sweep, nseg, xy, w, U);
	for (s = 0; s < nseg; s++) {
		int n = 2;
		for (i = 0; i < 3; i++) {
			px_vec3 p = fr(f, r * xy[2 * (2 * s + i)],
				       r * xy[2 * (2 * s + i) + 1], 0);
			set_pw(bz[i], p, w[2 * s + i]);
		}
		for (k = 0; k < elev; k++, n++) {
			double nb[12][4];
			int j, m;
			for (m = 0; m < 4; m++)
				nb[0][m] = bz[0][m], nb[n + 1][m] = bz[n][m];
			for (j = 1; j <= n; j++)
				for (m = 0; m < 4; m++)
					nb[j][m] = (double)j / (n + 1) * bz[j - 1][m] +
						   (1 - (double)j / (n + 1)) * bz[j][m];
			memcpy(bz, nb, sizeof(nb));
		}
		for (i = (s == 0 ? 0 : 1); i <= q; i++)
			memcpy(t->pw + 4 * np++, bz[i], 4 * sizeof(double));
	}
	for (i = 0; i <= q; i++)
		t->U[nk++] = 0;
	for (s = 1; s < nseg; s++)
		for (i = 0; i < q; i++)
			t->U[nk++] = (double)s / nseg;
	for (i = 0; i <= q; i++)
		t->U[nk++] = 1;
	return view_curve(t, q, np);
}

/* Straight curve: collinear control points at sorted random stations,
 * random weights and interior knots. */
static int make_line(struct tcurve *t, const struct frame *f, int p, int n,
		     double L, int rational, int uniform)
{
	int i, k = 0;
	double st[MAXC];
	for (i = 0; i < n; i++)
		st[i] = px_rand_range(0, L);
	for (i = 1; i < n; i++) { /* insertion sort */
		double v = st[i];
		int j = i - 1;
		while (j >= 0 && st[j] > v)
			st[j + 1] = st[j], j--;
		st[j + 1] = v;
	}
	if (!uniform)
		st[0] = 0, st[n - 1] = L;
	for (i = 0; i < n; i++)
		set_pw(t->pw + 4 * i, fr(f, st[i], 0, 0),
		       rational ? px_rand_range(0.2, 5) : 1.0);
	for (i = 0; i <= p; i++)
		t->U[k++] = 0;
	for (i = 1; i < n - p; i++)
		t->U[k++] = uniform ? (double)i / (n - p) : px_rand_range(0.05, 0.95);
	for (i = p + 1; i < n; i++) { /* sort interior knots */
		double v = t->U[i];
		int j = i - 1;
		while (j > p && t->U[j] > v)
			t->U[j + 1] = t->U[j], j--;
		t->U[j + 1] = v;
	}
	for (i = 0; i <= p; i++)
		t->U[k++] = 1;
	if (uniform) /* stations at the Greville abscissae: linear in u */
		for (i = 0; i < n; i++) {
			double g = 0;
			for (k = 1; k <= p; k++)
				g += t->U[i + k];
			st[i] = L * g / p;
		}
	for (i = 0; i < n; i++)
		set_pw(t->pw + 4 * i, fr(f, st[i], 0, 0), t->pw[4 * i + 3]);
	return view_curve(t, p, n);
}

/* ---- brute force references --------------------------------------------- */

/* Distance from the query point to the point at t of a 1D path. */
typedef double (*path_dist_fn)(const void *ctx, double t);

/* Minimum of dist over [t0, t1]: n + 1 samples, then a ternary polish
 * (iters steps) around up to 16 promising local minima of the samples
 * (a seam or a symmetric query has several; at a centre all tie).
 * *tbest (may be NULL) gets the parameter of the minimum. */
static double path_brute(path_dist_fn dist, const void *ctx, double t0,
			 double t1, int n, int iters, double *tbest)
{
	double d[3001];
	double best = INFINITY, bt = 0, dmin = INFINITY, dmax = 0;
	int i, it, npol = 0;
	if (n > 3000)
		n = 3000;
	for (i = 0; i <= n; i++) {
		d[i] = dist(ctx, t0 + (t1 - t0) * i / n);
		dmin = fmin(dmin, d[i]);
		dmax = fmax(dmax, d[i]);
	}
	for (i = 0; i <= n && npol < 16; i++) {
		double lo, hi, dm;
		if ((i > 0 && d[i] > d[i - 1]) || (i < n && d[i] > d[i + 1]) ||
		    d[i] > dmin + 0.05 * (dmax - dmin))
			continue;
		npol++;
		lo = fmax(t0, t0 + (t1 - t0) * (i - 1) / n);
		hi = fmin(t1, t0 + (t1 - t0) * (i + 1) / n);
		for (it = 0; it < iters; it++) {
			double a = lo + (hi - lo) / 3, b = hi - (hi - lo) / 3;
			if (dist(ctx, a) < dist(ctx, b))
				hi = b;
			else
				lo = a;
		}
		dm = dist(ctx, 0.5 * (lo + hi));
		if (d[i] < dm)
			dm = d[i], lo = hi = t0 + (t1 - t0) * i / n;
		if (dm < best)
			best = dm, bt = 0.5 * (lo + hi);
	}
	if (tbest)
		*tbest = bt;
	return best;
}

struct curve_path {
	const struct px_nurbs_curve *c;
	px_vec3 p;
};

static double curve_path_dist(const void *ctx, double u)
{
	const struct curve_path *q = ctx;
	return px_v3_dist(q->p, px_nurbs_curve_point(q->c, u));
}

static double curve_brute(const struct px_nurbs_curve *c, px_vec3 p, double *ub)
{
	struct curve_path q = {c, p};
	double u0, u1;
	px_nurbs_curve_domain(c, &u0, &u1);
	return path_brute(curve_path_dist, &q, u0, u1, 3000, 200, ub);
}

/* One boundary of a patch: u runs at v = fixed (along_u) or v runs at
 * u = fixed. */
struct edge_path {
	const struct px_nurbs_surf *s;
	px_vec3 p;
	int along_u;
	double fixed;
};

static double edge_path_dist(const void *ctx, double t)
{
	const struct edge_path *q = ctx;
	return px_v3_dist(q->p, q->along_u
					? px_nurbs_surf_point(q->s, t, q->fixed)
					: px_nurbs_surf_point(q->s, q->fixed, t));
}

/* Dense samples plus ternary polish along one boundary of the patch
 * (edge 0..3: v = v0, v = v1, u = u0, u = u1): minima on the boundary
 * are found by a 1D search, which a 2D pattern search misses near a
 * pole. */
static double surf_edge_brute(const struct px_nurbs_surf *s, px_vec3 p, int edge)
{
	struct edge_path q;
	double u0, u1, v0, v1;
	px_nurbs_surf_domain(s, &u0, &u1, &v0, &v1);
	q.s = s;
	q.p = p;
	q.along_u = edge < 2;
	q.fixed = edge == 0 ? v0 : edge == 1 ? v1 : edge == 2 ? u0 : u1;
	return q.along_u ? path_brute(edge_path_dist, &q, u0, u1, 400, 120, NULL)
			 : path_brute(edge_path_dist, &q, v0, v1, 400, 120, NULL);
}

/* Damped Newton on |S - p|^2 / 2 from (*bu, *bv), clamped to the
 * domain; keeps only steps that go down (halving them up to 20 times).
 * The pattern search crawls in the curved valleys near a pole. */
static void newton_polish(const struct px_nurbs_surf *s, px_vec3 p, double *bu,
			  double *bv, double *bd)
{
	double u0, u1, v0, v1;
	int it;
	px_nurbs_surf_domain(s, &u0, &u1, &v0, &v1);
	for (it = 0; it < 60; it++) {
		struct px_nurbs_surf_derivs sd;
		px_vec3 r;
		double g1, g2, h11, h12, h22, det, du, dv, lam = 1;
		int k, ok = 0;
		px_nurbs_surf_eval(s, *bu, *bv, 2, &sd);
		r = px_v3_sub(sd.s, p);
		g1 = px_v3_dot(r, sd.su);
		g2 = px_v3_dot(r, sd.sv);
		h11 = px_v3_dot(sd.su, sd.su) + px_v3_dot(r, sd.suu);
		h12 = px_v3_dot(sd.su, sd.sv) + px_v3_dot(r, sd.suv);
		h22 = px_v3_dot(sd.sv, sd.sv) + px_v3_dot(r, sd.svv);
		det = h11 * h22 - h12 * h12;
		if (det > 0 && h11 > 0) {
			du = -(h22 * g1 - h12 * g2) / det;
			dv = -(h11 * g2 - h12 * g1) / det;
		} else { /* not convex here: gradient direction */
			double gn = hypot(g1, g2);
			if (!(gn > 0))
				return;
			du = -g1 / gn * 1e-2 * (u1 - u0);
			dv = -g2 / gn * 1e-2 * (v1 - v0);
		}
		for (k = 0; k < 20 && !ok; k++, lam *= 0.5) {
			double u = fmin(u1, fmax(u0, *bu + lam * du));
			double v = fmin(v1, fmax(v0, *bv + lam * dv));
			double d = px_v3_dist(p, px_nurbs_surf_point(s, u, v));
			if (d < *bd)
				*bd = d, *bu = u, *bv = v, ok = 1;
		}
		if (!ok)
			return;
	}
}

static double surf_brute(const struct px_nurbs_surf *s, px_vec3 p)
{
	double u0, u1, v0, v1, best = INFINITY;
	enum { NC = 4 };
	double cu[NC] = {0}, cv[NC] = {0}, cd[NC];
	px_vec3 cx[NC];
	int i, j, N = 40, k;
	px_nurbs_surf_domain(s, &u0, &u1, &v0, &v1);
	for (k = 0; k < NC; k++)
		cd[k] = INFINITY;
	for (i = 0; i <= N; i++)
		for (j = 0; j <= N; j++) {
			double u = u0 + (u1 - u0) * i / N, v = v0 + (v1 - v0) * j / N;
			px_vec3 x = px_nurbs_surf_point(s, u, v);
			double d = px_v3_dist(p, x);
			int m, dup = 0;
			/* At most two samples of one point: a pole repeats a
			 * point along a whole row, a seam twice. */
			for (m = 0; m < NC; m++)
				if (cd[m] < INFINITY && px_v3_dist(x, cx[m]) < 1e-9)
					dup++;
			for (m = 0; m < NC && dup < 2; m++)
				if (d < cd[m]) {
					int q;
					for (q = NC - 1; q > m; q--)
						cd[q] = cd[q - 1], cu[q] = cu[q - 1],
						cv[q] = cv[q - 1], cx[q] = cx[q - 1];
					cd[m] = d, cu[m] = u, cv[m] = v, cx[m] = x;
					break;
				}
		}
	/* Strips just inside each edge: a minimum beside a pole is missed
	 * by the coarse grid (the pole row is nearer than the next row)
	 * and cannot be reached from the pole, where the parametrization
	 * is singular. The best strip sample of each edge is polished too. */
	double su[4], sv[4], sdist[4];
	for (k = 0; k < 4; k++) {
		int m, o;
		sdist[k] = INFINITY;
		for (o = 0; o < 3; o++)
			for (m = 0; m <= 120; m++) {
				double off = (o == 0 ? 0.002 : o == 1 ? 0.006 : 0.015);
				double a = (double)m / 120, u, v, d;
				u = k < 2 ? u0 + (u1 - u0) * a
					  : (k == 2 ? u0 + off * (u1 - u0) : u1 - off * (u1 - u0));
				v = k >= 2 ? v0 + (v1 - v0) * a
					   : (k == 0 ? v0 + off * (v1 - v0) : v1 - off * (v1 - v0));
				d = px_v3_dist(p, px_nurbs_surf_point(s, u, v));
				if (d < sdist[k])
					sdist[k] = d, su[k] = u, sv[k] = v;
			}
	}
	for (k = 0; k < NC + 4; k++) {
		double hu = (u1 - u0) / N, hv = (v1 - v0) / N, bu, bv, bd;
		if (k < NC) {
			if (!(cd[k] < INFINITY))
				continue;
			bu = cu[k], bv = cv[k], bd = cd[k];
		} else {
			bu = su[k - NC], bv = sv[k - NC], bd = sdist[k - NC];
			hu *= 0.1, hv *= 0.1;
		}
		int it;
		newton_polish(s, p, &bu, &bv, &bd);
		/* Compass search: keep the step while it improves, halve it
		 * when it does not. */
		for (it = 0; it < 1500 && hu > 1e-13 * (u1 - u0); it++) {
			double nu = bu, nv = bv;
			int a, b, moved = 0;
			for (a = -1; a <= 1; a++)
				for (b = -1; b <= 1; b++) {
					double u = fmin(u1, fmax(u0, bu + a * hu));
					double v = fmin(v1, fmax(v0, bv + b * hv));
					double d = px_v3_dist(p, px_nurbs_surf_point(s, u, v));
					if (d < bd)
						bd = d, nu = u, nv = v, moved = 1;
				}
			bu = nu, bv = nv;
			if (!moved)
				hu *= 0.5, hv *= 0.5;
		}
		newton_polish(s, p, &bu, &bv, &bd);
		if (bd < best)
			best = bd;
	}
	for (k = 0; k < 4; k++)
		best = fmin(best, surf_edge_brute(s, p, k));
	return best;
}

/* ---- curve tests ----------------------------------------------------------- */

static void check_curve_queries(const struct px_recog_shape *pr,
				const struct px_nurbs_curve *c, int nq,
				const px_vec3 *extra, int n_extra)
{
	int q;
	double tol = 1e-9 * pr->size;
	px_aabb b = px_nurbs_curve_aabb(c);
	px_vec3 mid = px_v3_scale(px_v3_add(b.min, b.max), 0.5);
	for (q = 0; q < nq + n_extra; q++) {
		struct px_recog_hit h;
		px_vec3 p;
		double ref, ub;
		if (q < n_extra)
			p = extra[q];
		else if (q == n_extra) /* far away */
			p = px_v3_madd(mid, rand_unit(), 100 * pr->size);
		else if (q % 4 == 0) /* on the curve */
			p = px_nurbs_curve_point(c, c->knots[c->degree] +
							    px_rand_unit() *
								    (c->knots[c->n_ctrl] -
								     c->knots[c->degree]));
		else
			p = px_v3_madd(mid, rand_unit(),
				       pr->size * px_rand_range(0, q % 4 == 1 ? 0.3 : 2));
		PX_CHECK_INT_EQ(px_recog_closest(pr, p, PX_RECOG_WANT_PARAMS, &h), PX_OK);
		ref = curve_brute(c, p, &ub);
		PX_CHECK_MSG(h.dist <= ref + tol && ref <= h.dist + tol,
			     "%s: closed form %.17g brute %.17g (at u %.17g; hit u %.17g, "
			     "entity there %.17g; query %d)",
			     px_recog_kind_name(pr->kind), h.dist, ref, ub, h.u,
			     px_v3_dist(p, px_nurbs_curve_point(c, h.u)), q);
		PX_CHECK_MSG(px_v3_dist(px_nurbs_curve_point(c, h.u), h.point) <= 1e-8 * pr->size,
			     "parameter %.17g gives a point %.3g away", h.u,
			     px_v3_dist(px_nurbs_curve_point(c, h.u), h.point));
		PX_CHECK_NEAR(px_v3_dist(p, h.point), h.dist, 1e-12 * pr->size);
		PX_CHECK_INT_EQ(h.param, (pr->kind == PX_RECOG_ARC && pr->qarc[0].n) ||
						 (pr->kind == PX_RECOG_SEGMENT && pr->linear)
					 ? PX_RECOG_PARAM_EXACT
					 : PX_RECOG_PARAM_SOLVED);
	}
}

static void test_circle_full_and_arcs(void)
{
	int trial;
	for (trial = 0; trial < 60; trial++) {
		struct tcurve t;
		struct px_recog_shape pr;
		struct frame f = rand_frame();
		double r = px_rand_range(0.1, 10), sweep;
		int nseg, elev = trial % 4 == 3 ? px_rand_int(1, 8) : 0;
		px_vec3 extra[3];
		if (trial % 3 == 0) {
			sweep = 2 * PI, nseg = 4; /* 9-point circle */
		} else if (trial % 3 == 1) {
			sweep = px_rand_range(PI / 4, PI * 179.0 / 180), nseg = 1;
		} else {
			sweep = px_rand_range(0.5, 2 * PI);
			nseg = (int)ceil(sweep / (PI / 2) - 1e-9);
		}
		PX_CHECK_INT_EQ(make_arc(&t, &f, r, sweep, nseg, elev), PX_OK);
		if (trial % 2) {
			/* Scaling homogeneous point m by k^m re-parametrizes
			 * every span (Moebius) and keeps the shape: the
			 * parameter-angle relation is no longer the standard
			 * one. */
			double k = px_rand_range(0.4, 2.5), sc = 1;
			int m, j;
			for (m = 0; m < t.c.n_ctrl; m++, sc *= k)
				for (j = 0; j < 4; j++)
					t.pw[4 * m + j] *= sc;
		}
		PX_CHECK_INT_EQ(px_recog_curve(&t.c, 0, &pr), 1);
		PX_CHECK_INT_EQ(pr.kind, PX_RECOG_ARC);
		if (pr.kind != PX_RECOG_ARC)
			continue;
		PX_CHECK_NEAR(pr.arc.radius, r, 1e-12 * r);
		PX_CHECK_NEAR(px_v3_dist(pr.arc.center, f.o), 0, 1e-12 * r);
		PX_CHECK_NEAR(pr.arc.sweep, sweep, 1e-11);
		PX_CHECK_NEAR(fabs(px_v3_dot(pr.arc.normal, f.z)), 1, 1e-12);
		PX_CHECK(pr.hausdorff <= 1e-10 * pr.size);
		/* Quadratic arcs invert in closed form, Moebius weights too. */
		PX_CHECK_INT_EQ(pr.qarc[0].n > 0, elev == 0);
		extra[0] = f.o; /* centre: every point equally near */
		extra[1] = fr(&f, 0, 0, r * px_rand_range(-2, 2)); /* on the axis */
		extra[2] = fr(&f, -r * 0.7, r * 0.01, r * 0.3);
		check_curve_queries(&pr, &t.c, 24, extra, 3);
		pr.qarc[0].n = 0; /* the bounded inversion instead */
		check_curve_queries(&pr, &t.c, 6, extra, 3);
		{
			struct px_recog_hit h;
			px_recog_closest(&pr, f.o, 0, &h);
			PX_CHECK(h.tie);
			PX_CHECK_NEAR(h.dist, r, 1e-12 * r);
		}
	}
}

static void test_lines(void)
{
	int trial;
	for (trial = 0; trial < 80; trial++) {
		struct tcurve t;
		struct px_recog_shape pr;
		struct frame f = rand_frame();
		int p = 1 + trial % 5, n = p + 1 + px_rand_int(0, 4);
		int uniform = trial % 4 == 0, rational = !uniform && trial % 2;
		double L = px_rand_range(0.5, 20);
		px_vec3 extra[2];
		PX_CHECK_INT_EQ(make_line(&t, &f, p, n, L, rational, uniform), PX_OK);
		if (trial % 8 == 5) { /* unclamped uniform knots */
			int k;
			double u0, u1;
			for (k = 0; k < n + p + 1; k++)
				t.U[k] = 0.5 * k;
			PX_CHECK_INT_EQ(view_curve(&t, p, n), PX_OK);
			px_nurbs_curve_domain(&t.c, &u0, &u1);
			L = px_v3_dist(px_nurbs_curve_point(&t.c, u0),
				       px_nurbs_curve_point(&t.c, u1));
		}
		PX_CHECK_INT_EQ(px_recog_curve(&t.c, 0, &pr), 1);
		PX_CHECK_INT_EQ(pr.kind, PX_RECOG_SEGMENT);
		if (pr.kind != PX_RECOG_SEGMENT)
			continue;
		PX_CHECK_NEAR(pr.seg.len, L, 1e-12 * L);
		PX_CHECK_NEAR(px_v3_dot(pr.seg.dir, f.x), 1, 1e-12);
		if (uniform)
			PX_CHECK(pr.linear);
		extra[0] = fr(&f, -L, 0.3, 0);
		extra[1] = fr(&f, 0.5 * L, 0, 0);
		check_curve_queries(&pr, &t.c, 20, extra, 2);
	}
}

static void test_curve_near_misses(void)
{
	int trial;
	for (trial = 0; trial < 60; trial++) {
		struct tcurve t;
		struct px_recog_shape pr;
		struct frame f = rand_frame();
		double r = px_rand_range(0.5, 5);
		int i, k;
		switch (trial % 5) {
		case 0: /* circle with one control point moved by 1e-6 size */
			make_arc(&t, &f, r, px_rand_range(1, 2 * PI), 4, trial % 2);
			k = px_rand_int(0, t.c.n_ctrl - 1);
			{
				px_vec3 d = px_v3_scale(rand_unit(), 2e-6 * r);
				for (i = 0; i < 3; i++)
					t.pw[4 * k + i] += px_v3_comp(d, i) * t.pw[4 * k + 3];
			}
			break;
		case 1: /* ellipse: circle stretched by 1e-6 or more */
			make_arc(&t, &f, r, px_rand_range(1, 2 * PI), 4, 0);
			for (k = 0; k < t.c.n_ctrl; k++) {
				px_vec3 q = px_v3_scale(px_v3(t.pw[4 * k], t.pw[4 * k + 1],
							      t.pw[4 * k + 2]),
							1.0 / t.pw[4 * k + 3]);
				double e = px_v3_dot(px_v3_sub(q, f.o), f.x);
				q = px_v3_madd(q, f.x, e * (trial % 2 ? 1e-6 : 0.3));
				set_pw(t.pw + 4 * k, q, t.pw[4 * k + 3]);
			}
			break;
		case 2: /* parabola (non-rational quadratic) */
			set_pw(t.pw, fr(&f, r, 0, 0), 1);
			set_pw(t.pw + 4, fr(&f, r, r, 0), 1);
			set_pw(t.pw + 8, fr(&f, 0, r, 0), 1);
			for (i = 0; i < 3; i++)
				t.U[i] = 0, t.U[i + 3] = 1;
			view_curve(&t, 2, 3);
			break;
		case 3: { /* line with a control point off by 1e-6 size */
			int p = px_rand_int(1, 4);
			make_line(&t, &f, p, p + 2, r, 1, 0);
			k = px_rand_int(0, t.c.n_ctrl - 1);
			for (i = 0; i < 3; i++)
				t.pw[4 * k + i] += 1e-6 * r * px_v3_comp(f.y, i) * t.pw[4 * k + 3];
			break;
		}
		default: { /* collinear but doubling back: not a monotone segment */
			set_pw(t.pw, fr(&f, 0, 0, 0), 1);
			set_pw(t.pw + 4, fr(&f, r, 0, 0), 1);
			set_pw(t.pw + 8, fr(&f, 0.2 * r, 0, 0), 1);
			set_pw(t.pw + 12, fr(&f, 0.5 * r, 0, 0), 1);
			for (i = 0; i < 3; i++)
				t.U[i] = 0, t.U[i + 4] = 1;
			t.U[3] = 0.5;
			view_curve(&t, 2, 4);
			break;
		}
		}
		PX_CHECK_MSG(px_recog_curve(&t.c, 0, &pr) == 0, "case %d recognised as %s",
			     trial % 5, px_recog_kind_name(pr.kind));
		PX_CHECK_INT_EQ(pr.kind, PX_RECOG_NONE);
	}
}

/* ---- surfaces ---------------------------------------------------------------- */

/* Surface of revolution: angular unit arc (xy, alpha, knots Ua, degree 2)
 * times profile (h_j, rho_j, beta_j, knots Vp, degree pp) in frame f,
 * axis f.z. transpose puts the angle along v. */
static int make_rev(struct tsurf *t, const struct frame *f, double a0,
		    double sweep, const double *hr, const double *beta, int np,
		    const double *Vp, int pp, int transpose)
{
	double xy[2 * MAXC], al[MAXC], Ua[MAXC];
	int nseg = (int)ceil(sweep / (PI / 2) - 1e-9), na, i, j;
	na = arc2d(a0, sweep, nseg, xy, al, Ua);
	for (i = 0; i < na; i++)
		for (j = 0; j < np; j++) {
			px_vec3 p = fr(f, hr[2 * j + 1] * xy[2 * i],
				       hr[2 * j + 1] * xy[2 * i + 1], hr[2 * j]);
			size_t idx = transpose ? (size_t)i * np + j : (size_t)j * na + i;
			set_pw(t->pw + 4 * idx, p, al[i] * beta[j]);
		}
	memcpy(transpose ? t->V : t->U, Ua, (size_t)(na + 3) * sizeof(double));
	memcpy(transpose ? t->U : t->V, Vp, (size_t)(np + pp + 1) * sizeof(double));
	if (!transpose)
		return px_nurbs_surf_view(&t->s, 2, pp, na, np, t->U, na + 3, t->V,
					  np + pp + 1, t->pw, NULL);
	return px_nurbs_surf_view(&t->s, pp, 2, np, na, t->U, np + pp + 1, t->V,
				  na + 3, t->pw, NULL);
}

/* Profile arc in the (h, rho) plane: centre (hc, rc), radius r, angles
 * [a0, a0 + sweep] measured from +h towards +rho. */
static int profile_arc(double hc, double rc, double r, double a0, double sweep,
		       double *hr, double *beta, double *V)
{
	double xy[2 * MAXC];
	int nseg = (int)ceil(sweep / (PI / 2) - 1e-9), n, j;
	n = arc2d(a0, sweep, nseg, xy, beta, V);
	for (j = 0; j < n; j++) {
		hr[2 * j] = hc + r * xy[2 * j];
		hr[2 * j + 1] = rc + r * xy[2 * j + 1];
	}
	return n;
}

static int profile_seg(double h0, double r0, double h1, double r1, int deg,
		       double *hr, double *beta, double *V)
{
	int j, n = deg + 1;
	for (j = 0; j < n; j++) {
		double s = (double)j / deg;
		hr[2 * j] = h0 + (h1 - h0) * s;
		hr[2 * j + 1] = r0 + (r1 - r0) * s;
		beta[j] = 1;
	}
	for (j = 0; j <= deg; j++)
		V[j] = 0, V[j + deg + 1] = 1;
	return n;
}

static void check_surf_queries(const struct px_recog_shape *pr,
			       const struct px_nurbs_surf *s, int nq,
			       const px_vec3 *extra, int n_extra)
{
	int q;
	double tol = 1e-9 * pr->size, u0, u1, v0, v1;
	px_aabb b = px_nurbs_surf_aabb(s);
	px_vec3 mid = px_v3_scale(px_v3_add(b.min, b.max), 0.5);
	px_nurbs_surf_domain(s, &u0, &u1, &v0, &v1);
	for (q = 0; q < nq + n_extra; q++) {
		struct px_recog_hit h;
		px_vec3 p;
		double ref;
		if (q < n_extra)
			p = extra[q];
		else if (q == n_extra)
			p = px_v3_madd(mid, rand_unit(), 100 * pr->size);
		else if (q % 4 == 0)
			p = px_nurbs_surf_point(s, u0 + (u1 - u0) * px_rand_unit(),
						v0 + (v1 - v0) * px_rand_unit());
		else
			p = px_v3_madd(mid, rand_unit(),
				       pr->size * px_rand_range(0, q % 4 == 1 ? 0.4 : 1.5));
		PX_CHECK_INT_EQ(px_recog_closest(pr, p, PX_RECOG_WANT_PARAMS, &h), PX_OK);
		ref = surf_brute(s, p);
		PX_CHECK_MSG(h.dist <= ref + tol && ref <= h.dist + tol,
			     "%s: closed form %.17g brute %.17g (query %d) p=(%g %g %g) hit=(%g %g) deg %d %d",
			     px_recog_kind_name(pr->kind), h.dist, ref, q, p.x, p.y, p.z, h.u, h.v, s->degree[0], s->degree[1]);
		PX_CHECK_MSG(px_v3_dist(px_nurbs_surf_point(s, h.u, h.v), h.point) <=
				     1e-8 * pr->size,
			     "%s: parameters (%.17g, %.17g) give a point %.3g away",
			     px_recog_kind_name(pr->kind), h.u, h.v,
			     px_v3_dist(px_nurbs_surf_point(s, h.u, h.v), h.point));
	}
}

static void test_revolutions(void)
{
	int trial;
	for (trial = 0; trial < 30; trial++) {
		struct tsurf t;
		struct px_recog_shape pr;
		struct frame f = rand_frame();
		double hr[2 * MAXC], beta[MAXC], V[MAXC + 8];
		double R = px_rand_range(0.5, 3), a0 = px_rand_range(-PI, PI), sweep;
		int np, want, kind = trial % 6, tr = (trial / 6) % 2;
		px_vec3 extra[4];
		int n_extra = 0;
		sweep = trial % 3 == 0 ? 2 * PI : px_rand_range(0.3, 2 * PI);
		switch (kind) {
		case 0: /* full sphere or sphere zone */
			np = trial % 2 ? profile_arc(0, 0, R, 0, PI, hr, beta, V)
				       : profile_arc(0, 0, R, px_rand_range(0, 1),
						     px_rand_range(0.5, 2), hr, beta, V);
			want = PX_RECOG_SPHERE;
			break;
		case 1: /* octant */
			np = profile_arc(0, 0, R, 0, PI / 2, hr, beta, V);
			sweep = PI / 2;
			want = PX_RECOG_SPHERE;
			break;
		case 2:
			np = profile_seg(-1, R, px_rand_range(0, 2), R, 1 + trial % 3, hr,
					 beta, V);
			want = PX_RECOG_CYLINDER;
			break;
		case 3:
			np = profile_seg(-1, R, 1.5, trial % 2 ? 0 : 0.3 * R, 1 + trial % 2,
					 hr, beta, V);
			want = PX_RECOG_CONE;
			break;
		case 4: /* torus: full tube or a partial one */
			np = profile_arc(0, R, 0.4 * R, 0,
					 trial % 2 ? 2 * PI : px_rand_range(1, 5), hr, beta,
					 V);
			want = PX_RECOG_TORUS;
			break;
		default:
			np = profile_seg(0.5, 0.2 * R, 0.5, R, 1, hr, beta, V);
			want = PX_RECOG_ANNULUS;
			break;
		}
		PX_CHECK_INT_EQ(make_rev(&t, &f, a0, sweep, hr, beta, np, V,
					 kind == 2 ? 1 + trial % 3
						   : (kind == 3 ? 1 + trial % 2
								: (kind == 5 ? 1 : 2)),
					 tr),
				PX_OK);
		PX_CHECK_INT_EQ(px_recog_surf(&t.s, 0, &pr), 1);
		PX_CHECK_MSG(pr.kind == (enum px_recog_kind)want, "trial %d: got %s want %s",
			     trial, px_recog_kind_name(pr.kind),
			     px_recog_kind_name((enum px_recog_kind)want));
		if (pr.kind != (enum px_recog_kind)want)
			continue;
		PX_CHECK(pr.hausdorff <= 1e-10 * pr.size);
		PX_CHECK(pr.qarc[0].n > 0);
		PX_CHECK(!pr.rev.profile_is_arc || pr.qarc[1].n > 0);
		PX_CHECK_NEAR(fabs(px_v3_dot(pr.rev.axis, f.z)), 1, 1e-12);
		PX_CHECK_NEAR(pr.rev.sweep, sweep, 1e-11);
		if (want == PX_RECOG_SPHERE) {
			PX_CHECK_NEAR(pr.radius, R, 1e-12 * R);
			PX_CHECK_NEAR(px_v3_dist(pr.center, f.o), 0, 1e-12 * R);
		} else if (want == PX_RECOG_CYLINDER) {
			PX_CHECK_NEAR(pr.radius, R, 1e-12 * R);
		} else if (want == PX_RECOG_TORUS) {
			PX_CHECK_NEAR(pr.radius, R, 1e-12 * R);
			PX_CHECK_NEAR(pr.radius2, 0.4 * R, 1e-12 * R);
		} else if (want == PX_RECOG_CONE && trial % 2) {
			PX_CHECK_NEAR(px_v3_dist(pr.center, fr(&f, 0, 0, 1.5)), 0, 1e-11);
		}
		/* On the axis (the evolute of every meridian circle), the
		 * centre, and outside the angular range. */
		extra[n_extra++] = fr(&f, 0, 0, px_rand_range(-2, 2));
		extra[n_extra++] = f.o;
		extra[n_extra++] = fr(&f, 2 * R * cos(a0 - 0.3), 2 * R * sin(a0 - 0.3), 0.2);
		extra[n_extra++] = fr(&f, 0.5 * R * cos(a0 + sweep + 0.4),
				      0.5 * R * sin(a0 + sweep + 0.4), -0.3);
		check_surf_queries(&pr, &t.s, 10, extra, n_extra);
		/* Without the closed-form tables the parameters come from the
		 * bounded monotone inversion: same points. */
		pr.qarc[0].n = pr.qarc[1].n = 0;
		pr.linear = 0;
		check_surf_queries(&pr, &t.s, 4, extra, n_extra);
	}
}

static void test_parallelograms(void)
{
	int trial;
	for (trial = 0; trial < 12; trial++) {
		struct tsurf t;
		struct px_recog_shape pr;
		struct frame f = rand_frame();
		int pu = 1 + trial % 3, pv = 1 + (trial / 3) % 3, nu = pu + 1 + trial % 2,
		    nv = pv + 1, i, j;
		double xs[MAXC], ys[MAXC], al[MAXC], be[MAXC], sk = px_rand_range(-0.5, 0.5);
		int uniform = trial % 4 == 0, trap = trial % 6 == 5;
		for (i = 0; i < nu; i++) {
			xs[i] = uniform ? 2.0 * i / (nu - 1) : (i == 0 ? 0 : xs[i - 1] + px_rand_range(0.1, 1));
			al[i] = uniform ? 1 : px_rand_range(0.3, 3);
		}
		for (j = 0; j < nv; j++) {
			ys[j] = uniform ? 1.5 * j / (nv - 1) : (j == 0 ? 0 : ys[j - 1] + px_rand_range(0.1, 1));
			be[j] = uniform ? 1 : px_rand_range(0.3, 3);
		}
		for (j = 0; j < nv; j++)
			for (i = 0; i < nu; i++) {
				double x = xs[i] + sk * ys[j];
				if (trap) /* trapezoid: not a parallelogram */
					x *= 1 + 0.3 * ys[j];
				set_pw(t.pw + 4 * (j * nu + i), fr(&f, x, ys[j], 0),
				       al[i] * be[j]);
			}
		for (i = 0; i <= pu; i++)
			t.U[i] = 0, t.U[nu + i] = 1;
		for (i = pu + 1; i < nu; i++)
			t.U[i] = 0.5;
		for (j = 0; j <= pv; j++)
			t.V[j] = 0, t.V[nv + j] = 1;
		PX_CHECK_INT_EQ(px_nurbs_surf_view(&t.s, pu, pv, nu, nv, t.U, nu + pu + 1,
						   t.V, nv + pv + 1, t.pw, NULL),
				PX_OK);
		PX_CHECK_INT_EQ(px_recog_surf(&t.s, 0, &pr), 1);
		if (trap) {
			struct px_recog_hit h;
			PX_CHECK_INT_EQ(pr.kind, PX_RECOG_PLANE);
			PX_CHECK_INT_EQ(px_recog_closest(&pr, f.o, 0, &h), PX_E_UNSUPPORTED);
			continue;
		}
		PX_CHECK_INT_EQ(pr.kind, PX_RECOG_PARALLELOGRAM);
		if (pr.kind != PX_RECOG_PARALLELOGRAM)
			continue;
		if (uniform && pu == 1 && pv == 1)
			PX_CHECK_INT_EQ(pr.linear, 3);
		check_surf_queries(&pr, &t.s, 16, NULL, 0);
	}
}

static void test_surface_near_misses(void)
{
	int trial;
	for (trial = 0; trial < 18; trial++) {
		struct tsurf t;
		struct px_recog_shape pr;
		struct frame f = rand_frame();
		double hr[2 * MAXC], beta[MAXC], V[MAXC + 8], R = px_rand_range(0.5, 2);
		int np, k, i;
		switch (trial % 3) {
		case 0:
			np = profile_arc(0, 0, R, 0, PI, hr, beta, V);
			break;
		case 1:
			np = profile_arc(0, R, 0.3 * R, 0, 2 * PI, hr, beta, V);
			break;
		default:
			np = profile_seg(-1, R, 1, 0.5 * R, 2, hr, beta, V);
			break;
		}
		if (trial % 2 == 0) {
			/* Profile slightly off: an ellipsoid / elliptic torus /
			 * a parabolic-profile cone. */
			for (k = 0; k < np; k++)
				hr[2 * k] *= 1 + (trial % 3 == 2 ? 1e-6 * hr[2 * k] : 1e-6);
			if (trial % 3 == 2)
				hr[3] += 1e-6 * R;
		}
		make_rev(&t, &f, 0, px_rand_range(1, 2 * PI), hr, beta, np, V,
			 trial % 3 == 2 ? 2 : 2, trial % 4 == 1);
		if (trial % 2 == 1) { /* one control point moved by 2e-6 size */
			px_vec3 d = px_v3_scale(rand_unit(), 2e-6 * R);
			k = px_rand_int(0, t.s.n_ctrl[0] * t.s.n_ctrl[1] - 1);
			for (i = 0; i < 3; i++)
				t.pw[4 * k + i] += px_v3_comp(d, i) * t.pw[4 * k + 3];
		}
		PX_CHECK_MSG(px_recog_surf(&t.s, 0, &pr) == 0, "trial %d recognised as %s",
			     trial, px_recog_kind_name(pr.kind));
	}
}

/* Non-revolution surfaces whose rows are all exact circles: an oblique
 * circular cylinder (circles slide sideways) and a twisted band (rows
 * turned against each other) must not pass as cylinders. */
static void test_circle_rows_not_revolution(void)
{
	int trial;
	for (trial = 0; trial < 8; trial++) {
		struct tsurf t;
		struct px_recog_shape pr;
		struct frame f = rand_frame();
		double xy[2 * MAXC], al[MAXC], Ua[MAXC], R = px_rand_range(0.5, 2);
		int na = arc2d(0, trial % 2 ? 2 * PI : 2.5, 4, xy, al, Ua), i, j;
		for (j = 0; j < 2; j++)
			for (i = 0; i < na; i++) {
				double h = j ? 1.5 : -0.5, x = R * xy[2 * i],
				       y = R * xy[2 * i + 1], g = trial % 4 < 2 ? 0 : 0.2 * j;
				double xr = x * cos(g) - y * sin(g), yr = x * sin(g) + y * cos(g);
				if (trial % 4 < 2)
					xr += 0.3 * h; /* oblique */
				set_pw(t.pw + 4 * (j * na + i), fr(&f, xr, yr, h), al[i]);
			}
		memcpy(t.U, Ua, (size_t)(na + 3) * sizeof(double));
		t.V[0] = t.V[1] = 0, t.V[2] = t.V[3] = 1;
		PX_CHECK_INT_EQ(px_nurbs_surf_view(&t.s, 2, 1, na, 2, t.U, na + 3, t.V, 4,
						   t.pw, NULL),
				PX_OK);
		PX_CHECK_MSG(px_recog_surf(&t.s, 0, &pr) == 0, "trial %d recognised as %s",
			     trial, px_recog_kind_name(pr.kind));
	}
}

/* The proved bound holds: entities perturbed by 1e-5 of their size are
 * recognised at a loose tolerance, and the closed form is then within
 * hausdorff of the brute-force distance to the perturbed entity. */
static void test_bound_holds_when_loose(void)
{
	int trial, q, rec = 0;
	for (trial = 0; trial < 24; trial++) {
		struct tcurve t;
		struct tsurf ts;
		struct px_recog_shape pr;
		struct frame f = rand_frame();
		double R = px_rand_range(0.5, 3), hr[2 * MAXC], beta[MAXC], V[MAXC + 8];
		int k, i, surf = trial % 2, np;
		double *pw;
		int n;
		if (!surf) {
			if (trial % 4 == 0)
				make_arc(&t, &f, R, px_rand_range(1, 2 * PI), 4, 0);
			else
				make_line(&t, &f, 3, 6, R, 1, 0);
			pw = t.pw, n = t.c.n_ctrl;
		} else {
			np = trial % 4 == 1 ? profile_arc(0, 0, R, 0, PI, hr, beta, V)
					    : profile_arc(0, R, 0.4 * R, 0.5, 4, hr, beta, V);
			make_rev(&ts, &f, 0, px_rand_range(1, 6), hr, beta, np, V, 2, 0);
			pw = ts.pw, n = ts.s.n_ctrl[0] * ts.s.n_ctrl[1];
		}
		for (k = 0; k < 2; k++) {
			int m = px_rand_int(0, n - 1);
			px_vec3 d = px_v3_scale(rand_unit(), 1e-5 * R);
			for (i = 0; i < 3; i++)
				pw[4 * m + i] += px_v3_comp(d, i) * pw[4 * m + 3];
		}
		if ((surf ? px_recog_surf(&ts.s, 1e-2, &pr) : px_recog_curve(&t.c, 1e-2, &pr)) != 1)
			continue;
		rec++;
		PX_CHECK(pr.hausdorff > 0 && pr.hausdorff <= 1e-2 * pr.size);
		for (q = 0; q < 12; q++) {
			struct px_recog_hit h;
			px_aabb b = surf ? px_nurbs_surf_aabb(&ts.s) : px_nurbs_curve_aabb(&t.c);
			px_vec3 p = px_v3_madd(px_v3_scale(px_v3_add(b.min, b.max), 0.5),
					       rand_unit(), pr.size * px_rand_range(0, 1));
			double ref = surf ? surf_brute(&ts.s, p) : curve_brute(&t.c, p, NULL);
			PX_CHECK_INT_EQ(px_recog_closest(&pr, p, 0, &h), PX_OK);
			PX_CHECK_INT_EQ(px_recog_closest(&pr, p, PX_RECOG_WANT_PARAMS, &h), PX_OK);
			PX_CHECK_MSG(fabs(h.dist - ref) <= pr.hausdorff + 1e-9 * pr.size,
				     "%s: |%.17g - %.17g| above bound %.3g (entity at hit "
				     "params %.17g)",
				     px_recog_kind_name(pr.kind), h.dist, ref, pr.hausdorff,
				     surf ? px_v3_dist(p, px_nurbs_surf_point(&ts.s, h.u, h.v))
					  : px_v3_dist(p, px_nurbs_curve_point(&t.c, h.u)));
		}
	}
	PX_CHECK_MSG(rec >= 12, "only %d of 24 perturbed entities recognised", rec);
}

/* The shipped example files: the NURBS circle and the rational sphere
 * are recognised with their documented dimensions, the bicubic patch is
 * not. */
static void test_obj_files(void)
{
	const char *names[3] = {"circle.obj", "sphere.obj", "bicubic.obj"};
	int k;
	for (k = 0; k < 3; k++) {
		char path[512];
		struct px_obj_model *m = NULL;
		struct px_obj_error e;
		struct px_recog_shape pr;
		int rc;
		px_test_data_path(path, sizeof(path), names[k]);
		rc = px_obj_load_file(path, &m, &e);
		PX_CHECK_MSG(rc == PX_OK, "%s: %s", path, e.msg);
		if (rc != PX_OK)
			continue;
		PX_CHECK(m->n_entities >= 1);
		if (k == 0) {
			PX_CHECK_INT_EQ(px_recog_curve(&m->entities[0].curve, 0, &pr), 1);
			PX_CHECK_INT_EQ(pr.kind, PX_RECOG_ARC);
			PX_CHECK_NEAR(pr.radius, 2, 1e-12);
			PX_CHECK_NEAR(px_v3_dist(pr.center, px_v3(1, -1, 0.5)), 0, 1e-12);
			PX_CHECK_NEAR(pr.arc.sweep, 2 * PI, 1e-12);
		} else if (k == 1) {
			PX_CHECK_INT_EQ(px_recog_surf(&m->entities[0].surf, 0, &pr), 1);
			PX_CHECK_INT_EQ(pr.kind, PX_RECOG_SPHERE);
			PX_CHECK_NEAR(pr.radius, 1.5, 1e-12);
			PX_CHECK_NEAR(px_v3_norm(pr.center), 0, 1e-12);
			check_surf_queries(&pr, &m->entities[0].surf, 10, NULL, 0);
		} else {
			PX_CHECK_INT_EQ(px_recog_surf(&m->entities[0].surf, 0, &pr), 0);
			PX_CHECK_INT_EQ(pr.kind, PX_RECOG_NONE);
		}
		px_obj_free(m);
	}
}

/* Extremes: a single-span arc of 179.9 degrees (middle weight ~9e-4),
 * a semicircle in two spans, and a spindle torus (tube radius above the
 * axis distance) whose profile arc ends on the axis. */
static void test_extremes(void)
{
	int trial;
	for (trial = 0; trial < 6; trial++) {
		struct tcurve t;
		struct px_recog_shape pr;
		struct frame f = rand_frame();
		double r = px_rand_range(0.5, 3), sweep = trial % 2 ? PI : PI * 179.9 / 180;
		px_vec3 extra[2];
		PX_CHECK_INT_EQ(make_arc(&t, &f, r, sweep, trial % 2 ? 2 : 1, 0), PX_OK);
		PX_CHECK_INT_EQ(px_recog_curve(&t.c, 0, &pr), 1);
		PX_CHECK_INT_EQ(pr.kind, PX_RECOG_ARC);
		if (pr.kind != PX_RECOG_ARC)
			continue;
		PX_CHECK_NEAR(pr.arc.sweep, sweep, 1e-10);
		extra[0] = f.o;
		extra[1] = fr(&f, 0, -0.5 * r, 0.1); /* in the gap of the arc */
		check_curve_queries(&pr, &t.c, 16, extra, 2);
	}
	for (trial = 0; trial < 4; trial++) {
		struct tsurf t;
		struct px_recog_shape pr;
		struct frame f = rand_frame();
		double hr[2 * MAXC], beta[MAXC], V[MAXC + 8];
		double R = px_rand_range(0.3, 1), rt = R * px_rand_range(1.2, 2);
		double a = asin(R / rt); /* rho = R + rt sin(psi) >= 0 */
		int np = profile_arc(0, R, rt, -a, PI + 2 * a, hr, beta, V);
		px_vec3 extra[2];
		int k;
		for (k = 0; k < np; k++) /* end points exactly on the axis */
			if (fabs(hr[2 * k + 1]) < 1e-12)
				hr[2 * k + 1] = 0;
		PX_CHECK_INT_EQ(make_rev(&t, &f, 0, trial < 2 ? 2 * PI : 4, hr, beta, np,
					 V, 2, trial % 2),
				PX_OK);
		PX_CHECK_INT_EQ(px_recog_surf(&t.s, 0, &pr), 1);
		PX_CHECK_INT_EQ(pr.kind, PX_RECOG_TORUS);
		if (pr.kind != PX_RECOG_TORUS)
			continue;
		PX_CHECK_NEAR(pr.radius, R, 1e-12);
		PX_CHECK_NEAR(pr.radius2, rt, 1e-12);
		extra[0] = f.o;
		extra[1] = fr(&f, 0, 0, 0.5 * rt);
		check_surf_queries(&pr, &t.s, 10, extra, 2);
	}
}

static void test_no_alloc_and_errors(void)
{
	struct tcurve t;
	struct tsurf ts;
	struct px_recog_shape pc, ps;
	struct px_recog_hit h;
	struct frame f = rand_frame();
	double hr[2 * MAXC], beta[MAXC], V[MAXC + 8];
	uint64_t reg;
	int i, np;

	make_arc(&t, &f, 2, 3, 2, 1);
	PX_CHECK_INT_EQ(px_recog_curve(&t.c, 0, &pc), 1);
	np = profile_arc(0, 1.5, 0.5, 0, 2 * PI, hr, beta, V);
	make_rev(&ts, &f, 0, 4, hr, beta, np, V, 2, 0);
	PX_CHECK_INT_EQ(px_recog_surf(&ts.s, 0, &ps), 1);
	reg = px_alloc_region_begin();
	for (i = 0; i < 200; i++) {
		px_vec3 p = px_v3(px_rand_range(-5, 5), px_rand_range(-5, 5),
				  px_rand_range(-5, 5));
		px_recog_closest(&pc, p, PX_RECOG_WANT_PARAMS, &h);
		px_recog_closest(&ps, p, PX_RECOG_WANT_PARAMS, &h);
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(reg), 0);
	PX_CHECK_INT_EQ(px_recog_closest(NULL, f.o, 0, &h), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_recog_closest(&pc, px_v3(NAN, 0, 0), 0, &h), PX_E_NAN);
	PX_CHECK_INT_EQ(px_recog_curve(NULL, 0, &pc), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_recog_surf(&ts.s, 0, NULL), PX_E_INVAL);
	memset(&pc, 0, sizeof(pc));
	PX_CHECK_INT_EQ(px_recog_closest(&pc, f.o, 0, &h), PX_E_UNSUPPORTED);
}

static const struct px_test tests[] = {
	PX_T(test_circle_full_and_arcs), PX_T(test_lines), PX_T(test_curve_near_misses),
	PX_T(test_revolutions), PX_T(test_parallelograms),
	PX_T(test_surface_near_misses), PX_T(test_circle_rows_not_revolution),
	PX_T(test_bound_holds_when_loose), PX_T(test_obj_files), PX_T(test_extremes),
	PX_T(test_no_alloc_and_errors),
};
PX_TEST_MAIN(tests)
