/*
 * Trimmed OBJ files (curv2, trim, hole, scrv, sp) read as B-rep models
 * (px_brep_obj.h), written here: a plane sheet with a rational circular
 * hole and a multi-face file against exact answers; a free-form sheet
 * trimmed by a spline loop and a polygon hole against a reference of
 * dense samples of the surface inside its trimmed domain and of the
 * composed edges, polished; zero wrong answers. Malformed files are
 * refused with their line and what is wrong; px_model_load() reads a
 * trimmed .obj as a B-rep and leaves untrimmed ones to the mesh loader.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "brep_internal.h"
#include "px_alloc_count.h"
#include "px_brep_obj.h"
#include "px_features.h"
#include "px_load.h"
#include "px_model.h"
#include "px_obj.h"
#include "px_test.h"
#include "px_trim.h"

/* A 2 x 2 plane z = z0 over [0, 1]^2 (u, v scaled by 2) and, when
 * hole, a rational circle of radius 0.25 around (0.5, 0.5) as its hole
 * (the outer loop: the domain). */
static int plane_text(char *buf, size_t cap, double z0, int hole, int first_v,
		      int first_vp, int first_c2)
{
	static const double cx[9] = {1, 1, 0, -1, -1, -1, 0, 1, 1};
	static const double cy[9] = {0, 1, 1, 1, 0, -1, -1, -1, 0};
	int n = 0, i;
	n += snprintf(buf + n, cap - (size_t)n,
		      "v 0 0 %g\nv 2 0 %g\nv 0 2 %g\nv 2 2 %g\n", z0, z0, z0, z0);
	if (hole) {
		for (i = 0; i < 9; i++)
			n += snprintf(buf + n, cap - (size_t)n, "vp %.17g %.17g %.17g\n",
				      0.5 + 0.25 * cx[i], 0.5 + 0.25 * cy[i],
				      (i & 1) ? sqrt(0.5) : 1.0);
		n += snprintf(buf + n, cap - (size_t)n,
			      "cstype rat bspline\ndeg 2\ncurv2");
		for (i = 0; i < 9; i++)
			n += snprintf(buf + n, cap - (size_t)n, " %d", first_vp + i);
		n += snprintf(buf + n, cap - (size_t)n,
			      "\nparm u 0 0 0 1 1 2 2 3 3 4 4 4\nend\n");
	}
	n += snprintf(buf + n, cap - (size_t)n,
		      "cstype bspline\ndeg 1 1\nsurf 0 1 0 1 %d %d %d %d\n"
		      "parm u 0 0 1 1\nparm v 0 0 1 1\n",
		      first_v, first_v + 1, first_v + 2, first_v + 3);
	if (hole)
		n += snprintf(buf + n, cap - (size_t)n, "hole 0 4 %d\n", first_c2);
	n += snprintf(buf + n, cap - (size_t)n, "end\n");
	return n;
}

/* Exact distance to the square [0, 2]^2 at z0 without the disc of
 * radius 0.5 around (1, 1) (hole) . */
static double plane_exact(px_vec3 p, double z0, int hole)
{
	double x = fmin(fmax(p.x, 0.0), 2.0), y = fmin(fmax(p.y, 0.0), 2.0);
	double dx = x - 1.0, dy = y - 1.0, r = sqrt(dx * dx + dy * dy);
	if (hole && r < 0.5) {
		if (r == 0.0) {
			dx = 1.0;
			dy = 0.0;
			r = 1.0;
		}
		x = 1.0 + 0.5 * dx / r;
		y = 1.0 + 0.5 * dy / r;
	}
	return px_v3_dist(p, px_v3(x, y, z0));
}

static struct px_model *load_text(const char *text, struct px_obj_error *e, int *rc)
{
	struct px_obj_model *m = NULL;
	struct px_brep *b = NULL;
	struct px_model *md = NULL;
	memset(e, 0, sizeof(*e));
	*rc = px_obj_load_mem("t.obj", text, strlen(text), &m, e);
	if (!*rc)
		*rc = px_brep_from_obj(m, 1.0, &b, e);
	px_obj_free(m);
	if (!*rc)
		*rc = px_model_from_brep(b, &md);
	return md;
}

static px_vec3 rand_point(double lo, double hi, double zlo, double zhi)
{
	return px_v3(px_rand_range(lo, hi), px_rand_range(lo, hi),
		     px_rand_range(zlo, zhi));
}

/* The sheet with the circular hole, and a file with it and a second
 * (untrimmed) plane above: every answer exact to 1e-9 of the size. */
