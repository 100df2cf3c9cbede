/* Opening devices from configurations (px_devcfg): every shipped example,
 * signal axes, drive scaling, GPIO roles and the errors. */
/* PX_TEST_NEEDS: libyaml (tests/run.sh skips it in builds without) */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "px_can.h"
#include "px_canopen.h"
#include "px_config.h"
#include "px_devcfg.h"
#include "px_gpio.h"
#include "px_sim.h"
#include "px_alloc_count.h"
#include "px_test.h"
#include "px_test_config.h"

static struct px_config_diag g_diag;

static int is_simulated(const struct px_config_device *d)
{
	return d->backend == PX_CONFIG_BACKEND_SIM ||
	       (d->backend == PX_CONFIG_BACKEND_SOCKETCAN &&
		d->socketcan.transport != PX_CONFIG_CAN_KERNEL);
}

/* Every device of every shipped example opens through the glue when its
 * back end is simulated; a real one either opens (hardware present, as
 * in the VM suite) or fails naming the device, its key and a reason. */
static void test_examples_open(void)
{
	static const char *const files[] = {
		"config/examples/haptic_sim.yaml",
		"config/examples/haptic_hid.yaml",
		"config/examples/spacemouse_hid.yaml",
		"config/examples/can_sim.yaml",
		"config/examples/can_arm.yaml",
	};
	size_t f, i;
	int real_failed = 0;
	if (access(files[0], R_OK) != 0)
		PX_SKIP("config/examples not found (run from the source tree)");
	for (f = 0; f < sizeof(files) / sizeof(files[0]); f++) {
		struct px_config *cfg = NULL;
		int rc = px_config_load_file(files[f], &cfg, &g_diag);
		PX_CHECK_MSG(rc == PX_OK, "%s: %s", files[f], px_strerror(rc));
		if (rc != PX_OK)
			continue;
		for (i = 0; i < cfg->n_devices; i++) {
			const struct px_config_device *d = &cfg->devices[i];
			struct px_devcfg *h = NULL;
			char msg[768], want[96];
			rc = px_devcfg_open(cfg, d, NULL, &h, msg, sizeof(msg));
			if (is_simulated(d)) {
				PX_CHECK_MSG(rc == PX_OK, "%s: %s", files[f],
					     msg);
				PX_CHECK(h != NULL);
				PX_CHECK(px_devcfg_dev(h) != NULL ||
					 px_devcfg_canopen(h) != NULL);
			} else if (rc != PX_OK) {
				real_failed++;
				PX_CHECK(h == NULL);
				snprintf(want, sizeof(want),
					 "device '%s' (%s, devices[%zu].", d->name,
					 px_config_backend_names()[d->backend],
					 i);
				PX_CHECK_MSG(strstr(msg, want) == msg,
					     "%s: '%s' lacks '%s'", files[f],
					     msg, want);
				/* the back end's reason follows the place */
				PX_CHECK_MSG(strlen(msg) > strlen(want) + 12,
					     "%s: no reason in '%s'", files[f],
					     msg);
				printf("    %s: %s\n", files[f], msg);
			}
			px_devcfg_free(h);
		}
		px_config_free(cfg);
	}
	printf("    %d real back ends failed to open (no hardware)\n",
	       real_failed);
}

/* The shipped simulated haptic device runs: pose from its reports,
 * force commands accepted, no allocation in the cycle. */
