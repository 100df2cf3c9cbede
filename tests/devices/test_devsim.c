/* Device layer and the simulated haptic device: hand-off between threads,
 * staleness, status messages, the arm's physics against closed forms,
 * every fault kind reaching the status and the loop watchdog, and
 * allocation-free cycles on the virtual clock. */
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "px_alloc_count.h"
#include "px_dev.h"
#include "px_loop.h"
#include "px_sim.h"
#include "px_test.h"
#include "px_test_dev.h"

/* ---- a bare back end fed by hand or by a thread ------------------------ */

static const struct px_dev_ops manual_ops = {
	.backend = "manual",
	.caps = PX_DEV_CAP_POSE,
};

static void test_staleness_and_age(void)
{
	struct px_dev_config c;
	struct px_dev *d;
	struct px_pose_sample s;
	double a[6] = {0.1, 0.2, 0.3, 0, 0, 0};
	px_dev_config_default(&c);
	c.name = "manual0";
	c.stale_timeout_ns = 20000000;
	PX_CHECK_INT_EQ(px_dev_create(&manual_ops, &c, 0, &d), PX_OK);
	PX_CHECK_INT_EQ(px_dev_start(d), PX_OK);
	PX_CHECK_INT_EQ(px_dev_pose_read(d, 1000, &s), 0);
	PX_CHECK(!s.valid && s.stale && s.seq == 0);
	PX_CHECK_INT_EQ(px_dev_feed_axes(d, a, 7u, 1, 1, 5000000), 1);
	PX_CHECK_INT_EQ(px_dev_pose_read(d, 8000000, &s), 1);
	PX_CHECK(s.valid && !s.stale && s.fresh);
	PX_CHECK_INT_EQ(s.age_ns, 3000000);
	PX_CHECK_INT_EQ(s.seq, 1);
	PX_CHECK_INT_EQ(s.buttons, 1);
	PX_CHECK_NEAR(s.pos_m.y, 0.2, 0);
	PX_CHECK_NEAR(s.q.w, 1.0, 0);
	/* a 1 kHz loop reading a slower device: same sample, age grows */
	PX_CHECK_INT_EQ(px_dev_pose_read(d, 9000000, &s), 0);
	PX_CHECK(!s.fresh && !s.stale);
	PX_CHECK_INT_EQ(s.age_ns, 4000000);
	PX_CHECK_INT_EQ(px_dev_pose_read(d, 25000001, &s), 0);
	PX_CHECK(s.stale && s.valid);
	/* velocity from the next position sample; rotation vector to q */
	a[0] = 0.2;
	a[3] = M_PI / 2;
	PX_CHECK_INT_EQ(px_dev_feed_axes(d, a, 0x3fu, 0, 0, 15000000), 1);
	PX_CHECK_INT_EQ(px_dev_pose_read(d, 15000000, &s), 1);
	PX_CHECK_NEAR(s.vel_m_s.x, 0.1 / 0.01, 1e-9);
	PX_CHECK_NEAR(s.q.w, cos(M_PI / 4), 1e-12);
	PX_CHECK_NEAR(s.q.x, sin(M_PI / 4), 1e-12);
	/* NaN refused and named */
	a[1] = NAN;
	PX_CHECK_INT_EQ(px_dev_feed_axes(d, a, 7u, 0, 0, 16000000), PX_E_NAN);
	{
		struct px_dev_status st;
		PX_CHECK_INT_EQ(px_dev_status(d, &st), PX_OK);
		PX_CHECK_INT_EQ(st.nonfinite, 1);
		PX_CHECK_MSG(strstr(st.last_msg, "manual0 (manual): non-finite"),
			     "%s", st.last_msg);
	}
	/* unplugged: read says so and the sample is invalid */
	px_dev_set_state(d, PX_DEV_STATE_UNPLUGGED, 17000000);
	PX_CHECK_INT_EQ(px_dev_pose_read(d, 17000000, &s), PX_E_NODEV);
	PX_CHECK(!s.valid && s.stale);
	px_dev_set_state(d, PX_DEV_STATE_RUNNING, 18000000);
	{
		struct px_dev_status st;
		px_dev_status(d, &st);
		PX_CHECK_INT_EQ(st.unplugs, 1);
		PX_CHECK_INT_EQ(st.replugs, 1);
	}
	PX_CHECK_INT_EQ(px_dev_force_write(d, &(struct px_force_cmd){{0}, {0}, 0}, 0),
			PX_E_UNSUPPORTED);
	px_dev_free(d);
	px_dev_free(NULL);
}

