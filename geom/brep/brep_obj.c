/*
 * brep_obj.c - a trimmed OBJ model (px_obj.h) as a B-rep description,
 * built with composed edges, its refusals placed at the file's trim,
 * hole, surf or curv statement (px_brep_obj.h).
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "brep_internal.h"
#include "px_brep_obj.h"
#include "px_file.h"
#include "px_model.h"

int px_obj_trimmed(const struct px_obj_model *m)
{
	return m && m->n_loops > 0;
}

int px_obj_text_trimmed(const char *data, size_t len)
{
	size_t i = 0;
	while (i < len) {
		while (i < len && (data[i] == ' ' || data[i] == '\t'))
			i++;
		if (len - i >= 5 && (memcmp(data + i, "trim", 4) == 0 ||
				     memcmp(data + i, "hole", 4) == 0) &&
		    (data[i + 4] == ' ' || data[i + 4] == '\t' || data[i + 4] == '\\'))
			return 1;
		while (i < len && data[i] != '\n')
			i++;
		i++;
	}
	return 0;
}

static int oerr(struct px_obj_error *e, int code, int line, int col,
		const char *fmt, ...) __attribute__((format(printf, 5, 6)));

static int oerr(struct px_obj_error *e, int code, int line, int col,
		const char *fmt, ...)
{
	va_list ap;
	if (e) {
		e->code = code;
		e->line = line;
		e->column = col;
		va_start(ap, fmt);
		vsnprintf(e->msg, sizeof(e->msg), fmt, ap);
		va_end(ap);
	}
	return code;
}

/* Per face: the loops given to px_brep_create() and where each came
 * from (line, column; 0 for the domain boundary made here). */
struct face_loops {
	struct px_trim_loop *loops;
	int n, *line, *col;
};

struct build {
	const struct px_obj_model *m;
	struct px_arena arena;
	struct px_brep_face_desc *faces;
	struct face_loops *fl;
	struct px_brep_edge_desc *edges;
	int *face_ent, *edge_ent;
	int n_faces, n_edges;
	/* per file loop: the 'trim' loop a hole belongs to (-1: the domain
	 * boundary), and for 'trim' loops of surfaces with several, the loop
	 * alone as a domain and its area */
	int *owner;
	struct px_trim **region;
	double *region_area;
};

static void build_free(struct build *b)
{
	int i;
	px_arena_fini(&b->arena);
	free(b->faces);
	free(b->fl);
	free(b->edges);
	free(b->face_ent);
	free(b->edge_ent);
	free(b->owner);
	if (b->region)
		for (i = 0; i < b->m->n_loops; i++)
			px_trim_free(b->region[i]);
	free(b->region);
	free(b->region_area);
}

/* Arena bytes: the sub-curves of the loops (twice: a 'trim' loop of a
 * surface with several is made once more to sort the holes) and the
 * boundary lines. */
static size_t arena_need(const struct px_obj_model *m)
{
	size_t n = 4096;
	int i;
	for (i = 0; i < m->n_trim_curves; i++)
		n += 2 * (px_nurbs_curve_extract_bytes(&m->curv2[m->trim_curves[i].curv2].curve) +
			  2 * PX_ARENA_ALIGN);
	for (i = 0; i < m->n_entities; i++)
		n += 4 * (px_nurbs_curve_bytes(1, 2) + 2 * PX_ARENA_ALIGN) +
		     4 * sizeof(struct px_nurbs_curve) + PX_ARENA_ALIGN;
	n += (size_t)(m->n_entities + 2 * m->n_loops + 1) *
		     (sizeof(struct px_trim_loop) + 2 * sizeof(int) + 3 * PX_ARENA_ALIGN) +
	     2 * (size_t)m->n_trim_curves *
		     (sizeof(struct px_nurbs_curve) + 1 + 2 * PX_ARENA_ALIGN);
	return n;
}

/* Loop curve: the curv2 on the statement's range (or whole). */
static int loop_curve(struct build *b, const struct px_obj_trim_curve *tc,
		      struct px_nurbs_curve *out, unsigned char *rev)
{
	const struct px_nurbs_curve *c = &b->m->curv2[tc->curv2].curve;
	double a, e, lo = fmin(tc->t0, tc->t1), hi = fmax(tc->t0, tc->t1);
	*rev = tc->t0 > tc->t1;
	px_nurbs_curve_domain(c, &a, &e);
	if (lo <= a && hi >= e) {
		*out = *c;
		return PX_OK;
	}
	return px_nurbs_curve_extract(c, lo, hi, &b->arena, out);
}

