/* proxima-run's DDS bridge (bridge/px_bridge.h): the config's bridge
 * section read with the rest, and, when enabled, the drained records and
 * the loop's status handed to the bridge's own thread. Everything here
 * runs on the draining thread; the loop's thread never gets here. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "px_bridge.h"
#include "px_scene.h"
#include "run_internal.h"

static struct {
	struct px_bridge_config c;
	struct px_bridge *b;
	struct px_app *app;
	int avoiding;
	int joints; /* joint states published (avoidance: the arm's) */
	double offer_every_s, last_offer_t_s;
	int64_t stamp0_ns; /* CLOCK_REALTIME of loop time 0; -1 unknown */
	int64_t status_every_ns, last_status_ns;
	uint64_t last_cycles;
	char topic0[PX_BRIDGE_TOPIC_MAX];
} B;

static int64_t clock_ns(clockid_t id)
{
	struct timespec ts;
	clock_gettime(id, &ts);
	return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

int run_bridge_read(const struct px_config *cfg, const char *path)
{
	static struct px_config_diag diag;
	int n;
	px_config_diag_init(&diag);
	if (px_bridge_config_read(cfg, &B.c, &diag) == PX_OK)
		return 0;
	n = px_config_diag_total(&diag);
	px_config_diag_print(&diag, stderr);
	fprintf(stderr, "%s: invalid configuration (%d error%s)\n", path, n,
		n == 1 ? "" : "s");
	return 1;
}

int run_bridge_start(struct px_app *app, int avoiding)
{
	char msg[320];
	double max_rate = 0;
	const double rates[] = {B.c.tool_pose_rate_hz, B.c.proxy_pose_rate_hz,
				B.c.wrench_rate_hz, B.c.distance_rate_hz};
	size_t i;
	if (!B.c.enable)
		return 0;
	if (px_bridge_create(&B.c, &B.b, msg, sizeof(msg)) != PX_OK) {
		fprintf(stderr, "proxima-run: %s\n", msg);
		return 1;
	}
	B.app = app;
	B.avoiding = avoiding;
	if (avoiding) {
		static struct px_app_summary sum;
		px_app_summary(app, &sum);
		B.joints = sum.record_joints;
	}
	for (i = 0; i < sizeof(rates) / sizeof(rates[0]); i++)
		if (rates[i] > max_rate)
			max_rate = rates[i];
	/* offer at twice the fastest stream's rate (each of its periods
	 * then sees a new sample), not every record: the distance query
	 * below runs once per offer */
	B.offer_every_s = max_rate > 0 ? 0.999 / (2 * max_rate) : INFINITY;
	B.last_offer_t_s = -INFINITY;
	B.stamp0_ns = -1;
	B.status_every_ns = B.c.status_rate_hz > 0
				    ? (int64_t)(1e9 / B.c.status_rate_hz)
				    : 0;
	B.last_status_ns = clock_ns(CLOCK_MONOTONIC);
	px_bridge_topic_name(B.c.ns, "...", B.topic0, sizeof(B.topic0));
	fprintf(stderr,
		"proxima-run: bridge: publishing on %s (DDS domain %lld, "
		"interface %s)\n",
		B.topic0, (long long)B.c.domain_id, B.c.interface);
	return 0;
}

/* The distance the sample carries: avoidance records hold the arm's
 * closest point and the obstacle's; otherwise the scene's nearest point
 * to the tool, asked here (a query beside the loop, as the drain's own
 * proxy check makes). */
static void distance_of(const struct px_app_record *r,
			struct px_bridge_sample *s)
{
	const struct px_scene *scene = px_app_scene(B.app);
	double n[3], len;
	int k;
	memcpy(s->tool_point_m, r->dev_m, sizeof(s->tool_point_m));
	if (!r->valid)
		return;
	if (B.avoiding) {
		if (!isfinite(r->distance_m))
			return;
		memcpy(s->closest_m, r->proxy_m, sizeof(s->closest_m));
		s->distance_m = r->distance_m;
	} else {
		struct px_scene_hit h;
		px_vec3 p = px_v3(r->dev_m[0], r->dev_m[1], r->dev_m[2]);
		if (!scene || px_scene_nearest(scene, p, INFINITY, &h) != 1)
			return;
		s->closest_m[0] = h.point.x;
		s->closest_m[1] = h.point.y;
		s->closest_m[2] = h.point.z;
		s->distance_m = h.distance_m;
	}
	for (k = 0; k < 3; k++)
		n[k] = s->tool_point_m[k] - s->closest_m[k];
	len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
	if (!(len > 0))
		return; /* on the surface: no direction */
	if (s->distance_m < 0)
		len = -len; /* inside: the normal still points outwards */
	for (k = 0; k < 3; k++)
		s->normal[k] = n[k] / len;
	s->distance_valid = true;
}

void run_bridge_record(const struct px_app_record *r)
{
	struct px_bridge_sample s;
	int k;
	if (!B.b || r->t_s - B.last_offer_t_s < B.offer_every_s)
		return;
	B.last_offer_t_s = r->t_s;
	if (B.stamp0_ns < 0)
		B.stamp0_ns = clock_ns(CLOCK_REALTIME) - (int64_t)(r->t_s * 1e9);
	memset(&s, 0, sizeof(s));
	s.stamp_ns = B.stamp0_ns + (int64_t)(r->t_s * 1e9);
	memcpy(s.tool_m, r->dev_m, sizeof(s.tool_m));
	/* the device's orientation; a record without one (all zero):
	 * identity */
	for (k = 0; k < 4; k++)
		s.tool_quat_xyzw[k] = r->dev_quat_xyzw[k];
	if (!(r->dev_quat_xyzw[0] || r->dev_quat_xyzw[1] ||
	      r->dev_quat_xyzw[2] || r->dev_quat_xyzw[3]))
		s.tool_quat_xyzw[3] = 1;
	memcpy(s.proxy_m, r->proxy_m, sizeof(s.proxy_m));
	memcpy(s.force_n, r->force_n, sizeof(s.force_n));
	distance_of(r, &s);
	px_bridge_offer(B.b, &s);
	if (B.joints > 0) {
		double q[PX_APP_RECORD_JOINTS], qd[PX_APP_RECORD_JOINTS];
		for (k = 0; k < B.joints; k++) {
			q[k] = r->q[k];
			qd[k] = r->qdot[k];
		}
		px_bridge_publish_joint_state(B.b, s.stamp_ns, (size_t)B.joints,
					      NULL, q, qd, NULL);
	}
}

void run_bridge_tick(void)
{
	static struct px_app_summary sum;
	struct px_bridge_status st;
	struct px_loop_status ls;
	struct px_stats_snapshot lat;
	int64_t now = clock_ns(CLOCK_MONOTONIC);
	if (!B.b || !B.status_every_ns || now - B.last_status_ns < B.status_every_ns)
		return;
	px_loop_status(px_app_loop(B.app), &ls);
	px_loop_stats(px_app_loop(B.app), PX_LOOP_STAT_LATENCY, &lat);
	px_app_summary(B.app, &sum);
	memset(&st, 0, sizeof(st));
	st.stamp_ns = clock_ns(CLOCK_REALTIME);
	st.loop_rate_hz = (double)(ls.cycles - B.last_cycles) /
			  ((double)(now - B.last_status_ns) * 1e-9);
	st.latency_p50_us = (double)lat.p50_ns * 1e-3;
	st.latency_p99_us = (double)lat.p99_ns * 1e-3;
	st.latency_max_us = (double)lat.max_ns * 1e-3;
	st.safe_state = ls.safe != 0;
	st.cycles = ls.cycles;
	st.overruns = ls.overruns;
	st.faults = ls.faults;
	st.safe_state_trips = ls.safe_entries;
	st.telemetry_dropped = sum.telemetry_dropped;
	B.last_cycles = ls.cycles;
	B.last_status_ns = now;
	px_bridge_offer_status(B.b, &st);
}

void run_bridge_stop(void)
{
	struct px_bridge_counts n;
	uint64_t total = 0;
	char js[48] = "";
	int t;
	if (!B.b)
		return;
	px_bridge_counts(B.b, &n);
	px_bridge_free(B.b);
	B.b = NULL;
	for (t = 0; t < PX_BRIDGE_TOPIC__COUNT; t++)
		total += n.published[t];
	if (B.joints)
		snprintf(js, sizeof(js), ", joint_states %llu",
			 (unsigned long long)n.published[PX_BRIDGE_JOINT_STATES]);
	fprintf(stderr,
		"proxima-run: bridge: %llu messages on %s (tool_pose %llu, "
		"wrench %llu, distance %llu, status %llu%s), %llu write errors\n",
		(unsigned long long)total, B.topic0,
		(unsigned long long)n.published[PX_BRIDGE_TOOL_POSE],
		(unsigned long long)n.published[PX_BRIDGE_WRENCH],
		(unsigned long long)n.published[PX_BRIDGE_DISTANCE],
		(unsigned long long)n.published[PX_BRIDGE_STATUS],
		js,
		(unsigned long long)n.write_errors);
}
