/*
 * px_sim.h - simulated devices for tests and hardware-in-the-loop runs.
 *
 * The simulated haptic device is a mass-spring-damper arm per axis: the
 * operator's hand, following a scripted trajectory (hold, sum of
 * sinusoids, or a CSV file), pulls the arm through a spring and damper;
 * the commanded force pushes back; the device's own damping dissipates:
 *
 *     m a = F_cmd + k_h (x_hand - x) + c_h (v_hand - v) - c v
 *
 * integrated with semi-implicit Euler in steps of at most 100 us. Every
 * report_period_ns it encodes the arm position (plus Gaussian noise) into
 * HID input reports with the device's codec map, and those bytes go
 * through the real decoder (px_dev_feed_report), exactly as a hidapi
 * device's would. Force commands are encoded into output reports with
 * the same map and decoded back by the simulated device (px_codec_encode
 * then px_codec_decode_output), so both directions test the codec.
 *
 * The simulation runs on the loop thread inside px_dev_pose_read()
 * (ops poll) and takes its time from the cycle's now_ns: on the loop's
 * virtual clock it is deterministic for a given seed.
 *
 * Fault injection: windows [start_ns, start_ns + duration_ns) of the
 * simulation clock in which each report suffers the fault with a given
 * probability (seeded): drop, delay (reports held back: a gap, then a
 * burst, stamped on arrival as a reader thread would), duplicate,
 * corrupt (truncated report, then a hit report id byte, then a flipped
 * high bit of the report's first value, in turn: the last is caught only
 * by a plausibility limit, max_abs),
 * stuck (the same bytes again), NaN (a non-finite sample, as a float
 * device would send), unplug (no reports, state unplugged; replug when
 * the window ends). Each reaches the device status and, through
 * staleness, the loop watchdog.
 *
 * Memory: one setup-time allocation per device (px_dev_create), plus the
 * CSV table loaded at setup. Nothing in a cycle allocates.
 */
#ifndef PX_SIM_H
#define PX_SIM_H

#include <stddef.h>
#include <stdint.h>

#include "px_base.h"
#include "px_dev.h"