static void test_plane_hole(void)
{
	static char text[8192];
	struct px_obj_error e;
	struct px_brep_info info;
	struct px_model *m;
	int rc, i, n, wrong = 0;

	plane_text(text, sizeof(text), 0.0, 1, 1, 1, 1);
	m = load_text(text, &e, &rc);
	PX_CHECK_MSG(rc == PX_OK, "%d:%d %s", e.line, e.column, e.msg);
	if (!m)
		return;
	PX_CHECK_INT_EQ(px_model_kind(m), PX_MODEL_BREP);
	px_brep_get_info(px_model_brep(m), &info);
	PX_CHECK_INT_EQ(info.n_faces, 1);
	PX_CHECK_INT_EQ(info.n_edges, 5); /* 4 domain sides + the circle */
	PX_CHECK_INT_EQ(info.closed, 0);
	for (i = 0; i < 3000; i++) {
		struct px_model_result r;
		/* near the hole's rim half the time */
		px_vec3 p = i & 1 ? rand_point(-0.5, 2.5, -1.0, 1.0)
				  : px_v3(1.0 + px_rand_range(-0.7, 0.7),
					  1.0 + px_rand_range(-0.7, 0.7),
					  px_rand_range(-0.05, 0.05));
		double want = plane_exact(p, 0.0, 1);
		PX_CHECK_INT_EQ(px_model_query(m, p, &r), 1);
		if (!(fabs(r.distance - want) <= 1e-9 * 2.83) ||
		    !(fabs(px_v3_dist(p, r.point) - r.distance) <= 1e-9)) {
			if (wrong++ < 5)
				PX_CHECK_MSG(0, "(%g, %g, %g): %.15g, exact %.15g", p.x,
					     p.y, p.z, r.distance, want);
		}
	}
	PX_CHECK_INT_EQ(wrong, 0);
	px_model_free(m);

	/* two faces: the holed sheet and a whole plane 0.3 above it */
	n = plane_text(text, sizeof(text), 0.0, 1, 1, 1, 1);
	plane_text(text + n, sizeof(text) - (size_t)n, 0.3, 0, 5, 10, 0);
	m = load_text(text, &e, &rc);
	PX_CHECK_MSG(rc == PX_OK, "%d:%d %s", e.line, e.column, e.msg);
	if (!m)
		return;
	px_brep_get_info(px_model_brep(m), &info);
	PX_CHECK_INT_EQ(info.n_faces, 2);
	PX_CHECK_INT_EQ(info.n_trimmed, 1);
	for (i = 0; i < 2000; i++) {
		struct px_model_result r;
		px_vec3 p = rand_point(-0.5, 2.5, -0.6, 0.9);
		double want = fmin(plane_exact(p, 0.0, 1), plane_exact(p, 0.3, 0));
		PX_CHECK_INT_EQ(px_model_query(m, p, &r), 1);
		if (!(fabs(r.distance - want) <= 1e-9 * 2.83) && wrong++ < 5)
			PX_CHECK_MSG(0, "two faces (%g, %g, %g): %.15g, exact %.15g",
				     p.x, p.y, p.z, r.distance, want);
	}
	PX_CHECK_INT_EQ(wrong, 0);
	px_model_free(m);
}

/* ---- the free-form sheet ---------------------------------------------------- */

#define FF_NU 6
#define FF_NV 5

/* A wavy biquadratic sheet over [0, 1]^2, trimmed by a closed
 * quadratic B-spline (8 points, the last equal to the first) and a
 * triangular hole of three degree-1 curv2 curves (the third reversed). */
static void freeform_text(char *buf, size_t cap, double *ctrl)
{
	static const double lp[8][2] = {{0.1, 0.1}, {0.5, 0.02}, {0.92, 0.1},
					{0.97, 0.55}, {0.85, 0.95}, {0.4, 0.9},
					{0.05, 0.6}, {0.1, 0.1}};
	static const double tri[3][2] = {{0.35, 0.35}, {0.65, 0.4}, {0.5, 0.65}};
	int n = 0, i, j;
	for (j = 0; j < FF_NV; j++)
		for (i = 0; i < FF_NU; i++) {
			double *P = ctrl + 3 * (j * FF_NU + i);
			P[0] = 3.0 * i / (FF_NU - 1);
			P[1] = 2.5 * j / (FF_NV - 1);
			P[2] = 0.4 * sin(1.7 * i + 0.3) * cos(1.3 * j);
			n += snprintf(buf + n, cap - (size_t)n, "v %.17g %.17g %.17g\n",
				      P[0], P[1], P[2]);
		}
	for (i = 0; i < 8; i++)
		n += snprintf(buf + n, cap - (size_t)n, "vp %g %g\n", lp[i][0], lp[i][1]);
	for (i = 0; i < 3; i++)
		n += snprintf(buf + n, cap - (size_t)n, "vp %g %g\n", tri[i][0], tri[i][1]);
	n += snprintf(buf + n, cap - (size_t)n,
		      "cstype bspline\ndeg 2\n"
		      "curv2 1 2 3 4 5 6 7 8\nparm u 0 0 0 1 2 3 4 5 6 6 6\nend\n"
		      "deg 1\n"
		      "curv2 9 10\nparm u 0 0 1 1\nend\n"
		      "curv2 10 11\nparm u 0 0 1 1\nend\n"
		      "curv2 9 11\nparm u 0 0 1 1\nend\n"
		      "deg 2 2\nsurf 0 1 0 1");
	for (i = 1; i <= FF_NU * FF_NV; i++)
		n += snprintf(buf + n, cap - (size_t)n, " %d", i);
	snprintf(buf + n, cap - (size_t)n,
		 "\nparm u 0 0 0 0.25 0.5 0.75 1 1 1\nparm v 0 0 0 0.3 0.6 1 1 1\n"
		 "trim 0 6 1\nhole 0 1 2 0 1 3 1 0 4\nsp 9\nscrv 0 1 2\nend\n");
}

/* Reference: samples of the surface inside the domain and of the loop
 * images, the best of each polished by projected Newton steps. */
struct ffref {
	const struct px_nurbs_surf *s;
	const struct px_trim *t[8]; /* the face regions */
	int nt;
	const struct px_nurbs_curve *c[8];
	int nc;
	double *su, *sv;
	px_vec3 *sp;
	int ns;
};

/* (u, v) in one of the regions (on its boundary counts). */
static int ff_in(const struct ffref *f, double u, double v, int strict)
{
	int k;
	for (k = 0; k < f->nt; k++) {
		int w = px_trim_contains(f->t[k], u, v, NULL);
		if (w == PX_TRIM_INSIDE || (!strict && w != PX_TRIM_OUTSIDE))
			return 1;
	}
	return 0;
}

