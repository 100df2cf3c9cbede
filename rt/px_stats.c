#include "px_stats.h"

#include <stdatomic.h>
#include <string.h>

#include "rt_internal.h"

_Static_assert(ATOMIC_LLONG_LOCK_FREE == 2 && ATOMIC_INT_LOCK_FREE == 2,
	       "px_stats needs lock-free 64-bit atomics");

/* A reader gives up after this many moves of the writer. At 10 kHz and
 * a few microseconds per attempt, more than a handful means a reader
 * that is starved by the scheduler, not by the writer. */
#define READ_TRIES 1000

struct px_stats {
	_Atomic unsigned seq; /* odd while the writer is inside an update */
	_Atomic unsigned reset_req;
	unsigned reset_ack;   /* writer only */
	size_t nbins;
	int64_t bin_ns;
	_Atomic uint64_t count, overflow;
	_Atomic int64_t sum_ns, min_ns, max_ns;
	/* Touched bin range [lo, hi] since the last reset; lo > hi when
	 * none. Readers scan only this range. */
	_Atomic size_t lo, hi;
	_Atomic uint64_t bins[];
};

#define LD(x) atomic_load_explicit(&(x), memory_order_relaxed)
#define ST(x, v) atomic_store_explicit(&(x), (v), memory_order_relaxed)

size_t px_stats_size(size_t nbins)
{
	if (nbins == 0)
		nbins = PX_STATS_DEFAULT_BINS;
	return sizeof(struct px_stats) + nbins * sizeof(_Atomic uint64_t) +
	       PX_ARENA_ALIGN;
}

static void clear(struct px_stats *s)
{
	size_t i, lo = LD(s->lo), hi = LD(s->hi);

	for (i = lo; i <= hi && i < s->nbins; i++)
		ST(s->bins[i], 0);
	ST(s->count, 0);
	ST(s->overflow, 0);
	ST(s->sum_ns, 0);
	ST(s->min_ns, INT64_MAX);
	ST(s->max_ns, INT64_MIN);
	ST(s->lo, s->nbins);
	ST(s->hi, 0);
}

int px_stats_create(struct px_arena *a, size_t nbins, int64_t bin_ns,
		    struct px_stats **out)
{
	struct px_stats *s;
	size_t i;

	if (!a || !out || bin_ns < 0)
		return PX_E_INVAL;
	*out = NULL;
	if (nbins == 0)
		nbins = PX_STATS_DEFAULT_BINS;
	if (bin_ns == 0)
		bin_ns = PX_STATS_DEFAULT_BIN_NS;
	if (nbins > (SIZE_MAX - sizeof(*s)) / sizeof(s->bins[0]) / 2)
		return PX_E_INVAL;
	s = px_arena_alloc(a, sizeof(*s) + nbins * sizeof(s->bins[0]), 64);
	if (!s)
		return PX_E_NOSPC;
	atomic_init(&s->seq, 0);
	atomic_init(&s->reset_req, 0);
	s->reset_ack = 0;
	s->nbins = nbins;
	s->bin_ns = bin_ns;
	atomic_init(&s->count, 0);
	atomic_init(&s->overflow, 0);
	atomic_init(&s->sum_ns, 0);
	atomic_init(&s->min_ns, INT64_MAX);
	atomic_init(&s->max_ns, INT64_MIN);
	atomic_init(&s->lo, nbins);
	atomic_init(&s->hi, 0);
	for (i = 0; i < nbins; i++)
		atomic_init(&s->bins[i], 0);
	*out = s;
	return PX_OK;
}

/* Seqlock writer side (Boehm, "Can seqlocks get along with programming
 * language memory models?", 2012): relaxed data stores between a
 * release fence and a release store of the even counter. */
static inline unsigned write_begin(struct px_stats *s)
{
	unsigned q = LD(s->seq);
	ST(s->seq, q + 1);
	atomic_thread_fence(memory_order_release);
	return q;
}

static inline void write_end(struct px_stats *s, unsigned q)
{
	atomic_store_explicit(&s->seq, q + 2, memory_order_release);
}

void px_stats_record(struct px_stats *s, int64_t v)
{
	unsigned q, req;
	size_t b;

	q = write_begin(s);
	req = atomic_load_explicit(&s->reset_req, memory_order_acquire);
	if (req != s->reset_ack) {
		clear(s);
		s->reset_ack = req;
	}
	b = v <= 0 ? 0 : (uint64_t)v / (uint64_t)s->bin_ns;
	if (b >= s->nbins) {
		ST(s->overflow, LD(s->overflow) + 1);
	} else {
		ST(s->bins[b], LD(s->bins[b]) + 1);
		if (b < LD(s->lo))
			ST(s->lo, b);
		if (b > LD(s->hi))
			ST(s->hi, b);
	}
	ST(s->count, LD(s->count) + 1);
	/* Wraps only after ~292 years of nanoseconds: unsigned arithmetic
	 * keeps it defined regardless. */
	ST(s->sum_ns, (int64_t)((uint64_t)LD(s->sum_ns) + (uint64_t)v));
	if (v < LD(s->min_ns))
		ST(s->min_ns, v);
	if (v > LD(s->max_ns))
		ST(s->max_ns, v);
	write_end(s, q);
}

