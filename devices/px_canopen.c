/* CANopen-lite master, CiA 402 state machine, simulated arm. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "px_canopen.h"
#include "px_codec.h"

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

static uint16_t get16(const uint8_t *p)
{
	return (uint16_t)(p[0] | (p[1] << 8));
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

/* ---- PDO mapping ------------------------------------------------------------- */

enum { IN_RPDO = 1, IN_TPDO = 2 };

struct obj_info {
	uint16_t index;
	uint8_t bits;
	uint8_t is_signed;
	uint8_t where;
};

static const struct obj_info objs[] = {
	{0x6040, 16, 0, IN_RPDO}, {0x6060, 8, 1, IN_RPDO},
	{0x607A, 32, 1, IN_RPDO}, {0x60FF, 32, 1, IN_RPDO},
	{0x6071, 16, 1, IN_RPDO}, {0x6041, 16, 0, IN_TPDO},
	{0x6064, 32, 1, IN_TPDO}, {0x606C, 32, 1, IN_TPDO},
	{0x6077, 16, 1, IN_TPDO},
};

static const struct obj_info *obj_find(uint16_t index)
{
	size_t i;
	for (i = 0; i < sizeof objs / sizeof objs[0]; i++)
		if (objs[i].index == index)
			return &objs[i];
	return NULL;
}

static int is_target(uint16_t index)
{
	return index == 0x607A || index == 0x60FF || index == 0x6071;
}

void px_canopen_pdo_map_default(struct px_canopen_pdo_map *m)
{
	static const struct px_canopen_pdo_map def = {
		{3, {{0x6040, 0, 16}, {0x607A, 0, 32}, {0x6060, 0, 8}}},
		{2, {{0x6041, 0, 16}, {0x6064, 0, 32}}},
		{2, {{0x606C, 0, 32}, {0x6077, 0, 16}}},
	};
	if (m)
		*m = def;
}

static int pdo_has(const struct px_canopen_pdo *p, uint16_t index)
{
	size_t i;
	for (i = 0; i < p->n && i < PX_CANOPEN_MAX_MAP; i++)
		if (p->e[i].index == index)
			return 1;
	return 0;
}

static int pdo_check(const struct px_canopen_pdo *p, const char *nm,
		     int where, char *msg, size_t cap)
{
	size_t i, j;
	unsigned bits = 0;
	if (p->n > PX_CANOPEN_MAX_MAP) {
		if (msg)
			snprintf(msg, cap, "%s: %zu entries; at most %d", nm,
				 p->n, PX_CANOPEN_MAX_MAP);
		return PX_E_INVAL;
	}
	for (i = 0; i < p->n; i++) {
		const struct px_canopen_map_entry *e = &p->e[i];
		const struct obj_info *o = obj_find(e->index);
		if (!o || o->where != where) {
			if (msg)
				snprintf(msg, cap, "%s[%zu]: object 0x%04X is "
					 "not one a%s carries in this subset",
					 nm, i, e->index,
					 where == IN_RPDO ? "n RPDO" : " TPDO");
			return PX_E_INVAL;
		}
		if (e->subindex != 0) {
			if (msg)
				snprintf(msg, cap, "%s[%zu]: object 0x%04X has "
					 "subindex 0, not %u", nm, i, e->index,
					 e->subindex);
			return PX_E_INVAL;
		}
		if (e->bits != o->bits) {
			if (msg)
				snprintf(msg, cap, "%s[%zu]: object 0x%04X is "
					 "%u bits, not %u", nm, i, e->index,
					 o->bits, e->bits);
			return PX_E_INVAL;
		}
		for (j = 0; j < i; j++)
			if (p->e[j].index == e->index ||
			    (is_target(e->index) && is_target(p->e[j].index))) {
				if (msg)
					snprintf(msg, cap, "%s[%zu]: object "
						 "0x%04X repeats %s[%zu]'s "
						 "role", nm, i, e->index, nm, j);
				return PX_E_INVAL;
			}
		bits += e->bits;
	}
	if (bits > 64) {
		if (msg)
			snprintf(msg, cap, "%s: %u bits; a PDO holds at most 64",
				 nm, bits);
		return PX_E_INVAL;
	}
	return PX_OK;
}

