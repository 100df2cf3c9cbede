/*
 * pair_nurbs.c - certified distance of a NURBS surface model to a
 * triangle mesh, to another NURBS surface model, or to a convex model
 * with a support function (pair_internal.h: px__pair_nurbs).
 *
 * Both models are descended at once. A NURBS model's nodes are its
 * rational Bezier patches (the distance core's pieces) and their
 * sub-squares, each with the control net restricted to it (de Casteljau
 * twice per direction from the piece's net, so nothing is stored): the
 * net's convex hull holds the sub-patch (positive weights), and its four
 * corner points lie on the surface. A mesh's nodes are its hierarchy's
 * boxes and triangles; a convex model is one node. A pair of nodes is
 * bounded below by their boxes, then (when neither is a box) by GJK's
 * lower bound on the distance of the two convex hulls (or hull and
 * convex model), which deviates from the surfaces' distance by the
 * hulls' flatness, the square of the sub-patch's size: deep in the
 * descent only the pairs near the minimum stay. Upper bounds are real
 * pairs of surface points: the corners of a sub-patch against a
 * triangle (exactly), against the corners of another sub-patch, or
 * against the convex model (its point query); a new best pair is
 * polished by Newton from its parameters (both sub-patches' four
 * parameters with the full Hessian; against a triangle or a convex
 * model, A's point problem towards the other's closest point), every
 * iterate a real pair. A pair is pruned when its lower bound is within
 * eps of the best distance, so the answer, a real pair of points, is at
 * most eps above the global minimum: eps = 1e-6 of the NURBS model's
 * box diagonal (the smaller of two). The patches themselves are grouped
 * by halving the model's patch list (the decomposition's order, row by
 * row) down to groups of four, bounded by their pieces' boxes in the
 * model's own frame; boxes are compared in both models' frames.
 * Depth-first, the nearer child first; with a coherent start (last
 * cycle's pair, its distance re-evaluated at the new poses) the
 * descent starts with a bound.
 *
 * Handled: NURBS models of untrimmed surfaces only (no curves), patches
 * of degree up to 5 in each direction, at most 256 patches per model.
 * Anything else (B-rep parts, trimmed or curve models) answers 0 and
 * takes the general search. The descent gives up certification (the
 * best pair found is still returned, flagged) when its work budget or
 * stack runs out or a pair of smallest nodes stays unresolved.
 * Overlapping pairs (a best distance within eps of zero, a projection
 * inside a closed model, one model inside the other) answer 0 as well:
 * the general search's depth search reports them, as before.
 *
 * Memory and real-time rules: no allocation; the stack of node pairs
 * (about 110 kB) and the children's buffer (about 40 kB) are on the C
 * stack; work bounded by NP_BUDGET node pairs and NP_POLISH polishes
 * of NP_NEWTON steps. RT-safe.
 */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "dist_internal.h"
#include "mesh_internal.h"
#include "model_internal.h"
#include "pair_internal.h"
#include "px_mesh.h"

#define NP_MAX_DEG 5
#define NP_MAX_CP ((NP_MAX_DEG + 1) * (NP_MAX_DEG + 1))
#define NP_MAX_PATCHES 256
#define NP_STACK 1024
#define NP_BUDGET 20000
#define NP_MAX_LEVEL 30
#define NP_POLISH 6
#define NP_NEWTON 12
#define NP_GROUP_LEAF 4
#define NP_REL 1e-6

#ifdef PX_TEST_HOOKS
int px__pair_nurbs_off = 0;
#endif

enum { N_GROUP, N_PATCH, N_BOX, N_LEAF, N_TRI, N_CONVEX };
enum { B_NONE, B_PATCH, B_TRI, B_CONVEX };
enum { S_NURBS, S_MESH, S_CONVEX };

/* A node of one side: a group of a NURBS model's patches (its patch
 * list's range [idx, cnt), halved down to NP_GROUP_LEAF patches; the
 * root is the whole list), a sub-patch
 * [i, i + 1] x [j, j + 1] / 2^level of piece idx, a mesh node (node4
 * idx) or leaf range [idx, idx + cnt) with its box, a triangle (leaf
 * index idx), or the whole convex model. */
struct np_node {
	int kind;
	int idx;
	int cnt; /* N_LEAF: triangles; N_PATCH: level; N_GROUP: range end */
	uint32_t i, j;
	/* N_BOX, N_LEAF: box, working frame; N_GROUP: the model's frame */
	float lo[3], hi[3];
};

struct np_ent {
	struct np_node a, b;
	double lb;
	float sa, sb; /* the nodes' box diagonals (which to split) */
};

struct np_side {
	int kind;
	const struct px_model *m;
	const struct px_dist_model *dm;
	const struct mesh *M;
	px_pose to_f; /* the model's frame to the working frame */
	int np;       /* NURBS: patches (pieces pid[0..np)) */
	int pid[NP_MAX_PATCHES];
};

