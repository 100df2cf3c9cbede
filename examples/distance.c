/*
 * distance.c - the distance from a point to a model: a unit cube built
 * as a mesh from arrays, one query, the answer printed and checked.
 * Exits 0 when the answer is the known one.
 */
#include <math.h>
#include <stdio.h>

#include <proxima/px_mesh.h>

int main(void)
{
	static const double xyz[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0,
				     0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
	static const uint32_t tri[] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7,
				       0, 1, 5, 0, 5, 4, 1, 2, 6, 1, 6, 5,
				       2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7};
	struct px_model *cube;
	struct px_model_result r;
	int rc = px_mesh_model(xyz, 8, tri, 12, NULL, NULL, &cube);
	if (rc != PX_OK) {
		fprintf(stderr, "distance: mesh: %s\n", px_strerror(rc));
		return 1;
	}
	/* 1 m beyond the +x face, in front of its centre. */
	rc = px_model_query(cube, px_v3(2.0, 0.5, 0.5), &r);
	printf("distance %.6f m to (%.3f, %.3f, %.3f)%s\n", r.distance,
	       r.point.x, r.point.y, r.point.z, r.is_signed ? " (signed)" : "");
	px_model_free(cube);
	return rc == 1 && fabs(r.distance - 1.0) < 1e-12 && r.is_signed ? 0 : 1;
}
