/*
 * strack_hooks.c - surface tracker (px_strack.h): the test and bench hooks
 * (track_hooks.h). The layout and the shared declarations are in
 * strack_internal.h.
 */
#include "strack_internal.h"

/* Only in the test build (-DPX_TEST_HOOKS): the shipped library has no
 * way in to switch its proofs off. */
#ifdef PX_TEST_HOOKS

void px__strack_set_drop_fault(struct px_strack *t, int fault)
{
	if (t)
		t->fault_drop = fault;
}

void px__strack_set_clock(struct px_strack *t, int64_t (*fn)(void *), void *ctx)
{
	if (t)
		px__gov_set_clock(&t->gov, fn, ctx);
}

struct px_gov *px__strack_gov(struct px_strack *t)
{
	return t ? &t->gov : NULL;
}

void px__strack_set_hot_fault(struct px_strack *t, int fault)
{
	if (t) {
		t->fault_hot = fault;
		t->hot_s = -1;
	}
}

/* The region cell of surface s holding (u, v), NULL for bad arguments
 * (the test hooks below). */
static const struct scell *region_at(const struct px_strack *t, int s,
				     double u, double v)
{
	const struct ssurf *f;
	const struct scell *c;
	int ch;
	if (!t || s < 0 || s >= t->n_surf)
		return NULL;
	f = &t->sf[s];
	if (u < f->u0 || u > f->u1 || v < f->v0 || v > f->v1)
		return NULL;
	c = &t->cell[f->first_cell + px__st_cell_of(f, u, v)];
	ch = (u >= 0.5 * (c->u0 + c->u1)) + 2 * (v >= 0.5 * (c->v0 + c->v1));
	return &t->rcell[c->child + ch];
}

double px__strack_cert_radius(const struct px_strack *t, int s, double u,
			      double v, px_vec3 p)
{
	const struct scell *g = region_at(t, s, u, v);
	return g ? region_radius_full(t, (int)(g - t->rcell), p) : -1.0;
}

int px__strack_region(const struct px_strack *t, int s, double u, double v,
		       px_vec3 p, double box[4])
{
	const struct scell *g = region_at(t, s, u, v);
	if (!g)
		return -1;
	px__st_box_of(g, -1, box);
	return region_empty(t, (int)(g - t->rcell), p);
}

int px__strack_one(const struct px_strack *t, int s, double u, double v,
		   px_vec3 p, double box[4])
{
	const struct scell *g = region_at(t, s, u, v);
	int ri, k, m;
	if (!g)
		return -1;
	px__st_box_of(g, -1, box);
	ri = (int)(g - t->rcell);
	m = one_root(&g->cert, p);
	for (k = 0; k < 4; k++)
		m |= one_root(&t->qcert[4 * ri + k], p) << (k + 1);
	return m;
}

int px__strack_contract(const struct px_strack *t, int s, double u, double v,
			px_vec3 p, double box[4], int out[5], double fu[5], double fv[5])
{
	const struct scell *g = region_at(t, s, u, v), *home;
	int ri, k;
	if (!g)
		return -1;
	px__st_box_of(g, -1, box);
	ri = (int)(g - t->rcell);
	home = &t->cell[t->sf[s].first_cell + px__st_cell_of(&t->sf[s], u, v)];
	for (k = -1; k < 4; k++) {
		const struct rcert *c = k < 0 ? &g->cert : &t->qcert[4 * ri + k];
		double y[2][2], rho, b[4];
		struct crit z;
		memset(&z, 0, sizeof(z));
		px__st_box_of(g, k, b);
		out[k + 1] = -1;
		if (!contract_rate(c, p, y, &rho))
			continue;
		out[k + 1] = px__st_contract_solve(&t->sf[s], c, b, &z, p, home);
		fu[k + 1] = z.u;
		fv[k + 1] = z.v;
	}
	return 0;
}

int px__strack_sub(const struct px_strack *t, int s, const double box[4], px_vec3 p,
		   int *regular, double *fu, double *fv)
{
	const struct ssurf *f;
	const struct scell *home, *g;
	const struct rcert *top;
	struct rcert rc;
	struct crit z;
	double mid[3], rad[3], y[2][2], rho, gb[4], qb[4];
	int k, ri;
	if (!t || s < 0 || s >= t->n_surf || !box || !regular || !fu || !fv)
		return -1;
	f = &t->sf[s];
	g = region_at(t, s, 0.5 * (box[0] + box[1]), 0.5 * (box[2] + box[3]));
	if (!g)
		return -1;
	/* the certificate a solve cuts the box from: its quarter's, or
	 * its region's */
	ri = (int)(g - t->rcell);
	px__st_box_of(g, -1, gb);
	if (!(box[0] >= gb[0] && box[1] <= gb[1] && box[2] >= gb[2] && box[3] <= gb[3]))
		return -1;
	top = &g->cert;
	for (k = 0; k < 4; k++) {
		px__st_box_of(g, k, qb);
		if (box[0] >= qb[0] && box[1] <= qb[1] && box[2] >= qb[2] && box[3] <= qb[3])
			top = &t->qcert[4 * ri + k];
	}
	px__st_taylor_cert(f, box, top, &rc);
	home = &t->cell[t->sf[s].first_cell +
			px__st_cell_of(f, 0.5 * (box[0] + box[1]), 0.5 * (box[2] + box[3]))];
	hess_at(&rc, p, mid, rad);
	*regular = px__st_one_root_h(mid, rad);
	if (px__st_no_root_h(&rc, p, mid, rad))
		return 1;
	if (!px__st_contract_h(&rc, mid, rad, y, &rho))
		return 2;
	memset(&z, 0, sizeof(z));
	switch (px__st_contract_solve(f, &rc, box, &z, p, home)) {
	case CS_FOUND:
		*fu = z.u;
		*fv = z.v;
		return 0;
	case CS_EMPTY:
		return 1;
	default:
		return 2;
	}
}

int px__strack_winding(const struct px_strack *t, int s, px_vec3 p, int *w)
{
	if (!t || s < 0 || s >= t->n_surf || !w)
		return -1;
	return px__st_winding(t, &t->sf[s], p, w);
}

#endif /* PX_TEST_HOOKS */
