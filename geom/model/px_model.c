/*
 * px_model.c - the model handle: pose, frame changes, dispatch.
 */
#include <math.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>

#include "px_model.h"
#include "math_internal.h"
#include "model_internal.h"

struct px_model {
	const struct px_model_ops *ops;
	void *impl;
	unsigned caps;
	px_pose pose;
	px_aabb local_box; /* cached at creation: geometry never changes */
	unsigned long serial; /* unique per model created (model_internal.h) */
};

static _Atomic unsigned long model_serial;

int px_model_create(const struct px_model_ops *ops, void *impl,
		    unsigned caps, struct px_model **out)
{
	struct px_model *m;

	if (out)
		*out = NULL;
	if (!ops || !ops->closest || !ops->aabb || !out) {
		if (ops && ops->free && impl)
			ops->free(impl);
		return PX_E_INVAL;
	}
	m = calloc(1, sizeof(*m));
	if (!m) {
		if (ops->free && impl)
			ops->free(impl);
		return PX_E_NOMEM;
	}
	m->ops = ops;
	m->impl = impl;
	m->caps = caps;
	m->pose = px_pose_identity();
	m->local_box = ops->aabb(impl);
	m->serial = ++model_serial;
	*out = m;
	return PX_OK;
}

unsigned long px__model_serial(const struct px_model *m)
{
	return m ? m->serial : 0;
}

void px_model_free(struct px_model *m)
{
	if (!m)
		return;
	if (m->ops->free && m->impl)
		m->ops->free(m->impl);
	free(m);
}

int px_model_set_pose(struct px_model *m, px_pose pose)
{
	int rc;

	if (!m)
		return PX_E_INVAL;
	rc = px_pose_sanitize(&pose);
	if (rc != PX_OK)
		return rc;
	/* a model moved farther than the models' reach leaves squared
	 * distances of the scene's box tests to overflow */
	if (fabs(pose.t.x) > PX_MODEL_MAX_COORD || fabs(pose.t.y) > PX_MODEL_MAX_COORD ||
	    fabs(pose.t.z) > PX_MODEL_MAX_COORD)
		return PX_E_RANGE;
	m->pose = pose;
	return PX_OK;
}

px_pose px_model_pose(const struct px_model *m)
{
	return m ? m->pose : px_pose_identity();
}

/* The query in m's frame (q->hint and q->flags left to the caller).
 * Returns PX_OK or the error of a bad point. */
static int query_in(const struct px_model *m, px_vec3 p, double max_dist,
		    struct px_model_query *q)
{
	if (!px_v3_isfinite(p))
		return PX_E_NAN;
	q->p = px_pose_inverse_transform_point(m->pose, p);
	/* Squared distances overflow past about 1e154: a point that far
	 * from the model's box gets a clear error instead of an infinite
	 * distance and an arbitrary closest point (every candidate ties). */
	if (px__too_far(&m->local_box, q->p))
		return PX_E_RANGE;
	q->max_dist = max_dist;
	return PX_OK;
}

static void to_world(const struct px_model *m, struct px_model_result *out)
{
	out->point = px_pose_transform_point(m->pose, out->point);
	out->direction = px_pose_transform_vector(m->pose, out->direction);
}

/* An implementation's answer rc (model frame) as the API gives it:
 * nothing in range spelled out, the point and direction in the world. */
static int answer_out(const struct px_model *m, int rc,
		      struct px_model_result *out)
{
	if (rc <= 0) {
		if (rc == 0) {
			out->distance = INFINITY;
			out->index = -1;
			out->sub = -1;
			out->feature = PX_FEATURE_NONE;
		}
		return rc;
	}
	if (!isfinite(out->distance))
		return PX_E_RANGE; /* the model's own extent overflowed */
	to_world(m, out);
	return 1;
}

int px_model_query_ex(const struct px_model *m, px_vec3 p, double max_dist,
		      int hint, unsigned flags, struct px_model_result *out)
{
	struct px_model_query q;
	int rc;

	if (!m || !out || !(max_dist >= 0.0))
		return PX_E_INVAL;
	rc = query_in(m, p, max_dist, &q);
	if (rc != PX_OK)
		return rc;
	q.hint = (flags & PX_QUERY_COHERENT) ? hint : -1;
	q.flags = flags;
	return answer_out(m, m->ops->closest(m->impl, &q, out), out);
}

int px_model_query(const struct px_model *m, px_vec3 p,
		   struct px_model_result *out)
{
	return px_model_query_ex(m, p, INFINITY, -1, 0u, out);
}

px_aabb px_model_local_aabb(const struct px_model *m)
{
	return m ? m->local_box : px_aabb_empty();
}

