/* A B-rep's faces one by one (px_brep_face()), for those who draw them. */
#include "brep_internal.h"

int px_brep_face(const struct px_brep *b, int i,
		 const struct px_nurbs_surf **surf,
		 const struct px_trim **trim, int *reversed)
{
	if (!b || i < 0 || i >= b->n_faces || !surf || !trim || !reversed)
		return PX_E_INVAL;
	*surf = &b->faces[i].surf;
	*trim = b->faces[i].trim;
	*reversed = b->faces[i].reversed;
	return PX_OK;
}
