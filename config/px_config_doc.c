/* Config documents: diagnostics, nodes, reading a file (the YAML parser
 * itself is px_config_yaml.c). */
#include <ctype.h>
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "config_internal.h"

/* A config file larger than this is certainly a mistake (wrong file). */
#define MAX_FILE_BYTES (64u << 20)
#define BLOCK_BYTES 16384u

/* ---- diagnostics ------------------------------------------------- */

void px_config_diag_init(struct px_config_diag *d)
{
	if (!d)
		return;
	d->count = 0;
	d->dropped = 0;
}

int px_config_diag_total(const struct px_config_diag *d)
{
	return d ? d->count + d->dropped : 0;
}

void px_config_diag_print(const struct px_config_diag *d, FILE *f)
{
	int i;
	if (!d || !f)
		return;
	for (i = 0; i < d->count; i++)
		fprintf(f, "%s\n", d->errors[i].msg);
	if (d->dropped > 0)
		fprintf(f, "... and %d more error%s\n", d->dropped,
			d->dropped == 1 ? "" : "s");
}

const struct px_config_error *
px_config_diag_find(const struct px_config_diag *d, const char *path)
{
	int i;
	if (!d || !path)
		return NULL;
	for (i = 0; i < d->count; i++)
		if (strcmp(d->errors[i].path, path) == 0)
			return &d->errors[i];
	return NULL;
}

static void append(char *dst, size_t cap, const char *src)
{
	size_t o = strlen(dst), n = strlen(src);
	if (o + 1 >= cap)
		return;
	if (n > cap - 1 - o)
		n = cap - 1 - o;
	memcpy(dst + o, src, n);
	dst[o + n] = '\0';
}

void px__cfg_diag_vadd(struct px_config_diag *d, const char *file, int line,
		       int column, const char *path, const char *fmt,
		       va_list ap)
{
	struct px_config_error *e;
	char what[PX_CONFIG_MSG_LEN];
	if (!d)
		return;
	if (d->count >= PX_CONFIG_MAX_ERRORS) {
		d->dropped++;
		return;
	}
	e = &d->errors[d->count++];
	e->line = line;
	e->column = column;
	snprintf(e->path, sizeof(e->path), "%s", path ? path : "");
	vsnprintf(what, sizeof(what), fmt, ap);
	if (!file)
		file = "<memory>";
	/* Truncation of an over-long message is acceptable: it stays one
	 * line and keeps the place, which comes first. */
	if (line > 0)
		snprintf(e->msg, sizeof(e->msg), "%s:%d:%d: ", file, line,
			 column);
	else
		snprintf(e->msg, sizeof(e->msg), "%s: ", file);
	if (path && *path) {
		append(e->msg, sizeof(e->msg), path);
		append(e->msg, sizeof(e->msg), ": ");
	}
	append(e->msg, sizeof(e->msg), what);
}

void px__cfg_diag_add(struct px_config_diag *d, const char *file, int line,
		      int column, const char *path, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	px__cfg_diag_vadd(d, file, line, column, path, fmt, ap);
	va_end(ap);
}

void px__cfg_diag_sort(struct px_config_diag *d)
{
	int i, j;
	struct px_config_error tmp;
	if (!d)
		return;
	/* Insertion sort: stable, and the list holds at most a few dozen. */
	for (i = 1; i < d->count; i++) {
		if (d->errors[i - 1].line < d->errors[i].line ||
		    (d->errors[i - 1].line == d->errors[i].line &&
		     d->errors[i - 1].column <= d->errors[i].column))
			continue;
		tmp = d->errors[i];
		for (j = i; j > 0 &&
			    (d->errors[j - 1].line > tmp.line ||
			     (d->errors[j - 1].line == tmp.line &&
			      d->errors[j - 1].column > tmp.column));
		     j--)
			d->errors[j] = d->errors[j - 1];
		d->errors[j] = tmp;
	}
}

/* Length of a valid UTF-8 sequence at s that is safe to print (not a C1
 * control, not U+2028/U+2029 which some viewers take as line breaks);
 * 0 when the bytes must be escaped. */
static size_t printable_utf8(const unsigned char *s, size_t left)
{
	size_t n, i;
	unsigned cp;
	if (s[0] >= 0xc2 && s[0] <= 0xdf) {
		n = 2;
		cp = s[0] & 0x1fu;
	} else if (s[0] >= 0xe0 && s[0] <= 0xef) {
		n = 3;
		cp = s[0] & 0x0fu;
	} else if (s[0] >= 0xf0 && s[0] <= 0xf4) {
		n = 4;
		cp = s[0] & 0x07u;
	} else {
		return 0;
	}
	if (n > left)
		return 0;
	for (i = 1; i < n; i++) {
		if ((s[i] & 0xc0) != 0x80)
			return 0;
		cp = (cp << 6) | (s[i] & 0x3fu);
	}
	if ((n == 3 && cp < 0x800) || (n == 4 && (cp < 0x10000 || cp > 0x10ffff)) ||
	    (cp >= 0xd800 && cp <= 0xdfff) || (cp >= 0x80 && cp <= 0x9f) ||
	    cp == 0x2028 || cp == 0x2029)
		return 0;
	return n;
}

