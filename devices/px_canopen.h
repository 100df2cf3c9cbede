/*
 * px_canopen.h - CANopen-lite master with CiA 402 drives, and a simulated
 * multi-joint arm that speaks the same subset, on any px_can_bus.
 *
 * The subset ("lite": no SDO, no object dictionary; PDO layouts are
 * fixed by default and configurable with a px_canopen_pdo_map):
 *  - NMT: the master sends "start remote node" (0x000: 01 00) at its
 *    first cycle, and again to a node whose heartbeat says boot-up or
 *    pre-operational (it started after the master);
 *  - SYNC (0x080, no data) each cycle when enabled: drives act on it;
 *  - heartbeat producer (0x700 + own node id: one state byte, 0x05
 *    operational) every heartbeat_period_ns, and a consumer per drive:
 *    no heartbeat for heartbeat_timeout_ns marks the drive lost;
 *  - RPDO1 to each drive (0x200 + node): controlword 0x6040 (u16 LE),
 *    target (i32 LE: position counts for CSP, velocity counts/s for CSV,
 *    torque in 1/1000 of rated for CST), modes of operation 0x6060 (i8);
 *  - TPDO1 from each drive (0x180 + node): statusword 0x6041 (u16),
 *    position actual 0x6064 (i32); TPDO2 (0x280 + node): velocity actual
 *    0x606C (i32), torque actual 0x6077 (i16);
 *  - EMCY (0x080 + node): error code (u16) recorded as the drive's fault.
 * counts_per_unit converts: position rad (or m) = counts / counts_per_unit,
 * velocity likewise per second, torque = thousandths * rated_torque.
 *
 * CiA 402 drive state machine: the master decodes the statusword into a
 * state and writes the controlword that moves each drive towards
 * "operation enabled" while enabled (fault reset as a rising edge of bit
 * 7 in FAULT), and towards standstill when disabled (quick stop from
 * "operation enabled", disable voltage otherwise).
 *
 * Real-time: px_canopen_rx/tx never block or allocate (bus I/O is
 * non-blocking); create/free are setup.
 */
#ifndef PX_CANOPEN_H
#define PX_CANOPEN_H

#include <stddef.h>
#include <stdint.h>

#include "px_base.h"
#include "px_can.h"
#include "px_sim.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- CiA 402 --------------------------------------------------------------- */

enum px_cia402_state {
	PX_CIA402_NOT_READY = 0,
	PX_CIA402_SWITCH_ON_DISABLED,
	PX_CIA402_READY_TO_SWITCH_ON,
	PX_CIA402_SWITCHED_ON,
	PX_CIA402_OPERATION_ENABLED,
	PX_CIA402_QUICK_STOP_ACTIVE,
	PX_CIA402_FAULT_REACTION_ACTIVE,
	PX_CIA402_FAULT,
	PX_CIA402_UNKNOWN
};

enum px_cia402_mode {
	PX_CIA402_CSP = 8, /* cyclic synchronous position (0x6060 value) */
	PX_CIA402_CSV = 9, /* cyclic synchronous velocity */
	PX_CIA402_CST = 10 /* cyclic synchronous torque */
};

/* Controlword commands (CiA 402 table). */
#define PX_CIA402_CW_SHUTDOWN 0x0006u
#define PX_CIA402_CW_SWITCH_ON 0x0007u
#define PX_CIA402_CW_ENABLE_OPERATION 0x000Fu
#define PX_CIA402_CW_DISABLE_VOLTAGE 0x0000u
#define PX_CIA402_CW_QUICK_STOP 0x0002u
#define PX_CIA402_CW_DISABLE_OPERATION 0x0007u
#define PX_CIA402_CW_FAULT_RESET 0x0080u

/* State from a statusword (bits 0-3, 5, 6). @note RT-safe. */
PX_API int px_cia402_state_of(uint16_t statusword);
/* Statusword bits a drive in state reports (voltage enabled bit 4 and
 * remote bit 9 set as a running drive does). @note RT-safe. */
PX_API uint16_t px_cia402_statusword(int state);
/* Drive side: the state after controlword cw in state (prev_cw for the
 * fault-reset edge), before automatic transitions. @note RT-safe. */
PX_API int px_cia402_transition(int state, uint16_t cw, uint16_t prev_cw);
/* Master side: the controlword that moves a drive in state towards
 * operation enabled (enable) or standstill (!enable). prev_cw: the last
 * one sent (fault reset needs an edge). @note RT-safe. */
PX_API uint16_t px_cia402_next_controlword(int state, int enable,
					   uint16_t prev_cw);
PX_API const char *px_cia402_state_name(int state);

/* ---- master ----------------------------------------------------------------- */

#define PX_CANOPEN_MAX_DRIVES 16

struct px_canopen_drive_cfg {
	uint8_t node_id;        /* 1..127 */
	int mode;               /* enum px_cia402_mode */
	int joint;              /* index into the targets/feedback arrays */
	double counts_per_unit; /* > 0 */
	double rated_torque_n_m;/* CST scale: target 1000 = rated */
};

