#include "px_test_dev.h"

#include <stdio.h>
#include <time.h>

#include "px_dev.h"

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
