/*
 * brep_stream.c - tracked streams on B-rep models (px_model.h): a
 * surface tracker (px_strack.h) over the faces' surfaces, untrimmed, and
 * the edges as its curves, which follows every critical point of each
 * surface but answers only with those inside the face's trimmed domain
 * (an in-domain test on the tracked extrema: the global minimum over a
 * face is such a point, or on a trimming edge, or at a vertex). Its
 * global query, where the tracked set cannot prove an answer, is the
 * distance core over the trimmed faces, as the model's own. The point
 * candidates (free vertices, loops collapsed to a point) and the
 * curve-on-surface edges (brep_cos.c, not tracked) are checked directly
 * every answer; when those edges alone bound the faces (the faces give
 * the core no sample of their own), every answer is the global query's. Answers go through the model's own signing
 * (px__brep_answer()), so they are the global query's, sign included.
 *
 * Closed-form faces (planes, cylinders, cones, spheres, tori that the
 * distance core's knowledge step recognised) are answered ahead of the
 * tracker, in closed form, as the global query answers them. Once an
 * answer lies inside such a face F, the stream holds a lower bound on
 * the distance from a point cq to every entity but F and F's own edges
 * (those that lie on F's shape: never nearer than F's closest point
 * when that point lies inside F's domain). Each entity's bound is its
 * box's distance, or where that is too small its shape's cheap bound
 * (px__dist_shape_lb2()) less the shape's proven deviation. An update
 * at p whose closed-form point on F lies inside the domain, off its
 * edges, and is nearer than the bound less |p - cq| (distances are
 * 1-Lipschitz) is the global answer; else the bounds are moved to p,
 * each made afresh only where the move left it too small, and where
 * that does not prove the answer either the tracker answers. A bound
 * that fails is tried again only after a wait that doubles with every
 * failure in a row (near edges and inside thin walls it rarely holds).
 * The jumped flag of these answers: another feature, or a closest point
 * that moved far more than the query point (across an axis or centre).
 *
 * When every face is closed-form and the cold switch is on, there is no
 * tracker: what the bound does not prove, the global query answers (the
 * tracker would follow each face's NURBS form, critical point by
 * critical point, where the global query answers it in closed form).
 */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "brep_internal.h"
#include "px_model.h"
#include "px_recog.h"
#include "strack_internal.h"

/* Longest wait (updates) between tries of a closed-form bound. */
#define CF_WAIT_MAX 64
/* A bound is sought that lasts this many steps like the last one. */
#define CF_AHEAD 2.0
/* The near entities of a full pass: within this many times that
 * margin again (cf_bound()). */
#define CF_NEAR 8.0

struct brep_stream {
	struct px_strack *st;
	int last;       /* last answer: -1 the tracker's, >= 0 a point
			 * candidate, -2 - k curve-on-surface edge k */
	/* the faces give the core no sample of their own: every answer is
	 * px__brep_closest_ws()'s in ws */
	int cos_global;
	int feature, index; /* the last answer's (feature -1: none yet) */
	uint64_t tracked, global, cold, jumps, hot;
	/* closed-form faces: per face its recognised shape (NULL: none)
	 * and its edges on it (own_first[f] .. own_first[f + 1] - 1 in
	 * own); per entity (edges, then faces) its box and shape; stamp
	 * marks a face's edges */
	const struct px_recog_shape **shape;
	const struct px_recog_shape **eshape; /* per entity: NULL none */
	px_aabb *box;
	/* cf_bound()'s two levels: the near entities of face nface (-1:
	 * none) and the far ones' least bound at nc */
	int *near, n_near, nface;
	px_vec3 nc;
	double far;
	int *own_first, *own;
	uint32_t *stamp, gen;
	double tol;     /* rounding allowance on the bound */
	/* the bound in force: face cf (-1: none), made at cq with value cl */
	int cf;
	px_vec3 cq;
	double cl;
	/* the last answer (a jump: its point moved far more than p) */
	px_vec3 lq, lpt;
	int wait, wait_len; /* updates before the next try of a bound */
	/* every face closed-form and the cold switch on: no tracker (st
	 * NULL); what the bound does not prove the global query answers
	 * in its own workspace */
	struct px_dist_ws *ws;
	/* the options' verification of the bound's answers (its own
	 * workspace ws then, also with a tracker) */
	int verify_every;
	uint64_t n_cf, verifications, disagreements;
};

