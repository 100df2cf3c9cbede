/*
 * NURBS curves and surfaces behind the point-to-model interface: the
 * distance core's certified global query as a px_model, signed for
 * closed surface shells (see the block comment further down).
 */
#include <math.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "px_dist.h"
#include "model_internal.h"
#include "px_model.h"
#include "px_strack.h"
#include "px_track.h"

/* Queries take a const model and may come from several threads at once;
 * each borrows one of these workspaces without waiting (a query that
 * finds all of them taken fails with PX_E_BUSY rather than blocking). */
#define NURBS_WS 4

struct sgn_surf;

struct nurbs_impl {
	struct px_dist_model *dm;
	struct px_dist_ws *ws[NURBS_WS];
	atomic_flag busy[NURBS_WS];
	px_aabb box;
	size_t bytes;
	/* sign (surfaces only) */
	struct sgn_surf *ss;
	int n_ss;
	int closed;       /* 1: signed queries */
	double orient;    /* +1: Su x Sv points out, -1: in */
	double volume;
	double tol;
	double on_tol;    /* rounding level: closer counts as on the surface */
	int edge_samples;
	char why[160];
	/* the inputs, kept for tracked streams (px_model_stream_create) */
	struct px_nurbs_curve *kc;
	struct px_nurbs_surf *ks;
	int n_kc, n_ks;
	double *kmem;
};

/* ---- signed distance for closed surface shells ---------------------------
 *
 * Setup decides whether the surfaces bound a solid and which side of each
 * is outside; queries then sign the certified unsigned answer.
 *
 * Closedness (only models made of surfaces alone): every domain edge of
 * every surface that is neither collapsed to a point (a pole) nor glued to
 * its opposite edge (px_nurbs_surf_closed(): a seam) is sampled at 2p+1
 * interior parameters per knot span (p the degree along the edge), and
 * every sample must lie within tol of a domain edge of another surface
 * (found by that surface's own certified distance model, foot within a
 * relative 1e-6 of its domain bounds). tol = SIGN_TOL_REL * box diagonal.
 * A surface matching only itself at a non-seam edge is reported open.
 *
 * Orientation: the domain boundary of a surface, run counterclockwise in
 * (u, v), is the boundary of the surface oriented by Su x Sv. Neighbours
 * agree on the side they call outside exactly when they run a shared edge
 * in opposite directions, so at each matched sample the two induced edge
 * tangents must point opposite ways (cosine < -0.5); a sample where they
 * point the same way makes the shell inconsistently oriented and the
 * model stays unsigned (no guessing). The sign of the enclosed volume
 * V = 1/3 sum of the integrals of S . (Su x Sv) du dv (divergence theorem,
 * Gauss-Legendre on every knot rectangle) then says whether Su x Sv points
 * outwards (V > 0) or inwards.
 *
 * Query: with the foot point S in the interior of a surface's domain and a
 * normal N there that (P - S) is nearly parallel to (|cos| >= 0.9, as at
 * every smooth foot point), the sign is that of (P - S) . N_out. Otherwise
 * (S on an edge, corner, seam, crease, pole, or where the normal
 * vanishes) the sign comes from the angle-weighted pseudo-normal at S
 * (Baerentzen and Aanaes: for a point whose closest point is S, the
 * pseudo-normal points towards it exactly when it is outside): every
 * surface passing within tol of S (its own distance model finds where)
 * contributes its sector of directions around S, sampled on a small
 * parameter circle clipped to its domain (seams add the image on the
 * other side; a collapsed edge contributes the whole fan around the
 * pole), each chord angle weighting the unit outward normal between its
 * ends. Bounded work: at most one distance query per surface and
 * SIGN_ARC samples per sector. A point on the model (distance 0, or
 * within 1e-13 of the box diagonal, where rounding decides the side) is
 * outside.
 */
#define SIGN_TOL_REL 1e-6
#define SIGN_ARC 16
#define SIGN_DELTA 1e-5 /* sector circle radius, fraction of the domain */

struct sgn_surf {
	struct px_nurbs_surf s;
	double u0, u1, v0, v1;
	int closed_u, closed_v;
	int collapsed[4];
	int n_brk[2];
	double *brk[2];
	px_aabb box;
	struct px_dist_model *dm;
	struct px_dist_ws *ws[NURBS_WS];
};

static px_vec3 sgn_normal(const struct px_nurbs_surf *s, double u, double v)
{
	struct px_nurbs_surf_derivs d;
	if (px_nurbs_surf_eval(s, u, v, 1, &d) != PX_OK)
		return px_v3(0, 0, 0);
	return px_v3_cross(d.su, d.sv);
}

static px_vec3 sgn_unit(px_vec3 a)
{
	double n = px_v3_norm(a);
	return n > 0.0 ? px_v3_scale(a, 1.0 / n) : px_v3(0, 0, 0);
}

