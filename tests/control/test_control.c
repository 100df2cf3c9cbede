/*
 * control/: query helpers, force limits, passivity, penalty and proxy
 * rendering, friction, serial chains and collision avoidance - against
 * exact analytic shapes (half-space, sphere, box, thin plate).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "px_alloc_count.h"
#include "px_config.h"
#include "px_control.h"
#include "px_test.h"
#include "px_test_config.h"

/* ------------------------------------------------------------------ */
/* Exact analytic scene                                                */
/* ------------------------------------------------------------------ */

enum shape_kind { HALFSPACE, SPHERE, BOX, PLATE };

struct shape {
	enum shape_kind kind;
	px_vec3 c;    /* halfspace: point on plane; sphere, box, plate: centre */
	px_vec3 n;    /* halfspace: outward normal */
	double r;     /* sphere radius */
	px_vec3 h;    /* box half extents; plate: hx, hy (z ignored) */
};

#define MAX_SHAPES 6
#define MAX_TRACE 4096

struct scene {
	int n;
	struct shape s[MAX_SHAPES];
	/* query log (proxy path check) */
	int n_trace;
	px_vec3 trace[MAX_TRACE];
	int calls;
};

static double clampd(double x, double lo, double hi)
{
	return x < lo ? lo : (x > hi ? hi : x);
}

/* Exact signed distance, closest point and normal of one shape. */
static void shape_point(const struct shape *s, px_vec3 p,
			struct px_control_hit *o)
{
	o->valid = true;
	o->two_sided = false;
	switch (s->kind) {
	case HALFSPACE: {
		double d = px_v3_dot(px_v3_sub(p, s->c), s->n);
		o->distance_m = d;
		o->point_m = px_v3_madd(p, s->n, -d);
		o->normal = s->n;
		break;
	}
	case SPHERE: {
		px_vec3 v = px_v3_sub(p, s->c);
		double l = px_v3_norm(v);
		px_vec3 n = l > 0 ? px_v3_scale(v, 1.0 / l) : px_v3(0, 0, 1);
		o->distance_m = l - s->r;
		o->point_m = px_v3_madd(s->c, n, s->r);
		o->normal = n;
		break;
	}
	case BOX: {
		px_vec3 q = px_v3_sub(p, s->c);
		double a[3] = {q.x, q.y, q.z}, h[3] = {s->h.x, s->h.y, s->h.z};
		double cl[3];
		int i, inside = 1;
		for (i = 0; i < 3; i++) {
			cl[i] = clampd(a[i], -h[i], h[i]);
			if (cl[i] != a[i])
				inside = 0;
		}
		if (!inside) {
			px_vec3 c = px_v3_add(s->c, px_v3(cl[0], cl[1], cl[2]));
			px_vec3 v = px_v3_sub(p, c);
			double l = px_v3_norm(v);
			o->distance_m = l;
			o->point_m = c;
			o->normal = px_v3_scale(v, 1.0 / l);
		} else {
			int best = 0;
			double bd = INFINITY, nn[3] = {0, 0, 0};
			for (i = 0; i < 3; i++) {
				double dd = h[i] - fabs(a[i]);
				if (dd < bd) {
					bd = dd;
					best = i;
				}
			}
			nn[best] = a[best] >= 0 ? 1 : -1;
			cl[best] = nn[best] * h[best];
			o->distance_m = -bd;
			o->point_m = px_v3_add(s->c, px_v3(cl[0], cl[1], cl[2]));
			o->normal = px_v3(nn[0], nn[1], nn[2]);
		}
		break;
	}
	case PLATE: {
		px_vec3 q = px_v3_sub(p, s->c);
		px_vec3 c = px_v3_add(s->c, px_v3(clampd(q.x, -s->h.x, s->h.x),
						  clampd(q.y, -s->h.y, s->h.y), 0));
		px_vec3 v = px_v3_sub(p, c);
		double l = px_v3_norm(v);
		o->two_sided = true;
		o->distance_m = l;
		o->point_m = c;
		o->normal = l > 0 ? px_v3_scale(v, 1.0 / l) : px_v3(0, 0, 1);
		break;
	}
	}
}

static int scene_point(void *ctx, px_vec3 p, double max_distance_m,
		       struct px_control_hit *out)
{
	struct scene *sc = ctx;
	int i;
	(void)max_distance_m;
	sc->calls++;
	if (sc->n_trace < MAX_TRACE)
		sc->trace[sc->n_trace++] = p;
	out->valid = false;
	for (i = 0; i < sc->n; i++) {
		struct px_control_hit h;
		shape_point(&sc->s[i], p, &h);
		if (!out->valid || h.distance_m < out->distance_m)
			*out = h;
	}
	return PX_OK;
}

/* Distance along a segment is convex for every shape here (signed
 * distance to a convex set), so golden-section search converges to the
 * exact minimum; the half-space and sphere are solved in closed form. */
static double shape_seg(const struct shape *s, px_vec3 a, px_vec3 b, double *t_out)
{
	struct px_control_hit h;
	if (s->kind == HALFSPACE) {
		double da = px_v3_dot(px_v3_sub(a, s->c), s->n);
		double db = px_v3_dot(px_v3_sub(b, s->c), s->n);
		*t_out = da <= db ? 0 : 1;
		return fmin(da, db);
	}
	if (s->kind == SPHERE) {
		px_vec3 ab = px_v3_sub(b, a);
		double l2 = px_v3_norm2(ab);
		double t = l2 > 0 ? clampd(px_v3_dot(px_v3_sub(s->c, a), ab) / l2, 0, 1)
				  : 0;
		*t_out = t;
		return px_v3_dist(px_v3_lerp(a, b, t), s->c) - s->r;
	}
	{
		double lo = 0, hi = 1, g = 0.5 * (sqrt(5.0) - 1);
		double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo), f1, f2;
		int k;
		shape_point(s, px_v3_lerp(a, b, x1), &h);
		f1 = h.distance_m;
		shape_point(s, px_v3_lerp(a, b, x2), &h);
		f2 = h.distance_m;
		for (k = 0; k < 90; k++) {
			if (f1 <= f2) {
				hi = x2;
				x2 = x1;
				f2 = f1;
				x1 = hi - g * (hi - lo);
				shape_point(s, px_v3_lerp(a, b, x1), &h);
				f1 = h.distance_m;
			} else {
				lo = x1;
				x1 = x2;
				f1 = f2;
				x2 = lo + g * (hi - lo);
				shape_point(s, px_v3_lerp(a, b, x2), &h);
				f2 = h.distance_m;
			}
		}
		*t_out = 0.5 * (lo + hi);
		shape_point(s, px_v3_lerp(a, b, *t_out), &h);
		/* the ends may be lower for a non-strict minimum */
		{
			struct px_control_hit ha, hb;
			shape_point(s, a, &ha);
			shape_point(s, b, &hb);
			if (ha.distance_m < h.distance_m) {
				*t_out = 0;
				h = ha;
			}
			if (hb.distance_m < h.distance_m) {
				*t_out = 1;
				h = hb;
			}
		}
		return h.distance_m;
	}
}

static int scene_segment(void *ctx, px_vec3 a, px_vec3 b, double max_distance_m,
			 struct px_control_seg_hit *out)
{
	struct scene *sc = ctx;
	int i;
	double best = INFINITY;
	(void)max_distance_m;
	sc->calls++;
	out->hit.valid = false;
	for (i = 0; i < sc->n; i++) {
		double t, d = shape_seg(&sc->s[i], a, b, &t);
		if (d < best) {
			best = d;
			out->t = t;
			shape_point(&sc->s[i], px_v3_lerp(a, b, t), &out->hit);
		}
	}
	out->lower_bound_m = out->hit.valid ? out->hit.distance_m : 0;
	return PX_OK;
}

/* Exact scene distance of a segment (reference). */
static double ref_seg(const struct scene *sc, px_vec3 a, px_vec3 b)
{
	double best = INFINITY, t;
	int i;
	for (i = 0; i < sc->n; i++)
		best = fmin(best, shape_seg(&sc->s[i], a, b, &t));
	return best;
}

static double ref_point(const struct scene *sc, px_vec3 p)
{
	double best = INFINITY;
	int i;
	for (i = 0; i < sc->n; i++) {
		struct px_control_hit h;
		shape_point(&sc->s[i], p, &h);
		best = fmin(best, h.distance_m);
	}
	return best;
}

static struct px_control_query query_of(struct scene *sc, int with_segment)
{
	struct px_control_query q = {scene_point,
				     with_segment ? scene_segment : NULL, sc};
	return q;
}

static struct shape halfspace(px_vec3 c, px_vec3 n)
{
	struct shape s = {HALFSPACE, c, n, 0, {0, 0, 0}};
	return s;
}
static struct shape sphere(px_vec3 c, double r)
{
	struct shape s = {SPHERE, c, {0, 0, 1}, r, {0, 0, 0}};
	return s;
}
static struct shape box(px_vec3 c, px_vec3 h)
{
	struct shape s = {BOX, c, {0, 0, 1}, 0, h};
	return s;
}
static struct shape plate(px_vec3 c, double hx, double hy)
{
	struct shape s = {PLATE, c, {0, 0, 1}, 0, {hx, hy, 0}};
	return s;
}

static px_vec3 rand_v3(double lo, double hi)
{
	return px_v3(px_rand_range(lo, hi), px_rand_range(lo, hi),
		     px_rand_range(lo, hi));
}

/* ------------------------------------------------------------------ */
/* Query helpers, limits, passivity bound                              */
/* ------------------------------------------------------------------ */

static void test_segment_search_bounds(void)
{
	static struct scene sc;
	int it;
	for (it = 0; it < 300; it++) {
		struct px_control_query q = query_of(&sc, 0);
		struct px_control_seg_hit sh;
		px_vec3 a = rand_v3(-0.3, 0.3), b = rand_v3(-0.3, 0.3);
		double ref;
		int budget = px_rand_int(2, 64), rc;
		memset(&sc, 0, sizeof(sc));
		sc.n = 3;
		sc.s[0] = sphere(rand_v3(-0.2, 0.2), px_rand_range(0.01, 0.1));
		sc.s[1] = box(rand_v3(-0.2, 0.2), rand_v3(0.01, 0.1));
		sc.s[2] = plate(rand_v3(-0.2, 0.2), 0.05, 0.08);
		ref = ref_seg(&sc, a, b);
		rc = px_control_query_segment(&q, a, b, 10.0, budget, 1e-6, &sh);
		PX_CHECK_INT_EQ(rc, PX_OK);
		PX_CHECK_MSG(sc.calls <= budget, "%d calls > budget %d", sc.calls,
			     budget);
		PX_CHECK_MSG(sh.lower_bound_m <= ref + 1e-12,
			     "lower bound %.17g above exact %.17g",
			     sh.lower_bound_m, ref);
		PX_CHECK_MSG(sh.hit.distance_m >= ref - 1e-12,
			     "sample %.17g below exact %.17g", sh.hit.distance_m,
			     ref);
		/* the reported point is the sample at t */
		PX_CHECK_NEAR(ref_point(&sc, px_v3_lerp(a, b, sh.t)),
			      sh.hit.distance_m, 1e-12);
		if (budget == 64 && ref > 0)
			PX_CHECK_MSG(sh.hit.distance_m - ref < 0.02,
				     "64 queries left a gap of %g",
				     sh.hit.distance_m - ref);
	}
	{
		/* exact callback is passed through */
		struct px_control_query q = query_of(&sc, 1);
		struct px_control_seg_hit sh;
		px_vec3 a = px_v3(-0.2, 0, 0.3), b = px_v3(0.2, 0, 0.3);
		memset(&sc, 0, sizeof(sc));
		sc.n = 1;
		sc.s[0] = sphere(px_v3(0.05, 0, 0), 0.1);
		PX_CHECK_INT_EQ(px_control_query_segment(&q, a, b, 1, 8, 0, &sh),
				PX_OK);
		PX_CHECK_NEAR(sh.hit.distance_m, 0.2, 1e-15);
		PX_CHECK_NEAR(sh.t, 0.625, 1e-15);
		PX_CHECK_NEAR(sh.lower_bound_m, 0.2, 1e-15);
	}
}

