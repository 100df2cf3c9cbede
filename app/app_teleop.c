/* Remote devices and teleoperation: the config's dds devices
 * (px_bridge_dev_create with the bridge section's domain and network),
 * the teleop section (a follower's arm tracking a remote pose, forces
 * from its clearances back, a master's remote force added to the
 * rendered one) and the link rule: a remote input that was live and goes
 * silent latches safe state, which its return does not end (as an
 * e-stop's release). The cycle part follows the real-time rules. */
#include "app_internal.h"
#include "px_bridge.h"
#include "schema_internal.h"

/* ---- the teleop section ---------------------------------------------- */

static const struct px_config_key params_keys[] = {
	K_DBL(struct px_bridge_params, stiffness_n_per_m, "stiffness_n_per_m", 0,
	      0, 1e7, 0),
	K_DBL(struct px_bridge_params, damping_n_s_per_m, "damping_n_s_per_m", 0,
	      0, 1e6, 0),
	K_DBL(struct px_bridge_params, max_force_n, "max_force_n", 0, 0, 10000,
	      0),
	K_DBL(struct px_bridge_params, speed_scale, "speed_scale", 0, 0, 1, 0),
};
SCHEMA(params_schema, "params", params_keys, NULL);

static const struct px_config_key teleop_keys[] = {
	K_STR(struct raw_teleop, follow_device, "follow_device",
	      PX_CONFIG_NONEMPTY),
	K_DBL(struct raw_teleop, follow_scale, "follow_scale",
	      PX_CONFIG_MIN_EXCL, 0, 100, 1.0),
	K_DBL(struct raw_teleop, follow_gain_per_s, "follow_gain_per_s",
	      PX_CONFIG_MIN_EXCL, 0, 1000, 10.0),
	K_DBL(struct raw_teleop, follow_max_speed_m_per_s,
	      "follow_max_speed_m_per_s", PX_CONFIG_MIN_EXCL, 0, 10, 0.5),
	K_STR(struct raw_teleop, feedback_device, "feedback_device",
	      PX_CONFIG_NONEMPTY),
	K_DBL(struct raw_teleop, feedback_max_force_n, "feedback_max_force_n",
	      0, 0, 1000, 2.0),
	K_STR(struct raw_teleop, force_device, "force_device",
	      PX_CONFIG_NONEMPTY),
	K_STR(struct raw_teleop, params_device, "params_device",
	      PX_CONFIG_NONEMPTY),
	K_SUB(struct raw_teleop, params_min, "params_min", params_schema),
	K_SUBP(struct raw_teleop, params_max, "params_max", params_schema,
	       has_params_max),
	K_STR(struct raw_teleop, scene_device, "scene_device", PX_CONFIG_NONEMPTY),
	{.name = "scene_models", .type = PX_CONFIG_T_SEQ,
	 .offset = offsetof(struct raw_teleop, scene_models),
	 .flags = PX_CONFIG_NONEMPTY, .elem = PX_CONFIG_T_STRING,
	 .elem_size = sizeof(const char *),
	 .count_offset = offsetof(struct raw_teleop, n_scene_models),
	 .min_count = 1, .max_count = PX_BRIDGE_SCENE_MODELS},
	K_VECPD(struct raw_teleop, workspace_min_m, "workspace_min_m", 0, -1e6,
		1e6, -2.0, has_ws_min),
	K_VECPD(struct raw_teleop, workspace_max_m, "workspace_max_m", 0, -1e6,
		1e6, 2.0, has_ws_max),
	K_INT(struct raw_teleop, cloud_max_points, "cloud_max_points", 0, 1,
	      PX_BRIDGE_CLOUD_MAX_POINTS, 20000),
};
SCHEMA(teleop_schema, "teleop", teleop_keys, NULL);

const struct px_config_schema *app_teleop_schema(void)
{
	return &teleop_schema;
}

