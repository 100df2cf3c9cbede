/*
 * px_pair_prim.c - closed-form model pairs: capsule/capsule and
 * capsule/box (see pair_internal.h). A capsule is the set of points
 * within its radius of its axis segment, so its distance to another
 * model is the axis segment's distance minus the radius; against a
 * capsule or a box the segment's distance has a closed form.
 */
#include <math.h>
#include <stddef.h>

#include "mesh_internal.h"
#include "pair_internal.h"
#include "px_mesh.h"
#include "px_prim.h"

static double clamp01(double x)
{
	return x < 0.0 ? 0.0 : (x > 1.0 ? 1.0 : x);
}

/* Parameter on segment a + u d (u in [0, 1]) nearest to x. */
static double seg_param(px_vec3 a, px_vec3 d, px_vec3 x)
{
	double dd = px_v3_norm2(d);
	return dd > 0.0 ? clamp01(px_v3_dot(px_v3_sub(x, a), d) / dd) : 0.0;
}

double px__seg_seg(px_vec3 p0, px_vec3 p1, px_vec3 q0, px_vec3 q1, double *s,
		   double *t)
{
	px_vec3 dp = px_v3_sub(p1, p0), dq = px_v3_sub(q1, q0), r = px_v3_sub(p0, q0);
	/* candidates: the interior stationary point, and on each of the four
	 * sides of the parameter square the best point of the other segment;
	 * the squared distance is convex, so its minimum over the square is
	 * among them (parallel segments have no unique interior point, but
	 * their minimum set reaches a side). Each candidate is measured, so
	 * a poorly conditioned interior solve can only lose. */
	double cs[5], ct[5], best = INFINITY;
	double a = px_v3_norm2(dp), e = px_v3_norm2(dq), b = px_v3_dot(dp, dq);
	double den = a * e - b * b;
	int n = 0, k;

	{
		/* tiny, huge or far out: the same at p0 scaled to a unit
		 * extent (den is a product of four differences) */
		px_vec3 P[4] = {p0, p1, q0, q1};
		double sc;
		int ex;
		if (px__pair_frame(P, 4, p0, &sc, &ex))
			return ldexp(px__seg_seg(px_v3(0, 0, 0), px_v3_scale(dp, sc),
						 px_v3_scale(px_v3_sub(q0, p0), sc),
						 px_v3_scale(px_v3_sub(q1, p0), sc), s, t),
				     2 * ex);
	}

	if (a > 0.0 && e > 0.0) {
		/* by Lagrange's identity s = (b f - c e) / den = n . (dq x r) /
		 * |n|^2, n = dp x dq (f = dq . r, c = dp . r): with n to one
		 * rounding (for nearly parallel segments the plain n tilts by
		 * u / sin(angle) and den cancels to u / sin^2) s errs only
		 * along the valley, where the distance barely moves */
		px_vec3 nv = den >= a * e * (1.0 / 64.0) ? px_v3_cross(dp, dq) : px__cross_acc(dp, dq);
		double nn = px_v3_norm2(nv);
		double si = px_v3_dot(nv, px_v3_cross(dq, r)) / nn;
		/* t as the best for that s (not from its own formula): errors
		 * of the two that do not match would leave the valley, by up to
		 * u |r| / sin(angle) */
		double ti = clamp01((px_v3_dot(dq, r) + b * si) / e);
		/* (parallel: nn = 0, a NaN parameter fails the test) */
		if (si >= 0.0 && si <= 1.0) {
			cs[n] = si;
			ct[n++] = ti;
		}
	}
	cs[n] = 0.0;
	ct[n++] = seg_param(q0, dq, p0);
	cs[n] = 1.0;
	ct[n++] = seg_param(q0, dq, p1);
	ct[n] = 0.0;
	cs[n++] = seg_param(p0, dp, q0);
	ct[n] = 1.0;
	cs[n++] = seg_param(p0, dp, q1);
	*s = *t = 0.0;
	for (k = 0; k < n; k++) {
		/* from the differences: no absolute coordinate's rounding */
		double d2 = px_v3_norm2(px_v3_sub(px_v3_madd(r, dp, cs[k]), px_v3_scale(dq, ct[k])));
		if (d2 < best) {
			best = d2;
			*s = cs[k];
			*t = ct[k];
		}
	}
	return best;
}

