/* YAML loader, schema reader and application config. */
/* PX_TEST_NEEDS: libyaml (tests/run.sh skips it in builds without) */
#include <dirent.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "px_config.h"
#include "px_test.h"
#include "px_test_config.h"

static struct px_config_diag g_diag;

static void dump_diag(void)
{
	int i;
	for (i = 0; i < g_diag.count; i++)
		fprintf(stderr, "    got: %s\n", g_diag.errors[i].msg);
}

static int load(const char *yaml)
{
	struct px_config *c = NULL;
	int rc = px_config_load_mem("t.yaml", yaml, strlen(yaml), &c, &g_diag);
	PX_CHECK(rc == PX_OK ? c != NULL : c == NULL);
	px_config_free(c);
	return rc;
}

static bool has_msg(const char *msg)
{
	int i;
	for (i = 0; i < g_diag.count; i++)
		if (strcmp(g_diag.errors[i].msg, msg) == 0)
			return true;
	return false;
}

/* The document fails to load and one of its messages is exactly msg. */
static void expect_error(const char *yaml, const char *msg)
{
	int rc = load(yaml);
	if (rc == PX_OK || !has_msg(msg)) {
		dump_diag();
		PX_CHECK_MSG(0, "rc %d, expected message:\n    %s\nfor:\n%s", rc,
			     msg, yaml);
	}
	PX_CHECK(rc == PX_E_PARSE);
}

static void expect_ok(const char *yaml)
{
	int rc = load(yaml);
	if (rc != PX_OK) {
		dump_diag();
		PX_CHECK_MSG(0, "rc %d for:\n%s", rc, yaml);
	}
	PX_CHECK_INT_EQ(px_config_diag_total(&g_diag), 0);
}

/* ---- the messages named in the config issue ---------------------- */

static void test_message_format(void)
{
	expect_error("loop:\n  period_ns: 0\n",
		     "t.yaml:2:14: loop.period_ns: 0 is out of range [10000, "
		     "100000000]");
	expect_error("loop:\n    perod_ns: 1000000\n",
		     "t.yaml:2:5: loop.perod_ns: unknown key (did you mean "
		     "'period_ns'?)");
	expect_error("loop:\n  priority: high\n",
		     "t.yaml:2:13: loop.priority: expected an integer, got "
		     "'high'");
	expect_error("devices:\n"
		     "  - name: a\n"
		     "    backend: sim\n"
		     "  - name: b\n"
		     "    backend: hidraw2\n",
		     "t.yaml:5:14: devices[1].backend: unknown value 'hidraw2' "
		     "(expected one of: sim, hidapi, libusb, socketcan, gpiod, dds)");
	/* Every error carries the place and the path in this shape. */
	PX_CHECK_INT_EQ(g_diag.errors[0].line, 5);
	PX_CHECK_INT_EQ(g_diag.errors[0].column, 14);
	PX_CHECK(strcmp(g_diag.errors[0].path, "devices[1].backend") == 0);
	PX_CHECK(px_config_diag_find(&g_diag, "devices[1].backend") ==
		 &g_diag.errors[0]);
}

/* ---- YAML-level errors ------------------------------------------- */

static void test_yaml_errors(void)
{
	expect_error("loop:\n  period_ns: 1000000\n  period_ns: 2000000\n",
		     "t.yaml:3:3: duplicate key 'period_ns' (first at line 2, "
		     "column 3)");
	expect_error("loop: [1, 2\n",
		     "t.yaml:2:1: YAML syntax error: did not find expected ',' "
		     "or ']' (while parsing a flow sequence at line 1, column 7)");
	expect_error("loop:\n\tperiod_ns: 1\n",
		     "t.yaml:2:1: YAML syntax error: found character that "
		     "cannot start any token (while scanning for the next token "
		     "at line 2, column 1)");
	expect_error("base: &b {period_ns: 20000}\nloop:\n  <<: *b\n",
		     "t.yaml:3:3: merge keys ('<<') are not supported; write "
		     "the keys out");
	expect_error("loop: *nowhere\n",
		     "t.yaml:1:7: alias '*nowhere' has no anchor before it");
	expect_error("loop: !custom {}\n",
		     "t.yaml:1:7: unsupported YAML tag '!custom'");
	expect_error("loop: {}\n---\nloop: {}\n",
		     "t.yaml:2:1: more than one YAML document (a config file "
		     "holds exactly one)");
	expect_error("? [a, b]\n: 1\n",
		     "t.yaml:1:3: mapping keys must be plain scalars, not a "
		     "sequence");
	expect_error("", "t.yaml:1:1: the document is empty (expected a "
			 "mapping of sections such as loop and devices)");
	expect_error("- loop\n", "t.yaml:1:1: expected a mapping of sections at "
				 "the top level, got a sequence");
	/* Invalid UTF-8 is a reader error placed by byte offset. */
	expect_error("loop:\n  cpu: \xff\n",
		     "t.yaml:2:8: YAML error: invalid leading UTF-8 octet "
		     "(byte 0xff)");
}

static void test_duplicates_all_reported(void)
{
	int rc = load("a: 1\nb: 2\na: 3\nc: 4\nb: 5\na: 6\n");
	PX_CHECK_INT_EQ(rc, PX_E_PARSE);
	PX_CHECK_INT_EQ(px_config_diag_total(&g_diag), 3);
	PX_CHECK(has_msg("t.yaml:3:1: duplicate key 'a' (first at line 1, "
			 "column 1)"));
	PX_CHECK(has_msg("t.yaml:5:1: duplicate key 'b' (first at line 2, "
			 "column 1)"));
	PX_CHECK(has_msg("t.yaml:6:1: duplicate key 'a' (first at line 1, "
			 "column 1)"));
	/* Quoting does not make a different key. */
	expect_error("loop: {cpu: 1, \"cpu\": 2}\n",
		     "t.yaml:1:16: duplicate key 'cpu' (first at line 1, "
		     "column 8)");
}

static void test_nesting_and_alias_limits(void)
{
	char buf[512];
	size_t i, o = 0;
	int rc;
	o += (size_t)snprintf(buf, sizeof(buf), "x: ");
	for (i = 0; i < 100; i++)
		buf[o++] = '[';
	for (i = 0; i < 100; i++)
		buf[o++] = ']';
	buf[o++] = '\n';
	buf[o] = '\0';
	rc = load(buf);
	PX_CHECK_INT_EQ(rc, PX_E_PARSE);
	PX_CHECK(strstr(g_diag.errors[0].msg, "nesting deeper than 64 levels"));
	/* "Billion laughs": ten levels of ten aliases each. */
	rc = load("a: &a [x, x, x, x, x, x, x, x, x, x]\n"
		  "b: &b [*a, *a, *a, *a, *a, *a, *a, *a, *a, *a]\n"
		  "c: &c [*b, *b, *b, *b, *b, *b, *b, *b, *b, *b]\n"
		  "d: &d [*c, *c, *c, *c, *c, *c, *c, *c, *c, *c]\n"
		  "e: &e [*d, *d, *d, *d, *d, *d, *d, *d, *d, *d]\n"
		  "f: &f [*e, *e, *e, *e, *e, *e, *e, *e, *e, *e]\n"
		  "g: &g [*f, *f, *f, *f, *f, *f, *f, *f, *f, *f]\n"
		  "h: &h [*g, *g, *g, *g, *g, *g, *g, *g, *g, *g]\n");
	PX_CHECK_INT_EQ(rc, PX_E_PARSE);
	PX_CHECK_MSG(strstr(g_diag.errors[0].msg,
			    "document too large with aliases expanded"),
		     "%s", g_diag.errors[0].msg);
	PX_CHECK_INT_EQ(g_diag.errors[0].line, 6); /* f: 1111111 nodes */
}

