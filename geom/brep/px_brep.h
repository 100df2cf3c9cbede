/*
 * px_brep.h - boundary-representation solids: trimmed NURBS faces, their
 * edges and vertices, shells and solids, as one distance model.
 *
 * A CAD part (STEP, IGES, trimmed OBJ) is a set of faces. A face is a
 * NURBS surface restricted to a region of its (u, v) plane bounded by
 * loops of 2D NURBS curves (px_trim.h: loop 0 the outer one, the others
 * holes); faces meet along edges (3D NURBS curves) that end at vertices.
 * Faces group into shells (closed or open) and shells into solids (one
 * outer shell, any inner voids).
 *
 * Importers fill a struct px_brep_desc (arrays they own, read during
 * px_brep_create() only, in the file's units times desc.scale = metres)
 * and px_brep_create() validates it, builds each face's trimmed domain
 * and the distance structures once, and returns a handle that owns all
 * of its memory. px_model_from_brep() wraps it as a px_model (kind
 * PX_MODEL_BREP), so scenes, pairs, streams and the tools use it like
 * any other model.
 *
 * Answers (struct px_model_result): index is the face (feature
 * PX_FEATURE_SURFACE, (u, v) its surface parameters), the edge
 * (PX_FEATURE_CURVE, u the edge curve's parameter) or the vertex
 * (PX_FEATURE_VERTEX; -1 for the point of a collapsed loop curve that is
 * no vertex); certified keeps its meaning (the global minimum
 * over the trimmed faces, their edges and vertices, proven).
 *
 * Tracked streams (px_model_stream_create()) follow the critical points
 * of the faces' surfaces and answer with those inside the trimmed
 * domains, the edges followed as curves, the point candidates checked
 * directly: the global query's answers, sign included.
 *
 * Memory and real-time rules: px_brep_create() and px_model_from_brep()
 * allocate (setup only); queries on the model never touch the heap, run
 * in bounded loops, keep no state and may run in several threads at
 * once. px_brep_free() releases everything.
 */
#ifndef PX_BREP_H
#define PX_BREP_H

#include "px_base.h"
#include "px_nurbs.h"
#include "px_trim.h"

