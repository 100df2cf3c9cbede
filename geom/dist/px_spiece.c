/*
 * px_spiece.c - a certified surface piece: setup (the control net and
 * the critical-point tensors of the squared distance, from the
 * Bernstein tensor algebra of spiece_tensor.c) and evaluation. The
 * closest-point query is in spiece_solve.c.
 */
#include "px_spiece.h"

#include <math.h>
#include <string.h>

#include "dist_internal.h"

#define MD PX__SP_MD
#define TMAX PX__SP_TMAX

/* Tensor sizes for degrees (p, q). */
static int nf_s(int p) { return 2 * p; }
static int ngu_s(int p) { return 3 * p - 1; }
static int ngu_t(int q) { return 3 * q; }
static int ngv_s(int p) { return 3 * p; }
static int ngv_t(int q) { return 3 * q - 1; }

size_t px_spiece_doubles(int p, int q)
{
	if (p < 1 || q < 1 || p > MD || q > MD)
		return 0;
	return 4 * px__sp_tsize(p, q) + 5 * px__sp_tsize(nf_s(p), nf_s(q)) +
	       4 * px__sp_tsize(ngu_s(p), ngu_t(q)) + 4 * px__sp_tsize(ngv_s(p), ngv_t(q));
}

/* Every weight equal: the patch is polynomial once they are divided out,
 * and its critical-point tensors have the lower degrees. */
static int equal_weights(const double (*hw)[4], size_t np)
{
	size_t i;
	for (i = 1; i < np; i++)
		if (hw[i][3] != hw[0][3])
			return 0;
	return 1;
}

size_t px_spiece_doubles_hw(int p, int q, const double (*hw)[4])
{
	if (p < 1 || q < 1 || p > MD || q > MD || !hw)
		return 0;
	if (!equal_weights(hw, px__sp_tsize(p, q)))
		return px_spiece_doubles(p, q);
	return 4 * px__sp_tsize(p, q) + 5 * px__sp_tsize(nf_s(p), nf_s(q)) +
	       4 * px__sp_tsize(2 * p - 1, 2 * q) + 4 * px__sp_tsize(2 * p, 2 * q - 1);
}

/* ---- setup ------------------------------------------------------------------ */

/* The next n doubles of the piece's memory. */
static double *take(double **cur, size_t n)
{
	double *p = *cur;
	*cur += n;
	return p;
}

