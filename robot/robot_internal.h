/*
 * robot_internal.h - what the URDF reader (urdf_xml.c), the checks and
 * accessors (urdf_tree.c) and the robot (urdf_robot.c) share.
 */
#ifndef ROBOT_INTERNAL_H
#define ROBOT_INTERNAL_H

#include "px_urdf.h"

struct px_urdf {
	char *name;
	char *file;   /* for messages */
	char *dir;    /* the file's folder, for relative mesh paths ("" none) */
	int n_links, n_joints, n_shapes;
	struct px_urdf_link *links;
	struct px_urdf_joint *joints;
	struct px_urdf_shape *shapes;
	/* unresolved mesh file names and their lines (resolved by
	 * px__urdf_finish into shapes[].mesh) */
	char **mesh_names;
	int root;
};

/* Fill err ("FILE:LINE: ELEMENT: ..."), return code. */
int px__urdf_fail(struct px_urdf_error *err, int code, const char *file,
		  long line, const char *element, const char *fmt, ...)
	__attribute__((format(printf, 6, 7)));

/* Check references, find the root, resolve mesh paths; u is complete
 * otherwise. Returns PX_OK or the error it filled. */
int px__urdf_finish(struct px_urdf *u, const struct px_urdf_opts *o,
		    struct px_urdf_error *err);

/* An empty description for file (copied) with its folder. */
struct px_urdf *px__urdf_new(const char *file, int with_dir);

char *px__urdf_strdup(const char *s);

#define URDF_NAME_LEN 64

struct px_urdf_robot {
	struct px_control_chain chain;
	int dof;
	char names[PX_CONTROL_MAX_JOINTS][URDF_NAME_LEN];
	double lower[PX_CONTROL_MAX_JOINTS], upper[PX_CONTROL_MAX_JOINTS];
	double velocity[PX_CONTROL_MAX_JOINTS];
	int n_bodies;
	struct px_urdf_body *bodies;
	char (*body_link)[URDF_NAME_LEN];
	px_pose frames[PX_CONTROL_MAX_JOINTS + 1];
	/* clearances: obstacles and the last answer of each pair */
	int n_obstacles;
	struct px_model **obstacles;
	struct px_pair_result *pairs;
	/* per pair: the cut cache of a link against a cloud obstacle (NULL
	 * for obstacles that were not clouds when set) */
	struct px_pair_cache **caches;
	/* self-clearance: body pairs measured and their last answers */
	int n_self;
	int (*self)[2];
	struct px_pair_result *self_pairs;
	/* avoidance: clearances and contacts of one cycle (sized by
	 * px__urdf_avoid_size at setup) */
	int cap_contacts;
	struct px_urdf_clearance *cl;
	struct px_control_contact *contacts;
	int *contact_of;
};

/* A pair's answer as a clearance (point_b on the body). */
struct px_urdf_clearance px__urdf_clearance(const struct px_pair_result *p, int body,
					    int obstacle, int other_body);

/* One pair (a's answer, b the body; cache: its cut cache, may be NULL):
 * measured into c (returns 1) unless the models' world boxes are reach
 * or more apart (returns 0: c holds the boxes' gap, a lower bound), or
 * an error. */
int px__urdf_pair(const struct px_model *a, const struct px_model *b,
		  const struct px_pair_opts *po, int coherent, double reach,
		  struct px_pair_result *p, struct px_pair_cache *cache, int body, int obstacle,
		  int other_body, struct px_urdf_clearance *c);
void px__urdf_pair_opts(const struct px_pair_opts *o, int coherent,
			struct px_pair_opts *po);
void px__urdf_min_init(struct px_urdf_clearance *min);
/* px_urdf_robot_clearances() with a reach (INFINITY: every pair
 * measured); *measured (may be NULL) counts the pairs measured. */
int px__urdf_obstacle_pairs(struct px_urdf_robot *r, const struct px_pair_opts *o,
			    int coherent, double reach, struct px_urdf_clearance *out,
			    size_t cap, struct px_urdf_clearance *min, int *measured);

/* Size the avoidance buffers for the obstacles and self pairs set
 * (urdf_avoid.c); free them. */
int px__urdf_avoid_size(struct px_urdf_robot *r);
void px__urdf_avoid_free(struct px_urdf_robot *r);

#endif