/* ---- value errors ------------------------------------------------ */

static void test_value_errors(void)
{
	expect_error("loop: {priority: 99999999999999999999}\n",
		     "t.yaml:1:18: loop.priority: '99999999999999999999' does "
		     "not fit in a 64-bit integer");
	expect_error("loop: {priority: 010}\n",
		     "t.yaml:1:18: loop.priority: expected an integer, got "
		     "'010' (leading zeros are not allowed)");
	expect_error("loop: {period_ns: 10ms}\n",
		     "t.yaml:1:19: loop.period_ns: expected an integer "
		     "(nanoseconds), got '10ms' (write the number alone: the "
		     "unit is in the key name)");
	expect_error("loop: {priority: 1.5}\n",
		     "t.yaml:1:18: loop.priority: expected an integer, got "
		     "'1.5' (not a whole number)");
	expect_error("loop: {priority: \"50\"}\n",
		     "t.yaml:1:18: loop.priority: expected an integer, got the "
		     "quoted string '50'");
	expect_error("loop: {priority: 1__0}\n",
		     "t.yaml:1:18: loop.priority: expected an integer, got "
		     "'1__0'");
	expect_error("loop: {priority: 10_}\n",
		     "t.yaml:1:18: loop.priority: expected an integer, got "
		     "'10_'");
	expect_error("loop: {priority: 0x}\n",
		     "t.yaml:1:18: loop.priority: expected an integer, got "
		     "'0x'");
	expect_error("loop: {priority: ~}\n",
		     "t.yaml:1:18: loop.priority: expected an integer, got "
		     "null");
	expect_error("loop: {priority: [1]}\n",
		     "t.yaml:1:18: loop.priority: expected an integer, got a "
		     "sequence");
	expect_error("safety: {max_force_n: .nan}\n",
		     "t.yaml:1:23: safety.max_force_n: expected a finite "
		     "number, got '.nan'");
	expect_error("safety: {max_force_n: -.inf}\n",
		     "t.yaml:1:23: safety.max_force_n: expected a finite "
		     "number, got '-.inf'");
	expect_error("safety: {max_force_n: 1e999}\n",
		     "t.yaml:1:23: safety.max_force_n: '1e999' is beyond the "
		     "range of a double");
	expect_error("safety: {max_force_n: 0x10}\n",
		     "t.yaml:1:23: safety.max_force_n: expected a number, got "
		     "'0x10'");
	expect_error("safety: {max_force_n: 5 N}\n",
		     "t.yaml:1:23: safety.max_force_n: expected a number, got "
		     "'5 N' (write the number alone: the unit is in the key "
		     "name)");
	expect_error("safety: {max_force_n: 0}\n",
		     "t.yaml:1:23: safety.max_force_n: 0 is out of range (0, "
		     "10000]");
	expect_error("safety: {max_force_n: 10000.5}\n",
		     "t.yaml:1:23: safety.max_force_n: 10000.5 is out of range "
		     "(0, 10000]");
	expect_error("loop: {lock_memory: yes}\n",
		     "t.yaml:1:21: loop.lock_memory: expected true or false, "
		     "got 'yes'");
	expect_error("loop: {overrun_policy: {a: 1}}\n",
		     "t.yaml:1:24: loop.overrun_policy: expected one of: skip, "
		     "catch_up, got a mapping");
	expect_error("loop: {overrun_policy: Skip}\n",
		     "t.yaml:1:24: loop.overrun_policy: unknown value 'Skip' "
		     "(expected one of: skip, catch_up)");
	expect_error("loop: 5\n",
		     "t.yaml:1:7: loop: expected a mapping, got '5'");
	expect_error("devices: {a: 1}\n",
		     "t.yaml:1:10: devices: expected a sequence, got a mapping");
	expect_error("telemetry: {file: \"\"}\n",
		     "t.yaml:1:19: telemetry.file: must not be empty");
	expect_error("scene: [1]\n",
		     "t.yaml:1:8: scene: expected a mapping, got a sequence");
	expect_error("scenery: {}\n",
		     "t.yaml:1:1: scenery: unknown key (did you mean 'scene'?)");
	expect_error("robot: {}\n",
		     "t.yaml:1:1: robot: unknown key (expected one of: version, "
		     "loop, safety, telemetry, devices, scene, control, sim, "
		     "bridge, teleop)");
	expect_error("version: 2\n",
		     "t.yaml:1:10: version: 2 is out of range [1, 1]");
	/* UTF-8 text is shown as text; line separators and C1 controls are
	 * escaped. */
	expect_error("loop: {priority: \"\xc3\xa9\\u2028\\x85\"}\n",
		     "t.yaml:1:18: loop.priority: expected an integer, got the "
		     "quoted string '\xc3\xa9\\xe2\\x80\\xa8\\xc2\\x85'");
	/* Control characters never reach the message raw. */
	expect_error("loop: {priority: \"a\\tb\\x01\"}\n",
		     "t.yaml:1:18: loop.priority: expected an integer, got the "
		     "quoted string 'a\\x09b\\x01'");
}

static const char sim_dev[] = "devices:\n"
			      "  - name: hand\n"
			      "    backend: sim\n";

