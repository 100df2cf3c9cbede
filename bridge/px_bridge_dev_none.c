/* The "dds" device back end of a build without Cyclone DDS: refused,
 * saying what is missing. */
#include <stdio.h>

#include "bridge_internal.h"

int px_bridge_dev_create(const struct px_dev_config *dc,
			 const struct px_bridge_dev_config *bc,
			 struct px_dev **out, char *msg, size_t cap)
{
	(void)dc, (void)bc;
	if (out)
		*out = NULL;
	if (msg && cap)
		snprintf(msg, cap, "dds device: this build has no DDS "
				   "(built without Cyclone DDS)");
	return PX_E_UNSUPPORTED;
}
