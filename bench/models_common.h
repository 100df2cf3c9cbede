/*
 * models_common.h - the workloads of bench_models, shared with the FCL
 * reference program (bench/fcl_models.cpp) so both time the very same
 * queries: a 70,490-triangle torus, a near-surface and free-space point
 * set, and a slow trajectory along the surface (coherent case).
 */
#ifndef PX_BENCH_MODELS_COMMON_H
#define PX_BENCH_MODELS_COMMON_H

#include <math.h>
#include <stdint.h>

#include "mesh_gen.h"

/* Torus in metres: major 0.3, tube 0.1, 265 x 133 quads = 70,490 triangles. */
#define BM_R 0.3
#define BM_r 0.1
#define BM_NU 265
#define BM_NV 133
#define BM_NQ 20000

static inline uint64_t bm_next(uint64_t *s)
{
	uint64_t z = (*s += 0x9e3779b97f4a7c15ull);
	z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
	z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
	return z ^ (z >> 31);
}

static inline double bm_unit(uint64_t *s)
{
	return (double)(bm_next(s) >> 11) * (1.0 / 9007199254740992.0);
}

/* Cold queries: even i near the surface (within 10 % of the tube radius,
 * both sides), odd i anywhere in the box grown by 20 %. */
static inline void bm_cold_point(uint64_t *s, int i, double p[3])
{
	if (i % 2 == 0) {
		double u = 2 * M_PI * bm_unit(s), v = 2 * M_PI * bm_unit(s);
		double rr = BM_r * (1.0 + 0.2 * (bm_unit(s) - 0.5));
		p[0] = (BM_R + rr * cos(v)) * cos(u);
		p[1] = (BM_R + rr * cos(v)) * sin(u);
		p[2] = rr * sin(v);
	} else {
		double e = 1.2 * (BM_R + BM_r);
		p[0] = e * (2 * bm_unit(s) - 1);
		p[1] = e * (2 * bm_unit(s) - 1);
		p[2] = 1.2 * BM_r * 2 * (2 * bm_unit(s) - 1);
	}
}

/* Coherent trajectory: a haptic probe at 1 kHz sliding over the surface
 * at about 0.1 m/s (0.1 mm per query), dipping in and out by 5 mm. */
static inline void bm_traj_point(int i, double p[3])
{
	double t = 1e-3 * i;
	double u = 0.3 * t, v = 1.1 * t + 0.4 * sin(0.7 * t);
	double rr = BM_r + 0.005 * sin(3.0 * t);
	p[0] = (BM_R + rr * cos(v)) * cos(u);
	p[1] = (BM_R + rr * cos(v)) * sin(u);
	p[2] = rr * sin(v);
}

/* Model-to-model workload (bench_models' pair section and fcl_models
 * "pair"): a 4,096-triangle torus (major 0.1, tube 0.03, 64 x 32 quads)
 * at the origin and a 4,096-triangle sphere (radius 0.08, 32 x 64) moved
 * through BM_PAIR_N poses along a circle of radius 0.25 at z = 0.02,
 * 1 mm apart, turning about (1, 1, 0) by 2 mrad per pose. */
#define BM_PAIR_N 2000

static inline void bm_pair_pose(int i, double t[3], double axis[3],
				double *angle)
{
	t[0] = 0.25 * cos(4e-3 * i);
	t[1] = 0.25 * sin(4e-3 * i);
	t[2] = 0.02;
	axis[0] = axis[1] = 1.0 / sqrt(2.0);
	axis[2] = 0.0;
	*angle = 2e-3 * i;
}

#endif
