/* Opening the devices of a configuration (px_devcfg.h). */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "px_devcfg.h"
#include "px_gpio.h"
#include "px_hid.h"
#include "px_sim.h"
#include "px_usb.h"

struct px_devcfg {
	struct px_dev *dev;
	struct px_canopen *co;
	struct px_can_bus *co_bus;
	struct px_can_sim *sim_bus;
	int own_sim_bus;
	struct px_sim_csv *csv;
	struct px_codec_map map;
	struct px_codec_field *inputs, *outputs;
	struct px_codec_buttons *buttons;
	struct px_can_signal *signals;
	struct px_canopen_drive_cfg drives[PX_CANOPEN_MAX_DRIVES];
	size_t n_drives;
	struct px_canopen_pdo_map pdo;
	char notes[256];
	int co_safe; /* the master's drives confirmed disabled */
};

/* Config fault windows as px_sim faults, moved onto the loop clock;
 * those of a drive (node_id) are the simulated arm's, not here. */
static size_t conv_faults(const struct px_config_fault *f, size_t n,
			  const struct px_devcfg_options *opt,
			  struct px_sim_fault *o)
{
	size_t i, k = 0;
	int64_t t0 = opt ? opt->clock0_ns : 0;
	for (i = 0; i < n && k < PX_SIM_MAX_FAULTS; i++) {
		if (f[i].has_node_id)
			continue;
		o[k].kind = f[i].kind + 1;
		o[k].start_ns = t0 + f[i].start_ns;
		o[k].duration_ns = f[i].duration_ns;
		o[k].probability = f[i].probability;
		o[k].delay_ns = f[i].delay_ns;
		k++;
	}
	return k;
}

/* The config's windows (conv_faults) plus the options' (already on the
 * loop clock). Returns the count or PX_E_NOSPC. */
static int sim_faults(const struct px_config_fault *f, size_t n,
		      const struct px_devcfg_options *opt,
		      struct px_sim_fault *o)
{
	size_t k = conv_faults(f, n, opt, o), i;
	size_t extra = opt && opt->faults ? opt->n_faults : 0;
	if (k + extra > PX_SIM_MAX_FAULTS)
		return PX_E_NOSPC;
	for (i = 0; i < extra; i++)
		o[k++] = opt->faults[i];
	return (int)k;
}

int px_devcfg_arm_faults(const struct px_config *cfg,
			 const struct px_config_device *dc, int64_t clock0_ns,
			 struct px_sim_fault *faults, size_t cap)
{
	const struct px_config_socketcan *c;
	size_t i, j;
	int n = 0;
	if (!cfg || !dc || (!faults && cap) || dc < cfg->devices ||
	    dc >= cfg->devices + cfg->n_devices)
		return PX_E_INVAL;
	if (dc->backend != PX_CONFIG_BACKEND_SOCKETCAN)
		return 0;
	c = &dc->socketcan;
	for (i = 0; i < c->n_faults; i++) {
		const struct px_config_fault *f = &c->faults[i];
		if (!f->has_node_id)
			continue;
		for (j = 0; j < c->canopen.n_drives &&
			    c->canopen.drives[j].node_id != f->node_id;
		     j++)
			;
		if (j == c->canopen.n_drives)
			return PX_E_INVAL;
		if ((size_t)n == cap)
			return PX_E_NOSPC;
		memset(&faults[n], 0, sizeof(faults[n]));
		faults[n].kind = f->kind + 1;
		faults[n].start_ns = clock0_ns + f->start_ns;
		faults[n].duration_ns = f->duration_ns;
		faults[n].probability = 1.0;
		/* px_canopen_sim takes the drive's index here */
		faults[n].delay_ns = (int64_t)j;
		n++;
	}
	return n;
}

/* Config PDO entries over the default layout; a failed check names the
 * entry ("socketcan.canopen.tpdo1[1]"). */
static int pdo_from_cfg(struct px_devcfg *h, const struct px_config_canopen *c,
			char *key, size_t kcap, char *why, size_t wcap)
{
	const struct px_config_pdo_entry *src[3] = {c->rpdo, c->tpdo1,
						    c->tpdo2};
	const size_t n[3] = {c->n_rpdo, c->n_tpdo1, c->n_tpdo2};
	struct px_canopen_pdo *dst[3] = {&h->pdo.rpdo, &h->pdo.tpdo1,
					 &h->pdo.tpdo2};
	size_t k, i;
	const char *p;
	px_canopen_pdo_map_default(&h->pdo);
	for (k = 0; k < 3; k++) {
		if (!n[k])
			continue;
		if (n[k] > PX_CANOPEN_MAX_MAP) {
			snprintf(key, kcap, "socketcan.canopen");
			snprintf(why, wcap, "at most %d PDO entries",
				 PX_CANOPEN_MAX_MAP);
			return PX_E_INVAL;
		}
		memset(dst[k], 0, sizeof(*dst[k]));
		for (i = 0; i < n[k]; i++) {
			dst[k]->e[i].index = (uint16_t)src[k][i].index;
			dst[k]->e[i].subindex = (uint8_t)src[k][i].subindex;
			dst[k]->e[i].bits = (uint8_t)src[k][i].bits;
		}
		dst[k]->n = n[k];
	}
	if (px_canopen_pdo_map_check(&h->pdo, why, wcap) == PX_OK)
		return PX_OK;
	/* why starts with "rpdo[2]: ..." or "tpdo1/tpdo2: ..." */
	p = strchr(why, ':');
	snprintf(key, kcap, "socketcan.canopen.%.*s",
		 p ? (int)(p - why) : 0, why);
	return PX_E_INVAL;
}

