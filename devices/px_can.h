/*
 * px_can.h - CAN: a DBC-like signal codec, buses (SocketCAN raw sockets,
 * an in-process simulated bus, a simulated bus between processes over a
 * UNIX datagram socket, candump log replay), error-frame decoding, and a
 * px_dev that turns signals into a pose source / force sink.
 *
 * Frames are struct canfd_frame (linux/can.h) in a px_can_msg with an
 * fd flag and a receive time; classic frames use the first 8 data bytes
 * and travel as struct can_frame (CAN_MTU bytes) on sockets, CAN FD as
 * struct canfd_frame (CANFD_MTU), both unchanged, so a simulator speaking
 * SocketCAN's wire layout can sit on the other end of a UNIX socket.
 *
 * Signals (as in DBC files): start_bit is the least significant bit for
 * little-endian (Intel) signals, with bit n = bit n%8 of byte n/8; for
 * big-endian (Motorola) it is the most significant bit in the same
 * numbering, and the signal continues towards less significant bits
 * through bit 0 of a byte into bit 7 of the next. Physical = raw * scale
 * + offset; outputs are clamped to [min, max] when given and to the raw
 * range; inputs outside [min, max] are implausible and rejected.
 *
 * Real-time: px_can_bus_send/recv are non-blocking (MSG_DONTWAIT on
 * sockets) and never allocate; so are the codec functions. Opening,
 * closing, log loading and formatting are setup/non-RT.
 *
 * Times: px_can_msg.t_ns is CLOCK_MONOTONIC for sockets (the kernel's
 * receive timestamp, converted from CLOCK_REALTIME, for raw CAN), and
 * the now_ns given to recv for the simulated buses and replay.
 */
#ifndef PX_CAN_H
#define PX_CAN_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include <linux/can.h>

#include "px_base.h"
#include "px_dev.h"
#include "px_sim.h"

