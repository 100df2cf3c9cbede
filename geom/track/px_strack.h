/*
 * px_strack.h - coherent tracking of the critical distances from a moving
 * point to a model of NURBS surfaces and curves, the surface counterpart
 * of px_track.h (Seong, Johnson and Cohen, lifted formulation, section 4).
 *
 * For every surface the tracker keeps all interior critical points of
 * f(u, v) = |S(u, v) - p|^2 / 2 (minima, maxima, saddles, told apart by
 * the Hessian H = I - l II, i.e. Su.Su + (S - p).Suu etc.):
 *  - Evolution (section 4.2): each point moves by the predictor
 *    d(u, v) = H^-1 (Su . dp, Sv . dp), then Newton on the gradient
 *    ((S - p) . Su, (S - p) . Sv) = 0 with the new point held fixed.
 *  - Transitions (section 4.3): pairs are born or die where p crosses a
 *    focal sheet S + N / k_i (k_i the principal curvatures): there a
 *    critical point is degenerate, E = 0 and det H = 0. Interior points
 *    enter or leave through an open edge (or a crease with less than C2
 *    continuity), where E = 0 on that side. Each Bezier patch is cut into
 *    (u, v) cells, each of those into 2 x 2 region cells, each of those
 *    into 2 x 2 quarters (tried where the region's own proof fails: their
 *    enclosures are about half as wide). At setup every region cell and
 *    quarter gets enclosures of S and its derivatives up to order 2
 *    over the cell (from its Bezier net: convex hull for S, difference
 *    nets for the derivatives; when rational, the derivatives'
 *    numerators over powers of W, bounded by the ratios of their
 *    Bernstein coefficients, met with the interval quotient rule). At
 *    run time these bound E and H over the cell for all points x of a
 *    cube about p, and the cell is proven free of transitions while x
 *    stays in the cube if E1 or E2 keeps its sign (no critical point
 *    there at all) or det H keeps its sign and E is signed on every open
 *    side. The largest such cube has a closed form (E: linear in the
 *    half width; det H: quadratic). No curvature is ever divided by, so
 *    parabolic lines (k = 0, the sheet through infinity) and umbilics give
 *    no NaN. Each cell carries that radius; its expiry on the travelled
 *    path length in the max norm (the sum of the steps' largest
 *    coordinate moves: it bounds the move from where the radius was
 *    taken in the cube's own norm, and is often half the Euclidean path,
 *    so cells fall due less often; the least of all and
 *    of each group of 8 cells kept, so that the usual update compares
 *    one number) names the cells due;
 *    a due cell whose cube still holds the new point with a tenth of
 *    its half width to spare is kept without a test (the path wound
 *    about inside it: about half the tests on the bench's random paths
 *    at 0.1 %), with an expiry of what is left; any other due cell
 *    is tested on the segment
 *    of this update (the cube about its middle) and solved again at the
 *    new point when the proof fails, with the rings of cells about it
 *    that the escape bound names (below). A solve runs Newton from a
 *    seed grid, leaving out the regions and quarters proven free of
 *    critical points and those that hold a tracked one and can hold only
 *    one (every matrix of the Hessian's enclosure regular: E is
 *    one-to-one there); evolved points are kept, duplicates merged.
 *    Where the enclosure makes x - Y E(x) (Y the inverse of its
 *    midpoint) a contraction of a region or quarter (Krawczyk), that box
 *    gets no seeds: the iteration from its centre, each step put back
 *    into the box, converges to its one critical point if it has one,
 *    and a step longer than the contraction allows proves it has none
 *    (stats.exact_solves), so the solve is exact there. A box these
 *    setup certificates leave open (near a focal point the enclosures
 *    over a whole quarter are too wide to contract) is cut in four, each
 *    piece with a certificate made at update time from the values at
 *    its centre and bounds of the third derivatives over the box made
 *    at setup (mean value theorem; the quotient rule where rational):
 *    enclosures about as wide as the piece, so they contract wherever H
 *    is regular. Each piece is done, solved exactly or cut again, down
 *    to two levels;
 *    Newton from its centre only in a piece still open there (within a
 *    sixteenth of a quarter of a near-degenerate point, or where the
 *    work bound leaves no room for a cut; stats.sub_boxes, sub_open).
 *    Cells on a collapsed edge have no proof near the pole's normal
 *    lines and are solved whenever hit.
 *  - Escape bound: a pair born in a hit cell may move on within the step
 *    (fast near a focal sheet), both members out of it. Where the
 *    certificates hold, d(u, v) = H^-1 (Su . dx, Sv . dx) is bounded by
 *    K |dx| (K from the Hessian's enclosure over the step's segment: the
 *    least singular value; 0 where E is proven nonzero); a point ending
 *    outside the k rings of cells about the hit cells crossed each of
 *    their quarter-wide layers, so the step's length is at least the sum
 *    of width / K over them. The rings out to the first k where that sum
 *    passes the step's length are solved (the same enclosures prove most
 *    of their checks); past 3 rings the whole surface (stats.ring_all).
 *  - Index check: after a step that found, lost or merged points, each
 *    surface's index sum (+1 minima and maxima, -1 saddles) must equal
 *    the winding number of E along its domain boundary (degree theory:
 *    births and deaths keep the sum, edge crossings change both). The
 *    winding number is exact where every boundary side keeps E1 or E2 of
 *    one sign (the certificates' side test); a mismatch means a point was
 *    missed (a point followed onto another's branch, or a seed grid that
 *    missed one of a cell's points where no contraction holds): the
 *    update is answered globally and the set re-established
 *    (stats.unbalanced). It cannot see a pair
 *    missed whole (the escape bound's task where pairs are born);
 *    surfaces with a collapsed edge or a C0 line are left out.
 *  - Bounded work: an update whose proven-hit cells exceed max_solves,
 *    or whose due cells exceed max_tests (a long step: their tests then
 *    go on max_tests per update), is answered by the global query; the
 *    tracked set then catches up with the point over the next updates in
 *    budgeted tracked steps (or is rebuilt in slices of cells when that
 *    fails) and is checked against the global answer before it answers
 *    again.
 *  - Collapsed edges (poles): (S - p) . Sv vanishes along such an edge,
 *    a spurious root set that attracts Newton; the tracker solves with
 *    that equation divided by the distance to the edge and leaves the
 *    pole itself to its own candidate.
 *  - Evaluation: each Bezier patch is kept in power form (Horner in both
 *    directions, rational derivatives up to order 2).
 *  - Boundary candidates: the domain edges (not at a closed seam, not
 *    collapsed) are tracked as curves by an internal px_track, with the
 *    corners as their end points; collapsed edges are point candidates.
 *    Free curves of the model go into the same curve tracker. It is left
 *    out of an update while boxes of its curves' half spans prove them
 *    all farther than the best interior minimum, or, where those boxes
 *    reach nearer (beside an edge, or far from the surface), while its
 *    own last answer does: the curves are at least dc - |x - q| from x
 *    when dc was their distance at q, the closest point at most
 *    best + |x - q|, so none is closest within (dc - best) / 2 of q
 *    (stats.curve_cert_skips); it is updated at least every 2 % of the
 *    model size of travel.
 *  - Answer: the smallest of the surface minima and the curve tracker's
 *    answer; jumped when the closest feature is not the continuation of
 *    the last one. (Trimmed surfaces, the B-rep's streams: only minima
 *    inside a face's domain answer, strack_internal.h's
 *    px__strack_create_trimmed().)
 *  - Hot path: after an update answered by a surface minimum, a
 *    certificate from the distance margins of the other minima, the
 *    poles and the curve boxes (all 1-Lipschitz: the margin shrinks at
 *    most twice as fast as the path grows) lets the following updates,
 *    while the due cells are proven free of transitions, follow that
 *    minimum alone (with the curve tracker too when a curve box is not
 *    proven farther; after an update answered by the curve tracker, that
 *    tracker alone); the other points rest and are followed from where
 *    they were at the next full update (stats.hot).
 *  - Fast motion (opts.cold_switch): while following the set costs more
 *    than the global query, or while the set keeps falling behind the
 *    point (catching up over the budget), the global query answers
 *    (PX_TRACK_COLD); the set is re-established when the steps have
 *    shrunk.
 *  - Never silent: verification every verify_every updates against
 *    px_dist_query() on the whole model counts disagreements and
 *    re-initialises; capacity overflow answers globally (counted).
 *
 * Entity indices follow px_dist.h: curves 0..n_curves-1, then surfaces.
 *
 * Memory and real-time rules: px_strack_create() allocates everything
 * (cells, boxes, expiries, critical-point arrays of fixed capacity, the
 * curve tracker and the global-query model; the certificates take about
 * 20 KB a cell, its 4 regions and 16 quarters; a bicubic patch keeps an
 * interleaved copy of its coefficients, 512 bytes, for the AVX2/FMA
 * evaluation where the processor has it). px_strack_update() and the
 * accessors never allocate, lock or print; every loop has a bound. One
 * tracker follows one point; not for concurrent use.
 */
