/*
 * mesh_tree.c - the setup of the box hierarchies and hint grids that
 * meshes and point clouds share (mesh_internal.h): the binary tree
 * build, its collapse to four-wide nodes, and the hint grid's layout and
 * fill. Setup only.
 */
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

#include "mesh_internal.h"
#include "model_internal.h"

void px__report_msg(char *msg, size_t cap, const char *fmt, ...)
{
	va_list ap;
	if (!msg || msg[0])
		return;
	va_start(ap, fmt);
	vsnprintf(msg, cap, fmt, ap);
	va_end(ap);
}

/* ---- binary tree ------------------------------------------------------------ */

/* Node for the range [s, s + n) of B->perm (n > leaf) at depth, its key
 * bounds klo, khi when B->box_is_key (else computed here); returns its
 * index. Recursion depth: the tree's (checked by the callers). */
static uint32_t tree_node(struct px__tree_build *B, size_t s, size_t n, int depth,
			  const double *klo, const double *khi)
{
	uint32_t me = (uint32_t)B->n_nodes++;
	double lo[3], hi[3], clo[2][3], chi[2][3];
	size_t half = 0, part[2][2];
	int c;

	if (depth > B->depth)
		B->depth = depth;
	if (!B->box_is_key) {
		px__key_bounds(B->perm + s, n, B->key, lo, hi);
		klo = lo;
		khi = hi;
	}
	if (B->split)
		half = B->split(B->ctx, B->perm + s, n, depth, klo, khi);
	if (half == 0)
		half = px__median_split(B->perm + s, n, B->key, klo, khi);
	part[0][0] = s;
	part[0][1] = half;
	part[1][0] = s + half;
	part[1][1] = n - half;
	for (c = 0; c < 2; c++) {
		uint32_t idx = (uint32_t)part[c][0], cnt = (uint32_t)part[c][1];
		B->box(B->ctx, B->perm + part[c][0], part[c][1], clo[c], chi[c]);
		if (part[c][1] > B->leaf) {
			idx = tree_node(B, part[c][0], part[c][1], depth + 1, clo[c], chi[c]);
			cnt = 0;
		}
		B->store(B->nodes, me, c, clo[c], chi[c], idx, cnt);
	}
	return me;
}

void px__tree_build(struct px__tree_build *B, size_t n)
{
	double lo[3], hi[3];
	B->n_nodes = 0;
	B->depth = 0;
	if (n > B->leaf) {
		if (!B->box_is_key) {
			tree_node(B, 0, n, 0, NULL, NULL);
			return;
		}
		B->box(B->ctx, B->perm, n, lo, hi);
		tree_node(B, 0, n, 0, lo, hi);
		return;
	}
	/* one leaf: the root's second child absent, its box empty */
	B->box(B->ctx, B->perm, n, lo, hi);
	B->n_nodes = 1;
	B->store(B->nodes, 0, 0, lo, hi, 0, (uint32_t)n);
	lo[0] = lo[1] = lo[2] = INFINITY;
	hi[0] = hi[1] = hi[2] = -INFINITY;
	B->store(B->nodes, 0, 1, lo, hi, EMPTY, 0);
}

void px__node_store(void *nodes, uint32_t me, int c, const double lo[3], const double hi[3],
		    uint32_t idx, uint32_t cnt)
{
	struct node *nd = (struct node *)nodes + me;
	int k;
	for (k = 0; k < 3; k++) {
		nd->lo[c][k] = px__f_down(lo[k]);
		nd->hi[c][k] = px__f_up(hi[k]);
	}
	nd->idx[c] = idx;
	nd->cnt[c] = cnt;
}

/* ---- four-wide nodes ---------------------------------------------------------- */

uint32_t px__node4_collapse(const struct node *bn, struct node4 *n4,
			    size_t *n_n4, uint32_t b)
{
	uint32_t me = (uint32_t)(*n_n4)++;
	struct node4 *o = &n4[me];
	int s = 0, c, g, j, k;
	const struct node *nb = &bn[b];

	for (j = 0; j < 4; j++) {
		for (k = 0; k < 3; k++) {
			o->lo[k][j] = INFINITY;
			o->hi[k][j] = -INFINITY;
		}
		o->idx[j] = EMPTY;
		o->cnt[j] = 0;
	}
	for (c = 0; c < 2; c++) {
		if (nb->idx[c] == EMPTY)
			continue;
		if (nb->cnt[c] > 0) {
			for (k = 0; k < 3; k++) {
				o->lo[k][s] = nb->lo[c][k];
				o->hi[k][s] = nb->hi[c][k];
			}
			o->idx[s] = nb->idx[c];
			o->cnt[s] = nb->cnt[c];
			s++;
			continue;
		}
		for (g = 0; g < 2; g++) {
			const struct node *gn = &bn[nb->idx[c]];
			if (gn->idx[g] == EMPTY)
				continue;
			for (k = 0; k < 3; k++) {
				o->lo[k][s] = gn->lo[g][k];
				o->hi[k][s] = gn->hi[g][k];
			}
			o->idx[s] = gn->idx[g]; /* binary index until collapsed below */
			o->cnt[s] = gn->cnt[g];
			s++;
		}
	}
	for (j = 0; j < s; j++)
		if (n4[me].cnt[j] == 0) {
			uint32_t ch = px__node4_collapse(bn, n4, n_n4, n4[me].idx[j]);
			n4[me].idx[j] = ch;
		}
	return me;
}

