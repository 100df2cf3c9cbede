/*
 * proxima-run - run a proxima application from its YAML config.
 *
 *   proxima-run CONFIG [--duration-s N] [--virtual-time] [--summary-json FILE]
 *                      [--telemetry FILE] [--view [ADDR:]PORT [--view-root DIR]]
 *   proxima-run --check CONFIG
 *
 * A main over the app module (app/px_app.h), which owns the setup from the
 * config, the loop's three phases and the whole safety policy (velocity
 * trip, e-stop lines, enable relay, CANopen quick stop, the safe state at
 * every exit). Here: the arguments, the signals (each that would end or
 * freeze the process - INT, TERM, HUP, QUIT, USR1, USR2, PIPE, ALRM,
 * VTALRM, PROF, XCPU, XFSZ, TSTP - ends the run like Ctrl-C through
 * px_app_stop()), the live status line on stderr, and the files: the
 * telemetry CSV from the drained records, then the summary on stdout
 * (tools/run_report.c), the SVG plots next to the CSV (run_plots.c) and
 * the JSON of --summary-json (run_json.c). Output paths are
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
#include "px_config.h"
#include "px_loop.h"
#include "px_stats.h"
#include "run_internal.h"
#include "tool_out.h"
#include "tool_svg.h"
#include "tool_view.h"

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
	"  --view [ADDR:]PORT serve the live view of the run to a browser on PORT\n"
	"                     (ADDR default 127.0.0.1; [::1]:PORT for IPv6)\n"
	"  --view-root DIR    the view's built page (default: build/view/web)\n"
	"  --help             this text\n"
	"Exit status: 0 ok, 1 invalid config or setup failure (e.g. a device\n"
	"absent), 2 usage error or --virtual-time with hardware devices.\n";

/* --view [ADDR:]PORT and --view-root DIR (NULL: none) */
static const char *view_spec, *view_root;

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
		} else if (!rest && matches(a, "--view-root")) {
			const char *v = opt_value(argc, argv, &i, "--view-root");
			if (!v || !*v)
				return usage_error("%s needs a folder", a);
			view_root = v;
		} else if (!rest && matches(a, "--view")) {
			const char *v = opt_value(argc, argv, &i, "--view");
			char addr[64];
			int port;
			if (!v || tool_view_parse(v, addr, sizeof(addr), &port))
				return usage_error("%s needs [ADDR:]PORT", a);
			view_spec = v;
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

/* The tests' counter (tests/support/px_alloc_count.c) when it is there: preloaded
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

/* The live status line on stderr: rewritten in place on a terminal, a
 * new line each time otherwise. */
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
	run_bridge_tick();
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
	run_bridge_record(r);
	run_view_record(r);
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
			if (CFG->telemetry.joint_positions)
				for (j = 0; j < S.record_joints; j++)
					fprintf(T.csv_f, ",%.9g", (double)r->q[j]);
		}
		fputc('\n', T.csv_f);
	}
}

/* Free the app (the safe state first, if it has not run), then the
 * config it reads. */
static void finish(void)
{
	run_bridge_stop();
	run_view_stop();
	tool_out_discard(&T.csv_out); /* an unfinished CSV: never in place */
	px_app_free(A);
	A = NULL;
	px_config_free(CFG);
	free(T.recs);
}

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
		/* telemetry.joint_positions: where the arm is (the view
		 * draws its links from them) */
		if (CFG->telemetry.joint_positions)
			for (j = 0; j < S.record_joints; j++)
				fprintf(T.csv_f, ",q%d_rad", j);
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

/* After the run: the summary, the CSV and plot names, the plots and the
 * JSON (the outputs are safe and the telemetry drained by now). */
static void report(double wall_s, const char *counter)
{
	static struct run_result r;
	char why[TOOL_OUT_WHY_MAX];
	r.app = A;
	r.opt = &O;
	r.sum = &S;
	px_loop_status(px_app_loop(A), &r.st);
	px_loop_stats(px_app_loop(A), PX_LOOP_STAT_LATENCY, &r.lat);
	px_stats_read(px_app_compute_stats(A), &r.cmp);
	r.wall_s = wall_s;
	r.interrupted = interrupted;
	r.counted = px_alloc_count_thread != NULL;
	r.counter = counter;
	r.setup_heap_calls = T.setup_heap_calls;
	r.recs = T.recs;
	r.n_recs = T.n_recs;
	run_print_summary(&r);
	if (S.csv_path[0])
		printf("  csv               %s\n", S.csv_path);
	if (run_write_plots(&r, S.time_svg, S.lat_svg) == 0)
		printf("  plots             %s\n                    %s\n",
		       S.time_svg, S.lat_svg);
	else
		fprintf(stderr, "proxima-run: cannot write the plots: %s\n",
			tool_svg_error());
	if (O.summary_json) {
		if (run_write_json(&r, O.summary_json, S.time_svg, S.lat_svg,
				   why, sizeof(why)) == 0)
			printf("  summary           %s\n", O.summary_json);
		else
			fprintf(stderr, "proxima-run: %s\n", why);
	}
}

/* What is about to run, on stderr. */
static void announce(void)
{
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
}

int main(int argc, char **argv)
{
	static struct px_config_diag diag;
	const char *counter = heap_counter_name();
	char msg[256];
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
	if (run_bridge_read(CFG, O.config)) {
		px_config_free(CFG);
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
	if (open_csv() || run_bridge_start(A, S.avoiding)) {
		finish();
		return 1;
	}
	run_view_start(A, O.config, view_spec, view_root, CFG->loop.period_ns);
	T.setup_heap_calls = heap_count();
	px_app_warnings(A);
	announce();
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
	report(wall_s, counter);
	if (rc < 0)
		fprintf(stderr, "proxima-run: the loop stopped: %s\n",
			px_strerror(rc));
	if (!S.shutdown_safe)
		run_shutdown_line(A, stderr, "proxima-run: shutdown: ");
	{
		int safe = S.shutdown_safe;
		finish();
		return rc < 0 || !safe ? 1 : 0;
	}
}
