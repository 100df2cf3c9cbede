/* The app's setup: devices (simulated, px_devcfg back ends, the CANopen
 * arm and its bus), the spawned proxima-simarm, the loop and its buffers,
 * the config's warnings, the teardown after the safe state. */
#include "app_internal.h"


/* A campaign fault window (sim.faults) as a px_sim fault on the loop
 * clock. */
struct px_sim_fault app_campaign_fault(struct px_app *a, const struct raw_fault *f)
{
	struct px_sim_fault x;
	memset(&x, 0, sizeof(x));
	x.kind = f->kind + 1;
	x.start_ns = a->clock0_ns + f->start_ns;
	x.duration_ns = f->duration_ns;
	x.probability = f->probability;
	x.delay_ns = f->delay_ns;
	return x;
}

/* ---- setup --------------------------------------------------------- */

void app_config_dir_path(char *out, size_t cap, const char *cfg_path,
			    const char *file)
{
	const char *slash = strrchr(cfg_path, '/');
	if (file[0] == '/' || !slash)
		snprintf(out, cap, "%s", file);
	else
		snprintf(out, cap, "%.*s/%s", (int)(slash - cfg_path), cfg_path,
			 file);
}

static void codec_field(struct px_codec_field *d, const struct px_config_field *s)
{
	memset(d, 0, sizeof(*d));
	d->report_id = (int)s->report_id;
	d->byte_offset = (uint32_t)s->byte_offset;
	d->bit_offset = (uint8_t)s->bit_offset;
	d->bit_width = (uint8_t)s->bit_width;
	d->is_signed = s->is_signed;
	d->byte_order = (uint8_t)s->byte_order;
	d->scale = s->scale;
	d->offset = s->offset;
	d->axis = s->axis;
	d->max_abs = s->max_abs;
}

/* The config's report format as a codec map (NULL when none is given:
 * the simulated device's built-in one). */
const struct px_codec_map *app_make_codec(struct px_app *a, int k, const struct px_config_codec *c)
{
	struct px_codec_map *m = &a->codec[k];
	size_t i;
	if (c->n_inputs == 0 && c->n_outputs == 0)
		return NULL;
	a->fields[k][0] = calloc(c->n_inputs + 1, sizeof(struct px_codec_field));
	a->fields[k][1] = calloc(c->n_outputs + 1, sizeof(struct px_codec_field));
	a->buttons[k] = calloc(c->n_buttons + 1, sizeof(struct px_codec_buttons));
	if (!a->fields[k][0] || !a->fields[k][1] || !a->buttons[k])
		return NULL;
	for (i = 0; i < c->n_inputs; i++)
		codec_field(&a->fields[k][0][i], &c->inputs[i]);
	for (i = 0; i < c->n_outputs; i++)
		codec_field(&a->fields[k][1][i], &c->outputs[i]);
	for (i = 0; i < c->n_buttons; i++) {
		a->buttons[k][i].report_id = (int)c->buttons[i].report_id;
		a->buttons[k][i].byte_offset = (uint32_t)c->buttons[i].byte_offset;
		a->buttons[k][i].first_bit = (uint8_t)c->buttons[i].first_bit;
		a->buttons[k][i].count = (uint8_t)c->buttons[i].count;
		a->buttons[k][i].first_button = (uint8_t)c->buttons[i].first_button;
	}
	m->inputs = a->fields[k][0];
	m->n_inputs = c->n_inputs;
	m->outputs = a->fields[k][1];
	m->n_outputs = c->n_outputs;
	m->buttons = a->buttons[k];
	m->n_buttons = c->n_buttons;
	m->output_report_id = (int)c->output_report_id;
	m->output_report_len = (size_t)c->output_report_len;
	return m;
}

/* A device through px_devcfg (every back end but the simulated
 * haptic/pose devices): hidapi, libusb, SocketCAN signals and CANopen
 * drives on any transport, libgpiod and simulated lines. A CANopen arm on
 * the in-process simulated bus gets its drives' side here as well (the
 * same drive table and PDO layouts as the master), stepped in the read
 * phase. Returns 0 or 1 (said why, naming the device). */
