/*
 * brep_gen.h - B-rep parts built in C for the B-rep test and benchmark
 * (no importer): a builder that fills a px_brep_desc from planes,
 * cylinders and free-form patches with their trimming loops, edges and
 * vertices, and four parts: a square sheet with a round hole, a cube
 * with a drilled through hole (closed), a biquadratic sheet trimmed by a
 * spline loop with a hole, and a closed box with 1 mm walls (outer shell
 * and void). Edges are exact: lines and circles as NURBS, and on the
 * free-form sheet the surface composed with each polynomial loop curve
 * (degree 8, interpolated at Chebyshev points to rounding).
 */
#ifndef PX_TEST_BREP_GEN_H
#define PX_TEST_BREP_GEN_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "arc_gen.h"
#include "px_brep.h"

#define BG_MAXF 16
#define BG_MAXL 4
#define BG_MAXC 8
#define BG_MAXE 64
#define BG_MAXV 32
#define BG_POOL 60000

struct brep_gen {
	struct px_brep_face_desc faces[BG_MAXF];
	struct px_trim_loop loops[BG_MAXF][BG_MAXL];
	struct px_nurbs_curve lc[BG_MAXF][BG_MAXL][BG_MAXC];
	unsigned char lrev[BG_MAXF][BG_MAXL][BG_MAXC];
	struct px_brep_coedge co[BG_MAXF][BG_MAXL][BG_MAXC];
	const struct px_brep_coedge *cop[BG_MAXF][BG_MAXL];
	struct px_brep_edge_desc edges[BG_MAXE];
	int epair[BG_MAXE][2]; /* vertex pair of a line edge, for sharing */
	px_vec3 verts[BG_MAXV];
	struct px_brep_shell_desc shells[4];
	double pool[BG_POOL];
	size_t at;
	int nf, ne, nv, ns;
	struct px_brep_desc d;
};

static inline double *bg_alloc(struct brep_gen *g, size_t n)
{
	double *p = g->pool + g->at;
	g->at += n;
	if (g->at > BG_POOL)
		abort();
	return p;
}

/* A curve view over homogeneous pw (copied) and knots. */
static inline struct px_nurbs_curve bg_curve(struct brep_gen *g, int p, int n,
					     const double *pw, const double *U)
{
	struct px_nurbs_curve c;
	double *k = bg_alloc(g, (size_t)(n + p + 1)), *h = bg_alloc(g, 4 * (size_t)n);
	memcpy(k, U, (size_t)(n + p + 1) * sizeof(double));
	memcpy(h, pw, 4 * (size_t)n * sizeof(double));
	if (px_nurbs_curve_view(&c, p, n, k, n + p + 1, h, NULL) != PX_OK)
		abort();
	return c;
}

static inline struct px_nurbs_curve bg_line(struct brep_gen *g, px_vec3 a, px_vec3 b)
{
	const double pw[8] = {a.x, a.y, a.z, 1, b.x, b.y, b.z, 1}, U[4] = {0, 0, 1, 1};
	return bg_curve(g, 1, 2, pw, U);
}

/* Full circle of radius r about c in the plane z = c.z, from angle 0,
 * counter-clockwise (4 rational quadratic spans on [0, 1]). */
static inline struct px_nurbs_curve bg_circle(struct brep_gen *g, px_vec3 c, double r)
{
	double xy[18], w[9], U[12], pw[36];
	int n = arc2d(0.0, 2.0 * M_PI, 4, xy, w, U), i;
	for (i = 0; i < n; i++) {
		pw[4 * i] = (c.x + r * xy[2 * i]) * w[i];
		pw[4 * i + 1] = (c.y + r * xy[2 * i + 1]) * w[i];
		pw[4 * i + 2] = c.z * w[i];
		pw[4 * i + 3] = w[i];
	}
	return bg_curve(g, 2, n, pw, U);
}

static inline int bg_vertex(struct brep_gen *g, px_vec3 p)
{
	int i;
	for (i = 0; i < g->nv; i++)
		if (px_v3_dist(g->verts[i], p) < 1e-12)
			return i;
	g->verts[g->nv] = p;
	return g->nv++;
}

