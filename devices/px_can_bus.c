/* CAN buses: raw SocketCAN, in-process simulation, UNIX datagram
 * simulation, candump replay; interface state and bitrate through the
 * netlink calls of backends/px_socketcan.c (libsocketcan). */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <net/if.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <time.h>
#include <unistd.h>

#include <linux/can/error.h>
#include <linux/can/netlink.h>
#include <linux/can/raw.h>

#include "dev_internal.h"
#include "px_arena.h"
#include "px_file.h"
#include "px_can.h"
#include "px_ring.h"

enum { K_SIM, K_UNIX, K_RAW, K_REPLAY, K_REC, K_FAULT };

struct px_can_sim {
	struct px_can_sim_config cfg;
	struct px_can_bus **eps;
	size_t n_eps;
	struct px__can_fx fx;
};

struct px_can_bus {
	int kind;
	struct px_can_bus_stats st;
	int last_errno;
	int sock;
	int fd_frames;
	/* sim */
	struct px_can_sim *sim;
	struct px_can_msg *q;
	size_t qcap, qhead, qn;
	/* unix */
	struct sockaddr_un peer;
	int connected; /* connect()ed to peer (see unix_send) */
	char local[sizeof(((struct sockaddr_un *)0)->sun_path)];
	dev_t local_dev; /* the socket file this bus bound (close removes */
	ino_t local_ino; /* it only while it is still that file) */
	/* replay */
	struct px_can_msg *recs;
	int64_t *rec_t;
	size_t n_recs, next;
	int started;
	int64_t t0_now;
	/* recorder, fault wrapper */
	struct px_can_bus *inner;
	struct px__can_fx *fx;
	struct px_can_msg pend[4];
	size_t npend;
	struct px_arena arena;
	struct px_ring *ring;
	char iface[IFNAMSIZ + 8];
};

static struct px_can_bus *bus_new(int kind)
{
	struct px_can_bus *b = calloc(1, sizeof *b);
	if (!b)
		return NULL;
	b->kind = kind;
	b->sock = -1;
	b->st.state = PX_CAN_STATE_ACTIVE;
	return b;
}

/* ---- in-process simulation ----------------------------------------------- */

void px_can_sim_config_default(struct px_can_sim_config *c)
{
	if (!c)
		return;
	memset(c, 0, sizeof *c);
	c->queue = 256;
	c->max_endpoints = 8;
	c->seed = 1;
}

int px_can_sim_create(const struct px_can_sim_config *c,
		      struct px_can_sim **out)
{
	struct px_can_sim *s;
	if (!c || !out || c->queue < 1 || c->max_endpoints < 2 ||
	    c->max_endpoints > 64)
		return PX_E_INVAL;
	s = calloc(1, sizeof *s);
	if (!s)
		return PX_E_NOMEM;
	if (px__can_fx_init(&s->fx, c->faults, c->n_faults, c->seed, NULL, 0) !=
	    PX_OK) {
		free(s);
		return PX_E_INVAL;
	}
	s->eps = calloc(c->max_endpoints, sizeof *s->eps);
	if (!s->eps) {
		free(s);
		return PX_E_NOMEM;
	}
	s->cfg = *c;
	s->cfg.faults = s->fx.f;
	*out = s;
	return PX_OK;
}

int px_can_sim_endpoint(struct px_can_sim *s, struct px_can_bus **out)
{
	struct px_can_bus *b;
	if (!s || !out)
		return PX_E_INVAL;
	if (s->n_eps >= s->cfg.max_endpoints)
		return PX_E_NOSPC;
	b = bus_new(K_SIM);
	if (!b)
		return PX_E_NOMEM;
	b->q = calloc(s->cfg.queue, sizeof *b->q);
	if (!b->q) {
		free(b);
		return PX_E_NOMEM;
	}
	b->qcap = s->cfg.queue;
	b->sim = s;
	b->fd_frames = 1;
	s->eps[s->n_eps++] = b;
	*out = b;
	return PX_OK;
}

void px_can_sim_free(struct px_can_sim *s)
{
	size_t i;
	if (!s)
		return;
	for (i = 0; i < s->n_eps; i++)
		if (s->eps[i]) {
			s->eps[i]->sim = NULL;
			px_can_bus_close(s->eps[i]);
		}
	free(s->eps);
	free(s);
}

static void q_push(struct px_can_bus *b, const struct px_can_msg *m)
{
	if (b->qn >= b->qcap) {
		b->st.rx_dropped++;
		return;
	}
	b->q[(b->qhead + b->qn) % b->qcap] = *m;
	b->qn++;
}

static void sim_broadcast(struct px_can_sim *s, const struct px_can_bus *from,
			  const struct px_can_msg *m)
{
	size_t i;
	for (i = 0; i < s->n_eps; i++)
		if (s->eps[i] && s->eps[i] != from)
			q_push(s->eps[i], m);
}

static void err_frame(struct px_can_msg *e, int off, int64_t now)
{
	memset(e, 0, sizeof *e);
	e->f.can_id = CAN_ERR_FLAG | (off ? CAN_ERR_BUSOFF : CAN_ERR_RESTARTED);
	e->f.len = CAN_ERR_DLC;
	e->t_ns = now;
}

