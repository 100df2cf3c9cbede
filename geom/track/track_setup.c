/*
 * track_setup.c - curve tracker (px_track.h): setup and teardown: options,
 * spans and leaves, the per-leaf event boxes, px_track_create() and
 * px_track_free(), the getters. The layout and the shared declarations are
 * in track_internal.h.
 */
#include "track_internal.h"

int px_track_critical(const struct px_track *t, int entity, double *u,
		      int *type, int cap)
{
	const struct ent *e;
	int i;
	if (!t || (cap > 0 && (!u || !type)))
		return PX_E_INVAL;
	if (entity < 0 || entity >= t->n_ent)
		return PX_E_RANGE;
	px__tk_ent_refresh((struct px_track *)t, &t->ent[entity]);
	e = &t->ent[entity];
	for (i = 0; i < e->nz && i < cap; i++) {
		u[i] = e->z[i].u;
		type[i] = e->z[i].type;
	}
	return e->nz;
}

void px_track_get_stats(const struct px_track *t, struct px_track_stats *s)
{
	px__tracker_stats_out(s, t ? &t->st : NULL, sizeof(*s), t ? &t->gov : NULL);
}

void px_track_get_info(const struct px_track *t, struct px_track_info *info)
{
	if (!info)
		return;
	memset(info, 0, sizeof(*info));
	if (!t)
		return;
	info->n_entities = t->n_ent;
	info->n_spans = t->n_spans;
	info->n_leaves = t->n_leaves;
	info->n_boxed_leaves = t->n_boxed;
	info->n_cells = t->n_prim;
	info->n_cusps = t->n_cusps;
	info->n_breaks = t->n_breaks;
	info->work = t->work;
	info->bytes = t->bytes;
}

struct px_dist_model *px_track_dist_model(struct px_track *t)
{
	return t ? t->dist : NULL;
}

/* ------------------------------------------------------------------ */
/* setup                                                               */

void px_track_opts_default(struct px_track_opts *o)
{
	if (!o)
		return;
	memset(o, 0, sizeof(*o));
	px__tracker_opts_default(&o->shared, 64);
	o->work.min = px_v3(1, 1, 1);
	o->work.max = px_v3(-1, -1, -1);
	o->leaves_per_span = 4;
	o->box_depth = 4;
	o->lazy = 1;
}

struct split {
	double u;
	int kind;
};

static double speed_at(const struct px_nurbs_curve *c, double u, int side)
{
	px_vec3 d[2];
	px_nurbs_curve_eval_side(c, u, side, 1, d);
	return px_v3_norm(d[1]);
}

/* Split points of one curve (interior knots with their continuity and
 * interior cusps), sorted, into out (cap). Returns the count. */
