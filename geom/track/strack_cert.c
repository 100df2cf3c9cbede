/*
 * strack_cert.c - surface tracker (px_strack.h): the region certificates
 * made at setup: Taylor enclosures of the patches and their derivatives
 * over each cell and quarter, the side tests, the winding pieces. The
 * layout and the shared declarations are in strack_internal.h.
 */
#include "strack_internal.h"

/* Distinct knot values of one direction inside the domain, with both
 * ends: the Bezier patch bounds. Returns the count. */
int px__st_span_bounds(const struct px_nurbs_surf *s, int dir, double a,
		       double b, double *out)
{
	const double *U = s->knots[dir];
	int i, n = 0;
	out[n++] = a;
	for (i = 0; i < s->n_knots[dir]; i++)
		if (U[i] > out[n - 1] && U[i] < b)
			out[n++] = U[i];
	out[n++] = b;
	return n;
}

/*
 * Enclosures of the homogeneous coordinates (k = 0..3) of the difference
 * nets of the Bezier net P ((p + 1) x (q + 1), u fastest, 4 per point),
 * all in one pass over the net: the derivative of order (a, b) in (u, v)
 * is a Bezier patch whose control points are the forward differences
 * times p!/(p - a)! q!/(q - b)! / (du^a dv^b); its range lies within
 * their hull. r[0]: order (0, 0), r[1] (1, 0), r[2] (0, 1), r[3] (2, 0),
 * r[4] (1, 1), r[5] (0, 2); an order above the degree is 0.
 */
static void net_ranges(const double *P, int p, int q, double du, double dv,
		       struct iv r[6][4])
{
	static const int oa[6] = {0, 1, 0, 2, 1, 0}, ob[6] = {0, 0, 1, 0, 1, 2};
	int i, j, k, o, n = p + 1;
	for (o = 0; o < 6; o++)
		for (k = 0; k < 4; k++) {
			r[o][k].lo = INFINITY;
			r[o][k].hi = -INFINITY;
		}
#define NR_AT(a, b) P[4 * ((b) * n + (a)) + k]
	for (j = 0; j <= q; j++)
		for (i = 0; i <= p; i++)
			for (k = 0; k < 4; k++) {
				double x = NR_AT(i, j);
				/* the sums in the order of the signed binomial
				 * terms (v outer, u inner) */
				iv_grow(&r[0][k], x);
				if (i < p)
					iv_grow(&r[1][k], -x + NR_AT(i + 1, j));
				if (j < q)
					iv_grow(&r[2][k], -x + NR_AT(i, j + 1));
				if (i + 1 < p)
					iv_grow(&r[3][k], (x - 2.0 * NR_AT(i + 1, j)) + NR_AT(i + 2, j));
				if (i < p && j < q)
					iv_grow(&r[4][k], ((x - NR_AT(i + 1, j)) - NR_AT(i, j + 1)) +
							      NR_AT(i + 1, j + 1));
				if (j + 1 < q)
					iv_grow(&r[5][k], (x - 2.0 * NR_AT(i, j + 1)) + NR_AT(i, j + 2));
			}
#undef NR_AT
	for (o = 0; o < 6; o++) {
		double f = 1.0;
		for (i = 0; i < oa[o]; i++)
			f *= (double)(p - i) / du;
		for (j = 0; j < ob[o]; j++)
			f *= (double)(q - j) / dv;
		for (k = 0; k < 4; k++) {
			struct iv *x = &r[o][k];
			if (oa[o] > p || ob[o] > q) {
				*x = iv_pt(0.0);
				continue;
			}
			/* f > 0: rounding is monotone, so the scaled bounds are
			 * the bounds of the scaled differences */
			x->lo *= f;
			x->hi *= f;
			*x = iv_pad(*x);
		}
	}
}

static void cert_fill(struct rcert *ce, const struct iv Su[3], const struct iv Sv[3],
		      double du, double dv);
static void net_ranges3(const double *P, int p, int q, double du, double dv,
			struct iv r[4][4]);

/*
 * Rational patches: the interval quotient rule on S = X / W counts the
 * ranges of S, S_u, W, W_u ... as if independent, and its enclosures of
 * the derivatives come out several times wider than the polynomial
 * case's (certificate radii 0.25 against 0.81 on the same net with unit
 * weights). The numerators of the derivatives over a power of W are
 * polynomials, products of Bernstein tensor polynomials: their hulls
 * are tight. Setup only (allocates).
 */
struct tpoly {
	int m, n;       /* degrees in u, v */
	double *c;      /* (m + 1) (n + 1), u fastest */
	double mag;     /* bound on the rounding of its coefficients */
};

#define TP_LEN ((3 * PX_NURBS_MAX_DEGREE + 1) * (3 * PX_NURBS_MAX_DEGREE + 1))

static void tp_net(const double *pw, int p, int q, int k, struct tpoly *o)
{
	int i;
	o->m = p;
	o->n = q;
	o->mag = 0.0;
	for (i = 0; i < (p + 1) * (q + 1); i++) {
		o->c[i] = pw[4 * i + k];
		o->mag = fmax(o->mag, 1e-16 * fabs(o->c[i]));
	}
}

