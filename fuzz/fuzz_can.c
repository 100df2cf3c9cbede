/*
 * libFuzzer target: the CAN signal codec and error-frame decoding
 * (devices/px_can.h). Signals come from the input (DBC start bit,
 * length, byte order, sign, scale, limits), then frames to decode and
 * values to encode.
 * Invariants: a signal passing px_can_signal_check() never makes the
 * codec touch bytes beyond px_can_signal_bytes(); raw bits written by
 * px_can_signal_put_raw() read back equal (sign-extended as the signal
 * says) and leave every other bit of the frame as it was; decoded values
 * are finite and inside [min, max]; encoding a decoded value gives the
 * same raw bits back (scale steps are exact for the raw values that fit
 * a double's mantissa); error frames decode into a state and a
 * description that fits the buffer.
 */
#include "fuzz_util.h"

#include "px_can.h"

static void check_signal(const struct px_can_signal *s, size_t frame_len,
			 struct fz *f)
{
	uint8_t *data, before[64];
	size_t nb = px_can_signal_bytes(s), i;
	int64_t raw, back;
	uint64_t put;
	double v;
	int rc, cl;

	if (nb == 0 || nb > frame_len || frame_len > 64)
		abort();
	/* exact-size heap frame: one byte too far is caught */
	data = malloc(nb);
	if (!data)
		abort();
	for (i = 0; i < nb; i++)
		data[i] = (uint8_t)fz_u8(f);
	memcpy(before, data, nb);

	if (px_can_signal_get_raw(s, data, nb, &raw) != PX_OK)
		abort();
	if (nb > 0 && px_can_signal_get_raw(s, data, nb - 1, &back) != PX_E_PARSE)
		abort();
	rc = px_can_signal_decode(s, data, nb, &v);
	if (rc == PX_OK) {
		if (!isfinite(v) || (s->has_min && v < s->min) ||
		    (s->has_max && v > s->max))
			abort();
		/* re-encode: same raw bits when the raw value is exact */
		if (s->length <= 52 && fabs(s->scale) >= 1e-300 &&
		    fabs(v) < 1e15 && fabs(s->offset) < 1e15 &&
		    fabs(s->scale) < 1e15 && s->offset == 0.0 &&
		    (fabs(s->scale) == 1.0 || fabs(s->scale) == 0.5 ||
		     fabs(s->scale) == 0.25)) {
			uint8_t *d2 = malloc(nb);
			int64_t raw2;
			if (!d2)
				abort();
			memcpy(d2, data, nb);
			if (px_can_signal_encode(s, v, d2, nb, &cl) != PX_OK ||
			    px_can_signal_get_raw(s, d2, nb, &raw2) != PX_OK ||
			    raw2 != raw || cl)
				abort();
			free(d2);
		}
	} else if (rc != PX_E_RANGE) {
		abort();
	}

	/* raw round trip; other bits untouched */
	put = fz_bits(f, 8);
	if (px_can_signal_put_raw(s, data, nb, put) != PX_OK)
		abort();
	if (px_can_signal_get_raw(s, data, nb, &back) != PX_OK)
		abort();
	{
		uint64_t mask = s->length == 64 ? ~(uint64_t)0
						: (((uint64_t)1 << s->length) - 1u);
		uint64_t want = put & mask;
		if (s->is_signed && s->length < 64 && ((want >> (s->length - 1)) & 1u))
			want |= ~mask;
		if ((uint64_t)back != want)
			abort();
		/* Put the original bits back: the frame must be as before. */
		if (px_can_signal_put_raw(s, data, nb, (uint64_t)raw) != PX_OK ||
		    memcmp(before, data, nb) != 0)
			abort();
	}

	/* encode any value */
	v = fz_double(f);
	rc = px_can_signal_encode(s, v, data, nb, &cl);
	if (!isfinite(v) ? rc != PX_E_NAN : rc != PX_OK)
		abort();
	if (rc == PX_OK) {
		double d;
		rc = px_can_signal_decode(s, data, nb, &d);
		if (rc == PX_OK && !isfinite(d))
			abort();
	}
	free(data);
}

static void check_err_frame(struct fz *f)
{
	struct canfd_frame fr;
	struct px_can_err_info e;
	char small[8], buf[256];
	size_t i;
	int rc, n;
	memset(&fr, 0, sizeof fr);
	fr.can_id = fz_u32(f);
	if (fz_u8(f) & 1u)
		fr.can_id |= CAN_ERR_FLAG;
	fr.len = (uint8_t)fz_u8(f);
	for (i = 0; i < sizeof fr.data; i++)
		fr.data[i] = (uint8_t)fz_u8(f);
	rc = px_can_err_decode(&fr, &e);
	if (!(fr.can_id & CAN_ERR_FLAG)) {
		if (rc != PX_E_INVAL)
			abort();
		return;
	}
	if (rc != PX_OK)
		return;
	if (e.state < PX_CAN_STATE_ACTIVE || e.state > PX_CAN_STATE_UNKNOWN ||
	    !px_can_state_name(e.state))
		abort();
	n = px_can_err_describe(&e, buf, sizeof buf);
	if (n < 0 || !memchr(buf, '\0', sizeof buf))
		abort();
	px_can_err_describe(&e, small, sizeof small);
	if (!memchr(small, '\0', sizeof small))
		abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct fz f = {data, size};
	int rounds = 0;
	while (f.n && rounds++ < 32) {
		unsigned what = fz_u8(&f);
		if (what < 32) {
			check_err_frame(&f);
		} else {
			struct px_can_signal s;
			size_t frame_len;
			memset(&s, 0, sizeof s);
			s.name = "fz";
			s.id = fz_u32(&f) & (what & 1 ? 0x7ffu : 0x3fffffffu);
			s.extended = (int)(what >> 1) & 1;
			s.start_bit = (uint16_t)fz_u16(&f);
			if (!(what & 4))
				s.start_bit %= 64;
			s.length = (uint8_t)fz_u8(&f);
			if (!(what & 8))
				s.length = (uint8_t)(s.length % 65u);
			s.byte_order = (uint8_t)(fz_u8(&f) % 3u);
			s.is_signed = (int)(fz_u8(&f) & 1u);
			s.scale = fz_double(&f);
			s.offset = fz_double(&f);
			s.has_min = (int)(what >> 4) & 1;
			s.has_max = (int)(what >> 5) & 1;
			s.min = fz_double(&f);
			s.max = fz_double(&f);
			frame_len = what & 64 ? 64 : 8;
			if (px_can_signal_check(&s, frame_len) == PX_OK)
				check_signal(&s, frame_len, &f);
		}
	}
	return 0;
}
