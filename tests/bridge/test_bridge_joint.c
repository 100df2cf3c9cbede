/*
 * A remote arm over DDS (px_bridge_dev_config's joint_state_topic and
 * joint_command_topic): the check of a sensor_msgs/JointState (joints
 * by name among others, lengths, non-finite values), and on real
 * Cyclone DDS over loopback a second process (this binary again) as the
 * arm: it publishes its joint states, its joints in another order and
 * one more, and takes the device's commands as its new state, so what
 * the cycle commands comes back field by field; the hold sends
 * velocity 0 at the arm's position; the arm killed, the states age.
 *
 * Role by environment: PX_JOINT_TEST_ROLE=arm:DOMAIN:NAMESPACE:SECONDS
 * (joint states on rt/NAMESPACE/arm/joint_states every 2 ms, commands
 * from rt/NAMESPACE/arm/joint_commands).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "px_bridge.h"
#include "px_features.h"
#include "px_test.h"

#if PX_HAVE_DDS
#include <dds/dds.h>

#include "bridge_internal.h"
#include "bridge_test.h"
#include "sensor_msgs.h"

static const char *const MINE[3] = {"shoulder", "elbow", "wrist"};
/* the arm's order: another one, and a joint of its own */
static const char *const ARM[4] = {"wrist", "gripper", "shoulder", "elbow"};

static void joint_msg(sensor_msgs_msg_dds__JointState_ *m, char **names,
		      double *pos, double *vel, uint32_t n)
{
	memset(m, 0, sizeof(*m));
	m->header.frame_id = "world";
	m->name._length = m->name._maximum = n;
	m->name._buffer = names;
	m->position._length = m->position._maximum = n;
	m->position._buffer = pos;
	m->velocity._length = m->velocity._maximum = vel ? n : 0;
	m->velocity._buffer = vel;
}

static void test_joint_state_check(void)
{
	sensor_msgs_msg_dds__JointState_ m;
	struct px_bridge_joint_state st;
	double pos[4] = {0.5, 9, -0.25, 1.5}, vel[4] = {1, 2, 3, 4};
	const char *why;
	int i;
	joint_msg(&m, (char **)ARM, pos, vel, 4);
	why = px__bridge_joint_state(&m, MINE, 3, &st);
	PX_CHECK_MSG(!why, "%s", why);
	PX_CHECK(st.position_rad[0] == -0.25 && st.position_rad[1] == 1.5 &&
		 st.position_rad[2] == 0.5);
	PX_CHECK(st.velocity_rad_per_s[0] == 3 && st.velocity_rad_per_s[1] == 4 &&
		 st.velocity_rad_per_s[2] == 1);
	joint_msg(&m, (char **)ARM, pos, NULL, 4); /* no velocities: 0 */
	PX_CHECK(!px__bridge_joint_state(&m, MINE, 3, &st));
	PX_CHECK(st.velocity_rad_per_s[0] == 0 && st.position_rad[2] == 0.5);
	for (i = 0; i < 5; i++) {
		static const char *const want[] = {"lengths", "lengths", "joint",
						   "non-finite", "non-finite"};
		double p[4] = {0.5, 9, -0.25, 1.5}, v[4] = {1, 2, 3, 4};
		joint_msg(&m, (char **)ARM, p, v, 4);
		switch (i) {
		case 0: m.position._length = 3; break;
		case 1: m.velocity._length = 2; break;
		case 2: m.name._length = 3; m.position._length = 3;
			m.velocity._length = 3; break; /* no elbow */
		case 3: p[2] = NAN; break;
		case 4: v[0] = INFINITY; break;
		}
		why = px__bridge_joint_state(&m, MINE, 3, &st);
		PX_CHECK_MSG(why && !strcmp(why, want[i]), "case %d: %s", i,
			     why ? why : "accepted");
	}
	/* a joint the arm does not have is not the device's concern */
	joint_msg(&m, (char **)ARM, pos, vel, 4);
	PX_CHECK(!px__bridge_joint_state(&m, (const char *const[]){"elbow"}, 1, &st));
}

