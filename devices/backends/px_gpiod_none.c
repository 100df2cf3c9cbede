/* The GPIO back end of a build without libgpiod: the functions of
 * px_gpio.h that need it exist and say so (the simulated GPIO device and
 * the debouncer do not need it). */
#include <stdio.h>

#include "px_gpio.h"

int px_gpiod_create(const struct px_dev_config *dcfg,
		    const struct px_gpio_config *cfg, struct px_dev **out,
		    int *sys_errno, char *msg, size_t cap)
{
	(void)cfg;
	if (out)
		*out = NULL;
	if (sys_errno)
		*sys_errno = 0;
	if (msg && cap)
		snprintf(msg, cap, "%s: this build has no GPIO back end "
			 "(built without libgpiod)",
			 dcfg && dcfg->name ? dcfg->name : "gpio");
	return PX_E_UNSUPPORTED;
}

int px_gpiod_list(int lines, void (*fn)(void *user, const char *line),
		  void *user)
{
	(void)lines, (void)fn, (void)user;
	return PX_E_UNSUPPORTED;
}

const char *px_gpiod_version(void)
{
	return "none (built without libgpiod)";
}
