/*
 * mesh_internal.h - the triangle mesh model's data layout, shared by the
 * files that implement it (point queries in px_mesh.c, the exact
 * point-triangle test in mesh_tri.c, setup in mesh_build.c, mesh-to-mesh
 * queries in px_mesh_pair.c), with the box-tree and hint-grid setup
 * meshes and point clouds share (mesh_tree.c) and the file importer. Not
 * part of the public API.
 *
 * Memory and real-time rules: everything here is built at setup
 * (px_mesh_model, px_cloud_model) and read only by queries.
 */
#ifndef PX_MESH_INTERNAL_H
#define PX_MESH_INTERNAL_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include <math.h>

#ifdef __SSE__
#include <xmmintrin.h>
#endif

#include "px_math.h"
#include "px_mesh.h"

/* A triangle whose squared height over its longest edge is below this
 * fraction of that edge's squared length is a needle: degenerate for
 * topology and signs (no face normal, no share of the pseudo-normals; a
 * closest point inside it is reported on its nearest edge). Its distance
 * is still exact (mesh_tri.c's robust test). */
#define NEEDLE_SIN2 1e-20

/* struct mesh's degen[] per leaf triangle: DEGEN_ZERO a degenerate
 * triangle (collapsed or needle: no face normal, no share of the
 * pseudo-normals); DEGEN_SLOW one outside the fast point-triangle
 * test's bound (thin, or edges beyond 2^+-100: mesh_tri.c), which the
 * robust test answers. Either sends the query to the robust test. */
#define DEGEN_ZERO 1u
#define DEGEN_SLOW 2u
/* Bits 2-3: the vertex (1 or 2) the fast test pivots on for a triangle
 * thin only at its first vertex (0: the first). */
#define DEGEN_ROT_SHIFT 2

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
 * 1 / |n|^2, for the plane-distance lower bound: 0 for degenerate
 * triangles and for those whose plain normal is not accurate (DEGEN_SLOW:
 * thin, where it tilts by u / sin(angle), or of extreme size), so they
 * are never pruned by it; a value made on demand from the compact vertex
 * data (px__mtri_get), not stored. */
struct mtri {
	px_vec3 a, b, c;
	px_vec3 n;
	double inv_nn;
};

/*
 * Single-precision lower bound of a triangle's distance, one cache line
 * per triangle, read before the exact data: with unit normal n and plane
 * offset d, h = n . p - d is the distance to the plane; with the
 * in-plane outward unit normals m[e] of the edges and their offsets, the
 * largest m[e] . p - (its offset) is at most the in-plane distance to the
 * triangle (a convex polygon is the intersection of its edge half-planes),
 * so h^2 + max(0, that)^2 <= the squared distance, exact in the face and
 * edge regions. Degenerate triangles have all zeros (bound 0: never
 * rejected). Rounding is absorbed by the query's slack (tri_lb).
 */
struct tlb {
	/* by component, so the four values come out side by side:
	 * c[0..2][0] = n, c[3][0] = d; c[0..2][1 + e] = m[e], c[3][1 + e]
	 * its offset */
	float c[4][4];
} __attribute__((aligned(64)));

