/* The real-time loop: phases, overruns, watchdog and safe state, status,
 * allocation-free cycles, the same cycle driven phase by phase.
 * Virtual-clock tests check exact behaviour; real-clock tests check
 * behaviour only, never timing. */
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <string.h>
#include <time.h>

#include "px_alloc_count.h"
#include "px_loop.h"
#include "px_param.h"
#include "px_ring.h"
#include "px_test.h"

#define P_NS 1000000
#define MAXC 400

/* A scripted device: what each cycle's phases do, and a log of what the
 * write phase saw. */
struct fx {
	struct px_loop *l;
	double out[4];
	int enable;
	int in_idx;
	/* script, indexed by cycle */
	int64_t read_adv[MAXC], compute_adv[MAXC];
	int stamp_until;       /* stamp the input in cycles < this */
	int nan_at, inf_at;    /* cycle writing a bad output, -1 none */
	int read_err_at;       /* cycle whose read fails, -1 none */
	int stop_at;           /* cycle whose write returns PX_LOOP_STOP */
	/* log */
	int n;
	char order[MAXC * 3 + 1];
	int order_n;
	struct px_loop_cycle cy[MAXC];
	int w_safe[MAXC], w_enable[MAXC];
	double w_out[MAXC];
};

static int ph_read(struct px_loop *l, const struct px_loop_cycle *c, void *u)
{
	struct fx *f = u;
	uint64_t k = c->index;
	f->order[f->order_n++] = 'r';
	if (k < MAXC && f->read_adv[k])
		px_loop_vclock_advance(l, f->read_adv[k]);
	if (f->in_idx >= 0 && (int64_t)k < f->stamp_until)
		px_loop_input_stamp(l, f->in_idx, px_loop_now_ns(l));
	if ((int64_t)k == f->read_err_at)
		return PX_E_NODEV;
	return PX_OK;
}

static int ph_compute(struct px_loop *l, const struct px_loop_cycle *c,
		      void *u)
{
	struct fx *f = u;
	uint64_t k = c->index;
	int i;
	f->order[f->order_n++] = 'c';
	if (k < MAXC && f->compute_adv[k])
		px_loop_vclock_advance(l, f->compute_adv[k]);
	/* The controller always commands something and enables power. */
	for (i = 0; i < 4; i++)
		f->out[i] = 1.0 + i;
	f->enable = 1;
	if ((int64_t)k == f->nan_at)
		f->out[2] = NAN;
	if ((int64_t)k == f->inf_at)
		f->out[3] = -INFINITY;
	return PX_OK;
}

static int ph_write(struct px_loop *l, const struct px_loop_cycle *c, void *u)
{
	struct fx *f = u;
	uint64_t k = c->index;
	(void)l;
	f->order[f->order_n++] = 'w';
	if (k < MAXC) {
		f->cy[k] = *c;
		f->w_safe[k] = c->safe;
		f->w_enable[k] = f->enable;
		f->w_out[k] = fabs(f->out[0]) + fabs(f->out[1]) +
			      fabs(f->out[2]) + fabs(f->out[3]);
		f->n = (int)k + 1;
	}
	if ((int64_t)k == f->stop_at)
		return PX_LOOP_STOP;
	return PX_OK;
}

static void fx_init(struct fx *f, struct px_loop_config *cfg)
{
	memset(f, 0, sizeof(*f));
	f->in_idx = -1;
	f->stamp_until = 1 << 30;
	f->nan_at = f->inf_at = f->read_err_at = f->stop_at = -1;
	px_loop_config_default(cfg);
	cfg->clock = PX_LOOP_CLOCK_VIRTUAL;
	cfg->period_ns = P_NS;
	cfg->read = ph_read;
	cfg->compute = ph_compute;
	cfg->write = ph_write;
	cfg->user = f;
}

static void fx_create(struct fx *f, const struct px_loop_config *cfg)
{
	PX_CHECK_INT_EQ(px_loop_create(cfg, &f->l), PX_OK);
	PX_CHECK(px_loop_output_add(f->l, "force", f->out, 4) == 0);
	PX_CHECK(px_loop_enable_add(f->l, "amp", &f->enable) == 0);
}

static void test_phase_order_virtual(void)
{
	struct px_loop_config cfg;
	struct fx f;
	int k;

	fx_init(&f, &cfg);
	cfg.vclock_start_ns = 5000;
	fx_create(&f, &cfg);
	for (k = 0; k < 20; k++) {
		f.read_adv[k] = 10000 + k;
		f.compute_adv[k] = 20000;
	}
	PX_CHECK_INT_EQ(px_loop_run(f.l, 20), PX_OK);
	PX_CHECK_INT_EQ(f.n, 20);
	PX_CHECK_INT_EQ(f.order_n, 60);
	for (k = 0; k < 20; k++) {
		const struct px_loop_cycle *c = &f.cy[k];
		PX_CHECK(memcmp(f.order + 3 * k, "rcw", 3) == 0);
		PX_CHECK_INT_EQ(c->index, k);
		/* Absolute deadlines from the start: no drift. */
		PX_CHECK_INT_EQ(c->deadline_ns, 5000 + (int64_t)(k + 1) * P_NS);
		PX_CHECK_INT_EQ(c->wake_ns, c->deadline_ns);
		PX_CHECK_INT_EQ(c->read_ns, c->wake_ns);
		PX_CHECK_INT_EQ(c->compute_ns, c->read_ns + 10000 + k);
		PX_CHECK_INT_EQ(c->compute_end_ns, c->compute_ns + 20000);
		PX_CHECK_INT_EQ(c->write_ns, c->compute_end_ns);
		PX_CHECK_INT_EQ(c->safe, 0);
		PX_CHECK_INT_EQ(c->missed, 0);
	}
	{
		struct px_stats_snapshot s;
		PX_CHECK_INT_EQ(px_loop_stats(f.l, PX_LOOP_STAT_COMPUTE, &s),
				PX_OK);
		PX_CHECK_INT_EQ(s.count, 20);
		PX_CHECK_INT_EQ(s.min_ns, 20000);
		PX_CHECK_INT_EQ(s.max_ns, 20000);
		PX_CHECK_INT_EQ(s.p99_ns, 20000);
		PX_CHECK_INT_EQ(px_loop_stats(f.l, PX_LOOP_STAT_LATENCY, &s),
				PX_OK);
		PX_CHECK_INT_EQ(s.max_ns, 0);
	}
	px_loop_free(f.l);
}