/* The surface's domain boundary, counter-clockwise, as four lines. */
static int domain_loop(struct build *b, const struct px_nurbs_surf *s,
		       struct px_trim_loop *l)
{
	static const double K[4] = {0, 0, 1, 1};
	double u0, u1, v0, v1;
	struct px_nurbs_curve *c = px_arena_alloc(&b->arena, 4 * sizeof(*c), 8);
	int k, rc = PX_OK;
	if (!c)
		return PX_E_NOMEM;
	px_nurbs_surf_domain(s, &u0, &u1, &v0, &v1);
	{
		const double P[5][3] = {{u0, v0, 0}, {u1, v0, 0}, {u1, v1, 0},
					{u0, v1, 0}, {u0, v0, 0}};
		for (k = 0; k < 4 && !rc; k++)
			rc = px_nurbs_curve_init(&c[k], &b->arena, 1, 2, K, 4, P[k],
						 NULL, NULL);
	}
	l->curves = c;
	l->n_curves = 4;
	l->reversed = NULL;
	return rc;
}

/* One loop of the file (index i of m->loops) into l, its place into
 * fl at slot at. */
static int file_loop(struct build *b, int i, struct face_loops *fl, int at)
{
	const struct px_obj_loop *ol = &b->m->loops[i];
	struct px_nurbs_curve *cv;
	unsigned char *rev;
	int k, rc;
	cv = px_arena_alloc(&b->arena, (size_t)ol->n * sizeof(*cv), 8);
	rev = px_arena_alloc(&b->arena, (size_t)ol->n, 1);
	if (!cv || !rev)
		return PX_E_NOMEM;
	for (k = 0; k < ol->n; k++) {
		rc = loop_curve(b, &b->m->trim_curves[ol->first + k], &cv[k], &rev[k]);
		if (rc)
			return rc;
	}
	fl->loops[at].curves = cv;
	fl->loops[at].n_curves = ol->n;
	fl->loops[at].reversed = rev;
	fl->line[at] = ol->line;
	fl->col[at] = ol->column;
	return PX_OK;
}

/* The loops of one face of surface entity ent: the outer loop (the
 * file's loop outer, or the domain boundary when outer < 0), then the
 * holes whose owner is outer. */
static int face_loops(struct build *b, int ent, int outer, struct face_loops *fl,
		      const struct px_nurbs_surf *s)
{
	const struct px_obj_model *m = b->m;
	int i, n = 1, rc;

	for (i = 0; i < m->n_loops; i++)
		n += m->loops[i].entity == ent && m->loops[i].hole &&
		     b->owner[i] == outer;
	memset(fl, 0, sizeof(*fl));
	fl->loops = px_arena_alloc(&b->arena, (size_t)n * sizeof(*fl->loops), 8);
	fl->line = px_arena_alloc(&b->arena, (size_t)n * sizeof(int), 8);
	fl->col = px_arena_alloc(&b->arena, (size_t)n * sizeof(int), 8);
	if (!fl->loops || !fl->line || !fl->col)
		return PX_E_NOMEM;
	rc = outer < 0 ? domain_loop(b, s, &fl->loops[0]) : file_loop(b, outer, fl, 0);
	if (rc)
		return rc;
	if (outer < 0)
		fl->line[0] = fl->col[0] = 0;
	fl->n = 1;
	for (i = 0; i < m->n_loops; i++)
		if (m->loops[i].entity == ent && m->loops[i].hole &&
		    b->owner[i] == outer) {
			rc = file_loop(b, i, fl, fl->n++);
			if (rc)
				return rc;
		}
	return PX_OK;
}

/* Where a point of loop i lies against the domain t (px_trim_contains):
 * the first of its sample points that is not on t's boundary decides. */
