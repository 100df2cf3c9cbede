/*
 * track_event.c - curve tracker (px_track.h): event detection: the definite
 * tests along a segment, the leaf certificates and radii, the event heap.
 * The layout and the shared declarations are in track_internal.h.
 */
#include "track_internal.h"

/* ------------------------------------------------------------------ */
/* event detection                                                     */

/* Coefficients a - p.b (count m, stride m) sign-definite along p0 -> p1. */
static int definite_seg(const double *a, int m, px_vec3 p0, px_vec3 p1,
			double tol)
{
	const double *bx = a + m, *by = bx + m, *bz = by + m;
	int i, pos = 0, neg = 0;
	for (i = 0; i < m; i++) {
		double v0 = a[i] - (p0.x * bx[i] + p0.y * by[i] + p0.z * bz[i]);
		double v1 = a[i] - (p1.x * bx[i] + p1.y * by[i] + p1.z * bz[i]);
		if (v0 > tol && v1 > tol)
			pos++;
		else if (v0 < -tol && v1 < -tol)
			neg++;
		else
			return 0;
		if (pos && neg)
			return 0;
	}
	return 1;
}

/* r, lowered to the radius within which g keeps its sign at each break
 * end of leaf l around p (a root crossing a break is an event). */
static double break_end_radius(const struct px_track *t, const struct leaf *l,
			       px_vec3 p, double r)
{
	const double *a = leaf_a(t, l), *ib = t->ipool + l->ioff;
	int n = l->n, i;
	for (i = 0; i < 2 && r > 0.0; i++) {
		double v;
		int e = i ? n : 0;
		if (!(l->flags & (i ? LF_EV1 : LF_EV0)))
			continue;
		v = fabs(gco(a, n, e, p));
		v = v > l->tol_g ? (v - l->tol_g) * ib[e] : 0.0;
		if (v < r)
			r = v;
	}
	return r;
}

/* Signs of c0[0..m-1] and c1[0..m-1] all one, beyond tol. */
static int definite2(const double *c0, const double *c1, int m, double tol)
{
	int i, pos = 0, neg = 0;
	for (i = 0; i < m; i++) {
		if (c0[i] > tol && c1[i] > tol)
			pos = 1;
		else if (c0[i] < -tol && c1[i] < -tol)
			neg = 1;
		else
			return 0;
	}
	return !(pos && neg);
}

#define TRK_FINE_DEPTH 3
/*
 * The leaf's proof by pieces, where the whole-leaf proof failed: an event
 * is a double root, g = dg/ds = 0 at one (s, point), so the leaf is free
 * of events along p0 -> p1 when each piece of it in s is free of them:
 * g of one sign there (no root) or dg/ds of one sign (one simple root at
 * most). Both are Bernstein polynomials in s with coefficients affine in
 * the point, so a piece's coefficients taken at p0 and at p1 (split the
 * same way: subdivision is linear) of one sign prove it for the whole
 * segment. Halves down to TRK_FINE_DEPTH levels; a piece still unproven
 * there counts as an event (the leaf is solved again, as before).
 * Saves most of the root isolations that the whole-leaf bound asked for
 * without a transition.
 */
static int leaf_event_fine(const double *a, const double *ib, int n,
			   px_vec3 p0, px_vec3 p1, double tol_g, double tol_d,
			   double *rad)
{
	struct piece {
		double g0[TRK_NG + 1], g1[TRK_NG + 1], d0[TRK_NG], d1[TRK_NG];
		int depth;
	} st[TRK_FINE_DEPTH + 2];
	const double *da = a + 4 * (n + 1);
	double ig = INFINITY, id = INFINITY, r1 = INFINITY;
	int sp = 1, i;
	/* a piece's coefficients are convex combinations of the leaf's, so
	 * their gradients in the point are no longer than the longest of the
	 * leaf's: 1 / max |b| bounds how fast any of them changes */
	for (i = 0; i <= n; i++)
		ig = ib[i] < ig ? ib[i] : ig;
	for (i = 0; i < n; i++)
		id = ib[n + 1 + i] < id ? ib[n + 1 + i] : id;
	for (i = 0; i <= n; i++) {
		st[0].g0[i] = gco(a, n, i, p0);
		st[0].g1[i] = gco(a, n, i, p1);
	}
	for (i = 0; i < n; i++) {
		st[0].d0[i] = gco(da, n - 1, i, p0);
		st[0].d1[i] = gco(da, n - 1, i, p1);
	}
	st[0].depth = 0;
	*rad = 0.0;
	while (sp > 0) {
		struct piece *q = &st[sp - 1], *r;
		int pg = definite2(q->g0, q->g1, n + 1, tol_g);
		int pd = definite2(q->d0, q->d1, n, tol_d);
		if (pg || pd) {
			/* the piece's radius at p1: the exclusion that holds
			 * (the larger when both do) */
			double rg = 0.0, rd = 0.0, m = INFINITY;
			if (pg) {
				for (i = 0; i <= n; i++)
					m = fabs(q->g1[i]) < m ? fabs(q->g1[i]) : m;
				rg = (m - tol_g) * ig;
			}
			if (pd) {
				m = INFINITY;
				for (i = 0; i < n; i++)
					m = fabs(q->d1[i]) < m ? fabs(q->d1[i]) : m;
				rd = (m - tol_d) * id;
			}
			m = rg > rd ? rg : rd;
			if (m < r1)
				r1 = m;
			sp--;
			continue;
		}
		if (q->depth >= TRK_FINE_DEPTH)
			return 1;
		/* q becomes the left half, the right half goes above it */
		r = &st[sp++];
		bern_halves(q->g0, n, r->g0);
		bern_halves(q->g1, n, r->g1);
		bern_halves(q->d0, n - 1, r->d0);
		bern_halves(q->d1, n - 1, r->d1);
		r->depth = ++q->depth;
	}
	*rad = r1 > 0.0 ? r1 : 0.0;
	return 0;
}

