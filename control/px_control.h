/*
 * px_control.h - force rendering for haptic devices and collision
 * avoidance for serial robot arms, computed from distances to the scene.
 *
 * The module sits between geometry and devices: a cycle reads a device
 * pose (or joint positions), asks the scene for distances through the
 * small query interface below, and produces a force (haptics) or a joint
 * velocity command (avoidance) that goes back to the device.
 *
 *  - Query interface (struct px_control_query): a point callback (signed
 *    distance, closest point, unit direction, valid flag) and an optional
 *    segment callback. The control code knows nothing else about the
 *    scene, so the same renderer runs against analytic test shapes, the
 *    distance core or any user geometry.
 *  - Haptic rendering (struct px_control_haptic): a penalty
 *    spring-damper along the signed-distance direction, or a god-object
 *    (proxy) constrained to the free side of closed solids and thin
 *    shells, with static/dynamic Coulomb friction and a virtual coupling
 *    spring-damper to the device; every force goes through a magnitude
 *    clamp and a force-rate limit. Setup checks the sampled-wall
 *    passivity condition and raises a stability warning.
 *  - Collision avoidance (struct px_control_chain): serial chain from DH
 *    parameters or URDF-like joint origins and axes, forward kinematics of
 *    every link frame, capsule link geometry, link-to-scene clearances,
 *    and a joint velocity command: speed-and-separation-monitoring style
 *    scaling of the nominal velocity plus a repulsive velocity along
 *    J^T n.
 *  - Configuration: px_control_config_read() reads the `control` section
 *    of a proxima config (keys in docs/config.md).
 *
 * Memory and real-time rules: every object is a plain struct with fixed
 * capacity (PX_CONTROL_MAX_JOINTS, PX_CONTROL_MAX_CAPSULES) owned by the
 * caller; nothing here allocates, except px_control_config_read() (setup
 * time, memory owned by the config document). Functions marked
 * "@note RT-safe" do no allocation, locking, I/O or unbounded loops:
 * every iteration count is bounded by a parameter given at setup. They
 * call the query callbacks, which must be RT-safe themselves. One object
 * is used by one thread at a time.
 */
#ifndef PX_CONTROL_H
#define PX_CONTROL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "px_base.h"
#include "px_math.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------------------ */
/* Scene query interface                                               */
/* ------------------------------------------------------------------ */

/*
 * Answer of a point query. For points outside a closed solid distance_m
 * > 0, inside < 0; normal is the unit gradient of the signed distance
 * (outside: from point_m toward the query point; inside: the outward
 * surface normal). Thin shells and open surfaces have no inside: they
 * set two_sided and report the unsigned distance, with normal from
 * point_m toward the query point - so the normal flips when a point
 * passes through the shell, and only continuity can tell the sides.
 */
struct px_control_hit {
	bool valid;         /* false: nothing within max_distance_m */
	bool two_sided;     /* closest feature is a shell: distance >= 0 */
	double distance_m;  /* signed distance to the closest surface point */
	px_vec3 point_m;    /* closest surface point, world frame */
	px_vec3 normal;     /* unit, see above */
};

/* Answer of a segment query: the hit of the closest point of the
 * segment, its segment parameter, and a certified lower bound of the
 * segment's distance (equal to hit.distance_m for exact answers). */
struct px_control_seg_hit {
	struct px_control_hit hit;
	double t;             /* closest point = a + t (b - a), t in [0, 1] */
	double lower_bound_m; /* distance of every segment point >= this */
};

/*
 * The scene as the control code sees it. point() is required; segment()
 * may be NULL (a bounded search with point() is used instead, see
 * px_control_query_segment()). Callbacks return PX_OK or a negative
 * px_err; max_distance_m is a hint: the callback may answer valid =
 * false when nothing lies within it. A valid |distance_m| must never
 * exceed the true distance (an answer known only within a gap reports
 * distance - gap): the proxy's no-crossing guarantee and the certified
 * clearances rest on it. Both must be RT-safe when used from a cycle.
 *
 * Backing it with a scene model (geom/model/px_model.h, px_model_query_ex):
 * valid = (return 1), distance_m = distance (minus gap when not
 * certified), point_m = point, normal = direction, two_sided =
 * !is_signed.
 */
