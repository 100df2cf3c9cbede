/*
 * px_math.c - the non-inline part of the math core: normalisation with
 * explicit fallbacks, quaternion conversions, boxes.
 *
 * Numerical notes (the failure cases each choice avoids):
 *  - norms are taken after dividing by the largest component, so vectors
 *    of size 1e-310 (denormal) or 1e300 neither underflow to zero nor
 *    overflow to infinity when squared;
 *  - angles come from atan2(|sin|, |cos|) rather than acos(dot), which
 *    loses half the digits near 0 and pi;
 *  - the rotation between two directions takes its axis from a x (b + a)
 *    when they are nearly opposite (a x (b - a) when nearly equal): the
 *    small sum is exact, so the axis stays accurate to rounding up to the
 *    exactly opposite case;
 *  - the matrix to quaternion conversion is Shepperd's: it divides by the
 *    largest of 4w^2, 4x^2, 4y^2, 4z^2 (at least 1 for a rotation), never
 *    by a w that vanishes near 180 degrees.
 */
#include <float.h>
#include <stddef.h>

#include "px_math.h"

/* Angles below this use normalized lerp: its deviation from the great
 * arc is O(angle^3), far below rounding. */
#define PX__SLERP_LERP_ANGLE 1e-6
/* Relative slack of the box overlap test (see px_obb_overlap). */
#define PX__SAT_REL_EPS 1e-12

static double px__max3(double a, double b, double c)
{
	return fmax(a, fmax(b, c));
}

static double px__clamp(double v, double lo, double hi)
{
	return v < lo ? lo : (v > hi ? hi : v);
}

/* ---- vec3 ------------------------------------------------------------- */

PX_API int px_v3_normalize(px_vec3 a, px_vec3 fallback, px_vec3 *out)
{
	double m, n;
	px_vec3 s;

	if (!px_v3_isfinite(a)) {
		*out = fallback;
		return PX_E_NAN;
	}
	m = px__max3(fabs(a.x), fabs(a.y), fabs(a.z));
	if (m == 0.0) {
		*out = fallback;
		return PX_E_DEGENERATE;
	}
	s = px_v3_scale(a, 1.0 / m);
	/* 1/m overflows for m below ~1e-308 (denormal); divide instead. */
	if (!px_v3_isfinite(s))
		s = px_v3(a.x / m, a.y / m, a.z / m);
	n = px_v3_norm(s); /* in [1, sqrt(3)] */
	*out = px_v3_scale(s, 1.0 / n);
	return PX_OK;
}

PX_API px_vec3 px_v3_any_perp(px_vec3 a)
{
	double ax = fabs(a.x), ay = fabs(a.y), az = fabs(a.z);
	px_vec3 p, r;

	/* Cross with the basis axis least aligned with a: its norm is at
	 * least sqrt(2/3) |a|, so the direction is well conditioned. */
	if (ax <= ay && ax <= az)
		p = px_v3(0.0, -a.z, a.y); /* e_x x a */
	else if (ay <= az)
		p = px_v3(a.z, 0.0, -a.x); /* e_y x a */
	else
		p = px_v3(-a.y, a.x, 0.0); /* e_z x a */
	(void)px_v3_normalize(p, px_v3(0.0, 1.0, 0.0), &r);
	return r;
}

/* ---- quaternion ------------------------------------------------------- */

static int px__quat_isfinite(px_quat q)
{
	return isfinite(q.w) && isfinite(q.x) && isfinite(q.y) &&
	       isfinite(q.z);
}

static px_quat px__quat_scale(px_quat q, double s)
{
	px_quat r = {q.w * s, q.x * s, q.y * s, q.z * s};
	return r;
}

static px_quat px__quat_neg(px_quat q)
{
	return px__quat_scale(q, -1.0);
}

