/*
 * track_hooks.h - test and bench hooks of the curve and surface
 * trackers (track_*.c, strack_*.c). Not installed, not part of the API.
 * The switches (PX__TEST_SWITCH, math_internal.h) are variables and the
 * hook functions exist only in the test build of these objects
 * (-DPX_TEST_HOOKS), which the tests and benches link.
 */
#ifndef PX_TRACK_HOOKS_H
#define PX_TRACK_HOOKS_H

#include <stdint.h>

#include "math_internal.h"
#include "px_math.h"

/* ---- coherent tracking (track_*.c) ---- */

struct px_track;
/* Test hook: deliberately break the proofs so tests can show they would
 * catch it (bit 0: every root may rest, bit 1: resting minima are never
 * woken, bit 2: every leaf's no-event radius is infinite, bit 3: every
 * leaf-end radius is infinite, bit 4: entity rest certificates never
 * expire, bit 5: they ignore the distance bound of their minima, bit 6:
 * the hot certificate never expires, bit 8: a due leaf keeps its
 * certificate while the point is within twice the ball its last test
 * proved). 0 restores normal operation. */
void px__track_set_fault(struct px_track *t, int fault);
/* Test hook: the cold switch's clock (NULL: CLOCK_MONOTONIC). */
void px__track_set_clock(struct px_track *t, int64_t (*fn)(void *), void *ctx);
struct px_gov;
/* Bench hook: the cold switch (gov_internal.h), whose state a bench
 * copies out and back in (px__gov_copy()) so that a path run again from
 * the same state with the same clock readings takes the same decisions. */
struct px_gov *px__track_gov(struct px_track *t);

/* Test hook: the certificate radius of leaf `leaf` at p (which 0: no
 * event in the leaf while the point travels less; 1: its end values of
 * f' keep their signs; 2: no event, with the piecewise proof of a due
 * leaf: no double root of f' in the leaf, though several simple roots
 * may be; fault 128 makes it 4 times too large), with the leaf's entity, parameter interval and
 * flags (bit 0: an end at a cusp, where g is divided). -1 for a bad
 * leaf index. */
double px__track_leaf_cert(const struct px_track *t, int leaf, px_vec3 p,
			   int which, int *ent, double *u0, double *u1,
			   unsigned *flags);

/* ---- coherent surface tracking (strack_*.c), for its tests ---- */

struct px_strack;

/* Certified radius at p of the region cell of surface s holding (u, v):
 * no transition of that cell while the point stays within this max-norm
 * distance of p. -1 for bad arguments. */
double px__strack_cert_radius(const struct px_strack *t, int s, double u,
			      double v, px_vec3 p);
/* Factor applied to every certified radius (1; the tests raise it to
 * show that their containment check fails for a non-conservative
 * bound). */
PX__TEST_SWITCH(double, px__strack_radius_scale, 1.0);
/* The region cell of surface s holding (u, v): its bounds (u0, u1, v0,
 * v1) in box; returns 1 when its certificates prove it free of critical
 * points for the point p, 0 when not, -1 for bad arguments. */
int px__strack_region(const struct px_strack *t, int s, double u, double v,
		      px_vec3 p, double box[4]);
/* The preconditioned emptiness test of the region certificates: 1 (the
 * default) on, 0 off, 2 with its remainder terms dropped (unsound: a
 * fault the tests must see). */
PX__TEST_SWITCH(int, px__strack_precond, 1);
/* The region cell of surface s holding (u, v), bounds in box as above:
 * bit 0 of the result set when its Hessian enclosure at p proves it
 * holds at most one critical point, bit 1 + k the same for its quarter
 * k (k & 1: upper half in u, k & 2: in v); -1 for bad arguments. */
int px__strack_one(const struct px_strack *t, int s, double u, double v,
		   px_vec3 p, double box[4]);
/* 1 drops the Hessian enclosure's radius from that test (unsound: a
 * fault the tests must see); 0 by default. */
PX__TEST_SWITCH(int, px__strack_one_fault, 0);
/* The contraction solve of the region cell of surface s holding (u, v)
 * (bounds in box as above) and of its quarters at p: out[0] the
 * region's, out[1 + k] quarter k's: -1 where its Hessian enclosure does
 * not make x - Y E(x) a contraction, else 0 a critical point found (at
 * fu, fv), 1 none there (proven), 2 undecided. Returns 0, -1 for bad
 * arguments. */
