/* Lock-free pieces of rt/: statistics, SPSC ring, parameter triple
 * buffer, fault names. Concurrency tests use a second thread; checks
 * that run there only record what they saw, the main thread asserts. */
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "px_alloc_count.h"
#include "px_arena.h"
#include "px_fault.h"
#include "px_param.h"
#include "px_ring.h"
#include "px_stats.h"
#include "px_test.h"

static int cmp_i64(const void *a, const void *b)
{
	int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
	return (x > y) - (x < y);
}

/* Reference quantile: sort, take rank ceil(q n), floor to its bin. */
static int64_t ref_quantile(const int64_t *sorted, size_t n, double q,
			    int64_t bin_ns, size_t nbins)
{
	size_t rank = (size_t)ceil(q * (double)n - 1e-9);
	int64_t v;
	if (rank < 1)
		rank = 1;
	v = sorted[rank - 1];
	if (v < 0)
		v = 0;
	if (v >= (int64_t)nbins * bin_ns)
		return sorted[n - 1];
	return v / bin_ns * bin_ns;
}

static void test_stats_against_sorting(void)
{
	static unsigned char mem[1 << 16];
	struct px_arena a;
	struct px_stats *s;
	struct px_stats_snapshot sn;
	enum { N = 3001 };
	static int64_t v[N], sorted[N];
	uint64_t bins[500], ov = 0, r;
	int64_t sum = 0;
	int round, i;

	for (round = 0; round < 4; round++) {
		size_t nbins = (size_t)px_rand_int(1, 400);
		int64_t bin = px_rand_int(1, 2000);
		int n = px_rand_int(1, N);

		PX_CHECK_INT_EQ(px_arena_init(&a, mem, sizeof(mem)), PX_OK);
		PX_CHECK_INT_EQ(px_stats_create(&a, nbins, bin, &s), PX_OK);
		sum = 0;
		r = px_alloc_region_begin();
		for (i = 0; i < n; i++) {
			/* Mostly in range, some negative, some overflow. */
			double u = px_rand_unit();
			v[i] = u < 0.05   ? -px_rand_int(0, 5000)
			       : u < 0.9 ? (int64_t)(px_rand_unit() *
						     (double)nbins * (double)bin)
					 : (int64_t)nbins * bin +
						   px_rand_int(0, 100000);
			px_stats_record(s, v[i]);
			sum += v[i];
		}
		PX_CHECK_INT_EQ(px_stats_read(s, &sn), PX_OK);
		PX_CHECK_INT_EQ(px_alloc_region_end(r), 0);
		memcpy(sorted, v, sizeof(v[0]) * (size_t)n);
		qsort(sorted, (size_t)n, sizeof(sorted[0]), cmp_i64);
		PX_CHECK_INT_EQ(sn.count, n);
		PX_CHECK_INT_EQ(sn.min_ns, sorted[0]);
		PX_CHECK_INT_EQ(sn.max_ns, sorted[n - 1]);
		PX_CHECK_INT_EQ(sn.mean_ns, sum / n);
		PX_CHECK_INT_EQ(sn.p50_ns,
				ref_quantile(sorted, (size_t)n, 0.5, bin, nbins));
		PX_CHECK_INT_EQ(sn.p99_ns,
				ref_quantile(sorted, (size_t)n, 0.99, bin, nbins));
		PX_CHECK_INT_EQ(sn.p999_ns, ref_quantile(sorted, (size_t)n,
							 0.999, bin, nbins));
		/* The histogram copy accounts for every sample, and the
		 * shared quantile function agrees with the snapshot. */
		{
			size_t cap = nbins < 500 ? nbins : 500;
			uint64_t tot = 0;
			size_t k;
			PX_CHECK_INT_EQ(px_stats_copy_bins(s, bins, cap, &ov),
					(int)cap);
			for (k = 0; k < cap; k++)
				tot += bins[k];
			PX_CHECK_INT_EQ(tot + ov, n);
			PX_CHECK_INT_EQ(px_stats_hist_quantile(bins, cap, ov,
							       bin, sn.max_ns,
							       0.99),
					sn.p99_ns);
		}
	}
	/* Reset by request is applied by the writer's next record. */
	px_stats_reset_request(s);
	PX_CHECK_INT_EQ(px_stats_read(s, &sn), PX_OK);
	PX_CHECK(sn.count > 0);
	px_stats_record(s, 7);
	PX_CHECK_INT_EQ(px_stats_read(s, &sn), PX_OK);
	PX_CHECK_INT_EQ(sn.count, 1);
	PX_CHECK_INT_EQ(sn.min_ns, 7);
	PX_CHECK_INT_EQ(sn.max_ns, 7);
	PX_CHECK_INT_EQ(sn.p999_ns, 0);
	px_stats_reset(s);
	PX_CHECK_INT_EQ(px_stats_read(s, &sn), PX_OK);
	PX_CHECK_INT_EQ(sn.count, 0);
	PX_CHECK_INT_EQ(sn.max_ns, 0);
}

