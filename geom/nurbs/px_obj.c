/*
 * px_obj.c - Wavefront OBJ loader: free-form B-spline curves and
 * surfaces, polygon faces. See px_obj.h for what is accepted.
 *
 * One pass over the text: statements are tokenised (with continuation
 * lines and comments handled in the tokeniser, so every token keeps its
 * own line and column), control points are resolved to coordinates when
 * their statement is read, and each entity is validated at its "end" so
 * that errors point at the statement holding the bad value. A final step
 * sizes one arena and builds every curve and surface into it.
 */
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "px_file.h"
#include "px_obj.h"

#define MAX_TOKEN 255

/* ---- growable arrays (setup-time) ------------------------------------- */

struct vec {
	void *p;
	size_t n, cap, elem;
};

static int vec_reserve(struct vec *v, size_t extra)
{
	size_t need, cap;
	void *q;
	if (extra > SIZE_MAX - v->n)
		return PX_E_NOMEM;
	need = v->n + extra;
	if (need <= v->cap)
		return PX_OK;
	cap = v->cap ? v->cap : 16;
	while (cap < need) {
		if (cap > SIZE_MAX / 2)
			return PX_E_NOMEM;
		cap *= 2;
	}
	if (cap > SIZE_MAX / v->elem)
		return PX_E_NOMEM;
	q = realloc(v->p, cap * v->elem);
	if (!q)
		return PX_E_NOMEM;
	v->p = q;
	v->cap = cap;
	return PX_OK;
}

static int vec_push(struct vec *v, const void *x)
{
	if (vec_reserve(v, 1))
		return PX_E_NOMEM;
	memcpy((char *)v->p + v->n * v->elem, x, v->elem);
	v->n++;
	return PX_OK;
}

#define VEC_AT(v, type, i) (((type *)(v).p)[i])

/* ---- tokens --------------------------------------------------------------- */

struct tok {
	const char *s;
	int len;
	int line, col;
};

enum { T_WORD, T_EOL, T_EOF, T_BAD };

struct lexer {
	const char *p, *end;
	const char *line_start;
	int line;
};

/* A backslash that ends its line (only blanks after it). */
static int is_continuation(const struct lexer *lx, const char *q)
{
	if (*q != '\\')
		return 0;
	for (q++; q < lx->end; q++) {
		if (*q == '\n')
			return 1;
		if (*q != ' ' && *q != '\t' && *q != '\r')
			return 0;
	}
	return 1; /* backslash at end of file */
}

static int lex(struct lexer *lx, struct tok *t)
{
	for (;;) {
		char c;
		if (lx->p >= lx->end)
			return T_EOF;
		c = *lx->p;
		if (c == ' ' || c == '\t' || c == '\r' || c == '\f' ||
		    c == '\v') {
			lx->p++;
			continue;
		}
		if (c == '\n') {
			lx->p++;
			lx->line++;
			lx->line_start = lx->p;
			return T_EOL;
		}
		if (c == '#') {
			while (lx->p < lx->end && *lx->p != '\n')
				lx->p++;
			continue;
		}
		if (is_continuation(lx, lx->p)) {
			while (lx->p < lx->end && *lx->p != '\n')
				lx->p++;
			if (lx->p < lx->end) {
				lx->p++;
				lx->line++;
				lx->line_start = lx->p;
			}
			continue;
		}
		t->s = lx->p;
		t->line = lx->line;
		t->col = (int)(lx->p - lx->line_start) + 1;
		if (c == '\0') {
			t->len = 1;
			return T_BAD;
		}
		while (lx->p < lx->end) {
			c = *lx->p;
			if (c == ' ' || c == '\t' || c == '\r' || c == '\n' ||
			    c == '\f' || c == '\v' || c == '#' || c == '\0' ||
			    is_continuation(lx, lx->p))
				break;
			lx->p++;
		}
		if (lx->p - t->s > MAX_TOKEN) {
			t->len = MAX_TOKEN + 1;
			return T_BAD;
		}
		t->len = (int)(lx->p - t->s);
		return T_WORD;
	}
}

/* ---- parser state --------------------------------------------------------- */

struct ent_rec {
	int kind, line, col, rat, deg[2];
	int deg_line, deg_col;
	double range[4];
	size_t ctrl_off, ctrl_count; /* into xyz/w pools (and ref places) */
	size_t knot_off[2];
	int knot_count[2]; /* -1: no parm statement yet */
	char name[64];
};

struct place {
	int line, col;
};

/* A trim or hole statement: its surface (index into ents) and curves
 * (tcs[first .. first + n - 1]). */
struct loop_rec {
	size_t ent;
	int hole, line, col;
	size_t first, n;
};

struct ctx {
	const char *name;
	struct px_obj_error *err;
	struct lexer lx;
	struct vec toks;   /* struct tok, current statement */
	struct vec verts;  /* double[4] per vertex */
	struct vec xyz;    /* double[3] per control point */
	struct vec wts;    /* double per control point */
	struct vec cplace; /* struct place per control point */
	struct vec knots;  /* double */
	struct vec kplace; /* struct place per knot */
	struct vec tris;   /* int[3] */
	struct vec ents;   /* struct ent_rec */
	struct vec vps;    /* double[3] per parameter vertex (u, v, w) */
	struct vec c2;     /* size_t: the ents index of each finished curv2 */
	struct vec loops;  /* struct loop_rec */
	struct vec tcs;    /* struct px_obj_trim_curve */
	int have_cstype, rat, deg[2], ndeg, deg_line, deg_col;
	int in_body;       /* index + 1 of the open entity, 0 if none */
	char oname[64]; /* name of the last o or g statement */
};

static int failv(struct ctx *c, int line, int col, int code, const char *fmt,
		 va_list ap)
{
	struct px_obj_error *e = c->err;
	if (e) {
		e->code = code;
		e->line = line;
		e->column = col;
		vsnprintf(e->msg, sizeof(e->msg), fmt, ap);
	}
	return code;
}

static int fail_at(struct ctx *c, int line, int col, int code,
		   const char *fmt, ...) __attribute__((format(printf, 5, 6)));
static int fail_at(struct ctx *c, int line, int col, int code,
		   const char *fmt, ...)
{
	va_list ap;
	int rc;
	va_start(ap, fmt);
	rc = failv(c, line, col, code, fmt, ap);
	va_end(ap);
	return rc;
}