struct mesh {
	size_t nt, nv;
	/* Exact triangles, compactly: the distinct vertices numbered in leaf
	 * order (a leaf's triangles share their vertices' cache lines, and
	 * neighbouring leaves mostly do too) and three indices per leaf
	 * triangle - about 24 bytes a triangle where a stored triangle with
	 * its normal took 128, which is what keeps a large mesh's query
	 * data in cache. */
	px_vec3 *vx;
	uint32_t *tv;
	size_t n_vx;
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

/* The three vertices of leaf triangle li, where the normal is not
 * needed. RT-safe. */
struct mtri3 {
	px_vec3 a, b, c;
};

static inline struct mtri3 px__tri3_get(const struct mesh *M, size_t li)
{
	const uint32_t *v = M->tv + 3 * li;
	struct mtri3 t;
	t.a = M->vx[v[0]];
	t.b = M->vx[v[1]];
	t.c = M->vx[v[2]];
	return t;
}

/* Leaf triangle li as a struct mtri. The same operations as setup used,
 * so n and inv_nn do not depend on where they are made. RT-safe. */
static inline struct mtri px__mtri_get(const struct mesh *M, size_t li)
{
	struct mtri3 v = px__tri3_get(M, li);
	struct mtri t;
	t.a = v.a;
	t.b = v.b;
	t.c = v.c;
	t.n = px_v3_cross(px_v3_sub(t.b, t.a), px_v3_sub(t.c, t.a));
	t.inv_nn = M->degen[li] ? 0.0 : 1.0 / px_v3_norm2(t.n);
	return t;
}

/* ---- point-triangle distance (mesh_tri.c) ---------------------------------- */

/* compares, not fmax (a library call); NaN gives NaN or a smaller
 * value, which the callers' range tests (written to fail on NaN) see */
static inline double px__mx2(double a, double b)
{
	return a > b ? a : b;
}

static inline double px__amax3(px_vec3 v)
{
	return px__mx2(fabs(v.x), px__mx2(fabs(v.y), fabs(v.z)));
}

/* 2^-e with 2^e > x >= 2^(e-1) (x > 0 finite): multiplying by it is
 * exact and brings x into [0.5, 1). */
static inline double px__pow2_scale(double x, int *e)
{
	(void)frexp(x, e);
	return ldexp(1.0, -*e);
}

/* The robust point-triangle test (mesh_tri.c's opening comment): any
 * shape and scale, outputs as px_tri_closest's. RT-safe, bounded (it
 * calls itself at most once, for a far point). */
double px__tri_exact(px_vec3 p, px_vec3 a, px_vec3 b, px_vec3 c, px_vec3 *q,
		     int *feature, int *sub, double *u, double *v);

/*
 * Voronoi-region walk (the vertex, edge and face regions are decided by
 * the signs of dot products of p - vertex with the edges, as in Ericson,
 * Real-Time Collision Detection 5.1.5). The face point is taken by
 * projecting onto the plane along the cross-product normal rather than
 * from the barycentric ratios, which lose accuracy on thin triangles;
 * edge distances from p - a and the edge (no absolute coordinate).
 * n = (b - a) x (c - a), nn = |n|^2; robust: the fast path's bound does
 * not hold for this triangle or point (px__tri_exact instead). Inline:
 * the mesh walk's innermost test.
 */
static inline __attribute__((always_inline)) double
px__tri_core(px_vec3 p, px_vec3 a, px_vec3 b, px_vec3 c, px_vec3 n, double nn, int robust,
	     px_vec3 *q, int *feature, int *sub, double *u, double *v)
{
	px_vec3 ab = px_v3_sub(b, a), ac = px_v3_sub(c, a), ap = px_v3_sub(p, a);
	px_vec3 bp, cp;
	double d1, d2, d3, d4, d5, d6, va, vb, vc, t;

	if (robust)
		return px__tri_exact(p, a, b, c, q, feature, sub, u, v);

	d1 = px_v3_dot(ab, ap);
	d2 = px_v3_dot(ac, ap);
	if (d1 <= 0.0 && d2 <= 0.0) {
		*q = a;
		*feature = PX_FEATURE_VERTEX;
		*sub = 0;
		*u = *v = 0.0;
		return px_v3_norm2(ap);
	}
	bp = px_v3_sub(p, b);
	d3 = px_v3_dot(ab, bp);
	d4 = px_v3_dot(ac, bp);
	if (d3 >= 0.0 && d4 <= d3) {
		*q = b;
		*feature = PX_FEATURE_VERTEX;
		*sub = 1;
		*u = 1.0;
		*v = 0.0;
		return px_v3_norm2(bp);
	}
	vc = d1 * d4 - d3 * d2;
	if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
		t = d1 / (d1 - d3);
		*q = px_v3_madd(a, ab, t);
		*feature = PX_FEATURE_EDGE;
		*sub = 0;
		*u = t;
		*v = 0.0;
		return px_v3_norm2(px_v3_madd(ap, ab, -t));
	}
	cp = px_v3_sub(p, c);
	d5 = px_v3_dot(ab, cp);
	d6 = px_v3_dot(ac, cp);
	if (d6 >= 0.0 && d5 <= d6) {
		*q = c;
		*feature = PX_FEATURE_VERTEX;
		*sub = 2;
		*u = 0.0;
		*v = 1.0;
		return px_v3_norm2(cp);
	}
	vb = d5 * d2 - d1 * d6;
	if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
		t = d2 / (d2 - d6);
		*q = px_v3_madd(a, ac, t);
		*feature = PX_FEATURE_EDGE;
		*sub = 2;
		*u = 0.0;
		*v = t;
		return px_v3_norm2(px_v3_madd(ap, ac, -t));
	}
	va = d3 * d6 - d5 * d4;
	if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
		px_vec3 bc = px_v3_sub(c, b);
		t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
		*q = px_v3_madd(b, bc, t);
		*feature = PX_FEATURE_EDGE;
		*sub = 1;
		*u = 1.0 - t;
		*v = t;
		return px_v3_norm2(px_v3_madd(bp, bc, -t));
	}
	/* face region */
	{
		double s = px_v3_dot(n, ap) / nn;
		double den = va + vb + vc;
		*q = px_v3_madd(p, n, -s);
		*feature = PX_FEATURE_FACE;
		*sub = -1;
		*u = den != 0.0 ? vb / den : 0.0;
		*v = den != 0.0 ? vc / den : 0.0;
		return s * s * nn;
	}
}



