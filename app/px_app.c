/* The app's public calls and its message helpers. */
#include "app_internal.h"

void px_app_options_default(struct px_app_options *opt)
{
	memset(opt, 0, sizeof(*opt));
}

void app_note(struct px_app *a, const char *fmt, ...)
{
	char buf[4096];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(buf, sizeof(buf), fmt, ap);
	va_end(ap);
	if (a->msg && a->msg_cap && !a->msg[0]) {
		/* the caller's msg: the first line of the first message */
		size_t n = strcspn(buf, "\n");
		if (n >= a->msg_cap)
			n = a->msg_cap - 1;
		memcpy(a->msg, buf, n);
		a->msg[n] = '\0';
	}
	if (a->o.note)
		a->o.note(a->o.user, buf);
}

/* A config diagnostic list as message text (px_config_diag_print writes
 * to a stream: here one in memory, handed to opt.note). */
void app_diag_print(struct px_app *a, const struct px_config_diag *diag)
{
	char *buf = NULL;
	size_t n = 0;
	FILE *f = open_memstream(&buf, &n);
	if (!f)
		return;
	px_config_diag_print(diag, f);
	fclose(f);
	if (buf && buf[0])
		app_note(a, "%s", buf);
	free(buf);
}

const char *app_name(const struct px_app *a)
{
	return a->o.name ? a->o.name : "px_app";
}

uint64_t app_heap_count(struct px_app *a)
{
	return a->o.heap_count ? a->o.heap_count() : 0;
}

/* The plots' names follow the CSV's (or the default CSV name's). */
void app_plot_paths(struct px_app *a, char *time_svg, char *lat_svg, size_t cap)
{
	const char *base = a->csv_path[0] ? a->csv_path : "proxima-run.csv";
	size_t n = strlen(base);
	if (n > 4 && strcmp(base + n - 4, ".csv") == 0)
		n -= 4;
	snprintf(time_svg, cap, "%.*s_time.svg", (int)n, base);
	snprintf(lat_svg, cap, "%.*s_latency.svg", (int)n, base);
}

void px_app_shutdown_describe(const struct px_app *a, char *buf, size_t cap)
{
	const struct shutdown_report *sd = &a->sd;
	char parts[160] = "";
	size_t n = 0;
	if (sd->force_devs)
		n += (size_t)snprintf(parts + n, sizeof(parts) - n,
				      "force zeroed on %d/%d device%s",
				      sd->force_zeroed, sd->force_devs,
				      sd->force_devs == 1 ? "" : "s");
	if (sd->dio_devs && n < sizeof(parts))
		n += (size_t)snprintf(parts + n, sizeof(parts) - n,
				      "%srelay off on %d/%d", n ? ", " : "",
				      sd->relays_off, sd->dio_devs);
	if (sd->drives && n < sizeof(parts))
		n += (size_t)snprintf(parts + n, sizeof(parts) - n,
				      "%s%d/%d drive%s disabled%s", n ? ", " : "",
				      sd->drives_disabled, sd->drives,
				      sd->drives == 1 ? "" : "s",
				      sd->drives_faulted ? " (some in fault)" : "");
	snprintf(buf, cap, "%s (%s) after %s in %.1f ms%s%s",
		 sd->safe ? "safe" : "NOT SAFE", n ? parts : "no outputs",
		 sd->reason, (double)sd->elapsed_ns * 1e-6, sd->why[0] ? ": " : "",
		 sd->why);
}

void app_note_shutdown(struct px_app *a)
{
	char line[1024];
	px_app_shutdown_describe(a, line, sizeof(line));
	app_note(a, "%s: shutdown: %s\n", app_name(a), line);
}

/* Internal status (0, 1 invalid or failed, 2 options refused) as the
 * public code. */
static int app_code(int status)
{
	return status == 0 ? PX_OK : status == 2 ? PX_E_INVAL : PX_E_PARSE;
}

