/* USB through libusb-1.0. Every libusb call of the library is here. */
#include <errno.h>
#include <pthread.h>
#include <semaphore.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <libusb.h>

#include "px_arena.h"
#include "px_param.h"
#include "px_usb.h"
#include "dev_internal.h"

#define MAX_XFER 16
#define FRAME_MAX 1024
#define REOPEN_NS 200000000

struct outframe {
	size_t len;
	uint8_t b[FRAME_MAX];
};

struct usb {
	struct px_usb_config cfg;
	char serial[128];
	libusb_context *ctx;
	libusb_device_handle *h;
	pthread_mutex_t lock; /* h between the event thread and the writer */
	pthread_t events, writer;
	int threads;
	atomic_int stop;
	sem_t wake;
	struct px_dev *dev;
	struct libusb_transfer *xfer[MAX_XFER];
	uint8_t buf[MAX_XFER][FRAME_MAX];
	atomic_int in_flight;
	atomic_int gone;
	/* hotplug: callback registered on ctx (0 = poll only), and a
	 * matching device arrived since the last reopen attempt */
	int hp_active;
	libusb_hotplug_callback_handle hp;
	atomic_int arrived;
	struct px_arena arena;
	uint8_t arena_buf[4 * sizeof(struct outframe) + 512];
	struct px_param *out;
	/* set by a safe output: no older frame goes out after it */
	atomic_int hold;
};

