/*
 * track_update.c - curve tracker (px_track.h): the answer: resting and
 * waking minima, the hot path, the global answer and verification,
 * px_track_reset(), px_track_update() and the cold answers. The layout and
 * the shared declarations are in track_internal.h.
 */
#include "track_internal.h"

/* ------------------------------------------------------------------ */
/* answer                                                              */

/* May root j of e (outside any re-solved leaf) skip its correction this
 * update? Only when its leaf certificate holds (it is provably still in
 * its leaf: no event there, end values of g kept their signs) and it is
 * alone there (a neighbour converging onto its branch would otherwise go
 * unseen by the duplicate check). */
static int can_rest(const struct px_track *t, const struct ent *e, int j)
{
	const struct zero *z = &e->z[j];
	if (t->fault & 1)
		return 1;
	if (!(t->travel < z->until))
		return 0;
	if (j > 0 && e->z[j - 1].leaf == z->leaf)
		return 0;
	if (j + 1 < e->nz && e->z[j + 1].leaf == z->leaf)
		return 0;
	return 1;
}

/* Correct every resting root of e at p. Returns 0 or 1 (anomaly). */
static int catch_up(struct px_track *t, struct ent *e, px_vec3 p)
{
	int j;
	for (j = 0; j < e->nz; j++) {
		struct zero *z = &e->z[j];
		if (z->ep == t->epoch)
			continue;
		if (px__tk_evolve(t, e, z, z->p, px_v3_sub(p, z->p), p))
			return 1;
	}
	return 0;
}

/*
 * Correct the resting minima that could be the closest point. A critical
 * distance is 1-Lipschitz in the query point along its branch (its
 * gradient is the unit vector from the foot point), so after a path of
 * length L since its last correction a minimum is at least dist - L
 * away; best (the distance to a real curve point: a current minimum or a
 * candidate) bounds the global minimum from above, and a minimum whose
 * bound exceeds it cannot be the closest point. Maxima never answer and
 * rest on their leaf certificates.
 */
static void wake_minima(struct px_track *t, px_vec3 p)
{
	double best2 = INFINITY, best;
	int i, j, round;
	for (i = 0; i < t->n_cand; i++) {
		double d2 = px_v3_dist2(t->cand[i].q, p);
		if (d2 < best2)
			best2 = d2;
	}
	for (i = 0; i < t->n_ent; i++) {
		const struct ent *e = &t->ent[i];
		if (e->stale || e->resting)
			continue;
		for (j = 0; j < e->nz; j++) {
			const struct zero *z = &e->z[j];
			double d2;
			if (z->type < 0 || z->ep != t->epoch)
				continue;
			d2 = px_v3_dist2(z->c, p);
			if (d2 < best2)
				best2 = d2;
		}
	}
	best = sqrt(best2);
	t->best_now = best;
	if (t->fault & 2)
		return;
	/* wake the resting minimum with the smallest bound first: it is
	 * usually the closest point and then excludes the others (bounded:
	 * each round corrects one root or ends) */
	for (round = 0; round <= t->n_rmin; round++) {
		struct ent *we = NULL;
		struct zero *wz = NULL;
		double wlb = INFINITY, d;
		int leaf0, k;
		/* the resting minima listed by the evolution pass (those of
		 * an entity caught up since are current now) */
		for (k = 0; k < t->n_rmin; k++) {
			struct ent *e = &t->ent[t->rmin[2 * k]];
			struct zero *z = &e->z[t->rmin[2 * k + 1]];
			double lb;
			if (e->stale || z->ep == t->epoch)
				continue;
			lb = z->dist - (t->travel - z->trav);
			if (lb < wlb) {
				wlb = lb;
				wz = z;
				we = e;
			}
		}
		if (!wz || wlb > best + 1e-9 * (best + t->scale))
			break;
		leaf0 = wz->leaf;
		if (px__tk_evolve(t, we, wz, wz->p, px_v3_sub(p, wz->p), p)) {
			we->stale = 1;
			continue;
		}
		if (wz->leaf != leaf0 && !we->full) {
			we->full = 1;
			if (catch_up(t, we, p)) {
				we->stale = 1;
				continue;
			}
			/* caught-up minima may be closer */
			for (j = 0; j < we->nz; j++)
				if (we->z[j].type > 0) {
					d = px_v3_dist(we->z[j].c, p);
					if (d < best)
						best = d;
				}
		}
		d = px_v3_dist(wz->c, p);
		if (d < best)
			best = d;
	}
	t->best_now = best;
}

