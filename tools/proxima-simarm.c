/* proxima-simarm: a simulated arm of CiA 402 drives speaking proxima's
 * CANopen-lite subset, as its own process, on a SocketCAN interface
 * (vcan0, can0) or on a simulated bus over a UNIX datagram socket - the
 * other side of a controller using px_canopen. With --config it takes
 * the controller's drive table and PDO mapping (and, unless --can or
 * --unix is given, its bus) from the controller's configuration file. */
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "px_canopen.h"
#include "px_config.h"
#include "px_devcfg.h"

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
		"       proxima-simarm --config FILE [--device NAME] "
		"[--can IFACE | --unix LOCAL PEER] [--seconds S]\n"
		"Simulates N (default 6) CiA 402 drives, node ids 1..N, joint "
		"i on node i+1,\n100000 counts per rad, rated torque 1 N m, "
		"the default PDO layout; runs S seconds\n(default: until a "
		"signal). With --config, the drives (node ids, modes, joints, "
		"counts_per_unit,\nrated torque) and the rpdo/tpdo1/tpdo2 "
		"mapping are those of the controller's socketcan\ndevice NAME "
		"(default: the first with canopen drives), and so is the bus: "
		"its kernel\ninterface, or for transport unix the other end "
		"(binds socket_path.peer, sends to\nsocket_path; an existing "
		"file there is removed only when it is a stale socket); the "
		"device's faults with node_id (estop, unplug of that drive)\n"
		"are injected, timed from the start of proxima-simarm.\n");
}

/* A number for flag within [lo, hi]; integer ones must be whole. Returns
 * 0, or 2 having said why (usage error). */
static int number(const char *flag, const char *v, double lo, double hi,
		  int integer, double *out)
{
	char *end;
	double d;
	errno = 0;
	d = strtod(v, &end);
	if (end == v || *end || errno || !isfinite(d) || d < lo || d > hi ||
	    (integer && d != floor(d))) {
		fprintf(stderr, "proxima-simarm: %s: '%s' is not %s in [%g, "
			"%g]\n", flag, v, integer ? "a whole number" : "a number",
			lo, hi);
		return 2;
	}
	*out = d;
	return 0;
}

/* What a --config gives: the bus's other end, the drives, their PDO
 * layout and faults. */
struct layout {
	struct px_config *cfg;
	struct px_canopen_pdo_map pdo;
	struct px_canopen_drive_cfg drv[PX_CANOPEN_MAX_DRIVES];
	struct px_sim_fault faults[PX_SIM_MAX_FAULTS];
	int n, n_faults;
	const char *iface, *local, *peer;
	char upeer[256], ulocal[256];
};

/* The arm of a config's device (devname, or the first socketcan device
 * with CANopen drives); need_bus: the bus's end from the config too.
 * 0, or the exit status with the config freed. */
static int from_config(struct layout *L, const char *config, const char *devname,
		       int need_bus)
{
	static struct px_config_diag diag;
	const struct px_config_device *dc = NULL;
	size_t k, nd = 0;
	char msg[400];
	int rc;
	px_config_diag_init(&diag);
	rc = px_config_load_file(config, &L->cfg, &diag);
	if (rc != PX_OK) {
		px_config_diag_print(&diag, stderr);
		fprintf(stderr, "proxima-simarm: %s: invalid "
			"configuration\n", config);
		return 1;
	}
	for (k = 0; k < L->cfg->n_devices && !dc; k++) {
		const struct px_config_device *d = &L->cfg->devices[k];
		if (devname ? !strcmp(d->name, devname)
			    : d->backend == PX_CONFIG_BACKEND_SOCKETCAN &&
				      d->socketcan.canopen.n_drives)
			dc = d;
	}
	if (!dc) {
		fprintf(stderr, "proxima-simarm: %s: %s\n", config,
			devname ? "no device of that name"
				: "no socketcan device with canopen "
				  "drives");
		goto fail1;
	}
	rc = px_devcfg_canopen_layout(L->cfg, dc, L->drv, PX_CANOPEN_MAX_DRIVES, &nd,
				      &L->pdo, msg, sizeof msg);
	if (rc != PX_OK) {
		fprintf(stderr, "proxima-simarm: %s: %s\n", config,
			msg[0] ? msg : px_strerror(rc));
		goto fail1;
	}
	L->n = (int)nd;
	/* the config's drive faults (node_id), from our start */
	L->n_faults = px_devcfg_arm_faults(L->cfg, dc, 0, L->faults, PX_SIM_MAX_FAULTS);
	if (L->n_faults < 0) {
		fprintf(stderr, "proxima-simarm: %s: device '%s': "
			"faults: %s\n", config, dc->name,
			px_strerror(L->n_faults));
		goto fail1;
	}
	if (need_bus) {
		const struct px_config_socketcan *c = &dc->socketcan;
		if (c->transport == PX_CONFIG_CAN_KERNEL) {
			L->iface = c->interface;
		} else if (c->transport == PX_CONFIG_CAN_UNIX) {
			/* the controller binds socket_path and sends
			 * to socket_path.peer: the other end */
			snprintf(L->ulocal, sizeof L->ulocal, "%s.peer", c->socket_path);
			snprintf(L->upeer, sizeof L->upeer, "%s", c->socket_path);
			L->local = L->ulocal;
			L->peer = L->upeer;
		} else {
			fprintf(stderr, "proxima-simarm: device '%s' is "
				"on an in-process simulated bus "
				"(transport sim), which another process "
				"cannot join: use transport unix or give "
				"--can / --unix\n", dc->name);
			px_config_free(L->cfg);
			L->cfg = NULL;
			return 2;
		}
	}
	return 0;
fail1:
	px_config_free(L->cfg);
	L->cfg = NULL;
	return 1;
}

