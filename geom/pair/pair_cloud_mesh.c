/*
 * pair_cloud_mesh.c - a small mesh (a robot link) against a large point
 * cloud: the least (signed, for a closed mesh) distance of the mesh over
 * the cloud's points, by the cloud's hierarchy alone, and the coherent
 * cut that lets the next cycles skip most of it (pair_internal.h).
 *
 * The walk is in the mesh's frame. A cloud box is bounded below by the
 * largest of: the gaps along the mesh box's axes (the cloud box rotated
 * in and enclosed), the gaps along the cloud's axes (the mesh box
 * rotated out and enclosed) - each a sum of squares over orthogonal
 * axes, a lower bound of the box distance - and the gap along the line
 * of centres. A point is bounded by its distance to the mesh's box (or,
 * inside the box, by minus its depth in the box: a point inside the mesh
 * is no deeper than that). Both are then raised by the mesh's bounding
 * planes (px_pair.h: face normals at the mesh's support along them, so
 * the mesh lies in each half-space and n . p - offset bounds the signed
 * distance from below, inside too; the plane facing the box or point is
 * found through a cube map of directions from the mesh's core) and by
 * the distance to the core less the mesh's radius about it: on a link,
 * bounds within a fraction of a millimetre where the box's were off by
 * centimetres. A point whose bound can still win is measured by the
 * mesh's exact (signed) point query. Nodes and points go nearest bound
 * first, pruned against the best found, so the answer is the exact
 * minimum over all points (up to a slack of 1e-12 of the coordinate
 * scale in the bounds, which only costs work).
 *
 * The cut: every subtree the walk pruned and every leaf it measured,
 * with its lower bound, cover the cloud. Later the mesh has moved
 * relative to the cloud by a rigid motion: its box centre c by |dc| and
 * its rotation by R' - R with spectral norm at most e (bounded by the
 * Frobenius norm). A point p at r = |p - c'| from the new centre has
 * moved in the mesh's frame by at most |dc| + e r, and lies at least r -
 * rad from a mesh inside the ball of radius rad about c'; the least over
 * r of the larger of the two bounds is (lb - |dc| - e rad) / (1 + e). So
 * an entry whose old bound lb is at least best (1 + e) + |dc| + e rad
 * cannot hold a point below best: only the few entries under that
 * threshold are walked again, and the answer stays exact.
 */
#include <math.h>
#include <string.h>

#include "mesh_internal.h"
#include "model_internal.h"
#include "pair_internal.h"
#include "px_cloud.h"
#include "px_mesh.h"

#define CL_STACK (3 * PX_CLOUD_MAX_DEPTH + 4)
#define LEAF_PTS 16 /* a cloud leaf holds at most 8 points (px_cloud.c) */

struct cl_ent {
	uint32_t idx, cnt;
	double lb;
};

/* The walk's context: the cloud (frame Pc), the mesh o, cloud frame ->
 * mesh frame (l = R p + t, t taken about the mesh box's centre), the
 * mesh box's half extents lh and, in the cloud frame, its centre cl
 * and enclosing half extents lhc; the best so far; the cut being
 * recorded (NULL: none). */
struct cl_ctx {
	const struct px_model *o;
	struct px__cloud_view V;
	px_pose Pc;
	double R[3][3], Ra[3][3];
	px_vec3 t, lh, cl, lhc;
	double inner;  /* the mesh box's least half extent */
	double slack;
	int signed_o, hint;
	/* bounding planes of o (mesh frame about its box centre: n . l <=
	 * off for all of o), the best per direction cell, and their
	 * normals in the cloud frame; np = 0: none */
	int np;
	double rho; /* o lies within rho of its core (dir_cell) */
	const double (*pl)[4];
	const uint8_t *cell;
	double nc[PX_PAIR_CACHE_PLANES][3];
	struct px__cloud_min *out;
	struct px_pair_cache *rec;
};

