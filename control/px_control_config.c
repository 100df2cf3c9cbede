/*
 * The `control` section of a proxima config: schema tables, checks
 * against the rest of the config, and conversion into the renderer,
 * avoidance and chain structs. Every key is documented in docs/config.md
 * (a test checks that).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "control_internal.h"
#include "px_config.h"
#include "schema_internal.h"

#define BIG 1e6

static const char *const mode_names[] = {"none", "haptic", "avoidance", NULL};
static const char *const renderer_names[] = {"penalty", "proxy", NULL};
static const char *const joint_type_names[] = {"revolute", "prismatic", NULL};
static const char *const clearance_names[] = {"auto", "capsules", "models", NULL};

/* ---- raw structs filled by the reader ---------------------------- */

struct raw_pose {
	double xyz_m[3];
	double rpy_rad[3];
};

struct raw_dh {
	double a_m, alpha_rad, d_m, theta_rad;
};

struct raw_joint {
	const char *name;
	int type;
	bool has_dh, has_origin, has_axis;
	struct raw_dh dh;
	struct raw_pose origin;
	double axis[3];
};

struct raw_capsule {
	int64_t link;
	double a_m[3], b_m[3];
	double radius_m;
};

struct raw_haptic {
	int renderer;
	double stiffness_n_per_m, damping_n_s_per_m, proxy_radius_m;
	double static_friction, dynamic_friction;
	bool has_max_force, has_max_rate, has_device_damping;
	double max_force_n, max_force_rate_n_per_s, device_damping_n_s_per_m;
	int64_t max_point_queries;
	double max_query_distance_m;
};

struct raw_avoid {
	const char *urdf, *base_link, *tip_link;
	const char **package_paths;
	size_t n_package_paths;
	const char **urdf_joints;
	size_t n_urdf_joints;
	int clearance;
	bool approach_only, self_clearance;
	struct px_control_link_pair *allowed;
	size_t n_allowed;
	double influence_distance_m, protective_distance_m;
	double self_influence_distance_m, self_protective_distance_m;
	double repulsive_speed_m_per_s, max_joint_velocity_rad_per_s;
	double max_margin_fraction;
	int64_t segment_point_queries;
	double segment_tol_m;
	struct raw_pose base;
	struct raw_joint *joints;
	size_t n_joints;
	struct raw_capsule *capsules;
	size_t n_capsules;
};

struct raw_control {
	int mode;
	const char *device;
	bool has_haptic, has_avoid;
	struct raw_haptic haptic;
	struct raw_avoid avoid;
	/* not keys: context for the checks */
	const struct px_config *cfg_;
	struct px_control_config *out_;
};

/* ---- schemas ------------------------------------------------------ */

static const struct px_config_key pose_keys[] = {
	K_VEC(struct raw_pose, xyz_m, "xyz_m", 0, -BIG, BIG),
	K_VEC(struct raw_pose, rpy_rad, "rpy_rad", 0, -100, 100),
};
SCHEMA(pose_schema, "pose", pose_keys, NULL);

static const struct px_config_key dh_keys[] = {
	K_DBL(struct raw_dh, a_m, "a_m", 0, -BIG, BIG, 0),
	K_DBL(struct raw_dh, alpha_rad, "alpha_rad", 0, -100, 100, 0),
	K_DBL(struct raw_dh, d_m, "d_m", 0, -BIG, BIG, 0),
	K_DBL(struct raw_dh, theta_rad, "theta_rad", 0, -100, 100, 0),
};
SCHEMA(dh_schema, "dh", dh_keys, NULL);

static void joint_check(struct px_config_reader *r,
			const struct px_config_node *map, void *obj)
{
	const struct raw_joint *j = obj;
	if (!map || map->kind != PX_CONFIG_NODE_MAP)
		return;
	if (j->has_dh && j->has_origin)
		px_config_reader_error(r, px_config_node_get(map, "origin"),
				       "origin",
				       "give either dh or origin and axis, "
				       "not both");
	else if (!j->has_dh && !j->has_origin)
		px_config_reader_error(r, map, "",
				       "missing geometry: give dh (a_m, "
				       "alpha_rad, d_m, theta_rad) or origin "
				       "and axis");
	if (j->has_dh && j->has_axis)
		px_config_reader_error(r, px_config_node_get(map, "axis"), "axis",
				       "not allowed with dh (the DH joint axis "
				       "is z)");
	if (j->has_origin && !j->has_axis)
		px_config_reader_error(r, map, "axis",
				       "missing required key (origin is given)");
	if (j->has_axis && sqrt(j->axis[0] * j->axis[0] + j->axis[1] * j->axis[1] +
				j->axis[2] * j->axis[2]) < 1e-9)
		px_config_reader_error(r, px_config_node_get(map, "axis"), "axis",
				       "must not be the zero vector");
}

