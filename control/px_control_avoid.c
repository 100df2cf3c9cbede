/*
 * Serial chains (DH or URDF-style joints), forward kinematics, capsule
 * clearances and the collision-avoidance velocity command.
 */
#include <math.h>
#include <string.h>

#include "control_internal.h"

px_pose px_control_pose_from_xyz_rpy(px_vec3 xyz_m, px_vec3 rpy_rad)
{
	/* URDF: fixed-axis roll about x, then pitch about y, then yaw about
	 * z, i.e. R = Rz(yaw) Ry(pitch) Rx(roll). */
	px_quat qx, qy, qz;
	px_pose p;
	px_quat_from_axis_angle(px_v3(1, 0, 0), rpy_rad.x, &qx);
	px_quat_from_axis_angle(px_v3(0, 1, 0), rpy_rad.y, &qy);
	px_quat_from_axis_angle(px_v3(0, 0, 1), rpy_rad.z, &qz);
	p.q = px_quat_mul(qz, px_quat_mul(qy, qx));
	p.t = xyz_m;
	return p;
}

void px_control_chain_init(struct px_control_chain *c, px_pose base)
{
	if (!c)
		return;
	memset(c, 0, sizeof(*c));
	c->base = base;
}

static int pose_finite(px_pose p)
{
	return isfinite(p.q.w) && isfinite(p.q.x) && isfinite(p.q.y) &&
	       isfinite(p.q.z) && px_v3_isfinite(p.t);
}

int px_control_chain_add_dh(struct px_control_chain *c, int type, double a_m,
			    double alpha_rad, double d_m, double theta_rad)
{
	struct px_control_joint *j;
	px_quat rz, rx;
	if (!c || (type != PX_CONTROL_REVOLUTE && type != PX_CONTROL_PRISMATIC))
		return PX_E_INVAL;
	if (!isfinite(a_m) || !isfinite(alpha_rad) || !isfinite(d_m) ||
	    !isfinite(theta_rad))
		return PX_E_NAN;
	if (c->n_joints >= PX_CONTROL_MAX_JOINTS)
		return PX_E_NOSPC;
	j = &c->joints[c->n_joints];
	j->type = type;
	j->pre = px_pose_identity();
	j->axis = px_v3(0, 0, 1);
	/* Rz(theta) Tz(d) Tx(a) Rx(alpha): Rz and Tz commute, so the joint
	 * motion (Rz(q) or Tz(q)) may come first. */
	px_quat_from_axis_angle(px_v3(0, 0, 1), theta_rad, &rz);
	px_quat_from_axis_angle(px_v3(1, 0, 0), alpha_rad, &rx);
	j->post.q = px_quat_mul(rz, rx);
	j->post.t = px_v3(a_m * cos(theta_rad), a_m * sin(theta_rad), d_m);
	c->n_joints++;
	return PX_OK;
}

int px_control_chain_add_joint(struct px_control_chain *c, int type,
			       px_pose origin, px_vec3 axis)
{
	struct px_control_joint *j;
	px_vec3 u;
	if (!c || (type != PX_CONTROL_REVOLUTE && type != PX_CONTROL_PRISMATIC))
		return PX_E_INVAL;
	if (!pose_finite(origin) || !px_v3_isfinite(axis))
		return PX_E_NAN;
	if (px_v3_norm(axis) < 1e-9)
		return PX_E_INVAL;
	if (px_pose_sanitize(&origin) < 0)
		return PX_E_INVAL;
	if (c->n_joints >= PX_CONTROL_MAX_JOINTS)
		return PX_E_NOSPC;
	u = px_v3_scale(axis, 1.0 / px_v3_norm(axis));
	j = &c->joints[c->n_joints];
	j->type = type;
	j->pre = origin;
	j->axis = u;
	j->post = px_pose_identity();
	c->n_joints++;
	return PX_OK;
}

