/*
 * Composed edges (brep_compose.c): the image S(c(t)) of a (u, v) curve
 * on a NURBS surface as one rational B-spline, checked against direct
 * evaluation at many parameters (1e-12 of the surface's size) for
 * polynomial and rational curves and surfaces, curves crossing many knot
 * lines, iso-curves (the lower degree), curves along knot lines and
 * tangent to them; the degree cap; a B-rep whose loops have no edges
 * built with compose_edges and refused without it.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "brep_internal.h"
#include "px_alloc_count.h"
#include "px_brep.h"
#include "px_test.h"

struct surf_buf {
	double ku[32], kv[32], pw[4 * 256];
	struct px_nurbs_surf s;
};

struct curve_buf {
	double k[64], pw[4 * 48];
	struct px_nurbs_curve c;
};

/* Uniform clamped knots on [a, b] for n control points of degree p,
 * with interior knot i of multiplicity mult[i] when given. */
static int clamped(double *k, int p, int n, double a, double b)
{
	int i, m = n - p;
	for (i = 0; i <= p; i++) {
		k[i] = a;
		k[n + i] = b;
	}
	for (i = 1; i < m; i++)
		k[p + i] = a + (b - a) * i / m;
	return n + p + 1;
}

/* A wavy (rational when rat) surface of degree (p, q), n_u x n_v points
 * over [0, 2] x [-1, 1]. */
static void make_surf(struct surf_buf *b, int p, int q, int nu, int nv, int rat)
{
	struct px_nurbs_error e;
	int i, j, nku = clamped(b->ku, p, nu, 0.0, 2.0), nkv = clamped(b->kv, q, nv, -1.0, 1.0);
	for (j = 0; j < nv; j++)
		for (i = 0; i < nu; i++) {
			double *P = b->pw + 4 * (j * nu + i);
			double w = rat ? 0.6 + 0.8 * px_rand_unit() : 1.0;
			P[0] = w * (3.0 * i / (nu - 1) + 0.2 * px_rand_range(-1, 1));
			P[1] = w * (2.0 * j / (nv - 1) + 0.2 * px_rand_range(-1, 1));
			P[2] = w * px_rand_range(-0.7, 0.7);
			P[3] = w;
		}
	PX_CHECK_INT_EQ(px_nurbs_surf_view(&b->s, p, q, nu, nv, b->ku, nku, b->kv,
					   nkv, b->pw, &e),
			PX_OK);
}

/* A curve of degree p through the given (u, v, w) control points. */
static void make_curve(struct curve_buf *b, int p, int n, const double *uvw)
{
	struct px_nurbs_error e;
	int i, nk = clamped(b->k, p, n, 0.0, 1.0 + n);
	for (i = 0; i < n; i++) {
		b->pw[4 * i] = uvw[3 * i] * uvw[3 * i + 2];
		b->pw[4 * i + 1] = uvw[3 * i + 1] * uvw[3 * i + 2];
		b->pw[4 * i + 2] = 0.0;
		b->pw[4 * i + 3] = uvw[3 * i + 2];
	}
	PX_CHECK_INT_EQ(px_nurbs_curve_view(&b->c, p, n, b->k, nk, b->pw, &e), PX_OK);
}

/* Compose and compare at 4001 parameters; returns the degree. */
static int check_compose(const struct px_nurbs_surf *s, const struct px_nurbs_curve *c)
{
	struct px_nurbs_curve out;
	px_aabb hb = px_nurbs_surf_aabb(s);
	double *mem = NULL, t0, t1, e0, e1, worst = 0.0, size = px_aabb_diagonal(&hb);
	char why[200];
	int rc, i, deg;

	rc = px__brep_compose_curve(s, c, &mem, &out, why, sizeof(why));
	PX_CHECK_MSG(rc == PX_OK, "compose: %d %s", rc, why);
	if (rc)
		return -1;
	px_nurbs_curve_domain(c, &t0, &t1);
	px_nurbs_curve_domain(&out, &e0, &e1);
	PX_CHECK(e0 == t0 && e1 == t1);
	for (i = 0; i <= 4000; i++) {
		double t = t0 + (t1 - t0) * i / 4000.0;
		px_vec3 q = px_nurbs_curve_point(c, t);
		px_vec3 a = px_nurbs_surf_point(s, q.x, q.y);
		px_vec3 b = px_nurbs_curve_point(&out, t);
		worst = fmax(worst, px_v3_dist(a, b));
	}
	PX_CHECK_MSG(worst <= 1e-12 * size, "composed curve off by %g (size %g)",
		     worst, size);
	deg = out.degree;
	free(mem);
	return deg;
}

