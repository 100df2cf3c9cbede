/*
 * track_hooks.c - curve tracker (px_track.h): the test and bench hooks
 * (track_hooks.h). The layout and the shared declarations are in
 * track_internal.h.
 */
#include "track_internal.h"

/* Only in the test build (-DPX_TEST_HOOKS): the shipped library has no
 * way in to switch its proofs off. */
#ifdef PX_TEST_HOOKS

void px__track_set_fault(struct px_track *t, int fault)
{
	if (t) {
		t->fault = fault;
		t->heap_ok = 0; /* radii of the new regime */
		t->hot_ent = -1;
	}
}

void px__track_set_clock(struct px_track *t, int64_t (*fn)(void *), void *ctx)
{
	if (t)
		px__gov_set_clock(&t->gov, fn, ctx);
}

struct px_gov *px__track_gov(struct px_track *t)
{
	return t ? &t->gov : NULL;
}

double px__track_leaf_cert(const struct px_track *t, int leaf, px_vec3 p,
			   int which, int *ent, double *u0, double *u1,
			   unsigned *flags)
{
	const struct leaf *l;
	if (!t || leaf < 0 || leaf >= t->n_leaves)
		return -1.0;
	l = &t->leaf[leaf];
	*ent = l->ent;
	*u0 = l->u0;
	*u1 = l->u1;
	*flags = (l->flags & (LF_CUSP0 | LF_CUSP1)) ? 1u : 0u;
	if (which == 2) {
		/* the radius leaf_test() gives at the end of a step of
		 * length 0: the larger of the whole-leaf one and the one
		 * the piecewise proof gives (0 when that fails) */
		double rf = 0.0, rr = px__tk_leaf_radius(t, l, p);
		if (px__tk_leaf_event(t, l, p, p, &rf))
			rf = 0.0;
		if (t->fault & 128)
			rf *= 4.0;
		return rf > rr ? rf : rr;
	}
	return which ? px__tk_leaf_end_radius(t, l, p) : px__tk_leaf_radius(t, l, p);
}

#endif /* PX_TEST_HOOKS */
