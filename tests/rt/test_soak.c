/*
 * Soak: the whole stack for many cycles on the virtual clock - the rt/
 * loop, the simulated haptic device (devices/px_sim.h) with random fault
 * windows (drop, delay, duplicate, corrupt, stuck, NaN, unplug), the
 * proxy renderer of control/ against a scene of a mesh, a cloud and two
 * primitives (scene/px_scene.h), random parameter updates through a
 * px_param triple buffer, random compute overruns, NaN outputs and
 * trips. What must hold over the whole run:
 *  - not one heap call after setup (allocation counter);
 *  - no drift: every deadline is start + j * period, and the last one is
 *    exactly (cycles + skipped periods) periods after the first;
 *  - statistics that add up: cycles = on-time + overrun cycles, the
 *    overruns and skipped periods the loop counts equal those the soak
 *    caused, every cycle recorded once in each histogram;
 *  - constant resident memory (/proc/self/statm read at intervals);
 *  - the commanded force never above the limit in force, never NaN, and
 *    zero in safe state; the loop leaves safe state by itself.
 *
 * PX_SOAK_CYCLES sets the length (default 200000, about 10 s of wall
 * time at most here); `make soak` runs 10 million cycles and prints
 * the figures the README quotes.
 */
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "mesh_gen.h"
#include "px_alloc_count.h"
#include "px_arena.h"
#include "px_cloud.h"
#include "px_codec.h"
#include "px_control.h"
#include "px_dev.h"
#include "px_loop.h"
#include "px_mesh.h"
#include "px_param.h"
#include "px_prim.h"
#include "px_sim.h"
#include "px_test.h"
#include "px_scene.h"

#define PERIOD_NS 1000000

struct soak_params {
	double stiffness_n_per_m;
	double max_force_n;
	double static_friction, dynamic_friction;
	uint64_t serial;
};

struct soak {
	struct px_dev *dev;
	struct px_scene *scene;
	struct px_control_query query;
	struct px_control_haptic h;
	struct px_param *param;
	struct px_force_cmd cmd;
	struct px_pose_sample s;
	double max_force_in_force; /* limit of the cycle's params */
	uint64_t param_serial_seen, param_updates_seen;
	/* what the soak caused, to compare with the loop's counts */
	uint64_t overruns, skipped, nan_outputs, trips;
	/* what it saw */
	uint64_t cycles, safe_cycles, contact_cycles, nodev_cycles;
	uint64_t bad_deadline, force_over, force_nan, safe_nonzero;
	int64_t first_deadline, last_deadline;
	uint64_t rng;
	double max_force_seen;
	struct px_loop *loop;
};

/* The cycle's own random stream (xorshift; no libc state, no locks). */
static double cyc_unit(struct soak *S)
{
	S->rng ^= S->rng << 13;
	S->rng ^= S->rng >> 7;
	S->rng ^= S->rng << 17;
	return (double)(S->rng >> 11) * (1.0 / 9007199254740992.0);
}

static int soak_read(struct px_loop *l, const struct px_loop_cycle *c, void *u)
{
	struct soak *S = u;
	int rc;
	(void)l;
	if (S->cycles == 0)
		S->first_deadline = c->deadline_ns;
	if ((c->deadline_ns - S->first_deadline) % PERIOD_NS != 0 ||
	    c->deadline_ns <= S->last_deadline)
		S->bad_deadline++;
	S->last_deadline = c->deadline_ns;
	S->cycles++;
	rc = px_dev_pose_read(S->dev, c->read_ns, &S->s);
	if (rc == PX_E_NODEV) {
		S->nodev_cycles++;
		return rc; /* unplugged: safe state this cycle */
	}
	return PX_OK;
}