static void test_force_limit(void)
{
	int it;
	for (it = 0; it < 2000; it++) {
		double maxf = px_rand_range(0.1, 20), step = px_rand_range(0, 5);
		px_vec3 prev = rand_v3(-1, 1), t = rand_v3(-40, 40), f;
		unsigned fl;
		if (px_v3_norm(prev) > maxf)
			prev = px_v3_scale(prev, maxf / px_v3_norm(prev) * 0.99);
		if (it % 7 == 0)
			prev = rand_v3(-40, 40); /* clamp lowered since */
		f = px_control_force_limit(t, prev, maxf, step, &fl);
		PX_CHECK_MSG(px_v3_norm(f) <= maxf * (1 + 1e-12), "|f| %g > %g",
			     px_v3_norm(f), maxf);
		if (px_v3_norm(prev) <= maxf)
			PX_CHECK_MSG(px_v3_dist(f, prev) <= step * (1 + 1e-12) + 1e-15,
				     "step %g > %g", px_v3_dist(f, prev), step);
		if (px_v3_norm(t) <= maxf && px_v3_dist(t, prev) <= step) {
			PX_CHECK(fl == 0);
			PX_CHECK_NEAR(px_v3_dist(f, t), 0, 1e-15);
		}
		if (px_v3_norm(t) > maxf)
			PX_CHECK(fl & PX_CONTROL_FORCE_CLAMPED);
	}
	{
		px_vec3 f = px_control_force_limit(px_v3(NAN, 0, 0), px_v3(1, 0, 0),
						   5, 1, NULL);
		PX_CHECK(f.x == 1 && f.y == 0 && f.z == 0);
	}
}

static void test_passive_limit_formula(void)
{
	struct px_control_haptic_params p;
	struct px_control_haptic h;
	char msg[400];
	/* b = 2 N s/m, B = 0.5 N s/m, T = 1 ms: K < 2 (2 - 0.5) / 0.001 */
	PX_CHECK_NEAR(px_control_passive_stiffness_limit(2.0, 0.5, 1000000),
		      3000.0, 1e-9);
	PX_CHECK_NEAR(px_control_passive_stiffness_limit(2.0, -0.5, 250000),
		      12000.0, 1e-9);
	PX_CHECK(px_control_passive_stiffness_limit(1.0, 2.0, 1000000) < 0);
	px_control_haptic_params_default(&p);
	p.device_damping_n_s_per_m = 2.0;
	p.damping_n_s_per_m = 0.5;
	p.stiffness_n_per_m = 2999.0;
	PX_CHECK_INT_EQ(px_control_haptic_init(&h, &p, 1000000), PX_OK);
	PX_CHECK(h.stable);
	PX_CHECK_INT_EQ(px_control_haptic_warning(&h, msg, sizeof(msg)), 0);
	PX_CHECK(msg[0] == '\0');
	p.stiffness_n_per_m = 3001.0;
	PX_CHECK_INT_EQ(px_control_haptic_init(&h, &p, 1000000), PX_OK);
	PX_CHECK(!h.stable);
	PX_CHECK(px_control_haptic_warning(&h, msg, sizeof(msg)) > 0);
	PX_CHECK_MSG(strstr(msg, "3001 N/m") && strstr(msg, "K < 3000 N/m") &&
			     strstr(msg, "b > K T / 2 + |B|"),
		     "%s", msg);
	/* the same stiffness is fine at 4 kHz */
	PX_CHECK_INT_EQ(px_control_haptic_init(&h, &p, 250000), PX_OK);
	PX_CHECK(h.stable);
	/* bad parameters */
	p.dynamic_friction = 0.5;
	p.static_friction = 0.3;
	PX_CHECK_INT_EQ(px_control_haptic_init(&h, &p, 1000000), PX_E_RANGE);
	px_control_haptic_params_default(&p);
	p.renderer = 7;
	PX_CHECK_INT_EQ(px_control_haptic_init(&h, &p, 1000000), PX_E_INVAL);
	px_control_haptic_params_default(&p);
	PX_CHECK_INT_EQ(px_control_haptic_init(&h, &p, 0), PX_E_INVAL);
	p.max_force_n = 0;
	PX_CHECK_INT_EQ(px_control_haptic_init(&h, &p, 1000000), PX_E_RANGE);
}

/* ------------------------------------------------------------------ */
/* Passivity of a sampled virtual wall                                 */
/* ------------------------------------------------------------------ */

struct osc {
	double c, a[3], w[3], ph[3];
};

static double osc_raw(const struct osc *o, double t)
{
	return o->c + o->a[0] * sin(o->w[0] * t + o->ph[0]) +
	       o->a[1] * sin(o->w[1] * t + o->ph[1]) +
	       o->a[2] * sin(o->w[2] * t + o->ph[2]);
}

static double osc_raw_v(const struct osc *o, double t)
{
	return o->a[0] * o->w[0] * cos(o->w[0] * t + o->ph[0]) +
	       o->a[1] * o->w[1] * cos(o->w[1] * t + o->ph[1]) +
	       o->a[2] * o->w[2] * cos(o->w[2] * t + o->ph[2]);
}

/* The motion starts 20 mm outside the wall (nothing stored) and blends
 * into the oscillation over the first 0.2 s. */
#define OSC_OUT 0.02
#define OSC_RAMP 0.2

static double osc_z(const struct osc *o, double t)
{
	double s = t < OSC_RAMP ? pow(sin(M_PI * t / (2 * OSC_RAMP)), 2) : 1;
	return OSC_OUT + (osc_raw(o, t) - OSC_OUT) * s;
}

static double osc_v(const struct osc *o, double t)
{
	double s = 1, ds = 0;
	if (t < OSC_RAMP) {
		double a = M_PI * t / (2 * OSC_RAMP);
		s = pow(sin(a), 2);
		ds = 2 * sin(a) * cos(a) * M_PI / (2 * OSC_RAMP);
	}
	return osc_raw_v(o, t) * s + (osc_raw(o, t) - OSC_OUT) * ds;
}

/*
 * Drive the device along z(t) (imposed by the hand) against the wall
 * z < 0 rendered by the penalty renderer at period T, the force held
 * between samples. The display (wall + device damper b) is passive when
 * the energy it has taken from the hand, E(t) = int b v^2 dt - int F v dt,
 * never goes below zero (it starts outside the wall, storing nothing;
 * the device mass only adds a non-negative kinetic term).
 * Returns the smallest E(t) seen.
 */
static double wall_energy_min(double k, double bv, double b, const struct osc *o,
			      int cycles)
{
	static struct scene sc;
	struct px_control_query q = query_of(&sc, 0);
	struct px_control_haptic_params p;
	struct px_control_haptic h;
	const int64_t period_ns = 1000000;
	const double T = 1e-3;
	double e = 0, emin = 0;
	int k_i;
	memset(&sc, 0, sizeof(sc));
	sc.n = 1;
	sc.s[0] = halfspace(px_v3(0, 0, 0), px_v3(0, 0, 1));
	px_control_haptic_params_default(&p);
	p.renderer = PX_CONTROL_PENALTY;
	p.stiffness_n_per_m = k;
	p.damping_n_s_per_m = bv;
	p.device_damping_n_s_per_m = b;
	p.max_force_n = 1e6;
	p.max_force_rate_n_per_s = 1e15;
	p.max_query_distance_m = 1.0;
	PX_CHECK_INT_EQ(px_control_haptic_init(&h, &p, period_ns), PX_OK);
	/* the setup-time warning agrees with the condition */
	PX_CHECK(h.stable == (k < px_control_passive_stiffness_limit(b, bv,
								      period_ns)));
	{
		char msg[400];
		PX_CHECK((px_control_haptic_warning(&h, msg, sizeof(msg)) > 0) ==
			 !h.stable);
	}
	for (k_i = 0; k_i < cycles; k_i++) {
		struct px_control_haptic_out out;
		double t0 = k_i * T, t1 = t0 + T, tm = 0.5 * (t0 + t1);
		double z0 = osc_z(o, t0), z1 = osc_z(o, t1), v0, v1, vm;
		PX_CHECK_INT_EQ(px_control_haptic_step(&h, &q, px_v3(0, 0, z0),
						       NULL, &out),
				PX_OK);
		v0 = osc_v(o, t0);
		v1 = osc_v(o, t1);
		vm = osc_v(o, tm);
		/* Simpson on v^2 over [t0, t1]: exact enough at these rates */
		e += b * T / 6.0 * (v0 * v0 + 4 * vm * vm + v1 * v1);
		e -= out.force_n.z * (z1 - z0);
		if (e < emin)
			emin = e;
	}
	return emin;
}

static void random_osc(struct osc *o)
{
	int i;
	o->c = px_rand_range(-0.012, 0.004);
	for (i = 0; i < 3; i++) {
		o->a[i] = px_rand_range(0.0005, 0.008);
		o->w[i] = 2 * M_PI * px_rand_range(0.5, 25.0);
		o->ph[i] = px_rand_range(0, 2 * M_PI);
	}
}

static void test_wall_passivity_energy(void)
{
	int it, generated = 0;
	for (it = 0; it < 24; it++) {
		struct osc o;
		double b = px_rand_range(0.5, 5.0);
		double bv = px_rand_range(0, 0.3) * b;
		double lim = px_control_passive_stiffness_limit(b, bv, 1000000);
		double emin;
		random_osc(&o);
		/* condition met: the wall never returns more than it took */
		emin = wall_energy_min(px_rand_range(0.3, 0.95) * lim, bv, b, &o,
				       1500);
		PX_CHECK_MSG(emin >= -1e-12,
			     "passive setting generated %.3g J (b %g, B %g)",
			     -emin, b, bv);
		/* violated (3x the limit): the same check must see energy
		 * generation on an oscillation that is mostly in contact */
		o.a[0] = px_rand_range(0.002, 0.01);
		o.w[0] = 2 * M_PI * px_rand_range(3.0, 25.0);
		o.a[1] = o.a[2] = 0;
		o.c = -0.7 * o.a[0];
		emin = wall_energy_min(3.0 * lim, bv, b, &o, 3000);
		if (emin < -1e-6)
			generated++;
	}
	PX_CHECK_MSG(generated == 24,
		     "energy generation seen in only %d of 24 violating runs",
		     generated);
}

/* ------------------------------------------------------------------ */
/* Proxy: never inside, never through                                  */
/* ------------------------------------------------------------------ */

/* Does the closed segment a..b touch or enter the shape? Exact. */
static int seg_enters(const struct shape *s, px_vec3 a, px_vec3 b)
{
	double t;
	switch (s->kind) {
	case HALFSPACE:
	case SPHERE:
		return shape_seg(s, a, b, &t) <= 0;
	case BOX: {
		/* slab clipping */
		double lo = 0, hi = 1;
		double pa[3] = {a.x - s->c.x, a.y - s->c.y, a.z - s->c.z};
		double d[3] = {b.x - a.x, b.y - a.y, b.z - a.z};
		double h[3] = {s->h.x, s->h.y, s->h.z};
		int i;
		for (i = 0; i < 3; i++) {
			if (d[i] == 0) {
				if (fabs(pa[i]) > h[i])
					return 0;
			} else {
				double t1 = (-h[i] - pa[i]) / d[i];
				double t2 = (h[i] - pa[i]) / d[i];
				if (t1 > t2) {
					double x = t1;
					t1 = t2;
					t2 = x;
				}
				lo = fmax(lo, t1);
				hi = fmin(hi, t2);
				if (lo > hi)
					return 0;
			}
		}
		return 1;
	}
	case PLATE: {
		double za = a.z - s->c.z, zb = b.z - s->c.z;
		px_vec3 x;
		if (za == 0 && zb == 0)
			return fabs(a.x - s->c.x) <= s->h.x ||
			       fabs(b.x - s->c.x) <= s->h.x; /* coarse */
		if ((za > 0 && zb > 0) || (za < 0 && zb < 0))
			return 0;
		x = px_v3_lerp(a, b, za / (za - zb));
		return fabs(x.x - s->c.x) <= s->h.x &&
		       fabs(x.y - s->c.y) <= s->h.y;
	}
	}
	return 1;
}