static double sgn_angle(px_vec3 a, px_vec3 b)
{
	return atan2(px_v3_norm(px_v3_cross(a, b)), px_v3_dot(a, b));
}

/* Angle-weighted outward normals of the sector of surface g around its
 * parameter point (u, v), added to *acc. */
static void sgn_sector(const struct sgn_surf *g, double orient, double u,
		       double v, px_vec3 *acc)
{
	const double wu = g->u1 - g->u0, wv = g->v1 - g->v0;
	const double du = SIGN_DELTA * wu, dv = SIGN_DELTA * wv;
	const int lu = u - g->u0 <= 0.5 * du, hu = g->u1 - u <= 0.5 * du;
	const int lv = v - g->v0 <= 0.5 * dv, hv = g->v1 - v <= 0.5 * dv;
	px_vec3 c = px_nurbs_surf_point(&g->s, u, v), prev;
	double a0, span;
	int k, pole = -1;

	if (lu && g->collapsed[0])
		pole = 0;
	else if (hu && g->collapsed[1])
		pole = 1;
	else if (lv && g->collapsed[2])
		pole = 2;
	else if (hv && g->collapsed[3])
		pole = 3;
	if (pole >= 0) {
		/* The whole collapsed edge is S: the fan around it is the
		 * iso line just inside, run over its full range. */
		double t0 = pole < 2 ? g->v0 : g->u0, t1 = pole < 2 ? g->v1 : g->u1;
		double fixed = pole == 0 ? g->u0 + du : pole == 1 ? g->u1 - du :
			       pole == 2 ? g->v0 + dv : g->v1 - dv;
		for (k = 0; k <= 2 * SIGN_ARC; k++) {
			double t = t0 + (t1 - t0) * k / (2 * SIGN_ARC);
			double tm = t - 0.5 * (t1 - t0) / (2 * SIGN_ARC);
			px_vec3 q = pole < 2 ? px_nurbs_surf_point(&g->s, fixed, t)
					     : px_nurbs_surf_point(&g->s, t, fixed);
			q = px_v3_sub(q, c);
			if (k > 0) {
				px_vec3 n = pole < 2 ? sgn_normal(&g->s, fixed, tm)
						     : sgn_normal(&g->s, tm, fixed);
				*acc = px_v3_madd(*acc, sgn_unit(n),
						  orient * sgn_angle(prev, q));
			}
			prev = q;
		}
		return;
	}
	if ((lu && hu) || (lv && hv))
		return; /* domain narrower than the circle: nothing sensible */
	a0 = 0.0;
	span = 2.0 * M_PI;
	if (lu && lv) {
		a0 = 0.0; span = 0.5 * M_PI;
	} else if (lu && hv) {
		a0 = -0.5 * M_PI; span = 0.5 * M_PI;
	} else if (hu && lv) {
		a0 = 0.5 * M_PI; span = 0.5 * M_PI;
	} else if (hu && hv) {
		a0 = M_PI; span = 0.5 * M_PI;
	} else if (lu) {
		a0 = -0.5 * M_PI; span = M_PI;
	} else if (hu) {
		a0 = 0.5 * M_PI; span = M_PI;
	} else if (lv) {
		a0 = 0.0; span = M_PI;
	} else if (hv) {
		a0 = M_PI; span = M_PI;
	}
	for (k = 0; k <= SIGN_ARC; k++) {
		double th = a0 + span * k / SIGN_ARC;
		double tm = th - 0.5 * span / SIGN_ARC;
		double pu = fmin(fmax(u + du * cos(th), g->u0), g->u1);
		double pv = fmin(fmax(v + dv * sin(th), g->v0), g->v1);
		px_vec3 q = px_v3_sub(px_nurbs_surf_point(&g->s, pu, pv), c);
		if (k > 0) {
			double mu = fmin(fmax(u + du * cos(tm), g->u0), g->u1);
			double mv = fmin(fmax(v + dv * sin(tm), g->v0), g->v1);
			*acc = px_v3_madd(*acc, sgn_unit(sgn_normal(&g->s, mu, mv)),
					  orient * sgn_angle(prev, q));
		}
		prev = q;
	}
}

/* Sector of g at (u, v) and, across its seams, at the images of (u, v). */
static void sgn_sectors(const struct sgn_surf *g, double orient, double u,
			double v, px_vec3 *acc)
{
	const double du = SIGN_DELTA * (g->u1 - g->u0);
	const double dv = SIGN_DELTA * (g->v1 - g->v0);
	double us[2] = {u, u}, vs[2] = {v, v};
	int nu = 1, nv = 1, i, j;
	if (g->closed_u && (u - g->u0 <= 0.5 * du || g->u1 - u <= 0.5 * du)) {
		us[0] = g->u0; us[1] = g->u1; nu = 2;
	}
	if (g->closed_v && (v - g->v0 <= 0.5 * dv || g->v1 - v <= 0.5 * dv)) {
		vs[0] = g->v0; vs[1] = g->v1; nv = 2;
	}
	for (i = 0; i < nu; i++)
		for (j = 0; j < nv; j++)
			sgn_sector(g, orient, us[i], vs[j], acc);
}

