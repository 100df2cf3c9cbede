/* CANopen-lite master, CiA 402 state machine, simulated arm. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "px_canopen.h"

/* ---- CiA 402 ------------------------------------------------------------- */

int px_cia402_state_of(uint16_t sw)
{
	if ((sw & 0x4F) == 0x00)
		return PX_CIA402_NOT_READY;
	if ((sw & 0x4F) == 0x40)
		return PX_CIA402_SWITCH_ON_DISABLED;
	if ((sw & 0x6F) == 0x21)
		return PX_CIA402_READY_TO_SWITCH_ON;
	if ((sw & 0x6F) == 0x23)
		return PX_CIA402_SWITCHED_ON;
	if ((sw & 0x6F) == 0x27)
		return PX_CIA402_OPERATION_ENABLED;
	if ((sw & 0x6F) == 0x07)
		return PX_CIA402_QUICK_STOP_ACTIVE;
	if ((sw & 0x4F) == 0x0F)
		return PX_CIA402_FAULT_REACTION_ACTIVE;
	if ((sw & 0x4F) == 0x08)
		return PX_CIA402_FAULT;
	return PX_CIA402_UNKNOWN;
}

uint16_t px_cia402_statusword(int state)
{
	static const uint16_t sw[] = {0x0000, 0x0040, 0x0031, 0x0033,
				      0x0037, 0x0017, 0x000F, 0x0008};
	if (state < 0 || state > PX_CIA402_FAULT)
		return 0x0008;
	return (uint16_t)(sw[state] | 0x0200);
}

int px_cia402_transition(int state, uint16_t cw, uint16_t prev_cw)
{
	int shutdown = (cw & 0x87) == 0x06;
	int switch_on = (cw & 0x8F) == 0x07; /* = disable operation */
	int enable = (cw & 0x8F) == 0x0F;
	int dis_volt = (cw & 0x82) == 0x00;
	int qstop = (cw & 0x86) == 0x02;
	if (state == PX_CIA402_FAULT)
		return (cw & 0x80) && !(prev_cw & 0x80)
			       ? PX_CIA402_SWITCH_ON_DISABLED
			       : PX_CIA402_FAULT;
	switch (state) {
	case PX_CIA402_NOT_READY:
		return PX_CIA402_SWITCH_ON_DISABLED;
	case PX_CIA402_SWITCH_ON_DISABLED:
		return shutdown ? PX_CIA402_READY_TO_SWITCH_ON : state;
	case PX_CIA402_READY_TO_SWITCH_ON:
		if (switch_on)
			return PX_CIA402_SWITCHED_ON;
		if (enable)
			return PX_CIA402_OPERATION_ENABLED;
		if (dis_volt || qstop)
			return PX_CIA402_SWITCH_ON_DISABLED;
		return state;
	case PX_CIA402_SWITCHED_ON:
		if (enable)
			return PX_CIA402_OPERATION_ENABLED;
		if (shutdown)
			return PX_CIA402_READY_TO_SWITCH_ON;
		if (dis_volt || qstop)
			return PX_CIA402_SWITCH_ON_DISABLED;
		return state;
	case PX_CIA402_OPERATION_ENABLED:
		if (switch_on)
			return PX_CIA402_SWITCHED_ON;
		if (shutdown)
			return PX_CIA402_READY_TO_SWITCH_ON;
		if (dis_volt)
			return PX_CIA402_SWITCH_ON_DISABLED;
		if (qstop)
			return PX_CIA402_QUICK_STOP_ACTIVE;
		return state;
	case PX_CIA402_QUICK_STOP_ACTIVE:
		if (dis_volt)
			return PX_CIA402_SWITCH_ON_DISABLED;
		if (enable)
			return PX_CIA402_OPERATION_ENABLED;
		return state;
	default:
		return state;
	}
}

