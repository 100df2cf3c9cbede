/* A dds device's remote arm (px_bridge_dev_config's joint_state_topic
 * and joint_command_topic): joint states (sensor_msgs/JointState)
 * checked and mapped by name onto the configured joints, handed to the
 * cycle through a seqlock slot stamped at receipt; the cycle's joint
 * commands sent as JointState (names, position target, velocity) by the
 * device's thread. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <dds/dds.h>

#include "bridge_internal.h"
#include "sensor_msgs.h"

struct joint_cmd {
	double pos[PX_BRIDGE_MAX_JOINTS], vel[PX_BRIDGE_MAX_JOINTS];
};
_Static_assert(sizeof(struct px_bridge_joint_state) <=
		       sizeof(((struct px__slot *)0)->v),
	       "a joint state fits a slot");

struct bridge_joints {
	char frame[PX_BRIDGE_NAME_MAX];
	char names[PX_BRIDGE_MAX_JOINTS][64];
	char *name_ptr[PX_BRIDGE_MAX_JOINTS];
	size_t n;
	dds_entity_t reader, writer;       /* 0 none */
	struct px__slot state, cmd;
	uint64_t cmd_seq;                  /* the thread's: last sent */
	_Atomic uint64_t n_in, n_refused, n_out;
};

void px__slot_put(struct px__slot *s, const void *v, size_t n)
{
	uint64_t q = atomic_load_explicit(&s->seq, memory_order_relaxed);
	atomic_store_explicit(&s->seq, q + 1, memory_order_relaxed);
	atomic_thread_fence(memory_order_release);
	memcpy(s->v, v, n);
	atomic_store_explicit(&s->seq, q + 2, memory_order_release);
}

int px__slot_get(struct px__slot *s, void *v, size_t n, uint64_t *last)
{
	int tries;
	for (tries = 0; tries < 16; tries++) {
		uint64_t s0 = atomic_load_explicit(&s->seq, memory_order_acquire);
		if (s0 == *last || (s0 & 1))
			return 0;
		memcpy(v, s->v, n);
		atomic_thread_fence(memory_order_acquire);
		if (atomic_load_explicit(&s->seq, memory_order_relaxed) == s0) {
			*last = s0;
			return 1;
		}
	}
	return 0;
}

const char *px__bridge_joint_state(const void *msg, const char *const *names,
				   size_t n, struct px_bridge_joint_state *out)
{
	const sensor_msgs_msg_dds__JointState_ *m = msg;
	uint32_t len = m->name._length;
	size_t i;
	uint32_t k;
	if (m->position._length != len ||
	    (m->velocity._length && m->velocity._length != len))
		return "lengths";
	for (i = 0; i < n; i++) {
		for (k = 0; k < len; k++)
			if (m->name._buffer[k] && !strcmp(m->name._buffer[k], names[i]))
				break;
		if (k == len)
			return "joint";
		out->position_rad[i] = m->position._buffer[k];
		out->velocity_rad_per_s[i] =
			m->velocity._length ? m->velocity._buffer[k] : 0.0;
		if (!isfinite(out->position_rad[i]) ||
		    !isfinite(out->velocity_rad_per_s[i]))
			return "non-finite";
	}
	return NULL;
}

static void take_states(struct bridge_joints *j)
{
	for (;;) {
		void *buf[1] = {NULL};
		dds_sample_info_t info[1];
		struct px_bridge_joint_state st;
		int k = dds_take(j->reader, buf, info, 1, 1);
		if (k <= 0)
			return;
		if (info[0].valid_data) {
			memset(&st, 0, sizeof(st));
			if (px__bridge_joint_state(buf[0], (const char *const *)j->name_ptr,
						   j->n, &st)) {
				atomic_fetch_add(&j->n_refused, 1);
			} else {
				st.t_ns = px_dev_mono_ns();
				px__slot_put(&j->state, &st, sizeof(st));
				atomic_fetch_add(&j->n_in, 1);
			}
		}
		dds_return_loan(j->reader, buf, k);
	}
}

static int send_cmd(struct bridge_joints *j, const struct joint_cmd *c)
{
	sensor_msgs_msg_dds__JointState_ m;
	dds_return_t rc;
	memset(&m, 0, sizeof(m));
	px__bridge_header_now(&m.header, j->frame);
	m.name._length = m.name._maximum = (uint32_t)j->n;
	m.name._buffer = j->name_ptr;
	m.position._length = m.position._maximum = (uint32_t)j->n;
	m.position._buffer = (double *)c->pos;
	m.velocity._length = m.velocity._maximum = (uint32_t)j->n;
	m.velocity._buffer = (double *)c->vel;
	rc = dds_write(j->writer, &m);
	if (rc != DDS_RETCODE_OK)
		return PX_E_IO;
	atomic_fetch_add(&j->n_out, 1);
	return PX_OK;
}

