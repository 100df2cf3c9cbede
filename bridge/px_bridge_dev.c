/* The "dds" device back end (px_bridge_dev_create): a pose stream from
 * the network as a device's pose input, a force command as a wrench
 * stream to the network, and for teleoperation a remote force in and a
 * pose out (scene updates: px_bridge_scene.c; a remote arm's joints:
 * px_bridge_joint.c). One thread of the device's own takes the poses and forces
 * (fed with the loop clock's receipt time, so the watchdog sees a silent
 * peer as stale) and sends the newest command and pose; the cycle only
 * swaps values through seqlock slots. */
#include <math.h>
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdio.h>
#include <string.h>

#include <dds/dds.h>

#include "bridge_internal.h"
#include "geometry_msgs.h"
#include "proxima_msgs.h"
#include "px_arena.h"
#include "px_param.h"

/* Parameter sets a reader holds until the device's thread takes them. */
#define PARAMS_DEPTH 64

/* Values of the slots (px__slot) between the cycle and the thread. */
struct pose_val {
	double pos[3], quat_xyzw[4];
};
struct wrench_val {
	struct px_force_cmd w;
	int64_t t_ns;
};

struct dds_dev {
	struct px_dev *d;
	char frame[PX_BRIDGE_NAME_MAX];
	/* for the connect message, in wait_peers' order */
	char topics[7][PX_BRIDGE_TOPIC_MAX];
	dds_entity_t domain, dp, reader, writer, ws;
	dds_entity_t wreader, pwriter; /* wrench in, pose out */
	dds_entity_t preader;          /* parameters in */
	struct bridge_scene *scene;    /* scene updates in, NULL none */
	struct bridge_joints *joints;  /* a remote arm, NULL none */
	struct px_bridge_params pmin, pmax;
	struct px_arena arena;         /* the parameters' triple buffer */
	struct px_param *params;
	int64_t connect_timeout_ns;
	int priority;
	pthread_t th;
	int started;
	atomic_int stop;
	struct px__slot cmd, pose_out, wrench;
	uint64_t sent_seq, pose_sent_seq;
	_Atomic uint64_t n_pose, n_wrench, n_cmd, n_pose_out, n_lost;
	_Atomic uint64_t n_accepted, n_refused;
};

/* A unit quaternion as a rotation vector (rad), the device's axes. */
static void rotvec(const geometry_msgs_msg_dds__Quaternion_ *q, double r[3])
{
	double w = q->w, s = sqrt(q->x * q->x + q->y * q->y + q->z * q->z);
	double ang = 2.0 * atan2(s, w), k = s > 1e-12 ? ang / s : 2.0;
	if (ang > M_PI) /* the shorter way round */
		k = (ang - 2.0 * M_PI) / s;
	r[0] = q->x * k;
	r[1] = q->y * k;
	r[2] = q->z * k;
}

static void take_poses(struct dds_dev *x)
{
	for (;;) {
		void *buf[1] = {NULL};
		dds_sample_info_t info[1];
		int n = dds_take(x->reader, buf, info, 1, 1);
		if (n <= 0)
			return;
		if (info[0].valid_data) {
			const geometry_msgs_msg_dds__PoseStamped_ *m = buf[0];
			double a[PX_AXIS__COUNT];
			a[PX_AXIS_X] = m->pose.position.x;
			a[PX_AXIS_Y] = m->pose.position.y;
			a[PX_AXIS_Z] = m->pose.position.z;
			rotvec(&m->pose.orientation, a + PX_AXIS_RX);
			/* non-finite values are refused and recorded there */
			px_dev_feed_axes(x->d, a, (1u << PX_AXIS__COUNT) - 1, 0,
					 0, px_dev_mono_ns());
			atomic_fetch_add(&x->n_pose, 1);
		}
		dds_return_loan(x->reader, buf, n);
	}
}

/* Remote forces as they arrive: non-finite ones are dropped (recorded),
 * the others go to the slot with their receipt time. */