static int loop_where(struct build *b, int i, const struct px_trim *t)
{
	const struct px_obj_loop *ol = &b->m->loops[i];
	int k, j, w = PX_TRIM_BOUNDARY;
	for (k = 0; k < ol->n && w == PX_TRIM_BOUNDARY; k++) {
		const struct px_obj_trim_curve *tc = &b->m->trim_curves[ol->first + k];
		const struct px_nurbs_curve *c = &b->m->curv2[tc->curv2].curve;
		for (j = 0; j < 8 && w == PX_TRIM_BOUNDARY; j++) {
			px_vec3 q = px_nurbs_curve_point(c, tc->t0 + (tc->t1 - tc->t0) *
								     (2 * j + 1) / 16.0);
			w = px_trim_contains(t, q.x, q.y, NULL);
		}
	}
	return w;
}

/* Surface entity ent with several 'trim' loops: every one is a face
 * region, every hole belongs to the smallest of them that holds it
 * (owner[hole] = that loop's index). A hole in none is refused. */
static int assign_holes(struct build *b, int ent, struct px_obj_error *err)
{
	const struct px_obj_model *m = b->m;
	struct px_trim_opts to;
	int i, k, rc = PX_OK;

	px_trim_opts_default(&to);
	for (i = 0; i < m->n_loops; i++) {
		const struct px_obj_loop *ol = &m->loops[i];
		struct face_loops fl;
		struct px_trim_loop tl;
		int line, col;
		if (ol->entity != ent || ol->hole)
			continue;
		memset(&fl, 0, sizeof(fl));
		fl.loops = &tl;
		fl.line = &line;
		fl.col = &col;
		rc = file_loop(b, i, &fl, 0);
		if (!rc) {
			struct px_trim_error te;
			memset(&te, 0, sizeof(te));
			rc = px_trim_create(&tl, 1, &to, &te, &b->region[i]);
			if (rc)
				return oerr(err, rc, ol->line, ol->column,
					    "'trim' of the surface of line %d: %s",
					    m->entities[ent].line, te.msg);
			b->region_area[i] = fabs(px__trim_loop_area(b->region[i], 0));
		}
		if (rc)
			return oerr(err, rc, ol->line, ol->column,
				    "'trim' of the surface of line %d: cannot "
				    "build it: %s",
				    m->entities[ent].line, px_strerror(rc));
	}
	for (i = 0; i < m->n_loops; i++) {
		const struct px_obj_loop *ol = &m->loops[i];
		double best = INFINITY;
		if (ol->entity != ent || !ol->hole)
			continue;
		b->owner[i] = -2;
		for (k = 0; k < m->n_loops; k++)
			if (b->region[k] && m->loops[k].entity == ent &&
			    b->region_area[k] < best &&
			    loop_where(b, i, b->region[k]) == PX_TRIM_INSIDE) {
				best = b->region_area[k];
				b->owner[i] = k;
			}
		if (b->owner[i] == -2)
			return oerr(err, PX_E_INVAL, ol->line, ol->column,
				    "'hole' of the surface of line %d lies in none "
				    "of its 'trim' loops",
				    m->entities[ent].line);
	}
	return PX_OK;
}

/* The loop of face f that reaches farthest outside its surface's domain
 * (by its control points): where a refusal of the whole domain points. */
static int farthest_loop(const struct build *b, int f)
{
	const struct face_loops *fl = &b->fl[f];
	double u0, u1, v0, v1, worst = -1.0;
	int l, k, i, at = -1;
	px_nurbs_surf_domain(&b->faces[f].surf, &u0, &u1, &v0, &v1);
	for (l = 0; l < fl->n; l++)
		for (k = 0; k < fl->loops[l].n_curves; k++) {
			const struct px_nurbs_curve *c = &fl->loops[l].curves[k];
			for (i = 0; i < c->n_ctrl; i++) {
				px_vec3 q = px_nurbs_curve_ctrl(c, i, NULL);
				double out = fmax(fmax(u0 - q.x, q.x - u1),
						  fmax(v0 - q.y, q.y - v1));
				if (out > worst) {
					worst = out;
					at = l;
				}
			}
		}
	return at;
}

