/* The app's checks: the `sim` section (fault campaigns, the avoidance
 * demo's nominal motion), validate() before any device opens, --check,
 * the command line's fault entries. */
#include "app_internal.h"

const char *const app_fault_kind_names[] = {
	"drop", "delay", "duplicate", "corrupt", "stuck", "nan", "unplug",
	"bus_off", "estop", "overrun", NULL};

static void fault_check(struct px_config_reader *r,
			const struct px_config_node *map, void *obj)
{
	const struct raw_fault *f = obj;
	int delay = f->kind == FK_DELAY || f->kind == FK_OVERRUN;
	if (delay && f->delay_ns <= 0)
		px_config_reader_error(r, map, "delay_ns",
				       "missing or zero for kind '%s'",
				       app_fault_kind_names[f->kind]);
	if (!delay && f->delay_ns > 0)
		px_config_reader_error(r, px_config_node_get(map, "delay_ns"),
				       "delay_ns",
				       "only for kinds 'delay' and 'overrun'");
}

/* Why fault f cannot be injected into its device (NULL: it can). What
 * takes what: simulated haptic/pose devices their report faults,
 * simulated lines the e-stop, a CANopen arm on the in-process simulated
 * bus the bus's faults and drive 0's (estop: a drive fault, unplug: the
 * drive falls silent), the pseudo-device 'loop' a compute overrun. */
const char *app_fault_misfit(const struct px_config *cfg,
				const struct raw_fault *f, char *buf, size_t cap)
{
	const struct px_config_device *d = px_config_device_find(cfg, f->device);
	if (f->kind == FK_OVERRUN)
		return strcmp(f->device, "loop") == 0
			       ? NULL
			       : "kind 'overrun' makes the compute phase slow: "
				 "its device is 'loop'";
	if (!d && strcmp(f->device, "loop") == 0)
		return "device 'loop' takes kind 'overrun' only";
	if (!d) {
		snprintf(buf, cap, "no device named '%s' in devices", f->device);
		return buf;
	}
	if (d->backend == PX_CONFIG_BACKEND_SIM && d->sim.kind != PX_CONFIG_SIM_GPIO)
		return f->kind <= FK_UNPLUG
			       ? NULL
			       : "a simulated haptic or pose device takes drop, "
				 "delay, duplicate, corrupt, stuck, nan or unplug";
	if (d->backend == PX_CONFIG_BACKEND_SIM)
		return f->kind == FK_ESTOP ? NULL
					   : "simulated lines take estop only";
	if (d->backend == PX_CONFIG_BACKEND_SOCKETCAN &&
	    d->socketcan.transport == PX_CONFIG_CAN_SIM &&
	    d->socketcan.canopen.present)
		return f->kind == FK_DROP || f->kind == FK_DUPLICATE ||
				       f->kind == FK_CORRUPT ||
				       f->kind == FK_BUS_OFF ||
				       f->kind == FK_ESTOP || f->kind == FK_UNPLUG
			       ? NULL
			       : "a CANopen arm on the simulated bus takes drop, "
				 "duplicate, corrupt, bus_off (the bus), estop "
				 "(drive 0 faults) or unplug (drive 0 falls "
				 "silent)";
	snprintf(buf, cap, "'%s' is not a simulated device (faults are "
		 "injected into simulated devices only)", f->device);
	return buf;
}

