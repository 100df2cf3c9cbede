/*
 * app_internal.h - the app module's private state and the functions its
 * files share (app_check.c: the sim section and the checks; app_setup.c:
 * devices, setup, teardown; app_cycle.c: the phases, the shutdown, the
 * drain and the run; px_app.c: the public calls).
 */
#ifndef PX_APP_INTERNAL_H
#define PX_APP_INTERNAL_H

#include <errno.h>
#include <math.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "px_app.h"
#include "px_arena.h"
#include "px_bridge.h"
#include "px_can.h"
#include "px_canopen.h"
#include "px_cloud.h"
#include "px_cloud_feed.h"
#include "px_config.h"
#include "px_control.h"
#include "px_depth_sim.h"
#include "px_dev.h"
#include "px_devcfg.h"
#include "px_gpio.h"
#include "px_loop.h"
#include "px_ring.h"
#include "px_sim.h"
#include "px_stats.h"
#include "px_scene.h"
#include "px_urdf.h"

#define APP_WHY_MAX 2560

/* ---- the `sim` section: fault campaigns --------------------------- */

#define SIM_RANGE (PX_CONFIG_HAS_MIN | PX_CONFIG_HAS_MAX)
#define MAX_CAMPAIGN PX_APP_MAX_CAMPAIGN

/* Fault kinds a simulated haptic/pose device takes (enum px_sim_fault_kind
 * is index + 1). */
/* Index + 1 is the px_sim fault kind (px_sim.h), up to estop; overrun
 * is the runner's own (the compute phase takes delay_ns). */
extern const char *const app_fault_kind_names[];
enum {
	FK_DROP, FK_DELAY, FK_DUPLICATE, FK_CORRUPT, FK_STUCK, FK_NAN,
	FK_UNPLUG, FK_BUS_OFF, FK_ESTOP, FK_OVERRUN
};

struct raw_fault {
	const char *device;
	int kind;
	int64_t start_ns, duration_ns, delay_ns;
	double probability;
};

/* Nominal joint velocity of the avoidance demo's task: a sum of
 * sinusoids per joint. */
struct raw_nominal {
	int64_t joint;
	double amplitude_rad_per_s, frequency_hz, phase_rad;
};

/* sim.depth_sensor: a simulated depth camera (app_sensor.c) */
struct raw_depth_pose {
	double xyz_m[3], rpy_rad[3];
};

struct raw_depth {
	int kind;
	struct raw_depth_pose camera;
	int64_t width, height, seed, slots;
	double fov_x_rad, max_range_m, noise_m, rate_hz;
	double size_m[3], from_m[3], to_m[3];
	double start_s, period_s;
	int64_t lookahead_ns, stale_timeout_ns;
};
extern const struct px_config_schema app_depth_schema;

struct raw_sim {
	struct raw_fault *faults;
	size_t n_faults;
	struct raw_nominal *nominal;
	size_t n_nominal;
	const char *spawn_arm; /* a socketcan device on transport unix */
	struct raw_depth depth;
	bool has_depth;
	const struct px_config *cfg_; /* not a key: context for the check */
};


/* The teleop section (app_teleop.c). */
struct raw_teleop {
	const char *follow_device, *feedback_device, *force_device;
	double follow_scale, follow_gain_per_s, follow_max_speed_m_per_s;
	double feedback_max_force_n;
	const char *params_device;
	struct px_bridge_params params_min, params_max;
	bool has_params_max;
	/* scene updates (app_teleop.c): the one source, the models it may
	 * pose, the box its points and positions must keep to, the largest
	 * cloud */
	const char *scene_device;
	const char **scene_models;
	size_t n_scene_models;
	double workspace_min_m[3], workspace_max_m[3];
	bool has_ws_min, has_ws_max;
	int64_t cloud_max_points;
};

/* Remote devices and teleoperation; device indices into px_app.dev,
 * -1 none. */