static inline int bg_edge(struct brep_gen *g, struct px_nurbs_curve c, int v0, int v1)
{
	int e = g->ne++;
	g->edges[e].curve = c;
	g->edges[e].v0 = v0;
	g->edges[e].v1 = v1;
	g->edges[e].id = 1000 + e;
	g->epair[e][0] = g->epair[e][1] = -1;
	return e;
}

/* The straight edge between two vertices (made once, then shared). */
static inline int bg_line_edge(struct brep_gen *g, int v0, int v1)
{
	int e;
	for (e = 0; e < g->ne; e++)
		if ((g->epair[e][0] == v0 && g->epair[e][1] == v1) ||
		    (g->epair[e][0] == v1 && g->epair[e][1] == v0))
			return e;
	e = bg_edge(g, bg_line(g, g->verts[v0], g->verts[v1]), v0, v1);
	g->epair[e][0] = v0;
	g->epair[e][1] = v1;
	return e;
}

static inline int bg_face(struct brep_gen *g, struct px_nurbs_surf s, int reversed,
			  int shell)
{
	int f = g->nf++;
	memset(&g->faces[f], 0, sizeof(g->faces[f]));
	g->faces[f].surf = s;
	g->faces[f].loops = g->loops[f];
	g->faces[f].coedges = g->cop[f];
	g->faces[f].reversed = reversed;
	g->faces[f].shell = shell;
	g->faces[f].id = 100 + f;
	return f;
}

static inline int bg_loop(struct brep_gen *g, int f)
{
	int l = g->faces[f].n_loops++;
	g->loops[f][l].curves = g->lc[f][l];
	g->loops[f][l].n_curves = 0;
	g->loops[f][l].reversed = g->lrev[f][l];
	g->cop[f][l] = g->co[f][l];
	return l;
}

static inline void bg_coedge(struct brep_gen *g, int f, int l, struct px_nurbs_curve pc,
			     int rev, int edge)
{
	int k = g->loops[f][l].n_curves++;
	g->lc[f][l][k] = pc;
	g->lrev[f][l][k] = (unsigned char)rev;
	g->co[f][l][k].edge = edge;
}

/* Plane O + u A + v B on [0, 1]^2. */
static inline struct px_nurbs_surf bg_plane(struct brep_gen *g, px_vec3 o, px_vec3 a,
					    px_vec3 b)
{
	static const double U[4] = {0, 0, 1, 1};
	struct px_nurbs_surf s;
	double *k = bg_alloc(g, 4), *pw = bg_alloc(g, 16);
	px_vec3 q[4];
	int i;
	q[0] = o;
	q[1] = px_v3_add(o, a);
	q[2] = px_v3_add(o, b);
	q[3] = px_v3_add(q[1], b);
	memcpy(k, U, sizeof(U));
	for (i = 0; i < 4; i++) {
		pw[4 * i] = q[i].x;
		pw[4 * i + 1] = q[i].y;
		pw[4 * i + 2] = q[i].z;
		pw[4 * i + 3] = 1.0;
	}
	if (px_nurbs_surf_view(&s, 1, 1, 2, 2, k, 4, k, 4, pw, NULL) != PX_OK)
		abort();
	return s;
}

/* (u, v) of the 3D point p on the plane O + u A + v B (A, B orthogonal). */
static inline px_vec3 bg_plane_uv(px_vec3 o, px_vec3 a, px_vec3 b, px_vec3 p)
{
	px_vec3 d = px_v3_sub(p, o);
	return px_v3(px_v3_dot(d, a) / px_v3_dot(a, a), px_v3_dot(d, b) / px_v3_dot(b, b), 0);
}

/* A rectangular plane face O + u A + v B, u, v in [0, 1], bounded by the
 * straight edges between its corners, whose outward normal is along
 * out; optionally a round hole of radius r about the 3D point hc (its
 * circle edge he). Returns the face. */