int app_teleop_read(struct px_app *a)
{
	struct app_teleop *t = &a->tele;
	int rc;
	t->follow = t->feedback = t->force = t->params = -1;
	t->scene = t->scene_dds = -1;
	t->force_input = -1;
	t->speed_scale = 1.0;
	rc = px_config_read(a->cfg->doc, a->cfg->teleop, "teleop",
			    &teleop_schema, &t->c, &a->diag);
	if (rc == PX_OK)
		rc = px_bridge_config_read(a->cfg, &t->bridge, &a->diag);
	t->bridge.thread_priority = app_link_priority(a->cfg, 2);
	/* without params_max: the config's own values, speed 1 (remote
	 * updates may only lower them) */
	if (rc == PX_OK && !t->c.has_params_max) {
		t->c.params_max.stiffness_n_per_m = a->ctl.haptic.stiffness_n_per_m;
		t->c.params_max.damping_n_s_per_m = a->ctl.haptic.damping_n_s_per_m;
		t->c.params_max.max_force_n = a->ctl.haptic.max_force_n;
		t->c.params_max.speed_scale = 1.0;
	}
	return rc;
}

/* The device named by teleop.KEY (NULL: not given) must be a dds
 * device with the topic `what` (has_topic of its dds keys), in control
 * mode `mode` (why: what that mode is for). */
static void need_dds(struct px_app *a, const char *key, const char *name,
		     size_t topic_off, const char *what, int mode,
		     const char *why)
{
	const struct px_config_node *at = app_cfg_node(a, "teleop", key);
	const struct px_config_device *d;
	char k[48];
	if (!name)
		return;
	d = px_config_device_find(a->cfg, name);
	snprintf(k, sizeof(k), "teleop.%s", key);
	if (!d || d->backend != PX_CONFIG_BACKEND_DDS)
		app_check_error(a, at, k, "'%s' is not a dds device in devices",
				name);
	else if (!*(const char *const *)((const char *)&d->dds + topic_off))
		app_check_error(a, at, k, "dds device '%s' has no %s", name, what);
	if (a->ctl.mode != mode)
		app_check_error(a, at, k, "%s", why);
}

/* The scene updates' keys: a dds device with a cloud or scene topic,
 * scene_models exactly with a scene topic, each the name of a scene
 * model (and a ROS 2 name token: it is part of a topic name), a box
 * that is one. The cloud's place among the obstacles is app_sensor.c's
 * to check. */
static void scene_check(struct px_app *a)
{
	const struct raw_teleop *c = &a->tele.c;
	const struct px_config_node *at = app_cfg_node(a, "teleop", "scene_device");
	const struct px_config_device *d;
	size_t i, j, n = a->scene ? px_scene_count(a->scene) : 0;
	if (!c->scene_device) {
		if (c->n_scene_models)
			app_check_error(a, app_cfg_node(a, "teleop", "scene_models"),
					"teleop.scene_models",
					"scene models without a teleop.scene_device");
		return;
	}
	d = px_config_device_find(a->cfg, c->scene_device);
	if (!d || d->backend != PX_CONFIG_BACKEND_DDS) {
		app_check_error(a, at, "teleop.scene_device",
				"'%s' is not a dds device in devices", c->scene_device);
		return;
	}
	if (!d->dds.cloud_topic && !d->dds.scene_topic)
		app_check_error(a, at, "teleop.scene_device",
				"dds device '%s' has neither cloud_topic nor scene_topic",
				c->scene_device);
	if (!d->dds.scene_topic != !c->n_scene_models)
		app_check_error(a, app_cfg_node(a, "teleop", "scene_models"),
				"teleop.scene_models",
				d->dds.scene_topic
					? "dds device '%s' has a scene_topic: name the "
					  "models it may pose"
					: "dds device '%s' has no scene_topic for them",
				c->scene_device);
	for (i = 0; i < c->n_scene_models; i++) {
		const char *m = c->scene_models[i];
		for (j = 0; j < n && strcmp(px_scene_name(a->scene, j), m); j++)
			;
		if (j == n || px__ros_name_problem(m, 64) || strchr(m, '/'))
			app_check_error(a, app_cfg_node(a, "teleop", "scene_models"),
					"teleop.scene_models",
					j == n ? "'%s' is not a model of the scene"
					       : "'%s' is not a ROS 2 name token "
						 "(letters, digits, '_')",
					m);
		else
			a->tele.scene_model[i] = (int)j;
	}
	for (i = 0; i < 3; i++)
		if (!(c->workspace_min_m[i] < c->workspace_max_m[i]))
			app_check_error(a, app_cfg_node(a, "teleop", "workspace_max_m"),
					"teleop.workspace_max_m",
					"each coordinate must be above workspace_min_m's");
}