/* Polylines across many knot lines, on polynomial and rational
 * surfaces of several degrees. */
static void test_lines(void)
{
	int it;
	for (it = 0; it < 40; it++) {
		struct surf_buf sb;
		struct curve_buf cb;
		double uvw[3 * 8];
		int p = 1 + it % 3, q = 1 + (it / 3) % 3, n = 3 + it % 6, i;
		make_surf(&sb, p, q, p + 2 + it % 5, q + 2 + it % 4, it & 1);
		for (i = 0; i < n; i++) {
			uvw[3 * i] = px_rand_range(0.0, 2.0);
			uvw[3 * i + 1] = px_rand_range(-1.0, 1.0);
			uvw[3 * i + 2] = 1.0;
		}
		PX_CHECK_INT_EQ(check_compose(&sb.s, (make_curve(&cb, 1, n, uvw), &cb.c)),
				p + q);
	}
}

/* Rational and polynomial curves of degree 2 and 3 on low-degree
 * surfaces; degree d (p + q). */
static void test_curves(void)
{
	int it;
	for (it = 0; it < 40; it++) {
		struct surf_buf sb;
		struct curve_buf cb;
		double uvw[3 * 12];
		int d = 2 + it % 2, p = 1 + (it / 2) % 2, q = 1 + (it / 4) % 2;
		int n = d + 1 + it % 5, i, rat = (it / 8) & 1;
		if (d * (p + q) > PX_NURBS_MAX_DEGREE)
			q = 1;
		make_surf(&sb, p, q, p + 3, q + 4, (it / 16) & 1);
		for (i = 0; i < n; i++) {
			uvw[3 * i] = px_rand_range(0.05, 1.95);
			uvw[3 * i + 1] = px_rand_range(-0.95, 0.95);
			uvw[3 * i + 2] = rat ? px_rand_range(0.5, 2.0) : 1.0;
		}
		make_curve(&cb, d, n, uvw);
		PX_CHECK_INT_EQ(check_compose(&sb.s, &cb.c), d * (p + q));
	}
}

/* A rational circle (9 points, degree 2) on a biquadratic rational
 * surface: degree 8. */
static void test_circle(void)
{
	static const double cx[9] = {1, 1, 0, -1, -1, -1, 0, 1, 1};
	static const double cy[9] = {0, 1, 1, 1, 0, -1, -1, -1, 0};
	struct surf_buf sb;
	struct curve_buf cb;
	struct px_nurbs_error e;
	double r = 0.4;
	int i;
	static const double K[12] = {0, 0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 4};
	make_surf(&sb, 2, 2, 6, 5, 1);
	for (i = 0; i < 9; i++) {
		double w = (i & 1) ? sqrt(0.5) : 1.0;
		cb.pw[4 * i] = w * (1.0 + r * cx[i]);
		cb.pw[4 * i + 1] = w * (0.1 + r * cy[i]);
		cb.pw[4 * i + 2] = 0.0;
		cb.pw[4 * i + 3] = w;
	}
	memcpy(cb.k, K, sizeof(K));
	PX_CHECK_INT_EQ(px_nurbs_curve_view(&cb.c, 2, 9, cb.k, 12, cb.pw, &e), PX_OK);
	PX_CHECK_INT_EQ(check_compose(&sb.s, &cb.c), 8);
}

/* Iso-curves keep the lower degree; curves along a knot line and
 * tangent to one. */
