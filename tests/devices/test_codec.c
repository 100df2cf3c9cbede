/* Report codec: bit access against a bit-by-bit reference, random
 * round trips, edges (odd widths, big-endian, sign extension, 64-bit),
 * clamping, and every kind of bad report. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "px_alloc_count.h"
#include "px_codec.h"
#include "px_test.h"

/* Reference: where field bit k lives. */
static void ref_pos(unsigned byte_offset, unsigned bit_offset, unsigned width,
		    int order, unsigned k, unsigned *byte, unsigned *bit)
{
	unsigned j = bit_offset + k;
	if (order == PX_LITTLE_ENDIAN) {
		*byte = byte_offset + j / 8;
	} else {
		unsigned nb = (bit_offset + width + 7) / 8;
		*byte = byte_offset + nb - 1 - j / 8;
	}
	*bit = j % 8;
}

static uint64_t ref_get(const uint8_t *b, unsigned bo, unsigned bit_off,
			unsigned w, int order)
{
	uint64_t v = 0;
	unsigned k, by, bi;
	for (k = 0; k < w; k++) {
		ref_pos(bo, bit_off, w, order, k, &by, &bi);
		if ((b[by] >> bi) & 1)
			v |= (uint64_t)1 << k;
	}
	return v;
}

static void ref_put(uint8_t *b, unsigned bo, unsigned bit_off, unsigned w,
		    int order, uint64_t v)
{
	unsigned k, by, bi;
	for (k = 0; k < w; k++) {
		ref_pos(bo, bit_off, w, order, k, &by, &bi);
		if ((v >> k) & 1)
			b[by] |= (uint8_t)(1u << bi);
		else
			b[by] &= (uint8_t)~(1u << bi);
	}
}

static void test_raw_bits_match_reference(void)
{
	int it;
	for (it = 0; it < 20000; it++) {
		uint8_t b[24], r[24];
		unsigned w = (unsigned)px_rand_int(1, 64);
		unsigned bit_off = (unsigned)px_rand_int(0, 7);
		unsigned nb = (bit_off + w + 7) / 8;
		unsigned bo = (unsigned)px_rand_int(0, (int)(sizeof b - nb));
		int order = px_rand_int(0, 1), sgn = px_rand_int(0, 1);
		int64_t raw;
		uint64_t want, val;
		size_t i;
		for (i = 0; i < sizeof b; i++)
			b[i] = (uint8_t)px_rand_u64();
		PX_CHECK_INT_EQ(px_codec_get_raw(b, sizeof b, bo, bit_off, w,
						 sgn, order, &raw),
				PX_OK);
		want = ref_get(b, bo, bit_off, w, order);
		if (sgn && w < 64 && ((want >> (w - 1)) & 1))
			want |= ~(((uint64_t)1 << w) - 1);
		PX_CHECK_MSG((uint64_t)raw == want,
			     "w %u off %u.%u order %d: %llx != %llx", w, bo,
			     bit_off, order, (unsigned long long)raw,
			     (unsigned long long)want);
		/* put touches exactly the field's bits */
		val = px_rand_u64();
		memcpy(r, b, sizeof b);
		ref_put(r, bo, bit_off, w, order, val);
		PX_CHECK_INT_EQ(px_codec_put_raw(b, sizeof b, bo, bit_off, w,
						 order, val),
				PX_OK);
		PX_CHECK(memcmp(r, b, sizeof b) == 0);
	}
	/* out of the buffer */
	{
		uint8_t b[4] = {0};
		int64_t raw;
		PX_CHECK_INT_EQ(px_codec_get_raw(b, 4, 2, 1, 16, 0, 0, &raw),
				PX_E_PARSE);
		PX_CHECK_INT_EQ(px_codec_put_raw(b, 4, 3, 0, 9, 0, 1),
				PX_E_PARSE);
		PX_CHECK_INT_EQ(px_codec_get_raw(b, 4, 0, 8, 4, 0, 0, &raw),
				PX_E_INVAL);
		PX_CHECK_INT_EQ(px_codec_get_raw(b, 4, 0, 0, 0, 0, 0, &raw),
				PX_E_INVAL);
		PX_CHECK_INT_EQ(px_codec_get_raw(b, 4, 0, 0, 65, 0, 0, &raw),
				PX_E_INVAL);
	}
}