/* Squared distance of x to the box |x_k| <= h[k]. */
static double box_d2(const double x[3], const double h[3])
{
	double s = 0.0;
	int k;
	for (k = 0; k < 3; k++) {
		double g = fabs(x[k]) - h[k];
		if (g > 0.0)
			s += g * g;
	}
	return s;
}

double px__seg_box(px_vec3 p0, px_vec3 p1, const double h[3], double *t,
		   px_vec3 *q)
{
	double P[3] = {p0.x, p0.y, p0.z}, D[3] = {p1.x - p0.x, p1.y - p0.y, p1.z - p0.z};
	double br[8], best = INFINITY, x[3];
	int nb = 0, i, j, k;

	br[nb++] = 0.0;
	br[nb++] = 1.0;
	for (k = 0; k < 3; k++) {
		int sg;
		if (D[k] == 0.0)
			continue;
		for (sg = -1; sg <= 1; sg += 2) {
			double u = (sg * h[k] - P[k]) / D[k];
			if (u > 0.0 && u < 1.0)
				br[nb++] = u;
		}
	}
	for (i = 1; i < nb; i++) { /* at most 8: insertion */
		double v = br[i];
		for (j = i; j > 0 && br[j - 1] > v; j--)
			br[j] = br[j - 1];
		br[j] = v;
	}
	*t = 0.0;
	for (i = 0; i + 1 < nb; i++) {
		/* on this piece each axis is either within its slab or beyond
		 * one face for the whole piece: a quadratic with a closed-form
		 * minimiser, clamped to the piece */
		double ta = br[i], tb = br[i + 1], tm = 0.5 * (ta + tb), num = 0.0, dd = 0.0, u;
		for (k = 0; k < 3; k++) {
			double xm = P[k] + tm * D[k], tgt;
			if (xm > h[k])
				tgt = h[k];
			else if (xm < -h[k])
				tgt = -h[k];
			else
				continue;
			num += (P[k] - tgt) * D[k];
			dd += D[k] * D[k];
		}
		u = dd > 0.0 ? -num / dd : ta;
		u = u < ta ? ta : (u > tb ? tb : u);
		for (k = 0; k < 3; k++)
			x[k] = P[k] + u * D[k];
		{
			double d2 = box_d2(x, h);
			if (d2 < best) {
				best = d2;
				*t = u;
			}
		}
	}
	for (k = 0; k < 3; k++) {
		double v = P[k] + *t * D[k];
		x[k] = v > h[k] ? h[k] : (v < -h[k] ? -h[k] : v);
	}
	*q = px_v3(x[0], x[1], x[2]);
	return best;
}

