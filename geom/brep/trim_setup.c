/*
 * trim_setup.c - building a trimmed domain (px_trim.h): Bezier pieces of
 * the loops, joints closed to one stored point, pieces halved to the
 * grid's cell size, the checks, orientation, and the grid.
 */
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "brep_internal.h"
#include "px_bern.h"

/* Halvings of one Bezier piece towards the cell size (a piece may then
 * still span a few cells; the bound keeps setup finite for pieces with
 * a far control point). */
#define SPLIT_DEPTH 12

void px_trim_opts_default(struct px_trim_opts *o)
{
	if (!o)
		return;
	o->close_tol_rel = 1e-6;
	o->on_tol_rel = 1e-13;
	o->grid = 0;
}

void px__trim_err(struct px_trim_error *err, int code,
		  enum px_trim_fault fault, int loop, int curve, int loop2,
		  int curve2, double u, double v, double value,
		  const char *fmt, ...)
{
	va_list ap;

	if (!err)
		return;
	err->code = code;
	err->fault = fault;
	err->loop = loop, err->curve = curve;
	err->loop2 = loop2, err->curve2 = curve2;
	err->u = u, err->v = v, err->value = value;
	va_start(ap, fmt);
	vsnprintf(err->msg, sizeof(err->msg), fmt, ap);
	va_end(ap);
}

const char *px__trim_loop_name(int k, char *buf, size_t len)
{
	if (k == 0)
		snprintf(buf, len, "outer loop");
	else
		snprintf(buf, len, "hole %d", k);
	return buf;
}

/* Setup scratch: pieces and their coefficients, grown as needed. */
struct build {
	struct trim_piece *pc;
	int n, cap;
	double *coef;
	size_t nc, ccap;
};

static int build_add(struct build *b, const struct trim_piece *p,
		     const double *X, const double *Y, const double *W)
{
	size_t k = (size_t)p->deg + 1;
	if (b->n == b->cap) {
		int cap = b->cap ? 2 * b->cap : 64;
		void *q = realloc(b->pc, (size_t)cap * sizeof(*b->pc));
		if (!q)
			return PX_E_NOMEM;
		b->pc = q, b->cap = cap;
	}
	if (b->nc + 3 * k > b->ccap) {
		size_t cap = b->ccap ? 2 * b->ccap : 1024;
		void *q;
		while (cap < b->nc + 3 * k)
			cap *= 2;
		q = realloc(b->coef, cap * sizeof(double));
		if (!q)
			return PX_E_NOMEM;
		b->coef = q, b->ccap = cap;
	}
	b->pc[b->n] = *p;
	b->pc[b->n].off = (int)b->nc;
	memcpy(b->coef + b->nc, X, k * sizeof(double));
	memcpy(b->coef + b->nc + k, Y, k * sizeof(double));
	memcpy(b->coef + b->nc + 2 * k, W, k * sizeof(double));
	b->nc += 3 * k;
	b->n++;
	return PX_OK;
}

static void build_free(struct build *b)
{
	free(b->pc);
	free(b->coef);
}

