/*
 * px_tess.h - a model as triangles (or points) for display: meshes as
 * they are, clouds as their points, primitives and NURBS surfaces and
 * B-rep faces tessellated on a parameter grid.
 *
 * What: px_model_tessellate() fills a px_tess with vertices in the
 * model's own frame (metres; px_model_pose() places them) and triangles
 * as vertex index triples. Surfaces are evaluated on a grid of each knot
 * span cut into grid_per_span pieces (at most max_per_dir per direction,
 * at least trimmed_min on a trimmed face);
 * a trimmed B-rep face keeps a triangle only when none of its corners is
 * outside the face's domain (px_trim_contains()), so holes stay open and
 * the trimmed edge is drawn within one grid cell. Clouds have points and
 * no triangles (points_only); a half-space is a square of side
 * halfspace_m about its origin. Display only: nothing here is a distance
 * answer.
 *
 * Memory: allocates the arrays (px_tess_free). Setup only, not RT-safe.
 */
#ifndef PX_TESS_H
#define PX_TESS_H

#include <stddef.h>
#include <stdint.h>

#include "px_base.h"
#include "px_model.h"

#ifdef __cplusplus
extern "C" {
#endif

struct px_tess_opts {
	int grid_per_span;   /* pieces per knot span (default 6) */
	int max_per_dir;     /* grid pieces per direction at most (default 64) */
	int trimmed_min;     /* a trimmed face's pieces per direction at least
			      * (default 48): its edge is drawn within a cell */
	int segments;        /* around a primitive's axis (default 32) */
	double halfspace_m;  /* drawn square's side (default 1) */
	size_t max_vertices; /* refuse more (PX_E_NOSPC); default 2,000,000 */
};

struct px_tess {
	double *xyz;         /* 3 * n_vertices, model frame */
	size_t n_vertices;
	uint32_t *tri;       /* 3 * n_triangles */
	size_t n_triangles;
	int points_only;     /* a cloud: vertices are the points */
};

PX_API void px_tess_opts_default(struct px_tess_opts *o);

/*
 * Tessellate m (o NULL: defaults) into *out (zeroed first; free with
 * px_tess_free(), also after a failure). Returns PX_OK, PX_E_INVAL,
 * PX_E_UNSUPPORTED (a custom model), PX_E_NOSPC (more than
 * max_vertices) or PX_E_NOMEM.
 */
PX_API int px_model_tessellate(const struct px_model *m,
			       const struct px_tess_opts *o,
			       struct px_tess *out);

PX_API void px_tess_free(struct px_tess *t);

#ifdef __cplusplus
}
#endif

#endif