static void test_sign_extension_edges(void)
{
	uint8_t b[9];
	int64_t raw;
	/* 1-bit signed: 1 is -1 */
	memset(b, 0, sizeof b);
	b[0] = 0x08;
	PX_CHECK_INT_EQ(px_codec_get_raw(b, 9, 0, 3, 1, 1, 0, &raw), PX_OK);
	PX_CHECK_INT_EQ(raw, -1);
	PX_CHECK_INT_EQ(px_codec_get_raw(b, 9, 0, 3, 1, 0, 0, &raw), PX_OK);
	PX_CHECK_INT_EQ(raw, 1);
	/* 12-bit big-endian 0x800 = -2048 */
	memset(b, 0, sizeof b);
	b[0] = 0x08;
	b[1] = 0x00;
	PX_CHECK_INT_EQ(px_codec_get_raw(b, 9, 0, 0, 12, 1, 1, &raw), PX_OK);
	PX_CHECK_INT_EQ(raw, -2048);
	/* same bytes little-endian, 12 bits: 0x008 */
	PX_CHECK_INT_EQ(px_codec_get_raw(b, 9, 0, 0, 12, 1, 0, &raw), PX_OK);
	PX_CHECK_INT_EQ(raw, 8);
	/* 64-bit signed extremes at an odd bit offset (9 bytes) */
	memset(b, 0, sizeof b);
	PX_CHECK_INT_EQ(px_codec_put_raw(b, 9, 0, 5, 64, 0,
					 (uint64_t)INT64_MIN),
			PX_OK);
	PX_CHECK_INT_EQ(px_codec_get_raw(b, 9, 0, 5, 64, 1, 0, &raw), PX_OK);
	PX_CHECK(raw == INT64_MIN);
	PX_CHECK_INT_EQ(px_codec_put_raw(b, 9, 0, 5, 64, 1,
					 (uint64_t)INT64_MAX),
			PX_OK);
	PX_CHECK_INT_EQ(px_codec_get_raw(b, 9, 0, 5, 64, 1, 1, &raw), PX_OK);
	PX_CHECK(raw == INT64_MAX);
	/* int16 big-endian 0xFEA2 = -350 */
	b[0] = 0xFE;
	b[1] = 0xA2;
	PX_CHECK_INT_EQ(px_codec_get_raw(b, 2, 0, 0, 16, 1, 1, &raw), PX_OK);
	PX_CHECK_INT_EQ(raw, -350);
}

/* Build a random single-report map with non-overlapping fields. */
static size_t random_fields(struct px_codec_field *f, size_t max, int id,
			    int outputs, size_t *len_out)
{
	size_t n = (size_t)px_rand_int(1, (int)max), i;
	unsigned bitpos = (unsigned)px_rand_int(0, 9);
	for (i = 0; i < n; i++) {
		unsigned w = (unsigned)px_rand_int(1, 40);
		int order = px_rand_int(0, 1);
		memset(&f[i], 0, sizeof f[i]);
		/* A big-endian field's bit offset counts in its last byte, so
		 * it gets whole bytes of its own. */
		if (order == PX_BIG_ENDIAN)
			bitpos = (bitpos + 7) / 8 * 8 +
				 (unsigned)px_rand_int(0, 7);
		f[i].report_id = id;
		f[i].byte_offset = bitpos / 8;
		f[i].bit_offset = (uint8_t)(bitpos % 8);
		f[i].bit_width = (uint8_t)w;
		f[i].is_signed = (uint8_t)px_rand_int(0, 1);
		f[i].byte_order = (uint8_t)order;
		f[i].scale = px_rand_range(-2.0, 2.0);
		if (fabs(f[i].scale) < 1e-3)
			f[i].scale = 1e-3;
		f[i].offset = px_rand_range(-10, 10);
		f[i].axis = (int)i;
		if (order == PX_BIG_ENDIAN)
			bitpos = f[i].byte_offset * 8 +
				 (f[i].bit_offset + w + 7) / 8 * 8;
		else
			bitpos += w;
		if (px_rand_int(0, 3) == 0)
			bitpos += (unsigned)px_rand_int(0, 12);
	}
	(void)outputs;
	*len_out = (bitpos + 7) / 8 + 2;
	return n;
}

