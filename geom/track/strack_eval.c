/*
 * strack_eval.c - surface tracker (px_strack.h): surface evaluation (the
 * bicubic and rational patches, portable and AVX2/FMA) and Newton on the
 * gradient of the squared distance. The layout and the shared declarations
 * are in strack_internal.h.
 */
#include "strack_internal.h"

/* ------------------------------------------------------------------ */
/* evaluation and Newton                                               */

/* H, H_s, H_t, H_ss, H_st, H_tt of one coordinate of a patch (power
 * basis, rows along t) at (s, t) into h[0..5][k]: Horner in t over the
 * rows a_j(s) and their s-derivatives (V = H, H_t, H_tt; W = H_s, H_st;
 * X = H_ss). */
static inline __attribute__((always_inline)) void
eval_one(const double *c, int p, int q, double s, double t, double h[6][4],
	 int k)
{
	double V0 = 0, V1 = 0, V2 = 0, W0 = 0, W1 = 0, X0 = 0;
	int i, j;
	/* (unrolled where the degrees are constants: the bicubic call) */
#pragma GCC unroll 4
	for (j = q; j >= 0; j--) {
		const double *row = c + j * (p + 1);
		double a = row[p], a1 = 0.0, a2 = 0.0;
#pragma GCC unroll 4
		for (i = p - 1; i >= 0; i--) {
			a2 = a2 * s + 2.0 * a1;
			a1 = a1 * s + a;
			a = a * s + row[i];
		}
		V2 = V2 * t + 2.0 * V1;
		V1 = V1 * t + V0;
		V0 = V0 * t + a;
		W1 = W1 * t + W0;
		W0 = W0 * t + a1;
		X0 = X0 * t + a2;
	}
	h[0][k] = V0;
	h[1][k] = W0;
	h[2][k] = V1;
	h[3][k] = X0;
	h[4][k] = W1;
	h[5][k] = V2;
}

/* Two coordinates at once where the compiler has generic vectors (GCC,
 * clang): lane by lane eval_one()'s arithmetic in the same order, so
 * the same values bit for bit, in about half the instructions (the
 * evaluation is most of a hot update). */
#if defined(__GNUC__) && !defined(PX_STRACK_NO_VEC)
#define ST_VEC 1
typedef double st_v2 __attribute__((vector_size(16)));

static inline __attribute__((always_inline)) void
eval_pair(const double *c0, const double *c1, int p, int q, double s,
	  double t, double h[6][4], int k)
{
	const st_v2 S = {s, s}, T = {t, t}, two = {2.0, 2.0};
	st_v2 V0 = {0.0, 0.0}, V1 = V0, V2 = V0, W0 = V0, W1 = V0, X0 = V0;
	int i, j;
#pragma GCC unroll 4
	for (j = q; j >= 0; j--) {
		const double *r0 = c0 + j * (p + 1), *r1 = c1 + j * (p + 1);
		st_v2 a = {r0[p], r1[p]}, a1 = {0.0, 0.0}, a2 = {0.0, 0.0};
#pragma GCC unroll 4
		for (i = p - 1; i >= 0; i--) {
			const st_v2 ci = {r0[i], r1[i]};
			a2 = a2 * S + two * a1;
			a1 = a1 * S + a;
			a = a * S + ci;
		}
		V2 = V2 * T + two * V1;
		V1 = V1 * T + V0;
		V0 = V0 * T + a;
		W1 = W1 * T + W0;
		W0 = W0 * T + a1;
		X0 = X0 * T + a2;
	}
	h[0][k] = V0[0], h[0][k + 1] = V0[1];
	h[1][k] = W0[0], h[1][k + 1] = W0[1];
	h[2][k] = V1[0], h[2][k + 1] = V1[1];
	h[3][k] = X0[0], h[3][k + 1] = X0[1];
	h[4][k] = W1[0], h[4][k + 1] = W1[1];
	h[5][k] = V2[0], h[5][k + 1] = V2[1];
}
#else
#define ST_VEC 0
#endif

