/* A pose source / force sink made of CAN signals on any px_can_bus. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <linux/can/error.h>

#include "px_can.h"
#include "dev_internal.h"

#define MAX_SIG 64
#define MAX_OUT_IDS 8
#define MAX_RX_PER_POLL 256
#define MAX_IN_IDS 16

struct cdev {
	struct px_can_bus *bus;
	int fd;
	const struct px_can_signal *sig;
	size_t n;
	double val[MAX_SIG];
	int64_t t[MAX_SIG];
	int have[MAX_SIG];
	uint32_t out_id[MAX_OUT_IDS];  /* with CAN_EFF_FLAG */
	uint8_t out_len[MAX_OUT_IDS];
	size_t n_out;
	/* duplicate check: last frame per input id */
	uint32_t in_id[MAX_IN_IDS];
	struct canfd_frame in_last[MAX_IN_IDS];
	int64_t in_t[MAX_IN_IDS];
	int in_have[MAX_IN_IDS];
	size_t n_in;
};

static uint32_t wire_id(const struct px_can_signal *s)
{
	return s->extended ? (s->id | CAN_EFF_FLAG) : s->id;
}

static const char *err_what(const struct px_can_err_info *e)
{
	if (e->bus_off)
		return "bus-off";
	if (e->error_passive)
		return "error passive (controller)";
	if (e->error_warning)
		return "error warning (controller)";
	if (e->restarted)
		return "controller restarted";
	if (e->rx_overflow || e->tx_overflow)
		return "controller buffer overflow";
	if (e->no_ack)
		return "no ACK";
	if (e->protocol)
		return "protocol violation";
	if (e->transceiver)
		return "transceiver problem";
	if (e->lost_arbitration)
		return "lost arbitration";
	if (e->tx_timeout)
		return "TX timeout";
	return "bus error";
}

/* The same frame (id, length, bytes) again sooner than the device's
 * min_report_interval_ns: a duplicate (a retransmission or a gateway
 * forwarding twice), dropped so it does not count as a fresh sample. */
static int is_duplicate(struct px_dev *d, struct cdev *c,
			const struct px_can_msg *m)
{
	int64_t min_ns = px_dev_config(d)->min_report_interval_ns;
	uint32_t id = m->f.can_id & (CAN_EFF_FLAG | CAN_EFF_MASK);
	size_t k;
	for (k = 0; k < c->n_in && c->in_id[k] != id; k++)
		;
	if (k == c->n_in)
		return 0; /* not an input frame */
	if (min_ns > 0 && c->in_have[k] && m->f.len == c->in_last[k].len &&
	    m->t_ns - c->in_t[k] < min_ns &&
	    !memcmp(m->f.data, c->in_last[k].data, m->f.len)) {
		px_dev_record(d, PX_DEV_ERR_DUPLICATE, PX_E_CORRUPT, 0,
			      (int64_t)(id & CAN_EFF_MASK), NULL, NULL,
			      m->t_ns);
		return 1;
	}
	c->in_last[k] = m->f;
	c->in_t[k] = m->t_ns;
	c->in_have[k] = 1;
	return 0;
}

static void handle(struct px_dev *d, struct cdev *c, const struct px_can_msg *m)
{
	double axis[PX_AXIS__COUNT] = {0};
	uint32_t mask = 0;
	size_t i;
	uint32_t id = m->f.can_id & (CAN_EFF_FLAG | CAN_EFF_MASK);
	if (m->f.can_id & CAN_ERR_FLAG) {
		struct px_can_err_info e;
		px_can_err_decode(&m->f, &e);
		px_dev_record(d, PX_DEV_ERR_BUS, e.bus_off ? PX_E_NODEV : PX_E_IO,
			      0, (int64_t)(m->f.can_id & CAN_ERR_MASK), NULL,
			      err_what(&e), m->t_ns);
		if (e.bus_off)
			px_dev_set_state(d, PX_DEV_STATE_FAILED, m->t_ns);
		else if ((e.restarted || e.back_to_active) &&
			 px_dev_state(d) == PX_DEV_STATE_FAILED)
			px_dev_set_state(d, PX_DEV_STATE_RUNNING, m->t_ns);
		return;
	}
	if (m->f.can_id & CAN_RTR_FLAG)
		return;
	if (is_duplicate(d, c, m))
		return;
	for (i = 0; i < c->n; i++) {
		const struct px_can_signal *s = &c->sig[i];
		double v;
		int rc;
		if (s->output || wire_id(s) != id)
			continue;
		rc = px_can_signal_decode(s, m->f.data, m->f.len, &v);
		if (rc != PX_OK) {
			/* the signal's name says where; frame id in the record */
			px_dev_record(d, rc == PX_E_NAN ? PX_DEV_ERR_NONFINITE
							: PX_DEV_ERR_DECODE,
				      rc, 0, (int64_t)s->id, NULL, s->name,
				      m->t_ns);
			return; /* a bad frame feeds nothing */
		}
		c->val[i] = v;
		c->t[i] = m->t_ns;
		c->have[i] = 1;
		if (s->axis >= 0 && s->axis < PX_AXIS__COUNT) {
			axis[s->axis] = v;
			mask |= 1u << s->axis;
		}
	}
	if (mask)
		px_dev_feed_axes(d, axis, mask, 0, 0, m->t_ns);
}

