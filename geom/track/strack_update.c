/*
 * strack_update.c - surface tracker (px_strack.h): the tracked update:
 * following the critical points, events, rings of cell solves, the hot
 * path, the answer and its checks; px_strack_reset() and
 * px_strack_update(). The layout and the shared declarations are in
 * strack_internal.h.
 */
#include "strack_internal.h"

/* ------------------------------------------------------------------ */
/* answer                                                              */

static int in_work(const struct px_strack *t, px_vec3 p)
{
	/* (px_aabb_contains() inline: twice in every update) */
	const px_aabb *b = &t->work;
	return p.x >= b->min.x && p.x <= b->max.x && p.y >= b->min.y &&
	       p.y <= b->max.y && p.z >= b->min.z && p.z <= b->max.z;
}

static void fill_dir(struct px_strack_result *r, px_vec3 p)
{
	px_vec3 d = px_v3_sub(p, r->point);
	double n = px_v3_norm(d);
	r->dist = n;
	r->dir = n > 0.0 ? px_v3_scale(d, 1.0 / n) : px_v3(0, 0, 0);
}

static void count_crit(const struct px_strack *t, struct px_strack_result *r,
		       int curve_crit)
{
	int i, j;
	r->n_min = r->n_max = r->n_saddle = 0;
	for (i = 0; i < t->n_surf; i++)
		for (j = 0; j < t->sf[i].nz; j++) {
			int ty = t->sf[i].z[j].type;
			if (ty > 0)
				r->n_min++;
			else if (ty < 0)
				r->n_max++;
			else
				r->n_saddle++;
		}
	r->n_crit = r->n_min + r->n_max + r->n_saddle + curve_crit;
}

/* The curve tracker's answer (a free curve or a surface edge) into r. */
static void answer_curve(const struct px_strack *t,
			 const struct px_track_result *cr,
			 struct px_strack_result *r)
{
	r->point = cr->point;
	if (cr->entity < t->n_curves) {
		r->entity = cr->entity;
		r->u = cr->u;
		r->v = 0.0;
		r->feature = PX_STRACK_CURVE;
	} else {
		const struct edge *e = &t->edge[cr->entity - t->n_curves];
		r->entity = t->n_curves + e->surf;
		r->u = e->dir ? e->t : cr->u;
		r->v = e->dir ? cr->u : e->t;
		r->feature = PX_STRACK_EDGE;
	}
}

/* The curve tracker's answer cr is a crease of a trimmed surface outside
 * its domain: no candidate of the model. */
static inline int crease_out(const struct px_strack *t,
			     const struct px_track_result *cr)
{
	const struct edge *e;
	if (cr->entity < t->n_curves)
		return 0;
	e = &t->edge[cr->entity - t->n_curves];
	return !st_in_domain(&t->sf[e->surf], e->dir ? e->t : cr->u,
			     e->dir ? cr->u : e->t);
}

static void answer(struct px_strack *t, px_vec3 p,
		   const struct px_track_result *cr, struct px_strack_result *r)
{
	double best = INFINITY;
	int kind = 0, i, j;
	uint32_t id = 0;

	t->ans_s = -1;
	if (cr->entity >= 0) {
		best = cr->dist * cr->dist;
		kind = 2;
		answer_curve(t, cr, r);
	}
	for (i = 0; i < t->n_surf; i++)
		for (j = 0; j < t->sf[i].nz; j++) {
			const struct crit *z = &t->sf[i].z[j];
			double d2;
			if (z->type <= 0)
				continue;
			d2 = px_v3_dist2(z->s, p);
			if (d2 < best && st_in_domain(&t->sf[i], z->u, z->v)) {
				best = d2;
				kind = 1;
				id = z->id;
				r->point = z->s;
				r->u = z->u;
				r->v = z->v;
				r->entity = t->n_curves + i;
				r->feature = PX_STRACK_MIN;
				t->ans_s = i;
				t->ans_j = j;
			}
		}
	for (i = 0; i < t->n_poles; i++) {
		double d2 = px_v3_dist2(t->pole[i].q, p);
		if (d2 < best) {
			best = d2;
			kind = 3;
			id = (uint32_t)i;
			r->point = t->pole[i].q;
			r->u = t->pole[i].u;
			r->v = t->pole[i].v;
			r->entity = t->n_curves + t->pole[i].surf;
			r->feature = PX_STRACK_POLE;
		}
	}
	fill_dir(r, p);
	count_crit(t, r, cr->n_crit);
	/* (the caller answers globally: the last answer stays) */
	t->ans_open = kind == 2 && crease_out(t, cr);
	if (t->ans_open)
		return;
	r->jumped = kind != t->best_kind || (kind == 2 && cr->jumped) ||
		    (kind != 2 && id != t->best_id);
	if (t->best_kind == 0 && t->have_last)
		/* after a global answer: judged as there */
		r->jumped = r->entity != t->last_entity ||
			    px_v3_dist(r->point, t->last_point) >
				    4.0 * px_v3_dist(p, t->last_q) + 1e-9 * t->scale;
	t->best_kind = kind;
	t->best_id = id;
	t->last_point = r->point;
	t->last_q = p;
	t->last_entity = r->entity;
	t->have_last = 1;
}

void px__st_answer_global(struct px_strack *t, px_vec3 p,
			  struct px_strack_result *r)
{
	struct px_dist_result g;
	px_dist_query(t->dist, p, &g);
	r->point = g.point;
	r->u = g.u;
	r->v = g.v;
	r->entity = g.entity;
	r->feature = PX_STRACK_GLOBAL;
	fill_dir(r, p);
	count_crit(t, r, 0);
	/* no feature identity here: a jump is a change of entity or a foot
	 * point that moved far more than the query point */
	r->jumped = !t->have_last || r->entity != t->last_entity ||
		    px_v3_dist(r->point, t->last_point) >
			    4.0 * px_v3_dist(p, t->last_q) + 1e-9 * t->scale;
	t->best_kind = 0;
	r->source = PX_TRACK_GLOBAL;
	t->st.fallbacks++;
	t->last_point = r->point;
	t->last_q = p;
	t->last_entity = r->entity;
	t->have_last = 1;
}

static int reinit_all(struct px_strack *t, px_vec3 p)
{
	int i, rc = 0;
	t->hot_s = -1;
	for (i = 0; i < t->n_surf; i++) {
		int r2 = px__st_surf_reinit(t, &t->sf[i], i, p);
		if (r2 && !rc)
			rc = r2;
	}
	return rc;
}