/*
 * A resting root's leaf certificate (z->until) renewed at t->p without
 * correcting the root, when its distance share still holds. Sound where
 * the certificate held at the previous update (renewals come at the
 * first update past the least expiry, hot_cert()): from there to t->p
 * the path is one straight step, along which the leaf's end values of g
 * (affine in p) are linear, so where each has at t->p the sign it had at
 * the root's last correction z->p it kept that sign the whole way and no
 * root left the leaf; the new certificate is leaf_end_radius() at t->p.
 * Returns 1 when renewed, 0 when the root must be corrected (an end
 * value changed sign or is too close to zero to tell).
 */
static int renew_until(struct px_track *t, struct zero *z)
{
	const struct leaf *l = &t->leaf[z->leaf];
	const double *a = leaf_a(t, l);
	double r, g0 = gco(a, l->n, 0, t->p), g1 = gco(a, l->n, l->n, t->p);
	if (!t->opts.lazy)
		return 0;
	if (!(t->fault & 512)) {
		double h0 = gco(a, l->n, 0, z->p), h1 = gco(a, l->n, l->n, z->p);
		if (!(fabs(h0) > l->tol_g) || !(fabs(h1) > l->tol_g) || !(g0 * h0 > 0.0) ||
		    !(g1 * h1 > 0.0))
			return 0;
	}
	r = px__tk_leaf_end_radius(t, l, t->p);
	if (!(r > 0.0))
		return 0;
	z->until = t->travel + r * (1.0 - 1e-9);
	t->st.renewals++;
	return 1;
}

/*
 * The certificate shared by resting roots: the travelled path below which
 * every root of e but skip provably stays in its leaf (each leaf
 * certificate; the caller checked that each is alone there) and no
 * minimum of them can be the closest point. best is the distance to a
 * real curve point followed continuously; the global distance d* is
 * 1-Lipschitz, so after a further path L, d* <= best + L, while a
 * minimum is at least lb - L away (lb its lower bound now); it cannot be
 * the closest while lb - L > best + L, i.e. L < (lb - best) / 2 (with the
 * same tolerance as wake_minima). With fix set, a root whose certificate
 * ran out is corrected first, on a copy kept only when it stayed in its
 * leaf. Lowers *until; returns 0, or 1 when there is no certificate.
 */
static int cert_roots(struct px_track *t, struct ent *e, int skip,
		      double best, int fix, double *until)
{
	double tol = 1e-9 * (best + t->scale), m, x;
	int j, margin = !(t->fault & 32);
	for (j = 0; j < e->nz; j++) {
		struct zero *z = &e->z[j];
		if (j == skip)
			continue;
		/* renewing (fix): a root whose share still runs keeps it - a
		 * proof made earlier stays a proof */
		if (fix && z->hexp > t->travel) {
			if (z->hexp < *until)
				*until = z->hexp;
			continue;
		}
		if (fix && (!(z->until > t->travel) ||
			    (z->type > 0 &&
			     !(z->dist - (t->travel - z->trav) - best - tol > 0.0))) &&
		    !(z->until <= t->travel &&
		      (z->type < 0 || z->dist - (t->travel - z->trav) - best - tol > 0.0) &&
		      renew_until(t, z))) {
			struct zero zc = *z;
			if (px__tk_evolve(t, e, &zc, zc.p, px_v3_sub(t->p, zc.p), t->p) ||
			    zc.leaf != z->leaf)
				return 1;
			*z = zc;
		}
		if (!(z->until > t->travel))
			return 1;
		x = z->until;
		if (z->type > 0 && margin) {
			m = z->dist - (t->travel - z->trav) - best - tol;
			if (!(m > 0.0))
				return 1;
			m = t->travel + 0.5 * m * (1.0 - 1e-9);
			if (m < x)
				x = m;
		}
		z->hexp = x;
		if (x < *until)
			*until = x;
	}
	return 0;
}

/* Each root of e alone in its leaf (the roots sorted: neighbours
 * compared); *nmin its minima. */
static int ent_alone(const struct ent *e, int *nmin)
{
	int j, n = 0;
	for (j = 0; j < e->nz; j++) {
		if (j > 0 && e->z[j - 1].leaf == e->z[j].leaf)
			return 0;
		n += e->z[j].type > 0;
	}
	*nmin = n;
	return 1;
}

/* Certify e to rest whole from now on (after its checks of this update):
 * each root alone in its leaf (can_rest), cert_roots against the best
 * distance of this update. */
