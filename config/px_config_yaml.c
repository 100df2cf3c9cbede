/* The YAML loader on libyaml's event parser: px_config_doc_load_mem()
 * builds a document's nodes (px_config_doc.c reads files and keeps the
 * diagnostics). */
#include <ctype.h>
#include <errno.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <yaml.h>

#include "config_internal.h"

#define MAX_ANCHORS 10000

/* ---- builder ----------------------------------------------------- */

struct anchor {
	const char *name;
	const struct px_config_node *node;
};

struct builder {
	struct px_config_doc *doc;
	struct px_config_diag *diag;
	yaml_parser_t parser;
	const unsigned char *buf;
	size_t buf_len;
	int err; /* first fatal error; PX_E_PARSE also for soft errors */
	struct anchor *anchors;
	size_t n_anchors, cap_anchors;
};

static void berr(struct builder *b, int line, int column, const char *fmt,
		 ...) __attribute__((format(printf, 4, 5)));

static void berr(struct builder *b, int line, int column, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	px__cfg_diag_vadd(b->diag, b->doc->name, line, column, "", fmt, ap);
	va_end(ap);
	if (!b->err)
		b->err = PX_E_PARSE;
}

static int nomem(struct builder *b)
{
	b->err = PX_E_NOMEM;
	px__cfg_diag_add(b->diag, b->doc->name, 0, 0, "",
			 "out of memory while loading");
	return PX_E_NOMEM;
}

/* Line and column (1-based) of a byte offset in the input. */
static void offset_place(const struct builder *b, size_t off, int *line,
			 int *col)
{
	size_t i, l = 1, c = 1;
	if (off > b->buf_len)
		off = b->buf_len;
	for (i = 0; i < off; i++) {
		if (b->buf[i] == '\n') {
			l++;
			c = 1;
		} else if ((b->buf[i] & 0xc0) != 0x80) {
			c++;
		}
	}
	*line = l > INT32_MAX ? INT32_MAX : (int)l;
	*col = c > INT32_MAX ? INT32_MAX : (int)c;
}

static int mark_line(const yaml_mark_t *m)
{
	return m->line >= INT32_MAX ? INT32_MAX : (int)m->line + 1;
}

static int mark_col(const yaml_mark_t *m)
{
	return m->column >= INT32_MAX ? INT32_MAX : (int)m->column + 1;
}

static int parser_error(struct builder *b)
{
	yaml_parser_t *p = &b->parser;
	const char *problem = p->problem ? p->problem : "unknown problem";
	int line, col;
	if (p->error == YAML_MEMORY_ERROR)
		return nomem(b);
	if (p->error == YAML_READER_ERROR) {
		offset_place(b, p->problem_offset, &line, &col);
		if (p->problem_value != -1)
			berr(b, line, col, "YAML error: %s (byte 0x%02x)",
			     problem, (unsigned)p->problem_value & 0xffu);
		else
			berr(b, line, col, "YAML error: %s", problem);
	} else if (p->context) {
		berr(b, mark_line(&p->problem_mark), mark_col(&p->problem_mark),
		     "YAML syntax error: %s (%s at line %d, column %d)",
		     problem, p->context, mark_line(&p->context_mark),
		     mark_col(&p->context_mark));
	} else {
		berr(b, mark_line(&p->problem_mark), mark_col(&p->problem_mark),
		     "YAML syntax error: %s", problem);
	}
	b->err = PX_E_PARSE;
	return PX_E_PARSE;
}

static int next_event(struct builder *b, yaml_event_t *ev)
{
	if (!yaml_parser_parse(&b->parser, ev))
		return parser_error(b);
	return PX_OK;
}

