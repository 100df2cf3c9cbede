/* Real-time thread setup: the refusal path (simulated, so it is tested
 * on every machine), the real path (whatever this machine grants, the
 * report must match what is in force), and the loop running either way. */
#include <fcntl.h>
#include <pthread.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "px_loop.h"
#include "px_rt.h"
#include "px_test.h"

#if defined(__SANITIZE_ADDRESS__)
/* mlockall would try to lock the sanitizer's terabytes of shadow. */
#define CAN_MLOCK 0
#else
#define CAN_MLOCK 1
#endif

struct warn_log {
	int calls;
	char last[2048];
};

static void on_warn(void *ctx, const char *msg)
{
	struct warn_log *w = ctx;
	w->calls++;
	snprintf(w->last, sizeof(w->last), "%s", msg);
}

static int count_of(const char *s, const char *needle)
{
	int n = 0;
	while ((s = strstr(s, needle)) != NULL) {
		n++;
		s += strlen(needle);
	}
	return n;
}

static int thread_policy(int *prio)
{
	struct sched_param sp;
	int pol = -1;
	pthread_getschedparam(pthread_self(), &pol, &sp);
	if (prio)
		*prio = sp.sched_priority;
	return pol;
}

static long vm_locked_kb(void)
{
	FILE *f = fopen("/proc/self/status", "r");
	char line[256];
	long kb = -1;
	if (!f)
		return -1;
	while (fgets(line, sizeof(line), f))
		if (sscanf(line, "VmLck: %ld", &kb) == 1)
			break;
	fclose(f);
	return kb;
}

static void test_simulated_refusal_all_steps(void)
{
	struct px_rt_config c;
	struct px_rt_report r;
	struct warn_log w;
	const unsigned all = PX_RT_SCHED | PX_RT_MEMLOCK | PX_RT_AFFINITY |
			     PX_RT_DMA_LATENCY;
	int pol0 = thread_policy(NULL);

	memset(&w, 0, sizeof(w));
	px_rt_config_default(&c);
	c.priority = 70;
	c.cpu = 0;
	c.dma_latency = 1;
	c.simulate_refusal = all;
	c.warn = on_warn;
	c.warn_ctx = &w;
	PX_CHECK_INT_EQ(px_rt_apply(&c, &r), PX_E_PERM);
	PX_CHECK_INT_EQ(r.requested, all | PX_RT_PREFAULT);
	PX_CHECK_INT_EQ(r.refused, all);
	PX_CHECK_INT_EQ(r.granted, PX_RT_PREFAULT);
	PX_CHECK_INT_EQ(r.policy, pol0);
	PX_CHECK_INT_EQ(thread_policy(NULL), pol0);
	PX_CHECK_INT_EQ(r.memlocked, 0);
	PX_CHECK_INT_EQ(r.cpu, -1);
	PX_CHECK_INT_EQ(r.dma_latency_fd, -1);
	/* One warning, one line per refusal, each saying how to grant it. */
	PX_CHECK_INT_EQ(w.calls, 1);
	PX_CHECK(strcmp(w.last, r.warning) == 0);
	PX_CHECK_INT_EQ(count_of(w.last, "\n  - "), 4);
	PX_CHECK(strstr(w.last, "SCHED_FIFO priority 70 refused"));
	PX_CHECK(strstr(w.last, "CAP_SYS_NICE"));
	PX_CHECK(strstr(w.last, "rtprio"));
	PX_CHECK(strstr(w.last, "running anyway on SCHED_OTHER"));
	PX_CHECK(strstr(w.last, "mlockall refused"));
	PX_CHECK(strstr(w.last, "memlock"));
	PX_CHECK(strstr(w.last, "CAP_IPC_LOCK"));
	PX_CHECK(strstr(w.last, "CPU 0"));
	PX_CHECK(strstr(w.last, "/dev/cpu_dma_latency"));
	PX_CHECK(strstr(w.last, "Operation not permitted"));
	px_rt_restore(&r);
	PX_CHECK_INT_EQ(thread_policy(NULL), pol0);
}