static void test_stats_bad_args(void)
{
	static unsigned char mem[256];
	struct px_arena a;
	struct px_stats *s = NULL;
	struct px_stats_snapshot sn;

	PX_CHECK_INT_EQ(px_arena_init(&a, mem, sizeof(mem)), PX_OK);
	PX_CHECK_INT_EQ(px_stats_create(&a, 0, 0, &s), PX_E_NOSPC);
	PX_CHECK(s == NULL);
	PX_CHECK_INT_EQ(px_stats_create(&a, 4, -1, &s), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_stats_create(NULL, 4, 1, &s), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_stats_read(NULL, &sn), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_stats_copy_bins(NULL, NULL, 0, NULL), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_stats_hist_quantile(NULL, 0, 0, 1, 0, 0.5), 0);
	px_stats_reset(NULL);
	px_stats_reset_request(NULL);
}

/* Writer records a ramp over 1000 bins; every snapshot a reader takes
 * must equal the exact statistics of some prefix of that ramp. */
#define RAMP 1000
struct stats_race {
	struct px_stats *s;
	atomic_int started, stop;
	long n;
};

static void *ramp_writer(void *arg)
{
	struct stats_race *sr = arg;
	long i;
	atomic_store(&sr->started, 1);
	for (i = 0; !atomic_load_explicit(&sr->stop, memory_order_relaxed);
	     i++) {
		volatile int k;
		px_stats_record(sr->s, (int64_t)(i % RAMP) * 1000 + 500);
		/* A real writer records once per period; a pause of a few
		 * microseconds lets readers finish most attempts. */
		for (k = 0; k < 300; k++)
			;
	}
	sr->n = i;
	return NULL;
}

static int64_t ramp_quantile(uint64_t n, double q)
{
	uint64_t rank = (uint64_t)ceil(q * (double)n - 1e-9), c = n / RAMP,
		 r = n % RAMP, cum = 0;
	int j;
	if (rank < 1)
		rank = 1;
	for (j = 0; j < RAMP; j++) {
		cum += c + ((uint64_t)j < r);
		if (cum >= rank)
			return (int64_t)j * 1000;
	}
	return -1;
}

