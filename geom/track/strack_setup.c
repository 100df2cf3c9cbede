/*
 * strack_setup.c - surface tracker (px_strack.h): setup and teardown:
 * options, patches, cells, px_strack_create() and px_strack_free(), the
 * getters. The layout and the shared declarations are in strack_internal.h.
 */
#include "strack_internal.h"

#include "dist_internal.h"

int px_strack_critical(const struct px_strack *t, int s, double *u, double *v,
		       int *type, int cap)
{
	const struct ssurf *f;
	int i;
	if (!t || (cap > 0 && (!u || !v || !type)))
		return PX_E_INVAL;
	if (s < 0 || s >= t->n_surf)
		return PX_E_RANGE;
	f = &t->sf[s];
	for (i = 0; i < f->nz && i < cap; i++) {
		struct crit w = f->z[i], last;
		/* a point resting on the hot path, followed to the current
		 * point on a copy (the state stays as the next update
		 * expects it); as it was if that fails */
		if (t->hot_s >= 0 && !(s == t->hot_s && i == t->hot_j) &&
		    px__st_follow(f, &w, t->hot_p, px_v3_sub(t->p, t->hot_p), t->p,
			   &last))
			w = f->z[i];
		u[i] = w.u;
		v[i] = w.v;
		type[i] = w.type;
	}
	return f->nz;
}

void px_strack_get_stats(const struct px_strack *t, struct px_strack_stats *s)
{
	px__tracker_stats_out(s, t ? &t->st : NULL, sizeof(*s), t ? &t->gov : NULL);
}

void px_strack_get_info(const struct px_strack *t, struct px_strack_info *info)
{
	if (!info)
		return;
	memset(info, 0, sizeof(*info));
	if (!t)
		return;
	info->n_surfaces = t->n_surf;
	info->n_curves = t->n_curves;
	info->n_patches = t->n_patches;
	info->n_cells = t->n_cells;
	info->n_edges = t->n_edges;
	info->n_poles = t->n_poles;
	info->n_unbounded = t->n_unbounded;
	info->work = t->work;
}

struct px_dist_model *px_strack_dist_model(struct px_strack *t)
{
	return t ? t->dist : NULL;
}

/* ------------------------------------------------------------------ */
/* setup                                                               */

void px_strack_opts_default(struct px_strack_opts *o)
{
	if (!o)
		return;
	memset(o, 0, sizeof(*o));
	px__tracker_opts_default(&o->shared, 256);
	o->cells_per_span = 3;
	o->seeds = 2;
	o->samples = 6;
	o->max_solves = 4;
	o->max_tests = 32;
}

void px_strack_free(struct px_strack *t)
{
	int i;
	if (!t)
		return;
	px_dist_model_free(t->dist);
	px_track_free(t->ct);
	if (t->sf)
		for (i = 0; i < t->n_surf; i++) {
			free(t->sf[i].mem);
			free(t->sf[i].pt);
			free(t->sf[i].pool);
			free(t->sf[i].pool4);
			free(t->sf[i].pu);
			free(t->sf[i].pv);
			free(t->sf[i].cu);
			free(t->sf[i].cv);
			free(t->sf[i].z);
			free(t->sf[i].tmp);
			free(t->sf[i].wp);
		}
	free(t->sf);
	free(t->cell);
	free(t->rcell);
	free(t->qcert);
	free(t->pcache);
	free(t->scache);
	free(t->edge);
	free(t->pole);
	free(t->ex);
	free(t->gdue);
	free(t->cube);
	free(t->popped);
	free(t->hits);
	free(t->pend);
	free(t->pend_ps);
	free(t->pend_kind);
	free(t->ring_list);
	free(t->pend_need);
	free(t->cbox);
	free(t);
}

/* Copy a surface into owned memory. */
static int surf_copy(struct ssurf *f, const struct px_nurbs_surf *s)
{
	size_t nu = (size_t)s->n_knots[0], nv = (size_t)s->n_knots[1];
	size_t np = 4 * (size_t)s->n_ctrl[0] * (size_t)s->n_ctrl[1];
	f->mem = malloc((nu + nv + np) * sizeof(double));
	if (!f->mem)
		return PX_E_NOMEM;
	memcpy(f->mem, s->knots[0], nu * sizeof(double));
	memcpy(f->mem + nu, s->knots[1], nv * sizeof(double));
	memcpy(f->mem + nu + nv, s->pw, np * sizeof(double));
	f->s = *s;
	f->s.knots[0] = f->mem;
	f->s.knots[1] = f->mem + nu;
	f->s.pw = f->mem + nu + nv;
	return PX_OK;
}