/* The campaign's fault windows that px_devcfg applies to device d: the
 * e-stop presses of simulated lines, and for a CANopen arm on the
 * in-process bus the bus's windows and drive 0's (*narm_out of them
 * in a->armf). Returns 0 or 1 (said why). */
static int devcfg_faults(struct px_app *a, const struct px_config_device *d,
			 struct px_devcfg_options *opt, size_t *narm_out)
{
	struct px_sim_fault *busf = a->busf, *armf = a->armf, *linef = a->linef;
	size_t nbus = 0, narm = 0, nline = 0, j;
	int rc;
	/* the campaign's e-stop presses of simulated lines: fault windows
	 * of the simulated GPIO device (px_devcfg applies them) */
	for (j = 0; j < a->sim.n_faults; j++) {
		const struct raw_fault *f = &a->sim.faults[j];
		if (strcmp(f->device, d->name) != 0 ||
		    d->backend != PX_CONFIG_BACKEND_SIM)
			continue;
		if (nline == PX_SIM_MAX_FAULTS) {
			app_note(a, "%s: device '%s': more than %d "
					"faults\n", app_name(a),
				d->name, PX_SIM_MAX_FAULTS);
			return 1;
		}
		linef[nline++] = app_campaign_fault(a, f);
	}
	opt->faults = nline ? linef : NULL;
	opt->n_faults = nline;
	/* faults of a CANopen arm on the in-process bus: the bus's (a bus
	 * of ours, given to px_devcfg) and drive 0's (the simulated arm) */
	for (j = 0; j < a->sim.n_faults; j++) {
		const struct raw_fault *f = &a->sim.faults[j];
		struct px_sim_fault x;
		if (strcmp(f->device, d->name) != 0 ||
		    d->backend != PX_CONFIG_BACKEND_SOCKETCAN)
			continue;
		x = app_campaign_fault(a, f);
		/* delay_ns is the simulated arm's drive index (drive 0);
		 * this path gives the bus windows none either */
		x.delay_ns = 0;
		if (f->kind == FK_ESTOP || f->kind == FK_UNPLUG)
			armf[narm++] = x; /* delay_ns 0: drive index 0 */
		else
			busf[nbus++] = x;
	}
	if (nbus) {
		struct px_can_sim_config bc;
		px_can_sim_config_default(&bc);
		bc.faults = busf;
		bc.n_faults = nbus;
		rc = px_can_sim_create(&bc, &a->fault_bus);
		if (rc != PX_OK) {
			app_note(a, "%s: device '%s': simulated bus: "
					"%s\n", app_name(a),
				d->name, px_strerror(rc));
			return 1;
		}
		opt->can_sim = a->fault_bus;
	}
	*narm_out = narm;
	return 0;
}

