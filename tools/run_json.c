/*
 * run_json.c - proxima-run's --summary-json (run_internal.h): one object,
 * its members in a fixed order, written through tools/tool_out.h.
 */
#include <stdio.h>
#include <string.h>

#include "px_canopen.h"
#include "px_dev.h"
#include "px_gpio.h"
#include "px_sim.h"
#include "run_internal.h"
#include "tool_out.h"

static void json_string(FILE *f, const char *s)
{
	fputc('"', f);
	for (; *s; s++) {
		if (*s == '"' || *s == '\\')
			fprintf(f, "\\%c", *s);
		else if ((unsigned char)*s < 0x20)
			fprintf(f, "\\u%04x", *s);
		else
			fputc(*s, f);
	}
	fputc('"', f);
}

static void json_stats(FILE *f, const char *name,
		       const struct px_stats_snapshot *s, int last)
{
	fprintf(f,
		"  \"%s\": {\"count\": %llu, \"p50\": %lld, \"p99\": %lld, "
		"\"p999\": %lld, \"max\": %lld, \"mean\": %lld}%s\n",
		name, (unsigned long long)s->count, (long long)s->p50_ns,
		(long long)s->p99_ns, (long long)s->p999_ns, (long long)s->max_ns,
		(long long)s->mean_ns, last ? "" : ",");
}

/* The devices' error counters added up by kind. */
static void device_faults(struct px_app *app, uint64_t by_kind[PX_DEV_ERR__COUNT])
{
	int i;
	memset(by_kind, 0, PX_DEV_ERR__COUNT * sizeof(by_kind[0]));
	for (i = 0; i < px_app_device_count(app); i++) {
		struct px_dev_status s;
		if (px_dev_status(px_app_device_at(app, i), &s) != PX_OK)
			continue;
		by_kind[PX_DEV_ERR_DECODE] += s.decode_errors;
		by_kind[PX_DEV_ERR_NONFINITE] += s.nonfinite;
		by_kind[PX_DEV_ERR_DUPLICATE] += s.duplicates;
		by_kind[PX_DEV_ERR_STUCK] += s.stuck;
		by_kind[PX_DEV_ERR_UNPLUG] += s.unplugs;
		by_kind[PX_DEV_ERR_IO] += s.io_errors + s.write_errors;
		by_kind[PX_DEV_ERR_BUS] += s.bus_errors;
	}
}

/* The loop and the timings, from "config" to "compute_ns". */
static void json_timing(FILE *f, const struct run_result *r)
{
	const struct px_loop_status *st = &r->st;
	fprintf(f, "{\n  \"config\": ");
	json_string(f, r->opt->config);
	fprintf(f,
		",\n  \"clock\": \"%s\",\n  \"period_ns\": %lld,\n"
		"  \"simulated_s\": %.6f,\n  \"wall_s\": %.3f,\n"
		"  \"cycles\": %llu,\n  \"overruns\": %llu,\n"
		"  \"missed_periods\": %llu,\n",
		r->opt->virtual_time ? "virtual" : "monotonic",
		(long long)st->period_ns,
		(double)st->cycles * (double)st->period_ns * 1e-9, r->wall_s,
		(unsigned long long)st->cycles, (unsigned long long)st->overruns,
		(unsigned long long)st->missed_periods);
	fprintf(f,
		"  \"loop_time_s\": %.6f,\n  \"wall_time_s\": %.3f,\n"
		"  \"duration_s\": %.9g,\n  \"ended_by\": \"%s\",\n",
		r->sum->loop_time_s, r->wall_s, r->opt->duration_s,
		run_ended_by(r));
	json_stats(f, "wakeup_latency_ns", &r->lat, 0);
	json_stats(f, "compute_ns", &r->cmp, 0);
}

