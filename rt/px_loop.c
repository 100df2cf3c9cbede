#include "px_loop.h"

#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "rt_internal.h"
#include "px_arena.h"
#include "px_ring.h"

#define NAME_LEN 32
#define MAX_TABLE 4096u
#define MAX_FAULTS ((size_t)1 << 20)

/* Where the open cycle stands (l->stage). */
enum { STAGE_IDLE = 0, STAGE_READ = 1, STAGE_COMPUTE = 2 };

struct input {
	char name[NAME_LEN];
	int64_t timeout_ns;
	int64_t last_ns; /* newest sample time */
	int stale;       /* stale at the last check */
};

struct output {
	char name[NAME_LEN];
	double *v;
	size_t n;
	int bad; /* held a non-finite value at the last check */
};

struct enable {
	char name[NAME_LEN];
	int *flag;
};

struct px_loop {
	struct px_loop_config cfg;
	struct px_arena arena;
	struct px_stats *st[PX_LOOP_STAT__COUNT];
	struct px_ring *faults;
	struct input *in;
	struct output *out;
	struct enable *en;
	size_t n_in, n_out, n_en;

	/* Cycle state: loop thread only. */
	int started;
	int64_t next_deadline;
	uint64_t index;
	uint32_t pending_missed;
	uint32_t consec_overruns, consec_budget, ok_cycles;
	unsigned trip_ack, rearm_ack, reset_ack, estop_ack;
	/* an e-stop tripped since the last px_loop_rearm(): safe state
	 * stays whatever rearm_after_ok_cycles says */
	int latched;
	/* The open cycle: the next piece to run is the one after stage. */
	struct px_loop_cycle cy;
	int stage;
	int cy_stop, cy_bad;

	/* Virtual clock; atomic so px_loop_now_ns() works from anywhere. */
	_Atomic int64_t vnow;

	/* Requests from other threads (counters: a request is pending
	 * while the counter differs from the loop's ack). */
	_Atomic int stop_req;
	_Atomic unsigned trip_req, rearm_req, reset_req, estop_req;

	/* Status, written by the loop thread, read by anyone. */
	_Atomic int running, safe;
	_Atomic int32_t safe_cause, safe_source;
	_Atomic uint64_t safe_cycle, cycles, overruns, missed, budget_exceeded,
		safe_entries, nfaults;
	/* Even when rt is stable; odd while the loop thread rewrites it. */
	_Atomic unsigned rt_gen;
	int rt_applied;
	struct px_rt_report rt;

	/* px_loop_start() */
	pthread_t thread;
	int thread_live;
	uint64_t thread_max;
	int thread_rc;
};

#define LD(x) atomic_load_explicit(&(x), memory_order_relaxed)
#define ST(x, v) atomic_store_explicit(&(x), (v), memory_order_relaxed)
#define INC(x) ST(x, LD(x) + 1)

void px_loop_config_default(struct px_loop_config *c)
{
	if (!c)
		return;
	memset(c, 0, sizeof(*c));
	c->period_ns = 1000000;
	c->clock = PX_LOOP_CLOCK_MONOTONIC;
	c->overrun = PX_LOOP_OVERRUN_SKIP;
	c->max_catch_up = 10;
	c->overrun_limit = 3;
	c->budget_limit = 3;
	c->max_inputs = 16;
	c->max_outputs = 16;
	c->max_enables = 16;
	c->fault_capacity = 256;
	c->hist_bins = PX_STATS_DEFAULT_BINS;
	c->hist_bin_ns = PX_STATS_DEFAULT_BIN_NS;
	px_rt_config_default(&c->rt);
}