/* Derivative along u (dir 0, box width h) or v. */
static void tp_d(const struct tpoly *a, int dir, double h, struct tpoly *o)
{
	int i, j, m = a->m, n = a->n;
	double f = (dir ? n : m) / h;
	o->m = dir ? m : m - 1;
	o->n = dir ? n - 1 : n;
	o->mag = 2.0 * f * a->mag;
	for (j = 0; j <= o->n; j++)
		for (i = 0; i <= o->m; i++) {
			double x1 = dir ? a->c[(j + 1) * (m + 1) + i] : a->c[j * (m + 1) + i + 1];
			o->c[j * (o->m + 1) + i] = f * (x1 - a->c[j * (m + 1) + i]);
		}
}

/* Binomials C(n, k) for n up to the numerators' degrees. */
#define TP_DEG (3 * PX_NURBS_MAX_DEGREE)
struct tp_binom {
	double c[TP_DEG + 1][TP_DEG + 1];
};

static void tp_binom_init(struct tp_binom *b)
{
	int n, k;
	for (n = 0; n <= TP_DEG; n++) {
		b->c[n][0] = b->c[n][n] = 1.0;
		for (k = 1; k < n; k++)
			b->c[n][k] = b->c[n - 1][k - 1] + b->c[n - 1][k];
	}
}

/* o = a b (o not a or b; scratch: TP_LEN): the coefficients times their
 * binomials convolve, then divided by the product's; each is a convex
 * combination of the products a_i b_j (Vandermonde), so its rounding is
 * at most a few units of the terms' count times amax bmax. */
static void tp_mul(const struct tpoly *a, const struct tpoly *b, struct tpoly *o,
		   const struct tp_binom *bc, double *scratch)
{
	int i, j, x, y, M = a->m + b->m, N = a->n + b->n, na = (a->m + 1) * (a->n + 1);
	double amax = 0.0, bmax = 0.0;
	o->m = M;
	o->n = N;
	for (i = 0; i < (M + 1) * (N + 1); i++)
		o->c[i] = 0.0;
	for (j = 0; j <= b->n; j++)
		for (i = 0; i <= b->m; i++) {
			double v = b->c[j * (b->m + 1) + i];
			bmax = fmax(bmax, fabs(v));
			scratch[j * (b->m + 1) + i] = v * bc->c[b->m][i] * bc->c[b->n][j];
		}
	for (j = 0; j <= a->n; j++)
		for (i = 0; i <= a->m; i++) {
			double ca = a->c[j * (a->m + 1) + i];
			amax = fmax(amax, fabs(ca));
			ca *= bc->c[a->m][i] * bc->c[a->n][j];
			for (y = 0; y <= b->n; y++) {
				double *restrict row = o->c + (j + y) * (M + 1) + i;
				const double *restrict bs = scratch + y * (b->m + 1);
				for (x = 0; x <= b->m; x++)
					row[x] += ca * bs[x];
			}
		}
	for (j = 0; j <= N; j++)
		for (i = 0; i <= M; i++)
			o->c[j * (M + 1) + i] /= bc->c[M][i] * bc->c[N][j];
	o->mag = amax * b->mag + bmax * a->mag + 2.3e-16 * (na + 4) * amax * bmax;
}

/* y += s a (the same degrees). */
static void tp_axpy(struct tpoly *y, double s, const struct tpoly *a)
{
	int i;
	for (i = 0; i < (y->m + 1) * (y->n + 1); i++)
		y->c[i] += s * a->c[i];
	y->mag += fabs(s) * a->mag + 1e-16 * fabs(s);
}

/* a raised to degrees (m, n) (not below its own), into o (not a;
 * scratch: TP_LEN). */
static void tp_elevate(const struct tpoly *a, int m, int n, struct tpoly *o,
		       double *scratch)
{
	double *cur = scratch, *nxt = o->c, *sw;
	int cm = a->m, cn = a->n, i, j;
	memcpy(cur, a->c, (size_t)((cm + 1) * (cn + 1)) * sizeof(double));
	for (; cm < m; cm++) {
		for (j = 0; j <= cn; j++)
			for (i = 0; i <= cm + 1; i++) {
				double x = (double)i / (cm + 1);
				double lo = i > 0 ? cur[j * (cm + 1) + i - 1] : 0.0;
				double hi = i <= cm ? cur[j * (cm + 1) + i] : 0.0;
				nxt[j * (cm + 2) + i] = x * lo + (1.0 - x) * hi;
			}
		sw = cur;
		cur = nxt;
		nxt = sw;
	}
	for (; cn < n; cn++) {
		for (j = 0; j <= cn + 1; j++)
			for (i = 0; i <= cm; i++) {
				double x = (double)j / (cn + 1);
				double lo = j > 0 ? cur[(j - 1) * (cm + 1) + i] : 0.0;
				double hi = j <= cn ? cur[j * (cm + 1) + i] : 0.0;
				nxt[j * (cm + 1) + i] = x * lo + (1.0 - x) * hi;
			}
		sw = cur;
		cur = nxt;
		nxt = sw;
	}
	if (cur != o->c)
		memcpy(o->c, cur, (size_t)((cm + 1) * (cn + 1)) * sizeof(double));
	o->m = cm;
	o->n = cn;
	/* convex combinations: no growth beyond a rounding each */
	o->mag = a->mag * (1.0 + 1e-15 * (m + n));
}