/* A node's geometry in the working frame: n hull points (0: only the
 * box; -1: the convex model itself), the corners on the surface, the
 * box, and the feature index a result reports. */
struct np_geo {
	int n, nc;
	px_vec3 p[NP_MAX_CP];
	px_vec3 c[4];
	px_aabb box;
	px_aabb lbox; /* NURBS nodes: the box in the model's own frame */
	int has_lbox;
	int ent;
	int piece, tri;          /* N_PATCH: its piece; N_TRI: leaf index */
	double s0, s1, t0, t1;   /* N_PATCH: its square in the piece */
};

/* Where the best pair lies, for the Newton polish: A's piece and (s,
 * t) (piece < 0: unknown), and B's sub-patch, triangle or model. */
struct np_at {
	int piece;
	double s, t;
	int bkind, bpiece, btri;
	double u, v;
};

struct np_ctx {
	struct np_side A, B;
	double eps, slack, best, polished;
	px_vec3 pa, pb; /* the best pair, working frame */
	int ia, ib;
	struct np_at at;
	int polish_left, certified, overlap, work;
	px_pose f_to_w, f_to_a; /* the working frame to the world, to A's */
};

/* Restrict the Bezier control polygon P[k * stride + c] (k = 0..n, c =
 * 0..3, homogeneous) to [a, b] of its parameter: the left part of a
 * split at b, then the right part of a split of that at a / b. */
static void bez_restrict(double *P, int n, int stride, double a, double b)
{
	int r, k, c;
	if (b < 1.0)
		for (r = 1; r <= n; r++)
			for (k = n; k >= r; k--)
				for (c = 0; c < 4; c++)
					P[k * stride + c] = (1.0 - b) * P[(k - 1) * stride + c] +
							    b * P[k * stride + c];
	if (a > 0.0) {
		double t = a / b;
		for (r = 1; r <= n; r++)
			for (k = 0; k <= n - r; k++)
				for (c = 0; c < 4; c++)
					P[k * stride + c] = (1.0 - t) * P[k * stride + c] +
							    t * P[(k + 1) * stride + c];
	}
}

/* A sub-patch's homogeneous control net: the piece's, restricted to
 * the node's square. */
static int patch_net(const struct np_side *s, const struct np_node *nd, double (*net)[4])
{
	const struct px_spiece *sp = &s->dm->spc[s->dm->pieces[nd->idx].idx];
	int p = sp->p_, q = sp->q_, np = (p + 1) * (q + 1), k, c;

	for (k = 0; k < np; k++)
		for (c = 0; c < 4; c++)
			net[k][c] = sp->h_[c * np + k];
	if (nd->cnt > 0) {
		double sc = ldexp(1.0, -nd->cnt);
		double s0 = nd->i * sc, s1 = (nd->i + 1) * sc, t0 = nd->j * sc,
		       t1 = (nd->j + 1) * sc;
		for (k = 0; k <= q; k++)
			bez_restrict(&net[k][0], p, 4 * (q + 1), s0, s1);
		for (k = 0; k <= p; k++)
			bez_restrict(&net[k * (q + 1)][0], q, 4, t0, t1);
	}
	return np;
}

/* Grow the box lo, hi by x (compares: no library calls). */
static inline void extend(px_vec3 *lo, px_vec3 *hi, px_vec3 x)
{
	lo->x = x.x < lo->x ? x.x : lo->x;
	lo->y = x.y < lo->y ? x.y : lo->y;
	lo->z = x.z < lo->z ? x.z : lo->z;
	hi->x = x.x > hi->x ? x.x : hi->x;
	hi->y = x.y > hi->y ? x.y : hi->y;
	hi->z = x.z > hi->z ? x.z : hi->z;
}

/* The geometry of a sub-patch from its net: points in the working
 * frame, their box, the corners. */
static void net_geo(const struct np_side *s, const struct np_node *nd, double (*net)[4],
		    struct np_geo *g)
{
	const struct piece *pc = &s->dm->pieces[nd->idx];
	const struct px_spiece *sp = &s->dm->spc[pc->idx];
	int p = sp->p_, q = sp->q_, np = (p + 1) * (q + 1), k;
	px_vec3 lo, hi, llo, lhi;

