/*
 * strack_cold.c - surface tracker (px_strack.h): the cold switch: answering
 * with the global query while the point moves too fast to track, and the
 * way back. The layout and the shared declarations are in
 * strack_internal.h.
 */
#include "strack_internal.h"

/* ------------------------------------------------------------------ */
/* cold switch                                                         */

/* (u, v) off the open domain edges (a seam direction has none). */
static int uv_inner(const struct ssurf *f, double u, double v)
{
	return (f->wrap_u || (u > f->u0 + 1e-9 * f->du && u < f->u1 - 1e-9 * f->du)) &&
	       (f->wrap_v || (v > f->v0 + 1e-9 * f->dv && v < f->v1 - 1e-9 * f->dv));
}

/* The answer r at p as a critical point, when it is an interior one of
 * a surface that is a minimum there (the cold answers' jumped follows
 * it): 1 with *z evaluated, else 0. One evaluation. */
static int cold_crit(const struct px_strack *t, px_vec3 p,
		     const struct px_strack_result *r, struct crit *z)
{
	const struct ssurf *f;
	px_vec3 gr;
	int s = r->entity - t->n_curves;
	if (s < 0 || s >= t->n_surf ||
	    (r->feature != PX_STRACK_MIN && r->feature != PX_STRACK_GLOBAL))
		return 0;
	f = &t->sf[s];
	if (!uv_inner(f, r->u, r->v))
		return 0;
	memset(z, 0, sizeof(*z));
	z->u = r->u;
	z->v = r->v;
	crit_eval(f, z, p, &gr);
	z->type = crit_type(z);
	return z->type == 1;
}

/* Keep the answer r at p (z: cold_crit()'s, ok its return) as the last
 * one for the cold answers' jumped. */
static void cold_keep(struct px_strack *t, px_vec3 p,
		      const struct px_strack_result *r, const struct crit *z,
		      int ok)
{
	t->cprev.ok = ok;
	t->cprev.s = r->entity - t->n_curves;
	if (ok)
		t->cprev.z = *z;
	t->cprev.q = p;
	t->last_point = r->point;
	t->last_q = p;
	t->last_entity = r->entity;
	t->have_last = 1;
	t->best_kind = 0;
}

/* Parameter offset a - b of surface f as a length in domain units (the
 * shorter way round a seam). */
static double uv_gap(const struct ssurf *f, double du, double dv)
{
	if (f->wrap_u)
		du = px__wrap_half(du, f->du);
	if (f->wrap_v)
		dv = px__wrap_half(dv, f->dv);
	return hypot(du / f->du, dv / f->dv);
}

/* The predictor (section 4.2) of z for a move dp: (su, sv). 0 when H is
 * singular. */
static int predict(const struct crit *z, px_vec3 dp, double *su, double *sv)
{
	double a = px_v3_dot(z->su, dp), b = px_v3_dot(z->sv, dp);
	double det = z->h11 * z->h22 - z->h12 * z->h12;
	if (!(fabs(det) > 0.0))
		return 0;
	*su = (z->h22 * a - z->h12 * b) / det;
	*sv = (-z->h12 * a + z->h11 * b) / det;
	return isfinite(*su) && isfinite(*sv);
}

/*
 * jumped for a cold answer g at p (c: g as a critical point when c_ok).
 * Nothing was followed, so the last answer decides, when it was an
 * interior minimum of the same surface:
 *  - both interior minima and the predictor, run forward from the last
 *    one and backward from the new one, lands each within half the
 *    parameter moved of the other: the same branch (on one branch its
 *    error is second order in the step, a jump lands it far off);
 *  - else the last minimum is followed to p (predictor and Newton, in
 *    one step or four): landing on g means g continues it; on another
 *    minimum, the closest point left a living minimum (a jump); losing
 *    it means it died at a fold (a jump when g is interior) or left
 *    through an edge.
 * Otherwise (edges, curves, poles) as a global answer: a foot point that
 * moved far more than the query point.
 */
