/* Schema-driven reader: fills C structs from mapping nodes. */
#include <locale.h>
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "config_internal.h"

#define MAX_SCHEMA_KEYS 128
#define MAX_NUMBER_CHARS 128

struct px_config_reader {
	struct px_config_doc *doc;
	struct px_config_diag *diag;
	const struct px_config_node *node; /* section being checked */
	char path[PX_CONFIG_PATH_LEN];
	size_t plen;
	int errors;
	int nomem;
	int bad_schema;
};

/* ---- path and errors --------------------------------------------- */

static size_t push(struct px_config_reader *r, const char *fmt, ...)
	__attribute__((format(printf, 2, 3)));

static size_t push(struct px_config_reader *r, const char *fmt, ...)
{
	size_t old = r->plen;
	va_list ap;
	int n;
	va_start(ap, fmt);
	n = vsnprintf(r->path + old, sizeof(r->path) - old, fmt, ap);
	va_end(ap);
	if (n > 0) {
		r->plen = old + (size_t)n;
		if (r->plen >= sizeof(r->path))
			r->plen = sizeof(r->path) - 1;
	}
	return old;
}

static void push_key(struct px_config_reader *r, const char *name, size_t len)
{
	char ex[96];
	px__cfg_excerpt(ex, sizeof(ex), name, len);
	push(r, "%s%s", r->plen ? "." : "", ex);
}

static void pop(struct px_config_reader *r, size_t old)
{
	r->plen = old;
	r->path[old] = '\0';
}

static void rverr(struct px_config_reader *r, const struct px_config_node *at,
		  const char *fmt, va_list ap)
{
	if (!at)
		at = r->node;
	if (!at)
		at = px_config_doc_root(r->doc);
	r->errors++;
	if (at)
		px__cfg_diag_vadd(r->diag, at->file, at->line, at->column,
				  r->path, fmt, ap);
	else
		px__cfg_diag_vadd(r->diag, r->doc->name, 1, 1, r->path, fmt, ap);
}

static void rerr(struct px_config_reader *r, const struct px_config_node *at,
		 const char *fmt, ...) __attribute__((format(printf, 3, 4)));

static void rerr(struct px_config_reader *r, const struct px_config_node *at,
		 const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	rverr(r, at, fmt, ap);
	va_end(ap);
}

void px_config_reader_error(struct px_config_reader *r,
			    const struct px_config_node *at, const char *sub,
			    const char *fmt, ...)
{
	size_t old;
	va_list ap;
	if (!r || !fmt)
		return;
	old = r->plen;
	if (sub && *sub) {
		if (sub[0] == '[')
			push(r, "%s", sub);
		else
			push_key(r, sub, strlen(sub));
	}
	va_start(ap, fmt);
	rverr(r, at, fmt, ap);
	va_end(ap);
	pop(r, old);
}

const char *px_config_reader_path(const struct px_config_reader *r)
{
	return r ? r->path : "";
}

const struct px_config_node *px_config_reader_node(const struct px_config_reader *r)
{
	return r ? r->node : NULL;
}

/* "'high'", "null", "a mapping", "the quoted string \"10\"". */
static void describe(const struct px_config_node *n, char *out, size_t cap)
{
	char ex[256];
	if (n->kind == PX_CONFIG_NODE_MAP) {
		snprintf(out, cap, "a mapping");
	} else if (n->kind == PX_CONFIG_NODE_SEQ) {
		snprintf(out, cap, "a sequence");
	} else if (px_config_node_is_null(n)) {
		snprintf(out, cap, "null");
	} else {
		px__cfg_excerpt(ex, sizeof(ex), n->str, n->len);
		if (n->quoted)
			snprintf(out, cap, "the quoted string '%s'", ex);
		else
			snprintf(out, cap, "'%s'", ex);
	}
}

/* Shortest %g form that reads back as the same double. */
static void fmt_double(char *out, size_t cap, double v)
{
	int prec;
	for (prec = 6; prec <= 17; prec++) {
		snprintf(out, cap, "%.*g", prec, v);
		if (strtod(out, NULL) == v)
			return;
	}
}

static void names_list(const char *const *names, char *out, size_t cap)
{
	size_t o = 0;
	int i;
	out[0] = '\0';
	for (i = 0; names && names[i]; i++) {
		int n = snprintf(out + o, cap - o, "%s%s", i ? ", " : "",
				 names[i]);
		if (n < 0 || (size_t)n >= cap - o)
			break;
		o += (size_t)n;
	}
}

