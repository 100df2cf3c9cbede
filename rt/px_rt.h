/*
 * px_rt.h - real-time setup of the thread that runs a control loop.
 *
 * px_rt_apply() does, for the calling thread, what a Linux control loop
 * needs before its first cycle: SCHED_FIFO at a chosen priority,
 * mlockall(MCL_CURRENT | MCL_FUTURE), prefaulting of stack and heap so
 * that no cycle takes a page fault, CPU affinity, and optionally holding
 * /dev/cpu_dma_latency at 0 to keep the CPU out of deep idle states.
 *
 * When a step is refused (no CAP_SYS_NICE or rtprio limit, memlock limit
 * too low, CPU not allowed, no access to /dev/cpu_dma_latency), the
 * thread goes on without it: px_rt_apply() gathers every refusal into
 * ONE warning that names what was refused and how to grant it, passes
 * it to the warn callback (stderr by default) and returns PX_E_PERM. The
 * report says exactly what is in force, so a loop can show it in its
 * status; a refused SCHED_FIFO leaves the thread on SCHED_OTHER.
 *
 * Memory and real-time rules: setup only (these calls are system calls,
 * may allocate and may sleep); never call them from a running cycle.
 * Memory stays locked after px_rt_restore() (mlockall is process-wide
 * and other threads may rely on it).
 */
#ifndef PX_RT_H
#define PX_RT_H

#include <stddef.h>

#include "px_base.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Steps of the setup, as bits in the report and in simulate_refusal. */
enum px_rt_step {
	PX_RT_SCHED = 1u << 0,       /* SCHED_FIFO at the priority */
	PX_RT_MEMLOCK = 1u << 1,     /* mlockall */
	PX_RT_AFFINITY = 1u << 2,    /* pin to one CPU */
	PX_RT_DMA_LATENCY = 1u << 3, /* hold /dev/cpu_dma_latency at 0 */
	PX_RT_PREFAULT = 1u << 4     /* stack and heap prefault */
};

struct px_rt_config {
	/* SCHED_FIFO priority 1..99; 0 leaves the scheduler alone. */
	int priority;
	/* mlockall(MCL_CURRENT | MCL_FUTURE). */
	int lock_memory;
	/* CPU to pin the thread to; -1 for none. */
	int cpu;
	/* Hold /dev/cpu_dma_latency at 0 while the setup is in force. */
	int dma_latency;
	/* Bytes of stack to touch now (capped at 4 MiB) and bytes of heap
	 * to touch and keep in the process (0 for none). Heap prefault
	 * turns off malloc trimming and mmap for the process (mallopt), so
	 * freed memory stays mapped and locked. */
	size_t prefault_stack_bytes;
	size_t prefault_heap_bytes;
	/* Steps (enum px_rt_step bits) to treat as refused with EPERM
	 * without trying them: exercises the degraded path in tests and
	 * dry runs on machines where everything would be granted. */
	unsigned simulate_refusal;
	/* Receives the single warning; NULL prints it to stderr. */
	void (*warn)(void *ctx, const char *msg);
	void *warn_ctx;
};

/*
 * What is in force after px_rt_apply(). Plain data, may be copied; pass
 * exactly one of the copies to px_rt_restore().
 */
struct px_rt_report {
	unsigned requested; /* steps asked for */
	unsigned granted;   /* steps in force */
	unsigned refused;   /* steps asked for and refused */
	int policy;         /* SCHED_FIFO or SCHED_OTHER (sched.h values) */
	int priority;       /* priority in force (0 on SCHED_OTHER) */
	int cpu;            /* pinned CPU or -1 */
	int memlocked;      /* memory locked */
	int dma_latency_fd; /* held file descriptor or -1 */
	int sched_errno, memlock_errno, affinity_errno, dma_errno;
	char warning[1024];  /* the warning text, "" when nothing refused */
	/* private: what px_rt_restore() puts back */
	int old_policy_, old_priority_, have_old_affinity_;
	unsigned char old_affinity_[128];
};

/* Defaults: priority 80, lock memory, no pinning, no dma latency,
 * 1 MiB of stack and no heap prefault, stderr warnings. */
PX_API void px_rt_config_default(struct px_rt_config *cfg);

/*
 * Apply cfg to the calling thread; fill rep (always, even on refusal).
 * Returns PX_OK when every requested step is in force, PX_E_PERM when
 * some were refused (the thread is still usable, degraded as rep says;
 * the warning has been issued once), PX_E_INVAL for NULL arguments or a
 * priority outside 0..99.
 */
PX_API int px_rt_apply(const struct px_rt_config *cfg,
		       struct px_rt_report *rep);

/* Put the calling thread's scheduling and affinity back as they were
 * before px_rt_apply(rep) and release /dev/cpu_dma_latency. Memory stays
 * locked. Safe on a report whose apply failed or was all refused. */
PX_API void px_rt_restore(struct px_rt_report *rep);

/* "SCHED_FIFO", "SCHED_OTHER", ... for a policy value. */
PX_API const char *px_rt_policy_name(int policy);

#ifdef __cplusplus
}
#endif

#endif
