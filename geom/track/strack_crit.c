/*
 * strack_crit.c - surface tracker (px_strack.h): the critical-point sets of
 * the cells: adding, the contraction and seed solves of a cell, and the
 * run-time subdivision of the boxes the setup certificates leave open. The
 * layout and the shared declarations are in strack_internal.h.
 */
#include "strack_internal.h"

/* ------------------------------------------------------------------ */
/* critical-point sets                                                 */

static int crit_dup(const struct ssurf *f, const struct crit *a,
		    const struct crit *b)
{
	double du = fabs(a->u - b->u), dv = fabs(a->v - b->v);
	if (f->wrap_u)
		du = fmin(du, f->du - du);
	if (f->wrap_v)
		dv = fmin(dv, f->dv - dv);
	return du <= 1e-7 * f->du && dv <= 1e-7 * f->dv;
}

/* Add z unless it duplicates a held point. Returns 1 added, 0 duplicate,
 * PX_E_NOSPC. */
int px__st_crit_add(struct px_strack *t, struct ssurf *f, const struct crit *z)
{
	int i;
	for (i = 0; i < f->nz; i++)
		if (crit_dup(f, &f->z[i], z))
			return 0;
	if (f->nz >= f->cap)
		return PX_E_NOSPC;
	f->z[f->nz] = *z;
	if (!f->z[f->nz].id) {
		if (++t->next_id >= 0x7fffffffu)
			t->next_id = 1;
		f->z[f->nz].id = t->next_id;
	}
	f->nz++;
	return 1;
}

/* 1 when f holds a point in the box b (u0, u1, v0, v1). */
static int holds(const struct ssurf *f, const double b[4])
{
	int i;
	for (i = 0; i < f->nz; i++)
		if (f->z[i].u >= b[0] && f->z[i].u <= b[1] && f->z[i].v >= b[2] &&
		    f->z[i].v <= b[3])
			return 1;
	return 0;
}

/* What a solve at p does in a box: nothing (proven to hold no
 * critical point, or none but a held one), contract_solve() (at most
 * one, found or proven absent), its seeds (not proven). */
enum { BOX_SEEDS = 0, BOX_DONE = 1, BOX_EXACT = 2 };

/* The work of box b (with certificate c) at p (known: the held set is at
 * p): done when proven free of critical points, or its Hessian enclosure
 * regular - at most one critical point in it - and a held point lies in
 * it, which is then the only one; exact when it holds none and the
 * contraction of contract_rate() runs on it. */
static int box_done(const struct ssurf *f, const struct rcert *c,
		    const double b[4], px_vec3 p, int known)
{
	double y[2][2], rho, mid[3], rad[3];
	int held;
	hess_at(c, p, mid, rad);
	if (px__st_no_root_h(c, p, mid, rad))
		return BOX_DONE;
	held = known && holds(f, b);
	if (held && px__st_one_root_h(mid, rad))
		return BOX_DONE;
	if (!px__st_contract_h(c, mid, rad, y, &rho))
		return BOX_SEEDS;
	return held ? BOX_DONE : BOX_EXACT;
}

/* The box (u0, u1, v0, v1) of cell g (k < 0) or of its quarter k (k & 1:
 * the upper half in u, k & 2: in v). */
void px__st_box_of(const struct scell *g, int k, double b[4])
{
	double um = 0.5 * (g->u0 + g->u1), vm = 0.5 * (g->v0 + g->v1);
	b[0] = k >= 0 && (k & 1) ? um : g->u0;
	b[1] = k >= 0 && !(k & 1) ? um : g->u1;
	b[2] = k >= 0 && (k & 2) ? vm : g->v0;
	b[3] = k >= 0 && !(k & 2) ? vm : g->v1;
}

/* box_done() from the K of box b over the step that ends at the held
 * set's point (NAN: none worked out): 0, no critical point in it at any
 * point of the step, so none at its end; finite, H regular there
 * throughout, so at most one, the held one if any (without one the
 * box's own test is still to be made). */
static int speed_done(const struct ssurf *f, double k, const double b[4])
{
	return k == 0.0 || (k < INFINITY && holds(f, b));
}

/* cell_done for c at ps (known: the held set is at ps; a seed converges
 * to a point near it, so those parts give none): a region needs none
 * when its own test or each of its quarters' holds. Returns the
 * certificate tests made (none where a ring's K covers them). */