static int soak_compute(struct px_loop *l, const struct px_loop_cycle *c,
			void *u)
{
	struct soak *S = u;
	struct px_control_haptic_out out;
	const struct soak_params *p;
	int fresh = 0, rc;
	double r;

	p = px_param_read(S->param, &fresh);
	if (fresh || p->serial != S->param_serial_seen) {
		S->h.p.stiffness_n_per_m = p->stiffness_n_per_m;
		S->h.p.max_force_n = p->max_force_n;
		S->h.p.static_friction = p->static_friction;
		S->h.p.dynamic_friction = p->dynamic_friction;
		S->param_serial_seen = p->serial;
		S->param_updates_seen++;
	}
	S->max_force_in_force = p->max_force_n;
	if (S->s.valid) {
		rc = px_control_haptic_step(&S->h, &S->query, S->s.pos_m,
					    &S->s.vel_m_s, &out);
		if (rc != PX_OK)
			return rc;
		S->cmd.force_n[0] = out.force_n.x;
		S->cmd.force_n[1] = out.force_n.y;
		S->cmd.force_n[2] = out.force_n.z;
		S->contact_cycles += out.contact;
	} else {
		S->cmd.force_n[0] = S->cmd.force_n[1] = S->cmd.force_n[2] = 0.0;
	}
	S->cmd.enable = 1;

	/* loop-level faults */
	r = cyc_unit(S);
	if (r < 2e-4) {
		/* a slow compute: 1.2 .. 4.7 periods, never a whole multiple */
		int64_t x = (int64_t)(PERIOD_NS * (1.2 + 3.5 * cyc_unit(S))) | 1;
		px_loop_vclock_advance(l, x);
		S->overruns++;
		S->skipped += (uint64_t)((x - 1) / PERIOD_NS);
	} else if (r < 2.5e-4) {
		S->cmd.force_n[1] = NAN; /* the loop must catch it */
		S->nan_outputs++;
	} else if (r < 2.7e-4) {
		px_loop_trip(l);
		S->trips++;
	} else if (r < 0.05) {
		/* ordinary compute time, well inside the period */
		px_loop_vclock_advance(l, (int64_t)(PERIOD_NS * 0.3 * cyc_unit(S)));
	}
	(void)c;
	return PX_OK;
}

static int soak_write(struct px_loop *l, const struct px_loop_cycle *c,
		      void *u)
{
	struct soak *S = u;
	double f2 = 0.0;
	int i;
	(void)l;
	for (i = 0; i < 3; i++) {
		if (!isfinite(S->cmd.force_n[i]))
			S->force_nan++;
		f2 += S->cmd.force_n[i] * S->cmd.force_n[i];
	}
	if (sqrt(f2) > S->max_force_in_force * (1.0 + 1e-12))
		S->force_over++;
	if (sqrt(f2) > S->max_force_seen)
		S->max_force_seen = sqrt(f2);
	if (c->safe) {
		S->safe_cycles++;
		if (f2 != 0.0 || S->cmd.enable)
			S->safe_nonzero++;
	}
	if (S->force_nan == 0)
		px_dev_force_write(S->dev, &S->cmd, c->write_ns);
	return PX_OK;
}

/* Resident pages, from /proc/self/statm (open/read: no heap). */
static long resident_pages(void)
{
	char b[128];
	int fd = open("/proc/self/statm", O_RDONLY);
	ssize_t n;
	long size = 0, res = -1;
	if (fd < 0)
		return -1;
	n = read(fd, b, sizeof b - 1);
	close(fd);
	if (n <= 0)
		return -1;
	b[n] = '\0';
	if (sscanf(b, "%ld %ld", &size, &res) != 2)
		return -1;
	return res;
}

static uint64_t soak_cycles(void)
{
	const char *s = getenv("PX_SOAK_CYCLES");
	uint64_t n = s && *s ? strtoull(s, NULL, 10) : 0;
	return n ? n : 200000;
}