static const struct px_config_key fault_keys[] = {
	{.name = "device", .type = PX_CONFIG_T_STRING,
	 .offset = offsetof(struct raw_fault, device),
	 .flags = PX_CONFIG_REQUIRED | PX_CONFIG_NONEMPTY},
	{.name = "kind", .type = PX_CONFIG_T_ENUM,
	 .offset = offsetof(struct raw_fault, kind), .flags = PX_CONFIG_REQUIRED,
	 .names = app_fault_kind_names},
	{.name = "start_ns", .type = PX_CONFIG_T_DURATION,
	 .offset = offsetof(struct raw_fault, start_ns),
	 .flags = PX_CONFIG_REQUIRED | SIM_RANGE, .imin = 0,
	 .imax = 1000000000000000},
	{.name = "duration_ns", .type = PX_CONFIG_T_DURATION,
	 .offset = offsetof(struct raw_fault, duration_ns),
	 .flags = PX_CONFIG_REQUIRED | SIM_RANGE, .imin = 1,
	 .imax = 1000000000000000, .idef = 1},
	{.name = "probability", .type = PX_CONFIG_T_DOUBLE,
	 .offset = offsetof(struct raw_fault, probability),
	 .flags = SIM_RANGE | PX_CONFIG_MIN_EXCL, .dmin = 0, .dmax = 1,
	 .ddef = 1},
	{.name = "delay_ns", .type = PX_CONFIG_T_DURATION,
	 .offset = offsetof(struct raw_fault, delay_ns), .flags = SIM_RANGE,
	 .imin = 0, .imax = 10000000000},
};
static const struct px_config_schema fault_schema = {
	"fault", fault_keys, sizeof(fault_keys) / sizeof(fault_keys[0]),
	fault_check};

/* sim.spawn_arm: proxima-simarm takes the drive table, PDO mapping and
 * drive faults from this config (--config FILE --device NAME), so any
 * drive table the master takes will do; what still matters is that it
 * can reach the device: a socketcan device on transport unix (another
 * process cannot join an in-process bus; a kernel bus needs no spawned
 * arm) with canopen drives. */
static void spawn_arm_check(struct px_config_reader *r,
			    const struct px_config_node *map,
			    const struct raw_sim *sm)
{
	const struct px_config_node *at = px_config_node_get(map, "spawn_arm");
	const struct px_config_device *d =
		px_config_device_find(sm->cfg_, sm->spawn_arm);
	const struct px_config_canopen *co;
	if (!d) {
		px_config_reader_error(r, at, "spawn_arm",
				       "no device named '%s' in devices",
				       sm->spawn_arm);
		return;
	}
	co = &d->socketcan.canopen;
	if (d->backend != PX_CONFIG_BACKEND_SOCKETCAN ||
	    d->socketcan.transport != PX_CONFIG_CAN_UNIX || !co->present ||
	    co->n_drives == 0) {
		px_config_reader_error(r, at, "spawn_arm",
				       "'%s' is not a socketcan device with "
				       "transport unix and canopen drives",
				       sm->spawn_arm);
		return;
	}
}

static void sim_check(struct px_config_reader *r,
		      const struct px_config_node *map, void *obj)
{
	const struct raw_sim *sm = obj;
	const struct px_config_node *seq = px_config_node_get(map, "faults");
	size_t i;
	char where[48];
	if (sm->spawn_arm)
		spawn_arm_check(r, map, sm);
	for (i = 0; i < sm->n_faults; i++) {
		const struct raw_fault *f = &sm->faults[i];
		const struct px_config_node *it =
			seq && seq->kind == PX_CONFIG_NODE_SEQ && i < seq->len
				? seq->items[i]
				: map;
		const char *why;
		char buf[160];
		if (!f->device)
			continue;
		snprintf(where, sizeof(where), "faults[%zu].device", i);
		why = app_fault_misfit(sm->cfg_, f, buf, sizeof(buf));
		if (why)
			px_config_reader_error(r, px_config_node_get(it, "device"),
					       where, "%s", why);
	}
}

