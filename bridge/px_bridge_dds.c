/* The bridge on Cyclone DDS: one participant, a topic and writer per
 * stream, and the thread that publishes the newest offered sample at
 * each stream's rate. The message types are idlc's from bridge/idl/. */
#include <errno.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <dds/dds.h>

#include "bridge_internal.h"
#include "proxima_msgs.h"
#include "sensor_msgs.h"

struct px_bridge {
	struct px_bridge_config c; /* strings: the copies below */
	char ns[PX_BRIDGE_NAME_MAX], iface[PX_BRIDGE_NAME_MAX];
	char frame[PX_BRIDGE_NAME_MAX];
	dds_entity_t domain; /* 0: the domain existed before this bridge */
	dds_entity_t dp;
	dds_entity_t topic[PX_BRIDGE_TOPIC__COUNT];
	dds_entity_t writer[PX_BRIDGE_TOPIC__COUNT];
	double rate_hz[PX_BRIDGE_TOPIC__COUNT]; /* 0: written directly */
	pthread_t th;
	int started;
	/* under mu: the offers (a queue of samples, the newest status),
	 * the stop request and the counts */
	pthread_mutex_t mu;
	pthread_cond_t cv;
	int stop;
	struct px_bridge_sample queue[PX_BRIDGE_QUEUE];
	unsigned head, n_queued;
	struct px_bridge_status status;
	uint64_t status_seq;
	struct px_bridge_counts counts;
	/* the bridge thread's: the samples taken from the queue */
	struct px_bridge_sample work[PX_BRIDGE_QUEUE];
};

static const dds_topic_descriptor_t *const descs[PX_BRIDGE_TOPIC__COUNT] = {
	&geometry_msgs_msg_dds__PoseStamped__desc,
	&geometry_msgs_msg_dds__PoseStamped__desc,
	&geometry_msgs_msg_dds__WrenchStamped__desc,
	&geometry_msgs_msg_dds__PointStamped__desc,
	&proxima_msgs_msg_dds__Distance__desc,
	&proxima_msgs_msg_dds__Status__desc,
	&sensor_msgs_msg_dds__JointState__desc,
	&sensor_msgs_msg_dds__PointCloud2__desc,
};

const void *px_bridge_topic_descriptor(enum px_bridge_topic t)
{
	return (unsigned)t < PX_BRIDGE_TOPIC__COUNT ? descs[t] : NULL;
}