int px_control_chain_add_capsule(struct px_control_chain *c, int link,
				 px_vec3 a_m, px_vec3 b_m, double radius_m)
{
	if (!c || link < 0 || link > PX_CONTROL_MAX_JOINTS)
		return PX_E_INVAL;
	if (!px_v3_isfinite(a_m) || !px_v3_isfinite(b_m) || !isfinite(radius_m))
		return PX_E_NAN;
	if (radius_m < 0)
		return PX_E_RANGE;
	if (c->n_capsules >= PX_CONTROL_MAX_CAPSULES)
		return PX_E_NOSPC;
	c->capsules[c->n_capsules++] =
		(struct px_control_capsule){link, a_m, b_m, radius_m};
	return PX_OK;
}

static int chain_valid(const struct px_control_chain *c)
{
	return c && c->n_joints >= 0 && c->n_joints <= PX_CONTROL_MAX_JOINTS &&
	       c->n_capsules >= 0 && c->n_capsules <= PX_CONTROL_MAX_CAPSULES;
}

/* Frames 0..n and, per joint, the world axis and a point on it. */
static int fk_full(const struct px_control_chain *c, const double *q,
		   px_pose *frames, px_vec3 *axis_w, px_vec3 *origin_w)
{
	int i;
	frames[0] = c->base;
	for (i = 0; i < c->n_joints; i++) {
		const struct px_control_joint *j = &c->joints[i];
		px_pose jf = px_pose_compose(frames[i], j->pre), m;
		if (!isfinite(q[i]))
			return PX_E_NAN;
		if (axis_w) {
			axis_w[i] = px_pose_transform_vector(jf, j->axis);
			origin_w[i] = jf.t;
		}
		if (j->type == PX_CONTROL_REVOLUTE) {
			px_quat_from_axis_angle(j->axis, q[i], &m.q);
			m.t = px_v3(0, 0, 0);
		} else {
			m.q = px_quat_identity();
			m.t = px_v3_scale(j->axis, q[i]);
		}
		frames[i + 1] = px_pose_compose(px_pose_compose(jf, m), j->post);
	}
	return PX_OK;
}

int px_control_chain_fk(const struct px_control_chain *c, const double *q,
			px_pose *frames, size_t cap)
{
	if (!chain_valid(c) || !frames || (c->n_joints > 0 && !q))
		return PX_E_INVAL;
	if (cap < (size_t)c->n_joints + 1)
		return PX_E_NOSPC;
	return fk_full(c, q, frames, NULL, NULL);
}

static void jac_from(const struct px_control_chain *c, const px_vec3 *axis_w,
		     const px_vec3 *origin_w, int link, px_vec3 p, px_vec3 *jac)
{
	int i;
	for (i = 0; i < c->n_joints; i++) {
		if (i >= link)
			jac[i] = px_v3(0, 0, 0);
		else if (c->joints[i].type == PX_CONTROL_REVOLUTE)
			jac[i] = px_v3_cross(axis_w[i], px_v3_sub(p, origin_w[i]));
		else
			jac[i] = axis_w[i];
	}
}

int px_control_chain_jacobian(const struct px_control_chain *c,
			      const double *q, int link, px_vec3 p_m,
			      px_vec3 *jac)
{
	px_pose frames[PX_CONTROL_MAX_JOINTS + 1];
	px_vec3 ax[PX_CONTROL_MAX_JOINTS], org[PX_CONTROL_MAX_JOINTS];
	int rc;
	if (!chain_valid(c) || !jac || (c->n_joints > 0 && !q) || link < 0 ||
	    link > c->n_joints)
		return PX_E_INVAL;
	if (!px_v3_isfinite(p_m))
		return PX_E_NAN;
	rc = fk_full(c, q, frames, ax, org);
	if (rc)
		return rc;
	jac_from(c, ax, org, link, p_m, jac);
	return PX_OK;
}

/* ---- avoidance ---------------------------------------------------- */