PX_API int px_quat_normalize(px_quat q, px_quat *out)
{
	double m, n;
	px_quat s;

	if (!px__quat_isfinite(q)) {
		*out = px_quat_identity();
		return PX_E_NAN;
	}
	m = fmax(fmax(fabs(q.w), fabs(q.x)), fmax(fabs(q.y), fabs(q.z)));
	if (m == 0.0) {
		*out = px_quat_identity();
		return PX_E_DEGENERATE;
	}
	s.w = q.w / m;
	s.x = q.x / m;
	s.y = q.y / m;
	s.z = q.z / m;
	n = sqrt(px_quat_dot(s, s)); /* in [1, 2] */
	*out = px__quat_scale(s, 1.0 / n);
	return PX_OK;
}

/* The rotation by angle_rad about the unit axis u. */
static px_quat quat_about_unit(px_vec3 u, double angle_rad)
{
	double h = 0.5 * angle_rad, s = sin(h);
	px_quat q;
	q.w = cos(h);
	q.x = s * u.x;
	q.y = s * u.y;
	q.z = s * u.z;
	return q;
}

PX_API int px_quat_from_axis_angle(px_vec3 axis, double angle_rad,
				   px_quat *out)
{
	px_vec3 u;
	int rc;

	if (!isfinite(angle_rad)) {
		*out = px_quat_identity();
		return PX_E_NAN;
	}
	rc = px_v3_normalize(axis, px_v3(1.0, 0.0, 0.0), &u);
	if (rc < 0) {
		*out = px_quat_identity();
		return rc;
	}
	*out = quat_about_unit(u, angle_rad);
	return PX_OK;
}

PX_API void px_quat_to_axis_angle(px_quat q, px_vec3 *axis, double *angle_rad)
{
	px_vec3 v, u;
	double s, w;

	if (!px__quat_isfinite(q)) {
		if (axis)
			*axis = px_v3(1.0, 0.0, 0.0);
		if (angle_rad)
			*angle_rad = 0.0;
		return;
	}
	/* q and -q are the same rotation; w >= 0 picks the angle <= pi. */
	if (q.w < 0.0)
		q = px__quat_neg(q);
	v = px_v3(q.x, q.y, q.z);
	w = q.w;
	if (px_v3_normalize(v, px_v3(1.0, 0.0, 0.0), &u) < 0) {
		s = 0.0;
	} else {
		/* |v| without overflow or underflow: u is unit. */
		s = px_v3_dot(v, u);
	}
	if (axis)
		*axis = u;
	if (angle_rad)
		*angle_rad = (s == 0.0 && w == 0.0) ? 0.0 : 2.0 * atan2(s, w);
}

PX_API int px_quat_from_two_vectors(px_vec3 a, px_vec3 b, px_quat *out)
{
	px_vec3 ua, ub, k, uk;
	double c, s;
	int ra, rb;

	ra = px_v3_normalize(a, px_v3(1.0, 0.0, 0.0), &ua);
	rb = px_v3_normalize(b, px_v3(1.0, 0.0, 0.0), &ub);
	if (ra < 0 || rb < 0) {
		*out = px_quat_identity();
		return (ra == PX_E_NAN || rb == PX_E_NAN) ? PX_E_NAN
							    : PX_E_DEGENERATE;
	}
	c = px_v3_dot(ua, ub);
	/* Axis ua x ub, computed as ua x (ub -+ ua): the difference (or the
	 * sum, for nearly opposite vectors) is small and exact, so the
	 * cross product keeps full relative precision instead of being the
	 * rounding residue of two products near 1. The half-vector formula
	 * q ~ (ua . (ua + ub), ua x (ua + ub)) would not do: a 1-ulp length
	 * mismatch of ua and ub tilts ua + ub by ulp / |ua + ub|. */
	k = px_v3_cross(ua, c >= 0.0 ? px_v3_sub(ub, ua) : px_v3_add(ub, ua));
	if (px_v3_normalize(k, px_v3(0.0, 0.0, 0.0), &uk) < 0) {
		if (c >= 0.0) {
			*out = px_quat_identity();
		} else {
			/* exactly opposite: half turn about any
			 * perpendicular */
			uk = px_v3_any_perp(ua);
			out->w = 0.0;
			out->x = uk.x;
			out->y = uk.y;
			out->z = uk.z;
		}
		return PX_OK;
	}
	s = px_v3_dot(k, uk); /* |k| = sin(angle), without underflow */
	*out = quat_about_unit(uk, atan2(s, c));
	return PX_OK;
}

