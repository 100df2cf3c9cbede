/*
 * px_cloud.h - point clouds: nearest point through a k-d tree built at
 * setup, optionally with a radius per point (a union of balls), loading
 * from PLY and XYZ/CSV text.
 *
 * Scanned environments arrive as point clouds. Setup copies the points
 * and builds a k-d tree by median splits on the widest axis (leaves of
 * at most 8 points), each node keeping the tight boxes of its children,
 * stored in single precision rounded outwards and collapsed to four
 * children per node (the mesh hierarchy's layout); a query descends
 * nearer child first and prunes every box farther than the best point so
 * far (boxes compared in single precision with a slack that keeps them
 * lower bounds, points in double). Each subtree also keeps the slab
 * between two parallel planes holding its points (normal near that of
 * the points' best-fit plane), and a child is pruned by the larger of
 * its box and slab bounds: scans sample surfaces, so a subtree is a thin
 * patch, and seen face-on its slab prunes where its box would not (on
 * the benchmark's 100k-point sphere, a fifth of the instructions). Cold queries (no hint) start from a
 * hint grid built at setup, as for meshes: one cell per 8 points (at
 * most 64^3), each holding the point nearest to its centre, whose
 * distance is a first upper bound. The answer is the exact nearest
 * point (ties broken arbitrarily).
 *
 * With radius r > 0 every point stands for a ball: the distance is
 * |p - x| - r for the nearest centre x and the closest point lies on
 * that ball; it is signed (negative inside a ball). Outside all balls
 * this is the exact distance to their union; inside, it is the depth
 * into the nearest ball's centre, a conservative penetration value.
 * With r = 0 distances are unsigned.
 *
 * Clouds without a radius support the coherence cache
 * (px_model_query_cached); with a radius, cached queries fall back to
 * hint-coherent ones.
 *
 * Results (px_model_result): index = point (input order), feature =
 * PX_FEATURE_POINT, u = v = 0, iterations = nodes and points visited,
 * certified = 1 (exact).
 *
 * Memory and real-time rules: building allocates (setup only), about
 * 45 bytes per point (points, index maps, hierarchy, slabs, grid); queries are
 * RT-safe (no heap, fixed stack of 3 PX_CLOUD_MAX_DEPTH + 4 entries on
 * the call stack).
 */
#ifndef PX_CLOUD_H
#define PX_CLOUD_H

#include <stddef.h>

#include "px_base.h"
#include "px_math.h"
#include "px_model.h"

#ifdef __cplusplus
extern "C" {
#endif

#define PX_CLOUD_MAX_DEPTH 48
#define PX_CLOUD_MAX_POINTS ((size_t)1 << 31)
/* Largest |coordinate| and radius a cloud takes (model units): the
 * extent, the hint grid and the squared distances of every query within
 * the models' reach (px_model.h, 1e150 beyond the box) stay finite. */
#define PX_CLOUD_MAX_COORD 1e150

struct px_cloud_report {
	size_t n_points;
	long line;          /* text files: line of the first problem, else -1 */
	char message[256];  /* "" when everything is fine */
};

/*
 * Build a cloud model from n points (xyz, 3 doubles each; copied) with
 * ball radius radius_m >= 0. rep may be NULL.
 * Returns PX_OK; PX_E_INVAL (NULL, n = 0), PX_E_RANGE (radius negative,
 * not finite or beyond PX_CLOUD_MAX_COORD, a coordinate beyond
 * +-PX_CLOUD_MAX_COORD, too many points), PX_E_NAN (a non-finite
 * coordinate: rep->message names the point), PX_E_NOMEM. Setup only.
 */
PX_API int px_cloud_model(const double *xyz, size_t n, double radius_m,
			  struct px_cloud_report *rep, struct px_model **out);

/*
 * Load a cloud, at most PX_FILE_MODEL_MAX_BYTES (1 GiB, px_file.h: a
 * larger regular file is refused from its size, a pipe or device when
 * the count passes it). ".ply" files: the header and body are checked
 * against each other, the vertex element must have scalar x, y and z,
 * and the coordinates are read exactly (float, double or integer types,
 * ASCII or binary of either byte order; faces ignored). Any other name
 * is text: one point per line, at least three numbers separated by
 * blanks or by one comma or semicolon (more columns, e.g. colours or
 * normals, are ignored; an empty field such as "1,,2" is an error), '#'
 * or '//' comment lines and blank lines skipped, and one header line
 * before the first point whose first field is a name, not a number
 * ("NaN,0,0" is a point, and non-finite). A NUL byte is an error at its
 * line and column. Errors name the file and, for text, line, column or
 * field: PX_E_NOTFOUND, PX_E_IO, PX_E_PARSE, PX_E_RANGE (over the size
 * limit, a coordinate beyond PX_CLOUD_MAX_COORD), and px_cloud_model()'s
 * errors. Setup only.
 */
PX_API int px_cloud_load(const char *path, double radius_m,
			 struct px_cloud_report *rep, struct px_model **out);

/* Accessors for a cloud model (0 / PX_E_INVAL otherwise). @note RT-safe. */
PX_API size_t px_cloud_point_count(const struct px_model *m);
PX_API int px_cloud_point(const struct px_model *m, size_t i, px_vec3 *p);
PX_API double px_cloud_radius(const struct px_model *m);

#ifdef __cplusplus
}
#endif

#endif
