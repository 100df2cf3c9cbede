/*
 * track_crit.c - curve tracker (px_track.h): the entity state: the zeros of
 * g (critical points) of each entity, their stamps, checks, Newton and
 * evolution along a step. The layout and the shared declarations are in
 * track_internal.h.
 */
#include "track_internal.h"

/* ------------------------------------------------------------------ */
/* entity state                                                        */

/* Travel (path length) the point may still cover from p before a root
 * of leaf l can leave it through an end: the end values of g are affine
 * in p, so none changes sign within |value| / |p-gradient| (0 when an
 * end value is too close to zero to tell). With no event inside the leaf
 * (it is not re-solved) its roots keep their number and stay in it. */
double px__tk_leaf_end_radius(const struct px_track *t, const struct leaf *l,
			      px_vec3 p)
{
	const double *a = leaf_a(t, l), *ib = t->ipool + l->ioff;
	double v0 = fabs(gco(a, l->n, 0, p)) - l->tol_g;
	if (t->fault & 8)
		return INFINITY;
	double v1 = fabs(gco(a, l->n, l->n, p)) - l->tol_g;
	if (!(v0 > 0.0) || !(v1 > 0.0))
		return 0.0;
	v0 *= ib[0];
	v1 *= ib[l->n];
	return v0 < v1 ? v0 : v1;
}

/* Record a correction of z at p (now). */
static void zero_stamp(const struct px_track *t, struct zero *z, px_vec3 p)
{
	z->p = p;
	z->trav = t->travel;
	z->dist = px_v3_dist(z->c, p);
	z->ep = t->epoch;
	z->until = t->opts.lazy
			   ? t->travel + px__tk_leaf_end_radius(t, &t->leaf[z->leaf], p) *
						 (1.0 - 1e-9)
			   : -1.0;
}

static void zero_eval(const struct px_track *t, const struct ent *e,
		      struct zero *z, px_vec3 p)
{
	px_vec3 c, d1, d2;
	span_eval(find_span(t, e, z->u), z->u, &c, &d1, &d2);
	z->c = c;
	z->d1 = d1;
	z->D = px_v3_dot(px_v3_sub(c, p), d2) + px_v3_dot(d1, d1);
	zero_stamp(t, z, p);
}

static int cmp_zero(const struct zero *a, const struct zero *b)
{
	return a->u > b->u;
}

void px__tk_sort_zeros(struct ent *e)
{
	int i, j;
	/* usually still sorted: one pass of comparisons, no copies */
	for (i = 1; i < e->nz; i++)
		if (e->z[i - 1].u > e->z[i].u)
			break;
	for (; i < e->nz; i++) {
		struct zero z = e->z[i];
		for (j = i; j > 0 && cmp_zero(&e->z[j - 1], &z); j--)
			e->z[j] = e->z[j - 1];
		e->z[j] = z;
	}
}

/* Give a new root the id of the nearest dropped root of the same type. */
static uint32_t inherit_id(struct px_track *t, struct ent *e, double u,
			   int type)
{
	int i, best = -1;
	double bd = 0.05 * e->len;
	for (i = 0; i < e->nold; i++) {
		double d;
		if (e->old[i].type != type || e->old[i].id == 0)
			continue;
		d = fabs(e->old[i].u - u);
		if (e->cyclic)
			d = fmin(d, e->len - d);
		if (d <= bd) {
			bd = d;
			best = i;
		}
	}
	if (best >= 0) {
		uint32_t id = e->old[best].id;
		e->old[best].id = 0;
		return id;
	}
	if (++t->next_id >= 0x7fffffffu)
		t->next_id = 1;
	return t->next_id;
}

/* Append the roots of leaf li at p. Returns the count or an error. */
int px__tk_add_leaf_roots(struct px_track *t, struct ent *e, int li, px_vec3 p)
{
	double u[TRK_NG + 1];
	int ty[TRK_NG + 1], n, i;
	n = px__tk_leaf_roots(t, &t->leaf[li], p, u, ty, TRK_NG + 1);
	if (n < 0)
		return n;
	if (e->nz + n > e->cap)
		return PX_E_NOSPC;
	for (i = 0; i < n; i++) {
		struct zero *z = &e->z[e->nz++];
		z->u = u[i];
		z->type = ty[i];
		z->leaf = li;
		z->id = inherit_id(t, e, u[i], ty[i]);
		zero_eval(t, e, z, p);
	}
	return n;
}

/* Sign of g at the start (side 0) or end (side 1) of leaf li at p, with
 * 0 for "too close to tell". */
static int leaf_end_sign(const struct px_track *t, int li, int side, px_vec3 p)
{
	const struct leaf *l = &t->leaf[li];
	double v = gco(leaf_a(t, l), l->n, side ? l->n : 0, p);
	if (fabs(v) <= l->tol_g)
		return 0;
	return v > 0.0 ? 1 : -1;
}

