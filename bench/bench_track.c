/*
 * Tracking benchmark: per-update time (median, p99, p99.9, max) of px_track on
 * moving-point trajectories (smooth random paths and sums of sinusoids,
 * steps of 0.01 %, 0.1 %, 1 % and 5 % of the model size), next to the
 * cold global query px_dist_query() on the same points in the same run
 * (ratio of medians; each runs the whole path in its own pass, so that
 * neither finds the branch predictor trained by the other at the same
 * point), with the number of answers that differ from the
 * global one (must be 0), transitions, leaf re-solves and
 * re-initialisations. Verification inside the tracker is off (the loop
 * configuration); the comparison is made outside the timed call.
 * Surfaces (px_strack) follow: a single wavy bicubic patch, a wavy
 * 16-patch bicubic, a concave fold, with cells solved per update.
 * BENCH_TRACK_DEPTH=d overrides the event-grid depth (default 4),
 * BENCH_TRACK_LEAVES=n the parameter leaves per span (default 4);
 * BENCH_TRACK_WORST=1 prints what the worst update of each curve row did;
 * BENCH_TRACK_CLASSES=1 prints for each surface row the median time of
 * the updates by their work (0, 1, 2, 3, 4 or more cell tests, answered
 * other than by tracking, cells solved): which of them sets the median
 * (both read the stats inside the timed call: tens of ns each update);
 * BENCH_TRACK_GOV=1 what the cold switch saw and did per row (its means,
 * cold updates and their median, switches). The header line of each
 * model gives the cost of a re-initialisation (reset: the least of 20;
 * surfaces also the median and its share per cell). The surfaces'
 * targets line puts the cold query's worst case, measured as the
 * tracker's (each point's least of 3), next to the tracker's. The runs
 * behind a least-of-3 replay the first run's cold switch decisions (its
 * clock readings, from the same switch state), so each update's least
 * time compares the same work; a replay that diverged says so.
 * BENCH_TRACK_CURVES_ONLY=1 stops after the curve models (profiling);
 * BENCH_TRACK_LAZY=0 turns lazy correction off; BENCH_TRACK_MODEL=text runs
 * only the curve models whose name holds text, BENCH_TRACK_STEP=0..3 only
 * that step size (profiling). Each curve path runs
 * three times; a summary line per model gives the medians per step size
 * (worse path kind) and the ratio to the cold query, and a targets line
 * says which of the curve targets are met. Each surface ends
 * with the tracked path against the cold query it replaces: median and
 * p99 ratios per step size (also by each update's least of 3 runs) and
 * the steps where it is never slower at either.
 * B-rep models (tests/support/brep_gen.h's parts, the shipped STEP block
 * with OpenCASCADE) follow: their tracked streams against the cold query
 * (BENCH_TRACK_BREP_ONLY=1 runs them alone).
 * Prints figures only; nothing here is a pass/fail test.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <linux/perf_event.h>
#include <sys/syscall.h>
#include <unistd.h>

#include "brep_gen.h"
#include "gov_internal.h"
#include "track_hooks.h"
#include "px_arena.h"
#include "px_brep.h"
#include "px_dist.h"
#include "px_features.h"
#include "px_load.h"
#include "px_model.h"
#include "px_nurbs.h"
#include "sheet_gen.h"
#include "px_strack.h"
#include "px_test_paths.h"
#include "px_track.h"

#define NSTEP_MAX 10000 /* the longer of the curve and surface paths */

static uint64_t rng = 0x9e3779b97f4a7c15ull;
static double urand(void)
{
	rng ^= rng << 13;
	rng ^= rng >> 7;
	rng ^= rng << 17;
	return (double)(rng >> 11) * 0x1.0p-53;
}

/* A uniform point in box (coordinates drawn x, y, z in that order). */
static px_vec3 box_urand(px_aabb box)
{
	double x = box.min.x + (box.max.x - box.min.x) * urand();
	double y = box.min.y + (box.max.y - box.min.y) * urand();
	double z = box.min.z + (box.max.z - box.min.z) * urand();
	return px_v3(x, y, z);
}

static double nrand(void)
{
	double a = urand(), b = urand();
	return sqrt(-2.0 * log(a + 1e-300)) * cos(2 * M_PI * b);
}

