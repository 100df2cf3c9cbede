/*
 * The DDS bridge (bridge/px_bridge.h): its config section, topic and
 * type naming against the IDL, the Cyclone configuration it generates,
 * and, on real Cyclone DDS over loopback, two processes: this one
 * subscribes to every topic and checks each message field by field
 * against what a second process (this binary again, as publisher)
 * published; a reader of the wrong type and one with incompatible QoS
 * are seen not to match (Cyclone's matched and incompatible-QoS status).
 *
 * Roles by environment, for the second process and for
 * tests/bridge/test_bridge_run.sh:
 *   PX_BRIDGE_TEST_ROLE=publish:DOMAIN:NAMESPACE:SECONDS
 *   PX_BRIDGE_TEST_ROLE=listen:DOMAIN:NAMESPACE:SECONDS
 *   PX_BRIDGE_TEST_ROLE=params:DOMAIN:NAMESPACE/TOPIC:COUNT (COUNT bad
 *     parameter sets, 2 ms apart: non-finite or absurd values; COUNT 0:
 *     one set of modest values)
 * (listen exits 0 once a tool pose, a wrench and a status arrived.)
 * Every wait is bounded; discovery is retried until its deadline.
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
#include "px_config.h"
#include "px_features.h"
#include "px_test.h"
#include "px_test_config.h"

#if PX_HAVE_DDS
#include <dds/dds.h>

#include "bridge_test.h"
#include "proxima_msgs.h"
#include "sensor_msgs.h"
#endif

/* ---- config, naming, Cyclone configuration (every build) ----------- */

static struct px_config *load(const char *yaml, struct px_config_diag *d)
{
	struct px_config *c = NULL;
	px_config_load_mem("t.yaml", yaml, strlen(yaml), &c, d);
	return c;
}

static void test_config_defaults_and_values(void)
{
	static struct px_config_diag d;
	struct px_bridge_config bc;
	struct px_config *c;
	PX_NEEDS(YAML);
	c = load("version: 1\n", &d);
	PX_CHECK(c != NULL);
	PX_CHECK_INT_EQ(px_bridge_config_read(c, &bc, &d), PX_OK);
	PX_CHECK(!bc.enable);
	PX_CHECK_INT_EQ(bc.domain_id, 0);
	PX_CHECK(!strcmp(bc.ns, "proxima") && !strcmp(bc.interface, "lo"));
	PX_CHECK(!strcmp(bc.frame_id, "world"));
	PX_CHECK_INT_EQ(bc.discovery, PX_BRIDGE_DISCOVERY_AUTO);
	PX_CHECK(bc.tool_pose_rate_hz == 100 && bc.distance_rate_hz == 50 &&
		 bc.status_rate_hz == 10);
	px_config_free(c);
	c = load("bridge:\n  enable: true\n  domain_id: 42\n"
		 "  namespace: lab/arm_1\n  interface: 127.0.0.1\n"
		 "  discovery: unicast\n  frame_id: base_link\n"
		 "  tool_pose_rate_hz: 250\n  proxy_pose_rate_hz: 0\n"
		 "  wrench_rate_hz: 500.5\n  distance_rate_hz: 20\n"
		 "  status_rate_hz: 1\n",
		 &d);
	PX_CHECK(c != NULL);
	PX_CHECK_INT_EQ(px_bridge_config_read(c, &bc, &d), PX_OK);
	PX_CHECK(bc.enable && bc.domain_id == 42);
	PX_CHECK(!strcmp(bc.ns, "lab/arm_1"));
	PX_CHECK(!strcmp(bc.interface, "127.0.0.1"));
	PX_CHECK(!strcmp(bc.frame_id, "base_link"));
	PX_CHECK_INT_EQ(bc.discovery, PX_BRIDGE_DISCOVERY_UNICAST);
	PX_CHECK(bc.tool_pose_rate_hz == 250 && bc.proxy_pose_rate_hz == 0 &&
		 bc.wrench_rate_hz == 500.5 && bc.distance_rate_hz == 20 &&
		 bc.status_rate_hz == 1);
	px_config_free(c);
}

/* Each bad value is reported at its line as bridge.<key>. */
static void test_config_errors(void)
{
	static const struct {
		const char *yaml, *path, *what;
	} cases[] = {
		{"bridge:\n  namespace: /proxima\n", "bridge.namespace", "empty token"},
		{"bridge:\n  namespace: a//b\n", "bridge.namespace", "empty token"},
		{"bridge:\n  namespace: 3d/tool\n", "bridge.namespace", "digit"},
		{"bridge:\n  namespace: tool-1\n", "bridge.namespace", "ROS 2 name"},
		{"bridge:\n  namespace: tool/\n", "bridge.namespace", "ends with"},
		{"bridge:\n  interface: \"lo<x>\"\n", "bridge.interface", "interface name"},
		{"bridge:\n  interface: eth0\n  discovery: unicast\n", "bridge.discovery", "loopback only"},
		{"bridge:\n  domain_id: 233\n", "bridge.domain_id", ""},
		{"bridge:\n  status_rate_hz: -1\n", "bridge.status_rate_hz", ""},
		{"bridge:\n  wrench_rate_hz: 20000\n", "bridge.wrench_rate_hz", ""},
		{"bridge:\n  discovery: broadcast\n", "bridge.discovery", ""},
		{"bridge:\n  enabled: true\n", "bridge.enabled", ""},
		{"bridge:\n  frame_id: \"\"\n", "bridge.frame_id", ""},
	};
	static struct px_config_diag d;
	size_t i;
	PX_NEEDS(YAML);
	for (i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
		struct px_bridge_config bc;
		const struct px_config_error *e;
		struct px_config *c = load(cases[i].yaml, &d);
		PX_CHECK(c != NULL);
		px_config_diag_init(&d);
		PX_CHECK_MSG(px_bridge_config_read(c, &bc, &d) == PX_E_PARSE,
			     "case %zu accepted", i);
		e = px_config_diag_find(&d, cases[i].path);
		PX_CHECK_MSG(e != NULL, "case %zu: no error at %s (first: %s)",
			     i, cases[i].path, d.count ? d.errors[0].msg : "");
		PX_CHECK_MSG(!strncmp(e->msg, "t.yaml:", 7) && e->line >= 2 &&
				     strstr(e->msg, cases[i].what),
			     "case %zu: %s", i, e->msg);
		px_config_free(c);
	}
}