struct px_control_query {
	int (*point)(void *ctx, px_vec3 p_m, double max_distance_m,
		     struct px_control_hit *out);
	int (*segment)(void *ctx, px_vec3 a_m, px_vec3 b_m,
		       double max_distance_m, struct px_control_seg_hit *out);
	void *ctx;
};

/*
 * Distance from the segment a..b to the scene. With q->segment that
 * callback answers. Otherwise a best-first bisection with at most
 * max_point_queries (>= 2) point queries: each interval [ta, tb] of
 * length L with end distances da, db holds no point closer than
 * (da + db - L) / 2 (distance is 1-Lipschitz), the interval with the
 * smallest such bound is split until the bound and the best sample agree
 * within tol_m or the budget is spent. out->hit is the best sample (an
 * upper bound of the true distance), out->lower_bound_m the certified
 * bound over all intervals. Points farther than max_distance_m count as
 * max_distance_m. Returns PX_OK, PX_E_INVAL, or a callback's error.
 * @note RT-safe (stack use grows with max_point_queries, capped at 64).
 */
PX_API int px_control_query_segment(const struct px_control_query *q,
				    px_vec3 a_m, px_vec3 b_m,
				    double max_distance_m,
				    int max_point_queries, double tol_m,
				    struct px_control_seg_hit *out);

/* ------------------------------------------------------------------ */
/* Force limits and passivity                                          */
/* ------------------------------------------------------------------ */

/*
 * Largest stiffness for which a sampled virtual wall stays passive
 * (Colgate and Schenkelberg, 1997: b > K T / 2 + |B|, with b the
 * device's physical damping, K and B the virtual stiffness and damping,
 * T the sample period): returns 2 (b - |B|) / T in N/m, which is <= 0
 * when the virtual damping alone already exceeds the device damping.
 * @note RT-safe.
 */
PX_API double px_control_passive_stiffness_limit(double device_damping_n_s_per_m,
						 double virtual_damping_n_s_per_m,
						 int64_t period_ns);

/*
 * Limit a force: first clamp |target| to max_force_n, then move from
 * prev_n toward it by at most max_step_n (the rate limit times the
 * period). prev_n inside the clamp keeps the result inside. flags (may
 * be NULL) gets bit 1 when clamped, bit 2 when rate limited. Non-finite
 * targets give prev_n.
 * @note RT-safe.
 */
PX_API px_vec3 px_control_force_limit(px_vec3 target_n, px_vec3 prev_n,
				      double max_force_n, double max_step_n,
				      unsigned *flags);

#define PX_CONTROL_FORCE_CLAMPED 1u
#define PX_CONTROL_FORCE_RATE_LIMITED 2u

/* ------------------------------------------------------------------ */
/* Haptic rendering                                                    */
/* ------------------------------------------------------------------ */

enum px_control_renderer {
	PX_CONTROL_PENALTY = 0, /* spring-damper on the device point */
	PX_CONTROL_PROXY = 1    /* god-object + virtual coupling */
};

struct px_control_haptic_params {
	int renderer;                  /* enum px_control_renderer */
	/* Penalty: wall spring and normal damper. Proxy: the virtual
	 * coupling spring and damper between device and proxy. */
	double stiffness_n_per_m;
	double damping_n_s_per_m;
	double proxy_radius_m;         /* proxy keeps about this clearance */
	double static_friction;        /* mu_s >= mu_d >= 0, proxy only */
	double dynamic_friction;
	double max_force_n;            /* > 0 */
	double max_force_rate_n_per_s; /* > 0 */
	/* Physical damping of the device; used only by the stability check. */
	double device_damping_n_s_per_m;
	int max_point_queries;         /* per cycle (proxy), 8..1024 */
	double max_query_distance_m;   /* hint passed to the query, > 0 */
};

/* Proxy contact plane: stay proxy_radius_m above the tangent plane at
 * point_m with normal n. */
struct px_control_plane {
	px_vec3 n;
	px_vec3 point_m;
};

/* Renderer state: plain data in caller memory. Fields ending in '_' are
 * private. */
struct px_control_haptic {
	struct px_control_haptic_params p;
	double period_s;
	/* Passivity at setup: stable is false when stiffness_n_per_m >=
	 * stiffness_limit_n_per_m (see px_control_passive_stiffness_limit). */
	bool stable;
	double stiffness_limit_n_per_m;
	bool started_;
	bool sticking_;
	bool crossed_;       /* penalty, shells: device behind side_n_ */
	px_vec3 side_n_;
	px_vec3 proxy_m_;
	px_vec3 prev_proxy_m_;
	px_vec3 prev_device_m_;
	px_vec3 force_n_;    /* last output */
	int n_planes_;
	struct px_control_plane planes_[3];
};

