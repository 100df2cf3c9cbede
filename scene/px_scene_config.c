/*
 * The `scene` section of a proxima config: schema, model files (meshes,
 * clouds, NURBS OBJ, STEP/IGES parts), inline primitives, poses and scale. Every key is
 * documented in docs/config.md (a test checks that).
 */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "px_cloud.h"
#include "px_config.h"
#include "px_control.h"
#include "px_dist.h"
#include "px_load.h"
#include "px_mesh.h"
#include "px_prim.h"
#include "px_scene.h"
#include "schema_internal.h"

#define BIG 1e6
#define LIST_MAX 256 /* models and primitives each (docs/config.md) */

enum file_kind { KIND_MESH = 0, KIND_NURBS = 1, KIND_CLOUD = 2, KIND_CAD = 3 };
static const char *const kind_names[] = {"mesh", "nurbs", "cloud", "cad", NULL};
static const char *const prim_names[] = {"sphere",   "box",  "capsule",
					 "cylinder", "cone", "torus",
					 "halfspace", NULL};
static const enum px_prim_type prim_types[] = {
	PX_PRIM_SPHERE, PX_PRIM_BOX,   PX_PRIM_CAPSULE,  PX_PRIM_CYLINDER,
	PX_PRIM_CONE,   PX_PRIM_TORUS, PX_PRIM_HALFSPACE};

struct raw_pose {
	double xyz_m[3];
	double rpy_rad[3];
};

struct raw_model {
	const char *name;
	const char *file;
	int kind;
	struct raw_pose pose;
	double scale;
	bool has_cloud_radius;
	double cloud_radius_m;
};

struct raw_prim {
	const char *name;
	int type;
	struct raw_pose pose;
	bool has_radius, has_half_extents, has_half_height, has_top_radius,
		has_tube_radius;
	double radius_m, half_extents_m[3], half_height_m, top_radius_m,
		tube_radius_m;
};

struct raw_tracking {
	bool enabled;
	int64_t verify_every;
	int64_t max_solves;
	bool cold_switch;
};

struct raw_scene {
	struct raw_model *models;
	size_t n_models;
	struct raw_prim *prims;
	size_t n_prims;
	struct raw_tracking tracking;
	/* not keys: context for the check */
	const struct px_config *cfg_;
	const struct px_config_diag *diag_;
	int errors_before_;
	struct px_scene *scene_;
	int failed_;
};

static const struct px_config_key pose_keys[] = {
	K_VEC(struct raw_pose, xyz_m, "xyz_m", 0, -BIG, BIG),
	K_VEC(struct raw_pose, rpy_rad, "rpy_rad", 0, -100, 100),
};
SCHEMA(pose_schema, "pose", pose_keys, NULL);

static const struct px_config_key model_keys[] = {
	K_STR(struct raw_model, name, "name", 0),
	K_STR(struct raw_model, file, "file", PX_CONFIG_REQUIRED),
	K_ENUM(struct raw_model, kind, "kind", PX_CONFIG_REQUIRED, kind_names,
	       KIND_MESH),
	K_SUB(struct raw_model, pose, "pose", pose_schema),
	/* below 1e-9 a query 1e141 m off would map past the models' reach
	 * in the file's own units and fail in the loop */
	K_DBL(struct raw_model, scale, "scale", 0, 1e-9, 1e6, 1.0),
	K_DBLP(struct raw_model, cloud_radius_m, "cloud_radius_m", 0, 0, 100,
	       has_cloud_radius),
};

static void model_check(struct px_config_reader *r,
			const struct px_config_node *map, void *obj)
{
	const struct raw_model *m = obj;
	if (m->has_cloud_radius && m->kind != KIND_CLOUD)
		px_config_reader_error(r, px_config_node_get(map, "cloud_radius_m"),
				       "cloud_radius_m",
				       "only for kind 'cloud' (kind is '%s')",
				       kind_names[m->kind]);
}
SCHEMA(model_schema, "model", model_keys, model_check);