/* Is the parameter t on a domain bound or an interior C0 break? */
static int sgn_on_line(double t, double t0, double t1, const double *brk,
		       int n, double eps)
{
	int i;
	if (t - t0 <= eps || t1 - t <= eps)
		return 1;
	for (i = 0; i < n; i++)
		if (fabs(t - brk[i]) <= eps)
			return 1;
	return 0;
}

/* Gauss-Legendre nodes and weights on [-1, 1] (Newton on P_n). */
static void sgn_gauss(int n, double *x, double *w)
{
	int i, it, k;
	for (i = 0; i < n; i++) {
		double z = cos(M_PI * (i + 0.75) / (n + 0.5)), dp = 1.0;
		for (it = 0; it < 100; it++) {
			double p0 = 1.0, p1 = z, dz;
			for (k = 2; k <= n; k++) {
				double p2 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
				p0 = p1;
				p1 = p2;
			}
			if (n == 1) {
				p1 = z;
				p0 = 1.0;
			}
			dp = n * (z * p1 - p0) / (z * z - 1.0);
			dz = p1 / dp;
			z -= dz;
			if (fabs(dz) < 1e-16)
				break;
		}
		x[i] = z;
		w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
	}
}

/* Distinct knot values inside [t0, t1] of one direction (setup). */
static int sgn_knots(const double *U, int nk, double t0, double t1, double *out,
		     int cap)
{
	int i, n = 0;
	out[n++] = t0;
	for (i = 0; i < nk && n < cap - 1; i++)
		if (U[i] > out[n - 1] && U[i] < t1)
			out[n++] = U[i];
	out[n++] = t1;
	return n;
}

/* 3 * volume contribution: integral of S . (Su x Sv) over the domain. */
static double sgn_volume3(const struct sgn_surf *g)
{
	double ku[256], kv[256], x[24], w[24], sum = 0.0;
	const struct px_nurbs_surf *s = &g->s;
	int nu = sgn_knots(s->knots[0], s->n_knots[0], g->u0, g->u1, ku, 256);
	int nv = sgn_knots(s->knots[1], s->n_knots[1], g->v0, g->v1, kv, 256);
	int deg = s->degree[0] > s->degree[1] ? s->degree[0] : s->degree[1];
	/* Polynomial integrand of degree 3p - 1 per direction: (3p + 1) / 2
	 * points are exact; rational ones get a margin. */
	int ng = (3 * deg + 2) / 2 + (s->rational ? 6 : 1), a, b, i, j;
	if (ng > 24)
		ng = 24;
	sgn_gauss(ng, x, w);
	for (a = 0; a + 1 < nu; a++)
		for (b = 0; b + 1 < nv; b++) {
			double hu = 0.5 * (ku[a + 1] - ku[a]), hv = 0.5 * (kv[b + 1] - kv[b]);
			double cu = 0.5 * (ku[a + 1] + ku[a]), cv = 0.5 * (kv[b + 1] + kv[b]);
			for (i = 0; i < ng; i++)
				for (j = 0; j < ng; j++) {
					struct px_nurbs_surf_derivs d;
					if (px_nurbs_surf_eval(s, cu + hu * x[i], cv + hv * x[j],
							       1, &d) != PX_OK)
						continue;
					sum += w[i] * w[j] * hu * hv *
					       px_v3_dot(d.s, px_v3_cross(d.su, d.sv));
				}
		}
	return sum;
}

/* Parameter point of edge e (0 u0, 1 u1, 2 v0, 3 v1) at t. */
static void sgn_edge_uv(const struct sgn_surf *g, int e, double t, double *u,
			double *v)
{
	*u = e == 0 ? g->u0 : e == 1 ? g->u1 : t;
	*v = e == 2 ? g->v0 : e == 3 ? g->v1 : t;
}

/* Tangent of edge e at (u, v) in the direction the counterclockwise
 * domain boundary runs it. */
static px_vec3 sgn_edge_tangent(const struct sgn_surf *g, int e, double u,
				double v)
{
	struct px_nurbs_surf_derivs d;
	if (px_nurbs_surf_eval(&g->s, u, v, 1, &d) != PX_OK)
		return px_v3(0, 0, 0);
	switch (e) {
	case 0: return px_v3_scale(d.sv, -1.0);
	case 1: return d.sv;
	case 2: return d.su;
	default: return px_v3_scale(d.su, -1.0);
	}
}