/* The range of a / d over the box, d > 0 of a's degrees: a / d is a
 * convex combination of the ratios of their Bernstein coefficients
 * (weights d_i B_i / sum d_j B_j), so it lies within their hull. */
static struct iv tp_ratio_range(const struct tpoly *a, const struct tpoly *d)
{
	struct iv r = {INFINITY, -INFINITY};
	int i;
	for (i = 0; i < (a->m + 1) * (a->n + 1); i++) {
		double x, e;
		if (!(d->c[i] > 0.0)) {
			r.lo = -INFINITY;
			r.hi = INFINITY;
			return r;
		}
		x = a->c[i] / d->c[i];
		e = (8.0 * a->mag + 1e-15 * fabs(a->c[i])) / d->c[i] +
		    fabs(x) * (8.0 * d->mag / d->c[i] + 1e-15);
		iv_grow(&r, x - e);
		iv_grow(&r, x + e);
	}
	return iv_pad(r);
}

/* Test hook (track_hooks.h): 1 shrinks rat_tight()'s enclosures to a
 * third of their width about their midpoints (unsound: the focal test
 * must see it). Read at setup. */
#ifdef PX_TEST_HOOKS
int px__strack_rat_fault = 0;
#endif

static struct iv iv_meet(struct iv a, struct iv b)
{
	struct iv r = {a.lo > b.lo ? a.lo : b.lo, a.hi < b.hi ? a.hi : b.hi};
	if (px__strack_rat_fault) {
		double m = 0.5 * (b.lo + b.hi), h = (b.hi - b.lo) / 6.0;
		r.lo = m - h;
		r.hi = m + h;
		return r;
	}
	return r.lo <= r.hi ? r : a;
}

/* y += s a b (tmp: a product's room; as tp_mul() then tp_axpy()). */
static void tp_muladd(struct tpoly *y, double s, const struct tpoly *a,
		      const struct tpoly *b, struct tpoly *tmp, const struct tp_binom *bc,
		      double *scratch)
{
	tp_mul(a, b, tmp, bc, scratch);
	tp_axpy(y, s, tmp);
}

/* *x met with the range of num / den: num raised to den's degrees (into
 * el), then the hull of the coefficients' ratios. */
static void tp_bound(struct iv *x, const struct tpoly *num, const struct tpoly *den,
		     struct tpoly *el, double *scratch)
{
	tp_elevate(num, den->m, den->n, el, scratch);
	*x = iv_meet(*x, tp_ratio_range(el, den));
}

/*
 * Tighter enclosures of the derivatives of S = X / W for each coordinate
 * of a rational net (degrees 2 or more): S_u = A_u / W^2 with
 * A_u = X_u W - X W_u, S_uu = (X_uu W^2 - X W W_uu - 2 W_u A_u) / W^3,
 * S_uv = ((X_uv W + X_u W_v - X_v W_u - X W_uv) W - 2 W_v A_u) / W^3, and
 * so for v; each numerator raised to its power of W's degree and
 * bounded by the ratios of their coefficients. They are met with the
 * interval quotient rule's (both hold). mem: ST_RAT_POLYS * TP_LEN
 * doubles; W's products once for the three coordinates.
 */
enum {
	R_X, R_W, R_XU, R_XV, R_WU, R_WV, R_XUU, R_XUV, R_XVV, R_WUU, R_WUV, R_WVV,
	R_AU, R_AV, R_T1, R_T2, R_W2, R_W3, R_EL, R_SC, R_XW, ST_RAT_POLYS
};
/* Coordinate k of the net and its derivatives to order 2 (du, dv: the
 * cell's sides), into t[f], t[fu], ... */
static void tp_jet(const double *pw, int p, int q, int k, double du, double dv,
		   struct tpoly *t, int f, int fu, int fv, int fuu, int fuv, int fvv)
{
	tp_net(pw, p, q, k, &t[f]);
	tp_d(&t[f], 0, du, &t[fu]);
	tp_d(&t[f], 1, dv, &t[fv]);
	tp_d(&t[fu], 0, du, &t[fuu]);
	tp_d(&t[fu], 1, dv, &t[fuv]);
	tp_d(&t[fv], 1, dv, &t[fvv]);
}

