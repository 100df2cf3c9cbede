/*
 * model_internal.h - private helpers of the model sources of geom/ (the
 * hierarchy builds of meshes, clouds and scenes; messages). Not installed,
 * not API.
 */
#ifndef PX_MODEL_INTERNAL_H
#define PX_MODEL_INTERNAL_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

#include "px_math.h"

/* A number no other model created in this process has (counted from
 * 1 at creation): tells a model from one allocated later at the same
 * address, for state kept across calls. 0 for NULL. RT-safe. */
struct px_model;
unsigned long px__model_serial(const struct px_model *m);

/*
 * Quickselect for the hierarchies (mesh, cloud, scene): reorder the index
 * array a[0..n) so that a[k] holds the element whose key[3 * a[k] + axis]
 * is the k-th smallest, smaller keys before it and larger after. Setup.
 */
void px__select_k(uint32_t *a, long n, long k, const double *key, int axis);

/* Bounds lo, hi of the keys (3 doubles each, finite) of the n elements
 * perm[0..n). Setup only (hierarchy builds). */
static inline void px__key_bounds(const uint32_t *perm, size_t n,
				  const double *key, double lo[3], double hi[3])
{
	size_t i;
	int k;
	for (k = 0; k < 3; k++) {
		lo[k] = INFINITY;
		hi[k] = -INFINITY;
	}
	/* compares, not fmin/fmax (library calls): the keys are finite */
	for (i = 0; i < n; i++)
		for (k = 0; k < 3; k++) {
			double x = key[3 * (size_t)perm[i] + k];
			lo[k] = x < lo[k] ? x : lo[k];
			hi[k] = x > hi[k] ? x : hi[k];
		}
}

/* Median split of perm[0..n) along the widest axis of the key bounds
 * lo, hi: afterwards the first n / 2 elements have keys at most those of
 * the rest. Returns n / 2. Setup only. */
static inline size_t px__median_split(uint32_t *perm, size_t n, const double *key,
				      const double lo[3], const double hi[3])
{
	int k, axis = 0;
	for (k = 1; k < 3; k++)
		if (hi[k] - lo[k] > hi[axis] - lo[axis])
			axis = k;
	px__select_k(perm, (long)n, (long)(n / 2), key, axis);
	return n / 2;
}

/* Rewrite msg (cap bytes, NUL-terminated) as "<path>: <msg>", cut to
 * fit. Setup only. */
void px__prefix_path(char *msg, size_t cap, const char *path);

/* The distance core's model behind a model from px_nurbs_model_create()
 * (read only: its pieces' control nets, for model-to-model descents,
 * geom/pair/pair_nurbs.c); NULL for any other model. @note RT-safe. */
struct px_model;
struct px_dist_model;
const struct px_dist_model *px__nurbs_model_dist(const struct px_model *m);

#endif
