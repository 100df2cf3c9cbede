/* Fault engine of the simulated CAN buses: windows of the simulation
 * clock in which frames are dropped, held back, sent twice, truncated,
 * frozen, overwritten with all-ones bytes, or the bus is off or gone. */
#include <stdio.h>
#include <string.h>

#include <linux/can/error.h>

#include "dev_internal.h"

int px__can_fx_init(struct px__can_fx *fx, const struct px_sim_fault *f,
		    size_t n, uint64_t seed, char *msg, size_t cap)
{
	size_t i;
	if (msg && cap)
		msg[0] = 0;
	if (!fx || n > PX_SIM_MAX_FAULTS || (n && !f)) {
		if (msg)
			snprintf(msg, cap, "at most %d faults", PX_SIM_MAX_FAULTS);
		return PX_E_INVAL;
	}
	for (i = 0; i < n; i++) {
		int k = f[i].kind;
		const char *why = NULL;
		if (k == PX_SIM_FAULT_ESTOP)
			why = "estop is not a CAN bus fault: it is given to the "
			      "simulated arm's drives (px_canopen_sim) or to a "
			      "GPIO e-stop line";
		else if (k <= PX_SIM_FAULT_NONE || k >= PX_SIM_FAULT__COUNT)
			why = "unknown kind";
		else if (f[i].duration_ns <= 0)
			why = "duration_ns must be > 0";
		else if (f[i].probability < 0 || f[i].probability > 1)
			why = "probability must be in (0, 1]";
		else if (k == PX_SIM_FAULT_DELAY && f[i].delay_ns <= 0)
			why = "kind delay needs delay_ns > 0";
		if (why) {
			if (msg)
				snprintf(msg, cap, "faults[%zu] (%s): %s", i,
					 px_sim_fault_name(k) ? px_sim_fault_name(k)
							      : "?",
					 why);
			return PX_E_INVAL;
		}
	}
	memset(fx, 0, sizeof *fx);
	if (n)
		memcpy(fx->f, f, n * sizeof *f);
	fx->n = n;
	fx->rng = seed ? seed : 1;
	return PX_OK;
}

static double unit(struct px__can_fx *fx)
{
	uint64_t x = fx->rng;
	x ^= x >> 12;
	x ^= x << 25;
	x ^= x >> 27;
	fx->rng = x;
	return (double)((x * 2685821657736338717ull) >> 11) *
	       (1.0 / 9007199254740992.0);
}

/* The fault of kind in effect at now; roll: also draw its probability. */
static const struct px_sim_fault *at(struct px__can_fx *fx, int kind,
				     int64_t now, int roll)
{
	size_t i;
	for (i = 0; i < fx->n; i++) {
		const struct px_sim_fault *f = &fx->f[i];
		double p;
		if (f->kind != kind || now < f->start_ns ||
		    now - f->start_ns >= f->duration_ns)
			continue;
		p = f->probability > 0 ? f->probability : 1.0;
		if (!roll || p >= 1.0 || unit(fx) < p)
			return f;
	}
	return NULL;
}

int px__can_fx_tick(struct px__can_fx *fx, int64_t now)
{
	int off = at(fx, PX_SIM_FAULT_BUSOFF, now, 0) != NULL;
	int gone = at(fx, PX_SIM_FAULT_UNPLUG, now, 0) != NULL;
	int changed = 0;
	if (off != fx->busoff)
		changed |= 1;
	if (gone != fx->unplugged) {
		changed |= 2;
		if (gone)
			fx->dn = 0; /* what was in flight is lost with the cable */
	}
	fx->busoff = off;
	fx->unplugged = gone;
	if (!at(fx, PX_SIM_FAULT_STUCK, now, 0))
		fx->n_stuck = 0; /* a later window freezes the values of then */
	return changed;
}

/* A frozen sender: each id repeats the first frame it sent in the
 * window (the same bytes, so a counter or noise in it stops too). */
static int stuck(struct px__can_fx *fx, struct px_can_msg *m)
{
	uint32_t id = m->f.can_id;
	size_t i;
	for (i = 0; i < fx->n_stuck; i++)
		if (fx->stuck_id[i] == id) {
			m->f = fx->stuck_f[i];
			return 1;
		}
	if (fx->n_stuck < PX__CAN_FX_IDS) {
		fx->stuck_id[fx->n_stuck] = id;
		fx->stuck_f[fx->n_stuck++] = m->f;
	}
	return 0;
}

int px__can_fx_apply(struct px__can_fx *fx, const struct px_can_msg *m,
		     const void *tag, int64_t now, struct px_can_msg out[2])
{
	const struct px_sim_fault *f;
	struct px_can_msg c = *m;
	int n = 1, data = !(m->f.can_id & (CAN_ERR_FLAG | CAN_RTR_FLAG));
	int64_t due = now;
	c.t_ns = now;
	if (fx->unplugged)
		return 0;
	if (!data || !fx->n)
		goto deliver;
	if (at(fx, PX_SIM_FAULT_DROP, now, 1)) {
		fx->hits++;
		return 0; /* lost on the wire: the sender cannot know */
	}
	if (at(fx, PX_SIM_FAULT_STUCK, now, 0) && stuck(fx, &c))
		fx->hits++;
	if (at(fx, PX_SIM_FAULT_CORRUPT, now, 1)) {
		/* a short frame: every signal reaching past the new length
		 * fails to decode */
		c.f.len /= 2;
		fx->hits++;
	}
	if (at(fx, PX_SIM_FAULT_NAN, now, 1)) {
		/* all ones: NaN in IEEE float payloads, "not available" in
		 * J1939-style integer signals (caught by min/max) */
		memset(c.f.data, 0xFF, c.f.len);
		fx->hits++;
	}
	if ((f = at(fx, PX_SIM_FAULT_DELAY, now, 1))) {
		due = now + f->delay_ns;
		fx->hits++;
	}
	if (at(fx, PX_SIM_FAULT_DUPLICATE, now, 1)) {
		n = 2;
		fx->hits++;
	}
deliver:
	/* Once frames are held back, later ones queue behind them: a
	 * delayed bus keeps its order (a gap, then a burst). */
	if (due > now || fx->dn) {
		int k;
		for (k = 0; k < n; k++) {
			struct px__can_fx_item *it;
			if (fx->dn == PX__CAN_FX_DELAY) {
				fx->delay_dropped++;
				continue;
			}
			it = &fx->dq[(fx->dh + fx->dn++) % PX__CAN_FX_DELAY];
			it->m = c;
			it->due_ns = due;
			it->tag = tag;
		}
		return 0;
	}
	out[0] = c;
	if (n == 2)
		out[1] = c;
	return n;
}

int px__can_fx_due(struct px__can_fx *fx, int64_t now, struct px_can_msg *m,
		   const void **tag)
{
	struct px__can_fx_item *it;
	if (!fx->dn)
		return 0;
	it = &fx->dq[fx->dh];
	if (it->due_ns > now)
		return 0;
	*m = it->m;
	m->t_ns = now; /* stamped on arrival, as a receiver would */
	if (tag)
		*tag = it->tag;
	fx->dh = (fx->dh + 1) % PX__CAN_FX_DELAY;
	fx->dn--;
	return 1;
}
