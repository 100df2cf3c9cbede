/*
 * strack_proof.c - surface tracker (px_strack.h): the lazy tests of the
 * transition boxes: certified radii, emptiness and uniqueness proofs, the
 * winding-number index check, the expiry groups and the collection of due
 * cells. The layout and the shared declarations are in strack_internal.h.
 */
#include "strack_internal.h"

/* ------------------------------------------------------------------ */
/* transition boxes: lazy tests                                        */

/*
 * Certified radius of a region cell at p: no transition of the cell
 * happens while the point stays in the cube |x - p|_inf <= r. A pair of
 * critical points is born or dies only at a degenerate critical point,
 * E = 0 and det H = 0 (the focal sheets, Seong-Johnson-Cohen section
 * 4.3), and a point enters or leaves only through a side that is an open
 * edge or a crease. For x in the cube and (u, v) in the cell:
 *  - H_ij = Si.Sj + (S - x).Sij lies in [H_ij(p)] + [-r m_ij, r m_ij];
 *  - E(u, v; x) lies in E(c; p) +- r |Su(c)|_1 + [H] * (cell half
 *    widths) (mean value form about the centre c, dE/du = (H11, H12)).
 * The cell is safe when E1 or E2 keeps its sign (no critical point at
 * all), or when det H keeps its sign (no degenerate one: the points only
 * move) and on every open side E1 or E2 keeps its sign. Each condition
 * is monotone in r; the radius is the largest r that keeps one of them
 * (closed forms: linear in r for E, quadratic for det H). Curvatures are
 * never divided by, so parabolic lines and umbilics need no care.
 */

/* Test hook (track_hooks.h): 0 leaves the preconditioned test out, 2 drops
 * its remainder terms (unsound). */
#ifdef PX_TEST_HOOKS
int px__strack_precond = 1;
#endif

/* Y, the inverse of the symmetric mid (entries 11, 12, 22), and
 * q = |I - Y mid| (zero but for rounding; padded by the rounding of the
 * products): the preconditioner of the Krawczyk tests. 0 when mid is
 * singular. */
static int precond(const double mid[3], double y[2][2], double q[2][2])
{
	double det = mid[0] * mid[2] - mid[1] * mid[1];
	if (!(fabs(det) > 0.0))
		return 0;
	y[0][0] = mid[2] / det;
	y[0][1] = y[1][0] = -mid[1] / det;
	y[1][1] = mid[0] / det;
	if (!(isfinite(y[0][0]) && isfinite(y[0][1]) && isfinite(y[1][1])))
		return 0;
	q[0][0] = fabs(1.0 - (y[0][0] * mid[0] + y[0][1] * mid[1])) + 1e-12;
	q[0][1] = fabs(y[0][0] * mid[1] + y[0][1] * mid[2]) + 1e-12;
	q[1][0] = fabs(y[1][0] * mid[0] + y[1][1] * mid[1]) + 1e-12;
	q[1][1] = fabs(1.0 - (y[1][0] * mid[1] + y[1][1] * mid[2])) + 1e-12;
	return 1;
}

/*
 * The E test preconditioned (Krawczyk's exclusion): by the mean value
 * theorem E(c + d) = E(c) + J d, each row of J the Hessian's at some point
 * of the cell, so a zero at c + d gives d = -Y E(c) + (I - Y J) d for any
 * Y; with Y the inverse of the midpoint of the Hessian's enclosure, a row
 * i with |(Y E(c))_i| > h_i + sum_j |I - Y J|_ij h_j proves there is none.
 * Unlike the plain test this sees where Newton from the centre would go:
 * a cell beside a critical point (its E small in both components, the
 * point just across a side) is proven empty when the step leads out of
 * it. For x in the cube of radius r about p, E(c) moves by r |Su(c)|_1
 * (resp. Sv) and J by r m_ij, so each row's test is linear in r: the
 * largest r that keeps one of them. mid and rad: the Hessian enclosure
 * at p (rad with its rounding pad), e1, e2: E(c) at p (signed), epad
 * their rounding.
 */
