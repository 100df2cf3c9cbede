/* The "dds" device back end (px_bridge_dev_create): a pose stream from
 * the network as a device's pose input, a force command as a wrench
 * stream to the network. One thread of the device's own takes the poses
 * (fed to the device with the loop clock's receipt time, so the
 * watchdog sees a silent peer as stale) and sends the newest command;
 * the cycle only swaps a command into a seqlock slot. */
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <string.h>

#include <dds/dds.h>

#include "bridge_internal.h"
#include "geometry_msgs.h"

struct dds_dev {
	struct px_dev *d;
	char frame[PX_BRIDGE_NAME_MAX];
	dds_entity_t domain, dp, reader, writer, ws;
	pthread_t th;
	int started;
	atomic_int stop;
	/* the newest command: written by the cycle (seq odd while it
	 * writes), read by the thread, which retries a torn copy */
	atomic_uint_fast64_t seq;
	struct px_force_cmd cmd;
	uint64_t sent_seq;
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
		}
		dds_return_loan(x->reader, buf, n);
	}
}

static int send_wrench(struct dds_dev *x, const struct px_force_cmd *c)
{
	geometry_msgs_msg_dds__WrenchStamped_ m;
	struct timespec ts;
	int on = c->enable != 0;
	dds_return_t rc;
	clock_gettime(CLOCK_REALTIME, &ts);
	memset(&m, 0, sizeof(m));
	m.header.stamp.sec = (int32_t)ts.tv_sec;
	m.header.stamp.nanosec = (uint32_t)ts.tv_nsec;
	m.header.frame_id = x->frame;
	m.wrench.force.x = on ? c->force_n[0] : 0;
	m.wrench.force.y = on ? c->force_n[1] : 0;
	m.wrench.force.z = on ? c->force_n[2] : 0;
	m.wrench.torque.x = on ? c->torque_n_m[0] : 0;
	m.wrench.torque.y = on ? c->torque_n_m[1] : 0;
	m.wrench.torque.z = on ? c->torque_n_m[2] : 0;
	rc = dds_write(x->writer, &m);
	px_dev_count_write(x->d, rc == DDS_RETCODE_OK);
	if (rc != DDS_RETCODE_OK) {
		px_dev_record(x->d, PX_DEV_ERR_IO, PX_E_IO, 0, -1, NULL,
			      "dds_write of the command", px_dev_mono_ns());
		return PX_E_IO;
	}
	return PX_OK;
}

/* The newest command, when the cycle wrote one since the last send. */
static void send_newest(struct dds_dev *x)
{
	struct px_force_cmd c;
	uint64_t s0, s1;
	do {
		s0 = atomic_load_explicit(&x->seq, memory_order_acquire);
		if (s0 == x->sent_seq || (s0 & 1))
			return;
		memcpy(&c, &x->cmd, sizeof(c));
		atomic_thread_fence(memory_order_acquire);
		s1 = atomic_load_explicit(&x->seq, memory_order_relaxed);
	} while (s0 != s1);
	x->sent_seq = s0;
	send_wrench(x, &c);
}

/* Poses as they arrive; commands within a millisecond of the cycle's
 * write. */
static void *dev_thread(void *arg)
{
	struct dds_dev *x = arg;
	while (!atomic_load(&x->stop)) {
		if (x->ws > 0)
			dds_waitset_wait(x->ws, NULL, 0, DDS_MSECS(1));
		else
			dds_sleepfor(DDS_MSECS(1));
		if (x->reader > 0)
			take_poses(x);
		if (x->writer > 0)
			send_newest(x);
	}
	return NULL;
}

static int dev_start(struct px_dev *d)
{
	struct dds_dev *x = px_dev_impl(d);
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
	uint64_t s = atomic_load_explicit(&x->seq, memory_order_relaxed);
	(void)now_ns;
	atomic_store_explicit(&x->seq, s + 1, memory_order_relaxed);
	atomic_thread_fence(memory_order_release);
	x->cmd = *c;
	atomic_store_explicit(&x->seq, s + 2, memory_order_release);
	return PX_OK;
}

/* Zero wrench, sent now from the calling thread: a write DDS accepted
 * is the confirmation. */
static int dev_safe(struct px_dev *d, int64_t now_ns)
{
	struct dds_dev *x = px_dev_impl(d);
	struct px_force_cmd zero;
	memset(&zero, 0, sizeof(zero));
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
}