static const struct px_config_key nominal_keys[] = {
	{.name = "joint", .type = PX_CONFIG_T_INT64,
	 .offset = offsetof(struct raw_nominal, joint),
	 .flags = PX_CONFIG_REQUIRED | SIM_RANGE, .imin = 0,
	 .imax = PX_CONTROL_MAX_JOINTS - 1},
	{.name = "amplitude_rad_per_s", .type = PX_CONFIG_T_DOUBLE,
	 .offset = offsetof(struct raw_nominal, amplitude_rad_per_s),
	 .flags = PX_CONFIG_REQUIRED | SIM_RANGE, .dmin = -100, .dmax = 100},
	{.name = "frequency_hz", .type = PX_CONFIG_T_DOUBLE,
	 .offset = offsetof(struct raw_nominal, frequency_hz),
	 .flags = SIM_RANGE, .dmin = 0, .dmax = 1000},
	{.name = "phase_rad", .type = PX_CONFIG_T_DOUBLE,
	 .offset = offsetof(struct raw_nominal, phase_rad), .flags = SIM_RANGE,
	 .dmin = -1000, .dmax = 1000},
};
static const struct px_config_schema nominal_schema = {
	"nominal", nominal_keys, sizeof(nominal_keys) / sizeof(nominal_keys[0]),
	NULL};

static const struct px_config_key sim_keys[] = {
	{.name = "faults", .type = PX_CONFIG_T_SEQ,
	 .offset = offsetof(struct raw_sim, faults), .sub = &fault_schema,
	 .elem = PX_CONFIG_T_SUB, .elem_size = sizeof(struct raw_fault),
	 .count_offset = offsetof(struct raw_sim, n_faults),
	 .max_count = MAX_CAMPAIGN},
	{.name = "nominal", .type = PX_CONFIG_T_SEQ,
	 .offset = offsetof(struct raw_sim, nominal), .sub = &nominal_schema,
	 .elem = PX_CONFIG_T_SUB, .elem_size = sizeof(struct raw_nominal),
	 .count_offset = offsetof(struct raw_sim, n_nominal), .max_count = 64},
	{.name = "spawn_arm", .type = PX_CONFIG_T_STRING,
	 .offset = offsetof(struct raw_sim, spawn_arm),
	 .flags = PX_CONFIG_NONEMPTY},
	{.name = "depth_sensor", .type = PX_CONFIG_T_SUB,
	 .offset = offsetof(struct raw_sim, depth), .sub = &app_depth_schema,
	 .flags = PX_CONFIG_PRESENT, .present_offset = offsetof(struct raw_sim, has_depth)},
};
static const struct px_config_schema sim_schema = {
	"sim", sim_keys, sizeof(sim_keys) / sizeof(sim_keys[0]), sim_check};

const struct px_config_schema *app_sim_schema(void)
{
	return &sim_schema;
}


int app_report_config(struct px_app *a, int rc, const struct px_config_diag *diag)
{
	int n = px_config_diag_total(diag);
	app_diag_print(a, diag);
	if (n == 0)
		app_note(a, "%s: %s\n", a->o.config, px_strerror(rc));
	app_note(a, "%s: invalid configuration (%d error%s)\n", a->o.config,
		n, n == 1 ? "" : "s");
	return 1;
}

/* ---- setup, part 1: the checks (no device opened) ------------------- */

/* Telemetry ring memory (telemetry.ring_records records of struct px_app_record,
 * allocated at setup and locked with loop.lock_memory): a warning above
 * TELE_WARN_BYTES, refused above TELE_MAX_BYTES (docs/config.md). */
#define TELE_WARN_BYTES ((size_t)64 << 20)
#define TELE_MAX_BYTES ((size_t)1 << 30)


/* One refusal in the config's own format, "file:line:column: key: what"
 * (the key alone when the value has no place: a default). */
void app_check_error(struct px_app *a, const struct px_config_node *at,
		     const char *key, const char *fmt, ...)
{
	char what[2048];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(what, sizeof(what), fmt, ap);
	va_end(ap);
	if (at)
		app_note(a, "%s:%d:%d: %s: %s\n", at->file, at->line, at->column,
			 key, what);
	else
		app_note(a, "%s: %s: %s\n", a->o.config, key, what);
	a->n_check_errors++;
}

