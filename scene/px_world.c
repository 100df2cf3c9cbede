/*
 * Scene: posed models, nearest surface with a box broad phase, and the
 * adapter to the control module's query interface.
 */
#include "px_world.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "px_control.h"

struct px_world_entry {
	struct px_model *m;
	px_aabb local;   /* model-frame box, cached at add */
	int bounded;     /* every bound finite */
	int is_signed;   /* PX_MODEL_CAP_SIGNED */
	char name[PX_WORLD_NAME_LEN];
};

struct px_world {
	size_t cap, n;
	bool track_on;
	struct px_model_stream_opts track_opts;
	struct px_world_entry e[];
};

int px_world_create(size_t capacity, struct px_world **out)
{
	struct px_world *s;
	if (out)
		*out = NULL;
	if (!out || capacity == 0 || capacity > PX_WORLD_MAX_MODELS)
		return PX_E_INVAL;
	s = calloc(1, sizeof(*s) + capacity * sizeof(s->e[0]));
	if (!s)
		return PX_E_NOMEM;
	s->cap = capacity;
	s->track_on = true;
	px_model_stream_opts_default(&s->track_opts);
	*out = s;
	return PX_OK;
}

void px_world_free(struct px_world *s)
{
	size_t i;
	if (!s)
		return;
	for (i = 0; i < s->n; i++)
		px_model_free(s->e[i].m);
	free(s);
}

int px_world_add(struct px_world *s, struct px_model *m, const char *name)
{
	struct px_world_entry *e;
	if (!s || !m) {
		px_model_free(m);
		return PX_E_INVAL;
	}
	if (s->n >= s->cap) {
		px_model_free(m);
		return PX_E_NOSPC;
	}
	{
		/* the scene's box bounds square distances to the box: a box
		 * beyond the models' reach would make them infinite and the
		 * model never nearest */
		px_aabb b = px_model_local_aabb(m);
		double reach = px_aabb_is_empty(&b) ? 0.0
			: fmax(fmax(fabs(b.min.x), fabs(b.max.x)),
			       fmax(fmax(fabs(b.min.y), fabs(b.max.y)),
				    fmax(fabs(b.min.z), fabs(b.max.z))));
		if (isfinite(reach) && reach > PX_MODEL_MAX_COORD) {
			px_model_free(m);
			return PX_E_RANGE;
		}
	}
	e = &s->e[s->n];
	memset(e, 0, sizeof(*e));
	e->m = m;
	e->local = px_model_local_aabb(m);
	e->bounded = !px_aabb_is_empty(&e->local) &&
		     px_v3_isfinite(e->local.min) && px_v3_isfinite(e->local.max);
	e->is_signed = (px_model_caps(m) & PX_MODEL_CAP_SIGNED) != 0;
	if (name)
		snprintf(e->name, sizeof(e->name), "%s", name);
	return (int)s->n++;
}

size_t px_world_count(const struct px_world *s)
{
	return s ? s->n : 0;
}

struct px_model *px_world_model(const struct px_world *s, size_t i)
{
	return s && i < s->n ? s->e[i].m : NULL;
}

const char *px_world_name(const struct px_world *s, size_t i)
{
	return s && i < s->n ? s->e[i].name : "";
}

int px_world_set_pose(struct px_world *s, size_t i, px_pose pose)
{
	if (!s || i >= s->n)
		return PX_E_INVAL;
	return px_model_set_pose(s->e[i].m, pose);
}

/* Lower bound of model e's signed distance to p. The box distance is
 * shrunk by a relative 1e-9 so that rounding in the box transform never
 * makes it exceed the true distance. */
static double lower_bound(const struct px_world_entry *e, px_vec3 p)
{
	px_obb b;
	double d;
	if (!e->bounded)
		return e->is_signed ? -INFINITY : 0.0;
	b = px_obb_from_aabb(&e->local, px_model_pose(e->m));
	d = sqrt(px_obb_dist2(&b, p));
	if (!(d > 0))
		return e->is_signed ? -INFINITY : 0.0;
	return d * (1 - 1e-9) - 1e-12;
}

/* The distance the scene reports for a model's answer: never farther
 * from the surface than the truth (uncertified answers lose their gap). */
static double reported(const struct px_model_result *r)
{
	double d = r->distance;
	if (!r->certified && r->gap > 0)
		d = d >= 0 ? fmax(d - r->gap, 0.0) : fmin(d + r->gap, 0.0);
	return d;
}

/* An answer that names no model (before a search, or refused). */
static void no_hit(struct px_world_hit *out)
{
	memset(out, 0, sizeof(*out));
	out->model = -1;
	out->distance_m = INFINITY;
}

