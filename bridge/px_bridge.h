/*
 * px_bridge.h - a ROS 2 compatible DDS bridge (Eclipse Cyclone DDS): the
 * loop's tool and proxy poses, force, distance and status published on
 * DDS topics that ROS 2 nodes and tools read as their own.
 *
 * Conventions (ROS 2 Humble, Iron and Jazzy alike; docs/bridge.md):
 * topics are named "rt/<namespace>/<name>", types
 * "<package>::msg::dds_::<Type>_" with ROS 2's message layouts (the IDL
 * files in bridge/idl/, compiled by Cyclone's idlc at build time).
 * Streams are best-effort keep-last-1, the status reliable keep-last-1;
 * both volatile, as ROS 2's sensor-data and default profiles.
 *
 * Threads: px_bridge_create() starts one bridge thread that publishes
 * the offered samples, each stream at its configured rate in the
 * samples' own time (their stamps), and the newest status at its rate.
 * px_bridge_offer() and px_bridge_offer_status() copy a sample into the
 * bridge's queue under a short lock and return: call them from a
 * non-real-time thread (the app's drain), never from a cycle. px_bridge_publish_*() write at once
 * from the calling (non-real-time) thread. A bridge is used by one
 * feeding thread at a time besides its own.
 *
 * Memory: create allocates (the DDS entities, the thread); offering and
 * the bridge thread's publishing may allocate inside Cyclone DDS. Nothing
 * here is real-time safe; the loop's thread never calls it.
 *
 * Devices: px_bridge_dev_create() is the "dds" back end of px_dev.h, a
 * pose stream in and a force command out, and scene updates in
 * (obstacle clouds, model poses) checked against configured limits
 * (below).
 *
 * Build: an optional part (PX_HAVE_DDS in px_features.h). Without Cyclone
 * DDS the config functions work and px_bridge_create() returns
 * PX_E_UNSUPPORTED, saying "built without Cyclone DDS".
 */
#ifndef PX_BRIDGE_H
#define PX_BRIDGE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "px_base.h"
#include "px_config.h"
#include "px_dev.h"

