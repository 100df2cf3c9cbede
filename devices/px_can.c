/* CAN signal codec (DBC bit numbering), error frames, candump logs, and
 * the CAN pose/force device. */
#include <ctype.h>
#include <errno.h>
#include <inttypes.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <linux/can/error.h>

#include "px_can.h"

/* ---- signal codec ------------------------------------------------------- */

/* Bit position (DBC numbering) of the k-th most significant bit. */
static unsigned moto_next(unsigned p)
{
	return p % 8 == 0 ? p + 15 : p - 1;
}

/* Highest byte index the signal touches + 1; 0 on a bad signal. */
size_t px_can_signal_bytes(const struct px_can_signal *s)
{
	unsigned p, k, maxb = 0;
	if (!s || s->length < 1 || s->length > 64)
		return 0;
	if (s->byte_order == PX_LITTLE_ENDIAN)
		return ((size_t)s->start_bit + s->length - 1) / 8 + 1;
	p = s->start_bit;
	for (k = 0; k < s->length; k++) {
		if (p / 8 > maxb)
			maxb = p / 8;
		if (k + 1 < s->length)
			p = moto_next(p);
	}
	return (size_t)maxb + 1;
}

int px_can_signal_check(const struct px_can_signal *s, size_t frame_len)
{
	if (!s || s->length < 1 || s->length > 64 ||
	    (s->byte_order != PX_LITTLE_ENDIAN &&
	     s->byte_order != PX_BIG_ENDIAN) ||
	    !isfinite(s->scale) || s->scale == 0.0 || !isfinite(s->offset) ||
	    s->start_bit >= 512)
		return PX_E_INVAL;
	if (s->id > (s->extended ? CAN_EFF_MASK : CAN_SFF_MASK))
		return PX_E_INVAL;
	if ((s->has_min && !isfinite(s->min)) ||
	    (s->has_max && !isfinite(s->max)) ||
	    (s->has_min && s->has_max && s->min > s->max))
		return PX_E_INVAL;
	if (px_can_signal_bytes(s) > frame_len)
		return PX_E_INVAL;
	if (s->is_float && s->length != 32 && s->length != 64)
		return PX_E_INVAL;
	return PX_OK;
}

int px_can_signal_get_raw(const struct px_can_signal *s, const uint8_t *data,
			  size_t len, int64_t *raw)
{
	uint64_t u = 0;
	unsigned k, p;
	if (!s || !data || !raw || s->length < 1 || s->length > 64)
		return PX_E_INVAL;
	if (px_can_signal_bytes(s) > len)
		return PX_E_PARSE;
	if (s->byte_order == PX_LITTLE_ENDIAN) {
		for (k = 0; k < s->length; k++) {
			p = s->start_bit + k;
			u |= (uint64_t)((data[p / 8] >> (p % 8)) & 1u) << k;
		}
	} else {
		p = s->start_bit;
		for (k = 0; k < s->length; k++) {
			u = (u << 1) | ((data[p / 8] >> (p % 8)) & 1u);
			p = moto_next(p);
		}
	}
	if (s->is_signed && s->length < 64 && ((u >> (s->length - 1)) & 1u))
		u |= ~(((uint64_t)1 << s->length) - 1u);
	*raw = (int64_t)u;
	return PX_OK;
}

int px_can_signal_put_raw(const struct px_can_signal *s, uint8_t *data,
			  size_t len, uint64_t raw)
{
	unsigned k, p;
	if (!s || !data || s->length < 1 || s->length > 64)
		return PX_E_INVAL;
	if (px_can_signal_bytes(s) > len)
		return PX_E_PARSE;
	if (s->byte_order == PX_LITTLE_ENDIAN) {
		for (k = 0; k < s->length; k++) {
			p = s->start_bit + k;
			if ((raw >> k) & 1u)
				data[p / 8] |= (uint8_t)(1u << (p % 8));
			else
				data[p / 8] &= (uint8_t)~(1u << (p % 8));
		}
	} else {
		p = s->start_bit;
		for (k = 0; k < s->length; k++) {
			unsigned bit = s->length - 1 - k; /* MSB first */
			if ((raw >> bit) & 1u)
				data[p / 8] |= (uint8_t)(1u << (p % 8));
			else
				data[p / 8] &= (uint8_t)~(1u << (p % 8));
			p = moto_next(p);
		}
	}
	return PX_OK;
}

