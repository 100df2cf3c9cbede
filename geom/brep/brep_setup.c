/*
 * brep_setup.c - px_brep_create(): the description checked entity by
 * entity (messages name the face, loop, curve, edge or shell), the
 * geometry copied and scaled into one block the handle owns, the trimmed
 * domains, the point candidates, and the distance core over the faces
 * (trimmed) and the edges (curves).
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "brep_internal.h"

void px_brep_opts_default(struct px_brep_opts *o)
{
	if (!o)
		return;
	px_trim_opts_default(&o->trim);
	o->dist = NULL;
	o->compose_edges = 0;
}

static void berr(struct px_brep_error *err, int code, int face, int loop,
		 int curve, int edge, long id, const char *fmt, ...)
	__attribute__((format(printf, 8, 9)));

static void berr(struct px_brep_error *err, int code, int face, int loop,
		 int curve, int edge, long id, const char *fmt, ...)
{
	va_list ap;
	if (!err)
		return;
	err->code = code;
	err->face = face;
	err->loop = loop;
	err->curve = curve;
	err->edge = edge;
	err->id = id;
	va_start(ap, fmt);
	vsnprintf(err->msg, sizeof(err->msg), fmt, ap);
	va_end(ap);
}

/* "face 3 (id 57)" or "face 3". */
static const char *face_name(const struct px_brep_desc *d, int f, char *buf,
			     size_t len)
{
	if (d->faces[f].id)
		snprintf(buf, len, "face %d (id %ld)", f, d->faces[f].id);
	else
		snprintf(buf, len, "face %d", f);
	return buf;
}

/* ---- checks of the description -------------------------------------------- */

static int check_counts(const struct px_brep_desc *d, struct px_brep_error *err)
{
	int i;
	if (d->n_faces < 1 || !d->faces) {
		berr(err, PX_E_INVAL, -1, -1, -1, -1, 0, "the B-rep has no faces");
		return PX_E_INVAL;
	}
	if (d->n_edges < 0 || d->n_vertices < 0 || d->n_shells < 0 ||
	    d->n_solids < 0 || (d->n_edges && !d->edges) ||
	    (d->n_vertices && !d->vertices) || (d->n_shells && !d->shells)) {
		berr(err, PX_E_INVAL, -1, -1, -1, -1, 0,
		     "negative count or missing array (edges %d, vertices %d, "
		     "shells %d, solids %d)",
		     d->n_edges, d->n_vertices, d->n_shells, d->n_solids);
		return PX_E_INVAL;
	}
	if (!(isfinite(d->scale) && d->scale > 0.0)) {
		berr(err, PX_E_INVAL, -1, -1, -1, -1, 0,
		     "scale %g is not a finite number above 0", d->scale);
		return PX_E_INVAL;
	}
	for (i = 0; i < d->n_shells; i++)
		if (d->shells[i].solid < -1 || d->shells[i].solid >= d->n_solids) {
			berr(err, PX_E_INVAL, -1, -1, -1, -1, d->shells[i].id,
			     "shell %d: solid %d out of range (%d solids)", i,
			     d->shells[i].solid, d->n_solids);
			if (err)
				err->shell = i;
			return PX_E_INVAL;
		}
	for (i = 0; i < d->n_vertices; i++)
		if (!px_v3_isfinite(d->vertices[i]) ||
		    fabs(d->vertices[i].x) > PX_NURBS_MAX_COORD ||
		    fabs(d->vertices[i].y) > PX_NURBS_MAX_COORD ||
		    fabs(d->vertices[i].z) > PX_NURBS_MAX_COORD) {
			berr(err, PX_E_NAN, -1, -1, -1, -1, 0,
			     "vertex %d is not a finite point", i);
			if (err)
				err->vertex = i;
			return PX_E_NAN;
		}
	return PX_OK;
}

