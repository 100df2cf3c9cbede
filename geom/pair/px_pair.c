/*
 * px_pair.c - model-to-model distance (px_pair.h): which method answers
 * a pair, and the answer's final form. The methods: one point query of a
 * sphere's centre, the closed forms (px_pair_prim.c), GJK and EPA for
 * two convex models (pair_gjk.c), the exact mesh paths (two meshes:
 * px_mesh_pair.c; a mesh against a convex model: pair_mesh.c), a cloud
 * against a mesh or a primitive (pair_cloud.c), and the general search
 * by alternating projections with the deepest-point search for overlaps
 * (pair_search.c).
 */
#include <math.h>
#include <string.h>

#include "pair_internal.h"
#include "mesh_internal.h"
#include "px_mesh.h"
#include "px_pair.h"
#include "px_prim.h"

/* The options with their defaults filled in. */
struct pair_cfg {
	int starts, max_iters, coherent, local_ok;
	double tol, rel;
};

/* The general search's state: the best pair so far, the work spent
 * (point queries and the like), the starts made, and the contact
 * triangles' corners (nxs per side) that seed the depth search when the
 * models overlap. */
struct pair_state {
	struct pair_run best;
	int total, n, have, nxs;
	px_vec3 xs[2][3];
};

/* What a step of px_pair_distance() did (or a negative error). */
#define STEP_NONE 0       /* not this pair's method: the next one */
#define STEP_DONE 1       /* answered; the normal follows from the points */
#define STEP_DONE_NORMAL 2 /* answered with its normal */
#define STEP_OVERLAP 3    /* the models overlap: on to the depth search */

/* A sphere against anything: one point query of its centre. */
static int pair_sphere(const struct px_model *a, const struct px_model *b,
		       struct px_pair_result *res)
{
	struct px_prim pr;
	const struct px_model *sph = NULL, *oth = NULL;
	struct px_model_result q;
	px_vec3 c, ps, po;
	double d;
	int swap = 0, rc;

	if (px_prim_get(a, &pr) == PX_OK && pr.type == PX_PRIM_SPHERE) {
		sph = a;
		oth = b;
	} else if (px_prim_get(b, &pr) == PX_OK && pr.type == PX_PRIM_SPHERE) {
		sph = b;
		oth = a;
		swap = 1;
	}
	if (!sph)
		return STEP_NONE;
	c = px_model_pose(sph).t;
	rc = px_model_query(oth, c, &q);
	if (rc < 0)
		return rc;
	d = q.distance - pr.a;
	po = q.point;
	/* the sphere's point towards the other model */
	ps = px_v3_madd(c, q.direction, q.distance < 0.0 ? pr.a : -pr.a);
	if (q.distance == 0.0)
		ps = px_v3_madd(c, q.direction, -pr.a);
	res->intersecting = d <= 0.0;
	res->distance = d;
	if (d < 0.0) {
		/* the sphere's point deepest in the other model: moving the
		 * sphere by -d along direction frees it */
		ps = px_v3_madd(c, q.direction, -pr.a);
		res->depth = -d;
		res->depth_approx = !q.is_signed && q.distance == 0.0;
		res->normal = swap ? q.direction : px_v3_neg(q.direction);
	}
	res->point_a = swap ? po : ps;
	res->point_b = swap ? ps : po;
	res->index_a = swap ? q.index : 0;
	res->index_b = swap ? 0 : q.index;
	res->iterations = 1;
	res->starts = 0;
	res->converged = 1;
	res->local_only = !q.certified;
	return STEP_DONE;
}

/*
 * GJK's witness points are convex combinations of support points, whose
 * weights lose accuracy on the thin simplices of smooth shapes (then
 * they can sit far from the contact though the distance |v| is right).
 * Two starts: those points (pa), and the supports along the separating
 * direction v (the contact points themselves on strictly convex
 * shapes); each is put on the surfaces by two exact projections (each
 * step can only shorten the pair, both models being convex), and the
 * shorter pair is kept in *qa, *qb at distance *dq. *ctol: the
 * certification tolerance, 1e-8 of the distance plus 1e-9 of the
 * coordinates (a nanometre in a metre-sized scene). *nq: the queries
 * made. Returns 0 or a negative error.
 */
