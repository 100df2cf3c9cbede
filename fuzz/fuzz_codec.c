/*
 * libFuzzer target: the HID report codec (devices/px_codec.h), decoder
 * and encoder, with maps built from the input as well as the shipped
 * ones. The first bytes describe a field map (fields, button runs,
 * output report), the rest are reports and command values.
 * Invariants: px_codec_check() accepts or names the bad entry; with a
 * checked map decoding never reads outside the report and gives finite
 * values within each field's plausibility limit; encoding refuses
 * non-finite commands, writes exactly 1 + output_report_len bytes, and
 * for fields that do not share bits the decoded output equals the
 * command clamped to max_abs and to the raw range (within half a
 * scale step); an input report built by px_codec_encode_input() decodes
 * back to the values it was built from (also within half a step).
 */
#include "fuzz_util.h"

#include "px_codec.h"

#define MAXF 8

static void read_field(struct fz *f, struct px_codec_field *x, int output)
{
	unsigned sel = fz_u8(f);
	x->report_id = (int)(sel & 3u);
	if (sel & 0x80)
		x->report_id = (int)(int8_t)fz_u8(f) * 3; /* out of range too */
	x->byte_offset = fz_u8(f) & 0x1fu;
	if (sel & 0x40)
		x->byte_offset = fz_u32(f);
	x->bit_offset = (uint8_t)fz_u8(f);
	if (!(sel & 0x20))
		x->bit_offset &= 7u;
	x->bit_width = (uint8_t)fz_u8(f);
	if (!(sel & 0x10))
		x->bit_width = (uint8_t)(x->bit_width % 65u);
	x->is_signed = (uint8_t)(fz_u8(f) & 1u);
	x->byte_order = (uint8_t)(fz_u8(f) % 3u);
	x->scale = fz_double(f);
	x->offset = fz_double(f);
	x->axis = (int)(fz_u8(f) % (output ? 8u : 8u)) - 1;
	x->max_abs = fz_double(f);
}

static int fields_overlap(const struct px_codec_field *a,
			  const struct px_codec_field *b)
{
	/* conservative: whole bytes */
	size_t a0 = a->byte_offset, a1 = px_codec_field_end(a);
	size_t b0 = b->byte_offset, b1 = px_codec_field_end(b);
	return a0 < b1 && b0 < a1;
}

/* The value a field round trip must give: value clamped to max_abs,
 * quantised, clamped to the raw range. Returns 0 when the field is too
 * wide for double arithmetic to say exactly. */
static int expected(const struct px_codec_field *x, double v, double *out,
		    double *tol)
{
	double lo, hi, r;
	if (x->bit_width > 52)
		return 0;
	if (x->max_abs > 0.0 && fabs(v) > x->max_abs)
		v = v > 0 ? x->max_abs : -x->max_abs;
	if (x->is_signed) {
		lo = -ldexp(1.0, x->bit_width - 1);
		hi = ldexp(1.0, x->bit_width - 1) - 1.0;
	} else {
		lo = 0.0;
		hi = ldexp(1.0, x->bit_width) - 1.0;
	}
	r = round((v - x->offset) / x->scale);
	if (!(r >= lo))
		r = lo;
	if (!(r <= hi))
		r = hi;
	*out = r * x->scale + x->offset;
	if (!isfinite(*out))
		return 0;
	*tol = 1e-9 * (fabs(*out) + fabs(x->offset) + fabs(x->scale));
	return 1;
}

static void check_diag(const struct px_codec_diag *d)
{
	char small[16], line[160];
	int n = px_codec_diag_format(d, "fz", line, sizeof line);
	if (n < 0)
		abort();
	if (!memchr(line, '\0', sizeof line))
		abort();
	px_codec_diag_format(d, NULL, small, sizeof small);
	if (!memchr(small, '\0', sizeof small))
		abort();
}