static void test_iso_and_tangent(void)
{
	struct surf_buf sb;
	struct curve_buf cb;
	double uvw[3 * 4];
	int i;

	make_surf(&sb, 3, 3, 7, 6, 1);
	/* u = 1 (a knot of the u direction? knots at 0.5 steps: yes) along v */
	for (i = 0; i < 4; i++) {
		uvw[3 * i] = 1.0;
		uvw[3 * i + 1] = -1.0 + 2.0 * i / 3.0;
		uvw[3 * i + 2] = 1.0;
	}
	make_curve(&cb, 3, 4, uvw);
	PX_CHECK_INT_EQ(check_compose(&sb.s, &cb.c), 9);
	/* v constant, u linear: degree 3 */
	uvw[0] = 0.0, uvw[1] = 0.3, uvw[3] = 2.0, uvw[4] = 0.3;
	uvw[2] = uvw[5] = 1.0;
	make_curve(&cb, 1, 2, uvw);
	PX_CHECK_INT_EQ(check_compose(&sb.s, &cb.c), 3);
	/* a parabola crossing the knot line u = 0.5 twice */
	make_surf(&sb, 2, 1, 6, 3, 0);
	uvw[0] = 0.2, uvw[1] = -0.9, uvw[2] = 1.0;
	uvw[3] = 1.7, uvw[4] = 0.0, uvw[5] = 1.0;
	uvw[6] = 0.2, uvw[7] = 0.9, uvw[8] = 1.0;
	make_curve(&cb, 2, 3, uvw);
	PX_CHECK_INT_EQ(check_compose(&sb.s, &cb.c), 6);
	/* the apex exactly on the line u = 1 (2/3 of the knot vector's span) */
	uvw[3] = 1.8; /* u(1/2) = (0.2 + 2 * 1.8 + 0.2) / 4 = 1 */
	make_curve(&cb, 2, 3, uvw);
	PX_CHECK_INT_EQ(check_compose(&sb.s, &cb.c), 6);
	/* a point of the plane: nothing made */
	for (i = 0; i < 4; i++) {
		uvw[3 * i] = 0.7;
		uvw[3 * i + 1] = 0.2;
		uvw[3 * i + 2] = 1.0;
	}
	make_curve(&cb, 3, 4, uvw);
	{
		struct px_nurbs_curve out;
		double *mem = NULL;
		char why[200];
		PX_CHECK_INT_EQ(px__brep_compose_curve(&sb.s, &cb.c, &mem, &out, why,
						       sizeof(why)),
				1);
		PX_CHECK(mem == NULL);
	}
}

/* A cubic trim on a bicubic surface would need degree 18. */
static void test_degree_cap(void)
{
	struct surf_buf sb;
	struct curve_buf cb;
	struct px_nurbs_curve out;
	double uvw[3 * 4] = {0.1, -0.5, 1, 0.7, 0.6, 1, 1.3, -0.4, 1, 1.9, 0.5, 1};
	double *mem = NULL;
	char why[200];
	make_surf(&sb, 3, 3, 5, 5, 0);
	make_curve(&cb, 3, 4, uvw);
	PX_CHECK_INT_EQ(px__brep_compose_curve(&sb.s, &cb.c, &mem, &out, why,
					       sizeof(why)),
			PX_E_NOSPC);
	PX_CHECK_MSG(strstr(why, "degree 18") != NULL, "%s", why);
	PX_CHECK(mem == NULL);
}

/* A bicubic sheet with a square outer loop and an inner polygon, no
 * edges: refused by default, built with compose_edges, with one edge
 * per loop curve; a cubic hole is refused with the face and curve. */
static void test_brep(void)
{
	static const double sq[5][2] = {{0.1, -0.9}, {1.9, -0.9}, {1.9, 0.9}, {0.1, 0.9}, {0.1, -0.9}};
	static const double tri[4][2] = {{0.6, -0.3}, {1.2, 0.4}, {1.4, -0.4}, {0.6, -0.3}};
	struct surf_buf sb;
	struct curve_buf outer[4], hole[3];
	struct px_nurbs_curve oc[4], hc[3];
	struct px_trim_loop loops[2];
	struct px_brep_face_desc face;
	struct px_brep_desc d;
	struct px_brep_opts o;
	struct px_brep_error err;
	struct px_brep_info info;
	struct px_brep *b = NULL;
	int i;

	make_surf(&sb, 3, 3, 6, 6, 1);
	for (i = 0; i < 4; i++) {
		double uvw[6] = {sq[i][0], sq[i][1], 1, sq[i + 1][0], sq[i + 1][1], 1};
		make_curve(&outer[i], 1, 2, uvw);
		oc[i] = outer[i].c;
	}
	for (i = 0; i < 3; i++) {
		double uvw[6] = {tri[i][0], tri[i][1], 1, tri[i + 1][0], tri[i + 1][1], 1};
		make_curve(&hole[i], 1, 2, uvw);
		hc[i] = hole[i].c;
	}
	loops[0].curves = oc;
	loops[0].n_curves = 4;
	loops[0].reversed = NULL;
	loops[1].curves = hc;
	loops[1].n_curves = 3;
	loops[1].reversed = NULL;
	memset(&face, 0, sizeof(face));
	face.surf = sb.s;
	face.loops = loops;
	face.n_loops = 2;
	face.id = 7;
	memset(&d, 0, sizeof(d));
	d.faces = &face;
	d.n_faces = 1;
	d.scale = 1.0;
	PX_CHECK_INT_EQ(px_brep_create(&d, NULL, &err, &b), PX_E_INVAL);
	PX_CHECK(strstr(err.msg, "has no 3D edge") != NULL);
	px_brep_opts_default(&o);
	PX_CHECK_INT_EQ(o.compose_edges, 0);
	o.compose_edges = 1;
	PX_CHECK_MSG(px_brep_create(&d, &o, &err, &b) == PX_OK, "%s", err.msg);
	PX_CHECK_INT_EQ(px_brep_get_info(b, &info), PX_OK);
	PX_CHECK_INT_EQ(info.n_edges, 7);
	PX_CHECK_INT_EQ(info.n_faces, 1);
	PX_CHECK_INT_EQ(info.closed, 0);
	px_brep_free(b);
	/* a cubic hole curve on the bicubic sheet: its image has degree
	 * 18, above the kernel's, so it is a curve-on-surface edge */
	{
		double uvw[12] = {0.6, -0.3, 1, 1.0, 0.5, 1, 1.4, -0.5, 1, 0.6, -0.3, 1};
		make_curve(&hole[0], 3, 4, uvw);
		hc[0] = hole[0].c;
		loops[1].n_curves = 1;
		PX_CHECK_MSG(px_brep_create(&d, &o, &err, &b) == PX_OK, "%s", err.msg);
		PX_CHECK_INT_EQ(px_brep_get_info(b, &info), PX_OK);
		PX_CHECK_INT_EQ(info.n_edges, 5);
		PX_CHECK(strstr(info.why, "curve-on-surface") != NULL);
		px_brep_free(b);
		b = NULL;
	}
	/* a quintic one: degree 30, above the curve-on-surface edges' 24 */
	{
		double uvw[18] = {0.6, -0.3, 1, 0.8, 0.4, 1, 1.0, 0.5, 1,
				  1.2, 0.1, 1, 1.4, -0.5, 1, 0.6, -0.3, 1};
		make_curve(&hole[0], 5, 6, uvw);
		hc[0] = hole[0].c;
		PX_CHECK_INT_EQ(px_brep_create(&d, &o, &err, &b), PX_E_NOSPC);
		PX_CHECK_MSG(strstr(err.msg, "face 0 (id 7): loop 1 curve 0") != NULL &&
				     strstr(err.msg, "degree 30") != NULL,
			     "%s", err.msg);
		PX_CHECK(b == NULL);
	}
}


