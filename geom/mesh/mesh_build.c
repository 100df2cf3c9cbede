/*
 * mesh_build.c - px_mesh_model: validation, welding, per-triangle shape
 * and normals, edge topology (closed, orientation), convexity, the box
 * hierarchy (surface-area splits), the leaf-order query data, the convex
 * hull's vertex graph and the hint grid. Setup only.
 */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mesh_internal.h"
#include "model_internal.h"
#include "px_mesh.h"

#define rep_msg(rep, ...) \
	px__report_msg((rep) ? (rep)->message : NULL, sizeof((rep)->message), __VA_ARGS__)

static int cmp_xyz(const void *x, const void *y, void *ctx)
{
	const double *P = ctx;
	const double *a = P + 3 * (size_t)*(const uint32_t *)x;
	const double *b = P + 3 * (size_t)*(const uint32_t *)y;
	int k;
	for (k = 0; k < 3; k++) {
		if (a[k] < b[k])
			return -1;
		if (a[k] > b[k])
			return 1;
	}
	return 0;
}

struct edge {
	uint32_t lo, hi; /* canonical vertex ids */
	uint32_t tri;
	uint8_t e;       /* local edge 0..2 */
	uint8_t fwd;     /* lo -> hi in the triangle's order */
};

static int cmp_edge(const void *x, const void *y)
{
	const struct edge *a = x, *b = y;
	if (a->lo != b->lo)
		return a->lo < b->lo ? -1 : 1;
	if (a->hi != b->hi)
		return a->hi < b->hi ? -1 : 1;
	return a->tri < b->tri ? -1 : (a->tri > b->tri);
}

static double ang(px_vec3 u, px_vec3 w)
{
	return atan2(px_v3_norm(px_v3_cross(u, w)), px_v3_dot(u, w));
}


/* One px_mesh_model call: its input, its scratch arrays (indexed by
 * input vertex or triangle) and the mesh it fills. */
struct mesh_setup {
	const double *xyz;
	size_t nv;
	const uint32_t *tri;
	size_t nt;
	unsigned flags;
	int leaf;
	struct px_mesh_report *rep;
	uint8_t *used;     /* per vertex: referenced by a triangle */
	uint32_t *order;   /* vertices sorted by position (then reused) */
	uint32_t *canon;   /* per vertex: the welded vertex it stands for */
	struct edge *E;    /* the edges of the non-collapsed triangles */
	size_t ne;
	int32_t *nb;       /* per triangle edge: the neighbour across, or -1 */
	px_vec3 *fn;       /* per triangle: unit normal (0 if degenerate) */
	px_vec3 *vn;       /* per vertex: angle-weighted pseudo-normal */
	double *cen, *tlo, *thi; /* per triangle: box centre and corners */
	uint8_t *deg;      /* per triangle: DEGEN_* and the fast test's vertex */
	uint32_t *perm;    /* leaf order -> triangle */
	double vsc;        /* 2^-vexp: the vertices scaled to below 1 */
	int vexp;
	double vol_s;      /* the volume in units of 2^(3 vexp) */
	struct mesh *M;
};

/* The arguments (before anything is allocated). */
static int check_args(const struct mesh_setup *S, const struct px_mesh_opts *opt,
		      struct px_model **out)
{
	struct px_mesh_report *rep = S->rep;
	if (!out || !S->xyz || !S->tri || S->nt == 0 || S->nv == 0 || S->leaf < 1 ||
	    S->leaf > 16 || (opt && opt->grid_cells > PX_MESH_MAX_GRID_CELLS)) {
		rep_msg(rep, "%s", S->nt == 0 || S->nv == 0 ? "mesh has no triangles"
							  : "invalid arguments");
		return PX_E_INVAL;
	}
	if (S->nt > PX_MESH_MAX_TRIANGLES || S->nv > 0xfffffffeu) {
		rep_msg(rep, "mesh too large (%zu triangles, %zu vertices)", S->nt, S->nv);
		return PX_E_RANGE;
	}
	return PX_OK;
}

/* Indices, then finiteness and range of the vertices actually used
 * (used[]), and the scale of the volume sum (vsc, vexp). */