/* Tracking, forces and distances, and the faults by cause. */
static void json_figures(FILE *f, const struct run_result *r)
{
	const struct px_app_summary *S = r->sum;
	struct px_model_stream_stats ts = S->tracking;
	uint64_t by_kind[PX_DEV_ERR__COUNT];
	int k;
	fprintf(f,
		"  \"tracking\": {\"enabled\": %s, \"streams\": %d, "
		"\"queries\": %llu, \"tracked\": %llu, \"hot\": %llu, "
		"\"global\": %llu, \"cold\": %llu, \"jumps\": %llu, "
		"\"reinits\": %llu, \"verifications\": %llu, "
		"\"disagreements\": %llu},\n",
		S->tracking_enabled ? "true" : "false", S->tracking_streams,
		(unsigned long long)ts.queries, (unsigned long long)ts.tracked,
		(unsigned long long)ts.hot, (unsigned long long)ts.global,
		(unsigned long long)ts.cold, (unsigned long long)ts.jumps,
		(unsigned long long)ts.reinits,
		(unsigned long long)ts.verifications,
		(unsigned long long)ts.disagreements);
	if (S->dds_devices) {
		fprintf(f,
			"  \"remote\": {\"dds_devices\": %d, \"samples_in\": %llu, "
			"\"samples_out\": %llu, \"lost\": %llu, "
			"\"params_accepted\": %llu, \"params_refused\": %llu, "
			"\"params_applied\": %llu, "
			"\"clouds_accepted\": %llu, \"clouds_refused\": %llu, "
			"\"clouds_dropped\": %llu, \"cloud_swaps\": %llu, "
			"\"scene_poses_accepted\": %llu, "
			"\"scene_poses_refused\": %llu, "
			"\"scene_poses_applied\": %llu, "
			"\"link_lost\": %s, \"link_lost_device\": ",
			S->dds_devices, (unsigned long long)S->remote_in,
			(unsigned long long)S->remote_out,
			(unsigned long long)S->remote_lost,
			(unsigned long long)S->params_accepted,
			(unsigned long long)S->params_refused,
			(unsigned long long)S->params_applied,
			(unsigned long long)S->clouds_accepted,
			(unsigned long long)S->clouds_refused,
			(unsigned long long)S->clouds_dropped,
			(unsigned long long)S->cloud_swaps,
			(unsigned long long)S->scene_poses_accepted,
			(unsigned long long)S->scene_poses_refused,
			(unsigned long long)S->scene_poses_applied,
			S->link_lost ? "true" : "false");
		json_string(f, S->link_lost_device);
		fprintf(f,
			", \"link_lost_t_s\": %.6f, \"link_silent_ns\": %lld, "
			"\"follow_cycles\": %llu, "
			"\"follow_error_max_m\": %.9g, "
			"\"follow_error_rms_m\": %.9g},\n",
			S->link_lost_t_s, (long long)S->link_silent_ns,
			(unsigned long long)S->follow_cycles,
			S->follow_error_max_m, S->follow_error_rms_m);
	}
	fprintf(f,
		"  \"max_force_n\": %.9g,\n  \"force_clamp_n\": %.9g,\n"
		"  \"min_distance_m\": %.9g,\n  \"max_penetration_m\": %.9g,\n"
		"  \"min_proxy_distance_m\": %.9g,\n"
		"  \"min_clearance_m\": %.9g,\n  \"protective_distance_m\": %.9g,\n"
		"  \"min_speed_scale\": %.9g,\n"
		"  \"cloud_swaps\": %llu,\n"
		"  \"contact_cycles\": %llu,\n  \"safe_state_trips\": %llu,\n"
		"  \"faults\": {",
		S->max_force_n, S->rendering ? S->force_clamp_n : 0.0,
		run_finite(S->min_distance_m), S->max_penetration_m,
		run_finite(S->min_proxy_distance_m),
		S->avoiding ? run_finite(S->min_clearance_m) : 0.0,
		S->avoiding ? S->protective_distance_m : 0.0,
		S->avoiding ? S->min_speed_scale : 1.0,
		(unsigned long long)S->cloud_swaps,
		(unsigned long long)S->contact_cycles,
		(unsigned long long)r->st.safe_entries);
	for (k = 1; k < PX_FAULT__COUNT; k++)
		fprintf(f, "\"%s\": %llu, ", px_fault_cause_name(k),
			(unsigned long long)S->faults_by_cause[k]);
	device_faults(r->app, by_kind);
	for (k = 1; k < PX_DEV_ERR__COUNT; k++)
		if (k != PX_DEV_ERR_OPEN && k != PX_DEV_ERR_ESTOP &&
		    k != PX_DEV_ERR_ENCODE)
			fprintf(f, "\"device_%s\": %llu, ", px_dev_errkind_name(k),
				(unsigned long long)by_kind[k]);
	fprintf(f,
		"\"velocity_limit\": %llu, \"query_error\": %llu, "
		"\"dropped\": %llu},\n",
		(unsigned long long)S->velocity_trips,
		(unsigned long long)S->query_errors,
		(unsigned long long)r->st.faults_dropped);
}

/* What the safety layer and the e-stop did: presses seen, how long after
 * the first press the loop was in safe state (ns, -1: never), state at
 * the end. */