uint16_t px_cia402_next_controlword(int state, int enable, uint16_t prev_cw)
{
	if (!enable) {
		if (state == PX_CIA402_OPERATION_ENABLED ||
		    state == PX_CIA402_QUICK_STOP_ACTIVE)
			return PX_CIA402_CW_QUICK_STOP;
		return PX_CIA402_CW_DISABLE_VOLTAGE;
	}
	switch (state) {
	case PX_CIA402_SWITCH_ON_DISABLED:
	case PX_CIA402_UNKNOWN:
		return PX_CIA402_CW_SHUTDOWN;
	case PX_CIA402_READY_TO_SWITCH_ON:
		return PX_CIA402_CW_SWITCH_ON;
	case PX_CIA402_SWITCHED_ON:
	case PX_CIA402_OPERATION_ENABLED:
		return PX_CIA402_CW_ENABLE_OPERATION;
	case PX_CIA402_FAULT:
		/* a reset is a rising edge of bit 7 */
		return (prev_cw & 0x80) ? PX_CIA402_CW_DISABLE_VOLTAGE
					: PX_CIA402_CW_FAULT_RESET;
	default: /* not ready, quick stop, fault reaction */
		return PX_CIA402_CW_DISABLE_VOLTAGE;
	}
}

const char *px_cia402_state_name(int state)
{
	static const char *const n[] = {
		"not ready to switch on", "switch on disabled",
		"ready to switch on", "switched on", "operation enabled",
		"quick stop active", "fault reaction active", "fault",
		"unknown"};
	if (state < 0 || state > PX_CIA402_UNKNOWN)
		return "unknown";
	return n[state];
}

/* ---- little-endian helpers ------------------------------------------------ */

static void put16(uint8_t *p, uint16_t v)
{
	p[0] = (uint8_t)v;
	p[1] = (uint8_t)(v >> 8);
}

static void put32(uint8_t *p, int32_t v)
{
	uint32_t u = (uint32_t)v;
	p[0] = (uint8_t)u;
	p[1] = (uint8_t)(u >> 8);
	p[2] = (uint8_t)(u >> 16);
	p[3] = (uint8_t)(u >> 24);
}

static uint16_t get16(const uint8_t *p)
{
	return (uint16_t)(p[0] | (p[1] << 8));
}

static int32_t get32(const uint8_t *p)
{
	return (int32_t)((uint32_t)p[0] | ((uint32_t)p[1] << 8) |
			 ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24));
}

static int32_t to_i32(double v)
{
	double r = round(v);
	if (r >= 2147483647.0)
		return INT32_MAX;
	if (r <= -2147483648.0)
		return INT32_MIN;
	return (int32_t)r;
}

static int send_frame(struct px_can_bus *b, uint32_t id, const uint8_t *d,
		      int len, int64_t now)
{
	struct px_can_msg m;
	memset(&m, 0, sizeof m);
	m.f.can_id = id;
	m.f.len = (uint8_t)len;
	if (len)
		memcpy(m.f.data, d, (size_t)len);
	return px_can_bus_send(b, &m, now);
}

static int drive_cfg_ok(const struct px_canopen_drive_cfg *d)
{
	return d->node_id >= 1 && d->node_id <= 127 &&
	       (d->mode == PX_CIA402_CSP || d->mode == PX_CIA402_CSV ||
		d->mode == PX_CIA402_CST) &&
	       d->joint >= 0 && isfinite(d->counts_per_unit) &&
	       d->counts_per_unit > 0 &&
	       (d->mode != PX_CIA402_CST ||
		(isfinite(d->rated_torque_n_m) && d->rated_torque_n_m > 0));
}

/* ---- master ------------------------------------------------------------------ */

struct px_canopen {
	struct px_canopen_config cfg;
	struct px_canopen_drive_cfg drv[PX_CANOPEN_MAX_DRIVES];
	struct px_canopen_drive_status st[PX_CANOPEN_MAX_DRIVES];
	struct px_can_bus *bus;
	int started;
	int64_t t0, last_hb;
	/* a node announced boot-up or pre-operational: start it (again) */
	int need_start[PX_CANOPEN_MAX_DRIVES];
};

void px_canopen_config_default(struct px_canopen_config *c)
{
	if (!c)
		return;
	memset(c, 0, sizeof *c);
	c->own_node_id = 127;
	c->sync = 1;
	c->heartbeat_period_ns = 100000000;
	c->heartbeat_timeout_ns = 300000000;
}

