/* Options of the CAD importer, the same with and without OpenCASCADE. */
#include "px_cad.h"

void px_cad_opts_default(struct px_cad_opts *o)
{
	if (!o)
		return;
	o->scale = 1.0;
	o->solid = -1;
	o->max_bytes = PX_CAD_MAX_BYTES;
}
