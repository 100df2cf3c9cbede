/* Device configuration beyond the back ends' own keys: fault windows
 * from the config reaching simulated devices and buses, the CANopen
 * master's own node id, libusb no_hotplug, the stuck and duplicate
 * detectors, and the CAN bitrate applied through a simulated netlink
 * (libsocketcan call table). */
/* PX_TEST_NEEDS: libyaml (tests/run.sh skips it in builds without) */
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "px_alloc_count.h"
#include "px_can.h"
#include "px_canopen.h"
#include "px_config.h"
#include "px_devcfg.h"
#include "px_test.h"
#include "px_test_config.h"

static struct px_config_diag g_diag;

/* The first diagnostic of a config that must not load. */
static int load_fails_with(const char *yaml, const char *want)
{
	struct px_config *c = NULL;
	char buf[4096];
	FILE *f;
	int rc = px_config_load_mem("t.yaml", yaml, strlen(yaml), &c, &g_diag);
	size_t n;
	if (rc == PX_OK) {
		px_config_free(c);
		PX_CHECK_MSG(0, "loaded, wanted '%s'", want);
		return 0;
	}
	f = fmemopen(buf, sizeof(buf) - 1, "w");
	if (!f)
		return 0;
	px_config_diag_print(&g_diag, f);
	n = (size_t)ftell(f);
	fclose(f);
	buf[n < sizeof(buf) ? n : sizeof(buf) - 1] = 0;
	PX_CHECK_MSG(strstr(buf, want) != NULL, "want '%s' in:\n%s", want, buf);
	return 1;
}

static void send_xy(struct px_can_bus *b, double x, int64_t t)
{
	static const struct px_can_signal sx = {
		"x", 0x100, 0, 0, 0, 16, PX_LITTLE_ENDIAN, 1, 1e-4, 0,
		0, 0, 0, 0, PX_AXIS_X, 0};
	struct px_can_msg m;
	memset(&m, 0, sizeof m);
	m.f.can_id = 0x100;
	m.f.len = 8;
	px_can_signal_encode(&sx, x, m.f.data, 8, NULL);
	px_can_bus_send(b, &m, t);
}

#define CAN_SIGNALS                                                         \
	"      signals:\n"                                                  \
	"        - {name: x, id: 0x100, direction: input, start_bit: 0, "   \
	"length: 16, signed: true, scale: 0.0001, axis: x}\n"

/* socketcan faults from the config wrap the device's endpoint: an
 * unplug window and a stuck window, on a bus the test also sits on. */
static void test_can_sim_faults_from_config(void)
{
	static const char y[] =
		"version: 1\n"
		"devices:\n"
		"  - name: arm\n"
		"    backend: socketcan\n"
		"    stuck_limit: 5\n"
		"    socketcan:\n"
		"      interface: simbus\n"
		"      transport: sim\n" CAN_SIGNALS
		"      faults:\n"
		"        - {kind: unplug, start_ns: 20000000, duration_ns: 10000000}\n"
		"        - {kind: stuck, start_ns: 50000000, duration_ns: 20000000}\n";
	struct px_config *cfg = px_test_config_load(y, &g_diag);
	struct px_can_sim_config sc;
	struct px_can_sim *bus = NULL;
	struct px_can_bus *robot = NULL;
	struct px_devcfg_options opt;
	struct px_devcfg *h = NULL;
	struct px_dev *d;
	struct px_pose_sample ps;
	struct px_dev_status st;
	char msg[512];
	int64_t t, t0 = 1000000000; /* the run starts at 1 s of the clock */
	int unplugged = 0, stuck_seen = 0;
	uint64_t r;
	PX_CHECK(cfg != NULL);
	if (!cfg)
		return;
	px_can_sim_config_default(&sc);
	PX_CHECK_INT_EQ(px_can_sim_create(&sc, &bus), PX_OK);
	PX_CHECK_INT_EQ(px_can_sim_endpoint(bus, &robot), PX_OK);
	memset(&opt, 0, sizeof opt);
	opt.can_sim = bus;
	opt.clock0_ns = t0;
	PX_CHECK_MSG(px_devcfg_open(cfg, &cfg->devices[0], &opt, &h, msg,
				    sizeof msg) == PX_OK,
		     "%s", msg);
	d = px_devcfg_dev(h);
	PX_CHECK(d != NULL);
	if (!d)
		goto out;
	PX_CHECK_INT_EQ(px_dev_config(d)->stuck_limit, 5);
	PX_CHECK_INT_EQ(px_dev_start(d), PX_OK);
	r = px_alloc_region_begin();
	for (t = t0; t < t0 + 100000000; t += 1000000) {
		int rc;
		send_xy(robot, 1e-4 * (double)((t - t0) / 1000000), t);
		rc = px_dev_pose_read(d, t, &ps);
		if (t >= t0 + 20000000 && t < t0 + 30000000) {
			PX_CHECK_INT_EQ(rc, PX_E_NODEV);
			unplugged += px_dev_state(d) == PX_DEV_STATE_UNPLUGGED;
		} else if (t >= t0 + 60000000 && t < t0 + 70000000) {
			/* frozen frames: held back by the stuck detector */
			stuck_seen += rc == 0;
		} else if (t < t0 + 20000000 ||
			   (t >= t0 + 30000000 && t < t0 + 50000000) ||
			   t >= t0 + 70000000) {
			PX_CHECK_MSG(rc == 1, "t %lld: %d", (long long)(t - t0),
				     rc);
		}
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(r), 0);
	PX_CHECK_INT_EQ(unplugged, 10);
	PX_CHECK_INT_EQ(stuck_seen, 10);
	px_dev_status(d, &st);
	PX_CHECK_INT_EQ(st.unplugs, 1);
	PX_CHECK_INT_EQ(st.replugs, 1);
	PX_CHECK_INT_EQ(st.stuck, 1);
out:
	px_devcfg_free(h);
	px_can_bus_close(robot);
	px_can_sim_free(bus);
	px_config_free(cfg);
}

