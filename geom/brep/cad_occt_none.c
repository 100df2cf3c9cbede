/* The CAD importer of a build without OpenCASCADE: every file is refused
 * with a message that says so. */
#include <stdio.h>

#include "px_cad.h"

int px_cad_load(const char *path, const struct px_cad_opts *opts,
		struct px_cad **out, char *msg, size_t msg_len)
{
	(void)opts;
	if (out)
		*out = NULL;
	if (msg && msg_len)
		snprintf(msg, msg_len, "%s: this build has no STEP/IGES "
			 "importer (built without OpenCASCADE)",
			 path ? path : "<null>");
	return PX_E_UNSUPPORTED;
}

const struct px_brep_desc *px_cad_desc(const struct px_cad *c)
{
	(void)c;
	return NULL;
}

int px_cad_solid_count(const struct px_cad *c)
{
	(void)c;
	return 0;
}

void px_cad_free(struct px_cad *c)
{
	(void)c;
}
