/*
 * px_prim.h - primitives with exact closed-form signed distances: sphere,
 * box, capsule, cylinder, cone (finite, capped, also truncated), torus and
 * half-space.
 *
 * Robot links and tools are often modelled by a handful of such shapes;
 * their distances are exact in closed form (no iteration, no tolerance),
 * signed (inside negative) and come with the closest point on the
 * surface, so penetration depth and direction for haptic rendering come
 * out of the same query. Every primitive sits in its own frame, centred
 * at the origin with its axis along z; px_model's pose places it.
 *
 * Solids of revolution (cylinder, cone, torus, capsule) reduce to a
 * planar problem: rotating any surface point about z into the half-plane
 * that holds the query point does not increase its distance, so the
 * closest point lies in that meridian half-plane, and the 3D distance is
 * the 2D distance from (rho, z) to the profile. For a query point on the
 * axis every meridian is equally good and azimuth 0 is reported.
 *
 * Result details (px_model_result, model frame before the pose):
 *  - index: the face. Sphere, torus, half-space: 0. Box: 0..5 for the
 *    faces -x, +x, -y, +y, -z, +z (the face nearest an inside point, the
 *    face whose slab the point is farthest outside of otherwise).
 *    Capsule: 0 side, 1 bottom (z < 0) cap, 2 top cap. Cylinder and
 *    cone: 0 bottom cap (z = -half_height), 1 side, 2 top cap.
 *  - feature: FACE, EDGE (box edges, rims of cylinders and cones),
 *    VERTEX (box corners, the apex of a pointed cone).
 *  - u, v: sphere: azimuth, polar angle; box: the two face coordinates
 *    (in axis order); capsule, cylinder, cone: azimuth, z; torus:
 *    azimuth, tube angle; half-space: x, y.
 *  - certified = 1, gap = 0, iterations = 1.
 *
 * Accuracy: the signed distance is within PX_PRIM_ERR_ULPS u (|q| +
 * size) of the exact one (u = 2^-53, size the largest length), for
 * lengths and points in the accepted range (PX_PRIM_MAX_LENGTH); the
 * closed forms have no cancellation beyond that of |q| itself.
 *
 * Memory and real-time rules: a struct px_prim is a plain value;
 * px_prim_closest() is RT-safe; px_prim_model() allocates the model
 * handle (setup).
 */
#ifndef PX_PRIM_H
#define PX_PRIM_H

#include "px_base.h"
#include "px_math.h"
#include "px_model.h"

#ifdef __cplusplus
extern "C" {
#endif

enum px_prim_type {
	PX_PRIM_SPHERE = 1,    /* a = radius */
	PX_PRIM_BOX = 2,       /* a, b, c = half extents along x, y, z */
	PX_PRIM_CAPSULE = 3,   /* a = radius, b = half length of the segment */
	PX_PRIM_CYLINDER = 4,  /* a = radius, b = half height */
	/* a = radius at z = -b, b = half height, c = radius at z = +b
	 * (0 for a pointed cone, a frustum otherwise). */
	PX_PRIM_CONE = 5,
	PX_PRIM_TORUS = 6,     /* a = major radius (axis z), b = tube radius < a */
	PX_PRIM_HALFSPACE = 7  /* solid z <= 0, outward normal +z; no parameters */
};

/* A primitive: type and up to three lengths (metres). */
struct px_prim {
	enum px_prim_type type;
	double a, b, c;
};

/*
 * The accepted range of every length (a cone's radii may also be 0):
 * up to 1e150, so that squared distances to points within the query
 * reach (1e150 beyond the box, px_model.h) stay finite; from 1e-140, so
 * that they stay normal doubles at the primitive's own scale.
 */
#define PX_PRIM_MAX_LENGTH 1e150
#define PX_PRIM_MIN_LENGTH 1e-140
#define PX_PRIM_ERR_ULPS 16.0

/*
 * Check a primitive: lengths finite and positive where required (cone:
 * a >= 0, c >= 0, not both zero; torus: 0 < b < a, since a spindle torus
 * is not the solid this distance describes) and within the accepted
 * range. Returns PX_OK, PX_E_INVAL (NULL or unknown type), PX_E_NAN,
 * PX_E_RANGE. @note RT-safe.
 */
PX_API int px_prim_check(const struct px_prim *p);

/*
 * Exact closest point of the primitive to q (primitive frame). Fills r
 * as described above; with unsigned_only the distance is |d| and the
 * direction points from the surface to q. The primitive must pass
 * px_prim_check(). Returns PX_OK or PX_E_INVAL (NULL, bad primitive).
 * @note RT-safe.
 */
PX_API int px_prim_closest(const struct px_prim *p, px_vec3 q,
			   int unsigned_only, struct px_model_result *r);

/* Box of the primitive in its frame (infinite in x, y and below for a
 * half-space). @note RT-safe. */
PX_API px_aabb px_prim_aabb(const struct px_prim *p);

/*
 * A model for the primitive (copied). Setup only.
 * Returns PX_OK, px_prim_check()'s errors, PX_E_NOMEM.
 */
PX_API int px_prim_model(const struct px_prim *p, struct px_model **out);

/* The primitive of a model made by px_prim_model(). Returns PX_OK, or
 * PX_E_INVAL when m is NULL or not a primitive. @note RT-safe. */
PX_API int px_prim_get(const struct px_model *m, struct px_prim *out);

#ifdef __cplusplus
}
#endif

#endif