static int check_edges(const struct px_brep_desc *d, struct px_brep_error *err)
{
	int i;
	for (i = 0; i < d->n_edges; i++) {
		const struct px_brep_edge_desc *e = &d->edges[i];
		struct px_nurbs_curve v;
		int rc = px_nurbs_curve_view(&v, e->curve.degree, e->curve.n_ctrl,
					     e->curve.knots, e->curve.n_knots,
					     e->curve.pw, err ? &err->nurbs : NULL);
		if (rc) {
			berr(err, rc, -1, -1, -1, i, e->id, "edge %d (id %ld): curve: %s",
			     i, e->id, err ? err->nurbs.msg : "");
			return rc;
		}
		if (e->v0 < -1 || e->v0 >= d->n_vertices || e->v1 < -1 ||
		    e->v1 >= d->n_vertices) {
			berr(err, PX_E_INVAL, -1, -1, -1, i, e->id,
			     "edge %d: vertex %d or %d out of range (%d vertices)",
			     i, e->v0, e->v1, d->n_vertices);
			return PX_E_INVAL;
		}
	}
	return PX_OK;
}

static int check_face(const struct px_brep_desc *d, int f,
		      struct px_brep_error *err)
{
	const struct px_brep_face_desc *fd = &d->faces[f];
	const struct px_nurbs_surf *s = &fd->surf;
	struct px_nurbs_surf v;
	char nm[64];
	int rc, l, k;

	face_name(d, f, nm, sizeof(nm));
	rc = px_nurbs_surf_view(&v, s->degree[0], s->degree[1], s->n_ctrl[0],
				s->n_ctrl[1], s->knots[0], s->n_knots[0],
				s->knots[1], s->n_knots[1], s->pw,
				err ? &err->nurbs : NULL);
	if (rc) {
		berr(err, rc, f, -1, -1, -1, fd->id, "%s: surface: %s", nm,
		     err ? err->nurbs.msg : "");
		return rc;
	}
	if (d->n_shells > 0 && (fd->shell < 0 || fd->shell >= d->n_shells)) {
		berr(err, PX_E_INVAL, f, -1, -1, -1, fd->id,
		     "%s: shell %d out of range (%d shells)", nm, fd->shell,
		     d->n_shells);
		return PX_E_INVAL;
	}
	if (fd->n_loops < 0 || (fd->n_loops > 0 && !fd->loops)) {
		berr(err, PX_E_INVAL, f, -1, -1, -1, fd->id,
		     "%s: %d loops without an array", nm, fd->n_loops);
		return PX_E_INVAL;
	}
	for (l = 0; l < fd->n_loops; l++) {
		if (fd->loops[l].n_curves < 1 || !fd->loops[l].curves) {
			berr(err, PX_E_INVAL, f, l, -1, -1, fd->id,
			     "%s: loop %d has no curves", nm, l);
			return PX_E_INVAL;
		}
		for (k = 0; k < fd->loops[l].n_curves; k++) {
			const struct px_nurbs_curve *c = &fd->loops[l].curves[k];
			struct px_nurbs_curve cv;
			int e = fd->coedges && fd->coedges[l] ? fd->coedges[l][k].edge : -1;
			rc = px_nurbs_curve_view(&cv, c->degree, c->n_ctrl, c->knots,
						 c->n_knots, c->pw,
						 err ? &err->nurbs : NULL);
			if (rc) {
				berr(err, rc, f, l, k, -1, fd->id,
				     "%s: loop %d curve %d: %s", nm, l, k,
				     err ? err->nurbs.msg : "");
				return rc;
			}
			if (e < -1 || e >= d->n_edges) {
				berr(err, PX_E_INVAL, f, l, k, e, fd->id,
				     "%s: loop %d curve %d: edge %d out of range "
				     "(%d edges)",
				     nm, l, k, e, d->n_edges);
				return PX_E_INVAL;
			}
		}
	}
	return PX_OK;
}

/* ---- copies ------------------------------------------------------------------ */

static size_t curve_doubles(const struct px_nurbs_curve *c)
{
	return (size_t)c->n_knots + 4 * (size_t)c->n_ctrl;
}