static const struct px_config_key prim_keys[] = {
	K_STR(struct raw_prim, name, "name", 0),
	K_ENUM(struct raw_prim, type, "type", PX_CONFIG_REQUIRED, prim_names, 0),
	K_SUB(struct raw_prim, pose, "pose", pose_schema),
	K_DBLP(struct raw_prim, radius_m, "radius_m", PX_CONFIG_MIN_EXCL, 0, BIG,
	       has_radius),
	K_VECP(struct raw_prim, half_extents_m, "half_extents_m",
	       PX_CONFIG_MIN_EXCL, 0, BIG, has_half_extents),
	K_DBLP(struct raw_prim, half_height_m, "half_height_m",
	       PX_CONFIG_MIN_EXCL, 0, BIG, has_half_height),
	K_DBLP(struct raw_prim, top_radius_m, "top_radius_m", 0, 0, BIG,
	       has_top_radius),
	K_DBLP(struct raw_prim, tube_radius_m, "tube_radius_m",
	       PX_CONFIG_MIN_EXCL, 0, BIG, has_tube_radius),
};

/* Which dimension keys each type takes: bit 0 radius_m, 1
 * half_extents_m, 2 half_height_m, 3 top_radius_m, 4 tube_radius_m;
 * required ones, allowed ones. */
static const unsigned prim_required[] = {0x1, 0x2, 0x5, 0x5, 0x5, 0x11, 0};
static const unsigned prim_allowed[] = {0x1, 0x2, 0x5, 0x5, 0xd, 0x11, 0};
static const char *const dim_names[] = {"radius_m", "half_extents_m",
					"half_height_m", "top_radius_m",
					"tube_radius_m"};

static void prim_check(struct px_config_reader *r,
		       const struct px_config_node *map, void *obj)
{
	const struct raw_prim *p = obj;
	unsigned given = (p->has_radius ? 1u : 0) | (p->has_half_extents ? 2u : 0) |
			 (p->has_half_height ? 4u : 0) |
			 (p->has_top_radius ? 8u : 0) |
			 (p->has_tube_radius ? 16u : 0);
	int k;
	if (p->type < 0 || p->type >= (int)(sizeof(prim_types) / sizeof(prim_types[0])))
		return;
	for (k = 0; k < 5; k++) {
		unsigned bit = 1u << k;
		if ((prim_required[p->type] & bit) && !(given & bit))
			px_config_reader_error(r, map, dim_names[k],
					       "missing required key for type "
					       "'%s'",
					       prim_names[p->type]);
		else if ((given & bit) && !(prim_allowed[p->type] & bit))
			px_config_reader_error(r, px_config_node_get(map, dim_names[k]),
					       dim_names[k],
					       "not used by type '%s'",
					       prim_names[p->type]);
	}
}
SCHEMA(prim_schema, "primitive", prim_keys, prim_check);

static void scene_check(struct px_config_reader *r,
			const struct px_config_node *map, void *obj);

static const struct px_config_key tracking_keys[] = {
	K_BOOL(struct raw_tracking, enabled, "enabled", 1),
	K_INT(struct raw_tracking, verify_every, "verify_every", 0, 0, 1000000, 0),
	K_INT(struct raw_tracking, max_solves, "max_solves", 0, 0, 1000, 4),
	K_BOOL(struct raw_tracking, cold_switch, "cold_switch", 1),
};
SCHEMA(tracking_schema, "tracking", tracking_keys, NULL);

static const struct px_config_key scene_keys[] = {
	K_SEQ(struct raw_scene, models, n_models, "models", 0, model_schema,
	      struct raw_model, 0, LIST_MAX),
	K_SEQ(struct raw_scene, prims, n_prims, "primitives", 0, prim_schema,
	      struct raw_prim, 0, LIST_MAX),
	K_SUB(struct raw_scene, tracking, "tracking", tracking_schema),
};
SCHEMA(scene_schema, "scene", scene_keys, scene_check);

const struct px_config_schema *px_scene_config_schema(void)
{
	return &scene_schema;
}

/* ---- uniform scale around the model origin ------------------------ */

/* A model seen at scale s: distance(p) = s * distance_inner(p / s). The
 * inner model keeps the identity pose; the wrapper carries the pose. */
struct scaled {
	struct px_model *inner;
	double s;
};

static int scaled_closest(const void *impl, const struct px_model_query *q,
			  struct px_model_result *r)
{
	const struct scaled *w = impl;
	double md = isinf(q->max_dist) ? q->max_dist : q->max_dist / w->s;
	int rc = px_model_query_ex(w->inner, px_v3_scale(q->p, 1 / w->s), md,
				   q->hint, q->flags, r);
	if (rc == 1) {
		r->distance *= w->s;
		r->gap *= w->s;
		r->point = px_v3_scale(r->point, w->s);
	}
	return rc;
}