/*
 * Cells per span along u (ncs_u, one per patch column) and v. A rational
 * patch's derivative enclosures widen with the spread of its weights
 * (the quotient rule over a cell where W changes by a factor: the
 * bench's sheet with weights 0.6-1.5 had S_uu enclosed in [-130, 11]
 * over a cell), and with them the certificates' radii fall to nothing;
 * halving the cells narrows them about fourfold. So a span whose patches
 * have weights more than ST_WRATIO_FINE apart gets twice the cells (at
 * most 16): on such a sheet small steps then cost less, their worst
 * updates too (larger steps cross cells either way); the setup and
 * memory of those cells grow fourfold. Polynomial patches and
 * circular arcs (weights 1 and 0.71) keep cells_per_span.
 */
#define ST_WRATIO_FINE 1.5

#ifdef PX_TEST_HOOKS
int px__strack_coarse = 0;
#endif

static void span_cells(const struct ssurf *f, int cps, int *ncs_u, int *ncs_v)
{
	int a, b, fine = 2 * cps > 16 ? 16 : 2 * cps;
	for (a = 0; a < f->npu; a++)
		ncs_u[a] = cps;
	for (b = 0; b < f->npv; b++)
		ncs_v[b] = cps;
	for (b = 0; b < f->npv; b++)
		for (a = 0; a < f->npu; a++)
			if (f->pt[b * f->npu + a].wratio > ST_WRATIO_FINE &&
			    !px__strack_coarse) {
				ncs_u[a] = fine;
				ncs_v[b] = fine;
			}
}

/* Cell bounds: each span [b[k], b[k + 1]] cut in ncs[k] equal parts. */
static void span_bounds_fill(double *cb, const double *b, int nb, const int *ncs)
{
	int k, j, n = 0;
	for (k = 0; k < nb - 1; k++)
		for (j = 0; j < ncs[k]; j++)
			cb[n++] = b[k] + (b[k + 1] - b[k]) * j / ncs[k];
}