static int64_t mono_ns(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

static void header(const struct px_bridge *b, int64_t stamp_ns,
		   std_msgs_msg_dds__Header_ *h)
{
	int64_t sec = stamp_ns / 1000000000, ns = stamp_ns % 1000000000;
	if (ns < 0) {
		ns += 1000000000;
		sec--;
	}
	h->stamp.sec = (int32_t)sec;
	h->stamp.nanosec = (uint32_t)ns;
	h->frame_id = (char *)b->frame; /* written, never freed */
}

static void point(geometry_msgs_msg_dds__Point_ *p, const double v[3])
{
	p->x = v[0];
	p->y = v[1];
	p->z = v[2];
}

static void vec(geometry_msgs_msg_dds__Vector3_ *p, const double v[3])
{
	p->x = v[0];
	p->y = v[1];
	p->z = v[2];
}

/* One write; failures are counted with Cyclone's code. */
static int write_msg(struct px_bridge *b, enum px_bridge_topic t,
		     const void *msg)
{
	dds_return_t rc = dds_write(b->writer[t], msg);
	pthread_mutex_lock(&b->mu);
	if (rc == DDS_RETCODE_OK) {
		b->counts.published[t]++;
	} else {
		b->counts.write_errors++;
		b->counts.last_error = rc;
	}
	pthread_mutex_unlock(&b->mu);
	return rc == DDS_RETCODE_OK ? PX_OK : PX_E_IO;
}

/* The stream t from the sample s (or the status st). */
static void publish_stream(struct px_bridge *b, enum px_bridge_topic t,
			   const struct px_bridge_sample *s,
			   const struct px_bridge_status *st)
{
	switch (t) {
	case PX_BRIDGE_TOOL_POSE:
	case PX_BRIDGE_PROXY_POSE: {
		geometry_msgs_msg_dds__PoseStamped_ m;
		const double *q = s->tool_quat_xyzw;
		memset(&m, 0, sizeof(m));
		header(b, s->stamp_ns, &m.header);
		if (t == PX_BRIDGE_TOOL_POSE) {
			point(&m.pose.position, s->tool_m);
		} else {
			/* the proxy carries the tool's orientation */
			point(&m.pose.position, s->proxy_m);
		}
		m.pose.orientation.x = q[0];
		m.pose.orientation.y = q[1];
		m.pose.orientation.z = q[2];
		m.pose.orientation.w = q[3];
		write_msg(b, t, &m);
		break;
	}
	case PX_BRIDGE_WRENCH: {
		geometry_msgs_msg_dds__WrenchStamped_ m;
		memset(&m, 0, sizeof(m));
		header(b, s->stamp_ns, &m.header);
		vec(&m.wrench.force, s->force_n);
		vec(&m.wrench.torque, s->torque_n_m);
		write_msg(b, t, &m);
		break;
	}
	case PX_BRIDGE_CLOSEST_POINT: {
		geometry_msgs_msg_dds__PointStamped_ m;
		if (!s->distance_valid)
			break; /* no closest point: nothing to show */
		memset(&m, 0, sizeof(m));
		header(b, s->stamp_ns, &m.header);
		point(&m.point, s->closest_m);
		write_msg(b, t, &m);
		break;
	}
	case PX_BRIDGE_DISTANCE: {
		proxima_msgs_msg_dds__Distance_ m;
		memset(&m, 0, sizeof(m));
		header(b, s->stamp_ns, &m.header);
		m.valid = s->distance_valid;
		m.distance_m = s->distance_m;
		point(&m.tool_point, s->tool_point_m);
		point(&m.closest_point, s->closest_m);
		vec(&m.normal, s->normal);
		write_msg(b, t, &m);
		break;
	}
	case PX_BRIDGE_STATUS: {
		proxima_msgs_msg_dds__Status_ m;
		memset(&m, 0, sizeof(m));
		header(b, st->stamp_ns, &m.header);
		m.loop_rate_hz = st->loop_rate_hz;
		m.latency_p50_us = st->latency_p50_us;
		m.latency_p99_us = st->latency_p99_us;
		m.latency_max_us = st->latency_max_us;
		m.safe_state = st->safe_state;
		m.cycles = st->cycles;
		m.overruns = st->overruns;
		m.faults = st->faults;
		m.safe_state_trips = st->safe_state_trips;
		m.telemetry_dropped = st->telemetry_dropped;
		write_msg(b, t, &m);
		break;
	}
	default:
		break;
	}
}

/* Each queued sample in order: a stream publishes it when the sample's
 * stamp has reached the stream's next due time, so the rates hold in the
 * loop's time however the samples arrive (the app drains in batches). */
static void publish_samples(struct px_bridge *b,
			    const struct px_bridge_sample *q, unsigned n,
			    int64_t *due, const int64_t *period)
{
	unsigned i;
	int t;
	for (i = 0; i < n; i++)
		for (t = 0; t < PX_BRIDGE_TOPIC__COUNT; t++) {
			if (!period[t] || t == PX_BRIDGE_STATUS ||
			    q[i].stamp_ns < due[t])
				continue;
			due[t] += period[t];
			if (due[t] <= q[i].stamp_ns) /* a gap: no burst */
				due[t] = q[i].stamp_ns + period[t];
			publish_stream(b, (enum px_bridge_topic)t, &q[i], NULL);
		}
}

/* Until stopped: the queued samples as they come, the newest status at
 * its rate in wall time (when one came since the last). */
static void *bridge_thread(void *arg)
{
	struct px_bridge *b = arg;
	int64_t due[PX_BRIDGE_TOPIC__COUNT] = {0}, period[PX_BRIDGE_TOPIC__COUNT];
	int64_t status_due = 0;
	uint64_t status_sent = 0;
	struct px_bridge_sample *q = b->work;
	struct px_bridge_status st;
	int t, stop = 0;
	for (t = 0; t < PX_BRIDGE_TOPIC__COUNT; t++)
		period[t] = b->rate_hz[t] > 0 ? (int64_t)(1e9 / b->rate_hz[t]) : 0;
	while (!stop) {
		int64_t now = mono_ns(), wake = now + 100000000;
		uint64_t st_seq;
		unsigned n = 0;
		struct timespec ts;
		if (period[PX_BRIDGE_STATUS] && status_due < wake)
			wake = status_due > now ? status_due : now;
		ts.tv_sec = (time_t)(wake / 1000000000);
		ts.tv_nsec = (long)(wake % 1000000000);
		pthread_mutex_lock(&b->mu);
		while (!b->stop && !b->n_queued && mono_ns() < wake)
			if (pthread_cond_timedwait(&b->cv, &b->mu, &ts) ==
			    ETIMEDOUT)
				break;
		stop = b->stop;
		while (b->n_queued) {
			q[n++] = b->queue[b->head];
			b->head = (b->head + 1) % PX_BRIDGE_QUEUE;
			b->n_queued--;
		}
		st = b->status;
		st_seq = b->status_seq;
		pthread_mutex_unlock(&b->mu);
		if (stop)
			break;
		publish_samples(b, q, n, due, period);
		now = mono_ns();
		if (period[PX_BRIDGE_STATUS] && now >= status_due) {
			status_due = now + period[PX_BRIDGE_STATUS];
			if (st_seq != status_sent) {
				status_sent = st_seq;
				publish_stream(b, PX_BRIDGE_STATUS, NULL, &st);
			}
		}
	}
	return NULL;
}

static void set_msg(char *msg, size_t cap, const char *what, dds_return_t rc)
{
	if (msg && cap)
		snprintf(msg, cap, "bridge: %s: %s", what, dds_strretcode(rc));
}

/* The QoS of ROS 2's profiles: sensor data (best-effort) for streams,
 * default (reliable) for the status; keep-last-1, volatile. */
void *px__bridge_qos(int reliable)
{
	dds_qos_t *q = dds_create_qos();
	if (!q)
		return NULL;
	if (reliable)
		dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE,
				     DDS_MSECS(100));
	else
		dds_qset_reliability(q, DDS_RELIABILITY_BEST_EFFORT, 0);
	dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
	dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
	return q;
}