static double random_raw_value(const struct px_codec_field *f, int64_t *raw)
{
	unsigned w = f->bit_width;
	int64_t lo, hi;
	if (f->is_signed) {
		lo = -((int64_t)1 << (w - 1));
		hi = ((int64_t)1 << (w - 1)) - 1;
	} else {
		lo = 0;
		hi = (int64_t)(((uint64_t)1 << w) - 1);
	}
	switch (px_rand_int(0, 3)) {
	case 0: *raw = lo; break;
	case 1: *raw = hi; break;
	default: *raw = lo + (int64_t)(px_rand_u64() % (uint64_t)(hi - lo + 1));
	}
	return (double)*raw * f->scale + f->offset;
}

static void test_random_input_and_output_roundtrip(void)
{
	int it;
	for (it = 0; it < 3000; it++) {
		struct px_codec_field f[6];
		struct px_codec_map m;
		struct px_codec_values v;
		struct px_codec_diag d;
		uint8_t buf[64];
		double axis[PX_AXIS__COUNT] = {0}, want[PX_AXIS__COUNT] = {0};
		double back[PX_WRENCH__COUNT];
		size_t len, n, i;
		int id = px_rand_int(0, 1) ? px_rand_int(1, 255) : 0;
		int rc;
		n = random_fields(f, 6, id, 0, &len);
		memset(&m, 0, sizeof m);
		m.inputs = f;
		m.n_inputs = n;
		m.outputs = f;
		m.n_outputs = n;
		m.output_report_id = id;
		m.output_report_len = len;
		PX_CHECK_INT_EQ(px_codec_check(&m, &d), PX_OK);
		for (i = 0; i < n; i++) {
			int64_t raw;
			want[i] = random_raw_value(&f[i], &raw);
			axis[i] = want[i];
		}
		rc = px_codec_encode_input(&m, id, axis, 0, buf, sizeof buf);
		PX_CHECK(rc > 0);
		memset(&v, 0, sizeof v);
		PX_CHECK_INT_EQ(px_codec_decode(&m, buf, (size_t)rc, &v, &d),
				(int)n);
		PX_CHECK_INT_EQ(v.report_id, id);
		PX_CHECK_INT_EQ(v.axis_mask, (1u << n) - 1);
		for (i = 0; i < n; i++)
			PX_CHECK_MSG(v.axis[i] == want[i],
				     "field %zu w %u: %.17g != %.17g", i,
				     f[i].bit_width, v.axis[i], want[i]);
		/* outputs through encode / decode_output */
		rc = px_codec_encode(&m, axis, buf, sizeof buf, NULL, &d);
		PX_CHECK_INT_EQ(rc, (int)(len + 1));
		PX_CHECK_INT_EQ(buf[0], id);
		PX_CHECK_INT_EQ(px_codec_decode_output(&m, buf, (size_t)rc,
						       back, &d),
				(int)n);
		for (i = 0; i < n; i++)
			PX_CHECK(back[i] == want[i]);
	}
}

