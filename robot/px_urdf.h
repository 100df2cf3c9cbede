/*
 * px_urdf.h - robots described by URDF files: links with their collision
 * geometry, joints, the kinematic chain between two named links, and
 * one distance model per collision shape posed by forward kinematics.
 *
 * A robot's vendor (or xacro, run first: xacro itself is not read here)
 * gives a URDF file: <link> elements whose <collision> elements hold a
 * <geometry> (box, cylinder, sphere, or a mesh file with a scale) at an
 * <origin>, and <joint> elements (revolute, continuous, prismatic, fixed)
 * joining a parent link to a child link at an origin, about or along an
 * axis, within limits. px_urdf_load() reads the file with libxml2
 * (no network, no entity expansion) and checks it: names unique, every
 * joint's links present, one root, no link with two parents, numbers
 * finite and in range, mesh files found ("package://NAME/..." looked up
 * as NAME/... under each configured package path, relative paths from
 * the URDF file's folder). Every refusal names the file, the line and
 * the element: "arm.urdf:42: <joint name='elbow'>: unknown type 'ball'".
 * <visual>, <inertial>, <material>, <transmission>, <gazebo> and other
 * elements are skipped.
 *
 * px_urdf_robot_create() then takes the chain from a base link to a tip
 * link: its movable joints become a px_control_chain (fixed joints fold
 * into the next joint's origin), and every collision shape of the links
 * rigidly attached to it (the chain's links and whatever hangs off them
 * by fixed joints) becomes a px_model in its own frame (boxes, cylinders
 * and spheres exactly as px_prim primitives; meshes through the mesh
 * importer, scaled), with the link frame it rides on.
 * px_urdf_robot_set_q() poses them all for a joint configuration, so
 * scenes and model pairs (px_pair.h) measure link clearances.
 *
 * Memory and real-time rules: loading and creating allocate (setup
 * only); px_urdf_robot_set_q() and the accessors are RT-safe (no heap,
 * bounded work). A robot keeps its own copy of what it needs; the
 * px_urdf may be freed after px_urdf_robot_create(). Not thread-safe:
 * one thread sets q and queries the shape models.
 *
 * Built with libxml2 only (the "xml" optional part); without it
 * px_urdf_load() returns PX_E_UNSUPPORTED and says so.
 */
#ifndef PX_URDF_H
#define PX_URDF_H

#include <stddef.h>

#include "px_base.h"
#include "px_control.h"
#include "px_math.h"
#include "px_model.h"
#include "px_pair.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Limits of what a URDF may hold. */
#define PX_URDF_MAX_BYTES ((size_t)16 << 20) /* file size */
#define PX_URDF_MAX_LINKS 1024
#define PX_URDF_MAX_SHAPES 4096              /* collision shapes in all */
#define PX_URDF_MAX_PACKAGE_PATHS 16
#define PX_URDF_MAX_LENGTH 1e6               /* |xyz|, sizes: metres */

enum px_urdf_joint_type {
	PX_URDF_FIXED = 0,
	PX_URDF_REVOLUTE = 1,  /* limits required */
	PX_URDF_CONTINUOUS = 2,/* revolute without position limits */
	PX_URDF_PRISMATIC = 3  /* limits required */
};

enum px_urdf_shape_type {
	PX_URDF_BOX = 1,      /* size: full extents x, y, z */
	PX_URDF_CYLINDER = 2, /* size[0] radius, size[1] length (along z) */
	PX_URDF_SPHERE = 3,   /* size[0] radius */
	PX_URDF_MESH = 4      /* mesh: resolved path; size: scale x, y, z */
};

/* One <collision> element. */
struct px_urdf_shape {
	int type;            /* enum px_urdf_shape_type */
	px_pose origin;      /* shape frame in the link frame */
	double size[3];
	const char *mesh;    /* PX_URDF_MESH: the file found, else NULL */
	long line;           /* of the <collision> element */
};

struct px_urdf_link {
	const char *name;
	int n_shapes;
	const struct px_urdf_shape *shapes;
	int parent_joint;    /* -1 for the root */
	long line;
};

struct px_urdf_joint {
	const char *name;
	int type;            /* enum px_urdf_joint_type */
	int parent, child;   /* link indices */
	px_pose origin;      /* child joint frame in the parent link frame */
	px_vec3 axis;        /* unit, joint frame (default x) */
	int has_limits;      /* a <limit> element was given */
	double lower, upper; /* rad or m (continuous: -inf, +inf) */
	double velocity;     /* rad/s or m/s; 0 when not given */
	double effort;       /* N m or N; 0 when not given */
	long line;
};

struct px_urdf_opts {
	/* Folders holding ROS packages: package://NAME/REST is the first
	 * existing DIR/NAME/REST (up to PX_URDF_MAX_PACKAGE_PATHS). */
	const char *const *package_paths;
	int n_package_paths;
	/* 1: do not check that mesh files exist (a URDF read for its
	 * kinematics only). */
	int skip_mesh_check;
};

/* Where and why a URDF was refused: file, line (0 when none), the
 * element ("<joint name='elbow'>"), and a whole sentence in msg:
 * "FILE:LINE: ELEMENT: what is wrong". */