static void verify(struct px_strack *t, px_vec3 p, struct px_strack_result *r)
{
	if (!px__tracker_verify(&t->opts.shared, &t->st.shared, t->dist, t->scale,
				p, r->dist, &r->verified))
		return;
	t->st.reinits++;
	if (t->opts.max_solves > 0) {
		/* re-established over the next updates */
		px__st_rebuild_start(t);
	} else if (reinit_all(t, p)) {
		t->st.overflows++;
	}
	px__st_answer_global(t, p, r);
	r->verified = 1;
}

/* The curve tracker's answer (none when the model has no curve and no
 * open edge: closed in both directions or all poles). */
void px__st_curves_update(struct px_strack *t, px_vec3 p,
			  struct px_track_result *cr, int reset)
{
	if (!t->ct) {
		memset(cr, 0, sizeof(*cr));
		cr->entity = -1;
		return;
	}
	if (reset)
		px_track_reset(t->ct, p, cr);
	else
		px_track_update(t->ct, p, cr);
	t->ct_p = p;
	t->ct_ncrit = cr->n_crit;
}

/*
 * The curve tracker's exact answer as a certificate for leaving it out:
 * with dc its distance at q and best that of some surface point (a
 * tracked minimum or a pole), at any x the curves are at least
 * dc - |x - q| away and the closest point at most best + |x - q|, so no
 * curve is closest while |x - q| < (dc - best) / 2. Where the boxes of
 * the curves' half spans reach nearer than best (a point beside an edge,
 * or far from the surface, its distance ball over the edges' boxes) they
 * prove nothing, and the curve tracker ran every update.
 */
static void ct_note(struct px_strack *t, px_vec3 q, double dc, double best)
{
	double m = dc - best - 1e-9 * (best + t->scale);
	t->ct_q = q;
	t->ct_rc = m > 0.0 ? 0.5 * m * (1.0 - 1e-9) : -1.0;
	t->ct_rc2 = m > 0.0 ? t->ct_rc * t->ct_rc : -1.0;
	if (px__strack_ct_fault)
		t->ct_rc = t->ct_rc2 = INFINITY;
}

/* The curve tracker's last update more than 2 % of the model size from
 * p: it must run before its step grows longer than it is made for. */
static inline int ct_stale(const struct px_strack *t, px_vec3 p)
{
	double lim = 0.02 * t->scale;
	return px_v3_dist2(p, t->ct_p) > lim * lim;
}

/* Its last answer still proves every curve farther than the closest
 * point at p (ct_note()). */
static inline int ct_proves(const struct px_strack *t, px_vec3 p)
{
	return px_v3_dist2(p, t->ct_q) < t->ct_rc2;
}

/*
 * 1 when the curve tracker must answer this update: a curve or edge can
 * be closest (some box of the curves is not farther than the best
 * interior minimum or pole), or it was left out over more than 2 % of
 * the model size (its next step stays of the length it is made for);
 * else 2 when its own last answer proves the curves farther, 0 when the
 * boxes do (or there are no curves).
 */
static int curves_needed(const struct px_strack *t, px_vec3 p)
{
	double best = INFINITY;
	int i, j;
	if (!t->ct)
		return 0;
	if (ct_stale(t, p))
		return 1;
	if (ct_proves(t, p))
		return 2;
	for (i = 0; i < t->n_surf; i++)
		for (j = 0; j < t->sf[i].nz; j++) {
			const struct crit *z = &t->sf[i].z[j];
			double d2 = px_v3_dist2(z->s, p);
			if (z->type > 0 && d2 < best &&
			    st_in_domain(&t->sf[i], z->u, z->v))
				best = d2;
		}
	for (i = 0; i < t->n_poles; i++) {
		double d2 = px_v3_dist2(t->pole[i].q, p);
		if (d2 < best)
			best = d2;
	}
	if (!(best < INFINITY))
		return 1;
	/* a margin for the rounding of both sides */
	best *= 1.0 + 1e-9;
	for (i = 0; i < t->n_cbox; i++)
		if (px_aabb_dist2(&t->cbox[i], p) <= best)
			return 1;
	return 0;
}

int px__st_full_reset(struct px_strack *t, px_vec3 p,
		      struct px_strack_result *r)
{
	struct px_track_result cr;
	int rc;
	px__st_curves_update(t, p, &cr, 1);
	rc = reinit_all(t, p);
	/* every cell's certificate here, not in the next update */
	px__st_expiries_rebuild(t, p);
	r->source = PX_TRACK_REINIT;
	if (rc) {
		t->st.overflows++;
		if (t->opts.max_solves > 0)
			px__st_rebuild_start(t);
		px__st_answer_global(t, p, r);
	} else {
		answer(t, p, &cr, r);
		r->jumped = 1;
		if (t->ans_open)
			px__st_answer_global(t, p, r);
		else
			verify(t, p, r);
	}
	return PX_OK;
}

int px_strack_reset(struct px_strack *t, px_vec3 p, struct px_strack_result *r)
{
	int rc = px__tracker_args(t, r, p);
	if (rc)
		return rc;
	result_clear(r);
	t->st.updates++;
	t->p = p;
	t->init = 1;
	px__gov_reset(&t->gov, &t->st.shared);
	t->gov_q = p;
	t->ret_left = 0;
	t->best_kind = 0;
	t->have_last = 0;
	t->mode = ST_TRACK;
	t->hot_s = -1;
	return px__st_full_reset(t, p, r);
}

/* Cell index (within the surface) holding (u, v). */
int px__st_cell_of(const struct ssurf *f, double u, double v)
{
	int i = bsearch_bounds(f->cu, f->ncu, u), j = bsearch_bounds(f->cv, f->ncv, v);
	return j * f->ncu + i;
}

/* Follow one point from its state at p0 to p (predictor, Newton). */
int px__st_evolve(const struct ssurf *f, struct crit *z, px_vec3 dp,
		  px_vec3 p)
{
	double a = px_v3_dot(z->su, dp), b = px_v3_dot(z->sv, dp);
	double det = z->h11 * z->h22 - z->h12 * z->h12;
	if (fabs(det) > 0.0) {
		double su = (z->h22 * a - z->h12 * b) / det;
		double sv = (-z->h12 * a + z->h11 * b) / det;
		if (isfinite(su) && isfinite(sv) && fabs(su) <= 0.25 * f->du &&
		    fabs(sv) <= 0.25 * f->dv) {
			z->u += su;
			z->v += sv;
		}
	}
	return px__st_snewton(f, z, p, 0.125 * f->du, 0.125 * f->dv, NULL);
}