double px__st_pre_radius(const struct rcert *c, const double mid[3],
			 const double rad_in[3], double e1, double e2, double epad)
{
	double y[2][2], q[2][2], best = 0.0;
	double rad[3] = {rad_in[0], rad_in[1], rad_in[2]};
	int i;
	if (!px__strack_precond || !precond(mid, y, q))
		return 0.0;
	if (px__strack_precond == 2)
		rad[0] = rad[1] = rad[2] = 0.0;
	for (i = 0; i < 2; i++) {
		double a = fabs(y[i][0]), b = fabs(y[i][1]);
		double ye = y[i][0] * e1 + y[i][1] * e2;
		double num = fabs(ye) - (a + b) * epad -
			     ST_PAD * (a * fabs(e1) + b * fabs(e2)) -
			     (i ? c->hv : c->hu) -
			     c->hu * (q[i][0] + a * rad[0] + b * rad[1]) -
			     c->hv * (q[i][1] + a * rad[1] + b * rad[2]);
		double den = a * c->n1 + b * c->n2 +
			     c->hu * (a * c->m11 + b * c->m12) +
			     c->hv * (a * c->m12 + b * c->m22);
		double r = num / den;
		if (r > best)
			best = r;
	}
	return best;
}

/* Open side sd, w = S - p at its centre, M11, M12, M22 bounds of |H|
 * over the cell: num[i] > 0 proves Ei keeps its sign along the side at
 * p (mean value form along it); cert_radius() divides it by the rate at
 * which it falls as the point moves. */
static inline void side_num(const struct cside *sd, px_vec3 w, double epad,
			    double M11, double M12, double M22, double num[2])
{
	num[0] = fabs(px_v3_dot(w, sd->su)) - epad - (sd->along ? M12 : M11) * sd->h;
	num[1] = fabs(px_v3_dot(w, sd->sv)) - epad - (sd->along ? M22 : M12) * sd->h;
}

static double cert_radius(const struct rcert *c, px_vec3 p)
{
	double mid[3], rad[3], a11, b11, a22, b22, M11, M12, M22,
	       m11 = c->m11, m12 = c->m12, m22 = c->m22, rE, rD, r, e1, e2, epad;
	px_vec3 w;
	int k;
	hess_at(c, p, mid, rad);
	a11 = mid[0] - rad[0];
	b11 = mid[0] + rad[0];
	a22 = mid[2] - rad[2];
	b22 = mid[2] + rad[2];
	M11 = fabs(mid[0]) + rad[0];
	M12 = fabs(mid[1]) + rad[1];
	M22 = fabs(mid[2]) + rad[2];
	/* E test */
	w = px_v3_sub(c->sc, p);
	e1 = px_v3_dot(w, c->suc);
	e2 = px_v3_dot(w, c->svc);
	epad = e_pad(c, w, p);
	rE = e_radius(c, M11, M12, M22, e1, e2, epad);
	/* det H test */
	rD = 0.0;
	{
		double x = 0.0, y = 0.0;
		int definite = 0;
		if (a11 > 0.0 && a22 > 0.0) {
			x = a11;
			y = a22;
			definite = 1;
		} else if (b11 < 0.0 && b22 < 0.0) {
			x = -b11;
			y = -b22;
			definite = 1;
		} else if (a11 > 0.0 && b22 < 0.0) {
			rD = ST_MIN(a11 * c->im11, -b22 * c->im22);
		} else if (b11 < 0.0 && a22 > 0.0) {
			rD = ST_MIN(-b11 * c->im11, a22 * c->im22);
		}
		if (definite) {
			/* f(r) = (x - r m11)(y - r m22) - (M12 + r m12)^2 falls
			 * on [0, min(x / m11, y / m22)]: its first root */
			double A = m11 * m22 - m12 * m12;
			double B = -(x * m22 + y * m11) - 2.0 * M12 * m12;
			double C = x * y - M12 * M12;
			double cap = ST_MIN(x * c->im11, y * c->im22);
			if (C > 0.0) {
				double disc = B * B - 4.0 * A * C;
				double root = disc < 0.0 ? INFINITY
							 : 2.0 * C / (-B + sqrt(disc));
				rD = ST_MIN(cap, root);
			}
		}
		if (!(rD > 0.0))
			rD = 0.0;
	}
	if (!(rE > 0.0) && !(rD > 0.0)) {
		/* neither: the preconditioned E test (costs as much again,
		 * so only here) */
		rE = px__st_pre_radius(c, mid, rad, e1, e2, epad);
	}
	for (k = 0; k < c->nside && rD > rE; k++) {
		/* open side: E restricted to it, mean value form along it */
		const struct cside *sd = &c->side[k];
		double q1 = sd->along ? m12 : m11, q2 = sd->along ? m22 : m12;
		double num[2], r1, r2;
		side_num(sd, px_v3_sub(sd->s, p), epad, M11, M12, M22, num);
		r1 = num[0] / (sd->n1 + q1 * sd->h);
		r2 = num[1] / (sd->n2 + q2 * sd->h);
		r1 = r1 > r2 ? r1 : r2;
		r1 = r1 > 0.0 ? r1 : 0.0;
		rD = ST_MIN(rD, r1);
	}
	r = (rE > rD ? rE : rD) * ST_RSAFE;
	return r > 0.0 ? r : 0.0;
}