static void test_sim_haptic_runs(void)
{
	struct px_config *cfg;
	struct px_devcfg *h = NULL;
	struct px_pose_sample s;
	struct px_force_cmd fc;
	char msg[512];
	int k, fresh = 0;
	uint64_t region;
	if (access("config/examples/haptic_sim.yaml", R_OK) != 0)
		PX_SKIP("config/examples not found");
	PX_CHECK_INT_EQ(px_config_load_file("config/examples/haptic_sim.yaml",
					    &cfg, &g_diag),
			PX_OK);
	PX_CHECK_INT_EQ(px_devcfg_open(cfg, &cfg->devices[0], NULL, &h, msg,
				       sizeof(msg)),
			PX_OK);
	PX_CHECK_INT_EQ(px_dev_start(px_devcfg_dev(h)), PX_OK);
	memset(&fc, 0, sizeof(fc));
	fc.enable = 1;
	fc.force_n[2] = -0.5;
	region = px_alloc_region_begin();
	for (k = 1; k <= 200; k++) {
		int rc = px_dev_pose_read(px_devcfg_dev(h), k * 1000000LL, &s);
		PX_CHECK(rc >= 0);
		fresh += rc == 1;
		PX_CHECK_INT_EQ(px_dev_force_write(px_devcfg_dev(h), &fc,
						   k * 1000000LL),
				PX_OK);
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(region), 0);
	/* 1 ms reports read at 1 kHz: nearly every read is fresh */
	PX_CHECK_MSG(fresh > 150, "fresh %d", fresh);
	PX_CHECK(s.valid && !s.stale);
	{
		/* the pose read is the simulated arm's position (noise
		 * 1e-5 m, up to one report old), and the force command
		 * reached the arm through the config's codec */
		struct px_sim_haptic_state st;
		PX_CHECK_INT_EQ(px_sim_haptic_state(px_devcfg_dev(h), &st),
				PX_OK);
		PX_CHECK_NEAR(s.pos_m.x, st.pos_m[0], 5e-4);
		PX_CHECK_NEAR(s.pos_m.y, st.pos_m[1], 5e-4);
		PX_CHECK_NEAR(s.pos_m.z, st.pos_m[2], 5e-4);
		PX_CHECK_CLOSE(st.force_n[2], -0.5, 1e-9, 0);
		PX_CHECK(st.outputs_decoded > 0);
	}
	px_devcfg_free(h);
	px_config_free(cfg);
}

/* Signals with axes on a simulated bus: input frames set pose axes,
 * force commands go out as output frames (random values, checked
 * against the signal formula). */
static void test_can_signal_axes(void)
{
	static const char y[] =
		PX_TEST_YAML_HEAD PX_TEST_YAML_CAN("ft", "simbus", "sim")
		"      signals:\n"
		"        - {name: px, id: 0x101, direction: input, start_bit: 0, length: 16, signed: true, scale: 0.001, axis: x}\n"
		"        - {name: pz, id: 0x101, direction: input, start_bit: 16, length: 16, signed: true, scale: 0.001, axis: z}\n"
		"        - {name: st, id: 0x101, direction: input, start_bit: 32, length: 8}\n"
		"        - {name: fy, id: 0x201, direction: output, start_bit: 0, length: 16, signed: true, scale: 0.01, axis: fy}\n"
		"        - {name: tz, id: 0x201, direction: output, start_bit: 23, length: 16, byte_order: big, signed: true, scale: 0.001, axis: tz}\n";
	struct px_config *cfg = px_test_config_load(y, &g_diag);
	struct px_can_sim *bus = NULL;
	struct px_can_sim_config sc;
	struct px_can_bus *peer = NULL;
	struct px_devcfg_options opt;
	struct px_devcfg *h = NULL;
	char msg[512];
	int k;
	PX_CHECK(cfg != NULL);
	if (!cfg)
		return;
	px_can_sim_config_default(&sc);
	PX_CHECK_INT_EQ(px_can_sim_create(&sc, &bus), PX_OK);
	PX_CHECK_INT_EQ(px_can_sim_endpoint(bus, &peer), PX_OK);
	memset(&opt, 0, sizeof(opt));
	opt.can_sim = bus;
	PX_CHECK_MSG(px_devcfg_open(cfg, &cfg->devices[0], &opt, &h, msg,
				    sizeof(msg)) == PX_OK,
		     "%s", msg);
	PX_CHECK(px_devcfg_can_sim(h) == bus);
	PX_CHECK(px_devcfg_canopen(h) == NULL);
	PX_CHECK_INT_EQ(px_dev_start(px_devcfg_dev(h)), PX_OK);
	for (k = 0; k < 50; k++) {
		int16_t rx = (int16_t)px_rand_int(-30000, 30000);
		int16_t rz = (int16_t)px_rand_int(-30000, 30000);
		int64_t t = (k + 1) * 1000000LL;
		struct px_can_msg m, o;
		struct px_pose_sample s;
		struct px_force_cmd fc;
		double fy = px_rand_range(-300.0, 300.0);
		double tz = px_rand_range(-30.0, 30.0);
		memset(&m, 0, sizeof(m));
		m.f.can_id = 0x101;
		m.f.len = 8;
		m.f.data[0] = (uint8_t)(rx & 0xff);
		m.f.data[1] = (uint8_t)((uint16_t)rx >> 8);
		m.f.data[2] = (uint8_t)(rz & 0xff);
		m.f.data[3] = (uint8_t)((uint16_t)rz >> 8);
		m.f.data[4] = (uint8_t)k;
		PX_CHECK_INT_EQ(px_can_bus_send(peer, &m, t), PX_OK);
		PX_CHECK_INT_EQ(px_dev_pose_read(px_devcfg_dev(h), t, &s), 1);
		PX_CHECK_CLOSE(s.pos_m.x, rx * 0.001, 1e-12, 1e-12);
		PX_CHECK_CLOSE(s.pos_m.z, rz * 0.001, 1e-12, 1e-12);
		memset(&fc, 0, sizeof(fc));
		fc.enable = 1;
		fc.force_n[1] = fy;
		fc.torque_n_m[2] = tz;
		PX_CHECK_INT_EQ(px_dev_force_write(px_devcfg_dev(h), &fc, t),
				PX_OK);
		PX_CHECK_INT_EQ(px_can_bus_recv(peer, t, &o), PX_OK);
		PX_CHECK_INT_EQ(o.f.can_id, 0x201);
		{
			/* decode independently: LE i16 at byte 0; BE i16
			 * with MSB at bit 23 = bytes 2..3 big-endian */
			int16_t rfy = (int16_t)(o.f.data[0] | o.f.data[1] << 8);
			int16_t rtz = (int16_t)(o.f.data[2] << 8 | o.f.data[3]);
			PX_CHECK_NEAR(rfy * 0.01, fy, 0.005 + 1e-9);
			PX_CHECK_NEAR(rtz * 0.001, tz, 0.0005 + 1e-9);
		}
	}
	px_devcfg_free(h);
	px_can_sim_free(bus);
	px_config_free(cfg);
}

