/*
 * Haptic rendering: penalty spring-damper and god-object (proxy) with
 * friction and virtual coupling.
 *
 * Proxy motion. The proxy is a point that keeps about r = proxy_radius_m
 * of clearance. Each cycle it moves toward a goal (the device point,
 * pulled back by friction) as the solution of the small constraint
 * problem of Zilles and Salisbury's god-object: minimise |x - goal|
 * subject to staying r above the tangent planes of up to three contacts.
 * The planes only steer; safety comes from how the proxy moves along the
 * chosen direction: from a point at distance d from the scene it steps
 * at most max(d - r, d / 2), or up to 1.9 d when the distance d1 queried
 * at the far end shows that the two balls cover the step (d + d1 > s).
 * Distance is 1-Lipschitz, so no surface point lies on a step and the
 * distance after it stays above min(d / 2, 0.9 d) > 0: the proxy never
 * touches, let alone crosses, any surface -
 * including thin shells, whose unsigned distance says nothing about
 * sides: the proxy's side is the side it has always been on, and the
 * contact normal (from the closest point toward the proxy) follows from
 * it. When the path closes in on a surface (distance below 2 r and
 * moving toward it), the contact plane joins the set and the direction
 * is solved again.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "control_internal.h"

#define CONTACT_BAND 2.0  /* contact when clearance < CONTACT_BAND * r */
#define APPROACH_COS -0.01 /* moving toward a surface point */
#define MAX_OUTER 16       /* constraint re-solves per cycle */
#define KNOWN_COS 0.999    /* same plane as one in the active set */
#define LOOKAHEAD 1.9      /* tentative step, in units of the clearance */

void px_control_haptic_params_default(struct px_control_haptic_params *p)
{
	if (!p)
		return;
	memset(p, 0, sizeof(*p));
	p->renderer = PX_CONTROL_PROXY;
	p->stiffness_n_per_m = 800.0;
	p->damping_n_s_per_m = 1.0;
	p->proxy_radius_m = 0.0005;
	p->static_friction = 0.0;
	p->dynamic_friction = 0.0;
	p->max_force_n = 10.0;
	p->max_force_rate_n_per_s = 2000.0;
	p->device_damping_n_s_per_m = 2.0;
	p->max_point_queries = 64;
	p->max_query_distance_m = 0.05;
}

static int params_check(const struct px_control_haptic_params *p)
{
	if (p->renderer != PX_CONTROL_PENALTY && p->renderer != PX_CONTROL_PROXY)
		return PX_E_INVAL;
	if (!(p->stiffness_n_per_m >= 0 && p->stiffness_n_per_m < 1e9) ||
	    !(p->damping_n_s_per_m >= 0 && p->damping_n_s_per_m < 1e9) ||
	    !(p->proxy_radius_m > 0 && p->proxy_radius_m < 1) ||
	    !(p->dynamic_friction >= 0) ||
	    !(p->static_friction >= p->dynamic_friction &&
	      p->static_friction < 100) ||
	    !(p->max_force_n > 0 && p->max_force_n < 1e9) ||
	    !(p->max_force_rate_n_per_s > 0) ||
	    !(p->device_damping_n_s_per_m >= 0 &&
	      p->device_damping_n_s_per_m < 1e9) ||
	    p->max_point_queries < 8 || p->max_point_queries > 1024 ||
	    !(p->max_query_distance_m > 2 * p->proxy_radius_m &&
	      p->max_query_distance_m < 1e6))
		return PX_E_RANGE;
	return PX_OK;
}

int px_control_haptic_init(struct px_control_haptic *h,
			   const struct px_control_haptic_params *p,
			   int64_t period_ns)
{
	int rc;
	if (!h || !p || period_ns <= 0)
		return PX_E_INVAL;
	rc = params_check(p);
	if (rc)
		return rc;
	memset(h, 0, sizeof(*h));
	h->p = *p;
	h->period_s = (double)period_ns * 1e-9;
	h->stiffness_limit_n_per_m = px_control_passive_stiffness_limit(
		p->device_damping_n_s_per_m, p->damping_n_s_per_m, period_ns);
	h->stable = p->stiffness_n_per_m < h->stiffness_limit_n_per_m;
	return PX_OK;
}