static inline int bg_rect_face(struct brep_gen *g, px_vec3 o, px_vec3 a, px_vec3 b,
			       px_vec3 out, int shell, double r, px_vec3 hc, int he)
{
	int f = bg_face(g, bg_plane(g, o, a, b),
			px_v3_dot(px_v3_cross(a, b), out) < 0.0, shell);
	const double cu[5] = {0, 1, 1, 0, 0}, cv[5] = {0, 0, 1, 1, 0};
	int l = bg_loop(g, f), k, vid[4];
	for (k = 0; k < 4; k++)
		vid[k] = bg_vertex(g, px_v3_add(o, px_v3_add(px_v3_scale(a, cu[k]),
							     px_v3_scale(b, cv[k]))));
	for (k = 0; k < 4; k++)
		bg_coedge(g, f, l,
			  bg_line(g, px_v3(cu[k], cv[k], 0), px_v3(cu[k + 1], cv[k + 1], 0)),
			  0, bg_line_edge(g, vid[k], vid[(k + 1) % 4]));
	if (r > 0.0) {
		px_vec3 c = bg_plane_uv(o, a, b, hc);
		/* The circle edge starts at angle 0 about hc; in (u, v) the
		 * same circle starts there when A, B are along +x, +y. */
		l = bg_loop(g, f);
		bg_coedge(g, f, l, bg_circle(g, c, r / px_v3_norm(a)), 0, he);
	}
	return f;
}

static inline void bg_finish(struct brep_gen *g, int n_solids, const char *name)
{
	memset(&g->d, 0, sizeof(g->d));
	g->d.faces = g->faces;
	g->d.n_faces = g->nf;
	g->d.edges = g->edges;
	g->d.n_edges = g->ne;
	g->d.vertices = g->verts;
	g->d.n_vertices = g->nv;
	g->d.shells = g->shells;
	g->d.n_shells = g->ns;
	g->d.n_solids = n_solids;
	g->d.scale = 1.0;
	g->d.name = name;
	g->d.source = "brep_gen.h";
}

static inline struct brep_gen *bg_new(void)
{
	struct brep_gen *g = calloc(1, sizeof(*g));
	if (!g)
		abort();
	return g;
}

/* ---- parts ------------------------------------------------------------------ */

/* Unit square sheet in z = 0 with a round hole (radius 0.25 about
 * (0.5, 0.5)): one face, 5 edges, 5 vertices, an open shell. */
static inline struct brep_gen *brep_gen_sheet_hole(void)
{
	struct brep_gen *g = bg_new();
	px_vec3 hc = px_v3(0.5, 0.5, 0.0);
	int vc, he;
	g->shells[g->ns++] = (struct px_brep_shell_desc){0, -1, 0};
	vc = bg_vertex(g, px_v3(0.75, 0.5, 0.0));
	he = bg_edge(g, bg_circle(g, hc, 0.25), vc, vc);
	bg_rect_face(g, px_v3(0, 0, 0), px_v3(1, 0, 0), px_v3(0, 1, 0), px_v3(0, 0, 1), 0,
		     0.25, hc, he);
	bg_finish(g, 0, "sheet_hole");
	return g;
}

/* Roof over the unit square (ridge of height h along u = 0.5: a C0
 * crease of a degree-1 surface) with a round hole of radius 0.25 about
 * (0.5, 0.5) that the crease crosses: the hole's two half circles and
 * the square's sides are the exact images (the surface is affine on
 * each side of the ridge). One face, an open shell. */