#ifdef __cplusplus
extern "C" {
#endif

struct px_bridge;

/* The streams the bridge publishes, and the direct-write topics. */
enum px_bridge_topic {
	PX_BRIDGE_TOOL_POSE = 0, /* geometry_msgs/PoseStamped "tool_pose" */
	PX_BRIDGE_PROXY_POSE,    /* geometry_msgs/PoseStamped "proxy_pose" */
	PX_BRIDGE_WRENCH,        /* geometry_msgs/WrenchStamped "wrench" */
	PX_BRIDGE_CLOSEST_POINT, /* geometry_msgs/PointStamped "closest_point" */
	PX_BRIDGE_DISTANCE,      /* proxima_msgs/Distance "distance" */
	PX_BRIDGE_STATUS,        /* proxima_msgs/Status "status" (reliable) */
	PX_BRIDGE_JOINT_STATES,  /* sensor_msgs/JointState "joint_states" */
	PX_BRIDGE_CLOUD,         /* sensor_msgs/PointCloud2 "cloud" */
	PX_BRIDGE_TOPIC__COUNT
};

/* Discovery: unicast to the peers on this machine, or multicast. */
enum px_bridge_discovery {
	PX_BRIDGE_DISCOVERY_AUTO = 0, /* unicast on loopback, else multicast */
	PX_BRIDGE_DISCOVERY_UNICAST,
	PX_BRIDGE_DISCOVERY_MULTICAST
};

#define PX_BRIDGE_NAME_MAX 128 /* namespace, interface, frame id */
#define PX_BRIDGE_TOPIC_MAX 192 /* "rt/<namespace>/<name>" */
#define PX_BRIDGE_DDS_CONFIG_MAX 2048 /* the generated Cyclone XML */

/* The section "bridge" of a config (docs/config.md). Rates in Hz; 0
 * leaves that stream unpublished. Strings point into the config's
 * document (or are the caller's). */
struct px_bridge_config {
	bool enable;
	int64_t domain_id;       /* 0..232 */
	const char *ns;          /* key "namespace": ROS 2 name, no leading / */
	const char *interface;   /* network interface name or IPv4 address */
	int discovery;           /* enum px_bridge_discovery */
	const char *frame_id;    /* header.frame_id of every message */
	/* key "security_file": a Cyclone DDS XML file (its DDS Security
	 * section) added to the generated configuration; NULL none */
	const char *security_file;
	/* not a key: SCHED_FIFO priority of Cyclone's receive, delivery
	 * and timed-event threads (1..99; 0: normal scheduling), so a
	 * loaded machine does not starve a real-time loop's link */
	int thread_priority;
	double tool_pose_rate_hz;
	double proxy_pose_rate_hz;
	double wrench_rate_hz;
	double distance_rate_hz; /* distance and closest_point */
	double status_rate_hz;
};

/* Defaults: off, domain 0, namespace "proxima", interface "lo",
 * discovery auto, frame "world", streams at 100 Hz (distance 50 Hz),
 * status at 10 Hz. */
PX_API void px_bridge_config_default(struct px_bridge_config *c);

/* The section's schema (tools and the docs check). */
PX_API const struct px_config_schema *px_bridge_config_schema(void);

/*
 * Read the section "bridge" of a loaded config into out (defaults when
 * absent). Problems go to diag as "file:line:column: bridge.key: what".
 * Returns PX_OK, PX_E_PARSE or PX_E_INVAL (NULL).
 */
PX_API int px_bridge_config_read(const struct px_config *cfg,
				 struct px_bridge_config *out,
				 struct px_config_diag *diag);

/* Check a filled config (also one made in code): names, ranges. PX_OK
 * or PX_E_INVAL with why. */
PX_API int px_bridge_config_check(const struct px_bridge_config *c,
				  char *why, size_t cap);

/* "rt/<namespace>/<name>" into buf. PX_OK or PX_E_RANGE (too long). */
PX_API int px_bridge_topic_name(const char *ns, const char *name, char *buf,
				size_t cap);

/* A topic's name ("tool_pose") and its DDS type name
 * ("geometry_msgs::msg::dds_::PoseStamped_"); NULL out of range. */
PX_API const char *px_bridge_topic_short_name(enum px_bridge_topic t);
PX_API const char *px_bridge_topic_type_name(enum px_bridge_topic t);
/* 1: the topic is reliable (status), 0: best-effort keep-last-1. */
PX_API int px_bridge_topic_reliable(enum px_bridge_topic t);

/* The topic's type for a reader of one's own: Cyclone DDS's
 * dds_topic_descriptor_t (const), compiled from bridge/idl/. NULL out of
 * range or in a build without Cyclone DDS. */
PX_API const void *px_bridge_topic_descriptor(enum px_bridge_topic t);

/*
 * The Cyclone DDS configuration the bridge runs with (XML, the content a
 * CYCLONEDDS_URI could hold): the interface, multicast off and the
 * localhost peers for unicast discovery, then ",file://<security_file>"
 * when one is given (Cyclone reads the list in order). PX_OK or
 * PX_E_RANGE / PX_E_INVAL.
 */
PX_API int px_bridge_dds_config(const struct px_bridge_config *c, char *buf,
				size_t cap);

/* What the loop did, as one feeding thread offers it. Times are
 * CLOCK_REALTIME nanoseconds (ROS 2's stamps). */
struct px_bridge_sample {
	int64_t stamp_ns;
	double tool_m[3];
	double tool_quat_xyzw[4];
	double proxy_m[3];
	double force_n[3];
	double torque_n_m[3];
	bool distance_valid;
	double distance_m;      /* signed: < 0 in contact */
	double tool_point_m[3]; /* the point the distance is measured from */
	double closest_m[3];    /* the closest point of the scene */
	double normal[3];       /* unit, from the scene towards the tool */
};

struct px_bridge_status {
	int64_t stamp_ns;
	double loop_rate_hz;
	double latency_p50_us, latency_p99_us, latency_max_us;
	bool safe_state;
	uint64_t cycles, overruns, faults, safe_state_trips;
	uint64_t telemetry_dropped;
};

/* What the bridge did. */
struct px_bridge_counts {
	uint64_t offered, status_offered;
	uint64_t dropped; /* offered samples the queue had no room for */
	uint64_t published[PX_BRIDGE_TOPIC__COUNT];
	uint64_t write_errors;
	int last_error; /* Cyclone's return code of the last failed write */
};

/*
 * Join the domain with the configuration of px_bridge_dds_config(),
 * make the topics and writers and start the bridge thread. c's strings
 * are copied. Returns PX_OK, PX_E_INVAL (c refused: msg says why),
 * PX_E_IO (Cyclone DDS refused: msg has its reason), PX_E_NOMEM or
 * PX_E_UNSUPPORTED (built without Cyclone DDS).
 */
PX_API int px_bridge_create(const struct px_bridge_config *c,
			    struct px_bridge **out, char *msg, size_t cap);

/* A sample for the bridge thread's queue (full: the oldest is dropped and
 * counted), stamps in increasing order; the newest status. PX_OK or
 * PX_E_INVAL. */
PX_API int px_bridge_offer(struct px_bridge *b,
			   const struct px_bridge_sample *s);
PX_API int px_bridge_offer_status(struct px_bridge *b,
				  const struct px_bridge_status *s);

/* Write one message now. names may be NULL (then "joint<i>"); position,
 * velocity, effort may be NULL (an empty array, as ROS 2 allows).
 * PX_OK, PX_E_INVAL or PX_E_IO. */
PX_API int px_bridge_publish_joint_state(struct px_bridge *b, int64_t stamp_ns,
					 size_t n, const char *const *names,
					 const double *position_rad,
					 const double *velocity_rad_per_s,
					 const double *effort_n_m);
/* n points x, y, z (float32, metres) as an unordered dense cloud. */
PX_API int px_bridge_publish_cloud(struct px_bridge *b, int64_t stamp_ns,
				   const float *xyz_m, size_t n);

/* Wait (at most timeout_ns) until each stream writer with a nonzero rate
 * and the status writer has at least min_readers matched readers. PX_OK
 * or PX_E_TIMEOUT. For tests and tools that must not publish into the
 * void. */
PX_API int px_bridge_wait_readers(struct px_bridge *b, int min_readers,
				  int64_t timeout_ns);

PX_API void px_bridge_counts(struct px_bridge *b, struct px_bridge_counts *out);

/* Stop the thread, leave the domain. NULL is a no-op. */
PX_API void px_bridge_free(struct px_bridge *b);

/* ---- the "dds" device back end -------------------------------------- */

/* Remote parameters (proxima_msgs/Params): the haptic renderer's
 * stiffness, damping and force clamp, and a speed scale on the task. */
struct px_bridge_params {
	double stiffness_n_per_m, damping_n_s_per_m, max_force_n, speed_scale;
};

/* Models whose poses one dds device may set; points of a remote cloud. */
#define PX_BRIDGE_SCENE_MODELS 16
#define PX_BRIDGE_CLOUD_MAX_POINTS (1 << 20)
#define PX_BRIDGE_MAX_JOINTS 16

struct px_cloud_feed;

/* A device on DDS topics rt/<namespace>/<topic> (bridge's namespace and
 * network), best-effort keep-last-1 as the bridge's streams (the
 * parameters reliable). */
struct px_bridge_dev_config {
	const struct px_bridge_config *bridge; /* domain, namespace, network */
	/* geometry_msgs/PoseStamped in: the device's pose input (NULL none) */
	const char *pose_topic;
	/* geometry_msgs/WrenchStamped out: its force command (NULL none) */
	const char *command_topic;
	/* geometry_msgs/WrenchStamped in: a remote force, read with
	 * px_bridge_dev_wrench() (NULL none) */
	const char *wrench_topic;
	/* geometry_msgs/PoseStamped out: a pose written in the cycle with
	 * px_bridge_dev_pose_write() (NULL none) */
	const char *pose_out_topic;
	/* proxima_msgs/Params in (reliable; NULL none): a message whose
	 * every value is finite and within [params_min, params_max] is
	 * handed to the cycle (px_bridge_dev_params()), any other is
	 * refused and counted. Not waited for by px_dev_start(). */
	const char *params_topic;
	struct px_bridge_params params_min, params_max;
	/* Scene updates in (docs/bridge.md, "Scene updates"). cloud_topic:
	 * sensor_msgs/PointCloud2 obstacle clouds, each accepted one built
	 * into cloud_feed (px_cloud_feed.h) by the device's thread, stamped
	 * with the loop clock at receipt. scene_topic: one
	 * geometry_msgs/PoseStamped topic per name of scene_models,
	 * <scene_topic>/<name>/pose, read by px_bridge_dev_scene_poses().
	 * A message is accepted whole or refused and counted: its frame_id
	 * must be the bridge's frame_id and every point or the position
	 * finite and inside [workspace_min_m, workspace_max_m]; a cloud has
	 * float32 fields x, y, z inside its point_step, consistent sizes
	 * and at most cloud_max_points (1 .. PX_BRIDGE_CLOUD_MAX_POINTS,
	 * at most the feed's) points; a pose a unit quaternion (within
	 * 1e-3). NULL topics: none. */
	const char *cloud_topic;
	struct px_cloud_feed *cloud_feed;
	size_t cloud_max_points;
	const char *scene_topic;
	const char *const *scene_models; /* ROS 2 name tokens */
	size_t n_scene_models;           /* 1 .. PX_BRIDGE_SCENE_MODELS */
	double workspace_min_m[3], workspace_max_m[3];
	/* A remote arm (docs/bridge.md, "Remote joints"): joint_state_topic,
	 * sensor_msgs/JointState in, the positions (and velocities, when
	 * given) of joint_names by name, in any order among others, read
	 * with px_bridge_dev_joint_state(); a message without one of the
	 * names, with lengths that differ (velocity may be empty) or a
	 * non-finite value is refused and counted. joint_command_topic,
	 * sensor_msgs/JointState out: joint_names with the position target
	 * and velocity the cycle writes (px_bridge_dev_joint_command());
	 * px_bridge_dev_joint_hold() sends velocity 0 at the newest
	 * received position. NULL topics: none. */
	const char *joint_state_topic;
	const char *joint_command_topic;
	const char *const *joint_names; /* 1 .. PX_BRIDGE_MAX_JOINTS */
	size_t n_joints;
	/* px_dev_start() waits at most this long until every topic above
	 * but the parameters and the scene poses has a peer (0: no wait) */
	int64_t connect_timeout_ns;
	/* SCHED_FIFO priority of the device's thread (1..99; 0: normal
	 * scheduling; refused without the privilege: normal) */
	int thread_priority;
};

/*
 * A device (px_dev.h) on the topics above: caps PX_DEV_CAP_POSE with a
 * pose_topic, PX_DEV_CAP_FORCE with a command_topic. Its own thread
 * takes each pose as it arrives, stamped with the loop clock at
 * receipt, so a silent peer makes the samples stale after
 * dc->stale_timeout_ns and the loop's watchdog trips; a command or pose
 * written in the cycle only crosses a wait-free slot and goes out within
 * a fraction of a millisecond. In safe state the loop zeroes the command
 * (px_dev_force_attach) and px_dev_safe() sends a zero wrench at once.
 * px_dev_start() starts the thread after the peers matched (or
 * PX_E_TIMEOUT naming the topic without one). Returns PX_OK, PX_E_INVAL
 * (msg says why), PX_E_IO (Cyclone DDS refused), PX_E_NOMEM or
 * PX_E_UNSUPPORTED (built without Cyclone DDS).
 */
PX_API int px_bridge_dev_create(const struct px_dev_config *dc,
				const struct px_bridge_dev_config *bc,
				struct px_dev **out, char *msg, size_t cap);

/* The newest remote force of the wrench_topic and its receipt time on
 * the loop clock (*t_ns). Returns 1, 0 (none yet) or PX_E_INVAL (not a
 * dds device with a wrench_topic). Loop thread. @note RT-safe. */
PX_API int px_bridge_dev_wrench(struct px_dev *d, struct px_force_cmd *out,
				int64_t *t_ns);

/* A pose for the pose_out_topic (sent by the device's thread, stamped
 * with CLOCK_REALTIME then). PX_OK or PX_E_INVAL. Loop thread.
 * @note RT-safe. */
PX_API int px_bridge_dev_pose_write(struct px_dev *d, const px_vec3 *pos_m,
				    const px_quat *q);

/* The newest accepted parameter set, when one arrived since this
 * thread's last call: 1 and *out, else 0; PX_E_INVAL (not a dds device
 * with a params_topic). Through a px_param triple buffer: never torn.
 * Loop thread. @note RT-safe. */
PX_API int px_bridge_dev_params(struct px_dev *d, struct px_bridge_params *out);

/* The remote poses of the scene_models (index as there): seq[i]
 * counts model i's accepted poses (0: none yet), pose[i] the newest. */
struct px_bridge_scene_poses {
	uint64_t seq[PX_BRIDGE_SCENE_MODELS];
	px_pose pose[PX_BRIDGE_SCENE_MODELS];
};

/* The newest scene poses, when a pose was accepted since this thread's
 * last call: 1 and *out, else 0; PX_E_INVAL (not a dds device with a
 * scene_topic). Through a px_param triple buffer: never torn. Loop
 * thread. @note RT-safe. */
PX_API int px_bridge_dev_scene_poses(struct px_dev *d,
				     struct px_bridge_scene_poses *out);

/* A remote arm's newest joint state (joint_names' order), its receipt
 * on the loop clock. */
struct px_bridge_joint_state {
	double position_rad[PX_BRIDGE_MAX_JOINTS];
	double velocity_rad_per_s[PX_BRIDGE_MAX_JOINTS]; /* 0: none given */
	int64_t t_ns;
};

/* The newest accepted joint state: 1 and *out, 0 (none yet) or
 * PX_E_INVAL (not a dds device with a joint_state_topic). Loop thread.
 * @note RT-safe. */
PX_API int px_bridge_dev_joint_state(struct px_dev *d,
				     struct px_bridge_joint_state *out);

/* A joint command (n_joints values each; velocity may be NULL: zeros)
 * for the joint_command_topic, sent by the device's thread. PX_OK or
 * PX_E_INVAL. Loop thread. @note RT-safe. */
PX_API int px_bridge_dev_joint_command(struct px_dev *d,
				       const double *position_rad,
				       const double *velocity_rad_per_s);

/* Hold the remote arm now: velocity 0 at the newest received position
 * (before any: the last commanded one), sent from the calling thread
 * and kept as the newest command until the cycle writes another; a
 * write DDS accepted is the confirmation (px_dev_safe() covers force
 * and I/O devices only; a shutdown calls this for a remote arm). PX_OK,
 * PX_E_IO, PX_E_INVAL (not a dds device with a joint_command_topic).
 * Not RT-safe (a DDS write). */
PX_API int px_bridge_dev_joint_hold(struct px_dev *d);

/* What a dds device's thread did. */
struct px_bridge_dev_counts {
	uint64_t poses_in, wrenches_in, commands_out, poses_out;
	uint64_t params_accepted, params_refused;
	/* scene updates: clouds built into the feed, refused, dropped (the
	 * feed had no free slot); model poses accepted, refused */
	uint64_t clouds_accepted, clouds_refused, clouds_dropped;
	uint64_t scene_poses_accepted, scene_poses_refused;
	/* remote joints: states accepted, refused; commands sent */
	uint64_t joint_states_in, joint_states_refused, joint_commands_out;
	/* best-effort samples the readers know were lost (DDS's sample
	 * lost status, sequence gaps) */
	uint64_t lost;
};

/* PX_OK or PX_E_INVAL (not a dds device). Any thread. */
PX_API int px_bridge_dev_counts(struct px_dev *d,
				struct px_bridge_dev_counts *out);

#ifdef __cplusplus
}
#endif

#endif
