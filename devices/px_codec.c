/* Report codec: bit fields of HID-style reports to and from physical
 * values. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "px_codec.h"

typedef unsigned __int128 px__u128;

static void diag_set(struct px_codec_diag *d, int what, int report_id,
		     int section, int index, size_t need, size_t got)
{
	if (!d)
		return;
	d->what = what;
	d->report_id = report_id;
	d->section = section;
	d->index = index;
	d->need = need;
	d->got = got;
	d->value = 0.0;
}

static unsigned span_bytes(unsigned bit_offset, unsigned bit_width)
{
	return (bit_offset + bit_width + 7u) / 8u;
}

size_t px_codec_field_end(const struct px_codec_field *f)
{
	if (!f)
		return 0;
	return (size_t)f->byte_offset + span_bytes(f->bit_offset, f->bit_width);
}

static px__u128 load(const uint8_t *p, unsigned nb, int byte_order)
{
	px__u128 acc = 0;
	unsigned i;
	for (i = 0; i < nb; i++) {
		unsigned sh = byte_order == PX_BIG_ENDIAN ? 8u * (nb - 1u - i)
							 : 8u * i;
		acc |= (px__u128)p[i] << sh;
	}
	return acc;
}

static void store(uint8_t *p, unsigned nb, int byte_order, px__u128 acc)
{
	unsigned i;
	for (i = 0; i < nb; i++) {
		unsigned sh = byte_order == PX_BIG_ENDIAN ? 8u * (nb - 1u - i)
							 : 8u * i;
		p[i] = (uint8_t)(acc >> sh);
	}
}

static uint64_t width_mask(unsigned w)
{
	return w >= 64 ? UINT64_MAX : (((uint64_t)1 << w) - 1u);
}

/* Unsigned bits of the field; the caller has checked that it fits. */
static uint64_t get_bits(const uint8_t *buf, uint32_t byte_offset,
			 unsigned bit_offset, unsigned bit_width,
			 int byte_order)
{
	unsigned nb = span_bytes(bit_offset, bit_width);
	px__u128 acc = load(buf + byte_offset, nb, byte_order);
	return (uint64_t)(acc >> bit_offset) & width_mask(bit_width);
}

static int64_t sign_extend(uint64_t u, unsigned w)
{
	if (w < 64 && (u >> (w - 1u)) & 1u)
		u |= ~width_mask(w);
	return (int64_t)u;
}

static void put_bits(uint8_t *buf, uint32_t byte_offset, unsigned bit_offset,
		     unsigned bit_width, int byte_order, uint64_t raw)
{
	unsigned nb = span_bytes(bit_offset, bit_width);
	px__u128 acc = load(buf + byte_offset, nb, byte_order);
	px__u128 m = (px__u128)width_mask(bit_width) << bit_offset;
	acc = (acc & ~m) | (((px__u128)(raw & width_mask(bit_width)))
			    << bit_offset);
	store(buf + byte_offset, nb, byte_order, acc);
}

static int bits_ok(unsigned bit_offset, unsigned bit_width, int byte_order)
{
	return bit_offset <= 7 && bit_width >= 1 && bit_width <= 64 &&
	       (byte_order == PX_LITTLE_ENDIAN || byte_order == PX_BIG_ENDIAN);
}

int px_codec_get_raw(const uint8_t *buf, size_t len, uint32_t byte_offset,
		     unsigned bit_offset, unsigned bit_width, int is_signed,
		     int byte_order, int64_t *raw)
{
	uint64_t u;
	if (!buf || !raw || !bits_ok(bit_offset, bit_width, byte_order))
		return PX_E_INVAL;
	if ((size_t)byte_offset + span_bytes(bit_offset, bit_width) > len)
		return PX_E_PARSE;
	u = get_bits(buf, byte_offset, bit_offset, bit_width, byte_order);
	*raw = is_signed ? sign_extend(u, bit_width) : (int64_t)u;
	return PX_OK;
}