double px__seg_tri(px_vec3 p0, px_vec3 p1, const px_vec3 v[3], double *s,
		   px_vec3 *q)
{
	px_vec3 d = px_v3_sub(p1, p0), n, x;
	double best, d2, hs0, hs1;
	int k;

	{
		/* tiny, huge or far out: the same at p0 scaled to a unit
		 * extent (the plane test is a product of three differences) */
		px_vec3 P[5] = {p0, p1, v[0], v[1], v[2]}, w[3];
		double sc;
		int ex;
		if (px__pair_frame(P, 5, p0, &sc, &ex)) {
			for (k = 0; k < 3; k++)
				w[k] = px_v3_scale(px_v3_sub(v[k], p0), sc);
			d2 = px__seg_tri(px_v3(0, 0, 0), px_v3_scale(d, sc), w, s, &x);
			*q = px_v3_madd(p0, x, 1.0 / sc);
			return ldexp(d2, 2 * ex);
		}
	}

	/* the end points */
	best = px_tri_closest(p0, v[0], v[1], v[2], q, NULL, NULL, NULL, NULL);
	*s = 0.0;
	d2 = px_tri_closest(p1, v[0], v[1], v[2], &x, NULL, NULL, NULL, NULL);
	if (d2 < best) {
		best = d2;
		*s = 1.0;
		*q = x;
	}
	/* the crossing of the plane (a segment through the triangle meets
	 * it there, at distance zero) */
	n = px_v3_cross(px_v3_sub(v[1], v[0]), px_v3_sub(v[2], v[0]));
	hs0 = px_v3_dot(n, px_v3_sub(p0, v[0]));
	hs1 = px_v3_dot(n, px_v3_sub(p1, v[0]));
	if ((hs0 < 0.0) != (hs1 < 0.0) && hs0 != hs1) {
		double u = hs0 / (hs0 - hs1);
		px_vec3 c = px_v3_madd(p0, d, u);
		d2 = px_tri_closest(c, v[0], v[1], v[2], &x, NULL, NULL, NULL, NULL);
		if (d2 < best) {
			best = d2;
			*s = u;
			*q = x;
		}
	}
	/* the edges */
	for (k = 0; k < 3; k++) {
		double a, b;
		px_vec3 e0 = v[k], e1 = v[(k + 1) % 3];
		d2 = px__seg_seg(p0, p1, e0, e1, &a, &b);
		if (d2 < best) {
			best = d2;
			*s = a;
			*q = px_v3_lerp(e0, e1, b);
		}
	}
	return best;
}

/* World-frame axis segment of a capsule model. */
static void capsule_axis(const struct px_model *m, const struct px_prim *c,
			 px_vec3 *e0, px_vec3 *e1)
{
	px_pose P = px_model_pose(m);
	*e0 = px_pose_transform_point(P, px_v3(0, 0, -c->b));
	*e1 = px_pose_transform_point(P, px_v3(0, 0, c->b));
}

int px__capsule_axis(const struct px_model *m, px_vec3 *e0, px_vec3 *e1,
		     double *radius)
{
	struct px_prim c;
	if (px_prim_get(m, &c) != PX_OK || c.type != PX_PRIM_CAPSULE)
		return 0;
	capsule_axis(m, &c, e0, e1);
	*radius = c.a;
	return 1;
}

/* Fill res from the closest points ca (A's core) and cb (B's core) with
 * the radii ra, rb around them and the unit direction from A towards B:
 * cb - ca normalised, or n when use_n (cores that touch, where that
 * difference is rounding, or where n is known better). */
static void fill(struct px_pair_result *res, px_vec3 ca, px_vec3 cb, double ra,
		 double rb, px_vec3 n, int use_n)
{
	double dc = px_v3_dist(ca, cb), d;
	if (!use_n && dc > 0.0)
		n = px_v3_scale(px_v3_sub(cb, ca), 1.0 / dc);
	d = dc - ra - rb;
	res->point_a = px_v3_madd(ca, n, ra);
	res->point_b = px_v3_madd(cb, n, -rb);
	res->distance = d;
	res->intersecting = d <= 0.0;
	if (d < 0.0) {
		/* moving B by -d along n separates: the witnesses are the
		 * points of each surface deepest in the other, and
		 * point_a - point_b = -d n */
		res->depth = -d;
		res->normal = n;
	}
	res->iterations = 1;
	res->starts = 0;
	res->converged = 1;
	res->local_only = 0;
}

/* Feature index of model m at its surface point x (primitive face id). */
static int face_at(const struct px_model *m, px_vec3 x, int *index)
{
	struct px_model_result q;
	int rc = px_model_query(m, x, &q);
	if (rc < 0)
		return rc;
	*index = q.index;
	return 0;
}

/* x = u x w normalised: the unit vector perpendicular to the segments'
 * directions u, w (cores that cross: the pair leaves along it), else any
 * perpendicular of u. */
