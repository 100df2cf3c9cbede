#include "px_spiece.h"

#include <math.h>
#include <string.h>

#include "px_bern.h"

#define MD PX_SPIECE_MAX_DEGREE
/* Largest tensor: gu of degree (3p - 1, 3q), or F of (2p, 2q). */
#define TMAX ((3 * MD + 1) * (3 * MD + 1))

/* Tensor sizes for degrees (p, q). */
static int nf_s(int p) { return 2 * p; }
static int ngu_s(int p) { return 3 * p - 1; }
static int ngu_t(int q) { return 3 * q; }
static int ngv_s(int p) { return 3 * p; }
static int ngv_t(int q) { return 3 * q - 1; }

static size_t tsize(int n, int m)
{
	return (size_t)(n + 1) * (size_t)(m + 1);
}

size_t px_spiece_doubles(int p, int q)
{
	if (p < 1 || q < 1 || p > MD || q > MD)
		return 0;
	return 4 * tsize(p, q) + 5 * tsize(nf_s(p), nf_s(q)) +
	       4 * tsize(ngu_s(p), ngu_t(q)) + 4 * tsize(ngv_s(p), ngv_t(q));
}

/* ---- tensor Bernstein helpers (row i along s, column j along t) ---------- */

/* c (na, ma) times d (nb, mb) into out (na + nb, ma + mb). */
static void t_mul(const double *a, int na, int ma, const double *b, int nb,
		  int mb, double *out)
{
	int n = na + nb, m = ma + mb, i, j, k, l;
	for (i = 0; i <= n; i++)
		for (j = 0; j <= m; j++)
			out[i * (m + 1) + j] = 0.0;
	for (i = 0; i <= na; i++)
		for (j = 0; j <= ma; j++) {
			double av = a[i * (ma + 1) + j] * px_bern_binom(na, i) *
				    px_bern_binom(ma, j);
			if (av == 0.0)
				continue;
			for (k = 0; k <= nb; k++)
				for (l = 0; l <= mb; l++)
					out[(i + k) * (m + 1) + j + l] +=
						av * b[k * (mb + 1) + l] *
						px_bern_binom(nb, k) *
						px_bern_binom(mb, l);
		}
	for (i = 0; i <= n; i++)
		for (j = 0; j <= m; j++)
			out[i * (m + 1) + j] /=
				px_bern_binom(n, i) * px_bern_binom(m, j);
}

/* Derivative along s (degree n - 1, m) or along t (n, m - 1). */
static void t_deriv_s(const double *c, int n, int m, double *out)
{
	int i, j;
	for (i = 0; i < n; i++)
		for (j = 0; j <= m; j++)
			out[i * (m + 1) + j] =
				n * (c[(i + 1) * (m + 1) + j] - c[i * (m + 1) + j]);
}

static void t_deriv_t(const double *c, int n, int m, double *out)
{
	int i, j;
	for (i = 0; i <= n; i++)
		for (j = 0; j < m; j++)
			out[i * m + j] =
				m * (c[i * (m + 1) + j + 1] - c[i * (m + 1) + j]);
}

/* Restriction to [s0, s1] x [t0, t1]. out may alias c. */
static void t_restrict(const double *c, int n, int m, double s0, double s1,
		       double t0, double t1, double *out)
{
	double col[3 * MD + 2];
	int i, j;

	if (out != c)
		memcpy(out, c, tsize(n, m) * sizeof(double));
	if (s0 > 0.0 || s1 < 1.0)
		for (j = 0; j <= m; j++) {
			for (i = 0; i <= n; i++)
				col[i] = out[i * (m + 1) + j];
			px_bern_restrict(col, n, s0, s1, col);
			for (i = 0; i <= n; i++)
				out[i * (m + 1) + j] = col[i];
		}
	if (t0 > 0.0 || t1 < 1.0)
		for (i = 0; i <= n; i++)
			px_bern_restrict(out + i * (m + 1), m, t0, t1,
					 out + i * (m + 1));
}