static void test_device_errors(void)
{
	expect_error("devices:\n  - name: x\n",
		     "t.yaml:2:5: devices[0].backend: missing required key");
	expect_error("devices:\n  - backend: sim\n",
		     "t.yaml:2:5: devices[0].name: missing required key");
	expect_error("devices:\n  - {name: 'a b', backend: sim}\n",
		     "t.yaml:2:12: devices[0].name: 'a b': use only letters, "
		     "digits, '_', '-' and '.'");
	/* Names are quoted back escaped: a message stays one line. */
	expect_error("devices:\n  - {name: \"a\\nb\", backend: sim}\n",
		     "t.yaml:2:12: devices[0].name: 'a\\x0ab': use only "
		     "letters, digits, '_', '-' and '.'");
	expect_error("devices:\n  - name: m\n    backend: hidapi\n",
		     "t.yaml:2:5: devices[0].hidapi: missing required key "
		     "(backend is 'hidapi')");
	expect_error("devices:\n"
		     "  - name: m\n"
		     "    backend: sim\n"
		     "    gpiod: {chip: gpiochip0, lines: [{name: a, offset: 1, "
		     "direction: input}]}\n",
		     "t.yaml:4:12: devices[0].gpiod: not allowed with backend "
		     "'sim'");
	expect_error("devices:\n"
		     "  - {name: a, backend: sim}\n"
		     "  - {name: a, backend: sim}\n",
		     "t.yaml:3:12: devices[1].name: duplicate device name 'a' "
		     "(first at line 2, column 12)");
	expect_error("devices:\n"
		     "  - name: m\n"
		     "    backend: hidapi\n"
		     "    hidapi:\n"
		     "      vid: 0x10000\n"
		     "      pid: 1\n"
		     "      inputs: [{byte_offset: 0, axis: x}]\n",
		     "t.yaml:5:12: devices[0].hidapi.vid: 0x10000 is out of "
		     "range [0, 65535]");
	expect_error("devices:\n"
		     "  - name: m\n"
		     "    backend: hidapi\n"
		     "    hidapi:\n"
		     "      path: /dev/hidraw0\n"
		     "      inputs:\n"
		     "        - {byte_offset: 0, axis: x}\n"
		     "        - {byte_offset: 2, axis: x}\n",
		     "t.yaml:8:34: devices[0].hidapi.inputs[1].axis: axis 'x' "
		     "is already mapped by inputs[0]");
	expect_error("devices:\n"
		     "  - name: m\n"
		     "    backend: hidapi\n"
		     "    hidapi:\n"
		     "      path: /dev/hidraw0\n"
		     "      inputs:\n"
		     "        - {byte_offset: 0, axis: q}\n",
		     "t.yaml:7:34: devices[0].hidapi.inputs[0].axis: unknown "
		     "value 'q' (expected one of: x, y, z, rx, ry, rz)");
	expect_error("devices:\n"
		     "  - name: m\n"
		     "    backend: hidapi\n"
		     "    hidapi:\n"
		     "      path: /dev/hidraw0\n"
		     "      inputs:\n"
		     "        - {axis: x, bit_width: 1}\n",
		     "t.yaml:7:11: devices[0].hidapi.inputs[0].byte_offset: "
		     "missing required key");
	PX_CHECK(has_msg("t.yaml:7:11: devices[0].hidapi.inputs[0].signed: a "
			 "signed field needs bit_width >= 2"));
	expect_error("devices:\n"
		     "  - name: m\n"
		     "    backend: hidapi\n"
		     "    hidapi:\n"
		     "      vid: 1\n"
		     "      pid: 2\n"
		     "      output_report_len: 2\n"
		     "      outputs: [{byte_offset: 1, axis: fx}]\n",
		     "t.yaml:8:31: devices[0].hidapi.outputs[0].byte_offset: "
		     "field ends at bit 24, past output_report_len 2 bytes");
	expect_error("devices:\n"
		     "  - name: c\n"
		     "    backend: socketcan\n"
		     "    socketcan:\n"
		     "      interface: can0\n"
		     "      signals:\n"
		     "        - {name: s, id: 0x800, direction: input, start_bit: "
		     "60, length: 8}\n",
		     "t.yaml:7:25: devices[0].socketcan.signals[0].id: 0x800 "
		     "needs extended: true (standard ids are 11 bits)");
	PX_CHECK(has_msg("t.yaml:7:61: devices[0].socketcan.signals[0]."
			 "start_bit: signal runs past the 8-byte classic CAN "
			 "frame"));
	expect_error("devices:\n"
		     "  - name: c\n"
		     "    backend: socketcan\n"
		     "    socketcan: {interface: can0, transport: unix}\n",
		     "t.yaml:4:16: devices[0].socketcan.socket_path: missing "
		     "required key (transport is 'unix')");
	expect_error("devices:\n"
		     "  - name: g\n"
		     "    backend: gpiod\n"
		     "    gpiod:\n"
		     "      chip: gpiochip0\n"
		     "      lines:\n"
		     "        - {name: e, direction: input}\n",
		     "t.yaml:7:11: devices[0].gpiod.lines[0]: give exactly one "
		     "of offset and line_name");
	expect_error("devices:\n"
		     "  - name: s\n"
		     "    backend: sim\n"
		     "    sim:\n"
		     "      trajectory: {kind: sines, center_m: [0, 0]}\n",
		     "t.yaml:5:43: devices[0].sim.trajectory.center_m: expected "
		     "a sequence of 3 numbers, got a sequence of 2");
	PX_CHECK(has_msg("t.yaml:5:19: devices[0].sim.trajectory.sines: "
			 "missing required key (kind is 'sines')"));
	expect_error("devices:\n"
		     "  - name: s\n"
		     "    backend: sim\n"
		     "    sim: {trajectory: {center_m: [0, x, 0]}}\n",
		     "t.yaml:4:38: devices[0].sim.trajectory.center_m[1]: "
		     "expected a number, got 'x'");
}

static void test_safety_line_refs(void)
{
	char buf[1024];
	const char *io = "  - name: io\n"
			 "    backend: gpiod\n"
			 "    gpiod:\n"
			 "      chip: gpiochip0\n"
			 "      lines:\n"
			 "        - {name: stop, offset: 1, direction: input}\n"
			 "        - {name: relay, offset: 2, direction: output}\n";
	snprintf(buf, sizeof(buf),
		 "safety:\n  estop: {device: iox, line: stop}\n%s%s", sim_dev,
		 io);
	expect_error(buf, "t.yaml:2:19: safety.estop.device: no device named "
			  "'iox' in devices");
	snprintf(buf, sizeof(buf),
		 "safety:\n  estop: {device: hand, line: stop}\n%s", sim_dev);
	expect_error(buf, "t.yaml:2:19: safety.estop.device: device 'hand' has "
			  "no digital lines (the e-stop line needs a gpiod "
			  "device or a sim device of kind gpio)");
	snprintf(buf, sizeof(buf),
		 "safety:\n  estop: {device: io, line: relay}\n%s%s", sim_dev,
		 io);
	expect_error(buf, "t.yaml:2:29: safety.estop.line: line 'relay' of "
			  "device 'io' is an output; the e-stop line must be "
			  "an input");
	snprintf(buf, sizeof(buf),
		 "safety:\n  enable: {device: io, line: nope}\n%s%s", sim_dev,
		 io);
	expect_error(buf, "t.yaml:2:30: safety.enable.line: device 'io' has no "
			  "line named 'nope'");
	snprintf(buf, sizeof(buf),
		 "safety:\n  estop: {device: io}\n%s%s", sim_dev, io);
	expect_error(buf, "t.yaml:2:10: safety.estop.line: missing required "
			  "key");
	snprintf(buf, sizeof(buf),
		 "safety:\n"
		 "  estop: {device: io, line: stop}\n"
		 "  enable: {device: io, line: relay}\n%s%s",
		 sim_dev, io);
	expect_ok(buf);
}

