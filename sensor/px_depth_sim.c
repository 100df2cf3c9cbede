/*
 * px_depth_sim.c - the simulated depth camera (px_depth_sim.h): pinhole
 * rays against a moving box or capsule, Gaussian depth noise, and the
 * thread that feeds its frames to a px_cloud_feed.
 */
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "px_cloud_feed.h"
#include "px_depth_sim.h"

struct px_depth_sim {
	struct px_depth_sim_params p;
	double tan_x, tan_y;
	/* thread */
	pthread_t thread;
	int running;
	atomic_int stop;
	atomic_llong now_ns;
	atomic_llong t0_ns;
	atomic_int have_t0;
	_Atomic uint64_t frames;
	atomic_int error;
	struct px_cloud_feed *feed;
	int64_t lookahead_ns;
	double *xyz;
};

void px_depth_sim_params_default(struct px_depth_sim_params *p)
{
	if (!p)
		return;
	memset(p, 0, sizeof(*p));
	p->kind = PX_DEPTH_SIM_BOX;
	p->camera = px_pose_identity();
	p->width = 64;
	p->height = 48;
	p->fov_x_rad = 1.0;
	p->max_range_m = 4.0;
	p->noise_m = 0.002;
	p->rate_hz = 30.0;
	p->size_m = px_v3(0.1, 0.1, 0.1);
	p->from_m = p->to_m = px_v3(0, 0, 2);
	p->seed = 1;
}

static int params_check(const struct px_depth_sim_params *p)
{
	px_pose cam = p->camera;
	if (p->kind != PX_DEPTH_SIM_BOX && p->kind != PX_DEPTH_SIM_ARM)
		return PX_E_INVAL;
	if (!px_v3_isfinite(p->size_m) || !px_v3_isfinite(p->from_m) ||
	    !px_v3_isfinite(p->to_m) || !isfinite(p->start_s) || !isfinite(p->period_s) ||
	    px_pose_sanitize(&cam) != PX_OK)
		return PX_E_NAN;
	if (p->width < 1 || p->width > PX_DEPTH_SIM_MAX_PIXELS || p->height < 1 ||
	    p->height > PX_DEPTH_SIM_MAX_PIXELS || !(p->fov_x_rad > 0 && p->fov_x_rad < 3) ||
	    !(p->max_range_m > 0 && p->max_range_m < 1e4) ||
	    !(p->noise_m >= 0 && p->noise_m < 1) || !(p->rate_hz >= 0.1 && p->rate_hz <= 1000) ||
	    !(p->start_s >= 0) || !(p->period_s >= 0) || !(p->size_m.x > 0 && p->size_m.y > 0) ||
	    (p->kind == PX_DEPTH_SIM_BOX && !(p->size_m.z > 0)))
		return PX_E_RANGE;
	return PX_OK;
}

int px_depth_sim_create(const struct px_depth_sim_params *p, struct px_depth_sim **out)
{
	struct px_depth_sim *s;
	int rc;
	if (!out)
		return PX_E_INVAL;
	*out = NULL;
	if (!p)
		return PX_E_INVAL;
	rc = params_check(p);
	if (rc)
		return rc;
	s = calloc(1, sizeof(*s));
	if (!s)
		return PX_E_NOMEM;
	s->p = *p;
	px_pose_sanitize(&s->p.camera);
	s->tan_x = tan(0.5 * p->fov_x_rad);
	s->tan_y = s->tan_x * p->height / p->width;
	atomic_init(&s->stop, 0);
	atomic_init(&s->now_ns, 0);
	atomic_init(&s->t0_ns, 0);
	atomic_init(&s->have_t0, 0);
	atomic_init(&s->frames, 0);
	atomic_init(&s->error, 0);
	*out = s;
	return PX_OK;
}

void px_depth_sim_free(struct px_depth_sim *s)
{
	if (!s)
		return;
	px_depth_sim_stop(s);
	free(s);
}

size_t px_depth_sim_max_points(const struct px_depth_sim *s)
{
	return s ? (size_t)s->p.width * (size_t)s->p.height : 0;
}

double px_depth_sim_motion(const struct px_depth_sim *s, double t_s)
{
	double u;
	if (!s || !(t_s >= s->p.start_s))
		return 0.0;
	if (s->p.period_s <= 0)
		return 1.0;
	u = (t_s - s->p.start_s) / s->p.period_s;
	if (u >= 1.0)
		return 0.0;
	return 0.5 - 0.5 * cos(2 * M_PI * u); /* 0 -> 1 -> 0, smooth */
}

