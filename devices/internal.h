/* Private declarations shared by devices/ files. */
#ifndef PX_DEVICES_INTERNAL_H
#define PX_DEVICES_INTERNAL_H

#include <stdint.h>

#include "px_dev.h"
#include "px_gpio.h"

struct px_loop;

/* The loop a device was attached to (NULL none). */
struct px_loop *px__dev_loop(const struct px_dev *d);

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

#endif