void px_control_avoid_params_default(struct px_control_avoid_params *p)
{
	if (!p)
		return;
	p->influence_distance_m = 0.3;
	p->protective_distance_m = 0.05;
	p->repulsive_speed_m_per_s = 0.1;
	p->max_joint_velocity = 1.0;
	p->max_margin_fraction = 0.5;
	p->segment_point_queries = 24;
	p->segment_tol_m = 1e-4;
	p->approach_only = false;
	p->self_influence_distance_m = 0.05;
	p->self_protective_distance_m = 0.01;
}

int px_control_avoid_params_check(const struct px_control_avoid_params *p)
{
	if (!p)
		return PX_E_INVAL;
	if (!(p->protective_distance_m >= 0) ||
	    !(p->influence_distance_m > p->protective_distance_m) ||
	    !(p->influence_distance_m < 1e6) ||
	    !(p->repulsive_speed_m_per_s >= 0 && p->repulsive_speed_m_per_s < 1e3) ||
	    !(p->max_joint_velocity > 0 && p->max_joint_velocity < 1e6) ||
	    !(p->max_margin_fraction > 0 && p->max_margin_fraction <= 1) ||
	    p->segment_point_queries < 2 ||
	    p->segment_point_queries > PX__CTL_SEG_MAX ||
	    !(p->segment_tol_m >= 0 && p->segment_tol_m < 1) ||
	    !((p->self_influence_distance_m == 0 && p->self_protective_distance_m == 0) ||
	      (p->self_protective_distance_m >= 0 &&
	       p->self_influence_distance_m > p->self_protective_distance_m &&
	       p->self_influence_distance_m < 1e6)))
		return PX_E_RANGE;
	return PX_OK;
}

static int clearances(const struct px_control_chain *c,
		      const struct px_control_avoid_params *p,
		      const struct px_control_query *qry, const px_pose *frames,
		      double max_distance_m, struct px_control_clearance *out)
{
	int i, rc;
	for (i = 0; i < c->n_capsules; i++) {
		const struct px_control_capsule *cp = &c->capsules[i];
		struct px_control_seg_hit sh;
		struct px_control_clearance *o = &out[i];
		px_vec3 a = px_pose_transform_point(frames[cp->link], cp->a_m);
		px_vec3 b = px_pose_transform_point(frames[cp->link], cp->b_m);
		rc = px_control_query_segment(qry, a, b,
					      max_distance_m + cp->radius_m,
					      p->segment_point_queries,
					      p->segment_tol_m, &sh);
		if (rc < 0)
			return rc;
		o->valid = sh.hit.valid;
		o->point_m = px_v3_lerp(a, b, sh.t);
		o->obstacle_m = sh.hit.point_m;
		o->normal = sh.hit.normal;
		o->clearance_m = sh.hit.distance_m - cp->radius_m;
		o->lower_bound_m = sh.lower_bound_m - cp->radius_m;
		if (!o->valid) {
			o->clearance_m = max_distance_m;
			o->lower_bound_m = max_distance_m;
		}
	}
	return PX_OK;
}

/* Counting wrapper so that callers see how many point queries a cycle
 * made. */
struct counting {
	const struct px_control_query *q;
	int n;
};

static int count_point(void *ctx, px_vec3 p, double maxd,
		       struct px_control_hit *out)
{
	struct counting *k = ctx;
	k->n++;
	return k->q->point(k->q->ctx, p, maxd, out);
}

static int count_segment(void *ctx, px_vec3 a, px_vec3 b, double maxd,
			 struct px_control_seg_hit *out)
{
	struct counting *k = ctx;
	k->n++;
	return k->q->segment(k->q->ctx, a, b, maxd, out);
}

/* cq: qry with each of its calls counted in k (k->n from 0). */
static void counting_wrap(struct counting *k,
			  const struct px_control_query *qry,
			  struct px_control_query *cq)
{
	k->q = qry;
	k->n = 0;
	cq->point = count_point;
	cq->segment = qry->segment ? count_segment : NULL;
	cq->ctx = k;
}