void px__bridge_joints_take(struct bridge_joints *j)
{
	struct joint_cmd c;
	if (!j)
		return;
	if (j->reader > 0)
		take_states(j);
	if (j->writer > 0 && px__slot_get(&j->cmd, &c, sizeof(c), &j->cmd_seq))
		send_cmd(j, &c);
}

int px__bridge_joints_hold(struct bridge_joints *j)
{
	struct px_bridge_joint_state st;
	struct joint_cmd c;
	uint64_t none = 0;
	if (!j || j->writer <= 0)
		return PX_OK;
	memset(&c, 0, sizeof(c));
	if (px__slot_get(&j->state, &st, sizeof(st), &none)) {
		memcpy(c.pos, st.position_rad, sizeof(c.pos));
	} else {
		none = 0; /* no state yet: the last commanded position */
		px__slot_get(&j->cmd, &c, sizeof(c), &none);
	}
	memset(c.vel, 0, sizeof(c.vel));
	/* the cycle's next command is this one until it writes another */
	px__slot_put(&j->cmd, &c, sizeof(c));
	return send_cmd(j, &c);
}

int px__bridge_joints_state(struct bridge_joints *j,
			    struct px_bridge_joint_state *out)
{
	uint64_t none = 0;
	if (!j || j->reader <= 0 || !out)
		return PX_E_INVAL;
	return px__slot_get(&j->state, out, sizeof(*out), &none);
}

int px__bridge_joints_command(struct bridge_joints *j, const double *position_rad,
			      const double *velocity_rad_per_s)
{
	struct joint_cmd c;
	if (!j || j->writer <= 0 || !position_rad)
		return PX_E_INVAL;
	memset(&c, 0, sizeof(c));
	memcpy(c.pos, position_rad, sizeof(double) * j->n);
	if (velocity_rad_per_s)
		memcpy(c.vel, velocity_rad_per_s, sizeof(double) * j->n);
	px__slot_put(&j->cmd, &c, sizeof(c));
	return PX_OK;
}

void px__bridge_joints_counts(const struct bridge_joints *j,
			      struct px_bridge_dev_counts *out)
{
	if (!j)
		return;
	out->joint_states_in = atomic_load(&j->n_in);
	out->joint_states_refused = atomic_load(&j->n_refused);
	out->joint_commands_out = atomic_load(&j->n_out);
}

int32_t px__bridge_joints_endpoint(const struct bridge_joints *j, int writer)
{
	return !j ? 0 : writer ? j->writer : j->reader;
}

void px__bridge_joints_free(struct bridge_joints *j)
{
	free(j);
}

int px__bridge_joints_open(struct bridge_joints **out, int32_t dp, int32_t *ws,
			   const struct px_bridge_dev_config *bc, char *msg,
			   size_t cap)
{
	const struct px_bridge_config *c = bc->bridge;
	struct bridge_joints *j;
	size_t i;
	*out = NULL;
	if (!bc->joint_state_topic && !bc->joint_command_topic)
		return PX_OK;
	if (!bc->joint_names || bc->n_joints == 0 ||
	    bc->n_joints > PX_BRIDGE_MAX_JOINTS) {
		snprintf(msg, cap, "dds device: joint topics need 1 .. %d joint names",
			 PX_BRIDGE_MAX_JOINTS);
		return PX_E_INVAL;
	}
	j = calloc(1, sizeof(*j));
	if (!j)
		return PX_E_NOMEM;
	*out = j;
	snprintf(j->frame, sizeof(j->frame), "%s", c->frame_id);
	j->n = bc->n_joints;
	for (i = 0; i < j->n; i++) {
		if (!bc->joint_names[i] || !bc->joint_names[i][0] ||
		    strlen(bc->joint_names[i]) >= sizeof(j->names[i])) {
			snprintf(msg, cap, "dds device: joint name %zu is empty or "
					   "too long", i);
			return PX_E_INVAL;
		}
		snprintf(j->names[i], sizeof(j->names[i]), "%s", bc->joint_names[i]);
		j->name_ptr[i] = j->names[i];
	}
	if (bc->joint_state_topic) {
		j->reader = px__bridge_watched_reader(
			dp, ws, c->ns, bc->joint_state_topic,
			&sensor_msgs_msg_dds__JointState__desc);
		if (j->reader < 0) {
			snprintf(msg, cap, "dds device: cannot read %s: %s",
				 bc->joint_state_topic, dds_strretcode(j->reader));
			return PX_E_IO;
		}
	}
	if (bc->joint_command_topic) {
		j->writer = px__bridge_writer(dp, c->ns, bc->joint_command_topic,
					      &sensor_msgs_msg_dds__JointState__desc);
		if (j->writer < 0) {
			snprintf(msg, cap, "dds device: cannot publish %s: %s",
				 bc->joint_command_topic, dds_strretcode(j->writer));
			return PX_E_IO;
		}
	}
	return PX_OK;
}