/* 1 when teleop.scene_device reads obstacle clouds. */
int app_teleop_cloud_source(const struct px_app *a)
{
	const struct px_config_device *d;
	if (!a->tele.c.scene_device)
		return 0;
	d = px_config_device_find(a->cfg, a->tele.c.scene_device);
	return d && d->backend == PX_CONFIG_BACKEND_DDS && d->dds.cloud_topic;
}

void app_teleop_check(struct px_app *a)
{
	const struct raw_teleop *c = &a->tele.c;
	need_dds(a, "follow_device", c->follow_device,
		 offsetof(struct px_config_dds, pose_topic), "pose_topic",
		 PX_CONTROL_MODE_AVOIDANCE,
		 "following a remote pose needs control mode 'avoidance' (an arm)");
	need_dds(a, "feedback_device", c->feedback_device,
		 offsetof(struct px_config_dds, command_topic), "command_topic",
		 PX_CONTROL_MODE_AVOIDANCE,
		 "forces from clearances need control mode 'avoidance' (an arm)");
	need_dds(a, "params_device", c->params_device,
		 offsetof(struct px_config_dds, params_topic), "params_topic",
		 a->ctl.mode, "");
	if (c->params_device &&
	    (c->params_min.stiffness_n_per_m > c->params_max.stiffness_n_per_m ||
	     c->params_min.damping_n_s_per_m > c->params_max.damping_n_s_per_m ||
	     c->params_min.max_force_n > c->params_max.max_force_n ||
	     c->params_min.speed_scale > c->params_max.speed_scale))
		app_check_error(a, app_cfg_node(a, "teleop", "params_min"),
				"teleop.params_min",
				"a minimum above its maximum (params_max, or "
				"the config's own value when absent)");
	scene_check(a);
	need_dds(a, "force_device", c->force_device,
		 offsetof(struct px_config_dds, wrench_topic), "wrench_topic",
		 PX_CONTROL_MODE_HAPTIC,
		 "a remote force needs control mode 'haptic' (it adds to the "
		 "rendered force)");
}

/* ---- dds devices ------------------------------------------------------ */

int app_link_priority(const struct px_config *cfg, int below)
{
	int64_t p = cfg->loop.priority - below;
	return p >= 1 ? (int)p : 0;
}

int app_make_dds(struct px_app *a, int k)
{
	const struct px_config_device *d = &a->cfg->devices[k];
	struct app_teleop *t = &a->tele;
	struct px_dev_config dc;
	struct px_bridge_dev_config bc;
	struct px_bridge_config br = t->bridge;
	char msg[400] = "";
	int rc, i = a->n_dev;
	if (i >= MAX_DEVS || t->n_dds >= MAX_DEVS) {
		app_note(a, "%s: more than %d devices\n", app_name(a), MAX_DEVS);
		return 1;
	}
	px_dev_config_default(&dc);
	dc.name = d->name;
	dc.stale_timeout_ns = d->stale_timeout_ns
				      ? d->stale_timeout_ns
				      : a->cfg->safety.watchdog.device_timeout_ns;
	if (d->dds.ns)
		br.ns = d->dds.ns;
	memset(&bc, 0, sizeof(bc));
	bc.bridge = &br;
	bc.pose_topic = d->dds.pose_topic;
	bc.command_topic = d->dds.command_topic;
	bc.wrench_topic = d->dds.wrench_topic;
	bc.pose_out_topic = d->dds.pose_out_topic;
	bc.connect_timeout_ns = d->dds.connect_timeout_ns;
	/* the link's thread just below the loop: it carries the loop's
	 * inputs and outputs */
	bc.thread_priority = app_link_priority(a->cfg, 1);
	/* parameters only from the device teleop.params_device names */
	if (t->c.params_device && !strcmp(t->c.params_device, d->name)) {
		bc.params_topic = d->dds.params_topic;
		bc.params_min = t->c.params_min;
		bc.params_max = t->c.params_max;
	}
	/* scene updates only from the device teleop.scene_device names */
	if (t->c.scene_device && !strcmp(t->c.scene_device, d->name)) {
		bc.cloud_topic = d->dds.cloud_topic;
		bc.cloud_feed = a->feed;
		bc.cloud_max_points = (size_t)t->c.cloud_max_points;
		bc.scene_topic = d->dds.scene_topic;
		bc.scene_models = t->c.scene_models;
		bc.n_scene_models = t->c.n_scene_models;
		memcpy(bc.workspace_min_m, t->c.workspace_min_m,
		       sizeof(bc.workspace_min_m));
		memcpy(bc.workspace_max_m, t->c.workspace_max_m,
		       sizeof(bc.workspace_max_m));
	}
	rc = px_bridge_dev_create(&dc, &bc, &a->dev[i], msg, sizeof(msg));
	if (rc != PX_OK) {
		app_note(a, "%s: device '%s' (dds): %s\n", app_name(a), d->name,
			 msg[0] ? msg : px_strerror(rc));
		return 1;
	}
	a->dev_owned[i] = 1;
	a->n_dev++;
	t->dds[t->n_dds].dev = i;
	t->dds[t->n_dds].tmo_ns = dc.stale_timeout_ns;
	t->dds[t->n_dds].pose_out = d->dds.pose_out_topic != NULL;
	t->dds[t->n_dds].connect_ns = d->dds.connect_timeout_ns;
	t->dds[t->n_dds].input = -1;
	t->n_dds++;
	if (t->c.follow_device && !strcmp(t->c.follow_device, d->name))
		t->follow = i;
	if (t->c.feedback_device && !strcmp(t->c.feedback_device, d->name))
		t->feedback = i;
	if (t->c.force_device && !strcmp(t->c.force_device, d->name))
		t->force = i;
	if (bc.params_topic)
		t->params = i;
	if (bc.cloud_topic || bc.scene_topic) {
		t->scene = i;
		t->scene_dds = t->n_dds - 1;
		t->scene_cloud = bc.cloud_topic != NULL;
	}
	if (a->ctl.device && !strcmp(a->ctl.device, d->name) && d->dds.pose_topic)
		a->ctl_dev = i;
	return 0;
}