static int cell_done(const struct px_strack *t, const struct scell *c,
		     px_vec3 ps, int known, struct cell_done *d)
{
	const struct ssurf *f = &t->sf[c->surf];
	/* the ring's K hold for ps: the end of the step they were worked
	 * out for (speed_done()) */
	int sp = c->kmark == t->pend_epoch && t->pend_on && known &&
		 px_v3_dist2(ps, t->p) == 0.0;
	int ch, k, tests = 0, open, seeds;
	for (ch = 0; ch < 4; ch++) {
		int ri = c->child + ch;
		const struct scell *g = &t->rcell[ri];
		double b[4];
		px__st_box_of(g, -1, b);
		d->region[ch] = speed_done(f, sp ? c->kr[ch] : NAN, b);
		if (!d->region[ch]) {
			d->region[ch] = box_done(f, &g->cert, b, ps, known);
			tests++;
		}
		if (d->region[ch] == BOX_DONE)
			continue;
		open = seeds = 0;
		for (k = 0; k < 4; k++) {
			px__st_box_of(g, k, b);
			d->quarter[ch][k] = speed_done(f, sp ? c->kq[4 * ch + k] : NAN, b);
			if (!d->quarter[ch][k]) {
				d->quarter[ch][k] = box_done(f, &t->qcert[4 * ri + k], b, ps, known);
				tests++;
			}
			open += d->quarter[ch][k] != BOX_DONE;
			seeds += d->quarter[ch][k] == BOX_SEEDS;
		}
		/* the quarters' tests first (a few hundred instructions each,
		 * a contraction some thousands); the region's contraction
		 * where they leave seeds or more than one to solve */
		if (!open)
			d->region[ch] = BOX_DONE;
		else if (!(d->region[ch] == BOX_EXACT && (seeds || open > 1)))
			d->region[ch] = BOX_SEEDS;
	}
	return tests;
}

/* 1 when z lies in box b, within Newton's tolerance. */
static int in_box(const struct ssurf *f, const struct crit *z, const double b[4])
{
	double tu = 1e-9 * f->du, tv = 1e-9 * f->dv;
	return z->u >= b[0] - tu && z->u <= b[1] + tu && z->v >= b[2] - tv &&
	       z->v <= b[3] + tv;
}

/*
 * The critical point of box b (certificate rc: contract_rate() holds) at
 * p, into z: x - Y E(x) iterated from the box's centre, each step put
 * back onto the box (clamping does not move a point away from one in the
 * box). If the box holds a point x*, |x_k - x*| <= rho^k (weighted norm,
 * the centre within 1 of anything in the box), so the k-th step
 * |g(x_k) - x_k| is at most (1 + rho) rho^k: a longer one proves the box
 * empty; a short one is the iteration converging, which Newton finishes
 * (within ST_POLISH). Returns CS_FOUND, CS_EMPTY, or CS_OPEN when
 * neither within ST_CONTRACT steps (rho near 1, or a point just outside
 * the box).
 */
int px__st_contract_solve(const struct ssurf *f, const struct rcert *rc,
			  const double b[4], struct crit *z, px_vec3 p,
			  const struct scell *home)
{
	double y[2][2], rho, lim = 1.0, hu = 0.5 * (b[1] - b[0]),
	       hv = 0.5 * (b[3] - b[2]);
	int k, polish = 2;
	if (!contract_rate(rc, p, y, &rho) || px__strack_contract_fault == 2)
		return CS_OPEN;
	z->u = b[0] + hu;
	z->v = b[2] + hv;
	for (k = 0; k < ST_CONTRACT; k++) {
		px_vec3 g, w;
		double du, dv, pu, pv, pad, step, r, u = z->u, v = z->v;
		crit_eval(f, z, p, &g);
		w = px_v3_sub(z->s, p);
		/* E's rounding, as e_pad() */
		pad = ST_PAD *
		      (fabs(w.x) + fabs(w.y) + fabs(w.z) + fabs(p.x) + fabs(p.y) + fabs(p.z)) *
		      (fabs(z->su.x) + fabs(z->su.y) + fabs(z->su.z) + fabs(z->sv.x) +
		       fabs(z->sv.y) + fabs(z->sv.z));
		du = -(y[0][0] * g.x + y[0][1] * g.y);
		dv = -(y[1][0] * g.x + y[1][1] * g.y);
		pu = (fabs(y[0][0]) + fabs(y[0][1])) * pad;
		pv = (fabs(y[1][0]) + fabs(y[1][1])) * pad;
		step = fmax((fabs(du) - pu) / hu, (fabs(dv) - pv) / hv);
		if (step > (1.0 + rho) * (lim + 1e-9))
			return CS_EMPTY;
		/* a posteriori, from any x of the box: |x - x*| <= s / (1 - rho)
		 * with s = |g(x) - x|, so x* = g(x*) lies within rho s / (1 -
		 * rho) of g(x); outside the box there, none in it */
		r = fmax((fabs(du) + pu) / hu, (fabs(dv) + pv) / hv) / (1.0 - rho);
		if (fabs(u + du - (b[0] + hu)) - pu > hu * (1.0 + rho * r) * (1.0 + 1e-9) ||
		    fabs(v + dv - (b[2] + hv)) - pv > hv * (1.0 + rho * r) * (1.0 + 1e-9))
			return CS_EMPTY;
		/* the box's zero, within r of x, on a collapsed edge: the
		 * pole (a candidate of its own), no interior point */
		if (has_pole(f) && px__st_pole_gap(f, u, v) + r * fmax(hu / f->du, hv / f->dv) < 1e-9)
			return CS_EMPTY;
		if (fabs(du) <= ST_POLISH * hu && fabs(dv) <= ST_POLISH * hv && polish > 0) {
			/* twice at most: where Newton converges just outside the
			 * box, the iteration's growing bound proves it empty */
			polish--;
			if (!px__st_snewton(f, z, p, hu, hv, home) && in_box(f, z, b))
				return CS_FOUND;
			z->u = u;
			z->v = v;
		}
		z->u = fmin(fmax(u + du, b[0]), b[1]);
		z->v = fmin(fmax(v + dv, b[2]), b[3]);
		lim *= rho;
	}
	return CS_OPEN;
}