int px_loop_create(const struct px_loop_config *cfg, struct px_loop **out)
{
	struct px_loop *l;
	size_t need;
	int i, rc;

	if (!out)
		return PX_E_INVAL;
	*out = NULL;
	if (!cfg || cfg->period_ns <= 0 || cfg->compute_budget_ns < 0 ||
	    cfg->hist_bin_ns < 0 ||
	    (cfg->clock != PX_LOOP_CLOCK_MONOTONIC &&
	     cfg->clock != PX_LOOP_CLOCK_VIRTUAL) ||
	    (cfg->overrun != PX_LOOP_OVERRUN_SKIP &&
	     cfg->overrun != PX_LOOP_OVERRUN_CATCH_UP) ||
	    cfg->max_inputs > MAX_TABLE || cfg->max_outputs > MAX_TABLE ||
	    cfg->max_enables > MAX_TABLE || cfg->fault_capacity < 2 ||
	    cfg->fault_capacity > MAX_FAULTS ||
	    cfg->hist_bins > ((size_t)1 << 24))
		return PX_E_INVAL;
	l = calloc(1, sizeof(*l));
	if (!l)
		return PX_E_NOMEM;
	l->cfg = *cfg;
	if (l->cfg.compute_budget_ns == 0)
		l->cfg.compute_budget_ns = l->cfg.period_ns;
	if (l->cfg.hist_bins == 0)
		l->cfg.hist_bins = PX_STATS_DEFAULT_BINS;
	if (l->cfg.hist_bin_ns == 0)
		l->cfg.hist_bin_ns = PX_STATS_DEFAULT_BIN_NS;
	need = PX_LOOP_STAT__COUNT * px_stats_size(l->cfg.hist_bins) +
	       px_ring_size(cfg->fault_capacity, sizeof(struct px_fault)) +
	       cfg->max_inputs * sizeof(struct input) +
	       cfg->max_outputs * sizeof(struct output) +
	       cfg->max_enables * sizeof(struct enable) + 4 * PX_ARENA_ALIGN;
	/* The arena zero-fills, so all of it is faulted in here. */
	if (px_arena_init_alloc(&l->arena, need) != PX_OK) {
		free(l);
		return PX_E_NOMEM;
	}
	rc = PX_OK;
	for (i = 0; i < PX_LOOP_STAT__COUNT && rc == PX_OK; i++)
		rc = px_stats_create(&l->arena, l->cfg.hist_bins,
				     l->cfg.hist_bin_ns, &l->st[i]);
	if (rc == PX_OK)
		rc = px_ring_create(&l->arena, cfg->fault_capacity,
				    sizeof(struct px_fault), &l->faults);
	l->in = px_arena_calloc(&l->arena, cfg->max_inputs, sizeof(*l->in), 0);
	l->out = px_arena_calloc(&l->arena, cfg->max_outputs, sizeof(*l->out),
				 0);
	l->en = px_arena_calloc(&l->arena, cfg->max_enables, sizeof(*l->en), 0);
	if (rc != PX_OK || !l->in || !l->out || !l->en) {
		px_arena_fini(&l->arena);
		free(l);
		return PX_E_NOMEM;
	}
	atomic_init(&l->vnow, cfg->vclock_start_ns);
	atomic_init(&l->stop_req, 0);
	atomic_init(&l->trip_req, 0);
	atomic_init(&l->rearm_req, 0);
	atomic_init(&l->estop_req, 0);
	atomic_init(&l->reset_req, 0);
	atomic_init(&l->running, 0);
	atomic_init(&l->safe, 0);
	atomic_init(&l->safe_cause, PX_FAULT_NONE);
	atomic_init(&l->safe_source, -1);
	atomic_init(&l->safe_cycle, 0);
	atomic_init(&l->cycles, 0);
	atomic_init(&l->overruns, 0);
	atomic_init(&l->missed, 0);
	atomic_init(&l->budget_exceeded, 0);
	atomic_init(&l->safe_entries, 0);
	atomic_init(&l->nfaults, 0);
	atomic_init(&l->rt_gen, 0);
	*out = l;
	return PX_OK;
}

