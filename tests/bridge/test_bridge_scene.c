/*
 * Scene updates over DDS (px_bridge_dev_config's cloud_topic and
 * scene_topic): the checks of a sensor_msgs/PointCloud2 and a
 * geometry_msgs/PoseStamped field by field (layouts, byte order, sizes,
 * frame, workspace, orientation), and on real Cyclone DDS over loopback
 * a second process (this binary again) whose cloud and model pose
 * arrive in a dds device: the cloud's points in the feed, the pose
 * through the cycle's hand-off, invalid ones refused and counted.
 *
 * Role by environment, for the second process and for
 * tests/bridge/test_scene_run.sh:
 *   PX_SCENE_TEST_ROLE=cloud:DOMAIN:NAMESPACE:KIND:SECONDS
 * publishes on rt/NAMESPACE/perception/cloud and
 * rt/NAMESPACE/perception/scene/post/pose every 20 ms until SECONDS (or
 * the parent is gone), after a reader matched (at most 10 s). KIND:
 *   near   a 5 x 5 x 5 grid of points, 10 cm wide, at NEAR_M, and the
 *          post's pose once (POST_M)
 *   far    the same grid at FAR_M
 *   flood  every period 10 invalid clouds (1 ms apart) and 5 invalid
 *          poses (frame, fields, sizes, NaN, workspace, orientation),
 *          then the far grid; the counts on stdout at the end
 * Every wait is bounded.
 */
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "px_bridge.h"
#include "px_cloud_feed.h"
#include "px_features.h"
#include "px_model.h"
#include "px_test.h"

#if PX_HAVE_DDS
#include <dds/dds.h>

#include "bridge_internal.h"
#include "bridge_test.h"
#include "geometry_msgs.h"
#include "sensor_msgs.h"

static const double NEAR_M[3] = {0.6, 0.5, 0.45}, FAR_M[3] = {0.6, 1.8, 0.45};
static const double POST_M[3] = {-1.2, -1.2, 0.3};
#define GRID 5
#define GRID_POINTS (GRID * GRID * GRID)

/* ---- the checks, on messages made here ------------------------------ */

static const float PTS[4][3] = {
	{0.5f, -0.25f, 1.0f}, {0.125f, 0.0f, -0.5f}, {1.5f, 1.75f, 0.0f},
	{-1.0f, 0.375f, 0.25f}};

/* A 2 x 2 cloud of PTS with an "intensity" field before x, y, z (point
 * step 20, two bytes of row padding), in the given byte order. */
struct cloud_buf {
	sensor_msgs_msg_dds__PointCloud2_ m;
	sensor_msgs_msg_dds__PointField_ f[4];
	uint8_t data[2 * 42];
};

static void put_f32(uint8_t *p, float v, int big)
{
	uint8_t b[4];
	int i;
	memcpy(b, &v, 4);
	for (i = 0; i < 4; i++) {
		static const union {
			uint16_t u;
			uint8_t c[2];
		} order = {1};
		int host_big = order.c[0] == 0;
		p[i] = b[big == host_big ? i : 3 - i];
	}
}

static void make_cloud(struct cloud_buf *c, int big)
{
	static const char *const names[4] = {"intensity", "x", "y", "z"};
	int i, k;
	memset(c, 0, sizeof(*c));
	for (i = 0; i < 4; i++) {
		c->f[i].name = (char *)names[i];
		c->f[i].offset = (uint32_t)(4 + 4 * i);
		c->f[i].datatype = sensor_msgs_msg_dds__PointField_Constants_FLOAT32;
		c->f[i].count = 1;
	}
	c->f[0].offset = 0;
	c->m.header.frame_id = "world";
	c->m.height = 2;
	c->m.width = 2;
	c->m.fields._length = c->m.fields._maximum = 4;
	c->m.fields._buffer = c->f;
	c->m.is_bigendian = big;
	c->m.point_step = 20;
	c->m.row_step = 42;
	c->m.data._length = c->m.data._maximum = sizeof(c->data);
	c->m.data._buffer = c->data;
	c->m.is_dense = true;
	for (i = 0; i < 4; i++) {
		uint8_t *p = c->data + (i / 2) * 42 + (i % 2) * 20;
		put_f32(p, 7.0f, big);
		for (k = 0; k < 3; k++)
			put_f32(p + 8 + 4 * k, PTS[i][k], big);
	}
}

static struct px__bridge_limits limits(void)
{
	struct px__bridge_limits l = {"world", {-2, -2, -2}, {2, 2, 2}, 100};
	return l;
}

