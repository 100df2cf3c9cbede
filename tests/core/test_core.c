/* Errors, version, setup-time arena, and the allocation counter itself. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "px_alloc_count.h"
#include "px_arena.h"
#include "px_base.h"
#include "px_test.h"

static void test_strerror_table(void)
{
	int e;
	for (e = 0; e > -PX_E__COUNT; e--) {
		const char *s = px_strerror(e), *n = px_strerror_name(e);
		PX_CHECK(s && *s && strcmp(s, "unknown error") != 0);
		PX_CHECK(n && strncmp(n, "PX_", 3) == 0);
		/* Positive form means the same. */
		PX_CHECK(px_strerror(-e) == s);
	}
	PX_CHECK(strcmp(px_strerror(-PX_E__COUNT), "unknown error") == 0);
	PX_CHECK(strcmp(px_strerror(-2147483647 - 1), "unknown error") == 0);
	PX_CHECK(strcmp(px_strerror_name(PX_E_NOSPC), "PX_E_NOSPC") == 0);
	PX_CHECK(strcmp(px_strerror_name(PX_E_CORRUPT), "PX_E_CORRUPT") == 0);
}

static void test_version(void)
{
	char buf[32];
	PX_CHECK(strcmp(px_version(), PX_VERSION_STRING) == 0);
	PX_CHECK_INT_EQ(px_version_number(), PX_VERSION_NUMBER);
	snprintf(buf, sizeof(buf), "%d.%d.%d", PX_VERSION_MAJOR,
		 PX_VERSION_MINOR, PX_VERSION_PATCH);
	PX_CHECK(strcmp(buf, px_version()) == 0);
}

static void test_arena_caller_buffer(void)
{
	/* Deliberately misaligned caller buffer. */
	static unsigned char raw[1000 + 64];
	struct px_arena a;
	unsigned char *buf = raw + 3;
	void *p, *q;
	size_t mark;

	PX_CHECK_INT_EQ(px_arena_init(&a, buf, 1000), PX_OK);
	PX_CHECK_INT_EQ(px_arena_capacity(&a), 1000);
	p = px_arena_alloc(&a, 10, 0);
	PX_CHECK(p != NULL);
	PX_CHECK((uintptr_t)p % PX_ARENA_ALIGN == 0);
	PX_CHECK((unsigned char *)p >= buf);
	q = px_arena_alloc(&a, 7, 8);
	PX_CHECK(q != NULL && (uintptr_t)q % 8 == 0);
	PX_CHECK((unsigned char *)q >= (unsigned char *)p + 10);
	PX_CHECK((unsigned char *)q + 7 <= buf + 1000);
	mark = px_arena_mark(&a);
	PX_CHECK(px_arena_alloc(&a, 500, 1) != NULL);
	PX_CHECK_INT_EQ(px_arena_high_water(&a), mark + 500);
	px_arena_reset_to(&a, mark);
	PX_CHECK_INT_EQ(px_arena_used(&a), mark);
	PX_CHECK_INT_EQ(px_arena_high_water(&a), mark + 500);
	/* Exhaustion is refused and counted, never overruns the buffer. */
	PX_CHECK(px_arena_alloc(&a, 1000, 1) == NULL);
	PX_CHECK_INT_EQ(px_arena_failed(&a), 1);
	PX_CHECK(px_arena_alloc(&a, (size_t)-1, 1) == NULL);
	PX_CHECK(px_arena_calloc(&a, (size_t)-1 / 2, 4, 1) == NULL);
	PX_CHECK_INT_EQ(px_arena_failed(&a), 3);
	PX_CHECK(px_arena_alloc(&a, 8, 3) == NULL); /* bad alignment */
	/* Fill exactly to the end. */
	p = px_arena_alloc(&a, 1000 - px_arena_used(&a), 1);
	PX_CHECK(p != NULL);
	PX_CHECK_INT_EQ(px_arena_used(&a), 1000);
	PX_CHECK(px_arena_alloc(&a, 1, 1) == NULL);
	px_arena_fini(&a);
}

