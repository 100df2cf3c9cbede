/*
 * uhid_feed - the haptic device of the VM suite's end-to-end scenario: a
 * HID device 1234:0001 created through /dev/uhid with the built-in
 * "haptic" report layout (report 1 in: x, y, z int32 in um and 4 button
 * bits; report 2 out: fx, fy, fz int16 in mN), so that proxima-run's
 * hidapi back end finds it like a real one.
 *
 *   uhid_feed SECONDS STATUS_FILE
 *
 * Once the host side opens the device (UHID_OPEN; input reports sent
 * before are dropped by the kernel) it sends a position every 2 ms: the
 * tool tip moving up and down through the plane z = 0 (z = 10 mm cos(pi
 * t)), so a renderer pushing back sends non-zero forces half the time. It
 * stops after SECONDS, or when the device is closed, and writes one line
 * of counts to STATUS_FILE:
 *
 *   inputs N outputs N nonzero N max_mn N tail_outputs N tail_nonzero N
 *   ... last_fx N last_fy N last_fz N
 *
 * where tail_* counts the output reports of the last TAIL_S seconds
 * before the end (the scenario presses the e-stop well before: all of
 * them must be zero) and last_* is the last output report received (mN):
 * what the device was left with when the host stopped. Exit status 0, or
 * 1 with the reason on stderr.
 */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <poll.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <linux/uhid.h>

#include "haptic_rd.h"

#define TAIL_S 1.0
#define TAIL_MAX 4096

static double now_s(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static void put_i32(uint8_t *p, int32_t v)
{
	uint32_t u = (uint32_t)v;
	p[0] = (uint8_t)u;
	p[1] = (uint8_t)(u >> 8);
	p[2] = (uint8_t)(u >> 16);
	p[3] = (uint8_t)(u >> 24);
}

static int16_t get_i16(const uint8_t *p)
{
	return (int16_t)(uint16_t)(p[0] | (p[1] << 8));
}

static int send_event(int fd, const struct uhid_event *ev)
{
	if (write(fd, ev, sizeof(*ev)) != (ssize_t)sizeof(*ev)) {
		fprintf(stderr, "uhid_feed: write /dev/uhid: %s\n",
			strerror(errno));
		return -1;
	}
	return 0;
}

struct out_rec {
	double t;
	int nonzero;
};

int main(int argc, char **argv)
{
	static struct out_rec tail[TAIL_MAX];
	struct uhid_event ev;
	double seconds, t0 = 0, next = 0, end_t;
	unsigned long inputs = 0, outputs = 0, nonzero = 0, tail_n = 0,
		      tail_nz = 0;
	size_t head = 0, count = 0, i;
	int fd, opened = 0, closed = 0, max_mn = 0, last[3] = {0, 0, 0};
	FILE *f;
	if (argc != 3 || (seconds = atof(argv[1])) <= 0) {
		fprintf(stderr, "usage: uhid_feed SECONDS STATUS_FILE\n");
		return 2;
	}
	fd = open("/dev/uhid", O_RDWR | O_CLOEXEC);
	if (fd < 0) {
		fprintf(stderr, "uhid_feed: /dev/uhid: %s\n", strerror(errno));
		return 1;
	}
	memset(&ev, 0, sizeof(ev));
	ev.type = UHID_CREATE2;
	snprintf((char *)ev.u.create2.name, sizeof(ev.u.create2.name),
		 "proxima e2e haptic");
	memcpy(ev.u.create2.rd_data, haptic_rd, sizeof(haptic_rd));
	ev.u.create2.rd_size = sizeof(haptic_rd);
	ev.u.create2.bus = 0x03; /* BUS_USB */
	ev.u.create2.vendor = 0x1234;
	ev.u.create2.product = 0x0001;
	if (send_event(fd, &ev))
		return 1;
	end_t = now_s() + 60; /* until opened: at most a minute */
	while (!closed) {
		struct pollfd p = {fd, POLLIN, 0};
		double t = now_s();
		int wait_ms;
		if (t >= end_t)
			break;
		if (opened && t >= next) {
			double x = t - t0;
			memset(&ev, 0, sizeof(ev));
			ev.type = UHID_INPUT2;
			ev.u.input2.data[0] = 1;
			put_i32(ev.u.input2.data + 1, 0);
			put_i32(ev.u.input2.data + 5, 0);
			put_i32(ev.u.input2.data + 9,
				(int32_t)lround(10000.0 * cos(M_PI * x)));
			ev.u.input2.data[13] = 0;
			ev.u.input2.size = 14;
			if (send_event(fd, &ev))
				return 1;
			inputs++;
			next += 0.002;
			if (next < t)
				next = t + 0.002; /* a stall: no burst after it */
		}
		wait_ms = opened ? (int)((next - now_s()) * 1e3) : 100;
		if (wait_ms < 0)
			wait_ms = 0;
		if (poll(&p, 1, wait_ms) <= 0)
			continue;
		if (read(fd, &ev, sizeof(ev)) <= 0) {
			fprintf(stderr, "uhid_feed: read /dev/uhid: %s\n",
				strerror(errno));
			return 1;
		}
		switch (ev.type) {
		case UHID_OPEN:
			if (!opened) {
				opened = 1;
				t0 = next = now_s();
				end_t = t0 + seconds;
				printf("uhid_feed: opened, feeding for %.1f s\n",
				       seconds);
				fflush(stdout);
			}
			break;
		case UHID_CLOSE:
			closed = opened;
			break;
		case UHID_OUTPUT:
			if (ev.u.output.size >= 7 && ev.u.output.data[0] == 2) {
				int k, nz = 0;
				for (k = 0; k < 3; k++) {
					int v = get_i16(ev.u.output.data + 1 + 2 * k);
					last[k] = v;
					if (v)
						nz = 1;
					if (abs(v) > max_mn)
						max_mn = abs(v);
				}
				outputs++;
				nonzero += (unsigned long)nz;
				tail[head].t = now_s();
				tail[head].nonzero = nz;
				head = (head + 1) % TAIL_MAX;
				if (count < TAIL_MAX)
					count++;
			}
			break;
		default:
			break;
		}
	}
	{
		/* the window ends at the last output report (the host may
		 * have gone well before this program stops) */
		double last = count ? tail[(head + TAIL_MAX - 1) % TAIL_MAX].t : 0;
		for (i = 0; i < count; i++) {
			const struct out_rec *r = &tail[(head + TAIL_MAX - 1 - i) % TAIL_MAX];
			if (r->t < last - TAIL_S)
				break;
			tail_n++;
			tail_nz += (unsigned long)r->nonzero;
		}
	}
	memset(&ev, 0, sizeof(ev));
	ev.type = UHID_DESTROY;
	send_event(fd, &ev);
	close(fd);
	f = fopen(argv[2], "w");
	if (!f) {
		fprintf(stderr, "uhid_feed: %s: %s\n", argv[2], strerror(errno));
		return 1;
	}
	fprintf(f,
		"inputs %lu outputs %lu nonzero %lu max_mn %d tail_outputs %lu "
		"tail_nonzero %lu opened %d closed %d last_fx %d last_fy %d "
		"last_fz %d\n",
		inputs, outputs, nonzero, max_mn, tail_n, tail_nz, opened, closed,
		last[0], last[1], last[2]);
	fclose(f);
	if (!opened) {
		fprintf(stderr, "uhid_feed: nobody opened the device\n");
		return 1;
	}
	return 0;
}