static void test_record_keeps_errno_and_hint(void)
{
	struct px_dev_config c;
	struct px_dev *d;
	struct px_dev_status st;
	px_dev_config_default(&c);
	c.name = "can0dev";
	PX_CHECK_INT_EQ(px_dev_create(&manual_ops, &c, 0, &d), PX_OK);
	px_dev_status(d, &st);
	PX_CHECK(strstr(st.last_msg, "no error") != NULL);
	px_dev_record(d, PX_DEV_ERR_OPEN, PX_E_UNSUPPORTED, 97, 0x123, NULL,
		      "socket(PF_CAN): no AF_CAN in this kernel", 5);
	px_dev_status(d, &st);
	PX_CHECK_INT_EQ(st.last_errno, 97);
	PX_CHECK_INT_EQ(st.last_frame_id, 0x123);
	PX_CHECK_INT_EQ(st.last_kind, PX_DEV_ERR_OPEN);
	PX_CHECK_MSG(strstr(st.last_msg, "can0dev (manual)") &&
			     strstr(st.last_msg, "[frame 0x123]") &&
			     strstr(st.last_msg, "EAFNOSUPPORT (97)") &&
			     strstr(st.last_msg, "no AF_CAN"),
		     "%s", st.last_msg);
	px_dev_free(d);
}

struct feeder {
	struct px_dev *d;
	atomic_int done;
	uint64_t fed;
};

static void *feed_thread(void *p)
{
	struct feeder *f = p;
	uint64_t k = 0;
	while (k < 300000) {
		double v = (double)++k;
		double a[6] = {v, v, v, 0, 0, 0};
		px_dev_feed_axes(f->d, a, 7u, k, UINT64_MAX, (int64_t)k);
	}
	f->fed = k;
	atomic_store(&f->done, 1);
	return NULL;
}

static int whole(const struct px_pose_sample *s, uint64_t last)
{
	return s->pos_m.x == s->pos_m.y && s->pos_m.y == s->pos_m.z &&
	       (double)s->seq == s->pos_m.x && s->buttons == s->seq &&
	       s->t_ns == (int64_t)s->seq && s->seq >= last;
}

static void test_threaded_handoff_never_torn(void)
{
	struct px_dev_config c;
	struct feeder f;
	pthread_t th;
	struct px_pose_sample s;
	uint64_t last = 0, fresh = 0, r, reads = 0;
	int ok = 1;
	px_dev_config_default(&c);
	c.name = "thr";
	c.stale_timeout_ns = INT64_MAX / 4;
	PX_CHECK_INT_EQ(px_dev_create(&manual_ops, &c, 0, &f.d), PX_OK);
	atomic_init(&f.done, 0);
	PX_CHECK_INT_EQ(pthread_create(&th, NULL, feed_thread, &f), 0);
	r = px_alloc_region_begin();
	/* bounded: the feeder ends after a fixed number of samples */
	while (!atomic_load(&f.done) && reads < 500000000u) {
		int rc = px_dev_pose_read(f.d, INT64_MAX / 8, &s);
		reads++;
		if (s.seq == 0)
			continue;
		if (!whole(&s, last)) {
			ok = 0;
			break;
		}
		fresh += rc == 1;
		last = s.seq;
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(r), 0);
	pthread_join(th, NULL);
	PX_CHECK_MSG(ok, "torn or reordered sample: seq %llu x %g y %g",
		     (unsigned long long)s.seq, s.pos_m.x, s.pos_m.y);
	/* after the feeder is done the newest sample is the last one fed */
	PX_CHECK_INT_EQ(px_dev_pose_read(f.d, INT64_MAX / 8, &s) >= 0, 1);
	PX_CHECK(whole(&s, last));
	PX_CHECK_INT_EQ(s.seq, f.fed);
	PX_CHECK(fresh + 1 >= 1);
	px_dev_free(f.d);
}

/* ---- the simulated arm --------------------------------------------------- */

static const struct px_codec_map *make_sim_map;

static struct px_dev *make_sim(const char *name,
			       struct px_sim_haptic_config *hc,
			       uint32_t stuck_limit)
{
	struct px_dev_config c;
	struct px_dev *d = NULL;
	char msg[200];
	int rc;
	px_dev_config_default(&c);
	c.name = name;
	c.stale_timeout_ns = 20000000;
	c.stuck_limit = stuck_limit;
	c.codec = make_sim_map;
	rc = px_sim_haptic_create(&c, hc, &d, msg, sizeof msg);
	PX_CHECK_MSG(rc == PX_OK, "%s", msg);
	PX_CHECK_INT_EQ(px_dev_start(d), PX_OK);
	return d;
}