static void test_stats_snapshots_never_torn(void)
{
	static unsigned char mem[1 << 16];
	struct px_arena a;
	struct stats_race sr;
	pthread_t th;
	long reads = 0, bad = 0, again = 0;
	struct px_stats_snapshot sn, bad_sn;

	memset(&bad_sn, 0, sizeof(bad_sn));
	PX_CHECK_INT_EQ(px_arena_init(&a, mem, sizeof(mem)), PX_OK);
	PX_CHECK_INT_EQ(px_stats_create(&a, 2 * RAMP, 1000, &sr.s), PX_OK);
	atomic_init(&sr.started, 0);
	atomic_init(&sr.stop, 0);
	sr.n = 0;
	PX_CHECK_INT_EQ(pthread_create(&th, NULL, ramp_writer, &sr), 0);
	while (!atomic_load(&sr.started))
		sched_yield();
	/* Readers race the writer for a fixed number of snapshots. */
	while (reads < 3000) {
		uint64_t n, full;
		int64_t sum;
		int rc = px_stats_read(sr.s, &sn);
		if (rc == PX_E_AGAIN) {
			again++;
			continue;
		}
		reads++;
		n = sn.count;
		if (n == 0)
			continue;
		full = n / RAMP;
		/* sum of (j*1000+500) over the prefix */
		sum = (int64_t)full * (RAMP * (int64_t)(RAMP - 1) / 2 * 1000 +
				       500 * RAMP);
		{
			int64_t r = (int64_t)(n % RAMP);
			sum += r * (r - 1) / 2 * 1000 + 500 * r;
		}
		if (sn.min_ns != 500 || sn.overflow != 0 ||
		    sn.max_ns != (n >= RAMP ? (RAMP - 1) * 1000 + 500
					    : (int64_t)(n - 1) * 1000 + 500) ||
		    sn.mean_ns != sum / (int64_t)n ||
		    sn.p50_ns != ramp_quantile(n, 0.5) ||
		    sn.p99_ns != ramp_quantile(n, 0.99) ||
		    sn.p999_ns != ramp_quantile(n, 0.999)) {
			if (!bad)
				bad_sn = sn;
			bad++;
		}
	}
	atomic_store(&sr.stop, 1);
	pthread_join(th, NULL);
	PX_CHECK_MSG(bad == 0,
		     "%ld of %ld snapshots torn; first: count %llu max %lld "
		     "p50 %lld",
		     bad, reads, (unsigned long long)bad_sn.count,
		     (long long)bad_sn.max_ns, (long long)bad_sn.p50_ns);
	PX_CHECK(reads > 0);
	PX_CHECK_INT_EQ(px_stats_read(sr.s, &sn), PX_OK);
	PX_CHECK_INT_EQ(sn.count, sr.n);
	(void)again;
}

static void test_ring_sequential(void)
{
	static unsigned char mem[4096];
	struct px_arena a;
	struct px_ring *r;
	uint32_t x, y;
	uint64_t reg;
	int i;

	PX_CHECK_INT_EQ(px_arena_init(&a, mem, sizeof(mem)), PX_OK);
	PX_CHECK_INT_EQ(px_ring_create(&a, 5, sizeof(x), &r), PX_OK);
	PX_CHECK_INT_EQ(px_ring_capacity(r), 8);
	PX_CHECK_INT_EQ(px_ring_record_size(r), 4);
	PX_CHECK_INT_EQ(px_ring_pop(r, &y), PX_E_AGAIN);
	reg = px_alloc_region_begin();
	for (x = 0; x < 8; x++)
		PX_CHECK_INT_EQ(px_ring_push(r, &x), PX_OK);
	PX_CHECK_INT_EQ(px_ring_count(r), 8);
	/* Full: the newest is dropped and counted. */
	x = 100;
	PX_CHECK_INT_EQ(px_ring_push(r, &x), PX_E_NOSPC);
	PX_CHECK_INT_EQ(px_ring_push(r, &x), PX_E_NOSPC);
	PX_CHECK_INT_EQ(px_ring_dropped(r), 2);
	PX_CHECK_INT_EQ(px_ring_pushed(r), 8);
	for (i = 0; i < 8; i++) {
		PX_CHECK_INT_EQ(px_ring_pop(r, &y), PX_OK);
		PX_CHECK_INT_EQ(y, i);
	}
	PX_CHECK_INT_EQ(px_ring_pop(r, &y), PX_E_AGAIN);
	/* Wrap around many times. */
	for (x = 0; x < 1000; x++) {
		PX_CHECK_INT_EQ(px_ring_push(r, &x), PX_OK);
		if (x % 3 == 2) {
			PX_CHECK_INT_EQ(px_ring_pop(r, &y), PX_OK);
			PX_CHECK_INT_EQ(px_ring_pop(r, &y), PX_OK);
			PX_CHECK_INT_EQ(px_ring_pop(r, &y), PX_OK);
			PX_CHECK_INT_EQ(y, x);
		}
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(reg), 0);
	PX_CHECK_INT_EQ(px_ring_create(&a, 1, 4, &r), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_ring_create(&a, 4, 0, &r), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_ring_create(&a, 1 << 20, 64, &r), PX_E_NOSPC);
	PX_CHECK(r == NULL);
}