static int fail(struct ctx *c, const struct tok *t, int code,
		const char *fmt, ...) __attribute__((format(printf, 4, 5)));
static int fail(struct ctx *c, const struct tok *t, int code,
		const char *fmt, ...)
{
	va_list ap;
	int rc;
	va_start(ap, fmt);
	rc = failv(c, t->line, t->col, code, fmt, ap);
	va_end(ap);
	return rc;
}

static int nomem(struct ctx *c)
{
	return fail_at(c, 0, 0, PX_E_NOMEM, "out of memory");
}

static int tok_is(const struct tok *t, const char *s)
{
	size_t n = strlen(s);
	return (size_t)t->len == n && memcmp(t->s, s, n) == 0;
}

/* Printable copy of a token for messages. */
static const char *tok_str(const struct tok *t, char *buf, size_t cap)
{
	size_t n = (size_t)t->len < cap - 1 ? (size_t)t->len : cap - 1;
	size_t i;
	for (i = 0; i < n; i++) {
		unsigned char ch = (unsigned char)t->s[i];
		buf[i] = (ch >= 32 && ch < 127) ? (char)ch : '?';
	}
	buf[n] = '\0';
	if ((size_t)t->len > n && n >= 3)
		memcpy(buf + n - 3, "...", 3);
	return buf;
}

static int tok_double(struct ctx *c, const struct tok *t, const char *what,
		      double *out)
{
	char buf[MAX_TOKEN + 1], sb[48];
	char *e;
	double x;
	memcpy(buf, t->s, (size_t)t->len);
	buf[t->len] = '\0';
	errno = 0;
	x = strtod(buf, &e);
	if (e == buf || *e != '\0')
		return fail(c, t, PX_E_PARSE, "%s: expected a number, got '%s'",
			    what, tok_str(t, sb, sizeof(sb)));
	if (!isfinite(x))
		return fail(c, t, PX_E_PARSE, "%s: number '%s' is not finite",
			    what, tok_str(t, sb, sizeof(sb)));
	*out = x;
	return PX_OK;
}

static int tok_int(struct ctx *c, const struct tok *t, const char *what,
		   int len, long *out)
{
	char buf[MAX_TOKEN + 1], sb[48];
	char *e;
	long x;
	memcpy(buf, t->s, (size_t)len);
	buf[len] = '\0';
	errno = 0;
	x = strtol(buf, &e, 10);
	if (e == buf || *e != '\0')
		return fail(c, t, PX_E_PARSE,
			    "%s: expected an integer, got '%s'", what,
			    tok_str(t, sb, sizeof(sb)));
	if (errno == ERANGE || x > INT_MAX || x < -INT_MAX)
		return fail(c, t, PX_E_PARSE, "%s: integer '%s' out of range",
			    what, tok_str(t, sb, sizeof(sb)));
	*out = x;
	return PX_OK;
}

/* Reference to the what (vertex, parameter vertex, curv2) number t
 * among nv defined so far ("v", "v/vt", "v//vn", "v/vt/vn" forms: the
 * part before the first slash): 0-based index. */
static int tok_ref(struct ctx *c, const struct tok *t, const char *what,
		   const char *whats, size_t nv, size_t *idx)
{
	char ref[48];
	long v;
	int len = 0, rc;
	while (len < t->len && t->s[len] != '/')
		len++;
	snprintf(ref, sizeof(ref), "%s reference", what);
	rc = tok_int(c, t, ref, len, &v);
	if (rc)
		return rc;
	if (v == 0)
		return fail(c, t, PX_E_PARSE,
			    "%s index 0 (OBJ indices start at 1; negative "
			    "ones count back from the last %s)",
			    what, what);
	if (v > 0) {
		if ((size_t)v > nv)
			return fail(c, t, PX_E_PARSE,
				    "%s %ld is not defined (%zu %s "
				    "so far)",
				    what, v, nv, whats);
		*idx = (size_t)v - 1;
	} else {
		if ((size_t)(-v) > nv)
			return fail(c, t, PX_E_PARSE,
				    "relative %s %ld reaches before the "
				    "first %s (%zu so far)",
				    what, v, what, nv);
		*idx = nv - (size_t)(-v);
	}
	return PX_OK;
}

/* Vertex reference: 0-based index. */
static int tok_vref(struct ctx *c, const struct tok *t, size_t *idx)
{
	return tok_ref(c, t, "vertex", "vertices", c->verts.n, idx);
}

/* Read one statement into c->toks; returns T_WORD if it has tokens,
 * T_EOF at the end of input, or an error code. */
static int read_statement(struct ctx *c)
{
	c->toks.n = 0;
	for (;;) {
		struct tok t;
		int k = lex(&c->lx, &t);
		if (k == T_EOL) {
			if (c->toks.n)
				return T_WORD;
			continue;
		}
		if (k == T_EOF)
			return c->toks.n ? T_WORD : T_EOF;
		if (k == T_BAD) {
			if (t.len > MAX_TOKEN)
				return fail(c, &t, PX_E_PARSE,
					    "token longer than %d characters",
					    MAX_TOKEN);
			return fail(c, &t, PX_E_PARSE, "NUL byte in the text");
		}
		if (vec_push(&c->toks, &t))
			return nomem(c);
	}
}

/* ---- statements ----------------------------------------------------------- */

static struct ent_rec *cur_ent(struct ctx *c)
{
	return c->in_body ? &VEC_AT(c->ents, struct ent_rec, c->in_body - 1)
			  : NULL;
}

static int st_vertex(struct ctx *c, const struct tok *tk, size_t n)
{
	double v[4] = {0, 0, 0, 1};
	size_t i, m;
	int rc;
	if (n != 4 && n != 5 && n != 7)
		return fail(c, &tk[0], PX_E_PARSE,
			    "'v' takes x y z [w] (or x y z r g b), got %zu "
			    "values",
			    n - 1);
	m = n == 7 ? 4 : n; /* colours are read for checking, then dropped */
	for (i = 1; i < n; i++) {
		double x;
		rc = tok_double(c, &tk[i], "vertex", &x);
		if (rc)
			return rc;
		if (i < m)
			v[i - 1] = x;
	}
	if (vec_reserve(&c->verts, 1))
		return nomem(c);
	memcpy((double *)c->verts.p + 4 * c->verts.n, v, sizeof(v));
	c->verts.n++;
	return PX_OK;
}