static const char *backend_name(int b)
{
	const char *const *n = px_config_backend_names();
	return (b >= 0 && b <= PX_CONFIG_BACKEND_GPIOD) ? n[b] : "?";
}

/* "device 'name' (backend, devices[i].key): what" */
static int fail(char *msg, size_t cap, const struct px_config *cfg,
		const struct px_config_device *dc, const char *key, int rc,
		const char *fmt, ...) __attribute__((format(printf, 7, 8)));
static int fail(char *msg, size_t cap, const struct px_config *cfg,
		const struct px_config_device *dc, const char *key, int rc,
		const char *fmt, ...)
{
	char what[512];
	va_list ap;
	size_t idx = (size_t)(dc - cfg->devices);
	if (!msg || !cap)
		return rc;
	va_start(ap, fmt);
	vsnprintf(what, sizeof(what), fmt, ap);
	va_end(ap);
	snprintf(msg, cap, "device '%s' (%s, devices[%zu]%s%s): %s", dc->name,
		 backend_name(dc->backend), idx, key && *key ? "." : "",
		 key ? key : "", what);
	return rc;
}

static int conv_field(const struct px_config_field *f,
		      struct px_codec_field *o)
{
	if (f->report_id < 0 || f->report_id > 255 || f->byte_offset < 0 ||
	    f->byte_offset > 65535 || f->bit_offset < 0 || f->bit_offset > 7 ||
	    f->bit_width < 1 || f->bit_width > 64)
		return PX_E_INVAL;
	memset(o, 0, sizeof(*o));
	o->report_id = (int)f->report_id;
	o->byte_offset = (uint32_t)f->byte_offset;
	o->bit_offset = (uint8_t)f->bit_offset;
	o->bit_width = (uint8_t)f->bit_width;
	o->is_signed = f->is_signed ? 1 : 0;
	o->byte_order = f->byte_order == PX_CONFIG_BIG_ENDIAN ? PX_BIG_ENDIAN
							       : PX_LITTLE_ENDIAN;
	o->scale = f->scale;
	o->offset = f->offset;
	o->axis = f->axis;
	o->max_abs = f->max_abs;
	return PX_OK;
}

/* Copy a config codec into h->map. Returns PX_OK or PX_E_INVAL with
 * *bad = "inputs[2]" etc. (static part + index in *bad_i). */
static int conv_codec(struct px_devcfg *h, const struct px_config_codec *c,
		      const char **bad, size_t *bad_i)
{
	size_t i;
	h->inputs = calloc(c->n_inputs ? c->n_inputs : 1, sizeof(*h->inputs));
	h->outputs = calloc(c->n_outputs ? c->n_outputs : 1,
			    sizeof(*h->outputs));
	h->buttons = calloc(c->n_buttons ? c->n_buttons : 1,
			    sizeof(*h->buttons));
	if (!h->inputs || !h->outputs || !h->buttons)
		return PX_E_NOMEM;
	for (i = 0; i < c->n_inputs; i++)
		if (conv_field(&c->inputs[i], &h->inputs[i]) != PX_OK) {
			*bad = "inputs";
			*bad_i = i;
			return PX_E_INVAL;
		}
	for (i = 0; i < c->n_outputs; i++)
		if (conv_field(&c->outputs[i], &h->outputs[i]) != PX_OK) {
			*bad = "outputs";
			*bad_i = i;
			return PX_E_INVAL;
		}
	for (i = 0; i < c->n_buttons; i++) {
		const struct px_config_buttons *b = &c->buttons[i];
		if (b->report_id < 0 || b->report_id > 255 ||
		    b->byte_offset < 0 || b->byte_offset > 65535 ||
		    b->first_bit < 0 || b->first_bit > 7 || b->count < 1 ||
		    b->count > 64 || b->first_button < 0 ||
		    b->first_button + b->count > 64) {
			*bad = "buttons";
			*bad_i = i;
			return PX_E_INVAL;
		}
		h->buttons[i].report_id = (int)b->report_id;
		h->buttons[i].byte_offset = (uint32_t)b->byte_offset;
		h->buttons[i].first_bit = (uint8_t)b->first_bit;
		h->buttons[i].count = (uint8_t)b->count;
		h->buttons[i].first_button = (uint8_t)b->first_button;
	}
	h->map.inputs = h->inputs;
	h->map.n_inputs = c->n_inputs;
	h->map.outputs = h->outputs;
	h->map.n_outputs = c->n_outputs;
	h->map.buttons = h->buttons;
	h->map.n_buttons = c->n_buttons;
	h->map.output_report_id = (int)c->output_report_id;
	h->map.output_report_len = c->output_report_len > 0
					   ? (size_t)c->output_report_len
					   : 0;
	return PX_OK;
}