/* Concurrent consumer: every record that was accepted arrives, intact
 * and in order; every record refused is counted as dropped. */
struct rec {
	uint64_t seq;
	uint64_t pad[5];
	uint64_t check;
};

struct ring_race {
	struct px_ring *r;
	atomic_int done;
	uint64_t got, bad, out_of_order, last;
	unsigned char *seen;
};

static void *consumer(void *arg)
{
	struct ring_race *rr = arg;
	struct rec x;
	int first = 1;
	for (;;) {
		int d = atomic_load(&rr->done);
		while (px_ring_pop(rr->r, &x) == PX_OK) {
			int k;
			uint64_t c = x.seq * 0x9e3779b97f4a7c15ull;
			for (k = 0; k < 5; k++)
				if (x.pad[k] != x.seq + (uint64_t)k)
					rr->bad++;
			if (x.check != c)
				rr->bad++;
			if (!first && x.seq <= rr->last)
				rr->out_of_order++;
			first = 0;
			rr->last = x.seq;
			rr->seen[x.seq] = 1;
			rr->got++;
		}
		if (d)
			break;
	}
	return NULL;
}

static void test_ring_concurrent_consumer(void)
{
	enum { N = 300000 };
	static unsigned char mem[1 << 14];
	static unsigned char ok[N], seen[N];
	struct px_arena a;
	struct ring_race rr;
	pthread_t th;
	uint64_t drops = 0, reg, i, mismatch = 0;

	memset(&rr, 0, sizeof(rr));
	memset(seen, 0, sizeof(seen));
	rr.seen = seen;
	PX_CHECK_INT_EQ(px_arena_init(&a, mem, sizeof(mem)), PX_OK);
	PX_CHECK_INT_EQ(px_ring_create(&a, 64, sizeof(struct rec), &rr.r),
			PX_OK);
	atomic_init(&rr.done, 0);
	PX_CHECK_INT_EQ(pthread_create(&th, NULL, consumer, &rr), 0);
	reg = px_alloc_region_begin();
	for (i = 0; i < N; i++) {
		struct rec x;
		int k;
		x.seq = i;
		for (k = 0; k < 5; k++)
			x.pad[k] = i + (uint64_t)k;
		x.check = i * 0x9e3779b97f4a7c15ull;
		ok[i] = px_ring_push(rr.r, &x) == PX_OK;
		drops += !ok[i];
		/* Bursts faster than the consumer force drops. */
		if ((i & 4095) == 0)
			sched_yield();
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(reg), 0);
	atomic_store(&rr.done, 1);
	pthread_join(th, NULL);
	for (i = 0; i < N; i++)
		mismatch += ok[i] != seen[i];
	PX_CHECK_INT_EQ(rr.bad, 0);
	PX_CHECK_INT_EQ(rr.out_of_order, 0);
	PX_CHECK_INT_EQ(mismatch, 0);
	PX_CHECK_INT_EQ(rr.got + drops, N);
	PX_CHECK_INT_EQ(px_ring_dropped(rr.r), drops);
	PX_CHECK_INT_EQ(px_ring_pushed(rr.r), rr.got);
}