/* ---- numbers ----------------------------------------------------- */

static int digit_val(char c, int base)
{
	int v;
	if (c >= '0' && c <= '9')
		v = c - '0';
	else if (c >= 'a' && c <= 'f')
		v = c - 'a' + 10;
	else if (c >= 'A' && c <= 'F')
		v = c - 'A' + 10;
	else
		return -1;
	return v < base ? v : -1;
}

enum { NUM_OK = 0, NUM_SYNTAX = -1, NUM_OVERFLOW = -2, NUM_LEADING0 = -3 };

/* [+-] (0x hex | decimal), '_' only between digits. */
static int parse_i64(const char *s, size_t len, int64_t *out)
{
	size_t i = 0;
	int neg = 0, base = 10, ndig = 0, prev_us = 0;
	uint64_t v = 0, limit;
	if (i < len && (s[i] == '+' || s[i] == '-'))
		neg = s[i++] == '-';
	if (len - i >= 2 && s[i] == '0' && (s[i + 1] == 'x' || s[i + 1] == 'X')) {
		base = 16;
		i += 2;
	}
	limit = neg ? (uint64_t)INT64_MAX + 1u : (uint64_t)INT64_MAX;
	if (base == 10 && i + 1 < len && s[i] == '0' &&
	    ((s[i + 1] >= '0' && s[i + 1] <= '9') || s[i + 1] == '_'))
		return NUM_LEADING0;
	for (; i < len; i++) {
		int d;
		if (s[i] == '_') {
			if (ndig == 0 || prev_us)
				return NUM_SYNTAX;
			prev_us = 1;
			continue;
		}
		d = digit_val(s[i], base);
		if (d < 0)
			return NUM_SYNTAX;
		prev_us = 0;
		ndig++;
		if (v > (limit - (uint64_t)d) / (uint64_t)base)
			return NUM_OVERFLOW;
		v = v * (uint64_t)base + (uint64_t)d;
	}
	if (ndig == 0 || prev_us)
		return NUM_SYNTAX;
	if (neg)
		*out = v == (uint64_t)INT64_MAX + 1u ? INT64_MIN : -(int64_t)v;
	else
		*out = (int64_t)v;
	return NUM_OK;
}

static locale_t c_locale;
static pthread_once_t c_locale_once = PTHREAD_ONCE_INIT;

static void make_c_locale(void)
{
	c_locale = newlocale(LC_NUMERIC_MASK, "C", (locale_t)0);
}

/* The digits of s from i on, a '_' allowed between two of them, copied
 * without the '_' to buf at *o and counted in *mant; returns the index
 * after them. */
static size_t mantissa_digits(const char *s, size_t i, size_t len, char *buf,
			      size_t *o, int *mant)
{
	int prev_digit = 0;
	for (; i < len; i++) {
		if (s[i] >= '0' && s[i] <= '9') {
			buf[(*o)++] = s[i];
			(*mant)++;
			prev_digit = 1;
		} else if (s[i] == '_' && prev_digit && i + 1 < len &&
			   s[i + 1] >= '0' && s[i + 1] <= '9') {
			prev_digit = 0;
		} else {
			break;
		}
	}
	return i;
}

/* Decimal floating point with '_' between digits; no inf/nan/hex. */
static int parse_double(const char *s, size_t len, double *out)
{
	char buf[MAX_NUMBER_CHARS];
	size_t i = 0, o = 0;
	int mant = 0;
	char *end;
	double v;
	if (len >= sizeof(buf))
		return NUM_SYNTAX;
#define EMIT(c) (buf[o++] = (c))
	if (i < len && (s[i] == '+' || s[i] == '-'))
		EMIT(s[i++]);
	i = mantissa_digits(s, i, len, buf, &o, &mant); /* integer part */
	if (i < len && s[i] == '.') {
		EMIT(s[i++]);
		i = mantissa_digits(s, i, len, buf, &o, &mant);
	}
	if (mant == 0)
		return NUM_SYNTAX;
	if (i < len && (s[i] == 'e' || s[i] == 'E')) {
		int edig = 0;
		EMIT(s[i++]);
		if (i < len && (s[i] == '+' || s[i] == '-'))
			EMIT(s[i++]);
		for (; i < len && s[i] >= '0' && s[i] <= '9'; i++, edig++)
			EMIT(s[i]);
		if (edig == 0)
			return NUM_SYNTAX;
	}
#undef EMIT
	if (i != len)
		return NUM_SYNTAX;
	buf[o] = '\0';
	pthread_once(&c_locale_once, make_c_locale);
	v = c_locale ? strtod_l(buf, &end, c_locale) : strtod(buf, &end);
	if (*end != '\0')
		return NUM_SYNTAX;
	if (!isfinite(v))
		return NUM_OVERFLOW;
	*out = v;
	return NUM_OK;
}

