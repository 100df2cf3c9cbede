/*
 * run_report.c - proxima-run's printed summary (run_internal.h).
 */
#include <stdio.h>

#include "px_canopen.h"
#include "run_internal.h"

const char *run_ended_by(const struct run_result *r)
{
	if (r->sum->max_cycles && r->st.cycles >= r->sum->max_cycles)
		return "cycles";
	if (r->sum->ended_by_time)
		return "time";
	return r->interrupted ? "signal" : "stop";
}

void run_shutdown_line(struct px_app *app, FILE *f, const char *prefix)
{
	char line[1024];
	px_app_shutdown_describe(app, line, sizeof(line));
	fprintf(f, "%s%s\n", prefix, line);
}

static void print_campaign(const struct px_app_summary *S)
{
	size_t i;
	if (!S->n_reactions)
		return;
	printf("  fault campaign    (loop faults from each window's start to "
	       "its end + device timeout)\n");
	for (i = 0; i < S->n_reactions; i++) {
		const struct px_app_reaction *r = &S->reactions[i];
		printf("    %-9s %-8s %7.3f..%7.3f s p %.2f: %4llu loop faults, ",
		       r->kind, r->device, (double)r->start_ns * 1e-9,
		       (double)(r->start_ns + r->duration_ns) * 1e-9, r->probability,
		       (unsigned long long)r->loop_faults);
		if (r->safe_after_ns >= 0)
			printf("safe state after %.1f ms\n", (double)r->safe_after_ns * 1e-6);
		else
			printf("no safe state (samples stayed fresh)\n");
	}
}

/* The cycles, the clocks, the overruns and the two timing figures. */
static void print_timing(const struct run_result *r)
{
	const struct px_loop_status *st = &r->st;
	const struct px_app_options *O = r->opt;
	double wall_s = r->wall_s;
	printf("proxima-run: %s (%s clock)\n", O->config,
	       O->virtual_time ? "virtual" : "monotonic");
	printf("  cycles            %llu in %.3f s simulated, %.3f s wall "
	       "(%.0f cycles/s)\n",
	       (unsigned long long)st->cycles,
	       (double)st->cycles * (double)st->period_ns * 1e-9, wall_s,
	       wall_s > 0 ? (double)st->cycles / wall_s : 0.0);
	printf("  time              loop clock %.3f s (%llu missed period%s), "
	       "wall %.3f s; ",
	       r->sum->loop_time_s, (unsigned long long)st->missed_periods,
	       st->missed_periods == 1 ? "" : "s", wall_s);
	if (O->duration_s > 0)
		printf("--duration-s %g: ended by %s\n", O->duration_s,
		       run_ended_by(r));
	else
		printf("until stopped: ended by %s\n", run_ended_by(r));
	printf("  overruns          %llu (missed periods %llu)%s\n",
	       (unsigned long long)st->overruns,
	       (unsigned long long)st->missed_periods,
	       O->virtual_time ? ""
	       : st->realtime   ? " on SCHED_FIFO"
				: " (not real-time scheduled)");
	printf("  wake-up latency   p50 %.1f us, p99 %.1f us, p99.9 %.1f us, "
	       "max %.1f us\n",
	       r->lat.p50_ns / 1e3, r->lat.p99_ns / 1e3, r->lat.p999_ns / 1e3,
	       r->lat.max_ns / 1e3);
	printf("  compute           p50 %.1f us, p99 %.1f us, p99.9 %.1f us, "
	       "max %.1f us\n",
	       r->cmp.p50_ns / 1e3, r->cmp.p99_ns / 1e3, r->cmp.p999_ns / 1e3,
	       r->cmp.max_ns / 1e3);
}

/* The safe state's line; the e-stop, drives and tracking lines after it
 * each start with the newline that ends the line before. */
static void print_safety(const struct run_result *r)
{
	const struct px_app_summary *S = r->sum;
	const struct px_loop_status *st = &r->st;
	struct px_canopen *co = px_app_canopen(r->app);
	int k;
	printf("  safe state        %llu trip%s",
	       (unsigned long long)st->safe_entries,
	       st->safe_entries == 1 ? "" : "s");
	for (k = 1; k < PX_FAULT__COUNT; k++)
		if (S->faults_by_cause[k])
			printf(", %s %llu", px_fault_cause_name(k),
			       (unsigned long long)S->faults_by_cause[k]);
	if (S->velocity_trips)
		printf(", velocity limit %llu", (unsigned long long)S->velocity_trips);
	if (S->query_errors)
		printf(", query errors %llu (last: %s)",
		       (unsigned long long)S->query_errors,
		       px_strerror(S->last_query_error));
	if (S->estop_lines)
		printf("\n  e-stop            %llu press%s, held %llu cycles%s",
		       (unsigned long long)S->estop_presses,
		       S->estop_presses == 1 ? "" : "es",
		       (unsigned long long)S->estop_cycles,
		       st->safe ? "; in safe state at the end" : "");
	if (co) {
		int i, n = 0;
		for (i = 0; i < S->n_drives; i++) {
			struct px_canopen_drive_status ds;
			if (px_canopen_drive_status(co, (size_t)i, &ds) == PX_OK &&
			    ds.state == PX_CIA402_OPERATION_ENABLED)
				n++;
		}
		printf("\n  drives            %d on '%s', enabled in %llu cycles, "
		       "%d in operation enabled at the end",
		       S->n_drives, S->drives_device,
		       (unsigned long long)S->drives_enabled_cycles, n);
	}
	if (S->tracking_enabled) {
		struct px_model_stream_stats ts = S->tracking;
		int ns = S->tracking_streams;
		double q = ts.queries ? (double)ts.queries : 1.0;
		printf("\n  tracking          %d stream%s: %llu answers, %.1f %% "
		       "tracked (%.1f %% hot), %.1f %% global, %.1f %% cold, "
		       "%llu jumps, %llu verified, %llu disagreements",
		       ns, ns == 1 ? "" : "s", (unsigned long long)ts.queries,
		       100.0 * (double)ts.tracked / q, 100.0 * (double)ts.hot / q,
		       100.0 * (double)ts.global / q, 100.0 * (double)ts.cold / q,
		       (unsigned long long)ts.jumps,
		       (unsigned long long)ts.verifications,
		       (unsigned long long)ts.disagreements);
	}
}