struct px_urdf_error {
	int code;
	char file[256];
	long line;
	char element[128];
	char msg[512];
};

struct px_urdf;

/* Read and check the URDF file path (opts may be NULL). Returns PX_OK,
 * PX_E_NOTFOUND (file or mesh missing), PX_E_IO, PX_E_RANGE (limits),
 * PX_E_PARSE (not XML, not a <robot>, a bad attribute), PX_E_INVAL (a
 * bad reference: unknown link, two parents, a cycle), PX_E_UNSUPPORTED
 * (built without libxml2), PX_E_NOMEM. err may be NULL. Setup only. */
PX_API int px_urdf_load(const char *path, const struct px_urdf_opts *opts,
			struct px_urdf **out, struct px_urdf_error *err);

/* The same from memory; name stands for the file in messages, and
 * relative mesh paths are taken from the current directory. */
PX_API int px_urdf_load_mem(const char *name, const char *xml, size_t len,
			    const struct px_urdf_opts *opts,
			    struct px_urdf **out, struct px_urdf_error *err);

PX_API void px_urdf_free(struct px_urdf *u);

/* The robot's name, its links and joints (NULL for a bad index), and
 * lookups by name (-1 when absent). @note RT-safe. */
PX_API const char *px_urdf_name(const struct px_urdf *u);
PX_API int px_urdf_link_count(const struct px_urdf *u);
PX_API const struct px_urdf_link *px_urdf_link(const struct px_urdf *u, int i);
PX_API int px_urdf_find_link(const struct px_urdf *u, const char *name);
PX_API int px_urdf_joint_count(const struct px_urdf *u);
PX_API const struct px_urdf_joint *px_urdf_joint(const struct px_urdf *u, int i);
PX_API int px_urdf_find_joint(const struct px_urdf *u, const char *name);
/* The root link (the one without a parent joint). */
PX_API int px_urdf_root(const struct px_urdf *u);

/* ---- the chain and its shapes --------------------------------------------- */

/* One collision shape on the chain: its model (own frame), the chain
 * frame it rides on (0 base, i after movable joint i) and its pose in
 * that frame, the link and the shape's index in the link. */
struct px_urdf_body {
	struct px_model *model;
	int frame;
	px_pose offset;
	int link, shape;
};

struct px_urdf_robot;

/*
 * The chain from base_link to tip_link (base_link NULL: the root; the
 * base must be an ancestor of the tip), its movable joints in order
 * (at most PX_CONTROL_MAX_JOINTS, else PX_E_NOSPC), and one model per
 * collision shape of every link rigidly attached to it. base is the
 * base link's pose in the world. Mesh shapes are loaded here (refusals
 * name the URDF line and the mesh file). err may be NULL. Setup only.
 */
PX_API int px_urdf_robot_create(const struct px_urdf *u, const char *base_link,
				const char *tip_link, px_pose base,
				struct px_urdf_robot **out,
				struct px_urdf_error *err);
PX_API void px_urdf_robot_free(struct px_urdf_robot *r);

/* The chain (joints in order; the capsule list is empty). */
PX_API const struct px_control_chain *px_urdf_robot_chain(const struct px_urdf_robot *r);
/* Number of movable joints, their URDF names and limits (lower, upper,
 * velocity as in struct px_urdf_joint). @note RT-safe. */
PX_API int px_urdf_robot_dof(const struct px_urdf_robot *r);
PX_API const char *px_urdf_robot_joint_name(const struct px_urdf_robot *r, int j);
PX_API int px_urdf_robot_limits(const struct px_urdf_robot *r, int j,
				double *lower, double *upper, double *velocity);
/* The shapes. @note RT-safe. */
PX_API int px_urdf_robot_body_count(const struct px_urdf_robot *r);
PX_API const struct px_urdf_body *px_urdf_robot_body(const struct px_urdf_robot *r, int i);
/* Name of body i's link ("" for a bad index). */
PX_API const char *px_urdf_robot_body_link(const struct px_urdf_robot *r, int i);

/*
 * Pose every shape model for joint positions q (dof values): the
 * chain's forward kinematics, then each body's pose is its frame times
 * its offset. frames (may be NULL, else cap >= dof + 1) receives the
 * chain frames. Returns PX_OK, PX_E_INVAL, PX_E_NAN, PX_E_NOSPC.
 * @note RT-safe.
 */
PX_API int px_urdf_robot_set_q(struct px_urdf_robot *r, const double *q,
			       px_pose *frames, size_t cap);

/* ---- clearances ------------------------------------------------------------ */

/*
 * Obstacles the robot's bodies are measured against (models the caller
 * keeps, posed by the caller; at most 1024). Sets up one model pair per
 * body and obstacle and keeps each pair's last answer for coherence;
 * for each obstacle that is a point cloud, also a cut cache per body
 * (px_pair_distance_cached(), about 15 kB each), which clouds swapped
 * into that slot later (px_urdf_robot_replace_obstacle) use as well.
 * Returns PX_OK, PX_E_INVAL, PX_E_RANGE (too many), PX_E_NOMEM. Setup.
 */
