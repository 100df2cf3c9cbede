/* GPIO lines through libgpiod 1.6. Every libgpiod call of the library is
 * in this file: a port to the 2.x API changes this file only. */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include <gpiod.h>

#include "dev_internal.h"
#include "px_gpio.h"

#define CONSUMER "proxima"
#define MAX_EV_PER_READ 64

struct gd {
	struct px__dio io;
	struct gpiod_chip *chip;
	struct gpiod_line *line[PX_GPIO__ROLES];
	int ev_fd;
	int failed;
};

static int err_code(int e)
{
	if (e == ENOENT || e == ENODEV || e == ENXIO)
		return PX_E_NOTFOUND;
	if (e == EACCES || e == EPERM)
		return PX_E_PERM;
	if (e == EBUSY)
		return PX_E_BUSY;
	return PX_E_IO;
}

static const char *role_name(int r)
{
	return r == PX_GPIO_ESTOP ? "estop" : r == PX_GPIO_ENABLE ? "enable"
								  : "timing";
}

static int gd_estop(struct px_dev *d, int64_t now, int *pressed)
{
	struct gd *g = px_dev_impl(d);
	int k;
	if (!g->failed && g->ev_fd >= 0) {
		for (k = 0; k < MAX_EV_PER_READ; k++) {
			struct gpiod_line_event ev;
			int64_t t;
			if (gpiod_line_event_read_fd(g->ev_fd, &ev) != 0) {
				int e = errno;
				if (e == EAGAIN || e == EWOULDBLOCK)
					break;
				px_dev_record(d, PX_DEV_ERR_IO, PX_E_IO, e,
					      g->io.cfg.line[PX_GPIO_ESTOP].offset,
					      NULL, "gpiod_line_event_read_fd",
					      now);
				g->failed = 1;
				px_dev_set_state(d, PX_DEV_STATE_FAILED, now);
				break;
			}
			/* GPIO uAPI v1 event times are CLOCK_MONOTONIC
			 * (Linux >= 5.7), the loop's clock. */
			t = (int64_t)ev.ts.tv_sec * 1000000000 + ev.ts.tv_nsec;
			px__dio_edge(&g->io,
				     ev.event_type == GPIOD_LINE_EVENT_RISING_EDGE,
				     t);
		}
	}
	return px__dio_estop(d, &g->io, now, g->failed, pressed);
}

static int gd_write(struct px_dev *d, int which, int value, int64_t now)
{
	struct gd *g = px_dev_impl(d);
	int role = which == PX_DIO_ENABLE ? PX_GPIO_ENABLE : PX_GPIO_TIMING;
	if (!g->line[role])
		return PX_E_UNSUPPORTED;
	if (gpiod_line_set_value(g->line[role],
				 px__dio_physical(&g->io, role, value)) != 0) {
		int e = errno;
		px_dev_record(d, PX_DEV_ERR_IO, PX_E_IO, e,
			      g->io.cfg.line[role].offset, NULL,
			      "gpiod_line_set_value", now);
		return PX_E_IO;
	}
	g->io.out[role] = value;
	return PX_OK;
}

/* Enable (relay) and timing outputs off, each read back: the kernel's
 * value of a requested output line is what the driver was last told,
 * and a line another consumer or a failing chip changed shows here. */
static int gd_safe(struct px_dev *d, int64_t now)
{
	static const int roles[2] = {PX_GPIO_ENABLE, PX_GPIO_TIMING};
	struct gd *g = px_dev_impl(d);
	int k, rc = PX_OK;
	for (k = 0; k < 2; k++) {
		int role = roles[k], want, got;
		int r = gd_write(d, role == PX_GPIO_ENABLE ? PX_DIO_ENABLE
							   : PX_DIO_TIMING,
				 0, now);
		if (r == PX_E_UNSUPPORTED)
			continue;
		if (r < 0) {
			rc = rc < 0 ? rc : r;
			continue;
		}
		want = px__dio_physical(&g->io, role, 0);
		got = gpiod_line_get_value(g->line[role]);
		if (got != want) {
			px_dev_record(d, PX_DEV_ERR_IO, PX_E_IO,
				      got < 0 ? errno : 0,
				      g->io.cfg.line[role].offset, NULL,
				      role == PX_GPIO_ENABLE
					      ? "enable output read back on "
						"after the safe output"
					      : "timing output read back on "
						"after the safe output",
				      now);
			rc = rc < 0 ? rc : PX_E_IO;
		}
	}
	return rc;
}

