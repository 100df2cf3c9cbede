/*
 * pair_internal.h - closed-form pairs for px_pair_distance (px_pair.c):
 * capsule against capsule and capsule against box, from the distance
 * between the capsules' axis segments and from a segment to a box. Not
 * part of the public API.
 *
 * Memory and real-time rules: no allocation, a fixed number of steps;
 * RT-safe.
 */
#ifndef PX_PAIR_INTERNAL_H
#define PX_PAIR_INTERNAL_H

#include "px_math.h"
#include "px_model.h"
#include "px_pair.h"

/*
 * Closest points of segments p0-p1 and q0-q1 (either may be a point):
 * the parameters *s, *t in [0, 1] and the squared distance. Exact up to
 * rounding, also for parallel segments (then one closest pair of the
 * many). RT-safe.
 */
double px__seg_seg(px_vec3 p0, px_vec3 p1, px_vec3 q0, px_vec3 q1, double *s,
		   double *t);

/*
 * Closest points of segment p0-p1 and the solid box |x_k| <= h[k]
 * (box frame): the segment parameter *t, the box point *q, and the
 * squared distance (0 when the segment meets the box). The squared
 * distance is a convex piecewise quadratic in t with breaks where the
 * segment crosses a face plane; each piece is minimised exactly.
 * RT-safe.
 */
double px__seg_box(px_vec3 p0, px_vec3 p1, const double h[3], double *t,
		   px_vec3 *q);

/*
 * Closest points of segment p0-p1 and triangle v[0..2] (any shape, also
 * collapsed): the segment parameter *s, the triangle point *q and the
 * squared distance. The least over the segment's end points and its
 * crossing of the triangle's plane against the triangle, and the
 * triangle's edges against the segment: a disjoint pair has its closest
 * points on one of these, and every candidate is a real pair of points.
 * RT-safe.
 */
double px__seg_tri(px_vec3 p0, px_vec3 p1, const px_vec3 v[3], double *s,
		   px_vec3 *q);

/* When m is a capsule primitive: its world-frame axis e0-e1 and radius,
 * returning 1; else 0. RT-safe. */
int px__capsule_axis(const struct px_model *m, px_vec3 *e0, px_vec3 *e1,
		     double *radius);

/*
 * The pair in closed form when it is a capsule against a capsule, or a
 * capsule against a box whose axis segment stays outside the box (the
 * axis inside the box is left to EPA). Fills res (distance, points,
 * depth and normal when the pair overlaps, converged, local_only = 0)
 * as px_pair_distance() documents and returns 1; returns 0 when the
 * pair is not one of these (res untouched), or a negative error.
 * RT-safe.
 */
int px__pair_closed(const struct px_model *a, const struct px_model *b,
		    struct px_pair_result *res);

#endif
