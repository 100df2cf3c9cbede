/*
 * px_nurbs.h - rational B-spline (NURBS) curves and surfaces: validation,
 * evaluation with derivatives, knot insertion, and extraction of
 * sub-curves and sub-patches with guaranteed bounding boxes.
 *
 * This is the geometric kernel under the point-to-NURBS distance core.
 * Degrees run from 1 to PX_NURBS_MAX_DEGREE in each direction; knot
 * vectors may be clamped (end knots of multiplicity degree+1) or
 * unclamped (uniform, periodic or arbitrary). Planar geometry is stored
 * as 3D with z = 0.
 *
 * Representation. Control points are stored homogeneous, four doubles
 * per point: (x*w, y*w, z*w, w) with w > 0 ("pw" arrays). Surface control
 * nets are stored with u varying fastest: the point (i, j), i along u
 * (0..n_u-1) and j along v (0..n_v-1), starts at pw[4 * (j * n_u + i)].
 * This is the order of the Wavefront OBJ "surf" statement.
 *
 * Domain. For a degree-p curve with n control points and knots
 * U[0..n+p], the parameter domain is [U[p], U[n]] (the usual valid
 * range: on it the basis functions sum to one). For clamped knot vectors
 * that is [U[0], U[n+p]]. Evaluation clamps parameters outside the
 * domain to its ends; a parameter at the domain end is evaluated as the
 * limit from inside. At an interior knot, evaluation gives the limit
 * from the right (px_nurbs_curve_eval_side() also gives the left limit,
 * which differs for derivatives at C0 knots).
 *
 * Knot rules (checked by the validate/init/view functions):
 *  - knot count = control points + degree + 1, control points >= degree+1;
 *  - knots finite and non-decreasing;
 *  - no knot value has multiplicity above degree+1;
 *  - a knot value strictly inside the domain has multiplicity at most
 *    degree (so the entity is at least C0 there; a value of multiplicity
 *    degree is a C0 break, which px_nurbs_curve_breaks() reports);
 *  - the domain is non-empty: U[p] < U[n];
 *  - weights finite and > 0, coordinates finite.
 *
 * Memory. A px_nurbs_curve / px_nurbs_surf is a small plain struct that
 * describes arrays living elsewhere; it never owns them. The arrays come
 * either from a px_arena (the *_init and *_extract functions copy into
 * the arena; size them with *_bytes) or from the caller (the *_view
 * functions validate caller arrays in place, and *_extract_work builds a
 * sub-piece inside a caller work buffer sized by the *_WORK_LEN macros).
 * The struct stays valid as long as that memory does.
 *
 * Real-time rules. Evaluation, span search, bounding boxes, extraction
 * into a work buffer and insertion into an arena never touch the heap,
 * never lock, and have loop counts bounded by the entity size; they use
 * fixed stack arrays sized by PX_NURBS_MAX_DEGREE (a few kilobytes). They
 * are marked @note RT-safe. Validation formats its message with
 * snprintf() and is meant for setup. Nothing keeps hidden state: a
 * curve or surface may be evaluated from several threads at once.
 */
#ifndef PX_NURBS_H
#define PX_NURBS_H

#include <stddef.h>

#include "px_arena.h"
#include "px_base.h"
#include "px_math.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Highest supported degree in each direction. */
#define PX_NURBS_MAX_DEGREE 10
/* Highest derivative order of the evaluation functions. */
#define PX_NURBS_MAX_DERIV 3

/* A curve: degree p, n control points, n + p + 1 knots. */
struct px_nurbs_curve {
	int degree;
	int n_ctrl;
	int n_knots;          /* n_ctrl + degree + 1 */
	const double *knots;  /* n_knots values */
	const double *pw;     /* 4 * n_ctrl: x*w, y*w, z*w, w */
	int rational;         /* 0 when every weight is exactly 1 */
};

/* A tensor-product surface; index 0 is u, 1 is v. */
struct px_nurbs_surf {
	int degree[2];
	int n_ctrl[2];        /* n_u, n_v */
	int n_knots[2];       /* n_ctrl[d] + degree[d] + 1 */
	const double *knots[2];
	const double *pw;     /* 4 * n_u * n_v, u fastest */
	int rational;
};

