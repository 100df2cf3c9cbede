/* The mesh importer of a build without the Open Asset Import Library:
 * every file read through it is refused with a message that says so
 * (px_mesh_load, and PLY point clouds, which share its reader). */
#include <stdio.h>

#include "mesh_internal.h"

int px__import_file(const char *path, int want_tri, double **xyz,
		    size_t *nv, uint32_t **tri, size_t *nt, size_t *n_skipped,
		    char *msg, size_t msg_cap)
{
	(void)want_tri;
	if (xyz)
		*xyz = NULL;
	if (nv)
		*nv = 0;
	if (tri)
		*tri = NULL;
	if (nt)
		*nt = 0;
	if (n_skipped)
		*n_skipped = 0;
	if (msg && msg_cap)
		snprintf(msg, msg_cap, "%s: this build has no mesh importer "
			 "(built without assimp)", path ? path : "<null>");
	return PX_E_UNSUPPORTED;
}