/* The Bezier pieces of one curve, in the loop's running direction. */
static int add_curve(struct build *b, const struct px_nurbs_curve *c,
		     int reversed, int loop, int curve)
{
	size_t len = PX_NURBS_CURVE_WORK_LEN(c->degree, c->n_ctrl);
	double *work = malloc(len * sizeof(double));
	double X[PX_NURBS_MAX_DEGREE + 1], Y[PX_NURBS_MAX_DEGREE + 1];
	double W[PX_NURBS_MAX_DEGREE + 1];
	int p = c->degree, k, first = b->n, rc = PX_OK, i, j;

	if (!work)
		return PX_E_NOMEM;
	for (k = p; k < c->n_ctrl && rc == PX_OK; k++) {
		struct px_nurbs_curve bz;
		struct trim_piece pc;
		if (!(c->knots[k] < c->knots[k + 1]))
			continue;
		rc = px_nurbs_curve_extract_work(c, c->knots[k], c->knots[k + 1],
						 work, len, &bz);
		if (rc == PX_OK && bz.n_ctrl != p + 1)
			rc = PX_E_STATE;
		if (rc != PX_OK)
			break;
		for (i = 0; i <= p; i++) {
			j = reversed ? p - i : i;
			X[j] = bz.pw[4 * i], Y[j] = bz.pw[4 * i + 1];
			W[j] = bz.pw[4 * i + 3];
		}
		memset(&pc, 0, sizeof(pc));
		pc.deg = p, pc.loop = loop, pc.curve = curve;
		pc.t0 = reversed ? c->knots[k + 1] : c->knots[k];
		pc.t1 = reversed ? c->knots[k] : c->knots[k + 1];
		pc.ax = X[0] / W[0], pc.ay = Y[0] / W[0];
		pc.ex = X[p] / W[p], pc.ey = Y[p] / W[p];
		rc = build_add(b, &pc, X, Y, W);
	}
	free(work);
	if (rc == PX_OK && reversed) {
		/* reverse the order of this curve's pieces */
		for (i = first, j = b->n - 1; i < j; i++, j--) {
			struct trim_piece tmp = b->pc[i];
			b->pc[i] = b->pc[j], b->pc[j] = tmp;
		}
	}
	return rc;
}

/* Box of a piece's control points and stored end points, widened. */
static void piece_box(struct trim_piece *p, const double *coef, double sl)
{
	const double *X = coef + p->off;
	const double *Y = X + p->deg + 1, *W = Y + p->deg + 1;
	int i;
	p->bx0 = fmin(p->ax, p->ex), p->bx1 = fmax(p->ax, p->ex);
	p->by0 = fmin(p->ay, p->ey), p->by1 = fmax(p->ay, p->ey);
	for (i = 0; i <= p->deg; i++) {
		double x = X[i] / W[i], y = Y[i] / W[i];
		p->bx0 = fmin(p->bx0, x), p->bx1 = fmax(p->bx1, x);
		p->by0 = fmin(p->by0, y), p->by1 = fmax(p->by1, y);
	}
	p->bx0 -= sl, p->bx1 += sl, p->by0 -= sl, p->by1 += sl;
}

/* Halve piece p (coefficients in c) until its box fits a cell. */
static int split_to(struct build *out, const struct trim_piece *p,
		    const double *c, double cw, double ch, double sl,
		    int depth)
{
	double L[3][PX_NURBS_MAX_DEGREE + 1], R[3][PX_NURBS_MAX_DEGREE + 1];
	struct trim_piece q = *p, l, r;
	size_t k = (size_t)p->deg + 1;
	int d, rc;

	q.off = 0;
	piece_box(&q, c, sl);
	if ((q.bx1 - q.bx0 - 2.0 * sl <= cw && q.by1 - q.by0 - 2.0 * sl <= ch) ||
	    depth >= SPLIT_DEPTH)
		return build_add(out, &q, c, c + k, c + 2 * k);
	for (d = 0; d < 3; d++)
		px_bern_split(c + d * k, p->deg, 0.5, L[d], R[d]);
	l = q, r = q;
	/* the split point is one value for both halves */
	l.ex = r.ax = L[0][p->deg] / L[2][p->deg];
	l.ey = r.ay = L[1][p->deg] / L[2][p->deg];
	l.t1 = r.t0 = 0.5 * (q.t0 + q.t1);
	{
		double cl[3 * (PX_NURBS_MAX_DEGREE + 1)];
		double cr[3 * (PX_NURBS_MAX_DEGREE + 1)];
		for (d = 0; d < 3; d++) {
			memcpy(cl + d * k, L[d], k * sizeof(double));
			memcpy(cr + d * k, R[d], k * sizeof(double));
		}
		rc = split_to(out, &l, cl, cw, ch, sl, depth + 1);
		if (rc == PX_OK)
			rc = split_to(out, &r, cr, cw, ch, sl, depth + 1);
	}
	return rc;
}