int px__bridge_join(const struct px_bridge_config *c, int32_t *domain,
		    int32_t *dp, char *msg, size_t cap)
{
	char xml[PX_BRIDGE_DDS_CONFIG_MAX];
	dds_domainid_t dom = (dds_domainid_t)c->domain_id;
	dds_entity_t e;
	*domain = *dp = 0;
	if (px_bridge_dds_config(c, xml, sizeof(xml)) != PX_OK) {
		snprintf(msg, cap, "bridge: the DDS configuration is too long");
		return PX_E_INVAL;
	}
	e = dds_create_domain(dom, xml);
	if (e < 0 && e != DDS_RETCODE_PRECONDITION_NOT_MET) {
		set_msg(msg, cap, "cannot configure the DDS domain", e);
		return PX_E_IO;
	}
	*domain = e > 0 ? e : 0; /* existing: its configuration stays */
	e = dds_create_participant(dom, NULL, NULL);
	if (e < 0) {
		set_msg(msg, cap, "cannot join the DDS domain", e);
		return PX_E_IO;
	}
	*dp = e;
	return PX_OK;
}

static int make_entities(struct px_bridge *b, char *msg, size_t cap)
{
	char name[PX_BRIDGE_TOPIC_MAX];
	int t, rc = px__bridge_join(&b->c, &b->domain, &b->dp, msg, cap);
	if (rc != PX_OK)
		return rc;
	for (t = 0; t < PX_BRIDGE_TOPIC__COUNT; t++) {
		dds_qos_t *q = px__bridge_qos(px_bridge_topic_reliable(t));
		if (!q)
			return PX_E_NOMEM;
		px_bridge_topic_name(b->ns, px_bridge_topic_short_name(t), name,
				     sizeof(name));
		b->topic[t] = dds_create_topic(b->dp, descs[t], name, q, NULL);
		b->writer[t] = b->topic[t] < 0 ? b->topic[t]
					       : dds_create_writer(b->dp,
								   b->topic[t],
								   q, NULL);
		dds_delete_qos(q);
		if (b->writer[t] < 0) {
			char what[PX_BRIDGE_TOPIC_MAX + 32];
			snprintf(what, sizeof(what), "cannot publish %s", name);
			set_msg(msg, cap, what, b->writer[t]);
			return PX_E_IO;
		}
	}
	return PX_OK;
}

