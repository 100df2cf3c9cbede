/* PX_TEST_NEEDS: libyaml (the shipped configs are YAML; tests/run.sh skips it in builds without) */
/*
 * app/: the runner as a module - create/free on every shipped simulated
 * config, the cycle stepped, or driven phase by phase, from the test's
 * own loop against the app's own run, the safe state at shutdown, no heap calls in the cycles, the
 * summary against the figures proxima-run prints, bad options refused.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "px_alloc_count.h"
#include "px_app.h"
#include "px_config.h"
#include "px_sim.h"
#include "px_test.h"
#include "px_test_app.h"

#define HAPTIC_SIM "config/examples/haptic_sim.yaml"

/* The shipped configs that run without hardware, in this process
 * (can_sim's arm is another program, proxima-simarm: test_proxima_run). */
static const char *const sim_configs[] = {
	"config/examples/haptic_sim.yaml",
	"config/examples/haptic_faults.yaml",
	"config/examples/can_avoid_sim.yaml",
};

static struct px_config *load(const char *path)
{
	static struct px_config_diag diag;
	struct px_config *cfg = NULL;
	int rc = px_config_load_file(path, &cfg, &diag);
	PX_CHECK_MSG(rc == PX_OK, "%s: %s", path, px_strerror(rc));
	return cfg;
}

static void options(struct px_app_options *o, const char *path, double dur_s)
{
	px_app_options_default(o);
	o->config = path;
	o->virtual_time = 1;
	o->duration_s = dur_s;
	o->note = px_test_app_note;
}

static struct px_app *create(const struct px_config *cfg,
			     const struct px_app_options *o)
{
	struct px_app *app = NULL;
	char msg[256];
	int rc;
	px_test_app_notes[0] = '\0';
	rc = px_app_create(cfg, o, &app, msg, sizeof(msg));
	PX_CHECK_MSG(rc == PX_OK, "%s: %s: %s (%s)", o->config, px_strerror(rc),
		     msg, px_test_app_notes);
	return app;
}

static void test_create_free_every_sim_config(void)
{
	size_t i;
	for (i = 0; i < sizeof(sim_configs) / sizeof(sim_configs[0]); i++) {
		struct px_config *cfg = load(sim_configs[i]);
		struct px_app_options o;
		struct px_app *app;
		options(&o, sim_configs[i], 0.1);
		app = create(cfg, &o);
		PX_CHECK(px_app_loop(app) != NULL);
		PX_CHECK_INT_EQ(px_app_run(app), PX_OK);
		px_app_free(app); /* the shutdown runs here */
		/* and the checks alone, as --check makes them */
		o.check = 1;
		app = create(cfg, &o);
		px_app_free(app);
		px_config_free(cfg);
	}
	px_app_free(NULL);
}

/* The same cycles, stepped here (draining every 100) or by px_app_run,
 * give the same telemetry. */
static void test_own_loop_matches_the_apps_run(void)
{
	static struct px_test_recs a, b;
	struct px_config *cfg = load(HAPTIC_SIM);
	struct px_app_options o;
	struct px_app *app;
	int k;
	options(&o, HAPTIC_SIM, 0.5);
	o.record = px_test_app_record;
	o.user = &a;
	a.n = b.n = 0;
	app = create(cfg, &o);
	PX_CHECK_INT_EQ(px_app_run(app), PX_OK);
	px_app_drain(app, px_test_app_record, &a);
	px_app_free(app);

	o.record = NULL;
	o.user = NULL;
	app = create(cfg, &o);
	for (k = 0; k < 500; k++) {
		PX_CHECK_INT_EQ(px_app_step(app), PX_OK);
		if (k % 100 == 99)
			px_app_drain(app, px_test_app_record, &b);
	}
	px_app_drain(app, px_test_app_record, &b);
	px_app_free(app);
	px_config_free(cfg);
	PX_CHECK_INT_EQ((long long)a.n, 500);
	PX_CHECK_INT_EQ((long long)b.n, (long long)a.n);
	PX_CHECK(memcmp(a.r, b.r, a.n * sizeof(a.r[0])) == 0);
}

/* The phases driven from the test's own loop with its own (simulated)
 * clock, at the loop's deadlines: the same telemetry and figures as
 * px_app_run, no heap call in any phase, the safe state at shutdown and
 * no phase after it. */
