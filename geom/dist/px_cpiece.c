#include "px_cpiece.h"
#include "dist_internal.h"

#include <math.h>
#include <string.h>

int px_cpiece_init(struct px_cpiece *pc, int degree, const double (*hw)[4],
		   double u0, double u1)
{
	double hd[4][PX_CPIECE_MAX_DEGREE + 1];
	double k[3][2 * PX_CPIECE_MAX_DEGREE];
	double t1[PX_BERN_MAX_DEGREE + 1], t2[PX_BERN_MAX_DEGREE + 1];
	double one[PX_CPIECE_MAX_DEGREE * 2 + 1];
	int p = degree, i, c, j, wp;

	if (!pc || !hw)
		return PX_E_INVAL;
	if (p < 1 || p > PX_CPIECE_MAX_DEGREE)
		return PX_E_RANGE;
	if (!isfinite(u0) || !isfinite(u1))
		return PX_E_NAN;
	if (!(u0 < u1))
		return PX_E_INVAL;
	memset(pc, 0, sizeof(*pc));
	pc->degree_ = p;
	pc->u0_ = u0;
	pc->u1_ = u1;
	pc->box_ = px_aabb_empty();
	for (i = 0; i <= p; i++) {
		for (c = 0; c < 4; c++) {
			if (!isfinite(hw[i][c]))
				return PX_E_NAN;
			pc->h_[c][i] = hw[i][c];
		}
		if (!(hw[i][3] > 0.0))
			return PX_E_INVAL;
		px_aabb_extend(&pc->box_,
			       px_v3(hw[i][0] / hw[i][3], hw[i][1] / hw[i][3],
				     hw[i][2] / hw[i][3]));
	}
	/* Equal weights: divide them out; w is then the constant 1 and g
	 * drops from degree 3p - 1 to 2p - 1. */
	pc->wconst_ = 1;
	for (i = 1; i <= p; i++)
		if (pc->h_[3][i] != pc->h_[3][0])
			pc->wconst_ = 0;
	if (pc->wconst_) {
		double w0 = pc->h_[3][0];
		for (c = 0; c < 4; c++)
			for (i = 0; i <= p; i++)
				pc->h_[c][i] /= w0;
	}
	wp = pc->wconst_ ? 0 : p;
	pc->gdeg_ = 2 * p + wp - 1;
	for (c = 0; c < 4; c++) {
		px_bern_deriv(pc->h_[c], p, hd[c]);
		px_bern_scale(pc->h_[c], p, pc->hb_[c]);
		px_bern_scale(hd[c], p - 1, pc->hd_[c]);
	}
	pc->center_ = px_aabb_center(&pc->box_);
	pc->radius_ = 0.5 * px_aabb_diagonal(&pc->box_);
	pc->end_[0] = px_v3(hw[0][0] / hw[0][3], hw[0][1] / hw[0][3],
			    hw[0][2] / hw[0][3]);
	pc->end_[1] = px_v3(hw[p][0] / hw[p][3], hw[p][1] / hw[p][3],
			    hw[p][2] / hw[p][3]);
	/* K = H' w - H w' (degree p + wp - 1; with a constant w, K = H'). */
	for (c = 0; c < 3; c++) {
		if (pc->wconst_) {
			for (j = 0; j < p; j++)
				k[c][j] = hd[c][j];
			continue;
		}
		px_bern_mul(hd[c], p - 1, pc->h_[3], p, t1);
		px_bern_mul(pc->h_[c], p, hd[3], p - 1, t2);
		for (j = 0; j < 2 * p; j++)
			k[c][j] = t1[j] - t2[j];
	}
	/* a = H . K and b = w K raised to the same degree 2p + wp - 1
	 * (multiplying by the degree p - wp form of 1 raises the degree). */
	for (i = 0; i <= PX_CPIECE_MAX_DEGREE; i++)
		one[i] = 1.0;
	for (c = 0; c < 3; c++) {
		px_bern_mul(pc->h_[c], p, k[c], p + wp - 1, t1);
		for (j = 0; j <= pc->gdeg_; j++)
			pc->ga_[j] += t1[j];
		px_bern_mul(pc->h_[3], wp, k[c], p + wp - 1, t2);
		px_bern_mul(one, p - wp, t2, p + 2 * wp - 1, pc->gb_[c]);
	}
	/* w^2 f = |H|^2 - 2 P . (w H) + |P|^2 w^2, degree 2p. */
	for (c = 0; c < 3; c++) {
		px_bern_mul(pc->h_[c], p, pc->h_[c], p, t1);
		for (j = 0; j <= 2 * p; j++)
			pc->fa_[j] += t1[j];
		px_bern_mul(pc->h_[3], wp, pc->h_[c], p, t2);
		px_bern_mul(one, p - wp, t2, p + wp, pc->fb_[c]);
	}
	px_bern_mul(pc->h_[3], wp, pc->h_[3], wp, t2);
	px_bern_mul(one, 2 * (p - wp), t2, 2 * wp, pc->fw_);
	return PX_OK;
}