static void copy_name(char *dst, const char *src)
{
	snprintf(dst, PX_BRIDGE_NAME_MAX, "%s", src);
}

int px_bridge_create(const struct px_bridge_config *c, struct px_bridge **out,
		     char *msg, size_t cap)
{
	struct px_bridge *b;
	pthread_condattr_t ca;
	char why[200];
	int rc;
	if (msg && cap)
		msg[0] = '\0';
	if (!out)
		return PX_E_INVAL;
	*out = NULL;
	if (px_bridge_config_check(c, why, sizeof(why)) != PX_OK) {
		if (msg && cap)
			snprintf(msg, cap, "bridge: %s", why);
		return PX_E_INVAL;
	}
	b = calloc(1, sizeof(*b));
	if (!b)
		return PX_E_NOMEM;
	b->c = *c;
	copy_name(b->ns, c->ns);
	copy_name(b->iface, c->interface);
	copy_name(b->frame, c->frame_id);
	b->c.ns = b->ns;
	b->c.interface = b->iface;
	b->c.frame_id = b->frame;
	b->rate_hz[PX_BRIDGE_TOOL_POSE] = c->tool_pose_rate_hz;
	b->rate_hz[PX_BRIDGE_PROXY_POSE] = c->proxy_pose_rate_hz;
	b->rate_hz[PX_BRIDGE_WRENCH] = c->wrench_rate_hz;
	b->rate_hz[PX_BRIDGE_CLOSEST_POINT] = c->distance_rate_hz;
	b->rate_hz[PX_BRIDGE_DISTANCE] = c->distance_rate_hz;
	b->rate_hz[PX_BRIDGE_STATUS] = c->status_rate_hz;
	pthread_mutex_init(&b->mu, NULL);
	pthread_condattr_init(&ca);
	pthread_condattr_setclock(&ca, CLOCK_MONOTONIC);
	pthread_cond_init(&b->cv, &ca);
	pthread_condattr_destroy(&ca);
	rc = make_entities(b, msg, cap);
	if (rc == PX_OK) {
		if (pthread_create(&b->th, NULL, bridge_thread, b) != 0) {
			if (msg && cap)
				snprintf(msg, cap,
					 "bridge: cannot start its thread");
			rc = PX_E_NOMEM;
		} else {
			b->started = 1;
		}
	}
	if (rc != PX_OK) {
		px_bridge_free(b);
		return rc;
	}
	*out = b;
	return PX_OK;
}

int px_bridge_offer(struct px_bridge *b, const struct px_bridge_sample *s)
{
	if (!b || !s)
		return PX_E_INVAL;
	pthread_mutex_lock(&b->mu);
	if (b->n_queued == PX_BRIDGE_QUEUE) { /* the oldest goes */
		b->head = (b->head + 1) % PX_BRIDGE_QUEUE;
		b->n_queued--;
		b->counts.dropped++;
	}
	b->queue[(b->head + b->n_queued) % PX_BRIDGE_QUEUE] = *s;
	if (!b->n_queued++)
		pthread_cond_signal(&b->cv);
	b->counts.offered++;
	pthread_mutex_unlock(&b->mu);
	return PX_OK;
}

int px_bridge_offer_status(struct px_bridge *b,
			   const struct px_bridge_status *s)
{
	if (!b || !s)
		return PX_E_INVAL;
	pthread_mutex_lock(&b->mu);
	b->status = *s;
	b->status_seq++;
	b->counts.status_offered++;
	pthread_mutex_unlock(&b->mu);
	return PX_OK;
}