int px_canopen_create(const struct px_canopen_config *c,
		      struct px_can_bus *bus, struct px_canopen **out,
		      char *msg, size_t cap)
{
	struct px_canopen *co;
	size_t i, j;
	if (msg && cap)
		msg[0] = 0;
	if (!c || !bus || !out || c->n_drives < 1 ||
	    c->n_drives > PX_CANOPEN_MAX_DRIVES || !c->drives ||
	    c->own_node_id < 1 || c->own_node_id > 127 ||
	    c->heartbeat_period_ns < 0 || c->heartbeat_timeout_ns < 0) {
		if (msg)
			snprintf(msg, cap, "canopen: 1..%d drives, own node id "
				 "1..127, heartbeat times >= 0",
				 PX_CANOPEN_MAX_DRIVES);
		return PX_E_INVAL;
	}
	for (i = 0; i < c->n_drives; i++) {
		if (!drive_cfg_ok(&c->drives[i])) {
			if (msg)
				snprintf(msg, cap, "canopen: drives[%zu] (node "
					 "%u): node id 1..127, mode csp/csv/cst, "
					 "joint >= 0, counts_per_unit > 0, "
					 "rated torque > 0 for cst", i,
					 c->drives[i].node_id);
			return PX_E_INVAL;
		}
		for (j = 0; j < i; j++)
			if (c->drives[j].node_id == c->drives[i].node_id) {
				if (msg)
					snprintf(msg, cap, "canopen: drives[%zu] "
						 "repeats node id %u", i,
						 c->drives[i].node_id);
				return PX_E_INVAL;
			}
	}
	co = calloc(1, sizeof *co);
	if (!co)
		return PX_E_NOMEM;
	co->cfg = *c;
	memcpy(co->drv, c->drives, c->n_drives * sizeof *c->drives);
	co->cfg.drives = co->drv;
	for (i = 0; i < c->n_drives; i++) {
		co->st[i].node_id = c->drives[i].node_id;
		co->st[i].state = PX_CIA402_UNKNOWN;
		co->st[i].nmt_state = -1;
	}
	co->bus = bus;
	*out = co;
	return PX_OK;
}

void px_canopen_free(struct px_canopen *co)
{
	free(co);
}

static int drive_of(const struct px_canopen *co, unsigned node)
{
	size_t i;
	for (i = 0; i < co->cfg.n_drives; i++)
		if (co->drv[i].node_id == node)
			return (int)i;
	return -1;
}

int px_canopen_rx(struct px_canopen *co, int64_t now)
{
	struct px_can_msg m;
	int n = 0, k, rc;
	size_t i;
	if (!co)
		return PX_E_INVAL;
	if (!co->started && !co->t0)
		co->t0 = now;
	for (k = 0; k < 512; k++) {
		uint32_t id, fn;
		int d;
		struct px_canopen_drive_status *s;
		const struct px_canopen_drive_cfg *c;
		rc = px_can_bus_recv(co->bus, now, &m);
		if (rc == PX_E_AGAIN)
			break;
		if (rc != PX_OK)
			return rc;
		if (m.f.can_id & (CAN_EFF_FLAG | CAN_ERR_FLAG | CAN_RTR_FLAG))
			continue;
		id = m.f.can_id & CAN_SFF_MASK;
		fn = id & 0x780;
		d = drive_of(co, id & 0x7F);
		if (d < 0)
			continue;
		s = &co->st[d];
		c = &co->drv[d];
		n++;
		if (fn == 0x180 && m.f.len >= 6) {
			s->statusword = get16(m.f.data);
			s->state = px_cia402_state_of(s->statusword);
			s->position = get32(m.f.data + 2) / c->counts_per_unit;
			s->feedback_ns = m.t_ns;
		} else if (fn == 0x280 && m.f.len >= 6) {
			s->velocity = get32(m.f.data) / c->counts_per_unit;
			s->torque_n_m = (int16_t)get16(m.f.data + 4) / 1000.0 *
					c->rated_torque_n_m;
		} else if (fn == 0x700 && m.f.len >= 1) {
			s->heartbeat_ns = m.t_ns;
			s->nmt_state = m.f.data[0] & 0x7F;
			if (s->nmt_state != 0x05)
				co->need_start[d] = 1;
		} else if (fn == 0x080 && m.f.len >= 2) {
			s->emcy_code = get16(m.f.data);
			s->emcy_count++;
		}
	}
	if (co->cfg.heartbeat_timeout_ns > 0)
		for (i = 0; i < co->cfg.n_drives; i++) {
			struct px_canopen_drive_status *s = &co->st[i];
			int64_t since = s->heartbeat_ns ? s->heartbeat_ns : co->t0;
			s->lost = now - since > co->cfg.heartbeat_timeout_ns;
		}
	return n;
}