/* The fast test with the vertices rotated by r (1 or 2: a' = P[r], b',
 * c' following): outputs mapped back to the caller's order. Out of
 * line: the rare path, kept out of the mesh walk's inlined common one.
 * RT-safe. */
double px__tri_core_rot(px_vec3 p, const px_vec3 P[3], int r, px_vec3 *q, int *feature,
			int *sub, double *u, double *v);

/*
 * Mesh setup's view of a triangle: its edges ab, ac, bc scaled by a
 * power of two to a largest component in [0.5, 1) (zero when all three
 * vertices coincide); *needle when its height is below sqrt(NEEDLE_SIN2)
 * of its edges (degenerate for topology and signs: no face normal; its
 * distance is still exact, by px__tri_exact); *fast when the fast test's
 * bound holds for it at vertex *rot (0: a, 1: b, 2: c). Setup.
 */
void px__tri_shape(px_vec3 a, px_vec3 b, px_vec3 c, px_vec3 *ab, px_vec3 *ac,
		   px_vec3 *bc, int *needle, int *fast, int *rot);

/* The accurate normal (b - a) x (c - a), as a unit vector (zero when
 * the scaled cross product vanishes). Setup and the robust path. */
px_vec3 px__unit_normal_acc(px_vec3 a, px_vec3 b, px_vec3 c);

/* Cell of a hint grid (gdim cells from corner org, 1 / cell size inv)
 * holding p, points outside taking the nearest cell. @note RT-safe. */
static inline size_t px__grid_cell(const int gdim[3], px_vec3 org, double inv,
				   px_vec3 p)
{
	double f[3] = {(p.x - org.x) * inv, (p.y - org.y) * inv, (p.z - org.z) * inv};
	size_t c[3];
	int k;
	for (k = 0; k < 3; k++) {
		/* clamp in double first: the cast is undefined out of range */
		double hi = (double)(gdim[k] - 1);
		c[k] = !(f[k] > 0.0) ? 0 : (f[k] >= hi ? (size_t)hi : (size_t)f[k]);
	}
	return (c[2] * (size_t)gdim[1] + c[1]) * (size_t)gdim[0] + c[0];
}