static const struct px_config_key joint_keys[] = {
	K_STR(struct raw_joint, name, "name", 0),
	K_ENUM(struct raw_joint, type, "type", 0, joint_type_names,
	       PX_CONTROL_REVOLUTE),
	K_SUBP(struct raw_joint, dh, "dh", dh_schema, has_dh),
	K_SUBP(struct raw_joint, origin, "origin", pose_schema, has_origin),
	K_VECPD(struct raw_joint, axis, "axis", 0, -BIG, BIG, 0, has_axis),
};
SCHEMA(joint_schema, "joint", joint_keys, joint_check);

static const struct px_config_key capsule_keys[] = {
	K_INT(struct raw_capsule, link, "link", PX_CONFIG_REQUIRED, 0,
	      PX_CONTROL_MAX_JOINTS, 0),
	K_VEC(struct raw_capsule, a_m, "a_m", PX_CONFIG_REQUIRED, -BIG, BIG),
	K_VEC(struct raw_capsule, b_m, "b_m", PX_CONFIG_REQUIRED, -BIG, BIG),
	K_DBL(struct raw_capsule, radius_m, "radius_m", PX_CONFIG_REQUIRED, 0,
	      100, 0),
};
SCHEMA(capsule_schema, "capsule", capsule_keys, NULL);

static const struct px_config_key link_pair_keys[] = {
	K_STR(struct px_control_link_pair, a, "a", PX_CONFIG_REQUIRED),
	K_STR(struct px_control_link_pair, b, "b", PX_CONFIG_REQUIRED),
};
SCHEMA(link_pair_schema, "link pair", link_pair_keys, NULL);

static const struct px_config_key haptic_keys[] = {
	K_ENUM(struct raw_haptic, renderer, "renderer", 0, renderer_names,
	       PX_CONTROL_PROXY),
	K_DBL(struct raw_haptic, stiffness_n_per_m, "stiffness_n_per_m", 0, 0,
	      1e8, 800.0),
	K_DBL(struct raw_haptic, damping_n_s_per_m, "damping_n_s_per_m", 0, 0,
	      1e6, 1.0),
	K_DBL(struct raw_haptic, proxy_radius_m, "proxy_radius_m",
	      PX_CONFIG_MIN_EXCL, 0, 0.1, 0.0005),
	K_DBL(struct raw_haptic, static_friction, "static_friction", 0, 0, 10,
	      0.0),
	K_DBL(struct raw_haptic, dynamic_friction, "dynamic_friction", 0, 0, 10,
	      0.0),
	K_DBLP(struct raw_haptic, max_force_n, "max_force_n", PX_CONFIG_MIN_EXCL,
	       0, 10000, has_max_force),
	K_DBLP(struct raw_haptic, max_force_rate_n_per_s,
	       "max_force_rate_n_per_s", PX_CONFIG_MIN_EXCL, 0, 1e9,
	       has_max_rate),
	K_DBLP(struct raw_haptic, device_damping_n_s_per_m,
	       "device_damping_n_s_per_m", 0, 0, 1e6, has_device_damping),
	K_INT(struct raw_haptic, max_point_queries, "max_point_queries", 0, 8,
	      1024, 64),
	K_DBL(struct raw_haptic, max_query_distance_m, "max_query_distance_m",
	      PX_CONFIG_MIN_EXCL, 0, 1000, 0.05),
};

static void haptic_check(struct px_config_reader *r,
			 const struct px_config_node *map, void *obj)
{
	const struct raw_haptic *h = obj;
	if (h->dynamic_friction > h->static_friction)
		px_config_reader_error(r, px_config_node_get(map, "dynamic_friction"),
				       "dynamic_friction",
				       "%g is larger than static_friction %g",
				       h->dynamic_friction, h->static_friction);
	if (h->max_query_distance_m <= 2 * h->proxy_radius_m)
		px_config_reader_error(r,
				       px_config_node_get(map, "max_query_distance_m"),
				       "max_query_distance_m",
				       "%g must be more than twice proxy_radius_m "
				       "(%g)",
				       h->max_query_distance_m, h->proxy_radius_m);
}
SCHEMA(haptic_schema, "haptic", haptic_keys, haptic_check);