int px_app_create(const struct px_config *cfg, const struct px_app_options *opt,
		  struct px_app **out, char *msg, size_t cap)
{
	struct px_app *a;
	int rc;
	if (msg && cap)
		msg[0] = '\0';
	if (!out)
		return PX_E_INVAL;
	*out = NULL;
	if (!cfg || !opt || !opt->config || opt->n_faults < 0 ||
	    opt->n_faults > PX_APP_MAX_CLI_FAULTS || opt->duration_s < 0 ||
	    !(opt->duration_s <= 1e8)) {
		if (msg && cap)
			snprintf(msg, cap, "px_app_create: %s",
				 !cfg || !opt || !opt->config
					 ? "no config (or no config path)"
					 : "duration_s outside [0, 1e8] or "
					   "n_faults outside [0, 64]");
		return PX_E_INVAL;
	}
	a = calloc(1, sizeof(*a));
	if (!a)
		return PX_E_NOMEM;
	a->o = *opt;
	/* the app reads the config only; its handle is not const for the
	 * px_scene/px_devcfg calls that take it so */
	a->cfg = (struct px_config *)(uintptr_t)cfg;
	a->msg = msg;
	a->msg_cap = cap;
	rc = px_control_config_read(cfg, &a->ctl, &a->diag);
	if (rc != PX_OK) {
		app_report_config(a, rc, &a->diag);
		rc = 1;
		goto fail;
	}
	a->sim.cfg_ = cfg;
	rc = px_config_read(cfg->doc, cfg->sim, "sim", app_sim_schema(), &a->sim,
			    &a->diag);
	if (rc != PX_OK) {
		app_report_config(a, rc, &a->diag);
		rc = 1;
		goto fail;
	}
	rc = app_teleop_read(a);
	if (rc != PX_OK) {
		app_report_config(a, rc, &a->diag);
		rc = 1;
		goto fail;
	}
	if (a->ctl.warning[0])
		app_note(a, "%s\n", a->ctl.warning);
	rc = app_add_cli_faults(a);
	if (rc)
		goto fail;
	rc = a->o.check ? app_check_config(a) : app_setup(a);
	if (rc)
		goto fail;
	a->msg = NULL;
	*out = a;
	return PX_OK;
fail:
	app_teardown(a);
	free(a);
	return app_code(rc);
}

void px_app_warnings(struct px_app *a)
{
	app_rearm_warnings(a);
}

struct px_loop *px_app_loop(struct px_app *a)
{
	return a->loop;
}

struct px_stats *px_app_compute_stats(struct px_app *a)
{
	return a->compute;
}

struct px_canopen *px_app_canopen(struct px_app *a)
{
	return a->co;
}

const struct px_scene *px_app_scene(const struct px_app *a)
{
	return a ? a->scene : NULL;
}

int px_app_arm(struct px_app *a, struct px_app_arm *out)
{
	/* (a config checked only is not avoiding yet: its mode says) */
	if (!a || !out || a->ctl.mode != PX_CONTROL_MODE_AVOIDANCE ||
	    a->ctl.chain.n_joints < 1)
		return 0;
	memset(out, 0, sizeof(*out));
	out->chain = &a->ctl.chain;
	out->robot = a->robot;
	out->joint_perm = a->robot ? a->joint_perm : NULL;
	out->record_joints = app_avoid_joints(a);
	out->protective_distance_m = a->ctl.avoid.protective_distance_m;
	out->influence_distance_m = a->ctl.avoid.influence_distance_m;
	out->cloud_feed = a->feed;
	return 1;
}

int px_app_last_record(const struct px_app *a, struct px_app_record *out)
{
	if (!a->have_last)
		return 0;
	*out = a->last;
	return 1;
}

int px_app_device_count(const struct px_app *a)
{
	return a->n_dev;
}

struct px_dev *px_app_device_at(struct px_app *a, int i)
{
	return i >= 0 && i < a->n_dev ? a->dev[i] : NULL;
}

struct px_dev *px_app_device(struct px_app *a, const char *name)
{
	int i;
	for (i = 0; name && i < a->n_dev; i++)
		if (!strcmp(px_dev_name(a->dev[i]), name))
			return a->dev[i];
	return NULL;
}

int px_app_run(struct px_app *a)
{
	return app_run(a);
}

int px_app_step(struct px_app *a)
{
	return px_loop_step(a->loop);
}

/* The caller's phases: not in a check-only app (no loop), and never
 * after the shutdown, whose safe outputs a later write would undo. */
static int phase_ready(const struct px_app *a)
{
	if (!a)
		return PX_E_INVAL;
	if (!a->loop || a->sd.done)
		return PX_E_STATE;
	return PX_OK;
}

int px_app_read(struct px_app *a, int64_t now_ns)
{
	int rc = phase_ready(a);
	return rc ? rc : px_loop_read(a->loop, now_ns);
}

