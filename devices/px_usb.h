/*
 * px_usb.h - USB devices through libusb-1.0. For now: listing (for
 * proxima-probe). The vendor-device back end (claiming an interface,
 * asynchronous interrupt/bulk transfers on a libusb event thread,
 * hotplug) will live here too; every libusb call stays in px_usb.c.
 *
 * Not for the cycle: listing allocates (libusb's device list).
 */
#ifndef PX_USB_H
#define PX_USB_H

#include <stddef.h>

#include "px_base.h"

#ifdef __cplusplus
extern "C" {
#endif

/*
 * Call fn once per USB device with "bus B address A VID:PID class C"
 * (and the product string where readable). Returns the device count,
 * or PX_E_UNSUPPORTED / PX_E_IO when libusb cannot start (no USB in
 * this machine or container); msg (cap bytes, may be NULL) says why.
 */
PX_API int px_usb_list(void (*fn)(void *user, const char *line), void *user,
		       char *msg, size_t cap);

#ifdef __cplusplus
}
#endif

#endif