/* Leaf index of the hint triangle for p (the grid must exist).
 * @note RT-safe. */
static inline uint32_t px__mesh_grid_hint(const struct mesh *M, px_vec3 p)
{
	return M->grid[px__grid_cell(M->gdim, M->gorg, M->ginv, p)];
}

/* Layout of a hint grid of at most cap cells (>= 1) over box grown by
 * an eighth of its largest extent on every side: cubic cells of edge *h,
 * d[3] per axis, centred on the box, corner *org. Setup only. */
void px__grid_layout(px_aabb box, long cap, int d[3], px_vec3 *org, double *h);

/* Lay out a grid of at most cap cells over box (px__grid_layout: *dim
 * cells of edge *h, 1 / edge *inv, corner *org) and fill each cell of
 * *cell (malloc'ed, x fastest) with nearest(ctx, its centre, the
 * previous cell's answer): an element index, or < 0 for none (the
 * previous one is then kept). Returns the number of cells or
 * PX_E_NOMEM. Setup only. */
long px__grid_fill(px_aabb box, long cap, long (*nearest)(const void *ctx, px_vec3 c, long prev),
		   const void *ctx, uint32_t **cell, int dim[3], px_vec3 *org, double *h,
		   double *inv);

/* ---- between the mesh's files -------------------------------------------- */

/* Free a mesh (any part may be missing). Setup and teardown. */
void px__mesh_free(void *impl);

/* Wrap M into a model (px_mesh.c's operations; convex: with the support
 * function). The model owns M from here on, also when this fails.
 * Returns PX_OK or PX_E_NOMEM. Setup only. */
int px__mesh_wrap(struct mesh *M, int convex, struct px_model **out);

/* Leaf index of the triangle nearest c (an exact query of the finished
 * hierarchy, started from leaf triangle prev when >= 0), or -1 for none:
 * px__grid_fill's nearest for a mesh (ctx). Setup only. */
long px__mesh_grid_nearest(const void *ctx, px_vec3 c, long prev);

/* ---- shared with the point cloud's hierarchy (px_cloud.c) ---------- */

/* Double to float rounded down / up (boxes stay lower bounds). */
static inline float px__f_down(double x)
{
	float f = (float)x;
	return (double)f > x ? nextafterf(f, -INFINITY) : f;
}

static inline float px__f_up(double x)
{
	float f = (float)x;
	return (double)f < x ? nextafterf(f, INFINITY) : f;
}

/*
 * A binary tree over n elements by recursive splits of an index range
 * (meshes, clouds; any set of boxed elements, e.g. a scene's models):
 * perm[0..n) the elements, reordered into leaf order; key 3 doubles per
 * element (what splits sort: centroids, points). box(ctx, perm, n, lo,
 * hi) gives the bounds of elements perm[0..n); split(ctx, perm, n,
 * depth, klo, khi) (may be NULL) partitions perm[0..n) itself and
 * returns the size of the left part, or 0 to take the median split of
 * the widest key axis; store(nodes, node, c, lo, hi, idx, cnt) records
 * child c (0, 1) of node: a leaf range [idx, idx + cnt) (cnt > 0) or the
 * inner node idx (cnt 0), or an absent child (idx EMPTY, empty box: only
 * in a root that is one leaf) with its box. Ranges of at most leaf
 * elements are leaves. box_is_key: the box of a range is its keys'
 * bounds (points), reused for its split. Setup only; recursion as deep
 * as the tree (callers check the depth against their stacks).
 */
struct px__tree_build {
	uint32_t *perm;
	const double *key;
	size_t leaf;
	int box_is_key;
	void *ctx;
	void (*box)(void *ctx, const uint32_t *perm, size_t n, double lo[3], double hi[3]);
	size_t (*split)(void *ctx, uint32_t *perm, size_t n, int depth, const double klo[3],
			const double khi[3]);
	void (*store)(void *nodes, uint32_t node, int c, const double lo[3], const double hi[3],
		      uint32_t idx, uint32_t cnt);
	void *nodes;    /* the node array store() writes */
	size_t n_nodes; /* out: nodes stored (the root is node 0) */
	int depth;      /* out: depth of the deepest node (the root's is 0) */
};