int app_make_devcfg(struct px_app *a, int k)
{
	const struct px_config_device *d = &a->cfg->devices[k];
	struct px_devcfg *h;
	struct px_devcfg_options opt;
	struct px_dev *dev;
	struct px_canopen *co;
	struct px_sim_fault *armf = a->armf;
	size_t narm = 0;
	char msg[512] = "";
	int rc, i;
	memset(&opt, 0, sizeof(opt));
	opt.clock0_ns = a->clock0_ns; /* the config's own fault windows */
	if (devcfg_faults(a, d, &opt, &narm))
		return 1;
	rc = px_devcfg_open(a->cfg, d, &opt, &h, msg, sizeof(msg));
	if (rc != PX_OK) {
		app_note(a, "%s: %s\n", app_name(a),
			msg[0] ? msg : px_strerror(rc));
		if (d->backend != PX_CONFIG_BACKEND_SIM)
			app_note(a,
				"%s: is the hardware connected and "
				"readable? build/bin/proxima-probe lists what "
				"this machine has\n", app_name(a));
		return 1;
	}
	a->dcfg[a->n_dcfg++] = h;
	if (px_devcfg_notes(h)[0])
		app_note(a, "%s: device '%s': note: %s\n", app_name(a), d->name,
			px_devcfg_notes(h));
	dev = px_devcfg_dev(h);
	if (dev) {
		if (a->n_dev >= MAX_DEVS) {
			app_note(a, "%s: more than %d devices\n", app_name(a),
				MAX_DEVS);
			return 1;
		}
		if (px_dev_caps(dev) & PX_DEV_CAP_DIO)
			a->dio[a->n_dio++] = dev;
		if ((px_dev_caps(dev) & PX_DEV_CAP_POSE) && a->ctl.device &&
		    strcmp(a->ctl.device, d->name) == 0)
			a->ctl_dev = a->n_dev;
		a->dev[a->n_dev++] = dev;
	}
	co = px_devcfg_canopen(h);
	if (co) {
		struct px_canopen_drive_cfg drv[PX_CANOPEN_MAX_DRIVES];
		int n = px_devcfg_drives(h, drv, PX_CANOPEN_MAX_DRIVES);
		if (a->co) {
			app_note(a,
				"%s: device '%s': a second CANopen "
				"arm ('%s' is the first); one per run\n", app_name(a),
				d->name, a->co_name);
			return 1;
		}
		if (n < 0) {
			app_note(a, "%s: device '%s': drives: %s\n", app_name(a),
				d->name, px_strerror(n));
			return 1;
		}
		a->co = co;
		a->co_name = d->name;
		a->n_drives = n;
		for (i = 0; i < n; i++) {
			a->drive_joint[i] = drv[i].joint;
			if (drv[i].mode == PX_CIA402_CST) {
				app_note(a,
					"%s: device '%s': drives in cst "
					"take torques; proxima-run commands csp "
					"or csv\n", app_name(a),
					d->name);
				return 1;
			}
		}
		a->csp = n > 0 && drv[0].mode == PX_CIA402_CSP;
		a->canbus = px_devcfg_can_sim(h);
		if (a->canbus) {
			struct px_canopen_sim_config sc;
			/* the config's drive faults (node_id) as well */
			int na = px_devcfg_arm_faults(a->cfg, d, a->clock0_ns,
						      armf + narm,
						      MAX_CAMPAIGN - narm);
			if (na < 0) {
				app_note(a,
					"%s: device '%s': drive "
					"faults: %s\n", app_name(a),
					d->name, px_strerror(na));
				return 1;
			}
			narm += (size_t)na;
			memset(&sc, 0, sizeof(sc));
			sc.pdo = px_devcfg_pdo(h);
			sc.drives = drv;
			sc.n_drives = (size_t)n;
			sc.heartbeat_period_ns = 100000000;
			sc.inertia_kg_m2 = 0.01;
			sc.faults = narm ? armf : NULL;
			sc.n_faults = narm;
			rc = px_can_sim_endpoint(a->canbus, &a->ep_arm);
			if (rc == PX_OK)
				rc = px_canopen_sim_create(&sc, a->ep_arm, &a->arm);
			if (rc != PX_OK) {
				app_note(a,
					"%s: device '%s': simulated arm "
					"on the in-process bus: %s\n", app_name(a),
					d->name, px_strerror(rc));
				return 1;
			}
		}
		if (a->ctl.device && strcmp(a->ctl.device, d->name) == 0)
			a->avoiding = a->ctl.mode == PX_CONTROL_MODE_AVOIDANCE;
	}
	return 0;
}

/* A device that is not simulated in this process (hardware, or a CAN bus
 * shared with another process) runs on the real clock only. */
int app_is_hardware(const struct px_config_device *d)
{
	return d->backend != PX_CONFIG_BACKEND_SIM &&
	       !(d->backend == PX_CONFIG_BACKEND_SOCKETCAN &&
		 d->socketcan.transport == PX_CONFIG_CAN_SIM);
}

/* Create device k of the config. Returns 0 or 1 (setup failed: said
 * why). */
