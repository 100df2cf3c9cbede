/* proxima-simarm: a simulated arm of CiA 402 drives speaking proxima's
 * CANopen-lite subset, as its own process, on a SocketCAN interface
 * (vcan0, can0) or on a simulated bus over a UNIX datagram socket - the
 * other side of a controller using px_canopen. */
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "px_canopen.h"

static volatile sig_atomic_t stop;

static void on_signal(int s)
{
	(void)s;
	stop = 1;
}

static int64_t mono(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

static void usage(FILE *f)
{
	fprintf(f,
		"usage: proxima-simarm (--can IFACE | --unix LOCAL PEER) "
		"[--drives N] [--mode csp|csv|cst] [--seconds S]\n"
		"Simulates N (default 6) CiA 402 drives, node ids 1..N, joint "
		"i on node i+1,\n100000 counts per rad, rated torque 1 N m; "
		"runs S seconds (default: until a signal).\n");
}

int main(int argc, char **argv)
{
	const char *iface = NULL, *local = NULL, *peer = NULL;
	int n = 6, mode = PX_CIA402_CSV, i, rc, e;
	double seconds = 0;
	struct px_can_bus *bus = NULL;
	struct px_canopen_drive_cfg drv[PX_CANOPEN_MAX_DRIVES];
	struct px_canopen_sim_config sc;
	struct px_canopen_sim *sim;
	char msg[400];
	int64_t t0, next;
	for (i = 1; i < argc; i++) {
		if (!strcmp(argv[i], "--can") && i + 1 < argc) {
			iface = argv[++i];
		} else if (!strcmp(argv[i], "--unix") && i + 2 < argc) {
			local = argv[++i];
			peer = argv[++i];
		} else if (!strcmp(argv[i], "--drives") && i + 1 < argc) {
			n = atoi(argv[++i]);
		} else if (!strcmp(argv[i], "--seconds") && i + 1 < argc) {
			seconds = atof(argv[++i]);
		} else if (!strcmp(argv[i], "--mode") && i + 1 < argc) {
			const char *m = argv[++i];
			mode = !strcmp(m, "csp") ? PX_CIA402_CSP
			       : !strcmp(m, "cst") ? PX_CIA402_CST
			       : !strcmp(m, "csv") ? PX_CIA402_CSV
						   : -1;
			if (mode < 0) {
				fprintf(stderr, "proxima-simarm: mode %s: csp, "
					"csv or cst\n", m);
				return 2;
			}
		} else if (!strcmp(argv[i], "-h") || !strcmp(argv[i], "--help")) {
			usage(stdout);
			return 0;
		} else {
			usage(stderr);
			return 2;
		}
	}
	if ((!iface && !local) || n < 1 || n > PX_CANOPEN_MAX_DRIVES) {
		usage(stderr);
		return 2;
	}
	if (iface) {
		struct px_can_raw_config rc_;
		memset(&rc_, 0, sizeof rc_);
		rc_.interface = iface;
		rc = px_can_raw_open(&rc_, &bus, &e, msg, sizeof msg);
	} else {
		rc = px_can_unix_open(local, peer, &bus, msg, sizeof msg);
	}
	if (rc != PX_OK) {
		fprintf(stderr, "proxima-simarm: %s\n", msg);
		return 1;
	}
	for (i = 0; i < n; i++) {
		drv[i].node_id = (uint8_t)(i + 1);
		drv[i].mode = mode;
		drv[i].joint = i;
		drv[i].counts_per_unit = 100000.0;
		drv[i].rated_torque_n_m = 1.0;
	}
	memset(&sc, 0, sizeof sc);
	sc.drives = drv;
	sc.n_drives = (size_t)n;
	if (px_canopen_sim_create(&sc, bus, &sim) != PX_OK) {
		fprintf(stderr, "proxima-simarm: cannot create the arm\n");
		px_can_bus_close(bus);
		return 1;
	}
	signal(SIGINT, on_signal);
	signal(SIGTERM, on_signal);
	printf("proxima-simarm: %d drives on %s\n", n, iface ? iface : local);
	fflush(stdout);
	t0 = next = mono();
	while (!stop && (seconds <= 0 || mono() - t0 < (int64_t)(seconds * 1e9))) {
		struct timespec ts;
		if (px_canopen_sim_step(sim, mono()) == PX_E_IO) {
			fprintf(stderr, "proxima-simarm: bus receive failed "
				"(errno %d)\n", px_can_bus_errno(bus));
			break;
		}
		next += 250000; /* 4 kHz polling: SYNC answered promptly */
		ts.tv_sec = next / 1000000000;
		ts.tv_nsec = next % 1000000000;
		clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL);
	}
	px_canopen_sim_free(sim);
	px_can_bus_close(bus);
	return 0;
}