void px__tree_build(struct px__tree_build *B, size_t n);

/* px__tree_build's store for an array of struct node: boxes rounded
 * outwards to float. */
void px__node_store(void *nodes, uint32_t me, int c, const double lo[3], const double hi[3],
		    uint32_t idx, uint32_t cnt);

/* Write a report message into msg (cap bytes) unless one is there
 * already (the first problem is the one reported); msg may be NULL.
 * Setup only. */
void px__report_msg(char *msg, size_t cap, const char *fmt, ...)
	__attribute__((format(printf, 3, 4)));

/* Collapse the binary tree bn (root b) into four-wide nodes appended to
 * n4 (room for as many as bn has); returns the index of the new node.
 * Setup only. */
uint32_t px__node4_collapse(const struct node *bn, struct node4 *n4,
			    size_t *n_n4, uint32_t b);

/* Squared distances from p to the four child boxes (+inf for absent
 * children, whose boxes are empty). */
static inline void px__box4_d2(const struct node4 *nd, px_vec3 p, double d2[4])
{
	int j;
	for (j = 0; j < 4; j++) {
		double dx = (double)nd->lo[0][j] - p.x, ex = p.x - (double)nd->hi[0][j];
		double dy = (double)nd->lo[1][j] - p.y, ey = p.y - (double)nd->hi[1][j];
		double dz = (double)nd->lo[2][j] - p.z, ez = p.z - (double)nd->hi[2][j];
		dx = dx > ex ? dx : ex;
		dy = dy > ey ? dy : ey;
		dz = dz > ez ? dz : ez;
		dx = dx > 0.0 ? dx : 0.0;
		dy = dy > 0.0 ? dy : 0.0;
		dz = dz > 0.0 ? dz : 0.0;
		d2[j] = dx * dx + dy * dy + dz * dz;
	}
}

/*
 * The same four lower bounds in single precision, side by side (the
 * compiler turns the loops into packed operations): half the work of the
 * double version per node. Rounding p and the differences to float can
 * overstate a gap by at most 2^-24 (2 |p| + |box|) per axis, so every gap
 * is first reduced by slack = 2^-22 (|box| + |p|) (max norms, given by
 * the caller), and the squared sum, itself rounded up to six times by
 * 2^-24 relative, is scaled by 1 - 2^-18: the result stays a lower bound
 * of the true squared distance, so pruning with it never loses the
 * closest triangle. Callers use it only while |p| and the mesh stay below
 * 1e18, so no square overflows the float range (callers fall back to
 * px__box4_d2 otherwise).
 */
static inline void px__box4_d2f(const struct node4 *nd, const float pf[3],
			    float slack, double d2[4])
{
	float s[4];
	int j;
#ifdef __SSE__
	/* the same operations as below, four children per instruction (the
	 * compiler does not vectorise the loops at -O2) */
	__m128 sl = _mm_set1_ps(slack), z = _mm_setzero_ps(), acc = z;
	int k;
	for (k = 0; k < 3; k++) {
		__m128 p = _mm_set1_ps(pf[k]);
		__m128 a = _mm_sub_ps(_mm_load_ps(nd->lo[k]), p);
		__m128 b = _mm_sub_ps(p, _mm_load_ps(nd->hi[k]));
		__m128 g = _mm_max_ps(_mm_sub_ps(_mm_max_ps(a, b), sl), z);
		acc = _mm_add_ps(acc, _mm_mul_ps(g, g));
	}
	_mm_storeu_ps(s, acc);
#else
	float g[3][4];
	int k;
	for (k = 0; k < 3; k++)
		for (j = 0; j < 4; j++) {
			float a = nd->lo[k][j] - pf[k], b = pf[k] - nd->hi[k][j];
			float m = (a > b ? a : b) - slack;
			g[k][j] = m > 0.0f ? m : 0.0f;
		}
	for (j = 0; j < 4; j++)
		s[j] = g[0][j] * g[0][j] + g[1][j] * g[1][j] + g[2][j] * g[2][j];
#endif
	for (j = 0; j < 4; j++)
		d2[j] = (double)s[j] * (1.0 - 0x1p-18);
}