static int check_vertices(struct mesh_setup *S)
{
	const double *xyz = S->xyz;
	struct px_mesh_report *rep = S->rep;
	double lo[3] = {INFINITY, INFINITY, INFINITY},
	       hi[3] = {-INFINITY, -INFINITY, -INFINITY}, ext = 0.0, amax = 0.0;
	size_t i;
	int k;

	S->used = calloc(S->nv, 1);
	if (!S->used)
		return PX_E_NOMEM;
	for (i = 0; i < S->nt; i++)
		for (k = 0; k < 3; k++) {
			uint32_t vi = S->tri[3 * i + k];
			if (vi >= S->nv) {
				rep_msg(rep, "triangle %zu: vertex index %u out of range (%zu vertices)",
					i, vi, S->nv);
				return PX_E_RANGE;
			}
			S->used[vi] = 1;
		}
	for (i = 0; i < S->nv; i++)
		if (S->used[i] && !(isfinite(xyz[3 * i]) && isfinite(xyz[3 * i + 1]) &&
				    isfinite(xyz[3 * i + 2]))) {
			rep_msg(rep, "vertex %zu: non-finite coordinate (%g %g %g)", i,
				xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
			return PX_E_NAN;
		}
	/* The accepted range (px_mesh.h): squared distances and the
	 * hierarchy's and hint grid's arithmetic stay finite and normal. */
	for (i = 0; i < S->nv; i++) {
		if (!S->used[i])
			continue;
		for (k = 0; k < 3; k++) {
			double x = xyz[3 * i + (size_t)k];
			if (!(fabs(x) <= PX_MESH_MAX_COORD)) {
				rep_msg(rep, "mesh: vertex %zu coordinate %.17g outside the "
					     "accepted range (|x| <= %g)",
					i, x, PX_MESH_MAX_COORD);
				return PX_E_RANGE;
			}
			lo[k] = fmin(lo[k], x);
			hi[k] = fmax(hi[k], x);
		}
	}
	for (k = 0; k < 3; k++) {
		ext = fmax(ext, hi[k] - lo[k]);
		amax = fmax(amax, fmax(fabs(lo[k]), fabs(hi[k])));
	}
	if (amax > 0.0)
		S->vsc = px__pow2_scale(amax, &S->vexp);
	if (ext > 0.0 && ext < PX_MESH_MIN_EXTENT) {
		rep_msg(rep, "mesh: extent %.17g below the accepted range (>= %g, or "
			     "0): its squared distances would underflow",
			ext, PX_MESH_MIN_EXTENT);
		return PX_E_RANGE;
	}
	return PX_OK;
}

/* Weld identical positions: canon[] names one vertex for each. */
static int weld(struct mesh_setup *S)
{
	size_t i;
	S->order = malloc(S->nv * sizeof(*S->order));
	S->canon = malloc(S->nv * sizeof(*S->canon));
	if (!S->order || !S->canon)
		return PX_E_NOMEM;
	for (i = 0; i < S->nv; i++)
		S->order[i] = (uint32_t)i;
	qsort_r(S->order, S->nv, sizeof(*S->order), cmp_xyz, (void *)S->xyz);
	for (i = 0; i < S->nv; i++) {
		uint32_t o = S->order[i];
		if (i > 0 && cmp_xyz(&S->order[i - 1], &S->order[i], (void *)S->xyz) == 0) {
			S->canon[o] = S->canon[S->order[i - 1]];
		} else {
			S->canon[o] = o;
			if (S->used[o])
				S->rep->n_welded++;
		}
	}
	return PX_OK;
}

/* Triangle i's shape, normal, share of the volume and of its vertices'
 * pseudo-normals; a (welded) vertices A, B, C. */
static void triangle_shape(struct mesh_setup *S, size_t i, const uint32_t cv[3])
{
	const double *A = S->xyz + 3 * (size_t)cv[0], *Bv = S->xyz + 3 * (size_t)cv[1],
		     *C = S->xyz + 3 * (size_t)cv[2];
	px_vec3 a = px_v3(A[0], A[1], A[2]), b = px_v3(Bv[0], Bv[1], Bv[2]),
		c = px_v3(C[0], C[1], C[2]);
	/* edges scaled by a power of two (exact) to a largest component
	 * near 1: the shape tests, angles and normal are scale-free, and
	 * nothing overflows at 1e150 or underflows at 1e-140 */
	px_vec3 ab, ac, bc, *vn = S->vn, *fn = S->fn;
	double vsc = S->vsc;
	int collapsed = cv[0] == cv[1] || cv[1] == cv[2] || cv[0] == cv[2], needle, fast, rot;

	px__tri_shape(a, b, c, &ab, &ac, &bc, &needle, &fast, &rot);
	if (collapsed || needle) {
		S->deg[i] = DEGEN_ZERO;
		if (S->rep->n_degenerate++ == 0)
			S->rep->first_degenerate = (long)i;
		return;
	}
	/* the accurate normal: the plain cross product of a thin
	 * triangle's edges is off by u / sin(angle) */
	fn[i] = px__unit_normal_acc(a, b, c);
	S->deg[i] = !fast ? DEGEN_SLOW : (uint8_t)(rot << DEGEN_ROT_SHIFT);
	/* in units of 2^vexp: a 1e150 mesh's volume overflows */
	S->vol_s += px_v3_dot(px_v3_scale(a, vsc),
			      px_v3_cross(px_v3_scale(b, vsc), px_v3_scale(c, vsc))) /
		    6.0;
	/* angle-weighted vertex pseudo-normals */
	vn[cv[0]] = px_v3_madd(vn[cv[0]], fn[i], ang(ab, ac));
	vn[cv[1]] = px_v3_madd(vn[cv[1]], fn[i], ang(px_v3_neg(ab), bc));
	vn[cv[2]] = px_v3_madd(vn[cv[2]], fn[i], ang(px_v3_neg(ac), px_v3_neg(bc)));
}

/* Per triangle: degeneracy, normal, box and centre, and the edges of
 * those not collapsed. */
static int triangles(struct mesh_setup *S)
{
	size_t i, nt = S->nt;
	int k;

	S->deg = calloc(nt, 1);
	S->fn = calloc(nt, sizeof(*S->fn));
	S->cen = malloc(nt * 3 * sizeof(double));
	S->tlo = malloc(nt * 3 * sizeof(double));
	S->thi = malloc(nt * 3 * sizeof(double));
	S->E = malloc(nt * 3 * sizeof(*S->E));
	S->nb = malloc(nt * 3 * sizeof(*S->nb));
	S->vn = calloc(S->nv, sizeof(*S->vn));
	if (!S->deg || !S->fn || !S->cen || !S->tlo || !S->thi || !S->E || !S->nb || !S->vn)
		return PX_E_NOMEM;
	for (i = 0; i < nt; i++) {
		uint32_t cv[3] = {S->canon[S->tri[3 * i]], S->canon[S->tri[3 * i + 1]],
				  S->canon[S->tri[3 * i + 2]]};
		const double *A = S->xyz + 3 * (size_t)cv[0], *Bv = S->xyz + 3 * (size_t)cv[1],
			     *C = S->xyz + 3 * (size_t)cv[2];

		triangle_shape(S, i, cv);
		S->nb[3 * i] = S->nb[3 * i + 1] = S->nb[3 * i + 2] = -1;
		for (k = 0; k < 3; k++) {
			double lo = fmin(fmin(A[k], Bv[k]), C[k]);
			double hi = fmax(fmax(A[k], Bv[k]), C[k]);
			S->tlo[3 * i + k] = lo;
			S->thi[3 * i + k] = hi;
			S->cen[3 * i + k] = 0.5 * (lo + hi);
		}
		if (cv[0] == cv[1] || cv[1] == cv[2] || cv[0] == cv[2])
			continue;
		for (k = 0; k < 3; k++) {
			uint32_t s = cv[k], e = cv[(k + 1) % 3];
			struct edge *ed = &S->E[S->ne++];
			ed->lo = s < e ? s : e;
			ed->hi = s < e ? e : s;
			ed->fwd = s < e;
			ed->tri = (uint32_t)i;
			ed->e = (uint8_t)k;
		}
	}
	if (S->rep->n_degenerate)
		rep_msg(S->rep, "triangle %ld is degenerate (zero area)%s",
			S->rep->first_degenerate,
			S->rep->n_degenerate > 1 ? ", and others" : "");
	if ((S->flags & PX_MESH_REJECT_DEGENERATE) && S->rep->n_degenerate)
		return PX_E_DEGENERATE;
	return PX_OK;
}

/* Edge topology: neighbours across the edges shared by two triangles in
 * opposite directions, the bad edges counted, closed, and the normals
 * flipped when a closed mesh is wound inwards. */
static int topology(struct mesh_setup *S)
{
	struct px_mesh_report *rep = S->rep;
	struct edge *E = S->E;
	size_t i, j, ne = S->ne;

	qsort(E, ne, sizeof(*E), cmp_edge);
	for (i = 0; i < ne; i = j) {
		for (j = i + 1; j < ne && E[j].lo == E[i].lo && E[j].hi == E[i].hi; j++)
			;
		if (j - i == 2 && E[i].fwd != E[i + 1].fwd) {
			S->nb[3 * E[i].tri + E[i].e] = (int32_t)E[i + 1].tri;
			S->nb[3 * E[i + 1].tri + E[i + 1].e] = (int32_t)E[i].tri;
			continue;
		}
		if (j - i == 1)
			rep->n_boundary_edges++;
		else if (j - i == 2)
			rep->n_misoriented_edges++;
		else
			rep->n_nonmanifold_edges++;
		if (rep->first_bad_edge_triangle < 0) {
			rep->first_bad_edge_triangle = (long)E[i].tri;
			rep_msg(rep, "triangle %u edge %d: %s edge (shared by %zu triangles%s)",
				E[i].tri, E[i].e,
				j - i == 1 ? "boundary" : (j - i == 2 ? "inconsistently oriented" : "non-manifold"),
				j - i, j - i == 2 ? " in the same direction" : "");
		}
	}
	rep->closed = rep->n_boundary_edges == 0 && rep->n_nonmanifold_edges == 0 &&
		      rep->n_misoriented_edges == 0 && ne > 0;
	if ((S->flags & PX_MESH_REQUIRE_CLOSED) && !rep->closed)
		return PX_E_DEGENERATE;
	rep->volume = rep->closed ? ldexp(S->vol_s, 3 * S->vexp) : 0.0;
	if (rep->closed && S->vol_s < 0.0 && !(S->flags & PX_MESH_NO_FLIP)) {
		rep->flipped = 1;
		rep->volume = -rep->volume;
		S->vol_s = -S->vol_s;
		for (i = 0; i < S->nt; i++)
			S->fn[i] = px_v3_neg(S->fn[i]);
		for (i = 0; i < S->nv; i++)
			S->vn[i] = px_v3_neg(S->vn[i]);
	}
	return PX_OK;
}

/* Convexity: closed, a solid rather than a flat double-sided sheet, and
 * across every edge the neighbour's far vertex on or below this
 * triangle's plane. */
static void convexity(struct mesh_setup *S)
{
	const double *xyz = S->xyz;
	px_aabb bb = px_aabb_empty();
	double ext = 0.0, dg;
	size_t i;
	int k;

	S->rep->convex = 0;
	if (!S->rep->closed)
		return;
	for (i = 0; i < S->nv; i++)
		if (S->used[i])
			px_aabb_extend(&bb, px_v3(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]));
	dg = px_aabb_diagonal(&bb) * S->vsc;
	if (!(S->vol_s > 1e-9 * dg * dg * dg))
		return;
	for (i = 0; i < S->nv; i++)
		if (S->used[i])
			ext = fmax(ext, fmax(fabs(xyz[3 * i]),
					     fmax(fabs(xyz[3 * i + 1]), fabs(xyz[3 * i + 2]))));
	for (i = 0; i < S->nt; i++) {
		const double *A = xyz + 3 * (size_t)S->canon[S->tri[3 * i]];
		const px_vec3 n = S->fn[i];
		if (S->deg[i] & DEGEN_ZERO)
			continue;
		for (k = 0; k < 3; k++) {
			int32_t o = S->nb[3 * i + k];
			int w;
			if (o < 0)
				continue;
			for (w = 0; w < 3; w++) {
				const double *W = xyz + 3 * (size_t)S->canon[S->tri[3 * (size_t)o + w]];
				double h = n.x * (W[0] - A[0]) + n.y * (W[1] - A[1]) + n.z * (W[2] - A[2]);
				if (h > 1e-12 * ext)
					return;
			}
		}
	}
	S->rep->convex = 1;
}