px_aabb px_cpiece_box(const struct px_cpiece *pc)
{
	return pc->box_;
}

/*
 * The four homogeneous components at t at once: the same Horner scheme
 * as px_bern_eval_scaled() (ratio t / (1 - t) or its mirror, at most 1),
 * with the ratio and the power of the base computed once for all four.
 */
static void eval4(const double (*cb)[PX_CPIECE_MAX_DEGREE + 1], int n, double t,
		  double v[4])
{
	double s, base, scale = 1.0, a0, a1, a2, a3;
	int i;

	if (t <= 0.5) {
		base = 1.0 - t;
		s = t / base;
		a0 = cb[0][n];
		a1 = cb[1][n];
		a2 = cb[2][n];
		a3 = cb[3][n];
		for (i = n - 1; i >= 0; i--) {
			a0 = a0 * s + cb[0][i];
			a1 = a1 * s + cb[1][i];
			a2 = a2 * s + cb[2][i];
			a3 = a3 * s + cb[3][i];
		}
	} else {
		base = t;
		s = (1.0 - t) / t;
		a0 = cb[0][0];
		a1 = cb[1][0];
		a2 = cb[2][0];
		a3 = cb[3][0];
		for (i = 1; i <= n; i++) {
			a0 = a0 * s + cb[0][i];
			a1 = a1 * s + cb[1][i];
			a2 = a2 * s + cb[2][i];
			a3 = a3 * s + cb[3][i];
		}
	}
	for (i = 0; i < n; i++)
		scale *= base;
	v[0] = a0 * scale;
	v[1] = a1 * scale;
	v[2] = a2 * scale;
	v[3] = a3 * scale;
}

px_vec3 px_cpiece_eval(const struct px_cpiece *pc, double t, px_vec3 *d1)
{
	double v[4], d[4];
	int c;

	eval4((const double(*)[PX_CPIECE_MAX_DEGREE + 1])pc->hb_, pc->degree_, t, v);
	if (d1) {
		for (c = 0; c < 4; c++)
			d[c] = px_bern_eval_scaled(pc->hd_[c], pc->degree_ - 1, t);
		/* Quotient rule, then the chain rule to the global parameter. */
		double s = 1.0 / (v[3] * v[3] * (pc->u1_ - pc->u0_));
		*d1 = px_v3((d[0] * v[3] - v[0] * d[3]) * s,
			    (d[1] * v[3] - v[1] * d[3]) * s,
			    (d[2] * v[3] - v[2] * d[3]) * s);
	}
	return px_v3(v[0] / v[3], v[1] / v[3], v[2] / v[3]);
}

/*
 * Lower bound of f = |C - P|^2 on [s, t]: with F = w^2 f and W = w^2 in
 * Bernstein form, F / W is a convex combination of F_i / W_i (W_i > 0).
 */