/* px_brep_create()'s refusal placed at the statement it concerns. */
static int place_error(const struct build *b, const struct px_brep_error *be,
		       struct px_obj_error *err)
{
	const struct px_obj_model *m = b->m;
	int line = 0, col = 0;
	if (be->face >= 0 && be->face < b->n_faces) {
		const struct face_loops *fl = &b->fl[be->face];
		const struct px_obj_entity *e = &m->entities[b->face_ent[be->face]];
		int l = be->loop >= 0 ? be->loop : farthest_loop(b, be->face);
		line = e->line;
		col = 1;
		if (l >= 0 && l < fl->n && fl->line[l] > 0) {
			line = fl->line[l];
			col = fl->col[l];
		}
		return oerr(err, be->code, line, col, "%s of the surface of line %d: %s",
			    l < 0 ? "trimmed domain"
				  : (l == 0 && fl->line[0] > 0 ? "'trim'"
				     : (l == 0 ? "domain boundary" : "'hole'")),
			    e->line, be->msg);
	}
	if (be->edge >= 0 && be->edge < b->n_edges) {
		line = m->entities[b->edge_ent[be->edge]].line;
		col = 1;
	}
	return oerr(err, be->code, line, col, "%s", be->msg);
}

/* One face of surface entity ent: outer loop outer (-1: the domain
 * boundary) and the holes it owns. */
static int add_face(struct build *b, int ent, int outer, struct px_obj_error *err)
{
	const struct px_obj_entity *e = &b->m->entities[ent];
	struct px_brep_face_desc *f = &b->faces[b->n_faces];
	struct face_loops *fl = &b->fl[b->n_faces];
	int rc = face_loops(b, ent, outer, fl, &e->surf);
	if (rc)
		return oerr(err, rc, e->line, 1,
			    "surface of line %d: cannot build its loops: %s",
			    e->line, px_strerror(rc));
	memset(f, 0, sizeof(*f));
	f->surf = e->surf;
	f->loops = fl->n > 1 || outer >= 0 ? fl->loops : NULL;
	f->n_loops = fl->n > 1 || outer >= 0 ? fl->n : 0;
	f->shell = 0;
	f->id = e->line;
	b->face_ent[b->n_faces++] = ent;
	return PX_OK;
}

/* The faces of surface entity ent: one per 'trim' loop (the whole
 * domain when it has none), the holes with the loop that holds them. */
static int surf_faces(struct build *b, int ent, struct px_obj_error *err)
{
	const struct px_obj_model *m = b->m;
	int i, n_outer = 0, last = -1, rc;

	for (i = 0; i < m->n_loops; i++)
		if (m->loops[i].entity == ent && !m->loops[i].hole) {
			n_outer++;
			last = i;
		}
	if (n_outer > 1) {
		rc = assign_holes(b, ent, err);
		if (rc)
			return rc;
	} else
		for (i = 0; i < m->n_loops; i++)
			if (m->loops[i].entity == ent)
				b->owner[i] = last;
	if (n_outer == 0)
		return add_face(b, ent, -1, err);
	for (i = 0; i < m->n_loops; i++)
		if (m->loops[i].entity == ent && !m->loops[i].hole) {
			rc = add_face(b, ent, i, err);
			if (rc)
				return rc;
		}
	return PX_OK;
}

static int describe(struct build *b, double scale, struct px_brep **out,
		    struct px_obj_error *err)
{
	const struct px_obj_model *m = b->m;
	struct px_brep_shell_desc shell = {0, -1, 0};
	struct px_brep_desc d;
	struct px_brep_opts o;
	struct px_brep_error be;
	int i, rc;

	for (i = 0; i < m->n_entities; i++) {
		const struct px_obj_entity *e = &m->entities[i];
		if (e->kind == PX_OBJ_SURF) {
			rc = surf_faces(b, i, err);
			if (rc)
				return rc;
		} else {
			struct px_brep_edge_desc *ed = &b->edges[b->n_edges];
			ed->curve = e->curve;
			ed->v0 = ed->v1 = -1;
			ed->id = e->line;
			b->edge_ent[b->n_edges++] = i;
		}
	}
	if (b->n_faces == 0)
		return oerr(err, PX_E_INVAL, 0, 0,
			    "trim or hole loops but no surface");
	memset(&d, 0, sizeof(d));
	d.faces = b->faces;
	d.n_faces = b->n_faces;
	d.edges = b->edges;
	d.n_edges = b->n_edges;
	d.shells = &shell;
	d.n_shells = 1;
	d.scale = scale;
	d.name = "obj";
	px_brep_opts_default(&o);
	o.compose_edges = 1;
	rc = px_brep_create(&d, &o, &be, out);
	if (rc)
		return place_error(b, &be, err);
	return PX_OK;
}