/* The domain edges (bits) that (u, v) lies on, within eps of the widths. */
static int sgn_edges_at(const struct sgn_surf *g, double u, double v, double eps)
{
	double eu = eps * (g->u1 - g->u0), ev = eps * (g->v1 - g->v0);
	return (u - g->u0 <= eu) | (g->u1 - u <= eu) << 1 |
	       (v - g->v0 <= ev) << 2 | (g->v1 - v <= ev) << 3;
}

/* The sign tables of the model's kept surfaces (n->ks, n->n_ks). */
static int sgn_setup(struct nurbs_impl *n, const struct px_dist_opts *opts)
{
	double diag, tol, vol3 = 0.0;
	int i, e, k, rc, ns = n->n_ks;

	diag = px_v3_norm(px_v3_sub(n->box.max, n->box.min));
	tol = SIGN_TOL_REL * diag;
	n->tol = tol;
	n->on_tol = 1e-13 * diag;
	n->ss = calloc((size_t)ns, sizeof(*n->ss));
	if (!n->ss)
		return PX_E_NOMEM;
	n->n_ss = ns;
	for (i = 0; i < ns; i++) {
		struct sgn_surf *g = &n->ss[i];
		/* the model's kept copy (keep_inputs()): only the breaks are
		 * this table's own */
		const struct px_nurbs_surf *s = &n->ks[i];
		int nb0 = px_nurbs_surf_breaks(s, 0, NULL, 0);
		int nb1 = px_nurbs_surf_breaks(s, 1, NULL, 0);
		double *mem = malloc(((size_t)nb0 + (size_t)nb1 + 1) * sizeof(double));
		if (!mem)
			return PX_E_NOMEM;
		g->s = *s;
		g->brk[0] = mem;
		g->brk[1] = g->brk[0] + nb0;
		g->n_brk[0] = px_nurbs_surf_breaks(s, 0, g->brk[0], nb0);
		g->n_brk[1] = px_nurbs_surf_breaks(s, 1, g->brk[1], nb1);
		n->bytes += ((size_t)nb0 + (size_t)nb1) * sizeof(double);
		px_nurbs_surf_domain(&g->s, &g->u0, &g->u1, &g->v0, &g->v1);
		g->closed_u = px_nurbs_surf_closed(&g->s, 0, tol);
		g->closed_v = px_nurbs_surf_closed(&g->s, 1, tol);
		for (e = 0; e < 4; e++)
			g->collapsed[e] = px_nurbs_surf_edge_collapsed(&g->s, e, tol);
		g->box = px_nurbs_surf_aabb(&g->s);
		g->box.min = px_v3_sub(g->box.min, px_v3(tol, tol, tol));
		g->box.max = px_v3_add(g->box.max, px_v3(tol, tol, tol));
		rc = px_dist_model_create(NULL, 0, s, 1, opts, &g->dm);
		for (k = 0; rc == PX_OK && k < NURBS_WS; k++)
			rc = px_dist_ws_create(g->dm, &g->ws[k]);
		if (rc != PX_OK)
			return rc;
		{
			struct px_dist_info di;
			px_dist_model_info(g->dm, &di);
			n->bytes += sizeof(*g) + di.bytes +
				    NURBS_WS * (size_t)di.n_pieces * (sizeof(uint32_t) + 16);
		}
	}
	/* Every free edge sample must lie on another surface's edge, run the
	 * opposite way. */
	for (i = 0; i < ns; i++) {
		const struct sgn_surf *g = &n->ss[i];
		for (e = 0; e < 4; e++) {
			int dir = e < 2 ? 1 : 0, p = g->s.degree[dir], a, nkn, j;
			double kn[256];
			if (g->collapsed[e] || (e < 2 && g->closed_u) ||
			    (e >= 2 && g->closed_v))
				continue;
			nkn = sgn_knots(g->s.knots[dir], g->s.n_knots[dir],
					dir ? g->v0 : g->u0, dir ? g->v1 : g->u1, kn, 256);
			for (a = 0; a + 1 < nkn; a++)
				for (k = 0; k < 2 * p + 1; k++) {
					double t = kn[a] + (kn[a + 1] - kn[a]) * (k + 0.5) / (2 * p + 1);
					double u, v;
					px_vec3 x, ta;
					int found = 0;
					sgn_edge_uv(g, e, t, &u, &v);
					x = px_nurbs_surf_point(&g->s, u, v);
					ta = sgn_edge_tangent(g, e, u, v);
					n->edge_samples++;
					for (j = 0; j < ns && !found; j++) {
						const struct sgn_surf *h = &n->ss[j];
						struct px_dist_result d;
						px_vec3 tb;
						int on, eb, cnt;
						double c;
						if (j == i || px_aabb_dist2(&h->box, x) > 0.0)
							continue;
						if (px_dist_query_ws(h->dm, h->ws[0], x, &d) != PX_OK ||
						    d.dist > tol)
							continue;
						on = sgn_edges_at(h, d.u, d.v, 1e-6);
						cnt = __builtin_popcount((unsigned)on);
						if (cnt == 0)
							continue; /* on its inside: not an edge */
						if (cnt > 1) {
							found = 1; /* a corner: no single tangent */
							break;
						}
						eb = __builtin_ctz((unsigned)on);
						tb = sgn_edge_tangent(h, eb, d.u, d.v);
						if (px_v3_norm(ta) == 0.0 || px_v3_norm(tb) == 0.0) {
							found = 1;
							break;
						}
						c = px_v3_dot(ta, tb) / (px_v3_norm(ta) * px_v3_norm(tb));
						if (c > 0.5) {
							snprintf(n->why, sizeof(n->why),
								 "surfaces %d and %d are oriented "
								 "oppositely along their shared edge "
								 "near (%g, %g, %g)",
								 i, j, x.x, x.y, x.z);
							return PX_OK;
						}
						if (c < -0.5)
							found = 1;
					}
					if (!found) {
						snprintf(n->why, sizeof(n->why),
							 "edge %d of surface %d is not shared "
							 "with another surface near (%g, %g, %g)",
							 e, i, x.x, x.y, x.z);
						return PX_OK;
					}
				}
		}
	}
	for (i = 0; i < ns; i++)
		vol3 += sgn_volume3(&n->ss[i]);
	n->volume = vol3 / 3.0;
	if (!(fabs(n->volume) > 1e-9 * diag * diag * diag)) {
		snprintf(n->why, sizeof(n->why),
			 "closed, but the enclosed volume is zero (%g)", n->volume);
		return PX_OK;
	}
	n->orient = n->volume > 0.0 ? 1.0 : -1.0;
	n->volume = fabs(n->volume);
	n->closed = 1;
	snprintf(n->why, sizeof(n->why), "closed and consistently oriented");
	return PX_OK;
}

