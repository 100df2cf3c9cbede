/* The arm of an avoidance run in the view (px_view.h): its links
 * tessellated once for scene.robot, their poses from a record's joint
 * positions by the chain's forward kinematics, and what a frame shows
 * beside its record (closest point, links, the closest pair). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "px_prim.h"
#include "px_tess.h"
#include "px_view.h"
#include "view_internal.h"

struct arm_link {
	int frame;       /* chain frame it rides on: 0 base, i after joint i */
	px_pose offset;  /* its model's frame in that frame */
};

struct px_view_arm {
	struct px_control_chain chain;
	int perm[PX_CONTROL_MAX_JOINTS];
	int record_joints;
	int n_links;
	struct arm_link links[PX_VIEW_MAX_LINKS];
	double protective_m, influence_m;
	struct view_buf json; /* the scene.robot object */
};

/* One link of scene.robot: model m's triangles in its own frame. */
static int link_json(struct view_buf *b, const char *name,
		     const struct px_model *m, int first)
{
	struct px_tess t;
	int rc = px_model_tessellate(m, NULL, &t);
	if (rc != PX_OK && rc != PX_E_UNSUPPORTED) {
		px_tess_free(&t);
		return rc;
	}
	view_buf_puts(b, first ? "{\"name\":" : ",{\"name\":");
	view_buf_str(b, name);
	view_buf_puts(b, ",\"positions\":");
	view_buf_floats(b, t.xyz, 3 * t.n_vertices, 1.0, 7);
	view_buf_puts(b, ",");
	view_tess_indices(b, &t);
	px_tess_free(&t);
	return b->err;
}

/* A capsule of the chain as a link: a capsule primitive along the
 * segment a..b (a sphere when a = b). */
static int capsule_link(struct px_view_arm *v, int i)
{
	const struct px_control_capsule *c = &v->chain.capsules[i];
	px_vec3 d = px_v3(c->b_m.x - c->a_m.x, c->b_m.y - c->a_m.y,
			  c->b_m.z - c->a_m.z);
	double len = sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
	struct px_prim p;
	struct px_model *m = NULL;
	char name[48];
	int rc;
	v->links[v->n_links].frame = c->link;
	v->links[v->n_links].offset = px_pose_identity();
	v->links[v->n_links].offset.t =
		px_v3(0.5 * (c->a_m.x + c->b_m.x), 0.5 * (c->a_m.y + c->b_m.y),
		      0.5 * (c->a_m.z + c->b_m.z));
	memset(&p, 0, sizeof(p));
	p.a = c->radius_m > 0 ? c->radius_m : 1e-3;
	if (len > 1e-9) {
		p.type = PX_PRIM_CAPSULE;
		p.b = 0.5 * len;
		rc = px_quat_from_two_vectors(px_v3(0, 0, 1), d,
					      &v->links[v->n_links].offset.q);
		if (rc != PX_OK)
			return rc;
	} else {
		p.type = PX_PRIM_SPHERE;
	}
	rc = px_prim_model(&p, &m);
	if (rc != PX_OK)
		return rc;
	snprintf(name, sizeof(name), "capsule %d (link %d)", i, c->link);
	rc = link_json(&v->json, name, m, v->n_links == 0);
	px_model_free(m);
	v->n_links++;
	return rc;
}