/* The pose of o in c's frame, as rotation and translation. */
static void rel_pose(const struct px_model *c, const struct px_model *o, px_mat3 *R, px_vec3 *t)
{
	px_pose Pc = px_model_pose(c), Po = px_model_pose(o);
	px_mat3 rc = px_quat_to_mat3(Pc.q), ro = px_quat_to_mat3(Po.q);
	px_mat3 rct = px_mat3_transpose(&rc);
	*R = px_mat3_mul(&rct, &ro);
	*t = px_pose_inverse_transform_vector(Pc, px_v3_sub(Po.t, Pc.t));
}

/* The direction cell of u (a cube map of 6 faces of 8 x 8). */
static int dir_cell0(double ux, double uy, double uz)
{
	double ax = fabs(ux), ay = fabs(uy), az = fabs(uz), m, a, b;
	int f, i, j;
	if (ax >= ay && ax >= az) {
		f = ux < 0.0;
		m = ax, a = uy, b = uz;
	} else if (ay >= az) {
		f = 2 + (uy < 0.0);
		m = ay, a = ux, b = uz;
	} else {
		f = 4 + (uz < 0.0);
		m = az, a = ux, b = uy;
	}
	if (!(m > 0.0))
		return 0;
	i = (int)((a / m + 1.0) * 4.0);
	j = (int)((b / m + 1.0) * 4.0);
	i = i < 0 ? 0 : (i > 7 ? 7 : i);
	j = j < 0 ? 0 : (j > 7 ? 7 : j);
	return (f * 8 + i) * 8 + j;
}

/* The direction cell of mesh-frame point l (about o's box centre)
 * seen from o's core: the box shrunk by its least half extent on every
 * side (a segment for a long link), so that beside a long mesh the
 * plane facing the point is chosen, not one at its end. */
static int dir_cell(const struct cl_ctx *X, const double l[3], double *dist)
{
	double u[3], lh[3] = {X->lh.x, X->lh.y, X->lh.z};
	int k;
	for (k = 0; k < 3; k++) {
		double c = lh[k] - X->inner;
		u[k] = l[k] > c ? l[k] - c : (l[k] < -c ? l[k] + c : 0.0);
	}
	*dist = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
	return dir_cell0(u[0], u[1], u[2]);
}

/* C's bounding planes of mesh o, made when they are another model's:
 * the unit normals of up to PX_PAIR_CACHE_PLANES triangles (spread over
 * the mesh), each at o's support along it (the largest n . v over every
 * vertex), so o lies in every half-space n . l <= off whatever its
 * shape; the radius of o about its core (dir_cell); and per direction
 * cell the plane best aligned with the cell's centre. Done once per
 * model, at its first call: 64 planes against the vertices of at most
 * PX_PAIR_PLANES_MAX_TRIS triangles (a millisecond at most). */
