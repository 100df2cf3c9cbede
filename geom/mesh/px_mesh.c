/*
 * px_mesh.c - triangle mesh model: the point queries (the walk of the
 * four-wide box hierarchy with float lower bounds, the exact triangle
 * test, the sign from pseudo-normals), the cache and support operations,
 * accessors and loading. Setup: mesh_build.c.
 */
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mesh_internal.h"
#include "model_internal.h"
#include "px_mesh.h"


/* ---- query --------------------------------------------------------------- */

struct best {
	double d2;
	long li;
	px_vec3 q;
	int feature, sub;
	double u, v;
};

/* Query point in single precision with the slack that covers the
 * rounding of the float bounds (px__box4_d2f, tri_lb); use = 0 when p or the
 * mesh is too far out for floats (then only exact tests are made). */
struct pq {
	float pf[3];
	float slack_box, slack_tri;
	int use;
	int fast; /* p and the mesh in the fast triangle test's range */
};

static inline void pq_init(const struct mesh *M, px_vec3 p, struct pq *q)
{
	double pmax = fmax(fabs(p.x), fmax(fabs(p.y), fabs(p.z)));
	/* Differences stay below 4e18 and their squares (and sums of three)
	 * far below FLT_MAX; beyond that a float square overflows to inf,
	 * which would prune the closest box or triangle. */
	q->fast = pmax < 1e18 && M->absmax < 1e18;
	/* and above 2^-40: a float square below 2^-126 rounds by up to
	 * 2^-150 absolute, which only the slack's margin over the real
	 * rounding (at least 2^-24 (|p| + |mesh|), squared) absorbs; at
	 * 1e-20 scale a bound overstated that way pruned the closest
	 * needle of test_accuracy's meshes */
	q->use = q->fast && M->absmax + pmax >= 0x1p-40;
	q->pf[0] = (float)p.x;
	q->pf[1] = (float)p.y;
	q->pf[2] = (float)p.z;
	q->slack_box = (float)(0x1p-22 * (M->absmax + pmax));
	/* plane and edge values: unit vectors and offsets rounded to float
	 * (2^-24 relative each), three products and sums, the rounded p:
	 * together below 16 * 2^-24 (|p| + |mesh|); twice that here */
	q->slack_tri = (float)(0x1p-19 * (M->absmax + pmax));
}

/* Lower bound of the squared distance to leaf triangle li (see struct
 * tlb); only when q->use. */
static inline double tri_lb(const struct tlb *L, const struct pq *q)
{
	const float *P = q->pf;
	float h, e;
#ifdef __SSE__
	/* the four values in one pass, in the scalar order of operations
	 * (((x P0 + y P1) + z P2) - w), so the rounding argument holds */
	__m128 v = _mm_sub_ps(
		_mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_load_ps(L->c[0]), _mm_set1_ps(P[0])),
				      _mm_mul_ps(_mm_load_ps(L->c[1]), _mm_set1_ps(P[1]))),
			   _mm_mul_ps(_mm_load_ps(L->c[2]), _mm_set1_ps(P[2]))),
		_mm_load_ps(L->c[3]));
	__m128 s1 = _mm_shuffle_ps(v, v, _MM_SHUFFLE(3, 3, 2, 1)); /* e0 e1 e2 e2 */
	__m128 mx = _mm_max_ps(s1, _mm_movehl_ps(s1, s1));        /* max(e0,e2) max(e1,e2) */
	mx = _mm_max_ss(mx, _mm_shuffle_ps(mx, mx, _MM_SHUFFLE(1, 1, 1, 1)));
	h = _mm_cvtss_f32(v);
	e = _mm_cvtss_f32(mx) - q->slack_tri;
#else
	float v[4];
	int j;
	for (j = 0; j < 4; j++)
		v[j] = L->c[0][j] * P[0] + L->c[1][j] * P[1] + L->c[2][j] * P[2] - L->c[3][j];
	h = v[0];
	e = v[1] > v[2] ? v[1] : v[2];
	e = (e > v[3] ? e : v[3]) - q->slack_tri;
#endif
	h = (h < 0.0f ? -h : h) - q->slack_tri;
	e = e > 0.0f ? e : 0.0f;
	h = h > 0.0f ? h : 0.0f;
	return (double)(h * h + e * e) * (1.0 - 0x1p-18);
}

/*
 * A degenerate triangle (needle: no face normal, so no face feature for
 * the sign) whose exact closest point lies inside it: the edge nearest
 * that point names the feature (its pseudo-normal gives the sign). The
 * distance from the point with barycentric weights w to the line of the
 * edge opposite vertex k is w[k] times that vertex's height, 2 area /
 * |edge|: so the least w[k] / |edge k'| wins. RT-safe.
 */
