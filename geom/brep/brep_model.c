/*
 * brep_model.c - the B-rep's queries: the distance core's certified
 * answer over trimmed faces and edges, the point candidates, the sign
 * (brep_sign.c), and the px_model behind them.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "brep_internal.h"
#include "px_model.h"

/* The core's answer, the point candidates, the curve-on-surface edges
 * (px__brep_closest() and px__brep_closest_ws(), one body). */
static inline __attribute__((always_inline)) int
closest(const struct px_brep *b, struct px_dist_ws *ws, px_vec3 p,
	struct px_dist_result *d)
{
	double best, edge_gap;
	int i, bi = -1, rc;

	if (b->cos) {
		/* a point of the curve-on-surface edges bounds the core's
		 * query (its faces may give no sample of their own) */
		rc = px__dist_query_below(b->dm, ws, p, px__brep_cos_bound2(b->cos, p), d);
		if (rc == 1) {
			d->kind = BREP_COS;
			d->entity = -1;
		}
	} else
		rc = px_dist_query_ws(b->dm, ws, p, d);
	if (rc < 0)
		return rc;
	best = d->dist * d->dist;
	for (i = 0; i < b->n_pts; i++) {
		double d2 = px_v3_dist2(b->pts[i].p, p);
		if (d2 < best) {
			best = d2;
			bi = i;
		}
	}
	if (bi >= 0) {
		px_vec3 v = px_v3_sub(p, b->pts[bi].p);
		d->dist = sqrt(best);
		d->point = b->pts[bi].p;
		d->u = d->v = 0.0;
		d->entity = bi;
		d->kind = BREP_POINT;
		d->piece = -1;
		d->dir = d->dist > 0.0 ? px_v3_scale(v, 1.0 / d->dist) : px_v3(0, 0, 0);
	}
	if (b->cos && px__brep_cos_closest(b->cos, p, d, &edge_gap) && !d->certified) {
		/* the core's proof stopped short above the edge: once more
		 * below the edge's distance, which prunes what it could not
		 * settle (as a composed edge of the core would) */
		struct px_dist_result e;
		rc = px__dist_query_below(b->dm, ws, p,
					  d->dist * d->dist * (1.0 + 1e-12) + 1e-300, &e);
		if (rc < 0)
			return rc;
		if (rc == PX_OK)
			*d = e;
		else
			d->gap = e.certified ? 0.0 : fmax(e.gap - (e.dist - d->dist), 0.0);
		d->certified = e.certified && edge_gap < 0.0;
		d->gap = fmax(d->gap, edge_gap);
	}
	return PX_OK;
}

int px__brep_closest(const struct px_brep *b, int k, px_vec3 p,
		     struct px_dist_result *d)
{
	return closest(b, b->ws[k], p, d);
}

int px__brep_closest_ws(const struct px_brep *b, struct px_dist_ws *ws, px_vec3 p,
			struct px_dist_result *d)
{
	return closest(b, ws, p, d);
}

static int ws_take(struct px_brep *b)
{
	int k;
	for (k = 0; k < BREP_WS; k++)
		if (!atomic_flag_test_and_set_explicit(&b->busy[k], memory_order_acquire))
			break;
	return k;
}

static void ws_give(struct px_brep *b, int k)
{
	atomic_flag_clear_explicit(&b->busy[k], memory_order_release);
}

/* Feature, index and (u, v) of unsigned answer d. */
static void answer_feature(const struct px_brep *b,
			   const struct px_dist_result *d,
			   struct px_model_result *r)
{
	r->u = d->u;
	r->v = d->v;
	r->sub = d->piece;
	if (d->kind == PX_DIST_SURFACE) {
		r->feature = PX_FEATURE_SURFACE;
		r->index = d->entity - b->n_edges;
	} else if (d->kind == PX_DIST_CURVE) {
		const struct brep_edge *e = &b->edges[d->entity];
		r->feature = PX_FEATURE_CURVE;
		r->index = d->entity;
		r->v = 0.0;
		if (e->v0 >= 0 && d->u <= e->t0) {
			r->feature = PX_FEATURE_VERTEX;
			r->index = e->v0;
		} else if (e->v1 >= 0 && d->u >= e->t1) {
			r->feature = PX_FEATURE_VERTEX;
			r->index = e->v1;
		}
	} else if (d->kind == BREP_COS) {
		/* curve-on-surface edges are numbered after the edges */
		r->feature = PX_FEATURE_CURVE;
		r->index = b->n_edges + d->entity;
		r->v = 0.0;
	} else {
		r->feature = PX_FEATURE_VERTEX;
		r->index = b->pts[d->entity].vertex;
		r->sub = -1;
	}
}

static int brep_closest(const void *impl, const struct px_model_query *q,
			struct px_model_result *r)
{
	/* Taking a workspace is the one write a query makes. */
	struct px_brep *b = (struct px_brep *)(uintptr_t)impl;
	struct px_dist_result d;
	int k, rc;