static void planes_make(struct px_pair_planes *C, const struct px_model *o)
{
	px_aabb ob = px_model_local_aabb(o);
	px_vec3 lc = px_aabb_center(&ob);
	size_t nt = px_mesh_triangle_count(o), t, step, k;
	int np = 0, c;
	if (C->model_ == o && C->serial_ == px__model_serial(o))
		return;
	C->model_ = o;
	C->serial_ = px__model_serial(o);
	C->n_ = 0;
	if (nt == 0 || nt > PX_PAIR_PLANES_MAX_TRIS)
		return;
	{
		/* the radius about the core (dir_cell), over every vertex,
		 * rounded up */
		px_vec3 lh = px_v3_scale(px_v3_sub(ob.max, ob.min), 0.5);
		double in = fmin(lh.x, fmin(lh.y, lh.z)), rho = 0.0;
		for (t = 0; t < nt; t++) {
			px_vec3 v[3];
			int j, q;
			if (px_mesh_triangle(o, t, v) != PX_OK)
				continue;
			for (j = 0; j < 3; j++) {
				double l[3] = {v[j].x - lc.x, v[j].y - lc.y, v[j].z - lc.z},
				       h[3] = {lh.x, lh.y, lh.z}, u2 = 0.0;
				for (q = 0; q < 3; q++) {
					double cq = h[q] - in,
					       u = l[q] > cq ? l[q] - cq : (l[q] < -cq ? l[q] + cq : 0.0);
					u2 += u * u;
				}
				rho = u2 > rho ? u2 : rho;
			}
		}
		C->rho_ = sqrt(rho) * (1.0 + 1e-12);
	}
	step = (nt + PX_PAIR_CACHE_PLANES - 1) / PX_PAIR_CACHE_PLANES;
	for (t = 0; t < nt && np < PX_PAIR_CACHE_PLANES; t += step) {
		px_vec3 v[3], n;
		double off = -INFINITY;
		if (px_mesh_triangle(o, t, v) != PX_OK ||
		    px_v3_normalize(px_v3_cross(px_v3_sub(v[1], v[0]), px_v3_sub(v[2], v[0])),
				    px_v3(0, 0, 0), &n) != PX_OK)
			continue;
		for (k = 0; k < nt; k++) {
			px_vec3 w[3];
			int j;
			if (px_mesh_triangle(o, k, w) != PX_OK)
				continue;
			for (j = 0; j < 3; j++) {
				double h = px_v3_dot(n, px_v3_sub(w[j], lc));
				off = h > off ? h : off;
			}
		}
		C->plane_[np][0] = n.x;
		C->plane_[np][1] = n.y;
		C->plane_[np][2] = n.z;
		C->plane_[np][3] = off;
		np++;
	}
	for (c = 0; c < PX_PAIR_CACHE_CELLS; c++) {
		int f = c / 64, i = (c / 8) % 8, j = c % 8, best = 0, q;
		double a = (i + 0.5) / 4.0 - 1.0, b = (j + 0.5) / 4.0 - 1.0, s = f % 2 ? -1.0 : 1.0;
		double u[3], bv = -INFINITY;
		u[f / 2] = s;
		u[f / 2 == 0 ? 1 : 0] = a;
		u[f / 2 == 2 ? 1 : 2] = b;
		for (q = 0; q < np; q++) {
			double v = C->plane_[q][0] * u[0] + C->plane_[q][1] * u[1] +
				   C->plane_[q][2] * u[2];
			if (v > bv) {
				bv = v;
				best = q;
			}
		}
		C->cell_[c] = (uint8_t)best;
	}
	C->n_ = np;
}

static void cl_setup(struct cl_ctx *X, const struct px_model *c, const struct px_model *o,
		     const struct px_pair_planes *C, struct px__cloud_min *out)
{
	px_aabb ob = px_model_local_aabb(o);
	px_vec3 lc = px_aabb_center(&ob), to;
	px_mat3 Ro;
	double sc;
	int i, k;

	memset(X, 0, sizeof(*X));
	px__cloud_view(c, &X->V);
	X->o = o;
	X->out = out;
	X->hint = -1;
	X->signed_o = (px_model_caps(o) & PX_MODEL_CAP_SIGNED) != 0;
	X->Pc = px_model_pose(c);
	/* o in c's frame is (Ro, to): mesh coordinates l = Ro^T (p - to) */
	rel_pose(c, o, &Ro, &to);
	X->lh = px_v3_scale(px_v3_sub(ob.max, ob.min), 0.5);
	for (i = 0; i < 3; i++)
		for (k = 0; k < 3; k++) {
			X->R[i][k] = Ro.m[k][i];
			X->Ra[i][k] = fabs(Ro.m[k][i]);
		}
	/* l - lc = R p + t: t = -R to - lc */
	{
		px_mat3 Rt = px_mat3_transpose(&Ro);
		X->t = px_v3_sub(px_v3_neg(px_mat3_mul_v3(&Rt, to)), lc);
	}
	X->cl = px_v3_add(px_mat3_mul_v3(&Ro, lc), to);
	X->lhc = px_v3(X->Ra[0][0] * X->lh.x + X->Ra[1][0] * X->lh.y + X->Ra[2][0] * X->lh.z,
		       X->Ra[0][1] * X->lh.x + X->Ra[1][1] * X->lh.y + X->Ra[2][1] * X->lh.z,
		       X->Ra[0][2] * X->lh.x + X->Ra[1][2] * X->lh.y + X->Ra[2][2] * X->lh.z);
	X->inner = fmin(X->lh.x, fmin(X->lh.y, X->lh.z));
	if (C && C->n_ > 0) {
		/* the normals in the cloud frame: n_c = R^T n */
		X->np = C->n_;
		X->rho = C->rho_;
		X->pl = C->plane_;
		X->cell = C->cell_;
		for (i = 0; i < X->np; i++)
			for (k = 0; k < 3; k++)
				X->nc[i][k] = X->R[0][k] * X->pl[i][0] + X->R[1][k] * X->pl[i][1] +
					      X->R[2][k] * X->pl[i][2];
	}
	sc = X->V.absmax + px__amax3(X->cl) + px__amax3(lc) + px__amax3(X->lh);
	X->slack = 1e-12 * sc;
}