static int curve_splits(const struct px_nurbs_curve *c, struct split *out,
			int cap, int *n_cusps)
{
	int p = c->degree, n = c->n_ctrl, i, ns = 0, k;
	double a, b, vmax = 0.0;
	const double *U = c->knots;

	px_nurbs_curve_domain(c, &a, &b);
	for (i = p + 1; i < n; i++) {
		int m = 1;
		if (U[i] <= a || U[i] >= b || U[i] == U[i - 1])
			continue;
		while (i + m < n + p + 1 && U[i + m] == U[i])
			m++;
		if (ns < cap) {
			out[ns].u = U[i];
			out[ns].kind = m >= p ? K_C0 : (m == p - 1 ? K_C1 : K_SMOOTH);
			ns++;
		}
	}
	/* speed scale */
	for (k = 0; k <= ns; k++) {
		double s0 = k == 0 ? a : out[k - 1].u, s1 = k == ns ? b : out[k].u;
		for (i = 0; i <= 32; i++)
			vmax = fmax(vmax, speed_at(c, s0 + (s1 - s0) * i / 32.0,
						   i == 32 ? -1 : 1));
	}
	/* cusps: speed (almost) vanishing, at knots or inside spans */
	{
		int nsp = ns;
		for (k = 0; k <= nsp; k++) {
			double s0 = k == 0 ? a : out[k - 1].u,
			       s1 = k == nsp ? b : out[k].u, sp[33];
			for (i = 0; i <= 32; i++)
				sp[i] = speed_at(c, s0 + (s1 - s0) * i / 32.0,
						 i == 32 ? -1 : 1);
			if (k < nsp && (sp[32] <= 1e-7 * vmax ||
					speed_at(c, s1, 1) <= 1e-7 * vmax))
				out[k].kind = K_CUSP;
			for (i = 1; i < 32; i++) {
				double lo, hi, x1, x2, g = 0.6180339887498949;
				int it;
				if (!(sp[i] <= sp[i - 1] && sp[i] <= sp[i + 1] &&
				      sp[i] <= 1e-3 * vmax))
					continue;
				lo = s0 + (s1 - s0) * (i - 1) / 32.0;
				hi = s0 + (s1 - s0) * (i + 1) / 32.0;
				for (it = 0; it < 100; it++) {
					x1 = hi - g * (hi - lo);
					x2 = lo + g * (hi - lo);
					if (speed_at(c, x1, 1) < speed_at(c, x2, 1))
						hi = x2;
					else
						lo = x1;
				}
				x1 = 0.5 * (lo + hi);
				if (speed_at(c, x1, 1) <= 1e-7 * vmax &&
				    x1 > s0 + 1e-9 * (s1 - s0) &&
				    x1 < s1 - 1e-9 * (s1 - s0) && ns < cap) {
					out[ns].u = x1;
					out[ns].kind = K_CUSP;
					ns++;
				}
			}
		}
		/* sort */
		for (i = 1; i < ns; i++) {
			struct split s = out[i];
			for (k = i; k > 0 && out[k - 1].u > s.u; k--)
				out[k] = out[k - 1];
			out[k] = s;
		}
	}
	for (i = 0; i < ns; i++)
		if (out[i].kind == K_CUSP)
			(*n_cusps)++;
	return ns;
}

/* Bernstein g (a, b[3]) of a span's Bezier net hb[4][p+1]; degree 3p-1. */
static void span_g(int p, double hb[4][TRK_MAXD + 1], double *a,
		   double b[3][TRK_NG])
{
	double hd[4][TRK_MAXD + 1], k[3][2 * TRK_MAXD];
	double t1[PX_BERN_MAX_DEGREE + 1], t2[PX_BERN_MAX_DEGREE + 1];
	int c, j, n = 3 * p - 1;
	for (c = 0; c < 4; c++)
		px_bern_deriv(hb[c], p, hd[c]);
	for (c = 0; c < 3; c++) {
		px_bern_mul(hd[c], p - 1, hb[3], p, t1);
		px_bern_mul(hb[c], p, hd[3], p - 1, t2);
		for (j = 0; j < 2 * p; j++)
			k[c][j] = t1[j] - t2[j];
	}
	for (j = 0; j <= n; j++)
		a[j] = 0.0;
	for (c = 0; c < 3; c++) {
		px_bern_mul(hb[c], p, k[c], 2 * p - 1, t1);
		for (j = 0; j <= n; j++)
			a[j] += t1[j];
		px_bern_mul(hb[3], p, k[c], 2 * p - 1, b[c]);
	}
}

/* Octree exclusion: can the leaf have an event for some p in the cell? */
static int cell_range(const double *a, int m, px_vec3 c, px_vec3 r, int i,
		      double tol, double *lo, double *hi)
{
	const double *bx = a + m, *by = bx + m, *bz = by + m;
	double v = a[i] - (c.x * bx[i] + c.y * by[i] + c.z * bz[i]);
	double e = fabs(bx[i]) * r.x + fabs(by[i]) * r.y + fabs(bz[i]) * r.z;
	*lo = v - e - tol;
	*hi = v + e + tol;
	return 0;
}

static int cell_definite(const double *a, int m, px_vec3 c, px_vec3 r,
			 double tol)
{
	int i, pos = 0, neg = 0;
	for (i = 0; i < m; i++) {
		double lo, hi;
		cell_range(a, m, c, r, i, tol, &lo, &hi);
		if (lo > 0.0)
			pos++;
		else if (hi < 0.0)
			neg++;
		else
			return 0;
		if (pos && neg)
			return 0;
	}
	return 1;
}