/* All four coordinates of a bicubic at once (x, y, z, w in the lanes of
 * one 256-bit vector, fused multiply-adds) where the processor has
 * AVX2 and FMA (checked at setup: have_fma()); eval_one()'s
 * Horner scheme, each multiply-add rounded once. About a third of the
 * instructions of the two-lane form, and the evaluation is most of a
 * hot update. */
#if defined(__GNUC__) && defined(__x86_64__) && !defined(PX_STRACK_NO_VEC)
#include <immintrin.h>
#define ST_FMA 1
__attribute__((target("avx2,fma"))) static void
eval4_bicubic(const double *c4, double s, double t, double h[6][4])
{
	const __m256d S = _mm256_set1_pd(s), T = _mm256_set1_pd(t);
	__m256d V0 = _mm256_setzero_pd(), V1 = V0, V2 = V0, W0 = V0, W1 = V0,
		X0 = V0;
	int i, j;
	for (j = 3; j >= 0; j--) {
		const double *row = c4 + 16 * j;
		__m256d a = _mm256_load_pd(row + 12), a1 = _mm256_setzero_pd(),
			a2 = a1;
		for (i = 2; i >= 0; i--) {
			a2 = _mm256_fmadd_pd(a2, S, _mm256_add_pd(a1, a1));
			a1 = _mm256_fmadd_pd(a1, S, a);
			a = _mm256_fmadd_pd(a, S, _mm256_load_pd(row + 4 * i));
		}
		V2 = _mm256_fmadd_pd(V2, T, _mm256_add_pd(V1, V1));
		V1 = _mm256_fmadd_pd(V1, T, V0);
		V0 = _mm256_fmadd_pd(V0, T, a);
		W1 = _mm256_fmadd_pd(W1, T, W0);
		W0 = _mm256_fmadd_pd(W0, T, a1);
		X0 = _mm256_fmadd_pd(X0, T, a2);
	}
	_mm256_storeu_pd(h[0], V0);
	_mm256_storeu_pd(h[1], W0);
	_mm256_storeu_pd(h[2], V1);
	_mm256_storeu_pd(h[3], X0);
	_mm256_storeu_pd(h[4], W1);
	_mm256_storeu_pd(h[5], V2);
}

#ifdef PX_TEST_HOOKS
int px__strack_no_fma = 0;
#endif

int px__st_have_fma(void)
{
	return !px__strack_no_fma && __builtin_cpu_supports("avx2") &&
	       __builtin_cpu_supports("fma");
}
#else
#define ST_FMA 0
#ifdef PX_TEST_HOOKS
int px__strack_no_fma = 0;
#endif
int px__st_have_fma(void)
{
	return 0;
}
#endif

