/*
 * px_cloud_feed.c - the ring of cloud models between a producer thread
 * and the cycle (px_cloud_feed.h). Frame s lives in slot s % n; head
 * counts frames published, used is 1 + the frame the consumer holds
 * (0: none). Frame s may be built once frame s - n (its slot's last) is
 * older than the held one, s - n < used - 1, and not pinned by the
 * reader beside the consumer: pinned != s - n + 1. The pin protocol
 * needs one order of the stores and loads of used and pinned across
 * the three threads, hence sequentially consistent atomics on them.
 */
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "px_cloud.h"
#include "px_cloud_feed.h"

struct slot {
	struct px_model *model;
	int64_t stamp_ns;
	size_t points;
};

struct px_cloud_feed {
	int n;
	size_t max_points;
	double radius_m;
	struct slot slots[PX_CLOUD_FEED_MAX_SLOTS];
	/* producer */
	uint64_t next;          /* frame to publish next */
	int64_t last_stamp;
	_Atomic uint64_t head;  /* frames published */
	_Atomic uint64_t refused;
	/* consumer */
	_Atomic uint64_t used;  /* 1 + frame held, 0 none */
	_Atomic uint64_t taken;
	/* the reader beside the consumer: 1 + frame pinned, 0 none */
	_Atomic uint64_t pinned;
};

int px_cloud_feed_create(int slots, size_t max_points, double radius_m,
			 struct px_cloud_feed **out)
{
	struct px_cloud_feed *f;
	if (!out)
		return PX_E_INVAL;
	*out = NULL;
	if (slots < 3 || slots > PX_CLOUD_FEED_MAX_SLOTS || max_points == 0 ||
	    max_points > PX_CLOUD_MAX_POINTS || !(radius_m >= 0 && radius_m < 1e6))
		return PX_E_RANGE;
	f = calloc(1, sizeof(*f));
	if (!f)
		return PX_E_NOMEM;
	f->n = slots;
	f->max_points = max_points;
	f->radius_m = radius_m;
	f->last_stamp = INT64_MIN;
	atomic_init(&f->head, 0);
	atomic_init(&f->refused, 0);
	atomic_init(&f->used, 0);
	atomic_init(&f->taken, 0);
	atomic_init(&f->pinned, 0);
	*out = f;
	return PX_OK;
}

void px_cloud_feed_free(struct px_cloud_feed *f)
{
	int i;
	if (!f)
		return;
	for (i = 0; i < f->n; i++)
		px_model_free(f->slots[i].model);
	free(f);
}

/* Frame s's slot is free: it never held a frame, or its last frame
 * (s - n) is older than the held one and not pinned. */
static int slot_free(const struct px_cloud_feed *f, uint64_t s, uint64_t used,
		     uint64_t pinned)
{
	uint64_t n = (uint64_t)f->n;
	return s < n || (s + 2 <= used + n && pinned != s - n + 1);
}

int px_cloud_feed_space(const struct px_cloud_feed *f)
{
	uint64_t used, pinned, s;
	int k = 0;
	if (!f)
		return 0;
	used = atomic_load_explicit(&f->used, memory_order_seq_cst);
	pinned = atomic_load_explicit(&f->pinned, memory_order_seq_cst);
	for (s = f->next; k < f->n && slot_free(f, s, used, pinned); s++)
		k++;
	return k;
}

int px_cloud_feed_publish(struct px_cloud_feed *f, const double *xyz, size_t n,
			  int64_t stamp_ns)
{
	static const double far[3] = {0, 0, PX_CLOUD_FEED_FAR_M};
	struct slot *sl;
	struct px_model *m = NULL;
	uint64_t used, pinned;
	int rc;
	if (!f || (n > 0 && !xyz))
		return PX_E_INVAL;
	if (n > f->max_points || stamp_ns < f->last_stamp)
		return PX_E_RANGE;
	used = atomic_load(&f->used);
	pinned = atomic_load(&f->pinned);
	if (!slot_free(f, f->next, used, pinned)) {
		atomic_fetch_add_explicit(&f->refused, 1, memory_order_relaxed);
		return PX_E_AGAIN;
	}
	rc = n ? px_cloud_model(xyz, n, f->radius_m, NULL, &m)
	       : px_cloud_model(far, 1, f->radius_m, NULL, &m);
	if (rc)
		return rc;
	sl = &f->slots[f->next % (uint64_t)f->n];
	px_model_free(sl->model); /* a frame older than the held one */
	sl->model = m;
	sl->stamp_ns = stamp_ns;
	sl->points = n;
	f->last_stamp = stamp_ns;
	f->next++;
	atomic_store_explicit(&f->head, f->next, memory_order_release);
	return PX_OK;
}