/* 1 when every coefficient is > 0, -1 when every one is < 0, else 0. */
static int strict_sign(const double *c, size_t k)
{
	size_t i;
	int pos = 1, neg = 1;
	for (i = 0; i < k; i++) {
		pos &= c[i] > 0.0;
		neg &= c[i] < 0.0;
	}
	return pos ? 1 : (neg ? -1 : 0);
}

static void t_range(const double *c, size_t k, double *lo, double *hi)
{
	size_t i;
	*lo = INFINITY;
	*hi = -INFINITY;
	for (i = 0; i < k; i++) {
		*lo = c[i] < *lo ? c[i] : *lo;
		*hi = c[i] > *hi ? c[i] : *hi;
	}
}

/* ---- setup ------------------------------------------------------------------ */

int px_spiece_init(struct px_spiece *sp, int p, int q, const double (*hw)[4],
		   double u0, double u1, double v0, double v1, double *mem)
{
	double hs[4][(MD) * (MD + 1)], ht[4][(MD + 1) * (MD)];
	double k1[TMAX], k2[TMAX], ku[3][TMAX], kv[3][TMAX], tmp[TMAX];
	size_t np = tsize(p, q), i, nfs, ngu, ngv;
	double *cur = mem;
	int c;

	if (!sp || !hw || !mem)
		return PX_E_INVAL;
	if (p < 1 || q < 1 || p > MD || q > MD)
		return PX_E_RANGE;
	if (!isfinite(u0) || !isfinite(u1) || !isfinite(v0) || !isfinite(v1))
		return PX_E_NAN;
	if (!(u0 < u1) || !(v0 < v1))
		return PX_E_INVAL;
	memset(sp, 0, sizeof(*sp));
	sp->p_ = p;
	sp->q_ = q;
	sp->u0_ = u0;
	sp->u1_ = u1;
	sp->v0_ = v0;
	sp->v1_ = v1;
	nfs = tsize(nf_s(p), nf_s(q));
	ngu = tsize(ngu_s(p), ngu_t(q));
	ngv = tsize(ngv_s(p), ngv_t(q));
	sp->h_ = cur;
	cur += 4 * np;
	sp->fa_ = cur;
	cur += nfs;
	sp->fb_ = cur;
	cur += 3 * nfs;
	sp->fw_ = cur;
	cur += nfs;
	sp->gua_ = cur;
	cur += ngu;
	sp->gub_ = cur;
	cur += 3 * ngu;
	sp->gva_ = cur;
	cur += ngv;
	sp->gvb_ = cur;
	sp->box_ = px_aabb_empty();
	for (i = 0; i < np; i++) {
		for (c = 0; c < 4; c++) {
			if (!isfinite(hw[i][c]))
				return PX_E_NAN;
			sp->h_[c * np + i] = hw[i][c];
		}
		if (!(hw[i][3] > 0.0))
			return PX_E_INVAL;
		px_aabb_extend(&sp->box_, px_v3(hw[i][0] / hw[i][3],
						hw[i][1] / hw[i][3],
						hw[i][2] / hw[i][3]));
	}
	sp->center_ = px_aabb_center(&sp->box_);
	sp->radius_ = 0.5 * px_aabb_diagonal(&sp->box_);
	for (c = 0; c < 4; c++) {
		t_deriv_s(sp->h_ + c * np, p, q, hs[c]);
		t_deriv_t(sp->h_ + c * np, p, q, ht[c]);
	}
	/* K_s = H_s w - H w_s (2p - 1, 2q) and K_t = H_t w - H w_t
	 * (2p, 2q - 1). */
	for (c = 0; c < 3; c++) {
		const double *h = sp->h_ + c * np, *w = sp->h_ + 3 * np;
		t_mul(hs[c], p - 1, q, w, p, q, k1);
		t_mul(h, p, q, hs[3], p - 1, q, k2);
		for (i = 0; i < tsize(2 * p - 1, 2 * q); i++)
			ku[c][i] = k1[i] - k2[i];
		t_mul(ht[c], p, q - 1, w, p, q, k1);
		t_mul(h, p, q, ht[3], p, q - 1, k2);
		for (i = 0; i < tsize(2 * p, 2 * q - 1); i++)
			kv[c][i] = k1[i] - k2[i];
	}
	memset(sp->gua_, 0, ngu * sizeof(double));
	memset(sp->gva_, 0, ngv * sizeof(double));
	memset(sp->fa_, 0, nfs * sizeof(double));
	for (c = 0; c < 3; c++) {
		const double *h = sp->h_ + c * np, *w = sp->h_ + 3 * np;
		t_mul(h, p, q, ku[c], 2 * p - 1, 2 * q, tmp);
		for (i = 0; i < ngu; i++)
			sp->gua_[i] += tmp[i];
		t_mul(w, p, q, ku[c], 2 * p - 1, 2 * q, sp->gub_ + c * ngu);
		t_mul(h, p, q, kv[c], 2 * p, 2 * q - 1, tmp);
		for (i = 0; i < ngv; i++)
			sp->gva_[i] += tmp[i];
		t_mul(w, p, q, kv[c], 2 * p, 2 * q - 1, sp->gvb_ + c * ngv);
		/* w^2 f = |H|^2 - 2 P . (w H) + |P|^2 w^2 */
		t_mul(h, p, q, h, p, q, tmp);
		for (i = 0; i < nfs; i++)
			sp->fa_[i] += tmp[i];
		t_mul(w, p, q, h, p, q, sp->fb_ + c * nfs);
	}
	t_mul(sp->h_ + 3 * np, p, q, sp->h_ + 3 * np, p, q, sp->fw_);
	return PX_OK;
}