/* Drives from the config reach the master with their counts_per_unit:
 * a simulated arm built from the same table enables and the master's
 * position feedback is counts / counts_per_unit. */
/* The safe stop's wait on a virtual clock: the arm answers each round. */
static int64_t arm_wait(void *user, int64_t now, int64_t period_ns)
{
	now += period_ns;
	px_canopen_sim_step(user, now);
	return now;
}

static void test_canopen_drives(void)
{
	static const char y[] =
		PX_TEST_YAML_HEAD PX_TEST_YAML_CAN("arm", "simbus", "sim")
		"      canopen:\n"
		"        heartbeat_period_ns: 0\n"
		"        heartbeat_timeout_ns: 0\n"
		"        rpdo: [{index: 0x6060, bits: 8}, {index: 0x6040, bits: 16}, {index: 0x607A, bits: 32}]\n"
		"        tpdo1: [{index: 0x6064, bits: 32}, {index: 0x6041, subindex: 0, bits: 16}]\n"
		"        drives:\n"
		"          - {node_id: 3, mode: csp, joint: 1, counts_per_unit: 1000}\n"
		"          - {node_id: 9, mode: csv, joint: 0, counts_per_unit: 20000, rated_torque_n_m: 4.5}\n";
	struct px_config *cfg = px_test_config_load(y, &g_diag);
	struct px_devcfg *h = NULL;
	struct px_canopen_drive_cfg dr[4];
	struct px_canopen_sim_config sc;
	struct px_canopen_sim *arm = NULL;
	struct px_can_bus *ep = NULL;
	struct px_canopen_drive_status st;
	double targets[2] = {0.0, 0.25};
	char msg[512];
	int k, n;
	double pos;
	int state;
	PX_CHECK(cfg != NULL);
	if (!cfg)
		return;
	PX_CHECK_MSG(px_devcfg_open(cfg, &cfg->devices[0], NULL, &h, msg,
				    sizeof(msg)) == PX_OK,
		     "%s", msg);
	PX_CHECK(px_devcfg_dev(h) == NULL);
	PX_CHECK(px_devcfg_canopen(h) != NULL);
	n = px_devcfg_drives(h, dr, 4);
	PX_CHECK_INT_EQ(n, 2);
	PX_CHECK_INT_EQ(px_devcfg_drives(h, dr, 1), PX_E_NOSPC);
	PX_CHECK_INT_EQ(dr[0].node_id, 3);
	PX_CHECK_INT_EQ(dr[0].mode, PX_CIA402_CSP);
	PX_CHECK_INT_EQ(dr[0].joint, 1);
	PX_CHECK_CLOSE(dr[0].counts_per_unit, 1000.0, 0, 0);
	PX_CHECK_CLOSE(dr[0].rated_torque_n_m, 1.0, 0, 0);
	PX_CHECK_INT_EQ(dr[1].mode, PX_CIA402_CSV);
	PX_CHECK_CLOSE(dr[1].counts_per_unit, 20000.0, 0, 0);
	PX_CHECK_CLOSE(dr[1].rated_torque_n_m, 4.5, 0, 0);
	PX_CHECK(px_devcfg_pdo(h) != NULL);
	PX_CHECK_INT_EQ(px_devcfg_pdo(h)->rpdo.e[0].index, 0x6060);
	PX_CHECK_INT_EQ(px_devcfg_pdo(h)->tpdo1.e[1].index, 0x6041);
	PX_CHECK_INT_EQ(px_devcfg_pdo(h)->tpdo2.e[0].index, 0x606C);
	memset(&sc, 0, sizeof(sc));
	sc.pdo = px_devcfg_pdo(h); /* the arm speaks the config's layout */
	sc.drives = dr;
	sc.n_drives = (size_t)n;
	sc.heartbeat_period_ns = 100000000;
	sc.inertia_kg_m2 = 0.01;
	PX_CHECK_INT_EQ(px_can_sim_endpoint(px_devcfg_can_sim(h), &ep), PX_OK);
	PX_CHECK_INT_EQ(px_canopen_sim_create(&sc, ep, &arm), PX_OK);
	for (k = 1; k <= 60; k++) {
		int64_t t = k * 1000000LL;
		px_canopen_sim_step(arm, t);
		px_canopen_rx(px_devcfg_canopen(h), t);
		px_canopen_tx(px_devcfg_canopen(h), t, targets, 2, 1);
	}
	PX_CHECK(px_canopen_all_enabled(px_devcfg_canopen(h)));
	PX_CHECK_INT_EQ(px_canopen_sim_joint(arm, 0, &pos, &state), PX_OK);
	PX_CHECK_INT_EQ(px_canopen_drive_status(px_devcfg_canopen(h), 0, &st),
			PX_OK);
	/* the CSP drive reached its target through the count scaling */
	PX_CHECK_NEAR(st.position, 0.25, 2e-3);
	PX_CHECK_NEAR(pos, 0.25, 2e-3);
	/* one call stops everything the handle opened: both drives
	 * confirmed disabled, the arm standing where it was */
	{
		struct px_devcfg_safe_config sfc;
		struct px_devcfg_safe_result r;
		px_devcfg_safe_config_default(&sfc);
		sfc.canopen.wait = arm_wait;
		sfc.canopen.user = arm;
		PX_CHECK_INT_EQ(px_devcfg_safe_stop(h, 61000000, &sfc, &r),
				PX_OK);
		PX_CHECK_INT_EQ(r.canopen_rc, PX_OK);
		PX_CHECK_INT_EQ(r.canopen.disabled, 2);
		PX_CHECK_INT_EQ(r.caps, 0); /* no px_dev on a canopen device */
		for (k = 0; k < 2; k++) {
			double p2;
			PX_CHECK_INT_EQ(px_canopen_sim_joint(arm, (size_t)k, &p2,
							     &state),
					PX_OK);
			PX_CHECK_INT_EQ(state, PX_CIA402_SWITCH_ON_DISABLED);
			if (k == 0)
				PX_CHECK_NEAR(p2, pos, 1e-3);
		}
		PX_CHECK(!px_canopen_all_enabled(px_devcfg_canopen(h)));
	}
	px_canopen_sim_free(arm);
	px_can_bus_close(ep);
	px_devcfg_free(h);
	px_config_free(cfg);
}

