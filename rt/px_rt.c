#include "px_rt.h"

#include <alloca.h>
#include <errno.h>
#include <fcntl.h>
#include <malloc.h>
#include <pthread.h>
#include <sched.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

_Static_assert(sizeof(cpu_set_t) <= sizeof(((struct px_rt_report *)0)->old_affinity_),
	       "affinity backup too small");

#define MAX_STACK_PREFAULT ((size_t)4 << 20)

void px_rt_config_default(struct px_rt_config *cfg)
{
	if (!cfg)
		return;
	memset(cfg, 0, sizeof(*cfg));
	cfg->priority = 80;
	cfg->lock_memory = 1;
	cfg->cpu = -1;
	cfg->dma_latency = 0;
	/* A surface query alone takes about 360 KiB of stack (see
	 * px_spiece.h), with the loop's frames above it. */
	cfg->prefault_stack_bytes = 1u << 20;
	cfg->prefault_heap_bytes = 0;
}

const char *px_rt_policy_name(int policy)
{
	switch (policy) {
	case SCHED_OTHER: return "SCHED_OTHER";
	case SCHED_FIFO: return "SCHED_FIFO";
	case SCHED_RR: return "SCHED_RR";
#ifdef SCHED_BATCH
	case SCHED_BATCH: return "SCHED_BATCH";
#endif
#ifdef SCHED_IDLE
	case SCHED_IDLE: return "SCHED_IDLE";
#endif
	default: return "unknown";
	}
}

static const char *errtext(int e, char *buf, size_t n)
{
	/* GNU strerror_r: returns a pointer, buf may be unused. */
	return strerror_r(e, buf, n);
}

/* Appends to the warning, never overflowing it. */
static void add(struct px_rt_report *r, const char *fmt, ...)
	__attribute__((format(printf, 2, 3)));
static void add(struct px_rt_report *r, const char *fmt, ...)
{
	size_t used = strlen(r->warning);
	va_list ap;

	if (used + 1 >= sizeof(r->warning))
		return;
	va_start(ap, fmt);
	vsnprintf(r->warning + used, sizeof(r->warning) - used, fmt, ap);
	va_end(ap);
}

/* Touch every page of a stack region now, so cycles never fault one in. */
static __attribute__((noinline)) void prefault_stack(size_t n)
{
	volatile unsigned char *p;
	size_t i;

	if (n > MAX_STACK_PREFAULT)
		n = MAX_STACK_PREFAULT;
	if (n == 0)
		return;
	p = alloca(n);
	for (i = 0; i < n; i += 4096)
		p[i] = 0;
	p[n - 1] = 0;
}

static void prefault_heap(size_t n)
{
	volatile unsigned char *p;
	size_t i;

	if (n == 0)
		return;
	/* Freed memory must stay in the process (and locked), else the
	 * next allocation faults again: no trimming, no mmap chunks. */
	mallopt(M_TRIM_THRESHOLD, -1);
	mallopt(M_MMAP_MAX, 0);
	p = malloc(n);
	if (!p)
		return;
	for (i = 0; i < n; i += 4096)
		p[i] = 0;
	free((void *)p);
}

static int step_sched(const struct px_rt_config *c)
{
	struct sched_param sp;

	if (c->simulate_refusal & PX_RT_SCHED)
		return EPERM;
	memset(&sp, 0, sizeof(sp));
	sp.sched_priority = c->priority;
	return pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp);
}

static int step_memlock(const struct px_rt_config *c)
{
	if (c->simulate_refusal & PX_RT_MEMLOCK)
		return EPERM;
	return mlockall(MCL_CURRENT | MCL_FUTURE) == 0 ? 0 : errno;
}

static int step_affinity(const struct px_rt_config *c)
{
	cpu_set_t set;

	if (c->simulate_refusal & PX_RT_AFFINITY)
		return EPERM;
	if (c->cpu >= CPU_SETSIZE)
		return EINVAL;
	CPU_ZERO(&set);
	CPU_SET(c->cpu, &set);
	return pthread_setaffinity_np(pthread_self(), sizeof(set), &set);
}

static int step_dma(const struct px_rt_config *c, int *fd_out)
{
	int32_t zero = 0;
	int fd, e;

	*fd_out = -1;
	if (c->simulate_refusal & PX_RT_DMA_LATENCY)
		return EPERM;
	fd = open("/dev/cpu_dma_latency", O_WRONLY | O_CLOEXEC);
	if (fd < 0)
		return errno;
	/* The request holds only while the file stays open. */
	if (write(fd, &zero, sizeof(zero)) != (ssize_t)sizeof(zero)) {
		e = errno ? errno : EIO;
		close(fd);
		return e;
	}
	*fd_out = fd;
	return 0;
}

