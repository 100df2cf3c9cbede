/*
 * trim_query.c - point and box queries of a trimmed domain (px_trim.h):
 * crossing counts of the ray towards +u with the Bezier pieces, refined
 * by halving where the ray passes through a piece's hull at the point.
 */
#include <math.h>
#include <stddef.h>

#include "brep_internal.h"
#include "px_bern.h"

void px__trim_point(const struct px_trim *t, const struct trim_piece *p,
		    double s, double *x, double *y)
{
	const double *X = t->coef + p->off;
	const double *Y = X + p->deg + 1, *W = Y + p->deg + 1;
	double w = px_bern_eval(W, p->deg, s);
	*x = px_bern_eval(X, p->deg, s) / w;
	*y = px_bern_eval(Y, p->deg, s) / w;
}

/*
 * The three coefficient runs c[0 .. 3 (d + 1)) restricted to [a, b] in
 * place: px_bern_restrict()'s de Casteljau steps in the same order (so
 * the same values), run on the three at once without copies (a query
 * near a loop restricts a node at every halving).
 */
static void restrict3(double *c, int d, double a, double b)
{
	double *X = c, *Y = c + d + 1, *W = Y + d + 1, s, l;
	int i, k;

	if (b < 1.0) {
		/* Left part at b: the first coefficient of every step. */
		double lx[PX_NURBS_MAX_DEGREE + 1], ly[PX_NURBS_MAX_DEGREE + 1];
		double lw[PX_NURBS_MAX_DEGREE + 1];
		s = 1.0 - b;
		lx[0] = X[0], ly[0] = Y[0], lw[0] = W[0];
		for (k = d; k > 0; k--) {
			for (i = 0; i < k; i++) {
				X[i] = s * X[i] + b * X[i + 1];
				Y[i] = s * Y[i] + b * Y[i + 1];
				W[i] = s * W[i] + b * W[i + 1];
			}
			lx[d - k + 1] = X[0], ly[d - k + 1] = Y[0], lw[d - k + 1] = W[0];
		}
		for (i = 0; i <= d; i++)
			X[i] = lx[i], Y[i] = ly[i], W[i] = lw[i];
		a = a / b;
	}
	if (a > 0.0) {
		/* Right part at a: what the steps leave. */
		l = a;
		s = 1.0 - l;
		for (k = d; k > 0; k--)
			for (i = 0; i < k; i++) {
				X[i] = s * X[i] + l * X[i + 1];
				Y[i] = s * Y[i] + l * Y[i + 1];
				W[i] = s * W[i] + l * W[i + 1];
			}
	}
}

void px__trim_node_ctrl(const struct px_trim *t, const struct trim_piece *p,
			const struct trim_node *n, double *x, double *y,
			double *w, double box[4])
{
	double c[3 * (PX_NURBS_MAX_DEGREE + 1)];
	const double *rx = c, *ry = c + p->deg + 1, *rw = ry + p->deg + 1;
	int i, d = p->deg;

	for (i = 0; i < 3 * (d + 1); i++)
		c[i] = t->coef[p->off + i];
	restrict3(c, d, n->a, n->b);
	box[0] = trim_min(n->ax, n->ex), box[1] = trim_max(n->ax, n->ex);
	box[2] = trim_min(n->ay, n->ey), box[3] = trim_max(n->ay, n->ey);
	for (i = 0; i <= d; i++) {
		x[i] = rx[i] / rw[i], y[i] = ry[i] / rw[i];
		if (w)
			w[i] = rw[i];
		box[0] = trim_min(box[0], x[i]), box[1] = trim_max(box[1], x[i]);
		box[2] = trim_min(box[2], y[i]), box[3] = trim_max(box[3], y[i]);
	}
}

/* Net crossings of a curve running from height ay to ey with the whole
 * line at height v, counting y >= v as above (the half-open rule that
 * makes the count of a closed chain the winding number). */
static inline int end_rule(double ay, double ey, double v)
{
	return (ey >= v) - (ay >= v);
}

