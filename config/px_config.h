/*
 * px_config.h - YAML configuration: document loader, schema-driven typed
 * reader, and the configuration of a proxima application.
 *
 * Three layers, each usable on its own:
 *
 *  1. Document. px_config_doc_load_file() / px_config_doc_load_mem() parse
 *     one YAML document (libyaml) into an immutable tree of mappings,
 *     sequences and scalars. Every node keeps the file name and the 1-based
 *     line and column where it starts, so any later complaint about a
 *     value can point at it. Duplicate keys, merge keys ('<<'), unknown
 *     tags, more than one document and nesting deeper than
 *     PX_CONFIG_MAX_DEPTH are errors. Anchors and aliases are supported:
 *     an alias shares the anchored subtree (it is not copied), and the
 *     total size of the tree with every alias expanded is capped at
 *     PX_CONFIG_MAX_EXPANDED nodes, so "billion laughs" documents are
 *     refused instead of making readers walk an exponential tree. A value
 *     reached through an alias reports the line and column of the
 *     anchored original.
 *
 *  2. Schema reader. A section is declared as a table of keys (struct
 *     px_config_key: name, type, field offset, required or default, range,
 *     enum names, sub-schema). px_config_read() fills a C struct from a
 *     mapping node, applies defaults, and reports every problem it finds
 *     (up to PX_CONFIG_MAX_ERRORS stored, the rest counted) as one line
 *     "file:line:column: key.path: what is wrong". Later modules (scene,
 *     control, sim) declare their own tables and read the raw mapping the
 *     top-level config keeps for them.
 *
 *  3. Configuration. px_config_load_file() reads a whole application
 *     config (sections loop, safety, telemetry, devices, plus the raw
 *     scene, control and sim mappings) into struct px_config and checks
 *     the relations between sections (device names, back-end sub-maps,
 *     e-stop and enable line references). Every key is documented in
 *     docs/config.md.
 *
 * Value syntax (strict on purpose; a config drives hardware):
 *  - integers: optional sign, decimal without leading zeros, or hex with
 *    0x; '_' allowed between digits (1_000_000); must fit in int64.
 *  - numbers (double): decimal with optional fraction and exponent, '_'
 *    between digits; integers accepted; NaN, infinities, hex floats and
 *    values beyond the double range are errors.
 *  - booleans: true or false (also True/TRUE/False/FALSE); yes/no/on/off
 *    are refused as ambiguous.
 *  - quoted scalars are strings: "10" is not an integer.
 *  - units are part of key names (period_ns, max_force_n); a unit written
 *    in the value ("10ms") is an error.
 *
 * Memory and real-time rules: everything here is setup-time. Loading and
 * reading allocate (the document owns all memory, released by one free);
 * strings and arrays in a filled struct point into the document and live
 * as long as it does. Nothing here may be called from a running cycle;
 * the structs it fills are plain data that a cycle may read.
 */
#ifndef PX_CONFIG_H
#define PX_CONFIG_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "px_base.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------------------ */
/* Diagnostics                                                         */
/* ------------------------------------------------------------------ */

#define PX_CONFIG_MAX_ERRORS 32   /* errors stored; more are counted */
#define PX_CONFIG_PATH_LEN 160    /* key path, e.g. devices[1].hidapi.vid */
#define PX_CONFIG_MSG_LEN 640     /* one formatted message */
#define PX_CONFIG_MAX_DEPTH 64    /* nesting of mappings and sequences */
#define PX_CONFIG_MAX_EXPANDED 1000000 /* nodes with aliases expanded */

/* One problem. msg is the full line "file:line:column: path: what";
 * line and column are 1-based (0 when no place is known, e.g. a file that
 * cannot be opened); path is the key path alone ("" for document-level
 * problems). */
struct px_config_error {
	int line;
	int column;
	char path[PX_CONFIG_PATH_LEN];
	char msg[PX_CONFIG_MSG_LEN];
};

/* Problems found by one load. Plain struct (about 25 KiB): keep it
 * static or on the heap rather than on a small stack. */