/* transport unix with a delay fault and the duplicate detector: frames
 * arrive 5 ms late in the window, duplicates are dropped. */
static void test_can_unix_faults_from_config(void)
{
	char y[2048], path[64], peer[80];
	struct px_config *cfg;
	struct px_devcfg *h = NULL;
	struct px_can_bus *robot = NULL;
	struct px_dev *d;
	struct px_pose_sample ps;
	struct px_dev_status st;
	char msg[512];
	int64_t t;
	int fresh_in_window = 0;
	snprintf(path, sizeof path, "/tmp/px_dcf_%d", (int)getpid());
	snprintf(peer, sizeof peer, "%s.peer", path);
	snprintf(y, sizeof y,
		 "version: 1\n"
		 "devices:\n"
		 "  - name: arm\n"
		 "    backend: socketcan\n"
		 "    min_report_interval_ns: 500000\n"
		 "    socketcan:\n"
		 "      interface: simbus\n"
		 "      transport: unix\n"
		 "      socket_path: %s\n" CAN_SIGNALS
		 "      faults:\n"
		 "        - {kind: delay, start_ns: 10000000, duration_ns: 10000000, delay_ns: 5000000}\n"
		 "        - {kind: duplicate, start_ns: 30000000, duration_ns: 10000000}\n",
		 path);
	cfg = px_test_config_load(y, &g_diag);
	PX_CHECK(cfg != NULL);
	if (!cfg)
		return;
	PX_CHECK_MSG(px_devcfg_open(cfg, &cfg->devices[0], NULL, &h, msg,
				    sizeof msg) == PX_OK,
		     "%s", msg);
	PX_CHECK_INT_EQ(px_can_unix_open(peer, path, &robot, msg, sizeof msg),
			PX_OK);
	d = px_devcfg_dev(h);
	if (!d || !robot)
		goto out;
	PX_CHECK_INT_EQ(px_dev_start(d), PX_OK);
	for (t = 0; t < 50000000; t += 1000000) {
		int rc;
		send_xy(robot, 1e-4 * (double)(t / 1000000), t);
		rc = px_dev_pose_read(d, t, &ps);
		if (t >= 10000000 && t < 15000000)
			fresh_in_window += rc == 1; /* the 5 ms gap */
		else
			PX_CHECK_MSG(rc == 1, "t %lld: %d", (long long)t, rc);
		if (t >= 15000000 && t < 20000000)
			PX_CHECK_MSG(ps.age_ns == 0 && ps.pos_m.x < 1e-4 *
						(double)(t / 1000000) - 4e-4,
				     "t %lld: x %g", (long long)t, ps.pos_m.x);
	}
	PX_CHECK_INT_EQ(fresh_in_window, 0);
	px_dev_status(d, &st);
	PX_CHECK_INT_EQ(st.duplicates, 10);
	PX_CHECK_INT_EQ(st.samples, 50); /* late, but none lost */
out:
	px_devcfg_free(h);
	px_can_bus_close(robot);
	px_config_free(cfg);
}