/*
 * Rebuild the proxy path of one cycle from the query log and check that
 * no edge of it touches a shape. Every query is either a step from the
 * current vertex of at most max(d - r, d / 2) (taken), or a longer
 * look-ahead, taken only when the balls of both ends cover it
 * (d + d1 > s); the rebuilt path must end at the reported proxy.
 */
static void check_trace(const struct scene *sc, px_vec3 *last, double r,
			px_vec3 proxy, int cycle)
{
	int i, j;
	for (i = 0; i < sc->n_trace; i++) {
		px_vec3 b = sc->trace[i];
		double d = fabs(ref_point(sc, *last)), s = px_v3_dist(*last, b);
		if (s > fmax(d - r, 0.5 * d) * (1 + 1e-9) + 1e-15 &&
		    !(fabs(ref_point(sc, b)) > (s - d) * (1 + 1e-12) + 1e-15))
			continue; /* rejected look-ahead */
		for (j = 0; j < sc->n; j++)
			PX_CHECK_MSG(!seg_enters(&sc->s[j], *last, b),
				     "cycle %d: proxy path (%.9g %.9g %.9g) -> "
				     "(%.9g %.9g %.9g) enters shape %d",
				     cycle, last->x, last->y, last->z, b.x, b.y,
				     b.z, j);
		*last = b;
	}
	PX_CHECK_MSG(px_v3_dist(*last, proxy) < 1e-12,
		     "cycle %d: path ends %.3g m from the proxy", cycle,
		     px_v3_dist(*last, proxy));
}

static int make_scene(struct scene *sc, int which)
{
	memset(sc, 0, sizeof(*sc));
	switch (which) {
	case 0:
		sc->s[sc->n++] = sphere(px_v3(0, 0, 0), 0.05);
		break;
	case 1:
		sc->s[sc->n++] = box(px_v3(0, 0, 0), px_v3(0.04, 0.03, 0.02));
		break;
	case 2:
		sc->s[sc->n++] = halfspace(px_v3(0, 0, -0.01), px_v3(0, 0, 1));
		break;
	case 3:
		sc->s[sc->n++] = plate(px_v3(0, 0, 0), 0.05, 0.05);
		break;
	case 4: /* two plates 4 mm apart: thin slot */
		sc->s[sc->n++] = plate(px_v3(0, 0, 0), 0.06, 0.06);
		sc->s[sc->n++] = plate(px_v3(0, 0.01, 0.004), 0.06, 0.06);
		break;
	default: /* plate resting on a box corner, and a sphere */
		sc->s[sc->n++] = box(px_v3(0.03, 0, -0.03), px_v3(0.03, 0.03, 0.03));
		sc->s[sc->n++] = plate(px_v3(0, 0, 0.0005), 0.05, 0.04);
		sc->s[sc->n++] = sphere(px_v3(-0.05, 0.05, 0.03), 0.02);
		break;
	}
	return sc->n;
}

static void run_random_proxy(int which, double mu_s, double mu_d)
{
	static struct scene sc;
	struct px_control_query q = query_of(&sc, 0);
	struct px_control_haptic_params p;
	struct px_control_haptic h;
	px_vec3 dev, last;
	int run, k;
	make_scene(&sc, which);
	px_control_haptic_params_default(&p);
	p.stiffness_n_per_m = px_rand_range(300, 3000);
	p.damping_n_s_per_m = px_rand_range(0, 1.0);
	p.static_friction = mu_s;
	p.dynamic_friction = mu_d;
	p.proxy_radius_m = px_rand_range(0.0002, 0.001);
	p.max_force_n = px_rand_range(2, 10);
	p.max_force_rate_n_per_s = px_rand_range(500, 20000);
	p.max_query_distance_m = 0.2;
	for (run = 0; run < 6; run++) {
		struct px_control_haptic_out out;
		PX_CHECK_INT_EQ(px_control_haptic_init(&h, &p, 1000000), PX_OK);
		do
			dev = rand_v3(-0.09, 0.09);
		while (ref_point(&sc, dev) < 0.002);
		PX_CHECK_INT_EQ(px_control_haptic_reset(&h, &q, dev), PX_OK);
		last = dev;
		for (k = 0; k < 800; k++) {
			double sigma = (k / 100) % 2 ? 0.003 : 0.0003;
			if (px_rand_unit() < 0.03)
				dev = rand_v3(-0.09, 0.09); /* fast jump */
			else
				dev = px_v3_add(dev, px_v3(sigma * px_rand_normal(),
							   sigma * px_rand_normal(),
							   sigma * px_rand_normal()));
			dev.x = clampd(dev.x, -0.1, 0.1);
			dev.y = clampd(dev.y, -0.1, 0.1);
			dev.z = clampd(dev.z, -0.1, 0.1);
			sc.n_trace = 0;
			PX_CHECK_INT_EQ(px_control_haptic_step(&h, &q, dev, NULL,
							       &out),
					PX_OK);
			PX_CHECK(out.point_queries <= p.max_point_queries);
			PX_CHECK_MSG(px_v3_norm(out.force_n) <=
					     p.max_force_n * (1 + 1e-12),
				     "force %g > clamp %g",
				     px_v3_norm(out.force_n), p.max_force_n);
			check_trace(&sc, &last, p.proxy_radius_m, out.proxy_m, k);
			PX_CHECK_MSG(ref_point(&sc, out.proxy_m) > 0,
				     "proxy inside: %.3g",
				     ref_point(&sc, out.proxy_m));
		}
	}
}

static void test_proxy_never_crosses_random(void)
{
	int which;
	for (which = 0; which < 6; which++)
		run_random_proxy(which, 0, 0);
}

static void test_proxy_never_crosses_with_friction(void)
{
	int which;
	for (which = 0; which < 6; which++)
		run_random_proxy(which, 0.6, 0.4);
}

static void init_proxy(struct px_control_haptic *h, double k, double r)
{
	struct px_control_haptic_params p;
	px_control_haptic_params_default(&p);
	p.stiffness_n_per_m = k;
	p.damping_n_s_per_m = 0;
	p.proxy_radius_m = r;
	p.max_force_n = 1e3;
	p.max_force_rate_n_per_s = 1e12;
	p.max_query_distance_m = 0.5;
	PX_CHECK_INT_EQ(px_control_haptic_init(h, &p, 1000000), PX_OK);
}

/* One cycle from above a thin plate to below it: the proxy stays on top,
 * over the device, and the force pushes the device back up. */
static void test_proxy_plate_jump_through(void)
{
	static struct scene sc;
	struct px_control_query q = query_of(&sc, 0);
	struct px_control_haptic h;
	struct px_control_haptic_out out;
	int it, k;
	const double r = 0.0005;
	memset(&sc, 0, sizeof(sc));
	sc.n = 1;
	sc.s[0] = plate(px_v3(0, 0, 0), 0.05, 0.05);
	for (it = 0; it < 50; it++) {
		double side = it % 2 ? 1.0 : -1.0; /* from above or below */
		px_vec3 a = px_v3(px_rand_range(-0.04, 0.04),
				  px_rand_range(-0.04, 0.04),
				  side * px_rand_range(0.001, 0.03));
		px_vec3 b = px_v3(px_rand_range(-0.04, 0.04),
				  px_rand_range(-0.04, 0.04),
				  -side * px_rand_range(0.001, 0.03));
		init_proxy(&h, 1000, r);
		PX_CHECK_INT_EQ(px_control_haptic_reset(&h, &q, a), PX_OK);
		for (k = 0; k < 4; k++) /* hold still at b: proxy settles */
			PX_CHECK_INT_EQ(px_control_haptic_step(&h, &q, b, NULL, &out),
					PX_OK);
		PX_CHECK_MSG(out.proxy_m.z * side > 0,
			     "proxy went through: z %.9g side %g", out.proxy_m.z,
			     side);
		PX_CHECK_NEAR(out.proxy_m.x, b.x, 1e-9);
		PX_CHECK_NEAR(out.proxy_m.y, b.y, 1e-9);
		PX_CHECK_NEAR(fabs(out.proxy_m.z), r, 0.1 * r);
		PX_CHECK(out.contact);
		PX_CHECK(out.force_n.z * side > 0);
		PX_CHECK_NEAR(out.force_n.z, 1000 * (out.proxy_m.z - b.z), 1e-9);
		PX_CHECK_NEAR(out.penetration_m, px_v3_dist(out.proxy_m, b), 1e-15);
	}
}

/* Device inside a box, entered through the top face: the frictionless
 * god-object rests r above the top face over the device (reference:
 * projection onto the face); at a concave corner made of three solids,
 * all three constraints hold at once. */
static void test_proxy_faces_and_corners(void)
{
	static struct scene sc;
	struct px_control_query q = query_of(&sc, 0);
	struct px_control_haptic h;
	struct px_control_haptic_out out;
	const double r = 0.0005;
	int it, k;
	memset(&sc, 0, sizeof(sc));
	sc.n = 1;
	sc.s[0] = box(px_v3(0, 0, 0), px_v3(0.04, 0.03, 0.02));
	for (it = 0; it < 50; it++) {
		px_vec3 start = px_v3(px_rand_range(-0.03, 0.03),
				      px_rand_range(-0.02, 0.02), 0.03);
		px_vec3 dev = start;
		init_proxy(&h, 1000, r);
		PX_CHECK_INT_EQ(px_control_haptic_reset(&h, &q, start), PX_OK);
		/* press down then wander inside, below the top face */
		for (k = 0; k < 60; k++) {
			px_vec3 tgt = px_v3(start.x, start.y, -0.005);
			if (k >= 30)
				tgt = px_v3(px_rand_range(-0.038, 0.038),
					    px_rand_range(-0.028, 0.028),
					    px_rand_range(-0.015, 0.015));
			dev = px_v3_lerp(dev, tgt, k < 30 ? 0.2 : 0.05);
			PX_CHECK_INT_EQ(px_control_haptic_step(&h, &q, dev, NULL,
							       &out),
					PX_OK);
			PX_CHECK(ref_point(&sc, out.proxy_m) > 0);
		}
		for (k = 0; k < 5; k++)
			PX_CHECK_INT_EQ(px_control_haptic_step(&h, &q, dev, NULL,
							       &out),
					PX_OK);
		PX_CHECK_NEAR(out.proxy_m.x, dev.x, 1e-9);
		PX_CHECK_NEAR(out.proxy_m.y, dev.y, 1e-9);
		PX_CHECK_NEAR(out.proxy_m.z, 0.02 + r, 0.1 * r);
	}
	/* concave corner: floor z < 0, wall x > 0.1, wall y > 0.1 */
	memset(&sc, 0, sizeof(sc));
	sc.n = 3;
	sc.s[0] = halfspace(px_v3(0, 0, 0), px_v3(0, 0, 1));
	sc.s[1] = halfspace(px_v3(0.1, 0, 0), px_v3(-1, 0, 0));
	sc.s[2] = halfspace(px_v3(0, 0.1, 0), px_v3(0, -1, 0));
	for (it = 0; it < 30; it++) {
		px_vec3 dev = px_v3(0.1 + px_rand_range(0.001, 0.01),
				    0.1 + px_rand_range(0.001, 0.01),
				    -px_rand_range(0.001, 0.01));
		init_proxy(&h, 1000, r);
		PX_CHECK_INT_EQ(px_control_haptic_reset(&h, &q,
							px_v3(px_rand_range(0, 0.08),
							      px_rand_range(0, 0.08),
							      px_rand_range(0.01, 0.05))),
				PX_OK);
		for (k = 0; k < 8; k++)
			PX_CHECK_INT_EQ(px_control_haptic_step(&h, &q, dev, NULL,
							       &out),
					PX_OK);
		PX_CHECK_NEAR(out.proxy_m.x, 0.1 - r, 0.1 * r);
		PX_CHECK_NEAR(out.proxy_m.y, 0.1 - r, 0.1 * r);
		PX_CHECK_NEAR(out.proxy_m.z, r, 0.1 * r);
		PX_CHECK_INT_EQ(out.n_planes, 3);
	}
}