static int64_t mono_ns(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

static int map_err(int rc)
{
	switch (rc) {
	case LIBUSB_ERROR_ACCESS: return PX_E_PERM;
	case LIBUSB_ERROR_NO_DEVICE:
	case LIBUSB_ERROR_NOT_FOUND: return PX_E_NOTFOUND;
	case LIBUSB_ERROR_BUSY: return PX_E_BUSY;
	case LIBUSB_ERROR_NO_MEM: return PX_E_NOMEM;
	case LIBUSB_ERROR_NOT_SUPPORTED: return PX_E_UNSUPPORTED;
	case LIBUSB_ERROR_TIMEOUT: return PX_E_TIMEOUT;
	default: return PX_E_IO;
	}
}

/* Find, open and claim. On failure msg says why (may be NULL). */
static int usb_open(struct usb *u, const char *nm, char *msg, size_t cap)
{
	libusb_device **list = NULL;
	ssize_t n, i;
	int rc = LIBUSB_ERROR_NOT_FOUND, found = 0;
	n = libusb_get_device_list(u->ctx, &list);
	if (n < 0) {
		if (msg)
			snprintf(msg, cap, "%s: libusb_get_device_list: %s", nm,
				 libusb_error_name((int)n));
		return map_err((int)n);
	}
	for (i = 0; i < n && !u->h; i++) {
		struct libusb_device_descriptor dd;
		libusb_device_handle *h;
		if (libusb_get_device_descriptor(list[i], &dd) != 0 ||
		    dd.idVendor != u->cfg.vid || dd.idProduct != u->cfg.pid)
			continue;
		found = 1;
		rc = libusb_open(list[i], &h);
		if (rc != 0)
			continue;
		if (u->cfg.serial) {
			unsigned char sn[128] = "";
			if (!dd.iSerialNumber ||
			    libusb_get_string_descriptor_ascii(
				    h, dd.iSerialNumber, sn, sizeof sn) < 0 ||
			    strcmp((const char *)sn, u->cfg.serial) != 0) {
				libusb_close(h);
				rc = LIBUSB_ERROR_NOT_FOUND;
				continue;
			}
		}
		u->h = h;
	}
	libusb_free_device_list(list, 1);
	if (!u->h) {
		if (msg) {
			if (!found || rc == LIBUSB_ERROR_NOT_FOUND)
				snprintf(msg, cap,
					 "%s: no USB device %04x:%04x%s%s "
					 "(%zd USB devices present; "
					 "proxima-probe lists them)",
					 nm, u->cfg.vid, u->cfg.pid,
					 u->cfg.serial ? " serial " : "",
					 u->cfg.serial ? u->cfg.serial : "", n);
			else
				snprintf(msg, cap,
					 "%s: libusb_open %04x:%04x: %s%s", nm,
					 u->cfg.vid, u->cfg.pid,
					 libusb_error_name(rc),
					 rc == LIBUSB_ERROR_ACCESS
						 ? " (no permission: add a udev "
						   "rule for the device)"
						 : "");
		}
		return !found ? PX_E_NOTFOUND : map_err(rc);
	}
	if (u->cfg.detach_kernel_driver)
		libusb_set_auto_detach_kernel_driver(u->h, 1);
	rc = libusb_claim_interface(u->h, u->cfg.interface);
	if (rc != 0) {
		if (msg)
			snprintf(msg, cap, "%s: libusb_claim_interface(%d): %s%s",
				 nm, u->cfg.interface, libusb_error_name(rc),
				 rc == LIBUSB_ERROR_BUSY
					 ? " (a kernel driver holds it: set "
					   "detach_kernel_driver)"
					 : "");
		libusb_close(u->h);
		u->h = NULL;
		return map_err(rc);
	}
	return PX_OK;
}

static void usb_close_handle(struct usb *u)
{
	if (!u->h)
		return;
	libusb_release_interface(u->h, u->cfg.interface);
	libusb_close(u->h);
	u->h = NULL;
}

static void LIBUSB_CALL on_in(struct libusb_transfer *t)
{
	struct usb *u = t->user_data;
	int64_t now = mono_ns();
	switch (t->status) {
	case LIBUSB_TRANSFER_COMPLETED:
		if (t->actual_length > 0)
			px_dev_feed_report(u->dev, t->buffer,
					   (size_t)t->actual_length, now);
		break;
	case LIBUSB_TRANSFER_NO_DEVICE:
		atomic_store(&u->gone, 1);
		atomic_fetch_sub(&u->in_flight, 1);
		return;
	case LIBUSB_TRANSFER_CANCELLED:
		atomic_fetch_sub(&u->in_flight, 1);
		return;
	default: /* timed out, stall, overflow, error: count, go on */
		px_dev_record(u->dev, PX_DEV_ERR_IO, PX_E_IO, 0,
			      t->endpoint, NULL, "USB IN transfer failed", now);
		break;
	}
	if (atomic_load(&u->stop)) {
		atomic_fetch_sub(&u->in_flight, 1);
		return;
	}
	/* On a disconnect the pending transfer may end in a plain error
	 * (dummy_hcd, some host controllers) and only the resubmission says
	 * NO_DEVICE. A transfer that cannot go again leaves no reader:
	 * handled like an unplug, so the device is reopened. */
	if (libusb_submit_transfer(t) != 0) {
		atomic_fetch_sub(&u->in_flight, 1);
		atomic_store(&u->gone, 1);
	}
}

static int submit_all(struct usb *u)
{
	int i, rc;
	for (i = 0; i < u->cfg.n_transfers; i++) {
		struct libusb_transfer *t = u->xfer[i];
		if (u->cfg.transfer == PX_USB_BULK)
			libusb_fill_bulk_transfer(t, u->h, u->cfg.endpoint_in,
						  u->buf[i],
						  (int)u->cfg.frame_len, on_in,
						  u, 0);
		else
			libusb_fill_interrupt_transfer(
				t, u->h, u->cfg.endpoint_in, u->buf[i],
				(int)u->cfg.frame_len, on_in, u, 0);
		rc = libusb_submit_transfer(t);
		if (rc != 0)
			return rc;
		atomic_fetch_add(&u->in_flight, 1);
	}
	return 0;
}

static void cancel_all(struct usb *u)
{
	int i, k;
	struct timeval tv = {0, 20000};
	for (i = 0; i < u->cfg.n_transfers; i++)
		libusb_cancel_transfer(u->xfer[i]);
	for (k = 0; k < 100 && atomic_load(&u->in_flight) > 0; k++)
		libusb_handle_events_timeout_completed(u->ctx, &tv, NULL);
}

static void sleep_ns(int64_t ns)
{
	struct timespec ts = {(time_t)(ns / 1000000000), (long)(ns % 1000000000)};
	nanosleep(&ts, NULL);
}

/* A fresh context lists the bus again: libusb's udev back end learns of
 * new devices only from udevd's events, and without udevd (containers,
 * minimal systems) a replugged device would never appear in the old
 * context. libusb transfers keep a reference to the device they last ran
 * on, so they are replaced too, and released while their context still
 * exists. Not for the cycle: runs in the events thread, device closed,
 * no transfer in flight. */
/* Runs inside libusb_handle_events on the events thread (the only
 * thread that closes u->h, so reading it here is safe). */
static int LIBUSB_CALL on_hotplug(libusb_context *ctx, libusb_device *dev,
				  libusb_hotplug_event ev, void *p)
{
	struct usb *u = p;
	(void)ctx;
	if (ev == LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED)
		atomic_store(&u->arrived, 1);
	else if (ev == LIBUSB_HOTPLUG_EVENT_DEVICE_LEFT && u->h &&
		 libusb_get_device(u->h) == dev)
		atomic_store(&u->gone, 1);
	return 0; /* stay registered */
}

/* Register for arrival/departure of our VID:PID where libusb can (its
 * Linux back ends learn of them from udev or netlink); otherwise, or with
 * no_hotplug, the events thread polls every REOPEN_NS. */
static void hotplug_register(struct usb *u)
{
	u->hp_active = 0;
	if (u->cfg.no_hotplug || !u->ctx ||
	    !libusb_has_capability(LIBUSB_CAP_HAS_HOTPLUG))
		return;
	if (libusb_hotplug_register_callback(
		    u->ctx,
		    LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED |
			    LIBUSB_HOTPLUG_EVENT_DEVICE_LEFT,
		    0, u->cfg.vid, u->cfg.pid, LIBUSB_HOTPLUG_MATCH_ANY,
		    on_hotplug, u, &u->hp) == LIBUSB_SUCCESS)
		u->hp_active = 1;
}

static void hotplug_deregister(struct usb *u)
{
	if (u->hp_active && u->ctx)
		libusb_hotplug_deregister_callback(u->ctx, u->hp);
	u->hp_active = 0;
}

/* Wait before a reopen attempt: until a matching device arrives (hotplug)
 * or REOPEN_NS have passed, whichever is first; the poll stays as the
 * fallback because arrival events need udev, which containers and
 * minimal systems lack. */
static void wait_reopen(struct usb *u)
{
	int64_t t0 = mono_ns();
	struct timeval tv = {0, 20000};
	if (!u->hp_active) {
		sleep_ns(REOPEN_NS);
		return;
	}
	while (!atomic_load(&u->stop) && !atomic_load(&u->arrived) &&
	       mono_ns() - t0 < REOPEN_NS)
		libusb_handle_events_timeout_completed(u->ctx, &tv, NULL);
	atomic_store(&u->arrived, 0);
}

static void renew_context(struct usb *u)
{
	struct libusb_transfer *t[MAX_XFER] = {0};
	libusb_context *c = NULL;
	int i, ok = 1;
	for (i = 0; i < u->cfg.n_transfers; i++)
		ok = ok && (t[i] = libusb_alloc_transfer(0)) != NULL;
	if (!ok || libusb_init(&c) != 0) {
		for (i = 0; i < u->cfg.n_transfers; i++)
			libusb_free_transfer(t[i]);
		return;
	}
	for (i = 0; i < u->cfg.n_transfers; i++) {
		libusb_free_transfer(u->xfer[i]);
		u->xfer[i] = t[i];
	}
	hotplug_deregister(u);
	libusb_exit(u->ctx);
	u->ctx = c;
	hotplug_register(u);
}

static void *events_main(void *p)
{
	struct usb *u = p;
	struct timeval tv = {0, 50000};
	while (!atomic_load(&u->stop)) {
		if (atomic_load(&u->gone)) {
			cancel_all(u);
			pthread_mutex_lock(&u->lock);
			usb_close_handle(u);
			pthread_mutex_unlock(&u->lock);
			px_dev_set_state(u->dev, PX_DEV_STATE_UNPLUGGED,
					 mono_ns());
			atomic_store(&u->gone, 0);
		}
		if (!u->h) {
			wait_reopen(u);
			pthread_mutex_lock(&u->lock);
			if (atomic_load(&u->in_flight) == 0)
				renew_context(u);
			if (usb_open(u, px_dev_name(u->dev), NULL, 0) == PX_OK) {
				if (submit_all(u) == 0)
					px_dev_set_state(u->dev,
							 PX_DEV_STATE_RUNNING,
							 mono_ns());
				else
					atomic_store(&u->gone, 1);
			}
			pthread_mutex_unlock(&u->lock);
			continue;
		}
		libusb_handle_events_timeout_completed(u->ctx, &tv, NULL);
	}
	return NULL;
}

static void *writer_main(void *p)
{
	struct usb *u = p;
	while (!atomic_load(&u->stop)) {
		const struct outframe *o;
		int fresh = 0, rc, done = 0;
		while (sem_wait(&u->wake) != 0 && errno == EINTR)
			;
		if (atomic_load(&u->stop))
			break;
		o = px_param_read(u->out, &fresh);
		if (!fresh || !o->len || !u->cfg.endpoint_out)
			continue;
		pthread_mutex_lock(&u->lock);
		if (u->h && !atomic_load(&u->hold)) {
			if (u->cfg.transfer == PX_USB_BULK)
				rc = libusb_bulk_transfer(u->h, u->cfg.endpoint_out,
							  (unsigned char *)o->b,
							  (int)o->len, &done, 100);
			else
				rc = libusb_interrupt_transfer(
					u->h, u->cfg.endpoint_out,
					(unsigned char *)o->b, (int)o->len,
					&done, 100);
			if (rc != 0)
				px_dev_record(u->dev, PX_DEV_ERR_IO, map_err(rc),
					      rc == LIBUSB_ERROR_NO_DEVICE ? ENODEV
									   : 0,
					      u->cfg.endpoint_out, NULL,
					      "USB OUT transfer failed",
					      mono_ns());
		}
		pthread_mutex_unlock(&u->lock);
	}
	return NULL;
}

static int usb_start(struct px_dev *d)
{
	struct usb *u = px_dev_impl(d);
	int rc;
	atomic_store(&u->stop, 0);
	rc = submit_all(u);
	if (rc != 0) {
		px_dev_record(d, PX_DEV_ERR_IO, map_err(rc), 0,
			      u->cfg.endpoint_in, NULL,
			      "libusb_submit_transfer", mono_ns());
		cancel_all(u);
		return map_err(rc);
	}
	if (pthread_create(&u->events, NULL, events_main, u) != 0) {
		cancel_all(u);
		return PX_E_NOMEM;
	}
	if (pthread_create(&u->writer, NULL, writer_main, u) != 0) {
		atomic_store(&u->stop, 1);
		pthread_join(u->events, NULL);
		cancel_all(u);
		return PX_E_NOMEM;
	}
	u->threads = 1;
	return PX_OK;
}

static void usb_stop(struct px_dev *d)
{
	struct usb *u = px_dev_impl(d);
	if (!u->threads)
		return;
	atomic_store(&u->stop, 1);
	sem_post(&u->wake);
	pthread_join(u->writer, NULL);
	pthread_join(u->events, NULL);
	cancel_all(u);
	u->threads = 0;
}

/* Force command c as the frame the OUT endpoint takes: a vendor frame
 * has no report id byte unless the map numbers its reports. */
static int out_frame(struct px_dev *d, const struct px_force_cmd *c,
		     int64_t now, struct outframe *o)
{
	const struct px_codec_map *m = px_dev_config(d)->codec;
	int n, off;
	n = px__dev_encode_force(d, m, c, now, o->b, sizeof o->b);
	if (n < 0)
		return n;
	off = px_codec_numbered(m) ? 0 : 1;
	o->len = (size_t)n - (size_t)off;
	if (off)
		memmove(o->b, o->b + 1, o->len);
	return PX_OK;
}

static int usb_force(struct px_dev *d, const struct px_force_cmd *c,
		     int64_t now)
{
	struct usb *u = px_dev_impl(d);
	const struct px_codec_map *m = px_dev_config(d)->codec;
	struct outframe o;
	int rc;
	if (!m->n_outputs || !u->cfg.endpoint_out)
		return PX_E_UNSUPPORTED;
	rc = out_frame(d, c, now, &o);
	if (rc < 0)
		return rc;
	atomic_store(&u->hold, 0);
	px_param_write(u->out, &o);
	sem_post(&u->wake);
	return PX_OK;
}

/* Zero force, sent here as one synchronous transfer under the handle's
 * lock (so the writer cannot send an older frame after it); libusb's
 * transferred byte count confirms it. */
static int usb_safe(struct px_dev *d, int64_t now)
{
	struct usb *u = px_dev_impl(d);
	const struct px_codec_map *m = px_dev_config(d)->codec;
	struct px_force_cmd zero;
	struct outframe o;
	int rc, done = 0;
	if (!m->n_outputs || !u->cfg.endpoint_out)
		return PX_OK; /* nothing to zero */
	memset(&zero, 0, sizeof zero);
	rc = out_frame(d, &zero, now, &o);
	if (rc < 0)
		return rc;
	atomic_store(&u->hold, 1);
	pthread_mutex_lock(&u->lock);
	if (!u->h) {
		rc = PX_E_NODEV;
	} else {
		if (u->cfg.transfer == PX_USB_BULK)
			rc = libusb_bulk_transfer(u->h, u->cfg.endpoint_out,
						  o.b, (int)o.len, &done, 100);
		else
			rc = libusb_interrupt_transfer(u->h, u->cfg.endpoint_out,
						       o.b, (int)o.len, &done,
						       100);
		if (rc == 0 && done != (int)o.len)
			rc = LIBUSB_ERROR_IO;
		if (rc != 0) {
			px_dev_record(d, PX_DEV_ERR_IO, map_err(rc),
				      rc == LIBUSB_ERROR_NO_DEVICE ? ENODEV : 0,
				      u->cfg.endpoint_out, NULL,
				      "USB OUT transfer of the safe output "
				      "failed",
				      mono_ns());
			rc = map_err(rc);
		}
	}
	pthread_mutex_unlock(&u->lock);
	return rc;
}

static void usb_destroy(struct px_dev *d)
{
	struct usb *u = px_dev_impl(d);
	int i;
	for (i = 0; i < MAX_XFER; i++)
		if (u->xfer[i])
			libusb_free_transfer(u->xfer[i]);
	usb_close_handle(u);
	hotplug_deregister(u);
	if (u->ctx)
		libusb_exit(u->ctx);
	sem_destroy(&u->wake);
	pthread_mutex_destroy(&u->lock);
}

static const struct px_dev_ops usb_ops = {
	.backend = "libusb",
	.caps = PX_DEV_CAP_POSE | PX_DEV_CAP_FORCE,
	.start = usb_start,
	.stop = usb_stop,
	.force = usb_force,
	.safe = usb_safe,
	.destroy = usb_destroy,
};

int px_usb_hotplug_active(struct px_dev *d)
{
	if (!d || px_dev_ops(d) != &usb_ops)
		return PX_E_INVAL;
	return ((struct usb *)px_dev_impl(d))->hp_active;
}

int px_usb_create(const struct px_dev_config *dcfg,
		  const struct px_usb_config *uc, struct px_dev **out,
		  char *msg, size_t cap)
{
	struct usb *u;
	struct outframe zero;
	const char *nm = dcfg && dcfg->name ? dcfg->name : "usb";
	libusb_context *ctx = NULL;
	int rc, i;
	if (msg && cap)
		msg[0] = 0;
	if (out)
		*out = NULL;
	if (!dcfg || !uc || !out || !dcfg->codec || uc->interface < 0 ||
	    (uc->endpoint_in & 0x80) == 0 || (uc->endpoint_in & 0x70) ||
	    (uc->endpoint_out & 0xF0) || uc->frame_len < 1 ||
	    uc->frame_len > FRAME_MAX || uc->n_transfers < 0 ||
	    uc->n_transfers > MAX_XFER ||
	    (uc->transfer != PX_USB_INTERRUPT && uc->transfer != PX_USB_BULK)) {
		if (msg)
			snprintf(msg, cap, "%s: USB device needs a codec map, "
				 "interface >= 0, endpoint_in 0x81..0x8f, "
				 "endpoint_out 0x01..0x0f or 0, frame_len "
				 "1..%d, at most %d transfers", nm, FRAME_MAX,
				 MAX_XFER);
		return PX_E_INVAL;
	}
	if (px_codec_check(dcfg->codec, NULL) != PX_OK) {
		if (msg)
			snprintf(msg, cap, "%s: bad codec map", nm);
		return PX_E_INVAL;
	}
	rc = libusb_init(&ctx);
	if (rc != 0) {
		if (msg)
			snprintf(msg, cap, "%s: libusb_init: %s (no USB in this "
				 "machine or container?)", nm,
				 libusb_error_name(rc));
		return rc == LIBUSB_ERROR_NOT_SUPPORTED ? PX_E_UNSUPPORTED
							: PX_E_IO;
	}
	rc = px_dev_create(&usb_ops, dcfg, sizeof *u, out);
	if (rc != PX_OK) {
		libusb_exit(ctx);
		return rc;
	}
	u = px_dev_impl(*out);
	u->cfg = *uc;
	if (!u->cfg.n_transfers)
		u->cfg.n_transfers = 4;
	if (uc->serial) {
		snprintf(u->serial, sizeof u->serial, "%s", uc->serial);
		u->cfg.serial = u->serial;
	}
	u->ctx = ctx;
	u->dev = *out;
	pthread_mutex_init(&u->lock, NULL);
	sem_init(&u->wake, 0, 0);
	atomic_init(&u->stop, 0);
	atomic_init(&u->hold, 0);
	atomic_init(&u->in_flight, 0);
	atomic_init(&u->gone, 0);
	atomic_init(&u->arrived, 0);
	for (i = 0; i < u->cfg.n_transfers; i++) {
		u->xfer[i] = libusb_alloc_transfer(0);
		if (!u->xfer[i]) {
			px_dev_free(*out);
			*out = NULL;
			return PX_E_NOMEM;
		}
	}
	px_arena_init(&u->arena, u->arena_buf, sizeof u->arena_buf);
	memset(&zero, 0, sizeof zero);
	rc = px_param_create(&u->arena, sizeof zero, &zero, &u->out);
	if (rc == PX_OK)
		rc = usb_open(u, nm, msg, cap);
	if (rc != PX_OK) {
		px_dev_free(*out);
		*out = NULL;
		return rc;
	}
	hotplug_register(u);
	return PX_OK;
}

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