/* Power-form Bezier patches of a surface between the bounds ub x vb. */
static int build_patches(struct ssurf *f, const double *ub, int nu,
			 const double *vb, int nv)
{
	int p = f->s.degree[0], q = f->s.degree[1], np = (p + 1) * (q + 1);
	int a, b, i, j, k, r;
	size_t wl = PX_NURBS_SURF_WORK_LEN(p, q, f->s.n_ctrl[0], f->s.n_ctrl[1]);
	double *work = malloc(wl * sizeof(double)), tmp[PX_NURBS_MAX_DEGREE + 1];
	f->npu = nu - 1;
	f->npv = nv - 1;
	f->pt = calloc((size_t)(f->npu * f->npv), sizeof(*f->pt));
	f->pool = calloc((size_t)(f->npu * f->npv) * 4 * (size_t)np, sizeof(double));
	f->pool4 = NULL;
	if (p == 3 && q == 3 && px__st_have_fma()) {
		/* 512 bytes a patch: a multiple of the alignment */
		f->pool4 = aligned_alloc(64, (size_t)(f->npu * f->npv) * 64 * sizeof(double));
		if (!f->pool4) {
			free(work);
			return PX_E_NOMEM;
		}
	}
	f->pu = malloc((size_t)nu * sizeof(double));
	f->pv = malloc((size_t)nv * sizeof(double));
	if (!work || !f->pt || !f->pool || !f->pu || !f->pv) {
		free(work);
		return PX_E_NOMEM;
	}
	memcpy(f->pu, ub, (size_t)nu * sizeof(double));
	memcpy(f->pv, vb, (size_t)nv * sizeof(double));
	/* the fault: a thousand times as long, on any Hessian and weights */
	f->quick_loose = px__strack_quick_fault;
	f->quick_u = (f->quick_loose ? 1e3 : 1.0) * ST_QUICK * f->du / f->npu;
	f->quick_v = (f->quick_loose ? 1e3 : 1.0) * ST_QUICK * f->dv / f->npv;
	for (b = 0; b < f->npv; b++)
		for (a = 0; a < f->npu; a++) {
			struct patch *pt = &f->pt[b * f->npu + a];
			struct px_nurbs_surf sub;
			double pt_w;
			double *c = f->pool + (size_t)(b * f->npu + a) * 4 * (size_t)np;
			int rc = px_nurbs_surf_extract_work(&f->s, ub[a], ub[a + 1], vb[b],
							    vb[b + 1], work, wl, &sub);
			if (rc || sub.n_ctrl[0] != p + 1 || sub.n_ctrl[1] != q + 1) {
				free(work);
				return rc ? rc : PX_E_INVAL;
			}
			pt->u0 = ub[a];
			pt->u1 = ub[a + 1];
			pt->v0 = vb[b];
			pt->v1 = vb[b + 1];
			pt->iu = 1.0 / (pt->u1 - pt->u0);
			pt->iv = 1.0 / (pt->v1 - pt->v0);
			pt->p = p;
			pt->q = q;
			pt->c = c;
			{
				/* equal weights: divide them out, evaluate as a
				 * polynomial */
				double w0 = sub.pw[3], wlo = w0, whi = w0;
				int m;
				pt->rat = 0;
				for (m = 0; m < np; m++) {
					double w = sub.pw[4 * m + 3];
					if (w != w0)
						pt->rat = 1;
					wlo = w < wlo ? w : wlo;
					whi = w > whi ? w : whi;
				}
				pt->wratio = whi / wlo;
				pt_w = pt->rat ? 1.0 : w0;
				if (pt->wratio > ST_QUICK_WRATIO && !f->quick_loose)
					f->quick_u = f->quick_v = 0.0;
			}
			for (k = 0; k < 4; k++) {
				double *ck = c + k * np;
				for (j = 0; j <= q; j++)
					for (i = 0; i <= p; i++)
						ck[j * (p + 1) + i] =
							k == 3 && !pt->rat ? 1.0
									   : sub.pw[4 * (j * (p + 1) + i) + k] / pt_w;
				/* Bernstein to power form along s, then along t */
				for (j = 0; j <= q; j++) {
					double *row = ck + j * (p + 1);
					for (i = 0; i <= p; i++) {
						double v = 0.0;
						for (r = 0; r <= i; r++)
							v += (((i - r) & 1) ? -1.0 : 1.0) *
							     px_bern_binom(i, r) * row[r];
						tmp[i] = px_bern_binom(p, i) * v;
					}
					memcpy(row, tmp, (size_t)(p + 1) * sizeof(double));
				}
				for (i = 0; i <= p; i++) {
					for (j = 0; j <= q; j++) {
						double v = 0.0;
						for (r = 0; r <= j; r++)
							v += (((j - r) & 1) ? -1.0 : 1.0) *
							     px_bern_binom(j, r) * ck[r * (p + 1) + i];
						tmp[j] = px_bern_binom(q, j) * v;
					}
					for (j = 0; j <= q; j++)
						ck[j * (p + 1) + i] = tmp[j];
				}
			}
			pt->c4 = NULL;
			if (f->pool4) {
				double *c4 = f->pool4 + (size_t)(b * f->npu + a) * 64;
				for (k = 0; k < 4; k++)
					for (i = 0; i < 16; i++)
						c4[4 * i + k] = c[k * 16 + i];
				pt->c4 = c4;
			}
		}
	free(work);
	return PX_OK;
}

/* The options (opts, or the defaults without) into o and whether
 * px_strack_create() accepts them and the surfaces: PX_OK, PX_E_INVAL or
 * PX_E_RANGE (degree); *max_knots the most knots of a surface in one
 * direction. */
static int create_check(const struct px_nurbs_surf *surfs, int n_surfs,
			const struct px_strack_opts *opts,
			struct px_strack_opts *o, int *max_knots)
{
	int i, k;
	if (opts)
		*o = *opts;
	else
		px_strack_opts_default(o);
	if (!px__tracker_opts_valid(&o->shared) || o->cells_per_span < 1 ||
	    o->cells_per_span > 16 || o->seeds < 1 || o->seeds > 8 ||
	    o->samples < 2 || o->samples > 32 || o->max_solves < 0 ||
	    o->max_tests < 0)
		return PX_E_INVAL;
	*max_knots = 0;
	for (i = 0; i < n_surfs; i++) {
		if (surfs[i].degree[0] < 1 || surfs[i].degree[1] < 1 ||
		    surfs[i].degree[0] > PX_NURBS_MAX_DEGREE ||
		    surfs[i].degree[1] > PX_NURBS_MAX_DEGREE)
			return PX_E_RANGE;
		if (!surfs[i].knots[0] || !surfs[i].knots[1] || !surfs[i].pw)
			return PX_E_INVAL;
		for (k = 0; k < 2; k++)
			if (surfs[i].n_knots[k] > *max_knots)
				*max_knots = surfs[i].n_knots[k];
	}
	return PX_OK;
}