static void ent_certify(struct px_track *t, struct ent *e)
{
	double until = INFINITY;
	int nmin;
	e->rest_until = -1.0;
	if (!ent_alone(e, &nmin))
		return;
	e->nmin = nmin;
	if (cert_roots(t, e, -1, t->best_now, 0, &until))
		return;
	e->rest_until = (t->fault & 16) ? INFINITY : until;
}

static int in_work(const struct px_track *t, px_vec3 p)
{
	return p.x >= t->work.min.x && p.x <= t->work.max.x &&
	       p.y >= t->work.min.y && p.y <= t->work.max.y &&
	       p.z >= t->work.min.z && p.z <= t->work.max.z;
}

static void fill_dir(struct px_track_result *r, px_vec3 p)
{
	px_vec3 d = px_v3_sub(p, r->point);
	double n = px_v3_norm(d);
	r->dist = n;
	r->dir = n > 0.0 ? px_v3_scale(d, 1.0 / n) : px_v3(0, 0, 0);
}

static void answer(struct px_track *t, px_vec3 p, struct px_track_result *r)
{
	double best = INFINITY;
	uint32_t id = 0;
	int i, j, nc = 0, nm = 0;

	t->ans_z = -1;
	t->ans_c = -1;
	for (i = 0; i < t->n_ent; i++) {
		const struct ent *e = &t->ent[i];
		nc += e->nz;
		if (e->resting) {
			/* rests whole: its minima provably not the closest */
			t->st.rested += (uint64_t)e->nz;
			nm += e->nmin;
			continue;
		}
		for (j = 0; j < e->nz; j++) {
			const struct zero *z = &e->z[j];
			double d2;
			if (z->ep != t->epoch)
				t->st.rested++;
			if (z->type < 0)
				continue;
			nm++;
			if (z->ep != t->epoch)
				continue; /* resting: provably not the closest */
			d2 = px_v3_dist2(z->c, p);
			if (d2 < best) {
				best = d2;
				id = z->id;
				r->point = z->c;
				r->u = z->u;
				r->entity = i;
				r->feature = PX_TRACK_MIN;
				t->ans_z = j;
				t->ans_c = -1;
			}
		}
	}
	for (i = 0; i < t->n_cand; i++) {
		double d2 = px_v3_dist2(t->cand[i].q, p);
		if (d2 < best) {
			best = d2;
			id = 0x80000000u | (uint32_t)i;
			r->point = t->cand[i].q;
			r->u = t->cand[i].u;
			r->entity = t->cand[i].ent;
			r->feature = t->cand[i].kind;
			t->ans_z = -1;
			t->ans_c = i;
		}
	}
	fill_dir(r, p);
	r->n_crit = nc;
	r->n_min = nm;
	r->jumped = t->best_id != 0 && id != t->best_id;
	t->best_id = id;
}

/*
 * The hot certificate over entity E answered by its minimum a (or, a -1,
 * by candidate hot_c), at the current point with best the distance of
 * the answer (current): cert_roots over the other roots of E (each alone
 * in its leaf, checked when armed) and over the other candidates (fixed
 * points, 1-Lipschitz distances: the same margin), every other entity
 * resting whole under its own certificate
 * (hot_other, their smallest). With fix set (from the hot path) the roots
 * whose certificates ran out are corrected and an entity whose rest ran
 * out is certified again the same way. Returns 0 (hot_until set) or 1
 * (no certificate: the full update runs).
 */
static int hot_cert(struct px_track *t, struct ent *E, int a, double best,
		    int fix)
{
	double until, tol = 1e-9 * (best + t->scale), m;
	int i;
	if (fix && !(t->travel < t->hot_other)) {
		double other = INFINITY;
		for (i = 0; i < t->n_ent; i++) {
			struct ent *e = &t->ent[i];
			if (e == E)
				continue;
			if (!(t->travel < e->rest_until)) {
				double u2 = INFINITY;
				if ((t->fault & 16) ||
				    cert_roots(t, e, -1, best, 1, &u2))
					return 1;
				e->rest_until = u2;
			}
			if (e->rest_until < other)
				other = e->rest_until;
		}
		t->hot_other = other;
	}
	until = t->hot_other;
	if (!(t->travel < until) || cert_roots(t, E, a, best, fix, &until))
		return 1;
	for (i = 0; i < t->n_cand; i++) {
		if (i == t->hot_c)
			continue;
		if (!fix || !(t->cexp[i] > t->travel)) {
			m = px_v3_dist(t->cand[i].q, t->p) - best - tol;
			if (!(m > 0.0))
				return 1;
			t->cexp[i] = t->travel + 0.5 * m * (1.0 - 1e-9);
		}
		if (t->cexp[i] < until)
			until = t->cexp[i];
	}
	t->hot_until = (t->fault & 64) ? INFINITY : until;
	return 0;
}