static bool is_nonfinite_word(const char *s, size_t len)
{
	static const char *const words[] = {"inf", ".inf", "infinity", "nan",
					    ".nan", NULL};
	int i;
	if (len && (s[0] == '+' || s[0] == '-')) {
		s++;
		len--;
	}
	for (i = 0; words[i]; i++)
		if (strlen(words[i]) == len && strncasecmp(s, words[i], len) == 0)
			return true;
	return false;
}

/* "10ms", "1.5 N": a number with a unit written after it. */
static bool looks_like_unit_suffix(const char *s, size_t len)
{
	size_t i = 0;
	if (i < len && (s[i] == '+' || s[i] == '-'))
		i++;
	if (i >= len || !(s[i] >= '0' && s[i] <= '9'))
		return false;
	if (i + 1 < len && s[i] == '0' && (s[i + 1] == 'x' || s[i + 1] == 'X'))
		return false; /* hex, not a unit */
	while (i < len && ((s[i] >= '0' && s[i] <= '9') || s[i] == '.' ||
			   s[i] == '_'))
		i++;
	while (i < len && s[i] == ' ')
		i++;
	if (i >= len)
		return false;
	for (; i < len; i++)
		if (!((s[i] >= 'a' && s[i] <= 'z') || (s[i] >= 'A' && s[i] <= 'Z') ||
		      s[i] == '/' || s[i] == '_'))
			return false;
	return true;
}

/* ---- typed values ------------------------------------------------ */

static const char *type_name(enum px_config_type t)
{
	switch (t) {
	case PX_CONFIG_T_INT64:
		return "an integer";
	case PX_CONFIG_T_DURATION:
		return "an integer (nanoseconds)";
	case PX_CONFIG_T_DOUBLE:
		return "a number";
	case PX_CONFIG_T_BOOL:
		return "true or false";
	case PX_CONFIG_T_STRING:
		return "a string";
	case PX_CONFIG_T_ENUM:
		return "a name";
	case PX_CONFIG_T_SEQ:
		return "a sequence";
	case PX_CONFIG_T_MAP:
	case PX_CONFIG_T_SUB:
		return "a mapping";
	}
	return "a value";
}

static void wrong_type(struct px_config_reader *r, const struct px_config_node *n,
		       enum px_config_type t, const char *extra)
{
	char got[320];
	describe(n, got, sizeof(got));
	rerr(r, n, "expected %s, got %s%s", type_name(t), got, extra ? extra : "");
}

static int read_int(struct px_config_reader *r, const struct px_config_key *k,
		    enum px_config_type t, const struct px_config_node *n,
		    int64_t *dst)
{
	int64_t v;
	int rc;
	char ex[256];
	if (n->kind != PX_CONFIG_NODE_SCALAR || n->quoted ||
	    px_config_node_is_null(n)) {
		wrong_type(r, n, t, NULL);
		return -1;
	}
	px__cfg_excerpt(ex, sizeof(ex), n->str, n->len);
	rc = parse_i64(n->str, n->len, &v);
	if (rc == NUM_OVERFLOW) {
		rerr(r, n, "'%s' does not fit in a 64-bit integer", ex);
		return -1;
	}
	if (rc == NUM_LEADING0) {
		wrong_type(r, n, t, " (leading zeros are not allowed)");
		return -1;
	}
	if (rc != NUM_OK) {
		double d;
		if (looks_like_unit_suffix(n->str, n->len))
			wrong_type(r, n, t,
				   " (write the number alone: the unit is in "
				   "the key name)");
		else if (parse_double(n->str, n->len, &d) == NUM_OK)
			wrong_type(r, n, t, " (not a whole number)");
		else
			wrong_type(r, n, t, NULL);
		return -1;
	}
	if (((k->flags & PX_CONFIG_HAS_MIN) && v < k->imin) ||
	    ((k->flags & PX_CONFIG_HAS_MAX) && v > k->imax)) {
		if ((k->flags & PX_CONFIG_HAS_MIN) && (k->flags & PX_CONFIG_HAS_MAX))
			rerr(r, n, "%s is out of range [%lld, %lld]", ex,
			     (long long)k->imin, (long long)k->imax);
		else if (k->flags & PX_CONFIG_HAS_MIN)
			rerr(r, n, "%s is out of range (must be >= %lld)", ex,
			     (long long)k->imin);
		else
			rerr(r, n, "%s is out of range (must be <= %lld)", ex,
			     (long long)k->imax);
		return -1;
	}
	*dst = v;
	return 0;
}

