/*
 * brep_ref.h - the B-rep tests' reference distance, written without the
 * distance core: dense samples of each face (an n x n cell grid over the
 * surface's parameter domain, a sample counting where px_trim_contains()
 * puts it inside the trimmed domain), of every edge and the vertices
 * (and the surface point of each loop curve without an edge: a pole),
 * taken once at setup; per query, Newton from every sample that no
 * neighbour beats (each basin of the distance on a face or an edge), a
 * polished face point counting only inside the domain, faces and
 * samples skipped only where their grid, within its reach (the longest
 * cell diagonal), is farther than the best found. Every candidate is a
 * point of the trimmed model, so the reference is never below the true
 * minimum, and it reaches it when the samples fall in the minimum's
 * basin. check_on_model(): an answer's
 * point lies on the feature it names. ref_rand_point(): query points of
 * every kind around a part. Tests only (PX_CHECK on failure).
 */
#ifndef PX_TEST_BREP_REF_H
#define PX_TEST_BREP_REF_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "px_brep.h"
#include "px_model.h"
#include "px_test.h"
#include "px_trim.h"

/* Samples of one face: the surface on an (n + 1) x (n + 1) grid over
 * its parameter domain (row-major in u), which of them lie inside the
 * trimmed domain, and the longest diagonal of a grid cell (no point of
 * the surface is farther than that from its cell's corners). */
struct ref_face {
	double u0, u1, v0, v1;
	px_vec3 *p;
	unsigned char *in;
	int n_in;
	double reach;
};

/* Samples of one edge at REF_EDGE_N + 1 parameters, and the longest
 * step between two of them. */
#define REF_EDGE_N 400
struct ref_edge {
	double t0, t1;
	px_vec3 p[REF_EDGE_N + 1];
	double reach;
};

struct ref {
	const struct px_brep_desc *d;
	struct px_trim **trim; /* per face */
	struct ref_face *face;
	struct ref_edge *edge;
	int n;          /* grid cells per side */
	double *d2;     /* scratch: squared distances of one face's grid */
	px_vec3 *pts;   /* vertices, then the poles of collapsed loop curves */
	int n_pts;
	double size;
};

static void ref_sample_face(struct ref *r, int f)
{
	const struct px_nurbs_surf *s = &r->d->faces[f].surf;
	struct ref_face *g = &r->face[f];
	int i, j, n = r->n, m = n + 1;
	px_nurbs_surf_domain(s, &g->u0, &g->u1, &g->v0, &g->v1);
	g->p = malloc(sizeof(*g->p) * (size_t)m * (size_t)m);
	g->in = malloc((size_t)m * (size_t)m);
	PX_CHECK(g->p != NULL && g->in != NULL);
	for (i = 0; i <= n; i++)
		for (j = 0; j <= n; j++) {
			double u = g->u0 + (g->u1 - g->u0) * i / n;
			double v = g->v0 + (g->v1 - g->v0) * j / n;
			g->p[i * m + j] = px_nurbs_surf_point(s, u, v);
			g->in[i * m + j] = px_trim_contains(r->trim[f], u, v, NULL) == PX_TRIM_INSIDE;
			g->n_in += g->in[i * m + j];
		}
	for (i = 0; i < n; i++)
		for (j = 0; j < n; j++) {
			const px_vec3 *c = &g->p[i * m + j];
			g->reach = fmax(g->reach, fmax(px_v3_dist(c[0], c[m + 1]), px_v3_dist(c[1], c[m])));
		}
}

static void ref_sample_edge(struct ref *r, int e)
{
	const struct px_nurbs_curve *c = &r->d->edges[e].curve;
	struct ref_edge *g = &r->edge[e];
	int i;
	px_nurbs_curve_domain(c, &g->t0, &g->t1);
	for (i = 0; i <= REF_EDGE_N; i++) {
		g->p[i] = px_nurbs_curve_point(c, g->t0 + (g->t1 - g->t0) * i / REF_EDGE_N);
		if (i)
			g->reach = fmax(g->reach, px_v3_dist(g->p[i], g->p[i - 1]));
	}
}