/* Sign of the query point of unsigned answer d (d->dist > 0) on a
 * closed shell: -1 inside, +1 outside. Uses workspace slot k. */
static int sgn_query(const struct nurbs_impl *n, int k,
		     const struct px_dist_result *d)
{
	const struct sgn_surf *g = &n->ss[d->entity];
	const double eps = 1e-9;
	px_vec3 nrm, acc = px_v3(0, 0, 0);
	double s;
	int j;

	if (!sgn_on_line(d->u, g->u0, g->u1, g->brk[0], g->n_brk[0],
			 eps * (g->u1 - g->u0)) &&
	    !sgn_on_line(d->v, g->v0, g->v1, g->brk[1], g->n_brk[1],
			 eps * (g->v1 - g->v0))) {
		nrm = sgn_unit(sgn_normal(&g->s, d->u, d->v));
		s = px_v3_dot(d->dir, nrm);
		if (fabs(s) >= 0.9)
			return s * n->orient < 0.0 ? -1 : 1;
	}
	/* Edge, corner, seam, crease, pole or vanishing normal. */
	sgn_sectors(g, n->orient, d->u, d->v, &acc);
	for (j = 0; j < n->n_ss; j++) {
		const struct sgn_surf *h = &n->ss[j];
		struct px_dist_result e;
		if (j == d->entity || px_aabb_dist2(&h->box, d->point) > 0.0)
			continue;
		if (px_dist_query_ws(h->dm, h->ws[k], d->point, &e) != PX_OK ||
		    e.dist > n->tol)
			continue;
		sgn_sectors(h, n->orient, e.u, e.v, &acc);
	}
	s = px_v3_dot(d->dir, acc);
	return s < 0.0 ? -1 : 1;
}

/* Take one of the workspaces without waiting; NURBS_WS when all are
 * taken. */
static int ws_take(struct nurbs_impl *n)
{
	int k;
	for (k = 0; k < NURBS_WS; k++)
		if (!atomic_flag_test_and_set_explicit(&n->busy[k],
						       memory_order_acquire))
			break;
	return k;
}

static void ws_give(struct nurbs_impl *n, int k)
{
	atomic_flag_clear_explicit(&n->busy[k], memory_order_release);
}

/* The model's answer from the unsigned one d (the global query's or a
 * stream's): the sign on closed shells (workspace slot k, or one taken
 * here when k < 0), the on-surface direction, the fields. Returns 1, 0
 * (beyond q->max_dist) or PX_E_BUSY. */