int app_make_device(struct px_app *a, int k)
{
	const struct px_config_device *d = &a->cfg->devices[k];
	const struct px_config_sim *s = &d->sim;
	struct px_dev_config dc;
	struct px_sim_haptic_config sc;
	struct px_sim_sine sines[PX_SIM_MAX_SINES];
	char msg[256] = "";
	size_t i;
	int rc;
	if (d->backend == PX_CONFIG_BACKEND_DDS)
		return app_make_dds(a, k);
	if (d->backend != PX_CONFIG_BACKEND_SIM || s->kind == PX_CONFIG_SIM_GPIO)
		return app_make_devcfg(a, k);
	px_dev_config_default(&dc);
	dc.name = d->name;
	dc.stale_timeout_ns = d->stale_timeout_ns
				      ? d->stale_timeout_ns
				      : a->cfg->safety.watchdog.device_timeout_ns;
	dc.codec = app_make_codec(a, k, &s->codec);
	px_sim_haptic_config_default(&sc);
	sc.mass_kg = s->mass_kg;
	sc.damping_n_s_per_m = s->damping_n_s_per_m;
	sc.hand_stiffness_n_per_m = s->hand_stiffness_n_per_m;
	sc.hand_damping_n_s_per_m = s->hand_damping_n_s_per_m;
	sc.report_period_ns = s->report_period_ns ? s->report_period_ns
						  : a->cfg->loop.period_ns;
	sc.seed = (uint64_t)s->seed;
	sc.position_noise_m = s->position_noise_m;
	sc.follow_hand = s->kind == PX_CONFIG_SIM_POSE;
	sc.traj.kind = s->trajectory.kind == PX_CONFIG_TRAJ_SINES ? PX_SIM_TRAJ_SINES
		       : s->trajectory.kind == PX_CONFIG_TRAJ_CSV ? PX_SIM_TRAJ_CSV
								  : PX_SIM_TRAJ_HOLD;
	memcpy(sc.traj.center_m, s->trajectory.center_m, sizeof(sc.traj.center_m));
	for (i = 0; i < s->trajectory.n_sines && i < PX_SIM_MAX_SINES; i++) {
		sines[i].axis = s->trajectory.sines[i].axis;
		sines[i].amplitude_m = s->trajectory.sines[i].amplitude_m;
		sines[i].frequency_hz = s->trajectory.sines[i].frequency_hz;
		sines[i].phase_rad = s->trajectory.sines[i].phase_rad;
	}
	sc.traj.sines = sines;
	sc.traj.n_sines = i;
	sc.traj.repeat = s->trajectory.repeat;
	if (sc.traj.kind == PX_SIM_TRAJ_CSV) {
		char path[2048];
		app_config_dir_path(path, sizeof(path), a->o.config, s->trajectory.file);
		rc = px_sim_csv_load(path, &a->csv[k], msg, sizeof(msg));
		if (rc != PX_OK) {
			const struct px_config_node *at = px_config_node_get(
				px_config_node_get(px_config_node_get(d->node_, "sim"),
						   "trajectory"),
				"file");
			if (at)
				app_note(a, "%s:%d:%d: devices[%d].sim.trajectory."
					"file: ", at->file, at->line, at->column, k);
			app_note(a, "%s: device '%s': %s\n", app_name(a), d->name,
				msg[0] ? msg : px_strerror(rc));
			return 1;
		}
		sc.traj.csv = a->csv[k];
	}
	{
		/* the device's own faults (devices[].sim.faults, timed from
		 * the start of the run), then the campaign's (sim.faults) */
		struct px_sim_fault *fl = a->devf;
		size_t n = 0;
		for (i = 0; i < s->n_faults; i++) {
			const struct px_config_fault *f = &s->faults[i];
			if (n == PX_SIM_MAX_FAULTS) {
				app_note(a,
					"%s: device '%s': more than %d "
					"faults in devices[%d].sim.faults\n", app_name(a),
					d->name, PX_SIM_MAX_FAULTS, k);
				return 1;
			}
			memset(&fl[n], 0, sizeof(fl[n]));
			fl[n].kind = f->kind + 1;
			fl[n].start_ns = a->clock0_ns + f->start_ns;
			fl[n].duration_ns = f->duration_ns;
			fl[n].probability = f->probability;
			fl[n].delay_ns = f->delay_ns;
			n++;
		}
		for (i = 0; i < a->sim.n_faults; i++) {
			const struct raw_fault *f = &a->sim.faults[i];
			if (strcmp(f->device, d->name) != 0)
				continue;
			if (n == PX_SIM_MAX_FAULTS) {
				app_note(a,
					"%s: device '%s': more than %d "
					"faults\n", app_name(a),
					d->name, PX_SIM_MAX_FAULTS);
				return 1;
			}
			fl[n++] = app_campaign_fault(a, f);
		}
		sc.faults = fl;
		sc.n_faults = n;
	}
	/* A noisy position never repeats exactly: identical samples mean a
	 * frozen sensor (the stuck fault), so let the device detect it. */
	if (s->position_noise_m > 0)
		dc.stuck_limit = 50;
	if (d->stuck_limit > 0)
		dc.stuck_limit = (uint32_t)d->stuck_limit;
	dc.min_report_interval_ns = d->min_report_interval_ns;
	rc = px_sim_haptic_create(&dc, &sc, &a->dev[a->n_dev], msg, sizeof(msg));
	if (rc != PX_OK) {
		app_note(a, "%s: device '%s': %s\n", app_name(a), d->name,
			msg[0] ? msg : px_strerror(rc));
		return 1;
	}
	if (a->ctl.device && strcmp(a->ctl.device, d->name) == 0)
		a->ctl_dev = a->n_dev;
	a->dev_owned[a->n_dev] = 1;
	a->n_dev++;
	return 0;
}