static void test_cloud_fields(void)
{
	struct px__bridge_limits l = limits();
	struct cloud_buf c;
	double xyz[3 * 100];
	size_t n = 99;
	int big, i, k;
	for (big = 0; big < 2; big++) {
		make_cloud(&c, big);
		PX_CHECK(px__bridge_cloud_points(&c.m, &l, xyz, &n) == NULL);
		PX_CHECK_INT_EQ(n, 4);
		for (i = 0; i < 4; i++)
			for (k = 0; k < 3; k++)
				PX_CHECK_MSG(xyz[3 * i + k] == PTS[i][k],
					     "%s point %d coordinate %d: %g",
					     big ? "big-endian" : "little-endian", i,
					     k, xyz[3 * i + k]);
	}
	/* an empty cloud: nothing in view, accepted */
	make_cloud(&c, 0);
	c.m.height = 0;
	c.m.data._length = 0;
	PX_CHECK(px__bridge_cloud_points(&c.m, &l, xyz, &n) == NULL);
	PX_CHECK_INT_EQ(n, 0);
}

/* Each broken message is refused with its reason. */
static void test_cloud_refused(void)
{
	struct px__bridge_limits l = limits();
	struct cloud_buf c;
	double xyz[3 * 100];
	size_t n;
	int i;
	for (i = 0; i < 11; i++) {
		const char *want = NULL, *got;
		make_cloud(&c, 0);
		switch (i) {
		case 0: c.m.header.frame_id = "map"; want = "frame"; break;
		case 1: c.f[3].name = "w"; want = "fields"; break;
		case 2: c.f[1].datatype = 8; want = "fields"; break;
		case 3: c.f[2].count = 3; want = "fields"; break;
		case 4: c.f[3].offset = 17; want = "fields"; break;
		case 5: c.m.row_step = 39; want = "sizes"; break;
		case 6: c.m.data._length -= 1; want = "sizes"; break;
		case 7: c.m.width = 3; want = "sizes"; break;
		case 8: l.max_points = 3; want = "points"; break;
		case 9:
			put_f32(c.data + 42 + 8, NAN, 0);
			want = "workspace";
			break;
		case 10:
			put_f32(c.data + 20 + 12, 2.5f, 0);
			want = "workspace";
			break;
		}
		got = px__bridge_cloud_points(&c.m, &l, xyz, &n);
		PX_CHECK_MSG(got && !strcmp(got, want), "case %d: %s, not %s", i,
			     got ? got : "accepted", want);
		l = limits();
	}
}

static void test_pose_checks(void)
{
	struct px__bridge_limits l = limits();
	geometry_msgs_msg_dds__PoseStamped_ m;
	px_pose p;
	const char *why;
	int i;
	memset(&m, 0, sizeof(m));
	m.header.frame_id = "world";
	m.pose.position.x = 0.25, m.pose.position.y = -1.5, m.pose.position.z = 2;
	m.pose.orientation.x = 0.5, m.pose.orientation.y = -0.5;
	m.pose.orientation.z = 0.5, m.pose.orientation.w = 0.5005; /* ~unit */
	why = px__bridge_scene_pose(&m, &l, &p);
	PX_CHECK_MSG(!why, "%s", why);
	PX_CHECK(p.t.x == 0.25 && p.t.y == -1.5 && p.t.z == 2);
	PX_CHECK_NEAR(p.q.w * p.q.w + p.q.x * p.q.x + p.q.y * p.q.y + p.q.z * p.q.z,
		      1.0, 1e-12);
	PX_CHECK_NEAR(p.q.x, 0.5 / sqrt(0.75 + 0.5005 * 0.5005), 1e-15);
	for (i = 0; i < 5; i++) {
		geometry_msgs_msg_dds__PoseStamped_ b = m;
		static const char *const want[] = {"frame", "workspace", "workspace",
						   "orientation", "orientation"};
		switch (i) {
		case 0: b.header.frame_id = "base_link"; break;
		case 1: b.pose.position.z = 2.001; break;
		case 2: b.pose.position.x = NAN; break;
		case 3: b.pose.orientation.w = 0.6; break;
		case 4: b.pose.orientation.y = INFINITY; break;
		}
		why = px__bridge_scene_pose(&b, &l, &p);
		PX_CHECK_MSG(why && !strcmp(why, want[i]), "case %d: %s", i,
			     why ? why : "accepted");
	}
}

/* ---- the publisher --------------------------------------------------- */

