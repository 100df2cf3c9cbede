/* HID back end over hidapi. Here (no HID devices) the open paths must give
 * clear errors. Where /dev/uhid exists (the VM suite) a virtual HID
 * device is created through it and the real back end reads its input
 * reports, writes output reports, and sees it unplugged. */
/* PX_TEST_NEEDS: hidapi (tests/run.sh skips it in builds without) */
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <linux/uhid.h>

#include "px_dev.h"
#include "px_hid.h"
#include "px_test.h"
#include "px_test_dev.h"
#include "../../vm/haptic_rd.h"

static void test_open_by_vid_pid_not_found(void)
{
	struct px_dev_config c;
	struct px_hid_config h;
	struct px_dev *d = (struct px_dev *)1;
	char msg[300];
	int rc;
	px_dev_config_default(&c);
	c.name = "spacemouse";
	c.codec = px_codec_builtin("spacemouse");
	memset(&h, 0, sizeof h);
	h.has_vid_pid = 1;
	h.vid = 0x256f;
	h.pid = 0xc635;
	h.driver = px_hid_driver();
	rc = px_hid_create(&c, &h, &d, msg, sizeof msg);
	if (rc == PX_OK) {
		px_dev_free(d);
		PX_SKIP("a real 256f:c635 device is attached");
	}
	PX_CHECK_INT_EQ(rc, PX_E_NOTFOUND);
	PX_CHECK(d == NULL);
	PX_CHECK_MSG(strstr(msg, "spacemouse: no HID device 256f:c635 found") &&
			     strstr(msg, "proxima-probe"), "%s", msg);
	h.serial = "SN123";
	rc = px_hid_create(&c, &h, &d, msg, sizeof msg);
	PX_CHECK_INT_EQ(rc, PX_E_NOTFOUND);
	PX_CHECK_MSG(strstr(msg, "256f:c635 serial SN123") != NULL, "%s", msg);
}

static void test_open_by_path_gives_errno(void)
{
	struct px_dev_config c;
	struct px_hid_config h;
	struct px_dev *d;
	char msg[300];
	int rc;
	px_dev_config_default(&c);
	c.name = "haptic";
	c.codec = px_codec_builtin("haptic");
	memset(&h, 0, sizeof h);
	h.path = "/dev/hidraw-proxima-absent";
	h.driver = px_hid_driver();
	rc = px_hid_create(&c, &h, &d, msg, sizeof msg);
	PX_CHECK_MSG(rc == PX_E_NOTFOUND || rc == PX_E_IO, "rc %d: %s", rc,
		     msg);
	PX_CHECK_MSG(strstr(msg, "haptic: cannot open HID device "
				 "/dev/hidraw-proxima-absent") != NULL,
		     "%s", msg);
	if (px_hid_driver() == PX_HID_HIDRAW)
		PX_CHECK_MSG(strstr(msg, "No such file or directory") != NULL,
			     "%s", msg);
}

static void test_config_errors(void)
{
	struct px_dev_config c;
	struct px_hid_config h;
	struct px_dev *d;
	char msg[300];
	px_dev_config_default(&c);
	c.name = "x";
	c.codec = px_codec_builtin("haptic");
	memset(&h, 0, sizeof h);
	h.has_vid_pid = 1;
	h.driver = px_hid_driver() == PX_HID_HIDRAW ? PX_HID_LIBUSB
						    : PX_HID_HIDRAW;
	PX_CHECK_INT_EQ(px_hid_create(&c, &h, &d, msg, sizeof msg),
			PX_E_UNSUPPORTED);
	PX_CHECK_MSG(strstr(msg, "rebuild with make HIDAPI=") != NULL, "%s",
		     msg);
	h.driver = px_hid_driver();
	h.has_vid_pid = 0;
	PX_CHECK_INT_EQ(px_hid_create(&c, &h, &d, msg, sizeof msg),
			PX_E_INVAL);
	PX_CHECK(strstr(msg, "vid:pid or a path") != NULL);
	c.codec = NULL;
	h.has_vid_pid = 1;
	PX_CHECK_INT_EQ(px_hid_create(&c, &h, &d, msg, sizeof msg),
			PX_E_INVAL);
	PX_CHECK(strcmp(px_hid_driver_name(), "hidraw") == 0 ||
		 strcmp(px_hid_driver_name(), "libusb") == 0);
}

/* ---- through /dev/uhid ------------------------------------------------ */

