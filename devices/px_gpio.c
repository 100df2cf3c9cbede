/* Digital I/O: debounce, the shared e-stop/enable logic, and simulated
 * GPIO lines. */
#include <stdio.h>
#include <string.h>

#include "dev_internal.h"
#include "px_gpio.h"
#include "px_loop.h"

void px_debounce_init(struct px_debounce *db, int level, int64_t debounce_ns)
{
	if (!db)
		return;
	db->stable = db->candidate = level != 0;
	db->since_ns = INT64_MIN / 2;
	db->debounce_ns = debounce_ns > 0 ? debounce_ns : 0;
}

void px_debounce_feed(struct px_debounce *db, int level, int64_t t_ns)
{
	if (!db)
		return;
	level = level != 0;
	/* The level being replaced may have lasted long enough already:
	 * settle it first, so the result depends on the signal only, not
	 * on when it was looked at. */
	if (db->candidate != db->stable && t_ns - db->since_ns >= db->debounce_ns)
		db->stable = db->candidate;
	if (level != db->candidate) {
		db->candidate = level;
		db->since_ns = t_ns;
	}
}

int px_debounce_get(struct px_debounce *db, int64_t now_ns)
{
	if (!db)
		return 0;
	if (db->candidate != db->stable &&
	    now_ns - db->since_ns >= db->debounce_ns)
		db->stable = db->candidate;
	return db->stable;
}

/* ---- shared logic ------------------------------------------------------ */

void px__dio_init(struct px__dio *io, const struct px_gpio_config *cfg,
		  int estop_physical, int64_t t_ns)
{
	const struct px_gpio_line *e = &cfg->line[PX_GPIO_ESTOP];
	int r;
	(void)t_ns;
	memset(io, 0, sizeof *io);
	io->cfg = *cfg;
	io->have_estop = e->present;
	px_debounce_init(&io->db, (estop_physical != 0) ^ (e->active_low != 0),
			 e->debounce_ns);
	for (r = PX_GPIO_ENABLE; r < PX_GPIO__ROLES; r++)
		io->out[r] = cfg->line[r].initial != 0;
}

void px__dio_edge(struct px__dio *io, int physical, int64_t t_ns)
{
	int logical = (physical != 0) ^
		      (io->cfg.line[PX_GPIO_ESTOP].active_low != 0);
	px_debounce_feed(&io->db, logical, t_ns);
}

int px__dio_estop(struct px_dev *d, struct px__dio *io, int64_t now_ns,
		  int gone, int *pressed)
{
	int p;
	struct px_loop *l;
	if (!io->have_estop)
		return PX_E_UNSUPPORTED;
	p = gone ? 1 : px_debounce_get(&io->db, now_ns);
	if (p && !io->pressed)
		px_dev_record(d, PX_DEV_ERR_ESTOP, PX_E_STATE, 0,
			      io->cfg.line[PX_GPIO_ESTOP].offset, NULL,
			      gone ? "e-stop line unreadable: treated as pressed"
				   : "e-stop pressed",
			      now_ns);
	io->pressed = p;
	*pressed = p;
	l = px__dev_loop(d);
	if (p && l)
		px_loop_trip_estop(l); /* latched: see px_loop.h */
	return gone ? PX_E_NODEV : PX_OK;
}

int px__dio_physical(const struct px__dio *io, int role, int logical)
{
	return (logical != 0) ^ (io->cfg.line[role].active_low != 0);
}

/* ---- simulated lines ----------------------------------------------------- */

#define SIMQ 64