static dds_entity_t writer(dds_entity_t dp, const dds_topic_descriptor_t *d,
			   const char *ns, const char *name)
{
	char topic[PX_BRIDGE_TOPIC_MAX];
	dds_qos_t *q = dds_create_qos();
	dds_entity_t t, w;
	px_bridge_topic_name(ns, name, topic, sizeof(topic));
	dds_qset_reliability(q, DDS_RELIABILITY_BEST_EFFORT, 0);
	dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
	t = dds_create_topic(dp, d, topic, q, NULL);
	w = t < 0 ? t : dds_create_writer(dp, t, q, NULL);
	dds_delete_qos(q);
	return w;
}

/* The grid around c, 2.5 cm apart, as float32 x, y, z. */
static void grid(float *xyz, const double c[3])
{
	int i, j, k, n = 0;
	for (i = 0; i < GRID; i++)
		for (j = 0; j < GRID; j++)
			for (k = 0; k < GRID; k++, n++) {
				xyz[3 * n] = (float)(c[0] + 0.025 * (i - 2));
				xyz[3 * n + 1] = (float)(c[1] + 0.025 * (j - 2));
				xyz[3 * n + 2] = (float)(c[2] + 0.025 * (k - 2));
			}
}

/* The cloud message of n points xyz (x, y, z float32, dense). */
static void cloud_msg(sensor_msgs_msg_dds__PointCloud2_ *m,
		      sensor_msgs_msg_dds__PointField_ f[3], float *xyz, uint32_t n)
{
	static const union {
		uint16_t u;
		uint8_t c[2];
	} order = {1};
	int i;
	memset(m, 0, sizeof(*m));
	for (i = 0; i < 3; i++) {
		f[i].name = (char *)(i == 0 ? "x" : i == 1 ? "y" : "z");
		f[i].offset = (uint32_t)(4 * i);
		f[i].datatype = sensor_msgs_msg_dds__PointField_Constants_FLOAT32;
		f[i].count = 1;
	}
	m->header.frame_id = "world";
	m->height = 1;
	m->width = n;
	m->fields._length = m->fields._maximum = 3;
	m->fields._buffer = f;
	m->is_bigendian = order.c[0] == 0;
	m->point_step = 12;
	m->row_step = 12 * n;
	m->data._length = m->data._maximum = 12 * n;
	m->data._buffer = (uint8_t *)xyz;
	m->is_dense = true;
}

static void pose_msg(geometry_msgs_msg_dds__PoseStamped_ *m, const double p[3])
{
	memset(m, 0, sizeof(*m));
	m->header.frame_id = "world";
	m->pose.position.x = p[0];
	m->pose.position.y = p[1];
	m->pose.position.z = p[2];
	m->pose.orientation.w = 1;
}

/* Invalid cloud number k (of 7 kinds) from the valid message v. */
static void bad_cloud(sensor_msgs_msg_dds__PointCloud2_ *m,
		      sensor_msgs_msg_dds__PointField_ f[3], float *tmp,
		      const float *xyz, int k)
{
	memcpy(tmp, xyz, sizeof(float) * 3 * GRID_POINTS);
	cloud_msg(m, f, tmp, GRID_POINTS);
	switch (k % 7) {
	case 0: m->header.frame_id = "map"; break;
	case 1: f[2].name = "w"; break;
	case 2: m->point_step = 8; break;
	case 3: m->data._length -= 12; break;
	case 4: tmp[7] = NAN; break;
	case 5: tmp[3 * 60 + 2] = -1e9f; break;
	case 6: tmp[0] = INFINITY; break;
	}
}