int px_can_signal_decode(const struct px_can_signal *s, const uint8_t *data,
			 size_t len, double *value)
{
	int64_t raw;
	double v;
	int rc;
	if (!value)
		return PX_E_INVAL;
	rc = px_can_signal_get_raw(s, data, len, &raw);
	if (rc != PX_OK)
		return rc;
	if (s->is_float) {
		double x;
		if (s->length == 32) {
			uint32_t b = (uint32_t)(uint64_t)raw;
			float fl;
			memcpy(&fl, &b, sizeof fl);
			x = fl;
		} else if (s->length == 64) {
			uint64_t b = (uint64_t)raw;
			memcpy(&x, &b, sizeof x);
		} else {
			return PX_E_INVAL;
		}
		if (!isfinite(x))
			return PX_E_NAN;
		v = x * s->scale + s->offset;
	} else {
		v = (s->is_signed ? (double)raw : (double)(uint64_t)raw) *
			    s->scale +
		    s->offset;
	}
	if ((s->has_min && v < s->min) || (s->has_max && v > s->max) ||
	    !isfinite(v))
		return PX_E_RANGE;
	*value = v;
	return PX_OK;
}

int px_can_signal_encode(const struct px_can_signal *s, double value,
			 uint8_t *data, size_t len, int *clamped)
{
	double r;
	uint64_t raw;
	int cl = 0;
	unsigned w;
	if (!s || !data || s->length < 1 || s->length > 64)
		return PX_E_INVAL;
	if (!isfinite(value))
		return PX_E_NAN;
	if (px_can_signal_bytes(s) > len)
		return PX_E_PARSE;
	if (s->has_min && value < s->min) {
		value = s->min;
		cl = 1;
	}
	if (s->has_max && value > s->max) {
		value = s->max;
		cl = 1;
	}
	w = s->length;
	if (s->is_float) {
		double x = (value - s->offset) / s->scale;
		if (w == 32) {
			float fl;
			uint32_t b;
			if (x > FLT_MAX || x < -FLT_MAX) {
				x = x > 0 ? FLT_MAX : -FLT_MAX;
				cl = 1;
			}
			fl = (float)x;
			memcpy(&b, &fl, sizeof b);
			raw = b;
		} else if (w == 64) {
			memcpy(&raw, &x, sizeof raw);
		} else {
			return PX_E_INVAL;
		}
		if (clamped)
			*clamped = cl;
		return px_can_signal_put_raw(s, data, len, raw);
	}
	r = round((value - s->offset) / s->scale);
	if (s->is_signed) {
		double hi = ldexp(1.0, (int)w - 1);
		if (r >= hi) {
			raw = w >= 64 ? (uint64_t)INT64_MAX
				      : ((uint64_t)1 << (w - 1)) - 1u;
			cl = 1;
		} else if (r < -hi) {
			raw = (uint64_t)1 << (w - 1);
			cl = 1;
		} else {
			raw = (uint64_t)(int64_t)r;
		}
	} else {
		double hi = ldexp(1.0, (int)w);
		if (r >= hi) {
			raw = w >= 64 ? UINT64_MAX : ((uint64_t)1 << w) - 1u;
			cl = 1;
		} else if (r < 0) {
			raw = 0;
			cl = 1;
		} else {
			raw = (uint64_t)r;
		}
	}
	if (clamped)
		*clamped = cl;
	return px_can_signal_put_raw(s, data, len, raw);
}

/* ---- error frames -------------------------------------------------------- */

int px_can_err_decode(const struct canfd_frame *f, struct px_can_err_info *e)
{
	uint32_t c;
	if (!f || !e || !(f->can_id & CAN_ERR_FLAG))
		return PX_E_INVAL;
	memset(e, 0, sizeof *e);
	c = f->can_id & CAN_ERR_MASK;
	e->state = PX_CAN_STATE_ACTIVE;
	e->tx_timeout = !!(c & CAN_ERR_TX_TIMEOUT);
	e->lost_arbitration = !!(c & CAN_ERR_LOSTARB);
	e->protocol = !!(c & CAN_ERR_PROT);
	e->transceiver = !!(c & CAN_ERR_TRX);
	e->no_ack = !!(c & CAN_ERR_ACK);
	e->bus_off = !!(c & CAN_ERR_BUSOFF);
	e->bus_error = !!(c & CAN_ERR_BUSERROR);
	e->restarted = !!(c & CAN_ERR_RESTARTED);
	if (c & CAN_ERR_CRTL) {
		uint8_t d1 = f->data[1];
		e->rx_overflow = !!(d1 & CAN_ERR_CRTL_RX_OVERFLOW);
		e->tx_overflow = !!(d1 & CAN_ERR_CRTL_TX_OVERFLOW);
		e->error_warning = !!(d1 & (CAN_ERR_CRTL_RX_WARNING |
					    CAN_ERR_CRTL_TX_WARNING));
		e->error_passive = !!(d1 & (CAN_ERR_CRTL_RX_PASSIVE |
					    CAN_ERR_CRTL_TX_PASSIVE));
		e->back_to_active = !!(d1 & CAN_ERR_CRTL_ACTIVE);
	}
	if (c & CAN_ERR_CNT) {
		e->tx_errors = f->data[6];
		e->rx_errors = f->data[7];
	}
	if (e->bus_off)
		e->state = PX_CAN_STATE_BUS_OFF;
	else if (e->error_passive)
		e->state = PX_CAN_STATE_PASSIVE;
	else if (e->error_warning)
		e->state = PX_CAN_STATE_WARNING;
	else if (e->restarted || e->back_to_active)
		e->state = PX_CAN_STATE_ACTIVE;
	else
		e->state = PX_CAN_STATE_UNKNOWN; /* no state change said */
	return PX_OK;
}