int px_control_haptic_warning(const struct px_control_haptic *h, char *buf,
			      size_t cap)
{
	int n;
	if (buf && cap)
		buf[0] = '\0';
	if (!h || h->stable || !buf || cap == 0)
		return 0;
	n = snprintf(buf, cap,
		     "stiffness %.6g N/m is not passive at period %.6g ms: the "
		     "sampled-wall condition b > K T / 2 + |B| (Colgate and "
		     "Schenkelberg) with device damping b = %.6g N s/m and "
		     "virtual damping B = %.6g N s/m allows K < %.6g N/m",
		     h->p.stiffness_n_per_m, h->period_s * 1e3,
		     h->p.device_damping_n_s_per_m, h->p.damping_n_s_per_m,
		     h->stiffness_limit_n_per_m > 0 ? h->stiffness_limit_n_per_m
						     : 0.0);
	if (n < 0)
		return 0;
	return n < (int)cap ? n : (int)cap - 1;
}

int px_control_haptic_reset(struct px_control_haptic *h,
			    const struct px_control_query *q, px_vec3 device_m)
{
	struct px_control_hit hit;
	int rc, used = 0;
	double r;
	if (!h || !q || !q->point)
		return PX_E_INVAL;
	if (!px_v3_isfinite(device_m))
		return PX_E_NAN;
	r = h->p.proxy_radius_m;
	h->started_ = true;
	h->sticking_ = false;
	h->crossed_ = false;
	h->n_planes_ = 0;
	h->force_n_ = px_v3(0, 0, 0);
	h->proxy_m_ = device_m;
	h->prev_proxy_m_ = device_m;
	h->prev_device_m_ = device_m;
	h->side_n_ = px_v3(0, 0, 0);
	rc = px__ctl_point(q, device_m, h->p.max_query_distance_m, &hit, &used);
	if (rc < 0)
		return rc;
	if (hit.valid) {
		h->side_n_ = hit.normal;
		/* Inside a solid, or so close to a surface that the proxy
		 * could not move: start on the surface, r out along the
		 * normal (the outward normal for solids; for a shell the side
		 * the device is on). */
		if (hit.distance_m < 0.5 * r) {
			h->proxy_m_ = px_v3_madd(hit.point_m, hit.normal, r);
			h->prev_proxy_m_ = h->proxy_m_;
		}
	}
	return PX_OK;
}

/* ---- proxy constraint solve --------------------------------------- */

/* Candidate v for active set S (bits of mask): u projected onto
 * {v : n_i . v = b_i, i in S}. Returns 0 when S is degenerate. */
static int project_set(const struct px_control_plane *pl, const double *b,
		       unsigned mask, px_vec3 u, px_vec3 *v)
{
	int idx[3], m = 0, i;
	for (i = 0; i < 3; i++)
		if (mask & (1u << i))
			idx[m++] = i;
	if (m == 0) {
		*v = u;
		return 1;
	}
	if (m == 1) {
		px_vec3 n = pl[idx[0]].n;
		*v = px_v3_madd(u, n, b[idx[0]] - px_v3_dot(n, u));
		return 1;
	}
	if (m == 2) {
		px_vec3 n0 = pl[idx[0]].n, n1 = pl[idx[1]].n;
		double c = px_v3_dot(n0, n1), det = 1.0 - c * c;
		double r0 = b[idx[0]] - px_v3_dot(n0, u);
		double r1 = b[idx[1]] - px_v3_dot(n1, u);
		double l0, l1;
		if (det < 1e-9)
			return 0;
		l0 = (r0 - c * r1) / det;
		l1 = (r1 - c * r0) / det;
		*v = px_v3_madd(px_v3_madd(u, n0, l0), n1, l1);
		return 1;
	}
	{
		px_vec3 n0 = pl[0].n, n1 = pl[1].n, n2 = pl[2].n;
		px_vec3 c12 = px_v3_cross(n1, n2), c20 = px_v3_cross(n2, n0),
			c01 = px_v3_cross(n0, n1);
		double det = px_v3_dot(n0, c12);
		if (fabs(det) < 1e-6)
			return 0;
		*v = px_v3_scale(
			px_v3_add(px_v3_add(px_v3_scale(c12, b[0]),
					    px_v3_scale(c20, b[1])),
				  px_v3_scale(c01, b[2])),
			1.0 / det);
		return 1;
	}
}