static int convex_witnesses(const struct px_model *a, const struct px_model *b, px_vec3 pa,
			    px_vec3 v, double d, struct px_model_result *qa,
			    struct px_model_result *qb, double *dq_out, double *ctol_out,
			    int *nq_out)
{
	struct px_model_result ka, kb;
	px_vec3 x = pa;
	double dq = INFINITY, ctol = 0.0;
	int j, s, nq = 0, rc;

	memset(qa, 0, sizeof(*qa));
	memset(qb, 0, sizeof(*qb));
	for (s = 0; s < 2; s++) {
		if (s == 1) {
			/* the second start only where the first one's pair
			 * is longer than |v| (its queries are the cost of
			 * this path on a convex mesh) */
			if (!(dq - d > ctol))
				break;
			if ((rc = px_model_support(a, px_v3_neg(v), &x)) < 0)
				return rc;
		}
		for (j = 0; j < 2; j++) {
			if ((rc = px_model_query(b, x, &kb)) < 0 ||
			    (rc = px_model_query(a, kb.point, &ka)) < 0)
				return rc;
			x = ka.point;
			nq += 2;
		}
		if (s == 0 || px_v3_dist(ka.point, kb.point) < dq) {
			dq = px_v3_dist(ka.point, kb.point);
			*qa = ka;
			*qb = kb;
		}
		ctol = 1e-8 * dq + 1e-9 * (1.0 + px_v3_norm(qa->point));
	}
	/* witnesses still longer than |v|: a few more rounds from the
	 * better start while they gain (slow near contact, where curved
	 * and flat parts meet; the distance itself is |v| either way) */
	for (j = 0; j < 4 && dq - d > ctol; j++) {
		double dn, gap = dq - d;
		if ((rc = px_model_query(b, qa->point, &kb)) < 0 ||
		    (rc = px_model_query(a, kb.point, &ka)) < 0)
			return rc;
		nq += 2;
		dn = px_v3_dist(ka.point, kb.point);
		if (!(dn < dq))
			break;
		dq = dn;
		*qa = ka;
		*qb = kb;
		if (dq - d > 0.75 * gap)
			break; /* stalled: less than a quarter gained */
	}
	*dq_out = dq;
	*ctol_out = ctol;
	*nq_out = nq;
	return 0;
}

/* Two convex models with support functions: GJK, and EPA when they
 * overlap. STEP_NONE when GJK cannot run (a support function failed). */
static int pair_convex(const struct px_model *a, const struct px_model *b,
		       struct px_pair_result *res)
{
	double d = 0.0, lower = 0.0;
	px_vec3 pa, pb, gv;
	struct gjk_vert S[4];
	struct shp sa = {a, NULL, 0}, sb = {b, NULL, 0};
	int its = 0, ns = 0, g = px__gjk(&sa, &sb, &d, &pa, &pb, &its, S, &ns, &gv, &lower);

	if (g > 0) {
		struct px_model_result qa, qb;
		double dq, ctol;
		int nq, rc = convex_witnesses(a, b, pa, gv, d, &qa, &qb, &dq, &ctol, &nq);
		if (rc < 0)
			return rc;
		res->intersecting = qb.is_signed && qb.distance <= 0.0;
		/* |v| is a point of A - B (an upper bound) and the support
		 * plane a lower one: the distance is |v| when they agree,
		 * whatever the witnesses' own gap */
		res->distance = res->intersecting ? 0.0 : fmin(d, dq);
		res->witness_gap = res->intersecting ? 0.0 : dq - res->distance;
		res->point_a = qa.point;
		res->point_b = qb.point;
		res->index_a = qa.index;
		res->index_b = qb.index;
		res->iterations = its + nq;
		res->starts = 0;
		res->converged = its < GJK_MAX_ITERS &&
				 (res->intersecting || res->distance - lower <= ctol);
		res->local_only = !res->converged;
		return STEP_DONE;
	}
	if (g == 0) {
		double depth = 0.0;
		px_vec3 nrm;
		int e = px__epa(a, b, S, ns, &depth, &nrm, &pa, &pb, &its);
		res->intersecting = 1;
		res->distance = 0.0;
		if (e >= 0 && depth > 0.0) {
			res->depth = depth;
			res->distance = -depth;
			res->normal = nrm;
			res->depth_approx = e == 0;
		}
		res->point_a = pa;
		res->point_b = pb;
		res->index_a = res->index_b = -1;
		res->iterations = its;
		res->starts = 0;
		res->converged = 1;
		res->local_only = 0;
		return STEP_DONE_NORMAL;
	}
	return STEP_NONE;
}

/* An exact answer of the mesh paths: best, apart, proven. */
static void pair_answer(struct px_pair_result *res, const struct pair_run *best, int total,
			int local_only)
{
	res->distance = best->d;
	res->point_a = best->pa;
	res->point_b = best->pb;
	res->index_a = best->ia;
	res->index_b = best->ib;
	res->iterations = total;
	res->starts = 0;
	res->converged = 1;
	res->intersecting = 0;
	res->local_only = local_only;
}