static void test_nothing_requested(void)
{
	struct px_rt_config c;
	struct px_rt_report r;
	struct warn_log w;

	memset(&w, 0, sizeof(w));
	memset(&c, 0, sizeof(c));
	c.cpu = -1;
	c.warn = on_warn;
	c.warn_ctx = &w;
	PX_CHECK_INT_EQ(px_rt_apply(&c, &r), PX_OK);
	PX_CHECK_INT_EQ(r.requested, 0);
	PX_CHECK_INT_EQ(r.refused, 0);
	PX_CHECK_INT_EQ(w.calls, 0);
	PX_CHECK_INT_EQ(r.warning[0], 0);
	c.priority = 100;
	PX_CHECK_INT_EQ(px_rt_apply(&c, &r), PX_E_INVAL);
	c.priority = -1;
	PX_CHECK_INT_EQ(px_rt_apply(&c, &r), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_rt_apply(&c, NULL), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_rt_apply(NULL, &r), PX_E_INVAL);
	px_rt_restore(NULL);
	PX_CHECK(strcmp(px_rt_policy_name(SCHED_FIFO), "SCHED_FIFO") == 0);
	PX_CHECK(strcmp(px_rt_policy_name(SCHED_OTHER), "SCHED_OTHER") == 0);
	PX_CHECK(strcmp(px_rt_policy_name(12345), "unknown") == 0);
}

/* Whatever this machine grants: the report must describe what is in
 * force, and restore must put scheduling and affinity back. */
static void test_real_path_consistent(void)
{
	struct px_rt_config c;
	struct px_rt_report r;
	struct warn_log w;
	cpu_set_t before, now;
	int pol0, prio0, prio, rc, cpu = sched_getcpu();

	memset(&w, 0, sizeof(w));
	pol0 = thread_policy(&prio0);
	PX_CHECK_INT_EQ(sched_getaffinity(0, sizeof(before), &before), 0);
	px_rt_config_default(&c);
	c.priority = 10;
	c.lock_memory = CAN_MLOCK;
	c.cpu = cpu < 0 ? 0 : cpu;
	c.dma_latency = 1;
	c.prefault_heap_bytes = 1 << 20;
	c.warn = on_warn;
	c.warn_ctx = &w;
	rc = px_rt_apply(&c, &r);
	printf("    real path: granted 0x%x refused 0x%x policy %s%s%s\n",
	       r.granted, r.refused, px_rt_policy_name(r.policy),
	       r.refused ? ": " : "", r.warning);
	PX_CHECK_INT_EQ(r.granted & r.refused, 0);
	PX_CHECK_INT_EQ((r.granted | r.refused) & ~PX_RT_PREFAULT,
			r.requested & ~PX_RT_PREFAULT);
	PX_CHECK_INT_EQ(rc, r.refused ? PX_E_PERM : PX_OK);
	PX_CHECK_INT_EQ(w.calls, r.refused ? 1 : 0);
	PX_CHECK_INT_EQ(r.warning[0] != 0, r.refused != 0);
	if (r.granted & PX_RT_SCHED) {
		PX_CHECK_INT_EQ(thread_policy(&prio), SCHED_FIFO);
		PX_CHECK_INT_EQ(prio, 10);
		PX_CHECK_INT_EQ(r.policy, SCHED_FIFO);
	} else {
		PX_CHECK_INT_EQ(thread_policy(NULL), pol0);
		PX_CHECK_INT_EQ(r.policy, pol0);
		PX_CHECK(strstr(r.warning, "SCHED_FIFO priority 10 refused"));
	}
	if (r.granted & PX_RT_MEMLOCK) {
		PX_CHECK_INT_EQ(r.memlocked, 1);
		PX_CHECK(vm_locked_kb() > 0);
	} else if (c.lock_memory) {
		PX_CHECK(strstr(r.warning, "mlockall refused"));
	}
	if (r.granted & PX_RT_AFFINITY) {
		PX_CHECK_INT_EQ(sched_getaffinity(0, sizeof(now), &now), 0);
		PX_CHECK_INT_EQ(CPU_COUNT(&now), 1);
		PX_CHECK(CPU_ISSET(c.cpu, &now));
	}
	if (r.granted & PX_RT_DMA_LATENCY)
		PX_CHECK(fcntl(r.dma_latency_fd, F_GETFD) >= 0);
	else
		PX_CHECK(strstr(r.warning, "/dev/cpu_dma_latency"));
	px_rt_restore(&r);
	PX_CHECK_INT_EQ(thread_policy(&prio), pol0);
	PX_CHECK_INT_EQ(prio, prio0);
	PX_CHECK_INT_EQ(sched_getaffinity(0, sizeof(now), &now), 0);
	PX_CHECK(CPU_EQUAL(&now, &before));
	PX_CHECK_INT_EQ(r.dma_latency_fd, -1);
}