/* Streams through the wrapper follow the point in the inner model's
 * frame (inner models without streams say PX_E_UNSUPPORTED). */
static int scaled_stream_create(const void *impl,
				const struct px_model_stream_opts *o,
				void **state)
{
	const struct scaled *w = impl;
	return px_model_stream_create(w->inner, o,
				      (struct px_model_stream **)state);
}

static int scaled_stream_query(const void *impl, void *state,
			       const struct px_model_query *q,
			       struct px_model_result *r,
			       struct px_model_stream_note *note)
{
	const struct scaled *w = impl;
	double md = isinf(q->max_dist) ? q->max_dist : q->max_dist / w->s;
	int rc = px_model_stream_query(state, px_v3_scale(q->p, 1 / w->s), md,
				       q->flags, r, note);
	if (rc == 1) {
		r->distance *= w->s;
		r->gap *= w->s;
		r->point = px_v3_scale(r->point, w->s);
	}
	return rc;
}

static void scaled_stream_stats(const void *state,
				struct px_model_stream_stats *st)
{
	px_model_stream_get_stats(state, st);
}

static void scaled_stream_free(void *state)
{
	px_model_stream_free(state);
}

static px_aabb scaled_aabb(const void *impl)
{
	const struct scaled *w = impl;
	px_aabb b = px_model_local_aabb(w->inner);
	if (!px_aabb_is_empty(&b)) {
		b.min = px_v3_scale(b.min, w->s);
		b.max = px_v3_scale(b.max, w->s);
	}
	return b;
}

static size_t scaled_bytes(const void *impl)
{
	const struct scaled *w = impl;
	return sizeof(*w) + px_model_memory_bytes(w->inner);
}

static void scaled_free(void *impl)
{
	struct scaled *w = impl;
	if (w)
		px_model_free(w->inner);
	free(w);
}

#define SCALED_OPS(k)                                                       \
	{.name = "scaled", .kind = k, .closest = scaled_closest,              \
	 .aabb = scaled_aabb, .memory_bytes = scaled_bytes, .free = scaled_free, \
	 .stream_create = scaled_stream_create,                               \
	 .stream_query = scaled_stream_query,                                 \
	 .stream_stats = scaled_stream_stats,                                 \
	 .stream_free = scaled_stream_free}
static const struct px_model_ops scaled_ops[] = {
	SCALED_OPS(PX_MODEL_CUSTOM),    SCALED_OPS(PX_MODEL_PRIMITIVE),
	SCALED_OPS(PX_MODEL_MESH),      SCALED_OPS(PX_MODEL_CLOUD),
	SCALED_OPS(PX_MODEL_NURBS),     SCALED_OPS(PX_MODEL_CUSTOM),
	SCALED_OPS(PX_MODEL_BREP),
};

static int scale_model(struct px_model **m, double s)
{
	struct scaled *w;
	int k = px_model_kind(*m);
	if (s == 1.0)
		return PX_OK;
	w = calloc(1, sizeof(*w));
	if (!w) {
		px_model_free(*m);
		*m = NULL;
		return PX_E_NOMEM;
	}
	w->inner = *m;
	w->s = s;
	*m = NULL;
	/* Coherence hints are passed through, so the capability stays. */
	return px_model_create(&scaled_ops[k >= 1 && k <= PX_MODEL_BREP ? k : 0], w,
			       px_model_caps(w->inner), m);
}

double px_scene_model_scale(const struct px_model *m,
			    const struct px_model **inner)
{
	const struct px_model_ops *o = px_model_get_ops(m);
	const struct scaled *w;
	if (!o || o < scaled_ops ||
	    o >= scaled_ops + sizeof(scaled_ops) / sizeof(scaled_ops[0])) {
		*inner = m;
		return 1.0;
	}
	w = px_model_impl(m);
	*inner = w->inner;
	return w->s;
}

/* ---- loading ------------------------------------------------------ */

static void resolve(char *out, size_t cap, const char *cfg_path,
		    const char *file)
{
	const char *slash = cfg_path ? strrchr(cfg_path, '/') : NULL;
	if (file[0] == '/' || !slash)
		snprintf(out, cap, "%s", file);
	else
		snprintf(out, cap, "%.*s/%s", (int)(slash - cfg_path), cfg_path,
			 file);
}