void px_loop_free(struct px_loop *l)
{
	if (!l)
		return;
	if (l->thread_live) {
		px_loop_stop(l);
		px_loop_join(l);
	}
	px_arena_fini(&l->arena);
	free(l);
}

static void copy_name(char *dst, const char *src)
{
	size_t n = 0;
	if (src)
		while (n + 1 < NAME_LEN && src[n]) {
			dst[n] = src[n];
			n++;
		}
	dst[n] = '\0';
}

static int setup_check(struct px_loop *l)
{
	if (!l)
		return PX_E_INVAL;
	if (atomic_load(&l->running))
		return PX_E_STATE;
	return PX_OK;
}

int px_loop_input_add(struct px_loop *l, const char *name, int64_t timeout_ns)
{
	int rc = setup_check(l);
	struct input *in;

	if (rc)
		return rc;
	if (timeout_ns <= 0)
		return PX_E_INVAL;
	if (l->n_in >= l->cfg.max_inputs)
		return PX_E_NOSPC;
	in = &l->in[l->n_in];
	copy_name(in->name, name);
	in->timeout_ns = timeout_ns;
	in->last_ns = INT64_MIN;
	in->stale = 0;
	return (int)l->n_in++;
}

int px_loop_input_stamp(struct px_loop *l, int idx, int64_t t_ns)
{
	if (!l || idx < 0 || (size_t)idx >= l->n_in)
		return PX_E_INVAL;
	if (t_ns > l->in[idx].last_ns)
		l->in[idx].last_ns = t_ns;
	return PX_OK;
}

int px_loop_output_add(struct px_loop *l, const char *name, double *values,
		       size_t n)
{
	int rc = setup_check(l);
	struct output *o;

	if (rc)
		return rc;
	if (!values || n == 0)
		return PX_E_INVAL;
	if (l->n_out >= l->cfg.max_outputs)
		return PX_E_NOSPC;
	o = &l->out[l->n_out];
	copy_name(o->name, name);
	o->v = values;
	o->n = n;
	o->bad = 0;
	return (int)l->n_out++;
}

int px_loop_enable_add(struct px_loop *l, const char *name, int *flag)
{
	int rc = setup_check(l);

	if (rc)
		return rc;
	if (!flag)
		return PX_E_INVAL;
	if (l->n_en >= l->cfg.max_enables)
		return PX_E_NOSPC;
	copy_name(l->en[l->n_en].name, name);
	l->en[l->n_en].flag = flag;
	return (int)l->n_en++;
}

const char *px_loop_input_name(const struct px_loop *l, int idx)
{
	if (!l || idx < 0 || (size_t)idx >= l->n_in)
		return "";
	return l->in[idx].name;
}

const char *px_loop_output_name(const struct px_loop *l, int idx)
{
	if (!l || idx < 0 || (size_t)idx >= l->n_out)
		return "";
	return l->out[idx].name;
}

/* ---- clock -------------------------------------------------------------- */

int64_t px_loop_now_ns(const struct px_loop *l_)
{
	struct px_loop *l = (struct px_loop *)l_;
	if (!l)
		return 0;
	if (l->cfg.clock == PX_LOOP_CLOCK_VIRTUAL)
		return atomic_load_explicit(&l->vnow, memory_order_relaxed);
	return px__mono_ns();
}

int px_loop_vclock_advance(struct px_loop *l, int64_t ns)
{
	if (!l || ns < 0)
		return PX_E_INVAL;
	if (l->cfg.clock != PX_LOOP_CLOCK_VIRTUAL)
		return PX_E_STATE;
	ST(l->vnow, LD(l->vnow) + ns);
	return PX_OK;
}

static void sleep_until(struct px_loop *l, int64_t t)
{
	struct timespec ts;

	if (l->cfg.clock == PX_LOOP_CLOCK_VIRTUAL) {
		if (LD(l->vnow) < t)
			ST(l->vnow, t);
		return;
	}
	ts = px__ns_to_ts(t);
	/* A signal interrupts the sleep; the absolute deadline makes
	 * resuming it exact. */
	while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) ==
	       EINTR)
		;
}