/* Ray o + t d (|d| = 1) against the box [lo, hi]: entry t, or -1. */
static double ray_box(px_vec3 o, px_vec3 d, px_vec3 lo, px_vec3 hi)
{
	double t0 = 0, t1 = INFINITY, oo[3] = {o.x, o.y, o.z}, dd[3] = {d.x, d.y, d.z};
	double l[3] = {lo.x, lo.y, lo.z}, h[3] = {hi.x, hi.y, hi.z};
	int k;
	for (k = 0; k < 3; k++) {
		double a, b;
		if (fabs(dd[k]) < 1e-300) {
			if (oo[k] < l[k] || oo[k] > h[k])
				return -1;
			continue;
		}
		a = (l[k] - oo[k]) / dd[k];
		b = (h[k] - oo[k]) / dd[k];
		if (a > b) {
			double t = a;
			a = b;
			b = t;
		}
		t0 = fmax(t0, a);
		t1 = fmin(t1, b);
		if (t0 > t1)
			return -1;
	}
	return t0 > 0 ? t0 : -1;
}

/* Ray o + t d (|d| = 1) against the capsule of axis a..b, radius r:
 * the first hit t, or -1. The cylinder's side, then the end spheres. */
static double ray_capsule(px_vec3 o, px_vec3 d, px_vec3 a, px_vec3 b, double r)
{
	px_vec3 ba = px_v3_sub(b, a), oa = px_v3_sub(o, a), oc;
	double baba = px_v3_dot(ba, ba), bard = px_v3_dot(ba, d), baoa = px_v3_dot(ba, oa);
	double rdoa = px_v3_dot(d, oa), oaoa = px_v3_dot(oa, oa);
	double qa = baba - bard * bard, qb = baba * rdoa - baoa * bard;
	double qc = baba * oaoa - baoa * baoa - r * r * baba, h = qb * qb - qa * qc;
	if (qa > 1e-12 * baba) {
		double t, y;
		if (h < 0)
			return -1; /* misses the infinite cylinder */
		t = (-qb - sqrt(h)) / qa;
		y = baoa + t * bard;
		if (y > 0 && y < baba)
			return t > 0 ? t : -1;
		oc = y <= 0 ? oa : px_v3_sub(o, b);
	} else {
		oc = bard > 0 ? oa : px_v3_sub(o, b); /* along the axis */
	}
	qb = px_v3_dot(d, oc);
	qc = px_v3_dot(oc, oc) - r * r;
	h = qb * qb - qc;
	if (h <= 0)
		return -1;
	h = -qb - sqrt(h);
	return h > 0 ? h : -1;
}

/* splitmix64: a frame's noise from its seed and index */
static uint64_t mix(uint64_t *x)
{
	uint64_t z = (*x += 0x9e3779b97f4a7c15ull);
	z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
	z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
	return z ^ (z >> 31);
}

static double gauss(uint64_t *x)
{
	double u1 = ((double)(mix(x) >> 11) + 0.5) * 0x1p-53;
	double u2 = (double)(mix(x) >> 11) * 0x1p-53;
	return sqrt(-2 * log(u1)) * cos(2 * M_PI * u2);
}

int px_depth_sim_capture(const struct px_depth_sim *s, double t_s, uint64_t k,
			 double *xyz, size_t cap, size_t *n)
{
	const struct px_depth_sim_params *p;
	double w;
	px_vec3 lo = px_v3(0, 0, 0), hi = lo, a = lo, b = lo;
	uint64_t rng;
	int i, j;
	if (!s || !xyz || !n || !isfinite(t_s))
		return PX_E_INVAL;
	*n = 0;
	if (cap < px_depth_sim_max_points(s))
		return PX_E_NOSPC;
	p = &s->p;
	w = px_depth_sim_motion(s, t_s);
	if (p->kind == PX_DEPTH_SIM_BOX) {
		px_vec3 c = px_v3_lerp(p->from_m, p->to_m, w);
		lo = px_v3_sub(c, p->size_m);
		hi = px_v3_add(c, p->size_m);
	} else {
		double ang = p->to_m.x + w * (p->to_m.y - p->to_m.x);
		a = p->from_m;
		b = px_v3_add(a, px_v3(p->size_m.x * cos(ang), p->size_m.x * sin(ang), 0));
	}
	rng = p->seed ^ (k * 0xd1b54a32d192ed03ull);
	for (j = 0; j < p->height; j++)
		for (i = 0; i < p->width; i++) {
			px_vec3 dc = px_v3(((i + 0.5) / p->width * 2 - 1) * s->tan_x,
					   ((j + 0.5) / p->height * 2 - 1) * s->tan_y, 1.0);
			px_vec3 d = px_pose_transform_vector(p->camera,
							     px_v3_scale(dc, 1.0 / px_v3_norm(dc)));
			double t = p->kind == PX_DEPTH_SIM_BOX
					   ? ray_box(p->camera.t, d, lo, hi)
					   : ray_capsule(p->camera.t, d, a, b, p->size_m.y);
			double noise = p->noise_m > 0 ? p->noise_m * gauss(&rng) : 0.0;
			px_vec3 q;
			if (t <= 0 || t > p->max_range_m)
				continue;
			q = px_v3_add(p->camera.t, px_v3_scale(d, t + noise));
			xyz[3 * *n] = q.x;
			xyz[3 * *n + 1] = q.y;
			xyz[3 * *n + 2] = q.z;
			(*n)++;
		}
	return PX_OK;
}