#ifdef __cplusplus
extern "C" {
#endif

struct px_can_msg {
	struct canfd_frame f; /* can_id with CAN_EFF/RTR/ERR flags, len */
	int fd;               /* 1: CAN FD frame */
	int64_t t_ns;
};

/* ---- signal codec ------------------------------------------------------ */

struct px_can_signal {
	const char *name;   /* for messages; must outlive users */
	uint32_t id;        /* 11- or 29-bit id, without flags */
	int extended;       /* 29-bit id */
	int output;         /* 0 input, 1 output */
	uint16_t start_bit; /* DBC numbering, see above */
	uint8_t length;     /* 1..64 */
	uint8_t byte_order; /* PX_LITTLE_ENDIAN (Intel) / PX_BIG_ENDIAN */
	int is_signed;
	double scale, offset;
	int has_min, has_max;
	double min, max;
	/* px_can dev: pose axis (enum px_axis) of an input, wrench channel
	 * (enum px_wrench_axis) of an output; -1 none. */
	int axis;
	/* IEEE 754 payload (DBC SIG_VALTYPE_ 1 and 2): binary32 for length
	 * 32, binary64 for length 64; is_signed does not apply. A NaN or
	 * infinite input is PX_E_NAN. */
	int is_float;
};

/* Check a signal against a frame of frame_len bytes (8 classic, up to
 * 64 FD): bits inside the frame, length, finite non-zero scale, min <=
 * max, a float signal 32 or 64 bits long. Returns PX_OK or PX_E_INVAL.
 * @note RT-safe. */
PX_API int px_can_signal_check(const struct px_can_signal *s,
			       size_t frame_len);

/* Bytes a frame needs to hold the signal. @note RT-safe. */
PX_API size_t px_can_signal_bytes(const struct px_can_signal *s);

/*
 * Raw bits of a signal from data (len bytes), sign-extended when signed.
 * Returns PX_OK, PX_E_PARSE (frame too short), PX_E_INVAL. @note RT-safe.
 */
PX_API int px_can_signal_get_raw(const struct px_can_signal *s,
				 const uint8_t *data, size_t len,
				 int64_t *raw);
/* Store the low length bits of raw, other bits untouched. */
PX_API int px_can_signal_put_raw(const struct px_can_signal *s,
				 uint8_t *data, size_t len, uint64_t raw);

/* Physical value of an input signal. PX_OK, PX_E_PARSE (short frame),
 * PX_E_RANGE (outside [min, max]: implausible), PX_E_NAN (a float
 * signal carrying NaN or infinity), PX_E_INVAL.
 * @note RT-safe. */
PX_API int px_can_signal_decode(const struct px_can_signal *s,
				const uint8_t *data, size_t len, double *value);
/* Encode value (clamped to [min, max] and the raw range; *clamped may be
 * NULL). PX_OK, PX_E_NAN, PX_E_PARSE, PX_E_INVAL. @note RT-safe. */
PX_API int px_can_signal_encode(const struct px_can_signal *s, double value,
				uint8_t *data, size_t len, int *clamped);

/* ---- error frames ------------------------------------------------------ */

enum px_can_state {
	PX_CAN_STATE_ACTIVE = 0,
	PX_CAN_STATE_WARNING,
	PX_CAN_STATE_PASSIVE,
	PX_CAN_STATE_BUS_OFF,
	PX_CAN_STATE_STOPPED,
	PX_CAN_STATE_UNKNOWN
};

struct px_can_err_info {
	int bus_off, restarted;
	int error_warning, error_passive; /* from controller problems */
	int back_to_active;
	int rx_overflow, tx_overflow;
	int lost_arbitration, protocol, transceiver, no_ack, bus_error;
	int tx_timeout;
	uint8_t tx_errors, rx_errors;     /* counters when reported */
	int state;                         /* enum px_can_state implied */
};

/* Decode an error frame (can_id has CAN_ERR_FLAG). Returns PX_OK or
 * PX_E_INVAL (not an error frame). @note RT-safe. */
PX_API int px_can_err_decode(const struct canfd_frame *f,
			     struct px_can_err_info *e);
/* "bus-off", "error passive (controller)", ... joined with ", ". */
PX_API int px_can_err_describe(const struct px_can_err_info *e, char *buf,
			       size_t cap);
PX_API const char *px_can_state_name(int state);

/* ---- buses ------------------------------------------------------------- */

struct px_can_bus;

struct px_can_bus_stats {
	uint64_t tx, rx, tx_dropped, rx_dropped, err_frames;
	int state;            /* enum px_can_state from error frames */
};

/* Send one frame; non-blocking. PX_OK, PX_E_AGAIN (queue full: frame
 * dropped and counted), PX_E_NODEV (interface gone: ENODEV), PX_E_IO
 * (bus-off, socket error; errno in px_can_bus_errno), PX_E_INVAL.
 * @note RT-safe. */
PX_API int px_can_bus_send(struct px_can_bus *b, const struct px_can_msg *m,
			   int64_t now_ns);
/* Receive one frame if there is one; non-blocking. PX_OK, PX_E_AGAIN,
 * PX_E_NODEV (interface gone), PX_E_IO. Error frames are returned too
 * (CAN_ERR_FLAG) after updating the bus state. @note RT-safe. */
PX_API int px_can_bus_recv(struct px_can_bus *b, int64_t now_ns,
			   struct px_can_msg *m);
PX_API void px_can_bus_stats(const struct px_can_bus *b,
			     struct px_can_bus_stats *st);
/* errno of the last failed socket call on this bus (0 none). */
PX_API int px_can_bus_errno(const struct px_can_bus *b);
/* Close and free. NULL is a no-op. */
PX_API void px_can_bus_close(struct px_can_bus *b);

/* In-process simulated bus: every frame sent on one endpoint is received
 * by every other endpoint (not by the sender), in order. All endpoints
 * of one bus are used from one thread at a time. */
struct px_can_sim;
struct px_can_sim_config {
	size_t queue;      /* frames per endpoint queue (default 256) */
	size_t max_endpoints; /* default 8 */
	/* fault windows on the simulation clock (now_ns of the calls),
	 * bus-wide on the sending side; kinds as px_can_fault_open(). */
	const struct px_sim_fault *faults;
	size_t n_faults;
	uint64_t seed;
};
PX_API void px_can_sim_config_default(struct px_can_sim_config *c);
PX_API int px_can_sim_create(const struct px_can_sim_config *c,
			     struct px_can_sim **out);
PX_API int px_can_sim_endpoint(struct px_can_sim *s, struct px_can_bus **out);
/* Free the bus and its endpoints (close endpoints first or not). */
PX_API void px_can_sim_free(struct px_can_sim *s);

/*
 * Fault injection on any bus (simulated buses above all): returns a bus
 * that passes calls through to inner (which it then owns; on failure
 * inner stays the caller's) and applies fault windows [start_ns,
 * start_ns + duration_ns) of now_ns to the frames it receives, each
 * data frame hit with the fault's probability (seeded):
 *   drop       the frame is lost;
 *   delay      frames are held back delay_ns (a gap, then a burst in
 *              order, stamped on arrival; at most 256 held at once);
 *   duplicate  the frame arrives twice;
 *   corrupt    the frame is truncated to half its length (signals past
 *              the end fail to decode);
 *   stuck      each id repeats the first frame it had in the window;
 *   nan        the data bytes become all ones: NaN in IEEE float
 *              payloads, J1939's "not available" in integer signals,
 *              which a signal's min/max rejects as implausible;
 *   unplug     the adapter is gone: send and receive fail with
 *              PX_E_NODEV (errno ENODEV), frames are lost; back when the
 *              window ends;
 *   bus_off    sends fail (PX_E_IO, errno ENETDOWN), nothing is
 *              received but a bus-off error frame on entry and a
 *              restarted one on exit.
 * estop is refused (PX_E_INVAL): on CAN an e-stop is the drives' own
 * fault (px_canopen_sim) or a GPIO line. msg (cap bytes, may be NULL)
 * names the bad fault. Returns PX_OK, PX_E_INVAL, PX_E_NOMEM. Send and
 * receive stay RT-safe (fixed memory).
 */
PX_API int px_can_fault_open(struct px_can_bus *inner,
			     const struct px_sim_fault *faults,
			     size_t n_faults, uint64_t seed,
			     struct px_can_bus **out, char *msg, size_t cap);

/* Simulated bus over a UNIX datagram socket bound at local_path,
 * sending to peer_path. What is at local_path already decides: nothing,
 * or a stale socket (nobody bound to it: a datagram connect is refused),
 * which is removed, then bound; a socket in use by another process is
 * refused (PX_E_BUSY); anything that is not a socket (regular file,
 * directory, symbolic link, device, FIFO) is left untouched and refused
 * (PX_E_INVAL), msg naming the path and what it is. px_can_bus_close()
 * removes the socket file only while it is still the one this call
 * bound (same device and inode), never another process's.
 * Returns PX_OK, PX_E_INVAL (path too long or empty, not a socket),
 * PX_E_BUSY (in use), PX_E_PERM, PX_E_IO, PX_E_NOMEM; msg says why. */
PX_API int px_can_unix_open(const char *local_path, const char *peer_path,
			    struct px_can_bus **out, char *msg, size_t cap);

struct px_can_filter {
	uint32_t id, mask;
	int extended;
};

struct px_can_raw_config {
	const char *interface;   /* "can0", "vcan0" */
	int fd;                  /* enable CAN FD frames */
	const struct px_can_filter *filters; /* none: receive everything */
	size_t n_filters;
	int error_frames;        /* receive error frames (default 1) */
	int loopback_own;        /* receive own frames (default 0) */
};

/*
 * Raw SocketCAN socket, non-blocking, with kernel filters, error frames
 * and kernel receive timestamps. Errors name the call, keep the errno
 * (*sys_errno, may be NULL) and give a hint, e.g. for a kernel without
 * CAN: "socket(PF_CAN, SOCK_RAW, CAN_RAW): errno EAFNOSUPPORT (97):
 * Address family not supported by protocol: this kernel has no AF_CAN
 * support (modprobe can can-raw; for a virtual bus modprobe vcan and ip
 * link add dev vcan0 type vcan)". Returns PX_OK, PX_E_UNSUPPORTED (no
 * AF_CAN / no CAN FD), PX_E_NODEV (no such interface), PX_E_PERM,
 * PX_E_IO, PX_E_INVAL, PX_E_NOMEM.
 */
PX_API int px_can_raw_open(const struct px_can_raw_config *c,
			   struct px_can_bus **out, int *sys_errno,
			   char *msg, size_t cap);

/* Interface state and restart through libsocketcan (netlink; not RT).
 * Return PX_OK or PX_E_NODEV / PX_E_IO / PX_E_UNSUPPORTED (state: also
 * a virtual interface such as vcan, which has no controller). */
PX_API int px_can_iface_state(const char *iface, int *state);
PX_API int px_can_iface_restart(const char *iface);

/*
 * Set a CAN interface's bitrate (and, when restart_ms > 0, its bus-off
 * restart delay) through libsocketcan: down, set, up (up again also
 * after a failed setting). Without restart_ms, an interface already at
 * bitrate is left alone (no privilege needed). Setup only; needs CAP_NET_ADMIN. Returns
 * PX_OK; PX_E_UNSUPPORTED for a virtual interface (vcan has no bitrate;
 * msg says it was not applied: callers go on) or a refused value;
 * PX_E_NODEV (no such interface), PX_E_PERM (msg has the errno and the
 * CAP_NET_ADMIN hint), PX_E_IO, PX_E_INVAL. *sys_errno (may be NULL)
 * gets the errno, msg (cap bytes, may be NULL) the call that failed,
 * e.g. "can0: can_do_stop (ip link set down): errno EPERM (1): Operation
 * not permitted (setting a CAN bitrate needs CAP_NET_ADMIN: ...)".
 */
PX_API int px_can_iface_set_bitrate(const char *iface, uint32_t bitrate,
				    uint32_t restart_ms, int *sys_errno,
				    char *msg, size_t cap);

/* The netlink calls px_can_iface_set_bitrate() makes (libsocketcan's,
 * each returning 0 or -1 with errno), replaceable to simulate a
 * controller or a refusal in tests. exists/is_virtual return 1 or 0. */
struct px_can_netlink_ops {
	int (*exists)(const char *iface);
	int (*is_virtual)(const char *iface);
	int (*do_stop)(const char *iface);
	int (*do_start)(const char *iface);
	int (*set_bitrate)(const char *iface, uint32_t bitrate);
	int (*set_restart_ms)(const char *iface, uint32_t restart_ms);
	/* current bitrate; may be NULL */
	int (*get_bitrate)(const char *iface, uint32_t *bitrate);
};
/* Use ops (NULL: libsocketcan again). Setup only, one thread. */
PX_API void px_can_netlink_set_ops(const struct px_can_netlink_ops *ops);

/* ---- candump -l logs ---------------------------------------------------- */

/* One log line "(sec.usec) iface id#data" (classic), "id##Fdata" (FD,
 * F = flags nibble), "id#R" / "id#Rn" (remote); 3 hex digits for
 * standard ids, 8 for extended and error frames. t_ns is CLOCK_REALTIME
 * in ns. Returns the length (< cap), PX_E_NOSPC. */
PX_API int px_can_log_format(const struct px_can_msg *m, int64_t t_ns,
			     const char *iface, char *buf, size_t cap);
/* Parse one line. Returns PX_OK, PX_E_PARSE. iface (icap bytes) may be
 * NULL. */
PX_API int px_can_log_parse(const char *line, struct px_can_msg *m,
			    int64_t *t_ns, char *iface, size_t icap);

/*
 * Replay a candump -l file as a bus: frames (of interface iface, or all
 * when NULL) are received when now_ns - (first now_ns given to recv) has
 * reached their offset from the first frame; sends are accepted and
 * dropped. Loaded whole at open, at most PX_FILE_LOG_MAX_BYTES (256 MiB,
 * px_file.h: PX_E_RANGE past it); a NUL byte is a parse error at its
 * line and column. On PX_E_PARSE msg says "file:line".
 */
PX_API int px_can_replay_open(const char *path, const char *iface,
			      struct px_can_bus **out, char *msg,
			      size_t cap);

/*
 * Record a bus as candump -l lines: returns a bus that passes every call
 * through to inner (which it then owns) and copies each frame received
 * or sent into a ring of capacity frames (wait-free; when full, frames
 * are dropped and counted). px_can_record_flush() writes what is in the
 * ring to f as candump -l lines for interface iface (times moved from
 * CLOCK_MONOTONIC to CLOCK_REALTIME as candump has them), from a non-RT
 * thread. Returns PX_OK, PX_E_INVAL, PX_E_NOMEM.
 */
PX_API int px_can_record_open(struct px_can_bus *inner, size_t capacity,
			      const char *iface, struct px_can_bus **out);
/* Lines written, or PX_E_INVAL / PX_E_IO. *dropped (may be NULL): frames
 * lost so far because the ring was full. One thread. */
PX_API int px_can_record_flush(struct px_can_bus *rec, FILE *f,
			       uint64_t *dropped);

/* ---- CAN pose source / force sink --------------------------------------- */

/*
 * A px_dev on a bus (ownership of the bus passes to the device): each
 * poll (inside px_dev_pose_read) drains the bus; input signals with an
 * axis feed the pose, error frames and decode failures are recorded
 * (with the frame id and signal name) and bus-off marks the device
 * failed until the bus comes back. px_dev_force_write encodes output
 * signals with a wrench axis and sends one frame per output id.
 * signals must outlive the device. Returns PX_OK, PX_E_INVAL (a bad
 * signal, named in msg), PX_E_NOMEM; on failure the bus stays the
 * caller's.
 */
PX_API int px_can_dev_create(const struct px_dev_config *dcfg,
			     struct px_can_bus *bus, int fd_frames,
			     const struct px_can_signal *signals,
			     size_t n_signals, struct px_dev **out,
			     char *msg, size_t cap);

/* Last decoded value of signal i (input) and its time. Loop thread.
 * PX_OK, PX_E_AGAIN (none yet), PX_E_INVAL. @note RT-safe. */
PX_API int px_can_dev_signal(struct px_dev *d, size_t i, double *value,
			     int64_t *t_ns);

#ifdef __cplusplus
}
#endif

#endif
