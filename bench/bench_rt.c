/*
 * bench_rt - the real-time loop against cyclictest, on this machine, in
 * this run.
 *
 * Wake-up latency at 1 kHz with real deadlines: proxima's loop (SCHED_FIFO,
 * mlockall, /dev/cpu_dma_latency held at 0, empty phases) and cyclictest
 * (rt-tests; same priority, interval, mlockall and dma latency, which it
 * holds at 0 by default) run alternately in chunks so that both see the
 * same machine load. Both histograms have 1 us bins and are summarised
 * by the same function (px_stats_hist_quantile), so the percentiles are
 * computed identically.
 *
 * Then the cost of the lock-free pieces: one ring push, one statistics
 * record, one statistics read, one virtual-clock cycle.
 *
 * Environment: PX_BENCH_RT_SECONDS (default 10, per side),
 * PX_BENCH_RT_PRIO (default 80), PX_BENCH_RT_CYCLICTEST (program path).
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "px_arena.h"
#include "px_loop.h"
#include "px_ring.h"
#include "px_stats.h"

#include "bench_util.h"

#define NBINS 5000 /* 1 us bins up to 5 ms */
#define PERIOD_NS 1000000

struct hist {
	uint64_t bins[NBINS];
	uint64_t overflow;
	int64_t min_ns, max_ns;
	uint64_t n;
};

static void hist_init(struct hist *h)
{
	memset(h, 0, sizeof(*h));
	h->min_ns = INT64_MAX;
	h->max_ns = INT64_MIN;
}

/* ---- cyclictest ---------------------------------------------------------- */

static int find_cyclictest(char *path, size_t n)
{
	const char *env = getenv("PX_BENCH_RT_CYCLICTEST");
	FILE *p;

	if (env && *env) {
		snprintf(path, n, "%s", env);
		return 1;
	}
	p = popen("command -v cyclictest 2>/dev/null", "r");
	if (!p)
		return 0;
	if (!fgets(path, (int)n, p))
		path[0] = '\0';
	pclose(p);
	path[strcspn(path, "\n")] = '\0';
	return path[0] != '\0';
}

/* Run cyclictest for `loops` cycles and add its histogram to h.
 * Returns 0 on success. */
static int run_cyclictest(const char *prog, int prio, long loops,
			  struct hist *h)
{
	char cmd[512], line[256];
	FILE *p;
	long bin, cnt, v;
	int got = 0, status;

	snprintf(cmd, sizeof(cmd),
		 "'%s' -q -m -p %d --policy=fifo -i %d -l %ld -h %d 2>&1", prog,
		 prio, PERIOD_NS / 1000, loops, NBINS);
	p = popen(cmd, "r");
	if (!p)
		return -1;
	while (fgets(line, sizeof(line), p)) {
		if (line[0] != '#' && sscanf(line, "%ld %ld", &bin, &cnt) == 2) {
			if (bin >= 0 && bin < NBINS && cnt > 0) {
				h->bins[bin] += (uint64_t)cnt;
				h->n += (uint64_t)cnt;
			}
			got = 1;
		} else if (sscanf(line, "# Histogram Overflows: %ld", &v) == 1) {
			h->overflow += (uint64_t)v;
			h->n += (uint64_t)v;
		} else if (sscanf(line, "# Max Latencies: %ld", &v) == 1) {
			if (v * 1000 > h->max_ns)
				h->max_ns = v * 1000;
		} else if (sscanf(line, "# Min Latencies: %ld", &v) == 1) {
			if (v * 1000 < h->min_ns)
				h->min_ns = v * 1000;
		} else if (line[0] != '#' && strspn(line, " \t\r\n") < strlen(line)) {
			fprintf(stderr, "cyclictest: %s", line);
		}
	}
	status = pclose(p);
	return got && status == 0 ? 0 : -1;
}

/* ---- proxima's loop -------------------------------------------------------- */

/* Each chunk sets the loop up again; show a refusal warning only once. */
static void warn_once(void *ctx, const char *msg)
{
	static int shown;
	(void)ctx;
	if (!shown++)
		fprintf(stderr, "%s\n", msg);
}

static int run_loop(int prio, long loops, struct hist *h,
		    struct px_loop_status *st_out)
{
	static uint64_t bins[NBINS];
	struct px_loop_config cfg;
	struct px_loop *l;
	struct px_stats_snapshot sn;
	uint64_t ov = 0;
	int i, rc;