/* Real deadlines at 1, 4 and 10 kHz: order and deadline phase only. */
static void test_phase_order_real_clock(void)
{
	static const int64_t periods[] = {1000000, 250000, 100000};
	size_t p;

	for (p = 0; p < 3; p++) {
		struct px_loop_config cfg;
		struct fx f;
		struct px_loop_status st;
		int k;

		fx_init(&f, &cfg);
		cfg.clock = PX_LOOP_CLOCK_MONOTONIC;
		cfg.period_ns = periods[p];
		cfg.overrun_limit = 0; /* a loaded machine may overrun */
		cfg.budget_limit = 0;
		fx_create(&f, &cfg);
		PX_CHECK_INT_EQ(px_loop_run(f.l, 30), PX_OK);
		PX_CHECK_INT_EQ(f.n, 30);
		for (k = 0; k < 30; k++) {
			const struct px_loop_cycle *c = &f.cy[k];
			PX_CHECK(memcmp(f.order + 3 * k, "rcw", 3) == 0);
			PX_CHECK(c->wake_ns >= c->deadline_ns);
			PX_CHECK(c->read_ns >= c->wake_ns);
			PX_CHECK(c->compute_ns >= c->read_ns);
			PX_CHECK(c->compute_end_ns >= c->compute_ns);
			PX_CHECK(c->write_ns >= c->compute_end_ns);
			if (k > 0) {
				int64_t d = c->deadline_ns - f.cy[0].deadline_ns;
				/* Phase kept even across skipped periods. */
				PX_CHECK(d > 0 && d % periods[p] == 0);
			}
		}
		PX_CHECK_INT_EQ(px_loop_status(f.l, &st), PX_OK);
		PX_CHECK_INT_EQ(st.cycles, 30);
		PX_CHECK_INT_EQ(st.safe, 0);
		PX_CHECK_INT_EQ(st.running, 0);
		px_loop_free(f.l);
	}
}

/* Real clock, slow compute by sleeping: behaviour only (at least the
 * periods slept through are missed, the phase is kept), no timing. */
static int sleepy_compute(struct px_loop *l, const struct px_loop_cycle *c,
			  void *u)
{
	(void)l;
	(void)u;
	if (c->index == 3) {
		struct timespec ts = {0, 2500000};
		nanosleep(&ts, NULL);
	}
	return PX_OK;
}

static void test_overrun_real_clock(void)
{
	struct px_loop_config cfg;
	struct fx f;
	struct px_loop_status st;
	int64_t d;

	fx_init(&f, &cfg);
	cfg.clock = PX_LOOP_CLOCK_MONOTONIC;
	cfg.compute = sleepy_compute;
	cfg.overrun_limit = 0;
	cfg.budget_limit = 0;
	fx_create(&f, &cfg);
	PX_CHECK_INT_EQ(px_loop_run(f.l, 8), PX_OK);
	PX_CHECK_INT_EQ(px_loop_status(f.l, &st), PX_OK);
	PX_CHECK(st.overruns >= 1);
	PX_CHECK(st.missed_periods >= 2);
	d = f.cy[4].deadline_ns - f.cy[3].deadline_ns;
	PX_CHECK(d >= 3 * P_NS && d % P_NS == 0);
	PX_CHECK(f.cy[4].missed >= 2);
	PX_CHECK_INT_EQ(st.cycles, 8);
	px_loop_free(f.l);
}

static int pop_cause(struct px_loop *l, int cause, struct px_fault *out)
{
	struct px_fault f;
	int found = 0;
	memset(out, 0, sizeof(*out));
	while (px_loop_fault_pop(l, &f) == PX_OK)
		if (f.cause == cause && !found) {
			*out = f;
			found = 1;
		}
	return found;
}

static void test_overrun_skip(void)
{
	struct px_loop_config cfg;
	struct fx f;
	struct px_loop_status st;
	struct px_fault flt;
	int64_t d5;

	fx_init(&f, &cfg);
	fx_create(&f, &cfg);
	f.compute_adv[5] = 2 * P_NS + P_NS / 2; /* slow compute */
	/* Ends exactly on a deadline: that one is not missed. */
	f.compute_adv[8] = 2 * P_NS;
	PX_CHECK_INT_EQ(px_loop_run(f.l, 12), PX_OK);
	PX_CHECK_INT_EQ(f.cy[9].deadline_ns, f.cy[8].deadline_ns + 2 * P_NS);
	PX_CHECK_INT_EQ(f.cy[9].missed, 1);
	PX_CHECK_INT_EQ(f.cy[9].wake_ns, f.cy[9].deadline_ns);
	d5 = f.cy[5].deadline_ns;
	/* Two deadlines passed during cycle 5; the next keeps the phase. */
	PX_CHECK_INT_EQ(f.cy[6].deadline_ns, d5 + 3 * P_NS);
	PX_CHECK_INT_EQ(f.cy[6].missed, 2);
	PX_CHECK_INT_EQ(f.cy[6].wake_ns, f.cy[6].deadline_ns);
	PX_CHECK_INT_EQ(f.cy[7].deadline_ns, d5 + 4 * P_NS);
	PX_CHECK_INT_EQ(f.cy[7].missed, 0);
	PX_CHECK_INT_EQ(px_loop_status(f.l, &st), PX_OK);
	PX_CHECK_INT_EQ(st.overruns, 2);
	PX_CHECK_INT_EQ(st.missed_periods, 3);
	PX_CHECK_INT_EQ(st.safe, 0); /* one overrun is below the limit */
	PX_CHECK(pop_cause(f.l, PX_FAULT_OVERRUN, &flt));
	PX_CHECK_INT_EQ(flt.cycle, 5);
	PX_CHECK_INT_EQ(flt.detail, 2);
	PX_CHECK_INT_EQ(flt.safe, 0);
	px_loop_free(f.l);
}

