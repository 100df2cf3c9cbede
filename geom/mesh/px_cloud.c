/*
 * px_cloud.c - point cloud model: k-d tree with tight child boxes, text
 * and PLY loading.
 */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "mesh_internal.h"
#include "model_internal.h"
#include "px_cloud.h"
#include "px_file.h"

#define LEAF 8
#define CSTACK4 (3 * PX_CLOUD_MAX_DEPTH + 4)

/* The points of each child of a four-wide node (a contiguous range of
 * the leaf order) lie between two parallel planes: lo[j] <= n[.][j] . x
 * <= hi[j] (n a float unit vector near the normal of the points'
 * best-fit plane; lo, hi computed with that float n, rounded outwards).
 * Scanned points sample surfaces, so a subtree is a thin curved patch,
 * and seen face-on its slab bounds its distance far more tightly than
 * its box. Per node, side by side as in struct node4. */
struct nslab {
	float n[3][4], lo[4], hi[4];
};

/* The hierarchy has the mesh's layout (mesh_internal.h): a binary tree
 * built by median splits, with single-precision child boxes rounded
 * outwards, collapsed to four children per node for the queries. */
struct cloud {
	size_t n;
	double radius;
	px_vec3 *pt;       /* leaf order */
	uint32_t *orig;    /* leaf -> input */
	uint32_t *leaf_of; /* input -> leaf */
	struct node4 *n4;
	size_t n_n4;
	int depth;
	px_aabb box;
	double absmax;     /* largest |coordinate| of the points */
	size_t bytes;
	/* hint grid as for meshes (mesh_internal.h): leaf index of the
	 * point nearest to each cell's centre; NULL = none */
	uint32_t *grid;
	int gdim[3];
	px_vec3 gorg;
	double gcell, ginv;
	struct nslab *ns;  /* per four-wide node, for its children */
};

#define rep_msg(rep, ...) \
	px__report_msg((rep) ? (rep)->message : NULL, sizeof((rep)->message), __VA_ARGS__)

static void cloud_free(void *impl)
{
	struct cloud *C = impl;
	if (!C)
		return;
	free(C->pt);
	free(C->orig);
	free(C->leaf_of);
	free(C->n4);
	free(C->grid);
	free(C->ns);
	free(C);
}

/* ---- build ------------------------------------------------------------------ */

/* px__tree_build's box: the bounds of points perm[0..n) (xyz, ctx). */
static void range_box(void *ctx, const uint32_t *perm, size_t n, double lo[3], double hi[3])
{
	px__key_bounds(perm, n, ctx, lo, hi);
}

/* ---- query ------------------------------------------------------------------ */

/* Fill a result from the nearest centre bi at squared distance best;
 * returns 0 when it lies beyond max_dist. */
static int cloud_finish(const struct cloud *C, const struct px_model_query *q,
			long bi, double best, int iters, int certified,
			struct px_model_result *r)
{
	px_vec3 p = q->p, v;
	double d;

	v = px_v3_sub(p, C->pt[bi]);
	d = sqrt(best);
	if (d > 0.0)
		r->direction = px_v3_scale(v, 1.0 / d);
	else
		r->direction = px_v3(0.0, 0.0, 1.0);
	r->point = px_v3_madd(C->pt[bi], r->direction, C->radius);
	r->distance = d - C->radius;
	r->is_signed = C->radius > 0.0;
	r->inside = 0;
	if (r->distance < 0.0) {
		if (q->flags & PX_QUERY_UNSIGNED) {
			r->distance = -r->distance;
			r->direction = px_v3_neg(r->direction);
			r->is_signed = 0;
		} else {
			r->inside = 1;
		}
	} else if (q->flags & PX_QUERY_UNSIGNED) {
		r->is_signed = 0;
	}
	if (r->distance == 0.0)
		r->distance = 0.0;
	if (fabs(r->distance) > q->max_dist)
		return 0;
	r->index = (int)C->orig[bi];
	r->sub = -1;
	r->feature = PX_FEATURE_POINT;
	r->u = r->v = 0.0;
	r->iterations = iters;
	r->certified = certified;
	r->gap = 0.0;
	return 1;
}