int px_codec_put_raw(uint8_t *buf, size_t len, uint32_t byte_offset,
		     unsigned bit_offset, unsigned bit_width, int byte_order,
		     uint64_t raw)
{
	if (!buf || !bits_ok(bit_offset, bit_width, byte_order))
		return PX_E_INVAL;
	if ((size_t)byte_offset + span_bytes(bit_offset, bit_width) > len)
		return PX_E_PARSE;
	put_bits(buf, byte_offset, bit_offset, bit_width, byte_order, raw);
	return PX_OK;
}

int px_codec_numbered(const struct px_codec_map *m)
{
	size_t i;
	if (!m)
		return 0;
	for (i = 0; i < m->n_inputs; i++)
		if (m->inputs[i].report_id != 0)
			return 1;
	for (i = 0; i < m->n_buttons; i++)
		if (m->buttons[i].report_id != 0)
			return 1;
	return (m->n_outputs > 0 || m->output_report_len > 0) &&
	       m->output_report_id != 0;
}

static int field_ok(const struct px_codec_field *f)
{
	return f->report_id >= 0 && f->report_id <= 255 &&
	       bits_ok(f->bit_offset, f->bit_width, f->byte_order) &&
	       isfinite(f->scale) && f->scale != 0.0 && isfinite(f->offset) &&
	       f->axis >= 0 && f->axis < PX_AXIS__COUNT &&
	       isfinite(f->max_abs) && f->max_abs >= 0.0;
}

int px_codec_check(const struct px_codec_map *m, struct px_codec_diag *d)
{
	size_t i;
	int numbered;
	diag_set(d, PX_CODEC_OK, -1, 0, -1, 0, 0);
	if (!m || (m->n_inputs && !m->inputs) ||
	    (m->n_buttons && !m->buttons) || (m->n_outputs && !m->outputs))
		return PX_E_INVAL;
	numbered = px_codec_numbered(m);
	for (i = 0; i < m->n_inputs; i++) {
		const struct px_codec_field *f = &m->inputs[i];
		if (!field_ok(f) || (numbered && f->report_id == 0)) {
			diag_set(d, PX_CODEC_BAD_FIELD, f->report_id, 0,
				 (int)i, 0, 0);
			return PX_E_INVAL;
		}
	}
	for (i = 0; i < m->n_buttons; i++) {
		const struct px_codec_buttons *b = &m->buttons[i];
		if (b->report_id < 0 || b->report_id > 255 ||
		    b->first_bit > 7 || b->count < 1 || b->count > 64 ||
		    (unsigned)b->first_button + b->count > 64 ||
		    (numbered && b->report_id == 0)) {
			diag_set(d, PX_CODEC_BAD_BUTTONS, b->report_id, 1,
				 (int)i, 0, 0);
			return PX_E_INVAL;
		}
	}
	if (m->output_report_id < 0 || m->output_report_id > 255 ||
	    (numbered && m->n_outputs && m->output_report_id == 0)) {
		diag_set(d, PX_CODEC_BAD_FIELD, m->output_report_id, 2, -1, 0,
			 0);
		return PX_E_INVAL;
	}
	for (i = 0; i < m->n_outputs; i++) {
		const struct px_codec_field *f = &m->outputs[i];
		size_t end = px_codec_field_end(f);
		if (!field_ok(f) || f->report_id != m->output_report_id ||
		    end > m->output_report_len) {
			diag_set(d, PX_CODEC_BAD_FIELD, f->report_id, 2,
				 (int)i, end, m->output_report_len);
			return PX_E_INVAL;
		}
	}
	return PX_OK;
}

static double field_value(const struct px_codec_field *f, const uint8_t *data)
{
	uint64_t u = get_bits(data, f->byte_offset, f->bit_offset,
			      f->bit_width, f->byte_order);
	double r = f->is_signed ? (double)sign_extend(u, f->bit_width)
				: (double)u;
	return r * f->scale + f->offset;
}

int px_codec_decode(const struct px_codec_map *m, const uint8_t *buf,
		    size_t len, struct px_codec_values *v,
		    struct px_codec_diag *d)
{
	const uint8_t *data;
	size_t dlen, i;
	int numbered, id, n = 0;
	double tmp[PX_AXIS__COUNT];
	uint32_t amask = 0;
	uint64_t btn = 0, bmask = 0;