	g->n = np;
	for (k = 0; k < np; k++) {
		double iw = 1.0 / net[k][3];
		px_vec3 l = px_v3(net[k][0] * iw, net[k][1] * iw, net[k][2] * iw);
		px_vec3 x = px_pose_transform_point(s->to_f, l);
		g->p[k] = x;
		if (k == 0) {
			lo = hi = x;
			llo = lhi = l;
			continue;
		}
		extend(&llo, &lhi, l);
		extend(&lo, &hi, x);
	}
	g->box.min = lo;
	g->box.max = hi;
	g->lbox.min = llo;
	g->lbox.max = lhi;
	g->has_lbox = 1;
	g->nc = 4;
	g->c[0] = g->p[0];
	g->c[1] = g->p[q];
	g->c[2] = g->p[p * (q + 1)];
	g->c[3] = g->p[np - 1];
	g->ent = pc->ent;
	g->piece = nd->idx;
	{
		double sc = ldexp(1.0, -nd->cnt);
		g->s0 = nd->i * sc;
		g->s1 = (nd->i + 1) * sc;
		g->t0 = nd->j * sc;
		g->t1 = (nd->j + 1) * sc;
	}
}

static void patch_geo(const struct np_side *s, const struct np_node *nd, struct np_geo *g)
{
	double net[NP_MAX_CP][4];
	patch_net(s, nd, net);
	net_geo(s, nd, net, g);
}

/* Child k of a sub-patch (its square's quarter k: bit 1 the upper half
 * in s, bit 0 in t, as children() numbers them) from the parent's net: one de Casteljau split per
 * direction. */
static void child_net(const struct np_side *s, const struct np_node *nd, double (*pnet)[4],
		      int k, double (*net)[4])
{
	const struct px_spiece *sp = &s->dm->spc[s->dm->pieces[nd->idx].idx];
	int p = sp->p_, q = sp->q_, np = (p + 1) * (q + 1), l;
	double s0 = (k & 2) ? 0.5 : 0.0, t0 = (k & 1) ? 0.5 : 0.0;

	memcpy(net, pnet, (size_t)np * sizeof(net[0]));
	for (l = 0; l <= q; l++)
		bez_restrict(&net[l][0], p, 4 * (q + 1), s0, s0 + 0.5);
	for (l = 0; l <= p; l++)
		bez_restrict(&net[l * (q + 1)][0], q, 4, t0, t0 + 0.5);
}

static void node_geo(const struct np_side *s, const struct np_node *nd, struct np_geo *g)
{
	int k;
	g->nc = 0;
	g->ent = -1;
	g->has_lbox = 0;
	switch (nd->kind) {
	case N_PATCH:
		patch_geo(s, nd, g);
		return;
	case N_TRI: {
		struct mtri3 t = px__tri3_get(s->M, (size_t)nd->idx);
		g->n = g->nc = 3;
		g->p[0] = g->c[0] = t.a;
		g->p[1] = g->c[1] = t.b;
		g->p[2] = g->c[2] = t.c;
		g->box.min = px_v3(fmin(t.a.x, fmin(t.b.x, t.c.x)), fmin(t.a.y, fmin(t.b.y, t.c.y)),
				   fmin(t.a.z, fmin(t.b.z, t.c.z)));
		g->box.max = px_v3(fmax(t.a.x, fmax(t.b.x, t.c.x)), fmax(t.a.y, fmax(t.b.y, t.c.y)),
				   fmax(t.a.z, fmax(t.b.z, t.c.z)));
		g->ent = (int)s->M->orig[nd->idx];
		g->tri = nd->idx;
		return;
	}
	case N_CONVEX:
		g->n = -1;
		g->box = px_model_world_aabb(s->m);
		return;
	default:
		g->n = 0;
		for (k = 0; k < 3; k++) {
			(&g->box.min.x)[k] = nd->lo[k];
			(&g->box.max.x)[k] = nd->hi[k];
		}
		if (nd->kind == N_LEAF && 3 * nd->cnt <= NP_MAX_CP) {
			/* a leaf's triangles: the hull of their corners */
			for (k = 0; k < nd->cnt; k++) {
				struct mtri3 t = px__tri3_get(s->M, (size_t)(nd->idx + k));
				g->p[3 * k] = t.a;
				g->p[3 * k + 1] = t.b;
				g->p[3 * k + 2] = t.c;
			}
			g->n = 3 * nd->cnt;
			if (nd->cnt == 1) { /* one triangle: as N_TRI */
				g->ent = (int)s->M->orig[nd->idx];
				g->tri = nd->idx;
			}
			return;
		}
		if (nd->kind == N_GROUP) {
			g->lbox = g->box;
			g->has_lbox = 1;
			g->box = px_aabb_transform(&g->lbox, s->to_f);
		}
		return;
	}
}

static double box_dist(const px_aabb *a, const px_aabb *b)
{
	double s = 0.0;
	int k;
	for (k = 0; k < 3; k++) {
		double g = fmax((&a->min.x)[k] - (&b->max.x)[k], (&b->min.x)[k] - (&a->max.x)[k]);
		if (g > 0.0)
			s += g * g;
	}
	return sqrt(s);
}