/* min |v - u| subject to n_i . v >= b_i (i < m): the optimum is the
 * projection onto the face of its active set, and is feasible, so the
 * nearest feasible face projection is it. */
static int solve_planes(const struct px_control_plane *pl, const double *b_in,
			int m, px_vec3 u, px_vec3 *out)
{
	double b[3] = {0, 0, 0};
	int pass, i;
	for (i = 0; i < m; i++)
		b[i] = b_in[i];
	for (pass = 0; pass < 2; pass++) {
		double best = INFINITY;
		unsigned mask;
		for (mask = 0; mask < (1u << m); mask++) {
			px_vec3 v;
			int ok = 1;
			double e;
			if (!project_set(pl, b, mask, u, &v))
				continue;
			for (i = 0; i < m && ok; i++)
				if (px_v3_dot(pl[i].n, v) < b[i] - 1e-12)
					ok = 0;
			if (!ok)
				continue;
			e = px_v3_dist2(v, u);
			if (e < best) {
				best = e;
				*out = v;
			}
		}
		if (best < INFINITY)
			return 1;
		/* Contradictory lifts (squeezed between close surfaces):
		 * give up lifting; v = 0 is then always feasible. */
		for (i = 0; i < m; i++)
			if (b[i] > 0)
				b[i] = 0;
	}
	*out = px_v3(0, 0, 0);
	return 0;
}

static void add_plane(struct px_control_haptic *h, const struct px_control_hit *hit,
		      px_vec3 x)
{
	int i, worst = 0;
	double worst_d = -INFINITY;
	struct px_control_plane pl = {hit->normal, hit->point_m};
	for (i = 0; i < h->n_planes_; i++) {
		if (px_v3_dot(h->planes_[i].n, pl.n) > 0.9999) {
			h->planes_[i] = pl;
			return;
		}
	}
	if (h->n_planes_ < 3) {
		h->planes_[h->n_planes_++] = pl;
		return;
	}
	/* Full: replace the plane the proxy is farthest above. */
	for (i = 0; i < 3; i++) {
		double d = px_v3_dot(h->planes_[i].n,
				     px_v3_sub(x, h->planes_[i].point_m));
		if (d > worst_d) {
			worst_d = d;
			worst = i;
		}
	}
	h->planes_[worst] = pl;
}

static void prune_planes(struct px_control_haptic *h, px_vec3 x)
{
	int i, k = 0;
	double r = h->p.proxy_radius_m;
	for (i = 0; i < h->n_planes_; i++) {
		double d = px_v3_dot(h->planes_[i].n,
				     px_v3_sub(x, h->planes_[i].point_m));
		if (d < CONTACT_BAND * r)
			h->planes_[k++] = h->planes_[i];
	}
	h->n_planes_ = k;
}

/* A contact whose plane the current direction already respects. */
static int known_plane(const struct px_control_haptic *h, px_vec3 n)
{
	int i;
	for (i = 0; i < h->n_planes_; i++)
		if (px_v3_dot(h->planes_[i].n, n) > KNOWN_COS)
			return 1;
	return 0;
}

/* Move the proxy toward goal; x, hit describe the proxy position and
 * its query answer on entry and exit. */