/* Freed without px_devcfg_safe_stop(): one round of quick stop goes out
 * before the bus closes, so the drives end disabled anyway. */
static void test_canopen_free_stops_drives(void)
{
	static const char y[] =
		PX_TEST_YAML_HEAD PX_TEST_YAML_CAN("arm", "simbus", "sim")
		"      canopen:\n"
		"        heartbeat_period_ns: 0\n"
		"        heartbeat_timeout_ns: 0\n"
		"        drives:\n"
		"          - {node_id: 3, mode: csv, joint: 0, counts_per_unit: 1000}\n";
	struct px_config *cfg = px_test_config_load(y, &g_diag);
	struct px_devcfg_options opt;
	struct px_can_sim_config bc;
	struct px_can_sim *bus = NULL;
	struct px_devcfg *h = NULL;
	struct px_canopen_drive_cfg dr[1];
	struct px_canopen_sim_config sc;
	struct px_canopen_sim *arm = NULL;
	struct px_can_bus *ep = NULL;
	double targets[1] = {0.5};
	char msg[512];
	int k, state;
	PX_CHECK(cfg != NULL);
	if (!cfg)
		return;
	px_can_sim_config_default(&bc);
	PX_CHECK_INT_EQ(px_can_sim_create(&bc, &bus), PX_OK);
	memset(&opt, 0, sizeof(opt));
	opt.can_sim = bus; /* the bus outlives the handle */
	PX_CHECK_MSG(px_devcfg_open(cfg, &cfg->devices[0], &opt, &h, msg,
				    sizeof(msg)) == PX_OK,
		     "%s", msg);
	PX_CHECK_INT_EQ(px_devcfg_drives(h, dr, 1), 1);
	memset(&sc, 0, sizeof(sc));
	sc.drives = dr;
	sc.n_drives = 1;
	PX_CHECK_INT_EQ(px_can_sim_endpoint(bus, &ep), PX_OK);
	PX_CHECK_INT_EQ(px_canopen_sim_create(&sc, ep, &arm), PX_OK);
	for (k = 1; k <= 30; k++) {
		int64_t t = k * 1000000LL;
		px_canopen_sim_step(arm, t);
		px_canopen_rx(px_devcfg_canopen(h), t);
		px_canopen_tx(px_devcfg_canopen(h), t, targets, 1, 1);
	}
	PX_CHECK(px_canopen_all_enabled(px_devcfg_canopen(h)));
	px_devcfg_free(h);
	px_canopen_sim_step(arm, 31000000);
	PX_CHECK_INT_EQ(px_canopen_sim_joint(arm, 0, NULL, &state), PX_OK);
	PX_CHECK_MSG(state == PX_CIA402_SWITCH_ON_DISABLED, "drive left %s",
		     px_cia402_state_name(state));
	px_canopen_sim_free(arm);
	px_can_bus_close(ep);
	px_can_sim_free(bus);
	px_config_free(cfg);
}