static void test_docs_cover_bridge_keys(void)
{
	char *docs = px_test_read_text("docs/config.md");
	char why[200];
	if (!docs)
		PX_SKIP("docs/config.md not found (run from the source tree)");
	px_test_check_documented(docs, px_bridge_config_schema(), 4);
	free(docs);
	PX_CHECK_INT_EQ(px_config_schema_validate(px_bridge_config_schema(),
						  why, sizeof(why)),
			PX_OK);
}

static void test_topic_names_and_types(void)
{
	char buf[PX_BRIDGE_TOPIC_MAX];
	static const char *const want[][2] = {
		{"tool_pose", "geometry_msgs::msg::dds_::PoseStamped_"},
		{"proxy_pose", "geometry_msgs::msg::dds_::PoseStamped_"},
		{"wrench", "geometry_msgs::msg::dds_::WrenchStamped_"},
		{"closest_point", "geometry_msgs::msg::dds_::PointStamped_"},
		{"distance", "proxima_msgs::msg::dds_::Distance_"},
		{"status", "proxima_msgs::msg::dds_::Status_"},
		{"joint_states", "sensor_msgs::msg::dds_::JointState_"},
		{"cloud", "sensor_msgs::msg::dds_::PointCloud2_"},
	};
	int t;
	PX_CHECK_INT_EQ(px_bridge_topic_name("proxima", "tool_pose", buf,
					     sizeof(buf)),
			PX_OK);
	PX_CHECK(!strcmp(buf, "rt/proxima/tool_pose"));
	PX_CHECK_INT_EQ(px_bridge_topic_name("lab/arm", "status", buf,
					     sizeof(buf)),
			PX_OK);
	PX_CHECK(!strcmp(buf, "rt/lab/arm/status"));
	PX_CHECK_INT_EQ(px_bridge_topic_name("proxima", "tool_pose", buf, 10),
			PX_E_RANGE);
	for (t = 0; t < PX_BRIDGE_TOPIC__COUNT; t++) {
		PX_CHECK(!strcmp(px_bridge_topic_short_name(t), want[t][0]));
		PX_CHECK(!strcmp(px_bridge_topic_type_name(t), want[t][1]));
		PX_CHECK_INT_EQ(px_bridge_topic_reliable(t),
				t == PX_BRIDGE_STATUS);
	}
	PX_CHECK(px_bridge_topic_short_name(PX_BRIDGE_TOPIC__COUNT) == NULL);
#if PX_HAVE_DDS
	{
		/* the IDL compiles to exactly these DDS type names */
		const dds_topic_descriptor_t *d;
		for (t = 0; t < PX_BRIDGE_TOPIC__COUNT; t++) {
			d = px_bridge_topic_descriptor(t);
			PX_CHECK(d != NULL);
			PX_CHECK_MSG(!strcmp(d->m_typename, want[t][1]), "%s",
				     d->m_typename);
			PX_CHECK_INT_EQ(d->m_nkeys, 0); /* ROS 2: no keys */
		}
		PX_CHECK(px_bridge_topic_descriptor(PX_BRIDGE_TOPIC__COUNT) == NULL);
		PX_CHECK(!strcmp(builtin_interfaces_msg_dds__Time__desc.m_typename,
				 "builtin_interfaces::msg::dds_::Time_"));
		PX_CHECK(!strcmp(std_msgs_msg_dds__Header__desc.m_typename,
				 "std_msgs::msg::dds_::Header_"));
		PX_CHECK(!strcmp(geometry_msgs_msg_dds__Pose__desc.m_typename,
				 "geometry_msgs::msg::dds_::Pose_"));
		PX_CHECK(!strcmp(sensor_msgs_msg_dds__PointField__desc.m_typename,
				 "sensor_msgs::msg::dds_::PointField_"));
	}
#else
	PX_CHECK(px_bridge_topic_descriptor(PX_BRIDGE_TOOL_POSE) == NULL);
#endif
}