/* ---- the thread ------------------------------------------------------------ */

void px_depth_sim_clock(struct px_depth_sim *s, int64_t now_ns)
{
	if (!s)
		return;
	if (!atomic_load_explicit(&s->have_t0, memory_order_relaxed)) {
		atomic_store_explicit(&s->t0_ns, now_ns, memory_order_relaxed);
		atomic_store_explicit(&s->have_t0, 1, memory_order_release);
	}
	atomic_store_explicit(&s->now_ns, now_ns, memory_order_release);
}

int64_t px_depth_sim_stamp(const struct px_depth_sim *s, uint64_t k)
{
	if (!s || !atomic_load_explicit(&s->have_t0, memory_order_acquire))
		return 0;
	return atomic_load_explicit(&s->t0_ns, memory_order_relaxed) +
	       (int64_t)llround((double)k * 1e9 / s->p.rate_hz);
}

uint64_t px_depth_sim_frames(const struct px_depth_sim *s)
{
	return s ? atomic_load_explicit(&s->frames, memory_order_relaxed) : 0;
}

int px_depth_sim_error(const struct px_depth_sim *s)
{
	return s ? atomic_load_explicit(&s->error, memory_order_relaxed) : PX_E_INVAL;
}

static void nap(void)
{
	struct timespec ts = {0, 200000};
	nanosleep(&ts, NULL);
}

static void *run(void *arg)
{
	struct px_depth_sim *s = arg;
	uint64_t k = 0;
	size_t cap = px_depth_sim_max_points(s), n;
	while (!atomic_load_explicit(&s->stop, memory_order_acquire)) {
		int64_t now, stamp;
		int rc;
		if (!atomic_load_explicit(&s->have_t0, memory_order_acquire)) {
			nap();
			continue;
		}
		now = atomic_load_explicit(&s->now_ns, memory_order_acquire);
		stamp = px_depth_sim_stamp(s, k);
		if (stamp > now + s->lookahead_ns || px_cloud_feed_space(s->feed) == 0) {
			nap();
			continue;
		}
		rc = px_depth_sim_capture(s, (double)k / s->p.rate_hz, k, s->xyz, cap, &n);
		if (rc == PX_OK)
			rc = px_cloud_feed_publish(s->feed, s->xyz, n, stamp);
		if (rc == PX_E_AGAIN)
			continue;
		if (rc != PX_OK)
			atomic_store_explicit(&s->error, rc, memory_order_relaxed);
		k++;
		atomic_fetch_add_explicit(&s->frames, 1, memory_order_relaxed);
	}
	return NULL;
}

int px_depth_sim_start(struct px_depth_sim *s, struct px_cloud_feed *f, int64_t lookahead_ns)
{
	int rc;
	if (!s || !f || lookahead_ns < 0)
		return PX_E_INVAL;
	if (s->running)
		return PX_E_STATE;
	s->xyz = malloc(3 * px_depth_sim_max_points(s) * sizeof(*s->xyz));
	if (!s->xyz)
		return PX_E_NOMEM;
	s->feed = f;
	s->lookahead_ns = lookahead_ns;
	atomic_store(&s->stop, 0);
	rc = pthread_create(&s->thread, NULL, run, s);
	if (rc) {
		free(s->xyz);
		s->xyz = NULL;
		return rc == EAGAIN ? PX_E_NOMEM : PX_E_IO;
	}
	s->running = 1;
	return PX_OK;
}

void px_depth_sim_stop(struct px_depth_sim *s)
{
	if (!s || !s->running)
		return;
	atomic_store_explicit(&s->stop, 1, memory_order_release);
	pthread_join(s->thread, NULL);
	s->running = 0;
	free(s->xyz);
	s->xyz = NULL;
}
