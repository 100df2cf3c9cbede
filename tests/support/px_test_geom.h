/*
 * px_test_geom.h - random geometry for the distance tests, drawn from
 * the test's seeded stream (px_rand_*), so a failing seed replays.
 */
#ifndef PX_TEST_GEOM_H
#define PX_TEST_GEOM_H

#include "px_math.h"

/* A uniformly random unit quaternion (normalised Gaussian). */
px_quat px_test_rand_quat(void);

/* A pose with a uniformly random rotation (normalised Gaussian
 * quaternion) and a translation uniform in [-spread, spread]^3. */
px_pose px_test_rand_pose(double spread);

struct px_model;

/* Exact distance from p (model frame) to a mesh model by a scan over
 * every triangle: the reference the hierarchy and grid tests compare
 * with. */
double px_test_mesh_brute(const struct px_model *m, px_vec3 p);

#endif
