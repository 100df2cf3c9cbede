/*
 * track_eval.c - curve tracker (px_track.h): span evaluation, Bernstein
 * roots and the root isolation of one leaf. The layout and the shared
 * declarations are in track_internal.h.
 */
#include "track_internal.h"

/* ------------------------------------------------------------------ */
/* evaluation                                                          */

/* ------------------------------------------------------------------ */
/* root isolation on one leaf                                          */

/* Bernstein polynomial and its derivative at x by de Casteljau (exact
 * enough near the ends, no library call): the last level's two values
 * give f = (1-x) b0 + x b1 and f' = n (b1 - b0). */
static inline double bern_val_d(const double *c, int n, double x, double *d)
{
	double b[TRK_NG + 1], y = 1.0 - x;
	int i, k;
	if (n == 0) {
		*d = 0.0;
		return c[0];
	}
	for (i = 0; i <= n; i++)
		b[i] = c[i];
	for (k = n; k > 1; k--)
		for (i = 0; i < k; i++)
			b[i] = y * b[i] + x * b[i + 1];
	*d = n * (b[1] - b[0]);
	return y * b[0] + x * b[1];
}

static double bern_root(const double *c, int n)
{
	double lo = 0.0, hi = 1.0, x = 0.5, flo = c[0], fe;
	int k, i;
	/* start where the control polygon crosses zero (it converges to
	 * the curve quadratically under subdivision) */
	for (i = 0; i < n; i++)
		if ((c[i] < 0.0) != (c[i + 1] < 0.0)) {
			x = (i + c[i] / (c[i] - c[i + 1])) / n;
			break;
		}
	if (!(x > 0.0 && x < 1.0))
		x = 0.5;
	/* rounding level of an evaluation: below it f carries no sign
	 * information and the iterate is as good as it gets */
	{
		double cm = 0.0;
		for (i = 0; i <= n; i++)
			if (fabs(c[i]) > cm)
				cm = fabs(c[i]);
		fe = 4.0 * (n + 1) * 2.2e-16 * cm;
	}
	for (k = 0; k < 100; k++) {
		double d, f = bern_val_d(c, n, x, &d), nx;
		if (fabs(f) <= fe)
			return x;
		if ((f < 0.0) == (flo < 0.0)) {
			lo = x;
			flo = f;
		} else {
			hi = x;
		}
		nx = (d != 0.0) ? x - f / d : 0.5 * (lo + hi);
		if (!(nx > lo && nx < hi))
			nx = 0.5 * (lo + hi);
		/* a Newton step of 1e-14 leaves an error far below rounding;
		 * smaller steps are rounding noise (waiting for an exact 0
		 * step can take dozens of bisections) */
		if (fabs(nx - x) <= 1e-14 || hi - lo <= 1e-16)
			return nx;
		x = nx;
	}
	return x;
}

/* Divide a Bernstein polynomial of degree n with a root at t = 0 (end 0)
 * or t = 1 (end 1) by t or (1 - t): degree n - 1. */
void px__tk_bern_divide(double *c, int n, int end)
{
	int i;
	if (end == 0) {
		for (i = 1; i <= n; i++)
			c[i - 1] = c[i] * n / i;
	} else {
		for (i = 0; i < n; i++)
			c[i] = c[i] * n / (n - i);
	}
}

struct iso_item {
	double c[TRK_NG + 1];
	double min, max;
	int depth;
};

/*
 * All roots of the leaf's g at p, in increasing order, into u/type (cap).
 * Returns the count, PX_E_NOSPC (more than cap) or PX_E_RANGE (a cluster
 * not separated at the depth bound: not certified).
 */
int px__tk_leaf_roots(const struct px_track *t, const struct leaf *l,
		      px_vec3 p, double *u, int *type, int cap)
{
	struct iso_item st[TRK_DEPTH + 3];
	const double *a = leaf_a(t, l);
	int n = l->n, sp = 1, nr = 0, i;

	for (i = 0; i <= n; i++)
		st[0].c[i] = gco(a, n, i, p);
	/* A root on a leaf boundary (the point on a normal plane there, e.g.
	 * exactly on the curve at a knot) belongs to the leaf it starts:
	 * claimed here unless the start is a stretch boundary (a candidate
	 * already), and divided out of both neighbours so the sign counts
	 * below stay exact. */
	if (n >= 1 && fabs(st[0].c[0]) <= l->tol_g) {
		if (!(l->flags & LF_SB0)) {
			for (i = 1; i <= n; i++)
				if (fabs(st[0].c[i]) > l->tol_g)
					break;
			if (i <= n) {
				if (nr >= cap)
					return PX_E_NOSPC;
				u[nr] = l->u0;
				type[nr] = st[0].c[i] > 0.0 ? 1 : -1;
				nr++;
			}
		}
		st[0].c[0] = 0.0;
		px__tk_bern_divide(st[0].c, n, 0);
		n--;
	}
	if (n >= 1 && fabs(st[0].c[n]) <= l->tol_g) {
		st[0].c[n] = 0.0;
		px__tk_bern_divide(st[0].c, n, 1);
		n--;
	}
	st[0].min = 0.0;
	st[0].max = 1.0;
	st[0].depth = 0;
	while (sp > 0) {
		struct iso_item it = st[--sp];
		int v = px_bern_sign_changes(it.c, n, 0.0);
		if (v == 0)
			continue;
		if (v == 1) {
			double x = bern_root(it.c, n), first = 0.0;
			for (i = 0; i <= n && first == 0.0; i++)
				first = it.c[i];
			if (nr >= cap)
				return PX_E_NOSPC;
			u[nr] = l->u0 + (l->u1 - l->u0) *
					(it.min + x * (it.max - it.min));
			type[nr] = first < 0.0 ? 1 : -1;
			nr++;
			continue;
		}
		if (it.depth >= TRK_DEPTH)
			return PX_E_RANGE;
		{
			/* right half below the left one: roots come out sorted */
			struct iso_item *r = &st[sp], *lf = &st[sp + 1];
			double mid = 0.5 * (it.min + it.max);
			memcpy(lf->c, it.c, (size_t)(n + 1) * sizeof(double));
			bern_halves(lf->c, n, r->c);
			r->min = mid;
			r->max = it.max;
			lf->min = it.min;
			lf->max = mid;
			r->depth = lf->depth = it.depth + 1;
			sp += 2;
		}
	}
	return nr;
}