/* ---- evaluation --------------------------------------------------------------- */

#define NB (3 * MD + 1)

/* Bernstein basis of degree n (<= 3 MD) at t with first and second
 * derivatives. */
static void basis(int n, double t, double *b0, double *b1, double *b2)
{
	double tri[NB][NB];
	int k, i;

	tri[0][0] = 1.0;
	for (k = 1; k <= n; k++) {
		tri[k][0] = (1.0 - t) * tri[k - 1][0];
		for (i = 1; i < k; i++)
			tri[k][i] = (1.0 - t) * tri[k - 1][i] + t * tri[k - 1][i - 1];
		tri[k][k] = t * tri[k - 1][k - 1];
	}
	for (i = 0; i <= n; i++) {
		double lo1 = n >= 1 ? (i >= 1 ? tri[n - 1][i - 1] : 0.0) -
					      (i <= n - 1 ? tri[n - 1][i] : 0.0)
				    : 0.0;
		b0[i] = tri[n][i];
		b1[i] = n * lo1;
		if (n >= 2) {
			double a = i >= 2 ? tri[n - 2][i - 2] : 0.0;
			double b = (i >= 1 && i - 1 <= n - 2) ? tri[n - 2][i - 1] : 0.0;
			double c = i <= n - 2 ? tri[n - 2][i] : 0.0;
			b2[i] = n * (n - 1) * (a - 2.0 * b + c);
		} else {
			b2[i] = 0.0;
		}
	}
}