int px_canopen_tx(struct px_canopen *co, int64_t now, const double *targets,
		  size_t n_targets, int enable)
{
	size_t i;
	int rc = PX_OK, r;
	uint8_t b[8];
	if (!co || (n_targets && !targets))
		return PX_E_INVAL;
	if (!co->started) {
		b[0] = 0x01; /* start remote node */
		b[1] = 0x00; /* all nodes */
		send_frame(co->bus, 0x000, b, 2, now);
		co->started = 1;
		if (!co->t0)
			co->t0 = now;
	}
	for (i = 0; i < co->cfg.n_drives; i++)
		if (co->need_start[i]) {
			/* it missed the broadcast start (booted later) */
			b[0] = 0x01;
			b[1] = co->drv[i].node_id;
			send_frame(co->bus, 0x000, b, 2, now);
			co->need_start[i] = 0;
		}
	for (i = 0; i < co->cfg.n_drives; i++) {
		const struct px_canopen_drive_cfg *c = &co->drv[i];
		struct px_canopen_drive_status *s = &co->st[i];
		double t = (size_t)c->joint < n_targets ? targets[c->joint] : 0.0;
		int32_t raw;
		int ok = 1;
		if (!isfinite(t)) {
			ok = 0;
			rc = PX_E_NAN;
			t = 0.0;
		}
		s->controlword = px_cia402_next_controlword(
			s->state, enable && ok && !s->lost, s->controlword);
		if (c->mode == PX_CIA402_CST)
			raw = to_i32(t / c->rated_torque_n_m * 1000.0);
		else
			raw = to_i32(t * c->counts_per_unit);
		put16(b, s->controlword);
		put32(b + 2, raw);
		b[6] = (uint8_t)(int8_t)c->mode;
		r = send_frame(co->bus, 0x200u + c->node_id, b, 7, now);
		if (r == PX_E_IO)
			rc = PX_E_IO;
	}
	if (co->cfg.sync && send_frame(co->bus, 0x080, b, 0, now) == PX_E_IO)
		rc = PX_E_IO;
	if (co->cfg.heartbeat_period_ns > 0 &&
	    (co->last_hb == 0 ||
	     now - co->last_hb >= co->cfg.heartbeat_period_ns)) {
		b[0] = 0x05; /* operational */
		send_frame(co->bus, 0x700u + co->cfg.own_node_id, b, 1, now);
		co->last_hb = now ? now : 1;
	}
	return rc;
}

int px_canopen_all_enabled(const struct px_canopen *co)
{
	size_t i;
	if (!co)
		return 0;
	for (i = 0; i < co->cfg.n_drives; i++)
		if (co->st[i].state != PX_CIA402_OPERATION_ENABLED ||
		    co->st[i].lost)
			return 0;
	return 1;
}

int px_canopen_first_problem(const struct px_canopen *co)
{
	size_t i;
	if (!co)
		return -1;
	for (i = 0; i < co->cfg.n_drives; i++)
		if (co->st[i].lost || co->st[i].state == PX_CIA402_FAULT ||
		    co->st[i].state == PX_CIA402_FAULT_REACTION_ACTIVE)
			return (int)i;
	return -1;
}

int px_canopen_drive_status(const struct px_canopen *co, size_t i,
			    struct px_canopen_drive_status *st)
{
	if (!co || !st || i >= co->cfg.n_drives)
		return PX_E_INVAL;
	*st = co->st[i];
	return PX_OK;
}

/* ---- simulated arm ------------------------------------------------------------ */

struct simdrv {
	int state;
	uint16_t cw, prev_cw;
	int32_t target;
	int mode;
	double pos, vel, torque;
	int nmt;           /* 0 boot/pre-op, 5 operational */
	int silent;
	int faulted;       /* inside a fault window already handled */
	int booted;
};

struct px_canopen_sim {
	struct px_canopen_sim_config cfg;
	struct px_canopen_drive_cfg drv[PX_CANOPEN_MAX_DRIVES];
	struct px_sim_fault faults[PX_SIM_MAX_FAULTS];
	struct simdrv d[PX_CANOPEN_MAX_DRIVES];
	struct px_can_bus *bus;
	int64_t last_sync, last_hb;
	int have_sync;
};