#ifdef __cplusplus
extern "C" {
#endif

/* One use of an edge by a face's loop: the loop's curve k lies on edge
 * edge (or -1 when the importer has no 3D edge for it). */
struct px_brep_coedge {
	int edge;
};

/*
 * A face: the surface, its trimming loops (px_trim_loop, loop 0 outer),
 * for each loop's curves the edge it runs along (coedges[l][k], NULL
 * when unknown), and its orientation: reversed == 0 means the outward
 * normal of the solid is Su x Sv, reversed != 0 that it is -(Su x Sv).
 * shell: the shell the face belongs to. id: the importer's own number
 * for messages (STEP #entity, IGES directory entry, OBJ line; 0 none).
 */
struct px_brep_face_desc {
	struct px_nurbs_surf surf;
	const struct px_trim_loop *loops;
	int n_loops;
	const struct px_brep_coedge *const *coedges;
	int reversed;
	int shell;
	long id;
};

/* An edge: a 3D curve between vertices v0 and v1 (indices into
 * px_brep_desc.vertices; equal for a closed edge, -1 when open-ended),
 * and the importer's id. */
struct px_brep_edge_desc {
	struct px_nurbs_curve curve;
	int v0, v1;
	long id;
};

/* A shell: closed != 0 when it bounds a volume (every edge used by two
 * faces in opposite directions); solid: the solid it belongs to, or -1
 * for a free shell (an open sheet). A solid's first shell is its outer
 * boundary, later shells are voids. */
struct px_brep_shell_desc {
	int closed;
	int solid;
	long id;
};

/*
 * What an importer hands to px_brep_create(). scale multiplies every
 * coordinate (file units to metres: 0.001 for millimetres). name and
 * source are copied (messages and px_model_name()).
 */
struct px_brep_desc {
	const struct px_brep_face_desc *faces;
	int n_faces;
	const struct px_brep_edge_desc *edges;
	int n_edges;
	const px_vec3 *vertices;
	int n_vertices;
	const struct px_brep_shell_desc *shells;
	int n_shells;
	int n_solids;
	double scale;
	const char *name;
	const char *source;
};

/* ---- the model ---------------------------------------------------------- */

/* Setup options: the trimmed domains' (px_trim.h) and the distance
 * core's (px_dist.h; NULL: its defaults, read during px_brep_create()
 * only). */
struct px_dist_opts;
struct px_brep_opts {
	struct px_trim_opts trim;
	const struct px_dist_opts *dist;
	/* 1: a loop curve without a 3D edge (coedge edge -1) whose image is
	 * not a single point gets its exact image on the surface as an own
	 * edge (degree d (p + q) for a degree-d curve on a (p, q) surface,
	 * d p or d q when u or v is constant along it): a NURBS curve up to
	 * PX_NURBS_MAX_DEGREE, above it a curve-on-surface edge (exact,
	 * numbered after the edges in answers and px_brep_info, not
	 * signed: a B-rep with one is open) up to degree 24, refused
	 * beyond; 0 (default): such a curve is refused. */
	int compose_edges;
};

/* Defaults of both. */
PX_API void px_brep_opts_default(struct px_brep_opts *o);

/*
 * Where and why px_brep_create() refused a description: code is the
 * px_err returned; face, loop, curve, edge, vertex, shell name the
 * culprit (-1 when not involved; loop 0 is the outer loop); id is the
 * importer's id of the face or edge (0 none); trim and nurbs carry the
 * trimmed domain's or the kernel's own report when one of them refused.
 * msg is a complete sentence naming the face, loop and curve, e.g.
 * "face 2 (id 57): hole 1 curve 0: gap of 0.01 between curves 0 and 1".
 */
struct px_brep_error {
	int code;
	int face, loop, curve, edge, vertex, shell;
	long id;
	struct px_trim_error trim;
	struct px_nurbs_error nurbs;
	char msg[384];
};

struct px_brep;

/*
 * Validate d and build the B-rep: every face's surface (the kernel's
 * validation), its loops (px_trim_create(); a face without loops is the
 * whole surface), the trimmed domain inside the surface's parameter
 * domain, every edge's curve, every index in range (coedge -> edge,
 * edge -> vertex, face -> shell, shell -> solid), scale finite and
 * > 0. Every loop curve needs a 3D edge (coedge edge >= 0) unless its
 * image on the surface is a single point (a pole, a collapsed side):
 * such a point is a vertex candidate; a loop curve with neither is
 * refused (the distance to it would not be exact) unless
 * opts->compose_edges asks for its exact image as an edge. Coordinates are
 * scaled; everything is copied into memory the handle owns and fixed
 * from then on. opts NULL: defaults; err may be NULL. Returns PX_OK,
 * PX_E_INVAL (a bad description: err says where), PX_E_RANGE, PX_E_NAN,
 * PX_E_DEGENERATE (zero-area loop), PX_E_NOCONV, PX_E_NOMEM, PX_E_NOSPC.
 * Setup only.
 */
PX_API int px_brep_create(const struct px_brep_desc *d,
			  const struct px_brep_opts *opts,
			  struct px_brep_error *err, struct px_brep **out);

/* Release a B-rep not handed to px_model_from_brep() (NULL is fine). */
PX_API void px_brep_free(struct px_brep *b);

/*
 * What setup made of a B-rep. closed: 1 when queries are signed: every
 * shell closed and in a solid, every edge used twice by faces of one
 * shell in opposite directions (the faces agree on the outside), every
 * vertex's pseudo-normal defined, and a point beyond the box comes out
 * outside; why says so or names the first failing check.
 */
struct px_brep_info {
	int n_faces, n_edges, n_vertices, n_shells, n_solids;
	int n_trimmed;       /* faces with loops */
	int n_point_cands;   /* free vertices and collapsed loop curves */
	int closed;
	char why[200];
	px_aabb bounds;      /* metres */
	size_t bytes;
};

/* Returns PX_OK or PX_E_INVAL. @note RT-safe. */
PX_API int px_brep_get_info(const struct px_brep *b, struct px_brep_info *info);

/*
 * The B-rep as a px_model of kind PX_MODEL_BREP named after desc.name
 * (px_model_name(); "brep" when none). The model takes b over, also on
 * failure. Capabilities: PX_MODEL_CAP_EXACT, and PX_MODEL_CAP_SIGNED
 * when px_brep_get_info() says closed. Signed answers (inside negative)
 * come from the B-rep's own faces: the foot point's face normal
 * (reversed faces flip it), on an edge the sum of its two faces'
 * normals there, at a vertex its angle-weighted pseudo-normal (for a
 * point whose closest point is that edge or vertex, it points towards
 * the point exactly when the point is outside); a point on the model
 * (within rounding) is outside. Up to four threads may query at once
 * (a fifth gets PX_E_BUSY). Setup only.
 */
struct px_model;
PX_API int px_model_from_brep(struct px_brep *b, struct px_model **out);

/* The B-rep behind a model from px_model_from_brep(), or NULL.
 * @note RT-safe. */
PX_API const struct px_brep *px_model_brep(const struct px_model *m);

/* Face i of b (0 <= i < n_faces of px_brep_get_info()): its surface in
 * metres (*surf, the B-rep's scaled copy) and its trimmed domain (*trim,
 * NULL: the whole surface), both valid while b lives; *reversed 1 when
 * the face's outside is against Su x Sv. For display (px_tess.h).
 * Returns PX_OK or PX_E_INVAL. @note RT-safe. */
PX_API int px_brep_face(const struct px_brep *b, int i,
			const struct px_nurbs_surf **surf,
			const struct px_trim **trim, int *reversed);

#ifdef __cplusplus
}
#endif

#endif /* PX_BREP_H */