static dds_entity_t endpoint(dds_entity_t dp, const char *ns, const char *name,
			     int reader)
{
	char topic[PX_BRIDGE_TOPIC_MAX];
	dds_qos_t *q = dds_create_qos();
	dds_entity_t t, e;
	px_bridge_topic_name(ns, name, topic, sizeof(topic));
	dds_qset_reliability(q, DDS_RELIABILITY_BEST_EFFORT, 0);
	dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
	t = dds_create_topic(dp, &sensor_msgs_msg_dds__JointState__desc, topic, q,
			     NULL);
	e = t < 0 ? t : reader ? dds_create_reader(dp, t, q, NULL)
			       : dds_create_writer(dp, t, q, NULL);
	dds_delete_qos(q);
	return e;
}

/* The arm: its state is the newest command (names mapped), published
 * every 2 ms with its own joint order. */
static int role_arm(const char *role)
{
	char ns[128];
	double seconds, pos[4] = {0.1, 0.0, 0.2, 0.3}, vel[4] = {0};
	int domain;
	dds_entity_t dom = 0, dp, r, w;
	sensor_msgs_msg_dds__JointState_ m;
	pid_t parent = getppid();
	int64_t end;
	if (sscanf(role, "arm:%d:%127[^:]:%lf", &domain, ns, &seconds) != 3)
		return 2;
	dp = join(domain, &dom);
	r = endpoint(dp, ns, "arm/joint_commands", 1);
	w = endpoint(dp, ns, "arm/joint_states", 0);
	if (dp < 0 || r < 0 || w < 0)
		return 1;
	end = mono_ns() + (int64_t)(seconds * 1e9);
	while (mono_ns() < end && getppid() == parent) {
		void *buf[1] = {NULL};
		dds_sample_info_t info[1];
		int n = dds_take(r, buf, info, 1, 1), i, k;
		if (n > 0 && info[0].valid_data) {
			const sensor_msgs_msg_dds__JointState_ *c = buf[0];
			for (i = 0; i < (int)c->name._length; i++)
				for (k = 0; k < 4; k++)
					if (!strcmp(c->name._buffer[i], ARM[k]) &&
					    c->position._length == c->name._length &&
					    c->velocity._length == c->name._length) {
						pos[k] = c->position._buffer[i];
						vel[k] = c->velocity._buffer[i];
					}
		}
		if (n > 0)
			dds_return_loan(r, buf, n);
		joint_msg(&m, (char **)ARM, pos, vel, 4);
		dds_write(w, &m);
		dds_sleepfor(DDS_MSECS(2));
	}
	dds_delete(dp);
	if (dom > 0)
		dds_delete(dom);
	return 0;
}

/* The device commands, the arm answers with it; safe: velocity 0 at the
 * arm's position; killed: the state ages. */
