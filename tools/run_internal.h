/*
 * run_internal.h - proxima-run's parts beside its main (tools/run_*.c,
 * linked into proxima-run alone): the printed summary (run_report.c), the
 * --summary-json writer (run_json.c) and the SVG plots (run_plots.c).
 *
 * Each reads the run as struct run_result once the loop has stopped and
 * the app has made its outputs safe (px_app_shutdown) and has been
 * drained. Their text is proxima-run's contract: every line and JSON
 * field stays as it is (tests/tools/test_run_golden.sh compares them).
 * Non-real-time; the plots allocate their series.
 */
#ifndef RUN_INTERNAL_H
#define RUN_INTERNAL_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "px_app.h"
#include "px_loop.h"
#include "px_stats.h"

/* The run as the reports see it. */
struct run_result {
	struct px_app *app;
	const struct px_app_options *opt; /* the arguments */
	const struct px_app_summary *sum; /* px_app_summary() after the run */
	struct px_loop_status st;
	struct px_stats_snapshot lat, cmp; /* wake-up latency, compute time */
	double wall_s;                     /* the run's real time */
	int interrupted;                   /* a signal ended it */
	int counted;                       /* a heap counter is loaded */
	const char *counter;               /* its name, "none" without */
	uint64_t setup_heap_calls;
	/* the records the plots keep (the first ones of the run) */
	const struct px_app_record *recs;
	size_t n_recs;
};

/* A figure for the reports: a non-finite value (no distance seen) is 0. */
static inline double run_finite(double v)
{
	return isfinite(v) ? v : 0.0;
}

/* What ended the run: "cycles" (--duration-s worth of cycles run),
 * "time" (real clock: --duration-s of loop time gone, periods missed),
 * "signal", or "stop" (the loop stopped: an error, a phase). */
const char *run_ended_by(const struct run_result *r);

/* prefix and px_app_shutdown_describe()'s line, to f. */
void run_shutdown_line(struct px_app *app, FILE *f, const char *prefix);

/* The summary on stdout, from the first line to the fault campaign. */
void run_print_summary(const struct run_result *r);

/* The summary as JSON at path (through tools/tool_out.h), naming the
 * plots. Returns 0, or -1 with why (cap bytes). */
int run_write_json(const struct run_result *r, const char *path,
		   const char *time_svg, const char *lat_svg, char *why,
		   size_t cap);

/* The time-series plot (distance, force, penetration; or clearance,
 * speed scale, joint velocities when avoiding) and the latency
 * histograms. Returns 0, or -1 (tool_svg_error() says why). */
int run_write_plots(const struct run_result *r, const char *time_svg,
		    const char *lat_svg);

/* The DDS bridge (run_bridge.c), all on the draining thread: read the
 * config's bridge section (errors printed; 0 or 1), start it when
 * enabled (0, or 1 said why), hand it each drained record and, from the
 * tick, the loop's status; stop prints what it published. */
int run_bridge_read(const struct px_config *cfg, const char *path);
int run_bridge_start(struct px_app *app, int avoiding);
void run_bridge_record(const struct px_app_record *r);
void run_bridge_tick(void);
void run_bridge_stop(void);

/* The browser view (run_view.c), on the draining thread too: start the server for --view SPEC (NULL: none)
 * with the page of root (NULL: the built one beside the program), saying
 * its URL on stderr, or why not and going on without it; feed it each
 * drained record; stop sends "end" and says what it sent. */
void run_view_start(struct px_app *app, const char *name, const char *spec,
		    const char *root, int64_t period_ns);
void run_view_record(const struct px_app_record *r);
void run_view_stop(void);

#endif