/* Compares rather than fmin/fmax (library calls, a fifth of the build
 * time): the coordinates are finite here. */
static inline double mn(double a, double b)
{
	return a < b ? a : b;
}

static inline double mx(double a, double b)
{
	return a > b ? a : b;
}


/* px__tree_build's box: the bounds of triangles perm[0..n). */
static void range_box(void *ctx, const uint32_t *perm, size_t n, double lo[3], double hi[3])
{
	const struct mesh_setup *S = ctx;
	size_t i;
	int k;
	for (k = 0; k < 3; k++) {
		lo[k] = INFINITY;
		hi[k] = -INFINITY;
	}
	for (i = 0; i < n; i++) {
		size_t t = perm[i];
		for (k = 0; k < 3; k++) {
			lo[k] = mn(lo[k], S->tlo[3 * t + k]);
			hi[k] = mx(hi[k], S->thi[3 * t + k]);
		}
	}
}

static int log2ceil(size_t n)
{
	int k = 0;
	while (((size_t)1 << k) < n)
		k++;
	return k;
}

static double half_area(const double lo[3], const double hi[3])
{
	double x = hi[0] - lo[0], y = hi[1] - lo[1], z = hi[2] - lo[2];
	return x * y + y * z + z * x;
}

#define SAH_BINS 16