static int read_double(struct px_config_reader *r, const struct px_config_key *k,
		       const struct px_config_node *n, double *dst)
{
	double v;
	int rc;
	char ex[256], lo[40], hi[40];
	bool bad_lo, bad_hi;
	if (n->kind != PX_CONFIG_NODE_SCALAR || n->quoted ||
	    px_config_node_is_null(n)) {
		wrong_type(r, n, PX_CONFIG_T_DOUBLE, NULL);
		return -1;
	}
	px__cfg_excerpt(ex, sizeof(ex), n->str, n->len);
	if (is_nonfinite_word(n->str, n->len)) {
		rerr(r, n, "expected a finite number, got '%s'", ex);
		return -1;
	}
	rc = parse_double(n->str, n->len, &v);
	if (rc == NUM_OVERFLOW) {
		rerr(r, n, "'%s' is beyond the range of a double", ex);
		return -1;
	}
	if (rc != NUM_OK) {
		wrong_type(r, n, PX_CONFIG_T_DOUBLE,
			   looks_like_unit_suffix(n->str, n->len)
				   ? " (write the number alone: the unit is in "
				     "the key name)"
				   : NULL);
		return -1;
	}
	bad_lo = (k->flags & PX_CONFIG_HAS_MIN) &&
		 ((k->flags & PX_CONFIG_MIN_EXCL) ? !(v > k->dmin) : v < k->dmin);
	bad_hi = (k->flags & PX_CONFIG_HAS_MAX) &&
		 ((k->flags & PX_CONFIG_MAX_EXCL) ? !(v < k->dmax) : v > k->dmax);
	if (bad_lo || bad_hi) {
		fmt_double(lo, sizeof(lo), k->dmin);
		fmt_double(hi, sizeof(hi), k->dmax);
		if ((k->flags & PX_CONFIG_HAS_MIN) && (k->flags & PX_CONFIG_HAS_MAX))
			rerr(r, n, "%s is out of range %c%s, %s%c", ex,
			     (k->flags & PX_CONFIG_MIN_EXCL) ? '(' : '[', lo, hi,
			     (k->flags & PX_CONFIG_MAX_EXCL) ? ')' : ']');
		else if (k->flags & PX_CONFIG_HAS_MIN)
			rerr(r, n, "%s is out of range (must be %s %s)", ex,
			     (k->flags & PX_CONFIG_MIN_EXCL) ? ">" : ">=", lo);
		else
			rerr(r, n, "%s is out of range (must be %s %s)", ex,
			     (k->flags & PX_CONFIG_MAX_EXCL) ? "<" : "<=", hi);
		return -1;
	}
	*dst = v;
	return 0;
}

static int read_bool(struct px_config_reader *r, const struct px_config_node *n,
		     bool *dst)
{
	if (n->kind == PX_CONFIG_NODE_SCALAR && !n->quoted) {
		const char *s = n->str;
		if (!strcmp(s, "true") || !strcmp(s, "True") || !strcmp(s, "TRUE")) {
			*dst = true;
			return 0;
		}
		if (!strcmp(s, "false") || !strcmp(s, "False") ||
		    !strcmp(s, "FALSE")) {
			*dst = false;
			return 0;
		}
	}
	wrong_type(r, n, PX_CONFIG_T_BOOL, NULL);
	return -1;
}

static int read_string(struct px_config_reader *r, const struct px_config_key *k,
		       const struct px_config_node *n, const char **dst)
{
	if (n->kind != PX_CONFIG_NODE_SCALAR || px_config_node_is_null(n)) {
		wrong_type(r, n, PX_CONFIG_T_STRING, NULL);
		return -1;
	}
	if (strlen(n->str) != n->len) {
		rerr(r, n, "string contains a NUL character");
		return -1;
	}
	if ((k->flags & PX_CONFIG_NONEMPTY) && n->len == 0) {
		rerr(r, n, "must not be empty");
		return -1;
	}
	*dst = n->str;
	return 0;
}

