/*
 * px_scene.c - the scene's models, their world boxes and the bounding-box
 * hierarchy over them; the tracking settings.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model_internal.h"
#include "scene_internal.h"

/* Every REBUILD-th update rebuilds the hierarchy; the others only refit
 * its boxes (O(n)), which keeps it valid (boxes always enclose their
 * models) while its shape slowly loosens as models move. */
#define REBUILD 16

/* Carve n bytes (rounded to 8) from *at. */
static void *carve(char **at, size_t n)
{
	void *p = *at;
	*at += (n + 7) & ~(size_t)7;
	return p;
}

int px_scene_create(size_t capacity, struct px_scene **out)
{
	struct px_scene *s;
	size_t bytes;
	char *at;
	if (out)
		*out = NULL;
	if (!out || capacity == 0)
		return PX_E_INVAL;
	if (capacity > PX_SCENE_MAX_CAPACITY)
		return PX_E_RANGE;
	bytes = sizeof(*s) + capacity * sizeof(struct scene_entry) +
		capacity * sizeof(px_aabb) + 3 * capacity * sizeof(double) +
		(capacity + 1) * sizeof(struct scene_node) +
		(3 * capacity + 1) * sizeof(uint32_t) + 64; /* carve()'s rounding */
	s = calloc(1, bytes);
	if (!s)
		return PX_E_NOMEM;
	at = (char *)s;
	carve(&at, sizeof(*s));
	s->e = carve(&at, capacity * sizeof(*s->e));
	s->box = carve(&at, capacity * sizeof(*s->box));
	s->cen = carve(&at, 3 * capacity * sizeof(*s->cen));
	s->nodes = carve(&at, (capacity + 1) * sizeof(*s->nodes));
	s->perm = carve(&at, capacity * sizeof(*s->perm));
	s->leaf_of = carve(&at, capacity * sizeof(*s->leaf_of));
	s->parent = carve(&at, (capacity + 1) * sizeof(*s->parent));
	s->cap = capacity;
	s->track_on = true;
	px_model_stream_opts_default(&s->track_opts);
	*out = s;
	return PX_OK;
}

void px_scene_free(struct px_scene *s)
{
	size_t i;
	if (!s)
		return;
	for (i = 0; i < s->n; i++)
		if (s->e[i].owned)
			px_model_free(s->e[i].m);
	free(s);
}

/* ---- hierarchy ---------------------------------------------------------- */

/* World box of model i from its current pose (unbounded: everywhere). */
static void refresh_box(struct px_scene *s, size_t i)
{
	px_aabb *b = &s->box[i];
	int k;
	if (px_v3_isfinite(s->e[i].local.min) && px_v3_isfinite(s->e[i].local.max)) {
		*b = px_model_world_aabb(s->e[i].m);
	} else {
		b->min = px_v3(-INFINITY, -INFINITY, -INFINITY);
		b->max = px_v3(INFINITY, INFINITY, INFINITY);
	}
	for (k = 0; k < 3; k++) {
		double l = px_v3_comp(b->min, k), h = px_v3_comp(b->max, k);
		s->cen[3 * i + k] = isfinite(l) && isfinite(h) ? 0.5 * (l + h) : 0.0;
	}
}

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

/* Child c of node j: its box again from its leaf's models or its node. */
static void refit_child(struct px_scene *s, size_t j, int c)
{
	struct scene_node *nd = &s->nodes[j];
	int k;
	if (nd->idx[c] == SCENE_EMPTY)
		return;
	if (nd->cnt[c] > 0) {
		range_box(s, nd->idx[c], nd->cnt[c], nd->lo[c], nd->hi[c]);
		return;
	}
	{
		const struct scene_node *ch = &s->nodes[nd->idx[c]];
		for (k = 0; k < 3; k++) {
			nd->lo[c][k] = fmin(ch->lo[0][k], ch->lo[1][k]);
			nd->hi[c][k] = fmax(ch->hi[0][k], ch->hi[1][k]);
		}
	}
}

static void mark_leaf(struct px_scene *s, uint32_t node, int c)
{
	const struct scene_node *nd = &s->nodes[node];
	uint32_t i;
	for (i = nd->idx[c]; i < nd->idx[c] + nd->cnt[c]; i++)
		s->leaf_of[s->perm[i]] = 2 * node + (uint32_t)c;
}

/* Recursion depth is log2 of the capacity (median splits). */
static uint32_t build(struct px_scene *s, size_t b, size_t n, uint32_t up)
{
	uint32_t me = (uint32_t)s->n_nodes++;
	double clo[3], chi[3];
	size_t half, part[2][2];
	int c;

	s->parent[me] = up;
	px__key_bounds(s->perm + b, n, s->cen, clo, chi);
	half = px__median_split(s->perm + b, n, s->cen, clo, chi);
	part[0][0] = b;
	part[0][1] = half;
	part[1][0] = b + half;
	part[1][1] = n - half;
	for (c = 0; c < 2; c++) {
		struct scene_node *nd = &s->nodes[me];
		range_box(s, part[c][0], part[c][1], nd->lo[c], nd->hi[c]);
		if (part[c][1] <= SCENE_LEAF) {
			nd->idx[c] = (uint32_t)part[c][0];
			nd->cnt[c] = (uint32_t)part[c][1];
			mark_leaf(s, me, c);
		} else {
			uint32_t ch = build(s, part[c][0], part[c][1],
					    2 * me + (uint32_t)c);
			s->nodes[me].idx[c] = ch;
			s->nodes[me].cnt[c] = 0;
		}
	}
	return me;
}

