/*
 * pair_search.c - the general pair search of px_pair_distance: starts
 * (seed points on the models' boxes), alternating projections from
 * each, neighbourhood steps over local minima, and the deepest-point
 * search for overlapping models without an exact method
 * (pair_internal.h).
 */
#include <math.h>

#include "pair_internal.h"

/* ---- approximate penetration: deepest point ---------------------------------
 *
 * For closed models without an exact method: the point of x's surface
 * deepest inside y (most negative signed distance to y), by projected
 * descent from a start on x: step against y's distance gradient,
 * project back onto x, keep the step when it went deeper (the step
 * grows after a success and halves after a failure). A local search:
 * results are flagged approximate. Returns 1 with *d (< 0) and the
 * points when a point of x inside y was found, 0 when none, or an error.
 */
#define DEEP_ITERS 40

int px__pair_deepest(const struct px_model *x, const struct px_model *y,
		      px_vec3 start, double scale, double *d, px_vec3 *px_,
		      px_vec3 *qy, px_vec3 *dir, int *iters)
{
	struct px_model_result rx, ry, t;
	double step;
	int it, rc;

	if ((rc = px_model_query(x, start, &rx)) < 0)
		return rc;
	if ((rc = px_model_query(y, rx.point, &ry)) < 0)
		return rc;
	*iters += 2;
	if (!ry.is_signed || !(ry.distance < 0.0))
		return 0;
	step = fmax(-ry.distance, 1e-3 * scale);
	for (it = 0; it < DEEP_ITERS && step > 1e-5 * scale; it++) {
		px_vec3 target = px_v3_madd(rx.point, ry.direction, -step);
		struct px_model_result nx;
		if ((rc = px_model_query(x, target, &nx)) < 0)
			return rc;
		if ((rc = px_model_query(y, nx.point, &t)) < 0)
			return rc;
		*iters += 2;
		if (t.is_signed && t.distance < ry.distance - 1e-12 * scale) {
			rx = nx;
			ry = t;
			step *= 1.5;
		} else {
			step *= 0.5;
		}
	}
	*d = ry.distance;
	*px_ = rx.point;
	*qy = ry.point;
	*dir = ry.direction;
	return 1;
}


/* The pair (ra's point, rb's point) as the best so far at distance d. */
static inline void run_take(struct pair_run *o, double d, const struct px_model_result *ra,
			    const struct px_model_result *rb)
{
	o->d = d;
	o->pa = ra->point;
	o->pb = rb->point;
	o->ia = ra->index;
	o->ib = rb->index;
}

int px__pair_run(const struct px_model *a, const struct px_model *b, px_vec3 seed,
		 int max_iters, double tol, double rel, struct pair_run *o)
{
	struct px_model_result ra, rb;
	double prev = INFINITY;
	int it, rc;

	o->iters = 0;
	o->converged = 0;
	o->intersecting = 0;
	o->d = INFINITY;
	rc = px_model_query(a, seed, &ra);
	if (rc < 0)
		return rc;
	o->iters++;
	for (it = 0; it < max_iters; it++) {
		double d;
		rc = px_model_query(b, ra.point, &rb);
		if (rc < 0)
			return rc;
		o->iters++;
		d = fabs(rb.distance);
		if (d < o->d)
			run_take(o, d, &ra, &rb);
		if ((rb.is_signed && rb.distance <= 0.0) || d == 0.0) {
			/* a point of A inside or on B */
			run_take(o, 0.0, &ra, &rb);
			o->intersecting = 1;
			o->converged = 1;
			return 0;
		}
		rc = px_model_query(a, rb.point, &ra);
		if (rc < 0)
			return rc;
		o->iters++;
		d = fabs(ra.distance);
		if ((ra.is_signed && ra.distance <= 0.0) || d == 0.0) {
			run_take(o, 0.0, &ra, &rb);
			o->intersecting = 1;
			o->converged = 1;
			return 0;
		}
		if (d < o->d)
			run_take(o, d, &ra, &rb);
		/* each projection can only lower the distance; stop when it
		 * no longer does by more than tol */
		if (prev - o->d <= tol + rel * o->d) {
			o->converged = 1;
			return 0;
		}
		prev = o->d;
	}
	return 0;
}

