/* proxima-view's inputs (view_internal.h): the telemetry CSV as the
 * track message, the summary JSON read and checked. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "px_app.h"
#include "px_view.h"
#include "view_internal.h"

/* The CSV columns a frame reads, by header name. */
enum col {
	C_T, C_CYCLE, C_X, C_Y, C_Z, C_PX, C_PY, C_PZ, C_FX, C_FY, C_FZ,
	C_DIST, C_PEN, C_CONTACT, C_SAFE, C_LAT, C_COMP, C_SCALE, C_Q0, C_Q1,
	C_Q2, C_Q3, C_Q4, C_Q5, C__N
};
static const char *const col_names[C__N] = {
	"t_s", "cycle", "x_m", "y_m", "z_m", "proxy_x_m", "proxy_y_m",
	"proxy_z_m", "fx_n", "fy_n", "fz_n", "distance_m", "penetration_m",
	"contact", "safe", "wakeup_latency_ns", "compute_ns", "speed_scale",
	"q0_rad", "q1_rad", "q2_rad", "q3_rad", "q4_rad", "q5_rad"};
_Static_assert(C__N - C_Q0 == PX_APP_RECORD_JOINTS, "a q column per record joint");
#define REQUIRED 5 /* the first five */
#define MAX_COLS 64

/* Text that grows; a failure sticks in oom. */
struct obuf {
	char *p;
	size_t n, cap;
	int oom;
};

static void put(struct obuf *o, const char *s, size_t k)
{
	if (o->oom)
		return;
	if (o->n + k + 1 > o->cap) {
		size_t c = o->cap ? o->cap : 65536;
		char *q;
		while (c < o->n + k + 1)
			c *= 2;
		q = realloc(o->p, c);
		if (!q) {
			o->oom = 1;
			return;
		}
		o->p = q;
		o->cap = c;
	}
	memcpy(o->p + o->n, s, k);
	o->n += k;
	o->p[o->n] = '\0';
}

/* Split line (modified) at commas into at most MAX_COLS fields. */
static int split(char *line, char **f)
{
	int n = 0;
	char *p = line;
	for (;;) {
		char *c = strchr(p, ',');
		if (n == MAX_COLS)
			return -1;
		f[n++] = p;
		if (!c)
			return n;
		*c = '\0';
		p = c + 1;
	}
}

/* Read one line into buf; 1 got one, 0 end, -1 too long. */
static int get_line(FILE *f, char *buf, size_t cap)
{
	size_t n;
	if (!fgets(buf, (int)cap, f))
		return 0;
	n = strlen(buf);
	if (n == cap - 1 && buf[n - 1] != '\n' && !feof(f))
		return -1;
	while (n && (buf[n - 1] == '\n' || buf[n - 1] == '\r'))
		buf[--n] = '\0';
	return 1;
}

static int number(const char *s, double *v)
{
	char *end;
	errno = 0;
	*v = strtod(s, &end);
	return end != s && *end == '\0' ? 0 : -1;
}

static int row_record(char **f, int nf, const int *idx,
		      struct px_app_record *r, const char **bad)
{
	double v[C__N];
	int c;
	memset(r, 0, sizeof(*r));
	for (c = 0; c < C__N; c++) {
		v[c] = c == C_SCALE ? 1.0 : c == C_DIST ? NAN : 0.0;
		if (idx[c] < 0)
			continue;
		if (idx[c] >= nf || number(f[idx[c]], &v[c])) {
			*bad = col_names[c];
			return -1;
		}
	}
	r->t_s = v[C_T];
	r->cycle = v[C_CYCLE] >= 0 ? (uint64_t)v[C_CYCLE] : 0;
	r->dev_m[0] = v[C_X], r->dev_m[1] = v[C_Y], r->dev_m[2] = v[C_Z];
	r->proxy_m[0] = v[C_PX], r->proxy_m[1] = v[C_PY], r->proxy_m[2] = v[C_PZ];
	r->force_n[0] = v[C_FX], r->force_n[1] = v[C_FY], r->force_n[2] = v[C_FZ];
	r->distance_m = v[C_DIST];
	r->penetration_m = v[C_PEN];
	r->contact = v[C_CONTACT] != 0;
	r->safe = v[C_SAFE] != 0;
	r->latency_ns = (int64_t)v[C_LAT];
	r->compute_ns = (int64_t)v[C_COMP];
	r->scale = v[C_SCALE];
	for (c = C_Q0; c < C__N; c++)
		r->q[c - C_Q0] = (float)v[c];
	r->valid = 1;
	return 0;
}

/* Whether row r starts a frame of the track: the first, one at most
 * every 1 / rate_hz of loop time (a clock that goes back starts again),
 * and every change of contact or safe state. */