static int read_enum(struct px_config_reader *r, const struct px_config_key *k,
		     const struct px_config_node *n, int *dst)
{
	char list[400], got[320];
	int i;
	names_list(k->names, list, sizeof(list));
	if (n->kind != PX_CONFIG_NODE_SCALAR || px_config_node_is_null(n)) {
		describe(n, got, sizeof(got));
		rerr(r, n, "expected one of: %s, got %s", list, got);
		return -1;
	}
	for (i = 0; k->names && k->names[i]; i++) {
		if (strlen(k->names[i]) == n->len &&
		    memcmp(k->names[i], n->str, n->len) == 0) {
			*dst = i;
			return 0;
		}
	}
	px__cfg_excerpt(got, sizeof(got), n->str, n->len);
	rerr(r, n, "unknown value '%s' (expected one of: %s)", got, list);
	return -1;
}

/* One scalar value of type t into dst. */
static int read_scalar(struct px_config_reader *r, const struct px_config_key *k,
		       enum px_config_type t, const struct px_config_node *n,
		       void *dst)
{
	switch (t) {
	case PX_CONFIG_T_INT64:
	case PX_CONFIG_T_DURATION:
		return read_int(r, k, t, n, dst);
	case PX_CONFIG_T_DOUBLE:
		return read_double(r, k, n, dst);
	case PX_CONFIG_T_BOOL:
		return read_bool(r, n, dst);
	case PX_CONFIG_T_STRING:
		return read_string(r, k, n, dst);
	case PX_CONFIG_T_ENUM:
		return read_enum(r, k, n, dst);
	default:
		r->bad_schema = 1;
		rerr(r, n, "schema error: type %d is not a scalar type", (int)t);
		return -1;
	}
}

/* ---- sections ---------------------------------------------------- */

static size_t scalar_size(enum px_config_type t)
{
	switch (t) {
	case PX_CONFIG_T_INT64:
	case PX_CONFIG_T_DURATION:
		return sizeof(int64_t);
	case PX_CONFIG_T_DOUBLE:
		return sizeof(double);
	case PX_CONFIG_T_BOOL:
		return sizeof(bool);
	case PX_CONFIG_T_STRING:
		return sizeof(const char *);
	case PX_CONFIG_T_ENUM:
		return sizeof(int);
	default:
		return 0;
	}
}

static void apply_defaults(const struct px_config_schema *s, void *obj,
			   int depth)
{
	size_t i, j;
	if (depth > 32)
		return;
	for (i = 0; i < s->n_keys; i++) {
		const struct px_config_key *k = &s->keys[i];
		unsigned char *f = (unsigned char *)obj + k->offset;
		size_t n = k->fixed_count ? k->fixed_count : 1;
		if (k->flags & PX_CONFIG_PRESENT)
			*(bool *)((unsigned char *)obj + k->present_offset) = false;
		switch (k->type) {
		case PX_CONFIG_T_INT64:
		case PX_CONFIG_T_DURATION:
			for (j = 0; j < n; j++)
				((int64_t *)(void *)f)[j] = k->idef;
			break;
		case PX_CONFIG_T_DOUBLE:
			for (j = 0; j < n; j++)
				((double *)(void *)f)[j] = k->ddef;
			break;
		case PX_CONFIG_T_BOOL:
			*(bool *)f = k->idef != 0;
			break;
		case PX_CONFIG_T_STRING:
			*(const char **)(void *)f = k->sdef;
			break;
		case PX_CONFIG_T_ENUM:
			*(int *)(void *)f = (int)k->idef;
			break;
		case PX_CONFIG_T_SEQ: {
			void *null = NULL;
			memcpy(f, &null, sizeof(null));
			*(size_t *)(void *)((unsigned char *)obj +
					    k->count_offset) = 0;
			break;
		}
		case PX_CONFIG_T_MAP:
			*(const struct px_config_node **)(void *)f = NULL;
			break;
		case PX_CONFIG_T_SUB:
			if (k->sub)
				apply_defaults(k->sub, f, depth + 1);
			break;
		}
	}
}

static void read_section(struct px_config_reader *r,
			 const struct px_config_node *map,
			 const struct px_config_schema *s, void *obj, int depth);