static int open_codec(struct px_devcfg *h, const struct px_config *cfg,
		      const struct px_config_device *dc,
		      const struct px_config_codec *c, const char *sect,
		      char *msg, size_t cap)
{
	const char *bad = NULL;
	size_t bi = 0;
	char key[64];
	int rc = conv_codec(h, c, &bad, &bi);
	if (rc == PX_E_NOMEM)
		return fail(msg, cap, cfg, dc, sect, rc, "out of memory");
	if (rc != PX_OK) {
		snprintf(key, sizeof(key), "%s.%s[%zu]", sect, bad, bi);
		return fail(msg, cap, cfg, dc, key, rc,
			    "field out of the codec's range (report id "
			    "0..255, byte offset 0..65535, bit offset 0..7, "
			    "width 1..64, buttons 1..64)");
	}
	return PX_OK;
}

/* ---- sim ------------------------------------------------------------- */

static int open_sim_haptic(struct px_devcfg *h, const struct px_config *cfg,
			   const struct px_config_device *dc,
			   const struct px_devcfg_options *opt,
			   struct px_dev_config *dcfg, char *msg, size_t cap)
{
	const struct px_config_sim *s = &dc->sim;
	struct px_sim_haptic_config hc;
	struct px_sim_fault faults[PX_SIM_MAX_FAULTS];
	struct px_sim_sine sines[PX_SIM_MAX_SINES];
	char why[256];
	size_t i;
	int rc;
	px_sim_haptic_config_default(&hc);
	hc.mass_kg = s->mass_kg;
	hc.damping_n_s_per_m = s->damping_n_s_per_m;
	hc.hand_stiffness_n_per_m = s->hand_stiffness_n_per_m;
	hc.hand_damping_n_s_per_m = s->hand_damping_n_s_per_m;
	hc.report_period_ns = s->report_period_ns;
	hc.seed = (uint64_t)s->seed;
	hc.position_noise_m = s->position_noise_m;
	hc.follow_hand = s->kind == PX_CONFIG_SIM_POSE;
	for (i = 0; i < 3; i++)
		hc.traj.center_m[i] = s->trajectory.center_m[i];
	switch (s->trajectory.kind) {
	case PX_CONFIG_TRAJ_SINES:
		if (s->trajectory.n_sines > PX_SIM_MAX_SINES)
			return fail(msg, cap, cfg, dc, "sim.trajectory.sines",
				    PX_E_INVAL, "%zu sines; at most %d",
				    s->trajectory.n_sines, PX_SIM_MAX_SINES);
		for (i = 0; i < s->trajectory.n_sines; i++) {
			const struct px_config_sine *c = &s->trajectory.sines[i];
			sines[i].axis = c->axis;
			sines[i].amplitude_m = c->amplitude_m;
			sines[i].frequency_hz = c->frequency_hz;
			sines[i].phase_rad = c->phase_rad;
		}
		hc.traj.kind = PX_SIM_TRAJ_SINES;
		hc.traj.sines = sines;
		hc.traj.n_sines = s->trajectory.n_sines;
		break;
	case PX_CONFIG_TRAJ_CSV:
		rc = px_sim_csv_load(s->trajectory.file, &h->csv, why,
				     sizeof(why));
		if (rc != PX_OK)
			return fail(msg, cap, cfg, dc, "sim.trajectory.file", rc,
				    "%s", why);
		hc.traj.kind = PX_SIM_TRAJ_CSV;
		hc.traj.csv = h->csv;
		hc.traj.repeat = s->trajectory.repeat;
		break;
	default:
		hc.traj.kind = PX_SIM_TRAJ_HOLD;
		break;
	}
	if (s->codec.n_inputs || s->codec.n_outputs || s->codec.n_buttons) {
		rc = open_codec(h, cfg, dc, &s->codec, "sim", msg, cap);
		if (rc != PX_OK)
			return rc;
		dcfg->codec = &h->map;
	}
	rc = sim_faults(s->faults, s->n_faults, opt, faults);
	if (rc < 0)
		return fail(msg, cap, cfg, dc, "sim.faults", rc,
			    "more than %d fault windows (config and campaign)",
			    PX_SIM_MAX_FAULTS);
	hc.n_faults = (size_t)rc;
	hc.faults = faults;
	rc = px_sim_haptic_create(dcfg, &hc, &h->dev, why, sizeof(why));
	if (rc != PX_OK)
		return fail(msg, cap, cfg, dc, "sim", rc, "%s", why);
	return PX_OK;
}

/* Role of a digital line (see px_devcfg.h). */
static int line_role(const struct px_config *cfg,
		     const struct px_config_device *dc,
		     const struct px_config_gpio_line *l)
{
	const struct px_config_line_ref *e = &cfg->safety.estop;
	const struct px_config_line_ref *en = &cfg->safety.enable;
	if (e->present && !strcmp(e->device, dc->name) &&
	    !strcmp(e->line, l->name))
		return PX_GPIO_ESTOP;
	if (en->present && !strcmp(en->device, dc->name) &&
	    !strcmp(en->line, l->name))
		return PX_GPIO_ENABLE;
	if (!strcmp(l->name, "estop"))
		return PX_GPIO_ESTOP;
	if (!strcmp(l->name, "enable"))
		return PX_GPIO_ENABLE;
	if (!strcmp(l->name, "timing"))
		return PX_GPIO_TIMING;
	return -1;
}