/* Device dev (index in px_app.dev) is the loop's input `input`. */
void app_teleop_input(struct px_app *a, int dev, int input)
{
	int i;
	for (i = 0; i < a->tele.n_dds; i++)
		if (a->tele.dds[i].dev == dev)
			a->tele.dds[i].input = input;
}

/* After the loop exists: the remote force is a watched input, the
 * feedback command a loop output (zero in safe state). */
int app_teleop_attach(struct px_app *a)
{
	struct app_teleop *t = &a->tele;
	int rc;
	if (t->force >= 0) {
		int64_t tmo = px_dev_stale_timeout_ns(a->dev[t->force]);
		t->force_input = px_loop_input_add(a->loop, px_dev_name(a->dev[t->force]),
						   tmo);
		if (t->force_input < 0) {
			app_note(a, "%s: remote force watchdog: %s\n", app_name(a),
				 px_strerror(t->force_input));
			return 1;
		}
	}
	if (t->feedback >= 0) {
		rc = px_dev_force_attach(a->dev[t->feedback], a->loop, &t->fb_cmd);
		if (rc < 0) {
			app_note(a, "%s: device '%s': %s\n", app_name(a),
				 px_dev_name(a->dev[t->feedback]), px_strerror(rc));
			return 1;
		}
	}
	return 0;
}

/* ---- the cycle (real-time rules) --------------------------------------- */

/* The remote model poses accepted since the last cycle, each set on
 * its scene model (seen by the next query; the robot measures the same
 * models). */
static void scene_poses(struct px_app *a)
{
	struct app_teleop *t = &a->tele;
	struct px_bridge_scene_poses p;
	size_t i;
	if (px_bridge_dev_scene_poses(a->dev[t->scene], &p) != 1)
		return;
	for (i = 0; i < t->c.n_scene_models; i++)
		if (p.seq[i] != t->scene_seq[i]) {
			t->scene_seq[i] = p.seq[i];
			if (px_scene_set_pose(a->scene, (size_t)t->scene_model[i],
					      p.pose[i]) == PX_OK)
				t->scene_poses_applied++;
		}
}

/* The remote cloud's newest frame (taken by app_sensor_read): its
 * receipt time, 0 before the first. */
static int64_t cloud_stamp(const struct px_app *a)
{
	struct px_cloud_feed_stats st;
	px_cloud_feed_stats(a->feed, &st);
	return st.taken ? st.stamp_ns : 0;
}