int px_cloud_feed_take(struct px_cloud_feed *f, int64_t now_ns,
		       struct px_model **model, int64_t *stamp_ns)
{
	uint64_t head, used, k, lo;
	if (!f)
		return PX_E_INVAL;
	head = atomic_load_explicit(&f->head, memory_order_acquire);
	used = atomic_load_explicit(&f->used, memory_order_relaxed);
	/* frames after the held one, newest first, at most n of them (the
	 * producer never overwrites these) */
	lo = used > 0 ? used : 0;
	if (head > lo + (uint64_t)f->n)
		lo = head - (uint64_t)f->n;
	for (k = head; k > lo; k--) {
		const struct slot *sl = &f->slots[(k - 1) % (uint64_t)f->n];
		if (sl->stamp_ns > now_ns)
			continue;
		atomic_store(&f->used, k); /* seq_cst: see the pin */
		atomic_fetch_add_explicit(&f->taken, 1, memory_order_relaxed);
		if (model)
			*model = sl->model;
		if (stamp_ns)
			*stamp_ns = sl->stamp_ns;
		return 1;
	}
	if (model)
		*model = used ? f->slots[(used - 1) % (uint64_t)f->n].model : NULL;
	if (stamp_ns)
		*stamp_ns = used ? f->slots[(used - 1) % (uint64_t)f->n].stamp_ns : 0;
	return 0;
}

struct px_model *px_cloud_feed_model(const struct px_cloud_feed *f)
{
	uint64_t used;
	if (!f)
		return NULL;
	used = atomic_load_explicit(&f->used, memory_order_relaxed);
	return used ? f->slots[(used - 1) % (uint64_t)f->n].model : NULL;
}

void px_cloud_feed_stats(const struct px_cloud_feed *f, struct px_cloud_feed_stats *out)
{
	uint64_t used;
	if (!out)
		return;
	memset(out, 0, sizeof(*out));
	if (!f)
		return;
	used = atomic_load_explicit(&f->used, memory_order_relaxed);
	out->published = atomic_load_explicit(&f->head, memory_order_relaxed);
	out->taken = atomic_load_explicit(&f->taken, memory_order_relaxed);
	out->refused = atomic_load_explicit(&f->refused, memory_order_relaxed);
	if (used) {
		out->stamp_ns = f->slots[(used - 1) % (uint64_t)f->n].stamp_ns;
		out->points = f->slots[(used - 1) % (uint64_t)f->n].points;
	}
}

struct px_model *px_cloud_feed_pin(struct px_cloud_feed *f, uint64_t *frame)
{
	uint64_t u = 0;
	int k;
	if (frame)
		*frame = 0;
	if (!f)
		return NULL;
	/* the held frame pinned and then seen still held: a producer can
	 * rebuild its slot only after a newer take, whose store of used
	 * comes after this load in the one order, so it sees the pin. A
	 * consumer taking frames faster than this loop turns is not waited
	 * for: the reader gets nothing this time. */
	for (k = 0; k < 64; k++) {
		u = atomic_load(&f->used);
		if (!u)
			return NULL;
		atomic_store(&f->pinned, u);
		if (atomic_load(&f->used) == u)
			break;
	}
	if (k == 64) {
		atomic_store(&f->pinned, 0);
		return NULL;
	}
	if (frame)
		*frame = u;
	return f->slots[(u - 1) % (uint64_t)f->n].model;
}

void px_cloud_feed_unpin(struct px_cloud_feed *f)
{
	if (f)
		atomic_store(&f->pinned, 0);
}