static int nurbs_answer(struct nurbs_impl *n, int k,
			const struct px_model_query *q,
			const struct px_dist_result *d,
			struct px_model_result *r)
{
	int sg = 1, own = 0;
	int want_sign = n->closed && !(q->flags & PX_QUERY_UNSIGNED);

	if (d->dist > q->max_dist)
		return 0;
	/* Within rounding of the surface the side is noise: outside. */
	if (want_sign && d->dist > n->on_tol) {
		if (k < 0) {
			k = ws_take(n);
			if (k == NURBS_WS)
				return PX_E_BUSY;
			own = 1;
		}
		sg = sgn_query(n, k, d);
		if (own)
			ws_give(n, k);
	}
	memset(r, 0, sizeof(*r));
	r->distance = d->dist;
	r->point = d->point;
	r->direction = d->dir;
	if (d->dist == 0.0) {
		/* On the model: any unit vector satisfies query = point +
		 * 0 * direction; keep the contract of a unit direction, the
		 * outward normal where a closed shell has one. */
		px_vec3 nn = px_v3(0, 0, 0);
		if (want_sign)
			nn = px_v3_scale(sgn_unit(sgn_normal(&n->ss[d->entity].s,
							     d->u, d->v)),
					 n->orient);
		r->direction = px_v3_norm(nn) > 0.5 ? nn : px_v3(0.0, 0.0, 1.0);
	} else if (sg < 0) {
		/* Inside: query = point + (-dist) * direction, direction
		 * pointing out of the solid. */
		r->distance = -d->dist;
		r->direction = px_v3_scale(d->dir, -1.0);
		r->inside = 1;
	}
	r->index = d->entity;
	r->sub = d->piece;
	r->feature = d->kind == PX_DIST_CURVE ? PX_FEATURE_CURVE : PX_FEATURE_SURFACE;
	r->u = d->u;
	r->v = d->v;
	r->is_signed = want_sign;
	r->iterations = d->iters;
	r->certified = d->certified;
	r->gap = d->gap;
	return 1;
}

static int nurbs_closest(const void *impl, const struct px_model_query *q,
			 struct px_model_result *r)
{
	/* The flags live in the impl, which the interface hands over as
	 * const; taking a workspace is the one write a query makes. */
	struct nurbs_impl *n = (struct nurbs_impl *)(uintptr_t)impl;
	struct px_dist_result d;
	int k, rc;

	k = ws_take(n);
	if (k == NURBS_WS)
		return PX_E_BUSY;
	rc = px_dist_query_ws(n->dm, n->ws[k], q->p, &d);
	if (rc == PX_OK)
		rc = nurbs_answer(n, k, q, &d, r);
	ws_give(n, k);
	return rc;
}

/* ---- tracked streams ------------------------------------------------------
 *
 * A stream is a px_strack over the model's surfaces and curves (a
 * px_track when there are curves alone), built from the inputs kept at
 * creation; its answers are exact (every critical distance followed, or
 * the global query where that cannot be proven), so they go through the
 * same signing as the global query's. Entity numbering is px_dist.h's
 * in both, as the model's own index. */

struct nurbs_stream {
	struct px_strack *st;
	struct px_track *tr;
	int n_curves;
	uint64_t tracked, global, cold, jumps;
};

static void stream_free(void *state)
{
	struct nurbs_stream *s = state;
	if (!s)
		return;
	px_strack_free(s->st);
	px_track_free(s->tr);
	free(s);
}

static int stream_create(const void *impl, const struct px_model_stream_opts *o,
			 void **state)
{
	const struct nurbs_impl *n = impl;
	struct nurbs_stream *s;
	int rc;

	*state = NULL;
	s = calloc(1, sizeof(*s));
	if (!s)
		return PX_E_NOMEM;
	s->n_curves = n->n_kc;
	if (n->n_ks > 0) {
		struct px_strack_opts so;
		px_strack_opts_default(&so);
		so.verify_every = o->verify_every;
		so.max_solves = o->max_solves;
		so.cold_switch = o->cold_switch;
		rc = px_strack_create(n->kc, n->n_kc, n->ks, n->n_ks, &so, &s->st);
	} else {
		struct px_track_opts to;
		px_track_opts_default(&to);
		to.verify_every = o->verify_every;
		to.cold_switch = o->cold_switch;
		rc = px_track_create(n->kc, n->n_kc, &to, &s->tr);
	}
	if (rc != PX_OK) {
		stream_free(s);
		return rc;
	}
	*state = s;
	return PX_OK;
}

static void stream_count(struct nurbs_stream *s, int source, int jumped)
{
	if (source == PX_TRACK_COLD)
		s->cold++;
	else if (source == PX_TRACK_GLOBAL || source == PX_TRACK_REINIT)
		s->global++;
	else
		s->tracked++;
	s->jumps += jumped != 0;
}