/* Read phase, after the devices: the remote force, the scene updates,
 * the link rule. */
void app_teleop_read_phase(struct px_app *a, struct px_loop *l, int64_t now_ns)
{
	struct app_teleop *t = &a->tele;
	int64_t cloud_at = t->scene_cloud ? cloud_stamp(a) : 0;
	int i;
	if (t->scene >= 0 && t->c.n_scene_models)
		scene_poses(a);
	if (t->force >= 0) {
		struct px_force_cmd w;
		int64_t at = 0;
		if (px_bridge_dev_wrench(a->dev[t->force], &w, &at) == 1) {
			memcpy(t->remote_force_n, w.force_n, sizeof(t->remote_force_n));
			t->force_t_ns = at;
			px_loop_input_stamp(l, t->force_input, at);
		}
	}
	if (t->params >= 0) {
		struct px_bridge_params p;
		if (px_bridge_dev_params(a->dev[t->params], &p) == 1) {
			/* checked against the configured ranges on receipt */
			a->haptic.p.stiffness_n_per_m = p.stiffness_n_per_m;
			a->haptic.p.damping_n_s_per_m = p.damping_n_s_per_m;
			a->haptic.p.max_force_n = p.max_force_n;
			t->speed_scale = p.speed_scale;
			t->params_applied++;
		}
	}
	/* the peer's loop may start a little after this one: until its
	 * first sample (at most connect_timeout_ns after the start) a remote
	 * input is not yet live, and not stale either */
	for (i = 0; i < t->n_dds; i++) {
		int k = t->dds[i].dev;
		if (now_ns - a->t0_ns >= t->dds[i].connect_ns)
			continue;
		if (t->dds[i].input >= 0 && a->sample[k].seq == 0)
			px_loop_input_stamp(l, t->dds[i].input, now_ns);
		if (k == t->force && !t->force_t_ns)
			px_loop_input_stamp(l, t->force_input, now_ns);
		if (k == t->scene && t->scene_cloud && !cloud_at)
			px_loop_input_stamp(l, a->cloud_input, now_ns);
	}
	for (i = 0; i < t->n_dds && !t->link_lost; i++) {
		int k = t->dds[i].dev, silent = 0;
		int64_t age = 0;
		if ((px_dev_caps(a->dev[k]) & PX_DEV_CAP_POSE) &&
		    a->sample[k].seq > 0 && a->sample[k].stale) {
			silent = 1;
			age = a->sample[k].age_ns;
		}
		if (k == t->force && t->force_t_ns &&
		    now_ns - t->force_t_ns > t->dds[i].tmo_ns) {
			silent = 1;
			age = now_ns - t->force_t_ns;
		}
		if (k == t->scene && cloud_at && now_ns - cloud_at > t->dds[i].tmo_ns) {
			silent = 1;
			age = now_ns - cloud_at;
		}
		if (silent) {
			t->link_lost = 1;
			t->link_lost_ns = now_ns;
			t->link_lost_dev = k;
			t->link_silent_ns = age;
		}
	}
	/* every cycle, as an e-stop held: no re-arm ends it */
	if (t->link_lost)
		px_loop_trip(l);
}

/* 3x3 solve of (J J^T + lambda^2 I) y = v, then qdot = J^T y: damped
 * least squares, well behaved near singular poses. */
static void dls(const px_vec3 *jac, int n, const double v[3], double *qdot)
{
	const double lam2 = 0.05 * 0.05;
	double m[3][3] = {{0}}, y[3], det, inv[3][3];
	int j, r, c;
	for (j = 0; j < n; j++) {
		const double col[3] = {jac[j].x, jac[j].y, jac[j].z};
		for (r = 0; r < 3; r++)
			for (c = 0; c < 3; c++)
				m[r][c] += col[r] * col[c];
	}
	for (r = 0; r < 3; r++)
		m[r][r] += lam2;
	inv[0][0] = m[1][1] * m[2][2] - m[1][2] * m[2][1];
	inv[0][1] = m[0][2] * m[2][1] - m[0][1] * m[2][2];
	inv[0][2] = m[0][1] * m[1][2] - m[0][2] * m[1][1];
	inv[1][0] = m[1][2] * m[2][0] - m[1][0] * m[2][2];
	inv[1][1] = m[0][0] * m[2][2] - m[0][2] * m[2][0];
	inv[1][2] = m[0][2] * m[1][0] - m[0][0] * m[1][2];
	inv[2][0] = m[1][0] * m[2][1] - m[1][1] * m[2][0];
	inv[2][1] = m[0][1] * m[2][0] - m[0][0] * m[2][1];
	inv[2][2] = m[0][0] * m[1][1] - m[0][1] * m[1][0];
	det = m[0][0] * inv[0][0] + m[0][1] * inv[1][0] + m[0][2] * inv[2][0];
	for (r = 0; r < 3; r++)
		y[r] = (inv[r][0] * v[0] + inv[r][1] * v[1] + inv[r][2] * v[2]) / det;
	for (j = 0; j < n; j++)
		qdot[j] = jac[j].x * y[0] + jac[j].y * y[1] + jac[j].z * y[2];
}