static int64_t now_ns(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

/* Thread CPU time: what an update costs without the time the thread
 * spends preempted (the raw max on a shared machine is that time). */
static int64_t cpu_ns(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
	return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

/*
 * The cold switch reads the clock, so two runs of the same path can
 * switch at different updates and "each update's least time over the
 * runs" would compare different work. The first run records the
 * switch's clock readings and the runs after it replay them from the
 * same switch state (px__gov_copy()): the same decisions at the same
 * updates. A replay that asks for more readings than were recorded
 * (or fewer) took another decision somewhere: counted in miss.
 */
struct rclock {
	int64_t v[4 * NSTEP_MAX];
	long n, pos, miss;
	int replay;
};

static struct rclock rclk;

static int64_t rclock_read(void *ctx)
{
	struct rclock *c = ctx;
	int64_t x;
	if (c->replay) {
		if (c->pos < c->n)
			return c->v[c->pos++];
		c->miss++;
		return now_ns();
	}
	x = now_ns();
	if (c->n < (long)(sizeof(c->v) / sizeof(c->v[0])))
		c->v[c->n++] = x;
	else
		c->miss++;
	return x;
}

static void rclock_record(void)
{
	rclk.n = rclk.pos = rclk.miss = 0;
	rclk.replay = 0;
}

/* The end of the runs: a replay that did not use all of the readings
 * diverged too. Returns the divergences. */
static long rclock_done(void)
{
	if (rclk.replay && rclk.pos != rclk.n)
		rclk.miss++;
	rclk.replay = 0;
	return rclk.miss;
}

/* The next replay (the one before it ended as rclock_done() ends). */
static void rclock_replay(void)
{
	rclock_done();
	rclk.pos = 0;
	rclk.replay = 1;
}

static int cmp_i64(const void *a, const void *b)
{
	int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
	return (x > y) - (x < y);
}

static struct px_arena arena;
static unsigned char arena_mem[1 << 20];

static int mk(struct px_nurbs_curve *c, int p, int n, const double *U,
	      const double *xyz, const double *w)
{
	return px_nurbs_curve_init(c, &arena, p, n, U, n + p + 1, xyz, w, NULL);
}

static int mk_periodic(struct px_nurbs_curve *c, int p, int m, const double *pts)
{
	double U[80], xyz[3 * 80];
	int n = m + p, i;
	for (i = 0; i < n + p + 1; i++)
		U[i] = i;
	for (i = 0; i < n; i++)
		memcpy(&xyz[3 * i], &pts[3 * (i % m)], 3 * sizeof(double));
	return mk(c, p, n, U, xyz, NULL);
}

static int blob(struct px_nurbs_curve *c, double cx, double cy)
{
	double pts[3 * 14];
	int i;
	for (i = 0; i < 14; i++) {
		double a = 2 * M_PI * i / 14, r = 1.0 + 0.35 * sin(3 * a) + 0.1 * cos(5 * a);
		pts[3 * i] = cx + r * cos(a);
		pts[3 * i + 1] = cy + 0.8 * r * sin(a);
		pts[3 * i + 2] = 0;
	}
	return mk_periodic(c, 3, 14, pts);
}

static int breaks(struct px_nurbs_curve *c, double cx, double cy)
{
	static const double U[] = {0, 0, 0, 0, 0.2, 0.35, 0.35, 0.5, 0.5, 0.5,
				   0.7, 0.85, 1, 1, 1, 1};
	double xyz[36];
	int i;
	for (i = 0; i < 12; i++) {
		double a = 1.6 * M_PI * i / 11;
		xyz[3 * i] = cx + 1.2 * cos(a) + 0.3 * ((i * 7) % 3 - 1);
		xyz[3 * i + 1] = cy + 0.9 * sin(a) + 0.25 * ((i * 5) % 4 - 1.5);
		xyz[3 * i + 2] = 0;
	}
	return mk(c, 3, 12, U, xyz, NULL);
}

static int knot(struct px_nurbs_curve *c, double cx, double cy, double cz)
{
	double pts[3 * 18];
	int i;
	for (i = 0; i < 18; i++) {
		double a = 2 * M_PI * i / 18;
		pts[3 * i] = cx + 0.5 * (sin(a) + 2 * sin(2 * a));
		pts[3 * i + 1] = cy + 0.5 * (cos(a) - 2 * cos(2 * a));
		pts[3 * i + 2] = cz - 0.5 * sin(3 * a);
	}
	return mk_periodic(c, 3, 18, pts);
}

static int circle(struct px_nurbs_curve *c, double cx, double cy, double r)
{
	static const double U[] = {0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1};
	static const double px[] = {1, 1, 0, -1, -1, -1, 0, 1, 1};
	static const double py[] = {0, 1, 1, 1, 0, -1, -1, -1, 0};
	double xyz[27], w[9];
	int i;
	for (i = 0; i < 9; i++) {
		xyz[3 * i] = cx + r * px[i];
		xyz[3 * i + 1] = cy + r * py[i];
		xyz[3 * i + 2] = 0;
		w[i] = (i & 1) ? sqrt(0.5) : 1.0;
	}
	return mk(c, 2, 9, U, xyz, w);
}

#define NSTEP 10000

/* One trajectory of n points: kind 0 smooth random, 1 sinusoids. */
static void make_path(px_vec3 *q, int n, int kind, px_aabb box, double step)
{
	static const struct px_path_opts o = {urand, nrand, 0.97, 0.25, 1.2};
	px_test_path(q, n, kind, box, step, &o);
}

/* Targets of the issue for a curve model, checked per model. */
#define TGT_MED_NS 300
#define TGT_MAX_NS 20000
#define TGT_RATIO 10.0
#define NRUN 3

static int tgt_models, tgt_med_ok, tgt_max_ok, tgt_ratio_ok, tgt_wrong_ok;
/* the clock's own cost: median of an empty timed region (every per-update
 * figure carries it once) */
static int64_t timer_ns;

static int cmp_i64(const void *a, const void *b);
static void measure_timer(void)
{
	static int64_t e[20001];
	int i;
	for (i = 0; i < 20001; i++) {
		int64_t x = now_ns();
		e[i] = now_ns() - x;
	}
	qsort(e, 20001, sizeof(e[0]), cmp_i64);
	timer_ns = e[10000];
}

/* steps (per path kind) where a target holds, for the targets line */
static void print_steps(const char *what, const int ok[2][4])
{
	static const char *nm[4] = {"0.01", "0.1", "1", "5"};
	int s, any = 0;
	printf("%s:", what);
	for (s = 0; s < 4; s++)
		if (ok[0][s] && ok[1][s]) {
			printf(" %s", nm[s]);
			any = 1;
		}
	printf("%s", any ? " %" : " none");
}

static void run(const char *name, const struct px_nurbs_curve *cs, int nc)
{
	static px_vec3 q[NSTEP];
	static int64_t tt[NRUN * NSTEP], tg[NRUN * NSTEP];
	static double dt[NSTEP];
	/* BENCH_TRACK_WORST=1: what the worst update of each row did */
	static int wk_solved[NSTEP], wk_src[NSTEP], wk_reinit[NSTEP], wk_tests[NSTEP];
	int worst_env = getenv("BENCH_TRACK_WORST") != NULL;
	static const double steps[] = {1e-4, 1e-3, 1e-2, 5e-2};
	struct px_track *t = NULL;
	struct px_track_opts o;
	struct px_dist_model *ref = NULL;
	struct px_track_info ti;
	struct px_dist_info di;
	int64_t t0, med[2][4], reset_ns;
	double ratio[2][4];
	int ok_med[2][4], ok_rt[2][4], ok_net[2][4], ok_bat[2][4], ok_m3[2][4];
	long wrong_all = 0;
	int kind, s, k, rc, run_i, med_ok = 1, max_ok = 1, max3_ok = 1, ratio_ok = 1;
	int64_t cmax_all = 0, mmax_all = 0;
	double size;
	px_aabb box;

	if (getenv("BENCH_TRACK_MODEL") && !strstr(name, getenv("BENCH_TRACK_MODEL")))
		return;
	px_track_opts_default(&o);
	if (getenv("BENCH_TRACK_DEPTH"))
		o.box_depth = atoi(getenv("BENCH_TRACK_DEPTH"));
	if (getenv("BENCH_TRACK_LAZY"))
		o.lazy = atoi(getenv("BENCH_TRACK_LAZY"));
	if (getenv("BENCH_TRACK_LEAVES"))
		o.leaves_per_span = atoi(getenv("BENCH_TRACK_LEAVES"));
	t0 = now_ns();
	rc = px_track_create(cs, nc, &o, &t);
	if (rc) {
		printf("%s: tracker setup failed: %s\n", name, px_strerror(rc));
		return;
	}
	t0 = now_ns() - t0;
	px_dist_model_create(cs, nc, NULL, 0, NULL, &ref);
	px_track_get_info(t, &ti);
	px_dist_model_info(ref, &di);
	box = di.bounds;
	size = px_aabb_diagonal(&box);
	box.min = px_v3_sub(box.min, px_v3(0.3 * size, 0.3 * size, 0.3 * size));
	box.max = px_v3_add(box.max, px_v3(0.3 * size, 0.3 * size, 0.3 * size));
	{
		/* what a re-initialisation costs (every leaf solved, every
		 * safe radius): the least of 20 at points spread over the
		 * model's box */
		struct px_track_result r0;
		int64_t best = INT64_MAX;
		int i;
		for (i = 0; i < 20; i++) {
			px_vec3 c = box_urand(box);
			int64_t x = now_ns();
			px_track_reset(t, c, &r0);
			x = now_ns() - x;
			if (x < best)
				best = x;
		}
		reset_ns = best;
	}
	printf("%s: %d curves, %d spans, %d leaves (%d boxed), setup %.1f ms, "
	       "%zu bytes, reset %.1f us\n", name, nc, ti.n_spans, ti.n_leaves,
	       ti.n_boxed_leaves, t0 / 1e6, ti.bytes, reset_ns / 1e3);
	printf("  %-8s %-7s %8s %8s %8s %8s %8s | %8s %8s | %6s | %5s %6s %6s %5s "
	       "%5s %6s %6s %6s %8s %8s | %5s %5s | %6s %6s %5s\n",
	       "path", "step", "med_ns", "p99_ns", "p999_ns", "max_ns", "max_m3",
	       "cold_med", "cold_p99", "ratio", "wrong", "trans", "solves",
	       "reini", "fallb", "tests", "rest", "erest", "cpu_max", "max_min3",
	       "hot", "net", "mean", "cmean", "bat");
	/* hot: share of updates answered on the hot path; net: the ratio of
	 * medians with the clock's own median (timer_ns) taken from both;
	 * mean, cmean: mean ns per update / per cold query over a whole path
	 * timed as one block (the same states again: no clock in between,
	 * every update's cost in it, the hot path's and the rest's); bat:
	 * cmean / mean */
	/* trans, solves, reini, fallb: counts per run of the path; tests:
	 * leaves given the exact segment test per update; rest:
	 * critical points left uncorrected per update (lazy); erest: curves
	 * passed whole on their rest certificate per update; max_m3: the
	 * median over NRUN runs of each run's max (max_ns is the raw max of
	 * all runs: on a shared machine it is dominated by interrupts);
	 * cpu_max: the max of one more run by thread CPU time (without the
	 * time preempted, but with page faults, interrupts and a VM's
	 * stolen time where the kernel charges them to the thread);
	 * max_min3: the largest over the updates of each update's least
	 * time in the NRUN runs (every run replays the same states, so the
	 * work of an update repeats and an interrupt rarely does: the
	 * worst case of the work itself) */
	for (kind = 0; kind < 2; kind++)
		for (s = 0; s < 4; s++) {
			struct px_track_result r;
			if (getenv("BENCH_TRACK_STEP") && atoi(getenv("BENCH_TRACK_STEP")) != s) {
				med[kind][s] = 0;
				ratio[kind][s] = 0.0;
				ok_med[kind][s] = ok_rt[kind][s] = ok_net[kind][s] = 0;
				ok_bat[kind][s] = ok_m3[kind][s] = 0;
				continue;
			}
			struct px_track_stats a, b;
			struct px_dist_result g;
			int64_t rmax[NRUN], x3, cmax, mmax;
			struct px_gov gsave;
			long miss;
			int kworst = -1;
			double bmean, cmean, net;
			long wrong = 0;
			int n = 0;
			make_path(q, NSTEP, kind, box, steps[s] * size);
			px_track_get_stats(t, &a);
			/* the tracker and the cold query each run the whole path
			 * on their own: interleaved at the same point, the
			 * second call finds the branch predictor trained by the
			 * first on the same data, which flatters whichever runs
			 * second */
			/* the cold switch's decisions of the first run
			 * replayed in the others (rclock) */
			gsave = *px__track_gov(t);
			px__track_set_clock(t, rclock_read, &rclk);
			rclock_record();
			for (run_i = 0; run_i < NRUN; run_i++) {
				int n0 = n;
				rmax[run_i] = 0;
				if (run_i > 0) {
					px__gov_copy(px__track_gov(t), &gsave);
					rclock_replay();
				}
				px_track_reset(t, q[0], &r);
				for (k = 0; k < NSTEP; k++, n++) {
					int64_t x = now_ns();
					struct px_track_stats s0, s1;
					if (run_i == 0 && worst_env)
						px_track_get_stats(t, &s0);
					px_track_update(t, q[k], &r);
					tt[n] = now_ns() - x;
					if (run_i == 0 && worst_env) {
						px_track_get_stats(t, &s1);
						wk_solved[k] = r.leaves_solved;
						wk_src[k] = r.source;
						wk_reinit[k] = (int)(s1.reinits - s0.reinits);
						wk_tests[k] = (int)(s1.box_hits - s0.box_hits);
					}
					if (tt[n] > rmax[run_i])
						rmax[run_i] = tt[n];
					dt[k] = r.dist;
				}
				for (k = 0, n = n0; k < NSTEP; k++, n++) {
					int64_t x = now_ns();
					px_dist_query(ref, q[k], &g);
					tg[n] = now_ns() - x;
					if (fabs(dt[k] - g.dist) > 1e-9 * (size + g.dist))
						wrong++;
				}
			}
			miss = rclock_done();
			px__track_set_clock(t, NULL, NULL);
			if (miss)
				printf("  (the cold switch's replay diverged %ld times: "
				       "max_min3 compares different decisions)\n", miss);
			px_track_get_stats(t, &b);
			if (getenv("BENCH_TRACK_GOV"))
				printf("  gov: tracked %.0f ns, cold %.0f ns, cold updates %llu, entered %llu, left %llu\n",
				       b.tracked_ns, b.cold_ns, (unsigned long long)(b.cold - a.cold),
				       (unsigned long long)(b.cold_entered - a.cold_entered),
				       (unsigned long long)(b.cold_left - a.cold_left));
			/* once more, by thread CPU time: the max without
			 * preemption */
			cmax = 0;
			px_track_reset(t, q[0], &r);
			for (k = 0; k < NSTEP; k++) {
				int64_t x = cpu_ns();
				px_track_update(t, q[k], &r);
				x = cpu_ns() - x;
				if (x > cmax)
					cmax = x;
			}
			if (cmax > cmax_all)
				cmax_all = cmax;
			/* each update's least time over the runs (the same
			 * state every run: real work repeats, an interrupt does
			 * not), then the largest of those */
			mmax = 0;
			for (k = 0; k < NSTEP; k++) {
				int64_t m = tt[k];
				for (run_i = 1; run_i < NRUN; run_i++)
					if (tt[run_i * NSTEP + k] < m)
						m = tt[run_i * NSTEP + k];
				if (m > mmax) {
					mmax = m;
					kworst = k;
				}
			}
			if (worst_env && kworst >= 0)
				printf("  (worst update %d: %.1f us, leaves solved %d, "
				       "leaf tests %d, entity re-initialisations %d, "
				       "source %d)\n", kworst, mmax / 1e3,
				       wk_solved[kworst], wk_tests[kworst],
				       wk_reinit[kworst], wk_src[kworst]);
			if (mmax > mmax_all)
				mmax_all = mmax;
			/* the whole path as one block, tracked then cold */
			{
				int64_t x;
				double chk = 0.0;
				px_track_reset(t, q[0], &r);
				x = now_ns();
				for (k = 0; k < NSTEP; k++) {
					px_track_update(t, q[k], &r);
					chk += r.dist;
				}
				bmean = (double)(now_ns() - x) / NSTEP;
				x = now_ns();
				for (k = 0; k < NSTEP; k++) {
					px_dist_query(ref, q[k], &g);
					chk -= g.dist;
				}
				cmean = (double)(now_ns() - x) / NSTEP;
				if (fabs(chk) > 1e-6 * size * NSTEP)
					printf("  (block runs disagree: %g)\n", chk);
			}
			qsort(tt, (size_t)n, sizeof(tt[0]), cmp_i64);
			qsort(tg, (size_t)n, sizeof(tg[0]), cmp_i64);
			qsort(rmax, NRUN, sizeof(rmax[0]), cmp_i64);
			x3 = rmax[NRUN / 2];
			med[kind][s] = tt[n / 2];
			ratio[kind][s] = (double)tg[n / 2] / (double)(tt[n / 2] ? tt[n / 2] : 1);
			net = tt[n / 2] > timer_ns
				      ? (double)(tg[n / 2] - timer_ns) /
						(double)(tt[n / 2] - timer_ns)
				      : 0.0;
			wrong_all += wrong;
			printf("  %-8s %-7g %8lld %8lld %8lld %8lld %8lld | %8lld %8lld | "
			       "%6.1f | %5ld %6llu %6llu %5llu %5llu %6.2f %6.2f %6.2f %8lld %8lld | "
			       "%5.2f %5.1f | %6.0f %6.0f %5.1f\n",
			       kind ? "sines" : "random", steps[s] * 100.0,
			       (long long)tt[n / 2], (long long)tt[n * 99 / 100],
			       (long long)tt[n * 999 / 1000], (long long)tt[n - 1],
			       (long long)x3, (long long)tg[n / 2],
			       (long long)tg[n * 99 / 100], ratio[kind][s], wrong,
			       (unsigned long long)(b.creations + b.annihilations -
						    a.creations - a.annihilations) / NRUN,
			       (unsigned long long)(b.leaf_solves - a.leaf_solves) / NRUN,
			       (unsigned long long)(b.reinits - a.reinits) / NRUN,
			       (unsigned long long)(b.fallbacks - a.fallbacks) / NRUN,
			       (double)(b.box_hits - a.box_hits) / n,
			       (double)(b.rested - a.rested) / n,
			       (double)(b.rested_entities - a.rested_entities) / n,
			       (long long)cmax, (long long)mmax,
			       (double)(b.hot - a.hot) / n, net, bmean, cmean,
			       cmean / bmean);
			ok_med[kind][s] = tt[n / 2] <= TGT_MED_NS;
			ok_rt[kind][s] = ratio[kind][s] >= TGT_RATIO;
			ok_net[kind][s] = net >= TGT_RATIO;
			ok_bat[kind][s] = cmean / bmean >= TGT_RATIO;
			ok_m3[kind][s] = mmax <= TGT_MAX_NS;
			if (tt[n / 2] > TGT_MED_NS)
				med_ok = 0;
			if (tt[n - 1] > TGT_MAX_NS)
				max_ok = 0;
			if (x3 > TGT_MAX_NS)
				max3_ok = 0;
			if (ratio[kind][s] < TGT_RATIO)
				ratio_ok = 0;
		}
	/* per step size: the worse of the two path kinds */
	printf("  summary:");
	for (s = 0; s < 4; s++) {
		int64_t m = med[0][s] > med[1][s] ? med[0][s] : med[1][s];
		double rt = ratio[0][s] < ratio[1][s] ? ratio[0][s] : ratio[1][s];
		printf(" %g%%: med %lld ns, x%.1f%s", steps[s] * 100.0, (long long)m,
		       rt, s < 3 ? " |" : "\n");
	}
	printf("  targets: median <= %d ns %s; max <= %d us %s (raw max), %s "
	       "(median of %d runs' max), %s (thread CPU time, preemption "
	       "excluded: max %.1f us), %s (worst update of its least of %d "
	       "runs: %.1f us); >= %.0fx cold %s; wrong 0 %s\n",
	       TGT_MED_NS, med_ok ? "MET" : "NOT MET", TGT_MAX_NS / 1000,
	       max_ok ? "MET" : "NOT MET", max3_ok ? "MET" : "NOT MET", NRUN,
	       cmax_all <= TGT_MAX_NS ? "MET" : "NOT MET", cmax_all / 1e3,
	       mmax_all <= TGT_MAX_NS ? "MET" : "NOT MET", NRUN, mmax_all / 1e3,
	       TGT_RATIO, ratio_ok ? "MET" : "NOT MET",
	       wrong_all == 0 ? "MET" : "NOT MET");
	printf("  targets by step (%% of the size, met on both paths): ");
	print_steps("median <= 300 ns", ok_med);
	print_steps("; max <= 20 us by the work (max_min3)", ok_m3);
	print_steps("; >= 10x cold by medians", ok_rt);
	print_steps(", by medians net of the clock", ok_net);
	print_steps(", by block means", ok_bat);
	printf("\n");
	tgt_models++;
	tgt_med_ok += med_ok;
	tgt_max_ok += max3_ok;
	tgt_ratio_ok += ratio_ok;
	tgt_wrong_ok += wrong_all == 0;
	/* verification disagreements with the tracker's own check on */
	{
		struct px_track *tv = NULL;
		struct px_track_stats st;
		struct px_track_result r;
		o.verify_every = 1;
		if (!getenv("BENCH_TRACK_STEP") && px_track_create(cs, nc, &o, &tv) == PX_OK) {
			make_path(q, NSTEP, 0, box, 1e-2 * size);
			for (k = 0; k < NSTEP; k++)
				px_track_update(tv, q[k], &r);
			make_path(q, NSTEP, 1, box, 5e-2 * size);
			for (k = 0; k < NSTEP; k++)
				px_track_update(tv, q[k], &r);
			px_track_get_stats(tv, &st);
			printf("  verification (every update, %llu checks): %llu "
			       "disagreements\n",
			       (unsigned long long)st.verifications,
			       (unsigned long long)st.disagreements);
			px_track_free(tv);
		}
	}
	px_track_free(t);
	px_dist_model_free(ref);
}

/* ---- surfaces ------------------------------------------------------- */

/* The wavy sheet of n x n control points (clamped knots, uniform
 * inside); rational: with weights 0.6 to 1.5 over the net (the
 * certificates' rational path, as a CAD model's cylinders and spheres
 * take it). */
static int wavy_net(struct px_nurbs_surf *s, int n, int rational)
{
	double U[16], xyz[3 * 49], w[49];
	sheet_net(n, 1.0, 0.35, U, xyz, w);
	return px_nurbs_surf_init(s, &arena, 3, 3, n, n, U, n + 4, U, n + 4, xyz,
				  rational ? w : NULL, NULL);
}

static int wavy_surf(struct px_nurbs_surf *s, int n)
{
	return wavy_net(s, n, 0);
}

/* The 16-patch wavy sheet made rational. */
static int rational_surf(struct px_nurbs_surf *s)
{
	return wavy_net(s, 7, 1);
}

static int fold_surf(struct px_nurbs_surf *s)
{
	static const double U[] = {0, 0, 0, 0, 1, 1, 1, 1};
	static const double V[] = {0, 0, 0, 0, 0.25, 0.5, 0.75, 1, 1, 1, 1};
	double xyz[3 * 4 * 7];
	int i, j;
	for (j = 0; j < 7; j++)
		for (i = 0; i < 4; i++) {
			double a = M_PI * (1.15 + 0.7 * j / 6.0);
			double *q = &xyz[3 * (j * 4 + i)];
			q[0] = 0.8 * cos(a);
			q[1] = -1 + 2.0 * i / 3;
			q[2] = 0.8 * sin(a) + 0.9 + 0.1 * (i == 1) - 0.08 * (i == 2);
		}
	return px_nurbs_surf_init(s, &arena, 3, 3, 4, 7, U, 8, V, 11, xyz, NULL,
				  NULL);
}

#define NSSTEP 3000

/* User-space instruction counter of this thread (perf events), for
 * figures that do not depend on the load of the machine; -1 when the
 * kernel refuses. */
static int ins_fd = -2;

static void ins_open(void)
{
	struct perf_event_attr a;
	if (ins_fd != -2)
		return;
	memset(&a, 0, sizeof(a));
	a.type = PERF_TYPE_HARDWARE;
	a.size = sizeof(a);
	a.config = PERF_COUNT_HW_INSTRUCTIONS;
	a.exclude_kernel = 1;
	a.exclude_hv = 1;
	ins_fd = (int)syscall(SYS_perf_event_open, &a, 0, -1, -1, 0);
	if (ins_fd < 0)
		ins_fd = -1;
}

static int64_t ins_read(void)
{
	uint64_t v = 0;
	if (ins_fd < 0 || read(ins_fd, &v, sizeof(v)) != (ssize_t)sizeof(v))
		return -1;
	return (int64_t)v;
}

/* Per path and step: what the summary and the targets line use. */
struct surf_row {
	int64_t med, p999, max, cold_med, ins_med, cold_ins_med, ins_max,
		cold_ins_max, wmax, cwmax;
	/* medians of each update's and each cold query's least time over
	 * the three runs (interrupts and a busy machine mostly fall out) */
	int64_t med3, cold_med3;
	/* 99th percentiles: of the first run, and of the least times */
	int64_t p99, cold_p99, p99_3, cold_p99_3;
	long wrong;
	double net, bat; /* ratio of medians net of the clock; of block means */
};

static double q_ratio(int64_t a, int64_t b)
{
	return b > 0 ? (double)a / (double)b : 0.0;
}

/* The steps (in %) where ok[] holds, into out (64 bytes). */
static void step_list(char *out, const int ok[4], const double steps[4])
{
	int n = 0, s;
	out[0] = 0;
	for (s = 0; s < 4; s++)
		if (ok[s])
			n += snprintf(out + n, 64 - (size_t)n, "%s%g", n ? ", " : "",
				      steps[s] * 100.0);
	if (!n)
		snprintf(out, 64, "none");
}

/* The tracked path against the cold query it replaces, per step size:
 * median and p99 of the tracked updates over the cold query's (first
 * run; in brackets each update's least of 3 runs, where interrupts and
 * other load mostly fall out), and the steps where the tracked path is
 * never slower (at most the cold query's median and p99 on both
 * paths). */
static void never_slower(const char *name, struct surf_row row[2][4],
			 const double steps[4])
{
	int med_ok[4], p99_ok[4], med3_ok[4], p993_ok[4], s, k;
	char lm[64], lp[64], lm3[64], lp3[64];
	printf("  against the cold query %s, tracked / cold (random / sines; "
	       "each update's least of 3 runs in brackets):\n", name);
	for (s = 0; s < 4; s++) {
		const struct surf_row *a = &row[0][s], *b = &row[1][s];
		printf("    step %-5g %%: median %4.2f / %4.2f [%4.2f / %4.2f], "
		       "p99 %4.2f / %4.2f [%4.2f / %4.2f]\n", steps[s] * 100.0,
		       q_ratio(a->med, a->cold_med), q_ratio(b->med, b->cold_med),
		       q_ratio(a->med3, a->cold_med3), q_ratio(b->med3, b->cold_med3),
		       q_ratio(a->p99, a->cold_p99), q_ratio(b->p99, b->cold_p99),
		       q_ratio(a->p99_3, a->cold_p99_3),
		       q_ratio(b->p99_3, b->cold_p99_3));
		med_ok[s] = p99_ok[s] = med3_ok[s] = p993_ok[s] = 1;
		for (k = 0; k < 2; k++) {
			const struct surf_row *w = &row[k][s];
			med_ok[s] &= w->med <= w->cold_med;
			p99_ok[s] &= w->p99 <= w->cold_p99;
			med3_ok[s] &= w->med3 <= w->cold_med3;
			p993_ok[s] &= w->p99_3 <= w->cold_p99_3;
		}
	}
	step_list(lm, med_ok, steps);
	step_list(lp, p99_ok, steps);
	step_list(lm3, med3_ok, steps);
	step_list(lp3, p993_ok, steps);
	printf("  never slower than the cold query %s, steps (%%) where met on "
	       "both paths: median %s, p99 %s; by each update's least of 3 "
	       "runs: median %s, p99 %s\n", name, lm, lp, lm3, lp3);
}

static void run_surf(const char *name, const struct px_nurbs_surf *ss, int ns)
{
	static px_vec3 q[NSSTEP];
	static int64_t tt[NSSTEP], tg[NSSTEP], it[NSSTEP], ig[NSSTEP], tw[NSSTEP];
	static int sw_solved[NSSTEP], sw_tests[NSSTEP], sw_src[NSSTEP];
	static int64_t tc[NSSTEP], tgw[NSSTEP], tsort[NSSTEP];
	static double ds[NSSTEP];
	int worst_env = getenv("BENCH_TRACK_WORST") != NULL ||
			getenv("BENCH_TRACK_CLASSES") != NULL;
	static const double steps[] = {1e-4, 1e-3, 1e-2, 5e-2};
	struct surf_row row[2][4];
	struct px_strack *t = NULL;
	struct px_strack_info ti;
	struct px_dist_model *ref = NULL;
	struct px_dist_info di;
	int64_t t0, ins0;
	int kind, s, k, rc;
	double size;
	px_aabb box;

	if (getenv("BENCH_TRACK_MODEL") && !strstr(name, getenv("BENCH_TRACK_MODEL")))
		return;
	ins_open();
	t0 = now_ns();
	rc = px_strack_create(NULL, 0, ss, ns, NULL, &t);
	if (rc) {
		printf("%s: tracker setup failed: %s\n", name, px_strerror(rc));
		return;
	}
	t0 = now_ns() - t0;
	px_dist_model_create(NULL, 0, ss, ns, NULL, &ref);
	px_strack_get_info(t, &ti);
	px_dist_model_info(ref, &di);
	box = di.bounds;
	size = px_aabb_diagonal(&box);
	box = px_aabb_inflate(&box, 0.3 * size);
	/* instructions of an empty bracket, taken off every count */
	ins0 = ins_read();
	ins0 = ins_read() - ins0;
	{
		/* a re-initialisation (every cell solved, the curve tracker
		 * reset): the least and the median of 20 at points spread
		 * over the box; per cell, what a slice of the rebuild costs */
		struct px_strack_result r0;
		int64_t rs[20];
		int i;
		for (i = 0; i < 20; i++) {
			px_vec3 c = box_urand(box);
			int64_t x = now_ns();
			px_strack_reset(t, c, &r0);
			rs[i] = now_ns() - x;
		}
		qsort(rs, 20, sizeof(rs[0]), cmp_i64);
		printf("%s: %d surfaces, %d patches, %d cells (%d solved whenever "
		       "hit: pole cells), %d edge curves, setup %.1f ms, reset "
		       "%.1f us (median %.1f, %.2f us a cell)\n",
		       name, ti.n_surfaces, ti.n_patches, ti.n_cells, ti.n_unbounded,
		       ti.n_edges, t0 / 1e6, rs[0] / 1e3, rs[10] / 1e3,
		       rs[10] / 1e3 / (ti.n_cells > 0 ? ti.n_cells : 1));
	}
	printf("  %-8s %-7s %8s %8s %8s %8s | %8s %8s | %6s | %5s %7s %6s %5s | "
	       "%5s %8s %8s %6s | %5s %5s | %6s %6s %5s\n",
	       "path", "step", "med_ns", "p99_ns", "p999_ns", "max_ns", "cold_med",
	       "cold_p99", "ratio", "wrong", "cells/u", "tests", "crit", "glob%",
	       "ins_med", "cins_med", "iratio", "hot", "net", "mean", "cmean",
	       "bat");
	for (kind = 0; kind < 2; kind++)
		for (s = 0; s < 4; s++) {
			struct px_strack_result r;
			struct px_strack_stats a, b;
			struct px_dist_result g;
			long wrong = 0, crit = 0, glob = 0, ncrit = 0, cold = 0, miss;
			struct px_gov gsave;
			double bmean, cmean;
			int kw = -1;
			if (getenv("BENCH_TRACK_STEP") && atoi(getenv("BENCH_TRACK_STEP")) != s) {
				memset(&row[kind][s], 0, sizeof(row[kind][s]));
				continue;
			}
			make_path(q, NSSTEP, kind, box, steps[s] * size);
			/* the cold switch's decisions of this run replayed in
			 * the two runs behind the work's worst (rclock) */
			gsave = *px__strack_gov(t);
			px__strack_set_clock(t, rclock_read, &rclk);
			rclock_record();
			px_strack_reset(t, q[0], &r);
			px_strack_get_stats(t, &a);
			for (k = 0; k < NSSTEP; k++) {
				int64_t x = now_ns();
				struct px_strack_stats s0, s1;
				if (worst_env)
					px_strack_get_stats(t, &s0);
				px_strack_update(t, q[k], &r);
				tt[k] = now_ns() - x;
				if (worst_env) {
					px_strack_get_stats(t, &s1);
					sw_solved[k] = (int)(s1.cell_solves - s0.cell_solves);
					sw_tests[k] = (int)(s1.box_tests - s0.box_tests);
					sw_src[k] = r.source;
				}
				ds[k] = r.dist;
				/* cold answers follow nothing (n_crit -1) */
				if (r.source != PX_TRACK_COLD) {
					crit += r.n_crit;
					ncrit++;
				}
				glob += r.source == PX_TRACK_GLOBAL;
				if (r.source == PX_TRACK_COLD)
					tc[cold++] = tt[k];
			}
			if (getenv("BENCH_TRACK_CLASSES")) {
				static const char *cname[8] = {"0 tests", "1 test", "2 tests",
							       "3 tests", "4 tests", ">4 tests",
							       "not tracked", "solves"};
				static int64_t cv[8][NSSTEP];
				int cn[8] = {0}, c;
				for (k = 1; k < NSSTEP; k++) {
					c = sw_solved[k] ? 7
					    : sw_src[k] != PX_TRACK_TRACKED ? 6
					    : sw_tests[k] > 4 ? 5 : sw_tests[k];
					cv[c][cn[c]++] = tt[k];
				}
				printf("  classes %s %g %%, updates and median ns:",
				       kind ? "sines" : "random", steps[s] * 100);
				for (c = 0; c < 8; c++) {
					if (!cn[c])
						continue;
					qsort(cv[c], (size_t)cn[c], sizeof(int64_t), cmp_i64);
					printf(" [%s %d: %lld]", cname[c], cn[c],
					       (long long)cv[c][cn[c] / 2]);
				}
				printf("\n");
			}
			/* the cold query on its own pass (as for the curves:
			 * not interleaved at the same point) */
			for (k = 0; k < NSSTEP; k++) {
				int64_t x = now_ns();
				px_dist_query(ref, q[k], &g);
				tg[k] = now_ns() - x;
				if (fabs(ds[k] - g.dist) > 1e-9 * (size + g.dist))
					wrong++;
			}
			px_strack_get_stats(t, &b);
			if (cold > 0)
				qsort(tc, (size_t)cold, sizeof(tc[0]), cmp_i64);
			if (getenv("BENCH_TRACK_GOV"))
				printf("  gov: tracked %.0f ns, cold %.0f ns, cold updates %ld (median %lld ns), entered %llu, left %llu\n",
				       b.tracked_ns, b.cold_ns, cold,
				       cold > 0 ? (long long)tc[cold / 2] : 0LL,
				       (unsigned long long)(b.cold_entered - a.cold_entered),
				       (unsigned long long)(b.cold_left - a.cold_left));
			{
				/* the work's worst case: each update's least time
				 * over this run and two more (the same states:
				 * work repeats, interrupts rarely do) */
				int rr;
				for (k = 0; k < NSSTEP; k++) {
					tw[k] = tt[k];
					tgw[k] = tg[k];
				}
				for (rr = 0; rr < 2; rr++) {
					px__gov_copy(px__strack_gov(t), &gsave);
					rclock_replay();
					px_strack_reset(t, q[0], &r);
					for (k = 0; k < NSSTEP; k++) {
						int64_t x = now_ns();
						px_strack_update(t, q[k], &r);
						x = now_ns() - x;
						if (x < tw[k])
							tw[k] = x;
					}
					/* the cold query's by the same measure */
					for (k = 0; k < NSSTEP; k++) {
						int64_t x = now_ns();
						px_dist_query(ref, q[k], &g);
						x = now_ns() - x;
						if (x < tgw[k])
							tgw[k] = x;
					}
				}
				miss = rclock_done();
				px__strack_set_clock(t, NULL, NULL);
				if (miss)
					printf("  (the cold switch's replay diverged %ld "
					       "times: the work's worst compares different "
					       "decisions)\n", miss);
				row[kind][s].cwmax = 0;
				for (k = 0; k < NSSTEP; k++)
					if (tgw[k] > row[kind][s].cwmax)
						row[kind][s].cwmax = tgw[k];
				row[kind][s].wmax = 0;
				for (k = 0; k < NSSTEP; k++)
					if (tw[k] > row[kind][s].wmax) {
						row[kind][s].wmax = tw[k];
						kw = k;
					}
				memcpy(tsort, tw, sizeof(tsort));
				qsort(tsort, NSSTEP, sizeof(tsort[0]), cmp_i64);
				row[kind][s].med3 = tsort[NSSTEP / 2];
				row[kind][s].p99_3 = tsort[NSSTEP * 99 / 100];
				memcpy(tsort, tgw, sizeof(tsort));
				qsort(tsort, NSSTEP, sizeof(tsort[0]), cmp_i64);
				row[kind][s].cold_med3 = tsort[NSSTEP / 2];
				row[kind][s].cold_p99_3 = tsort[NSSTEP * 99 / 100];
				if (worst_env && kw >= 0)
					printf("  (worst update %d: %.1f us, cells solved %d, "
					       "cell tests %d, source %d)\n", kw,
					       row[kind][s].wmax / 1e3, sw_solved[kw],
					       sw_tests[kw], sw_src[kw]);
			}
			/* the same path again, counting instructions (the
			 * tracker restarts from the same state) */
			px_strack_reset(t, q[0], &r);
			for (k = 0; k < NSSTEP; k++) {
				int64_t x = ins_read();
				px_strack_update(t, q[k], &r);
				it[k] = ins_read() - x - ins0;
			}
			for (k = 0; k < NSSTEP; k++) {
				int64_t x = ins_read();
				px_dist_query(ref, q[k], &g);
				ig[k] = ins_read() - x - ins0;
			}
			/* the whole path as one block, tracked then cold (as
			 * for the curves) */
			{
				int64_t x;
				px_strack_reset(t, q[0], &r);
				x = now_ns();
				for (k = 0; k < NSSTEP; k++)
					px_strack_update(t, q[k], &r);
				bmean = (double)(now_ns() - x) / NSSTEP;
				x = now_ns();
				for (k = 0; k < NSSTEP; k++)
					px_dist_query(ref, q[k], &g);
				cmean = (double)(now_ns() - x) / NSSTEP;
			}
			qsort(tt, NSSTEP, sizeof(tt[0]), cmp_i64);
			qsort(tg, NSSTEP, sizeof(tg[0]), cmp_i64);
			qsort(it, NSSTEP, sizeof(it[0]), cmp_i64);
			qsort(ig, NSSTEP, sizeof(ig[0]), cmp_i64);
			row[kind][s].med = tt[NSSTEP / 2];
			row[kind][s].p999 = tt[NSSTEP * 999 / 1000];
			row[kind][s].max = tt[NSSTEP - 1];
			row[kind][s].cold_med = tg[NSSTEP / 2];
			row[kind][s].p99 = tt[NSSTEP * 99 / 100];
			row[kind][s].cold_p99 = tg[NSSTEP * 99 / 100];
			row[kind][s].ins_med = ins_fd >= 0 ? it[NSSTEP / 2] : -1;
			row[kind][s].cold_ins_med = ins_fd >= 0 ? ig[NSSTEP / 2] : -1;
			row[kind][s].ins_max = ins_fd >= 0 ? it[NSSTEP - 1] : -1;
			row[kind][s].cold_ins_max = ins_fd >= 0 ? ig[NSSTEP - 1] : -1;
			row[kind][s].wrong = wrong;
			row[kind][s].net = tt[NSSTEP / 2] > timer_ns
						   ? (double)(tg[NSSTEP / 2] - timer_ns) /
							     (double)(tt[NSSTEP / 2] - timer_ns)
						   : 0.0;
			row[kind][s].bat = cmean / bmean;
			printf("  %-8s %-7g %8lld %8lld %8lld %8lld | %8lld %8lld | %6.1f | "
			       "%5ld %7.2f %6.2f %5.1f | %5.1f %8lld %8lld %6.1f | "
			       "%5.2f %5.1f | %6.0f %6.0f %5.1f\n",
			       kind ? "sines" : "random", steps[s] * 100.0,
			       (long long)tt[NSSTEP / 2], (long long)tt[NSSTEP * 99 / 100],
			       (long long)tt[NSSTEP * 999 / 1000],
			       (long long)tt[NSSTEP - 1], (long long)tg[NSSTEP / 2],
			       (long long)tg[NSSTEP * 99 / 100],
			       (double)tg[NSSTEP / 2] / (double)(tt[NSSTEP / 2] ? tt[NSSTEP / 2] : 1),
			       wrong,
			       (double)(b.cell_solves - a.cell_solves) / NSSTEP,
			       (double)(b.box_tests - a.box_tests) / NSSTEP,
			       ncrit ? (double)crit / ncrit : 0.0, 100.0 * glob / NSSTEP,
			       (long long)row[kind][s].ins_med,
			       (long long)row[kind][s].cold_ins_med,
			       row[kind][s].ins_med > 0
				       ? (double)row[kind][s].cold_ins_med / row[kind][s].ins_med
				       : 0.0,
			       (double)(b.hot - a.hot) / NSSTEP, row[kind][s].net,
			       bmean, cmean, row[kind][s].bat);
		}
	{
		/* per step size: medians of both paths and their ratios;
		 * then the targets, judged on these figures (met at
		 * a step size when met on both paths) */
		int med_ok[4], max_ok[4], ratio_ok[4], iratio_ok[4], wmax_ok[4];
		int net_ok[4], bat_ok[4], m3_ok[4];
		char lm[64], lx[64], lr[64], li[64], lw[64], ln[64], lb[64], l3[64];
		long wrong = 0;
		int64_t worst_max = 0, worst_p999 = 0, worst_w = 0, worst_cw = 0;
		printf("  summary %s (random / sines):\n", name);
		for (s = 0; s < 4; s++) {
			double r0 = (double)row[0][s].cold_med / (double)(row[0][s].med ? row[0][s].med : 1);
			double r1 = (double)row[1][s].cold_med / (double)(row[1][s].med ? row[1][s].med : 1);
			double i0 = row[0][s].ins_med > 0 ? (double)row[0][s].cold_ins_med / row[0][s].ins_med : 0.0;
			double i1 = row[1][s].ins_med > 0 ? (double)row[1][s].cold_ins_med / row[1][s].ins_med : 0.0;
			double m0 = row[0][s].med3 > 0 ? (double)row[0][s].cold_med3 / row[0][s].med3 : 0.0;
			double m1 = row[1][s].med3 > 0 ? (double)row[1][s].cold_med3 / row[1][s].med3 : 0.0;
			printf("    step %-5g %%: median %6lld / %6lld ns, ratio %5.1f / %5.1f; "
			       "median instructions %7lld / %7lld, ratio %5.1f / %5.1f; "
			       "p99.9 %7lld / %7lld ns, max %8lld / %8lld ns; max "
			       "instructions %7lld / %7lld (cold query %7lld / %7lld); "
			       "least-of-3 medians %6lld / %6lld ns against the cold "
			       "query's %6lld / %6lld, ratio %5.1f / %5.1f\n",
			       steps[s] * 100.0, (long long)row[0][s].med, (long long)row[1][s].med,
			       r0, r1, (long long)row[0][s].ins_med, (long long)row[1][s].ins_med,
			       i0, i1, (long long)row[0][s].p999, (long long)row[1][s].p999,
			       (long long)row[0][s].max, (long long)row[1][s].max,
			       (long long)row[0][s].ins_max, (long long)row[1][s].ins_max,
			       (long long)row[0][s].cold_ins_max, (long long)row[1][s].cold_ins_max,
			       (long long)row[0][s].med3, (long long)row[1][s].med3,
			       (long long)row[0][s].cold_med3, (long long)row[1][s].cold_med3,
			       m0, m1);
			med_ok[s] = row[0][s].med <= 1500 && row[1][s].med <= 1500;
			max_ok[s] = row[0][s].max <= 20000 && row[1][s].max <= 20000;
			wmax_ok[s] = row[0][s].wmax <= 20000 && row[1][s].wmax <= 20000;
			ratio_ok[s] = r0 >= 10.0 && r1 >= 10.0;
			iratio_ok[s] = i0 >= 10.0 && i1 >= 10.0;
			net_ok[s] = row[0][s].net >= 10.0 && row[1][s].net >= 10.0;
			bat_ok[s] = row[0][s].bat >= 10.0 && row[1][s].bat >= 10.0;
			m3_ok[s] = m0 >= 10.0 && m1 >= 10.0;
			for (kind = 0; kind < 2; kind++) {
				const struct surf_row *w = &row[kind][s];
				wrong += w->wrong;
				worst_max = w->max > worst_max ? w->max : worst_max;
				worst_p999 = w->p999 > worst_p999 ? w->p999 : worst_p999;
				worst_w = w->wmax > worst_w ? w->wmax : worst_w;
				worst_cw = w->cwmax > worst_cw ? w->cwmax : worst_cw;
			}
		}
		{
			char *out[8] = {lm, lx, lr, li, lw, ln, lb, l3};
			int *ok[8] = {med_ok, max_ok, ratio_ok, iratio_ok, wmax_ok,
				      net_ok, bat_ok, m3_ok}, m;
			for (m = 0; m < 8; m++)
				step_list(out[m], ok[m], steps);
		}
		printf("  targets %s, steps (%%) where met on both paths: median <= "
		       "1.5 us: %s; max <= 20 us: %s (raw max %.1f us, p99.9 %.1f us: "
		       "interrupts and other load on this machine are in the raw "
		       "max), %s by the work (worst update's least of 3 runs, "
		       "%.1f us; the cold query's the same way %.1f us); >= 10x "
		       "the cold query: %s by time, %s by "
		       "instructions, %s by medians net of the clock, %s by block "
		       "means, %s by least-of-3 medians; zero wrong: %s (%ld)\n",
		       name, lm, lx, worst_max / 1e3, worst_p999 / 1e3, lw, worst_w / 1e3,
		       worst_cw / 1e3, lr,
		       li, ln, lb, l3, wrong == 0 ? "MET" : "NOT MET", wrong);
		never_slower(name, row, steps);
	}
	{
		struct px_strack *tv = NULL;
		struct px_strack_opts o;
		struct px_strack_stats st;
		struct px_strack_result r;
		px_strack_opts_default(&o);
		o.verify_every = 1;
		if (px_strack_create(NULL, 0, ss, ns, &o, &tv) == PX_OK) {
			make_path(q, NSSTEP, 0, box, 1e-2 * size);
			for (k = 0; k < NSSTEP; k++)
				px_strack_update(tv, q[k], &r);
			make_path(q, NSSTEP, 1, box, 5e-2 * size);
			for (k = 0; k < NSSTEP; k++)
				px_strack_update(tv, q[k], &r);
			px_strack_get_stats(tv, &st);
			printf("  verification (every tracked update, %llu checks): %llu "
			       "disagreements; over budget %llu, updates answered "
			       "globally while catching up %llu\n",
			       (unsigned long long)st.verifications,
			       (unsigned long long)st.disagreements,
			       (unsigned long long)st.over_budget,
			       (unsigned long long)st.rebuild_updates);
			px_strack_free(tv);
		}
	}
	px_strack_free(t);
	px_dist_model_free(ref);
}

/* ---- B-rep models: tracked streams against the cold query ---- */

#define BREP_N 5000

/* Median, p99 and max of t[0..n) (sorted here). */
static void pct3(int64_t *t, int n, int64_t out[3])
{
	qsort(t, (size_t)n, sizeof(t[0]), cmp_i64);
	out[0] = t[n / 2];
	out[1] = t[(size_t)n * 99 / 100];
	out[2] = t[n - 1];
}

/*
 * One B-rep part: each path kind at steps of 0.1 % and 1 % of the part's
 * diagonal through its box grown by a fifth, a tracked stream
 * (px_model_stream_query(), cold switch on as in the loop, then off:
 * every answer from the tracker or its global fall-back) and the cold
 * query (px_model_query()) on the same points, each in a pass of its
 * own; wrong counts answers whose distance or side differs from the
 * cold query's.
 */
static void run_brep(const char *name, struct px_model *m)
{
	static const double steps[2] = {0.001, 0.01};
	static px_vec3 q[BREP_N];
	static int64_t tt[BREP_N], tc[BREP_N];
	static struct px_model_result rc[BREP_N];
	px_aabb box = px_model_local_aabb(m);
	double size = px_aabb_diagonal(&box);
	int kind, si, cs, i;
	box = px_aabb_inflate(&box, 0.1 * size);
	for (kind = 0; kind < 2; kind++)
		for (si = 0; si < 2; si++) {
			int64_t pc[3];
			make_path(q, BREP_N, kind, box, steps[si] * size);
			for (i = 0; i < BREP_N; i++) {
				int64_t t0 = now_ns();
				px_model_query(m, q[i], &rc[i]);
				tc[i] = now_ns() - t0;
			}
			pct3(tc, BREP_N, pc);
			for (cs = 1; cs >= 0; cs--) {
				struct px_model_stream_opts o;
				struct px_model_stream_stats st;
				struct px_model_stream *s;
				int64_t pt[3];
				int wrong = 0;
				px_model_stream_opts_default(&o);
				o.cold_switch = cs;
				if (px_model_stream_create(m, &o, &s) != PX_OK) {
					printf("  %-16s no stream\n", name);
					return;
				}
				for (i = 0; i < BREP_N; i++) {
					struct px_model_result r;
					int64_t t0 = now_ns();
					px_model_stream_query(s, q[i], INFINITY, 0, &r, NULL);
					tt[i] = now_ns() - t0;
					wrong += fabs(r.distance - rc[i].distance) >
							 1e-9 * (size + fabs(rc[i].distance)) ||
						 r.inside != rc[i].inside;
				}
				px_model_stream_get_stats(s, &st);
				px_model_stream_free(s);
				pct3(tt, BREP_N, pt);
				printf("  %-16s %-6s %4.1f%% cold_switch %d  tracked %6lld %7lld %8lld"
				       "  cold %6lld %7lld %8lld  ratio %5.2f %5.2f  tracked %5.1f%% "
				       "hot %5.1f%% cold %5.1f%%  wrong %d\n",
				       name, kind ? "sines" : "random", 100.0 * steps[si], cs,
				       (long long)pt[0], (long long)pt[1], (long long)pt[2],
				       (long long)pc[0], (long long)pc[1], (long long)pc[2],
				       (double)pc[0] / (double)pt[0], (double)pc[1] / (double)pt[1],
				       100.0 * (double)st.tracked / (double)st.queries,
				       100.0 * (double)st.hot / (double)st.queries,
				       100.0 * (double)st.cold / (double)st.queries, wrong);
			}
		}
}

/* The parts of tests/support/brep_gen.h and, with OpenCASCADE, the
 * shipped STEP block. */
static void run_breps(void)
{
	struct brep_gen *(*gen[4])(void) = {brep_gen_sheet_hole, brep_gen_cube_hole,
					    brep_gen_freeform, brep_gen_thin_box};
	int k;
	printf("\nB-rep models: px_model_stream_query() vs cold px_model_query() on the "
	       "same points (ns: median, p99, max; ratio = cold / tracked at the median "
	       "and p99; tracked/hot/cold: shares of the stream's answers; wrong: "
	       "answers differing from the cold query's)\n");
	for (k = 0; k < 4; k++) {
		struct brep_gen *g = gen[k]();
		struct px_brep *b;
		struct px_model *m;
		if (px_brep_create(&g->d, NULL, NULL, &b) == PX_OK &&
		    px_model_from_brep(b, &m) == PX_OK) {
			run_brep(g->d.name, m);
			px_model_free(m);
		}
		free(g);
	}
#if PX_HAVE_OCCT
	{
		struct px_model *m;
		char msg[256];
		if (px_model_load("config/examples/parts/filleted_block.step", 0.0, &m, msg,
				  sizeof(msg)) == PX_OK) {
			run_brep("filleted_block", m);
			px_model_free(m);
		} else {
			printf("  filleted_block: %s\n", msg);
		}
	}
#endif
}

int main(void)
{
	struct px_nurbs_curve c[6];
	px_arena_init(&arena, arena_mem, sizeof(arena_mem));
	measure_timer();
	printf("clock: an empty timed region takes %lld ns (median)\n",
	       (long long)timer_ns);
	/* BENCH_TRACK_SURF_ONLY=1: the surface part alone (profiling);
	 * BENCH_TRACK_BREP_ONLY=1: the B-rep models alone */
	if (getenv("BENCH_TRACK_BREP_ONLY"))
		goto breps;
	if (getenv("BENCH_TRACK_SURF_ONLY"))
		goto surfaces;
	printf("px_track: per-update ns vs cold px_dist_query on the same points "
	       "(step in %% of the model diagonal; ratio = cold median / tracked "
	       "median; wrong = answers differing from the global query)\n");
	if (blob(&c[0], 0, 0) == PX_OK)
		run("planar C2 closed (blob)", c, 1);
	if (breaks(&c[1], 0, 0) == PX_OK)
		run("planar open, C1 + C0 breaks", &c[1], 1);
	if (circle(&c[2], 0, 0, 1.5) == PX_OK)
		run("rational circle", &c[2], 1);
	if (knot(&c[3], 0, 0, 0) == PX_OK)
		run("space closed (trefoil)", &c[3], 1);
	blob(&c[0], 0, 0);
	breaks(&c[1], 2.5, 0.5);
	circle(&c[2], 0.5, -2.5, 1.0);
	knot(&c[3], 1.0, 1.0, 1.0);
	run("multi-entity (4 curves)", c, 4);
	printf("px_track targets over %d curve models (every step size and "
	       "path): median <= %d ns in %d, max <= %d us (median of %d runs) "
	       "in %d, >= %.0fx faster than the cold query in %d, zero wrong in "
	       "%d\n",
	       tgt_models, TGT_MED_NS, tgt_med_ok, TGT_MAX_NS / 1000, NRUN,
	       tgt_max_ok, TGT_RATIO, tgt_ratio_ok, tgt_wrong_ok);
	if (getenv("BENCH_TRACK_CURVES_ONLY"))
		return 0;
surfaces:
	{
		struct px_nurbs_surf sf[4];
		printf("\npx_strack: surfaces, same columns (cells/u: cells solved "
		       "per update; tests: cell tests per update; crit: live "
		       "critical points; p999_ns: 99.9th percentile; glob%%: "
		       "updates answered by the global query, over the budget or "
		       "catching up; ins_med / cins_med: median user-space "
		       "instructions of the update / the cold query, iratio their "
		       "ratio: figures independent of the machine's load)\n");
		if (wavy_surf(&sf[0], 4) == PX_OK)
			run_surf("bicubic patch (wavy)", &sf[0], 1);
		if (wavy_surf(&sf[1], 7) == PX_OK)
			run_surf("wavy bicubic, 16 patches", &sf[1], 1);
		if (fold_surf(&sf[2]) == PX_OK)
			run_surf("concave fold", &sf[2], 1);
		if (rational_surf(&sf[3]) == PX_OK)
			run_surf("rational wavy, 16 patches", &sf[3], 1);
	}
breps:
	run_breps();
	return 0;
}