static void test_timing_relations(void)
{
	expect_error("loop: {period_ns: 1000000}\n"
		     "safety:\n"
		     "  watchdog: {compute_budget_ns: 1000001}\n",
		     "t.yaml:3:33: safety.watchdog.compute_budget_ns: 1000001 "
		     "is longer than loop.period_ns 1000000");
	expect_error("loop: {period_ns: 100_000_000}\n"
		     "safety: {watchdog: {device_timeout_ns: 50_000_000}}\n",
		     "t.yaml:2:40: safety.watchdog.device_timeout_ns: 50000000 "
		     "is shorter than loop.period_ns 100000000: every cycle "
		     "would see stale data");
	expect_error("devices:\n"
		     "  - {name: a, backend: sim, stale_timeout_ns: 999_999}\n",
		     "t.yaml:2:47: devices[0].stale_timeout_ns: 999999 is "
		     "shorter than loop.period_ns 1000000: every cycle would see "
		     "stale data");
	expect_ok("loop: {period_ns: 1000000}\n"
		  "safety:\n"
		  "  watchdog: {compute_budget_ns: 1000000, device_timeout_ns: "
		  "1000000}\n"
		  "devices:\n"
		  "  - {name: a, backend: sim, stale_timeout_ns: 1000000}\n");
}

/* ---- many errors at once ----------------------------------------- */

static void test_collects_all_errors(void)
{
	int rc, i;
	rc = load("loop:\n"
		  "  period_ns: 5\n"
		  "  priority: high\n"
		  "  cpu: -2\n"
		  "safety:\n"
		  "  max_force_n: -1\n"
		  "  wachdog: {}\n"
		  "telemetry:\n"
		  "  decimation: 0\n");
	PX_CHECK_INT_EQ(rc, PX_E_PARSE);
	PX_CHECK_INT_EQ(g_diag.count, 6);
	PX_CHECK_INT_EQ(g_diag.dropped, 0);
	/* In document order. */
	for (i = 1; i < g_diag.count; i++)
		PX_CHECK(g_diag.errors[i - 1].line < g_diag.errors[i].line);
	PX_CHECK(has_msg("t.yaml:7:3: safety.wachdog: unknown key (did you "
			 "mean 'watchdog'?)"));
	PX_CHECK(has_msg("t.yaml:9:15: telemetry.decimation: 0 is out of "
			 "range [1, 1000000]"));
}

static void test_error_cap(void)
{
	char *buf = malloc(100 * 16 + 16), *text = NULL;
	size_t o = 0, tlen = 0;
	FILE *f;
	int i, rc;
	PX_CHECK(buf != NULL);
	o += (size_t)sprintf(buf + o, "loop:\n");
	for (i = 0; i < 100; i++)
		o += (size_t)sprintf(buf + o, "  k%d: 1\n", i);
	rc = load(buf);
	free(buf);
	PX_CHECK_INT_EQ(rc, PX_E_PARSE);
	PX_CHECK_INT_EQ(g_diag.count, PX_CONFIG_MAX_ERRORS);
	PX_CHECK_INT_EQ(g_diag.dropped, 100 - PX_CONFIG_MAX_ERRORS);
	PX_CHECK_INT_EQ(px_config_diag_total(&g_diag), 100);
	f = open_memstream(&text, &tlen);
	PX_CHECK(f != NULL);
	px_config_diag_print(&g_diag, f);
	fclose(f);
	PX_CHECK(strstr(text, "t.yaml:2:3: loop.k0: unknown key") == text);
	PX_CHECK(strstr(text, "\n... and 68 more errors\n") != NULL);
	free(text);
}

/* ---- defaults and values ----------------------------------------- */

static void test_defaults(void)
{
	struct px_config *c = NULL;
	const char *y = "devices:\n  - {name: d, backend: sim}\n";
	int rc = px_config_load_mem("d.yaml", y, strlen(y), &c, &g_diag);
	PX_CHECK_INT_EQ(rc, PX_OK);
	PX_CHECK_INT_EQ(c->version, 1);
	PX_CHECK_INT_EQ(c->loop.period_ns, 1000000);
	PX_CHECK_INT_EQ(c->loop.priority, 80);
	PX_CHECK_INT_EQ(c->loop.cpu, -1);
	PX_CHECK_INT_EQ(c->loop.overrun_policy, PX_CONFIG_OVERRUN_SKIP);
	PX_CHECK_INT_EQ(c->loop.max_consecutive_overruns, 10);
	PX_CHECK(c->loop.lock_memory && !c->loop.dma_latency);
	PX_CHECK_NEAR(c->safety.max_force_n, 10.0, 0);
	PX_CHECK_NEAR(c->safety.max_force_rate_n_per_s, 1000.0, 0);
	PX_CHECK_NEAR(c->safety.velocity_limit_m_per_s, 1.0, 0);
	PX_CHECK_INT_EQ(c->safety.watchdog.device_timeout_ns, 50000000);
	PX_CHECK_INT_EQ(c->safety.watchdog.compute_budget_ns, 0);
	PX_CHECK_INT_EQ(c->safety.watchdog.max_over_budget, 3);
	PX_CHECK(!c->safety.watchdog.auto_rearm);
	PX_CHECK(!c->safety.estop.present && !c->safety.enable.present);
	PX_CHECK(c->telemetry.file == NULL);
	PX_CHECK_INT_EQ(c->telemetry.decimation, 1);
	PX_CHECK_INT_EQ(c->n_devices, 1);
	PX_CHECK(strcmp(c->devices[0].name, "d") == 0);
	PX_CHECK_INT_EQ(c->devices[0].backend, PX_CONFIG_BACKEND_SIM);
	PX_CHECK(!c->devices[0].has_sim);
	/* Absent sim sub-map: its defaults still apply. */
	PX_CHECK_INT_EQ(c->devices[0].sim.kind, PX_CONFIG_SIM_HAPTIC);
	PX_CHECK_NEAR(c->devices[0].sim.mass_kg, 0.1, 0);
	PX_CHECK_INT_EQ(c->devices[0].sim.trajectory.kind, PX_CONFIG_TRAJ_HOLD);
	PX_CHECK(c->devices[0].sim.trajectory.repeat);
	PX_CHECK(c->scene == NULL && c->control == NULL && c->sim == NULL);
	PX_CHECK(px_config_device_find(c, "d") == &c->devices[0]);
	PX_CHECK(px_config_device_find(c, "e") == NULL);
	px_config_free(c);

	/* Sections written but emptied out are fine too. */
	expect_ok("loop:\nsafety:\ntelemetry:\ndevices:\nscene:\ncontrol: ~\n");
	expect_ok("loop: {}\n");
}

