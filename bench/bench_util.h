/*
 * bench_util.h - what the benchmarks share: a fixed-seed random stream
 * (so every run times the same inputs), a monotonic clock in ns, and an
 * int64 comparison for qsort of timings. Benchmarks only; one include
 * per program (the stream's state is per file).
 */
#ifndef PX_BENCH_UTIL_H
#define PX_BENCH_UTIL_H

#include <stdint.h>
#include <time.h>

static uint64_t rng = 0x9e3779b97f4a7c15ull;

/* Uniform in [0, 1): xorshift64, 53 bits. */
static inline double urand(void)
{
	rng ^= rng << 13;
	rng ^= rng >> 7;
	rng ^= rng << 17;
	return (double)(rng >> 11) * 0x1.0p-53;
}

static inline int64_t now_ns(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

static inline int cmp_i64(const void *a, const void *b)
{
	int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
	return (x > y) - (x < y);
}

#endif
