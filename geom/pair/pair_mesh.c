/*
 * pair_mesh.c - exact pairs with a mesh: a mesh against a convex model
 * (the mesh hierarchy bounded by the other's point queries, GJK or a
 * closed form per triangle), and the containment test of a closed model
 * holding the other whole (pair_internal.h).
 */
#include <math.h>
#include <string.h>

#include "mesh_internal.h"
#include "pair_internal.h"
#include "px_mesh.h"

void px__tri_world(const struct px_model *m, int t, px_vec3 v[3])
{
	int k;
	if (t < 0 || px_mesh_triangle(m, (size_t)t, v) != PX_OK) {
		v[0] = v[1] = v[2] = px_model_pose(m).t;
		return;
	}
	for (k = 0; k < 3; k++)
		v[k] = px_pose_transform_point(px_model_pose(m), v[k]);
}

/* Is p (world) clearly outside model x's box, where x holds nothing?
 * The margin, a millionth of the box and the coordinates, covers the
 * rounding of the move into x's frame. */
static int outside_box(const struct px_model *x, px_vec3 p)
{
	px_aabb b = px_model_local_aabb(x);
	px_vec3 l;
	double m;
	if (!px__finite_box(&b))
		return 0;
	l = px_pose_inverse_transform_point(px_model_pose(x), p);
	m = 1e-6 * (px_aabb_diagonal(&b) + px_v3_norm(l) + px_v3_norm(px_model_pose(x).t));
	return l.x < b.min.x - m || l.x > b.max.x + m || l.y < b.min.y - m ||
	       l.y > b.max.y + m || l.z < b.min.z - m || l.z > b.max.z + m;
}

int px__pair_contained(const struct px_model *a, const struct px_model *b,
		       struct pair_run *best, int *total)
{
	int side, rc;
	for (side = 0; side < 2; side++) {
		const struct px_model *x = side ? b : a;
		px_vec3 p = side ? best->pa : best->pb; /* a point of the other */
		struct px_model_result q;
		if (!(px_model_caps(x) & PX_MODEL_CAP_SIGNED) || outside_box(x, p))
			continue;
		if ((rc = px_model_query(x, p, &q)) < 0)
			return rc;
		(*total)++;
		if (q.is_signed && q.distance < 0.0) {
			best->intersecting = 1;
			best->d = 0.0;
			if (side)
				best->pb = q.point;
			else
				best->pa = q.point;
			return 1;
		}
	}
	return 0;
}

/* Mesh against a convex model with a support function: each triangle
 * is itself convex, so GJK between the two is exact. */
struct tv_ctx {
	const struct px_model *o;
	int capsule;        /* o is a capsule: axis c0-c1, radius cr */
	px_vec3 c0, c1;
	double cr;
	double best;
	px_vec3 pt, po; /* on the triangle, on o */
	px_vec3 tv[3];
	int tri;
	int iters;
};

static int tri_vs_convex(void *ctx, const px_vec3 v[3], int index, double *d)
{
	struct tv_ctx *c = ctx;
	struct shp T = {NULL, v, 3}, O = {c->o, NULL, 0};
	struct gjk_vert S[4];
	double dist = 0.0;
	px_vec3 pt = v[0], po = v[0];
	int its = 0, ns = 0, g;

	if (c->capsule) {
		/* closed form: the axis segment against the triangle */
		double s, d2 = px__seg_tri(c->c0, c->c1, v, &s, &pt);
		px_vec3 a = px_v3_lerp(c->c0, c->c1, s);
		dist = sqrt(d2) - c->cr;
		if (dist <= 0.0) {
			dist = 0.0;
			po = pt; /* the triangle point is in the capsule */
		} else {
			po = px_v3_madd(a, px_v3_sub(pt, a), c->cr / sqrt(d2));
		}
		its = 1;
		g = 1;
	} else {
		g = px__gjk(&T, &O, &dist, &pt, &po, &its, S, &ns, NULL, NULL);
	}
	c->iters += its;
	if (g < 0)
		return g;
	if (g == 0)
		dist = 0.0;
	if (dist < c->best) {
		c->best = dist;
		c->pt = pt;
		c->po = po;
		c->tv[0] = v[0];
		c->tv[1] = v[1];
		c->tv[2] = v[2];
		c->tri = index;
	}
	/* GJK out of iterations: only an upper bound, which the search
	 * must not take as exact */
	*d = its >= GJK_MAX_ITERS ? INFINITY : dist;
	return 0;
}

#define MESH_CONVEX_QUERIES 4096

int px__pair_mesh_convex(const struct px_model *m, const struct px_model *o, int hint,
			 struct pair_run *best, int *total)
{
	struct tv_ctx c;
	int rc, exact, queries = 0, bt = -1, j;
	double bd;
	px_vec3 v[3];
	double dd;

	memset(&c, 0, sizeof(c));
	c.o = o;
	c.capsule = px__capsule_axis(o, &c.c0, &c.c1, &c.cr);
	c.best = INFINITY;
	c.tri = -1;
	if (hint < 0 || (size_t)hint >= px_mesh_triangle_count(m)) {
		struct px_model_result q;
		if ((rc = px_model_query_ex(m, px_model_pose(o).t, INFINITY, -1,
					    PX_QUERY_UNSIGNED, &q)) < 0)
			return rc;
		(*total)++;
		hint = q.index;
	}
	px__tri_world(m, hint, v);
	if ((rc = tri_vs_convex(&c, v, hint, &dd)) < 0)
		return rc;
	bd = c.best;
	bt = c.tri;
	exact = px__mesh_vs_model(m, o, tri_vs_convex, &c, MESH_CONVEX_QUERIES, &bd, &bt,
				  &queries);
	*total += queries + c.iters;
	if (exact < 0)
		return exact;
	best->converged = 1;
	best->intersecting = c.best == 0.0;
	best->d = c.best;
	best->pa = c.pt;
	/* overlapping: GJK's common point, on the triangle and in o */
	best->pb = best->intersecting ? c.pt : c.po;
	best->ia = c.tri;
	best->ib = -1;
	for (j = 0; j < 2 && !best->intersecting; j++) {
		/* GJK's witness on o is a convex combination of support
		 * points, a chord point just inside a curved o: two exact
		 * projections put the pair on the surfaces (the triangle's
		 * witness is on it already; both sets are convex, so this
		 * converges to the true pair) */
		struct px_model_result q;
		px_vec3 pt;
		if ((rc = px_model_query(o, best->pa, &q)) < 0)
			return rc;
		(*total)++;
		if (q.is_signed && q.distance <= 0.0) {
			best->intersecting = 1;
			best->d = 0.0;
			best->pb = best->pa;
			break;
		}
		px_tri_closest(q.point, c.tv[0], c.tv[1], c.tv[2], &pt, NULL, NULL, NULL, NULL);
		best->ib = q.index;
		best->pb = q.point;
		best->pa = pt;
		best->d = px_v3_dist(pt, q.point);
	}
	return exact;
}
