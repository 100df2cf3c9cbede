/* Private declarations shared by the config/ sources. */
#ifndef PX_CONFIG_INTERNAL_H
#define PX_CONFIG_INTERNAL_H

#include <stdarg.h>

#include "px_config.h"

/* Memory of a document: a list of blocks carved bump-style, released
 * together. */
struct px__cfg_block {
	struct px__cfg_block *next;
	size_t cap;
	size_t used;
	_Alignas(16) unsigned char data[];
};

struct px_config_doc {
	char *name;
	const struct px_config_node *root;
	struct px__cfg_block *blocks;
};

/* size bytes, zeroed, 16-byte aligned, owned by doc; NULL when out of
 * memory or size overflows. */
void *px__cfg_alloc(struct px_config_doc *doc, size_t size);

/* Copy of len bytes plus a NUL, owned by doc. */
char *px__cfg_strndup(struct px_config_doc *doc, const char *s, size_t len);

/* Add one error to d (NULL: ignored). file may be NULL, line 0 means
 * "no place", path NULL or "" means no path. */
void px__cfg_diag_vadd(struct px_config_diag *d, const char *file, int line,
		       int column, const char *path, const char *fmt,
		       va_list ap);
void px__cfg_diag_add(struct px_config_diag *d, const char *file, int line,
		      int column, const char *path, const char *fmt, ...)
	__attribute__((format(printf, 6, 7)));

/* Printable excerpt of a scalar for messages: control and non-ASCII
 * bytes as \xNN, ' as \', cut with "..." past about 48 bytes. */
void px__cfg_excerpt(char *out, size_t cap, const char *s, size_t len);

/* Stable sort of the stored errors by line, then column. */
void px__cfg_diag_sort(struct px_config_diag *d);

#endif