static int cell_event(const struct px_track *t, const struct leaf *l,
		      px_vec3 c, px_vec3 r)
{
	const double *a = leaf_a(t, l);
	int n = l->n, i;
	if (cell_definite(a, n + 1, c, r, l->tol_g))
		return 0;
	for (i = 0; i < 2; i++) {
		double lo, hi;
		if (!(l->flags & (i ? LF_EV1 : LF_EV0)))
			continue;
		cell_range(a, n + 1, c, r, i ? n : 0, l->tol_g, &lo, &hi);
		if (lo <= 0.0 && hi >= 0.0)
			return 1;
	}
	if (n < 1)
		return 0;
	return !cell_definite(a + 4 * (n + 1), n, c, r, l->tol_d);
}

struct cellbuf {
	struct prim *p;
	long n, cap;
	int fail;
};

static void cell_push(struct cellbuf *cb, px_aabb box, int leaf)
{
	if (cb->n == cb->cap) {
		long nc = cb->cap ? 2 * cb->cap : 1024;
		struct prim *np = realloc(cb->p, (size_t)nc * sizeof(*np));
		if (!np) {
			cb->fail = 1;
			return;
		}
		cb->p = np;
		cb->cap = nc;
	}
	cb->p[cb->n].box = box;
	cb->p[cb->n].leaf = leaf;
	cb->n++;
}

/* Octree exclusion over the working volume: the cells at max_depth
 * where leaf li may have an event (a cell is also kept whole when the
 * budget runs out, which only makes the cover coarser). */
static void leaf_cells_rec(const struct px_track *t, int li, px_aabb cell,
			   int depth, int max_depth, struct cellbuf *cb,
			   long *budget)
{
	const struct leaf *l = &t->leaf[li];
	px_vec3 c = px_aabb_center(&cell);
	px_vec3 r = px_v3_scale(px_v3_sub(cell.max, cell.min), 0.5);
	int k;
	if (!cell_event(t, l, c, r))
		return;
	if (depth >= max_depth || --(*budget) <= 0) {
		cell_push(cb, cell, li);
		return;
	}
	for (k = 0; k < 8; k++) {
		px_aabb ch;
		ch.min = px_v3(k & 1 ? c.x : cell.min.x, k & 2 ? c.y : cell.min.y,
			       k & 4 ? c.z : cell.min.z);
		ch.max = px_v3(k & 1 ? cell.max.x : c.x, k & 2 ? cell.max.y : c.y,
			       k & 4 ? cell.max.z : c.z);
		leaf_cells_rec(t, li, ch, depth + 1, max_depth, cb, budget);
	}
}

void px_track_free(struct px_track *t)
{
	int i;
	if (!t)
		return;
	px_dist_model_free(t->dist);
	if (t->ent)
		for (i = 0; i < t->n_ent; i++) {
			free(t->ent[i].z);
			free(t->ent[i].old);
		}
	free(t->ent);
	free(t->span);
	free(t->leaf);
	free(t->pool);
	free(t->cand);
	free(t->cexp);
	free(t->hits);
	free(t->expiry);
	free(t->ectr);
	free(t->erad);
	free(t->rmin);
	free(t->gdue);
	free(t->ipool);
	free(t);
}

/* The options (opts, or the defaults without) into o and whether
 * px_track_create() accepts them and the curves: PX_OK, PX_E_RANGE
 * (degree) or PX_E_INVAL; *max_ctrl the most control points of a curve,
 * *span_cap a bound on the spans (knots and cusps: at most 32 a span). */
static int create_check(const struct px_nurbs_curve *curves, int n_curves,
			const struct px_track_opts *opts, struct px_track_opts *o,
			int *max_ctrl, int *span_cap)
{
	int i;
	if (opts)
		*o = *opts;
	else
		px_track_opts_default(o);
	if (!px__tracker_opts_valid(&o->shared) || o->leaves_per_span < 1 ||
	    o->leaves_per_span > 64 || o->box_depth < 0 || o->box_depth > 7)
		return PX_E_INVAL;
	*max_ctrl = 0;
	*span_cap = 0;
	for (i = 0; i < n_curves; i++) {
		if (curves[i].degree < 1 || curves[i].degree > TRK_MAXD)
			return PX_E_RANGE;
		if (!curves[i].knots || !curves[i].pw)
			return PX_E_INVAL;
		if (curves[i].n_ctrl > *max_ctrl)
			*max_ctrl = curves[i].n_ctrl;
		*span_cap += (curves[i].n_ctrl + 1) * 34 + 2;
	}
	return PX_OK;
}