static inline double pos(double x)
{
	return x > 0.0 ? x : 0.0;
}

/* Lower bound of the signed distance of o over the cloud box (centre
 * cb, half extents h, cloud frame): see the top of the file. */
static double box_lb(const struct cl_ctx *X, px_vec3 cb, px_vec3 h)
{
	double w[3] = {cb.x - X->cl.x, cb.y - X->cl.y, cb.z - X->cl.z}, wl[3];
	double hh[3] = {h.x, h.y, h.z}, lh[3] = {X->lh.x, X->lh.y, X->lh.z};
	double lhc[3] = {X->lhc.x, X->lhc.y, X->lhc.z};
	double s1 = 0.0, s2 = 0.0, ww = 0.0, ext = 0.0, w1 = 0.0;
	int k;
	for (k = 0; k < 3; k++) {
		double hl = X->Ra[k][0] * hh[0] + X->Ra[k][1] * hh[1] + X->Ra[k][2] * hh[2];
		double g1, g2;
		wl[k] = X->R[k][0] * w[0] + X->R[k][1] * w[1] + X->R[k][2] * w[2];
		g1 = pos(fabs(wl[k]) - hl - lh[k] - X->slack);
		g2 = pos(fabs(w[k]) - hh[k] - lhc[k] - X->slack);
		s1 += g1 * g1;
		s2 += g2 * g2;
		ww += w[k] * w[k];
		w1 += fabs(w[k]);
		ext += fabs(w[k]) * hh[k] + fabs(wl[k]) * lh[k];
	}
	s1 = s1 > s2 ? s1 : s2;
	/* the line of centres: (|w|^2 - ext) / |w|, the slack scaled by
	 * |w|_1 >= |w| */
	ext += 2.0 * X->slack * w1;
	if (ww > ext) {
		double g = (ww - ext) * (ww - ext) / ww;
		s1 = g > s1 ? g : s1;
	}
	if (X->np) {
		/* the plane facing the box: its gap over the box's extent
		 * along the normal (in the cloud frame, exactly) */
		double cd, s3 = 0.0;
		int f = X->cell[dir_cell(X, wl, &cd)];
		const double *n = X->pl[f], *m = X->nc[f];
		double g = n[0] * wl[0] + n[1] * wl[1] + n[2] * wl[2] -
			   (fabs(m[0]) * hh[0] + fabs(m[1]) * hh[1] + fabs(m[2]) * hh[2]) - n[3] -
			   2.0 * X->slack;
		/* the box (enclosed in the mesh frame) against the core,
		 * less the radius about it */
		for (k = 0; k < 3; k++) {
			double hl = X->Ra[k][0] * hh[0] + X->Ra[k][1] * hh[1] + X->Ra[k][2] * hh[2];
			double gc = pos(fabs(wl[k]) - hl - (lh[k] - X->inner) - X->slack);
			s3 += gc * gc;
		}
		s3 = sqrt(s3) - X->rho - 2.0 * X->slack;
		g = s3 > g ? s3 : g;
		if (g > 0.0 && g * g > s1)
			return g * (1.0 - 1e-15);
		if (s1 <= 0.0 && X->signed_o)
			return g > -X->inner ? g : -X->inner - X->slack;
	}
	if (s1 > 0.0)
		return sqrt(s1) * (1.0 - 1e-15);
	/* the boxes meet: a point of the box may be inside o, no deeper
	 * than o's box is thick */
	return X->signed_o ? -X->inner - X->slack : 0.0;
}

