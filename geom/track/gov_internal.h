/*
 * gov_internal.h - what the two trackers (track_*.c, strack_*.c) share:
 * the cost governor, and the setup, counters and verification of their
 * shared options and stats (px_track_shared_opts and
 * px_track_shared_stats in px_track.h; at the end of this header).
 *
 * The governor: when the query point moves so fast that
 * following every critical point costs more than the exact global query
 * (events in most updates, leaves or cells re-solved every cycle), the
 * tracker answers with that query instead ("cold" updates) and comes back
 * to tracking, with a fresh set of critical points, once the steps have
 * shrunk. Both ways are exact; only the cost differs.
 *
 * What is measured: one update in PX_GOV_EVERY is timed (two reads of
 * CLOCK_MONOTONIC, about 40 ns on the machines measured, so about 3 ns an
 * update on average), tracked or cold, except while deciding (below), and
 * each kind keeps a running mean of its samples (the last 32 samples, 512
 * updates, weigh about two thirds: events come in bursts, and a burst
 * alone should not send the tracker cold). A sample is first clipped to
 * PX_GOV_CLIP times the other kind's mean, so that one interrupt or
 * preemption (tens of microseconds on a shared machine) moves a mean by
 * a bounded amount. The
 * cold mean starts from a calibration made at setup. After a (re)start
 * (setup, reset, the return from cold, a probe) the first PX_GOV_WARM
 * updates are not timed (the set and its certificates are being rebuilt)
 * and then every tracked update is, until the decision's samples are in;
 * the decision is made on their plain mean. A point that moves fast thus
 * costs 48 expensive tracked updates before going cold, not 512 (each is
 * up to several global queries; on a path whose speed swings, every
 * swing pays it). Switching:
 *  - to cold when the tracked mean has at least PX_GOV_MIN_SAMPLES samples
 *    since the last (re)start and exceeds PX_GOV_ENTER times the cold
 *    mean;
 *  - back to tracking when at least PX_GOV_MIN_COLD updates ran cold and
 *    the running mean step length is below PX_GOV_LEAVE times what it was
 *    when the tracker went cold (the tracked cost grows with the step, so
 *    a step that has shrunk that much is where tracking paid before;
 *    halved again, down to 1/16, each time tracking goes cold within
 *    PX_GOV_BACK updates of such a return: a speed that swings by a
 *    factor two is no reason to re-initialise every swing), or
 *    as a probe after PX_GOV_PROBE cold updates, doubled each time a probe
 *    goes cold again (up to PX_GOV_PROBE_MAX): the cost of tracking also
 *    depends on where the point moves, not on its speed alone. A probe
 *    decides again after PX_GOV_PROBE_SAMPLES samples.
 * The return costs one re-initialisation (every leaf or cell solved at
 * the new point); the thresholds keep a steady speed from switching
 * back and forth.
 *
 * A tracker with a work budget also says, each tracked update, whether
 * the update fell behind: its set could not follow the point within the
 * budget, so the update paid the budget's work and the global query on
 * top (px__gov_behind()). That is known without a clock, and it is the
 * cost the clock's means hide: the updates of a catch-up are each several
 * global queries, few enough not to move a mean and many enough to set
 * the tail. The tracker goes cold at once when a catch-up runs longer
 * than PX_GOV_BEHIND_RUN updates (the point outruns the budget), or when
 * one starts within PX_GOV_BEHIND_GAP tracked updates of the last one
 * (catch-ups are not rare on this path); the first after a (re)start
 * (the catch-up of a return's rebuild) is not held against the second.
 * After a return the set was rebuilt where the point was when the
 * rebuild began, so its catch-up covers the whole path since: one that
 * is not done in PX_GOV_BEHIND_RETURN updates will not be (the point
 * moves on as fast), and the return goes cold again then.
 *
 * Memory and real-time rules: a plain struct inside the tracker, no
 * allocation; every call is O(1) and lock-free. Tests replace the clock
 * (px__gov_set_clock) to make the switching deterministic.
 */
#ifndef PX_GOV_INTERNAL_H
#define PX_GOV_INTERNAL_H

#include <math.h>
#include <stdint.h>

#include "px_dist.h"
#include "px_math.h"
#include "px_track.h"

#define PX_GOV_EVERY 16        /* one update timed in this many */
#define PX_GOV_CLIP 4.0        /* a sample is at most this times the other mean */
#define PX_GOV_ENTER 1.5       /* tracked mean over cold mean to go cold */
#define PX_GOV_LEAVE 0.5       /* step shrink factor to come back */
#define PX_GOV_MIN_SAMPLES 32  /* timed tracked updates before going cold */
#define PX_GOV_PROBE_SAMPLES 8 /* the same after a probe */
#define PX_GOV_MIN_COLD 64     /* cold updates before coming back */
#define PX_GOV_PROBE 1024      /* cold updates before a probe */
#define PX_GOV_PROBE_MAX 16384
#define PX_GOV_BACK 2048
#define PX_GOV_WARM 16         /* untimed updates after a (re)start */
#define PX_GOV_BEHIND_RUN 4    /* updates of one catch-up before going cold */
#define PX_GOV_BEHIND_GAP 1024 /* tracked updates between catch-ups, at least */
#define PX_GOV_BEHIND_RETURN 1 /* the same as PX_GOV_BEHIND_RUN after a return */