/* kind nurbs: an OBJ's curves and surfaces (a B-rep when trimmed). */
static int load_nurbs(const char *path, struct px_model **out, char *msg,
		      size_t cap)
{
	int rc = px_model_load_obj(path, out, msg, cap);
	if (rc == PX_OK && px_model_kind(*out) == PX_MODEL_MESH) {
		px_model_free(*out);
		*out = NULL;
		snprintf(msg, cap,
			 "%.256s: no curves or surfaces in the file (polygon "
			 "faces: use kind 'mesh')",
			 path);
		return PX_E_PARSE;
	}
	return rc;
}

static int load_model(const struct raw_model *m, const char *path,
		      struct px_model **out, char *msg, size_t cap)
{
	int rc;
	msg[0] = '\0';
	*out = NULL;
	if (m->kind == KIND_MESH) {
		struct px_mesh_report rep;
		memset(&rep, 0, sizeof(rep));
		rc = px_mesh_load(path, NULL, &rep, out);
		if (rc != PX_OK)
			snprintf(msg, cap, "%.500s",
				 rep.message[0] ? rep.message : px_strerror(rc));
	} else if (m->kind == KIND_CLOUD) {
		struct px_cloud_report rep;
		memset(&rep, 0, sizeof(rep));
		rc = px_cloud_load(path, m->has_cloud_radius ? m->cloud_radius_m : 0,
				   &rep, out);
		if (rc != PX_OK)
			snprintf(msg, cap, "%.500s",
				 rep.message[0] ? rep.message : px_strerror(rc));
	} else if (m->kind == KIND_CAD) {
		/* the scale goes into the B-rep itself (exact, no wrapper):
		 * it multiplies the importer's metres */
		rc = px_model_load_cad(path, m->scale, out, msg, cap);
		/* a warning (open part) is no error */
		if (rc == PX_OK)
			return PX_OK;
	} else {
		rc = load_nurbs(path, out, msg, cap);
	}
	if (rc == PX_OK)
		rc = scale_model(out, m->scale);
	if (rc != PX_OK && !msg[0])
		snprintf(msg, cap, "%.256s: %s", path, px_strerror(rc));
	return rc;
}

static px_pose raw_pose(const struct raw_pose *p)
{
	return px_control_pose_from_xyz_rpy(
		px_v3(p->xyz_m[0], p->xyz_m[1], p->xyz_m[2]),
		px_v3(p->rpy_rad[0], p->rpy_rad[1], p->rpy_rad[2]));
}

static const struct px_config_node *item(const struct px_config_node *map,
					 const char *key, size_t i)
{
	const struct px_config_node *s = px_config_node_get(map, key);
	return s && s->kind == PX_CONFIG_NODE_SEQ && i < s->len ? s->items[i] : map;
}

static void add_model(struct px_config_reader *r, struct raw_scene *sc,
		      struct px_model *m, px_pose pose, const char *name,
		      const struct px_config_node *at, const char *where)
{
	int rc = px_model_set_pose(m, pose);
	px_aabb b = px_model_local_aabb(m);
	double reach;
	if (rc != PX_OK) {
		px_model_free(m);
		px_config_reader_error(r, at, where, "bad pose: %s",
				       px_strerror(rc));
		sc->failed_ = 1;
		return;
	}
	/* after the scale: the box the scene's distance bounds square */
	reach = px_aabb_is_empty(&b) ? 0.0
		: fmax(fmax(fabs(b.min.x), fabs(b.max.x)),
		       fmax(fmax(fabs(b.min.y), fabs(b.max.y)),
			    fmax(fabs(b.min.z), fabs(b.max.z))));
	if (!(reach <= PX_MODEL_MAX_COORD) && !isinf(reach)) {
		px_model_free(m);
		px_config_reader_error(r, at, where,
				       "the model's extent reaches %g, beyond "
				       "+-%g after its scale (squared distances "
				       "would overflow)", reach, PX_MODEL_MAX_COORD);
		sc->failed_ = 1;
		return;
	}
	rc = px_scene_add(sc->scene_, m, name);
	if (rc < 0) {
		px_config_reader_error(r, at, where, "cannot add: %s",
				       px_strerror(rc));
		sc->failed_ = 1;
	}
}