/* Lower bound on the distance of the surfaces the two nodes hold: their
 * boxes', then the hulls' by GJK. */
static double pair_lb(struct np_ctx *X, const struct np_geo *ga, const struct np_geo *gb)
{
	struct shp sa = {NULL, ga->p, ga->n}, sb = {X->B.m, NULL, 0};
	struct gjk_vert S[4];
	double d0 = box_dist(&ga->box, &gb->box), dist = 0.0, lower = 0.0;
	px_vec3 pa, pb, bc[8];
	int its = 0, ns = 0, g, k;

	if (ga->has_lbox && gb->n != -1) {
		/* also in A's frame, where A's box is tight (a sheet tilted in
		 * the working frame has a fat box there) */
		px_aabb bl = px_aabb_transform(&gb->box, X->f_to_a);
		d0 = fmax(d0, box_dist(&ga->lbox, &bl));
	}

	if (ga->n == 0 || d0 - X->slack >= X->best - X->eps)
		return d0 - X->slack;
	if (gb->n == 0) {
		/* a box: the hull of its corners */
		for (k = 0; k < 8; k++)
			bc[k] = px_v3((k & 1) ? gb->box.max.x : gb->box.min.x,
				      (k & 2) ? gb->box.max.y : gb->box.min.y,
				      (k & 4) ? gb->box.max.z : gb->box.min.z);
		sb.m = NULL;
		sb.v = bc;
		sb.nv = 8;
	} else if (gb->n > 0) {
		sb.m = NULL;
		sb.v = gb->p;
		sb.nv = gb->n;
	}
	g = px__gjk(&sa, &sb, &dist, &pa, &pb, &its, S, &ns, NULL, &lower);
	X->work += its;
	if (g <= 0)
		return fmax(d0, 0.0) - X->slack; /* hulls overlap (or no support) */
	return fmax(d0, lower) - X->slack;
}

static void take(struct np_ctx *X, double d, px_vec3 pa, px_vec3 pb, int ia, int ib)
{
	X->best = d;
	X->pa = pa;
	X->pb = pb;
	X->ia = ia;
	X->ib = ib;
}

/* Corner k of a sub-patch's geometry: its (s, t) in the piece (c[0] at
 * (s0, t0), c[1] (s0, t1), c[2] (s1, t0), c[3] (s1, t1)). */
static void corner_st(const struct np_geo *g, int k, double *s, double *t)
{
	*s = (k & 2) ? g->s1 : g->s0;
	*t = (k & 1) ? g->t1 : g->t0;
}

/* Upper bounds from real surface points: A's sub-patch corners against
 * a triangle, another sub-patch's corners, or the convex model. */
static int pair_ub(struct np_ctx *X, const struct np_geo *ga, const struct np_geo *gb)
{
	int k, l, rc;
	for (k = 0; k < ga->nc; k++) {
		px_vec3 c = ga->c[k], q;
		double d = INFINITY;
		int ib = gb->ent, lb = -1;
		if (gb->n == 3) {
			px_tri_closest(c, gb->p[0], gb->p[1], gb->p[2], &q, NULL, NULL, NULL, NULL);
			d = px_v3_dist(c, q);
		} else if (gb->n == -1) {
			struct px_model_result r;
			if ((rc = px_model_query(X->B.m, c, &r)) < 0)
				return rc;
			X->work++;
			if (r.is_signed && r.distance <= 0.0)
				X->overlap = 1;
			d = r.distance;
			q = r.point;
			ib = r.index;
		} else {
			for (l = 0; l < gb->nc; l++)
				if (px_v3_dist(c, gb->c[l]) < d) {
					d = px_v3_dist(c, gb->c[l]);
					q = gb->c[l];
					lb = l;
				}
		}
		if (!(d < X->best))
			continue;
		take(X, d, c, q, ga->ent, ib);
		X->at.piece = ga->piece;
		corner_st(ga, k, &X->at.s, &X->at.t);
		X->at.bkind = gb->n == 3 ? B_TRI : (gb->n == -1 ? B_CONVEX : B_PATCH);
		X->at.btri = gb->tri;
		X->at.bpiece = gb->piece;
		if (lb >= 0)
			corner_st(gb, lb, &X->at.u, &X->at.v);
	}
	return 0;
}

/* A piece's point and derivatives in its own square's coordinates, in
 * the working frame: d[0] the point, d[1..2] first, d[3..5] second
 * (ss, st, tt). */
