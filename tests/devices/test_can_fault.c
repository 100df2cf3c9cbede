/* CAN fault injection: every fault kind on the in-process simulated bus
 * (bus-wide, sending side) and on the UNIX-datagram bus (fault wrapper,
 * receiving side), seen by a CAN pose device inside a running loop: each
 * is detected, reaches the device status and the loop's watchdog, and
 * the loop recovers after the window. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <linux/can/error.h>

#include "px_alloc_count.h"
#include "px_can.h"
#include "px_loop.h"
#include "px_test.h"
#include "px_test_dev.h"

/* J1939-style position signals: unsigned raw with an offset, so the
 * all-ones "not available" pattern decodes far outside [min, max]. */
static const struct px_can_signal sigs[] = {
	{"x", 0x100, 0, 0, 0, 16, PX_LITTLE_ENDIAN, 0, 1e-4, -3.2768, 1, 1, -2,
	 2, PX_AXIS_X, 0},
	{"y", 0x100, 0, 0, 48, 16, PX_LITTLE_ENDIAN, 0, 1e-4, -3.2768, 1, 1, -2,
	 2, PX_AXIS_Y, 0},
};

/* The same as IEEE 754 binary32 values (DBC float signals). */
static const struct px_can_signal fsigs[] = {
	{"x", 0x100, 0, 0, 0, 32, PX_LITTLE_ENDIAN, 0, 1, 0, 1, 1, -2, 2,
	 PX_AXIS_X, 1},
	{"y", 0x100, 0, 0, 32, 32, PX_LITTLE_ENDIAN, 0, 1, 0, 1, 1, -2, 2,
	 PX_AXIS_Y, 1},
};

static const struct px_can_signal *g_sigs = sigs;

enum { T_SIM, T_UNIX };

struct app {
	struct px_can_bus *robot;
	struct px_dev *dev;
	uint64_t n;
	int nodev_cycles;
	int last_fresh;
};

static int app_read(struct px_loop *l, const struct px_loop_cycle *c, void *u)
{
	struct app *a = u;
	struct px_can_msg m;
	struct px_pose_sample s;
	int rc;
	(void)l;
	/* a moving arm: no two frames alike, so stuck and duplicate are
	 * the faults' doing */
	memset(&m, 0, sizeof m);
	m.f.can_id = 0x100;
	m.f.len = 8;
	px_can_signal_encode(&g_sigs[0], 1e-4 * (double)(a->n % 5000), m.f.data,
			     8, NULL);
	px_can_signal_encode(&g_sigs[1], -0.25, m.f.data, 8, NULL);
	a->n++;
	px_can_bus_send(a->robot, &m, c->read_ns);
	rc = px_dev_pose_read(a->dev, c->read_ns, &s);
	if (rc == PX_E_NODEV) {
		a->nodev_cycles++;
		return rc; /* unplugged or bus-off: the read phase fails */
	}
	a->last_fresh = rc == 1;
	return PX_OK;
}

struct run {
	struct px_loop_status during, end;
	struct px_dev_status ds;
	int safe_during, safe_at_end;
	int nodev_cycles;
	struct px_can_bus_stats rs;
};

static char sock_a[64], sock_b[64];

/* One fault window at 200-400 ms of the virtual clock; the loop runs to
 * 600 ms, then is re-armed. */