static double lower_bound(const double *f, const double *w, int n, double s,
			  double t)
{
	double fr[PX_CPIECE_NF], wr[PX_CPIECE_NF], lb = INFINITY;
	int i;

	/* w NULL: constant weight 1, F is f itself. */
	px_bern_restrict(f, n, s, t, fr);
	if (w)
		px_bern_restrict(w, n, s, t, wr);
	for (i = 0; i <= n; i++) {
		double r = w ? fr[i] / wr[i] : fr[i];
		lb = r < lb ? r : lb;
	}
	return lb;
}

/*
 * A polynomial of degree n (binomial-scaled coefficients cb) and its
 * derivative (degree n - 1, db) at x, sharing the ratio and the power of
 * the Horner scheme of px_bern_eval_scaled().
 */
static double eval_with_deriv(const double *cb, const double *db, int n,
			      double x, double *dv)
{
	double s, base, scale = 1.0, a, d;
	int i;

	if (x <= 0.5) {
		base = 1.0 - x;
		s = x / base;
		a = cb[n];
		d = db[n - 1];
		for (i = n - 1; i >= 0; i--) {
			a = a * s + cb[i];
			if (i < n - 1)
				d = d * s + db[i];
		}
	} else {
		base = x;
		s = (1.0 - x) / x;
		a = cb[0];
		d = db[0];
		for (i = 1; i <= n; i++) {
			a = a * s + cb[i];
			if (i < n)
				d = d * s + db[i];
		}
	}
	for (i = 0; i < n - 1; i++)
		scale *= base;
	*dv = d * scale;
	return a * scale * base;
}

/*
 * Root of a Bernstein polynomial with one sign change from - to + on
 * [0, 1]: Newton steps kept inside a shrinking bracket, bisection when a
 * step would leave it. Always converges; the bracket halves at worst.
 */
static double refine_root(const double *c, int n, int *iters)
{
	double lo = 0.0, hi = 1.0, flo = c[0], fhi = c[n], x;
	double cb[PX_CPIECE_NG], db[PX_CPIECE_NG];
	int it, i, side = 0;

	/* Scale once: every iteration then costs O(n). */
	for (i = 0; i < n; i++)
		db[i] = n * (c[i + 1] - c[i]);
	px_bern_scale(c, n, cb);
	px_bern_scale(db, n - 1, db);
	/* Start where the control polygon crosses zero: with a single sign
	 * change it crosses once, and it hugs the polynomial, so Newton
	 * starts within a few percent of the root. */
	x = 0.5;
	for (i = 0; i < n; i++) {
		if ((c[i] < 0.0 && c[i + 1] >= 0.0) ||
		    (c[i] <= 0.0 && c[i + 1] > 0.0)) {
			x = (i + c[i] / (c[i] - c[i + 1])) / n;
			break;
		}
	}
	for (it = 0; it < PX_CPIECE_MAX_ITERS; it++) {
		double dv, v = eval_with_deriv(cb, db, n, x, &dv), xn;
		if (v == 0.0)
			break;
		if (v < 0.0) {
			lo = x;
			flo = v;
			/* Illinois: an end kept twice has its value halved so
			 * false position keeps converging superlinearly. */
			if (side == -1)
				fhi *= 0.5;
			side = -1;
		} else {
			hi = x;
			fhi = v;
			if (side == 1)
				flo *= 0.5;
			side = 1;
		}
		xn = (dv != 0.0) ? x - v / dv : lo - 1.0;
		/* A Newton step leaving the bracket is replaced by false
		 * position inside it, which keeps the good start rather than
		 * jumping to the middle of a wide bracket as bisection would. */
		if (!(xn > lo && xn < hi)) {
			xn = (fhi - flo) > 0.0 ? (lo * fhi - hi * flo) / (fhi - flo)
					       : 0.5 * (lo + hi);
			if (!(xn > lo && xn < hi))
				xn = 0.5 * (lo + hi);
		}
		/* 1e-13 of the interval is far below what the distance
		 * (quadratic in the parameter error) or the foot point can
		 * resolve at the required 1e-9 of the model size. */
		if (fabs(xn - x) <= 1e-13 || hi - lo <= 1e-13) {
			x = xn;
			it++;
			break;
		}
		x = xn;
	}
	*iters += it;
	return x;
}