static int role_cloud(const char *role)
{
	char ns[128], kind[16];
	double seconds;
	int domain, i, sent_bad = 0, sent_bad_poses = 0;
	dds_entity_t dom = 0, dp, wc, wp;
	dds_publication_matched_status_t st;
	static float xyz[3 * GRID_POINTS], tmp[3 * GRID_POINTS];
	sensor_msgs_msg_dds__PointCloud2_ m;
	sensor_msgs_msg_dds__PointField_ f[3];
	geometry_msgs_msg_dds__PoseStamped_ pm;
	pid_t parent = getppid();
	int64_t end;
	if (sscanf(role, "cloud:%d:%127[^:]:%15[^:]:%lf", &domain, ns, kind,
		   &seconds) != 4)
		return 2;
	dp = join(domain, &dom);
	wc = writer(dp, &sensor_msgs_msg_dds__PointCloud2__desc, ns,
		    "perception/cloud");
	wp = writer(dp, &geometry_msgs_msg_dds__PoseStamped__desc, ns,
		    "perception/scene/post/pose");
	if (dp < 0 || wc < 0 || wp < 0) {
		fprintf(stderr, "cloud: cannot publish\n");
		return 1;
	}
	end = mono_ns() + 10000000000LL;
	do
		dds_sleepfor(DDS_MSECS(5));
	while (dds_get_publication_matched_status(wc, &st) == 0 &&
	       !st.current_count && mono_ns() < end);
	grid(xyz, strcmp(kind, "near") ? FAR_M : NEAR_M);
	end = mono_ns() + (int64_t)(seconds * 1e9);
	for (i = 0; mono_ns() < end && getppid() == parent; i++) {
		int k;
		for (k = 0; !strcmp(kind, "flood") && k < 10; k++) {
			/* 1 ms apart: the reader keeps the last only */
			bad_cloud(&m, f, tmp, xyz, sent_bad + k);
			dds_write(wc, &m);
			dds_sleepfor(DDS_MSECS(1));
		}
		for (k = 0; !strcmp(kind, "flood") && k < 5; k++) {
			pose_msg(&pm, POST_M);
			switch (k) {
			case 0: pm.header.frame_id = "map"; break;
			case 1: pm.pose.position.x = NAN; break;
			case 2: pm.pose.position.z = 50; break;
			case 3: pm.pose.orientation.w = 0.5; break;
			case 4: pm.pose.orientation.x = INFINITY; break;
			}
			dds_write(wp, &pm);
		}
		if (!strcmp(kind, "flood"))
			sent_bad += 10, sent_bad_poses += 5;
		/* the valid ones last: keep-last-1 readers keep them */
		cloud_msg(&m, f, xyz, GRID_POINTS);
		dds_write(wc, &m);
		if (!strcmp(kind, "near") && i < 5) { /* best-effort: a few */
			pose_msg(&pm, POST_M);
			dds_write(wp, &pm);
		}
		dds_sleepfor(DDS_MSECS(20));
	}
	printf("cloud: %d periods, %d invalid clouds, %d invalid poses\n", i,
	       sent_bad, sent_bad_poses);
	dds_delete(dp);
	if (dom > 0)
		dds_delete(dom);
	return 0;
}

/* ---- two processes ---------------------------------------------------- */

/* The device reads the second process's near grid into the feed (each
 * point at distance 0 of the model) and the post's pose; with the flood
 * the invalid ones are refused and counted, the pose never changes. */
static void run_device(const char *kind, struct px_bridge_dev_counts *n,
		       int *points_ok, int *pose_ok, int *poses_fresh)
{
	static const char *const models[] = {"post"};
	struct px_bridge_config c;
	struct px_bridge_dev_config bc;
	struct px_dev_config dc;
	struct px_cloud_feed *feed = NULL;
	struct px_dev *d = NULL;
	struct px_bridge_scene_poses sp;
	char ns[64], role[256], msg[256];
	int64_t end;
	pid_t child;
	int domain = 1 + (int)(getpid() % 200), taken = 0;
	snprintf(ns, sizeof(ns), "pxscene_%d_%s", (int)getpid(), kind);
	px_bridge_config_default(&c);
	c.domain_id = domain;
	c.ns = ns;
	PX_CHECK_INT_EQ(px_cloud_feed_create(4, 1000, 0.0, &feed), PX_OK);
	px_dev_config_default(&dc);
	dc.name = "perception";
	memset(&bc, 0, sizeof(bc));
	bc.bridge = &c;
	bc.cloud_topic = "perception/cloud";
	bc.cloud_feed = feed;
	bc.cloud_max_points = 1000;
	bc.scene_topic = "perception/scene";
	bc.scene_models = models;
	bc.n_scene_models = 1;
	bc.workspace_min_m[0] = bc.workspace_min_m[1] = bc.workspace_min_m[2] = -2;
	bc.workspace_max_m[0] = bc.workspace_max_m[1] = bc.workspace_max_m[2] = 2;
	bc.connect_timeout_ns = 10000000000LL;
	PX_CHECK_MSG(px_bridge_dev_create(&dc, &bc, &d, msg, sizeof(msg)) == PX_OK,
		     "%s", msg);
	PX_CHECK_INT_EQ(px_dev_caps(d), 0);
	snprintf(role, sizeof(role), "cloud:%d:%s:%s:3", domain, ns, kind);
	child = spawn_role("PX_SCENE_TEST_ROLE", role);
	if (px_dev_start(d) != PX_OK) {
		stop_child(child);
		PX_CHECK_MSG(0, "no cloud publisher within 10 s");
	}
	*points_ok = *pose_ok = *poses_fresh = 0;
	end = mono_ns() + 2500000000LL;
	while (mono_ns() < end) {
		struct px_model *model = NULL;
		if (px_cloud_feed_take(feed, px_dev_mono_ns(), &model, NULL) == 1 &&
		    !taken++) {
			float xyz[3 * GRID_POINTS];
			struct px_cloud_feed_stats st;
			int i, ok = 1;
			grid(xyz, !strcmp(kind, "near") ? NEAR_M : FAR_M);
			px_cloud_feed_stats(feed, &st);
			for (i = 0; i < GRID_POINTS && ok; i++) {
				struct px_model_result r;
				px_vec3 p = px_v3(xyz[3 * i], xyz[3 * i + 1],
						  xyz[3 * i + 2]);
				ok = px_model_query(model, p, &r) == 1 &&
				     fabs(r.distance) < 1e-9;
			}
			*points_ok = ok && st.points == GRID_POINTS;
		}
		if (px_bridge_dev_scene_poses(d, &sp) == 1) {
			(*poses_fresh)++;
			*pose_ok = sp.seq[0] > 0 && sp.pose[0].t.x == POST_M[0] &&
				   sp.pose[0].t.y == POST_M[1] &&
				   sp.pose[0].t.z == POST_M[2] && sp.pose[0].q.w == 1;
		}
		dds_sleepfor(DDS_MSECS(2));
	}
	stop_child(child);
	PX_CHECK_INT_EQ(px_bridge_dev_counts(d, n), PX_OK);
	px_dev_free(d);
	px_cloud_feed_free(feed);
}