static px_vec3 cross_dir(px_vec3 x, px_vec3 u)
{
	px_vec3 n, out;
	if (px_v3_normalize(x, px_v3(0, 0, 0), &out) == PX_OK)
		return out;
	n = px_v3_cross(u, fabs(u.x) < 0.9 ? px_v3(1, 0, 0) : px_v3(0, 1, 0));
	if (px_v3_normalize(n, px_v3(0, 0, 1), &out) != PX_OK)
		out = px_v3(0, 0, 1);
	return out;
}

int px__pair_closed(const struct px_model *a, const struct px_model *b,
		    struct px_pair_result *res)
{
	struct px_prim pa, pb;
	px_vec3 a0, a1;
	int swap = 0;

	if (px_prim_get(a, &pa) != PX_OK || px_prim_get(b, &pb) != PX_OK)
		return 0;
	if (pa.type != PX_PRIM_CAPSULE && pb.type == PX_PRIM_CAPSULE) {
		/* the capsule first; witnesses and normal swapped at the end */
		const struct px_model *m = a;
		struct px_prim x = pa;
		a = b;
		b = m;
		pa = pb;
		pb = x;
		swap = 1;
	}
	if (pa.type != PX_PRIM_CAPSULE ||
	    (pb.type != PX_PRIM_CAPSULE && pb.type != PX_PRIM_BOX))
		return 0;
	capsule_axis(a, &pa, &a0, &a1);
	if (pb.type == PX_PRIM_CAPSULE) {
		px_vec3 b0, b1;
		double s, t;
		px_vec3 u, w, ca, cb, n, x;
		double scale;
		int interior;
		capsule_axis(b, &pb, &b0, &b1);
		px__seg_seg(a0, a1, b0, b1, &s, &t);
		u = px_v3_sub(a1, a0);
		w = px_v3_sub(b1, b0);
		ca = px_v3_lerp(a0, a1, s);
		cb = px_v3_lerp(b0, b1, t);
		scale = pa.a + pb.a + px_v3_norm(u) + px_v3_norm(w);
		/* closest points inside both axes of crossing directions: the
		 * core difference is along u x w in exact arithmetic, and that
		 * direction is the accurate one (the difference itself is all
		 * rounding when the axes nearly meet); axes that meet: the
		 * flat Minkowski difference of the segments holds the origin
		 * and the pair leaves along its normal after ra + rb */
		x = px_v3_cross(u, w);
		n = cross_dir(x, u);
		interior = s > 0.0 && s < 1.0 && t > 0.0 && t < 1.0 &&
			   px_v3_norm(x) > 1e-9 * px_v3_norm(u) * px_v3_norm(w);
		if (px_v3_dot(n, px_v3_sub(cb, ca)) < 0.0)
			n = px_v3_neg(n);
		fill(res, ca, cb, pa.a, pb.a, n,
		     interior || px_v3_dist(ca, cb) <= 1e-12 * scale);
	} else {
		px_pose P = px_model_pose(b);
		double h[3] = {pb.a, pb.b, pb.c}, t, d2, sc = pa.a + pa.b + h[0] + h[1] + h[2];
		px_vec3 q;
		d2 = px__seg_box(px_pose_inverse_transform_point(P, a0),
				 px_pose_inverse_transform_point(P, a1), h, &t, &q);
		/* the axis meets the box (or is within rounding of it, where
		 * the direction is lost): EPA measures the depth */
		if (!(d2 > 1e-24 * sc * sc))
			return 0;
		fill(res, px_v3_lerp(a0, a1, t), px_pose_transform_point(P, q), pa.a, 0.0,
		     px_v3(0, 0, 1), 0);
	}
	if (swap) {
		px_vec3 x = res->point_a;
		const struct px_model *m = a;
		res->point_a = res->point_b;
		res->point_b = x;
		if (res->depth > 0.0)
			res->normal = px_v3_neg(res->normal);
		a = b;
		b = m;
	}
	{
		int rc = face_at(a, res->point_a, &res->index_a);
		if (rc < 0 || (rc = face_at(b, res->point_b, &res->index_b)) < 0)
			return rc;
	}
	return 1;
}
