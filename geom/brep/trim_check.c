/*
 * trim_check.c - setup checks of a trimmed domain (px_trim.h): the
 * signed area of a loop, and the test that no loop crosses or touches
 * itself or another (box-pruned pairs of pieces, halved until they part
 * or come within the touching tolerance).
 */
#include <math.h>
#include <stdlib.h>

#include "brep_internal.h"
#include "px_bern.h"

/* Gauss-Legendre, 8 nodes on [0, 1]: exact for polynomials of degree
 * 15, and the pieces are short and smooth. */
static const double gl_s[8] = {
	0.019855071751231856, 0.10166676129318664, 0.23723379504183550,
	0.40828267875217510,  0.59171732124782490, 0.76276620495816450,
	0.89833323870681336,  0.98014492824876814};
static const double gl_w[8] = {
	0.050614268145188130, 0.11119051722668724, 0.15685332293894364,
	0.18134189168918100,  0.18134189168918100, 0.15685332293894364,
	0.11119051722668724,  0.050614268145188130};

/* 1/2 * integral of (x dy - y dx) around the loop, about the centre of
 * the domain's box (fewer cancelling digits), with the short straight
 * joins between each piece's curve and its stored end points. */
double px__trim_loop_area(const struct px_trim *t, int k)
{
	double cx = 0.5 * (t->bx0 + t->bx1), cy = 0.5 * (t->by0 + t->by1);
	double sum = 0.0;
	int i, j;

	for (i = t->loop_first[k]; i < t->loop_first[k + 1]; i++) {
		const struct trim_piece *p = &t->pc[i];
		const double *X = t->coef + p->off;
		const double *Y = X + p->deg + 1, *W = Y + p->deg + 1;
		double x0 = X[0] / W[0] - cx, y0 = Y[0] / W[0] - cy;
		double x1 = X[p->deg] / W[p->deg] - cx;
		double y1 = Y[p->deg] / W[p->deg] - cy;
		for (j = 0; j < 8; j++) {
			double dX, dY, dW, x, y, w, dx, dy;
			double Xv = px_bern_eval_d(X, p->deg, gl_s[j], &dX);
			double Yv = px_bern_eval_d(Y, p->deg, gl_s[j], &dY);
			w = px_bern_eval_d(W, p->deg, gl_s[j], &dW);
			x = Xv / w, y = Yv / w;
			dx = (dX - x * dW) / w, dy = (dY - y * dW) / w;
			sum += gl_w[j] * ((x - cx) * dy - (y - cy) * dx);
		}
		sum += (p->ax - cx) * y0 - x0 * (p->ay - cy);
		sum += x1 * (p->ey - cy) - (p->ex - cx) * y1;
	}
	return 0.5 * sum;
}

/* A node of one piece in the crossing test. */
struct xnode {
	int pi;
	struct trim_node n;
};

/* A point where two nodes may meet legitimately (a joint of the loop or
 * a halving point), and how far around it they are left alone. */
struct joint {
	double x, y, r;
};

struct xctx {
	const struct px_trim *t;
	double tol;
	long budget;
	int pa, pb;   /* pieces of the crossing found */
	double u, v;  /* where */
};

enum { X_NONE = 0, X_FOUND = 1, X_UNDECIDED = 2 };

static void xbox(const struct xctx *c, const struct xnode *a, double *x,
		 double *y, double box[4])
{
	px__trim_node_ctrl(c->t, &c->t->pc[a->pi], &a->n, x, y, NULL, box);
}

static void xsplit(const struct xctx *c, const struct xnode *a,
		   struct xnode *l, struct xnode *r)
{
	double m = 0.5 * (a->n.a + a->n.b), mx, my;
	px__trim_point(c->t, &c->t->pc[a->pi], m, &mx, &my);
	*l = *a, *r = *a;
	l->n.b = m, l->n.ex = mx, l->n.ey = my;
	r->n.a = m, r->n.ax = mx, r->n.ay = my;
}

static int in_square(const double b[4], const struct joint *j)
{
	return b[0] >= j->x - j->r && b[1] <= j->x + j->r &&
	       b[2] >= j->y - j->r && b[3] <= j->y + j->r;
}

/* Do nodes a and b come within the tolerance of each other, away from
 * the joints? Halves the larger node until they part or both are
 * smaller than the tolerance. */