/*
 * Range [*xl, *xr] of x where the slab |y - v| <= sl meets the hull of
 * the control points and the node's end points: the points inside the
 * slab and the crossings of every pair of points with its two edges.
 * The computed points may each be off by the rounding slack sl, so the
 * true hull meets the line y = v within this range widened by sl (a
 * cut of the line alone would move by sl / slope on a flat segment).
 * Every crossing of the node's curve with the line lies there.
 */
static void hull_cut(const double *x, const double *y, int d,
		     const struct trim_node *n, double v, double sl,
		     double *xl, double *xr)
{
	double px[PX_NURBS_MAX_DEGREE + 3], py[PX_NURBS_MAX_DEGREE + 3];
	double lo = INFINITY, hi = -INFINITY;
	int i, j, e, m = d + 3;

	for (i = 0; i <= d; i++)
		px[i] = x[i], py[i] = y[i] - v;
	px[d + 1] = n->ax, py[d + 1] = n->ay - v;
	px[d + 2] = n->ex, py[d + 2] = n->ey - v;
	for (i = 0; i < m; i++)
		if (fabs(py[i]) <= sl)
			lo = trim_min(lo, px[i]), hi = trim_max(hi, px[i]);
	for (e = -1; e <= 1; e += 2) {
		double h = e * sl;
		for (i = 0; i < m; i++)
			for (j = i + 1; j < m; j++) {
				double a = py[i] - h, b = py[j] - h, c;
				if (!((a < 0 && b > 0) || (a > 0 && b < 0)))
					continue;
				c = px[i] + (px[j] - px[i]) * (a / (a - b));
				lo = trim_min(lo, c), hi = trim_max(hi, c);
			}
	}
	*xl = lo, *xr = hi;
}

/* Halve node nd (at depth d) onto the stack, left half on top, the
 * split point one value for both. */
static void push_halves(const struct px_trim *t, const struct trim_piece *p,
			const struct trim_node *nd, int d,
			struct trim_node *st, unsigned char *dep, int *n)
{
	double m = 0.5 * (nd->a + nd->b), mx, my;
	px__trim_point(t, p, m, &mx, &my);
	st[*n] = (struct trim_node){m, nd->b, mx, my, nd->ex, nd->ey};
	dep[(*n)++] = (unsigned char)(d + 1);
	st[*n] = (struct trim_node){nd->a, m, nd->ax, nd->ay, mx, my};
	dep[(*n)++] = (unsigned char)(d + 1);
}

/*
 * Clipping (as Bezier clipping does): the curve meets the line y = v
 * where f = W (y - v) vanishes, a polynomial whose Bernstein
 * coefficients on the node are w_i (y_i - v); its roots lie where the
 * hull of the points (i / d, f_i) meets the band |f| <= eps (eps covers
 * the rounding of the f_i). Returns -1 when no root can exist (the
 * curve keeps more than the slack away from the line, so its ends lie
 * on one side and it counts nothing), 1 with the narrowed node in *out
 * when the roots fit in at most half of the node (a little widened, and
 * with both cut-off ends on the side of the node's ends: the cut-off
 * parts keep off the line, so they count nothing), else 0 (halve).
 * Near a simple crossing this shrinks the node quadratically.
 */
