/* CANopen-lite + CiA 402: the statusword decoding and the drive state
 * machine against the standard's tables, then the master driving a
 * simulated 6-joint arm on the simulated bus inside the loop (virtual
 * clock): enable, motion in CSV/CSP/CST, safe state (quick stop), a drive
 * fault and its reset, a silent drive (heartbeat timeout), no
 * allocations in cycles. */
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "px_alloc_count.h"
#include "px_canopen.h"
#include "px_config.h"
#include "px_devcfg.h"
#include "px_loop.h"
#include "px_test.h"
#include "px_test_dev.h"
#include "px_test_config.h"

static void test_statusword_table(void)
{
	/* CiA 402 statusword patterns (x = don't care) */
	static const struct {
		uint16_t mask, value;
		int state;
	} tab[] = {
		{0x4F, 0x00, PX_CIA402_NOT_READY},
		{0x4F, 0x40, PX_CIA402_SWITCH_ON_DISABLED},
		{0x6F, 0x21, PX_CIA402_READY_TO_SWITCH_ON},
		{0x6F, 0x23, PX_CIA402_SWITCHED_ON},
		{0x6F, 0x27, PX_CIA402_OPERATION_ENABLED},
		{0x6F, 0x07, PX_CIA402_QUICK_STOP_ACTIVE},
		{0x4F, 0x0F, PX_CIA402_FAULT_REACTION_ACTIVE},
		{0x4F, 0x08, PX_CIA402_FAULT},
	};
	int it;
	size_t i;
	for (it = 0; it < 20000; it++) {
		uint16_t sw = (uint16_t)px_rand_u64();
		int want = PX_CIA402_UNKNOWN;
		for (i = 0; i < sizeof tab / sizeof tab[0]; i++)
			if ((sw & tab[i].mask) == tab[i].value)
				want = tab[i].state;
		PX_CHECK_INT_EQ(px_cia402_state_of(sw), want);
	}
	for (i = 0; i <= PX_CIA402_FAULT; i++)
		PX_CHECK_INT_EQ(px_cia402_state_of(px_cia402_statusword((int)i)),
				(int)i);
}

static void test_drive_transitions(void)
{
	/* From each state, each command: the state the standard's
	 * transitions lead to (before automatic ones). */
	enum { S_SOD = PX_CIA402_SWITCH_ON_DISABLED,
	       S_RDY = PX_CIA402_READY_TO_SWITCH_ON,
	       S_SWO = PX_CIA402_SWITCHED_ON,
	       S_OPE = PX_CIA402_OPERATION_ENABLED,
	       S_QSA = PX_CIA402_QUICK_STOP_ACTIVE,
	       S_FLT = PX_CIA402_FAULT };
	static const uint16_t cmd[] = {0x06, 0x07, 0x0F, 0x00, 0x02};
	static const int want[][5] = {
		/*        shutdown switch-on enable  dis-volt quick-stop */
		[S_SOD] = {S_RDY, S_SOD, S_SOD, S_SOD, S_SOD},
		[S_RDY] = {S_RDY, S_SWO, S_OPE, S_SOD, S_SOD},
		[S_SWO] = {S_RDY, S_SWO, S_OPE, S_SOD, S_SOD},
		[S_OPE] = {S_RDY, S_SWO, S_OPE, S_SOD, S_QSA},
		[S_QSA] = {S_QSA, S_QSA, S_OPE, S_SOD, S_QSA},
		[S_FLT] = {S_FLT, S_FLT, S_FLT, S_FLT, S_FLT},
	};
	int s, c;
	for (s = S_SOD; s <= S_QSA; s++)
		for (c = 0; c < 5; c++)
			PX_CHECK_MSG(px_cia402_transition(s, cmd[c], 0) ==
					     want[s][c],
				     "state %d cmd %#x", s, cmd[c]);
	for (c = 0; c < 5; c++)
		PX_CHECK_INT_EQ(px_cia402_transition(S_FLT, cmd[c], 0), S_FLT);
	/* fault reset needs a rising edge of bit 7 */
	PX_CHECK_INT_EQ(px_cia402_transition(S_FLT, 0x80, 0x00), S_SOD);
	PX_CHECK_INT_EQ(px_cia402_transition(S_FLT, 0x80, 0x80), S_FLT);
	PX_CHECK_INT_EQ(px_cia402_transition(PX_CIA402_NOT_READY, 0, 0), S_SOD);
	/* with bit 7 set no other command acts */
	PX_CHECK_INT_EQ(px_cia402_transition(S_SOD, 0x86, 0), S_SOD);
	/* the master's policy reaches operation enabled from every state
	 * through the drive's own transitions, and standstill when
	 * disabled */
	for (s = PX_CIA402_NOT_READY; s <= S_FLT; s++) {
		int st = s, k;
		uint16_t cw = 0, prev = 0;
		for (k = 0; k < 10 && st != S_OPE; k++) {
			prev = cw;
			cw = px_cia402_next_controlword(st, 1, prev);
			st = px_cia402_transition(st, cw, prev);
			/* the drive's automatic transitions */
			if (st == S_QSA)
				st = S_SOD;
			if (st == PX_CIA402_FAULT_REACTION_ACTIVE)
				st = S_FLT;
		}
		PX_CHECK_MSG(st == S_OPE, "from %s", px_cia402_state_name(s));
	}
	PX_CHECK_INT_EQ(px_cia402_next_controlword(S_OPE, 0, 0x0F), 0x02);
	PX_CHECK_INT_EQ(px_cia402_next_controlword(S_SWO, 0, 0x0F), 0x00);
}