/*
 * Arm the hot certificate after a tracked update answered by an interior
 * minimum or a candidate. Every other entity must rest whole, and every
 * root of the
 * answer's entity must be alone in its leaf: with no event anywhere and
 * every other root held in its leaf, the root Newton converges to inside
 * the answering root's leaf is its continuation.
 */
static void hot_arm(struct px_track *t, const struct px_track_result *r)
{
	struct ent *E;
	double other = INFINITY;
	int a, i, ne, nc = 0, nm = 0, nre = 0;

	t->hot_ent = -1;
	if (!t->opts.lazy || r->source != PX_TRACK_TRACKED ||
	    (t->ans_z < 0) == (t->ans_c < 0) || r->entity < 0)
		return;
	E = &t->ent[r->entity];
	a = t->ans_z;
	if (E->stale || a >= E->nz || (a >= 0 && E->z[a].ep != t->epoch))
		return;
	for (i = 0; i < t->n_ent; i++) {
		const struct ent *e = &t->ent[i];
		nc += e->nz;
		if (e == E)
			continue;
		if (e->stale || !(e->rest_until > t->travel))
			return;
		if (e->rest_until < other)
			other = e->rest_until;
		nm += e->nmin;
		nre++;
	}
	if (!ent_alone(E, &ne))
		return;
	nm += ne;
	if (E->nz >= 2 && E->z[0].leaf == E->z[E->nz - 1].leaf)
		return;
	t->hot_other = other;
	t->hot_c = t->ans_c;
	if (hot_cert(t, E, a, r->dist, 0))
		return;
	t->hot_ent = r->entity;
	t->hot_z = a;
	t->hot_nc = nc;
	t->hot_nm = nm;
	t->hot_rest_ent = (uint64_t)nre;
	t->hot_rested = (uint64_t)(nc - (a >= 0));
}

/*
 * An update under the hot certificate (no leaf had an event on the way
 * here): the answering root by quick_evolve, into a neighbouring leaf of
 * the same stretch when that leaf holds no other root, then the
 * certificate renewed in place when the path has used it up. Returns 0
 * when answered, 1 when the full update must run (the state is then one
 * it can start from: only corrections it would make itself were kept).
 */
static int hot_update(struct px_track *t, px_vec3 p, struct px_track_result *r)
{
	struct ent *e = &t->ent[t->hot_ent];
	struct zero *z;
	px_vec3 c, d1;
	double D, u, ua, st;
	int li, j, q;
	if (t->hot_z < 0) {
		/* a candidate answers: a fixed point */
		const struct cand *cd = &t->cand[t->hot_c];
		if (!(t->travel < t->hot_until) &&
		    hot_cert(t, e, -1, px_v3_dist(cd->q, p), 1))
			return 1;
		r->point = cd->q;
		r->u = cd->u;
		r->entity = cd->ent;
		r->feature = cd->kind;
		goto done;
	}
	z = &e->z[t->hot_z];
	li = z->leaf;
	q = quick_evolve(t, z, li, z->u + px_v3_dot(px_v3_sub(p, z->p), z->d1) / z->D,
			 p, TRK_QUICK_ITERS, &c, &d1, &D, &u, &ua, &st);
	if (q) {
		/* the iteration left the leaf: on into the neighbour on that
		 * side, unless a stretch boundary, a break or another root
		 * is there */
		const struct leaf *l = &t->leaf[li];
		int side;
		if (q == 1)
			ua += st;
		side = ua > l->u1;
		if (!(ua < l->u0 || ua > l->u1) ||
		    (l->flags & (side ? (LF_SB1 | LF_EV1) : (LF_SB0 | LF_EV0))))
			return 1;
		li += side ? 1 : -1;
		if (li < e->first_leaf || li >= e->first_leaf + e->n_leaves ||
		    (t->leaf[li].flags &
		     (side ? (LF_SB0 | LF_EV0) : (LF_SB1 | LF_EV1))))
			return 1;
		for (j = 0; j < e->nz; j++)
			if (e->z[j].leaf == li)
				return 1;
		if (quick_evolve(t, z, li, ua, p, TRK_QUICK_ITERS, &c, &d1, &D,
				 &u, &ua, &st))
			return 1;
	}
	z->u = u;
	z->leaf = li;
	z->c = c;
	z->d1 = d1;
	z->D = D;
	z->p = p;
	z->trav = t->travel;
	z->ep = t->epoch;
	/* its leaf certificate is not kept up here: the full update that
	 * follows corrects it first */
	z->until = -1.0;
	{
		/* the distance once, for the root and the answer */
		px_vec3 d = px_v3_sub(p, c);
		double n = sqrt(px_v3_dot(d, d));
		z->dist = n;
		if (!(t->travel < t->hot_until) &&
		    hot_cert(t, e, t->hot_z, n, 1))
			return 1;
		r->dist = n;
		r->dir = n > 0.0 ? px_v3_scale(d, 1.0 / n) : px_v3(0, 0, 0);
	}
	r->point = c;
	r->u = u;
	r->entity = t->hot_ent;
	r->feature = PX_TRACK_MIN;
	goto counts;
done:
	fill_dir(r, p);
counts:
	r->n_crit = t->hot_nc;
	r->n_min = t->hot_nm;
	t->st.hot++;
	t->st.rested += t->hot_rested;
	t->st.rested_entities += t->hot_rest_ent;
	return 0;
}

