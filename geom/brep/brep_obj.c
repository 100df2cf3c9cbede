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
};

static void build_free(struct build *b)
{
	px_arena_fini(&b->arena);
	free(b->faces);
	free(b->fl);
	free(b->edges);
	free(b->face_ent);
	free(b->edge_ent);
}

/* Arena bytes: the sub-curves of the loops and the boundary lines. */
static size_t arena_need(const struct px_obj_model *m)
{
	size_t n = 4096;
	int i;
	for (i = 0; i < m->n_trim_curves; i++)
		n += px_nurbs_curve_extract_bytes(&m->curv2[m->trim_curves[i].curv2].curve) +
		     2 * PX_ARENA_ALIGN;
	for (i = 0; i < m->n_entities; i++)
		n += 4 * (px_nurbs_curve_bytes(1, 2) + 2 * PX_ARENA_ALIGN) +
		     4 * sizeof(struct px_nurbs_curve) + PX_ARENA_ALIGN;
	n += (size_t)(m->n_entities + m->n_loops + 1) *
	     (sizeof(struct px_trim_loop) + 2 * sizeof(int) + PX_ARENA_ALIGN) +
	     (size_t)m->n_trim_curves * (sizeof(struct px_nurbs_curve) + 1 + PX_ARENA_ALIGN);
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

/* The loops of surface entity ent: outer first, then the holes. */
static int face_loops(struct build *b, int ent, struct face_loops *fl,
		      const struct px_nurbs_surf *s)
{
	const struct px_obj_model *m = b->m;
	int i, n = 0, outer = -1, k, rc, pass;

	for (i = 0; i < m->n_loops; i++)
		if (m->loops[i].entity == ent) {
			n++;
			if (!m->loops[i].hole)
				outer = i;
		}
	memset(fl, 0, sizeof(*fl));
	if (n == 0)
		return PX_OK;
	if (outer < 0)
		n++;
	fl->loops = px_arena_alloc(&b->arena, (size_t)n * sizeof(*fl->loops), 8);
	fl->line = px_arena_alloc(&b->arena, (size_t)n * sizeof(int), 8);
	fl->col = px_arena_alloc(&b->arena, (size_t)n * sizeof(int), 8);
	if (!fl->loops || !fl->line || !fl->col)
		return PX_E_NOMEM;
	if (outer < 0) {
		rc = domain_loop(b, s, &fl->loops[0]);
		if (rc)
			return rc;
		fl->line[0] = fl->col[0] = 0;
		fl->n = 1;
	}
	for (pass = 0; pass < 2; pass++)
		for (i = 0; i < m->n_loops; i++) {
			const struct px_obj_loop *ol = &m->loops[i];
			struct px_trim_loop *l;
			struct px_nurbs_curve *cv;
			unsigned char *rev;
			int at;
			if (ol->entity != ent || ol->hole != pass)
				continue;
			at = fl->n++;
			l = &fl->loops[at];
			cv = px_arena_alloc(&b->arena, (size_t)ol->n * sizeof(*cv), 8);
			rev = px_arena_alloc(&b->arena, (size_t)ol->n, 1);
			if (!cv || !rev)
				return PX_E_NOMEM;
			for (k = 0; k < ol->n; k++) {
				rc = loop_curve(b, &m->trim_curves[ol->first + k], &cv[k],
						&rev[k]);
				if (rc)
					return rc;
			}
			l->curves = cv;
			l->n_curves = ol->n;
			l->reversed = rev;
			fl->line[at] = ol->line;
			fl->col[at] = ol->column;
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
			struct px_brep_face_desc *f = &b->faces[b->n_faces];
			struct face_loops *fl = &b->fl[b->n_faces];
			rc = face_loops(b, i, fl, &e->surf);
			if (rc)
				return oerr(err, rc, e->line, 1,
					    "surface of line %d: cannot build its "
					    "loops: %s",
					    e->line, px_strerror(rc));
			memset(f, 0, sizeof(*f));
			f->surf = e->surf;
			f->loops = fl->loops;
			f->n_loops = fl->n;
			f->shell = 0;
			f->id = e->line;
			b->face_ent[b->n_faces++] = i;
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
	n = (size_t)m->n_entities + 1;
	b.faces = calloc(n, sizeof(*b.faces));
	b.fl = calloc(n, sizeof(*b.fl));
	b.edges = calloc(n, sizeof(*b.edges));
	b.face_ent = calloc(n, sizeof(int));
	b.edge_ent = calloc(n, sizeof(int));
	rc = b.faces && b.fl && b.edges && b.face_ent && b.edge_ent
		     ? px_arena_init_alloc(&b.arena, arena_need(m))
		     : PX_E_NOMEM;
	if (rc)
		rc = oerr(err, PX_E_NOMEM, 0, 0, "out of memory");
	else
		rc = describe(&b, scale, out, err);
	build_free(&b);
	return rc;
}

int px_model_load_obj_brep(const char *path, double scale, int *trimmed,
			   struct px_model **out, char *msg, size_t msg_cap)
{
	struct px_obj_model *m = NULL;
	struct px_obj_error e;
	struct px_brep *b = NULL;
	struct px_brep_info info;
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
	if (!rc)
		rc = px_brep_from_obj(m, scale, &b, &e);
	px_obj_free(m);
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
