/*
 * px_math.h - small value types of the geometry core: 3-vectors, unit
 * quaternions, rigid poses (rotation + translation), axis-aligned and
 * oriented boxes.
 *
 * All types are plain structs passed by value; the hot operations are
 * static inline so that distance code compiles down to straight-line
 * arithmetic. Conventions: quaternions are (w, x, y, z) with w the scalar
 * part and rotate by q v q*; a pose p maps a point from its child frame to
 * its parent frame, x_parent = R(p.q) x_child + p.t; compose(a, b) applies
 * b first, then a (as matrices would: T_a * T_b).
 *
 * Memory and real-time rules: nothing here allocates, locks or does I/O;
 * every function is RT-safe and runs in bounded time. Functions that can
 * meet degenerate input (zero vectors, zero quaternions) say what they
 * return and never produce NaN from finite input; those that return an
 * int give PX_OK or a negative px_err and always write their output
 * (the documented fallback on error). Pointer arguments must be valid
 * unless a function says NULL is accepted.
 */
#ifndef PX_MATH_H
#define PX_MATH_H

#include <math.h>
#include <stddef.h>

#include "px_base.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct px_vec3 {
	double x, y, z;
} px_vec3;

/* Unit quaternion, scalar first. */
typedef struct px_quat {
	double w, x, y, z;
} px_quat;

/* Rigid transform: rotation q (unit) then translation t. */
typedef struct px_pose {
	px_quat q;
	px_vec3 t;
} px_pose;

/* Row-major 3x3 matrix. */
typedef struct px_mat3 {
	double m[3][3];
} px_mat3;

/* Axis-aligned box; empty when any min > max (see px_aabb_empty()). */
typedef struct px_aabb {
	px_vec3 min, max;
} px_aabb;

/* Oriented box: centre, orthonormal axes (columns of its rotation), and
 * non-negative half extents along each axis. */
typedef struct px_obb {
	px_vec3 center;
	px_vec3 axis[3];
	px_vec3 half;
} px_obb;

/* ---- vec3 (inline) ---------------------------------------------------- */

static inline px_vec3 px_v3(double x, double y, double z)
{
	px_vec3 r = {x, y, z};
	return r;
}
static inline px_vec3 px_v3_add(px_vec3 a, px_vec3 b)
{
	return px_v3(a.x + b.x, a.y + b.y, a.z + b.z);
}
static inline px_vec3 px_v3_sub(px_vec3 a, px_vec3 b)
{
	return px_v3(a.x - b.x, a.y - b.y, a.z - b.z);
}
static inline px_vec3 px_v3_scale(px_vec3 a, double s)
{
	return px_v3(a.x * s, a.y * s, a.z * s);
}
/* a + s * b */
static inline px_vec3 px_v3_madd(px_vec3 a, px_vec3 b, double s)
{
	return px_v3(a.x + s * b.x, a.y + s * b.y, a.z + s * b.z);
}
static inline px_vec3 px_v3_neg(px_vec3 a)
{
	return px_v3(-a.x, -a.y, -a.z);
}
static inline double px_v3_dot(px_vec3 a, px_vec3 b)
{
	return a.x * b.x + a.y * b.y + a.z * b.z;
}
static inline px_vec3 px_v3_cross(px_vec3 a, px_vec3 b)
{
	return px_v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z,
		     a.x * b.y - a.y * b.x);
}
static inline double px_v3_norm2(px_vec3 a)
{
	return px_v3_dot(a, a);
}
/* hypot-style scaling is not used: inputs are metres in a workspace, far
 * from overflow; callers with extreme magnitudes use px_v3_normalize(). */
static inline double px_v3_norm(px_vec3 a)
{
	return sqrt(px_v3_dot(a, a));
}
static inline double px_v3_dist2(px_vec3 a, px_vec3 b)
{
	return px_v3_norm2(px_v3_sub(a, b));
}
static inline double px_v3_dist(px_vec3 a, px_vec3 b)
{
	return sqrt(px_v3_dist2(a, b));
}
static inline px_vec3 px_v3_lerp(px_vec3 a, px_vec3 b, double t)
{
	return px_v3(a.x + t * (b.x - a.x), a.y + t * (b.y - a.y),
		     a.z + t * (b.z - a.z));
}
static inline px_vec3 px_v3_min(px_vec3 a, px_vec3 b)
{
	return px_v3(fmin(a.x, b.x), fmin(a.y, b.y), fmin(a.z, b.z));
}
static inline px_vec3 px_v3_max(px_vec3 a, px_vec3 b)
{
	return px_v3(fmax(a.x, b.x), fmax(a.y, b.y), fmax(a.z, b.z));
}
static inline double px_v3_comp(px_vec3 a, int i)
{
	return i == 0 ? a.x : (i == 1 ? a.y : a.z);
}
static inline int px_v3_isfinite(px_vec3 a)
{
	return isfinite(a.x) && isfinite(a.y) && isfinite(a.z);
}