/* Surface i: its copy, domain, seams, patches and the bounds of its
 * cells (ub, vb, ncs_u, ncs_v: scratch for max_knots + 2 entries); its
 * cells are numbered from *cell_cap on, which grows by their count. */
static int surf_setup(struct px_strack *t, int i, const struct px_nurbs_surf *s,
		      double *ub, double *vb, int *ncs_u, int *ncs_v,
		      int *cell_cap)
{
	struct ssurf *f = &t->sf[i];
	px_aabb hb = px_nurbs_surf_aabb(s);
	double tol = 1e-12 * (1.0 + px_aabb_diagonal(&hb));
	int nu, nv, k, rc = surf_copy(f, s);
	if (rc)
		return rc;
	px_nurbs_surf_domain(&f->s, &f->u0, &f->u1, &f->v0, &f->v1);
	f->du = f->u1 - f->u0;
	f->dv = f->v1 - f->v0;
	f->wrap_u = px_nurbs_surf_seam(&f->s, 0, tol, 1e-9) >= 1;
	f->wrap_v = px_nurbs_surf_seam(&f->s, 1, tol, 1e-9) >= 1;
	nu = px__st_span_bounds(&f->s, 0, f->u0, f->u1, ub);
	nv = px__st_span_bounds(&f->s, 1, f->v0, f->v1, vb);
	t->n_patches += (nu - 1) * (nv - 1);
	rc = build_patches(f, ub, nu, vb, nv);
	if (rc)
		return rc;
	span_cells(f, t->opts.cells_per_span, ncs_u, ncs_v);
	for (f->ncu = 0, k = 0; k < nu - 1; k++)
		f->ncu += ncs_u[k];
	for (f->ncv = 0, k = 0; k < nv - 1; k++)
		f->ncv += ncs_v[k];
	f->cu = calloc((size_t)f->ncu + 1, sizeof(double));
	f->cv = calloc((size_t)f->ncv + 1, sizeof(double));
	f->cap = t->opts.max_crit;
	f->z = calloc((size_t)f->cap, sizeof(*f->z));
	f->tmp = calloc((size_t)f->cap, sizeof(*f->tmp));
	if (!f->cu || !f->cv || !f->z || !f->tmp)
		return PX_E_NOMEM;
	span_bounds_fill(f->cu, ub, nu, ncs_u);
	f->cu[f->ncu] = f->u1;
	span_bounds_fill(f->cv, vb, nv, ncs_v);
	f->cv[f->ncv] = f->v1;
	f->first_cell = *cell_cap;
	*cell_cap += f->ncu * f->ncv;
	return PX_OK;
}

/* Every surface set up (surf_setup()); *bounds of the whole model (the
 * curves' too), *cell_cap the cells of all surfaces. */
static int surfs_setup(struct px_strack *t, const struct px_nurbs_curve *curves,
		       int n_curves, const struct px_nurbs_surf *surfs,
		       int max_knots, px_aabb *bounds, int *cell_cap)
{
	double *ub = calloc((size_t)max_knots + 2, sizeof(double));
	double *vb = calloc((size_t)max_knots + 2, sizeof(double));
	int *ncs_u = calloc((size_t)max_knots + 2, sizeof(int));
	int *ncs_v = calloc((size_t)max_knots + 2, sizeof(int));
	int i, rc = PX_OK;
	t->sf = calloc((size_t)t->n_surf, sizeof(*t->sf));
	if (!t->sf || !ub || !vb || !ncs_u || !ncs_v)
		rc = PX_E_NOMEM;
	*bounds = px_aabb_empty();
	*cell_cap = 0;
	for (i = 0; i < n_curves; i++) {
		px_aabb hb = px_nurbs_curve_aabb(&curves[i]);
		*bounds = px_aabb_union(bounds, &hb);
	}
	for (i = 0; i < t->n_surf && rc == PX_OK; i++) {
		px_aabb hb = px_nurbs_surf_aabb(&surfs[i]);
		*bounds = px_aabb_union(bounds, &hb);
		rc = surf_setup(t, i, &surfs[i], ub, vb, ncs_u, ncs_v, cell_cap);
	}
	free(ub);
	free(vb);
	free(ncs_u);
	free(ncs_v);
	return rc;
}