static void answer_global(struct px_track *t, px_vec3 p,
			  struct px_track_result *r)
{
	struct px_dist_result g;
	int i, nc = 0, nm = 0, j;
	px_dist_query(t->dist, p, &g);
	r->point = g.point;
	r->u = g.u;
	r->entity = g.entity;
	r->feature = PX_TRACK_FROM_GLOBAL;
	fill_dir(r, p);
	for (i = 0; i < t->n_ent; i++) {
		nc += t->ent[i].nz;
		for (j = 0; j < t->ent[i].nz; j++)
			nm += t->ent[i].z[j].type > 0;
	}
	r->n_crit = nc;
	r->n_min = nm;
	r->jumped = 1;
	t->best_id = 0;
	r->source = PX_TRACK_GLOBAL;
	t->st.fallbacks++;
}

static void result_clear(struct px_track_result *r)
{
	memset(r, 0, sizeof(*r));
	r->entity = -1;
}

/* Rebuild every entity; returns 0 or the first error. */
static int reinit_all(struct px_track *t, px_vec3 p)
{
	int i, rc = 0;
	for (i = 0; i < t->n_ent; i++) {
		int r2 = px__tk_ent_reinit(t, &t->ent[i], p);
		if (r2 && !rc)
			rc = r2;
	}
	return rc;
}

static void count_fail(struct px_track *t, int rc)
{
	if (rc == PX_E_NOSPC)
		t->st.overflows++;
	else
		t->st.unresolved++;
}

static void verify(struct px_track *t, px_vec3 p, struct px_track_result *r)
{
	int rc;
	if (!px__tracker_verify(&t->opts.shared, &t->st.shared, t->dist, t->scale,
				p, r->dist, &r->verified))
		return;
	rc = reinit_all(t, p);
	if (rc)
		count_fail(t, rc);
	answer_global(t, p, r);
	r->verified = 1;
}

int px_track_reset(struct px_track *t, px_vec3 p, struct px_track_result *r)
{
	int rc = px__tracker_args(t, r, p);
	if (rc)
		return rc;
	result_clear(r);
	t->st.updates++;
	t->p = p;
	t->p_in = in_work(t, p);
	t->init = 1;
	t->best_id = 0;
	t->hot_ent = -1;
	t->heap_ok = 0;
	px__gov_reset(&t->gov, &t->st.shared);
	rc = reinit_all(t, p);
	/* the leaves' safe radii here too, so that the next update costs
	 * what an update costs */
	if (t->p_in)
		px__tk_heap_rebuild(t, p);
	r->source = PX_TRACK_REINIT;
	if (rc) {
		count_fail(t, rc);
		answer_global(t, p, r);
	} else {
		answer(t, p, r);
		r->jumped = 1;
		verify(t, p, r);
	}
	return PX_OK;
}

static __attribute__((noinline)) int update_full(struct px_track *t, px_vec3 p, int nh,
		       struct px_track_result *r);

/*
 * Is the closest point (entity ent, parameter u, point) the continuation
 * of the last answer kept in t->prev? Used where no critical point was
 * followed: cold answers and the return from them. The same point (an
 * end, a break, no motion) is; otherwise the answer must be a minimum of
 * the same curve whose backward predictor (Eq. 6 from the new point to
 * the last one) lands nearer the last parameter than half the parameter
 * moved - on one branch the predictor's error is second order in the
 * step, a jump to another branch lands it near the new parameter.
 */