/* Two meshes: exact, by both hierarchies at once. */
static int pair_two_meshes(const struct px_model *a, const struct px_model *b,
			   const struct pair_cfg *cfg, struct px_pair_result *res,
			   struct pair_state *st)
{
	struct px__mesh_pair mp;
	int rc = px__mesh_pair(a, b, cfg->coherent ? res->index_a : -1,
			       cfg->coherent ? res->index_b : -1, &mp);
	if (rc < 0)
		return rc;
	st->total = mp.nodes + mp.tri_tests;
	st->best.d = mp.distance;
	st->best.pa = mp.point_a;
	st->best.pb = mp.point_b;
	st->best.ia = mp.tri_a;
	st->best.ib = mp.tri_b;
	st->best.converged = 1;
	st->best.intersecting = mp.intersecting;
	if (!st->best.intersecting && (rc = px__pair_contained(a, b, &st->best, &st->total)) < 0)
		return rc;
	if (st->best.intersecting) {
		px__tri_world(a, st->best.ia, st->xs[0]);
		px__tri_world(b, st->best.ib, st->xs[1]);
		st->nxs = 3;
		return STEP_OVERLAP;
	}
	pair_answer(res, &st->best, st->total, !mp.certified);
	return STEP_DONE;
}

/* A mesh against a convex model with a support function: exact, by the
 * mesh hierarchy and GJK per triangle. When its query budget runs out,
 * the best found so far goes on to the projections (STEP_NONE). */
static int pair_mesh_convex(const struct px_model *a, const struct px_model *b,
			    const struct pair_cfg *cfg, struct px_pair_result *res,
			    struct pair_state *st)
{
	int ma = px_mesh_triangle_count(a) > 0 && px_model_get_ops(b)->support;
	int mb = !ma && px_mesh_triangle_count(b) > 0 && px_model_get_ops(a)->support;
	const struct px_model *m = ma ? a : b, *o = ma ? b : a;
	struct pair_run mr;
	int ex, mt, rc;

	if (!ma && !mb)
		return STEP_NONE;
	memset(&mr, 0, sizeof(mr));
	ex = px__pair_mesh_convex(m, o, cfg->coherent ? (ma ? res->index_a : res->index_b) : -1,
				  &mr, &st->total);
	if (ex < 0)
		return ex;
	mt = mr.ia; /* the mesh's triangle */
	if (mb) {
		/* the pair was measured mesh first */
		px_vec3 t = mr.pa;
		int ti = mr.ia;
		mr.pa = mr.pb;
		mr.pb = t;
		mr.ia = mr.ib;
		mr.ib = ti;
	}
	st->best = mr;
	if (!st->best.intersecting && (rc = px__pair_contained(a, b, &st->best, &st->total)) < 0)
		return rc;
	if (st->best.intersecting) {
		px_vec3 *other = st->xs[ma ? 1 : 0];
		px__tri_world(m, mt, st->xs[ma ? 0 : 1]);
		other[0] = other[1] = other[2] = ma ? st->best.pb : st->best.pa;
		st->nxs = 3;
		return STEP_OVERLAP;
	}
	if (ex == 1) {
		pair_answer(res, &st->best, st->total, 0);
		return STEP_DONE;
	}
	/* budget out: projections may still do better */
	st->have = 1;
	return STEP_NONE;
}

/* Neighbourhood steps on both sides, each success polished by a further
 * round of projections. */
static int pair_refine(const struct px_model *a, const struct px_model *b,
		       const struct pair_cfg *cfg, struct pair_state *st)
{
	struct pair_run r;
	int k, rc;
	for (k = 0; k < (cfg->coherent && cfg->starts == 1 ? 0 : 2) && !st->best.intersecting &&
		    st->best.d > 0.0; k++) {
		int ia = st->best.ia, ib = st->best.ib, ra, rb;
		double d = st->best.d;
		px_vec3 pa = st->best.pa, pb = st->best.pb;
		ra = px__pair_refine_side(a, b, &pa, &pb, &ia, &ib, &d, &st->total);
		if (ra < 0)
			return ra;
		rb = px__pair_refine_side(b, a, &pb, &pa, &ib, &ia, &d, &st->total);
		if (rb < 0)
			return rb;
		if (!ra && !rb)
			break;
		st->best.d = d;
		st->best.pa = pa;
		st->best.pb = pb;
		st->best.ia = ia;
		st->best.ib = ib;
		rc = px__pair_run(a, b, pa, cfg->max_iters, cfg->tol, cfg->rel, &r);
		if (rc < 0)
			return rc;
		st->total += r.iters;
		if (r.d < st->best.d || r.intersecting)
			st->best = r;
	}
	return 0;
}

