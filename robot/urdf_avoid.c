/*
 * urdf_avoid.c - a URDF robot's self-clearance, obstacles replaced
 * while running, and the avoidance command from its link models'
 * clearances (px_control_avoid_command on the pairs' witnesses and
 * separating directions).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "robot_internal.h"

/* The per-cycle buffers (cl, contacts, contact_of) go together. */
static void set_buffers(struct px_urdf_robot *r, struct px_urdf_clearance *cl,
			struct px_control_contact *ks, int *of, int cap)
{
	free(r->cl);
	free(r->contacts);
	free(r->contact_of);
	r->cl = cl;
	r->contacts = ks;
	r->contact_of = of;
	r->cap_contacts = cap;
}

void px__urdf_avoid_free(struct px_urdf_robot *r)
{
	free(r->self);
	free(r->self_pairs);
	r->self = NULL;
	r->self_pairs = NULL;
	r->n_self = 0;
	set_buffers(r, NULL, NULL, NULL, 0);
}

int px__urdf_avoid_size(struct px_urdf_robot *r)
{
	size_t n = (size_t)r->n_bodies * (size_t)r->n_obstacles + (size_t)r->n_self;
	struct px_urdf_clearance *cl = calloc(n + 1, sizeof(*cl));
	struct px_control_contact *ks = calloc(n + 1, sizeof(*ks));
	int *of = calloc(n + 1, sizeof(*of));
	if (!cl || !ks || !of || n > (size_t)1 << 30) {
		free(cl);
		free(ks);
		free(of);
		return PX_E_NOMEM;
	}
	set_buffers(r, cl, ks, of, (int)n);
	return PX_OK;
}

int px_urdf_robot_replace_obstacle(struct px_urdf_robot *r, int k, struct px_model *m)
{
	int b;
	if (!r || !m || k < 0 || k >= r->n_obstacles)
		return PX_E_INVAL;
	r->obstacles[k] = m;
	for (b = 0; b < r->n_bodies; b++)
		r->pairs[(size_t)b * (size_t)r->n_obstacles + (size_t)k].valid = 0;
	return PX_OK;
}

/* Link index of a name among the robot's bodies' links, -1 if none. */
static int body_link_named(const struct px_urdf_robot *r, const char *name)
{
	int i;
	for (i = 0; i < r->n_bodies; i++)
		if (!strcmp(r->body_link[i], name))
			return r->bodies[i].link;
	return -1;
}

static int allowed_pair(const int *al, int n, int la, int lb)
{
	int i;
	for (i = 0; i < n; i++)
		if ((al[2 * i] == la && al[2 * i + 1] == lb) ||
		    (al[2 * i] == lb && al[2 * i + 1] == la))
			return 1;
	return 0;
}

/* The self pairs: counted, and written to self unless NULL. */
static int self_pass(const struct px_urdf_robot *r, const int *al, int n_allowed,
		     int (*self)[2])
{
	int a, b, n = 0;
	for (a = 0; a < r->n_bodies; a++)
		for (b = a + 1; b < r->n_bodies; b++) {
			int fa = r->bodies[a].frame, fb = r->bodies[b].frame;
			if (abs(fa - fb) <= 1 ||
			    allowed_pair(al, n_allowed, r->bodies[a].link, r->bodies[b].link))
				continue;
			if (self) {
				self[n][0] = a;
				self[n][1] = b;
			}
			n++;
		}
	return n;
}

int px_urdf_robot_set_self(struct px_urdf_robot *r, const char *const *allowed,
			   int n_allowed, struct px_urdf_error *err)
{
	int *al, a, n, rc;
	int (*self)[2] = NULL;
	struct px_pair_result *sp = NULL;
	if (err)
		memset(err, 0, sizeof(*err));
	if (!r || n_allowed < 0 || (n_allowed > 0 && !allowed))
		return PX_E_INVAL;
	al = calloc(2 * (size_t)n_allowed + 1, sizeof(*al));
	if (!al)
		return PX_E_NOMEM;
	for (a = 0; a < 2 * n_allowed; a++) {
		al[a] = allowed[a] ? body_link_named(r, allowed[a]) : -1;
		if (al[a] < 0) {
			free(al);
			return px__urdf_fail(err, PX_E_NOTFOUND, "", 0, "",
					     "allowed collision %d: no link with collision "
					     "shapes named '%.60s' on the robot",
					     a / 2, allowed[a] ? allowed[a] : "(null)");
		}
	}
	n = self_pass(r, al, n_allowed, NULL);
	self = calloc((size_t)n + 1, sizeof(*self));
	sp = calloc((size_t)n + 1, sizeof(*sp));
	if (!self || !sp) {
		free(al);
		free(self);
		free(sp);
		return PX_E_NOMEM;
	}
	n = self_pass(r, al, n_allowed, self);
	free(al);
	free(r->self);
	free(r->self_pairs);
	r->self = self;
	r->self_pairs = sp;
	r->n_self = n;
	rc = px__urdf_avoid_size(r);
	return rc ? rc : n;
}