/* The clock: nanoseconds, monotonic. ctx is the tests' own. */
typedef int64_t (*px_gov_clock_fn)(void *ctx);

struct px_gov {
	int on;           /* 0: always tracked */
	int cold;         /* 1 while the global query answers */
	uint32_t tick;    /* updates since the last timed one */
	int n_trk;        /* tracked samples since the last (re)start */
	uint32_t n_cold;  /* cold updates since going cold */
	uint32_t probe;   /* cold updates before the next probe */
	uint32_t n_back;  /* updates since the last return by step */
	double leave;     /* step factor of the next return by step */
	int probing;      /* tracking again as a probe */
	int skip;         /* updates left before timing (just restarted) */
	double trk_ns, cold_ns;   /* running means */
	double step, step_enter;  /* running mean step length; at going cold */
	uint64_t entered, left;   /* switches, for the stats */
	uint32_t behind_gap;      /* tracked updates since a catch-up began */
	int behind_run;           /* updates of the current catch-up */
	int returning;            /* back from cold, not yet on track */
	px_gov_clock_fn clock;
	void *clock_ctx;
};

/* Start with a cold-query cost (ns) measured at setup; on: 0 or 1. */
void px__gov_init(struct px_gov *g, int on, double cold_ns);

/* Tracking (re)starts: tracked samples are gathered afresh. */
void px__gov_restart(struct px_gov *g);

/* Tracked samples the next decision is made on. */
static inline int px__gov_need(const struct px_gov *g)
{
	return g->probing ? PX_GOV_PROBE_SAMPLES : PX_GOV_MIN_SAMPLES;
}

/* Whether this update is one to time (advances the tick). Inline: every
 * update calls it. */
static inline int px__gov_timed(struct px_gov *g)
{
	if (!g->on)
		return 0;
	if (!g->cold && g->n_trk < px__gov_need(g)) {
		/* deciding: every update once the first PX_GOV_WARM after
		 * a (re)start are past (they rebuild the set and its
		 * certificates) */
		if (g->skip > 0) {
			g->skip--;
			return 0;
		}
		return 1;
	}
	if (++g->tick < PX_GOV_EVERY)
		return 0;
	g->tick = 0;
	return 1;
}

/* The clock now (ns). */
int64_t px__gov_now(const struct px_gov *g);

/* A cold update's answer: px_dist_query() on m at p, timed as a cold
 * sample when this update is one to time, counted in st (updates, cold)
 * when answered. Returns as px_dist_query(). */
int px__gov_cold_query(struct px_gov *g, struct px_track_shared_stats *st,
		       struct px_dist_model *m, px_vec3 p,
		       struct px_dist_result *out);

/* Every update's step length (the running mean the return looks at:
 * the last 16 steps weigh about two thirds). Inline: every update calls
 * it. */
static inline void px__gov_step(struct px_gov *g, double len)
{
	if (!(len >= 0.0) || len > 1e300)
		return;
	g->step += 0.0625 * (len - g->step);
	if (!g->cold && g->n_back < UINT32_MAX)
		g->n_back++;
}

/* A timed tracked update took ns: returns 1 when the tracker should go
 * cold from the next update on (g->cold is then set). */
int px__gov_tracked(struct px_gov *g, double ns);

/* Around a tracked update: px__gov_start() returns the clock when this
 * update is one to time, else PX_GOV_UNTIMED; px__gov_stop() hands the
 * sample to px__gov_tracked() and returns 1 when the tracker goes cold
 * from the next update on. Inline: every update calls them. */
#define PX_GOV_UNTIMED INT64_MIN
static inline int64_t px__gov_start(struct px_gov *g)
{
	return px__gov_timed(g) ? px__gov_now(g) : PX_GOV_UNTIMED;
}

static inline int px__gov_stop(struct px_gov *g, int64_t t0)
{
	return t0 != PX_GOV_UNTIMED &&
	       px__gov_tracked(g, (double)(px__gov_now(g) - t0));
}

/* A tracked update fell behind (the catch-up's rule above): returns 1
 * when the tracker should go cold from the next update on (g->cold is
 * then set). */
int px__gov_fell_behind(struct px_gov *g);

/* After every tracked update (while the governor is on): behind 1 when
 * the update fell behind (answered globally, its set short of the point
 * after the budget's work), 0 when it was on track, -1 when neither (the
 * set being rebuilt, or waiting for the point to come back). Returns as
 * px__gov_fell_behind(). Inline: every update calls it. */