static void test_sim_static_force_balances_hand_spring(void)
{
	/* hand held at the origin, constant force F: the arm settles where
	 * the hand spring balances it, x = F / k_h (damping only shapes the
	 * transient). */
	struct px_sim_haptic_config hc;
	struct px_dev *d;
	struct px_force_cmd cmd = {{1.2, -0.8, 2.0}, {0}, 1};
	struct px_pose_sample s;
	struct px_sim_haptic_state st;
	int64_t t;
	px_sim_haptic_config_default(&hc);
	hc.hand_stiffness_n_per_m = px_rand_range(200, 800);
	hc.mass_kg = px_rand_range(0.05, 0.5);
	hc.hand_damping_n_s_per_m = px_rand_range(3, 10);
	d = make_sim("arm", &hc, 0);
	for (t = 0; t <= 4000000000LL; t += 1000000) {
		px_dev_pose_read(d, t, &s);
		PX_CHECK_INT_EQ(px_dev_force_write(d, &cmd, t), PX_OK);
	}
	PX_CHECK_INT_EQ(px_sim_haptic_state(d, &st), PX_OK);
	PX_CHECK_NEAR(st.force_n[0], 1.2, 1e-3); /* through the codec: mN */
	PX_CHECK_NEAR(s.pos_m.x, 1.2 / hc.hand_stiffness_n_per_m, 2e-6);
	PX_CHECK_NEAR(s.pos_m.y, -0.8 / hc.hand_stiffness_n_per_m, 2e-6);
	PX_CHECK_NEAR(s.pos_m.z, 2.0 / hc.hand_stiffness_n_per_m, 2e-6);
	PX_CHECK(!s.stale && s.valid);
	PX_CHECK(s.seq > 3900);
	/* enable off sends zero force: the arm returns to the hand */
	cmd.enable = 0;
	for (; t <= 8000000000LL; t += 1000000) {
		px_dev_pose_read(d, t, &s);
		px_dev_force_write(d, &cmd, t);
	}
	PX_CHECK_NEAR(s.pos_m.x, 0.0, 2e-6);
	px_dev_free(d);
}

static void test_sim_follows_sines_through_decoder(void)
{
	/* Free arm, stiff hand, slow sines: the decoded sample equals the
	 * simulated position to the report resolution (1 um). */
	struct px_sim_haptic_config hc;
	struct px_sim_sine sn[2] = {{PX_AXIS_X, 0.05, 0.5, 0.3},
				    {PX_AXIS_Z, 0.02, 1.0, 0.0}};
	struct px_dev *d;
	struct px_pose_sample s;
	struct px_sim_haptic_state st;
	double hp[3], hv[3], maxerr = 0;
	int64_t t;
	px_sim_haptic_config_default(&hc);
	hc.traj.kind = PX_SIM_TRAJ_SINES;
	hc.traj.center_m[2] = 0.1;
	hc.traj.sines = sn;
	hc.traj.n_sines = 2;
	d = make_sim("arm", &hc, 0);
	for (t = 0; t <= 3000000000LL; t += 1000000) {
		px_dev_pose_read(d, t, &s);
		px_sim_haptic_state(d, &st);
		PX_CHECK(fabs(s.pos_m.x - st.pos_m[0]) <= 0.5e-6 + 1e-12);
		PX_CHECK(fabs(s.pos_m.z - st.pos_m[2]) <= 0.5e-6 + 1e-12);
		px_sim_traj_eval(&hc.traj, (double)t * 1e-9, hp, hv);
		if (t > 1000000000LL && fabs(st.pos_m[0] - hp[0]) > maxerr)
			maxerr = fabs(st.pos_m[0] - hp[0]);
	}
	/* 8 Hz arm against a 0.5 Hz hand: tracking error well below 1 mm */
	PX_CHECK_MSG(maxerr < 1e-3, "tracking error %g", maxerr);
	PX_CHECK_NEAR(hp[0], 0.05 * sin(2 * M_PI * 0.5 * 3.0 + 0.3), 1e-12);
	PX_CHECK_NEAR(hv[2], 0.02 * 2 * M_PI * cos(2 * M_PI * 3.0), 1e-9);
	px_dev_free(d);
}

static void test_csv_trajectory(void)
{
	char path[] = "/tmp/px_traj_XXXXXX";
	int fd = mkstemp(path);
	FILE *f;
	struct px_sim_csv *c = NULL;
	struct px_sim_traj tr;
	double p[3], v[3];
	char msg[200];
	PX_CHECK(fd >= 0);
	f = fdopen(fd, "w");
	fprintf(f, "t_s,x_m,y_m,z_m\n# hand\n0,0,0,0\n1,0.1,0,-0.2\n\n"
		   "3, 0.1 ,0.4,0\n");
	fclose(f);
	PX_CHECK_INT_EQ(px_sim_csv_load(path, &c, msg, sizeof msg), PX_OK);
	PX_CHECK_INT_EQ(px_sim_csv_count(c), 3);
	PX_CHECK_NEAR(px_sim_csv_duration_s(c), 3.0, 0);
	memset(&tr, 0, sizeof tr);
	tr.kind = PX_SIM_TRAJ_CSV;
	tr.csv = c;
	tr.center_m[0] = 1.0;
	px_sim_traj_eval(&tr, 0.5, p, v);
	PX_CHECK_NEAR(p[0], 1.05, 1e-12);
	PX_CHECK_NEAR(p[2], -0.1, 1e-12);
	PX_CHECK_NEAR(v[0], 0.1, 1e-12);
	px_sim_traj_eval(&tr, 2.0, p, v);
	PX_CHECK_NEAR(p[1], 0.2, 1e-12);
	px_sim_traj_eval(&tr, 10.0, p, v); /* hold the last */
	PX_CHECK_NEAR(p[1], 0.4, 1e-12);
	tr.repeat = 1;
	px_sim_traj_eval(&tr, 3.5, p, v); /* 0.5 into the loop */
	PX_CHECK_NEAR(p[2], -0.1, 1e-12);
	px_sim_csv_free(c);
	f = fopen(path, "w");
	fprintf(f, "0,0,0,0\n1,0.1,0\n");
	fclose(f);
	PX_CHECK_INT_EQ(px_sim_csv_load(path, &c, msg, sizeof msg), PX_E_PARSE);
	PX_CHECK_MSG(strstr(msg, ":2: expected 4") != NULL, "%s", msg);
	f = fopen(path, "w");
	fprintf(f, "0,0,0,0\n0,0.1,0,0\n");
	fclose(f);
	PX_CHECK_INT_EQ(px_sim_csv_load(path, &c, msg, sizeof msg), PX_E_PARSE);
	PX_CHECK_MSG(strstr(msg, ":2: time 0 not after 0") != NULL, "%s", msg);
	unlink(path);
	PX_CHECK_INT_EQ(px_sim_csv_load(path, &c, msg, sizeof msg),
			PX_E_NOTFOUND);
	PX_CHECK(c == NULL);
}

