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

/*
 * Config writers: the pieces of YAML the device tests build their
 * configs from: string literals the compiler joins, so each config
 * keeps its exact lines (diagnostics name lines and columns).
 *   PX_TEST_YAML_HEAD                 the version and the devices list
 *   PX_TEST_YAML_CAN(name, if, tr)    a socketcan device up to its
 *                                     transport line (sim or unix)
 *   PX_TEST_YAML_SIM_GPIO(name)       a simulated GPIO device up to its
 *                                     kind line
 *   PX_TEST_YAML_SIM_HAP_IO           two whole simulated devices: "hap",
 *                                     a NaN window at 10 ms for 10 ms,
 *                                     and GPIO "io" with an estop input
 */
#define PX_TEST_YAML_HEAD "version: 1\n" \
			  "devices:\n"
#define PX_TEST_YAML_CAN(name, iface, transport)                            \
	"  - name: " name "\n"                                              \
	"    backend: socketcan\n"                                           \
	"    socketcan:\n"                                                   \
	"      interface: " iface "\n"                                       \
	"      transport: " transport "\n"
#define PX_TEST_YAML_SIM_GPIO(name)                                         \
	"  - name: " name "\n"                                              \
	"    backend: sim\n"                                                 \
	"    sim:\n"                                                         \
	"      kind: gpio\n"
#define PX_TEST_YAML_SIM_HAP_IO                                             \
	"  - name: hap\n"                                                    \
	"    backend: sim\n"                                                 \
	"    sim:\n"                                                         \
	"      faults:\n"                                                    \
	"        - {kind: nan, start_ns: 10000000, duration_ns: 10000000}\n" \
	PX_TEST_YAML_SIM_GPIO("io")                                         \
	"      lines: [{name: estop, direction: input}]\n"

#endif