/* Newton from (u, v) of cell c at ps, or (rc not NULL) contract_solve()
 * of box b with certificate rc, the root followed to p and added.
 * Returns 0, 1 (contract_solve() undecided) or PX_E_NOSPC. */
static int seed_solve(struct px_strack *t, struct ssurf *f, const struct scell *c,
		      double u, double v, px_vec3 ps, px_vec3 p,
		      const struct rcert *rc, const double b[4])
{
	struct crit z, last;
	int rc_;
	memset(&z, 0, sizeof(z));
	z.u = u;
	z.v = v;
	if (rc) {
		rc_ = px__st_contract_solve(f, rc, b, &z, ps, c);
		t->st.exact_solves++;
		t->st.exact_open += rc_ == CS_OPEN;
		if (rc_ != CS_FOUND)
			return rc_ == CS_OPEN;
	} else {
		t->st.seed_runs++;
		if (px__st_snewton(f, &z, ps, 0.5 * (c->u1 - c->u0), 0.5 * (c->v1 - c->v0), c))
			return 0;
	}
	if (px_v3_dist2(ps, p) != 0.0 &&
	    px__st_follow(f, &z, ps, px_v3_sub(p, ps), p, &last))
		return 0;
	if (t->fault_drop && t->pend_on && z.type == 1) {
		/* the fault: the point is lost, the step's finding it is
		 * not (as when a pair's other member is found) */
		t->ix_on = 1;
		return 0;
	}
	rc_ = px__st_crit_add(t, f, &z);
	if (rc_ < 0)
		return PX_E_NOSPC;
	/* a point found: the set's membership changed */
	t->ix_on |= rc_;
	return 0;
}

/*
 * The work of cell c's solve (done: cell_done() at the seed point): a
 * region or quarter proven to hold at most one point has its centre,
 * solved by contract_solve() (sk: 5 ch for region ch, 5 ch + 1 + k for
 * its quarter k); a quarter left open is cut into sub-boxes with
 * certificates of their own (sub_solve(); sk: ST_SK_SUB plus its number
 * as before). Puts up to 16 of them in sk; returns their count.
 */
#define ST_SK_SUB 32
int px__st_cell_seeds(const struct cell_done *done, int *sk)
{
	int ch, k, ns = 0;
	for (ch = 0; ch < 4; ch++) {
		const int *qe = done->quarter[ch];
		if (done->region[ch] == BOX_DONE)
			continue;
		if (done->region[ch] == BOX_EXACT) {
			sk[ns++] = 5 * ch;
			continue;
		}
		for (k = 0; k < 4; k++) {
			if (qe[k] == BOX_DONE)
				continue;
			sk[ns++] = (qe[k] == BOX_EXACT ? 0 : ST_SK_SUB) + 5 * ch + 1 + k;
		}
	}
	return ns;
}

/* The units of a solve running ns seeds: 1 for the checks, rounded up
 * to ST_UNITS for a full one. */