int px_canopen_sim_create(const struct px_canopen_sim_config *c,
			  struct px_can_bus *bus, struct px_canopen_sim **out)
{
	struct px_canopen_sim *s;
	size_t i;
	if (!c || !bus || !out || c->n_drives < 1 ||
	    c->n_drives > PX_CANOPEN_MAX_DRIVES || !c->drives ||
	    c->n_faults > PX_SIM_MAX_FAULTS || (c->n_faults && !c->faults))
		return PX_E_INVAL;
	for (i = 0; i < c->n_drives; i++)
		if (!drive_cfg_ok(&c->drives[i]))
			return PX_E_INVAL;
	for (i = 0; i < c->n_faults; i++)
		if ((c->faults[i].kind != PX_SIM_FAULT_ESTOP &&
		     c->faults[i].kind != PX_SIM_FAULT_UNPLUG) ||
		    c->faults[i].duration_ns <= 0 || c->faults[i].delay_ns < 0 ||
		    (size_t)c->faults[i].delay_ns >= c->n_drives)
			return PX_E_INVAL;
	s = calloc(1, sizeof *s);
	if (!s)
		return PX_E_NOMEM;
	s->cfg = *c;
	memcpy(s->drv, c->drives, c->n_drives * sizeof *c->drives);
	s->cfg.drives = s->drv;
	if (c->n_faults)
		memcpy(s->faults, c->faults, c->n_faults * sizeof *c->faults);
	s->cfg.faults = s->faults;
	if (s->cfg.heartbeat_period_ns <= 0)
		s->cfg.heartbeat_period_ns = 100000000;
	if (!(s->cfg.inertia_kg_m2 > 0))
		s->cfg.inertia_kg_m2 = 0.01;
	for (i = 0; i < c->n_drives; i++) {
		s->d[i].state = PX_CIA402_NOT_READY;
		s->d[i].mode = c->drives[i].mode;
	}
	s->bus = bus;
	*out = s;
	return PX_OK;
}

void px_canopen_sim_free(struct px_canopen_sim *s)
{
	free(s);
}

static int in_fault(const struct px_canopen_sim *s, int kind, size_t drive,
		    int64_t now)
{
	size_t i;
	for (i = 0; i < s->cfg.n_faults; i++) {
		const struct px_sim_fault *f = &s->faults[i];
		if (f->kind == kind && (size_t)f->delay_ns == drive &&
		    now >= f->start_ns && now < f->start_ns + f->duration_ns)
			return 1;
	}
	return 0;
}

static void sim_sync(struct px_canopen_sim *s, int64_t now)
{
	double dt = s->have_sync ? (double)(now - s->last_sync) * 1e-9 : 0.0;
	size_t i;
	uint8_t b[8];
	s->last_sync = now;
	s->have_sync = 1;
	for (i = 0; i < s->cfg.n_drives; i++) {
		struct simdrv *d = &s->d[i];
		const struct px_canopen_drive_cfg *c = &s->drv[i];
		if (d->silent || d->nmt != 5)
			continue;
		if (d->state == PX_CIA402_OPERATION_ENABLED) {
			if (d->mode == PX_CIA402_CSP) {
				double np = d->target / c->counts_per_unit;
				d->vel = dt > 0 ? (np - d->pos) / dt : 0.0;
				d->pos = np;
			} else if (d->mode == PX_CIA402_CSV) {
				d->vel = d->target / c->counts_per_unit;
				d->pos += d->vel * dt;
			} else {
				d->torque = d->target / 1000.0 *
					    c->rated_torque_n_m;
				d->vel += d->torque / s->cfg.inertia_kg_m2 * dt;
				d->pos += d->vel * dt;
			}
		} else {
			/* brake: standstill; a quick stop completes here */
			d->vel = 0.0;
			d->torque = 0.0;
			if (d->state == PX_CIA402_QUICK_STOP_ACTIVE)
				d->state = PX_CIA402_SWITCH_ON_DISABLED;
		}
		put16(b, px_cia402_statusword(d->state));
		put32(b + 2, to_i32(d->pos * c->counts_per_unit));
		send_frame(s->bus, 0x180u + c->node_id, b, 6, now);
		put32(b, to_i32(d->vel * c->counts_per_unit));
		put16(b + 4, (uint16_t)(int16_t)to_i32(
				     c->rated_torque_n_m > 0
					     ? d->torque / c->rated_torque_n_m *
						       1000.0
					     : 0.0));
		send_frame(s->bus, 0x280u + c->node_id, b, 6, now);
	}
}

