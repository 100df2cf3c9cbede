/*
 * px_load.h - one call that turns a mesh or point file into a model, for
 * tools and configs that take "a model file" (proxima-query, scenes
 * described in a config).
 *
 * By name: .stl and .obj are meshes; .xyz, .csv, .txt and .pts are point
 * clouds; .ply is a mesh when it has faces and a point cloud when it has
 * only vertices. Other names are tried as meshes (the importer knows many
 * formats). Free-form OBJ (NURBS curves and surfaces) belongs to the
 * NURBS loader, not here.
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
 * nothing to say. Returns PX_OK or the errors of px_mesh_load() and
 * px_cloud_load().
 */
PX_API int px_model_load(const char *path, double cloud_radius_m,
			 struct px_model **out, char *msg, size_t msg_cap);

#ifdef __cplusplus
}
#endif

#endif