static void test_sim_rejects_bad_config_with_place(void)
{
	struct px_sim_haptic_config hc;
	struct px_dev_config c;
	struct px_dev *d;
	struct px_sim_fault fl = {PX_SIM_FAULT_DELAY, 0, 100, 1.0, 0};
	char msg[200];
	px_dev_config_default(&c);
	c.name = "hx";
	px_sim_haptic_config_default(&hc);
	hc.mass_kg = 0;
	PX_CHECK_INT_EQ(px_sim_haptic_create(&c, &hc, &d, msg, sizeof msg),
			PX_E_INVAL);
	PX_CHECK(strstr(msg, "hx: mass_kg") != NULL);
	px_sim_haptic_config_default(&hc);
	hc.faults = &fl;
	hc.n_faults = 1;
	PX_CHECK_INT_EQ(px_sim_haptic_create(&c, &hc, &d, msg, sizeof msg),
			PX_E_INVAL);
	PX_CHECK_MSG(strstr(msg, "faults[0]: kind delay") &&
			     strstr(msg, "delay_ns > 0"), "%s", msg);
	/* a pose-only map cannot take forces */
	hc.n_faults = 0;
	c.codec = px_codec_builtin("spacemouse");
	PX_CHECK_INT_EQ(px_sim_haptic_create(&c, &hc, &d, msg, sizeof msg),
			PX_E_INVAL);
	PX_CHECK(strstr(msg, "fx, fy and fz outputs") != NULL);
	hc.follow_hand = 1; /* as a pose device it is fine */
	PX_CHECK_INT_EQ(px_sim_haptic_create(&c, &hc, &d, msg, sizeof msg),
			PX_OK);
	PX_CHECK_INT_EQ(px_dev_caps(d), PX_DEV_CAP_POSE);
	px_dev_free(d);
	PX_CHECK_INT_EQ(px_sim_fault_from_name("unplug"), PX_SIM_FAULT_UNPLUG);
	PX_CHECK_INT_EQ(px_sim_fault_from_name("x"), PX_E_NOTFOUND);
}

/* ---- in the loop ------------------------------------------------------- */

struct app {
	struct px_dev *dev;
	struct px_force_cmd cmd;
	struct px_pose_sample s;
	int nodev_cycles, fresh_cycles;
	int unplug_trips; /* read returned NODEV */
	double k; /* virtual spring towards the origin */
};

static int app_read(struct px_loop *l, const struct px_loop_cycle *c, void *u)
{
	struct app *a = u;
	int rc = px_dev_pose_read(a->dev, c->read_ns, &a->s);
	(void)l;
	if (rc == PX_E_NODEV) {
		a->nodev_cycles++;
		return rc; /* an unplugged device trips at once */
	}
	a->fresh_cycles += rc == 1;
	return PX_OK;
}

static int app_compute(struct px_loop *l, const struct px_loop_cycle *c,
		       void *u)
{
	struct app *a = u;
	(void)l;
	(void)c;
	a->cmd.force_n[0] = -a->k * a->s.pos_m.x;
	a->cmd.force_n[1] = -a->k * a->s.pos_m.y;
	a->cmd.force_n[2] = -a->k * (a->s.pos_m.z - 0.05);
	a->cmd.enable = 1;
	return PX_OK;
}

static int app_write(struct px_loop *l, const struct px_loop_cycle *c,
		     void *u)
{
	struct app *a = u;
	(void)l;
	px_dev_force_write(a->dev, &a->cmd, c->write_ns);
	return PX_OK;
}

static struct px_loop *make_loop(struct app *a, struct px_dev *d)
{
	struct px_loop *l = px_test_virtual_loop(app_read, app_compute, app_write, a);
	memset(a, 0, sizeof *a);
	a->dev = d;
	a->k = 50.0;
	PX_CHECK_INT_EQ(px_dev_attach(d, l), 0);
	PX_CHECK_INT_EQ(px_dev_force_attach(d, l, &a->cmd), PX_OK);
	return l;
}