/* The general search: alternating projections from the starts (last
 * cycle's pair first when coherent), then the neighbourhood steps. */
static int pair_projections(const struct px_model *a, const struct px_model *b,
			    const struct pair_cfg *cfg, const struct px_pair_result *res,
			    struct pair_state *st)
{
	struct pair_run r;
	px_vec3 seed;
	int k, rc;

	for (k = cfg->coherent ? -1 : 0; st->n < cfg->starts; k++) {
		if (k == -1) {
			/* last pair, moved with the models */
			seed = px_pose_transform_point(px_model_pose(a), res->local_a);
		} else if (!px__pair_seed(a, b, k, &seed)) {
			break;
		}
		if (!px_v3_isfinite(seed))
			continue;
		rc = px__pair_run(a, b, seed, cfg->max_iters, cfg->tol, cfg->rel, &r);
		if (rc < 0)
			return rc;
		st->total += r.iters;
		st->n++;
		if (!st->have || r.d < st->best.d) {
			st->best = r;
			st->have = 1;
		}
		if (st->best.intersecting)
			break;
	}
	if (!st->have)
		return PX_E_DEGENERATE;
	return pair_refine(a, b, cfg, st);
}

/* Penetration: the deepest point of either model in the other, from the
 * overlap found (and the contact triangles' corners) and from every
 * seed; fills the depth, points and normal when one was found. */
static int pair_depth(const struct px_model *a, const struct px_model *b,
		      const struct pair_cfg *cfg, struct pair_state *st,
		      struct px_pair_result *res)
{
	px_aabb ba = px_model_local_aabb(a), bb = px_model_local_aabb(b);
	double scale = fmax(px__finite_box(&ba) ? px_aabb_diagonal(&ba) : 0.0,
			    px__finite_box(&bb) ? px_aabb_diagonal(&bb) : 0.0);
	double dmin = 0.0;
	int side, j;

	scale = scale > 0.0 ? scale : 1.0;
	for (side = 0; side < 2; side++) {
		const struct px_model *x = side ? b : a, *y = side ? a : b;
		/* every seed costs up to 2 DEEP_ITERS + 2 point queries, and
		 * points deep inside a mesh are its most expensive queries
		 * (many triangles nearly equidistant): opt->starts trades
		 * time for the global hit rate */
		for (j = -1 - st->nxs; j < cfg->starts; j++) {
			px_vec3 s = side ? st->best.pb : st->best.pa, pxx, qy, dir;
			double dd;
			int g;
			if (j < -1)
				s = st->xs[side][-2 - j]; /* the contact triangles' corners */
			else if (j >= 0 && (!px__pair_seed(x, y, j, &s) || !px_v3_isfinite(s)))
				break;
			g = px__pair_deepest(x, y, s, scale, &dd, &pxx, &qy, &dir, &st->total);
			if (g < 0)
				return g;
			if (g == 0 || !(dd < dmin))
				continue;
			dmin = dd;
			/* pa - pb = depth * normal (see px_pair.h) */
			res->point_a = side ? qy : pxx;
			res->point_b = side ? pxx : qy;
			res->normal = side ? dir : px_v3_neg(dir);
		}
	}
	if (dmin < 0.0) {
		res->depth = -dmin;
		res->distance = dmin;
		res->depth_approx = 1;
	}
	return 0;
}

/* Everything that is not a sphere, a closed form or two convex models:
 * the mesh paths where they apply, else the general search; then the
 * depth of an overlap. */
