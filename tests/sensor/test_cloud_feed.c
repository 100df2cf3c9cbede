/*
 * sensor/: clouds handed from a producer thread to the cycle
 * (px_cloud_feed.h) and the simulated depth camera (px_depth_sim.h).
 * The ring's rules one step at a time (newest frame not in the future,
 * slots reused only behind the held frame, full ring refused, empty
 * frames far away); the camera's points on the obstacle's surface and
 * only on its side facing the camera, the motion in and out, the same
 * points for the same frame; and a producer thread swapping clouds
 * while the cycle takes them, replaces the robot's obstacle and runs
 * the avoidance step: thousands of cycles without a heap call in the
 * cycle's thread.
 */
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "px_alloc_count.h"
#include "px_cloud.h"
#include "px_cloud_feed.h"
#include "px_depth_sim.h"
#include "px_features.h"
#include "px_test.h"
#include "px_urdf.h"

static void cloud_at(double *xyz, int n, double x)
{
	int i;
	for (i = 0; i < n; i++) {
		xyz[3 * i] = x + 0.01 * i;
		xyz[3 * i + 1] = 0.02 * i;
		xyz[3 * i + 2] = 1.0;
	}
}

static double first_x(const struct px_model *m)
{
	px_vec3 p = px_v3(0, 0, 0);
	PX_CHECK_INT_EQ(px_cloud_point(m, 0, &p), PX_OK);
	return p.x;
}

static void test_feed_rules(void)
{
	struct px_cloud_feed *f;
	struct px_cloud_feed_stats st;
	struct px_model *m = (struct px_model *)1;
	double xyz[30];
	int64_t stamp = -1;
	int i;
	PX_CHECK_INT_EQ(px_cloud_feed_create(2, 10, 0, &f), PX_E_RANGE);
	PX_CHECK_INT_EQ(px_cloud_feed_create(4, 0, 0, &f), PX_E_RANGE);
	PX_CHECK_INT_EQ(px_cloud_feed_create(4, 10, 0, &f), PX_OK);
	PX_CHECK_INT_EQ(px_cloud_feed_take(f, 100, &m, &stamp), 0);
	PX_CHECK(m == NULL);
	PX_CHECK_INT_EQ(px_cloud_feed_space(f), 4);
	/* frames 0..3 stamped 10, 20, 30, 40 */
	for (i = 0; i < 4; i++) {
		cloud_at(xyz, 10, i);
		PX_CHECK_INT_EQ(px_cloud_feed_publish(f, xyz, 10, 10 * (i + 1)), PX_OK);
	}
	/* nothing held: frame 4 would overwrite frame 0, which the
	 * consumer may still take */
	PX_CHECK_INT_EQ(px_cloud_feed_space(f), 0);
	PX_CHECK_INT_EQ(px_cloud_feed_publish(f, xyz, 10, 50), PX_E_AGAIN);
	PX_CHECK_INT_EQ(px_cloud_feed_take(f, 5, &m, &stamp), 0);     /* all in the future */
	PX_CHECK_INT_EQ(px_cloud_feed_take(f, 25, &m, &stamp), 1);    /* frame 1 */
	PX_CHECK_INT_EQ(stamp, 20);
	PX_CHECK_NEAR(first_x(m), 1.0, 0);
	PX_CHECK_INT_EQ(px_cloud_feed_take(f, 29, &m, &stamp), 0);    /* held */
	PX_CHECK_INT_EQ(stamp, 20);
	PX_CHECK_NEAR(first_x(m), 1.0, 0);
	/* held frame 1: frame 4 may reuse frame 0's slot, not frame 5
	 * (frame 1's) */
	PX_CHECK_INT_EQ(px_cloud_feed_space(f), 1);
	cloud_at(xyz, 3, 4);
	PX_CHECK_INT_EQ(px_cloud_feed_publish(f, xyz, 3, 50), PX_OK);
	PX_CHECK_INT_EQ(px_cloud_feed_publish(f, xyz, 3, 60), PX_E_AGAIN);
	PX_CHECK_INT_EQ(px_cloud_feed_publish(f, xyz, 3, 45), PX_E_RANGE); /* earlier */
	PX_CHECK_INT_EQ(px_cloud_feed_publish(f, xyz, 11, 70), PX_E_RANGE); /* too many */
	PX_CHECK_INT_EQ(px_cloud_feed_take(f, 1000, &m, &stamp), 1);  /* newest: frame 4 */
	PX_CHECK_INT_EQ(stamp, 50);
	PX_CHECK_NEAR(first_x(m), 4.0, 0);
	PX_CHECK_INT_EQ(px_cloud_point_count(m), 3);
	PX_CHECK(px_cloud_feed_model(f) == m);
	PX_CHECK_INT_EQ(px_cloud_feed_space(f), 3);
	/* nothing in view: one point far away */
	PX_CHECK_INT_EQ(px_cloud_feed_publish(f, NULL, 0, 80), PX_OK);
	PX_CHECK_INT_EQ(px_cloud_feed_take(f, 80, &m, &stamp), 1);
	PX_CHECK_INT_EQ(px_cloud_point_count(m), 1);
	{
		px_vec3 p;
		PX_CHECK_INT_EQ(px_cloud_point(m, 0, &p), PX_OK);
		PX_CHECK(p.z >= PX_CLOUD_FEED_FAR_M);
	}
	px_cloud_feed_stats(f, &st);
	PX_CHECK_INT_EQ(st.published, 6);
	PX_CHECK_INT_EQ(st.taken, 3);
	PX_CHECK_INT_EQ(st.refused, 2);
	PX_CHECK_INT_EQ(st.stamp_ns, 80);
	PX_CHECK_INT_EQ(st.points, 0);
	px_cloud_feed_free(f);
}