/* The cloud walk's context (px__box4_nearest's callbacks): the nearest
 * centre so far (bi at squared distance best), and p in single precision
 * with the slacks that keep the float box and slab bounds lower bounds
 * (use: p and the cloud lie within 1e18). */
struct cwalk {
	const struct cloud *C;
	px_vec3 p;
	double best;
	long bi;
	int use;
	float pf[3];
	float slack, slack_s;
};

static inline void cloud_leaf(void *ctx, uint32_t i0, uint32_t n)
{
	struct cwalk *w = ctx;
	uint32_t i;
	for (i = i0; i < i0 + n; i++) {
		double d2 = px_v3_dist2(w->p, w->C->pt[i]);
		if (d2 < w->best || (d2 == w->best && w->bi < 0)) {
			w->best = d2;
			w->bi = (long)i;
		}
	}
}

static inline void cloud_bounds(void *ctx, uint32_t node, const struct node4 *nd, double dc[4])
{
	const struct cwalk *w = ctx;
	const struct nslab *S = &w->C->ns[node];
	const float *pf = w->pf;
	int j;
	if (!w->use) {
		px__box4_d2(nd, w->p, dc);
		return;
	}
	px__box4_d2f(nd, pf, w->slack, dc);
	/* the slabs: rounding as in the mesh's tri_lb */
	for (j = 0; j < 4; j++) {
		float h = S->n[0][j] * pf[0] + S->n[1][j] * pf[1] + S->n[2][j] * pf[2];
		float g = S->lo[j] - h > h - S->hi[j] ? S->lo[j] - h : h - S->hi[j];
		g -= w->slack_s;
		if (g > 0.0f) {
			double v = (double)(g * g) * (1.0 - 0x1p-18);
			dc[j] = v > dc[j] ? v : dc[j];
		}
	}
}

static inline void cloud_fetch(void *ctx, uint32_t idx, uint32_t cnt)
{
	const struct cloud *C = ((const struct cwalk *)ctx)->C;
	if (cnt) {
		/* up to 8 points of 24 bytes: three or four lines */
		const char *q = (const char *)&C->pt[idx];
		__builtin_prefetch(q);
		__builtin_prefetch(q + 64);
		__builtin_prefetch(q + 128);
		__builtin_prefetch(q + 191);
	} else {
		const char *q = (const char *)&C->n4[idx];
		__builtin_prefetch(q);
		__builtin_prefetch(q + 64);
		__builtin_prefetch(&C->ns[idx]);
	}
}

/* The hierarchy walk: improves the nearest centre (*bi at squared
 * distance *best, which may already be a bound from a hint). Boxes are
 * compared in single precision with the slack that keeps them lower
 * bounds (px__box4_d2f) while p and the cloud lie within 1e18, exactly
 * otherwise. RT-safe. */
static void cloud_walk(const struct cloud *C, px_vec3 p, double *best_io,
		       long *bi_io, int *iters_io, int *certified_io)
{
	struct px__walk4 st[CSTACK4];
	struct cwalk w;
	double pmax = fmax(fabs(p.x), fmax(fabs(p.y), fabs(p.z)));
	int iters = *iters_io;

	w.C = C;
	w.p = p;
	w.best = *best_io;
	w.bi = *bi_io;
	w.use = pmax < 1e18 && C->absmax < 1e18;
	w.pf[0] = (float)p.x;
	w.pf[1] = (float)p.y;
	w.pf[2] = (float)p.z;
	w.slack = (float)(0x1p-22 * (C->absmax + pmax));
	/* plane values: a float unit vector, products and sums, the rounded
	 * p: below 16 * 2^-24 (|p| + |cloud|); twice that */
	w.slack_s = (float)(0x1p-19 * (C->absmax + pmax));
	if (!px__box4_nearest(C->n4, st, CSTACK4, &w.best, &w.bi, cloud_leaf, cloud_bounds,
			      cloud_fetch, &w, &iters))
		*certified_io = 0;
	*best_io = w.best;
	*bi_io = w.bi;
	*iters_io = iters;
}

