/*
 * sheet_gen.h - the wavy bicubic sheet the NURBS benchmarks and tests
 * share: n x n control points (n <= 7) over about [-s, s]^2, clamped
 * uniform knots, heights s * amp * sin(2.2 x + 0.3) cos(2.7 y - 0.2), and
 * weights 0.6 to 1.5 over the net for its rational form.
 */
#ifndef PX_SHEET_GEN_H
#define PX_SHEET_GEN_H

#include <math.h>

/* Fill the knots U (n + 4, both directions), the control points xyz
 * (3 n^2, u fastest) and the weights w (n^2). */
static inline void sheet_net(int n, double s, double amp, double *U, double *xyz, double *w)
{
	int i, j, p = 3;
	for (i = 0; i <= p; i++) {
		U[i] = 0.0;
		U[n + i] = 1.0;
	}
	for (i = p + 1; i < n; i++)
		U[i] = (double)(i - p) / (n - p);
	for (j = 0; j < n; j++)
		for (i = 0; i < n; i++) {
			double x = -1 + 2.0 * i / (n - 1), y = -1 + 2.0 * j / (n - 1);
			double *q = &xyz[3 * (j * n + i)];
			q[0] = s * x;
			q[1] = s * (y + 0.1 * sin(3 * x));
			q[2] = s * amp * sin(2.2 * x + 0.3) * cos(2.7 * y - 0.2);
			w[j * n + i] = 0.6 + 0.9 * ((i * 7 + j * 3) % 5) / 4.0;
		}
}

#endif
