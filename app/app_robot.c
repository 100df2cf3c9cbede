/* The app's URDF robot (control.avoidance.urdf): loading and checking
 * it at setup, its link models against the scene's models, and its
 * avoidance command in the cycle (real-time rules there). */
#include "app_internal.h"

/* The node of control.avoidance.KEY, else control.avoidance. */
static const struct px_config_node *avoid_node(struct px_app *a, const char *key)
{
	const struct px_config_node *av =
		px_config_node_get(app_cfg_node(a, "control", NULL), "avoidance");
	const struct px_config_node *k = key ? px_config_node_get(av, key) : NULL;
	return k ? k : av;
}

/* Config joint i (drives' joint: i) -> chain joint perm[i]. */
static int joint_map(struct px_app *a, const struct px_urdf_robot *r)
{
	const struct px_control_urdf_config *u = &a->ctl.urdf;
	int dof = px_urdf_robot_dof(r), i, k, bad = 0;
	if (!u->n_joints) {
		for (i = 0; i < dof; i++)
			a->joint_perm[i] = i;
		return 0;
	}
	if ((int)u->n_joints != dof) {
		app_check_error(a, avoid_node(a, "urdf_joints"), "control.avoidance.urdf_joints",
				"lists %zu joints; the chain from '%s' to '%s' has %d "
				"movable joints",
				u->n_joints, u->base_link ? u->base_link : "(root)",
				u->tip_link, dof);
		return 1;
	}
	for (i = 0; i < dof; i++) {
		for (k = 0; k < dof; k++)
			if (!strcmp(u->joints[i], px_urdf_robot_joint_name(r, k)))
				break;
		if (k == dof) {
			const struct px_config_node *s = avoid_node(a, "urdf_joints");
			char key[64];
			snprintf(key, sizeof(key), "control.avoidance.urdf_joints[%d]", i);
			app_check_error(a,
					s && s->kind == PX_CONFIG_NODE_SEQ && (size_t)i < s->len
						? s->items[i]
						: s,
					key,
					"'%s' is no movable joint of the chain from "
					"'%s' to '%s'",
					u->joints[i], u->base_link ? u->base_link : "(root)",
					u->tip_link);
			bad = 1;
			continue;
		}
		a->joint_perm[i] = k;
	}
	return bad;
}

/* Drives feed joints 0..dof-1; capsules ride on frames 0..dof. */
static int check_indices(struct px_app *a, int dof)
{
	const struct px_config_device *d = a->ctl.device
		? px_config_device_find(a->cfg, a->ctl.device) : NULL;
	size_t i;
	int bad = 0;
	if (d && d->backend == PX_CONFIG_BACKEND_SOCKETCAN &&
	    d->socketcan.canopen.present && !a->ctl.urdf.n_joints)
		for (i = 0; i < d->socketcan.canopen.n_drives; i++)
			if (d->socketcan.canopen.drives[i].joint >= dof) {
				app_check_error(a, app_cfg_node(a, "control", "device"),
						"control.device",
						"drive with node_id %lld of device '%s' "
						"feeds joint %lld, but the URDF chain has "
						"%d movable joints",
						(long long)d->socketcan.canopen.drives[i].node_id,
						d->name,
						(long long)d->socketcan.canopen.drives[i].joint,
						dof);
				bad = 1;
			}
	for (i = 0; i < (size_t)a->ctl.chain.n_capsules; i++)
		if (a->ctl.chain.capsules[i].link > dof) {
			char key[64];
			snprintf(key, sizeof(key), "control.avoidance.capsules[%zu].link", i);
			app_check_error(a, avoid_node(a, "capsules"), key,
					"%d is beyond the last link (the URDF chain "
					"has %d joints: links 0..%d)",
					a->ctl.chain.capsules[i].link, dof, dof);
			bad = 1;
		}
	return bad;
}

/* The scene's models, and extra (may be NULL) after them, are the
 * robot's obstacles. */
int app_robot_obstacles(struct px_app *a, struct px_model *extra)
{
	struct px_model **ob;
	size_t n = a->scene ? px_scene_count(a->scene) : 0, i;
	int rc;
	ob = calloc(n + 2, sizeof(*ob));
	if (!ob) {
		app_note(a, "%s: URDF robot: out of memory\n", app_name(a));
		return 1;
	}
	for (i = 0; i < n; i++)
		ob[i] = px_scene_model(a->scene, i);
	if (extra)
		ob[n] = extra;
	a->n_scene_obstacles = (int)n;
	rc = px_urdf_robot_set_obstacles(a->robot, ob, (int)n + (extra != NULL));
	free(ob);
	if (rc) {
		app_note(a, "%s: URDF robot: obstacles: %s\n", app_name(a), px_strerror(rc));
		return 1;
	}
	return 0;
}

/* The scene's models are the obstacles; the self pairs skip the
 * allowed list. */