/* GPIO roles from safety references and names; e-stop and enable work
 * through the opened device. */
static void test_gpio_roles(void)
{
	static const char y[] =
		"version: 1\n"
		"safety:\n"
		"  estop: {device: io, line: stop_button}\n"
		"  enable: {device: io, line: relay}\n"
		"devices:\n"
		PX_TEST_YAML_SIM_GPIO("io")
		"      lines:\n"
		"        - {name: stop_button, direction: input, active_low: true}\n"
		"        - {name: relay, direction: output}\n"
		"        - {name: timing, direction: output}\n";
	struct px_config *cfg = px_test_config_load(y, &g_diag);
	struct px_devcfg *h = NULL;
	struct px_dev *d;
	char msg[512];
	int pressed = -1;
	PX_CHECK(cfg != NULL);
	if (!cfg)
		return;
	PX_CHECK_MSG(px_devcfg_open(cfg, &cfg->devices[0], NULL, &h, msg,
				    sizeof(msg)) == PX_OK,
		     "%s", msg);
	d = px_devcfg_dev(h);
	PX_CHECK_INT_EQ(px_dev_start(d), PX_OK);
	px_gpio_sim_drive(d, PX_GPIO_ESTOP, 1, 1000);
	PX_CHECK(px_dev_estop_read(d, 2000000, &pressed) >= 0);
	PX_CHECK_INT_EQ(pressed, 0);
	px_gpio_sim_drive(d, PX_GPIO_ESTOP, 0, 3000000); /* active low */
	PX_CHECK(px_dev_estop_read(d, 10000000, &pressed) >= 0);
	PX_CHECK_INT_EQ(pressed, 1);
	PX_CHECK_INT_EQ(px_dev_dio_write(d, PX_DIO_ENABLE, 1, 11000000), PX_OK);
	PX_CHECK_INT_EQ(px_gpio_sim_output(d, PX_GPIO_ENABLE), 1);
	PX_CHECK_INT_EQ(px_dev_dio_write(d, PX_DIO_TIMING, 1, 11000000), PX_OK);
	PX_CHECK_INT_EQ(px_gpio_sim_output(d, PX_GPIO_TIMING), 1);
	px_devcfg_free(h);
	px_config_free(cfg);
}