struct px_config_diag {
	int count;   /* entries stored in errors[] */
	int dropped; /* further errors found but not stored */
	struct px_config_error errors[PX_CONFIG_MAX_ERRORS];
};

/* Empty the list. */
PX_API void px_config_diag_init(struct px_config_diag *d);

/* Number of errors found (stored + dropped); 0 for NULL. */
PX_API int px_config_diag_total(const struct px_config_diag *d);

/* Print every stored message, one per line, then "... and N more errors"
 * when some were dropped. NULL d prints nothing. */
PX_API void px_config_diag_print(const struct px_config_diag *d, FILE *f);

/* First stored error whose path equals path (NULL if none). For tests and
 * for tools that want to highlight one key. */
PX_API const struct px_config_error *
px_config_diag_find(const struct px_config_diag *d, const char *path);

/* ------------------------------------------------------------------ */
/* Document                                                            */
/* ------------------------------------------------------------------ */

enum px_config_node_kind {
	PX_CONFIG_NODE_SCALAR = 1,
	PX_CONFIG_NODE_SEQ = 2,
	PX_CONFIG_NODE_MAP = 3
};

struct px_config_node;

struct px_config_pair {
	const struct px_config_node *key;   /* always a scalar */
	const struct px_config_node *value;
};

/* A node of the tree. Read-only; owned by its document. */
struct px_config_node {
	enum px_config_node_kind kind;
	/* 1-based line and column of the node's first character: its anchor
	 * or tag when it has one, the opening quote of a quoted scalar. */
	int line;
	int column;
	const char *file;  /* file or buffer name, for messages */
	size_t len;        /* scalar: bytes; seq: items; map: pairs */
	/* Scalar text, NUL-terminated (len is exact; the text may contain NUL
	 * bytes when the YAML escaped them, so compare with len). "" for seq
	 * and map. */
	const char *str;
	bool quoted;       /* scalar was quoted, a block scalar or !!str */
	const struct px_config_node *const *items; /* seq: len items */
	const struct px_config_pair *pairs;        /* map: len pairs, in order */
	size_t expanded_;  /* private: nodes in this subtree, aliases expanded */
};

/* Opaque: the tree and all memory of a loaded document. */
struct px_config_doc;

/*
 * Parse the YAML file at path. diag (may be NULL) is emptied first. On
 * success *out is the document (free with px_config_doc_free()). On
 * failure *out is NULL and diag says why: PX_E_IO (cannot open or read; the message carries strerror),
 * PX_E_PARSE (syntax, duplicate key, ...), PX_E_NOMEM, PX_E_INVAL (NULL
 * path or out).
 */
PX_API int px_config_doc_load_file(const char *path, struct px_config_doc **out,
				   struct px_config_diag *diag);

/*
 * As px_config_doc_load_file() from len bytes at buf (need not be
 * NUL-terminated). name is used as the file name in messages (NULL gives
 * "<memory>"); it is copied.
 */
PX_API int px_config_doc_load_mem(const char *name, const void *buf, size_t len,
				  struct px_config_doc **out,
				  struct px_config_diag *diag);

/* Release the document and everything pointing into it. NULL: no-op. */
PX_API void px_config_doc_free(struct px_config_doc *doc);

/* Root node; NULL for an empty document (no content at all). */
PX_API const struct px_config_node *
px_config_doc_root(const struct px_config_doc *doc);

/* File name given at load. */
PX_API const char *px_config_doc_name(const struct px_config_doc *doc);

/* Value of key in a mapping node, NULL if absent or map is not a mapping. */
PX_API const struct px_config_node *
px_config_node_get(const struct px_config_node *map, const char *key);

/* True for a plain scalar null: empty, ~, null, Null, NULL. */
PX_API bool px_config_node_is_null(const struct px_config_node *n);

/* ------------------------------------------------------------------ */
/* Schema reader                                                       */
/* ------------------------------------------------------------------ */