/* Result of one cycle. */
struct px_control_haptic_out {
	px_vec3 force_n;      /* on the device, after clamp and rate limit */
	px_vec3 proxy_m;      /* proxy (penalty: the device point) */
	/* Penalty: signed distance of the device point (shells: negative
	 * when behind the tracked side). Proxy: -penetration_m in contact,
	 * else the proxy's clearance (the proxy is then at the device). */
	double distance_m;
	double penetration_m; /* >= 0: how far the device is inside */
	bool contact;         /* the force comes from a surface */
	bool sticking;        /* proxy held by static friction */
	unsigned limit_flags; /* PX_CONTROL_FORCE_* */
	int point_queries;    /* query calls made this cycle */
	int n_planes;         /* active proxy constraints (0..3) */
};

/* Defaults: proxy, 800 N/m, 1 N s/m, 0.5 mm, no friction, 10 N,
 * 2000 N/s, device damping 2 N s/m, 64 queries, 0.05 m. */
PX_API void px_control_haptic_params_default(struct px_control_haptic_params *p);

/*
 * Check params and set up h (any previous content is overwritten).
 * Computes h->stable and h->stiffness_limit_n_per_m. Returns PX_OK,
 * PX_E_INVAL (NULL, unknown renderer, period <= 0) or PX_E_RANGE (a
 * parameter outside its range, e.g. mu_d > mu_s); an unstable setting is
 * not an error - read h->stable or px_control_haptic_warning().
 */
PX_API int px_control_haptic_init(struct px_control_haptic *h,
				  const struct px_control_haptic_params *p,
				  int64_t period_ns);

/*
 * Stability warning text for the setup ("stiffness 5000 N/m exceeds the
 * passive limit ..."), with the formula and the numbers. Returns the
 * length written (0 and buf "" when the setting is passive).
 */
PX_API int px_control_haptic_warning(const struct px_control_haptic *h,
				     char *buf, size_t cap);

/*
 * Place the proxy at the device point (or, when that point is inside a
 * closed solid, on the surface above it, proxy_radius_m out) and zero
 * the force history. Called by the first step when not called before.
 * Returns PX_OK, PX_E_INVAL or a query error.
 * @note RT-safe.
 */
PX_API int px_control_haptic_reset(struct px_control_haptic *h,
				   const struct px_control_query *q,
				   px_vec3 device_m);

/*
 * One rendering cycle for the device point device_m. device_velocity
 * (may be NULL: backward difference of positions) feeds the dampers.
 * The proxy moves toward the device only through certified free space:
 * each step along its path is shorter than the distance to the scene
 * at its start, so it never crosses a surface, however fast the device
 * moves; at most p.max_point_queries queries are made (when they run
 * out the proxy stops where it is). A proxy found inside a closed
 * solid (the scene moved onto it) is first put back on the nearest
 * surface, proxy_radius_m out. On a query error the force ramps toward
 * zero at the rate limit and the error is returned.
 * Returns PX_OK, PX_E_INVAL, PX_E_NAN (non-finite input) or the query's
 * error; out is always filled.
 * @note RT-safe.
 */
PX_API int px_control_haptic_step(struct px_control_haptic *h,
				  const struct px_control_query *q,
				  px_vec3 device_m,
				  const px_vec3 *device_velocity_m_per_s,
				  struct px_control_haptic_out *out);

/* ------------------------------------------------------------------ */
/* Serial chain and collision avoidance                                */
/* ------------------------------------------------------------------ */

#define PX_CONTROL_MAX_JOINTS 16
#define PX_CONTROL_MAX_CAPSULES 32

enum px_control_joint_type {
	PX_CONTROL_REVOLUTE = 0, /* q in rad about axis */
	PX_CONTROL_PRISMATIC = 1 /* q in m along axis */
};

/*
 * Joint i: link frame i = link frame i-1 * pre * motion(axis, q_i) *
 * post. URDF-style joints use pre = origin and post = identity; standard
 * DH joints use pre = identity, axis = z and post = Rz(theta) Tz(d)
 * Tx(a) Rx(alpha).
 */