static void run_fault(int transport, int kind, int64_t delay_ns, double prob,
		      uint32_t stuck_limit, struct run *out)
{
	struct px_sim_fault f = {kind, 200000000, 200000000, prob, delay_ns};
	struct px_can_sim *sim = NULL;
	struct px_can_bus *ctl = NULL, *raw = NULL;
	struct px_dev_config dc;
	struct px_loop *l;
	static struct app a;
	char msg[300];
	uint64_t r;
	int i;
	memset(&a, 0, sizeof a);
	memset(out, 0, sizeof *out);
	if (transport == T_SIM) {
		struct px_can_sim_config sc;
		px_can_sim_config_default(&sc);
		sc.faults = &f;
		sc.n_faults = 1;
		sc.seed = px_rand_u64();
		PX_CHECK_INT_EQ(px_can_sim_create(&sc, &sim), PX_OK);
		PX_CHECK_INT_EQ(px_can_sim_endpoint(sim, &a.robot), PX_OK);
		PX_CHECK_INT_EQ(px_can_sim_endpoint(sim, &ctl), PX_OK);
	} else {
		snprintf(sock_a, sizeof sock_a, "/tmp/px_cf_a_%d", (int)getpid());
		snprintf(sock_b, sizeof sock_b, "/tmp/px_cf_b_%d", (int)getpid());
		PX_CHECK_INT_EQ(px_can_unix_open(sock_b, sock_a, &a.robot, msg,
						 sizeof msg),
				PX_OK);
		PX_CHECK_INT_EQ(px_can_unix_open(sock_a, sock_b, &raw, msg,
						 sizeof msg),
				PX_OK);
		PX_CHECK_INT_EQ(px_can_fault_open(raw, &f, 1, px_rand_u64(),
						  &ctl, msg, sizeof msg),
				PX_OK);
	}
	if (!ctl || !a.robot)
		return;
	px_dev_config_default(&dc);
	dc.name = "arm";
	dc.stuck_limit = stuck_limit;
	dc.min_report_interval_ns = 500000; /* frames come every 1 ms */
	PX_CHECK_INT_EQ(px_can_dev_create(&dc, ctl, 0, g_sigs, 2, &a.dev, msg,
					  sizeof msg),
			PX_OK);
	PX_CHECK_INT_EQ(px_dev_start(a.dev), PX_OK);
	l = px_test_virtual_loop(app_read, NULL, NULL, &a);
	PX_CHECK_INT_EQ(px_dev_attach(a.dev, l), 0);
	PX_CHECK_INT_EQ(px_loop_run(l, 1), PX_OK);
	r = px_alloc_region_begin();
	PX_CHECK_INT_EQ(px_loop_run(l, 399), PX_OK); /* to 400 ms */
	PX_CHECK_INT_EQ(px_alloc_region_end(r), 0);
	out->safe_during = px_loop_is_safe(l);
	px_loop_status(l, &out->during);
	PX_CHECK_INT_EQ(px_loop_run(l, 200), PX_OK); /* window over */
	for (i = 0; i < 3; i++) {
		px_loop_rearm(l);
		px_loop_run(l, 50);
	}
	out->safe_at_end = px_loop_is_safe(l);
	px_loop_status(l, &out->end);
	px_dev_status(a.dev, &out->ds);
	px_can_bus_stats(a.robot, &out->rs);
	out->nodev_cycles = a.nodev_cycles;
	px_loop_free(l);
	px_dev_free(a.dev); /* closes ctl (and the wrapped socket) */
	if (sim)
		px_can_sim_free(sim); /* frees the robot endpoint */
	else
		px_can_bus_close(a.robot);
}

static void check_tripped(const struct run *r, int cause, const char *tr)
{
	PX_CHECK_MSG(r->end.safe_entries >= 1, "%s: no trip", tr);
	PX_CHECK_MSG(r->safe_during, "%s: not safe during the window", tr);
	PX_CHECK_MSG(!r->safe_at_end, "%s: still safe after re-arm", tr);
	PX_CHECK_MSG(r->during.safe_cause == cause, "%s: cause %d, want %d", tr,
		     (int)r->during.safe_cause, cause);
}

static const char *tname(int t)
{
	return t == T_SIM ? "in-process" : "unix";
}

static void test_can_fault_drop(void)
{
	struct run r;
	int t;
	for (t = T_SIM; t <= T_UNIX; t++) {
		run_fault(t, PX_SIM_FAULT_DROP, 0, 1.0, 0, &r);
		check_tripped(&r, PX_FAULT_INPUT_STALE, tname(t));
		/* 10 % loss at 1 kHz never leaves a 20 ms gap */
		run_fault(t, PX_SIM_FAULT_DROP, 0, 0.1, 0, &r);
		PX_CHECK_INT_EQ(r.end.safe_entries, 0);
		/* 750 cycles, 200 of them in the window */
		PX_CHECK_MSG(r.ds.samples < 750 - 5 && r.ds.samples > 750 - 45,
			     "%s: %llu samples", tname(t),
			     (unsigned long long)r.ds.samples);
	}
}