static void test_own_phases_match_the_apps_run(void)
{
	static struct px_test_recs a, b;
	struct px_config *cfg = load(HAPTIC_SIM);
	struct px_app_options o;
	struct px_app_summary sa, sb;
	struct px_loop_status ls;
	struct px_sim_haptic_state hs;
	struct px_app *app;
	struct px_dev *dev;
	uint64_t heap = 0, h0;
	int64_t t0, now;
	int k, pushed = 0;
	options(&o, HAPTIC_SIM, 3.0);
	o.record = px_test_app_record;
	o.user = &a;
	a.n = b.n = 0;
	app = create(cfg, &o);
	PX_CHECK_INT_EQ(px_app_run(app), PX_OK);
	px_app_drain(app, px_test_app_record, &a);
	PX_CHECK_INT_EQ(px_app_shutdown(app, "end of run"), PX_OK);
	px_app_drain(app, px_test_app_record, &a);
	PX_CHECK_INT_EQ(px_app_summary(app, &sa), PX_OK);
	px_app_free(app);

	o.record = NULL;
	o.user = NULL;
	app = create(cfg, &o);
	dev = px_app_device(app, "haptic");
	PX_CHECK(dev != NULL);
	PX_CHECK_INT_EQ(px_loop_status(px_app_loop(app), &ls), PX_OK);
	t0 = px_loop_now_ns(px_app_loop(app));
	PX_CHECK_INT_EQ(px_app_write(app, t0), PX_E_STATE);
	PX_CHECK_INT_EQ(px_app_compute(app, t0), PX_E_STATE);
	for (k = 0; k < 3000; k++) {
		now = t0 + (int64_t)(k + 1) * ls.period_ns;
		h0 = px_alloc_region_begin();
		PX_CHECK_INT_EQ(px_app_read(app, now), PX_OK);
		PX_CHECK_INT_EQ(px_app_compute(app, now), PX_OK);
		PX_CHECK_INT_EQ(px_app_write(app, now), PX_OK);
		heap += px_alloc_region_end(h0);
		PX_CHECK_INT_EQ(px_sim_haptic_state(dev, &hs), PX_OK);
		pushed |= hs.enable && (hs.force_n[0] != 0 ||
					hs.force_n[1] != 0 || hs.force_n[2] != 0);
		if (k % 100 == 99)
			px_app_drain(app, px_test_app_record, &b);
	}
	PX_CHECK_MSG(heap == 0, "%llu heap calls in 3000 phase-driven cycles",
		     (unsigned long long)heap);
	PX_CHECK_MSG(pushed, "no force in 3000 cycles");
	px_app_drain(app, px_test_app_record, &b);
	/* shut down in the middle of a cycle: safe, and the rest refused */
	PX_CHECK_INT_EQ(px_app_read(app, now + ls.period_ns), PX_OK);
	PX_CHECK_INT_EQ(px_app_shutdown(app, "end of run"), PX_OK);
	PX_CHECK_INT_EQ(px_sim_haptic_state(dev, &hs), PX_OK);
	PX_CHECK(hs.force_n[0] == 0 && hs.force_n[1] == 0 && hs.force_n[2] == 0);
	PX_CHECK_INT_EQ(hs.enable, 0);
	PX_CHECK_INT_EQ(px_app_compute(app, now + ls.period_ns), PX_E_STATE);
	PX_CHECK_INT_EQ(px_app_write(app, now + ls.period_ns), PX_E_STATE);
	PX_CHECK_INT_EQ(px_app_read(app, now + 2 * ls.period_ns), PX_E_STATE);
	PX_CHECK_INT_EQ(px_sim_haptic_state(dev, &hs), PX_OK);
	PX_CHECK_INT_EQ(hs.enable, 0);
	px_app_drain(app, px_test_app_record, &b);
	PX_CHECK_INT_EQ(px_app_summary(app, &sb), PX_OK);
	PX_CHECK(sb.shutdown_done && sb.shutdown_safe);
	PX_CHECK_INT_EQ(sb.force_zeroed, 1);
	PX_CHECK_INT_EQ(sb.relays_off, 1);
	px_app_free(app);
	px_config_free(cfg);
	PX_CHECK_INT_EQ((long long)a.n, 3000);
	PX_CHECK_INT_EQ((long long)b.n, (long long)a.n);
	PX_CHECK(memcmp(a.r, b.r, a.n * sizeof(a.r[0])) == 0);
	/* the cycle left open by the shutdown is not counted */
	PX_CHECK_INT_EQ(sb.cycles, sa.cycles);
	PX_CHECK(sb.max_force_n == sa.max_force_n);
	PX_CHECK_INT_EQ(sb.contact_cycles, sa.contact_cycles);
	PX_CHECK(sb.min_distance_m == sa.min_distance_m);
	PX_CHECK(sb.max_penetration_m == sa.max_penetration_m);
	PX_CHECK_INT_EQ(sb.safe_state_trips, sa.safe_state_trips);
	PX_CHECK_INT_EQ(sb.telemetry_records, sa.telemetry_records);
	PX_CHECK_INT_EQ(sb.faults_popped, sa.faults_popped);
	PX_CHECK_INT_EQ(px_app_read(NULL, 0), PX_E_INVAL);
}