/* Copy c into mem (*at advanced), coordinates times scale, as a view. */
static void copy_curve(const struct px_nurbs_curve *c, double scale,
		       double *mem, size_t *at, struct px_nurbs_curve *out)
{
	double *k = mem + *at, *pw = k + c->n_knots;
	int i;
	memcpy(k, c->knots, (size_t)c->n_knots * sizeof(double));
	for (i = 0; i < c->n_ctrl; i++) {
		pw[4 * i] = c->pw[4 * i] * scale;
		pw[4 * i + 1] = c->pw[4 * i + 1] * scale;
		pw[4 * i + 2] = c->pw[4 * i + 2] * scale;
		pw[4 * i + 3] = c->pw[4 * i + 3];
	}
	*at += curve_doubles(c);
	*out = *c;
	out->knots = k;
	out->pw = pw;
}

static void copy_surf(const struct px_nurbs_surf *s, double scale,
		      double *mem, size_t *at, struct px_nurbs_surf *out)
{
	size_t n = (size_t)s->n_ctrl[0] * (size_t)s->n_ctrl[1], i;
	double *ku = mem + *at, *kv = ku + s->n_knots[0], *pw = kv + s->n_knots[1];
	memcpy(ku, s->knots[0], (size_t)s->n_knots[0] * sizeof(double));
	memcpy(kv, s->knots[1], (size_t)s->n_knots[1] * sizeof(double));
	for (i = 0; i < n; i++) {
		pw[4 * i] = s->pw[4 * i] * scale;
		pw[4 * i + 1] = s->pw[4 * i + 1] * scale;
		pw[4 * i + 2] = s->pw[4 * i + 2] * scale;
		pw[4 * i + 3] = s->pw[4 * i + 3];
	}
	*at += (size_t)s->n_knots[0] + s->n_knots[1] + 4 * n;
	*out = *s;
	out->knots[0] = ku;
	out->knots[1] = kv;
	out->pw = pw;
}

/* Everything copied into one block: surfaces and edge curves scaled,
 * loop curves (parameter space) as they are; the coedge list. */
static int copy_all(struct px_brep *b, const struct px_brep_desc *d)
{
	size_t total = 0, at = 0;
	int f, l, k, e, n_co = 0;

	for (f = 0; f < d->n_faces; f++) {
		const struct px_brep_face_desc *fd = &d->faces[f];
		total += (size_t)fd->surf.n_knots[0] + fd->surf.n_knots[1] +
			 4 * (size_t)fd->surf.n_ctrl[0] * fd->surf.n_ctrl[1];
		for (l = 0; l < fd->n_loops; l++)
			for (k = 0; k < fd->loops[l].n_curves; k++) {
				total += curve_doubles(&fd->loops[l].curves[k]);
				n_co++;
			}
	}
	for (e = 0; e < d->n_edges; e++)
		total += curve_doubles(&d->edges[e].curve);
	b->mem = malloc((total + 1) * sizeof(double));
	b->faces = calloc((size_t)d->n_faces, sizeof(*b->faces));
	b->edges = calloc((size_t)d->n_edges + 1, sizeof(*b->edges));
	b->co = calloc((size_t)n_co + 1, sizeof(*b->co));
	b->verts = calloc((size_t)d->n_vertices + 1, sizeof(*b->verts));
	b->dtrim = calloc((size_t)d->n_faces, sizeof(*b->dtrim));
	if (!b->mem || !b->faces || !b->edges || !b->co || !b->verts || !b->dtrim)
		return PX_E_NOMEM;
	b->bytes += (total + 1) * sizeof(double) +
		    (size_t)d->n_faces * (sizeof(*b->faces) + sizeof(*b->dtrim)) +
		    ((size_t)d->n_edges + 1) * sizeof(*b->edges) +
		    ((size_t)n_co + 1) * sizeof(*b->co) +
		    ((size_t)d->n_vertices + 1) * sizeof(*b->verts);
	for (f = 0; f < d->n_faces; f++) {
		const struct px_brep_face_desc *fd = &d->faces[f];
		copy_surf(&fd->surf, d->scale, b->mem, &at, &b->faces[f].surf);
		b->faces[f].reversed = fd->reversed != 0;
		b->faces[f].shell = d->n_shells > 0 ? fd->shell : -1;
		b->faces[f].id = fd->id;
		for (l = 0; l < fd->n_loops; l++)
			for (k = 0; k < fd->loops[l].n_curves; k++) {
				struct brep_coedge *c = &b->co[b->n_co++];
				copy_curve(&fd->loops[l].curves[k], 1.0, b->mem, &at,
					   &c->pc);
				c->face = f;
				c->loop = l;
				c->curve = k;
				c->edge = fd->coedges && fd->coedges[l]
						  ? fd->coedges[l][k].edge
						  : -1;
				c->dir = fd->loops[l].reversed &&
						 fd->loops[l].reversed[k]
					 ? -1
					 : 1;
			}
	}
	for (e = 0; e < d->n_edges; e++) {
		struct brep_edge *be = &b->edges[e];
		copy_curve(&d->edges[e].curve, d->scale, b->mem, &at, &be->c);
		be->v0 = d->edges[e].v0;
		be->v1 = d->edges[e].v1;
		be->id = d->edges[e].id;
		px_nurbs_curve_domain(&be->c, &be->t0, &be->t1);
	}
	for (k = 0; k < d->n_vertices; k++)
		b->verts[k] = px_v3_scale(d->vertices[k], d->scale);
	return PX_OK;
}