int px_spiece_init(struct px_spiece *sp, int p, int q, const double (*hw)[4],
		   double u0, double u1, double v0, double v1, double *mem)
{
	double hs[4][(MD) * (MD + 1)], ht[4][(MD + 1) * (MD)];
	double k1[TMAX], k2[TMAX], ku[3][TMAX], kv[3][TMAX], tmp[TMAX];
	size_t np = px__sp_tsize(p, q), i, nfs, ngu, ngv;
	int wp, wq;
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
	nfs = px__sp_tsize(nf_s(p), nf_s(q));
	/* Blocks packed at the degrees the weights give (see
	 * px_spiece_doubles_hw()). */
	if (equal_weights(hw, np)) {
		ngu = px__sp_tsize(2 * p - 1, 2 * q);
		ngv = px__sp_tsize(2 * p, 2 * q - 1);
	} else {
		ngu = px__sp_tsize(ngu_s(p), ngu_t(q));
		ngv = px__sp_tsize(ngv_s(p), ngv_t(q));
	}
	sp->h_ = take(&cur, 4 * np);
	sp->fa_ = take(&cur, nfs);
	sp->fb_ = take(&cur, 3 * nfs);
	sp->fw_ = take(&cur, nfs);
	sp->gua_ = take(&cur, ngu);
	sp->gub_ = take(&cur, 3 * ngu);
	sp->gva_ = take(&cur, ngv);
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
	/* Equal weights: divide them out, and w becomes the degree-0
	 * constant 1. The critical-point tensors then drop from degree
	 * 3p - 1 to 2p - 1, which is most of the query's work. */
	sp->wconst_ = 1;
	for (i = 1; i < np; i++)
		if (sp->h_[3 * np + i] != sp->h_[3 * np])
			sp->wconst_ = 0;
	if (sp->wconst_) {
		double w0 = sp->h_[3 * np];
		for (i = 0; i < 4 * np; i++)
			sp->h_[i] /= w0;
	}
	wp = sp->wconst_ ? 0 : p;
	wq = sp->wconst_ ? 0 : q;
	sp->gun_ = 2 * p + wp - 1;
	sp->gum_ = 2 * q + wq;
	sp->gvn_ = 2 * p + wp;
	sp->gvm_ = 2 * q + wq - 1;
	/* The same decision as the layout above (the same weights). */
	ngu = px__sp_tsize(sp->gun_, sp->gum_);
	ngv = px__sp_tsize(sp->gvn_, sp->gvm_);
	{
		const double *w = sp->h_ + 3 * np;
		double one[TMAX];
		size_t nk;

		for (i = 0; i < TMAX; i++)
			one[i] = 1.0; /* Bernstein coefficients of 1: elevation */
		for (c = 0; c < 4; c++) {
			px__sp_deriv_s(sp->h_ + c * np, p, q, hs[c]);
			px__sp_deriv_t(sp->h_ + c * np, p, q, ht[c]);
		}
		/* K_s = H_s w - H w_s and K_t = H_t w - H w_t; with a constant
		 * w they are H_s and H_t. */
		for (c = 0; c < 3; c++) {
			const double *h = sp->h_ + c * np;
			if (sp->wconst_) {
				memcpy(ku[c], hs[c], px__sp_tsize(p - 1, q) * sizeof(double));
				memcpy(kv[c], ht[c], px__sp_tsize(p, q - 1) * sizeof(double));
				continue;
			}
			px__sp_mul(hs[c], p - 1, q, w, p, q, k1);
			px__sp_mul(h, p, q, hs[3], p - 1, q, k2);
			for (i = 0; i < px__sp_tsize(2 * p - 1, 2 * q); i++)
				ku[c][i] = k1[i] - k2[i];
			px__sp_mul(ht[c], p, q - 1, w, p, q, k1);
			px__sp_mul(h, p, q, ht[3], p, q - 1, k2);
			for (i = 0; i < px__sp_tsize(2 * p, 2 * q - 1); i++)
				kv[c][i] = k1[i] - k2[i];
		}
		memset(sp->gua_, 0, ngu * sizeof(double));
		memset(sp->gva_, 0, ngv * sizeof(double));
		memset(sp->fa_, 0, nfs * sizeof(double));
		for (c = 0; c < 3; c++) {
			const double *h = sp->h_ + c * np;
			/* a = H . K (degree of gu), b = w K raised to it. */
			px__sp_mul(h, p, q, ku[c], p + wp - 1, q + wq, tmp);
			nk = px__sp_tsize(sp->gun_, sp->gum_);
			for (i = 0; i < nk; i++)
				sp->gua_[i] += tmp[i];
			px__sp_mul(w, wp, wq, ku[c], p + wp - 1, q + wq, k1);
			px__sp_mul(one, p - wp, q - wq, k1, p + 2 * wp - 1, q + 2 * wq,
			      sp->gub_ + c * ngu);
			px__sp_mul(h, p, q, kv[c], p + wp, q + wq - 1, tmp);
			nk = px__sp_tsize(sp->gvn_, sp->gvm_);
			for (i = 0; i < nk; i++)
				sp->gva_[i] += tmp[i];
			px__sp_mul(w, wp, wq, kv[c], p + wp, q + wq - 1, k1);
			px__sp_mul(one, p - wp, q - wq, k1, p + 2 * wp, q + 2 * wq - 1,
			      sp->gvb_ + c * ngv);
			/* w^2 f = |H|^2 - 2 P . (w H) + |P|^2 w^2, all raised
			 * to degree (2p, 2q). */
			px__sp_mul(h, p, q, h, p, q, tmp);
			for (i = 0; i < nfs; i++)
				sp->fa_[i] += tmp[i];
			px__sp_mul(w, wp, wq, h, p, q, k1);
			px__sp_mul(one, p - wp, q - wq, k1, p + wp, q + wq, sp->fb_ + c * nfs);
		}
		px__sp_mul(w, wp, wq, w, wp, wq, k1);
		px__sp_mul(one, 2 * (p - wp), 2 * (q - wq), k1, 2 * wp, 2 * wq, sp->fw_);
	}
	return PX_OK;
}

/* ---- evaluation --------------------------------------------------------------- */


