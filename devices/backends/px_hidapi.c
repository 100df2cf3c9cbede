/* HID back end over hidapi. Every hidapi call of the library is in this
 * file. */
#include <errno.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <wchar.h>

#include <hidapi.h>

#include "px_arena.h"
#include "px_hid.h"
#include "px_param.h"
#include "dev_internal.h"

#ifndef PX_HIDAPI_DRIVER
#define PX_HIDAPI_DRIVER "hidraw"
#endif

#define REP_MAX 256
#define READ_TIMEOUT_MS 1
#define REOPEN_NS 200000000
#define SAFE_WAIT_NS 250000000 /* the I/O thread sends a safe output */

struct outrep {
	size_t len;
	uint8_t b[REP_MAX];
};

struct hid {
	struct px_hid_config cfg;
	char serial[128];
	char path[256];
	hid_device *h;
	pthread_t reader;
	int threads;
	atomic_int stop;
	struct px_arena arena;
	uint8_t arena_buf[4 * sizeof(struct outrep) + 512];
	struct px_param *out;
	/* Safe output: the shutdown side fills safe_rep, sets hold (no
	 * older command goes out after it) and bumps safe_req; the I/O
	 * thread sends it and answers with safe_rc and safe_ack. */
	struct outrep safe_rep;
	atomic_uint safe_req, safe_ack;
	atomic_int safe_rc, hold;
};

/* hidapi's library state (for hidapi-libusb, its one libusb context) is
 * process-wide: init, exit, enumerate, open and close all take this lock,
 * and n_open counts the handles this file holds open, so that the context
 * is only re-made when nothing uses it. */
static pthread_mutex_t hid_lock = PTHREAD_MUTEX_INITIALIZER;
static int init_done, init_rc, n_open;

/* Call with hid_lock held. */
static int lib_init_locked(void)
{
	if (!init_done) {
		init_rc = hid_init();
		init_done = 1;
	}
	return init_rc;
}

/* Debian's libusb learns of new devices only from udevd's events; where
 * none runs (containers, minimal guests) its context never sees a
 * replugged device. A new context scans sysfs again, so before a reopen
 * with hidapi-libusb, when no handle of the process uses the context,
 * hid_exit + hid_init replace it. hidapi-hidraw enumerates sysfs on every
 * call and needs none of this. Call with hid_lock held. */
static void lib_refresh_locked(void)
{
	if (px_hid_driver() != PX_HID_LIBUSB || n_open != 0 || !init_done)
		return;
	hid_exit();
	init_done = 0;
	lib_init_locked();
}

static void close_handle(hid_device *h)
{
	if (!h)
		return;
	pthread_mutex_lock(&hid_lock);
	hid_close(h);
	n_open--;
	pthread_mutex_unlock(&hid_lock);
}

int px_hid_driver(void)
{
	return strcmp(PX_HIDAPI_DRIVER, "libusb") == 0 ? PX_HID_LIBUSB
						       : PX_HID_HIDRAW;
}

const char *px_hid_driver_name(void)
{
	return PX_HIDAPI_DRIVER;
}

static int count_devices(void)
{
	struct hid_device_info *all = hid_enumerate(0, 0), *p;
	int n = 0;
	for (p = all; p; p = p->next)
		n++;
	hid_free_enumeration(all);
	pthread_mutex_unlock(&hid_lock);
	return n;
}

/* Find the path of the matching device, so that "not there" and "there
 * but cannot be opened" give different answers. */
static int find_path(const struct hid *x, char *path, size_t cap)
{
	struct hid_device_info *all, *p;
	int found = 0;
	wchar_t ws[128];
	if (x->cfg.serial && mbstowcs(ws, x->cfg.serial, 127) == (size_t)-1)
		return PX_E_INVAL;
	ws[127] = 0;
	all = hid_enumerate(x->cfg.vid, x->cfg.pid);
	for (p = all; p && !found; p = p->next) {
		if (x->cfg.serial &&
		    (!p->serial_number || wcscmp(p->serial_number, ws) != 0))
			continue;
		snprintf(path, cap, "%s", p->path);
		found = 1;
	}
	hid_free_enumeration(all);
	return found ? PX_OK : PX_E_NOTFOUND;
}

/* Find (by vid:pid) and open, under hid_lock; on failure *e is the
 * open's errno and he (hcap wide chars) hidapi's text, copied while the
 * lock still keeps it alive. */