struct px_world_tracking {
	const struct px_world *w;
	struct px_world_hints hints;
	size_t n;      /* models when made: streams[0..n) */
	int last;      /* model of the last answer, -1 none */
	struct px_model_stream *st[];
};

static int nearest(const struct px_world *s, px_vec3 p, double max_distance_m,
		   struct px_world_hints *hints, struct px_world_tracking *trk,
		   struct px_world_hit *out)
{
	double lb[PX_WORLD_MAX_MODELS];
	unsigned char done[PX_WORLD_MAX_MODELS];
	double best = INFINITY;
	size_t i, n;
	int queried = 0, jumped = 0;
	if (!out)
		return PX_E_INVAL;
	no_hit(out);
	out->r.distance = INFINITY;
	out->r.index = -1;
	if (!s || !(max_distance_m >= 0))
		return PX_E_INVAL;
	if (!px_v3_isfinite(p))
		return PX_E_NAN;
	n = s->n;
	for (i = 0; i < n; i++) {
		lb[i] = lower_bound(&s->e[i], p);
		done[i] = lb[i] > max_distance_m;
	}
	/* Best-first over the bounds; at most n rounds of n. */
	for (;;) {
		size_t k = n;
		double lo = INFINITY, range;
		struct px_model_result r;
		int rc;
		for (i = 0; i < n; i++)
			if (!done[i] && (k == n || lb[i] < lo)) {
				k = i;
				lo = lb[i];
			}
		if (k == n || lo >= best)
			break;
		done[k] = 1;
		/* |d| may be bounded by the best so far only when d cannot be
		 * negative here (unsigned model or point outside its box). */
		range = max_distance_m;
		if ((!s->e[k].is_signed || lo > 0) && best >= 0 && best < range)
			range = best;
		if (trk && k < trk->n && trk->st[k]) {
			struct px_model_stream_note note;
			rc = px_model_stream_query(trk->st[k], p, range, 0u, &r,
						   &note);
			if (rc == 1 && note.jumped && (int)k == trk->last)
				jumped = 1;
		} else {
			rc = px_model_query_ex(s->e[k].m, p, range,
					       hints ? hints->index[k] : -1,
					       hints ? PX_QUERY_COHERENT : 0u, &r);
		}
		queried++;
		if (rc < 0) {
			out->models_queried = queried;
			return rc;
		}
		if (hints && rc == 1)
			hints->index[k] = r.index;
		if (rc == 1) {
			double d = reported(&r);
			if (d < best && fabs(d) <= max_distance_m) {
				best = d;
				out->model = (int)k;
				out->r = r;
				out->distance_m = d;
			}
		}
	}
	out->models_queried = queried;
	if (trk) {
		/* a change of model is a jump; within the last model, its
		 * stream's word (models without a stream: changes of model
		 * only); coming into or out of range is none */
		out->jumped = out->model >= 0 && trk->last >= 0 &&
			      (out->model != trk->last || jumped);
		trk->last = out->model;
	}
	return out->model >= 0 ? 1 : 0;
}

int px_world_nearest(const struct px_world *s, px_vec3 p,
		     double max_distance_m, struct px_world_hit *out)
{
	return nearest(s, p, max_distance_m, NULL, NULL, out);
}

void px_world_hints_reset(struct px_world_hints *h)
{
	size_t i;
	if (!h)
		return;
	for (i = 0; i < PX_WORLD_MAX_MODELS; i++)
		h->index[i] = -1;
}

int px_world_nearest_coherent(const struct px_world *s, px_vec3 p,
			      double max_distance_m, struct px_world_hints *h,
			      struct px_world_hit *out)
{
	if (!h) {
		if (out)
			no_hit(out);
		return PX_E_INVAL;
	}
	return nearest(s, p, max_distance_m, h, NULL, out);
}

static int hit_to_control(int rc, const struct px_world_hit *h,
			  struct px_control_hit *out)
{
	memset(out, 0, sizeof(*out));
	if (rc < 0)
		return rc;
	out->valid = rc == 1;
	if (!out->valid) {
		out->distance_m = INFINITY;
		return PX_OK;
	}
	out->two_sided = !h->r.is_signed;
	out->distance_m = h->distance_m;
	out->point_m = h->r.point;
	out->normal = h->r.direction;
	return PX_OK;
}

static int scene_point(void *ctx, px_vec3 p_m, double max_distance_m,
		       struct px_control_hit *out)
{
	struct px_world_hit h;
	int rc = px_world_nearest(ctx, p_m, max_distance_m, &h);
	return hit_to_control(rc, &h, out);
}

static int scene_point_coherent(void *ctx, px_vec3 p_m, double max_distance_m,
				struct px_control_hit *out)
{
	struct px_world_hints *hints = ctx;
	struct px_world_hit h;
	int rc = nearest(hints->world_, p_m, max_distance_m, hints, NULL, &h);
	return hit_to_control(rc, &h, out);
}

