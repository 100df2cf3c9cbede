/* Plain SVG charts: axes with round ticks, polylines, step histograms. */
#include "tool_svg.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "tool_out.h"

#define W 960.0
#define PANEL_H 220.0
#define LEFT 80.0
#define RIGHT 150.0
#define TOP 40.0
#define GAP 50.0

/* Round tick step for a range: 1, 2 or 5 times a power of ten, about
 * five ticks. */
static double tick_step(double span)
{
	double raw = span / 5, p, m;
	if (!(raw > 0))
		return 1;
	p = pow(10, floor(log10(raw)));
	m = raw / p;
	return (m < 1.5 ? 1 : m < 3.5 ? 2 : m < 7.5 ? 5 : 10) * p;
}

static void axes(FILE *f, double x0, double y0, double w, double h,
		 double xmin, double xmax, double ymin, double ymax,
		 const char *xlabel, const char *ylabel)
{
	double s, v;
	fprintf(f,
		"<rect x='%.1f' y='%.1f' width='%.1f' height='%.1f' "
		"fill='none' stroke='#444'/>\n",
		x0, y0, w, h);
	s = tick_step(xmax - xmin);
	for (v = ceil(xmin / s) * s; v <= xmax + 1e-9 * s; v += s) {
		double px = x0 + (v - xmin) / (xmax - xmin) * w;
		fprintf(f,
			"<line x1='%.1f' y1='%.1f' x2='%.1f' y2='%.1f' "
			"stroke='#ddd'/><text x='%.1f' y='%.1f' "
			"text-anchor='middle'>%g</text>\n",
			px, y0, px, y0 + h, px, y0 + h + 15,
			fabs(v) < 1e-12 * s ? 0.0 : v);
	}
	s = tick_step(ymax - ymin);
	for (v = ceil(ymin / s) * s; v <= ymax + 1e-9 * s; v += s) {
		double py = y0 + h - (v - ymin) / (ymax - ymin) * h;
		fprintf(f,
			"<line x1='%.1f' y1='%.1f' x2='%.1f' y2='%.1f' "
			"stroke='#ddd'/><text x='%.1f' y='%.1f' "
			"text-anchor='end'>%g</text>\n",
			x0, py, x0 + w, py, x0 - 5, py + 4,
			fabs(v) < 1e-12 * s ? 0.0 : v);
	}
	if (xlabel)
		fprintf(f,
			"<text x='%.1f' y='%.1f' text-anchor='middle'>%s</text>\n",
			x0 + w / 2, y0 + h + 32, xlabel);
	fprintf(f,
		"<text x='%.1f' y='%.1f' text-anchor='middle' "
		"transform='rotate(-90 %.1f %.1f)'>%s</text>\n",
		x0 - 55, y0 + h / 2, x0 - 55, y0 + h / 2, ylabel);
}

/* The file being written (one at a time) and the last failure. */
static struct tool_out out;
static char last_why[TOOL_OUT_WHY_MAX];

const char *tool_svg_error(void)
{
	return last_why;
}

static FILE *open_svg(const char *path, double h, const char *title)
{
	if (tool_out_open(&out, path) != 0) {
		snprintf(last_why, sizeof(last_why), "%s", out.why);
		return NULL;
	}
	fprintf(out.f,
		"<?xml version='1.0' encoding='UTF-8'?>\n"
		"<svg xmlns='http://www.w3.org/2000/svg' width='%.0f' "
		"height='%.0f' viewBox='0 0 %.0f %.0f' "
		"font-family='sans-serif' font-size='12'>\n"
		"<rect width='100%%' height='100%%' fill='white'/>\n"
		"<text x='%.1f' y='24' font-size='16' text-anchor='middle'>%s"
		"</text>\n",
		W, h, W, h, W / 2, title);
	return out.f;
}

static int close_svg(FILE *f)
{
	fprintf(f, "</svg>\n");
	if (tool_out_commit(&out) != 0) {
		snprintf(last_why, sizeof(last_why), "%s", out.why);
		return -1;
	}
	return 0;
}