static void test_dds_config(void)
{
	struct px_bridge_config c;
	char xml[PX_BRIDGE_DDS_CONFIG_MAX], why[200];
	px_bridge_config_default(&c);
	PX_CHECK_INT_EQ(px_bridge_config_check(&c, why, sizeof(why)), PX_OK);
	PX_CHECK_INT_EQ(px_bridge_dds_config(&c, xml, sizeof(xml)), PX_OK);
	PX_CHECK(strstr(xml, "<NetworkInterface name=\"lo\"/>"));
	PX_CHECK(strstr(xml, "<AllowMulticast>false</AllowMulticast>"));
	PX_CHECK(strstr(xml, "<Peer address=\"127.0.0.1\"/>"));
	PX_CHECK(strstr(xml, "<ParticipantIndex>auto</ParticipantIndex>"));
	c.interface = "127.0.0.1";
	PX_CHECK_INT_EQ(px_bridge_dds_config(&c, xml, sizeof(xml)), PX_OK);
	PX_CHECK(strstr(xml, "<NetworkInterface address=\"127.0.0.1\"/>"));
	c.discovery = PX_BRIDGE_DISCOVERY_MULTICAST;
	c.interface = "lo";
	PX_CHECK_INT_EQ(px_bridge_dds_config(&c, xml, sizeof(xml)), PX_OK);
	PX_CHECK(strstr(xml, "multicast=\"true\""));
	PX_CHECK(strstr(xml, "<AllowMulticast>true</AllowMulticast>"));
	PX_CHECK(!strstr(xml, "<Peer "));
	c.interface = "eth0";
	c.discovery = PX_BRIDGE_DISCOVERY_AUTO;
	PX_CHECK_INT_EQ(px_bridge_dds_config(&c, xml, sizeof(xml)), PX_OK);
	PX_CHECK(strstr(xml, "<NetworkInterface name=\"eth0\"/>"));
	PX_CHECK(!strstr(xml, "<Peer ") && !strstr(xml, "multicast=\""));
	PX_CHECK_INT_EQ(px_bridge_dds_config(&c, xml, 40), PX_E_RANGE);
	/* a security configuration passed through as a second source */
	c.security_file = "/etc/proxima/dds_security.xml";
	PX_CHECK_INT_EQ(px_bridge_dds_config(&c, xml, sizeof(xml)), PX_OK);
	PX_CHECK(strstr(xml, "</CycloneDDS>,file:///etc/proxima/dds_security.xml"));
	c.security_file = "a,b.xml";
	PX_CHECK_INT_EQ(px_bridge_dds_config(&c, xml, sizeof(xml)), PX_E_INVAL);
	c.security_file = NULL;
	c.interface = "lo\"/><x";
	PX_CHECK_INT_EQ(px_bridge_dds_config(&c, xml, sizeof(xml)), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_bridge_config_check(&c, why, sizeof(why)),
			PX_E_INVAL);
	PX_CHECK(strstr(why, "interface"));
}

/* Without Cyclone DDS: refused, naming the library. */
static void test_create_unsupported_or_refused(void)
{
	struct px_bridge_config c;
	struct px_bridge *b = (struct px_bridge *)&c;
	char msg[200];
	px_bridge_config_default(&c);
	c.ns = "bad//ns";
	PX_CHECK_INT_EQ(px_bridge_create(&c, &b, msg, sizeof(msg)),
			PX_HAVE_DDS ? PX_E_INVAL : PX_E_UNSUPPORTED);
	PX_CHECK(b == NULL);
	if (!PX_HAVE_DDS)
		PX_CHECK(strstr(msg, "built without Cyclone DDS"));
	else
		PX_CHECK(strstr(msg, "namespace"));
	PX_CHECK_INT_EQ(px_bridge_create(&c, NULL, msg, sizeof(msg)),
			PX_HAVE_DDS ? PX_E_INVAL : PX_E_UNSUPPORTED);
	px_bridge_free(NULL);
	{
		struct px_dev_config dc;
		struct px_bridge_dev_config bc = {.bridge = &c, .pose_topic = "tool_pose"};
		struct px_dev *d = (struct px_dev *)&c;
		px_dev_config_default(&dc);
		dc.name = "remote";
		PX_CHECK_INT_EQ(px_bridge_dev_create(&dc, &bc, &d, msg,
						     sizeof(msg)),
				PX_HAVE_DDS ? PX_E_INVAL : PX_E_UNSUPPORTED);
		PX_CHECK(d == NULL);
		PX_CHECK(strstr(msg, PX_HAVE_DDS ? "namespace"
						 : "built without Cyclone DDS"));
		bc.pose_topic = NULL;
		c.ns = "proxima";
		if (PX_HAVE_DDS)
			PX_CHECK_INT_EQ(px_bridge_dev_create(&dc, &bc, &d, msg,
							     sizeof(msg)),
					PX_E_INVAL);
	}
}

/* ---- two processes on loopback (Cyclone DDS) ----------------------- */

#if PX_HAVE_DDS

/* What the publisher sends: fixed values, exact in binary. */
static const int64_t STAMP_NS = 1700000000123456789LL;

static void known_sample(struct px_bridge_sample *s)
{
	memset(s, 0, sizeof(*s));
	s->stamp_ns = STAMP_NS;
	s->tool_m[0] = 0.125, s->tool_m[1] = -0.25, s->tool_m[2] = 0.375;
	s->tool_quat_xyzw[0] = 0.5, s->tool_quat_xyzw[1] = -0.5;
	s->tool_quat_xyzw[2] = 0.5, s->tool_quat_xyzw[3] = 0.5;
	s->proxy_m[0] = 0.1, s->proxy_m[1] = -0.2, s->proxy_m[2] = 0.3;
	s->force_n[0] = 1.5, s->force_n[1] = -2.5, s->force_n[2] = 3.25;
	s->torque_n_m[0] = 0.01, s->torque_n_m[1] = 0.02;
	s->torque_n_m[2] = -0.03;
	s->distance_valid = true;
	s->distance_m = -0.0025;
	s->tool_point_m[0] = 0.125, s->tool_point_m[1] = -0.25;
	s->tool_point_m[2] = 0.375;
	s->closest_m[0] = 0.125, s->closest_m[1] = -0.25;
	s->closest_m[2] = 0.3775;
	s->normal[0] = 0, s->normal[1] = 0, s->normal[2] = -1;
}