/* ---- trimmed domains ------------------------------------------------------ */

static int dt_inside(const void *ctx, double u, double v)
{
	return px_trim_contains(ctx, u, v, NULL) == PX_TRIM_INSIDE;
}

static int dt_classify(const void *ctx, double u0, double u1, double v0,
		       double v1)
{
	int c = px_trim_classify_box(ctx, u0, u1, v0, v1);
	return c == PX_TRIM_BOX_INSIDE ? 1 : (c == PX_TRIM_BOX_OUTSIDE ? 0 : 2);
}

/* Face f's loops (the copied curves) into its trimmed domain, which must
 * lie in the surface's parameter domain. */
static int build_trim(struct px_brep *b, const struct px_brep_desc *d, int f,
		      int first_co, const struct px_brep_opts *o,
		      struct px_brep_error *err)
{
	const struct px_brep_face_desc *fd = &d->faces[f];
	struct px_trim_loop loops[64];
	struct px_nurbs_curve *cv;
	struct px_trim_error te;
	double u0, u1, v0, v1, a, bb, c, dd, ct, ot;
	char nm[64];
	int l, k, at = first_co, rc;

	face_name(d, f, nm, sizeof(nm));
	if (fd->n_loops > 64) {
		berr(err, PX_E_NOSPC, f, -1, -1, -1, fd->id,
		     "%s: %d loops (at most 64)", nm, fd->n_loops);
		return PX_E_NOSPC;
	}
	cv = malloc((size_t)(b->n_co - first_co + 1) * sizeof(*cv));
	if (!cv)
		return PX_E_NOMEM;
	for (l = 0; l < fd->n_loops; l++) {
		loops[l].curves = cv + (at - first_co);
		loops[l].n_curves = fd->loops[l].n_curves;
		loops[l].reversed = fd->loops[l].reversed;
		for (k = 0; k < fd->loops[l].n_curves; k++, at++)
			cv[at - first_co] = b->co[at].pc;
	}
	memset(&te, 0, sizeof(te));
	rc = px_trim_create(loops, fd->n_loops, &o->trim, &te, &b->faces[f].trim);
	free(cv);
	if (rc) {
		if (err)
			err->trim = te;
		berr(err, rc, f, te.loop, te.curve, -1, fd->id, "%s: %s", nm,
		     te.msg);
		return rc;
	}
	/* The loops' points (not their control points, which may stand
	 * outside) within the surface's domain. */
	px_trim_tolerances(b->faces[f].trim, &ct, &ot);
	px_nurbs_surf_domain(&b->faces[f].surf, &a, &bb, &c, &dd);
	u0 = v0 = INFINITY;
	u1 = v1 = -INFINITY;
	for (at = first_co; at < b->n_co && b->co[at].face == f; at++) {
		double t0, t1;
		px_nurbs_curve_domain(&b->co[at].pc, &t0, &t1);
		for (k = 0; k <= 64; k++) {
			px_vec3 q = px_nurbs_curve_point(&b->co[at].pc,
							 t0 + (t1 - t0) * k / 64.0);
			u0 = fmin(u0, q.x);
			u1 = fmax(u1, q.x);
			v0 = fmin(v0, q.y);
			v1 = fmax(v1, q.y);
		}
	}
	if (u0 < a - ct || u1 > bb + ct || v0 < c - ct || v1 > dd + ct) {
		berr(err, PX_E_INVAL, f, -1, -1, -1, fd->id,
		     "%s: the loops reach [%g, %g] x [%g, %g], outside the "
		     "surface's domain [%g, %g] x [%g, %g]",
		     nm, u0, u1, v0, v1, a, bb, c, dd);
		return PX_E_INVAL;
	}
	b->dtrim[f].ctx = b->faces[f].trim;
	b->dtrim[f].inside = dt_inside;
	b->dtrim[f].classify = dt_classify;
	b->n_trimmed++;
	return PX_OK;
}