/* The per-cell arrays for cell_cap cells. */
static int cells_alloc(struct px_strack *t, int cell_cap)
{
	/* pending items: each cell once, a crossing solve a hit, ST_RINGS
	 * bounds a surface */
	size_t npend = (2 + ST_RINGS) * (size_t)cell_cap + 2;
	t->cell = calloc((size_t)cell_cap + 1, sizeof(*t->cell));
	t->rcell = calloc(4 * (size_t)cell_cap + 1, sizeof(*t->rcell));
	t->qcert = calloc(16 * (size_t)cell_cap + 1, sizeof(*t->qcert));
	t->ex = calloc((size_t)cell_cap + 1, sizeof(*t->ex));
	t->gdue = calloc((size_t)cell_cap / ST_GROUP + 2, sizeof(*t->gdue));
	t->cube = calloc((size_t)cell_cap + 1, sizeof(*t->cube));
	t->popped = calloc((size_t)cell_cap + 1, sizeof(int));
	t->hits = calloc((size_t)cell_cap + 1, sizeof(int));
	t->pend = calloc(npend, sizeof(int));
	t->pend_ps = calloc(npend, sizeof(px_vec3));
	t->pend_need = calloc(npend, sizeof(double));
	t->pend_kind = calloc(npend, 1);
	t->ring_list = calloc((size_t)cell_cap + 1, sizeof(int));
	if (!t->cell || !t->rcell || !t->qcert || !t->ex || !t->gdue ||
	    !t->cube || !t->popped || !t->hits || !t->pend || !t->pend_ps ||
	    !t->pend_kind || !t->pend_need || !t->ring_list)
		return PX_E_NOMEM;
	return PX_OK;
}

/* Cell ci of surface i (cell k along u, j along v): its bounds and its
 * four region cells with their certificates (work: wl doubles). */
static int cell_setup(struct px_strack *t, int i, int ci, int k, int j,
		      double *work, size_t wl)
{
	const struct ssurf *f = &t->sf[i];
	struct scell *c = &t->cell[ci];
	double um, vm;
	px_aabb cb = px_aabb_empty();
	int ch, rc;
	c->surf = i;
	c->u0 = f->cu[k];
	c->u1 = f->cu[k + 1];
	c->v0 = f->cv[j];
	c->v1 = f->cv[j + 1];
	um = 0.5 * (c->u0 + c->u1);
	vm = 0.5 * (c->v0 + c->v1);
	c->child = 4 * ci;
	for (ch = 0; ch < 4; ch++) {
		struct scell *rg = &t->rcell[c->child + ch];
		int open[4];
		px_aabb rb;
		rg->surf = i;
		rg->u0 = ch & 1 ? um : c->u0;
		rg->u1 = ch & 1 ? c->u1 : um;
		rg->v0 = ch & 2 ? vm : c->v0;
		rg->v1 = ch & 2 ? c->v1 : vm;
		px__st_sides_open(f, rg, open);
		if ((rg->u0 == f->u0 && f->pole[0]) ||
		    (rg->u1 == f->u1 && f->pole[1]) ||
		    (rg->v0 == f->v0 && f->pole[2]) ||
		    (rg->v1 == f->v1 && f->pole[3]))
			c->always = 1;
		rc = px__st_cell_cert(t, rg, f, work, wl, open);
		if (rc)
			return rc;
		rc = px__st_quarter_certs(t, rg, f, work, wl,
					  &t->qcert[4 * (c->child + ch)]);
		if (rc)
			return rc;
		rb.min = px_v3(rg->cert.S[0].lo, rg->cert.S[1].lo, rg->cert.S[2].lo);
		rb.max = px_v3(rg->cert.S[0].hi, rg->cert.S[1].hi, rg->cert.S[2].hi);
		cb = px_aabb_union(&cb, &rb);
	}
	c->size = px_aabb_diagonal(&cb);
	t->n_unbounded += c->always;
	return PX_OK;
}

/* Every surface's poles as far as the certificates need them and its
 * cells (cell_setup()). */