static void read_seq(struct px_config_reader *r, const struct px_config_key *k,
		     const struct px_config_node *n, unsigned char *obj,
		     int depth)
{
	unsigned char *arr;
	size_t i, esz = k->sub ? k->elem_size : scalar_size(k->elem);
	if (n->kind != PX_CONFIG_NODE_SEQ) {
		/* An empty plain value ("inputs:") is an empty list. */
		if (px_config_node_is_null(n) && k->min_count == 0)
			return;
		wrong_type(r, n, PX_CONFIG_T_SEQ, NULL);
		return;
	}
	if (n->len < k->min_count) {
		rerr(r, n, "has %zu entr%s; at least %zu needed", n->len,
		     n->len == 1 ? "y" : "ies", k->min_count);
		return;
	}
	if (k->max_count && n->len > k->max_count) {
		rerr(r, n, "has %zu entries; at most %zu allowed", n->len,
		     k->max_count);
		return;
	}
	if (n->len == 0 || esz == 0)
		return;
	if (n->len > SIZE_MAX / esz ||
	    !(arr = px__cfg_alloc(r->doc, n->len * esz))) {
		r->nomem = 1;
		rerr(r, n, "out of memory");
		return;
	}
	for (i = 0; i < n->len; i++) {
		size_t old = push(r, "[%zu]", i);
		if (k->sub)
			read_section(r, n->items[i], k->sub, arr + i * esz,
				     depth + 1);
		else
			read_scalar(r, k, k->elem, n->items[i], arr + i * esz);
		pop(r, old);
	}
	memcpy(obj + k->offset, &arr, sizeof(arr));
	*(size_t *)(void *)(obj + k->count_offset) = n->len;
}

static void read_fixed(struct px_config_reader *r, const struct px_config_key *k,
		       const struct px_config_node *n, unsigned char *obj)
{
	unsigned char tmp[16 * sizeof(double)];
	size_t esz = scalar_size(k->type), i;
	int bad = 0;
	if (n->kind != PX_CONFIG_NODE_SEQ || n->len != k->fixed_count) {
		char got[320];
		if (n->kind == PX_CONFIG_NODE_SEQ)
			snprintf(got, sizeof(got), "a sequence of %zu", n->len);
		else
			describe(n, got, sizeof(got));
		rerr(r, n, "expected a sequence of %zu %s, got %s",
		     k->fixed_count,
		     k->type == PX_CONFIG_T_DOUBLE ? "numbers" : "integers", got);
		return;
	}
	if (k->fixed_count * esz > sizeof(tmp)) {
		r->bad_schema = 1;
		rerr(r, n, "schema error: fixed_count too large");
		return;
	}
	/* All or nothing: a half-written vector would be misleading. */
	for (i = 0; i < n->len; i++) {
		size_t old = push(r, "[%zu]", i);
		if (read_scalar(r, k, k->type, n->items[i], tmp + i * esz))
			bad = 1;
		pop(r, old);
	}
	if (!bad)
		memcpy(obj + k->offset, tmp, n->len * esz);
}

static void read_key(struct px_config_reader *r, const struct px_config_key *k,
		     const struct px_config_node *n, unsigned char *obj,
		     int depth)
{
	if (k->flags & PX_CONFIG_PRESENT)
		*(bool *)(obj + k->present_offset) = true;
	if (k->fixed_count) {
		read_fixed(r, k, n, obj);
		return;
	}
	switch (k->type) {
	case PX_CONFIG_T_SEQ:
		read_seq(r, k, n, obj, depth);
		break;
	case PX_CONFIG_T_SUB:
		read_section(r, n, k->sub, obj + k->offset, depth + 1);
		break;
	case PX_CONFIG_T_MAP:
		if (px_config_node_is_null(n))
			break; /* "scene:" with nothing under it: absent */
		if (n->kind != PX_CONFIG_NODE_MAP) {
			wrong_type(r, n, PX_CONFIG_T_MAP, NULL);
			break;
		}
		*(const struct px_config_node **)(void *)(obj + k->offset) = n;
		break;
	default: {
		/* Keep the default when the value is bad, so the struct stays
		 * usable for further checks. */
		unsigned char tmp[sizeof(int64_t) + sizeof(double)];
		size_t sz = scalar_size(k->type);
		if (read_scalar(r, k, k->type, n, tmp) == 0)
			memcpy(obj + k->offset, tmp, sz);
		break;
	}
	}
}

