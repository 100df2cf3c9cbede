/*
 * px_scene.c - posed models under a per-cycle bounding-box hierarchy.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "px_scene.h"
#include "model_internal.h"

#define LEAF 2
#define STACK 64 /* depth <= log2(PX_SCENE_MAX_CAPACITY) + 2 */
#define EMPTY 0xffffffffu

struct snode {
	double lo[2][3], hi[2][3];
	uint32_t idx[2], cnt[2];
};

struct px_scene {
	size_t cap, n;
	int dirty;
	struct px_model **models;
	px_aabb *box;      /* world box per model */
	double *cen;       /* 3 per model */
	uint32_t *perm;    /* leaf order -> model id */
	struct snode *nodes;
	size_t n_nodes;
	size_t built_n;    /* model count when the hierarchy was built */
	unsigned since;    /* updates since the last full build */
};

/* Every REBUILD-th update rebuilds the hierarchy; the others only refit
 * its boxes (O(n)), which keeps it valid (boxes always enclose their
 * models) while its shape slowly loosens as models move. */
#define REBUILD 16

int px_scene_create(size_t capacity, struct px_scene **out)
{
	struct px_scene *s;
	if (out)
		*out = NULL;
	if (!out || capacity == 0)
		return PX_E_INVAL;
	if (capacity > PX_SCENE_MAX_CAPACITY)
		return PX_E_RANGE;
	s = calloc(1, sizeof(*s));
	if (!s)
		return PX_E_NOMEM;
	s->cap = capacity;
	s->models = calloc(capacity, sizeof(*s->models));
	s->box = calloc(capacity, sizeof(*s->box));
	s->cen = calloc(3 * capacity, sizeof(double));
	s->perm = calloc(capacity, sizeof(*s->perm));
	s->nodes = calloc(capacity + 1, sizeof(*s->nodes));
	if (!s->models || !s->box || !s->cen || !s->perm || !s->nodes) {
		px_scene_free(s);
		return PX_E_NOMEM;
	}
	s->dirty = 1;
	*out = s;
	return PX_OK;
}

void px_scene_free(struct px_scene *s)
{
	if (!s)
		return;
	free(s->models);
	free(s->box);
	free(s->cen);
	free(s->perm);
	free(s->nodes);
	free(s);
}

int px_scene_add(struct px_scene *s, struct px_model *m, int *id)
{
	if (!s || !m)
		return PX_E_INVAL;
	if (s->n == s->cap)
		return PX_E_NOSPC;
	if (id)
		*id = (int)s->n;
	s->models[s->n++] = m;
	s->dirty = 1;
	return PX_OK;
}

size_t px_scene_count(const struct px_scene *s)
{
	return s ? s->n : 0;
}

/* ---- hierarchy ------------------------------------------------------------- */

static void range_box(const struct px_scene *s, size_t b, size_t n, double lo[3],
		      double hi[3])
{
	size_t i;
	int k;
	for (k = 0; k < 3; k++) {
		lo[k] = INFINITY;
		hi[k] = -INFINITY;
	}
	for (i = b; i < b + n; i++) {
		const px_aabb *x = &s->box[s->perm[i]];
		for (k = 0; k < 3; k++) {
			double l = px_v3_comp(x->min, k), h = px_v3_comp(x->max, k);
			lo[k] = l < lo[k] ? l : lo[k];
			hi[k] = h > hi[k] ? h : hi[k];
		}
	}
}

/* Recursion depth is log2 of the capacity (median splits). */
static uint32_t build(struct px_scene *s, size_t b, size_t n)
{
	uint32_t me = (uint32_t)s->n_nodes++;
	double clo[3], chi[3];
	size_t half, part[2][2];
	int c;

	px__key_bounds(s->perm + b, n, s->cen, clo, chi);
	half = px__median_split(s->perm + b, n, s->cen, clo, chi);
	part[0][0] = b;
	part[0][1] = half;
	part[1][0] = b + half;
	part[1][1] = n - half;
	for (c = 0; c < 2; c++) {
		range_box(s, part[c][0], part[c][1], s->nodes[me].lo[c], s->nodes[me].hi[c]);
		if (part[c][1] <= LEAF) {
			s->nodes[me].idx[c] = (uint32_t)part[c][0];
			s->nodes[me].cnt[c] = (uint32_t)part[c][1];
		} else {
			uint32_t ch = build(s, part[c][0], part[c][1]);
			s->nodes[me].idx[c] = ch;
			s->nodes[me].cnt[c] = 0;
		}
	}
	return me;
}

