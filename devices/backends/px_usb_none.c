/* The USB back end of a build without libusb: the functions of px_usb.h
 * exist and say so, so that callers and configs get a clear error. */
#include <stdio.h>

#include "px_usb.h"

int px_usb_create(const struct px_dev_config *dcfg,
		  const struct px_usb_config *uc, struct px_dev **out,
		  char *msg, size_t cap)
{
	(void)uc;
	if (out)
		*out = NULL;
	if (msg && cap)
		snprintf(msg, cap, "%s: this build has no USB back end "
			 "(built without libusb)",
			 dcfg && dcfg->name ? dcfg->name : "usb");
	return PX_E_UNSUPPORTED;
}

int px_usb_hotplug_active(struct px_dev *d)
{
	(void)d;
	return PX_E_INVAL; /* no device is a libusb device */
}

int px_usb_list(void (*fn)(void *user, const char *line), void *user,
		char *msg, size_t cap)
{
	(void)fn, (void)user;
	if (msg && cap)
		snprintf(msg, cap, "this build has no USB back end (built "
			 "without libusb)");
	return PX_E_UNSUPPORTED;
}
