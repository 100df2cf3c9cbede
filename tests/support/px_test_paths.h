/*
 * px_test_paths.h - moving-point trajectories shared by the tracking
 * tests and benchmarks (header only: the benchmarks build with -Itests/support
 * but do not link the test sources, so the random source is passed in).
 *
 * A path is n points inside box, consecutive points about step apart:
 *  - PX_PATH_RANDOM: a smooth random walk (velocity damped and kicked by
 *    normal noise every point, reflected at the box);
 *  - PX_PATH_SINES: sums of three sinusoids per coordinate around the box
 *    centre, sampled at a constant parameter step.
 */
#ifndef PX_TEST_PATHS_H
#define PX_TEST_PATHS_H

#include <math.h>

#include "px_math.h"

enum { PX_PATH_RANDOM = 0, PX_PATH_SINES = 1 };

struct px_path_opts {
	double (*unit)(void);   /* uniform in [0, 1) */
	double (*normal)(void); /* standard normal */
	double damp, kick;      /* random walk: velocity damping, noise */
	double period;          /* sines: parameter step = step / (period *
				 * half width of the box in x or y) */
};

static inline void px_test_path(px_vec3 *q, int n, int kind, px_aabb box,
				double step, const struct px_path_opts *o)
{
	px_vec3 c = px_aabb_center(&box);
	px_vec3 h = px_v3_scale(px_v3_sub(box.max, box.min), 0.5);
	px_vec3 pos = c, vel;
	double amp[3][3], frq[3][3], ph[3][3], tt = 0;
	int i, j, k;
	vel.x = o->normal();
	vel.y = o->normal();
	vel.z = o->normal();
	for (i = 0; i < 3; i++)
		for (j = 0; j < 3; j++) {
			amp[i][j] = 0.2 + 0.25 * o->unit();
			frq[i][j] = 0.5 + 2.5 * o->unit();
			ph[i][j] = 2 * M_PI * o->unit();
		}
	for (k = 0; k < n; k++) {
		if (kind == PX_PATH_RANDOM) {
			double nv, *pp = &pos.x, *vv = &vel.x;
			const double *cc = &c.x, *hh = &h.x;
			px_vec3 kick;
			kick.x = o->kick * o->normal();
			kick.y = o->kick * o->normal();
			kick.z = o->kick * o->normal();
			vel = px_v3_add(px_v3_scale(vel, o->damp), kick);
			nv = px_v3_norm(vel);
			pos = px_v3_add(pos, px_v3_scale(vel, step / nv));
			for (i = 0; i < 3; i++)
				if (fabs(pp[i] - cc[i]) > hh[i]) {
					pp[i] = cc[i] + (pp[i] > cc[i] ? hh[i] : -hh[i]);
					vv[i] = -vv[i];
				}
		} else {
			double v[3];
			for (i = 0; i < 3; i++) {
				v[i] = 0;
				for (j = 0; j < 3; j++)
					v[i] += amp[i][j] * sin(frq[i][j] * tt + ph[i][j]);
			}
			tt += step / (o->period * fmax(h.x, h.y));
			pos = px_v3_add(c, px_v3(v[0] * h.x, v[1] * h.y, v[2] * h.z));
		}
		q[k] = pos;
	}
}

#endif