static int proxy_move(struct px_control_haptic *h,
		      const struct px_control_query *q, px_vec3 goal,
		      px_vec3 *x, struct px_control_hit *hit, int *used)
{
	const double r = h->p.proxy_radius_m;
	const double maxd = h->p.max_query_distance_m;
	const int budget = h->p.max_point_queries;
	int outer, rc;
	for (outer = 0; outer < MAX_OUTER; outer++) {
		px_vec3 u, v = {0, 0, 0}, dir;
		double b[3], len, t = 0;
		int i, contact = 0;
		prune_planes(h, *x);
		/* A plane holds only while some surface is within the band:
		 * planes are infinite, faces are not, so a proxy that slid
		 * past the end of a face would otherwise keep a phantom wall
		 * there. Motion stays certified by the queries either way. */
		if (!hit->valid || fabs(hit->distance_m) >= CONTACT_BAND * r)
			h->n_planes_ = 0;
		else
			add_plane(h, hit, *x);
		u = px_v3_sub(goal, *x);
		if (px_v3_norm2(u) == 0)
			return PX_OK;
		for (i = 0; i < h->n_planes_; i++)
			b[i] = r - px_v3_dot(h->planes_[i].n,
					     px_v3_sub(*x, h->planes_[i].point_m));
		solve_planes(h->planes_, b, h->n_planes_, u, &v);
		len = px_v3_norm(v);
		if (!(len > 1e-12))
			return PX_OK;
		dir = px_v3_scale(v, 1.0 / len);
		while (t < len) {
			struct px_control_hit nh;
			double d = fabs(hit->distance_m);
			double s = fmax(d - r, 0.5 * d);
			double s_try = fmin(len - t, LOOKAHEAD * d);
			px_vec3 nx;
			int accepted = 0;
			if (*used >= budget)
				return PX_OK;
			if (s > len - t)
				s = len - t;
			if (!(s > 0))
				return PX_OK;
			if (s_try > s) {
				/* Longer step, certified afterwards: the two
				 * balls of the ends cover the segment when
				 * d + d1 > s_try. Pays off when sliding along a
				 * surface, where the ball of the start alone
				 * allows only d / 2. */
				nx = px_v3_madd(*x, dir, s_try);
				rc = px__ctl_point(q, nx, maxd, &nh, used);
				if (rc < 0)
					return rc;
				if (fabs(nh.distance_m) > (s_try - d) * (1 + 1e-12) + 1e-15) {
					s = s_try;
					accepted = 1;
				} else if (*used >= budget) {
					return PX_OK;
				}
			}
			if (!accepted) {
				nx = px_v3_madd(*x, dir, s);
				rc = px__ctl_point(q, nx, maxd, &nh, used);
				if (rc < 0)
					return rc;
			}
			*x = nx;
			*hit = nh;
			t += s;
			if (nh.valid && fabs(nh.distance_m) < CONTACT_BAND * r &&
			    px_v3_dot(dir, nh.normal) < APPROACH_COS &&
			    (fabs(nh.distance_m) < 0.75 * r ||
			     !known_plane(h, nh.normal))) {
				contact = 1;
				break;
			}
		}
		if (!contact)
			return PX_OK; /* reached the constrained optimum */
	}
	return PX_OK;
}

/* Friction cone on the proxy (static mu_s while stuck, dynamic mu_d while
 * slipping): the goal keeps a tangential offset of at most mu times the
 * normal depth of the device below the contact plane. */
static px_vec3 friction_goal(struct px_control_haptic *h,
			     const struct px_control_hit *hit, px_vec3 x,
			     px_vec3 device)
{
	const double r = h->p.proxy_radius_m;
	px_vec3 u = px_v3_sub(device, x), ut, n;
	double un, depth, tn, mu;
	if (h->p.static_friction <= 0 || !hit->valid ||
	    fabs(hit->distance_m) >= CONTACT_BAND * r) {
		h->sticking_ = false;
		return device;
	}
	n = hit->normal;
	un = px_v3_dot(u, n);
	if (un >= 0) {
		h->sticking_ = false;
		return device;
	}
	depth = -un;
	ut = px_v3_madd(u, n, -un);
	tn = px_v3_norm(ut);
	mu = h->sticking_ ? h->p.static_friction : h->p.dynamic_friction;
	if (tn <= mu * depth) {
		/* Inside the cone: stick (a slipping proxy stops when the
		 * offset falls inside the dynamic cone). */
		h->sticking_ = true;
		return px_v3_madd(x, n, un);
	}
	h->sticking_ = false;
	return px_v3_madd(device, ut,
			  -h->p.dynamic_friction * depth / tn);
}