/* One entry of the 4-wide box-tree walks' stacks (meshes and clouds): a
 * node (cnt == 0, its index idx) or a leaf range [idx, idx + cnt), with
 * the lower bound d2 of its squared distance where the walk keeps one. */
struct px__walk4 {
	uint32_t idx, cnt;
	double d2;
};

/* The within-radius walk of the tree n4 (root node 0) about p: every leaf
 * range [i0, i0 + n) under boxes within squared distance r2 goes to
 * leaf(ctx, i0, n), which returns 0 to go on or a negative error that
 * ends the walk. st holds cap entries (enough for the depth checked at
 * setup; a child past it is skipped). Returns 0 or leaf's error. RT-safe;
 * inline, so that leaf() is called directly. */
static inline int px__box4_within(const struct node4 *n4, px_vec3 p, double r2,
				  struct px__walk4 *st, int cap,
				  int (*leaf)(void *ctx, uint32_t i0, uint32_t n),
				  void *ctx)
{
	int sp = 0, rc;
	st[sp].idx = 0;
	st[sp].cnt = 0;
	sp++;
	while (sp > 0) {
		sp--;
		if (st[sp].cnt > 0) {
			rc = leaf(ctx, st[sp].idx, st[sp].cnt);
			if (rc < 0)
				return rc;
		} else {
			const struct node4 *nd = &n4[st[sp].idx];
			double dc[4];
			int c;
			px__box4_d2(nd, p, dc);
			for (c = 0; c < 4; c++) {
				if (nd->idx[c] == EMPTY || dc[c] > r2 || sp >= cap)
					continue;
				st[sp].idx = nd->idx[c];
				st[sp].cnt = nd->cnt[c];
				sp++;
			}
		}
	}
	return 0;
}

/*
 * The nearest-first walk of the tree n4 (root node 0), meshes' and
 * clouds' point query: pops the entry nearest by its bound, skips it
 * when the bound is past *best (or equal once *found >= 0), hands a leaf
 * range [i0, i0 + n) to leaf(ctx, i0, n), which improves *best and
 * *found, and expands a node: bounds(ctx, node index, node, d2) gives its
 * four children's lower bounds of the squared distance, and the children
 * that can still win are pushed farthest first (so the nearest is
 * expanded first), each announced to fetch(ctx, idx, cnt) to start its
 * memory loads. st holds cap entries (enough for the depth checked at
 * setup: past it a child is dropped and 0 returned, else 1). *iters
 * counts the entries expanded. RT-safe; inline so that the callbacks are
 * called directly (the walk is the query's hot loop).
 */