static void known_status(struct px_bridge_status *s)
{
	memset(s, 0, sizeof(*s));
	s->stamp_ns = STAMP_NS + 1000;
	s->loop_rate_hz = 1000.5;
	s->latency_p50_us = 12.5, s->latency_p99_us = 48.25;
	s->latency_max_us = 120.75;
	s->safe_state = true;
	s->cycles = 123456789012ULL, s->overruns = 3, s->faults = 7;
	s->safe_state_trips = 2, s->telemetry_dropped = 11;
}

static const char *const JOINTS[] = {"shoulder", "elbow", "wrist"};
static const double JPOS[] = {0.1, -0.2, 0.3}, JVEL[] = {-1, 2, -3},
		    JEFF[] = {5.5, 6.5, -7.5};
static const float CLOUD[] = {0, 0, 0, 1, 0, 0, 0, 1.5f, 0, 0, 0, -2.25f};

static int parse_role(const char *role, const char *kind, int *domain,
		      char *ns, size_t cap, double *seconds)
{
	char k[16];
	if (sscanf(role, "%15[^:]:%d:%127[^:]:%lf", k, domain, ns, seconds) != 4 ||
	    strcmp(k, kind))
		return -1;
	(void)cap;
	return 0;
}

static void role_config(struct px_bridge_config *c, int domain,
			const char *ns)
{
	px_bridge_config_default(c);
	c->enable = true;
	c->domain_id = domain;
	c->ns = ns;
	c->tool_pose_rate_hz = c->proxy_pose_rate_hz = 200;
	c->wrench_rate_hz = c->distance_rate_hz = 200;
	c->status_rate_hz = 50;
}

/* The second process: offers the known values over and over, the k-th
 * sample stamped k s after the first (the streams' rates count in the
 * samples' time), so a late subscriber still gets them on best-effort
 * topics, until SECONDS or the parent is gone. */
static int role_publish(const char *role)
{
	struct px_bridge_config c;
	struct px_bridge_sample s;
	struct px_bridge_status st;
	struct px_bridge *b;
	char ns[128], msg[256];
	double seconds;
	int domain;
	int64_t end;
	pid_t parent = getppid();
	if (parse_role(role, "publish", &domain, ns, sizeof(ns), &seconds))
		return 2;
	role_config(&c, domain, ns);
	if (px_bridge_create(&c, &b, msg, sizeof(msg)) != PX_OK) {
		fprintf(stderr, "publisher: %s\n", msg);
		return 1;
	}
	known_sample(&s);
	known_status(&st);
	end = mono_ns() + (int64_t)(seconds * 1e9);
	while (mono_ns() < end && getppid() == parent) {
		struct timespec ts = {0, 10000000};
		px_bridge_offer(b, &s);
		s.stamp_ns += 1000000000;
		px_bridge_offer_status(b, &st);
		px_bridge_publish_joint_state(b, STAMP_NS + 2000, 3, JOINTS,
					      JPOS, JVEL, JEFF);
		px_bridge_publish_cloud(b, STAMP_NS + 3000, CLOUD, 4);
		nanosleep(&ts, NULL);
	}
	px_bridge_free(b);
	return 0;
}

static dds_entity_t reader(dds_entity_t dp, const dds_topic_descriptor_t *d,
			   const char *ns, const char *name, int reliable)
{
	char topic[PX_BRIDGE_TOPIC_MAX];
	dds_qos_t *q = dds_create_qos();
	dds_entity_t t, r;
	px_bridge_topic_name(ns, name, topic, sizeof(topic));
	if (reliable)
		dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
	else
		dds_qset_reliability(q, DDS_RELIABILITY_BEST_EFFORT, 0);
	dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
	t = dds_create_topic(dp, d, topic, q, NULL);
	r = t < 0 ? t : dds_create_reader(dp, t, q, NULL);
	dds_delete_qos(q);
	return r;
}

/* Field checks that note the first mismatch (the child must be stopped
 * before the test may fail). */
static char bad[512];

static void eq(const char *what, double got, double want)
{
	if (!bad[0] && !(got == want))
		snprintf(bad, sizeof(bad), "%s: got %.17g, want %.17g", what,
			 got, want);
}

static void eq_s(const char *what, const char *got, const char *want)
{
	if (!bad[0] && (!got || strcmp(got, want)))
		snprintf(bad, sizeof(bad), "%s: got '%s', want '%s'", what,
			 got ? got : "(null)", want);
}

/* later: the stamp may be whole seconds later (the publisher's k-th
 * sample is stamped k s after the first) */
static void eq_header_k(const char *what, const std_msgs_msg_dds__Header_ *h,
			int64_t stamp_ns, int later)
{
	char w[96];
	int64_t sec = stamp_ns / 1000000000;
	snprintf(w, sizeof(w), "%s.header.stamp.sec", what);
	if (later && h->stamp.sec > sec && h->stamp.sec < sec + 100000)
		sec = h->stamp.sec;
	eq(w, h->stamp.sec, (double)sec);
	snprintf(w, sizeof(w), "%s.header.stamp.nanosec", what);
	eq(w, h->stamp.nanosec, (double)(stamp_ns % 1000000000));
	snprintf(w, sizeof(w), "%s.header.frame_id", what);
	eq_s(w, h->frame_id, "world");
}

static void eq_header(const char *what, const std_msgs_msg_dds__Header_ *h,
		      int64_t stamp_ns)
{
	eq_header_k(what, h, stamp_ns, 0);
}

