/*
 * urdf_robot.c - the chain between two links of a URDF and one model
 * per collision shape riding on it, posed by forward kinematics.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "px_mesh.h"
#include "px_prim.h"
#include "robot_internal.h"

void px_urdf_robot_free(struct px_urdf_robot *r)
{
	int i;
	if (!r)
		return;
	for (i = 0; r->bodies && i < r->n_bodies; i++)
		px_model_free(r->bodies[i].model);
	free(r->bodies);
	free(r->body_link);
	free(r->obstacles);
	free(r->pairs);
	free(r->caches);
	px__urdf_avoid_free(r);
	free(r);
}

/* A mesh file scaled by s (a negative product mirrors it: the loader
 * turns the triangles round so that outside stays outside). */
static int mesh_model(const char *path, const double *s, struct px_model **out,
		      char *why, size_t cap)
{
	struct px_mesh_report rep;
	int rc = px_mesh_load_scaled(path, s, NULL, &rep, out);
	if (rc)
		snprintf(why, cap, "%s", rep.message[0] ? rep.message : px_strerror(rc));
	return rc;
}

/* The model of one collision shape, in its own frame. */
static int shape_model(const struct px_urdf_shape *s, struct px_model **out,
		       char *why, size_t cap)
{
	struct px_prim p;
	int rc;
	memset(&p, 0, sizeof(p));
	switch (s->type) {
	case PX_URDF_BOX:
		p.type = PX_PRIM_BOX;
		p.a = 0.5 * s->size[0];
		p.b = 0.5 * s->size[1];
		p.c = 0.5 * s->size[2];
		break;
	case PX_URDF_CYLINDER:
		p.type = PX_PRIM_CYLINDER;
		p.a = s->size[0];
		p.b = 0.5 * s->size[1];
		break;
	case PX_URDF_SPHERE:
		p.type = PX_PRIM_SPHERE;
		p.a = s->size[0];
		break;
	case PX_URDF_MESH:
		return mesh_model(s->mesh, s->size, out, why, cap);
	default:
		snprintf(why, cap, "unknown shape");
		return PX_E_INVAL;
	}
	rc = px_prim_model(&p, out);
	if (rc)
		snprintf(why, cap, "%s", px_strerror(rc));
	return rc;
}

/* Joints from base to tip, in order (count, or an error). */
static int chain_path(const struct px_urdf *u, int base, int tip, int *path,
		      struct px_urdf_error *err)
{
	int n = 0, l = tip, i;
	while (l != base) {
		int j = u->links[l].parent_joint;
		if (j < 0)
			return px__urdf_fail(err, PX_E_INVAL, u->file, 0, "",
					     "link '%.60s' is not between the root and "
					     "'%.60s': no chain from it", u->links[base].name,
					     u->links[tip].name);
		path[n++] = j;
		l = u->joints[j].parent;
	}
	for (i = 0; i < n / 2; i++) {
		int t = path[i];
		path[i] = path[n - 1 - i];
		path[n - 1 - i] = t;
	}
	return n;
}

/* Link frames of the chain: frame[l] (-1: not attached), offset[l]. */
static int build_chain(struct px_urdf_robot *r, const struct px_urdf *u, int base,
		       const int *path, int n, int *frame, px_pose *offset,
		       struct px_urdf_error *err)
{
	px_pose acc = px_pose_identity();
	int i, f = 0, changed, pass;
	frame[base] = 0;
	offset[base] = acc;
	for (i = 0; i < n; i++) {
		const struct px_urdf_joint *j = &u->joints[path[i]];
		if (j->type == PX_URDF_FIXED) {
			acc = px_pose_compose(acc, j->origin);
		} else {
			int rc;
			if (r->dof == PX_CONTROL_MAX_JOINTS)
				return px__urdf_fail(err, PX_E_NOSPC, u->file, j->line, "",
						     "more than %d movable joints between the base "
						     "and the tip", PX_CONTROL_MAX_JOINTS);
			rc = px_control_chain_add_joint(&r->chain,
							j->type == PX_URDF_PRISMATIC
								? PX_CONTROL_PRISMATIC
								: PX_CONTROL_REVOLUTE,
							px_pose_compose(acc, j->origin), j->axis);
			if (rc)
				return px__urdf_fail(err, rc, u->file, j->line, "",
						     "joint '%.60s': %s", j->name, px_strerror(rc));
			snprintf(r->names[r->dof], URDF_NAME_LEN, "%s", j->name);
			r->lower[r->dof] = j->lower;
			r->upper[r->dof] = j->upper;
			r->velocity[r->dof] = j->velocity;
			r->dof++;
			f = r->dof;
			acc = px_pose_identity();
		}
		frame[j->child] = f;
		offset[j->child] = acc;
	}
	/* what hangs off the chain by fixed joints rides with it */
	for (pass = 0, changed = 1; changed && pass < u->n_links; pass++) {
		changed = 0;
		for (i = 0; i < u->n_joints; i++) {
			const struct px_urdf_joint *j = &u->joints[i];
			if (j->type != PX_URDF_FIXED || frame[j->parent] < 0 ||
			    frame[j->child] >= 0)
				continue;
			frame[j->child] = frame[j->parent];
			offset[j->child] = px_pose_compose(offset[j->parent], j->origin);
			changed = 1;
		}
	}
	return PX_OK;
}