/* A node of the config by path of mapping keys (NULL: absent). */
const struct px_config_node *app_cfg_node(struct px_app *a, const char *sect, const char *key)
{
	const struct px_config_node *s =
		px_config_node_get(px_config_doc_root(a->cfg->doc), sect);
	return key ? px_config_node_get(s, key) : s;
}

/* What a config device can do once opened (the back ends' px_dev caps),
 * known without opening it; *canopen: it carries CANopen drives. */
unsigned app_config_caps(const struct px_config_device *d, int *canopen)
{
	*canopen = 0;
	switch (d->backend) {
	case PX_CONFIG_BACKEND_SIM:
		return d->sim.kind == PX_CONFIG_SIM_GPIO   ? PX_DEV_CAP_DIO
		       : d->sim.kind == PX_CONFIG_SIM_POSE ? PX_DEV_CAP_POSE
							   : PX_DEV_CAP_POSE |
							     PX_DEV_CAP_FORCE;
	case PX_CONFIG_BACKEND_HIDAPI:
	case PX_CONFIG_BACKEND_LIBUSB:
		return PX_DEV_CAP_POSE | PX_DEV_CAP_FORCE;
	case PX_CONFIG_BACKEND_SOCKETCAN:
		*canopen = d->socketcan.canopen.present &&
			   d->socketcan.canopen.n_drives > 0;
		return d->socketcan.n_signals ? PX_DEV_CAP_POSE | PX_DEV_CAP_FORCE
					      : 0;
	case PX_CONFIG_BACKEND_GPIOD:
		return PX_DEV_CAP_DIO;
	case PX_CONFIG_BACKEND_DDS:
		return (d->dds.pose_topic ? PX_DEV_CAP_POSE : 0u) |
		       (d->dds.command_topic ? PX_DEV_CAP_FORCE : 0u);
	default:
		return 0;
	}
}

/* control.device must be able to do what control.mode asks of it. */
void app_check_control(struct px_app *a)
{
	const struct px_config_node *at = app_cfg_node(a, "control", "device");
	const struct px_config_device *d =
		a->ctl.device ? px_config_device_find(a->cfg, a->ctl.device) : NULL;
	unsigned caps;
	int co = 0;
	if (a->ctl.mode != PX_CONTROL_MODE_HAPTIC &&
	    a->ctl.mode != PX_CONTROL_MODE_AVOIDANCE)
		return;
	if (!d) {
		app_check_error(a, at ? at : app_cfg_node(a, "control", NULL), "control.device",
			    "mode '%s' needs a device",
			    a->ctl.mode == PX_CONTROL_MODE_HAPTIC ? "haptic"
								 : "avoidance");
		return;
	}
	caps = app_config_caps(d, &co);
	if (a->ctl.mode == PX_CONTROL_MODE_AVOIDANCE) {
		if (!co)
			app_check_error(a, at, "control.device",
				    "control mode 'avoidance' needs control.device "
				    "'%s' to be a socketcan device with canopen "
				    "drives",
				    d->name);
		return;
	}
	if (!(caps & PX_DEV_CAP_POSE))
		app_check_error(a, at, "control.device",
			    "'%s' (%s) is not a pose device: haptic rendering "
			    "needs one that reports a pose (sim kind haptic, "
			    "hidapi, libusb, socketcan signals)",
			    d->name, px_config_backend_names()[d->backend]);
	else if (!(caps & PX_DEV_CAP_FORCE))
		app_check_error(a, at, "control.device",
			    "'%s' takes no force (a sim device of kind pose): "
			    "haptic rendering needs a force output",
			    d->name);
}

/* Setup-time memory of the telemetry: refused when absurd, a warning
 * when large (the whole ring is allocated at setup and, with
 * loop.lock_memory, locked in RAM). */