int px_scene_update(struct px_scene *s)
{
	size_t i;
	int k;
	if (!s)
		return PX_E_INVAL;
	for (i = 0; i < s->n; i++) {
		px_aabb lb = px_model_local_aabb(s->models[i]);
		if (px_v3_isfinite(lb.min) && px_v3_isfinite(lb.max)) {
			s->box[i] = px_model_world_aabb(s->models[i]);
		} else {
			/* unbounded (a half-space): always a candidate */
			s->box[i].min = px_v3(-INFINITY, -INFINITY, -INFINITY);
			s->box[i].max = px_v3(INFINITY, INFINITY, INFINITY);
		}
		for (k = 0; k < 3; k++) {
			double l = px_v3_comp(s->box[i].min, k), h = px_v3_comp(s->box[i].max, k);
			s->cen[3 * i + k] = isfinite(l) && isfinite(h) ? 0.5 * (l + h) : 0.0;
		}
	}
	if (!s->dirty && s->built_n == s->n && s->n > LEAF && ++s->since < REBUILD) {
		/* refit: children come after their parent (preorder), so a
		 * reverse sweep sees every child before its parent */
		size_t j = s->n_nodes;
		while (j-- > 0) {
			struct snode *nd = &s->nodes[j];
			int c;
			for (c = 0; c < 2; c++) {
				if (nd->cnt[c] > 0) {
					range_box(s, nd->idx[c], nd->cnt[c], nd->lo[c], nd->hi[c]);
				} else {
					const struct snode *ch = &s->nodes[nd->idx[c]];
					for (k = 0; k < 3; k++) {
						nd->lo[c][k] = ch->lo[0][k] < ch->lo[1][k] ? ch->lo[0][k] : ch->lo[1][k];
						nd->hi[c][k] = ch->hi[0][k] > ch->hi[1][k] ? ch->hi[0][k] : ch->hi[1][k];
					}
				}
			}
		}
		return PX_OK;
	}
	s->since = 0;
	s->built_n = s->n;
	for (i = 0; i < s->n; i++)
		s->perm[i] = (uint32_t)i;
	s->n_nodes = 0;
	if (s->n <= LEAF) {
		struct snode *nd = &s->nodes[0];
		s->n_nodes = 1;
		range_box(s, 0, s->n, nd->lo[0], nd->hi[0]);
		nd->idx[0] = 0;
		nd->cnt[0] = (uint32_t)s->n;
		for (k = 0; k < 3; k++) {
			nd->lo[1][k] = INFINITY;
			nd->hi[1][k] = -INFINITY;
		}
		nd->idx[1] = EMPTY;
		nd->cnt[1] = 0;
	} else {
		build(s, 0, s->n);
	}
	s->dirty = 0;
	return PX_OK;
}

/* ---- queries ------------------------------------------------------------------ */

static inline double gap(double lo, double hi, double x)
{
	double d = lo - x > x - hi ? lo - x : x - hi;
	return d > 0.0 ? d : 0.0;
}

/* Distance from p to child c's box (0 inside; +inf for an empty child). */
static double box_dist(const struct snode *nd, int c, px_vec3 p)
{
	double dx, dy, dz;
	if (nd->idx[c] == EMPTY)
		return INFINITY;
	dx = gap(nd->lo[c][0], nd->hi[c][0], p.x);
	dy = gap(nd->lo[c][1], nd->hi[c][1], p.y);
	dz = gap(nd->lo[c][2], nd->hi[c][2], p.z);
	return sqrt(dx * dx + dy * dy + dz * dz);
}