px_aabb px_model_world_aabb(const struct px_model *m)
{
	if (!m)
		return px_aabb_empty();
	return px_aabb_transform(&m->local_box, m->pose);
}

px_obb px_model_world_obb(const struct px_model *m)
{
	px_aabb e = px_aabb_empty();
	if (!m)
		return px_obb_from_aabb(&e, px_pose_identity());
	return px_obb_from_aabb(&m->local_box, m->pose);
}

enum px_model_kind px_model_kind(const struct px_model *m)
{
	return m ? m->ops->kind : PX_MODEL_CUSTOM;
}

const char *px_model_name(const struct px_model *m)
{
	return (m && m->ops->name) ? m->ops->name : "?";
}

unsigned px_model_caps(const struct px_model *m)
{
	return m ? m->caps : 0u;
}

size_t px_model_memory_bytes(const struct px_model *m)
{
	if (!m)
		return 0;
	return sizeof(*m) +
	       (m->ops->memory_bytes ? m->ops->memory_bytes(m->impl) : 0);
}

const void *px_model_impl(const struct px_model *m)
{
	return m ? m->impl : NULL;
}

const struct px_model_ops *px_model_get_ops(const struct px_model *m)
{
	return m ? m->ops : NULL;
}

int px_model_support(const struct px_model *m, px_vec3 dir, px_vec3 *out)
{
	if (!m || !out)
		return PX_E_INVAL;
	if (!m->ops->support)
		return PX_E_UNSUPPORTED;
	*out = px_pose_transform_point(
		m->pose, m->ops->support(m->impl, px_pose_inverse_transform_vector(m->pose, dir)));
	return PX_OK;
}

/* ---- coherence cache ------------------------------------------------------- */

void px_model_cache_init(struct px_model_cache *c, double margin_m)
{
	if (!c)
		return;
	memset(c, 0, sizeof(*c));
	c->n_ = -1;
	c->last_ = -1;
	c->margin_ = margin_m > 0.0 && isfinite(margin_m) ? margin_m : 0.0;
}

int px_model_query_cached(const struct px_model *m, px_vec3 p,
			  struct px_model_cache *c, struct px_model_result *out)
{
	struct px_model_query q;
	const struct px_model_ops *o;
	double d, margin, R;
	int rc, n, tries;

	if (!m || !c || !out)
		return PX_E_INVAL;
	if (!px_v3_isfinite(p))
		return PX_E_NAN;
	o = m->ops;
	c->queries_++;
	if (!o->closest_among || !o->collect) {
		rc = px_model_query_ex(m, p, INFINITY, c->last_, PX_QUERY_COHERENT, out);
		if (rc == 1)
			c->last_ = out->index;
		return rc;
	}
	if (c->model_ != m) {
		c->model_ = m;
		c->n_ = -1;
		c->last_ = -1;
	}
	rc = query_in(m, p, INFINITY, &q);
	if (rc != PX_OK)
		return rc;
	q.flags = 0u;
	q.hint = -1;
	if (c->n_ > 0) {
		double moved = px_v3_dist(q.p, c->anchor_);
		rc = o->closest_among(m->impl, &q, c->idx_, c->n_, out);
		if (rc < 0)
			return rc;
		if (rc == 1 && fabs(out->distance) + moved <= c->radius_) {
			to_world(m, out);
			c->last_ = out->index;
			return 1;
		}
	}
	/* refill: one full query, then every feature near enough */
	c->refills_++;
	q.hint = c->last_;
	q.flags = PX_QUERY_COHERENT;
	rc = o->closest(m->impl, &q, out);
	if (rc <= 0)
		return rc < 0 ? rc : PX_E_DEGENERATE;
	if (!isfinite(out->distance))
		return PX_E_RANGE;
	d = fabs(out->distance);
	margin = c->margin_;
	if (!(margin > 0.0))
		margin = fmax(0.5 * d, 1e-3 * px_aabb_diagonal(&m->local_box));
	R = d + 2.0 * margin;
	n = PX_E_NOSPC;
	for (tries = 0; tries < 4 && n < 0; tries++) {
		n = o->collect(m->impl, q.p, R, c->idx_, PX_MODEL_CACHE_CAP);
		if (n == PX_E_NOSPC)
			R = d + 0.25 * (R - d);
		else if (n < 0)
			return n;
	}
	if (n > 0) {
		c->anchor_ = q.p;
		c->radius_ = R;
		c->n_ = n;
	} else {
		c->n_ = -1; /* too crowded here: plain queries until it thins */
	}
	to_world(m, out);
	c->last_ = out->index;
	return 1;
}