static void test_overrun_catch_up(void)
{
	struct px_loop_config cfg;
	struct fx f;
	struct px_loop_status st;
	int64_t d5, end5;

	fx_init(&f, &cfg);
	cfg.overrun = PX_LOOP_OVERRUN_CATCH_UP;
	cfg.max_catch_up = 3;
	cfg.overrun_limit = 0;
	fx_create(&f, &cfg);
	f.compute_adv[5] = 2 * P_NS + P_NS / 2;
	f.compute_adv[20] = 10 * P_NS + 1; /* more than max_catch_up */
	PX_CHECK_INT_EQ(px_loop_run(f.l, 40), PX_OK);
	d5 = f.cy[5].deadline_ns;
	end5 = f.cy[5].write_ns;
	/* Missed cycles run back to back, on their own deadlines. */
	PX_CHECK_INT_EQ(f.cy[6].deadline_ns, d5 + P_NS);
	PX_CHECK_INT_EQ(f.cy[6].wake_ns, end5);
	PX_CHECK_INT_EQ(f.cy[7].deadline_ns, d5 + 2 * P_NS);
	PX_CHECK_INT_EQ(f.cy[7].wake_ns, end5);
	PX_CHECK_INT_EQ(f.cy[8].deadline_ns, d5 + 3 * P_NS);
	PX_CHECK_INT_EQ(f.cy[8].wake_ns, f.cy[8].deadline_ns);
	PX_CHECK_INT_EQ(f.cy[6].missed, 0);
	/* 10 deadlines passed in cycle 20: 3 caught up, 7 skipped. */
	PX_CHECK_INT_EQ(f.cy[21].missed, 7);
	PX_CHECK_INT_EQ(f.cy[21].deadline_ns, f.cy[20].deadline_ns + 8 * P_NS);
	PX_CHECK_INT_EQ(f.cy[24].deadline_ns, f.cy[20].deadline_ns + 11 * P_NS);
	PX_CHECK_INT_EQ(f.cy[24].wake_ns, f.cy[24].deadline_ns);
	PX_CHECK_INT_EQ(px_loop_status(f.l, &st), PX_OK);
	PX_CHECK_INT_EQ(st.missed_periods, 7);
	/* Cycle 5 and its first catch-up (ends at d5 + 2.5P, after its
	 * next deadline d5 + 2P); cycle 20 and its first two catch-ups. */
	PX_CHECK_INT_EQ(st.overruns, 5);
	PX_CHECK_INT_EQ(st.safe, 0);
	px_loop_free(f.l);
}

/* Safe state after K overruns in a row; outputs zero from the next write. */
static void test_overrun_limit_trips(void)
{
	struct px_loop_config cfg;
	struct fx f;
	struct px_loop_status st;
	int k, K = px_rand_int(1, 5);

	fx_init(&f, &cfg);
	cfg.overrun_limit = (uint32_t)K;
	cfg.budget_limit = 0;
	fx_create(&f, &cfg);
	for (k = 10; k < 30; k++)
		f.compute_adv[k] = P_NS + P_NS / 2;
	f.compute_adv[12] = 0; /* breaks the first run of overruns */
	PX_CHECK_INT_EQ(px_loop_run(f.l, 40), PX_OK);
	PX_CHECK_INT_EQ(px_loop_status(f.l, &st), PX_OK);
	PX_CHECK_INT_EQ(st.safe, 1);
	PX_CHECK_INT_EQ(st.safe_cause, PX_FAULT_OVERRUN);
	/* Overruns in 10, 11, then 13, 14, ...: K-th in a row at 12+K,
	 * unless K <= 2 where 9+K comes first. */
	{
		int trip = K <= 2 ? 9 + K : 12 + K;
		PX_CHECK_INT_EQ(st.safe_cycle, trip);
		PX_CHECK_INT_EQ(f.w_safe[trip], 0);
		PX_CHECK(f.w_out[trip] > 0);
		PX_CHECK_INT_EQ(f.w_safe[trip + 1], 1);
		PX_CHECK_INT_EQ(f.w_out[trip + 1], 0);
		PX_CHECK_INT_EQ(f.w_enable[trip + 1], 0);
	}
	px_loop_free(f.l);
}

/* Each watchdog cause: the write phase of the very cycle that sees it
 * gets safe=1, zero outputs and enables off; the cause is recorded. */
static void check_tripped_at(struct fx *f, int k, int cause, int source)
{
	struct px_loop_status st;
	struct px_fault flt;
	int j;

	PX_CHECK_INT_EQ(px_loop_status(f->l, &st), PX_OK);
	PX_CHECK_INT_EQ(st.safe, 1);
	PX_CHECK_INT_EQ(st.safe_cause, cause);
	PX_CHECK_INT_EQ(st.safe_source, source);
	PX_CHECK_INT_EQ(st.safe_cycle, k);
	PX_CHECK_INT_EQ(st.safe_entries, 1);
	for (j = 0; j < k; j++) {
		PX_CHECK_INT_EQ(f->w_safe[j], 0);
		PX_CHECK(f->w_out[j] == 10.0);
		PX_CHECK_INT_EQ(f->w_enable[j], 1);
	}
	/* Explicit re-arm needed: stays safe until the end. */
	for (j = k; j < f->n; j++) {
		PX_CHECK_INT_EQ(f->w_safe[j], 1);
		PX_CHECK(f->w_out[j] == 0.0);
		PX_CHECK_INT_EQ(f->w_enable[j], 0);
	}
	PX_CHECK(pop_cause(f->l, cause, &flt));
	PX_CHECK_INT_EQ(flt.cycle, k);
	PX_CHECK_INT_EQ(flt.safe, 1);
	PX_CHECK_INT_EQ(flt.source, source);
}

static void test_watchdog_stale_input(void)
{
	int round;
	for (round = 0; round < 5; round++) {
		struct px_loop_config cfg;
		struct fx f;
		int64_t timeout = px_rand_int(P_NS / 2, 8 * P_NS);
		int last = px_rand_int(0, 20), k;

		fx_init(&f, &cfg);
		fx_create(&f, &cfg);
		f.in_idx = px_loop_input_add(f.l, "haptic0", timeout);
		PX_CHECK_INT_EQ(f.in_idx, 0);
		PX_CHECK(strcmp(px_loop_input_name(f.l, 0), "haptic0") == 0);
		f.stamp_until = last + 1;
		PX_CHECK_INT_EQ(px_loop_run(f.l, 40), PX_OK);
		/* Brute force: first cycle whose read ends with the newest
		 * sample (from cycle last) older than the timeout. */
		for (k = last + 1; (int64_t)(k - last) * P_NS <= timeout; k++)
			;
		check_tripped_at(&f, k, PX_FAULT_INPUT_STALE, 0);
		px_loop_free(f.l);
	}
}

static void test_watchdog_never_stamped_input(void)
{
	struct px_loop_config cfg;
	struct fx f;

	fx_init(&f, &cfg);
	fx_create(&f, &cfg);
	f.in_idx = px_loop_input_add(f.l, "can0", 3 * P_NS + 1);
	f.stamp_until = 0;
	PX_CHECK_INT_EQ(px_loop_run(f.l, 10), PX_OK);
	/* Counts from the first wake-up (cycle 0). */
	check_tripped_at(&f, 4, PX_FAULT_INPUT_STALE, 0);
	px_loop_free(f.l);
}