static int check_caps(const struct px_control_chain *c)
{
	int i;
	for (i = 0; i < c->n_capsules; i++)
		if (c->capsules[i].link < 0 || c->capsules[i].link > c->n_joints)
			return PX_E_RANGE;
	return PX_OK;
}

/* The params and the capsules' links (PX_E_RANGE). */
static int check_setup(const struct px_control_chain *c,
		       const struct px_control_avoid_params *p)
{
	int rc = px_control_avoid_params_check(p);
	return rc ? rc : check_caps(c);
}

int px_control_chain_clearances(const struct px_control_chain *c,
				const struct px_control_avoid_params *p,
				const struct px_control_query *qry,
				const double *q, double max_distance_m,
				struct px_control_clearance *out, int *n_queries)
{
	px_pose frames[PX_CONTROL_MAX_JOINTS + 1];
	struct counting k;
	struct px_control_query cq;
	int rc;
	if (n_queries)
		*n_queries = 0;
	if (!chain_valid(c) || !p || !qry || !qry->point || !out ||
	    (c->n_joints > 0 && !q))
		return PX_E_INVAL;
	if (!(max_distance_m > 0))
		return PX_E_RANGE;
	rc = check_setup(c, p);
	if (rc)
		return rc;
	rc = fk_full(c, q, frames, NULL, NULL);
	if (rc)
		return rc;
	counting_wrap(&k, qry, &cq);
	rc = clearances(c, p, &cq, frames, max_distance_m, out);
	if (n_queries)
		*n_queries = k.n;
	return rc;
}

static double ramp(double c, double lo, double hi)
{
	if (c <= lo)
		return 0.0;
	if (c >= hi)
		return 1.0;
	return (c - lo) / (hi - lo);
}

/* Jacobian row of a contact: g = J^T n at the contact point, minus the
 * other link's when the other side moves too (self-clearance); the
 * clearance grows at g . qdot. */
static double contact_grad(const struct px_control_chain *c, const px_vec3 *ax,
			   const px_vec3 *org, const struct px_control_contact *k,
			   double *g)
{
	px_vec3 jac[PX_CONTROL_MAX_JOINTS];
	double g2 = 0;
	int j;
	jac_from(c, ax, org, k->link, k->point_m, jac);
	for (j = 0; j < c->n_joints; j++)
		g[j] = px_v3_dot(jac[j], k->normal);
	if (k->other_link >= 0) {
		jac_from(c, ax, org, k->other_link, k->other_m, jac);
		for (j = 0; j < c->n_joints; j++)
			g[j] -= px_v3_dot(jac[j], k->normal);
	}
	for (j = 0; j < c->n_joints; j++)
		g2 += g[j] * g[j];
	return g2;
}

/* A contact's own distances, else the params'. */
static double k_infl(const struct px_control_avoid_params *p,
		     const struct px_control_contact *k)
{
	return k->influence_distance_m > 0 ? k->influence_distance_m
					   : p->influence_distance_m;
}

static double k_prot(const struct px_control_avoid_params *p,
		     const struct px_control_contact *k)
{
	return k->influence_distance_m > 0 ? k->protective_distance_m
					   : p->protective_distance_m;
}

/* The command from the contacts (their clearances certified lower
 * bounds): see px_control_avoid_command(). qd is the nominal velocity;
 * out->qdot, scale, min_clearance_m and *closest (contact index, -1)
 * are set. The scale is the smallest ramp over the contacts, which for
 * contacts sharing the params' distances is the ramp of the smallest
 * clearance (the ramp is monotone). */
static void command(const struct px_control_chain *c,
		    const struct px_control_avoid_params *p, const px_vec3 *ax,
		    const px_vec3 *org, const double *qd, double T,
		    const struct px_control_contact *ks, int nk,
		    struct px_control_avoid_out *out, int *closest)
{
	double s = 1.0, sigma = 1.0, vmax = 0;
	int i, j, n = c->n_joints;

