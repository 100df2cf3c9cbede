/*
 * px_track.h - coherent tracking of every critical distance from a moving
 * point to a set of NURBS curves (planar or space), the real-time path of
 * the distance core.
 *
 * In a 1 kHz loop the query point moves a little each cycle. Newton from
 * last cycle's foot point silently follows the wrong branch when the
 * closest point jumps; re-running the global query every cycle wastes the
 * budget. The tracker keeps ALL critical points of f(s) = |C(s) - p|^2
 * (local minima and maxima, per entity) and detects the moments when
 * pairs of them are born or die, following Chen, Cohen and Riesenfeld,
 * "Tracking point-curve critical distances" (lifted surface g = f'/2 = 0
 * in (p, s) space):
 *
 *  - Evolution (their Eq. 6): each critical point moves by the tangent
 *    predictor ds = (dp . C') / D, D = (C - p) . C'' + |C'|^2, then Newton
 *    on (C - p) . C' = 0 with the new point held fixed, staying inside its
 *    C1 stretch (across knot spans, wrapping at smooth closed seams).
 *    C, C', C'' come from per-span power-basis tables made at setup
 *    (homogeneous for rational spans), so the usual update of a critical
 *    point is the predictor, one evaluation and one Newton step: a step
 *    below 3e-5 of its span is accepted without another evaluation
 *    (quadratic convergence leaves a root error ~1e-9 of the span; the
 *    point is moved by its second-order Taylor expansion).
 *  - Lazy correction (opts.lazy, on by default): a critical point may
 *    skip its correction while two proofs hold. (1) It is still in its
 *    parameter leaf: the leaf had no event (it was not re-solved) and the
 *    values of g at the leaf's two ends - affine in p - kept their signs
 *    (|value| / |p-gradient| at its last correction bounds the travel for
 *    that), and it is alone in that leaf. (2) It cannot be the closest
 *    point: a critical distance is 1-Lipschitz in the query point along
 *    its branch, so a minimum last corrected at distance d is at least
 *    d - L away after a path of length L, and it rests only while that
 *    exceeds the best current answer; maxima never answer. Whenever an
 *    entity has a re-solved leaf or a root changes leaf, all its roots
 *    are corrected first, so the structure checks and transitions always
 *    see current data. px_track_critical() corrects resting roots before
 *    reporting them. An entity whose roots all rested in an update gets
 *    one rest certificate: a travel bound below every leaf certificate of
 *    its roots and below half the margin by which its minima exceed the
 *    best answer (the global distance and each critical distance are
 *    1-Lipschitz, so the margin shrinks at most twice as fast as the
 *    path grows); until the path uses it up or one of its leaves has an
 *    event, an update passes the entity with one comparison
 *    (stats.rested_entities).
 *  - Hot path (opts.lazy): after an update answered by an interior
 *    minimum, when every other entity rests whole and every other root
 *    of the answer's entity rests under its leaf certificate and the
 *    same distance margin (candidates too), one certificate covers them
 *    all; until the path uses it up, a leaf has an event or the answering
 *    root leaves the quick evolution (predictor, one evaluation, one
 *    accepted Newton step inside its leaf), an update is that evolution
 *    and nothing else (stats.hot). When the path uses up a resting
 *    root's leaf certificate, the certificate is taken again at the new
 *    point without correcting the root where the leaf's end values have
 *    the signs they had at its last correction (the step since the
 *    certificate held is straight, the end values linear along it;
 *    stats.renewals).
 *  - Cold switch (opts.cold_switch, on by default): when following every
 *    critical point costs more than the exact global query (fast motion,
 *    events in most updates; one update in 16 is timed), updates are
 *    answered by px_dist_query() until the steps shrink (or a probe finds
 *    tracking cheap again), then the critical points are found afresh.
 *  - Transitions: pairs appear or vanish only where the moving point
 *    crosses the transition set {p : g = 0 and dg/ds = 0} (the evolute of
 *    a planar curve, a ruled surface of polar lines for a space curve) or,
 *    at C0/C1 breaks, cusps and open ends, the normal planes there (the
 *    extended evolute of section 8 is contained in them). Each curve is
 *    cut into Bezier spans and those into parameter leaves; for every leaf
 *    the Bernstein coefficients of w^3 g (affine in p, as in px_cpiece.h)
 *    are precomputed, and the part of a working volume where the leaf can
 *    have an event is covered by octree cells (exclusion with exact
 *    interval bounds of those affine coefficients: a cell where the
 *    coefficients of g, or of dg/ds, keep one sign holds no event). The
 *    event tests are lazy: each leaf keeps a safe radius - how far the
 *    point may travel before the leaf can have an event: its distance
 *    to the box of its event cells, or the radius within which its
 *    coefficients provably keep their signs (each is affine in p, so
 *    |coefficient| / |its p-gradient| bounds it) - and the smallest
 *    expiry (travelled path length at which a radius is used up) names
 *    the updates with due leaves; usually there are none, so an update
 *    costs one comparison plus the evolution (otherwise one scan over
 *    groups of 8 leaves, each with its smallest expiry, finds them). A
 *    due leaf is tested exactly along the segment p_old -> p_new (the
 *    coefficients are affine in the segment parameter, so sign-definite
 *    coefficients at both ends prove there is no event - the exact
 *    counterpart of the paper's line/box-diagonal stage), gets a new
 *    radius at p_new, and is re-solved with a certified
 *    Bernstein/Descartes root isolation at the new point. A region is
 *    grown while a root crosses its outer boundary, so created pairs
 *    that drift away from the
 *    crossing are found too. Creation and annihilation are counted by the
 *    change in the number of roots of the re-solved leaves.
 *  - Candidates: open-curve ends, C0 breaks, cusps and a cornered closed
 *    seam are always candidates for the minimum.
 *  - Never silent: every evolved root is checked (converged, kept its
 *    type); types must alternate inside each C1 stretch and agree with the
 *    sign of f' at the stretch ends; duplicates are caught. Any anomaly
 *    re-initialises that entity by re-solving all its leaves (counted).
 *    A point outside the working volume re-initialises too (counted). A
 *    capacity overflow or an uncertified root isolation answers that
 *    update from the global query px_dist_query() (counted). An optional
 *    verification compares with the global query every N updates and
 *    counts disagreements (each re-initialises and answers globally).
 *
 * Surfaces: px_strack.h (it tracks surface edges and creases with this
 * module).
 *
 * Memory and real-time rules: px_track_create() allocates everything
 * (spans, leaves, coefficient pool, per-entity critical-point
 * arrays of fixed capacity, the global-query model) and may take long.
 * px_track_update() and the accessors never allocate, lock or print, and
 * every loop has a bound. One tracker follows one moving point; it must
 * not be updated from two threads at once.
 */