/* Span s over [s0, s1] of a curve of degree p from its Bezier piece sub:
 * the power-basis tables. */
static void span_setup(struct span *s, const struct px_nurbs_curve *sub,
		       double s0, double s1, int p)
{
	double hb[4][TRK_MAXD + 1], sc = 1.0;
	int q, jj, r;
	s->u0 = s0;
	s->u1 = s1;
	s->inv = 1.0 / (s1 - s0);
	s->deg = p;
	for (q = 0; q <= p; q++)
		for (jj = 0; jj < 4; jj++)
			hb[jj][q] = sub->pw[4 * q + jj];
	for (jj = 0; jj < 4; jj++)
		for (q = 0; q <= p; q++) {
			double v = 0.0;
			for (r = 0; r <= q; r++)
				v += (((q - r) & 1) ? -1.0 : 1.0) *
				     px_bern_binom(q, r) * hb[jj][r];
			s->pc[jj][q] = px_bern_binom(p, q) * v;
		}
	for (q = 0; q <= p; q++) {
		for (jj = 0; jj < 4; jj++)
			s->pu[jj][q] = s->pc[jj][q] * sc;
		sc *= s->inv;
	}
	s->rat = 0;
	for (q = 0; q <= p; q++)
		if (s->pc[3][q] != (q == 0 ? 1.0 : 0.0))
			s->rat = 1;
#if TRK_VEC
	for (jj = 0; jj < 4; jj++) {
		const double *w = s->pu[jj];
		int m = jj / 2, l2 = jj % 2;
		for (q = 0; q < 4; q++)
			s->hv[q][m][l2] = w[q];
		s->hd1[0][m][l2] = w[1];
		s->hd1[1][m][l2] = 2.0 * w[2];
		s->hd1[2][m][l2] = 3.0 * w[3];
		s->hd2[0][m][l2] = 2.0 * w[2];
		s->hd2[1][m][l2] = 6.0 * w[3];
	}
#endif
}

/* What the setup passes over the curves keep: the splits (spl, span_cap
 * entries), the curve work space (work_len doubles) and the sizes the
 * first pass finds for the second. */
struct setup {
	struct split *spl;
	int span_cap;
	double *work;
	size_t work_len;
	int leaf_cap, cand_cap;
	size_t pool_cap;
};

/* Curve c (entity i, hull its box): its domain, seam, spans and
 * critical-point arrays; the sizes in su grow by what its leaves and
 * candidates need. */
static int curve_spans(struct px_track *t, int i, const struct px_nurbs_curve *c,
		       const px_aabb *hull, struct setup *su)
{
	struct ent *e = &t->ent[i];
	int ns, k, p = c->degree, rc;
	double a, b;

	px_nurbs_curve_domain(c, &a, &b);
	e->u0 = a;
	e->u1 = b;
	e->len = b - a;
	e->cyclic = px_nurbs_curve_seam(c, 1e-12 * (1.0 + px_aabb_diagonal(hull)),
					1e-9) >= 1;
	ns = curve_splits(c, su->spl, su->span_cap - t->n_spans - 2, &t->n_cusps);
	e->first_span = t->n_spans;
	for (k = 0; k <= ns; k++) {
		double s0 = k == 0 ? a : su->spl[k - 1].u, s1 = k == ns ? b : su->spl[k].u;
		struct px_nurbs_curve sub;
		if (!(s1 > s0))
			continue;
		rc = px_nurbs_curve_extract_work(c, s0, s1, su->work, su->work_len, &sub);
		if (rc)
			return rc;
		if (sub.n_ctrl != p + 1)
			return PX_E_INVAL;
		span_setup(&t->span[t->n_spans], &sub, s0, s1, p);
		t->n_spans++;
	}
	e->n_spans = t->n_spans - e->first_span;
	e->cap = t->opts.max_crit;
	e->z = calloc((size_t)e->cap, sizeof(*e->z));
	e->old = calloc((size_t)e->cap, sizeof(*e->old));
	if (!e->z || !e->old)
		return PX_E_NOMEM;
	su->leaf_cap += e->n_spans * t->opts.leaves_per_span;
	su->cand_cap += ns + 2;
	for (k = 0; k < e->n_spans; k++) {
		int n = 3 * p - 1;
		su->pool_cap += (size_t)t->opts.leaves_per_span *
				(size_t)(4 * (n + 1) + 4 * n);
	}
	return PX_OK;
}