/* Compute phase of a follower: the nominal joint velocity (config joint
 * order) that moves the tool (the chain's last frame) towards the remote
 * pose, mapped by the offset caught at engagement and follow_scale.
 * Zero while the remote pose is stale. Returns 1 when following. */
int app_teleop_follow(struct px_app *a, double *qnom)
{
	struct app_teleop *t = &a->tele;
	const struct px_control_chain *ch = &a->ctl.chain;
	const struct px_pose_sample *s;
	px_pose frames[PX_CONTROL_MAX_JOINTS + 1];
	px_vec3 jac[PX_CONTROL_MAX_JOINTS];
	double qc[PX_CONTROL_MAX_JOINTS] = {0}, qd[PX_CONTROL_MAX_JOINTS] = {0};
	double v[3], tool[3], target[3], sp;
	int n = ch->n_joints, i;
	if (t->follow < 0)
		return 0;
	s = &a->sample[t->follow];
	if (!s->valid || s->stale)
		return 1;
	for (i = 0; i < n; i++)
		qc[a->robot ? a->joint_perm[i] : i] = a->q[i];
	if (px_control_chain_fk(ch, qc, frames, PX_CONTROL_MAX_JOINTS + 1) != PX_OK ||
	    px_control_chain_jacobian(ch, qc, n, frames[n].t, jac) != PX_OK)
		return 1;
	tool[0] = frames[n].t.x;
	tool[1] = frames[n].t.y;
	tool[2] = frames[n].t.z;
	if (!t->engaged) {
		t->offset_m[0] = tool[0] - t->c.follow_scale * s->pos_m.x;
		t->offset_m[1] = tool[1] - t->c.follow_scale * s->pos_m.y;
		t->offset_m[2] = tool[2] - t->c.follow_scale * s->pos_m.z;
		t->engaged = 1;
	}
	target[0] = t->offset_m[0] + t->c.follow_scale * s->pos_m.x;
	target[1] = t->offset_m[1] + t->c.follow_scale * s->pos_m.y;
	target[2] = t->offset_m[2] + t->c.follow_scale * s->pos_m.z;
	for (i = 0; i < 3; i++) {
		t->error_m[i] = target[i] - tool[i];
		v[i] = t->c.follow_gain_per_s * t->error_m[i];
	}
	sp = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
	if (sp > t->c.follow_max_speed_m_per_s)
		for (i = 0; i < 3; i++)
			v[i] *= t->c.follow_max_speed_m_per_s / sp;
	for (i = 0; i < 3; i++)
		v[i] *= t->speed_scale;
	dls(jac, n, v, qd);
	for (i = 0; i < n; i++)
		qnom[i] = qd[a->robot ? a->joint_perm[i] : i];
	return 1;
}

/* Compute phase, after the avoidance: the force sent back (from the
 * closest obstacle's clearance: 0 at the influence distance, the
 * maximum at the protective distance, along the normal that opens the
 * clearance), and on a master the remote force added to the rendered
 * one within the renderer's clamp. */
