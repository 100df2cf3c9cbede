#include "px_test_geom.h"

#include <math.h>

#include "px_mesh.h"
#include "px_test.h"
#include "mesh_gen.h"

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

double px_test_mesh_brute(const struct px_model *m, px_vec3 p)
{
	size_t i, n = px_mesh_triangle_count(m);
	double best = INFINITY;
	for (i = 0; i < n; i++) {
		px_vec3 v[3];
		double d2;
		px_mesh_triangle(m, i, v);
		d2 = px_tri_closest(p, v[0], v[1], v[2], NULL, NULL, NULL, NULL, NULL);
		if (d2 < best)
			best = d2;
	}
	return sqrt(best);
}

struct px_model *px_test_mesh_shape(int kind, int box_div, double *radius)
{
	struct gen_mesh g;
	struct px_model *m = NULL;
	double h[3] = {0.3, 0.5, 0.2}, r;
	switch (kind) {
	case 0:
		gen_torus(0.6, 0.2, 16, 8, &g);
		r = 0.8;
		break;
	case 1:
		gen_sphere(0.5, 8, 12, &g);
		r = 0.5;
		break;
	case 2:
		gen_box(h, box_div, &g);
		r = sqrt(0.09 + 0.25 + 0.04);
		break;
	default:
		gen_lprism(0.4, 0.3, &g);
		r = sqrt(2 * 0.64 + 0.09);
		break;
	}
	if (radius)
		*radius = r;
	PX_CHECK_INT_EQ(px_mesh_model(g.xyz, g.nv, g.tri, g.nt, NULL, NULL, &m), PX_OK);
	gen_free(&g);
	return m;
}
