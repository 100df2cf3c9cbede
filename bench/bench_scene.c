/*
 * bench_scene.c - the loop's scene queries three ways on the shipped
 * example scene (config/examples/haptic_sim.yaml: a NURBS terrain and
 * wall, a scaled closed mesh, a cylinder): plain global queries
 * (px_scene_nearest), coherent ones (hints), and tracked streams
 * (px_scene_nearest_tracked: NURBS models follow the point with
 * px_strack). The same smooth paths at several speeds, each query timed;
 * per-query median, p99 and max, the ratio of the medians to the tracked
 * one, and the answers compared (wrong: differs from the plain query by
 * more than 1e-9 m). Then the haptic proxy renderer's whole step through
 * the coherent and the tracked adapters on the same hand path. Exit
 * status 1 when a tracked or coherent answer was wrong.
 *
 * Run from the source tree (reads the example config). Timings on a
 * shared machine move between runs; ratios in one run are the figures.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "px_config.h"
#include "px_control.h"
#include "px_model.h"
#include "px_scene.h"

#define N 20000

static int64_t t_ns[3][N];
static double dist[3][N];

struct row {
	int64_t med, p99, max;
};

static struct row summarize(int64_t *t)
{
	struct row r;
	qsort(t, N, sizeof(t[0]), cmp_i64);
	r.med = t[N / 2];
	r.p99 = t[N * 99 / 100];
	r.max = t[N - 1];
	return r;
}

/* The hand's path: sums of sines over the terrain and past the wall and
 * the post; speed scales the time, so steps per query scale with it
 * (speed 1: about 0.25 mm a query at 1 kHz, 0.1 % of the 0.24 m scene). */
static px_vec3 path(int k, double speed)
{
	double t = k * 1e-3 * speed;
	return px_v3(0.06 * sin(2 * M_PI * 0.25 * t) + 0.01 * sin(2 * M_PI * 1.7 * t),
		     0.05 * sin(2 * M_PI * 0.35 * t + 0.4),
		     -0.005 + 0.03 * sin(2 * M_PI * 0.5 * t));
}

static int bench_queries(struct px_scene *s, double speed, const char *label)
{
	struct px_scene_tracking *trk = NULL;
	static struct px_scene_hints hints;
	struct px_model_stream_stats st;
	struct row r[3];
	int k, m, wrong = 0, rc;
	double step = 0;

	rc = px_scene_tracking_create(s, NULL, &trk);
	if (rc != PX_OK) {
		fprintf(stderr, "bench_scene: tracking: %s\n", px_strerror(rc));
		return 1;
	}
	px_scene_hints_reset(&hints);
	for (m = 0; m < 3; m++) {
		for (k = 0; k < N; k++) {
			px_vec3 p = path(k, speed);
			struct px_scene_hit h;
			int64_t t0 = now_ns();
			if (m == 0)
				rc = px_scene_nearest(s, p, 1.0, &h);
			else if (m == 1)
				rc = px_scene_nearest_coherent(s, p, 1.0, &hints, &h);
			else
				rc = px_scene_nearest_tracked(s, p, 1.0, trk, &h);
			t_ns[m][k] = now_ns() - t0;
			dist[m][k] = rc == 1 ? h.distance_m : INFINITY;
			if (m == 0 && k > 0)
				step += px_v3_dist(p, path(k - 1, speed));
		}
	}
	for (k = 0; k < N; k++)
		for (m = 1; m < 3; m++)
			if (!(fabs(dist[m][k] - dist[0][k]) <= 1e-9))
				wrong++;
	for (m = 0; m < 3; m++)
		r[m] = summarize(t_ns[m]);
	px_scene_tracking_stats(trk, &st);
	printf("%-10s step %6.1f um | plain %6lld / %6lld / %7lld ns | "
	       "hints %6lld / %6lld / %7lld ns | tracked %5lld / %6lld / %7lld ns | "
	       "plain/tracked %5.1fx hints/tracked %5.1fx | tracked %.1f %% "
	       "(hot %.1f %%), cold %.1f %% | wrong %d\n",
	       label, 1e6 * step / (N - 1), (long long)r[0].med,
	       (long long)r[0].p99, (long long)r[0].max, (long long)r[1].med,
	       (long long)r[1].p99, (long long)r[1].max, (long long)r[2].med,
	       (long long)r[2].p99, (long long)r[2].max,
	       (double)r[0].med / (double)(r[2].med > 0 ? r[2].med : 1),
	       (double)r[1].med / (double)(r[2].med > 0 ? r[2].med : 1),
	       100.0 * (double)st.tracked / (double)(st.queries ? st.queries : 1),
	       100.0 * (double)st.hot / (double)(st.queries ? st.queries : 1),
	       100.0 * (double)st.cold / (double)(st.queries ? st.queries : 1),
	       wrong);
	px_scene_tracking_free(trk);
	return wrong != 0;
}