static void take_wrenches(struct dds_dev *x)
{
	for (;;) {
		void *buf[1] = {NULL};
		dds_sample_info_t info[1];
		int n = dds_take(x->wreader, buf, info, 1, 1);
		if (n <= 0)
			return;
		if (info[0].valid_data) {
			const geometry_msgs_msg_dds__WrenchStamped_ *m = buf[0];
			struct wrench_val v;
			memset(&v, 0, sizeof(v));
			v.w.force_n[0] = m->wrench.force.x;
			v.w.force_n[1] = m->wrench.force.y;
			v.w.force_n[2] = m->wrench.force.z;
			v.w.torque_n_m[0] = m->wrench.torque.x;
			v.w.torque_n_m[1] = m->wrench.torque.y;
			v.w.torque_n_m[2] = m->wrench.torque.z;
			v.w.enable = 1;
			v.t_ns = px_dev_mono_ns();
			if (isfinite(v.w.force_n[0] + v.w.force_n[1] +
				     v.w.force_n[2] + v.w.torque_n_m[0] +
				     v.w.torque_n_m[1] + v.w.torque_n_m[2])) {
				px__slot_put(&x->wrench, &v, sizeof(v));
				atomic_fetch_add(&x->n_wrench, 1);
			} else {
				px_dev_record(x->d, PX_DEV_ERR_NONFINITE, PX_E_NAN, 0,
					      -1, NULL, "a non-finite wrench",
					      v.t_ns);
			}
		}
		dds_return_loan(x->wreader, buf, n);
	}
}

void px__bridge_header_now(void *header, char *frame)
{
	std_msgs_msg_dds__Header_ *h = header;
	struct timespec ts;
	clock_gettime(CLOCK_REALTIME, &ts);
	h->stamp.sec = (int32_t)ts.tv_sec;
	h->stamp.nanosec = (uint32_t)ts.tv_nsec;
	h->frame_id = frame; /* written, never freed */
}

static int send_wrench(struct dds_dev *x, const struct px_force_cmd *c)
{
	geometry_msgs_msg_dds__WrenchStamped_ m;
	int on = c->enable != 0;
	dds_return_t rc;
	memset(&m, 0, sizeof(m));
	px__bridge_header_now(&m.header, x->frame);
	m.wrench.force.x = on ? c->force_n[0] : 0;
	m.wrench.force.y = on ? c->force_n[1] : 0;
	m.wrench.force.z = on ? c->force_n[2] : 0;
	m.wrench.torque.x = on ? c->torque_n_m[0] : 0;
	m.wrench.torque.y = on ? c->torque_n_m[1] : 0;
	m.wrench.torque.z = on ? c->torque_n_m[2] : 0;
	rc = dds_write(x->writer, &m);
	px_dev_count_write(x->d, rc == DDS_RETCODE_OK);
	atomic_fetch_add(&x->n_cmd, rc == DDS_RETCODE_OK);
	if (rc != DDS_RETCODE_OK) {
		px_dev_record(x->d, PX_DEV_ERR_IO, PX_E_IO, 0, -1, NULL,
			      "dds_write of the command", px_dev_mono_ns());
		return PX_E_IO;
	}
	return PX_OK;
}

/* v within [lo, hi] and finite (NaN fails both comparisons). */
static int in_range(double v, double lo, double hi)
{
	return v >= lo && v <= hi && isfinite(v);
}

/* Parameter sets as they arrive: each value checked against the
 * configured range, the set applied whole or refused whole. */
