/*
 * run_plots.c - proxima-run's SVG plots (run_internal.h): the records'
 * time series and the histograms of wake-up latency and compute time.
 */
#include <stdlib.h>

#include "run_internal.h"
#include "tool_svg.h"

/* Clearance and protective distance, speed scale, commanded joint
 * velocities (x, d, f, pen: n + 1 values each, filled here). */
static int plot_avoidance(const struct run_result *r, const char *path,
			  double *x, double *d, double *f, double *pen)
{
	static const char *const colors[PX_APP_RECORD_JOINTS] = {
		"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd",
		"#8c564b"};
	static const char *const names[PX_APP_RECORD_JOINTS] = {
		"joint 0", "joint 1", "joint 2", "joint 3", "joint 4",
		"joint 5"};
	size_t n = r->n_recs, i;
	double *qd[PX_APP_RECORD_JOINTS] = {0};
	struct tool_svg_series sq[PX_APP_RECORD_JOINTS];
	struct tool_svg_series sd[] = {{"clearance", d, "#1f77b4"},
				       {"protective", pen, "#d62728"}};
	struct tool_svg_series ss[] = {{"speed scale", f, "#2ca02c"}};
	struct tool_svg_panel p[] = {{"clearance (mm)", sd, 2},
				     {"speed scale", ss, 1},
				     {"commanded velocity (rad/s)", sq, 0}};
	int j, nj = r->sum->record_joints, ok = 1, rc = -1;
	for (j = 0; j < nj; j++) {
		qd[j] = calloc(n + 1, sizeof(double));
		ok = ok && qd[j];
		sq[j].name = names[j];
		sq[j].y = qd[j];
		sq[j].color = colors[j];
	}
	p[2].n_series = nj;
	for (i = 0; ok && i < n; i++) {
		x[i] = r->recs[i].t_s;
		d[i] = r->recs[i].distance_m * 1e3;
		pen[i] = r->sum->protective_distance_m * 1e3;
		f[i] = r->recs[i].scale;
		for (j = 0; j < nj; j++)
			qd[j][i] = r->recs[i].qdot[j];
	}
	if (ok)
		rc = tool_svg_lines(path,
				    "proxima-run: clearance, speed scale "
				    "and commanded joint velocity",
				    "time (s)", x, n, p, 3);
	for (j = 0; j < nj; j++)
		free(qd[j]);
	return rc;
}

/* Distance, force (|F| and Fz), proxy penetration. */
static int plot_haptic(const struct run_result *r, const char *path,
		       double *x, double *d, double *f, double *pen, double *fz)
{
	size_t n = r->n_recs, i;
	struct tool_svg_series sd[] = {{"distance", d, "#1f77b4"}};
	struct tool_svg_series sf[] = {{"|F|", f, "#d62728"},
				       {"Fz", fz, "#ff7f0e"}};
	struct tool_svg_series sp[] = {{"penetration", pen, "#2ca02c"}};
	struct tool_svg_panel p[] = {{"distance (mm)", sd, 1},
				     {"force (N)", sf, 2},
				     {"proxy penetration (mm)", sp, 1}};
	for (i = 0; i < n; i++) {
		x[i] = r->recs[i].t_s;
		d[i] = r->recs[i].distance_m * 1e3;
		f[i] = r->recs[i].force_mag_n;
		fz[i] = r->recs[i].force_n[2];
		pen[i] = r->recs[i].penetration_m * 1e3;
	}
	return tool_svg_lines(path,
			      "proxima-run: distance, force and proxy "
			      "penetration",
			      "time (s)", x, n, p, 3);
}

static int plot_latency(const struct run_result *r, const char *path)
{
	static uint64_t lbins[PX_STATS_DEFAULT_BINS], cbins[PX_STATS_DEFAULT_BINS];
	struct px_stats *ls = px_loop_stats_handle(px_app_loop(r->app),
						   PX_LOOP_STAT_LATENCY);
	struct px_stats *cs = px_app_compute_stats(r->app);
	uint64_t lover = 0, cover = 0;
	int nl = px_stats_copy_bins(ls, lbins, PX_STATS_DEFAULT_BINS, &lover);
	int nc = px_stats_copy_bins(cs, cbins, PX_STATS_DEFAULT_BINS, &cover);
	if (nl < 0 || nc < 0)
		return -1;
	{
		struct tool_svg_hist h[] = {
			{"wake-up latency", lbins, (size_t)nl, lover,
			 (double)px_stats_bin_ns(ls) / 1e3, "#1f77b4"},
			{"compute time", cbins, (size_t)nc, cover,
			 (double)px_stats_bin_ns(cs) / 1e3, "#9467bd"}};
		return tool_svg_histograms(path,
					   r->opt->virtual_time
						   ? "proxima-run: latency (virtual "
						     "clock: wake-up is 0 by "
						     "construction)"
						   : "proxima-run: latency",
					   "microseconds", h, 2);
	}
}

int run_write_plots(const struct run_result *r, const char *time_svg,
		    const char *lat_svg)
{
	size_t n = r->n_recs;
	double *x = calloc(n + 1, sizeof(double));
	double *d = calloc(n + 1, sizeof(double));
	double *f = calloc(n + 1, sizeof(double));
	double *pen = calloc(n + 1, sizeof(double));
	double *fz = calloc(n + 1, sizeof(double));
	int rc = -1;
	if (x && d && f && pen && fz)
		rc = r->sum->avoiding
			     ? plot_avoidance(r, time_svg, x, d, f, pen)
			     : plot_haptic(r, time_svg, x, d, f, pen, fz);
	free(x);
	free(d);
	free(f);
	free(pen);
	free(fz);
	if (rc == 0)
		rc = plot_latency(r, lat_svg);
	return rc;
}