/* sim haptic and sim gpio faults from the config. */
static void test_sim_faults_from_config(void)
{
	static const char y[] =
		PX_TEST_YAML_HEAD PX_TEST_YAML_SIM_HAP_IO
		"      faults:\n"
		"        - {kind: estop, start_ns: 5000000, duration_ns: 5000000}\n";
	struct px_config *cfg = px_test_config_load(y, &g_diag);
	struct px_devcfg *h = NULL, *g = NULL;
	struct px_pose_sample ps;
	struct px_dev_status st;
	char msg[512];
	int64_t t;
	int pressed, n_pressed = 0;
	PX_CHECK(cfg != NULL);
	if (!cfg)
		return;
	PX_CHECK_MSG(px_devcfg_open(cfg, &cfg->devices[0], NULL, &h, msg,
				    sizeof msg) == PX_OK,
		     "%s", msg);
	PX_CHECK_MSG(px_devcfg_open(cfg, &cfg->devices[1], NULL, &g, msg,
				    sizeof msg) == PX_OK,
		     "%s", msg);
	if (!h || !g)
		goto out;
	px_dev_start(px_devcfg_dev(h));
	px_dev_start(px_devcfg_dev(g));
	for (t = 0; t < 30000000; t += 1000000) {
		px_dev_pose_read(px_devcfg_dev(h), t, &ps);
		PX_CHECK_INT_EQ(px_dev_estop_read(px_devcfg_dev(g), t, &pressed),
				PX_OK);
		n_pressed += pressed;
	}
	px_dev_status(px_devcfg_dev(h), &st);
	PX_CHECK_MSG(st.nonfinite >= 9 && st.nonfinite <= 11, "%llu",
		     (unsigned long long)st.nonfinite);
	/* 5 ms pressed; the contact bounces for 0.4 ms at the press */
	PX_CHECK_MSG(n_pressed >= 4 && n_pressed <= 5, "%d", n_pressed);
out:
	px_devcfg_free(h);
	px_devcfg_free(g);
	px_config_free(cfg);
}

/* Faults a back end cannot take are refused at load, naming the entry. */
static void test_fault_config_errors(void)
{
	load_fails_with("version: 1\ndevices:\n  - name: a\n    backend: socketcan\n"
			"    socketcan:\n      interface: can0\n" CAN_SIGNALS
			"      faults: [{kind: drop, start_ns: 0, duration_ns: 1}]\n",
			"faults[0]: bus faults are injected on simulated buses "
			"only");
	load_fails_with("version: 1\ndevices:\n  - name: a\n    backend: socketcan\n"
			"    socketcan:\n      interface: b\n      transport: sim\n"
			CAN_SIGNALS
			"      faults: [{kind: drop, start_ns: 0, duration_ns: 1},"
			" {kind: estop, start_ns: 0, duration_ns: 1}]\n",
			"faults[1].kind: kind 'estop' is not a CAN bus fault: "
			"give the node_id");
	load_fails_with("version: 1\ndevices:\n  - name: a\n    backend: socketcan\n"
			"    socketcan:\n      interface: b\n      transport: sim\n"
			"      canopen:\n        drives: [{node_id: 4, joint: 0}]\n"
			"      faults: [{kind: estop, node_id: 5, start_ns: 0, "
			"duration_ns: 1}, {kind: drop, node_id: 4, start_ns: 0, "
			"duration_ns: 1}]\n",
			"faults[0].node_id: no canopen drive has node id 5");
	load_fails_with("version: 1\ndevices:\n  - name: a\n    backend: socketcan\n"
			"    socketcan:\n      interface: b\n      transport: sim\n"
			"      canopen:\n        drives: [{node_id: 4, joint: 0}]\n"
			"      faults: [{kind: drop, node_id: 4, start_ns: 0, "
			"duration_ns: 1}]\n",
			"faults[0].node_id: a drive of the simulated arm takes "
			"estop");
	load_fails_with("version: 1\ndevices:\n  - name: a\n    backend: sim\n"
			"    sim:\n      faults: [{kind: bus_off, start_ns: 0, "
			"duration_ns: 1}]\n",
			"faults[0].kind: kind 'bus_off' does not apply to a "
			"simulated haptic");
	load_fails_with("version: 1\ndevices:\n  - name: a\n    backend: sim\n"
			"    sim:\n      kind: gpio\n      lines: [{name: estop, "
			"direction: input}]\n      faults: [{kind: nan, "
			"start_ns: 0, duration_ns: 1}]\n",
			"kind 'nan' does not apply to simulated GPIO");
	load_fails_with("version: 1\ndevices:\n  - name: a\n    backend: sim\n"
			"    sim:\n      faults: [{kind: delay, start_ns: 0, "
			"duration_ns: 1}]\n",
			"delay_ns: missing or zero for kind 'delay'");
	load_fails_with("version: 1\ndevices:\n  - name: a\n    backend: socketcan\n"
			"    socketcan:\n      interface: b\n      transport: sim\n"
			"      canopen:\n        node_id: 4\n        drives: "
			"[{node_id: 4, joint: 0}]\n",
			"drives[0].node_id: node id 4 is the master's own");
	load_fails_with("version: 1\ndevices:\n  - name: a\n    backend: socketcan\n"
			"    socketcan:\n      interface: b\n      transport: sim\n"
			"      bitrate: 500000\n" CAN_SIGNALS,
			"bitrate: only for a kernel interface");
	load_fails_with("version: 1\ndevices:\n  - name: a\n    backend: socketcan\n"
			"    socketcan:\n      interface: can0\n      restart_ms: 100\n"
			CAN_SIGNALS,
			"restart_ms: applied with bitrate");
}

