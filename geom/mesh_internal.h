/*
 * mesh_internal.h - the triangle mesh model's data layout, shared by the
 * files that implement it (point queries in px_mesh.c, mesh-to-mesh
 * queries beside it). Not part of the public API.
 *
 * Memory and real-time rules: everything here is built at setup
 * (px_mesh_create) and read only by queries.
 */
#ifndef PX_MESH_INTERNAL_H
#define PX_MESH_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include "px_math.h"
#include "px_mesh.h"

/* A triangle whose height over its longest edge is below this fraction
 * of that edge is a needle: its distance is taken as that of its three
 * edges (error at most this fraction of the edge length). */
#define NEEDLE_SIN2 1e-20

/* Two children per node, each with its box; cnt > 0 marks a leaf range
 * [idx, idx + cnt) of the reordered triangles, cnt == 0 an inner node
 * idx, and idx == EMPTY an absent child (only in a one-leaf root). */
#define EMPTY 0xffffffffu
struct node {
	float lo[2][3], hi[2][3]; /* rounded outwards: still lower bounds */
	uint32_t idx[2], cnt[2];
} __attribute__((aligned(64)));

/* The query hierarchy: the binary tree collapsed to four children per
 * node (each node takes its children and grandchildren), which halves
 * the number of dependent memory fetches on the way down. Boxes per axis
 * and child, so the four distances are computed side by side. */
struct node4 {
	float lo[3][4], hi[3][4];
	uint32_t idx[4], cnt[4];
} __attribute__((aligned(64)));

#define STACK4 (3 * PX_MESH_MAX_DEPTH + 4)

/* Triangle with its (unnormalized) normal n = (b - a) x (c - a) and
 * 1 / |n|^2, for the plane-distance lower bound. */
struct mtri {
	/* first cache line: what the plane lower bound reads */
	px_vec3 a;
	px_vec3 n;
	double inv_nn;
	double pad_;
	/* second line: only for triangles the bound does not reject */
	px_vec3 b, c;
} __attribute__((aligned(64)));

/*
 * Single-precision lower bound of a triangle's distance, one cache line
 * per triangle, read before the exact data: with unit normal n and plane
 * offset d, h = n . p - d is the distance to the plane; with the
 * in-plane outward unit normals m[e] of the edges and their offsets, the
 * largest m[e] . p - m[e][3] is at most the in-plane distance to the
 * triangle (a convex polygon is the intersection of its edge half-planes),
 * so h^2 + max(0, that)^2 <= the squared distance, exact in the face and
 * edge regions. Degenerate triangles have all zeros (bound 0: never
 * rejected). Rounding is absorbed by the query's slack (tri_lb).
 */
struct tlb {
	float n[3], d;
	float m[3][4];
} __attribute__((aligned(64)));

struct mesh {
	size_t nt, nv;
	struct mtri *tri;    /* leaf order */
	struct tlb *lb;      /* leaf order: float lower-bound data */
	uint32_t *orig;      /* leaf -> input triangle */
	uint32_t *leaf_of;   /* input -> leaf */
	px_vec3 *fn;         /* face normal per leaf triangle (0 if degenerate) */
	px_vec3 *en;         /* 3 edge pseudo-normals per leaf triangle */
	px_vec3 *vnt;        /* 3 vertex pseudo-normals per leaf triangle */
	uint8_t *degen;      /* per leaf triangle */
	struct node *nodes;  /* binary tree: setup only, freed after collapsing */
	size_t n_nodes;
	struct node4 *n4;
	size_t n_n4;
	int closed;
	int depth;
	px_aabb box;
	double absmax;       /* largest |coordinate| of the vertices */
	size_t bytes;
	px_vec3 *hull;  /* distinct vertices, convex meshes only (support) */
	size_t n_hull;
	uint32_t *adj_start; /* n_hull + 1 offsets into adj (vertex graph) */
	uint32_t *adj;
	uint32_t ext[6];     /* vertices extreme along -x, +x, -y, +y, -z, +z */
};

/* ---- mesh-to-mesh distance (px_mesh_pair.c) ------------------------------ */

/*
 * Exact distance between triangles A and B (any shape, also collapsed or
 * needle): the squared distance, a closest point on each, and *crossing
 * = 1 when an edge of one passes through the other (then both points are
 * that crossing point and the distance is 0). Separated triangles: the
 * least of the nine edge-edge and six vertex-triangle distances.
 * RT-safe.
 */
double px__tri_tri(const px_vec3 A[3], const px_vec3 B[3], px_vec3 *pa,
		   px_vec3 *pb, int *crossing);

/* Answer of px__mesh_pair(). */
struct px__mesh_pair {
	double distance;      /* >= 0: between the two surfaces */
	px_vec3 point_a, point_b; /* world frame */
	int tri_a, tri_b;     /* triangles (input order) */
	int intersecting;     /* the surfaces touch or cross (distance 0) */
	int nodes;            /* node pairs expanded */
	int tri_tests;        /* exact triangle-pair distances computed */
	int certified;        /* 0 only if the fixed stack ran out (cannot
			       * happen with depths checked at setup) */
};

/*
 * Exact distance between the surfaces of mesh models a and b at their
 * poses, by a simultaneous depth-first traversal of both hierarchies.
 * hint_a, hint_b: triangles (input order) of last cycle's closest pair,
 * tested first as the starting bound (-1 for none; wrong hints only cost
 * time). Returns PX_OK, PX_E_INVAL (NULL, or a model that is not a
 * mesh). RT-safe: a fixed stack of MP_STACK entries (about 4 kB).
 */
int px__mesh_pair(const struct px_model *a, const struct px_model *b,
		  int hint_a, int hint_b, struct px__mesh_pair *out);

/*
 * Lower-bounded search of mesh model m against any model o: visits the
 * mesh's hierarchy nearest node first, bounds each node box from below
 * by the distance of o to its centre (unsigned: 0 inside a closed o)
 * minus its half diagonal, and calls tri(ctx, v, index, &d) for every
 * triangle (world-frame vertices v, input index) whose box bound is
 * below *best (minus a relative 1e-12); tri returns 0 or a negative
 * error and sets d to the exact distance between the triangle and o (or
 * INFINITY when it cannot tell: the search then reports it, see below).
 * *best (in: an upper bound, e.g. a found distance; out: the least
 * distance seen) and *best_tri are updated. Returns 1 when every node
 * and triangle was either bounded out or measured exactly (the result is
 * the global minimum), 0 when some triangle could not be measured or the
 * point-query budget max_queries ran out, or a negative error. RT-safe.
 */
int px__mesh_vs_model(const struct px_model *m, const struct px_model *o,
		      int (*tri)(void *ctx, const px_vec3 v[3], int index,
				 double *d),
		      void *ctx, int max_queries, double *best, int *best_tri,
		      int *queries);

#endif