enum px_config_type {
	PX_CONFIG_T_INT64 = 1, /* int64_t */
	PX_CONFIG_T_DOUBLE,    /* double */
	PX_CONFIG_T_BOOL,      /* bool */
	PX_CONFIG_T_STRING,    /* const char * into the document */
	PX_CONFIG_T_ENUM,      /* int: index into names */
	PX_CONFIG_T_DURATION,  /* int64_t nanoseconds; key name ends in _ns */
	PX_CONFIG_T_SEQ,       /* array allocated in the document + count */
	PX_CONFIG_T_MAP,       /* const struct px_config_node * (raw mapping) */
	PX_CONFIG_T_SUB        /* nested struct read with key.sub */
};

/* key.flags */
#define PX_CONFIG_REQUIRED 0x01u /* absent is an error */
#define PX_CONFIG_HAS_MIN 0x02u  /* imin/dmin apply */
#define PX_CONFIG_HAS_MAX 0x04u  /* imax/dmax apply */
#define PX_CONFIG_MIN_EXCL 0x08u /* value must be > min (double) */
#define PX_CONFIG_MAX_EXCL 0x10u /* value must be < max (double) */
#define PX_CONFIG_NONEMPTY 0x20u /* string must not be "" */
#define PX_CONFIG_PRESENT 0x40u  /* set bool at present_offset when given */

struct px_config_schema;

/*
 * One key of a section. Fields a type does not use are ignored, so
 * designated initializers leave them zero.
 *  - INT64, DURATION: range imin..imax (flags), default idef.
 *  - DOUBLE: range dmin..dmax (flags, MIN_EXCL/MAX_EXCL), default ddef.
 *  - BOOL: default idef != 0. STRING: default sdef (may be NULL).
 *  - ENUM: names (NULL-terminated), default idef (an index).
 *  - INT64 or DOUBLE with fixed_count > 0: a sequence of exactly
 *    fixed_count values into an array field (int64_t[n] or double[n]);
 *    default every element idef/ddef.
 *  - SEQ: a sequence of min_count..max_count (0 = unbounded) elements.
 *    Elements are of type elem (a scalar type, with this key's range,
 *    names and flags), or mappings read with sub when sub is set. The
 *    array (elem_size bytes each) is allocated in the document; its
 *    pointer is stored at offset and the element count (size_t) at
 *    count_offset. Absent: NULL and 0.
 *  - SUB: a nested struct at offset, read with sub (defaults applied when
 *    the mapping is absent).
 *  - MAP: the raw mapping node kept for a later reader; absent or null:
 *    NULL.
 */
struct px_config_key {
	const char *name;
	enum px_config_type type;
	size_t offset;
	unsigned flags;
	int64_t imin, imax, idef;
	double dmin, dmax, ddef;
	const char *sdef;
	const char *const *names;
	const struct px_config_schema *sub;
	enum px_config_type elem;
	size_t elem_size;
	size_t count_offset;
	size_t min_count, max_count;
	size_t fixed_count;
	size_t present_offset;
};

/* Reader state handed to schema check callbacks. Opaque. */
struct px_config_reader;

/*
 * A section: its keys and an optional check run after the keys were read
 * (for relations between keys). The check reports problems with
 * px_config_reader_error(); map is the section's mapping node (NULL when
 * the section was absent and only defaults were applied).
 */
struct px_config_schema {
	const char *name;
	const struct px_config_key *keys;
	size_t n_keys;
	void (*check)(struct px_config_reader *r, const struct px_config_node *map,
		      void *obj);
};

/*
 * Fill obj from the mapping node map with schema. path names the section
 * in messages ("loop", "" for the root). A later module reads its section
 * of a loaded config with, for example,
 *   px_config_read(cfg->doc, cfg->scene, "scene", &scene_schema, &scene, diag)
 * and reports in the same format as the loader. Defaults are applied to every
 * key first, so obj is fully initialised even when errors are reported;
 * map NULL applies defaults only; a null node
 * ("scene:" with nothing under it) is an empty mapping. Problems are
 * appended to diag (may be NULL).
 * Arrays for SEQ keys are allocated in doc.
 * Returns PX_OK, PX_E_PARSE (at least one problem), PX_E_NOMEM or
 * PX_E_INVAL (NULL doc, schema or obj).
 */