struct gsim {
	struct px__dio io;
	struct px_sim_fault faults[PX_SIM_MAX_FAULTS];
	size_t n_faults;
	int64_t ev_t[SIMQ];
	int ev_v[SIMQ];
	unsigned ev_head, ev_n;
	int physical_in;      /* the line's true level */
	int phys_out[PX_GPIO__ROLES];
	int in_estop_fault;
	int unplugged;
	/* edge events as the reader sees them (faults drop, delay,
	 * duplicate, corrupt act on them) */
	int delivered;        /* level of the last event handed on */
	int64_t resync_ns;    /* last level check that corrected it */
	int64_t dl_t[SIMQ], dl_due[SIMQ];
	int dl_v[SIMQ];
	unsigned dl_head, dl_n;
	uint64_t rng;
};

static double gunit(struct gsim *g)
{
	uint64_t x = g->rng;
	x ^= x >> 12;
	x ^= x << 25;
	x ^= x >> 27;
	g->rng = x;
	return (double)((x * 2685821657736338717ull) >> 11) *
	       (1.0 / 9007199254740992.0);
}

/* The fault of kind in effect at t; roll: also draw its probability. */
static const struct px_sim_fault *gfault_p(struct gsim *g, int kind, int64_t t,
					   int roll)
{
	size_t i;
	for (i = 0; i < g->n_faults; i++) {
		const struct px_sim_fault *f = &g->faults[i];
		double p;
		if (f->kind != kind || t < f->start_ns ||
		    t - f->start_ns >= f->duration_ns)
			continue;
		p = f->probability > 0 ? f->probability : 1.0;
		if (!roll || p >= 1.0 || gunit(g) < p)
			return f;
	}
	return NULL;
}

static const struct px_sim_fault *gfault(struct gsim *g, int kind, int64_t t)
{
	return gfault_p(g, kind, t, 0);
}

/* An edge event reaches the reader. The same level again is a repeated
 * event: harmless, counted, unless it is a late one the level check
 * already made up for. */
static void gfeed(struct px_dev *d, struct gsim *g, int v, int64_t t)
{
	if (v == g->delivered) {
		if (t > g->resync_ns)
			px_dev_record(d, PX_DEV_ERR_DUPLICATE, PX_E_CORRUPT, 0,
				      g->io.cfg.line[PX_GPIO_ESTOP].offset, NULL,
				      "e-stop edge event repeated", t);
		return;
	}
	g->delivered = v;
	px__dio_edge(&g->io, v, t);
}

/* A scripted level change at t (the line changed then): what the edge
 * event suffers. */
static void gevent(struct px_dev *d, struct gsim *g, int v, int64_t t)
{
	const struct px_sim_fault *f;
	if (gfault_p(g, PX_SIM_FAULT_DROP, t, 1))
		return; /* lost: the level check finds it */
	if (gfault_p(g, PX_SIM_FAULT_CORRUPT, t, 1)) {
		/* the event reports the other edge */
		gfeed(d, g, !v, t);
		return;
	}
	if ((f = gfault_p(g, PX_SIM_FAULT_DELAY, t, 1)) || g->dl_n) {
		unsigned k = (g->dl_head + g->dl_n) % SIMQ;
		if (g->dl_n == SIMQ)
			return;
		g->dl_t[k] = t;
		g->dl_v[k] = v;
		g->dl_due[k] = t + (f ? f->delay_ns : 0);
		g->dl_n++;
		return;
	}
	gfeed(d, g, v, t);
	if (gfault_p(g, PX_SIM_FAULT_DUPLICATE, t, 1))
		gfeed(d, g, v, t);
}