/* The arrays of the leaves and candidates (sizes in su). */
static int leaves_alloc(struct px_track *t, const struct setup *su)
{
	size_t lc = (size_t)su->leaf_cap;
	t->leaf = calloc(lc, sizeof(*t->leaf));
	t->pool = calloc(su->pool_cap ? su->pool_cap : 1, sizeof(double));
	t->cand = calloc((size_t)su->cand_cap + 1, sizeof(*t->cand));
	t->cexp = calloc((size_t)su->cand_cap + 1, sizeof(*t->cexp));
	t->hits = calloc(lc + 1, sizeof(int));
	t->expiry = calloc(lc + 1, sizeof(double));
	t->ectr = calloc(lc + 1, sizeof(*t->ectr));
	t->erad = calloc(lc + 1, sizeof(double));
	t->gdue = calloc(lc / TRK_GROUP + 2, sizeof(double));
	t->ipool = calloc(lc * (2 * TRK_NG + 2) + 1, sizeof(double));
	if (!t->leaf || !t->pool || !t->cand || !t->cexp || !t->hits ||
	    !t->expiry || !t->ectr || !t->erad || !t->gdue || !t->ipool)
		return PX_E_NOMEM;
	return PX_OK;
}

static void cand_add(struct px_track *t, const struct px_nurbs_curve *c, int i,
		     double u, int kind)
{
	struct cand *cd = &t->cand[t->n_cand++];
	cd->q = px_nurbs_curve_point(c, u);
	cd->u = u;
	cd->ent = i;
	cd->kind = kind;
}

/* Curve c's (entity i) candidates for the minimum: open ends, a cornered
 * seam, C0 breaks and cusps (spl: its ns splits); its breaks counted. */
static void curve_cands(struct px_track *t, int i, const struct px_nurbs_curve *c,
			const struct split *spl, int ns, int seam)
{
	struct ent *e = &t->ent[i];
	int k;
	e->first_cand = t->n_cand;
	if (seam < 0) {
		cand_add(t, c, i, e->u0, PX_TRACK_END);
		cand_add(t, c, i, e->u1, PX_TRACK_END);
	} else if (seam == 0) {
		cand_add(t, c, i, e->u0, PX_TRACK_BREAK);
	}
	for (k = 0; k < ns; k++) {
		if (spl[k].kind == K_C0 || spl[k].kind == K_CUSP)
			cand_add(t, c, i, spl[k].u, PX_TRACK_BREAK);
		if (spl[k].kind != K_SMOOTH)
			t->n_breaks++;
	}
	e->n_cand = t->n_cand - e->first_cand;
}

/* The coefficients of leaf l, the part [t0, t1] of a span whose w^3 g
 * has the Bernstein coefficients ga, gb of degree n, into a (pool):
 * divided by (s - s0) / (s - s1) at a cusp start / end (cusp0, cusp1),
 * then the derivative's; returns the leaf's degree. */
static int leaf_coeffs(struct leaf *l, double *a, const double *ga,
		       const double gb[3][TRK_NG], int n, double t0, double t1,
		       int cusp0, int cusp1)
{
	double *b = a + n + 1;
	int m = n, cc;
	px_bern_restrict(ga, n, t0, t1, a);
	for (cc = 0; cc < 3; cc++)
		px_bern_restrict(gb[cc], n, t0, t1, b + cc * (n + 1));
	if (cusp0) {
		l->flags |= LF_CUSP0;
		px__tk_bern_divide(a, m, 0);
		for (cc = 0; cc < 3; cc++)
			px__tk_bern_divide(b + cc * (n + 1), m, 0);
		m--;
	}
	if (cusp1 && m >= 1) {
		l->flags |= LF_CUSP1;
		px__tk_bern_divide(a, m, 1);
		for (cc = 0; cc < 3; cc++)
			px__tk_bern_divide(b + cc * (n + 1), m, 1);
		m--;
	}
	/* compact to stride m + 1 */
	if (m != n) {
		double tmp[4 * (TRK_NG + 1)];
		for (cc = 0; cc < 4; cc++)
			memcpy(tmp + cc * (m + 1), a + cc * (n + 1),
			       (size_t)(m + 1) * sizeof(double));
		memcpy(a, tmp, (size_t)(4 * (m + 1)) * sizeof(double));
	}
	if (m >= 1)
		for (cc = 0; cc < 4; cc++)
			px_bern_deriv(a + cc * (m + 1), m, a + 4 * (m + 1) + cc * m);
	return m;
}