/* Fault windows at now: bus-off sends an error frame to everyone on
 * entry and on exit; unplug loses the frames in flight; frames held
 * back by delay arrive when due. */
static void sim_tick(struct px_can_sim *s, int64_t now)
{
	int ch = px__can_fx_tick(&s->fx, now);
	struct px_can_msg e;
	const void *from;
	size_t i;
	if (ch & 1) {
		err_frame(&e, s->fx.busoff, now);
		sim_broadcast(s, NULL, &e);
	}
	if ((ch & 2) && s->fx.unplugged)
		for (i = 0; i < s->n_eps; i++)
			if (s->eps[i])
				s->eps[i]->qn = 0;
	while (px__can_fx_due(&s->fx, now, &e, &from))
		sim_broadcast(s, from, &e);
}

static int sim_send(struct px_can_bus *b, const struct px_can_msg *m,
		    int64_t now)
{
	struct px_can_sim *s = b->sim;
	struct px_can_msg c[2];
	int n, k;
	if (!s)
		return PX_E_IO;
	sim_tick(s, now);
	if (s->fx.unplugged) {
		b->last_errno = ENODEV;
		return PX_E_NODEV;
	}
	if (s->fx.busoff) {
		b->last_errno = ENETDOWN;
		return PX_E_IO;
	}
	n = px__can_fx_apply(&s->fx, m, b, now, c);
	for (k = 0; k < n; k++)
		sim_broadcast(s, b, &c[k]);
	return PX_OK;
}

static int sim_recv(struct px_can_bus *b, int64_t now, struct px_can_msg *m)
{
	if (b->sim) {
		sim_tick(b->sim, now);
		if (b->sim->fx.unplugged) {
			b->last_errno = ENODEV;
			return PX_E_NODEV;
		}
	}
	if (!b->qn)
		return PX_E_AGAIN;
	*m = b->q[b->qhead];
	b->qhead = (b->qhead + 1) % b->qcap;
	b->qn--;
	return PX_OK;
}

/* ---- fault wrapper --------------------------------------------------------- */

int px_can_fault_open(struct px_can_bus *inner,
		      const struct px_sim_fault *faults, size_t n_faults,
		      uint64_t seed, struct px_can_bus **out, char *msg,
		      size_t cap)
{
	struct px_can_bus *b;
	struct px__can_fx *fx;
	int rc;
	if (msg && cap)
		msg[0] = 0;
	if (!inner || !out)
		return PX_E_INVAL;
	*out = NULL;
	fx = calloc(1, sizeof *fx);
	if (!fx)
		return PX_E_NOMEM;
	rc = px__can_fx_init(fx, faults, n_faults, seed, msg, cap);
	if (rc != PX_OK) {
		free(fx);
		return rc;
	}
	b = bus_new(K_FAULT);
	if (!b) {
		free(fx);
		return PX_E_NOMEM;
	}
	b->fx = fx;
	b->inner = inner;
	b->fd_frames = inner->fd_frames;
	*out = b;
	return PX_OK;
}

static void fault_tick(struct px_can_bus *b, int64_t now)
{
	int ch = px__can_fx_tick(b->fx, now);
	if ((ch & 1) && b->npend < 4)
		err_frame(&b->pend[b->npend++], b->fx->busoff, now);
	if ((ch & 2) && b->fx->unplugged)
		b->npend = 0;
}

static int fault_send(struct px_can_bus *b, const struct px_can_msg *m,
		      int64_t now)
{
	int rc;
	fault_tick(b, now);
	if (b->fx->unplugged) {
		b->last_errno = ENODEV;
		return PX_E_NODEV;
	}
	if (b->fx->busoff) {
		b->last_errno = ENETDOWN;
		return PX_E_IO;
	}
	rc = px_can_bus_send(b->inner, m, now);
	b->last_errno = px_can_bus_errno(b->inner);
	return rc;
}

static int fault_recv(struct px_can_bus *b, int64_t now, struct px_can_msg *m)
{
	struct px_can_msg c[2];
	int k, n, rc;
	fault_tick(b, now);
	if (b->npend) {
		*m = b->pend[0];
		memmove(b->pend, b->pend + 1, --b->npend * sizeof b->pend[0]);
		return PX_OK;
	}
	if (b->fx->unplugged) {
		/* the adapter is gone: what the peer sends meanwhile is lost */
		for (k = 0; k < 256 && px_can_bus_recv(b->inner, now, &c[0]) ==
					       PX_OK;
		     k++)
			;
		b->last_errno = ENODEV;
		return PX_E_NODEV;
	}
	for (k = 0; k < 256; k++) {
		if (px__can_fx_due(b->fx, now, m, NULL))
			return PX_OK;
		rc = px_can_bus_recv(b->inner, now, m);
		if (rc != PX_OK) {
			b->last_errno = px_can_bus_errno(b->inner);
			return rc;
		}
		if (b->fx->busoff && !(m->f.can_id & CAN_ERR_FLAG))
			continue; /* nothing reaches a bus-off controller */
		n = px__can_fx_apply(b->fx, m, NULL, now, c);
		if (n == 0)
			continue;
		*m = c[0];
		if (n == 2)
			b->pend[b->npend++] = c[1];
		return PX_OK;
	}
	return PX_E_AGAIN;
}

