/*
 * px_dev.h - device interfaces: pose sources, force sinks and digital
 * I/O, behind one opaque handle whose back end is a const ops table.
 *
 * What the cycle sees. px_dev_pose_read() gives the newest pose sample
 * (position in m, unit quaternion, velocity estimate, buttons, sample
 * time, sequence number) with its age against the loop clock and a
 * stale flag (no sample yet, device unplugged, or older than the
 * device's stale_timeout_ns). A HID pose device reporting at 60-125 Hz
 * read by a 1 kHz loop shows fresh = 1 in about one cycle in ten and the
 * age growing in between; that is visible, not hidden. px_dev_force_write()
 * encodes and sends a force/torque command; px_dev_estop_read(),
 * px_dev_enable_write() and px_dev_timing_write() are the digital I/O.
 *
 * Threads and hand-off. A read inside a cycle never blocks. A back end
 * that needs blocking I/O (hidapi) runs its own reader thread, started
 * at setup (px_dev_start), which feeds samples through
 * px_dev_feed_report() / px_dev_publish_pose(); the newest sample crosses
 * to the cycle through a px_param triple buffer (wait-free both sides,
 * never torn, intermediate samples skipped). Back ends without a thread
 * (simulated devices, non-blocking sockets) do their work in the ops'
 * poll(), called by px_dev_pose_read() on the loop thread. So for one
 * device there is exactly one feeding thread: its reader thread, or the
 * loop thread through poll().
 *
 * Loop clock. Sample times are on the loop's clock: CLOCK_MONOTONIC for
 * real back ends (their reader threads stamp with it), the virtual clock
 * for simulated devices driven by the loop (they take now_ns from the
 * cycle). px_dev_attach() registers the device's pose input with a loop
 * watchdog: each fresh valid sample is stamped with px_loop_input_stamp(),
 * so a dropped, delayed, corrupted, stuck, NaN or unplugged device trips
 * safe state after stale_timeout_ns, and px_dev_force_attach() registers
 * a force command as loop outputs and enable flag, so safe state zeroes
 * it before the write phase sends it.
 *
 * Errors say what and where: every rejected report, failed call and
 * fault is counted in the status, and the most recent one is kept as a
 * record (error code, raw errno, frame/report id, codec details)
 * that px_dev_status() turns into a message naming the device, e.g.
 * "haptic (hidapi): report 0x01: 9 bytes, inputs[2] needs 13".
 *
 * Memory: px_dev_create() takes one setup-time allocation (arena for
 * the hand-off buffers plus the back end's private block); nothing a
 * cycle calls allocates. Setup functions (create, attach, start, stop,
 * free) are not RT-safe; functions marked @note RT-safe are.
 */
#ifndef PX_DEV_H
#define PX_DEV_H

#include <stddef.h>
#include <stdint.h>

#include "px_base.h"
#include "px_codec.h"
#include "px_math.h"