void px_stats_reset_request(struct px_stats *s)
{
	if (s)
		atomic_fetch_add_explicit(&s->reset_req, 1,
					  memory_order_release);
}

void px_stats_reset(struct px_stats *s)
{
	unsigned q;

	if (!s)
		return;
	q = write_begin(s);
	s->reset_ack = LD(s->reset_req);
	/* A clear of a fresh object must cover every bin. */
	ST(s->lo, 0);
	ST(s->hi, s->nbins - 1);
	clear(s);
	write_end(s, q);
}

size_t px_stats_nbins(const struct px_stats *s)
{
	return s ? s->nbins : 0;
}

int64_t px_stats_bin_ns(const struct px_stats *s)
{
	return s ? s->bin_ns : 0;
}

int64_t px_stats_hist_quantile(const uint64_t *bins, size_t nbins,
			       uint64_t overflow, int64_t bin_ns,
			       int64_t max_ns, double q)
{
	uint64_t n = overflow, rank, cum = 0;
	size_t i;

	if (!bins && nbins)
		return 0;
	for (i = 0; i < nbins; i++)
		n += bins[i];
	if (n == 0)
		return 0;
	if (!(q >= 0.0))
		q = 0.0;
	if (q > 1.0)
		q = 1.0;
	rank = px__ceil_rank(q, n);
	for (i = 0; i < nbins; i++) {
		cum += bins[i];
		if (cum >= rank)
			return (int64_t)i * bin_ns;
	}
	return max_ns;
}

/* One attempt at reading: summary and the three quantiles in one pass
 * over the touched bins. Returns the sequence seen at the start (odd
 * means the writer was inside, so the attempt is void). */
static unsigned read_once(const struct px_stats *s_, struct px_stats_snapshot *o)
{
	struct px_stats *s = (struct px_stats *)s_;
	unsigned q = atomic_load_explicit(&s->seq, memory_order_acquire);
	uint64_t n, r50, r99, r999, cum = 0;
	int64_t mx;
	size_t i, lo, hi;
	int got50 = 0, got99 = 0, got999 = 0;

	memset(o, 0, sizeof(*o));
	o->bin_ns = s->bin_ns;
	o->nbins = s->nbins;
	if (q & 1u)
		return q;
	n = LD(s->count);
	o->count = n;
	if (n == 0)
		return q;
	o->overflow = LD(s->overflow);
	o->min_ns = LD(s->min_ns);
	mx = LD(s->max_ns);
	o->max_ns = mx;
	o->mean_ns = LD(s->sum_ns) / (int64_t)n;
	r50 = px__ceil_rank(0.5, n);
	r99 = px__ceil_rank(0.99, n);
	r999 = px__ceil_rank(0.999, n);
	o->p50_ns = o->p99_ns = o->p999_ns = mx;
	lo = LD(s->lo);
	hi = LD(s->hi);
	for (i = lo; i <= hi && i < s->nbins && !got999; i++) {
		cum += LD(s->bins[i]);
		if (!got50 && cum >= r50) {
			o->p50_ns = (int64_t)i * s->bin_ns;
			got50 = 1;
		}
		if (!got99 && cum >= r99) {
			o->p99_ns = (int64_t)i * s->bin_ns;
			got99 = 1;
		}
		if (cum >= r999) {
			o->p999_ns = (int64_t)i * s->bin_ns;
			got999 = 1;
		}
	}
	return q;
}

static int read_again(const struct px_stats *s, unsigned q)
{
	atomic_thread_fence(memory_order_acquire);
	return (q & 1u) ||
	       atomic_load_explicit(&((struct px_stats *)s)->seq,
				    memory_order_relaxed) != q;
}

int px_stats_read(const struct px_stats *s, struct px_stats_snapshot *out)
{
	int t;

	if (!s || !out)
		return PX_E_INVAL;
	for (t = 0; t < READ_TRIES; t++) {
		unsigned q = read_once(s, out);
		if (!read_again(s, q))
			return PX_OK;
		px__cpu_relax();
	}
	return PX_E_AGAIN;
}

int px_stats_copy_bins(const struct px_stats *s_, uint64_t *bins, size_t cap,
		       uint64_t *overflow)
{
	struct px_stats *s = (struct px_stats *)s_;
	int t;

	if (!s || (!bins && cap))
		return PX_E_INVAL;
	if (cap > s->nbins)
		cap = s->nbins;
	if (cap > (size_t)INT32_MAX)
		cap = (size_t)INT32_MAX;
	for (t = 0; t < READ_TRIES; t++) {
		unsigned q = atomic_load_explicit(&s->seq,
						  memory_order_acquire);
		uint64_t ov = 0;
		size_t i;

		if (!(q & 1u)) {
			for (i = 0; i < cap; i++)
				bins[i] = LD(s->bins[i]);
			ov = LD(s->overflow);
			for (i = cap; i < s->nbins; i++)
				ov += LD(s->bins[i]);
		}
		if (!read_again(s, q)) {
			if (overflow)
				*overflow = ov;
			return (int)cap;
		}
		px__cpu_relax();
	}
	return PX_E_AGAIN;
}