void app_check_memory(struct px_app *a)
{
	size_t rec = sizeof(struct px_app_record);
	uint64_t n = (uint64_t)a->cfg->telemetry.ring_records;
	uint64_t ring = n * rec;
	const struct px_config_node *at = app_cfg_node(a, "telemetry", "ring_records");
	if (ring > TELE_MAX_BYTES) {
		app_check_error(a, at, "telemetry.ring_records",
			    "%llu records take %.1f GiB (%zu bytes each): at "
			    "most %llu (%zu MiB)",
			    (unsigned long long)n, (double)ring / (1u << 30), rec,
			    (unsigned long long)(TELE_MAX_BYTES / rec),
			    TELE_MAX_BYTES >> 20);
	} else if (ring > TELE_WARN_BYTES) {
		if (at)
			app_note(a, "%s:%d:%d: ", at->file, at->line,
				at->column);
		app_note(a,
			"telemetry.ring_records: warning: %llu records take "
			"%.0f MiB at setup%s (warning above %zu MiB)\n",
			(unsigned long long)n, (double)ring / (1u << 20),
			a->cfg->loop.lock_memory ? ", locked in RAM (loop."
						  "lock_memory)"
						: "",
			TELE_WARN_BYTES >> 20);
	}
}

/* Every file the config names as input ("file" keys: scene models,
 * trajectories; not telemetry.file, an output), and the config itself:
 * no output of this run may be written over them. */
void app_protect_inputs(struct px_app *a, const struct px_config_node *n, int depth,
			   int in_telemetry)
{
	size_t i;
	if (!n || depth > PX_CONFIG_MAX_DEPTH)
		return;
	if (n->kind == PX_CONFIG_NODE_SEQ)
		for (i = 0; i < n->len; i++)
			app_protect_inputs(a, n->items[i], depth + 1, 0);
	if (n->kind != PX_CONFIG_NODE_MAP)
		return;
	for (i = 0; i < n->len; i++) {
		const struct px_config_node *k = n->pairs[i].key;
		const struct px_config_node *v = n->pairs[i].value;
		if (!in_telemetry && strcmp(k->str, "file") == 0 &&
		    v->kind == PX_CONFIG_NODE_SCALAR && v->str[0]) {
			char path[2048];
			app_config_dir_path(path, sizeof(path), a->o.config, v->str);
			if (a->o.input_protect)
				a->o.input_protect(a->o.user, path,
						   "an input file of the config,");
		}
		app_protect_inputs(a, v, depth + 1,
			       depth == 0 && strcmp(k->str, "telemetry") == 0);
	}
}

/* One output path: where it came from decides the status (2: a flag,
 * 1: the config, with its place). Returns 0, 1 or 2. */
int app_check_output(struct px_app *a, const char *path, const char *flag,
			const struct px_config_node *at, const char *key)
{
	char why[APP_WHY_MAX];
	if (!a->o.output_check ||
	    a->o.output_check(a->o.user, path, why, sizeof(why)) == 0)
		return 0;
	if (flag) {
		app_note(a, "%s: %s: %s\n", app_name(a), flag, why);
		return 2;
	}
	app_check_error(a, at, key, "%s", why);
	return 1;
}

/* The CSV, plot and summary paths, each checked before anything runs (a
 * refusal after a long run would lose it). */
int app_check_outputs(struct px_app *a)
{
	const char *tflag = NULL;
	const struct px_config_node *tat = app_cfg_node(a, "telemetry", "file");
	int rc, r;
	if (a->o.input_protect)
		a->o.input_protect(a->o.user, a->o.config, "the config file");
	app_protect_inputs(a, px_config_doc_root(a->cfg->doc), 0, 0);
	if (a->o.telemetry) {
		snprintf(a->csv_path, sizeof(a->csv_path), "%s", a->o.telemetry);
		tflag = "--telemetry";
	} else if (a->cfg->telemetry.file && a->cfg->telemetry.file[0]) {
		snprintf(a->csv_path, sizeof(a->csv_path), "%s",
			 a->cfg->telemetry.file);
	}
	app_plot_paths(a, a->time_svg, a->lat_svg, sizeof(a->time_svg));
	rc = a->csv_path[0] ? app_check_output(a, a->csv_path, tflag, tat, "telemetry.file")
			   : 0;
	/* the plot names follow the CSV's (or are the default's) */
	r = app_check_output(a, a->time_svg, tflag ? "--telemetry (its time plot)" : NULL,
			 tat, "telemetry.file (its time plot)");
	rc = rc ? rc : r;
	r = app_check_output(a, a->lat_svg, tflag ? "--telemetry (its latency plot)" : NULL,
			 tat, "telemetry.file (its latency plot)");
	rc = rc ? rc : r;
	if (a->o.summary_json) {
		r = app_check_output(a, a->o.summary_json, "--summary-json", NULL, NULL);
		rc = rc ? rc : r;
	}
	return rc;
}

