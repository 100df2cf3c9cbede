/*
 * px_app.h - a whole proxima application from its loaded config: the
 * devices, the scene, the control, the 1 kHz loop and its safety policy.
 *
 * What: px_app_create() validates the config and opens what it names
 * (simulated haptic/pose devices, every px_devcfg back end, a CANopen arm
 * on the in-process or a UNIX-socket bus, the fault campaign of the `sim`
 * section and of opt->faults), then makes the px_loop whose read, compute
 * and write phases are this module's. The safety policy lives here: the
 * velocity-limit trip, e-stop lines (a press trips, a release never
 * restarts motion by itself), the enable relay (off in safe state), the
 * CANopen drives held and quick-stopped in safe state, and
 * px_app_shutdown(): zero force, relays off, drives quick-stopped and
 * disabled, each confirmed within a bounded wait, before any device
 * closes. px_app_free() runs it too (reason "setup error") when it has
 * not run yet.
 *
 * Threads: create, run (or step, or the phases), drain, shutdown and
 * free belong to one control thread. With the real clock px_app_run()
 * runs the loop on its own thread (the config's real-time setup) and
 * drains telemetry on the calling thread; on the virtual clock it steps
 * the loop on the calling thread.
 * px_app_stop() is async-signal-safe and may be called from any thread.
 *
 * Memory: everything is allocated by create (telemetry ring, statistics,
 * devices); the cycle phases allocate nothing, take no lock and do no I/O
 * but device calls. Messages (errors, warnings, notes) are text passed to
 * opt->note in order; the library prints nothing itself.
 *
 * Real time: the phases (through the loop) are RT-safe; everything else
 * here is setup or non-real-time.
 */
#ifndef PX_APP_H
#define PX_APP_H

#include <stddef.h>
#include <stdint.h>

#include "px_base.h"
#include "px_config.h"
#include "px_dev.h"
#include "px_canopen.h"
#include "px_cloud_feed.h"
#include "px_control.h"
#include "px_loop.h"
#include "px_stats.h"
#include "px_scene.h"
#include "px_urdf.h"