/* ---- faults and safe state ---------------------------------------------- */

/*
 * A fault condition seen in this cycle. trip: it puts the loop in safe
 * state. record: push it to the fault ring even if the loop is already
 * safe (a new condition rather than one that persists).
 */
static void fault(struct px_loop *l, const struct px_loop_cycle *cy,
		  int cause, int source, int64_t detail, int trip, int record)
{
	struct px_fault f;
	int entered = 0;

	if (trip && !LD(l->safe)) {
		ST(l->safe_cause, cause);
		ST(l->safe_source, source);
		ST(l->safe_cycle, cy->index);
		INC(l->safe_entries);
		atomic_store_explicit(&l->safe, 1, memory_order_release);
		entered = 1;
	}
	if (trip)
		l->ok_cycles = 0;
	if (!entered && !record)
		return;
	memset(&f, 0, sizeof(f));
	f.cycle = cy->index;
	f.t_ns = px_loop_now_ns(l);
	f.cause = cause;
	f.source = source;
	f.detail = detail;
	f.safe = trip;
	INC(l->nfaults);
	px_ring_push(l->faults, &f);
}

static void requests(struct px_loop *l, const struct px_loop_cycle *cy)
{
	unsigned r;

	r = atomic_load_explicit(&l->reset_req, memory_order_acquire);
	if (r != l->reset_ack) {
		l->reset_ack = r;
		ST(l->overruns, 0);
		ST(l->missed, 0);
		ST(l->budget_exceeded, 0);
	}
	r = atomic_load_explicit(&l->rearm_req, memory_order_acquire);
	if (r != l->rearm_ack) {
		l->rearm_ack = r;
		l->latched = 0;
		l->consec_overruns = l->consec_budget = 0;
		ST(l->safe_cause, PX_FAULT_NONE);
		ST(l->safe_source, -1);
		atomic_store_explicit(&l->safe, 0, memory_order_release);
	}
	r = atomic_load_explicit(&l->trip_req, memory_order_acquire);
	if (r != l->trip_ack) {
		l->trip_ack = r;
		fault(l, cy, PX_FAULT_TRIP, -1, 0, 1, 1);
	}
	r = atomic_load_explicit(&l->estop_req, memory_order_acquire);
	if (r != l->estop_ack) {
		l->estop_ack = r;
		/* latched even when another cause holds safe state now */
		l->latched = 1;
		fault(l, cy, PX_FAULT_ESTOP, -1, 0, 1, 1);
	}
}

static int phase(struct px_loop *l, px_loop_phase_fn fn,
		 const struct px_loop_cycle *cy, int which, int *stop)
{
	int rc;

	if (!fn)
		return 0;
	rc = fn(l, cy, l->cfg.user);
	if (rc == PX_LOOP_STOP) {
		*stop = 1;
	} else if (rc < 0) {
		fault(l, cy, PX_FAULT_CALLBACK, which, rc, 1, 1);
		return 1;
	}
	return 0;
}

static int check_inputs(struct px_loop *l, const struct px_loop_cycle *cy)
{
	int64_t t = px_loop_now_ns(l);
	int any = 0;
	size_t i;

	for (i = 0; i < l->n_in; i++) {
		struct input *in = &l->in[i];
		int64_t age = t - in->last_ns;
		if (age > in->timeout_ns) {
			fault(l, cy, PX_FAULT_INPUT_STALE, (int)i, age, 1,
			      !in->stale);
			in->stale = 1;
			any = 1;
		} else {
			in->stale = 0;
		}
	}
	return any;
}