/* 1 when E is proven not to vanish on the cell for the point p: no
 * critical point there (the E tests of cert_radius() at r = 0); mid and
 * rad: hess_at() at p. */
int px__st_no_root_h(const struct rcert *c, px_vec3 p, const double mid[3],
		     const double rad[3])
{
	double mag[3], e1, e2, epad;
	px_vec3 w;
	int k;
	for (k = 0; k < 3; k++)
		mag[k] = fabs(mid[k]) + rad[k];
	w = px_v3_sub(c->sc, p);
	e1 = px_v3_dot(w, c->suc);
	e2 = px_v3_dot(w, c->svc);
	epad = e_pad(c, w, p);
	return fabs(e1) - epad > mag[0] * c->hu + mag[1] * c->hv ||
	       fabs(e2) - epad > mag[1] * c->hu + mag[2] * c->hv ||
	       px__st_pre_radius(c, mid, rad, e1, e2, epad) > 0.0;
}

/*
 * 1 when every symmetric matrix with entries 11, 12, 22 in [lo, hi] is
 * regular, and then (sig not NULL) a lower bound on the absolute values
 * of their eigenvalues into *sig. Definite (h11 h22 > h12^2 throughout,
 * the product rounded down): the least eigenvalue grows with the
 * diagonal and falls with |h12|, so the corner bounds it (the product
 * form avoids the cancellation of (x + y) / 2 - root); h11 h22 < 0 <=
 * h12^2: both |eigenvalues| are at least the lesser |diagonal|.
 */
int px__st_sym_regular(const double lo[3], const double hi[3], double *sig)
{
	double b = fmax(fabs(lo[1]), fabs(hi[1])), x, y, det;
	if ((lo[0] > 0.0 && lo[2] > 0.0) || (hi[0] < 0.0 && hi[2] < 0.0)) {
		x = lo[0] > 0.0 ? lo[0] : -hi[0];
		y = lo[0] > 0.0 ? lo[2] : -hi[2];
		det = x * y * (1.0 - 1e-12) - b * b;
		if (!(det > 0.0))
			return 0;
		if (sig)
			*sig = det / (0.5 * (x + y) + hypot(0.5 * (x - y), b));
		return 1;
	}
	if (lo[0] > 0.0 && hi[2] < 0.0) {
		if (sig)
			*sig = fmin(lo[0], -hi[2]);
		return 1;
	}
	if (hi[0] < 0.0 && lo[2] > 0.0) {
		if (sig)
			*sig = fmin(-hi[0], lo[2]);
		return 1;
	}
	return 0;
}

/* Test hook (track_hooks.h): 1 drops the Hessian enclosure's radius from
 * one_root() (unsound: its test must see it). */
#ifdef PX_TEST_HOOKS
int px__strack_one_fault = 0;
#endif