/* ---- UNIX datagram simulation ------------------------------------------- */

/* Make local_path free to bind without taking anything the caller did
 * not mean: nothing there is fine; a socket nobody is bound to (left by
 * a process that died: a datagram connect is refused) is removed;
 * anything else stays where it is and is refused: a live socket (two
 * runs on one path would steal frames from each other, and the first to
 * exit would delete the other's socket), a socket of another type, and
 * every file that is not a socket (a config typo must never delete a
 * file). The check and the bind are not one atomic step: two processes
 * starting in the same instant can still both see a stale socket, and
 * then one of them fails to bind (EADDRINUSE) or binds the other's
 * fresh path; close() removes only the file its own bind made. */
static int unix_claim(const char *path, char *msg, size_t cap)
{
	struct stat st;
	struct sockaddr_un a;
	int s, e, rc;
	if (lstat(path, &st) != 0) {
		e = errno;
		if (e == ENOENT)
			return PX_OK;
		if (msg)
			snprintf(msg, cap, "%s: %s", path, strerror(e));
		return e == EACCES ? PX_E_PERM : PX_E_IO;
	}
	if (!S_ISSOCK(st.st_mode)) {
		if (msg)
			snprintf(msg, cap, "%s exists and is %s, not a socket: "
				 "refusing to remove it", path,
				 px_file_kind(st.st_mode));
		return PX_E_INVAL;
	}
	s = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
	if (s < 0) {
		e = errno;
		if (msg)
			snprintf(msg, cap, "socket(AF_UNIX, SOCK_DGRAM): %s",
				 strerror(e));
		return PX_E_IO;
	}
	memset(&a, 0, sizeof a);
	a.sun_family = AF_UNIX;
	snprintf(a.sun_path, sizeof a.sun_path, "%s", path);
	rc = connect(s, (struct sockaddr *)&a, sizeof a);
	e = errno;
	close(s);
	/* accepted, or EPERM: a datagram socket connected to another peer
	 * refuses new senders, and only a live process has it connected */
	if (rc == 0 || e == EPERM) {
		if (msg)
			snprintf(msg, cap, "%s is in use: another process is "
				 "bound to it (a second run on the same "
				 "socket_path?): refusing to take it over",
				 path);
		return PX_E_BUSY;
	}
	if (e == ECONNREFUSED) {
		/* stale: nobody will ever read it */
		if (unlink(path) != 0 && errno != ENOENT) {
			e = errno;
			if (msg)
				snprintf(msg, cap, "%s: stale socket, cannot "
					 "remove it: %s", path, strerror(e));
			return e == EACCES || e == EPERM ? PX_E_PERM : PX_E_IO;
		}
		return PX_OK;
	}
	if (msg)
		snprintf(msg, cap, "%s is a socket that cannot be checked (%s): "
			 "refusing to remove it", path,
			 e == EPROTOTYPE ? "not a datagram socket"
					 : strerror(e));
	return e == EACCES ? PX_E_PERM : PX_E_BUSY;
}

