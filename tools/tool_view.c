/* The view's argument and page folder for the tools (tool_view.h). */
#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "tool_view.h"

int tool_view_parse(const char *spec, char *addr, size_t cap, int *port)
{
	const char *colon = strrchr(spec, ':'), *p = colon ? colon + 1 : spec;
	char *end;
	long n;
	addr[0] = '\0';
	if (colon) {
		size_t len = (size_t)(colon - spec);
		if (len == 0 || len >= cap)
			return -1;
		memcpy(addr, spec, len);
		addr[len] = '\0';
		if (addr[0] == '[' && len >= 2 && addr[len - 1] == ']') {
			memmove(addr, addr + 1, len - 2);
			addr[len - 2] = '\0';
		} else if (strchr(addr, ':')) {
			return -1; /* an IPv6 address needs its brackets */
		}
	}
	errno = 0;
	n = strtol(p, &end, 10);
	if (end == p || *end || errno || n < 1 || n > 65535)
		return -1;
	*port = (int)n;
	return 0;
}

void tool_view_root(char *buf, size_t cap)
{
	char exe[PATH_MAX], *slash;
	ssize_t n = readlink("/proc/self/exe", exe, sizeof(exe) - 1);
	buf[0] = '\0';
	if (n <= 0)
		return;
	exe[n] = '\0';
	slash = strrchr(exe, '/');
	if (!slash)
		return;
	*slash = '\0';
	snprintf(buf, cap, "%s/../view/web", exe);
	if (access(buf, R_OK) != 0)
		snprintf(buf, cap, "%s/../share/proxima/view", exe);
}

void tool_view_url(const char *addr, int port, char *buf, size_t cap)
{
	int v6 = strchr(addr, ':') != NULL;
	snprintf(buf, cap, "http://%s%s%s:%d/", v6 ? "[" : "",
		 addr[0] ? addr : "127.0.0.1", v6 ? "]" : "", port);
}