struct app_teleop {
	struct raw_teleop c;
	struct px_bridge_config bridge; /* domain, network of dds devices */
	struct {
		int dev;
		int64_t tmo_ns, connect_ns;
		int pose_out;
		int input; /* its loop input (pose devices), -1 none */
	} dds[64]; /* MAX_DEVS */
	int n_dds;
	int follow, feedback, force, params;
	/* scene updates: teleop.scene_device (index in px_app.dev, -1
	 * none), its dds entry, the scene index of each scene model, the
	 * sequence of each model's pose last applied, poses applied */
	int scene, scene_dds, scene_cloud;
	int scene_model[PX_BRIDGE_SCENE_MODELS];
	uint64_t scene_seq[PX_BRIDGE_SCENE_MODELS];
	uint64_t scene_poses_applied;
	double speed_scale;     /* remote parameter on the follow task */
	uint64_t params_applied;
	int force_input;        /* loop input of the remote force */
	/* follower: offset caught at engagement, the last tracking error */
	int engaged;
	double offset_m[3], error_m[3];
	uint64_t follow_cycles;
	double follow_err_max_m, follow_err_sq_sum;
	struct px_force_cmd fb_cmd; /* force from the clearances */
	/* master: the newest remote force and its receipt (loop clock) */
	double remote_force_n[3];
	int64_t force_t_ns;
	/* a live remote input went silent: latched safe state */
	int link_lost, link_lost_dev;
	int64_t link_lost_ns, link_silent_ns;
};

/* Bound of each of the shutdown's waits (devices, then each CANopen
 * master's drives): an unplugged device gets its safe output as soon as
 * it is back within it, drives must confirm within it. Loop clock. */
#define SHUTDOWN_TIMEOUT_NS 1000000000

/* What the shutdown did: summary, JSON and exit status. */
struct shutdown_report {
	int done, safe;
	char reason[32];        /* "end of run", "SIGINT", "setup error", ... */
	int force_devs, force_zeroed;
	int dio_devs, relays_off;
	int drives, drives_disabled, drives_faulted;
	int64_t elapsed_ns;     /* loop clock */
	char why[320];          /* the first failure, "" when safe */
};

/* ---- the application ----------------------------------------------- */

#define MAX_DEVS 64
_Static_assert(MAX_DEVS == 64, "app_teleop.dds holds MAX_DEVS entries");
#define TELE_JOINTS PX_APP_RECORD_JOINTS
#define PLOT_MAX ((size_t)1 << 20)