static int make_bodies(struct px_urdf_robot *r, const struct px_urdf *u,
		       const int *frame, const px_pose *offset,
		       struct px_urdf_error *err)
{
	int l, i, n = 0;
	for (l = 0; l < u->n_links; l++)
		if (frame[l] >= 0)
			n += u->links[l].n_shapes;
	r->bodies = calloc((size_t)n + 1, sizeof(*r->bodies));
	r->body_link = calloc((size_t)n + 1, sizeof(*r->body_link));
	if (!r->bodies || !r->body_link)
		return px__urdf_fail(err, PX_E_NOMEM, u->file, 0, "", "out of memory");
	for (l = 0; l < u->n_links; l++) {
		const struct px_urdf_link *lk = &u->links[l];
		if (frame[l] < 0)
			continue;
		for (i = 0; i < lk->n_shapes; i++) {
			struct px_urdf_body *b = &r->bodies[r->n_bodies];
			char why[300], el[128];
			int rc = shape_model(&lk->shapes[i], &b->model, why, sizeof(why));
			if (rc) {
				snprintf(el, sizeof(el), "<link name='%.60s'>", lk->name);
				return px__urdf_fail(err, rc, u->file, lk->shapes[i].line, el,
						     "collision %d: %s", i, why);
			}
			b->frame = frame[l];
			b->offset = px_pose_compose(offset[l], lk->shapes[i].origin);
			b->link = l;
			b->shape = i;
			snprintf(r->body_link[r->n_bodies], URDF_NAME_LEN, "%s", lk->name);
			r->n_bodies++;
		}
	}
	return PX_OK;
}

int px_urdf_robot_create(const struct px_urdf *u, const char *base_link,
			 const char *tip_link, px_pose base,
			 struct px_urdf_robot **out, struct px_urdf_error *err)
{
	struct px_urdf_robot *r;
	int *path = NULL, *frame = NULL, b, t, n, rc, i;
	px_pose *offset = NULL;
	if (err)
		memset(err, 0, sizeof(*err));
	if (!out)
		return PX_E_INVAL;
	*out = NULL;
	if (!u || !tip_link)
		return px__urdf_fail(err, PX_E_INVAL, u ? u->file : "", 0, "",
				     "a robot needs a URDF and a tip link");
	b = base_link ? px_urdf_find_link(u, base_link) : u->root;
	t = px_urdf_find_link(u, tip_link);
	if (b < 0 || t < 0)
		return px__urdf_fail(err, PX_E_NOTFOUND, u->file, 0, "",
				     "no link named '%.60s'", b < 0 ? base_link : tip_link);
	if (px_pose_sanitize(&base) != PX_OK)
		return px__urdf_fail(err, PX_E_NAN, u->file, 0, "", "the base pose is not finite");
	r = calloc(1, sizeof(*r));
	path = calloc((size_t)u->n_links + 1, sizeof(*path));
	frame = calloc((size_t)u->n_links + 1, sizeof(*frame));
	offset = calloc((size_t)u->n_links + 1, sizeof(*offset));
	if (!r || !path || !frame || !offset) {
		rc = px__urdf_fail(err, PX_E_NOMEM, u->file, 0, "", "out of memory");
		goto done;
	}
	px_control_chain_init(&r->chain, base);
	for (i = 0; i < u->n_links; i++)
		frame[i] = -1;
	n = chain_path(u, b, t, path, err);
	rc = n < 0 ? n : build_chain(r, u, b, path, n, frame, offset, err);
	if (rc == PX_OK)
		rc = make_bodies(r, u, frame, offset, err);
	if (rc == PX_OK) {
		double q0[PX_CONTROL_MAX_JOINTS] = {0};
		rc = px_urdf_robot_set_q(r, q0, NULL, 0);
	}
done:
	free(path);
	free(frame);
	free(offset);
	if (rc) {
		px_urdf_robot_free(r);
		return rc;
	}
	*out = r;
	return PX_OK;
}

