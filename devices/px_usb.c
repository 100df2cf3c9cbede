/* USB through libusb-1.0. Every libusb call of the library is here. */
#include <stdio.h>
#include <string.h>

#include <libusb.h>

#include "px_usb.h"

int px_usb_list(void (*fn)(void *user, const char *line), void *user,
		char *msg, size_t cap)
{
	libusb_context *ctx = NULL;
	libusb_device **list = NULL;
	ssize_t n, i;
	int rc;
	char line[300];
	if (msg && cap)
		msg[0] = 0;
	if (!fn)
		return PX_E_INVAL;
	rc = libusb_init(&ctx);
	if (rc != 0) {
		if (msg)
			snprintf(msg, cap, "libusb_init: %s (%s)",
				 libusb_error_name(rc), libusb_strerror(rc));
		return rc == LIBUSB_ERROR_NOT_SUPPORTED ? PX_E_UNSUPPORTED
							: PX_E_IO;
	}
	n = libusb_get_device_list(ctx, &list);
	if (n < 0) {
		if (msg)
			snprintf(msg, cap, "libusb_get_device_list: %s",
				 libusb_error_name((int)n));
		libusb_exit(ctx);
		return PX_E_IO;
	}
	for (i = 0; i < n; i++) {
		struct libusb_device_descriptor dd;
		libusb_device_handle *h = NULL;
		unsigned char prod[128] = "";
		if (libusb_get_device_descriptor(list[i], &dd) != 0)
			continue;
		if (dd.iProduct && libusb_open(list[i], &h) == 0) {
			if (libusb_get_string_descriptor_ascii(
				    h, dd.iProduct, prod, sizeof prod) < 0)
				prod[0] = 0;
			libusb_close(h);
		}
		snprintf(line, sizeof line,
			 "bus %03u address %03u %04x:%04x class %02x%s%s%s",
			 libusb_get_bus_number(list[i]),
			 libusb_get_device_address(list[i]), dd.idVendor,
			 dd.idProduct, dd.bDeviceClass, prod[0] ? " \"" : "",
			 (const char *)prod, prod[0] ? "\"" : "");
		fn(user, line);
	}
	libusb_free_device_list(list, 1);
	libusb_exit(ctx);
	return (int)n;
}