static void take_params(struct dds_dev *x)
{
	for (;;) {
		void *buf[1] = {NULL};
		dds_sample_info_t info[1];
		int n = dds_take(x->preader, buf, info, 1, 1);
		if (n <= 0)
			return;
		if (info[0].valid_data) {
			const proxima_msgs_msg_dds__Params_ *m = buf[0];
			struct px_bridge_params p;
			p.stiffness_n_per_m = m->stiffness_n_per_m;
			p.damping_n_s_per_m = m->damping_n_s_per_m;
			p.max_force_n = m->max_force_n;
			p.speed_scale = m->speed_scale;
			if (in_range(p.stiffness_n_per_m, x->pmin.stiffness_n_per_m,
				     x->pmax.stiffness_n_per_m) &&
			    in_range(p.damping_n_s_per_m, x->pmin.damping_n_s_per_m,
				     x->pmax.damping_n_s_per_m) &&
			    in_range(p.max_force_n, x->pmin.max_force_n,
				     x->pmax.max_force_n) &&
			    in_range(p.speed_scale, x->pmin.speed_scale,
				     x->pmax.speed_scale)) {
				px_param_write(x->params, &p);
				atomic_fetch_add(&x->n_accepted, 1);
			} else {
				atomic_fetch_add(&x->n_refused, 1);
			}
		}
		dds_return_loan(x->preader, buf, n);
	}
}

/* The newest command, when the cycle wrote one since the last send. */
static void send_newest(struct dds_dev *x)
{
	struct px_force_cmd c;
	if (px__slot_get(&x->cmd, &c, sizeof(c), &x->sent_seq))
		send_wrench(x, &c);
}

static void send_pose(struct dds_dev *x)
{
	geometry_msgs_msg_dds__PoseStamped_ m;
	struct pose_val v;
	if (!px__slot_get(&x->pose_out, &v, sizeof(v), &x->pose_sent_seq))
		return;
	memset(&m, 0, sizeof(m));
	px__bridge_header_now(&m.header, x->frame);
	m.pose.position.x = v.pos[0];
	m.pose.position.y = v.pos[1];
	m.pose.position.z = v.pos[2];
	m.pose.orientation.x = v.quat_xyzw[0];
	m.pose.orientation.y = v.quat_xyzw[1];
	m.pose.orientation.z = v.quat_xyzw[2];
	m.pose.orientation.w = v.quat_xyzw[3];
	if (dds_write(x->pwriter, &m) == DDS_RETCODE_OK)
		atomic_fetch_add(&x->n_pose_out, 1);
	else
		px_dev_record(x->d, PX_DEV_ERR_IO, PX_E_IO, 0, -1, NULL,
			      "dds_write of the pose", px_dev_mono_ns());
}

static void count_lost(struct dds_dev *x, dds_entity_t reader)
{
	dds_sample_lost_status_t st;
	if (reader > 0 && dds_get_sample_lost_status(reader, &st) == DDS_RETCODE_OK)
		atomic_fetch_add(&x->n_lost, (uint64_t)st.total_count_change);
}

/* Inputs as they arrive; outputs within a tenth of a millisecond of the
 * cycle's write (the wait's timeout: the cycle signals nothing, it only
 * swaps a slot). */
static void *dev_thread(void *arg)
{
	struct dds_dev *x = arg;
	int outputs = x->writer > 0 || x->pwriter > 0 ||
		      px__bridge_joints_endpoint(x->joints, 1) > 0;
	if (x->priority > 0) {
		/* beside the loop, below it; refused (no privilege): the
		 * thread runs at normal priority, as without */
		struct sched_param sp;
		memset(&sp, 0, sizeof(sp));
		sp.sched_priority = x->priority;
		pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp);
	}
	dds_duration_t poll = outputs ? DDS_USECS(100) : DDS_MSECS(1);
	while (!atomic_load(&x->stop)) {
		if (x->ws > 0)
			dds_waitset_wait(x->ws, NULL, 0, poll);
		else
			dds_sleepfor(poll);
		if (x->reader > 0)
			take_poses(x);
		if (x->wreader > 0)
			take_wrenches(x);
		if (x->preader > 0)
			take_params(x);
		px__bridge_scene_take(x->scene);
		px__bridge_joints_take(x->joints);
		if (x->writer > 0)
			send_newest(x);
		if (x->pwriter > 0)
			send_pose(x);
		count_lost(x, x->reader);
		count_lost(x, x->wreader);
	}
	return NULL;
}