	diag_set(d, PX_CODEC_OK, -1, 0, -1, 0, len);
	if (!m || !v || (!buf && len))
		return PX_E_INVAL;
	numbered = px_codec_numbered(m);
	if (len == 0 || (numbered && len < 1)) {
		diag_set(d, PX_CODEC_EMPTY, -1, 0, -1, 1, len);
		return PX_E_PARSE;
	}
	id = numbered ? buf[0] : 0;
	data = numbered ? buf + 1 : buf;
	dlen = numbered ? len - 1 : len;
	for (i = 0; i < PX_AXIS__COUNT; i++)
		tmp[i] = 0.0;
	for (i = 0; i < m->n_inputs; i++) {
		const struct px_codec_field *f = &m->inputs[i];
		size_t end;
		double val;
		if (f->report_id != id)
			continue;
		end = px_codec_field_end(f);
		if (end > dlen) {
			diag_set(d, PX_CODEC_SHORT, id, 0, (int)i,
				 end + (size_t)numbered, len);
			return PX_E_PARSE;
		}
		val = field_value(f, data);
		if (!isfinite(val)) {
			diag_set(d, PX_CODEC_NONFINITE, id, 0, (int)i, 0, len);
			return PX_E_RANGE;
		}
		if (f->max_abs > 0.0 && fabs(val) > f->max_abs) {
			diag_set(d, PX_CODEC_IMPLAUSIBLE, id, 0, (int)i, 0,
				 len);
			if (d)
				d->value = val;
			return PX_E_RANGE;
		}
		tmp[f->axis] = val;
		amask |= 1u << f->axis;
		n++;
	}
	for (i = 0; i < m->n_buttons; i++) {
		const struct px_codec_buttons *b = &m->buttons[i];
		size_t end;
		unsigned k;
		if (b->report_id != id)
			continue;
		end = (size_t)b->byte_offset + span_bytes(b->first_bit, b->count);
		if (end > dlen) {
			diag_set(d, PX_CODEC_SHORT, id, 1, (int)i,
				 end + (size_t)numbered, len);
			return PX_E_PARSE;
		}
		for (k = 0; k < b->count; k++) {
			unsigned bit = b->first_bit + k;
			unsigned btn_i = b->first_button + k;
			uint64_t one = (uint64_t)1 << btn_i;
			bmask |= one;
			if ((data[b->byte_offset + bit / 8u] >> (bit % 8u)) & 1u)
				btn |= one;
			else
				btn &= ~one;
		}
		n++;
	}
	if (n == 0) {
		diag_set(d, PX_CODEC_UNKNOWN_REPORT, id, 0, -1, 0, len);
		return PX_E_NOTFOUND;
	}
	v->report_id = id;
	for (i = 0; i < PX_AXIS__COUNT; i++)
		v->axis[i] = (amask >> i) & 1u ? tmp[i] : v->axis[i];
	v->axis_mask = amask;
	v->buttons = btn;
	v->button_mask = bmask;
	return n;
}

/* Physical value to raw bits, clamped to max_abs and to the raw range.
 * Returns 1 when clamped. */
static int to_raw(const struct px_codec_field *f, double value, uint64_t *raw)
{
	int clamped = 0;
	double r;
	unsigned w = f->bit_width;
	if (f->max_abs > 0.0 && fabs(value) > f->max_abs) {
		value = value > 0 ? f->max_abs : -f->max_abs;
		clamped = 1;
	}
	r = round((value - f->offset) / f->scale);
	if (f->is_signed) {
		double hi = ldexp(1.0, (int)w - 1); /* exclusive */
		if (r >= hi) {
			*raw = width_mask(w - 1u);
			return 1;
		}
		if (r < -hi) {
			*raw = (uint64_t)1 << (w - 1u);
			return 1;
		}
		*raw = (uint64_t)(int64_t)r;
	} else {
		double hi = ldexp(1.0, (int)w);
		if (r >= hi) {
			*raw = width_mask(w);
			return 1;
		}
		if (r < 0.0) {
			*raw = 0;
			return 1;
		}
		*raw = (uint64_t)r;
	}
	return clamped;
}