static const struct px_canopen_drive_cfg arm[6] = {
	{1, PX_CIA402_CSV, 0, 100000.0, 0},
	{2, PX_CIA402_CSV, 1, 100000.0, 0},
	{3, PX_CIA402_CSP, 2, 100000.0, 0},
	{4, PX_CIA402_CSP, 3, 100000.0, 0},
	{5, PX_CIA402_CST, 4, 100000.0, 2.0},
	{6, PX_CIA402_CSV, 5, 100000.0, 0},
};

struct app {
	struct px_canopen *co;
	struct px_canopen_sim *sim;
	double targets[6];
	int enable;
	int loop_enable; /* registered: cleared in safe state */
	int problem;
	int all_enabled_at;
};

static int c_read(struct px_loop *l, const struct px_loop_cycle *c, void *u)
{
	struct app *a = u;
	(void)l;
	px_canopen_sim_step(a->sim, c->read_ns); /* the arm, same bus */
	px_canopen_rx(a->co, c->read_ns);
	a->problem = px_canopen_first_problem(a->co);
	if (a->all_enabled_at < 0 && px_canopen_all_enabled(a->co))
		a->all_enabled_at = (int)c->index;
	return PX_OK;
}

static int c_compute(struct px_loop *l, const struct px_loop_cycle *c,
		     void *u)
{
	struct app *a = u;
	double t = (double)c->read_ns * 1e-9;
	(void)l;
	a->targets[0] = 0.5;       /* rad/s */
	a->targets[1] = -0.25;
	a->targets[2] = 0.1 * t;   /* rad */
	a->targets[3] = 0.2;
	a->targets[4] = 0.02;      /* N m */
	a->targets[5] = 0.0;
	a->loop_enable = a->enable;
	return PX_OK;
}

static int c_write(struct px_loop *l, const struct px_loop_cycle *c, void *u)
{
	struct app *a = u;
	(void)l;
	px_canopen_tx(a->co, c->write_ns, a->targets, 6, a->loop_enable);
	return PX_OK;
}