static double ff_polish_surf(const struct ffref *f, px_vec3 p, double u, double v)
{
	double best = px_v3_dist(px_nurbs_surf_point(f->s, u, v), p);
	int it;
	for (it = 0; it < 400; it++) {
		struct px_nurbs_surf_derivs d;
		px_vec3 r;
		double a, b, c, g0, g1, det, du, dv, nd, lam = 1.0;
		/* Newton on |S - p|^2 / 2 (the residual's curvature terms
		 * keep it quadratic far from the sheet), Gauss-Newton where
		 * that Hessian is not positive */
		px_nurbs_surf_eval(f->s, u, v, 2, &d);
		r = px_v3_sub(d.s, p);
		a = px_v3_dot(d.su, d.su) + px_v3_dot(r, d.suu);
		b = px_v3_dot(d.su, d.sv) + px_v3_dot(r, d.suv);
		c = px_v3_dot(d.sv, d.sv) + px_v3_dot(r, d.svv);
		if (!(a > 0.0 && a * c - b * b > 0.0)) {
			a = px_v3_dot(d.su, d.su);
			b = px_v3_dot(d.su, d.sv);
			c = px_v3_dot(d.sv, d.sv);
		}
		g0 = px_v3_dot(r, d.su);
		g1 = px_v3_dot(r, d.sv);
		det = a * c - b * b;
		if (!(det > 0.0))
			break;
		du = -(c * g0 - b * g1) / det;
		dv = -(a * g1 - b * g0) / det;
		for (; lam > 1e-6; lam *= 0.5) {
			double un = u + lam * du, vn = v + lam * dv;
			if (un < 0 || un > 1 || vn < 0 || vn > 1 || !ff_in(f, un, vn, 0))
				continue;
			nd = px_v3_dist(px_nurbs_surf_point(f->s, un, vn), p);
			if (nd < best) {
				best = nd;
				u = un;
				v = vn;
				break;
			}
		}
		if (lam <= 1e-6)
			break;
	}
	return best;
}

static double ff_polish_curve(const struct ffref *f, const struct px_nurbs_curve *c,
			      px_vec3 p, double t, double step)
{
	double t0, t1, best;
	px_vec3 q = px_nurbs_curve_point(c, t);
	px_nurbs_curve_domain(c, &t0, &t1);
	best = px_v3_dist(px_nurbs_surf_point(f->s, q.x, q.y), p);
	for (; step > 1e-15 * (t1 - t0); step *= 0.5) {
		int k, moved = 1;
		while (moved) {
			moved = 0;
			for (k = -1; k <= 1; k += 2) {
				double tn = fmin(fmax(t + k * step, t0), t1), d;
				q = px_nurbs_curve_point(c, tn);
				d = px_v3_dist(px_nurbs_surf_point(f->s, q.x, q.y), p);
				if (d < best) {
					best = d;
					t = tn;
					moved = 1;
				}
			}
		}
	}
	return best;
}

static double ff_reference(const struct ffref *f, px_vec3 p)
{
	double best = INFINITY;
	int i, k, bi = -1;
	for (i = 0; i < f->ns; i++) {
		double d = px_v3_dist2(f->sp[i], p);
		if (d < best) {
			best = d;
			bi = i;
		}
	}
	best = ff_polish_surf(f, p, f->su[bi], f->sv[bi]);
	/* and the next best samples away from it (other basins) */
	{
		int picked[6], np = 1, j;
		picked[0] = bi;
		while (np < 6) {
			double bd = INFINITY;
			int bj = -1;
			for (i = 0; i < f->ns; i++) {
				double d = px_v3_dist2(f->sp[i], p);
				int far = d < bd;
				for (j = 0; j < np && far; j++)
					far = fabs(f->su[i] - f->su[picked[j]]) +
						      fabs(f->sv[i] - f->sv[picked[j]]) >
					      0.08;
				if (far) {
					bd = d;
					bj = i;
				}
			}
			if (bj < 0)
				break;
			picked[np++] = bj;
			best = fmin(best, ff_polish_surf(f, p, f->su[bj], f->sv[bj]));
		}
	}
	for (k = 0; k < f->nc; k++) {
		/* every local minimum of the samples, polished */
		double t0, t1, ds[401];
		px_nurbs_curve_domain(f->c[k], &t0, &t1);
		for (i = 0; i <= 400; i++) {
			px_vec3 q = px_nurbs_curve_point(f->c[k], t0 + (t1 - t0) * i / 400.0);
			ds[i] = px_v3_dist(px_nurbs_surf_point(f->s, q.x, q.y), p);
		}
		for (i = 0; i <= 400; i++)
			if (!((i > 0 && ds[i - 1] < ds[i]) || (i < 400 && ds[i + 1] < ds[i])))
				best = fmin(best, ff_polish_curve(f, f->c[k], p,
								  t0 + (t1 - t0) * i / 400.0,
								  (t1 - t0) / 400.0));
	}
	return best;
}