/*
 * Follow z from p0 to p0 + dp, keeping its type (a point changes type only
 * at a fold, where it dies). A long step that fails or changes the type
 * is retried as a continuation in 4, then 16 sub-steps. Returns 0, or 1
 * with *last the furthest point reached (to solve its cell again).
 */
int px__st_follow(const struct ssurf *f, struct crit *z, px_vec3 p0,
		  px_vec3 dp, px_vec3 p, struct crit *last)
{
	struct crit w = *z;
	int ns, k;
	if (!px__st_evolve(f, &w, dp, p) && w.type == z->type) {
		*z = w;
		return 0;
	}
	*last = *z;
	for (ns = 4; ns <= 16; ns *= 4) {
		px_vec3 sd = px_v3_scale(dp, 1.0 / ns);
		w = *z;
		for (k = 1; k <= ns; k++) {
			px_vec3 pk = k == ns ? p : px_v3_add(p0, px_v3_scale(dp, (double)k / ns));
			int ty = w.type;
			if (px__st_evolve(f, &w, sd, pk) || w.type != ty)
				break;
			if (ns == 16)
				*last = w;
		}
		if (k > ns) {
			*z = w;
			return 0;
		}
	}
	return 1;
}

static double cross_at(const struct px_strack *t, const struct scell *c,
		       px_vec3 p0, px_vec3 p1, int *rounds);

/* Rounds of cross_at() at most. */
#define ST_CROSS_ROUNDS 8

static int ring_check(struct px_strack *t, int i, int lim, int *units,
		      int *spare);

/* Solve pending items from pend_next on, at most budget solves (0: all;
 * counted in solve_units(), a seed point still to be found by its
 * cross_at() rounds, an escape bound by the speeds it works out).
 * Returns 0 or PX_E_NOSPC; *done the solves made (rounded up). */
static int pend_solve(struct px_strack *t, int budget, int *done)
{
	int rc = 0, units = 0, spare = 0, lim = budget * ST_UNITS;
	t->pend_on = t->mode != ST_REBUILD;
	while (t->pend_next < t->n_pend) {
		int i = t->pend_next;
		const struct scell *c;
		if (t->pend_kind[i] >= PK_RING) {
			if (ring_check(t, i, lim, &units, &spare))
				break;
			t->pend_next++;
			continue;
		}
		c = &t->cell[t->pend[i]];
		if (t->pend_kind[i] == PK_CROSS) {
			/* its rounds (two cell radii each, about a check's
			 * work) count as units, at most ST_CROSS_ROUNDS */
			px_vec3 p0 = t->pend_ps[i];
			int rounds = 0;
			double s;
			if (lim > 0 && units > 0 && units + ST_CROSS_ROUNDS > lim)
				break;
			s = cross_at(t, c, p0, t->p, &rounds);
			t->pend_ps[i] = px_v3_add(p0, px_v3_scale(px_v3_sub(t->p, p0), s));
			t->pend_kind[i] = PK_SOLVE;
			t->st.cross_rounds += (uint64_t)rounds;
			units += rounds;
		}
		rc = px__st_cell_solve_budget(t, c, t->pend_ps[i], t->p, &units, lim);
		if (rc == 1)
			break;
		t->pend_next++;
		if (rc < 0)
			break;
	}
	t->pend_on = 0;
	*done = (units + ST_UNITS - 1) / ST_UNITS;
	return rc < 0 ? rc : 0;
}

/*
 * Where along p0 -> p1 to solve hit cell c again after a long step: past
 * the part of the segment its certificates leave open, so that a pair
 * born there is found near where it was born (and followed to p1), not
 * looked for after it may have left the cell. The certified radius at
 * either end of the open part [a, b] clears a stretch of it; a few
 * rounds from both ends narrow it down to where the transition can be.
 * Returns b (the col_test() estimate when all of it is cleared); *rounds
 * the rounds made.
 */
static double cross_at(const struct px_strack *t, const struct scell *c,
		       px_vec3 p0, px_vec3 p1, int *rounds)
{
	px_vec3 dp = px_v3_sub(p1, p0);
	double dinf = max_norm(dp);
	double a = 0.0, b = 1.0;
	int k;
	*rounds = 0;
	if (!(dinf > 0.0))
		return 1.0;
	for (k = 0; k < ST_CROSS_ROUNDS && b - a > 1e-3; k++) {
		double ra = cell_radius(t, c, px_v3_add(p0, px_v3_scale(dp, a))) / dinf;
		double rb = cell_radius(t, c, px_v3_add(p0, px_v3_scale(dp, b))) / dinf;
		*rounds = k + 1;
		if (!(ra > 0.0) && !(rb > 0.0))
			break;
		a += ra;
		b -= rb;
		if (a >= b)
			return c->cross;
	}
	return b;
}

/*
 * Escape bound. A critical point at p that no follow accounts for was,
 * at some time of the step, in a source cell: a hit cell (pairs are born
 * only where a certificate fails, and points enter only through the open
 * sides of those) or the cell where a lost point was last seen. After it
 * last left a source it moved through cells whose certificates hold, and
 * there H d(u, v) = (Su . dx, Sv . dx) (differentiate E = 0), so
 * |d(u, v)| <= K |dx| with K = sqrt(max Su.Su + max Sv.Sv) / sigma,
 * sigma a lower bound on the singular values of every H in the piece's
 * enclosure while x runs over the segment; where E is proven nonzero it
 * does not pass at all (K = 0). Ring k is the cells at Chebyshev
 * distance k from the sources (the cell grid, wrapped where the surface
 * is); within it the quarters at distance j (in quarters) from rings
 * 0..k-1 make layer j = 1..4, each one quarter thick: no two quarters of
 * layers j - 1 and j + 1 touch. A point ending outside ring k crossed
 * every layer of rings 1..k, each at K at most its largest and over at
 * least its least quarter width w, so the step's travel |dp| is at least
 * the sum of w / K over them. Rings are solved out to the first k where
 * that sum exceeds |dp|. Near a focal sheet points move fast and one
 * ring is not always enough; K is taken over the regions, and over the
 * quarters of those that would spoil their layers (tighter enclosures
 * near a fold).
 */

/* Test hook (track_hooks.h): bit 0 solves the first ring only, bound or
 * not; bit 1 leaves out the solves past where a long step met a hit
 * cell's region (the bound alone must hold). */
#ifdef PX_TEST_HOOKS
int px__strack_ring_fault = 0;
#endif

/* K of certificate c (above) while x runs over the cube of half width r
 * about xm: 0 when E is proven nonzero, INFINITY when no bound. */