PX_API int px_config_read(struct px_config_doc *doc,
			  const struct px_config_node *map, const char *path,
			  const struct px_config_schema *schema, void *obj,
			  struct px_config_diag *diag);

/*
 * Report a problem from a check callback. at is the node the message
 * points at (NULL: the section's node); sub is appended to the current
 * path (a key name, "[3]", "" or NULL for the section itself); fmt is the
 * "what is wrong" part.
 */
PX_API void px_config_reader_error(struct px_config_reader *r,
				   const struct px_config_node *at,
				   const char *sub, const char *fmt, ...)
	__attribute__((format(printf, 4, 5)));

/* Current key path ("devices[2].hidapi"). */
PX_API const char *px_config_reader_path(const struct px_config_reader *r);

/* Node of the section being checked (may be NULL). */
PX_API const struct px_config_node *
px_config_reader_node(const struct px_config_reader *r);

/*
 * Check a schema table itself: duplicate key names, missing sub-schemas
 * or enum names, defaults outside their range or enum, DURATION keys not
 * ending in "_ns". Recurses into sub-schemas. Writes a description of the
 * first defect to why (may be NULL). Returns PX_OK or PX_E_INVAL.
 */
PX_API int px_config_schema_validate(const struct px_config_schema *s,
				     char *why, size_t why_len);

/* ------------------------------------------------------------------ */
/* Application configuration                                           */
/* ------------------------------------------------------------------ */

enum px_config_overrun_policy {
	PX_CONFIG_OVERRUN_SKIP = 0,     /* drop missed periods, keep phase */
	PX_CONFIG_OVERRUN_CATCH_UP = 1  /* run missed periods back to back */
};

struct px_config_loop {
	int64_t period_ns;                /* cycle period */
	int64_t priority;                 /* SCHED_FIFO priority, 0 = none */
	int64_t cpu;                      /* CPU to pin to, -1 = no pinning */
	int overrun_policy;               /* enum px_config_overrun_policy */
	int64_t max_consecutive_overruns; /* safe state after this many */
	bool lock_memory;                 /* mlockall + prefault */
	bool dma_latency;                 /* hold /dev/cpu_dma_latency at 0 */
};

/* A reference to a digital line of a gpiod (or sim) device. */
struct px_config_line_ref {
	bool present;        /* the key was given */
	const char *device;  /* name of a device in devices */
	const char *line;    /* name of a line of that device */
};

struct px_config_watchdog {
	int64_t device_timeout_ns;     /* device data older than this trips */
	int64_t compute_budget_ns;     /* 0 = the loop period */
	int64_t max_over_budget;       /* consecutive over-budget cycles */
	bool auto_rearm;               /* leave safe state without re-arm */
};

struct px_config_safety {
	double max_force_n;
	double max_force_rate_n_per_s;
	double max_torque_n_m;
	double velocity_limit_m_per_s;
	struct px_config_watchdog watchdog;
	struct px_config_line_ref estop;
	struct px_config_line_ref enable;
};

struct px_config_telemetry {
	const char *file;     /* CSV path; NULL or "" = no telemetry file */
	int64_t decimation;   /* record every Nth cycle */
	int64_t ring_records; /* capacity of the RT-to-writer ring */
	bool joint_positions; /* avoidance: the joints' positions too */
};

enum px_config_backend {
	PX_CONFIG_BACKEND_SIM = 0,
	PX_CONFIG_BACKEND_HIDAPI,
	PX_CONFIG_BACKEND_LIBUSB,
	PX_CONFIG_BACKEND_SOCKETCAN,
	PX_CONFIG_BACKEND_GPIOD,
	PX_CONFIG_BACKEND_DDS
};