/* A loop curve without a 3D edge must map to one point of the surface:
 * then that point is a candidate (its vertex when one is there). */
static int collapsed_curve(struct px_brep *b, const struct px_brep_desc *d,
			   const struct brep_coedge *c, struct px_brep_error *err)
{
	const struct px_nurbs_surf *s = &b->faces[c->face].surf;
	px_aabb hb = px_nurbs_surf_aabb(s);
	double t0, t1, tol = 1e-9 * (1.0 + px_aabb_diagonal(&hb)), best = INFINITY;
	px_vec3 p0, q;
	int i, vi = -1;
	char nm[64];

	px_nurbs_curve_domain(&c->pc, &t0, &t1);
	q = px_nurbs_curve_point(&c->pc, t0);
	p0 = px_nurbs_surf_point(s, q.x, q.y);
	for (i = 1; i <= 64; i++) {
		q = px_nurbs_curve_point(&c->pc, t0 + (t1 - t0) * i / 64.0);
		if (px_v3_dist(px_nurbs_surf_point(s, q.x, q.y), p0) > tol) {
			face_name(d, c->face, nm, sizeof(nm));
			berr(err, PX_E_INVAL, c->face, c->loop, c->curve, -1,
			     d->faces[c->face].id,
			     "%s: loop %d curve %d has no 3D edge and its image "
			     "on the surface is not a point (give the edge's 3D "
			     "curve)",
			     nm, c->loop, c->curve);
			return PX_E_INVAL;
		}
	}
	for (i = 0; i < b->n_vertices; i++) {
		double dv = px_v3_dist(b->verts[i], p0);
		if (dv <= tol && dv < best) {
			best = dv;
			vi = i;
		}
	}
	b->pts[b->n_pts].p = p0;
	b->pts[b->n_pts].vertex = vi;
	b->pts[b->n_pts].collapsed = 1;
	b->n_pts++;
	return PX_OK;
}

/* Coedges to edges, collapsed loop curves and free vertices to point
 * candidates. */
static int link_topology(struct px_brep *b, const struct px_brep_desc *d,
			 struct px_brep_error *err)
{
	int i, rc, *used;