static void test_master_drives_simulated_arm(void)
{
	struct px_can_sim_config bc;
	struct px_can_sim *bus;
	struct px_can_bus *ep_master, *ep_arm;
	struct px_canopen_config cc;
	struct px_canopen_sim_config sc;
	struct px_sim_fault faults[2] = {
		{PX_SIM_FAULT_ESTOP, 1500000000, 50000000, 1.0, 2},  /* drive 3 */
		{PX_SIM_FAULT_UNPLUG, 2500000000LL, 500000000, 1.0, 1}, /* drive 2 */
	};
	struct px_loop *l;
	struct px_canopen_drive_status ds;
	static struct app a;
	double p;
	int st;
	uint64_t r;
	char msg[200];
	memset(&a, 0, sizeof a);
	a.all_enabled_at = -1;
	px_can_sim_config_default(&bc);
	PX_CHECK_INT_EQ(px_can_sim_create(&bc, &bus), PX_OK);
	PX_CHECK_INT_EQ(px_can_sim_endpoint(bus, &ep_master), PX_OK);
	PX_CHECK_INT_EQ(px_can_sim_endpoint(bus, &ep_arm), PX_OK);
	px_canopen_config_default(&cc);
	cc.drives = arm;
	cc.n_drives = 6;
	PX_CHECK_INT_EQ(px_canopen_create(&cc, ep_master, &a.co, msg, sizeof msg),
			PX_OK);
	memset(&sc, 0, sizeof sc);
	sc.drives = arm;
	sc.n_drives = 6;
	sc.faults = faults;
	sc.n_faults = 2;
	PX_CHECK_INT_EQ(px_canopen_sim_create(&sc, ep_arm, &a.sim), PX_OK);
	l = px_test_virtual_loop(c_read, c_compute, c_write, &a);
	PX_CHECK_INT_EQ(px_loop_enable_add(l, "drives", &a.loop_enable), 0);
	a.enable = 1;
	PX_CHECK_INT_EQ(px_loop_run(l, 1), PX_OK);
	r = px_alloc_region_begin();
	PX_CHECK_INT_EQ(px_loop_run(l, 999), PX_OK); /* to 1 s */
	PX_CHECK_INT_EQ(px_alloc_region_end(r), 0);
	PX_CHECK_MSG(a.all_enabled_at >= 2 && a.all_enabled_at <= 6,
		     "enabled at cycle %d", a.all_enabled_at);
	PX_CHECK(px_canopen_all_enabled(a.co));
	/* CSV: 0.5 rad/s for the time since enabled; CSP follows 0.1 t;
	 * CST: 0.02 N m on 0.01 kg m^2 accelerates at 2 rad/s^2 */
	px_canopen_sim_joint(a.sim, 0, &p, &st);
	PX_CHECK_NEAR(p, 0.5 * (1.0 - a.all_enabled_at * 1e-3), 0.01);
	px_canopen_drive_status(a.co, 0, &ds);
	PX_CHECK_NEAR(ds.position, p, 0.5 * 2e-3 + 1e-5); /* a cycle behind */
	PX_CHECK_NEAR(ds.velocity, 0.5, 1e-5);
	px_canopen_sim_joint(a.sim, 2, &p, &st);
	PX_CHECK_NEAR(p, 0.1, 0.001);
	px_canopen_drive_status(a.co, 4, &ds);
	PX_CHECK_NEAR(ds.torque_n_m, 0.02, 1e-3);
	PX_CHECK_NEAR(ds.velocity, 2.0 * (1.0 - a.all_enabled_at * 1e-3), 0.02);
	PX_CHECK_INT_EQ(ds.nmt_state, 5);
	/* safe state: enable flags cleared -> quick stop -> standstill */
	px_loop_trip(l);
	PX_CHECK_INT_EQ(px_loop_run(l, 20), PX_OK);
	PX_CHECK(px_loop_is_safe(l));
	px_canopen_sim_joint(a.sim, 0, &p, &st);
	PX_CHECK_INT_EQ(st, PX_CIA402_SWITCH_ON_DISABLED);
	{
		double p2;
		PX_CHECK_INT_EQ(px_loop_run(l, 50), PX_OK);
		px_canopen_sim_joint(a.sim, 0, &p2, &st);
		PX_CHECK_NEAR(p2, p, 0); /* not moving */
	}
	px_loop_rearm(l);
	PX_CHECK_INT_EQ(px_loop_run(l, 20), PX_OK);
	PX_CHECK(px_canopen_all_enabled(a.co));
	/* drive 3 faults at 1.5 s for 50 ms: EMCY, fault, reset after */
	PX_CHECK_INT_EQ(px_loop_run(l, 1510 - 1090), PX_OK);
	PX_CHECK_INT_EQ(a.problem, 2);
	px_canopen_drive_status(a.co, 2, &ds);
	PX_CHECK_INT_EQ(ds.state, PX_CIA402_FAULT);
	PX_CHECK_INT_EQ(ds.emcy_code, 0x5441);
	PX_CHECK_INT_EQ(px_loop_run(l, 100), PX_OK);
	PX_CHECK_INT_EQ(a.problem, -1);
	PX_CHECK(px_canopen_all_enabled(a.co));
	/* drive 2 falls silent at 2.5 s: lost after the 300 ms timeout */
	PX_CHECK_INT_EQ(px_loop_run(l, 2700 - 1610), PX_OK);
	PX_CHECK_INT_EQ(a.problem, -1); /* 200 ms: not yet */
	PX_CHECK_INT_EQ(px_loop_run(l, 200), PX_OK);
	PX_CHECK_INT_EQ(a.problem, 1);
	px_canopen_drive_status(a.co, 1, &ds);
	PX_CHECK(ds.lost);
	PX_CHECK(!px_canopen_all_enabled(a.co));
	/* back at 3.0 s: heartbeats again, enabled again */
	PX_CHECK_INT_EQ(px_loop_run(l, 400), PX_OK);
	PX_CHECK_INT_EQ(a.problem, -1);
	PX_CHECK(px_canopen_all_enabled(a.co));
	px_loop_free(l);
	px_canopen_sim_free(a.sim);
	px_canopen_free(a.co);
	px_can_sim_free(bus);
}