/*
 * 1 when every symmetric matrix in the Hessian's enclosure over the cell
 * at p is regular (the det H test of cert_radius() at r = 0): then the
 * cell holds at most one critical point, since E(a) - E(b) = M (a - b)
 * with M the Hessian averaged along the segment, a matrix of the
 * enclosure. mid, rad: hess_at() at p.
 */
int px__st_one_root_h(const double mid[3], const double rad[3])
{
	double lo[3], hi[3];
	int k;
	for (k = 0; k < 3; k++) {
		double r = px__strack_one_fault ? 0.0 : rad[k];
		lo[k] = mid[k] - r;
		hi[k] = mid[k] + r;
	}
	return px__st_sym_regular(lo, hi, NULL);
}

/* Test hook (track_hooks.h): 1 drops the Hessian enclosure's radius from
 * contract_rate() (unsound: its test must see it); 2 leaves every
 * contract_solve() undecided. */
#ifdef PX_TEST_HOOKS
int px__strack_contract_fault = 0;
#endif

/*
 * 1 when x - Y E(x), Y the inverse of the Hessian enclosure's midpoint,
 * contracts the cell at p (Krawczyk): by the mean value theorem
 * g(x) - g(x') = (I - Y J)(x - x') with the rows of J in the enclosure,
 * so in the norm weighted by the half widths the map shrinks distances
 * by rho = max_i sum_j |I - Y [H]|_ij h_j / h_i, into *rho, when that is
 * below 1. Every matrix of the enclosure is then regular: the cell holds
 * at most one critical point, and contract_solve() finds it or proves
 * there is none. mid, rad: hess_at() at p.
 */
int px__st_contract_h(const struct rcert *c, const double mid[3],
		      const double rad_in[3], double y[2][2], double *rho)
{
	double rad[3] = {rad_in[0], rad_in[1], rad_in[2]}, q[2][2], worst = 0.0;
	int i;
	if (px__strack_contract_fault)
		rad[0] = rad[1] = rad[2] = 0.0;
	if (!precond(mid, y, q))
		return 0;
	for (i = 0; i < 2; i++) {
		double a = fabs(y[i][0]), b = fabs(y[i][1]);
		double spread = c->hu * (q[i][0] + a * rad[0] + b * rad[1]) +
				c->hv * (q[i][1] + a * rad[1] + b * rad[2]);
		worst = fmax(worst, spread / (i ? c->hv : c->hu));
	}
	*rho = worst;
	return worst < ST_RHO_MAX;
}

/* Test hook (track_hooks.h): a factor on every certified radius. */
#ifdef PX_TEST_HOOKS
double px__strack_radius_scale = 1.0;
#endif

/* Test hook (track_hooks.h): 1 makes the curve tracker's certificate
 * (ct_note()) unbounded (unsound: a curve that comes nearer is missed). */
#ifdef PX_TEST_HOOKS
int px__strack_ct_fault = 0;
#endif

/* Test hook (track_hooks.h): 1 leaves the pieces out of the radii
 * (region_radius_full(), cell_radius()). */
#ifdef PX_TEST_HOOKS
int px__strack_piece_fault = 0;
#endif

/*
 * Certified radius at p of piece b of surface s, its certificate made as
 * a cut's (taylor_cert() from top, the certificate of a box holding it)
 * with the side tests of the open sides it lies on. The union argument
 * of region_radius() holds for the pieces as for quarters (pieces of a
 * second level gained nothing on the rational bench model).
 */
static double piece_radius(const struct px_strack *t, int s, const struct rcert *top,
			   const double b[4], px_vec3 p, int key, int j)
{
	const struct ssurf *f = &t->sf[s];
	struct rcert own, *rcp = &own;
	struct scell pc;
	int open[4];
	if (t->pcache_n > 0) {
		struct pcache *e = &t->pcache[key & (t->pcache_n - 1)];
		if (e->key != key) {
			e->key = key;
			e->filled = 0;
		}
		if (e->filled & (1u << j))
			return cert_radius(&e->rc[j], p);
		e->filled |= 1u << j; /* (made below) */
		rcp = &e->rc[j];
	}
	memset(&pc, 0, sizeof(pc));
	pc.surf = s;
	pc.u0 = b[0];
	pc.u1 = b[1];
	pc.v0 = b[2];
	pc.v1 = b[3];
	px__st_taylor_cert(f, b, top, rcp);
	px__st_sides_open(f, &pc, open);
	px__st_cert_sides(f, &pc, rcp, open);
	return cert_radius(rcp, p);
}