void app_teleop_compute(struct px_app *a)
{
	struct app_teleop *t = &a->tele;
	int i;
	if (t->feedback >= 0) {
		const struct px_control_avoid_params *p = &a->ctl.avoid;
		double c = a->aout.min_clearance_m, w = 0, n[3] = {0, 0, 0}, len;
		px_vec3 pr = {0, 0, 0}, po = {0, 0, 0};
		int k = a->aout.closest_capsule, have = 0;
		if (a->robot_models && a->uout.closest.body >= 0) {
			pr = a->uout.closest.point_robot;
			po = a->uout.closest.point_obstacle;
			have = 1;
		} else if (k >= 0) {
			pr = a->aout.caps[k].point_m;
			po = a->aout.caps[k].obstacle_m;
			have = 1;
		}
		n[0] = pr.x - po.x;
		n[1] = pr.y - po.y;
		n[2] = pr.z - po.z;
		len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
		if (have && a->started && len > 0 && isfinite(c))
			w = (p->influence_distance_m - c) /
			    (p->influence_distance_m - p->protective_distance_m);
		w = w < 0 ? 0 : w > 1 ? 1 : w;
		for (i = 0; i < 3; i++)
			t->fb_cmd.force_n[i] =
				w > 0 ? t->c.feedback_max_force_n * w * n[i] / len : 0;
		t->fb_cmd.enable = 1;
	}
	if (t->force >= 0 && a->rendering) {
		double f[3], m, lim = a->haptic.p.max_force_n;
		for (i = 0; i < 3; i++)
			f[i] = a->cmd.force_n[i] + t->remote_force_n[i];
		m = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
		for (i = 0; i < 3; i++)
			a->cmd.force_n[i] = m > lim ? f[i] * lim / m : f[i];
	}
}

/* Write phase: the feedback command, and control.device's pose to every
 * dds device with a pose_out_topic. */
void app_teleop_write(struct px_app *a, const struct px_loop_cycle *c)
{
	struct app_teleop *t = &a->tele;
	int i;
	if (t->engaged && !c->safe && a->enabled) {
		double e2 = t->error_m[0] * t->error_m[0] +
			    t->error_m[1] * t->error_m[1] +
			    t->error_m[2] * t->error_m[2];
		t->follow_cycles++;
		t->follow_err_sq_sum += e2;
		if (sqrt(e2) > t->follow_err_max_m)
			t->follow_err_max_m = sqrt(e2);
	}
	if (t->feedback >= 0 &&
	    px_dev_force_write(a->dev[t->feedback], &t->fb_cmd, c->write_ns) != PX_OK)
		a->write_errors++;
	if (a->ctl_dev < 0 || !a->sample[a->ctl_dev].valid)
		return;
	for (i = 0; i < t->n_dds; i++)
		if (t->dds[i].pose_out)
			px_bridge_dev_pose_write(a->dev[t->dds[i].dev],
						 &a->sample[a->ctl_dev].pos_m,
						 &a->sample[a->ctl_dev].q);
}

/* ---- the summary --------------------------------------------------------- */

void app_teleop_summary(const struct px_app *a, struct px_app_summary *s)
{
	const struct app_teleop *t = &a->tele;
	int i;
	s->dds_devices = t->n_dds;
	for (i = 0; i < t->n_dds; i++) {
		struct px_bridge_dev_counts n;
		if (px_bridge_dev_counts(a->dev[t->dds[i].dev], &n) != PX_OK)
			continue;
		s->remote_in += n.poses_in + n.wrenches_in;
		s->remote_out += n.commands_out + n.poses_out;
		s->remote_lost += n.lost;
		s->params_accepted += n.params_accepted;
		s->params_refused += n.params_refused;
		s->clouds_accepted += n.clouds_accepted;
		s->clouds_refused += n.clouds_refused;
		s->clouds_dropped += n.clouds_dropped;
		s->scene_poses_accepted += n.scene_poses_accepted;
		s->scene_poses_refused += n.scene_poses_refused;
	}
	s->scene_poses_applied = t->scene_poses_applied;
	s->link_lost = t->link_lost;
	if (t->link_lost) {
		snprintf(s->link_lost_device, sizeof(s->link_lost_device), "%s",
			 px_dev_name(a->dev[t->link_lost_dev]));
		s->link_lost_t_s = (double)(t->link_lost_ns - a->t0_ns) * 1e-9;
		s->link_silent_ns = t->link_silent_ns;
	}
	s->params_applied = t->params_applied;
	s->follow_cycles = t->follow_cycles;
	s->follow_error_max_m = t->follow_err_max_m;
	s->follow_error_rms_m =
		t->follow_cycles ? sqrt(t->follow_err_sq_sum / (double)t->follow_cycles)
				 : 0.0;
}