/* Point and derivatives up to order 2 from the patch holding (u, v). */
void px__st_surf_eval2(const struct ssurf *f, double u, double v,
		       struct px_nurbs_surf_derivs *d)
{
	const struct patch *pt;
	/* H, Hs, Ht, Hss, Hst, Htt by coordinate x, y, z, w */
	double s, t, h[6][4];
	int p, q;
	size_t n;
	pt = &f->pt[bsearch_bounds(f->pv, f->npv, v) * f->npu +
		    bsearch_bounds(f->pu, f->npu, u)];
	p = pt->p;
	q = pt->q;
	n = (size_t)(p + 1) * (size_t)(q + 1);
	s = (u - pt->u0) * pt->iu;
	t = (v - pt->v0) * pt->iv;
#if ST_FMA
	if (pt->c4)
		eval4_bicubic(pt->c4, s, t, h);
	else
#endif
#if ST_VEC
	if (p == 3 && q == 3) {
		/* bicubic, the usual patch: the loops unrolled */
		eval_pair(pt->c, pt->c + 16, 3, 3, s, t, h, 0);
		if (pt->rat)
			eval_pair(pt->c + 32, pt->c + 48, 3, 3, s, t, h, 2);
		else
			eval_one(pt->c + 32, 3, 3, s, t, h, 2);
	} else {
		eval_pair(pt->c, pt->c + n, p, q, s, t, h, 0);
		if (pt->rat)
			eval_pair(pt->c + 2 * n, pt->c + 3 * n, p, q, s, t, h, 2);
		else
			eval_one(pt->c + 2 * n, p, q, s, t, h, 2);
	}
#else
	{
		int k;
		for (k = 0; k < (pt->rat ? 4 : 3); k++)
			eval_one(pt->c + (size_t)k * n, p, q, s, t, h, k);
	}
#endif
	if (!pt->rat) {
		/* polynomial (weights normalised to 1 at setup) */
		d->s = px_v3(h[0][0], h[0][1], h[0][2]);
		d->su = px_v3(h[1][0] * pt->iu, h[1][1] * pt->iu, h[1][2] * pt->iu);
		d->sv = px_v3(h[2][0] * pt->iv, h[2][1] * pt->iv, h[2][2] * pt->iv);
		d->suu = px_v3_scale(px_v3(h[3][0], h[3][1], h[3][2]), pt->iu * pt->iu);
		d->suv = px_v3_scale(px_v3(h[4][0], h[4][1], h[4][2]), pt->iu * pt->iv);
		d->svv = px_v3_scale(px_v3(h[5][0], h[5][1], h[5][2]), pt->iv * pt->iv);
		return;
	}
	{
		double w = h[0][3], iw = 1.0 / w, ws = h[1][3], wt = h[2][3],
		       wss = h[3][3], wst = h[4][3], wtt = h[5][3];
		px_vec3 C, Cs, Ct, Css, Cst, Ctt;
		C = px_v3(h[0][0] * iw, h[0][1] * iw, h[0][2] * iw);
		Cs = px_v3((h[1][0] - ws * C.x) * iw, (h[1][1] - ws * C.y) * iw,
			   (h[1][2] - ws * C.z) * iw);
		Ct = px_v3((h[2][0] - wt * C.x) * iw, (h[2][1] - wt * C.y) * iw,
			   (h[2][2] - wt * C.z) * iw);
		Css = px_v3((h[3][0] - 2.0 * ws * Cs.x - wss * C.x) * iw,
			    (h[3][1] - 2.0 * ws * Cs.y - wss * C.y) * iw,
			    (h[3][2] - 2.0 * ws * Cs.z - wss * C.z) * iw);
		Ctt = px_v3((h[5][0] - 2.0 * wt * Ct.x - wtt * C.x) * iw,
			    (h[5][1] - 2.0 * wt * Ct.y - wtt * C.y) * iw,
			    (h[5][2] - 2.0 * wt * Ct.z - wtt * C.z) * iw);
		Cst = px_v3((h[4][0] - ws * Ct.x - wt * Cs.x - wst * C.x) * iw,
			    (h[4][1] - ws * Ct.y - wt * Cs.y - wst * C.y) * iw,
			    (h[4][2] - ws * Ct.z - wt * Cs.z - wst * C.z) * iw);
		d->s = C;
		d->su = px_v3_scale(Cs, pt->iu);
		d->sv = px_v3_scale(Ct, pt->iv);
		d->suu = px_v3_scale(Css, pt->iu * pt->iu);
		d->suv = px_v3_scale(Cst, pt->iu * pt->iv);
		d->svv = px_v3_scale(Ctt, pt->iv * pt->iv);
	}
}

/* z evaluated at its (u, v) for p: point, first derivatives, Hessian
 * of E; the gradient of E into grad_out and the surface derivatives
 * into d. */
void px__st_crit_eval_d(const struct ssurf *f, struct crit *z, px_vec3 p,
			px_vec3 *grad_out, struct px_nurbs_surf_derivs *d)
{
	px_vec3 w;
	px__st_surf_eval2(f, z->u, z->v, d);
	w = px_v3_sub(d->s, p);
	z->s = d->s;
	z->su = d->su;
	z->sv = d->sv;
	z->h11 = px_v3_dot(d->su, d->su) + px_v3_dot(w, d->suu);
	z->h12 = px_v3_dot(d->su, d->sv) + px_v3_dot(w, d->suv);
	z->h22 = px_v3_dot(d->sv, d->sv) + px_v3_dot(w, d->svv);
	grad_out->x = px_v3_dot(w, d->su);
	grad_out->y = px_v3_dot(w, d->sv);
	grad_out->z = 0.0;
}

