/*
 * scene_internal.h - the scene's layout, shared by its model list and
 * hierarchy (px_scene.c) and its queries (px_scene_query.c).
 */
#ifndef PX_SCENE_INTERNAL_H
#define PX_SCENE_INTERNAL_H

#include <stdint.h>

#include "px_scene.h"

#define SCENE_LEAF 2           /* models per hierarchy leaf, at most */
#define SCENE_STACK 64         /* depth <= log2(PX_SCENE_MAX_CAPACITY) + 2 */
#define SCENE_EMPTY 0xffffffffu

struct scene_entry {
	struct px_model *m;
	px_aabb local;  /* model-frame box, cached at add */
	int bounded;    /* every bound finite */
	int is_signed;  /* PX_MODEL_CAP_SIGNED */
	int owned;      /* freed with the scene */
	char name[PX_SCENE_NAME_LEN];
};

/* A node holds two children, each a subtree (cnt 0, idx its node) or a
 * leaf (cnt models at perm[idx ..]); lo/hi are the children's boxes. */
struct scene_node {
	double lo[2][3], hi[2][3];
	uint32_t idx[2], cnt[2];
};

struct px_scene {
	size_t cap, n;
	bool track_on;
	struct px_model_stream_opts track_opts;
	int stale;             /* kept models added since the last update */
	size_t built_n;        /* models in the hierarchy */
	size_t n_nodes;
	unsigned since;        /* updates since the last rebuild */
	struct scene_entry *e; /* [cap] */
	px_aabb *box;          /* [cap] world box per model */
	double *cen;           /* [3 cap] box centres, the build's keys */
	struct scene_node *nodes;  /* [cap + 1], preorder */
	uint32_t *perm;        /* [cap] leaf order -> model */
	uint32_t *leaf_of;     /* [cap] model -> 2 * node + child of its leaf */
	uint32_t *parent;      /* [cap + 1] node -> 2 * parent + child */
};

/* Shrink a box distance by a relative 1e-9 so that rounding in the box
 * transform never makes it exceed the true distance. */
static inline double scene_shrink(double d)
{
	return d * (1 - 1e-9) - 1e-12;
}

#endif