static int clip_node(const struct px_trim *t, const struct trim_piece *p,
		     const struct trim_node *nd, const double *y,
		     const double *w, double v, struct trim_node *out)
{
	double f[PX_NURBS_MAX_DEGREE + 1], eps = 0.0, lo = INFINITY;
	double hi = -INFINITY, pad, c, e, cx, cy, ex, ey;
	int i, j, k, d = p->deg;

	for (i = 0; i <= d; i++) {
		f[i] = w[i] * (y[i] - v);
		eps = trim_max(eps, w[i]);
	}
	eps *= 2.0 * t->slack;
	for (i = 0; i <= d; i++)
		if (fabs(f[i]) <= eps)
			lo = trim_min(lo, (double)i / d), hi = trim_max(hi, (double)i / d);
	for (k = -1; k <= 1; k += 2)
		for (i = 0; i <= d; i++)
			for (j = i + 1; j <= d; j++) {
				double a = f[i] - k * eps, b = f[j] - k * eps, s;
				if (!((a < 0 && b > 0) || (a > 0 && b < 0)))
					continue;
				s = (i + (j - i) * (a / (a - b))) / d;
				lo = trim_min(lo, s), hi = trim_max(hi, s);
			}
	if (lo > hi)
		return -1;
	pad = 0.02 * (hi - lo) + 1e-9;
	lo = lo - pad > 0.0 ? lo - pad : 0.0;
	hi = hi + pad < 1.0 ? hi + pad : 1.0;
	if (hi - lo > 0.5)
		return 0;
	c = lo > 0.0 ? nd->a + lo * (nd->b - nd->a) : nd->a;
	e = hi < 1.0 ? nd->a + hi * (nd->b - nd->a) : nd->b;
	if (!(c < e))
		return 0;
	cx = nd->ax, cy = nd->ay, ex = nd->ex, ey = nd->ey;
	if (c > nd->a) {
		px__trim_point(t, p, c, &cx, &cy);
		if ((cy >= v) != (nd->ay >= v))
			return 0;
	}
	if (e < nd->b) {
		px__trim_point(t, p, e, &ex, &ey);
		if ((ey >= v) != (nd->ey >= v))
			return 0;
	}
	*out = (struct trim_node){c, e, cx, cy, ex, ey};
	return 1;
}

/*
 * Depth-first halving; the left half is examined first, the right one
 * waits on the stack, so the stack never holds more than one node per
 * level. Every node that is not halved counts the exact crossings of
 * its own curve (joined to its stored end points), and neighbouring
 * nodes share those end points, so the sum is the crossing count of
 * the closed chain.
 */
int px__trim_piece_cross(const struct px_trim *t, const struct trim_piece *p,
			 double u, double v, int *on, double *s)
{
	struct trim_node st[PX_TRIM_MAX_DEPTH + 2];
	unsigned char dep[PX_TRIM_MAX_DEPTH + 2];
	double x[PX_NURBS_MAX_DEGREE + 1], y[PX_NURBS_MAX_DEGREE + 1];
	double w[PX_NURBS_MAX_DEGREE + 1], box[4], xl, xr, sl = t->slack;
	int n = 1, sum = 0;

	if (p->by1 < v || p->by0 > v || p->bx1 < u)
		return 0;
	if (p->bx0 > u)
		return end_rule(p->ay, p->ey, v);
	st[0] = (struct trim_node){0.0, 1.0, p->ax, p->ay, p->ex, p->ey};
	dep[0] = 0;
	while (n > 0) {
		struct trim_node nd = st[--n];
		int d = dep[n];

		px__trim_node_ctrl(t, p, &nd, x, y, w, box);
		if (box[3] + sl < v || box[2] - sl > v || box[1] + sl < u)
			continue;
		if (box[0] - sl > u) {
			sum += end_rule(nd.ay, nd.ey, v);
			continue;
		}
		hull_cut(x, y, p->deg, &nd, v, sl, &xl, &xr);
		if (xr + sl < u)
			continue;
		if (xl - sl > u) {
			sum += end_rule(nd.ay, nd.ey, v);
			continue;
		}
		if (d >= PX_TRIM_MAX_DEPTH ||
		    hypot(box[1] - box[0], box[3] - box[2]) <= t->on_tol) {
			*on = 1;
			*s = 0.5 * (nd.a + nd.b);
			return 0;
		}
		switch (clip_node(t, p, &nd, y, w, v, &st[n])) {
		case -1:
			break;
		case 1:
			dep[n++] = (unsigned char)(d + 1);
			break;
		default:
			push_halves(t, p, &nd, d, st, dep, &n);
		}
	}
	return sum;
}