/* proxima-simarm next to this program, in exe (cap bytes). Returns 0 or
 * 1 (said why). */
int app_arm_exe(struct px_app *a, char *exe, size_t cap)
{
	ssize_t len = cap > 32 ? readlink("/proc/self/exe", exe, cap - 32) : -1;
	char *slash;
	if (len <= 0 || !(slash = memrchr(exe, '/', (size_t)len))) {
		app_note(a, "%s: sim.spawn_arm: cannot find this "
				"program's directory\n", app_name(a));
		return 1;
	}
	strcpy(slash + 1, "proxima-simarm");
	if (access(exe, X_OK) != 0) {
		app_note(a, "%s: sim.spawn_arm: %s: %s (make builds "
				"it)\n", app_name(a),
			exe, strerror(errno));
		return 1;
	}
	return 0;
}

/* sim.spawn_arm: start proxima-simarm (next to this program) as the
 * drives' side of the unix-socket bus, as a second process, and wait
 * until it has bound its socket. It gets SIGTERM when this process ends
 * (teardown, or PR_SET_PDEATHSIG if this one dies). Returns 0 or 1. */
int app_spawn_arm(struct px_app *a)
{
	const struct px_config_device *d =
		px_config_device_find(a->cfg, a->sim.spawn_arm);
	const struct px_config_socketcan *c = &d->socketcan;
	char exe[1024], line[256] = "";
	int fds[2];
	size_t got = 0;
	int64_t until;
	if (app_arm_exe(a, exe, sizeof(exe)))
		return 1;
	if (pipe(fds) != 0) {
		app_note(a, "%s: sim.spawn_arm: pipe: %s\n", app_name(a),
			strerror(errno));
		return 1;
	}
	fflush(NULL);
	a->arm_pid = fork();
	if (a->arm_pid < 0) {
		app_note(a, "%s: sim.spawn_arm: fork: %s\n", app_name(a),
			strerror(errno));
		close(fds[0]);
		close(fds[1]);
		return 1;
	}
	if (a->arm_pid == 0) {
		/* the arm goes when the controller goes */
		prctl(PR_SET_PDEATHSIG, SIGTERM);
		dup2(fds[1], 1);
		close(fds[0]);
		close(fds[1]);
		/* the arm reads the same file: drives, PDO mapping, drive
		 * faults, and the other end of socket_path */
		execl(exe, "proxima-simarm", "--config", a->o.config, "--device",
		      d->name, (char *)NULL);
		app_note(a, "%s: sim.spawn_arm: %s: %s\n", app_name(a), exe,
			strerror(errno));
		_exit(127);
	}
	close(fds[1]);
	/* its first line says the socket is bound: wait for it (5 s) */
	until = app_mono_ns() + 5000000000;
	while (got + 1 < sizeof(line) && !memchr(line, '\n', got)) {
		struct pollfd p = {fds[0], POLLIN, 0};
		int64_t left = until - app_mono_ns();
		ssize_t r;
		if (left <= 0 || poll(&p, 1, (int)(left / 1000000) + 1) <= 0)
			break;
		r = read(fds[0], line + got, sizeof(line) - 1 - got);
		if (r <= 0)
			break;
		got += (size_t)r;
		line[got] = '\0';
	}
	close(fds[0]);
	if (!strstr(line, "drives on") || !strstr(line, "layout from")) {
		int st = 0;
		kill(a->arm_pid, SIGTERM);
		waitpid(a->arm_pid, &st, 0);
		a->arm_pid = 0;
		app_note(a,
			"%s: sim.spawn_arm: %s did not start (exit "
			"status %d)\n", app_name(a),
			exe, WIFEXITED(st) ? WEXITSTATUS(st) : -1);
		return 1;
	}
	app_note(a,
		"%s: spawned %s (pid %d): %zu drives on %s, layout "
		"from %s\n", app_name(a),
		exe, (int)a->arm_pid, c->canopen.n_drives, c->socket_path,
		a->o.config);
	return 0;
}

