/*
 * px_codec.h - the report codec: turns HID-style input reports into pose
 * axis values and buttons, and force/torque commands into output
 * reports, from a field mapping (the "inputs", "buttons" and "outputs"
 * of a device's config). Every back end that speaks reports (hidapi,
 * libusb, the simulated haptic device) goes through this one code, so a
 * simulated device exercises exactly the decoder a real one uses.
 *
 * Report layout. A device with numbered reports (any field with
 * report_id != 0) sends reports whose byte 0 is the report id; byte
 * offsets count from the byte after it. A device without numbered
 * reports (report_id 0 everywhere) sends data from byte 0. Output
 * reports are always built as hidapi's hid_write() wants them: byte 0 is
 * the report id (0 for an unnumbered device), then output_report_len
 * bytes.
 *
 * Field bits. A field is bit_width bits (1..64). Little-endian: the
 * bytes from byte_offset form a little-endian integer and the field is
 * its bits bit_offset .. bit_offset+bit_width-1 (bit 0 = least
 * significant bit of the byte at byte_offset), as HID report
 * descriptors number them. Big-endian: the ceil((bit_offset+bit_width)/8)
 * bytes from byte_offset form a big-endian integer (first byte most
 * significant) and the field is its bits bit_offset .. upwards counted
 * from the least significant bit of the last of those bytes; for whole
 * bytes (bit_offset 0, width 8/16/32/64) that is the usual big-endian
 * number. Signed fields are two's complement of bit_width bits.
 * Physical value = raw * scale + offset; outputs: raw = round((value -
 * offset) / scale), after clamping |value| to max_abs (when > 0) and raw
 * to the field's representable range.
 *
 * Memory: the map is caller memory (arrays of plain structs), read-only
 * to the codec; nothing here allocates. All functions are RT-safe except
 * the *_format helpers' callers may want them off the cycle (they use
 * snprintf).
 */
#ifndef PX_CODEC_H
#define PX_CODEC_H

#include <stddef.h>
#include <stdint.h>

#include "px_base.h"