static struct px_config_node *new_node(struct builder *b,
				       enum px_config_node_kind kind,
				       const yaml_event_t *ev)
{
	struct px_config_node *n = px__cfg_alloc(b->doc, sizeof(*n));
	if (!n) {
		nomem(b);
		return NULL;
	}
	n->kind = kind;
	n->line = mark_line(&ev->start_mark);
	n->column = mark_col(&ev->start_mark);
	n->file = b->doc->name;
	n->str = "";
	n->expanded_ = 1;
	return n;
}

static int add_anchor(struct builder *b, const yaml_char_t *name,
		      const struct px_config_node *n)
{
	if (!name)
		return PX_OK;
	if (b->n_anchors == MAX_ANCHORS) {
		berr(b, n->line, n->column, "more than %d anchors",
		     MAX_ANCHORS);
		return PX_E_PARSE;
	}
	if (b->n_anchors == b->cap_anchors) {
		size_t cap = b->cap_anchors ? b->cap_anchors * 2 : 16;
		struct anchor *a = realloc(b->anchors, cap * sizeof(*a));
		if (!a)
			return nomem(b);
		b->anchors = a;
		b->cap_anchors = cap;
	}
	b->anchors[b->n_anchors].name =
		px__cfg_strndup(b->doc, (const char *)name,
				strlen((const char *)name));
	if (!b->anchors[b->n_anchors].name)
		return nomem(b);
	b->anchors[b->n_anchors].node = n;
	b->n_anchors++;
	return PX_OK;
}

static const struct px_config_node *find_anchor(const struct builder *b,
						const char *name)
{
	size_t i = b->n_anchors;
	/* A redefined anchor applies from its new definition on. */
	while (i-- > 0)
		if (strcmp(b->anchors[i].name, name) == 0)
			return b->anchors[i].node;
	return NULL;
}

/* The YAML 1.2 core schema's forms of a tagged scalar's value, so that
 * a tag cannot contradict its value ("!!null 2000000", "!!int abc",
 * "!!bool 3"): the tag would otherwise be ignored and the value read as
 * whatever it looks like. */
static int is_core_int(const char *v, size_t n)
{
	size_t i = 0;
	if (n > 2 && v[0] == '0' && (v[1] == 'x' || v[1] == 'o')) {
		for (i = 2; i < n; i++)
			if (v[1] == 'x' ? !isxdigit((unsigned char)v[i])
					: (v[i] < '0' || v[i] > '7'))
				return 0;
		return 1;
	}
	if (i < n && (v[i] == '-' || v[i] == '+'))
		i++;
	if (i == n)
		return 0;
	for (; i < n; i++)
		if (!isdigit((unsigned char)v[i]))
			return 0;
	return 1;
}

static int is_one_of(const char *v, size_t n, const char *const *words)
{
	for (; *words; words++)
		if (strlen(*words) == n && memcmp(v, *words, n) == 0)
			return 1;
	return 0;
}

static int is_core_float(const char *v, size_t n)
{
	static const char *const special[] = {".inf", ".Inf", ".INF", "+.inf", "+.Inf",
					      "+.INF", "-.inf", "-.Inf", "-.INF", ".nan",
					      ".NaN", ".NAN", NULL};
	size_t i = 0, digits = 0;
	if (is_one_of(v, n, special) || is_core_int(v, n))
		return 1;
	if (i < n && (v[i] == '-' || v[i] == '+'))
		i++;
	for (; i < n && isdigit((unsigned char)v[i]); i++)
		digits++;
	if (i < n && v[i] == '.')
		for (i++; i < n && isdigit((unsigned char)v[i]); i++)
			digits++;
	if (!digits)
		return 0;
	if (i < n && (v[i] == 'e' || v[i] == 'E')) {
		size_t e0;
		i++;
		if (i < n && (v[i] == '-' || v[i] == '+'))
			i++;
		e0 = i;
		while (i < n && isdigit((unsigned char)v[i]))
			i++;
		if (i == e0)
			return 0;
	}
	return i == n;
}