static int check_outputs(struct px_loop *l, const struct px_loop_cycle *cy)
{
	int any = 0;
	size_t i, j;

	for (i = 0; i < l->n_out; i++) {
		struct output *o = &l->out[i];
		for (j = 0; j < o->n; j++)
			if (!isfinite(o->v[j]))
				break;
		if (j < o->n) {
			fault(l, cy, PX_FAULT_OUTPUT_NONFINITE, (int)i,
			      (int64_t)j, 1, !o->bad);
			o->bad = 1;
			any = 1;
		} else {
			o->bad = 0;
		}
	}
	return any;
}

static void make_safe(struct px_loop *l)
{
	size_t i, j;

	for (i = 0; i < l->n_out; i++)
		for (j = 0; j < l->out[i].n; j++)
			l->out[i].v[j] = 0.0;
	for (i = 0; i < l->n_en; i++)
		*l->en[i].flag = 0;
}

/* ---- one cycle ------------------------------------------------------------ */

/*
 * A cycle is open -> read -> compute -> write, each piece run once, in
 * that order, by px_loop_step() (the loop's own deadline) or by the
 * caller's px_loop_read/compute/write (the caller's clock). Both run the
 * same pieces, so the watchdog decides the same way whoever drives.
 */

/* The caller's time on the virtual clock moves it forward, never back;
 * the phase starts at the loop clock (the real clock: at the caller's
 * now_ns, taken on CLOCK_MONOTONIC). */
static int64_t phase_start(struct px_loop *l, int64_t now_ns)
{
	if (l->cfg.clock == PX_LOOP_CLOCK_VIRTUAL) {
		sleep_until(l, now_ns);
		return LD(l->vnow);
	}
	return now_ns;
}

static void cycle_open(struct px_loop *l, int64_t wake_ns)
{
	struct px_loop_cycle *cy = &l->cy;
	size_t i;

	memset(cy, 0, sizeof(*cy));
	cy->index = l->index;
	cy->period_ns = l->cfg.period_ns;
	cy->deadline_ns = l->next_deadline;
	cy->missed = l->pending_missed;
	cy->wake_ns = wake_ns;
	px_stats_record(l->st[PX_LOOP_STAT_LATENCY],
			cy->wake_ns - cy->deadline_ns);
	if (!l->started) {
		/* Inputs never stamped count from the first wake-up. */
		for (i = 0; i < l->n_in; i++)
			if (l->in[i].last_ns == INT64_MIN)
				l->in[i].last_ns = cy->wake_ns;
		l->started = 1;
	}
	l->cy_stop = l->cy_bad = 0;
	requests(l, cy);
}

static void cycle_read(struct px_loop *l, int64_t t_ns)
{
	struct px_loop_cycle *cy = &l->cy;

	cy->safe = LD(l->safe);
	cy->read_ns = t_ns;
	l->cy_bad |= phase(l, l->cfg.read, cy, 0, &l->cy_stop);
	l->cy_bad |= check_inputs(l, cy);
	l->stage = STAGE_READ;
}

static void cycle_compute(struct px_loop *l, int64_t t_ns)
{
	struct px_loop_cycle *cy = &l->cy;
	int64_t ct;

	cy->safe = LD(l->safe);
	cy->compute_ns = t_ns;
	l->cy_bad |= phase(l, l->cfg.compute, cy, 1, &l->cy_stop);
	cy->compute_end_ns = px_loop_now_ns(l);
	ct = cy->compute_end_ns - cy->compute_ns;
	px_stats_record(l->st[PX_LOOP_STAT_COMPUTE], ct);
	if (ct > l->cfg.compute_budget_ns) {
		INC(l->budget_exceeded);
		l->consec_budget++;
		if (l->cfg.budget_limit &&
		    l->consec_budget >= l->cfg.budget_limit) {
			fault(l, cy, PX_FAULT_COMPUTE_BUDGET, -1, ct, 1,
			      l->consec_budget == l->cfg.budget_limit);
			l->cy_bad = 1;
		}
	} else {
		l->consec_budget = 0;
	}
	l->cy_bad |= check_outputs(l, cy);
	l->stage = STAGE_COMPUTE;
}