/* Validate the curves and find the box of all control points. */
static int check_curves(const struct px_trim_loop *loops, int n_loops,
			struct px_trim_error *err, double box[4])
{
	char nm[32];
	int k, i, j;

	box[0] = box[2] = INFINITY, box[1] = box[3] = -INFINITY;
	for (k = 0; k < n_loops; k++) {
		if (!loops[k].curves || loops[k].n_curves < 1) {
			px__trim_err(err, PX_E_INVAL, PX_TRIM_FAULT_ARG, k, -1,
				     -1, -1, 0, 0, 0, "%s has no curves",
				     px__trim_loop_name(k, nm, sizeof(nm)));
			return PX_E_INVAL;
		}
		for (i = 0; i < loops[k].n_curves; i++) {
			const struct px_nurbs_curve *c = &loops[k].curves[i];
			struct px_nurbs_curve view;
			struct px_nurbs_error ne;
			int rc = px_nurbs_curve_view(&view, c->degree, c->n_ctrl,
						     c->knots, c->n_knots,
						     c->pw, &ne);
			if (rc != PX_OK) {
				if (err)
					err->nurbs = ne;
				px__trim_err(err, rc, PX_TRIM_FAULT_CURVE, k, i,
					     -1, -1, 0, 0, 0, "%s curve %d: %s",
					     px__trim_loop_name(k, nm,
								sizeof(nm)),
					     i, ne.msg);
				return rc;
			}
			for (j = 0; j < c->n_ctrl; j++) {
				double w = c->pw[4 * j + 3];
				double x = c->pw[4 * j] / w;
				double y = c->pw[4 * j + 1] / w;
				box[0] = fmin(box[0], x), box[1] = fmax(box[1], x);
				box[2] = fmin(box[2], y), box[3] = fmax(box[3], y);
			}
		}
	}
	if (!isfinite(box[1] - box[0]) || !isfinite(box[3] - box[2]) ||
	    !(hypot(box[1] - box[0], box[3] - box[2]) > 0.0)) {
		px__trim_err(err, PX_E_DEGENERATE, PX_TRIM_FAULT_EMPTY, -1, -1,
			     -1, -1, box[0], box[2], 0,
			     "the loops have no extent: every control point "
			     "is at (%.17g, %.17g)", box[0], box[2]);
		return PX_E_DEGENERATE;
	}
	return PX_OK;
}

/*
 * The Bezier pieces of every loop into b, loop_first[] marking where
 * each loop starts; gaps between consecutive curves checked against the
 * closure tolerance, then each piece's start set to its predecessor's
 * end (one value per joint).
 */
static int collect(const struct px_trim_loop *loops, int n_loops,
		   double close_tol, struct build *b, int *loop_first,
		   struct px_trim_error *err)
{
	char nm[32];
	int k, i, rc;