	b->pts = calloc((size_t)b->n_co + (size_t)b->n_vertices + 1, sizeof(*b->pts));
	used = calloc((size_t)b->n_vertices + 1, sizeof(int));
	if (!b->pts || !used) {
		free(used);
		return PX_E_NOMEM;
	}
	b->bytes += ((size_t)b->n_co + b->n_vertices + 1) * sizeof(*b->pts);
	for (i = 0; i < b->n_co; i++) {
		struct brep_coedge *c = &b->co[i];
		if (c->edge < 0 && px__brep_cos_on(b->cos, i))
			continue; /* answered by its curve-on-surface edge */
		if (c->edge < 0) {
			rc = collapsed_curve(b, d, c, err);
			if (rc) {
				free(used);
				return rc;
			}
			continue;
		}
		if (b->edges[c->edge].n_co < 2)
			b->edges[c->edge].co[b->edges[c->edge].n_co++] = i;
		b->edges[c->edge].uses++;
	}
	for (i = 0; i < b->n_edges; i++) {
		if (b->edges[i].v0 >= 0)
			used[b->edges[i].v0] = 1;
		if (b->edges[i].v1 >= 0)
			used[b->edges[i].v1] = 1;
	}
	for (i = 0; i < b->n_vertices; i++)
		if (!used[i]) {
			b->pts[b->n_pts].p = b->verts[i];
			b->pts[b->n_pts].vertex = i;
			b->n_pts++;
		}
	free(used);
	return PX_OK;
}

static char *dup_str(const char *s)
{
	char *c;
	size_t n;
	if (!s)
		return NULL;
	n = strlen(s) + 1;
	c = malloc(n);
	if (c)
		memcpy(c, s, n);
	return c;
}

/* link_topology() made every loop curve an edge (a curve of the
 * distance core) or, collapsed, a point candidate: so those answer the
 * whole boundary of every trimmed domain (px__dist_trim.edged). */
static void mark_edged(struct px_brep *b)
{
	int f;
	for (f = 0; f < b->n_faces; f++)
		if (b->dtrim[f].inside)
			b->dtrim[f].edged = 1;
}

/* The distance core over edges (curves) and faces (trimmed surfaces),
 * its workspaces, the box. */
static int build_dist(struct px_brep *b, const struct px_brep_opts *o)
{
	struct px_nurbs_curve *cv = NULL;
	struct px_nurbs_surf *sf;
	struct px_dist_info info;
	int i, rc;

	sf = malloc((size_t)b->n_faces * sizeof(*sf));
	if (b->n_edges)
		cv = malloc((size_t)b->n_edges * sizeof(*cv));
	if (!sf || (b->n_edges && !cv)) {
		free(sf);
		free(cv);
		return PX_E_NOMEM;
	}
	for (i = 0; i < b->n_faces; i++)
		sf[i] = b->faces[i].surf;
	for (i = 0; i < b->n_edges; i++)
		cv[i] = b->edges[i].c;
	mark_edged(b);
	rc = px__dist_model_create_trimmed(cv, b->n_edges, sf, b->n_faces,
					   b->dtrim, o->dist, &b->dm);
	free(sf);
	free(cv);
	for (i = 0; rc == PX_OK && i < BREP_WS; i++)
		rc = px_dist_ws_create(b->dm, &b->ws[i]);
	if (rc)
		return rc;
	px_dist_model_info(b->dm, &info);
	b->box = info.bounds;
	for (i = 0; i < b->n_pts; i++)
		px_aabb_extend(&b->box, b->pts[i].p);
	b->size = px_aabb_diagonal(&b->box);
	b->on_tol = 1e-13 * b->size;
	b->bytes += info.bytes + BREP_WS * (size_t)info.n_pieces * (sizeof(uint32_t) + 16);
	return PX_OK;
}

void px_brep_free(struct px_brep *b)
{
	int i;
	if (!b)
		return;
	for (i = 0; i < BREP_WS; i++)
		px_dist_ws_free(b->ws[i]);
	px_dist_model_free(b->dm);
	px__brep_cos_free(b->cos);
	for (i = 0; b->faces && i < b->n_faces; i++)
		px_trim_free(b->faces[i].trim);
	free(b->faces);
	free(b->edges);
	free(b->co);
	free(b->verts);
	free(b->pts);
	free(b->dtrim);
	free(b->shell_solid);
	free(b->shell_closed);
	free(b->vnormal);
	free(b->fsign);
	free(b->mem);
	free(b->name);
	free(b->source);
	free(b);
}