static void eq3(const char *what, double x, double y, double z,
		const double v[3])
{
	char w[96];
	snprintf(w, sizeof(w), "%s.x", what);
	eq(w, x, v[0]);
	snprintf(w, sizeof(w), "%s.y", what);
	eq(w, y, v[1]);
	snprintf(w, sizeof(w), "%s.z", what);
	eq(w, z, v[2]);
}

static void check_msg(int t, const void *m)
{
	struct px_bridge_sample s;
	struct px_bridge_status st;
	known_sample(&s);
	known_status(&st);
	switch (t) {
	case PX_BRIDGE_TOOL_POSE:
	case PX_BRIDGE_PROXY_POSE: {
		const geometry_msgs_msg_dds__PoseStamped_ *p = m;
		const geometry_msgs_msg_dds__Point_ *o = &p->pose.position;
		const geometry_msgs_msg_dds__Quaternion_ *q = &p->pose.orientation;
		eq_header_k("pose", &p->header, STAMP_NS, 1);
		eq3("pose.position", o->x, o->y, o->z,
		    t == PX_BRIDGE_TOOL_POSE ? s.tool_m : s.proxy_m);
		eq3("pose.orientation", q->x, q->y, q->z, s.tool_quat_xyzw);
		eq("pose.orientation.w", q->w, s.tool_quat_xyzw[3]);
		break;
	}
	case PX_BRIDGE_WRENCH: {
		const geometry_msgs_msg_dds__WrenchStamped_ *w = m;
		eq_header_k("wrench", &w->header, STAMP_NS, 1);
		eq3("wrench.force", w->wrench.force.x, w->wrench.force.y,
		    w->wrench.force.z, s.force_n);
		eq3("wrench.torque", w->wrench.torque.x, w->wrench.torque.y,
		    w->wrench.torque.z, s.torque_n_m);
		break;
	}
	case PX_BRIDGE_CLOSEST_POINT: {
		const geometry_msgs_msg_dds__PointStamped_ *p = m;
		eq_header_k("closest_point", &p->header, STAMP_NS, 1);
		eq3("closest_point.point", p->point.x, p->point.y, p->point.z,
		    s.closest_m);
		break;
	}
	case PX_BRIDGE_DISTANCE: {
		const proxima_msgs_msg_dds__Distance_ *d = m;
		eq_header_k("distance", &d->header, STAMP_NS, 1);
		eq("distance.valid", d->valid, 1);
		eq("distance.distance_m", d->distance_m, s.distance_m);
		eq3("distance.tool_point", d->tool_point.x, d->tool_point.y,
		    d->tool_point.z, s.tool_point_m);
		eq3("distance.closest_point", d->closest_point.x,
		    d->closest_point.y, d->closest_point.z, s.closest_m);
		eq3("distance.normal", d->normal.x, d->normal.y, d->normal.z,
		    s.normal);
		break;
	}
	case PX_BRIDGE_STATUS: {
		const proxima_msgs_msg_dds__Status_ *p = m;
		eq_header("status", &p->header, st.stamp_ns);
		eq("status.loop_rate_hz", p->loop_rate_hz, st.loop_rate_hz);
		eq("status.latency_p50_us", p->latency_p50_us, st.latency_p50_us);
		eq("status.latency_p99_us", p->latency_p99_us, st.latency_p99_us);
		eq("status.latency_max_us", p->latency_max_us, st.latency_max_us);
		eq("status.safe_state", p->safe_state, 1);
		eq("status.cycles", (double)p->cycles, (double)st.cycles);
		eq("status.overruns", (double)p->overruns, 3);
		eq("status.faults", (double)p->faults, 7);
		eq("status.safe_state_trips", (double)p->safe_state_trips, 2);
		eq("status.telemetry_dropped", (double)p->telemetry_dropped, 11);
		break;
	}
	case PX_BRIDGE_JOINT_STATES: {
		const sensor_msgs_msg_dds__JointState_ *j = m;
		uint32_t i;
		eq_header("joint_states", &j->header, STAMP_NS + 2000);
		eq("joint_states.name length", j->name._length, 3);
		eq("joint_states.position length", j->position._length, 3);
		eq("joint_states.velocity length", j->velocity._length, 3);
		eq("joint_states.effort length", j->effort._length, 3);
		for (i = 0; i < 3 && !bad[0]; i++) {
			eq_s("joint_states.name[i]", j->name._buffer[i], JOINTS[i]);
			eq("joint_states.position[i]", j->position._buffer[i], JPOS[i]);
			eq("joint_states.velocity[i]", j->velocity._buffer[i], JVEL[i]);
			eq("joint_states.effort[i]", j->effort._buffer[i], JEFF[i]);
		}
		break;
	}
	case PX_BRIDGE_CLOUD: {
		const sensor_msgs_msg_dds__PointCloud2_ *c = m;
		const union {
			uint16_t u;
			uint8_t b[2];
		} order = {1};
		uint32_t i;
		eq_header("cloud", &c->header, STAMP_NS + 3000);
		eq("cloud.height", c->height, 1);
		eq("cloud.width", c->width, 4);
		eq("cloud.fields length", c->fields._length, 3);
		for (i = 0; i < 3 && !bad[0]; i++) {
			const sensor_msgs_msg_dds__PointField_ *f =
				&c->fields._buffer[i];
			eq_s("cloud.fields[i].name", f->name,
			     i == 0 ? "x" : i == 1 ? "y" : "z");
			eq("cloud.fields[i].offset", f->offset, 4.0 * i);
			eq("cloud.fields[i].datatype", f->datatype, 7);
			eq("cloud.fields[i].count", f->count, 1);
		}
		eq("cloud.is_bigendian", c->is_bigendian, order.b[0] == 0);
		eq("cloud.point_step", c->point_step, 12);
		eq("cloud.row_step", c->row_step, 48);
		eq("cloud.data length", c->data._length, sizeof(CLOUD));
		eq("cloud.is_dense", c->is_dense, 1);
		if (!bad[0] && c->data._length == sizeof(CLOUD) &&
		    memcmp(c->data._buffer, CLOUD, sizeof(CLOUD)))
			snprintf(bad, sizeof(bad), "cloud.data differs");
		break;
	}
	default:
		break;
	}
}