static int cdev_poll(struct px_dev *d, int64_t now)
{
	struct cdev *c = px_dev_impl(d);
	struct px_can_msg m;
	int k, rc = PX_OK;
	for (k = 0; k < MAX_RX_PER_POLL; k++) {
		rc = px_can_bus_recv(c->bus, now, &m);
		if (rc == PX_E_AGAIN) {
			rc = PX_OK;
			break;
		}
		if (rc == PX_E_NODEV) {
			/* the adapter (or its simulation) is gone: stale and
			 * safe until it answers again */
			if (px_dev_state(d) != PX_DEV_STATE_UNPLUGGED)
				px_dev_set_state(d, PX_DEV_STATE_UNPLUGGED, now);
			return rc;
		}
		if (rc != PX_OK) {
			px_dev_record(d, PX_DEV_ERR_IO, rc,
				      px_can_bus_errno(c->bus), -1, NULL,
				      "CAN receive failed", now);
			break;
		}
		if (px_dev_state(d) == PX_DEV_STATE_UNPLUGGED)
			px_dev_set_state(d, PX_DEV_STATE_RUNNING, m.t_ns);
		handle(d, c, &m);
	}
	if (rc == PX_OK && px_dev_state(d) == PX_DEV_STATE_UNPLUGGED)
		px_dev_set_state(d, PX_DEV_STATE_RUNNING, now);
	return rc;
}

static int cdev_force(struct px_dev *d, const struct px_force_cmd *cmd,
		      int64_t now)
{
	struct cdev *c = px_dev_impl(d);
	double w[PX_WRENCH__COUNT];
	size_t j, i;
	int k, rc = PX_OK;
	if (!c->n_out)
		return PX_E_UNSUPPORTED;
	px__dev_force_wrench(cmd, w);
	for (j = 0; j < c->n_out; j++) {
		struct px_can_msg m;
		memset(&m, 0, sizeof m);
		m.f.can_id = c->out_id[j];
		m.f.len = c->out_len[j];
		m.fd = c->fd;
		for (i = 0; i < c->n; i++) {
			const struct px_can_signal *s = &c->sig[i];
			if (!s->output || wire_id(s) != c->out_id[j] ||
			    s->axis < 0 || s->axis >= PX_WRENCH__COUNT)
				continue;
			px_can_signal_encode(s, w[s->axis], m.f.data, m.f.len,
					     NULL);
		}
		k = px_can_bus_send(c->bus, &m, now);
		if (k != PX_OK) {
			px_dev_record(d, PX_DEV_ERR_IO, k,
				      px_can_bus_errno(c->bus),
				      (int64_t)(c->out_id[j] & CAN_EFF_MASK),
				      NULL, "CAN send failed", now);
			rc = k;
		}
	}
	return rc;
}

static void cdev_destroy(struct px_dev *d)
{
	struct cdev *c = px_dev_impl(d);
	px_can_bus_close(c->bus);
	c->bus = NULL;
}

static const struct px_dev_ops cdev_ops = {
	.backend = "socketcan",
	.caps = PX_DEV_CAP_POSE | PX_DEV_CAP_FORCE,
	.poll = cdev_poll,
	.force = cdev_force,
	.destroy = cdev_destroy,
};