static int cells_setup(struct px_strack *t)
{
	size_t wl = 0;
	double *work;
	int i, j, k, rc = PX_OK;
	for (i = 0; i < t->n_surf; i++) {
		const struct px_nurbs_surf *sf = &t->sf[i].s;
		size_t l = PX_NURBS_SURF_WORK_LEN(sf->degree[0], sf->degree[1],
						  sf->n_ctrl[0], sf->n_ctrl[1]);
		if (l > wl)
			wl = l;
	}
	work = malloc(wl * sizeof(double));
	if (!work)
		return PX_E_NOMEM;
	for (i = 0; i < t->n_surf && rc == PX_OK; i++) {
		struct ssurf *f = &t->sf[i];
		for (k = 0; k < 4; k++)
			/* as for the poles (edges_setup()) */
			f->pole[k] = !((k < 2 && f->wrap_u) || (k >= 2 && f->wrap_v)) &&
				     px_nurbs_surf_edge_collapsed(&f->s, k,
								  1e-12 * (1.0 + t->scale));
		for (j = 0; j < f->ncv && rc == PX_OK; j++)
			for (k = 0; k < f->ncu && rc == PX_OK; k++)
				rc = cell_setup(t, i, f->first_cell + j * f->ncu + k,
						k, j, work, wl);
	}
	free(work);
	return rc;
}

/* The curves of the curve tracker: the free curves, then the open
 * (uncollapsed) edges and C0 creases of the surfaces as iso-curves;
 * cpw[e] owns the control points of edge e. */
struct edge_set {
	struct px_nurbs_curve *cc;
	double **cpw;
	int n_cc, cap;
};

/* The iso-curve of surface i at parameter tv in direction dir (the
 * other held) as the next edge. */
static int edge_add(struct px_strack *t, struct edge_set *es, int i, int dir,
		    double tv)
{
	const struct ssurf *f = &t->sf[i];
	size_t len = 4 * (size_t)f->s.n_ctrl[dir];
	struct edge *ed = &t->edge[t->n_edges];
	int rc;
	es->cpw[t->n_edges] = malloc(len * sizeof(double));
	if (!es->cpw[t->n_edges])
		return PX_E_NOMEM;
	rc = px_nurbs_surf_iso_curve(&f->s, dir, tv, es->cpw[t->n_edges], len,
				     &es->cc[es->n_cc]);
	if (rc) {
		free(es->cpw[t->n_edges]);
		es->cpw[t->n_edges] = NULL;
		return rc;
	}
	ed->surf = i;
	ed->dir = dir;
	ed->t = tv;
	t->n_edges++;
	es->n_cc++;
	return PX_OK;
}

/* Surface i's edges: collapsed ones become poles, the others (not at a
 * closed seam) and the C0 creases edges. */
static int surf_edges(struct px_strack *t, struct edge_set *es, int i)
{
	struct ssurf *f = &t->sf[i];
	double tol = 1e-12 * (1.0 + t->scale), brk[64];
	int e, nb, d, k, rc;
	for (e = 0; e < 4; e++) {
		int dir = e < 2 ? 1 : 0; /* curve direction */
		double tv = e == 0 ? f->u0 : e == 1 ? f->u1 : e == 2 ? f->v0 : f->v1;
		if ((e < 2 && f->wrap_u) || (e >= 2 && f->wrap_v))
			continue;
		/* a trimmed surface's boundary is its trimming edges, the
		 * caller's curves (f->pole[] stays: Newton needs it) */
		if (f->dom_in)
			continue;
		if (px_nurbs_surf_edge_collapsed(&f->s, e, tol)) {
			struct pole *pl = &t->pole[t->n_poles++];
			f->pole[e] = 1;
			pl->u = e < 2 ? tv : f->u0;
			pl->v = e < 2 ? f->v0 : tv;
			pl->q = px_nurbs_surf_point(&f->s, pl->u, pl->v);
			pl->surf = i;
			continue;
		}
		rc = edge_add(t, es, i, dir, tv);
		if (rc)
			return rc;
	}
	for (d = 0; d < 2; d++) {
		/* creases across direction d: curves along the other */
		nb = px_nurbs_surf_breaks(&f->s, d, brk, 64);
		for (k = 0; k < nb && k < 64; k++) {
			if (t->n_edges >= es->cap)
				break;
			rc = edge_add(t, es, i, 1 - d, brk[k]);
			if (rc)
				return rc;
		}
	}
	return PX_OK;
}