const struct px_control_chain *px_urdf_robot_chain(const struct px_urdf_robot *r)
{
	return r ? &r->chain : NULL;
}

int px_urdf_robot_dof(const struct px_urdf_robot *r)
{
	return r ? r->dof : 0;
}

const char *px_urdf_robot_joint_name(const struct px_urdf_robot *r, int j)
{
	return r && j >= 0 && j < r->dof ? r->names[j] : "";
}

int px_urdf_robot_limits(const struct px_urdf_robot *r, int j, double *lower,
			 double *upper, double *velocity)
{
	if (!r || j < 0 || j >= r->dof)
		return PX_E_INVAL;
	if (lower)
		*lower = r->lower[j];
	if (upper)
		*upper = r->upper[j];
	if (velocity)
		*velocity = r->velocity[j];
	return PX_OK;
}

int px_urdf_robot_body_count(const struct px_urdf_robot *r)
{
	return r ? r->n_bodies : 0;
}

const struct px_urdf_body *px_urdf_robot_body(const struct px_urdf_robot *r, int i)
{
	return r && i >= 0 && i < r->n_bodies ? &r->bodies[i] : NULL;
}

const char *px_urdf_robot_body_link(const struct px_urdf_robot *r, int i)
{
	return r && i >= 0 && i < r->n_bodies ? r->body_link[i] : "";
}

int px_urdf_robot_set_q(struct px_urdf_robot *r, const double *q, px_pose *frames,
			size_t cap)
{
	int i, rc;
	if (!r || !q)
		return PX_E_INVAL;
	if (frames && cap < (size_t)r->dof + 1)
		return PX_E_NOSPC;
	rc = px_control_chain_fk(&r->chain, q, r->frames, (size_t)r->dof + 1);
	if (rc)
		return rc;
	for (i = 0; i < r->n_bodies; i++) {
		const struct px_urdf_body *b = &r->bodies[i];
		rc = px_model_set_pose(b->model, px_pose_compose(r->frames[b->frame], b->offset));
		if (rc)
			return rc;
	}
	if (frames)
		memcpy(frames, r->frames, ((size_t)r->dof + 1) * sizeof(*frames));
	return PX_OK;
}

int px_urdf_robot_set_obstacles(struct px_urdf_robot *r,
				struct px_model *const *obstacles, int n)
{
	struct px_model **ob;
	struct px_pair_result *pr;
	struct px_pair_cache **pc;
	size_t nc = 0, np = (size_t)n * (size_t)r->n_bodies;
	char *cmem;
	int i;
	if (!r || n < 0 || (n > 0 && !obstacles))
		return PX_E_INVAL;
	if (n > PX_URDF_MAX_OBSTACLES)
		return PX_E_RANGE;
	for (i = 0; i < n; i++)
		if (!obstacles[i])
			return PX_E_INVAL;
	/* a cut cache per link against each cloud (urdf_robot.c's pairs) */
	for (i = 0; i < n; i++)
		nc += px_model_kind(obstacles[i]) == PX_MODEL_CLOUD ? (size_t)r->n_bodies : 0;
	ob = calloc((size_t)n + 1, sizeof(*ob));
	pr = calloc(np + 1, sizeof(*pr));
	/* one block: the pointers per pair, then the caches */
	cmem = calloc(1, (np + 1) * sizeof(*pc) + nc * sizeof(struct px_pair_cache));
	if (!ob || !pr || !cmem) {
		free(ob);
		free(pr);
		free(cmem);
		return PX_E_NOMEM;
	}
	pc = (struct px_pair_cache **)(void *)cmem;
	nc = 0;
	for (i = 0; i < n; i++) {
		int b;
		if (px_model_kind(obstacles[i]) != PX_MODEL_CLOUD)
			continue;
		for (b = 0; b < r->n_bodies; b++) {
			struct px_pair_cache *c =
				(struct px_pair_cache *)(void *)(cmem + (np + 1) * sizeof(*pc)) +
				nc++;
			/* the link's planes now, not in its first cycle */
			px_pair_cache_prepare(c, r->bodies[b].model);
			pc[(size_t)b * (size_t)n + (size_t)i] = c;
		}
	}
	if (n)
		memcpy(ob, obstacles, (size_t)n * sizeof(*ob));
	free(r->obstacles);
	free(r->pairs);
	free(r->caches);
	r->obstacles = ob;
	r->pairs = pr;
	r->caches = pc;
	r->n_obstacles = n;
	return px__urdf_avoid_size(r);
}