static void json_safety(FILE *f, const struct run_result *r)
{
	const struct px_app_summary *S = r->sum;
	const struct px_loop_status *st = &r->st;
	fprintf(f,
		"  \"safe_at_end\": %d,\n  \"safe_cause\": \"%s\",\n"
		"  \"estop_lines\": %d,\n  \"estop_presses\": %llu,\n"
		"  \"estop_cycles\": %llu,\n  \"estop_to_safe_ns\": %lld,\n"
		"  \"estop_to_safe_cycles\": %lld,\n"
		"  \"safe_cycles_before_estop\": %llu,\n"
		"  \"safe_at_estop\": %d,\n"
		"  \"enable_write_errors\": %llu,\n",
		st->safe, st->safe ? px_fault_cause_name(st->safe_cause) : "",
		S->estop_lines, (unsigned long long)S->estop_presses,
		(unsigned long long)S->estop_cycles,
		(long long)S->estop_to_safe_ns, (long long)S->estop_to_safe_cycles,
		(unsigned long long)S->safe_cycles_before_estop, S->safe_at_estop,
		(unsigned long long)S->enable_write_errors);
}

/* Every device's counters, and the CANopen drives' states. */
static void json_devices(FILE *f, const struct run_result *r)
{
	struct px_app *app = r->app;
	struct px_canopen *co = px_app_canopen(app);
	int i, n_drives = r->sum->n_drives;
	fputs("  \"devices\": [", f);
	for (i = 0; i < px_app_device_count(app); i++) {
		struct px_dev_status s;
		if (px_dev_status(px_app_device_at(app, i), &s) != PX_OK)
			continue;
		fprintf(f, "%s\n    {\"name\": ", i ? "," : "");
		json_string(f, s.name);
		fprintf(f, ", \"backend\": ");
		json_string(f, s.backend);
		fprintf(f,
			", \"state\": %d, \"reports\": %llu, \"samples\": %llu, "
			"\"writes\": %llu, \"write_errors\": %llu, \"errors\": "
			"%llu, \"last_error\": ",
			s.state, (unsigned long long)s.reports,
			(unsigned long long)s.samples, (unsigned long long)s.writes,
			(unsigned long long)s.write_errors,
			(unsigned long long)s.errors);
		json_string(f, s.last_msg);
		fputc('}', f);
	}
	fputs(px_app_device_count(app) ? "\n  ],\n" : "],\n", f);
	fprintf(f,
		"  \"drives_enabled_cycles\": %llu,\n"
		"  \"drive_problem_cycles\": %llu,\n  \"drives\": [",
		(unsigned long long)r->sum->drives_enabled_cycles,
		(unsigned long long)r->sum->drive_problem_cycles);
	for (i = 0; co && i < n_drives; i++) {
		struct px_canopen_drive_status ds;
		if (px_canopen_drive_status(co, (size_t)i, &ds) != PX_OK)
			continue;
		fprintf(f,
			"%s\n    {\"node_id\": %d, \"state\": \"%s\", "
			"\"position\": %.9g, \"lost\": %d, \"emcy\": %llu}",
			i ? "," : "", ds.node_id, px_cia402_state_name(ds.state),
			run_finite(ds.position), ds.lost,
			(unsigned long long)ds.emcy_count);
	}
	fputs(co && n_drives ? "\n  ],\n" : "],\n", f);
}

/* The shutdown as a JSON object, with what each simulated device last
 * received. */