/* May leaf l hold an event while the point runs p0 -> p1? */
int px__tk_leaf_event(const struct px_track *t, const struct leaf *l,
		      px_vec3 p0, px_vec3 p1, double *rfine)
{
	const double *a = leaf_a(t, l);
	int n = l->n;
	*rfine = 0.0;
	if (definite_seg(a, n + 1, p0, p1, l->tol_g))
		return 0;
	if (l->flags & (LF_EV0 | LF_EV1)) {
		int i;
		for (i = 0; i < 2; i++) {
			double v0, v1;
			if (!(l->flags & (i ? LF_EV1 : LF_EV0)))
				continue;
			v0 = gco(a, n, i ? n : 0, p0);
			v1 = gco(a, n, i ? n : 0, p1);
			if (!((v0 > l->tol_g && v1 > l->tol_g) ||
			      (v0 < -l->tol_g && v1 < -l->tol_g)))
				return 1;
		}
	}
	if (n < 1)
		return 0;
	if (definite_seg(a + 4 * (n + 1), n, p0, p1, l->tol_d))
		return 0;
	if (leaf_event_fine(a, t->ipool + l->ioff, n, p0, p1, l->tol_g, l->tol_d,
			    rfine))
		return 1;
	/* a break end's sign bounds it too (the whole-leaf radius holds
	 * that term already) */
	*rfine = break_end_radius(t, l, p1, *rfine);
	return 0;
}

/* Radius within which coefficients a - p.b (count m, stride m; inverse
 * norms ib) keep their signs around p: 0 when they are not
 * sign-definite at p (the linear bound |dp . b_i| <= |dp| |b_i|). */
static double definite_radius(const double *a, const double *ib, int m,
			      px_vec3 p, double tol)
{
	const double *bx = a + m, *by = bx + m, *bz = by + m;
	double r = INFINITY;
	int i, sg = 0;
	for (i = 0; i < m; i++) {
		double v = a[i] - (p.x * bx[i] + p.y * by[i] + p.z * bz[i]);
		int s = v > tol ? 1 : (v < -tol ? -1 : 0);
		if (!s || (sg && s != sg))
			return 0.0;
		sg = s;
		{
			double ri = ((v > 0.0 ? v : -v) - tol) * ib[i];
			if (ri < r)
				r = ri;
		}
	}
	return r;
}

double px__tk_box_dist(const px_aabb *b, px_vec3 p)
{
	double dx = b->min.x - p.x > 0.0 ? b->min.x - p.x
					: (p.x - b->max.x > 0.0 ? p.x - b->max.x : 0.0);
	double dy = b->min.y - p.y > 0.0 ? b->min.y - p.y
					: (p.y - b->max.y > 0.0 ? p.y - b->max.y : 0.0);
	double dz = b->min.z - p.z > 0.0 ? b->min.z - p.z
					: (p.z - b->max.z > 0.0 ? p.z - b->max.z : 0.0);
	return sqrt(dx * dx + dy * dy + dz * dz);
}

/* Radius within which dg/ds of leaf l keeps its sign around p (at most
 * one simple root in the leaf: no event) and g keeps its sign at a break
 * end of it (no root through it); 0 when not proven at p. */
double px__tk_leaf_dradius(const struct px_track *t, const struct leaf *l,
			   px_vec3 p)
{
	const double *a = leaf_a(t, l), *ib = t->ipool + l->ioff;
	int n = l->n;
	double r = n >= 1 ? definite_radius(a + 4 * (n + 1), ib + n + 1, n, p,
					    l->tol_d)
			  : INFINITY;
	return break_end_radius(t, l, p, r);
}

/* Distance p may travel (inside the working volume) before leaf l can
 * have an event: the distance to its event cells, or the radius where
 * one of the two exclusions of leaf_event() still holds (g of one sign:
 * no root at all; dg/ds of one sign: one simple root at most), whichever
 * is largest. */
double px__tk_leaf_radius(const struct px_track *t, const struct leaf *l,
			  px_vec3 p)
{
	const double *a = leaf_a(t, l), *ib = t->ipool + l->ioff;
	double r, rd, rb;
	if (!l->boxed || (t->fault & 4))
		return INFINITY;
	rb = px__tk_box_dist(&l->box, p);
	r = definite_radius(a, ib, l->n + 1, p, l->tol_g);
	rd = px__tk_leaf_dradius(t, l, p);
	if (rd > r)
		r = rd;
	return r > rb ? r : rb;
}

/* Safe radii of all leaves at p (inside the working volume). */
void px__tk_heap_rebuild(struct px_track *t, px_vec3 p)
{
	int i;
	double nd = INFINITY;
	for (i = 0; i < t->n_leaves; i++) {
		double rad = px__tk_leaf_radius(t, &t->leaf[i], p) * (1.0 - 1e-9);
		double x = t->travel + rad;
		t->expiry[i] = x;
		t->ectr[i] = p;
		t->erad[i] = rad;
		if (i % TRK_GROUP == 0)
			t->gdue[i / TRK_GROUP] = x;
		else if (x < t->gdue[i / TRK_GROUP])
			t->gdue[i / TRK_GROUP] = x;
		if (x < nd)
			nd = x;
	}
	t->next_due = nd;
	t->heap_ok = 1;
}
