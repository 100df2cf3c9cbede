/* px_devcfg_options fault windows (a runner's campaign): added after the
 * config's own to simulated haptic/pose and GPIO devices, on the loop
 * clock as given (clock0_ns moves only the config's), too many refused
 * naming sim.faults, and refused for back ends that are not simulated. */
/* PX_TEST_NEEDS: libyaml (tests/run.sh skips it in builds without) */
#include <stdio.h>
#include <string.h>

#include "px_config.h"
#include "px_devcfg.h"
#include "px_sim.h"
#include "px_test.h"
#include "px_test_config.h"

static struct px_config_diag g_diag;

static const char yaml[] =
	PX_TEST_YAML_HEAD PX_TEST_YAML_SIM_HAP_IO
	PX_TEST_YAML_CAN("bus", "s0", "sim")
	"      signals:\n"
	"        - {name: x, id: 0x100, direction: input, start_bit: 0, "
	"length: 16, signed: true, scale: 0.0001, axis: x}\n";

static struct px_sim_fault window(int kind, int64_t start_ns,
				  int64_t duration_ns)
{
	struct px_sim_fault f;
	memset(&f, 0, sizeof f);
	f.kind = kind;
	f.start_ns = start_ns;
	f.duration_ns = duration_ns;
	f.probability = 1.0;
	return f;
}

/* A random clock origin: the config's nan window moves with it, the
 * option's (already on the loop clock) does not; both hit the device. */
static void test_option_faults_added(void)
{
	struct px_config *cfg = px_test_config_load(yaml, &g_diag);
	struct px_devcfg *h = NULL, *g = NULL;
	struct px_devcfg_options opt;
	struct px_sim_fault hf, gf;
	struct px_pose_sample ps;
	struct px_dev_status st;
	int64_t t0 = px_rand_int(0, 1000) * 1000000, t;
	int pressed, n_pressed = 0, pressed_early = 0;
	char msg[512];
	PX_CHECK(cfg != NULL);
	if (!cfg)
		return;
	memset(&opt, 0, sizeof opt);
	opt.clock0_ns = t0;
	/* the option's nan window: 40..50 ms after t0, on the loop clock */
	hf = window(PX_SIM_FAULT_NAN, t0 + 40000000, 10000000);
	opt.faults = &hf;
	opt.n_faults = 1;
	PX_CHECK_MSG(px_devcfg_open(cfg, &cfg->devices[0], &opt, &h, msg,
				    sizeof msg) == PX_OK,
		     "%s", msg);
	gf = window(PX_SIM_FAULT_ESTOP, t0 + 5000000, 5000000);
	opt.faults = &gf;
	PX_CHECK_MSG(px_devcfg_open(cfg, &cfg->devices[1], &opt, &g, msg,
				    sizeof msg) == PX_OK,
		     "%s", msg);
	if (!h || !g)
		goto out;
	px_dev_start(px_devcfg_dev(h));
	px_dev_start(px_devcfg_dev(g));
	for (t = t0; t < t0 + 60000000; t += 1000000) {
		px_dev_pose_read(px_devcfg_dev(h), t, &ps);
		PX_CHECK_INT_EQ(px_dev_estop_read(px_devcfg_dev(g), t, &pressed),
				PX_OK);
		n_pressed += pressed;
		if (t < t0 + 5000000)
			pressed_early += pressed;
	}
	px_dev_status(px_devcfg_dev(h), &st);
	/* 10 ms of the config's window + 10 ms of the option's */
	PX_CHECK_MSG(st.nonfinite >= 18 && st.nonfinite <= 22, "%llu",
		     (unsigned long long)st.nonfinite);
	PX_CHECK_MSG(n_pressed >= 4 && n_pressed <= 5, "%d", n_pressed);
	PX_CHECK_INT_EQ(pressed_early, 0);
out:
	px_devcfg_free(h);
	px_devcfg_free(g);
	px_config_free(cfg);
}

static void test_option_faults_refused(void)
{
	struct px_config *cfg = px_test_config_load(yaml, &g_diag);
	struct px_devcfg *h = NULL;
	struct px_devcfg_options opt;
	struct px_sim_fault f[PX_SIM_MAX_FAULTS];
	char msg[512];
	size_t i;
	int rc;
	PX_CHECK(cfg != NULL);
	if (!cfg)
		return;
	for (i = 0; i < PX_SIM_MAX_FAULTS; i++)
		f[i] = window(PX_SIM_FAULT_DROP, (int64_t)i * 1000000, 1000);
	memset(&opt, 0, sizeof opt);
	opt.faults = f;
	/* the config has one window: 16 more do not fit */
	opt.n_faults = PX_SIM_MAX_FAULTS;
	rc = px_devcfg_open(cfg, &cfg->devices[0], &opt, &h, msg, sizeof msg);
	PX_CHECK_INT_EQ(rc, PX_E_NOSPC);
	PX_CHECK(h == NULL);
	PX_CHECK_MSG(strstr(msg, "devices[0].sim.faults") != NULL, "%s", msg);
	/* 15 do */
	opt.n_faults = PX_SIM_MAX_FAULTS - 1;
	rc = px_devcfg_open(cfg, &cfg->devices[0], &opt, &h, msg, sizeof msg);
	PX_CHECK_MSG(rc == PX_OK, "%s", msg);
	px_devcfg_free(h);
	h = NULL;
	/* not a simulated device */
	opt.n_faults = 1;
	rc = px_devcfg_open(cfg, &cfg->devices[2], &opt, &h, msg, sizeof msg);
	PX_CHECK_INT_EQ(rc, PX_E_INVAL);
	PX_CHECK(h == NULL);
	PX_CHECK_MSG(strstr(msg, "device 'bus' (socketcan, devices[2].faults)") !=
			     NULL,
		     "%s", msg);
	/* no option faults: the same device opens */
	opt.n_faults = 0;
	opt.faults = NULL;
	rc = px_devcfg_open(cfg, &cfg->devices[2], &opt, &h, msg, sizeof msg);
	PX_CHECK_MSG(rc == PX_OK, "%s", msg);
	px_devcfg_free(h);
	px_config_free(cfg);
}

static const struct px_test tests[] = {
	PX_T(test_option_faults_added),
	PX_T(test_option_faults_refused),
};
PX_TEST_MAIN(tests)
