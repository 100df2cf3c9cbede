/*
 * brep_compose.c - exact 3D edges for loop curves that come without one
 * (trimmed OBJ files carry only the 2D curves): the image S(c(t)) of a
 * (u, v) curve c on a NURBS surface S is itself a rational B-spline.
 *
 * c is cut at its own knots and where it crosses S's interior knot
 * lines, so that every piece lies in one Bezier patch of S. A crossing
 * is a sign change of the Bernstein polynomial U(t) - k W(t) (k the knot,
 * (U, V, W) c's homogeneous coordinates), found by de Casteljau halving
 * down to the last bit of the piece's parameter. On a piece, with the
 * patch on [ua, ub] x [va, vb], s = (U - ua W) / (ub - ua) and
 * 1 - s = (ub W - U) / (ub - ua) are polynomials of c's degree d, so
 *   W^(p+q) S(c(t)) = sum_ab C(p,a) C(q,b) s^a (W-s)^(p-a) r^b (W-r)^(q-b) P_ab
 * (r likewise in v; P_ab the homogeneous patch points) is a polynomial of
 * degree d (p + q), built from Bernstein products (convex combinations,
 * well conditioned) directly as the piece's Bezier control points. A
 * coordinate that is constant along c (iso-curves, the common case)
 * stays a number: the degree is d (p eu + q ev) with eu, ev = 0 for a
 * constant u, v. The pieces join C0 (interior knots of multiplicity
 * D) and keep c's parameter: the edge at t is the face at c(t).
 *
 * An image above PX_NURBS_MAX_DEGREE (a cubic trim on a bicubic patch:
 * 18) is no NURBS curve of the kernel: its Bezier pieces become a
 * curve-on-surface edge (brep_cos.c) up to BREP_COS_MAX_DEGREE.
 * Refused with a message: a degree above that, more than CMP_MAX_PIECES
 * pieces, a crossing search over its budget, weights that stay not
 * positive after CMP_MAX_HALVE halvings. Setup only (allocates).
 */
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "brep_internal.h"
#include "px_bern.h"

#define CMP_MAX_PIECES 65536
#define CMP_NODE_BUDGET 8192
#define CMP_MAX_HALVE 8
#define CMP_MAX_DEPTH 52
#define MAXD PX_NURBS_MAX_DEGREE
#define CMAXD BREP_COS_MAX_DEGREE /* of the image's pieces */

struct cmp {
	const struct px_nurbs_surf *s;
	const struct px_nurbs_curve *c;
	int d, p, q, eu, ev, D;
	double uc, vc;          /* the constant coordinates (eu, ev == 0) */
	double *cwork, *swork;
	size_t cwlen, swlen;
	int pi, pj;             /* spans of the patch in swork (-1 none) */
	struct px_nurbs_surf patch;
	double *sp;             /* split parameters of one span, sp_cap */
	int sp_cap;
	double *pw;             /* output control points, 4 each */
	double *brk;            /* piece ends: n_pc + 1 */
	int n_pc, cap;
	int budget;
	char *why;
	size_t why_cap;
};

static int cmp_fail(struct cmp *x, int code, const char *fmt, ...)
	__attribute__((format(printf, 3, 4)));

static int cmp_fail(struct cmp *x, int code, const char *fmt, ...)
{
	va_list ap;
	if (x->why && x->why_cap) {
		va_start(ap, fmt);
		vsnprintf(x->why, x->why_cap, fmt, ap);
		va_end(ap);
	}
	return code;
}

/* 1 when coordinate k (0 u, 1 v) of every control point of c is the
 * same number to rounding (*val that number). */
static int constant_coord(const struct px_nurbs_curve *c, int k, double *val)
{
	double x0 = c->pw[k] / c->pw[3], m = fabs(x0);
	int i;
	for (i = 1; i < c->n_ctrl; i++) {
		double x = c->pw[4 * i + k] / c->pw[4 * i + 3];
		if (fabs(x - x0) > 4.0 * DBL_EPSILON * fmax(m, fabs(x)))
			return 0;
	}
	*val = x0;
	return 1;
}