void run_print_summary(const struct run_result *r)
{
	const struct px_app_summary *S = r->sum;
	const struct px_loop_status *st = &r->st;
	print_timing(r);
	if (S->rendering)
		printf("  force             max %.3f N (clamp %.3f N), contact "
		       "in %.1f %% of cycles\n",
		       S->max_force_n, S->force_clamp_n,
		       st->cycles ? 100.0 * (double)S->contact_cycles /
					    (double)st->cycles
				  : 0.0);
	if (S->avoiding)
		printf("  avoidance         min clearance %.1f mm (protective %.1f "
		       "mm, influence %.1f mm), speed scale min %.2f, nominal "
		       "motion stopped in %llu cycles\n",
		       run_finite(S->min_clearance_m) * 1e3,
		       S->protective_distance_m * 1e3,
		       S->influence_distance_m * 1e3, S->min_speed_scale,
		       (unsigned long long)S->stop_cycles);
	if (S->avoiding && S->cloud_swaps)
		printf("  obstacle cloud    %llu frames swapped in\n",
		       (unsigned long long)S->cloud_swaps);
	else if (S->distance_reported)
		printf("  distance          min %+.3f mm, max penetration %.3f mm, "
		       "proxy min clearance %+.3f mm\n",
		       run_finite(S->min_distance_m) * 1e3,
		       S->max_penetration_m * 1e3,
		       run_finite(S->min_proxy_distance_m) * 1e3);
	if (S->dds_devices) {
		printf("  remote            %d dds device%s: %llu samples in, %llu "
		       "out, %llu known lost",
		       S->dds_devices, S->dds_devices == 1 ? "" : "s",
		       (unsigned long long)S->remote_in,
		       (unsigned long long)S->remote_out,
		       (unsigned long long)S->remote_lost);
		if (S->params_accepted || S->params_refused)
			printf("; parameters %llu accepted, %llu refused",
			       (unsigned long long)S->params_accepted,
			       (unsigned long long)S->params_refused);
		if (S->clouds_accepted || S->clouds_refused || S->clouds_dropped)
			printf("; clouds %llu accepted, %llu refused, %llu dropped",
			       (unsigned long long)S->clouds_accepted,
			       (unsigned long long)S->clouds_refused,
			       (unsigned long long)S->clouds_dropped);
		if (S->scene_poses_accepted || S->scene_poses_refused)
			printf("; model poses %llu accepted, %llu refused, %llu "
			       "applied",
			       (unsigned long long)S->scene_poses_accepted,
			       (unsigned long long)S->scene_poses_refused,
			       (unsigned long long)S->scene_poses_applied);
		if (S->link_lost)
			printf("; link lost ('%s' silent %.1f ms at %.3f s: safe "
			       "state latched)",
			       S->link_lost_device, (double)S->link_silent_ns * 1e-6,
			       S->link_lost_t_s);
		printf("\n");
		if (S->follow_cycles)
			printf("  following         tool to target: max %.1f mm, "
			       "rms %.1f mm over %llu cycles\n",
			       S->follow_error_max_m * 1e3,
			       S->follow_error_rms_m * 1e3,
			       (unsigned long long)S->follow_cycles);
	}
	print_safety(r);
	if (!r->counted)
		printf("\n  allocations       not counted (no heap counter: "
		       "preload libproxima-alloc-count.so)\n");
	else
		printf("\n  allocations       %llu after setup (loop thread; "
		       "setup made %llu)\n",
		       (unsigned long long)S->allocations_after_setup,
		       (unsigned long long)r->setup_heap_calls);
	printf("  telemetry         %llu records (every %lld cycles), %llu "
	       "dropped\n",
	       (unsigned long long)S->telemetry_records, (long long)S->decimation,
	       (unsigned long long)S->telemetry_dropped);
	run_shutdown_line(r->app, stdout, "  shutdown          ");
	print_campaign(S);
}