int px_can_unix_open(const char *local_path, const char *peer_path,
		     struct px_can_bus **out, char *msg, size_t cap)
{
	struct px_can_bus *b;
	struct sockaddr_un a;
	struct stat st;
	int e, rc;
	if (msg && cap)
		msg[0] = 0;
	if (!local_path || !peer_path || !out)
		return PX_E_INVAL;
	*out = NULL;
	if (strlen(local_path) >= sizeof a.sun_path ||
	    strlen(peer_path) >= sizeof a.sun_path) {
		if (msg)
			snprintf(msg, cap, "UNIX socket path longer than %zu "
				 "bytes", sizeof a.sun_path - 1);
		return PX_E_INVAL;
	}
	if (!local_path[0]) {
		if (msg)
			snprintf(msg, cap, "empty UNIX socket path");
		return PX_E_INVAL;
	}
	rc = unix_claim(local_path, msg, cap);
	if (rc != PX_OK)
		return rc;
	b = bus_new(K_UNIX);
	if (!b)
		return PX_E_NOMEM;
	b->fd_frames = 1;
	b->sock = socket(AF_UNIX, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
	if (b->sock < 0) {
		e = errno;
		if (msg)
			snprintf(msg, cap, "socket(AF_UNIX, SOCK_DGRAM): %s",
				 strerror(e));
		free(b);
		return PX_E_IO;
	}
	memset(&a, 0, sizeof a);
	a.sun_family = AF_UNIX;
	snprintf(a.sun_path, sizeof a.sun_path, "%s", local_path);
	if (bind(b->sock, (struct sockaddr *)&a, sizeof a) != 0) {
		e = errno;
		if (msg)
			snprintf(msg, cap, "bind(%s): %s%s", local_path,
				 strerror(e),
				 e == EADDRINUSE ? " (another process took "
						   "it meanwhile)"
						 : "");
		close(b->sock);
		free(b);
		return e == EACCES ? PX_E_PERM
		       : e == EADDRINUSE ? PX_E_BUSY
					 : PX_E_IO;
	}
	/* the file this bind made: close() removes it only while it is
	 * still this one (another process may have replaced it) */
	if (lstat(local_path, &st) == 0 && S_ISSOCK(st.st_mode)) {
		snprintf(b->local, sizeof b->local, "%s", local_path);
		b->local_dev = st.st_dev;
		b->local_ino = st.st_ino;
	}
	memset(&b->peer, 0, sizeof b->peer);
	b->peer.sun_family = AF_UNIX;
	snprintf(b->peer.sun_path, sizeof b->peer.sun_path, "%s", peer_path);
	*out = b;
	return PX_OK;
}

static int unix_send(struct px_can_bus *b, const struct px_can_msg *m,
		     int64_t now)
{
	size_t mtu = m->fd ? CANFD_MTU : CAN_MTU;
	(void)now;
	/* Connected, not sendto(): the kernel caps an unconnected datagram
	 * receiver at net.unix.max_dgram_qlen (10) queued frames, fewer
	 * than one SYNC's answers of a 6-drive arm; a receiver connected
	 * back to its sender is limited only by its buffer. A peer not
	 * there yet (ENOENT, ECONNREFUSED) or gone and rebound
	 * (ECONNREFUSED, ENOTCONN) is connected again on the next send. */
	if (!b->connected) {
		if (connect(b->sock, (const struct sockaddr *)&b->peer,
			    sizeof b->peer) != 0) {
			b->last_errno = errno;
			b->st.tx_dropped++;
			return errno == ENOENT || errno == ECONNREFUSED ||
					       errno == EAGAIN
				       ? PX_E_AGAIN
				       : PX_E_IO;
		}
		b->connected = 1;
	}
	/* struct can_frame is the first CAN_MTU bytes of canfd_frame with
	 * the same field offsets: the frame goes out as SocketCAN has it. */
	if (send(b->sock, &m->f, mtu, MSG_DONTWAIT) == (ssize_t)mtu)
		return PX_OK;
	b->last_errno = errno;
	if (errno == ECONNREFUSED || errno == ENOTCONN)
		b->connected = 0;
	if (errno == EAGAIN || errno == ENOBUFS || errno == ECONNREFUSED ||
	    errno == ENOENT) {
		b->st.tx_dropped++; /* no peer yet, or it is not reading */
		return PX_E_AGAIN;
	}
	return PX_E_IO;
}

static int unix_recv(struct px_can_bus *b, int64_t now, struct px_can_msg *m)
{
	ssize_t n;
	memset(m, 0, sizeof *m);
	for (;;) {
		n = recv(b->sock, &m->f, sizeof m->f, MSG_DONTWAIT);
		if (n < 0) {
			if (errno == EAGAIN || errno == EWOULDBLOCK)
				return PX_E_AGAIN;
			b->last_errno = errno;
			return PX_E_IO;
		}
		if (n == CAN_MTU || n == CANFD_MTU)
			break;
		b->st.rx_dropped++; /* not a SocketCAN frame */
	}
	m->fd = n == CANFD_MTU;
	if (!m->fd && m->f.len > CAN_MAX_DLEN)
		m->f.len = CAN_MAX_DLEN;
	if (m->fd && m->f.len > CANFD_MAX_DLEN)
		m->f.len = CANFD_MAX_DLEN;
	m->t_ns = now;
	return PX_OK;
}

/* ---- raw SocketCAN ------------------------------------------------------- */

static int64_t clock_ns(clockid_t c)
{
	struct timespec ts;
	clock_gettime(c, &ts);
	return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

#define FAIL(code, ...)                                           \
	do {                                                      \
		if (msg)                                          \
			snprintf(msg, cap, __VA_ARGS__);          \
		rc = (code);                                      \
		goto fail;                                        \
	} while (0)

int px_can_raw_open(const struct px_can_raw_config *c,
		    struct px_can_bus **out, int *sys_errno, char *msg,
		    size_t cap)
{
	struct px_can_bus *b;
	struct sockaddr_can addr;
	struct can_filter flt[64];
	unsigned idx;
	int one = 1, e = 0, rc, opt;
	const char *nm;
	if (msg && cap)
		msg[0] = 0;
	if (sys_errno)
		*sys_errno = 0;
	if (!c || !out || !c->interface || !*c->interface ||
	    strlen(c->interface) >= IFNAMSIZ || c->n_filters > 64 ||
	    (c->n_filters && !c->filters)) {
		if (msg)
			snprintf(msg, cap, "CAN: interface name (< %d bytes) "
				 "and at most 64 filters", IFNAMSIZ);
		return PX_E_INVAL;
	}
	*out = NULL;
	b = bus_new(K_RAW);
	if (!b)
		return PX_E_NOMEM;
	b->fd_frames = c->fd;
	b->sock = socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC,
			 CAN_RAW);
	if (b->sock < 0) {
		e = errno;
		nm = strerrorname_np(e);
		if (e == EAFNOSUPPORT || e == EPROTONOSUPPORT)
			FAIL(PX_E_UNSUPPORTED,
			     "%s: socket(PF_CAN, SOCK_RAW, CAN_RAW): errno %s "
			     "(%d): %s: this kernel has no AF_CAN support "
			     "(modprobe can can-raw; for a virtual bus modprobe "
			     "vcan and ip link add dev vcan0 type vcan)",
			     c->interface, nm ? nm : "?", e, strerror(e));
		FAIL(e == EACCES || e == EPERM ? PX_E_PERM : PX_E_IO,
		     "%s: socket(PF_CAN, SOCK_RAW, CAN_RAW): errno %s (%d): %s",
		     c->interface, nm ? nm : "?", e, strerror(e));
	}
	idx = if_nametoindex(c->interface);
	if (!idx) {
		e = errno;
		nm = strerrorname_np(e);
		FAIL(PX_E_NODEV,
		     "%s: no such network interface: errno %s (%d): %s "
		     "(ip -details link show type can lists CAN interfaces; "
		     "a virtual one: ip link add dev %s type vcan)",
		     c->interface, nm ? nm : "?", e, strerror(e), c->interface);
	}
	if (c->fd && setsockopt(b->sock, SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &one,
				sizeof one) != 0) {
		e = errno;
		FAIL(PX_E_UNSUPPORTED, "%s: CAN FD frames refused "
		     "(setsockopt CAN_RAW_FD_FRAMES): %s", c->interface,
		     strerror(e));
	}
	if (c->n_filters) {
		size_t i;
		for (i = 0; i < c->n_filters; i++) {
			flt[i].can_id = c->filters[i].id |
					(c->filters[i].extended ? CAN_EFF_FLAG
								: 0);
			flt[i].can_mask = c->filters[i].mask | CAN_EFF_FLAG |
					  CAN_RTR_FLAG;
		}
		if (setsockopt(b->sock, SOL_CAN_RAW, CAN_RAW_FILTER, flt,
			       (socklen_t)(c->n_filters * sizeof flt[0])) != 0) {
			e = errno;
			FAIL(PX_E_IO, "%s: setsockopt CAN_RAW_FILTER: %s",
			     c->interface, strerror(e));
		}
	}
	opt = c->error_frames ? (int)CAN_ERR_MASK : 0;
	if (setsockopt(b->sock, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &opt,
		       sizeof opt) != 0) {
		e = errno;
		FAIL(PX_E_IO, "%s: setsockopt CAN_RAW_ERR_FILTER: %s",
		     c->interface, strerror(e));
	}
	opt = c->loopback_own ? 1 : 0;
	setsockopt(b->sock, SOL_CAN_RAW, CAN_RAW_RECV_OWN_MSGS, &opt,
		   sizeof opt);
	if (setsockopt(b->sock, SOL_SOCKET, SO_TIMESTAMPNS, &one,
		       sizeof one) != 0) {
		e = errno;
		FAIL(PX_E_IO, "%s: setsockopt SO_TIMESTAMPNS: %s",
		     c->interface, strerror(e));
	}
	memset(&addr, 0, sizeof addr);
	addr.can_family = AF_CAN;
	addr.can_ifindex = (int)idx;
	if (bind(b->sock, (struct sockaddr *)&addr, sizeof addr) != 0) {
		e = errno;
		nm = strerrorname_np(e);
		FAIL(e == ENETDOWN ? PX_E_NODEV : PX_E_IO,
		     "%s: bind: errno %s (%d): %s%s", c->interface,
		     nm ? nm : "?", e, strerror(e),
		     e == ENETDOWN ? " (ip link set up the interface)" : "");
	}
	*out = b;
	return PX_OK;
fail:
	if (sys_errno)
		*sys_errno = e;
	if (b->sock >= 0)
		close(b->sock);
	free(b);
	return rc;
}

static int raw_send(struct px_can_bus *b, const struct px_can_msg *m,
		    int64_t now)
{
	size_t mtu = m->fd ? CANFD_MTU : CAN_MTU;
	(void)now;
	if (m->fd && !b->fd_frames)
		return PX_E_INVAL;
	if (write(b->sock, &m->f, mtu) == (ssize_t)mtu)
		return PX_OK;
	b->last_errno = errno;
	if (errno == EAGAIN || errno == ENOBUFS) {
		b->st.tx_dropped++;
		return PX_E_AGAIN;
	}
	return errno == ENODEV || errno == ENXIO ? PX_E_NODEV : PX_E_IO;
}

static int raw_recv(struct px_can_bus *b, int64_t now, struct px_can_msg *m)
{
	struct iovec iov;
	struct msghdr mh;
	char ctrl[CMSG_SPACE(sizeof(struct timespec)) + 64];
	struct cmsghdr *cm;
	ssize_t n;
	(void)now;
	memset(m, 0, sizeof *m);
	iov.iov_base = &m->f;
	iov.iov_len = sizeof m->f;
	memset(&mh, 0, sizeof mh);
	mh.msg_iov = &iov;
	mh.msg_iovlen = 1;
	mh.msg_control = ctrl;
	mh.msg_controllen = sizeof ctrl;
	n = recvmsg(b->sock, &mh, MSG_DONTWAIT);
	if (n < 0) {
		if (errno == EAGAIN || errno == EWOULDBLOCK)
			return PX_E_AGAIN;
		b->last_errno = errno;
		/* a USB adapter pulled out: the interface is gone */
		return errno == ENODEV || errno == ENXIO ? PX_E_NODEV : PX_E_IO;
	}
	if (n != CAN_MTU && n != CANFD_MTU) {
		b->st.rx_dropped++;
		return PX_E_AGAIN;
	}
	m->fd = n == CANFD_MTU;
	m->t_ns = clock_ns(CLOCK_MONOTONIC);
	for (cm = CMSG_FIRSTHDR(&mh); cm; cm = CMSG_NXTHDR(&mh, cm)) {
		if (cm->cmsg_level == SOL_SOCKET &&
		    cm->cmsg_type == SCM_TIMESTAMPNS) {
			struct timespec ts;
			int64_t rt, off;
			memcpy(&ts, CMSG_DATA(cm), sizeof ts);
			rt = (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
			/* kernel stamps on CLOCK_REALTIME; move it onto the
			 * loop's clock */
			off = clock_ns(CLOCK_REALTIME) - m->t_ns;
			m->t_ns = rt - off;
		}
	}
	return PX_OK;
}

int px_can_iface_state(const char *iface, int *state)
{
	char p[64];
	if (!iface || !state)
		return PX_E_INVAL;
	if (if_nametoindex(iface) == 0)
		return PX_E_NODEV;
	/* vcan/vxcan have no controller, hence no state; libsocketcan would
	 * print "no link data found" on stderr for them. Controllers (also
	 * USB adapters) have a parent device in sysfs. */
	snprintf(p, sizeof p, "/sys/class/net/%s/device", iface);
	if (strlen(iface) >= IF_NAMESIZE || access(p, F_OK) != 0)
		return PX_E_UNSUPPORTED;
	return px__socketcan_state(iface, state);
}

/* ---- bitrate through netlink (libsocketcan) --------------------------- */

static int nl_exists(const char *iface)
{
	return if_nametoindex(iface) != 0;
}

/* vcan/vxcan have no controller: no parent device in sysfs. */
static int nl_is_virtual(const char *iface)
{
	char p[64];
	snprintf(p, sizeof p, "/sys/class/net/%s/device", iface);
	return access(p, F_OK) != 0;
}

static const struct px_can_netlink_ops nl_default = {
	nl_exists,		     nl_is_virtual,
	px__socketcan_do_stop,	     px__socketcan_do_start,
	px__socketcan_set_bitrate, px__socketcan_set_restart_ms,
	px__socketcan_get_bitrate,
};
static const struct px_can_netlink_ops *nl = &nl_default;

void px_can_netlink_set_ops(const struct px_can_netlink_ops *ops)
{
	nl = ops ? ops : &nl_default;
}

#define NLFAIL(code, call)                                                  \
	do {                                                                \
		e = errno ? errno : EIO;                                    \
		nm = strerrorname_np(e);                                    \
		if (msg)                                                    \
			snprintf(msg, cap,                                  \
				 "%s: %s: errno %s (%d): %s%s", iface, call, \
				 nm ? nm : "?", e, strerror(e),             \
				 e == EPERM || e == EACCES                  \
					 ? " (setting a CAN bitrate needs "  \
					   "CAP_NET_ADMIN: run as root, "   \
					   "give the program the capability, " \
					   "or set it with ip link set "    \
					   "<iface> type can bitrate N)"    \
					 : "");                              \
		if (sys_errno)                                              \
			*sys_errno = e;                                     \
		rc = (code);                                                \
	} while (0)

int px_can_iface_set_bitrate(const char *iface, uint32_t bitrate,
			     uint32_t restart_ms, int *sys_errno, char *msg,
			     size_t cap)
{
	const char *nm;
	int e, rc = PX_OK;
	if (msg && cap)
		msg[0] = 0;
	if (sys_errno)
		*sys_errno = 0;
	if (!iface || !*iface || strlen(iface) >= IFNAMSIZ || bitrate == 0 ||
	    bitrate > 8000000) {
		if (msg)
			snprintf(msg, cap, "CAN bitrate: interface name (< %d "
				 "bytes) and a bitrate of 1 .. 8000000 bit/s",
				 IFNAMSIZ);
		return PX_E_INVAL;
	}
	if (nl == &nl_default && !px__socketcan_have()) {
		if (msg)
			snprintf(msg, cap, "%s: this build has no libsocketcan: "
				 "%u bit/s not applied (set it with ip link set "
				 "%s type can bitrate %u)", iface, bitrate,
				 iface, bitrate);
		return PX_E_UNSUPPORTED;
	}
	if (!nl->exists(iface)) {
		if (msg)
			snprintf(msg, cap, "%s: no such network interface (ip "
				 "-details link show type can lists CAN "
				 "interfaces)", iface);
		if (sys_errno)
			*sys_errno = ENODEV;
		return PX_E_NODEV;
	}
	if (nl->is_virtual(iface)) {
		if (msg)
			snprintf(msg, cap, "%s: a virtual CAN interface (vcan, "
				 "vxcan) has no bitrate: %u bit/s not applied",
				 iface, bitrate);
		return PX_E_UNSUPPORTED;
	}
	/* Already so (set by ip link, say): nothing to do, no privilege
	 * needed. */
	{
		uint32_t now_bps = 0;
		if (!restart_ms && nl->get_bitrate &&
		    nl->get_bitrate(iface, &now_bps) == 0 && now_bps == bitrate)
			return PX_OK;
	}
	/* The bitrate can only change while the interface is down. */
	errno = 0;
	if (nl->do_stop(iface) != 0) {
		NLFAIL(errno == EPERM || errno == EACCES ? PX_E_PERM : PX_E_IO,
		       "can_do_stop (ip link set down)");
		return rc;
	}
	errno = 0;
	if (nl->set_bitrate(iface, bitrate) != 0)
		NLFAIL(errno == EPERM || errno == EACCES ? PX_E_PERM
		       : errno == EOPNOTSUPP || errno == EINVAL
			       ? PX_E_UNSUPPORTED
			       : PX_E_IO,
		       "can_set_bitrate");
	if (rc == PX_OK && restart_ms) {
		errno = 0;
		if (nl->set_restart_ms(iface, restart_ms) != 0)
			NLFAIL(errno == EPERM || errno == EACCES ? PX_E_PERM
								 : PX_E_IO,
			       "can_set_restart_ms");
	}
	/* Up again even after a failed setting: the bus worked before. */
	errno = 0;
	if (nl->do_start(iface) != 0 && rc == PX_OK)
		NLFAIL(errno == EPERM || errno == EACCES ? PX_E_PERM : PX_E_IO,
		       "can_do_start (ip link set up)");
	return rc;
}

int px_can_iface_restart(const char *iface)
{
	if (!iface)
		return PX_E_INVAL;
	if (if_nametoindex(iface) == 0)
		return PX_E_NODEV;
	return px__socketcan_restart(iface);
}

/* ---- replay ---------------------------------------------------------------- */

int px_can_replay_open(const char *path, const char *iface,
		       struct px_can_bus **out, char *msg, size_t cap)
{
	char *data = NULL, *cur, *line, ifn[IFNAMSIZ + 8];
	struct px_can_bus *b;
	size_t capn = 0, dlen = 0;
	int lineno = 0, rc = PX_OK;
	if (msg && cap)
		msg[0] = 0;
	if (!path || !out)
		return PX_E_INVAL;
	*out = NULL;
	/* Whole, within the log limit: a NUL byte is an error at its line
	 * and column, never the end of a line, and /dev/zero stops at its
	 * first read. Whole lines, never a fixed buffer that would split a
	 * long line into pieces parsed as lines of their own. */
	rc = px_file_read(path, PX_FILE_LOG_MAX_BYTES, PX_FILE_TEXT, "CAN log",
			  &data, &dlen, msg, cap);
	if (rc != PX_OK)
		return rc;
	b = bus_new(K_REPLAY);
	if (!b) {
		free(data);
		return PX_E_NOMEM;
	}
	b->fd_frames = 1;
	cur = data;
	while ((line = px_file_next_line(&cur)) != NULL) {
		struct px_can_msg m;
		int64_t t;
		lineno++;
		if (line[0] == 0 || line[0] == '#')
			continue;
		if (px_can_log_parse(line, &m, &t, ifn, sizeof ifn) != PX_OK) {
			if (msg)
				snprintf(msg, cap, "%s:%d: not a candump -l line "
					 "\"(sec.usec) iface id#data\"", path,
					 lineno);
			rc = PX_E_PARSE;
			break;
		}
		if (iface && strcmp(iface, ifn) != 0)
			continue;
		if (b->n_recs == capn) {
			size_t nc = capn ? capn * 2 : 256;
			struct px_can_msg *nr = realloc(b->recs, nc * sizeof *nr);
			int64_t *nt;
			if (!nr) {
				rc = PX_E_NOMEM;
				break;
			}
			b->recs = nr;
			nt = realloc(b->rec_t, nc * sizeof *nt);
			if (!nt) {
				rc = PX_E_NOMEM;
				break;
			}
			b->rec_t = nt;
			capn = nc;
		}
		b->recs[b->n_recs] = m;
		b->rec_t[b->n_recs] = t;
		b->n_recs++;
	}
	free(data);
	if (rc != PX_OK) {
		px_can_bus_close(b);
		return rc;
	}
	*out = b;
	return PX_OK;
}

static int replay_recv(struct px_can_bus *b, int64_t now, struct px_can_msg *m)
{
	int64_t off;
	if (!b->started) {
		b->started = 1;
		b->t0_now = now;
	}
	if (b->next >= b->n_recs)
		return PX_E_AGAIN;
	off = b->rec_t[b->next] - b->rec_t[0];
	if (now - b->t0_now < off)
		return PX_E_AGAIN;
	*m = b->recs[b->next++];
	m->t_ns = b->t0_now + off;
	return PX_OK;
}

/* ---- common --------------------------------------------------------------- */

int px_can_bus_send(struct px_can_bus *b, const struct px_can_msg *m,
		    int64_t now_ns)
{
	int rc;
	if (!b || !m || m->f.len > (m->fd ? CANFD_MAX_DLEN : CAN_MAX_DLEN))
		return PX_E_INVAL;
	switch (b->kind) {
	case K_SIM: rc = sim_send(b, m, now_ns); break;
	case K_UNIX: rc = unix_send(b, m, now_ns); break;
	case K_RAW: rc = raw_send(b, m, now_ns); break;
	case K_REC:
		rc = px_can_bus_send(b->inner, m, now_ns);
		b->last_errno = px_can_bus_errno(b->inner);
		if (rc == PX_OK) {
			struct px_can_msg c = *m;
			c.t_ns = now_ns;
			px_ring_push(b->ring, &c);
		}
		break;
	case K_FAULT: rc = fault_send(b, m, now_ns); break;
	default: rc = PX_OK; break; /* replay: sends go nowhere */
	}
	if (rc == PX_OK)
		b->st.tx++;
	return rc;
}

int px_can_bus_recv(struct px_can_bus *b, int64_t now_ns,
		    struct px_can_msg *m)
{
	int rc;
	if (!b || !m)
		return PX_E_INVAL;
	switch (b->kind) {
	case K_SIM: rc = sim_recv(b, now_ns, m); break;
	case K_UNIX: rc = unix_recv(b, now_ns, m); break;
	case K_RAW: rc = raw_recv(b, now_ns, m); break;
	case K_REC:
		rc = px_can_bus_recv(b->inner, now_ns, m);
		b->last_errno = px_can_bus_errno(b->inner);
		if (rc == PX_OK)
			px_ring_push(b->ring, m);
		break;
	case K_FAULT: rc = fault_recv(b, now_ns, m); break;
	default: rc = replay_recv(b, now_ns, m); break;
	}
	if (rc != PX_OK)
		return rc;
	b->st.rx++;
	if (m->f.can_id & CAN_ERR_FLAG) {
		struct px_can_err_info e;
		b->st.err_frames++;
		if (px_can_err_decode(&m->f, &e) == PX_OK &&
		    e.state != PX_CAN_STATE_UNKNOWN)
			b->st.state = e.state;
	}
	return PX_OK;
}

void px_can_bus_stats(const struct px_can_bus *b, struct px_can_bus_stats *st)
{
	if (!st)
		return;
	if (!b) {
		memset(st, 0, sizeof *st);
		return;
	}
	*st = b->st;
}

int px_can_bus_errno(const struct px_can_bus *b)
{
	return b ? b->last_errno : 0;
}

void px_can_bus_close(struct px_can_bus *b)
{
	size_t i;
	if (!b)
		return;
	if (b->sim)
		for (i = 0; i < b->sim->n_eps; i++)
			if (b->sim->eps[i] == b)
				b->sim->eps[i] = NULL;
	if (b->kind == K_UNIX && b->local[0]) {
		/* only the socket file this bus bound: never one another
		 * process has put there since */
		struct stat st;
		if (lstat(b->local, &st) == 0 && S_ISSOCK(st.st_mode) &&
		    st.st_dev == b->local_dev && st.st_ino == b->local_ino)
			unlink(b->local);
	}
	if (b->sock >= 0)
		close(b->sock);
	free(b->q);
	free(b->recs);
	free(b->rec_t);
	if (b->kind == K_REC) {
		px_can_bus_close(b->inner);
		px_arena_fini(&b->arena);
	}
	if (b->kind == K_FAULT)
		px_can_bus_close(b->inner);
	free(b->fx);
	free(b);
}

int px_can_record_open(struct px_can_bus *inner, size_t capacity,
		       const char *iface, struct px_can_bus **out)
{
	struct px_can_bus *b;
	if (!inner || !out || capacity < 2 || capacity > (1u << 20))
		return PX_E_INVAL;
	*out = NULL;
	b = bus_new(K_REC);
	if (!b)
		return PX_E_NOMEM;
	if (px_arena_init_alloc(&b->arena,
				px_ring_size(capacity, sizeof(struct px_can_msg))) !=
		    PX_OK ||
	    px_ring_create(&b->arena, capacity, sizeof(struct px_can_msg),
			   &b->ring) != PX_OK) {
		px_arena_fini(&b->arena);
		free(b);
		return PX_E_NOMEM;
	}
	b->inner = inner;
	b->fd_frames = inner->fd_frames;
	snprintf(b->iface, sizeof b->iface, "%s", iface ? iface : "can0");
	*out = b;
	return PX_OK;
}

int px_can_record_flush(struct px_can_bus *b, FILE *f, uint64_t *dropped)
{
	struct px_can_msg m;
	char line[256];
	int n = 0;
	int64_t off;
	if (!b || b->kind != K_REC || !f)
		return PX_E_INVAL;
	off = clock_ns(CLOCK_REALTIME) - clock_ns(CLOCK_MONOTONIC);
	while (px_ring_pop(b->ring, &m) == PX_OK) {
		if (px_can_log_format(&m, m.t_ns + off, b->iface, line,
				      sizeof line) < 0)
			continue;
		if (fprintf(f, "%s\n", line) < 0)
			return PX_E_IO;
		n++;
	}
	if (dropped)
		*dropped = px_ring_dropped(b->ring);
	return n;
}