static int gpio_cfg(const struct px_config *cfg,
		    const struct px_config_device *dc, const char *sect,
		    const struct px_config_gpio_line *lines, size_t n,
		    struct px_gpio_config *gc, char *msg, size_t cap)
{
	static const char *const role_names[] = {"e-stop", "enable", "timing"};
	size_t i;
	char key[64];
	memset(gc, 0, sizeof(*gc));
	for (i = 0; i < n; i++) {
		const struct px_config_gpio_line *l = &lines[i];
		int role = line_role(cfg, dc, l);
		struct px_gpio_line *g;
		snprintf(key, sizeof(key), "%s.lines[%zu]", sect, i);
		if (role < 0)
			return fail(msg, cap, cfg, dc, key, PX_E_INVAL,
				    "line '%s' has no role: name it estop "
				    "(input), enable or timing (outputs), or "
				    "refer to it from safety.estop / "
				    "safety.enable",
				    l->name);
		if ((role == PX_GPIO_ESTOP) !=
		    (l->direction == PX_CONFIG_GPIO_INPUT))
			return fail(msg, cap, cfg, dc, key, PX_E_INVAL,
				    "line '%s' is the %s line, which must be "
				    "an %s",
				    l->name, role_names[role],
				    role == PX_GPIO_ESTOP ? "input" : "output");
		g = &gc->line[role];
		if (g->present)
			return fail(msg, cap, cfg, dc, key, PX_E_INVAL,
				    "line '%s': a second %s line", l->name,
				    role_names[role]);
		g->present = 1;
		g->line_name = l->line_name;
		g->offset = l->has_offset ? (unsigned)l->offset : 0;
		g->active_low = l->active_low;
		g->debounce_ns = l->debounce_ns;
		g->initial = l->initial;
	}
	return PX_OK;
}

/* ---- CAN ------------------------------------------------------------- */

static int can_bus_open_bare(struct px_devcfg *h, const struct px_config *cfg,
			     const struct px_config_device *dc,
			     const struct px_devcfg_options *opt,
			     struct px_can_bus **bus, char *msg, size_t cap)
{
	const struct px_config_socketcan *c = &dc->socketcan;
	char why[512], peer[128];
	int rc, e = 0;
	size_t i;
	if (c->transport == PX_CONFIG_CAN_SIM) {
		if (!h->sim_bus) {
			if (opt && opt->can_sim) {
				h->sim_bus = opt->can_sim;
			} else {
				struct px_can_sim_config sc;
				px_can_sim_config_default(&sc);
				rc = px_can_sim_create(&sc, &h->sim_bus);
				if (rc != PX_OK)
					return fail(msg, cap, cfg, dc,
						    "socketcan.transport", rc,
						    "simulated bus: %s",
						    px_strerror(rc));
				h->own_sim_bus = 1;
			}
		}
		rc = px_can_sim_endpoint(h->sim_bus, bus);
		if (rc != PX_OK)
			return fail(msg, cap, cfg, dc, "socketcan.transport", rc,
				    "simulated bus '%s': no endpoint: %s",
				    c->interface, px_strerror(rc));
		return PX_OK;
	}
	if (c->transport == PX_CONFIG_CAN_UNIX) {
		snprintf(peer, sizeof(peer), "%s.peer", c->socket_path);
		rc = px_can_unix_open(c->socket_path, peer, bus, why,
				      sizeof(why));
		if (rc != PX_OK)
			return fail(msg, cap, cfg, dc, "socketcan.socket_path",
				    rc, "%s", why);
		return PX_OK;
	}
	{
		struct px_can_raw_config rc_;
		struct px_can_filter f[64];
		memset(&rc_, 0, sizeof(rc_));
		for (i = 0; i < c->n_filters && i < 64; i++) {
			f[i].id = (uint32_t)c->filters[i].id;
			f[i].mask = (uint32_t)c->filters[i].mask;
			f[i].extended = c->filters[i].extended;
		}
		rc_.interface = c->interface;
		rc_.fd = c->fd;
		rc_.filters = c->n_filters ? f : NULL;
		rc_.n_filters = i;
		rc_.error_frames = 1;
		rc = px_can_raw_open(&rc_, bus, &e, why, sizeof(why));
		if (rc != PX_OK)
			return fail(msg, cap, cfg, dc, "socketcan.interface", rc,
				    "%s", why);
	}
	return PX_OK;
}

/* The bus, wrapped in the config's bus faults when it has any (drive
 * faults, with node_id, are the simulated arm's). */
