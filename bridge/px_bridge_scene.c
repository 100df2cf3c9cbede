/* Scene updates of a dds device (px_bridge_dev_config's cloud_topic and
 * scene_topic): obstacle clouds (sensor_msgs/PointCloud2) checked and
 * built into the app's cloud feed, model poses (geometry_msgs/
 * PoseStamped, one topic per model) checked and handed to the cycle
 * through a triple buffer. Everything here but px__bridge_scene_poses()
 * runs in the device's thread or at setup. */
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <dds/dds.h>

#include "bridge_internal.h"
#include "geometry_msgs.h"
#include "px_arena.h"
#include "px_cloud_feed.h"
#include "px_param.h"
#include "schema_internal.h"
#include "sensor_msgs.h"

struct bridge_scene {
	char frame[PX_BRIDGE_NAME_MAX];
	struct px__bridge_limits lim;               /* its frame: the above */
	dds_entity_t cloud;                         /* reader, 0 none */
	dds_entity_t pose[PX_BRIDGE_SCENE_MODELS];  /* readers */
	size_t n_models;
	struct px_cloud_feed *feed;
	double *xyz;                                /* max_points * 3 */
	struct px_arena arena;                      /* the poses' buffer */
	struct px_param *param;
	struct px_bridge_scene_poses poses;         /* the thread's copy */
	_Atomic uint64_t clouds_in, clouds_refused, clouds_dropped;
	_Atomic uint64_t poses_in, poses_refused;
};

static int inside(const struct px__bridge_limits *s, const double p[3])
{
	int k;
	for (k = 0; k < 3; k++)
		if (!(p[k] >= s->lo_m[k] && p[k] <= s->hi_m[k])) /* NaN fails */
			return 0;
	return 1;
}

static int frame_ok(const struct px__bridge_limits *s, const char *frame)
{
	return frame && s->frame && !strcmp(frame, s->frame);
}

/* The offset of float32 field `name` (count 1), or -1. */
static long field_offset(const sensor_msgs_msg_dds__PointCloud2_ *m,
			 const char *name)
{
	uint32_t i;
	for (i = 0; i < m->fields._length; i++) {
		const sensor_msgs_msg_dds__PointField_ *f = &m->fields._buffer[i];
		if (f->name && !strcmp(f->name, name))
			return f->datatype ==
					       sensor_msgs_msg_dds__PointField_Constants_FLOAT32 &&
				       f->count == 1 &&
				       (uint64_t)f->offset + 4 <= m->point_step
				       ? (long)f->offset
				       : -1;
	}
	return -1;
}

static float get_f32(const uint8_t *p, int swap)
{
	uint8_t b[4];
	float v;
	if (swap) {
		b[0] = p[3], b[1] = p[2], b[2] = p[1], b[3] = p[0];
		p = b;
	}
	memcpy(&v, p, 4);
	return v;
}

/*
 * The points of cloud m into xyz (*n of them), or why it is refused:
 * the frame, x, y and z as float32 fields inside the point step, the
 * sizes (height x width points, row_step at least width x point_step,
 * data exactly height x row_step bytes), at most max_points, each point
 * finite and inside the workspace. Either byte order.
 */
const char *px__bridge_cloud_points(const void *msg,
				    const struct px__bridge_limits *s,
				    double *xyz, size_t *n)
{
	const sensor_msgs_msg_dds__PointCloud2_ *m = msg;
	static const union {
		uint16_t u;
		uint8_t b[2];
	} order = {1};
	long off[3];
	uint64_t npts = (uint64_t)m->height * m->width, r, c;
	int k, swap = (m->is_bigendian != 0) != (order.b[0] == 0);
	*n = 0;
	if (!frame_ok(s, m->header.frame_id))
		return "frame";
	for (k = 0; k < 3; k++)
		if ((off[k] = field_offset(m, k == 0 ? "x" : k == 1 ? "y" : "z")) < 0)
			return "fields";
	if (npts > s->max_points)
		return "points";
	if ((uint64_t)m->row_step < (uint64_t)m->width * m->point_step ||
	    (uint64_t)m->data._length != (uint64_t)m->height * m->row_step ||
	    (npts && !m->data._buffer))
		return "sizes";
	for (r = 0; r < m->height; r++)
		for (c = 0; c < m->width; c++) {
			const uint8_t *p = m->data._buffer + r * m->row_step +
					   c * m->point_step;
			double *q = xyz + 3 * *n;
			for (k = 0; k < 3; k++)
				q[k] = get_f32(p + off[k], swap);
			if (!inside(s, q))
				return "workspace";
			(*n)++;
		}
	return NULL;
}