/* ---- PDO mapping ------------------------------------------------------------ */

/*
 * A PDO's content as CANopen maps it: objects (index, subindex, bit
 * length) packed from bit 0 of byte 0 upwards, each little-endian, at
 * most 64 bits in all. Objects the subset knows:
 *   RPDO (master to drive, 0x200 + node): 0x6040 controlword (16),
 *     0x6060 modes of operation (8, signed), and the cyclic target in
 *     one of 0x607A target position (32), 0x60FF target velocity (32),
 *     0x6071 target torque (16): each carries the drive's target in its
 *     mode's units (counts, counts/s, thousandths of rated torque).
 *   TPDO1 / TPDO2 (drive to master, 0x180 / 0x280 + node): 0x6041
 *     statusword (16), 0x6064 position actual (32), 0x606C velocity
 *     actual (32), 0x6077 torque actual (16).
 * The RPDO must carry 0x6040 and a target; the TPDOs together 0x6041 and
 * 0x6064 (TPDO2 may be empty: not sent). Subindex is 0 for all of them.
 * The default (px_canopen_pdo_map_default) is the fixed layout above.
 */
#define PX_CANOPEN_MAX_MAP 8

struct px_canopen_map_entry {
	uint16_t index;
	uint8_t subindex;
	uint8_t bits;
};

struct px_canopen_pdo {
	size_t n;
	struct px_canopen_map_entry e[PX_CANOPEN_MAX_MAP];
};

struct px_canopen_pdo_map {
	struct px_canopen_pdo rpdo;
	struct px_canopen_pdo tpdo1, tpdo2;
};

/* The fixed layout of the header comment. */
PX_API void px_canopen_pdo_map_default(struct px_canopen_pdo_map *m);
/* Check a mapping; msg (cap bytes, may be NULL) names the PDO and entry,
 * e.g. "tpdo1[2]: object 0x6064 is 32 bits, not 16". PX_OK / PX_E_INVAL. */
PX_API int px_canopen_pdo_map_check(const struct px_canopen_pdo_map *m,
				    char *msg, size_t cap);
/* Bytes a PDO's frame carries (ceil of its bits / 8). @note RT-safe. */
PX_API size_t px_canopen_pdo_bytes(const struct px_canopen_pdo *p);
/* Pack / unpack object values (vals[i] for entry i, raw integers, sign
 * extended on unpack for signed objects). Return PX_OK, PX_E_PARSE (frame
 * too short), PX_E_INVAL. @note RT-safe. */
PX_API int px_canopen_pdo_pack(const struct px_canopen_pdo *p,
			       const int64_t *vals, uint8_t *data, size_t len);
PX_API int px_canopen_pdo_unpack(const struct px_canopen_pdo *p,
				 const uint8_t *data, size_t len,
				 int64_t *vals);

struct px_canopen_config {
	/* PDO layouts (copied); NULL = px_canopen_pdo_map_default. */
	const struct px_canopen_pdo_map *pdo;
	uint8_t own_node_id;          /* heartbeat producer id (default 127) */
	int sync;                     /* send SYNC each cycle (default 1) */
	int64_t heartbeat_period_ns;  /* 0 = no heartbeat producer */
	int64_t heartbeat_timeout_ns; /* 0 = no consumer supervision */
	const struct px_canopen_drive_cfg *drives; /* copied */
	size_t n_drives;
};

struct px_canopen;

struct px_canopen_drive_status {
	uint8_t node_id;
	int state;            /* enum px_cia402_state (UNKNOWN before data) */
	uint16_t statusword, controlword;
	double position, velocity, torque_n_m; /* SI via counts_per_unit */
	int64_t feedback_ns;  /* time of the last TPDO1 */
	int64_t heartbeat_ns; /* time of the last heartbeat, 0 none */
	int nmt_state;        /* last heartbeat byte, -1 none */
	int lost;             /* heartbeat timed out */
	uint16_t emcy_code;   /* last EMCY error code, 0 none */
	uint64_t emcy_count;
};

PX_API void px_canopen_config_default(struct px_canopen_config *c);

/* Create a master on bus (the bus stays the caller's). Returns PX_OK,
 * PX_E_INVAL (msg names the drive), PX_E_NOMEM. */
PX_API int px_canopen_create(const struct px_canopen_config *c,
			     struct px_can_bus *bus, struct px_canopen **out,
			     char *msg, size_t cap);
PX_API void px_canopen_free(struct px_canopen *co);

/* Read phase: drain the bus, update drive states, feedback, heartbeats,
 * EMCY. Returns the number of frames handled, or PX_E_IO.
 * @note RT-safe. */
PX_API int px_canopen_rx(struct px_canopen *co, int64_t now_ns);
/* Write phase: controlwords towards enable, RPDOs with targets (indexed
 * by joint, SI units), then SYNC and heartbeat when due. Returns PX_OK,
 * PX_E_NAN (a target not finite: that drive gets quick stop), PX_E_IO.
 * @note RT-safe. */