unsigned long px_model_cache_queries(const struct px_model_cache *c)
{
	return c ? c->queries_ : 0;
}

unsigned long px_model_cache_refills(const struct px_model_cache *c)
{
	return c ? c->refills_ : 0;
}

void px__select_k(uint32_t *a, long n, long k, const double *key, int axis)
{
	long lo = 0, hi = n - 1;
	while (lo < hi) {
		double pv = key[3 * (size_t)a[lo + (hi - lo) / 2] + axis];
		long i = lo, j = hi;
		while (i <= j) {
			while (key[3 * (size_t)a[i] + axis] < pv)
				i++;
			while (key[3 * (size_t)a[j] + axis] > pv)
				j--;
			if (i <= j) {
				uint32_t t = a[i];
				a[i] = a[j];
				a[j] = t;
				i++;
				j--;
			}
		}
		if (k <= j)
			hi = j;
		else if (k >= i)
			lo = i;
		else
			break;
	}
}

void px__prefix_path(char *msg, size_t cap, const char *path)
{
	char tmp[512];
	size_t lp = strlen(path), lm;

	if (cap < 4)
		return;
	lm = strnlen(msg, cap - 1);
	if (lm > sizeof(tmp) - 1)
		lm = sizeof(tmp) - 1;
	memcpy(tmp, msg, lm);
	tmp[lm] = '\0';
	if (lp > cap - 3)
		lp = cap - 3;
	memcpy(msg, path, lp);
	memcpy(msg + lp, ": ", 2);
	/* what is left of the message after the prefix, NUL included */
	snprintf(msg + lp + 2, cap - lp - 2, "%s", tmp);
}

/* ---- tracked streams ------------------------------------------------ */

struct px_model_stream {
	const struct px_model *m;
	void *state;
	uint64_t queries;
};

void px_model_stream_opts_default(struct px_model_stream_opts *o)
{
	if (!o)
		return;
	memset(o, 0, sizeof(*o));
	o->verify_every = 0;
	o->max_solves = 4;
	o->cold_switch = 1;
}

int px_model_stream_opts_check(const struct px_model_stream_opts *o)
{
	if (!o || o->verify_every < 0 || o->max_solves < 0 ||
	    (o->cold_switch != 0 && o->cold_switch != 1))
		return PX_E_INVAL;
	return PX_OK;
}

int px_model_stream_create(const struct px_model *m,
			   const struct px_model_stream_opts *o,
			   struct px_model_stream **out)
{
	struct px_model_stream_opts d;
	struct px_model_stream *s;
	int rc;

	if (out)
		*out = NULL;
	if (!m || !out)
		return PX_E_INVAL;
	if (!o) {
		px_model_stream_opts_default(&d);
		o = &d;
	}
	if (px_model_stream_opts_check(o) != PX_OK)
		return PX_E_INVAL;
	if (!m->ops->stream_create || !m->ops->stream_query ||
	    !m->ops->stream_free)
		return PX_E_UNSUPPORTED;
	s = calloc(1, sizeof(*s));
	if (!s)
		return PX_E_NOMEM;
	s->m = m;
	rc = m->ops->stream_create(m->impl, o, &s->state);
	if (rc != PX_OK) {
		free(s);
		return rc;
	}
	*out = s;
	return PX_OK;
}

void px_model_stream_free(struct px_model_stream *s)
{
	if (!s)
		return;
	if (s->state)
		s->m->ops->stream_free(s->state);
	free(s);
}

int px_model_stream_query(struct px_model_stream *s, px_vec3 p,
			  double max_dist, unsigned flags,
			  struct px_model_result *out,
			  struct px_model_stream_note *note)
{
	struct px_model_stream_note nn;
	struct px_model_query q;
	const struct px_model *m;
	int rc;

	if (!note)
		note = &nn;
	memset(note, 0, sizeof(*note));
	if (!s || !out || !(max_dist >= 0.0))
		return PX_E_INVAL;
	m = s->m;
	rc = query_in(m, p, max_dist, &q);
	if (rc != PX_OK)
		return rc;
	q.hint = -1;
	q.flags = flags & ~PX_QUERY_COHERENT;
	rc = m->ops->stream_query(m->impl, s->state, &q, out, note);
	if (rc >= 0)
		s->queries++;
	return answer_out(m, rc, out);
}

void px_model_stream_get_stats(const struct px_model_stream *s,
			       struct px_model_stream_stats *st)
{
	if (!st)
		return;
	memset(st, 0, sizeof(*st));
	if (!s)
		return;
	if (s->m->ops->stream_stats)
		s->m->ops->stream_stats(s->state, st);
	st->queries = s->queries;
}