px_vec3 px_spiece_eval(const struct px_spiece *sp, double s, double t,
		       px_vec3 *su, px_vec3 *sv, px_vec3 *suu, px_vec3 *suv,
		       px_vec3 *svv)
{
	double bs[3][MD + 1], bt[3][MD + 1];
	/* d[a][b][c]: derivative a in s, b in t of homogeneous component c */
	double d[3][3][4];
	int p = sp->p_, q = sp->q_, i, j, c, a, b;
	size_t np = tsize(p, q);
	double ks = 1.0 / (sp->u1_ - sp->u0_), kt = 1.0 / (sp->v1_ - sp->v0_);
	px_vec3 S;

	basis(p, s, bs[0], bs[1], bs[2]);
	basis(q, t, bt[0], bt[1], bt[2]);
	memset(d, 0, sizeof(d));
	for (c = 0; c < 4; c++)
		for (i = 0; i <= p; i++) {
			double row[3] = {0, 0, 0};
			for (j = 0; j <= q; j++) {
				double h = sp->h_[c * np + (size_t)i * (q + 1) + j];
				row[0] += bt[0][j] * h;
				row[1] += bt[1][j] * h;
				row[2] += bt[2][j] * h;
			}
			for (a = 0; a < 3; a++)
				for (b = 0; a + b < 3; b++)
					d[a][b][c] += bs[a][i] * row[b];
		}
	{
		/* Quotient rule for S = H / w up to second order. */
		double w = d[0][0][3], iw = 1.0 / w;
		double S0[3], Ss[3], St[3], Sss[3], Sst[3], Stt[3];
		double ws = d[1][0][3], wt = d[0][1][3], wss = d[2][0][3],
		       wst = d[1][1][3], wtt = d[0][2][3];
		for (c = 0; c < 3; c++) {
			S0[c] = d[0][0][c] * iw;
			Ss[c] = (d[1][0][c] - ws * S0[c]) * iw;
			St[c] = (d[0][1][c] - wt * S0[c]) * iw;
			Sss[c] = (d[2][0][c] - 2.0 * ws * Ss[c] - wss * S0[c]) * iw;
			Sst[c] = (d[1][1][c] - ws * St[c] - wt * Ss[c] - wst * S0[c]) * iw;
			Stt[c] = (d[0][2][c] - 2.0 * wt * St[c] - wtt * S0[c]) * iw;
		}
		S = px_v3(S0[0], S0[1], S0[2]);
		if (su)
			*su = px_v3(Ss[0] * ks, Ss[1] * ks, Ss[2] * ks);
		if (sv)
			*sv = px_v3(St[0] * kt, St[1] * kt, St[2] * kt);
		if (suu)
			*suu = px_v3(Sss[0] * ks * ks, Sss[1] * ks * ks, Sss[2] * ks * ks);
		if (suv)
			*suv = px_v3(Sst[0] * ks * kt, Sst[1] * ks * kt, Sst[2] * ks * kt);
		if (svv)
			*svv = px_v3(Stt[0] * kt * kt, Stt[1] * kt * kt, Stt[2] * kt * kt);
	}
	return S;
}

/* ---- query ---------------------------------------------------------------------- */

struct rect {
	double s0, s1, t0, t1;
	double lb; /* lower bound of f on the rectangle */
	int depth;
};

struct qctx {
	const struct px_spiece *sp;
	px_vec3 p;
	double best, slack;
	struct px_spiece_hit *hit;
	int improved;
};

static void consider(struct qctx *x, double s, double t)
{
	px_vec3 q = px_spiece_eval(x->sp, s, t, NULL, NULL, NULL, NULL, NULL);
	double d2 = px_v3_dist2(q, x->p);
	if (d2 < x->best) {
		x->best = d2;
		x->hit->d2 = d2;
		x->hit->point = q;
		x->hit->u = x->sp->u0_ + s * (x->sp->u1_ - x->sp->u0_);
		x->hit->v = x->sp->v0_ + t * (x->sp->v1_ - x->sp->v0_);
		x->improved = 1;
	}
}

/* Value and partial derivatives of a tensor polynomial at (s, t). */
static void t_eval(const double *c, int n, int m, const double *bs0,
		   const double *bs1, const double *bt0, const double *bt1,
		   double *v, double *vs, double *vt)
{
	int i, j;
	*v = *vs = *vt = 0.0;
	for (i = 0; i <= n; i++) {
		double r0 = 0.0, r1 = 0.0;
		for (j = 0; j <= m; j++) {
			r0 += bt0[j] * c[i * (m + 1) + j];
			r1 += bt1[j] * c[i * (m + 1) + j];
		}
		*v += bs0[i] * r0;
		*vs += bs1[i] * r0;
		*vt += bs0[i] * r1;
	}
}

