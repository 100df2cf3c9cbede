/*
 * px_file.c - whole files read with a size limit (see px_file.h).
 */
#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "px_file.h"

static void say(char *msg, size_t cap, const char *path, const char *text)
{
	if (msg && cap)
		snprintf(msg, cap, "%s: %s", path, text);
}

/* "64 MiB", "1 GiB" or a byte count, for the limit's message. */
static void size_text(size_t n, char *buf, size_t cap)
{
	if (n >= ((size_t)1 << 30) && n % ((size_t)1 << 30) == 0)
		snprintf(buf, cap, "%zu GiB", n >> 30);
	else if (n >= ((size_t)1 << 20) && n % ((size_t)1 << 20) == 0)
		snprintf(buf, cap, "%zu MiB", n >> 20);
	else
		snprintf(buf, cap, "%zu-byte", n);
}

static int too_big(const char *path, size_t max_bytes, const char *what,
		   char *msg, size_t cap)
{
	char lim[32];
	size_text(max_bytes, lim, sizeof lim);
	if (msg && cap)
		snprintf(msg, cap, "%s: larger than the %s limit for %s files",
			 path, lim, what ? what : "input");
	return PX_E_RANGE;
}

int px_file_find_nul(const char *data, size_t len, long *line, long *column)
{
	const char *z = data ? memchr(data, '\0', len) : NULL;
	const char *p, *start = data;
	long ln = 1;
	if (!z)
		return 0;
	for (p = data; p < z; p++)
		if (*p == '\n') {
			ln++;
			start = p + 1;
		}
	if (line)
		*line = ln;
	if (column)
		*column = (long)(z - start) + 1;
	return 1;
}

int px_file_read(const char *path, size_t max_bytes, unsigned flags,
		 const char *what, char **data, size_t *len, char *msg,
		 size_t msg_cap)
{
	struct stat st;
	char *buf = NULL;
	size_t n = 0, cap;
	int fd, rc = PX_OK;

	if (msg && msg_cap)
		msg[0] = '\0';
	if (data)
		*data = NULL;
	if (len)
		*len = 0;
	if (!path || !data || !len) {
		if (msg && msg_cap)
			snprintf(msg, msg_cap, "invalid arguments");
		return PX_E_INVAL;
	}
	fd = open(path, O_RDONLY | O_CLOEXEC);
	if (fd < 0) {
		int e = errno;
		if (msg && msg_cap)
			snprintf(msg, msg_cap, "%s: cannot open: %s", path, strerror(e));
		return e == ENOENT ? PX_E_NOTFOUND : PX_E_IO;
	}
	if (fstat(fd, &st) != 0) {
		say(msg, msg_cap, path, strerror(errno));
		close(fd);
		return PX_E_IO;
	}
	if (S_ISDIR(st.st_mode)) {
		say(msg, msg_cap, path, "is a directory");
		close(fd);
		return PX_E_IO;
	}
	/* a regular file is judged by its size before a byte is read; any
	 * other (pipe, device) by the running count below */
	if (S_ISREG(st.st_mode) && (unsigned long long)st.st_size > max_bytes) {
		close(fd);
		return too_big(path, max_bytes, what, msg, msg_cap);
	}
	cap = S_ISREG(st.st_mode) ? (size_t)st.st_size + 1 : 65536;
	if (cap > max_bytes + 1)
		cap = max_bytes + 1;
	for (;;) {
		ssize_t got;
		if (n == cap) {
			char *q;
			if (cap > max_bytes) {
				rc = too_big(path, max_bytes, what, msg, msg_cap);
				break;
			}
			cap = cap > (max_bytes + 1) / 2 ? max_bytes + 1 : 2 * cap;
			q = realloc(buf, cap);
			if (!q) {
				say(msg, msg_cap, path, "out of memory while reading");
				rc = PX_E_NOMEM;
				break;
			}
			buf = q;
		} else if (!buf) {
			buf = malloc(cap);
			if (!buf) {
				say(msg, msg_cap, path, "out of memory while reading");
				rc = PX_E_NOMEM;
				break;
			}
		}
		got = read(fd, buf + n, cap - n);
		if (got < 0) {
			if (errno == EINTR)
				continue;
			say(msg, msg_cap, path, strerror(errno));
			rc = PX_E_IO;
			break;
		}
		if (got == 0)
			break;
		/* NUL checked as it arrives: /dev/zero stops at its first read */
		if ((flags & PX_FILE_TEXT) && memchr(buf + n, '\0', (size_t)got)) {
			long ln = 0, col = 0;
			px_file_find_nul(buf, n + (size_t)got, &ln, &col);
			if (msg && msg_cap)
				snprintf(msg, msg_cap, "%s:%ld:%ld: NUL byte in a text file",
					 path, ln, col);
			rc = PX_E_PARSE;
			break;
		}
		n += (size_t)got;
		if (n > max_bytes) {
			rc = too_big(path, max_bytes, what, msg, msg_cap);
			break;
		}
	}
	close(fd);
	if (rc == PX_OK && n == cap) {
		/* room for the closing NUL */
		char *q = realloc(buf, n + 1);
		if (!q) {
			say(msg, msg_cap, path, "out of memory while reading");
			rc = PX_E_NOMEM;
		} else {
			buf = q;
		}
	}
	if (rc != PX_OK) {
		free(buf);
		return rc;
	}
	if (!buf) {
		buf = malloc(1);
		if (!buf) {
			say(msg, msg_cap, path, "out of memory while reading");
			return PX_E_NOMEM;
		}
	}
	buf[n] = '\0';
	*data = buf;
	*len = n;
	return PX_OK;
}

char *px_file_next_line(char **cursor)
{
	char *s, *nl;
	if (!cursor || !*cursor || !**cursor)
		return NULL;
	s = *cursor;
	nl = strchr(s, '\n');
	if (nl) {
		*cursor = nl + 1;
		if (nl > s && nl[-1] == '\r')
			nl[-1] = '\0';
		*nl = '\0';
	} else {
		*cursor = s + strlen(s);
		if (*cursor > s && (*cursor)[-1] == '\r')
			(*cursor)[-1] = '\0';
	}
	return s;
}

int px_file_is_header(const char *line)
{
	char *end;
	if (!line || !isalpha((unsigned char)*line))
		return 0;
	strtod(line, &end);
	while (*end == ' ' || *end == '\t')
		end++;
	return end == line || (*end != ',' && *end != '\0');
}

const char *px_file_kind(mode_t m)
{
	return S_ISREG(m)    ? "a regular file"
	       : S_ISDIR(m)  ? "a directory"
	       : S_ISLNK(m)  ? "a symbolic link"
	       : S_ISCHR(m)  ? "a character device"
	       : S_ISBLK(m)  ? "a block device"
	       : S_ISFIFO(m) ? "a FIFO"
	       : S_ISSOCK(m) ? "a socket"
			     : "an unknown kind of file";
}