/* Bring (u, v) into the domain: wrap a seam direction; 1 when an open
 * direction is left. */
static int domain_fix(const struct ssurf *f, double *u, double *v)
{
	if (*u < f->u0 || *u > f->u1) {
		if (!f->wrap_u)
			return 1;
		*u = f->u0 + fmod(*u - f->u0, f->du);
		if (*u < f->u0)
			*u += f->du;
	}
	if (*v < f->v0 || *v > f->v1) {
		if (!f->wrap_v)
			return 1;
		*v = f->v0 + fmod(*v - f->v0, f->dv);
		if (*v < f->v0)
			*v += f->dv;
	}
	return 0;
}

/* Distance of (u, v) from the nearest collapsed edge, relative to the
 * domain (1 when none is nearer): below 1e-9, a zero of E there is the
 * pole, not an interior critical point (snewton() rejects it). */
double px__st_pole_gap(const struct ssurf *f, double u, double v)
{
	return fmin(fmin(f->pole[0] ? u - f->u0 : f->du, f->pole[1] ? f->u1 - u : f->du) /
			    f->du,
		    fmin(f->pole[2] ? v - f->v0 : f->dv, f->pole[3] ? f->v1 - v : f->dv) /
			    f->dv);
}

/*
 * The Hessian at z far from singular: its eigenvalues within a factor 10
 * of each other in size. Newton then converges quadratically from a step
 * away, the error left O(step^2 / span) (a near-fold point, where one
 * eigenvalue goes to 0, converges linearly and a short step says
 * little); on a rational patch whose weights are far apart the
 * parametrization's own speed changes too fast for the constant to be
 * small (ST_QUICK_WRATIO).
 */
static inline int well_posed(const struct crit *z)
{
	double d = z->h11 - z->h22, tr = z->h11 + z->h22;
	double disc = sqrt(d * d + 4.0 * z->h12 * z->h12);
	double a = fabs(tr + disc), b = fabs(tr - disc);
	return a < b ? a >= 0.1 * b : b >= 0.1 * a;
}

/*
 * Newton on E = 0 with p fixed from z->u, z->v; steps clamped to lu, lv.
 * Returns 0 with z evaluated at the root, 1 on failure (no convergence,
 * singular Hessian, the domain left through an open edge).
 */