static uint8_t fd_len(size_t n)
{
	static const uint8_t lens[] = {12, 16, 20, 24, 32, 48, 64};
	size_t i;
	if (n <= 8)
		return (uint8_t)n;
	for (i = 0; i < sizeof lens; i++)
		if (n <= lens[i])
			return lens[i];
	return 64;
}

int px_can_dev_create(const struct px_dev_config *dcfg, struct px_can_bus *bus,
		      int fd_frames, const struct px_can_signal *signals,
		      size_t n_signals, struct px_dev **out, char *msg,
		      size_t cap)
{
	struct px_dev_config dc;
	struct cdev *c;
	size_t i, j, flen = fd_frames ? CANFD_MAX_DLEN : CAN_MAX_DLEN;
	uint32_t ids[MAX_OUT_IDS];
	uint8_t lens[MAX_OUT_IDS];
	size_t n_out = 0;
	const char *nm;
	int rc;
	if (msg && cap)
		msg[0] = 0;
	if (out)
		*out = NULL;
	if (!dcfg || !bus || !out || n_signals > MAX_SIG ||
	    (n_signals && !signals)) {
		if (msg)
			snprintf(msg, cap, "CAN device: bus and at most %d "
				 "signals", MAX_SIG);
		return PX_E_INVAL;
	}
	nm = dcfg->name ? dcfg->name : "can";
	for (i = 0; i < n_signals; i++) {
		const struct px_can_signal *s = &signals[i];
		if (px_can_signal_check(s, flen) != PX_OK ||
		    (!s->output && s->axis >= PX_AXIS__COUNT) ||
		    (s->output && s->axis >= PX_WRENCH__COUNT)) {
			if (msg)
				snprintf(msg, cap,
					 "%s: signals[%zu] (%s, id 0x%x): start "
					 "bit %u + length %u must fit a %zu-byte "
					 "frame, scale finite and non-zero, min "
					 "<= max, axis in range", nm, i,
					 s->name ? s->name : "?", s->id,
					 s->start_bit, s->length, flen);
			return PX_E_INVAL;
		}
		if (s->output && s->axis >= 0) {
			uint32_t w = wire_id(s);
			size_t nb = px_can_signal_bytes(s);
			for (j = 0; j < n_out && ids[j] != w; j++)
				;
			if (j == n_out) {
				if (n_out == MAX_OUT_IDS) {
					if (msg)
						snprintf(msg, cap, "%s: more than "
							 "%d output frame ids",
							 nm, MAX_OUT_IDS);
					return PX_E_INVAL;
				}
				ids[n_out] = w;
				lens[n_out++] = 0;
			}
			if (nb > lens[j])
				lens[j] = (uint8_t)nb;
		}
	}
	dc = *dcfg;
	dc.codec = NULL;
	rc = px_dev_create(&cdev_ops, &dc, sizeof *c, out);
	if (rc != PX_OK)
		return rc;
	c = px_dev_impl(*out);
	c->bus = bus;
	c->fd = fd_frames;
	c->sig = signals;
	c->n = n_signals;
	for (i = 0; i < n_signals; i++) {
		uint32_t w = wire_id(&signals[i]);
		if (signals[i].output)
			continue;
		for (j = 0; j < c->n_in && c->in_id[j] != w; j++)
			;
		if (j == c->n_in && c->n_in < MAX_IN_IDS)
			c->in_id[c->n_in++] = w;
	}
	for (j = 0; j < n_out; j++) {
		c->out_id[j] = ids[j];
		c->out_len[j] = fd_frames ? fd_len(lens[j]) : lens[j];
	}
	c->n_out = n_out;
	return PX_OK;
}

int px_can_dev_signal(struct px_dev *d, size_t i, double *value,
		      int64_t *t_ns)
{
	struct cdev *c;
	if (!d || !value || px_dev_ops(d) != &cdev_ops)
		return PX_E_INVAL;
	c = px_dev_impl(d);
	if (i >= c->n)
		return PX_E_INVAL;
	if (!c->have[i])
		return PX_E_AGAIN;
	*value = c->val[i];
	if (t_ns)
		*t_ns = c->t[i];
	return PX_OK;
}
