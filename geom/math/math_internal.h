/*
 * math_internal.h - private helpers of geom/ on plain math values (px_vec3,
 * px_aabb, periods), shared by the distance core, the trackers and the
 * models, and the declaration of the test switches. Not installed, not
 * part of the API.
 */
#ifndef PX_MATH_INTERNAL_H
#define PX_MATH_INTERNAL_H

#include <math.h>

#include "px_math.h"

/* x taken the shorter way round a period len > 0: in [-len/2, len/2]
 * (remainder() without its exact-halfway rule, which nothing here needs;
 * libm's costs about 120 instructions, and a cold update of the curve
 * tracker calls it three times). */
static inline double px__wrap_half(double x, double len)
{
	return x - len * floor(x / len + 0.5);
}

/* Farthest a query point may lie from a model's box (model units): the
 * queries work with squared distances, which overflow past about 1e154. */
#define PX__MAX_QUERY_REACH 1e150

/* 1 when p lies farther than PX__MAX_QUERY_REACH from box b along some
 * axis (an empty or infinite box never makes a point too far).
 * RT-safe. */
static inline int px__too_far(const px_aabb *b, px_vec3 p)
{
	return b->min.x - p.x > PX__MAX_QUERY_REACH ||
	       p.x - b->max.x > PX__MAX_QUERY_REACH ||
	       b->min.y - p.y > PX__MAX_QUERY_REACH ||
	       p.y - b->max.y > PX__MAX_QUERY_REACH ||
	       b->min.z - p.z > PX__MAX_QUERY_REACH ||
	       p.z - b->max.z > PX__MAX_QUERY_REACH;
}

/*
 * A test switch: a global the tests set to break a proof on purpose
 * (and show that their checks catch it) or to take another path. Only
 * the objects built with -DPX_TEST_HOOKS, which the tests and benches
 * link, have it as a writable variable; in the shipped library it is
 * the constant of normal operation, so the branches that read it
 * compile away and nothing there can switch a proof off.
 */
#ifdef PX_TEST_HOOKS
#define PX__TEST_SWITCH(type, name, normal) extern type name
#else
#define PX__TEST_SWITCH(type, name, normal) static const type name = normal
#endif

#endif
