/*
 * px_depth_sim.h - a simulated depth camera: a moving obstacle (a box
 * travelling in and out, or a swinging "arm") seen from a viewpoint as
 * noisy points, at a configured resolution and frame rate, feeding a
 * px_cloud_feed (px_cloud_feed.h) from its own thread. Every test and
 * demo of moving obstacles runs without hardware.
 *
 * The camera looks along its frame's +z (x right, y down), a pinhole of
 * width x height pixels over a horizontal field of view fov_x_rad (the
 * vertical one from the aspect). Each pixel's ray is cast against the
 * obstacle at the frame's time; a hit within max_range_m becomes a
 * world point, moved along the ray by Gaussian noise of noise_m
 * (seeded: the same frame index gives the same points). Only the
 * surface facing the camera is seen, as a real sensor sees it.
 *
 * The obstacle's motion is a function of time t (seconds from the first
 * frame): w(t) goes 0 -> 1 -> 0 smoothly over period_s, starting at
 * start_s (0 before; with period_s 0 it stays at 1 from start_s on).
 *  - PX_DEPTH_SIM_BOX: an axis-aligned box of half extents size_m,
 *    centred at from_m + w (to_m - from_m);
 *  - PX_DEPTH_SIM_ARM: a capsule of radius size_m.y from the pivot
 *    from_m, size_m.x long, in the horizontal plane at angle
 *    to_m.x + w (to_m.y - to_m.x) from the world x axis (to_m holds the
 *    two angles in rad).
 *
 * Frame k is stamped t0 + k / rate_hz (t0: the first clock the cycle
 * gives, px_depth_sim_clock()). The thread (px_depth_sim_start()) builds
 * frame k as soon as its stamp is within lookahead_ns of the cycle's
 * clock and the feed has a free slot: a simulated sensor may run ahead
 * of a virtual clock, as its frames depend on their stamps only.
 *
 * Memory and real-time rules: create, capture and the thread allocate
 * (not real time); px_depth_sim_clock() is RT-safe (one atomic store).
 */
#ifndef PX_DEPTH_SIM_H
#define PX_DEPTH_SIM_H

#include <stddef.h>
#include <stdint.h>

#include "px_base.h"
#include "px_math.h"

#ifdef __cplusplus
extern "C" {
#endif

struct px_cloud_feed;

enum px_depth_sim_kind {
	PX_DEPTH_SIM_BOX = 0,
	PX_DEPTH_SIM_ARM = 1
};

#define PX_DEPTH_SIM_MAX_PIXELS 1024

struct px_depth_sim_params {
	int kind;               /* enum px_depth_sim_kind */
	px_pose camera;         /* camera frame in the world */
	int width, height;      /* 1 .. PX_DEPTH_SIM_MAX_PIXELS each */
	double fov_x_rad;       /* 0 .. 3 */
	double max_range_m;     /* > 0 */
	double noise_m;         /* >= 0, standard deviation along the ray */
	double rate_hz;         /* 0.1 .. 1000 */
	px_vec3 size_m;         /* box: half extents; arm: x length, y radius */
	px_vec3 from_m, to_m;   /* see the header comment */
	double start_s, period_s;
	uint64_t seed;
};

struct px_depth_sim;

/* Defaults: a box of 0.1 m half extents, 64 x 48 pixels over 1.0 rad,
 * 4 m range, 2 mm noise, 30 Hz, camera at the origin looking along +z,
 * still (from = to = (0, 0, 2)), seed 1. */
PX_API void px_depth_sim_params_default(struct px_depth_sim_params *p);

/* Returns PX_OK, PX_E_INVAL (NULL, unknown kind), PX_E_RANGE,
 * PX_E_NAN, PX_E_NOMEM. Setup. */
PX_API int px_depth_sim_create(const struct px_depth_sim_params *p,
			       struct px_depth_sim **out);
/* Stops the thread first. */
PX_API void px_depth_sim_free(struct px_depth_sim *s);

/* Most points one frame has (width x height). */
PX_API size_t px_depth_sim_max_points(const struct px_depth_sim *s);

/* The motion parameter w(t) in [0, 1] (see above). */
PX_API double px_depth_sim_motion(const struct px_depth_sim *s, double t_s);

/*
 * The points seen at time t_s (seconds from the first frame), frame
 * index k for the noise: at most cap points into xyz (3 doubles each),
 * their count in *n. Returns PX_OK, PX_E_INVAL, PX_E_NOSPC (cap below
 * px_depth_sim_max_points()). Not RT-safe (called by the thread or a
 * test).
 */
PX_API int px_depth_sim_capture(const struct px_depth_sim *s, double t_s,
				uint64_t k, double *xyz, size_t cap, size_t *n);

/* ---- the sensor's thread ---------------------------------------------------- */

/* Start feeding f (which must take width x height points) from a
 * thread; frames are built lookahead_ns ahead of the clock at most.
 * Returns PX_OK, PX_E_INVAL, PX_E_STATE (running), PX_E_NOMEM, or an
 * error of pthread_create as PX_E_IO. */
PX_API int px_depth_sim_start(struct px_depth_sim *s, struct px_cloud_feed *f,
			      int64_t lookahead_ns);
/* Stop and join the thread (no-op when not running). */
PX_API void px_depth_sim_stop(struct px_depth_sim *s);
/* The cycle's clock (its first call sets t0). @note RT-safe. */
PX_API void px_depth_sim_clock(struct px_depth_sim *s, int64_t now_ns);
/* The stamp of frame k (t0 + k / rate_hz); 0 before the first clock. */
PX_API int64_t px_depth_sim_stamp(const struct px_depth_sim *s, uint64_t k);
/* Frames the thread built, and the errors it met (0 when none: the
 * last one otherwise). */
PX_API uint64_t px_depth_sim_frames(const struct px_depth_sim *s);
PX_API int px_depth_sim_error(const struct px_depth_sim *s);

#ifdef __cplusplus
}
#endif

#endif
