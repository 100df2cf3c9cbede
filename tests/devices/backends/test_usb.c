/* libusb back end: clear errors here (no USB). With a USB HID gadget (the
 * VM suite: PX_TEST_USB_VIDPID=vvvv:pppp, PX_TEST_HIDG=/dev/hidg0, and for
 * unplug/replug PX_TEST_GADGET_DIR + PX_TEST_UDC) the real back end claims
 * the interface, reads frames and sees an unplug and a replug. */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "px_dev.h"
#include "px_sim.h"
#include "px_usb.h"
#include "px_test.h"
#include "px_test_dev.h"

static struct px_usb_config base_cfg(void)
{
	struct px_usb_config u;
	memset(&u, 0, sizeof u);
	u.vid = 0x1234;
	u.pid = 0x0001;
	u.interface = 0;
	u.endpoint_in = 0x81;
	u.endpoint_out = 0x01;
	u.transfer = PX_USB_INTERRUPT;
	u.frame_len = 64;
	u.detach_kernel_driver = 1;
	return u;
}

static void test_open_errors(void)
{
	PX_NEEDS(LIBUSB);
	struct px_dev_config c;
	struct px_usb_config u = base_cfg();
	struct px_dev *d;
	char msg[300];
	int rc;
	px_dev_config_default(&c);
	c.name = "vendor";
	c.codec = px_codec_builtin("haptic");
	rc = px_usb_create(&c, &u, &d, msg, sizeof msg);
	if (rc == PX_OK) {
		px_dev_free(d);
		PX_SKIP("a real 1234:0001 device is attached");
	}
	PX_CHECK_MSG(rc == PX_E_NOTFOUND || rc == PX_E_UNSUPPORTED ||
			     rc == PX_E_IO, "rc %d: %s", rc, msg);
	if (rc == PX_E_NOTFOUND)
		PX_CHECK_MSG(strstr(msg, "vendor: no USB device 1234:0001 (") &&
				     strstr(msg, "proxima-probe"), "%s", msg);
	else
		PX_CHECK_MSG(strstr(msg, "vendor: libusb_init") != NULL, "%s",
			     msg);
	u.endpoint_in = 0x01; /* an OUT address */
	PX_CHECK_INT_EQ(px_usb_create(&c, &u, &d, msg, sizeof msg), PX_E_INVAL);
	PX_CHECK(strstr(msg, "endpoint_in 0x81..0x8f") != NULL);
	u = base_cfg();
	c.codec = NULL;
	PX_CHECK_INT_EQ(px_usb_create(&c, &u, &d, msg, sizeof msg), PX_E_INVAL);
}

/* Bounds of the waits (see px_test_dev.h); a replug on a loaded guest
 * once took more than 5 s. */
#define FRAME_WAIT_MS 10000
#define UNPLUG_WAIT_MS 10000
#define REPLUG_WAIT_MS 30000

/* no_hotplug 0: hotplug callbacks where libusb has them; 1: the 200 ms
 * reopen poll alone (the fallback for systems without udev). */
