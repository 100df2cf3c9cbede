/*
 * px_test_config.h - shared checks for tests of configuration schemas.
 */
#ifndef PX_TEST_CONFIG_H
#define PX_TEST_CONFIG_H

#include "px_config.h"

/* Whole file as a NUL-terminated string (malloc'ed, caller frees), or
 * NULL when it cannot be read. */
char *px_test_read_text(const char *path);

/*
 * Every key of schema s and of its sub-schemas appears in docs as
 * `name`, and every enum value too; sub-schemas deeper than max_depth
 * fail the test (a schema cycle).
 */
void px_test_check_documented(const char *docs,
			      const struct px_config_schema *s, int max_depth);

/*
 * The YAML document yaml loaded as "t.yaml" with its diagnostics in
 * *diag; NULL (diagnostics printed to stderr) when it does not load.
 * The caller frees the config with px_config_free().
 */
struct px_config *px_test_config_load(const char *yaml,
				      struct px_config_diag *diag);

#endif