/* The master's heartbeat carries its own node id: the configured one,
 * else the highest id no drive uses. */
static int heartbeat_id(const char *yaml)
{
	struct px_config *cfg = px_test_config_load(yaml, &g_diag);
	struct px_devcfg *h = NULL;
	struct px_can_bus *ep = NULL;
	struct px_can_msg m;
	char msg[512];
	int id = -1, k;
	if (!cfg)
		return -2;
	PX_CHECK_MSG(px_devcfg_open(cfg, &cfg->devices[0], NULL, &h, msg,
				    sizeof msg) == PX_OK,
		     "%s", msg);
	if (h &&
	    px_can_sim_endpoint(px_devcfg_can_sim(h), &ep) == PX_OK) {
		double tg[2] = {0, 0};
		for (k = 1; k <= 3; k++)
			px_canopen_tx(px_devcfg_canopen(h), k * 1000000LL, tg, 2,
				      0);
		while (px_can_bus_recv(ep, 3000000, &m) == PX_OK)
			if ((m.f.can_id & 0x780) == 0x700 && m.f.len == 1)
				id = (int)(m.f.can_id & 0x7f);
		px_can_bus_close(ep);
	}
	px_devcfg_free(h);
	px_config_free(cfg);
	return id;
}

static void test_canopen_own_node_id(void)
{
#define CO_HEAD                                                             \
	"version: 1\ndevices:\n  - name: a\n    backend: socketcan\n"       \
	"    socketcan:\n      interface: b\n      transport: sim\n"        \
	"      canopen:\n        heartbeat_period_ns: 1000000\n"            \
	"        heartbeat_timeout_ns: 0\n"
	PX_CHECK_INT_EQ(heartbeat_id(CO_HEAD "        drives: [{node_id: 2, "
					     "joint: 0}]\n"),
			127);
	PX_CHECK_INT_EQ(heartbeat_id(CO_HEAD "        drives: [{node_id: 127, "
					     "joint: 0}, {node_id: 126, "
					     "joint: 1}]\n"),
			125);
	PX_CHECK_INT_EQ(heartbeat_id(CO_HEAD "        node_id: 5\n"
					     "        drives: [{node_id: 2, "
					     "joint: 0}]\n"),
			5);
#undef CO_HEAD
}

/* Faults with node_id go to the simulated arm: an e-stop of drive 3
 * (safe torque off: FAULT and EMCY) and drive 9 falling silent, seen by
 * the master opened from the same config; bus faults stay off. */