static void rat_tight(const double *pw, int p, int q, double du, double dv,
		      struct iv Su[3], struct iv Sv[3], struct iv Suu[3], struct iv Suv[3],
		      struct iv Svv[3], double *mem, const struct tp_binom *bc)
{
	struct tpoly t[ST_RAT_POLYS];
	double *sc;
	int i, k;
	for (i = 0; i < ST_RAT_POLYS; i++)
		t[i].c = mem + (size_t)i * TP_LEN;
	sc = t[R_SC].c;
	tp_jet(pw, p, q, 3, du, dv, t, R_W, R_WU, R_WV, R_WUU, R_WUV, R_WVV);
	tp_mul(&t[R_W], &t[R_W], &t[R_W2], bc, sc);
	tp_mul(&t[R_W2], &t[R_W], &t[R_W3], bc, sc);
	for (k = 0; k < 3; k++) {
		int d;
		tp_jet(pw, p, q, k, du, dv, t, R_X, R_XU, R_XV, R_XUU, R_XUV, R_XVV);
		tp_mul(&t[R_X], &t[R_W], &t[R_XW], bc, sc);
		for (d = 0; d < 2; d++) {
			/* A_d = X_d W - X W_d over W^2; S_dd W^3 = X_dd W^2 -
			 * (X W) W_dd - 2 W_d A_d */
			int xd = d ? R_XV : R_XU, wd = d ? R_WV : R_WU, ad = d ? R_AV : R_AU;
			tp_mul(&t[xd], &t[R_W], &t[ad], bc, sc);
			tp_muladd(&t[ad], -1.0, &t[R_X], &t[wd], &t[R_T1], bc, sc);
			tp_bound(d ? &Sv[k] : &Su[k], &t[ad], &t[R_W2], &t[R_EL], sc);
			tp_mul(&t[d ? R_XVV : R_XUU], &t[R_W2], &t[R_T1], bc, sc);
			tp_muladd(&t[R_T1], -1.0, &t[R_XW], &t[d ? R_WVV : R_WUU], &t[R_T2], bc,
				  sc);
			tp_muladd(&t[R_T1], -2.0, &t[wd], &t[ad], &t[R_T2], bc, sc);
			tp_bound(d ? &Svv[k] : &Suu[k], &t[R_T1], &t[R_W3], &t[R_EL], sc);
		}
		/* S_uv W^3: (X_uv W + X_u W_v - X_v W_u - X W_uv) W - 2 W_v A_u */
		tp_mul(&t[R_XUV], &t[R_W], &t[R_T1], bc, sc);
		tp_muladd(&t[R_T1], 1.0, &t[R_XU], &t[R_WV], &t[R_T2], bc, sc);
		tp_muladd(&t[R_T1], -1.0, &t[R_XV], &t[R_WU], &t[R_T2], bc, sc);
		tp_muladd(&t[R_T1], -1.0, &t[R_X], &t[R_WUV], &t[R_T2], bc, sc);
		tp_mul(&t[R_T1], &t[R_W], &t[R_T2], bc, sc);
		tp_muladd(&t[R_T2], -2.0, &t[R_WV], &t[R_AU], &t[R_T1], bc, sc);
		tp_bound(&Suv[k], &t[R_T2], &t[R_W3], &t[R_EL], sc);
	}
}

/*
 * The enclosures of certificate ce over a box of size du x dv from its
 * Bezier net pw ((p + 1) x (q + 1) homogeneous points, u fastest): S and
 * its derivatives up to order 2, the first fundamental form, the
 * midpoint-radius form of H, and the bounds of the third derivatives
 * that the certificates of its sub-boxes are made from (taylor_cert()).
 * Returns 0, or PX_E_INVAL where the weights are not positive.
 */