/* What validation found wrong (px_nurbs_error.fault). */
enum px_nurbs_fault {
	PX_NURBS_FAULT_NONE = 0,
	PX_NURBS_FAULT_ARG,         /* NULL pointer or bad argument */
	PX_NURBS_FAULT_DEGREE,      /* degree outside 1..PX_NURBS_MAX_DEGREE */
	PX_NURBS_FAULT_TOO_FEW,     /* fewer than degree+1 control points */
	PX_NURBS_FAULT_KNOT_COUNT,  /* knot count != n_ctrl + degree + 1 */
	PX_NURBS_FAULT_KNOT_NAN,    /* knot not finite */
	PX_NURBS_FAULT_KNOT_ORDER,  /* knot smaller than its predecessor */
	PX_NURBS_FAULT_KNOT_MULT,   /* multiplicity too high (see rules) */
	PX_NURBS_FAULT_DOMAIN,      /* empty parameter domain */
	PX_NURBS_FAULT_COORD_NAN,   /* control point coordinate not finite */
	PX_NURBS_FAULT_WEIGHT,      /* weight not finite or not > 0 */
	PX_NURBS_FAULT_NOSPC,       /* arena too small */
	PX_NURBS_FAULT_COORD_RANGE  /* |coordinate| > PX_NURBS_MAX_COORD, or a
				     * weight outside PX_NURBS_MIN_WEIGHT ..
				     * PX_NURBS_MAX_WEIGHT */
};

/* Largest |control point coordinate| (model units): the curve or surface
 * lies in its control points' hull, so its extent stays finite, and so
 * do the surface searches' 2x2 systems, whose determinants multiply two
 * squared lengths (the fourth power of the extent: surfaces of extent
 * 5e77 to 3e80 answered wrongly). Weights are bounded so that the
 * homogeneous sums (w times a coordinate) and the weight sums cannot
 * overflow or vanish, and one entity's weights may differ by at most
 * PX_NURBS_MAX_WEIGHT_RATIO (beyond about 1e12 the distance search's
 * bounds stop holding). */
#define PX_NURBS_MAX_COORD 1e75
#define PX_NURBS_MIN_WEIGHT 1e-100
#define PX_NURBS_MAX_WEIGHT 1e100
#define PX_NURBS_MAX_WEIGHT_RATIO 1e6

/*
 * Where and why validation failed. code is the px_err returned; dir is
 * 0 (u, or the only direction of a curve) or 1 (v); index is the knot or
 * control point index (for surfaces the control point index is the flat
 * index j*n_u+i, with i/j in index_i/index_j); value and value2 carry
 * the numbers involved (e.g. the knot and its predecessor). msg is a
 * complete sentence such as "knot 7 decreases (0.5 < 0.6)".
 */
struct px_nurbs_error {
	int code;
	enum px_nurbs_fault fault;
	int dir;
	int index;
	int index_i, index_j;
	double value, value2;
	char msg[160];
};

/* ---- sizes ------------------------------------------------------------ */

/* Arena bytes that px_nurbs_curve_init() / _surf_init() take for these
 * counts (knots + homogeneous control points + alignment padding).
 * Returns 0 for counts that are negative or overflow. */
PX_API size_t px_nurbs_curve_bytes(int degree, int n_ctrl);
PX_API size_t px_nurbs_surf_bytes(int degree_u, int degree_v, int n_u,
				  int n_v);

/* Doubles of work buffer that px_nurbs_curve_extract_work() and
 * px_nurbs_curve_sub_aabb() need for an entity with these counts (the
 * result may live in the buffer, so keep it while you use the result). */
#define PX_NURBS_CURVE_WORK_LEN(degree, n_ctrl)                          \
	((size_t)4 * ((size_t)(n_ctrl) + 2 * (size_t)(degree)) +         \
	 (size_t)(n_ctrl) + 3 * (size_t)(degree) + 1)