/* Edit distance, for "did you mean". Names longer than 63 get none. */
static size_t edit_distance(const char *a, size_t la, const char *b, size_t lb)
{
	size_t row[64], i, j;
	if (la >= 64 || lb >= 64)
		return SIZE_MAX;
	for (j = 0; j <= lb; j++)
		row[j] = j;
	for (i = 1; i <= la; i++) {
		size_t diag = row[0];
		row[0] = i;
		for (j = 1; j <= lb; j++) {
			size_t up = row[j];
			size_t best = diag + (a[i - 1] != b[j - 1]);
			if (up + 1 < best)
				best = up + 1;
			if (row[j - 1] + 1 < best)
				best = row[j - 1] + 1;
			row[j] = best;
			diag = up;
		}
	}
	return row[lb];
}

static void unknown_key(struct px_config_reader *r,
			const struct px_config_node *key,
			const struct px_config_schema *s)
{
	size_t best = SIZE_MAX, bi = 0, i, limit;
	char list[400];
	size_t o = 0;
	for (i = 0; i < s->n_keys; i++) {
		size_t d = edit_distance(key->str, key->len, s->keys[i].name,
					 strlen(s->keys[i].name));
		if (d < best) {
			best = d;
			bi = i;
		}
	}
	limit = key->len <= 3 ? 1 : key->len <= 8 ? 2 : 3;
	if (best <= limit) {
		rerr(r, key, "unknown key (did you mean '%s'?)", s->keys[bi].name);
		return;
	}
	list[0] = '\0';
	for (i = 0; i < s->n_keys; i++) {
		int n = snprintf(list + o, sizeof(list) - o, "%s%s",
				 i ? ", " : "", s->keys[i].name);
		if (n < 0 || (size_t)n >= sizeof(list) - o) {
			list[o] = '\0';
			break;
		}
		o += (size_t)n;
	}
	if (s->n_keys == 0)
		rerr(r, key, "unknown key (this section takes no keys)");
	else
		rerr(r, key, "unknown key (expected one of: %s)", list);
}

static void read_section(struct px_config_reader *r,
			 const struct px_config_node *map,
			 const struct px_config_schema *s, void *obj, int depth)
{
	bool seen[MAX_SCHEMA_KEYS];
	const struct px_config_node *saved;
	size_t i, j;
	if (!s || s->n_keys > MAX_SCHEMA_KEYS || depth > 32) {
		r->bad_schema = 1;
		rerr(r, map, "schema error: missing, too large or too deep");
		return;
	}
	apply_defaults(s, obj, 0);
	/* A null value ("loop:" with everything commented out) is an empty
	 * mapping: defaults apply, required keys are still required. */
	if (map && map->kind != PX_CONFIG_NODE_MAP &&
	    !px_config_node_is_null(map)) {
		wrong_type(r, map, PX_CONFIG_T_SUB, NULL);
		map = NULL;
	} else if (map) {
		memset(seen, 0, sizeof(seen));
		for (i = 0; map->kind == PX_CONFIG_NODE_MAP && i < map->len; i++) {
			const struct px_config_node *key = map->pairs[i].key;
			size_t old = r->plen;
			for (j = 0; j < s->n_keys; j++)
				if (strlen(s->keys[j].name) == key->len &&
				    memcmp(s->keys[j].name, key->str, key->len) == 0)
					break;
			push_key(r, key->str, key->len);
			if (j == s->n_keys) {
				unknown_key(r, key, s);
			} else {
				seen[j] = true;
				read_key(r, &s->keys[j], map->pairs[i].value,
					 obj, depth);
			}
			pop(r, old);
		}
		for (j = 0; j < s->n_keys; j++) {
			if ((s->keys[j].flags & PX_CONFIG_REQUIRED) && !seen[j]) {
				size_t old = r->plen;
				push_key(r, s->keys[j].name,
					 strlen(s->keys[j].name));
				rerr(r, map, "missing required key");
				pop(r, old);
			}
		}
	}
	if (s->check) {
		saved = r->node;
		r->node = map;
		s->check(r, map, obj);
		r->node = saved;
	}
}

int px_config_read(struct px_config_doc *doc, const struct px_config_node *map,
		   const char *path, const struct px_config_schema *schema,
		   void *obj, struct px_config_diag *diag)
{
	struct px_config_reader r;
	if (!doc || !schema || !obj)
		return PX_E_INVAL;
	memset(&r, 0, sizeof(r));
	r.doc = doc;
	r.diag = diag;
	r.node = map;
	snprintf(r.path, sizeof(r.path), "%s", path ? path : "");
	r.plen = strlen(r.path);
	read_section(&r, map, schema, obj, 0);
	if (r.nomem)
		return PX_E_NOMEM;
	if (r.bad_schema)
		return PX_E_INVAL;
	return r.errors ? PX_E_PARSE : PX_OK;
}