static void test_arena_bad_args(void)
{
	struct px_arena a;
	PX_CHECK_INT_EQ(px_arena_init(NULL, NULL, 0), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_arena_init(&a, NULL, 16), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_arena_init(&a, NULL, 0), PX_OK);
	PX_CHECK(px_arena_alloc(&a, 1, 1) == NULL);
	PX_CHECK(px_arena_alloc(NULL, 1, 1) == NULL);
	px_arena_fini(NULL);
	PX_CHECK_INT_EQ(px_arena_init_alloc(&a, (size_t)-1 / 2), PX_E_NOMEM);
}

static void test_arena_owned_zeroed_random(void)
{
	struct px_arena a;
	size_t total = 0;
	int i;

	PX_CHECK_INT_EQ(px_arena_init_alloc(&a, 1 << 16), PX_OK);
	for (i = 0; i < 200; i++) {
		size_t n = (size_t)px_rand_int(0, 300);
		size_t al = (size_t)1 << px_rand_int(0, 6);
		unsigned char *p = px_arena_calloc(&a, n, 1, al);
		size_t k;
		if (!p) {
			PX_CHECK(px_arena_used(&a) + n + al > px_arena_capacity(&a));
			break;
		}
		PX_CHECK((uintptr_t)p % al == 0);
		for (k = 0; k < n; k++)
			PX_CHECK_MSG(p[k] == 0, "byte %zu not zero", k);
		memset(p, 0xab, n);
		total += n;
	}
	PX_CHECK(px_arena_used(&a) >= total);
	px_arena_fini(&a);
	PX_CHECK_INT_EQ(px_arena_capacity(&a), 0);
}

/* The counter must see a deliberate allocation inside a region... */
static void *volatile sink;

static void test_alloc_counter_sees_allocations(void)
{
	uint64_t r = px_alloc_region_begin();
	sink = malloc(64);
	free(sink);
	sink = calloc(4, 4);
	sink = realloc(sink, 128);
	free(sink);
	PX_CHECK_MSG(px_alloc_region_end(r) >= 5,
		     "counter (%s) saw %llu calls, expected >= 5",
		     px_alloc_count_mode(),
		     (unsigned long long)px_alloc_region_end(r));
	r = px_alloc_region_begin();
	{
		void *p = NULL;
		PX_CHECK_INT_EQ(posix_memalign(&p, 64, 100), 0);
		sink = p;
		free(sink);
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(r), 2);
}

/* ...and must see one made by library code on our behalf. */
static void test_alloc_counter_sees_library_allocation(void)
{
	struct px_arena a;
	uint64_t r = px_alloc_region_begin();
	PX_CHECK_INT_EQ(px_arena_init_alloc(&a, 4096), PX_OK);
	px_arena_fini(&a);
	PX_CHECK(px_alloc_region_end(r) >= 2);
}

/* The real use: arena hand-out after setup allocates nothing. */
static void test_arena_cycle_allocates_nothing(void)
{
	struct px_arena a;
	uint64_t r;
	int cycle;

	PX_CHECK_INT_EQ(px_arena_init_alloc(&a, 1 << 20), PX_OK);
	r = px_alloc_region_begin();
	for (cycle = 0; cycle < 100000; cycle++) {
		size_t mark = px_arena_mark(&a);
		double *scratch = px_arena_calloc(&a, 64, sizeof(double), 0);
		PX_CHECK(scratch != NULL);
		scratch[cycle % 64] = cycle;
		px_arena_reset_to(&a, mark);
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(r), 0);
	px_arena_fini(&a);
}

static const struct px_test tests[] = {
	PX_T(test_strerror_table),
	PX_T(test_version),
	PX_T(test_arena_caller_buffer),
	PX_T(test_arena_bad_args),
	PX_T(test_arena_owned_zeroed_random),
	PX_T(test_alloc_counter_sees_allocations),
	PX_T(test_alloc_counter_sees_library_allocation),
	PX_T(test_arena_cycle_allocates_nothing),
};

PX_TEST_MAIN(tests)
