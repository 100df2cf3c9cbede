/*
 * px_file.h - whole files read with a size limit, for the library's file
 * readers (models, point and trajectory files, CAN logs).
 *
 * Every reader of a file the user names takes its bytes through
 * px_file_read(), so that no input can make it loop or grow without
 * bound: a regular file larger than the limit is refused from its size
 * (fstat) before anything is read, and a pipe or device (a FIFO,
 * /dev/zero) is refused when the running count passes the limit. Text
 * readers also refuse a NUL byte, with its line and column: a NUL can
 * neither end a line early nor make a blank one.
 *
 * Limits: PX_FILE_TEXT_MAX_BYTES (64 MiB, as the config reader's) for
 * points files and trajectories; PX_FILE_LOG_MAX_BYTES (256 MiB) for
 * candump logs replayed as a bus; PX_FILE_MODEL_MAX_BYTES (1 GiB) for
 * meshes, point clouds and OBJ models.
 *
 * Memory and real-time rules: setup only (reads, allocates); the
 * returned buffer belongs to the caller, who frees it with free().
 */
#ifndef PX_FILE_H
#define PX_FILE_H

#include <stddef.h>
#include <sys/types.h>

#include "px_base.h"

#ifdef __cplusplus
extern "C" {
#endif

#define PX_FILE_TEXT_MAX_BYTES ((size_t)64 << 20)
#define PX_FILE_LOG_MAX_BYTES ((size_t)256 << 20)
#define PX_FILE_MODEL_MAX_BYTES ((size_t)1 << 30)

/* px_file_read() flags */
#define PX_FILE_TEXT 1u /* a NUL byte is a parse error */

/*
 * Read the file at path whole, at most max_bytes bytes. On success
 * *data (malloc'ed, one NUL byte past the end) and *len (the file's
 * bytes, without that NUL) belong to the caller. On failure *data is
 * NULL and msg (msg_cap bytes; may be NULL) says what and where:
 * "<path>: cannot open: <reason>", "<path>: larger than the 64 MiB limit for <what> files",
 * "<path>:<line>:<column>: NUL byte in a text file". what names the kind
 * of file in that message ("model", "points").
 * Returns PX_OK, PX_E_INVAL (NULL argument), PX_E_NOTFOUND, PX_E_IO
 * (cannot open or read, a directory), PX_E_RANGE (over the limit),
 * PX_E_PARSE (NUL byte with PX_FILE_TEXT), PX_E_NOMEM. Setup only.
 */
PX_API int px_file_read(const char *path, size_t max_bytes, unsigned flags,
			const char *what, char **data, size_t *len, char *msg,
			size_t msg_cap);

/*
 * Line and column (both 1-based) of the first NUL byte among the len
 * bytes at data; returns 0 when there is none, 1 otherwise. A '\r' is
 * a character of its line. RT-safe (no heap), but O(len).
 */
PX_API int px_file_find_nul(const char *data, size_t len, long *line,
			    long *column);

/*
 * Next line of a NUL-terminated text at *cursor: returns its first
 * character and ends it in place at its '\n' (a '\r' before it is cut
 * too), advancing *cursor past it; NULL when the text is exhausted. A
 * last line without '\n' is a line. Setup only (writes the buffer).
 */
PX_API char *px_file_next_line(char **cursor);

/*
 * Is line (leading blanks already skipped) a header of column names
 * rather than data: text starting with a letter whose first field is
 * not wholly a number. "NaN" and "inf" are numbers (and then an error
 * as data); "x" and "nanos" are names. Returns 1 or 0.
 */
PX_API int px_file_is_header(const char *line);

/*
 * The kind of file a st_mode names, for messages: "a regular file", "a
 * directory", "a symbolic link", "a character device", "a block
 * device", "a FIFO", "a socket". A static string.
 */
PX_API const char *px_file_kind(mode_t mode);

#ifdef __cplusplus
}
#endif

#endif
