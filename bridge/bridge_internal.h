/*
 * bridge_internal.h - private to bridge/: the limits and helpers that the
 * config side (px_bridge.c) and the DDS side (px_bridge_dds.c) share.
 */
#ifndef PX_BRIDGE_INTERNAL_H
#define PX_BRIDGE_INTERNAL_H

#include <stdatomic.h>

#include "px_bridge.h"

/* Highest stream rate: the loop's own rate bounds what is new anyway. */
#define PX_BRIDGE_MAX_RATE_HZ 10000.0
/* Processes on one machine that unicast discovery finds each other
 * among (participant indices 0 .. this). */
#define PX_BRIDGE_MAX_PARTICIPANTS 32

/* Samples offered and not yet published that a bridge holds; more drop
 * the oldest (counted). The app drains every 20 ms on the real clock,
 * in batches of up to 1000 cycles on the virtual one. */
#define PX_BRIDGE_QUEUE 256

/* DDS side (px_bridge_dds.c), shared with the device back end: join the
 * domain of c with the configuration of px_bridge_dds_config() (*domain
 * 0 when it existed before), and the QoS of a stream (best-effort) or of
 * the status (reliable), keep-last-1, volatile: a dds_qos_t to delete
 * with dds_delete_qos(), NULL without memory. Entities are Cyclone's
 * dds_entity_t (int32_t). */
int px__bridge_join(const struct px_bridge_config *c, int32_t *domain,
		    int32_t *dp, char *msg, size_t cap);
void *px__bridge_qos(int reliable);

/* A value handed between a cycle and a device's thread (a seqlock: seq
 * odd while the writer copies; a reader retries a torn copy, a few
 * times at most). get: the value when seq differs from *last (then
 * updated), 1; else 0 (also after too many torn copies). RT-safe. */
struct px__slot {
	atomic_uint_fast64_t seq;
	_Alignas(8) unsigned char v[288];
};
void px__slot_put(struct px__slot *s, const void *v, size_t n);
int px__slot_get(struct px__slot *s, void *v, size_t n, uint64_t *last);

/* A best-effort keep-last-1 reader of rt/<ns>/<name> (type: a
 * dds_topic_descriptor_t) on participant dp whose data wakes the
 * waitset *ws (made on first use). Cyclone's entity or its error. */
int32_t px__bridge_watched_reader(int32_t dp, int32_t *ws, const char *ns,
				  const char *name, const void *type);
/* header (a std_msgs_msg_dds__Header_) stamped now (CLOCK_REALTIME,
 * ROS 2's time) in frame (kept by the caller). */
void px__bridge_header_now(void *header, char *frame);

/* A best-effort keep-last-1 writer of rt/<ns>/<name>. */
int32_t px__bridge_writer(int32_t dp, const char *ns, const char *name,
			  const void *type);

/* A dds device's scene updates (px_bridge_scene.c): made by
 * px__bridge_scene_open() (*out NULL when bc asks for none; on an error
 * *out may hold what was made, for px__bridge_scene_free()), taken by
 * the device's thread (px__bridge_scene_take), the model poses read by
 * the cycle (px__bridge_scene_poses, RT-safe). The two checks say why a
 * message is refused ("frame", "fields", "points", "sizes",
 * "workspace", "orientation") or return NULL with its content. */
struct bridge_scene;
int px__bridge_scene_open(struct bridge_scene **out, int32_t dp, int32_t *ws,
			  const struct px_bridge_dev_config *bc, char *msg,
			  size_t cap);
void px__bridge_scene_take(struct bridge_scene *s);
int px__bridge_scene_poses(struct bridge_scene *s,
			   struct px_bridge_scene_poses *out);
void px__bridge_scene_counts(const struct bridge_scene *s,
			     struct px_bridge_dev_counts *out);
int32_t px__bridge_scene_cloud_reader(const struct bridge_scene *s);
void px__bridge_scene_free(struct bridge_scene *s);
struct px__bridge_limits {
	const char *frame;   /* the header's frame_id must be this */
	double lo_m[3], hi_m[3];
	size_t max_points;   /* of a cloud */
};
/* msg: a sensor_msgs_msg_dds__PointCloud2_ (its points into xyz, room
 * for max_points) or a geometry_msgs_msg_dds__PoseStamped_. */
const char *px__bridge_cloud_points(const void *msg,
				    const struct px__bridge_limits *s,
				    double *xyz, size_t *n);
const char *px__bridge_scene_pose(const void *msg,
				  const struct px__bridge_limits *s, px_pose *out);

/* A dds device's joints (px_bridge_joint.c): a remote arm's joint
 * states in, joint commands out, as px__bridge_scene_* above. hold
 * sends velocity 0 at the newest received position (else the last
 * commanded one) from the calling thread; PX_OK, PX_E_IO. */
struct bridge_joints;
int px__bridge_joints_open(struct bridge_joints **out, int32_t dp, int32_t *ws,
			   const struct px_bridge_dev_config *bc, char *msg,
			   size_t cap);
void px__bridge_joints_take(struct bridge_joints *j);
int px__bridge_joints_hold(struct bridge_joints *j);
int px__bridge_joints_state(struct bridge_joints *j,
			    struct px_bridge_joint_state *out);
int px__bridge_joints_command(struct bridge_joints *j, const double *position_rad,
			      const double *velocity_rad_per_s);
void px__bridge_joints_counts(const struct bridge_joints *j,
			      struct px_bridge_dev_counts *out);
/* its reader and writer (0: none), for the connect wait */
int32_t px__bridge_joints_endpoint(const struct bridge_joints *j, int writer);
void px__bridge_joints_free(struct bridge_joints *j);
/* msg: a sensor_msgs_msg_dds__JointState_; the positions (velocities:
 * 0 when it has none) of names[0..n) into out, or why it is refused
 * ("lengths", "joint", "non-finite"). */
const char *px__bridge_joint_state(const void *msg, const char *const *names,
				   size_t n, struct px_bridge_joint_state *out);

/* 1 for the loopback interface ("lo", 127.x.x.x, ::1, localhost). */
int px_bridge_is_loopback(const char *iface);

#endif