static void fill_out(struct px_control_haptic_out *out, px_vec3 f, px_vec3 proxy,
		     double dist, double pen, bool contact, bool stick,
		     unsigned flags, int used, int planes)
{
	out->force_n = f;
	out->proxy_m = proxy;
	out->distance_m = dist;
	out->penetration_m = pen;
	out->contact = contact;
	out->sticking = stick;
	out->limit_flags = flags;
	out->point_queries = used;
	out->n_planes = planes;
}

/* Ramp the force toward zero (errors, bad input). */
static int fail_step(struct px_control_haptic *h,
		     struct px_control_haptic_out *out, int rc, int used)
{
	unsigned flags;
	h->force_n_ = px_control_force_limit(px_v3(0, 0, 0), h->force_n_,
					     h->p.max_force_n,
					     h->p.max_force_rate_n_per_s *
						     h->period_s,
					     &flags);
	fill_out(out, h->force_n_, h->proxy_m_, 0, 0, false, false, flags,
		 used, 0);
	return rc;
}

/* Does the segment a..b touch a surface? Sphere tracing: true when the
 * distance falls below eps or the budget is spent (assume it did). */
static int seg_touches(const struct px_control_query *q, px_vec3 a, px_vec3 b,
		       double maxd, int budget, int *used, int *err)
{
	double len = px_v3_dist(a, b), t = 0;
	const double eps = 1e-9 + 1e-7 * len;
	px_vec3 dir;
	int k;
	if (len == 0)
		return 0;
	dir = px_v3_scale(px_v3_sub(b, a), 1.0 / len);
	for (k = 0; k < budget; k++) {
		struct px_control_hit hh;
		int rc = px__ctl_point(q, px_v3_madd(a, dir, t), maxd, &hh, used);
		if (rc < 0) {
			*err = rc;
			return 1;
		}
		if (fabs(hh.distance_m) < eps)
			return 1;
		t += fabs(hh.distance_m);
		if (t >= len)
			return 0;
	}
	return 1;
}

static int step_penalty(struct px_control_haptic *h,
			const struct px_control_query *q, px_vec3 g, px_vec3 vel,
			struct px_control_haptic_out *out)
{
	struct px_control_hit hit;
	int used = 0, rc, err = 0;
	double d, pen = 0;
	px_vec3 n, f = px_v3(0, 0, 0);
	unsigned flags;
	rc = px__ctl_point(q, g, h->p.max_query_distance_m, &hit, &used);
	if (rc < 0)
		return fail_step(h, out, rc, used);
	d = hit.distance_m;
	n = hit.normal;
	if (!hit.valid) {
		h->crossed_ = false;
	} else if (!hit.two_sided) {
		h->crossed_ = false;
		h->side_n_ = n;
	} else {
		/* Shell: the unsigned distance cannot say which side the
		 * device is on; keep the side it came from. The normal flips
		 * when the device passes through, or when it goes round a
		 * rim; only a path that touches the surface is a crossing. */
		int flipped = px_v3_dot(n, h->side_n_) < 0;
		if (!h->crossed_) {
			if (flipped &&
			    seg_touches(q, h->prev_device_m_, g,
					h->p.max_query_distance_m,
					h->p.max_point_queries - 1, &used, &err))
				h->crossed_ = true;
			else
				h->side_n_ = n;
		} else if (!flipped) {
			h->crossed_ = false;
			h->side_n_ = n;
		}
		if (err)
			return fail_step(h, out, err, used);
		if (h->crossed_) {
			d = -d;
			n = px_v3_neg(n);
		}
	}
	if (hit.valid && d < 0) {
		double fn;
		pen = -d;
		fn = h->p.stiffness_n_per_m * pen -
		     h->p.damping_n_s_per_m * px_v3_dot(vel, n);
		if (fn > 0) /* a wall pushes, never pulls */
			f = px_v3_scale(n, fn);
	}
	h->force_n_ = px_control_force_limit(f, h->force_n_, h->p.max_force_n,
					     h->p.max_force_rate_n_per_s *
						     h->period_s,
					     &flags);
	h->proxy_m_ = g;
	h->prev_proxy_m_ = g;
	fill_out(out, h->force_n_, g, d, pen, pen > 0, false, flags, used, 0);
	return PX_OK;
}