/*
 * The radius of a rational region whose quarters left it none: each
 * quarter without a radius stands for by its four pieces'
 * (piece_radius()). Where the parametrization varies fast, as at a
 * corner with weights far apart, a quarter's enclosures are too wide
 * ever to hold, and its cell would be due, tested and solved in every
 * update. On polynomial patches the pieces seldom hold where the
 * quarter does not (near a focal sheet) and cost more than they save:
 * not used there.
 */
double px__st_region_pieces(const struct px_strack *t, int ri, px_vec3 p)
{
	const struct scell *g = &t->rcell[ri];
	double r = INFINITY;
	int k, j;
	for (k = 0; k < 4 && r > 0.0; k++) {
		const struct rcert *q = &t->qcert[4 * ri + k];
		double b[4], sb[4], rq = cert_radius(q, p);
		if (!(rq > 0.0)) {
			px__st_box_of(g, k, b);
			rq = INFINITY;
			for (j = 0; j < 4 && rq > 0.0; j++) {
				px__st_box_quarter(b, j, sb);
				rq = fmin(rq, piece_radius(t, g->surf, q, sb, p, 4 * ri + k, j));
			}
		}
		r = fmin(r, rq);
	}
	return r;
}

/*
 * Certified radius of region cell ri at p; where its own certificate
 * gives none, or less than need, the least of its quarters' (each
 * quarter free of degenerate critical points, or of any, and the open
 * sides kept: so is their union, the interior sides between them being
 * no way in or out).
 */
double px__st_region_radius_to(const struct px_strack *t, int ri, px_vec3 p,
			       double need)
{
	/* (cert_radius() is never negative: none is r == 0) */
	double r = cert_radius(&t->rcell[ri].cert, p);
	if (!(r > 0.0) || r < need) {
		/* the quarters' enclosures are about half as wide, and their
		 * least radius is as good a proof for the region (the larger
		 * of the two stands); the loop stops once it cannot be */
		const struct rcert *q = &t->qcert[4 * ri];
		double rq = INFINITY;
		int k;
		for (k = 0; k < 4 && rq > r; k++)
			rq = fmin(rq, cert_radius(&q[k], p));
		if (rq > r)
			r = rq;
	}
	return r * px__strack_radius_scale;
}

/* ... and of a solve cell: its children's regions cover all of it. */
static __attribute__((noinline)) double cell_pieces(const struct px_strack *t,
						    const struct scell *c, px_vec3 p, double r0,
						    double r1, double r2, double r3);

double px__st_cell_radius_to(const struct px_strack *t, const struct scell *c,
			     px_vec3 p, double need)
{
	int ri = c->child;
	double r0 = px__st_region_radius_to(t, ri, p, need),
	       r1 = px__st_region_radius_to(t, ri + 1, p, need),
	       r2 = px__st_region_radius_to(t, ri + 2, p, need),
	       r3 = px__st_region_radius_to(t, ri + 3, p, need);
	double r = fmin(fmin(r0, r1), fmin(r2, r3));
	/* rational: quarters without a radius by their pieces (rarely run:
	 * out of line, so that the usual test stays as lean as it was) */
	if (!(r > 0.0) && t->rcell[ri].cert.rat && !px__strack_piece_fault)
		r = cell_pieces(t, c, p, r0, r1, r2, r3);
	return r;
}

/* cell_radius() where a region's radius (r0..r3) is none: by the
 * pieces of its quarters (the others as they were). */
static __attribute__((noinline)) double cell_pieces(const struct px_strack *t,
						    const struct scell *c, px_vec3 p, double r0,
						    double r1, double r2, double r3)
{
	const double r[4] = {r0, r1, r2, r3};
	double m = INFINITY;
	int i;
	for (i = 0; i < 4; i++)
		m = fmin(m, r[i] > 0.0 ? r[i]
				       : px__st_region_pieces(t, c->child + i, p) * px__strack_radius_scale);
	return m;
}