static void test_can_fault_delay(void)
{
	struct run r;
	int t;
	for (t = T_SIM; t <= T_UNIX; t++) {
		run_fault(t, PX_SIM_FAULT_DELAY, 50000000, 1.0, 0, &r);
		check_tripped(&r, PX_FAULT_INPUT_STALE, tname(t));
		/* every frame arrives in the end, in order: none lost */
		PX_CHECK_MSG(r.ds.samples == 750, "%s: %llu samples",
			     tname(t), (unsigned long long)r.ds.samples);
		PX_CHECK_INT_EQ(r.ds.errors, 0);
		/* 5 ms stays under the 20 ms stale timeout */
		run_fault(t, PX_SIM_FAULT_DELAY, 5000000, 1.0, 0, &r);
		PX_CHECK_INT_EQ(r.end.safe_entries, 0);
	}
}

static void test_can_fault_duplicate(void)
{
	struct run r;
	int t;
	for (t = T_SIM; t <= T_UNIX; t++) {
		run_fault(t, PX_SIM_FAULT_DUPLICATE, 0, 0.5, 0, &r);
		PX_CHECK_MSG(r.ds.duplicates > 50 && r.ds.duplicates < 150,
			     "%s: %llu duplicates", tname(t),
			     (unsigned long long)r.ds.duplicates);
		PX_CHECK_INT_EQ(r.ds.last_kind, PX_DEV_ERR_DUPLICATE);
		PX_CHECK_MSG(strstr(r.ds.last_msg, "arm (socketcan): duplicate") !=
				     NULL,
			     "%s", r.ds.last_msg);
		/* dropped, so harmless: the watchdog has nothing to do */
		PX_CHECK_INT_EQ(r.end.safe_entries, 0);
		PX_CHECK_INT_EQ(r.ds.samples, 750);
	}
}

static void test_can_fault_corrupt(void)
{
	struct run r;
	int t;
	for (t = T_SIM; t <= T_UNIX; t++) {
		run_fault(t, PX_SIM_FAULT_CORRUPT, 0, 1.0, 0, &r);
		check_tripped(&r, PX_FAULT_INPUT_STALE, tname(t));
		PX_CHECK(r.ds.decode_errors >= 199 && r.ds.decode_errors <= 201);
		PX_CHECK_INT_EQ(r.ds.last_kind, PX_DEV_ERR_DECODE);
		PX_CHECK_MSG(strstr(r.ds.last_msg, "frame too short") &&
				     strstr(r.ds.last_msg, "y"),
			     "%s", r.ds.last_msg);
	}
}

static void test_can_fault_stuck(void)
{
	struct run r;
	int t;
	for (t = T_SIM; t <= T_UNIX; t++) {
		run_fault(t, PX_SIM_FAULT_STUCK, 0, 1.0, 10, &r);
		check_tripped(&r, PX_FAULT_INPUT_STALE, tname(t));
		PX_CHECK_INT_EQ(r.ds.stuck, 1);
		PX_CHECK_MSG(strstr(r.ds.last_msg, "stuck") != NULL, "%s",
			     r.ds.last_msg);
		/* without the detector a frozen sender goes unnoticed */
		run_fault(t, PX_SIM_FAULT_STUCK, 0, 1.0, 0, &r);
		PX_CHECK_INT_EQ(r.end.safe_entries, 0);
		PX_CHECK_INT_EQ(r.ds.stuck, 0);
	}
}

static void test_can_fault_nan(void)
{
	struct run r;
	int t;
	for (t = T_SIM; t <= T_UNIX; t++) {
		run_fault(t, PX_SIM_FAULT_NAN, 0, 1.0, 0, &r);
		check_tripped(&r, PX_FAULT_INPUT_STALE, tname(t));
		PX_CHECK(r.ds.decode_errors >= 199 && r.ds.decode_errors <= 201);
		PX_CHECK_MSG(strstr(r.ds.last_msg, "plausible") != NULL, "%s",
			     r.ds.last_msg);
		PX_CHECK_INT_EQ(r.ds.nonfinite, 0);
		/* float signals: all ones is a NaN, rejected as non-finite */
		g_sigs = fsigs;
		run_fault(t, PX_SIM_FAULT_NAN, 0, 1.0, 0, &r);
		g_sigs = sigs;
		check_tripped(&r, PX_FAULT_INPUT_STALE, tname(t));
		PX_CHECK(r.ds.nonfinite >= 199 && r.ds.nonfinite <= 201);
		PX_CHECK_INT_EQ(r.ds.decode_errors, 0);
		PX_CHECK_MSG(strstr(r.ds.last_msg, "non-finite") != NULL, "%s",
			     r.ds.last_msg);
		PX_CHECK_INT_EQ(r.ds.samples, 750 - 200);
	}
}