static int create_steps(struct px_brep *b, const struct px_brep_desc *d,
			const struct px_brep_opts *o, struct px_brep_error *err)
{
	int rc, f, i, first = 0;

	rc = check_counts(d, err);
	if (!rc)
		rc = check_edges(d, err);
	for (f = 0; !rc && f < d->n_faces; f++)
		rc = check_face(d, f, err);
	if (rc)
		return rc;
	b->n_faces = d->n_faces;
	b->n_edges = d->n_edges;
	b->n_vertices = d->n_vertices;
	b->n_shells = d->n_shells;
	b->n_solids = d->n_solids;
	rc = copy_all(b, d);
	if (rc)
		return rc;
	for (f = 0; f < d->n_faces; f++) {
		int n = 0, l;
		for (l = 0; l < d->faces[f].n_loops; l++)
			n += d->faces[f].loops[l].n_curves;
		if (n > 0) {
			rc = build_trim(b, d, f, first, o, err);
			if (rc)
				return rc;
		}
		first += n;
	}
	rc = link_topology(b, d, err);
	if (rc)
		return rc;
	b->shell_solid = calloc((size_t)d->n_shells + 1, sizeof(int));
	b->shell_closed = calloc((size_t)d->n_shells + 1, sizeof(int));
	if (!b->shell_solid || !b->shell_closed)
		return PX_E_NOMEM;
	for (i = 0; i < d->n_shells; i++) {
		b->shell_solid[i] = d->shells[i].solid;
		b->shell_closed[i] = d->shells[i].closed != 0;
	}
	b->name = dup_str(d->name ? d->name : "brep");
	b->source = dup_str(d->source);
	if (!b->name || (d->source && !b->source))
		return PX_E_NOMEM;
	rc = build_dist(b, o);
	if (rc)
		return rc;
	return px__brep_sign_setup(b);
}

int px_brep_create(const struct px_brep_desc *d, const struct px_brep_opts *opts,
		   struct px_brep_error *err, struct px_brep **out)
{
	struct px_brep_opts o;
	struct brep_aug aug;
	struct px_brep *b;
	int rc, k;

	if (err) {
		memset(err, 0, sizeof(*err));
		err->face = err->loop = err->curve = -1;
		err->edge = err->vertex = err->shell = -1;
	}
	if (!out || !d) {
		berr(err, PX_E_INVAL, -1, -1, -1, -1, 0, "no description or result");
		return PX_E_INVAL;
	}
	*out = NULL;
	if (opts)
		o = *opts;
	else
		px_brep_opts_default(&o);
	b = calloc(1, sizeof(*b));
	if (!b)
		return PX_E_NOMEM;
	for (k = 0; k < BREP_WS; k++)
		atomic_flag_clear(&b->busy[k]);
	b->bytes = sizeof(*b);
	/* loop curves without edges get their exact images (brep_compose.c) */
	memset(&aug, 0, sizeof(aug));
	rc = o.compose_edges ? px__brep_compose(d, &aug, err) : PX_OK;
	b->cos = aug.cos;
	aug.cos = NULL;
	if (!rc)
		rc = create_steps(b, aug.d.faces ? &aug.d : d, &o, err);
	if (!rc && b->cos) {
		/* signs need every edge as a curve of the core */
		b->closed = 0;
		snprintf(b->why, sizeof(b->why),
			 "%d loop curves are curve-on-surface edges (no signed "
			 "distance over them)",
			 b->cos->n_cos);
		b->bytes += sizeof(*b->cos) + b->cos->n_coef * sizeof(double) +
			    (size_t)b->cos->n_pc * sizeof(*b->cos->pc) +
			    (size_t)b->cos->n_cos * sizeof(*b->cos->cos);
	}
	px__brep_aug_free(&aug);
	if (rc) {
		if (err && !err->msg[0])
			berr(err, rc, -1, -1, -1, -1, 0, "setup failed (%s)",
			     px_strerror(rc));
		px_brep_free(b);
		return rc;
	}
	*out = b;
	return PX_OK;
}
