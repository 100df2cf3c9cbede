/*
 * px_loop.h - the periodic real-time control loop.
 *
 * A px_loop wakes on absolute deadlines (clock_nanosleep with
 * TIMER_ABSTIME on CLOCK_MONOTONIC, so period errors never accumulate)
 * and runs three user phases per cycle: read (get device data), compute
 * (control law, distance queries), write (send commands). Around them it
 * keeps lock-free statistics (wake-up latency, compute time, cycle
 * time), handles overruns by a chosen policy, and runs a watchdog that
 * puts the loop in SAFE STATE in the very cycle that sees a fault:
 *
 *  - a watched input (px_loop_input_add) whose newest sample, as stamped
 *    by the read phase with px_loop_input_stamp(), is older than its
 *    timeout;
 *  - compute over its budget K cycles in a row;
 *  - NaN or infinity in a registered output (px_loop_output_add);
 *  - K overruns in a row (taking effect at the next write);
 *  - a phase callback returning an error, or px_loop_trip().
 *
 * In safe state the loop still runs every phase (so inputs stay fresh
 * and controllers keep their state), but after compute it zeroes every
 * registered output and clears every registered enable flag, and tells
 * the write phase (cycle->safe), which must send those zeros/disables to
 * the hardware. The cause is kept in the status and every fault goes to
 * a fault ring read outside the loop. Leaving safe state takes an
 * explicit px_loop_rearm() unless rearm_after_ok_cycles is set.
 *
 * Which causes re-arm by themselves (rearm_after_ok_cycles): those that
 * say the data or the timing was bad for a while and that the watchdog
 * sees again in the very cycle they come back: a stale input (a device
 * that answers again), compute over budget, overruns, a non-finite
 * output, a failing phase, px_loop_trip() (the application's own trips,
 * e.g. a velocity limit it checks every cycle). An emergency stop
 * (px_loop_trip_estop(), PX_FAULT_ESTOP) never does: its release must
 * not restart motion (ISO 13850, IEC 60204-1: the reset is a separate,
 * deliberate act), so safe state entered or joined by an e-stop lasts
 * until px_loop_rearm(), whatever the other causes do.
 *
 * The loop knows no device library: device back ends plug in through
 * the phase callbacks, the watched-input stamps and the registered
 * output buffers and enable flags.
 *
 * Clocks: PX_LOOP_CLOCK_MONOTONIC for real deadlines, or
 * PX_LOOP_CLOCK_VIRTUAL: the same code driven by simulated time that
 * jumps to each deadline instead of sleeping, as fast as the CPU allows
 * and deterministic; callbacks simulate time spent with
 * px_loop_vclock_advance(). For tests, soak runs and hardware-in-the-
 * loop simulation (px_loop_step() runs exactly one cycle).
 *
 * Memory: px_loop_create() takes one block sized from the config
 * (statistics, fault ring, input/output tables); px_loop_free() returns
 * it. Nothing a cycle does allocates. Output buffers and enable flags
 * stay owned by the caller and must outlive the loop.
 *
 * Driving: px_loop_run() (or its thread, px_loop_start()) keeps the
 * deadlines; px_loop_step() runs one cycle; px_loop_read(), _compute()
 * and _write() run one cycle phase by phase from the caller's own thread
 * and clock, with the same checks between the phases as a whole cycle.
 *
 * Threads: one thread runs the cycle (px_loop_run, px_loop_step or the
 * phase calls, or the thread px_loop_start makes). Functions marked "any
 * thread" may be called from others at any time; px_loop_fault_pop()
 * from one reader.
 * Setup functions (create, *_add) only before the loop runs.
 */
#ifndef PX_LOOP_H
#define PX_LOOP_H

#include <stddef.h>
#include <stdint.h>

#include "px_base.h"
#include "px_fault.h"
#include "px_rt.h"
#include "px_stats.h"