static void test_values_read(void)
{
	struct px_config *c = NULL;
	const char *y =
		"loop:\n"
		"  period_ns: 250_000\n"
		"  priority: +99\n"
		"  cpu: 0x3\n"
		"  overrun_policy: catch_up\n"
		"  lock_memory: False\n"
		"  dma_latency: TRUE\n"
		"safety: {max_force_n: 1_000.25e-1, velocity_limit_m_per_s: .5}\n"
		"telemetry: {file: 'out.csv', decimation: 7}\n"
		"scene: {models: []}\n"
		"control: {}\n"
		"sim: &s {faults: [drop]}\n"
		"devices:\n"
		"  - name: can.1\n"
		"    backend: socketcan\n"
		"    socketcan:\n"
		"      interface: vcan0\n"
		"      fd: true\n"
		"      signals:\n"
		"        - {name: m, id: 0x123, direction: output, start_bit: 7,\n"
		"           length: 16, byte_order: big, signed: true,\n"
		"           scale: -0.5, min: -10, max: 10}\n"
		"      canopen: {drives: [{node_id: 127, joint: 63, mode: cst}]}\n";
	int rc = px_config_load_mem("v.yaml", y, strlen(y), &c, &g_diag);
	if (rc)
		dump_diag();
	PX_CHECK_INT_EQ(rc, PX_OK);
	PX_CHECK_INT_EQ(c->loop.period_ns, 250000);
	PX_CHECK_INT_EQ(c->loop.priority, 99);
	PX_CHECK_INT_EQ(c->loop.cpu, 3);
	PX_CHECK_INT_EQ(c->loop.overrun_policy, PX_CONFIG_OVERRUN_CATCH_UP);
	PX_CHECK(!c->loop.lock_memory && c->loop.dma_latency);
	PX_CHECK_NEAR(c->safety.max_force_n, 100.025, 0);
	PX_CHECK_NEAR(c->safety.velocity_limit_m_per_s, 0.5, 0);
	PX_CHECK(strcmp(c->telemetry.file, "out.csv") == 0);
	PX_CHECK_INT_EQ(c->telemetry.decimation, 7);
	PX_CHECK(c->scene && c->scene->kind == PX_CONFIG_NODE_MAP);
	PX_CHECK(c->scene->line == 10 && c->scene->column == 8);
	PX_CHECK(c->control && c->control->len == 0);
	PX_CHECK(px_config_node_get(c->sim, "faults")->kind == PX_CONFIG_NODE_SEQ);
	PX_CHECK_INT_EQ(c->n_devices, 1);
	{
		const struct px_config_socketcan *s = &c->devices[0].socketcan;
		PX_CHECK(c->devices[0].has_socketcan && s->fd);
		PX_CHECK_INT_EQ(s->n_signals, 1);
		PX_CHECK_INT_EQ(s->signals[0].id, 0x123);
		PX_CHECK_INT_EQ(s->signals[0].direction, PX_CONFIG_SIGNAL_OUTPUT);
		PX_CHECK_INT_EQ(s->signals[0].byte_order, PX_CONFIG_BIG_ENDIAN);
		PX_CHECK(s->signals[0].is_signed);
		PX_CHECK(s->signals[0].has_min && s->signals[0].has_max);
		PX_CHECK_NEAR(s->signals[0].scale, -0.5, 0);
		PX_CHECK(s->canopen.present && s->canopen.sync);
		PX_CHECK_INT_EQ(s->canopen.heartbeat_timeout_ns, 300000000);
		PX_CHECK_INT_EQ(s->canopen.n_drives, 1);
		PX_CHECK_INT_EQ(s->canopen.drives[0].node_id, 127);
		PX_CHECK_INT_EQ(s->canopen.drives[0].mode, PX_CONFIG_CIA402_CST);
	}
	px_config_free(c);
}

/* ---- the document tree ------------------------------------------- */

static void test_doc_tree(void)
{
	struct px_config_doc *d = NULL;
	const struct px_config_node *root, *n;
	const char *y = "# comment\n"
			"a: &x\n"
			"  - 1\n"
			"  - 'two'\n"
			"  - {k: v}\n"
			"b: *x\n"
			"c: |\n"
			"  text\n"
			"d: !!str 12\n"
			"e:\n"
			"f: \"nul\\0here\"\n";
	int rc = px_config_doc_load_mem("doc", y, strlen(y), &d, &g_diag);
	PX_CHECK_INT_EQ(rc, PX_OK);
	PX_CHECK(strcmp(px_config_doc_name(d), "doc") == 0);
	root = px_config_doc_root(d);
	PX_CHECK(root->kind == PX_CONFIG_NODE_MAP && root->len == 6);
	PX_CHECK(root->line == 2 && root->column == 1);
	PX_CHECK(strcmp(root->file, "doc") == 0);
	n = px_config_node_get(root, "a");
	PX_CHECK(n->kind == PX_CONFIG_NODE_SEQ && n->len == 3);
	/* A node starts at its properties (anchor, tag) when it has any. */
	PX_CHECK(n->line == 2 && n->column == 4);
	PX_CHECK(n->items[0]->kind == PX_CONFIG_NODE_SCALAR && !n->items[0]->quoted);
	PX_CHECK(n->items[1]->quoted && strcmp(n->items[1]->str, "two") == 0);
	PX_CHECK(n->items[1]->line == 4 && n->items[1]->column == 5);
	PX_CHECK(n->items[2]->kind == PX_CONFIG_NODE_MAP);
	PX_CHECK(n->items[2]->pairs[0].value->column == 9);
	/* An alias is the anchored node itself. */
	PX_CHECK(px_config_node_get(root, "b") == n);
	n = px_config_node_get(root, "c");
	PX_CHECK(n->quoted && strcmp(n->str, "text\n") == 0);
	PX_CHECK(px_config_node_get(root, "d")->quoted);
	PX_CHECK(px_config_node_is_null(px_config_node_get(root, "e")));
	n = px_config_node_get(root, "f");
	PX_CHECK(n->len == 8 && memcmp(n->str, "nul\0here", 8) == 0);
	PX_CHECK(px_config_node_get(root, "g") == NULL);
	PX_CHECK(px_config_node_get(n, "x") == NULL);
	px_config_doc_free(d);

	/* Strings with NUL bytes are refused where a C string is needed. */
	expect_error("telemetry: {file: \"a\\0b\"}\n",
		     "t.yaml:1:19: telemetry.file: string contains a NUL "
		     "character");
	/* Empty input is a document without root. */
	rc = px_config_doc_load_mem(NULL, "", 0, &d, &g_diag);
	PX_CHECK_INT_EQ(rc, PX_OK);
	PX_CHECK(px_config_doc_root(d) == NULL);
	PX_CHECK(strcmp(px_config_doc_name(d), "<memory>") == 0);
	px_config_doc_free(d);
	px_config_doc_free(NULL);
	px_config_free(NULL);
	PX_CHECK_INT_EQ(px_config_doc_load_mem("x", NULL, 1, &d, &g_diag),
			PX_E_INVAL);
	PX_CHECK(d == NULL);
}