static inline struct brep_gen *brep_gen_roof_hole(void)
{
	static const double Uu[5] = {0, 0, 0.5, 1, 1}, Uv[4] = {0, 0, 1, 1};
	const double h = 0.2, r = 0.25;
	struct brep_gen *g = bg_new();
	struct px_nurbs_surf s;
	double *ku = bg_alloc(g, 5), *kv = bg_alloc(g, 4), *pw = bg_alloc(g, 24);
	int i, j, f, l, k, vid[4], vh[2];
	const double cu[5] = {0, 1, 1, 0, 0}, cv[5] = {0, 0, 1, 1, 0};
	memcpy(ku, Uu, sizeof(Uu));
	memcpy(kv, Uv, sizeof(Uv));
	for (j = 0; j < 2; j++)
		for (i = 0; i < 3; i++) {
			double *q = pw + 4 * (j * 3 + i);
			q[0] = 0.5 * i;
			q[1] = j;
			q[2] = i == 1 ? h : 0.0;
			q[3] = 1.0;
		}
	if (px_nurbs_surf_view(&s, 1, 1, 3, 2, ku, 5, kv, 4, pw, NULL) != PX_OK)
		abort();
	g->shells[g->ns++] = (struct px_brep_shell_desc){0, -1, 0};
	f = bg_face(g, s, 0, 0);
	l = bg_loop(g, f);
	for (k = 0; k < 4; k++)
		vid[k] = bg_vertex(g, px_v3(cu[k], cv[k], 0));
	for (k = 0; k < 4; k++) {
		px_vec3 a = px_v3(cu[k], cv[k], 0), b = px_v3(cu[k + 1], cv[k + 1], 0);
		struct px_nurbs_curve e3;
		if (cv[k] == cv[k + 1]) {
			/* Along u over the ridge: three points, the knot at the
			 * ridge as the surface's. */
			const double epw[12] = {a.x, a.y, 0, 1, 0.5, a.y, h, 1, b.x, b.y, 0, 1};
			const double U[5] = {0, 0, 0.5, 1, 1};
			e3 = bg_curve(g, 1, 3, epw, U);
		} else {
			e3 = bg_line(g, a, b);
		}
		bg_coedge(g, f, l, bg_line(g, a, b), 0, bg_edge(g, e3, vid[k], vid[(k + 1) % 4]));
	}
	/* The hole: the half circle left of the ridge (angles pi/2 to 3pi/2)
	 * and the right one, each mapped by its side's affine map. */
	vh[0] = bg_vertex(g, px_v3(0.5, 0.5 + r, h));
	vh[1] = bg_vertex(g, px_v3(0.5, 0.5 - r, h));
	l = bg_loop(g, f);
	for (k = 0; k < 2; k++) {
		double xy[10], w[5], U[8], p2[20], p3[20];
		int n = arc2d(M_PI / 2 + k * M_PI, M_PI, 2, xy, w, U), m;
		for (m = 0; m < n; m++) {
			double u = 0.5 + r * xy[2 * m], v = 0.5 + r * xy[2 * m + 1];
			double z = k == 0 ? 2.0 * h * u : 2.0 * h * (1.0 - u);
			p2[4 * m] = u * w[m], p2[4 * m + 1] = v * w[m], p2[4 * m + 2] = 0.0;
			p3[4 * m] = u * w[m], p3[4 * m + 1] = v * w[m], p3[4 * m + 2] = z * w[m];
			p2[4 * m + 3] = p3[4 * m + 3] = w[m];
		}
		bg_coedge(g, f, l, bg_curve(g, 2, n, p2, U), 0,
			  bg_edge(g, bg_curve(g, 2, n, p3, U), vh[k], vh[1 - k]));
	}
	bg_finish(g, 0, "roof_hole");
	return g;
}

/* The six faces of the box [lo, hi] (outward normals away from its
 * middle, or towards it for a void), holes none. */
static inline void bg_box(struct brep_gen *g, px_vec3 lo, px_vec3 hi, int shell, int voidb)
{
	px_vec3 e = px_v3_sub(hi, lo), z = px_v3(0, 0, 0);
	double s = voidb ? -1.0 : 1.0;
	bg_rect_face(g, lo, px_v3(e.x, 0, 0), px_v3(0, e.y, 0), px_v3(0, 0, -s), shell, 0, z, -1);
	bg_rect_face(g, px_v3(lo.x, lo.y, hi.z), px_v3(e.x, 0, 0), px_v3(0, e.y, 0),
		     px_v3(0, 0, s), shell, 0, z, -1);
	bg_rect_face(g, lo, px_v3(0, e.y, 0), px_v3(0, 0, e.z), px_v3(-s, 0, 0), shell, 0, z, -1);
	bg_rect_face(g, px_v3(hi.x, lo.y, lo.z), px_v3(0, e.y, 0), px_v3(0, 0, e.z),
		     px_v3(s, 0, 0), shell, 0, z, -1);
	bg_rect_face(g, lo, px_v3(e.x, 0, 0), px_v3(0, 0, e.z), px_v3(0, -s, 0), shell, 0, z, -1);
	bg_rect_face(g, px_v3(lo.x, hi.y, lo.z), px_v3(e.x, 0, 0), px_v3(0, 0, e.z),
		     px_v3(0, s, 0), shell, 0, z, -1);
}