/* Until each endpoint has a peer (readers: a matched writer; writers: a
 * matched reader), at most connect_timeout_ns. PX_OK or PX_E_TIMEOUT
 * (recorded, naming the topic). */
static int wait_peers(struct dds_dev *x)
{
	const dds_entity_t e[7] = {x->reader, x->wreader,
				   px__bridge_scene_cloud_reader(x->scene),
				   px__bridge_joints_endpoint(x->joints, 0),
				   x->writer, x->pwriter,
				   px__bridge_joints_endpoint(x->joints, 1)};
	int64_t end = px_dev_mono_ns() + x->connect_timeout_ns;
	int i;
	if (x->connect_timeout_ns <= 0)
		return PX_OK;
	for (i = 0; i < 7; i++) {
		while (e[i] > 0) {
			uint32_t n = 0;
			if (i < 4) {
				dds_subscription_matched_status_t st;
				if (dds_get_subscription_matched_status(e[i], &st) == 0)
					n = st.current_count;
			} else {
				dds_publication_matched_status_t st;
				if (dds_get_publication_matched_status(e[i], &st) == 0)
					n = st.current_count;
			}
			if (n > 0)
				break;
			if (px_dev_mono_ns() >= end) {
				char why[PX_BRIDGE_TOPIC_MAX + 64];
				snprintf(why, sizeof(why),
					 "no peer on %s within the connect timeout",
					 x->topics[i]);
				px_dev_record(x->d, PX_DEV_ERR_IO, PX_E_TIMEOUT, 0,
					      -1, NULL, why, px_dev_mono_ns());
				return PX_E_TIMEOUT;
			}
			dds_sleepfor(DDS_MSECS(5));
		}
	}
	return PX_OK;
}

static int dev_start(struct px_dev *d)
{
	struct dds_dev *x = px_dev_impl(d);
	int rc = wait_peers(x);
	if (rc != PX_OK)
		return rc;
	atomic_store(&x->stop, 0);
	if (pthread_create(&x->th, NULL, dev_thread, x) != 0)
		return PX_E_NOMEM;
	x->started = 1;
	px_dev_set_state(d, PX_DEV_STATE_RUNNING, px_dev_mono_ns());
	return PX_OK;
}

static void dev_stop(struct px_dev *d)
{
	struct dds_dev *x = px_dev_impl(d);
	if (!x->started)
		return;
	atomic_store(&x->stop, 1);
	pthread_join(x->th, NULL);
	x->started = 0;
}

/* In the cycle: the command into the slot, nothing else. */
static int dev_force(struct px_dev *d, const struct px_force_cmd *c,
		     int64_t now_ns)
{
	struct dds_dev *x = px_dev_impl(d);
	(void)now_ns;
	px__slot_put(&x->cmd, c, sizeof(*c));
	return PX_OK;
}

/* Zero wrench, sent now from the calling thread: a write DDS accepted
 * is the confirmation. */
static int dev_safe(struct px_dev *d, int64_t now_ns)
{
	struct dds_dev *x = px_dev_impl(d);
	struct px_force_cmd zero;
	memset(&zero, 0, sizeof(zero));
	if (x->writer <= 0)
		return PX_OK;
	dev_force(d, &zero, now_ns);
	return send_wrench(x, &zero);
}

static void dev_destroy(struct px_dev *d)
{
	struct dds_dev *x = px_dev_impl(d);
	if (x->dp > 0)
		dds_delete(x->dp);
	if (x->domain > 0)
		dds_delete(x->domain);
	px__bridge_scene_free(x->scene);
	px__bridge_joints_free(x->joints);
	px_arena_fini(&x->arena);
}