/* A reader beside the consumer pins the held frame: its slot is not
 * rebuilt while pinned, even after the consumer moved on. */
static void test_pin(void)
{
	struct px_cloud_feed *f;
	struct px_model *m, *held;
	double xyz[30];
	uint64_t frame = 99;
	int i;
	PX_CHECK_INT_EQ(px_cloud_feed_create(4, 10, 0, &f), PX_OK);
	PX_CHECK(px_cloud_feed_pin(f, &frame) == NULL); /* nothing held */
	PX_CHECK_INT_EQ(frame, 0);
	px_cloud_feed_unpin(f);
	for (i = 0; i < 4; i++) {
		cloud_at(xyz, 10, i);
		PX_CHECK_INT_EQ(px_cloud_feed_publish(f, xyz, 10, 10 * (i + 1)), PX_OK);
	}
	PX_CHECK_INT_EQ(px_cloud_feed_take(f, 15, &held, NULL), 1); /* frame 0 */
	m = px_cloud_feed_pin(f, &frame);
	PX_CHECK(m == held);
	PX_CHECK_INT_EQ(frame, 1);
	/* the consumer moves on to frame 3: frames 4..6 could reuse the
	 * slots of 0..2, but frame 0's is pinned */
	PX_CHECK_INT_EQ(px_cloud_feed_take(f, 1000, &held, NULL), 1);
	PX_CHECK(held != m);
	PX_CHECK_INT_EQ(px_cloud_feed_space(f), 0);
	PX_CHECK_INT_EQ(px_cloud_feed_publish(f, xyz, 10, 50), PX_E_AGAIN);
	PX_CHECK_INT_EQ(px_cloud_point_count(m), 10);
	PX_CHECK_NEAR(first_x(m), 0.0, 0);
	px_cloud_feed_unpin(f);
	PX_CHECK_INT_EQ(px_cloud_feed_space(f), 3);
	PX_CHECK_INT_EQ(px_cloud_feed_publish(f, xyz, 10, 50), PX_OK);
	/* the newest held frame pinned: its number grew */
	m = px_cloud_feed_pin(f, &frame);
	PX_CHECK(m == held && frame == 4);
	px_cloud_feed_unpin(f);
	px_cloud_feed_free(f);
}

/* Distance from p to the surface of the box [lo, hi]. */
static double box_surface(px_vec3 p, px_vec3 lo, px_vec3 hi)
{
	double d[3], out = 0, in = INFINITY, pp[3] = {p.x, p.y, p.z};
	double l[3] = {lo.x, lo.y, lo.z}, h[3] = {hi.x, hi.y, hi.z};
	int k, inside = 1;
	for (k = 0; k < 3; k++) {
		d[k] = fmax(l[k] - pp[k], pp[k] - h[k]);
		if (d[k] > 0) {
			inside = 0;
			out += d[k] * d[k];
		}
		in = fmin(in, -d[k]);
	}
	return inside ? in : sqrt(out);
}

/* The camera sees the box's near faces: every point on the surface
 * (noise 0), on a face whose outward normal faces the camera; the box
 * travels in and out; the same frame twice gives the same points. */