/* The write phase and the cycle's bookkeeping (overruns, the next
 * deadline, automatic re-arm). */
static int cycle_write(struct px_loop *l, int64_t t_ns)
{
	struct px_loop_cycle *cy = &l->cy;
	const int64_t P = l->cfg.period_ns;
	int64_t end, next;
	int bad;

	/* The same cycle that saw a fault writes only zeros. */
	cy->safe = LD(l->safe);
	if (cy->safe)
		make_safe(l);
	cy->write_ns = t_ns;
	l->cy_bad |= phase(l, l->cfg.write, cy, 2, &l->cy_stop);
	bad = l->cy_bad;

	end = px_loop_now_ns(l);
	px_stats_record(l->st[PX_LOOP_STAT_CYCLE], end - cy->wake_ns);
	next = cy->deadline_ns + P;
	l->pending_missed = 0;
	if (end > next) {
		/* Deadlines D + jP (j >= 1) already past at the end. */
		int64_t k = (end - cy->deadline_ns - 1) / P;
		int64_t skip = k;
		int trip;

		if (l->cfg.overrun == PX_LOOP_OVERRUN_CATCH_UP)
			skip = k > (int64_t)l->cfg.max_catch_up
				       ? k - (int64_t)l->cfg.max_catch_up
				       : 0;
		next = cy->deadline_ns + (skip + 1) * P;
		l->pending_missed = (uint32_t)(skip > UINT32_MAX ? UINT32_MAX
								  : skip);
		ST(l->missed, LD(l->missed) + (uint64_t)skip);
		INC(l->overruns);
		l->consec_overruns++;
		trip = l->cfg.overrun_limit &&
		       l->consec_overruns >= l->cfg.overrun_limit;
		fault(l, cy, PX_FAULT_OVERRUN, -1, k, trip, 1);
		bad |= trip;
	} else {
		l->consec_overruns = 0;
	}
	l->next_deadline = next;

	/* Automatic re-arm ends safe state after quiet cycles, never one
	 * an e-stop entered or joined: releasing an emergency stop must
	 * not restart motion (ISO 13850); the reset is px_loop_rearm(). */
	if (l->cfg.rearm_after_ok_cycles && LD(l->safe) && !l->latched) {
		if (bad) {
			l->ok_cycles = 0;
		} else if (++l->ok_cycles >= l->cfg.rearm_after_ok_cycles) {
			l->ok_cycles = 0;
			ST(l->safe_cause, PX_FAULT_NONE);
			ST(l->safe_source, -1);
			atomic_store_explicit(&l->safe, 0,
					      memory_order_release);
		}
	}
	l->index++;
	INC(l->cycles);
	l->stage = STAGE_IDLE;
	return l->cy_stop ? PX_LOOP_STOP : PX_OK;
}

static int cycle(struct px_loop *l)
{
	if (!l->started) {
		l->next_deadline = px_loop_now_ns(l) + l->cfg.period_ns;
		l->pending_missed = 0;
	}
	sleep_until(l, l->next_deadline);
	cycle_open(l, px_loop_now_ns(l));
	cycle_read(l, px_loop_now_ns(l));
	cycle_compute(l, px_loop_now_ns(l));
	return cycle_write(l, px_loop_now_ns(l));
}

int px_loop_step(struct px_loop *l)
{
	if (!l)
		return PX_E_INVAL;
	if (atomic_load(&l->running) || l->stage != STAGE_IDLE)
		return PX_E_STATE;
	return cycle(l);
}

/* The caller's phase calls: not while px_loop_run() owns the loop, and
 * only the phase that comes next in the open cycle. */
static int phase_check(struct px_loop *l, int stage)
{
	if (!l)
		return PX_E_INVAL;
	if (atomic_load_explicit(&l->running, memory_order_relaxed) ||
	    l->stage != stage)
		return PX_E_STATE;
	return PX_OK;
}