struct gsys {
	const double *gu, *gv;
	int un, um, vn, vm;
};

static void g_eval(const struct gsys *g, double s, double t, double G[2],
		   double J[2][2])
{
	double bs0[NB], bs1[NB], bs2[NB], bt0[NB], bt1[NB], bt2[NB];
	basis(g->un, s, bs0, bs1, bs2);
	basis(g->um, t, bt0, bt1, bt2);
	t_eval(g->gu, g->un, g->um, bs0, bs1, bt0, bt1, &G[0], &J[0][0], &J[0][1]);
	basis(g->vn, s, bs0, bs1, bs2);
	basis(g->vm, t, bt0, bt1, bt2);
	t_eval(g->gv, g->vn, g->vm, bs0, bs1, bt0, bt1, &G[1], &J[1][0], &J[1][1]);
}

/*
 * Zero of G = (gu, gv) inside the rectangle, where the caller proved
 * that G is strictly monotone (so there is at most one, and its Jacobian
 * is never singular): Newton steps with backtracking on |G|^2, each
 * clipped to the rectangle. Returns 1 with the zero when it converges
 * strictly inside; 0 otherwise (no zero here, or not yet reached: the
 * caller subdivides).
 */
static int newton_g(const struct gsys *g, const struct rect *r, int *iters,
		    double *s_out, double *t_out)
{
	double s = 0.5 * (r->s0 + r->s1), t = 0.5 * (r->t0 + r->t1);
	double G[2], J[2][2], n2;
	int it;

	g_eval(g, s, t, G, J);
	n2 = G[0] * G[0] + G[1] * G[1];
	for (it = 0; it < PX_SPIECE_MAX_ITERS; it++) {
		double det = J[0][0] * J[1][1] - J[0][1] * J[1][0], ds, dt, a;
		int k;

		(*iters)++;
		if (n2 == 0.0)
			break;
		if (det == 0.0)
			return 0;
		ds = -(J[1][1] * G[0] - J[0][1] * G[1]) / det;
		dt = -(J[0][0] * G[1] - J[1][0] * G[0]) / det;
		for (a = 1.0, k = 0; k < 30; k++, a *= 0.5) {
			double ns = fmin(r->s1, fmax(r->s0, s + a * ds));
			double nt = fmin(r->t1, fmax(r->t0, t + a * dt));
			double NG[2], NJ[2][2], nn2;
			g_eval(g, ns, nt, NG, NJ);
			nn2 = NG[0] * NG[0] + NG[1] * NG[1];
			if (nn2 < n2 || (fabs(ns - s) <= 1e-15 && fabs(nt - t) <= 1e-15)) {
				double moved = fmax(fabs(ns - s), fabs(nt - t));
				s = ns;
				t = nt;
				G[0] = NG[0];
				G[1] = NG[1];
				memcpy(J, NJ, sizeof(J));
				n2 = nn2;
				if (moved <= 1e-13)
					goto done;
				break;
			}
		}
		if (k == 30)
			return 0; /* no decrease possible: stalled on the border */
	}
done:
	/* A zero clipped onto the border is not this rectangle's. */
	if (s <= r->s0 || s >= r->s1 || t <= r->t0 || t >= r->t1) {
		if (!((s == 0.0 || s == 1.0 || t == 0.0 || t == 1.0) && n2 == 0.0))
			return 0;
	}
	*s_out = s;
	*t_out = t;
	return it < PX_SPIECE_MAX_ITERS;
}

/* Min-heap of rectangles by lower bound: nearest first, so the best
 * bound drops early and prunes the rest. */
static void heap_push(struct rect *h, int *n, struct rect r)
{
	int i = (*n)++;
	while (i > 0) {
		int parent = (i - 1) / 2;
		if (h[parent].lb <= r.lb)
			break;
		h[i] = h[parent];
		i = parent;
	}
	h[i] = r;
}