static void test_watchdog_compute_budget(void)
{
	struct px_loop_config cfg;
	struct fx f;
	int k;

	fx_init(&f, &cfg);
	cfg.compute_budget_ns = P_NS / 2;
	cfg.budget_limit = 3;
	fx_create(&f, &cfg);
	/* over, over, ok, over, over, over -> trips at the third in a row. */
	for (k = 4; k < 40; k++)
		f.compute_adv[k] = P_NS / 2 + 1;
	f.compute_adv[6] = P_NS / 2; /* exactly on budget is fine */
	PX_CHECK_INT_EQ(px_loop_run(f.l, 20), PX_OK);
	check_tripped_at(&f, 9, PX_FAULT_COMPUTE_BUDGET, -1);
	{
		struct px_loop_status st;
		px_loop_status(f.l, &st);
		PX_CHECK_INT_EQ(st.budget_exceeded, 15);
		PX_CHECK_INT_EQ(st.overruns, 0);
	}
	px_loop_free(f.l);
}

static void test_watchdog_nonfinite_output(void)
{
	int which;
	for (which = 0; which < 2; which++) {
		struct px_loop_config cfg;
		struct fx f;
		struct px_fault flt;
		int k = px_rand_int(0, 30);

		fx_init(&f, &cfg);
		fx_create(&f, &cfg);
		if (which)
			f.inf_at = k;
		else
			f.nan_at = k;
		PX_CHECK_INT_EQ(px_loop_run(f.l, 40), PX_OK);
		check_tripped_at(&f, k, PX_FAULT_OUTPUT_NONFINITE, 0);
		/* detail: index of the bad element (popped above), check
		 * again on a fresh trip below. */
		px_loop_rearm(f.l);
		f.nan_at = 40;
		f.inf_at = -1;
		PX_CHECK_INT_EQ(px_loop_run(f.l, 5), PX_OK);
		PX_CHECK_INT_EQ(f.w_safe[40], 1);
		PX_CHECK(pop_cause(f.l, PX_FAULT_OUTPUT_NONFINITE, &flt));
		PX_CHECK_INT_EQ(flt.detail, 2);
		PX_CHECK_INT_EQ(flt.cycle, 40);
		px_loop_free(f.l);
	}
}

static void test_watchdog_callback_error_and_trip(void)
{
	struct px_loop_config cfg;
	struct fx f;
	struct px_fault flt;

	fx_init(&f, &cfg);
	fx_create(&f, &cfg);
	f.read_err_at = 7;
	PX_CHECK_INT_EQ(px_loop_run(f.l, 12), PX_OK);
	check_tripped_at(&f, 7, PX_FAULT_CALLBACK, 0);
	px_loop_free(f.l);

	fx_init(&f, &cfg);
	fx_create(&f, &cfg);
	PX_CHECK_INT_EQ(px_loop_run(f.l, 3), PX_OK);
	px_loop_trip(f.l);
	PX_CHECK_INT_EQ(px_loop_run(f.l, 3), PX_OK);
	check_tripped_at(&f, 3, PX_FAULT_TRIP, -1);
	(void)flt;
	px_loop_free(f.l);
}

static void test_rearm(void)
{
	struct px_loop_config cfg;
	struct fx f;
	struct px_loop_status st;

	fx_init(&f, &cfg);
	fx_create(&f, &cfg);
	f.nan_at = 2;
	PX_CHECK_INT_EQ(px_loop_run(f.l, 10), PX_OK);
	PX_CHECK(px_loop_is_safe(f.l));
	PX_CHECK_INT_EQ(f.w_safe[9], 1);
	px_loop_rearm(f.l);
	PX_CHECK(px_loop_is_safe(f.l)); /* applied by the next cycle */
	PX_CHECK_INT_EQ(px_loop_run(f.l, 5), PX_OK);
	PX_CHECK(!px_loop_is_safe(f.l));
	PX_CHECK_INT_EQ(f.w_safe[10], 0);
	PX_CHECK(f.w_out[10] == 10.0);
	PX_CHECK_INT_EQ(f.w_enable[10], 1);
	/* A cause that persists trips again in the re-armed cycle. */
	px_loop_free(f.l);

	fx_init(&f, &cfg);
	fx_create(&f, &cfg);
	f.in_idx = px_loop_input_add(f.l, "dead", P_NS / 2);
	f.stamp_until = 0;
	PX_CHECK_INT_EQ(px_loop_run(f.l, 3), PX_OK);
	px_loop_rearm(f.l);
	PX_CHECK_INT_EQ(px_loop_run(f.l, 1), PX_OK);
	PX_CHECK_INT_EQ(f.w_safe[3], 1);
	PX_CHECK_INT_EQ(px_loop_status(f.l, &st), PX_OK);
	PX_CHECK_INT_EQ(st.safe_entries, 2);
	PX_CHECK_INT_EQ(st.safe_cycle, 3);
	px_loop_free(f.l);

	/* Automatic re-arm after N clean cycles, when configured. */
	fx_init(&f, &cfg);
	cfg.rearm_after_ok_cycles = 4;
	fx_create(&f, &cfg);
	f.nan_at = 2;
	PX_CHECK_INT_EQ(px_loop_run(f.l, 12), PX_OK);
	PX_CHECK_INT_EQ(f.w_safe[2], 1);
	PX_CHECK_INT_EQ(f.w_safe[6], 1); /* 3..6 clean: leaves after 6 */
	PX_CHECK_INT_EQ(f.w_safe[7], 0);
	PX_CHECK(f.w_out[7] == 10.0);
	px_loop_free(f.l);
}

/* An e-stop latches safe state against automatic re-arm, also when it
 * joins a safe state another cause entered (a NaN here), and a
 * px_loop_rearm() clears it; the fault ring names the cause. */