void app_stop_arm(struct px_app *a)
{
	if (a->arm_pid > 0) {
		kill(a->arm_pid, SIGTERM);
		waitpid(a->arm_pid, NULL, 0);
		a->arm_pid = 0;
	}
}



int app_setup(struct px_app *a)
{
	struct px_loop_config lc;
	const struct px_config *cfg = a->cfg;
	size_t ring_cap = (size_t)cfg->telemetry.ring_records;
	int i, rc = app_validate(a);

	if (rc)
		return rc;
	/* the loop's queries follow a moving point (proxy, device, link
	 * points): each model's search starts at last answer's feature */
	px_scene_control_query_coherent(a->scene, &a->hints, &a->query);
	/* a haptic renderer's queries follow one point (the proxy, or the
	 * device point): NURBS models follow it with tracked streams, the
	 * exact answer at a fraction of the global query's cost
	 * (scene.tracking); an arm's link points are many points, and stay
	 * with the hints */
	if (a->ctl.mode == PX_CONTROL_MODE_HAPTIC &&
	    px_scene_get_tracking(a->scene, NULL) == 1) {
		rc = px_scene_tracking_create(a->scene, NULL, &a->tracking);
		if (rc != PX_OK) {
			app_note(a,
				"%s: %s: scene.tracking: cannot make the "
				"tracked streams: %s\n", app_name(a),
				a->o.config, px_strerror(rc));
			return 1;
		}
		px_scene_control_query_tracked(a->scene, a->tracking, &a->query);
	}
	for (i = 0; i < (int)cfg->n_devices && i < MAX_DEVS; i++) {
		rc = app_make_device(a, i);
		if (rc)
			return rc;
	}
	if (a->ctl.mode == PX_CONTROL_MODE_AVOIDANCE && !a->avoiding) {
		app_note(a,
			"%s: control mode 'avoidance' needs "
			"control.device '%s' to be a socketcan device with "
			"canopen drives\n", app_name(a),
			a->ctl.device ? a->ctl.device : "");
		return 1;
	}

	a->min_clearance_m = INFINITY;
	a->min_scale = 1.0;
	a->rendering = a->ctl.mode == PX_CONTROL_MODE_HAPTIC && a->ctl_dev >= 0;
	if (a->ctl.mode == PX_CONTROL_MODE_HAPTIC && a->ctl_dev < 0) {
		app_note(a, "%s: control.device '%s' is not a "
				"pose device\n", app_name(a),
			a->ctl.device);
		return 1;
	}
	if (a->ctl_dev < 0 && a->n_dev > 0 && !a->avoiding)
		a->ctl_dev = 0; /* mode none: report the first device's distance */
	if (a->rendering) {
		if (!(px_dev_caps(a->dev[a->ctl_dev]) & PX_DEV_CAP_FORCE)) {
			app_note(a,
				"%s: control.device '%s' takes no force "
				"(a sim device of kind pose?)\n", app_name(a),
				a->ctl.device);
			return 1;
		}
		rc = px_control_haptic_init(&a->haptic, &a->ctl.haptic,
					    cfg->loop.period_ns);
		if (rc != PX_OK) {
			app_note(a, "%s: haptic setup: %s\n", app_name(a),
				px_strerror(rc));
			return 1;
		}
	}

	app_loop_config(a, &lc);
	rc = px_loop_create(&lc, &a->loop);
	if (rc != PX_OK) {
		app_note(a, "%s: loop: %s\n", app_name(a), px_strerror(rc));
		return 1;
	}
	for (i = 0; i < a->n_dev; i++) {
		rc = px_dev_start(a->dev[i]);
		/* a dds device may be a pure output or remote force: nothing
		 * for the watchdog to stamp */
		if (rc == PX_OK &&
		    (px_dev_caps(a->dev[i]) & (PX_DEV_CAP_POSE | PX_DEV_CAP_DIO))) {
			rc = px_dev_attach(a->dev[i], a->loop);
			if (rc >= 0 && a->tele.n_dds)
				app_teleop_input(a, i, rc);
		}
		if (rc >= 0 && a->rendering && i == a->ctl_dev)
			rc = px_dev_force_attach(a->dev[i], a->loop, &a->cmd);
		if (rc < 0) {
			struct px_dev_status ds;
			ds.last_msg[0] = '\0';
			px_dev_status(a->dev[i], &ds);
			app_note(a, "%s: device '%s': %s%s%s\n", app_name(a),
				px_dev_name(a->dev[i]), px_strerror(rc),
				ds.last_msg[0] ? ": " : "", ds.last_msg);
			return 1;
		}
	}
	if (a->co) {
		/* the drives' feedback (TPDO1) is a watched input like a pose */
		const struct px_config_device *d = px_config_device_find(cfg, a->co_name);
		int64_t tmo = d && d->stale_timeout_ns ? d->stale_timeout_ns
						       : cfg->safety.watchdog.device_timeout_ns;
		a->arm_input = px_loop_input_add(a->loop, a->co_name, tmo);
		if (a->arm_input < 0) {
			app_note(a, "%s: arm watchdog: %s\n", app_name(a),
				px_strerror(a->arm_input));
			return 1;
		}
	}
	if (app_teleop_attach(a))
		return 1;
	if (app_sensor_start(a))
		return 1;
	if (ring_cap < 16)
		ring_cap = 16;
	rc = px_arena_init_alloc(&a->arena, px_ring_size(ring_cap, sizeof(struct px_app_record)) +
						   px_stats_size(PX_STATS_DEFAULT_BINS) +
						   4096);
	if (rc == PX_OK)
		rc = px_ring_create(&a->arena, ring_cap, sizeof(struct px_app_record), &a->ring);
	if (rc == PX_OK)
		rc = px_stats_create(&a->arena, 0, 0, &a->compute);
	if (rc != PX_OK) {
		app_note(a, "%s: telemetry buffers: %s\n", app_name(a),
			px_strerror(rc));
		return 1;
	}
	if (a->sim.spawn_arm && app_spawn_arm(a))
		return 1;
	for (i = 0; i < (int)a->sim.n_faults; i++) {
		const struct raw_fault *f = &a->sim.faults[i];
		if (f->kind != FK_OVERRUN)
			continue;
		a->ov_start[a->n_ov] = a->clock0_ns + f->start_ns;
		a->ov_end[a->n_ov] = a->ov_start[a->n_ov] + f->duration_ns;
		a->ov_ns[a->n_ov++] = f->delay_ns;
	}
	/* safe state per cycle, to check the reaction to every trip (runs
	 * of a known length up to 2^26 cycles) */
	if (a->max_cycles && a->max_cycles <= ((uint64_t)1 << 26)) {
		a->safe_bits = calloc((size_t)(a->max_cycles + 7) / 8, 1);
		if (a->safe_bits)
			a->safe_bits_n = a->max_cycles;
	}
	return 0;
}


