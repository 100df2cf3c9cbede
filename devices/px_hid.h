/*
 * px_hid.h - USB/Bluetooth HID devices through hidapi: a pose source
 * (and force sink when the codec map has outputs) whose reports go
 * through the report codec (px_codec.h).
 *
 * The device is opened by VID:PID (with an optional serial number) or
 * by path (/dev/hidrawN for the hidraw build, "bus:addr:iface" style for
 * the libusb build; proxima-probe lists both). hidapi comes as two
 * builds exporting the same symbols, so one is linked: hidraw by
 * default, libusb with `make HIDAPI=libusb`; px_hid_driver() says which,
 * and asking for the other one is a clear PX_E_UNSUPPORTED.
 *
 * Threads: px_dev_start() starts one I/O thread that makes every hidapi
 * call for the device (hidapi's per-device error string makes concurrent
 * read and write unsafe): hid_read_timeout with 1 ms, stamping each
 * report with CLOCK_MONOTONIC on arrival and feeding it through the
 * codec, then the newest output report if there is one. The cycle's
 * px_dev_force_write() only encodes the output report and hands it over
 * (triple buffer), because hidapi calls may allocate; it goes out within
 * about 1 ms.
 * A failed read marks the device unplugged (stale, PX_E_NODEV to the
 * cycle; the loop goes to safe state); the reader then tries to reopen
 * every 200 ms and marks it running again when it is back (the loop
 * resumes after its re-arm).
 * Replug without udevd: hidapi-libusb keeps one libusb context per
 * process, and Debian's libusb learns of new devices only from udevd's
 * events, so where none runs (containers, minimal guests) that context
 * never sees a replugged device. So before each reopen attempt of the
 * libusb build, when this back end holds no hidapi handle open (every
 * HID device of the process is unplugged or freed; code that calls hidapi
 * itself in the same process must not hold one either), the reader
 * re-initialises hidapi (hid_exit + hid_init: a fresh context that scans
 * sysfs again).
 * While another HID device of the process stays open there, an unplugged
 * one comes back only if udevd runs. All hidapi initialisation,
 * enumeration, open and close go through one process-wide lock, never
 * taken by the cycle.
 *
 * Memory: hidapi allocates inside its own calls on the reader/writer
 * threads and at open; the cycle side allocates nothing.
 */
#ifndef PX_HID_H
#define PX_HID_H

#include <stddef.h>
#include <stdint.h>

#include "px_base.h"
#include "px_dev.h"

#ifdef __cplusplus
extern "C" {
#endif

enum px_hid_driver {
	PX_HID_HIDRAW = 0,
	PX_HID_LIBUSB = 1
};

struct px_hid_config {
	int has_vid_pid;     /* open by vid:pid (else by path) */
	uint16_t vid, pid;
	const char *serial;  /* NULL = any device with that vid:pid */
	const char *path;    /* used when !has_vid_pid */
	int driver;          /* enum px_hid_driver; must match the build */
};

/* The hidapi build linked in (enum px_hid_driver) and its name. */
PX_API int px_hid_driver(void);
PX_API const char *px_hid_driver_name(void);

/*
 * Open a HID device now (so a missing device is reported at setup) and
 * create its px_dev; reading starts with px_dev_start(). dcfg->codec is
 * required. On failure msg (cap bytes, may be NULL) says what and why,
 * with the raw errno where there is one, e.g. "spacemouse: no HID
 * device 256f:c635 found (0 HID devices present; proxima-probe lists
 * them)". Returns PX_OK, PX_E_INVAL, PX_E_UNSUPPORTED (other driver),
 * PX_E_NOTFOUND, PX_E_PERM (found, no permission: udev rule hint),
 * PX_E_IO, PX_E_NOMEM.
 */
PX_API int px_hid_create(const struct px_dev_config *dcfg,
			 const struct px_hid_config *hc, struct px_dev **out,
			 char *msg, size_t cap);

/* One line per HID device (VID:PID, usage page/usage, interface, path,
 * product) written to fn; for tools. fn is called with the back end's
 * hidapi lock held, so it must not call px_hid functions. Returns the
 * device count, or a negative error. Not for the cycle. */
PX_API int px_hid_list(void (*fn)(void *user, const char *line), void *user);

#ifdef __cplusplus
}
#endif

#endif