static int cloud_closest(const void *impl, const struct px_model_query *q,
			 struct px_model_result *r)
{
	const struct cloud *C = impl;
	int iters = 0, certified = 1;
	px_vec3 p = q->p;
	double best;
	long bi = -1;
	uint32_t li = EMPTY;

	if (isinf(q->max_dist))
		best = INFINITY;
	else
		best = (q->max_dist + C->radius) * (q->max_dist + C->radius);
	/* a starting bound: last cycle's point, else the grid's */
	if (q->hint >= 0 && (size_t)q->hint < C->n)
		li = C->leaf_of[q->hint];
	else if (C->grid)
		li = C->grid[px__grid_cell(C->gdim, C->gorg, C->ginv, p)];
	if (li != EMPTY) {
		double d2 = px_v3_dist2(p, C->pt[li]);
		if (d2 <= best) {
			best = d2;
			bi = (long)li;
		}
		iters++;
	}
	cloud_walk(C, p, &best, &bi, &iters, &certified);
	if (bi < 0)
		return 0;
	return cloud_finish(C, q, bi, best, iters, certified, r);
}

/* Cache operations (clouds without a radius: the feature distance is
 * then the point distance, which the cache's bound is about). */
static int cloud_closest_among(const void *impl, const struct px_model_query *q,
			       const int *idx, int n, struct px_model_result *r)
{
	const struct cloud *C = impl;
	double best = isinf(q->max_dist) ? INFINITY : q->max_dist * q->max_dist;
	long bi = -1;
	int i;
	for (i = 0; i < n; i++) {
		double d2;
		if (idx[i] < 0 || (size_t)idx[i] >= C->n)
			continue;
		d2 = px_v3_dist2(q->p, C->pt[idx[i]]);
		if (d2 < best || (d2 == best && bi < 0)) {
			best = d2;
			bi = idx[i];
		}
	}
	if (bi < 0)
		return 0;
	return cloud_finish(C, q, bi, best, n, 1, r);
}

/* cloud_collect()'s leaf: the points of [i0, i0 + n) within the radius. */
struct cloud_within {
	const struct cloud *C;
	px_vec3 p;
	double r2;
	int *idx, cap, n;
};

static int cloud_within_leaf(void *ctx, uint32_t i0, uint32_t n)
{
	struct cloud_within *w = ctx;
	uint32_t i;
	for (i = i0; i < i0 + n; i++)
		if (px_v3_dist2(w->p, w->C->pt[i]) <= w->r2) {
			if (w->n == w->cap)
				return PX_E_NOSPC;
			w->idx[w->n++] = (int)i;
		}
	return 0;
}

static int cloud_collect(const void *impl, px_vec3 p, double radius, int *idx,
			 int cap)
{
	const struct cloud *C = impl;
	struct px__walk4 st[CSTACK4];
	struct cloud_within w = {C, p, radius * radius, idx, cap, 0};
	int rc = px__box4_within(C->n4, p, w.r2, st, CSTACK4, cloud_within_leaf, &w);
	return rc < 0 ? rc : w.n;
}

static px_aabb cloud_aabb(const void *impl)
{
	const struct cloud *C = impl;
	return px_aabb_inflate(&C->box, C->radius);
}

static size_t cloud_bytes(const void *impl)
{
	return ((const struct cloud *)impl)->bytes;
}

static const struct px_model_ops cloud_ops = {
	.name = "cloud", .kind = PX_MODEL_CLOUD, .closest = cloud_closest,
	.aabb = cloud_aabb, .memory_bytes = cloud_bytes, .free = cloud_free};