/* Does a value v beat the best? Before anything is found the limit
 * itself counts. */
static int beats(const struct px__cloud_min *m, double v)
{
	return m->found ? v < m->s : v <= m->s;
}


/* Lower bound of the signed distance of o at cloud point p (cloud
 * frame): its distance to o's box, or minus its depth in the box. */
static double point_lb(const struct cl_ctx *X, px_vec3 p)
{
	double g2 = 0.0, gin = -INFINITY, l[3];
	double lh[3] = {X->lh.x, X->lh.y, X->lh.z}, tt[3] = {X->t.x, X->t.y, X->t.z};
	int k;
	for (k = 0; k < 3; k++) {
		double a;
		l[k] = X->R[k][0] * p.x + X->R[k][1] * p.y + X->R[k][2] * p.z + tt[k];
		a = fabs(l[k]) - lh[k];
		g2 += a > 0.0 ? a * a : 0.0;
		gin = a > gin ? a : gin;
	}
	if (X->np) {
		/* the plane facing the point */
		double cd;
		const double *n = X->pl[X->cell[dir_cell(X, l, &cd)]];
		double g = n[0] * l[0] + n[1] * l[1] + n[2] * l[2] - n[3] - 2.0 * X->slack;
		/* and the core's: o is within rho of it */
		cd -= X->rho + 2.0 * X->slack;
		g = cd > g ? cd : g;
		if (g > 0.0 ? g * g > g2 : (g2 <= 0.0 && g > gin))
			return g * (1.0 - 1e-15);
	}
	if (g2 > 0.0)
		return sqrt(g2) * (1.0 - 1e-15) - X->slack;
	return X->signed_o ? gin - X->slack : 0.0;
}

/* The points of leaf range [i0, i0 + n): each one whose bound can win
 * measured exactly. Returns the least bound or value over the leaf (for
 * the cut), or an error as a NaN-free negative code through *rc. */
static double cl_leaf(struct cl_ctx *X, uint32_t i0, uint32_t n, int *rc)
{
	double least = INFINITY, lbs[LEAF_PTS];
	uint32_t ord[LEAF_PTS], m = 0, i, j;
	/* the points' bounds first, then the points by bound: the nearest
	 * measured first lowers the best for the rest */
	for (i = 0; i < n && i < LEAF_PTS; i++) {
		double lb = point_lb(X, X->V.pt[i0 + i]);
		if (!beats(X->out, lb)) {
			least = lb < least ? lb : least;
			continue;
		}
		for (j = m; j > 0 && lbs[j - 1] > lb; j--) {
			lbs[j] = lbs[j - 1];
			ord[j] = ord[j - 1];
		}
		lbs[j] = lb;
		ord[j] = i0 + i;
		m++;
	}
	for (j = 0; j < m; j++) {
		px_vec3 p = X->V.pt[ord[j]];
		double lb = lbs[j], reach;
		struct px_model_result q;
		int r;
		if (!beats(X->out, lb)) {
			least = lb < least ? lb : least;
			continue;
		}
		/* a point with a positive bound is not inside o: a query
		 * bounded by the best may stop early */
		reach = lb > 0.0 && X->out->found ? X->out->s : INFINITY;
		r = px_model_query_ex(X->o, px_pose_transform_point(X->Pc, p), reach, X->hint, 0, &q);
		X->out->queries++;
		if (r < 0) {
			*rc = r;
			return least;
		}
		if (r == 0) {
			/* nothing of o within reach: reach bounds it */
			least = reach < least ? reach : least;
			continue;
		}
		X->hint = q.index;
		if (!q.certified)
			X->out->certified = 0;
		least = q.distance < least ? q.distance : least;
		if (!beats(X->out, q.distance))
			continue;
		X->out->s = q.distance;
		X->out->p = px_pose_transform_point(X->Pc, p);
		X->out->q = q.point;
		X->out->pi = (int)X->V.orig[ord[j]];
		X->out->oi = q.index;
		X->out->found = 1;
	}
	return least;
}

