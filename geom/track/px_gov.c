/*
 * px_gov.c - the trackers' cost governor (gov_internal.h).
 */
#include "gov_internal.h"

#include <stdlib.h>
#include <string.h>
#include <time.h>

/* running means: the last 32 timed samples weigh about two thirds */
#define GOV_ALPHA (1.0 / 32)

static int64_t mono_ns(void *ctx)
{
	struct timespec ts;
	(void)ctx;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

void px__gov_init(struct px_gov *g, int on, double cold_ns)
{
	px__gov_restart(g); /* cold, probing, the samples, the timing */
	g->on = on;
	g->n_cold = 0;
	g->cold_ns = cold_ns > 0.0 ? cold_ns : 1.0;
	g->step = 0.0;
	g->step_enter = 0.0;
	g->entered = g->left = 0;
	g->probe = PX_GOV_PROBE;
	g->n_back = UINT32_MAX;
	g->leave = PX_GOV_LEAVE;
	g->clock = mono_ns;
	g->clock_ctx = 0;
}

void px__gov_restart(struct px_gov *g)
{
	g->cold = 0;
	g->probing = 0;
	g->n_trk = 0;
	g->trk_ns = 0.0;
	g->tick = 0;
	g->skip = PX_GOV_WARM;
	g->behind_gap = UINT32_MAX;
	g->behind_run = 0;
	g->returning = 0;
}

void px__gov_set_clock(struct px_gov *g, px_gov_clock_fn fn, void *ctx)
{
	g->clock = fn ? fn : mono_ns;
	g->clock_ctx = ctx;
}

void px__gov_copy(struct px_gov *dst, const struct px_gov *src)
{
	px_gov_clock_fn fn = dst->clock;
	void *ctx = dst->clock_ctx;
	*dst = *src;
	dst->clock = fn;
	dst->clock_ctx = ctx;
}

int64_t px__gov_now(const struct px_gov *g)
{
	return g->clock(g->clock_ctx);
}

static double clip(double x, double lim)
{
	if (!(x >= 0.0))
		return 0.0;
	return x > lim ? lim : x;
}

/* Going cold from the next update on (a probe that failed waits twice
 * as long for the next; a return by step that failed soon asks for a
 * step halved again). Returns 1. */
static int go_cold(struct px_gov *g)
{
	if (g->probing) {
		g->probe = g->probe < PX_GOV_PROBE_MAX / 2 ? 2 * g->probe
							   : PX_GOV_PROBE_MAX;
	} else {
		g->probe = PX_GOV_PROBE;
		g->step_enter = g->step;
		g->leave = g->n_back < PX_GOV_BACK
				   ? (g->leave > PX_GOV_LEAVE / 8 ? 0.5 * g->leave
								 : g->leave)
				   : PX_GOV_LEAVE;
	}
	g->cold = 1;
	g->probing = 0;
	g->n_cold = 0;
	g->entered++;
	return 1;
}

int px__gov_tracked(struct px_gov *g, double ns)
{
	int need = px__gov_need(g);
	if (!g->on || g->cold)
		return 0;
	ns = clip(ns, PX_GOV_CLIP * g->cold_ns);
	if (g->n_trk < (1 << 30))
		g->n_trk++;
	/* the decision after a (re)start or probe is made on the plain
	 * mean of its consecutive samples; the running mean goes on from
	 * there */
	if (g->n_trk <= need)
		g->trk_ns += (ns - g->trk_ns) / g->n_trk;
	else
		g->trk_ns += GOV_ALPHA * (ns - g->trk_ns);
	if (g->n_trk < need)
		return 0;
	if (g->trk_ns > PX_GOV_ENTER * g->cold_ns)
		return go_cold(g);
	g->probing = 0;
	return 0;
}

int px__gov_fell_behind(struct px_gov *g)
{
	if (!g->on || g->cold)
		return 0;
	if (g->behind_run++ == 0) {
		/* a catch-up begins */
		int soon = g->behind_gap < PX_GOV_BEHIND_GAP;
		g->behind_gap = 0;
		if (soon)
			return go_cold(g);
	}
	return g->behind_run > (g->returning ? PX_GOV_BEHIND_RETURN : PX_GOV_BEHIND_RUN)
		       ? go_cold(g)
		       : 0;
}

/* A timed cold update took ns (the query alone). */
static void cold_sample(struct px_gov *g, double ns)
{
	/* clipped by the tracked mean that sent the tracker here: a cold
	 * mean inflated by an interrupt would keep it tracking too long */
	double lim = PX_GOV_CLIP * (g->trk_ns > g->cold_ns ? g->trk_ns : g->cold_ns);
	g->cold_ns += GOV_ALPHA * (clip(ns, lim) - g->cold_ns);
	if (!(g->cold_ns > 0.0))
		g->cold_ns = 1.0;
}

int px__gov_cold_query(struct px_gov *g, struct px_track_shared_stats *st,
		       struct px_dist_model *m, px_vec3 p,
		       struct px_dist_result *out)
{
	int64_t t0 = px__gov_start(g);
	int rc = px_dist_query(m, p, out);
	if (t0 != PX_GOV_UNTIMED)
		cold_sample(g, (double)(px__gov_now(g) - t0));
	if (rc == PX_OK) {
		st->updates++;
		st->cold++;
	}
	return rc;
}

int px__gov_leave(struct px_gov *g)
{
	int probe;
	if (!g->cold)
		return 0;
	if (g->n_cold < PX_GOV_MIN_COLD) {
		g->n_cold++;
		return 0;
	}
	probe = ++g->n_cold >= g->probe;
	if (!probe && !(g->step <= g->leave * g->step_enter))
		return 0;
	g->left++;
	px__gov_restart(g);
	g->probing = probe;
	g->n_back = probe ? UINT32_MAX : 0;
	g->returning = 1;
	return 1;
}

static int cmp_d(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

double px__gov_calibrate(struct px_dist_model *m, px_aabb box)
{
	/* single queries at points spread over the box (a fixed sequence:
	 * the same points on every run), as the loop makes them; the mean
	 * without the slowest eighth (interrupts, the first cold caches) */
	double t[64], sum = 0.0;
	uint64_t s = 0x9e3779b97f4a7c15ull;
	int i, k, n = 0, keep, pass;
	/* the second pass is timed: the first warms the caches */
	for (pass = 0; pass < 2; pass++) {
	n = 0;
	s = 0x9e3779b97f4a7c15ull;
	for (i = 0; i < 64; i++) {
		double c[3];
		struct px_dist_result r;
		int64_t x;
		for (k = 0; k < 3; k++) {
			s ^= s << 13;
			s ^= s >> 7;
			s ^= s << 17;
			c[k] = (double)(s >> 11) * 0x1.0p-53;
		}
		px_vec3 p = px_v3(box.min.x + c[0] * (box.max.x - box.min.x),
				  box.min.y + c[1] * (box.max.y - box.min.y),
				  box.min.z + c[2] * (box.max.z - box.min.z));
		x = mono_ns(NULL);
		if (px_dist_query(m, p, &r) != PX_OK)
			continue;
		t[n++] = (double)(mono_ns(NULL) - x);
	}
	}
	if (n == 0)
		return 1000.0;
	qsort(t, (size_t)n, sizeof(t[0]), cmp_d);
	keep = n - n / 8;
	for (i = 0; i < keep; i++)
		sum += t[i];
	sum /= keep;
	return sum > 1.0 ? sum : 1.0;
}

void px__gov_setup(struct px_gov *g, int on, struct px_dist_model *m,
		   px_aabb bounds, double scale)
{
	px_aabb cb = bounds;
	double d = 0.3 * scale;
	cb.min = px_v3_sub(cb.min, px_v3(d, d, d));
	cb.max = px_v3_add(cb.max, px_v3(d, d, d));
	px__gov_init(g, on, on ? px__gov_calibrate(m, cb) : 1.0);
}

/* ------------------------------------------------------------------ */
/* the shared options and stats                                        */

void px__tracker_opts_default(struct px_track_shared_opts *o, int max_crit)
{
	o->work_margin = 1.0;
	o->max_crit = max_crit;
	o->verify_every = 0;
	o->dist = NULL;
	o->cold_switch = 1;
}

int px__tracker_opts_valid(const struct px_track_shared_opts *o)
{
	return o->max_crit >= 2 && o->max_crit <= 1 << 20 &&
	       o->verify_every >= 0 && o->work_margin >= 0.0;
}

double px__tracker_scale(px_aabb bounds)
{
	double s = px_aabb_diagonal(&bounds);
	return s > 0.0 ? s : 1.0;
}

px_aabb px__tracker_work(px_aabb bounds, double margin, double scale)
{
	px_aabb w;
	double m = margin * scale;
	w.min = px_v3_sub(bounds.min, px_v3(m, m, m));
	w.max = px_v3_add(bounds.max, px_v3(m, m, m));
	return w;
}

void px__tracker_stats_out(void *out, const void *st, size_t size,
			   const struct px_gov *g)
{
	/* the shared counters are the first member of *out */
	struct px_track_shared_stats *sh = out;
	if (!out)
		return;
	if (!st) {
		memset(out, 0, size);
		return;
	}
	memcpy(out, st, size);
	sh->tracked_ns = g->trk_ns;
	sh->cold_ns = g->cold_ns;
}
