/*
 * pair_cloud.c - a point cloud against a model with exact point queries
 * (pair_internal.h): the least distance of the model over the cloud's
 * points, by the cloud's hierarchy alone. The model's distance function
 * (signed for a closed model) is 1-Lipschitz, so a node of points
 * within r of its box centre c holds no point below s(c) - r: one point
 * query per node visited bounds the whole node, and nodes are visited
 * nearest bound first, pruned against the best found.
 */
#include <math.h>
#include <string.h>

#include "mesh_internal.h"
#include "pair_internal.h"
#include "px_cloud.h"
#include "px_mesh.h"
#include "px_prim.h"

#define CM_STACK (3 * PX_CLOUD_MAX_DEPTH + 4)

struct cm_ent {
	uint32_t idx, cnt; /* inner node idx (cnt 0) or leaf range */
	double lb;
};

/* The search's context: the cloud's frame seen from o's (for the box
 * test), o's own box, and the best so far. */
struct cm_ctx {
	const struct px_model *o;
	struct px__cloud_view V;
	px_pose Pc;
	px_mat3 R;       /* cloud frame -> o frame */
	px_vec3 t;
	px_aabb obox;    /* o's box in its own frame */
	int inside_only, hint;
	struct px__cloud_min *out;
};

/* Does the cloud box (centre c, half extents h, cloud frame) reach o's
 * box? (The enclosing box of the rotated box against o's box.) */
static int reaches_box(const struct cm_ctx *X, px_vec3 c, px_vec3 h)
{
	px_vec3 co = px_v3_add(px_mat3_mul_v3(&X->R, c), X->t);
	px_vec3 om = px_aabb_center(&X->obox);
	int k;
	for (k = 0; k < 3; k++) {
		double e = fabs(X->R.m[k][0]) * h.x + fabs(X->R.m[k][1]) * h.y +
			   fabs(X->R.m[k][2]) * h.z;
		double oh = 0.5 * (px_v3_comp(X->obox.max, k) - px_v3_comp(X->obox.min, k));
		if (fabs(px_v3_comp(co, k) - px_v3_comp(om, k)) > e + oh)
			return 0;
	}
	return 1;
}

/* o's distance at world point p (signed where o has an inside). */
static int o_query(struct cm_ctx *X, px_vec3 p, struct px_model_result *q)
{
	int rc = px_model_query_ex(X->o, p, INFINITY, X->hint, 0, q);
	X->out->queries++;
	if (rc <= 0)
		return rc < 0 ? rc : PX_E_DEGENERATE;
	X->hint = q->index;
	if (!q->certified)
		X->out->certified = 0;
	return 0;
}

/* Does a value v beat the best? Before anything is found the limit
 * itself counts (a point exactly at it is still one to report). */
static int beats(const struct px__cloud_min *m, double v)
{
	return m->found ? v < m->s : v <= m->s;
}

static int cm_leaf(struct cm_ctx *X, uint32_t i0, uint32_t n)
{
	uint32_t i;
	int rc;
	for (i = i0; i < i0 + n; i++) {
		px_vec3 p = px_pose_transform_point(X->Pc, X->V.pt[i]);
		struct px_model_result q;
		if (X->inside_only &&
		    !px_aabb_contains(&X->obox, px_pose_inverse_transform_point(px_model_pose(X->o), p)))
			continue;
		if ((rc = o_query(X, p, &q)) < 0)
			return rc;
		if ((X->inside_only && !(q.distance < 0.0)) || !beats(X->out, q.distance))
			continue;
		X->out->s = q.distance;
		X->out->p = p;
		X->out->q = q.point;
		X->out->pi = (int)X->V.orig[i];
		X->out->oi = q.index;
		X->out->found = 1;
	}
	return 0;
}

