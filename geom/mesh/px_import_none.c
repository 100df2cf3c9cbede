/* The mesh importer of a build without the Open Asset Import Library.
 * PLY files are checked and their vertices read without it
 * (mesh_ply.c): a PLY point cloud loads as in every build, and a PLY
 * with vertices only, read as a mesh, says "no triangles" as there (so
 * px_model_load takes it as a cloud). Every other mesh - a PLY with
 * faces, STL, OBJ, ... - is refused with a message that says why. */
#include <stdio.h>
#include <stdlib.h>

#include "mesh_internal.h"

int px__import_data(const char *path, char *data, size_t len, int want_tri,
		    double **xyz, size_t *nv, uint32_t **tri, size_t *nt,
		    size_t *n_skipped, char *msg, size_t msg_cap)
{
	int rc = PX_OK, ply;
	if (msg_cap)
		msg[0] = '\0';
	if (tri)
		*tri = NULL;
	if (nt)
		*nt = 0;
	if (n_skipped)
		*n_skipped = 0;
	if (!path || !data || !xyz || !nv || (want_tri && (!tri || !nt))) {
		snprintf(msg, msg_cap, "invalid arguments");
		return PX_E_INVAL;
	}
	*xyz = NULL;
	*nv = 0;
	ply = px__ply_file(path, data, len);
	if (ply)
		rc = px__ply_read(path, data, len, want_tri, xyz, nv, msg, msg_cap);
	if (ply && (rc != PX_OK || !want_tri))
		return rc;
	free(*xyz);
	*xyz = NULL;
	*nv = 0;
	snprintf(msg, msg_cap, "%s: this build has no mesh importer%s "
		 "(built without assimp)", path,
		 ply ? " for the faces of a PLY" : "");
	return PX_E_UNSUPPORTED;
}