/* The curve tracker's curves (struct edge_set), the poles. */
static int edges_setup(struct px_strack *t, const struct px_nurbs_curve *curves,
		       int n_curves, int max_knots, struct edge_set *es)
{
	int i, rc;
	es->cap = 0;
	for (i = 0; i < t->n_surf; i++)
		es->cap += 4 + 2 * max_knots;
	t->edge = calloc((size_t)es->cap, sizeof(*t->edge));
	t->pole = calloc((size_t)4 * t->n_surf, sizeof(*t->pole));
	es->cc = calloc((size_t)(n_curves + es->cap), sizeof(*es->cc));
	es->cpw = calloc((size_t)es->cap, sizeof(*es->cpw));
	if (!t->edge || !t->pole || !es->cc || !es->cpw)
		return PX_E_NOMEM;
	for (i = 0; i < n_curves; i++)
		es->cc[es->n_cc++] = curves[i];
	for (i = 0; i < t->n_surf; i++) {
		rc = surf_edges(t, es, i);
		if (rc)
			return rc;
	}
	return PX_OK;
}

/* Boxes of the half spans of the n_cc curves cc (t->cbox), which prove
 * the curve tracker farther than an interior minimum. */
static int curve_boxes(struct px_strack *t, const struct px_nurbs_curve *cc,
		       int n_cc)
{
	double *cw;
	size_t cwl = 0;
	int i, k, nb = 0, rc = PX_OK;
	for (i = 0; i < n_cc; i++) {
		size_t l = PX_NURBS_CURVE_WORK_LEN(cc[i].degree, cc[i].n_ctrl);
		cwl = l > cwl ? l : cwl;
		nb += 2 * cc[i].n_knots;
	}
	t->cbox = calloc((size_t)nb, sizeof(*t->cbox));
	cw = malloc(cwl * sizeof(double));
	if (!t->cbox || !cw) {
		free(cw);
		return PX_E_NOMEM;
	}
	for (i = 0; i < n_cc && rc == PX_OK; i++) {
		const double *U = cc[i].knots;
		int p = cc[i].degree, n = cc[i].n_ctrl, h;
		for (k = p; k < n && rc == PX_OK; k++) {
			if (!(U[k + 1] > U[k]))
				continue;
			for (h = 0; h < 2 && rc == PX_OK; h++) {
				double a = U[k] + 0.5 * h * (U[k + 1] - U[k]);
				double b = h ? U[k + 1] : 0.5 * (U[k] + U[k + 1]);
				px_aabb bx;
				rc = px_nurbs_curve_sub_aabb(&cc[i], a, b, cw, cwl, &bx);
				if (rc == PX_OK)
					/* rounding of evaluated points */
					t->cbox[t->n_cbox++] = px_aabb_inflate(&bx, 1e-12 * t->scale);
			}
		}
	}
	free(cw);
	return rc;
}

/* The curve tracker over the edge set (none when it is empty) and its
 * boxes. */
static int curves_setup(struct px_strack *t, const struct edge_set *es)
{
	struct px_track_opts to;
	int rc;
	if (es->n_cc == 0)
		return PX_OK;
	rc = curve_boxes(t, es->cc, es->n_cc);
	if (rc)
		return rc;
	px_track_opts_default(&to);
	/* the surface tracker decides what is followed; its curve tracker
	 * must always track */
	to.cold_switch = 0;
	to.work = t->work;
	to.dist = t->opts.dist;
	return px_track_create(es->cc, es->n_cc, &to, &t->ct);
}

/* Slots for a cache: a power of two, at least want up to cap. */
static int cache_slots(int want, int cap)
{
	int n = 1;
	while (n < want && n < cap)
		n *= 2;
	return n;
}

/* n cache slots of size bytes, each beginning with its int key: all
 * empty (key -1, nothing filled). */
static void *cache_new(int n, size_t size)
{
	char *c = calloc((size_t)n, size);
	int i;
	for (i = 0; c && i < n; i++)
		*(int *)(void *)(c + (size_t)i * size) = -1;
	return c;
}