int px_world_control_query(const struct px_world *s, struct px_control_query *q)
{
	if (!s || !q)
		return PX_E_INVAL;
	memset(q, 0, sizeof(*q));
	q->point = scene_point;
	q->segment = NULL;
	q->ctx = (void *)s;
	return PX_OK;
}

int px_world_control_query_coherent(const struct px_world *s,
				    struct px_world_hints *h,
				    struct px_control_query *q)
{
	if (!s || !h || !q)
		return PX_E_INVAL;
	px_world_hints_reset(h);
	h->world_ = s;
	memset(q, 0, sizeof(*q));
	q->point = scene_point_coherent;
	q->segment = NULL;
	q->ctx = h;
	return PX_OK;
}

/* ---- tracked queries ------------------------------------------------ */

int px_world_set_tracking(struct px_world *s, bool enabled,
			  const struct px_model_stream_opts *o)
{
	if (!s)
		return PX_E_INVAL;
	if (o && px_model_stream_opts_check(o) != PX_OK)
		return PX_E_INVAL;
	s->track_on = enabled;
	if (o)
		s->track_opts = *o;
	else
		px_model_stream_opts_default(&s->track_opts);
	return PX_OK;
}

int px_world_get_tracking(const struct px_world *s,
			  struct px_model_stream_opts *o)
{
	if (!s)
		return PX_E_INVAL;
	if (o)
		*o = s->track_opts;
	return s->track_on ? 1 : 0;
}

int px_world_tracking_create(const struct px_world *s,
			     const struct px_model_stream_opts *o,
			     struct px_world_tracking **out)
{
	struct px_world_tracking *t;
	size_t i;
	if (out)
		*out = NULL;
	if (!s || !out)
		return PX_E_INVAL;
	if (!o)
		o = &s->track_opts;
	t = calloc(1, sizeof(*t) + (s->n + 1) * sizeof(t->st[0]));
	if (!t)
		return PX_E_NOMEM;
	t->w = s;
	t->n = s->n;
	t->last = -1;
	px_world_hints_reset(&t->hints);
	t->hints.world_ = s;
	for (i = 0; i < s->n; i++) {
		int rc = px_model_stream_create(s->e[i].m, o, &t->st[i]);
		if (rc == PX_E_UNSUPPORTED) {
			t->st[i] = NULL;
			continue;
		}
		if (rc != PX_OK) {
			px_world_tracking_free(t);
			return rc;
		}
	}
	*out = t;
	return PX_OK;
}

void px_world_tracking_free(struct px_world_tracking *t)
{
	size_t i;
	if (!t)
		return;
	for (i = 0; i < t->n; i++)
		px_model_stream_free(t->st[i]);
	free(t);
}

int px_world_nearest_tracked(const struct px_world *s, px_vec3 p,
			     double max_distance_m, struct px_world_tracking *t,
			     struct px_world_hit *out)
{
	if (!t || t->w != s) {
		if (out)
			no_hit(out);
		return PX_E_INVAL;
	}
	return nearest(s, p, max_distance_m, &t->hints, t, out);
}

int px_world_tracking_stats(const struct px_world_tracking *t,
			    struct px_model_stream_stats *sum)
{
	size_t i;
	int n = 0;
	if (sum)
		memset(sum, 0, sizeof(*sum));
	if (!t)
		return 0;
	for (i = 0; i < t->n; i++) {
		struct px_model_stream_stats st;
		if (!t->st[i])
			continue;
		n++;
		if (!sum)
			continue;
		px_model_stream_get_stats(t->st[i], &st);
		sum->queries += st.queries;
		sum->tracked += st.tracked;
		sum->hot += st.hot;
		sum->global += st.global;
		sum->cold += st.cold;
		sum->jumps += st.jumps;
		sum->reinits += st.reinits;
		sum->verifications += st.verifications;
		sum->disagreements += st.disagreements;
	}
	return n;
}

static int scene_point_tracked(void *ctx, px_vec3 p_m, double max_distance_m,
			       struct px_control_hit *out)
{
	struct px_world_tracking *t = ctx;
	struct px_world_hit h;
	int rc = nearest(t->w, p_m, max_distance_m, &t->hints, t, &h);
	return hit_to_control(rc, &h, out);
}

int px_world_control_query_tracked(const struct px_world *s,
				   struct px_world_tracking *t,
				   struct px_control_query *q)
{
	if (!s || !t || t->w != s || !q)
		return PX_E_INVAL;
	memset(q, 0, sizeof(*q));
	q->point = scene_point_tracked;
	q->segment = NULL;
	q->ctx = t;
	return PX_OK;
}