static void scene_check(struct px_config_reader *r,
			const struct px_config_node *map, void *obj)
{
	struct raw_scene *sc = obj;
	size_t i, total = sc->n_models + sc->n_prims;
	char where[64], path[4096], msg[600];
	int rc;
	/* Keys already wrong: do not read files on half-read values. */
	if (px_config_diag_total(sc->diag_) != sc->errors_before_) {
		sc->failed_ = 1;
		return;
	}
	rc = px_scene_create(total ? total : 1, &sc->scene_);
	if (rc != PX_OK) {
		px_config_reader_error(r, map, "", "%s", px_strerror(rc));
		sc->failed_ = 1;
		return;
	}
	for (i = 0; i < sc->n_models; i++) {
		const struct raw_model *m = &sc->models[i];
		const struct px_config_node *it = item(map, "models", i);
		const struct px_config_node *fn = px_config_node_get(it, "file");
		struct px_model *mod;
		if (!m->file)
			continue;
		resolve(path, sizeof(path), px_config_doc_name(sc->cfg_->doc),
			m->file);
		snprintf(where, sizeof(where), "models[%zu].file", i);
		rc = load_model(m, path, &mod, msg, sizeof(msg));
		if (rc != PX_OK) {
			px_config_reader_error(r, fn ? fn : it, where, "%s", msg);
			sc->failed_ = 1;
			continue;
		}
		snprintf(where, sizeof(where), "models[%zu]", i);
		add_model(r, sc, mod, raw_pose(&m->pose), m->name ? m->name : m->file,
			  it, where);
	}
	for (i = 0; i < sc->n_prims; i++) {
		const struct raw_prim *p = &sc->prims[i];
		const struct px_config_node *it = item(map, "primitives", i);
		struct px_prim pr;
		struct px_model *mod;
		char nm[32];
		memset(&pr, 0, sizeof(pr));
		pr.type = prim_types[p->type];
		switch (pr.type) {
		case PX_PRIM_BOX:
			pr.a = p->half_extents_m[0];
			pr.b = p->half_extents_m[1];
			pr.c = p->half_extents_m[2];
			break;
		case PX_PRIM_TORUS:
			pr.a = p->radius_m;
			pr.b = p->tube_radius_m;
			break;
		case PX_PRIM_CONE:
			pr.a = p->radius_m;
			pr.b = p->half_height_m;
			pr.c = p->has_top_radius ? p->top_radius_m : 0;
			break;
		default:
			pr.a = p->radius_m;
			pr.b = p->half_height_m;
			break;
		}
		snprintf(where, sizeof(where), "primitives[%zu]", i);
		rc = px_prim_model(&pr, &mod);
		if (rc != PX_OK) {
			px_config_reader_error(r, it, where,
					       "invalid %s dimensions: %s",
					       prim_names[p->type],
					       px_strerror(rc));
			sc->failed_ = 1;
			continue;
		}
		snprintf(nm, sizeof(nm), "%s", prim_names[p->type]);
		add_model(r, sc, mod, raw_pose(&p->pose), p->name ? p->name : nm,
			  it, where);
	}
}

int px_scene_config_load(const struct px_config *cfg, struct px_scene **out,
			 struct px_config_diag *diag)
{
	struct raw_scene raw;
	int rc;
	if (out)
		*out = NULL;
	if (!cfg || !out)
		return PX_E_INVAL;
	memset(&raw, 0, sizeof(raw));
	raw.cfg_ = cfg;
	raw.diag_ = diag;
	raw.errors_before_ = px_config_diag_total(diag);
	rc = px_config_read(cfg->doc, cfg->scene, "scene", &scene_schema, &raw,
			    diag);
	if (rc == PX_OK && raw.failed_)
		rc = PX_E_PARSE;
	if (rc == PX_OK && !raw.scene_)
		rc = px_scene_create(1, &raw.scene_);
	if (rc != PX_OK) {
		px_scene_free(raw.scene_);
		return rc;
	}
	{
		struct px_model_stream_opts o;
		px_model_stream_opts_default(&o);
		o.verify_every = (int)raw.tracking.verify_every;
		o.max_solves = (int)raw.tracking.max_solves;
		o.cold_switch = raw.tracking.cold_switch ? 1 : 0;
		px_scene_set_tracking(raw.scene_, raw.tracking.enabled, &o);
	}
	*out = raw.scene_;
	return PX_OK;
}