static void test_cloud_and_pose_arrive(void)
{
	struct px_bridge_dev_counts n;
	int points_ok, pose_ok, fresh;
	PX_NEEDS(DDS);
	run_device("near", &n, &points_ok, &pose_ok, &fresh);
	PX_CHECK_MSG(n.clouds_accepted >= 10, "%llu clouds accepted",
		     (unsigned long long)n.clouds_accepted);
	PX_CHECK_INT_EQ(n.clouds_refused, 0);
	PX_CHECK_MSG(points_ok, "the feed's cloud is not the published grid");
	PX_CHECK_MSG(pose_ok && fresh >= 1, "the post's pose did not arrive (%d)",
		     fresh);
	PX_CHECK(n.scene_poses_accepted >= 1 && n.scene_poses_refused == 0);
}

static void test_flood_refused(void)
{
	struct px_bridge_dev_counts n;
	int points_ok, pose_ok, fresh;
	PX_NEEDS(DDS);
	run_device("flood", &n, &points_ok, &pose_ok, &fresh);
	/* best-effort keep-last-1: a burst may lose samples before the
	 * thread takes them, never turn one into an accepted one */
	PX_CHECK_MSG(n.clouds_refused >= 400, "%llu clouds refused",
		     (unsigned long long)n.clouds_refused);
	PX_CHECK_MSG(n.scene_poses_refused >= 10, "%llu poses refused",
		     (unsigned long long)n.scene_poses_refused);
	PX_CHECK_INT_EQ(n.scene_poses_accepted, 0);
	PX_CHECK_INT_EQ(fresh, 0);
	PX_CHECK_MSG(points_ok, "the valid far grid was not the feed's cloud");
	PX_CHECK(n.clouds_accepted >= 10);
}

#else

static void test_cloud_fields(void) { PX_NEEDS(DDS); }
static void test_cloud_refused(void) { PX_NEEDS(DDS); }
static void test_pose_checks(void) { PX_NEEDS(DDS); }
static void test_cloud_and_pose_arrive(void) { PX_NEEDS(DDS); }
static void test_flood_refused(void) { PX_NEEDS(DDS); }

#endif

static const struct px_test tests[] = {
	PX_T(test_cloud_fields),
	PX_T(test_cloud_refused),
	PX_T(test_pose_checks),
	PX_T(test_cloud_and_pose_arrive),
	PX_T(test_flood_refused),
};

int main(int argc, char **argv)
{
	const char *role = getenv("PX_SCENE_TEST_ROLE");
	if (role) {
#if PX_HAVE_DDS
		if (!strncmp(role, "cloud:", 6))
			return role_cloud(role);
#endif
		fprintf(stderr, "unknown or unsupported role '%s'\n", role);
		return 2;
	}
	return px_test_main(argv[0], tests, sizeof(tests) / sizeof(tests[0]),
			    argc, argv);
}