/* The reference of d with an n x n cell sample grid per face. */
static void ref_init_grid(struct ref *r, const struct px_brep_desc *d, int n)
{
	px_aabb b = px_aabb_empty();
	int f, i, l, k, np = d->n_vertices;
	memset(r, 0, sizeof(*r));
	r->d = d;
	r->n = n;
	r->trim = calloc((size_t)d->n_faces, sizeof(*r->trim));
	r->face = calloc((size_t)d->n_faces, sizeof(*r->face));
	r->edge = calloc((size_t)d->n_edges + 1, sizeof(*r->edge));
	r->d2 = malloc(sizeof(*r->d2) * (size_t)(n + 1) * (size_t)(n + 1));
	PX_CHECK(r->trim != NULL && r->face != NULL && r->edge != NULL && r->d2 != NULL);
	for (f = 0; f < d->n_faces; f++) {
		px_aabb sb;
		PX_CHECK(px_trim_create(d->faces[f].loops, d->faces[f].n_loops, NULL, NULL,
					&r->trim[f]) == PX_OK);
		sb = px_nurbs_surf_aabb(&d->faces[f].surf);
		b = px_aabb_union(&b, &sb);
		ref_sample_face(r, f);
		for (l = 0; l < d->faces[f].n_loops; l++)
			np += d->faces[f].loops[l].n_curves;
	}
	for (i = 0; i < d->n_edges; i++)
		ref_sample_edge(r, i);
	r->pts = malloc(sizeof(*r->pts) * (size_t)(np + 1));
	PX_CHECK(r->pts != NULL);
	for (i = 0; i < d->n_vertices; i++) {
		px_aabb_extend(&b, d->vertices[i]);
		r->pts[r->n_pts++] = d->vertices[i];
	}
	/* a loop curve without an edge is a single point of its surface */
	for (f = 0; f < d->n_faces; f++)
		for (l = 0; l < d->faces[f].n_loops; l++)
			for (k = 0; k < d->faces[f].loops[l].n_curves; k++) {
				const struct px_nurbs_curve *c = &d->faces[f].loops[l].curves[k];
				double t0, t1;
				px_vec3 uv;
				if (d->faces[f].coedges && d->faces[f].coedges[l] &&
				    d->faces[f].coedges[l][k].edge >= 0)
					continue;
				px_nurbs_curve_domain(c, &t0, &t1);
				uv = px_nurbs_curve_point(c, t0);
				r->pts[r->n_pts++] = px_nurbs_surf_point(&d->faces[f].surf, uv.x, uv.y);
			}
	r->size = px_aabb_diagonal(&b);
}

static void ref_init(struct ref *r, const struct px_brep_desc *d)
{
	ref_init_grid(r, d, 64);
}

static void ref_fini(struct ref *r)
{
	int f;
	for (f = 0; f < r->d->n_faces; f++) {
		px_trim_free(r->trim[f]);
		free(r->face[f].p);
		free(r->face[f].in);
	}
	free(r->trim);
	free(r->face);
	free(r->edge);
	free(r->d2);
	free(r->pts);
}

/* Newton on |S(u, v) - p|^2 from (u, v), inside the domain; the best
 * point met that lies inside the trimmed domain lowers *best. */
static void polish_face(const struct ref *r, int f, px_vec3 p, double u, double v,
			double *best)
{
	const struct px_nurbs_surf *s = &r->d->faces[f].surf;
	double u0, u1, v0, v1;
	int it;
	px_nurbs_surf_domain(s, &u0, &u1, &v0, &v1);
	for (it = 0; it < 30; it++) {
		struct px_nurbs_surf_derivs dd;
		px_vec3 e;
		double g0, g1, h00, h01, h11, det, du, dv;
		px_nurbs_surf_eval(s, u, v, 2, &dd);
		e = px_v3_sub(dd.s, p);
		if (px_trim_contains(r->trim[f], u, v, NULL) == PX_TRIM_INSIDE &&
		    px_v3_dot(e, e) < *best)
			*best = px_v3_dot(e, e);
		g0 = px_v3_dot(e, dd.su);
		g1 = px_v3_dot(e, dd.sv);
		h00 = px_v3_dot(dd.su, dd.su) + px_v3_dot(e, dd.suu);
		h01 = px_v3_dot(dd.su, dd.sv) + px_v3_dot(e, dd.suv);
		h11 = px_v3_dot(dd.sv, dd.sv) + px_v3_dot(e, dd.svv);
		det = h00 * h11 - h01 * h01;
		if (!(det > 0.0 && h00 > 0.0)) {
			h00 = px_v3_dot(dd.su, dd.su);
			h01 = px_v3_dot(dd.su, dd.sv);
			h11 = px_v3_dot(dd.sv, dd.sv);
			det = h00 * h11 - h01 * h01;
			if (!(det > 0.0))
				break;
		}
		du = -(h11 * g0 - h01 * g1) / det;
		dv = -(h00 * g1 - h01 * g0) / det;
		u = fmin(fmax(u + du, u0), u1);
		v = fmin(fmax(v + dv, v0), v1);
		if (fabs(du) + fabs(dv) < 1e-15)
			break;
	}
}

