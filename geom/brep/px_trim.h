/*
 * px_trim.h - trimmed parameter domains: the in-domain test of a trimmed
 * NURBS face.
 *
 * A face of a B-rep solid is a NURBS surface restricted to a region of
 * its (u, v) parameter plane: one outer loop and any number of holes,
 * each loop a closed chain of planar NURBS curves in (u, v) (stored as
 * 3D with z = 0, px_nurbs.h; z is ignored). The distance core asks two
 * things of that region while a query runs: is this (u, v) inside
 * (px_trim_contains()), and does this parameter box lie wholly inside,
 * wholly outside, or across a loop (px_trim_classify_box(), to prune
 * or keep a surface piece whole).
 *
 * Setup (px_trim_create()) splits every curve into its Bezier pieces,
 * and those further until each is small against a uniform grid over
 * the domain; each piece keeps its homogeneous control polygon, its end
 * points and its box. Neighbouring pieces share their end point as one
 * stored value (joints between curves closed within the closure
 * tolerance are moved to one point), which is what makes the crossing
 * count exact. Setup refuses, saying which loop and curve and where:
 * invalid curves, open loops (gap above the closure tolerance), loops
 * that enclose no area, loops that cross or touch themselves or each
 * other (within the closure tolerance; box-pruned pairwise tests with
 * subdivision), holes outside the outer loop and holes inside other
 * holes. An outer loop given clockwise or a hole given counter-clockwise
 * is reversed (px_trim_loop_reversed() says which), so the winding
 * number is 1 inside the domain and 0 outside.
 *
 * Queries. The winding number at (u, v) counts the signed crossings of
 * the ray towards +u with the pieces. A piece whose box the ray misses
 * counts nothing; one the ray passes wholly counts from its end points
 * alone; otherwise the line v = const is cut with the hull of the
 * control polygon and, when (u, v) falls inside that cut, the piece is
 * halved (de Casteljau on the original piece) until the halves decide
 * or are smaller than the boundary tolerance. The grid holds per cell
 * the pieces whose box meets it, and for cells that no piece meets,
 * their winding number: a query walks its row from its own cell to the
 * first such cell. Answers are exact: "inside" and "outside" are the
 * winding number of the stored loops (the curves, joined within the
 * closure tolerance), up to rounding of a few units in the last place
 * of the coordinates; "boundary" means (u, v) lies within the boundary
 * tolerance of a loop (plus that rounding), or, for a parametrisation so
 * uneven that PX_TRIM_MAX_DEPTH halvings do not decide, near it.
 *
 * Memory and real-time rules: px_trim_create() allocates (one arena
 * block plus setup scratch); px_trim_contains(), px_trim_classify_box()
 * and the accessors never touch the heap, run in loops bounded by the
 * piece count, the grid size and PX_TRIM_MAX_DEPTH /
 * PX_TRIM_BOX_BUDGET, use about 4 KB of stack, keep no state and may
 * be called from several threads at once. They are marked
 * @note RT-safe.
 */
#ifndef PX_TRIM_H
#define PX_TRIM_H

#include "px_base.h"
#include "px_nurbs.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Halvings of one piece a point query may make before it calls the
 * point "boundary". */
#define PX_TRIM_MAX_DEPTH 60
/* Sub-pieces one box classification may examine before it answers
 * "crossed" (the conservative answer). */
#define PX_TRIM_BOX_BUDGET 512
/* Largest grid (cells per side). */
#define PX_TRIM_MAX_GRID 256

/* One loop: curves in chain order, each starting where the previous
 * ends (the last ends where the first starts). reversed[i] != 0 runs
 * curve i from its domain end to its start; NULL runs all forwards.
 * The curves' arrays are read during setup only. */
struct px_trim_loop {
	const struct px_nurbs_curve *curves;
	int n_curves;
	const unsigned char *reversed;
};

/* Tolerances relative to the diagonal D of the box of all control
 * points. close_tol_rel: largest gap between consecutive curves of a
 * loop, and the distance under which two loops (or two parts of one)
 * count as touching; default 1e-6. on_tol_rel: distance from a loop
 * within which a point may be answered "boundary"; default 1e-13
 * (never below a few units in the last place of the coordinates).
 * grid: cells per side, 0 picks one from the piece count (at most
 * PX_TRIM_MAX_GRID). */
struct px_trim_opts {
	double close_tol_rel;
	double on_tol_rel;
	int grid;
};

/* Defaults above. */
PX_API void px_trim_opts_default(struct px_trim_opts *o);