static void build_world(struct soak *S)
{
	struct gen_mesh g;
	struct px_model *m = NULL;
	struct px_prim sphere = {PX_PRIM_SPHERE, 0.03, 0, 0};
	struct px_prim floor = {PX_PRIM_HALFSPACE, 0, 0, 0};
	const double h[3] = {0.04, 0.02, 0.03};
	double *pts;
	px_pose pose = px_pose_identity();
	int i;

	PX_CHECK_INT_EQ(px_scene_create(8, &S->scene), PX_OK);
	PX_CHECK_INT_EQ(px_prim_model(&sphere, &m), PX_OK);
	pose.t = px_v3(0.0, 0.0, 0.05);
	PX_CHECK_INT_EQ(px_model_set_pose(m, pose), PX_OK);
	PX_CHECK(px_scene_add(S->scene, m, "sphere") >= 0);
	PX_CHECK_INT_EQ(px_prim_model(&floor, &m), PX_OK);
	pose.t = px_v3(0.0, 0.0, -0.02);
	PX_CHECK_INT_EQ(px_model_set_pose(m, pose), PX_OK);
	PX_CHECK(px_scene_add(S->scene, m, "floor") >= 0);
	PX_CHECK_INT_EQ(gen_box(h, 6, &g), 0);
	PX_CHECK_INT_EQ(px_mesh_model(g.xyz, g.nv, g.tri, g.nt, NULL, NULL, &m),
			PX_OK);
	gen_free(&g);
	pose.t = px_v3(0.06, 0.0, 0.06);
	PX_CHECK_INT_EQ(px_model_set_pose(m, pose), PX_OK);
	PX_CHECK(px_scene_add(S->scene, m, "box") >= 0);
	pts = malloc(3 * 2000 * sizeof(double));
	PX_CHECK(pts != NULL);
	for (i = 0; i < 2000; i++) {
		double a = 2.0 * M_PI * i / 2000.0;
		pts[3 * i] = -0.06 + 0.02 * cos(a);
		pts[3 * i + 1] = 0.02 * sin(a);
		pts[3 * i + 2] = 0.05 + 0.01 * sin(7.0 * a);
	}
	PX_CHECK_INT_EQ(px_cloud_model(pts, 2000, 0.004, NULL, &m), PX_OK);
	free(pts);
	PX_CHECK(px_scene_add(S->scene, m, "cloud") >= 0);
	PX_CHECK_INT_EQ(px_scene_control_query(S->scene, &S->query), PX_OK);
}

static void random_faults(struct px_sim_fault *f, size_t n, uint64_t cycles)
{
	static const int kinds[] = {PX_SIM_FAULT_DROP, PX_SIM_FAULT_DELAY,
				    PX_SIM_FAULT_DUPLICATE, PX_SIM_FAULT_CORRUPT,
				    PX_SIM_FAULT_STUCK, PX_SIM_FAULT_NAN,
				    PX_SIM_FAULT_UNPLUG};
	int64_t span = (int64_t)cycles * PERIOD_NS;
	size_t i;
	for (i = 0; i < n; i++) {
		f[i].kind = kinds[i % 7];
		f[i].start_ns = (int64_t)(px_rand_unit() * 0.9 * (double)span);
		f[i].duration_ns = (int64_t)px_rand_range(5e6, 3e8);
		f[i].probability = px_rand_range(0.05, 1.0);
		f[i].delay_ns = (int64_t)px_rand_range(1e6, 3e7);
	}
}