static int can_bus_open(struct px_devcfg *h, const struct px_config *cfg,
			const struct px_config_device *dc,
			const struct px_devcfg_options *opt,
			struct px_can_bus **bus, char *msg, size_t cap)
{
	const struct px_config_socketcan *c = &dc->socketcan;
	struct px_sim_fault f[PX_SIM_MAX_FAULTS];
	struct px_can_bus *in = NULL;
	char why[512];
	size_t n = conv_faults(c->faults, c->n_faults, opt, f);
	int rc = can_bus_open_bare(h, cfg, dc, opt, n ? &in : bus, msg, cap);
	if (rc != PX_OK || !n)
		return rc;
	rc = px_can_fault_open(in, f, n, 1 + (uint64_t)(dc - cfg->devices), bus,
			       why, sizeof(why));
	if (rc != PX_OK) {
		px_can_bus_close(in);
		return fail(msg, cap, cfg, dc, "socketcan.faults", rc, "%s", why);
	}
	return PX_OK;
}

static void drives_from_cfg(struct px_devcfg *h,
			    const struct px_config_canopen *c)
{
	size_t i;
	for (i = 0; i < c->n_drives && i < PX_CANOPEN_MAX_DRIVES; i++) {
		const struct px_config_canopen_drive *d = &c->drives[i];
		struct px_canopen_drive_cfg *o = &h->drives[i];
		o->node_id = (uint8_t)d->node_id;
		o->mode = d->mode == PX_CONFIG_CIA402_CSV   ? PX_CIA402_CSV
			  : d->mode == PX_CONFIG_CIA402_CST ? PX_CIA402_CST
							    : PX_CIA402_CSP;
		o->joint = (int)d->joint;
		o->counts_per_unit =
			d->has_counts_per_unit ? d->counts_per_unit : 1.0;
		o->rated_torque_n_m = d->rated_torque_n_m;
	}
	h->n_drives = i;
}

int px_devcfg_canopen_layout(const struct px_config *cfg,
			     const struct px_config_device *dc,
			     struct px_canopen_drive_cfg *drives, size_t cap,
			     size_t *n_drives, struct px_canopen_pdo_map *pdo,
			     char *msg, size_t mcap)
{
	struct px_devcfg *h;
	char why[256], key[64];
	int rc;
	if (msg && mcap)
		msg[0] = '\0';
	if (!cfg || !dc || !drives || !n_drives || !pdo ||
	    dc < cfg->devices || dc >= cfg->devices + cfg->n_devices)
		return PX_E_INVAL;
	if (dc->backend != PX_CONFIG_BACKEND_SOCKETCAN ||
	    !dc->socketcan.canopen.present ||
	    dc->socketcan.canopen.n_drives == 0)
		return fail(msg, mcap, cfg, dc, "socketcan.canopen",
			    PX_E_NOTFOUND, "no CANopen drives configured");
	if (dc->socketcan.canopen.n_drives > PX_CANOPEN_MAX_DRIVES ||
	    dc->socketcan.canopen.n_drives > cap)
		return fail(msg, mcap, cfg, dc, "socketcan.canopen.drives",
			    PX_E_NOSPC, "%zu drives; room for %zu",
			    dc->socketcan.canopen.n_drives,
			    cap < PX_CANOPEN_MAX_DRIVES ? cap
							: PX_CANOPEN_MAX_DRIVES);
	h = calloc(1, sizeof(*h));
	if (!h)
		return PX_E_NOMEM;
	drives_from_cfg(h, &dc->socketcan.canopen);
	rc = pdo_from_cfg(h, &dc->socketcan.canopen, key, sizeof(key), why,
			  sizeof(why));
	if (rc != PX_OK) {
		fail(msg, mcap, cfg, dc, key, rc, "%s", why);
	} else {
		memcpy(drives, h->drives, h->n_drives * sizeof(*drives));
		*n_drives = h->n_drives;
		*pdo = h->pdo;
	}
	free(h);
	return rc;
}

