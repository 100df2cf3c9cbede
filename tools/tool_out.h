/*
 * tool_out.h - output files of the tools (telemetry CSV, summary JSON,
 * plots), made so that a path can never be turned against the machine.
 *
 * An output is written to a new temporary file in the target's directory
 * (created with O_CREAT | O_EXCL | O_NOFOLLOW, mode 0644 less the umask)
 * and renamed over the target when complete. rename() replaces a
 * symbolic link itself, never the file it points to, so a link planted
 * at an output path (or at a plot name derived from one) cannot make a
 * tool running as root overwrite another file; a reader never sees a
 * half-written output under its final name. Refused with a message
 * naming the path: a target that exists and is not a regular file or a
 * symbolic link (a directory, a device, a FIFO, a socket), and a target
 * that is, or links to, a file registered with tool_out_protect() (the
 * config and the input files it names), compared by device and inode.
 *
 * Setup/offline code: allocates nothing, does file I/O; not for a cycle.
 * The protected list is process-wide (up to TOOL_OUT_MAX_PROTECTED
 * files) and not thread-safe: fill it at setup, from one thread.
 */
#ifndef TOOL_OUT_H
#define TOOL_OUT_H

#include <stddef.h>
#include <stdio.h>

#define TOOL_OUT_PATH_MAX 4096
#define TOOL_OUT_WHY_MAX (2 * TOOL_OUT_PATH_MAX + 512)
#define TOOL_OUT_MAX_PROTECTED 256

struct tool_out {
	FILE *f;                      /* write through this while open */
	char path[TOOL_OUT_PATH_MAX]; /* the target */
	char tmp[TOOL_OUT_PATH_MAX];  /* the temporary file beside it */
	char why[TOOL_OUT_WHY_MAX];   /* after a failure: what and why */
};

/*
 * Register an input file no output may replace; what names it in
 * messages ("the config file", "an input file"; a string literal, kept).
 * A path that does not exist is ignored (nothing to protect). Returns 0,
 * or -1 when the list is full.
 */
int tool_out_protect(const char *path, const char *what);

/*
 * Whether path can be an output, without creating anything: the checks
 * tool_out_open() makes, for a tool to refuse before a long run rather
 * than after it (the directory must exist). Returns 0, or -1 with why
 * (cap bytes) naming the path and the reason.
 */
int tool_out_check(const char *path, char *why, size_t cap);

/*
 * Check path (tool_out_check()) and create its temporary file; o->f is
 * then open for writing. Returns 0, or -1 with o->why set and errno
 * (EEXIST, EISDIR, EINVAL for a refused target, or the system's).
 */
int tool_out_open(struct tool_out *o, const char *path);

/*
 * Finish: flush and close o->f and rename the temporary file over the
 * target (checked again first: it may have changed meanwhile). On any
 * failure the temporary file is removed and the target left as it was.
 * Returns 0, or -1 with o->why and errno.
 */
int tool_out_commit(struct tool_out *o);

/* Give up an open output: close o->f, remove the temporary file, leave
 * the target as it was. A closed or zeroed o is a no-op. */
void tool_out_discard(struct tool_out *o);

#endif
