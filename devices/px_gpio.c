/* Digital I/O: debounce, the shared e-stop/enable logic, and simulated
 * GPIO lines. */
#include <stdio.h>
#include <string.h>

#include "internal.h"
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
		px_loop_trip(l);
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
	int physical_in;
	int phys_out[PX_GPIO__ROLES];
	int in_estop_fault;
	int unplugged;
};

static const struct px_sim_fault *gfault(struct gsim *g, int kind, int64_t t)
{
	size_t i;
	for (i = 0; i < g->n_faults; i++)
		if (g->faults[i].kind == kind && t >= g->faults[i].start_ns &&
		    t < g->faults[i].start_ns + g->faults[i].duration_ns)
			return &g->faults[i];
	return NULL;
}

static void gsim_advance(struct px_dev *d, struct gsim *g, int64_t now)
{
	const struct px_sim_fault *f;
	int pressed_phys = !g->io.cfg.line[PX_GPIO_ESTOP].active_low;
	while (g->ev_n && g->ev_t[g->ev_head] <= now) {
		g->physical_in = g->ev_v[g->ev_head];
		if (!g->in_estop_fault)
			px__dio_edge(&g->io, g->physical_in,
				     g->ev_t[g->ev_head]);
		g->ev_head = (g->ev_head + 1) % SIMQ;
		g->ev_n--;
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
	for (i = 0; i < n_faults; i++)
		if ((faults[i].kind != PX_SIM_FAULT_ESTOP &&
		     faults[i].kind != PX_SIM_FAULT_UNPLUG) ||
		    faults[i].duration_ns <= 0) {
			if (msg)
				snprintf(msg, cap, "%s: faults[%zu]: simulated "
					 "GPIO takes estop and unplug faults "
					 "with duration_ns > 0", nm, i);
			return PX_E_INVAL;
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