int px_can_err_describe(const struct px_can_err_info *e, char *buf,
			size_t cap)
{
	static const struct {
		size_t off;
		const char *what;
	} items[] = {
		{offsetof(struct px_can_err_info, bus_off), "bus-off"},
		{offsetof(struct px_can_err_info, restarted), "controller restarted"},
		{offsetof(struct px_can_err_info, error_passive), "error passive"},
		{offsetof(struct px_can_err_info, error_warning), "error warning"},
		{offsetof(struct px_can_err_info, back_to_active), "back to error active"},
		{offsetof(struct px_can_err_info, rx_overflow), "controller RX overflow"},
		{offsetof(struct px_can_err_info, tx_overflow), "controller TX overflow"},
		{offsetof(struct px_can_err_info, lost_arbitration), "lost arbitration"},
		{offsetof(struct px_can_err_info, protocol), "protocol violation"},
		{offsetof(struct px_can_err_info, transceiver), "transceiver problem"},
		{offsetof(struct px_can_err_info, no_ack), "no ACK"},
		{offsetof(struct px_can_err_info, bus_error), "bus error"},
		{offsetof(struct px_can_err_info, tx_timeout), "TX timeout"},
	};
	size_t i, n = 0;
	int first = 1;
	if (!e || !buf || !cap)
		return PX_E_INVAL;
	buf[0] = 0;
	for (i = 0; i < sizeof items / sizeof items[0]; i++) {
		const int *flag = (const int *)((const char *)e + items[i].off);
		int w;
		if (!*flag)
			continue;
		w = snprintf(buf + n, cap - n, "%s%s", first ? "" : ", ",
			     items[i].what);
		if (w < 0 || (size_t)w >= cap - n)
			return PX_E_NOSPC;
		n += (size_t)w;
		first = 0;
	}
	if (first) {
		if (snprintf(buf, cap, "unspecified error") >= (int)cap)
			return PX_E_NOSPC;
		n = strlen(buf);
	}
	return (int)n;
}

const char *px_can_state_name(int state)
{
	static const char *const n[] = {"error-active", "error-warning",
					"error-passive", "bus-off", "stopped",
					"unknown"};
	if (state < 0 || state > PX_CAN_STATE_UNKNOWN)
		return "unknown";
	return n[state];
}

/* ---- candump logs ------------------------------------------------------- */

static const char hexd[] = "0123456789ABCDEF";

int px_can_log_format(const struct px_can_msg *m, int64_t t_ns,
		      const char *iface, char *buf, size_t cap)
{
	char frame[200];
	size_t n = 0, i;
	uint32_t id;
	int w;
	if (!m || !buf)
		return PX_E_INVAL;
	id = m->f.can_id;
	if (id & CAN_ERR_FLAG)
		n += (size_t)snprintf(frame, sizeof frame, "%08" PRIX32,
				      id & (CAN_ERR_MASK | CAN_ERR_FLAG));
	else if (id & CAN_EFF_FLAG)
		n += (size_t)snprintf(frame, sizeof frame, "%08" PRIX32,
				      id & CAN_EFF_MASK);
	else
		n += (size_t)snprintf(frame, sizeof frame, "%03" PRIX32,
				      id & CAN_SFF_MASK);
	frame[n++] = '#';
	if (m->fd) {
		if (m->f.len > CANFD_MAX_DLEN)
			return PX_E_INVAL;
		frame[n++] = '#';
		frame[n++] = hexd[m->f.flags & 0xF];
	} else if (id & CAN_RTR_FLAG) {
		frame[n++] = 'R';
		if (m->f.len)
			frame[n++] = hexd[m->f.len & 0xF];
		frame[n] = 0;
		goto out;
	} else if (m->f.len > CAN_MAX_DLEN) {
		return PX_E_INVAL;
	}
	for (i = 0; i < m->f.len; i++) {
		frame[n++] = hexd[m->f.data[i] >> 4];
		frame[n++] = hexd[m->f.data[i] & 0xF];
	}
	frame[n] = 0;
out:
	w = snprintf(buf, cap, "(%" PRId64 ".%06" PRId64 ") %s %s",
		     t_ns / 1000000000, (t_ns % 1000000000) / 1000,
		     iface ? iface : "can0", frame);
	if (w < 0 || (size_t)w >= cap)
		return PX_E_NOSPC;
	return w;
}