/* Bernstein basis of degree n (<= MD) at t, with first and second
 * derivatives when b1 / b2 are not NULL (both need n >= 1). */
static void basis(int n, double t, double *b0, double *b1, double *b2)
{
	double lo[MD + 1], u = 1.0 - t;
	int k, i;

	b0[0] = 1.0;
	if (!b1 && !b2) {
		for (k = 1; k <= n; k++)
			px__sp_raise(b0, k, t, u);
		return;
	}
	for (k = 1; k <= n - 2; k++)
		px__sp_raise(b0, k, t, u);
	if (b2) {
		/* Degree n - 2 values give the second derivative. */
		for (i = 0; i <= n; i++) {
			double a = (n >= 2 && i >= 2) ? b0[i - 2] : 0.0;
			double m = (n >= 2 && i >= 1 && i - 1 <= n - 2) ? b0[i - 1] : 0.0;
			double c = (n >= 2 && i <= n - 2) ? b0[i] : 0.0;
			b2[i] = n * (n - 1) * (a - 2.0 * m + c);
		}
	}
	if (n >= 2)
		px__sp_raise(b0, n - 1, t, u);
	for (i = 0; i < n; i++)
		lo[i] = b0[i];
	px__sp_raise(b0, n, t, u);
	if (b1)
		for (i = 0; i <= n; i++)
			b1[i] = n * ((i >= 1 ? lo[i - 1] : 0.0) - (i < n ? lo[i] : 0.0));
}

/* Point only: the hot path of sampling and candidate checks. */
px_vec3 px__sp_point(const struct px_spiece *sp, double s, double t)
{
	double bs[MD + 1], bt[MD + 1], acc[4] = {0, 0, 0, 0};
	int p = sp->p_, q = sp->q_, i, j;
	size_t np = px__sp_tsize(p, q);
	const double *h = sp->h_;

	basis(p, s, bs, NULL, NULL);
	basis(q, t, bt, NULL, NULL);
	for (i = 0; i <= p; i++)
		for (j = 0; j <= q; j++) {
			size_t k = (size_t)i * (q + 1) + j;
			double w = bs[i] * bt[j];
			acc[0] += w * h[k];
			acc[1] += w * h[np + k];
			acc[2] += w * h[2 * np + k];
			acc[3] += w * h[3 * np + k];
		}
	return px_v3(acc[0] / acc[3], acc[1] / acc[3], acc[2] / acc[3]);
}

px_vec3 px_spiece_eval(const struct px_spiece *sp, double s, double t,
		       px_vec3 *su, px_vec3 *sv, px_vec3 *suu, px_vec3 *suv,
		       px_vec3 *svv)
{
	double bs[3][MD + 1], bt[3][MD + 1];
	/* d[a][b][c]: derivative a in s, b in t of homogeneous component c */
	double d[3][3][4];
	int p = sp->p_, q = sp->q_, i, j, c;
	size_t np = px__sp_tsize(p, q);
	double ks = 1.0 / (sp->u1_ - sp->u0_), kt = 1.0 / (sp->v1_ - sp->v0_);
	px_vec3 S;

	if (!su && !sv && !suu && !suv && !svv)
		return px__sp_point(sp, s, t);
	basis(p, s, bs[0], bs[1], bs[2]);
	basis(q, t, bt[0], bt[1], bt[2]);
	memset(d, 0, sizeof(d));
	/* Row by row: the t-sums of a row (value, first and second
	 * derivative) first, then their s-weights; fewer products than
	 * weighting every control point six times. */
	for (c = 0; c < 4; c++) {
		const double *h = sp->h_ + c * np;
		for (i = 0; i <= p; i++) {
			const double *row = h + (size_t)i * (q + 1);
			double r0 = 0.0, r1 = 0.0, r2 = 0.0;
			for (j = 0; j <= q; j++) {
				r0 += bt[0][j] * row[j];
				r1 += bt[1][j] * row[j];
				r2 += bt[2][j] * row[j];
			}
			d[0][0][c] += bs[0][i] * r0;
			d[1][0][c] += bs[1][i] * r0;
			d[2][0][c] += bs[2][i] * r0;
			d[0][1][c] += bs[0][i] * r1;
			d[1][1][c] += bs[1][i] * r1;
			d[0][2][c] += bs[0][i] * r2;
		}
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