	for (k = 0; k < n_loops; k++) {
		int first = b->n, last;
		loop_first[k] = first;
		for (i = 0; i < loops[k].n_curves; i++) {
			int rev = loops[k].reversed && loops[k].reversed[i];
			rc = add_curve(b, &loops[k].curves[i], rev, k, i);
			if (rc != PX_OK) {
				px__trim_err(err, rc, rc == PX_E_NOMEM ?
					     PX_TRIM_FAULT_NOMEM :
					     PX_TRIM_FAULT_CURVE, k, i, -1, -1,
					     0, 0, 0, "%s curve %d: %s",
					     px__trim_loop_name(k, nm,
								sizeof(nm)),
					     i, px_strerror(rc));
				return rc;
			}
		}
		last = b->n - 1;
		for (i = first; i <= last; i++) {
			struct trim_piece *p = &b->pc[i];
			struct trim_piece *q = &b->pc[i == last ? first : i + 1];
			double gap = hypot(q->ax - p->ex, q->ay - p->ey);
			if (!(gap <= close_tol)) {
				px__trim_err(err, PX_E_INVAL, PX_TRIM_FAULT_OPEN,
					     k, p->curve, k, q->curve, p->ex,
					     p->ey, gap,
					     "%s is open: curve %d ends at "
					     "(%.9g, %.9g), %.3g from the start "
					     "(%.9g, %.9g) of curve %d (closure "
					     "tolerance %.3g)",
					     px__trim_loop_name(k, nm, sizeof(nm)),
					     p->curve, p->ex, p->ey, gap, q->ax,
					     q->ay, q->curve, close_tol);
				return PX_E_INVAL;
			}
			/* the start of q moves to the end of p, and so does
			 * its first control point: the curve runs through the
			 * stored point (within rounding) */
			q->ax = p->ex, q->ay = p->ey;
			{
				double *X = b->coef + q->off;
				double *Y = X + q->deg + 1, *W = Y + q->deg + 1;
				X[0] = q->ax * W[0], Y[0] = q->ay * W[0];
			}
		}
	}
	loop_first[n_loops] = b->n;
	return PX_OK;
}

/* Reverse loop k in place: piece order, coefficients, end points. */
static void reverse_loop(struct px_trim *t, int k)
{
	int i, j, d;
	for (i = t->loop_first[k], j = t->loop_first[k + 1] - 1; i < j;
	     i++, j--) {
		struct trim_piece tmp = t->pc[i];
		t->pc[i] = t->pc[j], t->pc[j] = tmp;
	}
	for (i = t->loop_first[k]; i < t->loop_first[k + 1]; i++) {
		struct trim_piece *p = &t->pc[i];
		double x;
		for (d = 0; d < 3; d++) {
			double *c = t->coef + p->off + d * (p->deg + 1);
			int a = 0, e = p->deg;
			for (; a < e; a++, e--)
				x = c[a], c[a] = c[e], c[e] = x;
		}
		x = p->ax, p->ax = p->ex, p->ex = x;
		x = p->ay, p->ay = p->ey, p->ey = x;
		x = p->t0, p->t0 = p->t1, p->t1 = x;
	}
	t->area[k] = -t->area[k];
	t->reversed[k] = 1;
}

/* Holes inside the outer loop, no hole inside another. */
static int check_nesting(const struct px_trim *t, struct px_trim_error *err)
{
	char n1[32], n2[32];
	int k, j, on = 0, pi;
	double s;

	for (k = 1; k < t->n_loops; k++) {
		const struct trim_piece *p = &t->pc[t->loop_first[k]];
		if (px__trim_winding_range(t, 0, 1, p->ax, p->ay, &on, &pi,
					   &s) == 0 && !on) {
			px__trim_err(err, PX_E_INVAL, PX_TRIM_FAULT_NESTING, k,
				     -1, 0, -1, p->ax, p->ay, 0,
				     "%s lies outside the outer loop (its "
				     "point (%.9g, %.9g) is outside)",
				     px__trim_loop_name(k, n1, sizeof(n1)),
				     p->ax, p->ay);
			return PX_E_INVAL;
		}
		for (j = 1; j < t->n_loops; j++) {
			if (j == k || px__trim_winding_range(t, j, j + 1, p->ax,
							     p->ay, &on, &pi,
							     &s) == 0)
				continue;
			px__trim_err(err, PX_E_INVAL, PX_TRIM_FAULT_NESTING, k,
				     -1, j, -1, p->ax, p->ay, 0,
				     "%s lies inside %s (its point (%.9g, "
				     "%.9g) is enclosed)",
				     px__trim_loop_name(k, n1, sizeof(n1)),
				     px__trim_loop_name(j, n2, sizeof(n2)),
				     p->ax, p->ay);
			return PX_E_INVAL;
		}
	}
	return PX_OK;
}

