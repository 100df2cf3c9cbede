/* The YAML loader of a build without libyaml: loading a document fails
 * with a diagnostic that says so, so that a tool names the cause
 * instead of reporting a parse error. */
#include "config_internal.h"

int px_config_doc_load_mem(const char *name, const void *buf, size_t len,
			   struct px_config_doc **out,
			   struct px_config_diag *diag)
{
	(void)buf, (void)len;
	px_config_diag_init(diag);
	if (out)
		*out = NULL;
	px__cfg_diag_add(diag, name ? name : "<memory>", 0, 0, "",
			 "this build has no YAML loader (built without libyaml)");
	return PX_E_UNSUPPORTED;
}