	px_loop_config_default(&cfg);
	cfg.period_ns = PERIOD_NS;
	cfg.hist_bins = NBINS;
	cfg.hist_bin_ns = 1000;
	cfg.overrun_limit = 0;
	cfg.budget_limit = 0;
	cfg.rt_enable = 1;
	cfg.rt.priority = prio;
	cfg.rt.lock_memory = 1;
	cfg.rt.dma_latency = 1;
	cfg.rt.warn = warn_once;
	rc = px_loop_create(&cfg, &l);
	if (rc)
		return rc;
	rc = px_loop_start(l, (uint64_t)loops);
	if (rc == PX_OK)
		rc = px_loop_join(l);
	if (rc == PX_OK)
		rc = px_stats_copy_bins(px_loop_stats_handle(l,
						PX_LOOP_STAT_LATENCY),
					bins, NBINS, &ov) < 0;
	if (rc == PX_OK &&
	    px_loop_stats(l, PX_LOOP_STAT_LATENCY, &sn) == PX_OK) {
		for (i = 0; i < NBINS; i++)
			h->bins[i] += bins[i];
		h->overflow += ov;
		h->n += sn.count;
		if (sn.min_ns < h->min_ns)
			h->min_ns = sn.min_ns;
		if (sn.max_ns > h->max_ns)
			h->max_ns = sn.max_ns;
	}
	px_loop_status(l, st_out);
	px_loop_free(l);
	return rc;
}

static void summary(const struct hist *h, int64_t out[4])
{
	out[0] = px_stats_hist_quantile(h->bins, NBINS, h->overflow, 1000,
					h->max_ns, 0.50);
	out[1] = px_stats_hist_quantile(h->bins, NBINS, h->overflow, 1000,
					h->max_ns, 0.99);
	out[2] = px_stats_hist_quantile(h->bins, NBINS, h->overflow, 1000,
					h->max_ns, 0.999);
	out[3] = h->max_ns;
}

static void print_row(const char *name, const struct hist *h)
{
	int64_t q[4];
	summary(h, q);
	printf("  %-12s %8llu %8.0f %8.0f %8.0f %8.0f %8.0f\n", name,
	       (unsigned long long)h->n, h->n ? h->min_ns / 1e3 : 0.0,
	       q[0] / 1e3, q[1] / 1e3, q[2] / 1e3, q[3] / 1e3);
}

static void ratio(const char *label, int64_t ours, int64_t theirs)
{
	/* Values are whole microseconds (bin lower edges): a ratio of two
	 * zeros means equal, a zero denominator is reported as such. */
	if (theirs == 0)
		printf("  %-6s %s\n", label, ours == 0 ? "1.00" : "n/a (cyclictest 0 us)");
	else
		printf("  %-6s %.2f\n", label, (double)ours / (double)theirs);
}

static void latency_bench(void)
{
	static struct hist ours, theirs;
	struct px_loop_status st;
	char prog[256];
	long secs = bench_env_long("bench_rt", "PX_BENCH_RT_SECONDS", 10, 1,
				   86400);
	int prio = (int)bench_env_long("bench_rt", "PX_BENCH_RT_PRIO", 80, 1,
				       99);
	long chunks = secs, c, done = 0; /* 1 s chunks: both see the same load */
	int have_ct = find_cyclictest(prog, sizeof(prog)), ct_ok = have_ct;
	int64_t qo[4], qt[4];

	hist_init(&ours);
	hist_init(&theirs);
	memset(&st, 0, sizeof(st));
	printf("wake-up latency at 1 kHz, SCHED_FIFO %d, %ld s per side in %ld "
	       "alternating chunks\n", prio, secs, chunks);
	if (!have_ct)
		printf("  cyclictest not found (Debian package rt-tests): "
		       "showing proxima only\n");
	for (c = 0; c < chunks; c++) {
		long loops = (secs * 1000 - done) / (chunks - c);
		done += loops;
		if (ct_ok && run_cyclictest(prog, prio, loops, &theirs) != 0) {
			printf("  cyclictest failed (see its messages above): "
			       "showing proxima only\n");
			ct_ok = 0;
		}
		if (run_loop(prio, loops, &ours, &st) != PX_OK) {
			printf("  proxima loop failed\n");
			return;
		}
	}
	printf("  proxima loop ran on %s%s%s\n",
	       px_rt_policy_name(st.rt.policy),
	       st.realtime ? "" : " (real-time setup refused: ",
	       st.realtime ? "" : "see the warning above)");
	printf("  %-12s %8s %8s %8s %8s %8s %8s   (us)\n", "", "samples", "min",
	       "p50", "p99", "p99.9", "max");
	if (ct_ok)
		print_row("cyclictest", &theirs);
	print_row("proxima", &ours);
	if (!ct_ok)
		return;
	summary(&ours, qo);
	summary(&theirs, qt);
	printf("  ratio proxima / cyclictest:\n");
	ratio("p50", qo[0], qt[0]);
	ratio("p99", qo[1], qt[1]);
	ratio("p99.9", qo[2], qt[2]);
	ratio("max", qo[3], qt[3]);
	printf("  target p99 <= 1.2 x cyclictest p99 (+1 us bin): %s\n",
	       qo[1] <= (int64_t)(1.2 * (double)qt[1]) + 1000 ? "met"
							     : "NOT met");
}