PX_API int px_canopen_tx(struct px_canopen *co, int64_t now_ns,
			 const double *targets, size_t n_targets, int enable);
/* 1 when every drive is in operation enabled and none is lost.
 * @note RT-safe. */
PX_API int px_canopen_all_enabled(const struct px_canopen *co);
/* First drive lost or in fault (its index), or -1. @note RT-safe. */
PX_API int px_canopen_first_problem(const struct px_canopen *co);
PX_API int px_canopen_drive_status(const struct px_canopen *co, size_t i,
				   struct px_canopen_drive_status *st);

/* ---- safe stop --------------------------------------------------------------- */

/*
 * How px_canopen_safe_stop() waits. Rounds of one command each to every
 * drive (and SYNC) are period_ns apart; between them wait() lets the
 * time pass and returns the new now (on the clock of now_ns): NULL
 * sleeps on CLOCK_MONOTONIC, the clock now_ns must then be on. A
 * virtual clock, or a simulated arm stepped on the same thread, plugs in
 * here (step the arm, advance the clock). The wait is bounded twice:
 * timeout_ns of that clock and max_rounds rounds, whichever comes first.
 */
struct px_canopen_stop_config {
	int64_t timeout_ns;     /* default 500 ms */
	uint32_t max_rounds;    /* default 1000 */
	int64_t period_ns;      /* default 1 ms, > 0 */
	/* A drive found in operation enabled gets quick stop for this long
	 * (it decelerates on its own quick-stop ramp) before disable
	 * voltage; default 20 ms. */
	int64_t quick_stop_ns;
	int64_t (*wait)(void *user, int64_t now_ns, int64_t period_ns);
	void *user;
};

struct px_canopen_stop_result {
	size_t drives;
	size_t disabled;        /* confirmed with the power stage off */
	size_t faulted;         /* of those, in fault (off, not reset) */
	int first_unconfirmed;  /* drive index, -1 when all confirmed */
	uint32_t rounds;
	int64_t elapsed_ns;
};

PX_API void px_canopen_stop_config_default(struct px_canopen_stop_config *c);

/*
 * Take every drive to standstill with its power stage off (CiA 402): a
 * drive in operation enabled gets quick stop (controlword 0x0002) for
 * quick_stop_ns, then disable voltage (0x0000); a drive in any other
 * state disable voltage at once; a drive in fault is left in fault (no
 * reset). CSP drives are sent their last position as target, the
 * others zero. A drive counts as confirmed when a statusword it sent
 * after the first command says switch on disabled, not ready to switch
 * on or fault, and its heartbeat is not lost. cfg NULL: the defaults.
 * res (may be NULL) says how many drives confirmed and the first that
 * did not. Shutdown time, not for the cycle (it waits). Returns PX_OK
 * when every drive confirmed, PX_E_TIMEOUT when the bound passed first,
 * PX_E_IO when frames could not be sent or received and the bound
 * passed, PX_E_INVAL.
 */
PX_API int px_canopen_safe_stop(struct px_canopen *co, int64_t now_ns,
				const struct px_canopen_stop_config *cfg,
				struct px_canopen_stop_result *res);

/* ---- simulated arm (the drives' side) -------------------------------------- */

struct px_canopen_sim;

struct px_canopen_sim_config {
	/* PDO layouts (copied); NULL = the default, as for the master. */
	const struct px_canopen_pdo_map *pdo;
	const struct px_canopen_drive_cfg *drives; /* copied */
	size_t n_drives;
	int64_t heartbeat_period_ns;  /* default 100 ms */
	double inertia_kg_m2;         /* CST dynamics (default 0.01) */
	/* faults: PX_SIM_FAULT_ESTOP = drive fault (FAULT state + EMCY
	 * 0x5441) on drive faults[i].delay_ns (an index, reused here),
	 * PX_SIM_FAULT_UNPLUG = that drive falls silent (no heartbeat, no
	 * PDOs). */
	const struct px_sim_fault *faults;
	size_t n_faults;
};

/* The arm on bus (the bus stays the caller's). */
PX_API int px_canopen_sim_create(const struct px_canopen_sim_config *c,
				 struct px_can_bus *bus,
				 struct px_canopen_sim **out);
PX_API void px_canopen_sim_free(struct px_canopen_sim *s);
/* Handle received frames (NMT, SYNC, RPDO: on SYNC the joints move by
 * the time since the previous SYNC and TPDOs go out) and heartbeats.
 * Returns PX_OK or PX_E_IO. */
PX_API int px_canopen_sim_step(struct px_canopen_sim *s, int64_t now_ns);
/* Joint i's true position and state. */
PX_API int px_canopen_sim_joint(const struct px_canopen_sim *s, size_t i,
				double *position, int *state);

#ifdef __cplusplus
}
#endif

#endif