static int face_as_edge(px_vec3 a, px_vec3 b, px_vec3 c, double u, double v,
			int *sub)
{
	/* edge e (0: ab, 1: bc, 2: ca) is opposite vertex (e + 2) % 3 */
	double w[3] = {1.0 - u - v, u, v};
	double l[3] = {px_v3_dist(a, b), px_v3_dist(b, c), px_v3_dist(c, a)};
	int e, be = 0;
	for (e = 1; e < 3; e++)
		if (w[(e + 2) % 3] * l[be] < w[(be + 2) % 3] * l[e])
			be = e;
	*sub = be;
	return PX_FEATURE_EDGE;
}

/* A tie of squared distances (a far point: they round to one value)
 * decided by |q - r|^2 - 2 (p - r) . (q - r) < 0, r the best point so
 * far (= |p - q|^2 - |p - r|^2, without the rounding of the squares):
 * the truly nearer feature then holds the answer and gives the sign. */
static int nearer_than_best(px_vec3 p, px_vec3 q, const struct best *b)
{
	px_vec3 x = px_v3_sub(q, b->q);
	return px_v3_norm2(x) - 2.0 * px_v3_dot(px_v3_sub(p, b->q), x) < 0.0;
}

/* plane_done: the caller's float bound (tri_lb) already compared the
 * plane distance, so the double one here would repeat it. */
static inline void test_tri_x(const struct mesh *M, size_t li, px_vec3 p,
			      struct best *b, int plane_done, int fast)
{
	const uint32_t *vi = M->tv + 3 * li;
	px_vec3 ta = M->vx[vi[0]], tb = M->vx[vi[1]], tc = M->vx[vi[2]], n, q;
	int f, s, robust, rot;
	double u, v, d2, nn;

	n = px_v3_cross(px_v3_sub(tb, ta), px_v3_sub(tc, ta));
	/* |n|^2 as px_tri_closest computes it (a product, not a division);
	 * 1 / |n|^2 (px__mtri_get) is 0 exactly for these */
	nn = px_v3_norm2(n);
	/* degenerate, or a shape or size outside the fast test's bound
	 * (set at setup, DEGEN_*), or a point too far out for it; a
	 * triangle thin only at a takes the fast test from another vertex */
	robust = (M->degen[li] & (DEGEN_ZERO | DEGEN_SLOW)) || !fast;
	rot = M->degen[li] >> DEGEN_ROT_SHIFT;
	if (!plane_done && !robust && !rot) {
		/* the distance to the plane is a lower bound (compared
		 * without a division; the factor keeps rounding from ever
		 * rejecting a triangle whose plane distance equals the bound) */
		double h = px_v3_dot(n, px_v3_sub(p, ta));
		if (h * h > b->d2 * nn * (1.0 + 1e-12))
			return;
	}
	if (rot && !robust) {
		px_vec3 P[3] = {ta, tb, tc};
		d2 = px__tri_core_rot(p, P, rot, &q, &f, &s, &u, &v);
	} else {
		d2 = px__tri_core(p, ta, tb, tc, n, nn, robust, &q, &f, &s, &u, &v);
	}
	if ((M->degen[li] & DEGEN_ZERO) && f == PX_FEATURE_FACE)
		f = face_as_edge(ta, tb, tc, u, v, &s);
	if (d2 < b->d2 ||
	    (d2 == b->d2 && (b->li < 0 || ((M->degen[b->li] & DEGEN_ZERO) &&
					   !(M->degen[li] & DEGEN_ZERO)) ||
			     nearer_than_best(p, q, b)))) {
		b->d2 = d2;
		b->li = (long)li;
		b->q = q;
		b->feature = f;
		b->sub = s;
		/* what mesh_finish reads if this stays the answer: fetched
		 * while the walk goes on, not after it */
		__builtin_prefetch(&M->orig[li]);
		__builtin_prefetch(f == PX_FEATURE_FACE   ? &M->fn[li]
				   : f == PX_FEATURE_EDGE ? &M->en[3 * li + (size_t)s]
							  : &M->vnt[3 * li + (size_t)s]);
		b->u = u;
		b->v = v;
	}
}

/* 1 when p and the mesh are in the fast triangle test's range (struct
 * pq's fast, for callers without one). */
static inline int fast_range(const struct mesh *M, px_vec3 p)
{
	return M->absmax < 1e18 && px__amax3(p) < 1e18;
}

