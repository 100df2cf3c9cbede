/*
 * dist_decomp.c - the knowledge step of the distance core's setup: each
 * entity's parametrization factor picks its decomposition tolerance and
 * jitter, and the entity is cut into pieces (curves by nearly uniform
 * chords, surfaces by the cuts of their longest iso-curves).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "dist_internal.h"

/* ---- knowledge step: parametrization factor ---------------------------- */

/*
 * Decomposition tolerance and jitter by parametrization factor (paper
 * section 5 and its table): the further the speed |C'| varies, the finer
 * the pieces and the more uniform their spacing. The table's finest row
 * (1 %) serves Newton starts; pieces here carry their own proofs, so the
 * callers floor it at the paper's recommended settings (5 % for curves,
 * 10 % for surfaces), where boxes are tight and candidates few.
 */
static void pf_table(double pf, double *tol, double *jit)
{
	if (pf <= 0.2) {
		*tol = 0.2;
		*jit = 0.5;
	} else if (pf <= 0.4) {
		*tol = 0.1;
		*jit = 0.6;
	} else if (pf <= 0.7) {
		*tol = 0.05;
		*jit = 0.7;
	} else {
		*tol = 0.01;
		*jit = 0.8;
	}
}

/* Settings for an entity from its info->pf: the table, floored at
 * floor_tol, unless the options fix tolerance or jitter. */
void px__dist_decomp_settings(struct px_dist_entity_info *info,
			      double floor_tol, const struct px_dist_opts *o)
{
	double tol, jit;
	pf_table(info->pf, &tol, &jit);
	if (tol < floor_tol)
		tol = floor_tol;
	info->tol = o->decomp_tol > 0.0 ? o->decomp_tol : tol;
	info->jitter = o->jitter > 0.0 ? o->jitter : jit;
}

static double speed(const struct px_nurbs_curve *c, double u, int side)
{
	px_vec3 d[2];
	px_nurbs_curve_eval_side(c, u, side, 1, d);
	return px_v3_norm(d[1]);
}

/* Sorted distinct interior knots: the span boundaries. */
static int interior_knots(const struct px_nurbs_curve *c, double a, double b,
			  double *out)
{
	int i, n = 0;
	for (i = 0; i < c->n_knots; i++) {
		double k = c->knots[i];
		if (k > a && k < b && (n == 0 || k > out[n - 1]))
			out[n++] = k;
	}
	return n;
}

#define SPAN_SAMPLES 16

static int push(struct px__dist_cuts *d, double u)
{
	if (d->n == d->cap) {
		int nc = d->cap ? 2 * d->cap : 64;
		double *nu = realloc(d->u, (size_t)nc * sizeof(double));
		if (!nu)
			return PX_E_NOMEM;
		d->u = nu;
		d->cap = nc;
	}
	d->u[d->n++] = u;
	return PX_OK;
}