/*
 * Binned surface-area split (the usual 16 bins per axis over the
 * centroid bounds); returns the size of the left part after partitioning
 * perm[0..n), or 0 when no split beats the others (then the caller takes
 * the median).
 */
static size_t sah_split(const struct mesh_setup *S, uint32_t *perm, size_t n,
			const double clo[3], const double chi[3])
{
	double best = INFINITY;
	int bax = -1, bbin = 0, k, j;
	size_t i, left;

	for (k = 0; k < 3; k++) {
		double ext = chi[k] - clo[k], blo[SAH_BINS][3], bhi[SAH_BINS][3];
		size_t cnt[SAH_BINS] = {0};
		double llo[3], lhi[3], rlo[3], rhi[3], la[SAH_BINS];
		size_t lc[SAH_BINS], acc;
		int m;
		if (!(ext > 0.0))
			continue;
		for (j = 0; j < SAH_BINS; j++)
			for (m = 0; m < 3; m++) {
				blo[j][m] = INFINITY;
				bhi[j][m] = -INFINITY;
			}
		for (i = 0; i < n; i++) {
			size_t t = perm[i];
			int b = (int)(SAH_BINS * (S->cen[3 * t + k] - clo[k]) / ext);
			b = b < 0 ? 0 : (b >= SAH_BINS ? SAH_BINS - 1 : b);
			cnt[b]++;
			for (m = 0; m < 3; m++) {
				blo[b][m] = mn(blo[b][m], S->tlo[3 * t + m]);
				bhi[b][m] = mx(bhi[b][m], S->thi[3 * t + m]);
			}
		}
		for (m = 0; m < 3; m++) {
			llo[m] = rlo[m] = INFINITY;
			lhi[m] = rhi[m] = -INFINITY;
		}
		acc = 0;
		for (j = 0; j < SAH_BINS - 1; j++) {
			acc += cnt[j];
			for (m = 0; m < 3; m++) {
				llo[m] = mn(llo[m], blo[j][m]);
				lhi[m] = mx(lhi[m], bhi[j][m]);
			}
			lc[j] = acc;
			la[j] = acc ? half_area(llo, lhi) : 0.0;
		}
		acc = 0;
		for (j = SAH_BINS - 1; j > 0; j--) {
			double cost;
			acc += cnt[j];
			for (m = 0; m < 3; m++) {
				rlo[m] = mn(rlo[m], blo[j][m]);
				rhi[m] = mx(rhi[m], bhi[j][m]);
			}
			if (lc[j - 1] == 0 || acc == 0)
				continue;
			cost = la[j - 1] * (double)lc[j - 1] + half_area(rlo, rhi) * (double)acc;
			if (cost < best) {
				best = cost;
				bax = k;
				bbin = j; /* bins < j go left */
			}
		}
	}
	if (bax < 0)
		return 0;
	/* partition: bins < bbin to the left */
	{
		double ext = chi[bax] - clo[bax];
		size_t a = 0, b = n;
		while (a < b) {
			size_t t = perm[a];
			int bin = (int)(SAH_BINS * (S->cen[3 * t + bax] - clo[bax]) / ext);
			bin = bin < 0 ? 0 : (bin >= SAH_BINS ? SAH_BINS - 1 : bin);
			if (bin < bbin) {
				a++;
			} else {
				uint32_t x = perm[a];
				perm[a] = perm[--b];
				perm[b] = x;
			}
		}
		left = a;
	}
	return (left > 0 && left < n) ? left : 0;
}