/* (u, v) in the closed trimmed domain ctx (a px_trim). */
static int dom_in(const void *ctx, double u, double v)
{
	return px_trim_contains(ctx, u, v, NULL) > 0;
}

void px__brep_stream_free(void *state)
{
	struct brep_stream *s = state;
	if (!s)
		return;
	px_strack_free(s->st);
	px_dist_ws_free(s->ws);
	free(s->shape);
	free(s->eshape);
	free(s->near);
	free(s->box);
	free(s->own_first);
	free(s->own);
	free(s->stamp);
	free(s);
}

/* Edge e lies on shape sh to rounding (at 33 points along it). Setup. */
static int on_face(const struct px_recog_shape *sh, const struct brep_edge *e,
		   double size)
{
	int k;
	for (k = 0; k <= 32; k++) {
		struct px_recog_hit h;
		double t = e->t0 + (e->t1 - e->t0) * (k / 32.0);
		if (px_recog_closest(sh, px_nurbs_curve_point(&e->c, t), 0, &h) != PX_OK ||
		    !(h.dist <= 1e-12 * size))
			return 0;
	}
	return 1;
}

/* The closed-form data: shapes, boxes and each face's edges; *all set
 * to 1 when every face has a shape. Setup. */
static int cf_setup(struct brep_stream *s, const struct px_brep *b, int *all)
{
	int nf = b->n_faces, ne = b->n_edges, f, i, k, any = 0;
	s->cf = -1;
	s->wait_len = 1;
	s->tol = 1e-9 * b->size;
	s->shape = calloc((size_t)nf, sizeof(*s->shape));
	if (!s->shape)
		return PX_E_NOMEM;
	for (f = 0; b->dm->shape && f < nf; f++) {
		const struct px_recog_shape *sh = &b->dm->shape[ne + f];
		if (sh->is_surface && sh->kind >= PX_RECOG_PARALLELOGRAM &&
		    sh->kind <= PX_RECOG_TORUS) {
			s->shape[f] = sh;
			any++;
		}
	}
	*all = any == nf;
	if (!any)
		return PX_OK;
	s->box = malloc((size_t)(ne + nf) * sizeof(*s->box));
	s->eshape = calloc((size_t)(ne + nf), sizeof(*s->eshape));
	s->near = malloc((size_t)(ne + nf) * sizeof(*s->near));
	s->own_first = calloc((size_t)nf + 1, sizeof(int));
	s->own = malloc(((size_t)b->n_co + 1) * sizeof(int));
	s->stamp = calloc((size_t)ne + 1, sizeof(uint32_t));
	if (!s->box || !s->eshape || !s->near || !s->own_first || !s->own || !s->stamp)
		return PX_E_NOMEM;
	s->nface = -1;
	for (i = 0; i < ne + nf; i++) {
		const struct px_recog_shape *sh = &b->dm->shape[i];
		if (sh->kind != PX_RECOG_NONE && sh->kind != PX_RECOG_PLANE)
			s->eshape[i] = sh;
	}
	for (i = 0; i < ne; i++)
		s->box[i] = px_nurbs_curve_aabb(&b->edges[i].c);
	for (f = 0; f < nf; f++)
		s->box[ne + f] = px_nurbs_surf_aabb(&b->faces[f].surf);
	/* a face's edges that lie on its shape (to rounding: exact
	 * conversions of analytic geometry; an edge within a modelling
	 * tolerance of its face is bounded as any other entity) */
	for (i = 0; i < b->n_co; i++) {
		const struct brep_coedge *c = &b->co[i];
		if (c->edge >= 0 && s->shape[c->face] &&
		    on_face(s->shape[c->face], &b->edges[c->edge], b->size))
			s->own_first[c->face + 1]++;
	}
	for (f = 0; f < nf; f++)
		s->own_first[f + 1] += s->own_first[f];
	for (f = 0, k = 0; f < nf; f++)
		for (i = 0; i < b->n_co; i++)
			if (b->co[i].face == f && b->co[i].edge >= 0 && s->shape[f] &&
			    on_face(s->shape[f], &b->edges[b->co[i].edge], b->size))
				s->own[k++] = b->co[i].edge;
	return PX_OK;
}

