/*
 * brep_internal.h - private layout of the trimmed domain (px_trim.h),
 * shared by its setup (trim_setup.c, trim_check.c) and its queries
 * (trim_query.c). Not installed, not part of the API.
 */
#ifndef PX_BREP_INTERNAL_H
#define PX_BREP_INTERNAL_H

#include "px_arena.h"
#include "px_trim.h"

/* One Bezier piece of a loop. The homogeneous coefficients (x*w, y*w,
 * w) of its deg + 1 control points sit at coef[off ..], three runs of
 * deg + 1. The end points (ax, ay) and (ex, ey) are the values every
 * crossing count uses: the end of one piece is bit for bit the start of
 * the next. The box holds the control points and both end points and is
 * widened by the domain's rounding slack. */
struct trim_piece {
	double bx0, bx1, by0, by1;
	double ax, ay, ex, ey;
	double t0, t1;  /* curve parameters of the ends (t0 > t1: reversed) */
	int deg, off;
	int loop, curve;
	int col0, row0; /* first grid cell the box meets */
};

/* A node of the subdivision of a piece: its parameter range in [0, 1]
 * and end points. */
struct trim_node {
	double a, b;
	double ax, ay, ex, ey;
};

struct px_trim {
	struct px_arena arena;   /* owns everything below */
	int n_loops;
	int *loop_first;         /* pieces of loop k: loop_first[k] .. [k+1]-1 */
	unsigned char *reversed; /* per loop */
	double *area;            /* per loop, after orientation */
	int n_pieces;
	struct trim_piece *pc;
	double *coef;
	/* grid over [gx0, gx0 + g / ginv_x] x [gy0, ...] */
	int g;
	double gx0, gy0, ginv_x, ginv_y;
	int *cell_start;         /* g * g + 1 */
	int *cell_item;          /* piece indices */
	signed char *cell_wind;  /* winding of cells without pieces */
	double bx0, bx1, by0, by1; /* box of all control points */
	double slack;            /* rounding margin of boxes and cuts */
	double on_tol, close_tol;
};

/* Smaller / larger of two numbers that are not NaN (the queries' hot
 * loops: libm's fmin/fmax are calls). */
static inline double trim_min(double a, double b)
{
	return a < b ? a : b;
}

static inline double trim_max(double a, double b)
{
	return a > b ? a : b;
}

/* Grid column / row of a coordinate: monotone in x, clamped to the grid
 * (setup and queries must use these same functions). */
static inline int trim_cell(double x, double x0, double inv, int g)
{
	double c = (x - x0) * inv;
	if (!(c >= 0.0))
		return 0;
	if (c >= (double)(g - 1))
		return g - 1;
	return (int)c;
}

static inline int trim_col(const struct px_trim *t, double x)
{
	return trim_cell(x, t->gx0, t->ginv_x, t->g);
}

static inline int trim_row(const struct px_trim *t, double y)
{
	return trim_cell(y, t->gy0, t->ginv_y, t->g);
}

/* Cartesian point of piece p at s in [0, 1] (de Casteljau on the
 * homogeneous coefficients: the one function every split point comes
 * from, so both halves see the same value). */
void px__trim_point(const struct px_trim *t, const struct trim_piece *p,
		    double s, double *x, double *y);

/* Cartesian control points of node n of piece p (deg + 1 each), their
 * weights when w is not NULL, and their box with the node's end points,
 * unwidened. */
void px__trim_node_ctrl(const struct px_trim *t, const struct trim_piece *p,
			const struct trim_node *n, double *x, double *y,
			double *w, double box[4]);

/* Winding number of (u, v) over the pieces of loops lo..hi-1 without the
 * grid; *on set when the point is on one of them (then *pi is the piece
 * and *s its parameter). */
int px__trim_winding_range(const struct px_trim *t, int lo, int hi,
			   double u, double v, int *on, int *pi, double *s);

/* Signed crossings of the ray from (u, v) towards +u with piece p: the
 * count, with *on set (and *s the piece parameter) when (u, v) is
 * within the boundary tolerance. */
int px__trim_piece_cross(const struct px_trim *t, const struct trim_piece *p,
			 double u, double v, int *on, double *s);

/* Winding number of (u, v) from the grid: the pieces of row r in cells
 * c.. up to the first cell without pieces, plus that cell's winding.
 * *on, *pi, *s as for px__trim_winding_range(). */
int px__trim_walk(const struct px_trim *t, int r, int c, double u, double v,
		  int *on, int *pi, double *s);

/* Setup checks (trim_check.c): signed area of loop k, and the crossing
 * test over all pieces; both fill err on refusal. */
double px__trim_loop_area(const struct px_trim *t, int k);
int px__trim_check_crossings(const struct px_trim *t,
			     struct px_trim_error *err);

/* Error reporting shared by setup files. */
void px__trim_err(struct px_trim_error *err, int code,
		  enum px_trim_fault fault, int loop, int curve, int loop2,
		  int curve2, double u, double v, double value,
		  const char *fmt, ...) __attribute__((format(printf, 11, 12)));
/* "outer loop" / "hole k" */
const char *px__trim_loop_name(int k, char *buf, size_t len);

#endif