/* A tracker's answer t (px_strack_result or px_track_result: the same
 * field names) into the distance core's result d and the stream's note
 * (a surface's v apart). */
#define TRACK_ANSWER(d, note, t)                    \
	do {                                        \
		(d)->dist = (t).dist;               \
		(d)->point = (t).point;             \
		(d)->dir = (t).dir;                 \
		(d)->u = (t).u;                     \
		(d)->entity = (t).entity;           \
		(note)->source = (t).source;        \
		(note)->jumped = (t).jumped;        \
		(note)->n_crit = (t).n_crit;        \
	} while (0)

static int stream_query(const void *impl, void *state,
			const struct px_model_query *q, struct px_model_result *r,
			struct px_model_stream_note *note)
{
	struct nurbs_impl *n = (struct nurbs_impl *)(uintptr_t)impl;
	struct nurbs_stream *s = state;
	struct px_dist_result d;
	int rc;

	memset(&d, 0, sizeof(d));
	if (s->st) {
		struct px_strack_result sr;
		rc = px_strack_update(s->st, q->p, &sr);
		if (rc != PX_OK)
			return rc;
		TRACK_ANSWER(&d, note, sr);
		d.v = sr.v;
	} else {
		struct px_track_result tr;
		rc = px_track_update(s->tr, q->p, &tr);
		if (rc != PX_OK)
			return rc;
		TRACK_ANSWER(&d, note, tr);
	}
	stream_count(s, note->source, note->jumped);
	d.kind = d.entity < s->n_curves ? PX_DIST_CURVE : PX_DIST_SURFACE;
	d.piece = -1;
	d.certified = 1;
	return nurbs_answer(n, -1, q, &d, r);
}

/* The counts a stream reports from its tracker's stats t (px_strack_stats
 * or px_track_stats: the same field names). */
#define TRACK_STATS(st, t)                                \
	do {                                              \
		(st)->hot = (t).hot;                      \
		(st)->reinits = (t).reinits;              \
		(st)->verifications = (t).verifications;  \
		(st)->disagreements = (t).disagreements;  \
	} while (0)

static void stream_stats(const void *state, struct px_model_stream_stats *st)
{
	const struct nurbs_stream *s = state;
	st->tracked = s->tracked;
	st->global = s->global;
	st->cold = s->cold;
	st->jumps = s->jumps;
	if (s->st) {
		struct px_strack_stats ss;
		px_strack_get_stats(s->st, &ss);
		TRACK_STATS(st, ss);
	} else {
		struct px_track_stats ts;
		px_track_get_stats(s->tr, &ts);
		TRACK_STATS(st, ts);
	}
}

/* Copies of the inputs in one block (the caller's arrays may go). */
static int keep_inputs(struct nurbs_impl *n, const struct px_nurbs_curve *curves,
		       int nc, const struct px_nurbs_surf *surfs, int ns)
{
	size_t total = 0, at = 0;
	int i;
	for (i = 0; i < nc; i++)
		total += 4 * (size_t)curves[i].n_ctrl + (size_t)curves[i].n_knots;
	for (i = 0; i < ns; i++)
		total += 4 * (size_t)surfs[i].n_ctrl[0] * (size_t)surfs[i].n_ctrl[1] +
			 (size_t)surfs[i].n_knots[0] + (size_t)surfs[i].n_knots[1];
	n->kc = calloc((size_t)nc + 1, sizeof(*n->kc));
	n->ks = calloc((size_t)ns + 1, sizeof(*n->ks));
	n->kmem = malloc((total + 1) * sizeof(double));
	if (!n->kc || !n->ks || !n->kmem)
		return PX_E_NOMEM;
	for (i = 0; i < nc; i++) {
		const struct px_nurbs_curve *c = &curves[i];
		size_t npw = 4 * (size_t)c->n_ctrl, nk = (size_t)c->n_knots;
		n->kc[i] = *c;
		memcpy(n->kmem + at, c->pw, npw * sizeof(double));
		n->kc[i].pw = n->kmem + at;
		at += npw;
		memcpy(n->kmem + at, c->knots, nk * sizeof(double));
		n->kc[i].knots = n->kmem + at;
		at += nk;
	}
	for (i = 0; i < ns; i++) {
		const struct px_nurbs_surf *f = &surfs[i];
		size_t npw = 4 * (size_t)f->n_ctrl[0] * (size_t)f->n_ctrl[1];
		int d;
		n->ks[i] = *f;
		memcpy(n->kmem + at, f->pw, npw * sizeof(double));
		n->ks[i].pw = n->kmem + at;
		at += npw;
		for (d = 0; d < 2; d++) {
			size_t nk = (size_t)f->n_knots[d];
			memcpy(n->kmem + at, f->knots[d], nk * sizeof(double));
			n->ks[i].knots[d] = n->kmem + at;
			at += nk;
		}
	}
	n->n_kc = nc;
	n->n_ks = ns;
	n->bytes += ((size_t)nc + 1) * sizeof(*n->kc) +
		    ((size_t)ns + 1) * sizeof(*n->ks) + (total + 1) * sizeof(double);
	return PX_OK;
}