/* What setup found wrong (px_trim_error.fault). */
enum px_trim_fault {
	PX_TRIM_FAULT_NONE = 0,
	PX_TRIM_FAULT_ARG,       /* NULL, no loop, a loop without curves, bad option */
	PX_TRIM_FAULT_CURVE,     /* a curve fails px_nurbs_curve_view() (nurbs has it) */
	PX_TRIM_FAULT_EMPTY,     /* all control points at one place, or not finite */
	PX_TRIM_FAULT_OPEN,      /* gap between consecutive curves above the tolerance */
	PX_TRIM_FAULT_AREA,      /* a loop encloses no area */
	PX_TRIM_FAULT_CROSS,     /* loops (or one loop with itself) cross or touch */
	PX_TRIM_FAULT_NESTING,   /* a hole outside the outer loop or inside a hole */
	PX_TRIM_FAULT_UNDECIDED, /* the crossing test ran out of its work bound */
	PX_TRIM_FAULT_NOMEM
};

/*
 * Where and why setup failed. code is the px_err returned; loop/curve
 * (loop 0 is the outer loop, 1.. the holes) name the first culprit and
 * loop2/curve2 the second one of a crossing (else -1); (u, v) is where
 * (the gap's end, the crossing, a point of the misplaced hole); value
 * the number involved (gap, area). msg is a complete sentence, e.g.
 * "hole 1 curve 0 and hole 2 curve 1 cross near (0.5, 0.25)".
 */
struct px_trim_error {
	int code;
	enum px_trim_fault fault;
	int loop, curve, loop2, curve2;
	double u, v, value;
	struct px_nurbs_error nurbs;
	char msg[224];
};

struct px_trim;

/*
 * Build a trimmed domain from loops[0] (outer) and loops[1..n_loops-1]
 * (holes). opts NULL: defaults. err may be NULL. Returns PX_OK,
 * PX_E_INVAL (arguments, open loop, crossing, nesting), PX_E_RANGE,
 * PX_E_NAN (a curve, forwarded from the kernel's validation),
 * PX_E_DEGENERATE (no extent, zero area), PX_E_NOCONV (crossing test
 * undecided), PX_E_NOMEM. Setup only.
 */
PX_API int px_trim_create(const struct px_trim_loop *loops, int n_loops,
			  const struct px_trim_opts *opts,
			  struct px_trim_error *err, struct px_trim **out);

/* Release a domain (NULL is fine). */
PX_API void px_trim_free(struct px_trim *t);

enum px_trim_where {
	PX_TRIM_OUTSIDE = 0,
	PX_TRIM_INSIDE = 1,
	PX_TRIM_BOUNDARY = 2
};

/* Details of a point query. winding: winding number (1 inside, 0
 * outside; undefined on the boundary, where it is 0). For "boundary":
 * loop, curve and the curve parameter t near the point (the edge to
 * take as candidate), else -1, -1, 0. */
struct px_trim_hit {
	int where;
	int winding;
	int loop, curve;
	double t;
};

/*
 * Classify (u, v): returns PX_TRIM_OUTSIDE, PX_TRIM_INSIDE or
 * PX_TRIM_BOUNDARY (see the contract above); hit may be NULL. Returns
 * PX_E_INVAL (NULL t) or PX_E_NAN (u or v not finite). @note RT-safe.
 */
PX_API int px_trim_contains(const struct px_trim *t, double u, double v,
			    struct px_trim_hit *hit);

enum px_trim_box_class {
	PX_TRIM_BOX_OUTSIDE = 0,
	PX_TRIM_BOX_INSIDE = 1,
	PX_TRIM_BOX_CROSSED = 2
};

/*
 * Classify the box [u0, u1] x [v0, v1] (u0 <= u1, v0 <= v1): wholly
 * outside the domain, wholly inside (no loop meets the box, within
 * rounding), or crossed. Conservative: "crossed" whenever a loop comes
 * within the boundary tolerance of the box or PX_TRIM_BOX_BUDGET
 * sub-pieces do not decide; "inside" and "outside" are never wrong.
 * Returns one of enum px_trim_box_class, PX_E_INVAL (NULL, u0 > u1 or
 * v0 > v1) or PX_E_NAN. @note RT-safe.
 */
PX_API int px_trim_classify_box(const struct px_trim *t, double u0, double u1,
				double v0, double v1);

/* Accessors (0 / -1 for NULL or an index out of range). @note RT-safe. */
PX_API int px_trim_loop_count(const struct px_trim *t);
PX_API int px_trim_piece_count(const struct px_trim *t);
PX_API int px_trim_grid_size(const struct px_trim *t);
/* 1 when setup reversed loop k to orient it (outer counter-clockwise,
 * holes clockwise), 0 when it was given so, -1 for a bad index. */
PX_API int px_trim_loop_reversed(const struct px_trim *t, int k);
/* Signed area of loop k after orientation (outer > 0, holes < 0). */
PX_API double px_trim_loop_area(const struct px_trim *t, int k);
/* Box of all control points (u0, u1, v0, v1). */
PX_API void px_trim_bounds(const struct px_trim *t, double *u0, double *u1,
			   double *v0, double *v1);
/* Absolute closure and boundary tolerances in use. */
PX_API void px_trim_tolerances(const struct px_trim *t, double *close_tol,
			       double *on_tol);

#ifdef __cplusplus
}
#endif

#endif