int px_loop_read(struct px_loop *l, int64_t now_ns)
{
	int64_t t;
	int rc = phase_check(l, STAGE_IDLE);

	if (rc)
		return rc;
	t = phase_start(l, now_ns);
	/* The caller's clock wakes the cycle: one due later than that (a
	 * caller faster than the period, or the first cycle) is taken as
	 * due now, so the latency is never negative. */
	if (!l->started || t < l->next_deadline) {
		l->next_deadline = t;
		l->pending_missed = 0;
	}
	cycle_open(l, t);
	cycle_read(l, t);
	return l->cy_stop ? PX_LOOP_STOP : PX_OK;
}

int px_loop_compute(struct px_loop *l, int64_t now_ns)
{
	int rc = phase_check(l, STAGE_READ);

	if (rc)
		return rc;
	cycle_compute(l, phase_start(l, now_ns));
	return l->cy_stop ? PX_LOOP_STOP : PX_OK;
}

int px_loop_write(struct px_loop *l, int64_t now_ns)
{
	int rc = phase_check(l, STAGE_COMPUTE);

	if (rc)
		return rc;
	return cycle_write(l, phase_start(l, now_ns));
}

/* Status readers copy l->rt while the generation is even and unchanged
 * (a seqlock: the report is written at most twice per run). */
static void publish_rt(struct px_loop *l, const struct px_rt_report *rep)
{
	unsigned g = atomic_load_explicit(&l->rt_gen, memory_order_relaxed);
	atomic_store_explicit(&l->rt_gen, g + 1, memory_order_relaxed);
	atomic_thread_fence(memory_order_release);
	l->rt = *rep;
	l->rt_applied = 1;
	atomic_store_explicit(&l->rt_gen, g + 2, memory_order_release);
}

int px_loop_run(struct px_loop *l, uint64_t max_cycles)
{
	uint64_t n = 0;
	int expected = 0;

	if (!l)
		return PX_E_INVAL;
	if (l->stage != STAGE_IDLE ||
	    !atomic_compare_exchange_strong(&l->running, &expected, 1))
		return PX_E_STATE;
	if (l->cfg.rt_enable) {
		struct px_rt_report rep;
		/* Refusal is not an error here: the warning went out once,
		 * the report shows it, and the loop runs degraded. */
		(void)px_rt_apply(&l->cfg.rt, &rep);
		publish_rt(l, &rep);
	}
	/* Fresh deadlines: a run never tries to catch up on the time
	 * between runs. */
	l->started = 0;
	while (!atomic_load_explicit(&l->stop_req, memory_order_acquire) &&
	       (max_cycles == 0 || n < max_cycles)) {
		n++;
		if (cycle(l) == PX_LOOP_STOP)
			break;
	}
	atomic_store(&l->stop_req, 0);
	if (l->cfg.rt_enable) {
		/* The status keeps what was in force during the run. */
		struct px_rt_report undo = l->rt, kept = l->rt;
		px_rt_restore(&undo);
		kept.dma_latency_fd = -1;
		publish_rt(l, &kept);
	}
	atomic_store(&l->running, 0);
	return PX_OK;
}

static void *thread_main(void *arg)
{
	struct px_loop *l = arg;
	l->thread_rc = px_loop_run(l, l->thread_max);
	return NULL;
}

int px_loop_start(struct px_loop *l, uint64_t max_cycles)
{
	if (!l)
		return PX_E_INVAL;
	if (l->thread_live || atomic_load(&l->running) ||
	    l->stage != STAGE_IDLE)
		return PX_E_STATE;
	l->thread_max = max_cycles;
	l->thread_rc = PX_OK;
	if (pthread_create(&l->thread, NULL, thread_main, l) != 0)
		return PX_E_NOMEM;
	l->thread_live = 1;
	return PX_OK;
}