int tool_svg_lines(const char *path, const char *title, const char *xlabel,
		   const double *x, size_t n, const struct tool_svg_panel *p,
		   int n_panels)
{
	double h = TOP + n_panels * (PANEL_H + GAP) + 10;
	double pw = W - LEFT - RIGHT;
	double xmin = n ? x[0] : 0, xmax = n ? x[n - 1] : 1;
	int k, s;
	FILE *f = open_svg(path, h, title);
	if (!f)
		return -1;
	if (!(xmax > xmin))
		xmax = xmin + 1;
	for (k = 0; k < n_panels; k++) {
		double y0 = TOP + k * (PANEL_H + GAP);
		double ymin = INFINITY, ymax = -INFINITY;
		size_t i;
		for (s = 0; s < p[k].n_series; s++)
			for (i = 0; i < n; i++) {
				double v = p[k].series[s].y[i];
				if (isfinite(v)) {
					ymin = fmin(ymin, v);
					ymax = fmax(ymax, v);
				}
			}
		if (!isfinite(ymin)) {
			ymin = 0;
			ymax = 1;
		}
		if (ymax - ymin < 1e-12 * fmax(1, fabs(ymax))) {
			ymin -= 0.5 * fmax(1e-9, fabs(ymin));
			ymax += 0.5 * fmax(1e-9, fabs(ymax));
		} else {
			double pad = 0.05 * (ymax - ymin);
			ymin -= pad;
			ymax += pad;
		}
		axes(f, LEFT, y0, pw, PANEL_H, xmin, xmax, ymin, ymax,
		     k == n_panels - 1 ? xlabel : NULL, p[k].ylabel);
		for (s = 0; s < p[k].n_series; s++) {
			const double *y = p[k].series[s].y;
			int col = -1, open = 0;
			double lo = 0, hi = 0;
			fprintf(f,
				"<text x='%.1f' y='%.1f' fill='%s'>%s</text>\n",
				LEFT + pw + 10, y0 + 16 + 16 * s,
				p[k].series[s].color, p[k].series[s].name);
			fprintf(f, "<path fill='none' stroke='%s' stroke-width='1' d='",
				p[k].series[s].color);
			/* min/max envelope per pixel column */
			for (i = 0; i <= n; i++) {
				int c = i < n ? (int)((x[i] - xmin) / (xmax - xmin) * pw)
					      : -2;
				int finite = i < n && isfinite(y[i]);
				if (col >= 0 && (c != col || !finite)) {
					double px = LEFT + col;
					double pl = y0 + PANEL_H -
						    (lo - ymin) / (ymax - ymin) * PANEL_H;
					double ph = y0 + PANEL_H -
						    (hi - ymin) / (ymax - ymin) * PANEL_H;
					fprintf(f, "%c%.1f %.2f L%.1f %.2f ",
						open ? 'L' : 'M', px, pl, px, ph);
					open = 1;
					col = -1;
				}
				if (i < n && !finite) {
					open = 0;
					continue;
				}
				if (i == n)
					break;
				if (col < 0) {
					col = c;
					lo = hi = y[i];
				} else {
					lo = fmin(lo, y[i]);
					hi = fmax(hi, y[i]);
				}
			}
			fprintf(f, "'/>\n");
		}
	}
	return close_svg(f);
}

int tool_svg_histograms(const char *path, const char *title,
			const char *xlabel, const struct tool_svg_hist *hs,
			int n)
{
	double h = TOP + n * (PANEL_H + GAP) + 10;
	double pw = W - LEFT - RIGHT;
	int k;
	FILE *f = open_svg(path, h, title);
	if (!f)
		return -1;
	for (k = 0; k < n; k++) {
		const struct tool_svg_hist *g = &hs[k];
		double y0 = TOP + k * (PANEL_H + GAP), ymax = 1, xmax;
		size_t last = 0, i;
		for (i = 0; i < g->n_bins; i++)
			if (g->bins[i]) {
				last = i;
				ymax = fmax(ymax, log10(1.0 + (double)g->bins[i]));
			}
		if (last < 9)
			last = 9;
		xmax = (double)(last + 1) * g->bin_width;
		ymax = ceil(ymax);
		axes(f, LEFT, y0, pw, PANEL_H, 0, xmax, 0, ymax, xlabel,
		     "log10(1 + count)");
		fprintf(f, "<text x='%.1f' y='%.1f' fill='%s'>%s</text>\n",
			LEFT + pw + 10, y0 + 16, g->color, g->name);
		if (g->overflow)
			fprintf(f,
				"<text x='%.1f' y='%.1f'>+%llu beyond</text>\n",
				LEFT + pw + 10, y0 + 32,
				(unsigned long long)g->overflow);
		fprintf(f,
			"<path fill='%s' fill-opacity='0.4' stroke='%s' d='M%.1f %.1f ",
			g->color, g->color, LEFT, y0 + PANEL_H);
		for (i = 0; i <= last && i < g->n_bins; i++) {
			double v = log10(1.0 + (double)g->bins[i]);
			double xa = LEFT + (double)i / (double)(last + 1) * pw;
			double xb = LEFT + (double)(i + 1) / (double)(last + 1) * pw;
			double py = y0 + PANEL_H - v / ymax * PANEL_H;
			fprintf(f, "L%.1f %.1f L%.1f %.1f ", xa, py, xb, py);
		}
		fprintf(f, "L%.1f %.1f Z'/>\n",
			LEFT + (double)(last + 1) / (double)(last + 1) * pw,
			y0 + PANEL_H);
	}
	return close_svg(f);
}