#ifndef PX_STRACK_H
#define PX_STRACK_H

#include <stdint.h>

#include "px_base.h"
#include "px_dist.h"
#include "px_math.h"
#include "px_nurbs.h"
#include "px_track.h"

#ifdef __cplusplus
extern "C" {
#endif

struct px_strack_opts {
	/* work_margin, max_crit (interior points each surface can hold,
	 * default 256), verify_every, dist, cold_switch: px_track.h.
	 * Outside the working volume the update answers globally and the
	 * set waits (max_solves > 0) or re-initialises (max_solves = 0).
	 * Cold switch: the updates go cold when cells are due and solved
	 * in most updates or the set keeps catching up; on the return the
	 * critical points are re-established in budgeted slices as after
	 * an over-budget update (max_solves > 0; at once with 0), the
	 * curve tracker started afresh at the point (with max_solves > 0
	 * in an update of its own, answered globally, before the first
	 * slice: after many cold updates its memory is out of the caches,
	 * and the two together made the return's worst update). */
	PX_TRACK_SHARED(px_track_shared_opts, PX_TRACK_SHARED_OPTS_FIELDS);
	/* Cells per Bezier patch along u and along v (default 3, 1..16).
	 * Spans of rational patches whose weights are more than a factor
	 * 1.5 apart get twice as many (at most 16): their derivative
	 * enclosures, and so the certificates, need the smaller cells
	 * (px_strack_info.n_cells tells the total). */
	int cells_per_span;
	/* Unused since the boxes the certificates leave open are cut
	 * into pieces with certificates of their own instead of seeded on
	 * a grid; still checked (1..8) so that old option sets stay
	 * valid. */
	int seeds;
	/* Unused since the transition regions are proven instead of
	 * sampled; still checked (2..32) so that old option sets stay
	 * valid. */
	int samples;
	/* Bound on the transition work of one update, in cell solves
	 * (default 4; 0: no bound). A solve's work is counted by the seeds
	 * it runs: a cell whose region certificates prove it free of
	 * critical points where it is solved costs those checks alone and
	 * counts 1/8 of a solve (those checks cost a fraction of one
	 * Newton run from a seed; a box's
	 * contraction, stats.exact_solves, counts as one seed, and the
	 * cut of an open box four certificates made at update time, 3/16
	 * of a seed each; a cut is made only where the bound leaves room
	 * for it and a seed in each piece, up to half a full solve a
	 * cell), one whose
	 * certificates leave only some regions or quarters open
	 * (near a focal sheet) 1/8 plus that share of the other 7/8; after
	 * a long step, finding where it met a hit cell's region (up to 8
	 * rounds of certificate radii) 1/8 a round; the escape bound 1/64 a
	 * speed (a ring cell takes 4 to 20, and they spare its solve the
	 * checks' 1/8 where they prove them). A solve is never
	 * started past the bound. An update whose certificates name more
	 * work than this does the bound's worth of it and is answered by
	 * the global query (px_dist_query(), exact) instead; the rest is
	 * done over the following updates (max_solves each, answered
	 * globally too), then one tracked step takes the set from where it
	 * waited to the current point, checked against the global answer
	 * before the tracker answers again. Where the set is re-established
	 * (its critical points overflow max_crit, a check fails, or the
	 * point left the working volume: from its return) it is solved cell
	 * by cell, max_solves / 2 solves (at least 1) per update - mostly
	 * cells proven empty, 8 of them to a solve - each update answered
	 * globally.
	 * Real-time meaning: an update costs at most about max_solves cell
	 * solves plus the following of the live points and max_tests cell
	 * tests, and one global query where it is answered globally (see
	 * stats.over_budget and stats.rebuild_updates). With 0 these cases
	 * re-initialise at once (cost of px_strack_reset()). */
	int max_solves;
	/* Bound on the cell tests of one update (default 32; 0: no bound;
	 * unused with max_solves 0). A test is up to 12 certificate
	 * radii (0.3-0.7 us); a long step or a long lag makes many cells due at
	 * once (every cell of the model after a long enough one). With more
	 * due than this the update is answered by the global query, as over
	 * max_solves, and the due cells are tested max_tests per update, the
	 * set waiting where the step started, before the tracked step is
	 * made (see stats.box_tests and stats.over_budget). */
	int max_tests;
};

PX_API void px_strack_opts_default(struct px_strack_opts *o);

/* Kind of the closest feature (px_strack_result.feature). */
enum px_strack_feature {
	PX_STRACK_MIN = 0,    /* interior minimum of a surface */
	PX_STRACK_EDGE = 1,   /* on a surface edge or corner (u, v set) */
	PX_STRACK_CURVE = 2,  /* on a free curve (u set) */
	PX_STRACK_POLE = 3,   /* a collapsed surface edge */
	PX_STRACK_GLOBAL = 4  /* answered by px_dist_query() */
};

struct px_strack_result {
	double dist;
	px_vec3 point;
	double u, v;
	int entity;        /* px_dist.h numbering */
	int feature;       /* enum px_strack_feature */
	px_vec3 dir;       /* unit, from point to the query (zero on it) */
	int jumped;        /* closest feature changed this update */
	int n_crit;        /* interior surface critical points + the curve
			    * tracker's critical points */
	int n_min, n_max, n_saddle; /* interior surface points by type */
	int source;        /* enum px_track_source */
	int cells_solved;  /* cell solves this update, as max_solves
			    * counts them (a cell proven empty is 1/8, one
			    * partly proven a share more; the sum rounded
			    * up); stats.cell_solves counts
			    * every cell */
	/* interior points that appeared this update (born in pairs at a
	 * focal sheet, or entered through an edge) and that ended (died in
	 * pairs at a focal sheet, left through an edge, or lost by Newton:
	 * their cell is solved again) */
	int born, died;
	int verified;
};
/* On cold answers (source PX_TRACK_COLD) n_crit, n_min, n_max and
 * n_saddle are -1 (nothing followed) and feature is PX_STRACK_GLOBAL;
 * jumped compares with the last answer: an interior minimum followed
 * from there (predictor and Newton) must land on the new one, other
 * features as for PX_TRACK_GLOBAL. */

struct px_strack_stats {
	/* updates, reinits, outside, fallbacks, overflows, verifications,
	 * disagreements, rekeys (due cells not tested again: the point was
	 * still well inside the cube their last test proved, the path had
	 * wound about in it), hot (updates on the hot path: the answering
	 * minimum followed alone), cold, cold_entered, cold_left,
	 * tracked_ns (every mode but cold), cold_ns: px_track.h */
	PX_TRACK_SHARED(px_track_shared_stats, PX_TRACK_SHARED_STATS_FIELDS);
	/* cells solved, cell region tests, points whose Newton failed (died
	 * at a fold or left through an edge; their cell is solved again) */
	uint64_t cell_solves, box_tests, lost;
	uint64_t born;     /* interior points found by cell solves */
	/* boxes of cell solves that hold at most one critical point and
	 * none of the held ones, where x - Y E(x) contracts (Krawczyk): the
	 * point found or proven absent from one start instead of seeds;
	 * exact_open of them undecided (seeded after all); Newton runs
	 * from the seeds of the boxes where no contraction holds */
	uint64_t exact_solves, exact_open, seed_runs;
	/* boxes no certificate made at setup decides are cut in four, down
	 * to two levels, each piece with a certificate of its own made at
	 * update time (enclosures about as wide as the piece): sub_boxes
	 * of those made, sub_open the pieces left undecided (Newton from
	 * their centres: at the last level, or where the work bound had no
	 * room for a cut) */
	uint64_t sub_boxes, sub_open;
	/* rounds spent finding where a long step met a hit cell's region
	 * (two certificate radii each; counted in max_solves as 1/8 of a
	 * solve each) */
	uint64_t cross_rounds;
	/* escape bounds (file comment) that 3 rings of cells about a
	 * step's hit cells did not satisfy: the whole surface was solved */
	uint64_t ring_all;
	/* speeds K worked out for the escape bounds (counted in max_solves
	 * as 1/64 of a solve each) */
	uint64_t ring_speeds;
	/* updates whose transition work exceeded max_solves; updates
	 * answered globally while the set was re-established */
	uint64_t over_budget, rebuild_updates;
	/* updates that left the curve tracker out: every curve and edge
	 * was proven farther than the best interior minimum */
	uint64_t curve_skips;
	/* updates (tracked or on the hot path) that left it out on its own
	 * last answer instead: the curves' distance there, less the way
	 * since, still beyond the best minimum's (where the boxes reach
	 * nearer: beside an edge, or far from the surface) */
	uint64_t curve_cert_skips;
	/* steps after which the index sum of a surface's critical points
	 * differed from the winding number of the gradient along its
	 * boundary (a point missed): answered globally, the set
	 * re-established */
	uint64_t unbalanced;
};

struct px_strack_info {
	int n_surfaces, n_curves, n_patches, n_cells;
	int n_edges;       /* edges tracked as curves */
	int n_poles;       /* collapsed edges */
	int n_unbounded;   /* cells on a collapsed edge: solved whenever
			    * hit (within the work budget, never more
			    * than once a step) */
	px_aabb work;
};

struct px_strack;

/*
 * Prepare a tracker for n_surfs surfaces and n_curves curves (valid
 * NURBS, copied; at least one surface). opts may be NULL. Setup only.
 * Returns PX_OK, PX_E_INVAL, PX_E_RANGE (degree), PX_E_NOMEM or an error
 * of px_dist_model_create() / px_track_create().
 */
PX_API int px_strack_create(const struct px_nurbs_curve *curves, int n_curves,
			    const struct px_nurbs_surf *surfs, int n_surfs,
			    const struct px_strack_opts *opts,
			    struct px_strack **out);

/* NULL is a no-op. */
PX_API void px_strack_free(struct px_strack *t);

/* Rebuild the state at p (every cell solved) and answer. Returns as
 * px_strack_update(). @note RT-safe (bounded; costs more than a global
 * query). */
PX_API int px_strack_reset(struct px_strack *t, px_vec3 p,
			   struct px_strack_result *r);

/* Move the point to p and answer. Returns PX_OK, PX_E_INVAL (NULL) or
 * PX_E_NAN (p not finite; state and r untouched). The answer is exact
 * in every case: from the tracked set (source PX_TRACK_TRACKED or, the
 * first after catching up, PX_TRACK_REINIT) or from px_dist_query()
 * (PX_TRACK_GLOBAL: over the budget, catching up, outside the working
 * volume; PX_TRACK_COLD: fast motion, opts.cold_switch); for global ones, jumped means a change of entity or a foot point
 * that moved far more than the query point. n_crit counts the curve
 * tracker's points as of its last update. @note RT-safe. */
PX_API int px_strack_update(struct px_strack *t, px_vec3 p,
			    struct px_strack_result *r);

/* Interior critical points of surface s (0-based among the surfaces):
 * u[i], v[i], type[i] (+1 min, -1 max, 0 saddle), up to cap. Returns the
 * number held or PX_E_INVAL / PX_E_RANGE. None are held while the
 * answers are cold (source PX_TRACK_COLD); while the set catches up or
 * is re-established (PX_TRACK_GLOBAL) they may be incomplete or lag the
 * point. @note RT-safe. */
PX_API int px_strack_critical(const struct px_strack *t, int s, double *u,
			      double *v, int *type, int cap);

PX_API void px_strack_get_stats(const struct px_strack *t,
				struct px_strack_stats *s);
PX_API void px_strack_get_info(const struct px_strack *t,
			       struct px_strack_info *info);

/* The whole-model global query the tracker verifies and falls back
 * with (owned by it). @note RT-safe. */
PX_API struct px_dist_model *px_strack_dist_model(struct px_strack *t);

#ifdef __cplusplus
}
#endif

#endif