static int st_cstype(struct ctx *c, const struct tok *tk, size_t n)
{
	static const char *const other[] = {"bezier", "cardinal", "taylor",
					    "bmatrix"};
	size_t i = 1, k;
	int rat = 0;
	char sb[48];
	if (n >= 2 && tok_is(&tk[1], "rat")) {
		rat = 1;
		i = 2;
	}
	if (n != i + 1)
		return fail(c, &tk[0], PX_E_PARSE,
			    "'cstype' takes [rat] and one type");
	if (tok_is(&tk[i], "bspline")) {
		c->have_cstype = 1;
		c->rat = rat;
		return PX_OK;
	}
	for (k = 0; k < sizeof(other) / sizeof(other[0]); k++)
		if (tok_is(&tk[i], other[k]))
			return fail(c, &tk[i], PX_E_UNSUPPORTED,
				    "curve/surface type '%s' is not supported "
				    "(only [rat] bspline)",
				    other[k]);
	return fail(c, &tk[i], PX_E_PARSE, "unknown curve/surface type '%s'",
		    tok_str(&tk[i], sb, sizeof(sb)));
}

static int st_deg(struct ctx *c, const struct tok *tk, size_t n)
{
	size_t i;
	if (n != 2 && n != 3)
		return fail(c, &tk[0], PX_E_PARSE, "'deg' takes degu [degv]");
	for (i = 1; i < n; i++) {
		long d;
		int rc = tok_int(c, &tk[i], "degree", tk[i].len, &d);
		if (rc)
			return rc;
		if (d < 1 || d > PX_NURBS_MAX_DEGREE)
			return fail(c, &tk[i],
				    d > PX_NURBS_MAX_DEGREE ? PX_E_UNSUPPORTED
							    : PX_E_PARSE,
				    "degree %ld outside 1..%d", d,
				    PX_NURBS_MAX_DEGREE);
		c->deg[i - 1] = (int)d;
	}
	c->ndeg = (int)n - 1;
	c->deg_line = tk[0].line;
	c->deg_col = tk[0].col;
	return PX_OK;
}

/* curv (what 0), surf (1) or curv2 (2, over parameter vertices, no
 * range). */
static int st_element(struct ctx *c, const struct tok *tk, size_t n, int what)
{
	struct ent_rec e;
	int surf = what == 1, c2 = what == 2;
	size_t nr = surf ? 4 : (c2 ? 0 : 2), i;
	const char *kw = surf ? "surf" : (c2 ? "curv2" : "curv");
	int rc;

	if (c->in_body)
		return fail(c, &tk[0], PX_E_PARSE,
			    "'%s' inside the body of the entity of line %d "
			    "(missing 'end')",
			    kw, cur_ent(c)->line);
	if (!c->have_cstype)
		return fail(c, &tk[0], c2 ? PX_E_UNSUPPORTED : PX_E_PARSE,
			    c2 ? "'%s' before any 'cstype' statement is not "
				 "supported"
			       : "'%s' before any 'cstype' statement",
			    kw);
	if (!c->ndeg || (surf && c->ndeg < 2))
		return fail(c, &tk[0], PX_E_PARSE,
			    surf ? "'surf' needs 'deg degu degv' first"
				 : "'%s' needs 'deg degu' first", kw);
	if (n < 1 + nr + 2)
		return fail(c, &tk[0], PX_E_PARSE,
			    surf ? "'surf' takes s0 s1 t0 t1 and at least two "
				   "control points"
				 : (c2 ? "'curv2' takes at least two parameter "
					 "vertices"
				       : "'curv' takes u0 u1 and at least two "
					 "control points"));
	memset(&e, 0, sizeof(e));
	e.kind = surf ? PX_OBJ_SURF : (c2 ? PX_OBJ_CURVE2 : PX_OBJ_CURVE);
	e.line = tk[0].line;
	e.col = tk[0].col;
	e.rat = c->rat;
	e.deg[0] = c->deg[0];
	e.deg[1] = surf ? c->deg[1] : 0;
	e.deg_line = c->deg_line;
	e.deg_col = c->deg_col;
	e.knot_count[0] = e.knot_count[1] = -1;
	snprintf(e.name, sizeof(e.name), "%s", c->oname);
	for (i = 0; i < nr; i++) {
		rc = tok_double(c, &tk[1 + i], "parameter range", &e.range[i]);
		if (rc)
			return rc;
	}
	for (i = 0; i < nr; i += 2)
		if (!(e.range[i] < e.range[i + 1]))
			return fail(c, &tk[1 + i], PX_E_PARSE,
				    "empty parameter range %g..%g", e.range[i],
				    e.range[i + 1]);
	e.ctrl_off = c->wts.n;
	e.ctrl_count = n - 1 - nr;
	if (vec_reserve(&c->xyz, e.ctrl_count) ||
	    vec_reserve(&c->wts, e.ctrl_count) ||
	    vec_reserve(&c->cplace, e.ctrl_count))
		return nomem(c);
	for (i = 1 + nr; i < n; i++) {
		size_t vi;
		const double *v;
		struct place pl = {tk[i].line, tk[i].col};
		double *x = (double *)c->xyz.p + 3 * c->xyz.n;
		if (c2) {
			rc = tok_ref(c, &tk[i], "parameter vertex",
				     "parameter vertices", c->vps.n, &vi);
			if (rc)
				return rc;
			v = (const double *)c->vps.p + 3 * vi;
			x[0] = v[0];
			x[1] = v[1];
			x[2] = 0.0;
		} else {
			rc = tok_vref(c, &tk[i], &vi);
			if (rc)
				return rc;
			v = (const double *)c->verts.p + 4 * vi;
			memcpy(x, v, 3 * sizeof(double));
		}
		c->xyz.n++;
		VEC_AT(c->wts, double, c->wts.n++) = e.rat ? v[c2 ? 2 : 3] : 1.0;
		VEC_AT(c->cplace, struct place, c->cplace.n++) = pl;
	}
	if (vec_push(&c->ents, &e))
		return nomem(c);
	c->in_body = (int)c->ents.n;
	return PX_OK;
}

