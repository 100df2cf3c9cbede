/*
 * nurbs_internal.h - private declarations of the NURBS kernel
 * (px_nurbs_basis.c, px_nurbs_curve.c, px_nurbs_surf.c), shared with the
 * trackers. Not installed, not part of the API.
 */
#ifndef PX_NURBS_INTERNAL_H
#define PX_NURBS_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include "px_nurbs.h"

/* Span k in [p, n-1] for n control points (see px_nurbs_curve_find_span);
 * u must not be NaN. */
int px__nurbs_span(const double *U, int p, int n, double u, int side);

/* Clamp t to [U[p], U[n]]; NaN stays NaN. */
double px__nurbs_clamp(const double *U, int p, int n, double t);

/* Knot vector checks for one direction; fills err (dir given). */
int px__nurbs_check_knots(int p, int n, const double *U, int n_knots,
			  int dir, struct px_nurbs_error *err);
/* Control point checks: xyz (3 per point) + w (or NULL), or pw
 * (homogeneous, 4 per point) when xyz is NULL. n_u > 0 gives i/j. */
int px__nurbs_check_points(int count, int n_u, const double *xyz,
			   const double *w, const double *pw,
			   struct px_nurbs_error *err);
void px__nurbs_err(struct px_nurbs_error *err, int code,
		   enum px_nurbs_fault fault, int dir, int index, double v1,
		   double v2, const char *fmt, ...)
	__attribute__((format(printf, 8, 9)));
void px__nurbs_ok(struct px_nurbs_error *err);
/* The start of the init and view functions: obj (size bytes), when
 * given, is cleared; when null_arg (a NULL argument), PX_E_INVAL with err
 * saying msg, else PX_OK with err untouched. */
int px__nurbs_start(struct px_nurbs_error *err, void *obj, size_t size,
		    int null_arg, const char *msg);

/* Number of knots equal to u (exact) in U[0..n_knots-1]. */
int px__nurbs_mult(const double *U, int n_knots, double u);

/*
 * Insert u once into a grid of homogeneous points along one direction.
 * U has *nk knots (room for one more); the grid has *cnt points along the
 * direction (room for one more) and `other` lines across it; point
 * (a along, b across) is at P + 4 * (a * s_along + b * s_across).
 * u must lie in [U[p], U[*cnt]].
 */
void px__nurbs_insert_once(int p, double *U, int *nk, double *P, int *cnt,
			   int other, size_t s_along, size_t s_across,
			   double u);

/* Number of knots strictly inside (a, b). */
int px__nurbs_count_inside(const double *U, int n_knots, double a, double b);

/* Convert homogeneous to Cartesian and extend a box. */
void px__nurbs_box_add(px_aabb *box, const double *pw);
px_aabb px__nurbs_box_empty(void);

/* Bytes of one arena allocation of n doubles including worst-case
 * alignment padding; 0 on overflow. */
size_t px__nurbs_padded(size_t n_doubles);

/* Homogeneous control points P (4 per point) from xyz (3 per point) and
 * weights w (NULL: all 1). */
void px__nurbs_homogeneous(double *P, const double *xyz, const double *w,
			   size_t count);

/* 1 when every weight of the count homogeneous points pw is exactly 1. */
int px__nurbs_unit_weights(const double *pw, size_t count);

/* Binomial coefficient C(n, k), 0 <= k <= n <= 3: the derivative orders
 * of the quotient rule. Inline: it sits in the evaluation loops. */
static inline double px__nurbs_binom(int n, int k)
{
	static const double b[4][4] = {
		{1, 0, 0, 0}, {1, 1, 0, 0}, {1, 2, 1, 0}, {1, 3, 3, 1}};
	return b[n][k];
}

/*
 * Sub-block extraction shared by curves (nd = 1) and surfaces (nd = 2):
 * p, n, U per direction, pw the homogeneous net (direction 0 fastest),
 * [a[d], b[d]] inside each domain with a < b. Builds the clamped sub-net
 * in work (see PX_NURBS_*_WORK_LEN) and returns its counts in n_out and
 * pointers into work in U_out / *pw_out.
 */
int px__nurbs_extract(int nd, const int *p, const int *n,
		      const double *const *U, const double *pw,
		      const double *a, const double *b, double *work,
		      size_t work_len, int *n_out, double **U_out,
		      double **pw_out);

/* Interior knot values of multiplicity >= p; returns the count. */
int px__nurbs_breaks(const double *U, int p, int n, double *out, int cap);

#endif