/*
 * Unit vector along a. Robust for tiny (denormal) and huge (1e300) finite
 * inputs: scales by the largest component before squaring.
 * Returns PX_OK; PX_E_DEGENERATE for a zero vector, PX_E_NAN for a NaN or
 * infinite component; in both error cases *out = fallback (as given, not
 * normalized). @note RT-safe.
 */
PX_API int px_v3_normalize(px_vec3 a, px_vec3 fallback, px_vec3 *out);

/* Some unit vector perpendicular to a (a x the basis axis least aligned
 * with a, normalized). A zero or non-finite a gives a fixed unit vector;
 * never NaN. @note RT-safe. */
PX_API px_vec3 px_v3_any_perp(px_vec3 a);

/* ---- quaternion -------------------------------------------------------- */

static inline px_quat px_quat_identity(void)
{
	px_quat q = {1.0, 0.0, 0.0, 0.0};
	return q;
}
static inline px_quat px_quat_conj(px_quat q)
{
	px_quat r = {q.w, -q.x, -q.y, -q.z};
	return r;
}
/* Hamilton product a * b (rotate by b, then by a). */
static inline px_quat px_quat_mul(px_quat a, px_quat b)
{
	px_quat r = {a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z,
		     a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
		     a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
		     a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
	return r;
}
/* Rotate v by unit quaternion q (v' = q v q*), 15 multiplies. */
static inline px_vec3 px_quat_rotate(px_quat q, px_vec3 v)
{
	px_vec3 u = px_v3(q.x, q.y, q.z);
	px_vec3 t = px_v3_scale(px_v3_cross(u, v), 2.0);
	return px_v3_add(px_v3_madd(v, t, q.w), px_v3_cross(u, t));
}
static inline double px_quat_dot(px_quat a, px_quat b)
{
	return a.w * b.w + a.x * b.x + a.y * b.y + a.z * b.z;
}

/* Normalize q (scaled, so 1e-300 and 1e300 components work). Returns
 * PX_OK; PX_E_DEGENERATE for a zero q, PX_E_NAN for a non-finite one, in
 * both cases *out = identity. The sign of q is kept. @note RT-safe. */
PX_API int px_quat_normalize(px_quat q, px_quat *out);
/* Rotation of angle_rad (right hand) about axis (need not be unit).
 * Returns PX_OK; PX_E_DEGENERATE for a zero axis, PX_E_NAN for a
 * non-finite axis or angle; on error *out = identity. @note RT-safe. */
PX_API int px_quat_from_axis_angle(px_vec3 axis, double angle_rad,
				   px_quat *out);
/* Unit axis and angle in [0, pi] of q (any nonzero scale; q and -q give
 * the same answer). The identity, a zero or a non-finite q give axis
 * (1,0,0) and angle 0. Accurate near 0 and pi (atan2, not acos). Either
 * output pointer may be NULL. @note RT-safe. */
PX_API void px_quat_to_axis_angle(px_quat q, px_vec3 *axis, double *angle_rad);
/* Shortest rotation taking direction a to direction b (neither need be
 * unit); accurate to rounding up to b = -a, where it picks a half turn
 * about px_v3_any_perp(a). Returns PX_OK; PX_E_DEGENERATE if a or b is
 * zero, PX_E_NAN if either is non-finite; on error *out = identity.
 * @note RT-safe. */
PX_API int px_quat_from_two_vectors(px_vec3 a, px_vec3 b, px_quat *out);
/* Rotation matrix of q (normalized first, so any nonzero q gives a proper
 * rotation; a zero or non-finite q gives the identity matrix).
 * @note RT-safe. */
PX_API px_mat3 px_quat_to_mat3(px_quat q);
/* Quaternion of rotation matrix m by Shepperd's method: stable at and
 * near 180 degrees. The result is unit with w >= 0. A non-finite m gives
 * the identity; a non-rotation m gives some unit quaternion (check input
 * with px_mat3_is_rotation() or use px_pose_from_mat3_t()).
 * @note RT-safe. */
PX_API px_quat px_quat_from_mat3(const px_mat3 *m);
/* Spherical interpolation from a (t = 0) to b (t = 1) along the shorter
 * arc (b is negated when a . b < 0, so slerp(q, -q, t) = q); inputs are
 * normalized first, and below 1e-6 rad it is normalized lerp. The result
 * is unit. A non-finite t gives a. @note RT-safe. */
PX_API px_quat px_quat_slerp(px_quat a, px_quat b, double t);
/* Angle in [0, pi] of the rotation taking orientation a to b (q and -q
 * are the same orientation); accurate near 0 and pi. @note RT-safe. */
PX_API double px_quat_angle_between(px_quat a, px_quat b);

/* ---- mat3 -------------------------------------------------------------- */

/* Plain 3x3 algebra; all @note RT-safe. */
PX_API px_mat3 px_mat3_identity(void);
PX_API px_mat3 px_mat3_from_rows(px_vec3 r0, px_vec3 r1, px_vec3 r2);
PX_API px_mat3 px_mat3_from_cols(px_vec3 c0, px_vec3 c1, px_vec3 c2);
/* Column j (clamped to 0..2). */
PX_API px_vec3 px_mat3_col(const px_mat3 *m, int j);
PX_API px_vec3 px_mat3_mul_v3(const px_mat3 *m, px_vec3 v);
PX_API px_mat3 px_mat3_mul(const px_mat3 *a, const px_mat3 *b);
PX_API px_mat3 px_mat3_transpose(const px_mat3 *m);
PX_API double px_mat3_det(const px_mat3 *m);
/* 1 if m is finite, |M^T M - I| <= tol entrywise and det(m) > 0 (a
 * proper rotation), else 0. @note RT-safe. */
PX_API int px_mat3_is_rotation(const px_mat3 *m, double tol);

/* ---- pose -------------------------------------------------------------- */

static inline px_pose px_pose_identity(void)
{
	px_pose p = {{1.0, 0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}};
	return p;
}
/* Point from child to parent frame: R x + t. */
static inline px_vec3 px_pose_transform_point(px_pose p, px_vec3 x)
{
	return px_v3_add(px_quat_rotate(p.q, x), p.t);
}
/* Direction from child to parent frame (rotation only). */
static inline px_vec3 px_pose_transform_vector(px_pose p, px_vec3 v)
{
	return px_quat_rotate(p.q, v);
}
/* Point from parent to child frame: R^T (x - t). */
static inline px_vec3 px_pose_inverse_transform_point(px_pose p, px_vec3 x)
{
	return px_quat_rotate(px_quat_conj(p.q), px_v3_sub(x, p.t));
}
static inline px_vec3 px_pose_inverse_transform_vector(px_pose p, px_vec3 v)
{
	return px_quat_rotate(px_quat_conj(p.q), v);
}
/* a * b: apply b, then a. */
static inline px_pose px_pose_compose(px_pose a, px_pose b)
{
	px_pose r;
	r.q = px_quat_mul(a.q, b.q);
	r.t = px_pose_transform_point(a, b.t);
	return r;
}
static inline px_pose px_pose_inverse(px_pose p)
{
	px_pose r;
	r.q = px_quat_conj(p.q);
	r.t = px_quat_rotate(r.q, px_v3_neg(p.t));
	return r;
}

/* Check a pose is finite and its quaternion is unit within 1e-6, and
 * renormalize it. Call on every pose that comes from a device, a file or
 * a config. Returns PX_OK (q renormalized, t kept); PX_E_INVAL for a NULL
 * p; PX_E_NAN for any non-finite component, PX_E_DEGENERATE for a zero
 * quaternion, PX_E_RANGE for |q| outside 1 +- 1e-6 (a wrong convention or
 * a corrupt frame, not rounding): on these three errors *p becomes the
 * identity. @note RT-safe. */
PX_API int px_pose_sanitize(px_pose *p);
/* Pose from a rotation matrix r and translation t (as read from a config
 * or a robot's forward kinematics). Returns PX_OK; PX_E_INVAL for NULL
 * pointers; PX_E_NAN for non-finite input; PX_E_RANGE if r is not a
 * proper rotation within 1e-6 (px_mat3_is_rotation); on error *out is the
 * identity. @note RT-safe. */
PX_API int px_pose_from_mat3_t(const px_mat3 *r, px_vec3 t, px_pose *out);

/* ---- axis-aligned box ------------------------------------------------- */

/* All box functions are @note RT-safe. Boxes are closed: points on the
 * boundary are inside, touching boxes overlap. */

/* The empty box (min = +inf, max = -inf): extending it by a point gives
 * that point. */
PX_API px_aabb px_aabb_empty(void);
/* 1 if any min > max or any bound is NaN. */
PX_API int px_aabb_is_empty(const px_aabb *b);
/* Grow b to contain p; a non-finite p is ignored. */
PX_API void px_aabb_extend(px_aabb *b, px_vec3 p);
/* Box of n points (non-finite ones ignored); empty for n = 0 or NULL. */
PX_API px_aabb px_aabb_from_points(const px_vec3 *pts, size_t n);
PX_API px_aabb px_aabb_union(const px_aabb *a, const px_aabb *b);
PX_API int px_aabb_contains(const px_aabb *b, px_vec3 p);
/* 1 if the closed boxes share a point; 0 if either is empty. */
PX_API int px_aabb_overlap(const px_aabb *a, const px_aabb *b);
/* Squared distance from p to the box (0 inside, +inf for an empty box):
 * the lower bound used everywhere in the distance core. */
PX_API double px_aabb_dist2(const px_aabb *b, px_vec3 p);
/* Squared distance from p to the farthest point of the box: an upper
 * bound on the distance to anything inside it (+inf for an empty box). */
PX_API double px_aabb_max_dist2(const px_aabb *b, px_vec3 p);
/* Point of the box nearest p (p itself inside, and for an empty box). */
PX_API px_vec3 px_aabb_closest_point(const px_aabb *b, px_vec3 p);
/* Centre and half extents; (0,0,0) for an empty box. */
PX_API px_vec3 px_aabb_center(const px_aabb *b);
PX_API px_vec3 px_aabb_half_extents(const px_aabb *b);
/* Length of the diagonal; 0 for an empty box. */
PX_API double px_aabb_diagonal(const px_aabb *b);
/* Box enclosing b after transforming it by pose: tight for the 8 corners
 * up to a few ulps of slack added so that the corners, however rounded,
 * are inside. An empty box stays empty. */
PX_API px_aabb px_aabb_transform(const px_aabb *b, px_pose pose);
/* Grow by margin on every side (shrink for margin < 0). An empty box or
 * a non-finite margin gives b unchanged. */
PX_API px_aabb px_aabb_inflate(const px_aabb *b, double margin);

/* ---- oriented box ----------------------------------------------------- */

/* The axes of an obb are assumed orthonormal to double precision, as the
 * functions below produce them; half extents non-negative. */

/* Box b (in pose's child frame) as seen in pose's parent frame. An empty
 * b gives a point box at pose(0). */
PX_API px_obb px_obb_from_aabb(const px_aabb *b, px_pose pose);
/* b moved by pose (centre and axes transformed, extents kept). */
PX_API px_obb px_obb_transform(const px_obb *b, px_pose pose);
/* Coordinates of p along the box's axes, relative to its centre. */
PX_API px_vec3 px_obb_to_local(const px_obb *b, px_vec3 p);
/* Point of the box nearest p (clamping in local coordinates). */
PX_API px_vec3 px_obb_closest_point(const px_obb *b, px_vec3 p);
/* Squared distance from p to the box, 0 inside; computed from local
 * coordinates, so it stays accurate for points near a face. */
PX_API double px_obb_dist2(const px_obb *b, px_vec3 p);
PX_API int px_obb_contains(const px_obb *b, px_vec3 p);
/* Axis-aligned box enclosing b (with a few ulps of slack). */
PX_API px_aabb px_obb_aabb(const px_obb *b);
/* Separating-axis test over the 15 candidate axes (3 + 3 face normals, 9
 * edge cross products). Conservative: never reports a separation for
 * boxes that touch or overlap; may report overlap for boxes separated by
 * less than 1e-12 times (|centre offset| + sum of half extents). The
 * slack is what keeps parallel edges, whose cross product is rounding
 * noise, from producing a false separation. Returns 1 or 0. */
PX_API int px_obb_overlap(const px_obb *a, const px_obb *b);
/* Corner i (0..7): bit k of i selects + (set) or - along axis k. */
PX_API px_vec3 px_obb_corner(const px_obb *b, int i);

#ifdef __cplusplus
}
#endif

#endif