static int solve_units(const struct px_strack *t, int ns)
{
	return 1 + (ns * (ST_UNITS - 1) + t->full_seeds - 1) / t->full_seeds;
}

/* ------------------------------------------------------------------ */
/* run-time subdivision of the boxes the setup certificates leave open */

/* Test hook (track_hooks.h): 1 leaves every open box uncut (Newton from
 * its centre, as before the cuts). */
#ifdef PX_TEST_HOOKS
int px__strack_sub_fault = 0;
#endif

/* Levels of sub-boxes below a region's quarter (or a box whose
 * contraction stayed undecided): 4 + 16 certificates at most each. */
#define ST_SUB_DEPTH 2

/* Quarter k of box b into q (k & 1: upper half in u, k & 2: in v). */
void px__st_box_quarter(const double b[4], int k, double q[4])
{
	double um = 0.5 * (b[0] + b[1]), vm = 0.5 * (b[2] + b[3]);
	q[0] = (k & 1) ? um : b[0];
	q[1] = (k & 1) ? b[1] : um;
	q[2] = (k & 2) ? vm : b[2];
	q[3] = (k & 2) ? b[3] : vm;
}

static int seed_solve(struct px_strack *t, struct ssurf *f, const struct scell *c,
		      double u, double v, px_vec3 ps, px_vec3 p,
		      const struct rcert *rc, const double b[4]);

/* The work of a solve in sixteenths of a seed's run: a certificate
 * made at update time (taylor_cert()) and its tests cost about 3/16 of
 * one (measured on the 16-patch bench surface: 3,500 instructions,
 * against 17,000 for a seed's Newton run with the following of its
 * root). */
#define ST_SUB_CERT 3
#define ST_SUB_SEED 16

/*
 * Box b of cell c, left open by the certificates it has (setup's, top,
 * or a contraction that stayed undecided), at ps (roots followed to p):
 * its quarters get certificates of their own (taylor_cert() from top's
 * third-derivative bounds; about half as wide) and are each done
 * (proven empty, or holding a held point and no other), solved exactly
 * (contract_solve()) or cut again, down to ST_SUB_DEPTH levels below
 * the box; a piece still open there, or where the solve's allowance
 * (t->sub_left) has no room for another cut, gets Newton from its
 * centre. t->sub_work holds the work made or reserved:
 * every open piece holds one seed's worth (the box's own is in it when
 * this is called), a cut reserves its four certificates and a seed for
 * each quarter and gives back what a quarter proven done does not use.
 * The held set counts where it is at ps. Returns 0 or PX_E_NOSPC.
 */
static int sub_solve(struct px_strack *t, struct ssurf *f, const struct scell *c,
		     const struct rcert *top, const double b[4], int depth, px_vec3 ps,
		     px_vec3 p, int top_id, int k1)
{
	int known = px_v3_dist2(ps, p) == 0.0, k, r,
	    cut = 4 * ST_SUB_CERT + 3 * ST_SUB_SEED;
	if (depth > ST_SUB_DEPTH || t->sub_work + cut > t->sub_left ||
	    px__strack_sub_fault) {
		t->st.sub_open++;
		return seed_solve(t, f, c, 0.5 * (b[0] + b[1]), 0.5 * (b[2] + b[3]), ps, p,
				  NULL, b);
	}
	t->sub_work += cut;
	for (k = 0; k < 4; k++) {
		struct rcert own, *rcp = &own;
		double sb[4];
		int w;
		px__st_box_quarter(b, k, sb);
		if (t->scache_n > 0 && top_id >= 0 && depth <= 2) {
			/* (two levels a slot: ST_SUB_DEPTH's) */
			/* made before (the point does not enter a certificate) */
			const int key = 4 * top_id + (depth == 1 ? k : k1),
				  slot = depth == 1 ? 0 : 1 + k;
			struct scache *e = &t->scache[key & (t->scache_n - 1)];
			if (e->key != key) {
				e->key = key;
				e->filled = 0;
			}
			rcp = &e->rc[slot];
			if (!(e->filled & (1u << slot))) {
				px__st_taylor_cert(f, sb, top, rcp);
				e->filled |= 1u << slot;
			}
		} else
			px__st_taylor_cert(f, sb, top, rcp);
		t->st.sub_boxes++;
		w = box_done(f, rcp, sb, ps, known);
		if (w == BOX_DONE) {
			t->sub_work -= ST_SUB_SEED;
			continue;
		}
		/* a contraction takes the piece's seed; undecided (rare:
		 * none in the tests), the piece goes on as an open one */
		r = w == BOX_EXACT ? seed_solve(t, f, c, 0.0, 0.0, ps, p, rcp, sb) : 1;
		if (r == 1)
			r = sub_solve(t, f, c, top, sb, depth + 1, ps, p, top_id,
				      depth == 1 ? k : k1);
		if (r < 0)
			return r;
	}
	return 0;
}

