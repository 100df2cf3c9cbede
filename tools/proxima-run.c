/*
 * proxima-run - run a proxima application from its YAML config.
 *
 *   proxima-run CONFIG [--duration-s N] [--virtual-time] [--summary-json FILE]
 *                      [--telemetry FILE]
 *   proxima-run --check CONFIG
 *
 * Setup: config, scene (px_world_config_load), control, devices (the
 * simulated back end), the loop. Then the 1 kHz cycle: read the device
 * pose, query the scene and render the force (compute), send the force
 * (write). A live status line goes to stderr a few times per second; at
 * the end come a summary (stdout, and JSON with --summary-json), the
 * telemetry CSV and SVG plots next to it.
 *
 * Threads: with the real clock the loop runs on its own thread (with the
 * config's real-time setup) while the main thread drains the telemetry
 * ring, writes the CSV and prints the status; with --virtual-time the
 * main thread steps the loop itself and drains the ring between batches
 * of cycles. Heap calls are counted per thread by the tests' allocator
 * hook when it is loaded (LD_PRELOAD=libproxima-alloc-count.so, as the
 * test suite runs this program: the interposed malloc family; sanitizer
 * builds link it: the sanitizer's malloc/free hooks) and only the calls
 * the loop's thread makes while cycles run are reported
 * (allocations_after_setup), beside the calls setup made
 * (allocations_setup, showing the counter is live). Without the hook
 * allocation_counter is "none" and nothing is counted.
 * PX_RUN_ALLOC_PROBE=1 in the environment makes cycle 10 allocate and
 * free once on purpose: the count is then 2 (a self-check for tests).
 *
 * Devices: the simulated haptic and pose devices are made here (they
 * take their own devices[].sim.faults, stuck_limit and
 * min_report_interval_ns, then the `sim` section's fault campaign); every
 * other back end is opened through px_devcfg (hidapi, libusb, SocketCAN
 * signals and CANopen drives, libgpiod, simulated lines; the campaign's
 * e-stop presses go in as px_devcfg_options fault windows, its notes are
 * printed), so the cycle sees only px_dev and the CANopen master, never
 * a back end. Back-end headers still included: px_sim.h (the simulated
 * haptic/pose device and the px_sim_fault windows), px_can.h and
 * px_canopen.h (the in-process simulated bus and arm, and the CANopen
 * master the avoidance cycle commands). Each cycle reads every pose
 * device and e-stop line (a pressed one trips safe state), computes
 * (haptic rendering on control.device, or avoidance on the CANopen arm),
 * and writes the force, the drives' targets (held still without
 * avoidance; quick stop in safe state), the enable relay (off in safe
 * state) and the timing toggle. A CANopen arm on the in-process
 * simulated bus gets its drives' side here, stepped in the read phase as
 * another node on the bus would answer.
 *
 * Shutdown: every way out after the devices opened (duration reached,
 * a signal, a loop error, a setup error) goes through safe_shutdown()
 * before anything closes: zero force and torque with enable off on each
 * force sink, enable relays and timing lines off (px_dev_safe), each
 * CANopen master's drives to quick stop and then disabled, confirmed by
 * their statuswords (px_devcfg_safe_stop), each within a bounded wait;
 * the summary, the JSON (object 'shutdown') and the exit status say how
 * it went. Every signal that would end or freeze the process (INT, TERM,
 * HUP, QUIT, USR1, USR2, PIPE, ALRM, VTALRM, PROF, XCPU, XFSZ, TSTP)
 * ends the run like Ctrl-C. PX_RUN_STOP_AT=CYCLE[:SIGNAL] raises SIGNAL
 * after CYCLE cycles ("stop now", for tests). px_gpio.h is included for
 * what simulated lines last received (the JSON's shutdown record).
 *
 * Checks: validate() makes every check setup makes before it opens a
 * device (outputs, scene, clock, control.device against what the device
 * can do, telemetry memory, renderer); --check runs it, opens the
 * in-process simulated devices and checks the others through px_devcfg
 * without opening them. Outputs go through tools/tool_out.h (temporary
 * file renamed over the target: no symbolic link followed, never over
 * the config or an input file). --duration-s runs duration / period
 * cycles; on the real clock the run also ends once its loop clock has
 * covered the duration, so missed periods never stretch it.
 *
 * Exit status: 0 ok, 1 invalid config or setup failure (an absent device
 * is named with the back end's reason) or outputs not confirmed safe at
 * the end, 2 usage error (a flag's value, an output flag refused) or
 * --virtual-time with hardware.
 */
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
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "px_arena.h"
#include "px_can.h"
#include "px_canopen.h"
#include "px_alloc_count.h"
#include "px_config.h"
#include "px_control.h"
#include "px_dev.h"
#include "px_devcfg.h"
#include "px_gpio.h"
#include "px_loop.h"
#include "px_ring.h"
#include "px_world.h"
#include "px_sim.h"
#include "px_stats.h"
#include "tool_out.h"
#include "tool_svg.h"

static const char usage_text[] =
	"usage: proxima-run CONFIG [--duration-s N] [--virtual-time] "
	"[--summary-json FILE]\n"
	"       proxima-run --check CONFIG\n"
	"\n"
	"  --check            validate CONFIG, print every problem, and exit\n"
	"  --duration-s N     run for N seconds of loop time (0 < N <= 1e8);\n"
	"                     default: until Ctrl-C\n"
	"  --virtual-time     run the loop on the virtual clock, as fast as "
	"possible\n"
	"  --summary-json F   write a machine-readable summary to F\n"
	"  --telemetry F      telemetry CSV (default: telemetry.file of "
	"CONFIG);\n"
	"                     plots go next to it as <stem>_time.svg and "
	"<stem>_latency.svg\n"
	"  --fault K,DEV,START_S,DURATION_S[,PROBABILITY[,DELAY_S]]\n"
	"                     inject fault kind K into device DEV (as an entry "
	"of\n"
	"                     sim.faults; DEV 'loop' for overrun); repeatable\n"
	"  --help             this text\n"
	"Exit status: 0 ok, 1 invalid config or setup failure (e.g. a device\n"
	"absent), 2 usage error or --virtual-time with hardware devices.\n";

static int usage_error(const char *fmt, const char *arg)
{
	fprintf(stderr, "proxima-run: ");
	fprintf(stderr, fmt, arg);
	fprintf(stderr, "\n%s", usage_text);
	return 2;
}

/* --duration-s at most (about 3 years): cycles and the loop clock's
 * nanoseconds stay far inside their integers at any period. */
#define RUN_MAX_DURATION_S 1e8

struct options {
	const char *config;
	int check;
	int virtual_time;
	double duration_s; /* 0 = until stopped */
	const char *summary_json;
	const char *telemetry; /* overrides telemetry.file */
	const char *fault[64]; /* --fault specs, added to sim.faults */
	int n_fault;
};

/* Value of an option given as "--opt VALUE" or "--opt=VALUE". */
static const char *opt_value(int argc, char **argv, int *i, const char *name)
{
	size_t n = strlen(name);
	if (argv[*i][n] == '=')
		return argv[*i] + n + 1;
	if (*i + 1 >= argc)
		return NULL;
	return argv[++*i];
}

static int matches(const char *arg, const char *name)
{
	size_t n = strlen(name);
	return strncmp(arg, name, n) == 0 && (arg[n] == '\0' || arg[n] == '=');
}

static int parse_args(int argc, char **argv, struct options *o)
{
	int i, rest = 0;
	memset(o, 0, sizeof(*o));
	for (i = 1; i < argc; i++) {
		const char *a = argv[i];
		if (!rest && strcmp(a, "--") == 0) {
			rest = 1;
		} else if (!rest && (strcmp(a, "--help") == 0 ||
				     strcmp(a, "-h") == 0)) {
			fputs(usage_text, stdout);
			return 1;
		} else if (!rest && strcmp(a, "--check") == 0) {
			o->check = 1;
		} else if (!rest && strcmp(a, "--virtual-time") == 0) {
			o->virtual_time = 1;
		} else if (!rest && matches(a, "--duration-s")) {
			const char *v = opt_value(argc, argv, &i, "--duration-s");
			char *end;
			double d;
			if (!v)
				return usage_error("%s needs a value", a);
			errno = 0;
			d = strtod(v, &end);
			if (end == v || *end || errno || !isfinite(d) || d <= 0 ||
			    d > RUN_MAX_DURATION_S)
				return usage_error(
					"--duration-s: '%s' is not a positive "
					"number of seconds (at most 1e8)",
					v);
			o->duration_s = d;
		} else if (!rest && matches(a, "--summary-json")) {
			const char *v = opt_value(argc, argv, &i, "--summary-json");
			if (!v || !*v)
				return usage_error("%s needs a file name", a);
			o->summary_json = v;
		} else if (!rest && matches(a, "--fault")) {
			const char *v = opt_value(argc, argv, &i, "--fault");
			if (!v || !*v)
				return usage_error("%s needs KIND,DEVICE,START_S,"
						   "DURATION_S", a);
			if (o->n_fault == 64)
				return usage_error("%s: at most 64", a);
			o->fault[o->n_fault++] = v;
		} else if (!rest && matches(a, "--telemetry")) {
			const char *v = opt_value(argc, argv, &i, "--telemetry");
			if (!v || !*v)
				return usage_error("%s needs a file name", a);
			o->telemetry = v;
		} else if (!rest && a[0] == '-' && a[1] != '\0') {
			return usage_error("unknown option '%s'", a);
		} else if (!o->config) {
			o->config = a;
		} else {
			return usage_error("unexpected argument '%s' (one CONFIG "
					   "only)",
					   a);
		}
	}
	if (!o->config)
		return usage_error("%s", "no CONFIG given");
	return 0;
}

/* ---- heap call counter (per thread) -------------------------------- */

/* The tests' counter (tests/px_alloc_count.c) when it is there: preloaded
 * as libproxima-alloc-count.so, or linked in sanitizer builds. It sees
 * every malloc-family call of the loop thread. Weak, so that a run
 * without it still works and says the counter is "none". */
#pragma weak px_alloc_count_thread
#pragma weak px_alloc_count_mode

static uint64_t heap_count(void)
{
	return px_alloc_count_thread ? px_alloc_count_thread() : 0;
}

static const char *heap_counter_name(void)
{
	return px_alloc_count_mode ? px_alloc_count_mode() : "none";
}

/* ---- the `sim` section: fault campaigns --------------------------- */

#define SIM_RANGE (PX_CONFIG_HAS_MIN | PX_CONFIG_HAS_MAX)
#define MAX_CAMPAIGN 64

/* Fault kinds a simulated haptic/pose device takes (enum px_sim_fault_kind
 * is index + 1). */
/* Index + 1 is the px_sim fault kind (px_sim.h), up to estop; overrun
 * is the runner's own (the compute phase takes delay_ns). */
static const char *const fault_kind_names[] = {
	"drop", "delay", "duplicate", "corrupt", "stuck", "nan", "unplug",
	"bus_off", "estop", "overrun", NULL};
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

struct raw_sim {
	struct raw_fault *faults;
	size_t n_faults;
	struct raw_nominal *nominal;
	size_t n_nominal;
	const char *spawn_arm; /* a socketcan device on transport unix */
	const struct px_config *cfg_; /* not a key: context for the check */
};

static void fault_check(struct px_config_reader *r,
			const struct px_config_node *map, void *obj)
{
	const struct raw_fault *f = obj;
	int delay = f->kind == FK_DELAY || f->kind == FK_OVERRUN;
	if (delay && f->delay_ns <= 0)
		px_config_reader_error(r, map, "delay_ns",
				       "missing or zero for kind '%s'",
				       fault_kind_names[f->kind]);
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
static const char *fault_misfit(const struct px_config *cfg,
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
	 .names = fault_kind_names},
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
		why = fault_misfit(sm->cfg_, f, buf, sizeof(buf));
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
};
static const struct px_config_schema sim_schema = {
	"sim", sim_keys, sizeof(sim_keys) / sizeof(sim_keys[0]), sim_check};

/* ---- the application ----------------------------------------------- */

#define MAX_DEVS 64
#define TELE_JOINTS 6
#define PLOT_MAX ((size_t)1 << 20)

/* One telemetry record, pushed by the write phase every decimation-th
 * cycle. */
struct tele {
	double t_s;
	uint64_t cycle;
	double dev_m[3], proxy_m[3], force_n[3];
	double force_mag_n;
	double distance_m;
	double penetration_m;
	int64_t latency_ns, compute_ns;
	int32_t contact, safe, queries, valid;
	/* avoidance: speed scale and commanded joint velocities (the first
	 * TELE_JOINTS joints) */
	double scale, qdot[TELE_JOINTS];
};

struct app {
	struct options o;
	struct px_config *cfg;
	struct px_control_config ctl;
	struct px_world *scene;
	struct px_world_hints hints; /* coherent queries of the loop thread */
	/* haptic mode, scene.tracking on: the renderer's queries follow one
	 * point through tracked streams (NULL otherwise) */
	struct px_world_tracking *tracking;
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
	int alloc_probe;
	uint64_t setup_heap_calls;
	/* main thread */
	FILE *csv_f;            /* csv_out.f while the CSV is written */
	struct tool_out csv_out;
	char csv_path[1024];
	char time_svg[1100], lat_svg[1100];
	struct tele *recs;
	size_t n_recs, cap_recs;
	uint64_t n_rows;        /* records drained (CSV rows) */
	double min_proxy_distance_m;
	uint64_t faults_by_cause[PX_FAULT__COUNT];
	uint64_t faults_popped;
	struct tele last;
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
	char out_why[TOOL_OUT_WHY_MAX]; /* why write_json() failed */
};

static struct app A;

/* A campaign fault window (sim.faults) as a px_sim fault on the loop
 * clock. */
static struct px_sim_fault campaign_fault(const struct raw_fault *f)
{
	struct px_sim_fault x;
	memset(&x, 0, sizeof(x));
	x.kind = f->kind + 1;
	x.start_ns = A.clock0_ns + f->start_ns;
	x.duration_ns = f->duration_ns;
	x.probability = f->probability;
	x.delay_ns = f->delay_ns;
	return x;
}

static volatile sig_atomic_t interrupted;
static volatile sig_atomic_t stop_signal; /* the signal that ended the run */

static void on_signal(int sig)
{
	if (!stop_signal)
		stop_signal = sig;
	interrupted = 1;
	if (A.loop)
		px_loop_stop(A.loop);
}