#define PX_NURBS_SURF_WORK_LEN(degree_u, degree_v, n_u, n_v)             \
	((size_t)4 * ((size_t)(n_u) + 2 * (size_t)(degree_u)) *          \
		 ((size_t)(n_v) + 2 * (size_t)(degree_v)) +               \
	 (size_t)(n_u) + 3 * (size_t)(degree_u) + 1 + (size_t)(n_v) +    \
	 3 * (size_t)(degree_v) + 1)

/* ---- curves: construction --------------------------------------------- */

/*
 * Check curve data without storing it. xyz holds 3 * n_ctrl Cartesian
 * coordinates, w holds n_ctrl weights or is NULL (all 1). err may be
 * NULL; when given it is filled (fault NONE and code PX_OK on success).
 * Returns PX_OK, PX_E_INVAL (NULL, knot count/order/multiplicity,
 * too few points), PX_E_RANGE (degree, weight <= 0 or outside
 * PX_NURBS_MIN_WEIGHT .. PX_NURBS_MAX_WEIGHT, weights further apart than
 * PX_NURBS_MAX_WEIGHT_RATIO, a coordinate beyond +-PX_NURBS_MAX_COORD),
 * PX_E_NAN, PX_E_DEGENERATE (empty domain).
 */
PX_API int px_nurbs_curve_validate(int degree, int n_ctrl,
				   const double *knots, int n_knots,
				   const double *xyz, const double *w,
				   struct px_nurbs_error *err);

/*
 * Validate, then copy knots and control points (converted to homogeneous
 * form) into arena memory (px_nurbs_curve_bytes() bytes) and describe
 * them in *c. On failure *c is zeroed and nothing useful is left in the
 * arena; PX_E_NOSPC when the arena is too small. Setup-time.
 */
PX_API int px_nurbs_curve_init(struct px_nurbs_curve *c, struct px_arena *a,
			       int degree, int n_ctrl, const double *knots,
			       int n_knots, const double *xyz, const double *w,
			       struct px_nurbs_error *err);

/*
 * Validate caller arrays in homogeneous form (pw: 4 * n_ctrl) and make *c
 * a view of them (no copy; the arrays must outlive *c).
 */
PX_API int px_nurbs_curve_view(struct px_nurbs_curve *c, int degree,
			       int n_ctrl, const double *knots, int n_knots,
			       const double *pw, struct px_nurbs_error *err);

/* ---- curves: evaluation (all RT-safe) --------------------------------- */

/* Parameter domain [U[p], U[n]]. @note RT-safe. */
PX_API void px_nurbs_curve_domain(const struct px_nurbs_curve *c,
				  double *u0, double *u1);

/*
 * Knot span index k in [degree, n_ctrl-1] with U[k] <= u < U[k+1], after
 * clamping u to the domain; u at the domain end gives the last non-empty
 * span. side < 0 asks for the left limit instead (U[k] < u <= U[k+1]),
 * except at the domain start. NaN u gives the first span.
 * @note RT-safe.
 */
PX_API int px_nurbs_curve_find_span(const struct px_nurbs_curve *c, double u,
				    int side);

/*
 * Point and derivatives: ders[k] = d^k C / du^k at u for k = 0..nder,
 * nder in 0..PX_NURBS_MAX_DERIV (ders has nder+1 entries). u outside the
 * domain is clamped. Returns PX_OK, PX_E_INVAL (NULL, bad nder) or
 * PX_E_NAN (u not a number; ders untouched). @note RT-safe.
 */
PX_API int px_nurbs_curve_eval(const struct px_nurbs_curve *c, double u,
			       int nder, px_vec3 *ders);

/* As px_nurbs_curve_eval(); side < 0 evaluates the left limit at knots
 * (derivatives differ there at C0 breaks). @note RT-safe. */
PX_API int px_nurbs_curve_eval_side(const struct px_nurbs_curve *c, double u,
				    int side, int nder, px_vec3 *ders);

/* Point only (NaN u gives the domain start). @note RT-safe. */
PX_API px_vec3 px_nurbs_curve_point(const struct px_nurbs_curve *c, double u);

