/*
 * px_test.h - the in-tree test harness.
 *
 * One binary per module. A test is a void function; checks that fail
 * abort the current test (longjmp back to the runner), so helper
 * functions may use them too. Each test gets its own random stream
 * seeded from the run seed and the test's name; the seed is printed and
 * can be forced with PX_TEST_SEED=<number> to replay a failure. A single
 * test can be selected with PX_TEST_ONLY=<name>.
 *
 * Output: one line per test ("ok", "FAIL", "skip"), then a summary line
 * "<binary>: N passed, N failed, N skipped". tests/run.sh adds the
 * binaries up into the final "N passed, N failed, N skipped" line.
 */
#ifndef PX_TEST_H
#define PX_TEST_H

#include "px_features.h"
#include <math.h>
#include <stddef.h>
#include <stdint.h>

struct px_test {
	const char *name;
	void (*fn)(void);
};

#define PX_T(fn) {#fn, fn}

/* Run the table; returns the exit status for main(). */
int px_test_main(const char *binary, const struct px_test *tests, size_t n,
		 int argc, char **argv);

#define PX_TEST_MAIN(table)                                                \
	int main(int argc, char **argv)                                    \
	{                                                                  \
		return px_test_main(argv[0], table,                        \
				    sizeof(table) / sizeof(table[0]), argc, \
				    argv);                                 \
	}

/* Failure and skip: print, then leave the test. */
_Noreturn void px_test_fail_(const char *file, int line, const char *fmt,
			     ...) __attribute__((format(printf, 3, 4)));
_Noreturn void px_test_skip_(const char *fmt, ...)
	__attribute__((format(printf, 1, 2)));
/* Skip the test when the build left out an optional part it needs
 * (PART as in px_features.h: HIDAPI, LIBUSB, SOCKETCAN, GPIOD, ASSIMP,
 * YAML, OCCT, XML, DDS, VIEW), saying which: "skipped: built without libyaml". */
#define PX_NEEDS(PART)                                                      \
	do {                                                                \
		if (!PX_HAVE_##PART)                                        \
			px_test_skip_("built without %s",                   \
				      px_test_part_lib_(#PART));            \
	} while (0)
const char *px_test_part_lib_(const char *part);
/* buf = the path of tests/data/<name>, the shared test files, found from
 * where the harness source is (tests/support/), not from the test's own
 * folder. */
void px_test_data_path(char *buf, size_t cap, const char *name);
/* Count one assertion (a test with no assertion at all fails). */
void px_test_count_(void);

#define PX_CHECK(cond)                                                      \
	do {                                                                \
		px_test_count_();                                           \
		if (!(cond))                                                \
			px_test_fail_(__FILE__, __LINE__, "%s", #cond);     \
	} while (0)

#define PX_CHECK_MSG(cond, ...)                                             \
	do {                                                                \
		px_test_count_();                                           \
		if (!(cond))                                                \
			px_test_fail_(__FILE__, __LINE__, __VA_ARGS__);     \
	} while (0)

#define PX_CHECK_INT_EQ(a, b)                                               \
	do {                                                                \
		long long px_a_ = (long long)(a), px_b_ = (long long)(b);   \
		px_test_count_();                                           \
		if (px_a_ != px_b_)                                         \
			px_test_fail_(__FILE__, __LINE__,                   \
				      "%s == %s: %lld != %lld", #a, #b,     \
				      px_a_, px_b_);                        \
	} while (0)

/* |a - b| <= abs_tol + rel_tol * max(|a|, |b|); NaN never passes. */
int px_test_close(double a, double b, double abs_tol, double rel_tol);

#define PX_CHECK_CLOSE(a, b, abs_tol, rel_tol)                              \
	do {                                                                \
		double px_a_ = (a), px_b_ = (b);                            \
		px_test_count_();                                           \
		if (!px_test_close(px_a_, px_b_, (abs_tol), (rel_tol)))     \
			px_test_fail_(__FILE__, __LINE__,                   \
				      "%s ~ %s: %.17g vs %.17g (diff %.3g, " \
				      "abs tol %.3g, rel tol %.3g)",        \
				      #a, #b, px_a_, px_b_,                 \
				      fabs(px_a_ - px_b_), (double)(abs_tol), \
				      (double)(rel_tol));                   \
	} while (0)

#define PX_CHECK_NEAR(a, b, abs_tol) PX_CHECK_CLOSE(a, b, abs_tol, 0.0)
#define PX_CHECK_REL(a, b, rel_tol) PX_CHECK_CLOSE(a, b, 0.0, rel_tol)

#define PX_SKIP(...) px_test_skip_(__VA_ARGS__)

/* Random numbers from the current test's stream (xoshiro256**). */
uint64_t px_rand_u64(void);
double px_rand_unit(void);                 /* [0, 1) */
double px_rand_range(double lo, double hi); /* [lo, hi) */
int px_rand_int(int lo, int hi);           /* [lo, hi] inclusive */
double px_rand_normal(void);
uint64_t px_test_seed(void); /* seed of the running test */
/* The stream's state, saved and put back: a test can replay the same
 * random inputs under two settings. */
struct px_rand_state {
	uint64_t s[4];
};
void px_rand_save(struct px_rand_state *st);
void px_rand_restore(const struct px_rand_state *st);

/* A clock for code that takes one as fn(ctx) -> ns (the trackers' cold
 * switch): every read advances it by inc, so every timed region measures
 * inc. Pass px_test_clock_read with a struct px_test_clock as ctx. */
struct px_test_clock {
	int64_t now, inc;
};
int64_t px_test_clock_read(void *ctx);

#endif