static int net_cert(const double *pw, int p, int q, double du, double dv,
		    struct rcert *ce)
{
	struct iv W, Wu, Wv, Wuu, Wuv, Wvv, Su[3], Sv[3], nr[6][4];
	double *mem = NULL;
	int k, i, rational = 0;
	memset(ce, 0, sizeof(*ce));
	for (i = 1; i < (p + 1) * (q + 1); i++)
		rational |= pw[4 * i + 3] != pw[3];
	net_ranges(pw, p, q, du, dv, nr);
	W = nr[0][3];
	if (!(W.lo > 0.0))
		return PX_E_INVAL;
	ce->rat = rational;
	if (rational && p >= 2 && q >= 2) {
		mem = malloc((size_t)ST_RAT_POLYS * TP_LEN * sizeof(double) +
			     sizeof(struct tp_binom));
		if (!mem)
			return PX_E_NOMEM;
		tp_binom_init((struct tp_binom *)(mem + (size_t)ST_RAT_POLYS * TP_LEN));
	}
	Wu = nr[1][3];
	Wv = nr[2][3];
	Wuu = nr[3][3];
	Wuv = nr[4][3];
	Wvv = nr[5][3];
	for (k = 0; k < 3; k++) {
		struct iv S = {INFINITY, -INFINITY};
		/* the surface lies in the hull of its projected net */
		for (i = 0; i < (p + 1) * (q + 1); i++)
			iv_grow(&S, pw[4 * i + k] / pw[4 * i + 3]);
		S = iv_pad(S);
		ce->S[k] = S;
		/* quotient rule on S = X / W, differentiated */
		Su[k] = iv_pad(iv_divw(iv_sub(nr[1][k],
					      iv_mul(S, Wu)), W));
		Sv[k] = iv_pad(iv_divw(iv_sub(nr[2][k],
					      iv_mul(S, Wv)), W));
		ce->Suu[k] = iv_pad(iv_divw(
			iv_sub(iv_sub(nr[3][k],
				      iv_scale(iv_mul(Su[k], Wu), 2.0)),
			       iv_mul(S, Wuu)), W));
		ce->Svv[k] = iv_pad(iv_divw(
			iv_sub(iv_sub(nr[5][k],
				      iv_scale(iv_mul(Sv[k], Wv), 2.0)),
			       iv_mul(S, Wvv)), W));
		ce->Suv[k] = iv_pad(iv_divw(
			iv_sub(iv_sub(iv_sub(nr[4][k],
					     iv_mul(Su[k], Wv)),
				      iv_mul(Sv[k], Wu)),
			       iv_mul(S, Wuv)), W));
	}
	if (mem)
		rat_tight(pw, p, q, du, dv, Su, Sv, ce->Suu, ce->Suv, ce->Svv, mem,
			  (const struct tp_binom *)(mem + (size_t)ST_RAT_POLYS * TP_LEN));
	free(mem);
	{
		/* third derivatives, for the certificates of sub-boxes
		 * (taylor_cert()): X = S W differentiated three times */
		struct iv n3[4][4], Wt[4];
		net_ranges3(pw, p, q, du, dv, n3);
		for (i = 0; i < 4; i++)
			Wt[i] = n3[i][3];
		for (k = 0; k < 3; k++) {
			struct iv S = ce->S[k], T[4];
			T[0] = iv_sub(iv_sub(iv_sub(n3[0][k], iv_scale(iv_mul(ce->Suu[k], Wu), 3.0)),
					     iv_scale(iv_mul(Su[k], Wuu), 3.0)),
				      iv_mul(S, Wt[0]));
			T[1] = iv_sub(iv_sub(iv_sub(iv_sub(iv_sub(n3[1][k], iv_mul(ce->Suu[k], Wv)),
						      iv_scale(iv_mul(ce->Suv[k], Wu), 2.0)),
					       iv_scale(iv_mul(Su[k], Wuv), 2.0)),
					iv_mul(Sv[k], Wuu)),
				      iv_mul(S, Wt[1]));
			T[2] = iv_sub(iv_sub(iv_sub(iv_sub(iv_sub(n3[2][k], iv_mul(ce->Svv[k], Wu)),
						      iv_scale(iv_mul(ce->Suv[k], Wv), 2.0)),
					       iv_scale(iv_mul(Sv[k], Wuv), 2.0)),
					iv_mul(Su[k], Wvv)),
				      iv_mul(S, Wt[2]));
			T[3] = iv_sub(iv_sub(iv_sub(n3[3][k], iv_scale(iv_mul(ce->Svv[k], Wv), 3.0)),
					     iv_scale(iv_mul(Sv[k], Wvv), 3.0)),
				      iv_mul(S, Wt[3]));
			for (i = 0; i < 4; i++)
				ce->t3[i][k] = iv_mag(iv_pad(iv_divw(iv_pad(T[i]), W)));
		}
	}
	cert_fill(ce, Su, Sv, du, dv);
	return PX_OK;
}

/* The rest of certificate ce from its enclosures of S, Su, Sv and the
 * second derivatives over a box of size du x dv: the first fundamental
 * form, the bounds m_ij and the midpoint-radius form of H. */
static void cert_fill(struct rcert *ce, const struct iv Su[3], const struct iv Sv[3],
		      double du, double dv)
{
	int k, i;
	ce->G11 = ce->G12 = ce->G22 = iv_pt(0.0);
	ce->m11 = ce->m12 = ce->m22 = 0.0;
	for (k = 0; k < 3; k++) {
		struct iv a = Su[k], b = Sv[k], sa = iv_mul(a, a), sb = iv_mul(b, b);
		/* squares are not negative */
		if (a.lo <= 0.0 && a.hi >= 0.0)
			sa.lo = 0.0;
		if (b.lo <= 0.0 && b.hi >= 0.0)
			sb.lo = 0.0;
		ce->G11 = iv_add(ce->G11, sa);
		ce->G22 = iv_add(ce->G22, sb);
		ce->G12 = iv_add(ce->G12, iv_mul(a, b));
		ce->m11 += iv_mag(ce->Suu[k]);
		ce->m12 += iv_mag(ce->Suv[k]);
		ce->m22 += iv_mag(ce->Svv[k]);
	}
	ce->G11 = iv_pad(ce->G11);
	ce->G12 = iv_pad(ce->G12);
	ce->G22 = iv_pad(ce->G22);
	{
		/* midpoint-radius form: (S - x) . Sij with S = sm +- sr,
		 * Sij = hm +- hr per coordinate lies in
		 * (sm - x) . hm +- (|sm - x| . hr + sr . |hm| + sr . hr) */
		const struct iv *G[3] = {&ce->G11, &ce->G12, &ce->G22};
		const struct iv *D[3] = {ce->Suu, ce->Suv, ce->Svv};
		double *sm = &ce->smid.x;
		for (k = 0; k < 3; k++)
			sm[k] = 0.5 * (ce->S[k].lo + ce->S[k].hi);
		for (i = 0; i < 3; i++) {
			double *b = &ce->B[i].x, *qq = &ce->Q[i].x;
			ce->A[i] = 0.5 * (G[i]->lo + G[i]->hi);
			ce->R[i] = 0.5 * (G[i]->hi - G[i]->lo);
			for (k = 0; k < 3; k++) {
				double hm = 0.5 * (D[i][k].lo + D[i][k].hi);
				double hr = 0.5 * (D[i][k].hi - D[i][k].lo);
				double sr = 0.5 * (ce->S[k].hi - ce->S[k].lo);
				b[k] = hm;
				qq[k] = hr;
				ce->A[i] += sm[k] * hm;
				ce->R[i] += sr * fabs(hm) + sr * hr;
			}
			ce->R[i] = iv_pad(iv_pt(ce->R[i])).hi;
		}
	}
	ce->hu = 0.5 * du;
	ce->hv = 0.5 * dv;
}