static int open_locked(struct hid *x, char *path, size_t cap, int *e,
		       wchar_t *he, size_t hcap)
{
	const wchar_t *t;
	int rc;
	*e = 0;
	if (x->cfg.has_vid_pid) {
		rc = find_path(x, path, cap);
		if (rc != PX_OK)
			return rc;
	} else {
		snprintf(path, cap, "%s", x->path);
	}
	errno = 0;
	x->h = hid_open_path(path);
	*e = errno;
	if (!x->h) {
		t = hid_error(NULL);
		if (t) {
			wcsncpy(he, t, hcap - 1);
			he[hcap - 1] = 0;
		}
		if (*e == EACCES || *e == EPERM)
			return PX_E_PERM;
		return PX_E_IO;
	}
	n_open++;
	return PX_OK;
}

/* Open (or reopen, refresh = 1: see lib_refresh_locked). Returns PX_OK
 * or an error with msg filled. */
static int hid_open_dev(struct hid *x, const char *nm, char *msg, size_t cap,
			int *sys_errno, int refresh)
{
	char path[256];
	wchar_t he[128];
	int rc, e, ndev = 0;
	*sys_errno = 0;
	he[0] = 0;
	pthread_mutex_lock(&hid_lock);
	if (refresh)
		lib_refresh_locked();
	if (lib_init_locked() != 0) {
		pthread_mutex_unlock(&hid_lock);
		if (msg)
			snprintf(msg, cap, "%s: hid_init failed: %ls", nm,
				 hid_error(NULL) ? hid_error(NULL) : L"?");
		return PX_E_IO;
	}
	rc = open_locked(x, path, sizeof path, &e, he, 128);
	if (rc == PX_E_NOTFOUND && msg)
		ndev = count_devices();
	pthread_mutex_unlock(&hid_lock);
	if (rc == PX_OK) {
		snprintf(x->path, sizeof x->path, "%s", path);
		return PX_OK;
	}
	if (rc == PX_E_INVAL) {
		if (msg)
			snprintf(msg, cap, "%s: serial '%s' is not valid text",
				 nm, x->cfg.serial);
		return rc;
	}
	if (rc == PX_E_NOTFOUND) {
		if (msg)
			snprintf(msg, cap,
				 "%s: no HID device %04x:%04x%s%s found "
				 "(%d HID devices present; "
				 "proxima-probe lists them)",
				 nm, x->cfg.vid, x->cfg.pid,
				 x->cfg.serial ? " serial " : "",
				 x->cfg.serial ? x->cfg.serial : "", ndev);
		return PX_E_NOTFOUND;
	}
	*sys_errno = e;
	if (msg) {
		snprintf(msg, cap, "%s: cannot open HID device %s (hidapi %s)%s%s"
			 "%s%ls",
			 nm, path, PX_HIDAPI_DRIVER,
			 e ? ": " : "", e ? strerror(e) : "",
			 he[0] ? ": " : "", he);
		if (e == EACCES || e == EPERM) {
			size_t l = strlen(msg);
			snprintf(msg + l, cap > l ? cap - l : 0,
				 " (no permission: add a udev rule giving your "
				 "user access to the hidraw node)");
		}
	}
	if (e == EACCES || e == EPERM)
		return PX_E_PERM;
	if (e == ENOENT || e == ENODEV || e == ENXIO)
		return PX_E_NOTFOUND;
	return PX_E_IO;
}

static void sleep_ns(int64_t ns)
{
	struct timespec ts = {(time_t)(ns / 1000000000), (long)(ns % 1000000000)};
	nanosleep(&ts, NULL);
}

/* Send the safe output report (I/O thread, or the caller when no
 * thread runs) and answer the request. */
static void send_safe(struct px_dev *d, struct hid *x)
{
	unsigned r = atomic_load(&x->safe_req);
	int rc = PX_OK;
	errno = 0;
	if (!x->h) {
		rc = PX_E_NODEV;
	} else if (hid_write(x->h, x->safe_rep.b, x->safe_rep.len) !=
		   (int)x->safe_rep.len) {
		rc = PX_E_IO;
		px_dev_record(d, PX_DEV_ERR_IO, PX_E_IO, errno, x->safe_rep.b[0],
			      NULL, "hid_write of the safe output failed",
			      px_dev_mono_ns());
	}
	atomic_store(&x->safe_rc, rc);
	atomic_store(&x->safe_ack, r);
}

/* One thread makes every hidapi call for a device: hidapi 0.13 keeps a
 * per-device error string that hid_read_timeout and hid_write both
 * replace, so reading and writing from two threads would race. Reads
 * wait at most 1 ms, so an output command waits at most that long. */