#ifndef PX_TRACK_H
#define PX_TRACK_H

#include <stdint.h>

#include "px_base.h"
#include "px_dist.h"
#include "px_math.h"
#include "px_nurbs.h"

#ifdef __cplusplus
extern "C" {
#endif

/*
 * What both trackers take and count (px_strack.h too): px_track_opts and
 * px_strack_opts begin with the options of px_track_shared_opts,
 * px_track_stats and px_strack_stats with the counters of
 * px_track_shared_stats. Each is reached by its own name (o.max_crit,
 * s.updates) or all of them together as the member shared (o.shared,
 * s.shared), the same storage.
 *
 * Options:
 *  - work_margin: the working volume is the model bounds grown by this
 *    fraction of the model diagonal on every side (default 1.0); what a
 *    query point outside it does, each tracker says.
 *  - max_crit: critical points each entity (curve or surface) can hold
 *    (default 64 for curves, 256 for surfaces; 2..2^20).
 *  - verify_every: compare with the global query every verify_every
 *    updates (0: off, the default); a disagreement re-initialises and
 *    the update is answered globally.
 *  - dist: options of the global-query model (NULL: its defaults).
 *  - cold_switch (default 1): when the point moves so fast that tracking
 *    costs more than the exact global query (one update in 16 is timed;
 *    tracked mean over 1.5 times the cold query's), updates are answered
 *    by px_dist_query() (source PX_TRACK_COLD) until the mean step has
 *    halved (or as a probe after a while), then the critical points are
 *    found afresh at the point and tracking goes on. Both answers are
 *    exact; this bounds the cost of fast motion by the global query's.
 *    0: always track.
 */
#define PX_TRACK_SHARED_OPTS_FIELDS                                           \
	double work_margin;                                                  \
	int max_crit;                                                        \
	int verify_every;                                                    \
	const struct px_dist_opts *dist;                                     \
	int cold_switch;

struct px_track_shared_opts {
	PX_TRACK_SHARED_OPTS_FIELDS
};

/* Counters (since creation) of both trackers; rekeys counts leaves or
 * cells, hot the updates that followed the answering point alone. */
#define PX_TRACK_SHARED_STATS_FIELDS                                          \
	uint64_t updates;                                                    \
	uint64_t reinits;       /* tracked state re-initialised (anomalies,   \
				 * failed checks) */                         \
	uint64_t outside;       /* updates with a point outside the volume */ \
	uint64_t fallbacks;     /* answered by the global query */           \
	uint64_t overflows;     /* capacity exceeded (answered globally) */   \
	uint64_t verifications;                                              \
	uint64_t disagreements; /* verification found a closer point */      \
	uint64_t rekeys;        /* due leaves or cells kept without their    \
				 * test: the point still well inside the     \
				 * ball or cube their last test proved */    \
	uint64_t hot;           /* updates on the hot path */                \
	uint64_t cold;          /* updates answered cold (cold_switch) */    \
	uint64_t cold_entered, cold_left; /* switches to and from cold */    \
	double tracked_ns, cold_ns; /* the cold switch's running means (ns) \
				     * of a timed tracked update and of the  \
				     * cold query */

struct px_track_shared_stats {
	PX_TRACK_SHARED_STATS_FIELDS
};

/* The first member of the four structs above: the shared part under both
 * its names (C11 anonymous members; two structs of the same members in
 * one union share their storage). */
#define PX_TRACK_SHARED(tag, fields)                                          \
	union {                                                              \
		struct tag shared;                                           \
		struct {                                                     \
			fields                                               \
		};                                                           \
	}

struct px_track_opts {
	/* work_margin, max_crit (default 64), verify_every, dist,
	 * cold_switch: above. A query point outside the working volume
	 * re-initialises. */
	PX_TRACK_SHARED(px_track_shared_opts, PX_TRACK_SHARED_OPTS_FIELDS);
	/* Working volume: the transition boxes are clipped to it. An empty
	 * box (lo > hi, the default) takes the model bounds grown by
	 * work_margin. */
	px_aabb work;
	/* Parameter leaves per Bezier span (default 4, 1..64). */
	int leaves_per_span;
	/* Octree depth of the event cells of a leaf inside the working
	 * volume (default 4, 0..7); their union per leaf bounds its safe
	 * radius. */
	int box_depth;
	/* Lazy correction (default 1): a critical point provably still in
	 * its parameter leaf rests (is not corrected) while it cannot be the
	 * closest point - maxima always, minima while their last distance
	 * minus the path travelled since exceeds the current best. 0
	 * corrects every critical point on every update. */
	int lazy;
};

/* Defaults as documented above. */
PX_API void px_track_opts_default(struct px_track_opts *o);

/* How an update was answered (px_track_result.source). */
enum px_track_source {
	PX_TRACK_TRACKED = 0, /* from the tracked critical points */
	PX_TRACK_REINIT = 1,  /* state rebuilt at this point, then tracked */
	PX_TRACK_GLOBAL = 2,  /* fallback to px_dist_query() */
	PX_TRACK_COLD = 3     /* px_dist_query() while it is the cheaper
			       * exact answer (opts.cold_switch): n_crit and
			       * n_min are -1 (not followed) */
};

/* Kind of the closest feature (px_track_result.feature). */
enum px_track_feature {
	PX_TRACK_MIN = 0,     /* interior local minimum (f' = 0) */
	PX_TRACK_END = 1,     /* end point of an open curve */
	PX_TRACK_BREAK = 2,   /* C0 break, cusp or cornered seam */
	PX_TRACK_FROM_GLOBAL = 3
};

struct px_track_result {
	double dist;       /* distance to the closest point */
	px_vec3 point;     /* closest point */
	double u;          /* its curve parameter */
	int entity;        /* curve index */
	int feature;       /* enum px_track_feature */
	px_vec3 dir;       /* unit vector from point to the query (zero on
			    * the curve) */
	/* 1 when the closest point is not the continuation of last update's
	 * closest point (another entity, another branch, a candidate). */
	int jumped;
	int n_crit;        /* live interior critical points, all entities */
	int n_min;         /* of which minima */
	int source;        /* enum px_track_source */
	int leaves_solved; /* leaves re-solved this update */
	int created;       /* pairs created this update */
	int annihilated;   /* pairs annihilated this update */
	int verified;      /* 1 when compared with the global query */
};

struct px_track_stats {
	/* updates, reinits (entity re-initialisations), outside,
	 * fallbacks, overflows, verifications, disagreements, rekeys (due
	 * leaves kept without the exact segment test), hot (updates
	 * answered under the hot certificate: only the answering root
	 * evolved, opts.lazy), cold, cold_entered, cold_left, tracked_ns,
	 * cold_ns: above */
	PX_TRACK_SHARED(px_track_shared_stats, PX_TRACK_SHARED_STATS_FIELDS);
	uint64_t unresolved;     /* root isolation not certified (fallback) */
	uint64_t leaf_solves;
	uint64_t box_hits;       /* leaves whose safe radius ran out (given
				  * the exact segment test) */
	uint64_t renewals;       /* resting roots' leaf certificates renewed
				  * without correcting them (their leaf's
				  * end values kept their signs) */
	uint64_t creations, annihilations; /* pairs */
	uint64_t rested;         /* critical points left uncorrected in an
				  * update (opts.lazy), summed over updates */
	uint64_t rested_entities; /* entities passed whole under their rest
				   * certificate, summed over updates */
};

struct px_track_info {
	int n_entities, n_spans, n_leaves, n_boxed_leaves;
	int n_cells;             /* octree event cells over all leaves
				  * (setup only: their union box per leaf
				  * bounds its safe radius) */
	int n_cusps, n_breaks;   /* detected cusps, C0/C1 breaks (all) */
	px_aabb work;
	size_t bytes;            /* tracker memory without the global model */
};

struct px_track;

/*
 * Prepare a tracker for n_curves curves (valid NURBS curves, copied).
 * opts may be NULL. Setup only: allocates, may take long.
 * Returns PX_OK, PX_E_INVAL (NULL, no curve, bad options), PX_E_RANGE
 * (degree above PX_NURBS_MAX_DEGREE), PX_E_NOMEM, or an error of
 * px_dist_model_create().
 */
PX_API int px_track_create(const struct px_nurbs_curve *curves, int n_curves,
			   const struct px_track_opts *opts,
			   struct px_track **out);

/* NULL is a no-op. */
PX_API void px_track_free(struct px_track *t);

/*
 * Rebuild the tracked state at p (all critical points by root isolation)
 * and answer for p. The first px_track_update() does this by itself.
 * Returns as px_track_update(). @note RT-safe (bounded, but costs as
 * much as a global query or more).
 */
PX_API int px_track_reset(struct px_track *t, px_vec3 p,
			  struct px_track_result *r);

/*
 * Move the point to p and answer: the closest point of all curves.
 * Returns PX_OK, PX_E_INVAL (NULL) or PX_E_NAN (p not finite; state and
 * r untouched). @note RT-safe.
 */
PX_API int px_track_update(struct px_track *t, px_vec3 p,
			   struct px_track_result *r);

/*
 * The live critical points of an entity, sorted by parameter: u[i] and
 * type[i] (+1 minimum, -1 maximum), up to cap of them. Points resting
 * under opts.lazy are corrected to the current point first (the tracker
 * state changes, the answers do not). Returns the number held (may
 * exceed cap) or PX_E_INVAL / PX_E_RANGE (entity). @note RT-safe.
 */
PX_API int px_track_critical(const struct px_track *t, int entity, double *u,
			     int *type, int cap);

/* Counters since creation. @note RT-safe. */
PX_API void px_track_get_stats(const struct px_track *t,
			       struct px_track_stats *s);

PX_API void px_track_get_info(const struct px_track *t,
			      struct px_track_info *info);

/* The global-query model the tracker verifies and falls back with
 * (owned by the tracker). @note RT-safe. */
PX_API struct px_dist_model *px_track_dist_model(struct px_track *t);

#ifdef __cplusplus
}
#endif

#endif