#ifdef __cplusplus
extern "C" {
#endif

enum px_byte_order {
	PX_LITTLE_ENDIAN = 0,
	PX_BIG_ENDIAN = 1
};

/* Pose axes an input field feeds: position (m), rotation-vector
 * components (rad). Same order as the config's enum px_config_axis. */
enum px_axis {
	PX_AXIS_X = 0,
	PX_AXIS_Y,
	PX_AXIS_Z,
	PX_AXIS_RX,
	PX_AXIS_RY,
	PX_AXIS_RZ,
	PX_AXIS__COUNT
};

/* Wrench channels an output field carries: N and N m. Same order as the
 * config's enum px_config_wrench_axis. */
enum px_wrench_axis {
	PX_WRENCH_FX = 0,
	PX_WRENCH_FY,
	PX_WRENCH_FZ,
	PX_WRENCH_TX,
	PX_WRENCH_TY,
	PX_WRENCH_TZ,
	PX_WRENCH__COUNT
};

/* One numeric field (fields mean what struct px_config_field's do). */
struct px_codec_field {
	int report_id;        /* 0..255; 0 = device without numbered reports */
	uint32_t byte_offset; /* from the first byte after the report id */
	uint8_t bit_offset;   /* 0..7 */
	uint8_t bit_width;    /* 1..64 */
	uint8_t is_signed;    /* two's complement */
	uint8_t byte_order;   /* enum px_byte_order */
	double scale;         /* finite, non-zero */
	double offset;
	int axis;             /* enum px_axis (inputs) / px_wrench_axis (outputs) */
	/* Outputs: clamp |value| to this before encoding. Inputs: a decoded
	 * |value| above it is implausible (a corrupted report) and rejects
	 * the report. 0 = no limit. */
	double max_abs;
};

/* Button bits: bit first_bit + i of the byte at byte_offset (continuing
 * into the following bytes) is button first_button + i. */
struct px_codec_buttons {
	int report_id;
	uint32_t byte_offset;
	uint8_t first_bit;    /* 0..7 */
	uint8_t count;        /* 1..64 */
	uint8_t first_button; /* 0..63, first_button + count <= 64 */
};

/* A device's whole mapping (struct px_config_codec's meaning). */
struct px_codec_map {
	const struct px_codec_field *inputs;
	size_t n_inputs;
	const struct px_codec_buttons *buttons;
	size_t n_buttons;
	const struct px_codec_field *outputs;
	size_t n_outputs;
	int output_report_id;     /* 0..255 */
	size_t output_report_len; /* bytes after the report id */
};

/* What went wrong and where, for a clear message without formatting in
 * the cycle. */
enum px_codec_what {
	PX_CODEC_OK = 0,
	PX_CODEC_EMPTY,          /* zero-length report */
	PX_CODEC_UNKNOWN_REPORT, /* report id no field uses */
	PX_CODEC_SHORT,          /* report shorter than a field needs */
	PX_CODEC_IMPLAUSIBLE,    /* |value| above the field's max_abs */
	PX_CODEC_NONFINITE,      /* NaN or infinity to encode */
	PX_CODEC_BAD_FIELD,      /* map check: field out of range */
	PX_CODEC_BAD_BUTTONS,    /* map check: button run out of range */
	PX_CODEC_NOSPC           /* caller buffer too small */
};

struct px_codec_diag {
	int what;            /* enum px_codec_what */
	int report_id;       /* report concerned, -1 none */
	int index;           /* field/button-run index, -1 none */
	int section;         /* 0 inputs, 1 buttons, 2 outputs */
	size_t need, got;    /* bytes needed / bytes present */
	double value;        /* offending value (implausible) */
};

/* Decoded content of one input report. */
struct px_codec_values {
	int report_id;
	double axis[PX_AXIS__COUNT];
	uint32_t axis_mask;      /* bit a set: axis[a] came from this report */
	uint64_t buttons;        /* button bits carried by this report */
	uint64_t button_mask;    /* which buttons this report carries */
};

/*
 * Check a map: field widths and offsets, scales, axes, button runs,
 * outputs inside output_report_len. On failure d (may be NULL) says
 * which entry. Returns PX_OK or PX_E_INVAL. @note RT-safe.
 */
PX_API int px_codec_check(const struct px_codec_map *m,
			  struct px_codec_diag *d);

/* 1 when the map uses numbered reports (some input or button report id,
 * or the output report id, is non-zero). @note RT-safe. */
PX_API int px_codec_numbered(const struct px_codec_map *m);

/*
 * Decode one input report (as hid_read() returns it: with the id byte
 * for numbered devices). v is set from the fields and buttons of that
 * report only. Every field is checked before v changes: a bad report
 * leaves v as it was (and an all-zero mask).
 * Returns the number of fields plus button runs decoded (> 0), or
 * PX_E_PARSE (empty or short report), PX_E_NOTFOUND (report id the map
 * does not use), PX_E_RANGE (implausible value, corrupted report),
 * PX_E_INVAL (NULL). d (may be NULL) gets the details. @note RT-safe.
 */
PX_API int px_codec_decode(const struct px_codec_map *m, const uint8_t *buf,
			   size_t len, struct px_codec_values *v,
			   struct px_codec_diag *d);

/*
 * Encode a wrench command (indexed by enum px_wrench_axis) into the
 * output report: buf[0] = output_report_id, then output_report_len
 * bytes (unmapped bytes zero). *clamped (may be NULL) gets a bit per
 * output field that was clamped. Returns the byte count
 * (1 + output_report_len), PX_E_NOSPC (cap too small), PX_E_NAN (a
 * mapped channel not finite: nothing is encoded), PX_E_INVAL.
 * @note RT-safe.
 */
PX_API int px_codec_encode(const struct px_codec_map *m,
			   const double wrench[PX_WRENCH__COUNT], uint8_t *buf,
			   size_t cap, uint32_t *clamped,
			   struct px_codec_diag *d);

/*
 * The device side of the same map (simulated devices and test programs
 * that play a device, e.g. through /dev/uhid):
 * px_codec_encode_input() builds input report report_id from axis values
 * and buttons (values clamped to the fields' ranges; the id byte is
 * written for numbered maps) and returns its length, the smallest that
 * holds every field of that report, or PX_E_NOTFOUND / PX_E_NOSPC /
 * PX_E_NAN / PX_E_INVAL. px_codec_decode_output() reads an output
 * report back into wrench values (unmapped channels 0) and returns the
 * number of fields, or PX_E_PARSE / PX_E_NOTFOUND / PX_E_INVAL.
 * @note RT-safe.
 */
PX_API int px_codec_encode_input(const struct px_codec_map *m, int report_id,
				 const double axis[PX_AXIS__COUNT],
				 uint64_t buttons, uint8_t *buf, size_t cap);
PX_API int px_codec_decode_output(const struct px_codec_map *m,
				  const uint8_t *buf, size_t len,
				  double wrench[PX_WRENCH__COUNT],
				  struct px_codec_diag *d);

/*
 * Raw bit access used by the codec (exposed for tests and other frame
 * formats): read / write bit_width bits as described above at
 * byte_offset/bit_offset of buf (len bytes). Read sign-extends when
 * is_signed. Write stores the low bit_width bits of raw, leaving other
 * bits of the bytes untouched. Return PX_OK, PX_E_PARSE (does not fit
 * in len), PX_E_INVAL. @note RT-safe.
 */
PX_API int px_codec_get_raw(const uint8_t *buf, size_t len,
			    uint32_t byte_offset, unsigned bit_offset,
			    unsigned bit_width, int is_signed, int byte_order,
			    int64_t *raw);
PX_API int px_codec_put_raw(uint8_t *buf, size_t len, uint32_t byte_offset,
			    unsigned bit_offset, unsigned bit_width,
			    int byte_order, uint64_t raw);

/* Bytes (after the id byte) a field occupies up to: byte_offset +
 * ceil((bit_offset + bit_width) / 8). @note RT-safe. */
PX_API size_t px_codec_field_end(const struct px_codec_field *f);

/*
 * Write a one-line description of d into buf (cap bytes, always
 * terminated when cap > 0), prefixed with dev (device name, may be
 * NULL), e.g. "spacemouse: report 0x02: 5 bytes, inputs[3] needs 6".
 * Returns the length snprintf would produce. Not for the cycle.
 */
PX_API int px_codec_diag_format(const struct px_codec_diag *d,
				const char *dev, char *buf, size_t cap);

/*
 * Shipped mappings (the same as config/examples' spacemouse_hid.yaml and
 * haptic_hid.yaml):
 *  - "spacemouse": a 3Dconnexion-class 6-DoF device. Report 1 = X/Y/Z,
 *    report 2 = Rx/Ry/Rz, int16 little-endian about +-350 counts
 *    (350 counts = 50 mm and 0.35 rad); report 3 = 2 buttons.
 *  - "haptic": a generic 3-DoF haptic device. Input report 1: x, y, z
 *    int32 little-endian micrometres, 4 buttons in byte 12; output
 *    report 2: fx, fy, fz int16 little-endian millinewtons, clamped to
 *    3 N.
 * Returns the static map, or NULL for an unknown name.
 */
PX_API const struct px_codec_map *px_codec_builtin(const char *name);

#ifdef __cplusplus
}
#endif

#endif