static void test_load_file_errors(void)
{
	struct px_config *c = (struct px_config *)&c;
	int rc = px_config_load_file("/nonexistent/robot.yaml", &c, &g_diag);
	PX_CHECK_INT_EQ(rc, PX_E_IO);
	PX_CHECK(c == NULL);
	PX_CHECK(has_msg("/nonexistent/robot.yaml: cannot open: No such file "
			 "or directory"));
	rc = px_config_load_file("config", &c, &g_diag);
	PX_CHECK_INT_EQ(rc, PX_E_IO);
	PX_CHECK(has_msg("config: cannot read: Is a directory"));
	PX_CHECK_INT_EQ(px_config_load_file(NULL, &c, &g_diag), PX_E_INVAL);
}

/* ---- generic reader on a schema of our own ----------------------- */

struct gen {
	int64_t i;
	int64_t xs_fixed[2];
	int64_t *xs;
	size_t n_xs;
	int *modes;
	size_t n_modes;
	double d;
	const char *s;
	bool has_d;
};

static const char *const gen_modes[] = {"a", "bb", NULL};

static const struct px_config_key gen_keys[] = {
	{.name = "i", .type = PX_CONFIG_T_INT64, .offset = offsetof(struct gen, i),
	 .idef = 7},
	{.name = "fixed", .type = PX_CONFIG_T_INT64,
	 .offset = offsetof(struct gen, xs_fixed), .fixed_count = 2, .idef = -1},
	{.name = "xs", .type = PX_CONFIG_T_SEQ, .offset = offsetof(struct gen, xs),
	 .count_offset = offsetof(struct gen, n_xs), .elem = PX_CONFIG_T_INT64,
	 .flags = PX_CONFIG_HAS_MIN | PX_CONFIG_HAS_MAX, .imin = 0, .imax = 9,
	 .max_count = 4},
	{.name = "modes", .type = PX_CONFIG_T_SEQ,
	 .offset = offsetof(struct gen, modes),
	 .count_offset = offsetof(struct gen, n_modes), .elem = PX_CONFIG_T_ENUM,
	 .names = gen_modes, .min_count = 1},
	{.name = "d", .type = PX_CONFIG_T_DOUBLE, .offset = offsetof(struct gen, d),
	 .flags = PX_CONFIG_PRESENT | PX_CONFIG_REQUIRED,
	 .present_offset = offsetof(struct gen, has_d)},
	{.name = "s", .type = PX_CONFIG_T_STRING, .offset = offsetof(struct gen, s),
	 .sdef = "dflt"},
};

static const struct px_config_schema gen_schema = {
	"gen", gen_keys, sizeof(gen_keys) / sizeof(gen_keys[0]), NULL};

static int read_gen(const char *y, struct gen *g, struct px_config_doc **d)
{
	int rc = px_config_doc_load_mem("g", y, strlen(y), d, &g_diag);
	PX_CHECK_INT_EQ(rc, PX_OK);
	return px_config_read(*d, px_config_doc_root(*d), "top", &gen_schema, g,
			      &g_diag);
}

static void test_generic_reader(void)
{
	struct px_config_doc *d = NULL;
	struct gen g;
	char why[200];
	int rc;
	PX_CHECK_INT_EQ(px_config_schema_validate(&gen_schema, why, sizeof(why)),
			PX_OK);
	rc = read_gen("d: 2.5\nxs: [0, 9, 3]\nmodes: [bb, a]\nfixed: [4, 5]\n",
		      &g, &d);
	PX_CHECK_INT_EQ(rc, PX_OK);
	PX_CHECK_INT_EQ(g.i, 7);
	PX_CHECK(g.has_d && g.d == 2.5);
	PX_CHECK_INT_EQ(g.n_xs, 3);
	PX_CHECK(g.xs[0] == 0 && g.xs[1] == 9 && g.xs[2] == 3);
	PX_CHECK(g.n_modes == 2 && g.modes[0] == 1 && g.modes[1] == 0);
	PX_CHECK(g.xs_fixed[0] == 4 && g.xs_fixed[1] == 5);
	PX_CHECK(strcmp(g.s, "dflt") == 0);
	px_config_doc_free(d);

	px_config_diag_init(&g_diag);
	rc = read_gen("xs: [0, 10, 1, 2, 3]\nmodes: []\nfixed: [1, z]\n", &g, &d);
	PX_CHECK_INT_EQ(rc, PX_E_PARSE);
	PX_CHECK(has_msg("g:1:5: top.xs: has 5 entries; at most 4 allowed"));
	PX_CHECK(has_msg("g:2:8: top.modes: has 0 entries; at least 1 needed"));
	PX_CHECK(has_msg("g:3:12: top.fixed[1]: expected an integer, got 'z'"));
	PX_CHECK(has_msg("g:1:1: top.d: missing required key"));
	/* A half-bad fixed array keeps its defaults. */
	PX_CHECK(g.xs_fixed[0] == -1 && g.xs_fixed[1] == -1);
	PX_CHECK(!g.has_d);
	px_config_doc_free(d);

	px_config_diag_init(&g_diag);
	rc = read_gen("d: 1\nxs: [0, 10]\nmodes: [c]\n", &g, &d);
	PX_CHECK_INT_EQ(rc, PX_E_PARSE);
	PX_CHECK(has_msg("g:2:9: top.xs[1]: 10 is out of range [0, 9]"));
	PX_CHECK(has_msg("g:3:9: top.modes[0]: unknown value 'c' (expected one "
			 "of: a, bb)"));
	px_config_doc_free(d);

	PX_CHECK_INT_EQ(px_config_read(NULL, NULL, "", &gen_schema, &g, NULL),
			PX_E_INVAL);
}