static void test_can_fault_unplug_replug(void)
{
	struct run r;
	int t;
	for (t = T_SIM; t <= T_UNIX; t++) {
		run_fault(t, PX_SIM_FAULT_UNPLUG, 0, 1.0, 0, &r);
		check_tripped(&r, PX_FAULT_CALLBACK, tname(t));
		PX_CHECK_INT_EQ(r.ds.unplugs, 1);
		PX_CHECK_INT_EQ(r.ds.replugs, 1);
		PX_CHECK_INT_EQ(r.ds.state, PX_DEV_STATE_RUNNING);
		PX_CHECK_MSG(r.nodev_cycles >= 199 && r.nodev_cycles <= 201,
			     "%s: %d", tname(t), r.nodev_cycles);
		PX_CHECK(strstr(r.ds.last_msg, "unplugged") != NULL ||
			 r.ds.unplugs == 1);
	}
}

static void test_can_fault_bus_off(void)
{
	struct run r;
	int t;
	for (t = T_SIM; t <= T_UNIX; t++) {
		run_fault(t, PX_SIM_FAULT_BUSOFF, 0, 1.0, 0, &r);
		check_tripped(&r, PX_FAULT_CALLBACK, tname(t));
		PX_CHECK_INT_EQ(r.ds.bus_errors, 2); /* bus-off, restarted */
		PX_CHECK_INT_EQ(r.ds.state, PX_DEV_STATE_RUNNING);
		PX_CHECK_MSG(r.nodev_cycles >= 199 && r.nodev_cycles <= 201,
			     "%s: %d", tname(t), r.nodev_cycles);
	}
}

/* estop is not a bus fault; bad windows are refused with the index. */
static void test_can_fault_config_errors(void)
{
	struct px_sim_fault f[2] = {
		{PX_SIM_FAULT_DROP, 0, 1000, 1.0, 0},
		{PX_SIM_FAULT_ESTOP, 0, 1000, 1.0, 0},
	};
	struct px_can_sim_config sc;
	struct px_can_sim *s = NULL;
	struct px_can_bus *in, *out = NULL;
	char msg[300];
	px_can_sim_config_default(&sc);
	sc.faults = f;
	sc.n_faults = 2;
	PX_CHECK_INT_EQ(px_can_sim_create(&sc, &s), PX_E_INVAL);
	sc.n_faults = 0;
	PX_CHECK_INT_EQ(px_can_sim_create(&sc, &s), PX_OK);
	PX_CHECK_INT_EQ(px_can_sim_endpoint(s, &in), PX_OK);
	PX_CHECK_INT_EQ(px_can_fault_open(in, f, 2, 1, &out, msg, sizeof msg),
			PX_E_INVAL);
	PX_CHECK(out == NULL);
	PX_CHECK_MSG(strstr(msg, "faults[1] (estop)") != NULL, "%s", msg);
	f[1].kind = PX_SIM_FAULT_DELAY;
	PX_CHECK_INT_EQ(px_can_fault_open(in, f, 2, 1, &out, msg, sizeof msg),
			PX_E_INVAL);
	PX_CHECK_MSG(strstr(msg, "faults[1] (delay): kind delay needs delay_ns") !=
			     NULL,
		     "%s", msg);
	f[1].delay_ns = 1000;
	f[0].duration_ns = 0;
	PX_CHECK_INT_EQ(px_can_fault_open(in, f, 2, 1, &out, msg, sizeof msg),
			PX_E_INVAL);
	PX_CHECK_MSG(strstr(msg, "faults[0] (drop): duration_ns") != NULL, "%s",
		     msg);
	f[0].duration_ns = 1000;
	PX_CHECK_INT_EQ(px_can_fault_open(in, f, 2, 1, &out, msg, sizeof msg),
			PX_OK);
	px_can_bus_close(out); /* closes in too */
	px_can_sim_free(s);
}

static const struct px_test tests[] = {
	PX_T(test_can_fault_drop),
	PX_T(test_can_fault_delay),
	PX_T(test_can_fault_duplicate),
	PX_T(test_can_fault_corrupt),
	PX_T(test_can_fault_stuck),
	PX_T(test_can_fault_nan),
	PX_T(test_can_fault_unplug_replug),
	PX_T(test_can_fault_bus_off),
	PX_T(test_can_fault_config_errors),
};

PX_TEST_MAIN(tests)