static void test_remote_arm(void)
{
	struct px_bridge_config c;
	struct px_bridge_dev_config bc;
	struct px_dev_config dc;
	struct px_bridge_joint_state st, first;
	struct px_bridge_dev_counts n;
	struct px_dev *d = NULL;
	static const double cmd_pos[3] = {-0.5, 0.75, 1.25}, cmd_vel[3] = {0.5, -1, 2};
	char ns[64], role[256], msg[256];
	int got_first = 0, echoed = 0, held = 0, aged = 0, rc_safe;
	int64_t end, t_last = 0;
	pid_t child;
	PX_NEEDS(DDS);
	memset(&first, 0, sizeof(first));
	snprintf(ns, sizeof(ns), "pxjoint_%d", (int)getpid());
	px_bridge_config_default(&c);
	c.domain_id = 1 + (int)(getpid() % 200);
	c.ns = ns;
	px_dev_config_default(&dc);
	dc.name = "arm";
	memset(&bc, 0, sizeof(bc));
	bc.bridge = &c;
	bc.joint_state_topic = "arm/joint_states";
	bc.joint_command_topic = "arm/joint_commands";
	bc.joint_names = MINE;
	bc.n_joints = 3;
	bc.connect_timeout_ns = 10000000000LL;
	PX_CHECK_MSG(px_bridge_dev_create(&dc, &bc, &d, msg, sizeof(msg)) == PX_OK,
		     "%s", msg);
	snprintf(role, sizeof(role), "arm:%d:%s:20", (int)c.domain_id, ns);
	child = spawn_role("PX_JOINT_TEST_ROLE", role);
	if (px_dev_start(d) != PX_OK) {
		stop_child(child);
		px_dev_free(d);
		PX_CHECK_MSG(0, "the arm did not connect within 10 s");
	}
	end = mono_ns() + 10000000000LL;
	while (!echoed && mono_ns() < end) {
		if (px_bridge_dev_joint_state(d, &st) == 1) {
			if (!got_first++)
				first = st;
			echoed = !memcmp(st.position_rad, cmd_pos, sizeof(cmd_pos)) &&
				 !memcmp(st.velocity_rad_per_s, cmd_vel, sizeof(cmd_vel));
		}
		if (got_first)
			px_bridge_dev_joint_command(d, cmd_pos, cmd_vel);
		dds_sleepfor(DDS_MSECS(2));
	}
	rc_safe = px_bridge_dev_joint_hold(d);
	end = mono_ns() + 5000000000LL;
	while (!held && mono_ns() < end) {
		if (px_bridge_dev_joint_state(d, &st) == 1)
			held = !memcmp(st.position_rad, cmd_pos, sizeof(cmd_pos)) &&
			       st.velocity_rad_per_s[0] == 0 &&
			       st.velocity_rad_per_s[1] == 0 &&
			       st.velocity_rad_per_s[2] == 0;
		dds_sleepfor(DDS_MSECS(2));
	}
	stop_child(child);
	dds_sleepfor(DDS_MSECS(50));
	if (px_bridge_dev_joint_state(d, &st) == 1) {
		t_last = st.t_ns;
		dds_sleepfor(DDS_MSECS(100));
		aged = px_bridge_dev_joint_state(d, &st) == 1 && st.t_ns == t_last &&
		       px_dev_mono_ns() - st.t_ns >= 100000000;
	}
	px_bridge_dev_counts(d, &n);
	px_dev_free(d);
	PX_CHECK_MSG(got_first, "no joint state from the arm");
	PX_CHECK(first.position_rad[0] == 0.2 && first.position_rad[1] == 0.3 &&
		 first.position_rad[2] == 0.1);
	PX_CHECK_MSG(echoed, "the command did not come back field by field");
	PX_CHECK_INT_EQ(rc_safe, PX_OK);
	PX_CHECK_MSG(held, "no velocity 0 at the arm's position after the hold "
			   "(%g %g %g, %g %g %g)", st.position_rad[0], st.position_rad[1],
		     st.position_rad[2], st.velocity_rad_per_s[0],
		     st.velocity_rad_per_s[1], st.velocity_rad_per_s[2]);
	PX_CHECK_MSG(aged, "the joint state kept arriving after the arm was killed");
	PX_CHECK_MSG(n.joint_states_in >= 3 && n.joint_states_refused == 0 &&
			     n.joint_commands_out > 1,
		     "%llu states in, %llu refused, %llu commands out",
		     (unsigned long long)n.joint_states_in,
		     (unsigned long long)n.joint_states_refused,
		     (unsigned long long)n.joint_commands_out);
}

#else

static void test_joint_state_check(void) { PX_NEEDS(DDS); }
static void test_remote_arm(void) { PX_NEEDS(DDS); }

#endif

static const struct px_test tests[] = {
	PX_T(test_joint_state_check),
	PX_T(test_remote_arm),
};

int main(int argc, char **argv)
{
	const char *role = getenv("PX_JOINT_TEST_ROLE");
	if (role) {
#if PX_HAVE_DDS
		if (!strncmp(role, "arm:", 4))
			return role_arm(role);
#endif
		fprintf(stderr, "unknown or unsupported role '%s'\n", role);
		return 2;
	}
	return px_test_main(argv[0], tests, sizeof(tests) / sizeof(tests[0]),
			    argc, argv);
}