int px__tk_ent_dups(const struct ent *e)
{
	int i;
	double dtol = 1e-11 * e->len;
	for (i = 1; i < e->nz; i++)
		if (e->z[i].u - e->z[i - 1].u <= dtol)
			return 1;
	if (e->cyclic && e->nz >= 2 &&
	    e->z[0].u + e->len - e->z[e->nz - 1].u <= dtol)
		return 1;
	return 0;
}

/*
 * Structure check at p: sorted, no duplicates, types alternate inside
 * every C1 stretch and agree with the sign of f' at the stretch ends.
 * Returns 0 when consistent.
 */
int px__tk_ent_check(const struct px_track *t, const struct ent *e, px_vec3 p)
{
	int i, j, k0 = -1, zi, n = e->n_leaves;

	if (px__tk_ent_dups(e))
		return 1;
	if (e->n_sb == 0) {
		/* one closed stretch: even count, alternating cyclically */
		if (e->nz & 1)
			return 1;
		for (i = 0; i < e->nz; i++)
			if (e->z[i].type == e->z[(i + 1) % e->nz].type)
				return 1;
		return 0;
	}
	for (j = 0; j < n; j++)
		if (t->leaf[e->first_leaf + j].flags & LF_SB0) {
			k0 = j;
			break;
		}
	if (k0 < 0)
		return 1;
	/* first zero at or after leaf k0 (cyclic order) */
	zi = 0;
	while (zi < e->nz && e->z[zi].leaf - e->first_leaf < k0)
		zi++;
	{
		int expect = 0, seen = 0;
		for (j = 0; j < n; j++) {
			int lj = (k0 + j) % n, li = e->first_leaf + lj;
			const struct leaf *l = &t->leaf[li];
			if (l->flags & LF_SB0) {
				int s = leaf_end_sign(t, li, 0, p);
				expect = s < 0 ? 1 : (s > 0 ? -1 : 0);
			}
			while (seen < e->nz) {
				const struct zero *z = &e->z[zi % e->nz];
				if (z->leaf != li)
					break;
				if (expect && z->type != expect)
					return 1;
				expect = -z->type;
				zi++;
				seen++;
			}
			if (l->flags & LF_SB1) {
				int s = leaf_end_sign(t, li, 1, p);
				/* after a minimum g > 0, after a maximum g < 0 */
				if (s && expect && s != -expect)
					return 1;
			}
		}
		if (seen != e->nz)
			return 1;
	}
	return 0;
}

/* Rebuild one entity at p. Returns 0, PX_E_NOSPC or PX_E_RANGE. */
int px__tk_ent_reinit(struct px_track *t, struct ent *e, px_vec3 p)
{
	int i, rc;
	e->rest_until = -1.0;
	e->resting = 0;
	memcpy(e->old, e->z, (size_t)e->nz * sizeof(*e->z));
	e->nold = e->nz;
	e->nz = 0;
	for (i = 0; i < e->n_leaves; i++) {
		rc = px__tk_add_leaf_roots(t, e, e->first_leaf + i, p);
		if (rc < 0) {
			e->nz = 0;
			e->stale = 1;
			return rc;
		}
	}
	e->stale = 0;
	return 0;
}

/*
 * Newton on (C - p) . C' = 0 with p fixed from the unwrapped parameter
 * *unw (updated); the root must keep its type. Returns 0 or 1.
 */
static int newton(const struct px_track *t, const struct ent *e, int type,
		  double *unw, px_vec3 p, double lim, px_vec3 *c, px_vec3 *d1,
		  double *D, double *u_out, int hint)
{
	double u, step, tol = 1e-8 * e->len, quick = TRK_QUICK;
	int k;
	px_vec3 d2;
	for (k = 0;; k++) {
		double f1;
		const struct span *sp = hint >= 0 ? &t->span[hint] : NULL;
		u = *unw;
		if (e->cyclic) {
			if (u < e->u0 || u >= e->u1) {
				u = fmod(u - e->u0, e->len);
				if (u < 0)
					u += e->len;
				u += e->u0;
			}
		} else if (u < e->u0 || u > e->u1) {
			/* an iterate beyond an open end: come back to it */
			u = u < e->u0 ? e->u0 : e->u1;
			*unw = u;
		}
		if (!sp || u < sp->u0 || u > sp->u1)
			sp = find_span(t, e, u);
		span_eval(sp, u, c, d1, &d2);
		f1 = px_v3_dot(px_v3_sub(*c, p), *d1);
		*D = px_v3_dot(px_v3_sub(*c, p), d2) + px_v3_dot(*d1, *d1);
		if (!(*D != 0.0))
			return 1;
		step = -f1 / *D;
		if (!isfinite(step))
			return 1;
		if (fabs(step) <= tol)
			break;
		if (fabs(step) <= quick * (sp->u1 - sp->u0) &&
		    u + step >= sp->u0 && u + step <= sp->u1) {
			/* quadratic convergence: the root error after this
			 * step is O(step^2) (below 1e-9 of the span), so the
			 * point is moved by its Taylor expansion instead of
			 * another evaluation: second order in C (error
			 * O(step^3), far below the answer tolerance), first
			 * order in C' (only the next predictor uses it) */
			px_vec3 pc;
			*unw += step;
			u += step;
			*c = px_v3_add(*c, px_v3_scale(px_v3_add(*d1,
					px_v3_scale(d2, 0.5 * step)), step));
			*d1 = px_v3_add(*d1, px_v3_scale(d2, step));
			pc = px_v3_sub(*c, p);
			*D = px_v3_dot(pc, d2) + px_v3_dot(*d1, *d1);
			break;
		}
		if (k >= TRK_NEWTON)
			return 1;
		if (fabs(step) > lim)
			step = step > 0 ? lim : -lim;
		*unw += step;
	}
	if ((*D > 0.0 ? 1 : -1) != type)
		return 1;
	*u_out = u;
	return 0;
}