/* Wait (bounded) for a uhid event of type want; returns 0 or -1. */
static int uhid_wait(int fd, uint32_t want, struct uhid_event *ev, int ms)
{
	while (ms > 0) {
		struct pollfd p = {fd, POLLIN, 0};
		int r = poll(&p, 1, 100);
		ms -= 100;
		if (r <= 0)
			continue;
		if (read(fd, ev, sizeof *ev) <= 0)
			return -1;
		if (ev->type == want)
			return 0;
	}
	return -1;
}

static void test_uhid_device_roundtrip(void)
{
	struct uhid_event ev;
	struct px_dev_config c;
	struct px_hid_config h;
	struct px_dev *d = NULL;
	struct px_pose_sample s;
	struct px_force_cmd cmd = {{1.5, -0.25, 7.0}, {0, 0, 0}, 1};
	struct px_dev_status st;
	const struct px_codec_map *m = px_codec_builtin("haptic");
	char msg[300];
	int fd, rc = PX_E_NOTFOUND, i, k;
	if (px_hid_driver() == PX_HID_LIBUSB)
		PX_SKIP("uhid devices are not USB; hidapi-libusb is tested on "
			"the USB gadget");
	fd = open("/dev/uhid", O_RDWR | O_CLOEXEC);
	if (fd < 0)
		PX_SKIP("no /dev/uhid (%s): the VM suite runs this",
			strerror(errno));
	memset(&ev, 0, sizeof ev);
	ev.type = UHID_CREATE2;
	snprintf((char *)ev.u.create2.name, sizeof ev.u.create2.name,
		 "proxima test haptic");
	memcpy(ev.u.create2.rd_data, haptic_rd, sizeof haptic_rd);
	ev.u.create2.rd_size = sizeof haptic_rd;
	ev.u.create2.bus = 0x03; /* BUS_USB */
	ev.u.create2.vendor = 0x1234;
	ev.u.create2.product = 0x0001;
	PX_CHECK(write(fd, &ev, sizeof ev) == (ssize_t)sizeof ev);
	PX_CHECK_INT_EQ(uhid_wait(fd, UHID_START, &ev, 5000), 0);
	px_dev_config_default(&c);
	c.name = "uhid-haptic";
	c.codec = m;
	c.stale_timeout_ns = 1000000000;
	memset(&h, 0, sizeof h);
	h.has_vid_pid = 1;
	h.vid = 0x1234;
	h.pid = 0x0001;
	h.driver = px_hid_driver();
	for (i = 0; i < 50 && rc != PX_OK; i++) { /* node appears async */
		rc = px_hid_create(&c, &h, &d, msg, sizeof msg);
		if (rc != PX_OK)
			px_test_wait_ms(100);
	}
	PX_CHECK_MSG(rc == PX_OK, "%s", msg);
	PX_CHECK_INT_EQ(px_dev_start(d), PX_OK);
	/* input reports sent before UHID_OPEN are dropped */
	PX_CHECK_INT_EQ(uhid_wait(fd, UHID_OPEN, &ev, 5000), 0);
	for (k = 1; k <= 20; k++) {
		double a[6] = {k * 1e-3, -k * 2e-3, 0.25, 0, 0, 0};
		int n;
		memset(&ev, 0, sizeof ev);
		ev.type = UHID_INPUT2;
		n = px_codec_encode_input(m, 1, a, (uint64_t)k & 15,
					  ev.u.input2.data,
					  sizeof ev.u.input2.data);
		PX_CHECK(n == 14);
		ev.u.input2.size = (uint16_t)n;
		PX_CHECK(write(fd, &ev, sizeof ev) == (ssize_t)sizeof ev);
	}
	for (i = 0; i < 500; i++) {
		px_dev_pose_read(d, px_dev_mono_ns(), &s);
		if (s.seq >= 1 && s.pos_m.x > 0.0199)
			break;
		px_test_wait_ms(10);
	}
	PX_CHECK_NEAR(s.pos_m.x, 0.020, 1e-12);
	PX_CHECK_NEAR(s.pos_m.y, -0.040, 1e-12);
	PX_CHECK_NEAR(s.pos_m.z, 0.25, 1e-12);
	PX_CHECK_INT_EQ(s.buttons, 20 & 15);
	PX_CHECK(s.valid);
	/* output report: 1.5 N, -0.25 N, 7 N clamped to 3 N, in mN */
	PX_CHECK_INT_EQ(px_dev_force_write(d, &cmd, px_dev_mono_ns()), PX_OK);
	PX_CHECK_INT_EQ(uhid_wait(fd, UHID_OUTPUT, &ev, 5000), 0);
	PX_CHECK_INT_EQ(ev.u.output.size, 7);
	PX_CHECK_INT_EQ(ev.u.output.data[0], 2);
	PX_CHECK_INT_EQ(ev.u.output.data[1] | (ev.u.output.data[2] << 8), 1500);
	PX_CHECK_INT_EQ(ev.u.output.data[5] | (ev.u.output.data[6] << 8), 3000);
	/* the safe output: sent by the I/O thread, confirmed by hidapi's
	 * byte count, and the last report the device gets is zero */
	PX_CHECK_INT_EQ(px_dev_force_write(d, &cmd, px_dev_mono_ns()), PX_OK);
	PX_CHECK_INT_EQ(px_dev_safe(d, px_dev_mono_ns()), PX_OK);
	{
		uint8_t last[7] = {0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff};
		int got = 0;
		while (uhid_wait(fd, UHID_OUTPUT, &ev, 300) == 0) {
			memcpy(last, ev.u.output.data, 7);
			got++;
		}
		PX_CHECK(got >= 1);
		PX_CHECK_INT_EQ(last[0], 2);
		for (k = 1; k < 7; k++)
			PX_CHECK_INT_EQ(last[k], 0);
	}
	px_dev_status(d, &st);
	PX_CHECK_INT_EQ(st.outputs_safe, 1);
	/* unplug: the reader sees it, the cycle gets PX_E_NODEV */
	memset(&ev, 0, sizeof ev);
	ev.type = UHID_DESTROY;
	PX_CHECK(write(fd, &ev, sizeof ev) == (ssize_t)sizeof ev);
	for (i = 0; i < 300; i++) {
		if (px_dev_pose_read(d, px_dev_mono_ns(), &s) == PX_E_NODEV)
			break;
		px_test_wait_ms(10);
	}
	PX_CHECK(!s.valid && s.stale);
	px_dev_status(d, &st);
	PX_CHECK_INT_EQ(st.unplugs, 1);
	PX_CHECK_MSG(strstr(st.last_msg, "uhid-haptic (hidapi)") != NULL, "%s",
		     st.last_msg);
	px_dev_free(d);
	close(fd);
}

