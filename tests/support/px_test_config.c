#include "px_test_config.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "px_test.h"

char *px_test_read_text(const char *path)
{
	FILE *f = fopen(path, "rb");
	char *buf;
	long n;
	if (!f)
		return NULL;
	fseek(f, 0, SEEK_END);
	n = ftell(f);
	fseek(f, 0, SEEK_SET);
	buf = n >= 0 ? malloc((size_t)n + 1) : NULL;
	if (buf && fread(buf, 1, (size_t)n, f) != (size_t)n) {
		free(buf);
		buf = NULL;
	}
	if (buf)
		buf[n] = '\0';
	fclose(f);
	return buf;
}

static void walk(const char *docs, const struct px_config_schema *s,
		 int depth, int max_depth)
{
	size_t i;
	char needle[96];
	PX_CHECK(depth < max_depth);
	for (i = 0; i < s->n_keys; i++) {
		const struct px_config_key *k = &s->keys[i];
		snprintf(needle, sizeof(needle), "`%s`", k->name);
		PX_CHECK_MSG(strstr(docs, needle) != NULL,
			     "docs/config.md does not document %s.%s", s->name,
			     k->name);
		if (k->names) {
			int j;
			for (j = 0; k->names[j]; j++) {
				snprintf(needle, sizeof(needle), "`%s`",
					 k->names[j]);
				PX_CHECK_MSG(strstr(docs, needle) != NULL,
					     "docs/config.md lacks value %s of "
					     "%s.%s",
					     k->names[j], s->name, k->name);
			}
		}
		if (k->sub)
			walk(docs, k->sub, depth + 1, max_depth);
	}
}

void px_test_check_documented(const char *docs,
			      const struct px_config_schema *s, int max_depth)
{
	walk(docs, s, 0, max_depth);
}

struct px_config *px_test_config_load(const char *yaml,
				      struct px_config_diag *diag)
{
	struct px_config *c = NULL;
	int rc = px_config_load_mem("t.yaml", yaml, strlen(yaml), &c, diag);
	if (rc != PX_OK) {
		px_config_diag_print(diag, stderr);
		return NULL;
	}
	return c;
}