static struct px_sim_haptic_config sines_cfg(void)
{
	static const struct px_sim_sine sn[3] = {
		{PX_AXIS_X, 0.06, 0.25, 0.0},
		{PX_AXIS_Y, 0.04, 0.35, 1.5708},
		{PX_AXIS_Z, 0.05, 0.5, 0.0},
	};
	struct px_sim_haptic_config hc;
	px_sim_haptic_config_default(&hc);
	hc.traj.kind = PX_SIM_TRAJ_SINES;
	hc.traj.center_m[2] = 0.05;
	hc.traj.sines = sn;
	hc.traj.n_sines = 3;
	hc.position_noise_m = 1e-5;
	hc.seed = 42;
	return hc;
}

static void test_loop_with_sim_allocates_nothing(void)
{
	struct px_sim_haptic_config hc = sines_cfg();
	struct px_dev *d = make_sim("haptic", &hc, 0);
	struct app a;
	struct px_loop *l = make_loop(&a, d);
	struct px_loop_status ls;
	struct px_dev_status ds;
	struct px_sim_haptic_state st;
	uint64_t r;
	/* one cycle outside the region: first-use work */
	PX_CHECK_INT_EQ(px_loop_run(l, 1), PX_OK);
	r = px_alloc_region_begin();
	PX_CHECK_INT_EQ(px_loop_run(l, 3000), PX_OK);
	PX_CHECK_INT_EQ(px_alloc_region_end(r), 0);
	px_loop_status(l, &ls);
	PX_CHECK_INT_EQ(ls.safe, 0);
	PX_CHECK_INT_EQ(ls.cycles, 3001);
	px_dev_status(d, &ds);
	PX_CHECK_INT_EQ(ds.errors, 0);
	PX_CHECK(ds.samples >= 3000);
	PX_CHECK(ds.writes >= 3000);
	PX_CHECK_INT_EQ(a.fresh_cycles, 3001);
	/* the virtual spring pulls the arm toward the origin, against the
	 * hand: the command in effect is the decoded one */
	px_sim_haptic_state(d, &st);
	PX_CHECK_NEAR(st.force_n[0], a.cmd.force_n[0], 0.5e-3 + 1e-9);
	px_loop_free(l);
	px_dev_free(d);
}

/* Run the loop with one fault window at 200-400 ms and report. */
struct fault_run {
	struct px_loop_status ls;
	struct px_dev_status ds;
	int safe_at_end;
	int safe_during;
	struct px_loop_status during;
	struct app a;
};

static const struct px_codec_map *fault_map;

static void run_fault(int kind, int64_t delay_ns, double prob, uint32_t stuck,
		      struct fault_run *fr)
{
	struct px_sim_haptic_config hc = sines_cfg();
	struct px_sim_fault f = {kind, 200000000, 200000000, prob, delay_ns};
	struct px_dev *d;
	struct px_loop *l;
	uint64_t r;
	int i;
	hc.faults = &f;
	hc.n_faults = 1;
	make_sim_map = fault_map;
	d = make_sim("haptic", &hc, stuck);
	make_sim_map = NULL;
	l = make_loop(&fr->a, d);
	PX_CHECK_INT_EQ(px_loop_run(l, 1), PX_OK);
	r = px_alloc_region_begin();
	PX_CHECK_INT_EQ(px_loop_run(l, 399), PX_OK); /* to 400 ms */
	PX_CHECK_INT_EQ(px_alloc_region_end(r), 0);
	fr->safe_during = px_loop_is_safe(l);
	px_loop_status(l, &fr->during);
	PX_CHECK_INT_EQ(px_loop_run(l, 200), PX_OK); /* fault over */
	/* re-arm after the fault window: the loop leaves safe state */
	for (i = 0; i < 3; i++) {
		px_loop_rearm(l);
		px_loop_run(l, 50);
	}
	fr->safe_at_end = px_loop_is_safe(l);
	px_loop_status(l, &fr->ls);
	px_dev_status(d, &fr->ds);
	px_loop_free(l);
	px_dev_free(d);
}

static void check_tripped(const struct fault_run *fr, int cause)
{
	PX_CHECK_MSG(fr->ls.safe_entries >= 1, "no trip");
	PX_CHECK(fr->safe_during);
	PX_CHECK_INT_EQ(fr->safe_at_end, 0);
	if (cause >= 0)
		PX_CHECK_INT_EQ(fr->during.safe_cause, cause);
	PX_CHECK_MSG(strstr(fr->ds.last_msg, "haptic (sim-haptic)") != NULL,
		     "%s", fr->ds.last_msg);
}

static void test_fault_drop(void)
{
	struct fault_run fr;
	run_fault(PX_SIM_FAULT_DROP, 0, 1.0, 0, &fr);
	check_tripped(&fr, PX_FAULT_INPUT_STALE);
	PX_CHECK_INT_EQ(fr.during.safe_source, 0);
	/* sparse drops (10 %) at 1 kHz never leave a 20 ms gap */
	run_fault(PX_SIM_FAULT_DROP, 0, 0.1, 0, &fr);
	PX_CHECK_INT_EQ(fr.ls.safe_entries, 0);
	PX_CHECK(fr.ds.samples < 1000 - 100 + 80);
}