static inline void test_tri(const struct mesh *M, size_t li, px_vec3 p,
			    struct best *b)
{
	test_tri_x(M, li, p, b, 0, fast_range(M, p));
}

/* Fill a result from the best triangle: the sign from the pseudo-normal
 * of the feature holding the closest point. */
static void mesh_finish(const struct mesh *M, px_vec3 p, const struct best *bp,
			unsigned flags, int iters, int certified,
			struct px_model_result *r)
{
	struct best b = *bp;
	px_vec3 n, dv;
	double d;

	r->point = b.q;
	r->index = (int)M->orig[b.li];
	r->sub = b.sub;
	r->feature = b.feature;
	r->u = b.u;
	r->v = b.v;
	r->iterations = iters;
	r->certified = certified;
	r->gap = 0.0;
	if (b.feature == PX_FEATURE_FACE)
		n = M->fn[b.li];
	else if (b.feature == PX_FEATURE_EDGE)
		n = M->en[3 * b.li + b.sub];
	else
		n = M->vnt[3 * b.li + b.sub];
	d = sqrt(b.d2);
	dv = px_v3_sub(p, b.q);
	r->is_signed = M->closed && !(flags & PX_QUERY_UNSIGNED);
	r->inside = 0;
	if (d > 0.0) {
		r->direction = px_v3_scale(dv, 1.0 / d);
		r->distance = d;
		if (r->is_signed && px_v3_dot(dv, n) < 0.0) {
			r->inside = 1;
			r->distance = -d;
			r->direction = px_v3_neg(r->direction);
		}
	} else {
		px_vec3 f = M->fn[b.li];
		r->distance = 0.0;
		if (px_v3_normalize(n, f, &r->direction) != PX_OK)
			px_v3_normalize(f, px_v3(0, 0, 1), &r->direction);
	}
}


/* The mesh walk's context (px__box4_nearest's callbacks). */
struct mwalk {
	const struct mesh *M;
	px_vec3 p;
	struct best *b;
	struct pq pq;
};

static inline void mesh_leaf(void *ctx, uint32_t i0, uint32_t n)
{
	struct mwalk *w = ctx;
	const struct mesh *M = w->M;
	double lb[16];
	uint32_t k;
	if (!w->pq.use) {
		for (k = 0; k < n; k++)
			test_tri(M, i0 + k, w->p, w->b);
		return;
	}
	/* all bounds of the leaf first, then the vertex fetches of the
	 * triangles they keep at once, then the exact tests: the fetches
	 * overlap instead of queueing */
	for (k = 0; k < n; k++) {
		lb[k] = tri_lb(&M->lb[i0 + k], &w->pq);
		if (!(lb[k] > w->b->d2)) {
			const uint32_t *v = M->tv + 3 * (i0 + k);
			__builtin_prefetch(M->vx + v[0]);
			__builtin_prefetch(M->vx + v[1]);
			__builtin_prefetch(M->vx + v[2]);
		}
	}
	for (k = 0; k < n; k++)
		if (!(lb[k] > w->b->d2))
			test_tri_x(M, i0 + k, w->p, w->b, 1, w->pq.fast);
}

static inline void mesh_bounds(void *ctx, uint32_t node, const struct node4 *nd, double d2[4])
{
	const struct mwalk *w = ctx;
	(void)node;
	if (w->pq.use)
		px__box4_d2f(nd, w->pq.pf, w->pq.slack_box, d2);
	else
		px__box4_d2(nd, w->p, d2);
}

/* Start the memory fetch of a pushed entry: the node or the leaf's
 * triangles are needed within a few steps. */
static inline void mesh_fetch(void *ctx, uint32_t idx, uint32_t cnt)
{
	const struct mesh *M = ((const struct mwalk *)ctx)->M;
	if (cnt) {
		/* one line per triangle */
		const struct tlb *L = &M->lb[idx];
		uint32_t k;
		for (k = 0; k < cnt; k++)
			__builtin_prefetch(L + k);
		__builtin_prefetch(M->tv + 3 * idx);
	} else {
		/* a node spans two lines */
		const char *q = (const char *)&M->n4[idx];
		__builtin_prefetch(q);
		__builtin_prefetch(q + 64);
	}
}

/* The hierarchy walk: improves *b (which may already hold a bound from
 * a hint) to the exact closest triangle within its bound. RT-safe. */