static void test_estop_latched_against_auto_rearm(void)
{
	struct px_loop_config cfg;
	struct px_loop_status st;
	struct px_fault ft;
	struct fx f;
	int k, estops = 0;

	fx_init(&f, &cfg);
	cfg.rearm_after_ok_cycles = 4;
	fx_create(&f, &cfg);
	f.nan_at = 2;
	PX_CHECK_INT_EQ(px_loop_run(f.l, 3), PX_OK); /* safe from 2 */
	px_loop_trip_estop(f.l);                      /* joins at 3 */
	PX_CHECK_INT_EQ(px_loop_run(f.l, 40), PX_OK);
	for (k = 2; k < 43; k++) {
		PX_CHECK_MSG(f.w_safe[k] == 1 && f.w_enable[k] == 0 &&
				     f.w_out[k] == 0.0,
			     "cycle %d left safe state", k);
	}
	PX_CHECK_INT_EQ(px_loop_status(f.l, &st), PX_OK);
	PX_CHECK_INT_EQ(st.safe_entries, 1);
	while (px_loop_fault_pop(f.l, &ft) == PX_OK)
		if (ft.cause == PX_FAULT_ESTOP) {
			estops++;
			PX_CHECK_INT_EQ(ft.cycle, 3);
			PX_CHECK_INT_EQ(ft.safe, 1);
		}
	PX_CHECK_INT_EQ(estops, 1);
	PX_CHECK(strcmp(px_fault_cause_name(PX_FAULT_ESTOP), "estop") == 0);
	px_loop_rearm(f.l);
	PX_CHECK_INT_EQ(px_loop_run(f.l, 2), PX_OK);
	PX_CHECK_INT_EQ(f.w_safe[43], 0);
	PX_CHECK(f.w_out[44] == 10.0);
	/* after the reset, automatic re-arm works again for other causes */
	f.nan_at = 50;
	PX_CHECK_INT_EQ(px_loop_run(f.l, 15), PX_OK);
	PX_CHECK_INT_EQ(f.w_safe[50], 1);
	PX_CHECK_INT_EQ(f.w_safe[55], 0);
	/* an e-stop entering safe state itself: latched as well, its cause */
	px_loop_trip_estop(f.l);
	PX_CHECK_INT_EQ(px_loop_run(f.l, 20), PX_OK);
	PX_CHECK(px_loop_is_safe(f.l));
	PX_CHECK_INT_EQ(px_loop_status(f.l, &st), PX_OK);
	PX_CHECK_INT_EQ(st.safe_cause, PX_FAULT_ESTOP);
	px_loop_free(f.l);
}

static void test_stop_from_phase(void)
{
	struct px_loop_config cfg;
	struct fx f;

	fx_init(&f, &cfg);
	fx_create(&f, &cfg);
	f.stop_at = 4;
	PX_CHECK_INT_EQ(px_loop_run(f.l, 100), PX_OK);
	PX_CHECK_INT_EQ(f.n, 5);
	PX_CHECK_INT_EQ(f.order_n, 15);
	/* px_loop_step runs single cycles and reports the stop. */
	PX_CHECK_INT_EQ(px_loop_step(f.l), PX_OK);
	f.stop_at = 6;
	PX_CHECK_INT_EQ(px_loop_step(f.l), PX_LOOP_STOP);
	px_loop_free(f.l);
}

/* 100,000 cycles with every feature busy, virtual clock: not one heap
 * call on the loop's thread. */
struct busy {
	struct px_ring *tele;
	struct px_param *gains;
	double out[6];
	int en;
	int in;
	uint64_t got_fresh;
};

static int busy_read(struct px_loop *l, const struct px_loop_cycle *c, void *u)
{
	struct busy *b = u;
	if (c->index % 5000 != 4999) /* a dropout now and then */
		px_loop_input_stamp(l, b->in, px_loop_now_ns(l));
	px_loop_vclock_advance(l, 1000 + (int64_t)(c->index % 7) * 100);
	return PX_OK;
}

static int busy_compute(struct px_loop *l, const struct px_loop_cycle *c,
			void *u)
{
	struct busy *b = u;
	int fresh, i;
	const double *g = px_param_read(b->gains, &fresh);
	struct px_stats_snapshot s;

	b->got_fresh += (uint64_t)fresh;
	for (i = 0; i < 6; i++)
		b->out[i] = g[0] * (double)i;
	if (c->index % 20000 == 10)
		b->out[1] = NAN;
	if (c->index % 30000 == 20)
		px_loop_vclock_advance(l, 3 * P_NS); /* overrun */
	b->en = 1;
	if (c->index % 1000 == 0) {
		px_loop_stats(l, PX_LOOP_STAT_LATENCY, &s);
		px_loop_status(l, &(struct px_loop_status){0});
	}
	if (c->index % 10000 == 0) {
		px_loop_rearm(l);
		px_loop_stats_reset(l);
	}
	return PX_OK;
}

static int busy_write(struct px_loop *l, const struct px_loop_cycle *c,
		      void *u)
{
	struct busy *b = u;
	struct {
		uint64_t i;
		double f[6];
	} rec;
	struct px_fault flt;
	(void)l;
	rec.i = c->index;
	memcpy(rec.f, b->out, sizeof(rec.f));
	px_ring_push(b->tele, &rec);
	if (c->index % 2 == 0) { /* drain part of it, as a consumer would */
		unsigned char tmp[64];
		px_ring_pop(b->tele, tmp);
	}
	px_loop_fault_pop(l, &flt);
	return PX_OK;
}

static void test_no_allocation_100k_cycles(void)
{
	static unsigned char mem[1 << 16];
	struct px_arena a;
	struct px_loop_config cfg;
	struct px_loop *l;
	struct px_loop_status st;
	struct busy b;
	double g = 2.0;
	uint64_t r;

	memset(&b, 0, sizeof(b));
	PX_CHECK_INT_EQ(px_arena_init(&a, mem, sizeof(mem)), PX_OK);
	PX_CHECK_INT_EQ(px_ring_create(&a, 64, 56, &b.tele), PX_OK);
	PX_CHECK_INT_EQ(px_param_create(&a, sizeof(g), &g, &b.gains), PX_OK);
	px_loop_config_default(&cfg);
	cfg.clock = PX_LOOP_CLOCK_VIRTUAL;
	cfg.read = busy_read;
	cfg.compute = busy_compute;
	cfg.write = busy_write;
	cfg.user = &b;
	cfg.overrun_limit = 1;
	PX_CHECK_INT_EQ(px_loop_create(&cfg, &l), PX_OK);
	b.in = px_loop_input_add(l, "dev", 2 * P_NS);
	PX_CHECK(px_loop_output_add(l, "cmd", b.out, 6) >= 0);
	PX_CHECK(px_loop_enable_add(l, "en", &b.en) >= 0);
	r = px_alloc_region_begin();
	PX_CHECK_INT_EQ(px_loop_run(l, 100000), PX_OK);
	PX_CHECK_INT_EQ(px_alloc_region_end(r), 0);
	PX_CHECK_INT_EQ(px_loop_status(l, &st), PX_OK);
	PX_CHECK_INT_EQ(st.cycles, 100000);
	/* The features were really exercised. */
	PX_CHECK(st.safe_entries >= 5);
	PX_CHECK(st.faults >= 5);
	PX_CHECK(px_ring_pushed(b.tele) > 50000);
	px_loop_free(l);
}