/* Cubic curves on bicubic surfaces (polynomial and rational): the
 * degree-18 Bezier pieces of px__brep_compose_bezier() reproduce
 * S(c(t)) to 1e-12 of the size, and the curve-on-surface solver
 * (brep_cos.c) finds the distance to them as dense sampling of S(c(t))
 * polished by golden-section steps does, certified and without heap
 * calls. */
static void test_cos_solver(void)
{
	int it, worst_q = 0;
	double worst = 0.0;
	for (it = 0; it < 8; it++) {
		struct surf_buf sb;
		struct curve_buf cb;
		struct brep_cos_set set;
		double uvw[3 * 6], *pw = NULL, *brk = NULL, t0, t1, size, ew = 0.0;
		char why[200];
		int deg, n_pc, i, k, q;
		px_aabb hb;
		make_surf(&sb, 3, 3, 5 + it % 3, 4 + it % 2, it & 1);
		for (i = 0; i < 6; i++) {
			uvw[3 * i] = px_rand_range(0.05, 1.95);
			uvw[3 * i + 1] = px_rand_range(-0.95, 0.95);
			uvw[3 * i + 2] = it & 2 ? px_rand_range(0.7, 1.4) : 1.0;
		}
		make_curve(&cb, 3, 6, uvw);
		hb = px_nurbs_surf_aabb(&sb.s);
		size = px_aabb_diagonal(&hb);
		PX_CHECK_INT_EQ(px__brep_compose_bezier(&sb.s, &cb.c, &deg, &n_pc, &pw, &brk,
							why, sizeof(why)),
				PX_OK);
		PX_CHECK_INT_EQ(deg, 18);
		if (!pw)
			continue;
		memset(&set, 0, sizeof(set));
		PX_CHECK_INT_EQ(px__brep_cos_add(&set, 0, 0, deg, n_pc, pw, brk, 1.0), PX_OK);
		/* the pieces against the surface at the curve */
		for (k = 0; k < n_pc; k++)
			for (i = 0; i <= 50; i++) {
				double s = i / 50.0, t = brk[k] + (brk[k + 1] - brk[k]) * s;
				px_vec3 c = px_nurbs_curve_point(&cb.c, t), a;
				struct px_dist_result d;
				memset(&d, 0, sizeof(d));
				a = px_nurbs_surf_point(&sb.s, c.x, c.y);
				/* the piece's own point at s (de Casteljau) */
				{
					double h[19][4];
					int r, j, c4;
					for (j = 0; j <= deg; j++)
						for (c4 = 0; c4 < 4; c4++)
							h[j][c4] = pw[4 * (k * deg + j) + c4];
					for (r = 1; r <= deg; r++)
						for (j = 0; j <= deg - r; j++)
							for (c4 = 0; c4 < 4; c4++)
								h[j][c4] = (1 - s) * h[j][c4] +
									   s * h[j + 1][c4];
					ew = fmax(ew, px_v3_dist(a, px_v3(h[0][0] / h[0][3],
									h[0][1] / h[0][3],
									h[0][2] / h[0][3])));
				}
				/* and the solver's answer at a query on it */
				d.dist = INFINITY;
				d.certified = 1;
				px__brep_cos_closest(&set, a, &d, NULL);
				ew = fmax(ew, d.dist);
			}
		PX_CHECK_MSG(ew <= 1e-12 * size, "pieces off the surface by %g", ew);
		px_nurbs_curve_domain(&cb.c, &t0, &t1);
		for (q = 0; q < 300; q++) {
			px_vec3 p = px_v3(px_rand_range(-1.0, 4.0), px_rand_range(-2.0, 3.0),
					  px_rand_range(-1.5, 1.5));
			struct px_dist_result d;
			double ref = INFINITY, step = (t1 - t0) / 3000.0, lo, hi, ds[3001];
			uint64_t a0;
			if (q % 2) {
				/* near the curve */
				px_vec3 c = px_nurbs_curve_point(&cb.c, px_rand_range(t0, t1));
				p = px_v3_add(px_nurbs_surf_point(&sb.s, c.x, c.y),
					      px_v3(px_rand_range(-1e-3, 1e-3),
						    px_rand_range(-1e-3, 1e-3),
						    px_rand_range(-1e-3, 1e-3)));
			}
			/* every local minimum of the samples, golden-section
			 * polished between its neighbours */
			for (i = 0; i <= 3000; i++) {
				px_vec3 c = px_nurbs_curve_point(&cb.c, t0 + step * i);
				ds[i] = px_v3_dist(px_nurbs_surf_point(&sb.s, c.x, c.y), p);
				ref = fmin(ref, ds[i]);
			}
			for (k = 0; k <= 3000; k++) {
				if ((k > 0 && ds[k - 1] < ds[k]) || (k < 3000 && ds[k + 1] < ds[k]))
					continue;
				lo = fmax(t0, t0 + step * (k - 1));
				hi = fmin(t1, t0 + step * (k + 1));
				for (i = 0; i < 100; i++) {
					double m1 = lo + 0.381966 * (hi - lo), m2 = hi - 0.381966 * (hi - lo);
					px_vec3 c1 = px_nurbs_curve_point(&cb.c, m1);
					px_vec3 c2 = px_nurbs_curve_point(&cb.c, m2);
					double d1 = px_v3_dist(px_nurbs_surf_point(&sb.s, c1.x, c1.y), p);
					double d2 = px_v3_dist(px_nurbs_surf_point(&sb.s, c2.x, c2.y), p);
					ref = fmin(ref, fmin(d1, d2));
					if (d1 < d2)
						hi = m2;
					else
						lo = m1;
				}
			}
			memset(&d, 0, sizeof(d));
			d.dist = INFINITY;
			d.certified = 1;
			a0 = px_alloc_region_begin();
			PX_CHECK_INT_EQ(px__brep_cos_closest(&set, p, &d, NULL), 1);
			PX_CHECK_INT_EQ((int)px_alloc_region_end(a0), 0);
			PX_CHECK(d.certified);
			if (fabs(d.dist - ref) > worst) {
				worst = fabs(d.dist - ref);
				worst_q = q;
			}
			{
				px_vec3 c = px_nurbs_curve_point(&cb.c, d.u);
				px_vec3 sp = px_nurbs_surf_point(&sb.s, c.x, c.y);
				PX_CHECK_MSG(fabs(d.dist - ref) <= 1e-9 * size,
					     "case %d query %d: %.17g, reference %.17g; at u %.17g "
					     "the curve is %g from the answer, %.17g from p",
					     it, q, d.dist, ref, d.u, px_v3_dist(sp, d.point),
					     px_v3_dist(sp, p));
			}
		}
		free(pw);
		free(brk);
		free(set.cos);
		free(set.pc);
		free(set.coef);
	}
	(void)worst_q;
}

static const struct px_test tests[] = {
	PX_T(test_lines), PX_T(test_curves), PX_T(test_circle),
	PX_T(test_iso_and_tangent), PX_T(test_degree_cap), PX_T(test_brep),
	PX_T(test_cos_solver)};
PX_TEST_MAIN(tests)