int px__cloud_min_model(const struct px_model *c, const struct px_model *o, double limit,
			int inside_only, struct px__cloud_min *out)
{
	struct cm_ctx X;
	struct cm_ent st[CM_STACK];
	px_pose Po;
	int sp, j, k, rc;

	memset(out, 0, sizeof(*out));
	out->s = limit;
	out->certified = 1;
	memset(&X, 0, sizeof(X));
	if (!px__cloud_view(c, &X.V))
		return PX_E_INVAL;
	X.o = o;
	X.out = out;
	X.hint = -1;
	X.inside_only = inside_only;
	X.Pc = px_model_pose(c);
	Po = px_model_pose(o);
	X.obox = px_model_local_aabb(o);
	/* cloud frame -> o frame: Ro^T Rc, Ro^T (tc - to) */
	{
		px_mat3 ro = px_quat_to_mat3(Po.q), rc_ = px_quat_to_mat3(X.Pc.q);
		px_mat3 rt = px_mat3_transpose(&ro);
		X.R = px_mat3_mul(&rt, &rc_);
	}
	X.t = px_pose_inverse_transform_vector(Po, px_v3_sub(X.Pc.t, Po.t));
	st[0].idx = 0;
	st[0].cnt = 0;
	st[0].lb = -INFINITY;
	sp = 1;
	while (sp > 0) {
		struct cm_ent e = st[--sp], kid[4];
		const struct node4 *nd;
		int nk = 0;
		if (!beats(out, e.lb))
			continue;
		if (e.cnt > 0) {
			if ((rc = cm_leaf(&X, e.idx, e.cnt)) < 0)
				return rc;
			continue;
		}
		nd = &X.V.n4[e.idx];
		for (j = 0; j < 4; j++) {
			px_vec3 lo, hi, cc, h;
			struct px_model_result q;
			struct cm_ent ch;
			if (nd->idx[j] == EMPTY)
				continue;
			lo = px_v3(nd->lo[0][j], nd->lo[1][j], nd->lo[2][j]);
			hi = px_v3(nd->hi[0][j], nd->hi[1][j], nd->hi[2][j]);
			cc = px_v3_scale(px_v3_add(lo, hi), 0.5);
			h = px_v3_scale(px_v3_sub(hi, lo), 0.5);
			if (inside_only && !reaches_box(&X, cc, h))
				continue;
			if ((rc = o_query(&X, px_pose_transform_point(X.Pc, cc), &q)) < 0)
				return rc;
			/* every point of the box is within |h| of its centre
			 * (a relative 1e-12 more for the rounding of both) */
			ch.lb = q.distance - px_v3_norm(h) * (1.0 + 1e-12) -
				1e-12 * fabs(q.distance);
			if (!beats(out, ch.lb))
				continue;
			ch.idx = nd->idx[j];
			ch.cnt = nd->cnt[j];
			/* insertion by bound, farthest first: the nearest is
			 * popped next */
			for (k = nk; k > 0 && kid[k - 1].lb < ch.lb; k--)
				kid[k] = kid[k - 1];
			kid[k] = ch;
			nk++;
		}
		for (k = 0; k < nk; k++) {
			if (sp >= CM_STACK) {
				out->certified = 0;
				continue;
			}
			st[sp++] = kid[k];
		}
	}
	return PX_OK;
}

/*
 * The answer from a cloud point's centre pc at distance s from model o
 * (negative: inside o), po its closest point on o: the point's ball of
 * the cloud's radius reaches radius nearer. o_first: o is the pair's A.
 */
static int cloud_answer(struct px_pair_result *res, double s, px_vec3 po, px_vec3 pc,
			double radius, int oi, int pi, int o_first, int certified, int work)
{
	px_vec3 u = px_v3(0, 0, 0), pcw;
	double d = s - radius;

	/* u: from o towards the point (outside), from the point towards o's
	 * surface (inside): the way the point leaves o */
	if (px_v3_normalize(s < 0.0 ? px_v3_sub(po, pc) : px_v3_sub(pc, po), px_v3(0, 0, 0), &u) !=
	    PX_OK)
		u = px_v3(0, 0, 0);
	pcw = px_v3_madd(pc, u, -radius);
	res->distance = d;
	res->intersecting = d <= 0.0;
	res->point_a = o_first ? po : pcw;
	res->point_b = o_first ? pcw : po;
	res->index_a = o_first ? oi : pi;
	res->index_b = o_first ? pi : oi;
	res->iterations = work;
	res->starts = 0;
	res->converged = 1;
	res->local_only = !certified;
	if (d < 0.0 && px_v3_norm2(u) > 0.0) {
		/* point_a - point_b = depth * normal: B leaves A along it */
		res->depth = -d;
		res->normal = o_first ? u : px_v3_neg(u);
		return 2;
	}
	return 1;
}