/* Tags: the YAML core ones are accepted (!!str makes a string) where
 * they agree with what they tag (a scalar's value in the core schema's
 * form for !!int, !!float, !!bool and !!null; !!seq on a sequence, !!map
 * on a mapping); anything else would need a meaning we do not have. */
static int check_tag(struct builder *b, const yaml_char_t *tag,
		     const yaml_event_t *ev, bool *is_str)
{
	static const char core[] = "tag:yaml.org,2002:";
	static const char *const bools[] = {"true", "True", "TRUE", "false",
					    "False", "FALSE", NULL};
	static const char *const nulls[] = {"", "~", "null", "Null", "NULL", NULL};
	const char *t = (const char *)tag;
	char ex[80], vx[80];
	const char *want = NULL, *on = NULL;
	if (!t)
		return PX_OK;
	if (strncmp(t, core, sizeof(core) - 1) == 0) {
		const char *s = t + sizeof(core) - 1;
		int scalar = ev->type == YAML_SCALAR_EVENT;
		const char *v = scalar ? (const char *)ev->data.scalar.value : "";
		size_t n = scalar ? ev->data.scalar.length : 0;
		if (strcmp(s, "str") == 0 && scalar) {
			*is_str = true;
			return PX_OK;
		}
		if (strcmp(s, "seq") == 0) {
			if (ev->type == YAML_SEQUENCE_START_EVENT)
				return PX_OK;
			on = "a sequence";
		} else if (strcmp(s, "map") == 0) {
			if (ev->type == YAML_MAPPING_START_EVENT)
				return PX_OK;
			on = "a mapping";
		} else if (!strcmp(s, "str") || !strcmp(s, "int") ||
			   !strcmp(s, "float") || !strcmp(s, "bool") ||
			   !strcmp(s, "null")) {
			if (!scalar)
				on = "a scalar";
			else if (!strcmp(s, "int") && !is_core_int(v, n))
				want = "an integer";
			else if (!strcmp(s, "float") && !is_core_float(v, n))
				want = "a number";
			else if (!strcmp(s, "bool") && !is_one_of(v, n, bools))
				want = "true or false";
			else if (!strcmp(s, "null") && !is_one_of(v, n, nulls))
				want = "null, ~ or nothing";
			else
				return PX_OK;
		}
		if (want) {
			px__cfg_excerpt(vx, sizeof(vx), v, n);
			berr(b, mark_line(&ev->start_mark), mark_col(&ev->start_mark),
			     "YAML tag '!!%s' contradicts its value '%s' (!!%s wants %s)",
			     s, vx, s, want);
			return PX_E_PARSE;
		}
		if (on) {
			berr(b, mark_line(&ev->start_mark), mark_col(&ev->start_mark),
			     "YAML tag '!!%s' belongs on %s, not here", s, on);
			return PX_E_PARSE;
		}
	}
	if (strcmp(t, "!") == 0) /* non-specific tag: a quoted-like string */
		return PX_OK;
	px__cfg_excerpt(ex, sizeof(ex), t, strlen(t));
	berr(b, mark_line(&ev->start_mark), mark_col(&ev->start_mark),
	     "unsupported YAML tag '%s'", ex);
	return PX_E_PARSE;
}

static int build(struct builder *b, yaml_event_t *ev, int depth,
		 const struct px_config_node **out);

static int expand_add(struct builder *b, struct px_config_node *parent,
		      const struct px_config_node *child)
{
	parent->expanded_ += child->expanded_;
	if (parent->expanded_ > PX_CONFIG_MAX_EXPANDED) {
		berr(b, parent->line, parent->column,
		     "document too large with aliases expanded (more than %d "
		     "nodes)",
		     PX_CONFIG_MAX_EXPANDED);
		return PX_E_PARSE;
	}
	return PX_OK;
}