/* check_only: px_devcfg_open()'s tests of a config without opening
 * anything outside the process. Every shipped example's devices pass
 * (the real ones too, absent here), nothing comes back, a UNIX-socket
 * bus binds no file, and a refusal reads as the open's would. */
static void test_check_only(void)
{
	static const char *const files[] = {
		"config/examples/haptic_sim.yaml",
		"config/examples/haptic_hid.yaml",
		"config/examples/spacemouse_hid.yaml",
		"config/examples/can_sim.yaml",
		"config/examples/can_arm.yaml",
	};
	struct px_devcfg_options opt;
	char y[1024], sock[64], msg[512], msg2[512];
	struct px_config *cfg;
	struct px_devcfg *h;
	size_t f, i;
	memset(&opt, 0, sizeof(opt));
	opt.check_only = 1;
	if (access(files[0], R_OK) != 0)
		PX_SKIP("config/examples not found (run from the source tree)");
	for (f = 0; f < sizeof(files) / sizeof(files[0]); f++) {
		int rc = px_config_load_file(files[f], &cfg, &g_diag);
		PX_CHECK_MSG(rc == PX_OK, "%s: %s", files[f], px_strerror(rc));
		if (rc != PX_OK)
			continue;
		for (i = 0; i < cfg->n_devices; i++) {
			h = (struct px_devcfg *)&opt; /* must come back NULL */
			rc = px_devcfg_open(cfg, &cfg->devices[i], &opt, &h, msg,
					    sizeof(msg));
			PX_CHECK_MSG(rc == PX_OK, "%s: %s", files[f], msg);
			PX_CHECK(h == NULL);
		}
		px_config_free(cfg);
	}
	snprintf(sock, sizeof(sock), "/tmp/px-devcfg-check-%d.sock",
		 (int)getpid());
	snprintf(y, sizeof(y),
		 PX_TEST_YAML_HEAD PX_TEST_YAML_CAN("arm", "simcan0", "unix")
		 "      socket_path: %s\n"
		 "      canopen:\n"
		 "        drives:\n"
		 "          - {node_id: 1, mode: csv, joint: 0}\n"
		 "  - name: io\n"
		 "    backend: gpiod\n"
		 "    gpiod:\n"
		 "      chip: gpiochip0\n"
		 "      lines:\n"
		 "        - {name: estop, offset: 1, direction: input}\n"
		 "        - {name: spare, offset: 2, direction: output}\n",
		 sock);
	cfg = px_test_config_load(y, &g_diag);
	PX_CHECK(cfg != NULL);
	if (!cfg)
		return;
	PX_CHECK_INT_EQ(px_devcfg_open(cfg, &cfg->devices[0], &opt, &h, msg,
				       sizeof(msg)),
			PX_OK);
	PX_CHECK(access(sock, F_OK) != 0); /* nothing bound */
	PX_CHECK_INT_EQ(px_devcfg_open(cfg, &cfg->devices[1], &opt, &h, msg,
				       sizeof(msg)),
			PX_E_INVAL);
	PX_CHECK(h == NULL);
	PX_CHECK_INT_EQ(px_devcfg_open(cfg, &cfg->devices[1], NULL, &h, msg2,
				       sizeof(msg2)),
			PX_E_INVAL);
	PX_CHECK_MSG(strcmp(msg, msg2) == 0 && strstr(msg, "line 'spare' has "
							   "no role"),
		     "check: '%s', open: '%s'", msg, msg2);
	px_config_free(cfg);
}

