/*
 * _pxpy.h - the C side of the Python package: whole-array loops over the
 * library's queries and the model constructors, with plain types only
 * (doubles, ints, opaque handles), so that the cffi declarations in
 * _build.py stay small and the compiler checks them against this file.
 *
 * Every function writes a sentence into msg (capacity msg_cap) when it
 * fails, naming the file and place where the library gave one, and
 * returns the library's negative error code; loops over points stop at
 * the first point the library refuses and say which (*bad).
 *
 * Threads: the package calls these with the GIL released (cffi's
 * default); a model may be queried from several Python threads, a
 * stream or tracking only from one at a time (the package locks it).
 */
#ifndef PXPY_H
#define PXPY_H

#include <stddef.h>
#include <stdint.h>

struct px_model;
struct px_model_stream;
struct px_scene;
struct px_scene_tracking;

/* ---- models ------------------------------------------------------------ */

int pxpy_load(const char *path, double cloud_radius_m, double scale,
	      struct px_model **out, char *msg, size_t msg_cap);
int pxpy_mesh(const double *xyz, size_t n_vertices, const int64_t *tri,
	      size_t n_triangles, struct px_model **out, char *msg,
	      size_t msg_cap);
int pxpy_cloud(const double *xyz, size_t n, double radius_m,
	       struct px_model **out, char *msg, size_t msg_cap);
int pxpy_prim(int type, double a, double b, double c, struct px_model **out,
	      char *msg, size_t msg_cap);
/* curves: n_curves of degree deg[i], n_ctrl[i] points; knots and
 * homogeneous-free points (x, y, z) and weights laid end to end.
 * surfs: the same with two degrees and counts, points u fastest. */
int pxpy_nurbs(int n_curves, const int *c_deg, const int *c_n,
	       const double *c_knots, const double *c_xyz, const double *c_w,
	       int n_surfs, const int *s_deg, const int *s_n,
	       const double *s_knots, const double *s_xyz, const double *s_w,
	       struct px_model **out, char *msg, size_t msg_cap);
void pxpy_model_free(struct px_model *m);

/* Model facts: kind, capabilities, name, box (6), memory. */
int pxpy_model_kind(const struct px_model *m);
unsigned pxpy_model_caps(const struct px_model *m);
const char *pxpy_model_name(const struct px_model *m);
void pxpy_model_box(const struct px_model *m, int world, double *box6);
size_t pxpy_model_bytes(const struct px_model *m);

/* Pose: unit quaternion (w, x, y, z) and translation. */
int pxpy_set_pose(struct px_model *m, const double *q4, const double *t3,
		  char *msg, size_t msg_cap);
void pxpy_get_pose(const struct px_model *m, double *q4, double *t3);

/* ---- answers ------------------------------------------------------------ */

/* Per point i of a query: the model's answer spread over arrays (each
 * may be NULL when not wanted). */
struct pxpy_out {
	double *distance;  /* n */
	double *point;     /* 3n */
	double *direction; /* 3n */
	double *u, *v;     /* n */
	double *gap;       /* n */
	int32_t *index;    /* n */
	int32_t *sub;      /* n */
	int32_t *feature;  /* n */
	int8_t *inside;    /* n */
	int8_t *certified; /* n */
	int8_t *found;     /* n: 0 when nothing within max_dist */
	int8_t *jumped;    /* n (streams, tracked scene) */
	int32_t *model;    /* n (scenes) */
};

/* n points (3n doubles); flags: bit 0 unsigned. */
int pxpy_query(const struct px_model *m, const double *p, size_t n,
	       double max_dist, unsigned flags, const struct pxpy_out *o,
	       size_t *bad, char *msg, size_t msg_cap);

/* ---- streams ------------------------------------------------------------ */

int pxpy_stream_create(const struct px_model *m, int verify_every,
		       int max_solves, int cold_switch,
		       struct px_model_stream **out, char *msg,
		       size_t msg_cap);
void pxpy_stream_free(struct px_model_stream *s);
int pxpy_stream_query(struct px_model_stream *s, const double *p, size_t n,
		      double max_dist, unsigned flags,
		      const struct pxpy_out *o, size_t *bad, char *msg,
		      size_t msg_cap);
/* queries, tracked, hot, global, cold, jumps, reinits, verifications,
 * disagreements */
void pxpy_stream_stats(const struct px_model_stream *s, uint64_t *st9);

/* ---- pairs --------------------------------------------------------------- */

/* out10: distance, point_a (3), point_b (3), depth, witness_gap, and
 * normal in out_n (3); ints: index_a, index_b, intersecting,
 * local_only, converged, iterations. */
int pxpy_pair(const struct px_model *a, const struct px_model *b, int starts,
	      int max_iters, double *out9, double *normal3, int *ints6,
	      char *msg, size_t msg_cap);

/* ---- scenes -------------------------------------------------------------- */

int pxpy_scene_create(size_t capacity, struct px_scene **out, char *msg,
		      size_t msg_cap);
void pxpy_scene_free(struct px_scene *s);
int pxpy_scene_add(struct px_scene *s, struct px_model *m, char *msg,
		   size_t msg_cap);
int pxpy_scene_update(struct px_scene *s);
int pxpy_scene_nearest(const struct px_scene *s, const double *p, size_t n,
		       double max_dist, const struct pxpy_out *o, size_t *bad,
		       char *msg, size_t msg_cap);
int pxpy_scene_tracking_create(const struct px_scene *s,
			       struct px_scene_tracking **out, char *msg,
			       size_t msg_cap);
void pxpy_scene_tracking_free(struct px_scene_tracking *t);
int pxpy_scene_nearest_tracked(const struct px_scene *s,
			       struct px_scene_tracking *t, const double *p,
			       size_t n, double max_dist,
			       const struct pxpy_out *o, size_t *bad,
			       char *msg, size_t msg_cap);

/* ---- robots (px_urdf.h) ---------------------------------------------------- */

struct px_urdf_robot;
/* The chain base..tip of a URDF file (base NULL: the root); package
 * paths separated by ':' (may be NULL). */
int pxpy_robot_load(const char *path, const char *base, const char *tip,
		    const char *package_paths, struct px_urdf_robot **out,
		    char *msg, size_t msg_cap);
void pxpy_robot_free(struct px_urdf_robot *r);
int pxpy_robot_dof(const struct px_urdf_robot *r);
const char *pxpy_robot_joint_name(const struct px_urdf_robot *r, int j);
/* lower, upper, velocity */
int pxpy_robot_limits(const struct px_urdf_robot *r, int j, double *out3);
int pxpy_robot_body_count(const struct px_urdf_robot *r);
/* Body i: its model (owned by the robot), link name, frame. */
struct px_model *pxpy_robot_body(const struct px_urdf_robot *r, int i,
				 const char **link, int *frame);
/* q: dof values; frames (7 doubles each: w x y z, x y z) may be NULL. */
int pxpy_robot_set_q(struct px_urdf_robot *r, const double *q, double *frames,
		     char *msg, size_t msg_cap);

/* ---- misc ---------------------------------------------------------------- */

const char *pxpy_strerror(int code);
const char *pxpy_version(void);

#endif
