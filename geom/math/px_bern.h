/*
 * px_bern.h - polynomials in Bernstein form on [0, 1].
 *
 * The certified parts of the distance core work on Bernstein
 * coefficients: a polynomial whose coefficients are all positive is
 * positive on the whole interval, the number of sign changes of the
 * coefficients bounds the number of roots (Descartes' rule in Bernstein
 * form), and de Casteljau subdivision refines both. These are the tools
 * that let a query prove that a piece of a curve holds at most one
 * closest-point candidate instead of trusting Newton from a sample.
 *
 * A polynomial of degree n has n + 1 coefficients c[0..n]. Degrees are at
 * most PX_BERN_MAX_DEGREE; every function works in caller memory or fixed
 * stack arrays. Memory and real-time rules: nothing allocates; all
 * functions are RT-safe.
 */
#ifndef PX_BERN_H
#define PX_BERN_H

#include "px_base.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Enough for the distance core's critical-point polynomial of degree
 * 3p - 1 at the highest NURBS degree (10). */
#define PX_BERN_MAX_DEGREE 32

/* Value at t in O(n) (see px_bern_eval_scaled()). @note RT-safe. */
PX_API double px_bern_eval(const double *c, int n, double t);

/* Value and first derivative at t. @note RT-safe. */
PX_API double px_bern_eval_d(const double *c, int n, double t, double *dt);

/* Multiply c_i by C(n, i) (n <= PX_BERN_MAX_DEGREE), for
 * px_bern_eval_scaled(). out may alias c.
 * @note RT-safe. */
PX_API void px_bern_scale(const double *c, int n, double *out);

/* Value at t from binomial-scaled coefficients (px_bern_scale()) in O(n):
 * the fast path for evaluating one polynomial many times.
 * @note RT-safe. */
PX_API double px_bern_eval_scaled(const double *cb, int n, double t);

/*
 * Split at t into the coefficients of the pieces on [0, t] and [t, 1]
 * (each re-parametrized to [0, 1]). left or right may be NULL; either may
 * alias c. @note RT-safe.
 */
PX_API void px_bern_split(const double *c, int n, double t, double *left,
			  double *right);

/* Coefficients of the restriction to [a, b] within [0, 1], a < b.
 * out may alias c. @note RT-safe. */
PX_API void px_bern_restrict(const double *c, int n, double a, double b,
			     double *out);

/* Derivative: degree n - 1, coefficients n (c[i+1] - c[i]). For n = 0 the
 * result is the single coefficient 0. @note RT-safe. */
PX_API void px_bern_deriv(const double *c, int n, double *out);

/*
 * Product of a (degree na) and b (degree nb): degree na + nb.
 * Returns PX_OK or PX_E_RANGE if na + nb > PX_BERN_MAX_DEGREE.
 * out must not alias a or b. @note RT-safe.
 */
PX_API int px_bern_mul(const double *a, int na, const double *b, int nb,
		       double *out);

/* Degree elevation by one: n + 2 coefficients out. out must not alias c.
 * @note RT-safe. */
PX_API void px_bern_elevate(const double *c, int n, double *out);

/*
 * Sign changes in c[0..n], ignoring coefficients with |c| <= zero_tol.
 * Bounds the number of roots in (0, 1) from above (counted with
 * multiplicity), with equal parity. @note RT-safe.
 */
PX_API int px_bern_sign_changes(const double *c, int n, double zero_tol);

/* Binomial coefficient C(n, k) for n <= PX_BERN_MAX_DEGREE, exact in
 * double. @note RT-safe. */
PX_API double px_bern_binom(int n, int k);

#ifdef __cplusplus
}
#endif

#endif