/*
 * Box of the Cartesian control points: contains the whole curve (convex
 * hull property, weights > 0). @note RT-safe.
 */
PX_API px_aabb px_nurbs_curve_aabb(const struct px_nurbs_curve *c);

/* Control point i as Cartesian point and weight (w may be NULL).
 * @note RT-safe. */
PX_API px_vec3 px_nurbs_curve_ctrl(const struct px_nurbs_curve *c, int i,
				   double *w);

/*
 * Seam of the curve: -1 when the end points are farther apart than
 * tol; otherwise the largest k in 0..min(degree-1, PX_NURBS_MAX_DERIV)
 * such that derivatives 1..k at the start and end agree within
 * tol_rel * max(|d_start|, |d_end|, 1e-300) (so 0 is a closed curve with
 * a corner, >= 1 a smooth closed or periodic one). @note RT-safe.
 */
PX_API int px_nurbs_curve_seam(const struct px_nurbs_curve *c, double tol,
			       double tol_rel);

/*
 * Interior knot values (strictly inside the domain) of multiplicity
 * >= degree, i.e. where the curve is only C0 (tangent may jump): writes
 * up to cap values to breaks and returns how many there are (may exceed
 * cap). @note RT-safe.
 */
PX_API int px_nurbs_curve_breaks(const struct px_nurbs_curve *c,
				 double *breaks, int cap);

/* ---- curves: refinement and extraction -------------------------------- */

/*
 * Insert knot u `times` times (Boehm). u must lie in the domain and the
 * resulting multiplicity must stay <= degree (times == 0 copies). The
 * result gets px_nurbs_curve_bytes(degree, n_ctrl + times) bytes from
 * the arena; it describes the same curve. Returns PX_OK, PX_E_INVAL,
 * PX_E_RANGE (u outside the domain, multiplicity too high), PX_E_NAN,
 * PX_E_NOSPC. RT-safe given the arena (no heap).
 * @note RT-safe.
 */
PX_API int px_nurbs_curve_insert_knot(const struct px_nurbs_curve *c,
				      double u, int times, struct px_arena *a,
				      struct px_nurbs_curve *out);

/*
 * Sub-curve on [a, b] (domain0 <= a < b <= domain1), clamped at both
 * ends, equal to the curve there. Built inside work (work_len doubles,
 * at least PX_NURBS_CURVE_WORK_LEN(degree, n_ctrl)); *out points into
 * work. Returns PX_OK, PX_E_INVAL, PX_E_RANGE (a, b outside the domain
 * or a >= b), PX_E_NAN, PX_E_NOSPC (work too small). @note RT-safe.
 */
PX_API int px_nurbs_curve_extract_work(const struct px_nurbs_curve *c,
				       double a, double b, double *work,
				       size_t work_len,
				       struct px_nurbs_curve *out);

/* Arena bytes px_nurbs_curve_extract() may take (result + scratch, the
 * scratch is given back). @note RT-safe. */
PX_API size_t px_nurbs_curve_extract_bytes(const struct px_nurbs_curve *c);

/* As px_nurbs_curve_extract_work(), result copied into arena memory.
 * @note RT-safe. */
PX_API int px_nurbs_curve_extract(const struct px_nurbs_curve *c, double a,
				  double b, struct px_arena *arena,
				  struct px_nurbs_curve *out);

/*
 * Guaranteed box of the curve on [a, b]: the box of the extracted
 * sub-curve's control points (every curve point with a <= u <= b lies in
 * it, by the convex hull property; knot insertion only takes convex
 * combinations). Floating point: evaluated points may stray outside by
 * rounding, a few ulps of the coordinates (the tests allow 1e-13 of the
 * entity's box diagonal); inflate by such a margin where the box is used
 * as an exact bound. work as for px_nurbs_curve_extract_work().
 * @note RT-safe.
 */
PX_API int px_nurbs_curve_sub_aabb(const struct px_nurbs_curve *c, double a,
				   double b, double *work, size_t work_len,
				   px_aabb *box);

/* ---- surfaces --------------------------------------------------------- */

