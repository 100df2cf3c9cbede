/* Output files created beside their target and renamed over it: no
 * final symbolic link followed, no input file overwritten. */
#include "tool_out.h"

#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "px_file.h"

struct protected_file {
	dev_t dev;
	ino_t ino;
	const char *what;
	char path[512];
};

static struct protected_file prot[TOOL_OUT_MAX_PROTECTED];
static int n_prot;

int tool_out_protect(const char *path, const char *what)
{
	struct stat st;
	int i;
	if (!path || stat(path, &st) != 0)
		return 0;
	for (i = 0; i < n_prot; i++)
		if (prot[i].dev == st.st_dev && prot[i].ino == st.st_ino)
			return 0;
	if (n_prot == TOOL_OUT_MAX_PROTECTED)
		return -1;
	prot[n_prot].dev = st.st_dev;
	prot[n_prot].ino = st.st_ino;
	prot[n_prot].what = what ? what : "an input file";
	snprintf(prot[n_prot].path, sizeof(prot[n_prot].path), "%s", path);
	n_prot++;
	return 0;
}

static const struct protected_file *find_protected(const struct stat *st)
{
	int i;
	for (i = 0; i < n_prot; i++)
		if (prot[i].dev == st->st_dev && prot[i].ino == st->st_ino)
			return &prot[i];
	return NULL;
}

/* The directory part of path ("." for a bare name). 0 or -1. */
static int dir_of(const char *path, char *dir, size_t cap)
{
	const char *slash = strrchr(path, '/');
	int n;
	if (!slash)
		n = snprintf(dir, cap, ".");
	else if (slash == path)
		n = snprintf(dir, cap, "/");
	else
		n = snprintf(dir, cap, "%.*s", (int)(slash - path), path);
	return n < 0 || (size_t)n >= cap ? -1 : 0;
}

/* Say why (the message names the path) and fail with errno err. */
static int refuse(char *why, size_t cap, int err, const char *fmt, ...)
	__attribute__((format(printf, 4, 5)));
static int refuse(char *why, size_t cap, int err, const char *fmt, ...)
{
	va_list ap;
	if (why && cap) {
		va_start(ap, fmt);
		vsnprintf(why, cap, fmt, ap);
		va_end(ap);
	}
	errno = err;
	return -1;
}

int tool_out_check(const char *path, char *why, size_t cap)
{
	struct stat ls, st;
	char dir[TOOL_OUT_PATH_MAX];
	const struct protected_file *p;
	if (!path || !*path)
		return refuse(why, cap, EINVAL, "empty output file name");
	if (strlen(path) >= TOOL_OUT_PATH_MAX - 64)
		return refuse(why, cap, ENAMETOOLONG, "%.200s...: file name "
			      "too long", path);
	if (lstat(path, &ls) == 0) {
		if (S_ISLNK(ls.st_mode)) {
			/* the link itself would be replaced, its target
			 * never written; one that points at an input is
			 * still refused: the user meant something else */
			if (stat(path, &st) == 0 && (p = find_protected(&st)))
				return refuse(why, cap, EINVAL,
					      "%s is a symbolic link to %s %s: "
					      "refusing to write an output there",
					      path, p->what, p->path);
		} else if (!S_ISREG(ls.st_mode)) {
			return refuse(why, cap, EINVAL,
				      "%s exists and is %s, not a regular file: "
				      "refusing to replace it",
				      path, px_file_kind(ls.st_mode));
		} else if ((p = find_protected(&ls))) {
			return refuse(why, cap, EINVAL,
				      "%s is %s %s (the same file): refusing to "
				      "write an output over it",
				      path, p->what, p->path);
		}
	} else if (errno != ENOENT) {
		int e = errno;
		return refuse(why, cap, e, "%s: %s", path, strerror(e));
	}
	if (dir_of(path, dir, sizeof(dir)) != 0)
		return refuse(why, cap, ENAMETOOLONG, "%s: file name too long",
			      path);
	if (stat(dir, &st) != 0) {
		int e = errno;
		return refuse(why, cap, e, "%s: directory %s: %s", path, dir,
			      strerror(e));
	}
	if (!S_ISDIR(st.st_mode))
		return refuse(why, cap, ENOTDIR, "%s: %s is not a directory",
			      path, dir);
	return 0;
}

int tool_out_open(struct tool_out *o, const char *path)
{
	char dir[TOOL_OUT_PATH_MAX];
	const char *base;
	int fd = -1, k;
	memset(o, 0, sizeof(*o));
	if (tool_out_check(path, o->why, sizeof(o->why)) != 0)
		return -1;
	snprintf(o->path, sizeof(o->path), "%s", path);
	dir_of(path, dir, sizeof(dir));
	base = strrchr(path, '/');
	base = base ? base + 1 : path;
	/* a fresh name each try: O_EXCL refuses anything already there,
	 * a symbolic link included */
	for (k = 0; k < 100 && fd < 0; k++) {
		int n = snprintf(o->tmp, sizeof(o->tmp), "%s/.%s.%ld-%d.tmp", dir,
				 base, (long)getpid(), k);
		if (n < 0 || (size_t)n >= sizeof(o->tmp)) {
			errno = ENAMETOOLONG;
			break;
		}
		fd = open(o->tmp, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW |
					  O_CLOEXEC,
			  0644);
		if (fd < 0 && errno != EEXIST)
			break;
	}
	if (fd < 0) {
		int e = errno;
		snprintf(o->why, sizeof(o->why), "%s: cannot create a file in %s: "
			 "%s", path, dir, strerror(e));
		o->tmp[0] = '\0';
		errno = e;
		return -1;
	}
	o->f = fdopen(fd, "w");
	if (!o->f) {
		int e = errno;
		close(fd);
		unlink(o->tmp);
		o->tmp[0] = '\0';
		snprintf(o->why, sizeof(o->why), "%s: %s", path, strerror(e));
		errno = e;
		return -1;
	}
	return 0;
}

int tool_out_commit(struct tool_out *o)
{
	int e = 0;
	if (!o->f) {
		snprintf(o->why, sizeof(o->why), "%s: not open", o->path);
		errno = EINVAL;
		return -1;
	}
	if (fflush(o->f) != 0 || ferror(o->f))
		e = errno ? errno : EIO;
	if (fclose(o->f) != 0 && !e)
		e = errno;
	o->f = NULL;
	if (e) {
		snprintf(o->why, sizeof(o->why), "%s: %s", o->path, strerror(e));
	} else if (tool_out_check(o->path, o->why, sizeof(o->why)) != 0) {
		e = errno; /* the target changed while the file was written */
	} else if (rename(o->tmp, o->path) != 0) {
		e = errno;
		snprintf(o->why, sizeof(o->why), "%s: %s", o->path, strerror(e));
	} else {
		o->tmp[0] = '\0';
		return 0;
	}
	unlink(o->tmp);
	o->tmp[0] = '\0';
	errno = e;
	return -1;
}

void tool_out_discard(struct tool_out *o)
{
	if (o->f)
		fclose(o->f);
	o->f = NULL;
	if (o->tmp[0])
		unlink(o->tmp);
	o->tmp[0] = '\0';
}
