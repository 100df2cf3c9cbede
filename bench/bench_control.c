/*
 * Control benchmark: time per cycle (median, p99, max) and queries per
 * cycle of the proxy and penalty renderers and of the avoidance step
 * (for avoidance "in contact" = inside the influence distance),
 * against a small analytic scene (sphere, thin plate, floor), so the
 * figures are the control code's own cost plus cheap queries. Prints
 * figures only; nothing here is a pass/fail test.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "px_control.h"

#include "bench_util.h"

static double clampd(double x, double lo, double hi)
{
	return x < lo ? lo : (x > hi ? hi : x);
}

/* sphere r 0.04 at (0.05, 0, 0), plate 0.1 x 0.1 at z = 0.02, floor z = -0.05 */
static int scene_point(void *ctx, px_vec3 p, double maxd,
		       struct px_control_hit *o)
{
	px_vec3 v = px_v3_sub(p, px_v3(0.05, 0, 0)), c;
	double l = px_v3_norm(v), d;
	(void)ctx;
	(void)maxd;
	o->valid = true;
	o->two_sided = false;
	o->normal = l > 0 ? px_v3_scale(v, 1 / l) : px_v3(0, 0, 1);
	o->distance_m = l - 0.04;
	o->point_m = px_v3_madd(px_v3(0.05, 0, 0), o->normal, 0.04);
	c = px_v3(clampd(p.x, -0.1, 0.0), clampd(p.y, -0.05, 0.05), 0.02);
	d = px_v3_dist(p, c);
	if (d < o->distance_m && d > 0) {
		o->two_sided = true;
		o->distance_m = d;
		o->point_m = c;
		o->normal = px_v3_scale(px_v3_sub(p, c), 1 / d);
	}
	if (p.z + 0.05 < o->distance_m) {
		o->two_sided = false;
		o->distance_m = p.z + 0.05;
		o->point_m = px_v3(p.x, p.y, -0.05);
		o->normal = px_v3(0, 0, 1);
	}
	return PX_OK;
}

#define N 20000

static int64_t t_ns[N];

static void report(const char *what, double queries, double contact)
{
	qsort(t_ns, N, sizeof(t_ns[0]), cmp_i64);
	printf("%-28s median %6lld ns  p99 %6lld ns  max %7lld ns  "
	       "queries/cycle %.1f  in contact %.0f%%\n",
	       what, (long long)t_ns[N / 2], (long long)t_ns[N * 99 / 100],
	       (long long)t_ns[N - 1], queries, 100 * contact);
}

static void bench_haptic(int renderer, double mu, const char *name)
{
	struct px_control_query q = {scene_point, NULL, NULL};
	struct px_control_haptic_params p;
	struct px_control_haptic h;
	struct px_control_haptic_out out;
	double nq = 0, nc = 0;
	int k;
	px_control_haptic_params_default(&p);
	p.renderer = renderer;
	p.static_friction = mu;
	p.dynamic_friction = 0.7 * mu;
	px_control_haptic_init(&h, &p, 1000000);
	for (k = 0; k < N; k++) {
		double t = k * 1e-3;
		/* a hand stroking over the plate, through it and into the
		 * sphere and floor, about 0.3 m/s */
		px_vec3 d = px_v3(0.08 * sin(2 * M_PI * 0.4 * t) - 0.03,
				  0.04 * sin(2 * M_PI * 0.7 * t),
				  0.04 * sin(2 * M_PI * 0.9 * t));
		int64_t t0 = now_ns();
		px_control_haptic_step(&h, &q, d, NULL, &out);
		t_ns[k] = now_ns() - t0;
		nq += out.point_queries;
		nc += out.contact;
	}
	report(name, nq / N, nc / N);
}

static void bench_avoid(void)
{
	struct px_control_query q = {scene_point, NULL, NULL};
	struct px_control_chain c;
	struct px_control_avoid_params p;
	struct px_control_avoid_out out;
	double qa[6] = {0}, qd[6] = {0.2, -0.1, 0.3, 0.1, 0.2, -0.2}, nq = 0,
	       nc = 0;
	int k, i;
	px_control_chain_init(&c, px_pose_identity());
	for (i = 0; i < 6; i++) {
		px_control_chain_add_dh(&c, PX_CONTROL_REVOLUTE, 0.1, i % 2 ? 0 : M_PI / 2,
					0.05, 0);
		px_control_chain_add_capsule(&c, i + 1, px_v3(-0.1, 0, 0),
					     px_v3(0, 0, 0), 0.02);
	}
	px_control_avoid_params_default(&p);
	for (k = 0; k < N; k++) {
		int64_t t0;
		for (i = 0; i < 6; i++)
			qa[i] = sin(k * 1e-3 * (i + 1));
		t0 = now_ns();
		px_control_avoid_step(&c, &p, &q, qa, qd, 1000000, &out);
		t_ns[k] = now_ns() - t0;
		nq += out.point_queries;
		nc += out.min_clearance_m < p.influence_distance_m;
	}
	report("avoid 6 joints, 6 capsules", nq / N, nc / N);
}

int main(void)
{
	printf("control: %d cycles each, analytic scene (point queries only)\n", N);
	bench_haptic(PX_CONTROL_PROXY, 0.0, "proxy, frictionless");
	bench_haptic(PX_CONTROL_PROXY, 0.5, "proxy, mu_s 0.5");
	bench_haptic(PX_CONTROL_PENALTY, 0.0, "penalty");
	bench_avoid();
	return 0;
}