void app_rearm_warnings(struct px_app *a)
{
	const struct px_config *cfg = a->cfg;
	const struct px_config_node *n = px_config_doc_root(cfg->doc);
	const char *dev = NULL, *line = NULL;
	size_t i, k;
	if (!cfg->safety.watchdog.auto_rearm)
		return;
	if (cfg->safety.estop.present) {
		dev = cfg->safety.estop.device;
		line = cfg->safety.estop.line;
	}
	for (i = 0; !dev && i < cfg->n_devices; i++) {
		const struct px_config_device *d = &cfg->devices[i];
		const struct px_config_gpio_line *l = NULL;
		size_t nl = 0;
		if (d->backend == PX_CONFIG_BACKEND_SIM &&
		    d->sim.kind == PX_CONFIG_SIM_GPIO) {
			l = d->sim.lines;
			nl = d->sim.n_lines;
		} else if (d->backend == PX_CONFIG_BACKEND_GPIOD) {
			l = d->gpiod.lines;
			nl = d->gpiod.n_lines;
		}
		for (k = 0; k < nl; k++)
			if (l[k].name && !strcmp(l[k].name, "estop")) {
				dev = d->name;
				line = l[k].name;
				break;
			}
	}
	if (!dev)
		return;
	n = px_config_node_get(px_config_node_get(px_config_node_get(n, "safety"),
						  "watchdog"),
			       "auto_rearm");
	if (n)
		app_note(a, "%s:%d:%d: ", n->file, n->line, n->column);
	else
		app_note(a, "%s: ", a->o.config);
	app_note(a,
		"warning: safety.watchdog.auto_rearm: true re-arms after other "
		"trips, never after the e-stop (device '%s' line '%s'): its "
		"release keeps safe state until an explicit re-arm\n",
		dev, line);
}