int px__pair_cloud(const struct px_model *a, const struct px_model *b, int coherent,
		   struct px_pair_cache *cache, int keep_cut, struct px_pair_result *res)
{
	int ca = px_model_kind(a) == PX_MODEL_CLOUD, cb = !ca && px_model_kind(b) == PX_MODEL_CLOUD;
	const struct px_model *c = ca ? a : b, *o = ca ? b : a;
	struct px__cloud_min cm;
	struct px_prim pr;
	double radius;
	int rc;

	if ((!ca && !cb) || px_model_kind(o) == PX_MODEL_CLOUD)
		return 0;
	radius = px_cloud_radius(c);
	if (cache && px_mesh_triangle_count(o) > 0 &&
	    px_mesh_triangle_count(o) <= PX_PAIR_PLANES_MAX_TRIS) {
		/* a small mesh through a cache: the cloud's hierarchy alone,
		 * bounded by the mesh's planes, signed over the points for a
		 * closed mesh (inside: minus the depth), unsigned for an
		 * open one */
		if ((rc = px__cloud_mesh_min(c, o, cache, keep_cut,
					     coherent ? (ca ? res->index_a : res->index_b) : -1,
					     &cm)) < 0)
			return rc;
		if (!cm.found)
			return PX_E_DEGENERATE;
		return cloud_answer(res, cm.s, cm.q, cm.p, radius, cm.oi, cm.pi, cb, cm.certified,
				    cm.nodes + cm.queries);
	}
	if (px_mesh_triangle_count(o) > 0) {
		struct px__mesh_pair mp;
		int ht = -1, hp = -1;
		if (coherent) {
			ht = ca ? res->index_b : res->index_a;
			hp = ca ? res->index_a : res->index_b;
		}
		if ((rc = px__mesh_cloud_pair(o, c, ht, hp, &mp)) < 0)
			return rc;
		if (!(px_model_caps(o) & PX_MODEL_CAP_SIGNED))
			return cloud_answer(res, mp.distance, mp.point_a, mp.point_b, radius,
					    mp.tri_a, mp.tri_b, cb, mp.certified,
					    mp.nodes + mp.tri_tests);
		/* a closed mesh: points inside it are at negative distance,
		 * at least as far in as the nearest point is from the
		 * surface (a relative 1e-9 of slack for the two ways of
		 * measuring it) */
		if ((rc = px__cloud_min_model(c, o, -mp.distance * (1.0 - 1e-9), 1, &cm)) < 0)
			return rc;
		if (!cm.found)
			return cloud_answer(res, mp.distance, mp.point_a, mp.point_b, radius,
					    mp.tri_a, mp.tri_b, cb, mp.certified && cm.certified,
					    mp.nodes + mp.tri_tests + cm.queries);
		return cloud_answer(res, cm.s, cm.q, cm.p, radius, cm.oi, cm.pi, cb,
				    mp.certified && cm.certified,
				    mp.nodes + mp.tri_tests + cm.queries);
	}
	if (px_prim_get(o, &pr) != PX_OK)
		return 0;
	/* a primitive: its exact (signed) point queries over the cloud */
	if ((rc = px__cloud_min_model(c, o, INFINITY, 0, &cm)) < 0)
		return rc;
	if (!cm.found)
		return PX_E_DEGENERATE;
	return cloud_answer(res, cm.s, cm.q, cm.p, radius, cm.oi, cm.pi, cb, cm.certified,
			    cm.queries);
}