static int continued(struct px_track *t, px_vec3 p, int ent, double u,
		     px_vec3 point, double dist)
{
	const struct ent *e;
	double D, ub, du, dub, duf = 0.0;
	px_vec3 c, d1, d2;
	t->cur_D = 0.0;
	if (ent < 0 || ent >= t->n_ent)
		return 0;
	e = &t->ent[ent];
	span_eval(find_span(t, e, u), u, &c, &d1, &d2);
	D = px_v3_dot(px_v3_sub(c, p), d2) + px_v3_dot(d1, d1);
	t->cur_d1 = d1;
	t->cur_D = D;
	if (t->prev.ent < 0 || ent != t->prev.ent)
		return 0;
	if (px_v3_dist(point, t->prev.point) <= 1e-9 * (t->scale + dist))
		return 1;
	if (t->prev.fixed || !(D > 0.0))
		return 0;
	ub = u + px_v3_dot(px_v3_sub(t->prev.p, p), d1) / D;
	du = u - t->prev.u;
	dub = ub - t->prev.u;
	if (t->prev.D > 0.0)
		/* and forward from the last answer (Eq. 6 itself) */
		duf = t->prev.u + px_v3_dot(px_v3_sub(p, t->prev.p), t->prev.d1) /
					  t->prev.D - u;
	if (e->cyclic) {
		/* the shorter way round the seam */
		du = px__wrap_half(du, e->len);
		dub = px__wrap_half(dub, e->len);
		duf = px__wrap_half(duf, e->len);
	}
	return fabs(dub) <= 0.5 * fabs(du) && fabs(duf) <= 0.5 * fabs(du);
}

static void prev_keep(struct px_track *t, const struct px_track_result *r)
{
	t->prev.ent = r->entity;
	t->prev.fixed = r->feature == PX_TRACK_END || r->feature == PX_TRACK_BREAK;
	t->prev.u = r->u;
	t->prev.point = r->point;
	t->prev.p = t->p;
	t->prev.d1 = t->cur_d1;
	t->prev.D = t->cur_D;
}

/* An update answered cold (gov.cold): the global query alone; the
 * critical points wait for the return. Returns 0 or the query's error
 * (the caller then tracks instead). */
static int cold_update(struct px_track *t, px_vec3 p, struct px_track_result *r)
{
	struct px_dist_result g;
	int rc = px__gov_cold_query(&t->gov, &t->st.shared, t->dist, p, &g);
	if (rc)
		return rc;
	result_clear(r);
	r->dist = g.dist;
	r->point = g.point;
	r->u = g.u;
	r->entity = g.entity;
	r->dir = g.dir;
	r->feature = PX_TRACK_FROM_GLOBAL;
	r->n_crit = r->n_min = -1;
	r->source = PX_TRACK_COLD;
	r->jumped = !continued(t, p, g.entity, g.u, g.point, g.dist);
	t->p = p;
	prev_keep(t, r);
	return 0;
}

static int track_update(struct px_track *t, px_vec3 p, double len, int fresh,
			struct px_track_result *r);

int px_track_update(struct px_track *t, px_vec3 p, struct px_track_result *r)
{
	int64_t t0;
	int rc = px__tracker_args(t, r, p), fresh = 0, mode;
	double len;

	if (rc)
		return rc;
	if (!t->init)
		return px_track_reset(t, p, r);
	/* the step's length, for the travelled path and the cold switch */
	len = px_v3_dist(t->p, p);
	mode = px__gov_begin(&t->gov, len);
	if (mode == PX_GOV_COLD) {
		if (cold_update(t, p, r) == 0)
			return PX_OK;
		/* no global answer here (far away): track */
		px__gov_restart(&t->gov);
	}
	if (mode != PX_GOV_TRACK) {
		t->st.cold_left++;
		fresh = 1;
	}
	t0 = px__gov_start(&t->gov);
	rc = track_update(t, p, len, fresh, r);
	if (px__gov_stop(&t->gov, t0)) {
		/* cold from the next update on */
		t->st.cold_entered++;
		t->hot_ent = -1;
		t->cur_D = 0.0;
		prev_keep(t, r);
	}
	if (fresh && rc == PX_OK)
		r->jumped = !continued(t, p, r->entity, r->u, r->point, r->dist);
	return rc;
}

/* The tracked update; len: |p - t->p|; fresh: every critical point found
 * again at p (the return from cold answers). */
static int track_update(struct px_track *t, px_vec3 p, double len, int fresh,
			struct px_track_result *r)
{
	int i, j, nh, rc, in;
	px_vec3 p0;