/* control.avoidance with a URDF: the chain comes from the file (loaded
 * by the runner, which names the file's own line on a refusal), so the
 * typed chain keys are out, and the names must be usable. */
static void urdf_check(struct px_config_reader *r,
		       const struct px_config_node *map, const struct raw_avoid *a)
{
	size_t i, k;
	char p[48];
	if (a->n_joints)
		px_config_reader_error(r, px_config_node_get(map, "joints"), "joints",
				       "give either urdf or joints, not both (the "
				       "URDF's joints between base_link and "
				       "tip_link are the chain)");
	if (!a->tip_link)
		px_config_reader_error(r, map, "tip_link",
				       "missing required key (urdf is given)");
	if (a->clearance == PX_CONTROL_CLEARANCE_CAPSULES && !a->n_capsules)
		px_config_reader_error(r, px_config_node_get(map, "clearance"),
				       "clearance",
				       "'capsules' needs the capsules list");
	if (a->clearance != PX_CONTROL_CLEARANCE_CAPSULES && a->n_capsules)
		px_config_reader_error(r, px_config_node_get(map, "capsules"),
				       "capsules",
				       "used only with clearance: capsules (the "
				       "URDF's collision shapes are measured)");
	for (i = 0; i < a->n_urdf_joints; i++)
		for (k = 0; k < i; k++)
			if (!strcmp(a->urdf_joints[i], a->urdf_joints[k])) {
				const struct px_config_node *s =
					px_config_node_get(map, "urdf_joints");
				snprintf(p, sizeof(p), "urdf_joints[%zu]", i);
				px_config_reader_error(
					r,
					s && s->kind == PX_CONFIG_NODE_SEQ && i < s->len
						? s->items[i]
						: map,
					p, "'%s' is listed twice", a->urdf_joints[i]);
			}
}

static void avoid_check(struct px_config_reader *r,
			const struct px_config_node *map, void *obj)
{
	const struct raw_avoid *a = obj;
	size_t i;
	char p[48];
	if (a->protective_distance_m >= a->influence_distance_m)
		px_config_reader_error(r,
				       px_config_node_get(map, "protective_distance_m"),
				       "protective_distance_m",
				       "%g must be smaller than "
				       "influence_distance_m %g",
				       a->protective_distance_m,
				       a->influence_distance_m);
	if (a->self_protective_distance_m >= a->self_influence_distance_m)
		px_config_reader_error(r,
				       px_config_node_get(map, "self_protective_distance_m"),
				       "self_protective_distance_m",
				       "%g must be smaller than "
				       "self_influence_distance_m %g",
				       a->self_protective_distance_m,
				       a->self_influence_distance_m);
	if (a->urdf)
		urdf_check(r, map, a);
	for (i = 0; !a->urdf && i < a->n_capsules; i++) {
		const struct px_config_node *caps = px_config_node_get(map, "capsules");
		const struct px_config_node *c =
			caps && caps->kind == PX_CONFIG_NODE_SEQ && i < caps->len
				? caps->items[i]
				: map;
		if (a->capsules[i].link > (int64_t)a->n_joints) {
			snprintf(p, sizeof(p), "capsules[%zu].link", i);
			px_config_reader_error(r, px_config_node_get(c, "link") ?
						       px_config_node_get(c, "link") : c,
					       p,
					       "%lld is beyond the last link (%zu "
					       "joints: links 0..%zu)",
					       (long long)a->capsules[i].link,
					       a->n_joints, a->n_joints);
		}
	}
}