/*
 * Index check. A critical point's index is the sign of det H (+1 a
 * minimum or maximum, -1 a saddle), and by degree theory the index sum
 * of the critical points in the domain equals the winding number of
 * E = (E1, E2) along the domain's boundary (Poincare-Hopf for the plane;
 * a wrapped direction's seam sides cancel). Births and deaths keep the
 * sum, a point crossing an open edge changes it and the winding number
 * with it. A tracked set whose index sum differs from the winding number
 * is incomplete: a point a cell's seed grid missed, or a point followed
 * onto another's branch. It sees every miss whose indices do not
 * cancel, never a missing pair of a saddle and a minimum or maximum (the
 * escape bound keeps pairs from being carried out of the solved cells).
 *
 * The winding number is exact when each boundary side keeps E in an open
 * half plane (E1 or E2 of one sign on it: the open-side test of the
 * certificates): then the angle turned along the side is the principal
 * angle between its end values. Sides whose test fails are split into
 * their quarters' sides; when one of those fails too the winding number
 * is not known at p.
 */

/* Sign test of open side entry k of certificate c at p: 1 when E1 or E2
 * keeps its sign on the side. */
static int side_keeps(const struct rcert *c, int k, px_vec3 p)
{
	const struct cside *sd = &c->side[k];
	double mid[3], rad[3], num[2];
	px_vec3 w = px_v3_sub(sd->s, p);
	hess_at(c, p, mid, rad);
	side_num(sd, w, e_pad(c, w, p), fabs(mid[0]) + rad[0], fabs(mid[1]) + rad[1],
		 fabs(mid[2]) + rad[2], num);
	return num[0] > 0.0 || num[1] > 0.0;
}

/* The angle E turns from point a to point b of piece w at p (principal
 * value: E stays in a half plane between them). */
static double piece_turn(const struct wpiece *w, int a, int b, px_vec3 p)
{
	px_vec3 da = px_v3_sub(w->s[a], p), db = px_v3_sub(w->s[b], p);
	double a1 = px_v3_dot(da, w->su[a]), a2 = px_v3_dot(da, w->sv[a]);
	double b1 = px_v3_dot(db, w->su[b]), b2 = px_v3_dot(db, w->sv[b]);
	return atan2(a1 * b2 - a2 * b1, a1 * b1 + a2 * b2);
}

/* Test hook (track_hooks.h): 1 turns every boundary piece the wrong way
 * (the winding number negated: the check must see it). */
#ifdef PX_TEST_HOOKS
int px__strack_wind_fault = 0;
#endif

/* Winding number of E along f's boundary at p into *w: 1 when known,
 * 0 when not (a side whose test fails, or no boundary to use). */
int px__st_winding(const struct px_strack *t, const struct ssurf *f,
		   px_vec3 p, int *w)
{
	double sum = 0.0, x;
	int i, k;
	if (!f->wind_ok)
		return 0;
	for (i = 0; i < f->nwp; i++) {
		const struct wpiece *wp = &f->wp[i];
		if (side_keeps(&t->rcell[wp->ri].cert, wp->side, p)) {
			sum += piece_turn(wp, 0, 2, p);
			continue;
		}
		for (k = 0; k < 2; k++) {
			if (!side_keeps(&t->qcert[4 * wp->ri + wp->qk[k]], wp->qside[k], p))
				return 0;
			sum += piece_turn(wp, k, k + 1, p);
		}
	}
	if (px__strack_wind_fault)
		sum = -sum;
	x = sum / (2.0 * M_PI);
	*w = (int)lround(x);
	/* each turn is exact up to rounding: far from an integer means
	 * a side's end value was zero to rounding */
	return fabs(x - *w) < 1e-6;
}

static int crit_index(const struct crit *z)
{
	return z->type ? 1 : -1;
}

/* 1 when every surface whose winding number is known at p (the set's
 * point) has a held set of that index sum. */