/* Derivatives of a surface point; orders above the requested one are
 * left zero. */
struct px_nurbs_surf_derivs {
	px_vec3 s;                     /* order 0 */
	px_vec3 su, sv;                /* order 1 */
	px_vec3 suu, suv, svv;         /* order 2 */
	px_vec3 suuu, suuv, suvv, svvv; /* order 3 */
};

/*
 * Check surface data: xyz holds 3 * n_u * n_v coordinates (u fastest),
 * w n_u * n_v weights or NULL. Same codes as px_nurbs_curve_validate();
 * err->dir tells the direction of a knot fault.
 */
PX_API int px_nurbs_surf_validate(int degree_u, int degree_v, int n_u,
				  int n_v, const double *knots_u,
				  int n_knots_u, const double *knots_v,
				  int n_knots_v, const double *xyz,
				  const double *w, struct px_nurbs_error *err);

/* Validate and copy into arena memory (px_nurbs_surf_bytes()). */
PX_API int px_nurbs_surf_init(struct px_nurbs_surf *s, struct px_arena *a,
			      int degree_u, int degree_v, int n_u, int n_v,
			      const double *knots_u, int n_knots_u,
			      const double *knots_v, int n_knots_v,
			      const double *xyz, const double *w,
			      struct px_nurbs_error *err);

/* Validate homogeneous caller arrays and view them (no copy). */
PX_API int px_nurbs_surf_view(struct px_nurbs_surf *s, int degree_u,
			      int degree_v, int n_u, int n_v,
			      const double *knots_u, int n_knots_u,
			      const double *knots_v, int n_knots_v,
			      const double *pw, struct px_nurbs_error *err);

/* Domain [u0,u1] x [v0,v1]. @note RT-safe. */
PX_API void px_nurbs_surf_domain(const struct px_nurbs_surf *s, double *u0,
				 double *u1, double *v0, double *v1);

/* Span index in direction dir (0 u, 1 v); as px_nurbs_curve_find_span().
 * @note RT-safe. */
PX_API int px_nurbs_surf_find_span(const struct px_nurbs_surf *s, int dir,
				   double t, int side);

/*
 * Point and all partial derivatives of total order <= order (0..3) at
 * (u, v), clamped to the domain. Returns PX_OK, PX_E_INVAL or PX_E_NAN.
 * @note RT-safe.
 */
PX_API int px_nurbs_surf_eval(const struct px_nurbs_surf *s, double u,
			      double v, int order,
			      struct px_nurbs_surf_derivs *d);

/* As px_nurbs_surf_eval(); side_u / side_v < 0 take left limits.
 * @note RT-safe. */
PX_API int px_nurbs_surf_eval_side(const struct px_nurbs_surf *s, double u,
				   double v, int side_u, int side_v,
				   int order, struct px_nurbs_surf_derivs *d);

/* Point only. @note RT-safe. */
PX_API px_vec3 px_nurbs_surf_point(const struct px_nurbs_surf *s, double u,
				   double v);

/* Box of the Cartesian control points (contains the surface).
 * @note RT-safe. */
PX_API px_aabb px_nurbs_surf_aabb(const struct px_nurbs_surf *s);

/* Control point (i along u, j along v). @note RT-safe. */
PX_API px_vec3 px_nurbs_surf_ctrl(const struct px_nurbs_surf *s, int i, int j,
				  double *w);

/*
 * Iso-parametric curve running along direction dir with the other
 * parameter fixed at t (clamped to its domain): dir 0 gives
 * C(u) = S(u, t), dir 1 gives C(v) = S(t, v) - boundary curves at the
 * domain ends, the "longest iso-curves" of a decomposition inside. The
 * curve views the surface's knot vector of dir and gets its homogeneous
 * control points in pw_out (pw_len >= 4 * n_ctrl[dir] doubles; keep both
 * alive while using *out). Returns PX_OK, PX_E_INVAL, PX_E_NAN,
 * PX_E_NOSPC. @note RT-safe.
 */
