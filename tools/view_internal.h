/*
 * view_internal.h - proxima-view's parts beside its main
 * (tools/view_*.c, linked into proxima-view alone): the track message
 * from a telemetry CSV and the checks of the summary JSON put beside it.
 * Offline code; everything allocates.
 */
#ifndef TOOLS_VIEW_INTERNAL_H
#define TOOLS_VIEW_INTERNAL_H

#include <stddef.h>

/* The CSV's limits: longer lines and more rows are refused. */
#define VIEW_CSV_LINE_MAX 4096
#define VIEW_CSV_ROWS_MAX 5000000
/* The summary JSON's limits: bytes and nesting. */
#define VIEW_JSON_MAX (4u << 20)
#define VIEW_JSON_DEPTH 64

/*
 * The track message {"type":"track","frames":[...],"summary":S} of the
 * telemetry CSV at path (proxima-run's columns, found by their header
 * names; t_s, cycle, x_m, y_m, z_m are required), summary the JSON text
 * of the run's summary or NULL (then null). *json malloc'd, *rows the
 * frames. Returns 0, or -1 with why ("FILE:LINE: what").
 */
int view_track_json(const char *path, const char *summary, char **json,
		    size_t *len, size_t *rows, char *why, size_t cap);

/* The whole file at path as text (at most max bytes, no NUL byte),
 * malloc'd. Returns 0, or -1 with why. */
int view_read_file(const char *path, size_t max, char **text, size_t *len,
		   char *why, size_t cap);

/* Whether text is one JSON value (RFC 8259, nesting at most
 * VIEW_JSON_DEPTH). Returns 0, or -1 with why ("offset N: what"). */
int view_json_check(const char *text, size_t len, char *why, size_t cap);

#endif