int px_canopen_pdo_map_check(const struct px_canopen_pdo_map *m, char *msg,
			     size_t cap)
{
	int rc;
	if (msg && cap)
		msg[0] = 0;
	if (!m)
		return PX_E_INVAL;
	if ((rc = pdo_check(&m->rpdo, "rpdo", IN_RPDO, msg, cap)) ||
	    (rc = pdo_check(&m->tpdo1, "tpdo1", IN_TPDO, msg, cap)) ||
	    (rc = pdo_check(&m->tpdo2, "tpdo2", IN_TPDO, msg, cap)))
		return rc;
	if (!pdo_has(&m->rpdo, 0x6040) ||
	    !(pdo_has(&m->rpdo, 0x607A) || pdo_has(&m->rpdo, 0x60FF) ||
	      pdo_has(&m->rpdo, 0x6071))) {
		if (msg)
			snprintf(msg, cap, "rpdo: needs the controlword "
				 "0x6040 and a target (0x607A, 0x60FF or "
				 "0x6071)");
		return PX_E_INVAL;
	}
	if (m->tpdo1.n == 0) {
		if (msg)
			snprintf(msg, cap, "tpdo1: empty (it carries the "
				 "feedback)");
		return PX_E_INVAL;
	}
	if (!(pdo_has(&m->tpdo1, 0x6041) || pdo_has(&m->tpdo2, 0x6041)) ||
	    !(pdo_has(&m->tpdo1, 0x6064) || pdo_has(&m->tpdo2, 0x6064))) {
		if (msg)
			snprintf(msg, cap, "tpdo1/tpdo2: need the statusword "
				 "0x6041 and position actual 0x6064");
		return PX_E_INVAL;
	}
	return PX_OK;
}

size_t px_canopen_pdo_bytes(const struct px_canopen_pdo *p)
{
	size_t i, bits = 0;
	if (!p)
		return 0;
	for (i = 0; i < p->n && i < PX_CANOPEN_MAX_MAP; i++)
		bits += p->e[i].bits;
	return (bits + 7) / 8;
}

int px_canopen_pdo_pack(const struct px_canopen_pdo *p, const int64_t *vals,
			uint8_t *data, size_t len)
{
	size_t i;
	unsigned pos = 0;
	if (!p || !vals || !data || p->n > PX_CANOPEN_MAX_MAP)
		return PX_E_INVAL;
	for (i = 0; i < p->n; i++) {
		int rc = px_codec_put_raw(data, len, pos / 8, pos % 8,
					  p->e[i].bits, PX_LITTLE_ENDIAN,
					  (uint64_t)vals[i]);
		if (rc != PX_OK)
			return rc;
		pos += p->e[i].bits;
	}
	return PX_OK;
}

int px_canopen_pdo_unpack(const struct px_canopen_pdo *p, const uint8_t *data,
			  size_t len, int64_t *vals)
{
	size_t i;
	unsigned pos = 0;
	if (!p || !vals || !data || p->n > PX_CANOPEN_MAX_MAP)
		return PX_E_INVAL;
	for (i = 0; i < p->n; i++) {
		const struct obj_info *o = obj_find(p->e[i].index);
		int rc = px_codec_get_raw(data, len, pos / 8, pos % 8,
					  p->e[i].bits, o ? o->is_signed : 0,
					  PX_LITTLE_ENDIAN, &vals[i]);
		if (rc != PX_OK)
			return rc;
		pos += p->e[i].bits;
	}
	return PX_OK;
}

/* v clamped to what a bits-wide object holds (signed or not). */
static int64_t fit(int64_t v, unsigned bits, int is_signed)
{
	int64_t lo = is_signed ? -((int64_t)1 << (bits - 1)) : 0;
	int64_t hi = is_signed ? ((int64_t)1 << (bits - 1)) - 1
			       : ((int64_t)1 << bits) - 1;
	return v < lo ? lo : v > hi ? hi : v;
}