static void test_soak(void)
{
	static unsigned char arena_mem[1 << 14];
	static const struct px_sim_sine sn[3] = {
		{PX_AXIS_X, 0.08, 0.21, 0.0},
		{PX_AXIS_Y, 0.03, 0.37, 1.1},
		{PX_AXIS_Z, 0.05, 0.53, 0.3},
	};
	struct soak S;
	struct px_arena arena;
	struct px_sim_haptic_config hc;
	struct px_dev_config dc;
	struct px_control_haptic_params hp;
	struct px_loop_config lc;
	struct px_loop_status st;
	struct px_stats_snapshot lat, comp, cyc;
	struct px_sim_fault faults[PX_SIM_MAX_FAULTS];
	struct soak_params prm;
	struct px_fault fl;
	char msg[256];
	uint64_t n = soak_cycles(), i, a0, allocs, writes = 0, next_write;
	long rss0 = -1, rss_min = -1, rss_max = -1, rss;
	uint64_t faults_popped = 0;
	struct timespec t0, t1;
	double wall;
	int rc;

	memset(&S, 0, sizeof S);
	S.rng = px_rand_u64() | 1;
	S.last_deadline = INT64_MIN;
	build_world(&S);

	px_sim_haptic_config_default(&hc);
	hc.traj.kind = PX_SIM_TRAJ_SINES;
	hc.traj.center_m[2] = 0.05;
	hc.traj.sines = sn;
	hc.traj.n_sines = 3;
	hc.position_noise_m = 2e-5;
	hc.seed = px_rand_u64();
	random_faults(faults, PX_SIM_MAX_FAULTS, n);
	hc.faults = faults;
	hc.n_faults = PX_SIM_MAX_FAULTS;
	px_dev_config_default(&dc);
	dc.name = "soak";
	dc.stale_timeout_ns = 20000000;
	dc.stuck_limit = 50;
	rc = px_sim_haptic_create(&dc, &hc, &S.dev, msg, sizeof msg);
	PX_CHECK_MSG(rc == PX_OK, "%s", msg);
	PX_CHECK_INT_EQ(px_dev_start(S.dev), PX_OK);

	px_control_haptic_params_default(&hp);
	hp.renderer = PX_CONTROL_PROXY;
	hp.proxy_radius_m = 0.002;
	PX_CHECK_INT_EQ(px_control_haptic_init(&S.h, &hp, PERIOD_NS), PX_OK);

	px_arena_init(&arena, arena_mem, sizeof arena_mem);
	prm.stiffness_n_per_m = hp.stiffness_n_per_m;
	prm.max_force_n = hp.max_force_n;
	prm.static_friction = hp.static_friction;
	prm.dynamic_friction = hp.dynamic_friction;
	prm.serial = 0;
	PX_CHECK_INT_EQ(px_param_create(&arena, sizeof prm, &prm, &S.param), PX_OK);

	px_loop_config_default(&lc);
	lc.clock = PX_LOOP_CLOCK_VIRTUAL;
	lc.vclock_start_ns = 1000000000;
	lc.period_ns = PERIOD_NS;
	lc.rearm_after_ok_cycles = 30;
	lc.hist_bins = 1000;
	lc.read = soak_read;
	lc.compute = soak_compute;
	lc.write = soak_write;
	lc.user = &S;
	PX_CHECK_INT_EQ(px_loop_create(&lc, &S.loop), PX_OK);
	PX_CHECK_INT_EQ(px_dev_attach(S.dev, S.loop), 0);
	PX_CHECK_INT_EQ(px_dev_force_attach(S.dev, S.loop, &S.cmd), PX_OK);

	/* first cycle outside the counted region: first-use work */
	PX_CHECK(px_loop_step(S.loop) >= 0);
	next_write = 1000;
	clock_gettime(CLOCK_MONOTONIC, &t0);
	a0 = px_alloc_region_begin();
	for (i = 1; i < n; i++) {
		if (px_loop_step(S.loop) < 0)
			break;
		if (i == next_write) {
			/* the non-real-time side: a new parameter set */
			prm.stiffness_n_per_m = px_rand_range(100.0, 1500.0);
			prm.max_force_n = px_rand_range(0.5, 8.0);
			prm.static_friction = px_rand_range(0.0, 0.6);
			prm.dynamic_friction = prm.static_friction * px_rand_unit();
			prm.serial++;
			px_param_write(S.param, &prm);
			writes++;
			next_write = i + 1 + (uint64_t)px_rand_int(10, 4000);
		}
		while (px_loop_fault_pop(S.loop, &fl) == PX_OK)
			faults_popped++;
		if (i % (n / 20 + 1) == 0) {
			rss = resident_pages();
			if (i >= n / 10) {
				if (rss0 < 0)
					rss0 = rss_min = rss_max = rss;
				rss_min = rss < rss_min ? rss : rss_min;
				rss_max = rss > rss_max ? rss : rss_max;
			}
		}
	}
	allocs = px_alloc_region_end(a0);
	clock_gettime(CLOCK_MONOTONIC, &t1);
	wall = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);

	PX_CHECK_INT_EQ(i, n);
	PX_CHECK_INT_EQ(allocs, 0);
	px_loop_status(S.loop, &st);
	PX_CHECK_INT_EQ(px_loop_stats(S.loop, PX_LOOP_STAT_LATENCY, &lat), PX_OK);
	PX_CHECK_INT_EQ(px_loop_stats(S.loop, PX_LOOP_STAT_COMPUTE, &comp), PX_OK);
	PX_CHECK_INT_EQ(px_loop_stats(S.loop, PX_LOOP_STAT_CYCLE, &cyc), PX_OK);

	/* statistics add up */
	PX_CHECK_INT_EQ(st.cycles, n);
	PX_CHECK_INT_EQ(S.cycles, n);
	PX_CHECK_INT_EQ(st.overruns, S.overruns);
	PX_CHECK_INT_EQ(st.missed_periods, S.skipped);
	PX_CHECK_INT_EQ(lat.count, n);
	PX_CHECK_INT_EQ(comp.count, n);
	PX_CHECK_INT_EQ(cyc.count, n);
	/* no drift: deadlines on the grid, the last one exactly where the
	 * periods run and skipped put it */
	PX_CHECK_INT_EQ(S.bad_deadline, 0);
	PX_CHECK_INT_EQ(S.first_deadline, lc.vclock_start_ns + PERIOD_NS);
	PX_CHECK_INT_EQ(S.last_deadline - S.first_deadline,
			(int64_t)(st.cycles - 1 + st.missed_periods) * PERIOD_NS);
	PX_CHECK_INT_EQ(lat.max_ns, 0); /* virtual clock: on the deadline */
	/* safety */
	PX_CHECK_INT_EQ(S.force_nan, 0);
	PX_CHECK_INT_EQ(S.force_over, 0);
	PX_CHECK_INT_EQ(S.safe_nonzero, 0);
	PX_CHECK(st.safe_entries >= 1);
	PX_CHECK(S.safe_cycles < n / 2);
	PX_CHECK(S.param_updates_seen >= writes / 2 && writes > 0);
	/* constant resident memory after warm-up */
	PX_CHECK(rss0 > 0);