int px__trim_winding_range(const struct px_trim *t, int lo, int hi,
			   double u, double v, int *on, int *pi, double *s)
{
	int i, w = 0;
	for (i = t->loop_first[lo]; i < t->loop_first[hi]; i++) {
		w += px__trim_piece_cross(t, &t->pc[i], u, v, on, s);
		if (*on) {
			*pi = i;
			return 0;
		}
	}
	return w;
}

/*
 * A piece that meets the segment from (u, v) to a point of cell (r, k)
 * lies in one of the cells c..k of row r (the cell functions are
 * monotone). Walking to the first cell k without pieces, whose winding
 * w_k is stored, the pieces of cells c..k-1 end left of that cell, so
 * they count nothing from there: w(u, v) = w_k + their crossings from
 * (u, v). A piece listed in several cells counts once, in the first of
 * them at or after c.
 */
int px__trim_walk(const struct px_trim *t, int r, int c, double u, double v,
		  int *on, int *pi, double *s)
{
	int k, w = 0;
	for (k = c; k < t->g; k++) {
		int cell = r * t->g + k, i;
		int b = t->cell_start[cell], e = t->cell_start[cell + 1];
		if (b == e)
			return w + t->cell_wind[cell];
		for (i = b; i < e; i++) {
			const struct trim_piece *p = &t->pc[t->cell_item[i]];
			if (k != (p->col0 > c ? p->col0 : c))
				continue;
			w += px__trim_piece_cross(t, p, u, v, on, s);
			if (*on) {
				*pi = t->cell_item[i];
				return 0;
			}
		}
	}
	return w;
}

int px_trim_contains(const struct px_trim *t, double u, double v,
		     struct px_trim_hit *hit)
{
	struct px_trim_hit h = {PX_TRIM_OUTSIDE, 0, -1, -1, 0.0};
	int on = 0, pi = -1;
	double s = 0.0;

	if (!t)
		return PX_E_INVAL;
	if (!isfinite(u) || !isfinite(v))
		return PX_E_NAN;
	/* Every piece lies in the box of all control points widened by the
	 * slack; beyond it the winding number is 0. */
	if (!(u < t->bx0 - t->slack || u > t->bx1 + t->slack ||
	      v < t->by0 - t->slack || v > t->by1 + t->slack)) {
		h.winding = px__trim_walk(t, trim_row(t, v), trim_col(t, u),
					  u, v, &on, &pi, &s);
		if (on) {
			const struct trim_piece *p = &t->pc[pi];
			h.where = PX_TRIM_BOUNDARY;
			h.winding = 0;
			h.loop = p->loop, h.curve = p->curve;
			h.t = p->t0 + s * (p->t1 - p->t0);
		} else {
			h.where = h.winding ? PX_TRIM_INSIDE : PX_TRIM_OUTSIDE;
		}
	}
	if (hit)
		*hit = h;
	return h.where;
}

/*
 * 1 when piece p may enter the box q (widened by the slack): a node
 * whose end point lies inside the box proves it, a node whose box
 * misses the box clears itself; the budget shared by one
 * classification bounds the work and, spent, answers 1.
 */
static int piece_meets_box(const struct px_trim *t,
			   const struct trim_piece *p, const double q[4],
			   int *budget)
{
	struct trim_node st[PX_TRIM_MAX_DEPTH + 2];
	unsigned char dep[PX_TRIM_MAX_DEPTH + 2];
	double x[PX_NURBS_MAX_DEGREE + 1], y[PX_NURBS_MAX_DEGREE + 1];
	double box[4], sl = t->slack;
	int n = 1;

	if (p->bx1 < q[0] || p->bx0 > q[1] || p->by1 < q[2] || p->by0 > q[3])
		return 0;
	st[0] = (struct trim_node){0.0, 1.0, p->ax, p->ay, p->ex, p->ey};
	dep[0] = 0;
	while (n > 0) {
		struct trim_node nd = st[--n];
		int d = dep[n];

		if (--*budget < 0)
			return 1;
		px__trim_node_ctrl(t, p, &nd, x, y, NULL, box);
		if (box[1] + sl < q[0] || box[0] - sl > q[1] ||
		    box[3] + sl < q[2] || box[2] - sl > q[3])
			continue;
		if ((nd.ax > q[0] + sl && nd.ax < q[1] - sl &&
		     nd.ay > q[2] + sl && nd.ay < q[3] - sl) ||
		    d >= PX_TRIM_MAX_DEPTH ||
		    hypot(box[1] - box[0], box[3] - box[2]) <= t->on_tol)
			return 1;
		push_halves(t, p, &nd, d, st, dep, &n);
	}
	return 0;
}