/* The loop with real-time setup: refused (simulated) or real, it runs
 * its cycles, warns at most once, and its status says which. */
struct seen {
	int policy, prio, cycles;
};

static int note_policy(struct px_loop *l, const struct px_loop_cycle *c,
		       void *u)
{
	struct seen *s = u;
	(void)l;
	(void)c;
	s->policy = thread_policy(&s->prio);
	s->cycles++;
	return PX_OK;
}

static void run_loop_with_rt(unsigned simulate)
{
	struct px_loop_config cfg;
	struct px_loop *l;
	struct px_loop_status st;
	struct warn_log w;
	struct seen s;
	int pol0 = thread_policy(NULL);

	memset(&w, 0, sizeof(w));
	memset(&s, 0, sizeof(s));
	px_loop_config_default(&cfg);
	cfg.period_ns = 250000;
	cfg.overrun_limit = 0;
	cfg.budget_limit = 0;
	cfg.compute = note_policy;
	cfg.user = &s;
	cfg.rt_enable = 1;
	cfg.rt.priority = 20;
	cfg.rt.lock_memory = CAN_MLOCK || (simulate & PX_RT_MEMLOCK);
	cfg.rt.simulate_refusal = simulate;
	cfg.rt.warn = on_warn;
	cfg.rt.warn_ctx = &w;
	PX_CHECK_INT_EQ(px_loop_create(&cfg, &l), PX_OK);
	PX_CHECK_INT_EQ(px_loop_start(l, 40), PX_OK);
	PX_CHECK_INT_EQ(px_loop_join(l), PX_OK);
	PX_CHECK_INT_EQ(px_loop_status(l, &st), PX_OK);
	PX_CHECK_INT_EQ(s.cycles, 40);
	PX_CHECK_INT_EQ(st.cycles, 40);
	PX_CHECK_INT_EQ(st.rt_applied, 1);
	PX_CHECK_INT_EQ(st.rt.refused & simulate, simulate);
	PX_CHECK_INT_EQ(w.calls, st.rt.refused ? 1 : 0);
	/* What the phases ran under is what the status reported. */
	PX_CHECK_INT_EQ(st.realtime, s.policy == SCHED_FIFO);
	if (st.realtime)
		PX_CHECK_INT_EQ(s.prio, 20);
	else
		PX_CHECK(strstr(st.rt.warning, "SCHED_FIFO priority 20 refused"));
	if (simulate & PX_RT_SCHED) {
		PX_CHECK_INT_EQ(st.realtime, 0);
		PX_CHECK_INT_EQ(s.policy, pol0);
		PX_CHECK(strstr(w.last, "CAP_SYS_NICE"));
	}
	px_loop_free(l);
}

static void test_loop_runs_when_refused(void)
{
	run_loop_with_rt(PX_RT_SCHED | PX_RT_MEMLOCK);
}

static void test_loop_real_rt_either_outcome(void)
{
	run_loop_with_rt(0);
}

static const struct px_test tests[] = {
	PX_T(test_simulated_refusal_all_steps),
	PX_T(test_nothing_requested),
	PX_T(test_real_path_consistent),
	PX_T(test_loop_runs_when_refused),
	PX_T(test_loop_real_rt_either_outcome),
};

PX_TEST_MAIN(tests)