#ifdef __cplusplus
extern "C" {
#endif

struct px_app;

/* Joints whose commanded velocity a record carries. */
#define PX_APP_RECORD_JOINTS 6
/* At most this many --fault style entries in px_app_options. */
#define PX_APP_MAX_CLI_FAULTS 64

/* One telemetry record, pushed by the write phase every
 * telemetry.decimation-th cycle and read by px_app_drain(). */
struct px_app_record {
	double t_s;
	uint64_t cycle;
	double dev_m[3], proxy_m[3], force_n[3];
	double force_mag_n;
	double distance_m;    /* NaN: no meaningful distance this cycle */
	double penetration_m;
	int64_t latency_ns, compute_ns;
	int32_t contact, safe, queries, valid;
	/* avoidance: speed scale and commanded joint velocities */
	double scale, qdot[PX_APP_RECORD_JOINTS];
	/* avoidance: the drives' joint positions (rad or m; single
	 * precision keeps the record small: 1e-7 of a turn) */
	float q[PX_APP_RECORD_JOINTS];
	/* the device's orientation (identity for a point device) */
	float dev_quat_xyzw[4];
};

struct px_app_options {
	const char *name;      /* starts the messages; NULL: "px_app" */
	const char *config;    /* the config's path: base of relative files */
	int check;             /* validate, open only in-process devices */
	int virtual_time;      /* loop on the virtual clock */
	double duration_s;     /* run length in loop time; 0: until stopped */
	const char *summary_json; /* an output path to check, or NULL */
	const char *telemetry; /* CSV path overriding telemetry.file */
	/* entries KIND,DEVICE,START_S,DURATION_S[,PROBABILITY[,DELAY_S]]
	 * added to sim.faults */
	const char *faults[PX_APP_MAX_CLI_FAULTS];
	int n_faults;
	int alloc_probe;       /* cycle 10 allocates once (counter self-check) */
	/* run after this many cycles: at_cycle(user) is called once (0 none) */
	uint64_t stop_at_cycle;
	/* hooks, each optional; user is passed back */
	void *user;
	void (*note)(void *user, const char *text); /* message text, in order */
	uint64_t (*heap_count)(void);  /* heap calls of the calling thread */
	int (*output_check)(void *user, const char *path, char *why, size_t cap);
	void (*input_protect)(void *user, const char *path, const char *what);
	void (*tick)(void *user);      /* between batches of px_app_run */
	void (*at_cycle)(void *user);
	void (*record)(void *user, const struct px_app_record *r);
};

PX_API void px_app_options_default(struct px_app_options *opt);

/*
 * Validate cfg and, unless opt->check, open everything and make the loop.
 * cfg is the caller's and must outlive the app. Returns PX_OK, PX_E_INVAL
 * (options refused: an output path, a fault entry, the virtual clock with
 * hardware), PX_E_PARSE (the config is invalid or setup failed) or
 * PX_E_NOMEM; msg gets the first message line, every message has gone to
 * opt->note. On failure everything opened is back in the safe state and
 * closed.
 */
PX_API int px_app_create(const struct px_config *cfg,
			 const struct px_app_options *opt, struct px_app **out,
			 char *msg, size_t cap);

/* The config's warnings (e.g. auto_rearm beside an e-stop) to opt->note. */
PX_API void px_app_warnings(struct px_app *app);

/* The app's loop (its phases attached), to step or inspect. */
PX_API struct px_loop *px_app_loop(struct px_app *app);

/* The app's devices in config order (0 <= i < px_app_device_count). */
PX_API int px_app_device_count(const struct px_app *app);
PX_API struct px_dev *px_app_device_at(struct px_app *app, int i);

/* The compute phase's duration statistics (wall clock), and the CANopen
 * master of the arm (NULL: none); the app owns both. */
PX_API struct px_stats *px_app_compute_stats(struct px_app *app);
PX_API struct px_canopen *px_app_canopen(struct px_app *app);

/* The scene the loop queries (NULL: none), for queries from a
 * non-real-time thread beside the loop (as px_app_drain() makes); the
 * app owns it. */
PX_API const struct px_scene *px_app_scene(const struct px_app *app);

/* The arm of an avoidance run, for drawing it beside the loop (a view):
 * what setup made, never changed while the loop runs. */
struct px_app_arm {
	const struct px_control_chain *chain; /* joints; capsules unless robot */
	const struct px_urdf_robot *robot;    /* URDF link models, or NULL */
	const int *joint_perm; /* record joint i is chain joint joint_perm[i];
				* NULL: the same */
	int record_joints;     /* joints a record's q carries */
	double protective_distance_m, influence_distance_m;
	/* sim.depth_sensor: its feed of clouds (NULL: none); a reader
	 * pins the frame it copies (px_cloud_feed_pin()) */
	struct px_cloud_feed *cloud_feed;
};

/* 1 and *out for an app in avoidance mode (also one made to check its
 * config), else 0. */
PX_API int px_app_arm(struct px_app *app, struct px_app_arm *out);

/* The newest drained record: 1 and *out, or 0 before any. */
PX_API int px_app_last_record(const struct px_app *app,
			      struct px_app_record *out);

/* The device of that config name (NULL: none), e.g. for a simulated
 * device's state (px_sim_haptic_state). The app owns it. */
PX_API struct px_dev *px_app_device(struct px_app *app, const char *name);

/* Run until the duration, px_app_stop() or a loop error; drains into
 * opt->record. Returns PX_OK or the loop's error. */
PX_API int px_app_run(struct px_app *app);

/* One cycle (read, compute, write) on the calling thread: the caller's
 * own loop steps the app (on the virtual clock it returns at once, on the
 * real one after the cycle's deadline). Returns PX_OK, PX_LOOP_STOP or the
 * loop's error. RT-safe on the app's side (no allocation, no I/O but
 * device calls); drain from time to time so the ring does not fill. */
PX_API int px_app_step(struct px_app *app);

/*
 * One cycle phase by phase from the caller's own thread and clock (a
 * program with its own 1 kHz loop): px_app_read(), px_app_compute(),
 * px_app_write(), in that order, once each per cycle. They are
 * px_loop_read/compute/write (px_loop.h) on the app's loop: the app's
 * device reads, control and writes with the loop's watchdog and safe
 * state between them, the same cycle as px_app_step() at the same times.
 * now_ns as there: the simulated time on the virtual clock,
 * CLOCK_MONOTONIC on the real one. The caller's own work goes before
 * px_app_read() or after px_app_write(); px_app_loop() gives the loop's
 * status, trips and re-arm. Returns PX_OK, PX_LOOP_STOP (a phase asked to
 * stop: finish the cycle), PX_E_INVAL (NULL) or PX_E_STATE: out of order,
 * a check-only app, or after px_app_shutdown() (a write then would undo
 * the safe state). RT-safe as px_app_step(); drain between cycles or
 * from one other thread (as px_app_run() does on the real clock).
 */
PX_API int px_app_read(struct px_app *app, int64_t now_ns);
PX_API int px_app_compute(struct px_app *app, int64_t now_ns);
PX_API int px_app_write(struct px_app *app, int64_t now_ns);

/* Ask the run to end. Async-signal-safe. */
PX_API void px_app_stop(struct px_app *app);

/* Pop the telemetry records (into record(user, r), may be NULL) and the
 * loop's faults (counted). Non-real-time thread. */
PX_API void px_app_drain(struct px_app *app,
			 void (*record)(void *user, const struct px_app_record *r),
			 void *user);

/* The safe state before anything closes (once; reason is reported).
 * Returns PX_OK when every output was confirmed safe, else PX_E_TIMEOUT. */
PX_API int px_app_shutdown(struct px_app *app, const char *reason);

/* "safe (force zeroed on 1/1 device, ...) after REASON in 0.0 ms" */
PX_API void px_app_shutdown_describe(const struct px_app *app, char *buf,
				     size_t cap);

/* At most this many fault windows (sim.faults and opt.faults together). */
#define PX_APP_MAX_CAMPAIGN 64

/* How the loop reacted to one fault window of the campaign: the loop
 * faults from the window's start to its end plus the device's timeout
 * (and 10 ms), and how long after the start the first of them found the
 * loop in safe state. */
struct px_app_reaction {
	const char *kind;       /* "drop", "delay", ..., "overrun" */
	const char *device;     /* the app's; valid until px_app_free */
	int64_t start_ns, duration_ns; /* from the run's start */
	double probability;
	uint64_t loop_faults;
	int64_t safe_after_ns;  /* -1: no safe state (samples stayed fresh) */
};

/* The figures of the run so far (after px_app_shutdown: of the whole
 * run), the numbers proxima-run prints. Non-real-time thread; call
 * px_app_drain() first for the drained counts to be complete. */
struct px_app_summary {
	uint64_t cycles, overruns, missed_periods;
	double loop_time_s;
	double max_force_n;           /* over every cycle */
	uint64_t contact_cycles;
	double min_distance_m;        /* INFINITY: no distance seen */
	double max_penetration_m;
	double min_proxy_distance_m;  /* of the drained records */
	double min_clearance_m;       /* avoidance: the arm's least clearance */
	uint64_t safe_state_trips;    /* entries into safe state */
	uint64_t velocity_trips;
	uint64_t query_errors;
	uint64_t estop_presses, estop_cycles;
	uint64_t telemetry_records;   /* drained */
	uint64_t telemetry_dropped;
	uint64_t faults_popped;
	uint64_t allocations_after_setup; /* 0 without opt.heap_count */
	/* the shutdown (px_app_shutdown): outputs made safe and confirmed */
	int shutdown_done, shutdown_safe;
	char shutdown_reason[32];     /* "end of run", "SIGINT", ... */
	int force_devices, force_zeroed;
	int relay_devices, relays_off;
	int shutdown_drives, drives_disabled, drives_faulted;
	int64_t shutdown_ns;          /* loop clock */
	char shutdown_error[320];     /* the first failure, "" when safe */
	/* every loop fault that found the loop in safe state, checked
	 * against the per-cycle record: how many, and the most cycles from
	 * the fault to safe state (-1: none checked) */
	uint64_t watchdog_trips_checked;
	int64_t max_trip_to_safe_cycles;
	size_t n_reactions;
	struct px_app_reaction reactions[PX_APP_MAX_CAMPAIGN];
	/* what the app is (known from create on) */
	size_t scene_models;
	int rendering;                /* haptic rendering on control.device */
	int proxy_renderer;           /* ... with the proxy renderer */
	int avoiding;                 /* avoidance on a CANopen arm */
	int distance_reported;        /* a pose device's distance is followed */
	int record_joints;            /* joints a record's qdot carries */
	uint64_t max_cycles;          /* 0: until stopped */
	int64_t decimation;           /* a record every this many cycles */
	double force_clamp_n, protective_distance_m, influence_distance_m;
	char csv_path[1024], time_svg[1100], lat_svg[1100]; /* "" none */
	/* the run */
	int ended_by_time;            /* real clock: the duration's time gone */
	int64_t phase_error_ns;       /* deadlines' span minus the cycles' */
	double min_speed_scale;
	uint64_t stop_cycles;         /* avoidance: nominal motion stopped */
	uint64_t cloud_swaps;         /* sim.depth_sensor: frames swapped in */
	int last_query_error;
	uint64_t faults_by_cause[PX_FAULT__COUNT];
	size_t faults_injected;
	uint64_t nonfinite_outputs;
	int estop_lines;
	int64_t estop_to_safe_ns, estop_to_safe_cycles; /* -1: no press/safe */
	uint64_t safe_cycles_before_estop;
	int safe_at_estop;
	uint64_t enable_write_errors;
	int n_drives;
	const char *drives_device;    /* the CANopen arm's device, or NULL */
	uint64_t drives_enabled_cycles, drive_problem_cycles;
	int tracking_enabled, tracking_streams;
	struct px_model_stream_stats tracking;
	/* remote (dds) devices and teleoperation: the link (samples in and
	 * out of every dds device, best-effort samples known lost), a live
	 * remote input that went silent (latched safe state: the device,
	 * loop time), a follower's tool against its target (outside safe
	 * state, after engagement) */
	int dds_devices;
	uint64_t remote_in, remote_out, remote_lost;
	/* remote parameter sets: accepted (within the configured ranges),
	 * refused (non-finite or out of range), applied by the cycle */
	uint64_t params_accepted, params_refused, params_applied;
	/* remote scene updates (teleop.scene_device): clouds built into the
	 * feed, refused (frame, fields, sizes, points, workspace), dropped
	 * (the feed full); model poses accepted, refused, applied */
	uint64_t clouds_accepted, clouds_refused, clouds_dropped;
	uint64_t scene_poses_accepted, scene_poses_refused, scene_poses_applied;
	int link_lost;
	char link_lost_device[32];
	double link_lost_t_s;
	int64_t link_silent_ns;       /* its last sample's age then */
	uint64_t follow_cycles;
	double follow_error_max_m, follow_error_rms_m;
};

PX_API int px_app_summary(const struct px_app *app, struct px_app_summary *out);

/* Shutdown if not done, close everything. NULL is a no-op. */
PX_API void px_app_free(struct px_app *app);

#ifdef __cplusplus
}
#endif

#endif
