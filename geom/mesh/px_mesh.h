/*
 * px_mesh.h - triangle meshes: exact point-to-mesh distance with a
 * bounding-volume hierarchy, signed distance for closed meshes, loading
 * from STL, OBJ and PLY.
 *
 * Setup (px_mesh_model, px_mesh_load) validates the triangles, welds
 * vertices at identical positions, builds the edge topology, decides
 * whether the mesh is a closed, consistently oriented 2-manifold
 * (watertight), computes angle-weighted pseudo-normals (Baerentzen and
 * Aanaes 2005) and builds a binary AABB hierarchy over the triangles
 * (binned surface-area splits, switching to median splits where needed
 * to keep the depth within PX_MESH_MAX_DEPTH; child boxes are stored in
 * single precision rounded outwards, so they stay lower bounds), then
 * collapses it to four children per node for the queries. A query then needs no memory but a fixed array on
 * the call stack: it descends nearer child first and prunes every box
 * farther than the best triangle so far. Boxes, and then each
 * triangle's plane and edge half-planes (one cache line per triangle),
 * are first compared in single precision with a slack that covers the
 * rounding (so they stay lower bounds and never prune the answer); only
 * triangles that survive get the exact double-precision test. The
 * distance to a triangle is
 * exact over all seven Voronoi regions (face, three edges, three
 * vertices), also for slivers, needles of any aspect ratio and
 * collapsed triangles (see px_tri_closest for the bound).
 *
 * Accepted range: every used vertex coordinate within
 * +-PX_MESH_MAX_COORD (1e150) and the largest extent 0 or at least
 * PX_MESH_MIN_EXTENT (1e-140); setup refuses anything else with
 * PX_E_RANGE and a message naming the vertex or the extent. Query
 * points up to 1e150 outside the box (px_model.h) are answered. The
 * hierarchy's boxes are single-precision floats: beyond about 3e38 they
 * round out to infinity, and below about 1e-38 (subnormal floats) they
 * coarsen until, near 1e-45, they no longer separate anything; such a
 * mesh is answered exactly, but by visiting more (up to every)
 * triangle.
 *
 * Signed distance: on a watertight mesh the sign of (p - q) . n, with n
 * the pseudo-normal of the feature (face, edge or vertex) holding the
 * closest point q, is the inside/outside answer. A closed mesh whose
 * triangles face inwards (negative volume) is flipped. Open,
 * non-manifold or inconsistently oriented meshes answer with unsigned
 * distances (result is_signed = 0) and say why in the report.
 *
 * Cold queries (no hint) walk the hierarchy from the root, nearest
 * child first. An optional hint grid (px_mesh_opts.grid_cells > 0)
 * gives them a first bound instead: cubic cells over the mesh's box
 * grown by an eighth of its largest extent on every side, each holding
 * the triangle closest to the cell's centre (found by the exact query;
 * points outside the grid take the nearest cell), at most one cell per
 * 8 triangles; building it costs about one cold query per cell. The
 * answer is exact either way: the hint only sets the starting bound.
 * It is off by default because it seldom pays: most of a cold query's
 * work is the proof that no other triangle is closer, not the search
 * for a bound, while the hint costs three dependent memory fetches
 * (cell, hint indices, hint vertices) before the walk starts.
 *
 * Coherent queries (PX_QUERY_COHERENT with last cycle's triangle index as
 * hint) start from that triangle's distance as an upper bound, which
 * prunes most of the hierarchy at once when the point moved little.
 * Meshes also implement the coherence cache (px_model_query_cached):
 * most cycles then scan a few nearby triangles with a proof that no
 * other triangle can be closer.
 *
 * Results (px_model_result): index = triangle (input order), feature =
 * FACE / EDGE (sub = 0: v0v1, 1: v1v2, 2: v2v0) / VERTEX (sub = 0..2),
 * u, v = barycentric weights of v1 and v2 of the closest point,
 * iterations = nodes and triangles visited, certified = 1 (exact).
 *
 * Memory and real-time rules: building allocates (setup only) about 280
 * bytes per triangle (of which a query reads about 110: nodes, float
 * bounds, vertex indices and the welded vertices; the optional hint
 * grid adds at most half a byte); queries are RT-safe (no heap, bounded
 * by the triangle count, fixed stack of 3 PX_MESH_MAX_DEPTH + 4
 * entries).
 */