/*
 * Enclosures of the third difference nets of the Bezier net P (as
 * net_ranges() the lower ones), every homogeneous coordinate: r[0] order
 * (3, 0), r[1] (2, 1), r[2] (1, 2), r[3] (0, 3); an order above the
 * degree is 0.
 */
static void net_ranges3(const double *P, int p, int q, double du, double dv,
			struct iv r[4][4])
{
	int i, j, k, o, n = p + 1;
	for (o = 0; o < 4; o++) {
		int a = 3 - o, b = o, x, y;
		double f = 1.0;
		for (i = 0; i < a; i++)
			f *= (double)(p - i) / du;
		for (j = 0; j < b; j++)
			f *= (double)(q - j) / dv;
		for (k = 0; k < 4; k++) {
			struct iv *z = &r[o][k];
			if (a > p || b > q) {
				*z = iv_pt(0.0);
				continue;
			}
			z->lo = INFINITY;
			z->hi = -INFINITY;
			for (j = 0; j + b <= q; j++)
				for (i = 0; i + a <= p; i++) {
					double d = 0.0;
					for (y = 0; y <= b; y++)
						for (x = 0; x <= a; x++)
							d += ((a - x + b - y) & 1 ? -1.0 : 1.0) *
							     px_bern_binom(a, x) * px_bern_binom(b, y) *
							     P[4 * ((j + y) * n + i + x) + k];
					iv_grow(z, d);
				}
			z->lo *= f;
			z->hi *= f;
			*z = iv_pad(*z);
		}
	}
}

/* The centre values of certificate ce from the evaluation d there. */
static void centre_set(struct rcert *ce, const struct px_nurbs_surf_derivs *d)
{
	ce->sc = d->s;
	ce->suc = d->su;
	ce->svc = d->sv;
	ce->n1 = fabs(d->su.x) + fabs(d->su.y) + fabs(d->su.z);
	ce->n2 = fabs(d->sv.x) + fabs(d->sv.y) + fabs(d->sv.z);
	/* (hu, hv and the m_ij are set: cert_fill() comes first) */
	ce->ie1 = 1.0 / (ce->n1 + ce->m11 * ce->hu + ce->m12 * ce->hv);
	ce->ie2 = 1.0 / (ce->n2 + ce->m12 * ce->hu + ce->m22 * ce->hv);
	ce->im11 = 1.0 / ce->m11;
	ce->im22 = 1.0 / ce->m22;
}

/*
 * Certificate of sub-box b (u0, u1, v0, v1) of the box of certificate
 * top, at update time: the values at b's centre and the mean value
 * theorem per coordinate, S_uu in S_uu(c) +- (|S_uuu| h_u + |S_uuv| h_v)
 * and so on down to S, with top's third-derivative bounds (they hold
 * over every piece of its box); then cert_fill(). About as wide as b:
 * the width falls with the piece, which a hull of the box's own net
 * cut down to it would give too, at a small part of the cost.
 */