int px__brep_stream_create(const void *impl, const struct px_model_stream_opts *o,
			   void **state)
{
	const struct px_brep *b = px__brep_of(impl);
	struct px_nurbs_curve *cv = NULL;
	struct px_nurbs_surf *sf = NULL;
	struct px_strack_opts so;
	struct brep_stream *s;
	int i, rc, all = 0;

	*state = NULL;
	if (b->n_faces == 0)
		return PX_E_UNSUPPORTED;
	s = calloc(1, sizeof(*s));
	if (!s)
		return PX_E_NOMEM;
	s->last = -1;
	s->feature = -1;
	s->cf = -1;
	s->verify_every = o->verify_every;
	if (b->cos) {
		struct px_dist_info di;
		px_dist_model_info(b->dm, &di);
		if (di.n_samples == 0) {
			s->cos_global = 1;
			rc = px_dist_ws_create(b->dm, &s->ws);
			goto out;
		}
	}
	rc = cf_setup(s, b, &all);
	if (rc == PX_OK && ((all && o->cold_switch) || (s->box && o->verify_every > 0)))
		rc = px_dist_ws_create(b->dm, &s->ws);
	if (rc == PX_OK && all && o->cold_switch)
		goto out; /* the tracker would follow every critical point of
			   * each face's NURBS form, while the global query
			   * answers the faces in closed form */
	sf = malloc((size_t)b->n_faces * sizeof(*sf));
	if (b->n_edges)
		cv = malloc((size_t)b->n_edges * sizeof(*cv));
	if (rc == PX_OK && (!sf || (b->n_edges && !cv)))
		rc = PX_E_NOMEM;
	if (rc != PX_OK)
		goto out;
	for (i = 0; i < b->n_faces; i++)
		sf[i] = b->faces[i].surf;
	for (i = 0; i < b->n_edges; i++)
		cv[i] = b->edges[i].c;
	px_strack_opts_default(&so);
	so.verify_every = o->verify_every;
	so.max_solves = o->max_solves;
	so.cold_switch = o->cold_switch;
	/* the entities as the model's: edges, then faces */
	rc = px__strack_create_trimmed(cv, b->n_edges, sf, b->n_faces, b->dtrim,
				       dom_in, &so, &s->st);
out:
	free(sf);
	free(cv);
	if (rc == PX_OK) {
		*state = s;
		s = NULL;
	}
	px__brep_stream_free(s);
	return rc;
}

/* The point candidate nearer to p than dist (-1 when none). */
static int point_nearer(const struct px_brep *b, px_vec3 p, double dist)
{
	double best = dist * dist;
	int i, bi = -1;
	for (i = 0; i < b->n_pts; i++) {
		double d2 = px_v3_dist2(b->pts[i].p, p);
		if (d2 < best) {
			best = d2;
			bi = i;
		}
	}
	return bi;
}

/* Distance from p to box a. */
static inline double gap(double lo, double hi, double x)
{
	return x < lo ? lo - x : (x > hi ? x - hi : 0.0);
}

/* A lower bound on the distance from entity i to p: its box's, and
 * where that is below need and the entity has a shape, the distance to
 * the shape's cheap bound (px__dist_shape_lb2(): no angles; a segment's
 * own distance) less the shape's proven deviation from the entity (a
 * face's shape is its untrimmed surface: never farther than the face). */