static inline int px__gov_behind(struct px_gov *g, int behind)
{
	if (!g->on || g->cold || behind < 0)
		return 0;
	if (behind)
		return px__gov_fell_behind(g);
	g->behind_run = 0;
	g->returning = 0;
	if (g->behind_gap < UINT32_MAX)
		g->behind_gap++;
	return 0;
}

/* In cold mode, once per update: returns 1 when this update should go
 * back to tracking (g->cold is then cleared). */
int px__gov_leave(struct px_gov *g);

/* What an update does, as px__gov_begin() decides. */
#define PX_GOV_TRACK 0  /* track */
#define PX_GOV_COLD 1   /* answer with px__gov_cold_query(); where it has
			 * no answer, px__gov_restart() and do as below */
#define PX_GOV_RETURN 2 /* track again, the critical points found afresh
			 * (stats.cold_left) */

/* The governor at the start of an update whose step was len (unused
 * while it is off). Inline: every update calls it. */
static inline int px__gov_begin(struct px_gov *g, double len)
{
	if (!g->on)
		return PX_GOV_TRACK;
	px__gov_step(g, len);
	if (!g->cold)
		return PX_GOV_TRACK;
	return px__gov_leave(g) ? PX_GOV_RETURN : PX_GOV_COLD;
}

/* A reset (px_*_reset()): the governor starts tracking afresh, counted
 * as a return in st when it was cold. */
static inline void px__gov_reset(struct px_gov *g,
				 struct px_track_shared_stats *st)
{
	if (g->cold)
		st->cold_left++;
	px__gov_restart(g);
}

/* Setup only: the cold query's cost (ns) at points spread over box,
 * from the real clock. */
double px__gov_calibrate(struct px_dist_model *m, px_aabb box);

/* Setup only: px__gov_init() with, when on, the cold query's cost on m
 * about the model (its bounds grown by 0.3 of its size scale: where a
 * tool works, not the whole working volume). */
void px__gov_setup(struct px_gov *g, int on, struct px_dist_model *m,
		   px_aabb bounds, double scale);

/* Tests: another clock (NULL: CLOCK_MONOTONIC). */
void px__gov_set_clock(struct px_gov *g, px_gov_clock_fn fn, void *ctx);

/* The state of src into dst, dst's clock kept (benches: a path replayed
 * from the same state). */
void px__gov_copy(struct px_gov *dst, const struct px_gov *src);

/* ---- the rest the trackers share: arguments, options, stats,
 * verification ---- */

/* The arguments of px_*_update() and px_*_reset(): PX_E_INVAL (tracker
 * or result NULL), PX_E_NAN (p not finite) or PX_OK. */
static inline int px__tracker_args(const void *t, const void *r, px_vec3 p)
{
	if (!t || !r)
		return PX_E_INVAL;
	if (!isfinite(p.x) || !isfinite(p.y) || !isfinite(p.z))
		return PX_E_NAN;
	return PX_OK;
}

/* Their defaults; max_crit is each tracker's own. */
void px__tracker_opts_default(struct px_track_shared_opts *o, int max_crit);

/* 1 when create accepts them (max_crit 2..2^20, verify_every >= 0,
 * work_margin >= 0). */
int px__tracker_opts_valid(const struct px_track_shared_opts *o);

/* Setup only: the model's size (the diagonal of its bounds; 1 when
 * they are a point) and its working volume (the bounds grown by margin
 * times that size on every side). */
double px__tracker_scale(px_aabb bounds);
px_aabb px__tracker_work(px_aabb bounds, double margin, double scale);

/* px_*_get_stats(): *out = *st (size bytes: a px_track_stats or a
 * px_strack_stats, each beginning with the shared counters) with the
 * running means of the governor g; zeros without a tracker (st NULL),
 * nothing without out. */
void px__tracker_stats_out(void *out, const void *st, size_t size,
			   const struct px_gov *g);

/* The verification of an update counted in st and answered at distance
 * dist from p (opts.verify_every): 1 when px_dist_query() on m found a
 * point closer by more than the rounding allowance at the model size
 * scale (counted; the caller re-initialises and answers globally), else
 * 0; *verified is set to 1 where the answers were compared. Inline:
 * every update asks whether it is due. */
static inline int px__tracker_verify(const struct px_track_shared_opts *o,
				     struct px_track_shared_stats *st,
				     struct px_dist_model *m, double scale,
				     px_vec3 p, double dist, int *verified)
{
	struct px_dist_result g;
	if (o->verify_every <= 0 || st->updates % (uint64_t)o->verify_every != 0)
		return 0;
	if (px_dist_query(m, p, &g))
		return 0;
	st->verifications++;
	*verified = 1;
	if (!(dist > g.dist + 1e-9 * (scale + g.dist)))
		return 0;
	st->disagreements++;
	return 1;
}

#endif