/* The scene moves: a sphere slides over the resting proxy. The proxy
 * is never left inside it. */
static void test_proxy_moving_solid(void)
{
	static struct scene sc;
	struct px_control_query q = query_of(&sc, 0);
	struct px_control_haptic h;
	struct px_control_haptic_out out;
	int it, k;
	for (it = 0; it < 20; it++) {
		px_vec3 dev = rand_v3(-0.01, 0.01);
		px_vec3 from = px_v3_add(dev, px_v3(0.1, 0, 0));
		px_vec3 dir = px_v3(-1, px_rand_range(-0.2, 0.2), px_rand_range(-0.2, 0.2));
		memset(&sc, 0, sizeof(sc));
		sc.n = 1;
		sc.s[0] = sphere(from, 0.03);
		init_proxy(&h, 1000, 0.0005);
		PX_CHECK_INT_EQ(px_control_haptic_reset(&h, &q, dev), PX_OK);
		for (k = 0; k < 200; k++) {
			/* 1 mm per cycle: faster than the proxy can be pushed */
			sc.s[0].c = px_v3_madd(from, dir, 0.001 * k);
			PX_CHECK_INT_EQ(px_control_haptic_step(&h, &q, dev, NULL, &out),
					PX_OK);
			PX_CHECK_MSG(ref_point(&sc, out.proxy_m) > 0,
				     "cycle %d: proxy %.3g inside", k,
				     ref_point(&sc, out.proxy_m));
		}
	}
}

/* ------------------------------------------------------------------ */
/* Friction                                                            */
/* ------------------------------------------------------------------ */

static void test_friction_stick_and_slip(void)
{
	static struct scene sc;
	struct px_control_query q = query_of(&sc, 0);
	struct px_control_haptic_params p;
	struct px_control_haptic h;
	struct px_control_haptic_out out;
	int it, k;
	memset(&sc, 0, sizeof(sc));
	sc.n = 1;
	sc.s[0] = halfspace(px_v3(0, 0, 0), px_v3(0, 0, 1));
	px_control_haptic_params_default(&p);
	p.stiffness_n_per_m = 1000;
	p.damping_n_s_per_m = 0;
	p.static_friction = 0.6;
	p.dynamic_friction = 0.35;
	p.max_force_n = 1e3;
	p.max_force_rate_n_per_s = 1e12;
	for (it = 0; it < 40; it++) {
		double depth = px_rand_range(0.002, 0.01);
		double ang = px_rand_range(0, 2 * M_PI);
		px_vec3 dir = px_v3(cos(ang), sin(ang), 0);
		px_vec3 c = px_v3(px_rand_range(-0.05, 0.05),
				  px_rand_range(-0.05, 0.05), 0);
		px_vec3 held;
		double frac = px_rand_range(0.05, 0.9), ratio;
		PX_CHECK_INT_EQ(px_control_haptic_init(&h, &p, 1000000), PX_OK);
		PX_CHECK_INT_EQ(px_control_haptic_reset(&h, &q,
							px_v3_add(c, px_v3(0, 0, 0.01))),
				PX_OK);
		/* press straight down */
		for (k = 0; k <= 10; k++)
			PX_CHECK_INT_EQ(px_control_haptic_step(
						&h, &q,
						px_v3_add(c, px_v3(0, 0, 0.01 - k * (0.01 + depth) / 10)),
						NULL, &out),
					PX_OK);
		held = out.proxy_m;
		PX_CHECK_NEAR(held.x, c.x, 1e-9);
		/* drag tangentially inside the static cone: sticks */
		for (k = 1; k <= 20; k++) {
			double s = frac * 0.6 * (depth + held.z) * k / 20;
			px_vec3 d = px_v3_add(px_v3_madd(c, dir, s), px_v3(0, 0, -depth));
			PX_CHECK_INT_EQ(px_control_haptic_step(&h, &q, d, NULL, &out),
					PX_OK);
			PX_CHECK(out.sticking);
			PX_CHECK_NEAR(px_v3_dist(out.proxy_m, held), 0, 1e-9);
			ratio = hypot(out.force_n.x, out.force_n.y) / out.force_n.z;
			PX_CHECK(ratio <= 0.6 + 1e-9);
		}
		/* drag beyond it: slips, and keeps the dynamic cone */
		for (k = 1; k <= 40; k++) {
			double s = 0.6 * (depth + held.z) * (1 + 0.1 * k);
			px_vec3 d = px_v3_add(px_v3_madd(c, dir, s), px_v3(0, 0, -depth));
			PX_CHECK_INT_EQ(px_control_haptic_step(&h, &q, d, NULL, &out),
					PX_OK);
		}
		PX_CHECK(!out.sticking);
		ratio = hypot(out.force_n.x, out.force_n.y) / out.force_n.z;
		PX_CHECK_NEAR(ratio, 0.35, 1e-3);
		/* the friction force opposes the drag */
		PX_CHECK(px_v3_dot(out.force_n, dir) < 0);
		PX_CHECK(out.proxy_m.z > 0);
	}
}

/* ------------------------------------------------------------------ */
/* Penalty rendering                                                   */
/* ------------------------------------------------------------------ */

static void init_penalty(struct px_control_haptic *h, double k, double maxf)
{
	struct px_control_haptic_params p;
	px_control_haptic_params_default(&p);
	p.renderer = PX_CONTROL_PENALTY;
	p.stiffness_n_per_m = k;
	p.damping_n_s_per_m = 0;
	p.max_force_n = maxf;
	p.max_force_rate_n_per_s = 1e12;
	p.max_query_distance_m = 0.5;
	PX_CHECK_INT_EQ(px_control_haptic_init(h, &p, 1000000), PX_OK);
}

static void test_penalty_solids(void)
{
	static struct scene sc;
	struct px_control_query q = query_of(&sc, 0);
	struct px_control_haptic h;
	struct px_control_haptic_out out;
	int it;
	for (it = 0; it < 500; it++) {
		px_vec3 p = rand_v3(-0.06, 0.06);
		struct px_control_hit ref;
		double maxf = px_rand_range(1, 30), k = 900;
		px_vec3 want = px_v3(0, 0, 0);
		make_scene(&sc, it % 3);
		init_penalty(&h, k, maxf);
		PX_CHECK_INT_EQ(px_control_haptic_step(&h, &q, p, NULL, &out), PX_OK);
		shape_point(&sc.s[0], p, &ref);
		if (ref.distance_m < 0) {
			want = px_v3_scale(ref.normal, -k * ref.distance_m);
			if (px_v3_norm(want) > maxf)
				want = px_v3_scale(want, maxf / px_v3_norm(want));
		}
		PX_CHECK_NEAR(px_v3_dist(out.force_n, want), 0, 1e-12);
		PX_CHECK(px_v3_norm(out.force_n) <= maxf * (1 + 1e-12));
		PX_CHECK_NEAR(out.distance_m, ref.distance_m, 1e-15);
		PX_CHECK(out.contact == (ref.distance_m < 0));
	}
}

/* Through a thin plate with the penalty renderer: the unsigned distance
 * grows again behind the plate and its normal flips, but the side is
 * kept by continuity, so the force keeps pushing back; going round the
 * rim is not a crossing. */
static void test_penalty_shell_side_tracking(void)
{
	static struct scene sc;
	struct px_control_query q = query_of(&sc, 0);
	struct px_control_haptic h;
	struct px_control_haptic_out out;
	int k;
	memset(&sc, 0, sizeof(sc));
	sc.n = 1;
	sc.s[0] = plate(px_v3(0, 0, 0), 0.05, 0.05);
	init_penalty(&h, 1000, 100);
	for (k = 0; k <= 40; k++) {
		double z = 0.01 - k * 0.0005; /* 10 mm above to 10 mm below */
		PX_CHECK_INT_EQ(px_control_haptic_step(&h, &q, px_v3(0.01, 0, z),
						       NULL, &out),
				PX_OK);
		if (z < 0) {
			PX_CHECK_NEAR(out.distance_m, z, 1e-12);
			PX_CHECK_NEAR(out.force_n.z, -1000 * z, 1e-9);
		} else {
			PX_CHECK(out.force_n.z == 0);
		}
	}
	/* one fast jump from below to above: back on the free side */
	PX_CHECK_INT_EQ(px_control_haptic_step(&h, &q, px_v3(0.0, 0.01, 0.02),
					       NULL, &out),
			PX_OK);
	PX_CHECK(px_v3_norm(out.force_n) == 0);
	PX_CHECK_NEAR(out.distance_m, 0.02, 1e-12);
	/* go round the rim from above to below: no force anywhere */
	for (k = 0; k <= 60; k++) {
		double a = M_PI * k / 60; /* half circle round the edge x = 0.05 */
		px_vec3 p = px_v3(0.05 + 0.01 * sin(a), 0, 0.01 * cos(a));
		PX_CHECK_INT_EQ(px_control_haptic_step(&h, &q, p, NULL, &out),
				PX_OK);
		PX_CHECK_MSG(px_v3_norm(out.force_n) == 0, "k %d force %g", k,
			     px_v3_norm(out.force_n));
	}
	/* now below the plate, and that is the free side: going up through
	 * it is the crossing */
	PX_CHECK_INT_EQ(px_control_haptic_step(&h, &q, px_v3(0.0, 0, -0.005),
					       NULL, &out),
			PX_OK);
	PX_CHECK(px_v3_norm(out.force_n) == 0);
	PX_CHECK_INT_EQ(px_control_haptic_step(&h, &q, px_v3(0.0, 0, 0.002),
					       NULL, &out),
			PX_OK);
	PX_CHECK_NEAR(out.force_n.z, -2.0, 1e-9);
}

/* ------------------------------------------------------------------ */
/* Errors and allocation                                               */
/* ------------------------------------------------------------------ */

static int failing_point(void *ctx, px_vec3 p, double maxd,
			 struct px_control_hit *out)
{
	(void)ctx;
	(void)p;
	(void)maxd;
	(void)out;
	return PX_E_IO;
}

static void test_haptic_errors_ramp_down(void)
{
	static struct scene sc;
	struct px_control_query q = query_of(&sc, 0);
	struct px_control_query bad = {failing_point, NULL, NULL};
	struct px_control_haptic h;
	struct px_control_haptic_out out;
	struct px_control_haptic_params p;
	int k;
	make_scene(&sc, 2);
	px_control_haptic_params_default(&p);
	p.max_force_n = 5;
	p.max_force_rate_n_per_s = 1000; /* 1 N per cycle */
	PX_CHECK_INT_EQ(px_control_haptic_init(&h, &p, 1000000), PX_OK);
	PX_CHECK_INT_EQ(px_control_haptic_reset(&h, &q, px_v3(0, 0, 0.01)), PX_OK);
	for (k = 0; k < 20; k++)
		PX_CHECK_INT_EQ(px_control_haptic_step(&h, &q, px_v3(0, 0, -0.02),
						       NULL, &out),
				PX_OK);
	PX_CHECK_NEAR(out.force_n.z, 5, 1e-12);
	PX_CHECK_INT_EQ(px_control_haptic_step(&h, &bad, px_v3(0, 0, -0.02), NULL,
					       &out),
			PX_E_IO);
	PX_CHECK_NEAR(out.force_n.z, 4, 1e-12);
	PX_CHECK_INT_EQ(px_control_haptic_step(&h, &q, px_v3(NAN, 0, 0), NULL,
					       &out),
			PX_E_NAN);
	PX_CHECK_NEAR(out.force_n.z, 3, 1e-12);
	PX_CHECK_INT_EQ(px_control_haptic_step(NULL, &q, px_v3(0, 0, 0), NULL,
					       &out),
			PX_E_INVAL);
}