static const dds_topic_descriptor_t *desc_of(int t)
{
	return px_bridge_topic_descriptor(t);
}

/* Take at most one sample; 1 and the check made when it had data. */
static int take_check(dds_entity_t r, int t)
{
	void *buf[1] = {NULL};
	dds_sample_info_t info[1];
	int n = dds_take(r, buf, info, 1, 1), got = 0;
	if (n > 0 && info[0].valid_data) {
		check_msg(t, buf[0]);
		got = 1;
	}
	if (n > 0)
		dds_return_loan(r, buf, n);
	return got;
}

/* The second process: this binary as publisher. */
static pid_t spawn(const char *role)
{
	return spawn_role("PX_BRIDGE_TEST_ROLE", role);
}

static int test_domain(void)
{
	return 1 + (int)(getpid() % 200);
}

static void test_round_trip_two_processes(void)
{
	char role[256], ns[64];
	dds_entity_t dom = 0, dp, dp2, rd[PX_BRIDGE_TOPIC__COUNT], wrong, strict;
	int got[PX_BRIDGE_TOPIC__COUNT] = {0}, n_got = 0, t, domain;
	int wrong_matched = -1, strict_matched = -1, incompatible = 0;
	uint32_t policy = 0;
	int64_t end;
	pid_t child;
	PX_NEEDS(DDS);
	domain = test_domain();
	snprintf(ns, sizeof(ns), "pxtest_%d", (int)getpid());
	snprintf(role, sizeof(role), "publish:%d:%s:30", domain, ns);
	child = spawn(role);
	PX_CHECK(child > 0);
	bad[0] = '\0';
	dp = join(domain, &dom);
	/* a second participant for the wrong readers, as another node */
	dp2 = dp > 0 ? dds_create_participant((dds_domainid_t)domain, NULL, NULL)
		     : -1;
	if (dp <= 0 || dp2 <= 0) {
		stop_child(child);
		PX_CHECK_MSG(0, "cannot join domain %d: %s", domain,
			     dds_strretcode(dp <= 0 ? dp : dp2));
	}
	for (t = 0; t < PX_BRIDGE_TOPIC__COUNT; t++)
		rd[t] = reader(dp, desc_of(t), ns, px_bridge_topic_short_name(t),
			       px_bridge_topic_reliable(t));
	/* the wrong type on the tool pose; reliable on a best-effort stream */
	wrong = reader(dp2, &geometry_msgs_msg_dds__PointStamped__desc, ns,
		       "tool_pose", 0);
	strict = reader(dp2, &geometry_msgs_msg_dds__WrenchStamped__desc, ns,
			"wrench", 1);
	dds_set_status_mask(strict, DDS_REQUESTED_INCOMPATIBLE_QOS_STATUS |
					    DDS_SUBSCRIPTION_MATCHED_STATUS);
	end = mono_ns() + 20000000000LL; /* discovery and data: 20 s at most */
	while (n_got < PX_BRIDGE_TOPIC__COUNT && !bad[0] && mono_ns() < end) {
		for (t = 0; t < PX_BRIDGE_TOPIC__COUNT; t++)
			if (!got[t] && rd[t] > 0 && take_check(rd[t], t)) {
				got[t] = 1;
				n_got++;
			}
		dds_sleepfor(DDS_MSECS(5));
	}
	/* by now the publisher is known to every reader; the mismatched
	 * ones have had the same discovery (and get 2 s more) */
	end = mono_ns() + 2000000000LL;
	do {
		dds_requested_incompatible_qos_status_t iq;
		dds_subscription_matched_status_t m;
		if (dds_get_requested_incompatible_qos_status(strict, &iq) == 0) {
			incompatible = (int)iq.total_count;
			policy = iq.last_policy_id;
		}
		if (dds_get_subscription_matched_status(strict, &m) == 0)
			strict_matched = (int)m.total_count;
		if (dds_get_subscription_matched_status(wrong, &m) == 0)
			wrong_matched = (int)m.total_count;
		if (incompatible > 0 && mono_ns() > end - 1000000000LL)
			break;
		dds_sleepfor(DDS_MSECS(20));
	} while (mono_ns() < end);
	stop_child(child);
	dds_delete(dp2);
	dds_delete(dp);
	if (dom > 0)
		dds_delete(dom);
	for (t = 0; t < PX_BRIDGE_TOPIC__COUNT; t++)
		PX_CHECK_MSG(rd[t] > 0 && got[t], "nothing received on %s",
			     px_bridge_topic_short_name(t));
	PX_CHECK_MSG(!bad[0], "%s", bad);
	PX_CHECK_MSG(wrong > 0 && wrong_matched == 0,
		     "a PointStamped_ reader matched the PoseStamped_ topic "
		     "(%d)", wrong_matched);
	PX_CHECK_MSG(strict > 0 && incompatible > 0 &&
			     policy == DDS_RELIABILITY_QOS_POLICY_ID,
		     "reliable reader on a best-effort stream: %d incompatible, "
		     "policy %u",
		     incompatible, policy);
	PX_CHECK_INT_EQ(strict_matched, 0);
}

