#include "px_test_dev.h"

#include <stdio.h>
#include <time.h>

#include "px_dev.h"
#include "px_test.h"

void px_test_wait_ms(int ms)
{
	struct timespec ts = {ms / 1000, (ms % 1000) * 1000000L};
	nanosleep(&ts, NULL);
}

int px_test_write_file(const char *dir, const char *name, const char *v)
{
	char p[512];
	FILE *f;
	snprintf(p, sizeof p, "%s/%s", dir, name);
	f = fopen(p, "w");
	if (!f)
		return -1;
	fputs(v, f);
	return fclose(f);
}

int64_t px_test_deadline_ms(int ms)
{
	return px_dev_mono_ns() + (int64_t)ms * 1000000;
}

int px_test_past(int64_t deadline_ns)
{
	return px_dev_mono_ns() > deadline_ns;
}

struct px_loop *px_test_virtual_loop(px_loop_phase_fn read,
				     px_loop_phase_fn compute,
				     px_loop_phase_fn write, void *user)
{
	struct px_loop_config lc;
	struct px_loop *l = NULL;
	px_loop_config_default(&lc);
	lc.clock = PX_LOOP_CLOCK_VIRTUAL;
	lc.read = read;
	lc.compute = compute;
	lc.write = write;
	lc.user = user;
	lc.hist_bins = 100;
	PX_CHECK_INT_EQ(px_loop_create(&lc, &l), PX_OK);
	return l;
}