/* In contact the device receives force; after px_app_shutdown it last
 * received zero force and torque with enable off. */
static void test_shutdown_leaves_zero_force(void)
{
	struct px_config *cfg = load(HAPTIC_SIM);
	struct px_app_options o;
	struct px_app *app;
	struct px_sim_haptic_state hs;
	struct px_app_summary s;
	struct px_dev *dev;
	int k, pushed = 0;
	options(&o, HAPTIC_SIM, 0);
	app = create(cfg, &o);
	dev = px_app_device(app, "haptic");
	PX_CHECK(dev != NULL);
	PX_CHECK(px_app_device(app, "no such device") == NULL);
	for (k = 0; k < 3000 && !pushed; k++) {
		PX_CHECK_INT_EQ(px_app_step(app), PX_OK);
		PX_CHECK_INT_EQ(px_sim_haptic_state(dev, &hs), PX_OK);
		pushed = hs.enable && (hs.force_n[0] != 0 || hs.force_n[1] != 0 ||
				       hs.force_n[2] != 0);
		if (k % 100 == 99)
			px_app_drain(app, NULL, NULL);
	}
	PX_CHECK_MSG(pushed, "no force within %d cycles", k);
	PX_CHECK_INT_EQ(px_app_shutdown(app, "test"), PX_OK);
	PX_CHECK_INT_EQ(px_sim_haptic_state(dev, &hs), PX_OK);
	PX_CHECK(hs.force_n[0] == 0 && hs.force_n[1] == 0 && hs.force_n[2] == 0);
	PX_CHECK(hs.torque_n_m[0] == 0 && hs.torque_n_m[1] == 0 &&
		 hs.torque_n_m[2] == 0);
	PX_CHECK_INT_EQ(hs.enable, 0);
	PX_CHECK_INT_EQ(px_app_summary(app, &s), PX_OK);
	PX_CHECK(s.shutdown_done && s.shutdown_safe);
	PX_CHECK(strcmp(s.shutdown_reason, "test") == 0);
	/* haptic_sim: the haptic device's force and the io relay */
	PX_CHECK_INT_EQ(px_app_device_count(app), 2);
	PX_CHECK(px_app_device_at(app, 0) == dev && px_app_device_at(app, 2) == NULL);
	PX_CHECK_INT_EQ(s.force_devices, 1);
	PX_CHECK_INT_EQ(s.force_zeroed, 1);
	PX_CHECK_INT_EQ(s.relay_devices, 1);
	PX_CHECK_INT_EQ(s.relays_off, 1);
	PX_CHECK_INT_EQ(s.shutdown_drives, 0);
	PX_CHECK(s.shutdown_error[0] == '\0');
	/* once: a second call reports the first */
	PX_CHECK_INT_EQ(px_app_shutdown(app, "again"), PX_OK);
	PX_CHECK_INT_EQ(px_app_summary(app, &s), PX_OK);
	PX_CHECK(strcmp(s.shutdown_reason, "test") == 0);
	px_app_free(app);
	px_config_free(cfg);
}

static void test_cycles_allocate_nothing(void)
{
	size_t i;
	for (i = 0; i < sizeof(sim_configs) / sizeof(sim_configs[0]); i++) {
		struct px_config *cfg = load(sim_configs[i]);
		struct px_app_options o;
		struct px_app *app;
		uint64_t heap = 0, h0;
		int k;
		options(&o, sim_configs[i], 0);
		app = create(cfg, &o);
		for (k = 0; k < 2000; k++) {
			h0 = px_alloc_region_begin();
			PX_CHECK_INT_EQ(px_app_step(app), PX_OK);
			heap += px_alloc_region_end(h0);
			if (k % 100 == 99)
				px_app_drain(app, NULL, NULL);
		}
		PX_CHECK_MSG(heap == 0, "%s: %llu heap calls in 2000 cycles",
			     sim_configs[i], (unsigned long long)heap);
		px_app_free(app);
		px_config_free(cfg);
	}
}