static int st_parm(struct ctx *c, const struct tok *tk, size_t n)
{
	struct ent_rec *e = cur_ent(c);
	int d;
	size_t i;
	if (!e)
		return fail(c, &tk[0], PX_E_PARSE,
			    "'parm' outside a curv/surf body");
	if (n < 2 || (!tok_is(&tk[1], "u") && !tok_is(&tk[1], "v")))
		return fail(c, &tk[0], PX_E_PARSE, "'parm' takes u|v and knots");
	d = tok_is(&tk[1], "v");
	if (d == 1 && e->kind != PX_OBJ_SURF)
		return fail(c, &tk[1], PX_E_PARSE,
			    "'parm v' in the body of a curve");
	if (e->knot_count[d] >= 0)
		return fail(c, &tk[0], PX_E_PARSE,
			    "second 'parm %c' for the entity of line %d",
			    d ? 'v' : 'u', e->line);
	if (n - 2 > (size_t)INT_MAX / 2)
		return fail(c, &tk[0], PX_E_PARSE, "too many knots");
	e->knot_off[d] = c->knots.n;
	e->knot_count[d] = (int)(n - 2);
	if (vec_reserve(&c->knots, n - 2) || vec_reserve(&c->kplace, n - 2))
		return nomem(c);
	for (i = 2; i < n; i++) {
		double x;
		struct place pl = {tk[i].line, tk[i].col};
		int rc = tok_double(c, &tk[i], "knot", &x);
		if (rc)
			return rc;
		VEC_AT(c->knots, double, c->knots.n++) = x;
		VEC_AT(c->kplace, struct place, c->kplace.n++) = pl;
	}
	return PX_OK;
}

/* Report a NURBS validation error at the token that holds the value. */
static int nurbs_fail(struct ctx *c, const struct ent_rec *e,
		      const struct px_nurbs_error *ne)
{
	const struct place *kp = (const struct place *)c->kplace.p;
	const struct place *cp = (const struct place *)c->cplace.p;
	int line = e->line, col = e->col;
	int code = ne->code == PX_E_NOMEM ? PX_E_NOMEM : PX_E_PARSE;
	if (c->err)
		c->err->nurbs = *ne;
	switch (ne->fault) {
	case PX_NURBS_FAULT_DEGREE:
		line = e->deg_line;
		col = e->deg_col;
		break;
	case PX_NURBS_FAULT_KNOT_NAN:
	case PX_NURBS_FAULT_KNOT_ORDER:
	case PX_NURBS_FAULT_KNOT_MULT:
	case PX_NURBS_FAULT_DOMAIN:
		if (ne->index >= 0 && ne->index < e->knot_count[ne->dir]) {
			const struct place *p = &kp[e->knot_off[ne->dir] +
						    (size_t)ne->index];
			line = p->line;
			col = p->col;
		}
		break;
	case PX_NURBS_FAULT_KNOT_COUNT:
	case PX_NURBS_FAULT_TOO_FEW:
		break; /* the curv/surf statement itself */
	case PX_NURBS_FAULT_WEIGHT:
	case PX_NURBS_FAULT_COORD_NAN:
	case PX_NURBS_FAULT_COORD_RANGE:
		if (ne->index >= 0 && (size_t)ne->index < e->ctrl_count) {
			const struct place *p = &cp[e->ctrl_off +
						    (size_t)ne->index];
			line = p->line;
			col = p->col;
		}
		break;
	default:
		break;
	}
	return fail_at(c, line, col, code, "%s of line %d: %s",
		       e->kind == PX_OBJ_SURF ? "surface" : "curve", e->line,
		       ne->msg);
}

static const double no_knots = 0.0;

static int st_end(struct ctx *c, const struct tok *tk, size_t n)
{
	struct ent_rec *e = cur_ent(c);
	struct px_nurbs_error ne;
	const double *K, *X, *W;
	int d, rc, nd;
	if (!e)
		return fail(c, &tk[0], PX_E_PARSE,
			    "'end' without an open curv/surf");
	/* Pools are non-empty here: an entity has >= 2 control points, and
	 * every knot vector was checked to exist below before use. */
	K = c->knots.p ? (const double *)c->knots.p : &no_knots;
	X = (const double *)c->xyz.p + 3 * e->ctrl_off;
	W = (const double *)c->wts.p + e->ctrl_off;
	if (n != 1)
		return fail(c, &tk[1], PX_E_PARSE, "'end' takes no arguments");
	nd = e->kind == PX_OBJ_SURF ? 2 : 1;
	for (d = 0; d < nd; d++)
		if (e->knot_count[d] < 0)
			return fail(c, &tk[0], PX_E_PARSE,
				    "%s of line %d has no 'parm %c' knot "
				    "vector",
				    nd == 2 ? "surface" : "curve", e->line,
				    d ? 'v' : 'u');
	if (e->kind != PX_OBJ_SURF) {
		int p = e->deg[0], nk = e->knot_count[0];
		int need = (int)e->ctrl_count + p + 1;
		if (nk != need)
			return fail(c, &tk[0], PX_E_PARSE,
				    "curve of line %d: 'parm u' has %d knots; "
				    "%zu control points of degree %d need %d",
				    e->line, nk, e->ctrl_count, p, need);
		rc = px_nurbs_curve_validate(p, (int)e->ctrl_count,
					     K + e->knot_off[0], nk, X, W, &ne);
	} else {
		int nu = e->knot_count[0] - e->deg[0] - 1;
		int nv = e->knot_count[1] - e->deg[1] - 1;
		if (nu < 1 || nv < 1 ||
		    (size_t)nu * (size_t)nv != e->ctrl_count)
			return fail(c, &tk[0], PX_E_PARSE,
				    "surface of line %d: %zu control points, "
				    "but the knot vectors (%d u knots, degree "
				    "%d; %d v knots, degree %d) ask for %d x %d",
				    e->line, e->ctrl_count, e->knot_count[0],
				    e->deg[0], e->knot_count[1], e->deg[1],
				    nu, nv);
		rc = px_nurbs_surf_validate(e->deg[0], e->deg[1], nu, nv,
					    K + e->knot_off[0],
					    e->knot_count[0],
					    K + e->knot_off[1],
					    e->knot_count[1], X, W, &ne);
	}
	if (rc)
		return nurbs_fail(c, e, &ne);
	if (e->kind == PX_OBJ_CURVE2) {
		/* no range: the knot domain; referable from now on */
		size_t idx = (size_t)(c->in_body - 1);
		e->range[0] = K[e->knot_off[0] + (size_t)e->deg[0]];
		e->range[1] = K[e->knot_off[0] + (size_t)(e->knot_count[0] - e->deg[0] - 1)];
		if (vec_push(&c->c2, &idx))
			return nomem(c);
	}
	for (d = 0; d < nd; d++) {
		int p = e->deg[d], nk = e->knot_count[d];
		const double *U = K + e->knot_off[d];
		double lo = U[p], hi = U[nk - p - 1];
		if (e->range[2 * d] < lo || e->range[2 * d + 1] > hi)
			return fail_at(c, e->line, e->col, PX_E_PARSE,
				       "%s range %g..%g lies outside the knot "
				       "domain %g..%g",
				       d ? "v" : (nd == 2 ? "u" : "parameter"),
				       e->range[2 * d], e->range[2 * d + 1],
				       lo, hi);
	}
	c->in_body = 0;
	return PX_OK;
}