static int pair_general(const struct px_model *a, const struct px_model *b,
			const struct pair_cfg *cfg, struct px_pair_result *res)
{
	struct pair_state st;
	int two_meshes = px_mesh_triangle_count(a) > 0 && px_mesh_triangle_count(b) > 0;
	/* two meshes, coherent and allowed local: last cycle's pair tracked
	 * by the projections, no exact proof (px_pair.h, local_ok) */
	int mesh_local = cfg->coherent && cfg->local_ok && two_meshes;
	int rc = STEP_NONE;

	memset(&st, 0, sizeof(st));
	st.best.d = INFINITY;
	if (!mesh_local) {
		rc = two_meshes ? pair_two_meshes(a, b, cfg, res, &st)
				: pair_mesh_convex(a, b, cfg, res, &st);
		if (rc < 0 || rc == STEP_DONE)
			return rc;
	}
	if (rc == STEP_NONE && (rc = pair_projections(a, b, cfg, res, &st)) < 0)
		return rc;
	res->distance = st.best.d;
	res->point_a = st.best.pa;
	res->point_b = st.best.pb;
	res->index_a = st.best.ia;
	res->index_b = st.best.ib;
	if (st.best.intersecting && (rc = pair_depth(a, b, cfg, &st, res)) < 0)
		return rc;
	res->iterations = st.total;
	res->starts = st.n;
	res->converged = st.best.converged;
	res->intersecting = st.best.intersecting;
	res->local_only = !(st.best.intersecting ||
			    (st.best.converged &&
			     (px_model_caps(a) & PX_MODEL_CAP_CONVEX) &&
			     (px_model_caps(b) & PX_MODEL_CAP_CONVEX)));
	return STEP_DONE;
}

int px_pair_distance(const struct px_model *a, const struct px_model *b,
		     const struct px_pair_opts *opt, struct px_pair_result *res)
{
	return px_pair_distance_cached(a, b, opt, NULL, res);
}

void px_pair_cache_init(struct px_pair_cache *c)
{
	if (c) {
		c->valid_ = 0;
		c->n_ = 0;
		c->cloud_ = c->model_ = NULL;
		c->planes_.model_ = NULL;
		c->planes_.serial_ = 0;
		c->planes_.n_ = 0;
		c->made_ = c->reused_ = 0;
	}
}

unsigned long px_pair_cache_full(const struct px_pair_cache *c)
{
	return c ? c->made_ : 0;
}

unsigned long px_pair_cache_reused(const struct px_pair_cache *c)
{
	return c ? c->reused_ : 0;
}

int px_pair_distance_cached(const struct px_model *a, const struct px_model *b,
			    const struct px_pair_opts *opt, struct px_pair_cache *cache,
			    struct px_pair_result *res)
{
	struct pair_cfg cfg;
	int rc;

	cfg.starts = opt && opt->starts ? opt->starts : 8;
	cfg.max_iters = opt && opt->max_iters ? opt->max_iters : 64;
	cfg.tol = opt && opt->tol > 0.0 ? opt->tol : 1e-12;
	cfg.rel = opt && opt->rel_tol > 0.0 ? opt->rel_tol : 1e-9;
	cfg.coherent = opt && opt->coherent && res && res->valid;
	cfg.local_ok = opt && opt->local_ok;
	if (!a || !b || !res || cfg.starts < 1 || cfg.starts > PX_PAIR_MAX_STARTS ||
	    cfg.max_iters < 1 || !(cfg.tol >= 0.0))
		return PX_E_INVAL;
	res->depth = 0.0;
	res->depth_approx = 0;
	res->witness_gap = 0.0;

	rc = pair_sphere(a, b, res);
	/* capsule against capsule or box: closed forms (pair_internal.h) */
	if (rc == STEP_NONE)
		rc = px__pair_closed(a, b, res);
	if (rc == STEP_NONE && (px_model_caps(a) & PX_MODEL_CAP_CONVEX) &&
	    (px_model_caps(b) & PX_MODEL_CAP_CONVEX) && px_model_get_ops(a)->support &&
	    px_model_get_ops(b)->support)
		rc = pair_convex(a, b, res);
	/* a cloud against a mesh or a primitive: exact (pair_cloud.c) */
	if (rc == STEP_NONE)
		rc = px__pair_cloud(a, b, cfg.coherent, cache, opt && opt->coherent, res);
	/* NURBS surfaces against a mesh, NURBS or a convex primitive:
	 * certified by both hierarchies (pair_nurbs.c) */
	if (rc == STEP_NONE)
		rc = px__pair_nurbs(a, b, cfg.coherent, res);
	if (rc == STEP_NONE)
		rc = pair_general(a, b, &cfg, res);
	if (rc < 0)
		return rc;
	if (rc != STEP_DONE_NORMAL) {
		/* apart: the way B moves away from A */
		px_vec3 dv = px_v3_sub(res->point_b, res->point_a);
		if (res->depth == 0.0 &&
		    px_v3_normalize(dv, px_v3(0, 0, 0), &res->normal) != PX_OK)
			res->normal = px_v3(0, 0, 0);
	}
	res->local_a = px_pose_inverse_transform_point(px_model_pose(a), res->point_a);
	res->local_b = px_pose_inverse_transform_point(px_model_pose(b), res->point_b);
	res->valid = 1;
	return PX_OK;
}