static const struct px_config_key avoid_keys[] = {
	K_STR(struct raw_avoid, urdf, "urdf", 0),
	K_STR(struct raw_avoid, base_link, "base_link", 0),
	K_STR(struct raw_avoid, tip_link, "tip_link", 0),
	{.name = "package_paths", .type = PX_CONFIG_T_SEQ,
	 .offset = offsetof(struct raw_avoid, package_paths),
	 .flags = PX_CONFIG_NONEMPTY, .elem = PX_CONFIG_T_STRING,
	 .elem_size = sizeof(const char *),
	 .count_offset = offsetof(struct raw_avoid, n_package_paths),
	 .max_count = PX_CONTROL_MAX_PACKAGE_PATHS},
	{.name = "urdf_joints", .type = PX_CONFIG_T_SEQ,
	 .offset = offsetof(struct raw_avoid, urdf_joints),
	 .flags = PX_CONFIG_NONEMPTY, .elem = PX_CONFIG_T_STRING,
	 .elem_size = sizeof(const char *),
	 .count_offset = offsetof(struct raw_avoid, n_urdf_joints),
	 .min_count = 1, .max_count = PX_CONTROL_MAX_JOINTS},
	K_ENUM(struct raw_avoid, clearance, "clearance", 0, clearance_names,
	       PX_CONTROL_CLEARANCE_AUTO),
	K_BOOL(struct raw_avoid, approach_only, "approach_only", 0),
	K_DBL(struct raw_avoid, self_influence_distance_m, "self_influence_distance_m",
	      PX_CONFIG_MIN_EXCL, 0, 100, 0.05),
	K_DBL(struct raw_avoid, self_protective_distance_m, "self_protective_distance_m",
	      0, 0, 100, 0.01),
	K_BOOL(struct raw_avoid, self_clearance, "self_clearance", 1),
	K_SEQ(struct raw_avoid, allowed, n_allowed, "allowed_collisions", 0,
	      link_pair_schema, struct px_control_link_pair, 0,
	      PX_CONTROL_MAX_ALLOWED),
	K_DBL(struct raw_avoid, influence_distance_m, "influence_distance_m",
	      PX_CONFIG_MIN_EXCL, 0, 100, 0.3),
	K_DBL(struct raw_avoid, protective_distance_m, "protective_distance_m", 0,
	      0, 100, 0.05),
	K_DBL(struct raw_avoid, repulsive_speed_m_per_s,
	      "repulsive_speed_m_per_s", 0, 0, 100, 0.1),
	K_DBL(struct raw_avoid, max_joint_velocity_rad_per_s,
	      "max_joint_velocity_rad_per_s", PX_CONFIG_MIN_EXCL, 0, 1000, 1.0),
	K_DBL(struct raw_avoid, max_margin_fraction, "max_margin_fraction",
	      PX_CONFIG_MIN_EXCL, 0, 1, 0.5),
	K_INT(struct raw_avoid, segment_point_queries, "segment_point_queries",
	      0, 2, PX__CTL_SEG_MAX, 24),
	K_DBL(struct raw_avoid, segment_tol_m, "segment_tol_m", 0, 0, 0.1, 1e-4),
	K_SUB(struct raw_avoid, base, "base", pose_schema),
	K_SEQ(struct raw_avoid, joints, n_joints, "joints", 0, joint_schema,
	      struct raw_joint, 0, PX_CONTROL_MAX_JOINTS),
	K_SEQ(struct raw_avoid, capsules, n_capsules, "capsules", 0,
	      capsule_schema, struct raw_capsule, 0, PX_CONTROL_MAX_CAPSULES),
};
SCHEMA(avoid_schema, "avoidance", avoid_keys, avoid_check);

static px_vec3 v3a(const double *a)
{
	return px_v3(a[0], a[1], a[2]);
}

static const struct px_config_node *path_node(const struct px_config_node *m,
					      const char *a, const char *b)
{
	const struct px_config_node *n = px_config_node_get(m, a), *k;
	if (!n)
		return m;
	k = b ? px_config_node_get(n, b) : NULL;
	return k ? k : n;
}