static void polish_curve(const struct px_nurbs_curve *c, px_vec3 p, double t, double *best)
{
	double t0, t1;
	int it;
	px_nurbs_curve_domain(c, &t0, &t1);
	for (it = 0; it < 30; it++) {
		px_vec3 d[3], e;
		double g, h, dt;
		px_nurbs_curve_eval(c, t, 2, d);
		e = px_v3_sub(d[0], p);
		if (px_v3_dot(e, e) < *best)
			*best = px_v3_dot(e, e);
		g = px_v3_dot(e, d[1]);
		h = px_v3_dot(d[1], d[1]) + px_v3_dot(e, d[2]);
		if (!(h > 0.0))
			h = px_v3_dot(d[1], d[1]);
		if (!(h > 0.0))
			break;
		dt = -g / h;
		t = fmin(fmax(t + dt, t0), t1);
		if (fabs(dt) < 1e-15)
			break;
	}
}

/* Face f's contribution to *best (squared): Newton from every sample
 * inside the domain that no neighbour inside it beats (each basin of
 * the distance on the face), unless the whole grid, within its reach,
 * is farther than *best. */
static void ref_face_dist(const struct ref *r, int f, px_vec3 p, double *best)
{
	const struct ref_face *g = &r->face[f];
	int n = r->n, m = n + 1, i, j, a, b;
	double lo = INFINITY, cut;
	for (i = 0; i < m * m; i++) {
		r->d2[i] = px_v3_dist2(g->p[i], p);
		lo = fmin(lo, r->d2[i]);
		if (g->in[i])
			*best = fmin(*best, r->d2[i]);
	}
	if (sqrt(lo) - g->reach > sqrt(*best))
		return;
	for (i = 0; i <= n; i++)
		for (j = 0; j <= n; j++) {
			int k = i * m + j, low = 1;
			if (!g->in[k])
				continue;
			cut = sqrt(*best) + g->reach;
			if (r->d2[k] > cut * cut)
				continue;
			for (a = i - 1; a <= i + 1 && low; a++)
				for (b = j - 1; b <= j + 1 && low; b++)
					if (a >= 0 && a <= n && b >= 0 && b <= n && g->in[a * m + b] &&
					    r->d2[a * m + b] < r->d2[k])
						low = 0;
			if (low)
				polish_face(r, f, p, g->u0 + (g->u1 - g->u0) * i / n,
					    g->v0 + (g->v1 - g->v0) * j / n, best);
		}
}

/* Edge e's contribution, the same way along its samples. */
static void ref_edge_dist(const struct ref *r, int e, px_vec3 p, double *best)
{
	const struct ref_edge *g = &r->edge[e];
	double d2[REF_EDGE_N + 1], lo = INFINITY, cut;
	int i;
	for (i = 0; i <= REF_EDGE_N; i++) {
		d2[i] = px_v3_dist2(g->p[i], p);
		lo = fmin(lo, d2[i]);
	}
	*best = fmin(*best, lo);
	for (i = 0; i <= REF_EDGE_N; i++) {
		cut = sqrt(*best) + g->reach;
		if (d2[i] > cut * cut || (i > 0 && d2[i - 1] < d2[i]) ||
		    (i < REF_EDGE_N && d2[i + 1] < d2[i]))
			continue;
		polish_curve(&r->d->edges[e].curve, p,
			     g->t0 + (g->t1 - g->t0) * i / REF_EDGE_N, best);
	}
}

/* Reference distance from p to the trimmed model. Not thread-safe (one
 * scratch grid per reference). */