static void test_fault_delay(void)
{
	struct fault_run fr;
	run_fault(PX_SIM_FAULT_DELAY, 50000000, 1.0, 0, &fr);
	check_tripped(&fr, PX_FAULT_INPUT_STALE);
	/* a short delay (5 ms) stays under the 20 ms timeout */
	run_fault(PX_SIM_FAULT_DELAY, 5000000, 1.0, 0, &fr);
	PX_CHECK_INT_EQ(fr.ls.safe_entries, 0);
}

static void test_fault_duplicate(void)
{
	struct fault_run fr;
	run_fault(PX_SIM_FAULT_DUPLICATE, 0, 0.5, 0, &fr);
	PX_CHECK(fr.ds.duplicates > 50);
	PX_CHECK_INT_EQ(fr.ds.last_kind, PX_DEV_ERR_DUPLICATE);
	PX_CHECK_MSG(strstr(fr.ds.last_msg, "duplicate report 0x01 dropped"),
		     "%s", fr.ds.last_msg);
	PX_CHECK_INT_EQ(fr.ls.safe_entries, 0); /* harmless once dropped */
}

static void test_fault_corrupt(void)
{
	struct fault_run fr;
	const struct px_codec_map *hp = px_codec_builtin("haptic");
	struct px_codec_field in[3];
	struct px_codec_map m = *hp;
	int i;
	/* truncation and a hit id byte are always caught; a flipped high
	 * bit of a value only with a plausibility limit (max_abs) */
	run_fault(PX_SIM_FAULT_CORRUPT, 0, 1.0, 0, &fr);
	PX_CHECK_INT_EQ(fr.ls.safe_entries, 0);
	PX_CHECK(fr.ds.decode_errors >= 130 && fr.ds.decode_errors <= 136);
	memcpy(in, hp->inputs, sizeof in);
	for (i = 0; i < 3; i++)
		in[i].max_abs = 1.0;
	m.inputs = in;
	fault_map = &m;
	run_fault(PX_SIM_FAULT_CORRUPT, 0, 1.0, 0, &fr);
	fault_map = NULL;
	check_tripped(&fr, PX_FAULT_INPUT_STALE);
	PX_CHECK(fr.ds.decode_errors >= 199);
	PX_CHECK_INT_EQ(fr.ds.last_kind, PX_DEV_ERR_DECODE);
	PX_CHECK_MSG(strstr(fr.ds.last_msg, "report") != NULL, "%s",
		     fr.ds.last_msg);
}

static void test_fault_stuck(void)
{
	struct fault_run fr;
	run_fault(PX_SIM_FAULT_STUCK, 0, 1.0, 10, &fr);
	check_tripped(&fr, PX_FAULT_INPUT_STALE);
	PX_CHECK(fr.ds.stuck >= 1);
	/* without the detector a frozen device goes unnoticed */
	run_fault(PX_SIM_FAULT_STUCK, 0, 1.0, 0, &fr);
	PX_CHECK_INT_EQ(fr.ls.safe_entries, 0);
	PX_CHECK_INT_EQ(fr.ds.stuck, 0);
}

static void test_fault_nan(void)
{
	struct fault_run fr;
	run_fault(PX_SIM_FAULT_NAN, 0, 1.0, 0, &fr);
	check_tripped(&fr, PX_FAULT_INPUT_STALE);
	PX_CHECK(fr.ds.nonfinite >= 190);
	PX_CHECK(strstr(fr.ds.last_msg, "non-finite") != NULL);
}

static void test_fault_unplug_replug(void)
{
	struct fault_run fr;
	run_fault(PX_SIM_FAULT_UNPLUG, 0, 1.0, 0, &fr);
	check_tripped(&fr, PX_FAULT_CALLBACK);
	PX_CHECK_INT_EQ(fr.ds.unplugs, 1);
	PX_CHECK_INT_EQ(fr.ds.replugs, 1);
	PX_CHECK_INT_EQ(fr.ds.state, PX_DEV_STATE_RUNNING); /* replugged */
	PX_CHECK(fr.a.nodev_cycles >= 199 && fr.a.nodev_cycles <= 201);
}

