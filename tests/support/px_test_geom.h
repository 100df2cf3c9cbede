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

/* Mesh model number kind of four, the shapes the pair tests share:
 * 0 a torus (radii 0.6 and 0.2, 16 x 8), 1 a sphere (radius 0.5, 8 x 12),
 * 2 a box of half sides 0.3, 0.5, 0.2 with box_div x box_div quads a
 * face, 3 an L-shaped prism (arm 0.4, height 0.3). *radius, when radius
 * is not NULL: the distance from the origin within which it lies. */
struct px_model *px_test_mesh_shape(int kind, int box_div, double *radius);

#endif