static int cmp_double(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

/*
 * Speed range and arc length of a curve from SPAN_SAMPLES per span
 * (speeds at knots from both sides: they differ at C0 breaks), and its
 * cusps into cusps: local minima of the sampled speed, refined by golden
 * section, where the speed (almost) vanishes inside the span. Fills
 * info's n_cusps, arc_length and pf.
 */
static int speed_scan(const struct px_nurbs_curve *c, double a, double b,
		      const double *knots, int nk,
		      struct px_dist_entity_info *info,
		      struct px__dist_cuts *cusps)
{
	double dmin = INFINITY, dmax = 0.0, len = 0.0, u;
	int i, j, rc;
	px_vec3 prev = px_nurbs_curve_point(c, a);

	for (i = 0; i <= nk; i++) {
		double s0 = i == 0 ? a : knots[i - 1], s1 = i == nk ? b : knots[i];
		double sp[SPAN_SAMPLES + 1];
		for (j = 0; j <= SPAN_SAMPLES; j++) {
			double t = s0 + (s1 - s0) * j / SPAN_SAMPLES;
			px_vec3 q = px_nurbs_curve_point(c, t);
			sp[j] = speed(c, t, j == SPAN_SAMPLES ? -1 : 1);
			dmin = fmin(dmin, sp[j]);
			dmax = fmax(dmax, sp[j]);
			len += px_v3_dist(prev, q);
			prev = q;
		}
		for (j = 1; j < SPAN_SAMPLES; j++) {
			double lo, hi;
			int k;
			if (!(sp[j] <= sp[j - 1] && sp[j] <= sp[j + 1]))
				continue;
			lo = s0 + (s1 - s0) * (j - 1) / SPAN_SAMPLES;
			hi = s0 + (s1 - s0) * (j + 1) / SPAN_SAMPLES;
			for (k = 0; k < 80; k++) {
				double x1 = hi - (hi - lo) * 0.6180339887498949;
				double x2 = lo + (hi - lo) * 0.6180339887498949;
				if (speed(c, x1, 1) < speed(c, x2, 1))
					hi = x2;
				else
					lo = x1;
			}
			u = 0.5 * (lo + hi);
			if (speed(c, u, 1) <= 1e-7 * dmax && u > s0 && u < s1) {
				rc = push(cusps, u);
				if (rc)
					return rc;
			}
		}
	}
	info->n_cusps = cusps->n;
	info->arc_length = len;
	info->pf = dmax > 0.0 ? (dmax - dmin) / dmax : 1.0;
	return PX_OK;
}

/*
 * Nearly uniform stepping over [a, b] with chord length in [jit * tol *
 * len, tol * len]: each step starts from the previous increment (spatial
 * coherence) and is brought into the chord band by bisection. PX_E_NOSPC
 * past max_steps.
 */
static int uniform_steps(const struct px_nurbs_curve *c, double a, double b,
			 double len, double tol, double jit, int max_steps,
			 struct px__dist_cuts *steps)
{
	double eps_u = tol * len, eps_l = jit * eps_u, u = a, du = (b - a) * tol;
	int guard, rc;
	px_vec3 prev = px_nurbs_curve_point(c, a);

	for (guard = 0; len > 0.0 && guard < max_steps; guard++) {
		double lo = u, hi = b, x = fmin(u + du, b), d;
		int k, overshot = 0;
		for (k = 0; k < 60; k++) {
			d = px_v3_dist(prev, px_nurbs_curve_point(c, x));
			if (d > eps_u) {
				hi = x;
				overshot = 1;
			} else if (d < eps_l && x < b) {
				lo = x;
			} else {
				break;
			}
			/* Grow the step until the chord overshoots, then
			 * bisect: growing from the last step rather than
			 * bisecting towards the domain end keeps the step from
			 * jumping across a loop to a far part of the curve. */
			x = overshot ? 0.5 * (lo + hi) : fmin(b, u + 2 * (x - u));
		}
		if (x >= b || b - x < 1e-3 * (x - u))
			break;
		rc = push(steps, x);
		if (rc)
			return rc;
		du = x - u;
		u = x;
		prev = px_nurbs_curve_point(c, u);
	}
	return guard >= max_steps ? PX_E_NOSPC : PX_OK;
}

/*
 * The cuts in out, sorted and distinct: ends, knots, cusps, then the
 * steps not within gap of one of those mandatory cuts (which would leave
 * a sliver piece).
 */
static int merge_cuts(double a, double b, const double *knots, int nk,
		      const struct px__dist_cuts *cusps,
		      const struct px__dist_cuts *steps, double gap,
		      struct px__dist_cuts *out)
{
	int i, j, mandatory, rc;

	rc = push(out, a);
	for (i = 0; !rc && i < nk; i++)
		rc = push(out, knots[i]);
	for (i = 0; !rc && i < cusps->n; i++)
		rc = push(out, cusps->u[i]);
	if (!rc)
		rc = push(out, b);
	if (rc)
		return rc;
	qsort(out->u, (size_t)out->n, sizeof(double), cmp_double);
	mandatory = out->n;
	for (i = 0; i < steps->n; i++) {
		double s = steps->u[i];
		int ok = 1;
		for (j = 0; j < mandatory; j++)
			if (fabs(out->u[j] - s) < gap)
				ok = 0;
		if (ok && (rc = push(out, s)))
			return rc;
	}
	qsort(out->u, (size_t)out->n, sizeof(double), cmp_double);
	/* Drop exact duplicates. */
	for (i = 1, j = 1; i < out->n; i++)
		if (out->u[i] > out->u[j - 1])
			out->u[j++] = out->u[i];
	out->n = j;
	return PX_OK;
}

/*
 * Parameters that cut one curve into pieces: domain ends, every interior
 * knot (so pieces are Bezier), cusps, and nearly uniform steps (paper
 * section 5) with chord length in [jit * tol * L, tol * L].
 */
int px__dist_decompose(const struct px_nurbs_curve *c,
		       const struct px_dist_opts *o,
		       struct px_dist_entity_info *info,
		       struct px__dist_cuts *out)
{
	double a, b, *knots;
	struct px__dist_cuts cusps = {0}, steps = {0};
	int nk, rc;

	px_nurbs_curve_domain(c, &a, &b);
	knots = malloc((size_t)c->n_knots * sizeof(double));
	if (!knots)
		return PX_E_NOMEM;
	nk = interior_knots(c, a, b, knots);
	info->n_breaks = px_nurbs_curve_breaks(c, NULL, 0);
	{
		px_aabb hull = px_nurbs_curve_aabb(c);
		info->closed = px_nurbs_curve_seam(
				       c, 1e-12 * (1.0 + px_aabb_diagonal(&hull)),
				       1e-9) >= 0;
	}
	rc = speed_scan(c, a, b, knots, nk, info, &cusps);
	if (!rc) {
		px__dist_decomp_settings(info, 0.05, o);
		rc = uniform_steps(c, a, b, info->arc_length, info->tol,
				   info->jitter, o->max_pieces_per_entity, &steps);
	}
	if (!rc)
		rc = merge_cuts(a, b, knots, nk, &cusps, &steps,
				(b - a) * info->tol * 0.25, out);
	if (!rc && out->n - 1 > o->max_pieces_per_entity)
		rc = PX_E_NOSPC;
	free(knots);
	free(cusps.u);
	free(steps.u);
	return rc;
}

/* ---- surfaces: decomposition ------------------------------------------ */

/* Speed of a surface along one direction at (u, v). */
static double surf_speed(const struct px_nurbs_surf *s, double u, double v,
			 int dir)
{
	struct px_nurbs_surf_derivs d;
	px_nurbs_surf_eval(s, u, v, 1, &d);
	return px_v3_norm(dir == 0 ? d.su : d.sv);
}

/* Approximate length of a curve from SPAN_SAMPLES chords per span. */
static double curve_length(const struct px_nurbs_curve *c)
{
	double a, b, len = 0.0;
	int k, j;
	px_vec3 prev;
	px_nurbs_curve_domain(c, &a, &b);
	prev = px_nurbs_curve_point(c, a);
	for (k = c->degree; k < c->n_ctrl; k++) {
		double s0 = c->knots[k], s1 = c->knots[k + 1];
		if (!(s1 > s0) || s1 <= a || s0 >= b)
			continue;
		for (j = 1; j <= SPAN_SAMPLES; j++) {
			px_vec3 q = px_nurbs_curve_point(c, s0 + (s1 - s0) * j / SPAN_SAMPLES);
			len += px_v3_dist(prev, q);
			prev = q;
		}
	}
	return len;
}

/*
 * Cut parameters of a surface in direction dir: the nearly uniform steps
 * of its longest iso-curve in that direction (paper section 5), which
 * include the direction's knots. The iso-curves compared are those at
 * the other direction's knots and span middles.
 */
int px__dist_surf_cuts(const struct px_nurbs_surf *s, int dir,
		       const struct px_dist_opts *o, double *len_out,
		       struct px__dist_cuts *out)
{
	int other = 1 - dir, nk = s->n_knots[other], k, rc;
	const double *kn = s->knots[other];
	size_t pwl = 4 * (size_t)s->n_ctrl[dir];
	double *pw = malloc(pwl * sizeof(double)), best_len = -1.0, best_t = 0.0;
	double a, b, c0, c1;
	struct px_nurbs_curve iso;
	struct px_dist_entity_info info;

	if (!pw)
		return PX_E_NOMEM;
	px_nurbs_surf_domain(s, &a, &b, &c0, &c1);
	if (other == 0) {
		c0 = a;
		c1 = b;
	}
	for (k = 0; k + 1 < nk; k++) {
		double t0 = kn[k], t1 = kn[k + 1], ts[2];
		int j;
		if (!(t1 > t0) || t1 <= c0 || t0 >= c1)
			continue;
		ts[0] = t0 < c0 ? c0 : t0;
		ts[1] = 0.5 * (t0 + t1);
		for (j = 0; j < 2; j++) {
			double l;
			if (px_nurbs_surf_iso_curve(s, dir, ts[j], pw, pwl, &iso))
				continue;
			l = curve_length(&iso);
			if (l > best_len) {
				best_len = l;
				best_t = ts[j];
			}
		}
	}
	{
		double l;
		if (!px_nurbs_surf_iso_curve(s, dir, c1, pw, pwl, &iso)) {
			l = curve_length(&iso);
			if (l > best_len) {
				best_len = l;
				best_t = c1;
			}
		}
	}
	rc = px_nurbs_surf_iso_curve(s, dir, best_t, pw, pwl, &iso);
	if (!rc) {
		memset(&info, 0, sizeof(info));
		rc = px__dist_decompose(&iso, o, &info, out);
	}
	*len_out = best_len > 0.0 ? best_len : 0.0;
	free(pw);
	return rc;
}

/* Parametrization factor of a surface: speed range in u and in v over
 * SPAN_SAMPLES^2 samples per knot rectangle. */
double px__dist_surf_pf(const struct px_nurbs_surf *s)
{
	double a, b, c, d, pf = 0.0;
	int dir;
	px_nurbs_surf_domain(s, &a, &b, &c, &d);
	for (dir = 0; dir < 2; dir++) {
		double mn = INFINITY, mx = 0.0;
		int i, j, ku, kv;
		for (ku = s->degree[0]; ku < s->n_ctrl[0]; ku++) {
			double u0 = s->knots[0][ku], u1 = s->knots[0][ku + 1];
			if (!(u1 > u0))
				continue;
			for (kv = s->degree[1]; kv < s->n_ctrl[1]; kv++) {
				double v0 = s->knots[1][kv], v1 = s->knots[1][kv + 1];
				if (!(v1 > v0))
					continue;
				for (i = 0; i <= 4; i++)
					for (j = 0; j <= 4; j++) {
						double sp = surf_speed(s, u0 + (u1 - u0) * i / 4,
								       v0 + (v1 - v0) * j / 4, dir);
						mn = sp < mn ? sp : mn;
						mx = sp > mx ? sp : mx;
					}
			}
		}
		/* A collapsed edge (pole) has zero speed along it: that is a
		 * property of the parametrization, and pf says so. */
		if (mx > 0.0 && (mx - mn) / mx > pf)
			pf = (mx - mn) / mx;
	}
	return pf;
}
