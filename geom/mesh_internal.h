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
	/* Hint grid for cold queries: cubic cells over the box grown by a
	 * margin, each holding the leaf index of the triangle closest to
	 * the cell's centre (exact, computed at setup). Any triangle's
	 * distance is an upper bound of the answer, and this one's is
	 * within a cell diagonal of it, so the walk starts as a coherent
	 * query does. Points outside the grid take the nearest cell.
	 * grid == NULL: no grid (cold queries start unbounded). */
	uint32_t *grid;      /* gdim[0] * gdim[1] * gdim[2] cells, x fastest */
	int gdim[3];
	px_vec3 gorg;        /* lower corner of cell (0, 0, 0) */
	double gcell;        /* cell edge length */
	double ginv;         /* 1 / gcell */
};

/* Leaf index of the hint triangle for p (the grid must exist).
 * @note RT-safe. */
static inline uint32_t px__mesh_grid_hint(const struct mesh *M, px_vec3 p)
{
	double f[3] = {(p.x - M->gorg.x) * M->ginv, (p.y - M->gorg.y) * M->ginv,
		       (p.z - M->gorg.z) * M->ginv};
	size_t c[3];
	int k;
	for (k = 0; k < 3; k++) {
		/* clamp in double first: the cast is undefined out of range */
		double hi = (double)(M->gdim[k] - 1);
		c[k] = !(f[k] > 0.0) ? 0 : (f[k] >= hi ? (size_t)hi : (size_t)f[k]);
	}
	return M->grid[(c[2] * (size_t)M->gdim[1] + c[1]) * (size_t)M->gdim[0] + c[0]];
}

#endif