/* ---- safe stop ------------------------------------------------------------ */

struct stopper {
	struct px_canopen_sim *sim;
	struct px_can_bus *sniff;
	uint16_t cw1[64];   /* controlwords node 1 was sent, in order */
	int n_cw1;
	int calls;
};

static void sniff(struct stopper *k, int64_t now)
{
	struct px_can_msg m;
	while (px_can_bus_recv(k->sniff, now, &m) == PX_OK)
		if ((m.f.can_id & CAN_SFF_MASK) == 0x201 && m.f.len >= 2 &&
		    k->n_cw1 < 64)
			k->cw1[k->n_cw1++] =
				(uint16_t)(m.f.data[0] | m.f.data[1] << 8);
}

/* The virtual clock of the safe stop: the arm answers each round. */
static int64_t stop_wait(void *user, int64_t now, int64_t period_ns)
{
	struct stopper *k = user;
	k->calls++;
	now += period_ns;
	px_canopen_sim_step(k->sim, now);
	sniff(k, now);
	return now;
}

/* An arm driven to operation enabled, then px_canopen_safe_stop():
 * quick stop, then disable voltage, every drive confirmed in switch on
 * disabled by its own statusword, the joints still; a drive that falls
 * silent is named after the bounded wait and the others still stop. */
static void test_safe_stop_disables_every_drive(void)
{
	struct px_can_sim_config bc;
	struct px_can_sim *bus;
	struct px_can_bus *ep_master, *ep_arm;
	struct px_canopen_config cc;
	struct px_canopen_sim_config sc;
	struct px_canopen_stop_config stc;
	struct px_canopen_stop_result res;
	struct px_sim_fault silent = {PX_SIM_FAULT_UNPLUG, 1000000000, 5000000000LL,
				      1.0, 3};
	struct stopper k;
	double targets[6] = {0.5, -0.25, 0.1, 0.2, 0.02, 0.0}, p0[6], p;
	char msg[200];
	int64_t t;
	int pass, st, i;
	for (pass = 0; pass < 2; pass++) {
		struct px_canopen *co;
		memset(&k, 0, sizeof k);
		px_can_sim_config_default(&bc);
		PX_CHECK_INT_EQ(px_can_sim_create(&bc, &bus), PX_OK);
		PX_CHECK_INT_EQ(px_can_sim_endpoint(bus, &ep_master), PX_OK);
		PX_CHECK_INT_EQ(px_can_sim_endpoint(bus, &ep_arm), PX_OK);
		PX_CHECK_INT_EQ(px_can_sim_endpoint(bus, &k.sniff), PX_OK);
		px_canopen_config_default(&cc);
		cc.drives = arm;
		cc.n_drives = 6;
		PX_CHECK_INT_EQ(px_canopen_create(&cc, ep_master, &co, msg,
						  sizeof msg),
				PX_OK);
		memset(&sc, 0, sizeof sc);
		sc.drives = arm;
		sc.n_drives = 6;
		sc.faults = pass ? &silent : NULL;
		sc.n_faults = pass ? 1 : 0;
		PX_CHECK_INT_EQ(px_canopen_sim_create(&sc, ep_arm, &k.sim), PX_OK);
		for (t = 1000000; t <= 1100000000; t += 1000000) {
			px_canopen_sim_step(k.sim, t);
			px_canopen_rx(co, t);
			px_canopen_tx(co, t, targets, 6, 1);
			sniff(&k, t);
		}
		if (!pass)
			PX_CHECK(px_canopen_all_enabled(co));
		for (i = 0; i < 6; i++)
			px_canopen_sim_joint(k.sim, (size_t)i, &p0[i], &st);
		k.n_cw1 = 0;
		px_canopen_stop_config_default(&stc);
		stc.wait = stop_wait;
		stc.user = &k;
		stc.timeout_ns = 300000000;
		i = px_canopen_safe_stop(co, t, &stc, &res);
		PX_CHECK_INT_EQ(res.drives, 6);
		PX_CHECK(k.calls <= 301); /* bounded by the timeout */
		PX_CHECK(res.elapsed_ns <= stc.timeout_ns + stc.period_ns);
		/* quick stop first, then disable voltage */
		PX_CHECK(k.n_cw1 >= 1);
		PX_CHECK_INT_EQ(k.cw1[0], PX_CIA402_CW_QUICK_STOP);
		if (k.n_cw1 > 1)
			PX_CHECK_INT_EQ(k.cw1[k.n_cw1 - 1],
					PX_CIA402_CW_DISABLE_VOLTAGE);
		if (!pass) {
			PX_CHECK_INT_EQ(i, PX_OK);
			PX_CHECK_INT_EQ(res.disabled, 6);
			PX_CHECK_INT_EQ(res.first_unconfirmed, -1);
			PX_CHECK(res.rounds <= 3);
		} else {
			PX_CHECK_INT_EQ(i, PX_E_TIMEOUT);
			PX_CHECK_INT_EQ(res.disabled, 5);
			PX_CHECK_INT_EQ(res.first_unconfirmed, 3);
		}
		for (i = 0; i < 6; i++) {
			px_canopen_sim_joint(k.sim, (size_t)i, &p, &st);
			if (pass && i == 3)
				continue; /* silent: never heard it */
			PX_CHECK_MSG(st == PX_CIA402_SWITCH_ON_DISABLED,
				     "drive %d: %s", i, px_cia402_state_name(st));
			/* stopped where it was (a CSP drive not sent to 0) */
			PX_CHECK_MSG(fabs(p - p0[i]) < 0.01, "drive %d moved %g",
				     i, p - p0[i]);
		}
		PX_CHECK(!px_canopen_all_enabled(co));
		px_canopen_sim_free(k.sim);
		px_canopen_free(co);
		px_can_sim_free(bus);
	}
	PX_CHECK_INT_EQ(px_canopen_safe_stop(NULL, 0, NULL, &res), PX_E_INVAL);
}

