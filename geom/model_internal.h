/*
 * model_internal.h - private declarations shared by the model sources of
 * geom/ (meshes, clouds, file import). Not installed, not API.
 */
#ifndef PX_MODEL_INTERNAL_H
#define PX_MODEL_INTERNAL_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

#include "px_math.h"

/*
 * Read a mesh or point file with the Open Asset Import Library: all
 * meshes of the scene with their node transforms applied (a mesh that no
 * node references, as for a faceless PLY, is taken as it is), polygons
 * triangulated. want_tri: collect triangles (other primitives are
 * skipped and counted in *n_skipped); else only vertices. On success
 * *xyz (3 doubles per vertex) and *tri (3 per triangle, NULL when
 * !want_tri) are malloc'ed and owned by the caller. On failure msg holds
 * "<path>: <reason>". The file is read once, at most
 * PX_FILE_MODEL_MAX_BYTES, and the importer parses those bytes. PLY
 * files are checked against their header first (x, y, z required); a
 * PLY read for points (!want_tri) is read exactly by that check, without
 * the importer; a mesh (PLY, ASCII STL, OBJ) whose coordinates would
 * move by more than 1e-5 of its extent in the importer's single
 * precision is PX_E_RANGE.
 * Returns PX_OK, PX_E_INVAL, PX_E_NOTFOUND, PX_E_IO, PX_E_PARSE,
 * PX_E_RANGE, PX_E_NOMEM, PX_E_OVERFLOW. Setup only.
 */
int px__import_file(const char *path, int want_tri, double **xyz,
		    size_t *nv, uint32_t **tri, size_t *nt, size_t *n_skipped,
		    char *msg, size_t msg_cap);

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

/* Point cloud hint grid (px_cloud.c), for tests: the input index of the
 * point the grid names for p, and the centre of p's cell (clamped to the
 * grid); -1 when m is not a cloud or has no grid. RT-safe. */
struct px_model;
long px__cloud_grid_hint(const struct px_model *m, px_vec3 p, px_vec3 *centre);

/* Rewrite msg (cap bytes, NUL-terminated) as "<path>: <msg>", cut to
 * fit. Setup only. */
void px__prefix_path(char *msg, size_t cap, const char *path);

/* Farthest a query point may lie from a model's box (model units): the
 * queries work with squared distances, which overflow past about 1e154. */
#define PX__MAX_QUERY_REACH 1e150

/* 1 when p lies farther than PX__MAX_QUERY_REACH from box b along some
 * axis (an empty or infinite box never makes a point too far).
 * RT-safe. */
static inline int px__too_far(const px_aabb *b, px_vec3 p)
{
	return b->min.x - p.x > PX__MAX_QUERY_REACH ||
	       p.x - b->max.x > PX__MAX_QUERY_REACH ||
	       b->min.y - p.y > PX__MAX_QUERY_REACH ||
	       p.y - b->max.y > PX__MAX_QUERY_REACH ||
	       b->min.z - p.z > PX__MAX_QUERY_REACH ||
	       p.z - b->max.z > PX__MAX_QUERY_REACH;
}

#endif