/* Everything setup checks before it opens a device: the outputs, the
 * scene (px_scene_config_load: keys, values, files, geometry), what the
 * clock allows, control.device against what the device can do, the
 * telemetry memory, the haptic renderer's parameters. --check runs this
 * (and opens the in-process simulated devices); a run goes on to open
 * everything. Says every problem (app_note); returns 0, 1 (invalid) or 2 (a
 * flag's value, or --virtual-time with hardware). */
int app_validate(struct px_app *a)
{
	const struct px_config *cfg = a->cfg;
	int i, rc, status = 0;

	a->ctl_dev = -1;
	a->cloud_input = -1;
	a->estop_first_ns = -1;
	a->safe_first_after_estop_ns = -1;
	a->clock0_ns = a->o.virtual_time || a->o.check ? 0 : app_mono_ns();
	a->min_distance_m = INFINITY;
	a->min_proxy_distance_m = INFINITY;
	a->decimation = cfg->telemetry.decimation > 0 ? cfg->telemetry.decimation : 1;
	if (a->o.duration_s > 0)
		a->max_cycles = (uint64_t)ceil(a->o.duration_s * 1e9 /
					      (double)cfg->loop.period_ns);
	a->n_check_errors = 0;

	rc = app_check_outputs(a);
	if (rc == 2)
		return 2;
	px_config_diag_init(&a->diag);
	rc = px_scene_config_load(cfg, &a->scene, &a->diag);
	if (rc != PX_OK) {
		int n = px_config_diag_total(&a->diag);
		app_diag_print(a, &a->diag);
		if (n == 0)
			app_note(a, "%s: %s\n", a->o.config, px_strerror(rc));
		a->n_check_errors += n ? n : 1;
	}
	for (i = 0; i < (int)cfg->n_devices; i++) {
		if (!app_is_hardware(&cfg->devices[i]))
			continue;
		a->hardware = 1;
		if (a->o.virtual_time) {
			app_note(a,
				"%s: device '%s' (%s): --virtual-time "
				"drives simulated devices only; hardware and "
				"buses shared with other processes run on the "
				"real clock\n", app_name(a),
				cfg->devices[i].name,
				px_config_backend_names()[cfg->devices[i].backend]);
			status = 2;
		}
	}
	if (cfg->n_devices > MAX_DEVS)
		app_check_error(a, app_cfg_node(a, "devices", NULL), "devices",
			    "%zu devices; a run takes at most %d",
			    cfg->n_devices, MAX_DEVS);
	app_check_control(a);
	app_teleop_check(a);
	if (!a->n_check_errors && !app_robot_setup(a))
		app_sensor_setup(a);
	app_check_memory(a);
	if (a->ctl.mode == PX_CONTROL_MODE_HAPTIC) {
		rc = px_control_haptic_init(&a->haptic, &a->ctl.haptic,
					    cfg->loop.period_ns);
		if (rc != PX_OK)
			app_check_error(a, app_cfg_node(a, "control", "haptic"), "control.haptic",
				    "the renderer refuses these parameters: %s",
				    px_strerror(rc));
	}
	if (a->n_check_errors) {
		app_note(a, "%s: invalid configuration (%d error%s)\n",
			a->o.config, a->n_check_errors, a->n_check_errors == 1 ? "" : "s");
		return status ? status : 1;
	}
	return status;
}