	k = ws_take(b);
	if (k == BREP_WS)
		return PX_E_BUSY;
	rc = px__brep_closest(b, k, q->p, &d);
	ws_give(b, k);
	if (rc != PX_OK)
		return rc;
	return px__brep_answer(b, q, &d, r);
}

int px__brep_answer(const struct px_brep *b, const struct px_model_query *q,
		    const struct px_dist_result *dp, struct px_model_result *r)
{
	struct px_dist_result d = *dp;
	int sg = 1, want_sign = b->closed && !(q->flags & PX_QUERY_UNSIGNED);

	if (d.dist > q->max_dist)
		return 0;
	/* Within rounding of the surface the side is noise: outside. */
	if (want_sign && d.dist > b->on_tol)
		sg = px__brep_sign(b, q->p, &d);
	memset(r, 0, sizeof(*r));
	r->distance = d.dist;
	r->point = d.point;
	r->direction = d.dir;
	answer_feature(b, &d, r);
	if (d.dist == 0.0) {
		px_vec3 nn = px_v3(0, 0, 0);
		if (want_sign && d.kind == PX_DIST_SURFACE)
			nn = px__brep_face_normal(b, r->index, d.u, d.v);
		r->direction = px_v3_norm(nn) > 0.5 ? nn : px_v3(0.0, 0.0, 1.0);
	} else if (sg < 0) {
		r->distance = -d.dist;
		r->direction = px_v3_scale(d.dir, -1.0);
		r->inside = 1;
	}
	r->is_signed = want_sign;
	r->iterations = d.iters;
	r->certified = d.certified;
	r->gap = d.gap;
	return 1;
}

static px_aabb brep_aabb(const void *impl)
{
	return ((const struct px_brep *)impl)->box;
}

static size_t brep_bytes(const void *impl)
{
	return ((const struct px_brep *)impl)->bytes;
}

static void brep_free_impl(void *impl)
{
	px_brep_free(impl);
}

/* The model's table is one per B-rep, so that px_model_name() gives the
 * part's name; this wrapper owns it with the B-rep. */
struct brep_holder {
	struct px_model_ops ops;
	struct px_brep *b;
};

static int holder_closest(const void *impl, const struct px_model_query *q,
			  struct px_model_result *r)
{
	return brep_closest(((const struct brep_holder *)impl)->b, q, r);
}

static px_aabb holder_aabb(const void *impl)
{
	return brep_aabb(((const struct brep_holder *)impl)->b);
}

static size_t holder_bytes(const void *impl)
{
	return brep_bytes(((const struct brep_holder *)impl)->b) +
	       sizeof(struct brep_holder);
}

static void holder_free(void *impl)
{
	struct brep_holder *h = impl;
	if (!h)
		return;
	brep_free_impl(h->b);
	free(h);
}

int px_model_from_brep(struct px_brep *b, struct px_model **out)
{
	struct brep_holder *h;
	if (!out) {
		px_brep_free(b);
		return PX_E_INVAL;
	}
	*out = NULL;
	if (!b)
		return PX_E_INVAL;
	h = calloc(1, sizeof(*h));
	if (!h) {
		px_brep_free(b);
		return PX_E_NOMEM;
	}
	h->b = b;
	h->ops.name = b->name;
	h->ops.kind = PX_MODEL_BREP;
	h->ops.closest = holder_closest;
	h->ops.aabb = holder_aabb;
	h->ops.memory_bytes = holder_bytes;
	h->ops.free = holder_free;
	h->ops.stream_create = px__brep_stream_create;
	h->ops.stream_query = px__brep_stream_query;
	h->ops.stream_stats = px__brep_stream_stats;
	h->ops.stream_free = px__brep_stream_free;
	return px_model_create(&h->ops, h,
			       PX_MODEL_CAP_EXACT | (b->closed ? PX_MODEL_CAP_SIGNED : 0u),
			       out);
}

struct px_brep *px__brep_of(const void *impl)
{
	return ((const struct brep_holder *)impl)->b;
}

const struct px_brep *px_model_brep(const struct px_model *m)
{
	const struct px_model_ops *ops = px_model_get_ops(m);
	if (!ops || ops->closest != holder_closest)
		return NULL;
	return ((const struct brep_holder *)px_model_impl(m))->b;
}

int px_brep_get_info(const struct px_brep *b, struct px_brep_info *info)
{
	if (!b || !info)
		return PX_E_INVAL;
	memset(info, 0, sizeof(*info));
	info->n_faces = b->n_faces;
	info->n_edges = b->n_edges + (b->cos ? b->cos->n_cos : 0);
	info->n_vertices = b->n_vertices;
	info->n_shells = b->n_shells;
	info->n_solids = b->n_solids;
	info->n_trimmed = b->n_trimmed;
	info->n_point_cands = b->n_pts;
	info->closed = b->closed;
	memcpy(info->why, b->why, sizeof(info->why));
	info->bounds = b->box;
	info->bytes = b->bytes;
	return PX_OK;
}