struct span {
	double s, t;
	/* g at s and at t, computed once where an interval was split and
	 * shared by both halves, so that the two halves can never disagree
	 * on the sign at their common end. */
	double gs, gt;
	int depth;
};

/* The point at t lowers the bound when it is nearer and, with a filter,
 * inside its trimmed domain (a critical point outside the domain is no
 * answer, and must not prune the ones inside). */
static inline __attribute__((always_inline)) void
consider(const struct px_cpiece *pc, px_vec3 p, double t,
		     const struct px__uv_filter *flt, double *best,
		     struct px_cpiece_hit *hit, int *improved)
{
	px_vec3 q = t <= 0.0 ? pc->end_[0]
			     : (t >= 1.0 ? pc->end_[1] : px_cpiece_eval(pc, t, NULL));
	double d2 = px_v3_dist2(q, p);
	if (d2 < *best) {
		double u = t >= 1.0 ? pc->u1_ : pc->u0_ + t * (pc->u1_ - pc->u0_);
		if (flt && !flt->inside(flt->ctx, flt->iso_dir == 1 ? flt->iso_t : u,
					flt->iso_dir == 1 ? u : flt->iso_t))
			return;
		*best = d2;
		hit->d2 = d2;
		hit->point = q;
		hit->u = u;
		*improved = 1;
	}
}

/* The solver, inlined into both entry points so that the plain one
 * (flt NULL) compiles without the filter. */