static void test_freeform(void)
{
	static char text[16384];
	double ctrl[3 * FF_NU * FF_NV];
	struct px_obj_model *om = NULL;
	struct px_obj_error e;
	struct px_brep_info info;
	struct px_trim_loop loops[2];
	struct px_nurbs_curve hc[3];
	unsigned char hrev[3] = {0, 0, 1};
	struct px_trim *t = NULL;
	struct ffref f;
	struct px_model *m;
	double size;
	int rc, i, j, wrong = 0, outside = 0;

	freeform_text(text, sizeof(text), ctrl);
	PX_CHECK_INT_EQ(px_obj_load_mem("ff.obj", text, strlen(text), &om, &e), PX_OK);
	if (!om) {
		PX_CHECK_MSG(0, "%d:%d %s", e.line, e.column, e.msg);
		return;
	}
	PX_CHECK_INT_EQ(om->n_curv2, 4);
	PX_CHECK_INT_EQ(om->n_loops, 2);
	PX_CHECK(px_obj_trimmed(om));
	m = load_text(text, &e, &rc);
	PX_CHECK_MSG(rc == PX_OK, "%d:%d %s", e.line, e.column, e.msg);
	if (!m) {
		px_obj_free(om);
		return;
	}
	px_brep_get_info(px_model_brep(m), &info);
	PX_CHECK_INT_EQ(info.n_edges, 4);
	/* the reference's own domain */
	loops[0].curves = &om->curv2[0].curve;
	loops[0].n_curves = 1;
	loops[0].reversed = NULL;
	for (i = 0; i < 3; i++)
		hc[i] = om->curv2[1 + i].curve;
	loops[1].curves = hc;
	loops[1].n_curves = 3;
	loops[1].reversed = hrev;
	PX_CHECK_INT_EQ(px_trim_create(loops, 2, NULL, NULL, &t), PX_OK);
	memset(&f, 0, sizeof(f));
	f.s = &om->entities[0].surf;
	f.t[0] = t;
	f.nt = 1;
	for (i = 0; i < 4; i++)
		f.c[i] = &om->curv2[i].curve;
	f.nc = 4;
	f.su = malloc(201 * 201 * sizeof(double));
	f.sv = malloc(201 * 201 * sizeof(double));
	f.sp = malloc(201 * 201 * sizeof(px_vec3));
	for (i = 0; i <= 200; i++)
		for (j = 0; j <= 200; j++) {
			double u = i / 200.0, v = j / 200.0;
			if (px_trim_contains(t, u, v, NULL) != PX_TRIM_INSIDE)
				continue;
			f.su[f.ns] = u;
			f.sv[f.ns] = v;
			f.sp[f.ns++] = px_nurbs_surf_point(f.s, u, v);
		}
	size = 3.5;
	for (i = 0; i < 600; i++) {
		struct px_model_result r;
		px_vec3 p = px_v3(px_rand_range(-0.5, 3.5), px_rand_range(-0.5, 3.0),
				  px_rand_range(-1.0, 1.0));
		double want = ff_reference(&f, p);
		int where;
		PX_CHECK_INT_EQ(px_model_query(m, p, &r), 1);
		/* never worse than the reference, always a point of the
		 * trimmed sheet (so never better than the true minimum) */
		if (!(r.distance <= want + 1e-9 * size) && wrong++ < 5)
			PX_CHECK_MSG(0, "(%g, %g, %g): %.15g, reference %.15g", p.x,
				     p.y, p.z, r.distance, want);
		where = px_trim_contains(t, r.u, r.v, NULL);
		if (r.feature == PX_FEATURE_SURFACE &&
		    (where == PX_TRIM_OUTSIDE ||
		     px_v3_dist(px_nurbs_surf_point(f.s, r.u, r.v), r.point) > 1e-9))
			outside++;
		if (!(fabs(px_v3_dist(p, r.point) - r.distance) <= 1e-9) && wrong++ < 5)
			PX_CHECK_MSG(0, "point not at the distance");
	}
	PX_CHECK_INT_EQ(wrong, 0);
	PX_CHECK_INT_EQ(outside, 0);
	free(f.su);
	free(f.sv);
	free(f.sp);
	px_trim_free(t);
	px_model_free(m);
	px_obj_free(om);
}


/* ---- cubic trims, several regions ------------------------------------------ */

/* A closed loop of the sheets below: a wobbly circle of 8 control points
 * (the ninth closes it) around (cx, cy), its face region, hole or not. */
struct loop_spec {
	double cx, cy, r;
	int hole, region;
};

/* A wavy n x n sheet of degree p over [0, 1]^2 (x up to 3, y up to
 * 2.5) with the loops as degree-dt curv2 curves, trim or hole, in the
 * given order. */
static void sheet_text(char *buf, size_t cap, int p, int n, int dt,
		       const struct loop_spec *L, int nl)
{
	int at = 0, i, j, k;
	for (j = 0; j < n; j++)
		for (i = 0; i < n; i++)
			at += snprintf(buf + at, cap - (size_t)at, "v %.17g %.17g %.17g\n",
				       3.0 * i / (n - 1), 2.5 * j / (n - 1),
				       0.4 * sin(1.7 * i * 5.0 / (n - 1) + 0.3) *
					       cos(1.3 * j * 4.0 / (n - 1)));
	for (k = 0; k < nl; k++)
		for (i = 0; i < 9; i++) {
			double th = 2.0 * M_PI * (i % 8) / 8.0;
			double r = L[k].r * (1.0 + 0.12 * sin(3.0 * th + 7.0 * L[k].cx));
			at += snprintf(buf + at, cap - (size_t)at, "vp %.17g %.17g\n",
				       L[k].cx + r * cos(th), L[k].cy + r * sin(th));
		}
	at += snprintf(buf + at, cap - (size_t)at, "cstype bspline\ndeg %d\n", dt);
	for (k = 0; k < nl; k++) {
		at += snprintf(buf + at, cap - (size_t)at, "curv2");
		for (i = 0; i < 9; i++)
			at += snprintf(buf + at, cap - (size_t)at, " %d", 9 * k + i + 1);
		at += snprintf(buf + at, cap - (size_t)at, "\nparm u");
		for (i = 0; i < 9 + dt + 1; i++)
			at += snprintf(buf + at, cap - (size_t)at, " %.17g",
				       i <= dt ? 0.0 : (i >= 9 ? 1.0 : (double)(i - dt) / (9 - dt)));
		at += snprintf(buf + at, cap - (size_t)at, "\nend\n");
	}
	at += snprintf(buf + at, cap - (size_t)at, "deg %d %d\nsurf 0 1 0 1", p, p);
	for (i = 1; i <= n * n; i++)
		at += snprintf(buf + at, cap - (size_t)at, " %d", i);
	for (k = 0; k < 2; k++) {
		at += snprintf(buf + at, cap - (size_t)at, "\nparm %c", k ? 'v' : 'u');
		for (i = 0; i < n + p + 1; i++)
			at += snprintf(buf + at, cap - (size_t)at, " %.17g",
				       i <= p ? 0.0 : (i >= n ? 1.0 : (double)(i - p) / (n - p)));
	}
	at += snprintf(buf + at, cap - (size_t)at, "\n");
	for (k = 0; k < nl; k++)
		at += snprintf(buf + at, cap - (size_t)at, "%s 0 1 %d\n",
			       L[k].hole ? "hole" : "trim", k + 1);
	snprintf(buf + at, cap - (size_t)at, "end\n");
}

/* The reference of a sheet: one domain per region (its trim loop and
 * its holes), every loop curve, the surface sampled inside. */