static void piece_eval(const struct np_side *sd, int pid, double s, double t, px_vec3 d[6])
{
	const struct px_spiece *sp = &sd->dm->spc[sd->dm->pieces[pid].idx];
	double ku = sp->u1_ - sp->u0_, kv = sp->v1_ - sp->v0_;
	px_vec3 su, sv, suu, suv, svv, p = px_spiece_eval(sp, s, t, &su, &sv, &suu, &suv, &svv);
	d[0] = px_pose_transform_point(sd->to_f, p);
	d[1] = px_pose_transform_vector(sd->to_f, px_v3_scale(su, ku));
	d[2] = px_pose_transform_vector(sd->to_f, px_v3_scale(sv, kv));
	d[3] = px_pose_transform_vector(sd->to_f, px_v3_scale(suu, ku * ku));
	d[4] = px_pose_transform_vector(sd->to_f, px_v3_scale(suv, ku * kv));
	d[5] = px_pose_transform_vector(sd->to_f, px_v3_scale(svv, kv * kv));
}

static double clamp01(double x)
{
	return x < 0.0 ? 0.0 : (x > 1.0 ? 1.0 : x);
}

/* Solve the symmetric n x n system H x = -g (n <= 4) by Cholesky,
 * damping the diagonal until it is positive definite. Returns 0 when
 * even the damped matrix fails. */
static int solve_spd(int n, double H[4][4], const double *g, double *x)
{
	double L[4][4], tr = 0.0, lam = 0.0;
	int i, j, k, tries;
	for (i = 0; i < n; i++)
		tr += fabs(H[i][i]);
	for (tries = 0; tries < 4; tries++, lam = lam > 0.0 ? 10.0 * lam : 1e-6 * tr) {
		int ok = 1;
		for (i = 0; i < n && ok; i++)
			for (j = 0; j <= i && ok; j++) {
				double v = H[i][j] + (i == j ? lam : 0.0);
				for (k = 0; k < j; k++)
					v -= L[i][k] * L[j][k];
				if (i == j) {
					if (!(v > 0.0))
						ok = 0;
					else
						L[i][i] = sqrt(v);
				} else {
					L[i][j] = v / L[j][j];
				}
			}
		if (!ok)
			continue;
		for (i = 0; i < n; i++) {
			double v = -g[i];
			for (k = 0; k < i; k++)
				v -= L[i][k] * x[k];
			x[i] = v / L[i][i];
		}
		for (i = n - 1; i >= 0; i--) {
			double v = x[i];
			for (k = i + 1; k < n; k++)
				v -= L[k][i] * x[k];
			x[i] = v / L[i][i];
		}
		return 1;
	}
	return 0;
}

/* Record a polished pair when it is the best so far. */
static void take_at(struct np_ctx *X, px_vec3 pa, px_vec3 pb, int ib, const struct np_at *at)
{
	double d = px_v3_dist(pa, pb);
	if (!(d < X->best))
		return;
	take(X, d, pa, pb, X->A.dm->pieces[at->piece].ent, ib);
	X->at = *at;
}

/* Newton from the best pair's parameters, each iterate a real pair of
 * surface points (only improvements are kept): against a sub-patch on
 * the four parameters of both (the full Hessian of the squared
 * distance); against a triangle or a convex model, steps of A's point
 * problem towards the other's closest point, recomputed each time. */
static int polish(struct np_ctx *X)
{
	struct np_at at = X->at;
	int it, rc;

	if (X->polish_left <= 0 || at.piece < 0 || !(X->best < X->polished - X->eps))
		return 0;
	X->polish_left--;
	for (it = 0; it < NP_NEWTON; it++) {
		px_vec3 A[6], B[6], r, q;
		double H[4][4], g[4], dx[4];
		int n = 2, ib = X->ib;
		piece_eval(&X->A, at.piece, at.s, at.t, A);
		memset(B, 0, sizeof(B));
		if (at.bkind == B_PATCH) {
			piece_eval(&X->B, at.bpiece, at.u, at.v, B);
			q = B[0];
			ib = X->B.dm->pieces[at.bpiece].ent;
			n = 4;
		} else if (at.bkind == B_TRI) {
			struct mtri3 t = px__tri3_get(X->B.M, (size_t)at.btri);
			px_tri_closest(A[0], t.a, t.b, t.c, &q, NULL, NULL, NULL, NULL);
			ib = (int)X->B.M->orig[at.btri];
		} else {
			struct px_model_result mr;
			if ((rc = px_model_query(X->B.m, A[0], &mr)) < 0)
				return rc;
			if (mr.is_signed && mr.distance <= 0.0)
				X->overlap = 1;
			q = mr.point;
			ib = mr.index;
		}
		X->work++;
		take_at(X, A[0], q, ib, &at);
		r = px_v3_sub(A[0], q);
		g[0] = px_v3_dot(r, A[1]);
		g[1] = px_v3_dot(r, A[2]);
		g[2] = -px_v3_dot(r, B[1]);
		g[3] = -px_v3_dot(r, B[2]);
		H[0][0] = px_v3_dot(A[1], A[1]) + px_v3_dot(r, A[3]);
		H[1][0] = px_v3_dot(A[1], A[2]) + px_v3_dot(r, A[4]);
		H[1][1] = px_v3_dot(A[2], A[2]) + px_v3_dot(r, A[5]);
		H[2][0] = -px_v3_dot(A[1], B[1]);
		H[2][1] = -px_v3_dot(A[2], B[1]);
		H[3][0] = -px_v3_dot(A[1], B[2]);
		H[3][1] = -px_v3_dot(A[2], B[2]);
		H[2][2] = px_v3_dot(B[1], B[1]) - px_v3_dot(r, B[3]);
		H[3][2] = px_v3_dot(B[1], B[2]) - px_v3_dot(r, B[4]);
		H[3][3] = px_v3_dot(B[2], B[2]) - px_v3_dot(r, B[5]);
		if (!solve_spd(n, H, g, dx))
			break;
		{
			double step = 0.0, ns = clamp01(at.s + dx[0]), nt = clamp01(at.t + dx[1]);
			step = fabs(ns - at.s) + fabs(nt - at.t);
			at.s = ns;
			at.t = nt;
			if (n == 4) {
				double nu = clamp01(at.u + dx[2]), nv = clamp01(at.v + dx[3]);
				step += fabs(nu - at.u) + fabs(nv - at.v);
				at.u = nu;
				at.v = nv;
			}
			if (!(step > 1e-13))
				break;
		}
	}
	X->polished = X->best;
	return 0;
}