static int open_can(struct px_devcfg *h, const struct px_config *cfg,
		    const struct px_config_device *dc,
		    const struct px_devcfg_options *opt,
		    struct px_dev_config *dcfg, char *msg, size_t cap)
{
	const struct px_config_socketcan *c = &dc->socketcan;
	struct px_can_bus *bus = NULL;
	char why[256], key[64];
	size_t i;
	int rc;
	int has_co = c->canopen.present && c->canopen.n_drives > 0;
	int chk = opt && opt->check_only;
	if (c->n_signals == 0 && !has_co)
		return fail(msg, cap, cfg, dc, "socketcan", PX_E_INVAL,
			    "neither signals nor canopen drives: nothing "
			    "to open");
	if (c->transport == PX_CONFIG_CAN_UNIX && c->n_signals && has_co)
		return fail(msg, cap, cfg, dc, "socketcan.signals", PX_E_INVAL,
			    "transport 'unix' has one socket: give signals "
			    "or canopen, not both");
	if (!chk && c->transport == PX_CONFIG_CAN_KERNEL && c->bitrate > 0) {
		int e = 0;
		rc = px_can_iface_set_bitrate(c->interface, (uint32_t)c->bitrate,
					      (uint32_t)c->restart_ms, &e, why,
					      sizeof(why));
		if (rc == PX_E_UNSUPPORTED && e == 0)
			snprintf(h->notes, sizeof(h->notes), "%s", why);
		else if (rc != PX_OK)
			return fail(msg, cap, cfg, dc, "socketcan.bitrate", rc,
				    "%s", why);
	}
	if (c->n_signals) {
		if (c->n_signals > 64)
			return fail(msg, cap, cfg, dc, "socketcan.signals",
				    PX_E_INVAL, "%zu signals; a device takes "
				    "at most 64", c->n_signals);
		h->signals = calloc(c->n_signals, sizeof(*h->signals));
		if (!h->signals)
			return fail(msg, cap, cfg, dc, "socketcan", PX_E_NOMEM,
				    "out of memory");
		for (i = 0; i < c->n_signals; i++) {
			const struct px_config_can_signal *s = &c->signals[i];
			struct px_can_signal *o = &h->signals[i];
			int out = s->direction == PX_CONFIG_SIGNAL_OUTPUT;
			o->name = s->name;
			o->id = (uint32_t)s->id;
			o->extended = s->extended;
			o->output = out;
			o->start_bit = (uint16_t)s->start_bit;
			o->length = (uint8_t)s->length;
			o->byte_order = s->byte_order == PX_CONFIG_BIG_ENDIAN
						? PX_BIG_ENDIAN
						: PX_LITTLE_ENDIAN;
			o->is_signed = s->is_signed;
			o->is_float = s->is_float;
			o->scale = s->scale;
			o->offset = s->offset;
			o->has_min = s->has_min;
			o->has_max = s->has_max;
			o->min = s->min;
			o->max = s->max;
			o->axis = -1;
			snprintf(key, sizeof(key), "socketcan.signals[%zu].axis",
				 i);
			if (s->axis >= PX_CONFIG_SIGNAL_AXIS_FX) {
				if (!out)
					return fail(msg, cap, cfg, dc, key,
						    PX_E_INVAL,
						    "input signal '%s' cannot "
						    "feed a force channel",
						    s->name);
				o->axis = s->axis - PX_CONFIG_SIGNAL_AXIS_FX;
			} else if (s->axis != PX_CONFIG_SIGNAL_AXIS_NONE) {
				if (out)
					return fail(msg, cap, cfg, dc, key,
						    PX_E_INVAL,
						    "output signal '%s' cannot "
						    "carry a pose axis",
						    s->name);
				o->axis = s->axis - PX_CONFIG_SIGNAL_AXIS_X;
			}
		}
		rc = chk ? PX_OK : can_bus_open(h, cfg, dc, opt, &bus, msg, cap);
		if (rc != PX_OK || chk)
			goto signals_done;
		rc = px_can_dev_create(dcfg, bus, c->fd, h->signals,
				       c->n_signals, &h->dev, why, sizeof(why));
		if (rc != PX_OK) {
			px_can_bus_close(bus);
			return fail(msg, cap, cfg, dc, "socketcan.signals", rc,
				    "%s", why);
		}
	signals_done:
		if (rc != PX_OK)
			return rc;
	}
	if (has_co) {
		struct px_canopen_config cc;
		if (c->canopen.n_drives > PX_CANOPEN_MAX_DRIVES)
			return fail(msg, cap, cfg, dc, "socketcan.canopen.drives",
				    PX_E_INVAL, "%zu drives; the master takes "
				    "at most %d", c->canopen.n_drives,
				    PX_CANOPEN_MAX_DRIVES);
		drives_from_cfg(h, &c->canopen);
		rc = pdo_from_cfg(h, &c->canopen, key, sizeof(key), why,
				  sizeof(why));
		if (rc != PX_OK)
			return fail(msg, cap, cfg, dc, key, rc, "%s", why);
		px_canopen_config_default(&cc);
		cc.pdo = &h->pdo;
		cc.sync = c->canopen.sync;
		cc.heartbeat_period_ns = c->canopen.heartbeat_period_ns;
		cc.heartbeat_timeout_ns = c->canopen.heartbeat_timeout_ns;
		cc.drives = h->drives;
		cc.n_drives = h->n_drives;
		if (c->canopen.has_node_id) {
			cc.own_node_id = (uint8_t)c->canopen.node_id;
		} else {
			/* the highest id no drive uses */
			int id;
			for (id = 127; id > 1; id--) {
				for (i = 0; i < h->n_drives &&
					    h->drives[i].node_id != id;
				     i++)
					;
				if (i == h->n_drives)
					break;
			}
			cc.own_node_id = (uint8_t)id;
		}
		if (chk)
			return PX_OK;
		rc = can_bus_open(h, cfg, dc, opt, &h->co_bus, msg, cap);
		if (rc != PX_OK)
			return rc;
		rc = px_canopen_create(&cc, h->co_bus, &h->co, why, sizeof(why));
		if (rc != PX_OK)
			return fail(msg, cap, cfg, dc, "socketcan.canopen", rc,
				    "%s", why);
	}
	return PX_OK;
}

/* ---- entry ----------------------------------------------------------- */