PX_API px_mat3 px_quat_to_mat3(px_quat q)
{
	px_mat3 r;
	double n2, s;
	double xx, yy, zz, xy, xz, yz, wx, wy, wz;

	/* 2 / |q|^2 instead of 2 makes any nonzero q give a rotation. */
	if (px_quat_normalize(q, &q) < 0)
		q = px_quat_identity();
	n2 = px_quat_dot(q, q);
	s = 2.0 / n2;
	xx = s * q.x * q.x;
	yy = s * q.y * q.y;
	zz = s * q.z * q.z;
	xy = s * q.x * q.y;
	xz = s * q.x * q.z;
	yz = s * q.y * q.z;
	wx = s * q.w * q.x;
	wy = s * q.w * q.y;
	wz = s * q.w * q.z;
	r.m[0][0] = 1.0 - (yy + zz);
	r.m[0][1] = xy - wz;
	r.m[0][2] = xz + wy;
	r.m[1][0] = xy + wz;
	r.m[1][1] = 1.0 - (xx + zz);
	r.m[1][2] = yz - wx;
	r.m[2][0] = xz - wy;
	r.m[2][1] = yz + wx;
	r.m[2][2] = 1.0 - (xx + yy);
	return r;
}

static int px__mat3_isfinite(const px_mat3 *m)
{
	int i, j;
	for (i = 0; i < 3; i++)
		for (j = 0; j < 3; j++)
			if (!isfinite(m->m[i][j]))
				return 0;
	return 1;
}

PX_API px_quat px_quat_from_mat3(const px_mat3 *m)
{
	const double(*a)[3] = m->m;
	double tr, r, s;
	px_quat q;

	if (!px__mat3_isfinite(m))
		return px_quat_identity();
	tr = a[0][0] + a[1][1] + a[2][2];
	/* 4w^2 = 1 + tr and 4x^2 = 1 + 2 m00 - tr (likewise y, z): the
	 * largest of tr, m00, m11, m22 picks the largest component, whose
	 * square is at least 1/4 for a rotation. */
	if (tr >= a[0][0] && tr >= a[1][1] && tr >= a[2][2]) {
		r = sqrt(fmax(1.0 + tr, 0.0));
		s = r > 0.0 ? 0.5 / r : 0.0;
		q.w = 0.5 * r;
		q.x = (a[2][1] - a[1][2]) * s;
		q.y = (a[0][2] - a[2][0]) * s;
		q.z = (a[1][0] - a[0][1]) * s;
	} else if (a[0][0] >= a[1][1] && a[0][0] >= a[2][2]) {
		r = sqrt(fmax(1.0 + a[0][0] - a[1][1] - a[2][2], 0.0));
		s = r > 0.0 ? 0.5 / r : 0.0;
		q.x = 0.5 * r;
		q.w = (a[2][1] - a[1][2]) * s;
		q.y = (a[0][1] + a[1][0]) * s;
		q.z = (a[0][2] + a[2][0]) * s;
	} else if (a[1][1] >= a[2][2]) {
		r = sqrt(fmax(1.0 - a[0][0] + a[1][1] - a[2][2], 0.0));
		s = r > 0.0 ? 0.5 / r : 0.0;
		q.y = 0.5 * r;
		q.w = (a[0][2] - a[2][0]) * s;
		q.x = (a[0][1] + a[1][0]) * s;
		q.z = (a[1][2] + a[2][1]) * s;
	} else {
		r = sqrt(fmax(1.0 - a[0][0] - a[1][1] + a[2][2], 0.0));
		s = r > 0.0 ? 0.5 / r : 0.0;
		q.z = 0.5 * r;
		q.w = (a[1][0] - a[0][1]) * s;
		q.x = (a[0][2] + a[2][0]) * s;
		q.y = (a[1][2] + a[2][1]) * s;
	}
	if (px_quat_normalize(q, &q) < 0)
		return px_quat_identity();
	if (q.w < 0.0)
		q = px__quat_neg(q);
	return q;
}