int px_brep_from_obj(const struct px_obj_model *m, double scale,
		     struct px_brep **out, struct px_obj_error *err)
{
	struct build b;
	size_t n;
	int rc;

	if (out)
		*out = NULL;
	if (!m || !out || !(isfinite(scale) && scale > 0.0))
		return oerr(err, PX_E_INVAL, 0, 0, "no model, no result or a bad scale");
	if (m->n_triangles > 0)
		return oerr(err, PX_E_UNSUPPORTED, 0, 0,
			    "polygon faces (f) together with free-form "
			    "surfaces in a trimmed file are not supported");
	memset(&b, 0, sizeof(b));
	b.m = m;
	n = (size_t)m->n_entities + (size_t)m->n_loops + 1;
	b.faces = calloc(n, sizeof(*b.faces));
	b.fl = calloc(n, sizeof(*b.fl));
	b.edges = calloc(n, sizeof(*b.edges));
	b.face_ent = calloc(n, sizeof(int));
	b.edge_ent = calloc(n, sizeof(int));
	b.owner = calloc(n, sizeof(int));
	b.region = calloc(n, sizeof(*b.region));
	b.region_area = calloc(n, sizeof(double));
	rc = b.faces && b.fl && b.edges && b.face_ent && b.edge_ent && b.owner &&
	     b.region && b.region_area
		     ? px_arena_init_alloc(&b.arena, arena_need(m))
		     : PX_E_NOMEM;
	if (rc)
		rc = oerr(err, PX_E_NOMEM, 0, 0, "out of memory");
	else
		rc = describe(&b, scale, out, err);
	build_free(&b);
	return rc;
}

int px_model_from_obj_brep(const struct px_obj_model *m, const char *path,
			   double scale, struct px_model **out, char *msg,
			   size_t msg_cap)
{
	struct px_obj_error e;
	struct px_brep *b = NULL;
	struct px_brep_info info;
	int rc;

	if (msg && msg_cap)
		msg[0] = '\0';
	if (!m || !path || !out)
		return PX_E_INVAL;
	*out = NULL;
	memset(&e, 0, sizeof(e));
	snprintf(e.file, sizeof(e.file), "%s", path);
	rc = px_brep_from_obj(m, scale, &b, &e);
	if (!rc)
		rc = px_model_from_brep(b, out);
	if (rc) {
		px_obj_error_text(&e, path, rc, msg, msg_cap);
		return rc;
	}
	px_brep_get_info(px_model_brep(*out), &info);
	if (!info.closed && msg && msg_cap)
		snprintf(msg, msg_cap, "%s: open B-rep, distances are unsigned (%s)",
			 path, info.why);
	return PX_OK;
}

int px_model_load_obj_brep(const char *path, double scale, int *trimmed,
			   struct px_model **out, char *msg, size_t msg_cap)
{
	struct px_obj_model *m = NULL;
	struct px_obj_error e;
	char *buf = NULL;
	size_t len = 0;
	int rc;

	if (msg && msg_cap)
		msg[0] = '\0';
	if (trimmed)
		*trimmed = 0;
	if (!path || !out || !trimmed)
		return PX_E_INVAL;
	*out = NULL;
	rc = px_file_read(path, PX_FILE_MODEL_MAX_BYTES, PX_FILE_TEXT, "model",
			  &buf, &len, msg, msg_cap);
	if (rc || !px_obj_text_trimmed(buf, len)) {
		free(buf);
		if (msg && msg_cap)
			msg[0] = '\0';
		return PX_OK; /* the other loaders read (and report) it */
	}
	*trimmed = 1;
	memset(&e, 0, sizeof(e));
	rc = px_obj_load_mem(path, buf, len, &m, &e);
	free(buf);
	if (rc) {
		px_obj_error_text(&e, path, rc, msg, msg_cap);
		return rc;
	}
	rc = px_model_from_obj_brep(m, path, scale, out, msg, msg_cap);
	px_obj_free(m);
	return rc;
}
