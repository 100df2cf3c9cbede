/*
 * bridge_internal.h - private to bridge/: the limits and helpers that the
 * config side (px_bridge.c) and the DDS side (px_bridge_dds.c) share.
 */
#ifndef PX_BRIDGE_INTERNAL_H
#define PX_BRIDGE_INTERNAL_H

#include "px_bridge.h"

/* Highest stream rate: the loop's own rate bounds what is new anyway. */
#define PX_BRIDGE_MAX_RATE_HZ 10000.0
/* Processes on one machine that unicast discovery finds each other
 * among (participant indices 0 .. this). */
#define PX_BRIDGE_MAX_PARTICIPANTS 32

/* Samples offered and not yet published that a bridge holds; more drop
 * the oldest (counted). The app drains every 20 ms on the real clock,
 * in batches of up to 1000 cycles on the virtual one. */
#define PX_BRIDGE_QUEUE 256

/* DDS side (px_bridge_dds.c), shared with the device back end: join the
 * domain of c with the configuration of px_bridge_dds_config() (*domain
 * 0 when it existed before), and the QoS of a stream (best-effort) or of
 * the status (reliable), keep-last-1, volatile: a dds_qos_t to delete
 * with dds_delete_qos(), NULL without memory. Entities are Cyclone's
 * dds_entity_t (int32_t). */
int px__bridge_join(const struct px_bridge_config *c, int32_t *domain,
		    int32_t *dp, char *msg, size_t cap);
void *px__bridge_qos(int reliable);

/* 1 for the loopback interface ("lo", 127.x.x.x, ::1, localhost). */
int px_bridge_is_loopback(const char *iface);

#endif