static const struct px_model_ops cloud_ops_cache = {
	.name = "cloud", .kind = PX_MODEL_CLOUD, .closest = cloud_closest,
	.aabb = cloud_aabb, .memory_bytes = cloud_bytes, .free = cloud_free,
	.closest_among = cloud_closest_among, .collect = cloud_collect};

/* Slab of the points [s, e) into child j of S. The normal: the
 * smallest-eigenvalue direction of the points' covariance by power
 * iteration on trace - covariance (any unit vector gives a valid slab;
 * a better one only a thinner). Setup only. */
static void slab_fit(const struct cloud *C, size_t s, size_t e, struct nslab *S, int j)
{
	double m[3] = {0, 0, 0}, cv[3][3] = {{0}}, v[3] = {0.577, 0.577, 0.577}, t;
	double lo = INFINITY, hi = -INFINITY, cnt = (double)(e - s);
	size_t i;
	int a, b, it;
	for (i = s; i < e; i++) {
		m[0] += C->pt[i].x / cnt;
		m[1] += C->pt[i].y / cnt;
		m[2] += C->pt[i].z / cnt;
	}
	for (i = s; i < e; i++) {
		double d[3] = {C->pt[i].x - m[0], C->pt[i].y - m[1], C->pt[i].z - m[2]};
		for (a = 0; a < 3; a++)
			for (b = 0; b < 3; b++)
				cv[a][b] += d[a] * d[b];
	}
	t = cv[0][0] + cv[1][1] + cv[2][2];
	for (it = 0; it < 32 && t > 0.0 && isfinite(t); it++) {
		double w[3], l;
		for (a = 0; a < 3; a++)
			w[a] = t * v[a] - (cv[a][0] * v[0] + cv[a][1] * v[1] + cv[a][2] * v[2]);
		l = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
		if (!(l > 0.0) || !isfinite(l))
			break;
		for (a = 0; a < 3; a++)
			v[a] = w[a] / l;
	}
	t = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
	for (a = 0; a < 3; a++)
		S->n[a][j] = (float)(v[a] / t);
	/* the offsets with the float normal itself, rounded outwards */
	for (i = s; i < e; i++) {
		double h = (double)S->n[0][j] * C->pt[i].x + (double)S->n[1][j] * C->pt[i].y +
			   (double)S->n[2][j] * C->pt[i].z;
		lo = h < lo ? h : lo;
		hi = h > hi ? h : hi;
	}
	S->lo[j] = px__f_down(lo - 1e-12 * fabs(lo));
	S->hi[j] = px__f_up(hi + 1e-12 * fabs(hi));
}

/* Slabs of node ni's children, recursively; returns the node's point
 * range [*s, *e). Setup only. */
static void slab_build(struct cloud *C, uint32_t ni, size_t *s_out, size_t *e_out)
{
	const struct node4 *nd = &C->n4[ni];
	struct nslab *S = &C->ns[ni];
	size_t s = (size_t)-1, e = 0;
	int j;
	for (j = 0; j < 4; j++) {
		size_t cs, ce;
		/* absent children: a slab nothing is inside (never prunes
		 * more than their empty box does) */
		S->n[0][j] = S->n[1][j] = S->n[2][j] = 0.0f;
		S->lo[j] = -INFINITY;
		S->hi[j] = INFINITY;
		if (nd->idx[j] == EMPTY)
			continue;
		if (nd->cnt[j] > 0) {
			cs = nd->idx[j];
			ce = cs + nd->cnt[j];
		} else {
			slab_build(C, nd->idx[j], &cs, &ce);
		}
		slab_fit(C, cs, ce, S, j);
		s = cs < s ? cs : s;
		e = ce > e ? ce : e;
	}
	*s_out = s;
	*e_out = e;
}

/* px__grid_fill's nearest for a cloud (ctx): the exact nearest point
 * to c, from point prev when >= 0. Setup only. */
