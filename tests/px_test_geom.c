#include "px_test_geom.h"

#include <math.h>

#include "px_test.h"

px_pose px_test_rand_pose(double spread)
{
	px_pose P;
	px_quat q = {px_rand_normal(), px_rand_normal(), px_rand_normal(),
		     px_rand_normal()};
	double n = sqrt(px_quat_dot(q, q));
	P.q.w = q.w / n;
	P.q.x = q.x / n;
	P.q.y = q.y / n;
	P.q.z = q.z / n;
	P.t = px_v3(px_rand_range(-spread, spread),
		    px_rand_range(-spread, spread),
		    px_rand_range(-spread, spread));
	return P;
}