/* A corrected root: its new state at p, stamped. */
static void zero_commit(struct px_track *t, struct ent *e, struct zero *z,
			double u, int leaf, px_vec3 c, px_vec3 d1, double D,
			px_vec3 p)
{
	z->u = u;
	z->leaf = leaf;
	z->c = c;
	z->d1 = d1;
	z->D = D;
	zero_stamp(t, z, p);
	e->moved = 1;
}

/*
 * Evolve one root from p0 to p0 + dp: predictor (dp . C') / D (Eq. 6),
 * then Newton with the point held fixed. When that fails (a long step
 * near a fold), the same in four sub-steps along the segment. Then the
 * leaf walk: no stretch boundary may be crossed and no re-solved leaf
 * entered. Returns 0, or 1 for an anomaly.
 */
int px__tk_evolve(struct px_track *t, struct ent *e, struct zero *z,
		  px_vec3 p0, px_vec3 dp, px_vec3 p)
{
	double lim, unw, u = z->u, step, D = 0.0, next = 0.0;
	int li, guard, k, ok, have = 0;
	px_vec3 c, d1;

	{
		/* the usual case, in a few dozen flops */
		double ua;
		int q = quick_evolve(t, z, z->leaf,
				     z->u + px_v3_dot(dp, z->d1) / z->D, p,
				     TRK_QUICK_ITERS, &c, &d1, &D, &u, &ua,
				     &next);
		if (q == 0) {
			zero_commit(t, e, z, u, z->leaf, c, d1, D, p);
			return 0;
		}
		if (q == 1) {
			/* the general iteration goes on from this Newton
			 * step instead of evaluating ua again */
			have = 1;
			lim = e->len / (e->n_leaves > 0 ? e->n_leaves : 1);
			if (fabs(next) > lim)
				next = next > 0 ? lim : -lim;
			next += ua;
		}
	}
	lim = e->len / (e->n_leaves > 0 ? e->n_leaves : 1);
	step = (z->D != 0.0) ? px_v3_dot(dp, z->d1) / z->D : 0.0;
	if (!isfinite(step))
		step = 0.0;
	if (fabs(step) > lim)
		step = step > 0 ? lim : -lim;
	unw = have ? next : z->u + step;
	ok = !newton(t, e, z->type, &unw, p, lim, &c, &d1, &D, &u,
		     t->leaf[z->leaf].span);
	if (!ok) {
		/* continuation in sub-steps */
		px_vec3 sd = px_v3_scale(dp, 0.25), dk = z->d1;
		double Dk = z->D;
		unw = z->u;
		for (k = 1; k <= 4; k++) {
			px_vec3 pk = k == 4 ? p : px_v3_add(p0, px_v3_scale(dp, 0.25 * k));
			step = (Dk != 0.0) ? px_v3_dot(sd, dk) / Dk : 0.0;
			if (!isfinite(step))
				step = 0.0;
			if (fabs(step) > lim)
				step = step > 0 ? lim : -lim;
			unw += step;
			if (newton(t, e, z->type, &unw, pk, lim, &c, &d1, &D, &u,
				   t->leaf[z->leaf].span))
				return 1;
			dk = d1;
			Dk = D;
		}
	}
	li = z->leaf - e->first_leaf;
	{
		double off = 0.0; /* unwrapped offset of the leaf walk */
		for (guard = 0; guard <= e->n_leaves + 1; guard++) {
			const struct leaf *l = &t->leaf[e->first_leaf + li];
			if (unw >= l->u0 + off && unw <= l->u1 + off)
				break;
			if (unw > l->u1 + off) {
				if (l->flags & LF_SB1)
					return 1;
				if (++li == e->n_leaves) {
					if (!e->cyclic)
						return 1;
					li = 0;
					off += e->len;
				}
			} else {
				if (l->flags & LF_SB0)
					return 1;
				if (--li < 0) {
					if (!e->cyclic)
						return 1;
					li = e->n_leaves - 1;
					off -= e->len;
				}
			}
		}
		if (guard > e->n_leaves + 1)
			return 1;
	}
	li += e->first_leaf;
	if (t->leaf[li].mark == t->epoch)
		return 1;
	zero_commit(t, e, z, u, li, c, d1, D, p);
	return 0;
}