/* The loop as the config describes it (setup, and --check's trial). */
void app_loop_config(struct px_app *a, struct px_loop_config *lcp)
{
	const struct px_config *cfg = a->cfg;
	struct px_loop_config lc;
	px_loop_config_default(&lc);
	lc.period_ns = cfg->loop.period_ns;
	lc.clock = a->o.virtual_time ? PX_LOOP_CLOCK_VIRTUAL : PX_LOOP_CLOCK_MONOTONIC;
	lc.overrun = cfg->loop.overrun_policy == PX_CONFIG_OVERRUN_CATCH_UP
			     ? PX_LOOP_OVERRUN_CATCH_UP
			     : PX_LOOP_OVERRUN_SKIP;
	lc.overrun_limit = (uint32_t)cfg->loop.max_consecutive_overruns;
	lc.compute_budget_ns = cfg->safety.watchdog.compute_budget_ns;
	lc.budget_limit = (uint32_t)cfg->safety.watchdog.max_over_budget;
	/* auto_rearm: leave safe state after 50 ms without a fault */
	lc.rearm_after_ok_cycles =
		cfg->safety.watchdog.auto_rearm
			? (uint32_t)(50000000 / cfg->loop.period_ns + 1)
			: 0;
	lc.read = app_phase_read;
	lc.compute = app_phase_compute;
	lc.write = app_phase_write;
	lc.user = a;
	lc.rt_enable = !a->o.virtual_time;
	lc.rt.priority = (int)cfg->loop.priority;
	lc.rt.cpu = (int)cfg->loop.cpu;
	lc.rt.lock_memory = cfg->loop.lock_memory;
	lc.rt.dma_latency = cfg->loop.dma_latency;
	*lcp = lc;
}

/* A device outside this process (hardware, a UNIX-socket bus) checked
 * as px_devcfg_open() would check it, without opening it. Returns 0 or
 * 1 (said why, at the device's place). */
int app_check_device(struct px_app *a, int k)
{
	const struct px_config_device *d = &a->cfg->devices[k];
	struct px_devcfg_options opt;
	struct px_devcfg *h = NULL;
	char msg[512] = "";
	int rc;
	if (d->backend == PX_CONFIG_BACKEND_DDS)
		return 0; /* its keys were checked with the config's */
	memset(&opt, 0, sizeof(opt));
	opt.check_only = 1;
	rc = px_devcfg_open(a->cfg, d, &opt, &h, msg, sizeof(msg));
	px_devcfg_free(h);
	if (rc == PX_OK)
		return 0;
	if (d->node_)
		app_note(a, "%s:%d:%d: ", d->node_->file, d->node_->line,
			d->node_->column);
	app_note(a, "%s\n", msg[0] ? msg : px_strerror(rc));
	return 1;
}

/* --check: app_validate(a), then open what lives in this process (simulated
 * devices, buses and arms) as the run would, so their own refusals show
 * too; hardware and UNIX-socket buses get px_devcfg's checks without
 * being opened. Returns the exit status. */
int app_check_config(struct px_app *a)
{
	struct px_loop_config lc;
	char exe[1024];
	int i, rc = app_validate(a);
	for (i = 0; rc == 0 && i < (int)a->cfg->n_devices && i < MAX_DEVS; i++)
		rc = app_is_hardware(&a->cfg->devices[i]) ? app_check_device(a, i)
						     : app_make_device(a, i);
	if (rc == 0) {
		/* the loop as the run makes it (real-time setup is applied
		 * only when a run starts) */
		app_loop_config(a, &lc);
		rc = px_loop_create(&lc, &a->loop);
		if (rc != PX_OK)
			app_note(a, "%s: %s: loop: %s\n", app_name(a), a->o.config,
				px_strerror(rc));
		rc = rc != PX_OK;
	}
	if (rc == 0 && a->sim.spawn_arm)
		rc = app_arm_exe(a, exe, sizeof(exe));
	if (rc == 0)
		app_rearm_warnings(a);
	return rc;
}


