/* Netlink calls on CAN interfaces in a build without libsocketcan: raw
 * CAN frames still work; state, bitrate and restart are not available
 * (px_can_bus.c says so in its messages). */
#include <errno.h>

#include "dev_internal.h"

int px__socketcan_have(void)
{
	return 0;
}

int px__socketcan_state(const char *iface, int *px_state)
{
	(void)iface, (void)px_state;
	return PX_E_UNSUPPORTED;
}

static int unsupported(void)
{
	errno = EOPNOTSUPP;
	return -1;
}

int px__socketcan_do_stop(const char *iface)
{
	(void)iface;
	return unsupported();
}

int px__socketcan_do_start(const char *iface)
{
	(void)iface;
	return unsupported();
}

int px__socketcan_set_bitrate(const char *iface, uint32_t bitrate)
{
	(void)iface, (void)bitrate;
	return unsupported();
}

int px__socketcan_set_restart_ms(const char *iface, uint32_t ms)
{
	(void)iface, (void)ms;
	return unsupported();
}

int px__socketcan_get_bitrate(const char *iface, uint32_t *bitrate)
{
	(void)iface, (void)bitrate;
	return unsupported();
}

int px__socketcan_restart(const char *iface)
{
	(void)iface;
	return PX_E_UNSUPPORTED;
}
