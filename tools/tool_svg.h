/*
 * tool_svg.h - plain SVG charts for the tools (no plotting dependency):
 * stacked panels of line series over a shared x axis, and histograms.
 * Setup/offline code: allocates, writes files. Each file is written
 * through tool_out.h (a temporary file renamed over the target: no
 * symbolic link followed, no protected input overwritten).
 */
#ifndef TOOL_SVG_H
#define TOOL_SVG_H

#include <stddef.h>
#include <stdint.h>

struct tool_svg_series {
	const char *name;   /* legend */
	const double *y;    /* n values; non-finite ones break the line */
	const char *color;  /* CSS colour */
};

struct tool_svg_panel {
	const char *ylabel;
	const struct tool_svg_series *series;
	int n_series;
};

/*
 * Write panels stacked vertically, sharing x (n values, increasing).
 * Long series are reduced to a min/max envelope per pixel column, so
 * peaks survive. Returns 0 or -1 (errno set, tool_svg_error() says
 * why) when the file cannot be written.
 */
int tool_svg_lines(const char *path, const char *title, const char *xlabel,
		   const double *x, size_t n, const struct tool_svg_panel *p,
		   int n_panels);

struct tool_svg_hist {
	const char *name;       /* panel title */
	const uint64_t *bins;   /* counts, bin i covers [i, i+1) * bin_width */
	size_t n_bins;
	uint64_t overflow;      /* samples beyond the last bin */
	double bin_width;       /* in x units */
	const char *color;
};

/*
 * Histograms, one panel each, counts on a log scale (log10(1 + count)),
 * x from 0 to the last non-empty bin (at least 10 bins). Returns 0 or -1.
 */
int tool_svg_histograms(const char *path, const char *title,
			const char *xlabel, const struct tool_svg_hist *h,
			int n);

/* Why the last tool_svg_lines() / tool_svg_histograms() returned -1
 * (naming the file), "" before any failure. */
const char *tool_svg_error(void);

#endif