/* One table per caps combination (index: bit 0 pose, bit 1 force). */
#define DDS_OPS(caps_, force_)                                              \
	{.backend = "dds", .caps = (caps_), .start = dev_start,             \
	 .stop = dev_stop, .force = (force_) ? dev_force : NULL,            \
	 .safe = dev_safe, .destroy = dev_destroy}
static const struct px_dev_ops dds_ops[4] = {
	DDS_OPS(0, 0), DDS_OPS(PX_DEV_CAP_POSE, 0), DDS_OPS(PX_DEV_CAP_FORCE, 1),
	DDS_OPS(PX_DEV_CAP_POSE | PX_DEV_CAP_FORCE, 1)};

static struct dds_dev *dds_of(struct px_dev *d)
{
	const struct px_dev_ops *o = d ? px_dev_ops(d) : NULL;
	return o >= dds_ops && o < dds_ops + 4 ? px_dev_impl(d) : NULL;
}

int px_bridge_dev_wrench(struct px_dev *d, struct px_force_cmd *out,
			 int64_t *t_ns)
{
	struct dds_dev *x = dds_of(d);
	struct wrench_val v;
	uint64_t none = 0;
	if (!x || x->wreader <= 0 || !out || !t_ns)
		return PX_E_INVAL;
	/* seq 0 is "never written": a copy against 0 is any value */
	if (!px__slot_get(&x->wrench, &v, sizeof(v), &none))
		return 0;
	*out = v.w;
	*t_ns = v.t_ns;
	return 1;
}

int px_bridge_dev_pose_write(struct px_dev *d, const px_vec3 *pos_m,
			     const px_quat *q)
{
	struct dds_dev *x = dds_of(d);
	struct pose_val v;
	if (!x || x->pwriter <= 0 || !pos_m)
		return PX_E_INVAL;
	v.pos[0] = pos_m->x;
	v.pos[1] = pos_m->y;
	v.pos[2] = pos_m->z;
	v.quat_xyzw[0] = q ? q->x : 0;
	v.quat_xyzw[1] = q ? q->y : 0;
	v.quat_xyzw[2] = q ? q->z : 0;
	v.quat_xyzw[3] = q ? q->w : 1;
	px__slot_put(&x->pose_out, &v, sizeof(v));
	return PX_OK;
}

int px_bridge_dev_params(struct px_dev *d, struct px_bridge_params *out)
{
	struct dds_dev *x = dds_of(d);
	const struct px_bridge_params *p;
	int fresh = 0;
	if (!x || !x->params || !out)
		return PX_E_INVAL;
	p = px_param_read(x->params, &fresh);
	if (!fresh)
		return 0;
	*out = *p;
	return 1;
}

int px_bridge_dev_scene_poses(struct px_dev *d,
			      struct px_bridge_scene_poses *out)
{
	struct dds_dev *x = dds_of(d);
	return x ? px__bridge_scene_poses(x->scene, out) : PX_E_INVAL;
}

int px_bridge_dev_joint_state(struct px_dev *d,
			      struct px_bridge_joint_state *out)
{
	struct dds_dev *x = dds_of(d);
	return x ? px__bridge_joints_state(x->joints, out) : PX_E_INVAL;
}

int px_bridge_dev_joint_command(struct px_dev *d, const double *position_rad,
				const double *velocity_rad_per_s)
{
	struct dds_dev *x = dds_of(d);
	return x ? px__bridge_joints_command(x->joints, position_rad,
					     velocity_rad_per_s)
		 : PX_E_INVAL;
}

int px_bridge_dev_joint_hold(struct px_dev *d)
{
	struct dds_dev *x = dds_of(d);
	if (!x || px__bridge_joints_endpoint(x->joints, 1) <= 0)
		return PX_E_INVAL;
	return px__bridge_joints_hold(x->joints);
}

