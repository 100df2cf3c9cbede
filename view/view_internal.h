/*
 * view_internal.h - the view's text buffer (view_json.c), shared by the
 * JSON writers (view_json.c, view_arm.c) and the server (view_lws.c).
 */
#ifndef VIEW_INTERNAL_H
#define VIEW_INTERNAL_H

#include <stdarg.h>
#include <stddef.h>

/* Text that grows (growable) or stays in the caller's array; the first
 * failure sticks (err: PX_E_NOMEM or PX_E_NOSPC). */
struct view_buf {
	char *p;
	size_t n, cap;
	int growable, err;
};

void view_buf_fixed(struct view_buf *b, char *p, size_t cap);
void view_buf_put(struct view_buf *b, const char *s, size_t n);
void view_buf_puts(struct view_buf *b, const char *s);
void view_buf_printf(struct view_buf *b, const char *fmt, ...)
	__attribute__((format(printf, 2, 3)));
/* A JSON number (%.*g), null when not finite. */
void view_buf_num(struct view_buf *b, double v, int digits);
/* A JSON string, escaped. */
void view_buf_str(struct view_buf *b, const char *s);
/* A JSON array of the n numbers v[i] * scale. */
void view_buf_floats(struct view_buf *b, const double *v, size_t n,
		     double scale, int digits);

struct px_tess;
/* "indices":[...]} of t's triangles: the end of a model's object. */
void view_tess_indices(struct view_buf *b, const struct px_tess *t);

struct px_view_arm;
/* The arm's scene.robot object (view_arm.c). */
const char *view_arm_json(const struct px_view_arm *a, size_t *len);

#endif