/* "vp u [v [w]]": a parameter vertex (v 0 and w 1 when left out). */
static int st_vp(struct ctx *c, const struct tok *tk, size_t n)
{
	double v[3] = {0, 0, 1};
	size_t i;
	int rc;
	if (n < 2 || n > 4)
		return fail(c, &tk[0], PX_E_PARSE, "'vp' takes u [v [w]]");
	for (i = 1; i < n; i++) {
		rc = tok_double(c, &tk[i], "parameter vertex", &v[i - 1]);
		if (rc)
			return rc;
	}
	if (vec_reserve(&c->vps, 1))
		return nomem(c);
	memcpy((double *)c->vps.p + 3 * c->vps.n, v, sizeof(v));
	c->vps.n++;
	return PX_OK;
}

/* "trim", "hole" (kind 0, 1: loops of the open surface) or "scrv" (2:
 * a special curve, checked and not kept): triples u0 u1 curv2. */
static int st_loop(struct ctx *c, const struct tok *tk, size_t n, int kind)
{
	static const char *const kw[] = {"trim", "hole", "scrv"};
	struct ent_rec *e = cur_ent(c);
	struct loop_rec lr;
	size_t i;
	int rc;

	if (!e || e->kind != PX_OBJ_SURF)
		return fail(c, &tk[0], PX_E_UNSUPPORTED,
			    "'%s' is supported only inside a surf body",
			    kw[kind]);
	if (n < 4 || (n - 1) % 3)
		return fail(c, &tk[0], PX_E_PARSE,
			    "'%s' takes triples u0 u1 curv2 (got %zu values)",
			    kw[kind], n - 1);
	lr.ent = (size_t)(c->in_body - 1);
	lr.hole = kind == 1;
	lr.line = tk[0].line;
	lr.col = tk[0].col;
	lr.first = c->tcs.n;
	lr.n = (n - 1) / 3;
	for (i = 1; i < n; i += 3) {
		struct px_obj_trim_curve tc;
		const struct ent_rec *ce;
		size_t ci;
		rc = tok_double(c, &tk[i], "curve parameter", &tc.t0);
		if (!rc)
			rc = tok_double(c, &tk[i + 1], "curve parameter", &tc.t1);
		if (!rc)
			rc = tok_ref(c, &tk[i + 2], "curv2", "curv2 curves",
				     c->c2.n, &ci);
		if (rc)
			return rc;
		ce = &VEC_AT(c->ents, struct ent_rec, VEC_AT(c->c2, size_t, ci));
		if (tc.t0 == tc.t1 || fmin(tc.t0, tc.t1) < ce->range[0] ||
		    fmax(tc.t0, tc.t1) > ce->range[1])
			return fail(c, &tk[i], PX_E_PARSE,
				    "range %g..%g of curv2 %zu (line %d) is "
				    "empty or outside its domain %g..%g",
				    tc.t0, tc.t1, ci + 1, ce->line, ce->range[0],
				    ce->range[1]);
		tc.curv2 = (int)ci;
		if (kind < 2 && vec_push(&c->tcs, &tc))
			return nomem(c);
	}
	if (kind == 2)
		return PX_OK;
	return vec_push(&c->loops, &lr) ? nomem(c) : PX_OK;
}

/* "sp vp1 vp2 ...": special points of the open curve or surface; they
 * only guide tessellation, so they are checked and not kept. */
static int st_sp(struct ctx *c, const struct tok *tk, size_t n)
{
	size_t i, vi;
	int rc;
	if (!c->in_body)
		return fail(c, &tk[0], PX_E_UNSUPPORTED,
			    "'sp' is supported only inside a curve or surface "
			    "body");
	for (i = 1; i < n; i++) {
		rc = tok_ref(c, &tk[i], "parameter vertex",
			     "parameter vertices", c->vps.n, &vi);
		if (rc)
			return rc;
	}
	return PX_OK;
}

static int st_face(struct ctx *c, const struct tok *tk, size_t n)
{
	size_t i, first = 0, prev = 0;
	int rc;
	if (n < 4)
		return fail(c, &tk[0], PX_E_PARSE,
			    "'f' needs at least 3 vertices");
	if (c->verts.n > (size_t)INT_MAX)
		return fail(c, &tk[0], PX_E_PARSE, "too many vertices");
	for (i = 1; i < n; i++) {
		size_t vi;
		rc = tok_vref(c, &tk[i], &vi);
		if (rc)
			return rc;
		if (i == 1)
			first = vi;
		if (i >= 3) {
			int t[3] = {(int)first, (int)prev, (int)vi};
			if (vec_push(&c->tris, t))
				return nomem(c);
		}
		prev = vi;
	}
	return PX_OK;
}

static void set_name(char *dst, size_t cap, const struct tok *tk, size_t n)
{
	char sb[64];
	dst[0] = '\0';
	if (n >= 2)
		snprintf(dst, cap, "%s", tok_str(&tk[1], sb, sizeof(sb)));
}