#define REFINE_CAP 16

int px__pair_refine_side(const struct px_model *x, const struct px_model *y,
			  px_vec3 *px, px_vec3 *py, int *ix, int *iy, double *d,
			  int *iters)
{
	const struct px_model_ops *o = px_model_get_ops(x);
	const void *impl = px_model_impl(x);
	px_pose P = px_model_pose(x);
	struct px_model_query q;
	int idx[REFINE_CAP], n = PX_E_NOSPC, k, tries, improved = 0;
	double R = *d;
	px_vec3 c;

	if (!o->collect || !o->closest_among || !(R > 0.0))
		return 0;
	c = px_pose_inverse_transform_point(P, *px);
	for (tries = 0; tries < 8 && n == PX_E_NOSPC; tries++) {
		n = o->collect(impl, c, R, idx, REFINE_CAP);
		if (n == PX_E_NOSPC)
			R *= 0.5;
	}
	if (n < 0)
		return n == PX_E_NOSPC ? 0 : n;
	q.p = px_pose_inverse_transform_point(P, *py);
	q.max_dist = INFINITY;
	q.hint = -1;
	q.flags = PX_QUERY_UNSIGNED;
	for (k = 0; k < n; k++) {
		struct px_model_result rx, ry;
		px_vec3 xw;
		int rc = o->closest_among(impl, &q, &idx[k], 1, &rx);
		if (rc < 0)
			return rc;
		if (rc == 0)
			continue;
		xw = px_pose_transform_point(P, rx.point);
		rc = px_model_query_ex(y, xw, INFINITY, -1, PX_QUERY_UNSIGNED, &ry);
		if (rc < 0)
			return rc;
		(*iters)++;
		if (ry.distance < *d) {
			*d = ry.distance;
			*px = xw;
			*py = ry.point;
			*ix = rx.index;
			*iy = ry.index;
			improved = 1;
		}
	}
	return improved;
}

int px__finite_box(const px_aabb *b)
{
	return !px_aabb_is_empty(b) && px_v3_isfinite(b->min) &&
	       px_v3_isfinite(b->max);
}

/* Seed k of a box: its 8 corners, then its 6 face centres; 0 past them. */
static int box_seed(const px_obb *B, int k, px_vec3 *out)
{
	if (k < 8) {
		*out = px_obb_corner(B, k);
		return 1;
	}
	if (k < 14) {
		int ax = (k - 8) / 2;
		double s = (k - 8) % 2 ? 1.0 : -1.0;
		*out = px_v3_madd(B->center, B->axis[ax], s * px_v3_comp(B->half, ax));
		return 1;
	}
	return 0;
}

int px__pair_seed(const struct px_model *a, const struct px_model *b, int k, px_vec3 *out)
{
	px_aabb la = px_model_local_aabb(a), lb = px_model_local_aabb(b);
	int fa = px__finite_box(&la), fb = px__finite_box(&lb);
	px_obb A, B;

	if (fa)
		A = px_model_world_obb(a);
	if (fb)
		B = px_model_world_obb(b);
	if (k == 0) {
		if (fa && fb) {
			px_vec3 x = A.center, y;
			int i;
			for (i = 0; i < 16; i++) {
				y = px_obb_closest_point(&B, x);
				x = px_obb_closest_point(&A, y);
			}
			*out = x;
		} else if (fb) {
			*out = B.center;
		} else if (fa) {
			*out = A.center;
		} else {
			*out = px_model_pose(b).t;
		}
		return 1;
	}
	k--;
	if (fb) {
		if (box_seed(&B, k, out))
			return 1;
		k -= 14;
	}
	return fa && box_seed(&A, k, out);
}
