/*
 * px_gpio.h - digital I/O devices: an e-stop input (active-low
 * configurable, debounced, edge events), an enable output (amplifier
 * enable, brake release relay) and a loop-timing toggle output, on GPIO
 * lines through libgpiod (Debian 12's 1.6 API; every libgpiod call is in
 * px_gpiod.c so a port to the 2.x API touches one file) or on simulated
 * lines.
 *
 * Debounce: the e-stop state changes only after the line has held its
 * new level for debounce_ns (a bounce restarts the wait), measured on
 * the edge events' timestamps, so a contact that chatters for a few ms
 * gives one press. Press and release are both debounced.
 *
 * Fail-safe: an e-stop device that is unplugged, failed or cannot be
 * read reports pressed (px_dev_estop_read returns PX_E_NODEV with
 * *pressed = 1). With a loop attached (px_dev_attach) a pressed e-stop
 * calls px_loop_trip_estop() every cycle it is read as pressed, so the
 * loop enters safe state, cannot be re-armed while it is held, and stays
 * there after the release until an explicit px_loop_rearm() (automatic
 * re-arm never ends an e-stop's safe state).
 *
 * Memory: one allocation at create (plus libgpiod's own at open);
 * reading events and setting outputs in the cycle allocate nothing.
 */
#ifndef PX_GPIO_H
#define PX_GPIO_H

#include <stddef.h>
#include <stdint.h>

#include "px_base.h"
#include "px_dev.h"
#include "px_sim.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Line roles of a DIO device. */
enum px_gpio_role {
	PX_GPIO_ESTOP = 0,   /* input */
	PX_GPIO_ENABLE = 1,  /* output (PX_DIO_ENABLE) */
	PX_GPIO_TIMING = 2,  /* output (PX_DIO_TIMING) */
	PX_GPIO__ROLES = 3
};

struct px_gpio_line {
	int present;
	const char *line_name; /* kernel line name, or NULL to use offset */
	unsigned offset;
	int active_low;        /* logical 1 = physical low */
	int64_t debounce_ns;   /* e-stop only */
	int initial;           /* outputs: logical value at open */
};

struct px_gpio_config {
	const char *chip;      /* gpiod: "gpiochip0", "/dev/gpiochip0", label */
	struct px_gpio_line line[PX_GPIO__ROLES];
};

/* The debounce rule, alone (for tests and other inputs). */
struct px_debounce {
	int stable;          /* debounced level */
	int candidate;       /* newest raw level */
	int64_t since_ns;    /* when candidate was first seen */
	int64_t debounce_ns;
};
/* Start in level at t_ns. @note RT-safe. */
PX_API void px_debounce_init(struct px_debounce *db, int level,
			     int64_t debounce_ns);
/* A raw level seen at t_ns (edge event or sample, in time order). */
PX_API void px_debounce_feed(struct px_debounce *db, int level, int64_t t_ns);
/* Debounced level at now_ns. @note RT-safe. */
PX_API int px_debounce_get(struct px_debounce *db, int64_t now_ns);

/*
 * Simulated GPIO lines: the roles of cfg (chip ignored), inputs driven
 * with px_gpio_sim_drive(), outputs read back with px_gpio_sim_output().
 * Faults (px_sim_fault windows on the time given to the reads):
 *   estop      the line held at pressed, after a short bounce;
 *   unplug     the device gone (e-stop reads pressed, PX_E_NODEV);
 *   drop, delay, duplicate, corrupt: the e-stop's edge events lost,
 *              late by delay_ns, repeated, or reporting the other edge.
 *              Each read also checks the line's level against the
 *              events: a lost, late or wrong event is corrected within
 *              one read and recorded (a press is never missed), a
 *              repeated one is counted as a duplicate;
 *   stuck      a welded contact: the e-stop line keeps its level (not
 *              detectable on one channel), and outputs keep theirs:
 *              writes that would change them fail with PX_E_IO and a
 *              record ("enable output stuck: readback differs"), as a
 *              relay's feedback contact shows it.
 * nan and bus_off do not apply to digital lines (PX_E_INVAL).
 * Returns PX_OK, PX_E_INVAL (msg says what), PX_E_NOMEM.
 */
PX_API int px_gpio_sim_create(const struct px_dev_config *dcfg,
			      const struct px_gpio_config *cfg,
			      const struct px_sim_fault *faults,
			      size_t n_faults, struct px_dev **out,
			      char *msg, size_t cap);
/* Set the physical level of input role at t_ns (queued in time order;
 * at most 64 pending). Any time before the cycle that reads it; same
 * thread. Returns PX_OK, PX_E_NOSPC, PX_E_INVAL. */
PX_API int px_gpio_sim_drive(struct px_dev *d, int role, int physical,
			     int64_t t_ns);
/* Physical level of output role now (-1 if the role is absent). */
PX_API int px_gpio_sim_output(struct px_dev *d, int role);

/*
 * libgpiod lines. Opens the chip and requests the lines now (consumer
 * "proxima"): e-stop with both-edge events, outputs driven to their
 * initial values. On failure msg names the chip/line, the libgpiod call
 * and the errno, with a hint (no /dev/gpiochip*, permissions, line
 * busy). Returns PX_OK, PX_E_NOTFOUND, PX_E_PERM, PX_E_BUSY, PX_E_IO,
 * PX_E_INVAL, PX_E_NOMEM; *sys_errno (may be NULL) gets the errno.
 */
PX_API int px_gpiod_create(const struct px_dev_config *dcfg,
			   const struct px_gpio_config *cfg,
			   struct px_dev **out, int *sys_errno, char *msg,
			   size_t cap);

/* One line per GPIO chip (name, label, line count) and, with lines set,
 * one per line (offset, name, consumer, direction). Returns the chip
 * count, or PX_E_NOTFOUND when there is no chip. Not for the cycle. */
PX_API int px_gpiod_list(int lines, void (*fn)(void *user, const char *line),
			 void *user);
/* Version string of the linked libgpiod. */
PX_API const char *px_gpiod_version(void);

#ifdef __cplusplus
}
#endif

#endif
