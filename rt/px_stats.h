/*
 * px_stats.h - lock-free latency statistics for a real-time cycle.
 *
 * A px_stats is a fixed histogram (nbins bins of bin_ns each, default
 * 5000 bins of 1 microsecond, i.e. 0..5 ms, plus an overflow count) with
 * exact min, max, count and sum beside it. One thread, the real-time
 * writer, calls px_stats_record(); any number of other threads may read
 * a snapshot (min, mean, p50, p99, p99.9, max) at any time without ever
 * blocking or slowing the writer.
 *
 * Consistency: the writer brackets each update with a sequence counter
 * (a seqlock whose writer never waits). A reader copies what it needs
 * and retries when the counter moved, so a snapshot is always the state
 * between two records, never half of one. Readers only touch the range
 * of bins written since the last reset, so reading stays cheap.
 *
 * Reset: px_stats_reset_request() may be called from any thread; the
 * writer applies it at its next record (clearing only the bins it
 * touched, a bounded cost). px_stats_reset() clears at once and is only
 * for when no writer is running.
 *
 * Memory: one block from a setup-time arena; nothing is ever freed on
 * its own (the arena owns it). Values are nanoseconds (int64_t);
 * negative values are counted in bin 0 and still reach min.
 */
#ifndef PX_STATS_H
#define PX_STATS_H

#include <stddef.h>
#include <stdint.h>

#include "px_arena.h"
#include "px_base.h"

#ifdef __cplusplus
extern "C" {
#endif

#define PX_STATS_DEFAULT_BINS 5000u
#define PX_STATS_DEFAULT_BIN_NS 1000

struct px_stats;

/*
 * Summary of everything recorded since the last reset. Percentiles are
 * the lower edge of the bin holding that rank (the convention of
 * cyclictest's histogram: a 13.7 us sample counts as 13 us); a rank that
 * falls in the overflow gives max_ns. All zero when count is 0.
 */
struct px_stats_snapshot {
	uint64_t count;    /* samples */
	uint64_t overflow; /* samples >= nbins * bin_ns */
	int64_t min_ns, max_ns, mean_ns;
	int64_t p50_ns, p99_ns, p999_ns;
	int64_t bin_ns;    /* histogram resolution */
	size_t nbins;
};

/*
 * Create a histogram in arena a: nbins bins (>= 1) of bin_ns (>= 1)
 * each; 0 for either picks the default. *out receives the object, owned
 * by the arena. Setup only.
 * Returns PX_OK, PX_E_INVAL (NULL pointer, negative bin_ns) or
 * PX_E_NOSPC (arena too small; see px_stats_size()).
 */
PX_API int px_stats_create(struct px_arena *a, size_t nbins, int64_t bin_ns,
			   struct px_stats **out);

/* Arena bytes px_stats_create() needs for nbins bins (upper bound,
 * alignment included). */
PX_API size_t px_stats_size(size_t nbins);

/*
 * Add one sample. Single writer only (the cycle's thread).
 * @note RT-safe: wait-free, O(1) except when a reset request is pending,
 * then O(bins touched since the last reset).
 */
PX_API void px_stats_record(struct px_stats *s, int64_t value_ns);

/*
 * Consistent summary, from any thread. Never blocks the writer; retries
 * while a record is in progress, at most a bounded number of times.
 * Returns PX_OK, PX_E_INVAL, or PX_E_AGAIN if the writer kept moving for
 * every attempt (out is then left as the last, possibly torn, attempt).
 * @note RT-safe (bounded, no allocation), though meant for other threads.
 */
PX_API int px_stats_read(const struct px_stats *s,
			 struct px_stats_snapshot *out);

/*
 * Consistent copy of the histogram: bins[i] counts samples in
 * [i*bin_ns, (i+1)*bin_ns). Copies min(cap, nbins) bins; *overflow (may
 * be NULL) gets the overflow count plus the samples of bins beyond cap,
 * so the copy always accounts for every sample.
 * Returns the number of bins copied, or PX_E_INVAL / PX_E_AGAIN.
 */
PX_API int px_stats_copy_bins(const struct px_stats *s, uint64_t *bins,
			      size_t cap, uint64_t *overflow);

/* Ask the writer to clear everything at its next record. Any thread.
 * @note RT-safe. */
PX_API void px_stats_reset_request(struct px_stats *s);

/* Clear now. Only while no thread is calling px_stats_record(). */
PX_API void px_stats_reset(struct px_stats *s);

/* Histogram geometry. @note RT-safe. */
PX_API size_t px_stats_nbins(const struct px_stats *s);
PX_API int64_t px_stats_bin_ns(const struct px_stats *s);

/*
 * Quantile q in [0, 1] of a plain histogram (bins as above, plus the
 * overflow count): the lower edge of the bin holding rank ceil(q * n)
 * (rank at least 1), or max_ns when that rank falls in the overflow.
 * Shared so that histograms from elsewhere (cyclictest) are summarised
 * the same way. Returns 0 for an empty histogram.
 * @note RT-safe.
 */
PX_API int64_t px_stats_hist_quantile(const uint64_t *bins, size_t nbins,
				      uint64_t overflow, int64_t bin_ns,
				      int64_t max_ns, double q);

#ifdef __cplusplus
}
#endif

#endif