/* px__tree_build's split: surface-area splits while the depth leaves
 * room for the rest of the range to be finished by median splits within
 * PX_MESH_MAX_DEPTH. */
static size_t split(void *ctx, uint32_t *perm, size_t n, int depth, const double klo[3],
		    const double khi[3])
{
	if (depth + 2 + log2ceil(n) <= PX_MESH_MAX_DEPTH - 2)
		return sah_split(ctx, perm, n, klo, khi);
	return 0;
}

/* The hierarchy: a binary tree over the triangles' centres, collapsed
 * to four-wide nodes; perm[] the leaf order. */
static int hierarchy(struct mesh_setup *S)
{
	struct mesh *M = S->M;
	struct px__tree_build B;
	size_t i;

	S->perm = malloc(S->nt * sizeof(*S->perm));
	/* cache-line aligned: a 64-byte node then costs one line, not two */
	M->nodes = aligned_alloc(64, (S->nt + 1) * sizeof(*M->nodes));
	if (!S->perm || !M->nodes)
		return PX_E_NOMEM;
	memset(M->nodes, 0, (S->nt + 1) * sizeof(*M->nodes));
	for (i = 0; i < S->nt; i++)
		S->perm[i] = (uint32_t)i;
	memset(&B, 0, sizeof(B));
	B.perm = S->perm;
	B.key = S->cen;
	B.leaf = (size_t)S->leaf;
	B.ctx = S;
	B.box = range_box;
	B.split = split;
	B.store = px__node_store;
	B.nodes = M->nodes;
	px__tree_build(&B, S->nt);
	M->n_nodes = B.n_nodes;
	M->depth = B.depth + 1;
	S->rep->depth = M->depth;
	if (M->depth > PX_MESH_MAX_DEPTH) {
		rep_msg(S->rep, "hierarchy too deep (%d)", M->depth);
		return PX_E_RANGE;
	}
	M->n4 = aligned_alloc(64, M->n_nodes * sizeof(*M->n4));
	if (!M->n4)
		return PX_E_NOMEM;
	M->n_n4 = 0;
	px__node4_collapse(M->nodes, M->n4, &M->n_n4, 0);
	free(M->nodes);
	M->nodes = NULL;
	return PX_OK;
}

/* Leaf triangle L's float lower-bound data (struct tlb) from its unit
 * normal nu in the vertex order (unflipped) and its vertices P. */
