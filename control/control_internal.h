/* Private declarations shared by the control/ sources. */
#ifndef PX_CONTROL_INTERNAL_H
#define PX_CONTROL_INTERNAL_H

#include <math.h>

#include "px_control.h"

/* Query budget limit of px_control_query_segment(). */
#define PX__CTL_SEG_MAX 64

static inline int px__ctl_finite(double x)
{
	return isfinite(x);
}

/* Call q->point, count it, and check the answer: a valid hit needs a
 * finite distance and point and a unit normal. An invalid answer is
 * turned into "free up to max_distance_m". */
int px__ctl_point(const struct px_control_query *q, px_vec3 p,
		  double max_distance_m, struct px_control_hit *out,
		  int *count);

#endif