static int statement(struct ctx *c)
{
	static const char *const ignored[] = {
		"vt",       "vn",        "s",         "mg",
		"usemtl",   "mtllib",    "maplib",    "usemap",    "bevel",
		"c_interp", "d_interp",  "lod",       "shadow_obj", "trace_obj",
		"ctech",    "stech"};
	static const char *const unsupported[] = {
		"bmat", "step", "con", "p",   "l",
		"bsp",  "bzp",  "cdc", "cdp", "res"};
	const struct tok *tk = (const struct tok *)c->toks.p;
	size_t n = c->toks.n, k;
	char sb[48];

	if (tok_is(&tk[0], "v"))
		return st_vertex(c, tk, n);
	if (tok_is(&tk[0], "f") || tok_is(&tk[0], "fo"))
		return st_face(c, tk, n);
	if (tok_is(&tk[0], "cstype"))
		return st_cstype(c, tk, n);
	if (tok_is(&tk[0], "deg"))
		return st_deg(c, tk, n);
	if (tok_is(&tk[0], "curv"))
		return st_element(c, tk, n, 0);
	if (tok_is(&tk[0], "surf"))
		return st_element(c, tk, n, 1);
	if (tok_is(&tk[0], "curv2"))
		return st_element(c, tk, n, 2);
	if (tok_is(&tk[0], "vp"))
		return st_vp(c, tk, n);
	if (tok_is(&tk[0], "trim"))
		return st_loop(c, tk, n, 0);
	if (tok_is(&tk[0], "hole"))
		return st_loop(c, tk, n, 1);
	if (tok_is(&tk[0], "scrv"))
		return st_loop(c, tk, n, 2);
	if (tok_is(&tk[0], "sp"))
		return st_sp(c, tk, n);
	if (tok_is(&tk[0], "parm"))
		return st_parm(c, tk, n);
	if (tok_is(&tk[0], "end"))
		return st_end(c, tk, n);
	if (tok_is(&tk[0], "o") || tok_is(&tk[0], "g")) {
		set_name(c->oname, sizeof(c->oname), tk, n);
		return PX_OK;
	}
	for (k = 0; k < sizeof(ignored) / sizeof(ignored[0]); k++)
		if (tok_is(&tk[0], ignored[k]))
			return PX_OK;
	for (k = 0; k < sizeof(unsupported) / sizeof(unsupported[0]); k++)
		if (tok_is(&tk[0], unsupported[k]))
			return fail(c, &tk[0], PX_E_UNSUPPORTED,
				    "statement '%s' is not supported",
				    unsupported[k]);
	return fail(c, &tk[0], PX_E_PARSE, "unknown statement '%s'",
		    tok_str(&tk[0], sb, sizeof(sb)));
}

/* ---- building the model --------------------------------------------------- */

static int same_domain(const double *U, int p, int nk, const double *r)
{
	return r[0] == U[p] && r[1] == U[nk - p - 1];
}

/* Arena bytes of entity e (0 when too large to count), and the
 * extraction scratch it needs into *scratch when larger. */
static size_t entity_bytes(const struct ent_rec *e, const double *K,
			   size_t *scratch)
{
	int d, nd = e->kind == PX_OBJ_SURF ? 2 : 1, n[2] = {1, 1}, narrow = 0;
	size_t b, s = 0;

	for (d = 0; d < nd; d++) {
		const double *U = K + e->knot_off[d];
		int p = e->deg[d], nk = e->knot_count[d];
		n[d] = nk - p - 1;
		if (!same_domain(U, p, nk, e->range + 2 * d))
			narrow = 1;
	}
	if (narrow) {
		/* count_inside + p + 1 <= n + p */
		for (d = 0; d < nd; d++)
			n[d] += e->deg[d];
	}
	if (e->kind != PX_OBJ_SURF) {
		b = px_nurbs_curve_bytes(e->deg[0], n[0]);
		if (narrow)
			s = PX_NURBS_CURVE_WORK_LEN(e->deg[0], n[0]);
	} else {
		b = px_nurbs_surf_bytes(e->deg[0], e->deg[1], n[0], n[1]);
		if (narrow)
			s = PX_NURBS_SURF_WORK_LEN(e->deg[0], e->deg[1], n[0], n[1]);
	}
	if (narrow) {
		s = s * sizeof(double) + PX_ARENA_ALIGN;
		*scratch = s > *scratch ? s : *scratch;
	}
	return b;
}

/* Arena size: every final entity plus the largest extraction scratch
 * (given back after each extraction). */
static int arena_bytes(struct ctx *c, size_t *bytes)
{
	const struct ent_rec *E = (const struct ent_rec *)c->ents.p;
	const double *K = (const double *)c->knots.p;
	size_t scratch = 0, i;

	*bytes = 0;
	for (i = 0; i < c->ents.n; i++) {
		size_t b = entity_bytes(&E[i], K, &scratch);
		if (!b || b > SIZE_MAX / 2 - *bytes)
			return fail_at(c, E[i].line, E[i].col, PX_E_NOMEM,
				       "entity too large");
		*bytes += b;
	}
	if (scratch > SIZE_MAX / 2 - *bytes)
		return nomem(c);
	*bytes += scratch;
	return PX_OK;
}

/* The model with its arena of bytes, the entity array, and the
 * vertices and triangles copied. */
static int model_alloc(struct ctx *c, size_t bytes, struct px_obj_model **out)
{
	struct px_obj_model *m = calloc(1, sizeof(*m));
	size_t i;

	if (!m)
		return nomem(c);
	m->memory_bytes = sizeof(*m) + bytes;
	if (bytes && px_arena_init_alloc(&m->arena_, bytes)) {
		free(m);
		return nomem(c);
	}
	if (c->ents.n) {
		m->entities = calloc(c->ents.n, sizeof(*m->entities));
		m->memory_bytes += c->ents.n * sizeof(*m->entities);
	}
	if (c->verts.n) {
		m->vertices = malloc(c->verts.n * 3 * sizeof(double));
		m->memory_bytes += c->verts.n * 3 * sizeof(double);
	}
	if (c->tris.n) {
		m->triangles = malloc(c->tris.n * 3 * sizeof(int));
		m->memory_bytes += c->tris.n * 3 * sizeof(int);
	}
	if ((c->ents.n && !m->entities) || (c->verts.n && !m->vertices) ||
	    (c->tris.n && !m->triangles)) {
		px_obj_free(m);
		return nomem(c);
	}
	for (i = 0; i < c->verts.n; i++)
		memcpy(m->vertices + 3 * i, (const double *)c->verts.p + 4 * i,
		       3 * sizeof(double));
	m->n_vertices = (int)c->verts.n;
	if (c->tris.n)
		memcpy(m->triangles, c->tris.p, c->tris.n * 3 * sizeof(int));
	m->n_triangles = (int)c->tris.n;
	*out = m;
	return PX_OK;
}

