/* The application configuration: schema tables and cross-section checks.
 * Every key here is documented in docs/config.md (a test checks that). */
#include <stdlib.h>
#include <string.h>

#include "config_internal.h"
#include "schema_internal.h"

#define NS_PER_S 1000000000LL
#define BIG 1e12

/* ---- enum names (order = the C enums in px_config.h) ------------- */

static const char *const backend_names[] = {
	"sim", "hidapi", "libusb", "socketcan", "gpiod", "dds", NULL};
static const char *const overrun_names[] = {"skip", "catch_up", NULL};
static const char *const byte_order_names[] = {"little", "big", NULL};
static const char *const axis_names[] = {"x", "y", "z", "rx", "ry", "rz", NULL};
static const char *const xyz_names[] = {"x", "y", "z", NULL};
static const char *const wrench_names[] = {"fx", "fy", "fz",
					   "tx", "ty", "tz", NULL};
static const char *const signal_axis_names[] = {
	"none", "x", "y", "z", "rx", "ry", "rz",
	"fx", "fy", "fz", "tx", "ty", "tz", NULL};
static const char *const hid_driver_names[] = {"hidraw", "libusb", NULL};
static const char *const transfer_names[] = {"interrupt", "bulk", NULL};
static const char *const dir_names[] = {"input", "output", NULL};
static const char *const can_transport_names[] = {"kernel", "sim", "unix",
						  NULL};
static const char *const cia402_names[] = {"csp", "csv", "cst", NULL};
static const char *const sim_kind_names[] = {"haptic", "pose", "gpio", NULL};
static const char *const traj_names[] = {"hold", "sines", "csv", NULL};
/* enum px_config_fault_kind order (px_sim.h's numbering minus 1) */
static const char *const fault_names[] = {
	"drop", "delay", "duplicate", "corrupt", "stuck", "nan", "unplug",
	"bus_off", "estop", NULL};

const char *const *px_config_backend_names(void)
{
	return backend_names;
}

/* ---- helpers for checks ------------------------------------------ */

/* Node of map[key][idx][sub] as far as it exists (for error places). */
static const struct px_config_node *node_at(const struct px_config_node *map,
					    const char *key, size_t idx,
					    const char *sub)
{
	const struct px_config_node *n = px_config_node_get(map, key), *m;
	if (!n)
		return map;
	if (n->kind != PX_CONFIG_NODE_SEQ || idx >= n->len)
		return n;
	m = n->items[idx];
	if (sub && px_config_node_get(m, sub))
		return px_config_node_get(m, sub);
	return m;
}

static void sub_path(char *out, size_t cap, const char *key, size_t idx,
		     const char *sub)
{
	if (sub)
		snprintf(out, cap, "%s[%zu].%s", key, idx, sub);
	else
		snprintf(out, cap, "%s[%zu]", key, idx);
}

static void err_item(struct px_config_reader *r, const struct px_config_node *map,
		     const char *key, size_t idx, const char *sub,
		     const char *what)
{
	char p[96];
	sub_path(p, sizeof(p), key, idx, sub);
	px_config_reader_error(r, node_at(map, key, idx, sub), p, "%s", what);
}

/* A config string made safe for a one-line message (control bytes
 * escaped, long ones cut). Use as EX(s) inside one statement. */
struct exbuf {
	char s[112];
};

static const char *ex(struct exbuf *b, const char *s)
{
	px__cfg_excerpt(b->s, sizeof(b->s), s, strlen(s));
	return b->s;
}

#define EX(s) ex(&(struct exbuf){{0}}, (s))

/* Equal names; a name left NULL by an earlier error matches nothing. */
static bool same(const char *a, const char *b)
{
	return a && b && strcmp(a, b) == 0;
}

static bool valid_name(const char *s)
{
	if (!s || !*s)
		return false;
	for (; *s; s++)
		if (!((*s >= 'a' && *s <= 'z') || (*s >= 'A' && *s <= 'Z') ||
		      (*s >= '0' && *s <= '9') || *s == '_' || *s == '-' ||
		      *s == '.'))
			return false;
	return true;
}

