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

#endif
