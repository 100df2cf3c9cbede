/* The app's obstacle cloud: a simulated depth camera (sim.depth_sensor:
 * its keys, the camera) or a remote cloud (teleop.scene_device's
 * cloud_topic, filled by the dds device's thread). At setup the cloud
 * feed (the cloud is one more obstacle of the URDF robot), in the cycle
 * (real-time rules) the newest frame swapped in and its stamp given to
 * the watchdog. */
#include "app_internal.h"
#include "schema_internal.h"

static const char *const depth_kind_names[] = {"box", "arm", NULL};

static const struct px_config_key depth_pose_keys[] = {
	K_VEC(struct raw_depth_pose, xyz_m, "xyz_m", 0, -1e6, 1e6),
	K_VEC(struct raw_depth_pose, rpy_rad, "rpy_rad", 0, -100, 100),
};
SCHEMA(depth_pose_schema, "camera", depth_pose_keys, NULL);

static void depth_check(struct px_config_reader *r, const struct px_config_node *map,
			void *obj)
{
	const struct raw_depth *d = obj;
	if (d->kind == PX_DEPTH_SIM_BOX && !(d->size_m[2] > 0))
		px_config_reader_error(r, px_config_node_get(map, "size_m"), "size_m",
				       "a box needs three half extents > 0");
	if (!(d->size_m[0] > 0 && d->size_m[1] > 0))
		px_config_reader_error(r, px_config_node_get(map, "size_m"), "size_m",
				       "box: half extents > 0; arm: length and radius > 0");
}

static const struct px_config_key depth_keys[] = {
	K_ENUM(struct raw_depth, kind, "kind", 0, depth_kind_names, PX_DEPTH_SIM_BOX),
	K_SUB(struct raw_depth, camera, "camera", depth_pose_schema),
	K_INT(struct raw_depth, width, "width", 0, 1, PX_DEPTH_SIM_MAX_PIXELS, 64),
	K_INT(struct raw_depth, height, "height", 0, 1, PX_DEPTH_SIM_MAX_PIXELS, 48),
	K_DBL(struct raw_depth, fov_x_rad, "fov_x_rad", PX_CONFIG_MIN_EXCL | PX_CONFIG_MAX_EXCL,
	      0, 3, 1.0),
	K_DBL(struct raw_depth, max_range_m, "max_range_m", PX_CONFIG_MIN_EXCL, 0, 1e4, 4.0),
	K_DBL(struct raw_depth, noise_m, "noise_m", 0, 0, 0.5, 0.002),
	K_DBL(struct raw_depth, rate_hz, "rate_hz", 0, 0.1, 1000, 30),
	K_VEC(struct raw_depth, size_m, "size_m", PX_CONFIG_REQUIRED, 0, 100),
	K_VEC(struct raw_depth, from_m, "from_m", PX_CONFIG_REQUIRED, -1e6, 1e6),
	K_VEC(struct raw_depth, to_m, "to_m", PX_CONFIG_REQUIRED, -1e6, 1e6),
	K_DBL(struct raw_depth, start_s, "start_s", 0, 0, 1e6, 0),
	K_DBL(struct raw_depth, period_s, "period_s", 0, 0, 1e6, 0),
	K_INT(struct raw_depth, seed, "seed", 0, 0, INT64_MAX, 1),
	K_INT(struct raw_depth, slots, "slots", 0, 3, PX_CLOUD_FEED_MAX_SLOTS, 4),
	K_DUR(struct raw_depth, lookahead_ns, "lookahead_ns", 0, 0, 10000000000LL,
	      100000000),
	K_DUR(struct raw_depth, stale_timeout_ns, "stale_timeout_ns", 0, 1000000,
	      100000000000LL, 200000000),
};
const struct px_config_schema app_depth_schema = {
	"depth_sensor", depth_keys, sizeof(depth_keys) / sizeof(depth_keys[0]), depth_check};

/* ---- setup --------------------------------------------------------------- */

/* Not an obstacle without a URDF robot's clearance models. */
static int needs_robot(struct px_app *a, const struct px_config_node *at,
		       const char *key, const char *what)
{
	if (a->robot_models)
		return 0;
	app_check_error(a, at, key,
			"%s is an obstacle of a URDF robot: it needs control.mode "
			"avoidance with control.avoidance.urdf and clearance models",
			what);
	return 1;
}

/* The feed and the far point that stands for an empty view, the
 * robot's last obstacle until the first frame (what: the source, for
 * the error). */
static int feed_setup(struct px_app *a, const struct px_config_node *at,
		      const char *key, const char *what, int slots,
		      size_t max_points)
{
	static const double far[3] = {0, 0, PX_CLOUD_FEED_FAR_M};
	int rc = px_cloud_feed_create(slots, max_points, 0.0, &a->feed);
	if (rc == PX_OK)
		rc = px_cloud_model(far, 1, 0.0, NULL, &a->cloud_none);
	if (rc != PX_OK) {
		app_check_error(a, at, key, "%s: %s", what, px_strerror(rc));
		return 1;
	}
	rc = app_robot_obstacles(a, a->cloud_none);
	a->cloud_obstacle = a->n_scene_obstacles;
	return rc;
}

/* A remote cloud (teleop.scene_device with a cloud_topic): the feed its
 * device's thread fills, made before the devices. */
static int remote_cloud_setup(struct px_app *a)
{
	const struct px_config_node *at = app_cfg_node(a, "teleop", "scene_device");
	if (a->sim.has_depth) {
		app_check_error(a, at, "teleop.scene_device",
				"one obstacle cloud per run: sim.depth_sensor or a "
				"remote cloud, not both");
		return 1;
	}
	if (needs_robot(a, at, "teleop.scene_device", "a remote cloud"))
		return 1;
	return feed_setup(a, at, "teleop.scene_device", "the cloud feed", 4,
			  (size_t)a->tele.c.cloud_max_points);
}