static void test_clamping(void)
{
	struct px_codec_field f[3] = {
		{1, 0, 0, 16, 1, PX_LITTLE_ENDIAN, 1e-3, 0, PX_WRENCH_FX, 3.0},
		{1, 2, 0, 8, 1, PX_LITTLE_ENDIAN, 1.0, 0, PX_WRENCH_FY, 0.0},
		{1, 3, 4, 4, 0, PX_BIG_ENDIAN, 1.0, 0, PX_WRENCH_FZ, 0.0},
	};
	struct px_codec_map m = {NULL, 0, NULL, 0, f, 3, 1, 4};
	double w[6] = {5.0, 1000.0, -3.0, 0, 0, 0}, back[6];
	uint8_t buf[8];
	uint32_t cl = 0;
	PX_CHECK_INT_EQ(px_codec_check(&m, NULL), PX_OK);
	PX_CHECK_INT_EQ(px_codec_encode(&m, w, buf, sizeof buf, &cl, NULL), 5);
	PX_CHECK_INT_EQ(cl, 7u);
	PX_CHECK_INT_EQ(px_codec_decode_output(&m, buf, 5, back, NULL), 3);
	PX_CHECK_NEAR(back[0], 3.0, 1e-12);   /* max_abs */
	PX_CHECK_NEAR(back[1], 127.0, 0);     /* int8 saturation */
	PX_CHECK_NEAR(back[2], 0.0, 0);       /* unsigned floor */
	w[0] = -5.0;
	w[1] = -1000.0;
	w[2] = 99.0;
	PX_CHECK_INT_EQ(px_codec_encode(&m, w, buf, sizeof buf, &cl, NULL), 5);
	PX_CHECK_INT_EQ(px_codec_decode_output(&m, buf, 5, back, NULL), 3);
	PX_CHECK_NEAR(back[0], -3.0, 1e-12);
	PX_CHECK_NEAR(back[1], -128.0, 0);
	PX_CHECK_NEAR(back[2], 15.0, 0);
	/* inside the range: no clamp, rounding to nearest */
	w[0] = 1.2344;
	w[1] = -7.6;
	w[2] = 2.5;
	PX_CHECK_INT_EQ(px_codec_encode(&m, w, buf, sizeof buf, &cl, NULL), 5);
	PX_CHECK_INT_EQ(cl, 0u);
	PX_CHECK_INT_EQ(px_codec_decode_output(&m, buf, 5, back, NULL), 3);
	PX_CHECK_NEAR(back[0], 1.234, 1e-12);
	PX_CHECK_NEAR(back[1], -8.0, 0);
	PX_CHECK_NEAR(back[2], 3.0, 0);
	/* NaN: refused, nothing written */
	memset(buf, 0xEE, sizeof buf);
	w[1] = NAN;
	PX_CHECK_INT_EQ(px_codec_encode(&m, w, buf, sizeof buf, &cl, NULL),
			PX_E_NAN);
	PX_CHECK_INT_EQ(buf[0], 0xEE);
	/* too small a buffer */
	w[1] = 0;
	PX_CHECK_INT_EQ(px_codec_encode(&m, w, buf, 4, &cl, NULL), PX_E_NOSPC);
}

static void msg_has(const struct px_codec_diag *d, const char *dev,
		    const char *needle)
{
	char buf[200];
	px_codec_diag_format(d, dev, buf, sizeof buf);
	PX_CHECK_MSG(strstr(buf, needle) != NULL, "'%s' lacks '%s'", buf,
		     needle);
}