/* Grow a temporary pointer array (freed by the caller). */
static int grow(struct builder *b, void **arr, size_t *cap, size_t n,
		size_t elem)
{
	size_t ncap;
	void *p;
	if (n < *cap)
		return PX_OK;
	ncap = *cap ? *cap * 2 : 8;
	if (ncap > SIZE_MAX / elem)
		return nomem(b);
	p = realloc(*arr, ncap * elem);
	if (!p)
		return nomem(b);
	*arr = p;
	*cap = ncap;
	return PX_OK;
}

/* The next node of a sequence or mapping, built into *child: 1, or 0 at
 * the event of type end (the collection's end; -1: none expected), or
 * an error code. */
static int build_child(struct builder *b, int end, int depth,
		       const struct px_config_node **child)
{
	yaml_event_t ev;
	int rc = next_event(b, &ev);
	if (rc)
		return rc;
	if ((int)ev.type == end) {
		yaml_event_delete(&ev);
		return 0;
	}
	rc = build(b, &ev, depth, child);
	yaml_event_delete(&ev);
	return rc ? rc : 1;
}

static int build_seq(struct builder *b, const yaml_event_t *start, int depth,
		     const struct px_config_node **out)
{
	struct px_config_node *n = new_node(b, PX_CONFIG_NODE_SEQ, start);
	const struct px_config_node **tmp = NULL;
	size_t count = 0, cap = 0;
	int rc = PX_OK;
	if (!n)
		return PX_E_NOMEM;
	for (;;) {
		const struct px_config_node *child;
		rc = build_child(b, YAML_SEQUENCE_END_EVENT, depth + 1, &child);
		if (rc <= 0)
			break;
		rc = grow(b, (void **)&tmp, &cap, count, sizeof(*tmp));
		if (rc)
			break;
		tmp[count++] = child;
		rc = expand_add(b, n, child);
		if (rc)
			break;
	}
	if (!rc && count) {
		const struct px_config_node **items =
			px__cfg_alloc(b->doc, count * sizeof(*items));
		if (!items) {
			rc = nomem(b);
		} else {
			memcpy(items, tmp, count * sizeof(*items));
			n->items = items;
			n->len = count;
		}
	}
	free(tmp);
	if (!rc)
		rc = add_anchor(b, start->data.sequence_start.anchor, n);
	*out = n;
	return rc;
}

struct keyref {
	const struct px_config_node *key;
	size_t idx;
};

static int keyref_cmp(const void *pa, const void *pb)
{
	const struct keyref *a = pa, *b = pb;
	size_t n = a->key->len < b->key->len ? a->key->len : b->key->len;
	int c = memcmp(a->key->str, b->key->str, n);
	if (c)
		return c;
	if (a->key->len != b->key->len)
		return a->key->len < b->key->len ? -1 : 1;
	return a->idx < b->idx ? -1 : a->idx > b->idx;
}

/* Report every key that repeats an earlier one, in document order. */
static int check_duplicates(struct builder *b, const struct px_config_pair *p,
			    size_t n)
{
	struct keyref *refs;
	size_t *first; /* per pair: index of its first occurrence */
	size_t i;
	if (n < 2)
		return PX_OK;
	refs = malloc(n * sizeof(*refs));
	first = malloc(n * sizeof(*first));
	if (!refs || !first) {
		free(refs);
		free(first);
		return nomem(b);
	}
	for (i = 0; i < n; i++) {
		refs[i].key = p[i].key;
		refs[i].idx = i;
		first[i] = i;
	}
	qsort(refs, n, sizeof(*refs), keyref_cmp);
	for (i = 1; i < n; i++) {
		const struct px_config_node *k0 = refs[i - 1].key, *k1 = refs[i].key;
		if (k0->len == k1->len && memcmp(k0->str, k1->str, k0->len) == 0)
			first[refs[i].idx] = first[refs[i - 1].idx];
	}
	for (i = 0; i < n; i++) {
		if (first[i] != i) {
			const struct px_config_node *k = p[i].key,
						    *f = p[first[i]].key;
			char ex[200];
			px__cfg_excerpt(ex, sizeof(ex), k->str, k->len);
			berr(b, k->line, k->column,
			     "duplicate key '%s' (first at line %d, column %d)",
			     ex, f->line, f->column);
		}
	}
	free(refs);
	free(first);
	return PX_OK;
}