static int take_wrench(dds_entity_t r, double w[6])
{
	void *buf[1] = {NULL};
	dds_sample_info_t info[1];
	int n = dds_take(r, buf, info, 1, 1), got = 0;
	if (n > 0 && info[0].valid_data) {
		const geometry_msgs_msg_dds__WrenchStamped_ *m = buf[0];
		w[0] = m->wrench.force.x, w[1] = m->wrench.force.y;
		w[2] = m->wrench.force.z, w[3] = m->wrench.torque.x;
		w[4] = m->wrench.torque.y, w[5] = m->wrench.torque.z;
		got = 1;
	}
	if (n > 0)
		dds_return_loan(r, buf, n);
	return got;
}

/* The "dds" device: the bridge's tool pose as its pose input (stale once
 * the stream stops), its force command on a wrench topic, zero after
 * px_dev_safe(). */
static void test_dds_device(void)
{
	struct px_bridge_config c;
	struct px_bridge_dev_config bc;
	struct px_dev_config dc;
	struct px_bridge_sample s;
	struct px_pose_sample p;
	struct px_force_cmd cmd = {{1.5, -2.0, 0.25}, {0.0, 0.5, 0.0}, 1};
	struct px_dev_status st;
	struct px_bridge *b = NULL;
	struct px_dev *d = NULL;
	dds_entity_t dom = 0, dp, rd;
	char ns[64], msg[256];
	double w[6] = {0}, zero_seen = 0;
	int fresh = 0, got = 0, stale, rc_safe;
	int64_t end;
	PX_NEEDS(DDS);
	snprintf(ns, sizeof(ns), "pxdev_%d", (int)getpid());
	role_config(&c, test_domain() + 1, ns);
	c.tool_pose_rate_hz = 500;
	PX_CHECK_MSG(px_bridge_create(&c, &b, msg, sizeof(msg)) == PX_OK, "%s",
		     msg);
	px_dev_config_default(&dc);
	dc.name = "remote";
	dc.stale_timeout_ns = 50000000;
	memset(&bc, 0, sizeof(bc));
	bc.bridge = &c;
	bc.pose_topic = "tool_pose";
	bc.command_topic = "command_wrench";
	PX_CHECK_MSG(px_bridge_dev_create(&dc, &bc, &d, msg, sizeof(msg)) ==
			     PX_OK,
		     "%s", msg);
	PX_CHECK_INT_EQ(px_dev_caps(d), PX_DEV_CAP_POSE | PX_DEV_CAP_FORCE);
	PX_CHECK_INT_EQ(px_dev_start(d), PX_OK);
	dp = join((int)c.domain_id, &dom);
	rd = reader(dp, px_bridge_topic_descriptor(PX_BRIDGE_WRENCH), ns,
		    "command_wrench", 0);
	known_sample(&s);
	end = mono_ns() + 10000000000LL;
	while (!fresh && mono_ns() < end) {
		px_bridge_offer(b, &s);
		s.stamp_ns += 2000000;
		dds_sleepfor(DDS_MSECS(2));
		if (px_dev_pose_read(d, px_dev_mono_ns(), &p) >= 0 && p.valid &&
		    !p.stale)
			fresh = 1;
	}
	/* the stream stops: stale after the device's timeout */
	dds_sleepfor(DDS_MSECS(150));
	px_dev_pose_read(d, px_dev_mono_ns(), &p);
	stale = p.stale;
	while (!got && mono_ns() < end) {
		px_dev_force_write(d, &cmd, px_dev_mono_ns());
		dds_sleepfor(DDS_MSECS(2));
		got = take_wrench(rd, w);
	}
	rc_safe = px_dev_safe(d, px_dev_mono_ns());
	end = mono_ns() + 5000000000LL;
	while (!zero_seen && mono_ns() < end) {
		double z[6];
		if (take_wrench(rd, z) && !z[0] && !z[1] && !z[2] && !z[3] &&
		    !z[4] && !z[5])
			zero_seen = 1;
		dds_sleepfor(DDS_MSECS(2));
	}
	px_dev_status(d, &st);
	px_dev_free(d);
	px_bridge_free(b);
	dds_delete(dp);
	if (dom > 0)
		dds_delete(dom);
	PX_CHECK_MSG(fresh, "no fresh pose from the stream");
	PX_CHECK_NEAR(p.pos_m.x, s.tool_m[0], 0);
	PX_CHECK_NEAR(p.pos_m.y, s.tool_m[1], 0);
	PX_CHECK_NEAR(p.pos_m.z, s.tool_m[2], 0);
	/* q (w x y z) and -q are the same rotation */
	PX_CHECK_NEAR(fabs(p.q.w * s.tool_quat_xyzw[3] + p.q.x * s.tool_quat_xyzw[0] +
			   p.q.y * s.tool_quat_xyzw[1] + p.q.z * s.tool_quat_xyzw[2]),
		      1.0, 1e-12);
	PX_CHECK_MSG(stale, "the pose stayed fresh 150 ms after the stream stopped");
	PX_CHECK_MSG(got, "the command never arrived");
	PX_CHECK(w[0] == 1.5 && w[1] == -2.0 && w[2] == 0.25 && w[3] == 0 &&
		 w[4] == 0.5 && w[5] == 0);
	PX_CHECK_INT_EQ(rc_safe, PX_OK);
	PX_CHECK_MSG(zero_seen, "no zero wrench after px_dev_safe");
	PX_CHECK(st.safe_writes >= 1 && st.outputs_safe == 1);
	PX_CHECK(!strcmp(st.backend, "dds"));
}