/* The certificate caches of the update. */
static int caches_setup(struct px_strack *t)
{
	int i, nrat = 0;
	/* the piece cache where a region is rational: a slot for each
	 * quarter of up to 64 such regions (about 4.4 KiB a slot), fewer
	 * when the model has fewer */
	for (i = 0; i < 4 * t->n_cells; i++)
		nrat += t->rcell[i].cert.rat;
	if (nrat > 0) {
		t->pcache_n = cache_slots(4 * nrat, 256);
		t->pcache = cache_new(t->pcache_n, sizeof(*t->pcache));
		if (!t->pcache)
			return PX_E_NOMEM;
	}
	/* the cut cache: 128 slots (about 5.4 KiB each), fewer for small
	 * models */
	t->scache_n = cache_slots(4 * t->n_cells, 128);
	t->scache = cache_new(t->scache_n, sizeof(*t->scache));
	return t->scache ? PX_OK : PX_E_NOMEM;
}

/* px_strack_create() and px__strack_create_trimmed() (trims NULL: no
 * trimmed surface). */
static int strack_create(const struct px_nurbs_curve *curves, int n_curves,
			 const struct px_nurbs_surf *surfs, int n_surfs,
			 const struct px__dist_trim *trims,
			 int (*in)(const void *ctx, double u, double v),
			 const struct px_strack_opts *opts, struct px_strack **out)
{
	struct px_strack *t;
	struct px_strack_opts o;
	struct edge_set es = {0};
	int rc, i, max_knots, cell_cap;
	px_aabb bounds;

	if (!out || (n_curves > 0 && !curves) || !surfs || n_surfs <= 0 ||
	    n_curves < 0)
		return PX_E_INVAL;
	*out = NULL;
	rc = create_check(surfs, n_surfs, opts, &o, &max_knots);
	if (rc)
		return rc;
	t = calloc(1, sizeof(*t));
	if (!t)
		return PX_E_NOMEM;
	t->opts = o;
	{
		struct cell_done none;
		int sk[ST_SEEDS_MAX];
		memset(&none, 0, sizeof(none));
		t->full_seeds = px__st_cell_seeds(&none, sk);
	}
	t->n_curves = n_curves;
	t->n_surf = n_surfs;
	rc = trims ? px__dist_model_create_trimmed(curves, n_curves, surfs, n_surfs,
						   trims, o.dist, &t->dist)
		   : px_dist_model_create(curves, n_curves, surfs, n_surfs, o.dist,
					  &t->dist);
	if (rc) {
		free(t);
		return rc;
	}
	rc = surfs_setup(t, curves, n_curves, surfs, max_knots, &bounds,
			 &cell_cap);
	if (rc)
		goto fail;
	t->scale = px__tracker_scale(bounds);
	t->work = px__tracker_work(bounds, o.work_margin, t->scale);
	rc = cells_alloc(t, cell_cap);
	if (!rc)
		rc = cells_setup(t);
	if (rc)
		goto fail;
	t->n_cells = cell_cap;
	for (i = 0; trims && i < n_surfs; i++)
		if (trims[i].inside) {
			t->sf[i].dom_in = in;
			t->sf[i].dom = trims[i].ctx;
		}
	for (i = 0; i < n_surfs; i++) {
		rc = px__st_wind_pieces(t, i);
		if (rc)
			goto fail;
	}
	rc = edges_setup(t, curves, n_curves, max_knots, &es);
	if (!rc)
		rc = curves_setup(t, &es);
	if (!rc)
		rc = caches_setup(t);
	if (rc)
		goto fail;
	t->epoch = 1;
	t->hot_s = -1;
	t->ans_s = -1;
	px__gov_setup(&t->gov, o.cold_switch != 0, t->dist, bounds, t->scale);
	*out = t;
	t = NULL;
fail:
	if (es.cpw)
		for (i = 0; i < es.cap; i++)
			free(es.cpw[i]);
	free(es.cpw);
	free(es.cc);
	px_strack_free(t);
	return rc;
}

int px_strack_create(const struct px_nurbs_curve *curves, int n_curves,
		     const struct px_nurbs_surf *surfs, int n_surfs,
		     const struct px_strack_opts *opts, struct px_strack **out)
{
	return strack_create(curves, n_curves, surfs, n_surfs, NULL, NULL, opts,
			     out);
}

int px__strack_create_trimmed(const struct px_nurbs_curve *curves, int n_curves,
			      const struct px_nurbs_surf *surfs, int n_surfs,
			      const struct px__dist_trim *trims,
			      int (*in)(const void *ctx, double u, double v),
			      const struct px_strack_opts *opts,
			      struct px_strack **out)
{
	if (!trims || !in)
		return PX_E_INVAL;
	return strack_create(curves, n_curves, surfs, n_surfs, trims, in, opts,
			     out);
}