static void tlb_fill(struct tlb *L, px_vec3 nu, const px_vec3 P[3])
{
	int k;
	L->c[0][0] = (float)nu.x;
	L->c[1][0] = (float)nu.y;
	L->c[2][0] = (float)nu.z;
	L->c[3][0] = (float)px_v3_dot(nu, P[0]);
	for (k = 0; k < 3; k++) {
		px_vec3 e = px_v3_sub(P[(k + 1) % 3], P[k]), mm;
		if (px_v3_normalize(px_v3_cross(e, nu), px_v3(0, 0, 0), &mm) != PX_OK)
			continue;
		L->c[0][1 + k] = (float)mm.x;
		L->c[1][1 + k] = (float)mm.y;
		L->c[2][1 + k] = (float)mm.z;
		L->c[3][1 + k] = (float)px_v3_dot(mm, P[k]);
	}
}

/* The query data in leaf order: compact vertices (welded, numbered in
 * order of first use), lower-bound data, normals and pseudo-normals. */
static int leaf_order(struct mesh_setup *S)
{
	struct mesh *M = S->M;
	size_t i, nv = S->nv, nt = S->nt;
	uint32_t *vmap;
	int k;

	/* at most this many distinct vertices; trimmed once they are known */
	M->vx = malloc((nv < 3 * nt ? nv : 3 * nt) * sizeof(*M->vx));
	M->tv = malloc(3 * nt * sizeof(*M->tv));
	M->lb = aligned_alloc(64, nt * sizeof(*M->lb));
	M->orig = malloc(nt * sizeof(*M->orig));
	M->leaf_of = malloc(nt * sizeof(*M->leaf_of));
	M->fn = malloc(nt * sizeof(*M->fn));
	M->en = malloc(3 * nt * sizeof(*M->en));
	M->vnt = malloc(3 * nt * sizeof(*M->vnt));
	M->degen = malloc(nt);
	if (!M->vx || !M->tv || !M->lb || !M->orig || !M->leaf_of || !M->fn || !M->en || !M->vnt ||
	    !M->degen)
		return PX_E_NOMEM;
	vmap = malloc(nv * sizeof(*vmap));
	if (!vmap)
		return PX_E_NOMEM;
	for (i = 0; i < nv; i++)
		vmap[i] = UINT32_MAX;
	M->n_vx = 0;
	M->box = px_aabb_empty();
	for (i = 0; i < nt; i++) {
		uint32_t t = S->perm[i];
		const uint32_t *tc = S->tri + 3 * (size_t)t;
		const int32_t *nb = S->nb + 3 * (size_t)t;
		px_vec3 P[3];
		for (k = 0; k < 3; k++) {
			/* welded vertices numbered in order of first use */
			uint32_t c = S->canon[tc[k]];
			const double *X = S->xyz + 3 * (size_t)c;
			P[k] = px_v3(X[0], X[1], X[2]);
			px_aabb_extend(&M->box, P[k]);
			M->vnt[3 * i + k] = S->vn[c];
			M->en[3 * i + k] = nb[k] >= 0 ? px_v3_add(S->fn[t], S->fn[nb[k]]) : S->fn[t];
			if (vmap[c] == UINT32_MAX) {
				vmap[c] = (uint32_t)M->n_vx;
				M->vx[M->n_vx++] = P[k];
			}
			M->tv[3 * i + k] = vmap[c];
		}
		memset(&M->lb[i], 0, sizeof(M->lb[i]));
		/* the accurate normal (a thin triangle's plain one could tilt
		 * past the slack), in the vertex order, which the edges'
		 * outward normals need: unflipped */
		if (!(S->deg[t] & DEGEN_ZERO))
			tlb_fill(&M->lb[i], S->rep->flipped ? px_v3_neg(S->fn[t]) : S->fn[t], P);
		M->orig[i] = t;
		M->leaf_of[t] = (uint32_t)i;
		M->fn[i] = S->fn[t];
		M->degen[i] = S->deg[t];
	}
	free(vmap);
	{
		px_vec3 *vx = realloc(M->vx, M->n_vx * sizeof(*M->vx));
		if (vx)
			M->vx = vx;
	}
	M->absmax = fmax(fmax(fabs(M->box.min.x), fabs(M->box.max.x)),
			 fmax(fmax(fabs(M->box.min.y), fabs(M->box.max.y)),
			      fmax(fabs(M->box.min.z), fabs(M->box.max.z))));
	M->bytes = sizeof(*M) + M->n_vx * sizeof(px_vec3) +
		   nt * (3 * sizeof(uint32_t) + sizeof(struct tlb) + 2 * sizeof(uint32_t) +
			 7 * sizeof(px_vec3) + 1) +
		   M->n_n4 * sizeof(struct node4);
	return PX_OK;
}

/* Convex meshes: the distinct vertices for the support function and,
 * beyond 32 of them, their edge graph (CSR, from the distinct edges
 * sorted in E) with the six axis-extreme vertices as climbing starts. */