#if defined(__SANITIZE_ADDRESS__)
	PX_CHECK_MSG(rss_max - rss_min <= 256, "resident %ld..%ld pages",
		     rss_min, rss_max);
#else
	PX_CHECK_MSG(rss_max - rss_min <= 16, "resident %ld..%ld pages",
		     rss_min, rss_max);
#endif

	printf("soak: %llu cycles (%.0f s virtual) in %.1f s wall, %.0f cycles/s\n",
	       (unsigned long long)n, (double)(n + st.missed_periods) * PERIOD_NS * 1e-9,
	       wall, (double)n / wall);
	printf("soak: on-time %llu + overrun %llu = cycles %llu; skipped periods "
	       "%llu; deadline drift 0 ns\n",
	       (unsigned long long)(st.cycles - st.overruns),
	       (unsigned long long)st.overruns, (unsigned long long)st.cycles,
	       (unsigned long long)st.missed_periods);
	printf("soak: safe-state entries %llu (%llu cycles), faults %llu "
	       "(%llu popped, %llu dropped), NaN outputs %llu, trips %llu, "
	       "unplugged cycles %llu\n",
	       (unsigned long long)st.safe_entries,
	       (unsigned long long)S.safe_cycles, (unsigned long long)st.faults,
	       (unsigned long long)faults_popped,
	       (unsigned long long)st.faults_dropped,
	       (unsigned long long)S.nan_outputs, (unsigned long long)S.trips,
	       (unsigned long long)S.nodev_cycles);
	printf("soak: parameter sets %llu written, %llu taken; contact cycles "
	       "%llu; max force %.3f N (never above the limit in force)\n",
	       (unsigned long long)writes,
	       (unsigned long long)S.param_updates_seen,
	       (unsigned long long)S.contact_cycles, S.max_force_seen);
	printf("soak: heap calls after setup %llu; resident memory %ld..%ld KB "
	       "after warm-up\n",
	       (unsigned long long)allocs, rss_min * (sysconf(_SC_PAGESIZE) / 1024),
	       rss_max * (sysconf(_SC_PAGESIZE) / 1024));

	px_loop_free(S.loop);
	px_dev_free(S.dev);
	px_scene_free(S.scene);
}

static const struct px_test tests[] = {
	PX_T(test_soak),
};
PX_TEST_MAIN(tests)