struct px_app {
	struct px_app_options o;
	struct px_config *cfg;
	struct px_control_config ctl;
	struct px_scene *scene;
	struct px_scene_hints hints; /* coherent queries of the loop thread */
	/* haptic mode, scene.tracking on: the renderer's queries follow one
	 * point through tracked streams (NULL otherwise) */
	struct px_scene_tracking *tracking;
	struct px_control_query query;
	struct px_control_haptic haptic;
	struct px_dev *dev[MAX_DEVS];
	struct px_pose_sample sample[MAX_DEVS];
	struct px_sim_csv *csv[MAX_DEVS];
	struct px_codec_field *fields[MAX_DEVS][2];
	struct px_codec_buttons *buttons[MAX_DEVS];
	struct px_codec_map codec[MAX_DEVS];
	int n_dev;
	/* devices opened through px_devcfg (every back end but the
	 * simulated haptic/pose devices, which take the sim section's
	 * faults): the handles own their devices */
	struct px_devcfg *dcfg[MAX_DEVS];
	int n_dcfg;
	int dev_owned[MAX_DEVS]; /* dev[i] is freed by px_dev_free here */
	struct px_dev *dio[MAX_DEVS]; /* digital I/O: e-stop, enable, timing */
	int n_dio;
	int estop_pressed, timing_level, hardware;
	uint64_t estop_presses, estop_cycles, enable_errors;
	int64_t estop_first_ns, safe_first_after_estop_ns;
	uint64_t estop_first_cycle, safe_first_cycle_after_estop;
	uint64_t safe_cycles_before_estop;
	int safe_at_estop;      /* the loop was in safe state at the press */
	int ctl_dev;          /* index of control.device, -1 none */
	int rendering;        /* mode haptic */
	struct px_force_cmd cmd;
	struct px_loop *loop;
	struct px_arena arena;
	struct px_ring *ring;
	struct px_stats *compute;
	int64_t decimation;
	uint64_t max_cycles;  /* 0 = until stopped */
	int64_t t0_ns;        /* loop clock at the first read */
	int64_t compute_t0;
	struct px_control_haptic_out out;
	int have_out;
	/* statistics of every cycle (loop thread; read after the run or
	 * approximately by the status line) */
	double max_force_n, min_distance_m, max_penetration_m;
	uint64_t query_errors, write_errors, velocity_trips, contact_cycles;
	int last_query_err;
	int over_velocity;
	/* allocation counting in the loop thread */
	int counting;
	uint64_t heap_base;
	_Atomic uint64_t allocs;
	/* main thread */
	char csv_path[1024];
	char time_svg[1100], lat_svg[1100];
	uint64_t n_rows;        /* records drained (CSV rows) */
	double min_proxy_distance_m;
	uint64_t faults_by_cause[PX_FAULT__COUNT];
	uint64_t faults_popped;
	struct px_app_record last;
	int have_last;
	/* a CANopen arm: the master from px_devcfg on any transport; on the
	 * in-process simulated bus the drives' side (arm) runs here too */
	int avoiding;
	const char *co_name;
	struct px_can_sim *canbus;
	struct px_can_bus *ep_arm;
	struct px_canopen *co;
	struct px_canopen_sim *arm;
	uint64_t enabled_cycles, drive_problem_cycles;
	pid_t arm_pid;          /* proxima-simarm spawned by sim.spawn_arm */
	int arm_input;          /* loop input index of the drives' feedback */
	int n_drives;
	int drive_joint[PX_CANOPEN_MAX_DRIVES];
	int started;
	int csp;                /* drives in CSP: targets are positions */
	double q[PX_CONTROL_MAX_JOINTS], qcmd[PX_CONTROL_MAX_JOINTS];
	double targets[PX_CONTROL_MAX_JOINTS];
	int have_q, enabled;
	int64_t last_feedback_ns;
	struct px_control_avoid_out aout;
	/* control.avoidance.urdf: the robot, its link models measured
	 * (clearance: models), config joint i = chain joint joint_perm[i] */
	struct px_urdf_robot *robot;
	int robot_models;
	int joint_perm[PX_CONTROL_MAX_JOINTS];
	struct px_urdf_avoid_out uout;
	int n_scene_obstacles;
	/* sim.depth_sensor: the camera, its feed, the robot's obstacle it
	 * fills (a far point until the first frame), the loop input its
	 * stamps feed, frames taken and swapped in */
	struct px_depth_sim *depth;
	struct px_cloud_feed *feed;
	struct px_model *cloud_none;
	int cloud_obstacle, cloud_input;
	uint64_t cloud_taken, cloud_swaps;
	double min_clearance_m, min_scale;
	uint64_t stop_cycles;   /* cycles with the nominal motion stopped */
	/* fault campaign */
	struct raw_sim sim;
	int64_t clock0_ns;      /* loop clock at setup: fault windows start here */
	struct px_fault *lfaults; /* loop faults seen, for the campaign report */
	size_t n_lfaults, cap_lfaults;
	struct raw_fault *all_faults; /* sim.faults + --fault (ours) */
	int n_ov;               /* injected compute overruns (device loop) */
	int64_t ov_start[MAX_CAMPAIGN], ov_end[MAX_CAMPAIGN], ov_ns[MAX_CAMPAIGN];
	struct px_can_sim *fault_bus; /* in-process CAN bus with faults (ours) */
	/* checks of every run: safe state per cycle (bit i: cycle i was in
	 * safe state; runs of a known length), outputs that were not
	 * finite, the first and last deadline (phase) */
	uint8_t *safe_bits;
	uint64_t safe_bits_n;
	uint64_t nonfinite_outputs;
	int64_t first_deadline_ns, last_deadline_ns;
	int have_deadline;
	/* --duration-s runs its cycles (duration / period); on the real
	 * clock the run also ends with the cycle whose deadline reaches
	 * this (first deadline + duration - one period), so missed periods
	 * never make it run longer than asked (0: no such bound) */
	int64_t stop_deadline_ns;
	int ended_by_time;      /* the run ended at stop_deadline_ns */
	/* moved from function statics and file globals */
	struct shutdown_report sd;
	struct px_config_diag diag; /* the checks' and create's */
	int n_check_errors;
	atomic_int stop_requested;  /* px_app_stop(): the run ends */
	atomic_int loop_done;
	int loop_rc;
	struct px_sim_fault busf[MAX_CAMPAIGN], armf[MAX_CAMPAIGN];
	struct px_sim_fault linef[PX_SIM_MAX_FAULTS];
	struct px_sim_fault devf[PX_SIM_MAX_FAULTS];
	char cli_devs[PX_APP_MAX_CLI_FAULTS][64];
	struct app_teleop tele;
	char *msg;              /* px_app_create's msg buffer (first line) */
	size_t msg_cap;
};