static int build_map(struct builder *b, const yaml_event_t *start, int depth,
		     const struct px_config_node **out)
{
	struct px_config_node *n = new_node(b, PX_CONFIG_NODE_MAP, start);
	struct px_config_pair *tmp = NULL;
	size_t count = 0, cap = 0;
	int rc = PX_OK;
	if (!n)
		return PX_E_NOMEM;
	for (;;) {
		const struct px_config_node *key, *value;
		rc = build_child(b, YAML_MAPPING_END_EVENT, depth + 1, &key);
		if (rc <= 0)
			break;
		if (key->kind != PX_CONFIG_NODE_SCALAR) {
			berr(b, key->line, key->column,
			     "mapping keys must be plain scalars, not a %s",
			     key->kind == PX_CONFIG_NODE_MAP ? "mapping"
							     : "sequence");
			rc = PX_E_PARSE;
			break;
		}
		if (!key->quoted && key->len == 2 && key->str[0] == '<' &&
		    key->str[1] == '<') {
			berr(b, key->line, key->column,
			     "merge keys ('<<') are not supported; write the "
			     "keys out");
			rc = PX_E_PARSE;
			break;
		}
		rc = build_child(b, -1, depth + 1, &value);
		if (rc < 0)
			break;
		rc = grow(b, (void **)&tmp, &cap, count, sizeof(*tmp));
		if (rc)
			break;
		tmp[count].key = key;
		tmp[count].value = value;
		count++;
		rc = expand_add(b, n, value);
		if (rc)
			break;
	}
	if (!rc && count) {
		struct px_config_pair *pairs =
			px__cfg_alloc(b->doc, count * sizeof(*pairs));
		if (!pairs) {
			rc = nomem(b);
		} else {
			memcpy(pairs, tmp, count * sizeof(*pairs));
			n->pairs = pairs;
			n->len = count;
			rc = check_duplicates(b, pairs, count);
		}
	}
	free(tmp);
	if (!rc)
		rc = add_anchor(b, start->data.mapping_start.anchor, n);
	*out = n;
	return rc;
}

static int build(struct builder *b, yaml_event_t *ev, int depth,
		 const struct px_config_node **out)
{
	struct px_config_node *n;
	bool is_str = false;
	int rc;
	*out = NULL;
	if (depth > PX_CONFIG_MAX_DEPTH) {
		berr(b, mark_line(&ev->start_mark), mark_col(&ev->start_mark),
		     "nesting deeper than %d levels", PX_CONFIG_MAX_DEPTH);
		return PX_E_PARSE;
	}
	switch (ev->type) {
	case YAML_ALIAS_EVENT: {
		const char *name = (const char *)ev->data.alias.anchor;
		const struct px_config_node *t = find_anchor(b, name);
		if (!t) {
			char ex[80];
			px__cfg_excerpt(ex, sizeof(ex), name, strlen(name));
			berr(b, mark_line(&ev->start_mark),
			     mark_col(&ev->start_mark),
			     "alias '*%s' has no anchor before it", ex);
			return PX_E_PARSE;
		}
		*out = t;
		return PX_OK;
	}
	case YAML_SCALAR_EVENT:
		rc = check_tag(b, ev->data.scalar.tag, ev, &is_str);
		if (rc)
			return rc;
		n = new_node(b, PX_CONFIG_NODE_SCALAR, ev);
		if (!n)
			return PX_E_NOMEM;
		n->str = px__cfg_strndup(b->doc, (const char *)ev->data.scalar.value,
					 ev->data.scalar.length);
		if (!n->str)
			return nomem(b);
		n->len = ev->data.scalar.length;
		n->quoted = is_str || ev->data.scalar.style != YAML_PLAIN_SCALAR_STYLE;
		*out = n;
		return add_anchor(b, ev->data.scalar.anchor, n);
	case YAML_SEQUENCE_START_EVENT:
		rc = check_tag(b, ev->data.sequence_start.tag, ev, &is_str);
		if (rc)
			return rc;
		return build_seq(b, ev, depth, out);
	case YAML_MAPPING_START_EVENT:
		rc = check_tag(b, ev->data.mapping_start.tag, ev, &is_str);
		if (rc)
			return rc;
		return build_map(b, ev, depth, out);
	default:
		berr(b, mark_line(&ev->start_mark), mark_col(&ev->start_mark),
		     "unexpected YAML event %d", (int)ev->type);
		return PX_E_PARSE;
	}
}