struct px_urdf_clearance px__urdf_clearance(const struct px_pair_result *p, int body,
					    int obstacle, int other_body)
{
	struct px_urdf_clearance c;
	c.body = body;
	c.obstacle = obstacle;
	c.other_body = other_body;
	c.distance_m = p->distance;
	c.point_robot = p->point_b;
	c.point_obstacle = p->point_a;
	c.normal = p->normal;
	c.intersecting = p->intersecting;
	c.local_only = p->local_only;
	return c;
}

/* Gap between two models' world boxes: a lower bound of their
 * distance (0 when the boxes meet or one is unbounded). */
static double box_gap(const struct px_model *a, const struct px_model *b)
{
	px_aabb x = px_model_world_aabb(a), y = px_model_world_aabb(b);
	px_vec3 d = px_v3(fmax(0, fmax(x.min.x - y.max.x, y.min.x - x.max.x)),
			  fmax(0, fmax(x.min.y - y.max.y, y.min.y - x.max.y)),
			  fmax(0, fmax(x.min.z - y.max.z, y.min.z - x.max.z)));
	double g = px_v3_norm(d);
	return isfinite(g) ? g : 0.0;
}

int px__urdf_pair(const struct px_model *a, const struct px_model *b,
		  const struct px_pair_opts *po, int coherent, double reach,
		  struct px_pair_result *p, struct px_pair_cache *cache, int body, int obstacle,
		  int other_body, struct px_urdf_clearance *c)
{
	double gap = reach < INFINITY ? box_gap(a, b) : 0.0;
	int rc;
	if (gap >= reach) {
		/* farther than anyone asks: the boxes' gap stands for it */
		memset(c, 0, sizeof(*c));
		c->body = body;
		c->obstacle = obstacle;
		c->other_body = other_body;
		c->distance_m = gap;
		return 0;
	}
	if (!coherent)
		p->valid = 0;
	rc = px_pair_distance_cached(a, b, po, cache, p);
	if (rc)
		return rc;
	*c = px__urdf_clearance(p, body, obstacle, other_body);
	return 1;
}

void px__urdf_pair_opts(const struct px_pair_opts *o, int coherent, struct px_pair_opts *po)
{
	if (o)
		*po = *o;
	else
		memset(po, 0, sizeof(*po));
	po->coherent = coherent ? 1 : 0;
}

void px__urdf_min_init(struct px_urdf_clearance *min)
{
	if (!min)
		return;
	memset(min, 0, sizeof(*min));
	min->body = min->obstacle = min->other_body = -1;
	min->distance_m = INFINITY;
}

int px__urdf_obstacle_pairs(struct px_urdf_robot *r, const struct px_pair_opts *o,
			    int coherent, double reach, struct px_urdf_clearance *out,
			    size_t cap, struct px_urdf_clearance *min, int *measured)
{
	struct px_pair_opts po;
	int b, k, n = 0, rc;
	if (!r)
		return PX_E_INVAL;
	if (out && cap < (size_t)r->n_bodies * (size_t)r->n_obstacles)
		return PX_E_NOSPC;
	px__urdf_pair_opts(o, coherent, &po);
	px__urdf_min_init(min);
	for (b = 0; b < r->n_bodies; b++)
		for (k = 0; k < r->n_obstacles; k++, n++) {
			struct px_urdf_clearance c;
			rc = px__urdf_pair(r->obstacles[k], r->bodies[b].model, &po, coherent,
					   reach, &r->pairs[n], r->caches[n], b, k, -1, &c);
			if (rc < 0)
				return rc;
			if (measured)
				*measured += rc;
			if (out)
				out[n] = c;
			if (min && c.distance_m < min->distance_m)
				*min = c;
		}
	return n;
}

int px_urdf_robot_clearances(struct px_urdf_robot *r, const struct px_pair_opts *o,
			     int coherent, struct px_urdf_clearance *out, size_t cap,
			     struct px_urdf_clearance *min)
{
	return px__urdf_obstacle_pairs(r, o, coherent, INFINITY, out, cap, min, NULL);
}