/* haptic_sim for 2 s on the virtual clock: the figures proxima-run
 * prints and writes for it (test_proxima_run checks those outputs). */
static void test_summary_is_proxima_runs(void)
{
	struct px_config *cfg = load(HAPTIC_SIM);
	struct px_app_options o;
	struct px_app *app;
	struct px_app_summary s;
	options(&o, HAPTIC_SIM, 2.0);
	o.heap_count = px_alloc_count_thread;
	app = create(cfg, &o);
	PX_CHECK_INT_EQ(px_app_run(app), PX_OK);
	PX_CHECK_INT_EQ(px_app_shutdown(app, "end of run"), PX_OK);
	px_app_drain(app, NULL, NULL);
	PX_CHECK_INT_EQ(px_app_summary(app, &s), PX_OK);
	PX_CHECK_INT_EQ((long long)s.cycles, 2000);
	PX_CHECK_NEAR(s.loop_time_s, 2.0, 1e-12);
	PX_CHECK_INT_EQ((long long)s.telemetry_records, 2000);
	PX_CHECK_INT_EQ((long long)s.telemetry_dropped, 0);
	PX_CHECK_INT_EQ((long long)s.safe_state_trips, 0);
	PX_CHECK_INT_EQ((long long)s.allocations_after_setup, 0);
	PX_CHECK_NEAR(s.max_force_n, 8.0, 1e-12);
	PX_CHECK(s.min_distance_m < 0 && s.max_penetration_m > 0);
	PX_CHECK_NEAR(s.min_distance_m, -s.max_penetration_m, 1e-15);
	PX_CHECK(s.min_proxy_distance_m > 0);
	PX_CHECK(s.contact_cycles > 0 && s.contact_cycles < s.cycles);
	/* the banner's and the JSON's description of the app */
	PX_CHECK_INT_EQ((long long)s.scene_models, 3);
	PX_CHECK(s.rendering && s.proxy_renderer && !s.avoiding);
	PX_CHECK(s.distance_reported);
	PX_CHECK_INT_EQ((long long)s.max_cycles, 2000);
	PX_CHECK_INT_EQ((long long)s.decimation, 1);
	PX_CHECK_NEAR(s.force_clamp_n, 8.0, 0);
	PX_CHECK(strcmp(s.csv_path, "build/telemetry.csv") == 0);
	PX_CHECK(strcmp(s.time_svg, "build/telemetry_time.svg") == 0);
	PX_CHECK(s.tracking_enabled && s.tracking_streams == 1);
	PX_CHECK(s.tracking.queries > 0);
	PX_CHECK_INT_EQ(s.estop_lines, 1);
	PX_CHECK_INT_EQ((long long)s.estop_to_safe_ns, -1);
	PX_CHECK_INT_EQ((long long)s.phase_error_ns, 0);
	PX_CHECK_INT_EQ((long long)s.faults_injected, 0);
	PX_CHECK_INT_EQ((long long)s.nonfinite_outputs, 0);
	PX_CHECK(px_app_compute_stats(app) != NULL);
	PX_CHECK(px_app_canopen(app) == NULL);
	{
		struct px_app_record last;
		PX_CHECK_INT_EQ(px_app_last_record(app, &last), 1);
		PX_CHECK_INT_EQ((long long)last.cycle, 1999);
	}
	px_app_free(app);
	px_config_free(cfg);
}

/* haptic_faults for 2 s: the campaign's reactions proxima-run reports
 * (its fault campaign lines and JSON array), here from the summary. */