/* Integers and doubles written in every accepted form read back exactly. */
static void test_random_numbers(void)
{
	struct px_config_doc *d = NULL;
	struct gen g;
	char y[200], digits[64];
	int it;
	for (it = 0; it < 2000; it++) {
		int64_t v = (int64_t)px_rand_u64();
		double x;
		int form = px_rand_int(0, 2), rc;
		if (px_rand_int(0, 3) == 0)
			v >>= px_rand_int(0, 62);
		if (form == 0) {
			snprintf(digits, sizeof(digits), "%" PRId64, v);
		} else if (form == 1) {
			uint64_t m = v < 0 ? 0 - (uint64_t)v : (uint64_t)v;
			snprintf(digits, sizeof(digits), "%s0x%" PRIX64,
				 v < 0 ? "-" : "", m);
		} else {
			/* Thousands separators. */
			char raw[32];
			size_t n, i, o = 0, start;
			snprintf(raw, sizeof(raw), "%" PRId64, v);
			n = strlen(raw);
			start = raw[0] == '-';
			for (i = 0; i < n; i++) {
				digits[o++] = raw[i];
				if (i >= start && i + 1 < n &&
				    (n - 1 - i) % 3 == 0)
					digits[o++] = '_';
			}
			digits[o] = '\0';
		}
		x = px_rand_normal() * pow(10.0, px_rand_int(-300, 300));
		snprintf(y, sizeof(y), "i: %s\nd: %.17g\nmodes: [a]\n", digits, x);
		px_config_diag_init(&g_diag);
		rc = read_gen(y, &g, &d);
		if (rc)
			dump_diag();
		PX_CHECK_MSG(rc == PX_OK, "%s", y);
		PX_CHECK_MSG(g.i == v, "%s -> %" PRId64, digits, g.i);
		PX_CHECK_MSG(g.d == x, "%.17g -> %.17g", x, g.d);
		px_config_doc_free(d);
	}
	/* The int64 edges. */
	px_config_diag_init(&g_diag);
	PX_CHECK_INT_EQ(read_gen("i: -9223372036854775808\nd: 0\nmodes: [a]\n",
				 &g, &d),
			PX_OK);
	PX_CHECK(g.i == INT64_MIN);
	px_config_doc_free(d);
	PX_CHECK_INT_EQ(read_gen("i: 0x7fffffffffffffff\nd: 0\nmodes: [a]\n",
				 &g, &d),
			PX_OK);
	PX_CHECK(g.i == INT64_MAX);
	px_config_doc_free(d);
	PX_CHECK_INT_EQ(read_gen("i: 9223372036854775808\nd: 0\nmodes: [a]\n",
				 &g, &d),
			PX_E_PARSE);
	px_config_doc_free(d);
	PX_CHECK_INT_EQ(read_gen("i: -0x8000000000000001\nd: 0\nmodes: [a]\n",
				 &g, &d),
			PX_E_PARSE);
	px_config_doc_free(d);
}

/* ---- every range of every key ------------------------------------ */

static union {
	max_align_t align;
	unsigned char bytes[1 << 16];
} scratch;

/* Read "name: val" with schema s alone; the key's range error is there or
 * not. */
static void range_case(const struct px_config_schema *s,
		       const struct px_config_key *k, const char *val,
		       bool want_err)
{
	char y[256], path[128], prefix[300];
	struct px_config_doc *d = NULL;
	const struct px_config_error *e;
	snprintf(y, sizeof(y), "%s: %s\n", k->name, val);
	px_config_diag_init(&g_diag);
	PX_CHECK_INT_EQ(px_config_doc_load_mem("r", y, strlen(y), &d, &g_diag),
			PX_OK);
	px_config_read(d, px_config_doc_root(d), s->name, s, scratch.bytes,
		       &g_diag);
	snprintf(path, sizeof(path), "%s.%s", s->name, k->name);
	e = px_config_diag_find(&g_diag, path);
	if (want_err) {
		snprintf(prefix, sizeof(prefix), "r:1:%d: %s: %s is out of range",
			 (int)strlen(k->name) + 3, path, val);
		PX_CHECK_MSG(e && strncmp(e->msg, prefix, strlen(prefix)) == 0,
			     "%s: %s accepted or wrong message (%s)", path, val,
			     e ? e->msg : "no error");
	} else {
		/* Relations checked elsewhere (a standard CAN id must fit in
		 * 11 bits) may still complain; the range must not. */
		int i;
		for (i = 0; i < g_diag.count; i++) {
			e = &g_diag.errors[i];
			PX_CHECK_MSG(strcmp(e->path, path) != 0 ||
					     !strstr(e->msg, "out of range"),
				     "%s: %s refused: %s", path, val, e->msg);
		}
	}
	px_config_doc_free(d);
}

static void walk_ranges(const struct px_config_schema *s, int depth, int *n)
{
	size_t i;
	char v[64];
	PX_CHECK(depth < 16);
	PX_CHECK(sizeof(scratch) >= 4096);
	for (i = 0; i < s->n_keys; i++) {
		const struct px_config_key *k = &s->keys[i];
		if (k->sub)
			walk_ranges(k->sub, depth + 1, n);
		if (k->fixed_count)
			continue;
		if (k->type == PX_CONFIG_T_INT64 ||
		    k->type == PX_CONFIG_T_DURATION) {
			if (k->flags & PX_CONFIG_HAS_MIN) {
				snprintf(v, sizeof(v), "%lld", (long long)k->imin);
				range_case(s, k, v, false);
				if (k->imin > INT64_MIN) {
					snprintf(v, sizeof(v), "%lld",
						 (long long)k->imin - 1);
					range_case(s, k, v, true);
				}
			}
			if (k->flags & PX_CONFIG_HAS_MAX) {
				snprintf(v, sizeof(v), "%lld", (long long)k->imax);
				range_case(s, k, v, false);
				if (k->imax < INT64_MAX) {
					snprintf(v, sizeof(v), "%lld",
						 (long long)k->imax + 1);
					range_case(s, k, v, true);
				}
			}
			++*n;
		} else if (k->type == PX_CONFIG_T_DOUBLE) {
			if (k->flags & PX_CONFIG_HAS_MIN) {
				double below = k->dmin - (fabs(k->dmin) * 1e-9 + 1e-6);
				snprintf(v, sizeof(v), "%.17g", k->dmin);
				range_case(s, k, v, (k->flags & PX_CONFIG_MIN_EXCL) != 0);
				snprintf(v, sizeof(v), "%.17g", below);
				range_case(s, k, v, true);
			}
			if (k->flags & PX_CONFIG_HAS_MAX) {
				double above = k->dmax + (fabs(k->dmax) * 1e-9 + 1e-6);
				snprintf(v, sizeof(v), "%.17g", k->dmax);
				range_case(s, k, v, (k->flags & PX_CONFIG_MAX_EXCL) != 0);
				snprintf(v, sizeof(v), "%.17g", above);
				range_case(s, k, v, true);
			}
			++*n;
		}
	}
}

static void test_every_range_enforced(void)
{
	int n = 0;
	walk_ranges(px_config_schema_root(), 0, &n);
	/* The walk reached the nested sections (devices, codecs, CAN). */
	PX_CHECK_MSG(n >= 60, "only %d numeric keys walked", n);
}

/* ---- schemas and docs -------------------------------------------- */