/* Status and statistics read from another thread while a real-clock
 * loop runs; px_loop_stop() from outside. */
static void test_concurrent_status_and_stop(void)
{
	struct px_loop_config cfg;
	struct fx f;
	struct px_loop_status st;
	struct px_stats_snapshot s;
	uint64_t last = 0, reads = 0, backwards = 0;

	fx_init(&f, &cfg);
	cfg.clock = PX_LOOP_CLOCK_MONOTONIC;
	cfg.period_ns = 100000;
	cfg.overrun_limit = 0;
	cfg.budget_limit = 0;
	fx_create(&f, &cfg);
	PX_CHECK_INT_EQ(px_loop_start(f.l, 0), PX_OK);
	PX_CHECK_INT_EQ(px_loop_start(f.l, 0), PX_E_STATE);
	while (last < 300) {
		PX_CHECK_INT_EQ(px_loop_status(f.l, &st), PX_OK);
		if (st.cycles < last)
			backwards++;
		last = st.cycles;
		if (px_loop_stats(f.l, PX_LOOP_STAT_LATENCY, &s) == PX_OK &&
		    s.count > 0 &&
		    !(s.min_ns <= s.p50_ns + 1000 && s.p50_ns <= s.p99_ns &&
		      s.p99_ns <= s.p999_ns && s.p999_ns <= s.max_ns))
			backwards++;
		reads++;
		{
			struct timespec ts = {0, 200000};
			nanosleep(&ts, NULL);
		}
	}
	PX_CHECK_INT_EQ(px_loop_step(f.l), PX_E_STATE);
	PX_CHECK_INT_EQ(px_loop_input_add(f.l, "late", 1), PX_E_STATE);
	px_loop_stop(f.l);
	PX_CHECK_INT_EQ(px_loop_join(f.l), PX_OK);
	PX_CHECK_INT_EQ(backwards, 0);
	PX_CHECK_INT_EQ(px_loop_status(f.l, &st), PX_OK);
	PX_CHECK_INT_EQ(st.running, 0);
	PX_CHECK(st.cycles >= 300);
	PX_CHECK_INT_EQ(px_loop_stats(f.l, PX_LOOP_STAT_CYCLE, &s), PX_OK);
	PX_CHECK_INT_EQ(s.count, st.cycles);
	px_loop_stats_reset(f.l);
	PX_CHECK_INT_EQ(px_loop_stats(f.l, PX_LOOP_STAT_CYCLE, &s), PX_OK);
	PX_CHECK_INT_EQ(s.count, 0);
	px_loop_free(f.l);
}

/* ---- phase by phase ------------------------------------------------------ */

static void check_cycle_eq(const struct px_loop_cycle *a,
			   const struct px_loop_cycle *b, int k)
{
	PX_CHECK_MSG(a->index == b->index && a->period_ns == b->period_ns &&
			     a->deadline_ns == b->deadline_ns &&
			     a->wake_ns == b->wake_ns &&
			     a->read_ns == b->read_ns &&
			     a->compute_ns == b->compute_ns &&
			     a->compute_end_ns == b->compute_end_ns &&
			     a->write_ns == b->write_ns &&
			     a->missed == b->missed && a->safe == b->safe,
		     "cycle %d: the phases saw another cycle than the step", k);
}

/* The same scripted faults, once by px_loop_step() and once by the phase
 * calls at the deadlines' times: a stale input that comes back, compute
 * over budget, a NaN and an infinity (all re-armed automatically), and an
 * e-stop that stays latched against the automatic re-arm until
 * px_loop_rearm(). Every phase, output, fault and status is the same. */