enum px_config_byte_order {
	PX_CONFIG_LITTLE_ENDIAN = 0,
	PX_CONFIG_BIG_ENDIAN = 1
};

/* Pose axes a decoded field feeds: position in m, rotation in rad
 * (rotation vector components). */
enum px_config_axis {
	PX_CONFIG_AXIS_X = 0,
	PX_CONFIG_AXIS_Y,
	PX_CONFIG_AXIS_Z,
	PX_CONFIG_AXIS_RX,
	PX_CONFIG_AXIS_RY,
	PX_CONFIG_AXIS_RZ,
	PX_CONFIG_AXIS__COUNT
};

/* Force/torque channels an encoded output field carries: N and N m. */
enum px_config_wrench_axis {
	PX_CONFIG_WRENCH_FX = 0,
	PX_CONFIG_WRENCH_FY,
	PX_CONFIG_WRENCH_FZ,
	PX_CONFIG_WRENCH_TX,
	PX_CONFIG_WRENCH_TY,
	PX_CONFIG_WRENCH_TZ,
	PX_CONFIG_WRENCH__COUNT
};

/*
 * One numeric field of a report or frame. Bits are counted from the
 * least significant bit of the byte at byte_offset (byte_offset counts
 * from the first byte after the report id). Physical value =
 * raw * scale + offset (inputs); raw = round((value - offset) / scale),
 * clamped to the field's range (outputs).
 */
struct px_config_field {
	int64_t report_id;   /* 0 = device without numbered reports */
	int64_t byte_offset;
	int64_t bit_offset;  /* 0..7 */
	int64_t bit_width;   /* 1..64 */
	bool is_signed;      /* key "signed": two's complement */
	int byte_order;      /* enum px_config_byte_order */
	double scale;
	double offset;
	int axis;            /* enum px_config_axis or px_config_wrench_axis */
	double max_abs;      /* outputs: clamp |value| here, 0 = no clamp */
};

/* A run of button bits: bit first_bit + i of the byte at byte_offset
 * (continuing into the following bytes) is button first_button + i. */
struct px_config_buttons {
	int64_t report_id;
	int64_t byte_offset;
	int64_t first_bit;
	int64_t count;
	int64_t first_button;
};

/* Report codec shared by hidapi, libusb and sim devices. */
struct px_config_codec {
	struct px_config_field *inputs;
	size_t n_inputs;
	struct px_config_buttons *buttons;
	size_t n_buttons;
	struct px_config_field *outputs;
	size_t n_outputs;
	int64_t output_report_id;  /* report id of the force output report */
	int64_t output_report_len; /* bytes after the report id */
};

enum px_config_hid_driver {
	PX_CONFIG_HID_HIDRAW = 0,
	PX_CONFIG_HID_LIBUSB = 1
};

struct px_config_hidapi {
	bool has_vid, has_pid;
	int64_t vid, pid;
	const char *serial;  /* NULL = any */
	const char *path;    /* NULL = open by vid:pid */
	int driver;          /* enum px_config_hid_driver */
	struct px_config_codec codec;
};

enum px_config_usb_transfer {
	PX_CONFIG_USB_INTERRUPT = 0,
	PX_CONFIG_USB_BULK = 1
};

struct px_config_libusb {
	int64_t vid, pid;
	const char *serial;
	int64_t interface;
	int64_t endpoint_in;   /* 0x81..0x8f */
	int64_t endpoint_out;  /* 0x01..0x0f, 0 = none */
	int transfer;          /* enum px_config_usb_transfer */
	int64_t frame_len;     /* bytes of one input frame */
	bool detach_kernel_driver;
	struct px_config_codec codec;
	bool no_hotplug;       /* find a replugged device by polling (no udev) */
};

struct px_config_can_filter {
	int64_t id;
	int64_t mask;
	bool extended;
};

enum px_config_signal_dir {
	PX_CONFIG_SIGNAL_INPUT = 0,
	PX_CONFIG_SIGNAL_OUTPUT = 1
};