static int can_split(const struct np_node *n)
{
	return n->kind == N_GROUP || n->kind == N_BOX || n->kind == N_LEAF ||
	       (n->kind == N_PATCH && n->cnt < NP_MAX_LEVEL);
}

/* A group of patches pid[lo..hi) of side s, its box in the model's
 * frame (the pieces' boxes, which hold their nets). */
static struct np_node group_node(const struct np_side *s, int lo, int hi)
{
	struct np_node n;
	px_aabb b = px_aabb_empty();
	int k;
	memset(&n, 0, sizeof(n));
	n.kind = N_GROUP;
	n.idx = lo;
	n.cnt = hi;
	for (k = lo; k < hi; k++)
		b = px_aabb_union(&b, &s->dm->pieces[s->pid[k]].box);
	for (k = 0; k < 3; k++) {
		n.lo[k] = px__f_down((&b.min.x)[k]);
		n.hi[k] = px__f_up((&b.max.x)[k]);
	}
	return n;
}

/* The children of node n of side s, at most cap (0 when it has none). */
static int children(const struct np_side *s, const struct np_node *n, struct np_node *out,
		    int cap)
{
	int k, c, m = 0;
	if (n->kind == N_PATCH) {
		for (k = 0; k < 4; k++) {
			out[k] = *n;
			out[k].cnt = n->cnt + 1;
			out[k].i = 2 * n->i + (uint32_t)((k >> 1) & 1);
			out[k].j = 2 * n->j + (uint32_t)(k & 1);
		}
		return 4;
	}
	if (n->kind == N_GROUP) {
		if (n->cnt - n->idx > NP_GROUP_LEAF) {
			int mid = (n->idx + n->cnt) / 2;
			out[0] = group_node(s, n->idx, mid);
			out[1] = group_node(s, mid, n->cnt);
			return 2;
		}
		for (k = n->idx; k < n->cnt && m < cap; k++) {
			memset(&out[m], 0, sizeof(out[m]));
			out[m].kind = N_PATCH;
			out[m++].idx = s->pid[k];
		}
		return m;
	}
	if (n->kind == N_LEAF) {
		for (k = 0; k < n->cnt && m < cap; k++) {
			memset(&out[m], 0, sizeof(out[m]));
			out[m].kind = N_TRI;
			out[m++].idx = n->idx + k;
		}
		return m;
	}
	if (n->kind == N_BOX) {
		const struct node4 *nd = &s->M->n4[n->idx];
		for (k = 0; k < 4; k++) {
			if (nd->idx[k] == EMPTY)
				continue;
			memset(&out[m], 0, sizeof(out[m]));
			out[m].kind = nd->cnt[k] > 0 ? N_LEAF : N_BOX;
			out[m].idx = (int)nd->idx[k];
			out[m].cnt = (int)nd->cnt[k];
			for (c = 0; c < 3; c++) {
				out[m].lo[c] = nd->lo[c][k];
				out[m].hi[c] = nd->hi[c][k];
			}
			m++;
		}
		return m;
	}
	return 0;
}

/* The node pair e: split one side (the larger, or the one that can),
 * bound each child pair, push the survivors nearest on top. */