int app_sensor_setup(struct px_app *a)
{
	const struct raw_depth *d = &a->sim.depth;
	const struct px_config_node *at =
		px_config_node_get(app_cfg_node(a, "sim", NULL), "depth_sensor");
	struct px_depth_sim_params p;
	int rc;
	if (app_teleop_cloud_source(a))
		return remote_cloud_setup(a);
	if (!a->sim.has_depth)
		return 0;
	if (needs_robot(a, at, "sim.depth_sensor", "the camera's cloud"))
		return 1;
	px_depth_sim_params_default(&p);
	p.kind = d->kind;
	p.camera = px_control_pose_from_xyz_rpy(px_v3(d->camera.xyz_m[0], d->camera.xyz_m[1],
						      d->camera.xyz_m[2]),
						px_v3(d->camera.rpy_rad[0], d->camera.rpy_rad[1],
						      d->camera.rpy_rad[2]));
	p.width = (int)d->width;
	p.height = (int)d->height;
	p.fov_x_rad = d->fov_x_rad;
	p.max_range_m = d->max_range_m;
	p.noise_m = d->noise_m;
	p.rate_hz = d->rate_hz;
	p.size_m = px_v3(d->size_m[0], d->size_m[1], d->size_m[2]);
	p.from_m = px_v3(d->from_m[0], d->from_m[1], d->from_m[2]);
	p.to_m = px_v3(d->to_m[0], d->to_m[1], d->to_m[2]);
	p.start_s = d->start_s;
	p.period_s = d->period_s;
	p.seed = (uint64_t)d->seed;
	rc = px_depth_sim_create(&p, &a->depth);
	if (rc != PX_OK) {
		app_check_error(a, at, "sim.depth_sensor", "the simulated camera: %s",
				px_strerror(rc));
		return 1;
	}
	return feed_setup(a, at, "sim.depth_sensor", "the simulated camera",
			  (int)d->slots, px_depth_sim_max_points(a->depth));
}

/* After the loop exists: the cloud's frames are a watched input (a
 * remote one with its device's stale timeout), and the camera's thread
 * starts. */
int app_sensor_start(struct px_app *a)
{
	int rc;
	if (a->feed && !a->depth && a->tele.scene >= 0) {
		struct px_dev *d = a->dev[a->tele.scene];
		a->cloud_input = px_loop_input_add(a->loop, px_dev_name(d),
						   px_dev_stale_timeout_ns(d));
		if (a->cloud_input < 0) {
			app_note(a, "%s: remote cloud watchdog: %s\n", app_name(a),
				 px_strerror(a->cloud_input));
			return 1;
		}
		return 0;
	}
	if (!a->depth)
		return 0;
	a->cloud_input = px_loop_input_add(a->loop, "depth_sensor", a->sim.depth.stale_timeout_ns);
	rc = a->cloud_input < 0 ? a->cloud_input
				: px_depth_sim_start(a->depth, a->feed, a->sim.depth.lookahead_ns);
	if (rc < 0) {
		app_note(a, "%s: depth sensor: %s\n", app_name(a), px_strerror(rc));
		return 1;
	}
	return 0;
}

void app_sensor_free(struct px_app *a)
{
	px_depth_sim_free(a->depth); /* stops the thread first */
	a->depth = NULL;
	px_cloud_feed_free(a->feed);
	a->feed = NULL;
	px_model_free(a->cloud_none);
	a->cloud_none = NULL;
}

/* ---- the cycle (real-time rules) ----------------------------------------- */

/* On the virtual clock the simulated camera is part of the simulation:
 * a frame that is due is waited for (its thread builds it from its
 * stamp alone, ahead of the clock), so every run sees the same frames
 * at the same cycles. On the real clock nothing waits: a late frame is
 * a stale input. */
static void wait_due_frame(struct px_app *a, int64_t now_ns)
{
	int64_t t0 = px_depth_sim_stamp(a->depth, 0), due, until;
	struct px_cloud_feed_stats st;
	uint64_t k;
	if (!a->o.virtual_time || now_ns < t0)
		return;
	k = (uint64_t)((double)(now_ns - t0) * 1e-9 * a->sim.depth.rate_hz);
	due = px_depth_sim_stamp(a->depth, k);
	if (due > now_ns && k > 0)
		due = px_depth_sim_stamp(a->depth, k - 1);
	until = app_mono_ns() + 1000000000;
	do {
		px_cloud_feed_take(a->feed, now_ns, NULL, NULL);
		px_cloud_feed_stats(a->feed, &st);
	} while ((!st.taken || st.stamp_ns < due) && app_mono_ns() < until);
}

void app_sensor_read(struct px_app *a, struct px_loop *l, int64_t now_ns)
{
	struct px_cloud_feed_stats st;
	if (!a->feed || a->cloud_input < 0)
		return;
	if (a->depth)
		px_depth_sim_clock(a->depth, now_ns);
	if (a->depth && a->o.virtual_time)
		wait_due_frame(a, now_ns);
	else
		px_cloud_feed_take(a->feed, now_ns, NULL, NULL);
	px_cloud_feed_stats(a->feed, &st);
	if (st.taken != a->cloud_taken) {
		/* a newer frame: the robot measures it, its pairs cold */
		a->cloud_taken = st.taken;
		px_urdf_robot_replace_obstacle(a->robot, a->cloud_obstacle,
					       px_cloud_feed_model(a->feed));
		a->cloud_swaps++;
	}
	if (st.taken)
		px_loop_input_stamp(l, a->cloud_input, st.stamp_ns);
}