/* The ns items of cell_seeds() for cell c at ps, each root found then
 * followed from ps to p (a pair born where the path met the cell's
 * region keeps moving for the rest of the step, possibly out of the
 * cell); t->sub_work the subdivisions' work. Returns 0 or PX_E_NOSPC. */
static int seeds_run(struct px_strack *t, const struct scell *c, px_vec3 ps,
		     px_vec3 p, const int *sk, int ns)
{
	struct ssurf *f = &t->sf[c->surf];
	int i, rc;
	t->st.cell_solves++;
	/* every item holds one seed's worth; sub_solve() adds its cuts */
	t->sub_work = ns * ST_SUB_SEED;
	for (i = 0; i < ns; i++) {
		int n = sk[i] % ST_SK_SUB, ri = c->child + n / 5, q = n % 5 - 1;
		const struct rcert *xc = q < 0 ? &t->rcell[ri].cert : &t->qcert[4 * ri + q];
		double b[4];
		px__st_box_of(&t->rcell[ri], q, b);
		rc = 1;
		if (sk[i] < ST_SK_SUB)
			rc = seed_solve(t, f, c, 0.0, 0.0, ps, p, xc, b);
		/* open, or its contraction undecided: cut into sub-boxes */
		if (rc == 1)
			rc = sub_solve(t, f, c, xc, b, 1, ps, p, 5 * ri + q + 1, -1);
		if (rc < 0)
			return rc;
	}
	return 0;
}

/* Solve cell c at p from its seeds (cell_seeds()); the held set is at p
 * (every caller), so a region or quarter holding one of its points
 * needs no seeds if it can hold only one. Returns 0 or PX_E_NOSPC. */
static int cell_solve(struct px_strack *t, const struct scell *c, px_vec3 p)
{
	struct cell_done done;
	int sk[ST_SEEDS_MAX];
	cell_done(t, c, p, 1, &done);
	t->sub_left = INT_MAX / 2;
	return seeds_run(t, c, p, p, sk, px__st_cell_seeds(&done, sk));
}

/* Solve c at ps (roots followed to p) if its work fits: *units grows by
 * the cost (solve_units()) unless that passes lim (lim <= 0: no bound).
 * Returns 0 solved, 1 left for later (nothing done), PX_E_NOSPC. */
int px__st_cell_solve_budget(struct px_strack *t, const struct scell *c,
			     px_vec3 ps, px_vec3 p, int *units, int lim)
{
	struct cell_done done;
	int sk[ST_SEEDS_MAX];
	int ns, cost, rc, more, tests = cell_done(t, c, ps, px_v3_dist2(ps, p) == 0.0, &done);
	ns = px__st_cell_seeds(&done, sk);
	/* the checks' unit only where they were made */
	cost = solve_units(t, ns) - (tests == 0);
	if (lim > 0 && *units > 0 && *units + cost > lim)
		return 1;
	*units += cost;
	/* the cuts of open boxes may use what the bound leaves (m more
	 * seeds cost at most ceil(7 m / full_seeds) units more), up to
	 * half a full solve more: a cell's cuts must not take the work of
	 * the other cells of the step (they would wait, the set lagging) */
	more = lim > 0 ? (lim - *units) * t->full_seeds / (ST_UNITS - 1) : INT_MAX / 64;
	if (more > t->full_seeds / 2)
		more = t->full_seeds / 2;
	t->sub_left = ST_SUB_SEED * (ns + more);
	rc = seeds_run(t, c, ps, p, sk, ns);
	/* the sub-boxes' work past the one seed each item was counted as
	 * (bounded: ST_SUB_DEPTH levels) */
	more = (t->sub_work + ST_SUB_SEED - 1) / ST_SUB_SEED - ns;
	if (more > 0)
		*units += solve_units(t, ns + more) - solve_units(t, ns);
	return rc;
}

int px__st_surf_reinit(struct px_strack *t, struct ssurf *f, int si, px_vec3 p)
{
	int c, rc;
	f->nz = 0;
	for (c = 0; c < f->ncu * f->ncv; c++) {
		const struct scell *cl = &t->cell[f->first_cell + c];
		if (cl->surf != si)
			continue;
		rc = cell_solve(t, cl, p);
		if (rc)
			return rc;
	}
	return 0;
}
