/*
 * px_prim.c - closed-form signed distances of primitives.
 */
#include <math.h>
#include <stdlib.h>

#include "px_prim.h"

static int px_prim_check_shape(const struct px_prim *p);

/* A length in the accepted range (px_prim.h); zero only where zero_ok. */
static int len_ok(double x, int zero_ok)
{
	return (x >= PX_PRIM_MIN_LENGTH && x <= PX_PRIM_MAX_LENGTH) ||
	       (zero_ok && x == 0.0);
}

/* The range half of the check (the shape's own rules are below). */
static int prim_range(const struct px_prim *p)
{
	switch (p->type) {
	case PX_PRIM_SPHERE:
		return len_ok(p->a, 0);
	case PX_PRIM_BOX:
		return len_ok(p->a, 0) && len_ok(p->b, 0) && len_ok(p->c, 0);
	case PX_PRIM_CAPSULE:
	case PX_PRIM_CYLINDER:
	case PX_PRIM_TORUS:
		return len_ok(p->a, 0) && len_ok(p->b, 0);
	case PX_PRIM_CONE:
		return len_ok(p->a, 1) && len_ok(p->b, 0) && len_ok(p->c, 1);
	default:
		return 1;
	}
}

int px_prim_check(const struct px_prim *p)
{
	int rc;
	if (!p)
		return PX_E_INVAL;
	rc = px_prim_check_shape(p);
	if (rc == PX_OK && !prim_range(p))
		rc = PX_E_RANGE;
	return rc;
}

static int px_prim_check_shape(const struct px_prim *p)
{
	switch (p->type) {
	case PX_PRIM_SPHERE:
		if (!isfinite(p->a))
			return PX_E_NAN;
		return p->a > 0.0 ? PX_OK : PX_E_RANGE;
	case PX_PRIM_BOX:
		if (!isfinite(p->a) || !isfinite(p->b) || !isfinite(p->c))
			return PX_E_NAN;
		return (p->a > 0.0 && p->b > 0.0 && p->c > 0.0) ? PX_OK
								 : PX_E_RANGE;
	case PX_PRIM_CAPSULE:
	case PX_PRIM_CYLINDER:
		if (!isfinite(p->a) || !isfinite(p->b))
			return PX_E_NAN;
		return (p->a > 0.0 && p->b > 0.0) ? PX_OK : PX_E_RANGE;
	case PX_PRIM_CONE:
		if (!isfinite(p->a) || !isfinite(p->b) || !isfinite(p->c))
			return PX_E_NAN;
		if (!(p->a >= 0.0 && p->c >= 0.0 && p->b > 0.0) ||
		    !(p->a > 0.0 || p->c > 0.0))
			return PX_E_RANGE;
		return PX_OK;
	case PX_PRIM_TORUS:
		if (!isfinite(p->a) || !isfinite(p->b))
			return PX_E_NAN;
		return (p->b > 0.0 && p->b < p->a) ? PX_OK : PX_E_RANGE;
	case PX_PRIM_HALFSPACE:
		return PX_OK;
	}
	return PX_E_INVAL;
}

/* Meridian frame of q: rho = |q_xy| and the unit radial direction (x
 * axis on the axis itself, where every meridian is equally near). */
static double meridian(px_vec3 q, double *ex, double *ey)
{
	double rho = hypot(q.x, q.y);
	if (rho > 0.0) {
		*ex = q.x / rho;
		*ey = q.y / rho;
	} else {
		*ex = 1.0;
		*ey = 0.0;
	}
	return rho;
}

/* 2D closest point on segment a-b (zero length allowed) to p; returns the
 * squared distance and the parameter t in [0, 1]. */
static double seg2(double px, double pz, double ax, double az, double bx,
		   double bz, double *t, double *qx, double *qz)
{
	double dx = bx - ax, dz = bz - az;
	double l2 = dx * dx + dz * dz, s = 0.0;
	if (l2 > 0.0) {
		s = ((px - ax) * dx + (pz - az) * dz) / l2;
		s = s < 0.0 ? 0.0 : (s > 1.0 ? 1.0 : s);
	}
	*t = s;
	*qx = ax + s * dx;
	*qz = az + s * dz;
	return (px - *qx) * (px - *qx) + (pz - *qz) * (pz - *qz);
}