static inline __attribute__((always_inline)) int
closest(const struct px_cpiece *pc, px_vec3 p, const struct px__uv_filter *flt,
	double *best_d2, struct px_cpiece_hit *hit)
{
	double g[PX_CPIECE_NG], c[PX_CPIECE_NG], f[PX_CPIECE_NF], cs[PX_CPIECE_NG];
	double eps_g = 0.0;
	struct span stack[2 * PX_CPIECE_MAX_DEPTH + 4];
	int n = pc->gdeg_, nf = 2 * pc->degree_, sp = 0, i;
	int improved = 0;
	double best = *best_d2, pp = px_v3_dot(p, p), slack, lb_root = 0.0;
	double lb_unresolved = INFINITY;

	hit->iters = 0;
	hit->nodes = 0;
	hit->certified = 1;
	hit->gap = 0.0;
	/* Cheapest rejection first: a sphere around the box. */
	{
		double dc = px_v3_dist(p, pc->center_) - pc->radius_;
		if (dc > 0.0 && dc * dc >= best)
			goto out;
	}
	for (i = 0; i <= nf; i++)
		f[i] = pc->fa_[i] -
		       2.0 * (p.x * pc->fb_[0][i] + p.y * pc->fb_[1][i] +
			      p.z * pc->fb_[2][i]) +
		       pp * (pc->wconst_ ? 1.0 : pc->fw_[i]);
	/* Rounding in F is about 1e-16 of |H|^2 + |P|^2 w^2; an interval
	 * whose bound is within a few hundred times that of the best can
	 * only improve it by rounding noise, so it is settled. This is what
	 * stops endless subdivision where every point is equally near (a
	 * circle seen from its centre). */
	{
		double r = px_v3_dist(pc->center_, p) + 2.0 * pc->radius_;
		slack = 1e-13 * (r * r + px_v3_dot(pc->center_, pc->center_));
	}
	{
		double lb = INFINITY;
		for (i = 0; i <= nf; i++) {
			double r = pc->wconst_ ? f[i] : f[i] / pc->fw_[i];
			lb = r < lb ? r : lb;
		}
		if (lb >= best - slack)
			goto out;
		lb_root = lb;
	}
	/* End points: candidates in their own right (open ends, corners
	 * at knots) and a bound that prunes early. */
	consider(pc, p, 0.0, flt, &best, hit, &improved);
	consider(pc, p, 1.0, flt, &best, hit, &improved);
	for (i = 0; i <= n; i++)
		g[i] = pc->ga_[i] - (p.x * pc->gb_[0][i] + p.y * pc->gb_[1][i] +
				     p.z * pc->gb_[2][i]);
	/* Rounding in g is about 1e-16 of its largest coefficient per
	 * operation; values within 1e-13 of it count as zero. */
	{
		double gmax = 0.0;
		for (i = 0; i <= n; i++)
			gmax = fabs(g[i]) > gmax ? fabs(g[i]) : gmax;
		eps_g = 1e-13 * gmax;
	}
	stack[sp].s = 0.0;
	stack[sp].t = 1.0;
	stack[sp].gs = g[0];
	stack[sp].gt = g[n];
	stack[sp].depth = 0;
	sp++;
	while (sp > 0) {
		struct span e = stack[--sp];
		double lb;
		int sc, k;

		if (hit->nodes >= PX_CPIECE_MAX_NODES) {
			sp++; /* account for it below */
			break;
		}
		hit->nodes++;
		/* The root interval's bound was computed above. */
		lb = e.depth ? lower_bound(f, pc->wconst_ ? NULL : pc->fw_, nf, e.s, e.t)
			     : lb_root;
		if (lb >= best - slack)
			continue;
		px_bern_restrict(g, n, e.s, e.t, c);
		/* The end coefficients are the values at the ends: use the
		 * shared ones. A root exactly at an end (within rounding) is
		 * invisible to the sign count, which skips zeros: the end
		 * itself is then the candidate. */
		c[0] = e.gs;
		c[n] = e.gt;
		if (fabs(c[0]) <= eps_g) {
			consider(pc, p, e.s, flt, &best, hit, &improved);
			c[0] = 0.0;
		}
		if (fabs(c[n]) <= eps_g) {
			consider(pc, p, e.t, flt, &best, hit, &improved);
			c[n] = 0.0;
		}
		sc = px_bern_sign_changes(c, n, 0.0);
		if (sc == 0)
			continue; /* f monotone here: no interior minimum */
		if (sc == 1) {
			for (k = 0; k <= n && c[k] == 0.0; k++)
				;
			if (k > n || c[k] > 0.0)
				continue; /* the one critical point is a maximum */
			consider(pc, p,
				 e.s + refine_root(c, n, &hit->iters) * (e.t - e.s),
				 flt, &best, hit, &improved);
			continue;
		}
		if (e.depth >= PX_CPIECE_MAX_DEPTH) {
			consider(pc, p, 0.5 * (e.s + e.t), flt, &best, hit, &improved);
			lb_unresolved = fmin(lb_unresolved, lb);
			continue;
		}
		{
			double m = 0.5 * (e.s + e.t), gm;
			px_bern_split(c, n, 0.5, NULL, cs);
			gm = cs[0];
			stack[sp].s = m;
			stack[sp].t = e.t;
			stack[sp].gs = gm;
			stack[sp].gt = e.gt;
			stack[sp].depth = e.depth + 1;
			sp++;
			stack[sp].s = e.s;
			stack[sp].t = m;
			stack[sp].gs = e.gs;
			stack[sp].gt = gm;
			stack[sp].depth = e.depth + 1;
			sp++;
		}
	}
	/* Intervals left by the node bound: their boxes bound what we may
	 * have missed. */
	for (i = 0; i < sp; i++)
		lb_unresolved = fmin(lb_unresolved,
				     lower_bound(f, pc->wconst_ ? NULL : pc->fw_, nf, stack[i].s,
						 stack[i].t));
	if (lb_unresolved < best - slack) {
		hit->certified = 0;
		hit->gap = sqrt(best) - sqrt(fmax(lb_unresolved, 0.0));
	}
out:
	*best_d2 = best;
	return improved;
}

int px_cpiece_closest(const struct px_cpiece *pc, px_vec3 p, double *best_d2,
		      struct px_cpiece_hit *hit)
{
	return closest(pc, p, NULL, best_d2, hit);
}

int px__cpiece_closest_in(const struct px_cpiece *pc, px_vec3 p,
			  const struct px__uv_filter *flt, double *best_d2,
			  struct px_cpiece_hit *hit)
{
	return closest(pc, p, flt, best_d2, hit);
}
