/*
 * view_internal.h - proxima-view's parts beside its main
 * (tools/view_*.c, linked into proxima-view alone): the track message
 * from a telemetry CSV and the checks of the summary JSON put beside it.
 * Offline code; everything allocates.
 */
#ifndef TOOLS_VIEW_INTERNAL_H
#define TOOLS_VIEW_INTERNAL_H

#include <stddef.h>

#include "px_view.h"

/* The CSV's limits: longer lines and more rows are refused. */
#define VIEW_CSV_LINE_MAX 4096
#define VIEW_CSV_ROWS_MAX 5000000
/* The summary JSON's limits: bytes and nesting. */
#define VIEW_JSON_MAX (4u << 20)
#define VIEW_JSON_DEPTH 64

/* The track's inputs beside the CSV. */
struct view_track_opts {
	const char *summary;      /* the run's summary JSON text, or NULL */
	double rate_hz;           /* frames a second of loop time at most;
				   * 0: every row */
	const struct px_scene *scene;   /* the closest points, or NULL */
	const struct px_view_arm *arm;  /* links from q<j>_rad, or NULL */
};

struct view_track_info {
	size_t rows, frames;      /* of the CSV, of the track */
	int links;                /* the frames carry the arm's links */
};

/*
 * The track message {"type":"track","frames":[...],"summary":S} of the
 * telemetry CSV at path (proxima-run's columns, found by their header
 * names; t_s, cycle, x_m, y_m, z_m are required): a frame at most every
 * 1 / rate_hz of loop time, at every change of contact or safe state,
 * and the last row; with the closest point on the scene (no arm) and
 * the arm's links where the CSV has its joint positions. *json
 * malloc'd. Returns 0, or -1 with why ("FILE:LINE: what").
 */
int view_track_json(const char *path, const struct view_track_opts *opt,
		    char **json, size_t *len, struct view_track_info *info,
		    char *why, size_t cap);

/* The whole file at path as text (at most max bytes, no NUL byte),
 * malloc'd. Returns 0, or -1 with why. */
int view_read_file(const char *path, size_t max, char **text, size_t *len,
		   char *why, size_t cap);

/* Whether text is one JSON value (RFC 8259, nesting at most
 * VIEW_JSON_DEPTH). Returns 0, or -1 with why ("offset N: what"). */
int view_json_check(const char *text, size_t len, char *why, size_t cap);

#endif