/* What cannot be mapped is refused with the device, the key and why. */
static void test_errors(void)
{
	static const struct {
		const char *yaml;
		const char *key;  /* expected in the message */
		const char *what; /* expected in the message */
	} cases[] = {
		{PX_TEST_YAML_HEAD PX_TEST_YAML_SIM_GPIO("io")
		 "      lines:\n"
		 "        - {name: estop, direction: input}\n"
		 "        - {name: lamp, direction: output}\n",
		 "devices[0].sim.lines[1]", "'lamp' has no role"},
		{PX_TEST_YAML_HEAD PX_TEST_YAML_SIM_GPIO("io")
		 "      lines:\n"
		 "        - {name: enable, direction: input}\n",
		 "devices[0].sim.lines[0]", "must be an output"},
		{PX_TEST_YAML_HEAD PX_TEST_YAML_CAN("arm", "x", "unix")
		 "      socket_path: /tmp/px-devcfg-test.sock\n"
		 "      signals:\n"
		 "        - {name: a, id: 1, direction: input, start_bit: 0, length: 8}\n"
		 "      canopen:\n"
		 "        drives: [{node_id: 1, joint: 0}]\n",
		 "devices[0].socketcan.signals", "not both"},
		{"version: 1\n"
		 "devices:\n"
		 "  - name: bus\n"
		 "    backend: socketcan\n"
		 "    socketcan: {interface: x, transport: sim}\n",
		 "devices[0].socketcan", "nothing"},
		{"version: 1\n"
		 "devices:\n"
		 "  - name: bad_csv\n"
		 "    backend: sim\n"
		 "    sim:\n"
		 "      trajectory: {kind: csv, file: /nonexistent/hand.csv}\n",
		 "devices[0].sim.trajectory.file", "/nonexistent/hand.csv"},
		{PX_TEST_YAML_HEAD PX_TEST_YAML_CAN("arm", "x", "sim")
		 "      canopen:\n"
		 "        drives: [{node_id: 1, joint: 0}]\n"
		 "        tpdo1: [{index: 0x6041, bits: 16}, {index: 0x6064, bits: 16}]\n",
		 "devices[0].socketcan.canopen.tpdo1[1]", "is 32 bits, not 16"},
	};
	size_t i;
	for (i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
		struct px_config *cfg =
			px_test_config_load(cases[i].yaml, &g_diag);
		struct px_devcfg *h = NULL;
		char msg[512];
		int rc;
		PX_CHECK_MSG(cfg != NULL, "case %zu", i);
		if (!cfg)
			continue;
		rc = px_devcfg_open(cfg, &cfg->devices[0], NULL, &h, msg,
				    sizeof(msg));
		PX_CHECK_MSG(rc < 0, "case %zu opened", i);
		PX_CHECK(h == NULL);
		PX_CHECK_MSG(strstr(msg, cfg->devices[0].name) &&
				     strstr(msg, cases[i].key) &&
				     strstr(msg, cases[i].what),
			     "case %zu: '%s'", i, msg);
		px_config_free(cfg);
	}
	/* a device of another config, NULLs */
	{
		struct px_config *a =
			px_test_config_load(cases[0].yaml, &g_diag);
		struct px_devcfg *h = NULL;
		char msg[128];
		struct px_config_device other;
		PX_CHECK(a != NULL);
		if (!a)
			return;
		other = a->devices[0];
		PX_CHECK_INT_EQ(px_devcfg_open(a, &other, NULL, &h, msg,
					       sizeof(msg)),
				PX_E_INVAL);
		PX_CHECK_INT_EQ(px_devcfg_open(NULL, NULL, NULL, &h, NULL, 0),
				PX_E_INVAL);
		px_devcfg_free(NULL);
		px_config_free(a);
	}
}

/* The config refuses an axis that does not fit the direction. */
static void test_signal_axis_config(void)
{
	static const char y[] =
		PX_TEST_YAML_HEAD PX_TEST_YAML_CAN("c", "x", "sim")
		"      signals:\n"
		"        - {name: a, id: 1, direction: input, start_bit: 0, length: 8, axis: fx}\n"
		"        - {name: b, id: 2, direction: output, start_bit: 0, length: 8, axis: rz}\n";
	struct px_config *c = NULL;
	int rc = px_config_load_mem("t.yaml", y, strlen(y), &c, &g_diag);
	PX_CHECK_INT_EQ(rc, PX_E_PARSE);
	PX_CHECK(px_config_diag_find(&g_diag,
				     "devices[0].socketcan.signals[0].axis"));
	PX_CHECK(px_config_diag_find(&g_diag,
				     "devices[0].socketcan.signals[1].axis"));
	px_config_free(c);
}

static const struct px_test tests[] = {
	PX_T(test_examples_open),   PX_T(test_sim_haptic_runs),
	PX_T(test_can_signal_axes), PX_T(test_canopen_drives),
	PX_T(test_gpio_roles),      PX_T(test_errors),
	PX_T(test_signal_axis_config), PX_T(test_canopen_free_stops_drives),
	PX_T(test_check_only),
};
PX_TEST_MAIN(tests)