static void test_arm_faults_from_config(void)
{
	static const char y[] =
		PX_TEST_YAML_HEAD PX_TEST_YAML_CAN("arm", "simbus", "sim")
		"      canopen:\n"
		"        heartbeat_period_ns: 10000000\n"
		"        heartbeat_timeout_ns: 30000000\n"
		"        drives:\n"
		"          - {node_id: 3, mode: csv, joint: 0}\n"
		"          - {node_id: 9, mode: csv, joint: 1}\n"
		"      faults:\n"
		"        - {kind: estop, node_id: 3, start_ns: 100000000, duration_ns: 50000000}\n"
		"        - {kind: unplug, node_id: 9, start_ns: 200000000, duration_ns: 100000000}\n";
	struct px_config *cfg = px_test_config_load(y, &g_diag);
	struct px_devcfg *h = NULL;
	struct px_canopen_drive_cfg dr[4];
	struct px_canopen_pdo_map pdo;
	struct px_sim_fault f[4];
	struct px_canopen_sim_config sc;
	struct px_canopen_sim *arm = NULL;
	struct px_can_bus *ep = NULL;
	struct px_canopen_drive_status d0, d1;
	double tg[2] = {0.1, 0.1};
	size_t nd = 0;
	char msg[512];
	int k, n, fault_seen = 0, lost_seen = 0;
	PX_CHECK(cfg != NULL);
	if (!cfg)
		return;
	PX_CHECK_MSG(px_devcfg_open(cfg, &cfg->devices[0], NULL, &h, msg,
				    sizeof msg) == PX_OK,
		     "%s", msg);
	n = px_devcfg_arm_faults(cfg, &cfg->devices[0], 0, f, 4);
	PX_CHECK_INT_EQ(n, 2);
	PX_CHECK_INT_EQ(px_devcfg_arm_faults(cfg, &cfg->devices[0], 0, f, 1),
			PX_E_NOSPC);
	PX_CHECK_INT_EQ(px_devcfg_canopen_layout(cfg, &cfg->devices[0], dr, 4,
						 &nd, &pdo, msg, sizeof msg),
			PX_OK);
	if (!h || n != 2)
		goto out;
	PX_CHECK_INT_EQ(f[0].kind, PX_SIM_FAULT_ESTOP);
	PX_CHECK_INT_EQ(f[0].delay_ns, 0); /* drive index */
	PX_CHECK_INT_EQ(f[1].kind, PX_SIM_FAULT_UNPLUG);
	PX_CHECK_INT_EQ(f[1].delay_ns, 1);
	memset(&sc, 0, sizeof sc);
	sc.pdo = &pdo;
	sc.drives = dr;
	sc.n_drives = nd;
	sc.heartbeat_period_ns = 10000000;
	sc.faults = f;
	sc.n_faults = (size_t)n;
	PX_CHECK_INT_EQ(px_can_sim_endpoint(px_devcfg_can_sim(h), &ep), PX_OK);
	PX_CHECK_INT_EQ(px_canopen_sim_create(&sc, ep, &arm), PX_OK);
	for (k = 1; k <= 400; k++) {
		int64_t t = k * 1000000LL;
		px_canopen_sim_step(arm, t);
		px_canopen_rx(px_devcfg_canopen(h), t);
		px_canopen_tx(px_devcfg_canopen(h), t, tg, 2, 1);
		px_canopen_drive_status(px_devcfg_canopen(h), 0, &d0);
		px_canopen_drive_status(px_devcfg_canopen(h), 1, &d1);
		if (d0.state == PX_CIA402_FAULT && d0.emcy_code == 0x5441) {
			PX_CHECK_MSG(t >= 100000000 && t < 160000000, "t %lld",
				     (long long)t);
			fault_seen++;
		}
		if (d1.lost) {
			PX_CHECK_MSG(t >= 200000000 && t < 320000000, "t %lld",
				     (long long)t);
			lost_seen++;
		}
	}
	PX_CHECK(fault_seen > 10);
	PX_CHECK(lost_seen > 10);
	/* both back: the master enabled them again */
	PX_CHECK(px_canopen_all_enabled(px_devcfg_canopen(h)));
out:
	px_canopen_sim_free(arm);
	px_can_bus_close(ep);
	px_devcfg_free(h);
	px_config_free(cfg);
}