/* Angle between unit 4-vectors a and b, accurate near 0 and pi/2. */
static double px__quat_arc(px_quat a, px_quat b)
{
	px_quat d = {a.w - b.w, a.x - b.x, a.y - b.y, a.z - b.z};
	px_quat s = {a.w + b.w, a.x + b.x, a.y + b.y, a.z + b.z};
	return 2.0 * atan2(sqrt(px_quat_dot(d, d)), sqrt(px_quat_dot(s, s)));
}

PX_API px_quat px_quat_slerp(px_quat a, px_quat b, double t)
{
	px_quat r;
	double th, sa, sb, st;

	(void)px_quat_normalize(a, &a);
	(void)px_quat_normalize(b, &b);
	if (!isfinite(t))
		return a;
	/* q and -q are the same rotation: take the shorter arc. */
	if (px_quat_dot(a, b) < 0.0)
		b = px__quat_neg(b);
	th = px__quat_arc(a, b); /* in [0, pi/2] */
	if (th < PX__SLERP_LERP_ANGLE) {
		sa = 1.0 - t;
		sb = t;
	} else {
		st = sin(th);
		sa = sin((1.0 - t) * th) / st;
		sb = sin(t * th) / st;
	}
	r.w = sa * a.w + sb * b.w;
	r.x = sa * a.x + sb * b.x;
	r.y = sa * a.y + sb * b.y;
	r.z = sa * a.z + sb * b.z;
	/* Extrapolation far outside [0, 1] with nearly equal inputs can
	 * cancel to zero; fall back to a. */
	if (px_quat_normalize(r, &r) < 0)
		return a;
	return r;
}

PX_API double px_quat_angle_between(px_quat a, px_quat b)
{
	(void)px_quat_normalize(a, &a);
	(void)px_quat_normalize(b, &b);
	if (px_quat_dot(a, b) < 0.0)
		b = px__quat_neg(b);
	/* The relative rotation a* b turns by twice the 4D arc; rounding
	 * of |a - b| ~ |a + b| near a half turn may overshoot pi by an ulp. */
	return fmin(2.0 * px__quat_arc(a, b), M_PI);
}

/* ---- mat3 ------------------------------------------------------------- */

PX_API px_mat3 px_mat3_identity(void)
{
	px_mat3 r = {{{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}}};
	return r;
}

PX_API px_mat3 px_mat3_from_rows(px_vec3 r0, px_vec3 r1, px_vec3 r2)
{
	px_mat3 r = {{{r0.x, r0.y, r0.z}, {r1.x, r1.y, r1.z},
		      {r2.x, r2.y, r2.z}}};
	return r;
}

PX_API px_mat3 px_mat3_from_cols(px_vec3 c0, px_vec3 c1, px_vec3 c2)
{
	px_mat3 r = {{{c0.x, c1.x, c2.x}, {c0.y, c1.y, c2.y},
		      {c0.z, c1.z, c2.z}}};
	return r;
}

PX_API px_vec3 px_mat3_col(const px_mat3 *m, int j)
{
	j = j < 0 ? 0 : (j > 2 ? 2 : j);
	return px_v3(m->m[0][j], m->m[1][j], m->m[2][j]);
}

PX_API px_vec3 px_mat3_mul_v3(const px_mat3 *m, px_vec3 v)
{
	const double(*a)[3] = m->m;
	return px_v3(a[0][0] * v.x + a[0][1] * v.y + a[0][2] * v.z,
		     a[1][0] * v.x + a[1][1] * v.y + a[1][2] * v.z,
		     a[2][0] * v.x + a[2][1] * v.y + a[2][2] * v.z);
}

PX_API px_mat3 px_mat3_mul(const px_mat3 *a, const px_mat3 *b)
{
	px_mat3 r;
	int i, j;
	for (i = 0; i < 3; i++)
		for (j = 0; j < 3; j++)
			r.m[i][j] = a->m[i][0] * b->m[0][j] +
				    a->m[i][1] * b->m[1][j] +
				    a->m[i][2] * b->m[2][j];
	return r;
}