int px__strack_contract(const struct px_strack *t, int s, double u, double v,
			px_vec3 p, double box[4], int out[5], double fu[5], double fv[5]);
/* 1 drops the Hessian enclosure's radius from the contraction's rate
 * (unsound: a fault the tests must see); 2 leaves every contraction
 * undecided (the solve falls back to seeds); 0 by default. */
PX__TEST_SWITCH(int, px__strack_contract_fault, 0);
/* px_strack: the certificate made at update time for box (u0, u1, v0,
 * v1) of surface s (inside one region cell: taylor_cert() from its
 * quarter's or region's third-derivative bounds) at p, as a solve's cut
 * uses it: 1 proven free
 * of critical points, 0 its one point found by the contraction (into
 * fu, fv), 2 undecided; *regular 1 when its Hessian enclosure is
 * regular (at most one point). -1 for bad arguments or a box across
 * region cells. */
int px__strack_sub(const struct px_strack *t, int s, const double box[4], px_vec3 p,
		   int *regular, double *fu, double *fv);
/* px_strack: 1 shrinks the enclosures of a rational patch's derivatives
 * from their numerators to a third of their width (unsound: a fault the
 * focal test must see); read when certificates are made (create). */
PX__TEST_SWITCH(int, px__strack_rat_fault, 0);
/* px_strack: 1 leaves the pieces out of a region's radius (a rational
 * quarter without a radius of its own then has none). */
PX__TEST_SWITCH(int, px__strack_piece_fault, 0);
PX__TEST_SWITCH(int, px__strack_ct_fault, 0);
/* Test hook: rational spans keep cells_per_span (no finer cells where
 * the weights are far apart), read by px_strack_create(). */
PX__TEST_SWITCH(int, px__strack_coarse, 0);
/* px_strack: 1 leaves every box no certificate decides uncut (Newton
 * from its centre), the solve as it was before the run-time cuts. */
PX__TEST_SWITCH(int, px__strack_sub_fault, 0);
/* The winding number of the gradient of the squared distance from p
 * along the domain boundary of surface s, which the tracker compares
 * with the index sum of its critical points (+1 minima and maxima, -1
 * saddles) after a step that changed them: into *w; returns 1 when
 * known, 0 when the boundary's sign tests fail at p (or the surface has
 * a collapsed edge or a C0 line), -1 for bad arguments. */
int px__strack_winding(const struct px_strack *t, int s, px_vec3 p, int *w);
/* 1 negates that winding number (a fault the tests must see); 0 by
 * default. */
PX__TEST_SWITCH(int, px__strack_wind_fault, 0);
/* Bit 0: a step solves the first ring of cells about each hit cell only,
 * whatever the escape bound says (unsound: its test must see it); bit 1:
 * no solve past where a long step met a hit cell's region. */
PX__TEST_SWITCH(int, px__strack_ring_fault, 0);
/* 1: a due cell keeps its certificate while the point is within twice
 * the cube its last test proved (unsound: the tests must see it). */
PX__TEST_SWITCH(int, px__strack_rekey_fault, 0);
/* 1: surfaces made while it is set take Newton's quick last step
 * (snewton()) up to a thousand times as far, whatever the Hessian and
 * the weights (unsound: the tests must see it). */
PX__TEST_SWITCH(int, px__strack_quick_fault, 0);
/* 1: surface trackers made while it is set evaluate their bicubics
 * with the portable two-lane code, not the AVX2/FMA one (the tests
 * compare the two). */
PX__TEST_SWITCH(int, px__strack_no_fma, 0);
/* Test hook: 1 turns the surface tracker's hot path off, 2 makes its
 * certificate never expire (a fault the tests must see). */
void px__strack_set_hot_fault(struct px_strack *t, int fault);
/* Test hook: 1 makes a tracked step's cell solves drop every minimum
 * they find (the set then misses points), 2 turns the index check off
 * as well (faults the tests must see). */
void px__strack_set_drop_fault(struct px_strack *t, int fault);
/* Test hook: the cold switch's clock (NULL: CLOCK_MONOTONIC). */
void px__strack_set_clock(struct px_strack *t, int64_t (*fn)(void *), void *ctx);
/* Bench hook: as px__track_gov(). */
struct px_gov *px__strack_gov(struct px_strack *t);

#endif