static void test_safe_state_sends_zero_force(void)
{
	struct px_sim_haptic_config hc = sines_cfg();
	struct px_dev *d = make_sim("haptic", &hc, 0);
	struct app a;
	struct px_loop *l = make_loop(&a, d);
	struct px_sim_haptic_state st;
	uint8_t out[16];
	int n, i;
	PX_CHECK_INT_EQ(px_loop_run(l, 100), PX_OK);
	px_sim_haptic_state(d, &st);
	PX_CHECK(fabs(st.force_n[0]) > 1e-3);
	px_loop_trip(l);
	PX_CHECK_INT_EQ(px_loop_run(l, 2), PX_OK);
	PX_CHECK(px_loop_is_safe(l));
	px_sim_haptic_state(d, &st);
	PX_CHECK_NEAR(st.force_n[0], 0, 0);
	n = px_sim_haptic_last_output(d, out, sizeof out);
	PX_CHECK_INT_EQ(n, 7);
	PX_CHECK_INT_EQ(out[0], 2);
	for (i = 1; i < n; i++)
		PX_CHECK_INT_EQ(out[i], 0);
	/* a NaN command is refused and counted */
	a.cmd.force_n[1] = NAN;
	PX_CHECK_INT_EQ(px_dev_force_write(d, &a.cmd, 0), PX_E_NAN);
	{
		struct px_dev_status ds;
		px_dev_status(d, &ds);
		PX_CHECK_INT_EQ(ds.write_errors, 1);
		PX_CHECK(strstr(ds.last_msg, "force command not finite"));
	}
	px_loop_free(l);
	px_dev_free(d);
}

/* The safe output (px_dev_safe, and px_dev_stop of a device written to):
 * what the simulated device last received is zero force with enable
 * off, and it counts as one more write. */
static void test_safe_output_is_what_the_device_received_last(void)
{
	struct px_sim_haptic_config hc;
	struct px_dev *d;
	struct px_force_cmd cmd = {{1.5, -0.7, 0.9}, {0.01, 0, 0}, 1};
	struct px_pose_sample s;
	struct px_sim_haptic_state st;
	struct px_dev_status ds;
	uint8_t out[16];
	int64_t t;
	int n, i;
	px_sim_haptic_config_default(&hc);
	d = make_sim("arm", &hc, 0);
	for (t = 0; t < 100000000; t += 1000000) {
		px_dev_pose_read(d, t, &s);
		PX_CHECK_INT_EQ(px_dev_force_write(d, &cmd, t), PX_OK);
	}
	px_sim_haptic_state(d, &st);
	PX_CHECK_NEAR(st.force_n[0], 1.5, 1e-3);
	PX_CHECK_INT_EQ(st.enable, 1);
	px_dev_status(d, &ds);
	PX_CHECK_INT_EQ(ds.writes, 100);
	PX_CHECK_INT_EQ(ds.outputs_safe, 0);
	PX_CHECK_INT_EQ(px_dev_safe(d, t), PX_OK);
	px_sim_haptic_state(d, &st);
	for (i = 0; i < 3; i++) {
		PX_CHECK_NEAR(st.force_n[i], 0, 0);
		PX_CHECK_NEAR(st.torque_n_m[i], 0, 0);
	}
	PX_CHECK_INT_EQ(st.enable, 0);
	n = px_sim_haptic_last_output(d, out, sizeof out);
	PX_CHECK_INT_EQ(n, 7);
	for (i = 1; i < n; i++)
		PX_CHECK_INT_EQ(out[i], 0);
	px_dev_status(d, &ds);
	PX_CHECK_INT_EQ(ds.writes, 101);
	PX_CHECK_INT_EQ(ds.safe_writes, 1);
	PX_CHECK_INT_EQ(ds.outputs_safe, 1);
	/* a command after it: no longer safe; stopping sends it again */
	PX_CHECK_INT_EQ(px_dev_force_write(d, &cmd, t), PX_OK);
	px_dev_status(d, &ds);
	PX_CHECK_INT_EQ(ds.outputs_safe, 0);
	px_sim_haptic_state(d, &st);
	PX_CHECK_NEAR(st.force_n[0], 1.5, 1e-3);
	px_dev_stop(d);
	px_sim_haptic_state(d, &st);
	PX_CHECK_NEAR(st.force_n[0], 0, 0);
	PX_CHECK_INT_EQ(st.enable, 0);
	px_dev_status(d, &ds);
	PX_CHECK_INT_EQ(ds.safe_writes, 2);
	PX_CHECK_INT_EQ(ds.outputs_safe, 1);
	/* a device with nothing to zero: nothing sent, PX_OK */
	hc.follow_hand = 1;
	{
		struct px_dev *p = make_sim("pose", &hc, 0);
		PX_CHECK_INT_EQ(px_dev_safe(p, 0), PX_OK);
		px_dev_status(p, &ds);
		PX_CHECK_INT_EQ(ds.writes, 0);
		px_dev_free(p);
	}
	PX_CHECK_INT_EQ(px_dev_safe(NULL, 0), PX_E_INVAL);
	px_dev_free(d);
}

/* An unplugged device cannot take the safe output: an error, counted,
 * and outputs_safe stays 0 until it is back and takes it. */