static void test_phases_match_step(void)
{
	struct px_loop_config cfg;
	struct fx a, b;
	struct px_loop_status sa, sb;
	struct px_fault fa, fb;
	int k, i, n = 120, nf = 0;

	fx_init(&b, &cfg);
	fx_init(&a, &cfg);
	cfg.rearm_after_ok_cycles = 3;
	cfg.compute_budget_ns = P_NS / 2;
	fx_create(&a, &cfg);
	cfg.user = &b;
	fx_create(&b, &cfg);
	a.in_idx = px_loop_input_add(a.l, "haptic0", 3 * P_NS);
	b.in_idx = px_loop_input_add(b.l, "haptic0", 3 * P_NS);
	PX_CHECK(a.in_idx == 0 && b.in_idx == 0);
	for (k = 0; k < MAXC; k++)
		a.read_adv[k] = b.read_adv[k] = 1000 + 10 * k;
	for (k = 40; k < 44; k++)
		a.compute_adv[k] = b.compute_adv[k] = 7 * P_NS / 10;
	a.nan_at = b.nan_at = 30;
	a.inf_at = b.inf_at = 90;
	a.read_err_at = b.read_err_at = 100;
	for (k = 0; k < n; k++) {
		int64_t now = (int64_t)(k + 1) * P_NS;
		if (k == 10)
			a.stamp_until = b.stamp_until = 10;
		if (k == 20)
			a.stamp_until = b.stamp_until = 1 << 30;
		if (k == 50) {
			px_loop_trip_estop(a.l);
			px_loop_trip_estop(b.l);
		}
		if (k == 75) {
			px_loop_rearm(a.l);
			px_loop_rearm(b.l);
		}
		PX_CHECK_INT_EQ(px_loop_step(a.l), PX_OK);
		PX_CHECK_INT_EQ(px_loop_read(b.l, now), PX_OK);
		PX_CHECK_INT_EQ(px_loop_compute(b.l, now), PX_OK);
		PX_CHECK_INT_EQ(px_loop_write(b.l, now), PX_OK);
		PX_CHECK_MSG(px_loop_is_safe(a.l) == px_loop_is_safe(b.l),
			     "cycle %d: safe %d by the step, %d by the phases",
			     k, px_loop_is_safe(a.l), px_loop_is_safe(b.l));
	}
	PX_CHECK_INT_EQ(a.n, n);
	PX_CHECK_INT_EQ(b.n, n);
	PX_CHECK(a.order_n == b.order_n &&
		 memcmp(a.order, b.order, (size_t)a.order_n) == 0);
	for (k = 0; k < n; k++) {
		check_cycle_eq(&a.cy[k], &b.cy[k], k);
		PX_CHECK_MSG(a.w_safe[k] == b.w_safe[k] &&
				     a.w_enable[k] == b.w_enable[k] &&
				     a.w_out[k] == b.w_out[k],
			     "cycle %d: other outputs than the step", k);
	}
	/* the script did trip each way: stale, NaN, e-stop held past the
	 * automatic re-arm, a failing read */
	PX_CHECK_INT_EQ(a.w_safe[11], 0);
	PX_CHECK_INT_EQ(a.w_safe[12], 1);
	PX_CHECK_INT_EQ(a.w_safe[29], 0);
	PX_CHECK_INT_EQ(a.w_safe[30], 1);
	PX_CHECK_INT_EQ(a.w_safe[42], 1);
	PX_CHECK_INT_EQ(a.w_safe[49], 0);
	for (k = 50; k < 75; k++)
		PX_CHECK_MSG(b.w_safe[k] == 1 && b.w_enable[k] == 0 &&
				     b.w_out[k] == 0.0,
			     "cycle %d left the e-stop's safe state", k);
	PX_CHECK_INT_EQ(b.w_safe[75], 0);
	PX_CHECK(b.w_out[75] == 10.0);
	PX_CHECK_INT_EQ(b.w_safe[90], 1);
	PX_CHECK_INT_EQ(b.w_safe[100], 1);
	PX_CHECK_INT_EQ(b.w_safe[n - 1], 0);
	PX_CHECK_INT_EQ(px_loop_status(a.l, &sa), PX_OK);
	PX_CHECK_INT_EQ(px_loop_status(b.l, &sb), PX_OK);
	PX_CHECK(sa.cycles == sb.cycles && sa.overruns == sb.overruns &&
		 sa.missed_periods == sb.missed_periods &&
		 sa.budget_exceeded == sb.budget_exceeded &&
		 sa.safe_entries == sb.safe_entries &&
		 sa.faults == sb.faults && sa.safe == sb.safe &&
		 sa.safe_cause == sb.safe_cause &&
		 sa.safe_cycle == sb.safe_cycle);
	PX_CHECK_INT_EQ(sa.budget_exceeded, 4);
	PX_CHECK(sa.safe_entries >= 5);
	while (px_loop_fault_pop(a.l, &fa) == PX_OK) {
		PX_CHECK_INT_EQ(px_loop_fault_pop(b.l, &fb), PX_OK);
		PX_CHECK_MSG(fa.cycle == fb.cycle && fa.t_ns == fb.t_ns &&
				     fa.cause == fb.cause &&
				     fa.source == fb.source &&
				     fa.detail == fb.detail &&
				     fa.safe == fb.safe,
			     "fault %d differs", nf);
		nf++;
	}
	PX_CHECK_INT_EQ(px_loop_fault_pop(b.l, &fb), PX_E_AGAIN);
	PX_CHECK_INT_EQ((uint64_t)nf, sa.faults);
	for (i = 0; i < PX_LOOP_STAT__COUNT; i++) {
		struct px_stats_snapshot xa, xb;
		PX_CHECK_INT_EQ(px_loop_stats(a.l, (enum px_loop_stat)i, &xa),
				PX_OK);
		PX_CHECK_INT_EQ(px_loop_stats(b.l, (enum px_loop_stat)i, &xb),
				PX_OK);
		PX_CHECK(xa.count == xb.count && xa.min_ns == xb.min_ns &&
			 xa.max_ns == xb.max_ns && xa.p99_ns == xb.p99_ns);
	}
	px_loop_free(a.l);
	px_loop_free(b.l);
}

/* Phases out of order are refused and leave the open cycle as it was;
 * nothing else drives the loop while a cycle is open. */
static void test_phases_out_of_order(void)
{
	struct px_loop_config cfg;
	struct fx f;

	fx_init(&f, &cfg);
	fx_create(&f, &cfg);
	PX_CHECK_INT_EQ(px_loop_write(f.l, P_NS), PX_E_STATE);
	PX_CHECK_INT_EQ(px_loop_compute(f.l, P_NS), PX_E_STATE);
	PX_CHECK_INT_EQ(f.order_n, 0);
	PX_CHECK_INT_EQ(px_loop_read(f.l, P_NS), PX_OK);
	PX_CHECK_INT_EQ(px_loop_read(f.l, P_NS), PX_E_STATE);
	PX_CHECK_INT_EQ(px_loop_write(f.l, P_NS), PX_E_STATE);
	PX_CHECK_INT_EQ(px_loop_step(f.l), PX_E_STATE);
	PX_CHECK_INT_EQ(px_loop_run(f.l, 1), PX_E_STATE);
	PX_CHECK_INT_EQ(px_loop_start(f.l, 1), PX_E_STATE);
	PX_CHECK_INT_EQ(px_loop_compute(f.l, P_NS), PX_OK);
	PX_CHECK_INT_EQ(px_loop_compute(f.l, P_NS), PX_E_STATE);
	PX_CHECK_INT_EQ(px_loop_read(f.l, P_NS), PX_E_STATE);
	PX_CHECK_INT_EQ(px_loop_write(f.l, P_NS), PX_OK);
	PX_CHECK_INT_EQ(f.order_n, 3);
	PX_CHECK(memcmp(f.order, "rcw", 3) == 0);
	PX_CHECK_INT_EQ(px_loop_write(f.l, 2 * P_NS), PX_E_STATE);
	/* a closed cycle: the step takes over at the next deadline */
	PX_CHECK_INT_EQ(px_loop_step(f.l), PX_OK);
	PX_CHECK_INT_EQ(f.n, 2);
	PX_CHECK_INT_EQ(f.cy[1].deadline_ns, 2 * P_NS);
	/* a stop asked by a phase comes back from that phase on */
	f.stop_at = 2;
	PX_CHECK_INT_EQ(px_loop_read(f.l, 3 * P_NS), PX_OK);
	PX_CHECK_INT_EQ(px_loop_compute(f.l, 3 * P_NS), PX_OK);
	PX_CHECK_INT_EQ(px_loop_write(f.l, 3 * P_NS), PX_LOOP_STOP);
	PX_CHECK_INT_EQ(px_loop_read(NULL, 0), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_loop_compute(NULL, 0), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_loop_write(NULL, 0), PX_E_INVAL);
	px_loop_free(f.l);
}