static int self_pairs(struct px_urdf_robot *r, const struct px_pair_opts *o,
		      int coherent, double reach, struct px_urdf_clearance *out,
		      size_t cap, struct px_urdf_clearance *min, int *measured)
{
	struct px_pair_opts po;
	int i, rc;
	if (!r)
		return PX_E_INVAL;
	if (out && cap < (size_t)r->n_self)
		return PX_E_NOSPC;
	px__urdf_pair_opts(o, coherent, &po);
	px__urdf_min_init(min);
	for (i = 0; i < r->n_self; i++) {
		struct px_urdf_clearance c;
		int a = r->self[i][0], b = r->self[i][1];
		rc = px__urdf_pair(r->bodies[a].model, r->bodies[b].model, &po, coherent, reach,
				   &r->self_pairs[i], NULL, b, -1, a, &c);
		if (rc < 0)
			return rc;
		if (measured)
			*measured += rc;
		if (out)
			out[i] = c;
		if (min && c.distance_m < min->distance_m)
			*min = c;
	}
	return r->n_self;
}

int px_urdf_robot_self_clearances(struct px_urdf_robot *r,
				  const struct px_pair_opts *o, int coherent,
				  struct px_urdf_clearance *out, size_t cap,
				  struct px_urdf_clearance *min)
{
	return self_pairs(r, o, coherent, INFINITY, out, cap, min, NULL);
}

/* A clearance as a contact of the command (0: not finite). Unsigned
 * models touching (a cloud on a link) have no direction: the normal
 * stays zero, which the command takes as approaching (it scales, it
 * cannot repel). */
static int to_contact(const struct px_urdf_robot *r, const struct px_urdf_clearance *c,
		      const struct px_control_avoid_params *p,
		      struct px_control_contact *k)
{
	double nn = px_v3_norm(c->normal);
	if (!isfinite(c->distance_m) || !px_v3_isfinite(c->normal))
		return 0;
	k->link = r->bodies[c->body].frame;
	k->other_link = c->other_body >= 0 ? r->bodies[c->other_body].frame : -1;
	k->clearance_m = c->distance_m;
	k->point_m = c->point_robot;
	k->other_m = c->point_obstacle;
	k->normal = nn > 0.5 ? px_v3_scale(c->normal, 1.0 / nn) : px_v3(0, 0, 0);
	k->influence_distance_m = 0;
	k->protective_distance_m = 0;
	if (c->other_body >= 0 && p->self_influence_distance_m > 0) {
		k->influence_distance_m = p->self_influence_distance_m;
		k->protective_distance_m = p->self_protective_distance_m;
	}
	return 1;
}

int px_urdf_avoid_step(struct px_urdf_robot *r,
		       const struct px_control_avoid_params *p,
		       const struct px_pair_opts *o, int coherent, const double *q,
		       const double *qdot_nominal, int64_t period_ns,
		       struct px_urdf_avoid_out *out)
{
	int i, n, ns, nk = 0, closest = -1, measured = 0, rc;
	if (!out)
		return PX_E_INVAL;
	memset(&out->closest, 0, sizeof(out->closest));
	out->closest.body = out->closest.obstacle = out->closest.other_body = -1;
	out->pairs = 0;
	out->local_only = 0;
	if (!r || !p || !q) {
		memset(&out->cmd, 0, sizeof(out->cmd));
		out->cmd.closest_capsule = -1;
		return PX_E_INVAL;
	}
	rc = px_urdf_robot_set_q(r, q, NULL, 0);
	/* pairs whose boxes lie beyond the influence distance cannot make
	 * a contact: not measured */
	n = rc ? rc : px__urdf_obstacle_pairs(r, o, coherent, p->influence_distance_m, r->cl,
					      (size_t)r->cap_contacts, NULL, &measured);
	ns = n < 0 ? n : self_pairs(r, o, coherent,
				    p->self_influence_distance_m > 0
					    ? p->self_influence_distance_m
					    : p->influence_distance_m,
				    r->cl + n, (size_t)(r->cap_contacts - n), NULL, &measured);
	if (n < 0 || ns < 0) {
		rc = n < 0 ? n : ns;
		/* the command's own checks zero it; the error wins */
		px_control_avoid_command(&r->chain, p, q, NULL, period_ns, NULL, 0,
					 &out->cmd, NULL);
		memset(out->cmd.qdot, 0, sizeof(out->cmd.qdot));
		out->cmd.scale = 0;
		return rc;
	}
	out->pairs = measured;
	for (i = 0; i < n + ns; i++) {
		const struct px_urdf_clearance *c = &r->cl[i];
		double reach = c->other_body >= 0 && p->self_influence_distance_m > 0
				       ? p->self_influence_distance_m
				       : p->influence_distance_m;
		out->local_only += c->local_only != 0;
		if (c->distance_m >= reach || !to_contact(r, c, p, &r->contacts[nk]))
			continue;
		r->contact_of[nk++] = i;
	}
	rc = px_control_avoid_command(&r->chain, p, q, qdot_nominal, period_ns,
				      r->contacts, nk, &out->cmd, &closest);
	if (rc == PX_OK && closest >= 0)
		out->closest = r->cl[r->contact_of[closest]];
	return rc;
}