void px__st_taylor_cert(const struct ssurf *f, const double b[4],
			const struct rcert *top, struct rcert *ce)
{
	struct px_nurbs_surf_derivs d;
	struct iv Su[3], Sv[3];
	double hu = 0.5 * (b[1] - b[0]), hv = 0.5 * (b[3] - b[2]);
	int k;
	memset(ce, 0, sizeof(*ce));
	px__st_surf_eval2(f, b[0] + hu, b[2] + hv, &d);
	for (k = 0; k < 3; k++) {
		const double *t = &top->t3[0][0];
		double s = (&d.s.x)[k], su = (&d.su.x)[k], sv = (&d.sv.x)[k];
		double suu = (&d.suu.x)[k], suv = (&d.suv.x)[k], svv = (&d.svv.x)[k];
		double ruu = t[0 * 3 + k] * hu + t[1 * 3 + k] * hv;
		double ruv = t[1 * 3 + k] * hu + t[2 * 3 + k] * hv;
		double rvv = t[2 * 3 + k] * hu + t[3 * 3 + k] * hv;
		struct iv x;
		x.lo = suu - ruu;
		x.hi = suu + ruu;
		ce->Suu[k] = iv_pad(x);
		x.lo = suv - ruv;
		x.hi = suv + ruv;
		ce->Suv[k] = iv_pad(x);
		x.lo = svv - rvv;
		x.hi = svv + rvv;
		ce->Svv[k] = iv_pad(x);
		ruu = iv_mag(ce->Suu[k]) * hu + iv_mag(ce->Suv[k]) * hv;
		rvv = iv_mag(ce->Suv[k]) * hu + iv_mag(ce->Svv[k]) * hv;
		x.lo = su - ruu;
		x.hi = su + ruu;
		Su[k] = iv_pad(x);
		x.lo = sv - rvv;
		x.hi = sv + rvv;
		Sv[k] = iv_pad(x);
		ruu = iv_mag(Su[k]) * hu + iv_mag(Sv[k]) * hv;
		x.lo = s - ruu;
		x.hi = s + ruu;
		ce->S[k] = iv_pad(x);
	}
	cert_fill(ce, Su, Sv, 2.0 * hu, 2.0 * hv);
	centre_set(ce, &d);
}

/* The centre values of certificate ce of box (u0, u1, v0, v1). */
static void cert_centre(const struct ssurf *f, double u0, double u1, double v0,
			double v1, struct rcert *ce)
{
	struct px_nurbs_surf_derivs d;
	px__st_surf_eval2(f, 0.5 * (u0 + u1), 0.5 * (v0 + v1), &d);
	centre_set(ce, &d);
}

/* Certificate data of region cell c (setup; work: extraction scratch). */
int px__st_cell_cert(struct px_strack *t, struct scell *c, const struct ssurf *f,
		     double *work, size_t wl, const int side_open[4])
{
	struct rcert *ce = &c->cert;
	struct px_nurbs_surf sub;
	double du = c->u1 - c->u0, dv = c->v1 - c->v0;
	int p = f->s.degree[0], q = f->s.degree[1], rc;
	rc = px_nurbs_surf_extract_work(&f->s, c->u0, c->u1, c->v0, c->v1, work,
					wl, &sub);
	if (rc)
		return rc;
	if (sub.n_ctrl[0] != p + 1 || sub.n_ctrl[1] != q + 1)
		return PX_E_INVAL;
	rc = net_cert(sub.pw, p, q, du, dv, ce);
	if (rc)
		return rc;
	cert_centre(f, c->u0, c->u1, c->v0, c->v1, ce);
	px__st_cert_sides(f, c, ce, side_open);
	(void)t;
	return PX_OK;
}

/* The side tests' data of certificate ce (hu, hv set) of box c for its
 * open sides (side_open: u0, u1, v0, v1). */
void px__st_cert_sides(const struct ssurf *f, const struct scell *c, struct rcert *ce,
		       const int side_open[4])
{
	struct px_nurbs_surf_derivs d;
	double du = c->u1 - c->u0, dv = c->v1 - c->v0;
	int k;
	ce->nside = 0;
	for (k = 0; k < 4; k++) {
		struct cside *sd;
		double u, v;
		if (!side_open[k])
			continue;
		sd = &ce->side[ce->nside++];
		/* sides 0, 1: u = u0, u1 (along v); 2, 3: v = v0, v1 */
		u = k == 0 ? c->u0 : k == 1 ? c->u1 : 0.5 * (c->u0 + c->u1);
		v = k == 2 ? c->v0 : k == 3 ? c->v1 : 0.5 * (c->v0 + c->v1);
		/* evaluate on the cell's own patch (one-sided at a crease) */
		u = fmin(fmax(u, c->u0 + 1e-13 * du), c->u1 - 1e-13 * du);
		v = fmin(fmax(v, c->v0 + 1e-13 * dv), c->v1 - 1e-13 * dv);
		px__st_surf_eval2(f, u, v, &d);
		sd->s = d.s;
		sd->su = d.su;
		sd->sv = d.sv;
		sd->n1 = fabs(d.su.x) + fabs(d.su.y) + fabs(d.su.z);
		sd->n2 = fabs(d.sv.x) + fabs(d.sv.y) + fabs(d.sv.z);
		sd->along = k < 2;
		sd->h = k < 2 ? ce->hv : ce->hu;
		/* the side point is off the exact side by 1e-13 of the cell:
		 * cover it in the half length */
		sd->h *= 1.0 + 1e-12;
	}
}

/* 1 when x is a break of the surface along dir where it is less than
 * C2 (knot multiplicity above degree - 2): points enter and leave a
 * patch there as through an edge. */
static int crease_at(const struct ssurf *f, int dir, double x)
{
	return px__nurbs_mult(f->s.knots[dir], f->s.n_knots[dir], x) >
	       f->s.degree[dir] - 2;
}

/* Which sides of cell c are open domain edges or creases (u0, u1, v0,
 * v1): where critical points enter and leave. */