/* Leaf l's tolerances: the rounding of its affine coefficients a (degree
 * m) anywhere in a working volume within wmax of the origin. */
static void leaf_tols(struct leaf *l, const double *a, int m, double wmax)
{
	const double *da = a + 4 * (m + 1);
	double tg = 0.0, td = 0.0;
	int q;
	for (q = 0; q <= m; q++) {
		double s2 = fabs(a[q]) +
			    wmax * (fabs(a[m + 1 + q]) + fabs(a[2 * (m + 1) + q]) +
				    fabs(a[3 * (m + 1) + q]));
		tg = fmax(tg, s2);
	}
	for (q = 0; q < m; q++) {
		double s2 = fabs(da[q]) + wmax * (fabs(da[m + q]) +
						  fabs(da[2 * m + q]) +
						  fabs(da[3 * m + q]));
		td = fmax(td, s2);
	}
	l->tol_g = 1e-12 * tg;
	l->tol_d = 1e-12 * td;
}

/* The inverse norms of the p-gradients of leaf li's coefficients a
 * (degree m) into ib (safe radii; 0 for a constant). */
static void leaf_inorms(double *ib, const double *a, int m)
{
	const double *da = a + 4 * (m + 1);
	int q;
	for (q = 0; q <= m; q++) {
		double nb = sqrt(a[m + 1 + q] * a[m + 1 + q] +
				 a[2 * (m + 1) + q] * a[2 * (m + 1) + q] +
				 a[3 * (m + 1) + q] * a[3 * (m + 1) + q]);
		ib[q] = nb > 0.0 ? 1.0 / nb : INFINITY;
	}
	for (q = 0; q < m; q++) {
		double nb = sqrt(da[m + q] * da[m + q] + da[2 * m + q] * da[2 * m + q] +
				 da[3 * m + q] * da[3 * m + q]);
		ib[m + 1 + q] = nb > 0.0 ? 1.0 / nb : INFINITY;
	}
}

/* The leaves of span si (entity i, degree p; kind0 / kind1 the kinds of
 * its ends; wmax as for leaf_tols()). */
static void span_leaves(struct px_track *t, int i, int si, int p, int kind0,
			int kind1, double wmax)
{
	const struct span *s = &t->span[si];
	double hb[4][TRK_MAXD + 1], ga[TRK_NG], gb[3][TRK_NG];
	int n = 3 * p - 1, q, jj, L, nl = t->opts.leaves_per_span;
	/* Bernstein net back from the power basis */
	for (jj = 0; jj < 4; jj++)
		for (q = 0; q <= p; q++) {
			double v = 0.0;
			int r;
			for (r = 0; r <= q; r++)
				v += px_bern_binom(q, r) / px_bern_binom(p, r) *
				     s->pc[jj][r];
			hb[jj][q] = v;
		}
	span_g(p, hb, ga, gb);
	for (L = 0; L < nl; L++) {
		struct leaf *l = &t->leaf[t->n_leaves];
		double t0 = (double)L / nl, t1 = (double)(L + 1) / nl;
		double *a = t->pool + t->pool_len;
		int m, k0 = L == 0 ? kind0 : K_SMOOTH,
		       k1 = L == nl - 1 ? kind1 : K_SMOOTH;
		l->u0 = s->u0 + (s->u1 - s->u0) * t0;
		l->u1 = L == nl - 1 ? s->u1 : s->u0 + (s->u1 - s->u0) * t1;
		l->ent = i;
		l->span = si;
		l->off = t->pool_len;
		m = leaf_coeffs(l, a, ga, gb, n, t0, t1, k0 == K_CUSP, k1 == K_CUSP);
		l->n = m;
		leaf_tols(l, a, m, wmax);
		l->ioff = (size_t)t->n_leaves * (2 * TRK_NG + 2);
		leaf_inorms(t->ipool + l->ioff, a, m);
		t->pool_len += (size_t)(4 * (m + 1) + 4 * m);
		if (k0 != K_SMOOTH)
			l->flags |= LF_EV0;
		if (k1 != K_SMOOTH)
			l->flags |= LF_EV1;
		if (k0 == K_C0 || k0 == K_CUSP)
			l->flags |= LF_SB0;
		if (k1 == K_C0 || k1 == K_CUSP)
			l->flags |= LF_SB1;
		t->n_leaves++;
	}
}