static struct rect heap_pop(struct rect *h, int *n)
{
	struct rect top = h[0], last = h[--(*n)];
	int i = 0;
	for (;;) {
		int l = 2 * i + 1, m = i;
		if (l < *n && h[l].lb < last.lb)
			m = l;
		if (l + 1 < *n && h[l + 1].lb < (m == i ? last.lb : h[m].lb))
			m = l + 1;
		if (m == i)
			break;
		h[i] = h[m];
		i = m;
	}
	if (*n > 0)
		h[i] = last;
	return top;
}

static double rect_lb(const double *F, const double *W, int fn, int fm,
		      const struct rect *r, double *rf, double *rw)
{
	size_t i, k = tsize(fn, fm);
	double lb = INFINITY;
	t_restrict(F, fn, fm, r->s0, r->s1, r->t0, r->t1, rf);
	t_restrict(W, fn, fm, r->s0, r->s1, r->t0, r->t1, rw);
	for (i = 0; i < k; i++) {
		double q = rf[i] / rw[i];
		lb = q < lb ? q : lb;
	}
	return lb;
}

int px_spiece_closest(const struct px_spiece *sp, px_vec3 p, double *best_d2,
		      struct px_spiece_hit *hit)
{
	const int P = sp->p_, Q = sp->q_;
	const int fn = nf_s(P), fm = nf_s(Q);
	const int un = ngu_s(P), um = ngu_t(Q), vn = ngv_s(P), vm = ngv_t(Q);
	const size_t nfs = tsize(fn, fm), ngu = tsize(un, um), ngv = tsize(vn, vm);
	double F[TMAX], GU[TMAX], GV[TMAX];
	double rf[TMAX], rw[TMAX], rg[TMAX], rv[TMAX], dg[TMAX];
	/* Each split replaces one rectangle by four: the heap never holds
	 * more than 3 * nodes + 1. */
	struct rect heap[3 * PX_SPIECE_MAX_NODES + 4];
	struct gsys gs;
	struct qctx x;
	double pp = px_v3_dot(p, p), lb_unresolved = INFINITY;
	int hn = 0, k;
	size_t i;