static inline __attribute__((always_inline)) int
px__box4_nearest(const struct node4 *n4, struct px__walk4 *st, int cap, const double *best,
		 const long *found, void (*leaf)(void *ctx, uint32_t i0, uint32_t n),
		 void (*bounds)(void *ctx, uint32_t node, const struct node4 *nd, double d2[4]),
		 void (*fetch)(void *ctx, uint32_t idx, uint32_t cnt), void *ctx, int *iters)
{
	int sp = 0, certified = 1;

	st[sp].idx = 0;
	st[sp].cnt = 0;
	st[sp].d2 = 0.0;
	sp++;
	while (sp > 0) {
		const struct node4 *nd;
		double dc[4];
		int ord[4], no = 0, j, c;

		sp--;
		if (st[sp].d2 > *best || (st[sp].d2 == *best && *found >= 0))
			continue;
		(*iters)++;
		if (st[sp].cnt > 0) {
			leaf(ctx, st[sp].idx, st[sp].cnt);
			continue;
		}
		nd = &n4[st[sp].idx];
		bounds(ctx, st[sp].idx, nd, dc);
		/* children that can still win, nearest first */
		for (j = 0; j < 4; j++) {
			if (nd->idx[j] == EMPTY || dc[j] > *best)
				continue;
			for (c = no; c > 0 && dc[ord[c - 1]] > dc[j]; c--)
				ord[c] = ord[c - 1];
			ord[c] = j;
			no++;
		}
		for (c = no - 1; c >= 0; c--) {
			j = ord[c];
			if (sp >= cap) {
				certified = 0; /* cannot happen: depth checked at setup */
				continue;
			}
			st[sp].idx = nd->idx[j];
			st[sp].cnt = nd->cnt[j];
			st[sp].d2 = dc[j];
			fetch(ctx, st[sp].idx, st[sp].cnt);
			sp++;
		}
	}
	return certified;
}

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

/*
 * Whether points P[0..n-1] need a frame of their own before the pair
 * formulas (products of four differences: cross-product line parameters,
 * plane tests) are safe and translation-free: 1 when their extent about
 * o is outside [2^-100, 2^100] or their coordinates exceed 2^26 times
 * it; then *s = 2^-*e brings the extent into [0.5, 1) (exact) and the
 * caller works on (P - o) s, returning squared distances times 2^(2 e).
 * 0 (nothing to do) otherwise, and also for an extent of 0 (then *e =
 * INT_MIN: every point is o). RT-safe.
 */
int px__pair_frame(const px_vec3 *P, int n, px_vec3 o, double *s, int *e);

/* u x w with one rounding per component (error-free products by fma):
 * accurate also for nearly parallel vectors. RT-safe. */
px_vec3 px__cross_acc(px_vec3 u, px_vec3 w);

/* Unit normal of triangle abc, accurate to a few u in direction for any
 * shape and scale (the plain cross product where the fast point-triangle
 * test's bound holds, the error-free one elsewhere: mesh_tri.c); zero for
 * a triangle without area. RT-safe. */
px_vec3 px__tri_unit_normal(px_vec3 a, px_vec3 b, px_vec3 c);

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

/*
 * Read a mesh or point file with the Open Asset Import Library: all
 * meshes of the scene with their node transforms applied (a mesh that no
 * node references, as for a faceless PLY, is taken as it is), polygons
 * triangulated. want_tri: collect triangles (other primitives are
 * skipped and counted in *n_skipped); else only vertices. On success
 * *xyz (3 doubles per vertex) and *tri (3 per triangle, NULL when
 * !want_tri) are malloc'ed and owned by the caller. On failure msg holds
 * "<path>: <reason>". The file is read once, at most
 * PX_FILE_MODEL_MAX_BYTES, and the importer parses those bytes. PLY
 * files are checked against their header first (x, y, z required); a
 * PLY read for points (!want_tri) is read exactly by that check, without
 * the importer; a mesh (PLY, ASCII STL, OBJ) whose coordinates would
 * move by more than 1e-5 of its extent in the importer's single
 * precision is PX_E_RANGE.
 * Returns PX_OK, PX_E_INVAL, PX_E_NOTFOUND, PX_E_IO, PX_E_PARSE,
 * PX_E_RANGE, PX_E_NOMEM, PX_E_OVERFLOW. Setup only.
 */
int px__import_file(const char *path, int want_tri, double **xyz,
		    size_t *nv, uint32_t **tri, size_t *nt, size_t *n_skipped,
		    char *msg, size_t msg_cap);
/* The same for bytes already read (px__import_read()); data stays the
 * caller's. */