static int sheet_ref(struct ffref *f, const struct px_obj_model *om,
		     const struct loop_spec *L, int nl)
{
	struct px_trim *tr[8];
	int r, k, i, j, nr = 0;
	memset(f, 0, sizeof(*f));
	f->s = &om->entities[0].surf;
	for (k = 0; k < nl; k++) {
		f->c[f->nc++] = &om->curv2[k].curve;
		nr = L[k].region + 1 > nr ? L[k].region + 1 : nr;
	}
	for (r = 0; r < nr; r++) {
		struct px_trim_loop loops[8];
		int n = 0;
		for (k = 0; k < nl; k++)
			if (L[k].region == r && !L[k].hole) {
				loops[n].curves = &om->curv2[k].curve;
				loops[n].n_curves = 1;
				loops[n++].reversed = NULL;
			}
		for (k = 0; k < nl; k++)
			if (L[k].region == r && L[k].hole) {
				loops[n].curves = &om->curv2[k].curve;
				loops[n].n_curves = 1;
				loops[n++].reversed = NULL;
			}
		if (px_trim_create(loops, n, NULL, NULL, &tr[r]) != PX_OK)
			return -1;
		f->t[f->nt++] = tr[r];
	}
	f->su = malloc(201 * 201 * sizeof(double));
	f->sv = malloc(201 * 201 * sizeof(double));
	f->sp = malloc(201 * 201 * sizeof(px_vec3));
	for (i = 0; i <= 200; i++)
		for (j = 0; j <= 200; j++) {
			double u = i / 200.0, v = j / 200.0;
			if (!ff_in(f, u, v, 1))
				continue;
			f->su[f->ns] = u;
			f->sv[f->ns] = v;
			f->sp[f->ns++] = px_nurbs_surf_point(f->s, u, v);
		}
	return PX_OK;
}

static void sheet_ref_free(struct ffref *f)
{
	int k;
	for (k = 0; k < f->nt; k++)
		px_trim_free((struct px_trim *)(uintptr_t)f->t[k]);
	free(f->su);
	free(f->sv);
	free(f->sp);
}

/* Query points: far, near the trimmed sheet (both sides) and near the
 * loops' images (offsets from 1e-7 to 0.1). */
static px_vec3 sheet_point(const struct ffref *f, int i)
{
	px_vec3 dir = px_v3(px_rand_range(-1, 1), px_rand_range(-1, 1),
			    px_rand_range(-1, 1));
	double off = pow(10.0, px_rand_range(-7.0, -1.0));
	dir = px_v3_scale(dir, 1.0 / fmax(px_v3_norm(dir), 1e-3));
	if (i % 3 == 0)
		return px_v3(px_rand_range(-2.0, 5.0), px_rand_range(-2.0, 4.5),
			     px_rand_range(-2.0, 2.0));
	if (i % 3 == 1) {
		int k = rand() % f->ns;
		return px_v3_add(f->sp[k], px_v3_scale(dir, off));
	} else {
		const struct px_nurbs_curve *c = f->c[rand() % f->nc];
		px_vec3 q = px_nurbs_curve_point(c, px_rand_range(0.0, 1.0));
		return px_v3_add(px_nurbs_surf_point(f->s, q.x, q.y), px_v3_scale(dir, off));
	}
}