static int hexval(int c)
{
	if (c >= '0' && c <= '9')
		return c - '0';
	c = toupper(c);
	if (c >= 'A' && c <= 'F')
		return c - 'A' + 10;
	return -1;
}

int px_can_log_parse(const char *line, struct px_can_msg *m, int64_t *t_ns,
		     char *iface, size_t icap)
{
	const char *p = line, *q;
	int64_t sec = 0, usec = 0;
	int digits = 0, idlen = 0, fracdigits = 0;
	uint32_t id = 0;
	size_t n;
	if (!line || !m)
		return PX_E_INVAL;
	memset(m, 0, sizeof *m);
	while (*p == ' ' || *p == '\t')
		p++;
	if (*p++ != '(')
		return PX_E_PARSE;
	while (isdigit((unsigned char)*p) && digits < 18) {
		sec = sec * 10 + (*p++ - '0');
		digits++;
	}
	/* The time in ns must fit int64_t (seconds up to 9223372035, year
	 * 2262): a larger value overflowed sec * 1e9 (found by fuzzing). */
	if (!digits || *p++ != '.' || sec > INT64_MAX / 1000000000 - 1)
		return PX_E_PARSE;
	while (isdigit((unsigned char)*p)) {
		if (fracdigits < 6) {
			usec = usec * 10 + (*p - '0');
			fracdigits++;
		}
		p++;
	}
	if (!fracdigits || *p++ != ')')
		return PX_E_PARSE;
	while (fracdigits++ < 6)
		usec *= 10;
	if (*p != ' ')
		return PX_E_PARSE;
	while (*p == ' ')
		p++;
	q = p;
	while (*p && *p != ' ')
		p++;
	if (p == q || *p != ' ')
		return PX_E_PARSE;
	if (iface && icap) {
		n = (size_t)(p - q) < icap - 1 ? (size_t)(p - q) : icap - 1;
		memcpy(iface, q, n);
		iface[n] = 0;
	}
	while (*p == ' ')
		p++;
	while (hexval(*p) >= 0 && idlen < 8) {
		id = (id << 4) | (uint32_t)hexval(*p++);
		idlen++;
	}
	if ((idlen != 3 && idlen != 8) || *p++ != '#')
		return PX_E_PARSE;
	if (idlen == 8) {
		/* An error frame's id is the error flag and class bits only:
		 * bits 30/31 would smuggle in the RTR and EFF flags, which the
		 * formatter does not write back (found by fuzzing). */
		if ((id & CAN_ERR_FLAG) && (id & ~(CAN_ERR_FLAG | CAN_ERR_MASK)))
			return PX_E_PARSE;
		if (id & CAN_ERR_FLAG)
			m->f.can_id = id;
		else if (id <= CAN_EFF_MASK)
			m->f.can_id = id | CAN_EFF_FLAG;
		else
			return PX_E_PARSE;
	} else {
		if (id > CAN_SFF_MASK)
			return PX_E_PARSE;
		m->f.can_id = id;
	}
	if (*p == '#') {
		int fl;
		p++;
		fl = hexval(*p++);
		if (fl < 0)
			return PX_E_PARSE;
		m->fd = 1;
		m->f.flags = (uint8_t)fl;
	} else if (*p == 'R' || *p == 'r') {
		p++;
		m->f.can_id |= CAN_RTR_FLAG;
		if (hexval(*p) >= 0) {
			m->f.len = (uint8_t)hexval(*p++);
			if (m->f.len > CAN_MAX_DLEN)
				return PX_E_PARSE;
		}
		goto tail;
	}
	n = 0;
	while (hexval(p[0]) >= 0) {
		if (hexval(p[1]) < 0)
			return PX_E_PARSE;
		if (n >= (m->fd ? CANFD_MAX_DLEN : CAN_MAX_DLEN))
			return PX_E_PARSE;
		m->f.data[n++] = (uint8_t)(hexval(p[0]) << 4 | hexval(p[1]));
		p += 2;
	}
	m->f.len = (uint8_t)n;
	if (m->fd && n > 8 && n != 12 && n != 16 && n != 20 && n != 24 &&
	    n != 32 && n != 48 && n != 64)
		return PX_E_PARSE; /* not a CAN FD length */
tail:
	while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n')
		p++;
	/* candump -l may append " T" / " R" direction marks in newer
	 * versions; accept a single trailing letter. */
	if (*p && !(isalpha((unsigned char)p[0]) &&
		    (p[1] == 0 || p[1] == '\n' || p[1] == '\r')))
		return PX_E_PARSE;
	if (t_ns)
		*t_ns = sec * 1000000000 + usec * 1000;
	return PX_OK;
}
