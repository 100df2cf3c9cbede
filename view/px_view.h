/*
 * px_view.h - the browser view of a run: a small HTTP and WebSocket
 * server (libwebsockets) on its own non-real-time thread that serves the
 * page's static files and streams the scene and the telemetry to it as
 * JSON messages (docs/view.md has the protocol).
 *
 * What: px_view_create() binds ADDR:PORT (127.0.0.1 unless given) and
 * serves GET / (index.html), /app.js, /app.css, ... from web_root; GET
 * /ws upgrades to a WebSocket of subprotocol "proxima-view.v1". Each
 * connection gets "hello", then "scene" (px_view_set_scene()), then in
 * replay "track" (px_view_set_track()), then "frame" messages as they
 * are fed, and "end" after px_view_end(). Read-only: what a page sends is
 * never acted on. A malformed request gets an error status and the
 * server goes on serving.
 *
 * Slow clients: each connection has a queue of at most queue_frames
 * frames; when it cannot keep up the oldest queued frames are dropped
 * (newest frame wins, counted), and a connection that has taken nothing
 * for stall_ms while frames wait is closed (counted). Feeding never waits
 * for a client: px_view_feed_*() format into the view's own buffer, copy
 * it into a fixed ring under a short lock the server thread holds only to
 * copy one frame out, and wake the server thread.
 *
 * Threads: create, set_*, start, stop and free from one control thread;
 * feed and end from one feeding thread (proxima-run's draining thread),
 * never from the loop's cycle. Memory: create allocates the ring; the
 * feed allocates nothing but a swapped cloud's message; the server
 * thread allocates per connection.
 *
 * Builds without libwebsockets (PX_HAVE_VIEW 0) keep the JSON side;
 * px_view_create() returns PX_E_UNSUPPORTED saying so.
 */
#ifndef PX_VIEW_H
#define PX_VIEW_H

#include <stddef.h>
#include <stdint.h>

#include "px_app.h"
#include "px_base.h"
#include "px_cloud_feed.h"
#include "px_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

struct px_view;

/* The WebSocket subprotocol and the largest frame message. */
#define PX_VIEW_PROTOCOL "proxima-view.v1"
#define PX_VIEW_FRAME_MAX 16384
/* At most this many arm links and moved models in one frame, and
 * points in one cloud message (a larger cloud is decimated). */
#define PX_VIEW_MAX_LINKS 48
#define PX_VIEW_MAX_MOVED 16
#define PX_VIEW_CLOUD_MAX 20000

struct px_view_options {
	const char *addr;      /* numeric IPv4/IPv6 address; NULL: 127.0.0.1 */
	int port;              /* 1..65535 */
	const char *web_root;  /* folder of index.html, app.js, app.css */
	const char *mode;      /* "live" (default) or "replay" */
	const char *name;      /* the config's name, for the page */
	int64_t period_ns;     /* the loop's period, for the page */
	double rate_hz;        /* frames per second fed at most (default 30) */
	int max_clients;       /* connections at once (default 8) */
	int queue_frames;      /* per connection (default 16) */
	int stall_ms;          /* close a connection stuck this long (5000) */
};

/* Counters of the server (px_view_stats()). */
struct px_view_stats {
	int clients;              /* connected WebSockets now */
	uint64_t connections;     /* WebSockets accepted */
	uint64_t frames_fed;      /* frames taken by the feed (after decimation) */
	uint64_t frames_sent;     /* frame messages written, all connections */
	uint64_t frames_dropped;  /* skipped for a connection behind */
	uint64_t clients_closed;  /* closed for falling behind */
	uint64_t refused;         /* WebSockets refused (path, too many) */
};

PX_API void px_view_options_default(struct px_view_options *o);

/*
 * Bind and make the server (not yet serving). Returns PX_OK, PX_E_INVAL
 * (options), PX_E_NOTFOUND (no index.html in web_root), PX_E_IO (cannot
 * listen: the port taken, the address not local), PX_E_NOMEM or
 * PX_E_UNSUPPORTED (built without libwebsockets); msg says why.
 */
PX_API int px_view_create(const struct px_view_options *o,
			  struct px_view **out, char *msg, size_t cap);

/* The bound port (the options' one). */
PX_API int px_view_port(const struct px_view *v);

/* The scene message (px_view_scene_json()) and, in replay, the track
 * message, copied; before px_view_start(). PX_OK, PX_E_INVAL, PX_E_NOMEM. */
PX_API int px_view_set_scene(struct px_view *v, const char *json, size_t len);
PX_API int px_view_set_track(struct px_view *v, const char *json, size_t len);

struct px_view_arm;

/* Where the feed finds what a frame shows beside its record; each may
 * be NULL. Read on the feeding thread only: */
struct px_view_sources {
	/* the closest point of a haptic run (the scene's point nearest the
	 * tool) and the models whose pose changed since set (frame.models):
	 * nothing may move the scene's models while the feed reads them */
	const struct px_scene *scene;
	/* the arm: frame.links from the record's joint positions and
	 * frame.clearances from its closest pair (px_view_arm_create()) */
	const struct px_view_arm *arm;
	/* a point cloud obstacle: when the consumer has taken a newer
	 * frame, it is pinned, copied (decimated to PX_VIEW_CLOUD_MAX) and
	 * sent as a "cloud" message of model cloud_id */
	struct px_cloud_feed *cloud_feed;
	int cloud_id;
};

