/*
 * proxima-run - run a proxima application from its YAML config.
 *
 *   proxima-run CONFIG [--duration-s N] [--virtual-time] [--summary-json FILE]
 *                      [--telemetry FILE]
 *   proxima-run --check CONFIG
 *
 * A main over the app module (app/px_app.h), which owns the setup from the
 * config, the loop's three phases and the whole safety policy (velocity
 * trip, e-stop lines, enable relay, CANopen quick stop, the safe state at
 * every exit). Here: the arguments, the signals (each that would end or
 * freeze the process - INT, TERM, HUP, QUIT, USR1, USR2, PIPE, ALRM,
 * VTALRM, PROF, XCPU, XFSZ, TSTP - ends the run like Ctrl-C through
 * px_app_stop()), the live status line on stderr, and the files: the
 * telemetry CSV from the drained records, the SVG plots next to it, the
 * summary on stdout and as JSON (--summary-json). Output paths are
 * checked by the app at setup through tools/tool_out.h (temporary file
 * renamed over the target; never over the config or an input file).
 *
 * Heap calls are counted per thread by the tests' allocator hook when it
 * is loaded (LD_PRELOAD=libproxima-alloc-count.so, as the test suite runs
 * this program: the interposed malloc family; sanitizer builds link it:
 * the sanitizer's malloc/free hooks) and only the calls the loop's thread
 * makes while cycles run are reported (allocations_after_setup), beside
 * the calls setup made (allocations_setup, showing the counter is live).
 * Without the hook allocation_counter is "none" and nothing is counted.
 * PX_RUN_ALLOC_PROBE=1 makes cycle 10 allocate and free once on purpose
 * (the count is then 2); PX_RUN_STOP_AT=CYCLE[:SIGNAL] raises SIGNAL after
 * CYCLE cycles ("stop now", for tests).
 *
 * Exit status: 0 ok, 1 invalid config or setup failure (an absent device
 * is named with the back end's reason) or outputs not confirmed safe at
 * the end, 2 usage error (a flag's value, an output flag refused) or
 * --virtual-time with hardware.
 */
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "px_alloc_count.h"
#include "px_app.h"
#include "px_canopen.h"
#include "px_config.h"
#include "px_dev.h"
#include "px_gpio.h"
#include "px_loop.h"
#include "px_sim.h"
#include "px_stats.h"
#include "px_world.h"
#include "tool_out.h"
#include "tool_svg.h"

static const char usage_text[] =
	"usage: proxima-run CONFIG [--duration-s N] [--virtual-time] "
	"[--summary-json FILE]\n"
	"       proxima-run --check CONFIG\n"
	"\n"
	"  --check            validate CONFIG, print every problem, and exit\n"
	"  --duration-s N     run for N seconds of loop time (0 < N <= 1e8);\n"
	"                     default: until Ctrl-C\n"
	"  --virtual-time     run the loop on the virtual clock, as fast as "
	"possible\n"
	"  --summary-json F   write a machine-readable summary to F\n"
	"  --telemetry F      telemetry CSV (default: telemetry.file of "
	"CONFIG);\n"
	"                     plots go next to it as <stem>_time.svg and "
	"<stem>_latency.svg\n"
	"  --fault K,DEV,START_S,DURATION_S[,PROBABILITY[,DELAY_S]]\n"
	"                     inject fault kind K into device DEV (as an entry "
	"of\n"
	"                     sim.faults; DEV 'loop' for overrun); repeatable\n"
	"  --help             this text\n"
	"Exit status: 0 ok, 1 invalid config or setup failure (e.g. a device\n"
	"absent), 2 usage error or --virtual-time with hardware devices.\n";

static int usage_error(const char *fmt, const char *arg)
{
	fprintf(stderr, "proxima-run: ");
	fprintf(stderr, fmt, arg);
	fprintf(stderr, "\n%s", usage_text);
	return 2;
}

/* --duration-s at most (about 3 years): cycles and the loop clock's
 * nanoseconds stay far inside their integers at any period. */
#define RUN_MAX_DURATION_S 1e8


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