int px_app_compute(struct px_app *a, int64_t now_ns)
{
	int rc = phase_ready(a);
	return rc ? rc : px_loop_compute(a->loop, now_ns);
}

int px_app_write(struct px_app *a, int64_t now_ns)
{
	int rc = phase_ready(a);
	return rc ? rc : px_loop_write(a->loop, now_ns);
}

/* The campaign's window i against the loop faults seen. */
static void reaction(const struct px_app *a, size_t i, struct px_app_reaction *r)
{
	const struct raw_fault *f = &a->sim.faults[i];
	const struct px_config_device *d = px_config_device_find(a->cfg, f->device);
	int64_t tmo = d && d->stale_timeout_ns ? d->stale_timeout_ns
					       : a->cfg->safety.watchdog.device_timeout_ns;
	int64_t t0 = a->clock0_ns + f->start_ns;
	int64_t t1 = t0 + f->duration_ns + tmo + 10000000;
	size_t k;
	r->kind = app_fault_kind_names[f->kind];
	r->device = f->device;
	r->start_ns = f->start_ns;
	r->duration_ns = f->duration_ns;
	r->probability = f->probability;
	r->loop_faults = 0;
	r->safe_after_ns = -1;
	for (k = 0; k < a->n_lfaults; k++) {
		const struct px_fault *lf = &a->lfaults[k];
		if (lf->t_ns < t0 || lf->t_ns > t1)
			continue;
		r->loop_faults++;
		if (lf->safe && r->safe_after_ns < 0)
			r->safe_after_ns = lf->t_ns - t0;
	}
}

/* Cycles from each loop fault that reported safe state to the first
 * cycle recorded in safe state (at most 1000 looked at; a fault whose
 * run ended first is not counted). -1: none checked. */
static int64_t trip_to_safe(const struct px_app *a, uint64_t *checked)
{
	int64_t worst = -1;
	size_t k;
	*checked = 0;
	if (!a->safe_bits)
		return -1;
	for (k = 0; k < a->n_lfaults; k++) {
		const struct px_fault *lf = &a->lfaults[k];
		int64_t d = 1000;
		uint64_t c;
		if (!lf->safe || lf->cycle >= a->safe_bits_n)
			continue;
		for (c = lf->cycle; c < a->safe_bits_n && c < lf->cycle + 1000; c++)
			if (a->safe_bits[c >> 3] & (1u << (c & 7))) {
				d = (int64_t)(c - lf->cycle);
				break;
			}
		if (c == a->safe_bits_n && d == 1000)
			continue; /* the run ended first */
		(*checked)++;
		if (d > worst)
			worst = d;
	}
	return worst;
}

