/* Scene query helpers, force limiting and the passivity bound. */
#include <math.h>

#include "control_internal.h"

int px__ctl_point(const struct px_control_query *q, px_vec3 p,
		  double max_distance_m, struct px_control_hit *out,
		  int *count)
{
	int rc;
	out->valid = false;
	out->two_sided = false;
	out->distance_m = max_distance_m;
	out->point_m = p;
	out->normal = px_v3(0, 0, 1);
	if (count)
		(*count)++;
	rc = q->point(q->ctx, p, max_distance_m, out);
	if (rc < 0)
		return rc;
	if (!out->valid) {
		out->distance_m = max_distance_m;
		out->two_sided = false;
		return PX_OK;
	}
	if (!isfinite(out->distance_m) || !px_v3_isfinite(out->point_m) ||
	    !px_v3_isfinite(out->normal))
		return PX_E_NAN;
	{
		double n2 = px_v3_norm2(out->normal);
		/* A query that cannot give a direction (exactly on an edge of
		 * zero length, say) must not steer the proxy anywhere. */
		if (!(n2 > 0.5 && n2 < 2.0))
			return PX_E_DEGENERATE;
		out->normal = px_v3_scale(out->normal, 1.0 / sqrt(n2));
	}
	if (out->two_sided && out->distance_m < 0)
		out->distance_m = -out->distance_m;
	return PX_OK;
}

/* ---- segment distance by certified bisection ---------------------- */

struct seg_iv {
	double ta, tb, da, db;
};

static double iv_bound(const struct seg_iv *iv, double len)
{
	return 0.5 * (iv->da + iv->db - len * (iv->tb - iv->ta));
}

int px_control_query_segment(const struct px_control_query *q, px_vec3 a_m,
			     px_vec3 b_m, double max_distance_m,
			     int max_point_queries, double tol_m,
			     struct px_control_seg_hit *out)
{
	struct seg_iv iv[PX__CTL_SEG_MAX];
	struct px_control_hit h;
	double len, best;
	int n_iv = 0, used = 0, rc, k;
	if (!q || !q->point || !out)
		return PX_E_INVAL;
	if (!px_v3_isfinite(a_m) || !px_v3_isfinite(b_m) ||
	    !(max_distance_m > 0) || !(tol_m >= 0))
		return PX_E_NAN;
	if (q->segment) {
		rc = q->segment(q->ctx, a_m, b_m, max_distance_m, out);
		if (rc < 0)
			return rc;
		if (!out->hit.valid) {
			out->hit.distance_m = max_distance_m;
			out->lower_bound_m = max_distance_m;
			out->t = 0;
			return PX_OK;
		}
		if (!isfinite(out->hit.distance_m) || !isfinite(out->t) ||
		    !isfinite(out->lower_bound_m))
			return PX_E_NAN;
		if (out->lower_bound_m > out->hit.distance_m)
			out->lower_bound_m = out->hit.distance_m;
		return PX_OK;
	}
	if (max_point_queries < 2)
		max_point_queries = 2;
	if (max_point_queries > PX__CTL_SEG_MAX)
		max_point_queries = PX__CTL_SEG_MAX;
	len = px_v3_dist(a_m, b_m);
	rc = px__ctl_point(q, a_m, max_distance_m, &out->hit, &used);
	if (rc < 0)
		return rc;
	out->t = 0;
	best = out->hit.distance_m;
	out->lower_bound_m = best;
	if (len == 0)
		return PX_OK;
	rc = px__ctl_point(q, b_m, max_distance_m, &h, &used);
	if (rc < 0)
		return rc;
	iv[n_iv++] = (struct seg_iv){0.0, 1.0, best, h.distance_m};
	if (h.distance_m < best) {
		out->hit = h;
		out->t = 1;
		best = h.distance_m;
	}
	while (used < max_point_queries && n_iv < PX__CTL_SEG_MAX) {
		int lo = 0;
		double lb, tm;
		struct seg_iv cur;
		for (k = 1; k < n_iv; k++)
			if (iv_bound(&iv[k], len) < iv_bound(&iv[lo], len))
				lo = k;
		lb = iv_bound(&iv[lo], len);
		if (best - lb <= tol_m)
			break;
		cur = iv[lo];
		tm = 0.5 * (cur.ta + cur.tb);
		rc = px__ctl_point(q, px_v3_lerp(a_m, b_m, tm), max_distance_m,
				   &h, &used);
		if (rc < 0)
			return rc;
		if (h.distance_m < best) {
			out->hit = h;
			out->t = tm;
			best = h.distance_m;
		}
		iv[lo] = (struct seg_iv){cur.ta, tm, cur.da, h.distance_m};
		iv[n_iv++] = (struct seg_iv){tm, cur.tb, h.distance_m, cur.db};
	}
	out->lower_bound_m = best;
	for (k = 0; k < n_iv; k++) {
		double lb = iv_bound(&iv[k], len);
		if (lb < out->lower_bound_m)
			out->lower_bound_m = lb;
	}
	return PX_OK;
}

/* ---- force limits and passivity ----------------------------------- */

double px_control_passive_stiffness_limit(double device_damping_n_s_per_m,
					  double virtual_damping_n_s_per_m,
					  int64_t period_ns)
{
	double t = (double)period_ns * 1e-9;
	if (!(t > 0))
		return 0.0;
	/* Colgate & Schenkelberg: the sampled wall K, B on a device with
	 * damping b is passive iff b > K T / 2 + |B|. */
	return 2.0 * (device_damping_n_s_per_m - fabs(virtual_damping_n_s_per_m)) /
	       t;
}

static px_vec3 clamp_norm(px_vec3 f, double max_n, unsigned *flags,
			  unsigned bit)
{
	double n = px_v3_norm(f);
	if (n > max_n) {
		if (flags)
			*flags |= bit;
		return n > 0 ? px_v3_scale(f, max_n / n) : f;
	}
	return f;
}

px_vec3 px_control_force_limit(px_vec3 target_n, px_vec3 prev_n,
			       double max_force_n, double max_step_n,
			       unsigned *flags)
{
	px_vec3 d, f;
	double dn;
	if (flags)
		*flags = 0;
	if (!(max_force_n >= 0))
		max_force_n = 0;
	if (!(max_step_n >= 0))
		max_step_n = 0;
	if (!px_v3_isfinite(prev_n))
		prev_n = px_v3(0, 0, 0);
	if (!px_v3_isfinite(target_n))
		target_n = prev_n;
	f = clamp_norm(target_n, max_force_n, flags, PX_CONTROL_FORCE_CLAMPED);
	d = px_v3_sub(f, prev_n);
	dn = px_v3_norm(d);
	if (dn > max_step_n) {
		if (flags)
			*flags |= PX_CONTROL_FORCE_RATE_LIMITED;
		f = px_v3_madd(prev_n, d, max_step_n / dn);
	}
	/* prev_n may lie outside a clamp that was lowered since. */
	return clamp_norm(f, max_force_n, flags, PX_CONTROL_FORCE_CLAMPED);
}