/* ---- hint grid ------------------------------------------------------------------ */

/*
 * The hint grid (struct mesh, struct cloud): cubic cells over the box
 * grown by an eighth of its largest extent, as many as the budget allows.
 * Cells are filled in a serpentine order so that each exact query starts
 * from its neighbour's answer, which keeps the build near the cost of
 * coherent queries.
 */
void px__grid_layout(px_aabb box, long cap, int d[3], px_vec3 *org, double *h_out)
{
	double ext[3] = {box.max.x - box.min.x, box.max.y - box.min.y,
			 box.max.z - box.min.z};
	double len = fmax(ext[0], fmax(ext[1], ext[2])), margin, h, vol;
	int k, it;

	if (cap < 1)
		cap = 1;
	/* a model collapsed to one point still gets a (one-cell) grid */
	margin = len > 0.0 ? 0.125 * len : 1.0;
	vol = (ext[0] + 2 * margin) * (ext[1] + 2 * margin) * (ext[2] + 2 * margin);
	h = cbrt(vol / (double)cap);
	/* a model wider than about 1e102 overflows the volume, one
	 * smaller than about 1e-103 underflows it to 0; neither its cube
	 * root */
	if (!isfinite(h) || !(h > 0.0))
		h = cbrt(ext[0] + 2 * margin) * cbrt(ext[1] + 2 * margin) *
		    cbrt(ext[2] + 2 * margin) / cbrt((double)cap);
	for (it = 0;; it++) {
		double cells = 1.0;
		for (k = 0; k < 3; k++) {
			double n = ceil((ext[k] + 2 * margin) / h);
			/* clamped before the cast (undefined past INT_MAX) to
			 * cap + 1, which still fails the test below */
			double nmax = cap < INT_MAX ? (double)cap + 1.0 : (double)INT_MAX;
			d[k] = !(n >= 1.0) ? 1 : (n > nmax ? (int)nmax : (int)n);
			cells *= d[k];
		}
		if (cells <= (double)cap || it > 200)
			break;
		h *= 1.02;
	}
	if ((double)d[0] * d[1] * d[2] > (double)cap) {
		d[0] = d[1] = d[2] = 1;
		h = len + 2 * margin;
	}
	*h_out = h;
	*org = px_v3(0.5 * (box.min.x + box.max.x - d[0] * h),
		     0.5 * (box.min.y + box.max.y - d[1] * h),
		     0.5 * (box.min.z + box.max.z - d[2] * h));
}

long px__grid_fill(px_aabb box, long cap, long (*nearest)(const void *ctx, px_vec3 c, long prev),
		   const void *ctx, uint32_t **cell, int dim[3], px_vec3 *org, double *h_out,
		   double *inv)
{
	int d[3], k, iz, jx, jy;
	long prev = -1;
	size_t ncell;
	uint32_t *g;
	double h;

	px__grid_layout(box, cap, d, org, &h);
	ncell = (size_t)d[0] * (size_t)d[1] * (size_t)d[2];
	*cell = g = malloc(ncell * sizeof(*g));
	if (!g)
		return PX_E_NOMEM;
	for (k = 0; k < 3; k++)
		dim[k] = d[k];
	*h_out = h;
	*inv = 1.0 / h;
	for (iz = 0; iz < d[2]; iz++)
		for (jy = 0; jy < d[1]; jy++) {
			int y = (iz & 1) ? d[1] - 1 - jy : jy;
			int back = ((iz * d[1] + jy) & 1) != 0;
			for (jx = 0; jx < d[0]; jx++) {
				int x = back ? d[0] - 1 - jx : jx;
				px_vec3 c = px_v3(org->x + (x + 0.5) * h, org->y + (y + 0.5) * h,
						  org->z + (iz + 0.5) * h);
				long bi = nearest(ctx, c, prev);
				if (bi < 0)
					bi = prev >= 0 ? prev : 0;
				prev = bi;
				g[((size_t)iz * (size_t)d[1] + (size_t)y) * (size_t)d[0] + (size_t)x] =
					(uint32_t)bi;
			}
		}
	return (long)ncell;
}