static void set_signed(struct px_model_result *r, double d, int unsigned_only)
{
	if (d == 0.0)
		d = 0.0; /* no -0 */
	if (unsigned_only && d < 0.0) {
		r->distance = -d;
		r->direction = px_v3_neg(r->direction);
		r->is_signed = 0;
		r->inside = 0;
		return;
	}
	r->distance = d;
	r->is_signed = !unsigned_only;
	r->inside = !unsigned_only && d < 0.0;
}

/*
 * Capped frustum (cylinder when r0 = r1, cone when r1 = 0) in the
 * meridian half-plane: the profile is the trapezoid (0,-h) (r0,-h)
 * (r1,h) (0,h); its edge on the axis is not surface, so the distance is
 * the minimum over the other three edges, negated inside.
 */
static void frustum(double r0, double r1, double h, px_vec3 q,
		    struct px_model_result *r)
{
	double ex, ey, rho = meridian(q, &ex, &ey);
	double P[4][2] = {{0.0, -h}, {r0, -h}, {r1, h}, {0.0, h}};
	double best = INFINITY, bt = 0.0, bx = 0.0, bz = 0.0;
	int be = 0, e, inside;
	double gx, gz, d, nl;

	for (e = 0; e < 3; e++) {
		double t, qx, qz;
		double d2 = seg2(rho, q.z, P[e][0], P[e][1], P[e + 1][0],
				 P[e + 1][1], &t, &qx, &qz);
		if (d2 < best) {
			best = d2;
			be = e;
			bt = t;
			bx = qx;
			bz = qz;
		}
	}
	inside = fabs(q.z) <= h &&
		 rho <= r0 + (r1 - r0) * (q.z + h) / (2.0 * h);
	d = sqrt(best);
	if (d > 0.0) {
		gx = (rho - bx) / d;
		gz = (q.z - bz) / d;
		if (inside) {
			gx = -gx;
			gz = -gz;
		}
	} else if (be == 1) {
		/* outward normal of the side */
		nl = hypot(2.0 * h, r1 - r0);
		gx = 2.0 * h / nl;
		gz = -(r1 - r0) / nl;
	} else {
		gx = 0.0;
		gz = be == 0 ? -1.0 : 1.0;
	}
	r->index = be;
	r->sub = -1;
	r->feature = PX_FEATURE_FACE;
	if (bt <= 0.0 || bt >= 1.0) {
		/* A profile corner: off the axis it is a rim; on the axis it is
		 * the apex of a pointed end, or else a cap centre (a face). */
		double cx = bt <= 0.0 ? P[be][0] : P[be + 1][0];
		if (cx > 0.0)
			r->feature = PX_FEATURE_EDGE;
		else if ((bz < 0.0 ? r0 : r1) == 0.0)
			r->feature = PX_FEATURE_VERTEX;
	}
	r->point = px_v3(bx * ex, bx * ey, bz);
	r->direction = px_v3(gx * ex, gx * ey, gz);
	r->u = atan2(ey, ex);
	r->v = bz;
	d = inside ? -d : d;
	r->distance = d;
}

int px_prim_closest(const struct px_prim *p, px_vec3 q, int unsigned_only,
		    struct px_model_result *r)
{
	double d;

	if (!p || !r || px_prim_check(p) != PX_OK)
		return PX_E_INVAL;
	r->sub = -1;
	r->feature = PX_FEATURE_FACE;
	r->index = 0;
	r->u = r->v = 0.0;
	r->iterations = 1;
	r->certified = 1;
	r->gap = 0.0;

