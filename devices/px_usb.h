/*
 * px_usb.h - USB vendor devices through libusb-1.0 (every libusb call is
 * in px_usb.c), and device listing for proxima-probe.
 *
 * px_usb_create() opens the device by VID:PID (and serial), detaches the
 * kernel driver when asked, claims the interface, and makes a px_dev
 * whose input frames (frame_len bytes from endpoint_in) go through the
 * report codec (px_codec.h) exactly as HID reports do. px_dev_start()
 * starts a libusb event thread that keeps n_transfers asynchronous
 * interrupt or bulk IN transfers in flight, stamping each completed frame
 * with CLOCK_MONOTONIC, and a writer thread for output frames (the cycle
 * only encodes and hands over). Unplug (LIBUSB_ERROR_NO_DEVICE or a
 * transfer reporting no device) marks the device unplugged: samples go
 * stale and the loop into safe state; the event thread reopens it and
 * marks it running again (the loop resumes after re-arm). Where libusb
 * has hotplug (libusb_has_capability(LIBUSB_CAP_HAS_HOTPLUG)) and
 * no_hotplug is 0, arrival and departure callbacks for the VID:PID make
 * the reopen immediate and the unplug visible at once; a reopen attempt
 * every 200 ms stays as the fallback, because arrival events need udev,
 * which containers and minimal systems lack.
 *
 * Memory: libusb allocates on its own threads and at open; the cycle
 * side allocates nothing. Listing allocates (not for the cycle).
 */
#ifndef PX_USB_H
#define PX_USB_H

#include <stddef.h>

#include <stdint.h>

#include "px_base.h"
#include "px_dev.h"

#ifdef __cplusplus
extern "C" {
#endif

/*
 * Call fn once per USB device with "bus B address A VID:PID class C"
 * (and the product string where readable). Returns the device count,
 * or PX_E_UNSUPPORTED / PX_E_IO when libusb cannot start (no USB in
 * this machine or container); msg (cap bytes, may be NULL) says why.
 */
enum px_usb_transfer {
	PX_USB_INTERRUPT = 0,
	PX_USB_BULK = 1
};

struct px_usb_config {
	uint16_t vid, pid;
	const char *serial;        /* NULL = any */
	int interface;             /* >= 0 */
	uint8_t endpoint_in;       /* 0x81..0x8f */
	uint8_t endpoint_out;      /* 0x01..0x0f, 0 = none */
	int transfer;              /* enum px_usb_transfer */
	size_t frame_len;          /* bytes of one input frame, 1..1024 */
	int detach_kernel_driver;  /* let go of e.g. usbhid first */
	int n_transfers;           /* IN transfers in flight (default 4) */
	int no_hotplug;            /* 1: find a replugged device by polling
				    * only (see below) */
};

/*
 * Open and claim now (a missing device is reported at setup); reading
 * starts with px_dev_start(). dcfg->codec is required. Returns PX_OK,
 * PX_E_INVAL, PX_E_NOTFOUND ("no USB device 1234:0001 (N USB devices
 * present...)"), PX_E_PERM (udev rule hint), PX_E_BUSY (interface
 * claimed by a driver: detach_kernel_driver), PX_E_UNSUPPORTED (libusb
 * cannot start here), PX_E_IO, PX_E_NOMEM; msg says which and why.
 */
PX_API int px_usb_create(const struct px_dev_config *dcfg,
			 const struct px_usb_config *uc, struct px_dev **out,
			 char *msg, size_t cap);

/* 1 when d's hotplug callbacks are registered (0: polling only), or
 * PX_E_INVAL when d is not a libusb device. */
PX_API int px_usb_hotplug_active(struct px_dev *d);

PX_API int px_usb_list(void (*fn)(void *user, const char *line), void *user,
		       char *msg, size_t cap);

#ifdef __cplusplus
}
#endif

#endif