static void *io_main(void *p)
{
	struct px_dev *d = p;
	struct hid *x = px_dev_impl(d);
	uint8_t buf[REP_MAX];
	while (!atomic_load(&x->stop)) {
		const struct outrep *o;
		int n, e, fresh = 0;
		if (!x->h) {
			int se;
			sleep_ns(REOPEN_NS);
			if (hid_open_dev(x, px_dev_name(d), NULL, 0, &se, 1) ==
			    PX_OK)
				px_dev_set_state(d, PX_DEV_STATE_RUNNING,
						 px_dev_mono_ns());
			continue;
		}
		errno = 0;
		n = hid_read_timeout(x->h, buf, sizeof buf, READ_TIMEOUT_MS);
		e = errno;
		if (n > 0)
			px_dev_feed_report(d, buf, (size_t)n, px_dev_mono_ns());
		if (n < 0) {
			px_dev_record(d, PX_DEV_ERR_IO, PX_E_NODEV, e, -1, NULL,
				      "hid_read failed", px_dev_mono_ns());
			px_dev_set_state(d, PX_DEV_STATE_UNPLUGGED,
					 px_dev_mono_ns());
			close_handle(x->h);
			x->h = NULL;
			continue;
		}
		o = px_param_read(x->out, &fresh);
		if (fresh && o->len && !atomic_load(&x->hold)) {
			errno = 0;
			if (hid_write(x->h, o->b, o->len) < 0)
				px_dev_record(d, PX_DEV_ERR_IO, PX_E_IO, errno,
					      o->b[0], NULL, "hid_write failed",
					      px_dev_mono_ns());
		}
		/* after any command of this turn, so the safe one is last */
		if (atomic_load(&x->safe_req) != atomic_load(&x->safe_ack))
			send_safe(d, x);
	}
	return NULL;
}

static int hid_start(struct px_dev *d)
{
	struct hid *x = px_dev_impl(d);
	atomic_store(&x->stop, 0);
	if (pthread_create(&x->reader, NULL, io_main, d) != 0)
		return PX_E_NOMEM;
	x->threads = 1;
	return PX_OK;
}

static void hid_stop(struct px_dev *d)
{
	struct hid *x = px_dev_impl(d);
	if (!x->threads)
		return;
	atomic_store(&x->stop, 1);
	pthread_join(x->reader, NULL);
	x->threads = 0;
}

static int hid_force(struct px_dev *d, const struct px_force_cmd *c,
		     int64_t now)
{
	struct hid *x = px_dev_impl(d);
	const struct px_codec_map *m = px_dev_config(d)->codec;
	struct outrep o;
	int n;
	if (!m->n_outputs)
		return PX_E_UNSUPPORTED;
	n = px__dev_encode_force(d, m, c, now, o.b, sizeof o.b);
	if (n < 0)
		return n;
	o.len = (size_t)n;
	atomic_store(&x->hold, 0);
	px_param_write(x->out, &o); /* the I/O thread sends it */
	return PX_OK;
}

/* Zero force through the codec; hid_write's byte count is the
 * confirmation hidapi gives. With the I/O thread running it sends (it
 * makes every hidapi call), the caller waits a bounded time. */
static int hid_safe(struct px_dev *d, int64_t now)
{
	struct hid *x = px_dev_impl(d);
	const struct px_codec_map *m = px_dev_config(d)->codec;
	struct px_force_cmd zero;
	int64_t t0;
	unsigned r;
	int n;
	if (!m->n_outputs)
		return PX_OK; /* an input-only device has nothing to zero */
	memset(&zero, 0, sizeof zero);
	n = px__dev_encode_force(d, m, &zero, now, x->safe_rep.b,
				 sizeof x->safe_rep.b);
	if (n < 0)
		return n;
	x->safe_rep.len = (size_t)n;
	atomic_store(&x->hold, 1);
	if (!x->threads) {
		atomic_fetch_add(&x->safe_req, 1);
		send_safe(d, x);
		return atomic_load(&x->safe_rc);
	}
	if (px_dev_state(d) == PX_DEV_STATE_UNPLUGGED)
		return PX_E_NODEV; /* the thread waits to reopen: no handle */
	r = atomic_fetch_add(&x->safe_req, 1) + 1;
	t0 = px_dev_mono_ns();
	while (atomic_load(&x->safe_ack) != r) {
		if (px_dev_mono_ns() - t0 > SAFE_WAIT_NS)
			return PX_E_TIMEOUT;
		sleep_ns(1000000);
	}
	return atomic_load(&x->safe_rc);
}