static void gsim_advance(struct px_dev *d, struct gsim *g, int64_t now)
{
	const struct px_sim_fault *f;
	int pressed_phys = !g->io.cfg.line[PX_GPIO_ESTOP].active_low;
	while (g->ev_n && g->ev_t[g->ev_head] <= now) {
		int64_t t = g->ev_t[g->ev_head];
		int v = g->ev_v[g->ev_head];
		g->ev_head = (g->ev_head + 1) % SIMQ;
		g->ev_n--;
		if (gfault(g, PX_SIM_FAULT_STUCK, t))
			continue; /* the contact is welded: the line holds */
		g->physical_in = v;
		if (!g->in_estop_fault)
			gevent(d, g, v, t);
	}
	while (g->dl_n && g->dl_due[g->dl_head] <= now) {
		if (!g->in_estop_fault)
			gfeed(d, g, g->dl_v[g->dl_head], g->dl_t[g->dl_head]);
		g->dl_head = (g->dl_head + 1) % SIMQ;
		g->dl_n--;
	}
	f = gfault(g, PX_SIM_FAULT_ESTOP, now);
	if (f && !g->in_estop_fault) {
		/* a real contact bounces: two short glitches, then held */
		int64_t t0 = f->start_ns;
		g->in_estop_fault = 1;
		px__dio_edge(&g->io, pressed_phys, t0);
		px__dio_edge(&g->io, !pressed_phys, t0 + 200000);
		px__dio_edge(&g->io, pressed_phys, t0 + 400000);
	} else if (!f && g->in_estop_fault) {
		g->in_estop_fault = 0;
		px__dio_edge(&g->io, g->physical_in,
			     now > 0 ? now : 0);
		g->delivered = g->physical_in;
		g->resync_ns = now;
	}
	if (gfault(g, PX_SIM_FAULT_UNPLUG, now)) {
		if (!g->unplugged) {
			g->unplugged = 1;
			px_dev_set_state(d, PX_DEV_STATE_UNPLUGGED, now);
		}
	} else if (g->unplugged) {
		g->unplugged = 0;
		px_dev_set_state(d, PX_DEV_STATE_RUNNING, now);
	}
}

static int gsim_estop(struct px_dev *d, int64_t now, int *pressed)
{
	struct gsim *g = px_dev_impl(d);
	gsim_advance(d, g, now);
	/* Level check: the line is read besides its edge events, so a lost,
	 * late or wrong event is corrected within a cycle (a press is
	 * never missed for longer than that). */
	if (!g->in_estop_fault && !g->unplugged &&
	    g->delivered != g->physical_in) {
		px_dev_record(d, PX_DEV_ERR_IO, PX_E_CORRUPT, 0,
			      g->io.cfg.line[PX_GPIO_ESTOP].offset, NULL,
			      "e-stop line level differs from its edge events "
			      "(event lost, late or wrong): resynchronised",
			      now);
		g->delivered = g->physical_in;
		g->resync_ns = now;
		px__dio_edge(&g->io, g->physical_in, now);
	}
	return px__dio_estop(d, &g->io, now, g->unplugged, pressed);
}

static int gsim_write(struct px_dev *d, int which, int value, int64_t now)
{
	struct gsim *g = px_dev_impl(d);
	int role = which == PX_DIO_ENABLE ? PX_GPIO_ENABLE : PX_GPIO_TIMING;
	gsim_advance(d, g, now);
	if (!g->io.cfg.line[role].present)
		return PX_E_UNSUPPORTED;
	if (g->unplugged)
		return PX_E_NODEV;
	g->io.out[role] = value;
	if (gfault(g, PX_SIM_FAULT_STUCK, now)) {
		/* a welded relay: the output keeps its level; the feedback
		 * (readback) shows it */
		if (g->phys_out[role] !=
		    px__dio_physical(&g->io, role, value)) {
			px_dev_record(d, PX_DEV_ERR_IO, PX_E_IO, 0,
				      g->io.cfg.line[role].offset, NULL,
				      role == PX_GPIO_ENABLE
					      ? "enable output stuck: readback "
						"differs from the command"
					      : "timing output stuck: readback "
						"differs from the command",
				      now);
			return PX_E_IO;
		}
		return PX_OK;
	}
	g->phys_out[role] = px__dio_physical(&g->io, role, value);
	return PX_OK;
}

static const struct px_dev_ops gsim_ops = {
	.backend = "sim-gpio",
	.caps = PX_DEV_CAP_DIO,
	.estop = gsim_estop,
	.dio_write = gsim_write,
};