#ifndef PX_MESH_H
#define PX_MESH_H

#include <stddef.h>
#include <stdint.h>

#include "px_base.h"
#include "px_math.h"
#include "px_model.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Depth bound of the binary build (median splits give about
 * log2(triangles / 2); surface-area splits are used only while they leave
 * room for that). */
#define PX_MESH_MAX_DEPTH 48
/* Largest triangle count (indices are 32-bit inside). */
#define PX_MESH_MAX_TRIANGLES ((size_t)1 << 30)

/* Options (all zero = defaults). */
#define PX_MESH_REJECT_DEGENERATE 0x1u /* zero-area triangles are errors */
#define PX_MESH_REQUIRE_CLOSED 0x2u    /* open/non-manifold are errors */
#define PX_MESH_NO_FLIP 0x4u           /* keep inward orientation (sign inverted) */

/* The accepted range (px_mesh_model refuses anything else with
 * PX_E_RANGE): every used vertex coordinate within +-PX_MESH_MAX_COORD,
 * so that differences, squared distances (also to query points up to the
 * query reach of 1e150 outside the box, px_model.h) and the hierarchy's
 * arithmetic stay finite; and the mesh's largest extent either 0 (one
 * point) or at least PX_MESH_MIN_EXTENT, so that squared distances at
 * its scale are normal doubles. px_tri_closest takes coordinates up to
 * PX_TRI_MAX_COORD. */
#define PX_MESH_MAX_COORD 1e150
#define PX_MESH_MIN_EXTENT 1e-140
#define PX_TRI_MAX_COORD 1e152

/* Largest hint grid (cells of 4 bytes). */
#define PX_MESH_MAX_GRID_CELLS (1L << 26)

struct px_mesh_opts {
	unsigned flags;     /* PX_MESH_* */
	/* triangles per leaf, 1..16; 0 = 6 (measured on the benchmark
	 * torus: 4 and 8 cost a few percent more per cold query, 4 also
	 * about 15 % more per mesh pair) */
	int leaf_size;
	/* Hint-grid budget in cells (4 bytes each): > 0 = a grid of at
	 * most this many cells (up to PX_MESH_MAX_GRID_CELLS, and at most
	 * one cell per 8 triangles; meshes under 16 triangles get one
	 * cell); 0 (the default) or < 0 = no grid. */
	long grid_cells;
};

/* What setup found. message names the first problem and where it is. */
struct px_mesh_report {
	size_t n_vertices, n_triangles;
	size_t n_welded;              /* distinct vertex positions */
	size_t n_degenerate;          /* zero-area or collapsed triangles */
	size_t n_boundary_edges;      /* used by one triangle */
	size_t n_nonmanifold_edges;   /* used by three or more */
	size_t n_misoriented_edges;   /* two triangles, same direction */
	long first_degenerate;        /* triangle index, -1 if none */
	long first_bad_edge_triangle; /* a triangle on a bad edge, -1 if none */
	int closed;                   /* watertight: signed distances */
	int flipped;                  /* was inward, normals reversed */
	int convex;                   /* closed, and no reflex edge */
	double volume;                /* enclosed volume (closed meshes) */
	int depth;                    /* hierarchy depth */
	char message[256];            /* "" when everything is fine */
};

/*
 * Build a mesh model from n_vertices points (xyz, 3 doubles each) and
 * n_triangles index triples (tri, 3 each, 0-based). The data are copied.
 * opt may be NULL; rep may be NULL (else always filled, also on error).
 * Returns PX_OK; PX_E_INVAL (NULL pointers, no triangles, bad leaf
 * size), PX_E_RANGE (an index >= n_vertices: rep->message names the
 * triangle; or too many triangles), PX_E_NAN (a non-finite coordinate
 * of a used vertex), PX_E_DEGENERATE (with PX_MESH_REJECT_DEGENERATE or
 * PX_MESH_REQUIRE_CLOSED, when the mesh has what they reject),
 * PX_E_NOMEM. Setup only.
 */