#ifdef __cplusplus
extern "C" {
#endif

struct px_loop;

enum px_loop_clock {
	PX_LOOP_CLOCK_MONOTONIC = 0, /* real time, CLOCK_MONOTONIC */
	PX_LOOP_CLOCK_VIRTUAL = 1    /* simulated time, no sleeping */
};

enum px_loop_overrun {
	/* Skip the periods already missed, keeping the phase of the
	 * deadlines, and count them (ros2_control's behaviour). */
	PX_LOOP_OVERRUN_SKIP = 0,
	/* Run the missed cycles back to back, at most max_catch_up of
	 * them; beyond that, skip as above. */
	PX_LOOP_OVERRUN_CATCH_UP = 1
};

/* Return value of a phase callback that asks the loop to stop after
 * this cycle (the cycle still completes all its phases). */
#define PX_LOOP_STOP 1

/* What a phase callback sees. Timestamps are on the loop clock (ns);
 * those of phases not started yet are 0. */
struct px_loop_cycle {
	uint64_t index;       /* 0 for the first cycle of the loop */
	int64_t period_ns;
	int64_t deadline_ns;  /* when this cycle was due */
	int64_t wake_ns;      /* when it woke (wake - deadline = latency) */
	int64_t read_ns;      /* start of the read phase */
	int64_t compute_ns;   /* start of the compute phase */
	int64_t compute_end_ns;
	int64_t write_ns;     /* start of the write phase */
	uint32_t missed;      /* periods skipped just before this cycle */
	int safe;             /* in safe state: outputs zeroed, enables off */
};

/*
 * A phase: return PX_OK (0), PX_LOOP_STOP, or a negative px_err code,
 * which records a PX_FAULT_CALLBACK fault and puts the loop in safe
 * state (for an error in write, from the next cycle on).
 * Runs inside the cycle: must keep the real-time rules.
 */
typedef int (*px_loop_phase_fn)(struct px_loop *loop,
				const struct px_loop_cycle *cycle,
				void *user);

struct px_loop_config {
	int64_t period_ns;            /* default 1 000 000 (1 kHz) */
	enum px_loop_clock clock;     /* default monotonic */
	int64_t vclock_start_ns;      /* virtual clock origin (default 0) */
	enum px_loop_overrun overrun; /* default skip */
	uint32_t max_catch_up;        /* catch-up bound (default 10) */
	/* Safe state after this many overruns in a row; 0 never. Default 3. */
	uint32_t overrun_limit;
	/* Compute budget; 0 means the period. Default 0. */
	int64_t compute_budget_ns;
	/* Safe state after this many over-budget computes in a row; 0
	 * never. Default 3. */
	uint32_t budget_limit;
	/* 0 (default): safe state lasts until px_loop_rearm(). N > 0: it
	 * also ends by itself after N consecutive cycles with no fault,
	 * unless an e-stop tripped it (see the top of this file). */
	uint32_t rearm_after_ok_cycles;
	size_t max_inputs;      /* watched inputs (default 16) */
	size_t max_outputs;     /* output blocks (default 16) */
	size_t max_enables;     /* enable flags (default 16) */
	size_t fault_capacity;  /* fault ring records (default 256) */
	size_t hist_bins;       /* histogram bins (default 5000) */
	int64_t hist_bin_ns;    /* histogram resolution (default 1000) */
	px_loop_phase_fn read, compute, write; /* each may be NULL */
	void *user;             /* passed to the phases */
	/* Real-time setup of the thread that runs px_loop_run(); applied
	 * when rt_enable is set (default 0), undone when the run ends. */
	int rt_enable;
	struct px_rt_config rt;
};

/* Fill cfg with the defaults above (rt with px_rt_config_default()). */
PX_API void px_loop_config_default(struct px_loop_config *cfg);

/*
 * Create a loop. cfg is copied. Setup only.
 * Returns PX_OK, PX_E_INVAL (NULL, period <= 0, negative budget or
 * resolution, capacity out of range) or PX_E_NOMEM. *out is NULL on
 * failure. Free with px_loop_free().
 */
PX_API int px_loop_create(const struct px_loop_config *cfg,
			  struct px_loop **out);

/* Free a loop. A loop started with px_loop_start() is stopped and joined
 * first; one running in px_loop_run() elsewhere must have returned.
 * NULL is a no-op. */
PX_API void px_loop_free(struct px_loop *loop);

/*
 * Watch an input: the read phase calls px_loop_input_stamp() with the
 * timestamp of each sample; a sample older than timeout_ns (> 0) when
 * the read phase ends trips safe state. name (may be NULL) is copied
 * (up to 31 bytes) for reports. Until the first stamp the input counts
 * from the loop's first wake-up. Setup only.
 * Returns the input's index (>= 0), PX_E_INVAL, PX_E_NOSPC (max_inputs
 * reached) or PX_E_STATE (loop running).
 */
PX_API int px_loop_input_add(struct px_loop *loop, const char *name,
			     int64_t timeout_ns);

/*
 * Report the newest sample of input idx, taken at t_ns on the loop
 * clock (px_loop_now_ns(); CLOCK_MONOTONIC for the real clock). Older
 * timestamps than the one held are ignored. Loop thread only.
 * Returns PX_OK or PX_E_INVAL (bad index). @note RT-safe.
 */
PX_API int px_loop_input_stamp(struct px_loop *loop, int idx, int64_t t_ns);

/*
 * Register n doubles of caller memory as an output block: checked for
 * NaN and infinity after every compute, zeroed in safe state before the
 * write phase. Setup only. Returns the index (>= 0), PX_E_INVAL,
 * PX_E_NOSPC or PX_E_STATE.
 */
PX_API int px_loop_output_add(struct px_loop *loop, const char *name,
			      double *values, size_t n);

/*
 * Register an enable flag (amplifier enable, brake release, motor
 * power): set to 0 in safe state before the write phase, left alone
 * otherwise. Setup only. Returns the index (>= 0), PX_E_INVAL,
 * PX_E_NOSPC or PX_E_STATE.
 */
PX_API int px_loop_enable_add(struct px_loop *loop, const char *name,
			      int *flag);

/*
 * Run cycles in the calling thread until px_loop_stop(), a phase
 * returning PX_LOOP_STOP, or max_cycles cycles (0: no limit). Applies
 * the real-time setup first when cfg.rt_enable (a refusal warns once and
 * the loop runs anyway, see the status) and undoes it at the end.
 * Returns PX_OK, PX_E_STATE (already running), PX_E_INVAL.
 */
PX_API int px_loop_run(struct px_loop *loop, uint64_t max_cycles);

/*
 * Run exactly one cycle in the calling thread: wait for its deadline
 * (virtual clock: jump to it), read, compute, write, bookkeeping.
 * For callers that drive the loop themselves (simulation, tests); no
 * real-time setup is applied. Returns PX_OK, PX_LOOP_STOP when a phase
 * asked to stop, PX_E_STATE while px_loop_run() owns the loop or a
 * phase-by-phase cycle is open.
 * @note RT-safe.
 */
PX_API int px_loop_step(struct px_loop *loop);

/*
 * One cycle phase by phase, for a caller that owns the thread and the
 * clock (its own 1 kHz loop): px_loop_read(), px_loop_compute(),
 * px_loop_write(), in that order, once each per cycle. Each runs its
 * phase callback and the checks px_loop_step() runs after that phase
 * (read: requests, the callback, stale inputs; compute: the callback, the
 * budget, non-finite outputs; write: safe state's zeros and disables, the
 * callback, overruns, automatic re-arm), so the outputs, faults and safe
 * state are those of px_loop_step() at the same times.
 *
 * now_ns is when the caller starts the phase, on the loop clock: for
 * the virtual clock it moves the simulated time forward to now_ns (never
 * back); for the real clock it is CLOCK_MONOTONIC time, e.g. the caller's
 * own wake-up. The loop does not sleep: the read opens the cycle at
 * now_ns, due at the loop's next deadline, or at now_ns when that
 * deadline has not come yet (the first cycle, a caller faster than the
 * period); a write that ends after the next deadline counts an overrun as
 * px_loop_step() does.
 *
 * Returns PX_OK, PX_LOOP_STOP once a phase of the cycle asked to stop
 * (finish the cycle all the same), PX_E_INVAL (NULL), or PX_E_STATE: the
 * call is out of order (e.g. write before compute; the open cycle is
 * unchanged) or px_loop_run() owns the loop. While a cycle is open,
 * px_loop_step(), px_loop_run() and px_loop_start() return PX_E_STATE.
 * Loop thread. @note RT-safe.
 */
PX_API int px_loop_read(struct px_loop *loop, int64_t now_ns);
PX_API int px_loop_compute(struct px_loop *loop, int64_t now_ns);
PX_API int px_loop_write(struct px_loop *loop, int64_t now_ns);

/*
 * Start px_loop_run(loop, max_cycles) on a new thread (setup only: the
 * thread is created here). px_loop_join() waits for it and returns
 * px_loop_run()'s result. Returns PX_OK, PX_E_STATE, PX_E_NOMEM.
 */
PX_API int px_loop_start(struct px_loop *loop, uint64_t max_cycles);
PX_API int px_loop_join(struct px_loop *loop);

/* Ask the running loop to return after the current cycle. Any thread;
 * async-signal-safe. @note RT-safe. */
PX_API void px_loop_stop(struct px_loop *loop);

/* Ask for safe state (PX_FAULT_TRIP), applied in the next cycle before
 * its write. Any thread; async-signal-safe. @note RT-safe. */
PX_API void px_loop_trip(struct px_loop *loop);

/* Emergency stop (PX_FAULT_ESTOP): safe state as px_loop_trip(), and
 * latched: automatic re-arm (rearm_after_ok_cycles) never ends it, only
 * px_loop_rearm() does (and an e-stop still held trips again in the
 * same cycle). Any thread; async-signal-safe. @note RT-safe. */
PX_API void px_loop_trip_estop(struct px_loop *loop);

/* Ask to leave safe state at the start of the next cycle (the watchdog
 * trips again in that cycle if a cause persists); the only way out of an
 * e-stop's safe state. Any thread. @note RT-safe. */
PX_API void px_loop_rearm(struct px_loop *loop);

/* Loop clock now (virtual time for the virtual clock). Any thread.
 * @note RT-safe. */
PX_API int64_t px_loop_now_ns(const struct px_loop *loop);

/* Virtual clock only: simulate ns (>= 0) of time passing, e.g. inside
 * a phase to model a slow compute. Loop thread. Returns PX_OK,
 * PX_E_INVAL, or PX_E_STATE on the real clock. @note RT-safe. */
PX_API int px_loop_vclock_advance(struct px_loop *loop, int64_t ns);

/* Is the loop in safe state now. Any thread. @note RT-safe. */
PX_API int px_loop_is_safe(const struct px_loop *loop);

struct px_loop_status {
	int running;            /* inside px_loop_run() */
	int safe;               /* in safe state */
	int32_t safe_cause;     /* enum px_fault_cause that tripped it */
	int32_t safe_source;    /* input/output/phase index, or -1 */
	uint64_t safe_cycle;    /* cycle that tripped it */
	uint64_t cycles;        /* cycles run */
	uint64_t overruns;      /* cycles that ended after the next deadline */
	uint64_t missed_periods;/* periods skipped (skip policy) */
	uint64_t budget_exceeded; /* computes over budget */
	uint64_t safe_entries;  /* times safe state was entered */
	uint64_t faults;        /* faults recorded */
	uint64_t faults_dropped;/* faults lost because the ring was full */
	int64_t period_ns;
	/* Real-time setup as in force during the last (or current)
	 * px_loop_run(); all zero before the first. */
	int rt_applied;         /* cfg.rt_enable was set */
	int realtime;           /* SCHED_FIFO actually in force */
	struct px_rt_report rt;
};

/*
 * Copy the status. Any thread; each field is exact, though fields may
 * come from neighbouring cycles. Returns PX_OK or PX_E_INVAL.
 */
PX_API int px_loop_status(const struct px_loop *loop,
			  struct px_loop_status *st);

enum px_loop_stat {
	PX_LOOP_STAT_LATENCY = 0, /* wake - deadline */
	PX_LOOP_STAT_COMPUTE = 1, /* compute phase duration */
	PX_LOOP_STAT_CYCLE = 2,   /* wake to end of write */
	PX_LOOP_STAT__COUNT = 3
};

/* Snapshot of one statistic; any thread (see px_stats_read()).
 * Returns PX_OK, PX_E_INVAL, PX_E_AGAIN. */
PX_API int px_loop_stats(const struct px_loop *loop, enum px_loop_stat which,
			 struct px_stats_snapshot *out);

/* The statistic itself, for px_stats_copy_bins(). NULL on bad input. */
PX_API struct px_stats *px_loop_stats_handle(struct px_loop *loop,
					     enum px_loop_stat which);

/* Clear all statistics (applied by the loop at its next record while it
 * runs, at once otherwise) and the overrun and budget counters. Any
 * thread. */
PX_API void px_loop_stats_reset(struct px_loop *loop);

/*
 * Take the oldest fault out of the fault ring. One reader thread.
 * Returns PX_OK or PX_E_AGAIN when empty.
 */
PX_API int px_loop_fault_pop(struct px_loop *loop, struct px_fault *out);

/* Name given to input / output / enable idx ("" if none or bad idx). */
PX_API const char *px_loop_input_name(const struct px_loop *loop, int idx);
PX_API const char *px_loop_output_name(const struct px_loop *loop, int idx);

#ifdef __cplusplus
}
#endif

#endif