	/* Speed and separation monitoring on the certified clearances
	 * (approach_only: of the contacts the nominal motion closes). */
	out->min_clearance_m = p->influence_distance_m;
	*closest = -1;
	for (i = 0; i < nk; i++) {
		double lo = k_prot(p, &ks[i]), hi = k_infl(p, &ks[i]);
		if (ks[i].clearance_m < out->min_clearance_m) {
			out->min_clearance_m = ks[i].clearance_m;
			*closest = i;
		}
		if (ks[i].clearance_m >= hi)
			continue;
		if (p->approach_only) {
			double g[PX_CONTROL_MAX_JOINTS], rate = 0;
			double g2 = contact_grad(c, ax, org, &ks[i], g);
			for (j = 0; j < n; j++)
				rate -= g[j] * qd[j];
			/* closing faster than a nanometre per second, or no
			 * direction (touching unsigned models, a singular
			 * point): approaching */
			if (!(rate > 1e-9 || g2 < 1e-12))
				continue;
		}
		s = fmin(s, ramp(ks[i].clearance_m, lo, hi));
	}
	for (i = 0; i < n; i++)
		out->qdot[i] = s * qd[i];

	/* Repulsion: minimum-norm joint velocity moving contact i's point
	 * along its normal at w_i * v_rep (direction J^T n). */
	for (i = 0; i < nk; i++) {
		const struct px_control_contact *ci = &ks[i];
		double w, g2, g[PX_CONTROL_MAX_JOINTS];
		double lo = k_prot(p, ci), hi = k_infl(p, ci);
		if (ci->clearance_m >= hi)
			continue;
		w = 1.0 - ramp(ci->clearance_m, lo, hi);
		g2 = contact_grad(c, ax, org, ci, g);
		if (g2 < 1e-12)
			continue; /* no joint can move this point away */
		for (j = 0; j < n; j++)
			out->qdot[j] += g[j] * (w * p->repulsive_speed_m_per_s / g2);
	}

	for (j = 0; j < n; j++)
		vmax = fmax(vmax, fabs(out->qdot[j]));
	if (vmax > p->max_joint_velocity)
		for (j = 0; j < n; j++)
			out->qdot[j] *= p->max_joint_velocity / vmax;

	/* Discrete-time guard: no contact may close more than the given
	 * fraction of its margin to the protective distance in one period
	 * (first order; with the fraction below 1 the curvature of the
	 * motion within one period is covered). */
	for (i = 0; i < nk; i++) {
		const struct px_control_contact *ci = &ks[i];
		double rate = 0, margin, g[PX_CONTROL_MAX_JOINTS];
		contact_grad(c, ax, org, ci, g);
		for (j = 0; j < n; j++)
			rate -= g[j] * out->qdot[j];
		if (rate <= 0)
			continue;
		margin = ci->clearance_m - k_prot(p, ci);
		if (margin <= 0)
			sigma = 0;
		else
			sigma = fmin(sigma, p->max_margin_fraction * margin /
						    (rate * T));
	}
	if (sigma < 1)
		for (j = 0; j < n; j++)
			out->qdot[j] *= sigma;
	out->scale = s * sigma;
}

/* Common checks and the nominal velocity of both commands. */
static int command_begin(const struct px_control_chain *c,
			 const struct px_control_avoid_params *p, const double *q,
			 const double *qdot_nominal, int64_t period_ns,
			 int bad_input, struct px_control_avoid_out *out,
			 double *qd)
{
	int i, rc;
	if (!out)
		return PX_E_INVAL;
	memset(out->qdot, 0, sizeof(out->qdot));
	out->scale = 0;
	out->min_clearance_m = 0;
	out->closest_capsule = -1;
	out->point_queries = 0;
	if (bad_input || !chain_valid(c) || !p || (c->n_joints > 0 && !q) ||
	    period_ns <= 0)
		return PX_E_INVAL;
	rc = check_setup(c, p);
	if (rc)
		return rc;
	for (i = 0; i < c->n_joints; i++) {
		qd[i] = qdot_nominal ? qdot_nominal[i] : 0.0;
		if (!isfinite(qd[i]))
			return PX_E_NAN;
	}
	return PX_OK;
}