/* For test_bridge_run.sh: exit 0 once proxima-run's tool pose, wrench and
 * status arrived, 1 after SECONDS without. */
static int role_listen(const char *role)
{
	static const int want[] = {PX_BRIDGE_TOOL_POSE, PX_BRIDGE_WRENCH,
				   PX_BRIDGE_STATUS};
	dds_entity_t dom = 0, dp, rd[3];
	int got[3] = {0}, i, n = 0, domain;
	char ns[128];
	double seconds;
	int64_t end;
	if (parse_role(role, "listen", &domain, ns, sizeof(ns), &seconds))
		return 2;
	dp = join(domain, &dom);
	if (dp <= 0) {
		fprintf(stderr, "listen: %s\n", dds_strretcode(dp));
		return 1;
	}
	for (i = 0; i < 3; i++)
		rd[i] = reader(dp, desc_of(want[i]), ns,
			       px_bridge_topic_short_name(want[i]),
			       px_bridge_topic_reliable(want[i]));
	end = mono_ns() + (int64_t)(seconds * 1e9);
	while (n < 3 && mono_ns() < end) {
		for (i = 0; i < 3; i++) {
			void *buf[1] = {NULL};
			dds_sample_info_t info[1];
			int k = got[i] ? 0 : dds_take(rd[i], buf, info, 1, 1);
			if (k > 0 && info[0].valid_data) {
				got[i] = 1;
				n++;
				printf("listen: %s received\n",
				       px_bridge_topic_short_name(want[i]));
				fflush(stdout);
			}
			if (k > 0)
				dds_return_loan(rd[i], buf, k);
		}
		dds_sleepfor(DDS_MSECS(5));
	}
	dds_delete(dp);
	if (dom > 0)
		dds_delete(dom);
	return n == 3 ? 0 : 1;
}

/* A peer that sends parameter sets (proxima_msgs/Params, reliable) to
 * rt/NAMESPACE/TOPIC once a reader matched (at most 10 s): COUNT sets
 * each with one value non-finite or far out of any range, or with COUNT
 * 0 one set of modest values. Exit 0 when all were written. */
static int role_params(const char *role)
{
	char ns[128], *slash;
	double count;
	int domain, i, n, fails = 0;
	dds_entity_t dom = 0, dp, t, w;
	dds_qos_t *q;
	dds_publication_matched_status_t st;
	int64_t end = mono_ns() + 10000000000LL;
	char topic[PX_BRIDGE_TOPIC_MAX];
	if (parse_role(role, "params", &domain, ns, sizeof(ns), &count) ||
	    !(slash = strrchr(ns, '/')))
		return 2;
	*slash = '\0';
	dp = join(domain, &dom);
	px_bridge_topic_name(ns, slash + 1, topic, sizeof(topic));
	q = dds_create_qos();
	dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
	dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
	t = dds_create_topic(dp, &proxima_msgs_msg_dds__Params__desc, topic, q,
			     NULL);
	w = t < 0 ? t : dds_create_writer(dp, t, q, NULL);
	dds_delete_qos(q);
	if (w < 0)
		return 1;
	do
		dds_sleepfor(DDS_MSECS(5));
	while (dds_get_publication_matched_status(w, &st) == 0 &&
	       !st.current_count && mono_ns() < end);
	n = count > 0 ? (int)count : 1;
	for (i = 0; i < n; i++) {
		proxima_msgs_msg_dds__Params_ m;
		memset(&m, 0, sizeof(m));
		m.header.frame_id = "world";
		m.stiffness_n_per_m = 100;
		m.damping_n_s_per_m = 0.1;
		m.max_force_n = 1;
		m.speed_scale = 0.5;
		switch (count > 0 ? i % 5 : -1) {
		case 0: m.stiffness_n_per_m = NAN; break;
		case 1: m.stiffness_n_per_m = 1e12; break;
		case 2: m.damping_n_s_per_m = -1; break;
		case 3: m.max_force_n = INFINITY; break;
		case 4: m.speed_scale = 7; break;
		default: break;
		}
		fails += dds_write(w, &m) != DDS_RETCODE_OK;
		dds_sleepfor(DDS_MSECS(2));
	}
	dds_sleepfor(DDS_MSECS(100)); /* reliable: let the last arrive */
	dds_delete(dp);
	if (dom > 0)
		dds_delete(dom);
	return fails ? 1 : 0;
}

#else

static void test_round_trip_two_processes(void)
{
	PX_NEEDS(DDS);
}

static void test_dds_device(void)
{
	PX_NEEDS(DDS);
}

#endif

static const struct px_test tests[] = {
	PX_T(test_config_defaults_and_values),
	PX_T(test_config_errors),
	PX_T(test_docs_cover_bridge_keys),
	PX_T(test_topic_names_and_types),
	PX_T(test_dds_config),
	PX_T(test_create_unsupported_or_refused),
	PX_T(test_round_trip_two_processes),
	PX_T(test_dds_device),
};

int main(int argc, char **argv)
{
	const char *role = getenv("PX_BRIDGE_TEST_ROLE");
	if (role) {
#if PX_HAVE_DDS
		if (!strncmp(role, "publish:", 8))
			return role_publish(role);
		if (!strncmp(role, "listen:", 7))
			return role_listen(role);
		if (!strncmp(role, "params:", 7))
			return role_params(role);
#endif
		fprintf(stderr, "unknown or unsupported role '%s'\n", role);
		return 2;
	}
	return px_test_main(argv[0], tests, sizeof(tests) / sizeof(tests[0]),
			    argc, argv);
}