static double cert_speed(const struct rcert *c, px_vec3 xm, double r)
{
	double mid[3], rad[3], lo[3], hi[3], e1, e2, epad, sig;
	const double m[3] = {c->m11, c->m12, c->m22};
	px_vec3 w;
	int k;
	hess_at(c, xm, mid, rad);
	w = px_v3_sub(c->sc, xm);
	e1 = px_v3_dot(w, c->suc);
	e2 = px_v3_dot(w, c->svc);
	epad = e_pad(c, w, xm);
	/* cert_radius()'s E test over the cube */
	if (e_radius(c, fabs(mid[0]) + rad[0], fabs(mid[1]) + rad[1],
		     fabs(mid[2]) + rad[2], e1, e2, epad) * ST_RSAFE > r)
		return 0.0;
	for (k = 0; k < 3; k++) {
		lo[k] = mid[k] - rad[k] - r * m[k];
		hi[k] = mid[k] + rad[k] + r * m[k];
	}
	if (!px__st_sym_regular(lo, hi, &sig) || !(sig > 0.0))
		/* the preconditioned E test last: it costs as much again */
		return px__st_pre_radius(c, mid, rad, e1, e2, epad) > r ? 0.0 : INFINITY;
	return sqrt(c->G11.hi + c->G22.hi) / sig * (1.0 + 1e-9);
}

static void pend_item(struct px_strack *t, int ci, int kind, px_vec3 ps,
		      double need)
{
	t->pend[t->n_pend] = ci;
	t->pend_kind[t->n_pend] = (unsigned char)kind;
	t->pend_need[t->n_pend] = need;
	t->pend_ps[t->n_pend++] = ps;
}

/* Pend cell ci of the step's solves at p, once. */
static void pend_at(struct px_strack *t, int ci, px_vec3 p)
{
	if (t->cell[ci].mark == t->pend_epoch)
		return;
	t->cell[ci].mark = t->pend_epoch;
	pend_item(t, ci, PK_SOLVE, p, 0.0);
}

/* Cell (cu + du, cv + dv) of f, wrapped; -1 off the domain. */
static int cell_at(const struct ssurf *f, int cu, int cv, int du, int dv)
{
	int nu = cu + du, nv = cv + dv;
	if (f->wrap_u)
		nu = ((nu % f->ncu) + f->ncu) % f->ncu;
	if (f->wrap_v)
		nv = ((nv % f->ncv) + f->ncv) % f->ncv;
	if (nu < 0 || nu >= f->ncu || nv < 0 || nv >= f->ncv)
		return -1;
	return f->first_cell + nv * f->ncu + nu;
}

/* Ring k of surface si: the cells at distance k from its sources (hits
 * 0..pend_nh) get that distance and make its list (ring_list from the
 * surface's first cell on; ring_check() pends their solves); its bound
 * starts. */
static void ring_build(struct px_strack *t, int si, int k)
{
	struct ssurf *f = &t->sf[si];
	int i, du, dv;
	f->rl_n = f->rl_next = 0;
	for (i = 0; i < 4; i++) {
		f->rl_kl[i] = 0.0;
		f->rl_wl[i] = INFINITY;
	}
	for (i = 0; i < t->pend_nh; i++) {
		int ci = t->hits[i], loc, cu, cv;
		if (t->cell[ci].surf != si)
			continue;
		loc = ci - f->first_cell;
		cu = loc % f->ncu;
		cv = loc / f->ncu;
		for (dv = -k; dv <= k; dv++)
			for (du = -k; du <= k; du += (dv == -k || dv == k) ? 1 : 2 * k) {
				int nc = cell_at(f, cu, cv, du, dv);
				struct scell *c;
				if (nc < 0)
					continue;
				c = &t->cell[nc];
				/* nearer rings were built whole: unmarked here is
				 * distance k */
				if (c->dmark == t->pend_epoch)
					continue;
				c->dmark = t->pend_epoch;
				c->dist = k;
				t->ring_list[f->first_cell + f->rl_n++] = nc;
			}
	}
}

/* Distance in pieces (res a side) of piece (a, b) of a ring cell from the
 * inner neighbours in (in[dv + 1][du + 1]); 1..res. */
static int piece_dist(const int in[3][3], int res, int a, int b)
{
	int lo_u = a + 1, hi_u = res - a, lo_v = b + 1, hi_v = res - b, d = res;
	if (in[1][0] && lo_u < d)
		d = lo_u;
	if (in[1][2] && hi_u < d)
		d = hi_u;
	if (in[0][1] && lo_v < d)
		d = lo_v;
	if (in[2][1] && hi_v < d)
		d = hi_v;
	if (in[0][0] && ST_MAX(lo_u, lo_v) < d)
		d = ST_MAX(lo_u, lo_v);
	if (in[0][2] && ST_MAX(hi_u, lo_v) < d)
		d = ST_MAX(hi_u, lo_v);
	if (in[2][0] && ST_MAX(lo_u, hi_v) < d)
		d = ST_MAX(lo_u, hi_v);
	if (in[2][2] && ST_MAX(hi_u, hi_v) < d)
		d = ST_MAX(hi_u, hi_v);
	return d;
}

/*
 * Add ring cell ci of surface f to its ring's layers (quarter layers
 * rl_kl, rl_wl): each region's K, or its quarters' where the region's
 * could leave the four layers short of rem of travel. Returns the K
 * worked out.
 */
static int ring_cell(struct px_strack *t, struct ssurf *f, int ci, px_vec3 xm,
		     double r, double rem)
{
	struct scell *c = &t->cell[ci];
	int loc = ci - f->first_cell, cu = loc % f->ncu, cv = loc / f->ncu, in[3][3],
	    du, dv, a, b, n = 0;
	double wq = 0.25 * fmin(c->u1 - c->u0, c->v1 - c->v0);
	for (dv = -1; dv <= 1; dv++)
		for (du = -1; du <= 1; du++) {
			int nc = cell_at(f, cu, cv, du, dv);
			in[dv + 1][du + 1] = nc >= 0 && t->cell[nc].dmark == t->pend_epoch &&
					     t->cell[nc].dist < c->dist;
		}
	for (b = 0; b < 2; b++)
		for (a = 0; a < 2; a++) {
			int ri = c->child + a + 2 * b, d = piece_dist(in, 2, a, b), q;
			double k = cert_speed(&t->rcell[ri].cert, xm, r);
			n++;
			c->kr[2 * b + a] = k;
			for (q = 0; q < 4; q++)
				c->kq[4 * (2 * b + a) + q] = NAN;
			if (!(k * rem > 3.8 * wq)) {
				/* both of its quarter layers get the region's: with
				 * every piece so, the four layers take over rem */
				for (q = 2 * d - 2; q < 2 * d; q++) {
					f->rl_kl[q] = fmax(f->rl_kl[q], k);
					f->rl_wl[q] = fmin(f->rl_wl[q], wq);
				}
				continue;
			}
			for (q = 0; q < 4; q++) {
				int l = piece_dist(in, 4, 2 * a + (q & 1), 2 * b + (q >> 1)) - 1;
				k = cert_speed(&t->qcert[4 * ri + q], xm, r);
				c->kq[4 * (2 * b + a) + q] = k;
				n++;
				f->rl_kl[l] = fmax(f->rl_kl[l], k);
				f->rl_wl[l] = fmin(f->rl_wl[l], wq);
			}
		}
	c->kmark = t->pend_epoch;
	return n;
}