int px_control_avoid_step(const struct px_control_chain *c,
			  const struct px_control_avoid_params *p,
			  const struct px_control_query *qry, const double *q,
			  const double *qdot_nominal, int64_t period_ns,
			  struct px_control_avoid_out *out)
{
	px_pose frames[PX_CONTROL_MAX_JOINTS + 1];
	px_vec3 ax[PX_CONTROL_MAX_JOINTS], org[PX_CONTROL_MAX_JOINTS];
	double qd[PX_CONTROL_MAX_JOINTS];
	struct px_control_contact ks[PX_CONTROL_MAX_CAPSULES];
	int cap_of[PX_CONTROL_MAX_CAPSULES];
	struct counting k;
	struct px_control_query cq;
	int i, nk = 0, closest, rc;
	rc = command_begin(c, p, q, qdot_nominal, period_ns, !qry || !qry->point,
			   out, qd);
	if (rc)
		return rc;
	rc = fk_full(c, q, frames, ax, org);
	if (rc)
		return rc;
	counting_wrap(&k, qry, &cq);
	rc = clearances(c, p, &cq, frames, p->influence_distance_m, out->caps);
	out->point_queries = k.n;
	if (rc < 0)
		return rc;
	for (i = 0; i < c->n_capsules; i++) {
		const struct px_control_clearance *ci = &out->caps[i];
		if (!ci->valid)
			continue;
		ks[nk].link = c->capsules[i].link;
		ks[nk].other_link = -1;
		ks[nk].clearance_m = ci->lower_bound_m;
		ks[nk].point_m = ci->point_m;
		ks[nk].other_m = ci->obstacle_m;
		ks[nk].normal = ci->normal;
		ks[nk].influence_distance_m = 0;
		ks[nk].protective_distance_m = 0;
		cap_of[nk++] = i;
	}
	command(c, p, ax, org, qd, (double)period_ns * 1e-9, ks, nk, out, &closest);
	out->closest_capsule = closest >= 0 ? cap_of[closest] : -1;
	return PX_OK;
}

int px_control_avoid_command(const struct px_control_chain *c,
			     const struct px_control_avoid_params *p,
			     const double *q, const double *qdot_nominal,
			     int64_t period_ns,
			     const struct px_control_contact *contacts, int n,
			     struct px_control_avoid_out *out, int *closest)
{
	px_pose frames[PX_CONTROL_MAX_JOINTS + 1];
	px_vec3 ax[PX_CONTROL_MAX_JOINTS], org[PX_CONTROL_MAX_JOINTS];
	double qd[PX_CONTROL_MAX_JOINTS];
	int i, k, rc;
	if (closest)
		*closest = -1;
	rc = command_begin(c, p, q, qdot_nominal, period_ns,
			   n < 0 || (n > 0 && !contacts), out, qd);
	if (rc)
		return rc;
	for (i = 0; i < n; i++) {
		const struct px_control_contact *ci = &contacts[i];
		if (ci->link < 0 || ci->link > c->n_joints ||
		    ci->other_link < -1 || ci->other_link > c->n_joints)
			return PX_E_RANGE;
		if (!(ci->influence_distance_m >= 0) ||
		    (ci->influence_distance_m > 0 &&
		     !(ci->protective_distance_m >= 0 &&
		       ci->protective_distance_m < ci->influence_distance_m)))
			return PX_E_RANGE;
		if (!isfinite(ci->clearance_m) || !px_v3_isfinite(ci->point_m) ||
		    !px_v3_isfinite(ci->other_m) || !px_v3_isfinite(ci->normal))
			return PX_E_NAN;
	}
	rc = fk_full(c, q, frames, ax, org);
	if (rc)
		return rc;
	command(c, p, ax, org, qd, (double)period_ns * 1e-9, contacts, n, out, &k);
	if (closest)
		*closest = k;
	return PX_OK;
}