static const struct px_dev_ops pose_ops = {
	.backend = "dds", .caps = PX_DEV_CAP_POSE, .start = dev_start,
	.stop = dev_stop, .destroy = dev_destroy};
static const struct px_dev_ops force_ops = {
	.backend = "dds", .caps = PX_DEV_CAP_FORCE, .start = dev_start,
	.stop = dev_stop, .force = dev_force, .safe = dev_safe,
	.destroy = dev_destroy};
static const struct px_dev_ops both_ops = {
	.backend = "dds", .caps = PX_DEV_CAP_POSE | PX_DEV_CAP_FORCE,
	.start = dev_start, .stop = dev_stop, .force = dev_force,
	.safe = dev_safe, .destroy = dev_destroy};

static dds_entity_t endpoint(struct dds_dev *x, const char *ns,
			     const char *name, const dds_topic_descriptor_t *t,
			     int reader)
{
	char topic[PX_BRIDGE_TOPIC_MAX];
	dds_qos_t *q = px__bridge_qos(0); /* a stream, as the bridge's */
	dds_entity_t tp, e;
	if (!q)
		return DDS_RETCODE_OUT_OF_RESOURCES;
	if (px_bridge_topic_name(ns, name, topic, sizeof(topic)) != PX_OK) {
		dds_delete_qos(q);
		return DDS_RETCODE_BAD_PARAMETER;
	}
	tp = dds_create_topic(x->dp, t, topic, q, NULL);
	e = tp < 0 ? tp
	    : reader ? dds_create_reader(x->dp, tp, q, NULL)
		     : dds_create_writer(x->dp, tp, q, NULL);
	dds_delete_qos(q);
	return e;
}

static int open_dds(struct dds_dev *x, const struct px_bridge_dev_config *bc,
		    char *msg, size_t cap)
{
	const struct px_bridge_config *c = bc->bridge;
	int rc = px__bridge_join(c, &x->domain, &x->dp, msg, cap);
	if (rc != PX_OK)
		return rc;
	if (bc->pose_topic) {
		x->reader = endpoint(x, c->ns, bc->pose_topic,
				     &geometry_msgs_msg_dds__PoseStamped__desc, 1);
		x->ws = x->reader > 0 ? dds_create_waitset(x->dp) : x->reader;
		if (x->ws > 0) {
			dds_entity_t cond = dds_create_readcondition(
				x->reader, DDS_ANY_STATE);
			if (cond < 0 || dds_waitset_attach(x->ws, cond, 0) < 0)
				x->ws = cond < 0 ? cond : DDS_RETCODE_ERROR;
		}
		if (x->reader < 0 || x->ws < 0) {
			snprintf(msg, cap, "dds device: cannot read %s: %s",
				 bc->pose_topic,
				 dds_strretcode(x->reader < 0 ? x->reader : x->ws));
			return PX_E_IO;
		}
	}
	if (bc->command_topic) {
		x->writer = endpoint(x, c->ns, bc->command_topic,
				     &geometry_msgs_msg_dds__WrenchStamped__desc,
				     0);
		if (x->writer < 0) {
			snprintf(msg, cap, "dds device: cannot publish %s: %s",
				 bc->command_topic, dds_strretcode(x->writer));
			return PX_E_IO;
		}
	}
	return PX_OK;
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
	if (!dc || !bc || !bc->bridge || (!bc->pose_topic && !bc->command_topic)) {
		snprintf(msg, cap, "dds device: a pose or a command topic needed");
		return PX_E_INVAL;
	}
	if (px_bridge_config_check(bc->bridge, why, sizeof(why)) != PX_OK) {
		snprintf(msg, cap, "dds device: %s", why);
		return PX_E_INVAL;
	}
	ops = !bc->command_topic ? &pose_ops
	      : !bc->pose_topic  ? &force_ops
				 : &both_ops;
	rc = px_dev_create(ops, dc, sizeof(*x), out);
	if (rc != PX_OK)
		return rc;
	x = px_dev_impl(*out);
	x->d = *out;
	snprintf(x->frame, sizeof(x->frame), "%s", bc->bridge->frame_id);
	rc = open_dds(x, bc, msg, cap);
	if (rc != PX_OK) {
		px_dev_free(*out);
		*out = NULL;
	}
	return rc;
}