static int pair(struct xctx *c, const struct xnode *a, const struct xnode *b,
		const struct joint *jt, int nj)
{
	double x[PX_NURBS_MAX_DEGREE + 1], y[PX_NURBS_MAX_DEGREE + 1];
	double ba[4], bb[4], g = c->tol + 2.0 * c->t->slack, da, db;
	struct xnode l, r;
	int i, rc;

	if (--c->budget < 0)
		return X_UNDECIDED;
	xbox(c, a, x, y, ba);
	xbox(c, b, x, y, bb);
	if (ba[1] + g < bb[0] || bb[1] + g < ba[0] || ba[3] + g < bb[2] ||
	    bb[3] + g < ba[2])
		return X_NONE;
	for (i = 0; i < nj; i++)
		if (in_square(ba, &jt[i]) && in_square(bb, &jt[i]))
			return X_NONE;
	da = hypot(ba[1] - ba[0], ba[3] - ba[2]);
	db = hypot(bb[1] - bb[0], bb[3] - bb[2]);
	if (da <= c->tol && db <= c->tol) {
		c->pa = a->pi, c->pb = b->pi;
		c->u = 0.25 * (ba[0] + ba[1] + bb[0] + bb[1]);
		c->v = 0.25 * (ba[2] + ba[3] + bb[2] + bb[3]);
		return X_FOUND;
	}
	if (da >= db) {
		xsplit(c, a, &l, &r);
		rc = pair(c, &l, b, jt, nj);
		return rc ? rc : pair(c, &r, b, jt, nj);
	}
	xsplit(c, b, &l, &r);
	rc = pair(c, a, &l, jt, nj);
	return rc ? rc : pair(c, a, &r, jt, nj);
}

/* 1 when the values run strictly one way: the curve is then monotone in
 * that coordinate (a rational Bezier curve is, when its Cartesian control
 * points are) and cannot meet itself. */
static int monotone(const double *v, int d)
{
	int i, up = 1, down = 1;
	for (i = 0; i < d; i++) {
		up &= v[i + 1] >= v[i];
		down &= v[i + 1] <= v[i];
	}
	return (up || down) && v[d] != v[0];
}

/* Does node a meet itself? (jt: the loop's own joint when the loop is
 * this one piece.) */
static int self(struct xctx *c, const struct xnode *a, const struct joint *jt,
		int nj)
{
	double x[PX_NURBS_MAX_DEGREE + 1], y[PX_NURBS_MAX_DEGREE + 1], box[4];
	struct joint j2[2];
	struct xnode l, r;
	int d = c->t->pc[a->pi].deg, rc;

	if (--c->budget < 0)
		return X_UNDECIDED;
	xbox(c, a, x, y, box);
	if (monotone(x, d) || monotone(y, d) ||
	    hypot(box[1] - box[0], box[3] - box[2]) <= c->tol)
		return X_NONE;
	xsplit(c, a, &l, &r);
	rc = self(c, &l, jt, nj);
	if (!rc)
		rc = self(c, &r, jt, nj);
	if (rc)
		return rc;
	j2[0] = (struct joint){l.n.ex, l.n.ey, 2.0 * c->tol};
	if (nj)
		j2[1] = jt[0];
	return pair(c, &l, &r, j2, nj + 1);
}

static int next_piece(const struct px_trim *t, int i)
{
	const struct trim_piece *p = &t->pc[i];
	return i + 1 < t->loop_first[p->loop + 1] ? i + 1
						  : t->loop_first[p->loop];
}

/* When the loop runs from the end of piece i to piece j over pieces
 * shorter in all than the closure tolerance, they meet there: the joint
 * at the end of i, with room for the gap closed there. */
static int joint_after(const struct px_trim *t, int i, int j, double tol,
		       struct joint *jt)
{
	double acc = 0.0;
	int k = next_piece(t, i), steps;
	for (steps = 0; steps < 64; steps++) {
		const struct trim_piece *p = &t->pc[k];
		if (k == j) {
			jt->x = t->pc[i].ex, jt->y = t->pc[i].ey;
			jt->r = 2.0 * t->close_tol + 2.0 * tol + acc;
			return 1;
		}
		if (k == i || p->loop != t->pc[i].loop)
			return 0;
		acc += hypot(p->bx1 - p->bx0, p->by1 - p->by0);
		if (acc > t->close_tol)
			return 0;
		k = next_piece(t, k);
	}
	return 0;
}

struct xorder {
	double x0;
	int i;
};

static int cmp_order(const void *a, const void *b)
{
	const struct xorder *p = a, *q = b;
	return (p->x0 > q->x0) - (p->x0 < q->x0);
}