/* DBC-like signal: start_bit is the LSB position for little-endian
 * (Intel) and the MSB position for big-endian (Motorola), as in DBC. */
struct px_config_can_signal {
	const char *name;
	int64_t id;
	bool extended;
	int direction;       /* enum px_config_signal_dir */
	int64_t start_bit;
	int64_t length;
	int byte_order;      /* enum px_config_byte_order */
	bool is_signed;
	double scale;
	double offset;
	bool has_min, has_max;
	double min, max;     /* physical clamp (outputs), plausibility (inputs) */
	/* What the signal carries on the device (enum px_config_signal_axis):
	 * an input feeds a pose axis, an output a force/torque channel. */
	int axis;
	bool is_float;       /* IEEE 754 payload: length 32 or 64 */
};

/* Key "axis" of a CAN signal: none (a plain signal, read by name), a pose
 * axis (inputs) or a wrench channel (outputs). */
enum px_config_signal_axis {
	PX_CONFIG_SIGNAL_AXIS_NONE = 0,
	PX_CONFIG_SIGNAL_AXIS_X,  /* x y z rx ry rz: enum px_config_axis + 1 */
	PX_CONFIG_SIGNAL_AXIS_Y,
	PX_CONFIG_SIGNAL_AXIS_Z,
	PX_CONFIG_SIGNAL_AXIS_RX,
	PX_CONFIG_SIGNAL_AXIS_RY,
	PX_CONFIG_SIGNAL_AXIS_RZ,
	PX_CONFIG_SIGNAL_AXIS_FX, /* fx .. tz: enum px_config_wrench_axis + 7 */
	PX_CONFIG_SIGNAL_AXIS_FY,
	PX_CONFIG_SIGNAL_AXIS_FZ,
	PX_CONFIG_SIGNAL_AXIS_TX,
	PX_CONFIG_SIGNAL_AXIS_TY,
	PX_CONFIG_SIGNAL_AXIS_TZ
};

enum px_config_can_transport {
	PX_CONFIG_CAN_KERNEL = 0, /* SocketCAN socket on interface */
	PX_CONFIG_CAN_SIM = 1,    /* in-process simulated bus */
	PX_CONFIG_CAN_UNIX = 2    /* simulated bus over a UNIX datagram socket */
};

enum px_config_cia402_mode {
	PX_CONFIG_CIA402_CSP = 0,
	PX_CONFIG_CIA402_CSV,
	PX_CONFIG_CIA402_CST
};

struct px_config_canopen_drive {
	int64_t node_id; /* 1..127 */
	int mode;        /* enum px_config_cia402_mode */
	int64_t joint;   /* joint index fed by this drive */
	bool has_counts_per_unit;
	double counts_per_unit;  /* encoder counts per rad (or m); default 1 */
	double rated_torque_n_m; /* CST: target 1000 = this torque */
};

/* One object of a PDO mapping (CANopen index, subindex, bit length). */
struct px_config_pdo_entry {
	int64_t index;
	int64_t subindex;
	int64_t bits;
};

struct px_config_canopen {
	bool present;
	/* PDO layouts; absent or empty = the fixed default layout. */
	struct px_config_pdo_entry *rpdo, *tpdo1, *tpdo2;
	size_t n_rpdo, n_tpdo1, n_tpdo2;
	bool sync;                      /* produce SYNC every cycle */
	int64_t heartbeat_period_ns;    /* own heartbeat, 0 = none */
	int64_t heartbeat_timeout_ns;   /* consumer timeout per drive */
	struct px_config_canopen_drive *drives;
	size_t n_drives;
	/* The master's own node id (heartbeat 0x700 + id), 1..127; absent:
	 * the highest id no drive uses (127 mostly). */
	bool has_node_id;
	int64_t node_id;
};

/* A fault window of a simulated device or bus (key "faults"): kind is
 * enum px_config_fault_kind; px_sim.h's enum px_sim_fault_kind is kind
 * + 1. Times are from the start of the run. */