int px__import_data(const char *path, char *data, size_t len, int want_tri,
		    double **xyz, size_t *nv, uint32_t **tri, size_t *nt,
		    size_t *n_skipped, char *msg, size_t msg_cap);

/* px_mesh_load_scaled() of bytes already read; scale may be NULL. */
int px__mesh_load_data(const char *path, char *data, size_t len,
		       const double scale[3], const struct px_mesh_opts *opt,
		       struct px_mesh_report *rep, struct px_model **out);

/* ---- mesh_ply.c: the importer's parts that need no importer library
 * (so that PLY point clouds load in a build without assimp). Setup only. */

/* The file once, at most PX_FILE_MODEL_MAX_BYTES (.obj and .off as
 * text): *data (malloc'ed) and *len; an empty file is PX_E_PARSE. */
int px__import_read(const char *path, char **data, size_t *len, char *msg,
		    size_t msg_cap);
/* A PLY: the magic line, or a .ply name (the check sees those too). */
int px__ply_file(const char *path, const char *data, size_t len);
/* The PLY's structure checked against its header, element by element,
 * and its vertices' x, y, z read exactly as doubles into *xyz
 * (malloc'ed, 3 per vertex, *nv of them). want_tri: a file without
 * faces is PX_E_PARSE "<path>: no triangles in the file" (a cloud).
 * Returns PX_OK, PX_E_PARSE, PX_E_IO or PX_E_NOMEM. */
int px__ply_read(const char *path, char *data, size_t len, int want_tri,
		 double **xyz, size_t *nv, char *msg, size_t msg_cap);
/* An unsigned integer of size bytes (big: big-endian). */
unsigned long long px__ply_uint(const unsigned char *b, int size, int big);
/* A decimal number as the importer's parser reads it: sign, digits with
 * an optional point, optional exponent; or nan / inf (strtod() alone
 * would also take hexadecimal floats). */
int px__num_ok(const char *t);
/* A reader over len bytes at data: NULL with msg on failure. */
FILE *px__mem_stream(const char *path, char *data, size_t len, char *msg,
		     size_t msg_cap);
/* s ends with ext, ignoring case. */
int px__ends_with_ci(const char *s, const char *ext);

/* Point cloud hint grid (px_cloud.c), for tests: the input index of the
 * point the grid names for p, and the centre of p's cell (clamped to the
 * grid); -1 when m is not a cloud or has no grid. RT-safe. */
struct px_model;
long px__cloud_grid_hint(const struct px_model *m, px_vec3 p, px_vec3 *centre);

/* A point cloud's hierarchy, read only, for the pair traversals: the
 * four-wide tree (root node 0; a leaf range indexes pt), the points in
 * leaf order with their input indices (orig) and back (leaf_of), the
 * points' box in the cloud's frame, the largest |coordinate| and the
 * point radius. */
struct px__cloud_view {
	const struct node4 *n4;
	const px_vec3 *pt;
	const uint32_t *orig, *leaf_of;
	size_t n;
	px_aabb box;
	double absmax, radius;
};

/* Fills *v and returns 1 when m is a point cloud, else 0. RT-safe. */
int px__cloud_view(const struct px_model *m, struct px__cloud_view *v);

/*
 * Exact distance between the surface of mesh model a and the points of
 * cloud model c (their centres: the point radius is the caller's) at
 * their poses, by a simultaneous depth-first traversal of both
 * hierarchies as px__mesh_pair's (box pairs bounded below in both
 * frames and along the line of centres; a mesh leaf against a cloud
 * leaf by exact point-triangle distances). hint_tri, hint_pt: last
 * cycle's triangle and point (input order; -1: none), the first bound.
 * out: tri_a the triangle, tri_b the point. Unsigned: inside a closed
 * mesh is the caller's (px__cloud_min_model). RT-safe: no allocation,
 * a fixed stack.
 */
int px__mesh_cloud_pair(const struct px_model *a, const struct px_model *c, int hint_tri,
			int hint_pt, struct px__mesh_pair *out);

#endif