static void gadget_run(int no_hotplug)
{
	const char *vp = getenv("PX_TEST_USB_VIDPID");
	const char *hidg = getenv("PX_TEST_HIDG");
	const char *gdir = getenv("PX_TEST_GADGET_DIR");
	const char *udc = getenv("PX_TEST_UDC");
	const struct px_codec_map *m = px_codec_builtin("haptic");
	struct px_dev_config c;
	struct px_usb_config u = base_cfg();
	struct px_dev *d;
	struct px_pose_sample s;
	struct px_dev_status st;
	unsigned vid, pid;
	char msg[300];
	uint8_t rep[64];
	double a[6] = {0.003, -0.002, 0.001, 0, 0, 0};
	int64_t t_end;
	int fd, n, rc;
	if (!vp || !hidg || sscanf(vp, "%x:%x", &vid, &pid) != 2)
		PX_SKIP("PX_TEST_USB_VIDPID/PX_TEST_HIDG not set: the VM suite "
			"runs this on a USB HID gadget");
	u.vid = (uint16_t)vid;
	u.pid = (uint16_t)pid;
	u.endpoint_out = 0;
	u.no_hotplug = no_hotplug;
	px_dev_config_default(&c);
	c.name = "gadget";
	c.codec = m;
	c.stale_timeout_ns = 1000000000;
	PX_CHECK_MSG((rc = px_usb_create(&c, &u, &d, msg, sizeof msg)) == PX_OK,
		     "%s", msg);
	if (no_hotplug)
		PX_CHECK_INT_EQ(px_usb_hotplug_active(d), 0);
	else
		printf("    hotplug callbacks: %s\n",
		       px_usb_hotplug_active(d) == 1 ? "registered"
						    : "not available (poll)");
	PX_CHECK_INT_EQ(px_dev_start(d), PX_OK);
	fd = open(hidg, O_RDWR);
	PX_CHECK_MSG(fd >= 0, "%s: %s", hidg, strerror(errno));
	n = px_codec_encode_input(m, 1, a, 5, rep, sizeof rep);
	PX_CHECK_INT_EQ(n, 14);
	for (t_end = px_test_deadline_ms(FRAME_WAIT_MS);;) {
		if (write(fd, rep, (size_t)n) != n)
			px_test_wait_ms(5);
		px_dev_pose_read(d, px_dev_mono_ns(), &s);
		if (s.seq > 0 || px_test_past(t_end))
			break;
		px_test_wait_ms(10);
	}
	PX_CHECK(s.valid);
	PX_CHECK_NEAR(s.pos_m.x, 0.003, 1e-12);
	PX_CHECK_INT_EQ(s.buttons, 5);
	if (gdir && udc) {
		PX_CHECK_INT_EQ(px_test_write_file(gdir, "UDC", "\n"), 0); /* unplug */
		for (t_end = px_test_deadline_ms(UNPLUG_WAIT_MS);;) {
			rc = px_dev_pose_read(d, px_dev_mono_ns(), &s);
			if (rc == PX_E_NODEV || px_test_past(t_end))
				break;
			px_test_wait_ms(10);
		}
		px_dev_status(d, &st);
		PX_CHECK_MSG(!s.valid && s.stale,
			     "after unplug: read %d, valid %d, stale %d, "
			     "state %d, unplugs %d: %s",
			     rc, s.valid, s.stale, px_dev_state(d),
			     (int)st.unplugs, st.last_msg);
		PX_CHECK_INT_EQ(px_test_write_file(gdir, "UDC", udc), 0); /* replug */
		for (t_end = px_test_deadline_ms(REPLUG_WAIT_MS);;) {
			px_dev_pose_read(d, px_dev_mono_ns(), &s);
			if (px_dev_state(d) == PX_DEV_STATE_RUNNING ||
			    px_test_past(t_end))
				break;
			px_test_wait_ms(10);
		}
		PX_CHECK_MSG(px_dev_state(d) == PX_DEV_STATE_RUNNING,
			     "not running %d s after the replug: state %d",
			     REPLUG_WAIT_MS / 1000, px_dev_state(d));
		px_dev_status(d, &st);
		PX_CHECK_INT_EQ(st.unplugs, 1);
		PX_CHECK_INT_EQ(st.replugs, 1);
	}
	close(fd);
	px_dev_free(d);
}

static void test_hid_gadget_frames_unplug_replug(void)
{
	gadget_run(0);
}

static void test_hid_gadget_replug_poll_fallback(void)
{
	gadget_run(1);
}

/* px_usb_hotplug_active refuses what is not a libusb device. */
static void test_hotplug_query_args(void)
{
	struct px_dev_config c;
	struct px_sim_haptic_config hc;
	struct px_dev *d = NULL;
	PX_CHECK_INT_EQ(px_usb_hotplug_active(NULL), PX_E_INVAL);
	px_dev_config_default(&c);
	c.name = "sim";
	px_sim_haptic_config_default(&hc);
	PX_CHECK_INT_EQ(px_sim_haptic_create(&c, &hc, &d, NULL, 0), PX_OK);
	PX_CHECK_INT_EQ(px_usb_hotplug_active(d), PX_E_INVAL);
	px_dev_free(d);
}

static const struct px_test tests[] = {
	PX_T(test_open_errors),
	PX_T(test_hid_gadget_frames_unplug_replug),
	PX_T(test_hid_gadget_replug_poll_fallback),
	PX_T(test_hotplug_query_args),
};

PX_TEST_MAIN(tests)