int px_devcfg_open(const struct px_config *cfg,
		   const struct px_config_device *dc,
		   const struct px_devcfg_options *opt, struct px_devcfg **out,
		   char *msg, size_t cap)
{
	struct px_devcfg *h;
	struct px_dev_config dcfg;
	char why[512];
	int rc = PX_OK, chk;
	if (msg && cap)
		msg[0] = '\0';
	if (out)
		*out = NULL;
	if (!cfg || !dc || !out || dc < cfg->devices ||
	    dc >= cfg->devices + cfg->n_devices) {
		if (msg && cap)
			snprintf(msg, cap, "px_devcfg_open: NULL argument or "
					   "a device not of this config");
		return PX_E_INVAL;
	}
	chk = opt && opt->check_only;
	h = calloc(1, sizeof(*h));
	if (!h)
		return fail(msg, cap, cfg, dc, NULL, PX_E_NOMEM,
			    "out of memory");
	if (opt && opt->n_faults && dc->backend != PX_CONFIG_BACKEND_SIM) {
		free(h);
		return fail(msg, cap, cfg, dc, "faults", PX_E_INVAL,
			    "fault windows in the options are for simulated "
			    "devices only");
	}
	px_dev_config_default(&dcfg);
	dcfg.name = dc->name;
	dcfg.stale_timeout_ns = dc->stale_timeout_ns
					? dc->stale_timeout_ns
					: cfg->safety.watchdog.device_timeout_ns;
	if (dcfg.stale_timeout_ns <= 0)
		px_dev_config_default(&dcfg), dcfg.name = dc->name;
	dcfg.stuck_limit = (uint32_t)dc->stuck_limit;
	dcfg.min_report_interval_ns = dc->min_report_interval_ns;

	switch (dc->backend) {
	case PX_CONFIG_BACKEND_SIM:
		if (dc->sim.kind == PX_CONFIG_SIM_GPIO) {
			struct px_gpio_config gc;
			rc = gpio_cfg(cfg, dc, "sim", dc->sim.lines,
				      dc->sim.n_lines, &gc, msg, cap);
			if (rc == PX_OK) {
				struct px_sim_fault f[PX_SIM_MAX_FAULTS];
				int n = sim_faults(dc->sim.faults,
						   dc->sim.n_faults, opt, f);
				if (n < 0) {
					rc = fail(msg, cap, cfg, dc,
						  "sim.faults", n,
						  "more than %d fault windows "
						  "(config and campaign)",
						  PX_SIM_MAX_FAULTS);
					break;
				}
				rc = px_gpio_sim_create(&dcfg, &gc, f,
							(size_t)n, &h->dev,
							why, sizeof(why));
				if (rc != PX_OK)
					fail(msg, cap, cfg, dc, "sim.lines", rc,
					     "%s", why);
			}
		} else {
			rc = open_sim_haptic(h, cfg, dc, opt, &dcfg, msg, cap);
		}
		break;
	case PX_CONFIG_BACKEND_HIDAPI: {
		const struct px_config_hidapi *c = &dc->hidapi;
		struct px_hid_config hc;
		if (!c->codec.n_inputs) {
			rc = fail(msg, cap, cfg, dc, "hidapi.inputs", PX_E_INVAL,
				  "a HID device needs input fields");
			break;
		}
		rc = open_codec(h, cfg, dc, &c->codec, "hidapi", msg, cap);
		if (rc != PX_OK)
			break;
		dcfg.codec = &h->map;
		memset(&hc, 0, sizeof(hc));
		hc.has_vid_pid = c->has_vid && c->has_pid && !c->path;
		hc.vid = (uint16_t)c->vid;
		hc.pid = (uint16_t)c->pid;
		hc.serial = c->serial;
		hc.path = c->path;
		hc.driver = c->driver == PX_CONFIG_HID_LIBUSB ? PX_HID_LIBUSB
							      : PX_HID_HIDRAW;
		rc = chk ? PX_OK
			 : px_hid_create(&dcfg, &hc, &h->dev, why, sizeof(why));
		if (rc != PX_OK)
			fail(msg, cap, cfg, dc,
			     hc.has_vid_pid ? "hidapi.vid" : "hidapi.path", rc,
			     "%s", why);
		break;
	}
	case PX_CONFIG_BACKEND_LIBUSB: {
		const struct px_config_libusb *c = &dc->libusb;
		struct px_usb_config uc;
		if (!c->codec.n_inputs) {
			rc = fail(msg, cap, cfg, dc, "libusb.inputs", PX_E_INVAL,
				  "a USB device needs input fields");
			break;
		}
		rc = open_codec(h, cfg, dc, &c->codec, "libusb", msg, cap);
		if (rc != PX_OK)
			break;
		dcfg.codec = &h->map;
		memset(&uc, 0, sizeof(uc));
		uc.vid = (uint16_t)c->vid;
		uc.pid = (uint16_t)c->pid;
		uc.serial = c->serial;
		uc.interface = (int)c->interface;
		uc.endpoint_in = (uint8_t)c->endpoint_in;
		uc.endpoint_out = (uint8_t)c->endpoint_out;
		uc.transfer = c->transfer == PX_CONFIG_USB_BULK ? PX_USB_BULK
								: PX_USB_INTERRUPT;
		uc.frame_len = (size_t)c->frame_len;
		uc.detach_kernel_driver = c->detach_kernel_driver;
		uc.no_hotplug = c->no_hotplug;
		uc.n_transfers = 4;
		rc = chk ? PX_OK
			 : px_usb_create(&dcfg, &uc, &h->dev, why, sizeof(why));
		if (rc != PX_OK)
			fail(msg, cap, cfg, dc, "libusb.vid", rc, "%s", why);
		break;
	}
	case PX_CONFIG_BACKEND_SOCKETCAN:
		rc = open_can(h, cfg, dc, opt, &dcfg, msg, cap);
		break;
	case PX_CONFIG_BACKEND_GPIOD: {
		struct px_gpio_config gc;
		int e = 0;
		rc = gpio_cfg(cfg, dc, "gpiod", dc->gpiod.lines,
			      dc->gpiod.n_lines, &gc, msg, cap);
		if (rc != PX_OK)
			break;
		gc.chip = dc->gpiod.chip;
		rc = chk ? PX_OK
			 : px_gpiod_create(&dcfg, &gc, &h->dev, &e, why,
					   sizeof(why));
		if (rc != PX_OK)
			fail(msg, cap, cfg, dc, "gpiod.chip", rc, "%s", why);
		break;
	}
	default:
		rc = fail(msg, cap, cfg, dc, "backend", PX_E_INVAL,
			  "unknown back end %d", dc->backend);
		break;
	}
	if (rc != PX_OK || chk) {
		px_devcfg_free(h); /* check_only: nothing was opened */
		return rc;
	}
	*out = h;
	return PX_OK;
}