struct px_control_joint {
	int type;       /* enum px_control_joint_type */
	px_pose pre;
	px_vec3 axis;   /* unit, in the frame after pre */
	px_pose post;
};

/* A capsule on link frame `link` (0 = base, i = after joint i): the
 * points within radius_m of the segment a_m..b_m (link frame). */
struct px_control_capsule {
	int link;
	px_vec3 a_m, b_m;
	double radius_m;
};

struct px_control_chain {
	px_pose base;   /* link frame 0 in the world */
	int n_joints;
	struct px_control_joint joints[PX_CONTROL_MAX_JOINTS];
	int n_capsules;
	struct px_control_capsule capsules[PX_CONTROL_MAX_CAPSULES];
};

/* Pose from a URDF origin: translation xyz_m and fixed-axis roll,
 * pitch, yaw (R = Rz(yaw) Ry(pitch) Rx(roll)). @note RT-safe. */
PX_API px_pose px_control_pose_from_xyz_rpy(px_vec3 xyz_m, px_vec3 rpy_rad);

/* Empty chain with the given base pose. */
PX_API void px_control_chain_init(struct px_control_chain *c, px_pose base);

/* Append a joint with standard DH parameters (Denavit-Hartenberg: Rz(theta
 * + q) Tz(d) Tx(a) Rx(alpha); prismatic: q adds to d). Returns PX_OK,
 * PX_E_INVAL, PX_E_NAN or PX_E_NOSPC (PX_CONTROL_MAX_JOINTS). */
PX_API int px_control_chain_add_dh(struct px_control_chain *c, int type,
				   double a_m, double alpha_rad, double d_m,
				   double theta_rad);

/* Append a URDF-style joint: origin (parent link frame to joint frame)
 * and axis in the joint frame (normalised here; zero is PX_E_INVAL). */
PX_API int px_control_chain_add_joint(struct px_control_chain *c, int type,
				      px_pose origin, px_vec3 axis);

/* Add a capsule to link frame link (0..n_joints at the time of the
 * call or later; checked by px_control_avoid_step). radius_m >= 0.
 * Returns PX_OK, PX_E_INVAL, PX_E_NAN or PX_E_NOSPC. */
PX_API int px_control_chain_add_capsule(struct px_control_chain *c, int link,
					px_vec3 a_m, px_vec3 b_m,
					double radius_m);

/*
 * Forward kinematics: frames[0] = base, frames[i] = link frame i, for
 * i = 0..n_joints (cap >= n_joints + 1, else PX_E_NOSPC). q has n_joints
 * values. Returns PX_OK, PX_E_INVAL, PX_E_NAN, PX_E_NOSPC.
 * @note RT-safe.
 */
PX_API int px_control_chain_fk(const struct px_control_chain *c,
			       const double *q, px_pose *frames, size_t cap);

/*
 * Linear velocity Jacobian of the world point p_m rigidly attached to
 * link frame `link` at configuration q: column j (j < n_joints) is the
 * point's velocity per unit velocity of joint j (zero for joints after
 * link). jac has n_joints entries. Returns PX_OK, PX_E_INVAL.
 * @note RT-safe.
 */
PX_API int px_control_chain_jacobian(const struct px_control_chain *c,
				     const double *q, int link, px_vec3 p_m,
				     px_vec3 *jac);

struct px_control_avoid_params {
	double influence_distance_m;  /* scaling starts below this */
	double protective_distance_m; /* nominal motion stops here */
	/* Repulsive speed of the closest point away from the obstacle at
	 * the protective distance (linear to 0 at the influence distance). */
	double repulsive_speed_m_per_s;
	double max_joint_velocity;    /* rad/s or m/s, each joint */
	/* At most this fraction of a capsule's remaining margin to the
	 * protective distance may be closed by one cycle (linear
	 * prediction), 0 < f <= 1. */
	double max_margin_fraction;
	int segment_point_queries;    /* budget per capsule, 2..64 */
	double segment_tol_m;         /* bisection stops at this gap */
	/* true: the speed scaling looks only at the contacts that the
	 * nominal motion closes (moving away, or along an obstacle, keeps
	 * full speed); false: at the smallest clearance whatever the
	 * motion. Repulsion and the discrete-time guard act either way. */
	bool approach_only;
	/* Self-clearance of robot links (px_urdf_avoid_step): their own
	 * ramp, as the two distances above; 0 <= protective < influence,
	 * or both 0: self contacts take the distances above. */
	double self_influence_distance_m, self_protective_distance_m;
};