/* ---- master ------------------------------------------------------------------ */

struct px_canopen {
	struct px_canopen_config cfg;
	struct px_canopen_pdo_map pdo;
	struct px_canopen_drive_cfg drv[PX_CANOPEN_MAX_DRIVES];
	struct px_canopen_drive_status st[PX_CANOPEN_MAX_DRIVES];
	struct px_can_bus *bus;
	int started;
	int64_t t0, last_hb;
	/* a node announced boot-up or pre-operational: start it (again) */
	int need_start[PX_CANOPEN_MAX_DRIVES];
	/* when each drive's statusword last came (0 never) */
	int64_t sw_ns[PX_CANOPEN_MAX_DRIVES];
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

/* Own copies of a config's PDO map (the default when it names none) and
 * drive table, so the caller's may go away after create. */
static void own_tables(const struct px_canopen_pdo_map *pdo_in,
		       const struct px_canopen_drive_cfg *drives, size_t n,
		       struct px_canopen_pdo_map *pdo,
		       struct px_canopen_drive_cfg *drv)
{
	if (pdo_in)
		*pdo = *pdo_in;
	else
		px_canopen_pdo_map_default(pdo);
	memcpy(drv, drives, n * sizeof *drives);
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
	if (c->pdo && px_canopen_pdo_map_check(c->pdo, msg, cap) != PX_OK)
		return PX_E_INVAL;
	co = calloc(1, sizeof *co);
	if (!co)
		return PX_E_NOMEM;
	co->cfg = *c;
	own_tables(c->pdo, c->drives, c->n_drives, &co->pdo, co->drv);
	co->cfg.pdo = &co->pdo;
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
		if ((fn == 0x180 || fn == 0x280) &&
		    (fn == 0x180 ? co->pdo.tpdo1.n : co->pdo.tpdo2.n)) {
			const struct px_canopen_pdo *p =
				fn == 0x180 ? &co->pdo.tpdo1 : &co->pdo.tpdo2;
			int64_t v[PX_CANOPEN_MAX_MAP];
			size_t e;
			if (px_canopen_pdo_unpack(p, m.f.data, m.f.len, v) !=
			    PX_OK)
				continue; /* short frame: not this layout */
			for (e = 0; e < p->n; e++)
				switch (p->e[e].index) {
				case 0x6041:
					s->statusword = (uint16_t)v[e];
					s->state = px_cia402_state_of(
						s->statusword);
					co->sw_ns[d] = m.t_ns ? m.t_ns : 1;
					break;
				case 0x6064:
					s->position = (double)v[e] /
						      c->counts_per_unit;
					s->feedback_ns = m.t_ns;
					break;
				case 0x606C:
					s->velocity = (double)v[e] /
						      c->counts_per_unit;
					break;
				case 0x6077:
					s->torque_n_m = (double)v[e] / 1000.0 *
							c->rated_torque_n_m;
					break;
				}
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

/* Drive i's RPDO: its controlword as set, modes of operation, target
 * raw (in the mode's units). */
static int send_rpdo(struct px_canopen *co, size_t i, int32_t raw, int64_t now)
{
	const struct px_canopen_pdo *p = &co->pdo.rpdo;
	const struct px_canopen_drive_cfg *c = &co->drv[i];
	int64_t v[PX_CANOPEN_MAX_MAP];
	uint8_t b[8];
	size_t e;
	for (e = 0; e < p->n; e++) {
		uint16_t ix = p->e[e].index;
		v[e] = ix == 0x6040   ? co->st[i].controlword
		       : ix == 0x6060 ? c->mode
				      : fit(raw, p->e[e].bits, 1);
	}
	memset(b, 0, sizeof b);
	px_canopen_pdo_pack(p, v, b, sizeof b);
	return send_frame(co->bus, 0x200u + c->node_id, b,
			  (int)px_canopen_pdo_bytes(p), now);
}

/* SYNC when enabled, and the heartbeat when due. */
static int sync_and_heartbeat(struct px_canopen *co, int64_t now)
{
	uint8_t b[1] = {0};
	int rc = PX_OK;
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
		r = send_rpdo(co, i, raw, now);
		if (r == PX_E_IO)
			rc = PX_E_IO;
	}
	r = sync_and_heartbeat(co, now);
	return rc < 0 ? rc : r;
}

/* ---- safe stop ------------------------------------------------------------ */

void px_canopen_stop_config_default(struct px_canopen_stop_config *c)
{
	if (!c)
		return;
	memset(c, 0, sizeof *c);
	c->timeout_ns = 500000000;
	c->max_rounds = 1000;
	c->period_ns = 1000000;
	c->quick_stop_ns = 20000000;
}

static int64_t sleep_period(void *user, int64_t now, int64_t period_ns)
{
	struct timespec ts;
	(void)user;
	(void)now;
	ts.tv_sec = (time_t)(period_ns / 1000000000);
	ts.tv_nsec = (long)(period_ns % 1000000000);
	nanosleep(&ts, NULL);
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

/* Power stage off as the drive itself reports it. */
static int disabled_state(int state)
{
	return state == PX_CIA402_SWITCH_ON_DISABLED ||
	       state == PX_CIA402_NOT_READY || state == PX_CIA402_FAULT;
}

int px_canopen_safe_stop(struct px_canopen *co, int64_t now_ns,
			 const struct px_canopen_stop_config *cfg,
			 struct px_canopen_stop_result *res)
{
	struct px_canopen_stop_config c;
	int64_t qs_since[PX_CANOPEN_MAX_DRIVES];
	int64_t t0 = now_ns, sent0 = 0;
	uint32_t round;
	size_t i;
	int io = 0;
	if (res) {
		memset(res, 0, sizeof *res);
		res->first_unconfirmed = -1;
	}
	if (!co)
		return PX_E_INVAL;
	if (cfg)
		c = *cfg;
	else
		px_canopen_stop_config_default(&c);
	if (c.timeout_ns < 0 || c.period_ns <= 0 || c.quick_stop_ns < 0)
		return PX_E_INVAL;
	if (!c.wait)
		c.wait = sleep_period;
	for (i = 0; i < co->cfg.n_drives; i++)
		qs_since[i] = INT64_MIN;
	for (round = 0;; round++) {
		size_t ok = 0, faulted = 0;
		int first = -1;
		if (px_canopen_rx(co, now_ns) == PX_E_IO)
			io = 1; /* kept trying within the bound */
		/* confirmed: a statusword sent after our first command says
		 * the power stage is off */
		for (i = 0; i < co->cfg.n_drives; i++) {
			const struct px_canopen_drive_status *s = &co->st[i];
			if (round > 0 && co->sw_ns[i] > sent0 && !s->lost &&
			    disabled_state(s->state)) {
				ok++;
				faulted += s->state == PX_CIA402_FAULT;
			} else if (first < 0) {
				first = (int)i;
			}
		}
		if (res) {
			res->drives = co->cfg.n_drives;
			res->disabled = ok;
			res->faulted = faulted;
			res->first_unconfirmed = first;
			res->rounds = round;
			res->elapsed_ns = now_ns - t0;
		}
		if (ok == co->cfg.n_drives)
			return PX_OK;
		if (round >= c.max_rounds || now_ns - t0 >= c.timeout_ns)
			return io ? PX_E_IO : PX_E_TIMEOUT;
		if (round == 0)
			sent0 = now_ns - 1;
		/* quick stop from operation enabled, held quick_stop_ns so
		 * the drive decelerates on its own ramp, then disable
		 * voltage; anything else straight to disable voltage (no
		 * fault reset: a faulted drive stays off) */
		for (i = 0; i < co->cfg.n_drives; i++) {
			struct px_canopen_drive_status *s = &co->st[i];
			const struct px_canopen_drive_cfg *d = &co->drv[i];
			int32_t hold = 0;
			if (s->state == PX_CIA402_OPERATION_ENABLED ||
			    (s->state == PX_CIA402_QUICK_STOP_ACTIVE &&
			     (qs_since[i] == INT64_MIN ||
			      now_ns - qs_since[i] < c.quick_stop_ns))) {
				if (qs_since[i] == INT64_MIN)
					qs_since[i] = now_ns;
				s->controlword = PX_CIA402_CW_QUICK_STOP;
			} else {
				s->controlword = PX_CIA402_CW_DISABLE_VOLTAGE;
			}
			/* a position drive is told to stay where it is, the
			 * others zero velocity or torque */
			if (d->mode == PX_CIA402_CSP)
				hold = to_i32(s->position * d->counts_per_unit);
			if (send_rpdo(co, i, hold, now_ns) == PX_E_IO)
				io = 1;
		}
		if (sync_and_heartbeat(co, now_ns) == PX_E_IO)
			io = 1;
		now_ns = c.wait(c.user, now_ns, c.period_ns);
	}
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
	struct px_canopen_pdo_map pdo;
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
	if (c->pdo && px_canopen_pdo_map_check(c->pdo, NULL, 0) != PX_OK)
		return PX_E_INVAL;
	s = calloc(1, sizeof *s);
	if (!s)
		return PX_E_NOMEM;
	s->cfg = *c;
	own_tables(c->pdo, c->drives, c->n_drives, &s->pdo, s->drv);
	s->cfg.pdo = &s->pdo;
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
		{
			int k;
			for (k = 0; k < 2; k++) {
				const struct px_canopen_pdo *p =
					k ? &s->pdo.tpdo2 : &s->pdo.tpdo1;
				int64_t v[PX_CANOPEN_MAX_MAP];
				size_t e;
				if (!p->n)
					continue;
				for (e = 0; e < p->n; e++) {
					int64_t x = 0;
					switch (p->e[e].index) {
					case 0x6041:
						x = px_cia402_statusword(
							d->state);
						break;
					case 0x6064:
						x = to_i32(d->pos *
							   c->counts_per_unit);
						break;
					case 0x606C:
						x = to_i32(d->vel *
							   c->counts_per_unit);
						break;
					case 0x6077:
						x = to_i32(
							c->rated_torque_n_m > 0
								? d->torque /
									  c->rated_torque_n_m *
									  1000.0
								: 0.0);
						break;
					}
					v[e] = fit(x, p->e[e].bits,
						   p->e[e].index != 0x6041);
				}
				memset(b, 0, sizeof b);
				px_canopen_pdo_pack(p, v, b, sizeof b);
				send_frame(s->bus,
					   (k ? 0x280u : 0x180u) + c->node_id,
					   b, (int)px_canopen_pdo_bytes(p),
					   now);
			}
		}
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
		} else if ((id & 0x780) == 0x200 &&
			   m.f.len >= px_canopen_pdo_bytes(&s->pdo.rpdo)) {
			int64_t v[PX_CANOPEN_MAX_MAP];
			size_t e;
			if (px_canopen_pdo_unpack(&s->pdo.rpdo, m.f.data,
						  m.f.len, v) != PX_OK)
				continue;
			for (i = 0; i < s->cfg.n_drives; i++) {
				struct simdrv *d = &s->d[i];
				if (s->drv[i].node_id != (id & 0x7F) || d->silent ||
				    d->nmt != 5)
					continue;
				d->prev_cw = d->cw;
				for (e = 0; e < s->pdo.rpdo.n; e++) {
					uint16_t ix = s->pdo.rpdo.e[e].index;
					if (ix == 0x6040)
						d->cw = (uint16_t)v[e];
					else if (ix == 0x6060)
						d->mode = (int)v[e];
					else
						d->target = (int32_t)v[e];
				}
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