int px_view_arm_create(const struct px_app_arm *in, struct px_view_arm **out)
{
	struct px_view_arm *v;
	int i, n, rc = PX_OK;
	if (!in || !in->chain || !out)
		return PX_E_INVAL;
	*out = NULL;
	n = in->robot ? px_urdf_robot_body_count(in->robot) : in->chain->n_capsules;
	if (n > PX_VIEW_MAX_LINKS)
		return PX_E_RANGE;
	v = calloc(1, sizeof(*v));
	if (!v)
		return PX_E_NOMEM;
	v->chain = *in->chain;
	for (i = 0; i < PX_CONTROL_MAX_JOINTS; i++)
		v->perm[i] = in->joint_perm ? in->joint_perm[i] : i;
	v->record_joints = in->record_joints;
	v->protective_m = in->protective_distance_m;
	v->influence_m = in->influence_distance_m;
	v->json.growable = 1;
	view_buf_puts(&v->json, "{\"links\":[");
	for (i = 0; i < n && rc == PX_OK; i++) {
		if (in->robot) {
			const struct px_urdf_body *bd = px_urdf_robot_body(in->robot, i);
			v->links[i].frame = bd->frame;
			v->links[i].offset = bd->offset;
			rc = link_json(&v->json, px_urdf_robot_body_link(in->robot, i),
				       bd->model, i == 0);
			v->n_links++;
		} else {
			rc = capsule_link(v, i);
		}
	}
	view_buf_puts(&v->json, "],\"protective_distance_m\":");
	view_buf_num(&v->json, v->protective_m, 9);
	view_buf_puts(&v->json, ",\"influence_distance_m\":");
	view_buf_num(&v->json, v->influence_m, 9);
	view_buf_puts(&v->json, "}");
	if (rc == PX_OK)
		rc = v->json.err;
	if (rc != PX_OK) {
		px_view_arm_free(v);
		return rc;
	}
	*out = v;
	return PX_OK;
}

void px_view_arm_free(struct px_view_arm *a)
{
	if (!a)
		return;
	free(a->json.p);
	free(a);
}

int px_view_arm_link_count(const struct px_view_arm *a)
{
	return a ? a->n_links : 0;
}

const char *view_arm_json(const struct px_view_arm *a, size_t *len)
{
	*len = a->json.n;
	return a->json.p;
}

int px_view_arm_links(const struct px_view_arm *a, const struct px_app_record *r,
		      double (*poses)[7], int cap)
{
	double q[PX_CONTROL_MAX_JOINTS] = {0};
	px_pose frames[PX_CONTROL_MAX_JOINTS + 1];
	int n, i;
	if (!a || !r || !poses)
		return PX_E_INVAL;
	if (a->n_links > cap)
		return PX_E_NOSPC;
	n = a->chain.n_joints;
	if (n > a->record_joints || n > PX_APP_RECORD_JOINTS)
		return 0;
	for (i = 0; i < n; i++)
		q[a->perm[i]] = r->q[i];
	if (px_control_chain_fk(&a->chain, q, frames, (size_t)n + 1) != PX_OK)
		return 0;
	for (i = 0; i < a->n_links; i++) {
		const struct arm_link *l = &a->links[i];
		px_pose P = px_pose_compose(frames[l->frame], l->offset);
		const double p[7] = {P.t.x, P.t.y, P.t.z, P.q.w, P.q.x, P.q.y, P.q.z};
		memcpy(poses[i], p, sizeof(p));
	}
	return a->n_links;
}

/* The arm's closest pair as the record carries it (the link point as
 * the tool, the obstacle's as the proxy), within the influence
 * distance (beyond it the points are not the pair's). */
static int clearance(const struct px_view_arm *a, const struct px_app_record *r,
		     double *seg)
{
	int k;
	if (!(r->distance_m < a->influence_m) || !r->valid)
		return 0;
	for (k = 0; k < 3; k++) {
		seg[k] = r->dev_m[k];
		seg[3 + k] = r->proxy_m[k];
		if (!isfinite(seg[k]) || !isfinite(seg[3 + k]))
			return 0;
	}
	seg[6] = r->distance_m;
	return 1;
}

void px_view_frame_fill(const struct px_view_sources *src,
			const struct px_app_record *r,
			struct px_view_frame_extra *x)
{
	x->has_closest = 0;
	x->n_links = x->n_clearances = x->n_models = 0;
	if (!src || !r)
		return;
	if (src->arm) {
		int n = px_view_arm_links(src->arm, r, x->links, PX_VIEW_MAX_LINKS);
		x->n_links = n > 0 ? n : 0;
		x->n_clearances = clearance(src->arm, r, x->clearances[0]);
	} else if (src->scene && px_scene_count(src->scene) > 0) {
		struct px_scene_hit h;
		px_vec3 p = px_v3(r->dev_m[0], r->dev_m[1], r->dev_m[2]);
		if (px_scene_nearest(src->scene, p, INFINITY, &h) == 1) {
			x->has_closest = 1;
			x->closest_m[0] = h.point.x;
			x->closest_m[1] = h.point.y;
			x->closest_m[2] = h.point.z;
		}
	}
}