/* Note an entry of the cut being recorded. */
static void cut_add(struct cl_ctx *X, uint32_t idx, uint32_t cnt, double lb)
{
	struct px_pair_cache *C = X->rec;
	if (!C)
		return;
	if (C->n_ < PX_PAIR_CACHE_CAP) {
		C->ent_[C->n_].idx = idx;
		C->ent_[C->n_].cnt = cnt;
		C->ent_[C->n_].lb = (float)lb;
		/* float rounded down: still a lower bound */
		if ((double)C->ent_[C->n_].lb > lb)
			C->ent_[C->n_].lb = nextafterf(C->ent_[C->n_].lb, -INFINITY);
		C->n_++;
	} else if (lb < C->far_) {
		C->far_ = lb;
	}
}

/* The walk from the entries st[0..sp), nearest bound first. */
static int cl_walk(struct cl_ctx *X, struct cl_ent *st, int sp)
{
	int j, k, rc = 0;
	while (sp > 0) {
		struct cl_ent e = st[--sp], kid[4];
		const struct node4 *nd;
		int nk = 0;
		if (!beats(X->out, e.lb)) {
			cut_add(X, e.idx, e.cnt, e.lb);
			continue;
		}
		if (e.cnt > 0) {
			double least = cl_leaf(X, e.idx, e.cnt, &rc);
			if (rc < 0)
				return rc;
			cut_add(X, e.idx, e.cnt, least);
			continue;
		}
		X->out->nodes++;
		nd = &X->V.n4[e.idx];
		for (j = 0; j < 4; j++) {
			px_vec3 lo, hi;
			struct cl_ent ch;
			if (nd->idx[j] == EMPTY)
				continue;
			lo = px_v3(nd->lo[0][j], nd->lo[1][j], nd->lo[2][j]);
			hi = px_v3(nd->hi[0][j], nd->hi[1][j], nd->hi[2][j]);
			ch.lb = box_lb(X, px_v3_scale(px_v3_add(lo, hi), 0.5),
				       px_v3_scale(px_v3_sub(hi, lo), 0.5));
			ch.idx = nd->idx[j];
			ch.cnt = nd->cnt[j];
			if (!beats(X->out, ch.lb)) {
				cut_add(X, ch.idx, ch.cnt, ch.lb);
				continue;
			}
			/* insertion by bound, farthest first: the nearest is
			 * popped next */
			for (k = nk; k > 0 && kid[k - 1].lb < ch.lb; k--)
				kid[k] = kid[k - 1];
			kid[k] = ch;
			nk++;
		}
		for (k = 0; k < nk; k++) {
			if (sp >= CL_STACK) {
				X->out->certified = 0;
				continue;
			}
			st[sp++] = kid[k];
		}
	}
	return 0;
}

/* The pose a cut is made at: o's rotation and box centre in c's frame,
 * and the radius of o's box about that centre. */
static void cut_pose(const struct px_model *c, const struct px_model *o, px_mat3 *R,
		     px_vec3 *centre, double *rad)
{
	px_aabb ob = px_model_local_aabb(o);
	px_vec3 t;
	rel_pose(c, o, R, &t);
	*centre = px_v3_add(px_mat3_mul_v3(R, px_aabb_center(&ob)), t);
	*rad = 0.5 * px_v3_norm(px_v3_sub(ob.max, ob.min));
}

/* The walk from the root, recording the cut into C (may be NULL). */
static int full_walk(struct cl_ctx *X, struct px_pair_cache *C)
{
	struct cl_ent st[CL_STACK];
	int rc;
	st[0].idx = 0;
	st[0].cnt = 0;
	st[0].lb = -INFINITY;
	X->rec = C;
	if (C) {
		C->n_ = 0;
		C->far_ = INFINITY;
	}
	rc = cl_walk(X, st, 1);
	X->rec = NULL;
	return rc;
}

