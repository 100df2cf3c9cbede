/* Netlink calls on CAN interfaces through libsocketcan: controller state,
 * bitrate, restart (px_can_bus.c decides when to make them). */
#include <errno.h>
#include <string.h>

#include <libsocketcan.h>
#include <linux/can/netlink.h>

#include "dev_internal.h"
#include "px_can.h"

int px__socketcan_have(void)
{
	return 1;
}

int px__socketcan_state(const char *iface, int *px_state)
{
	int s = 0;
	if (can_get_state(iface, &s) != 0)
		return PX_E_IO;
	switch (s) {
	case CAN_STATE_ERROR_ACTIVE: *px_state = PX_CAN_STATE_ACTIVE; break;
	case CAN_STATE_ERROR_WARNING: *px_state = PX_CAN_STATE_WARNING; break;
	case CAN_STATE_ERROR_PASSIVE: *px_state = PX_CAN_STATE_PASSIVE; break;
	case CAN_STATE_BUS_OFF: *px_state = PX_CAN_STATE_BUS_OFF; break;
	case CAN_STATE_STOPPED: *px_state = PX_CAN_STATE_STOPPED; break;
	default: *px_state = PX_CAN_STATE_UNKNOWN; break;
	}
	return PX_OK;
}

int px__socketcan_do_stop(const char *iface)
{
	return can_do_stop(iface);
}

int px__socketcan_do_start(const char *iface)
{
	return can_do_start(iface);
}

int px__socketcan_set_bitrate(const char *iface, uint32_t bitrate)
{
	return can_set_bitrate(iface, bitrate);
}

int px__socketcan_set_restart_ms(const char *iface, uint32_t ms)
{
	return can_set_restart_ms(iface, ms);
}

int px__socketcan_get_bitrate(const char *iface, uint32_t *bitrate)
{
	struct can_bittiming bt;
	memset(&bt, 0, sizeof bt);
	if (can_get_bittiming(iface, &bt) != 0)
		return -1;
	*bitrate = bt.bitrate;
	return 0;
}

int px__socketcan_restart(const char *iface)
{
	return can_do_restart(iface) == 0 ? PX_OK : PX_E_IO;
}