/* Clearance of one capsule. */
struct px_control_clearance {
	bool valid;           /* an obstacle lies within the query range */
	double clearance_m;   /* surface-to-scene distance (best estimate) */
	double lower_bound_m; /* certified lower bound */
	px_vec3 point_m;      /* closest point on the capsule axis, world */
	px_vec3 obstacle_m;   /* closest scene point */
	px_vec3 normal;       /* unit, from the obstacle toward the link */
};

struct px_control_avoid_out {
	double qdot[PX_CONTROL_MAX_JOINTS]; /* command, rad/s or m/s */
	double scale;          /* factor on the nominal velocity, 0..1 */
	double min_clearance_m;/* smallest certified clearance */
	int closest_capsule;   /* index, -1 when nothing is in range */
	int point_queries;     /* query calls made this cycle */
	struct px_control_clearance caps[PX_CONTROL_MAX_CAPSULES];
};

/* Defaults: influence 0.3 m, protective 0.05 m, repulsion 0.1 m/s, joint
 * limit 1 rad/s, margin fraction 0.5, 24 queries, 1e-4 m, scaling on
 * every contact (approach_only false), self-clearance 0.05 m influence
 * and 0.01 m protective. */
PX_API void px_control_avoid_params_default(struct px_control_avoid_params *p);

/* Check params. Returns PX_OK, PX_E_INVAL (NULL) or PX_E_RANGE. */
PX_API int px_control_avoid_params_check(const struct px_control_avoid_params *p);

/*
 * Clearances of every capsule at q (out has chain->n_capsules entries;
 * max_distance_m is the query range). Returns PX_OK, PX_E_INVAL,
 * PX_E_NAN or a query error. *n_queries (may be NULL) gets the query
 * calls made.
 * @note RT-safe.
 */
PX_API int px_control_chain_clearances(const struct px_control_chain *c,
				       const struct px_control_avoid_params *p,
				       const struct px_control_query *qry,
				       const double *q, double max_distance_m,
				       struct px_control_clearance *out,
				       int *n_queries);

/*
 * One avoidance cycle: clearances at q, then
 *   qdot = s * qdot_nominal + sum_i w_i v_rep J_i^T n_i / |J_i^T n_i|^2
 * where s is 1 at or beyond the influence distance, falls linearly to 0
 * at the protective distance and is 0 inside it (also reduced so that no
 * capsule closes more than max_margin_fraction of its margin in one
 * period, to first order), w_i the same ramp reversed (0 at the
 * influence distance, 1 at and inside the protective distance), J_i the
 * Jacobian of capsule i's closest point and n_i its normal; the result
 * is scaled down uniformly to max_joint_velocity. On a query error the
 * command is zero and the error is returned.
 * Returns PX_OK, PX_E_INVAL, PX_E_RANGE, PX_E_NAN or a query error.
 * @note RT-safe.
 */
PX_API int px_control_avoid_step(const struct px_control_chain *c,
				 const struct px_control_avoid_params *p,
				 const struct px_control_query *qry,
				 const double *q, const double *qdot_nominal,
				 int64_t period_ns,
				 struct px_control_avoid_out *out);

/*
 * A clearance measured elsewhere (robot link models against obstacles
 * or against each other, px_urdf.h): the point on link frame `link`
 * closest to the other side, the other side's point (a fixed obstacle,
 * or on link frame other_link for self-clearance), the unit normal from
 * the other side toward the link point (the direction that opens the
 * clearance; its opposite points at the obstacle), and the clearance,
 * a certified lower bound where one is known, negative (-depth) when
 * the two overlap.
 */
struct px_control_contact {
	int link;           /* 0 (base) .. n_joints */
	int other_link;     /* -1: a fixed obstacle; else 0 .. n_joints */
	double clearance_m;
	px_vec3 point_m;    /* on the link, world */
	px_vec3 other_m;    /* on the other side, world */
	px_vec3 normal;
	/* this contact's own ramp (self-clearance, whose links come close
	 * by design): influence_distance_m > protective_distance_m >= 0;
	 * influence_distance_m 0: the params' distances */
	double influence_distance_m, protective_distance_m;
};