static void mesh_walk(const struct mesh *M, px_vec3 p, struct best *b,
		      int *iters_io, int *certified_io)
{
	struct px__walk4 st[STACK4];
	struct mwalk w;
	int iters = *iters_io;

	w.M = M;
	w.p = p;
	w.b = b;
	pq_init(M, p, &w.pq);
	if (!px__box4_nearest(M->n4, st, STACK4, &b->d2, &b->li, mesh_leaf, mesh_bounds,
			      mesh_fetch, &w, &iters))
		*certified_io = 0;
	*iters_io = iters;
}

static void best_init(struct best *b, px_vec3 p, double max_dist)
{
	b->d2 = isinf(max_dist) ? INFINITY : max_dist * max_dist;
	b->li = -1;
	b->q = p;
	b->feature = PX_FEATURE_NONE;
	b->sub = 0;
	b->u = b->v = 0.0;
}

static int mesh_closest(const void *impl, const struct px_model_query *qq,
			struct px_model_result *r)
{
	const struct mesh *M = impl;
	int iters = 0, certified = 1;
	struct best b;
	px_vec3 p = qq->p;

	best_init(&b, p, qq->max_dist);
	/* a starting bound: last cycle's triangle, else the grid's */
	if (qq->hint >= 0 && (size_t)qq->hint < M->nt) {
		test_tri(M, M->leaf_of[qq->hint], p, &b);
		iters++;
	} else if (M->grid) {
		test_tri(M, px__mesh_grid_hint(M, p), p, &b);
		iters++;
	}
	mesh_walk(M, p, &b, &iters, &certified);
	if (b.li < 0)
		return 0;
	mesh_finish(M, p, &b, qq->flags, iters, certified, r);
	return 1;
}

/* Exact closest point among the given leaf-order triangles (coherence
 * caches: px_model_query_cached() decides when that set is enough). */
static int mesh_closest_among(const void *impl, const struct px_model_query *qq,
			      const int *idx, int n, struct px_model_result *r)
{
	const struct mesh *M = impl;
	struct best b;
	struct pq pq;
	int i;

	best_init(&b, qq->p, qq->max_dist);
	pq_init(M, qq->p, &pq);
	for (i = 0; i < n; i++) {
		size_t li = (size_t)idx[i];
		if (idx[i] < 0 || li >= M->nt)
			continue;
		/* the float bound first, as the walk does: most of the set
		 * is farther than the best so far */
		if (!pq.use)
			test_tri(M, li, qq->p, &b);
		else if (!(tri_lb(&M->lb[li], &pq) > b.d2))
			test_tri_x(M, li, qq->p, &b, 1, pq.fast);
	}
	if (b.li < 0)
		return 0;
	mesh_finish(M, qq->p, &b, qq->flags, n, 1, r);
	return 1;
}

long px__mesh_grid_nearest(const void *ctx, px_vec3 c, long prev)
{
	const struct mesh *M = ctx;
	struct best b;
	int iters = 0, cert = 1;
	best_init(&b, c, INFINITY);
	if (prev >= 0)
		test_tri(M, (size_t)prev, c, &b);
	mesh_walk(M, c, &b, &iters, &cert);
	return b.li;
}

/* mesh_collect()'s leaf: the triangles of [i0, i0 + n) within the
 * radius. */
struct mesh_within {
	const struct mesh *M;
	px_vec3 p;
	double r2;
	struct pq pq;
	int *idx, cap, n;
};

static int mesh_within_leaf(void *ctx, uint32_t i0, uint32_t n)
{
	struct mesh_within *w = ctx;
	const struct mesh *M = w->M;
	uint32_t i;
	for (i = i0; i < i0 + n; i++) {
		const uint32_t *v = M->tv + 3 * i;
		if (w->pq.use && tri_lb(&M->lb[i], &w->pq) > w->r2)
			continue;
		if (px_tri_closest(w->p, M->vx[v[0]], M->vx[v[1]], M->vx[v[2]], NULL,
				   NULL, NULL, NULL, NULL) <= w->r2) {
			if (w->n == w->cap)
				return PX_E_NOSPC;
			w->idx[w->n++] = (int)i;
		}
	}
	return 0;
}

/* Leaf-order indices of every triangle within radius of p: the count,
 * or PX_E_NOSPC when there are more than cap. */
static int mesh_collect(const void *impl, px_vec3 p, double radius, int *idx,
			int cap)
{
	const struct mesh *M = impl;
	struct px__walk4 st[STACK4];
	struct mesh_within w;
	int rc;

	w.M = M;
	w.p = p;
	w.r2 = radius * radius;
	w.idx = idx;
	w.cap = cap;
	w.n = 0;
	pq_init(M, p, &w.pq);
	rc = px__box4_within(M->n4, p, w.r2, st, STACK4, mesh_within_leaf, &w);
	return rc < 0 ? rc : w.n;
}