static int report(const struct xctx *c, int rc, struct px_trim_error *err)
{
	const struct trim_piece *a = &c->t->pc[c->pa], *b = &c->t->pc[c->pb];
	char n1[32], n2[32];

	if (b->loop < a->loop || (b->loop == a->loop && b->curve < a->curve)) {
		const struct trim_piece *x = a;
		a = b, b = x;
	}

	if (rc == X_UNDECIDED) {
		px__trim_err(err, PX_E_NOCONV, PX_TRIM_FAULT_UNDECIDED, a->loop,
			     a->curve, b->loop, b->curve, a->ax, a->ay, 0,
			     "could not decide within the work bound whether "
			     "the loops cross (%s curve %d and %s curve %d "
			     "run very close)",
			     px__trim_loop_name(a->loop, n1, sizeof(n1)),
			     a->curve, px__trim_loop_name(b->loop, n2,
							  sizeof(n2)),
			     b->curve);
		return PX_E_NOCONV;
	}
	if (a->loop == b->loop)
		px__trim_err(err, PX_E_INVAL, PX_TRIM_FAULT_CROSS, a->loop,
			     a->curve, b->loop, b->curve, c->u, c->v, 0,
			     "%s crosses or touches itself: curve %d meets "
			     "curve %d near (%.9g, %.9g)",
			     px__trim_loop_name(a->loop, n1, sizeof(n1)),
			     a->curve, b->curve, c->u, c->v);
	else
		px__trim_err(err, PX_E_INVAL, PX_TRIM_FAULT_CROSS, a->loop,
			     a->curve, b->loop, b->curve, c->u, c->v, 0,
			     "%s curve %d and %s curve %d cross or touch near "
			     "(%.9g, %.9g)",
			     px__trim_loop_name(a->loop, n1, sizeof(n1)),
			     a->curve, px__trim_loop_name(b->loop, n2,
							  sizeof(n2)),
			     b->curve, c->u, c->v);
	return PX_E_INVAL;
}

int px__trim_check_crossings(const struct px_trim *t,
			     struct px_trim_error *err)
{
	struct xctx c;
	struct xorder *ord;
	int a, b, rc = X_NONE, n = t->n_pieces;

	c.t = t;
	/* touching: far below the closure tolerance, above rounding */
	c.tol = fmax(1e-4 * t->close_tol, 4.0 * t->on_tol);
	c.budget = 1L << 22;
	c.pa = c.pb = 0;
	c.u = c.v = 0.0;
	ord = malloc((size_t)n * sizeof(*ord));
	if (!ord) {
		px__trim_err(err, PX_E_NOMEM, PX_TRIM_FAULT_NOMEM, -1, -1, -1,
			     -1, 0, 0, 0, "out of memory");
		return PX_E_NOMEM;
	}
	for (a = 0; a < n && !rc; a++) {
		const struct trim_piece *p = &t->pc[a];
		struct xnode x = {a, {0, 1, p->ax, p->ay, p->ex, p->ey}};
		struct joint j = {p->ax, p->ay, 2.0 * t->close_tol + 2.0 * c.tol};
		int closed = next_piece(t, a) == a;
		ord[a].x0 = p->bx0, ord[a].i = a;
		c.pa = c.pb = a;
		rc = self(&c, &x, &j, closed);
	}
	if (!rc)
		qsort(ord, (size_t)n, sizeof(*ord), cmp_order);
	for (a = 0; a < n && !rc; a++) {
		const struct trim_piece *p = &t->pc[ord[a].i];
		for (b = a + 1; b < n && !rc; b++) {
			const struct trim_piece *q = &t->pc[ord[b].i];
			struct joint jt[2];
			int nj = 0;
			if (q->bx0 > p->bx1 + c.tol)
				break;
			if (q->by0 > p->by1 + c.tol || p->by0 > q->by1 + c.tol)
				continue;
			if (p->loop == q->loop) {
				nj += joint_after(t, ord[a].i, ord[b].i, c.tol,
						  &jt[nj]);
				nj += joint_after(t, ord[b].i, ord[a].i, c.tol,
						  &jt[nj]);
			}
			{
				struct xnode x = {ord[a].i,
						  {0, 1, p->ax, p->ay, p->ex,
						   p->ey}};
				struct xnode y = {ord[b].i,
						  {0, 1, q->ax, q->ay, q->ex,
						   q->ey}};
				c.pa = ord[a].i, c.pb = ord[b].i;
				rc = pair(&c, &x, &y, jt, nj);
			}
		}
	}
	free(ord);
	return rc ? report(&c, rc, err) : PX_OK;
}