static inline double ent_bound(const struct brep_stream *s, int i, px_vec3 p,
			       double need)
{
	const px_aabb *a = &s->box[i];
	const struct px_recog_shape *sh = s->eshape[i];
	double gx = gap(a->min.x, a->max.x, p.x), gy = gap(a->min.y, a->max.y, p.y);
	double gz = gap(a->min.z, a->max.z, p.z), l = gx * gx + gy * gy + gz * gz, c;
	if (l >= need * need || !sh)
		return sqrt(l);
	if (sh->kind == PX_RECOG_SEGMENT) {
		px_vec3 w = px_v3_sub(p, sh->seg.p0);
		c = px_v3_dot(w, sh->seg.dir);
		c = c < 0.0 ? 0.0 : (c > sh->seg.len ? sh->seg.len : c);
		c = px_v3_dist(w, px_v3_scale(sh->seg.dir, c));
	} else {
		c = sqrt(px__dist_shape_lb2(sh, p));
	}
	/* (the relative margin: rounding of the bound's own arithmetic) */
	c = c * (1.0 - 1e-9) - sh->hausdorff;
	l = sqrt(l);
	return c > l ? c : l;
}

/*
 * A lower bound on the distance from p to every entity but face f and
 * its edges (less the rounding allowance), or -INFINITY as soon as one
 * is seen nearer than must (the least bound that proves the answer).
 * Two levels, so that a bound made afresh at every update (long steps)
 * costs a few entities, not all: a full pass over all of them at a
 * point nc keeps those within need (the near ones, each made as
 * ent_bound()) and the least bound of the others (far); later, for the
 * same face, the near ones are made afresh at p and the others are
 * bounded by far - |p - nc| (distances are 1-Lipschitz), until that
 * falls below must and a full pass is made again. The near entity that
 * last failed is tried first (where the point moves slowly it fails
 * again, and the update goes to the global query at once).
 */
static double cf_full(struct brep_stream *s, const struct px_brep *b, int f,
		      px_vec3 p, double need, double must)
{
	int ne = b->n_edges, n = ne + b->n_faces, i;
	double best = INFINITY, far = INFINITY;
	s->nface = -1;
	s->n_near = 0;
	if (++s->gen == 0) {
		memset(s->stamp, 0, (size_t)ne * sizeof(uint32_t));
		s->gen = 1;
	}
	for (i = s->own_first[f]; i < s->own_first[f + 1]; i++)
		s->stamp[s->own[i]] = s->gen;
	for (i = 0; i < n; i++) {
		double l;
		if (i == ne + f || (i < ne && s->stamp[i] == s->gen))
			continue;
		l = ent_bound(s, i, p, need);
		if (l < must)
			return -INFINITY;
		if (l < need) {
			s->near[s->n_near++] = i;
			best = l < best ? l : best;
		} else {
			far = l < far ? l : far;
		}
	}
	s->nface = f;
	s->nc = p;
	s->far = far;
	return (best < far ? best : far) - s->tol;
}

static double cf_bound(struct brep_stream *s, const struct px_brep *b, int f,
		       px_vec3 p, double need, double must)
{
	double best;
	int k;
	must += s->tol;
	best = s->far - px_v3_dist(p, s->nc);
	if (s->nface != f || !(best >= must))
		return cf_full(s, b, f, p, need + CF_NEAR * (need - must), must);
	for (k = 0; k < s->n_near; k++) {
		int i = s->near[k];
		double l = ent_bound(s, i, p, INFINITY);
		if (l < must) {
			/* first the next time */
			s->near[k] = s->near[0];
			s->near[0] = i;
			return -INFINITY;
		}
		best = l < best ? l : best;
	}
	return best - s->tol;
}

/* (u, v) of shape sh on the edge of its parameter domain (as the
 * distance core's closed-form answers: the nearest point of a trimmed
 * part of it is then on the part's boundary). */
static int cf_on_edge(const struct px_recog_shape *sh, double u, double v)
{
	double eu = 1e-13 * (sh->dom[1] - sh->dom[0]);
	double ev = 1e-13 * (sh->dom[3] - sh->dom[2]);
	return u <= sh->dom[0] + eu || u >= sh->dom[1] - eu ||
	       v <= sh->dom[2] + ev || v >= sh->dom[3] - ev;
}

/* A bound failed to prove an answer: the next try waits (doubling). */
static void cf_failed(struct brep_stream *s)
{
	s->wait = s->wait_len;
	s->wait_len = s->wait_len < CF_WAIT_MAX ? 2 * s->wait_len : CF_WAIT_MAX;
}