static void gd_destroy(struct px_dev *d)
{
	struct gd *g = px_dev_impl(d);
	int r;
	for (r = 0; r < PX_GPIO__ROLES; r++)
		if (g->line[r])
			gpiod_line_release(g->line[r]);
	if (g->chip)
		gpiod_chip_close(g->chip);
	g->chip = NULL;
}

static const struct px_dev_ops gd_ops = {
	.backend = "gpiod",
	.caps = PX_DEV_CAP_DIO,
	.estop = gd_estop,
	.dio_write = gd_write,
	.safe = gd_safe,
	.destroy = gd_destroy,
};

#define FAIL(e_, ...)                                          \
	do {                                                   \
		e = (e_);                                      \
		if (msg)                                       \
			snprintf(msg, cap, __VA_ARGS__);       \
		goto fail;                                     \
	} while (0)

int px_gpiod_create(const struct px_dev_config *dcfg,
		    const struct px_gpio_config *cfg, struct px_dev **out,
		    int *sys_errno, char *msg, size_t cap)
{
	struct gd tmp, *g;
	const char *nm = dcfg && dcfg->name ? dcfg->name : "gpio";
	int r, e = 0, rc, level = 0;
	if (msg && cap)
		msg[0] = 0;
	if (sys_errno)
		*sys_errno = 0;
	if (out)
		*out = NULL;
	if (!dcfg || !cfg || !out || !cfg->chip || !*cfg->chip) {
		if (msg)
			snprintf(msg, cap, "%s: gpiod device needs a chip", nm);
		return PX_E_INVAL;
	}
	memset(&tmp, 0, sizeof tmp);
	tmp.ev_fd = -1;
	errno = 0;
	tmp.chip = gpiod_chip_open_lookup(cfg->chip);
	if (!tmp.chip) {
		e = errno ? errno : ENOENT;
		FAIL(e, "%s: gpiod_chip_open_lookup(\"%s\"): errno %s (%d): %s%s",
		     nm, cfg->chip, strerrorname_np(e) ? strerrorname_np(e) : "?",
		     e, strerror(e),
		     e == ENOENT
			     ? (access("/dev/gpiochip0", F_OK) == 0
					? " (no chip of that name, number or "
					  "label: proxima-probe lists them)"
					: " (no /dev/gpiochip*: this machine "
					  "has no GPIO controller; gpio-sim "
					  "provides virtual ones)")
			     : e == EACCES ? " (no permission on /dev/gpiochip*: "
					     "add your user to the gpio group "
					     "or a udev rule)"
					   : "");
	}
	for (r = 0; r < PX_GPIO__ROLES; r++) {
		const struct px_gpio_line *L = &cfg->line[r];
		struct gpiod_line *ln;
		if (!L->present)
			continue;
		errno = 0;
		ln = L->line_name ? gpiod_chip_find_line(tmp.chip, L->line_name)
				  : gpiod_chip_get_line(tmp.chip, L->offset);
		if (!ln) {
			e = errno ? errno : ENOENT;
			if (L->line_name)
				FAIL(e, "%s: %s line named \"%s\" not found on "
				     "%s (errno %d: %s)", nm, role_name(r),
				     L->line_name, cfg->chip, e, strerror(e));
			FAIL(e, "%s: %s line offset %u on %s: errno %d: %s "
			     "(the chip has %u lines)", nm, role_name(r),
			     L->offset, cfg->chip, e, strerror(e),
			     gpiod_chip_num_lines(tmp.chip));
		}
		if (r == PX_GPIO_ESTOP)
			rc = gpiod_line_request_both_edges_events(ln, CONSUMER);
		else
			rc = gpiod_line_request_output(
				ln, CONSUMER, (L->initial != 0) ^ (L->active_low != 0));
		if (rc != 0) {
			e = errno;
			FAIL(e, "%s: request of %s line %u (\"%s\") on %s: "
			     "errno %s (%d): %s%s", nm, role_name(r),
			     gpiod_line_offset(ln),
			     gpiod_line_name(ln) ? gpiod_line_name(ln) : "",
			     cfg->chip,
			     strerrorname_np(e) ? strerrorname_np(e) : "?", e,
			     strerror(e),
			     e == EBUSY ? " (used by another consumer: "
					  "proxima-probe shows which)"
					: "");
		}
		tmp.line[r] = ln;
	}
	if (tmp.line[PX_GPIO_ESTOP]) {
		tmp.ev_fd = gpiod_line_event_get_fd(tmp.line[PX_GPIO_ESTOP]);
		if (tmp.ev_fd < 0 ||
		    fcntl(tmp.ev_fd, F_SETFL,
			  fcntl(tmp.ev_fd, F_GETFL) | O_NONBLOCK) != 0) {
			e = errno;
			FAIL(e, "%s: e-stop event descriptor: %s", nm,
			     strerror(e));
		}
		level = gpiod_line_get_value(tmp.line[PX_GPIO_ESTOP]);
		if (level < 0) {
			e = errno;
			FAIL(e, "%s: gpiod_line_get_value(estop): %s", nm,
			     strerror(e));
		}
	}
	rc = px_dev_create(&gd_ops, dcfg, sizeof *g, out);
	if (rc != PX_OK) {
		e = ENOMEM;
		if (msg)
			snprintf(msg, cap, "%s: %s", nm, px_strerror(rc));
		goto fail;
	}
	g = px_dev_impl(*out);
	*g = tmp;
	px__dio_init(&g->io, cfg, level, 0);
	g->io.cfg.chip = NULL; /* not kept: the caller's string */
	for (r = 0; r < PX_GPIO__ROLES; r++)
		g->io.cfg.line[r].line_name = NULL;
	return PX_OK;
fail:
	if (sys_errno)
		*sys_errno = e;
	for (r = 0; r < PX_GPIO__ROLES; r++)
		if (tmp.line[r])
			gpiod_line_release(tmp.line[r]);
	if (tmp.chip)
		gpiod_chip_close(tmp.chip);
	return e == ENOMEM ? PX_E_NOMEM : err_code(e);
}