static int step_proxy(struct px_control_haptic *h,
		      const struct px_control_query *q, px_vec3 g, px_vec3 vel,
		      struct px_control_haptic_out *out)
{
	struct px_control_hit hit;
	px_vec3 x = h->proxy_m_, goal, f, vp;
	int used = 0, rc;
	unsigned flags;
	double pen = 0, dist;
	bool contact;
	rc = px__ctl_point(q, x, h->p.max_query_distance_m, &hit, &used);
	if (rc < 0)
		return fail_step(h, out, rc, used);
	if (hit.valid && !hit.two_sided && hit.distance_m < 0) {
		/* A moving solid swallowed the proxy: put it back on the
		 * surface the short way out, r outside, and start over from
		 * there (the force then pushes the device out too). */
		x = px_v3_madd(hit.point_m, hit.normal, h->p.proxy_radius_m);
		h->n_planes_ = 0;
		h->sticking_ = false;
		rc = px__ctl_point(q, x, h->p.max_query_distance_m, &hit, &used);
		if (rc < 0)
			return fail_step(h, out, rc, used);
	}
	goal = friction_goal(h, &hit, x, g);
	rc = proxy_move(h, q, goal, &x, &hit, &used);
	if (rc < 0)
		return fail_step(h, out, rc, used);
	prune_planes(h, x);
	h->prev_proxy_m_ = h->proxy_m_;
	h->proxy_m_ = x;
	contact = h->n_planes_ > 0 && px_v3_dist2(x, g) > 0;
	if (contact)
		pen = px_v3_dist(x, g);
	else
		h->sticking_ = false;
	dist = contact ? -pen : hit.distance_m;
	vp = px_v3_scale(px_v3_sub(x, h->prev_proxy_m_), 1.0 / h->period_s);
	/* Virtual coupling: spring-damper between proxy and device. */
	f = px_v3_add(px_v3_scale(px_v3_sub(x, g), h->p.stiffness_n_per_m),
		      px_v3_scale(px_v3_sub(vp, vel), h->p.damping_n_s_per_m));
	h->force_n_ = px_control_force_limit(f, h->force_n_, h->p.max_force_n,
					     h->p.max_force_rate_n_per_s *
						     h->period_s,
					     &flags);
	fill_out(out, h->force_n_, x, dist, pen, contact, h->sticking_, flags,
		 used, h->n_planes_);
	return PX_OK;
}

int px_control_haptic_step(struct px_control_haptic *h,
			   const struct px_control_query *q, px_vec3 device_m,
			   const px_vec3 *device_velocity_m_per_s,
			   struct px_control_haptic_out *out)
{
	px_vec3 vel;
	int rc;
	if (!h || !out)
		return PX_E_INVAL;
	if (!q || !q->point)
		return fail_step(h, out, PX_E_INVAL, 0);
	if (!px_v3_isfinite(device_m) ||
	    (device_velocity_m_per_s && !px_v3_isfinite(*device_velocity_m_per_s)))
		return fail_step(h, out, PX_E_NAN, 0);
	if (!h->started_) {
		rc = px_control_haptic_reset(h, q, device_m);
		if (rc < 0)
			return fail_step(h, out, rc, 1);
	}
	if (device_velocity_m_per_s)
		vel = *device_velocity_m_per_s;
	else
		vel = px_v3_scale(px_v3_sub(device_m, h->prev_device_m_),
				  1.0 / h->period_s);
	if (h->p.renderer == PX_CONTROL_PENALTY)
		rc = step_penalty(h, q, device_m, vel, out);
	else
		rc = step_proxy(h, q, device_m, vel, out);
	h->prev_device_m_ = device_m;
	return rc;
}