/* Cell lists (each piece in every cell its box meets) and the winding
 * of the cells without pieces, from right to left along each row, so
 * the walk from a cell finds the windings further right ready. */
static void fill_grid(struct px_trim *t)
{
	int g = t->g, i, r, c;

	/* cell_start[c] runs to the end of cell c, then shifts back */
	for (i = 0; i < t->n_pieces; i++) {
		const struct trim_piece *p = &t->pc[i];
		int r1 = trim_row(t, p->by1), c1 = trim_col(t, p->bx1);
		for (r = p->row0; r <= r1; r++)
			for (c = p->col0; c <= c1; c++)
				t->cell_item[t->cell_start[r * g + c]++] = i;
	}
	for (i = g * g; i > 0; i--)
		t->cell_start[i] = t->cell_start[i - 1];
	t->cell_start[0] = 0;
	for (r = 0; r < g; r++)
		for (c = g - 1; c >= 0; c--) {
			int cell = r * g + c, on = 0, pi;
			double s, x, y;
			if (t->cell_start[cell] != t->cell_start[cell + 1])
				continue;
			x = t->gx0 + (c + 0.5) / t->ginv_x;
			y = t->gy0 + (r + 0.5) / t->ginv_y;
			t->cell_wind[cell] = (signed char)px__trim_walk(
				t, r, c + 1, x, y, &on, &pi, &s);
		}
}

/* Arena layout from the collected pieces; counts the cell entries. */
static int make_domain(const struct px_trim *tmp, const struct build *b,
		       const int *loop_first, struct px_trim **out)
{
	struct px_arena a;
	struct px_trim *t;
	size_t bytes, items = 0, cells = (size_t)tmp->g * tmp->g;
	int i, n_loops = tmp->n_loops;

	for (i = 0; i < b->n; i++) {
		const struct trim_piece *p = &b->pc[i];
		items += (size_t)(trim_row(tmp, p->by1) - trim_row(tmp, p->by0) + 1) *
			 (size_t)(trim_col(tmp, p->bx1) - trim_col(tmp, p->bx0) + 1);
	}
	bytes = sizeof(*t) + (size_t)(n_loops + 1) * sizeof(int) +
		(size_t)n_loops * (1 + sizeof(double)) +
		(size_t)b->n * sizeof(struct trim_piece) +
		b->nc * sizeof(double) + (cells + 1 + items) * sizeof(int) +
		cells + 9 * PX_ARENA_ALIGN;
	if (items > (size_t)1 << 30 || px_arena_init_alloc(&a, bytes) != PX_OK)
		return PX_E_NOMEM;
	t = px_arena_alloc(&a, sizeof(*t), 0);
	*t = *tmp;
	t->loop_first = px_arena_calloc(&a, (size_t)n_loops + 1, sizeof(int), 0);
	t->reversed = px_arena_calloc(&a, (size_t)n_loops, 1, 0);
	t->area = px_arena_calloc(&a, (size_t)n_loops, sizeof(double), 0);
	t->pc = px_arena_calloc(&a, (size_t)b->n, sizeof(*t->pc), 0);
	t->coef = px_arena_calloc(&a, b->nc, sizeof(double), 0);
	t->cell_start = px_arena_calloc(&a, cells + 1, sizeof(int), 0);
	t->cell_item = px_arena_calloc(&a, items ? items : 1, sizeof(int), 0);
	t->cell_wind = px_arena_calloc(&a, cells, 1, 0);
	if (!t->cell_wind) {
		px_arena_fini(&a);
		return PX_E_NOMEM;
	}
	memcpy(t->loop_first, loop_first, (size_t)(n_loops + 1) * sizeof(int));
	memcpy(t->pc, b->pc, (size_t)b->n * sizeof(*t->pc));
	memcpy(t->coef, b->coef, b->nc * sizeof(double));
	t->n_pieces = b->n;
	for (i = 0; i < b->n; i++) {
		struct trim_piece *p = &t->pc[i];
		int r, c, r1 = trim_row(t, p->by1), c1 = trim_col(t, p->bx1);
		p->row0 = trim_row(t, p->by0), p->col0 = trim_col(t, p->bx0);
		for (r = p->row0; r <= r1; r++)
			for (c = p->col0; c <= c1; c++)
				t->cell_start[r * t->g + c + 1]++;
	}
	for (i = 0; i < (int)cells; i++)
		t->cell_start[i + 1] += t->cell_start[i];
	t->arena = a;
	*out = t;
	return PX_OK;
}