int px_gpio_sim_create(const struct px_dev_config *dcfg,
		       const struct px_gpio_config *cfg,
		       const struct px_sim_fault *faults, size_t n_faults,
		       struct px_dev **out, char *msg, size_t cap)
{
	struct gsim *g;
	size_t i;
	int rc, r;
	const char *nm = dcfg && dcfg->name ? dcfg->name : "gpio";
	if (msg && cap)
		msg[0] = 0;
	if (out)
		*out = NULL;
	if (!dcfg || !cfg || !out || n_faults > PX_SIM_MAX_FAULTS ||
	    (n_faults && !faults)) {
		if (msg)
			snprintf(msg, cap, "%s: bad arguments (at most %d faults)",
				 nm, PX_SIM_MAX_FAULTS);
		return PX_E_INVAL;
	}
	for (i = 0; i < n_faults; i++) {
		int k = faults[i].kind;
		if (k <= PX_SIM_FAULT_NONE || k >= PX_SIM_FAULT__COUNT ||
		    k == PX_SIM_FAULT_NAN || k == PX_SIM_FAULT_BUSOFF ||
		    faults[i].duration_ns <= 0 ||
		    (k == PX_SIM_FAULT_DELAY && faults[i].delay_ns <= 0)) {
			if (msg)
				snprintf(msg, cap, "%s: faults[%zu] (%s): "
					 "simulated GPIO takes drop, delay "
					 "(delay_ns > 0), duplicate, corrupt, "
					 "stuck, unplug and estop, with "
					 "duration_ns > 0 (nan and bus_off do "
					 "not apply to digital lines)",
					 nm, i,
					 px_sim_fault_name(k) ? px_sim_fault_name(k)
							      : "?");
			return PX_E_INVAL;
		}
	}
	if (cfg->line[PX_GPIO_ESTOP].debounce_ns < 0) {
		if (msg)
			snprintf(msg, cap, "%s: debounce_ns must be >= 0", nm);
		return PX_E_INVAL;
	}
	rc = px_dev_create(&gsim_ops, dcfg, sizeof *g, out);
	if (rc != PX_OK)
		return rc;
	g = px_dev_impl(*out);
	/* at rest: the e-stop line at its released level */
	g->physical_in = cfg->line[PX_GPIO_ESTOP].active_low ? 1 : 0;
	g->delivered = g->physical_in;
	g->resync_ns = INT64_MIN;
	g->rng = 0x9E3779B97F4A7C15ull;
	px__dio_init(&g->io, cfg, g->physical_in, 0);
	g->io.cfg.chip = NULL;
	for (r = PX_GPIO_ENABLE; r < PX_GPIO__ROLES; r++)
		g->phys_out[r] = cfg->line[r].present
					 ? px__dio_physical(&g->io, r,
							    g->io.out[r])
					 : -1;
	if (n_faults)
		memcpy(g->faults, faults, n_faults * sizeof *faults);
	g->n_faults = n_faults;
	return PX_OK;
}

int px_gpio_sim_drive(struct px_dev *d, int role, int physical, int64_t t_ns)
{
	struct gsim *g;
	if (!d || px_dev_ops(d) != &gsim_ops || role != PX_GPIO_ESTOP)
		return PX_E_INVAL;
	g = px_dev_impl(d);
	if (g->ev_n >= SIMQ)
		return PX_E_NOSPC;
	g->ev_t[(g->ev_head + g->ev_n) % SIMQ] = t_ns;
	g->ev_v[(g->ev_head + g->ev_n) % SIMQ] = physical != 0;
	g->ev_n++;
	return PX_OK;
}

int px_gpio_sim_output(struct px_dev *d, int role)
{
	struct gsim *g;
	if (!d || px_dev_ops(d) != &gsim_ops || role <= PX_GPIO_ESTOP ||
	    role >= PX_GPIO__ROLES)
		return -1;
	g = px_dev_impl(d);
	return g->phys_out[role];
}
