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
 * every function is RT-safe. Functions that can meet degenerate input
 * (zero vectors, zero quaternions) say what they return and never
 * produce NaN from finite input.
 */
#ifndef PX_MATH_H
#define PX_MATH_H

#include <math.h>
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
 * Unit vector along a. Robust for tiny and huge finite inputs (scales
 * before squaring). For a zero or non-finite vector *out is set to
 * fallback and PX_E_DEGENERATE (zero) or PX_E_NAN is returned.
 * @note RT-safe.
 */
PX_API int px_v3_normalize(px_vec3 a, px_vec3 fallback, px_vec3 *out);

/* Some unit vector perpendicular to a (any direction if a is zero).
 * @note RT-safe. */
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

/* Normalize q. A zero or non-finite q gives the identity and
 * PX_E_DEGENERATE / PX_E_NAN. @note RT-safe. */
PX_API int px_quat_normalize(px_quat q, px_quat *out);
/* Rotation of angle_rad about axis (need not be unit). A zero axis gives
 * the identity and PX_E_DEGENERATE. @note RT-safe. */
PX_API int px_quat_from_axis_angle(px_vec3 axis, double angle_rad,
				   px_quat *out);
/* Axis and angle in [0, pi] of unit q; the identity gives axis (1,0,0).
 * @note RT-safe. */
PX_API void px_quat_to_axis_angle(px_quat q, px_vec3 *axis, double *angle_rad);
/* Shortest rotation taking direction a to direction b; robust when they
 * are opposite (picks a perpendicular axis). Zero inputs give the identity
 * and PX_E_DEGENERATE. @note RT-safe. */
PX_API int px_quat_from_two_vectors(px_vec3 a, px_vec3 b, px_quat *out);
/* Rotation matrix of unit q, and back (Shepperd's method, stable near
 * 180 degrees; the result is normalized and has w >= 0). @note RT-safe. */
PX_API px_mat3 px_quat_to_mat3(px_quat q);
PX_API px_quat px_quat_from_mat3(const px_mat3 *m);
/* Spherical interpolation along the shorter arc. @note RT-safe. */
PX_API px_quat px_quat_slerp(px_quat a, px_quat b, double t);
/* Angle in [0, pi] between two orientations. @note RT-safe. */
PX_API double px_quat_angle_between(px_quat a, px_quat b);

/* ---- mat3 -------------------------------------------------------------- */

PX_API px_vec3 px_mat3_mul_v3(const px_mat3 *m, px_vec3 v);
PX_API px_mat3 px_mat3_mul(const px_mat3 *a, const px_mat3 *b);
PX_API px_mat3 px_mat3_transpose(const px_mat3 *m);
PX_API double px_mat3_det(const px_mat3 *m);

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
 * renormalize it. Returns PX_OK, PX_E_NAN or PX_E_DEGENERATE (the pose is
 * then the identity). Call on every pose that comes from a device, a file
 * or a config. @note RT-safe. */
PX_API int px_pose_sanitize(px_pose *p);

/* ---- axis-aligned box ------------------------------------------------- */

/* The empty box (min = +inf, max = -inf): extending it by a point gives
 * that point. */
PX_API px_aabb px_aabb_empty(void);
PX_API int px_aabb_is_empty(const px_aabb *b);
PX_API void px_aabb_extend(px_aabb *b, px_vec3 p);
PX_API px_aabb px_aabb_union(const px_aabb *a, const px_aabb *b);
PX_API int px_aabb_contains(const px_aabb *b, px_vec3 p);
PX_API int px_aabb_overlap(const px_aabb *a, const px_aabb *b);
/* Squared distance from p to the box (0 inside): the lower bound used
 * everywhere in the distance core. @note RT-safe. */
PX_API double px_aabb_dist2(const px_aabb *b, px_vec3 p);
/* Squared distance from p to the farthest point of the box: an upper
 * bound on the distance to anything inside it. @note RT-safe. */
PX_API double px_aabb_max_dist2(const px_aabb *b, px_vec3 p);
PX_API px_vec3 px_aabb_closest_point(const px_aabb *b, px_vec3 p);
PX_API px_vec3 px_aabb_center(const px_aabb *b);
PX_API double px_aabb_diagonal(const px_aabb *b);
/* Box enclosing b after transforming it by pose (exact for the box's
 * corners). */
PX_API px_aabb px_aabb_transform(const px_aabb *b, px_pose pose);
/* Grow by margin on every side. */
PX_API px_aabb px_aabb_inflate(const px_aabb *b, double margin);

/* ---- oriented box ----------------------------------------------------- */

PX_API px_obb px_obb_from_aabb(const px_aabb *b, px_pose pose);
PX_API px_obb px_obb_transform(const px_obb *b, px_pose pose);
PX_API px_vec3 px_obb_closest_point(const px_obb *b, px_vec3 p);
PX_API double px_obb_dist2(const px_obb *b, px_vec3 p);
PX_API int px_obb_contains(const px_obb *b, px_vec3 p);
PX_API px_aabb px_obb_aabb(const px_obb *b);
/* Separating-axis test (15 axes), robust for parallel edges. */
PX_API int px_obb_overlap(const px_obb *a, const px_obb *b);
/* Corner i (0..7): bit k of i selects the sign along axis k. */
PX_API px_vec3 px_obb_corner(const px_obb *b, int i);

#ifdef __cplusplus
}
#endif

#endif