static void test_config_errors_name_the_drive(void)
{
	struct px_canopen_config cc;
	struct px_canopen_drive_cfg d[2] = {
		{1, PX_CIA402_CSV, 0, 1000.0, 0},
		{1, PX_CIA402_CSP, 1, 1000.0, 0},
	};
	struct px_can_sim_config bc;
	struct px_can_sim *bus;
	struct px_can_bus *ep;
	struct px_canopen *co;
	char msg[200];
	px_can_sim_config_default(&bc);
	PX_CHECK_INT_EQ(px_can_sim_create(&bc, &bus), PX_OK);
	PX_CHECK_INT_EQ(px_can_sim_endpoint(bus, &ep), PX_OK);
	px_canopen_config_default(&cc);
	cc.drives = d;
	cc.n_drives = 2;
	PX_CHECK_INT_EQ(px_canopen_create(&cc, ep, &co, msg, sizeof msg),
			PX_E_INVAL);
	PX_CHECK(strstr(msg, "drives[1] repeats node id 1") != NULL);
	d[1].node_id = 2;
	d[1].mode = PX_CIA402_CST; /* no rated torque */
	PX_CHECK_INT_EQ(px_canopen_create(&cc, ep, &co, msg, sizeof msg),
			PX_E_INVAL);
	PX_CHECK(strstr(msg, "drives[1] (node 2)") != NULL);
	d[1].rated_torque_n_m = 1.0;
	PX_CHECK_INT_EQ(px_canopen_create(&cc, ep, &co, msg, sizeof msg), PX_OK);
	px_canopen_free(co);
	px_can_sim_free(bus);
}