/* Unbind the gadget's UDC (an unplug) and bind it again (a replug). The
 * back end must report the device stale and unplugged, then reopen it and
 * deliver reports again, with either hidapi build. hidapi-libusb's libusb
 * context learns of new devices only from udevd, which the guest does not
 * run: this proves the back end's fresh context before a reopen. */
static void gadget_unplug_replug(struct px_dev *d, const char *gdir,
				 const char *udc, const char *hidg)
{
	const struct px_codec_map *m = px_codec_builtin("haptic");
	double a[6] = {0.007, 0.001, -0.002, 0, 0, 0};
	struct px_pose_sample s;
	struct px_dev_status st;
	uint8_t rep[64];
	int64_t t_end;
	int n, fd, rc = 0;
	PX_CHECK_INT_EQ(px_test_write_file(gdir, "UDC", "\n"), 0);
	for (t_end = px_test_deadline_ms(10000);;) {
		rc = px_dev_pose_read(d, px_dev_mono_ns(), &s);
		if (rc == PX_E_NODEV || px_test_past(t_end))
			break;
		px_test_wait_ms(10);
	}
	PX_CHECK_INT_EQ(rc, PX_E_NODEV);
	PX_CHECK(!s.valid && s.stale);
	PX_CHECK_INT_EQ(px_test_write_file(gdir, "UDC", udc), 0);
	/* re-enumeration on a loaded guest once took more than 5 s */
	for (t_end = px_test_deadline_ms(30000);
	     px_dev_state(d) != PX_DEV_STATE_RUNNING && !px_test_past(t_end);)
		px_test_wait_ms(10);
	PX_CHECK_INT_EQ(px_dev_state(d), PX_DEV_STATE_RUNNING);
	fd = open(hidg, O_RDWR);
	PX_CHECK_MSG(fd >= 0, "%s: %s", hidg, strerror(errno));
	n = px_codec_encode_input(m, 1, a, 9, rep, sizeof rep);
	for (t_end = px_test_deadline_ms(10000);;) {
		if (write(fd, rep, (size_t)n) != n)
			px_test_wait_ms(5);
		px_dev_pose_read(d, px_dev_mono_ns(), &s);
		if ((s.valid && s.buttons == 9) || px_test_past(t_end))
			break;
		px_test_wait_ms(10);
	}
	PX_CHECK(s.valid && !s.stale);
	PX_CHECK_NEAR(s.pos_m.x, 0.007, 1e-12);
	PX_CHECK_INT_EQ(s.buttons, 9);
	px_dev_status(d, &st);
	PX_CHECK_INT_EQ(st.unplugs, 1);
	PX_CHECK_INT_EQ(st.replugs, 1);
	close(fd);
}