static void test_usb_no_hotplug_key(void)
{
	static const char y[] =
		"version: 1\n"
		"devices:\n"
		"  - name: u\n"
		"    backend: libusb\n"
		"    libusb:\n"
		"      vid: 0x1234\n"
		"      pid: 0x5678\n"
		"      endpoint_in: 0x81\n"
		"      no_hotplug: true\n"
		"      inputs: [{byte_offset: 0, axis: x}]\n"
		"  - name: v\n"
		"    backend: libusb\n"
		"    libusb:\n"
		"      vid: 0x1234\n"
		"      pid: 0x5678\n"
		"      endpoint_in: 0x81\n"
		"      inputs: [{byte_offset: 0, axis: x}]\n";
	struct px_config *cfg = px_test_config_load(y, &g_diag);
	PX_CHECK(cfg != NULL);
	if (!cfg)
		return;
	PX_CHECK(cfg->devices[0].libusb.no_hotplug);
	PX_CHECK(!cfg->devices[1].libusb.no_hotplug);
	px_config_free(cfg);
}

/* ---- bitrate through a simulated netlink ---------------------------- */

static char calls[256];
static uint32_t nl_rate, nl_restart;
static int nl_fail_errno;     /* errno of the failing call */
static const char *nl_fail_at; /* "stop", "bitrate", ... */
static int nl_virtual, nl_present = 1;

static void note(const char *c)
{
	size_t n = strlen(calls);
	snprintf(calls + n, sizeof calls - n, "%s%s", n ? "," : "", c);
}

static int step(const char *c)
{
	note(c);
	if (nl_fail_at && !strcmp(nl_fail_at, c)) {
		errno = nl_fail_errno;
		return -1;
	}
	return 0;
}

static int f_exists(const char *i) { (void)i; return nl_present; }
static int f_virtual(const char *i) { (void)i; return nl_virtual; }
static int f_stop(const char *i) { (void)i; return step("stop"); }
static int f_start(const char *i) { (void)i; return step("start"); }
static int f_rate(const char *i, uint32_t b)
{
	(void)i;
	if (step("bitrate"))
		return -1;
	nl_rate = b;
	return 0;
}
static int f_restart(const char *i, uint32_t ms)
{
	(void)i;
	if (step("restart"))
		return -1;
	nl_restart = ms;
	return 0;
}
static int f_get(const char *i, uint32_t *b)
{
	(void)i;
	*b = nl_rate;
	return 0;
}

static const struct px_can_netlink_ops fake = {
	f_exists, f_virtual, f_stop, f_start, f_rate, f_restart, f_get};

static void reset_nl(void)
{
	calls[0] = 0;
	nl_rate = 250000;
	nl_restart = 0;
	nl_fail_at = NULL;
	nl_fail_errno = 0;
	nl_virtual = 0;
	nl_present = 1;
}

static void test_bitrate_applied(void)
{
	char msg[512];
	int e = -1;
	px_can_netlink_set_ops(&fake);
	reset_nl();
	PX_CHECK_INT_EQ(px_can_iface_set_bitrate("can0", 500000, 100, &e, msg,
						 sizeof msg),
			PX_OK);
	PX_CHECK_MSG(!strcmp(calls, "stop,bitrate,restart,start"), "%s", calls);
	PX_CHECK_INT_EQ(nl_rate, 500000);
	PX_CHECK_INT_EQ(nl_restart, 100);
	PX_CHECK_INT_EQ(e, 0);
	/* already at the bitrate: left alone (no privilege needed) */
	calls[0] = 0;
	PX_CHECK_INT_EQ(px_can_iface_set_bitrate("can0", 500000, 0, &e, msg,
						 sizeof msg),
			PX_OK);
	PX_CHECK_MSG(calls[0] == 0, "%s", calls);
	/* without privilege: the errno, the call and the hint */
	reset_nl();
	nl_fail_at = "stop";
	nl_fail_errno = EPERM;
	PX_CHECK_INT_EQ(px_can_iface_set_bitrate("can0", 500000, 0, &e, msg,
						 sizeof msg),
			PX_E_PERM);
	PX_CHECK_INT_EQ(e, EPERM);
	PX_CHECK_MSG(strstr(msg, "can0: can_do_stop (ip link set down): errno "
				 "EPERM (1)") &&
			     strstr(msg, "CAP_NET_ADMIN"),
		     "%s", msg);
	PX_CHECK_INT_EQ(nl_rate, 250000);
	/* a refused bitrate still brings the interface up again */
	reset_nl();
	nl_fail_at = "bitrate";
	nl_fail_errno = EINVAL;
	PX_CHECK_INT_EQ(px_can_iface_set_bitrate("can0", 123456, 0, &e, msg,
						 sizeof msg),
			PX_E_UNSUPPORTED);
	PX_CHECK_MSG(!strcmp(calls, "stop,bitrate,start"), "%s", calls);
	PX_CHECK_MSG(strstr(msg, "can_set_bitrate: errno EINVAL") != NULL, "%s",
		     msg);
	/* a virtual interface has no bitrate: said, not applied */
	reset_nl();
	nl_virtual = 1;
	PX_CHECK_INT_EQ(px_can_iface_set_bitrate("vcan0", 500000, 0, &e, msg,
						 sizeof msg),
			PX_E_UNSUPPORTED);
	PX_CHECK_INT_EQ(e, 0);
	PX_CHECK_MSG(calls[0] == 0, "%s", calls);
	PX_CHECK_MSG(strstr(msg, "vcan0: a virtual CAN interface") != NULL, "%s",
		     msg);
	/* absent */
	reset_nl();
	nl_present = 0;
	PX_CHECK_INT_EQ(px_can_iface_set_bitrate("can7", 500000, 0, &e, msg,
						 sizeof msg),
			PX_E_NODEV);
	PX_CHECK_MSG(strstr(msg, "can7: no such network interface") != NULL,
		     "%s", msg);
	PX_CHECK_INT_EQ(px_can_iface_set_bitrate("can0", 0, 0, &e, msg,
						 sizeof msg),
			PX_E_INVAL);
	px_can_netlink_set_ops(NULL);
}