static int expand(struct np_ctx *X, const struct np_ent *e, struct np_ent *stk, int *sp)
{
	struct np_node kid[NP_MAX_PATCHES];
	struct np_ent ce[NP_MAX_PATCHES];
	struct np_geo gs, gk;
	double pnet[NP_MAX_CP][4], cnet[NP_MAX_CP][4];
	const struct np_side *sd;
	const struct np_node *par;
	int split_b, nk, k, m = 0, rc;

	if (!can_split(&e->a) && !can_split(&e->b)) {
		X->certified = 0; /* smallest nodes, bounds still apart */
		return 0;
	}
	split_b = can_split(&e->b) && (!can_split(&e->a) || e->sb > e->sa);
	/* gs: the side kept whole; the other's children from its net */
	node_geo(split_b ? &X->A : &X->B, split_b ? &e->a : &e->b, &gs);
	sd = split_b ? &X->B : &X->A;
	par = split_b ? &e->b : &e->a;
	nk = children(sd, par, kid, NP_MAX_PATCHES);
	if (par->kind == N_PATCH)
		patch_net(sd, par, pnet);
	for (k = 0; k < nk; k++) {
		struct np_ent c;
		if (par->kind == N_PATCH) {
			child_net(sd, par, pnet, k, cnet);
			net_geo(sd, &kid[k], cnet, &gk);
		} else {
			node_geo(sd, &kid[k], &gk);
		}
		c.a = split_b ? e->a : kid[k];
		c.b = split_b ? kid[k] : e->b;
		c.sa = split_b ? e->sa : (float)px_aabb_diagonal(&gk.box);
		c.sb = split_b ? (float)px_aabb_diagonal(&gk.box) : e->sb;
		c.lb = split_b ? pair_lb(X, &gs, &gk) : pair_lb(X, &gk, &gs);
		if (!(c.lb < X->best - X->eps))
			continue; /* pruned: its corners cannot beat the best */
		if (split_b ? gk.n > 0 : gs.n != 0) {
			rc = split_b ? pair_ub(X, &gs, &gk) : pair_ub(X, &gk, &gs);
			if (rc < 0)
				return rc;
		}
		if (c.lb < X->best - X->eps)
			ce[m++] = c;
	}
	if ((rc = polish(X)) < 0)
		return rc;
	/* insertion sort, largest first: the nearest is pushed last */
	for (k = 1; k < m; k++) {
		struct np_ent t = ce[k];
		int l = k;
		for (; l > 0 && ce[l - 1].lb < t.lb; l--)
			ce[l] = ce[l - 1];
		ce[l] = t;
	}
	for (k = 0; k < m; k++) {
		if (ce[k].lb >= X->best - X->eps)
			continue;
		if (*sp >= NP_STACK) {
			X->certified = 0;
			continue;
		}
		stk[(*sp)++] = ce[k];
	}
	return 0;
}

/* A side of the pair, or -1 when the model is not one this path takes. */
static int side_kind(const struct px_model *m)
{
	const struct px_dist_model *dm = px__nurbs_model_dist(m);
	if (dm) {
		int k, np = 0;
		if (dm->trim)
			return -1;
		for (k = 0; k < dm->n_ent; k++)
			if (dm->ent[k].kind != PX_DIST_SURFACE)
				return -1;
		for (k = 0; k < dm->n_sp; k++)
			if (dm->spc[k].p_ > NP_MAX_DEG || dm->spc[k].q_ > NP_MAX_DEG)
				return -1;
		for (k = 0; k < dm->n_pieces; k++)
			np += dm->pieces[k].kind == PK_PATCH;
		return np > 0 && np <= NP_MAX_PATCHES ? S_NURBS : -1;
	}
	if (px_mesh_triangle_count(m) > 0)
		return S_MESH;
	if ((px_model_caps(m) & PX_MODEL_CAP_CONVEX) && px_model_get_ops(m)->support &&
	    px_model_kind(m) == PX_MODEL_PRIMITIVE)
		return S_CONVEX;
	return -1;
}

static void side_init(struct np_side *s, const struct px_model *m, int kind)
{
	memset(s, 0, sizeof(*s));
	s->kind = kind;
	s->m = m;
	s->dm = px__nurbs_model_dist(m);
	s->M = kind == S_MESH ? px_model_impl(m) : NULL;
	if (s->dm) {
		int k;
		for (k = 0; k < s->dm->n_pieces && s->np < NP_MAX_PATCHES; k++)
			if (s->dm->pieces[k].kind == PK_PATCH)
				s->pid[s->np++] = k;
	}
}

static struct np_node root_node(const struct np_side *s)
{
	struct np_node n;
	int k;
	if (s->kind == S_NURBS)
		return group_node(s, 0, s->np);
	memset(&n, 0, sizeof(n));
	n.kind = s->kind == S_MESH ? N_BOX : N_CONVEX;
	if (s->kind == S_MESH)
		for (k = 0; k < 3; k++) {
			n.lo[k] = px__f_down((&s->M->box.min.x)[k]);
			n.hi[k] = px__f_up((&s->M->box.max.x)[k]);
		}
	return n;
}