	x.sp = sp;
	x.p = p;
	x.best = *best_d2;
	x.hit = hit;
	x.improved = 0;
	hit->iters = 0;
	hit->nodes = 0;
	hit->certified = 1;
	hit->gap = 0.0;
	{
		double dc = px_v3_dist(p, sp->center_) - sp->radius_;
		if (dc > 0.0 && dc * dc >= x.best)
			goto out;
	}
	for (i = 0; i < nfs; i++)
		F[i] = sp->fa_[i] -
		       2.0 * (p.x * sp->fb_[i] + p.y * sp->fb_[nfs + i] +
			      p.z * sp->fb_[2 * nfs + i]) +
		       pp * sp->fw_[i];
	{
		double r = px_v3_dist(sp->center_, p) + 2.0 * sp->radius_;
		x.slack = 1e-13 * (r * r + px_v3_dot(sp->center_, sp->center_));
	}
	{
		struct rect root = {0.0, 1.0, 0.0, 1.0, 0.0, 0};
		root.lb = rect_lb(F, sp->fw_, fn, fm, &root, rf, rw);
		if (root.lb >= x.best - x.slack)
			goto out;
		heap_push(heap, &hn, root);
	}
	for (i = 0; i < ngu; i++)
		GU[i] = sp->gua_[i] - (p.x * sp->gub_[i] + p.y * sp->gub_[ngu + i] +
				       p.z * sp->gub_[2 * ngu + i]);
	for (i = 0; i < ngv; i++)
		GV[i] = sp->gva_[i] - (p.x * sp->gvb_[i] + p.y * sp->gvb_[ngv + i] +
				       p.z * sp->gvb_[2 * ngv + i]);
	gs.gu = GU;
	gs.gv = GV;
	gs.un = un;
	gs.um = um;
	gs.vn = vn;
	gs.vm = vm;
	/* An upper bound before subdividing: without one, a patch whose
	 * every point is equally near (a sphere seen from its centre) could
	 * not be settled by the F / W bound. */
	consider(&x, 0.5, 0.5);
	while (hn > 0 && hit->nodes < PX_SPIECE_MAX_NODES) {
		struct rect r = heap_pop(heap, &hn);
		double ws = r.s1 - r.s0, wt = r.t1 - r.t0;
		int certain = 0;

		if (r.lb >= x.best - x.slack)
			continue; /* the best dropped since it was queued */
		hit->nodes++;
		t_restrict(GU, un, um, r.s0, r.s1, r.t0, r.t1, rg);
		if (strict_sign(rg, ngu))
			continue; /* df/ds never vanishes here */
		t_restrict(GV, vn, vm, r.s0, r.s1, r.t0, r.t1, rv);
		if (strict_sign(rv, ngv))
			continue; /* df/dt never vanishes here */
		{
			/* Bernstein bounds of the Jacobian of (gu, gv), in the
			 * piece's local scale (d/ds = (1/ws) d/ds_sub). */
			double a_lo, a_hi, b_lo, b_hi, c_lo, c_hi, d_lo, d_hi, off;
			t_deriv_s(rg, un, um, dg);
			t_range(dg, tsize(un - 1, um), &a_lo, &a_hi);
			t_deriv_t(rg, un, um, dg);
			t_range(dg, tsize(un, um - 1), &b_lo, &b_hi);
			t_deriv_s(rv, vn, vm, dg);
			t_range(dg, tsize(vn - 1, vm), &c_lo, &c_hi);
			t_deriv_t(rv, vn, vm, dg);
			t_range(dg, tsize(vn, vm - 1), &d_lo, &d_hi);
			a_lo /= ws;
			a_hi /= ws;
			c_lo /= ws;
			c_hi /= ws;
			b_lo /= wt;
			b_hi /= wt;
			d_lo /= wt;
			d_hi /= wt;
			off = 0.5 * fmax(fabs(b_lo + c_lo), fabs(b_hi + c_hi));
			if (a_lo > 0.0 && d_lo > 0.0 && a_lo * d_lo > off * off)
				certain = 1; /* monotone: one zero at most, a minimum */
			else if (a_hi < 0.0 && d_hi < 0.0 && a_hi * d_hi > off * off)
				continue; /* at most one zero, and a maximum */
		}
		if (certain) {
			double s, t;
			if (newton_g(&gs, &r, &hit->iters, &s, &t)) {
				consider(&x, s, t);
				continue;
			}
		} else {
			/* Keep the upper bound moving while we subdivide. */
			consider(&x, 0.5 * (r.s0 + r.s1), 0.5 * (r.t0 + r.t1));
		}
		if (r.depth >= PX_SPIECE_MAX_DEPTH) {
			lb_unresolved = fmin(lb_unresolved, r.lb);
			continue;
		}
		{
			double sm = 0.5 * (r.s0 + r.s1), tm = 0.5 * (r.t0 + r.t1);
			struct rect ch[4] = {{r.s0, sm, r.t0, tm, 0.0, r.depth + 1},
					     {sm, r.s1, r.t0, tm, 0.0, r.depth + 1},
					     {r.s0, sm, tm, r.t1, 0.0, r.depth + 1},
					     {sm, r.s1, tm, r.t1, 0.0, r.depth + 1}};
			for (k = 0; k < 4; k++) {
				ch[k].lb = rect_lb(F, sp->fw_, fn, fm, &ch[k], rf, rw);
				if (ch[k].lb < x.best - x.slack)
					heap_push(heap, &hn, ch[k]);
			}
		}
	}
	/* What the node bound left queued bounds what may have been missed. */
	for (k = 0; k < hn; k++)
		lb_unresolved = fmin(lb_unresolved, heap[k].lb);
	if (lb_unresolved < x.best - x.slack) {
		hit->certified = 0;
		hit->gap = sqrt(x.best) - sqrt(fmax(lb_unresolved, 0.0));
	}
out:
	*best_d2 = x.best;
	return x.improved;
}