/* The closed-form answer of the bound in force at p into *d: 1 when it
 * is proven the global one (the bound made afresh at p where the old one
 * does not reach), else 0 and the bound is dropped. */
static int cf_update(struct brep_stream *s, const struct px_brep *b, px_vec3 p,
		     struct px_dist_result *d)
{
	int f = s->cf;
	const struct px_recog_shape *sh = s->shape[f];
	const struct px_trim *tr = b->faces[f].trim;
	struct px_recog_hit h;
	double lim = s->cl - px_v3_dist(p, s->cq);

	s->cf = -1;
	if (px_recog_closest(sh, p, PX_RECOG_WANT_PARAMS, &h) != PX_OK || h.tie ||
	    cf_on_edge(sh, h.u, h.v) || (tr && px_trim_contains(tr, h.u, h.v, NULL) <= 0))
		return 0;
	if (!(h.dist <= lim)) {
		double l = cf_bound(s, b, f, p, h.dist + CF_AHEAD * px_v3_dist(p, s->lq) + s->tol,
				    h.dist);
		if (!(h.dist <= l)) {
			cf_failed(s);
			return 0;
		}
		s->cq = p;
		s->cl = l;
	}
	s->cf = f;
	d->dist = h.dist;
	d->point = h.point;
	d->dir = h.dir;
	d->u = h.u;
	d->v = h.v;
	d->entity = b->n_edges + f;
	d->kind = PX_DIST_SURFACE;
	return 1;
}

/* After an answer d at p that the bound did not give: a bound for its
 * face when it is a closed-form one and d an interior point of it that
 * the bound proves (tried at most every wait updates). */
static void cf_start(struct brep_stream *s, const struct px_brep *b, px_vec3 p,
		     const struct px_dist_result *d)
{
	int f = d->entity - b->n_edges;
	double l;
	if (s->wait > 0) {
		s->wait--;
		return;
	}
	if (d->kind != PX_DIST_SURFACE || f < 0 || !s->shape[f] ||
	    cf_on_edge(s->shape[f], d->u, d->v))
		return;
	l = cf_bound(s, b, f, p, d->dist + CF_AHEAD * px_v3_dist(p, s->lq) + s->tol,
		     d->dist);
	if (d->dist <= l) {
		s->cf = f;
		s->cq = p;
		s->cl = l;
		s->wait_len = 1;
		return;
	}
	cf_failed(s);
}

/* The options' verification of the bound's answer d at p: a global
 * answer nearer by more than the rounding allowance is counted, replaces
 * d and drops the bound. */
static void verify(struct brep_stream *s, const struct px_brep *b, px_vec3 p,
		   struct px_dist_result *d)
{
	struct px_dist_result g;
	if (px_dist_query_ws(b->dm, s->ws, p, &g) != PX_OK)
		return;
	s->verifications++;
	if (!(d->dist > g.dist + 1e-9 * (b->size + g.dist)))
		return;
	s->disagreements++;
	s->cf = -1;
	*d = g;
}

/* The tracker's answer at p into *d (and the note). */
static int tracked(struct brep_stream *s, const struct px_brep *b, px_vec3 p,
		   struct px_dist_result *d, struct px_model_stream_note *note)
{
	struct px_strack_result sr;
	int rc = px_strack_update(s->st, p, &sr);
	if (rc != PX_OK)
		return rc;
	note->source = sr.source;
	note->n_crit = sr.n_crit;
	d->dist = sr.dist;
	d->point = sr.point;
	d->dir = sr.dir;
	d->u = sr.u;
	d->v = sr.v;
	d->entity = sr.entity;
	d->kind = sr.entity < b->n_edges ? PX_DIST_CURVE : PX_DIST_SURFACE;
	note->jumped = s->last >= 0 || sr.jumped;
	/* the bound only from an interior point of the face */
	if (s->box && sr.feature != PX_STRACK_EDGE)
		cf_start(s, b, p, d);
	return PX_OK;
}

/* The closest point moved far more than the query point since the last
 * answer (on a closed-form face or an edge it moves by about the query's
 * step, far more only across an axis, a centre or to another branch). */