static long grid_nearest(const void *ctx, px_vec3 c, long prev)
{
	const struct cloud *C = ctx;
	double best = INFINITY;
	long bi = -1;
	int iters = 0, cert = 1;
	if (prev >= 0) {
		best = px_v3_dist2(c, C->pt[prev]);
		bi = prev;
	}
	cloud_walk(C, c, &best, &bi, &iters, &cert);
	return bi;
}

/* The hint grid (see struct cloud): one cell per 8 points, at most
 * 64^3; each cell's exact nearest point, found in a serpentine order
 * from its neighbour's. Setup only. */
static int grid_build(struct cloud *C)
{
	long cap = (long)(C->n / 8), ncell;

	if (cap > 64L * 64 * 64)
		cap = 64L * 64 * 64;
	ncell = px__grid_fill(C->box, cap, grid_nearest, C, &C->grid, C->gdim, &C->gorg, &C->gcell,
			      &C->ginv);
	if (ncell < 0)
		return (int)ncell;
	C->bytes += (size_t)ncell * sizeof(*C->grid);
	return PX_OK;
}

int px_cloud_model(const double *xyz, size_t n, double radius_m,
		   struct px_cloud_report *rep, struct px_model **out)
{
	struct px_cloud_report lrep;
	struct cloud *C = NULL;
	uint32_t *perm = NULL;
	struct node *nodes = NULL;
	struct px__tree_build B;
	size_t i;
	int rc = PX_E_NOMEM, k;