void px_pair_cache_prepare(struct px_pair_cache *c, const struct px_model *mesh)
{
	if (c && mesh && px_model_kind(mesh) == PX_MODEL_MESH)
		planes_make(&c->planes_, mesh);
}

int px__cloud_mesh_min(const struct px_model *c, const struct px_model *o, struct px_pair_cache *C,
		       int coherent, int hint, struct px__cloud_min *out)
{
	struct cl_ctx X;
	const struct px_pair_planes *pl = NULL;
	int rc = 0;
	memset(out, 0, sizeof(*out));
	out->s = INFINITY;
	out->certified = 1;
	if (!px__cloud_view(c, &X.V))
		return PX_E_INVAL;
	/* the mesh's bounding planes, made at its first call */
	if (C) {
		planes_make(&C->planes_, o);
		pl = &C->planes_;
	}
	cl_setup(&X, c, o, pl, out);
	if (!coherent)
		C = NULL;
	if (C && C->valid_ && C->cloud_ == c && C->model_ == o && C->serial_ == px__model_serial(c)) {
		struct cl_ent st[CL_STACK];
		px_mat3 R, R0 = C->rot_;
		px_vec3 cen;
		double rad, e = 0.0, dc, thr, lb;
		uint32_t w = C->witness_;
		int i, k, m, reopened = 0;
		cut_pose(c, o, &R, &cen, &rad);
		for (i = 0; i < 3; i++)
			for (k = 0; k < 3; k++)
				e += (R.m[i][k] - R0.m[i][k]) * (R.m[i][k] - R0.m[i][k]);
		e = sqrt(e) * (1.0 + 1e-12) + 1e-15;
		dc = px_v3_dist(cen, C->centre_) * (1.0 + 1e-12) + X.slack;
		/* last cycle's point first: the best to bound the rest */
		if (w < X.V.n) {
			(void)cl_leaf(&X, w, 1, &rc);
			if (rc < 0)
				return rc;
		}
		thr = (out->found ? out->s : INFINITY) * (1.0 + e) + dc + e * rad + X.slack;
		if (!(C->far_ >= thr)) {
			C->valid_ = 0; /* what the cut does not hold may win */
		} else {
			for (m = 0; m < C->n_; m++) {
				lb = C->ent_[m].lb;
				thr = out->s * (1.0 + e) + dc + e * rad + X.slack;
				if (out->found && lb >= thr)
					continue;
				reopened++;
				st[0].idx = C->ent_[m].idx;
				st[0].cnt = C->ent_[m].cnt;
				st[0].lb = -INFINITY;
				if ((rc = cl_walk(&X, st, 1)) < 0)
					return rc;
			}
			if (out->found) {
				C->witness_ = X.V.leaf_of[out->pi];
				/* a cut that leaves too much to walk again is
				 * made anew next cycle */
				if (reopened > C->n_ / 8 + 4)
					C->valid_ = 0;
				C->reused_++;
				return PX_OK;
			}
		}
		memset(out, 0, sizeof(*out));
		out->s = INFINITY;
		out->certified = 1;
		X.hint = -1;
	}
	/* a point of last cycle's: a first bound */
	if (hint >= 0 && (size_t)hint < X.V.n) {
		(void)cl_leaf(&X, X.V.leaf_of[hint], 1, &rc);
		if (rc < 0)
			return rc;
	}
	if ((rc = full_walk(&X, C)) < 0)
		return rc;
	if (C) {
		C->valid_ = out->found && out->certified;
		C->cloud_ = c;
		C->model_ = o;
		C->serial_ = px__model_serial(c);
		if (out->found)
			C->witness_ = X.V.leaf_of[out->pi];
		{
			double rad;
			cut_pose(c, o, &C->rot_, &C->centre_, &rad);
		}
		C->made_++;
	}
	return PX_OK;
}