/* ------------------------------------------------------------------ */
/* Serial chains                                                       */
/* ------------------------------------------------------------------ */

static px_vec3 frame_x(px_pose f)
{
	return px_pose_transform_vector(f, px_v3(1, 0, 0));
}

static void test_fk_planar_and_elbow_by_hand(void)
{
	struct px_control_chain c;
	px_pose f[PX_CONTROL_MAX_JOINTS + 1];
	int it;
	/* planar 2R, a1 = 0.4, a2 = 0.3 */
	px_control_chain_init(&c, px_pose_identity());
	PX_CHECK_INT_EQ(px_control_chain_add_dh(&c, PX_CONTROL_REVOLUTE, 0.4, 0, 0, 0),
			PX_OK);
	PX_CHECK_INT_EQ(px_control_chain_add_dh(&c, PX_CONTROL_REVOLUTE, 0.3, 0, 0, 0),
			PX_OK);
	for (it = 0; it < 100; it++) {
		double q[2] = {px_rand_range(-3, 3), px_rand_range(-3, 3)};
		px_vec3 x;
		PX_CHECK_INT_EQ(px_control_chain_fk(&c, q, f, 3), PX_OK);
		PX_CHECK_NEAR(f[1].t.x, 0.4 * cos(q[0]), 1e-14);
		PX_CHECK_NEAR(f[1].t.y, 0.4 * sin(q[0]), 1e-14);
		PX_CHECK_NEAR(f[2].t.x, 0.4 * cos(q[0]) + 0.3 * cos(q[0] + q[1]), 1e-14);
		PX_CHECK_NEAR(f[2].t.y, 0.4 * sin(q[0]) + 0.3 * sin(q[0] + q[1]), 1e-14);
		PX_CHECK_NEAR(f[2].t.z, 0, 1e-15);
		x = frame_x(f[2]);
		PX_CHECK_NEAR(x.x, cos(q[0] + q[1]), 1e-14);
		PX_CHECK_NEAR(x.y, sin(q[0] + q[1]), 1e-14);
	}
	PX_CHECK_INT_EQ(px_control_chain_fk(&c, (double[]){0, 0}, f, 2), PX_E_NOSPC);
	/* base rotation + shoulder + elbow + wrist pitch (alpha1 = pi/2):
	 * r = a2 c2 + a3 c23 + a4 c234, z = d1 + a2 s2 + a3 s23 + a4 s234,
	 * tip = (r cos q1, r sin q1, z), on a base at (1, 2, 3) */
	px_control_chain_init(&c, px_control_pose_from_xyz_rpy(px_v3(1, 2, 3),
								px_v3(0, 0, 0)));
	PX_CHECK_INT_EQ(px_control_chain_add_dh(&c, PX_CONTROL_REVOLUTE, 0, M_PI / 2,
						0.3, 0),
			PX_OK);
	PX_CHECK_INT_EQ(px_control_chain_add_dh(&c, PX_CONTROL_REVOLUTE, 0.4, 0, 0, 0),
			PX_OK);
	PX_CHECK_INT_EQ(px_control_chain_add_dh(&c, PX_CONTROL_REVOLUTE, 0.35, 0, 0, 0),
			PX_OK);
	PX_CHECK_INT_EQ(px_control_chain_add_dh(&c, PX_CONTROL_REVOLUTE, 0.1, 0, 0, 0),
			PX_OK);
	for (it = 0; it < 100; it++) {
		double q[4], r, z;
		int j;
		for (j = 0; j < 4; j++)
			q[j] = px_rand_range(-3, 3);
		r = 0.4 * cos(q[1]) + 0.35 * cos(q[1] + q[2]) +
		    0.1 * cos(q[1] + q[2] + q[3]);
		z = 0.3 + 0.4 * sin(q[1]) + 0.35 * sin(q[1] + q[2]) +
		    0.1 * sin(q[1] + q[2] + q[3]);
		PX_CHECK_INT_EQ(px_control_chain_fk(&c, q, f, 5), PX_OK);
		PX_CHECK_NEAR(f[4].t.x, 1 + r * cos(q[0]), 1e-13);
		PX_CHECK_NEAR(f[4].t.y, 2 + r * sin(q[0]), 1e-13);
		PX_CHECK_NEAR(f[4].t.z, 3 + z, 1e-13);
		PX_CHECK_NEAR(f[1].t.z, 3.3, 1e-14);
	}
}

/* The same arm written as URDF-style joints gives the same points; a
 * prismatic DH joint moves along z. */
static void test_fk_urdf_matches_dh(void)
{
	struct px_control_chain dh, ur;
	px_pose fd[PX_CONTROL_MAX_JOINTS + 1], fu[PX_CONTROL_MAX_JOINTS + 1];
	int it;
	px_control_chain_init(&dh, px_pose_identity());
	px_control_chain_add_dh(&dh, PX_CONTROL_REVOLUTE, 0, M_PI / 2, 0.3, 0);
	px_control_chain_add_dh(&dh, PX_CONTROL_REVOLUTE, 0.4, 0, 0, 0);
	px_control_chain_add_dh(&dh, PX_CONTROL_PRISMATIC, 0.2, 0, 0.05, 0.3);
	/* URDF: joint i sits at the end of link i-1 */
	px_control_chain_init(&ur, px_pose_identity());
	PX_CHECK_INT_EQ(px_control_chain_add_joint(&ur, PX_CONTROL_REVOLUTE,
						   px_pose_identity(), px_v3(0, 0, 2)),
			PX_OK);
	PX_CHECK_INT_EQ(px_control_chain_add_joint(
				&ur, PX_CONTROL_REVOLUTE,
				px_control_pose_from_xyz_rpy(px_v3(0, 0, 0.3),
							     px_v3(M_PI / 2, 0, 0)),
				px_v3(0, 0, 1)),
			PX_OK);
	PX_CHECK_INT_EQ(px_control_chain_add_joint(
				&ur, PX_CONTROL_PRISMATIC,
				px_control_pose_from_xyz_rpy(px_v3(0.4, 0, 0),
							     px_v3(0, 0, 0.3)),
				px_v3(0, 0, 1)),
			PX_OK);
	for (it = 0; it < 100; it++) {
		double q[3] = {px_rand_range(-3, 3), px_rand_range(-3, 3),
			       px_rand_range(-0.2, 0.2)};
		px_vec3 tip_u;
		PX_CHECK_INT_EQ(px_control_chain_fk(&dh, q, fd, 4), PX_OK);
		PX_CHECK_INT_EQ(px_control_chain_fk(&ur, q, fu, 4), PX_OK);
		/* DH frame 3 = URDF frame 3 moved by d = 0.05 along z... then
		 * a = 0.2 along the rotated x */
		tip_u = px_pose_transform_point(fu[3], px_v3(0.2, 0, 0.05));
		PX_CHECK_NEAR(px_v3_dist(fd[3].t, tip_u), 0, 1e-13);
		PX_CHECK_NEAR(px_v3_dist(fd[2].t, px_pose_transform_point(
							  fu[2], px_v3(0.4, 0, 0))),
			      0, 1e-13);
		/* prismatic: the DH frame moves along joint 3's z by q */
		PX_CHECK_NEAR(px_v3_dot(px_v3_sub(fd[3].t, fd[2].t),
					px_pose_transform_vector(fd[2], px_v3(0, 0, 1))),
			      0.05 + q[2], 1e-13);
	}
	PX_CHECK_INT_EQ(px_control_chain_add_joint(&ur, 5, px_pose_identity(),
						   px_v3(0, 0, 1)),
			PX_E_INVAL);
	PX_CHECK_INT_EQ(px_control_chain_add_joint(&ur, 0, px_pose_identity(),
						   px_v3(0, 0, 0)),
			PX_E_INVAL);
	PX_CHECK_INT_EQ(px_control_chain_add_dh(&ur, 0, NAN, 0, 0, 0), PX_E_NAN);
	while (ur.n_joints < PX_CONTROL_MAX_JOINTS)
		px_control_chain_add_dh(&ur, 0, 0.1, 0, 0, 0);
	PX_CHECK_INT_EQ(px_control_chain_add_dh(&ur, 0, 0.1, 0, 0, 0), PX_E_NOSPC);
}

static void test_jacobian_finite_differences(void)
{
	struct px_control_chain c;
	int it;
	px_control_chain_init(&c, px_control_pose_from_xyz_rpy(px_v3(0.1, 0, 0.2),
							       px_v3(0.1, 0.2, 0.3)));
	px_control_chain_add_dh(&c, PX_CONTROL_REVOLUTE, 0, M_PI / 2, 0.3, 0);
	px_control_chain_add_dh(&c, PX_CONTROL_REVOLUTE, 0.4, 0, 0, 0.2);
	px_control_chain_add_dh(&c, PX_CONTROL_PRISMATIC, 0.1, -M_PI / 2, 0.0, 0);
	px_control_chain_add_dh(&c, PX_CONTROL_REVOLUTE, 0.2, 0.3, 0.1, 0);
	for (it = 0; it < 50; it++) {
		double q[4];
		px_vec3 jac[4], pl = rand_v3(-0.1, 0.1), p;
		px_pose f[5];
		int j, link = px_rand_int(0, 4);
		for (j = 0; j < 4; j++)
			q[j] = px_rand_range(-2, 2);
		px_control_chain_fk(&c, q, f, 5);
		p = px_pose_transform_point(f[link], pl);
		PX_CHECK_INT_EQ(px_control_chain_jacobian(&c, q, link, p, jac), PX_OK);
		for (j = 0; j < 4; j++) {
			double qp[4], qm[4], h = 1e-6;
			px_vec3 pp, pm, fd;
			memcpy(qp, q, sizeof(q));
			memcpy(qm, q, sizeof(q));
			qp[j] += h;
			qm[j] -= h;
			px_control_chain_fk(&c, qp, f, 5);
			pp = px_pose_transform_point(f[link], pl);
			px_control_chain_fk(&c, qm, f, 5);
			pm = px_pose_transform_point(f[link], pl);
			fd = px_v3_scale(px_v3_sub(pp, pm), 0.5 / h);
			PX_CHECK_NEAR(px_v3_dist(fd, jac[j]), 0, 1e-8);
		}
	}
}

/* ------------------------------------------------------------------ */
/* Collision avoidance                                                 */
/* ------------------------------------------------------------------ */

/* Spatial arm: base yaw, shoulder, elbow, wrist; capsules on the three
 * moving links (radius 4 cm). */
static void make_arm(struct px_control_chain *c)
{
	static const double a[4] = {0, 0.4, 0.35, 0.15};
	int i;
	px_control_chain_init(c, px_pose_identity());
	px_control_chain_add_dh(c, PX_CONTROL_REVOLUTE, 0, M_PI / 2, 0.3, 0);
	for (i = 1; i < 4; i++)
		px_control_chain_add_dh(c, PX_CONTROL_REVOLUTE, a[i], 0, 0, 0);
	for (i = 1; i < 4; i++)
		PX_CHECK_INT_EQ(px_control_chain_add_capsule(c, i + 1,
							     px_v3(-a[i], 0, 0),
							     px_v3(0, 0, 0), 0.04),
				PX_OK);
	PX_CHECK_INT_EQ(px_control_chain_add_capsule(c, 1, px_v3(0, 0, 0),
						     px_v3(0, -0.2, 0), 0.05),
			PX_OK);
}