	result_clear(r);
	t->st.updates++;
	p0 = t->p;
	t->p = p;
	r->source = PX_TRACK_TRACKED;
	if (++t->epoch == 0) {
		/* wrapped: no stale mark or correction stamp may look current */
		for (i = 0; i < t->n_leaves; i++)
			t->leaf[i].mark = t->leaf[i].tested = 0;
		for (i = 0; i < t->n_ent; i++) {
			t->ent[i].hit = 0;
			for (j = 0; j < t->ent[i].nz; j++)
				t->ent[i].z[j].ep = 0;
		}
		t->epoch = 1;
	}

	/* (whether p0 was inside was found by the last update) */
	in = in_work(t, p);
	if (!in || !t->p_in || fresh) {
		if (!in || !t->p_in)
			t->st.outside++;
		t->p_in = in;
		t->hot_ent = -1;
		t->heap_ok = 0;
		r->source = PX_TRACK_REINIT;
		rc = reinit_all(t, p);
		/* back inside: the radii at p in this update (a re-start
		 * already), not in the next */
		if (in)
			px__tk_heap_rebuild(t, p);
		if (rc) {
			count_fail(t, rc);
			answer_global(t, p, r);
			return PX_OK;
		}
		answer(t, p, r);
		verify(t, p, r);
		return PX_OK;
	}

	nh = collect_events(t, p0, p, len);
	if (t->hot_ent >= 0) {
		if (nh == 0 && !hot_update(t, p, r)) {
			if (t->opts.verify_every > 0) {
				verify(t, p, r);
				if (r->source != PX_TRACK_TRACKED)
					t->hot_ent = -1;
			}
			return PX_OK;
		}
		t->hot_ent = -1;
	}
	return update_full(t, p, nh, r);
}

/* The update beyond the hot path: evolution of every root that cannot
 * rest, the re-solved leaves, the checks, the answer. */
/* Entity i's roots outside the re-solved leaves evolved to p; in an
 * entity without re-solved leaves a root whose leaf certificate holds
 * may rest (can_rest) until the answer needs it, and the entity whole
 * while its rest certificate holds. */
static void ent_evolve(struct px_track *t, int i, px_vec3 p)
{
	struct ent *e = &t->ent[i];
	int j, w = 0;
	e->nold = 0;
	e->touched = 0;
	e->full = !t->opts.lazy || e->hit == t->epoch;
	e->moved = 0;
	e->resting = 0;
	if (e->stale)
		return;
	if (!e->full && t->travel < e->rest_until) {
		e->resting = 1;
		t->st.rested_entities++;
		return;
	}
	e->rest_until = -1.0;
	for (j = 0; j < e->nz; j++) {
		struct zero *zj = &e->z[j];
		int leaf0;
		if (t->leaf[zj->leaf].mark == t->epoch) {
			e->old[e->nold++] = *zj;
			e->touched = 1;
			continue;
		}
		/* without a re-solved leaf nothing is dropped: w == j */
		if (!e->full && can_rest(t, e, j)) {
			if (zj->type > 0) {
				t->rmin[2 * t->n_rmin] = i;
				t->rmin[2 * t->n_rmin + 1] = j;
				t->n_rmin++;
			}
			w++;
			continue;
		}
		leaf0 = zj->leaf;
		if (w != j)
			e->z[w] = *zj;
		if (px__tk_evolve(t, e, &e->z[w], e->z[w].p, px_v3_sub(p, e->z[w].p),
				  p)) {
			e->stale = 1;
			break;
		}
		if (e->z[w].leaf != leaf0)
			e->full = 1;
		w++;
	}
	if (!e->stale) {
		e->nz = w;
		if (e->full && catch_up(t, e, p))
			e->stale = 1;
	}
}

/* The nh event leaves (t->hits) re-solved at p: 0, or the error that
 * stopped it (the update then falls back); *added the roots they hold. */
static int hits_solve(struct px_track *t, px_vec3 p, int nh, int *added)
{
	int i;
	*added = 0;
	for (i = 0; i < nh; i++) {
		int li = t->hits[i];
		struct ent *e = &t->ent[t->leaf[li].ent];
		int n;
		if (e->stale)
			continue;
		n = px__tk_add_leaf_roots(t, e, li, p);
		if (n < 0) {
			e->stale = 1;
			return n;
		}
		*added += n;
		e->touched = 1;
	}
	return 0;
}

/* The structure checks: an entity with re-solved leaves checked whole,
 * one whose roots only evolved for duplicates; stale where they fail. */