int px_codec_encode(const struct px_codec_map *m,
		    const double wrench[PX_WRENCH__COUNT], uint8_t *buf,
		    size_t cap, uint32_t *clamped, struct px_codec_diag *d)
{
	size_t i, n;
	uint32_t cm = 0;
	diag_set(d, PX_CODEC_OK, m ? m->output_report_id : -1, 2, -1, 0, 0);
	if (!m || !wrench || !buf)
		return PX_E_INVAL;
	n = 1 + m->output_report_len;
	if (cap < n) {
		diag_set(d, PX_CODEC_NOSPC, m->output_report_id, 2, -1, n, cap);
		return PX_E_NOSPC;
	}
	for (i = 0; i < m->n_outputs; i++) {
		const struct px_codec_field *f = &m->outputs[i];
		if (f->axis < 0 || f->axis >= PX_WRENCH__COUNT ||
		    px_codec_field_end(f) > m->output_report_len ||
		    !bits_ok(f->bit_offset, f->bit_width, f->byte_order)) {
			diag_set(d, PX_CODEC_BAD_FIELD, f->report_id, 2,
				 (int)i, px_codec_field_end(f),
				 m->output_report_len);
			return PX_E_INVAL;
		}
		if (!isfinite(wrench[f->axis])) {
			diag_set(d, PX_CODEC_NONFINITE, f->report_id, 2,
				 (int)i, 0, 0);
			return PX_E_NAN;
		}
	}
	memset(buf, 0, n);
	buf[0] = (uint8_t)m->output_report_id;
	for (i = 0; i < m->n_outputs; i++) {
		const struct px_codec_field *f = &m->outputs[i];
		uint64_t raw;
		if (to_raw(f, wrench[f->axis], &raw) && i < 32)
			cm |= 1u << i;
		put_bits(buf + 1, f->byte_offset, f->bit_offset, f->bit_width,
			 f->byte_order, raw);
	}
	if (clamped)
		*clamped = cm;
	return (int)n;
}

int px_codec_encode_input(const struct px_codec_map *m, int report_id,
			  const double axis[PX_AXIS__COUNT], uint64_t buttons,
			  uint8_t *buf, size_t cap)
{
	size_t i, end = 0, n;
	int numbered, found = 0;
	uint8_t *data;
	if (!m || !axis || !buf)
		return PX_E_INVAL;
	numbered = px_codec_numbered(m);
	for (i = 0; i < m->n_inputs; i++) {
		const struct px_codec_field *f = &m->inputs[i];
		if (f->report_id != report_id)
			continue;
		if (f->axis < 0 || f->axis >= PX_AXIS__COUNT ||
		    !bits_ok(f->bit_offset, f->bit_width, f->byte_order))
			return PX_E_INVAL;
		if (!isfinite(axis[f->axis]))
			return PX_E_NAN;
		found = 1;
		if (px_codec_field_end(f) > end)
			end = px_codec_field_end(f);
	}
	for (i = 0; i < m->n_buttons; i++) {
		const struct px_codec_buttons *b = &m->buttons[i];
		size_t e;
		if (b->report_id != report_id)
			continue;
		found = 1;
		e = (size_t)b->byte_offset + span_bytes(b->first_bit, b->count);
		if (e > end)
			end = e;
	}
	if (!found)
		return PX_E_NOTFOUND;
	n = end + (size_t)numbered;
	if (cap < n)
		return PX_E_NOSPC;
	memset(buf, 0, n);
	if (numbered)
		buf[0] = (uint8_t)report_id;
	data = numbered ? buf + 1 : buf;
	for (i = 0; i < m->n_inputs; i++) {
		const struct px_codec_field *f = &m->inputs[i];
		struct px_codec_field g;
		uint64_t raw;
		if (f->report_id != report_id)
			continue;
		g = *f;
		g.max_abs = 0.0; /* a device may send implausible values */
		to_raw(&g, axis[f->axis], &raw);
		put_bits(data, f->byte_offset, f->bit_offset, f->bit_width,
			 f->byte_order, raw);
	}
	for (i = 0; i < m->n_buttons; i++) {
		const struct px_codec_buttons *b = &m->buttons[i];
		unsigned k;
		if (b->report_id != report_id)
			continue;
		for (k = 0; k < b->count; k++) {
			unsigned bit = b->first_bit + k;
			uint8_t *p = &data[b->byte_offset + bit / 8u];
			if ((buttons >> (b->first_button + k)) & 1u)
				*p |= (uint8_t)(1u << (bit % 8u));
			else
				*p &= (uint8_t)~(1u << (bit % 8u));
		}
	}
	return (int)n;
}

