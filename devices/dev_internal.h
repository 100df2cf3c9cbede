/* Private declarations shared by devices/ files. */
#ifndef PX_DEVICES_INTERNAL_H
#define PX_DEVICES_INTERNAL_H

#include <stdint.h>

#include "px_can.h"
#include "px_codec.h"
#include "px_dev.h"
#include "px_gpio.h"

struct px_loop;

/* The loop a device was attached to (NULL none). */
struct px_loop *px__dev_loop(const struct px_dev *d);

/* The wrench of force command c in codec channel order: force, then
 * torque; all 0 when c is not enabled. RT-safe. */
void px__dev_force_wrench(const struct px_force_cmd *c,
			  double w[PX_WRENCH__COUNT]);
/* Output report of force command c through map m into buf (cap bytes):
 * its length, or the negative px_codec_encode() code after recording
 * PX_DEV_ERR_ENCODE on d at now. RT-safe. */
int px__dev_encode_force(struct px_dev *d, const struct px_codec_map *m,
			 const struct px_force_cmd *c, int64_t now,
			 uint8_t *buf, size_t cap);

/* Shared digital I/O logic of the GPIO back ends: roles, debounce of
 * the e-stop, fail-safe reporting and loop trips. */
struct px__dio {
	struct px_gpio_config cfg;
	struct px_debounce db;
	int have_estop;
	int pressed;          /* last reported */
	int out[PX_GPIO__ROLES]; /* logical output values */
};

void px__dio_init(struct px__dio *io, const struct px_gpio_config *cfg,
		  int estop_physical, int64_t t_ns);
/* Feed a physical e-stop level change at t_ns. */
void px__dio_edge(struct px__dio *io, int physical, int64_t t_ns);
/* Evaluate at now: sets *pressed, records the press, trips the loop.
 * gone: the device cannot be read (fail-safe: pressed). */
int px__dio_estop(struct px_dev *d, struct px__dio *io, int64_t now_ns,
		  int gone, int *pressed);
/* Logical to physical for an output role. */
int px__dio_physical(const struct px__dio *io, int role, int logical);

/* Fault engine of the simulated CAN buses (px_can_fault.c): the
 * in-process bus runs one bus-wide on the sending side, the fault
 * wrapper (px_can_fault_open) one on the receiving side of any bus.
 * Fixed memory; every call is RT-safe. */
#define PX__CAN_FX_DELAY 256 /* frames held back at once by delay */
#define PX__CAN_FX_IDS 64    /* ids remembered by stuck */
struct px__can_fx_item {
	struct px_can_msg m;
	int64_t due_ns;
	const void *tag;     /* the sender, for the in-process bus */
};
struct px__can_fx {
	struct px_sim_fault f[PX_SIM_MAX_FAULTS];
	size_t n;
	uint64_t rng;
	struct px__can_fx_item dq[PX__CAN_FX_DELAY];
	size_t dh, dn;
	uint32_t stuck_id[PX__CAN_FX_IDS];
	struct canfd_frame stuck_f[PX__CAN_FX_IDS];
	size_t n_stuck;
	int busoff, unplugged;
	uint64_t hits, delay_dropped;
};
/* Check and copy the faults (kinds drop, delay, duplicate, corrupt,
 * stuck, nan, unplug, bus_off). PX_E_INVAL with the fault's index and
 * why in msg (cap bytes, may be NULL). */
int px__can_fx_init(struct px__can_fx *fx, const struct px_sim_fault *f,
		    size_t n, uint64_t seed, char *msg, size_t cap);
/* Window states at now: bits 1 = bus-off changed, 2 = unplug changed;
 * fx->busoff / fx->unplugged hold the new states. Entering unplug
 * discards held frames. */
int px__can_fx_tick(struct px__can_fx *fx, int64_t now);
/* Pass frame m (at now) through drop, stuck, corrupt, nan, delay and
 * duplicate. Fills out[0..1] with the frames to deliver now and returns
 * their count (0: dropped or held back by delay). */
int px__can_fx_apply(struct px__can_fx *fx, const struct px_can_msg *m,
		     const void *tag, int64_t now, struct px_can_msg out[2]);
/* A held-back frame due at now (stamped now), FIFO. 1 when *m was
 * filled, 0 none. */
int px__can_fx_due(struct px__can_fx *fx, int64_t now, struct px_can_msg *m,
		   const void **tag);

/* Netlink calls on a CAN interface (backends/px_socketcan.c through
 * libsocketcan; px_socketcan_none.c in a build without it: have() 0,
 * every call fails with EOPNOTSUPP or PX_E_UNSUPPORTED). The do/set/get
 * calls return 0 or -1 with errno, as libsocketcan's; state and restart
 * return PX_OK or a px_err. */
int px__socketcan_have(void);
int px__socketcan_state(const char *iface, int *px_state);
int px__socketcan_do_stop(const char *iface);
int px__socketcan_do_start(const char *iface);
int px__socketcan_set_bitrate(const char *iface, uint32_t bitrate);
int px__socketcan_set_restart_ms(const char *iface, uint32_t ms);
int px__socketcan_get_bitrate(const char *iface, uint32_t *bitrate);
int px__socketcan_restart(const char *iface);

#endif