PX_API int px_mesh_model(const double *xyz, size_t n_vertices,
			 const uint32_t *tri, size_t n_triangles,
			 const struct px_mesh_opts *opt,
			 struct px_mesh_report *rep, struct px_model **out);

/*
 * Load a mesh file (STL ASCII or binary, OBJ faces, PLY; polygons are
 * triangulated, all meshes of the file merged with their node
 * transforms applied) and build it as px_mesh_model() does. Errors
 * name the file in rep->message: PX_E_NOTFOUND (no such file),
 * PX_E_IO (unreadable), PX_E_PARSE (the importer's message: malformed
 * or unknown format, a PLY body shorter or longer than its header says,
 * or a file without triangles), and px_mesh_model()'s errors.
 * Files are read by the Open Asset Import Library, whose coordinates are
 * single-precision floats (about 7 significant digits; exact for binary
 * STL, which stores floats). Setup only.
 */
PX_API int px_mesh_load(const char *path, const struct px_mesh_opts *opt,
			struct px_mesh_report *rep, struct px_model **out);

/*
 * px_mesh_load() with the file's coordinates multiplied by scale[0..2]
 * (x, y, z; each finite and not zero, else PX_E_RANGE) before the model
 * is built, as a URDF <mesh scale> asks. A mirroring scale (an odd
 * number of negative factors) turns every triangle round, so the
 * outside stays outside. scale NULL is px_mesh_load(). Setup only.
 */
PX_API int px_mesh_load_scaled(const char *path, const double scale[3],
			       const struct px_mesh_opts *opt,
			       struct px_mesh_report *rep,
			       struct px_model **out);

/*
 * Exact closest point of triangle (a, b, c) to p: returns the squared
 * distance, writes the point q, its feature (PX_FEATURE_FACE, _EDGE,
 * _VERTEX), sub (edge 0: ab, 1: bc, 2: ca, or vertex 0..2) and the
 * barycentric weights u (of b) and v (of c). Any output pointer may be
 * NULL.
 *
 * Accuracy: with d* the exact distance from the given doubles, u =
 * 2^-53 and l the longest edge, the distance d = sqrt(result) obeys
 * |d - d*| <= PX_TRI_ERR_ULPS u (d* + l) + 1e-160 for every shape
 * (needles and slivers of any aspect ratio, collinear and repeated
 * vertices) and scale (a triangle well shaped at its vertex a and of
 * moderate size takes the fast test, others a robust one whose error
 * does not depend on the shape; the last term is the subnormal range
 * of the squares). Non-finite coordinates return NaN (q = p, feature
 * PX_FEATURE_NONE), and so do coordinates beyond +-PX_TRI_MAX_COORD
 * (1e152) unless the triangle and p are close enough together for the
 * fast test (whose differences then stay small): no answer rather than
 * an overflowed one. q lies at the returned distance to the same
 * bound (plus its own rounding as a point); u and v carry a rounding
 * that grows with the aspect ratio (a needle's weights move by that much
 * more when a vertex moves by rounding): take the point from q. A
 * triangle thin only at a takes the fast test from the vertex with the
 * widest angle. @note RT-safe.
 */
#define PX_TRI_ERR_ULPS 64.0
PX_API double px_tri_closest(px_vec3 p, px_vec3 a, px_vec3 b, px_vec3 c,
			     px_vec3 *q, int *feature, int *sub, double *u,
			     double *v);

/* Mesh accessors for a model made by px_mesh_model/px_mesh_load (NULL or
 * another kind of model gives 0 / PX_E_INVAL). @note RT-safe. */
PX_API size_t px_mesh_triangle_count(const struct px_model *m);
/* Vertices of triangle i (input order), model frame. */
PX_API int px_mesh_triangle(const struct px_model *m, size_t i, px_vec3 v[3]);
/* 1 when the mesh is watertight (signed distances), else 0. */
PX_API int px_mesh_is_closed(const struct px_model *m);

#ifdef __cplusplus
}
#endif

#endif