static void test_bad_reports_give_clear_errors(void)
{
	const struct px_codec_map *sm = px_codec_builtin("spacemouse");
	struct px_codec_values v;
	struct px_codec_diag d;
	uint8_t r1[7] = {1, 0x5E, 0x01, 0xA2, 0xFE, 0, 0};
	uint8_t bad[7];
	PX_CHECK(sm != NULL);
	memset(&v, 0, sizeof v);
	PX_CHECK_INT_EQ(px_codec_decode(sm, r1, 7, &v, &d), 3);
	PX_CHECK_NEAR(v.axis[PX_AXIS_X], 0.05, 1e-12);
	PX_CHECK_NEAR(v.axis[PX_AXIS_Y], -0.05, 1e-12);
	/* unknown report id: values untouched */
	memcpy(bad, r1, 7);
	bad[0] = 7;
	PX_CHECK_INT_EQ(px_codec_decode(sm, bad, 7, &v, &d), PX_E_NOTFOUND);
	PX_CHECK_INT_EQ(d.what, PX_CODEC_UNKNOWN_REPORT);
	PX_CHECK_NEAR(v.axis[PX_AXIS_X], 0.05, 1e-12);
	msg_has(&d, "spacemouse", "spacemouse: report id 0x07 is not in the mapping");
	/* short */
	PX_CHECK_INT_EQ(px_codec_decode(sm, r1, 6, &v, &d), PX_E_PARSE);
	PX_CHECK_INT_EQ(d.what, PX_CODEC_SHORT);
	PX_CHECK_INT_EQ(d.index, 2);
	PX_CHECK_INT_EQ((int)d.need, 7);
	msg_has(&d, "sm", "report 0x01: 6 bytes, inputs[2] needs 7");
	PX_CHECK_NEAR(v.axis[PX_AXIS_X], 0.05, 1e-12);
	/* empty */
	PX_CHECK_INT_EQ(px_codec_decode(sm, r1, 0, &v, &d), PX_E_PARSE);
	PX_CHECK_INT_EQ(d.what, PX_CODEC_EMPTY);
	/* buttons short */
	bad[0] = 3;
	PX_CHECK_INT_EQ(px_codec_decode(sm, bad, 1, &v, &d), PX_E_PARSE);
	msg_has(&d, NULL, "buttons[0] needs 2");
	/* implausible value with an input max_abs */
	{
		struct px_codec_field f = {1, 0, 0, 16, 1, 0, 1e-3, 0,
					   PX_AXIS_Z, 0.5};
		struct px_codec_map m = {&f, 1, NULL, 0, NULL, 0, 0, 0};
		uint8_t r[3] = {1, 0x10, 0x27}; /* 10000 -> 10.0 */
		PX_CHECK_INT_EQ(px_codec_decode(&m, r, 3, &v, &d), PX_E_RANGE);
		PX_CHECK_INT_EQ(d.what, PX_CODEC_IMPLAUSIBLE);
		msg_has(&d, "dev", "corrupted");
		r[2] = 0x01; /* 272 -> 0.272 */
		PX_CHECK_INT_EQ(px_codec_decode(&m, r, 3, &v, &d), 1);
		PX_CHECK_NEAR(v.axis[PX_AXIS_Z], 0.272, 1e-12);
	}
	PX_CHECK_INT_EQ(px_codec_decode(NULL, r1, 7, &v, &d), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_codec_decode(sm, NULL, 7, &v, &d), PX_E_INVAL);
}

static void test_map_check_names_the_entry(void)
{
	struct px_codec_field in[2] = {
		{1, 0, 0, 16, 1, 0, 1.0, 0, PX_AXIS_X, 0},
		{1, 2, 0, 16, 1, 0, 1.0, 0, PX_AXIS_Y, 0},
	};
	struct px_codec_field out[2] = {
		{2, 0, 0, 16, 1, 0, 1.0, 0, PX_WRENCH_FX, 0},
		{2, 4, 4, 16, 1, 0, 1.0, 0, PX_WRENCH_FY, 0},
	};
	struct px_codec_buttons bt = {1, 4, 3, 8, 60};
	struct px_codec_map m = {in, 2, NULL, 0, out, 2, 2, 6};
	struct px_codec_diag d;
	PX_CHECK_INT_EQ(px_codec_check(&m, &d), PX_E_INVAL);
	PX_CHECK_INT_EQ(d.section, 2);
	PX_CHECK_INT_EQ(d.index, 1);
	msg_has(&d, "hap", "outputs[1] ends at byte 7, beyond output_report_len 6");
	m.output_report_len = 7;
	PX_CHECK_INT_EQ(px_codec_check(&m, &d), PX_OK);
	in[1].bit_width = 0;
	PX_CHECK_INT_EQ(px_codec_check(&m, &d), PX_E_INVAL);
	msg_has(&d, NULL, "inputs[1]: bad field");
	in[1].bit_width = 16;
	in[1].scale = 0.0;
	PX_CHECK_INT_EQ(px_codec_check(&m, &d), PX_E_INVAL);
	in[1].scale = 1.0;
	in[1].report_id = 0; /* mixing numbered and unnumbered */
	PX_CHECK_INT_EQ(px_codec_check(&m, &d), PX_E_INVAL);
	in[1].report_id = 1;
	m.buttons = &bt;
	m.n_buttons = 1;
	PX_CHECK_INT_EQ(px_codec_check(&m, &d), PX_E_INVAL);
	msg_has(&d, NULL, "buttons[0]: bad button run");
	bt.first_button = 0;
	PX_CHECK_INT_EQ(px_codec_check(&m, &d), PX_OK);
	out[0].report_id = 3; /* not the output report */
	PX_CHECK_INT_EQ(px_codec_check(&m, &d), PX_E_INVAL);
}