int px_bridge_publish_joint_state(struct px_bridge *b, int64_t stamp_ns,
				  size_t n, const char *const *names,
				  const double *position_rad,
				  const double *velocity_rad_per_s,
				  const double *effort_n_m)
{
	sensor_msgs_msg_dds__JointState_ m;
	char **nm, *text = NULL;
	size_t i;
	int rc;
	if (!b || n > 1024)
		return PX_E_INVAL;
	nm = calloc(n ? n : 1, sizeof(*nm));
	if (!names)
		text = calloc(n ? n : 1, 16);
	if (!nm || (!names && !text)) {
		free(nm);
		free(text);
		return PX_E_NOMEM;
	}
	for (i = 0; i < n; i++) {
		if (names) {
			nm[i] = (char *)names[i];
		} else {
			nm[i] = text + 16 * i;
			snprintf(nm[i], 16, "joint%u", (unsigned)i);
		}
	}
	memset(&m, 0, sizeof(m));
	header(b, stamp_ns, &m.header);
	m.name._length = m.name._maximum = (uint32_t)n;
	m.name._buffer = nm;
	m.position._length = m.position._maximum =
		position_rad ? (uint32_t)n : 0;
	m.position._buffer = (double *)position_rad;
	m.velocity._length = m.velocity._maximum =
		velocity_rad_per_s ? (uint32_t)n : 0;
	m.velocity._buffer = (double *)velocity_rad_per_s;
	m.effort._length = m.effort._maximum = effort_n_m ? (uint32_t)n : 0;
	m.effort._buffer = (double *)effort_n_m;
	rc = write_msg(b, PX_BRIDGE_JOINT_STATES, &m);
	free(nm);
	free(text);
	return rc;
}

int px_bridge_publish_cloud(struct px_bridge *b, int64_t stamp_ns,
			    const float *xyz_m, size_t n)
{
	sensor_msgs_msg_dds__PointCloud2_ m;
	sensor_msgs_msg_dds__PointField_ f[3];
	static const union {
		uint16_t u;
		uint8_t c[2];
	} order = {1};
	int i;
	if (!b || (!xyz_m && n) || n > UINT32_MAX / 12)
		return PX_E_INVAL;
	memset(&m, 0, sizeof(m));
	memset(f, 0, sizeof(f));
	header(b, stamp_ns, &m.header);
	for (i = 0; i < 3; i++) {
		f[i].name = (char *)(i == 0 ? "x" : i == 1 ? "y" : "z");
		f[i].offset = (uint32_t)(4 * i);
		f[i].datatype = sensor_msgs_msg_dds__PointField_Constants_FLOAT32;
		f[i].count = 1;
	}
	m.height = 1;
	m.width = (uint32_t)n;
	m.fields._length = m.fields._maximum = 3;
	m.fields._buffer = f;
	m.is_bigendian = order.c[0] == 0;
	m.point_step = 12;
	m.row_step = (uint32_t)(12 * n);
	m.data._length = m.data._maximum = (uint32_t)(12 * n);
	m.data._buffer = (uint8_t *)xyz_m;
	m.is_dense = true;
	return write_msg(b, PX_BRIDGE_CLOUD, &m);
}

int px_bridge_wait_readers(struct px_bridge *b, int min_readers,
			   int64_t timeout_ns)
{
	int64_t end = mono_ns() + timeout_ns;
	if (!b)
		return PX_E_INVAL;
	for (;;) {
		int t, ok = 1;
		for (t = 0; t < PX_BRIDGE_TOPIC__COUNT && ok; t++) {
			dds_publication_matched_status_t m;
			if (!b->rate_hz[t])
				continue;
			if (dds_get_publication_matched_status(b->writer[t],
							       &m) < 0 ||
			    m.current_count < (uint32_t)min_readers)
				ok = 0;
		}
		if (ok)
			return PX_OK;
		if (mono_ns() >= end)
			return PX_E_TIMEOUT;
		dds_sleepfor(DDS_MSECS(10));
	}
}

void px_bridge_counts(struct px_bridge *b, struct px_bridge_counts *out)
{
	if (!out)
		return;
	memset(out, 0, sizeof(*out));
	if (!b)
		return;
	pthread_mutex_lock(&b->mu);
	*out = b->counts;
	pthread_mutex_unlock(&b->mu);
}

void px_bridge_free(struct px_bridge *b)
{
	if (!b)
		return;
	if (b->started) {
		pthread_mutex_lock(&b->mu);
		b->stop = 1;
		pthread_cond_signal(&b->cv);
		pthread_mutex_unlock(&b->mu);
		pthread_join(b->th, NULL);
	}
	if (b->dp > 0)
		dds_delete(b->dp);
	if (b->domain > 0)
		dds_delete(b->domain);
	pthread_cond_destroy(&b->cv);
	pthread_mutex_destroy(&b->mu);
	free(b);
}