/* The real clock: the caller's times are the phases' starts, the cycle
 * is due at the caller's wake-up and no phase sleeps. */
static void test_phases_real_clock(void)
{
	struct px_loop_config cfg;
	struct fx f;
	struct timespec ts;
	int64_t t0;
	int k;

	fx_init(&f, &cfg);
	cfg.clock = PX_LOOP_CLOCK_MONOTONIC;
	cfg.period_ns = 10 * P_NS;
	fx_create(&f, &cfg);
	for (k = 0; k < 3; k++) {
		clock_gettime(CLOCK_MONOTONIC, &ts);
		t0 = (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
		PX_CHECK_INT_EQ(px_loop_read(f.l, t0), PX_OK);
		PX_CHECK_INT_EQ(px_loop_compute(f.l, t0 + 1), PX_OK);
		PX_CHECK_INT_EQ(px_loop_write(f.l, t0 + 2), PX_OK);
		PX_CHECK_INT_EQ(f.cy[k].wake_ns, t0);
		PX_CHECK_INT_EQ(f.cy[k].deadline_ns, t0);
		PX_CHECK_INT_EQ(f.cy[k].read_ns, t0);
		PX_CHECK_INT_EQ(f.cy[k].compute_ns, t0 + 1);
		PX_CHECK_INT_EQ(f.cy[k].write_ns, t0 + 2);
	}
	PX_CHECK_INT_EQ(f.n, 3);
	px_loop_free(f.l);
}

/* 10,000 phase-driven cycles with a fault script: no heap call. */
static void test_phases_no_allocation(void)
{
	struct px_loop_config cfg;
	struct fx f;
	uint64_t r;
	int k;

	fx_init(&f, &cfg);
	cfg.rearm_after_ok_cycles = 2;
	fx_create(&f, &cfg);
	f.in_idx = px_loop_input_add(f.l, "in", 2 * P_NS);
	f.nan_at = 50;
	f.stamp_until = 100;
	r = px_alloc_region_begin();
	for (k = 0; k < 10000; k++) {
		int64_t now = (int64_t)(k + 1) * P_NS;
		if (k == 200)
			f.stamp_until = 1 << 30;
		if (k == 300)
			px_loop_trip_estop(f.l);
		if (k == 360)
			px_loop_rearm(f.l);
		f.order_n = 0; /* the order log holds MAXC cycles */
		px_loop_read(f.l, now);
		px_loop_compute(f.l, now);
		px_loop_write(f.l, now);
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(r), 0);
	PX_CHECK_INT_EQ(f.w_safe[350], 1);
	PX_CHECK_INT_EQ(f.w_safe[MAXC - 1], 0);
	px_loop_free(f.l);
}

static void test_bad_args(void)
{
	struct px_loop_config cfg;
	struct px_loop *l = (struct px_loop *)1;
	double v[2];
	int e;

	px_loop_config_default(&cfg);
	PX_CHECK_INT_EQ(px_loop_create(NULL, &l), PX_E_INVAL);
	PX_CHECK(l == NULL);
	cfg.period_ns = 0;
	PX_CHECK_INT_EQ(px_loop_create(&cfg, &l), PX_E_INVAL);
	px_loop_config_default(&cfg);
	cfg.fault_capacity = 1;
	PX_CHECK_INT_EQ(px_loop_create(&cfg, &l), PX_E_INVAL);
	px_loop_config_default(&cfg);
	cfg.clock = (enum px_loop_clock)7;
	PX_CHECK_INT_EQ(px_loop_create(&cfg, &l), PX_E_INVAL);
	px_loop_config_default(&cfg);
	cfg.max_inputs = 1;
	cfg.max_outputs = 1;
	cfg.max_enables = 1;
	PX_CHECK_INT_EQ(px_loop_create(&cfg, &l), PX_OK);
	PX_CHECK_INT_EQ(px_loop_input_add(l, NULL, 0), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_loop_input_add(l, NULL, 5), 0);
	PX_CHECK_INT_EQ(px_loop_input_add(l, NULL, 5), PX_E_NOSPC);
	PX_CHECK_INT_EQ(px_loop_input_stamp(l, 1, 0), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_loop_output_add(l, "x", NULL, 2), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_loop_output_add(l, "x", v, 2), 0);
	PX_CHECK_INT_EQ(px_loop_output_add(l, "y", v, 2), PX_E_NOSPC);
	PX_CHECK_INT_EQ(px_loop_enable_add(l, "e", NULL), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_loop_enable_add(l, "e", &e), 0);
	PX_CHECK_INT_EQ(px_loop_enable_add(l, "e", &e), PX_E_NOSPC);
	PX_CHECK_INT_EQ(px_loop_vclock_advance(l, 5), PX_E_STATE);
	PX_CHECK_INT_EQ(px_loop_join(l), PX_E_STATE);
	PX_CHECK_INT_EQ(px_loop_stats(l, PX_LOOP_STAT__COUNT,
				      &(struct px_stats_snapshot){0}),
			PX_E_INVAL);
	PX_CHECK(px_loop_stats_handle(l, PX_LOOP_STAT_LATENCY) != NULL);
	PX_CHECK(strcmp(px_loop_output_name(l, 0), "x") == 0);
	PX_CHECK(strcmp(px_loop_output_name(l, 3), "") == 0);
	px_loop_free(l);
	px_loop_free(NULL);
	PX_CHECK_INT_EQ(px_loop_status(NULL, NULL), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_loop_step(NULL), PX_E_INVAL);
}

static const struct px_test tests[] = {
	PX_T(test_phase_order_virtual),
	PX_T(test_phase_order_real_clock),
	PX_T(test_overrun_skip),
	PX_T(test_overrun_catch_up),
	PX_T(test_overrun_real_clock),
	PX_T(test_overrun_limit_trips),
	PX_T(test_watchdog_stale_input),
	PX_T(test_watchdog_never_stamped_input),
	PX_T(test_watchdog_compute_budget),
	PX_T(test_watchdog_nonfinite_output),
	PX_T(test_watchdog_callback_error_and_trip),
	PX_T(test_rearm),
	PX_T(test_estop_latched_against_auto_rearm),
	PX_T(test_stop_from_phase),
	PX_T(test_no_allocation_100k_cycles),
	PX_T(test_concurrent_status_and_stop),
	PX_T(test_bad_args),
	PX_T(test_phases_match_step),
	PX_T(test_phases_out_of_order),
	PX_T(test_phases_real_clock),
	PX_T(test_phases_no_allocation),
};

PX_TEST_MAIN(tests)