static void test_builtin_maps(void)
{
	const struct px_codec_map *sm = px_codec_builtin("spacemouse");
	const struct px_codec_map *hp = px_codec_builtin("haptic");
	struct px_codec_values v;
	uint8_t r2[7] = {2, 0xA2, 0xFE, 0, 0, 0x5E, 0x01};
	uint8_t r3[2] = {3, 0x02};
	uint8_t h1[14] = {1, 0x40, 0x42, 0x0F, 0x00, 0xC0, 0xBD, 0xF0, 0xFF,
			  0, 0, 0, 0, 0x09};
	uint8_t out[8];
	double w[6] = {1.5, -0.25, 7.0, 0, 0, 0};
	PX_CHECK(sm && hp);
	PX_CHECK(px_codec_builtin("nope") == NULL);
	PX_CHECK_INT_EQ(px_codec_check(sm, NULL), PX_OK);
	PX_CHECK_INT_EQ(px_codec_check(hp, NULL), PX_OK);
	PX_CHECK_INT_EQ(px_codec_numbered(sm), 1);
	memset(&v, 0, sizeof v);
	PX_CHECK_INT_EQ(px_codec_decode(sm, r2, 7, &v, NULL), 3);
	PX_CHECK_NEAR(v.axis[PX_AXIS_RX], -0.35, 1e-12);
	PX_CHECK_NEAR(v.axis[PX_AXIS_RY], 0.0, 0);
	PX_CHECK_NEAR(v.axis[PX_AXIS_RZ], 0.35, 1e-12);
	PX_CHECK_INT_EQ(v.axis_mask, 0x38u);
	PX_CHECK_INT_EQ(px_codec_decode(sm, r3, 2, &v, NULL), 1);
	PX_CHECK_INT_EQ(v.buttons, 2u);
	PX_CHECK_INT_EQ(v.button_mask, 3u);
	/* haptic: 1 000 000 um = 1 m, -1 000 000 um, buttons 0b1001 */
	PX_CHECK_INT_EQ(px_codec_decode(hp, h1, 14, &v, NULL), 4);
	PX_CHECK_NEAR(v.axis[PX_AXIS_X], 1.0, 1e-12);
	PX_CHECK_NEAR(v.axis[PX_AXIS_Y], -1.0, 1e-12);
	PX_CHECK_INT_EQ(v.buttons, 9u);
	PX_CHECK_INT_EQ(px_codec_encode(hp, w, out, sizeof out, NULL, NULL), 7);
	PX_CHECK_INT_EQ(out[0], 2);
	PX_CHECK_INT_EQ(out[1] | (out[2] << 8), 1500);
	PX_CHECK_INT_EQ((int16_t)(out[3] | (out[4] << 8)), -250);
	PX_CHECK_INT_EQ(out[5] | (out[6] << 8), 3000); /* clamped to 3 N */
}

static void test_codec_allocates_nothing(void)
{
	const struct px_codec_map *hp = px_codec_builtin("haptic");
	uint8_t b[16];
	double a[6] = {0.01, 0.02, 0.03, 0, 0, 0}, w[6] = {1, 2, 3, 0, 0, 0};
	struct px_codec_values v;
	struct px_codec_diag d;
	uint64_t r;
	int i;
	memset(&v, 0, sizeof v);
	r = px_alloc_region_begin();
	for (i = 0; i < 1000; i++) {
		int n = px_codec_encode_input(hp, 1, a, 5, b, sizeof b);
		px_codec_decode(hp, b, (size_t)n, &v, &d);
		px_codec_encode(hp, w, b, sizeof b, NULL, &d);
		px_codec_decode(hp, b, 3, &v, &d);
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(r), 0);
	PX_CHECK_NEAR(v.axis[PX_AXIS_Z], 0.03, 1e-12);
}

static const struct px_test tests[] = {
	PX_T(test_raw_bits_match_reference),
	PX_T(test_sign_extension_edges),
	PX_T(test_random_input_and_output_roundtrip),
	PX_T(test_clamping),
	PX_T(test_bad_reports_give_clear_errors),
	PX_T(test_map_check_names_the_entry),
	PX_T(test_builtin_maps),
	PX_T(test_codec_allocates_nothing),
};

PX_TEST_MAIN(tests)