#define PX_URDF_MAX_OBSTACLES 1024
PX_API int px_urdf_robot_set_obstacles(struct px_urdf_robot *r,
				       struct px_model *const *obstacles, int n);

/* The clearance of one body to one obstacle (px_pair.h's answer). */
struct px_urdf_clearance {
	int body, obstacle;
	double distance_m;      /* -depth when they intersect */
	px_vec3 point_robot;    /* on the body, world */
	px_vec3 point_obstacle; /* on the obstacle, world */
	px_vec3 normal;         /* unit, from the obstacle towards the body */
	int intersecting;
	int local_only;         /* may be only a local minimum */
	/* self-clearance (px_urdf_robot_self_clearances): the other body,
	 * whose point is point_obstacle (obstacle is then -1); else -1 */
	int other_body;
};

/*
 * Every body against every obstacle at the poses last set
 * (px_urdf_robot_set_q() and the obstacles' own), as model pairs
 * (px_pair_distance(); o NULL: defaults). coherent != 0 starts each
 * pair from its answer of the last call. out (may be NULL, else cap >=
 * bodies x obstacles entries, body-major) receives every pair; *min
 * (may be NULL) the smallest. Returns the number of pairs, or
 * PX_E_INVAL, PX_E_NOSPC, a pair's error. @note RT-safe.
 */
PX_API int px_urdf_robot_clearances(struct px_urdf_robot *r,
				    const struct px_pair_opts *o, int coherent,
				    struct px_urdf_clearance *out, size_t cap,
				    struct px_urdf_clearance *min);

/*
 * Replace obstacle k by model m (same kind of use as set_obstacles:
 * the caller keeps m) between two calls of px_urdf_robot_clearances(),
 * e.g. a point cloud rebuilt outside the cycle and handed over
 * (px_cloud_feed.h). The pairs of every body with obstacle k forget
 * their last answer, so the next call measures them cold. Returns
 * PX_OK, PX_E_INVAL. @note RT-safe (no heap: bodies steps).
 */
PX_API int px_urdf_robot_replace_obstacle(struct px_urdf_robot *r, int k,
					  struct px_model *m);

/* ---- self-clearance ----------------------------------------------------- */

/*
 * Measure the robot's bodies against each other: every pair of bodies
 * on different chain frames except bodies on consecutive frames (links
 * joined by one movable joint: adjacent, they touch by design) and
 * except the link pairs in allowed (2 n_allowed names: allowed[2i] and
 * allowed[2i+1], MoveIt's allowed-collision matrix; both orders). Bodies
 * on the same frame (one link, or links joined by fixed joints) never
 * move against each other and are never measured. Replaces any previous
 * set. Returns the number of body pairs, or PX_E_INVAL, PX_E_NOTFOUND
 * (a name that is no link of the robot: err names it), PX_E_NOMEM.
 * err may be NULL. Setup.
 */
PX_API int px_urdf_robot_set_self(struct px_urdf_robot *r,
				  const char *const *allowed, int n_allowed,
				  struct px_urdf_error *err);

/*
 * The self pairs at the pose last set, as px_urdf_robot_clearances()
 * (body is the pair's second body, other_body the first, obstacle -1;
 * normal from the first toward the second). Returns the number of
 * pairs or an error. @note RT-safe.
 */
PX_API int px_urdf_robot_self_clearances(struct px_urdf_robot *r,
					 const struct px_pair_opts *o,
					 int coherent,
					 struct px_urdf_clearance *out, size_t cap,
					 struct px_urdf_clearance *min);

/* ---- avoidance ---------------------------------------------------------- */

struct px_urdf_avoid_out {
	/* the command (qdot, scale, min_clearance_m; caps unused,
	 * closest_capsule -1) */
	struct px_control_avoid_out cmd;
	/* the smallest clearance within the influence distance (body -1
	 * when none) */
	struct px_urdf_clearance closest;
	int pairs;          /* pairs measured this cycle */
	int local_only;     /* of them, answered without a global proof */
};

/*
 * One avoidance cycle on the robot's own link models: pose the bodies
 * at q (px_urdf_robot_set_q), measure every body against every obstacle
 * and, after px_urdf_robot_set_self(), the self pairs (o: pair options,
 * NULL defaults; coherent: start from last cycle's pairs), and turn
 * every clearance below p->influence_distance_m into a contact of
 * px_control_avoid_command(): speed scaling (p->approach_only: only for
 * the contacts the nominal motion closes), repulsion along J^T n with n
 * the pair's separating direction at its witness point, the velocity
 * limit and the discrete-time guard. On an error the command is zero
 * and the error is returned. @note RT-safe.
 */
PX_API int px_urdf_avoid_step(struct px_urdf_robot *r,
			      const struct px_control_avoid_params *p,
			      const struct px_pair_opts *o, int coherent,
			      const double *q, const double *qdot_nominal,
			      int64_t period_ns, struct px_urdf_avoid_out *out);

#ifdef __cplusplus
}
#endif

#endif