void px__st_sides_open(const struct ssurf *f, const struct scell *c, int open[4])
{
	open[0] = c->u0 == f->u0 ? !f->wrap_u : crease_at(f, 0, c->u0);
	open[1] = c->u1 == f->u1 ? !f->wrap_u : crease_at(f, 0, c->u1);
	open[2] = c->v0 == f->v0 ? !f->wrap_v : crease_at(f, 1, c->v0);
	open[3] = c->v1 == f->v1 ? !f->wrap_v : crease_at(f, 1, c->v1);
}

/* Quarter k of region cell rg as a cell of its own (bounds and
 * surface; box_of()). */
static void quarter_of(const struct scell *rg, int k, struct scell *q)
{
	double b[4];
	memset(q, 0, sizeof(*q));
	q->surf = rg->surf;
	px__st_box_of(rg, k, b);
	q->u0 = b[0];
	q->u1 = b[1];
	q->v0 = b[2];
	q->v1 = b[3];
}

/* The entry of side k (sides_open()'s order) among c's side tests:
 * cell_cert() keeps the open sides alone, in that order. */
static int side_entry(const struct ssurf *f, const struct scell *c, int k)
{
	int open[4], a, n = 0;
	px__st_sides_open(f, c, open);
	for (a = 0; a < k; a++)
		n += open[a];
	return n;
}

/* The certificates of the four quarters of region cell rg. */
int px__st_quarter_certs(struct px_strack *t, const struct scell *rg,
			 const struct ssurf *f, double *work, size_t wl,
			 struct rcert out[4])
{
	int k, rc, open[4];
	for (k = 0; k < 4; k++) {
		struct scell q;
		quarter_of(rg, k, &q);
		px__st_sides_open(f, &q, open);
		rc = px__st_cell_cert(t, &q, f, work, wl, open);
		if (rc)
			return rc;
		out[k] = q.cert;
	}
	return 0;
}

/* The boundary pieces of surface si for winding() (after the region
 * and quarter certificates are made). Returns 0 or PX_E_NOMEM. */
int px__st_wind_pieces(struct px_strack *t, int si)
{
	struct ssurf *f = &t->sf[si];
	int nu = 2 * f->ncu, nv = 2 * f->ncv, e, n, i;
	f->wind_ok = 0;
	f->nwp = 0;
	/* E jumps at a C0 line */
	if (has_pole(f) || px_nurbs_surf_breaks(&f->s, 0, NULL, 0) > 0 ||
	    px_nurbs_surf_breaks(&f->s, 1, NULL, 0) > 0)
		return 0;
	n = (f->wrap_v ? 0 : 2 * nu) + (f->wrap_u ? 0 : 2 * nv);
	if (n > 0) {
		f->wp = calloc((size_t)n, sizeof(*f->wp));
		if (!f->wp)
			return PX_E_NOMEM;
	}
	/* e 0: v = v0, u rising; 1: u = u1, v rising; 2: v = v1, u falling;
	 * 3: u = u0, v falling (counter-clockwise) */
	for (e = 0; e < 4; e++) {
		int len = e & 1 ? nv : nu, side = (int[]){2, 1, 3, 0}[e];
		/* the quarters along the side, in the order traversed */
		static const int qk[4][2] = {{0, 1}, {1, 3}, {3, 2}, {2, 0}};
		if ((e & 1) ? f->wrap_u : f->wrap_v)
			continue;
		for (i = 0; i < len; i++) {
			int s2 = e >= 2 ? len - 1 - i : i;
			int I = e == 0 ? s2 : e == 1 ? nu - 1 : e == 2 ? s2 : 0;
			int J = e == 0 ? 0 : e == 1 ? s2 : e == 2 ? nv - 1 : s2;
			int ri = 4 * (f->first_cell + (J / 2) * f->ncu + I / 2) + (I & 1) + 2 * (J & 1);
			const struct scell *rg = &t->rcell[ri];
			struct wpiece *w = &f->wp[f->nwp++];
			int q;
			double x0, x1;
			w->ri = ri;
			w->side = side_entry(f, rg, side);
			for (q = 0; q < 2; q++) {
				struct scell qc;
				quarter_of(rg, qk[e][q], &qc);
				w->qk[q] = qk[e][q];
				w->qside[q] = side_entry(f, &qc, side);
			}
			x0 = e & 1 ? (e == 1 ? rg->v0 : rg->v1) : (e == 0 ? rg->u0 : rg->u1);
			x1 = e & 1 ? (e == 1 ? rg->v1 : rg->v0) : (e == 0 ? rg->u1 : rg->u0);
			for (q = 0; q < 3; q++) {
				struct px_nurbs_surf_derivs d;
				double x = x0 + 0.5 * q * (x1 - x0);
				double u = e & 1 ? (e == 1 ? f->u1 : f->u0) : x;
				double v = e & 1 ? x : (e == 0 ? f->v0 : f->v1);
				px__st_surf_eval2(f, u, v, &d);
				w->s[q] = d.s;
				w->su[q] = d.su;
				w->sv[q] = d.sv;
			}
		}
	}
	f->wind_ok = 1;
	return 0;
}
