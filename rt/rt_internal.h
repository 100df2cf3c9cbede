/* Private helpers shared by the rt/ modules. Not installed. */
#ifndef PX_RT_INTERNAL_H
#define PX_RT_INTERNAL_H

#include <math.h>
#include <stdint.h>
#include <time.h>

/*
 * Rank of quantile q among n samples: ceil(q * n), at least 1, at most n.
 * q is taken to a millionth and the product done in integers, so 0.99 of
 * 100 is exactly rank 99 (double arithmetic can give 99.000000000000014).
 */
static inline uint64_t px__ceil_rank(double q, uint64_t n)
{
	const uint64_t den = 1000000u;
	uint64_t num, r;

	if (!(q > 0.0))
		return 1;
	if (q >= 1.0)
		return n;
	num = (uint64_t)llround(q * (double)den);
	r = (n / den) * num + ((n % den) * num + den - 1) / den;
	if (r < 1)
		r = 1;
	if (r > n)
		r = n;
	return r;
}

static inline void px__cpu_relax(void)
{
#if defined(__x86_64__) || defined(__i386__)
	__builtin_ia32_pause();
#elif defined(__aarch64__)
	__asm__ __volatile__("yield");
#endif
}

static inline int64_t px__ts_to_ns(const struct timespec *ts)
{
	return (int64_t)ts->tv_sec * 1000000000 + ts->tv_nsec;
}

static inline struct timespec px__ns_to_ts(int64_t ns)
{
	struct timespec ts;
	ts.tv_sec = (time_t)(ns / 1000000000);
	ts.tv_nsec = (long)(ns % 1000000000);
	return ts;
}

static inline int64_t px__mono_ns(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return px__ts_to_ns(&ts);
}

#endif