/* Units a ring cell's bound may take at most (4 regions and their 16
 * quarters, 8 speeds a unit, about a check's work). */
#define ST_RING_CELL_UNITS 3

/*
 * The escape bound of pending item i (ring k of surface pend[i], the step
 * from pend_ps[i]; the rings inside it take pend_need[i] of travel): its
 * cells' layers, then held (done) or ring k + 1 built and pended; past
 * ST_RINGS the whole surface. *spare: speeds already counted in *units.
 * Not continued past lim after other work; returns 1 when left for later
 * (resumed at the next cell).
 */
static int ring_check(struct px_strack *t, int i, int lim, int *units,
		      int *spare)
{
	int si = t->pend[i], k = t->pend_kind[i] - PK_RING + 1, j;
	struct ssurf *f = &t->sf[si];
	px_vec3 p0 = t->pend_ps[i], dp = px_v3_sub(t->p, p0),
		xm = px_v3_scale(px_v3_add(p0, t->p), 0.5);
	double r = 0.5 * max_norm(dp), len = px_v3_norm(dp), need = t->pend_need[i];
	while (f->rl_next < f->rl_n) {
		int n, ci;
		if (lim > 0 && *units > 0 && *units + ST_RING_CELL_UNITS > lim)
			return 1;
		ci = t->ring_list[f->first_cell + f->rl_next++];
		n = ring_cell(t, f, ci, xm, r, len - need);
		/* its solve after its K: they prove most of its checks */
		pend_at(t, ci, t->p);
		t->st.ring_speeds += (uint64_t)n;
		for (*spare -= n; *spare < 0; *spare += 8)
			++*units;
	}
	for (j = 0; j < 4; j++)
		need += f->rl_kl[j] > 0.0 ? f->rl_wl[j] / f->rl_kl[j] : INFINITY;
	/* held; or nothing to cross (no ring left in the domain), or no
	 * motion (a point of a fixed x stays put) */
	if (need > len || f->rl_n == 0 || !(len > 0.0))
		return 0;
	if (k < ST_RINGS) {
		ring_build(t, si, k + 1);
		pend_item(t, si, PK_RING + k, p0, need);
		return 0;
	}
	t->st.ring_all++;
	for (j = 0; j < f->ncu * f->ncv; j++)
		pend_at(t, f->first_cell + j, t->p);
	return 0;
}

/*
 * Move the tracked set from p0 to p (t->p becomes p), the nh cells whose
 * certificates the segment may break collected (collect_cells()): follow
 * every point, add the cells of lost points, and solve them (a hit after
 * a long step also past where its region was met, its roots followed to
 * p) with the rings of cells about them that the escape bound names
 * (ring_check()). Returns 0; 1 when that work exceeds the
 * budget: the budget's worth is done, the rest left pending (mode
 * ST_PEND, solved over the next updates at p); 2 when the index check
 * fails (ix_check()); PX_E_NOSPC.
 */
static int track_step(struct px_strack *t, px_vec3 p0, px_vec3 p,
		      struct px_strack_result *r, int nh)
{
	px_vec3 dp = px_v3_sub(p, p0);
	double step = px_v3_norm(dp);
	int i, j, rc = 0, before = 0, after = 0, done = 0,
		      budget = t->opts.max_solves;

	t->ix_on = 0;
	for (i = 0; i < t->n_surf; i++) {
		struct ssurf *f = &t->sf[i];
		int n = f->nz;
		memcpy(f->tmp, f->z, (size_t)n * sizeof(*f->z));
		f->nz = 0;
		for (j = 0; j < n; j++) {
			struct crit z = f->tmp[j], last;
			/* a point that rested on the hot path starts where it
			 * was last followed */
			int rest = t->hot_s >= 0 && !(i == t->hot_s && j == t->hot_j);
			px_vec3 q0 = rest ? t->hot_p : p0;
			if (px__st_follow(f, &z, q0, px_v3_sub(p, q0), p, &last)) {
				/* died at a fold (or left through an edge), or
				 * Newton lost it: solve its cell and the cell
				 * where it was last seen, so a survivor is found
				 * again */
				int q;
				t->st.lost++;
				r->died++;
				t->ix_on = 1;
				for (q = 0; q < 2; q++) {
					const struct crit *o = q ? &last : &f->tmp[j];
					int ci = f->first_cell + px__st_cell_of(f, o->u, o->v);
					if (t->cell[ci].mark != t->epoch && nh < t->n_cells) {
						t->cell[ci].mark = t->epoch;
						t->cell[ci].cross = 1.0;
						t->hits[nh++] = ci;
					}
				}
				continue;
			}
			rc = px__st_crit_add(t, f, &z);
			if (rc < 0) {
				t->hot_s = -1;
				return rc;
			}
			/* followed onto a held point's branch */
			t->ix_on |= rc == 0;
		}
	}
	t->hot_s = -1;
	t->p = p;
	/* the work list: solve at p, after a long step also past where the
	 * region was met (not for pole cells: hit_work()); and the
	 * cells about it at p */
	t->n_pend = t->pend_next = 0;
	t->pend_epoch = t->epoch;
	for (i = 0; i < nh; i++) {
		int ci = t->hits[i];
		pend_item(t, ci, PK_SOLVE, p, 0.0);
		if (hit_work(t, ci, step) > 1 && !(px__strack_ring_fault & 2))
			pend_item(t, ci, PK_CROSS, p0, 0.0);
	}
	/* a pair born in a hit cell may have moved on into the cells about
	 * it, both its members sometimes (the index check does not see
	 * that): the rings of the escape bound (mostly cheap: their regions
	 * are proven empty or hold the one point they can) */
	t->pend_nh = nh;
	for (i = 0; i < nh; i++) {
		t->cell[t->hits[i]].dmark = t->epoch;
		t->cell[t->hits[i]].dist = 0;
	}
	for (i = 0; i < t->n_surf; i++) {
		const struct ssurf *f = &t->sf[i];
		ring_build(t, i, 1);
		if (!(px__strack_ring_fault & 1)) {
			if (f->rl_n > 0)
				pend_item(t, i, PK_RING, p0, 0.0);
			continue;
		}
		/* the fault: the first ring solved, its bound not made */
		for (j = 0; j < f->rl_n; j++)
			pend_at(t, t->ring_list[f->first_cell + j], p);
	}
	for (i = 0; i < t->n_surf; i++)
		before += t->sf[i].nz;
	/* within the budget all of it; over it, the budget's worth now and
	 * the rest over the next updates */
	rc = pend_solve(t, budget, &done);
	for (i = 0; i < t->n_surf; i++)
		after += t->sf[i].nz;
	/* new points only come from solved cells: births (pairs at a focal
	 * sheet) and entries through an edge */
	r->born = after - before;
	t->st.born += (uint64_t)r->born;
	r->cells_solved = done;
	if (rc < 0)
		return rc;
	if (t->pend_next < t->n_pend) {
		t->st.over_budget++;
		t->mode = ST_PEND;
		return 1;
	}
	return px__st_ix_check(t) ? 2 : 0;
}