int px_app_summary(const struct px_app *a, struct px_app_summary *s)
{
	struct px_loop_status st;
	size_t i;
	if (!a || !s)
		return PX_E_INVAL;
	memset(s, 0, sizeof(*s));
	if (a->loop && px_loop_status(a->loop, &st) == PX_OK) {
		s->cycles = st.cycles;
		s->overruns = st.overruns;
		s->missed_periods = st.missed_periods;
		s->safe_state_trips = st.safe_entries;
		if (a->have_deadline)
			s->loop_time_s = (double)(a->last_deadline_ns -
						  a->first_deadline_ns +
						  st.period_ns) *
					 1e-9;
		s->phase_error_ns =
			(a->have_deadline ? a->last_deadline_ns - a->first_deadline_ns
					  : 0) -
			(st.cycles ? ((int64_t)st.cycles - 1 +
				      (int64_t)st.missed_periods) *
					     st.period_ns
				   : 0);
	}
	s->max_force_n = a->max_force_n;
	s->contact_cycles = a->contact_cycles;
	s->min_distance_m = a->min_distance_m;
	s->max_penetration_m = a->max_penetration_m;
	s->min_proxy_distance_m = a->min_proxy_distance_m;
	s->min_clearance_m = a->min_clearance_m;
	s->velocity_trips = a->velocity_trips;
	s->query_errors = a->query_errors;
	s->estop_presses = a->estop_presses;
	s->estop_cycles = a->estop_cycles;
	s->telemetry_records = a->n_rows;
	s->telemetry_dropped = a->ring ? px_ring_dropped(a->ring) : 0;
	s->faults_popped = a->faults_popped;
	s->allocations_after_setup = atomic_load(&a->allocs);
	s->shutdown_done = a->sd.done;
	s->shutdown_safe = a->sd.safe;
	snprintf(s->shutdown_reason, sizeof(s->shutdown_reason), "%s",
		 a->sd.reason);
	s->force_devices = a->sd.force_devs;
	s->force_zeroed = a->sd.force_zeroed;
	s->relay_devices = a->sd.dio_devs;
	s->relays_off = a->sd.relays_off;
	s->shutdown_drives = a->sd.drives;
	s->drives_disabled = a->sd.drives_disabled;
	s->drives_faulted = a->sd.drives_faulted;
	s->shutdown_ns = a->sd.elapsed_ns;
	snprintf(s->shutdown_error, sizeof(s->shutdown_error), "%s", a->sd.why);
	s->max_trip_to_safe_cycles = trip_to_safe(a, &s->watchdog_trips_checked);
	s->scene_models = px_scene_count(a->scene);
	s->rendering = a->rendering;
	s->proxy_renderer = a->ctl.haptic.renderer == PX_CONTROL_PROXY;
	s->avoiding = a->avoiding;
	s->distance_reported = a->ctl_dev >= 0;
	s->record_joints = app_avoid_joints(a);
	s->max_cycles = a->max_cycles;
	s->decimation = a->decimation;
	s->force_clamp_n = a->ctl.haptic.max_force_n;
	s->protective_distance_m = a->ctl.avoid.protective_distance_m;
	s->influence_distance_m = a->ctl.avoid.influence_distance_m;
	snprintf(s->csv_path, sizeof(s->csv_path), "%s", a->csv_path);
	snprintf(s->time_svg, sizeof(s->time_svg), "%s", a->time_svg);
	snprintf(s->lat_svg, sizeof(s->lat_svg), "%s", a->lat_svg);
	s->ended_by_time = a->ended_by_time;
	s->min_speed_scale = a->min_scale;
	s->stop_cycles = a->stop_cycles;
	s->cloud_swaps = a->cloud_swaps;
	s->last_query_error = a->last_query_err;
	memcpy(s->faults_by_cause, a->faults_by_cause, sizeof(s->faults_by_cause));
	s->faults_injected = a->sim.n_faults;
	s->nonfinite_outputs = a->nonfinite_outputs;
	s->estop_lines = a->n_dio;
	s->estop_to_safe_ns = a->estop_first_ns >= 0 && a->safe_first_after_estop_ns >= 0
				      ? a->safe_first_after_estop_ns - a->estop_first_ns
				      : -1;
	s->estop_to_safe_cycles =
		a->estop_first_ns >= 0 && a->safe_first_after_estop_ns >= 0
			? (int64_t)(a->safe_first_cycle_after_estop -
				    a->estop_first_cycle)
			: -1;
	s->safe_cycles_before_estop = a->safe_cycles_before_estop;
	s->safe_at_estop = a->safe_at_estop;
	s->enable_write_errors = a->enable_errors;
	s->n_drives = a->co ? a->n_drives : 0;
	s->drives_device = a->co ? a->co_name : NULL;
	s->drives_enabled_cycles = a->enabled_cycles;
	s->drive_problem_cycles = a->drive_problem_cycles;
	app_teleop_summary(a, s);
	s->tracking_enabled = a->tracking != NULL;
	s->tracking_streams = px_scene_tracking_stats(a->tracking, &s->tracking);
	for (i = 0; i < a->sim.n_faults && i < PX_APP_MAX_CAMPAIGN; i++)
		reaction(a, i, &s->reactions[i]);
	s->n_reactions = i;
	return PX_OK;
}

void px_app_stop(struct px_app *a)
{
	if (!a)
		return;
	atomic_store(&a->stop_requested, 1);
	if (a->loop)
		px_loop_stop(a->loop);
}

void px_app_drain(struct px_app *a,
		  void (*record)(void *user, const struct px_app_record *r),
		  void *user)
{
	app_drain(a, record, user);
}

int px_app_shutdown(struct px_app *a, const char *reason)
{
	app_safe_shutdown(a, reason ? reason : "shutdown");
	return a->sd.safe ? PX_OK : PX_E_TIMEOUT;
}

void px_app_free(struct px_app *a)
{
	if (!a)
		return;
	app_teardown(a);
	free(a);
}