/* Exact smallest clearance of the arm's capsules (reference). */
static double arm_clearance(const struct px_control_chain *c,
			    const struct scene *sc, const double *q)
{
	px_pose f[PX_CONTROL_MAX_JOINTS + 1];
	double best = INFINITY;
	int i;
	px_control_chain_fk(c, q, f, PX_CONTROL_MAX_JOINTS + 1);
	for (i = 0; i < c->n_capsules; i++) {
		const struct px_control_capsule *cp = &c->capsules[i];
		double d = ref_seg(sc, px_pose_transform_point(f[cp->link], cp->a_m),
				   px_pose_transform_point(f[cp->link], cp->b_m)) -
			   cp->radius_m;
		best = fmin(best, d);
	}
	return best;
}

static void test_clearances_exact_and_searched(void)
{
	static struct scene sc;
	struct px_control_chain c;
	struct px_control_avoid_params p;
	struct px_control_clearance cl[PX_CONTROL_MAX_CAPSULES];
	px_pose f[PX_CONTROL_MAX_JOINTS + 1];
	int it, i, nq;
	make_arm(&c);
	px_control_avoid_params_default(&p);
	p.segment_point_queries = 40;
	for (it = 0; it < 100; it++) {
		struct px_control_query qe = query_of(&sc, 1), qs = query_of(&sc, 0);
		double q[4];
		for (i = 0; i < 4; i++)
			q[i] = px_rand_range(-2, 2);
		make_scene(&sc, it % 6);
		for (i = 0; i < sc.n; i++)
			sc.s[i].c = px_v3_add(sc.s[i].c, px_v3(0.4, 0.1, 0.3));
		px_control_chain_fk(&c, q, f, 5);
		PX_CHECK_INT_EQ(px_control_chain_clearances(&c, &p, &qe, q, 10, cl, &nq),
				PX_OK);
		PX_CHECK_INT_EQ(nq, c.n_capsules);
		for (i = 0; i < c.n_capsules; i++) {
			const struct px_control_capsule *cp = &c.capsules[i];
			px_vec3 a = px_pose_transform_point(f[cp->link], cp->a_m);
			px_vec3 b = px_pose_transform_point(f[cp->link], cp->b_m);
			double ref = ref_seg(&sc, a, b) - cp->radius_m;
			PX_CHECK_NEAR(cl[i].clearance_m, ref, 1e-12);
			PX_CHECK_NEAR(cl[i].lower_bound_m, ref, 1e-12);
			PX_CHECK_NEAR(ref_point(&sc, cl[i].point_m) - cp->radius_m, ref,
				      1e-12);
		}
		PX_CHECK_INT_EQ(px_control_chain_clearances(&c, &p, &qs, q, 10, cl, &nq),
				PX_OK);
		PX_CHECK(nq <= c.n_capsules * p.segment_point_queries);
		for (i = 0; i < c.n_capsules; i++) {
			const struct px_control_capsule *cp = &c.capsules[i];
			px_vec3 a = px_pose_transform_point(f[cp->link], cp->a_m);
			px_vec3 b = px_pose_transform_point(f[cp->link], cp->b_m);
			double ref = ref_seg(&sc, a, b) - cp->radius_m;
			PX_CHECK(cl[i].lower_bound_m <= ref + 1e-12);
			PX_CHECK(cl[i].clearance_m >= ref - 1e-12);
		}
	}
}

static void test_avoid_scaling_law(void)
{
	static struct scene sc;
	struct px_control_query q = query_of(&sc, 1);
	struct px_control_chain c;
	struct px_control_avoid_params p;
	struct px_control_avoid_out out;
	int it;
	/* one prismatic joint along x carrying a point capsule (r = 0) toward
	 * a wall at x = 1 */
	px_control_chain_init(&c, px_pose_identity());
	px_control_chain_add_joint(&c, PX_CONTROL_PRISMATIC, px_pose_identity(),
				   px_v3(1, 0, 0));
	px_control_chain_add_capsule(&c, 1, px_v3(0, 0, 0), px_v3(0, 0, 0), 0);
	memset(&sc, 0, sizeof(sc));
	sc.n = 1;
	sc.s[0] = halfspace(px_v3(1, 0, 0), px_v3(-1, 0, 0));
	px_control_avoid_params_default(&p);
	p.influence_distance_m = 0.3;
	p.protective_distance_m = 0.1;
	p.repulsive_speed_m_per_s = 0.05;
	p.max_joint_velocity = 10;
	p.max_margin_fraction = 1;
	for (it = 0; it < 200; it++) {
		double x = px_rand_range(0.5, 1.0), v = -px_rand_range(0.01, 0.5);
		double c0 = 1 - x, s, w, want;
		PX_CHECK_INT_EQ(px_control_avoid_step(&c, &p, &q, &x, &v, 1000000,
						      &out),
				PX_OK);
		s = c0 >= 0.3 ? 1 : (c0 <= 0.1 ? 0 : (c0 - 0.1) / 0.2);
		w = c0 >= 0.3 ? 0 : 1 - s;
		/* moving away from the wall (v < 0): no margin limit */
		want = s * v - w * 0.05;
		PX_CHECK_NEAR(out.scale, s, 1e-12);
		PX_CHECK_NEAR(out.qdot[0], want, 1e-12);
		PX_CHECK_NEAR(out.min_clearance_m, fmin(c0, 0.3), 1e-12);
		/* toward the wall: never more than the margin per period */
		v = -v;
		PX_CHECK_INT_EQ(px_control_avoid_step(&c, &p, &q, &x, &v, 1000000,
						      &out),
				PX_OK);
		PX_CHECK(out.qdot[0] * 1e-3 <= fmax(c0 - 0.1, 0) + 1e-15);
		if (c0 > 0.3 && v * 1e-3 < c0 - 0.1)
			PX_CHECK_NEAR(out.qdot[0], v, 1e-12);
		if (c0 <= 0.1)
			PX_CHECK(out.qdot[0] <= 0);
	}
}

/*
 * Scripted approaches: the nominal command drives the arm (a joint-space
 * P controller toward a goal inside or behind an obstacle); the arm
 * integrates the commanded velocities at 1 kHz. Without avoidance the
 * path collides; with it, the exact clearance never drops below the
 * protective distance.
 */
static double run_arm(const struct px_control_chain *c, struct scene *sc,
		      int with_segment, const double *q0, const double *goal,
		      int avoid, double v_rep, double *min_clear)
{
	struct px_control_query qry = query_of(sc, with_segment);
	struct px_control_avoid_params p;
	struct px_control_avoid_out out;
	double q[4], qn[4], mc = INFINITY;
	int k, j;
	px_control_avoid_params_default(&p);
	p.influence_distance_m = 0.25;
	p.protective_distance_m = 0.05;
	p.repulsive_speed_m_per_s = v_rep;
	p.max_joint_velocity = 1.5;
	memcpy(q, q0, sizeof(q));
	for (k = 0; k < 3000; k++) {
		for (j = 0; j < 4; j++)
			qn[j] = clampd(2.0 * (goal[j] - q[j]), -1.0, 1.0);
		if (avoid) {
			PX_CHECK_INT_EQ(px_control_avoid_step(c, &p, &qry, q, qn,
							      1000000, &out),
					PX_OK);
			for (j = 0; j < 4; j++)
				q[j] += out.qdot[j] * 1e-3;
		} else {
			for (j = 0; j < 4; j++)
				q[j] += qn[j] * 1e-3;
		}
		mc = fmin(mc, arm_clearance(c, sc, q));
	}
	*min_clear = mc;
	return p.protective_distance_m;
}

/* Joint goal that puts the wrist tip of make_arm() (wrist straight) at
 * target: base yaw, then two-link inverse kinematics, elbow up. */
static void arm_ik(px_vec3 target, double *goal)
{
	const double l1 = 0.4, l2 = 0.5;
	double r = hypot(target.x, target.y), z = target.z - 0.3;
	double d = clampd((r * r + z * z - l1 * l1 - l2 * l2) / (2 * l1 * l2), -1, 1);
	goal[0] = atan2(target.y, target.x);
	goal[2] = -acos(d);
	goal[1] = atan2(z, r) - atan2(l2 * sin(goal[2]), l1 + l2 * cos(goal[2]));
	goal[3] = 0;
}

static void test_avoid_scripted_approaches(void)
{
	static struct scene sc;
	struct px_control_chain c;
	int it, approached = 0;
	make_arm(&c);
	for (it = 0; it < 24; it++) {
		double q0[4] = {0, 1.4, -2.2, 0}, goal[4], mc_free, mc, dp;
		px_vec3 tgt;
		int j;
		memset(&sc, 0, sizeof(sc));
		sc.n = 1;
		switch (it % 4) {
		case 0: /* reach through a table */
			sc.s[0] = halfspace(px_v3(0, 0, -0.3), px_v3(0, 0, 1));
			tgt = px_v3(px_rand_range(0.3, 0.6), px_rand_range(-0.3, 0.3),
				    -0.4);
			break;
		case 1: /* reach into a sphere in front */
			tgt = px_v3(px_rand_range(0.6, 0.8), px_rand_range(-0.3, 0.3),
				    px_rand_range(0.0, 0.5));
			sc.s[0] = sphere(tgt, 0.06);
			break;
		case 2: /* swing sideways into a post */
			tgt = px_v3(px_rand_range(0.2, 0.5), px_rand_range(0.5, 0.7),
				    px_rand_range(0.1, 0.5));
			sc.s[0] = box(tgt, px_v3(0.05, 0.05, 0.15));
			break;
		default: /* reach through a 2 mm wall */
			sc.s[0] = box(px_v3(0.7, 0, 0.3), px_v3(0.001, 0.4, 0.3));
			tgt = px_v3(0.85, px_rand_range(-0.2, 0.2),
				    px_rand_range(0.1, 0.5));
			break;
		}
		arm_ik(tgt, goal);
		for (j = 0; j < 4; j++)
			q0[j] += px_rand_range(-0.05, 0.05);
		if (arm_clearance(&c, &sc, q0) < 0.25)
			continue; /* start outside the influence zone */
		run_arm(&c, &sc, 1, q0, goal, 0, 0, &mc_free);
		if (mc_free >= 0.0)
			continue; /* this path does not collide */
		approached++;
		dp = run_arm(&c, &sc, it % 2, q0, goal, 1, 0.05, &mc);
		PX_CHECK_MSG(mc >= dp - 1e-9,
			     "case %d: clearance %.6g below protective %.3g "
			     "(without avoidance %.4g)",
			     it % 4, mc, dp, mc_free);
		/* and it did come close: the command is not just "stop" */
		PX_CHECK_MSG(mc < 0.15, "case %d: stayed %.3g away", it % 4, mc);
		/* scaling alone (no repulsion) creeps up to the protective
		 * distance without crossing it */
		dp = run_arm(&c, &sc, it % 2, q0, goal, 1, 0.0, &mc);
		PX_CHECK_MSG(mc >= dp - 1e-9,
			     "case %d, no repulsion: clearance %.6g below "
			     "protective %.3g",
			     it % 4, mc, dp);
		PX_CHECK_MSG(mc < dp + 0.03, "case %d: stayed %.3g away", it % 4, mc);
	}
	PX_CHECK_MSG(approached >= 12, "only %d scripted paths approached",
		     approached);
}

/* ------------------------------------------------------------------ */
/* Allocation                                                          */
/* ------------------------------------------------------------------ */

