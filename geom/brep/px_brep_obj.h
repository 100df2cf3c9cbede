/*
 * px_brep_obj.h - trimmed Wavefront OBJ free-form files (px_obj.h:
 * curv2, trim, hole) as B-rep models.
 *
 * Every surf of the file becomes one face per 'trim' loop (the
 * surface's whole domain when it has none) of one free shell (an open
 * sheet: distances are unsigned; faces are not matched into a closed
 * solid): the trim loop is the face's outer loop, its holes the hole
 * loops that lie inside it (with several trim loops, a hole belongs to
 * the smallest one around it: an island in a hole of another region is
 * a face of its own), each loop curve the curv2 restricted to the
 * statement's range (run backwards when u0 > u1). Loop curves have no
 * 3D edges in OBJ, so every one gets its exact image on the surface as
 * an own edge (px_brep_opts compose_edges; edges are not shared between
 * faces): a NURBS curve of the kernel when its degree allows, else
 * (a cubic trim on a bicubic surface: degree 18) a curve-on-surface
 * edge solved as exactly (up to degree 24). curv entities are free
 * edges; polygon faces (f) in a trimmed file are refused.
 *
 * Errors carry the place in the file: px_obj_error line and column of
 * the trim or hole statement whose loop is refused (open, crossing,
 * zero area, outside the surface's domain, a hole in none of several
 * trim loops, an image of too high a degree), or of the surf or curv
 * statement, and a message that says what is wrong.
 *
 * Memory: setup only (allocates); the B-rep owns its copies.
 */
#ifndef PX_BREP_OBJ_H
#define PX_BREP_OBJ_H

#include <stddef.h>

#include "px_base.h"
#include "px_brep.h"
#include "px_obj.h"

#ifdef __cplusplus
extern "C" {
#endif

/* 1 when the model has trim or hole loops, else 0. */
PX_API int px_obj_trimmed(const struct px_obj_model *m);

/* 1 when the OBJ text holds a trim or hole statement (a line whose
 * first word is one of them): the cheap test a loader makes before it
 * picks the B-rep reader. */
PX_API int px_obj_text_trimmed(const char *data, size_t len);

/*
 * The B-rep of m's surfaces and curves, coordinates times scale (finite,
 * > 0). err (optional) is filled with the place and reason on failure.
 * Returns PX_OK, PX_E_INVAL (bad arguments, no surface), PX_E_UNSUPPORTED
 * (polygon faces), or px_brep_create()'s errors. Setup only.
 */
PX_API int px_brep_from_obj(const struct px_obj_model *m, double scale,
			    struct px_brep **out, struct px_obj_error *err);

/*
 * The model of a loaded OBJ with trim or hole loops (px_obj_trimmed()):
 * px_brep_from_obj() then px_model_from_brep(). path names the file in
 * msg, as px_model_load_obj_brep() says it. Setup only.
 */
PX_API int px_model_from_obj_brep(const struct px_obj_model *m,
				  const char *path, double scale,
				  struct px_model **out, char *msg,
				  size_t msg_cap);

/*
 * Load the OBJ file at path as a model: a file with trim or hole
 * statements as a B-rep (kind PX_MODEL_BREP, coordinates times scale)
 * with *trimmed = 1; any other file is left alone (*trimmed = 0,
 * *out NULL, PX_OK) for the mesh or NURBS loader. msg: on failure
 * "<path>:<line>:<column>: <why>" (or "<path>: <why>"); on success why
 * distances are unsigned. Setup only.
 */
PX_API int px_model_load_obj_brep(const char *path, double scale, int *trimmed,
				  struct px_model **out, char *msg,
				  size_t msg_cap);

#ifdef __cplusplus
}
#endif

#endif