/* Cells solved per update of a rebuild (max_solves > 0). */
int px__st_rebuild_slice(const struct px_strack *t)
{
	return t->opts.max_solves > 1 ? t->opts.max_solves / 2 : 1;
}

/* Re-establish the critical points from scratch over the next updates,
 * starting at the next point inside the working volume. */
void px__st_rebuild_start(struct px_strack *t)
{
	int i;
	t->hot_s = -1;
	t->mode = ST_REBUILD;
	t->rb_started = 0;
	t->rb_next = 0;
	t->ex_ok = 0;
	t->col_on = 0;
	t->ix_on = 0;
	for (i = 0; i < t->n_surf; i++)
		t->sf[i].nz = 0;
}

/*
 * One update while the tracked set is not at the query point; the answer
 * is the global query's unless the set reaches p in this update and
 * agrees with it.
 *  - ST_PEND: the set is at t->p but owes cell solves there: up to the
 *    budget of them now; when none is left: ST_LAG.
 *  - ST_REBUILD: a slice of cells is solved at the fixed point t->p
 *    where the rebuild started, each cell's certificate taken there;
 *    when all are, the set is complete at t->p: ST_LAG.
 *  - ST_LAG: the set moves from t->p to p by one tracked step; solves
 *    over the budget are left pending (ST_PEND) at p. When more than
 *    max_tests cells are due, the step's end is held at that p and its
 *    cells are tested max_tests per update first. It catches up when the
 *    work of the distance travelled meanwhile fits the budgets: while
 *    the point moves with less work per update than the budgets on
 *    average.
 */
static int catch_up(struct px_strack *t, px_vec3 p, struct px_strack_result *r)
{
	struct px_track_result cr;
	struct px_dist_result g;
	int rc = 0;
	t->st.rebuild_updates++;
	px__st_curves_update(t, p, &cr, 0);
	if (t->mode == ST_PEND) {
		int done = 0, i, before = 0, after = 0;
		for (i = 0; i < t->n_surf; i++)
			before += t->sf[i].nz;
		rc = pend_solve(t, t->opts.max_solves > 0 ? t->opts.max_solves : 0, &done);
		for (i = 0; i < t->n_surf; i++)
			after += t->sf[i].nz;
		r->born = after - before;
		t->st.born += (uint64_t)r->born;
		r->cells_solved = done;
		if (rc < 0) {
			t->st.overflows++;
			px__st_rebuild_start(t);
		} else if (t->pend_next >= t->n_pend) {
			t->mode = ST_LAG;
			if (px__st_ix_check(t))
				px__st_rebuild_start(t);
		}
		px__st_answer_global(t, p, r);
		return PX_OK;
	}
	if (t->mode == ST_REBUILD) {
		int slice = px__st_rebuild_slice(t);
		if (!t->rb_started) {
			if (!in_work(t, p)) {
				t->st.outside++;
				px__st_answer_global(t, p, r);
				return PX_OK;
			}
			t->rb_started = 1;
			t->p = p;
			t->travel = t->ctravel = 0.0;
		}
		int units = 0;
		while (t->rb_next < t->n_cells && rc >= 0) {
			struct scell *c = &t->cell[t->rb_next];
			rc = px__st_cell_solve_budget(t, c, t->p, t->p, &units,
					       slice * ST_UNITS);
			if (rc == 1) {
				rc = 0;
				break;
			}
			cell_expire(t, c, t->p, cell_radius(t, c, t->p));
			t->rb_next++;
		}
		r->cells_solved = (units + ST_UNITS - 1) / ST_UNITS;
		if (rc < 0) {
			t->st.overflows++;
			px__st_rebuild_start(t);
		} else if (t->rb_next >= t->n_cells) {
			px__st_groups_rebuild(t);
			t->ex_ok = 1;
			t->mode = ST_LAG;
		}
		px__st_answer_global(t, p, r);
		return PX_OK;
	}
	/* ST_LAG */
	if (t->col_on || in_work(t, p)) {
		int nh = t->col_on ? col_resume(t) : px__st_collect_cells(t, t->p, p);
		px_vec3 p1;
		if (nh < 0) {
			px__st_answer_global(t, p, r);
			return PX_OK;
		}
		/* the step ends where its collection started */
		p1 = t->col_p1;
		rc = track_step(t, t->p, p1, r, nh);
		if (rc < 0 || rc == 2) {
			t->st.overflows += rc < 0;
			px__st_rebuild_start(t);
		} else if (rc == 0 && p1.x == p.x && p1.y == p.y && p1.z == p.z) {
			/* caught up: checked against the global answer */
			answer(t, p, &cr, r);
			if (t->ans_open) {
				/* the set is complete: only this answer is
				 * not its own */
				t->mode = ST_TRACK;
				px__st_answer_global(t, p, r);
				return PX_OK;
			}
			if (px_dist_query(t->dist, p, &g) == PX_OK) {
				t->st.verifications++;
				r->verified = 1;
				if (fabs(r->dist - g.dist) <= 1e-9 * (t->scale + g.dist)) {
					t->mode = ST_TRACK;
					r->source = PX_TRACK_REINIT;
					return PX_OK;
				}
				t->st.disagreements++;
			}
			px__st_rebuild_start(t);
		}
	} else {
		t->st.outside++;
	}
	px__st_answer_global(t, p, r);
	return PX_OK;
}