static const char *parse_fault(const char *spec, struct raw_fault *f,
			       char *dev, size_t dev_cap, char *buf, size_t cap)
{
	char tmp[256], *fld[7], *save = NULL, *t;
	int n = 0, k;
	double v[4] = {0, 0, 1, 0};
	if (strlen(spec) >= sizeof(tmp))
		return "too long";
	strcpy(tmp, spec);
	for (t = strtok_r(tmp, ",", &save); t && n < 7;
	     t = strtok_r(NULL, ",", &save))
		fld[n++] = t;
	if (n < 4 || n > 6)
		return "expected KIND,DEVICE,START_S,DURATION_S[,PROBABILITY[,"
		       "DELAY_S]]";
	memset(f, 0, sizeof(*f));
	f->kind = -1;
	for (k = 0; app_fault_kind_names[k]; k++)
		if (strcmp(fld[0], app_fault_kind_names[k]) == 0)
			f->kind = k;
	if (f->kind < 0) {
		snprintf(buf, cap, "unknown kind '%s' (drop, delay, duplicate, "
			 "corrupt, stuck, nan, unplug, bus_off, estop, overrun)",
			 fld[0]);
		return buf;
	}
	snprintf(dev, dev_cap, "%s", fld[1]);
	f->device = dev;
	for (k = 2; k < n; k++) {
		char *end;
		errno = 0;
		v[k - 2] = strtod(fld[k], &end);
		if (end == fld[k] || *end || errno || !isfinite(v[k - 2]) ||
		    v[k - 2] < 0 || v[k - 2] > 1e6) {
			snprintf(buf, cap, "'%s' is not a number of seconds (or a "
				 "probability)", fld[k]);
			return buf;
		}
	}
	if (v[1] <= 0 || v[2] <= 0 || v[2] > 1)
		return "DURATION_S must be > 0 and PROBABILITY in (0, 1]";
	f->start_ns = (int64_t)llround(v[0] * 1e9);
	f->duration_ns = (int64_t)llround(v[1] * 1e9);
	f->probability = v[2];
	f->delay_ns = (int64_t)llround(v[3] * 1e9);
	if ((f->kind == FK_DELAY || f->kind == FK_OVERRUN) != (f->delay_ns > 0))
		return "DELAY_S is required for kinds delay and overrun, and only "
		       "for them";
	return NULL;
}

/* sim.faults plus the --fault ones, checked like the config's. Returns
 * 0 or 2 (said why). */
int app_add_cli_faults(struct px_app *a)
{
	size_t n = a->sim.n_faults, i;
	if (!a->o.n_faults)
		return 0;
	a->all_faults = calloc(n + (size_t)a->o.n_faults, sizeof(*a->all_faults));
	if (!a->all_faults)
		return 2;
	if (n)
		memcpy(a->all_faults, a->sim.faults, n * sizeof(*a->all_faults));
	for (i = 0; i < (size_t)a->o.n_faults; i++) {
		char buf[200];
		const char *why = parse_fault(a->o.faults[i], &a->all_faults[n],
					      a->cli_devs[i], sizeof(a->cli_devs[i]), buf,
					      sizeof(buf));
		if (!why)
			why = app_fault_misfit(a->cfg, &a->all_faults[n], buf, sizeof(buf));
		if (why) {
			app_note(a, "%s: --fault %s: %s\n", app_name(a),
				a->o.faults[i], why);
			return 2;
		}
		n++;
	}
	if (n > MAX_CAMPAIGN) {
		app_note(a, "%s: more than %d faults\n", app_name(a), MAX_CAMPAIGN);
		return 2;
	}
	a->sim.faults = a->all_faults;
	a->sim.n_faults = n;
	return 0;
}