static void hid_destroy(struct px_dev *d)
{
	struct hid *x = px_dev_impl(d);
	close_handle(x->h);
	x->h = NULL;
}

static const struct px_dev_ops hid_ops = {
	.backend = "hidapi",
	.caps = PX_DEV_CAP_POSE | PX_DEV_CAP_FORCE,
	.start = hid_start,
	.stop = hid_stop,
	.force = hid_force,
	.safe = hid_safe,
	.destroy = hid_destroy,
};

int px_hid_create(const struct px_dev_config *dcfg,
		  const struct px_hid_config *hc, struct px_dev **out,
		  char *msg, size_t cap)
{
	struct hid tmp, *x;
	struct outrep zero;
	const char *nm;
	int rc, se = 0;
	if (msg && cap)
		msg[0] = 0;
	if (out)
		*out = NULL;
	if (!dcfg || !hc || !out || !dcfg->codec ||
	    (!hc->has_vid_pid && (!hc->path || !*hc->path))) {
		if (msg)
			snprintf(msg, cap, "%s: HID device needs a codec map "
				 "and vid:pid or a path",
				 dcfg && dcfg->name ? dcfg->name : "hid");
		return PX_E_INVAL;
	}
	nm = dcfg->name ? dcfg->name : "hid";
	if (hc->driver != px_hid_driver()) {
		if (msg)
			snprintf(msg, cap,
				 "%s: driver %s asked for, but this build "
				 "links hidapi-%s (rebuild with make HIDAPI=%s)",
				 nm, hc->driver == PX_HID_LIBUSB ? "libusb"
								 : "hidraw",
				 PX_HIDAPI_DRIVER,
				 hc->driver == PX_HID_LIBUSB ? "libusb"
							     : "hidraw");
		return PX_E_UNSUPPORTED;
	}
	if (px_codec_check(dcfg->codec, NULL) != PX_OK) {
		if (msg)
			snprintf(msg, cap, "%s: bad codec map (px_codec_check)",
				 nm);
		return PX_E_INVAL;
	}
	memset(&tmp, 0, sizeof tmp);
	tmp.cfg = *hc;
	if (hc->serial) {
		snprintf(tmp.serial, sizeof tmp.serial, "%s", hc->serial);
		tmp.cfg.serial = tmp.serial;
	}
	if (hc->path)
		snprintf(tmp.path, sizeof tmp.path, "%s", hc->path);
	tmp.cfg.path = NULL;
	rc = hid_open_dev(&tmp, nm, msg, cap, &se, 0);
	if (rc != PX_OK)
		return rc;
	rc = px_dev_create(&hid_ops, dcfg, sizeof *x, out);
	if (rc != PX_OK) {
		close_handle(tmp.h);
		if (msg)
			snprintf(msg, cap, "%s: %s", nm, px_strerror(rc));
		return rc;
	}
	x = px_dev_impl(*out);
	memcpy(x, &tmp, sizeof tmp);
	if (x->cfg.serial)
		x->cfg.serial = x->serial;
	atomic_init(&x->stop, 0);
	atomic_init(&x->safe_req, 0);
	atomic_init(&x->safe_ack, 0);
	atomic_init(&x->safe_rc, 0);
	atomic_init(&x->hold, 0);
	px_arena_init(&x->arena, x->arena_buf, sizeof x->arena_buf);
	memset(&zero, 0, sizeof zero);
	rc = px_param_create(&x->arena, sizeof zero, &zero, &x->out);
	if (rc != PX_OK) {
		px_dev_free(*out);
		*out = NULL;
		return rc;
	}
	return PX_OK;
}

int px_hid_list(void (*fn)(void *user, const char *line), void *user)
{
	struct hid_device_info *all, *p;
	int n = 0;
	char line[512];
	if (!fn)
		return PX_E_INVAL;
	pthread_mutex_lock(&hid_lock);
	if (lib_init_locked() != 0) {
		pthread_mutex_unlock(&hid_lock);
		return PX_E_IO;
	}
	all = hid_enumerate(0, 0);
	for (p = all; p; p = p->next) {
		snprintf(line, sizeof line,
			 "%04x:%04x usage %04x:%04x interface %d path %s "
			 "\"%ls\" serial \"%ls\"",
			 p->vendor_id, p->product_id, p->usage_page, p->usage,
			 p->interface_number, p->path,
			 p->product_string ? p->product_string : L"",
			 p->serial_number ? p->serial_number : L"");
		fn(user, line);
		n++;
	}
	hid_free_enumeration(all);
	pthread_mutex_unlock(&hid_lock);
	return n;
}