PX_API int px_nurbs_surf_iso_curve(const struct px_nurbs_surf *s, int dir,
				   double t, double *pw_out, size_t pw_len,
				   struct px_nurbs_curve *out);

/*
 * Closed in direction dir: 1 when the boundary curves at the two ends of
 * dir coincide within tol. Checked at 2*p+1 parameters per span of the
 * other direction (p its degree), which decides equality of two rational
 * curves of that degree exactly (their cross-multiplied difference is a
 * polynomial of degree 2p per span). @note RT-safe.
 */
PX_API int px_nurbs_surf_closed(const struct px_nurbs_surf *s, int dir,
				double tol);

/*
 * Seam across direction dir, as px_nurbs_curve_seam() for the boundary
 * curves at the two ends of dir: -1 when they are not within tol at the
 * sample parameters of px_nurbs_surf_closed(); otherwise the largest k in
 * 0..min(degree[dir]-1, PX_NURBS_MAX_DERIV) such that the partial
 * derivatives along dir of orders 1..k agree there within tol_rel times
 * the largest magnitude of that order along the seam (so vanishing
 * derivatives at a pole do not count as a break); k >= 1: smooth closed
 * or periodic. The derivative test is made at those samples only.
 * @note RT-safe.
 */
PX_API int px_nurbs_surf_seam(const struct px_nurbs_surf *s, int dir,
			      double tol, double tol_rel);

/*
 * Collapsed boundary (a pole): 1 when every control point of the edge
 * lies within tol of the edge's first control point, so the boundary
 * curve is a single point. edge: 0 u = u0, 1 u = u1, 2 v = v0, 3 v = v1.
 * @note RT-safe.
 */
PX_API int px_nurbs_surf_edge_collapsed(const struct px_nurbs_surf *s,
					int edge, double tol);

/* Interior C0 break values in direction dir, as px_nurbs_curve_breaks().
 * @note RT-safe. */
PX_API int px_nurbs_surf_breaks(const struct px_nurbs_surf *s, int dir,
				double *breaks, int cap);

/* Insert knot t `times` times in direction dir (result from the arena,
 * px_nurbs_surf_bytes() of the new counts). @note RT-safe. */
PX_API int px_nurbs_surf_insert_knot(const struct px_nurbs_surf *s, int dir,
				     double t, int times, struct px_arena *a,
				     struct px_nurbs_surf *out);

/* Sub-patch [u0,u1] x [v0,v1] inside work (at least
 * PX_NURBS_SURF_WORK_LEN(...) doubles); *out points into work.
 * @note RT-safe. */
PX_API int px_nurbs_surf_extract_work(const struct px_nurbs_surf *s,
				      double u0, double u1, double v0,
				      double v1, double *work,
				      size_t work_len,
				      struct px_nurbs_surf *out);

/* Arena bytes px_nurbs_surf_extract() may take. @note RT-safe. */
PX_API size_t px_nurbs_surf_extract_bytes(const struct px_nurbs_surf *s);

/* Sub-patch copied into arena memory. @note RT-safe. */
PX_API int px_nurbs_surf_extract(const struct px_nurbs_surf *s, double u0,
				 double u1, double v0, double v1,
				 struct px_arena *arena,
				 struct px_nurbs_surf *out);

/* Guaranteed box of the surface over [u0,u1] x [v0,v1] (control net of
 * the extracted sub-patch). @note RT-safe. */
PX_API int px_nurbs_surf_sub_aabb(const struct px_nurbs_surf *s, double u0,
				  double u1, double v0, double v1,
				  double *work, size_t work_len, px_aabb *box);

/* ---- basis functions (exposed for tests and for the distance core) ----- */

/*
 * Non-zero basis functions of degree p on span k and their derivatives:
 * ders[r * (p+1) + i] = d^r N_{k-p+i,p}(u) / du^r for r = 0..nder,
 * i = 0..p. knots as in a curve; k from px_nurbs_curve_find_span().
 * @note RT-safe.
 */
PX_API void px_nurbs_basis_ders(const double *knots, int p, int k, double u,
				int nder, double *ders);

#ifdef __cplusplus
}
#endif

#endif