static int ix_balanced(const struct px_strack *t, px_vec3 p)
{
	int i, k, w;
	for (i = 0; i < t->n_surf; i++) {
		const struct ssurf *f = &t->sf[i];
		int sum = 0;
		if (!px__st_winding(t, f, p, &w))
			continue;
		for (k = 0; k < f->nz; k++)
			sum += crit_index(&f->z[k]);
		if (sum != w)
			return 0;
	}
	return 1;
}

/* The check owed by a step whose membership changed, once its solves
 * are done: 0 when none is owed or it holds; 1 when it fails (counted:
 * the caller re-establishes the set). */
int px__st_ix_check(struct px_strack *t)
{
	if (!t->ix_on || t->pend_next < t->n_pend || t->fault_drop == 2)
		return 0;
	t->ix_on = 0;
	if (ix_balanced(t, t->p))
		return 0;
	t->st.unbalanced++;
	return 1;
}

/* Every group's least expiry and the least of all, afresh. */
void px__st_groups_rebuild(struct px_strack *t)
{
	int g, k, n = t->n_cells, ng = (n + ST_GROUP - 1) / ST_GROUP;
	double nd = INFINITY;
	for (g = 0; g < ng; g++) {
		int k1 = (g + 1) * ST_GROUP < n ? (g + 1) * ST_GROUP : n;
		double gm = INFINITY;
		for (k = g * ST_GROUP; k < k1; k++)
			gm = t->ex[k] < gm ? t->ex[k] : gm;
		t->gdue[g] = gm;
		nd = gm < nd ? gm : nd;
	}
	t->next_due = nd;
}

void px__st_expiries_rebuild(struct px_strack *t, px_vec3 p)
{
	int i;
	for (i = 0; i < t->n_cells; i++)
		cell_expire(t, &t->cell[i], p,
			    cell_radius(t, &t->cell[i], p) * (1.0 - 1e-9));
	px__st_groups_rebuild(t);
	t->ex_ok = 1;
	t->col_on = 0;
}

/* A due cell whose cube still holds the step's end with at least this
 * share of its half width to spare is not tested again: the path wound
 * about inside it (an expiry counts the path, not the way from the
 * centre); a test there would prove a cube about as large. Keeping one
 * costs a comparison, so the share can be small: the smaller it is, the
 * more tests a winding path is spared. */
#define ST_REKEY 0.1

/* Test hook (track_hooks.h): 1 takes the cubes twice as wide. */
#ifdef PX_TEST_HOOKS
int px__strack_rekey_fault = 0;
#endif
#ifdef PX_TEST_HOOKS
int px__strack_quick_fault = 0;
#endif

/* Start collecting the cells whose certificates the segment p0 -> p1
 * may break: the travel grows by the segment and the cells it makes due
 * are taken out (popped), to be tested by col_test().
 * A due cell whose cube still holds p1 well inside keeps it: p0 is in
 * it too (every cell's expiry less the travel is at most its half width
 * less the way of the point from its centre, by induction over the
 * steps), so the cube holds the segment; its expiry becomes the travel
 * plus what is left of the half width beyond p1, the same bound. */
static void col_begin(struct px_strack *t, px_vec3 p0, px_vec3 p1)
{
	int np = 0;
	if (!t->ex_ok)
		px__st_expiries_rebuild(t, p0);
	t->travel += px_v3_dist(p0, p1);
	t->ctravel += max_norm(px_v3_sub(p1, p0));
	if (t->next_due <= t->ctravel) {
		double nd = INFINITY, tr = t->ctravel, *ex = t->ex;
		int g, k, n = t->n_cells, ng = (n + ST_GROUP - 1) / ST_GROUP;
		for (g = 0; g < ng; g++) {
			int k1 = (g + 1) * ST_GROUP < n ? (g + 1) * ST_GROUP : n;
			double gm = INFINITY;
			if (!(t->gdue[g] <= tr)) {
				nd = t->gdue[g] < nd ? t->gdue[g] : nd;
				continue;
			}
			for (k = g * ST_GROUP; k < k1; k++) {
				if (ex[k] <= tr) {
					const struct cube *q = &t->cube[k];
					double left = q->crad * (px__strack_rekey_fault ? 2.0 : 1.0) -
						      max_norm(px_v3_sub(p1, q->ctr));
					if (left > ST_REKEY * q->crad) {
						ex[k] = tr + left;
						t->st.rekeys++;
					} else {
						/* its next expiry comes with its
						 * test (col_test(), col_end()) */
						t->popped[np++] = k;
						ex[k] = INFINITY;
					}
				}
				gm = ex[k] < gm ? ex[k] : gm;
			}
			t->gdue[g] = gm;
			nd = gm < nd ? gm : nd;
		}
		t->next_due = nd;
	}
	t->col_np = np;
	t->col_k = 0;
	t->col_nh = 0;
	t->col_p0 = p0;
	t->col_p1 = p1;
	t->col_on = 1;
}