/*
 * Arm the hot path after a tracked update answered by surface minimum
 * (ans_s, ans_j), with every point current at p. The global distance is
 * 1-Lipschitz and best is that of a real surface point followed
 * continuously, so after a further path L it is at most best + L, while
 * another minimum, a pole or any curve or edge (bounded below by the
 * distance to the boxes of its half spans) at distance d now is at least
 * d - L away: none can answer while L < (d - best) / 2. While no cell is
 * due the set of critical points keeps its count and types (the cell
 * certificates), so the answering minimum is followed alone. The curve
 * tracker is left out for at most 2 % of the size of travel, as
 * curves_needed() does.
 */
static void hot_arm(struct px_strack *t, px_vec3 p,
		    const struct px_strack_result *r)
{
	double best = r->dist, tol = 1e-9 * (best + t->scale), until, m, lim,
	       cc = INFINITY, uout = INFINITY;
	int i, j;
	int curve = r->feature == PX_STRACK_CURVE || r->feature == PX_STRACK_EDGE;
	t->hot_s = -1;
	if (t->mode != ST_TRACK || r->source != PX_TRACK_TRACKED ||
	    (t->fault_hot & 1) ||
	    !(curve ? t->best_kind == 2 && t->ct_p.x == p.x && t->ct_p.y == p.y &&
			      t->ct_p.z == p.z
		    : r->feature == PX_STRACK_MIN && t->ans_s >= 0))
		return;
	until = INFINITY;
	for (i = 0; i < t->n_surf; i++)
		for (j = 0; j < t->sf[i].nz; j++) {
			const struct crit *z = &t->sf[i].z[j];
			if (z->type <= 0 ||
			    (!curve && i == t->ans_s && j == t->ans_j))
				continue;
			m = px_v3_dist(z->s, p) - best - tol;
			if (!st_in_domain(&t->sf[i], z->u, z->v)) {
				uout = m < uout ? m : uout;
				continue;
			}
			if (!(m > 0.0))
				return;
			if (m < until)
				until = m;
		}
	for (i = 0; i < t->n_poles; i++) {
		m = px_v3_dist(t->pole[i].q, p) - best - tol;
		if (!(m > 0.0))
			return;
		if (m < until)
			until = m;
	}
	/* when the curve tracker answers it runs every update (the least
	 * distance to the curves is 1-Lipschitz too); else the curves are
	 * left out while the curve tracker's last answer proves them
	 * farther (ct_note(): cc, already halved) or their boxes do (and
	 * for 2 % of the size at most, as curves_needed()), or updated
	 * along with the minimum every update */
	t->hot_curves = 0;
	lim = INFINITY;
	if (!curve && t->ct) {
		double uc = until;
		lim = 0.02 * t->scale - px_v3_dist(p, t->ct_p);
		t->hot_curves = !(lim > 0.0);
		for (i = 0; i < t->n_cbox && !t->hot_curves; i++) {
			m = sqrt(px_aabb_dist2(&t->cbox[i], p)) - best - tol;
			if (!(m > 0.0))
				t->hot_curves = 1;
			else if (m < uc)
				uc = m;
		}
		if (t->hot_curves && lim > 0.0 && t->ct_rc > 0.0) {
			/* the boxes prove nothing: the curve tracker's
			 * answer may, when it does not cut the certificate
			 * short (else the curves run with the minimum, and
			 * hot_update() notes their answers) */
			cc = t->ct_rc - px_v3_dist(p, t->ct_q);
			if (cc >= 0.5 * fmin(until, 2.0 * lim)) {
				t->hot_curves = 0;
				uc = until;
			} else
				cc = INFINITY;
		}
		if (t->hot_curves)
			lim = INFINITY;
		else
			until = uc;
	}
	/* A minimum outside its trimmed domain enters it through a
	 * trimming edge, a curve: while the curves are proven farther than
	 * the answer along the way (their bound is 1-Lipschitz too), it
	 * enters and stays farther; else its own margin counts. */
	if ((curve || t->hot_curves || !t->ct) && uout < INFINITY) {
		if (!(uout > 0.0))
			return;
		until = uout < until ? uout : until;
	}
	until *= 0.5;
	if (lim < until)
		until = lim;
	if (cc < until)
		until = cc;
	t->hot_s = curve ? t->n_surf : t->ans_s;
	t->hot_j = curve ? -1 : t->ans_j;
	t->hot_p = p;
	t->hot_until = (t->fault_hot & 2) ? INFINITY
					   : t->travel + until * (1.0 - 1e-9);
	t->hot_nmin = r->n_min;
	t->hot_nmax = r->n_max;
	t->hot_nsad = r->n_saddle;
	t->hot_ncrit = r->n_crit;
	t->hot_ccrit = t->ct_ncrit;
}

/* An update on the hot path (the certificate running, the due cells
 * tested and none hit; the travelled path includes this step): the
 * answering minimum followed by one predictor and Newton (on a copy,
 * kept when it stays a minimum), or the curve tracker updated. Returns 0
 * when answered, 1 when the full update must run (the point set is as
 * it was). */