PX_API px_mat3 px_mat3_transpose(const px_mat3 *m)
{
	px_mat3 r;
	int i, j;
	for (i = 0; i < 3; i++)
		for (j = 0; j < 3; j++)
			r.m[i][j] = m->m[j][i];
	return r;
}

PX_API double px_mat3_det(const px_mat3 *m)
{
	const double(*a)[3] = m->m;
	return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
	       a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
	       a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
}

PX_API int px_mat3_is_rotation(const px_mat3 *m, double tol)
{
	px_mat3 mt, p;
	int i, j;

	if (!px__mat3_isfinite(m) || !(tol >= 0.0))
		return 0;
	mt = px_mat3_transpose(m);
	p = px_mat3_mul(&mt, m);
	for (i = 0; i < 3; i++)
		for (j = 0; j < 3; j++)
			if (!(fabs(p.m[i][j] - (i == j ? 1.0 : 0.0)) <= tol))
				return 0;
	return px_mat3_det(m) > 0.0;
}

/* ---- pose ------------------------------------------------------------- */

PX_API int px_pose_sanitize(px_pose *p)
{
	double m, n2;
	px_quat q;

	if (!p)
		return PX_E_INVAL;
	if (!px__quat_isfinite(p->q) || !px_v3_isfinite(p->t)) {
		*p = px_pose_identity();
		return PX_E_NAN;
	}
	if (px_quat_normalize(p->q, &q) < 0) {
		*p = px_pose_identity();
		return PX_E_DEGENERATE;
	}
	/* |q| lies in [m, 2m]: outside [1/4, 2] it cannot be near 1, and
	 * inside, squaring neither overflows nor underflows (a corrupt frame
	 * can carry 1e300 or denormal components). */
	m = fmax(fmax(fabs(p->q.w), fabs(p->q.x)),
		 fmax(fabs(p->q.y), fabs(p->q.z)));
	n2 = (m < 0.25 || m > 2.0) ? 0.0 : px_quat_dot(p->q, p->q);
	if (!(fabs(sqrt(n2) - 1.0) <= 1e-6)) {
		*p = px_pose_identity();
		return PX_E_RANGE;
	}
	p->q = q;
	return PX_OK;
}

PX_API int px_pose_from_mat3_t(const px_mat3 *r, px_vec3 t, px_pose *out)
{
	if (!r || !out)
		return PX_E_INVAL;
	if (!px__mat3_isfinite(r) || !px_v3_isfinite(t)) {
		*out = px_pose_identity();
		return PX_E_NAN;
	}
	if (!px_mat3_is_rotation(r, 1e-6)) {
		*out = px_pose_identity();
		return PX_E_RANGE;
	}
	out->q = px_quat_from_mat3(r);
	out->t = t;
	return PX_OK;
}

/* ---- axis-aligned box ------------------------------------------------- */

PX_API px_aabb px_aabb_empty(void)
{
	px_aabb b = {{INFINITY, INFINITY, INFINITY},
		     {-INFINITY, -INFINITY, -INFINITY}};
	return b;
}

PX_API int px_aabb_is_empty(const px_aabb *b)
{
	/* Written with <= so that a NaN bound also counts as empty. */
	return !(b->min.x <= b->max.x && b->min.y <= b->max.y &&
		 b->min.z <= b->max.z);
}

PX_API void px_aabb_extend(px_aabb *b, px_vec3 p)
{
	if (!px_v3_isfinite(p))
		return;
	b->min = px_v3_min(b->min, p);
	b->max = px_v3_max(b->max, p);
}

PX_API px_aabb px_aabb_from_points(const px_vec3 *pts, size_t n)
{
	px_aabb b = px_aabb_empty();
	size_t i;
	if (!pts)
		return b;
	for (i = 0; i < n; i++)
		px_aabb_extend(&b, pts[i]);
	return b;
}

PX_API px_aabb px_aabb_union(const px_aabb *a, const px_aabb *b)
{
	px_aabb r;
	if (px_aabb_is_empty(a))
		return *b;
	if (px_aabb_is_empty(b))
		return *a;
	r.min = px_v3_min(a->min, b->min);
	r.max = px_v3_max(a->max, b->max);
	return r;
}