/* Cylinder about the z axis line through (cx, cy): radius r, z from z0
 * to z1, u along the circle from angle 0 counter-clockwise, v along z. */
static inline struct px_nurbs_surf bg_cylinder(struct brep_gen *g, double cx, double cy,
					       double r, double z0, double z1)
{
	double xy[18], w[9], U[12], *pw = bg_alloc(g, 72), *ku = bg_alloc(g, 12),
			       *kv = bg_alloc(g, 4);
	struct px_nurbs_surf s;
	int n = arc2d(0.0, 2.0 * M_PI, 4, xy, w, U), i, j;
	memcpy(ku, U, sizeof(U));
	kv[0] = kv[1] = 0.0;
	kv[2] = kv[3] = 1.0;
	for (j = 0; j < 2; j++)
		for (i = 0; i < n; i++) {
			double *q = pw + 4 * (j * n + i);
			q[0] = (cx + r * xy[2 * i]) * w[i];
			q[1] = (cy + r * xy[2 * i + 1]) * w[i];
			q[2] = (j ? z1 : z0) * w[i];
			q[3] = w[i];
		}
	if (px_nurbs_surf_view(&s, 2, 1, n, 2, ku, 12, kv, 4, pw, NULL) != PX_OK)
		abort();
	return s;
}

/* Cube [0, 1]^3 drilled along z by a hole of radius 0.2 about
 * (0.5, 0.5): 7 faces (the cylinder's one seam edge used twice), a
 * closed shell of one solid. */
static inline struct brep_gen *brep_gen_cube_hole(void)
{
	struct brep_gen *g = bg_new();
	const double r = 0.2;
	px_vec3 c0 = px_v3(0.5, 0.5, 0.0), c1 = px_v3(0.5, 0.5, 1.0), z = px_v3(0, 0, 0);
	int vb, vt, eb, et, es, f, l;
	g->shells[g->ns++] = (struct px_brep_shell_desc){1, 0, 0};
	vb = bg_vertex(g, px_v3(0.5 + r, 0.5, 0.0));
	vt = bg_vertex(g, px_v3(0.5 + r, 0.5, 1.0));
	eb = bg_edge(g, bg_circle(g, c0, r), vb, vb);
	et = bg_edge(g, bg_circle(g, c1, r), vt, vt);
	es = bg_edge(g, bg_line(g, g->verts[vb], g->verts[vt]), vb, vt);
	bg_rect_face(g, px_v3(0, 0, 0), px_v3(1, 0, 0), px_v3(0, 1, 0), px_v3(0, 0, -1), 0, r,
		     c0, eb);
	bg_rect_face(g, px_v3(0, 0, 1), px_v3(1, 0, 0), px_v3(0, 1, 0), px_v3(0, 0, 1), 0, r,
		     c1, et);
	bg_rect_face(g, px_v3(0, 0, 0), px_v3(0, 1, 0), px_v3(0, 0, 1), px_v3(-1, 0, 0), 0, 0, z, -1);
	bg_rect_face(g, px_v3(1, 0, 0), px_v3(0, 1, 0), px_v3(0, 0, 1), px_v3(1, 0, 0), 0, 0, z, -1);
	bg_rect_face(g, px_v3(0, 0, 0), px_v3(1, 0, 0), px_v3(0, 0, 1), px_v3(0, -1, 0), 0, 0, z, -1);
	bg_rect_face(g, px_v3(0, 1, 0), px_v3(1, 0, 0), px_v3(0, 0, 1), px_v3(0, 1, 0), 0, 0, z, -1);
	/* The bore: Su x Sv points away from the axis, out of the hole
	 * into the material, so the face is reversed. */
	f = bg_face(g, bg_cylinder(g, 0.5, 0.5, r, 0.0, 1.0), 1, 0);
	l = bg_loop(g, f);
	bg_coedge(g, f, l, bg_line(g, px_v3(0, 0, 0), px_v3(1, 0, 0)), 0, eb);
	bg_coedge(g, f, l, bg_line(g, px_v3(1, 0, 0), px_v3(1, 1, 0)), 0, es);
	bg_coedge(g, f, l, bg_line(g, px_v3(1, 1, 0), px_v3(0, 1, 0)), 0, et);
	bg_coedge(g, f, l, bg_line(g, px_v3(0, 1, 0), px_v3(0, 0, 0)), 0, es);
	bg_finish(g, 1, "cube_hole");
	return g;
}