/* The sources (kept by the caller until px_view_free()), before
 * px_view_start(). PX_OK, PX_E_INVAL, PX_E_STATE, PX_E_NOMEM. */
PX_API int px_view_set_sources(struct px_view *v,
			       const struct px_view_sources *src);

/* The server thread. PX_OK, PX_E_STATE (started), PX_E_NOMEM. */
PX_API int px_view_start(struct px_view *v);

/* One telemetry record: fed when rate_hz allows (by r->t_s), dropped
 * otherwise, with what the sources add to it. Returns 1 fed, 0
 * decimated away. No allocation but a cloud message's (a newer cloud). */
PX_API int px_view_feed_record(struct px_view *v,
			       const struct px_app_record *r);

/* A frame message already formatted (at most PX_VIEW_FRAME_MAX bytes),
 * no decimation. PX_OK or PX_E_INVAL. No allocation. */
PX_API int px_view_feed_json(struct px_view *v, const char *json, size_t len);

/* The run ended: every connection gets "end" after its frames. */
PX_API void px_view_end(struct px_view *v);

PX_API void px_view_stats(struct px_view *v, struct px_view_stats *s);

/* Stop the thread (connections get "end" first, waited for at most
 * wait_ms) and close every connection. Idempotent. */
PX_API void px_view_stop(struct px_view *v, int wait_ms);

/* Stop and free. NULL is a no-op. */
PX_API void px_view_free(struct px_view *v);

/* ---- the JSON of the messages (no server needed) ------------------------ */

/* What the scene message shows beside the models. */
struct px_view_scene_info {
	double tool_radius_m;           /* 0: none */
	double protective_distance_m;   /* unused: scene.robot has the arm's */
	double influence_distance_m;
	const struct px_view_arm *arm;  /* scene.robot; NULL: null */
	/* a point cloud obstacle outside the scene (a depth sensor): one
	 * more model of kind cloud, id px_scene_count(), no points until a
	 * "cloud" message; NULL: none */
	const char *cloud_name;
};

/*
 * The arm of an avoidance run drawn: every link model of arm->robot
 * (or every capsule of arm->chain without one) tessellated once, and
 * the chain copied, for scene.robot and the links' poses from a
 * record's joint positions. Setup only (allocates). PX_OK, PX_E_INVAL,
 * PX_E_RANGE (more than PX_VIEW_MAX_LINKS links), PX_E_NOMEM.
 */
PX_API int px_view_arm_create(const struct px_app_arm *arm,
			      struct px_view_arm **out);
PX_API void px_view_arm_free(struct px_view_arm *a);
PX_API int px_view_arm_link_count(const struct px_view_arm *a);

/* The links' poses (world, [x,y,z,qw,qx,qy,qz], order of scene.robot)
 * at the joint positions r->q: the chain's forward kinematics. Returns
 * the number of links (0 when the record carries fewer joints than the
 * chain has, or they are not finite), PX_E_INVAL, PX_E_NOSPC (cap).
 * No allocation. */
PX_API int px_view_arm_links(const struct px_view_arm *a,
			     const struct px_app_record *r, double (*poses)[7],
			     int cap);

/* What a frame shows beside its record (px_view_frame_fill()). */
struct px_view_frame_extra {
	int has_closest;
	double closest_m[3];
	int n_links;
	double links[PX_VIEW_MAX_LINKS][7];
	int n_clearances;                 /* [ax,ay,az,bx,by,bz,d_m] */
	double clearances[1][7];
	int n_models;                     /* [id,x,y,z,qw,qx,qy,qz] */
	double models[PX_VIEW_MAX_MOVED][8];
};

/* x from record r and src (scene and arm; the cloud and moved models
 * are the server's): the closest point of a haptic run, the links and
 * the closest pair of an arm. No allocation. */
PX_API void px_view_frame_fill(const struct px_view_sources *src,
			       const struct px_app_record *r,
			       struct px_view_frame_extra *x);

/*
 * The scene message of s (may be NULL: no models): every model
 * tessellated (px_tess.h), pose and world bounds. *json is malloc'd
 * (free()), *len its length. Setup only. PX_OK, PX_E_NOMEM.
 */
PX_API int px_view_scene_json(const struct px_scene *s,
			      const struct px_view_scene_info *info,
			      char **json, size_t *len);

/* The frame object of r into buf: with_type 0 leaves "type" out (for a
 * track). Returns the length, or PX_E_NOSPC. No allocation. */
PX_API int px_view_frame_json(const struct px_app_record *r, int with_type,
			      char *buf, size_t cap);
/* The same with x's fields (x NULL: none). */
PX_API int px_view_frame_json_extra(const struct px_app_record *r,
				    const struct px_view_frame_extra *x,
				    int with_type, char *buf, size_t cap);

/* The "cloud" message of n points (xyz, 3 per point; every
 * ceil(n / PX_VIEW_CLOUD_MAX)-th kept) of model id at t_s: *json
 * malloc'd. PX_OK, PX_E_INVAL, PX_E_NOMEM. */
PX_API int px_view_cloud_json(int id, double t_s, const float *xyz, size_t n,
			      char **json, size_t *len);

#ifdef __cplusplus
}
#endif

#endif