/* The hierarchy anew over the current boxes. */
static void rebuild(struct px_scene *s)
{
	size_t i;
	int k;
	s->since = 0;
	s->built_n = s->n;
	s->n_nodes = 0;
	for (i = 0; i < s->n; i++)
		s->perm[i] = (uint32_t)i;
	if (s->n > SCENE_LEAF) {
		build(s, 0, s->n, SCENE_EMPTY);
		return;
	}
	{
		struct scene_node *nd = &s->nodes[0];
		s->n_nodes = 1;
		s->parent[0] = SCENE_EMPTY;
		range_box(s, 0, s->n, nd->lo[0], nd->hi[0]);
		nd->idx[0] = s->n ? 0 : SCENE_EMPTY;
		nd->cnt[0] = (uint32_t)s->n;
		mark_leaf(s, 0, 0);
		for (k = 0; k < 3; k++) {
			nd->lo[1][k] = INFINITY;
			nd->hi[1][k] = -INFINITY;
		}
		nd->idx[1] = SCENE_EMPTY;
		nd->cnt[1] = 0;
	}
}

int px_scene_update(struct px_scene *s)
{
	size_t i, j;
	if (!s)
		return PX_E_INVAL;
	for (i = 0; i < s->n; i++)
		refresh_box(s, i);
	s->stale = 0;
	if (s->built_n != s->n || s->n <= SCENE_LEAF || ++s->since >= REBUILD) {
		rebuild(s);
		return PX_OK;
	}
	/* children come after their parent (preorder): a reverse sweep
	 * sees every child before its parent */
	j = s->n_nodes;
	while (j-- > 0) {
		refit_child(s, j, 0);
		refit_child(s, j, 1);
	}
	return PX_OK;
}

/* ---- models ------------------------------------------------------------- */

static int add(struct px_scene *s, struct px_model *m, const char *name,
	       int owned)
{
	struct scene_entry *e;
	px_aabb b;
	double reach;
	if (!s || !m)
		return PX_E_INVAL;
	if (s->n >= s->cap)
		return PX_E_NOSPC;
	/* the box bounds square distances to it: a box beyond the models'
	 * reach would make them infinite and the model never nearest */
	b = px_model_local_aabb(m);
	reach = px_aabb_is_empty(&b) ? 0.0
		: fmax(fmax(fabs(b.min.x), fabs(b.max.x)),
		       fmax(fmax(fabs(b.min.y), fabs(b.max.y)),
			    fmax(fabs(b.min.z), fabs(b.max.z))));
	if (isfinite(reach) && reach > PX_MODEL_MAX_COORD)
		return PX_E_RANGE;
	e = &s->e[s->n];
	memset(e, 0, sizeof(*e));
	e->m = m;
	e->local = b;
	e->bounded = !px_aabb_is_empty(&b) && px_v3_isfinite(b.min) &&
		     px_v3_isfinite(b.max);
	e->is_signed = (px_model_caps(m) & PX_MODEL_CAP_SIGNED) != 0;
	e->owned = owned;
	if (name)
		snprintf(e->name, sizeof(e->name), "%s", name);
	refresh_box(s, s->n);
	return (int)s->n++;
}

int px_scene_add(struct px_scene *s, struct px_model *m, const char *name)
{
	int rc = add(s, m, name, 1);
	if (rc < 0) {
		px_model_free(m);
		return rc;
	}
	/* queries see an owned model at once (setup: O(n log n)) */
	if (!s->stale)
		rebuild(s);
	return rc;
}

int px_scene_add_kept(struct px_scene *s, struct px_model *m, int *id)
{
	int rc = add(s, m, NULL, 0);
	if (rc < 0)
		return rc;
	if (id)
		*id = rc;
	s->stale = 1;
	return PX_OK;
}

size_t px_scene_count(const struct px_scene *s)
{
	return s ? s->n : 0;
}

struct px_model *px_scene_model(const struct px_scene *s, size_t i)
{
	return s && i < s->n ? s->e[i].m : NULL;
}

const char *px_scene_name(const struct px_scene *s, size_t i)
{
	return s && i < s->n ? s->e[i].name : "";
}

int px_scene_set_pose(struct px_scene *s, size_t i, px_pose pose)
{
	uint32_t at;
	int rc;
	if (!s || i >= s->n)
		return PX_E_INVAL;
	rc = px_model_set_pose(s->e[i].m, pose);
	if (rc != PX_OK)
		return rc;
	refresh_box(s, i);
	if (i >= s->built_n)
		return PX_OK; /* not in the hierarchy yet: the update adds it */
	/* its leaf's box, then every ancestor's: O(depth) */
	at = s->leaf_of[i];
	for (;;) {
		refit_child(s, at / 2, (int)(at % 2));
		at = s->parent[at / 2];
		if (at == SCENE_EMPTY)
			return PX_OK;
	}
}

/* ---- tracking settings -------------------------------------------------- */

int px_scene_set_tracking(struct px_scene *s, bool enabled,
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

int px_scene_get_tracking(const struct px_scene *s,
			  struct px_model_stream_opts *o)
{
	if (!s)
		return PX_E_INVAL;
	if (o)
		*o = s->track_opts;
	return s->track_on ? 1 : 0;
}