	if (!rep)
		rep = &lrep;
	memset(rep, 0, sizeof(*rep));
	rep->line = -1;
	rep->n_points = n;
	if (out)
		*out = NULL;
	if (!out || !xyz || n == 0) {
		rep_msg(rep, "%s", n == 0 ? "cloud has no points" : "invalid arguments");
		return PX_E_INVAL;
	}
	if (!(radius_m >= 0.0) || !isfinite(radius_m)) {
		rep_msg(rep, "point radius %g must be finite and >= 0", radius_m);
		return PX_E_RANGE;
	}
	if (n > PX_CLOUD_MAX_POINTS) {
		rep_msg(rep, "too many points (%zu)", n);
		return PX_E_RANGE;
	}
	for (i = 0; i < n; i++)
		if (!(isfinite(xyz[3 * i]) && isfinite(xyz[3 * i + 1]) &&
		      isfinite(xyz[3 * i + 2]))) {
			rep_msg(rep, "point %zu: non-finite coordinate (%g %g %g)", i,
				xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
			return PX_E_NAN;
		}
	/* The extent, the hint grid's cells and every squared distance of a
	 * query within reach stay finite only for coordinates and radius
	 * within PX_CLOUD_MAX_COORD (points near 1e308 overflowed the
	 * extent to infinity and the grid's cell counts with it). */
	if (radius_m > PX_CLOUD_MAX_COORD) {
		rep_msg(rep, "point radius %g beyond %g", radius_m, PX_CLOUD_MAX_COORD);
		return PX_E_RANGE;
	}
	for (i = 0; i < n; i++)
		for (k = 0; k < 3; k++)
			if (fabs(xyz[3 * i + (size_t)k]) > PX_CLOUD_MAX_COORD) {
				rep_msg(rep, "point %zu: coordinate %c = %g beyond +-%g "
					"(squared distances would overflow)", i, "xyz"[k],
					xyz[3 * i + (size_t)k], PX_CLOUD_MAX_COORD);
				return PX_E_RANGE;
			}
	C = calloc(1, sizeof(*C));
	if (!C)
		goto fail;
	C->n = n;
	C->radius = radius_m;
	perm = malloc(n * sizeof(*perm));
	/* cache-line aligned: a 64-byte node then costs one line, not two */
	nodes = aligned_alloc(64, (n / 2 + 2) * sizeof(*nodes));
	C->pt = malloc(n * sizeof(*C->pt));
	C->orig = malloc(n * sizeof(*C->orig));
	C->leaf_of = malloc(n * sizeof(*C->leaf_of));
	if (!perm || !nodes || !C->pt || !C->orig || !C->leaf_of)
		goto fail;
	memset(nodes, 0, (n / 2 + 2) * sizeof(*nodes));
	for (i = 0; i < n; i++)
		perm[i] = (uint32_t)i;
	memset(&B, 0, sizeof(B));
	B.perm = perm;
	B.key = xyz;
	B.leaf = LEAF;
	B.box_is_key = 1;
	B.ctx = (void *)xyz;
	B.box = range_box;
	B.store = px__node_store;
	B.nodes = nodes;
	px__tree_build(&B, n);
	C->depth = B.depth + 1;
	if (C->depth > PX_CLOUD_MAX_DEPTH) {
		rep_msg(rep, "tree too deep (%d)", C->depth);
		rc = PX_E_RANGE;
		goto fail;
	}
	C->n4 = aligned_alloc(64, B.n_nodes * sizeof(*C->n4));
	if (!C->n4)
		goto fail;
	C->n_n4 = 0;
	px__node4_collapse(nodes, C->n4, &C->n_n4, 0);
	free(nodes);
	nodes = NULL;
	C->box = px_aabb_empty();
	for (i = 0; i < n; i++) {
		uint32_t t = perm[i];
		C->pt[i] = px_v3(xyz[3 * (size_t)t], xyz[3 * (size_t)t + 1],
				 xyz[3 * (size_t)t + 2]);
		px_aabb_extend(&C->box, C->pt[i]);
		C->orig[i] = t;
		C->leaf_of[t] = (uint32_t)i;
	}
	C->absmax = fmax(fmax(fabs(C->box.min.x), fabs(C->box.max.x)),
			 fmax(fmax(fabs(C->box.min.y), fabs(C->box.max.y)),
			      fmax(fabs(C->box.min.z), fabs(C->box.max.z))));
	C->bytes = sizeof(*C) + n * (sizeof(px_vec3) + 2 * sizeof(uint32_t)) +
		   C->n_n4 * sizeof(struct node4);
	C->ns = malloc(C->n_n4 * sizeof(*C->ns));
	if (!C->ns)
		goto fail;
	C->bytes += C->n_n4 * sizeof(*C->ns);
	{
		size_t rs, re;
		slab_build(C, 0, &rs, &re);
	}
	if (grid_build(C) != PX_OK)
		goto fail;
	free(perm);
	rc = px_model_create(radius_m > 0.0 ? &cloud_ops : &cloud_ops_cache, C,
			     PX_MODEL_CAP_EXACT | PX_MODEL_CAP_COHERENT |
				     (radius_m > 0.0 ? PX_MODEL_CAP_SIGNED : 0u),
			     out);
	if (rc != PX_OK)
		rep_msg(rep, "out of memory");
	return rc;
fail:
	if (rc == PX_E_NOMEM)
		rep_msg(rep, "out of memory");
	free(perm);
	free(nodes);
	cloud_free(C);
	return rc;
}

/* ---- text files -------------------------------------------------------------- */

static int is_sep(int c)
{
	return c == ' ' || c == '\t' || c == ',' || c == ';' || c == '\r' ||
	       c == '\0';
}

/*
 * Parse one line: up to 3 numbers (more columns ignored), separated by
 * blanks or by one ',' or ';' with optional blanks around it. Returns
 * the count of numbers read at the start of the line (0..3); *bad_col is
 * the 1-based column of the first field that is not a number (0 if all
 * of the first three parsed) and *empty the 1-based number of a field
 * that is empty ("1,,2": two separators, or one at either end), which
 * would otherwise shift the columns.
 */
static int parse_line(const char *s, double v[3], int *bad_col, int *empty)
{
	const char *p = s;
	int k = 0;
	*bad_col = 0;
	*empty = 0;
	while (*p == ' ' || *p == '\t')
		p++;
	while (k < 3 && *p) {
		char *end;
		if (*p == ',' || *p == ';') {
			*bad_col = (int)(p - s) + 1;
			*empty = k + 1;
			return k;
		}
		v[k] = strtod(p, &end);
		if (end == p || !is_sep((unsigned char)*end)) {
			*bad_col = (int)(p - s) + 1;
			return k;
		}
		p = end;
		k++;
		while (*p == ' ' || *p == '\t' || *p == '\r')
			p++;
		if (*p == ',' || *p == ';') {
			const char *sep = p++;
			while (*p == ' ' || *p == '\t' || *p == '\r')
				p++;
			if (!*p && k < 3) {
				*bad_col = (int)(sep - s) + 2;
				*empty = k + 1;
				return k;
			}
		}
	}
	return k;
}

static int load_text(const char *path, double **xyz_out, size_t *n_out,
		     struct px_cloud_report *rep)
{
	char *data = NULL, *cur, *line;
	size_t n = 0, vcap = 0, len = 0;
	long lineno = 0;
	double *xyz = NULL;
	int seen_data = 0, rc;