static void json_shutdown(FILE *f, const struct run_result *r)
{
	const struct px_app_summary *S = r->sum;
	int i, first = 1;
	fprintf(f,
		"  \"shutdown\": {\"shutdown_safe\": %d, \"shutdown_reason\": "
		"\"%s\", \"force_devices\": %d, \"force_zeroed\": %d, "
		"\"relay_devices\": %d, \"relays_off\": %d, "
		"\"shutdown_drives\": %d, \"drives_disabled\": %d, "
		"\"drives_faulted\": %d, \"shutdown_ns\": %lld, "
		"\"shutdown_error\": ",
		S->shutdown_safe, S->shutdown_reason, S->force_devices,
		S->force_zeroed, S->relay_devices, S->relays_off,
		S->shutdown_drives, S->drives_disabled, S->drives_faulted,
		(long long)S->shutdown_ns);
	json_string(f, S->shutdown_error);
	fputs(", \"last_outputs\": [", f);
	for (i = 0; i < px_app_device_count(r->app); i++) {
		struct px_dev *d = px_app_device_at(r->app, i);
		struct px_sim_haptic_state hs;
		struct px_dev_status st;
		int relay;
		px_dev_status(d, &st);
		if (px_sim_haptic_state(d, &hs) == PX_OK &&
		    (px_dev_caps(d) & PX_DEV_CAP_FORCE)) {
			fprintf(f, "%s{\"name\": ", first ? "" : ", ");
			json_string(f, st.name);
			fprintf(f,
				", \"last_force_n\": [%.9g, "
				"%.9g, %.9g], \"last_torque_n_m\": [%.9g, %.9g, "
				"%.9g], \"last_enable\": %d, \"outputs_safe\": %d}",
				hs.force_n[0],
				hs.force_n[1], hs.force_n[2], hs.torque_n_m[0],
				hs.torque_n_m[1], hs.torque_n_m[2], hs.enable,
				st.outputs_safe);
			first = 0;
		} else if ((relay = px_gpio_sim_output(d,
						       PX_GPIO_ENABLE)) >= 0) {
			fprintf(f, "%s{\"name\": ", first ? "" : ", ");
			json_string(f, st.name);
			fprintf(f,
				", \"enable_line\": %d, "
				"\"timing_line\": %d, \"outputs_safe\": %d}",
				relay,
				px_gpio_sim_output(d, PX_GPIO_TIMING),
				st.outputs_safe);
			first = 0;
		}
	}
	fputs("]},\n", f);
}

static void json_campaign(FILE *f, const struct px_app_summary *S)
{
	size_t i;
	fputs("  \"fault_campaign\": [", f);
	for (i = 0; i < S->n_reactions; i++) {
		const struct px_app_reaction *r = &S->reactions[i];
		fprintf(f, "%s\n    {\"kind\": \"%s\", \"device\": ", i ? "," : "",
			r->kind);
		json_string(f, r->device);
		fprintf(f,
			", \"start_ns\": %lld, \"duration_ns\": %lld, "
			"\"loop_faults\": %llu, \"safe_after_ns\": %lld}",
			(long long)r->start_ns, (long long)r->duration_ns,
			(unsigned long long)r->loop_faults,
			(long long)r->safe_after_ns);
	}
	fputs(S->n_reactions ? "\n  ],\n" : "],\n", f);
}

int run_write_json(const struct run_result *r, const char *path,
		   const char *time_svg, const char *lat_svg, char *why,
		   size_t cap)
{
	static struct tool_out out;
	const struct px_app_summary *S = r->sum;
	FILE *f;
	if (tool_out_open(&out, path) != 0) {
		snprintf(why, cap, "%s", out.why);
		return -1;
	}
	f = out.f;
	json_timing(f, r);
	json_figures(f, r);
	json_safety(f, r);
	json_devices(f, r);
	json_shutdown(f, r);
	fprintf(f,
		"  \"faults_injected\": %zu,\n  \"faults_popped\": %llu,\n"
		"  \"watchdog_trips_checked\": %llu,\n"
		"  \"max_trip_to_safe_cycles\": %lld,\n"
		"  \"nonfinite_outputs\": %llu,\n"
		"  \"phase_error_ns\": %lld,\n",
		S->faults_injected, (unsigned long long)S->faults_popped,
		(unsigned long long)S->watchdog_trips_checked,
		(long long)S->max_trip_to_safe_cycles,
		(unsigned long long)S->nonfinite_outputs,
		(long long)S->phase_error_ns);
	json_campaign(f, S);
	fprintf(f,
		"  \"allocations_after_setup\": %llu,\n"
		"  \"allocations_setup\": %llu,\n"
		"  \"allocation_counter\": \"%s\",\n"
		"  \"telemetry_records\": %llu,\n  \"telemetry_dropped\": %llu,\n"
		"  \"telemetry_decimation\": %lld,\n"
		"  \"realtime\": %d,\n  \"csv\": ",
		(unsigned long long)S->allocations_after_setup,
		(unsigned long long)r->setup_heap_calls, r->counter,
		(unsigned long long)S->telemetry_records,
		(unsigned long long)S->telemetry_dropped, (long long)S->decimation,
		r->st.realtime);
	if (S->csv_path[0])
		json_string(f, S->csv_path);
	else
		fputs("null", f);
	fputs(",\n  \"plots\": [", f);
	json_string(f, time_svg);
	fputs(", ", f);
	json_string(f, lat_svg);
	fputs("]\n}\n", f);
	if (tool_out_commit(&out) != 0) {
		snprintf(why, cap, "%s", out.why);
		return -1;
	}
	return 0;
}