/* messages (app_note: format, then opt.note) */
void app_note(struct px_app *a, const char *fmt, ...)
	__attribute__((format(printf, 2, 3)));
uint64_t app_heap_count(struct px_app *a);
const char *app_name(const struct px_app *a);
int64_t app_mono_ns(void);
void app_config_dir_path(char *out, size_t cap, const char *cfg_path,
			 const char *file);
void app_plot_paths(struct px_app *a, char *time_svg, char *lat_svg, size_t cap);
const struct px_config_schema *app_sim_schema(void);
const char *app_fault_misfit(const struct px_config *cfg,
			     const struct raw_fault *f, char *buf, size_t cap);
int app_is_hardware(const struct px_config_device *d);
unsigned app_config_caps(const struct px_config_device *d, int *canopen);
int app_phase_read(struct px_loop *l, const struct px_loop_cycle *c, void *user);
int app_phase_compute(struct px_loop *l, const struct px_loop_cycle *c,
		      void *user);
int app_phase_write(struct px_loop *l, const struct px_loop_cycle *c,
		    void *user);
struct px_sim_fault app_campaign_fault(struct px_app *a, const struct raw_fault *f);
int app_make_devcfg(struct px_app *a, int k);
int app_make_device(struct px_app *a, int k);
int app_arm_exe(struct px_app *a, char *exe, size_t cap);
int app_spawn_arm(struct px_app *a);
void app_stop_arm(struct px_app *a);
int app_report_config(struct px_app *a, int rc, const struct px_config_diag *diag);
void app_check_error(struct px_app *a, const struct px_config_node *at,
		     const char *key, const char *fmt, ...)
	__attribute__((format(printf, 4, 5)));
const struct px_config_node *app_cfg_node(struct px_app *a, const char *sect,
					  const char *key);
int app_validate(struct px_app *a);
void app_loop_config(struct px_app *a, struct px_loop_config *lcp);
int app_check_config(struct px_app *a);
int app_setup(struct px_app *a);
void app_rearm_warnings(struct px_app *a);
void app_diag_print(struct px_app *a, const struct px_config_diag *diag);
void app_note_shutdown(struct px_app *a);
void app_teardown(struct px_app *a);
void app_safe_shutdown(struct px_app *a, const char *reason);
int app_avoid_joints(const struct px_app *a);
int app_robot_setup(struct px_app *a);
void app_robot_free(struct px_app *a);
int app_robot_step(struct px_app *a, const double *qnom, int64_t period_ns);
int app_robot_obstacles(struct px_app *a, struct px_model *extra);
int app_sensor_setup(struct px_app *a);
int app_sensor_start(struct px_app *a);
void app_sensor_free(struct px_app *a);
void app_sensor_read(struct px_app *a, struct px_loop *l, int64_t now_ns);
void app_drain(struct px_app *a,
	       void (*record)(void *user, const struct px_app_record *r),
	       void *user);
int app_run(struct px_app *a);
int app_add_cli_faults(struct px_app *a);
const struct px_config_schema *app_teleop_schema(void);
int app_teleop_read(struct px_app *a);
void app_teleop_check(struct px_app *a);
int app_make_dds(struct px_app *a, int k);
/* SCHED_FIFO priority `below` the loop's for the DDS link's threads
 * (0: the loop has none to spare). */
int app_link_priority(const struct px_config *cfg, int below);
int app_teleop_attach(struct px_app *a);
void app_teleop_input(struct px_app *a, int dev, int input);
void app_teleop_read_phase(struct px_app *a, struct px_loop *l, int64_t now_ns);
int app_teleop_follow(struct px_app *a, double *qnom);
void app_teleop_compute(struct px_app *a);
void app_teleop_write(struct px_app *a, const struct px_loop_cycle *c);
void app_teleop_summary(const struct px_app *a, struct px_app_summary *s);
int app_teleop_cloud_source(const struct px_app *a);

#endif