/* Closed box 100 mm a side with 1 mm walls: the outer shell and the
 * void's (faces pointing into the void), one solid. */
static inline struct brep_gen *brep_gen_thin_box(void)
{
	struct brep_gen *g = bg_new();
	g->shells[g->ns++] = (struct px_brep_shell_desc){1, 0, 0};
	g->shells[g->ns++] = (struct px_brep_shell_desc){1, 0, 0};
	bg_box(g, px_v3(0, 0, 0), px_v3(0.1, 0.1, 0.1), 0, 0);
	bg_box(g, px_v3(0.001, 0.001, 0.001), px_v3(0.099, 0.099, 0.099), 1, 1);
	bg_finish(g, 1, "thin_box");
	return g;
}

/* Solve the n x n system a x = b in place (partial pivoting). */
static inline void bg_solve(double *a, double *b, int n)
{
	int i, j, k;
	for (k = 0; k < n; k++) {
		int piv = k;
		for (i = k + 1; i < n; i++)
			if (fabs(a[i * n + k]) > fabs(a[piv * n + k]))
				piv = i;
		for (j = 0; j < n; j++) {
			double t = a[k * n + j];
			a[k * n + j] = a[piv * n + j];
			a[piv * n + j] = t;
		}
		{
			double t = b[k];
			b[k] = b[piv];
			b[piv] = t;
		}
		for (i = k + 1; i < n; i++) {
			double f = a[i * n + k] / a[k * n + k];
			for (j = k; j < n; j++)
				a[i * n + j] -= f * a[k * n + j];
			b[i] -= f * b[k];
		}
	}
	for (k = n - 1; k >= 0; k--) {
		for (j = k + 1; j < n; j++)
			b[k] -= a[k * n + j] * b[j];
		b[k] /= a[k * n + k];
	}
}

/* The surface composed with the polynomial loop curve pc (one Bezier
 * span of degree dp, on a surface of degrees (p, q): degree dp (p + q)),
 * as a Bezier curve: interpolated at Chebyshev points, exact to
 * rounding since the composition is a polynomial of that degree. */
static inline struct px_nurbs_curve bg_compose(struct brep_gen *g,
					       const struct px_nurbs_surf *s,
					       const struct px_nurbs_curve *pc)
{
	double a[121] = {0}, bx[11], by[11], bz[11], pw[44], U[22], t0, t1;
	int n = pc->degree * (s->degree[0] + s->degree[1]), i, j;
	px_nurbs_curve_domain(pc, &t0, &t1);
	for (i = 0; i <= n; i++) {
		double t = 0.5 - 0.5 * cos(M_PI * (i + 0.5) / (n + 1));
		px_vec3 q = px_nurbs_curve_point(pc, t0 + t * (t1 - t0));
		px_vec3 x = px_nurbs_surf_point(s, q.x, q.y);
		for (j = 0; j <= n; j++) {
			double bin = 1.0;
			int k;
			for (k = 1; k <= j; k++)
				bin = bin * (n - j + k) / k;
			a[i * (n + 1) + j] = bin * pow(t, j) * pow(1.0 - t, n - j);
		}
		bx[i] = x.x;
		by[i] = x.y;
		bz[i] = x.z;
	}
	{
		double a2[121], a3[121];
		memcpy(a2, a, sizeof(a));
		memcpy(a3, a, sizeof(a));
		bg_solve(a, bx, n + 1);
		bg_solve(a2, by, n + 1);
		bg_solve(a3, bz, n + 1);
	}
	for (i = 0; i <= n; i++) {
		pw[4 * i] = bx[i];
		pw[4 * i + 1] = by[i];
		pw[4 * i + 2] = bz[i];
		pw[4 * i + 3] = 1.0;
		U[i] = 0.0;
		U[n + 1 + i] = 1.0;
	}
	/* The parameter runs as the loop curve's, mapped to [0, 1]. */
	return bg_curve(g, n, n + 1, pw, U);
}