const char *px__ros_name_problem(const char *s, size_t max)
{
	const char *p;
	int start = 1;
	if (!s || !*s)
		return "must not be empty";
	if (strlen(s) >= max)
		return "is too long";
	for (p = s; *p; p++) {
		char ch = *p;
		if (ch == '/') {
			if (start)
				return "has an empty token (a leading or "
				       "doubled '/')";
			start = 1;
			continue;
		}
		if (!((ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') ||
		      (ch >= '0' && ch <= '9') || ch == '_'))
			return "may hold only letters, digits, '_' and '/' "
			       "(ROS 2 name rules)";
		if (start && ch >= '0' && ch <= '9')
			return "has a token starting with a digit (ROS 2 "
			       "name rules)";
		start = 0;
	}
	return start ? "ends with '/'" : NULL;
}

/* ---- codec (hidapi, libusb, sim) --------------------------------- */

static void field_check(struct px_config_reader *r,
			const struct px_config_node *map, void *obj)
{
	const struct px_config_field *f = obj;
	if (!map)
		return;
	if (f->is_signed && f->bit_width < 2)
		px_config_reader_error(r, px_config_node_get(map, "signed"),
				       "signed",
				       "a signed field needs bit_width >= 2");
	if (f->byte_order == PX_CONFIG_BIG_ENDIAN && f->bit_width > 8 &&
	    (f->bit_offset != 0 || f->bit_width % 8 != 0))
		px_config_reader_error(r, px_config_node_get(map, "byte_order"),
				       "byte_order",
				       "big-endian fields wider than a byte must "
				       "start at bit 0 and be whole bytes");
	if (f->scale == 0.0)
		px_config_reader_error(r, px_config_node_get(map, "scale"),
				       "scale", "must not be 0");
}

#define FIELD_KEYS(T, axisnames)                                                \
	K_INT(T, report_id, "report_id", 0, 0, 255, 0),                         \
	K_INT(T, byte_offset, "byte_offset", PX_CONFIG_REQUIRED, 0, 1023, 0),   \
	K_INT(T, bit_offset, "bit_offset", 0, 0, 7, 0),                         \
	K_INT(T, bit_width, "bit_width", 0, 1, 64, 16),                         \
	K_BOOL(T, is_signed, "signed", 1),                                      \
	K_ENUM(T, byte_order, "byte_order", 0, byte_order_names,                \
	       PX_CONFIG_LITTLE_ENDIAN),                                        \
	K_DBL(T, scale, "scale", 0, -BIG, BIG, 1.0),                            \
	K_DBL(T, offset, "offset", 0, -BIG, BIG, 0.0),                          \
	K_ENUM(T, axis, "axis", PX_CONFIG_REQUIRED, axisnames, 0)

static const struct px_config_key input_keys[] = {
	FIELD_KEYS(struct px_config_field, axis_names),
};
SCHEMA(input_schema, "input", input_keys, field_check);

static const struct px_config_key output_keys[] = {
	FIELD_KEYS(struct px_config_field, wrench_names),
	K_DBL(struct px_config_field, max_abs, "max_abs", 0, 0, BIG, 0.0),
};
SCHEMA(output_schema, "output", output_keys, field_check);

static const struct px_config_key buttons_keys[] = {
	K_INT(struct px_config_buttons, report_id, "report_id", 0, 0, 255, 0),
	K_INT(struct px_config_buttons, byte_offset, "byte_offset",
	      PX_CONFIG_REQUIRED, 0, 1023, 0),
	K_INT(struct px_config_buttons, first_bit, "first_bit", 0, 0, 7, 0),
	K_INT(struct px_config_buttons, count, "count", 0, 1, 64, 1),
	K_INT(struct px_config_buttons, first_button, "first_button", 0, 0, 63,
	      0),
};

static void buttons_check(struct px_config_reader *r,
			  const struct px_config_node *map, void *obj)
{
	const struct px_config_buttons *b = obj;
	if (map && b->first_button + b->count > 64)
		px_config_reader_error(r, px_config_node_get(map, "count"),
				       "count",
				       "buttons %lld..%lld: at most 64 buttons "
				       "(0..63)",
				       (long long)b->first_button,
				       (long long)(b->first_button + b->count - 1));
}
SCHEMA(buttons_schema, "buttons", buttons_keys, buttons_check);

#define CODEC_KEYS(T)                                                           \
	K_SEQ(T, codec.inputs, codec.n_inputs, "inputs", 0, input_schema,       \
	      struct px_config_field, 0, 64),                                   \
	K_SEQ(T, codec.buttons, codec.n_buttons, "buttons", 0, buttons_schema,  \
	      struct px_config_buttons, 0, 16),                                 \
	K_SEQ(T, codec.outputs, codec.n_outputs, "outputs", 0, output_schema,   \
	      struct px_config_field, 0, 64),                                   \
	K_INT(T, codec.output_report_id, "output_report_id", 0, 0, 255, 0),     \
	K_INT(T, codec.output_report_len, "output_report_len", 0, 0, 1024, 0)

/* Relations inside a codec: one field per axis, outputs inside the
 * output report. */
static void codec_check(struct px_config_reader *r,
			const struct px_config_node *map,
			const struct px_config_codec *c)
{
	size_t i, j;
	char what[256];
	for (i = 0; i < c->n_inputs; i++)
		for (j = 0; j < i; j++)
			if (c->inputs[i].axis == c->inputs[j].axis) {
				snprintf(what, sizeof(what),
					 "axis '%s' is already mapped by "
					 "inputs[%zu]",
					 axis_names[c->inputs[i].axis], j);
				err_item(r, map, "inputs", i, "axis", what);
				break;
			}
	for (i = 0; i < c->n_outputs; i++) {
		const struct px_config_field *f = &c->outputs[i];
		for (j = 0; j < i; j++)
			if (f->axis == c->outputs[j].axis) {
				snprintf(what, sizeof(what),
					 "axis '%s' is already mapped by "
					 "outputs[%zu]",
					 wrench_names[f->axis], j);
				err_item(r, map, "outputs", i, "axis", what);
				break;
			}
		if (f->report_id != c->output_report_id) {
			snprintf(what, sizeof(what),
				 "%lld differs from output_report_id %lld",
				 (long long)f->report_id,
				 (long long)c->output_report_id);
			err_item(r, map, "outputs", i, "report_id", what);
		}
		if ((f->byte_offset * 8 + f->bit_offset + f->bit_width) >
		    c->output_report_len * 8) {
			snprintf(what, sizeof(what),
				 "field ends at bit %lld, past output_report_len "
				 "%lld bytes",
				 (long long)(f->byte_offset * 8 + f->bit_offset +
					     f->bit_width),
				 (long long)c->output_report_len);
			err_item(r, map, "outputs", i, "byte_offset", what);
		}
	}
}

/* ---- back ends --------------------------------------------------- */

static void hidapi_check(struct px_config_reader *r,
			 const struct px_config_node *map, void *obj)
{
	const struct px_config_hidapi *h = obj;
	if (!map)
		return;
	if (h->path && (h->has_vid || h->has_pid))
		px_config_reader_error(r, px_config_node_get(map, "path"), "path",
				       "give either path or vid and pid, not "
				       "both");
	else if (!h->path && !(h->has_vid && h->has_pid))
		px_config_reader_error(r, map, "",
				       "give either path, or vid and pid");
	if (h->serial && h->path)
		px_config_reader_error(r, px_config_node_get(map, "serial"),
				       "serial",
				       "serial selects among vid:pid matches; "
				       "not used with path");
	if (h->codec.n_inputs == 0 && h->codec.n_outputs == 0 &&
	    h->codec.n_buttons == 0)
		px_config_reader_error(r, map, "",
				       "maps no inputs, buttons or outputs");
	codec_check(r, map, &h->codec);
}

static const struct px_config_key hidapi_keys[] = {
	K_INTP(struct px_config_hidapi, vid, "vid", 0, 0, 0xffff, 0, has_vid),
	K_INTP(struct px_config_hidapi, pid, "pid", 0, 0, 0xffff, 0, has_pid),
	K_STR(struct px_config_hidapi, serial, "serial", 0),
	K_STR(struct px_config_hidapi, path, "path", 0),
	K_ENUM(struct px_config_hidapi, driver, "driver", 0, hid_driver_names,
	       PX_CONFIG_HID_HIDRAW),
	CODEC_KEYS(struct px_config_hidapi),
};
SCHEMA(hidapi_schema, "hidapi", hidapi_keys, hidapi_check);

static void libusb_check(struct px_config_reader *r,
			 const struct px_config_node *map, void *obj)
{
	const struct px_config_libusb *u = obj;
	size_t i;
	char what[256];
	if (!map)
		return;
	for (i = 0; i < u->codec.n_inputs; i++) {
		const struct px_config_field *f = &u->codec.inputs[i];
		if (f->byte_offset * 8 + f->bit_offset + f->bit_width >
		    u->frame_len * 8) {
			snprintf(what, sizeof(what),
				 "field ends past frame_len %lld bytes",
				 (long long)u->frame_len);
			err_item(r, map, "inputs", i, "byte_offset", what);
		}
	}
	codec_check(r, map, &u->codec);
}

static const struct px_config_key libusb_keys[] = {
	K_INT(struct px_config_libusb, vid, "vid", PX_CONFIG_REQUIRED, 0, 0xffff,
	      0),
	K_INT(struct px_config_libusb, pid, "pid", PX_CONFIG_REQUIRED, 0, 0xffff,
	      0),
	K_STR(struct px_config_libusb, serial, "serial", 0),
	K_INT(struct px_config_libusb, interface, "interface", 0, 0, 255, 0),
	K_INT(struct px_config_libusb, endpoint_in, "endpoint_in",
	      PX_CONFIG_REQUIRED, 0x81, 0x8f, 0x81),
	K_INT(struct px_config_libusb, endpoint_out, "endpoint_out", 0, 0, 0x0f,
	      0),
	K_ENUM(struct px_config_libusb, transfer, "transfer", 0, transfer_names,
	       PX_CONFIG_USB_INTERRUPT),
	K_INT(struct px_config_libusb, frame_len, "frame_len", 0, 1, 16384, 64),
	K_BOOL(struct px_config_libusb, detach_kernel_driver,
	       "detach_kernel_driver", 1),
	CODEC_KEYS(struct px_config_libusb),
	K_BOOL(struct px_config_libusb, no_hotplug, "no_hotplug", 0),
};
SCHEMA(libusb_schema, "libusb", libusb_keys, libusb_check);

/* ---- fault windows (sim devices, simulated CAN buses) ------------- */

static void fault_check(struct px_config_reader *r,
			const struct px_config_node *map, void *obj)
{
	struct px_config_fault *f = obj;
	int delay = f->kind == PX_CONFIG_FAULT_DELAY;
	if (!map)
		return;
	if (delay && f->delay_ns <= 0)
		px_config_reader_error(r, map, "delay_ns",
				       "missing or zero for kind 'delay'");
	if (!delay && f->delay_ns > 0)
		px_config_reader_error(r, px_config_node_get(map, "delay_ns"),
				       "delay_ns", "only for kind 'delay'");
}

static const struct px_config_key fault_keys[] = {
	{.name = "kind", .type = PX_CONFIG_T_ENUM,
	 .offset = offsetof(struct px_config_fault, kind),
	 .flags = PX_CONFIG_REQUIRED, .names = fault_names},
	K_DUR(struct px_config_fault, start_ns, "start_ns", PX_CONFIG_REQUIRED,
	      0, 1000000000000000LL, 0),
	K_DUR(struct px_config_fault, duration_ns, "duration_ns",
	      PX_CONFIG_REQUIRED, 1, 1000000000000000LL, 1),
	K_DBL(struct px_config_fault, probability, "probability",
	      PX_CONFIG_MIN_EXCL, 0, 1, 1.0),
	K_DUR(struct px_config_fault, delay_ns, "delay_ns", 0, 0, 10 * NS_PER_S,
	      0),
	K_INTP(struct px_config_fault, node_id, "node_id", 0, 1, 127, 1,
	       has_node_id),
};
SCHEMA(fault_schema, "fault", fault_keys, fault_check);

/* Kinds allowed by a back end: bit k for kind k. */
#define FK(k) (1u << (k))
static void faults_check(struct px_config_reader *r,
			 const struct px_config_node *map,
			 const struct px_config_fault *f, size_t n,
			 unsigned allowed, const char *why)
{
	size_t i;
	char what[256];
	for (i = 0; i < n; i++)
		if (!(allowed & FK(f[i].kind))) {
			snprintf(what, sizeof(what), "kind '%s' %s",
				 fault_names[f[i].kind], why);
			err_item(r, map, "faults", i, "kind", what);
		}
}

static const struct px_config_key filter_keys[] = {
	K_INT(struct px_config_can_filter, id, "id", PX_CONFIG_REQUIRED, 0,
	      0x1fffffff, 0),
	K_INT(struct px_config_can_filter, mask, "mask", 0, 0, 0x1fffffff,
	      0x7ff),
	K_BOOL(struct px_config_can_filter, extended, "extended", 0),
};

static void filter_check(struct px_config_reader *r,
			 const struct px_config_node *map, void *obj)
{
	const struct px_config_can_filter *f = obj;
	if (map && !f->extended && f->id > 0x7ff)
		px_config_reader_error(r, px_config_node_get(map, "id"), "id",
				       "0x%llx needs extended: true (standard "
				       "ids are 11 bits)",
				       (unsigned long long)f->id);
	if (map && !f->extended && f->mask > 0x7ff)
		px_config_reader_error(r, px_config_node_get(map, "mask"), "mask",
				       "0x%llx is wider than a standard 11-bit "
				       "id",
				       (unsigned long long)f->mask);
}
SCHEMA(filter_schema, "filter", filter_keys, filter_check);

/* Last bit (in DBC numbering, byte * 8 + bit) a signal touches. */
static int64_t signal_end_bit(const struct px_config_can_signal *s)
{
	int64_t pos = s->start_bit, i;
	if (s->byte_order == PX_CONFIG_LITTLE_ENDIAN)
		return s->start_bit + s->length - 1;
	/* Motorola: start_bit is the MSB; walk down to the LSB, moving to
	 * the next byte's bit 7 after bit 0. */
	for (i = 1; i < s->length; i++)
		pos = (pos % 8 == 0) ? pos + 15 : pos - 1;
	return pos;
}

static void signal_check(struct px_config_reader *r,
			 const struct px_config_node *map, void *obj)
{
	const struct px_config_can_signal *s = obj;
	if (!map)
		return;
	if (!s->extended && s->id > 0x7ff)
		px_config_reader_error(r, px_config_node_get(map, "id"), "id",
				       "0x%llx needs extended: true (standard "
				       "ids are 11 bits)",
				       (unsigned long long)s->id);
	if (s->is_signed && s->length < 2)
		px_config_reader_error(r, px_config_node_get(map, "signed"),
				       "signed",
				       "a signed signal needs length >= 2");
	if (s->scale == 0.0)
		px_config_reader_error(r, px_config_node_get(map, "scale"),
				       "scale", "must not be 0");
	if (s->is_float && s->length != 32 && s->length != 64)
		px_config_reader_error(r, px_config_node_get(map, "length"),
				       "length",
				       "a float signal is 32 (binary32) or 64 "
				       "(binary64) bits long");
	if (s->is_float && s->is_signed)
		px_config_reader_error(r, px_config_node_get(map, "signed"),
				       "signed",
				       "does not apply to a float signal");
	if (s->has_min && s->has_max && !(s->min < s->max))
		px_config_reader_error(r, px_config_node_get(map, "max"), "max",
				       "must be greater than min");
	if (s->direction == PX_CONFIG_SIGNAL_INPUT &&
	    s->axis >= PX_CONFIG_SIGNAL_AXIS_FX)
		px_config_reader_error(r, px_config_node_get(map, "axis"),
				       "axis",
				       "an input signal feeds a pose axis (x, "
				       "y, z, rx, ry, rz), not '%s'",
				       signal_axis_names[s->axis]);
	if (s->direction == PX_CONFIG_SIGNAL_OUTPUT &&
	    s->axis != PX_CONFIG_SIGNAL_AXIS_NONE &&
	    s->axis < PX_CONFIG_SIGNAL_AXIS_FX)
		px_config_reader_error(r, px_config_node_get(map, "axis"),
				       "axis",
				       "an output signal carries a force or "
				       "torque (fx, fy, fz, tx, ty, tz), not "
				       "'%s'",
				       signal_axis_names[s->axis]);
}

static const struct px_config_key signal_keys[] = {
	K_STR(struct px_config_can_signal, name, "name", PX_CONFIG_REQUIRED),
	K_INT(struct px_config_can_signal, id, "id", PX_CONFIG_REQUIRED, 0,
	      0x1fffffff, 0),
	K_BOOL(struct px_config_can_signal, extended, "extended", 0),
	K_ENUM(struct px_config_can_signal, direction, "direction",
	       PX_CONFIG_REQUIRED, dir_names, 0),
	K_INT(struct px_config_can_signal, start_bit, "start_bit",
	      PX_CONFIG_REQUIRED, 0, 511, 0),
	K_INT(struct px_config_can_signal, length, "length", PX_CONFIG_REQUIRED,
	      1, 64, 1),
	K_ENUM(struct px_config_can_signal, byte_order, "byte_order", 0,
	       byte_order_names, PX_CONFIG_LITTLE_ENDIAN),
	K_BOOL(struct px_config_can_signal, is_signed, "signed", 0),
	K_DBL(struct px_config_can_signal, scale, "scale", 0, -BIG, BIG, 1.0),
	K_DBL(struct px_config_can_signal, offset, "offset", 0, -BIG, BIG, 0.0),
	K_DBLPD(struct px_config_can_signal, min, "min", 0, -BIG, BIG, 0,
		has_min),
	K_DBLPD(struct px_config_can_signal, max, "max", 0, -BIG, BIG, 0,
		has_max),
	K_ENUM(struct px_config_can_signal, axis, "axis", 0, signal_axis_names,
	       PX_CONFIG_SIGNAL_AXIS_NONE),
	K_BOOL(struct px_config_can_signal, is_float, "float", 0),
};
SCHEMA(signal_schema, "signal", signal_keys, signal_check);

static const struct px_config_key drive_keys[] = {
	K_INT(struct px_config_canopen_drive, node_id, "node_id",
	      PX_CONFIG_REQUIRED, 1, 127, 1),
	K_ENUM(struct px_config_canopen_drive, mode, "mode", 0, cia402_names,
	       PX_CONFIG_CIA402_CSP),
	K_INT(struct px_config_canopen_drive, joint, "joint", PX_CONFIG_REQUIRED,
	      0, 63, 0),
	{.name = "counts_per_unit", .type = PX_CONFIG_T_DOUBLE,
	 .offset = offsetof(struct px_config_canopen_drive, counts_per_unit),
	 .flags = RANGE | PX_CONFIG_MIN_EXCL | PX_CONFIG_PRESENT, .dmin = 0.0,
	 .dmax = BIG, .ddef = 1.0,
	 .present_offset = offsetof(struct px_config_canopen_drive,
				    has_counts_per_unit)},
	K_DBL(struct px_config_canopen_drive, rated_torque_n_m,
	      "rated_torque_n_m", PX_CONFIG_MIN_EXCL, 0.0, BIG, 1.0),
};
SCHEMA(drive_schema, "drive", drive_keys, NULL);

static const struct px_config_key pdo_entry_keys[] = {
	K_INT(struct px_config_pdo_entry, index, "index", PX_CONFIG_REQUIRED,
	      0x1000, 0xffff, 0x1000),
	K_INT(struct px_config_pdo_entry, subindex, "subindex", 0, 0, 255, 0),
	K_INT(struct px_config_pdo_entry, bits, "bits", PX_CONFIG_REQUIRED, 1,
	      64, 8),
};
SCHEMA(pdo_entry_schema, "pdo entry", pdo_entry_keys, NULL);

static void canopen_check(struct px_config_reader *r,
			  const struct px_config_node *map, void *obj)
{
	const struct px_config_canopen *c = obj;
	size_t i, j;
	char what[256];
	if (!map)
		return;
	for (i = 0; i < c->n_drives; i++) {
		if (c->has_node_id && c->drives[i].node_id == c->node_id) {
			snprintf(what, sizeof(what),
				 "node id %lld is the master's own (canopen."
				 "node_id)",
				 (long long)c->node_id);
			err_item(r, map, "drives", i, "node_id", what);
		}
		for (j = 0; j < i; j++) {
			if (c->drives[i].node_id == c->drives[j].node_id) {
				snprintf(what, sizeof(what),
					 "node id %lld is already used by "
					 "drives[%zu]",
					 (long long)c->drives[i].node_id, j);
				err_item(r, map, "drives", i, "node_id", what);
			}
			if (c->drives[i].joint == c->drives[j].joint) {
				snprintf(what, sizeof(what),
					 "joint %lld is already driven by "
					 "drives[%zu]",
					 (long long)c->drives[i].joint, j);
				err_item(r, map, "drives", i, "joint", what);
			}
		}
	}
	if (c->heartbeat_timeout_ns && c->heartbeat_period_ns &&
	    c->heartbeat_timeout_ns <= c->heartbeat_period_ns)
		px_config_reader_error(r,
				       px_config_node_get(map,
							  "heartbeat_timeout_ns"),
				       "heartbeat_timeout_ns",
				       "must be longer than heartbeat_period_ns");
}

static const struct px_config_key canopen_keys[] = {
	K_BOOL(struct px_config_canopen, sync, "sync", 1),
	K_DUR(struct px_config_canopen, heartbeat_period_ns,
	      "heartbeat_period_ns", 0, 0, 10 * NS_PER_S, 100000000),
	K_DUR(struct px_config_canopen, heartbeat_timeout_ns,
	      "heartbeat_timeout_ns", 0, 0, 10 * NS_PER_S, 300000000),
	K_SEQ(struct px_config_canopen, drives, n_drives, "drives", 0,
	      drive_schema, struct px_config_canopen_drive, 0, 64),
	K_SEQ(struct px_config_canopen, rpdo, n_rpdo, "rpdo", 0,
	      pdo_entry_schema, struct px_config_pdo_entry, 0, 8),
	K_SEQ(struct px_config_canopen, tpdo1, n_tpdo1, "tpdo1", 0,
	      pdo_entry_schema, struct px_config_pdo_entry, 0, 8),
	K_SEQ(struct px_config_canopen, tpdo2, n_tpdo2, "tpdo2", 0,
	      pdo_entry_schema, struct px_config_pdo_entry, 0, 8),
	K_INTP(struct px_config_canopen, node_id, "node_id", 0, 1, 127, 127,
	       has_node_id),
};
SCHEMA(canopen_schema, "canopen", canopen_keys, canopen_check);

static void socketcan_check(struct px_config_reader *r,
			    const struct px_config_node *map, void *obj)
{
	const struct px_config_socketcan *c = obj;
	int64_t frame_bits = c->fd ? 64 * 8 : 8 * 8;
	size_t i, j;
	char what[256];
	if (!map)
		return;
	if (c->transport == PX_CONFIG_CAN_UNIX && !c->socket_path)
		px_config_reader_error(r, map, "socket_path",
				       "missing required key (transport is "
				       "'unix')");
	if (c->transport != PX_CONFIG_CAN_UNIX && c->socket_path)
		px_config_reader_error(r, px_config_node_get(map, "socket_path"),
				       "socket_path",
				       "only used with transport 'unix'");
	for (i = 0; i < c->n_faults; i++) {
		const struct px_config_fault *f = &c->faults[i];
		if (!f->has_node_id && c->transport == PX_CONFIG_CAN_KERNEL) {
			err_item(r, map, "faults", i, NULL,
				 "bus faults are injected on simulated buses "
				 "only (transport 'sim' or 'unix'); a fault "
				 "with node_id goes to the simulated arm");
		} else if (!f->has_node_id &&
			   f->kind == PX_CONFIG_FAULT_ESTOP) {
			err_item(r, map, "faults", i, "kind",
				 "kind 'estop' is not a CAN bus fault: give the "
				 "node_id of the simulated arm's drive it "
				 "stops, or use a GPIO e-stop line");
		} else if (f->has_node_id &&
			   f->kind != PX_CONFIG_FAULT_ESTOP &&
			   f->kind != PX_CONFIG_FAULT_UNPLUG) {
			err_item(r, map, "faults", i, "node_id",
				 "a drive of the simulated arm takes estop "
				 "(drive fault) and unplug (falls silent)");
		} else if (f->has_node_id) {
			for (j = 0; j < c->canopen.n_drives &&
				    c->canopen.drives[j].node_id != f->node_id;
			     j++)
				;
			if (j == c->canopen.n_drives) {
				snprintf(what, sizeof(what),
					 "no canopen drive has node id %lld",
					 (long long)f->node_id);
				err_item(r, map, "faults", i, "node_id", what);
			}
		}
	}
	if (c->transport != PX_CONFIG_CAN_KERNEL && c->bitrate)
		px_config_reader_error(r, px_config_node_get(map, "bitrate"),
				       "bitrate",
				       "only for a kernel interface (transport "
				       "'kernel')");
	if (c->restart_ms && !c->bitrate)
		px_config_reader_error(r, px_config_node_get(map, "restart_ms"),
				       "restart_ms",
				       "applied with bitrate: give bitrate too");
	for (i = 0; i < c->n_signals; i++) {
		const struct px_config_can_signal *s = &c->signals[i];
		int64_t end = signal_end_bit(s);
		if (end < 0 || end >= frame_bits) {
			snprintf(what, sizeof(what),
				 "signal runs past the %lld-byte %s frame",
				 (long long)(frame_bits / 8),
				 c->fd ? "CAN FD" : "classic CAN");
			err_item(r, map, "signals", i, "start_bit", what);
		}
		for (j = 0; j < i; j++)
			if (same(s->name, c->signals[j].name)) {
				snprintf(what, sizeof(what),
					 "signal name '%s' is already used by "
					 "signals[%zu]",
					 EX(s->name), j);
				err_item(r, map, "signals", i, "name", what);
				break;
			}
	}
}

static const struct px_config_key socketcan_keys[] = {
	K_STR(struct px_config_socketcan, interface, "interface",
	      PX_CONFIG_REQUIRED),
	K_ENUM(struct px_config_socketcan, transport, "transport", 0,
	       can_transport_names, PX_CONFIG_CAN_KERNEL),
	K_STR(struct px_config_socketcan, socket_path, "socket_path", 0),
	K_BOOL(struct px_config_socketcan, fd, "fd", 0),
	K_INT(struct px_config_socketcan, bitrate, "bitrate", 0, 0, 1000000, 0),
	K_SEQ(struct px_config_socketcan, filters, n_filters, "filters", 0,
	      filter_schema, struct px_config_can_filter, 0, 64),
	K_SEQ(struct px_config_socketcan, signals, n_signals, "signals", 0,
	      signal_schema, struct px_config_can_signal, 0, 256),
	K_SUBP(struct px_config_socketcan, canopen, "canopen", canopen_schema,
	       canopen.present),
	K_INT(struct px_config_socketcan, restart_ms, "restart_ms", 0, 0, 60000,
	      0),
	K_SEQ(struct px_config_socketcan, faults, n_faults, "faults", 0,
	      fault_schema, struct px_config_fault, 0, 16),
};
SCHEMA(socketcan_schema, "socketcan", socketcan_keys, socketcan_check);

static const struct px_config_key line_keys[] = {
	K_STR(struct px_config_gpio_line, name, "name", PX_CONFIG_REQUIRED),
	K_INTP(struct px_config_gpio_line, offset, "offset", 0, 0, 4095, 0,
	       has_offset),
	K_STR(struct px_config_gpio_line, line_name, "line_name", 0),
	K_ENUM(struct px_config_gpio_line, direction, "direction",
	       PX_CONFIG_REQUIRED, dir_names, 0),
	K_BOOL(struct px_config_gpio_line, active_low, "active_low", 0),
	K_DUR(struct px_config_gpio_line, debounce_ns, "debounce_ns", 0, 0,
	      NS_PER_S, 0),
	K_BOOL(struct px_config_gpio_line, initial, "initial", 0),
};
SCHEMA(line_schema, "line", line_keys, NULL);

/* Names unique; for real chips exactly one of offset and line_name. */
static void lines_check(struct px_config_reader *r,
			const struct px_config_node *map,
			const struct px_config_gpio_line *l, size_t n,
			bool real_chip)
{
	size_t i, j;
	char what[256];
	for (i = 0; i < n; i++) {
		for (j = 0; j < i; j++)
			if (same(l[i].name, l[j].name)) {
				snprintf(what, sizeof(what),
					 "line name '%s' is already used by "
					 "lines[%zu]",
					 EX(l[i].name), j);
				err_item(r, map, "lines", i, "name", what);
				break;
			}
		if (real_chip && l[i].has_offset == (l[i].line_name != NULL))
			err_item(r, map, "lines", i, NULL,
				 "give exactly one of offset and line_name");
		if (l[i].debounce_ns && l[i].direction != PX_CONFIG_GPIO_INPUT)
			err_item(r, map, "lines", i, "debounce_ns",
				 "debouncing applies to inputs only");
	}
}

static void gpiod_check(struct px_config_reader *r,
			const struct px_config_node *map, void *obj)
{
	const struct px_config_gpiod *g = obj;
	if (map)
		lines_check(r, map, g->lines, g->n_lines, true);
}

static const struct px_config_key gpiod_keys[] = {
	K_STR(struct px_config_gpiod, chip, "chip", PX_CONFIG_REQUIRED),
	K_SEQ(struct px_config_gpiod, lines, n_lines, "lines", PX_CONFIG_REQUIRED,
	      line_schema, struct px_config_gpio_line, 1, 64),
};
SCHEMA(gpiod_schema, "gpiod", gpiod_keys, gpiod_check);

static const struct px_config_key sine_keys[] = {
	K_ENUM(struct px_config_sine, axis, "axis", PX_CONFIG_REQUIRED, xyz_names,
	       0),
	K_DBL(struct px_config_sine, amplitude_m, "amplitude_m",
	      PX_CONFIG_REQUIRED, 0, 10, 0),
	K_DBL(struct px_config_sine, frequency_hz, "frequency_hz",
	      PX_CONFIG_REQUIRED, 0, 1000, 0),
	K_DBL(struct px_config_sine, phase_rad, "phase_rad", 0, -1000, 1000, 0),
};
SCHEMA(sine_schema, "sine", sine_keys, NULL);

static void trajectory_check(struct px_config_reader *r,
			     const struct px_config_node *map, void *obj)
{
	const struct px_config_trajectory *t = obj;
	if (!map)
		return;
	if (t->kind == PX_CONFIG_TRAJ_SINES && t->n_sines == 0)
		px_config_reader_error(r, map, "sines",
				       "missing required key (kind is 'sines')");
	if (t->kind != PX_CONFIG_TRAJ_SINES && t->n_sines)
		px_config_reader_error(r, px_config_node_get(map, "sines"),
				       "sines", "only used with kind 'sines'");
	if (t->kind == PX_CONFIG_TRAJ_CSV && !t->file)
		px_config_reader_error(r, map, "file",
				       "missing required key (kind is 'csv')");
	if (t->kind != PX_CONFIG_TRAJ_CSV && t->file)
		px_config_reader_error(r, px_config_node_get(map, "file"), "file",
				       "only used with kind 'csv'");
}

static const struct px_config_key trajectory_keys[] = {
	K_ENUM(struct px_config_trajectory, kind, "kind", 0, traj_names,
	       PX_CONFIG_TRAJ_HOLD),
	K_VEC(struct px_config_trajectory, center_m, "center_m", 0, -100, 100),
	K_SEQ(struct px_config_trajectory, sines, n_sines, "sines", 0,
	      sine_schema, struct px_config_sine, 0, 32),
	K_STR(struct px_config_trajectory, file, "file", 0),
	K_BOOL(struct px_config_trajectory, repeat, "repeat", 1),
};
SCHEMA(trajectory_schema, "trajectory", trajectory_keys, trajectory_check);

static void sim_check(struct px_config_reader *r,
		      const struct px_config_node *map, void *obj)
{
	const struct px_config_sim *s = obj;
	if (!map)
		return;
	if (s->kind != PX_CONFIG_SIM_GPIO && s->n_lines)
		px_config_reader_error(r, px_config_node_get(map, "lines"),
				       "lines", "only used with kind 'gpio'");
	if (s->kind == PX_CONFIG_SIM_GPIO && s->n_lines == 0)
		px_config_reader_error(r, map, "lines",
				       "missing required key (kind is 'gpio')");
	lines_check(r, map, s->lines, s->n_lines, false);
	codec_check(r, map, &s->codec);
	if (s->kind == PX_CONFIG_SIM_GPIO)
		faults_check(r, map, s->faults, s->n_faults,
			     ~(FK(PX_CONFIG_FAULT_NAN) |
			       FK(PX_CONFIG_FAULT_BUS_OFF)),
			     "does not apply to simulated GPIO lines (drop, "
			     "delay, duplicate, corrupt, stuck, unplug, estop)");
	else
		faults_check(r, map, s->faults, s->n_faults,
			     ~(FK(PX_CONFIG_FAULT_BUS_OFF) |
			       FK(PX_CONFIG_FAULT_ESTOP)),
			     "does not apply to a simulated haptic or pose "
			     "device (drop, delay, duplicate, corrupt, stuck, "
			     "nan, unplug)");
}

static const struct px_config_key sim_keys[] = {
	K_ENUM(struct px_config_sim, kind, "kind", 0, sim_kind_names,
	       PX_CONFIG_SIM_HAPTIC),
	K_DBL(struct px_config_sim, mass_kg, "mass_kg", PX_CONFIG_MIN_EXCL, 0,
	      1000, 0.1),
	K_DBL(struct px_config_sim, damping_n_s_per_m, "damping_n_s_per_m", 0, 0,
	      1e6, 1.0),
	K_DBL(struct px_config_sim, hand_stiffness_n_per_m,
	      "hand_stiffness_n_per_m", 0, 0, 1e7, 500.0),
	K_DBL(struct px_config_sim, hand_damping_n_s_per_m,
	      "hand_damping_n_s_per_m", 0, 0, 1e6, 5.0),
	K_DUR(struct px_config_sim, report_period_ns, "report_period_ns", 0, 0,
	      NS_PER_S, 1000000),
	K_INT(struct px_config_sim, seed, "seed", 0, 0, INT64_MAX, 1),
	K_DBL(struct px_config_sim, position_noise_m, "position_noise_m", 0, 0,
	      1, 0.0),
	K_SUB(struct px_config_sim, trajectory, "trajectory", trajectory_schema),
	CODEC_KEYS(struct px_config_sim),
	K_SEQ(struct px_config_sim, lines, n_lines, "lines", 0, line_schema,
	      struct px_config_gpio_line, 0, 64),
	K_SEQ(struct px_config_sim, faults, n_faults, "faults", 0, fault_schema,
	      struct px_config_fault, 0, 16),
};
SCHEMA(sim_schema, "sim", sim_keys, sim_check);

/* ---- dds --------------------------------------------------------- */

/* Longest namespace or topic: rt/<namespace>/<topic> fits the bridge's
 * 192-byte topic names. */
#define DDS_NAME_MAX 90

static void dds_check(struct px_config_reader *r,
		      const struct px_config_node *map, void *obj)
{
	const struct px_config_dds *d = obj;
	const char *const names[] = {"namespace",     "pose_topic",
				     "wrench_topic",  "command_topic",
				     "pose_out_topic", "params_topic",
				     "cloud_topic",   "scene_topic"};
	const char *const vals[] = {d->ns,		d->pose_topic,
				    d->wrench_topic,	d->command_topic,
				    d->pose_out_topic, d->params_topic,
				    d->cloud_topic,	d->scene_topic};
	size_t i;
	if (!map)
		return;
	for (i = 0; i < sizeof(vals) / sizeof(vals[0]); i++) {
		const char *p =
			vals[i] ? px__ros_name_problem(vals[i], DDS_NAME_MAX) : NULL;
		if (p)
			px_config_reader_error(r, px_config_node_get(map, names[i]),
					       names[i], "'%s' %s", EX(vals[i]), p);
	}
	if (!d->pose_topic && !d->wrench_topic && !d->command_topic &&
	    !d->pose_out_topic && !d->params_topic && !d->cloud_topic &&
	    !d->scene_topic)
		px_config_reader_error(r, map, "pose_topic",
				       "a dds device needs at least one of "
				       "pose_topic, wrench_topic, command_topic, "
				       "pose_out_topic, params_topic, cloud_topic "
				       "and scene_topic");
}

static const struct px_config_key dds_keys[] = {
	{.name = "namespace", .type = PX_CONFIG_T_STRING,
	 .offset = offsetof(struct px_config_dds, ns),
	 .flags = PX_CONFIG_NONEMPTY},
	K_STR(struct px_config_dds, pose_topic, "pose_topic", PX_CONFIG_NONEMPTY),
	K_STR(struct px_config_dds, wrench_topic, "wrench_topic",
	      PX_CONFIG_NONEMPTY),
	K_STR(struct px_config_dds, command_topic, "command_topic",
	      PX_CONFIG_NONEMPTY),
	K_STR(struct px_config_dds, pose_out_topic, "pose_out_topic",
	      PX_CONFIG_NONEMPTY),
	K_STR(struct px_config_dds, params_topic, "params_topic",
	      PX_CONFIG_NONEMPTY),
	K_STR(struct px_config_dds, cloud_topic, "cloud_topic",
	      PX_CONFIG_NONEMPTY),
	K_STR(struct px_config_dds, scene_topic, "scene_topic",
	      PX_CONFIG_NONEMPTY),
	K_DUR(struct px_config_dds, connect_timeout_ns, "connect_timeout_ns", 0,
	      0, 60 * NS_PER_S, 10 * NS_PER_S),
};
SCHEMA(dds_schema, "dds", dds_keys, dds_check);

/* ---- devices ----------------------------------------------------- */

static void device_check(struct px_config_reader *r,
			 const struct px_config_node *map, void *obj)
{
	struct px_config_device *d = obj;
	const bool has[] = {d->has_sim, d->has_hidapi, d->has_libusb,
			    d->has_socketcan, d->has_gpiod, d->has_dds};
	int b;
	d->node_ = map;
	if (!map || map->kind != PX_CONFIG_NODE_MAP)
		return;
	if (d->name && !valid_name(d->name))
		px_config_reader_error(r, px_config_node_get(map, "name"), "name",
				       "'%s': use only letters, digits, '_', "
				       "'-' and '.'",
				       EX(d->name));
	if (!px_config_node_get(map, "backend"))
		return; /* already reported as missing */
	for (b = 0; backend_names[b]; b++) {
		if (b == d->backend && !has[b] && b != PX_CONFIG_BACKEND_SIM)
			px_config_reader_error(r, map, backend_names[b],
					       "missing required key (backend "
					       "is '%s')",
					       backend_names[b]);
		if (b != d->backend && has[b])
			px_config_reader_error(
				r, px_config_node_get(map, backend_names[b]),
				backend_names[b],
				"not allowed with backend '%s'",
				backend_names[d->backend]);
	}
}

static const struct px_config_key device_keys[] = {
	K_STR(struct px_config_device, name, "name", PX_CONFIG_REQUIRED),
	K_ENUM(struct px_config_device, backend, "backend", PX_CONFIG_REQUIRED,
	       backend_names, 0),
	K_DUR(struct px_config_device, stale_timeout_ns, "stale_timeout_ns", 0,
	      0, 10 * NS_PER_S, 0),
	K_SUBP(struct px_config_device, sim, "sim", sim_schema, has_sim),
	K_SUBP(struct px_config_device, hidapi, "hidapi", hidapi_schema,
	       has_hidapi),
	K_SUBP(struct px_config_device, libusb, "libusb", libusb_schema,
	       has_libusb),
	K_SUBP(struct px_config_device, socketcan, "socketcan", socketcan_schema,
	       has_socketcan),
	K_SUBP(struct px_config_device, gpiod, "gpiod", gpiod_schema, has_gpiod),
	K_SUBP(struct px_config_device, dds, "dds", dds_schema, has_dds),
	K_INT(struct px_config_device, stuck_limit, "stuck_limit", 0, 0, 1000000,
	      0),
	K_DUR(struct px_config_device, min_report_interval_ns,
	      "min_report_interval_ns", 0, 0, NS_PER_S, 0),
};
SCHEMA(device_schema, "device", device_keys, device_check);

/* ---- loop, safety, telemetry ------------------------------------- */

static const struct px_config_key loop_keys[] = {
	K_DUR(struct px_config_loop, period_ns, "period_ns", 0, 10000,
	      100000000, 1000000),
	K_INT(struct px_config_loop, priority, "priority", 0, 0, 99, 80),
	K_INT(struct px_config_loop, cpu, "cpu", 0, -1, 4095, -1),
	K_ENUM(struct px_config_loop, overrun_policy, "overrun_policy", 0,
	       overrun_names, PX_CONFIG_OVERRUN_SKIP),
	K_INT(struct px_config_loop, max_consecutive_overruns,
	      "max_consecutive_overruns", 0, 1, 1000000, 10),
	K_BOOL(struct px_config_loop, lock_memory, "lock_memory", 1),
	K_BOOL(struct px_config_loop, dma_latency, "dma_latency", 0),
};
SCHEMA(loop_schema, "loop", loop_keys, NULL);

static const struct px_config_key watchdog_keys[] = {
	K_DUR(struct px_config_watchdog, device_timeout_ns, "device_timeout_ns",
	      0, 100000, 10 * NS_PER_S, 50000000),
	K_DUR(struct px_config_watchdog, compute_budget_ns, "compute_budget_ns",
	      0, 0, 100000000, 0),
	K_INT(struct px_config_watchdog, max_over_budget, "max_over_budget", 0,
	      1, 1000000, 3),
	K_BOOL(struct px_config_watchdog, auto_rearm, "auto_rearm", 0),
};
SCHEMA(watchdog_schema, "watchdog", watchdog_keys, NULL);

static const struct px_config_key line_ref_keys[] = {
	K_STR(struct px_config_line_ref, device, "device", PX_CONFIG_REQUIRED),
	K_STR(struct px_config_line_ref, line, "line", PX_CONFIG_REQUIRED),
};
SCHEMA(line_ref_schema, "line_ref", line_ref_keys, NULL);

static const struct px_config_key safety_keys[] = {
	K_DBL(struct px_config_safety, max_force_n, "max_force_n",
	      PX_CONFIG_MIN_EXCL, 0, 10000, 10.0),
	K_DBL(struct px_config_safety, max_force_rate_n_per_s,
	      "max_force_rate_n_per_s", PX_CONFIG_MIN_EXCL, 0, 1e9, 1000.0),
	K_DBL(struct px_config_safety, max_torque_n_m, "max_torque_n_m", 0, 0,
	      1000, 1.0),
	K_DBL(struct px_config_safety, velocity_limit_m_per_s,
	      "velocity_limit_m_per_s", PX_CONFIG_MIN_EXCL, 0, 100, 1.0),
	K_SUB(struct px_config_safety, watchdog, "watchdog", watchdog_schema),
	K_SUBP(struct px_config_safety, estop, "estop", line_ref_schema,
	       estop.present),
	K_SUBP(struct px_config_safety, enable, "enable", line_ref_schema,
	       enable.present),
};
SCHEMA(safety_schema, "safety", safety_keys, NULL);

static const struct px_config_key telemetry_keys[] = {
	K_STR(struct px_config_telemetry, file, "file", 0),
	K_INT(struct px_config_telemetry, decimation, "decimation", 0, 1,
	      1000000, 1),
	K_INT(struct px_config_telemetry, ring_records, "ring_records", 0, 16,
	      1 << 24, 8192),
	K_BOOL(struct px_config_telemetry, joint_positions, "joint_positions", 0),
};
SCHEMA(telemetry_schema, "telemetry", telemetry_keys, NULL);

/* ---- root -------------------------------------------------------- */

static void line_ref_check(struct px_config_reader *r,
			   const struct px_config_node *root,
			   const struct px_config *cfg,
			   const struct px_config_line_ref *ref,
			   const char *key, int want_dir)
{
	const struct px_config_node *safety = px_config_node_get(root, "safety");
	const struct px_config_node *rn = px_config_node_get(safety, key);
	const struct px_config_device *d;
	const struct px_config_gpio_line *lines = NULL;
	size_t n = 0, i;
	char p[64];
	const char *role = want_dir == PX_CONFIG_GPIO_INPUT ? "e-stop" : "enable";
	if (!ref->present || !ref->device || !ref->line)
		return;
	d = px_config_device_find(cfg, ref->device);
	snprintf(p, sizeof(p), "safety.%s.device", key);
	if (!d) {
		px_config_reader_error(r, px_config_node_get(rn, "device"), p,
				       "no device named '%s' in devices",
				       EX(ref->device));
		return;
	}
	if (d->backend == PX_CONFIG_BACKEND_GPIOD) {
		lines = d->gpiod.lines;
		n = d->gpiod.n_lines;
	} else if (d->backend == PX_CONFIG_BACKEND_SIM &&
		   d->sim.kind == PX_CONFIG_SIM_GPIO) {
		lines = d->sim.lines;
		n = d->sim.n_lines;
	} else {
		px_config_reader_error(r, px_config_node_get(rn, "device"), p,
				       "device '%s' has no digital lines (the "
				       "%s line needs a gpiod device or a sim "
				       "device of kind gpio)",
				       EX(ref->device), role);
		return;
	}
	snprintf(p, sizeof(p), "safety.%s.line", key);
	for (i = 0; i < n; i++)
		if (same(lines[i].name, ref->line))
			break;
	if (i == n) {
		px_config_reader_error(r, px_config_node_get(rn, "line"), p,
				       "device '%s' has no line named '%s'",
				       EX(ref->device), EX(ref->line));
		return;
	}
	if (lines[i].direction != want_dir)
		px_config_reader_error(r, px_config_node_get(rn, "line"), p,
				       "line '%s' of device '%s' is an %s; the "
				       "%s line must be an %s",
				       EX(ref->line), EX(ref->device),
				       dir_names[lines[i].direction], role,
				       dir_names[want_dir]);
}

static void root_check(struct px_config_reader *r,
		       const struct px_config_node *root, void *obj)
{
	struct px_config *cfg = obj;
	size_t i, j;
	char what[256];
	if (!root || root->kind != PX_CONFIG_NODE_MAP)
		return;
	for (i = 0; i < cfg->n_devices; i++) {
		if (!cfg->devices[i].name)
			continue;
		for (j = 0; j < i; j++) {
			if (cfg->devices[j].name &&
			    strcmp(cfg->devices[i].name, cfg->devices[j].name) ==
				    0) {
				const struct px_config_node *f =
					node_at(root, "devices", j, "name");
				snprintf(what, sizeof(what),
					 "duplicate device name '%s' (first at "
					 "line %d, column %d)",
					 EX(cfg->devices[i].name), f->line,
					 f->column);
				err_item(r, root, "devices", i, "name", what);
				break;
			}
		}
	}
	/* Timing relations: a budget beyond the period can never be kept, a
	 * timeout shorter than the period trips on every cycle. */
	if (cfg->safety.watchdog.compute_budget_ns > cfg->loop.period_ns)
		px_config_reader_error(
			r,
			px_config_node_get(px_config_node_get(px_config_node_get(
						   root, "safety"),
						   "watchdog"),
					   "compute_budget_ns"),
			"safety.watchdog.compute_budget_ns",
			"%lld is longer than loop.period_ns %lld",
			(long long)cfg->safety.watchdog.compute_budget_ns,
			(long long)cfg->loop.period_ns);
	if (cfg->safety.watchdog.device_timeout_ns < cfg->loop.period_ns)
		px_config_reader_error(
			r,
			px_config_node_get(px_config_node_get(px_config_node_get(
						   root, "safety"),
						   "watchdog"),
					   "device_timeout_ns"),
			"safety.watchdog.device_timeout_ns",
			"%lld is shorter than loop.period_ns %lld: every cycle "
			"would see stale data",
			(long long)cfg->safety.watchdog.device_timeout_ns,
			(long long)cfg->loop.period_ns);
	for (i = 0; i < cfg->n_devices; i++) {
		int64_t t = cfg->devices[i].stale_timeout_ns;
		if (t && t < cfg->loop.period_ns) {
			snprintf(what, sizeof(what),
				 "%lld is shorter than loop.period_ns %lld: "
				 "every cycle would see stale data",
				 (long long)t, (long long)cfg->loop.period_ns);
			err_item(r, root, "devices", i, "stale_timeout_ns", what);
		}
	}
	line_ref_check(r, root, cfg, &cfg->safety.estop, "estop",
		       PX_CONFIG_GPIO_INPUT);
	line_ref_check(r, root, cfg, &cfg->safety.enable, "enable",
		       PX_CONFIG_GPIO_OUTPUT);
}

static const struct px_config_key root_keys[] = {
	K_INT(struct px_config, version, "version", 0, 1, 1, 1),
	K_SUB(struct px_config, loop, "loop", loop_schema),
	K_SUB(struct px_config, safety, "safety", safety_schema),
	K_SUB(struct px_config, telemetry, "telemetry", telemetry_schema),
	K_SEQ(struct px_config, devices, n_devices, "devices", 0, device_schema,
	      struct px_config_device, 0, 64),
	K_MAP(struct px_config, scene, "scene"),
	K_MAP(struct px_config, control, "control"),
	K_MAP(struct px_config, sim, "sim"),
	K_MAP(struct px_config, bridge, "bridge"),
	K_MAP(struct px_config, teleop, "teleop"),
};
SCHEMA(root_schema, "config", root_keys, root_check);

const struct px_config_schema *px_config_schema_root(void)
{
	return &root_schema;
}

/* ---- loading ----------------------------------------------------- */

const struct px_config_device *px_config_device_find(const struct px_config *cfg,
						     const char *name)
{
	size_t i;
	if (!cfg || !name)
		return NULL;
	for (i = 0; i < cfg->n_devices; i++)
		if (cfg->devices[i].name &&
		    strcmp(cfg->devices[i].name, name) == 0)
			return &cfg->devices[i];
	return NULL;
}

void px_config_free(struct px_config *cfg)
{
	if (!cfg)
		return;
	px_config_doc_free(cfg->doc);
	free(cfg);
}

int px_config_from_doc(struct px_config_doc *doc, struct px_config **out,
		       struct px_config_diag *diag)
{
	const struct px_config_node *root;
	struct px_config *cfg;
	int rc;
	if (out)
		*out = NULL;
	if (!doc || !out) {
		px_config_doc_free(doc);
		return PX_E_INVAL;
	}
	root = px_config_doc_root(doc);
	if (!root || px_config_node_is_null(root)) {
		px__cfg_diag_add(diag, doc->name, root ? root->line : 1,
				 root ? root->column : 1, "",
				 "the document is empty (expected a mapping "
				 "of sections such as loop and devices)");
		px_config_doc_free(doc);
		return PX_E_PARSE;
	}
	if (root->kind != PX_CONFIG_NODE_MAP) {
		px__cfg_diag_add(diag, doc->name, root->line, root->column, "",
				 "expected a mapping of sections at the top "
				 "level, got a %s",
				 root->kind == PX_CONFIG_NODE_SEQ ? "sequence"
								  : "scalar");
		px_config_doc_free(doc);
		return PX_E_PARSE;
	}
	cfg = calloc(1, sizeof(*cfg));
	if (!cfg) {
		px__cfg_diag_add(diag, doc->name, 0, 0, "", "out of memory");
		px_config_doc_free(doc);
		return PX_E_NOMEM;
	}
	cfg->doc = doc;
	rc = px_config_read(doc, root, "", &root_schema, cfg, diag);
	px__cfg_diag_sort(diag);
	if (rc) {
		px_config_free(cfg);
		return rc;
	}
	*out = cfg;
	return PX_OK;
}

int px_config_load_mem(const char *name, const void *buf, size_t len,
		       struct px_config **out, struct px_config_diag *diag)
{
	struct px_config_doc *doc;
	int rc;
	if (out)
		*out = NULL;
	px_config_diag_init(diag);
	if (!out)
		return PX_E_INVAL;
	rc = px_config_doc_load_mem(name, buf, len, &doc, diag);
	if (rc)
		return rc;
	return px_config_from_doc(doc, out, diag);
}

int px_config_load_file(const char *path, struct px_config **out,
			struct px_config_diag *diag)
{
	struct px_config_doc *doc;
	int rc;
	if (out)
		*out = NULL;
	px_config_diag_init(diag);
	if (!out || !path)
		return PX_E_INVAL;
	rc = px_config_doc_load_file(path, &doc, diag);
	if (rc)
		return rc;
	return px_config_from_doc(doc, out, diag);
}