PX_API int px_aabb_contains(const px_aabb *b, px_vec3 p)
{
	return p.x >= b->min.x && p.x <= b->max.x && p.y >= b->min.y &&
	       p.y <= b->max.y && p.z >= b->min.z && p.z <= b->max.z;
}

PX_API int px_aabb_overlap(const px_aabb *a, const px_aabb *b)
{
	if (px_aabb_is_empty(a) || px_aabb_is_empty(b))
		return 0;
	return a->min.x <= b->max.x && b->min.x <= a->max.x &&
	       a->min.y <= b->max.y && b->min.y <= a->max.y &&
	       a->min.z <= b->max.z && b->min.z <= a->max.z;
}

/* Distance from v to the interval [lo, hi] (0 inside). */
static double px__gap(double v, double lo, double hi)
{
	return v < lo ? lo - v : (v > hi ? v - hi : 0.0);
}

PX_API double px_aabb_dist2(const px_aabb *b, px_vec3 p)
{
	double dx, dy, dz;
	if (px_aabb_is_empty(b))
		return INFINITY;
	dx = px__gap(p.x, b->min.x, b->max.x);
	dy = px__gap(p.y, b->min.y, b->max.y);
	dz = px__gap(p.z, b->min.z, b->max.z);
	return dx * dx + dy * dy + dz * dz;
}

PX_API double px_aabb_max_dist2(const px_aabb *b, px_vec3 p)
{
	double dx, dy, dz;
	if (px_aabb_is_empty(b))
		return INFINITY;
	dx = fmax(fabs(p.x - b->min.x), fabs(p.x - b->max.x));
	dy = fmax(fabs(p.y - b->min.y), fabs(p.y - b->max.y));
	dz = fmax(fabs(p.z - b->min.z), fabs(p.z - b->max.z));
	return dx * dx + dy * dy + dz * dz;
}

PX_API px_vec3 px_aabb_closest_point(const px_aabb *b, px_vec3 p)
{
	if (px_aabb_is_empty(b))
		return p;
	return px_v3(px__clamp(p.x, b->min.x, b->max.x),
		     px__clamp(p.y, b->min.y, b->max.y),
		     px__clamp(p.z, b->min.z, b->max.z));
}

PX_API px_vec3 px_aabb_center(const px_aabb *b)
{
	if (px_aabb_is_empty(b))
		return px_v3(0.0, 0.0, 0.0);
	/* Halves first: min + max overflows for bounds near DBL_MAX. */
	return px_v3(0.5 * b->min.x + 0.5 * b->max.x,
		     0.5 * b->min.y + 0.5 * b->max.y,
		     0.5 * b->min.z + 0.5 * b->max.z);
}

PX_API px_vec3 px_aabb_half_extents(const px_aabb *b)
{
	if (px_aabb_is_empty(b))
		return px_v3(0.0, 0.0, 0.0);
	return px_v3(0.5 * b->max.x - 0.5 * b->min.x,
		     0.5 * b->max.y - 0.5 * b->min.y,
		     0.5 * b->max.z - 0.5 * b->min.z);
}

PX_API double px_aabb_diagonal(const px_aabb *b)
{
	if (px_aabb_is_empty(b))
		return 0.0;
	return 2.0 * hypot(hypot(0.5 * b->max.x - 0.5 * b->min.x,
				 0.5 * b->max.y - 0.5 * b->min.y),
			   0.5 * b->max.z - 0.5 * b->min.z);
}

/* Rounding slack for boxes built from rotated points: a few ulps of the
 * largest magnitude involved, so that the result encloses the corners as
 * any caller would compute them. */
static double px__round_slack(double scale)
{
	return 16.0 * DBL_EPSILON * scale;
}