/* Curve c's (entity i) candidates and leaves. */
static void curve_leaves(struct px_track *t, int i, const struct px_nurbs_curve *c,
			 const struct setup *su)
{
	struct ent *e = &t->ent[i];
	const struct split *spl = su->spl;
	int ns, p = c->degree, seam, nc0 = 0, k, q;
	px_aabb hull = px_nurbs_curve_aabb(c);
	double wmax = fmax(fmax(fabs(t->work.min.x), fabs(t->work.max.x)),
			   fmax(fmax(fabs(t->work.min.y), fabs(t->work.max.y)),
				fmax(fabs(t->work.min.z), fabs(t->work.max.z))));

	ns = curve_splits(c, su->spl, su->span_cap, &nc0);
	seam = px_nurbs_curve_seam(c, 1e-12 * (1.0 + px_aabb_diagonal(&hull)), 1e-9);
	e->first_leaf = t->n_leaves;
	curve_cands(t, i, c, spl, ns, seam);
	for (k = 0; k < e->n_spans; k++) {
		const struct span *s = &t->span[e->first_span + k];
		int kind0 = K_SMOOTH, kind1 = K_SMOOTH;
		/* kinds of the span's ends */
		for (q = 0; q < ns; q++) {
			if (spl[q].u == s->u0)
				kind0 = spl[q].kind;
			if (spl[q].u == s->u1)
				kind1 = spl[q].kind;
		}
		if (k == 0)
			kind0 = seam >= 2 ? K_SMOOTH : seam == 1 ? K_C1 : K_C0;
		if (k == e->n_spans - 1)
			kind1 = seam >= 2 ? K_SMOOTH : seam == 1 ? K_C1 : K_C0;
		span_leaves(t, i, e->first_span + k, p, kind0, kind1, wmax);
	}
	e->n_leaves = t->n_leaves - e->first_leaf;
	if (!e->cyclic) {
		/* open or cornered: parameters do not wrap */
		t->leaf[e->first_leaf].flags |= LF_EV0 | LF_SB0;
		t->leaf[t->n_leaves - 1].flags |= LF_EV1 | LF_SB1;
	}
	for (k = 0; k < e->n_leaves; k++)
		if (t->leaf[e->first_leaf + k].flags & LF_SB0)
			e->n_sb++;
}

/* Event cells: octree exclusion per leaf down to depth; their union box
 * per leaf bounds its safe radius. */
static int event_cells(struct px_track *t, int depth)
{
	struct cellbuf cb = {0};
	long q;
	int i;
	for (i = 0; i < t->n_leaves; i++) {
		long budget = 1L << 14, first = cb.n;
		struct leaf *l = &t->leaf[i];
		leaf_cells_rec(t, i, t->work, 0, depth, &cb, &budget);
		if (cb.fail) {
			free(cb.p);
			return PX_E_NOMEM;
		}
		l->box = px_aabb_empty();
		for (q = first; q < cb.n; q++) {
			px_aabb_extend(&l->box, cb.p[q].box.min);
			px_aabb_extend(&l->box, cb.p[q].box.max);
		}
		if (cb.n > first) {
			l->boxed = 1;
			t->n_boxed++;
		}
	}
	t->n_prim = (int)cb.n;
	free(cb.p);
	return PX_OK;
}

