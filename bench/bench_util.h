/*
 * bench_util.h - what the benchmarks share: a fixed-seed random stream
 * (so every run times the same inputs), a monotonic clock in ns, an
 * int64 comparison for qsort of timings, where the FCL reference
 * program is, and a bounded integer from the environment. Benchmarks
 * only; one include
 * per program (the stream's state is per file).
 */
#ifndef PX_BENCH_UTIL_H
#define PX_BENCH_UTIL_H

#include <libgen.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
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

/* Path of the FCL reference program (bench/fcl_models.cpp):
 * $PX_BENCH_MODELS_FCL, else fcl_models next to the benchmark argv0. */
static inline void fcl_path(const char *argv0, char *path, size_t n)
{
	const char *env = getenv("PX_BENCH_MODELS_FCL");
	char dir[4096];
	if (env && *env) {
		snprintf(path, n, "%s", env);
	} else {
		snprintf(dir, sizeof(dir), "%s", argv0);
		snprintf(path, n, "%s/fcl_models", dirname(dir));
	}
}

/* The integer in environment variable name, def when unset or outside
 * lo..hi (then said on stderr, prefixed by the program's name). */
static inline long bench_env_long(const char *prog, const char *name,
				  long def, long lo, long hi)
{
	const char *s = getenv(name);
	char *end;
	long v;
	if (!s || !*s)
		return def;
	v = strtol(s, &end, 10);
	if (*end || v < lo || v > hi) {
		fprintf(stderr, "%s: ignoring %s=%s (want %ld..%ld)\n", prog,
			name, s, lo, hi);
		return def;
	}
	return v;
}

#endif