static void test_cycles_do_not_allocate(void)
{
	static struct scene sc;
	struct px_control_query q = query_of(&sc, 0), qe = query_of(&sc, 1);
	struct px_control_haptic hp, hq;
	struct px_control_haptic_params pp;
	struct px_control_haptic_out out;
	struct px_control_chain c;
	struct px_control_avoid_params ap;
	struct px_control_avoid_out aout;
	px_pose f[PX_CONTROL_MAX_JOINTS + 1];
	px_vec3 jac[PX_CONTROL_MAX_JOINTS];
	double qa[4] = {0.1, 0.5, -0.7, 0.2}, qd[4] = {0.3, -0.2, 0.1, 0.4};
	uint64_t r;
	int k;
	make_scene(&sc, 5);
	px_control_haptic_params_default(&pp);
	pp.static_friction = 0.5;
	pp.dynamic_friction = 0.3;
	PX_CHECK_INT_EQ(px_control_haptic_init(&hq, &pp, 1000000), PX_OK);
	pp.renderer = PX_CONTROL_PENALTY;
	PX_CHECK_INT_EQ(px_control_haptic_init(&hp, &pp, 1000000), PX_OK);
	make_arm(&c);
	px_control_avoid_params_default(&ap);
	r = px_alloc_region_begin();
	for (k = 0; k < 500; k++) {
		px_vec3 d = px_v3(0.06 * sin(k * 0.01), 0.05 * cos(k * 0.013),
				  0.03 * sin(k * 0.02));
		px_control_haptic_step(&hq, &q, d, NULL, &out);
		px_control_haptic_step(&hp, &q, d, NULL, &out);
		px_control_avoid_step(&c, &ap, k % 2 ? &q : &qe, qa, qd, 1000000,
				      &aout);
		px_control_chain_fk(&c, qa, f, 5);
		px_control_chain_jacobian(&c, qa, 3, f[3].t, jac);
		qa[k % 4] += 0.001;
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(r), 0);
}

/* ------------------------------------------------------------------ */
/* Configuration                                                       */
/* ------------------------------------------------------------------ */

static const char cfg_head[] =
	"loop: {period_ns: 1000000}\n"                          /* 1 */
	"safety: {max_force_n: 8.0, max_force_rate_n_per_s: 2000.0}\n"
	"devices:\n"                                            /* 3 */
	"  - name: pen\n"
	"    backend: sim\n"                                    /* 5 */
	"    sim: {kind: haptic, damping_n_s_per_m: 2.0}\n"
	"  - name: arm\n"                                       /* 7 */
	"    backend: socketcan\n"
	"    socketcan:\n"                                      /* 9 */
	"      interface: vcan0\n"
	"      canopen:\n"                                      /* 11 */
	"        drives:\n"
	"          - {node_id: 1, mode: csv, joint: 0}\n"       /* 13 */
	"          - {node_id: 2, mode: csv, joint: 1}\n";

/* Load cfg_head + body and read its control section. The strings out
 * points to (device, URDF names) live in the config, which is kept until
 * the next call. */
static int load_control(const char *body, struct px_control_config *out,
			struct px_config_diag *diag)
{
	static char buf[8192];
	static struct px_config *cfg;
	int rc;
	px_config_free(cfg);
	cfg = NULL;
	snprintf(buf, sizeof(buf), "%s%s", cfg_head, body);
	rc = px_config_load_mem("t.yaml", buf, strlen(buf), &cfg, diag);
	PX_CHECK_MSG(rc == PX_OK, "base config failed: %s",
		     diag->count ? diag->errors[0].msg : px_strerror(rc));
	return px_control_config_read(cfg, out, diag);
}

static void expect_control_error(const char *body, const char *path, int line,
				 const char *what)
{
	static struct px_config_diag diag;
	static struct px_control_config out;
	const struct px_config_error *e;
	int rc = load_control(body, &out, &diag);
	PX_CHECK_MSG(rc == PX_E_PARSE, "expected an error at %s, got %d", path, rc);
	e = px_config_diag_find(&diag, path);
	PX_CHECK_MSG(e != NULL, "no error at %s (first: %s)", path,
		     diag.count ? diag.errors[0].msg : "none");
	PX_CHECK_MSG(e->line == line, "%s: line %d, expected %d", e->msg, e->line,
		     line);
	PX_CHECK_MSG(strstr(e->msg, what) != NULL, "'%s' lacks '%s'", e->msg, what);
	PX_CHECK_MSG(strncmp(e->msg, "t.yaml:", 7) == 0, "%s", e->msg);
}

static void test_config_haptic_section(void)
{
	PX_NEEDS(YAML);
	static struct px_config_diag diag;
	static struct px_control_config c;
	struct px_control_haptic h;
	PX_CHECK_INT_EQ(load_control("control:\n"                  /* 15 */
				     "  mode: haptic\n"
				     "  device: pen\n"
				     "  haptic:\n"
				     "    renderer: penalty\n"
				     "    stiffness_n_per_m: 1200\n"  /* 20 */
				     "    damping_n_s_per_m: 0.25\n"
				     "    static_friction: 0.4\n"
				     "    dynamic_friction: 0.3\n"
				     "    max_force_rate_n_per_s: 1000\n",
				     &c, &diag),
			PX_OK);
	PX_CHECK_INT_EQ(c.mode, PX_CONTROL_MODE_HAPTIC);
	PX_CHECK_INT_EQ(c.haptic.renderer, PX_CONTROL_PENALTY);
	PX_CHECK_NEAR(c.haptic.stiffness_n_per_m, 1200, 0);
	PX_CHECK_NEAR(c.haptic.damping_n_s_per_m, 0.25, 0);
	PX_CHECK_NEAR(c.haptic.max_force_n, 8.0, 0);          /* from safety */
	PX_CHECK_NEAR(c.haptic.max_force_rate_n_per_s, 1000, 0);
	PX_CHECK_NEAR(c.haptic.device_damping_n_s_per_m, 2.0, 0); /* sim */
	PX_CHECK_NEAR(c.haptic.proxy_radius_m, 0.0005, 0);
	PX_CHECK(c.stable);
	PX_CHECK(c.warning[0] == '\0');
	PX_CHECK_INT_EQ(px_control_haptic_init(&h, &c.haptic, 1000000), PX_OK);
	/* too stiff for 1 kHz and b = 2, B = 0.25: limit 3500 N/m */
	PX_CHECK_INT_EQ(load_control("control:\n"
				     "  mode: haptic\n"
				     "  device: pen\n"
				     "  haptic:\n"
				     "    damping_n_s_per_m: 0.25\n"
				     "    stiffness_n_per_m: 5000\n", /* 20 */
				     &c, &diag),
			PX_OK);
	PX_CHECK(!c.stable);
	PX_CHECK_NEAR(c.stiffness_limit_n_per_m, 3500, 1e-9);
	PX_CHECK_MSG(strncmp(c.warning,
			     "t.yaml:20:24: control.haptic.stiffness_n_per_m: "
			     "warning: stiffness 5000 N/m",
			     strlen("t.yaml:20:24: control.haptic.stiffness_n_per_m: "
				    "warning: stiffness 5000 N/m")) == 0,
		     "%s", c.warning);
	PX_CHECK(strstr(c.warning, "K < 3500 N/m") != NULL);
	/* a real device states its damping: none given = 0 = never passive */
	PX_CHECK_INT_EQ(load_control("control: {mode: haptic, device: arm}\n", &c,
				     &diag),
			PX_OK);
	PX_CHECK(!c.stable);
	/* absent section: mode none */
	PX_CHECK_INT_EQ(load_control("", &c, &diag), PX_OK);
	PX_CHECK_INT_EQ(c.mode, PX_CONTROL_MODE_NONE);
}

static void test_config_errors(void)
{
	PX_NEEDS(YAML);
	expect_control_error("control:\n  mode: haptic\n  device: pen\n"
			     "  haptic:\n    stifness_n_per_m: 10\n",
			     "control.haptic.stifness_n_per_m", 19,
			     "did you mean 'stiffness_n_per_m'");
	expect_control_error("control:\n  mode: haptic\n  device: pen\n"
			     "  haptic:\n    stiffness_n_per_m: stiff\n",
			     "control.haptic.stiffness_n_per_m", 19, "number");
	expect_control_error("control:\n  mode: haptic\n  device: pen\n"
			     "  haptic:\n    stiffness_n_per_m: -1\n",
			     "control.haptic.stiffness_n_per_m", 19, "-1");
	expect_control_error("control:\n  mode: haptic\n  device: pen\n"
			     "  haptic:\n    static_friction: 0.2\n"
			     "    dynamic_friction: 0.5\n",
			     "control.haptic.dynamic_friction", 20,
			     "larger than static_friction");
	expect_control_error("control:\n  mode: haptic\n  device: pen\n"
			     "  haptic:\n    max_force_n: 9\n",
			     "control.haptic.max_force_n", 19,
			     "above safety.max_force_n 8");
	expect_control_error("control:\n  mode: haptic\n  device: pne\n",
			     "control.device", 17, "no device named 'pne'");
	expect_control_error("control:\n  mode: haptic\n", "control.device", 16,
			     "missing required key");
	expect_control_error("control:\n  mode: hapitc\n", "control.mode", 16,
			     "hapitc");
	expect_control_error("control:\n  mode: avoidance\n  device: arm\n"
			     "  avoidance:\n"
			     "    influence_distance_m: 0.1\n"
			     "    protective_distance_m: 0.2\n"
			     "    joints:\n"
			     "      - {dh: {a_m: 0.3}, origin: {xyz_m: [0, 0, 1]}, axis: [0, 0, 1]}\n"
			     "      - {type: prismatic}\n"
			     "      - {origin: {xyz_m: [0, 0, 1]}}\n"
			     "      - {origin: {xyz_m: [0, 0, 1]}, axis: [0, 0, 0]}\n"
			     "    capsules:\n"
			     "      - {link: 6, a_m: [0, 0, 0], b_m: [0, 0, 1], radius_m: 0.1}\n",
			     "control.avoidance.protective_distance_m", 20,
			     "smaller than influence_distance_m");
	expect_control_error("control:\n  mode: avoidance\n  device: arm\n"
			     "  avoidance:\n    joints:\n"
			     "      - {dh: {a_m: 0.3}, origin: {xyz_m: [0, 0, 1]}, axis: [0, 0, 1]}\n",
			     "control.avoidance.joints[0].origin", 20,
			     "either dh or origin");
	expect_control_error("control:\n  mode: avoidance\n  device: arm\n"
			     "  avoidance:\n    joints:\n"
			     "      - {dh: {a_m: 0.3}}\n"
			     "      - {type: prismatic}\n",
			     "control.avoidance.joints[1]", 21, "missing geometry");
	expect_control_error("control:\n  mode: avoidance\n  device: arm\n"
			     "  avoidance:\n    joints:\n"
			     "      - {origin: {xyz_m: [0, 0, 1]}}\n",
			     "control.avoidance.joints[0].axis", 20,
			     "missing required key");
	expect_control_error("control:\n  mode: avoidance\n  device: arm\n"
			     "  avoidance:\n    joints:\n"
			     "      - {dh: {a_m: 0.3}}\n"
			     "      - {origin: {xyz_m: [0, 0, 1]}, axis: [0, 0, 0]}\n",
			     "control.avoidance.joints[1].axis", 21, "zero vector");
	expect_control_error("control:\n  mode: avoidance\n  device: arm\n"
			     "  avoidance:\n    joints:\n"
			     "      - {dh: {a_m: 0.3}}\n"
			     "      - {dh: {a_m: 0.3}}\n"
			     "    capsules:\n"
			     "      - {link: 3, a_m: [0, 0, 0], b_m: [0, 0, 1], radius_m: 0.1}\n",
			     "control.avoidance.capsules[0].link", 23,
			     "beyond the last link");
	/* the CAN drives feed joints 0 and 1: one joint is too few */
	expect_control_error("control:\n  mode: avoidance\n  device: arm\n"
			     "  avoidance:\n    joints:\n"
			     "      - {dh: {a_m: 0.3}}\n"
			     "    capsules:\n"
			     "      - {link: 1, a_m: [0, 0, 0], b_m: [0, 0, 1], radius_m: 0.1}\n",
			     "control.device", 17, "feeds joint 1");
	expect_control_error("control:\n  mode: avoidance\n  device: arm\n"
			     "  avoidance:\n    joints:\n"
			     "      - {dh: {a_m: 0.3}}\n      - {dh: {a_m: 0.3}}\n",
			     "control.avoidance.capsules", 19, "at least one capsule");
}