static int64_t mono_ns(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

/* ---- loop phases (real-time rules: no allocation, no I/O) --------- */

static int phase_read(struct px_loop *l, const struct px_loop_cycle *c,
		      void *user)
{
	struct app *a = user;
	int i;
	if (!a->counting) {
		/* Everything this thread does from here on counts. */
		a->counting = 1;
		a->heap_base = heap_count();
		a->t0_ns = c->read_ns;
	}
	if (a->co) {
		int64_t newest = 0;
		int have = a->n_drives > 0;
		/* on the in-process bus, the robot's side first, as another
		 * process would have answered the last SYNC by now */
		if (a->arm)
			px_canopen_sim_step(a->arm, c->read_ns);
		px_canopen_rx(a->co, c->read_ns);
		for (i = 0; i < a->n_drives; i++) {
			struct px_canopen_drive_status ds;
			px_canopen_drive_status(a->co, (size_t)i, &ds);
			if (ds.feedback_ns == 0) {
				have = 0;
				continue;
			}
			a->q[a->drive_joint[i]] = ds.position;
			if (ds.feedback_ns > newest)
				newest = ds.feedback_ns;
		}
		a->have_q = have;
		if (have && newest > a->last_feedback_ns) {
			a->last_feedback_ns = newest;
			px_loop_input_stamp(l, a->arm_input, newest);
		}
		a->enabled = px_canopen_all_enabled(a->co);
		if (a->enabled)
			a->enabled_cycles++;
		/* a drive lost (heartbeat timeout) or in fault: safe state,
		 * held while the problem lasts */
		if (px_canopen_first_problem(a->co) >= 0) {
			a->drive_problem_cycles++;
			px_loop_trip(l);
		}
	}
	for (i = 0; i < a->n_dev; i++) {
		int rc;
		if (!(px_dev_caps(a->dev[i]) & PX_DEV_CAP_POSE))
			continue;
		rc = px_dev_pose_read(a->dev[i], c->read_ns, &a->sample[i]);
		(void)rc; /* staleness reaches the watchdog through the stamp */
	}
	{
		/* e-stop lines: a pressed (or unreadable) one trips the loop
		 * inside px_dev_estop_read (px_dev_attach), every cycle it is
		 * held, so safe state cannot be left while it is */
		int any = 0;
		for (i = 0; i < a->n_dio; i++) {
			int p = 0;
			int rc = px_dev_estop_read(a->dio[i], c->read_ns, &p);
			if (rc != PX_E_UNSUPPORTED && p)
				any = 1;
		}
		if (any && !a->estop_pressed) {
			a->estop_presses++;
			if (a->estop_first_ns < 0) {
				a->estop_first_ns = c->read_ns;
				a->estop_first_cycle = c->index;
				a->safe_at_estop = c->safe;
			}
		}
		if (any)
			a->estop_cycles++;
		a->estop_pressed = any;
	}
	if (a->ctl_dev >= 0) {
		const struct px_pose_sample *s = &a->sample[a->ctl_dev];
		double v = px_v3_norm(s->vel_m_s);
		double lim = a->cfg->safety.velocity_limit_m_per_s;
		if (s->valid && v > lim) {
			if (!a->over_velocity) {
				a->velocity_trips++;
				px_loop_trip(l);
			}
			a->over_velocity = 1;
		} else {
			a->over_velocity = 0;
		}
	}
	return PX_OK;
}

/* Avoidance: nominal joint velocity from the demo task, scaled and
 * deflected by the clearances (px_control_avoid_step), into drive
 * targets (CSP: integrated positions; CSV: velocities). */
static void avoid_compute(struct app *a, const struct px_loop_cycle *c)
{
	double qnom[PX_CONTROL_MAX_JOINTS] = {0};
	double t = (double)(c->deadline_ns - a->t0_ns) * 1e-9;
	double dt = (double)c->period_ns * 1e-9;
	size_t k;
	int i, rc;
	if (!a->have_q || !a->enabled) {
		for (i = 0; i < PX_CONTROL_MAX_JOINTS; i++)
			a->targets[i] = a->csp ? a->q[i] : 0.0;
		return;
	}
	if (!a->started) {
		memcpy(a->qcmd, a->q, sizeof(a->qcmd));
		a->started = 1;
	}
	for (k = 0; k < a->sim.n_nominal; k++) {
		const struct raw_nominal *nm = &a->sim.nominal[k];
		if (nm->joint < a->ctl.chain.n_joints)
			qnom[nm->joint] += nm->amplitude_rad_per_s *
					   cos(2 * M_PI * nm->frequency_hz * t +
					       nm->phase_rad);
	}
	rc = px_control_avoid_step(&a->ctl.chain, &a->ctl.avoid, &a->query, a->q,
				   qnom, c->period_ns, &a->aout);
	if (rc < 0) {
		a->query_errors++;
		a->last_query_err = rc;
	}
	for (i = 0; i < a->ctl.chain.n_joints; i++) {
		double v = rc < 0 ? 0.0 : a->aout.qdot[i];
		a->qcmd[i] += v * dt;
		a->targets[i] = a->csp ? a->qcmd[i] : v;
	}
}

static int phase_compute(struct px_loop *l, const struct px_loop_cycle *c,
			 void *user)
{
	struct app *a = user;
	int64_t t = mono_ns();
	int i;
	a->have_out = 0;
	if (a->avoiding)
		avoid_compute(a, c);
	if (a->ctl_dev >= 0 && a->sample[a->ctl_dev].valid) {
		const struct px_pose_sample *s = &a->sample[a->ctl_dev];
		if (a->rendering) {
			int rc = px_control_haptic_step(&a->haptic, &a->query,
							s->pos_m, &s->vel_m_s,
							&a->out);
			if (rc < 0) {
				a->query_errors++;
				a->last_query_err = rc;
			}
			a->cmd.force_n[0] = a->out.force_n.x;
			a->cmd.force_n[1] = a->out.force_n.y;
			a->cmd.force_n[2] = a->out.force_n.z;
			a->cmd.enable = 1;
		} else {
			struct px_control_hit h;
			memset(&a->out, 0, sizeof(a->out));
			a->out.proxy_m = s->pos_m;
			if (a->query.point(a->query.ctx, s->pos_m, 1e3, &h) == PX_OK &&
			    h.valid)
				a->out.distance_m = h.distance_m;
			else
				a->out.distance_m = INFINITY;
		}
		a->have_out = 1;
	}
	for (i = 0; i < a->n_ov; i++)
		if (c->deadline_ns >= a->ov_start[i] && c->deadline_ns < a->ov_end[i]) {
			/* injected overrun: this compute takes ov_ns */
			if (px_loop_vclock_advance(l, a->ov_ns[i]) == PX_E_STATE) {
				int64_t until = mono_ns() + a->ov_ns[i];
				while (mono_ns() < until)
					;
			}
		}
	if (a->alloc_probe && c->index == 10) {
		/* self-check of the heap counter (PX_RUN_ALLOC_PROBE=1): one
		 * deliberate allocation and release inside a cycle */
		void *volatile p = malloc(64);
		free(p);
	}
	a->compute_t0 = mono_ns() - t;
	px_stats_record(a->compute, a->compute_t0);
	return PX_OK;
}

static int phase_write(struct px_loop *l, const struct px_loop_cycle *c,
		       void *user)
{
	struct app *a = user;
	double f;
	(void)l;
	if (a->rendering && a->ctl_dev >= 0) {
		/* In safe state the loop has zeroed cmd and cleared enable. */
		if (px_dev_force_write(a->dev[a->ctl_dev], &a->cmd, c->write_ns) !=
		    PX_OK)
			a->write_errors++;
	}
	if (a->n_dio) {
		int i;
		if (c->safe && a->estop_first_ns >= 0 &&
		    a->safe_first_after_estop_ns < 0) {
			a->safe_first_after_estop_ns = c->write_ns;
			a->safe_first_cycle_after_estop = c->index;
		}
		if (c->safe && a->estop_first_ns < 0)
			a->safe_cycles_before_estop++;
		/* enable relay: on while the loop runs outside safe state;
		 * timing line: toggles every cycle (scope probe) */
		a->timing_level = !a->timing_level;
		for (i = 0; i < a->n_dio; i++) {
			int rc = px_dev_dio_write(a->dio[i], PX_DIO_ENABLE, !c->safe,
						  c->write_ns);
			if (rc != PX_OK && rc != PX_E_UNSUPPORTED)
				a->enable_errors++;
			(void)px_dev_dio_write(a->dio[i], PX_DIO_TIMING,
					       a->timing_level, c->write_ns);
		}
	}
	if (a->co) {
		int i;
		/* safe state: hold where the arm is, drives to quick stop;
		 * without avoidance (an arm beside a haptic device) the
		 * drives are enabled and hold still */
		if (c->safe || !a->avoiding)
			for (i = 0; i < PX_CONTROL_MAX_JOINTS; i++)
				a->targets[i] = a->csp ? a->q[i] : 0.0;
		if (px_canopen_tx(a->co, c->write_ns, a->targets,
				  PX_CONTROL_MAX_JOINTS,
				  !c->safe && a->have_q) != PX_OK)
			a->write_errors++;
		if (a->avoiding && a->started && !c->safe) {
			if (a->aout.min_clearance_m < a->min_clearance_m)
				a->min_clearance_m = a->aout.min_clearance_m;
			if (a->aout.min_clearance_m < a->min_distance_m)
				a->min_distance_m = a->aout.min_clearance_m;
			if (a->aout.scale < a->min_scale)
				a->min_scale = a->aout.scale;
			if (a->aout.scale == 0)
				a->stop_cycles++;
		}
	}
	{
		/* what went out this cycle: finite? in safe state? phase? */
		int i, bad = 0;
		for (i = 0; i < 3; i++)
			bad |= !isfinite(a->cmd.force_n[i]) ||
			       !isfinite(a->cmd.torque_n_m[i]);
		for (i = 0; a->co && i < PX_CONTROL_MAX_JOINTS; i++)
			bad |= !isfinite(a->targets[i]);
		if (bad)
			a->nonfinite_outputs++;
		if (c->safe && c->index < a->safe_bits_n)
			a->safe_bits[c->index >> 3] |= (uint8_t)(1u << (c->index & 7));
		if (!a->have_deadline) {
			/* periods skipped before the first cycle count too */
			a->first_deadline_ns =
				c->deadline_ns - (int64_t)c->missed * c->period_ns;
			a->have_deadline = 1;
			if (a->max_cycles && !a->o.virtual_time)
				a->stop_deadline_ns =
					a->first_deadline_ns +
					(int64_t)(a->max_cycles - 1) * c->period_ns;
		}
		a->last_deadline_ns = c->deadline_ns;
	}
	f = sqrt(a->cmd.force_n[0] * a->cmd.force_n[0] +
		 a->cmd.force_n[1] * a->cmd.force_n[1] +
		 a->cmd.force_n[2] * a->cmd.force_n[2]);
	if (f > a->max_force_n)
		a->max_force_n = f;
	/* Figures of the rendering only while it drives the device: not in
	 * safe state (force zeroed) nor on a sample that broke the velocity
	 * limit (a corrupted report the loop is tripping on). */
	if (a->have_out && !c->safe && !a->over_velocity) {
		if (a->out.distance_m < a->min_distance_m)
			a->min_distance_m = a->out.distance_m;
		if (a->out.penetration_m > a->max_penetration_m)
			a->max_penetration_m = a->out.penetration_m;
		if (a->out.contact)
			a->contact_cycles++;
	}
	if (c->index % (uint64_t)a->decimation == 0) {
		struct tele r;
		const struct px_pose_sample *s =
			a->ctl_dev >= 0 ? &a->sample[a->ctl_dev] : NULL;
		memset(&r, 0, sizeof(r));
		r.t_s = (double)(c->deadline_ns - a->t0_ns) * 1e-9;
		r.cycle = c->index;
		if (s) {
			r.dev_m[0] = s->pos_m.x;
			r.dev_m[1] = s->pos_m.y;
			r.dev_m[2] = s->pos_m.z;
			r.valid = s->valid;
		}
		r.proxy_m[0] = a->out.proxy_m.x;
		r.proxy_m[1] = a->out.proxy_m.y;
		r.proxy_m[2] = a->out.proxy_m.z;
		memcpy(r.force_n, a->cmd.force_n, sizeof(r.force_n));
		r.force_mag_n = f;
		/* a sample that broke the velocity limit has no meaningful
		 * distance: left empty (NaN) rather than spoiling the plots */
		r.distance_m = a->have_out && !a->over_velocity ? a->out.distance_m
								: NAN;
		r.penetration_m = a->have_out && !a->over_velocity
					  ? a->out.penetration_m
					  : NAN;
		r.latency_ns = c->wake_ns - c->deadline_ns;
		r.compute_ns = a->compute_t0;
		r.scale = 1.0;
		if (a->avoiding && a->started) {
			int k = a->aout.closest_capsule, j;
			r.scale = c->safe ? 0.0 : a->aout.scale;
			for (j = 0; j < TELE_JOINTS && j < a->ctl.chain.n_joints; j++)
				r.qdot[j] = c->safe ? 0.0 : a->aout.qdot[j];
			r.distance_m = a->aout.min_clearance_m;
			r.penetration_m = 0;
			r.queries = a->aout.point_queries;
			r.valid = 1;
			if (k >= 0) {
				px_vec3 pa = a->aout.caps[k].point_m;
				px_vec3 pb = a->aout.caps[k].obstacle_m;
				r.dev_m[0] = pa.x;
				r.dev_m[1] = pa.y;
				r.dev_m[2] = pa.z;
				r.proxy_m[0] = pb.x;
				r.proxy_m[1] = pb.y;
				r.proxy_m[2] = pb.z;
			}
		}
		r.contact = a->out.contact;
		r.safe = c->safe;
		if (!a->avoiding)
			r.queries = a->out.point_queries;
		px_ring_push(a->ring, &r);
	}
	atomic_store_explicit(&a->allocs, heap_count() - a->heap_base,
			      memory_order_relaxed);
	if (a->stop_deadline_ns && c->deadline_ns >= a->stop_deadline_ns) {
		a->ended_by_time = 1; /* --duration-s of real time gone */
		return PX_LOOP_STOP;
	}
	return PX_OK;
}

/* ---- setup --------------------------------------------------------- */

static void config_dir_path(char *out, size_t cap, const char *cfg_path,
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
static const struct px_codec_map *make_codec(int k, const struct px_config_codec *c)
{
	struct px_codec_map *m = &A.codec[k];
	size_t i;
	if (c->n_inputs == 0 && c->n_outputs == 0)
		return NULL;
	A.fields[k][0] = calloc(c->n_inputs + 1, sizeof(struct px_codec_field));
	A.fields[k][1] = calloc(c->n_outputs + 1, sizeof(struct px_codec_field));
	A.buttons[k] = calloc(c->n_buttons + 1, sizeof(struct px_codec_buttons));
	if (!A.fields[k][0] || !A.fields[k][1] || !A.buttons[k])
		return NULL;
	for (i = 0; i < c->n_inputs; i++)
		codec_field(&A.fields[k][0][i], &c->inputs[i]);
	for (i = 0; i < c->n_outputs; i++)
		codec_field(&A.fields[k][1][i], &c->outputs[i]);
	for (i = 0; i < c->n_buttons; i++) {
		A.buttons[k][i].report_id = (int)c->buttons[i].report_id;
		A.buttons[k][i].byte_offset = (uint32_t)c->buttons[i].byte_offset;
		A.buttons[k][i].first_bit = (uint8_t)c->buttons[i].first_bit;
		A.buttons[k][i].count = (uint8_t)c->buttons[i].count;
		A.buttons[k][i].first_button = (uint8_t)c->buttons[i].first_button;
	}
	m->inputs = A.fields[k][0];
	m->n_inputs = c->n_inputs;
	m->outputs = A.fields[k][1];
	m->n_outputs = c->n_outputs;
	m->buttons = A.buttons[k];
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
static int make_devcfg(int k)
{
	const struct px_config_device *d = &A.cfg->devices[k];
	struct px_devcfg *h;
	struct px_devcfg_options opt;
	struct px_dev *dev;
	struct px_canopen *co;
	static struct px_sim_fault busf[MAX_CAMPAIGN], armf[MAX_CAMPAIGN];
	static struct px_sim_fault linef[PX_SIM_MAX_FAULTS];
	size_t nbus = 0, narm = 0, nline = 0, j;
	char msg[512] = "";
	int rc, i;
	memset(&opt, 0, sizeof(opt));
	opt.clock0_ns = A.clock0_ns; /* the config's own fault windows */
	/* the campaign's e-stop presses of simulated lines: fault windows
	 * of the simulated GPIO device (px_devcfg applies them) */
	for (j = 0; j < A.sim.n_faults; j++) {
		const struct raw_fault *f = &A.sim.faults[j];
		if (strcmp(f->device, d->name) != 0 ||
		    d->backend != PX_CONFIG_BACKEND_SIM)
			continue;
		if (nline == PX_SIM_MAX_FAULTS) {
			fprintf(stderr, "proxima-run: device '%s': more than %d "
					"faults\n",
				d->name, PX_SIM_MAX_FAULTS);
			return 1;
		}
		linef[nline++] = campaign_fault(f);
	}
	opt.faults = nline ? linef : NULL;
	opt.n_faults = nline;
	/* faults of a CANopen arm on the in-process bus: the bus's (a bus
	 * of ours, given to px_devcfg) and drive 0's (the simulated arm) */
	for (j = 0; j < A.sim.n_faults; j++) {
		const struct raw_fault *f = &A.sim.faults[j];
		struct px_sim_fault x;
		if (strcmp(f->device, d->name) != 0 ||
		    d->backend != PX_CONFIG_BACKEND_SOCKETCAN)
			continue;
		x = campaign_fault(f);
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
		rc = px_can_sim_create(&bc, &A.fault_bus);
		if (rc != PX_OK) {
			fprintf(stderr, "proxima-run: device '%s': simulated bus: "
					"%s\n",
				d->name, px_strerror(rc));
			return 1;
		}
		opt.can_sim = A.fault_bus;
	}
	rc = px_devcfg_open(A.cfg, d, &opt, &h, msg, sizeof(msg));
	if (rc != PX_OK) {
		fprintf(stderr, "proxima-run: %s\n",
			msg[0] ? msg : px_strerror(rc));
		if (d->backend != PX_CONFIG_BACKEND_SIM)
			fprintf(stderr,
				"proxima-run: is the hardware connected and "
				"readable? build/bin/proxima-probe lists what "
				"this machine has\n");
		return 1;
	}
	A.dcfg[A.n_dcfg++] = h;
	if (px_devcfg_notes(h)[0])
		fprintf(stderr, "proxima-run: device '%s': note: %s\n", d->name,
			px_devcfg_notes(h));
	dev = px_devcfg_dev(h);
	if (dev) {
		if (A.n_dev >= MAX_DEVS) {
			fprintf(stderr, "proxima-run: more than %d devices\n",
				MAX_DEVS);
			return 1;
		}
		if (px_dev_caps(dev) & PX_DEV_CAP_DIO)
			A.dio[A.n_dio++] = dev;
		if ((px_dev_caps(dev) & PX_DEV_CAP_POSE) && A.ctl.device &&
		    strcmp(A.ctl.device, d->name) == 0)
			A.ctl_dev = A.n_dev;
		A.dev[A.n_dev++] = dev;
	}
	co = px_devcfg_canopen(h);
	if (co) {
		struct px_canopen_drive_cfg drv[PX_CANOPEN_MAX_DRIVES];
		int n = px_devcfg_drives(h, drv, PX_CANOPEN_MAX_DRIVES);
		if (A.co) {
			fprintf(stderr,
				"proxima-run: device '%s': a second CANopen "
				"arm ('%s' is the first); one per run\n",
				d->name, A.co_name);
			return 1;
		}
		if (n < 0) {
			fprintf(stderr, "proxima-run: device '%s': drives: %s\n",
				d->name, px_strerror(n));
			return 1;
		}
		A.co = co;
		A.co_name = d->name;
		A.n_drives = n;
		for (i = 0; i < n; i++) {
			A.drive_joint[i] = drv[i].joint;
			if (drv[i].mode == PX_CIA402_CST) {
				fprintf(stderr,
					"proxima-run: device '%s': drives in cst "
					"take torques; proxima-run commands csp "
					"or csv\n",
					d->name);
				return 1;
			}
		}
		A.csp = n > 0 && drv[0].mode == PX_CIA402_CSP;
		A.canbus = px_devcfg_can_sim(h);
		if (A.canbus) {
			struct px_canopen_sim_config sc;
			/* the config's drive faults (node_id) as well */
			int na = px_devcfg_arm_faults(A.cfg, d, A.clock0_ns,
						      armf + narm,
						      MAX_CAMPAIGN - narm);
			if (na < 0) {
				fprintf(stderr,
					"proxima-run: device '%s': drive "
					"faults: %s\n",
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
			rc = px_can_sim_endpoint(A.canbus, &A.ep_arm);
			if (rc == PX_OK)
				rc = px_canopen_sim_create(&sc, A.ep_arm, &A.arm);
			if (rc != PX_OK) {
				fprintf(stderr,
					"proxima-run: device '%s': simulated arm "
					"on the in-process bus: %s\n",
					d->name, px_strerror(rc));
				return 1;
			}
		}
		if (A.ctl.device && strcmp(A.ctl.device, d->name) == 0)
			A.avoiding = A.ctl.mode == PX_CONTROL_MODE_AVOIDANCE;
	}
	return 0;
}

/* A device that is not simulated in this process (hardware, or a CAN bus
 * shared with another process) runs on the real clock only. */
static int is_hardware(const struct px_config_device *d)
{
	return d->backend != PX_CONFIG_BACKEND_SIM &&
	       !(d->backend == PX_CONFIG_BACKEND_SOCKETCAN &&
		 d->socketcan.transport == PX_CONFIG_CAN_SIM);
}

/* Create device k of the config. Returns 0 or 1 (setup failed: said
 * why). */
static int make_device(int k)
{
	const struct px_config_device *d = &A.cfg->devices[k];
	const struct px_config_sim *s = &d->sim;
	struct px_dev_config dc;
	struct px_sim_haptic_config sc;
	struct px_sim_sine sines[PX_SIM_MAX_SINES];
	char msg[256] = "";
	size_t i;
	int rc;
	if (d->backend != PX_CONFIG_BACKEND_SIM || s->kind == PX_CONFIG_SIM_GPIO)
		return make_devcfg(k);
	px_dev_config_default(&dc);
	dc.name = d->name;
	dc.stale_timeout_ns = d->stale_timeout_ns
				      ? d->stale_timeout_ns
				      : A.cfg->safety.watchdog.device_timeout_ns;
	dc.codec = make_codec(k, &s->codec);
	px_sim_haptic_config_default(&sc);
	sc.mass_kg = s->mass_kg;
	sc.damping_n_s_per_m = s->damping_n_s_per_m;
	sc.hand_stiffness_n_per_m = s->hand_stiffness_n_per_m;
	sc.hand_damping_n_s_per_m = s->hand_damping_n_s_per_m;
	sc.report_period_ns = s->report_period_ns ? s->report_period_ns
						  : A.cfg->loop.period_ns;
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
		config_dir_path(path, sizeof(path), A.o.config, s->trajectory.file);
		rc = px_sim_csv_load(path, &A.csv[k], msg, sizeof(msg));
		if (rc != PX_OK) {
			const struct px_config_node *at = px_config_node_get(
				px_config_node_get(px_config_node_get(d->node_, "sim"),
						   "trajectory"),
				"file");
			if (at)
				fprintf(stderr, "%s:%d:%d: devices[%d].sim.trajectory."
					"file: ", at->file, at->line, at->column, k);
			fprintf(stderr, "proxima-run: device '%s': %s\n", d->name,
				msg[0] ? msg : px_strerror(rc));
			return 1;
		}
		sc.traj.csv = A.csv[k];
	}
	{
		/* the device's own faults (devices[].sim.faults, timed from
		 * the start of the run), then the campaign's (sim.faults) */
		static struct px_sim_fault fl[PX_SIM_MAX_FAULTS];
		size_t n = 0;
		for (i = 0; i < s->n_faults; i++) {
			const struct px_config_fault *f = &s->faults[i];
			if (n == PX_SIM_MAX_FAULTS) {
				fprintf(stderr,
					"proxima-run: device '%s': more than %d "
					"faults in devices[%d].sim.faults\n",
					d->name, PX_SIM_MAX_FAULTS, k);
				return 1;
			}
			memset(&fl[n], 0, sizeof(fl[n]));
			fl[n].kind = f->kind + 1;
			fl[n].start_ns = A.clock0_ns + f->start_ns;
			fl[n].duration_ns = f->duration_ns;
			fl[n].probability = f->probability;
			fl[n].delay_ns = f->delay_ns;
			n++;
		}
		for (i = 0; i < A.sim.n_faults; i++) {
			const struct raw_fault *f = &A.sim.faults[i];
			if (strcmp(f->device, d->name) != 0)
				continue;
			if (n == PX_SIM_MAX_FAULTS) {
				fprintf(stderr,
					"proxima-run: device '%s': more than %d "
					"faults\n",
					d->name, PX_SIM_MAX_FAULTS);
				return 1;
			}
			fl[n++] = campaign_fault(f);
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
	rc = px_sim_haptic_create(&dc, &sc, &A.dev[A.n_dev], msg, sizeof(msg));
	if (rc != PX_OK) {
		fprintf(stderr, "proxima-run: device '%s': %s\n", d->name,
			msg[0] ? msg : px_strerror(rc));
		return 1;
	}
	if (A.ctl.device && strcmp(A.ctl.device, d->name) == 0)
		A.ctl_dev = A.n_dev;
	A.dev_owned[A.n_dev] = 1;
	A.n_dev++;
	return 0;
}

/* proxima-simarm next to this program, in exe (cap bytes). Returns 0 or
 * 1 (said why). */
static int arm_exe(char *exe, size_t cap)
{
	ssize_t len = cap > 32 ? readlink("/proc/self/exe", exe, cap - 32) : -1;
	char *slash;
	if (len <= 0 || !(slash = memrchr(exe, '/', (size_t)len))) {
		fprintf(stderr, "proxima-run: sim.spawn_arm: cannot find this "
				"program's directory\n");
		return 1;
	}
	strcpy(slash + 1, "proxima-simarm");
	if (access(exe, X_OK) != 0) {
		fprintf(stderr, "proxima-run: sim.spawn_arm: %s: %s (make builds "
				"it)\n",
			exe, strerror(errno));
		return 1;
	}
	return 0;
}

/* sim.spawn_arm: start proxima-simarm (next to this program) as the
 * drives' side of the unix-socket bus, as a second process, and wait
 * until it has bound its socket. It gets SIGTERM when this process ends
 * (teardown, or PR_SET_PDEATHSIG if this one dies). Returns 0 or 1. */
static int spawn_arm(void)
{
	const struct px_config_device *d =
		px_config_device_find(A.cfg, A.sim.spawn_arm);
	const struct px_config_socketcan *c = &d->socketcan;
	char exe[1024], line[256] = "";
	int fds[2];
	size_t got = 0;
	int64_t until;
	if (arm_exe(exe, sizeof(exe)))
		return 1;
	if (pipe(fds) != 0) {
		fprintf(stderr, "proxima-run: sim.spawn_arm: pipe: %s\n",
			strerror(errno));
		return 1;
	}
	fflush(NULL);
	A.arm_pid = fork();
	if (A.arm_pid < 0) {
		fprintf(stderr, "proxima-run: sim.spawn_arm: fork: %s\n",
			strerror(errno));
		close(fds[0]);
		close(fds[1]);
		return 1;
	}
	if (A.arm_pid == 0) {
		/* the arm goes when the controller goes */
		prctl(PR_SET_PDEATHSIG, SIGTERM);
		dup2(fds[1], 1);
		close(fds[0]);
		close(fds[1]);
		/* the arm reads the same file: drives, PDO mapping, drive
		 * faults, and the other end of socket_path */
		execl(exe, "proxima-simarm", "--config", A.o.config, "--device",
		      d->name, (char *)NULL);
		fprintf(stderr, "proxima-run: sim.spawn_arm: %s: %s\n", exe,
			strerror(errno));
		_exit(127);
	}
	close(fds[1]);
	/* its first line says the socket is bound: wait for it (5 s) */
	until = mono_ns() + 5000000000;
	while (got + 1 < sizeof(line) && !memchr(line, '\n', got)) {
		struct pollfd p = {fds[0], POLLIN, 0};
		int64_t left = until - mono_ns();
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
		kill(A.arm_pid, SIGTERM);
		waitpid(A.arm_pid, &st, 0);
		A.arm_pid = 0;
		fprintf(stderr,
			"proxima-run: sim.spawn_arm: %s did not start (exit "
			"status %d)\n",
			exe, WIFEXITED(st) ? WEXITSTATUS(st) : -1);
		return 1;
	}
	fprintf(stderr,
		"proxima-run: spawned %s (pid %d): %zu drives on %s, layout "
		"from %s\n",
		exe, (int)A.arm_pid, c->canopen.n_drives, c->socket_path,
		A.o.config);
	return 0;
}

static void stop_arm(void)
{
	if (A.arm_pid > 0) {
		kill(A.arm_pid, SIGTERM);
		waitpid(A.arm_pid, NULL, 0);
		A.arm_pid = 0;
	}
}

static void teardown(void);
static void rearm_warnings(FILE *f);
static void plot_paths(char *time_svg, char *lat_svg, size_t cap);

static int report_config(int rc, const struct px_config_diag *diag)
{
	int n = px_config_diag_total(diag);
	px_config_diag_print(diag, stderr);
	if (n == 0)
		fprintf(stderr, "%s: %s\n", A.o.config, px_strerror(rc));
	fprintf(stderr, "%s: invalid configuration (%d error%s)\n", A.o.config,
		n, n == 1 ? "" : "s");
	return 1;
}

/* ---- setup, part 1: the checks (no device opened) ------------------- */

/* Telemetry ring memory (telemetry.ring_records records of struct tele,
 * allocated at setup and locked with loop.lock_memory): a warning above
 * TELE_WARN_BYTES, refused above TELE_MAX_BYTES (docs/config.md). */
#define TELE_WARN_BYTES ((size_t)64 << 20)
#define TELE_MAX_BYTES ((size_t)1 << 30)

static int n_check_errors;

/* One refusal in the config's own format, "file:line:column: key: what"
 * (the key alone when the value has no place: a default). */
static void check_error(const struct px_config_node *at, const char *key,
			const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static void check_error(const struct px_config_node *at, const char *key,
			const char *fmt, ...)
{
	va_list ap;
	if (at)
		fprintf(stderr, "%s:%d:%d: %s: ", at->file, at->line, at->column,
			key);
	else
		fprintf(stderr, "%s: %s: ", A.o.config, key);
	va_start(ap, fmt);
	vfprintf(stderr, fmt, ap);
	va_end(ap);
	fputc('\n', stderr);
	n_check_errors++;
}

/* A node of the config by path of mapping keys (NULL: absent). */
static const struct px_config_node *cfg_node(const char *sect, const char *key)
{
	const struct px_config_node *s =
		px_config_node_get(px_config_doc_root(A.cfg->doc), sect);
	return key ? px_config_node_get(s, key) : s;
}

/* What a config device can do once opened (the back ends' px_dev caps),
 * known without opening it; *canopen: it carries CANopen drives. */
static unsigned config_caps(const struct px_config_device *d, int *canopen)
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
	default:
		return 0;
	}
}

/* control.device must be able to do what control.mode asks of it. */
static void check_control(void)
{
	const struct px_config_node *at = cfg_node("control", "device");
	const struct px_config_device *d =
		A.ctl.device ? px_config_device_find(A.cfg, A.ctl.device) : NULL;
	unsigned caps;
	int co = 0;
	if (A.ctl.mode != PX_CONTROL_MODE_HAPTIC &&
	    A.ctl.mode != PX_CONTROL_MODE_AVOIDANCE)
		return;
	if (!d) {
		check_error(at ? at : cfg_node("control", NULL), "control.device",
			    "mode '%s' needs a device",
			    A.ctl.mode == PX_CONTROL_MODE_HAPTIC ? "haptic"
								 : "avoidance");
		return;
	}
	caps = config_caps(d, &co);
	if (A.ctl.mode == PX_CONTROL_MODE_AVOIDANCE) {
		if (!co)
			check_error(at, "control.device",
				    "control mode 'avoidance' needs control.device "
				    "'%s' to be a socketcan device with canopen "
				    "drives",
				    d->name);
		return;
	}
	if (!(caps & PX_DEV_CAP_POSE))
		check_error(at, "control.device",
			    "'%s' (%s) is not a pose device: haptic rendering "
			    "needs one that reports a pose (sim kind haptic, "
			    "hidapi, libusb, socketcan signals)",
			    d->name, px_config_backend_names()[d->backend]);
	else if (!(caps & PX_DEV_CAP_FORCE))
		check_error(at, "control.device",
			    "'%s' takes no force (a sim device of kind pose): "
			    "haptic rendering needs a force output",
			    d->name);
}

/* Setup-time memory of the telemetry: refused when absurd, a warning
 * when large (the whole ring is allocated at setup and, with
 * loop.lock_memory, locked in RAM). */
static void check_memory(void)
{
	size_t rec = sizeof(struct tele);
	uint64_t n = (uint64_t)A.cfg->telemetry.ring_records;
	uint64_t ring = n * rec;
	const struct px_config_node *at = cfg_node("telemetry", "ring_records");
	if (ring > TELE_MAX_BYTES) {
		check_error(at, "telemetry.ring_records",
			    "%llu records take %.1f GiB (%zu bytes each): at "
			    "most %llu (%zu MiB)",
			    (unsigned long long)n, (double)ring / (1u << 30), rec,
			    (unsigned long long)(TELE_MAX_BYTES / rec),
			    TELE_MAX_BYTES >> 20);
	} else if (ring > TELE_WARN_BYTES) {
		if (at)
			fprintf(stderr, "%s:%d:%d: ", at->file, at->line,
				at->column);
		fprintf(stderr,
			"telemetry.ring_records: warning: %llu records take "
			"%.0f MiB at setup%s (warning above %zu MiB)\n",
			(unsigned long long)n, (double)ring / (1u << 20),
			A.cfg->loop.lock_memory ? ", locked in RAM (loop."
						  "lock_memory)"
						: "",
			TELE_WARN_BYTES >> 20);
	}
}

/* Every file the config names as input ("file" keys: scene models,
 * trajectories; not telemetry.file, an output), and the config itself:
 * no output of this run may be written over them. */
static void protect_inputs(const struct px_config_node *n, int depth,
			   int in_telemetry)
{
	size_t i;
	if (!n || depth > PX_CONFIG_MAX_DEPTH)
		return;
	if (n->kind == PX_CONFIG_NODE_SEQ)
		for (i = 0; i < n->len; i++)
			protect_inputs(n->items[i], depth + 1, 0);
	if (n->kind != PX_CONFIG_NODE_MAP)
		return;
	for (i = 0; i < n->len; i++) {
		const struct px_config_node *k = n->pairs[i].key;
		const struct px_config_node *v = n->pairs[i].value;
		if (!in_telemetry && strcmp(k->str, "file") == 0 &&
		    v->kind == PX_CONFIG_NODE_SCALAR && v->str[0]) {
			char path[2048];
			config_dir_path(path, sizeof(path), A.o.config, v->str);
			tool_out_protect(path, "an input file of the config,");
		}
		protect_inputs(v, depth + 1,
			       depth == 0 && strcmp(k->str, "telemetry") == 0);
	}
}

/* One output path: where it came from decides the status (2: a flag,
 * 1: the config, with its place). Returns 0, 1 or 2. */
static int check_output(const char *path, const char *flag,
			const struct px_config_node *at, const char *key)
{
	char why[TOOL_OUT_WHY_MAX];
	if (tool_out_check(path, why, sizeof(why)) == 0)
		return 0;
	if (flag) {
		fprintf(stderr, "proxima-run: %s: %s\n", flag, why);
		return 2;
	}
	check_error(at, key, "%s", why);
	return 1;
}

/* The CSV, plot and summary paths, each checked before anything runs (a
 * refusal after a long run would lose it). */
static int check_outputs(void)
{
	const char *tflag = NULL;
	const struct px_config_node *tat = cfg_node("telemetry", "file");
	int rc, r;
	tool_out_protect(A.o.config, "the config file");
	protect_inputs(px_config_doc_root(A.cfg->doc), 0, 0);
	if (A.o.telemetry) {
		snprintf(A.csv_path, sizeof(A.csv_path), "%s", A.o.telemetry);
		tflag = "--telemetry";
	} else if (A.cfg->telemetry.file && A.cfg->telemetry.file[0]) {
		snprintf(A.csv_path, sizeof(A.csv_path), "%s",
			 A.cfg->telemetry.file);
	}
	plot_paths(A.time_svg, A.lat_svg, sizeof(A.time_svg));
	rc = A.csv_path[0] ? check_output(A.csv_path, tflag, tat, "telemetry.file")
			   : 0;
	/* the plot names follow the CSV's (or are the default's) */
	r = check_output(A.time_svg, tflag ? "--telemetry (its time plot)" : NULL,
			 tat, "telemetry.file (its time plot)");
	rc = rc ? rc : r;
	r = check_output(A.lat_svg, tflag ? "--telemetry (its latency plot)" : NULL,
			 tat, "telemetry.file (its latency plot)");
	rc = rc ? rc : r;
	if (A.o.summary_json) {
		r = check_output(A.o.summary_json, "--summary-json", NULL, NULL);
		rc = rc ? rc : r;
	}
	return rc;
}

/* Everything setup checks before it opens a device: the outputs, the
 * scene (px_world_config_load: keys, values, files, geometry), what the
 * clock allows, control.device against what the device can do, the
 * telemetry memory, the haptic renderer's parameters. --check runs this
 * (and opens the in-process simulated devices); a run goes on to open
 * everything. Prints every problem; returns 0, 1 (invalid) or 2 (a
 * flag's value, or --virtual-time with hardware). */
static int validate(void)
{
	static struct px_config_diag diag;
	const struct px_config *cfg = A.cfg;
	int i, rc, status = 0;

	A.ctl_dev = -1;
	A.estop_first_ns = -1;
	A.safe_first_after_estop_ns = -1;
	A.clock0_ns = A.o.virtual_time || A.o.check ? 0 : mono_ns();
	A.min_distance_m = INFINITY;
	A.min_proxy_distance_m = INFINITY;
	A.decimation = cfg->telemetry.decimation > 0 ? cfg->telemetry.decimation : 1;
	if (A.o.duration_s > 0)
		A.max_cycles = (uint64_t)ceil(A.o.duration_s * 1e9 /
					      (double)cfg->loop.period_ns);
	n_check_errors = 0;

	rc = check_outputs();
	if (rc == 2)
		return 2;
	px_config_diag_init(&diag);
	rc = px_world_config_load(cfg, &A.scene, &diag);
	if (rc != PX_OK) {
		int n = px_config_diag_total(&diag);
		px_config_diag_print(&diag, stderr);
		if (n == 0)
			fprintf(stderr, "%s: %s\n", A.o.config, px_strerror(rc));
		n_check_errors += n ? n : 1;
	}
	for (i = 0; i < (int)cfg->n_devices; i++) {
		if (!is_hardware(&cfg->devices[i]))
			continue;
		A.hardware = 1;
		if (A.o.virtual_time) {
			fprintf(stderr,
				"proxima-run: device '%s' (%s): --virtual-time "
				"drives simulated devices only; hardware and "
				"buses shared with other processes run on the "
				"real clock\n",
				cfg->devices[i].name,
				px_config_backend_names()[cfg->devices[i].backend]);
			status = 2;
		}
	}
	if (cfg->n_devices > MAX_DEVS)
		check_error(cfg_node("devices", NULL), "devices",
			    "%zu devices; a run takes at most %d",
			    cfg->n_devices, MAX_DEVS);
	check_control();
	check_memory();
	if (A.ctl.mode == PX_CONTROL_MODE_HAPTIC) {
		rc = px_control_haptic_init(&A.haptic, &A.ctl.haptic,
					    cfg->loop.period_ns);
		if (rc != PX_OK)
			check_error(cfg_node("control", "haptic"), "control.haptic",
				    "the renderer refuses these parameters: %s",
				    px_strerror(rc));
	}
	if (n_check_errors) {
		fprintf(stderr, "%s: invalid configuration (%d error%s)\n",
			A.o.config, n_check_errors, n_check_errors == 1 ? "" : "s");
		return status ? status : 1;
	}
	return status;
}

/* The loop as the config describes it (setup, and --check's trial). */
static void loop_config(struct px_loop_config *lcp)
{
	const struct px_config *cfg = A.cfg;
	struct px_loop_config lc;
	px_loop_config_default(&lc);
	lc.period_ns = cfg->loop.period_ns;
	lc.clock = A.o.virtual_time ? PX_LOOP_CLOCK_VIRTUAL : PX_LOOP_CLOCK_MONOTONIC;
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
	lc.read = phase_read;
	lc.compute = phase_compute;
	lc.write = phase_write;
	lc.user = &A;
	lc.rt_enable = !A.o.virtual_time;
	lc.rt.priority = (int)cfg->loop.priority;
	lc.rt.cpu = (int)cfg->loop.cpu;
	lc.rt.lock_memory = cfg->loop.lock_memory;
	lc.rt.dma_latency = cfg->loop.dma_latency;
	*lcp = lc;
}

/* A device outside this process (hardware, a UNIX-socket bus) checked
 * as px_devcfg_open() would check it, without opening it. Returns 0 or
 * 1 (said why, at the device's place). */
static int check_device(int k)
{
	const struct px_config_device *d = &A.cfg->devices[k];
	struct px_devcfg_options opt;
	struct px_devcfg *h = NULL;
	char msg[512] = "";
	int rc;
	memset(&opt, 0, sizeof(opt));
	opt.check_only = 1;
	rc = px_devcfg_open(A.cfg, d, &opt, &h, msg, sizeof(msg));
	px_devcfg_free(h);
	if (rc == PX_OK)
		return 0;
	if (d->node_)
		fprintf(stderr, "%s:%d:%d: ", d->node_->file, d->node_->line,
			d->node_->column);
	fprintf(stderr, "%s\n", msg[0] ? msg : px_strerror(rc));
	return 1;
}

/* --check: validate(), then open what lives in this process (simulated
 * devices, buses and arms) as the run would, so their own refusals show
 * too; hardware and UNIX-socket buses get px_devcfg's checks without
 * being opened. Returns the exit status. */
static int check_config(void)
{
	struct px_loop_config lc;
	char exe[1024];
	int i, rc = validate();
	for (i = 0; rc == 0 && i < (int)A.cfg->n_devices && i < MAX_DEVS; i++)
		rc = is_hardware(&A.cfg->devices[i]) ? check_device(i)
						     : make_device(i);
	if (rc == 0) {
		/* the loop as the run makes it (real-time setup is applied
		 * only when a run starts) */
		loop_config(&lc);
		rc = px_loop_create(&lc, &A.loop);
		if (rc != PX_OK)
			fprintf(stderr, "proxima-run: %s: loop: %s\n", A.o.config,
				px_strerror(rc));
		rc = rc != PX_OK;
	}
	if (rc == 0 && A.sim.spawn_arm)
		rc = arm_exe(exe, sizeof(exe));
	if (rc == 0)
		rearm_warnings(stderr);
	if (rc == 0)
		printf("%s: OK (%zu device%s, loop period %lld ns)\n", A.o.config,
		       A.cfg->n_devices, A.cfg->n_devices == 1 ? "" : "s",
		       (long long)A.cfg->loop.period_ns);
	teardown();
	return rc;
}

static int setup(void)
{
	struct px_loop_config lc;
	const struct px_config *cfg = A.cfg;
	size_t ring_cap = (size_t)cfg->telemetry.ring_records;
	int i, rc = validate();

	if (rc)
		return rc;
	/* the loop's queries follow a moving point (proxy, device, link
	 * points): each model's search starts at last answer's feature */
	px_world_control_query_coherent(A.scene, &A.hints, &A.query);
	/* a haptic renderer's queries follow one point (the proxy, or the
	 * device point): NURBS models follow it with tracked streams, the
	 * exact answer at a fraction of the global query's cost
	 * (scene.tracking); an arm's link points are many points, and stay
	 * with the hints */
	if (A.ctl.mode == PX_CONTROL_MODE_HAPTIC &&
	    px_world_get_tracking(A.scene, NULL) == 1) {
		rc = px_world_tracking_create(A.scene, NULL, &A.tracking);
		if (rc != PX_OK) {
			fprintf(stderr,
				"proxima-run: %s: scene.tracking: cannot make the "
				"tracked streams: %s\n",
				A.o.config, px_strerror(rc));
			return 1;
		}
		px_world_control_query_tracked(A.scene, A.tracking, &A.query);
	}
	for (i = 0; i < (int)cfg->n_devices && i < MAX_DEVS; i++) {
		rc = make_device(i);
		if (rc)
			return rc;
	}
	if (A.ctl.mode == PX_CONTROL_MODE_AVOIDANCE && !A.avoiding) {
		fprintf(stderr,
			"proxima-run: control mode 'avoidance' needs "
			"control.device '%s' to be a socketcan device with "
			"canopen drives\n",
			A.ctl.device ? A.ctl.device : "");
		return 1;
	}

	A.min_clearance_m = INFINITY;
	A.min_scale = 1.0;
	A.rendering = A.ctl.mode == PX_CONTROL_MODE_HAPTIC && A.ctl_dev >= 0;
	if (A.ctl.mode == PX_CONTROL_MODE_HAPTIC && A.ctl_dev < 0) {
		fprintf(stderr, "proxima-run: control.device '%s' is not a "
				"pose device\n",
			A.ctl.device);
		return 1;
	}
	if (A.ctl_dev < 0 && A.n_dev > 0 && !A.avoiding)
		A.ctl_dev = 0; /* mode none: report the first device's distance */
	if (A.rendering) {
		if (!(px_dev_caps(A.dev[A.ctl_dev]) & PX_DEV_CAP_FORCE)) {
			fprintf(stderr,
				"proxima-run: control.device '%s' takes no force "
				"(a sim device of kind pose?)\n",
				A.ctl.device);
			return 1;
		}
		rc = px_control_haptic_init(&A.haptic, &A.ctl.haptic,
					    cfg->loop.period_ns);
		if (rc != PX_OK) {
			fprintf(stderr, "proxima-run: haptic setup: %s\n",
				px_strerror(rc));
			return 1;
		}
	}

	loop_config(&lc);
	rc = px_loop_create(&lc, &A.loop);
	if (rc != PX_OK) {
		fprintf(stderr, "proxima-run: loop: %s\n", px_strerror(rc));
		return 1;
	}
	for (i = 0; i < A.n_dev; i++) {
		rc = px_dev_start(A.dev[i]);
		if (rc == PX_OK)
			rc = px_dev_attach(A.dev[i], A.loop);
		if (rc >= 0 && A.rendering && i == A.ctl_dev)
			rc = px_dev_force_attach(A.dev[i], A.loop, &A.cmd);
		if (rc < 0) {
			struct px_dev_status ds;
			ds.last_msg[0] = '\0';
			px_dev_status(A.dev[i], &ds);
			fprintf(stderr, "proxima-run: device '%s': %s%s%s\n",
				px_dev_name(A.dev[i]), px_strerror(rc),
				ds.last_msg[0] ? ": " : "", ds.last_msg);
			return 1;
		}
	}
	if (A.co) {
		/* the drives' feedback (TPDO1) is a watched input like a pose */
		const struct px_config_device *d = px_config_device_find(cfg, A.co_name);
		int64_t tmo = d && d->stale_timeout_ns ? d->stale_timeout_ns
						       : cfg->safety.watchdog.device_timeout_ns;
		A.arm_input = px_loop_input_add(A.loop, A.co_name, tmo);
		if (A.arm_input < 0) {
			fprintf(stderr, "proxima-run: arm watchdog: %s\n",
				px_strerror(A.arm_input));
			return 1;
		}
	}
	if (ring_cap < 16)
		ring_cap = 16;
	rc = px_arena_init_alloc(&A.arena, px_ring_size(ring_cap, sizeof(struct tele)) +
						   px_stats_size(PX_STATS_DEFAULT_BINS) +
						   4096);
	if (rc == PX_OK)
		rc = px_ring_create(&A.arena, ring_cap, sizeof(struct tele), &A.ring);
	if (rc == PX_OK)
		rc = px_stats_create(&A.arena, 0, 0, &A.compute);
	if (rc != PX_OK) {
		fprintf(stderr, "proxima-run: telemetry buffers: %s\n",
			px_strerror(rc));
		return 1;
	}
	if (A.sim.spawn_arm && spawn_arm())
		return 1;
	for (i = 0; i < (int)A.sim.n_faults; i++) {
		const struct raw_fault *f = &A.sim.faults[i];
		if (f->kind != FK_OVERRUN)
			continue;
		A.ov_start[A.n_ov] = A.clock0_ns + f->start_ns;
		A.ov_end[A.n_ov] = A.ov_start[A.n_ov] + f->duration_ns;
		A.ov_ns[A.n_ov++] = f->delay_ns;
	}
	/* safe state per cycle, to check the reaction to every trip (runs
	 * of a known length up to 2^26 cycles) */
	if (A.max_cycles && A.max_cycles <= ((uint64_t)1 << 26)) {
		A.safe_bits = calloc((size_t)(A.max_cycles + 7) / 8, 1);
		if (A.safe_bits)
			A.safe_bits_n = A.max_cycles;
	}
	return 0;
}

/* ---- shutdown: the safe state before anything closes ---------------- */

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
static struct shutdown_report SD;

static int64_t shutdown_now(void)
{
	return A.loop && A.o.virtual_time ? px_loop_now_ns(A.loop) : mono_ns();
}

static int64_t shutdown_period_ns(void)
{
	return A.cfg && A.cfg->loop.period_ns > 0 ? A.cfg->loop.period_ns
						  : 1000000;
}

/* Let period_ns pass between two shutdown rounds: the virtual clock
 * jumps, the real one sleeps; an arm on the in-process bus answers as it
 * does in the read phase. */
static int64_t shutdown_wait(void *user, int64_t now, int64_t period_ns)
{
	(void)user;
	if (A.o.virtual_time) {
		now += period_ns;
	} else {
		struct timespec ts = {(time_t)(period_ns / 1000000000),
				      (long)(period_ns % 1000000000)};
		nanosleep(&ts, NULL);
		now = mono_ns();
	}
	if (A.arm)
		px_canopen_sim_step(A.arm, now);
	return now;
}

/* The drives of one master after its safe stop: counted, and the first
 * that did not confirm named. */
static void shutdown_drives(const char *dev, struct px_canopen *co, int rc,
			    const struct px_canopen_stop_result *r)
{
	SD.drives += (int)r->drives;
	SD.drives_disabled += (int)r->disabled;
	SD.drives_faulted += (int)r->faulted;
	if (rc != PX_OK && !SD.why[0]) {
		struct px_canopen_drive_status ds;
		memset(&ds, 0, sizeof(ds));
		ds.state = PX_CIA402_UNKNOWN;
		if (r->first_unconfirmed >= 0)
			px_canopen_drive_status(co, (size_t)r->first_unconfirmed,
						&ds);
		snprintf(SD.why, sizeof(SD.why),
			 "device '%s': drive %d (node %u) not confirmed disabled "
			 "within %.0f ms (%u rounds): %s, last state %s%s",
			 dev, r->first_unconfirmed, ds.node_id,
			 (double)SHUTDOWN_TIMEOUT_NS * 1e-6, r->rounds,
			 px_strerror(rc), px_cia402_state_name(ds.state),
			 ds.lost ? ", heartbeat lost" : "");
	}
}

/*
 * Every exit path comes here before any device closes: zero force and
 * torque with enable off on each force sink, enable relays and timing
 * lines off, then each CANopen master's drives to quick stop and
 * disabled (px_devcfg_safe_stop), each confirmed where the device can;
 * a device that could not take it (unplugged) is tried again each
 * period within SHUTDOWN_TIMEOUT_NS. The loop has stopped: this runs on
 * the main thread. Once per process.
 */
static void safe_shutdown(const char *reason)
{
	int64_t t0, now, period = shutdown_period_ns();
	int confirmed[MAX_DEVS];
	int i, pending;
	if (SD.done)
		return;
	SD.done = 1;
	snprintf(SD.reason, sizeof(SD.reason), "%s", reason);
	now = t0 = shutdown_now();
	memset(confirmed, 0, sizeof(confirmed));
	/* first the force at the hand: one try each, at once */
	for (i = 0; i < A.n_dev; i++) {
		unsigned caps = px_dev_caps(A.dev[i]);
		SD.force_devs += (caps & PX_DEV_CAP_FORCE) != 0;
		SD.dio_devs += (caps & PX_DEV_CAP_DIO) != 0;
		if (A.dev_owned[i] && (caps & (PX_DEV_CAP_FORCE | PX_DEV_CAP_DIO)))
			confirmed[i] = px_dev_safe(A.dev[i], now) == PX_OK;
	}
	/* the handles' devices and their masters' drives */
	for (i = 0; i < A.n_dcfg; i++) {
		struct px_devcfg_safe_config sc;
		struct px_devcfg_safe_result r;
		struct px_canopen *co = px_devcfg_canopen(A.dcfg[i]);
		px_devcfg_safe_config_default(&sc);
		sc.canopen.timeout_ns = SHUTDOWN_TIMEOUT_NS;
		sc.canopen.max_rounds =
			(uint32_t)(SHUTDOWN_TIMEOUT_NS / period + 1);
		sc.canopen.period_ns = period;
		sc.canopen.wait = shutdown_wait;
		(void)px_devcfg_safe_stop(A.dcfg[i], now, &sc, &r);
		if (co) {
			shutdown_drives(A.co_name ? A.co_name : "canopen", co,
					r.canopen_rc, &r.canopen);
			now += r.canopen.elapsed_ns;
		}
	}
	for (i = 0; i < A.n_dev; i++) {
		struct px_dev_status st;
		if (!A.dev_owned[i] && px_dev_status(A.dev[i], &st) == PX_OK)
			confirmed[i] = st.outputs_safe;
	}
	/* again, for a device that could not take it yet */
	for (;;) {
		pending = 0;
		for (i = 0; i < A.n_dev; i++) {
			struct px_dev *d = A.dev[i];
			unsigned caps = px_dev_caps(d);
			if (confirmed[i] || !(caps & (PX_DEV_CAP_FORCE | PX_DEV_CAP_DIO)))
				continue;
			if (caps & PX_DEV_CAP_POSE) {
				/* a simulated device lives in its poll: it
				 * comes back there */
				struct px_pose_sample ps;
				(void)px_dev_pose_read(d, now, &ps);
			}
			if (px_dev_safe(d, now) == PX_OK)
				confirmed[i] = 1;
			else
				pending++;
		}
		if (!pending || now - t0 >= SHUTDOWN_TIMEOUT_NS)
			break;
		now = shutdown_wait(NULL, now, period);
	}
	for (i = 0; i < A.n_dev; i++) {
		unsigned caps = px_dev_caps(A.dev[i]);
		if (!(caps & (PX_DEV_CAP_FORCE | PX_DEV_CAP_DIO)))
			continue;
		if (confirmed[i]) {
			SD.force_zeroed += (caps & PX_DEV_CAP_FORCE) != 0;
			SD.relays_off += (caps & PX_DEV_CAP_DIO) != 0;
		} else if (!SD.why[0]) {
			struct px_dev_status st;
			px_dev_status(A.dev[i], &st);
			snprintf(SD.why, sizeof(SD.why),
				 "device '%s': %s not confirmed within %.0f ms: %s",
				 st.name,
				 caps & PX_DEV_CAP_FORCE ? "zero force" : "relay off",
				 (double)SHUTDOWN_TIMEOUT_NS * 1e-6, st.last_msg);
		}
	}
	SD.elapsed_ns = now - t0;
	SD.safe = !SD.why[0];
}

/* "safe (force zeroed on 1/1 device, relay off on 1/1, 6/6 drives
 * disabled) after SIGINT in 2.0 ms", or NOT SAFE and why. */
static void shutdown_line(FILE *f, const char *prefix)
{
	char parts[160] = "";
	size_t n = 0;
	if (SD.force_devs)
		n += (size_t)snprintf(parts + n, sizeof(parts) - n,
				      "force zeroed on %d/%d device%s",
				      SD.force_zeroed, SD.force_devs,
				      SD.force_devs == 1 ? "" : "s");
	if (SD.dio_devs && n < sizeof(parts))
		n += (size_t)snprintf(parts + n, sizeof(parts) - n,
				      "%srelay off on %d/%d", n ? ", " : "",
				      SD.relays_off, SD.dio_devs);
	if (SD.drives && n < sizeof(parts))
		n += (size_t)snprintf(parts + n, sizeof(parts) - n,
				      "%s%d/%d drive%s disabled%s", n ? ", " : "",
				      SD.drives_disabled, SD.drives,
				      SD.drives == 1 ? "" : "s",
				      SD.drives_faulted ? " (some in fault)" : "");
	fprintf(f, "%s%s (%s) after %s in %.1f ms%s%s\n", prefix,
		SD.safe ? "safe" : "NOT SAFE", n ? parts : "no outputs",
		SD.reason, (double)SD.elapsed_ns * 1e-6, SD.why[0] ? ": " : "",
		SD.why);
}

static void json_string(FILE *f, const char *s);

/* The shutdown as a JSON object (a member of the summary), with what
 * each simulated device last received. */
static void json_shutdown(FILE *f)
{
	int i, first = 1;
	fprintf(f,
		"  \"shutdown\": {\"shutdown_safe\": %d, \"shutdown_reason\": "
		"\"%s\", \"force_devices\": %d, \"force_zeroed\": %d, "
		"\"relay_devices\": %d, \"relays_off\": %d, "
		"\"shutdown_drives\": %d, \"drives_disabled\": %d, "
		"\"drives_faulted\": %d, \"shutdown_ns\": %lld, "
		"\"shutdown_error\": ",
		SD.safe, SD.reason, SD.force_devs, SD.force_zeroed, SD.dio_devs,
		SD.relays_off, SD.drives, SD.drives_disabled, SD.drives_faulted,
		(long long)SD.elapsed_ns);
	json_string(f, SD.why);
	fputs(", \"last_outputs\": [", f);
	for (i = 0; i < A.n_dev; i++) {
		struct px_sim_haptic_state hs;
		struct px_dev_status st;
		int relay;
		px_dev_status(A.dev[i], &st);
		if (px_sim_haptic_state(A.dev[i], &hs) == PX_OK &&
		    (px_dev_caps(A.dev[i]) & PX_DEV_CAP_FORCE)) {
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
		} else if ((relay = px_gpio_sim_output(A.dev[i],
						       PX_GPIO_ENABLE)) >= 0) {
			fprintf(f, "%s{\"name\": ", first ? "" : ", ");
			json_string(f, st.name);
			fprintf(f,
				", \"enable_line\": %d, "
				"\"timing_line\": %d, \"outputs_safe\": %d}",
				relay,
				px_gpio_sim_output(A.dev[i], PX_GPIO_TIMING),
				st.outputs_safe);
			first = 0;
		}
	}
	fputs("]},\n", f);
}

/* Ask for the safe state on every signal that would otherwise end (or,
 * SIGTSTP, freeze) the process with the last command in effect: each
 * ends the run like SIGINT, through the summary and safe_shutdown(). */
static const int stop_signals[] = {SIGINT,    SIGTERM, SIGHUP,  SIGQUIT,
				   SIGUSR1,   SIGUSR2, SIGPIPE, SIGALRM,
				   SIGVTALRM, SIGPROF, SIGXCPU, SIGXFSZ,
				   SIGTSTP};

static void install_signals(void)
{
	struct sigaction sa;
	size_t i;
	memset(&sa, 0, sizeof(sa));
	sa.sa_handler = on_signal;
	sigemptyset(&sa.sa_mask);
	sa.sa_flags = SA_RESTART;
	for (i = 0; i < sizeof(stop_signals) / sizeof(stop_signals[0]); i++)
		sigaction(stop_signals[i], &sa, NULL);
}

/* "SIGINT" for the run's end by a signal. */
static void signal_reason(int sig, char *buf, size_t cap)
{
	const char *ab = sigabbrev_np(sig);
	if (ab)
		snprintf(buf, cap, "SIG%s", ab);
	else
		snprintf(buf, cap, "signal %d", sig);
}

/* safety.watchdog.auto_rearm with an e-stop line: the e-stop still
 * needs an explicit re-arm (px_loop_trip_estop), which the user of such
 * a config may not expect: say so, at the auto_rearm key. */
static void rearm_warnings(FILE *f)
{
	const struct px_config *cfg = A.cfg;
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
		fprintf(f, "%s:%d:%d: ", n->file, n->line, n->column);
	else
		fprintf(f, "%s: ", A.o.config);
	fprintf(f,
		"warning: safety.watchdog.auto_rearm: true re-arms after other "
		"trips, never after the e-stop (device '%s' line '%s'): its "
		"release keeps safe state until an explicit re-arm\n",
		dev, line);
}

static void teardown(void)
{
	int i;
	/* a setup error after devices opened (or any path that did not
	 * stop them yet): the safe state before anything closes */
	if (!SD.done && (A.n_dev || A.n_dcfg) && !A.o.check) {
		safe_shutdown("setup error");
		shutdown_line(stderr, "proxima-run: shutdown: ");
	}
	tool_out_discard(&A.csv_out); /* an unfinished CSV: never in place */
	stop_arm();
	px_loop_free(A.loop);
	for (i = 0; i < A.n_dev; i++)
		if (A.dev_owned[i])
			px_dev_free(A.dev[i]);
	for (i = 0; i < MAX_DEVS; i++) {
		px_sim_csv_free(A.csv[i]);
		free(A.fields[i][0]);
		free(A.fields[i][1]);
		free(A.buttons[i]);
	}
	px_canopen_sim_free(A.arm);
	px_can_bus_close(A.ep_arm);
	for (i = 0; i < A.n_dcfg; i++)
		px_devcfg_free(A.dcfg[i]); /* devices, master, buses */
	px_can_sim_free(A.fault_bus); /* after its endpoints */
	px_world_tracking_free(A.tracking); /* before its world */
	px_world_free(A.scene);
	px_arena_fini(&A.arena);
	free(A.recs);
	free(A.lfaults);
	free(A.all_faults);
	free(A.safe_bits);
	px_config_free(A.cfg);
}

/* ---- outside the cycle: telemetry, faults, status ------------------ */

/* Joints whose commanded velocity is recorded (CSV columns, plot). */
static int avoid_joints(void)
{
	int n = A.ctl.chain.n_joints;
	return n < TELE_JOINTS ? n : TELE_JOINTS;
}

static void drain(void)
{
	struct tele r;
	struct px_fault f;
	while (px_ring_pop(A.ring, &r) == PX_OK) {
		A.n_rows++;
		/* the plots keep the first PLOT_MAX records (about 17 min at
		 * 1 kHz); the CSV gets everything */
		if (A.n_recs == PLOT_MAX)
			goto stored;
		if (A.n_recs == A.cap_recs) {
			size_t cap = A.cap_recs ? 2 * A.cap_recs : 4096;
			struct tele *p = realloc(A.recs, cap * sizeof(*p));
			if (!p)
				break;
			A.recs = p;
			A.cap_recs = cap;
		}
		A.recs[A.n_recs++] = r;
	stored:
		A.last = r;
		A.have_last = 1;
		if (A.csv_f)
			fprintf(A.csv_f,
				"%.6f,%llu,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.6g,%.6g,"
				"%.6g,%.6g,%.9g,%.9g,%d,%d,%lld,%lld,%d",
				r.t_s, (unsigned long long)r.cycle, r.dev_m[0],
				r.dev_m[1], r.dev_m[2], r.proxy_m[0], r.proxy_m[1],
				r.proxy_m[2], r.force_n[0], r.force_n[1],
				r.force_n[2], r.force_mag_n, r.distance_m,
				r.penetration_m, r.contact, r.safe,
				(long long)r.latency_ns, (long long)r.compute_ns,
				r.queries);
		if (A.csv_f) {
			int j;
			if (A.avoiding) {
				fprintf(A.csv_f, ",%.6g", r.scale);
				for (j = 0; j < avoid_joints(); j++)
					fprintf(A.csv_f, ",%.6g", r.qdot[j]);
			}
			fputc('\n', A.csv_f);
		}
		/* The proxy must stay on the free side of closed models:
		 * check each recorded proxy against the scene (not in the
		 * cycle; the scene is only read). */
		if (A.rendering && r.valid && !r.safe) {
			struct px_world_hit h;
			px_vec3 p = px_v3(r.proxy_m[0], r.proxy_m[1], r.proxy_m[2]);
			if (px_world_nearest(A.scene, p, INFINITY, &h) == 1 &&
			    h.distance_m < A.min_proxy_distance_m)
				A.min_proxy_distance_m = h.distance_m;
		}
	}
	while (px_loop_fault_pop(A.loop, &f) == PX_OK) {
		if (f.cause >= 0 && f.cause < PX_FAULT__COUNT)
			A.faults_by_cause[f.cause]++;
		A.faults_popped++;
		if (A.sim.n_faults && A.n_lfaults < 100000) {
			if (A.n_lfaults == A.cap_lfaults) {
				size_t cap = A.cap_lfaults ? 2 * A.cap_lfaults : 256;
				struct px_fault *p =
					realloc(A.lfaults, cap * sizeof(*p));
				if (!p)
					continue;
				A.lfaults = p;
				A.cap_lfaults = cap;
			}
			A.lfaults[A.n_lfaults++] = f;
		}
	}
}

static void status_line(int final, double wall_s, double rate)
{
	struct px_stats_snapshot lat, cmp;
	struct px_loop_status st;
	static int tty = -1;
	if (tty < 0)
		tty = isatty(2);
	px_loop_stats(A.loop, PX_LOOP_STAT_LATENCY, &lat);
	px_stats_read(A.compute, &cmp);
	px_loop_status(A.loop, &st);
	fprintf(stderr,
		"%s[%7.2f s] %6.0f cycles/s | wake p99 %5.1f us | compute p99 "
		"%5.1f us | distance %+8.2f mm | force %5.2f N | faults %llu%s%s",
		tty ? "\r" : "", A.have_last ? A.last.t_s : 0.0, rate,
		(double)lat.p99_ns / 1e3, (double)cmp.p99_ns / 1e3,
		A.have_last && isfinite(A.last.distance_m) ? A.last.distance_m * 1e3
							     : 0.0,
		A.have_last ? A.last.force_mag_n : 0.0,
		(unsigned long long)st.faults, st.safe ? " | SAFE STATE" : "",
		tty ? "\033[K" : "\n");
	if (final && tty)
		fputc('\n', stderr);
	(void)wall_s;
	fflush(stderr);
}

struct rate_meter {
	int64_t t_ns;
	uint64_t cycles;
	double rate;
};

static void maybe_status(struct rate_meter *m, int64_t now, int64_t every_ns)
{
	struct px_loop_status st;
	if (now - m->t_ns < every_ns)
		return;
	px_loop_status(A.loop, &st);
	m->rate = (double)(st.cycles - m->cycles) / ((double)(now - m->t_ns) * 1e-9);
	m->cycles = st.cycles;
	m->t_ns = now;
	status_line(0, 0, m->rate);
}

static _Atomic int loop_done;
static int loop_rc;

static void *loop_thread(void *arg)
{
	(void)arg;
	loop_rc = px_loop_run(A.loop, A.max_cycles);
	atomic_store(&loop_done, 1);
	return NULL;
}

/* PX_RUN_STOP_AT=CYCLE[:SIGNAL] in the environment raises SIGNAL (a
 * name as kill -l gives it, default TERM) in this process once CYCLE
 * cycles have run: "stop now" at a chosen cycle, through the real signal
 * path (for tests and fault campaigns). 0 when not asked. */
static uint64_t stop_at_cycle(int *sig)
{
	const char *e = getenv("PX_RUN_STOP_AT"), *c;
	char *end;
	unsigned long long n;
	size_t i;
	*sig = SIGTERM;
	if (!e || !*e)
		return 0;
	n = strtoull(e, &end, 10);
	if (end == e || (*end && *end != ':'))
		return 0;
	if (*end == ':') {
		c = end + 1;
		if (!strncmp(c, "SIG", 3))
			c += 3;
		for (i = 0; i < sizeof(stop_signals) / sizeof(stop_signals[0]);
		     i++) {
			const char *ab = sigabbrev_np(stop_signals[i]);
			if (ab && !strcmp(ab, c))
				*sig = stop_signals[i];
		}
	}
	return (uint64_t)n;
}

static int run(void)
{
	struct rate_meter m;
	int64_t status_every = isatty(2) ? 250000000 : 1000000000;
	int stop_sig;
	uint64_t stop_at = stop_at_cycle(&stop_sig);
	memset(&m, 0, sizeof(m));
	m.t_ns = mono_ns();
	if (interrupted)
		return PX_OK; /* a signal during setup: straight to shutdown */
	if (A.o.virtual_time) {
		/* Drain well before the ring can fill. */
		uint64_t batch = (uint64_t)A.decimation *
				 (px_ring_capacity(A.ring) / 2);
		uint64_t done = 0, allocs = 0;
		int rc = PX_OK;
		if (batch > 1000)
			batch = 1000;
		while (!interrupted && rc == PX_OK &&
		       (A.max_cycles == 0 || done < A.max_cycles)) {
			uint64_t k, before = heap_count();
			for (k = 0; k < batch && rc == PX_OK && !interrupted &&
				    (A.max_cycles == 0 || done < A.max_cycles);
			     k++, done++) {
				rc = px_loop_step(A.loop);
				if (stop_at && done + 1 == stop_at)
					raise(stop_sig);
			}
			/* only the cycles' own heap calls, not the drain's */
			allocs += heap_count() - before;
			drain();
			maybe_status(&m, mono_ns(), status_every);
		}
		atomic_store(&A.allocs, allocs);
		return rc < 0 ? rc : PX_OK;
	} else {
		pthread_t th;
		if (pthread_create(&th, NULL, loop_thread, NULL) != 0) {
			fprintf(stderr, "proxima-run: cannot start the loop thread\n");
			return PX_E_NOMEM;
		}
		while (!atomic_load(&loop_done)) {
			struct timespec ts = {0, 20000000};
			nanosleep(&ts, NULL);
			drain();
			maybe_status(&m, mono_ns(), status_every);
			if (stop_at && !interrupted) {
				struct px_loop_status ls;
				px_loop_status(A.loop, &ls);
				if (ls.cycles >= stop_at)
					raise(stop_sig);
			}
		}
		pthread_join(th, NULL);
		drain();
		return loop_rc;
	}
}

/* ---- results -------------------------------------------------------- */

static void plot_paths(char *time_svg, char *lat_svg, size_t cap)
{
	const char *base = A.csv_path[0] ? A.csv_path : "proxima-run.csv";
	size_t n = strlen(base);
	if (n > 4 && strcmp(base + n - 4, ".csv") == 0)
		n -= 4;
	snprintf(time_svg, cap, "%.*s_time.svg", (int)n, base);
	snprintf(lat_svg, cap, "%.*s_latency.svg", (int)n, base);
}

static int write_plots(const char *time_svg, const char *lat_svg)
{
	size_t n = A.n_recs, i;
	double *x = calloc(n + 1, sizeof(double));
	double *d = calloc(n + 1, sizeof(double));
	double *f = calloc(n + 1, sizeof(double));
	double *pen = calloc(n + 1, sizeof(double));
	double *fz = calloc(n + 1, sizeof(double));
	int rc = -1;
	static uint64_t lbins[PX_STATS_DEFAULT_BINS], cbins[PX_STATS_DEFAULT_BINS];
	uint64_t lover = 0, cover = 0;
	int nl, nc;
	if (x && d && f && pen && fz && A.avoiding) {
		static const char *const colors[TELE_JOINTS] = {
			"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd",
			"#8c564b"};
		static const char *const names[TELE_JOINTS] = {
			"joint 0", "joint 1", "joint 2", "joint 3", "joint 4",
			"joint 5"};
		double *qd[TELE_JOINTS] = {0};
		struct tool_svg_series sq[TELE_JOINTS];
		struct tool_svg_series sd[] = {{"clearance", d, "#1f77b4"},
					       {"protective", pen, "#d62728"}};
		struct tool_svg_series ss[] = {{"speed scale", f, "#2ca02c"}};
		struct tool_svg_panel p[] = {{"clearance (mm)", sd, 2},
					     {"speed scale", ss, 1},
					     {"commanded velocity (rad/s)", sq, 0}};
		int j, nj = avoid_joints(), ok = 1;
		for (j = 0; j < nj; j++) {
			qd[j] = calloc(n + 1, sizeof(double));
			ok = ok && qd[j];
			sq[j].name = names[j];
			sq[j].y = qd[j];
			sq[j].color = colors[j];
		}
		p[2].n_series = nj;
		for (i = 0; ok && i < n; i++) {
			x[i] = A.recs[i].t_s;
			d[i] = A.recs[i].distance_m * 1e3;
			pen[i] = A.ctl.avoid.protective_distance_m * 1e3;
			f[i] = A.recs[i].scale;
			for (j = 0; j < nj; j++)
				qd[j][i] = A.recs[i].qdot[j];
		}
		if (ok)
			rc = tool_svg_lines(time_svg,
					    "proxima-run: clearance, speed scale "
					    "and commanded joint velocity",
					    "time (s)", x, n, p, 3);
		for (j = 0; j < nj; j++)
			free(qd[j]);
	} else if (x && d && f && pen && fz) {
		struct tool_svg_series sd[] = {{"distance", d, "#1f77b4"}};
		struct tool_svg_series sf[] = {{"|F|", f, "#d62728"},
					       {"Fz", fz, "#ff7f0e"}};
		struct tool_svg_series sp[] = {{"penetration", pen, "#2ca02c"}};
		struct tool_svg_panel p[] = {{"distance (mm)", sd, 1},
					     {"force (N)", sf, 2},
					     {"proxy penetration (mm)", sp, 1}};
		for (i = 0; i < n; i++) {
			x[i] = A.recs[i].t_s;
			d[i] = A.recs[i].distance_m * 1e3;
			f[i] = A.recs[i].force_mag_n;
			fz[i] = A.recs[i].force_n[2];
			pen[i] = A.recs[i].penetration_m * 1e3;
		}
		rc = tool_svg_lines(time_svg,
				    "proxima-run: distance, force and proxy "
				    "penetration",
				    "time (s)", x, n, p, 3);
	}
	free(x);
	free(d);
	free(f);
	free(pen);
	free(fz);
	nl = px_stats_copy_bins(px_loop_stats_handle(A.loop, PX_LOOP_STAT_LATENCY),
				lbins, PX_STATS_DEFAULT_BINS, &lover);
	nc = px_stats_copy_bins(A.compute, cbins, PX_STATS_DEFAULT_BINS, &cover);
	if (rc == 0 && nl >= 0 && nc >= 0) {
		struct tool_svg_hist h[] = {
			{"wake-up latency", lbins, (size_t)nl, lover,
			 (double)px_stats_bin_ns(px_loop_stats_handle(
				 A.loop, PX_LOOP_STAT_LATENCY)) /
				 1e3,
			 "#1f77b4"},
			{"compute time", cbins, (size_t)nc, cover,
			 (double)px_stats_bin_ns(A.compute) / 1e3, "#9467bd"}};
		rc = tool_svg_histograms(lat_svg,
					 A.o.virtual_time
						 ? "proxima-run: latency (virtual "
						   "clock: wake-up is 0 by "
						   "construction)"
						 : "proxima-run: latency",
					 "microseconds", h, 2);
	}
	return rc;
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

static double json_num(double v)
{
	return isfinite(v) ? v : 0.0;
}

struct dev_faults {
	uint64_t by_kind[PX_DEV_ERR__COUNT];
};

static void device_faults(struct dev_faults *df)
{
	int i;
	memset(df, 0, sizeof(*df));
	for (i = 0; i < A.n_dev; i++) {
		struct px_dev_status s;
		if (px_dev_status(A.dev[i], &s) != PX_OK)
			continue;
		df->by_kind[PX_DEV_ERR_DECODE] += s.decode_errors;
		df->by_kind[PX_DEV_ERR_NONFINITE] += s.nonfinite;
		df->by_kind[PX_DEV_ERR_DUPLICATE] += s.duplicates;
		df->by_kind[PX_DEV_ERR_STUCK] += s.stuck;
		df->by_kind[PX_DEV_ERR_UNPLUG] += s.unplugs;
		df->by_kind[PX_DEV_ERR_IO] += s.io_errors + s.write_errors;
		df->by_kind[PX_DEV_ERR_BUS] += s.bus_errors;
	}
}

static void json_campaign(FILE *f);

/* The loop clock's span over the run: first deadline (periods skipped
 * before it included) to the last cycle's end; missed periods count,
 * as time that went by. On the real clock this is the run's real time,
 * on the virtual clock its simulated time. */
static double loop_time_s(const struct px_loop_status *st)
{
	if (!A.have_deadline)
		return 0.0;
	return (double)(A.last_deadline_ns - A.first_deadline_ns + st->period_ns) *
	       1e-9;
}

/* What ended the run: "cycles" (--duration-s worth of cycles run),
 * "time" (real clock: --duration-s of loop time gone, periods missed),
 * "signal", or "stop" (the loop stopped: an error, a phase). */
static const char *ended_by(const struct px_loop_status *st)
{
	if (A.max_cycles && st->cycles >= A.max_cycles)
		return "cycles";
	if (A.ended_by_time)
		return "time";
	return interrupted ? "signal" : "stop";
}

/* The slowest reaction to a trip: for every loop fault that put (or
 * kept) the loop in safe state, the cycles from the one that saw it to
 * the first in safe state (-1: no fault to check; 1000: none within the
 * run). Needs the per-cycle record (runs of a known length) and the
 * faults list (kept when faults are injected). */
static int64_t trip_to_safe(uint64_t *checked)
{
	int64_t worst = -1;
	size_t k;
	*checked = 0;
	if (!A.safe_bits)
		return -1;
	for (k = 0; k < A.n_lfaults; k++) {
		const struct px_fault *lf = &A.lfaults[k];
		int64_t d = 1000;
		uint64_t c;
		if (!lf->safe || lf->cycle >= A.safe_bits_n)
			continue;
		for (c = lf->cycle; c < A.safe_bits_n && c < lf->cycle + 1000; c++)
			if (A.safe_bits[c >> 3] & (1u << (c & 7))) {
				d = (int64_t)(c - lf->cycle);
				break;
			}
		if (c == A.safe_bits_n && d == 1000)
			continue; /* the run ended first */
		(*checked)++;
		if (d > worst)
			worst = d;
	}
	return worst;
}

/* What the safety layer and the e-stop did: presses seen, how long after
 * the first press the loop was in safe state (ns, -1: never), state at
 * the end. */
static void json_safety(FILE *f, const struct px_loop_status *st)
{
	fprintf(f,
		"  \"safe_at_end\": %d,\n  \"safe_cause\": \"%s\",\n"
		"  \"estop_lines\": %d,\n  \"estop_presses\": %llu,\n"
		"  \"estop_cycles\": %llu,\n  \"estop_to_safe_ns\": %lld,\n"
		"  \"estop_to_safe_cycles\": %lld,\n"
		"  \"safe_cycles_before_estop\": %llu,\n"
		"  \"safe_at_estop\": %d,\n"
		"  \"enable_write_errors\": %llu,\n",
		st->safe, st->safe ? px_fault_cause_name(st->safe_cause) : "",
		A.n_dio, (unsigned long long)A.estop_presses,
		(unsigned long long)A.estop_cycles,
		(long long)(A.estop_first_ns >= 0 && A.safe_first_after_estop_ns >= 0
				    ? A.safe_first_after_estop_ns - A.estop_first_ns
				    : -1),
		(long long)(A.estop_first_ns >= 0 && A.safe_first_after_estop_ns >= 0
				    ? (long long)(A.safe_first_cycle_after_estop -
						  A.estop_first_cycle)
				    : -1),
		(unsigned long long)A.safe_cycles_before_estop, A.safe_at_estop,
		(unsigned long long)A.enable_errors);
}

/* Every device's counters, and the CANopen drives' states. */
static void json_devices(FILE *f)
{
	int i;
	fputs("  \"devices\": [", f);
	for (i = 0; i < A.n_dev; i++) {
		struct px_dev_status s;
		if (px_dev_status(A.dev[i], &s) != PX_OK)
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
	fputs(A.n_dev ? "\n  ],\n" : "],\n", f);
	fprintf(f,
		"  \"drives_enabled_cycles\": %llu,\n"
		"  \"drive_problem_cycles\": %llu,\n  \"drives\": [",
		(unsigned long long)A.enabled_cycles,
		(unsigned long long)A.drive_problem_cycles);
	for (i = 0; A.co && i < A.n_drives; i++) {
		struct px_canopen_drive_status ds;
		if (px_canopen_drive_status(A.co, (size_t)i, &ds) != PX_OK)
			continue;
		fprintf(f,
			"%s\n    {\"node_id\": %d, \"state\": \"%s\", "
			"\"position\": %.9g, \"lost\": %d, \"emcy\": %llu}",
			i ? "," : "", ds.node_id, px_cia402_state_name(ds.state),
			json_num(ds.position), ds.lost,
			(unsigned long long)ds.emcy_count);
	}
	fputs(A.co && A.n_drives ? "\n  ],\n" : "],\n", f);
}

static int write_json(const char *path, const struct px_loop_status *st,
		      const struct px_stats_snapshot *lat,
		      const struct px_stats_snapshot *cmp, double wall_s,
		      const char *time_svg, const char *lat_svg,
		      const char *counter)
{
	static struct tool_out out;
	FILE *f;
	struct dev_faults df;
	int k;
	if (tool_out_open(&out, path) != 0) {
		snprintf(A.out_why, sizeof(A.out_why), "%s", out.why);
		return -1;
	}
	f = out.f;
	device_faults(&df);
	fprintf(f, "{\n  \"config\": ");
	json_string(f, A.o.config);
	fprintf(f,
		",\n  \"clock\": \"%s\",\n  \"period_ns\": %lld,\n"
		"  \"simulated_s\": %.6f,\n  \"wall_s\": %.3f,\n"
		"  \"cycles\": %llu,\n  \"overruns\": %llu,\n"
		"  \"missed_periods\": %llu,\n",
		A.o.virtual_time ? "virtual" : "monotonic",
		(long long)st->period_ns,
		(double)st->cycles * (double)st->period_ns * 1e-9, wall_s,
		(unsigned long long)st->cycles, (unsigned long long)st->overruns,
		(unsigned long long)st->missed_periods);
	fprintf(f,
		"  \"loop_time_s\": %.6f,\n  \"wall_time_s\": %.3f,\n"
		"  \"duration_s\": %.9g,\n  \"ended_by\": \"%s\",\n",
		loop_time_s(st), wall_s, A.o.duration_s, ended_by(st));
	json_stats(f, "wakeup_latency_ns", lat, 0);
	json_stats(f, "compute_ns", cmp, 0);
	{
		struct px_model_stream_stats ts;
		int ns = px_world_tracking_stats(A.tracking, &ts);
		fprintf(f,
			"  \"tracking\": {\"enabled\": %s, \"streams\": %d, "
			"\"queries\": %llu, \"tracked\": %llu, \"hot\": %llu, "
			"\"global\": %llu, \"cold\": %llu, \"jumps\": %llu, "
			"\"reinits\": %llu, \"verifications\": %llu, "
			"\"disagreements\": %llu},\n",
			A.tracking ? "true" : "false", ns,
			(unsigned long long)ts.queries,
			(unsigned long long)ts.tracked,
			(unsigned long long)ts.hot, (unsigned long long)ts.global,
			(unsigned long long)ts.cold, (unsigned long long)ts.jumps,
			(unsigned long long)ts.reinits,
			(unsigned long long)ts.verifications,
			(unsigned long long)ts.disagreements);
	}
	fprintf(f,
		"  \"max_force_n\": %.9g,\n  \"force_clamp_n\": %.9g,\n"
		"  \"min_distance_m\": %.9g,\n  \"max_penetration_m\": %.9g,\n"
		"  \"min_proxy_distance_m\": %.9g,\n"
		"  \"min_clearance_m\": %.9g,\n  \"protective_distance_m\": %.9g,\n"
		"  \"min_speed_scale\": %.9g,\n"
		"  \"contact_cycles\": %llu,\n  \"safe_state_trips\": %llu,\n"
		"  \"faults\": {",
		A.max_force_n, A.rendering ? A.ctl.haptic.max_force_n : 0.0,
		json_num(A.min_distance_m), A.max_penetration_m,
		json_num(A.min_proxy_distance_m),
		A.avoiding ? json_num(A.min_clearance_m) : 0.0,
		A.avoiding ? A.ctl.avoid.protective_distance_m : 0.0,
		A.avoiding ? A.min_scale : 1.0,
		(unsigned long long)A.contact_cycles,
		(unsigned long long)st->safe_entries);
	for (k = 1; k < PX_FAULT__COUNT; k++)
		fprintf(f, "\"%s\": %llu, ", px_fault_cause_name(k),
			(unsigned long long)A.faults_by_cause[k]);
	for (k = 1; k < PX_DEV_ERR__COUNT; k++)
		if (k != PX_DEV_ERR_OPEN && k != PX_DEV_ERR_ESTOP &&
		    k != PX_DEV_ERR_ENCODE)
			fprintf(f, "\"device_%s\": %llu, ", px_dev_errkind_name(k),
				(unsigned long long)df.by_kind[k]);
	fprintf(f,
		"\"velocity_limit\": %llu, \"query_error\": %llu, "
		"\"dropped\": %llu},\n",
		(unsigned long long)A.velocity_trips,
		(unsigned long long)A.query_errors,
		(unsigned long long)st->faults_dropped);
	json_safety(f, st);
	json_devices(f);
	json_shutdown(f);
	{
		uint64_t checked;
		int64_t worst = trip_to_safe(&checked);
		int64_t span = A.have_deadline ? A.last_deadline_ns -
							 A.first_deadline_ns
					       : 0;
		int64_t want = st->cycles
				       ? ((int64_t)st->cycles - 1 +
					  (int64_t)st->missed_periods) *
						 st->period_ns
				       : 0;
		fprintf(f,
			"  \"faults_injected\": %zu,\n  \"faults_popped\": %llu,\n"
			"  \"watchdog_trips_checked\": %llu,\n"
			"  \"max_trip_to_safe_cycles\": %lld,\n"
			"  \"nonfinite_outputs\": %llu,\n"
			"  \"phase_error_ns\": %lld,\n",
			A.sim.n_faults, (unsigned long long)A.faults_popped,
			(unsigned long long)checked, (long long)worst,
			(unsigned long long)A.nonfinite_outputs,
			(long long)(span - want));
	}
	json_campaign(f);
	fprintf(f,
		"  \"allocations_after_setup\": %llu,\n"
		"  \"allocations_setup\": %llu,\n"
		"  \"allocation_counter\": \"%s\",\n"
		"  \"telemetry_records\": %llu,\n  \"telemetry_dropped\": %llu,\n"
		"  \"telemetry_decimation\": %lld,\n"
		"  \"realtime\": %d,\n  \"csv\": ",
		(unsigned long long)atomic_load(&A.allocs),
		(unsigned long long)A.setup_heap_calls, counter,
		(unsigned long long)A.n_rows,
		(unsigned long long)px_ring_dropped(A.ring), (long long)A.decimation,
		st->realtime);
	if (A.csv_path[0])
		json_string(f, A.csv_path);
	else
		fputs("null", f);
	fputs(",\n  \"plots\": [", f);
	json_string(f, time_svg);
	fputs(", ", f);
	json_string(f, lat_svg);
	fputs("]\n}\n", f);
	if (tool_out_commit(&out) != 0) {
		snprintf(A.out_why, sizeof(A.out_why), "%s", out.why);
		return -1;
	}
	return 0;
}

/* The telemetry CSV (A.csv_path, checked by validate()): its header now,
 * rows as the ring drains, renamed into place by close_csv(). Returns 0
 * or 1 (said why). */
static int open_csv(void)
{
	if (!A.csv_path[0])
		return 0;
	if (tool_out_open(&A.csv_out, A.csv_path) != 0) {
		fprintf(stderr, "proxima-run: %s\n", A.csv_out.why);
		return 1;
	}
	A.csv_f = A.csv_out.f;
	fprintf(A.csv_f,
		"t_s,cycle,x_m,y_m,z_m,proxy_x_m,proxy_y_m,proxy_z_m,"
		"fx_n,fy_n,fz_n,force_n,distance_m,penetration_m,"
		"contact,safe,wakeup_latency_ns,compute_ns,queries");
	if (A.avoiding) {
		/* distance_m is the clearance; x..z the closest link
		 * point, proxy_* the obstacle point */
		int j;
		fprintf(A.csv_f, ",speed_scale");
		for (j = 0; j < avoid_joints(); j++)
			fprintf(A.csv_f, ",qdot%d_rad_per_s", j);
	}
	fputc('\n', A.csv_f);
	return 0;
}

/* The CSV complete: in place under its name (said why when not). */
static void close_csv(void)
{
	if (!A.csv_f)
		return;
	A.csv_f = NULL;
	if (tool_out_commit(&A.csv_out) != 0)
		fprintf(stderr, "proxima-run: %s\n", A.csv_out.why);
}

/* What the safety layer did about configured fault i: loop faults seen
 * from the window's start to its end plus the device timeout (and 10 ms),
 * and the time from the start to the first that put or kept the loop in
 * safe state (-1: none). */
static void campaign_reaction(size_t i, uint64_t *n, int64_t *safe_after_ns,
			      int64_t *t0, int64_t *t1)
{
	const struct raw_fault *f = &A.sim.faults[i];
	const struct px_config_device *d = px_config_device_find(A.cfg, f->device);
	int64_t tmo = d && d->stale_timeout_ns ? d->stale_timeout_ns
					       : A.cfg->safety.watchdog.device_timeout_ns;
	size_t k;
	*t0 = A.clock0_ns + f->start_ns;
	*t1 = *t0 + f->duration_ns + tmo + 10000000;
	*n = 0;
	*safe_after_ns = -1;
	for (k = 0; k < A.n_lfaults; k++) {
		const struct px_fault *lf = &A.lfaults[k];
		if (lf->t_ns < *t0 || lf->t_ns > *t1)
			continue;
		(*n)++;
		if (lf->safe && *safe_after_ns < 0)
			*safe_after_ns = lf->t_ns - *t0;
	}
}

static void print_campaign(void)
{
	size_t i;
	if (!A.sim.n_faults)
		return;
	printf("  fault campaign    (loop faults from each window's start to "
	       "its end + device timeout)\n");
	for (i = 0; i < A.sim.n_faults; i++) {
		const struct raw_fault *f = &A.sim.faults[i];
		uint64_t n;
		int64_t after, t0, t1;
		campaign_reaction(i, &n, &after, &t0, &t1);
		printf("    %-9s %-8s %7.3f..%7.3f s p %.2f: %4llu loop faults, ",
		       fault_kind_names[f->kind], f->device, (double)f->start_ns * 1e-9,
		       (double)(f->start_ns + f->duration_ns) * 1e-9, f->probability,
		       (unsigned long long)n);
		if (after >= 0)
			printf("safe state after %.1f ms\n", (double)after * 1e-6);
		else
			printf("no safe state (samples stayed fresh)\n");
	}
}

static void json_campaign(FILE *f)
{
	size_t i;
	fputs("  \"fault_campaign\": [", f);
	for (i = 0; i < A.sim.n_faults; i++) {
		const struct raw_fault *x = &A.sim.faults[i];
		uint64_t n;
		int64_t after, t0, t1;
		campaign_reaction(i, &n, &after, &t0, &t1);
		fprintf(f,
			"%s\n    {\"kind\": \"%s\", \"device\": ", i ? "," : "",
			fault_kind_names[x->kind]);
		json_string(f, x->device);
		fprintf(f,
			", \"start_ns\": %lld, \"duration_ns\": %lld, "
			"\"loop_faults\": %llu, \"safe_after_ns\": %lld}",
			(long long)x->start_ns, (long long)x->duration_ns,
			(unsigned long long)n, (long long)after);
	}
	fputs(A.sim.n_faults ? "\n  ],\n" : "],\n", f);
}

static void print_summary(const struct px_loop_status *st,
			  const struct px_stats_snapshot *lat,
			  const struct px_stats_snapshot *cmp, double wall_s)
{
	int k;
	printf("proxima-run: %s (%s clock)\n", A.o.config,
	       A.o.virtual_time ? "virtual" : "monotonic");
	printf("  cycles            %llu in %.3f s simulated, %.3f s wall "
	       "(%.0f cycles/s)\n",
	       (unsigned long long)st->cycles,
	       (double)st->cycles * (double)st->period_ns * 1e-9, wall_s,
	       wall_s > 0 ? (double)st->cycles / wall_s : 0.0);
	printf("  time              loop clock %.3f s (%llu missed period%s), "
	       "wall %.3f s; ",
	       loop_time_s(st), (unsigned long long)st->missed_periods,
	       st->missed_periods == 1 ? "" : "s", wall_s);
	if (A.o.duration_s > 0)
		printf("--duration-s %g: ended by %s\n", A.o.duration_s,
		       ended_by(st));
	else
		printf("until stopped: ended by %s\n", ended_by(st));
	printf("  overruns          %llu (missed periods %llu)%s\n",
	       (unsigned long long)st->overruns,
	       (unsigned long long)st->missed_periods,
	       A.o.virtual_time ? ""
	       : st->realtime   ? " on SCHED_FIFO"
				: " (not real-time scheduled)");
	printf("  wake-up latency   p50 %.1f us, p99 %.1f us, p99.9 %.1f us, "
	       "max %.1f us\n",
	       lat->p50_ns / 1e3, lat->p99_ns / 1e3, lat->p999_ns / 1e3,
	       lat->max_ns / 1e3);
	printf("  compute           p50 %.1f us, p99 %.1f us, p99.9 %.1f us, "
	       "max %.1f us\n",
	       cmp->p50_ns / 1e3, cmp->p99_ns / 1e3, cmp->p999_ns / 1e3,
	       cmp->max_ns / 1e3);
	if (A.rendering)
		printf("  force             max %.3f N (clamp %.3f N), contact "
		       "in %.1f %% of cycles\n",
		       A.max_force_n, A.ctl.haptic.max_force_n,
		       st->cycles ? 100.0 * (double)A.contact_cycles /
					    (double)st->cycles
				  : 0.0);
	if (A.avoiding)
		printf("  avoidance         min clearance %.1f mm (protective %.1f "
		       "mm, influence %.1f mm), speed scale min %.2f, nominal "
		       "motion stopped in %llu cycles\n",
		       json_num(A.min_clearance_m) * 1e3,
		       A.ctl.avoid.protective_distance_m * 1e3,
		       A.ctl.avoid.influence_distance_m * 1e3, A.min_scale,
		       (unsigned long long)A.stop_cycles);
	else if (A.ctl_dev >= 0)
		printf("  distance          min %+.3f mm, max penetration %.3f mm, "
	       "proxy min clearance %+.3f mm\n",
	       json_num(A.min_distance_m) * 1e3, A.max_penetration_m * 1e3,
	       json_num(A.min_proxy_distance_m) * 1e3);
	printf("  safe state        %llu trip%s",
	       (unsigned long long)st->safe_entries,
	       st->safe_entries == 1 ? "" : "s");
	for (k = 1; k < PX_FAULT__COUNT; k++)
		if (A.faults_by_cause[k])
			printf(", %s %llu", px_fault_cause_name(k),
			       (unsigned long long)A.faults_by_cause[k]);
	if (A.velocity_trips)
		printf(", velocity limit %llu", (unsigned long long)A.velocity_trips);
	if (A.query_errors)
		printf(", query errors %llu (last: %s)",
		       (unsigned long long)A.query_errors,
		       px_strerror(A.last_query_err));
	if (A.n_dio)
		printf("\n  e-stop            %llu press%s, held %llu cycles%s",
		       (unsigned long long)A.estop_presses,
		       A.estop_presses == 1 ? "" : "es",
		       (unsigned long long)A.estop_cycles,
		       st->safe ? "; in safe state at the end" : "");
	if (A.co) {
		int i, n = 0;
		for (i = 0; i < A.n_drives; i++) {
			struct px_canopen_drive_status ds;
			if (px_canopen_drive_status(A.co, (size_t)i, &ds) == PX_OK &&
			    ds.state == PX_CIA402_OPERATION_ENABLED)
				n++;
		}
		printf("\n  drives            %d on '%s', enabled in %llu cycles, "
		       "%d in operation enabled at the end",
		       A.n_drives, A.co_name, (unsigned long long)A.enabled_cycles,
		       n);
	}
	if (A.tracking) {
		struct px_model_stream_stats ts;
		int ns = px_world_tracking_stats(A.tracking, &ts);
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
	if (!px_alloc_count_thread)
		printf("\n  allocations       not counted (no heap counter: "
		       "preload libproxima-alloc-count.so)\n");
	else
		printf("\n  allocations       %llu after setup (loop thread; "
		       "setup made %llu)\n",
		       (unsigned long long)atomic_load(&A.allocs),
		       (unsigned long long)A.setup_heap_calls);
	printf("  telemetry         %llu records (every %lld cycles), %llu "
	       "dropped\n",
	       (unsigned long long)A.n_rows, (long long)A.decimation,
	       (unsigned long long)px_ring_dropped(A.ring));
	shutdown_line(stdout, "  shutdown          ");
	print_campaign();
}

/* Parse --fault KIND,DEVICE,START_S,DURATION_S[,PROBABILITY[,DELAY_S]]
 * into f. Returns NULL or why not. */
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
	for (k = 0; fault_kind_names[k]; k++)
		if (strcmp(fld[0], fault_kind_names[k]) == 0)
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
static int add_cli_faults(void)
{
	static char devs[64][64];
	size_t n = A.sim.n_faults, i;
	if (!A.o.n_fault)
		return 0;
	A.all_faults = calloc(n + (size_t)A.o.n_fault, sizeof(*A.all_faults));
	if (!A.all_faults)
		return 2;
	if (n)
		memcpy(A.all_faults, A.sim.faults, n * sizeof(*A.all_faults));
	for (i = 0; i < (size_t)A.o.n_fault; i++) {
		char buf[200];
		const char *why = parse_fault(A.o.fault[i], &A.all_faults[n],
					      devs[i], sizeof(devs[i]), buf,
					      sizeof(buf));
		if (!why)
			why = fault_misfit(A.cfg, &A.all_faults[n], buf, sizeof(buf));
		if (why) {
			fprintf(stderr, "proxima-run: --fault %s: %s\n",
				A.o.fault[i], why);
			return 2;
		}
		n++;
	}
	if (n > MAX_CAMPAIGN) {
		fprintf(stderr, "proxima-run: more than %d faults\n", MAX_CAMPAIGN);
		return 2;
	}
	A.sim.faults = A.all_faults;
	A.sim.n_faults = n;
	return 0;
}

int main(int argc, char **argv)
{
	static struct px_config_diag diag;
	const char *counter = heap_counter_name();
	struct px_loop_status st;
	struct px_stats_snapshot lat, cmp;
	char time_svg[1100], lat_svg[1100];
	int64_t wall0;
	double wall_s;
	int rc = parse_args(argc, argv, &A.o);
	if (rc)
		return rc == 1 ? 0 : rc;
	/* from here on a signal ends the run through the safe state */
	install_signals();
	rc = px_config_load_file(A.o.config, &A.cfg, &diag);
	if (rc != PX_OK)
		return report_config(rc, &diag);
	rc = px_control_config_read(A.cfg, &A.ctl, &diag);
	if (rc != PX_OK) {
		report_config(rc, &diag);
		px_config_free(A.cfg);
		return 1;
	}
	A.sim.cfg_ = A.cfg;
	rc = px_config_read(A.cfg->doc, A.cfg->sim, "sim", &sim_schema, &A.sim,
			    &diag);
	if (rc != PX_OK) {
		report_config(rc, &diag);
		px_config_free(A.cfg);
		return 1;
	}
	if (A.ctl.warning[0])
		fprintf(stderr, "%s\n", A.ctl.warning);
	rc = add_cli_faults();
	if (rc) {
		free(A.all_faults);
		px_config_free(A.cfg);
		return rc;
	}
	if (A.o.check)
		return check_config();
	rc = setup();
	if (rc) {
		teardown();
		return rc;
	}
	if (open_csv()) {
		teardown();
		return 1;
	}
	A.alloc_probe = getenv("PX_RUN_ALLOC_PROBE") &&
			strcmp(getenv("PX_RUN_ALLOC_PROBE"), "1") == 0;
	A.setup_heap_calls = heap_count();
	rearm_warnings(stderr);
	fprintf(stderr,
		"proxima-run: %s: %zu scene model%s, %d device%s, %s, %s clock, "
		"%s\n",
		A.o.config, px_world_count(A.scene),
		px_world_count(A.scene) == 1 ? "" : "s",
		(int)A.cfg->n_devices, A.cfg->n_devices == 1 ? "" : "s",
		A.rendering ? (A.ctl.haptic.renderer == PX_CONTROL_PROXY
				       ? "haptic proxy rendering"
				       : "haptic penalty rendering")
		: A.avoiding ? "collision avoidance over CANopen"
			     : "no control output",
		A.o.virtual_time ? "virtual" : "real-time",
		A.max_cycles ? "fixed duration" : "until Ctrl-C");
	wall0 = mono_ns();
	rc = run();
	wall_s = (double)(mono_ns() - wall0) * 1e-9;
	{
		/* the loop has stopped: zero force, relays off, drives
		 * disabled, before the summary (which reports it) and
		 * before anything closes */
		char why[32];
		if (stop_signal)
			signal_reason(stop_signal, why, sizeof(why));
		else
			snprintf(why, sizeof(why), "%s",
				 rc < 0 ? "loop error" : "end of run");
		safe_shutdown(why);
	}
	drain();
	{
		struct px_loop_status s0;
		px_loop_status(A.loop, &s0);
		status_line(1, wall_s,
			    wall_s > 0 ? (double)s0.cycles / wall_s : 0.0);
	}
	close_csv();
	px_loop_status(A.loop, &st);
	px_loop_stats(A.loop, PX_LOOP_STAT_LATENCY, &lat);
	px_stats_read(A.compute, &cmp);
	print_summary(&st, &lat, &cmp, wall_s);
	plot_paths(time_svg, lat_svg, sizeof(time_svg));
	if (A.csv_path[0])
		printf("  csv               %s\n", A.csv_path);
	if (write_plots(time_svg, lat_svg) == 0)
		printf("  plots             %s\n                    %s\n", time_svg,
		       lat_svg);
	else
		fprintf(stderr, "proxima-run: cannot write the plots: %s\n",
			tool_svg_error());
	if (A.o.summary_json) {
		if (write_json(A.o.summary_json, &st, &lat, &cmp, wall_s, time_svg,
			       lat_svg, counter) == 0)
			printf("  summary           %s\n", A.o.summary_json);
		else
			fprintf(stderr, "proxima-run: %s\n", A.out_why);
	}
	if (rc < 0)
		fprintf(stderr, "proxima-run: the loop stopped: %s\n",
			px_strerror(rc));
	if (!SD.safe)
		shutdown_line(stderr, "proxima-run: shutdown: ");
	teardown();
	return rc < 0 || !SD.safe ? 1 : 0;
}