static void test_campaign_reactions_in_the_summary(void)
{
	static const char path[] = "config/examples/haptic_faults.yaml";
	struct px_config *cfg = load(path);
	struct px_app_options o;
	struct px_app *app;
	static struct px_app_summary s;
	options(&o, path, 2.0);
	app = create(cfg, &o);
	PX_CHECK_INT_EQ(px_app_run(app), PX_OK);
	PX_CHECK_INT_EQ(px_app_shutdown(app, "end of run"), PX_OK);
	px_app_drain(app, NULL, NULL);
	PX_CHECK_INT_EQ(px_app_summary(app, &s), PX_OK);
	PX_CHECK_INT_EQ((long long)s.n_reactions, 9);
	PX_CHECK(strcmp(s.reactions[0].kind, "drop") == 0);
	PX_CHECK_INT_EQ((long long)s.reactions[0].safe_after_ns, -1);
	PX_CHECK(strcmp(s.reactions[1].kind, "delay") == 0);
	PX_CHECK(strcmp(s.reactions[1].device, "haptic") == 0);
	PX_CHECK_INT_EQ((long long)s.reactions[1].start_ns, 500000000);
	PX_CHECK_INT_EQ((long long)s.reactions[1].loop_faults, 3);
	PX_CHECK_INT_EQ((long long)s.reactions[1].safe_after_ns, 20000000);
	PX_CHECK(strcmp(s.reactions[8].kind, "overrun") == 0);
	PX_CHECK(s.watchdog_trips_checked > 0);
	PX_CHECK_INT_EQ((long long)s.max_trip_to_safe_cycles, 0);
	px_app_free(app);
	px_config_free(cfg);
}

static void test_bad_options_refused(void)
{
	struct px_config *cfg = load(HAPTIC_SIM);
	struct px_config *hid = load("config/examples/haptic_hid.yaml");
	struct px_app_options o;
	struct px_app *app = (struct px_app *)&app;
	char msg[256];
	options(&o, NULL, 1);
	PX_CHECK_INT_EQ(px_app_create(cfg, &o, &app, msg, sizeof(msg)), PX_E_INVAL);
	PX_CHECK(app == NULL && msg[0]);
	options(&o, HAPTIC_SIM, -1);
	PX_CHECK_INT_EQ(px_app_create(cfg, &o, &app, msg, sizeof(msg)), PX_E_INVAL);
	PX_CHECK(msg[0]);
	PX_CHECK_INT_EQ(px_app_create(NULL, &o, &app, msg, sizeof(msg)), PX_E_INVAL);
	options(&o, HAPTIC_SIM, 1);
	o.faults[0] = "melt,haptic,0,1";
	o.n_faults = 1;
	px_test_app_notes[0] = '\0';
	PX_CHECK_INT_EQ(px_app_create(cfg, &o, &app, msg, sizeof(msg)), PX_E_INVAL);
	PX_CHECK_MSG(strstr(msg, "unknown kind 'melt'") != NULL, "%s", msg);
	/* messages start with opt.name (default px_app) */
	PX_CHECK_MSG(strncmp(msg, "px_app: --fault melt", 20) == 0, "%s", msg);
	o.name = "mytool";
	PX_CHECK_INT_EQ(px_app_create(cfg, &o, &app, msg, sizeof(msg)), PX_E_INVAL);
	PX_CHECK_MSG(strncmp(msg, "mytool: --fault melt", 20) == 0, "%s", msg);
	PX_CHECK(strstr(px_test_app_notes, "unknown kind 'melt'") != NULL);
	o.faults[0] = "drop,nosuchdevice,0,1";
	PX_CHECK_INT_EQ(px_app_create(cfg, &o, &app, msg, sizeof(msg)), PX_E_INVAL);
	PX_CHECK(msg[0]);
	/* the virtual clock drives simulated devices only */
	options(&o, "config/examples/haptic_hid.yaml", 1);
	PX_CHECK_INT_EQ(px_app_create(hid, &o, &app, msg, sizeof(msg)), PX_E_INVAL);
	PX_CHECK_MSG(strstr(msg, "--virtual-time drives simulated devices only"),
		     "%s", msg);
	PX_CHECK(app == NULL);
	px_config_free(hid);
	px_config_free(cfg);
}

static const struct px_test tests[] = {
	PX_T(test_create_free_every_sim_config),
	PX_T(test_own_loop_matches_the_apps_run),
	PX_T(test_own_phases_match_the_apps_run),
	PX_T(test_shutdown_leaves_zero_force),
	PX_T(test_cycles_allocate_nothing),
	PX_T(test_summary_is_proxima_runs),
	PX_T(test_campaign_reactions_in_the_summary),
	PX_T(test_bad_options_refused),
};

PX_TEST_MAIN(tests)