int px_codec_decode_output(const struct px_codec_map *m, const uint8_t *buf,
			   size_t len, double wrench[PX_WRENCH__COUNT],
			   struct px_codec_diag *d)
{
	size_t i;
	int n = 0;
	diag_set(d, PX_CODEC_OK, -1, 2, -1, 0, len);
	if (!m || !wrench || (!buf && len))
		return PX_E_INVAL;
	if (len < 1) {
		diag_set(d, PX_CODEC_EMPTY, -1, 2, -1, 1, len);
		return PX_E_PARSE;
	}
	if (buf[0] != m->output_report_id) {
		diag_set(d, PX_CODEC_UNKNOWN_REPORT, buf[0], 2, -1, 0, len);
		return PX_E_NOTFOUND;
	}
	for (i = 0; i < m->n_outputs; i++) {
		const struct px_codec_field *f = &m->outputs[i];
		if (f->axis < 0 || f->axis >= PX_WRENCH__COUNT ||
		    !bits_ok(f->bit_offset, f->bit_width, f->byte_order))
			return PX_E_INVAL;
		if (px_codec_field_end(f) + 1 > len) {
			diag_set(d, PX_CODEC_SHORT, buf[0], 2, (int)i,
				 px_codec_field_end(f) + 1, len);
			return PX_E_PARSE;
		}
	}
	for (i = 0; i < PX_WRENCH__COUNT; i++)
		wrench[i] = 0.0;
	for (i = 0; i < m->n_outputs; i++) {
		wrench[m->outputs[i].axis] = field_value(&m->outputs[i], buf + 1);
		n++;
	}
	return n;
}

static const char *section_name(int s)
{
	return s == 1 ? "buttons" : s == 2 ? "outputs" : "inputs";
}

int px_codec_diag_format(const struct px_codec_diag *d, const char *dev,
			 char *buf, size_t cap)
{
	char where[48] = "";
	const char *sep = dev && *dev ? ": " : "";
	if (!dev)
		dev = "";
	if (!d)
		return snprintf(buf, cap, "%s%sno diagnostic", dev, sep);
	if (d->index >= 0)
		snprintf(where, sizeof where, "%s[%d]", section_name(d->section),
			 d->index);
	switch (d->what) {
	case PX_CODEC_OK:
		return snprintf(buf, cap, "%s%sok", dev, sep);
	case PX_CODEC_EMPTY:
		return snprintf(buf, cap, "%s%sempty report", dev, sep);
	case PX_CODEC_UNKNOWN_REPORT:
		return snprintf(buf, cap,
				"%s%sreport id 0x%02x is not in the mapping "
				"(%zu bytes)", dev, sep, d->report_id & 0xff,
				d->got);
	case PX_CODEC_SHORT:
		return snprintf(buf, cap,
				"%s%sreport 0x%02x: %zu bytes, %s needs %zu", dev,
				sep, d->report_id & 0xff, d->got, where,
				d->need);
	case PX_CODEC_IMPLAUSIBLE:
		return snprintf(buf, cap,
				"%s%sreport 0x%02x: %s = %g beyond max_abs "
				"(corrupted report?)", dev, sep,
				d->report_id & 0xff, where, d->value);
	case PX_CODEC_NONFINITE:
		return snprintf(buf, cap, "%s%sreport 0x%02x: %s not finite",
				dev, sep, d->report_id & 0xff, where);
	case PX_CODEC_BAD_FIELD:
		if (d->section == 2 && d->need > d->got)
			return snprintf(buf, cap,
					"%s%s%s ends at byte %zu, beyond "
					"output_report_len %zu", dev, sep,
					where, d->need, d->got);
		return snprintf(buf, cap,
				"%s%s%s: bad field (report id 0..255 and "
				"consistent, bit_offset 0..7, bit_width 1..64, "
				"finite non-zero scale, axis 0..5)", dev, sep,
				where[0] ? where : "output_report_id");
	case PX_CODEC_BAD_BUTTONS:
		return snprintf(buf, cap,
				"%s%s%s: bad button run (first_bit 0..7, "
				"count 1..64, first_button + count <= 64)", dev,
				sep, where);
	case PX_CODEC_NOSPC:
		return snprintf(buf, cap,
				"%s%sbuffer of %zu bytes, report needs %zu", dev,
				sep, d->got, d->need);
	default:
		return snprintf(buf, cap, "%s%sunknown codec error %d", dev,
				sep, d->what);
	}
}