void app_teardown(struct px_app *a)
{
	int i;
	/* a setup error after devices opened (or any path that did not
	 * stop them yet): the safe state before anything closes */
	if (!a->sd.done && (a->n_dev || a->n_dcfg) && !a->o.check) {
		app_safe_shutdown(a, "setup error");
		app_note_shutdown(a);
	}
	app_stop_arm(a);
	px_loop_free(a->loop);
	for (i = 0; i < a->n_dev; i++)
		if (a->dev_owned[i])
			px_dev_free(a->dev[i]);
	for (i = 0; i < MAX_DEVS; i++) {
		px_sim_csv_free(a->csv[i]);
		free(a->fields[i][0]);
		free(a->fields[i][1]);
		free(a->buttons[i]);
	}
	px_canopen_sim_free(a->arm);
	px_can_bus_close(a->ep_arm);
	for (i = 0; i < a->n_dcfg; i++)
		px_devcfg_free(a->dcfg[i]); /* devices, master, buses */
	px_can_sim_free(a->fault_bus); /* after its endpoints */
	px_scene_tracking_free(a->tracking); /* before its scene */
	app_sensor_free(a); /* its thread first */
	app_robot_free(a); /* its pairs point at the scene's models */
	px_scene_free(a->scene);
	px_arena_fini(&a->arena);
	free(a->lfaults);
	free(a->all_faults);
	free(a->safe_bits);
}