void px__cfg_excerpt(char *out, size_t cap, const char *s, size_t len)
{
	static const char hex[] = "0123456789abcdef";
	const unsigned char *u = (const unsigned char *)s;
	size_t o = 0, i = 0;
	if (cap == 0)
		return;
	while (i < len) {
		unsigned char c = u[i];
		size_t n = c >= 0x80 ? printable_utf8(u + i, len - i) : 0;
		if (o + 8 >= cap || i >= 48) {
			if (o + 4 <= cap) {
				memcpy(out + o, "...", 3);
				o += 3;
			}
			break;
		}
		if (n) {
			memcpy(out + o, u + i, n);
			o += n;
			i += n;
			continue;
		}
		if (c < 0x20 || c >= 0x7f) {
			out[o++] = '\\';
			out[o++] = 'x';
			out[o++] = hex[c >> 4];
			out[o++] = hex[c & 15];
		} else if (c == '\'' || c == '\\') {
			out[o++] = '\\';
			out[o++] = (char)c;
		} else {
			out[o++] = (char)c;
		}
		i++;
	}
	out[o] = '\0';
}

/* ---- document memory --------------------------------------------- */

void *px__cfg_alloc(struct px_config_doc *doc, size_t size)
{
	struct px__cfg_block *b = doc->blocks;
	size_t need = (size + 15u) & ~(size_t)15u;
	void *p;
	if (need < size)
		return NULL;
	if (!b || b->cap - b->used < need) {
		size_t cap = need > BLOCK_BYTES ? need : BLOCK_BYTES;
		if (cap > SIZE_MAX - sizeof(*b))
			return NULL;
		b = malloc(sizeof(*b) + cap);
		if (!b)
			return NULL;
		b->cap = cap;
		b->used = 0;
		/* A big one-off block goes behind the current one so the
		 * current block's free space is not abandoned. */
		if (doc->blocks && need > BLOCK_BYTES / 2) {
			b->next = doc->blocks->next;
			doc->blocks->next = b;
		} else {
			b->next = doc->blocks;
			doc->blocks = b;
		}
	}
	p = b->data + b->used;
	b->used += need;
	memset(p, 0, size);
	return p;
}

char *px__cfg_strndup(struct px_config_doc *doc, const char *s, size_t len)
{
	char *p;
	if (len == SIZE_MAX)
		return NULL;
	p = px__cfg_alloc(doc, len + 1);
	if (!p)
		return NULL;
	if (len)
		memcpy(p, s, len);
	p[len] = '\0';
	return p;
}

void px_config_doc_free(struct px_config_doc *doc)
{
	struct px__cfg_block *b, *next;
	if (!doc)
		return;
	for (b = doc->blocks; b; b = next) {
		next = b->next;
		free(b);
	}
	free(doc->name);
	free(doc);
}

const struct px_config_node *px_config_doc_root(const struct px_config_doc *doc)
{
	return doc ? doc->root : NULL;
}

const char *px_config_doc_name(const struct px_config_doc *doc)
{
	return doc ? doc->name : NULL;
}

const struct px_config_node *px_config_node_get(const struct px_config_node *map,
						const char *key)
{
	size_t i, n;
	if (!map || !key || map->kind != PX_CONFIG_NODE_MAP)
		return NULL;
	n = strlen(key);
	for (i = 0; i < map->len; i++) {
		const struct px_config_node *k = map->pairs[i].key;
		if (k->len == n && memcmp(k->str, key, n) == 0)
			return map->pairs[i].value;
	}
	return NULL;
}

bool px_config_node_is_null(const struct px_config_node *n)
{
	if (!n || n->kind != PX_CONFIG_NODE_SCALAR || n->quoted)
		return false;
	return n->len == 0 || strcmp(n->str, "~") == 0 ||
	       strcmp(n->str, "null") == 0 || strcmp(n->str, "Null") == 0 ||
	       strcmp(n->str, "NULL") == 0;
}

int px_config_doc_load_file(const char *path, struct px_config_doc **out,
			    struct px_config_diag *diag)
{
	FILE *f;
	unsigned char *data = NULL;
	size_t len = 0, cap = 0;
	int rc;
	px_config_diag_init(diag);
	if (out)
		*out = NULL;
	if (!path || !out) {
		px__cfg_diag_add(diag, path, 0, 0, "",
				 "invalid arguments to the loader");
		return PX_E_INVAL;
	}
	f = fopen(path, "rb");
	if (!f) {
		int e = errno;
		px__cfg_diag_add(diag, path, 0, 0, "", "cannot open: %s",
				 strerror(e));
		return e == ENOMEM ? PX_E_NOMEM : PX_E_IO;
	}
	{
		/* a regular file is judged by its size before it is read */
		struct stat st;
		if (fstat(fileno(f), &st) == 0 && S_ISREG(st.st_mode) &&
		    (unsigned long long)st.st_size > MAX_FILE_BYTES) {
			px__cfg_diag_add(diag, path, 0, 0, "",
					 "larger than %u MiB; not a config file?",
					 MAX_FILE_BYTES >> 20);
			fclose(f);
			return PX_E_PARSE;
		}
	}
	for (;;) {
		size_t got;
		if (len == cap) {
			unsigned char *p;
			if (cap >= MAX_FILE_BYTES) {
				px__cfg_diag_add(diag, path, 0, 0, "",
						 "larger than %u MiB; not a "
						 "config file?",
						 MAX_FILE_BYTES >> 20);
				free(data);
				fclose(f);
				return PX_E_PARSE;
			}
			cap = cap ? cap * 2 : 8192;
			p = realloc(data, cap);
			if (!p) {
				px__cfg_diag_add(diag, path, 0, 0, "",
						 "out of memory while reading");
				free(data);
				fclose(f);
				return PX_E_NOMEM;
			}
			data = p;
		}
		got = fread(data + len, 1, cap - len, f);
		len += got;
		if (got == 0) {
			if (ferror(f)) {
				int e = errno;
				px__cfg_diag_add(diag, path, 0, 0, "",
						 "cannot read: %s",
						 strerror(e));
				free(data);
				fclose(f);
				return PX_E_IO;
			}
			break;
		}
	}
	fclose(f);
	rc = px_config_doc_load_mem(path, data, len, out, diag);
	free(data);
	return rc;
}
