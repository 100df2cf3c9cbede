/* proxima-run's browser view (view/px_view.h, --view [ADDR:]PORT): the
 * server made at setup with the scene, fed the drained records (on the
 * draining thread, never the loop's), ended and stopped after the run.
 * A view that cannot start (no page built, the port taken) is said on
 * stderr and the run goes on without it. */
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "px_view.h"
#include "run_internal.h"
#include "tool_view.h"

static struct px_view *V;
static struct px_view_arm *ARM;

/* The arm of an avoidance run and its obstacle clouds (none
 * when the run has no arm or the arm cannot be drawn: said). */
static void arm_sources(struct px_app *app, struct px_view_scene_info *info,
			struct px_view_sources *src)
{
	struct px_app_arm arm;
	int rc;
	if (!px_app_arm(app, &arm))
		return;
	rc = px_view_arm_create(&arm, &ARM);
	if (rc != PX_OK)
		fprintf(stderr, "proxima-run: view: the arm is not drawn: %s\n",
			px_strerror(rc));
	info->arm = ARM;
	src->arm = ARM;
	if (arm.cloud_feed) {
		info->cloud_name = "obstacle cloud";
		src->cloud_feed = arm.cloud_feed;
		src->cloud_id = (int)(px_app_scene(app) ? px_scene_count(px_app_scene(app)) : 0);
	}
}

void run_view_start(struct px_app *app, const char *name, const char *spec,
		    const char *root, int64_t period_ns)
{
	struct px_view_options o;
	struct px_view_scene_info info;
	struct px_view_sources src;
	char addr[64], dflt[PATH_MAX + 32], msg[320], url[128];
	char *scene = NULL;
	size_t len = 0;
	int port, rc;
	if (!spec)
		return;
	if (tool_view_parse(spec, addr, sizeof(addr), &port)) {
		fprintf(stderr, "proxima-run: view: '%s' is not [ADDR:]PORT; "
				"running without the view\n", spec);
		return;
	}
	if (!root) {
		tool_view_root(dflt, sizeof(dflt));
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
	memset(&src, 0, sizeof(src));
	info.tool_radius_m = 0.002;
	src.scene = px_app_scene(app);
	arm_sources(app, &info, &src);
	rc = px_view_scene_json(px_app_scene(app), &info, &scene, &len);
	if (rc == PX_OK)
		rc = px_view_set_scene(V, scene, len);
	free(scene);
	if (rc == PX_OK)
		rc = px_view_set_sources(V, &src);
	if (rc == PX_OK)
		rc = px_view_start(V);
	if (rc != PX_OK) {
		fprintf(stderr, "proxima-run: view: %s; running without the view\n",
			px_strerror(rc));
		px_view_free(V);
		V = NULL;
		px_view_arm_free(ARM);
		ARM = NULL;
		return;
	}
	tool_view_url(addr, port, url, sizeof(url));
	fprintf(stderr, "proxima-run: view: %s\n", url);
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
	px_view_arm_free(ARM);
	ARM = NULL;
}