static void test_depth_box(void)
{
	struct px_depth_sim_params p;
	struct px_depth_sim *s;
	static double xyz[3 * 64 * 48], again[3 * 64 * 48];
	size_t n, n2, i;
	double ts[3] = {0.0, 4.0, 5.0};
	int k;
	px_depth_sim_params_default(&p);
	p.noise_m = 0;
	p.camera = px_control_pose_from_xyz_rpy(px_v3(0, -1.5, 1.0), px_v3(-1.9, 0, 0));
	p.from_m = px_v3(2.5, 0.5, 0.5);
	p.to_m = px_v3(0.3, 0.5, 0.5);
	p.size_m = px_v3(0.15, 0.1, 0.3);
	p.start_s = 1.0;
	p.period_s = 6.0;
	PX_CHECK_INT_EQ(px_depth_sim_create(&p, &s), PX_OK);
	PX_CHECK_INT_EQ(px_depth_sim_max_points(s), 64 * 48);
	PX_CHECK_NEAR(px_depth_sim_motion(s, 0.5), 0, 0);
	PX_CHECK_NEAR(px_depth_sim_motion(s, 4.0), 1, 1e-12);
	PX_CHECK_NEAR(px_depth_sim_motion(s, 7.5), 0, 0);
	PX_CHECK_INT_EQ(px_depth_sim_capture(s, 0, 0, xyz, 10, &n), PX_E_NOSPC);
	for (k = 0; k < 3; k++) {
		double w = px_depth_sim_motion(s, ts[k]);
		px_vec3 c = px_v3_lerp(p.from_m, p.to_m, w);
		px_vec3 lo = px_v3_sub(c, p.size_m), hi = px_v3_add(c, p.size_m);
		PX_CHECK_INT_EQ(px_depth_sim_capture(s, ts[k], k, xyz, 64 * 48, &n), PX_OK);
		if (k == 1)
			PX_CHECK_MSG(n > 100, "%zu points of the box in view", n);
		for (i = 0; i < n; i++) {
			px_vec3 q = px_v3(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
			PX_CHECK_MSG(fabs(box_surface(q, lo, hi)) < 1e-9, "point %zu off the box", i);
			/* seen from the camera: the segment to it stays
			 * outside the box */
			PX_CHECK(box_surface(px_v3_lerp(p.camera.t, q, 0.999), lo, hi) > 0);
		}
	}
	/* noise: the same frame, the same points; another frame, others */
	px_depth_sim_free(s);
	p.noise_m = 0.003;
	PX_CHECK_INT_EQ(px_depth_sim_create(&p, &s), PX_OK);
	PX_CHECK_INT_EQ(px_depth_sim_capture(s, 4.0, 7, xyz, 64 * 48, &n), PX_OK);
	PX_CHECK(n > 100);
	PX_CHECK_INT_EQ(px_depth_sim_capture(s, 4.0, 7, again, 64 * 48, &n2), PX_OK);
	PX_CHECK_INT_EQ(n, n2);
	PX_CHECK(memcmp(xyz, again, 3 * n * sizeof(double)) == 0);
	PX_CHECK_INT_EQ(px_depth_sim_capture(s, 4.0, 8, again, 64 * 48, &n2), PX_OK);
	PX_CHECK(memcmp(xyz, again, 3 * n * sizeof(double)) != 0);
	px_depth_sim_free(s);
	p.width = 0;
	PX_CHECK_INT_EQ(px_depth_sim_create(&p, &s), PX_E_RANGE);
	p.width = 64;
	p.kind = 7;
	PX_CHECK_INT_EQ(px_depth_sim_create(&p, &s), PX_E_INVAL);
}

/* The swinging arm: points on the capsule's surface (noise 0). */
static void test_depth_arm(void)
{
	struct px_depth_sim_params p;
	struct px_depth_sim *s;
	static double xyz[3 * 80 * 60];
	size_t n, i;
	double w, ang;
	px_vec3 a, b;
	px_depth_sim_params_default(&p);
	p.kind = PX_DEPTH_SIM_ARM;
	p.noise_m = 0;
	p.width = 80;
	p.height = 60;
	p.camera = px_control_pose_from_xyz_rpy(px_v3(0, 0, 3.0), px_v3(M_PI, 0, 0));
	p.from_m = px_v3(0.5, 0.5, 0.4);
	p.to_m = px_v3(0.0, 1.5, 0);
	p.size_m = px_v3(0.6, 0.05, 0);
	p.period_s = 4.0;
	PX_CHECK_INT_EQ(px_depth_sim_create(&p, &s), PX_OK);
	PX_CHECK_INT_EQ(px_depth_sim_capture(s, 1.3, 0, xyz, 80 * 60, &n), PX_OK);
	PX_CHECK_MSG(n > 30, "%zu points of the arm", n);
	w = px_depth_sim_motion(s, 1.3);
	ang = 0.0 + w * 1.5;
	a = p.from_m;
	b = px_v3_add(a, px_v3(0.6 * cos(ang), 0.6 * sin(ang), 0));
	for (i = 0; i < n; i++) {
		px_vec3 q = px_v3(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
		px_vec3 ab = px_v3_sub(b, a);
		double t = fmin(1, fmax(0, px_v3_dot(px_v3_sub(q, a), ab) / px_v3_dot(ab, ab)));
		double d = px_v3_norm(px_v3_sub(q, px_v3_lerp(a, b, t))) - 0.05;
		PX_CHECK_MSG(fabs(d) < 1e-9, "point %zu at %g from the arm's surface", i, d);
		PX_CHECK(q.z >= a.z - 1e-9); /* seen from above */
	}
	px_depth_sim_free(s);
}

/* ---- swapping while running -------------------------------------------- */

struct producer {
	struct px_cloud_feed *f;
	atomic_int stop;
	atomic_llong now;
	int published;
};

static void *produce(void *arg)
{
	struct producer *pr = arg;
	static double xyz[3 * 400];
	int64_t stamp = 0;
	uint64_t k = 0;
	while (!atomic_load(&pr->stop)) {
		int n = 20 + (int)(k % 60), i, rc;
		if (stamp > atomic_load(&pr->now) + 20000000) {
			struct timespec ts = {0, 100000};
			nanosleep(&ts, NULL);
			continue;
		}
		for (i = 0; i < n; i++) {
			double t = 0.01 * (double)k;
			xyz[3 * i] = 0.5 + 0.3 * cos(t) + 0.001 * i;
			xyz[3 * i + 1] = 0.3 * sin(t) + 0.3;
			xyz[3 * i + 2] = 0.2 + 0.0005 * i;
		}
		rc = px_cloud_feed_publish(pr->f, xyz, (size_t)n, stamp);
		if (rc == PX_E_AGAIN) {
			struct timespec ts = {0, 50000};
			nanosleep(&ts, NULL);
			continue;
		}
		PX_CHECK_INT_EQ(rc, PX_OK);
		pr->published++;
		stamp += 5000000;
		k++;
	}
	return NULL;
}

/* A producer thread publishes a new cloud every 5 ms of the cycle's
 * clock (up to 20 ms ahead); the cycle (this thread) takes the newest,
 * replaces the robot's obstacle by it and runs the avoidance step, 4000
 * cycles of 1 ms: no heap call here, and every answer measured against
 * the cloud held. */
static void test_swap_while_running(void)
{
	struct px_urdf_robot *r;
	struct px_urdf *u = NULL;
	struct px_urdf_error e;
	struct px_urdf_opts o;
	const char *pk[1] = {"config/examples/robots"};
	struct px_control_avoid_params ap;
	struct px_urdf_avoid_out out;
	struct producer pr;
	pthread_t th;
	struct px_model *obs[1], *held = NULL, *first;
	double far_pt[3] = {0, 0, 50}, q[6] = {0, 0.1, -0.2, 0, 0, 0}, qn[6] = {0.3, 0, 0, 0, 0, 0};
	uint64_t a, allocs = 0;
	int64_t last_stamp = -1;
	int cyc, swaps = 0, j;
	PX_NEEDS(XML);
	PX_NEEDS(ASSIMP);
	memset(&o, 0, sizeof(o));
	o.package_paths = pk;
	o.n_package_paths = 1;
	PX_CHECK_MSG(px_urdf_load("config/examples/robots/arm6/arm6.urdf", &o, &u, &e) == PX_OK,
		     "%s", e.msg);
	PX_CHECK_INT_EQ(px_urdf_robot_create(u, "base_link", "tool0", px_pose_identity(), &r, &e),
			PX_OK);
	px_urdf_free(u);
	PX_CHECK_INT_EQ(px_cloud_model(far_pt, 1, 0, NULL, &first), PX_OK);
	obs[0] = first;
	PX_CHECK_INT_EQ(px_urdf_robot_set_obstacles(r, obs, 1), PX_OK);
	PX_CHECK_INT_EQ(px_urdf_robot_set_self(r, NULL, 0, NULL), 15);
	px_control_avoid_params_default(&ap);
	ap.approach_only = true;
	memset(&pr, 0, sizeof(pr));
	PX_CHECK_INT_EQ(px_cloud_feed_create(4, 400, 0, &pr.f), PX_OK);
	atomic_init(&pr.stop, 0);
	atomic_init(&pr.now, 0);
	PX_CHECK_INT_EQ(pthread_create(&th, NULL, produce, &pr), 0);
	for (cyc = 0; cyc < 4000; cyc++) {
		int64_t now = (int64_t)cyc * 1000000, stamp;
		struct px_model *m;
		int took;
		atomic_store(&pr.now, now);
		a = px_alloc_region_begin();
		took = px_cloud_feed_take(pr.f, now, &m, &stamp);
		if (took == 1)
			px_urdf_robot_replace_obstacle(r, 0, m);
		PX_CHECK_INT_EQ(px_urdf_avoid_step(r, &ap, NULL, 1, q, qn, 1000000, &out), PX_OK);
		allocs += px_alloc_region_end(a);
		PX_CHECK(took >= 0);
		if (took == 1) {
			PX_CHECK(stamp > last_stamp && stamp <= now);
			last_stamp = stamp;
			held = m;
			swaps++;
		}
		if (held && out.closest.body >= 0 && out.closest.obstacle == 0) {
			/* the answer is the held cloud's: its obstacle point
			 * is one of its points */
			struct px_model_result res;
			PX_CHECK_INT_EQ(px_model_query(held, out.closest.point_obstacle, &res), 1);
			PX_CHECK(res.distance < 1e-9);
		}
		for (j = 0; j < 6; j++)
			q[j] += out.cmd.qdot[j] * 1e-3;
		if (cyc % 50 == 0) {
			/* the producer gets the CPU now and then */
			struct timespec ts = {0, 20000};
			nanosleep(&ts, NULL);
		}
	}
	atomic_store(&pr.stop, 1);
	pthread_join(th, NULL);
	PX_CHECK_INT_EQ(allocs, 0);
	PX_CHECK_MSG(swaps > 100, "only %d swaps (%d published)", swaps, pr.published);
	px_urdf_robot_free(r);
	px_cloud_feed_free(pr.f);
	px_model_free(first);
}

/* The camera's own thread feeds a feed ahead of a clock; the frames
 * come stamped at the frame rate, in order. */
static void test_depth_thread(void)
{
	struct px_depth_sim_params p;
	struct px_depth_sim *s;
	struct px_cloud_feed *f;
	int64_t now, last = -1, stamp;
	int takes = 0, spins;
	px_depth_sim_params_default(&p);
	p.width = 32;
	p.height = 24;
	p.from_m = p.to_m = px_v3(0, 0, 1.5);
	PX_CHECK_INT_EQ(px_depth_sim_create(&p, &s), PX_OK);
	PX_CHECK_INT_EQ(px_cloud_feed_create(4, px_depth_sim_max_points(s), 0, &f), PX_OK);
	PX_CHECK_INT_EQ(px_depth_sim_start(s, f, 50000000), PX_OK);
	PX_CHECK_INT_EQ(px_depth_sim_start(s, f, 50000000), PX_E_STATE);
	for (now = 1000000000; now < 1000000000 + 1000000000LL; now += 10000000) {
		struct px_model *m;
		px_depth_sim_clock(s, now);
		for (spins = 0; spins < 2000; spins++) {
			int took = px_cloud_feed_take(f, now, &m, &stamp);
			if (took == 1 || (took == 0 && stamp + 40000000 > now))
				break;
			struct timespec ts = {0, 100000};
			nanosleep(&ts, NULL);
		}
		if (stamp != last) {
			PX_CHECK(stamp > last && stamp <= now);
			{
				/* on the 30 Hz grid from the first clock */
				long long k = llround((double)(stamp - 1000000000) * 30e-9);
				PX_CHECK_INT_EQ(stamp - 1000000000, llround((double)k * 1e9 / 30));
			}
			last = stamp;
			takes++;
		}
	}
	px_depth_sim_stop(s);
	PX_CHECK_MSG(takes >= 25, "%d frames taken over 1 s at 30 Hz", takes);
	PX_CHECK_INT_EQ(px_depth_sim_error(s), 0);
	PX_CHECK(px_depth_sim_frames(s) >= 30);
	px_depth_sim_free(s);
	px_cloud_feed_free(f);
}

static const struct px_test tests[] = {
	PX_T(test_feed_rules),
	PX_T(test_pin),
	PX_T(test_depth_box),
	PX_T(test_depth_arm),
	PX_T(test_swap_while_running),
	PX_T(test_depth_thread),
};
PX_TEST_MAIN(tests)