static void test_usb_hid_gadget(void)
{
	/* A configfs USB HID gadget (PX_TEST_USB_VIDPID, PX_TEST_HIDG): seen
	 * by hidraw through usbhid, or by hidapi-libusb directly. */
	const char *vp = getenv("PX_TEST_USB_VIDPID");
	const char *hidg = getenv("PX_TEST_HIDG");
	const char *gdir = getenv("PX_TEST_GADGET_DIR");
	const char *udc = getenv("PX_TEST_UDC");
	const struct px_codec_map *m = px_codec_builtin("haptic");
	struct px_dev_config c;
	struct px_hid_config h;
	struct px_dev *d = NULL;
	struct px_pose_sample s;
	double a[6] = {-0.004, 0.002, 0.5, 0, 0, 0};
	uint8_t rep[64];
	unsigned vid, pid;
	char msg[300];
	int fd, n, i, rc = PX_E_NOTFOUND;
	if (!vp || !hidg || sscanf(vp, "%x:%x", &vid, &pid) != 2)
		PX_SKIP("PX_TEST_USB_VIDPID/PX_TEST_HIDG not set: the VM suite "
			"runs this on a USB HID gadget");
	px_dev_config_default(&c);
	c.name = "gadget-hid";
	c.codec = m;
	c.stale_timeout_ns = 1000000000;
	memset(&h, 0, sizeof h);
	h.has_vid_pid = 1;
	h.vid = (uint16_t)vid;
	h.pid = (uint16_t)pid;
	h.driver = px_hid_driver();
	for (i = 0; i < 50 && rc != PX_OK; i++) {
		rc = px_hid_create(&c, &h, &d, msg, sizeof msg);
		if (rc != PX_OK)
			px_test_wait_ms(100);
	}
	PX_CHECK_MSG(rc == PX_OK, "%s", msg);
	PX_CHECK_INT_EQ(px_dev_start(d), PX_OK);
	fd = open(hidg, O_RDWR);
	PX_CHECK_MSG(fd >= 0, "%s: %s", hidg, strerror(errno));
	n = px_codec_encode_input(m, 1, a, 3, rep, sizeof rep);
	for (i = 0; i < 300; i++) {
		if (write(fd, rep, (size_t)n) != n)
			px_test_wait_ms(5);
		px_dev_pose_read(d, px_dev_mono_ns(), &s);
		if (s.seq > 0)
			break;
		px_test_wait_ms(10);
	}
	PX_CHECK(s.valid);
	PX_CHECK_NEAR(s.pos_m.x, -0.004, 1e-12);
	PX_CHECK_NEAR(s.pos_m.z, 0.5, 1e-12);
	PX_CHECK_INT_EQ(s.buttons, 3);
	/* output report 2 through the back end, read by the gadget:
	 * 1.5 N, -0.25 N, 7 N clamped to 3 N, in mN */
	{
		struct px_force_cmd cmd = {{1.5, -0.25, 7.0}, {0, 0, 0}, 1};
		struct pollfd p = {fd, POLLIN, 0};
		/* the gadget may still hold the safe (zero) report an earlier
		 * program's device sent when it was freed: not this one's */
		while (poll(&p, 1, 200) == 1 && read(fd, rep, sizeof rep) > 0)
			;
		PX_CHECK_INT_EQ(px_dev_force_write(d, &cmd, px_dev_mono_ns()),
				PX_OK);
		PX_CHECK(poll(&p, 1, 5000) == 1);
		n = (int)read(fd, rep, sizeof rep);
		PX_CHECK_INT_EQ(n, 7);
		PX_CHECK_INT_EQ(rep[0], 2);
		PX_CHECK_INT_EQ(rep[1] | (rep[2] << 8), 1500);
		PX_CHECK_INT_EQ((int16_t)(rep[3] | (rep[4] << 8)), -250);
		PX_CHECK_INT_EQ(rep[5] | (rep[6] << 8), 3000);
	}
	close(fd);
	if (gdir && udc)
		gadget_unplug_replug(d, gdir, udc, hidg);
	px_dev_free(d);
}

static const struct px_test tests[] = {
	PX_T(test_usb_hid_gadget),
	PX_T(test_open_by_vid_pid_not_found),
	PX_T(test_open_by_path_gives_errno),
	PX_T(test_config_errors),
	PX_T(test_uhid_device_roundtrip),
};

PX_TEST_MAIN(tests)