static int keep_row(const struct px_app_record *r, const struct px_app_record *kept,
		    size_t rows, double rate_hz)
{
	return rows == 0 || !(rate_hz > 0) || r->t_s < kept->t_s ||
	       r->t_s - kept->t_s >= 0.999 / rate_hz ||
	       r->contact != kept->contact || r->safe != kept->safe;
}

/* One frame of the track, after n others. -1: too long. */
static int frame_put(struct obuf *o, const struct px_view_sources *src,
		     const struct px_app_record *r, size_t n, char *buf,
		     size_t cap)
{
	struct px_view_frame_extra x;
	int k;
	px_view_frame_fill(src, r, &x);
	k = px_view_frame_json_extra(r, &x, 0, buf, cap);
	if (k < 0)
		return -1;
	if (n)
		put(o, ",", 1);
	put(o, buf, (size_t)k);
	return 0;
}

int view_track_json(const char *path, const struct view_track_opts *opt,
		    char **json, size_t *len, struct view_track_info *info,
		    char *why, size_t cap)
{
	FILE *f = fopen(path, "r");
	char *line = malloc(VIEW_CSV_LINE_MAX + 2), *fields[MAX_COLS];
	char frame[PX_VIEW_FRAME_MAX];
	struct obuf o = {NULL, 0, 0, 0};
	struct px_app_record kept, last;
	struct px_view_sources src;
	size_t lineno = 0, *rows = &info->frames;
	int idx[C__N], nf, c, rc = -1, got, last_kept = 1;
	memset(info, 0, sizeof(*info));
	memset(&src, 0, sizeof(src));
	memset(&kept, 0, sizeof(kept));
	memset(&last, 0, sizeof(last));
	src.scene = opt->scene;
	if (!f || !line) {
		snprintf(why, cap, "%s: %s", path, f ? "out of memory" : strerror(errno));
		goto done;
	}
	got = get_line(f, line, VIEW_CSV_LINE_MAX + 2);
	lineno = 1;
	if (got <= 0 || (nf = split(line, fields)) < 0) {
		snprintf(why, cap, "%s:1: %s", path,
			 got == 0 ? "empty file, no header" : "header too long");
		goto done;
	}
	for (c = 0; c < C__N; c++) {
		int k;
		idx[c] = -1;
		for (k = 0; k < nf; k++)
			if (!strcmp(fields[k], col_names[c]))
				idx[c] = k;
		if (c < REQUIRED && idx[c] < 0) {
			snprintf(why, cap, "%s:1: no column '%s' (not a proxima-run "
					   "telemetry CSV)", path, col_names[c]);
			goto done;
		}
	}
	/* the arm's links where the CSV has every joint position it needs */
	if (opt->arm && idx[C_Q0] >= 0) {
		struct px_view_frame_extra probe;
		memset(&last, 0, sizeof(last));
		for (c = C_Q0; c < C__N; c++)
			if (idx[c] < 0)
				last.q[c - C_Q0] = NAN;
		if (px_view_arm_links(opt->arm, &last, probe.links, PX_VIEW_MAX_LINKS) > 0)
			src.arm = opt->arm;
	}
	info->links = src.arm != NULL;
	put(&o, "{\"type\":\"track\",\"frames\":[", 26);
	while ((got = get_line(f, line, VIEW_CSV_LINE_MAX + 2)) != 0) {
		struct px_app_record r;
		const char *bad = NULL;
		lineno++;
		if (got < 0) {
			snprintf(why, cap, "%s:%zu: line longer than %d bytes", path,
				 lineno, VIEW_CSV_LINE_MAX);
			goto done;
		}
		if (!line[0])
			continue;
		if (*rows == VIEW_CSV_ROWS_MAX) {
			snprintf(why, cap, "%s:%zu: more than %d rows", path, lineno,
				 VIEW_CSV_ROWS_MAX);
			goto done;
		}
		nf = split(line, fields);
		if (nf < 0 || row_record(fields, nf, idx, &r, &bad)) {
			snprintf(why, cap, "%s:%zu: %s%s%s", path, lineno,
				 bad ? "no number in column " : "too many columns",
				 bad ? bad : "", "");
			goto done;
		}
		info->rows++;
		last = r;
		last_kept = keep_row(&r, &kept, *rows, opt->rate_hz);
		if (!last_kept)
			continue;
		if (frame_put(&o, &src, &r, *rows, frame, sizeof(frame)) < 0) {
			snprintf(why, cap, "%s:%zu: frame too long", path, lineno);
			goto done;
		}
		kept = r;
		++*rows;
	}
	/* the run's last row ends the track */
	if (!last_kept) {
		if (frame_put(&o, &src, &last, *rows, frame, sizeof(frame)) < 0) {
			snprintf(why, cap, "%s:%zu: frame too long", path, lineno);
			goto done;
		}
		++*rows;
	}
	put(&o, "],\"summary\":", 12);
	if (opt->summary)
		put(&o, opt->summary, strlen(opt->summary));
	else
		put(&o, "null", 4);
	put(&o, "}", 1);
	if (o.oom) {
		snprintf(why, cap, "%s: out of memory", path);
		goto done;
	}
	*json = o.p;
	*len = o.n;
	o.p = NULL;
	rc = 0;
done:
	free(o.p);
	free(line);
	if (f)
		fclose(f);
	return rc;
}

