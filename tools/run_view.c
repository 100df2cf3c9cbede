/* proxima-run's browser view (view/px_view.h, --view [ADDR:]PORT): the
 * server made at setup with the scene, fed the drained records (on the
 * draining thread, never the loop's), ended and stopped after the run.
 * A view that cannot start (no page built, the port taken) is said on
 * stderr and the run goes on without it. */
#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "px_view.h"
#include "run_internal.h"

static struct px_view *V;

int run_view_parse(const char *spec, char *addr, size_t cap, int *port)
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
		/* [::1]:PORT */
		if (addr[0] == '[' && addr[len - 1] == ']') {
			memmove(addr, addr + 1, len - 2);
			addr[len - 2] = '\0';
		}
	}
	errno = 0;
	n = strtol(p, &end, 10);
	if (end == p || *end || errno || n < 1 || n > 65535)
		return -1;
	*port = (int)n;
	return 0;
}

/* build/view/web beside build/bin, else share/proxima/view beside bin. */
static void default_root(char *buf, size_t cap)
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

void run_view_start(struct px_app *app, const char *name, const char *spec,
		    const char *root, int64_t period_ns)
{
	struct px_view_options o;
	struct px_view_scene_info info;
	char addr[64], dflt[PATH_MAX + 32], msg[320];
	char *scene = NULL;
	size_t len = 0;
	int port, rc;
	if (!spec)
		return;
	if (run_view_parse(spec, addr, sizeof(addr), &port)) {
		fprintf(stderr, "proxima-run: view: '%s' is not [ADDR:]PORT; "
				"running without the view\n", spec);
		return;
	}
	if (!root) {
		default_root(dflt, sizeof(dflt));
		root = dflt;
	}
	px_view_options_default(&o);
	o.addr = addr[0] ? addr : NULL;
	o.port = port;
	o.web_root = root;
	o.name = name;
	o.period_ns = period_ns;
	rc = px_view_create(&o, &V, msg, sizeof(msg));
	if (rc != PX_OK) {
		fprintf(stderr, "proxima-run: %s; running without the view\n", msg);
		return;
	}
	memset(&info, 0, sizeof(info));
	info.tool_radius_m = 0.002;
	rc = px_view_scene_json(px_app_scene(app), &info, &scene, &len);
	if (rc == PX_OK)
		rc = px_view_set_scene(V, scene, len);
	free(scene);
	if (rc == PX_OK)
		rc = px_view_start(V);
	if (rc != PX_OK) {
		fprintf(stderr, "proxima-run: view: %s; running without the view\n",
			px_strerror(rc));
		px_view_free(V);
		V = NULL;
		return;
	}
	fprintf(stderr, "proxima-run: view: http://%s%s%s:%d/\n",
		strchr(addr[0] ? addr : "", ':') ? "[" : "",
		addr[0] ? addr : "127.0.0.1",
		strchr(addr[0] ? addr : "", ':') ? "]" : "", port);
}

void run_view_record(const struct px_app_record *r)
{
	if (V)
		px_view_feed_record(V, r);
}

void run_view_stop(void)
{
	struct px_view_stats st;
	if (!V)
		return;
	px_view_stop(V, 500);
	px_view_stats(V, &st);
	fprintf(stderr,
		"proxima-run: view: %llu frames fed, %llu sent to %llu "
		"connection%s, %llu dropped\n",
		(unsigned long long)st.frames_fed,
		(unsigned long long)st.frames_sent,
		(unsigned long long)st.connections, st.connections == 1 ? "" : "s",
		(unsigned long long)st.frames_dropped);
	px_view_free(V);
	V = NULL;
}