/* The pose of m, or why it is refused: the frame, a finite position
 * inside the workspace, a finite quaternion of norm 1 within 1e-3
 * (normalised). */
const char *px__bridge_scene_pose(const void *msg,
				  const struct px__bridge_limits *s, px_pose *out)
{
	const geometry_msgs_msg_dds__PoseStamped_ *m = msg;
	const geometry_msgs_msg_dds__Quaternion_ *q = &m->pose.orientation;
	double p[3] = {m->pose.position.x, m->pose.position.y, m->pose.position.z};
	double len = sqrt(q->w * q->w + q->x * q->x + q->y * q->y + q->z * q->z);
	if (!frame_ok(s, m->header.frame_id))
		return "frame";
	if (!inside(s, p))
		return "workspace";
	if (!(fabs(len - 1.0) <= 1e-3))
		return "orientation";
	out->t = px_v3(p[0], p[1], p[2]);
	out->q.w = q->w / len;
	out->q.x = q->x / len;
	out->q.y = q->y / len;
	out->q.z = q->z / len;
	return NULL;
}

/* Clouds as they arrive: checked, then built into the feed (a frame the
 * feed has no free slot for is dropped and counted), stamped with the
 * loop clock at receipt so a silent source ages. */
static void take_clouds(struct bridge_scene *s)
{
	for (;;) {
		void *buf[1] = {NULL};
		dds_sample_info_t info[1];
		size_t n;
		int k = dds_take(s->cloud, buf, info, 1, 1);
		if (k <= 0)
			return;
		if (info[0].valid_data) {
			if (px__bridge_cloud_points(buf[0], &s->lim, s->xyz, &n))
				atomic_fetch_add(&s->clouds_refused, 1);
			else if (px_cloud_feed_publish(s->feed, s->xyz, n,
						       px_dev_mono_ns()) == PX_OK)
				atomic_fetch_add(&s->clouds_in, 1);
			else
				atomic_fetch_add(&s->clouds_dropped, 1);
		}
		dds_return_loan(s->cloud, buf, k);
	}
}

static void take_poses(struct bridge_scene *s, size_t i)
{
	for (;;) {
		void *buf[1] = {NULL};
		dds_sample_info_t info[1];
		px_pose p;
		int k = dds_take(s->pose[i], buf, info, 1, 1);
		if (k <= 0)
			return;
		if (info[0].valid_data) {
			if (px__bridge_scene_pose(buf[0], &s->lim, &p)) {
				atomic_fetch_add(&s->poses_refused, 1);
			} else {
				s->poses.pose[i] = p;
				s->poses.seq[i]++;
				px_param_write(s->param, &s->poses);
				atomic_fetch_add(&s->poses_in, 1);
			}
		}
		dds_return_loan(s->pose[i], buf, k);
	}
}

void px__bridge_scene_take(struct bridge_scene *s)
{
	size_t i;
	if (!s)
		return;
	if (s->cloud > 0)
		take_clouds(s);
	for (i = 0; i < s->n_models; i++)
		take_poses(s, i);
}

int px__bridge_scene_poses(struct bridge_scene *s,
			   struct px_bridge_scene_poses *out)
{
	const struct px_bridge_scene_poses *p;
	int fresh = 0;
	if (!s || !s->param || !out)
		return PX_E_INVAL;
	p = px_param_read(s->param, &fresh);
	if (!fresh)
		return 0;
	*out = *p;
	return 1;
}

void px__bridge_scene_counts(const struct bridge_scene *s,
			     struct px_bridge_dev_counts *out)
{
	if (!s)
		return;
	out->clouds_accepted = atomic_load(&s->clouds_in);
	out->clouds_refused = atomic_load(&s->clouds_refused);
	out->clouds_dropped = atomic_load(&s->clouds_dropped);
	out->scene_poses_accepted = atomic_load(&s->poses_in);
	out->scene_poses_refused = atomic_load(&s->poses_refused);
}

int32_t px__bridge_scene_cloud_reader(const struct bridge_scene *s)
{
	return s ? s->cloud : 0;
}

void px__bridge_scene_free(struct bridge_scene *s)
{
	if (!s)
		return;
	free(s->xyz);
	px_arena_fini(&s->arena);
	free(s);
}

