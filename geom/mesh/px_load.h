/*
 * px_load.h - one call that turns a mesh, point or CAD file into a model,
 * for tools and configs that take "a model file" (proxima-query, scenes
 * described in a config).
 *
 * By name: .stl and .obj are meshes; .xyz, .csv, .txt and .pts are point
 * clouds; .ply is a mesh when it has faces and a point cloud when it has
 * only vertices; .step, .stp, .iges and .igs are CAD parts. Other names
 * are tried as meshes (the importer knows many formats). An OBJ with
 * free-form statements (NURBS curves and surfaces) is read by
 * px_model_load_obj(): trim or hole loops make a B-rep (px_brep_obj.h),
 * untrimmed curves and surfaces one NURBS model; a polygon OBJ goes to
 * the mesh importer as other meshes do. Each file is read once.
 *
 * CAD parts (px_model_load_cad()) are read with px_cad_load() and built
 * with px_brep_create() into one model of kind PX_MODEL_BREP: the whole
 * file as one union (every solid with its placement, free shells and
 * free faces; px_cad_opts.solid = -1), in metres (the importer converts
 * the file's length unit). The model is signed when the B-rep is closed,
 * else unsigned with a message that says why. A build without
 * OpenCASCADE refuses them with PX_E_UNSUPPORTED and a message that
 * names the file and says "built without OpenCASCADE". Only the C
 * interface of the importer is called: the mesh module needs no C++.
 *
 * Every file is read whole with the model limit, PX_FILE_MODEL_MAX_BYTES
 * (1 GiB, px_file.h): a larger regular file is refused from its size, a
 * pipe or device when the count passes it, and text formats refuse a NUL
 * byte at its line and column. Coordinates beyond 1e150 are refused at
 * load (their squared distances would overflow), with their place.
 *
 * Memory and real-time rules: setup only (allocates, reads files).
 */
#ifndef PX_LOAD_H
#define PX_LOAD_H

#include <stddef.h>

#include "px_base.h"
#include "px_model.h"

#ifdef __cplusplus
extern "C" {
#endif

/*
 * Load path into *out. cloud_radius_m is the ball radius for point
 * clouds (0 for plain points). msg (may be NULL) receives a message that
 * names the file and the problem, also for warnings on success (for
 * example "open mesh: distances are unsigned"), or "" when there is
 * nothing to say. Returns PX_OK or the errors of px_mesh_load(),
 * px_cloud_load() and, for CAD names, px_model_load_cad() (scale 1).
 */
PX_API int px_model_load(const char *path, double cloud_radius_m,
			 struct px_model **out, char *msg, size_t msg_cap);

/*
 * Load the OBJ file at path (px_obj.h reads it, coordinates as written,
 * in metres) as one model: trim or hole loops make a B-rep
 * (PX_MODEL_BREP, px_model_from_obj_brep()); free-form curves and
 * surfaces one NURBS model (px_nurbs_model_create()); polygon faces a
 * mesh (px_mesh_model(), exact doubles). A file with both free-form
 * entities and faces is PX_E_UNSUPPORTED (load them as two files); one
 * with neither PX_E_NOTFOUND. msg as for px_model_load(); errors name
 * the file (and line and column for syntax). Setup only.
 */
PX_API int px_model_load_obj(const char *path, struct px_model **out,
			     char *msg, size_t msg_cap);

/*
 * Load the STEP or IGES file path (the format from its name, else from
 * its first line) as one B-rep model: the file in metres times scale
 * (finite, > 0; 1 keeps metres). msg as for px_model_load(): on success
 * "" for a closed part, else why distances are unsigned. Returns PX_OK,
 * the errors of px_cad_load() (PX_E_UNSUPPORTED without OpenCASCADE) or
 * of px_brep_create(), PX_E_INVAL for bad arguments.
 */
PX_API int px_model_load_cad(const char *path, double scale,
			     struct px_model **out, char *msg, size_t msg_cap);

/* 1 when path names a CAD part by its extension (.step, .stp, .iges,
 * .igs, any case), else 0. */
PX_API int px_model_is_cad_name(const char *path);

#ifdef __cplusplus
}
#endif

#endif
