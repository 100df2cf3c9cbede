/*
 * dist_internal.h - test hooks of the certified surface piece solver
 * (px_spiece.c). Not installed, not part of the API.
 */
#ifndef PX_DIST_INTERNAL_H
#define PX_DIST_INTERNAL_H

#include "math_internal.h"
#include "px_math.h"

/* px_spiece: at most this many slots in a query's pool of parent
 * tensors (-1: as many as fit), so tests can run the restriction from
 * the root and compare. */
PX__TEST_SWITCH(int, px__spiece_pool_cap, -1);
/* px_spiece: 1 leaves the preconditioned monotonicity test out (a
 * rectangle is then split where only it would prove one minimum). */
PX__TEST_SWITCH(int, px__spiece_no_precond, 0);
/* px_spiece: the preconditioned monotonicity test on one rectangle, and
 * the symmetric Jacobian part's least eigenvalue sampled there (see
 * px_spiece.c). */
struct px_spiece;
int px__spiece_precond_probe(const struct px_spiece *sp, px_vec3 p, double s0,
			     double s1, double t0, double t1, int o, int grid,
			     double *mu, double *sampled);

#endif