static double now_s(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Load text with the composed edges or, force, every loop curve as a
 * curve-on-surface edge. */
static struct px_model *load_forced(const char *text, int force, struct px_obj_error *e,
				    int *rc)
{
	struct px_model *m;
	px__brep_force_cos = force;
	m = load_text(text, e, rc);
	px__brep_force_cos = 0;
	return m;
}

/* Every answer of m on n points against the reference: never above it,
 * never below (the reference reaches the minimum on these sheets), the
 * point on the model at that distance, certified or with a gap that
 * reaches the minimum, no heap call. */
static void sheet_check(const char *name, struct px_model *m, const struct ffref *f, int n)
{
	double size = 3.5;
	int i, wrong = 0, below = 0, uncert = 0;
	uint64_t allocs = 0;
	for (i = 0; i < n; i++) {
		struct px_model_result r;
		px_vec3 p = sheet_point(f, i);
		double want = ff_reference(f, p);
		uint64_t a0 = px_alloc_region_begin();
		int rc = px_model_query(m, p, &r);
		allocs += px_alloc_region_end(a0);
		PX_CHECK_INT_EQ(rc, 1);
		if (!(r.distance <= want + 1e-9 * size) && wrong++ < 5)
			PX_CHECK_MSG(0, "%s (%.17g, %.17g, %.17g): %.15g, reference %.15g "
				     "(feature %d index %d)",
				     name, p.x, p.y, p.z, r.distance, want, r.feature, r.index);
		if (!(r.distance >= want - 1e-9 * size) && below++ < 5)
			PX_CHECK_MSG(0, "%s (%.17g, %.17g, %.17g): %.15g below the reference "
				     "%.15g (feature %d index %d)",
				     name, p.x, p.y, p.z, r.distance, want, r.feature, r.index);
		if (r.feature == PX_FEATURE_SURFACE &&
		    (!ff_in(f, r.u, r.v, 0) ||
		     px_v3_dist(px_nurbs_surf_point(f->s, r.u, r.v), r.point) > 1e-9 * size) &&
		    wrong++ < 5)
			PX_CHECK_MSG(0, "%s: a surface point outside the domain", name);
		if (!(fabs(px_v3_dist(p, r.point) - r.distance) <= 1e-9 * size) && wrong++ < 5)
			PX_CHECK_MSG(0, "%s: point not at the distance", name);
		/* an unproved answer's gap reaches the true minimum */
		if (!r.certified && !(r.gap > 0.0 && r.distance - r.gap <= want + 1e-9 * size))
			uncert++;
	}
	PX_CHECK_INT_EQ(wrong, 0);
	PX_CHECK_INT_EQ(below, 0);
	PX_CHECK_INT_EQ(uncert, 0);
	PX_CHECK_INT_EQ((int)allocs, 0);
}

/* The sheet of degree p with degree-dt loops L: loaded, its faces and
 * edges counted, n points against the reference. */
static void sheet_case(const char *name, int p, int dt, const struct loop_spec *L, int nl,
		       int n_faces, int n_points)
{
	static char text[65536];
	struct px_obj_model *om = NULL;
	struct px_obj_error e;
	struct px_brep_info info;
	struct ffref f;
	struct px_model *m;
	int rc;

	sheet_text(text, sizeof(text), p, 7, dt, L, nl);
	PX_CHECK_INT_EQ(px_obj_load_mem("s.obj", text, strlen(text), &om, &e), PX_OK);
	m = load_text(text, &e, &rc);
	PX_CHECK_MSG(rc == PX_OK, "%s %d:%d %s", name, e.line, e.column, e.msg);
	if (!m || !om) {
		px_model_free(m);
		px_obj_free(om);
		return;
	}
	px_brep_get_info(px_model_brep(m), &info);
	PX_CHECK_INT_EQ(info.n_faces, n_faces);
	PX_CHECK_INT_EQ(info.n_edges, nl);
	PX_CHECK_INT_EQ(info.closed, 0);
	/* images above degree 10 are curve-on-surface edges */
	PX_CHECK((strstr(info.why, "curve-on-surface") != NULL) == (dt * 2 * p > 10));
	PX_CHECK_INT_EQ(sheet_ref(&f, om, L, nl), PX_OK);
	sheet_check(name, m, &f, n_points);
	sheet_ref_free(&f);
	px_model_free(m);
	px_obj_free(om);
}

/* A bicubic sheet trimmed by a cubic loop with a cubic hole (Rhino's
 * usual export): the images (degree 18) are curve-on-surface edges. */
static void test_cubic_trim(void)
{
	static const struct loop_spec L[2] = {{0.5, 0.5, 0.38, 0, 0}, {0.45, 0.5, 0.12, 1, 0}};
	sheet_case("cubic", 3, 3, L, 2, 1, 900);
}

/* Several trim loops: two disjoint regions with a hole each, and an
 * island in one hole (the hole belongs to the smallest loop around
 * it); biquadratic with quadratic loops (composed edges) and bicubic
 * with cubic ones (curve-on-surface edges). */
static void test_regions(void)
{
	static const struct loop_spec L[5] = {{0.3, 0.5, 0.24, 0, 0},
					      {0.76, 0.5, 0.07, 1, 2},
					      {0.3, 0.5, 0.06, 0, 1},
					      {0.76, 0.5, 0.18, 0, 2},
					      {0.3, 0.5, 0.13, 1, 0}};
	sheet_case("regions 2", 2, 2, L, 5, 3, 600);
	sheet_case("regions 3", 3, 3, L, 5, 3, 600);
}

/* Quadratic loops on a biquadratic sheet, both ways: the composed edges
 * (degree 8 curves of the core) and curve-on-surface edges answer the
 * same; the time of both is printed. */
static void test_cos_vs_composed(void)
{
	static const struct loop_spec L[2] = {{0.5, 0.5, 0.38, 0, 0}, {0.45, 0.5, 0.12, 1, 0}};
	static char text[32768];
	struct px_obj_error e;
	struct px_model *mc, *ms;
	px_vec3 *pts;
	struct ffref f;
	struct px_obj_model *om = NULL;
	double worst = 0.0, sec[2] = {0, 0};
	int rc, rc2, i, k, n = 3000;

	sheet_text(text, sizeof(text), 2, 7, 2, L, 2);
	PX_CHECK_INT_EQ(px_obj_load_mem("q.obj", text, strlen(text), &om, &e), PX_OK);
	mc = load_forced(text, 0, &e, &rc);
	ms = load_forced(text, 1, &e, &rc2);
	PX_CHECK_INT_EQ(rc, PX_OK);
	PX_CHECK_INT_EQ(rc2, PX_OK);
	if (!mc || !ms || !om || sheet_ref(&f, om, L, 2)) {
		px_model_free(mc);
		px_model_free(ms);
		px_obj_free(om);
		return;
	}
	pts = malloc((size_t)n * sizeof(*pts));
	for (i = 0; i < n; i++)
		pts[i] = sheet_point(&f, i);
	for (k = 0; k < 2; k++) {
		struct px_model *m = k ? ms : mc;
		struct px_model_result r;
		double t0 = now_s();
		for (i = 0; i < n; i++)
			px_model_query(m, pts[i], &r);
		sec[k] = now_s() - t0;
	}
	for (i = 0; i < n; i++) {
		struct px_model_result a, b;
		PX_CHECK_INT_EQ(px_model_query(mc, pts[i], &a), 1);
		PX_CHECK_INT_EQ(px_model_query(ms, pts[i], &b), 1);
		worst = fmax(worst, fabs(a.distance - b.distance));
		/* as proved as the composed edges' answer (the core's
		 * crossed-patch proofs stop short on the same far points) */
		PX_CHECK_MSG(b.certified >= a.certified,
			     "(%.17g, %.17g, %.17g): %.17g uncertified (gap %g), composed %.17g "
			     "certified",
			     pts[i].x, pts[i].y, pts[i].z, b.distance, b.gap, a.distance);
	}
	PX_CHECK_MSG(worst <= 1e-9 * 3.5, "composed and curve-on-surface differ by %g", worst);
	printf("  quadratic trims, %d points: composed edges %.2f us/query, "
	       "curve-on-surface %.2f us/query\n",
	       n, 1e6 * sec[0] / n, 1e6 * sec[1] / n);
	sheet_check("forced", ms, &f, 300);
	free(pts);
	sheet_ref_free(&f);
	px_model_free(mc);
	px_model_free(ms);
	px_obj_free(om);
}

/* A tracked stream on text along a path that slides over the faces,
 * crosses the trimming edges and the holes: every answer the global
 * query's, jumps flagged, no heap call. */
static void track_sheet(const char *name, const char *text)
{
	struct px_obj_error e;
	struct px_model *m;
	struct px_model_stream *st = NULL;
	int rc, i, n = 2000, pf = -1, pi = -1;
	uint64_t a0;

	m = load_text(text, &e, &rc);
	PX_CHECK_MSG(rc == PX_OK, "%s %d:%d %s", name, e.line, e.column, e.msg);
	if (!m)
		return;
	PX_CHECK_INT_EQ(px_model_stream_create(m, NULL, &st), PX_OK);
	a0 = px_alloc_region_begin();
	for (i = 0; st && i <= n; i++) {
		double s = (double)i / n;
		px_vec3 p = px_v3(-0.3 + 3.6 * s, 1.25 + 0.6 * sin(6.0 * s),
				  0.15 * cos(9.0 * s));
		struct px_model_result a, c;
		struct px_model_stream_note note;
		PX_CHECK_INT_EQ(px_model_stream_query(st, p, INFINITY, 0, &a, &note), 1);
		PX_CHECK_INT_EQ(px_model_query(m, p, &c), 1);
		PX_CHECK_MSG(fabs(a.distance - c.distance) <= 1e-11 * 3.5,
			     "%s step %d: tracked %.17g (feature %d index %d), global %.17g "
			     "(feature %d index %d)",
			     name, i, a.distance, a.feature, a.index, c.distance, c.feature,
			     c.index);
		PX_CHECK(a.certified);
		if (i > 0 && (a.feature != pf || a.index != pi))
			PX_CHECK_MSG(note.jumped, "%s step %d: feature %d/%d -> %d/%d, not jumped",
				     name, i, pf, pi, a.feature, a.index);
		pf = a.feature;
		pi = a.index;
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(a0), 0);
	px_model_stream_free(st);
	px_model_free(m);
}

/* Tracked streams over the cubic-trim sheet and the cubic regions. */
static void test_cubic_tracked(void)
{
	static const struct loop_spec L[2] = {{0.5, 0.5, 0.38, 0, 0}, {0.45, 0.5, 0.12, 1, 0}};
	static const struct loop_spec R[5] = {{0.3, 0.5, 0.24, 0, 0},
					      {0.76, 0.5, 0.07, 1, 2},
					      {0.3, 0.5, 0.06, 0, 1},
					      {0.76, 0.5, 0.18, 0, 2},
					      {0.3, 0.5, 0.13, 1, 0}};
	static char text[65536];
	sheet_text(text, sizeof(text), 3, 7, 3, L, 2);
	track_sheet("cubic", text);
	sheet_text(text, sizeof(text), 3, 7, 3, R, 5);
	track_sheet("regions", text);
}

/* ---- refusals ---------------------------------------------------------------- */

struct bad {
	const char *tail; /* after the plane's head */
	int code, line;
	const char *needle;
};

/* Lines 1-8: four vertices, three parameter vertices, cstype. Line 9
 * on: the cases. */
#define HEAD "v 0 0 0\nv 2 0 0\nv 0 2 0\nv 2 2 0\nvp 0.3 0.3\nvp 0.7 0.3\nvp 0.5 0.7\ncstype bspline\n"
#define SURF "deg 1 1\nsurf 0 1 0 1 1 2 3 4\nparm u 0 0 1 1\nparm v 0 0 1 1\n"
#define TRI "deg 1\ncurv2 1 2\nparm u 0 0 1 1\nend\ncurv2 2 3\nparm u 0 0 1 1\nend\n" \
	    "curv2 3 1\nparm u 0 0 1 1\nend\n"

static const struct bad bad_files[] = {
	/* syntax: not triples (line 23, after TRI (lines 9-18) and SURF) */
	{TRI SURF "hole 0 1 1 0 1\nend\n", PX_E_PARSE, 23, "triples"},
	/* a missing curv2 */
	{TRI SURF "hole 0 1 1 0 1 2 0 1 9\nend\n", PX_E_PARSE, 23,
	 "curv2 9 is not defined (3 curv2 curves so far)"},
	/* a range outside the curv2's domain */
	{TRI SURF "hole 0 1 1 0 2 2 0 1 3\nend\n", PX_E_PARSE, 23,
	 "outside its domain"},
	/* a missing parameter vertex */
	{"deg 1\ncurv2 1 12\n", PX_E_PARSE, 10,
	 "parameter vertex 12 is not defined (3 parameter vertices so far)"},
	/* an open loop: the third side left out */
	{TRI SURF "hole 0 1 1 0 1 2\nend\n", PX_E_INVAL, 23, "is open"},
	/* a zero-area loop: there and back */
	{TRI SURF "hole 0 1 1 1 0 1\nend\n", PX_E_DEGENERATE, 23, "area"},
	/* a self-crossing loop: a bow tie */
	{"vp 0.9 0.9\nvp 0.3 0.7\ndeg 1\ncurv2 1 2 5 4 1\nparm u 0 0 1 2 3 4 4\nend\n" SURF
	 "hole 0 4 1\nend\n",
	 PX_E_INVAL, 19, "cross"},
	/* a loop outside the surface's domain */
	{"vp 1.5 0.3\ndeg 1\ncurv2 1 4 3 1\nparm u 0 0 1 2 3 3\nend\n" SURF
	 "trim 0 3 1\nend\n",
	 PX_E_INVAL, 18, "outside the surface's domain"},
	/* two outer loops and a hole in neither (lines 23, 24 the loops) */
	{"vp 0.1 0.1\nvp 0.2 0.1\nvp 0.15 0.2\n" TRI
	 "curv2 4 5\nparm u 0 0 1 1\nend\ncurv2 5 6\nparm u 0 0 1 1\nend\n"
	 "curv2 6 4\nparm u 0 0 1 1\nend\n" SURF
	 "trim 0 1 1 0 1 2 0 1 3\ntrim 0 1 4 0 1 5 0 1 6\n"
	 "hole 0 1 4 0 1 5 0 1 6\nend\n",
	 PX_E_INVAL, 37, "lies in none of its 'trim' loops"},
	/* limits: a quintic curv2 on a bicubic surface (degree 30) */
	{"vp 0.4 0.6\nvp 0.5 0.5\nvp 0.6 0.4\ndeg 5\ncurv2 1 2 4 5 6 1\n"
	 "parm u 0 0 0 0 0 0 1 1 1 1 1 1\nend\ndeg 3 3\n"
	 "surf 0 1 0 1 1 2 3 4 1 2 3 4 1 2 3 4 1 2 3 4\n"
	 "parm u 0 0 0 0 1 1 1 1\nparm v 0 0 0 0 1 1 1 1\nhole 0 1 1\nend\n",
	 PX_E_NOSPC, 20, "degree 30"},
	/* a trim outside a surf body */
	{TRI "hole 0 1 1 0 1 2 0 1 3\n", PX_E_UNSUPPORTED, 19, "inside a surf body"},
	/* a polygon face in a trimmed file */
	{TRI "f 1 2 3\n" SURF "hole 0 1 1 0 1 2 0 1 3\nend\n", PX_E_UNSUPPORTED, 0,
	 "polygon faces"},
};

static void test_refusals(void)
{
	size_t i;
	for (i = 0; i < sizeof(bad_files) / sizeof(bad_files[0]); i++) {
		char text[4096];
		struct px_obj_error e;
		struct px_model *m;
		int rc;
		snprintf(text, sizeof(text), "%s%s", HEAD, bad_files[i].tail);
		m = load_text(text, &e, &rc);
		PX_CHECK_MSG(m == NULL && rc == bad_files[i].code &&
				     e.line == bad_files[i].line &&
				     strstr(e.msg, bad_files[i].needle) != NULL,
			     "case %zu: rc %d (want %d) line %d (want %d): %s", i, rc,
			     bad_files[i].code, e.line, bad_files[i].line, e.msg);
		px_model_free(m);
	}
}

/* px_model_load(): a trimmed .obj is a B-rep, its refusal names the
 * file and line; an untrimmed free-form .obj goes where it went. */
static void test_model_load(void)
{
	static char text[8192];
	char path[256], msg[512], msg2[512];
	struct px_model *m = NULL;
	FILE *fp;
	int rc;

	snprintf(path, sizeof(path), "/tmp/px_objtrim_%d.obj", (int)getpid());
	plane_text(text, sizeof(text), 0.0, 1, 1, 1, 1);
	fp = fopen(path, "w");
	PX_CHECK(fp != NULL);
	if (!fp)
		return;
	fputs(text, fp);
	fclose(fp);
	rc = px_model_load(path, 0.0, &m, msg, sizeof(msg));
	PX_CHECK_MSG(rc == PX_OK, "%s", msg);
	PX_CHECK(m && px_model_kind(m) == PX_MODEL_BREP);
	PX_CHECK(strstr(msg, "unsigned") != NULL);
	px_model_free(m);
	m = NULL;
	/* the hole's curv2 turned into a straight 'there and back' */
	fp = fopen(path, "w");
	fputs("v 0 0 0\nv 2 0 0\nv 0 2 0\nv 2 2 0\nvp 0.3 0.3\nvp 0.7 0.3\n"
	      "cstype bspline\ndeg 1\ncurv2 1 2 1\nparm u 0 0 1 2 2\nend\n"
	      "deg 1 1\nsurf 0 1 0 1 1 2 3 4\nparm u 0 0 1 1\nparm v 0 0 1 1\n"
	      "hole 0 2 1\nend\n",
	      fp);
	fclose(fp);
	rc = px_model_load(path, 0.0, &m, msg, sizeof(msg));
	PX_CHECK_INT_EQ(rc, PX_E_DEGENERATE);
	PX_CHECK(m == NULL);
	snprintf(msg2, sizeof(msg2), "%s:16:1: ", path);
	PX_CHECK_MSG(strncmp(msg, msg2, strlen(msg2)) == 0, "%s", msg);
	/* untrimmed: one NURBS model, the same as px_model_load_obj()'s */
	plane_text(text, sizeof(text), 0.0, 0, 1, 1, 1);
	fp = fopen(path, "w");
	fputs(text, fp);
	fclose(fp);
	rc = px_model_load(path, 0.0, &m, msg, sizeof(msg));
	PX_CHECK_MSG(rc == PX_OK, "%s", msg);
	PX_CHECK(m && px_model_kind(m) == PX_MODEL_NURBS);
	if (m) {
		struct px_model *m2 = NULL;
		px_vec3 p = {0.3, 0.4, 0.7};
		struct px_model_result r1, r2;
		PX_CHECK_INT_EQ(px_model_load_obj(path, &m2, msg, sizeof(msg)), PX_OK);
		PX_CHECK(m2 && px_model_kind(m2) == PX_MODEL_NURBS);
		if (m2) {
			PX_CHECK_INT_EQ(px_model_query(m, p, &r1), 1);
			PX_CHECK_INT_EQ(px_model_query(m2, p, &r2), 1);
			PX_CHECK(r1.distance == r2.distance);
		}
		px_model_free(m2);
	}
	px_model_free(m);
	/* both free-form entities and faces: refused, named */
	fp = fopen(path, "a");
	fputs("f 1 2 3\n", fp);
	fclose(fp);
	m = NULL;
	PX_CHECK_INT_EQ(px_model_load_obj(path, &m, msg, sizeof(msg)), PX_E_UNSUPPORTED);
	PX_CHECK(m == NULL && strstr(msg, path) && strstr(msg, "both"));
	/* faces only: a mesh with the file's own coordinates */
	fp = fopen(path, "w");
	fputs("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", fp);
	fclose(fp);
	PX_CHECK_INT_EQ(px_model_load_obj(path, &m, msg, sizeof(msg)), PX_OK);
	PX_CHECK(m && px_model_kind(m) == PX_MODEL_MESH);
	px_model_free(m);
	unlink(path);
}

static const struct px_test tests[] = {
	PX_T(test_plane_hole), PX_T(test_freeform), PX_T(test_cubic_trim),
	PX_T(test_regions), PX_T(test_cos_vs_composed), PX_T(test_cubic_tracked),
	PX_T(test_refusals), PX_T(test_model_load)};
PX_TEST_MAIN(tests)