static int bench_haptic(struct px_scene *s)
{
	struct px_scene_tracking *trk = NULL;
	static struct px_scene_hints hints;
	struct px_control_query q[2];
	struct px_control_haptic_params p;
	struct px_control_haptic h;
	struct px_control_haptic_out out;
	struct row r[2];
	double nq[2] = {0, 0}, fdiff = 0;
	static px_vec3 force[N];
	int k, m, rc;

	rc = px_scene_tracking_create(s, NULL, &trk);
	if (rc != PX_OK)
		return 1;
	px_scene_control_query_coherent(s, &hints, &q[0]);
	px_scene_control_query_tracked(s, trk, &q[1]);
	px_control_haptic_params_default(&p);
	p.renderer = PX_CONTROL_PROXY;
	p.stiffness_n_per_m = 1500;
	p.damping_n_s_per_m = 0.5;
	p.proxy_radius_m = 0.0005;
	p.static_friction = 0.3;
	p.dynamic_friction = 0.2;
	p.max_point_queries = 64;
	p.max_query_distance_m = 0.05;
	for (m = 0; m < 2; m++) {
		px_control_haptic_init(&h, &p, 1000000);
		for (k = 0; k < N; k++) {
			px_vec3 d = path(k, 1.0);
			int64_t t0 = now_ns();
			px_control_haptic_step(&h, &q[m], d, NULL, &out);
			t_ns[m][k] = now_ns() - t0;
			nq[m] += out.point_queries;
			if (m == 0)
				force[k] = out.force_n;
			else if (px_v3_dist(force[k], out.force_n) > fdiff)
				fdiff = px_v3_dist(force[k], out.force_n);
		}
		r[m] = summarize(t_ns[m]);
	}
	printf("haptic proxy step (64 queries max): hints %lld / %lld / %lld ns, "
	       "tracked %lld / %lld / %lld ns (median / p99 / max), ratio %.1fx; "
	       "%.1f queries a step; largest force difference %.2e N\n",
	       (long long)r[0].med, (long long)r[0].p99, (long long)r[0].max,
	       (long long)r[1].med, (long long)r[1].p99, (long long)r[1].max,
	       (double)r[0].med / (double)(r[1].med > 0 ? r[1].med : 1),
	       nq[1] / N, fdiff);
	px_scene_tracking_free(trk);
	/* the answers agree to rounding; the proxy's friction decisions may
	 * still amplify a last-bit difference over a long path, so this is
	 * reported, not judged */
	return 0;
}

int main(void)
{
	static struct px_config_diag diag;
	struct px_config *cfg;
	struct px_scene *s;
	int bad = 0;

	px_config_diag_init(&diag);
	if (px_config_load_file("config/examples/haptic_sim.yaml", &cfg, &diag) !=
		    PX_OK ||
	    px_scene_config_load(cfg, &s, &diag) != PX_OK) {
		px_config_diag_print(&diag, stderr);
		fprintf(stderr, "bench_scene: run from the source tree\n");
		return 1;
	}
	px_config_free(cfg);
	printf("bench_scene: %zu models of config/examples/haptic_sim.yaml, %d "
	       "queries a path; per query median / p99 / max\n",
	       px_scene_count(s), N);
	bad |= bench_queries(s, 0.1, "slow");
	bad |= bench_queries(s, 1.0, "hand");
	bad |= bench_queries(s, 10.0, "fast");
	bad |= bench_haptic(s);
	px_scene_free(s);
	return bad;
}