/* Through the config: the bitrate is applied before the socket opens;
 * a refusal fails the open at socketcan.bitrate, a virtual interface
 * is a note and the open goes on. */
static void test_bitrate_from_config(void)
{
	static const char y[] =
		"version: 1\n"
		"devices:\n"
		"  - name: arm\n"
		"    backend: socketcan\n"
		"    socketcan:\n"
		"      interface: can0\n"
		"      bitrate: 1000000\n"
		"      restart_ms: 50\n" CAN_SIGNALS;
	struct px_config *cfg = px_test_config_load(y, &g_diag);
	struct px_devcfg *h = NULL;
	char msg[512];
	int rc;
	PX_CHECK(cfg != NULL);
	if (!cfg)
		return;
	px_can_netlink_set_ops(&fake);
	reset_nl();
	nl_fail_at = "bitrate";
	nl_fail_errno = EPERM;
	PX_CHECK_INT_EQ(px_devcfg_open(cfg, &cfg->devices[0], NULL, &h, msg,
				       sizeof msg),
			PX_E_PERM);
	PX_CHECK_MSG(strstr(msg, "device 'arm' (socketcan, devices[0]."
				 "socketcan.bitrate): can0: can_set_bitrate: "
				 "errno EPERM") &&
			     strstr(msg, "CAP_NET_ADMIN"),
		     "%s", msg);
	reset_nl();
	PX_CHECK_INT_EQ(nl_rate, 250000);
	rc = px_devcfg_open(cfg, &cfg->devices[0], NULL, &h, msg, sizeof msg);
	PX_CHECK_INT_EQ(nl_rate, 1000000);
	PX_CHECK_INT_EQ(nl_restart, 50);
	/* the socket itself opens where the kernel has CAN (not here) */
	PX_CHECK_MSG(rc == PX_OK || strstr(msg, "socketcan.interface"), "%s",
		     msg);
	px_devcfg_free(h);
	h = NULL;
	reset_nl();
	nl_virtual = 1;
	rc = px_devcfg_open(cfg, &cfg->devices[0], NULL, &h, msg, sizeof msg);
	PX_CHECK_MSG(rc == PX_OK || strstr(msg, "socketcan.interface"), "%s",
		     msg);
	if (rc == PX_OK)
		PX_CHECK_MSG(strstr(px_devcfg_notes(h), "no bitrate") != NULL,
			     "%s", px_devcfg_notes(h));
	px_devcfg_free(h);
	px_can_netlink_set_ops(NULL);
	px_config_free(cfg);
}

static const struct px_test tests[] = {
	PX_T(test_can_sim_faults_from_config),
	PX_T(test_can_unix_faults_from_config),
	PX_T(test_sim_faults_from_config),
	PX_T(test_fault_config_errors),
	PX_T(test_canopen_own_node_id),
	PX_T(test_arm_faults_from_config),
	PX_T(test_usb_no_hotplug_key),
	PX_T(test_bitrate_applied),
	PX_T(test_bitrate_from_config),
};

PX_TEST_MAIN(tests)
