/* The HID back end of a build without hidapi: the functions of px_hid.h
 * exist and say so, so that callers and configs get a clear error. */
#include <stdio.h>

#include "px_hid.h"

int px_hid_driver(void)
{
	return PX_E_UNSUPPORTED;
}

const char *px_hid_driver_name(void)
{
	return "none";
}

int px_hid_create(const struct px_dev_config *dcfg,
		  const struct px_hid_config *hc, struct px_dev **out,
		  char *msg, size_t cap)
{
	(void)hc;
	if (out)
		*out = NULL;
	if (msg && cap)
		snprintf(msg, cap, "%s: this build has no HID back end "
			 "(built without hidapi)",
			 dcfg && dcfg->name ? dcfg->name : "hid");
	return PX_E_UNSUPPORTED;
}

int px_hid_list(void (*fn)(void *user, const char *line), void *user)
{
	(void)fn, (void)user;
	return PX_E_UNSUPPORTED;
}
