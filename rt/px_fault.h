/*
 * px_fault.h - fault records of the real-time loop.
 *
 * Everything the loop's watchdog sees (stale device data, compute over
 * budget, NaN or infinity in an output, overruns, a phase callback
 * failing, a trip requested from outside) becomes one fixed-size
 * struct px_fault pushed into a lock-free ring (px_ring) from inside the
 * cycle and read outside it with px_loop_fault_pop(). When the ring is
 * full, newer faults are dropped and counted; the cause that put the
 * loop in safe state is also kept in its status, so it is never lost.
 *
 * Memory and real-time rules: plain data; px_fault_cause_name() returns
 * static strings and is RT-safe.
 */
#ifndef PX_FAULT_H
#define PX_FAULT_H

#include <stdint.h>

#include "px_base.h"

#ifdef __cplusplus
extern "C" {
#endif

enum px_fault_cause {
	PX_FAULT_NONE = 0,
	PX_FAULT_INPUT_STALE = 1,      /* watched input older than its timeout */
	PX_FAULT_COMPUTE_BUDGET = 2,   /* compute over budget K times in a row */
	PX_FAULT_OUTPUT_NONFINITE = 3, /* NaN or infinity in an output */
	PX_FAULT_OVERRUN = 4,          /* cycle ended after the next deadline */
	PX_FAULT_CALLBACK = 5,         /* a phase callback returned an error */
	PX_FAULT_TRIP = 6,             /* px_loop_trip() from the application */
	PX_FAULT_ESTOP = 7,            /* px_loop_trip_estop(): an emergency stop */
	PX_FAULT__COUNT = 8
};

struct px_fault {
	uint64_t cycle;   /* index of the cycle that saw it */
	int64_t t_ns;     /* loop clock when seen */
	int32_t cause;    /* enum px_fault_cause */
	/* Which one: input index, output index, phase (0 read, 1 compute,
	 * 2 write), or -1. */
	int32_t source;
	/* Cause-specific: input age (ns), compute time (ns), element index
	 * of the bad value, periods missed, callback error code, or 0. */
	int64_t detail;
	int32_t safe;     /* this fault put (or kept) the loop in safe state */
	int32_t reserved_;
};

/* "input_stale", "compute_budget", ...; "unknown" for other values.
 * @note RT-safe. */
PX_API const char *px_fault_cause_name(int cause);

#ifdef __cplusplus
}
#endif

#endif