/* ---- costs of the lock-free pieces ------------------------------------------ */

static void cost_bench(void)
{
	static unsigned char mem[4 << 20];
	struct px_arena a;
	struct px_ring *r;
	struct px_stats *s;
	struct px_stats_snapshot sn;
	unsigned char rec[64], out[64];
	const int cap = 4096, rounds = 1000;
	int64_t t0, t_push = 0, t_drop;
	double x = 0;
	int i, j;

	memset(rec, 1, sizeof(rec));
	px_arena_init(&a, mem, sizeof(mem));
	if (px_ring_create(&a, (size_t)cap, sizeof(rec), &r) ||
	    px_stats_create(&a, NBINS, 1000, &s)) {
		printf("setup failed\n");
		return;
	}
	printf("cost of one operation (ns, single thread):\n");
	for (j = 0; j < rounds; j++) {
		t0 = now_ns();
		for (i = 0; i < cap; i++)
			px_ring_push(r, rec);
		t_push += now_ns() - t0;
		for (i = 0; i < cap; i++)
			px_ring_pop(r, out);
	}
	printf("  ring push, 64-byte record       %6.1f   (target <= 100)\n",
	       (double)t_push / ((double)cap * rounds));
	for (i = 0; i < cap; i++)
		px_ring_push(r, rec);
	t0 = now_ns();
	for (i = 0; i < cap * 100; i++)
		px_ring_push(r, rec);
	t_drop = now_ns() - t0;
	printf("  ring push when full (drop)      %6.1f\n",
	       (double)t_drop / ((double)cap * 100));

	t0 = now_ns();
	for (i = 0; i < 10000000; i++)
		px_stats_record(s, 8000 + (i & 63) * 250);
	printf("  statistics record               %6.1f\n",
	       (double)(now_ns() - t0) / 1e7);
	t0 = now_ns();
	for (i = 0; i < 100000; i++) {
		px_stats_read(s, &sn);
		x += (double)sn.p99_ns;
	}
	printf("  statistics read, 17 bins in use %6.1f\n",
	       (double)(now_ns() - t0) / 1e5);
	/* Worst case: every bin in use and p99.9 near the top. */
	px_stats_reset(s);
	for (j = 0; j < 4; j++)
		for (i = 0; i < NBINS; i++)
			px_stats_record(s, (int64_t)i * 1000);
	t0 = now_ns();
	for (i = 0; i < 10000; i++) {
		px_stats_read(s, &sn);
		x += (double)sn.p99_ns;
	}
	printf("  statistics read, %d bins in use %6.1f\n", NBINS,
	       (double)(now_ns() - t0) / 1e4);

	{
		struct px_loop_config cfg;
		struct px_loop *l;
		px_loop_config_default(&cfg);
		cfg.clock = PX_LOOP_CLOCK_VIRTUAL;
		if (px_loop_create(&cfg, &l) == PX_OK) {
			t0 = now_ns();
			px_loop_run(l, 1000000);
			printf("  one loop cycle, virtual clock   %6.1f\n",
			       (double)(now_ns() - t0) / 1e6);
			px_loop_free(l);
		}
	}
	if (x < 0)
		printf("%f\n", x);
}

int main(void)
{
	setvbuf(stdout, NULL, _IOLBF, 0);
	cost_bench();
	latency_bench();
	return 0;
}