/* Cross-section checks and the conversion into out_. */
static void control_check(struct px_config_reader *r,
			  const struct px_config_node *map, void *obj)
{
	struct raw_control *c = obj;
	const struct px_config *cfg = c->cfg_;
	struct px_control_config *out = c->out_;
	const struct px_config_device *dev = NULL;
	struct px_control_haptic h;
	size_t i;

	out->mode = c->mode;
	out->device = c->device;
	if (c->mode != PX_CONTROL_MODE_NONE && !c->device)
		px_config_reader_error(r, map, "device",
				       "missing required key (mode is '%s')",
				       mode_names[c->mode]);
	if (c->device) {
		dev = px_config_device_find(cfg, c->device);
		if (!dev)
			px_config_reader_error(r, px_config_node_get(map, "device"),
					       "device",
					       "no device named '%s' in devices",
					       c->device);
	}

	/* Haptic: limits default to, and may not exceed, the safety ones. */
	out->haptic.renderer = c->haptic.renderer;
	out->haptic.stiffness_n_per_m = c->haptic.stiffness_n_per_m;
	out->haptic.damping_n_s_per_m = c->haptic.damping_n_s_per_m;
	out->haptic.proxy_radius_m = c->haptic.proxy_radius_m;
	out->haptic.static_friction = c->haptic.static_friction;
	out->haptic.dynamic_friction = c->haptic.dynamic_friction;
	out->haptic.max_force_n = cfg->safety.max_force_n;
	out->haptic.max_force_rate_n_per_s = cfg->safety.max_force_rate_n_per_s;
	if (c->haptic.has_max_force) {
		if (c->haptic.max_force_n > cfg->safety.max_force_n)
			px_config_reader_error(
				r, path_node(map, "haptic", "max_force_n"),
				"haptic.max_force_n",
				"%g is above safety.max_force_n %g",
				c->haptic.max_force_n, cfg->safety.max_force_n);
		out->haptic.max_force_n = c->haptic.max_force_n;
	}
	if (c->haptic.has_max_rate) {
		if (c->haptic.max_force_rate_n_per_s >
		    cfg->safety.max_force_rate_n_per_s)
			px_config_reader_error(
				r, path_node(map, "haptic", "max_force_rate_n_per_s"),
				"haptic.max_force_rate_n_per_s",
				"%g is above safety.max_force_rate_n_per_s %g",
				c->haptic.max_force_rate_n_per_s,
				cfg->safety.max_force_rate_n_per_s);
		out->haptic.max_force_rate_n_per_s =
			c->haptic.max_force_rate_n_per_s;
	}
	/* A simulated device states its damping; a real one must be told. */
	out->haptic.device_damping_n_s_per_m = 0;
	if (c->haptic.has_device_damping)
		out->haptic.device_damping_n_s_per_m =
			c->haptic.device_damping_n_s_per_m;
	else if (dev && dev->backend == PX_CONFIG_BACKEND_SIM &&
		 dev->sim.kind == PX_CONFIG_SIM_HAPTIC)
		out->haptic.device_damping_n_s_per_m = dev->sim.damping_n_s_per_m;
	out->haptic.max_point_queries = (int)c->haptic.max_point_queries;
	out->haptic.max_query_distance_m = c->haptic.max_query_distance_m;

	/* Avoidance. */
	out->avoid.influence_distance_m = c->avoid.influence_distance_m;
	out->avoid.protective_distance_m = c->avoid.protective_distance_m;
	out->avoid.repulsive_speed_m_per_s = c->avoid.repulsive_speed_m_per_s;
	out->avoid.max_joint_velocity = c->avoid.max_joint_velocity_rad_per_s;
	out->avoid.max_margin_fraction = c->avoid.max_margin_fraction;
	out->avoid.segment_point_queries = (int)c->avoid.segment_point_queries;
	out->avoid.segment_tol_m = c->avoid.segment_tol_m;
	out->avoid.approach_only = c->avoid.approach_only;
	out->avoid.self_influence_distance_m = c->avoid.self_influence_distance_m;
	out->avoid.self_protective_distance_m = c->avoid.self_protective_distance_m;
	out->urdf.path = c->avoid.urdf;
	out->urdf.base_link = c->avoid.base_link;
	out->urdf.tip_link = c->avoid.tip_link;
	out->urdf.package_paths = c->avoid.package_paths;
	out->urdf.n_package_paths = c->avoid.n_package_paths;
	out->urdf.joints = c->avoid.urdf_joints;
	out->urdf.n_joints = c->avoid.n_urdf_joints;
	out->urdf.clearance = c->avoid.clearance == PX_CONTROL_CLEARANCE_AUTO
				      ? (c->avoid.urdf ? PX_CONTROL_CLEARANCE_MODELS
						       : PX_CONTROL_CLEARANCE_CAPSULES)
				      : c->avoid.clearance;
	out->urdf.self_clearance = c->avoid.self_clearance;
	out->urdf.allowed = c->avoid.allowed;
	out->urdf.n_allowed = c->avoid.n_allowed;
	if (!c->avoid.urdf && c->avoid.clearance == PX_CONTROL_CLEARANCE_MODELS)
		px_config_reader_error(r, path_node(map, "avoidance", "clearance"),
				       "avoidance.clearance",
				       "'models' needs urdf (the link models "
				       "come from its collision shapes)");
	px_control_chain_init(&out->chain,
			      px_control_pose_from_xyz_rpy(
				      v3a(c->avoid.base.xyz_m),
				      v3a(c->avoid.base.rpy_rad)));
	for (i = 0; i < c->avoid.n_joints; i++) {
		const struct raw_joint *j = &c->avoid.joints[i];
		if (j->has_dh && !j->has_origin)
			px_control_chain_add_dh(&out->chain, j->type, j->dh.a_m,
						j->dh.alpha_rad, j->dh.d_m,
						j->dh.theta_rad);
		else if (j->has_origin && j->has_axis &&
			 px_control_chain_add_joint(
				 &out->chain, j->type,
				 px_control_pose_from_xyz_rpy(v3a(j->origin.xyz_m),
							      v3a(j->origin.rpy_rad)),
				 v3a(j->axis)) == PX_OK)
			;
		else
			px_control_chain_add_dh(&out->chain, j->type, 0, 0, 0, 0);
	}
	for (i = 0; i < c->avoid.n_capsules; i++) {
		const struct raw_capsule *cp = &c->avoid.capsules[i];
		px_control_chain_add_capsule(&out->chain, (int)cp->link,
					     v3a(cp->a_m), v3a(cp->b_m),
					     cp->radius_m);
	}
	if (c->mode == PX_CONTROL_MODE_AVOIDANCE && !c->avoid.urdf) {
		if (c->avoid.n_joints == 0)
			px_config_reader_error(r, path_node(map, "avoidance", NULL),
					       "avoidance.joints",
					       "mode avoidance needs at least "
					       "one joint");
		if (c->avoid.n_capsules == 0)
			px_config_reader_error(r, path_node(map, "avoidance", NULL),
					       "avoidance.capsules",
					       "mode avoidance needs at least "
					       "one capsule");
	}
	if (c->mode == PX_CONTROL_MODE_AVOIDANCE) {
		/* Joint positions come from the device's drives (with a URDF
		 * and no urdf_joints the count is known once it is read: the
		 * runner checks then). */
		size_t nj = c->avoid.urdf ? c->avoid.n_urdf_joints : c->avoid.n_joints;
		if (dev && (!c->avoid.urdf || nj) &&
		    dev->backend == PX_CONFIG_BACKEND_SOCKETCAN &&
		    dev->socketcan.canopen.present) {
			for (i = 0; i < dev->socketcan.canopen.n_drives; i++)
				if (dev->socketcan.canopen.drives[i].joint >=
				    (int64_t)nj)
					px_config_reader_error(
						r, px_config_node_get(map, "device"),
						"device",
						"drive with node_id %lld of device "
						"'%s' feeds joint %lld, but "
						"avoidance.%s has %zu joints",
						(long long)dev->socketcan.canopen
							.drives[i].node_id,
						c->device,
						(long long)dev->socketcan.canopen
							.drives[i].joint,
						c->avoid.urdf ? "urdf_joints" : "joints",
						nj);
		}
	}

	/* Stability of the haptic setting at the loop period. */
	out->stable = true;
	out->stiffness_limit_n_per_m = 0;
	out->warning[0] = '\0';
	if (c->mode == PX_CONTROL_MODE_HAPTIC &&
	    px_control_haptic_init(&h, &out->haptic, cfg->loop.period_ns) ==
		    PX_OK) {
		const struct px_config_node *k =
			path_node(map, "haptic", "stiffness_n_per_m");
		char why[400];
		out->stable = h.stable;
		out->stiffness_limit_n_per_m = h.stiffness_limit_n_per_m;
		if (!h.stable && px_control_haptic_warning(&h, why, sizeof(why)) > 0)
			snprintf(out->warning, sizeof(out->warning),
				 "%s:%d:%d: control.haptic.stiffness_n_per_m: "
				 "warning: %.380s",
				 k && k->file ? k->file : "<config>",
				 k ? k->line : 0, k ? k->column : 0, why);
	}
}

static const struct px_config_key control_keys[] = {
	K_ENUM(struct raw_control, mode, "mode", 0, mode_names,
	       PX_CONTROL_MODE_NONE),
	K_STR(struct raw_control, device, "device", 0),
	K_SUBP(struct raw_control, haptic, "haptic", haptic_schema, has_haptic),
	K_SUBP(struct raw_control, avoid, "avoidance", avoid_schema, has_avoid),
};
SCHEMA(control_schema, "control", control_keys, control_check);

const struct px_config_schema *px_control_config_schema(void)
{
	return &control_schema;
}

int px_control_config_read(const struct px_config *cfg,
			   struct px_control_config *out,
			   struct px_config_diag *diag)
{
	struct raw_control raw;
	int rc;
	if (!cfg || !out || !cfg->doc)
		return PX_E_INVAL;
	memset(out, 0, sizeof(*out));
	memset(&raw, 0, sizeof(raw));
	raw.cfg_ = cfg;
	raw.out_ = out;
	rc = px_config_read(cfg->doc, cfg->control, "control", &control_schema,
			    &raw, diag);
	return rc;
}