static int hull(struct mesh_setup *S)
{
	struct mesh *M = S->M;
	const struct edge *E = S->E;
	uint32_t *hid = S->order; /* reused: canonical vertex -> hull index */
	uint32_t *fill;
	size_t i, h = 0, ne2 = 0;
	int k;

	M->hull = malloc(S->rep->n_welded * sizeof(*M->hull));
	if (!M->hull)
		return PX_E_NOMEM;
	for (i = 0; i < S->nv; i++)
		if (S->used[i] && S->canon[i] == i && h < S->rep->n_welded) {
			hid[i] = (uint32_t)h;
			M->hull[h++] = px_v3(S->xyz[3 * i], S->xyz[3 * i + 1], S->xyz[3 * i + 2]);
		}
	M->n_hull = h;
	M->bytes += h * sizeof(*M->hull);
	if (h <= 32)
		return PX_OK;
	M->adj_start = calloc(h + 1, sizeof(uint32_t));
	M->adj = malloc(2 * S->ne * sizeof(uint32_t));
	fill = calloc(h, sizeof(uint32_t));
	if (!M->adj_start || !M->adj || !fill) {
		free(fill);
		return PX_E_NOMEM;
	}
	for (i = 0; i < S->ne; i++)
		if (i == 0 || E[i].lo != E[i - 1].lo || E[i].hi != E[i - 1].hi) {
			M->adj_start[hid[E[i].lo] + 1]++;
			M->adj_start[hid[E[i].hi] + 1]++;
		}
	for (i = 0; i < h; i++)
		M->adj_start[i + 1] += M->adj_start[i];
	for (i = 0; i < S->ne; i++)
		if (i == 0 || E[i].lo != E[i - 1].lo || E[i].hi != E[i - 1].hi) {
			uint32_t a = hid[E[i].lo], b = hid[E[i].hi];
			M->adj[M->adj_start[a] + fill[a]++] = b;
			M->adj[M->adj_start[b] + fill[b]++] = a;
			ne2 += 2;
		}
	free(fill);
	for (k = 0; k < 6; k++) {
		double bs = -INFINITY;
		for (i = 0; i < h; i++) {
			double v = px_v3_comp(M->hull[i], k / 2) * (k % 2 ? 1.0 : -1.0);
			if (v > bs) {
				bs = v;
				M->ext[k] = (uint32_t)i;
			}
		}
	}
	M->bytes += (h + 1 + ne2) * sizeof(uint32_t);
	return PX_OK;
}

/* The hint grid (struct mesh), within budget cells: measured on a
 * 70k-triangle torus, one cell per 8 triangles gives most of the gain of
 * 30 times more cells at a fifth of the setup. */
static int grid(struct mesh *M, long budget)
{
	long cap = budget, ncell;

	if (budget <= 0)
		return PX_OK;
	if ((double)cap > (double)(M->nt / 8))
		cap = (long)(M->nt / 8);
	ncell = px__grid_fill(M->box, cap, px__mesh_grid_nearest, M, &M->grid, M->gdim, &M->gorg,
			      &M->gcell, &M->ginv);
	if (ncell < 0)
		return (int)ncell;
	M->bytes += (size_t)ncell * sizeof(*M->grid);
	return PX_OK;
}

void px__mesh_free(void *impl)
{
	struct mesh *M = impl;
	if (!M)
		return;
	free(M->vx);
	free(M->tv);
	free(M->lb);
	free(M->orig);
	free(M->leaf_of);
	free(M->fn);
	free(M->en);
	free(M->vnt);
	free(M->degen);
	free(M->nodes);
	free(M->n4);
	free(M->hull);
	free(M->adj_start);
	free(M->adj);
	free(M->grid);
	free(M);
}

static void setup_free(struct mesh_setup *S)
{
	free(S->used);
	free(S->order);
	free(S->canon);
	free(S->perm);
	free(S->E);
	free(S->nb);
	free(S->fn);
	free(S->vn);
	free(S->cen);
	free(S->tlo);
	free(S->thi);
	free(S->deg);
}

/* Everything but the model: checks, topology, hierarchy, query data. */
static int build(struct mesh_setup *S, const struct px_mesh_opts *opt)
{
	int rc;
	if ((rc = check_vertices(S)) != PX_OK || (rc = weld(S)) != PX_OK ||
	    (rc = triangles(S)) != PX_OK || (rc = topology(S)) != PX_OK)
		return rc;
	convexity(S);
	S->M = calloc(1, sizeof(*S->M));
	if (!S->M)
		return PX_E_NOMEM;
	S->M->nt = S->nt;
	S->M->nv = S->nv;
	S->M->closed = S->rep->closed;
	if ((rc = hierarchy(S)) != PX_OK || (rc = leaf_order(S)) != PX_OK ||
	    (rc = grid(S->M, opt ? opt->grid_cells : 0)) != PX_OK)
		return rc;
	return S->rep->convex ? hull(S) : PX_OK;
}