int px_rt_apply(const struct px_rt_config *c, struct px_rt_report *r)
{
	struct sched_param sp;
	char eb[128];
	int pol, e;

	if (!r)
		return PX_E_INVAL;
	memset(r, 0, sizeof(*r));
	r->cpu = -1;
	r->dma_latency_fd = -1;
	r->old_policy_ = -1;
	if (pthread_getschedparam(pthread_self(), &pol, &sp) == 0) {
		r->old_policy_ = pol;
		r->old_priority_ = sp.sched_priority;
		r->policy = pol;
		r->priority = sp.sched_priority;
	}
	if (!c || c->priority < 0 || c->priority > 99)
		return PX_E_INVAL;
	{
		cpu_set_t old;
		if (pthread_getaffinity_np(pthread_self(), sizeof(old), &old) == 0) {
			memcpy(r->old_affinity_, &old, sizeof(old));
			r->have_old_affinity_ = 1;
		}
	}

	if (c->priority > 0) {
		r->requested |= PX_RT_SCHED;
		e = step_sched(c);
		if (e == 0) {
			r->granted |= PX_RT_SCHED;
			r->policy = SCHED_FIFO;
			r->priority = c->priority;
		} else {
			r->refused |= PX_RT_SCHED;
			r->sched_errno = e;
			add(r, "\n  - SCHED_FIFO priority %d refused (%s): the "
			       "loop runs on %s with no real-time guarantee. "
			       "Grant it: give the program CAP_SYS_NICE "
			       "(run as root, or setcap cap_sys_nice+ep "
			       "PROGRAM), or raise the rtprio limit "
			       "(ulimit -r %d; '@group - rtprio %d' in "
			       "/etc/security/limits.conf); in a container "
			       "add --cap-add=SYS_NICE --ulimit rtprio=%d and "
			       "real-time CPU time for its cgroup.",
			    c->priority, errtext(e, eb, sizeof(eb)),
			    px_rt_policy_name(r->policy), c->priority,
			    c->priority, c->priority);
		}
	}
	if (c->lock_memory) {
		r->requested |= PX_RT_MEMLOCK;
		e = step_memlock(c);
		if (e == 0) {
			r->granted |= PX_RT_MEMLOCK;
			r->memlocked = 1;
		} else {
			r->refused |= PX_RT_MEMLOCK;
			r->memlock_errno = e;
			add(r, "\n  - mlockall refused (%s): memory may be "
			       "paged out and a cycle may stall on a page "
			       "fault. Grant it: raise the memlock limit "
			       "(ulimit -l unlimited; '@group - memlock "
			       "unlimited' in /etc/security/limits.conf) or "
			       "give the program CAP_IPC_LOCK; in a container "
			       "--ulimit memlock=-1.",
			    errtext(e, eb, sizeof(eb)));
		}
	}
	if (c->cpu >= 0) {
		r->requested |= PX_RT_AFFINITY;
		e = step_affinity(c);
		if (e == 0) {
			r->granted |= PX_RT_AFFINITY;
			r->cpu = c->cpu;
		} else {
			r->refused |= PX_RT_AFFINITY;
			r->affinity_errno = e;
			add(r, "\n  - pinning to CPU %d refused (%s): the CPU "
			       "must exist and be in the process's allowed "
			       "set (see taskset -p, the cgroup cpuset, "
			       "docker --cpuset-cpus).",
			    c->cpu, errtext(e, eb, sizeof(eb)));
		}
	}
	if (c->dma_latency) {
		r->requested |= PX_RT_DMA_LATENCY;
		e = step_dma(c, &r->dma_latency_fd);
		if (e == 0) {
			r->granted |= PX_RT_DMA_LATENCY;
		} else {
			r->refused |= PX_RT_DMA_LATENCY;
			r->dma_errno = e;
			add(r, "\n  - /dev/cpu_dma_latency not held at 0 (%s): "
			       "deep CPU idle states may add wake-up "
			       "latency. Grant it: write access to "
			       "/dev/cpu_dma_latency (root, or a udev rule; "
			       "in a container --device=/dev/cpu_dma_latency).",
			    errtext(e, eb, sizeof(eb)));
		}
	}
	/* Prefault last: with memory locked the touched pages stay. It
	 * cannot be refused. */
	if (c->prefault_stack_bytes || c->prefault_heap_bytes) {
		r->requested |= PX_RT_PREFAULT;
		prefault_stack(c->prefault_stack_bytes);
		prefault_heap(c->prefault_heap_bytes);
		r->granted |= PX_RT_PREFAULT;
	}

	if (!r->refused)
		return PX_OK;
	{
		/* One message: a header, then one line per refusal. */
		char msg[sizeof(r->warning) + 160];
		snprintf(msg, sizeof(msg),
			 "proxima: real-time setup incomplete, running "
			 "anyway on %s%s",
			 px_rt_policy_name(r->policy), r->warning);
		memcpy(r->warning, msg, sizeof(r->warning) - 1);
		r->warning[sizeof(r->warning) - 1] = '\0';
	}
	if (c->warn)
		c->warn(c->warn_ctx, r->warning);
	else
		fprintf(stderr, "%s\n", r->warning);
	return PX_E_PERM;
}

void px_rt_restore(struct px_rt_report *r)
{
	if (!r)
		return;
	if (r->dma_latency_fd >= 0) {
		close(r->dma_latency_fd);
		r->dma_latency_fd = -1;
	}
	if ((r->granted & PX_RT_SCHED) && r->old_policy_ >= 0) {
		struct sched_param sp;
		memset(&sp, 0, sizeof(sp));
		sp.sched_priority = r->old_priority_;
		pthread_setschedparam(pthread_self(), r->old_policy_, &sp);
	}
	if ((r->granted & PX_RT_AFFINITY) && r->have_old_affinity_) {
		cpu_set_t old;
		memcpy(&old, r->old_affinity_, sizeof(old));
		pthread_setaffinity_np(pthread_self(), sizeof(old), &old);
	}
	r->granted &= ~(unsigned)(PX_RT_SCHED | PX_RT_AFFINITY |
				  PX_RT_DMA_LATENCY);
	r->policy = r->old_policy_;
	r->priority = r->old_priority_;
	r->cpu = -1;
}
