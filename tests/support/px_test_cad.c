/* The tests' CAD parts (px_test_cad.h). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "px_test.h"
#include "px_test_cad.h"

static char dir[256];

int px_test_cadgen(const char *args)
{
	char exe[256], cmd[1600];
	ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
	PX_CHECK(n > 0);
	exe[n] = 0;
	*strrchr(exe, '/') = 0;
	snprintf(cmd, sizeof cmd, "'%s/../bin/proxima-cadgen' %s", exe, args);
	return system(cmd);
}

const char *px_test_cad_dir(void)
{
	char args[300], tmp[] = "/tmp/px_cad_XXXXXX";
	if (dir[0])
		return dir;
	PX_CHECK(mkdtemp(tmp) != NULL);
	snprintf(dir, sizeof dir, "%s", tmp);
	snprintf(args, sizeof args, "'%s'", dir);
	PX_CHECK_MSG(px_test_cadgen(args) == 0, "proxima-cadgen %s failed", args);
	return dir;
}

void px_test_cad_path(char *buf, size_t cap, const char *name, const char *ext)
{
	snprintf(buf, cap, "%s/%s.%s", px_test_cad_dir(), name, ext);
}

void px_test_cad_cleanup(void)
{
	char cmd[300];
	if (!dir[0])
		return;
	snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
	if (system(cmd) != 0)
		fprintf(stderr, "could not remove %s\n", dir);
	dir[0] = 0;
}
