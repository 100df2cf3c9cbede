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
 * (PX_FEATURE_VERTEX); certified keeps its meaning (the global minimum
 * over the trimmed faces, their edges and vertices, proven).
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

#ifdef __cplusplus
}
#endif

#endif /* PX_BREP_H */