static void test_safe_output_refused_while_unplugged(void)
{
	struct px_sim_haptic_config hc;
	struct px_sim_fault f = {PX_SIM_FAULT_UNPLUG, 50000000, 50000000, 1.0, 0};
	struct px_dev *d;
	struct px_force_cmd cmd = {{2.0, 0, 0}, {0}, 1};
	struct px_pose_sample s;
	struct px_sim_haptic_state st;
	struct px_dev_status ds;
	int64_t t;
	px_sim_haptic_config_default(&hc);
	hc.faults = &f;
	hc.n_faults = 1;
	d = make_sim("arm", &hc, 0);
	for (t = 0; t < 60000000; t += 1000000) {
		px_dev_pose_read(d, t, &s);
		px_dev_force_write(d, &cmd, t);
	}
	PX_CHECK_INT_EQ(px_dev_state(d), PX_DEV_STATE_UNPLUGGED);
	PX_CHECK_INT_EQ(px_dev_safe(d, t), PX_E_NODEV);
	px_sim_haptic_state(d, &st);
	PX_CHECK_NEAR(st.force_n[0], 2.0, 1e-3); /* still what it had */
	px_dev_status(d, &ds);
	PX_CHECK_INT_EQ(ds.safe_errors, 1);
	PX_CHECK_INT_EQ(ds.outputs_safe, 0);
	PX_CHECK(strstr(ds.last_msg, "safe output not confirmed") != NULL);
	/* back after the window: it takes it */
	px_dev_pose_read(d, 110000000, &s);
	PX_CHECK_INT_EQ(px_dev_safe(d, 110000000), PX_OK);
	px_sim_haptic_state(d, &st);
	PX_CHECK_NEAR(st.force_n[0], 0, 0);
	px_dev_status(d, &ds);
	PX_CHECK_INT_EQ(ds.outputs_safe, 1);
	px_dev_free(d);
}

static int slow_read(struct px_loop *l, const struct px_loop_cycle *c,
		     void *u)
{
	struct app *a = u;
	int rc = px_dev_pose_read(a->dev, c->read_ns, &a->s);
	(void)l;
	a->fresh_cycles += rc == 1;
	if (a->s.age_ns > a->k)
		a->k = (double)a->s.age_ns; /* largest age seen */
	a->nodev_cycles += a->s.stale;
	return PX_OK;
}

static void test_slow_pose_device_age_is_visible(void)
{
	/* A 6-DoF pose device at 125 Hz (two reports per sample, like a
	 * 3Dconnexion device) read by a 1 kHz loop: one fresh sample in
	 * eight cycles, the age climbing to 7 ms in between, never stale
	 * with a 50 ms timeout. */
	struct px_sim_haptic_config hc = sines_cfg();
	struct px_dev_config c;
	struct px_dev *d;
	struct px_loop *l;
	struct px_loop_status ls;
	struct app a;
	char msg[200];
	px_dev_config_default(&c);
	c.name = "spacemouse";
	c.codec = px_codec_builtin("spacemouse");
	c.stale_timeout_ns = 50000000;
	hc.follow_hand = 1;
	hc.report_period_ns = 8000000;
	hc.traj.sines = NULL; /* stay inside the +-50 mm range */
	hc.traj.n_sines = 0;
	hc.traj.center_m[0] = 0.01;
	hc.traj.center_m[2] = -0.02;
	PX_CHECK_INT_EQ(px_sim_haptic_create(&c, &hc, &d, msg, sizeof msg),
			PX_OK);
	l = px_test_virtual_loop(slow_read, NULL, NULL, &a);
	memset(&a, 0, sizeof a);
	a.dev = d;
	PX_CHECK_INT_EQ(px_dev_attach(d, l), 0);
	PX_CHECK_INT_EQ(px_loop_run(l, 800), PX_OK);
	px_loop_status(l, &ls);
	PX_CHECK_INT_EQ(ls.safe_entries, 0);
	PX_CHECK_INT_EQ(a.fresh_cycles, 100);
	PX_CHECK_INT_EQ((int64_t)a.k, 7000000);
	PX_CHECK_INT_EQ(a.nodev_cycles, 0);
	PX_CHECK_NEAR(a.s.pos_m.x, 0.01, 1.5e-4);  /* 1 count = 0.14 mm */
	PX_CHECK_NEAR(a.s.pos_m.z, -0.02, 1.5e-4);
	PX_CHECK_NEAR(a.s.q.w, 1.0, 0);
	px_loop_free(l);
	px_dev_free(d);
}

static const struct px_test tests[] = {
	PX_T(test_slow_pose_device_age_is_visible),
	PX_T(test_staleness_and_age),
	PX_T(test_record_keeps_errno_and_hint),
	PX_T(test_threaded_handoff_never_torn),
	PX_T(test_sim_static_force_balances_hand_spring),
	PX_T(test_sim_follows_sines_through_decoder),
	PX_T(test_csv_trajectory),
	PX_T(test_sim_rejects_bad_config_with_place),
	PX_T(test_loop_with_sim_allocates_nothing),
	PX_T(test_fault_drop),
	PX_T(test_fault_delay),
	PX_T(test_fault_duplicate),
	PX_T(test_fault_corrupt),
	PX_T(test_fault_stuck),
	PX_T(test_fault_nan),
	PX_T(test_fault_unplug_replug),
	PX_T(test_safe_state_sends_zero_force),
	PX_T(test_safe_output_is_what_the_device_received_last),
	PX_T(test_safe_output_refused_while_unplugged),
};

PX_TEST_MAIN(tests)