/* A quadratic Bezier loop curve in (u, v). */
static inline struct px_nurbs_curve bg_quad2(struct brep_gen *g, double x0, double y0,
					     double x1, double y1, double x2, double y2)
{
	const double pw[12] = {x0, y0, 0, 1, x1, y1, 0, 1, x2, y2, 0, 1},
		     U[6] = {0, 0, 0, 1, 1, 1};
	return bg_curve(g, 2, 3, pw, U);
}

/* Loop through the n points pts (closed), each side a quadratic Bezier
 * whose middle control point is pushed out by bulge along the side's
 * normal; every curve gets its edge on the surface. */
static inline void bg_spline_loop(struct brep_gen *g, int f, const double *pts, int n,
				  double bulge)
{
	int l = bg_loop(g, f), k, vid[8];
	for (k = 0; k < n; k++) {
		px_vec3 q = px_v3(pts[2 * k], pts[2 * k + 1], 0);
		vid[k] = bg_vertex(g, px_nurbs_surf_point(&g->faces[f].surf, q.x, q.y));
	}
	for (k = 0; k < n; k++) {
		int k1 = (k + 1) % n;
		double x0 = pts[2 * k], y0 = pts[2 * k + 1], x2 = pts[2 * k1],
		       y2 = pts[2 * k1 + 1];
		double mx = 0.5 * (x0 + x2) + bulge * (y2 - y0),
		       my = 0.5 * (y0 + y2) - bulge * (x2 - x0);
		struct px_nurbs_curve pc = bg_quad2(g, x0, y0, mx, my, x2, y2);
		int e = bg_edge(g, bg_compose(g, &g->faces[f].surf, &pc), vid[k], vid[k1]);
		bg_coedge(g, f, l, pc, 0, e);
	}
}

/* Biquadratic bumpy sheet over [0, 1]^2 trimmed by a loop of five
 * bulging quadratic curves and a four-curve hole: one face, an open
 * shell. */
static inline struct brep_gen *brep_gen_freeform(void)
{
	static const double U[6] = {0, 0, 0, 1, 1, 1};
	static const double zz[9] = {0.0, 0.2, 0.05, 0.25, -0.3, 0.3, 0.1, 0.35, -0.1};
	static const double outer[10] = {0.1, 0.1, 0.9, 0.05, 0.95, 0.6, 0.5, 0.95, 0.05, 0.7};
	static const double hole[8] = {0.4, 0.35, 0.6, 0.4, 0.6, 0.6, 0.4, 0.55};
	struct brep_gen *g = bg_new();
	struct px_nurbs_surf s;
	double *k = bg_alloc(g, 6), *pw = bg_alloc(g, 36);
	int i, j, f;
	memcpy(k, U, sizeof(U));
	for (j = 0; j < 3; j++)
		for (i = 0; i < 3; i++) {
			double *q = pw + 4 * (j * 3 + i);
			q[0] = 0.5 * i + 0.05 * j;
			q[1] = 0.5 * j;
			q[2] = zz[j * 3 + i];
			q[3] = 1.0;
		}
	if (px_nurbs_surf_view(&s, 2, 2, 3, 3, k, 6, k, 6, pw, NULL) != PX_OK)
		abort();
	g->shells[g->ns++] = (struct px_brep_shell_desc){0, -1, 0};
	f = bg_face(g, s, 0, 0);
	bg_spline_loop(g, f, outer, 5, 0.15);
	bg_spline_loop(g, f, hole, 4, -0.2);
	bg_finish(g, 0, "freeform");
	return g;
}

#endif