int px_bridge_dev_counts(struct px_dev *d, struct px_bridge_dev_counts *out)
{
	struct dds_dev *x = dds_of(d);
	if (!x || !out)
		return PX_E_INVAL;
	out->poses_in = atomic_load(&x->n_pose);
	out->wrenches_in = atomic_load(&x->n_wrench);
	out->commands_out = atomic_load(&x->n_cmd);
	out->poses_out = atomic_load(&x->n_pose_out);
	out->lost = atomic_load(&x->n_lost);
	out->params_accepted = atomic_load(&x->n_accepted);
	out->params_refused = atomic_load(&x->n_refused);
	out->clouds_accepted = out->clouds_refused = out->clouds_dropped = 0;
	out->scene_poses_accepted = out->scene_poses_refused = 0;
	out->joint_states_in = out->joint_states_refused = 0;
	out->joint_commands_out = 0;
	px__bridge_scene_counts(x->scene, out);
	px__bridge_joints_counts(x->joints, out);
	return PX_OK;
}

static dds_entity_t endpoint(dds_entity_t dp, const char *ns,
			     const char *name, const dds_topic_descriptor_t *t,
			     int reader)
{
	char topic[PX_BRIDGE_TOPIC_MAX];
	/* a stream, as the bridge's; the parameters reliable, and kept
	 * until the thread takes them (a burst is not cut to its last) */
	int params = t == &proxima_msgs_msg_dds__Params__desc;
	dds_qos_t *q = px__bridge_qos(params);
	dds_entity_t tp, e;
	if (!q)
		return DDS_RETCODE_OUT_OF_RESOURCES;
	if (params && reader)
		dds_qset_history(q, DDS_HISTORY_KEEP_LAST, PARAMS_DEPTH);
	if (px_bridge_topic_name(ns, name, topic, sizeof(topic)) != PX_OK) {
		dds_delete_qos(q);
		return DDS_RETCODE_BAD_PARAMETER;
	}
	tp = dds_create_topic(dp, t, topic, q, NULL);
	e = tp < 0 ? tp
	    : reader ? dds_create_reader(dp, tp, q, NULL)
		     : dds_create_writer(dp, tp, q, NULL);
	dds_delete_qos(q);
	return e;
}

int32_t px__bridge_writer(int32_t dp, const char *ns, const char *name,
			  const void *type)
{
	return endpoint(dp, ns, name, type, 0);
}

/* A reader whose data wakes the device's thread. */
int32_t px__bridge_watched_reader(int32_t dp, int32_t *ws, const char *ns,
				  const char *name, const void *type)
{
	dds_entity_t r = endpoint(dp, ns, name, type, 1), cond;
	if (r < 0)
		return r;
	if (*ws <= 0) {
		*ws = dds_create_waitset(dp);
		if (*ws < 0)
			return *ws;
	}
	cond = dds_create_readcondition(r, DDS_ANY_STATE);
	if (cond < 0)
		return cond;
	return dds_waitset_attach(*ws, cond, 0) < 0 ? DDS_RETCODE_ERROR : r;
}