int px_canopen_sim_step(struct px_canopen_sim *s, int64_t now)
{
	struct px_can_msg m;
	size_t i;
	int k, rc;
	uint8_t b[8];
	if (!s)
		return PX_E_INVAL;
	for (i = 0; i < s->cfg.n_drives; i++) {
		struct simdrv *d = &s->d[i];
		int fault = in_fault(s, PX_SIM_FAULT_ESTOP, i, now);
		d->silent = in_fault(s, PX_SIM_FAULT_UNPLUG, i, now);
		if (fault && !d->faulted) {
			d->faulted = 1;
			d->state = PX_CIA402_FAULT; /* via fault reaction */
			memset(b, 0, sizeof b);
			put16(b, 0x5441); /* device specific: drive fault */
			b[2] = 0x01;      /* error register: generic */
			send_frame(s->bus, 0x080u + s->drv[i].node_id, b, 8, now);
		} else if (!fault) {
			d->faulted = 0;
		}
	}
	for (k = 0; k < 1024; k++) {
		uint32_t id;
		rc = px_can_bus_recv(s->bus, now, &m);
		if (rc == PX_E_AGAIN)
			break;
		if (rc != PX_OK)
			return rc;
		if (m.f.can_id & (CAN_EFF_FLAG | CAN_ERR_FLAG | CAN_RTR_FLAG))
			continue;
		id = m.f.can_id & CAN_SFF_MASK;
		if (id == 0x000 && m.f.len >= 2) {
			for (i = 0; i < s->cfg.n_drives; i++)
				if (!s->d[i].silent &&
				    (m.f.data[1] == 0 ||
				     m.f.data[1] == s->drv[i].node_id)) {
					if (m.f.data[0] == 0x01)
						s->d[i].nmt = 5;
					else if (m.f.data[0] == 0x02)
						s->d[i].nmt = 4;
					else if (m.f.data[0] == 0x80)
						s->d[i].nmt = 0x7F;
				}
		} else if (id == 0x080 && m.f.len == 0) {
			sim_sync(s, m.t_ns);
		} else if ((id & 0x780) == 0x200 && m.f.len >= 7) {
			for (i = 0; i < s->cfg.n_drives; i++) {
				struct simdrv *d = &s->d[i];
				if (s->drv[i].node_id != (id & 0x7F) || d->silent ||
				    d->nmt != 5)
					continue;
				d->prev_cw = d->cw;
				d->cw = get16(m.f.data);
				d->target = get32(m.f.data + 2);
				d->mode = (int8_t)m.f.data[6];
				if (d->state == PX_CIA402_NOT_READY)
					d->state = PX_CIA402_SWITCH_ON_DISABLED;
				if (d->state != PX_CIA402_FAULT ||
				    !in_fault(s, PX_SIM_FAULT_ESTOP, i, now))
					d->state = px_cia402_transition(
						d->state, d->cw, d->prev_cw);
			}
		}
	}
	for (i = 0; i < s->cfg.n_drives; i++) {
		struct simdrv *d = &s->d[i];
		if (d->silent || d->booted)
			continue;
		b[0] = 0x00; /* boot-up */
		send_frame(s->bus, 0x700u + s->drv[i].node_id, b, 1, now);
		d->booted = 1;
		d->nmt = d->nmt ? d->nmt : 0x7F;
	}
	if (!s->last_hb || now - s->last_hb >= s->cfg.heartbeat_period_ns) {
		s->last_hb = now ? now : 1;
		for (i = 0; i < s->cfg.n_drives; i++) {
			if (s->d[i].silent)
				continue;
			b[0] = (uint8_t)s->d[i].nmt;
			send_frame(s->bus, 0x700u + s->drv[i].node_id, b, 1, now);
		}
	}
	return PX_OK;
}

int px_canopen_sim_joint(const struct px_canopen_sim *s, size_t i,
			 double *position, int *state)
{
	if (!s || i >= s->cfg.n_drives)
		return PX_E_INVAL;
	if (position)
		*position = s->d[i].pos;
	if (state)
		*state = s->d[i].state;
	return PX_OK;
}