static px_aabb nurbs_aabb(const void *impl)
{
	return ((const struct nurbs_impl *)impl)->box;
}

static size_t nurbs_bytes(const void *impl)
{
	return ((const struct nurbs_impl *)impl)->bytes;
}

static void nurbs_free(void *impl)
{
	struct nurbs_impl *n = impl;
	int k, i;
	if (!n)
		return;
	for (i = 0; n->ss && i < n->n_ss; i++) {
		for (k = 0; k < NURBS_WS; k++)
			px_dist_ws_free(n->ss[i].ws[k]);
		px_dist_model_free(n->ss[i].dm);
		free(n->ss[i].brk[0]);
	}
	free(n->ss);
	free(n->kc);
	free(n->ks);
	free(n->kmem);
	for (k = 0; k < NURBS_WS; k++)
		px_dist_ws_free(n->ws[k]);
	px_dist_model_free(n->dm);
	free(n);
}

static const struct px_model_ops nurbs_ops = {
	.name = "nurbs",
	.kind = PX_MODEL_NURBS,
	.closest = nurbs_closest,
	.aabb = nurbs_aabb,
	.memory_bytes = nurbs_bytes,
	.free = nurbs_free,
	.stream_create = stream_create,
	.stream_query = stream_query,
	.stream_stats = stream_stats,
	.stream_free = stream_free,
};

int px_nurbs_model_create(const struct px_nurbs_curve *curves, int n_curves,
			  const struct px_nurbs_surf *surfs, int n_surfs,
			  const struct px_dist_opts *opts, struct px_model **out)
{
	struct nurbs_impl *n;
	struct px_dist_info info;
	int rc, k;

	if (!out)
		return PX_E_INVAL;
	*out = NULL;
	n = calloc(1, sizeof(*n));
	if (!n)
		return PX_E_NOMEM;
	for (k = 0; k < NURBS_WS; k++)
		atomic_flag_clear(&n->busy[k]);
	rc = px_dist_model_create(curves, n_curves, surfs, n_surfs, opts, &n->dm);
	for (k = 0; rc == PX_OK && k < NURBS_WS; k++)
		rc = px_dist_ws_create(n->dm, &n->ws[k]);
	if (rc != PX_OK) {
		nurbs_free(n);
		return rc;
	}
	px_dist_model_info(n->dm, &info);
	n->box = info.bounds;
	n->bytes = sizeof(*n) + info.bytes +
		   NURBS_WS * (size_t)info.n_pieces * (sizeof(uint32_t) + 16);
	rc = keep_inputs(n, curves, n_curves, surfs, n_surfs);
	if (rc != PX_OK) {
		nurbs_free(n);
		return rc;
	}
	if (n_curves > 0) {
		snprintf(n->why, sizeof(n->why),
			 "the model has curves: only surface shells are signed");
	} else {
		rc = sgn_setup(n, opts);
		if (rc != PX_OK) {
			nurbs_free(n);
			return rc;
		}
	}
	return px_model_create(&nurbs_ops, n,
			       PX_MODEL_CAP_EXACT |
				       (n->closed ? PX_MODEL_CAP_SIGNED : 0u),
			       out);
}

int px_nurbs_model_sign_info(const struct px_model *m,
			     struct px_nurbs_sign_info *info)
{
	const struct nurbs_impl *n;
	if (!m || !info || px_model_get_ops(m) != &nurbs_ops)
		return PX_E_INVAL;
	n = px_model_impl(m);
	memset(info, 0, sizeof(*info));
	info->closed = n->closed;
	info->volume = n->closed ? n->volume : 0.0;
	info->edge_samples = n->edge_samples;
	info->tol = n->tol;
	memcpy(info->why, n->why, sizeof(info->why));
	return PX_OK;
}

int px_nurbs_model_surfaces(const struct px_model *m,
			    const struct px_nurbs_surf **surfs)
{
	const struct nurbs_impl *n;
	if (!m || !surfs || px_model_get_ops(m) != &nurbs_ops)
		return PX_E_INVAL;
	n = px_model_impl(m);
	*surfs = n->ks;
	return n->n_ks;
}

const struct px_dist_model *px__nurbs_model_dist(const struct px_model *m)
{
	if (!m || px_model_get_ops(m) != &nurbs_ops)
		return NULL;
	return ((const struct nurbs_impl *)px_model_impl(m))->dm;
}