/*
 * No piece enters the box: the winding number is the same all over it
 * (the box is connected and no loop meets it), so its centre decides.
 * The pieces examined are those of the cells the box covers, each once
 * (in the first covered cell of its list), or all of them when that is
 * fewer.
 */
int px_trim_classify_box(const struct px_trim *t, double u0, double u1,
			 double v0, double v1)
{
	double q[4];
	int budget = PX_TRIM_BOX_BUDGET, r0, r1, c0, c1, r, c, i;

	if (!t)
		return PX_E_INVAL;
	if (!isfinite(u0) || !isfinite(u1) || !isfinite(v0) || !isfinite(v1))
		return PX_E_NAN;
	if (u0 > u1 || v0 > v1)
		return PX_E_INVAL;
	q[0] = u0, q[1] = u1, q[2] = v0, q[3] = v1;
	r0 = trim_row(t, v0), r1 = trim_row(t, v1);
	c0 = trim_col(t, u0), c1 = trim_col(t, u1);
	if ((double)(r1 - r0 + 1) * (c1 - c0 + 1) > t->n_pieces) {
		for (i = 0; i < t->n_pieces; i++)
			if (piece_meets_box(t, &t->pc[i], q, &budget))
				return PX_TRIM_BOX_CROSSED;
	} else {
		for (r = r0; r <= r1; r++)
			for (c = c0; c <= c1; c++) {
				int cell = r * t->g + c;
				for (i = t->cell_start[cell];
				     i < t->cell_start[cell + 1]; i++) {
					const struct trim_piece *p =
						&t->pc[t->cell_item[i]];
					if (r != (p->row0 > r0 ? p->row0 : r0) ||
					    c != (p->col0 > c0 ? p->col0 : c0))
						continue;
					if (piece_meets_box(t, p, q, &budget))
						return PX_TRIM_BOX_CROSSED;
				}
			}
	}
	switch (px_trim_contains(t, 0.5 * (u0 + u1), 0.5 * (v0 + v1), NULL)) {
	case PX_TRIM_INSIDE:
		return PX_TRIM_BOX_INSIDE;
	case PX_TRIM_OUTSIDE:
		return PX_TRIM_BOX_OUTSIDE;
	default:
		return PX_TRIM_BOX_CROSSED;
	}
}

int px_trim_loop_count(const struct px_trim *t)
{
	return t ? t->n_loops : 0;
}

int px_trim_piece_count(const struct px_trim *t)
{
	return t ? t->n_pieces : 0;
}

int px_trim_grid_size(const struct px_trim *t)
{
	return t ? t->g : 0;
}

int px_trim_loop_reversed(const struct px_trim *t, int k)
{
	if (!t || k < 0 || k >= t->n_loops)
		return -1;
	return t->reversed[k];
}

double px_trim_loop_area(const struct px_trim *t, int k)
{
	if (!t || k < 0 || k >= t->n_loops)
		return 0.0;
	return t->area[k];
}

void px_trim_bounds(const struct px_trim *t, double *u0, double *u1,
		    double *v0, double *v1)
{
	if (!t)
		return;
	if (u0)
		*u0 = t->bx0;
	if (u1)
		*u1 = t->bx1;
	if (v0)
		*v0 = t->by0;
	if (v1)
		*v1 = t->by1;
}

void px_trim_tolerances(const struct px_trim *t, double *close_tol,
			double *on_tol)
{
	if (!t)
		return;
	if (close_tol)
		*close_tol = t->close_tol;
	if (on_tol)
		*on_tol = t->on_tol;
}