int px_loop_join(struct px_loop *l)
{
	if (!l)
		return PX_E_INVAL;
	if (!l->thread_live)
		return PX_E_STATE;
	pthread_join(l->thread, NULL);
	l->thread_live = 0;
	return l->thread_rc;
}

void px_loop_stop(struct px_loop *l)
{
	if (l)
		atomic_store_explicit(&l->stop_req, 1, memory_order_release);
}

void px_loop_trip(struct px_loop *l)
{
	if (l)
		atomic_fetch_add_explicit(&l->trip_req, 1,
					  memory_order_release);
}

void px_loop_trip_estop(struct px_loop *l)
{
	if (l)
		atomic_fetch_add_explicit(&l->estop_req, 1,
					  memory_order_release);
}

void px_loop_rearm(struct px_loop *l)
{
	if (l)
		atomic_fetch_add_explicit(&l->rearm_req, 1,
					  memory_order_release);
}

int px_loop_is_safe(const struct px_loop *l)
{
	return l ? atomic_load_explicit(&((struct px_loop *)l)->safe,
					memory_order_acquire)
		 : 0;
}

int px_loop_status(const struct px_loop *l_, struct px_loop_status *s)
{
	struct px_loop *l = (struct px_loop *)l_;
	int tries;

	if (!l || !s)
		return PX_E_INVAL;
	memset(s, 0, sizeof(*s));
	s->running = atomic_load(&l->running);
	s->safe = atomic_load_explicit(&l->safe, memory_order_acquire);
	s->safe_cause = LD(l->safe_cause);
	s->safe_source = LD(l->safe_source);
	s->safe_cycle = LD(l->safe_cycle);
	s->cycles = LD(l->cycles);
	s->overruns = LD(l->overruns);
	s->missed_periods = LD(l->missed);
	s->budget_exceeded = LD(l->budget_exceeded);
	s->safe_entries = LD(l->safe_entries);
	s->faults = LD(l->nfaults);
	s->faults_dropped = px_ring_dropped(l->faults);
	s->period_ns = l->cfg.period_ns;
	for (tries = 0; tries < 1000; tries++) {
		unsigned g = atomic_load_explicit(&l->rt_gen,
						  memory_order_acquire);
		if (g & 1u) {
			px__cpu_relax();
			continue;
		}
		s->rt_applied = l->rt_applied;
		s->rt = l->rt;
		atomic_thread_fence(memory_order_acquire);
		if (atomic_load_explicit(&l->rt_gen, memory_order_relaxed) == g)
			break;
	}
	s->realtime = s->rt_applied && (s->rt.granted & PX_RT_SCHED) != 0;
	return PX_OK;
}

int px_loop_stats(const struct px_loop *l, enum px_loop_stat which,
		  struct px_stats_snapshot *out)
{
	if (!l || (unsigned)which >= PX_LOOP_STAT__COUNT || !out)
		return PX_E_INVAL;
	return px_stats_read(l->st[which], out);
}

struct px_stats *px_loop_stats_handle(struct px_loop *l,
				      enum px_loop_stat which)
{
	if (!l || (unsigned)which >= PX_LOOP_STAT__COUNT)
		return NULL;
	return l->st[which];
}

void px_loop_stats_reset(struct px_loop *l)
{
	int i;

	if (!l)
		return;
	if (atomic_load(&l->running)) {
		for (i = 0; i < PX_LOOP_STAT__COUNT; i++)
			px_stats_reset_request(l->st[i]);
		atomic_fetch_add_explicit(&l->reset_req, 1,
					  memory_order_release);
		return;
	}
	for (i = 0; i < PX_LOOP_STAT__COUNT; i++)
		px_stats_reset(l->st[i]);
	ST(l->overruns, 0);
	ST(l->missed, 0);
	ST(l->budget_exceeded, 0);
}

int px_loop_fault_pop(struct px_loop *l, struct px_fault *out)
{
	if (!l || !out)
		return PX_E_INVAL;
	return px_ring_pop(l->faults, out);
}