/* A cleared report (nothing found yet) and no model yet. */
static struct px_mesh_report *report_init(struct px_mesh_report *rep, struct px_model **out)
{
	memset(rep, 0, sizeof(*rep));
	rep->first_degenerate = -1;
	rep->first_bad_edge_triangle = -1;
	if (out)
		*out = NULL;
	return rep;
}

int px_mesh_model(const double *xyz, size_t nv, const uint32_t *tri,
		  size_t nt, const struct px_mesh_opts *opt,
		  struct px_mesh_report *rep, struct px_model **out)
{
	struct px_mesh_report lrep;
	struct mesh_setup S;
	int rc;

	rep = report_init(rep ? rep : &lrep, out);
	rep->n_vertices = nv;
	rep->n_triangles = nt;
	memset(&S, 0, sizeof(S));
	S.xyz = xyz;
	S.nv = nv;
	S.tri = tri;
	S.nt = nt;
	S.flags = opt ? opt->flags : 0u;
	S.leaf = (opt && opt->leaf_size) ? opt->leaf_size : 6;
	S.rep = rep;
	S.vsc = 1.0;
	if ((rc = check_args(&S, opt, out)) != PX_OK)
		return rc;
	rc = build(&S, opt);
	if (rc == PX_OK) {
		/* the model owns the mesh now, also on failure */
		rc = px__mesh_wrap(S.M, rep->convex, out);
		S.M = NULL;
		if (rc != PX_OK)
			rep_msg(rep, "out of memory");
	} else if (rc == PX_E_NOMEM) {
		rep_msg(rep, "out of memory");
	}
	px__mesh_free(S.M);
	setup_free(&S);
	return rc;
}

/* ---- files ------------------------------------------------------------------ */

/* The imported vertices times scale; a mirroring scale (negative
 * product) turns every triangle round so that outside stays outside. */
static void scale_mesh(double *xyz, size_t nv, uint32_t *tri, size_t nt,
		       const double scale[3])
{
	size_t i;
	for (i = 0; i < nv; i++) {
		xyz[3 * i] *= scale[0];
		xyz[3 * i + 1] *= scale[1];
		xyz[3 * i + 2] *= scale[2];
	}
	if (scale[0] * scale[1] * scale[2] < 0.0)
		for (i = 0; i < nt; i++) {
			uint32_t t = tri[3 * i + 1];
			tri[3 * i + 1] = tri[3 * i + 2];
			tri[3 * i + 2] = t;
		}
}

int px__mesh_load_data(const char *path, char *data, size_t len,
		       const double scale[3], const struct px_mesh_opts *opt,
		       struct px_mesh_report *rep, struct px_model **out)
{
	struct px_mesh_report lrep;
	double *xyz = NULL;
	uint32_t *tri = NULL;
	size_t nv = 0, nt = 0, skipped = 0;
	char msg[sizeof(rep->message)];
	int rc;

	rep = report_init(rep ? rep : &lrep, out);
	if (!out || !path || !data) {
		rep_msg(rep, "invalid arguments");
		return PX_E_INVAL;
	}
	rc = px__import_data(path, data, len, 1, &xyz, &nv, &tri, &nt, &skipped,
			     msg, sizeof(msg));
	if (rc != PX_OK) {
		snprintf(rep->message, sizeof(rep->message), "%s", msg);
		return rc;
	}
	if (scale)
		scale_mesh(xyz, nv, tri, nt, scale);
	rc = px_mesh_model(xyz, nv, tri, nt, opt, rep, out);
	if (rep->message[0]) {
		px__prefix_path(rep->message, sizeof(rep->message), path);
	}
	free(xyz);
	free(tri);
	return rc;
}

int px_mesh_load_scaled(const char *path, const double scale[3],
			const struct px_mesh_opts *opt,
			struct px_mesh_report *rep, struct px_model **out)
{
	struct px_mesh_report lrep;
	char *data = NULL;
	size_t len = 0;
	int rc, k;

	rep = report_init(rep ? rep : &lrep, out);
	if (!out || !path) {
		rep_msg(rep, "invalid arguments");
		return PX_E_INVAL;
	}
	for (k = 0; scale && k < 3; k++)
		if (!isfinite(scale[k]) || scale[k] == 0.0) {
			snprintf(rep->message, sizeof(rep->message),
				 "%s: scale %d must be finite and not zero", path, k);
			return PX_E_RANGE;
		}
	rc = px__import_read(path, &data, &len, rep->message, sizeof(rep->message));
	if (rc != PX_OK)
		return rc;
	rc = px__mesh_load_data(path, data, len, scale, opt, rep, out);
	free(data);
	return rc;
}

int px_mesh_load(const char *path, const struct px_mesh_opts *opt,
		 struct px_mesh_report *rep, struct px_model **out)
{
	return px_mesh_load_scaled(path, NULL, opt, rep, out);
}
