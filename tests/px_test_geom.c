#include "px_test_geom.h"

#include <math.h>

#include "px_test.h"

px_quat px_test_rand_quat(void)
{
	px_quat q = {px_rand_normal(), px_rand_normal(), px_rand_normal(),
		     px_rand_normal()}, u;
	double n = sqrt(px_quat_dot(q, q));
	u.w = q.w / n;
	u.x = q.x / n;
	u.y = q.y / n;
	u.z = q.z / n;
	return u;
}

px_pose px_test_rand_pose(double spread)
{
	px_pose P;
	P.q = px_test_rand_quat();
	P.t = px_v3(px_rand_range(-spread, spread),
		    px_rand_range(-spread, spread),
		    px_rand_range(-spread, spread));
	return P;
}