static void test_schema_validate(void)
{
	static const struct px_config_key bad1[] = {
		{.name = "timeout", .type = PX_CONFIG_T_DURATION}};
	static const struct px_config_key bad2[] = {
		{.name = "n", .type = PX_CONFIG_T_INT64,
		 .flags = PX_CONFIG_HAS_MIN, .imin = 1, .idef = 0}};
	static const struct px_config_key bad3[] = {
		{.name = "a", .type = PX_CONFIG_T_BOOL},
		{.name = "a", .type = PX_CONFIG_T_BOOL}};
	static const struct px_config_key bad4[] = {
		{.name = "e", .type = PX_CONFIG_T_ENUM, .names = gen_modes,
		 .idef = 2}};
	const struct px_config_schema s1 = {"s1", bad1, 1, NULL},
				      s2 = {"s2", bad2, 1, NULL},
				      s3 = {"s3", bad3, 2, NULL},
				      s4 = {"s4", bad4, 1, NULL};
	char why[200];
	PX_CHECK_INT_EQ(px_config_schema_validate(px_config_schema_root(), why,
						  sizeof(why)),
			PX_OK);
	PX_CHECK_INT_EQ(px_config_schema_validate(&s1, why, sizeof(why)),
			PX_E_INVAL);
	PX_CHECK(strcmp(why, "s1.timeout: duration key must end in _ns") == 0);
	PX_CHECK_INT_EQ(px_config_schema_validate(&s2, why, sizeof(why)),
			PX_E_INVAL);
	PX_CHECK(strstr(why, "default out of range"));
	PX_CHECK_INT_EQ(px_config_schema_validate(&s3, why, sizeof(why)),
			PX_E_INVAL);
	PX_CHECK(strstr(why, "duplicate key"));
	PX_CHECK_INT_EQ(px_config_schema_validate(&s4, why, sizeof(why)),
			PX_E_INVAL);
	PX_CHECK(strstr(why, "enum default"));
}

static void test_docs_cover_every_key(void)
{
	char *docs = px_test_read_text("docs/config.md");
	if (!docs)
		PX_SKIP("docs/config.md not found (run from the source tree)");
	px_test_check_documented(docs, px_config_schema_root(), 16);
	free(docs);
}

/* ---- shipped examples -------------------------------------------- */

static int list_examples(char names[][300], int cap)
{
	DIR *dir = opendir("config/examples");
	struct dirent *e;
	int n = 0;
	if (!dir)
		return -1;
	while ((e = readdir(dir)) && n < cap) {
		size_t l = strlen(e->d_name);
		if (l > 5 && strcmp(e->d_name + l - 5, ".yaml") == 0)
			snprintf(names[n++], 300, "config/examples/%s",
				 e->d_name);
	}
	closedir(dir);
	return n;
}

static void test_examples_load(void)
{
	static char names[64][300];
	int n = list_examples(names, 64), i;
	struct px_config *c;
	if (n < 0)
		PX_SKIP("config/examples not found (run from the source tree)");
	PX_CHECK(n >= 3);
	for (i = 0; i < n; i++) {
		int rc = px_config_load_file(names[i], &c, &g_diag);
		if (rc)
			dump_diag();
		PX_CHECK_MSG(rc == PX_OK, "%s: %s", names[i], px_strerror(rc));
		PX_CHECK(c->n_devices >= 1);
		px_config_free(c);
	}
	/* The 3Dconnexion-class mapping means what the issue says. */
	PX_CHECK_INT_EQ(px_config_load_file("config/examples/spacemouse_hid.yaml",
					    &c, &g_diag),
			PX_OK);
	{
		const struct px_config_hidapi *h = &c->devices[0].hidapi;
		PX_CHECK_INT_EQ(c->devices[0].backend, PX_CONFIG_BACKEND_HIDAPI);
		PX_CHECK_INT_EQ(h->codec.n_inputs, 6);
		for (i = 0; i < 6; i++) {
			const struct px_config_field *f = &h->codec.inputs[i];
			PX_CHECK_INT_EQ(f->report_id, i < 3 ? 1 : 2);
			PX_CHECK_INT_EQ(f->byte_offset, 2 * (i % 3));
			PX_CHECK_INT_EQ(f->bit_width, 16);
			PX_CHECK(f->is_signed);
			PX_CHECK_INT_EQ(f->byte_order, PX_CONFIG_LITTLE_ENDIAN);
			PX_CHECK_INT_EQ(f->axis, PX_CONFIG_AXIS_X + i);
		}
		PX_CHECK_INT_EQ(h->codec.n_buttons, 1);
		PX_CHECK_INT_EQ(h->codec.buttons[0].report_id, 3);
	}
	px_config_free(c);
}

/* Every prefix and many random corruptions of the examples load or fail
 * cleanly, with a placed first message. */
static void test_examples_mutated(void)
{
	static char names[64][300];
	int n = list_examples(names, 64), i, it;
	if (n < 0)
		PX_SKIP("config/examples not found (run from the source tree)");
	for (i = 0; i < n; i++) {
		char *text = px_test_read_text(names[i]), *buf;
		size_t len, cut;
		PX_CHECK(text != NULL);
		len = strlen(text);
		buf = malloc(len + 1);
		PX_CHECK(buf != NULL);
		for (cut = 0; cut <= len; cut += 7) {
			struct px_config *c = NULL;
			int rc = px_config_load_mem(names[i], text, cut, &c,
						    &g_diag);
			PX_CHECK(rc == PX_OK || rc == PX_E_PARSE);
			PX_CHECK(rc == PX_OK ? c != NULL
					     : (c == NULL && g_diag.count > 0 &&
						g_diag.errors[0].line >= 1));
			px_config_free(c);
		}
		for (it = 0; it < 300; it++) {
			struct px_config *c = NULL;
			int k, rc;
			memcpy(buf, text, len + 1);
			for (k = px_rand_int(1, 4); k > 0; k--)
				buf[px_rand_int(0, (int)len - 1)] =
					(char)px_rand_int(0, 255);
			rc = px_config_load_mem(names[i], buf, len, &c, &g_diag);
			PX_CHECK(rc == PX_OK || rc == PX_E_PARSE);
			PX_CHECK(rc == PX_OK || g_diag.count > 0);
			px_config_free(c);
		}
		free(buf);
		free(text);
	}
}

static const struct px_test tests[] = {
	PX_T(test_message_format),
	PX_T(test_yaml_errors),
	PX_T(test_duplicates_all_reported),
	PX_T(test_nesting_and_alias_limits),
	PX_T(test_value_errors),
	PX_T(test_device_errors),
	PX_T(test_safety_line_refs),
	PX_T(test_timing_relations),
	PX_T(test_collects_all_errors),
	PX_T(test_error_cap),
	PX_T(test_defaults),
	PX_T(test_values_read),
	PX_T(test_doc_tree),
	PX_T(test_load_file_errors),
	PX_T(test_generic_reader),
	PX_T(test_random_numbers),
	PX_T(test_every_range_enforced),
	PX_T(test_schema_validate),
	PX_T(test_docs_cover_every_key),
	PX_T(test_examples_load),
	PX_T(test_examples_mutated),
};

PX_TEST_MAIN(tests)