static int64_t no_wait(void *user, int64_t now_ns, int64_t period_ns)
{
	(void)user;
	return now_ns + period_ns;
}

void px_devcfg_safe_config_default(struct px_devcfg_safe_config *c)
{
	if (!c)
		return;
	memset(c, 0, sizeof *c);
	px_canopen_stop_config_default(&c->canopen);
}

int px_devcfg_safe_stop(struct px_devcfg *h, int64_t now_ns,
			const struct px_devcfg_safe_config *cfg,
			struct px_devcfg_safe_result *res)
{
	struct px_devcfg_safe_config c;
	int rc = PX_OK;
	if (res) {
		memset(res, 0, sizeof *res);
		res->canopen.first_unconfirmed = -1;
	}
	if (!h)
		return PX_E_INVAL;
	if (cfg)
		c = *cfg;
	else
		px_devcfg_safe_config_default(&c);
	if (h->dev) {
		rc = px_dev_safe(h->dev, now_ns);
		if (res) {
			res->dev_rc = rc;
			res->caps = px_dev_caps(h->dev);
		}
	}
	if (h->co) {
		int r = px_canopen_safe_stop(h->co, now_ns, &c.canopen,
					     res ? &res->canopen : NULL);
		h->co_safe = r == PX_OK;
		if (res)
			res->canopen_rc = r;
		if (rc == PX_OK)
			rc = r;
	}
	return rc;
}

void px_devcfg_free(struct px_devcfg *h)
{
	if (!h)
		return;
	if (h->co && !h->co_safe) {
		/* Freed without px_devcfg_safe_stop(): one round of quick
		 * stop / disable voltage still goes out before the bus
		 * closes (no waiting for confirmation here). */
		struct px_canopen_stop_config sc;
		px_canopen_stop_config_default(&sc);
		sc.max_rounds = 1;
		sc.wait = no_wait;
		(void)px_canopen_safe_stop(h->co, px_dev_mono_ns(), &sc, NULL);
	}
	px_dev_free(h->dev); /* a device written to gets its safe output */
	px_canopen_free(h->co);
	px_can_bus_close(h->co_bus);
	if (h->own_sim_bus)
		px_can_sim_free(h->sim_bus);
	px_sim_csv_free(h->csv);
	free(h->inputs);
	free(h->outputs);
	free(h->buttons);
	free(h->signals);
	free(h);
}

const char *px_devcfg_notes(const struct px_devcfg *h)
{
	return h ? h->notes : "";
}

struct px_dev *px_devcfg_dev(const struct px_devcfg *h)
{
	return h ? h->dev : NULL;
}

struct px_canopen *px_devcfg_canopen(const struct px_devcfg *h)
{
	return h ? h->co : NULL;
}

struct px_can_bus *px_devcfg_canopen_bus(const struct px_devcfg *h)
{
	return h ? h->co_bus : NULL;
}

struct px_can_sim *px_devcfg_can_sim(const struct px_devcfg *h)
{
	return h ? h->sim_bus : NULL;
}

const struct px_canopen_pdo_map *px_devcfg_pdo(const struct px_devcfg *h)
{
	return h && h->co ? &h->pdo : NULL;
}

int px_devcfg_drives(const struct px_devcfg *h,
		     struct px_canopen_drive_cfg *drives, size_t cap)
{
	if (!h || (!drives && cap))
		return PX_E_INVAL;
	if (cap < h->n_drives)
		return PX_E_NOSPC;
	if (h->n_drives)
		memcpy(drives, h->drives, h->n_drives * sizeof(*drives));
	return (int)h->n_drives;
}