int px__st_snewton(const struct ssurf *f, struct crit *z, px_vec3 p,
		   double lu, double lv, const struct scell *home)
{
	double tu = 1e-11 * f->du, tv = 1e-11 * f->dv;
	double qu = 1e-6 * f->du, qv = 1e-6 * f->dv;
	int k, outs = 0;
	for (k = 0; k < ST_NEWTON; k++) {
		struct px_nurbs_surf_derivs d;
		px_vec3 g;
		double det, su, sv;
		int tiny;
		if (domain_fix(f, &z->u, &z->v)) {
			/* an overshoot past an open edge: back onto it (a
			 * point just inside the edge is reached from there);
			 * pushing out again means the point has left */
			if (++outs > 2)
				return 1;
			z->u = fmin(fmax(z->u, f->u0 + 1e-9 * f->du), f->u1 - 1e-9 * f->du);
			z->v = fmin(fmax(z->v, f->v0 + 1e-9 * f->dv), f->v1 - 1e-9 * f->dv);
		}
		px__st_crit_eval_d(f, z, p, &g, &d);
		det = z->h11 * z->h22 - z->h12 * z->h12;
		if (has_pole(f)) {
			/* At a collapsed edge u = u0 the v-derivative vanishes,
			 * so (S - p) . Sv = 0 holds along the whole edge: a
			 * spurious root set that attracts Newton. Solve with
			 * that equation divided by the distance to the edge
			 * (regular there) and reject the edge itself (the pole
			 * is a candidate of its own). */
			double du0 = z->u - f->u0, du1 = f->u1 - z->u;
			double dv0 = z->v - f->v0, dv1 = f->v1 - z->v;
			double bu = 1.0, bup = 0.0, av = 1.0, avp = 0.0;
			double j11, j12, j21, j22, g1, g2, dj;
			if (f->pole[0] && f->pole[1]) {
				bu = 1.0 / (du0 * du1);
				bup = -(du1 - du0) * bu * bu;
			} else if (f->pole[0]) {
				bu = 1.0 / du0;
				bup = -bu * bu;
			} else if (f->pole[1]) {
				bu = 1.0 / du1;
				bup = bu * bu;
			}
			if (f->pole[2] && f->pole[3]) {
				av = 1.0 / (dv0 * dv1);
				avp = -(dv1 - dv0) * av * av;
			} else if (f->pole[2]) {
				av = 1.0 / dv0;
				avp = -av * av;
			} else if (f->pole[3]) {
				av = 1.0 / dv1;
				avp = av * av;
			}
			if (px__st_pole_gap(f, z->u, z->v) < 1e-9)
				return 1;
			g1 = g.x * av;
			g2 = g.y * bu;
			j11 = z->h11 * av;
			j12 = z->h12 * av + g.x * avp;
			j21 = z->h12 * bu + g.y * bup;
			j22 = z->h22 * bu;
			dj = j11 * j22 - j12 * j21;
			if (!(fabs(dj) > 0.0))
				return 1;
			su = -(j22 * g1 - j12 * g2) / dj;
			sv = -(-j21 * g1 + j11 * g2) / dj;
		} else {
			if (!(fabs(det) > 0.0))
				return 1;
			su = -(z->h22 * g.x - z->h12 * g.y) / det;
			sv = -(-z->h12 * g.x + z->h11 * g.y) / det;
		}
		if (!isfinite(su) || !isfinite(sv))
			return 1;
		if (fabs(su) <= tu && fabs(sv) <= tv) {
			z->type = crit_type(z);
			return 0;
		}
		tiny = fabs(su) <= qu && fabs(sv) <= qv;
		if ((tiny || (fabs(su) <= f->quick_u && fabs(sv) <= f->quick_v &&
			      (f->quick_loose || well_posed(z)))) &&
		    z->u + su >= f->u0 && z->u + su <= f->u1 && z->v + sv >= f->v0 &&
		    z->v + sv <= f->v1) {
			/* quadratic convergence: after this step the error is
			 * O(step^2), far below the tolerance; move the point by
			 * the second-order Taylor step instead of evaluating
			 * again. (To first order the point is off the surface by
			 * S'' step^2 / 2, along the normal, so straight into
			 * the distance: 3.7e-9 of it on the rational sheet's
			 * 5 % steps, over the 1e-9 the answers are held to;
			 * below 1e-6 of the domain the first order is enough.) */
			z->u += su;
			z->v += sv;
			z->s = px_v3_add(z->s, px_v3_add(px_v3_scale(z->su, su),
							 px_v3_scale(z->sv, sv)));
			if (!tiny)
				z->s = px_v3_add(z->s, px_v3_add(px_v3_scale(d.suu, 0.5 * su * su),
								 px_v3_add(px_v3_scale(d.suv, su * sv),
									   px_v3_scale(d.svv, 0.5 * sv * sv))));
			z->type = crit_type(z);
			return 0;
		}
		if (fabs(su) > lu)
			su = su > 0 ? lu : -lu;
		if (fabs(sv) > lv)
			sv = sv > 0 ? lv : -lv;
		z->u += su;
		z->v += sv;
		if (home) {
			/* a seed heading out of its cell (beyond one cell width)
			 * converges to a point its own cell answers for */
			double w = home->u1 - home->u0, h = home->v1 - home->v0;
			if (z->u < home->u0 - w || z->u > home->u1 + w ||
			    z->v < home->v0 - h || z->v > home->v1 + h)
				return 1;
		}
	}
	return 1;
}