static int build_stream(struct builder *b)
{
	yaml_event_t ev;
	int rc, docs = 0;
	for (;;) {
		rc = next_event(b, &ev);
		if (rc)
			return rc;
		switch (ev.type) {
		case YAML_STREAM_START_EVENT:
		case YAML_DOCUMENT_END_EVENT:
			break;
		case YAML_STREAM_END_EVENT:
			yaml_event_delete(&ev);
			return b->err;
		case YAML_DOCUMENT_START_EVENT:
			if (docs++ > 0) {
				berr(b, mark_line(&ev.start_mark),
				     mark_col(&ev.start_mark),
				     "more than one YAML document (a config "
				     "file holds exactly one)");
				yaml_event_delete(&ev);
				return PX_E_PARSE;
			}
			break;
		default: {
			const struct px_config_node *root;
			rc = build(b, &ev, 1, &root);
			yaml_event_delete(&ev);
			if (rc)
				return rc;
			b->doc->root = root;
			continue;
		}
		}
		yaml_event_delete(&ev);
	}
}

static int set_name(struct px_config_doc *doc, const char *name)
{
	size_t n = strlen(name);
	doc->name = malloc(n + 1);
	if (!doc->name)
		return PX_E_NOMEM;
	memcpy(doc->name, name, n + 1);
	return PX_OK;
}

int px_config_doc_load_mem(const char *name, const void *buf, size_t len,
			   struct px_config_doc **out,
			   struct px_config_diag *diag)
{
	struct builder b;
	int rc;
	px_config_diag_init(diag);
	if (out)
		*out = NULL;
	if (!out || (!buf && len)) {
		px__cfg_diag_add(diag, name, 0, 0, "",
				 "invalid arguments to the loader");
		return PX_E_INVAL;
	}
	memset(&b, 0, sizeof(b));
	b.diag = diag;
	b.buf = buf ? buf : (const void *)"";
	b.buf_len = len;
	b.doc = calloc(1, sizeof(*b.doc));
	if (!b.doc || set_name(b.doc, name ? name : "<memory>") != PX_OK) {
		px__cfg_diag_add(diag, name, 0, 0, "",
				 "out of memory while loading");
		px_config_doc_free(b.doc);
		return PX_E_NOMEM;
	}
	if (!yaml_parser_initialize(&b.parser)) {
		px__cfg_diag_add(diag, name, 0, 0, "",
				 "out of memory while loading");
		px_config_doc_free(b.doc);
		return PX_E_NOMEM;
	}
	yaml_parser_set_input_string(&b.parser, b.buf, len);
	yaml_parser_set_encoding(&b.parser, YAML_UTF8_ENCODING);
	rc = build_stream(&b);
	if (!rc && b.err)
		rc = b.err;
	yaml_parser_delete(&b.parser);
	free(b.anchors);
	if (rc) {
		px_config_doc_free(b.doc);
		return rc;
	}
	*out = b.doc;
	return PX_OK;
}