static void ents_check(struct px_track *t, px_vec3 p)
{
	int i;
	for (i = 0; i < t->n_ent; i++) {
		struct ent *e = &t->ent[i];
		if (!e->stale && e->touched) {
			px__tk_sort_zeros(e);
			if (px__tk_ent_check(t, e, p))
				e->stale = 1;
		}
	}
	for (i = 0; i < t->n_ent; i++) {
		struct ent *e = &t->ent[i];
		if (!e->stale && !e->touched && e->moved) {
			/* evolved roots kept type and stretch; two
			 * converging to one root shows as a duplicate (an
			 * entity whose roots all rest is unchanged) */
			px__tk_sort_zeros(e);
			if (px__tk_ent_dups(e))
				e->stale = 1;
		}
	}
}

/* Anomalies: the stale entities rebuilt at p. Returns 0 or the first
 * error. */
static int stale_reinit(struct px_track *t, px_vec3 p, struct px_track_result *r)
{
	int i, rc;
	for (i = 0; i < t->n_ent; i++) {
		struct ent *e = &t->ent[i];
		if (!e->stale)
			continue;
		t->st.reinits++;
		r->source = PX_TRACK_REINIT;
		rc = px__tk_ent_reinit(t, e, p);
		if (rc)
			return rc;
	}
	return 0;
}

/* Creation / annihilation: the roots the re-solved leaves gained
 * (added) against those they held. */
static void count_pairs(struct px_track *t, int added, struct px_track_result *r)
{
	int i, before = 0;
	for (i = 0; i < t->n_ent; i++)
		before += t->ent[i].nold;
	if (added > before) {
		r->created = (added - before) / 2;
		t->st.creations += (uint64_t)r->created;
	} else if (added < before) {
		r->annihilated = (before - added) / 2;
		t->st.annihilations += (uint64_t)r->annihilated;
	}
}

static __attribute__((noinline)) int update_full(struct px_track *t, px_vec3 p, int nh,
		       struct px_track_result *r)
{
	int i, rc, added = 0;

	r->leaves_solved = nh;
	t->st.leaf_solves += (uint64_t)nh;

	for (i = 0; i < nh; i++)
		t->ent[t->leaf[t->hits[i]].ent].hit = t->epoch;
	t->n_rmin = 0;
	for (i = 0; i < t->n_ent; i++)
		ent_evolve(t, i, p);
	/* re-solve the event leaves at the new point */
	rc = hits_solve(t, p, nh, &added);
	if (!rc) {
		if (t->opts.lazy)
			wake_minima(t, p);
		ents_check(t, p);
		/* anomalies: rebuild those entities here */
		rc = stale_reinit(t, p, r);
	}
	if (!rc && t->opts.lazy) {
		for (i = 0; i < t->n_ent; i++) {
			struct ent *e = &t->ent[i];
			/* corrected roots too: their certificates were made
			 * at this point (the hot path needs every entity
			 * but the answer's resting whole) */
			if (!e->resting && !e->stale &&
			    r->source == PX_TRACK_TRACKED)
				ent_certify(t, e);
		}
	}
	if (rc) {
		count_fail(t, rc);
		for (i = 0; i < t->n_ent; i++)
			t->ent[i].stale = 1;
		answer_global(t, p, r);
		return PX_OK;
	}
	if (r->source == PX_TRACK_TRACKED)
		count_pairs(t, added, r);
	answer(t, p, r);
	r->leaves_solved = nh;
	verify(t, p, r);
	hot_arm(t, r);
	return PX_OK;
}

/* Bring the resting roots of e up to date at the current point (for
 * px_track_critical: the caller sees every root where it is now). */
void px__tk_ent_refresh(struct px_track *t, struct ent *e)
{
	int j, rest = 0;
	if (!t->init || e->stale)
		return;
	if (t->gov.cold) {
		/* not followed while cold: found afresh at the point */
		if (px__tk_ent_reinit(t, e, t->p))
			count_fail(t, PX_E_RANGE);
		return;
	}
	t->hot_ent = -1; /* the roots are corrected and re-sorted here */
	e->rest_until = -1.0;
	e->resting = 0;
	for (j = 0; j < e->nz; j++)
		rest |= e->z[j].ep != t->epoch;
	if (!rest)
		return;
	if (catch_up(t, e, t->p) || (px__tk_sort_zeros(e), px__tk_ent_check(t, e, t->p))) {
		t->st.reinits++;
		if (px__tk_ent_reinit(t, e, t->p))
			count_fail(t, PX_E_RANGE);
	}
}