/* Test up to limit (0: all) more of the popped cells; each gets its
 * next expiry, the hit ones go to hits. Returns 1 when all are tested. */
int px__st_col_test(struct px_strack *t, int limit)
{
	px_vec3 p0 = t->col_p0, p1 = t->col_p1;
	px_vec3 mid = px_v3_scale(px_v3_add(p0, p1), 0.5);
	/* the segment lies in the cube of half width dinf about p1 and in
	 * the cube of half width dinf / 2 about its middle */
	double dinf = max_norm(px_v3_sub(p1, p0));
	/* A region whose radius falls short of clearing the segment is
	 * given its quarters' too before the cell counts as hit: a hit cell
	 * is solved, and with the quarters fewer cells are solved at small
	 * and medium steps (the larger radii also put the next test off).
	 * Not while catching up: the segment then spans many updates'
	 * travel, most regions fall short of it by far and the quarters'
	 * work costs more than it saves. */
	double fine = t->mode == ST_TRACK ? 1.0 : 0.0;
	int end = t->col_np;
	if (limit > 0 && t->col_k + limit < end)
		end = t->col_k + limit;
	for (; t->col_k < end; t->col_k++) {
		int ci = t->popped[t->col_k];
		struct scell *c = &t->cell[ci];
		double r1 = px__st_cell_radius_to(t, c, p1, fine * dinf);
		t->st.box_tests++;
		if (r1 < dinf && px__st_cell_radius_to(t, c, mid, fine * 0.5 * dinf) < 0.5 * dinf) {
			/* where along the segment the region can first be met */
			double r0 = cell_radius(t, c, p0);
			double s0 = fmin(1.0, r0 / dinf);
			double s1 = fmax(s0, 1.0 - r1 / dinf);
			c->cross = 0.5 * (s0 + s1);
			t->hits[t->col_nh++] = ci;
		}
		cell_expire(t, c, p1, r1);
	}
	return t->col_k >= t->col_np;
}

/* End the collection: the popped cells' expiries count again, the hit ones
 * are marked with this update's epoch (track_step() adds the cells of
 * lost points to them once). Returns the count of hits. */
int px__st_col_end(struct px_strack *t)
{
	int k;
	for (k = 0; k < t->col_np; k++) {
		int ci = t->popped[k], g = ci / ST_GROUP;
		double x = t->ex[ci];
		if (x < t->gdue[g])
			t->gdue[g] = x;
		if (x < t->next_due)
			t->next_due = x;
	}
	for (k = 0; k < t->col_nh; k++)
		t->cell[t->hits[k]].mark = t->epoch;
	t->col_on = 0;
	return t->col_nh;
}

/*
 * Cells whose certificates the segment p0 -> p1 may break. Returns their
 * count (in hits); -1 when more than max_tests cells are due: then that
 * many are tested now and the collection goes on over the next updates
 * (col_on; the tracked set stays at p0).
 */
int px__st_collect_cells(struct px_strack *t, px_vec3 p0, px_vec3 p1)
{
	int lim = tests_budget(t);
	col_begin(t, p0, p1);
	if (t->col_np == 0) {
		/* none due (most updates): nothing to test or put back */
		t->col_on = 0;
		return 0;
	}
	if (lim > 0 && t->col_np > lim) {
		px__st_col_test(t, lim);
		return -1;
	}
	px__st_col_test(t, 0);
	return px__st_col_end(t);
}