static void run_map(const struct px_codec_map *m, struct fz *f)
{
	struct px_codec_diag d;
	struct px_codec_values v;
	uint8_t rep[80], out[300];
	double wrench[PX_WRENCH__COUNT], back[PX_WRENCH__COUNT];
	double axis[PX_AXIS__COUNT];
	size_t i, j;
	int rc, k, rounds = 0;

	memset(&v, 0, sizeof v);
	/* reports */
	while (f->n && rounds++ < 16) {
		size_t len = fz_u8(f) % sizeof rep;
		uint8_t *exact;
		for (i = 0; i < len; i++)
			rep[i] = (uint8_t)fz_u8(f);
		/* exact-size heap copy: a read past its end is caught */
		exact = malloc(len ? len : 1);
		if (!exact)
			abort();
		memcpy(exact, rep, len);
		rc = px_codec_decode(m, exact, len, &v, &d);
		free(exact);
		if (rc > 0) {
			for (i = 0; i < m->n_inputs; i++) {
				const struct px_codec_field *x = &m->inputs[i];
				if (x->report_id != v.report_id)
					continue;
				if (!((v.axis_mask >> x->axis) & 1u))
					abort();
			}
			for (k = 0; k < PX_AXIS__COUNT; k++)
				if ((v.axis_mask >> k) & 1u) {
					if (!isfinite(v.axis[k]))
						abort();
				}
			for (i = 0; i < m->n_inputs; i++) {
				const struct px_codec_field *x = &m->inputs[i];
				if (x->report_id == v.report_id && x->max_abs > 0 &&
				    fabs(v.axis[x->axis]) > x->max_abs) {
					/* another field of the same axis may
					 * have written last: only if unique */
					int shared = 0;
					for (j = 0; j < m->n_inputs; j++)
						if (j != i &&
						    m->inputs[j].report_id == x->report_id &&
						    m->inputs[j].axis == x->axis)
							shared = 1;
					if (!shared)
						abort();
				}
			}
		} else {
			if (rc != PX_E_PARSE && rc != PX_E_NOTFOUND &&
			    rc != PX_E_RANGE)
				abort();
			check_diag(&d);
		}
		if (fz_u8(f) & 1u)
			break;
	}

	/* commands: encode and read back */
	for (k = 0; k < PX_WRENCH__COUNT; k++)
		wrench[k] = fz_double(f);
	rc = px_codec_encode(m, wrench, out, sizeof out, NULL, &d);
	if (rc == PX_E_NAN) {
		int any = 0;
		for (i = 0; i < m->n_outputs; i++)
			if (!isfinite(wrench[m->outputs[i].axis]))
				any = 1;
		if (!any)
			abort();
		check_diag(&d);
	} else if (rc == PX_E_NOSPC) {
		if (1 + m->output_report_len <= sizeof out)
			abort();
	} else {
		if (rc != (int)(1 + m->output_report_len) ||
		    out[0] != (uint8_t)m->output_report_id)
			abort();
		rc = px_codec_decode_output(m, out, (size_t)rc, back, &d);
		if (m->n_outputs && rc != (int)m->n_outputs)
			abort();
		for (i = 0; i < m->n_outputs; i++) {
			const struct px_codec_field *x = &m->outputs[i];
			double want, tol;
			int alone = 1;
			for (j = 0; j < m->n_outputs; j++)
				if (j != i && (fields_overlap(x, &m->outputs[j]) ||
					       m->outputs[j].axis == x->axis))
					alone = 0;
			if (!alone || !expected(x, wrench[x->axis], &want, &tol))
				continue;
			if (!(fabs(back[x->axis] - want) <= tol))
				abort();
		}
	}

	/* the device side: build an input report, decode it again */
	for (k = 0; k < PX_AXIS__COUNT; k++)
		axis[k] = fz_double(f);
	{
		int id = m->n_inputs ? m->inputs[0].report_id : 0;
		uint64_t buttons = fz_bits(f, 8);
		rc = px_codec_encode_input(m, id, axis, buttons, rep, sizeof rep);
		if (rc > 0) {
			memset(&v, 0, sizeof v);
			rc = px_codec_decode(m, rep, (size_t)rc, &v, &d);
			if (rc == PX_E_RANGE)
				return; /* clamped into an implausible value */
			if (rc <= 0)
				abort();
			for (i = 0; i < m->n_inputs; i++) {
				const struct px_codec_field *x = &m->inputs[i];
				double want, tol;
				int alone = 1;
				if (x->report_id != id)
					continue;
				for (j = 0; j < m->n_inputs; j++)
					if (j != i && m->inputs[j].report_id == id &&
					    (fields_overlap(x, &m->inputs[j]) ||
					     m->inputs[j].axis == x->axis))
						alone = 0;
				for (j = 0; j < m->n_buttons; j++)
					if (m->buttons[j].report_id == id)
						alone = 0;
				if (!alone || x->max_abs > 0 ||
				    !expected(x, axis[x->axis], &want, &tol))
					continue;
				if (!(fabs(v.axis[x->axis] - want) <= tol))
					abort();
			}
		} else if (rc != PX_E_NOTFOUND && rc != PX_E_NOSPC &&
			   rc != PX_E_NAN) {
			abort();
		}
	}
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct fz f = {data, size};
	struct px_codec_field in[MAXF], out[MAXF];
	struct px_codec_buttons bt[MAXF];
	struct px_codec_map m;
	struct px_codec_diag d;
	unsigned sel = fz_u8(&f);
	size_t i;

	if (sel < 16) {
		/* the shipped maps against arbitrary reports */
		const struct px_codec_map *b =
			px_codec_builtin(sel & 1 ? "haptic" : "spacemouse");
		if (!b || px_codec_check(b, &d) != PX_OK)
			abort();
		run_map(b, &f);
		return 0;
	}
	memset(&m, 0, sizeof m);
	memset(in, 0, sizeof in);
	memset(out, 0, sizeof out);
	memset(bt, 0, sizeof bt);
	m.n_inputs = fz_u8(&f) % (MAXF + 1);
	m.n_buttons = fz_u8(&f) % 3;
	m.n_outputs = fz_u8(&f) % (MAXF + 1);
	for (i = 0; i < m.n_inputs; i++)
		read_field(&f, &in[i], 0);
	for (i = 0; i < m.n_buttons; i++) {
		bt[i].report_id = (int)(fz_u8(&f) & 3u);
		bt[i].byte_offset = fz_u8(&f) & 0x1fu;
		bt[i].first_bit = (uint8_t)(fz_u8(&f) % 9u);
		bt[i].count = (uint8_t)(fz_u8(&f) % 66u);
		bt[i].first_button = (uint8_t)(fz_u8(&f) % 66u);
	}
	m.output_report_id = (int)(fz_u8(&f) & 3u);
	m.output_report_len = fz_u8(&f) % 40u;
	if (sel & 1)
		m.output_report_len = fz_u32(&f);
	for (i = 0; i < m.n_outputs; i++) {
		read_field(&f, &out[i], 1);
		if (!(sel & 2))
			out[i].report_id = m.output_report_id;
	}
	m.inputs = in;
	m.buttons = bt;
	m.outputs = out;
	if (px_codec_check(&m, &d) != PX_OK) {
		check_diag(&d);
		return 0;
	}
	run_map(&m, &f);
	return 0;
}