/* Distance between child c's box and box b (0 when they overlap). */
static double box_box(const struct snode *nd, int c, const px_aabb *b)
{
	double d2 = 0.0;
	int k;
	if (nd->idx[c] == EMPTY)
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

static int box_contains(const px_aabb *b, px_vec3 p)
{
	return p.x >= b->min.x && p.x <= b->max.x && p.y >= b->min.y &&
	       p.y <= b->max.y && p.z >= b->min.z && p.z <= b->max.z;
}

static void fill_point_hit(struct px_scene_hit *h, int id, px_vec3 p,
			   const struct px_model_result *r)
{
	h->model = id;
	h->distance = r->distance;
	h->point = r->point;
	h->tool_point = p;
	h->feature_index = r->index;
	h->intersecting = r->inside || r->distance == 0.0;
	h->local_only = !r->certified;
}

int px_scene_nearest(const struct px_scene *s, px_vec3 p, double max_dist,
		     struct px_scene_hit *hit)
{
	struct {
		uint32_t idx, cnt;
		double lb;
	} st[STACK];
	int sp = 0, found = 0;
	double best = max_dist;

	if (!s || !hit || !(max_dist >= 0.0))
		return PX_E_INVAL;
	if (!px_v3_isfinite(p))
		return PX_E_NAN;
	if (s->dirty)
		return PX_E_STATE;
	if (s->n == 0)
		return 0;
	st[sp].idx = 0;
	st[sp].cnt = 0;
	st[sp].lb = 0.0;
	sp++;
	while (sp > 0) {
		const struct snode *nd;
		double dc[2], cut;
		int c, near;
		sp--;
		/* a model whose box holds p may be nearer with a negative
		 * (inside) distance, so the cut is at least 0 */
		cut = best > 0.0 ? best : 0.0;
		if (st[sp].lb > cut)
			continue;
		if (st[sp].cnt > 0) {
			uint32_t i;
			for (i = st[sp].idx; i < st[sp].idx + st[sp].cnt; i++) {
				uint32_t id = s->perm[i];
				struct px_model_result r;
				double bound = box_contains(&s->box[id], p) || !(best > 0.0)
						       ? INFINITY : best;
				int rc = px_model_query_ex(s->models[id], p, bound, -1, 0u, &r);
				if (rc < 0)
					return rc;
				if (rc == 1 && r.distance <= best && (!found || r.distance < best)) {
					best = r.distance;
					fill_point_hit(hit, (int)id, p, &r);
					found = 1;
				}
			}
			continue;
		}
		nd = &s->nodes[st[sp].idx];
		dc[0] = box_dist(nd, 0, p);
		dc[1] = box_dist(nd, 1, p);
		near = dc[1] < dc[0];
		for (c = 0; c < 2; c++) {
			int ch = c == 0 ? 1 - near : near;
			if (dc[ch] > cut || sp >= STACK)
				continue;
			st[sp].idx = nd->idx[ch];
			st[sp].cnt = nd->cnt[ch];
			st[sp].lb = dc[ch];
			sp++;
		}
	}
	return found;
}

/* Depth-first walk over the models in the leaves whose boxes lie within
 * lim of a point p (b NULL) or of a box b, for the queries that want
 * every model in range; on the caller's stack, no allocation. */
struct leaf_walk {
	struct {
		uint32_t idx, cnt;
	} st[STACK];
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
		const struct snode *nd;
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
			if (d > w->lim || w->sp >= STACK)
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
	if (s->dirty)
		return PX_E_STATE;
	if (s->n == 0)
		return 0;
	walk_start(&w, p, NULL, dist);
	while ((id = walk_next(s, &w)) >= 0) {
		struct px_model_result r;
		double bound = box_contains(&s->box[id], p) ? INFINITY : dist;
		int rc = px_model_query_ex(s->models[id], p, bound, -1, 0u, &r);
		if (rc < 0)
			return rc;
		if (rc == 1 && r.distance <= dist) {
			if (n < cap)
				fill_point_hit(&hits[n], (int)id, p, &r);
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
	if (s->dirty)
		return PX_E_STATE;
	if (s->n == 0)
		return 0;
	tb = px_model_world_aabb(tool);
	walk_start(&w, px_v3(0.0, 0.0, 0.0), &tb, max_dist);
	while ((id = walk_next(s, &w)) >= 0) {
		struct px_pair_result r;
		int rc;
		if (s->models[id] == tool)
			continue;
		memset(&r, 0, sizeof(r));
		rc = px_pair_distance(tool, s->models[id], opt, &r);
		if (rc < 0)
			return rc;
		if (r.distance <= max_dist) {
			if (n < cap) {
				struct px_scene_hit *h = &hits[n];
				h->model = (int)id;
				h->distance = r.distance;
				h->point = r.point_b;
				h->tool_point = r.point_a;
				h->feature_index = r.index_b;
				h->intersecting = r.intersecting;
				h->local_only = r.local_only;
			}
			n++;
		}
	}
	if (n_found)
		*n_found = n;
	return n > cap ? PX_E_NOSPC : (int)n;
}