static float node_size(const struct np_node *n)
{
	px_vec3 d = px_v3(n->hi[0] - n->lo[0], n->hi[1] - n->lo[1], n->hi[2] - n->lo[2]);
	return n->kind == N_CONVEX ? 0.0f : (float)px_v3_norm(d);
}

/* The descent proper: fills X, returns 0 or an error. */
static int descend(struct np_ctx *X)
{
	struct np_ent stk[NP_STACK];
	int sp = 0, rc, pairs = 0;

	memset(&stk[0], 0, sizeof(stk[0]));
	stk[0].a = root_node(&X->A);
	stk[0].b = root_node(&X->B);
	stk[0].sa = node_size(&stk[0].a);
	stk[0].sb = node_size(&stk[0].b);
	stk[0].lb = 0.0;
	sp = 1;
	while (sp > 0) {
		struct np_ent e = stk[--sp];
		if (e.lb >= X->best - X->eps)
			continue;
		if (++pairs > NP_BUDGET) {
			X->certified = 0;
			break;
		}
		if ((rc = expand(X, &e, stk, &sp)) < 0)
			return rc;
		if (X->overlap)
			break;
	}
	X->work += pairs;
	return 0;
}

int px__pair_nurbs(const struct px_model *a, const struct px_model *b, int coherent,
		   struct px_pair_result *res)
{
	struct np_ctx X;
	int ka = side_kind(a), kb = side_kind(b), swap, rc;
	const struct px_model *ma, *mb;
	px_aabb box;
	px_pose w_to_f;

	if (px__pair_nurbs_off || ka < 0 || kb < 0 || (ka != S_NURBS && kb != S_NURBS))
		return 0;
	swap = ka != S_NURBS;
	ma = swap ? b : a;
	mb = swap ? a : b;
	memset(&X, 0, sizeof(X));
	side_init(&X.A, ma, S_NURBS);
	side_init(&X.B, mb, swap ? ka : kb);
	/* the working frame: B's own (its hierarchy's), the world for a
	 * convex model (its support function's) */
	X.f_to_w = X.B.kind == S_CONVEX ? px_pose_identity() : px_model_pose(mb);
	w_to_f = px_pose_inverse(X.f_to_w);
	X.A.to_f = px_pose_compose(w_to_f, px_model_pose(ma));
	X.f_to_a = px_pose_inverse(X.A.to_f);
	X.B.to_f = px_pose_identity();
	box = X.A.dm->bounds;
	X.eps = NP_REL * px_aabb_diagonal(&box);
	if (X.B.kind == S_NURBS)
		X.eps = fmin(X.eps, NP_REL * px_aabb_diagonal(&X.B.dm->bounds));
	X.slack = 1e-12 * px_aabb_diagonal(&box);
	X.best = INFINITY;
	X.polished = INFINITY;
	X.polish_left = NP_POLISH;
	X.certified = 1;
	X.ia = X.ib = -1;
	X.at.piece = -1;
	if (coherent && res->valid && !res->intersecting) {
		/* last cycle's pair, moved with the models: real surface
		 * points, so their distance bounds this cycle's */
		px_vec3 pa = px_pose_transform_point(px_model_pose(ma), swap ? res->local_b : res->local_a);
		px_vec3 pb = px_pose_transform_point(px_model_pose(mb), swap ? res->local_a : res->local_b);
		take(&X, px_v3_dist(pa, pb), px_pose_transform_point(w_to_f, pa),
		     px_pose_transform_point(w_to_f, pb), swap ? res->index_b : res->index_a,
		     swap ? res->index_a : res->index_b);
	}
	if ((rc = descend(&X)) < 0)
		return rc;
	if (X.overlap || !(X.best > X.eps) || !(X.best < INFINITY))
		return 0;
	{
		struct pair_run run;
		memset(&run, 0, sizeof(run));
		run.d = X.best;
		run.pa = px_pose_transform_point(X.f_to_w, swap ? X.pb : X.pa);
		run.pb = px_pose_transform_point(X.f_to_w, swap ? X.pa : X.pb);
		if ((rc = px__pair_contained(a, b, &run, &X.work)) < 0)
			return rc;
		if (rc > 0)
			return 0;
		res->distance = X.best;
		res->point_a = run.pa;
		res->point_b = run.pb;
	}
	res->index_a = swap ? X.ib : X.ia;
	res->index_b = swap ? X.ia : X.ib;
	res->iterations = X.work;
	res->starts = 0;
	res->converged = 1;
	res->intersecting = 0;
	res->local_only = !X.certified;
	return 1;
}
