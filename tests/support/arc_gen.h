/*
 * arc_gen.h - exact NURBS circle arcs for the recognition test and
 * benchmark: the control net of a unit circle arc in rational quadratic
 * spans, from which both build circles, spheres and tori.
 */
#ifndef PX_TEST_ARC_GEN_H
#define PX_TEST_ARC_GEN_H

#include <math.h>

/* 2D unit-circle arc from angle a0 over sweep in nseg rational quadratic
 * spans: xy (2 per point), w, n points, knots U on [0, 1] (clamped). */
static inline int arc2d(double a0, double sweep, int nseg, double *xy,
			double *w, double *U)
{
	int s, k = 0, n = 2 * nseg + 1, i;
	double h = sweep / nseg;
	for (s = 0; s < nseg; s++) {
		double t0 = a0 + s * h, tm = t0 + h / 2;
		if (s == 0) {
			xy[0] = cos(t0), xy[1] = sin(t0), w[0] = 1;
		}
		xy[2 * (2 * s + 1)] = cos(tm) / cos(h / 2);
		xy[2 * (2 * s + 1) + 1] = sin(tm) / cos(h / 2);
		w[2 * s + 1] = cos(h / 2);
		xy[2 * (2 * s + 2)] = cos(t0 + h);
		xy[2 * (2 * s + 2) + 1] = sin(t0 + h);
		w[2 * s + 2] = 1;
	}
	for (i = 0; i < 3; i++)
		U[k++] = 0;
	for (s = 1; s < nseg; s++)
		U[k++] = (double)s / nseg, U[k++] = (double)s / nseg;
	for (i = 0; i < 3; i++)
		U[k++] = 1;
	return n;
}

#endif