/* The working volume: opts.work where it is a box, else about the model. */
static px_aabb work_volume(const struct px_track_opts *o, px_aabb bounds,
			   double scale)
{
	if (o->work.min.x <= o->work.max.x && o->work.min.y <= o->work.max.y &&
	    o->work.min.z <= o->work.max.z)
		return o->work;
	return px__tracker_work(bounds, o->work_margin, scale);
}

/* Every curve's spans (curve_spans()), then the working volume, every
 * curve's leaves and candidates (curve_leaves()) and the event cells;
 * *bounds the model's. */
static int curves_setup(struct px_track *t, const struct px_nurbs_curve *curves,
			struct setup *su, px_aabb *bounds)
{
	int i, rc = PX_OK;
	*bounds = px_aabb_empty();
	for (i = 0; i < t->n_ent && rc == PX_OK; i++) {
		px_aabb hull = px_nurbs_curve_aabb(&curves[i]);
		px_aabb_extend(bounds, hull.min);
		px_aabb_extend(bounds, hull.max);
		rc = curve_spans(t, i, &curves[i], &hull, su);
	}
	if (rc)
		return rc;
	t->scale = px__tracker_scale(*bounds);
	t->work = work_volume(&t->opts, *bounds, t->scale);
	rc = leaves_alloc(t, su);
	if (rc)
		return rc;
	for (i = 0; i < t->n_ent; i++)
		curve_leaves(t, i, &curves[i], su);
	return event_cells(t, t->opts.box_depth);
}

int px_track_create(const struct px_nurbs_curve *curves, int n_curves,
		    const struct px_track_opts *opts, struct px_track **out)
{
	struct px_track *t;
	struct px_track_opts o;
	struct setup su = {0};
	int rc, max_ctrl;
	px_aabb bounds;

	if (!out || !curves || n_curves <= 0)
		return PX_E_INVAL;
	*out = NULL;
	rc = create_check(curves, n_curves, opts, &o, &max_ctrl, &su.span_cap);
	if (rc)
		return rc;
	t = calloc(1, sizeof(*t));
	if (!t)
		return PX_E_NOMEM;
	t->opts = o;
	rc = px_dist_model_create(curves, n_curves, NULL, 0, o.dist, &t->dist);
	if (rc) {
		free(t);
		return rc;
	}
	t->n_ent = n_curves;
	t->ent = calloc((size_t)n_curves, sizeof(*t->ent));
	t->span = calloc((size_t)su.span_cap, sizeof(*t->span));
	su.spl = calloc((size_t)su.span_cap, sizeof(*su.spl));
	su.work_len = PX_NURBS_CURVE_WORK_LEN(TRK_MAXD, max_ctrl);
	su.work = calloc(su.work_len, sizeof(double));
	if (!t->ent || !t->span || !su.spl || !su.work)
		rc = PX_E_NOMEM;
	if (!rc)
		rc = curves_setup(t, curves, &su, &bounds);
	if (rc)
		goto fail;
	t->bytes = sizeof(*t) + (size_t)t->n_ent * sizeof(*t->ent) +
		   (size_t)t->n_ent * 2 * (size_t)o.max_crit * sizeof(struct zero) +
		   (size_t)su.span_cap * sizeof(*t->span) +
		   (size_t)su.leaf_cap * (sizeof(*t->leaf) + 2 * sizeof(int) +
					  (2 * TRK_NG + 2) * sizeof(double)) +
		   su.pool_cap * sizeof(double) +
		   (size_t)(su.cand_cap + 1) * (sizeof(*t->cand) + sizeof(double));
	t->epoch = 1;
	t->hot_ent = -1;
	t->ans_z = -1;
	t->ans_c = -1;
	t->hot_c = -1;
	t->n_crit_cap = n_curves * o.max_crit;
	t->rmin = calloc((size_t)t->n_crit_cap * 2 + 2, sizeof(int));
	if (!t->rmin) {
		rc = PX_E_NOMEM;
		goto fail;
	}
	t->prev.ent = -1;
	px__gov_setup(&t->gov, o.cold_switch != 0, t->dist, bounds, t->scale);
	free(su.spl);
	free(su.work);
	*out = t;
	return PX_OK;
fail:
	free(su.spl);
	free(su.work);
	px_track_free(t);
	return rc;
}