/* Largest weight ratio of the pieces (scales the rounding slack). */
static double weight_ratio(const struct build *b)
{
	double r = 1.0;
	int i, j;
	for (i = 0; i < b->n; i++) {
		const struct trim_piece *p = &b->pc[i];
		const double *W = b->coef + p->off + 2 * (p->deg + 1);
		double lo = W[0], hi = W[0];
		for (j = 1; j <= p->deg; j++)
			lo = fmin(lo, W[j]), hi = fmax(hi, W[j]);
		r = fmax(r, hi / lo);
	}
	return r;
}

/* The checks, orientation and grid of a laid-out domain. */
static int finish(struct px_trim *t, struct px_trim_error *err)
{
	char nm[32];
	int k, rc;

	for (k = 0; k < t->n_loops; k++) {
		double a = px__trim_loop_area(t, k), x0 = INFINITY, x1 = -INFINITY;
		double y0 = INFINITY, y1 = -INFINITY, lim;
		int i;
		for (i = t->loop_first[k]; i < t->loop_first[k + 1]; i++) {
			x0 = fmin(x0, t->pc[i].bx0), x1 = fmax(x1, t->pc[i].bx1);
			y0 = fmin(y0, t->pc[i].by0), y1 = fmax(y1, t->pc[i].by1);
		}
		/* thinner than the closure tolerance: no area */
		lim = t->close_tol * hypot(x1 - x0, y1 - y0);
		t->area[k] = a;
		if (!(fabs(a) > lim)) {
			px__trim_err(err, PX_E_DEGENERATE, PX_TRIM_FAULT_AREA, k,
				     -1, -1, -1, 0.5 * (x0 + x1),
				     0.5 * (y0 + y1), a,
				     "%s encloses zero area (signed area %.3g, "
				     "at most %.3g counts as none)",
				     px__trim_loop_name(k, nm, sizeof(nm)), a,
				     lim);
			return PX_E_DEGENERATE;
		}
	}
	rc = px__trim_check_crossings(t, err);
	if (rc != PX_OK)
		return rc;
	for (k = 0; k < t->n_loops; k++)
		if ((k == 0) != (t->area[k] > 0.0))
			reverse_loop(t, k);
	rc = check_nesting(t, err);
	if (rc != PX_OK)
		return rc;
	fill_grid(t);
	return PX_OK;
}

int px_trim_create(const struct px_trim_loop *loops, int n_loops,
		   const struct px_trim_opts *opts, struct px_trim_error *err,
		   struct px_trim **out)
{
	struct px_trim_opts o;
	struct px_trim tmp;
	struct build raw = {0}, fine = {0};
	int *loop_first = NULL, rc, k, i, n_bez;
	double box[4], D, M, cw, ch, pad;