int view_read_file(const char *path, size_t max, char **text, size_t *len,
		   char *why, size_t cap)
{
	FILE *f = fopen(path, "rb");
	char *buf;
	size_t n;
	if (!f) {
		snprintf(why, cap, "%s: %s", path, strerror(errno));
		return -1;
	}
	buf = malloc(max + 1);
	if (!buf) {
		fclose(f);
		snprintf(why, cap, "%s: out of memory", path);
		return -1;
	}
	n = fread(buf, 1, max + 1, f);
	fclose(f);
	if (n > max || memchr(buf, '\0', n)) {
		free(buf);
		snprintf(why, cap, "%s: %s", path,
			 n > max ? "larger than the limit" : "a NUL byte: not text");
		return -1;
	}
	buf[n] = '\0';
	*text = buf;
	*len = n;
	return 0;
}

/* ---- a JSON value, checked (RFC 8259) ----------------------------------- */

struct jp {
	const char *s;
	size_t n, i;
	const char *err;
};

static void ws(struct jp *p)
{
	while (p->i < p->n && strchr(" \t\r\n", p->s[p->i]))
		p->i++;
}

static int lit(struct jp *p, const char *w)
{
	size_t k = strlen(w);
	if (p->n - p->i < k || memcmp(p->s + p->i, w, k))
		return -1;
	p->i += k;
	return 0;
}

static int jstring(struct jp *p)
{
	p->i++; /* the quote */
	while (p->i < p->n) {
		unsigned char c = (unsigned char)p->s[p->i++];
		if (c == '"')
			return 0;
		if (c < 0x20)
			return -1;
		if (c == '\\') {
			if (p->i >= p->n)
				return -1;
			c = (unsigned char)p->s[p->i++];
			if (c == 'u') {
				int k;
				for (k = 0; k < 4; k++, p->i++)
					if (p->i >= p->n || !strchr("0123456789abcdefABCDEF",
								  p->s[p->i]))
						return -1;
			} else if (!strchr("\"\\/bfnrt", c)) {
				return -1;
			}
		}
	}
	return -1;
}

static int digits(struct jp *p)
{
	size_t i0 = p->i;
	while (p->i < p->n && p->s[p->i] >= '0' && p->s[p->i] <= '9')
		p->i++;
	return p->i > i0 ? 0 : -1;
}

static int jnumber(struct jp *p)
{
	if (p->s[p->i] == '-')
		p->i++;
	if (p->i < p->n && p->s[p->i] == '0')
		p->i++;
	else if (digits(p))
		return -1;
	if (p->i < p->n && p->s[p->i] == '.') {
		p->i++;
		if (digits(p))
			return -1;
	}
	if (p->i < p->n && (p->s[p->i] == 'e' || p->s[p->i] == 'E')) {
		p->i++;
		if (p->i < p->n && (p->s[p->i] == '+' || p->s[p->i] == '-'))
			p->i++;
		if (digits(p))
			return -1;
	}
	return 0;
}

static int jvalue(struct jp *p, int depth)
{
	char c;
	ws(p);
	if (p->i >= p->n)
		return -1;
	c = p->s[p->i];
	if (c == '{' || c == '[') {
		char close = c == '{' ? '}' : ']';
		if (depth >= VIEW_JSON_DEPTH) {
			p->err = "nested too deep";
			return -1;
		}
		p->i++;
		ws(p);
		if (p->i < p->n && p->s[p->i] == close) {
			p->i++;
			return 0;
		}
		for (;;) {
			if (c == '{') {
				ws(p);
				if (p->i >= p->n || p->s[p->i] != '"' || jstring(p))
					return -1;
				ws(p);
				if (p->i >= p->n || p->s[p->i++] != ':')
					return -1;
			}
			if (jvalue(p, depth + 1))
				return -1;
			ws(p);
			if (p->i >= p->n)
				return -1;
			if (p->s[p->i] == close) {
				p->i++;
				return 0;
			}
			if (p->s[p->i++] != ',')
				return -1;
		}
	}
	if (c == '"')
		return jstring(p);
	if (c == '-' || (c >= '0' && c <= '9'))
		return jnumber(p);
	return lit(p, c == 't' ? "true" : c == 'f' ? "false" : "null");
}

int view_json_check(const char *text, size_t len, char *why, size_t cap)
{
	struct jp p = {text, len, 0, NULL};
	if (jvalue(&p, 0) == 0) {
		ws(&p);
		if (p.i == p.n)
			return 0;
	}
	snprintf(why, cap, "offset %zu: %s", p.i, p.err ? p.err : "not JSON");
	return -1;
}