#ifdef __cplusplus
extern "C" {
#endif

struct px_dev;
struct px_loop;

/* What a device offers (bits). */
enum px_dev_cap {
	PX_DEV_CAP_POSE = 1,  /* pose source */
	PX_DEV_CAP_FORCE = 2, /* force sink */
	PX_DEV_CAP_DIO = 4    /* digital I/O: e-stop in, enable/timing out */
};

enum px_dev_state {
	PX_DEV_STATE_CLOSED = 0,    /* created, not started */
	PX_DEV_STATE_RUNNING = 1,   /* started, present */
	PX_DEV_STATE_UNPLUGGED = 2, /* gone; samples stale until replug */
	PX_DEV_STATE_FAILED = 3     /* back end stopped on an error */
};

/* Kinds of recorded problems (what the last error record is about). */
enum px_dev_errkind {
	PX_DEV_ERR_NONE = 0,
	PX_DEV_ERR_DECODE,     /* input report rejected by the codec */
	PX_DEV_ERR_NONFINITE,  /* sample with NaN/inf rejected */
	PX_DEV_ERR_DUPLICATE,  /* same report again too soon: dropped */
	PX_DEV_ERR_STUCK,      /* value unchanged for stuck_limit samples */
	PX_DEV_ERR_UNPLUG,     /* device disappeared */
	PX_DEV_ERR_OPEN,       /* open failed */
	PX_DEV_ERR_IO,         /* read/write call failed */
	PX_DEV_ERR_ENCODE,     /* output command rejected (NaN, buffer) */
	PX_DEV_ERR_BUS,        /* bus error (CAN error frame) */
	PX_DEV_ERR_ESTOP,      /* e-stop pressed */
	PX_DEV_ERR__COUNT
};

struct px_pose_sample {
	px_vec3 pos_m;
	px_quat q;           /* unit; identity when the device has no rotation */
	px_vec3 vel_m_s;     /* finite difference of the last two samples */
	uint64_t buttons;
	int64_t t_ns;        /* when sampled, loop clock */
	uint64_t seq;        /* 1, 2, ... per accepted sample; 0 = none yet */
	int64_t age_ns;      /* now_ns - t_ns at the read */
	int valid;           /* a sample exists and the device is present */
	int stale;           /* !valid or age_ns > stale_timeout_ns */
	int fresh;           /* seq differs from the previous read's */
};

/* Force/torque command. As loop outputs: force_n and torque_n_m are
 * zeroed and enable cleared in safe state (px_dev_force_attach). */
struct px_force_cmd {
	double force_n[3];
	double torque_n_m[3];
	int enable;
};

/* Digital outputs of a DIO device. */
enum px_dio_out {
	PX_DIO_ENABLE = 0, /* amplifier enable / relay */
	PX_DIO_TIMING = 1  /* loop-timing toggle (scope probe) */
};

struct px_dev_status {
	char name[32];
	const char *backend;   /* static string from the ops table */
	int state;             /* enum px_dev_state */
	uint64_t reports;      /* input reports/frames seen */
	uint64_t samples;      /* samples accepted (= newest seq) */
	uint64_t decode_errors;
	uint64_t nonfinite;
	uint64_t duplicates;
	uint64_t stuck;        /* times the stuck detector fired */
	uint64_t unplugs, replugs;
	uint64_t writes, write_errors;
	uint64_t io_errors;
	uint64_t bus_errors;
	uint64_t safe_writes;  /* safe outputs sent and confirmed (px_dev_safe) */
	uint64_t safe_errors;  /* safe outputs that failed */
	/* 1 when the newest output of the device is a confirmed safe one
	 * (no force or output change since); 0 otherwise. */
	int outputs_safe;
	uint64_t errors;       /* all recorded problems */
	/* The last recorded problem. */
	int last_kind;         /* enum px_dev_errkind */
	int last_err;          /* px_err code */
	int last_errno;        /* raw errno (0 when none) */
	int64_t last_frame_id; /* report id / CAN id / line, -1 none */
	int64_t last_t_ns;
	char last_msg[160];    /* "name (backend): what, where" */
};

/* A back end. Every pointer may be NULL where the back end has no such
 * thing. poll, force, estop and dio_write run in the cycle (RT rules);
 * start, stop, safe and destroy at setup or shutdown. safe puts every
 * output in its safe state (zero force and torque with enable off;
 * enable and timing outputs off) and confirms it where the back end can
 * (a write acknowledged, a line read back), waiting a bounded time at
 * most; NULL means the generic safe output of px_dev_safe(). */
struct px_dev_ops {
	const char *backend;   /* "sim-haptic", "hidapi", ... */
	unsigned caps;         /* enum px_dev_cap bits */
	int (*start)(struct px_dev *d);
	void (*stop)(struct px_dev *d);
	int (*poll)(struct px_dev *d, int64_t now_ns);
	int (*force)(struct px_dev *d, const struct px_force_cmd *c,
		     int64_t now_ns);
	int (*estop)(struct px_dev *d, int64_t now_ns, int *pressed);
	int (*dio_write)(struct px_dev *d, int which, int value,
			 int64_t now_ns);
	int (*safe)(struct px_dev *d, int64_t now_ns);
	void (*destroy)(struct px_dev *d); /* free the back end's resources */
};

struct px_dev_config {
	const char *name;          /* copied, up to 31 bytes */
	int64_t stale_timeout_ns;  /* default 20 ms */
	/* Report codec (report back ends); must outlive the device. */
	const struct px_codec_map *codec;
	/* An identical report of the same id sooner than this after the
	 * previous one is a duplicate and dropped; 0 = no check. */
	int64_t min_report_interval_ns;
	/* Samples with all axes exactly unchanged this many times in a row
	 * mark the device stuck (samples invalid until a change); 0 = off.
	 * For devices with sensor noise, where exact repeats mean a frozen
	 * reading. */
	uint32_t stuck_limit;
};

PX_API void px_dev_config_default(struct px_dev_config *cfg);

/*
 * Create a device with back end ops and impl_size bytes of zeroed
 * private memory (px_dev_impl()). cfg is copied (codec by pointer).
 * Setup only. Returns PX_OK, PX_E_INVAL (NULL ops/cfg, bad codec map:
 * see px_dev_status) or PX_E_NOMEM; *out NULL on failure.
 */
PX_API int px_dev_create(const struct px_dev_ops *ops,
			 const struct px_dev_config *cfg, size_t impl_size,
			 struct px_dev **out);

/* Stop (if started), destroy the back end, free. A device with outputs
 * that were written since its last safe output gets one first
 * (px_dev_safe), so freeing never leaves the last command in effect.
 * NULL is a no-op. */
PX_API void px_dev_free(struct px_dev *d);

/* Start the back end (reader threads, opening). Setup only. Returns
 * PX_OK or the back end's error (recorded in the status). */
PX_API int px_dev_start(struct px_dev *d);
/* Stop reader threads; the device can be started again. As
 * px_dev_free(), a device written to since its last safe output gets
 * one before its threads stop. */
PX_API void px_dev_stop(struct px_dev *d);

/*
 * Put the device's outputs in their safe state at now_ns (loop clock):
 * a force sink gets zero force and torque with enable off, through the
 * same encoding as any command (codec, CAN signals); a digital I/O
 * device gets its enable output (relay) and timing output off. Where the
 * back end can confirm (a write acknowledged by the transport, an output
 * line read back) it does, waiting at most about 250 ms for a device
 * thread to send. Tried whatever the device state (an unplugged device
 * cannot take it: PX_E_NODEV). A force write is counted as a write (so
 * a run of N cycles that ends safely shows N + 1); the outcome is kept
 * in the status (safe_writes, safe_errors, outputs_safe). Not for the
 * cycle (it may wait): call it after the loop stops, before closing.
 * Returns PX_OK (also for a device without outputs), PX_E_NODEV,
 * PX_E_IO, PX_E_TIMEOUT (a device thread did not send in time) or the
 * back end's error; PX_E_INVAL for NULL.
 */
PX_API int px_dev_safe(struct px_dev *d, int64_t now_ns);

/*
 * Register the device's pose input with loop l's watchdog (timeout
 * stale_timeout_ns); px_dev_pose_read() stamps it from then on. For a
 * digital I/O device without pose, remember l so that a pressed e-stop
 * trips it (px_gpio.h) and return 0. Setup only. Returns the input
 * index or px_loop_input_add()'s error.
 */
PX_API int px_dev_attach(struct px_dev *d, struct px_loop *l);

/*
 * Register cmd's force and torque as one loop output block (6 doubles)
 * and cmd->enable as an enable flag, so that safe state zeroes and
 * disables the command before the write phase. cmd must outlive the
 * loop. Setup only. Returns PX_OK or the loop's error.
 */
PX_API int px_dev_force_attach(struct px_dev *d, struct px_loop *l,
			       struct px_force_cmd *cmd);

/*
 * The newest pose sample as seen at now_ns (loop clock). Polls the back
 * end first when it has a poll(). Returns 1 when the sample is new
 * since the previous call, 0 when not (out still holds the newest, with
 * its age), PX_E_NODEV when the device is unplugged or failed (out is
 * the last sample, marked stale and invalid), PX_E_INVAL.
 * Loop thread only. @note RT-safe.
 */
PX_API int px_dev_pose_read(struct px_dev *d, int64_t now_ns,
			    struct px_pose_sample *out);

/*
 * Send a force command. A command with NaN/inf is refused (PX_E_NAN,
 * recorded; nothing sent); enable = 0 sends zero force. Returns PX_OK,
 * PX_E_NAN, PX_E_NODEV, PX_E_UNSUPPORTED (no force capability), or the
 * back end's error. Loop thread only. @note RT-safe.
 */
PX_API int px_dev_force_write(struct px_dev *d, const struct px_force_cmd *c,
			      int64_t now_ns);

/* E-stop input: *pressed = 1 when pressed (debounced). Returns PX_OK,
 * PX_E_UNSUPPORTED, PX_E_NODEV or the back end's error. Loop thread.
 * @note RT-safe. */
PX_API int px_dev_estop_read(struct px_dev *d, int64_t now_ns, int *pressed);

/* Digital output which (enum px_dio_out) to value (0/1). Loop thread.
 * @note RT-safe. */
PX_API int px_dev_dio_write(struct px_dev *d, int which, int value,
			    int64_t now_ns);

/* Status copy, with the last error formatted. Any thread; not RT-safe
 * (formats). Returns PX_OK or PX_E_INVAL. */
PX_API int px_dev_status(const struct px_dev *d, struct px_dev_status *st);

PX_API const char *px_dev_name(const struct px_dev *d);
PX_API unsigned px_dev_caps(const struct px_dev *d);
PX_API int64_t px_dev_stale_timeout_ns(const struct px_dev *d);

/* Name of an error kind, e.g. "decode". @note RT-safe. */
PX_API const char *px_dev_errkind_name(int kind);

/* ---- for back ends ------------------------------------------------- */

/* The back end's private block (impl_size bytes, zeroed at create). */
PX_API void *px_dev_impl(struct px_dev *d);
PX_API const struct px_dev_config *px_dev_config(const struct px_dev *d);
/* The ops table the device was created with. */
PX_API const struct px_dev_ops *px_dev_ops(const struct px_dev *d);

/*
 * Feed one input report received at t_ns through the device's codec:
 * duplicate check, decode (updating the axes it carries), then publish
 * a pose sample. Feeding thread only. Returns 1 when a sample was
 * published, 0 when the report was dropped as a duplicate, or the codec
 * error (recorded with report id and details). @note RT-safe.
 */
PX_API int px_dev_feed_report(struct px_dev *d, const uint8_t *buf,
			      size_t len, int64_t t_ns);

/*
 * Feed decoded axis values (enum px_axis; only axes in axis_mask
 * change) and buttons, as px_dev_feed_report() does after decoding.
 * Non-finite values are rejected (PX_E_NAN, recorded). Returns 1 when
 * published, PX_E_NAN, or 0 when the stuck detector holds it back.
 * Feeding thread only. @note RT-safe.
 */
PX_API int px_dev_feed_axes(struct px_dev *d,
			    const double axis[PX_AXIS__COUNT],
			    uint32_t axis_mask, uint64_t buttons,
			    uint64_t button_mask, int64_t t_ns);

/*
 * Record a problem: kind, px_err code, raw errno (0 none), frame id
 * (-1 none), codec diagnostic (may be NULL), what (a static string:
 * the failing call or a hint, e.g. "socket(PF_CAN): this kernel has no
 * AF_CAN support (modprobe can can-raw)"; may be NULL), time. Counts it
 * in the status. Never blocks: if another thread is recording at this
 * instant the record is counted but not kept. Any thread.
 * @note RT-safe.
 */
PX_API void px_dev_record(struct px_dev *d, int kind, int err, int sys_errno,
			  int64_t frame_id, const struct px_codec_diag *diag,
			  const char *what, int64_t t_ns);

/* Set the device state (enum px_dev_state); going to UNPLUGGED counts an
 * unplug, leaving it for RUNNING a replug. Any thread. @note RT-safe. */
PX_API void px_dev_set_state(struct px_dev *d, int state, int64_t t_ns);
PX_API int px_dev_state(const struct px_dev *d);

/* Add to a status counter from the back end. @note RT-safe. */
PX_API void px_dev_count_write(struct px_dev *d, int ok);

/* CLOCK_MONOTONIC in ns (the real loop clock). @note RT-safe. */
PX_API int64_t px_dev_mono_ns(void);

#ifdef __cplusplus
}
#endif

#endif