PX_API px_aabb px_aabb_transform(const px_aabb *b, px_pose pose)
{
	px_mat3 r;
	px_vec3 c, h, nc, nh;
	px_aabb out;
	double slack;
	int i;

	if (px_aabb_is_empty(b))
		return *b;
	r = px_quat_to_mat3(pose.q);
	c = px_aabb_center(b);
	h = px_aabb_half_extents(b);
	nc = px_pose_transform_point(pose, c);
	/* Arvo: the extent along each world axis is |R| h. */
	for (i = 0; i < 3; i++) {
		double e = fabs(r.m[i][0]) * h.x + fabs(r.m[i][1]) * h.y +
			   fabs(r.m[i][2]) * h.z;
		if (i == 0)
			nh.x = e;
		else if (i == 1)
			nh.y = e;
		else
			nh.z = e;
	}
	slack = px__round_slack(fabs(c.x) + fabs(c.y) + fabs(c.z) + h.x +
				h.y + h.z + fabs(pose.t.x) + fabs(pose.t.y) +
				fabs(pose.t.z));
	nh = px_v3_add(nh, px_v3(slack, slack, slack));
	out.min = px_v3_sub(nc, nh);
	out.max = px_v3_add(nc, nh);
	return out;
}

PX_API px_aabb px_aabb_inflate(const px_aabb *b, double margin)
{
	px_aabb r;
	if (px_aabb_is_empty(b) || !isfinite(margin))
		return *b;
	r.min = px_v3_sub(b->min, px_v3(margin, margin, margin));
	r.max = px_v3_add(b->max, px_v3(margin, margin, margin));
	return r;
}

/* ---- oriented box ----------------------------------------------------- */

PX_API px_obb px_obb_from_aabb(const px_aabb *b, px_pose pose)
{
	px_obb o;
	o.center = px_pose_transform_point(pose, px_aabb_center(b));
	o.axis[0] = px_pose_transform_vector(pose, px_v3(1.0, 0.0, 0.0));
	o.axis[1] = px_pose_transform_vector(pose, px_v3(0.0, 1.0, 0.0));
	o.axis[2] = px_pose_transform_vector(pose, px_v3(0.0, 0.0, 1.0));
	o.half = px_aabb_half_extents(b);
	return o;
}

PX_API px_obb px_obb_transform(const px_obb *b, px_pose pose)
{
	px_obb o;
	int k;
	o.center = px_pose_transform_point(pose, b->center);
	for (k = 0; k < 3; k++)
		o.axis[k] = px_pose_transform_vector(pose, b->axis[k]);
	o.half = b->half;
	return o;
}

PX_API px_vec3 px_obb_to_local(const px_obb *b, px_vec3 p)
{
	px_vec3 d = px_v3_sub(p, b->center);
	return px_v3(px_v3_dot(d, b->axis[0]), px_v3_dot(d, b->axis[1]),
		     px_v3_dot(d, b->axis[2]));
}

PX_API px_vec3 px_obb_closest_point(const px_obb *b, px_vec3 p)
{
	px_vec3 l = px_obb_to_local(b, p), r = b->center;
	r = px_v3_madd(r, b->axis[0], px__clamp(l.x, -b->half.x, b->half.x));
	r = px_v3_madd(r, b->axis[1], px__clamp(l.y, -b->half.y, b->half.y));
	r = px_v3_madd(r, b->axis[2], px__clamp(l.z, -b->half.z, b->half.z));
	return r;
}

PX_API double px_obb_dist2(const px_obb *b, px_vec3 p)
{
	/* In local coordinates, not |p - closest|^2: no cancellation when
	 * p is close to the box far from the centre. */
	px_vec3 l = px_obb_to_local(b, p);
	double dx = px__gap(l.x, -b->half.x, b->half.x);
	double dy = px__gap(l.y, -b->half.y, b->half.y);
	double dz = px__gap(l.z, -b->half.z, b->half.z);
	return dx * dx + dy * dy + dz * dz;
}

PX_API int px_obb_contains(const px_obb *b, px_vec3 p)
{
	px_vec3 l = px_obb_to_local(b, p);
	return fabs(l.x) <= b->half.x && fabs(l.y) <= b->half.y &&
	       fabs(l.z) <= b->half.z;
}