static double ref_dist(const struct ref *r, px_vec3 p)
{
	double best = INFINITY;
	int i;
	for (i = 0; i < r->n_pts; i++)
		best = fmin(best, px_v3_dist2(r->pts[i], p));
	for (i = 0; i < r->d->n_edges; i++)
		ref_edge_dist(r, i, p, &best);
	for (i = 0; i < r->d->n_faces; i++)
		ref_face_dist(r, i, p, &best);
	return sqrt(best);
}

/* The answer's point lies on the trimmed model where it says. */
static void check_on_model(const struct ref *r, const struct px_model_result *a)
{
	const struct px_brep_desc *d = r->d;
	double tol = 1e-9 * r->size;
	px_vec3 q;
	if (a->feature == PX_FEATURE_SURFACE) {
		PX_CHECK(a->index >= 0 && a->index < d->n_faces);
		q = px_nurbs_surf_point(&d->faces[a->index].surf, a->u, a->v);
		PX_CHECK_MSG(px_trim_contains(r->trim[a->index], a->u, a->v, NULL) !=
				     PX_TRIM_OUTSIDE,
			     "face %d answer (%g, %g) outside its domain", a->index, a->u, a->v);
	} else if (a->feature == PX_FEATURE_CURVE) {
		PX_CHECK(a->index >= 0 && a->index < d->n_edges);
		q = px_nurbs_curve_point(&d->edges[a->index].curve, a->u);
	} else {
		int i;
		PX_CHECK_INT_EQ(a->feature, PX_FEATURE_VERTEX);
		PX_CHECK(a->index >= -1 && a->index < d->n_vertices);
		q = a->index >= 0 ? d->vertices[a->index] : r->pts[0];
		/* -1: the point of a collapsed loop curve */
		for (i = 0; a->index < 0 && i < r->n_pts; i++)
			if (px_v3_dist(r->pts[i], a->point) < px_v3_dist(q, a->point))
				q = r->pts[i];
	}
	PX_CHECK_MSG(px_v3_dist(q, a->point) <= tol, "answer point %g off its feature",
		     px_v3_dist(q, a->point));
}

/* A random query point: in the enlarged box, near a face (both sides),
 * near an edge, or far. */
static px_vec3 ref_rand_point(const struct ref *r, px_aabb box)
{
	const struct px_brep_desc *d = r->d;
	int kind = (int)(px_rand_u64() % 5);
	px_vec3 c = px_v3_scale(px_v3_add(box.min, box.max), 0.5);
	double s = r->size;
	if (kind == 0 || kind == 4) {
		double k = kind == 4 ? 10.0 : 0.8;
		return px_v3(c.x + px_rand_range(-k, k) * s, c.y + px_rand_range(-k, k) * s,
			     c.z + px_rand_range(-k, k) * s);
	}
	if (kind == 1) {
		int f = (int)(px_rand_u64() % (uint64_t)d->n_faces), tries;
		const struct px_nurbs_surf *sf = &d->faces[f].surf;
		double u0, u1, v0, v1;
		px_nurbs_surf_domain(sf, &u0, &u1, &v0, &v1);
		for (tries = 0; tries < 100; tries++) {
			double u = px_rand_range(u0, u1), v = px_rand_range(v0, v1);
			struct px_nurbs_surf_derivs dd;
			px_vec3 n;
			double h;
			if (px_trim_contains(r->trim[f], u, v, NULL) != PX_TRIM_INSIDE)
				continue;
			px_nurbs_surf_eval(sf, u, v, 1, &dd);
			n = px_v3_cross(dd.su, dd.sv);
			n = px_v3_scale(n, 1.0 / px_v3_norm(n));
			h = s * pow(10.0, px_rand_range(-7.0, -1.5)) * (px_rand_u64() & 1 ? 1 : -1);
			return px_v3_madd(dd.s, n, h);
		}
	}
	if (d->n_edges > 0) {
		int e = (int)(px_rand_u64() % (uint64_t)d->n_edges);
		double t0, t1;
		px_vec3 q;
		px_nurbs_curve_domain(&d->edges[e].curve, &t0, &t1);
		q = px_nurbs_curve_point(&d->edges[e].curve, px_rand_range(t0, t1));
		return px_v3(q.x + s * px_rand_range(-0.05, 0.05), q.y + s * px_rand_range(-0.05, 0.05),
			     q.z + s * px_rand_range(-0.05, 0.05));
	}
	return c;
}

#endif