int px_gpiod_list(int lines, void (*fn)(void *user, const char *line),
		  void *user)
{
	struct gpiod_chip_iter *it;
	struct gpiod_chip *chip;
	char buf[256];
	int n = 0;
	if (!fn)
		return PX_E_INVAL;
	it = gpiod_chip_iter_new();
	if (!it)
		return errno == ENOENT ? PX_E_NOTFOUND : PX_E_IO;
	gpiod_foreach_chip(it, chip) {
		unsigned i, nl = gpiod_chip_num_lines(chip);
		snprintf(buf, sizeof buf, "%s [%s] %u lines",
			 gpiod_chip_name(chip), gpiod_chip_label(chip), nl);
		fn(user, buf);
		n++;
		for (i = 0; lines && i < nl; i++) {
			struct gpiod_line *ln = gpiod_chip_get_line(chip, i);
			if (!ln)
				continue;
			snprintf(buf, sizeof buf, "  line %3u: \"%s\" %s%s%s",
				 i, gpiod_line_name(ln) ? gpiod_line_name(ln)
							: "",
				 gpiod_line_direction(ln) ==
						 GPIOD_LINE_DIRECTION_OUTPUT
					 ? "output"
					 : "input",
				 gpiod_line_consumer(ln) ? " used by " : "",
				 gpiod_line_consumer(ln)
					 ? gpiod_line_consumer(ln)
					 : "");
			fn(user, buf);
		}
	}
	gpiod_chip_iter_free(it);
	return n ? n : PX_E_NOTFOUND;
}

const char *px_gpiod_version(void)
{
	return gpiod_version_string();
}