PX_API px_aabb px_obb_aabb(const px_obb *b)
{
	px_vec3 e;
	px_aabb r;
	double slack;
	e.x = fabs(b->axis[0].x) * b->half.x + fabs(b->axis[1].x) * b->half.y +
	      fabs(b->axis[2].x) * b->half.z;
	e.y = fabs(b->axis[0].y) * b->half.x + fabs(b->axis[1].y) * b->half.y +
	      fabs(b->axis[2].y) * b->half.z;
	e.z = fabs(b->axis[0].z) * b->half.x + fabs(b->axis[1].z) * b->half.y +
	      fabs(b->axis[2].z) * b->half.z;
	slack = px__round_slack(fabs(b->center.x) + fabs(b->center.y) +
				fabs(b->center.z) + b->half.x + b->half.y +
				b->half.z);
	e = px_v3_add(e, px_v3(slack, slack, slack));
	r.min = px_v3_sub(b->center, e);
	r.max = px_v3_add(b->center, e);
	return r;
}

PX_API int px_obb_overlap(const px_obb *a, const px_obb *b)
{
	double r[3][3], ar[3][3], t[3], ha[3], hb[3], ra, rb, tol;
	px_vec3 d;
	int i, j;

	ha[0] = a->half.x;
	ha[1] = a->half.y;
	ha[2] = a->half.z;
	hb[0] = b->half.x;
	hb[1] = b->half.y;
	hb[2] = b->half.z;
	d = px_v3_sub(b->center, a->center);
	for (i = 0; i < 3; i++) {
		t[i] = px_v3_dot(d, a->axis[i]);
		for (j = 0; j < 3; j++) {
			r[i][j] = px_v3_dot(a->axis[i], b->axis[j]);
			ar[i][j] = fabs(r[i][j]);
		}
	}
	/* Every test below is |t . L| > ra + rb for an axis L of length at
	 * most 1. Rounding of t and R is a few ulps of |d| and of the
	 * extents; when two edges are parallel, L = a_i x b_j is pure
	 * rounding noise and both sides are ~0. A slack of 1e-12 of the
	 * problem's size keeps such noise from ever claiming a separation:
	 * the test may report overlap for boxes closer than that slack,
	 * never miss one. */
	tol = PX__SAT_REL_EPS * (fabs(t[0]) + fabs(t[1]) + fabs(t[2]) +
				 ha[0] + ha[1] + ha[2] + hb[0] + hb[1] + hb[2]);

	/* a's face normals */
	for (i = 0; i < 3; i++) {
		rb = hb[0] * ar[i][0] + hb[1] * ar[i][1] + hb[2] * ar[i][2];
		if (fabs(t[i]) > ha[i] + rb + tol)
			return 0;
	}
	/* b's face normals */
	for (j = 0; j < 3; j++) {
		ra = ha[0] * ar[0][j] + ha[1] * ar[1][j] + ha[2] * ar[2][j];
		if (fabs(t[0] * r[0][j] + t[1] * r[1][j] + t[2] * r[2][j]) >
		    ra + hb[j] + tol)
			return 0;
	}
	/* a_i x b_j, in a's frame: components (e_i x R_col_j). */
	for (i = 0; i < 3; i++) {
		int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
		for (j = 0; j < 3; j++) {
			int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
			double lhs = fabs(t[i2] * r[i1][j] - t[i1] * r[i2][j]);
			ra = ha[i1] * ar[i2][j] + ha[i2] * ar[i1][j];
			rb = hb[j1] * ar[i][j2] + hb[j2] * ar[i][j1];
			if (lhs > ra + rb + tol)
				return 0;
		}
	}
	return 1;
}

PX_API px_vec3 px_obb_corner(const px_obb *b, int i)
{
	px_vec3 r = b->center;
	r = px_v3_madd(r, b->axis[0], (i & 1) ? b->half.x : -b->half.x);
	r = px_v3_madd(r, b->axis[1], (i & 2) ? b->half.y : -b->half.y);
	r = px_v3_madd(r, b->axis[2], (i & 4) ? b->half.z : -b->half.z);
	return r;
}