/*
 * The avoidance command of px_control_avoid_step() from n given
 * contacts instead of capsule queries: speed scaling by the smallest
 * ramp (1 at the contact's influence distance, 0 at its protective
 * distance) over the contacts (p->approach_only: over those the nominal
 * motion closes, rate -(J^T n) . qdot_nominal > 0), repulsion along J^T n
 * for every contact inside the influence distance (self-contacts: the
 * relative Jacobian J_link^T n - J_other^T n), the joint velocity limit
 * and the discrete-time guard, exactly as there. out->caps and
 * out->point_queries are left zero, out->closest_capsule -1; *closest
 * (may be NULL) gets the index of the smallest contact, -1 when none
 * lies within the influence distance. Returns PX_OK, PX_E_INVAL,
 * PX_E_RANGE (a link index out of the chain, bad params), PX_E_NAN.
 * @note RT-safe.
 */
PX_API int px_control_avoid_command(const struct px_control_chain *c,
				    const struct px_control_avoid_params *p,
				    const double *q, const double *qdot_nominal,
				    int64_t period_ns,
				    const struct px_control_contact *contacts,
				    int n, struct px_control_avoid_out *out,
				    int *closest);

/* ------------------------------------------------------------------ */
/* Configuration (setup time)                                          */
/* ------------------------------------------------------------------ */

struct px_config;
struct px_config_diag;
struct px_config_schema;

enum px_control_mode {
	PX_CONTROL_MODE_NONE = 0,
	PX_CONTROL_MODE_HAPTIC = 1,
	PX_CONTROL_MODE_AVOIDANCE = 2
};

enum px_control_clearance_kind {
	PX_CONTROL_CLEARANCE_AUTO = 0,     /* models with a URDF, else capsules */
	PX_CONTROL_CLEARANCE_CAPSULES = 1, /* capsules against the scene */
	PX_CONTROL_CLEARANCE_MODELS = 2    /* URDF collision shapes as models */
};

#define PX_CONTROL_MAX_PACKAGE_PATHS 16
#define PX_CONTROL_MAX_ALLOWED 4096

/* Two link names (an allowed-collision entry). */
struct px_control_link_pair {
	const char *a, *b;
};

/*
 * control.avoidance with a URDF (path NULL: the chain is the typed
 * joints). The control module only reads the keys; the runner loads the
 * file (robot/px_urdf.h). Strings point into the config document.
 */
struct px_control_urdf_config {
	const char *path;        /* as written: relative to the config file */
	const char *base_link;   /* NULL: the URDF's root */
	const char *tip_link;
	const char **package_paths;
	size_t n_package_paths;
	/* joint i of the drives (canopen drives' joint: i) is the URDF
	 * joint joints[i]; n_joints 0: the chain's own order */
	const char **joints;
	size_t n_joints;
	int clearance;           /* enum px_control_clearance_kind, never AUTO */
	bool self_clearance;     /* non-adjacent links against each other */
	/* link pairs never measured against each other (MoveIt's allowed
	 * collision matrix) */
	const struct px_control_link_pair *allowed;
	size_t n_allowed;
};

struct px_control_config {
	int mode;                              /* enum px_control_mode */
	const char *device;                    /* device the output goes to */
	struct px_control_haptic_params haptic;
	struct px_control_avoid_params avoid;
	struct px_control_chain chain;
	struct px_control_urdf_config urdf;
	/* Haptic stability at the config's loop period (mode haptic). */
	bool stable;
	double stiffness_limit_n_per_m;
	/* "file:line:column: control.haptic.stiffness_n_per_m: warning: ..."
	 * when not stable, else "". */
	char warning[640];
};

/*
 * Read cfg->control (absent: mode none, defaults) into out, check it
 * against the rest of the config (device names, safety limits, CANopen
 * joint indices) and compute the stability warning at loop.period_ns.
 * Problems are appended to diag as "file:line:column: control.key: what".
 * Haptic max_force_n and max_force_rate_n_per_s default to the safety
 * values and may not exceed them; device_damping_n_s_per_m defaults to
 * the damping of a simulated haptic device, else 0. Strings in out point
 * into cfg's document. Returns PX_OK, PX_E_PARSE (problems found),
 * PX_E_NOMEM, PX_E_INVAL.
 */
PX_API int px_control_config_read(const struct px_config *cfg,
				  struct px_control_config *out,
				  struct px_config_diag *diag);

/* Schema of the control section (for tools and the docs check). */
PX_API const struct px_config_schema *px_control_config_schema(void);

#ifdef __cplusplus
}
#endif

#endif