static int robot_pairs(struct px_app *a, struct px_urdf_robot *r)
{
	const struct px_control_urdf_config *u = &a->ctl.urdf;
	const char **al;
	struct px_urdf_error err;
	size_t i;
	int rc = app_robot_obstacles(a, NULL);
	if (rc || !u->self_clearance)
		return rc;
	al = calloc(2 * u->n_allowed + 1, sizeof(*al));
	if (!al) {
		app_note(a, "%s: URDF robot: out of memory\n", app_name(a));
		return 1;
	}
	for (i = 0; i < u->n_allowed; i++) {
		al[2 * i] = u->allowed[i].a;
		al[2 * i + 1] = u->allowed[i].b;
	}
	rc = px_urdf_robot_set_self(r, al, (int)u->n_allowed, &err);
	if (rc == PX_E_NOTFOUND)
		app_check_error(a, avoid_node(a, "allowed_collisions"),
				"control.avoidance.allowed_collisions", "%s", err.msg);
	else if (rc < 0)
		app_note(a, "%s: URDF robot: self pairs: %s\n", app_name(a), px_strerror(rc));
	free(al);
	return rc < 0;
}

int app_robot_setup(struct px_app *a)
{
	const struct px_control_urdf_config *u = &a->ctl.urdf;
	char path[1024], pk[PX_CONTROL_MAX_PACKAGE_PATHS][1024];
	const char *pkp[PX_CONTROL_MAX_PACKAGE_PATHS];
	struct px_urdf_opts uo;
	struct px_urdf_error err;
	struct px_urdf *doc = NULL;
	struct px_control_chain caps = a->ctl.chain;
	size_t i;
	int rc;
	if (a->ctl.mode != PX_CONTROL_MODE_AVOIDANCE || !u->path)
		return 0;
	app_config_dir_path(path, sizeof(path), a->o.config, u->path);
	for (i = 0; i < u->n_package_paths && i < PX_CONTROL_MAX_PACKAGE_PATHS; i++) {
		app_config_dir_path(pk[i], sizeof(pk[i]), a->o.config, u->package_paths[i]);
		pkp[i] = pk[i];
	}
	memset(&uo, 0, sizeof(uo));
	uo.package_paths = pkp;
	uo.n_package_paths = (int)i;
	rc = px_urdf_load(path, &uo, &doc, &err);
	if (rc != PX_OK) {
		app_check_error(a, avoid_node(a, "urdf"), "control.avoidance.urdf", "%s",
				err.msg[0] ? err.msg : px_strerror(rc));
		return 1;
	}
	rc = px_urdf_robot_create(doc, u->base_link, u->tip_link, a->ctl.chain.base,
				  &a->robot, &err);
	px_urdf_free(doc);
	if (rc != PX_OK) {
		const char *key = u->base_link && strstr(err.msg, u->base_link) &&
					  !strstr(err.msg, u->tip_link)
				  ? "base_link" : "tip_link";
		char k[64];
		snprintf(k, sizeof(k), "control.avoidance.%s", key);
		app_check_error(a, avoid_node(a, key), k, "%s",
				err.msg[0] ? err.msg : px_strerror(rc));
		return 1;
	}
	/* the chain is the URDF's, the capsules (clearance: capsules) the
	 * config's */
	a->ctl.chain = *px_urdf_robot_chain(a->robot);
	for (i = 0; i < (size_t)caps.n_capsules; i++)
		a->ctl.chain.capsules[i] = caps.capsules[i];
	a->ctl.chain.n_capsules = caps.n_capsules;
	if (joint_map(a, a->robot) | check_indices(a, px_urdf_robot_dof(a->robot)))
		return 1;
	a->robot_models = u->clearance == PX_CONTROL_CLEARANCE_MODELS;
	return a->robot_models ? robot_pairs(a, a->robot) : 0;
}

void app_robot_free(struct px_app *a)
{
	px_urdf_robot_free(a->robot);
	a->robot = NULL;
}

/* ---- the cycle (real-time rules) ----------------------------------- */

int app_robot_step(struct px_app *a, const double *qnom, int64_t period_ns)
{
	double qc[PX_CONTROL_MAX_JOINTS] = {0}, qn[PX_CONTROL_MAX_JOINTS] = {0};
	int n = a->ctl.chain.n_joints, i, rc;
	for (i = 0; i < n; i++) {
		qc[a->joint_perm[i]] = a->q[i];
		qn[a->joint_perm[i]] = qnom[i];
	}
	if (a->robot_models)
		rc = px_urdf_avoid_step(a->robot, &a->ctl.avoid, NULL, 1, qc, qn,
					period_ns, &a->uout);
	else
		rc = px_control_avoid_step(&a->ctl.chain, &a->ctl.avoid, &a->query,
					   qc, qn, period_ns, &a->uout.cmd);
	a->aout = a->uout.cmd;
	for (i = 0; i < n; i++)
		a->aout.qdot[i] = a->uout.cmd.qdot[a->joint_perm[i]];
	return rc;
}
