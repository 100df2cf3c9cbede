/*
 * proxima-run - run a proxima application from its YAML config.
 *
 *   proxima-run CONFIG [--duration-s N] [--virtual-time] [--summary-json FILE]
 *   proxima-run --check CONFIG
 *
 * This version validates configurations; the runner itself (loop,
 * devices, scene, control) is not built yet, and says so.
 * Exit status: 0 config valid (--check), 1 config invalid or unreadable,
 * 2 usage error or runner not available.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "px_config.h"
#include "px_control.h"

static const char usage_text[] =
	"usage: proxima-run CONFIG [--duration-s N] [--virtual-time] "
	"[--summary-json FILE]\n"
	"       proxima-run --check CONFIG\n"
	"\n"
	"  --check            validate CONFIG, print every problem, and exit\n"
	"  --duration-s N     run for N seconds (N > 0)\n"
	"  --virtual-time     run the loop on the virtual clock, as fast as "
	"possible\n"
	"  --summary-json F   write a machine-readable summary to F\n"
	"  --help             this text\n"
	"Exit status: 0 ok, 1 invalid config, 2 usage error or runner not "
	"available.\n";

static int usage_error(const char *fmt, const char *arg)
{
	fprintf(stderr, "proxima-run: ");
	fprintf(stderr, fmt, arg);
	fprintf(stderr, "\n%s", usage_text);
	return 2;
}

struct options {
	const char *config;
	int check;
	int virtual_time;
	double duration_s; /* 0 = until stopped */
	const char *summary_json;
};

/* Value of an option given as "--opt VALUE" or "--opt=VALUE". */
static const char *opt_value(int argc, char **argv, int *i, const char *name)
{
	size_t n = strlen(name);
	if (argv[*i][n] == '=')
		return argv[*i] + n + 1;
	if (*i + 1 >= argc)
		return NULL;
	return argv[++*i];
}

static int matches(const char *arg, const char *name)
{
	size_t n = strlen(name);
	return strncmp(arg, name, n) == 0 && (arg[n] == '\0' || arg[n] == '=');
}

static int parse_args(int argc, char **argv, struct options *o)
{
	int i, rest = 0;
	memset(o, 0, sizeof(*o));
	for (i = 1; i < argc; i++) {
		const char *a = argv[i];
		if (!rest && strcmp(a, "--") == 0) {
			rest = 1;
		} else if (!rest && (strcmp(a, "--help") == 0 ||
				     strcmp(a, "-h") == 0)) {
			fputs(usage_text, stdout);
			return 1;
		} else if (!rest && strcmp(a, "--check") == 0) {
			o->check = 1;
		} else if (!rest && strcmp(a, "--virtual-time") == 0) {
			o->virtual_time = 1;
		} else if (!rest && matches(a, "--duration-s")) {
			const char *v = opt_value(argc, argv, &i, "--duration-s");
			char *end;
			double d;
			if (!v)
				return usage_error("%s needs a value", a);
			errno = 0;
			d = strtod(v, &end);
			if (end == v || *end || errno || !isfinite(d) || d <= 0)
				return usage_error(
					"--duration-s: '%s' is not a positive "
					"number of seconds",
					v);
			o->duration_s = d;
		} else if (!rest && matches(a, "--summary-json")) {
			const char *v = opt_value(argc, argv, &i, "--summary-json");
			if (!v || !*v)
				return usage_error("%s needs a file name", a);
			o->summary_json = v;
		} else if (!rest && a[0] == '-' && a[1] != '\0') {
			return usage_error("unknown option '%s'", a);
		} else if (!o->config) {
			o->config = a;
		} else {
			return usage_error("unexpected argument '%s' (one CONFIG "
					   "only)",
					   a);
		}
	}
	if (!o->config)
		return usage_error("%s", "no CONFIG given");
	return 0;
}

int main(int argc, char **argv)
{
	static struct px_config_diag diag;
	struct options o;
	struct px_config *cfg = NULL;
	int rc = parse_args(argc, argv, &o);
	if (rc)
		return rc == 1 ? 0 : rc;
	rc = px_config_load_file(o.config, &cfg, &diag);
	if (rc != PX_OK) {
		int n = px_config_diag_total(&diag);
		px_config_diag_print(&diag, stderr);
		if (n == 0)
			fprintf(stderr, "%s: %s\n", o.config, px_strerror(rc));
		fprintf(stderr, "%s: invalid configuration (%d error%s)\n",
			o.config, n, n == 1 ? "" : "s");
		return 1;
	}
	{
		static struct px_control_config ctl;
		rc = px_control_config_read(cfg, &ctl, &diag);
		if (rc != PX_OK) {
			int n = px_config_diag_total(&diag);
			px_config_diag_print(&diag, stderr);
			if (n == 0)
				fprintf(stderr, "%s: %s\n", o.config,
					px_strerror(rc));
			fprintf(stderr, "%s: invalid configuration (%d error%s)\n",
				o.config, n, n == 1 ? "" : "s");
			px_config_free(cfg);
			return 1;
		}
		if (ctl.warning[0])
			fprintf(stderr, "%s\n", ctl.warning);
	}
	if (o.check) {
		printf("%s: OK (%zu device%s, loop period %lld ns)\n", o.config,
		       cfg->n_devices, cfg->n_devices == 1 ? "" : "s",
		       (long long)cfg->loop.period_ns);
		px_config_free(cfg);
		return 0;
	}
	px_config_free(cfg);
	fprintf(stderr,
		"proxima-run: %s is valid, but the runner (loop, devices, "
		"scene, control) is not built yet in this version; only "
		"--check works\n",
		o.config);
	return 2;
}