/* The drives' own view at the end: what the controller last told them
 * over the bus (a controller that stopped safely leaves each in switch
 * on disabled). */
static void report_end(struct px_canopen_sim *sim,
		       const struct px_canopen_drive_cfg *drv, int n)
{
	int k, st;
	double pos;
	for (k = 0; k < n; k++)
		if (px_canopen_sim_joint(sim, (size_t)k, &pos, &st) == PX_OK)
			printf("proxima-simarm: drive %d (node %u) at the "
			       "end: %s, position %.6g\n",
			       k, drv[k].node_id, px_cia402_state_name(st), pos);
	fflush(stdout);
}

int main(int argc, char **argv)
{
	const char *iface = NULL, *local = NULL, *peer = NULL;
	const char *config = NULL, *devname = NULL;
	int n = 6, mode = PX_CIA402_CSV, i, rc, e, layout_flags = 0;
	static struct layout L;
	int n_faults = 0;
	double seconds = 0;
	struct px_can_bus *bus = NULL;
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
		} else if (!strcmp(argv[i], "--config") && i + 1 < argc) {
			config = argv[++i];
		} else if (!strcmp(argv[i], "--device") && i + 1 < argc) {
			devname = argv[++i];
		} else if (!strcmp(argv[i], "--drives") && i + 1 < argc) {
			double d;
			if (number("--drives", argv[++i], 1,
				   PX_CANOPEN_MAX_DRIVES, 1, &d))
				return 2;
			n = (int)d;
			layout_flags = 1;
		} else if (!strcmp(argv[i], "--seconds") && i + 1 < argc) {
			/* bounded: the loop's nanoseconds stay in int64 */
			if (number("--seconds", argv[++i], 0, 1e8, 0, &seconds))
				return 2;
		} else if (!strcmp(argv[i], "--mode") && i + 1 < argc) {
			const char *m = argv[++i];
			layout_flags = 1;
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
	if (config) {
		if (layout_flags) {
			fprintf(stderr, "proxima-simarm: --drives and --mode "
				"come from the config with --config\n");
			return 2;
		}
		rc = from_config(&L, config, devname, !iface && !local);
		if (rc)
			return rc;
		n = L.n;
		n_faults = L.n_faults;
		if (!iface && !local) {
			iface = L.iface;
			local = L.local;
			peer = L.peer;
		}
	}
	if ((!iface && !local) || n < 1 || n > PX_CANOPEN_MAX_DRIVES) {
		usage(stderr);
		px_config_free(L.cfg);
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
		px_config_free(L.cfg);
		return 1;
	}
	for (i = 0; i < n && !config; i++) {
		L.drv[i].node_id = (uint8_t)(i + 1);
		L.drv[i].mode = mode;
		L.drv[i].joint = i;
		L.drv[i].counts_per_unit = 100000.0;
		L.drv[i].rated_torque_n_m = 1.0;
	}
	t0 = next = mono();
	for (i = 0; i < n_faults; i++)
		L.faults[i].start_ns += t0;
	memset(&sc, 0, sizeof sc);
	sc.pdo = config ? &L.pdo : NULL;
	sc.faults = n_faults > 0 ? L.faults : NULL;
	sc.n_faults = n_faults > 0 ? (size_t)n_faults : 0;
	sc.drives = L.drv;
	sc.n_drives = (size_t)n;
	if (px_canopen_sim_create(&sc, bus, &sim) != PX_OK) {
		fprintf(stderr, "proxima-simarm: cannot create the arm\n");
		px_can_bus_close(bus);
		px_config_free(L.cfg);
		return 1;
	}
	signal(SIGINT, on_signal);
	signal(SIGTERM, on_signal);
	/* stdout may be a pipe its reader closed (proxima-run reads only
	 * the first line): a late report must not kill the arm before it
	 * has closed its bus and removed its socket */
	signal(SIGPIPE, SIG_IGN);
	printf("proxima-simarm: %d drives on %s%s%s\n", n, iface ? iface : local,
	       config ? ", layout from " : "", config ? config : "");
	fflush(stdout);
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
	report_end(sim, L.drv, n);
	px_canopen_sim_free(sim);
	px_can_bus_close(bus);
	px_config_free(L.cfg);
	return 0;
}