static int moved_far(const struct brep_stream *s, px_vec3 p, px_vec3 point)
{
	return px_v3_dist(point, s->lpt) > 4.0 * px_v3_dist(p, s->lq) + s->tol;
}

int px__brep_stream_query(const void *impl, void *state,
			  const struct px_model_query *q, struct px_model_result *r,
			  struct px_model_stream_note *note)
{
	const struct px_brep *b = px__brep_of(impl);
	struct brep_stream *s = state;
	struct px_dist_result d;
	int rc, pi;

	memset(&d, 0, sizeof(d));
	if (s->cos_global) {
		rc = px__brep_closest_ws(b, s->ws, q->p, &d);
		if (rc != PX_OK)
			return rc;
		note->source = PX_TRACK_GLOBAL;
		note->n_crit = -1;
		note->jumped = s->last != -1 || moved_far(s, q->p, d.point);
	} else if (s->cf >= 0 && cf_update(s, b, q->p, &d)) {
		note->source = PX_TRACK_TRACKED;
		note->n_crit = 1;
		note->jumped = s->last >= 0 || s->feature != PX_FEATURE_SURFACE ||
			       s->index != s->cf || moved_far(s, q->p, d.point);
		s->hot++;
		if (s->verify_every > 0 && ++s->n_cf % (uint64_t)s->verify_every == 0)
			verify(s, b, q->p, &d);
	} else if (!s->st) {
		rc = px_dist_query_ws(b->dm, s->ws, q->p, &d);
		if (rc != PX_OK)
			return rc;
		note->source = PX_TRACK_COLD;
		note->n_crit = -1;
		note->jumped = s->last >= 0 || moved_far(s, q->p, d.point);
		cf_start(s, b, q->p, &d);
	} else {
		rc = tracked(s, b, q->p, &d, note);
		if (rc != PX_OK)
			return rc;
	}
	pi = point_nearer(b, q->p, d.dist);
	if (pi >= 0) {
		/* the same fields as the global query's point answer */
		px_vec3 v = px_v3_sub(q->p, b->pts[pi].p);
		memset(&d, 0, sizeof(d));
		d.dist = px_v3_norm(v);
		d.point = b->pts[pi].p;
		d.dir = d.dist > 0.0 ? px_v3_scale(v, 1.0 / d.dist) : px_v3(0, 0, 0);
		d.entity = pi;
		d.kind = BREP_POINT;
		note->jumped = s->last != pi;
		s->cf = -1;
	}
	if (!s->cos_global) {
		d.piece = -1;
		d.certified = 1;
	}
	/* curve-on-surface edges are not tracked: solved every answer */
	if (b->cos && px__brep_cos_closest(b->cos, q->p, &d, NULL)) {
		pi = -2 - d.entity;
		note->jumped = s->last != pi;
		s->cf = -1;
	}
	s->lq = q->p;
	s->lpt = d.point;
	s->last = pi;
	rc = px__brep_answer(b, q, &d, r);
	/* a face, an edge and its end vertex are features of their own
	 * (the tracker's curve answer may run into an edge's end) */
	if (rc == 1) {
		note->jumped |= r->feature != s->feature || r->index != s->index;
		s->feature = r->feature;
		s->index = r->index;
	}
	if (note->source == PX_TRACK_COLD)
		s->cold++;
	else if (note->source == PX_TRACK_GLOBAL || note->source == PX_TRACK_REINIT)
		s->global++;
	else
		s->tracked++;
	s->jumps += note->jumped != 0;
	return rc;
}

void px__brep_stream_stats(const void *state, struct px_model_stream_stats *st)
{
	const struct brep_stream *s = state;
	struct px_strack_stats ss;
	st->tracked = s->tracked;
	st->global = s->global;
	st->cold = s->cold;
	st->jumps = s->jumps;
	px_strack_get_stats(s->st, &ss);
	st->hot = ss.hot + s->hot;
	st->reinits = ss.reinits;
	st->verifications = ss.verifications + s->verifications;
	st->disagreements = ss.disagreements + s->disagreements;
}
