#include "px_test.h"

#include <setjmp.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static jmp_buf jump_;
static uint64_t rng_[4];
static uint64_t seed_;
static unsigned long checks_;

enum outcome { PASSED, FAILED, SKIPPED };

static uint64_t splitmix(uint64_t *x)
{
	uint64_t z = (*x += 0x9e3779b97f4a7c15ull);
	z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
	z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
	return z ^ (z >> 31);
}

static uint64_t hash_name(const char *s)
{
	uint64_t h = 1469598103934665603ull; /* FNV-1a */
	for (; *s; s++)
		h = (h ^ (unsigned char)*s) * 1099511628211ull;
	return h;
}

static void seed_stream(uint64_t seed)
{
	uint64_t x = seed;
	int i;
	seed_ = seed;
	for (i = 0; i < 4; i++)
		rng_[i] = splitmix(&x);
}

void px_rand_save(struct px_rand_state *st)
{
	int i;
	for (i = 0; i < 4; i++)
		st->s[i] = rng_[i];
}

void px_rand_restore(const struct px_rand_state *st)
{
	int i;
	for (i = 0; i < 4; i++)
		rng_[i] = st->s[i];
}

static uint64_t rotl(uint64_t x, int k)
{
	return (x << k) | (x >> (64 - k));
}

uint64_t px_rand_u64(void)
{
	uint64_t r = rotl(rng_[1] * 5, 7) * 9, t = rng_[1] << 17;
	rng_[2] ^= rng_[0];
	rng_[3] ^= rng_[1];
	rng_[1] ^= rng_[2];
	rng_[0] ^= rng_[3];
	rng_[2] ^= t;
	rng_[3] = rotl(rng_[3], 45);
	return r;
}

double px_rand_unit(void)
{
	return (double)(px_rand_u64() >> 11) * 0x1.0p-53;
}

double px_rand_range(double lo, double hi)
{
	return lo + (hi - lo) * px_rand_unit();
}

int64_t px_test_clock_read(void *ctx)
{
	struct px_test_clock *c = ctx;
	c->now += c->inc;
	return c->now;
}

int px_rand_int(int lo, int hi)
{
	uint64_t span = (uint64_t)((int64_t)hi - lo) + 1;
	return (int)(lo + (int64_t)(px_rand_u64() % span));
}

double px_rand_normal(void)
{
	/* Box-Muller; the unit draw is kept away from 0 for the log. */
	double u = 1.0 - px_rand_unit(), v = px_rand_unit();
	return sqrt(-2.0 * log(u)) * cos(6.283185307179586 * v);
}

uint64_t px_test_seed(void)
{
	return seed_;
}

void px_test_count_(void)
{
	checks_++;
}

int px_test_close(double a, double b, double abs_tol, double rel_tol)
{
	double d, m;
	if (isnan(a) || isnan(b))
		return 0;
	if (a == b) /* also equal infinities */
		return 1;
	d = fabs(a - b);
	m = fmax(fabs(a), fabs(b));
	return d <= abs_tol + rel_tol * m;
}

void px_test_fail_(const char *file, int line, const char *fmt, ...)
{
	va_list ap;
	printf("    %s:%d: ", file, line);
	va_start(ap, fmt);
	vprintf(fmt, ap);
	va_end(ap);
	printf("\n");
	fflush(stdout);
	longjmp(jump_, 1 + FAILED);
}

void px_test_skip_(const char *fmt, ...)
{
	va_list ap;
	printf("    skipped: ");
	va_start(ap, fmt);
	vprintf(fmt, ap);
	va_end(ap);
	printf("\n");
	fflush(stdout);
	longjmp(jump_, 1 + SKIPPED);
}

const char *px_test_part_lib_(const char *part)
{
	static const char *const names[][2] = {
		{"HIDAPI", "hidapi"},	  {"LIBUSB", "libusb"},
		{"SOCKETCAN", "libsocketcan"}, {"GPIOD", "libgpiod"},
		{"ASSIMP", "assimp"},	  {"YAML", "libyaml"},
		{"OCCT", "OpenCASCADE"},   {"XML", "libxml2"},
		{"DDS", "cyclonedds"},     {"VIEW", "libwebsockets"},
	};
	for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
		if (!strcmp(part, names[i][0]))
			return names[i][1];
	return part;
}

void px_test_data_path(char *buf, size_t cap, const char *name)
{
	const char *f = __FILE__, *slash = strrchr(f, '/');
	if (slash)
		snprintf(buf, cap, "%.*s/../data/%s", (int)(slash - f), f, name);
	else
		snprintf(buf, cap, "../data/%s", name);
}

static const char *base_name(const char *path)
{
	const char *s = strrchr(path, '/');
	return s ? s + 1 : path;
}

/* setjmp lives alone here so no caller variable can be clobbered. */
static enum outcome run_one(void (*fn)(void))
{
	int j;

	checks_ = 0;
	j = setjmp(jump_);
	if (j != 0)
		return (enum outcome)(j - 1);
	fn();
	if (checks_ == 0) {
		printf("    no assertion was made\n");
		return FAILED;
	}
	return PASSED;
}

int px_test_main(const char *binary, const struct px_test *tests, size_t n,
		 int argc, char **argv)
{
	const char *env_seed = getenv("PX_TEST_SEED");
	const char *only = getenv("PX_TEST_ONLY");
	uint64_t run_seed = 0x5eed0f0c0ffee123ull;
	int forced = 0;
	unsigned passed = 0, failed = 0, skipped = 0;
	size_t i;

	(void)argc;
	(void)argv;
	binary = base_name(binary);
	if (env_seed && *env_seed) {
		run_seed = strtoull(env_seed, NULL, 0);
		forced = 1;
	}
	setvbuf(stdout, NULL, _IOLBF, 0);
	for (i = 0; i < n; i++) {
		enum outcome res;
		uint64_t seed;

		if (only && *only && strcmp(only, tests[i].name) != 0)
			continue;
		/* A forced seed is used as is, so the printed value replays
		 * exactly; otherwise each test gets its own stream. */
		seed = forced ? run_seed : run_seed ^ hash_name(tests[i].name);
		seed_stream(seed);
		res = run_one(tests[i].fn);
		switch (res) {
		case PASSED:
			passed++;
			printf("ok   %s (seed 0x%016llx)\n", tests[i].name,
			       (unsigned long long)seed);
			break;
		case FAILED:
			failed++;
			printf("FAIL %s (seed 0x%016llx; replay with "
			       "PX_TEST_SEED=0x%016llx PX_TEST_ONLY=%s)\n",
			       tests[i].name, (unsigned long long)seed,
			       (unsigned long long)seed, tests[i].name);
			break;
		case SKIPPED:
			skipped++;
			printf("skip %s\n", tests[i].name);
			break;
		}
	}
	printf("%s: %u passed, %u failed, %u skipped\n", binary, passed, failed,
	       skipped);
	return failed ? 1 : 0;
}