	rc = px_file_read(path, PX_FILE_MODEL_MAX_BYTES, PX_FILE_TEXT,
			  "point cloud", &data, &len, rep->message,
			  sizeof(rep->message));
	if (rc != PX_OK)
		return rc;
	cur = data;
	while ((line = px_file_next_line(&cur)) != NULL) {
		const char *s = line;
		double v[3];
		int k, bad, empty;
		lineno++;
		while (*s == ' ' || *s == '\t')
			s++;
		if (*s == '\0' || *s == '#' || (s[0] == '/' && s[1] == '/'))
			continue;
		k = parse_line(line, v, &bad, &empty);
		if (k < 3) {
			/* a header of names before the first point is fine; a
			 * line whose first field reads as a number (NaN and inf
			 * included) is data */
			if (!seen_data && k == 0 && !empty && isalpha((unsigned char)*s)) {
				seen_data = 1;
				continue;
			}
			rep->line = lineno;
			if (empty)
				rep_msg(rep, "%s:%ld:%d: field %d is empty", path, lineno,
					bad, empty);
			else if (bad)
				rep_msg(rep, "%s:%ld:%d: field %d: not a number", path,
					lineno, bad, k + 1);
			else
				rep_msg(rep, "%s:%ld: %d numbers, a point needs 3", path,
					lineno, k);
			rc = PX_E_PARSE;
			goto out;
		}
		if (!(isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]))) {
			rep->line = lineno;
			rep_msg(rep, "%s:%ld: field %d: non-finite coordinate", path, lineno,
				!isfinite(v[0]) ? 1 : !isfinite(v[1]) ? 2 : 3);
			rc = PX_E_NAN;
			goto out;
		}
		for (k = 0; k < 3; k++)
			if (fabs(v[k]) > PX_CLOUD_MAX_COORD) {
				rep->line = lineno;
				rep_msg(rep, "%s:%ld: field %d: coordinate %g beyond +-%g "
					"(squared distances would overflow)", path, lineno,
					k + 1, v[k], PX_CLOUD_MAX_COORD);
				rc = PX_E_RANGE;
				goto out;
			}
		seen_data = 1;
		if (n == vcap) {
			size_t nc = vcap ? 2 * vcap : 4096;
			double *q = realloc(xyz, 3 * nc * sizeof(double));
			if (!q) {
				rep_msg(rep, "%s: out of memory", path);
				rc = PX_E_NOMEM;
				goto out;
			}
			xyz = q;
			vcap = nc;
		}
		memcpy(xyz + 3 * n, v, sizeof(v));
		n++;
	}
	if (n == 0) {
		rep_msg(rep, "%s: no points in the file", path);
		rc = PX_E_PARSE;
	}
out:
	free(data);
	if (rc != PX_OK) {
		free(xyz);
		return rc;
	}
	*xyz_out = xyz;
	*n_out = n;
	return PX_OK;
}