	switch (p->type) {
	case PX_PRIM_SPHERE: {
		double n = px_v3_norm(q);
		px_vec3 dir = n > 0.0 ? px_v3_scale(q, 1.0 / n) : px_v3(0, 0, 1);
		r->direction = dir;
		r->point = px_v3_scale(dir, p->a);
		r->u = atan2(dir.y, dir.x);
		r->v = acos(fmax(-1.0, fmin(1.0, dir.z)));
		d = n - p->a;
		break;
	}
	case PX_PRIM_BOX: {
		double h[3] = {p->a, p->b, p->c};
		double x[3] = {q.x, q.y, q.z}, c[3], g[3] = {0, 0, 0};
		int i, nout = 0, k = 0;
		double worst = -INFINITY;
		for (i = 0; i < 3; i++) {
			double o = fabs(x[i]) - h[i];
			c[i] = fmax(-h[i], fmin(h[i], x[i]));
			if (o > 0.0)
				nout++;
			if (o > worst) {
				worst = o;
				k = i;
			}
		}
		if (nout > 0) {
			px_vec3 cp = px_v3(c[0], c[1], c[2]);
			px_vec3 v = px_v3_sub(q, cp);
			d = px_v3_norm(v);
			r->direction = px_v3_scale(v, 1.0 / d);
			r->point = cp;
			r->feature = nout == 1 ? PX_FEATURE_FACE
					       : (nout == 2 ? PX_FEATURE_EDGE
							    : PX_FEATURE_VERTEX);
		} else {
			/* inside: the nearest face (largest o = -depth) */
			double s = x[k] < 0.0 ? -1.0 : 1.0;
			c[k] = s * h[k];
			g[k] = s;
			r->point = px_v3(c[0], c[1], c[2]);
			r->direction = px_v3(g[0], g[1], g[2]);
			d = worst; /* <= 0 */
		}
		r->index = 2 * k + (x[k] < 0.0 ? 0 : 1);
		r->u = c[k == 0 ? 1 : 0];
		r->v = c[k == 2 ? 1 : 2];
		break;
	}
	case PX_PRIM_CAPSULE: {
		double z = fmax(-p->b, fmin(p->b, q.z));
		px_vec3 c = px_v3(0.0, 0.0, z), v = px_v3_sub(q, c);
		double n = px_v3_norm(v);
		px_vec3 dir = n > 0.0 ? px_v3_scale(v, 1.0 / n) : px_v3(1, 0, 0);
		r->direction = dir;
		r->point = px_v3_madd(c, dir, p->a);
		r->index = q.z < -p->b ? 1 : (q.z > p->b ? 2 : 0);
		r->u = atan2(dir.y, dir.x);
		r->v = r->point.z;
		d = n - p->a;
		break;
	}
	case PX_PRIM_CYLINDER:
		frustum(p->a, p->a, p->b, q, r);
		d = r->distance;
		break;
	case PX_PRIM_CONE:
		frustum(p->a, p->c, p->b, q, r);
		d = r->distance;
		break;
	case PX_PRIM_TORUS: {
		double ex, ey, rho = meridian(q, &ex, &ey);
		double vx = rho - p->a, vz = q.z, n = hypot(vx, vz);
		double gx = n > 0.0 ? vx / n : 1.0, gz = n > 0.0 ? vz / n : 0.0;
		double rx = p->a + p->b * gx, pz = p->b * gz;
		r->point = px_v3(rx * ex, rx * ey, pz);
		r->direction = px_v3(gx * ex, gx * ey, gz);
		r->u = atan2(ey, ex);
		r->v = atan2(gz, gx);
		d = n - p->b;
		break;
	}
	case PX_PRIM_HALFSPACE:
		r->point = px_v3(q.x, q.y, 0.0);
		r->direction = px_v3(0.0, 0.0, 1.0);
		r->u = q.x;
		r->v = q.y;
		d = q.z;
		break;
	default:
		return PX_E_INVAL;
	}
	set_signed(r, d, unsigned_only);
	return PX_OK;
}

px_aabb px_prim_aabb(const struct px_prim *p)
{
	px_aabb b;
	double e;

	if (!p || px_prim_check(p) != PX_OK)
		return px_aabb_empty();
	switch (p->type) {
	case PX_PRIM_SPHERE:
		b.max = px_v3(p->a, p->a, p->a);
		break;
	case PX_PRIM_BOX:
		b.max = px_v3(p->a, p->b, p->c);
		break;
	case PX_PRIM_CAPSULE:
		b.max = px_v3(p->a, p->a, p->b + p->a);
		break;
	case PX_PRIM_CYLINDER:
		b.max = px_v3(p->a, p->a, p->b);
		break;
	case PX_PRIM_CONE:
		e = fmax(p->a, p->c);
		b.max = px_v3(e, e, p->b);
		break;
	case PX_PRIM_TORUS:
		e = p->a + p->b;
		b.max = px_v3(e, e, p->b);
		break;
	case PX_PRIM_HALFSPACE:
	default:
		b.min = px_v3(-INFINITY, -INFINITY, -INFINITY);
		b.max = px_v3(INFINITY, INFINITY, 0.0);
		return b;
	}
	b.min = px_v3_neg(b.max);
	return b;
}