enum px_config_fault_kind {
	PX_CONFIG_FAULT_DROP = 0,
	PX_CONFIG_FAULT_DELAY,
	PX_CONFIG_FAULT_DUPLICATE,
	PX_CONFIG_FAULT_CORRUPT,
	PX_CONFIG_FAULT_STUCK,
	PX_CONFIG_FAULT_NAN,
	PX_CONFIG_FAULT_UNPLUG,
	PX_CONFIG_FAULT_BUS_OFF,
	PX_CONFIG_FAULT_ESTOP
};

struct px_config_fault {
	int kind;              /* enum px_config_fault_kind */
	int64_t start_ns;
	int64_t duration_ns;
	double probability;    /* (0, 1] */
	int64_t delay_ns;      /* kind delay */
	/* socketcan: a fault of the simulated arm's drive with this node
	 * id (kinds estop and unplug), not of the bus */
	bool has_node_id;
	int64_t node_id;
};

struct px_config_socketcan {
	const char *interface;
	int transport;           /* enum px_config_can_transport */
	const char *socket_path; /* transport unix */
	bool fd;                 /* CAN FD frames */
	int64_t bitrate;         /* 0 = leave the interface as configured */
	struct px_config_can_filter *filters;
	size_t n_filters;
	struct px_config_can_signal *signals;
	size_t n_signals;
	struct px_config_canopen canopen;
	int64_t restart_ms;      /* bus-off auto restart (with bitrate); 0 = off */
	/* transport sim/unix: fault windows on the frames this device
	 * receives */
	struct px_config_fault *faults;
	size_t n_faults;
};

enum px_config_gpio_dir {
	PX_CONFIG_GPIO_INPUT = 0,
	PX_CONFIG_GPIO_OUTPUT = 1
};

struct px_config_gpio_line {
	const char *name;        /* used by safety.estop/enable */
	bool has_offset;
	int64_t offset;          /* line offset on the chip */
	const char *line_name;   /* or the kernel's line name */
	int direction;           /* enum px_config_gpio_dir */
	bool active_low;
	int64_t debounce_ns;
	bool initial;            /* outputs: value at open */
};

struct px_config_gpiod {
	const char *chip;        /* "gpiochip0", "/dev/gpiochip0" or a label */
	struct px_config_gpio_line *lines;
	size_t n_lines;
};

/* A device on DDS topics (bridge/px_bridge.h, px_bridge_dev_create):
 * domain, interface and discovery are the bridge section's. Topic names
 * are ROS 2 names below the namespace (rt/<namespace>/<topic>); NULL:
 * not used. */
struct px_config_dds {
	const char *ns;              /* key "namespace"; NULL: the bridge's */
	const char *pose_topic;      /* PoseStamped in: a watched pose input */
	const char *wrench_topic;    /* WrenchStamped in: a remote force */
	const char *command_topic;   /* WrenchStamped out: zero in safe state */
	const char *pose_out_topic;  /* PoseStamped out: control.device's pose */
	const char *params_topic;    /* proxima_msgs Params in (teleop) */
	const char *cloud_topic;     /* PointCloud2 in: obstacles (teleop) */
	const char *scene_topic;     /* <scene_topic>/<model>/pose in (teleop) */
	int64_t connect_timeout_ns;  /* setup waits this long for the peers */
};

enum px_config_sim_kind {
	PX_CONFIG_SIM_HAPTIC = 0, /* mass-spring-damper arm + hand trajectory */
	PX_CONFIG_SIM_POSE,       /* pose source following the trajectory */
	PX_CONFIG_SIM_GPIO        /* simulated digital lines */
};

enum px_config_trajectory_kind {
	PX_CONFIG_TRAJ_HOLD = 0,  /* stay at center_m */
	PX_CONFIG_TRAJ_SINES,     /* center_m + sum of sinusoids */
	PX_CONFIG_TRAJ_CSV        /* time-stamped samples from a file */
};