static int64_t mono(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

/* The master against tools/proxima-simarm as a second program, on the bus
 * given: a UNIX datagram pair, or vcan0 through the SocketCAN back end.
 * Behaviour only: no timing asserted. */
static void master_with_simarm(int on_vcan)
{
	const char *build = getenv("BUILD");
	char tool[256], pa[64], pb[64], msg[400];
	struct px_can_bus *bus;
	struct px_canopen_config cc;
	struct px_canopen *co;
	struct px_canopen_drive_status ds;
	struct px_canopen_drive_cfg d[2] = {
		{1, PX_CIA402_CSV, 0, 100000.0, 1.0},
		{2, PX_CIA402_CSV, 1, 100000.0, 1.0},
	};
	double targets[2] = {0.5, -0.2};
	pid_t pid;
	int i, ok = 0, st, e;
	snprintf(tool, sizeof tool, "%s/bin/proxima-simarm",
		 build && *build ? build : "build");
	if (access(tool, X_OK) != 0)
		PX_SKIP("%s not built", tool);
	snprintf(pa, sizeof pa, "/tmp/pxarm-a-%d", (int)getpid());
	snprintf(pb, sizeof pb, "/tmp/pxarm-b-%d", (int)getpid());
	if (on_vcan) {
		struct px_can_raw_config rc;
		memset(&rc, 0, sizeof rc);
		rc.interface = "vcan0";
		if (px_can_raw_open(&rc, &bus, &e, msg, sizeof msg) != PX_OK)
			PX_SKIP("no usable vcan0 here (%s): the VM suite runs "
				"this", msg);
	} else {
		PX_CHECK_INT_EQ(px_can_unix_open(pb, pa, &bus, msg, sizeof msg),
				PX_OK);
	}
	pid = fork();
	PX_CHECK(pid >= 0);
	if (pid == 0) {
		if (on_vcan)
			execl(tool, tool, "--can", "vcan0", "--drives", "2",
			      "--seconds", "60", (char *)NULL);
		else
			execl(tool, tool, "--unix", pa, pb, "--drives", "2",
			      "--seconds", "20", (char *)NULL);
		_exit(127);
	}
	px_canopen_config_default(&cc);
	cc.drives = d;
	cc.n_drives = 2;
	cc.heartbeat_timeout_ns = 0; /* the child may start slowly */
	PX_CHECK_INT_EQ(px_canopen_create(&cc, bus, &co, msg, sizeof msg),
			PX_OK);
	for (i = 0; i < 10000 && !ok; i++) {
		struct timespec ts = {0, 1000000};
		int64_t now = mono();
		px_canopen_rx(co, now);
		px_canopen_tx(co, now, targets, 2, 1);
		px_canopen_drive_status(co, 1, &ds);
		ok = px_canopen_all_enabled(co) && fabs(ds.velocity + 0.2) < 1e-9 &&
		     ds.nmt_state == 5;
		nanosleep(&ts, NULL);
	}
	kill(pid, SIGTERM);
	waitpid(pid, &st, 0);
	PX_CHECK_MSG(ok, "drive 2: %s, velocity %g, nmt %d",
		     px_cia402_state_name(ds.state), ds.velocity, ds.nmt_state);
	PX_CHECK(WIFEXITED(st) && WEXITSTATUS(st) == 0);
	px_canopen_free(co);
	px_can_bus_close(bus);
}

static void test_master_with_simarm_process(void)
{
	master_with_simarm(0);
}

static void test_master_with_simarm_on_vcan(void)
{
	master_with_simarm(1);
}

/* proxima-simarm --config takes the controller's drives, PDO mapping,
 * bus and drive faults from the controller's own config: with a
 * reordered RPDO and TPDO1 an arm on the default layout would never
 * enable; the e-stop of node 7 in the first 300 ms shows as its EMCY. */
static void test_simarm_takes_the_config_mapping(void)
{
	PX_NEEDS(YAML);
	const char *build = getenv("BUILD");
	char tool[256], path[64], sock[64], msg[512];
	struct px_config *cfg = NULL;
	struct px_config_diag diag;
	struct px_devcfg *h = NULL;
	struct px_canopen *co;
	struct px_canopen_drive_status ds;
	double targets[2] = {0.3, -0.4};
	pid_t pid;
	int i, ok = 0, st;
	FILE *f;
	snprintf(tool, sizeof tool, "%s/bin/proxima-simarm",
		 build && *build ? build : "build");
	if (access(tool, X_OK) != 0)
		PX_SKIP("%s not built", tool);
	snprintf(path, sizeof path, "/tmp/pxarm-cfg-%d.yaml", (int)getpid());
	snprintf(sock, sizeof sock, "/tmp/pxarm-cfg-%d", (int)getpid());
	f = fopen(path, "w");
	PX_CHECK(f != NULL);
	if (!f)
		return;
	fprintf(f,
		PX_TEST_YAML_HEAD PX_TEST_YAML_CAN("arm", "simbus", "unix")
		"      socket_path: %s\n"
		"      canopen:\n"
		"        heartbeat_timeout_ns: 0\n"
		"        rpdo: [{index: 0x6060, bits: 8}, {index: 0x607A, bits: 32}, {index: 0x6040, bits: 16}]\n"
		"        tpdo1: [{index: 0x6064, bits: 32}, {index: 0x6041, bits: 16}]\n"
		"        drives:\n"
		"          - {node_id: 7, mode: csp, joint: 0, counts_per_unit: 5000}\n"
		"          - {node_id: 3, mode: csp, joint: 1, counts_per_unit: 20000}\n"
		"      faults:\n"
		"        - {kind: estop, node_id: 7, start_ns: 0, duration_ns: 300000000}\n",
		sock);
	fclose(f);
	px_config_diag_init(&diag);
	PX_CHECK_INT_EQ(px_config_load_file(path, &cfg, &diag), PX_OK);
	if (!cfg)
		goto out;
	PX_CHECK_MSG(px_devcfg_open(cfg, &cfg->devices[0], NULL, &h, msg,
				    sizeof msg) == PX_OK,
		     "%s", msg);
	if (!h)
		goto out;
	co = px_devcfg_canopen(h);
	pid = fork();
	PX_CHECK(pid >= 0);
	if (pid == 0) {
		execl(tool, tool, "--config", path, "--seconds", "20",
		      (char *)NULL);
		_exit(127);
	}
	for (i = 0; i < 10000 && !ok; i++) {
		struct timespec ts = {0, 1000000};
		int64_t now = mono();
		px_canopen_rx(co, now);
		px_canopen_tx(co, now, targets, 2, 1);
		px_canopen_drive_status(co, 1, &ds);
		ok = px_canopen_all_enabled(co) &&
		     fabs(ds.position + 0.4) < 1e-3;
		nanosleep(&ts, NULL);
	}
	kill(pid, SIGTERM);
	waitpid(pid, &st, 0);
	PX_CHECK_MSG(ok, "drive node 3: %s, position %g",
		     px_cia402_state_name(ds.state), ds.position);
	/* node 7's e-stop window from the config: its EMCY reached us, and
	 * after the window the master brought it back */
	px_canopen_drive_status(co, 0, &ds);
	PX_CHECK_MSG(ds.emcy_count >= 1 && ds.emcy_code == 0x5441,
		     "node 7: %llu EMCY, code 0x%04x",
		     (unsigned long long)ds.emcy_count, ds.emcy_code);
	PX_CHECK(WIFEXITED(st) && WEXITSTATUS(st) == 0);
	/* the layout flags and --config do not mix */
	pid = fork();
	if (pid == 0) {
		freopen("/dev/null", "w", stderr);
		execl(tool, tool, "--config", path, "--drives", "2",
		      (char *)NULL);
		_exit(127);
	}
	waitpid(pid, &st, 0);
	PX_CHECK(WIFEXITED(st) && WEXITSTATUS(st) == 2);
out:
	px_devcfg_free(h);
	px_config_free(cfg);
	unlink(path);
}

static const struct px_test tests[] = {
	PX_T(test_master_with_simarm_process),
	PX_T(test_simarm_takes_the_config_mapping),
	PX_T(test_master_with_simarm_on_vcan),
	PX_T(test_statusword_table),
	PX_T(test_drive_transitions),
	PX_T(test_master_drives_simulated_arm),
	PX_T(test_config_errors_name_the_drive),
	PX_T(test_safe_stop_disables_every_drive),
};

PX_TEST_MAIN(tests)
