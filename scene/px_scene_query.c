/*
 * px_scene_query.c - the scene's queries: nearest (plain, coherent,
 * tracked), within a distance, a tool against the scene, and the
 * adapters to the control module's query interface.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "px_control.h"
#include "scene_internal.h"

struct px_scene_tracking {
	const struct px_scene *w;
	struct px_scene_hints hints;
	size_t n;      /* models when made: streams[0..n) */
	int last;      /* model of the last answer, -1 none */
	struct px_model_stream *st[];
};

/* Lower bound of model e's signed distance to p, from its oriented box
 * under the current pose. Inside the box: -infinity for a closed model
 * (it may be inside), 0 for an open one. */
static inline __attribute__((always_inline)) double
lower_bound(const struct scene_entry *e, px_vec3 p)
{
	px_obb b;
	double d;
	if (!e->bounded)
		return e->is_signed ? -INFINITY : 0.0;
	b = px_obb_from_aabb(&e->local, px_model_pose(e->m));
	d = sqrt(px_obb_dist2(&b, p));
	if (!(d > 0))
		return e->is_signed ? -INFINITY : 0.0;
	return scene_shrink(d);
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
static void no_hit(struct px_scene_hit *out)
{
	memset(out, 0, sizeof(*out));
	out->model = -1;
	out->distance_m = INFINITY;
	out->r.distance = INFINITY;
	out->r.index = -1;
}

static void point_hit(struct px_scene_hit *h, int id, px_vec3 p, double d,
		      const struct px_model_result *r)
{
	h->model = id;
	h->distance_m = d;
	h->point = r->point;
	h->tool_point = p;
	h->feature_index = r->index;
	h->intersecting = r->inside || r->distance == 0.0;
	h->local_only = !r->certified;
	h->r = *r;
}

/* ---- nearest ------------------------------------------------------------- */

struct near {
	const struct px_scene *s;
	px_vec3 p;
	double max, best;
	struct px_scene_hints *hints;
	struct px_scene_tracking *trk;
	struct px_scene_hit *out;
	int queried, jumped;
};

/* Query model k, whose lower bound lo is below the best so far and
 * within range. Returns >= 0 or the model's error. */
static inline __attribute__((always_inline)) int
visit(struct near *c, size_t k, double lo)
{
	const struct scene_entry *e = &c->s->e[k];
	struct px_model_result r;
	double range = c->max;
	int rc, hinted = c->hints && k < PX_SCENE_HINT_MODELS;
	/* |d| may be bounded by the best so far only when d cannot be
	 * negative here (unsigned model or point outside its box) */
	if ((!e->is_signed || lo > 0) && c->best >= 0 && c->best < range)
		range = c->best;
	if (c->trk && k < c->trk->n && c->trk->st[k]) {
		struct px_model_stream_note note;
		rc = px_model_stream_query(c->trk->st[k], c->p, range, 0u, &r,
					   &note);
		if (rc == 1 && note.jumped && (int)k == c->trk->last)
			c->jumped = 1;
	} else {
		rc = px_model_query_ex(e->m, c->p, range,
				       hinted ? c->hints->index[k] : -1,
				       hinted ? PX_QUERY_COHERENT : 0u, &r);
	}
	c->queried++;
	if (rc < 0)
		return rc;
	if (hinted && rc == 1)
		c->hints->index[k] = r.index;
	if (rc == 1) {
		double d = reported(&r);
		if (d < c->best && fabs(d) <= c->max) {
			c->best = d;
			point_hit(c->out, (int)k, c->p, d, &r);
		}
	}
	return 0;
}

/* Few models: each one's bound, visited in increasing bound until the
 * next is not below the best (at most n rounds of n). */
static int near_few(struct near *c)
{
	double lb[PX_SCENE_SMALL];
	unsigned char done[PX_SCENE_SMALL];
	size_t i, n = c->s->n;
	for (i = 0; i < n; i++) {
		lb[i] = lower_bound(&c->s->e[i], c->p);
		done[i] = lb[i] > c->max;
	}
	for (;;) {
		size_t k = n;
		double lo = INFINITY;
		int rc;
		for (i = 0; i < n; i++)
			if (!done[i] && (k == n || lb[i] < lo)) {
				k = i;
				lo = lb[i];
			}
		if (k == n || lo >= c->best)
			return 0;
		done[k] = 1;
		rc = visit(c, k, lo);
		if (rc < 0)
			return rc;
	}
}

static inline double gap1(double lo, double hi, double x)
{
	double d = lo - x > x - hi ? lo - x : x - hi;
	return d > 0.0 ? d : 0.0;
}

/* Distance from p to child c's box (0 inside; +inf for an empty child). */
static double box_dist(const struct scene_node *nd, int c, px_vec3 p)
{
	double dx, dy, dz;
	if (nd->idx[c] == SCENE_EMPTY)
		return INFINITY;
	dx = gap1(nd->lo[c][0], nd->hi[c][0], p.x);
	dy = gap1(nd->lo[c][1], nd->hi[c][1], p.y);
	dz = gap1(nd->lo[c][2], nd->hi[c][2], p.z);
	return sqrt(dx * dx + dy * dy + dz * dz);
}

/* Nothing under a box at distance lb can be nearer than the best or in
 * range (a box holding p, lb 0, may hold a model p is inside). */
static int cut(const struct near *c, double lb)
{
	double b = scene_shrink(lb);
	return lb > 0 && (b > c->max || b >= c->best);
}

/* The models of one leaf (at most SCENE_LEAF), nearest bound first. */
static int near_leaf(struct near *c, uint32_t idx, uint32_t cnt)
{
	double lb[SCENE_LEAF];
	uint32_t id[SCENE_LEAF], i;
	for (i = 0; i < cnt; i++) {
		id[i] = c->s->perm[idx + i];
		lb[i] = lower_bound(&c->s->e[id[i]], c->p);
	}
	if (cnt == 2 && lb[1] < lb[0]) {
		double t = lb[0];
		uint32_t u = id[0];
		lb[0] = lb[1];
		lb[1] = t;
		id[0] = id[1];
		id[1] = u;
	}
	for (i = 0; i < cnt; i++) {
		int rc;
		if (lb[i] > c->max || lb[i] >= c->best)
			continue;
		rc = visit(c, id[i], lb[i]);
		if (rc < 0)
			return rc;
	}
	return 0;
}

/* Many models: the hierarchy, depth first, nearer child first. */
static int near_tree(struct near *c)
{
	struct {
		uint32_t idx, cnt;
		double lb;
	} st[SCENE_STACK];
	int sp = 1;
	st[0].idx = 0;
	st[0].cnt = 0;
	st[0].lb = 0.0;
	while (sp > 0) {
		const struct scene_node *nd;
		double dc[2];
		int k, near;
		sp--;
		if (cut(c, st[sp].lb))
			continue;
		if (st[sp].cnt > 0) {
			int rc = near_leaf(c, st[sp].idx, st[sp].cnt);
			if (rc < 0)
				return rc;
			continue;
		}
		nd = &c->s->nodes[st[sp].idx];
		dc[0] = box_dist(nd, 0, c->p);
		dc[1] = box_dist(nd, 1, c->p);
		near = dc[1] < dc[0];
		/* the farther child first on the stack, the nearer popped next */
		for (k = 0; k < 2; k++) {
			int ch = k == 0 ? 1 - near : near;
			if (cut(c, dc[ch]) || sp >= SCENE_STACK)
				continue;
			st[sp].idx = nd->idx[ch];
			st[sp].cnt = nd->cnt[ch];
			st[sp].lb = dc[ch];
			sp++;
		}
	}
	return 0;
}

static int nearest(const struct px_scene *s, px_vec3 p, double max_distance_m,
		   struct px_scene_hints *hints, struct px_scene_tracking *trk,
		   struct px_scene_hit *out)
{
	struct near c;
	int rc;
	if (!out)
		return PX_E_INVAL;
	no_hit(out);
	if (!s || !(max_distance_m >= 0))
		return PX_E_INVAL;
	if (!px_v3_isfinite(p))
		return PX_E_NAN;
	if (s->stale)
		return PX_E_STATE;
	c = (struct near){.s = s, .p = p, .max = max_distance_m,
			  .best = INFINITY, .hints = hints, .trk = trk,
			  .out = out};
	if (s->n == 0)
		rc = 0;
	else
		rc = s->n <= PX_SCENE_SMALL ? near_few(&c) : near_tree(&c);
	out->models_queried = c.queried;
	if (rc < 0)
		return rc;
	if (trk) {
		/* a change of model is a jump; within the last model, its
		 * stream's word (models without a stream: changes of model
		 * only); coming into or out of range is none */
		out->jumped = out->model >= 0 && trk->last >= 0 &&
			      (out->model != trk->last || c.jumped);
		trk->last = out->model;
	}
	return out->model >= 0 ? 1 : 0;
}

int px_scene_nearest(const struct px_scene *s, px_vec3 p,
		     double max_distance_m, struct px_scene_hit *out)
{
	return nearest(s, p, max_distance_m, NULL, NULL, out);
}

void px_scene_hints_reset(struct px_scene_hints *h)
{
	size_t i;
	if (!h)
		return;
	for (i = 0; i < PX_SCENE_HINT_MODELS; i++)
		h->index[i] = -1;
}

int px_scene_nearest_coherent(const struct px_scene *s, px_vec3 p,
			      double max_distance_m, struct px_scene_hints *h,
			      struct px_scene_hit *out)
{
	if (!h) {
		if (out)
			no_hit(out);
		return PX_E_INVAL;
	}
	return nearest(s, p, max_distance_m, h, NULL, out);
}

/* ---- every model in range ---------------------------------------------- */

static int box_contains(const px_aabb *b, px_vec3 p)
{
	return p.x >= b->min.x && p.x <= b->max.x && p.y >= b->min.y &&
	       p.y <= b->max.y && p.z >= b->min.z && p.z <= b->max.z;
}

/* Distance between child c's box and box b (0 when they overlap). */
static double box_box(const struct scene_node *nd, int c, const px_aabb *b)
{
	double d2 = 0.0;
	int k;
	if (nd->idx[c] == SCENE_EMPTY)
		return INFINITY;
	for (k = 0; k < 3; k++) {
		double g1 = px_v3_comp(b->min, k) - nd->hi[c][k];
		double g2 = nd->lo[c][k] - px_v3_comp(b->max, k);
		double g = g1 > g2 ? g1 : g2;
		if (g > 0.0)
			d2 += g * g;
	}
	return sqrt(d2);
}

/* Depth-first walk over the models in the leaves whose boxes lie within
 * lim of a point p (b NULL) or of a box b, for the queries that want
 * every model in range; on the caller's stack, no allocation. */
struct leaf_walk {
	struct {
		uint32_t idx, cnt;
	} st[SCENE_STACK];
	int sp;
	uint32_t i, end; /* the leaf range being handed out */
	px_vec3 p;
	const px_aabb *b;
	double lim;
};

static void walk_start(struct leaf_walk *w, px_vec3 p, const px_aabb *b,
		       double lim)
{
	w->st[0].idx = 0;
	w->st[0].cnt = 0;
	w->sp = 1;
	w->i = w->end = 0;
	w->p = p;
	w->b = b;
	w->lim = lim;
}

/* The next model id of the walk, or -1 when it is over. */
static int64_t walk_next(const struct px_scene *s, struct leaf_walk *w)
{
	while (w->i == w->end) {
		const struct scene_node *nd;
		int c;
		if (w->sp == 0)
			return -1;
		w->sp--;
		if (w->st[w->sp].cnt > 0) {
			w->i = w->st[w->sp].idx;
			w->end = w->i + w->st[w->sp].cnt;
			continue;
		}
		nd = &s->nodes[w->st[w->sp].idx];
		for (c = 0; c < 2; c++) {
			double d = w->b ? box_box(nd, c, w->b)
					 : box_dist(nd, c, w->p);
			if (d > w->lim || w->sp >= SCENE_STACK)
				continue;
			w->st[w->sp].idx = nd->idx[c];
			w->st[w->sp].cnt = nd->cnt[c];
			w->sp++;
		}
	}
	return s->perm[w->i++];
}

int px_scene_within(const struct px_scene *s, px_vec3 p, double dist,
		    struct px_scene_hit *hits, size_t cap, size_t *n_found)
{
	struct leaf_walk w;
	int64_t id;
	size_t n = 0;

	if (n_found)
		*n_found = 0;
	if (!s || (!hits && cap) || !(dist >= 0.0))
		return PX_E_INVAL;
	if (!px_v3_isfinite(p))
		return PX_E_NAN;
	if (s->stale)
		return PX_E_STATE;
	if (s->n == 0)
		return 0;
	walk_start(&w, p, NULL, dist);
	while ((id = walk_next(s, &w)) >= 0) {
		struct px_model_result r;
		double bound = box_contains(&s->box[id], p) ? INFINITY : dist;
		int rc = px_model_query_ex(s->e[id].m, p, bound, -1, 0u, &r);
		if (rc < 0)
			return rc;
		if (rc == 1 && reported(&r) <= dist) {
			if (n < cap) {
				memset(&hits[n], 0, sizeof(hits[n]));
				point_hit(&hits[n], (int)id, p, reported(&r), &r);
			}
			n++;
		}
	}
	if (n_found)
		*n_found = n;
	return n > cap ? PX_E_NOSPC : (int)n;
}

int px_scene_tool(const struct px_scene *s, const struct px_model *tool,
		  double max_dist, const struct px_pair_opts *opt,
		  struct px_scene_hit *hits, size_t cap, size_t *n_found)
{
	struct leaf_walk w;
	int64_t id;
	size_t n = 0;
	px_aabb tb;

	if (n_found)
		*n_found = 0;
	if (!s || !tool || (!hits && cap) || !(max_dist >= 0.0))
		return PX_E_INVAL;
	if (s->stale)
		return PX_E_STATE;
	if (s->n == 0)
		return 0;
	tb = px_model_world_aabb(tool);
	walk_start(&w, px_v3(0.0, 0.0, 0.0), &tb, max_dist);
	while ((id = walk_next(s, &w)) >= 0) {
		struct px_pair_result r;
		int rc;
		if (s->e[id].m == tool)
			continue;
		memset(&r, 0, sizeof(r));
		rc = px_pair_distance(tool, s->e[id].m, opt, &r);
		if (rc < 0)
			return rc;
		if (r.distance <= max_dist) {
			if (n < cap) {
				struct px_scene_hit *h = &hits[n];
				memset(h, 0, sizeof(*h));
				h->model = (int)id;
				h->distance_m = r.distance;
				h->point = r.point_b;
				h->tool_point = r.point_a;
				h->feature_index = r.index_b;
				h->intersecting = r.intersecting;
				h->local_only = r.local_only;
				h->r.index = -1;
			}
			n++;
		}
	}
	if (n_found)
		*n_found = n;
	return n > cap ? PX_E_NOSPC : (int)n;
}

/* ---- tracked queries ----------------------------------------------------- */

int px_scene_tracking_create(const struct px_scene *s,
			     const struct px_model_stream_opts *o,
			     struct px_scene_tracking **out)
{
	struct px_scene_tracking *t;
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
	px_scene_hints_reset(&t->hints);
	t->hints.scene_ = s;
	for (i = 0; i < s->n; i++) {
		int rc = px_model_stream_create(s->e[i].m, o, &t->st[i]);
		if (rc == PX_E_UNSUPPORTED) {
			t->st[i] = NULL;
			continue;
		}
		if (rc != PX_OK) {
			px_scene_tracking_free(t);
			return rc;
		}
	}
	*out = t;
	return PX_OK;
}

void px_scene_tracking_free(struct px_scene_tracking *t)
{
	size_t i;
	if (!t)
		return;
	for (i = 0; i < t->n; i++)
		px_model_stream_free(t->st[i]);
	free(t);
}

int px_scene_nearest_tracked(const struct px_scene *s, px_vec3 p,
			     double max_distance_m, struct px_scene_tracking *t,
			     struct px_scene_hit *out)
{
	if (!t || t->w != s) {
		if (out)
			no_hit(out);
		return PX_E_INVAL;
	}
	return nearest(s, p, max_distance_m, &t->hints, t, out);
}

int px_scene_tracking_stats(const struct px_scene_tracking *t,
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

/* ---- the control module's query ------------------------------------------ */

static int hit_to_control(int rc, const struct px_scene_hit *h,
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
	struct px_scene_hit h;
	int rc = nearest(ctx, p_m, max_distance_m, NULL, NULL, &h);
	return hit_to_control(rc, &h, out);
}

static int scene_point_coherent(void *ctx, px_vec3 p_m, double max_distance_m,
				struct px_control_hit *out)
{
	struct px_scene_hints *hints = ctx;
	struct px_scene_hit h;
	int rc = nearest(hints->scene_, p_m, max_distance_m, hints, NULL, &h);
	return hit_to_control(rc, &h, out);
}

static int scene_point_tracked(void *ctx, px_vec3 p_m, double max_distance_m,
			       struct px_control_hit *out)
{
	struct px_scene_tracking *t = ctx;
	struct px_scene_hit h;
	int rc = nearest(t->w, p_m, max_distance_m, &t->hints, t, &h);
	return hit_to_control(rc, &h, out);
}

static void control_query(struct px_control_query *q,
			  int (*point)(void *, px_vec3, double,
				       struct px_control_hit *),
			  void *ctx)
{
	memset(q, 0, sizeof(*q));
	q->point = point;
	q->segment = NULL; /* the control module bisects over point queries */
	q->ctx = ctx;
}

int px_scene_control_query(const struct px_scene *s, struct px_control_query *q)
{
	if (!s || !q)
		return PX_E_INVAL;
	control_query(q, scene_point, (void *)s);
	return PX_OK;
}

int px_scene_control_query_coherent(const struct px_scene *s,
				    struct px_scene_hints *h,
				    struct px_control_query *q)
{
	if (!s || !h || !q)
		return PX_E_INVAL;
	px_scene_hints_reset(h);
	h->scene_ = s;
	control_query(q, scene_point_coherent, h);
	return PX_OK;
}

int px_scene_control_query_tracked(const struct px_scene *s,
				   struct px_scene_tracking *t,
				   struct px_control_query *q)
{
	if (!s || !t || t->w != s || !q)
		return PX_E_INVAL;
	control_query(q, scene_point_tracked, t);
	return PX_OK;
}