/* ---- model ops ---------------------------------------------------------- */

static int prim_closest(const void *impl, const struct px_model_query *q,
			struct px_model_result *r)
{
	int rc = px_prim_closest(impl, q->p,
				 (q->flags & PX_QUERY_UNSIGNED) != 0, r);
	if (rc != PX_OK)
		return rc;
	return fabs(r->distance) <= q->max_dist ? 1 : 0;
}

static px_aabb prim_aabb(const void *impl)
{
	return px_prim_aabb(impl);
}

static size_t prim_bytes(const void *impl)
{
	(void)impl;
	return sizeof(struct px_prim);
}

static void prim_free(void *impl)
{
	free(impl);
}

static px_vec3 unit_or_x(double x, double y, double z)
{
	double n = sqrt(x * x + y * y + z * z);
	return n > 0.0 ? px_v3(x / n, y / n, z / n) : px_v3(1.0, 0.0, 0.0);
}

static double sgn(double x)
{
	return x < 0.0 ? -1.0 : 1.0;
}

/* Support points of the convex primitives (GJK). */
static px_vec3 prim_support(const void *impl, px_vec3 d)
{
	const struct px_prim *p = impl;
	double rho = hypot(d.x, d.y), ux = rho > 0 ? d.x / rho : 1.0,
	       uy = rho > 0 ? d.y / rho : 0.0;
	switch (p->type) {
	case PX_PRIM_SPHERE:
		return px_v3_scale(unit_or_x(d.x, d.y, d.z), p->a);
	case PX_PRIM_BOX:
		return px_v3(sgn(d.x) * p->a, sgn(d.y) * p->b, sgn(d.z) * p->c);
	case PX_PRIM_CAPSULE:
		return px_v3_add(px_v3(0, 0, sgn(d.z) * p->b),
				 px_v3_scale(unit_or_x(d.x, d.y, d.z), p->a));
	case PX_PRIM_CYLINDER:
		return px_v3(p->a * ux, p->a * uy, sgn(d.z) * p->b);
	case PX_PRIM_CONE: {
		/* the farther of the two rims (a rim of radius 0 is the apex) */
		double s0 = p->a * rho - p->b * d.z, s1 = p->c * rho + p->b * d.z;
		return s0 > s1 ? px_v3(p->a * ux, p->a * uy, -p->b)
			       : px_v3(p->c * ux, p->c * uy, p->b);
	}
	default:
		return px_v3(0, 0, 0);
	}
}

static const struct px_model_ops prim_ops = {
	.name = "primitive", .kind = PX_MODEL_PRIMITIVE, .closest = prim_closest,
	.aabb = prim_aabb, .memory_bytes = prim_bytes, .free = prim_free,
	.support = prim_support};

/* Torus and half-space have no support function (not convex, or not
 * bounded). */
static const struct px_model_ops prim_ops_nosupport = {
	.name = "primitive", .kind = PX_MODEL_PRIMITIVE, .closest = prim_closest,
	.aabb = prim_aabb, .memory_bytes = prim_bytes, .free = prim_free};

int px_prim_get(const struct px_model *m, struct px_prim *out)
{
	const struct px_model_ops *o = px_model_get_ops(m);
	if (!out || (o != &prim_ops && o != &prim_ops_nosupport))
		return PX_E_INVAL;
	*out = *(const struct px_prim *)px_model_impl(m);
	return PX_OK;
}

int px_prim_model(const struct px_prim *p, struct px_model **out)
{
	struct px_prim *copy;
	int rc;

	if (out)
		*out = NULL;
	if (!out)
		return PX_E_INVAL;
	rc = px_prim_check(p);
	if (rc != PX_OK)
		return rc;
	copy = malloc(sizeof(*copy));
	if (!copy)
		return PX_E_NOMEM;
	*copy = *p;
	return px_model_create(p->type == PX_PRIM_TORUS || p->type == PX_PRIM_HALFSPACE
				       ? &prim_ops_nosupport : &prim_ops,
			       copy,
			       PX_MODEL_CAP_SIGNED | PX_MODEL_CAP_EXACT |
				       (p->type != PX_PRIM_TORUS ? PX_MODEL_CAP_CONVEX : 0u),
			       out);
}