/* A chain read from the config equals the same chain built in code. */
static void test_config_chain_matches_code(void)
{
	PX_NEEDS(YAML);
	static struct px_config_diag diag;
	static struct px_control_config c;
	struct px_control_chain ref;
	px_pose fa[PX_CONTROL_MAX_JOINTS + 1], fb[PX_CONTROL_MAX_JOINTS + 1];
	int it, i;
	PX_CHECK_INT_EQ(load_control(
				"control:\n  mode: avoidance\n  device: arm\n"
				"  avoidance:\n"
				"    influence_distance_m: 0.4\n"
				"    protective_distance_m: 0.1\n"
				"    base: {xyz_m: [0.1, 0.2, 0.3], rpy_rad: [0, 0, 1.5]}\n"
				"    joints:\n"
				"      - {dh: {a_m: 0.0, alpha_rad: 1.5707963267948966, d_m: 0.3}}\n"
				"      - {type: revolute, origin: {xyz_m: [0.4, 0, 0], rpy_rad: [0.1, 0.2, 0.3]}, axis: [0, 0, 2]}\n"
				"      - {type: prismatic, origin: {xyz_m: [0, 0.1, 0]}, axis: [1, 0, 0]}\n"
				"    capsules:\n"
				"      - {link: 2, a_m: [-0.4, 0, 0], b_m: [0, 0, 0], radius_m: 0.05}\n"
				"      - {link: 3, a_m: [0, 0, 0], b_m: [0.1, 0, 0], radius_m: 0.02}\n",
				&c, &diag),
			PX_OK);
	PX_CHECK_INT_EQ(c.mode, PX_CONTROL_MODE_AVOIDANCE);
	PX_CHECK_INT_EQ(c.chain.n_joints, 3);
	PX_CHECK_INT_EQ(c.chain.n_capsules, 2);
	PX_CHECK_NEAR(c.avoid.influence_distance_m, 0.4, 0);
	PX_CHECK_NEAR(c.avoid.protective_distance_m, 0.1, 0);
	PX_CHECK_INT_EQ(px_control_avoid_params_check(&c.avoid), PX_OK);
	px_control_chain_init(&ref, px_control_pose_from_xyz_rpy(px_v3(0.1, 0.2, 0.3),
								 px_v3(0, 0, 1.5)));
	px_control_chain_add_dh(&ref, PX_CONTROL_REVOLUTE, 0, M_PI / 2, 0.3, 0);
	px_control_chain_add_joint(&ref, PX_CONTROL_REVOLUTE,
				   px_control_pose_from_xyz_rpy(px_v3(0.4, 0, 0),
								px_v3(0.1, 0.2, 0.3)),
				   px_v3(0, 0, 1));
	px_control_chain_add_joint(&ref, PX_CONTROL_PRISMATIC,
				   px_control_pose_from_xyz_rpy(px_v3(0, 0.1, 0),
								px_v3(0, 0, 0)),
				   px_v3(1, 0, 0));
	for (it = 0; it < 20; it++) {
		double q[3] = {px_rand_range(-2, 2), px_rand_range(-2, 2),
			       px_rand_range(-0.1, 0.1)};
		PX_CHECK_INT_EQ(px_control_chain_fk(&c.chain, q, fa, 4), PX_OK);
		PX_CHECK_INT_EQ(px_control_chain_fk(&ref, q, fb, 4), PX_OK);
		for (i = 0; i < 4; i++)
			PX_CHECK_NEAR(px_v3_dist(fa[i].t, fb[i].t), 0, 1e-15);
	}
	/* rpy is roll about x, then pitch about y, then yaw about z */
	{
		px_pose p = px_control_pose_from_xyz_rpy(px_v3(0, 0, 0),
							 px_v3(M_PI / 2, 0, M_PI / 2));
		px_vec3 y = px_pose_transform_vector(p, px_v3(0, 1, 0));
		/* roll takes y to z; yaw leaves z */
		PX_CHECK_NEAR(px_v3_dist(y, px_v3(0, 0, 1)), 0, 1e-15);
	}
}

static void test_config_docs_and_examples(void)
{
	PX_NEEDS(YAML);
	static struct px_config_diag diag;
	static struct px_control_config c;
	struct px_config *cfg;
	char why[200];
	char *docs = px_test_read_text("docs/config.md");
	if (!docs)
		PX_SKIP("docs/config.md not found (run from the source tree)");
	PX_CHECK_INT_EQ(px_config_schema_validate(px_control_config_schema(), why,
						  sizeof(why)),
			PX_OK);
	PX_CHECK(strstr(docs, "## control") != NULL);
	px_test_check_documented(docs, px_control_config_schema(), 8);
	free(docs);
	PX_CHECK_INT_EQ(px_config_load_file("config/examples/haptic_sim.yaml", &cfg,
					    &diag),
			PX_OK);
	PX_CHECK_INT_EQ(px_control_config_read(cfg, &c, &diag), PX_OK);
	PX_CHECK_INT_EQ(c.mode, PX_CONTROL_MODE_HAPTIC);
	PX_CHECK(c.stable);
	px_config_free(cfg);
	PX_CHECK_INT_EQ(px_config_load_file("config/examples/can_arm.yaml", &cfg,
					    &diag),
			PX_OK);
	PX_CHECK_INT_EQ(px_control_config_read(cfg, &c, &diag), PX_OK);
	PX_CHECK_INT_EQ(c.mode, PX_CONTROL_MODE_AVOIDANCE);
	PX_CHECK_INT_EQ(c.chain.n_joints, 6);
	PX_CHECK_INT_EQ(c.chain.n_capsules, 3);
	px_config_free(cfg);
}

/* control.avoidance with a URDF: the keys read as written (clearance
 * auto turns to models), and every misuse refused at its key. */
static void test_config_avoid_urdf(void)
{
	static struct px_config_diag diag;
	static struct px_control_config c;
	PX_NEEDS(YAML);
	PX_CHECK_INT_EQ(load_control("control:\n"                  /* 15 */
				     "  mode: avoidance\n"
				     "  device: arm\n"
				     "  avoidance:\n"
				     "    urdf: robots/arm6/arm6.urdf\n"
				     "    base_link: base_link\n"    /* 20 */
				     "    tip_link: tool0\n"
				     "    package_paths: [robots, /opt/ros]\n"
				     "    urdf_joints: [shoulder_pan, shoulder_lift]\n"
				     "    approach_only: true\n"
				     "    self_influence_distance_m: 0.04\n" /* 25 */
				     "    allowed_collisions:\n"
				     "      - {a: wrist1_link, b: wrist3_link}\n",
				     &c, &diag),
			PX_OK);
	PX_CHECK(c.urdf.path && !strcmp(c.urdf.path, "robots/arm6/arm6.urdf"));
	PX_CHECK(!strcmp(c.urdf.base_link, "base_link") && !strcmp(c.urdf.tip_link, "tool0"));
	PX_CHECK_INT_EQ(c.urdf.n_package_paths, 2);
	PX_CHECK(!strcmp(c.urdf.package_paths[1], "/opt/ros"));
	PX_CHECK_INT_EQ(c.urdf.n_joints, 2);
	PX_CHECK(!strcmp(c.urdf.joints[1], "shoulder_lift"));
	PX_CHECK_INT_EQ(c.urdf.clearance, PX_CONTROL_CLEARANCE_MODELS);
	PX_CHECK(c.urdf.self_clearance);
	PX_CHECK(c.avoid.approach_only);
	PX_CHECK_NEAR(c.avoid.self_influence_distance_m, 0.04, 0);
	PX_CHECK_NEAR(c.avoid.self_protective_distance_m, 0.01, 0);
	PX_CHECK_INT_EQ(c.urdf.n_allowed, 1);
	PX_CHECK(!strcmp(c.urdf.allowed[0].b, "wrist3_link"));
	PX_CHECK_INT_EQ(px_control_avoid_params_check(&c.avoid), PX_OK);
	/* without a URDF: capsules, as before */
	PX_CHECK_INT_EQ(load_control("control:\n"
				     "  mode: none\n", &c, &diag),
			PX_OK);
	PX_CHECK(c.urdf.path == NULL);
	PX_CHECK_INT_EQ(c.urdf.clearance, PX_CONTROL_CLEARANCE_CAPSULES);
	/* lines 15..20: control, mode, device, avoidance, urdf, tip_link */
#define URDF_HEAD "control:\n  mode: avoidance\n  device: arm\n  avoidance:\n" \
		  "    urdf: a.urdf\n    tip_link: tool0\n"
	expect_control_error(URDF_HEAD "    joints:\n      - {dh: {a_m: 0.1}}\n",
			     "control.avoidance.joints", 22, "either urdf or joints");
	expect_control_error("control:\n  mode: avoidance\n  device: arm\n  avoidance:\n"
			     "    urdf: a.urdf\n",
			     "control.avoidance.tip_link", 19, "missing required key");
	expect_control_error("control:\n  mode: avoidance\n  device: arm\n  avoidance:\n"
			     "    clearance: models\n",
			     "control.avoidance.clearance", 19, "needs urdf");
	expect_control_error(URDF_HEAD "    clearance: capsules\n",
			     "control.avoidance.clearance", 21, "needs the capsules list");
	expect_control_error(URDF_HEAD "    urdf_joints: [a, b, a]\n",
			     "control.avoidance.urdf_joints[2]", 21, "listed twice");
	/* drive joint 1 of the head's arm beyond a one-joint mapping */
	expect_control_error(URDF_HEAD "    urdf_joints: [a]\n",
			     "control.device", 17, "avoidance.urdf_joints has 1 joints");
	expect_control_error(URDF_HEAD "    self_influence_distance_m: 0.01\n"
			     "    self_protective_distance_m: 0.02\n",
			     "control.avoidance.self_protective_distance_m", 22,
			     "smaller than");
#undef URDF_HEAD
}

static const struct px_test tests[] = {
	PX_T(test_segment_search_bounds),
	PX_T(test_force_limit),
	PX_T(test_passive_limit_formula),
	PX_T(test_wall_passivity_energy),
	PX_T(test_proxy_never_crosses_random),
	PX_T(test_proxy_never_crosses_with_friction),
	PX_T(test_proxy_plate_jump_through),
	PX_T(test_proxy_faces_and_corners),
	PX_T(test_proxy_moving_solid),
	PX_T(test_friction_stick_and_slip),
	PX_T(test_penalty_solids),
	PX_T(test_penalty_shell_side_tracking),
	PX_T(test_haptic_errors_ramp_down),
	PX_T(test_fk_planar_and_elbow_by_hand),
	PX_T(test_fk_urdf_matches_dh),
	PX_T(test_jacobian_finite_differences),
	PX_T(test_clearances_exact_and_searched),
	PX_T(test_avoid_scaling_law),
	PX_T(test_avoid_scripted_approaches),
	PX_T(test_cycles_do_not_allocate),
	PX_T(test_config_haptic_section),
	PX_T(test_config_errors),
	PX_T(test_config_chain_matches_code),
	PX_T(test_config_avoid_urdf),
	PX_T(test_config_docs_and_examples),
};
PX_TEST_MAIN(tests)