/* ---- shipped mappings ---------------------------------------------- */

#define SM_POS (50e-3 / 350.0) /* 350 counts = 50 mm */
#define SM_ROT (0.35 / 350.0)  /* 350 counts = 0.35 rad */

static const struct px_codec_field spacemouse_in[] = {
	{1, 0, 0, 16, 1, PX_LITTLE_ENDIAN, SM_POS, 0.0, PX_AXIS_X, 0.0},
	{1, 2, 0, 16, 1, PX_LITTLE_ENDIAN, SM_POS, 0.0, PX_AXIS_Y, 0.0},
	{1, 4, 0, 16, 1, PX_LITTLE_ENDIAN, SM_POS, 0.0, PX_AXIS_Z, 0.0},
	{2, 0, 0, 16, 1, PX_LITTLE_ENDIAN, SM_ROT, 0.0, PX_AXIS_RX, 0.0},
	{2, 2, 0, 16, 1, PX_LITTLE_ENDIAN, SM_ROT, 0.0, PX_AXIS_RY, 0.0},
	{2, 4, 0, 16, 1, PX_LITTLE_ENDIAN, SM_ROT, 0.0, PX_AXIS_RZ, 0.0},
};
static const struct px_codec_buttons spacemouse_btn[] = {
	{3, 0, 0, 2, 0},
};
static const struct px_codec_map spacemouse_map = {
	spacemouse_in, 6, spacemouse_btn, 1, NULL, 0, 0, 0,
};

static const struct px_codec_field haptic_in[] = {
	{1, 0, 0, 32, 1, PX_LITTLE_ENDIAN, 1e-6, 0.0, PX_AXIS_X, 0.0},
	{1, 4, 0, 32, 1, PX_LITTLE_ENDIAN, 1e-6, 0.0, PX_AXIS_Y, 0.0},
	{1, 8, 0, 32, 1, PX_LITTLE_ENDIAN, 1e-6, 0.0, PX_AXIS_Z, 0.0},
};
static const struct px_codec_buttons haptic_btn[] = {
	{1, 12, 0, 4, 0},
};
static const struct px_codec_field haptic_out[] = {
	{2, 0, 0, 16, 1, PX_LITTLE_ENDIAN, 1e-3, 0.0, PX_WRENCH_FX, 3.0},
	{2, 2, 0, 16, 1, PX_LITTLE_ENDIAN, 1e-3, 0.0, PX_WRENCH_FY, 3.0},
	{2, 4, 0, 16, 1, PX_LITTLE_ENDIAN, 1e-3, 0.0, PX_WRENCH_FZ, 3.0},
};
static const struct px_codec_map haptic_map = {
	haptic_in, 3, haptic_btn, 1, haptic_out, 3, 2, 6,
};

const struct px_codec_map *px_codec_builtin(const char *name)
{
	if (!name)
		return NULL;
	if (!strcmp(name, "spacemouse"))
		return &spacemouse_map;
	if (!strcmp(name, "haptic"))
		return &haptic_map;
	return NULL;
}
