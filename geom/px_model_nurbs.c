/*
 * NURBS curves and surfaces behind the point-to-model interface: the
 * distance core's certified global query as a px_model.
 */
#include <math.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "px_dist.h"
#include "px_model.h"

/* Queries take a const model and may come from several threads at once;
 * each borrows one of these workspaces without waiting (a query that
 * finds all of them taken fails with PX_E_BUSY rather than blocking). */
#define NURBS_WS 4

struct nurbs_impl {
	struct px_dist_model *dm;
	struct px_dist_ws *ws[NURBS_WS];
	atomic_flag busy[NURBS_WS];
	px_aabb box;
	size_t bytes;
};

static int nurbs_closest(const void *impl, const struct px_model_query *q,
			 struct px_model_result *r)
{
	/* The flags live in the impl, which the interface hands over as
	 * const; taking a workspace is the one write a query makes. */
	struct nurbs_impl *n = (struct nurbs_impl *)(uintptr_t)impl;
	struct px_dist_result d;
	int k, rc;

	for (k = 0; k < NURBS_WS; k++)
		if (!atomic_flag_test_and_set_explicit(&n->busy[k],
						       memory_order_acquire))
			break;
	if (k == NURBS_WS)
		return PX_E_BUSY;
	rc = px_dist_query_ws(n->dm, n->ws[k], q->p, &d);
	atomic_flag_clear_explicit(&n->busy[k], memory_order_release);
	if (rc < 0)
		return rc;
	if (d.dist > q->max_dist)
		return 0;
	memset(r, 0, sizeof(*r));
	r->distance = d.dist;
	r->point = d.point;
	r->direction = d.dir;
	if (d.dist == 0.0) {
		/* On the model: any unit vector satisfies query = point +
		 * 0 * direction; keep the contract of a unit direction. */
		r->direction = px_v3(0.0, 0.0, 1.0);
	}
	r->index = d.entity;
	r->sub = d.piece;
	r->feature = d.kind == PX_DIST_CURVE ? PX_FEATURE_CURVE : PX_FEATURE_SURFACE;
	r->u = d.u;
	r->v = d.v;
	r->is_signed = 0;
	r->inside = 0;
	r->iterations = d.iters;
	r->certified = d.certified;
	r->gap = d.gap;
	return 1;
}

static px_aabb nurbs_aabb(const void *impl)
{
	return ((const struct nurbs_impl *)impl)->box;
}

static size_t nurbs_bytes(const void *impl)
{
	return ((const struct nurbs_impl *)impl)->bytes;
}

static void nurbs_free(void *impl)
{
	struct nurbs_impl *n = impl;
	int k;
	if (!n)
		return;
	for (k = 0; k < NURBS_WS; k++)
		px_dist_ws_free(n->ws[k]);
	px_dist_model_free(n->dm);
	free(n);
}

static const struct px_model_ops nurbs_ops = {
	.name = "nurbs",
	.kind = PX_MODEL_NURBS,
	.closest = nurbs_closest,
	.aabb = nurbs_aabb,
	.memory_bytes = nurbs_bytes,
	.free = nurbs_free,
};

int px_nurbs_model_create(const struct px_nurbs_curve *curves, int n_curves,
			  const struct px_nurbs_surf *surfs, int n_surfs,
			  const struct px_dist_opts *opts, struct px_model **out)
{
	struct nurbs_impl *n;
	struct px_dist_info info;
	int rc, k;

	if (!out)
		return PX_E_INVAL;
	*out = NULL;
	n = calloc(1, sizeof(*n));
	if (!n)
		return PX_E_NOMEM;
	for (k = 0; k < NURBS_WS; k++)
		atomic_flag_clear(&n->busy[k]);
	rc = px_dist_model_create(curves, n_curves, surfs, n_surfs, opts, &n->dm);
	for (k = 0; rc == PX_OK && k < NURBS_WS; k++)
		rc = px_dist_ws_create(n->dm, &n->ws[k]);
	if (rc != PX_OK) {
		nurbs_free(n);
		return rc;
	}
	px_dist_model_info(n->dm, &info);
	n->box = info.bounds;
	n->bytes = sizeof(*n) + info.bytes +
		   NURBS_WS * (size_t)info.n_pieces * (sizeof(uint32_t) + 16);
	return px_model_create(&nurbs_ops, n, PX_MODEL_CAP_EXACT, out);
}