static px_aabb mesh_aabb(const void *impl)
{
	return ((const struct mesh *)impl)->box;
}

static size_t mesh_bytes(const void *impl)
{
	return ((const struct mesh *)impl)->bytes;
}

/* Convex meshes: the vertex farthest along d (a linear scan: convex
 * meshes in this role are small, e.g. a tool or a hull). */
/*
 * Convex meshes: the vertex farthest along d. Small meshes are scanned;
 * larger ones are climbed along the vertex graph from the best of the
 * six axis-extreme vertices, always to a strictly better neighbour. On a
 * convex solid a vertex with no better neighbour is a global maximum:
 * along a polytope edge or across a facet the objective rises wherever
 * the vertex is not optimal, and the mesh edges follow those edges and
 * fan across those facets. The one trap, a vertex inside a facet whose
 * normal is -d, cannot be reached by strict climbing (that facet is the
 * minimum) and is not a start unless all six extremes lie on one facet,
 * which the volume required of convex meshes excludes. Each step
 * strictly increases the objective, so at most n_hull steps.
 */
static px_vec3 mesh_support(const void *impl, px_vec3 d)
{
	const struct mesh *M = impl;
	size_t i, bi = 0, steps;
	double best = -INFINITY;
	if (!M->adj_start) {
		for (i = 0; i < M->n_hull; i++) {
			double s = px_v3_dot(M->hull[i], d);
			if (s > best) {
				best = s;
				bi = i;
			}
		}
		return M->hull[bi];
	}
	for (i = 0; i < 6; i++) {
		double s = px_v3_dot(M->hull[M->ext[i]], d);
		if (s > best) {
			best = s;
			bi = M->ext[i];
		}
	}
	for (steps = 0; steps < M->n_hull; steps++) {
		size_t nb = bi;
		uint32_t k;
		for (k = M->adj_start[bi]; k < M->adj_start[bi + 1]; k++) {
			double s = px_v3_dot(M->hull[M->adj[k]], d);
			if (s > best) {
				best = s;
				nb = M->adj[k];
			}
		}
		if (nb == bi)
			break;
		bi = nb;
	}
	return M->hull[bi];
}

static const struct px_model_ops mesh_ops = {
	.name = "mesh", .kind = PX_MODEL_MESH, .closest = mesh_closest,
	.aabb = mesh_aabb, .memory_bytes = mesh_bytes, .free = px__mesh_free,
	.closest_among = mesh_closest_among, .collect = mesh_collect};
static const struct px_model_ops mesh_ops_convex = {
	.name = "mesh", .kind = PX_MODEL_MESH, .closest = mesh_closest,
	.aabb = mesh_aabb, .memory_bytes = mesh_bytes, .free = px__mesh_free,
	.support = mesh_support, .closest_among = mesh_closest_among,
	.collect = mesh_collect};

int px__mesh_wrap(struct mesh *M, int convex, struct px_model **out)
{
	return px_model_create(convex ? &mesh_ops_convex : &mesh_ops, M,
			       PX_MODEL_CAP_EXACT | PX_MODEL_CAP_COHERENT |
				       (M->closed ? PX_MODEL_CAP_SIGNED : 0u) |
				       (convex ? PX_MODEL_CAP_CONVEX : 0u),
			       out);
}

/* ---- accessors ------------------------------------------------------------- */

static const struct mesh *as_mesh(const struct px_model *m)
{
	const struct px_model_ops *o = px_model_get_ops(m);
	if (o != &mesh_ops && o != &mesh_ops_convex)
		return NULL;
	return px_model_impl(m);
}

size_t px_mesh_triangle_count(const struct px_model *m)
{
	const struct mesh *M = as_mesh(m);
	return M ? M->nt : 0;
}

int px_mesh_triangle(const struct px_model *m, size_t i, px_vec3 v[3])
{
	const struct mesh *M = as_mesh(m);
	const uint32_t *t;
	if (!M || !v || i >= M->nt)
		return PX_E_INVAL;
	t = M->tv + 3 * (size_t)M->leaf_of[i];
	v[0] = M->vx[t[0]];
	v[1] = M->vx[t[1]];
	v[2] = M->vx[t[2]];
	return PX_OK;
}

int px_mesh_is_closed(const struct px_model *m)
{
	const struct mesh *M = as_mesh(m);
	return M ? M->closed : 0;
}
