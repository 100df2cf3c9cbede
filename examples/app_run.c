/* PX_TEST_NEEDS: libyaml (the shipped configs are YAML; tests/run.sh skips it in builds without) */
/*
 * app_run.c - the shipped haptic_sim.yaml through the app module: the
 * config's devices, scene, control and safety policy, 2 s on the virtual
 * clock, the nearest distance of the run printed. Exits 0 when the
 * outputs ended confirmed safe.
 */
#include <stdio.h>

#include <proxima/px_app.h>

int main(int argc, char **argv)
{
	const char *path = argc > 1 ? argv[1] : "config/examples/haptic_sim.yaml";
	static struct px_config_diag diag;
	struct px_config *cfg;
	struct px_app_options opt;
	struct px_app_summary s;
	struct px_app *app;
	char msg[256];
	int rc = px_config_load_file(path, &cfg, &diag);
	if (rc != PX_OK)
		return fprintf(stderr, "%s: %s\n", path, px_strerror(rc)), 1;
	px_app_options_default(&opt);
	opt.config = path;
	opt.virtual_time = 1;
	opt.duration_s = 2.0;
	rc = px_app_create(cfg, &opt, &app, msg, sizeof(msg));
	if (rc == PX_OK) {
		px_app_run(app);
		rc = px_app_shutdown(app, "end of run");
		px_app_drain(app, NULL, NULL);
		px_app_summary(app, &s);
		printf("%llu cycles, min distance %+.3f mm, max force %.3f N, %s\n",
		       (unsigned long long)s.cycles, s.min_distance_m * 1e3,
		       s.max_force_n, s.shutdown_safe ? "safe at the end" : "NOT SAFE");
		px_app_free(app);
	} else {
		fprintf(stderr, "%s\n", msg);
	}
	px_config_free(cfg);
	return rc == PX_OK ? 0 : 1;
}