/* ---- crossings of knot lines --------------------------------------------- */

/* Leaf walk of the halving of f (degree n) on [a, b] within [0, 1]:
 * leaves are labelled +1 / -1 (on one side of the knot line, to
 * rounding tol) or 0 (within tol of it: either side); a split is
 * recorded where the side changes (at the start of the 0-run between). */
struct walk {
	int last;       /* last nonzero label, 0 none */
	double run;     /* start of the current 0-run, or -1 */
	double *out;
	int n, cap;
};

static int side_walk(struct cmp *x, struct walk *w, const double *f, int n,
		     double a, double b, int depth, double tol)
{
	double l[MAXD + 1], r[MAXD + 1];
	int i, pos = 0, neg = 0, lab, rc;

	if (--x->budget < 0)
		return PX_E_NOCONV;
	for (i = 0; i <= n; i++) {
		pos |= f[i] > tol;
		neg |= f[i] < -tol;
	}
	if (pos && neg && depth < CMP_MAX_DEPTH) {
		px_bern_split(f, n, 0.5, l, r);
		rc = side_walk(x, w, l, n, a, 0.5 * (a + b), depth + 1, tol);
		if (!rc)
			rc = side_walk(x, w, r, n, 0.5 * (a + b), b, depth + 1, tol);
		return rc;
	}
	lab = pos && neg ? 0 : (pos ? 1 : (neg ? -1 : 0));
	if (lab == 0) {
		if (w->run < 0.0)
			w->run = a;
		return PX_OK;
	}
	if (w->last == -lab) {
		double t = w->run >= 0.0 ? w->run : a;
		if (w->n >= w->cap)
			return PX_E_NOSPC;
		w->out[w->n++] = t;
	}
	w->last = lab;
	w->run = -1.0;
	return PX_OK;
}

/* Parameters s in (0, 1) where the Bezier piece (homogeneous pw, degree
 * d) crosses the interior knot lines of S in direction dir; appended to
 * out[*n..cap). */
static int knot_crossings(struct cmp *x, const double *pw, int dir, double *out,
			  int *n, int cap)
{
	const struct px_nurbs_surf *s = x->s;
	const double *K = s->knots[dir];
	int deg = s->degree[dir], nc = s->n_ctrl[dir], i, k, rc;
	double lo = INFINITY, hi = -INFINITY;

	for (k = 0; k <= x->d; k++) {
		double c = pw[4 * k + dir] / pw[4 * k + 3];
		lo = fmin(lo, c);
		hi = fmax(hi, c);
	}
	for (i = deg + 1; i < nc; i++) {
		double kv = K[i], f[MAXD + 1], tol = 0.0;
		struct walk w;
		if (K[i] == K[i - 1] || kv < lo || kv > hi)
			continue;
		for (k = 0; k <= x->d; k++) {
			f[k] = pw[4 * k + dir] - kv * pw[4 * k + 3];
			tol = fmax(tol, fabs(pw[4 * k + dir]) + fabs(kv * pw[4 * k + 3]));
		}
		tol *= 16.0 * DBL_EPSILON;
		w.last = 0;
		w.run = -1.0;
		w.out = out + *n;
		w.n = 0;
		w.cap = cap - *n;
		x->budget = CMP_NODE_BUDGET;
		rc = side_walk(x, &w, f, x->d, 0.0, 1.0, 0, tol);
		if (rc == PX_E_NOCONV)
			return cmp_fail(x, rc,
					"the crossings of the %c knot line %g were "
					"not found within the work bound",
					dir ? 'v' : 'u', kv);
		if (rc)
			return cmp_fail(x, rc, "too many knot line crossings");
		*n += w.n;
	}
	return PX_OK;
}