/* ---- schema self-check ------------------------------------------- */

static int schema_bad(char *why, size_t cap, const char *sname,
		      const char *kname, const char *what)
{
	if (why && cap)
		snprintf(why, cap, "%s.%s: %s", sname ? sname : "?",
			 kname ? kname : "?", what);
	return PX_E_INVAL;
}

static int validate(const struct px_config_schema *s, char *why, size_t cap,
		    int depth)
{
	size_t i, j;
	if (!s)
		return schema_bad(why, cap, "?", "?", "NULL schema");
	if (depth > 16)
		return schema_bad(why, cap, s->name, "", "nested too deep");
	if (s->n_keys > MAX_SCHEMA_KEYS)
		return schema_bad(why, cap, s->name, "", "too many keys");
	for (i = 0; i < s->n_keys; i++) {
		const struct px_config_key *k = &s->keys[i];
		enum px_config_type t = k->type == PX_CONFIG_T_SEQ && !k->sub
						? k->elem
						: k->type;
		if (!k->name || !*k->name)
			return schema_bad(why, cap, s->name, "", "empty name");
		for (j = 0; j < i; j++)
			if (strcmp(s->keys[j].name, k->name) == 0)
				return schema_bad(why, cap, s->name, k->name,
						  "duplicate key");
		if (t == PX_CONFIG_T_DURATION) {
			size_t n = strlen(k->name);
			if (n < 3 || strcmp(k->name + n - 3, "_ns") != 0)
				return schema_bad(why, cap, s->name, k->name,
						  "duration key must end in _ns");
		}
		if ((k->type == PX_CONFIG_T_SUB ||
		     (k->type == PX_CONFIG_T_SEQ && k->elem == PX_CONFIG_T_SUB)) &&
		    !k->sub)
			return schema_bad(why, cap, s->name, k->name,
					  "sub-schema missing");
		if (k->type == PX_CONFIG_T_SEQ && k->sub && k->elem_size == 0)
			return schema_bad(why, cap, s->name, k->name,
					  "elem_size missing");
		if (k->type == PX_CONFIG_T_SEQ && !k->sub && scalar_size(k->elem) == 0)
			return schema_bad(why, cap, s->name, k->name,
					  "sequence element type missing");
		if (k->fixed_count && k->type != PX_CONFIG_T_INT64 &&
		    k->type != PX_CONFIG_T_DOUBLE)
			return schema_bad(why, cap, s->name, k->name,
					  "fixed_count needs INT64 or DOUBLE");
		if (t == PX_CONFIG_T_ENUM) {
			int n = 0;
			if (!k->names || !k->names[0])
				return schema_bad(why, cap, s->name, k->name,
						  "enum without names");
			while (k->names[n])
				n++;
			if (k->type == PX_CONFIG_T_ENUM &&
			    (k->idef < 0 || k->idef >= n))
				return schema_bad(why, cap, s->name, k->name,
						  "enum default out of range");
		}
		if (k->type == PX_CONFIG_T_INT64 || k->type == PX_CONFIG_T_DURATION) {
			if (((k->flags & PX_CONFIG_HAS_MIN) && k->idef < k->imin) ||
			    ((k->flags & PX_CONFIG_HAS_MAX) && k->idef > k->imax))
				return schema_bad(why, cap, s->name, k->name,
						  "default out of range");
		}
		if (k->type == PX_CONFIG_T_DOUBLE && !(k->flags & PX_CONFIG_REQUIRED)) {
			bool lo = (k->flags & PX_CONFIG_HAS_MIN) &&
				  ((k->flags & PX_CONFIG_MIN_EXCL)
					   ? !(k->ddef > k->dmin)
					   : k->ddef < k->dmin);
			bool hi = (k->flags & PX_CONFIG_HAS_MAX) &&
				  ((k->flags & PX_CONFIG_MAX_EXCL)
					   ? !(k->ddef < k->dmax)
					   : k->ddef > k->dmax);
			if (lo || hi || !isfinite(k->ddef))
				return schema_bad(why, cap, s->name, k->name,
						  "default out of range");
		}
		if (k->sub) {
			int rc = validate(k->sub, why, cap, depth + 1);
			if (rc)
				return rc;
		}
	}
	return PX_OK;
}

int px_config_schema_validate(const struct px_config_schema *s, char *why,
			      size_t why_len)
{
	if (why && why_len)
		why[0] = '\0';
	return validate(s, why, why_len, 0);
}
