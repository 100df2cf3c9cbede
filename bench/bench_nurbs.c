/* Evaluation cost (best of REPS runs, thread CPU time) of NURBS curves and surfaces (the inner step of every
 * Newton iteration of the distance core). Prints nanoseconds per call. */
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "px_nurbs.h"

static double now_ns(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
	return ts.tv_sec * 1e9 + ts.tv_nsec;
}

static unsigned long long rng = 88172645463325252ull;
static double urand(void)
{
	rng ^= rng << 13;
	rng ^= rng >> 7;
	rng ^= rng << 17;
	return (rng >> 11) * (1.0 / 9007199254740992.0);
}

#define N 20000
#define REPS 15

int main(void)
{
	static unsigned char buf[1 << 20];
	static double prm[2 * N];
	double U[16], V[16], xyz[3 * 64], w[64], sink = 0, t0, t1;
	struct px_arena a;
	struct px_nurbs_curve c;
	struct px_nurbs_surf s;
	int i, order, rat;

	for (rat = 0; rat < 2; rat++) {
		px_arena_init(&a, buf, sizeof(buf));
		/* cubic curve, 8 points; bicubic patch 8 x 8, clamped */
		for (i = 0; i < 12; i++)
			U[i] = V[i] = i < 4 ? 0 : (i > 7 ? 1 : (i - 3) / 5.0);
		for (i = 0; i < 3 * 64; i++)
			xyz[i] = urand();
		for (i = 0; i < 64; i++)
			w[i] = rat ? 0.5 + urand() : 1.0;
		if (px_nurbs_curve_init(&c, &a, 3, 8, U, 12, xyz, w, NULL) ||
		    px_nurbs_surf_init(&s, &a, 3, 3, 8, 8, U, 12, V, 12, xyz, w,
				       NULL))
			return 1;
		for (i = 0; i < 2 * N; i++)
			prm[i] = urand();
		for (order = 0; order <= 3; order++) {
			px_vec3 d[4];
			double best = 1e300;
			int rep;
			for (rep = 0; rep < REPS; rep++) {
				t0 = now_ns();
				for (i = 0; i < N; i++) {
					px_nurbs_curve_eval(&c, prm[i], order, d);
					sink += d[order].x;
				}
				t1 = now_ns();
				if (t1 - t0 < best)
					best = t1 - t0;
			}
			printf("curve  cubic    %s order %d: %6.1f ns/eval\n",
			       rat ? "rational" : "poly    ", order, best / N);
		}
		for (order = 0; order <= 3; order++) {
			struct px_nurbs_surf_derivs d;
			double best = 1e300;
			int rep;
			for (rep = 0; rep < REPS; rep++) {
				t0 = now_ns();
				for (i = 0; i < N; i++) {
					px_nurbs_surf_eval(&s, prm[2 * i],
							   prm[2 * i + 1], order,
							   &d);
					sink += d.s.x;
				}
				t1 = now_ns();
				if (t1 - t0 < best)
					best = t1 - t0;
			}
			printf("surf   bicubic  %s order %d: %6.1f ns/eval\n",
			       rat ? "rational" : "poly    ", order, best / N);
		}
	}
	printf("(checksum %g)\n", sink);
	return 0;
}