/* Parameters: a writer hammering whole sets; the reader must only ever
 * see sets whose fields all agree, in non-decreasing order. */
struct gains {
	uint64_t k;
	double kp[12];
	uint64_t k_again;
};

struct param_race {
	struct px_param *p;
	atomic_int done;
	long n;
};

static void *param_writer(void *arg)
{
	struct param_race *pr = arg;
	struct gains g;
	long i;
	int j;
	for (i = 1; i <= pr->n; i++) {
		g.k = (uint64_t)i;
		for (j = 0; j < 12; j++)
			g.kp[j] = (double)i * (j + 1);
		g.k_again = (uint64_t)i;
		px_param_write(pr->p, &g);
	}
	atomic_store(&pr->done, 1);
	return NULL;
}

static void test_param_never_torn(void)
{
	static unsigned char mem[4096];
	struct px_arena a;
	struct param_race pr;
	struct gains g0;
	const struct gains *g;
	pthread_t th;
	uint64_t last = 0, torn = 0, backwards = 0, fresh_n = 0, reg;
	int fresh, j;

	memset(&g0, 0, sizeof(g0));
	PX_CHECK_INT_EQ(px_arena_init(&a, mem, sizeof(mem)), PX_OK);
	PX_CHECK_INT_EQ(px_param_create(&a, sizeof(g0), &g0, &pr.p), PX_OK);
	g = px_param_read(pr.p, &fresh);
	PX_CHECK_INT_EQ(fresh, 0);
	PX_CHECK_INT_EQ(g->k, 0);
	atomic_init(&pr.done, 0);
	pr.n = 300000;
	PX_CHECK_INT_EQ(pthread_create(&th, NULL, param_writer, &pr), 0);
	reg = px_alloc_region_begin();
	for (;;) {
		int d = atomic_load(&pr.done);
		g = px_param_read(pr.p, &fresh);
		fresh_n += (uint64_t)fresh;
		if (g->k != g->k_again)
			torn++;
		for (j = 0; j < 12; j++)
			if (g->kp[j] != (double)g->k * (j + 1))
				torn++;
		if (g->k < last)
			backwards++;
		last = g->k;
		if (d && !fresh)
			break;
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(reg), 0);
	pthread_join(th, NULL);
	PX_CHECK_INT_EQ(torn, 0);
	PX_CHECK_INT_EQ(backwards, 0);
	/* After the writer finished, the reader holds the last set. */
	PX_CHECK_INT_EQ(last, (uint64_t)pr.n);
	PX_CHECK(fresh_n >= 1);
	PX_CHECK_INT_EQ(px_param_writes(pr.p), pr.n);
	g = px_param_read(pr.p, &fresh);
	PX_CHECK_INT_EQ(fresh, 0);
	PX_CHECK_INT_EQ(px_param_create(&a, 0, NULL, &pr.p), PX_E_INVAL);
	PX_CHECK(px_param_read(NULL, &fresh) == NULL);
}

static void test_fault_names(void)
{
	int c;
	for (c = 0; c < PX_FAULT__COUNT; c++)
		PX_CHECK(strcmp(px_fault_cause_name(c), "unknown") != 0);
	PX_CHECK(strcmp(px_fault_cause_name(PX_FAULT__COUNT), "unknown") == 0);
	PX_CHECK(strcmp(px_fault_cause_name(-1), "unknown") == 0);
	PX_CHECK(strcmp(px_fault_cause_name(PX_FAULT_INPUT_STALE),
			"input_stale") == 0);
}

static const struct px_test tests[] = {
	PX_T(test_stats_against_sorting),
	PX_T(test_stats_bad_args),
	PX_T(test_stats_snapshots_never_torn),
	PX_T(test_ring_sequential),
	PX_T(test_ring_concurrent_consumer),
	PX_T(test_param_never_torn),
	PX_T(test_fault_names),
};

PX_TEST_MAIN(tests)