static int open_dds(struct dds_dev *x, const struct px_bridge_dev_config *bc,
		    char *msg, size_t cap)
{
	const struct px_bridge_config *c = bc->bridge;
	/* in wait_peers' order; the cloud and joint endpoints are made
	 * by their own files (only their names here) */
	const char *const all[7] = {bc->pose_topic, bc->wrench_topic,
				    bc->cloud_topic, bc->joint_state_topic,
				    bc->command_topic, bc->pose_out_topic,
				    bc->joint_command_topic};
	const char *const names[4] = {bc->pose_topic, bc->wrench_topic,
				      bc->command_topic, bc->pose_out_topic};
	dds_entity_t *const ents[4] = {&x->reader, &x->wreader, &x->writer,
				       &x->pwriter};
	const dds_topic_descriptor_t *const types[4] = {
		&geometry_msgs_msg_dds__PoseStamped__desc,
		&geometry_msgs_msg_dds__WrenchStamped__desc,
		&geometry_msgs_msg_dds__WrenchStamped__desc,
		&geometry_msgs_msg_dds__PoseStamped__desc};
	int i, rc = px__bridge_join(c, &x->domain, &x->dp, msg, cap);
	if (rc != PX_OK)
		return rc;
	for (i = 0; i < 7; i++)
		if (all[i])
			px_bridge_topic_name(c->ns, all[i], x->topics[i],
					     sizeof(x->topics[i]));
	for (i = 0; i < 4; i++) {
		if (!names[i])
			continue;
		*ents[i] = i < 2 ? px__bridge_watched_reader(x->dp, &x->ws, c->ns,
							      names[i], types[i])
				 : endpoint(x->dp, c->ns, names[i], types[i], 0);
		if (*ents[i] < 0) {
			snprintf(msg, cap, "dds device: cannot %s %s: %s",
				 i < 2 ? "read" : "publish", names[i],
				 dds_strretcode(*ents[i]));
			return PX_E_IO;
		}
	}
	if (bc->params_topic) {
		struct px_bridge_params zero;
		memset(&zero, 0, sizeof(zero));
		x->pmin = bc->params_min;
		x->pmax = bc->params_max;
		rc = px_arena_init_alloc(&x->arena,
					 px_param_size(sizeof(zero)) + 256);
		if (rc == PX_OK)
			rc = px_param_create(&x->arena, sizeof(zero), &zero,
					     &x->params);
		if (rc != PX_OK)
			return rc;
		x->preader = px__bridge_watched_reader(
			x->dp, &x->ws, c->ns, bc->params_topic,
			&proxima_msgs_msg_dds__Params__desc);
		if (x->preader < 0) {
			snprintf(msg, cap, "dds device: cannot read %s: %s",
				 bc->params_topic, dds_strretcode(x->preader));
			return PX_E_IO;
		}
	}
	rc = px__bridge_scene_open(&x->scene, x->dp, &x->ws, bc, msg, cap);
	return rc != PX_OK ? rc
			   : px__bridge_joints_open(&x->joints, x->dp, &x->ws, bc,
						    msg, cap);
}

int px_bridge_dev_create(const struct px_dev_config *dc,
			 const struct px_bridge_dev_config *bc,
			 struct px_dev **out, char *msg, size_t cap)
{
	const struct px_dev_ops *ops;
	struct dds_dev *x;
	char why[200];
	int rc;
	if (msg && cap)
		msg[0] = '\0';
	if (!out)
		return PX_E_INVAL;
	*out = NULL;
	if (!dc || !bc || !bc->bridge ||
	    (!bc->pose_topic && !bc->command_topic && !bc->wrench_topic &&
	     !bc->pose_out_topic && !bc->params_topic && !bc->cloud_topic &&
	     !bc->scene_topic && !bc->joint_state_topic &&
	     !bc->joint_command_topic) ||
	    bc->connect_timeout_ns < 0) {
		snprintf(msg, cap, "dds device: a pose, wrench, command, "
				   "pose_out, params, cloud, scene or joint topic "
				   "needed");
		return PX_E_INVAL;
	}
	if (px_bridge_config_check(bc->bridge, why, sizeof(why)) != PX_OK) {
		snprintf(msg, cap, "dds device: %s", why);
		return PX_E_INVAL;
	}
	ops = &dds_ops[(bc->pose_topic ? 1 : 0) | (bc->command_topic ? 2 : 0)];
	rc = px_dev_create(ops, dc, sizeof(*x), out);
	if (rc != PX_OK)
		return rc;
	x = px_dev_impl(*out);
	x->d = *out;
	snprintf(x->frame, sizeof(x->frame), "%s", bc->bridge->frame_id);
	x->connect_timeout_ns = bc->connect_timeout_ns;
	x->priority = bc->thread_priority;
	rc = open_dds(x, bc, msg, cap);
	if (rc != PX_OK) {
		px_dev_free(*out);
		*out = NULL;
	}
	return rc;
}