static int cold_jumped(struct px_strack *t, px_vec3 p,
		       const struct px_dist_result *g, const struct crit *c,
		       int c_ok)
{
	const struct ssurf *f;
	const struct crit *z = &t->cprev.z;
	struct crit w;
	double moved, du, dv, gap, su, sv;
	int far, n, s = g->entity - t->n_curves;
	if (!t->have_last || g->entity != t->last_entity)
		return 1;
	moved = px_v3_dist(g->point, t->last_point);
	if (moved <= 1e-9 * (t->scale + g->dist))
		return 0;
	far = moved > 4.0 * px_v3_dist(p, t->last_q) + 1e-9 * t->scale;
	if (!t->cprev.ok || t->cprev.s != s || s < 0 || s >= t->n_surf)
		return far;
	f = &t->sf[s];
	if (c_ok) {
		du = c->u - z->u;
		dv = c->v - z->v;
		gap = uv_gap(f, du, dv);
		if (predict(z, px_v3_sub(p, t->cprev.q), &su, &sv) &&
		    uv_gap(f, du - su, dv - sv) <= 0.5 * gap &&
		    predict(c, px_v3_sub(t->cprev.q, p), &su, &sv) &&
		    uv_gap(f, du + su, dv + sv) <= 0.5 * gap)
			return 0;
	}
	/* one step, else four (a long step near a focal point; bounded
	 * work: at most five corrections) */
	for (n = 1; n <= 4; n *= 4) {
		px_vec3 dp = px_v3_scale(px_v3_sub(p, t->cprev.q), 1.0 / n);
		int k;
		w = *z;
		for (k = 1; k <= n; k++) {
			px_vec3 pk = k == n ? p : px_v3_add(t->cprev.q, px_v3_scale(dp, (double)k));
			if (px__st_evolve(f, &w, dp, pk) || w.type != 1)
				break;
		}
		if (k > n)
			return uv_gap(f, w.u - g->u, w.v - g->v) > 1e-7;
	}
	return c_ok ? 1 : far;
}

/* An update answered cold: the global query alone. Returns 0 or the
 * query's error (the caller then tracks again). */
int px__st_cold_update(struct px_strack *t, px_vec3 p, struct px_strack_result *r)
{
	struct px_dist_result g;
	struct crit c;
	int ok, rc = px__gov_cold_query(&t->gov, &t->st.shared, t->dist, p, &g);
	if (rc)
		return rc;
	result_clear(r);
	r->dist = g.dist;
	r->point = g.point;
	r->u = g.u;
	r->v = g.v;
	r->entity = g.entity;
	r->dir = g.dir;
	r->feature = PX_STRACK_GLOBAL;
	r->n_crit = r->n_min = r->n_max = r->n_saddle = -1;
	r->source = PX_TRACK_COLD;
	ok = cold_crit(t, p, r, &c);
	r->jumped = cold_jumped(t, p, &g, &c, ok);
	cold_keep(t, p, r, &c, ok);
	return 0;
}

/* The tracker goes cold after the update that answered r at p: the set
 * is dropped (it is not followed; px_strack_critical() holds none). */
void px__st_cold_enter(struct px_strack *t, px_vec3 p,
		       const struct px_strack_result *r)
{
	struct crit c;
	int i;
	t->st.cold_entered++;
	t->hot_s = -1;
	t->ret_left = 0;
	for (i = 0; i < t->n_surf; i++)
		t->sf[i].nz = 0;
	cold_keep(t, p, r, &c, cold_crit(t, p, r, &c));
}

/* Back from cold answers at p: the curve tracker starts afresh at p and
 * the surface set is re-established in slices (max_solves > 0, answered
 * globally meanwhile) or at once. The curve tracker's restart has an
 * update of its own: with the first slice and the global query, after a
 * thousand cold updates had pushed the tracker's memory out of the
 * caches, it was the worst update of the return. */
int px__st_cold_return(struct px_strack *t, px_vec3 p, struct px_strack_result *r)
{
	struct px_track_result cr;
	int slice = px__st_rebuild_slice(t);
	t->st.cold_left++;
	result_clear(r);
	t->st.updates++;
	if (t->opts.max_solves > 0) {
		px__st_curves_update(t, p, &cr, 1);
		px__st_rebuild_start(t);
		/* this update, the rebuild's slices, then a margin for
		 * catching up */
		t->ret_left = 1 + t->n_cells / slice + 2 * PX_GOV_MIN_COLD;
		t->st.rebuild_updates++;
		px__st_answer_global(t, p, r);
		return PX_OK;
	}
	t->p = p;
	t->mode = ST_TRACK;
	t->hot_s = -1;
	return px__st_full_reset(t, p, r);
}
