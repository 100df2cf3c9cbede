/* proxima-probe: list the devices proxima can use - HID devices (hidapi),
 * USB devices (libusb), CAN interfaces with their state, GPIO chips (and
 * lines with --lines). A subsystem that is absent gets one clear line. */
#include <errno.h>
#include <net/if.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include <linux/can.h>

#include "px_can.h"
#include "px_features.h"
#include "px_gpio.h"
#include "px_hid.h"
#include "px_usb.h"

static void print_item(void *user, const char *line)
{
	printf("%s  %s\n", (const char *)user, line);
}

static int sys_type(const char *ifname)
{
	char p[300];
	FILE *f;
	int t = -1;
	snprintf(p, sizeof p, "/sys/class/net/%s/type", ifname);
	f = fopen(p, "r");
	if (!f)
		return -1;
	if (fscanf(f, "%d", &t) != 1)
		t = -1;
	fclose(f);
	return t;
}

static void probe_hid(void)
{
	int n;
	if (!PX_HAVE_HIDAPI) {
		printf("hid: this build has no HID back end (built without "
		       "hidapi)\n");
		return;
	}
	n = px_hid_list(print_item, "hid:");
	if (n < 0)
		printf("hid: hidapi (%s) could not start: %s\n",
		       px_hid_driver_name(), px_strerror(n));
	else if (n == 0)
		printf("hid: no HID devices (hidapi %s%s)\n", px_hid_driver_name(),
		       px_hid_driver() == PX_HID_HIDRAW &&
				       access("/dev/hidraw0", F_OK) != 0
			       ? "; no /dev/hidraw* nodes"
			       : "");
}

static void probe_usb(void)
{
	char msg[200];
	int n = px_usb_list(print_item, "usb:", msg, sizeof msg);
	if (n < 0)
		printf("usb: USB not available here: %s%s\n", msg,
		       access("/dev/bus/usb", F_OK) != 0
			       ? " (no /dev/bus/usb: no USB in this machine "
				 "or container)"
			       : "");
	else if (n == 0)
		printf("usb: no USB devices%s\n",
		       access("/dev/bus/usb", F_OK) != 0
			       ? " (no /dev/bus/usb: no USB in this machine or "
				 "container)"
			       : "");
}

static void probe_can(void)
{
	struct if_nameindex *ifs, *p;
	int s = socket(PF_CAN, SOCK_RAW, CAN_RAW), e = errno, n = 0;
	if (s < 0) {
		const char *nm = strerrorname_np(e);
		if (e == EAFNOSUPPORT || e == EPROTONOSUPPORT)
			printf("can: this kernel has no AF_CAN support (socket: "
			       "errno %s (%d)); modprobe can can-raw, and vcan "
			       "for a virtual bus\n", nm ? nm : "?", e);
		else
			printf("can: cannot open a CAN socket: errno %s (%d): "
			       "%s\n", nm ? nm : "?", e, strerror(e));
		return;
	}
	close(s);
	ifs = if_nameindex();
	for (p = ifs; p && p->if_index; p++) {
		int st;
		/* ARPHRD_CAN */
		if (sys_type(p->if_name) != 280)
			continue;
		n++;
		if (px_can_iface_state(p->if_name, &st) == PX_OK)
			printf("can:  %s state %s\n", p->if_name,
			       px_can_state_name(st));
		else
			printf("can:  %s (no controller state: virtual)\n",
			       p->if_name);
	}
	if (ifs)
		if_freenameindex(ifs);
	if (!n)
		printf("can: AF_CAN is available but there is no CAN interface "
		       "(ip link add dev vcan0 type vcan for a virtual one)\n");
}

static void probe_gpio(int lines)
{
	int n;
	if (!PX_HAVE_GPIOD) {
		printf("gpio: this build has no GPIO back end (built without "
		       "libgpiod)\n");
		return;
	}
	n = px_gpiod_list(lines, print_item, "gpio:");
	if (n == PX_E_NOTFOUND)
		printf("gpio: no GPIO chips (no /dev/gpiochip*; libgpiod %s)\n",
		       px_gpiod_version());
	else if (n < 0)
		printf("gpio: cannot list GPIO chips: %s\n", px_strerror(n));
}

int main(int argc, char **argv)
{
	int i, lines = 0;
	for (i = 1; i < argc; i++) {
		if (!strcmp(argv[i], "--lines")) {
			lines = 1;
		} else if (!strcmp(argv[i], "-h") || !strcmp(argv[i], "--help")) {
			printf("usage: proxima-probe [--lines]\n"
			       "Lists HID devices (hidapi), USB devices "
			       "(libusb), CAN interfaces and GPIO chips\n"
			       "(--lines: and each GPIO line). Every output "
			       "line starts with its subsystem.\n");
			return 0;
		} else {
			fprintf(stderr, "proxima-probe: unknown option %s "
				"(try --help)\n", argv[i]);
			return 2;
		}
	}
	probe_hid();
	probe_usb();
	probe_can();
	probe_gpio(lines);
	return 0;
}