static int cmp_double(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

/* ---- one piece ------------------------------------------------------------ */

/* The span of direction dir that [ta, tb] of c lies in: of the spans of
 * seven sample points (both sides), the one they leave least. */
static int piece_span(struct cmp *x, int dir, double ta, double tb)
{
	const double *K = x->s->knots[dir];
	double val[7], best = INFINITY;
	int cand[14], nc = 0, i, j, bi = -1;

	for (i = 0; i < 7; i++) {
		px_vec3 q = px_nurbs_curve_point(x->c, ta + (tb - ta) * (i + 1) / 8.0);
		val[i] = dir ? q.y : q.x;
		cand[nc++] = px_nurbs_surf_find_span(x->s, dir, val[i], 1);
		cand[nc++] = px_nurbs_surf_find_span(x->s, dir, val[i], -1);
	}
	for (j = 0; j < nc; j++) {
		double out = 0.0;
		for (i = 0; i < 7; i++)
			out = fmax(out, fmax(K[cand[j]] - val[i], val[i] - K[cand[j] + 1]));
		if (out < best) {
			best = out;
			bi = cand[j];
		}
	}
	return bi;
}

/* Bernstein coefficients (degree deg * d) of C(deg, a) s^a (W - s)^(deg - a)
 * for a = 0..deg, with s = (X - k0 W) / (k1 - k0) on the piece (X the
 * coordinate's homogeneous values, W the weights); out[a] has MAXD + 1. */
static void basis_polys(const double *X, const double *W, int d, int deg,
			double k0, double k1, double out[][CMAXD + 1])
{
	double s[MAXD + 1], t[MAXD + 1], sp[MAXD + 1][CMAXD + 1],
		tp[MAXD + 1][CMAXD + 1];
	int k, a;

	for (k = 0; k <= d; k++) {
		s[k] = (X[k] - k0 * W[k]) / (k1 - k0);
		t[k] = (k1 * W[k] - X[k]) / (k1 - k0);
	}
	sp[0][0] = tp[0][0] = 1.0;
	for (a = 1; a <= deg; a++) {
		px_bern_mul(sp[a - 1], (a - 1) * d, s, d, sp[a]);
		px_bern_mul(tp[a - 1], (a - 1) * d, t, d, tp[a]);
	}
	for (a = 0; a <= deg; a++) {
		px_bern_mul(sp[a], a * d, tp[deg - a], (deg - a) * d, out[a]);
		for (k = 0; k <= deg * d; k++)
			out[a][k] *= px_bern_binom(deg, a);
	}
}

/* The same for a constant coordinate: the Bernstein values (degree 0). */
static void basis_const(double val, int deg, double k0, double k1,
			double out[][CMAXD + 1])
{
	double s = (val - k0) / (k1 - k0);
	int a;
	for (a = 0; a <= deg; a++)
		out[a][0] = px_bern_binom(deg, a) * pow(s, a) * pow(1.0 - s, deg - a);
}

static int append_piece(struct cmp *x, const double *N, double tb)
{
	int D = x->D, k, first = x->n_pc ? 1 : 0;
	if (x->n_pc >= CMP_MAX_PIECES)
		return cmp_fail(x, PX_E_NOSPC, "the edge would need more than %d "
				"Bezier pieces", CMP_MAX_PIECES);
	if (x->n_pc >= x->cap) {
		int cap = x->cap ? 2 * x->cap : 16;
		double *pw = realloc(x->pw, ((size_t)cap * D + 1) * 4 * sizeof(double));
		double *bk;
		if (!pw)
			return PX_E_NOMEM;
		x->pw = pw;
		bk = realloc(x->brk, ((size_t)cap + 1) * sizeof(double));
		if (!bk)
			return PX_E_NOMEM;
		x->brk = bk;
		x->cap = cap;
	}
	if (first)
		for (k = 0; k < 4; k++) {
			double *j = x->pw + 4 * (size_t)x->n_pc * D + k;
			*j = 0.5 * (*j + N[k]);
		}
	memcpy(x->pw + 4 * ((size_t)x->n_pc * D + first), N + 4 * first,
	       (size_t)(D + 1 - first) * 4 * sizeof(double));
	x->n_pc++;
	x->brk[x->n_pc] = tb;
	return PX_OK;
}

/* Compose c on [ta, tb] (inside one span of c and one patch of S, spans
 * i, j) and append it; halved when a weight comes out not positive. */
static int compose_range(struct cmp *x, double ta, double tb, int i, int j,
			 int halvings)
{
	const double *Ku = x->s->knots[0], *Kv = x->s->knots[1];
	double X[MAXD + 1], Y[MAXD + 1], W[MAXD + 1], N[4 * (CMAXD + 1)];
	double bu[MAXD + 1][CMAXD + 1], bv[MAXD + 1][CMAXD + 1], prod[CMAXD + 1];
	struct px_nurbs_curve pc;
	int p = x->p, q = x->q, du = x->eu * p * x->d, dv = x->ev * q * x->d;
	int k, a, b, rc, ok = 1;

	rc = px_nurbs_curve_extract_work(x->c, ta, tb, x->cwork, x->cwlen, &pc);
	if (rc || pc.n_ctrl != x->d + 1)
		return cmp_fail(x, rc ? rc : PX_E_STATE,
				"cannot extract the curve on [%g, %g]", ta, tb);
	if (i != x->pi || j != x->pj) {
		rc = px_nurbs_surf_extract_work(x->s, Ku[i], Ku[i + 1], Kv[j],
						Kv[j + 1], x->swork, x->swlen,
						&x->patch);
		if (rc || x->patch.n_ctrl[0] != p + 1 || x->patch.n_ctrl[1] != q + 1)
			return cmp_fail(x, rc ? rc : PX_E_STATE,
					"cannot extract the surface patch %d, %d", i, j);
		x->pi = i;
		x->pj = j;
	}
	for (k = 0; k <= x->d; k++) {
		X[k] = pc.pw[4 * k];
		Y[k] = pc.pw[4 * k + 1];
		W[k] = pc.pw[4 * k + 3];
	}
	if (x->eu)
		basis_polys(X, W, x->d, p, Ku[i], Ku[i + 1], bu);
	else
		basis_const(x->uc, p, Ku[i], Ku[i + 1], bu);
	if (x->ev)
		basis_polys(Y, W, x->d, q, Kv[j], Kv[j + 1], bv);
	else
		basis_const(x->vc, q, Kv[j], Kv[j + 1], bv);
	memset(N, 0, sizeof(N));
	for (a = 0; a <= p; a++)
		for (b = 0; b <= q; b++) {
			const double *P = x->patch.pw + 4 * (b * (p + 1) + a);
			px_bern_mul(bu[a], du, bv[b], dv, prod);
			for (k = 0; k <= x->D; k++) {
				N[4 * k] += prod[k] * P[0];
				N[4 * k + 1] += prod[k] * P[1];
				N[4 * k + 2] += prod[k] * P[2];
				N[4 * k + 3] += prod[k] * P[3];
			}
		}
	for (k = 0; k <= x->D; k++)
		ok &= N[4 * k + 3] > 0.0 && isfinite(N[4 * k]) &&
		      isfinite(N[4 * k + 1]) && isfinite(N[4 * k + 2]) &&
		      isfinite(N[4 * k + 3]);
	if (ok)
		return append_piece(x, N, tb);
	if (halvings >= CMP_MAX_HALVE || !(ta < 0.5 * (ta + tb) && 0.5 * (ta + tb) < tb))
		return cmp_fail(x, PX_E_RANGE,
				"the image's weights are not positive near t = %g",
				0.5 * (ta + tb));
	rc = compose_range(x, ta, 0.5 * (ta + tb), i, j, halvings + 1);
	if (!rc)
		rc = compose_range(x, 0.5 * (ta + tb), tb, i, j, halvings + 1);
	return rc;
}

/* c's span [ta, tb] cut at the knot line crossings, each part composed. */
static int compose_span(struct cmp *x, double ta, double tb)
{
	struct px_nurbs_curve pc;
	double *sp = x->sp;
	int n = 0, k, rc, dir;

	rc = px_nurbs_curve_extract_work(x->c, ta, tb, x->cwork, x->cwlen, &pc);
	if (rc)
		return cmp_fail(x, rc, "cannot extract the curve on [%g, %g]", ta, tb);
	for (dir = 0; dir < 2; dir++)
		if (dir ? x->ev : x->eu) {
			rc = knot_crossings(x, pc.pw, dir, sp, &n, x->sp_cap - 1);
			if (rc)
				return rc;
		}
	qsort(sp, (size_t)n, sizeof(double), cmp_double);
	sp[n] = 1.0;
	for (k = 0; k <= n; k++) {
		double t1 = k == n ? tb : ta + (tb - ta) * sp[k];
		double t0 = x->brk[x->n_pc];
		if (k < n && !(t1 - t0 > 1e-13 * (tb - ta) && tb - t1 > 1e-13 * (tb - ta)))
			continue;
		rc = compose_range(x, t0, t1, x->eu ? piece_span(x, 0, t0, t1)
						   : px_nurbs_surf_find_span(x->s, 0, x->uc, 1),
				   x->ev ? piece_span(x, 1, t0, t1)
					 : px_nurbs_surf_find_span(x->s, 1, x->vc, 1),
				   0);
		if (rc)
			return rc;
	}
	return PX_OK;
}

/* The Bezier pieces of S(c(t)) into x (x->pw, x->brk, x->n_pc of
 * degree x->D; free both): PX_OK, 1 for a point, or a refusal. */
static int compose_pieces(struct cmp *x, const struct px_nurbs_surf *s,
			  const struct px_nurbs_curve *c, int max_deg)
{
	double t0, t1;
	int i, rc;

	x->s = s;
	x->c = c;
	x->pi = x->pj = -1;
	x->d = c->degree;
	x->p = s->degree[0];
	x->q = s->degree[1];
	x->eu = !constant_coord(c, 0, &x->uc);
	x->ev = !constant_coord(c, 1, &x->vc);
	x->D = x->d * (x->p * x->eu + x->q * x->ev);
	if (x->D == 0)
		return 1; /* a point of the parameter plane */
	if (x->D > max_deg)
		return cmp_fail(x, PX_E_NOSPC,
				"its image on the surface has degree %d "
				"(curve %d times (%d + %d)), above %d",
				x->D, x->d, x->eu ? x->p : 0, x->ev ? x->q : 0,
				max_deg);
	x->cwlen = PX_NURBS_CURVE_WORK_LEN(c->degree, c->n_ctrl);
	x->swlen = PX_NURBS_SURF_WORK_LEN(x->p, x->q, s->n_ctrl[0], s->n_ctrl[1]);
	x->cwork = malloc(x->cwlen * sizeof(double));
	x->swork = malloc(x->swlen * sizeof(double));
	x->brk = malloc(17 * sizeof(double));
	x->cap = 0;
	/* a knot line is crossed at most d times by a piece (a few more
	 * side changes where rounding blurs a tangency) */
	x->sp_cap = (s->n_knots[0] + s->n_knots[1]) * (x->d + 4) + 16;
	x->sp = malloc((size_t)x->sp_cap * sizeof(double));
	rc = x->cwork && x->swork && x->brk && x->sp ? PX_OK : PX_E_NOMEM;
	px_nurbs_curve_domain(c, &t0, &t1);
	if (!rc)
		x->brk[0] = t0;
	for (i = c->degree; !rc && i < c->n_ctrl; i++) {
		double a = fmax(c->knots[i], t0), b = fmin(c->knots[i + 1], t1);
		if (b > a)
			rc = compose_span(x, a, b);
	}
	free(x->cwork);
	free(x->swork);
	free(x->sp);
	if (!rc && x->n_pc < 1)
		rc = cmp_fail(x, PX_E_STATE, "no piece");
	if (rc) {
		free(x->pw);
		free(x->brk);
		x->pw = x->brk = NULL;
	}
	return rc;
}

int px__brep_compose_curve(const struct px_nurbs_surf *s,
			   const struct px_nurbs_curve *c, double **mem,
			   struct px_nurbs_curve *out, char *why, size_t why_cap)
{
	struct cmp x;
	double t0, t1, *k, *pw;
	int i, rc, n_ctrl, nk;

	*mem = NULL;
	memset(&x, 0, sizeof(x));
	x.why = why;
	x.why_cap = why_cap;
	rc = compose_pieces(&x, s, c, MAXD);
	if (rc)
		return rc;
	px_nurbs_curve_domain(c, &t0, &t1);
	n_ctrl = x.n_pc * x.D + 1;
	nk = n_ctrl + x.D + 1;
	*mem = malloc(((size_t)nk + 4 * (size_t)n_ctrl) * sizeof(double));
	if (!*mem) {
		free(x.pw);
		free(x.brk);
		return PX_E_NOMEM;
	}
	k = *mem;
	pw = k + nk;
	for (i = 0; i <= x.D; i++) {
		k[i] = t0;
		k[nk - 1 - i] = t1;
	}
	for (i = 1; i < x.n_pc; i++) {
		int j;
		for (j = 0; j < x.D; j++)
			k[1 + i * x.D + j] = x.brk[i];
	}
	memcpy(pw, x.pw, 4 * (size_t)n_ctrl * sizeof(double));
	if (!c->rational && !s->rational)
		for (i = 0; i < n_ctrl; i++) {
			/* a polynomial composed with a polynomial */
			pw[4 * i] /= pw[4 * i + 3];
			pw[4 * i + 1] /= pw[4 * i + 3];
			pw[4 * i + 2] /= pw[4 * i + 3];
			pw[4 * i + 3] = 1.0;
		}
	free(x.pw);
	free(x.brk);
	{
		struct px_nurbs_error ne;
		rc = px_nurbs_curve_view(out, x.D, n_ctrl, k, nk, pw, &ne);
		if (rc) {
			free(*mem);
			*mem = NULL;
			return cmp_fail(&x, rc, "the composed curve: %s", ne.msg);
		}
	}
	return PX_OK;
}

int px__brep_compose_bezier(const struct px_nurbs_surf *s,
			    const struct px_nurbs_curve *c, int *deg, int *n_pc,
			    double **pw, double **brk, char *why, size_t why_cap)
{
	struct cmp x;
	int rc;
	memset(&x, 0, sizeof(x));
	x.why = why;
	x.why_cap = why_cap;
	rc = compose_pieces(&x, s, c, CMAXD);
	*deg = x.D;
	*n_pc = rc ? 0 : x.n_pc;
	*pw = rc ? NULL : x.pw;
	*brk = rc ? NULL : x.brk;
	return rc;
}

/* ---- the description with the composed edges ------------------------------ */

void px__brep_aug_free(struct brep_aug *g)
{
	int i;
	for (i = 0; i < g->n_mem; i++)
		free(g->mem[i]);
	free(g->mem);
	free(g->faces);
	free(g->edges);
	free(g->co);
	free(g->cop);
	px__brep_cos_free(g->cos);
	memset(g, 0, sizeof(*g));
}

/* The loop curves of d whose coedge has no edge, counted; 0 when the
 * description is not fit to look at (the checks will say why). */
static int count_missing(const struct px_brep_desc *d, int *n_co, int *n_lp)
{
	int f, l, k, n = 0;
	*n_co = *n_lp = 0;
	if (d->n_faces < 1 || !d->faces || d->n_edges < 0 || (d->n_edges && !d->edges))
		return 0;
	for (f = 0; f < d->n_faces; f++) {
		const struct px_brep_face_desc *fd = &d->faces[f];
		if (fd->n_loops < 0 || (fd->n_loops && !fd->loops))
			return 0;
		for (l = 0; l < fd->n_loops; l++) {
			if (fd->loops[l].n_curves < 0 ||
			    (fd->loops[l].n_curves && !fd->loops[l].curves))
				return 0;
			*n_co += fd->loops[l].n_curves;
			(*n_lp)++;
			for (k = 0; k < fd->loops[l].n_curves; k++)
				if (!fd->coedges || !fd->coedges[l] ||
				    fd->coedges[l][k].edge == -1)
					n++;
		}
	}
	return n;
}

/* The refusal of loop curve (f, l, k)'s image into err. */
static int compose_refused(const struct px_brep_face_desc *fd, int f, int l,
			   int k, int rc, const char *why, struct px_brep_error *err)
{
	if (err) {
		err->code = rc;
		err->face = f;
		err->loop = l;
		err->curve = k;
		err->id = fd->id;
		if (fd->id)
			snprintf(err->msg, sizeof(err->msg),
				 "face %d (id %ld): loop %d curve %d has no "
				 "3D edge and its exact image cannot be made: %s",
				 f, fd->id, l, k, why[0] ? why : px_strerror(rc));
		else
			snprintf(err->msg, sizeof(err->msg),
				 "face %d: loop %d curve %d has no 3D edge "
				 "and its exact image cannot be made: %s",
				 f, l, k, why[0] ? why : px_strerror(rc));
	}
	return rc;
}

/* 1 when the n homogeneous points pw lie within tol of the first. */
static int one_point(const double *pw, int n, double tol)
{
	px_vec3 p0 = px_v3(pw[0] / pw[3], pw[1] / pw[3], pw[2] / pw[3]);
	int i;
	for (i = 1; i < n; i++)
		if (px_v3_dist(px_v3(pw[4 * i] / pw[4 * i + 3],
				     pw[4 * i + 1] / pw[4 * i + 3],
				     pw[4 * i + 2] / pw[4 * i + 3]),
			       p0) > tol)
			return 0;
	return 1;
}

/* Loop curve (f, l, k), coedge co, as a curve-on-surface edge of g->cos
 * (its image's degree is above the kernel's; *edge stays -1). */
static int compose_cos(struct brep_aug *g, const struct px_brep_desc *d, int f,
		       int l, int k, int co, const struct px_nurbs_surf *sv,
		       const struct px_nurbs_curve *cv, double tol,
		       struct px_brep_error *err)
{
	double *pw = NULL, *brk = NULL;
	char why[200];
	int deg, n_pc, rc;

	why[0] = '\0';
	rc = px__brep_compose_bezier(sv, cv, &deg, &n_pc, &pw, &brk, why, sizeof(why));
	if (rc == 1)
		return PX_OK;
	if (rc)
		return compose_refused(&d->faces[f], f, l, k, rc, why, err);
	if (!one_point(pw, n_pc * deg + 1, tol)) {
		if (!g->cos)
			g->cos = calloc(1, sizeof(*g->cos));
		rc = g->cos ? px__brep_cos_add(g->cos, f, co, deg, n_pc, pw, brk,
					       d->scale)
			    : PX_E_NOMEM;
	}
	free(pw);
	free(brk);
	return rc;
}

/* Compose loop curve (f, l, k) (coedge co) into edge slot g->edges[*ne]
 * when the surface and the curve are valid and the image is no point;
 * an image of too high a degree for the kernel becomes a curve-on-
 * surface edge instead. */
static int compose_one(struct brep_aug *g, const struct px_brep_desc *d, int f,
		       int l, int k, int co, int *edge, struct px_brep_error *err)
{
	const struct px_brep_face_desc *fd = &d->faces[f];
	const struct px_nurbs_curve *c = &fd->loops[l].curves[k];
	struct px_nurbs_surf sv;
	struct px_nurbs_curve cv, out;
	px_aabb hb;
	double *mem = NULL, tol;
	char why[200];
	int rc, i, point = 1;

	*edge = -1;
	if (px_nurbs_surf_view(&sv, fd->surf.degree[0], fd->surf.degree[1],
			       fd->surf.n_ctrl[0], fd->surf.n_ctrl[1],
			       fd->surf.knots[0], fd->surf.n_knots[0],
			       fd->surf.knots[1], fd->surf.n_knots[1], fd->surf.pw,
			       NULL) ||
	    px_nurbs_curve_view(&cv, c->degree, c->n_ctrl, c->knots, c->n_knots,
				c->pw, NULL))
		return PX_OK; /* the checks report it */
	/* an image within the tolerance of one point stays a collapsed
	 * curve (px_brep_create()'s own test, in these units) */
	hb = px_nurbs_surf_aabb(&sv);
	tol = 1e-9 * (1.0 / d->scale + px_aabb_diagonal(&hb));
	why[0] = '\0';
	rc = px__brep_force_cos ? PX_E_NOSPC
				: px__brep_compose_curve(&sv, &cv, &mem, &out, why,
							 sizeof(why));
	if (rc == 1)
		return PX_OK;
	if (rc == PX_E_NOSPC)
		return compose_cos(g, d, f, l, k, co, &sv, &cv, tol, err);
	if (rc)
		return compose_refused(fd, f, l, k, rc, why, err);
	g->mem[g->n_mem++] = mem;
	{
		px_vec3 p0 = px_nurbs_curve_ctrl(&out, 0, NULL);
		for (i = 1; i < out.n_ctrl && point; i++)
			point = px_v3_dist(px_nurbs_curve_ctrl(&out, i, NULL), p0) <= tol;
	}
	if (point)
		return PX_OK;
	*edge = g->d.n_edges;
	g->edges[g->d.n_edges].curve = out;
	g->edges[g->d.n_edges].v0 = g->edges[g->d.n_edges].v1 = -1;
	g->edges[g->d.n_edges].id = fd->id;
	g->d.n_edges++;
	return PX_OK;
}

int px__brep_compose(const struct px_brep_desc *d, struct brep_aug *g,
		     struct px_brep_error *err)
{
	int n_miss, n_co, n_lp, f, l, k, at = 0, lat = 0, rc;

	memset(g, 0, sizeof(*g));
	n_miss = count_missing(d, &n_co, &n_lp);
	if (n_miss == 0 || !(isfinite(d->scale) && d->scale > 0.0))
		return PX_OK;
	g->d = *d;
	g->faces = malloc((size_t)d->n_faces * sizeof(*g->faces));
	g->edges = malloc(((size_t)d->n_edges + n_miss) * sizeof(*g->edges));
	g->co = malloc((size_t)n_co * sizeof(*g->co));
	g->cop = calloc((size_t)n_lp + 1, sizeof(*g->cop));
	g->mem = calloc((size_t)n_miss, sizeof(*g->mem));
	if (!g->faces || !g->edges || !g->co || !g->cop || !g->mem) {
		px__brep_aug_free(g);
		return PX_E_NOMEM;
	}
	memcpy(g->faces, d->faces, (size_t)d->n_faces * sizeof(*g->faces));
	if (d->n_edges)
		memcpy(g->edges, d->edges, (size_t)d->n_edges * sizeof(*g->edges));
	g->d.faces = g->faces;
	g->d.edges = g->edges;
	/* every loop gets its own coedge array (cop: per loop, in order) */
	for (f = 0; f < d->n_faces; f++) {
		const struct px_brep_face_desc *fd = &d->faces[f];
		const struct px_brep_coedge **cp = g->cop + lat;
		lat += fd->n_loops;
		for (l = 0; l < fd->n_loops; l++) {
			struct px_brep_coedge *co = g->co + at;
			cp[l] = co;
			for (k = 0; k < fd->loops[l].n_curves; k++, at++) {
				int e = fd->coedges && fd->coedges[l]
						? fd->coedges[l][k].edge
						: -1;
				if (e == -1) {
					rc = compose_one(g, d, f, l, k, at, &e, err);
					if (rc) {
						px__brep_aug_free(g);
						return rc;
					}
				}
				co[k].edge = e;
			}
		}
		g->faces[f].coedges = fd->n_loops ? cp : fd->coedges;
	}
	return PX_OK;
}