#ifdef __cplusplus
extern "C" {
#endif

enum px_sim_fault_kind {
	PX_SIM_FAULT_NONE = 0,
	PX_SIM_FAULT_DROP,
	PX_SIM_FAULT_DELAY,
	PX_SIM_FAULT_DUPLICATE,
	PX_SIM_FAULT_CORRUPT,
	PX_SIM_FAULT_STUCK,
	PX_SIM_FAULT_NAN,
	PX_SIM_FAULT_UNPLUG,
	PX_SIM_FAULT_BUSOFF, /* simulated CAN */
	PX_SIM_FAULT_ESTOP,  /* simulated GPIO: e-stop pressed */
	PX_SIM_FAULT__COUNT
};

struct px_sim_fault {
	int kind;             /* enum px_sim_fault_kind */
	int64_t start_ns;     /* simulation clock */
	int64_t duration_ns;  /* > 0 */
	double probability;   /* per report, (0, 1]; 0 means 1 */
	int64_t delay_ns;     /* delay: how long reports are held */
};

/* Name of a fault kind ("drop", ...), or NULL. And back from a name
 * (returns the kind or PX_E_NOTFOUND). @note RT-safe. */
PX_API const char *px_sim_fault_name(int kind);
PX_API int px_sim_fault_from_name(const char *name);

enum px_sim_traj_kind {
	PX_SIM_TRAJ_HOLD = 0,
	PX_SIM_TRAJ_SINES = 1,
	PX_SIM_TRAJ_CSV = 2
};

struct px_sim_sine {
	int axis;             /* PX_AXIS_X, _Y or _Z */
	double amplitude_m;
	double frequency_hz;
	double phase_rad;
};

/* A trajectory loaded from CSV: lines "t_s,x_m,y_m,z_m" with t strictly
 * increasing; blank lines, '#' comments and one header line (its first
 * field a name, not a number) before the first sample are skipped. An
 * empty field, NaN or inf is an error. */
struct px_sim_csv;

/*
 * Load a CSV trajectory (setup), at most PX_FILE_TEXT_MAX_BYTES (64 MiB,
 * px_file.h; a NUL byte is an error at its line and column). On
 * PX_E_PARSE / PX_E_IO / PX_E_RANGE (over the limit) / PX_E_NOTFOUND /
 * PX_E_NOMEM msg (cap bytes, may be NULL) says where: "hand.csv:7:
 * expected 4 finite numbers t_s,x_m,y_m,z_m (field 3 is empty)". Free
 * with px_sim_csv_free (NULL no-op).
 */
PX_API int px_sim_csv_load(const char *path, struct px_sim_csv **out,
			   char *msg, size_t cap);
PX_API void px_sim_csv_free(struct px_sim_csv *c);
/* Number of samples and duration (s) of a loaded trajectory. */
PX_API size_t px_sim_csv_count(const struct px_sim_csv *c);
PX_API double px_sim_csv_duration_s(const struct px_sim_csv *c);

#define PX_SIM_MAX_SINES 16
#define PX_SIM_MAX_FAULTS 16

struct px_sim_traj {
	int kind;                 /* enum px_sim_traj_kind */
	double center_m[3];
	const struct px_sim_sine *sines; /* copied, up to PX_SIM_MAX_SINES */
	size_t n_sines;
	const struct px_sim_csv *csv;    /* CSV: must outlive the device */
	int repeat;               /* CSV: loop at the end (else hold last) */
};

/* Hand position and velocity at t_s seconds. @note RT-safe. */
PX_API void px_sim_traj_eval(const struct px_sim_traj *tr, double t_s,
			     double pos_m[3], double vel_m_s[3]);

struct px_sim_haptic_config {
	double mass_kg;                 /* > 0 */
	double damping_n_s_per_m;       /* >= 0 */
	double hand_stiffness_n_per_m;  /* >= 0 */
	double hand_damping_n_s_per_m;  /* >= 0 */
	int64_t report_period_ns;       /* > 0 */
	uint64_t seed;
	double position_noise_m;        /* standard deviation, >= 0 */
	/* 1: a pose device that reports the hand trajectory itself (no
	 * arm dynamics, forces ignored): the config's sim kind "pose". */
	int follow_hand;
	struct px_sim_traj traj;
	const struct px_sim_fault *faults; /* copied, up to PX_SIM_MAX_FAULTS */
	size_t n_faults;
};

/* Defaults: 0.15 kg, 2 N s/m, hand 400 N/m and 4 N s/m, 1 ms reports,
 * seed 1, no noise, hold at the origin, no faults. */
PX_API void px_sim_haptic_config_default(struct px_sim_haptic_config *c);

/*
 * Create a simulated haptic (or pose) device. dcfg->codec NULL uses the
 * built-in "haptic" map; the map needs X, Y and Z inputs (in any
 * reports) and, unless follow_hand, FX/FY/FZ outputs. When
 * dcfg->min_report_interval_ns is 0 it is set to half the report
 * period, so duplicates are detected. Capabilities: pose, and force
 * unless follow_hand. Returns PX_OK, PX_E_INVAL (bad values; which one
 * in msg, cap bytes, may be NULL), PX_E_NOMEM.
 */
PX_API int px_sim_haptic_create(const struct px_dev_config *dcfg,
				const struct px_sim_haptic_config *cfg,
				struct px_dev **out, char *msg, size_t cap);

/* Simulation state of a sim haptic device (loop thread, or any thread
 * when the loop is not running). Returns PX_OK or PX_E_INVAL. */
struct px_sim_haptic_state {
	int64_t t_ns;
	double pos_m[3], vel_m_s[3];
	double hand_m[3];
	double force_n[3];          /* force in effect (decoded command) */
	/* What the device last received: the decoded torque of the
	 * newest output report, and the command's enable flag (0 before
	 * any); a safe output shows force and torque 0, enable 0. */
	double torque_n_m[3];
	int enable;
	uint64_t reports_sent;
	uint64_t reports_faulted;
	uint64_t outputs_decoded;
};
PX_API int px_sim_haptic_state(struct px_dev *d,
			       struct px_sim_haptic_state *st);

/* Bytes of the last output report the simulated device received
 * (copies up to cap; returns the length, 0 none). */
PX_API int px_sim_haptic_last_output(struct px_dev *d, uint8_t *buf,
				     size_t cap);

#ifdef __cplusplus
}
#endif

#endif