static int parse_args(int argc, char **argv, struct px_app_options *o)
{
	int i, rest = 0;
	px_app_options_default(o);
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
			if (end == v || *end || errno || !isfinite(d) || d <= 0 ||
			    d > RUN_MAX_DURATION_S)
				return usage_error(
					"--duration-s: '%s' is not a positive "
					"number of seconds (at most 1e8)",
					v);
			o->duration_s = d;
		} else if (!rest && matches(a, "--summary-json")) {
			const char *v = opt_value(argc, argv, &i, "--summary-json");
			if (!v || !*v)
				return usage_error("%s needs a file name", a);
			o->summary_json = v;
		} else if (!rest && matches(a, "--fault")) {
			const char *v = opt_value(argc, argv, &i, "--fault");
			if (!v || !*v)
				return usage_error("%s needs KIND,DEVICE,START_S,"
						   "DURATION_S", a);
			if (o->n_faults == 64)
				return usage_error("%s: at most 64", a);
			o->faults[o->n_faults++] = v;
		} else if (!rest && matches(a, "--telemetry")) {
			const char *v = opt_value(argc, argv, &i, "--telemetry");
			if (!v || !*v)
				return usage_error("%s needs a file name", a);
			o->telemetry = v;
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

/* ---- heap call counter (per thread) -------------------------------- */

/* The tests' counter (tests/px_alloc_count.c) when it is there: preloaded
 * as libproxima-alloc-count.so, or linked in sanitizer builds. It sees
 * every malloc-family call of the loop thread. Weak, so that a run
 * without it still works and says the counter is "none". */
#pragma weak px_alloc_count_thread
#pragma weak px_alloc_count_mode

static uint64_t heap_count(void)
{
	return px_alloc_count_thread ? px_alloc_count_thread() : 0;
}

static const char *heap_counter_name(void)
{
	return px_alloc_count_mode ? px_alloc_count_mode() : "none";
}

/* ---- the run's state on this side: the app, the CSV, the plots ------ */

/* The plots keep the first PLOT_MAX records (about 17 min at 1 kHz). */
#define PLOT_MAX ((size_t)1 << 20)

static int64_t mono_ns(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

static struct px_app *A;
static struct px_config *CFG;
static struct px_app_options O; /* the arguments */
static struct px_app_summary S; /* what the app reports (after the run: all) */

static struct {
	FILE *csv_f;            /* csv_out.f while the CSV is written */
	struct tool_out csv_out;
	struct px_app_record *recs; /* the plots' records */
	size_t n_recs, cap_recs;
	uint64_t setup_heap_calls;
	char out_why[TOOL_OUT_WHY_MAX]; /* why write_json() failed */
} T;

static volatile sig_atomic_t interrupted;
static volatile sig_atomic_t stop_signal; /* the signal that ended the run */

static void on_signal(int sig)
{
	if (!stop_signal)
		stop_signal = sig;
	interrupted = 1;
	px_app_stop(A);
}

static void shutdown_line(FILE *f, const char *prefix)
{
	char line[1024];
	px_app_shutdown_describe(A, line, sizeof(line));
	fprintf(f, "%s%s\n", prefix, line);
}

static void json_string(FILE *f, const char *s);

/* The shutdown as a JSON object (a member of the summary), with what
 * each simulated device last received. */
static void json_shutdown(FILE *f)
{
	int i, first = 1;
	fprintf(f,
		"  \"shutdown\": {\"shutdown_safe\": %d, \"shutdown_reason\": "
		"\"%s\", \"force_devices\": %d, \"force_zeroed\": %d, "
		"\"relay_devices\": %d, \"relays_off\": %d, "
		"\"shutdown_drives\": %d, \"drives_disabled\": %d, "
		"\"drives_faulted\": %d, \"shutdown_ns\": %lld, "
		"\"shutdown_error\": ",
		S.shutdown_safe, S.shutdown_reason, S.force_devices, S.force_zeroed,
		S.relay_devices, S.relays_off, S.shutdown_drives, S.drives_disabled,
		S.drives_faulted, (long long)S.shutdown_ns);
	json_string(f, S.shutdown_error);
	fputs(", \"last_outputs\": [", f);
	for (i = 0; i < px_app_device_count(A); i++) {
		struct px_dev *d = px_app_device_at(A, i);
		struct px_sim_haptic_state hs;
		struct px_dev_status st;
		int relay;
		px_dev_status(d, &st);
		if (px_sim_haptic_state(d, &hs) == PX_OK &&
		    (px_dev_caps(d) & PX_DEV_CAP_FORCE)) {
			fprintf(f, "%s{\"name\": ", first ? "" : ", ");
			json_string(f, st.name);
			fprintf(f,
				", \"last_force_n\": [%.9g, "
				"%.9g, %.9g], \"last_torque_n_m\": [%.9g, %.9g, "
				"%.9g], \"last_enable\": %d, \"outputs_safe\": %d}",
				hs.force_n[0],
				hs.force_n[1], hs.force_n[2], hs.torque_n_m[0],
				hs.torque_n_m[1], hs.torque_n_m[2], hs.enable,
				st.outputs_safe);
			first = 0;
		} else if ((relay = px_gpio_sim_output(d,
						       PX_GPIO_ENABLE)) >= 0) {
			fprintf(f, "%s{\"name\": ", first ? "" : ", ");
			json_string(f, st.name);
			fprintf(f,
				", \"enable_line\": %d, "
				"\"timing_line\": %d, \"outputs_safe\": %d}",
				relay,
				px_gpio_sim_output(d, PX_GPIO_TIMING),
				st.outputs_safe);
			first = 0;
		}
	}
	fputs("]},\n", f);
}

/* Ask for the safe state on every signal that would otherwise end (or,
 * SIGTSTP, freeze) the process with the last command in effect: each
 * ends the run like SIGINT, through the summary and safe_shutdown(). */
static const int stop_signals[] = {SIGINT,    SIGTERM, SIGHUP,  SIGQUIT,
				   SIGUSR1,   SIGUSR2, SIGPIPE, SIGALRM,
				   SIGVTALRM, SIGPROF, SIGXCPU, SIGXFSZ,
				   SIGTSTP};

static void install_signals(void)
{
	struct sigaction sa;
	size_t i;
	memset(&sa, 0, sizeof(sa));
	sa.sa_handler = on_signal;
	sigemptyset(&sa.sa_mask);
	sa.sa_flags = SA_RESTART;
	for (i = 0; i < sizeof(stop_signals) / sizeof(stop_signals[0]); i++)
		sigaction(stop_signals[i], &sa, NULL);
}

/* "SIGINT" for the run's end by a signal. */
static void signal_reason(int sig, char *buf, size_t cap)
{
	const char *ab = sigabbrev_np(sig);
	if (ab)
		snprintf(buf, cap, "SIG%s", ab);
	else
		snprintf(buf, cap, "signal %d", sig);
}

/* safety.watchdog.auto_rearm with an e-stop line: the e-stop still
 * needs an explicit re-arm (px_loop_trip_estop), which the user of such
 * a config may not expect: say so, at the auto_rearm key. */
static void status_line(int final, double wall_s, double rate)
{
	struct px_app_record last;
	int have_last = px_app_last_record(A, &last);
	struct px_stats_snapshot lat, cmp;
	struct px_loop_status st;
	static int tty = -1;
	if (tty < 0)
		tty = isatty(2);
	px_loop_stats(px_app_loop(A), PX_LOOP_STAT_LATENCY, &lat);
	px_stats_read(px_app_compute_stats(A), &cmp);
	px_loop_status(px_app_loop(A), &st);
	fprintf(stderr,
		"%s[%7.2f s] %6.0f cycles/s | wake p99 %5.1f us | compute p99 "
		"%5.1f us | distance %+8.2f mm | force %5.2f N | faults %llu%s%s",
		tty ? "\r" : "", have_last ? last.t_s : 0.0, rate,
		(double)lat.p99_ns / 1e3, (double)cmp.p99_ns / 1e3,
		have_last && isfinite(last.distance_m) ? last.distance_m * 1e3
							     : 0.0,
		have_last ? last.force_mag_n : 0.0,
		(unsigned long long)st.faults, st.safe ? " | SAFE STATE" : "",
		tty ? "\033[K" : "\n");
	if (final && tty)
		fputc('\n', stderr);
	(void)wall_s;
	fflush(stderr);
}

struct rate_meter {
	int64_t t_ns;
	uint64_t cycles;
	double rate;
};

static void maybe_status(struct rate_meter *m, int64_t now, int64_t every_ns)
{
	struct px_loop_status st;
	if (now - m->t_ns < every_ns)
		return;
	px_loop_status(px_app_loop(A), &st);
	m->rate = (double)(st.cycles - m->cycles) / ((double)(now - m->t_ns) * 1e-9);
	m->cycles = st.cycles;
	m->t_ns = now;
	status_line(0, 0, m->rate);
}

/* The app's hooks: messages to stderr, the status line between
 * batches, the records into the CSV and the plots, PX_RUN_STOP_AT. */
static void on_note(void *user, const char *text)
{
	(void)user;
	fputs(text, stderr);
}

static struct rate_meter meter;
static int64_t status_every_ns;
static int stop_sig;

static void on_tick(void *user)
{
	(void)user;
	maybe_status(&meter, mono_ns(), status_every_ns);
}

static void on_stop_cycle(void *user)
{
	(void)user;
	raise(stop_sig);
}

static int out_check(void *user, const char *path, char *why, size_t cap)
{
	(void)user;
	return tool_out_check(path, why, cap);
}

static void in_protect(void *user, const char *path, const char *what)
{
	(void)user;
	tool_out_protect(path, what);
}

static void on_record(void *user, const struct px_app_record *r)
{
	(void)user;
	/* the plots keep the first PLOT_MAX records (about 17 min at
	 * 1 kHz); the CSV gets everything */
	if (T.n_recs < PLOT_MAX) {
		if (T.n_recs == T.cap_recs) {
			size_t cap = T.cap_recs ? 2 * T.cap_recs : 4096;
			struct px_app_record *p = realloc(T.recs, cap * sizeof(*p));
			if (p) {
				T.recs = p;
				T.cap_recs = cap;
			}
		}
		if (T.n_recs < T.cap_recs)
			T.recs[T.n_recs++] = *r;
	}
	if (T.csv_f) {
		int j;
		fprintf(T.csv_f,
			"%.6f,%llu,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.6g,%.6g,"
			"%.6g,%.6g,%.9g,%.9g,%d,%d,%lld,%lld,%d",
			r->t_s, (unsigned long long)r->cycle, r->dev_m[0],
			r->dev_m[1], r->dev_m[2], r->proxy_m[0], r->proxy_m[1],
			r->proxy_m[2], r->force_n[0], r->force_n[1],
			r->force_n[2], r->force_mag_n, r->distance_m,
			r->penetration_m, r->contact, r->safe,
			(long long)r->latency_ns, (long long)r->compute_ns,
			r->queries);
		if (S.avoiding) {
			fprintf(T.csv_f, ",%.6g", r->scale);
			for (j = 0; j < S.record_joints; j++)
				fprintf(T.csv_f, ",%.6g", r->qdot[j]);
		}
		fputc('\n', T.csv_f);
	}
}

/* Free the app (the safe state first, if it has not run), then the
 * config it reads. */
static void finish(void)
{
	tool_out_discard(&T.csv_out); /* an unfinished CSV: never in place */
	px_app_free(A);
	A = NULL;
	px_config_free(CFG);
	free(T.recs);
}

/* ---- results -------------------------------------------------------- */

/* The plot names the app checked (next to the CSV). */
/* PX_RUN_STOP_AT=CYCLE[:SIGNAL] in the environment raises SIGNAL (a
 * name as kill -l gives it, default TERM) in this process once CYCLE
 * cycles have run: "stop now" at a chosen cycle, through the real signal
 * path (for tests and fault campaigns). 0 when not asked. */
static uint64_t stop_at_cycle(int *sig)
{
	const char *e = getenv("PX_RUN_STOP_AT"), *c;
	char *end;
	unsigned long long n;
	size_t i;
	*sig = SIGTERM;
	if (!e || !*e)
		return 0;
	n = strtoull(e, &end, 10);
	if (end == e || (*end && *end != ':'))
		return 0;
	if (*end == ':') {
		c = end + 1;
		if (!strncmp(c, "SIG", 3))
			c += 3;
		for (i = 0; i < sizeof(stop_signals) / sizeof(stop_signals[0]);
		     i++) {
			const char *ab = sigabbrev_np(stop_signals[i]);
			if (ab && !strcmp(ab, c))
				*sig = stop_signals[i];
		}
	}
	return (uint64_t)n;
}

static void plot_paths(char *time_svg, char *lat_svg, size_t cap)
{
	snprintf(time_svg, cap, "%s", S.time_svg);
	snprintf(lat_svg, cap, "%s", S.lat_svg);
}

static int write_plots(const char *time_svg, const char *lat_svg)
{
	size_t n = T.n_recs, i;
	double *x = calloc(n + 1, sizeof(double));
	double *d = calloc(n + 1, sizeof(double));
	double *f = calloc(n + 1, sizeof(double));
	double *pen = calloc(n + 1, sizeof(double));
	double *fz = calloc(n + 1, sizeof(double));
	int rc = -1;
	static uint64_t lbins[PX_STATS_DEFAULT_BINS], cbins[PX_STATS_DEFAULT_BINS];
	uint64_t lover = 0, cover = 0;
	int nl, nc;
	if (x && d && f && pen && fz && S.avoiding) {
		static const char *const colors[PX_APP_RECORD_JOINTS] = {
			"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd",
			"#8c564b"};
		static const char *const names[PX_APP_RECORD_JOINTS] = {
			"joint 0", "joint 1", "joint 2", "joint 3", "joint 4",
			"joint 5"};
		double *qd[PX_APP_RECORD_JOINTS] = {0};
		struct tool_svg_series sq[PX_APP_RECORD_JOINTS];
		struct tool_svg_series sd[] = {{"clearance", d, "#1f77b4"},
					       {"protective", pen, "#d62728"}};
		struct tool_svg_series ss[] = {{"speed scale", f, "#2ca02c"}};
		struct tool_svg_panel p[] = {{"clearance (mm)", sd, 2},
					     {"speed scale", ss, 1},
					     {"commanded velocity (rad/s)", sq, 0}};
		int j, nj = S.record_joints, ok = 1;
		for (j = 0; j < nj; j++) {
			qd[j] = calloc(n + 1, sizeof(double));
			ok = ok && qd[j];
			sq[j].name = names[j];
			sq[j].y = qd[j];
			sq[j].color = colors[j];
		}
		p[2].n_series = nj;
		for (i = 0; ok && i < n; i++) {
			x[i] = T.recs[i].t_s;
			d[i] = T.recs[i].distance_m * 1e3;
			pen[i] = S.protective_distance_m * 1e3;
			f[i] = T.recs[i].scale;
			for (j = 0; j < nj; j++)
				qd[j][i] = T.recs[i].qdot[j];
		}
		if (ok)
			rc = tool_svg_lines(time_svg,
					    "proxima-run: clearance, speed scale "
					    "and commanded joint velocity",
					    "time (s)", x, n, p, 3);
		for (j = 0; j < nj; j++)
			free(qd[j]);
	} else if (x && d && f && pen && fz) {
		struct tool_svg_series sd[] = {{"distance", d, "#1f77b4"}};
		struct tool_svg_series sf[] = {{"|F|", f, "#d62728"},
					       {"Fz", fz, "#ff7f0e"}};
		struct tool_svg_series sp[] = {{"penetration", pen, "#2ca02c"}};
		struct tool_svg_panel p[] = {{"distance (mm)", sd, 1},
					     {"force (N)", sf, 2},
					     {"proxy penetration (mm)", sp, 1}};
		for (i = 0; i < n; i++) {
			x[i] = T.recs[i].t_s;
			d[i] = T.recs[i].distance_m * 1e3;
			f[i] = T.recs[i].force_mag_n;
			fz[i] = T.recs[i].force_n[2];
			pen[i] = T.recs[i].penetration_m * 1e3;
		}
		rc = tool_svg_lines(time_svg,
				    "proxima-run: distance, force and proxy "
				    "penetration",
				    "time (s)", x, n, p, 3);
	}
	free(x);
	free(d);
	free(f);
	free(pen);
	free(fz);
	nl = px_stats_copy_bins(px_loop_stats_handle(px_app_loop(A), PX_LOOP_STAT_LATENCY),
				lbins, PX_STATS_DEFAULT_BINS, &lover);
	nc = px_stats_copy_bins(px_app_compute_stats(A), cbins, PX_STATS_DEFAULT_BINS, &cover);
	if (rc == 0 && nl >= 0 && nc >= 0) {
		struct tool_svg_hist h[] = {
			{"wake-up latency", lbins, (size_t)nl, lover,
			 (double)px_stats_bin_ns(px_loop_stats_handle(
				 px_app_loop(A), PX_LOOP_STAT_LATENCY)) /
				 1e3,
			 "#1f77b4"},
			{"compute time", cbins, (size_t)nc, cover,
			 (double)px_stats_bin_ns(px_app_compute_stats(A)) / 1e3, "#9467bd"}};
		rc = tool_svg_histograms(lat_svg,
					 O.virtual_time
						 ? "proxima-run: latency (virtual "
						   "clock: wake-up is 0 by "
						   "construction)"
						 : "proxima-run: latency",
					 "microseconds", h, 2);
	}
	return rc;
}

static void json_stats(FILE *f, const char *name,
		       const struct px_stats_snapshot *s, int last)
{
	fprintf(f,
		"  \"%s\": {\"count\": %llu, \"p50\": %lld, \"p99\": %lld, "
		"\"p999\": %lld, \"max\": %lld, \"mean\": %lld}%s\n",
		name, (unsigned long long)s->count, (long long)s->p50_ns,
		(long long)s->p99_ns, (long long)s->p999_ns, (long long)s->max_ns,
		(long long)s->mean_ns, last ? "" : ",");
}

static void json_string(FILE *f, const char *s)
{
	fputc('"', f);
	for (; *s; s++) {
		if (*s == '"' || *s == '\\')
			fprintf(f, "\\%c", *s);
		else if ((unsigned char)*s < 0x20)
			fprintf(f, "\\u%04x", *s);
		else
			fputc(*s, f);
	}
	fputc('"', f);
}

static double json_num(double v)
{
	return isfinite(v) ? v : 0.0;
}

struct dev_faults {
	uint64_t by_kind[PX_DEV_ERR__COUNT];
};

static void device_faults(struct dev_faults *df)
{
	int i;
	memset(df, 0, sizeof(*df));
	for (i = 0; i < px_app_device_count(A); i++) {
		struct px_dev_status s;
		if (px_dev_status(px_app_device_at(A, i), &s) != PX_OK)
			continue;
		df->by_kind[PX_DEV_ERR_DECODE] += s.decode_errors;
		df->by_kind[PX_DEV_ERR_NONFINITE] += s.nonfinite;
		df->by_kind[PX_DEV_ERR_DUPLICATE] += s.duplicates;
		df->by_kind[PX_DEV_ERR_STUCK] += s.stuck;
		df->by_kind[PX_DEV_ERR_UNPLUG] += s.unplugs;
		df->by_kind[PX_DEV_ERR_IO] += s.io_errors + s.write_errors;
		df->by_kind[PX_DEV_ERR_BUS] += s.bus_errors;
	}
}

static void json_campaign(FILE *f);

/* The loop clock's span over the run: first deadline (periods skipped
 * before it included) to the last cycle's end; missed periods count,
 * as time that went by. On the real clock this is the run's real time,
 * on the virtual clock its simulated time. */
static double loop_time_s(const struct px_loop_status *st)
{
	(void)st;
	return S.loop_time_s;
}

/* What ended the run: "cycles" (--duration-s worth of cycles run),
 * "time" (real clock: --duration-s of loop time gone, periods missed),
 * "signal", or "stop" (the loop stopped: an error, a phase). */
static const char *ended_by(const struct px_loop_status *st)
{
	if (S.max_cycles && st->cycles >= S.max_cycles)
		return "cycles";
	if (S.ended_by_time)
		return "time";
	return interrupted ? "signal" : "stop";
}


/* What the safety layer and the e-stop did: presses seen, how long after
 * the first press the loop was in safe state (ns, -1: never), state at
 * the end. */
static void json_safety(FILE *f, const struct px_loop_status *st)
{
	fprintf(f,
		"  \"safe_at_end\": %d,\n  \"safe_cause\": \"%s\",\n"
		"  \"estop_lines\": %d,\n  \"estop_presses\": %llu,\n"
		"  \"estop_cycles\": %llu,\n  \"estop_to_safe_ns\": %lld,\n"
		"  \"estop_to_safe_cycles\": %lld,\n"
		"  \"safe_cycles_before_estop\": %llu,\n"
		"  \"safe_at_estop\": %d,\n"
		"  \"enable_write_errors\": %llu,\n",
		st->safe, st->safe ? px_fault_cause_name(st->safe_cause) : "",
		S.estop_lines, (unsigned long long)S.estop_presses,
		(unsigned long long)S.estop_cycles,
		(long long)S.estop_to_safe_ns, (long long)S.estop_to_safe_cycles,
		(unsigned long long)S.safe_cycles_before_estop, S.safe_at_estop,
		(unsigned long long)S.enable_write_errors);
}

/* Every device's counters, and the CANopen drives' states. */
static void json_devices(FILE *f)
{
	struct px_canopen *co = px_app_canopen(A);
	int i;
	fputs("  \"devices\": [", f);
	for (i = 0; i < px_app_device_count(A); i++) {
		struct px_dev_status s;
		if (px_dev_status(px_app_device_at(A, i), &s) != PX_OK)
			continue;
		fprintf(f, "%s\n    {\"name\": ", i ? "," : "");
		json_string(f, s.name);
		fprintf(f, ", \"backend\": ");
		json_string(f, s.backend);
		fprintf(f,
			", \"state\": %d, \"reports\": %llu, \"samples\": %llu, "
			"\"writes\": %llu, \"write_errors\": %llu, \"errors\": "
			"%llu, \"last_error\": ",
			s.state, (unsigned long long)s.reports,
			(unsigned long long)s.samples, (unsigned long long)s.writes,
			(unsigned long long)s.write_errors,
			(unsigned long long)s.errors);
		json_string(f, s.last_msg);
		fputc('}', f);
	}
	fputs(px_app_device_count(A) ? "\n  ],\n" : "],\n", f);
	fprintf(f,
		"  \"drives_enabled_cycles\": %llu,\n"
		"  \"drive_problem_cycles\": %llu,\n  \"drives\": [",
		(unsigned long long)S.drives_enabled_cycles,
		(unsigned long long)S.drive_problem_cycles);
	for (i = 0; co && i < S.n_drives; i++) {
		struct px_canopen_drive_status ds;
		if (px_canopen_drive_status(co, (size_t)i, &ds) != PX_OK)
			continue;
		fprintf(f,
			"%s\n    {\"node_id\": %d, \"state\": \"%s\", "
			"\"position\": %.9g, \"lost\": %d, \"emcy\": %llu}",
			i ? "," : "", ds.node_id, px_cia402_state_name(ds.state),
			json_num(ds.position), ds.lost,
			(unsigned long long)ds.emcy_count);
	}
	fputs(co && S.n_drives ? "\n  ],\n" : "],\n", f);
}

static int write_json(const char *path, const struct px_loop_status *st,
		      const struct px_stats_snapshot *lat,
		      const struct px_stats_snapshot *cmp, double wall_s,
		      const char *time_svg, const char *lat_svg,
		      const char *counter)
{
	static struct tool_out out;
	FILE *f;
	struct dev_faults df;
	int k;
	if (tool_out_open(&out, path) != 0) {
		snprintf(T.out_why, sizeof(T.out_why), "%s", out.why);
		return -1;
	}
	f = out.f;
	device_faults(&df);
	fprintf(f, "{\n  \"config\": ");
	json_string(f, O.config);
	fprintf(f,
		",\n  \"clock\": \"%s\",\n  \"period_ns\": %lld,\n"
		"  \"simulated_s\": %.6f,\n  \"wall_s\": %.3f,\n"
		"  \"cycles\": %llu,\n  \"overruns\": %llu,\n"
		"  \"missed_periods\": %llu,\n",
		O.virtual_time ? "virtual" : "monotonic",
		(long long)st->period_ns,
		(double)st->cycles * (double)st->period_ns * 1e-9, wall_s,
		(unsigned long long)st->cycles, (unsigned long long)st->overruns,
		(unsigned long long)st->missed_periods);
	fprintf(f,
		"  \"loop_time_s\": %.6f,\n  \"wall_time_s\": %.3f,\n"
		"  \"duration_s\": %.9g,\n  \"ended_by\": \"%s\",\n",
		loop_time_s(st), wall_s, O.duration_s, ended_by(st));
	json_stats(f, "wakeup_latency_ns", lat, 0);
	json_stats(f, "compute_ns", cmp, 0);
	{
		struct px_model_stream_stats ts;
		int ns = S.tracking_streams;
		ts = S.tracking;
		fprintf(f,
			"  \"tracking\": {\"enabled\": %s, \"streams\": %d, "
			"\"queries\": %llu, \"tracked\": %llu, \"hot\": %llu, "
			"\"global\": %llu, \"cold\": %llu, \"jumps\": %llu, "
			"\"reinits\": %llu, \"verifications\": %llu, "
			"\"disagreements\": %llu},\n",
			S.tracking_enabled ? "true" : "false", ns,
			(unsigned long long)ts.queries,
			(unsigned long long)ts.tracked,
			(unsigned long long)ts.hot, (unsigned long long)ts.global,
			(unsigned long long)ts.cold, (unsigned long long)ts.jumps,
			(unsigned long long)ts.reinits,
			(unsigned long long)ts.verifications,
			(unsigned long long)ts.disagreements);
	}
	fprintf(f,
		"  \"max_force_n\": %.9g,\n  \"force_clamp_n\": %.9g,\n"
		"  \"min_distance_m\": %.9g,\n  \"max_penetration_m\": %.9g,\n"
		"  \"min_proxy_distance_m\": %.9g,\n"
		"  \"min_clearance_m\": %.9g,\n  \"protective_distance_m\": %.9g,\n"
		"  \"min_speed_scale\": %.9g,\n"
		"  \"contact_cycles\": %llu,\n  \"safe_state_trips\": %llu,\n"
		"  \"faults\": {",
		S.max_force_n, S.rendering ? S.force_clamp_n : 0.0,
		json_num(S.min_distance_m), S.max_penetration_m,
		json_num(S.min_proxy_distance_m),
		S.avoiding ? json_num(S.min_clearance_m) : 0.0,
		S.avoiding ? S.protective_distance_m : 0.0,
		S.avoiding ? S.min_speed_scale : 1.0,
		(unsigned long long)S.contact_cycles,
		(unsigned long long)st->safe_entries);
	for (k = 1; k < PX_FAULT__COUNT; k++)
		fprintf(f, "\"%s\": %llu, ", px_fault_cause_name(k),
			(unsigned long long)S.faults_by_cause[k]);
	for (k = 1; k < PX_DEV_ERR__COUNT; k++)
		if (k != PX_DEV_ERR_OPEN && k != PX_DEV_ERR_ESTOP &&
		    k != PX_DEV_ERR_ENCODE)
			fprintf(f, "\"device_%s\": %llu, ", px_dev_errkind_name(k),
				(unsigned long long)df.by_kind[k]);
	fprintf(f,
		"\"velocity_limit\": %llu, \"query_error\": %llu, "
		"\"dropped\": %llu},\n",
		(unsigned long long)S.velocity_trips,
		(unsigned long long)S.query_errors,
		(unsigned long long)st->faults_dropped);
	json_safety(f, st);
	json_devices(f);
	json_shutdown(f);
	{
		uint64_t checked = S.watchdog_trips_checked;
		int64_t worst = S.max_trip_to_safe_cycles;
		fprintf(f,
			"  \"faults_injected\": %zu,\n  \"faults_popped\": %llu,\n"
			"  \"watchdog_trips_checked\": %llu,\n"
			"  \"max_trip_to_safe_cycles\": %lld,\n"
			"  \"nonfinite_outputs\": %llu,\n"
			"  \"phase_error_ns\": %lld,\n",
			S.faults_injected, (unsigned long long)S.faults_popped,
			(unsigned long long)checked, (long long)worst,
			(unsigned long long)S.nonfinite_outputs,
			(long long)S.phase_error_ns);
	}
	json_campaign(f);
	fprintf(f,
		"  \"allocations_after_setup\": %llu,\n"
		"  \"allocations_setup\": %llu,\n"
		"  \"allocation_counter\": \"%s\",\n"
		"  \"telemetry_records\": %llu,\n  \"telemetry_dropped\": %llu,\n"
		"  \"telemetry_decimation\": %lld,\n"
		"  \"realtime\": %d,\n  \"csv\": ",
		(unsigned long long)S.allocations_after_setup,
		(unsigned long long)T.setup_heap_calls, counter,
		(unsigned long long)S.telemetry_records,
		(unsigned long long)S.telemetry_dropped, (long long)S.decimation,
		st->realtime);
	if (S.csv_path[0])
		json_string(f, S.csv_path);
	else
		fputs("null", f);
	fputs(",\n  \"plots\": [", f);
	json_string(f, time_svg);
	fputs(", ", f);
	json_string(f, lat_svg);
	fputs("]\n}\n", f);
	if (tool_out_commit(&out) != 0) {
		snprintf(T.out_why, sizeof(T.out_why), "%s", out.why);
		return -1;
	}
	return 0;
}

/* The telemetry CSV (S.csv_path, checked by validate()): its header now,
 * rows as the ring drains, renamed into place by close_csv(). Returns 0
 * or 1 (said why). */
static int open_csv(void)
{
	if (!S.csv_path[0])
		return 0;
	if (tool_out_open(&T.csv_out, S.csv_path) != 0) {
		fprintf(stderr, "proxima-run: %s\n", T.csv_out.why);
		return 1;
	}
	T.csv_f = T.csv_out.f;
	fprintf(T.csv_f,
		"t_s,cycle,x_m,y_m,z_m,proxy_x_m,proxy_y_m,proxy_z_m,"
		"fx_n,fy_n,fz_n,force_n,distance_m,penetration_m,"
		"contact,safe,wakeup_latency_ns,compute_ns,queries");
	if (S.avoiding) {
		/* distance_m is the clearance; x..z the closest link
		 * point, proxy_* the obstacle point */
		int j;
		fprintf(T.csv_f, ",speed_scale");
		for (j = 0; j < S.record_joints; j++)
			fprintf(T.csv_f, ",qdot%d_rad_per_s", j);
	}
	fputc('\n', T.csv_f);
	return 0;
}

/* The CSV complete: in place under its name (said why when not). */
static void close_csv(void)
{
	if (!T.csv_f)
		return;
	T.csv_f = NULL;
	if (tool_out_commit(&T.csv_out) != 0)
		fprintf(stderr, "proxima-run: %s\n", T.csv_out.why);
}


static void print_campaign(void)
{
	size_t i;
	if (!S.n_reactions)
		return;
	printf("  fault campaign    (loop faults from each window's start to "
	       "its end + device timeout)\n");
	for (i = 0; i < S.n_reactions; i++) {
		const struct px_app_reaction *r = &S.reactions[i];
		printf("    %-9s %-8s %7.3f..%7.3f s p %.2f: %4llu loop faults, ",
		       r->kind, r->device, (double)r->start_ns * 1e-9,
		       (double)(r->start_ns + r->duration_ns) * 1e-9, r->probability,
		       (unsigned long long)r->loop_faults);
		if (r->safe_after_ns >= 0)
			printf("safe state after %.1f ms\n", (double)r->safe_after_ns * 1e-6);
		else
			printf("no safe state (samples stayed fresh)\n");
	}
}

static void json_campaign(FILE *f)
{
	size_t i;
	fputs("  \"fault_campaign\": [", f);
	for (i = 0; i < S.n_reactions; i++) {
		const struct px_app_reaction *r = &S.reactions[i];
		fprintf(f, "%s\n    {\"kind\": \"%s\", \"device\": ", i ? "," : "",
			r->kind);
		json_string(f, r->device);
		fprintf(f,
			", \"start_ns\": %lld, \"duration_ns\": %lld, "
			"\"loop_faults\": %llu, \"safe_after_ns\": %lld}",
			(long long)r->start_ns, (long long)r->duration_ns,
			(unsigned long long)r->loop_faults,
			(long long)r->safe_after_ns);
	}
	fputs(S.n_reactions ? "\n  ],\n" : "],\n", f);
}

static void print_summary(const struct px_loop_status *st,
			  const struct px_stats_snapshot *lat,
			  const struct px_stats_snapshot *cmp, double wall_s)
{
	int k;
	printf("proxima-run: %s (%s clock)\n", O.config,
	       O.virtual_time ? "virtual" : "monotonic");
	printf("  cycles            %llu in %.3f s simulated, %.3f s wall "
	       "(%.0f cycles/s)\n",
	       (unsigned long long)st->cycles,
	       (double)st->cycles * (double)st->period_ns * 1e-9, wall_s,
	       wall_s > 0 ? (double)st->cycles / wall_s : 0.0);
	printf("  time              loop clock %.3f s (%llu missed period%s), "
	       "wall %.3f s; ",
	       loop_time_s(st), (unsigned long long)st->missed_periods,
	       st->missed_periods == 1 ? "" : "s", wall_s);
	if (O.duration_s > 0)
		printf("--duration-s %g: ended by %s\n", O.duration_s,
		       ended_by(st));
	else
		printf("until stopped: ended by %s\n", ended_by(st));
	printf("  overruns          %llu (missed periods %llu)%s\n",
	       (unsigned long long)st->overruns,
	       (unsigned long long)st->missed_periods,
	       O.virtual_time ? ""
	       : st->realtime   ? " on SCHED_FIFO"
				: " (not real-time scheduled)");
	printf("  wake-up latency   p50 %.1f us, p99 %.1f us, p99.9 %.1f us, "
	       "max %.1f us\n",
	       lat->p50_ns / 1e3, lat->p99_ns / 1e3, lat->p999_ns / 1e3,
	       lat->max_ns / 1e3);
	printf("  compute           p50 %.1f us, p99 %.1f us, p99.9 %.1f us, "
	       "max %.1f us\n",
	       cmp->p50_ns / 1e3, cmp->p99_ns / 1e3, cmp->p999_ns / 1e3,
	       cmp->max_ns / 1e3);
	if (S.rendering)
		printf("  force             max %.3f N (clamp %.3f N), contact "
		       "in %.1f %% of cycles\n",
		       S.max_force_n, S.force_clamp_n,
		       st->cycles ? 100.0 * (double)S.contact_cycles /
					    (double)st->cycles
				  : 0.0);
	if (S.avoiding)
		printf("  avoidance         min clearance %.1f mm (protective %.1f "
		       "mm, influence %.1f mm), speed scale min %.2f, nominal "
		       "motion stopped in %llu cycles\n",
		       json_num(S.min_clearance_m) * 1e3,
		       S.protective_distance_m * 1e3,
		       S.influence_distance_m * 1e3, S.min_speed_scale,
		       (unsigned long long)S.stop_cycles);
	else if (S.distance_reported)
		printf("  distance          min %+.3f mm, max penetration %.3f mm, "
	       "proxy min clearance %+.3f mm\n",
	       json_num(S.min_distance_m) * 1e3, S.max_penetration_m * 1e3,
	       json_num(S.min_proxy_distance_m) * 1e3);
	printf("  safe state        %llu trip%s",
	       (unsigned long long)st->safe_entries,
	       st->safe_entries == 1 ? "" : "s");
	for (k = 1; k < PX_FAULT__COUNT; k++)
		if (S.faults_by_cause[k])
			printf(", %s %llu", px_fault_cause_name(k),
			       (unsigned long long)S.faults_by_cause[k]);
	if (S.velocity_trips)
		printf(", velocity limit %llu", (unsigned long long)S.velocity_trips);
	if (S.query_errors)
		printf(", query errors %llu (last: %s)",
		       (unsigned long long)S.query_errors,
		       px_strerror(S.last_query_error));
	if (S.estop_lines)
		printf("\n  e-stop            %llu press%s, held %llu cycles%s",
		       (unsigned long long)S.estop_presses,
		       S.estop_presses == 1 ? "" : "es",
		       (unsigned long long)S.estop_cycles,
		       st->safe ? "; in safe state at the end" : "");
	if (px_app_canopen(A)) {
		int i, n = 0;
		for (i = 0; i < S.n_drives; i++) {
			struct px_canopen_drive_status ds;
			if (px_canopen_drive_status(px_app_canopen(A), (size_t)i,
						    &ds) == PX_OK &&
			    ds.state == PX_CIA402_OPERATION_ENABLED)
				n++;
		}
		printf("\n  drives            %d on '%s', enabled in %llu cycles, "
		       "%d in operation enabled at the end",
		       S.n_drives, S.drives_device, (unsigned long long)S.drives_enabled_cycles,
		       n);
	}
	if (S.tracking_enabled) {
		struct px_model_stream_stats ts = S.tracking;
		int ns = S.tracking_streams;
		double q = ts.queries ? (double)ts.queries : 1.0;
		printf("\n  tracking          %d stream%s: %llu answers, %.1f %% "
		       "tracked (%.1f %% hot), %.1f %% global, %.1f %% cold, "
		       "%llu jumps, %llu verified, %llu disagreements",
		       ns, ns == 1 ? "" : "s", (unsigned long long)ts.queries,
		       100.0 * (double)ts.tracked / q, 100.0 * (double)ts.hot / q,
		       100.0 * (double)ts.global / q, 100.0 * (double)ts.cold / q,
		       (unsigned long long)ts.jumps,
		       (unsigned long long)ts.verifications,
		       (unsigned long long)ts.disagreements);
	}
	if (!px_alloc_count_thread)
		printf("\n  allocations       not counted (no heap counter: "
		       "preload libproxima-alloc-count.so)\n");
	else
		printf("\n  allocations       %llu after setup (loop thread; "
		       "setup made %llu)\n",
		       (unsigned long long)S.allocations_after_setup,
		       (unsigned long long)T.setup_heap_calls);
	printf("  telemetry         %llu records (every %lld cycles), %llu "
	       "dropped\n",
	       (unsigned long long)S.telemetry_records, (long long)S.decimation,
	       (unsigned long long)S.telemetry_dropped);
	shutdown_line(stdout, "  shutdown          ");
	print_campaign();
}

/* Parse --fault KIND,DEVICE,START_S,DURATION_S[,PROBABILITY[,DELAY_S]]
 * into f. Returns NULL or why not. */
int main(int argc, char **argv)
{
	static struct px_config_diag diag;
	const char *counter = heap_counter_name();
	struct px_loop_status st;
	struct px_stats_snapshot lat, cmp;
	char time_svg[1100], lat_svg[1100], msg[256];
	int64_t wall0;
	double wall_s;
	int rc = parse_args(argc, argv, &O);
	if (rc)
		return rc == 1 ? 0 : rc;
	/* from here on a signal ends the run through the safe state */
	install_signals();
	rc = px_config_load_file(O.config, &CFG, &diag);
	if (rc != PX_OK) {
		int n = px_config_diag_total(&diag);
		px_config_diag_print(&diag, stderr);
		if (n == 0)
			fprintf(stderr, "%s: %s\n", O.config, px_strerror(rc));
		fprintf(stderr, "%s: invalid configuration (%d error%s)\n",
			O.config, n, n == 1 ? "" : "s");
		return 1;
	}
	O.name = "proxima-run";
	O.note = on_note;
	O.heap_count = heap_count;
	O.output_check = out_check;
	O.input_protect = in_protect;
	O.tick = on_tick;
	O.record = on_record;
	O.at_cycle = on_stop_cycle;
	O.stop_at_cycle = stop_at_cycle(&stop_sig);
	O.alloc_probe = getenv("PX_RUN_ALLOC_PROBE") &&
			strcmp(getenv("PX_RUN_ALLOC_PROBE"), "1") == 0;
	rc = px_app_create(CFG, &O, &A, msg, sizeof(msg));
	if (rc != PX_OK) {
		px_config_free(CFG);
		return rc == PX_E_INVAL ? 2 : 1;
	}
	px_app_summary(A, &S); /* what the app is: outputs, mode */
	if (O.check) {
		printf("%s: OK (%zu device%s, loop period %lld ns)\n", O.config,
		       CFG->n_devices, CFG->n_devices == 1 ? "" : "s",
		       (long long)CFG->loop.period_ns);
		finish();
		return 0;
	}
	if (open_csv()) {
		finish();
		return 1;
	}
	T.setup_heap_calls = heap_count();
	px_app_warnings(A);
	fprintf(stderr,
		"proxima-run: %s: %zu scene model%s, %d device%s, %s, %s clock, "
		"%s\n",
		O.config, S.scene_models,
		S.scene_models == 1 ? "" : "s",
		(int)CFG->n_devices, CFG->n_devices == 1 ? "" : "s",
		S.rendering ? (S.proxy_renderer
				       ? "haptic proxy rendering"
				       : "haptic penalty rendering")
		: S.avoiding ? "collision avoidance over CANopen"
			     : "no control output",
		O.virtual_time ? "virtual" : "real-time",
		S.max_cycles ? "fixed duration" : "until Ctrl-C");
	wall0 = mono_ns();
	if (interrupted)
		px_app_stop(A); /* a signal during setup: straight to shutdown */
	status_every_ns = isatty(2) ? 250000000 : 1000000000;
	memset(&meter, 0, sizeof(meter));
	meter.t_ns = mono_ns();
	rc = px_app_run(A);
	wall_s = (double)(mono_ns() - wall0) * 1e-9;
	{
		/* the loop has stopped: zero force, relays off, drives
		 * disabled, before the summary (which reports it) and
		 * before anything closes */
		char why[32];
		if (stop_signal)
			signal_reason(stop_signal, why, sizeof(why));
		else
			snprintf(why, sizeof(why), "%s",
				 rc < 0 ? "loop error" : "end of run");
		px_app_shutdown(A, why);
	}
	px_app_drain(A, on_record, NULL);
	{
		struct px_loop_status s0;
		px_loop_status(px_app_loop(A), &s0);
		status_line(1, wall_s,
			    wall_s > 0 ? (double)s0.cycles / wall_s : 0.0);
	}
	close_csv();
	px_app_summary(A, &S);
	px_loop_status(px_app_loop(A), &st);
	px_loop_stats(px_app_loop(A), PX_LOOP_STAT_LATENCY, &lat);
	px_stats_read(px_app_compute_stats(A), &cmp);
	print_summary(&st, &lat, &cmp, wall_s);
	plot_paths(time_svg, lat_svg, sizeof(time_svg));
	if (S.csv_path[0])
		printf("  csv               %s\n", S.csv_path);
	if (write_plots(time_svg, lat_svg) == 0)
		printf("  plots             %s\n                    %s\n", time_svg,
		       lat_svg);
	else
		fprintf(stderr, "proxima-run: cannot write the plots: %s\n",
			tool_svg_error());
	if (O.summary_json) {
		if (write_json(O.summary_json, &st, &lat, &cmp, wall_s, time_svg,
			       lat_svg, counter) == 0)
			printf("  summary           %s\n", O.summary_json);
		else
			fprintf(stderr, "proxima-run: %s\n", T.out_why);
	}
	if (rc < 0)
		fprintf(stderr, "proxima-run: the loop stopped: %s\n",
			px_strerror(rc));
	if (!S.shutdown_safe)
		shutdown_line(stderr, "proxima-run: shutdown: ");
	{
		int safe = S.shutdown_safe;
		finish();
		return rc < 0 || !safe ? 1 : 0;
	}
}