int px_cloud_load(const char *path, double radius_m,
		  struct px_cloud_report *rep, struct px_model **out)
{
	struct px_cloud_report lrep;
	double *xyz = NULL;
	size_t n = 0, len;
	struct stat st;
	int rc;

	if (!rep)
		rep = &lrep;
	memset(rep, 0, sizeof(*rep));
	rep->line = -1;
	if (out)
		*out = NULL;
	if (!path || !out) {
		rep_msg(rep, "invalid arguments");
		return PX_E_INVAL;
	}
	if (stat(path, &st) != 0) {
		int e = errno;
		rep_msg(rep, "%s: %s", path, strerror(e));
		return e == ENOENT ? PX_E_NOTFOUND : PX_E_IO;
	}
	if (S_ISDIR(st.st_mode)) {
		rep_msg(rep, "%s: is a directory", path);
		return PX_E_IO;
	}
	len = strlen(path);
	if (len >= 4 && strcasecmp(path + len - 4, ".ply") == 0) {
		char msg[sizeof(rep->message)];
		rc = px__import_file(path, 0, &xyz, &n, NULL, NULL, NULL, msg,
				     sizeof(msg));
		if (rc != PX_OK) {
			snprintf(rep->message, sizeof(rep->message), "%s", msg);
			return rc;
		}
	} else {
		rc = load_text(path, &xyz, &n, rep);
		if (rc != PX_OK)
			return rc;
	}
	rc = px_cloud_model(xyz, n, radius_m, rep, out);
	if (rc != PX_OK && rep->message[0]) {
		px__prefix_path(rep->message, sizeof(rep->message), path);
	}
	free(xyz);
	return rc;
}

/* ---- accessors ------------------------------------------------------------- */

static const struct cloud *as_cloud(const struct px_model *m);

long px__cloud_grid_hint(const struct px_model *m, px_vec3 p, px_vec3 *centre)
{
	const struct cloud *C = as_cloud(m);
	size_t cell, x, y, z;
	if (!C || !C->grid)
		return -1;
	cell = px__grid_cell(C->gdim, C->gorg, C->ginv, p);
	x = cell % (size_t)C->gdim[0];
	y = (cell / (size_t)C->gdim[0]) % (size_t)C->gdim[1];
	z = cell / ((size_t)C->gdim[0] * (size_t)C->gdim[1]);
	if (centre)
		*centre = px_v3(C->gorg.x + ((double)x + 0.5) * C->gcell,
				C->gorg.y + ((double)y + 0.5) * C->gcell,
				C->gorg.z + ((double)z + 0.5) * C->gcell);
	return (long)C->orig[C->grid[cell]];
}

static const struct cloud *as_cloud(const struct px_model *m)
{
	const struct px_model_ops *o = px_model_get_ops(m);
	if (o != &cloud_ops && o != &cloud_ops_cache)
		return NULL;
	return px_model_impl(m);
}

int px__cloud_view(const struct px_model *m, struct px__cloud_view *v)
{
	const struct cloud *C = as_cloud(m);
	if (!C)
		return 0;
	v->n4 = C->n4;
	v->pt = C->pt;
	v->orig = C->orig;
	v->leaf_of = C->leaf_of;
	v->n = C->n;
	v->box = C->box;
	v->absmax = C->absmax;
	v->radius = C->radius;
	return 1;
}

size_t px_cloud_point_count(const struct px_model *m)
{
	const struct cloud *C = as_cloud(m);
	return C ? C->n : 0;
}

int px_cloud_point(const struct px_model *m, size_t i, px_vec3 *p)
{
	const struct cloud *C = as_cloud(m);
	if (!C || !p || i >= C->n)
		return PX_E_INVAL;
	*p = C->pt[C->leaf_of[i]];
	return PX_OK;
}

double px_cloud_radius(const struct px_model *m)
{
	const struct cloud *C = as_cloud(m);
	return C ? C->radius : 0.0;
}