struct px_config_sine {
	int axis;            /* enum px_config_axis (x, y, z only) */
	double amplitude_m;
	double frequency_hz;
	double phase_rad;
};

struct px_config_trajectory {
	int kind;            /* enum px_config_trajectory_kind */
	double center_m[3];
	struct px_config_sine *sines;
	size_t n_sines;
	const char *file;    /* csv */
	bool repeat;         /* csv: loop at the end */
};

struct px_config_sim {
	int kind;                        /* enum px_config_sim_kind */
	double mass_kg;
	double damping_n_s_per_m;        /* device damping */
	double hand_stiffness_n_per_m;   /* hand-to-device coupling */
	double hand_damping_n_s_per_m;
	int64_t report_period_ns;        /* simulated report interval */
	int64_t seed;                    /* noise and fault randomness */
	double position_noise_m;
	struct px_config_trajectory trajectory;
	struct px_config_codec codec;    /* report format; empty = built-in */
	struct px_config_gpio_line *lines; /* kind gpio */
	size_t n_lines;
	struct px_config_fault *faults;  /* fault windows of this device */
	size_t n_faults;
};

struct px_config_device {
	const char *name;
	int backend;                 /* enum px_config_backend */
	int64_t stale_timeout_ns;    /* 0 = safety.watchdog.device_timeout_ns */
	bool has_sim, has_hidapi, has_libusb, has_socketcan, has_gpiod, has_dds;
	struct px_config_sim sim;
	struct px_config_hidapi hidapi;
	struct px_config_libusb libusb;
	struct px_config_socketcan socketcan;
	struct px_config_gpiod gpiod;
	struct px_config_dds dds;
	const struct px_config_node *node_; /* the device's mapping */
	/* Pose inputs: identical samples this many times in a row mark the
	 * device stuck (0 = off), and an identical report/frame sooner than
	 * min_report_interval_ns after the last is a duplicate (0 = off). */
	int64_t stuck_limit;
	int64_t min_report_interval_ns;
};

struct px_config {
	int64_t version;
	struct px_config_loop loop;
	struct px_config_safety safety;
	struct px_config_telemetry telemetry;
	struct px_config_device *devices;
	size_t n_devices;
	/* Raw sections for the scene, control and sim readers (NULL when
	 * absent). */
	const struct px_config_node *scene;
	const struct px_config_node *control;
	const struct px_config_node *sim;
	const struct px_config_node *bridge; /* read by bridge/px_bridge.h */
	const struct px_config_node *teleop; /* read by app/px_app.h */
	struct px_config_doc *doc; /* owns every string and array above */
};

/* Names of the enums above, NULL-terminated (for messages and tools). */
PX_API const char *const *px_config_backend_names(void);

/* Schema of the whole file (for tools and docs checks). */
PX_API const struct px_config_schema *px_config_schema_root(void);

/*
 * Load and check a configuration file. diag (may be NULL) is emptied
 * first. On success *out is the config (free with px_config_free()). On
 * failure *out is NULL, diag holds every problem found (sorted by line
 * and column), and the return is PX_E_IO, PX_E_PARSE,
 * PX_E_NOMEM or PX_E_INVAL.
 */
PX_API int px_config_load_file(const char *path, struct px_config **out,
			       struct px_config_diag *diag);

/* As px_config_load_file() from a buffer; name is used in messages. */
PX_API int px_config_load_mem(const char *name, const void *buf, size_t len,
			      struct px_config **out,
			      struct px_config_diag *diag);

/* Read an already loaded document into a config (takes ownership of doc
 * on success and on failure). Problems are appended to diag. */
PX_API int px_config_from_doc(struct px_config_doc *doc, struct px_config **out,
			      struct px_config_diag *diag);

/* Device by name, NULL if none. */
PX_API const struct px_config_device *
px_config_device_find(const struct px_config *cfg, const char *name);

/* Release the config and its document. NULL: no-op. */
PX_API void px_config_free(struct px_config *cfg);

#ifdef __cplusplus
}
#endif

#endif