static int check_config(const struct px_bridge_dev_config *bc, char *msg,
			size_t cap)
{
	size_t i;
	int k;
	if (bc->cloud_topic && (!bc->cloud_feed || bc->cloud_max_points == 0 ||
				bc->cloud_max_points > PX_BRIDGE_CLOUD_MAX_POINTS)) {
		snprintf(msg, cap, "dds device: a cloud_topic needs a cloud feed "
				   "and 1 .. %d points",
			 PX_BRIDGE_CLOUD_MAX_POINTS);
		return PX_E_INVAL;
	}
	if (bc->scene_topic && (bc->n_scene_models == 0 ||
				bc->n_scene_models > PX_BRIDGE_SCENE_MODELS ||
				!bc->scene_models)) {
		snprintf(msg, cap, "dds device: a scene_topic needs 1 .. %d models",
			 PX_BRIDGE_SCENE_MODELS);
		return PX_E_INVAL;
	}
	for (i = 0; bc->scene_topic && i < bc->n_scene_models; i++)
		if (!bc->scene_models[i] ||
		    px__ros_name_problem(bc->scene_models[i], 64)) {
			snprintf(msg, cap, "dds device: scene model '%s' is not "
					   "a ROS 2 name token",
				 bc->scene_models[i] ? bc->scene_models[i] : "");
			return PX_E_INVAL;
		}
	for (k = 0; k < 3; k++)
		if (!(bc->workspace_min_m[k] <= bc->workspace_max_m[k]) ||
		    !isfinite(bc->workspace_min_m[k] + bc->workspace_max_m[k])) {
			snprintf(msg, cap, "dds device: the workspace is empty "
					   "or not finite");
			return PX_E_INVAL;
		}
	return PX_OK;
}

int px__bridge_scene_open(struct bridge_scene **out, int32_t dp, int32_t *ws,
			  const struct px_bridge_dev_config *bc, char *msg,
			  size_t cap)
{
	const char *ns = bc->bridge->ns;
	struct bridge_scene *s;
	char name[PX_BRIDGE_TOPIC_MAX];
	size_t i;
	int rc;
	*out = NULL;
	if (!bc->cloud_topic && !bc->scene_topic)
		return PX_OK;
	rc = check_config(bc, msg, cap);
	if (rc != PX_OK)
		return rc;
	s = calloc(1, sizeof(*s));
	if (!s)
		return PX_E_NOMEM;
	*out = s;
	snprintf(s->frame, sizeof(s->frame), "%s", bc->bridge->frame_id);
	s->lim.frame = s->frame;
	memcpy(s->lim.lo_m, bc->workspace_min_m, sizeof(s->lim.lo_m));
	memcpy(s->lim.hi_m, bc->workspace_max_m, sizeof(s->lim.hi_m));
	if (bc->cloud_topic) {
		s->feed = bc->cloud_feed;
		s->lim.max_points = bc->cloud_max_points;
		s->xyz = malloc(3 * sizeof(double) * s->lim.max_points);
		if (!s->xyz)
			return PX_E_NOMEM;
		s->cloud = px__bridge_watched_reader(
			dp, ws, ns, bc->cloud_topic,
			&sensor_msgs_msg_dds__PointCloud2__desc);
		if (s->cloud < 0) {
			snprintf(msg, cap, "dds device: cannot read %s: %s",
				 bc->cloud_topic, dds_strretcode(s->cloud));
			return PX_E_IO;
		}
	}
	if (!bc->scene_topic)
		return PX_OK;
	rc = px_arena_init_alloc(&s->arena, px_param_size(sizeof(s->poses)) + 256);
	if (rc == PX_OK)
		rc = px_param_create(&s->arena, sizeof(s->poses), &s->poses,
				     &s->param);
	if (rc != PX_OK)
		return rc;
	s->n_models = bc->n_scene_models;
	for (i = 0; i < s->n_models; i++) {
		snprintf(name, sizeof(name), "%s/%s/pose", bc->scene_topic,
			 bc->scene_models[i]);
		s->pose[i] = px__bridge_watched_reader(
			dp, ws, ns, name, &geometry_msgs_msg_dds__PoseStamped__desc);
		if (s->pose[i] < 0) {
			snprintf(msg, cap, "dds device: cannot read %s: %s", name,
				 dds_strretcode(s->pose[i]));
			return PX_E_IO;
		}
	}
	return PX_OK;
}