static int hot_update(struct px_strack *t, px_vec3 p,
		      struct px_strack_result *r)
{
	struct ssurf *f = NULL;
	struct crit w;
	struct px_track_result cr;
	int use_min = t->hot_s < t->n_surf, kind = 1;
	if (use_min) {
		f = &t->sf[t->hot_s];
		w = f->z[t->hot_j];
		if (px__st_evolve(f, &w, px_v3_sub(p, t->p), p) || w.type != 1 ||
		    !st_in_domain(f, w.u, w.v))
			return 1;
	}
	r->n_crit = t->hot_ncrit;
	if (!use_min || (t->hot_curves && (ct_stale(t, p) || !ct_proves(t, p)))) {
		/* the curve tracker answers, or could (its own update,
		 * exact; left out while its last answer proves the curves
		 * farther, ct_note(), for 2 % of the size at most); the
		 * margin of the other minima and the poles holds against
		 * either answer, and the nearer answers */
		px__st_curves_update(t, p, &cr, 0);
		if (!use_min && cr.entity < 0)
			return 1; /* not expected: the full update decides */
		if (cr.entity >= 0 &&
		    (!use_min || cr.dist * cr.dist < px_v3_dist2(w.s, p)))
			kind = 2;
		if (kind == 2 && crease_out(t, &cr))
			return 1; /* the full update answers globally */
		if (use_min && kind == 1 && cr.entity >= 0)
			ct_note(t, p, cr.dist, px_v3_dist(w.s, p));
	} else if (t->hot_curves) {
		t->st.curve_cert_skips++;
	}
	if (!use_min || t->hot_curves)
		r->n_crit = t->hot_ncrit - t->hot_ccrit + t->ct_ncrit;
	if (use_min)
		f->z[t->hot_j] = w;
	t->p = p;
	r->source = PX_TRACK_TRACKED;
	if (kind == 2) {
		answer_curve(t, &cr, r);
		if (cr.source != PX_TRACK_TRACKED)
			r->source = cr.source;
		r->jumped = t->best_kind != 2 || cr.jumped;
	} else {
		r->point = w.s;
		r->u = w.u;
		r->v = w.v;
		r->entity = t->n_curves + t->hot_s;
		r->feature = PX_STRACK_MIN;
		r->jumped = t->best_kind != 1;
	}
	t->best_kind = kind;
	fill_dir(r, p);
	r->n_min = t->hot_nmin;
	r->n_max = t->hot_nmax;
	r->n_saddle = t->hot_nsad;
	t->last_point = r->point;
	t->last_q = p;
	t->last_entity = r->entity;
	t->st.hot++;
	return 0;
}

/* The tracked update (every mode but cold). */
static int strack_update(struct px_strack *t, px_vec3 p, struct px_strack_result *r)
{
	struct px_track_result cr;
	px_vec3 p0;
	int rc, nh, ran;

	result_clear(r);
	t->st.updates++;
	if (++t->epoch == 0)
		t->epoch = 1;
	if (t->mode != ST_TRACK)
		return catch_up(t, p, r);
	p0 = t->p;
	nh = -1;
	if (t->hot_s >= 0 && t->ex_ok && in_work(t, p) && in_work(t, p0) &&
	    t->travel + px_v3_dist(p0, p) < t->hot_until) {
		/* the due cells first (as track_step would): none hit and
		 * the hot path answers */
		nh = px__st_collect_cells(t, p0, p);
		if (nh == 0 && !hot_update(t, p, r)) {
			verify(t, p, r);
			return PX_OK;
		}
	}
	r->source = PX_TRACK_TRACKED;
	if (!in_work(t, p) || !in_work(t, p0)) {
		if (t->opts.max_solves > 0) {
			/* the set waits at p0 for the point to come back */
			t->mode = ST_LAG;
			return catch_up(t, p, r);
		}
		t->p = p;
		t->st.outside++;
		return px__st_full_reset(t, p, r);
	}
	if (nh < 0 && !t->col_on)
		nh = px__st_collect_cells(t, p0, p);
	if (t->col_on) {
		/* more cells due than max_tests: tested over the next updates
		 * (the set waits at p0), answered globally meanwhile */
		t->st.over_budget++;
		t->mode = ST_LAG;
		px__st_answer_global(t, p, r);
		return PX_OK;
	}
	rc = track_step(t, p0, p, r, nh);
	if (rc == 1) {
		/* over the budget: answer globally; the rest of the solves
		 * is done over the next updates, then the set catches up */
		px__st_answer_global(t, p, r);
		return PX_OK;
	}
	if (rc) {
		/* capacity, or the index check failed: the set is
		 * re-established (over the next updates with a budget) */
		t->st.overflows += rc < 0;
		t->st.reinits++;
		if (t->opts.max_solves > 0) {
			px__st_rebuild_start(t);
		} else {
			t->p = p;
			if (reinit_all(t, p))
				t->st.overflows++;
			px__st_expiries_rebuild(t, p);
		}
		px__st_answer_global(t, p, r);
		return PX_OK;
	}
	ran = curves_needed(t, p);
	if (ran == 1) {
		px__st_curves_update(t, p, &cr, 0);
	} else {
		memset(&cr, 0, sizeof(cr));
		cr.entity = -1;
		cr.n_crit = t->ct_ncrit;
		t->st.curve_skips++;
		t->st.curve_cert_skips += ran == 2;
	}
	answer(t, p, &cr, r);
	if (t->ans_open) {
		t->hot_s = -1;
		px__st_answer_global(t, p, r);
		return PX_OK;
	}
	if (ran == 1 && cr.entity >= 0 && isfinite(r->dist))
		ct_note(t, p, cr.dist, r->dist);
	if (cr.source != PX_TRACK_TRACKED)
		r->source = cr.source;
	verify(t, p, r);
	hot_arm(t, p, r);
	return PX_OK;
}

/* Whether the update that answered r at p fell behind, for the
 * governor's px__gov_behind(): 1 when answered globally with the set
 * short of the point after its work (catching up or owing solves); -1
 * when the set is being rebuilt (the return's own cost, or a failed
 * check's) or waits outside the working volume without work; else 0. */
static int fell_behind(const struct px_strack *t, px_vec3 p,
		       const struct px_strack_result *r)
{
	if (r->source != PX_TRACK_GLOBAL)
		return 0;
	if (t->mode == ST_REBUILD || !in_work(t, p))
		return -1;
	return t->mode == ST_LAG || t->mode == ST_PEND;
}

int px_strack_update(struct px_strack *t, px_vec3 p, struct px_strack_result *r)
{
	int64_t t0;
	int rc = px__tracker_args(t, r, p), mode;
	double len = 0.0;

	if (rc)
		return rc;
	if (!t->init)
		return px_strack_reset(t, p, r);
	if (t->gov.on) {
		len = px_v3_dist(t->gov_q, p);
		t->gov_q = p;
	}
	mode = px__gov_begin(&t->gov, len);
	if (mode == PX_GOV_COLD) {
		if (px__st_cold_update(t, p, r) == 0)
			return PX_OK;
		/* no global answer here: track again */
		px__gov_restart(&t->gov);
	}
	if (mode != PX_GOV_TRACK)
		return px__st_cold_return(t, p, r);
	t0 = t->ret_left == 0 ? px__gov_start(&t->gov) : PX_GOV_UNTIMED;
	rc = strack_update(t, p, r);
	if (t->ret_left > 0 && (t->mode == ST_TRACK || --t->ret_left == 0))
		t->ret_left = 0;
	if (px__gov_behind(&t->gov, fell_behind(t, p, r)) || px__gov_stop(&t->gov, t0))
		px__st_cold_enter(t, p, r);
	return rc;
}