/* Curve entity e into o (in the model's arena a): as given, or the
 * declared range extracted from the whole curve built in tmp. */
static int build_curve(const struct ent_rec *e, const double *K,
		       const double *X, const double *W, struct px_arena *a,
		       struct px_arena *tmp, struct px_obj_entity *o)
{
	const double *Uu = K + e->knot_off[0];
	int pu = e->deg[0], nku = e->knot_count[0], rc;
	struct px_nurbs_curve full;

	if (same_domain(Uu, pu, nku, e->range))
		return px_nurbs_curve_init(&o->curve, a, pu, (int)e->ctrl_count,
					   Uu, nku, X, W, NULL);
	rc = px_arena_init_alloc(tmp, px_nurbs_curve_bytes(pu, (int)e->ctrl_count));
	if (!rc)
		rc = px_nurbs_curve_init(&full, tmp, pu, (int)e->ctrl_count, Uu,
					 nku, X, W, NULL);
	if (!rc)
		rc = px_nurbs_curve_extract(&full, e->range[0], e->range[1], a,
					    &o->curve);
	return rc;
}

/* The same for a surface entity. */
static int build_surf(const struct ent_rec *e, const double *K,
		      const double *X, const double *W, struct px_arena *a,
		      struct px_arena *tmp, struct px_obj_entity *o)
{
	const double *Uu = K + e->knot_off[0], *Uv = K + e->knot_off[1];
	int pu = e->deg[0], nku = e->knot_count[0];
	int pv = e->deg[1], nkv = e->knot_count[1];
	int nu = nku - pu - 1, nv = nkv - pv - 1, rc;
	struct px_nurbs_surf full;

	if (same_domain(Uu, pu, nku, e->range) &&
	    same_domain(Uv, pv, nkv, e->range + 2))
		return px_nurbs_surf_init(&o->surf, a, pu, pv, nu, nv, Uu, nku,
					  Uv, nkv, X, W, NULL);
	rc = px_arena_init_alloc(tmp, px_nurbs_surf_bytes(pu, pv, nu, nv));
	if (!rc)
		rc = px_nurbs_surf_init(&full, tmp, pu, pv, nu, nv, Uu, nku, Uv,
					nkv, X, W, NULL);
	if (!rc)
		rc = px_nurbs_surf_extract(&full, e->range[0], e->range[1],
					   e->range[2], e->range[3], a, &o->surf);
	return rc;
}

static int build_entity(struct ctx *c, const struct ent_rec *e,
			struct px_obj_model *m, struct px_obj_entity *o)
{
	const double *K = (const double *)c->knots.p;
	const double *X = (const double *)c->xyz.p + 3 * e->ctrl_off;
	const double *W = (const double *)c->wts.p + e->ctrl_off;
	struct px_arena tmp;
	int rc;

	o->kind = (enum px_obj_kind)e->kind;
	o->line = e->line;
	o->rational = e->rat;
	memcpy(o->range, e->range, sizeof(o->range));
	memcpy(o->name, e->name, sizeof(o->name));
	memset(&tmp, 0, sizeof(tmp));
	if (e->kind != PX_OBJ_SURF)
		rc = build_curve(e, K, X, W, &m->arena_, &tmp, o);
	else
		rc = build_surf(e, K, X, W, &m->arena_, &tmp, o);
	px_arena_fini(&tmp);
	if (rc)
		rc = fail_at(c, e->line, e->col,
			     rc == PX_E_NOMEM ? PX_E_NOMEM : PX_E_STATE,
			     "cannot build the entity: %s", px_strerror(rc));
	return rc;
}

/* The trimming tables: curv2 curves, loops (their surfaces renumbered
 * as model entities through map) and loop curves. */
static int trim_alloc(struct ctx *c, struct px_obj_model *m)
{
	size_t n2 = c->c2.n, nl = c->loops.n, nt = c->tcs.n;
	m->curv2 = n2 ? calloc(n2, sizeof(*m->curv2)) : NULL;
	m->loops = nl ? calloc(nl, sizeof(*m->loops)) : NULL;
	m->trim_curves = nt ? malloc(nt * sizeof(*m->trim_curves)) : NULL;
	m->memory_bytes += n2 * sizeof(*m->curv2) + nl * sizeof(*m->loops) +
			   nt * sizeof(*m->trim_curves);
	if ((n2 && !m->curv2) || (nl && !m->loops) || (nt && !m->trim_curves))
		return nomem(c);
	if (nt)
		memcpy(m->trim_curves, c->tcs.p, nt * sizeof(*m->trim_curves));
	m->n_trim_curves = (int)nt;
	return PX_OK;
}

static int build(struct ctx *c, struct px_obj_model **out)
{
	const struct ent_rec *E = (const struct ent_rec *)c->ents.p;
	struct px_obj_model *m = NULL;
	size_t bytes, i, *map;
	int rc;

	rc = arena_bytes(c, &bytes);
	if (!rc)
		rc = model_alloc(c, bytes, &m);
	if (rc)
		return rc;
	map = calloc(c->ents.n + 1, sizeof(*map));
	rc = map ? trim_alloc(c, m) : nomem(c);
	for (i = 0; i < c->ents.n && !rc; i++) {
		if (E[i].kind == PX_OBJ_CURVE2) {
			map[i] = (size_t)m->n_curv2;
			rc = build_entity(c, &E[i], m, &m->curv2[m->n_curv2++]);
		} else {
			map[i] = (size_t)m->n_entities;
			rc = build_entity(c, &E[i], m, &m->entities[m->n_entities++]);
		}
	}
	for (i = 0; i < c->loops.n && !rc; i++) {
		const struct loop_rec *lr = &VEC_AT(c->loops, struct loop_rec, i);
		struct px_obj_loop *l = &m->loops[m->n_loops++];
		l->entity = (int)map[lr->ent];
		l->hole = lr->hole;
		l->line = lr->line;
		l->column = lr->col;
		l->first = (int)lr->first;
		l->n = (int)lr->n;
	}
	free(map);
	if (rc) {
		px_obj_free(m);
		return rc;
	}
	*out = m;
	return PX_OK;
}