	if (err) {
		memset(err, 0, sizeof(*err));
		err->loop = err->curve = err->loop2 = err->curve2 = -1;
	}
	if (out)
		*out = NULL;
	px_trim_opts_default(&o);
	if (opts)
		o = *opts;
	if (!loops || n_loops < 1 || !out || !(o.close_tol_rel > 0.0) ||
	    !(o.close_tol_rel <= 0.1) || !(o.on_tol_rel >= 0.0) ||
	    !(o.on_tol_rel <= o.close_tol_rel) || o.grid < 0 ||
	    o.grid > PX_TRIM_MAX_GRID) {
		px__trim_err(err, PX_E_INVAL, PX_TRIM_FAULT_ARG, -1, -1, -1, -1,
			     0, 0, 0,
			     "bad arguments (need loops, n_loops >= 1, out; "
			     "0 < close_tol_rel <= 0.1, 0 <= on_tol_rel <= "
			     "close_tol_rel, grid 0..%d)", PX_TRIM_MAX_GRID);
		return PX_E_INVAL;
	}
	rc = check_curves(loops, n_loops, err, box);
	if (rc != PX_OK)
		return rc;
	D = hypot(box[1] - box[0], box[3] - box[2]);
	M = fmax(fmax(fabs(box[0]), fabs(box[1])),
		 fmax(fmax(fabs(box[2]), fabs(box[3])), D));
	memset(&tmp, 0, sizeof(tmp));
	tmp.n_loops = n_loops;
	tmp.bx0 = box[0], tmp.bx1 = box[1], tmp.by0 = box[2], tmp.by1 = box[3];
	tmp.close_tol = o.close_tol_rel * D;
	loop_first = malloc((size_t)(n_loops + 1) * sizeof(int));
	if (!loop_first) {
		rc = PX_E_NOMEM;
		px__trim_err(err, rc, PX_TRIM_FAULT_NOMEM, -1, -1, -1, -1, 0, 0,
			     0, "out of memory");
		goto done;
	}
	rc = collect(loops, n_loops, tmp.close_tol, &raw, loop_first, err);
	if (rc != PX_OK)
		goto done;
	/* Rounding of a de Casteljau step on homogeneous coordinates,
	 * divided by the smallest weight, with room to spare. */
	tmp.slack = 64.0 * DBL_EPSILON * M * weight_ratio(&raw);
	tmp.on_tol = fmax(o.on_tol_rel * D, 4.0 * tmp.slack);
	n_bez = raw.n;
	tmp.g = o.grid ? o.grid : (int)ceil(4.0 * sqrt((double)n_bez));
	tmp.g = tmp.g < 16 && !o.grid ? 16 : tmp.g;
	tmp.g = tmp.g > PX_TRIM_MAX_GRID ? PX_TRIM_MAX_GRID : tmp.g;
	pad = 2.0 * tmp.slack;
	cw = (box[1] - box[0] + 2.0 * pad) / tmp.g;
	ch = (box[3] - box[2] + 2.0 * pad) / tmp.g;
	tmp.gx0 = box[0] - pad, tmp.gy0 = box[2] - pad;
	tmp.ginv_x = 1.0 / cw, tmp.ginv_y = 1.0 / ch;
	for (k = 0; k < n_loops && rc == PX_OK; k++) {
		int f0 = loop_first[k];
		loop_first[k] = fine.n;
		for (i = f0; i < (k + 1 < n_loops ? loop_first[k + 1] : raw.n) &&
			     rc == PX_OK; i++)
			rc = split_to(&fine, &raw.pc[i], raw.coef + raw.pc[i].off,
				      cw, ch, tmp.slack, 0);
	}
	loop_first[n_loops] = fine.n;
	if (rc == PX_OK)
		rc = fine.n > 0 ? make_domain(&tmp, &fine, loop_first, out)
				: PX_E_DEGENERATE;
	if (rc != PX_OK) {
		px__trim_err(err, rc, rc == PX_E_NOMEM ? PX_TRIM_FAULT_NOMEM :
			     PX_TRIM_FAULT_EMPTY, -1, -1, -1, -1, 0, 0, 0,
			     "setting up the pieces failed: %s",
			     px_strerror(rc));
		goto done;
	}
	rc = finish(*out, err);
	if (rc != PX_OK) {
		px_trim_free(*out);
		*out = NULL;
	}
done:
	free(loop_first);
	build_free(&raw);
	build_free(&fine);
	return rc;
}

void px_trim_free(struct px_trim *t)
{
	struct px_arena a;
	if (!t)
		return;
	a = t->arena;
	px_arena_fini(&a);
}