static void ctx_free(struct ctx *c)
{
	free(c->toks.p);
	free(c->verts.p);
	free(c->xyz.p);
	free(c->wts.p);
	free(c->cplace.p);
	free(c->knots.p);
	free(c->kplace.p);
	free(c->tris.p);
	free(c->ents.p);
	free(c->vps.p);
	free(c->c2.p);
	free(c->loops.p);
	free(c->tcs.p);
}

static void err_init(struct px_obj_error *err, const char *name)
{
	if (!err)
		return;
	memset(err, 0, sizeof(*err));
	snprintf(err->file, sizeof(err->file), "%s", name ? name : "(memory)");
}

int px_obj_load_mem(const char *name, const char *data, size_t len,
		    struct px_obj_model **out, struct px_obj_error *err)
{
	struct ctx c;
	int rc;

	err_init(err, name);
	if (out)
		*out = NULL;
	if (!out || (!data && len)) {
		if (err) {
			err->code = PX_E_INVAL;
			snprintf(err->msg, sizeof(err->msg),
				 "NULL output or data");
		}
		return PX_E_INVAL;
	}
	memset(&c, 0, sizeof(c));
	c.name = name;
	c.err = err;
	c.lx.p = data ? data : "";
	c.lx.end = c.lx.p + len;
	c.lx.line_start = c.lx.p;
	c.lx.line = 1;
	c.toks.elem = sizeof(struct tok);
	c.verts.elem = 4 * sizeof(double);
	c.xyz.elem = 3 * sizeof(double);
	c.wts.elem = sizeof(double);
	c.cplace.elem = sizeof(struct place);
	c.knots.elem = sizeof(double);
	c.kplace.elem = sizeof(struct place);
	c.tris.elem = 3 * sizeof(int);
	c.ents.elem = sizeof(struct ent_rec);
	c.vps.elem = 3 * sizeof(double);
	c.c2.elem = sizeof(size_t);
	c.loops.elem = sizeof(struct loop_rec);
	c.tcs.elem = sizeof(struct px_obj_trim_curve);

	for (;;) {
		rc = read_statement(&c);
		if (rc == T_EOF) {
			rc = PX_OK;
			break;
		}
		if (rc < 0)
			break;
		rc = statement(&c);
		if (rc)
			break;
	}
	if (!rc && c.in_body) {
		const struct ent_rec *e = cur_ent(&c);
		rc = fail_at(&c, e->line, e->col, PX_E_PARSE,
			     "%s of line %d has no 'end' before the end of "
			     "the file",
			     e->kind == PX_OBJ_SURF ? "surf"
						    : (e->kind == PX_OBJ_CURVE2 ? "curv2" : "curv"),
			     e->line);
	}
	if (!rc && (c.verts.n > (size_t)INT_MAX || c.tris.n > (size_t)INT_MAX ||
		    c.ents.n > (size_t)INT_MAX || c.tcs.n > (size_t)INT_MAX))
		rc = fail_at(&c, 0, 0, PX_E_PARSE, "too many elements");
	if (!rc)
		rc = build(&c, out);
	ctx_free(&c);
	return rc;
}

int px_obj_load_file(const char *path, struct px_obj_model **out,
		     struct px_obj_error *err)
{
	char *buf = NULL, msg[sizeof(err->msg) + 512];
	size_t len = 0;
	int rc;

	err_init(err, path);
	if (out)
		*out = NULL;
	if (!path || !out) {
		if (err) {
			err->code = PX_E_INVAL;
			snprintf(err->msg, sizeof(err->msg), "NULL path or output");
		}
		return PX_E_INVAL;
	}
	/* the model limit and the NUL check as bytes arrive: /dev/zero stops
	 * at its first read instead of filling the memory */
	rc = px_file_read(path, PX_FILE_MODEL_MAX_BYTES, PX_FILE_TEXT, "model",
			  &buf, &len, msg, sizeof msg);
	/* a missing file stays PX_E_IO, as this function has always said */
	if (rc == PX_E_NOTFOUND)
		rc = PX_E_IO;
	if (rc != PX_OK) {
		if (err) {
			size_t np = strlen(path);
			long ln = 0, col = 0;
			const char *why = msg;
			err->code = rc;
			/* "<path>:<line>:<column>: ..." or "<path>: ..." */
			if (strncmp(msg, path, np) == 0) {
				why = msg + np;
				if (rc == PX_E_PARSE &&
				    sscanf(why, ":%ld:%ld:", &ln, &col) == 2 &&
				    ln > 0 && ln <= INT_MAX && col <= INT_MAX) {
					err->line = (int)ln;
					err->column = (int)col;
					why = strstr(why, ": ");
					why = why ? why : msg + np;
				}
				while (*why == ':' || *why == ' ')
					why++;
			}
			snprintf(err->msg, sizeof(err->msg), "%.255s", why);
		}
		return rc;
	}
	rc = px_obj_load_mem(path, buf, len, out, err);
	free(buf);
	return rc;
}

void px_obj_free(struct px_obj_model *m)
{
	if (!m)
		return;
	px_arena_fini(&m->arena_);
	free(m->entities);
	free(m->curv2);
	free(m->loops);
	free(m->trim_curves);
	free(m->vertices);
	free(m->triangles);
	free(m);
}

const char *px_obj_error_text(const struct px_obj_error *err, const char *path,
			      int rc, char *buf, size_t cap)
{
	if (!buf || !cap)
		return buf;
	if (err && err->line > 0)
		snprintf(buf, cap, "%s:%d:%d: %s", err->file, err->line, err->column,
			 err->msg);
	else
		snprintf(buf, cap, "%s: %s", path ? path : "",
			 err && err->msg[0] ? err->msg : px_strerror(rc));
	return buf;
}
