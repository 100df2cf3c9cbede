/*
 * px_devcfg.h - open the devices a configuration describes: the glue from
 * a struct px_config_device (config/px_config.h) to the back ends
 * (simulated haptic/pose and GPIO, hidapi, libusb, SocketCAN signals,
 * CANopen-lite drives, libgpiod).
 *
 * What a config device becomes:
 *  - sim haptic / pose: px_sim_haptic_create() with the sim keys; the
 *    codec from inputs/buttons/outputs when given, else the built-in
 *    "haptic" map; a csv trajectory is loaded (path as written, relative
 *    to the working directory).
 *  - sim gpio and gpiod: a DIO device. Each line gets a role: the line
 *    named by safety.estop is the e-stop input and the one named by
 *    safety.enable the enable output; otherwise a line named "estop"
 *    (input), "enable" or "timing" (outputs) takes that role. Any other
 *    line, a role given twice or a direction that does not fit the role
 *    is an error naming the line.
 *  - hidapi, libusb: px_hid_create() / px_usb_create() with the codec
 *    from the config (it must have inputs).
 *  - socketcan: signals with an axis (see docs/config.md, key "axis")
 *    make a pose source / force sink (px_can_dev_create()); canopen makes
 *    a px_canopen master whose drives take counts_per_unit and
 *    rated_torque_n_m from the config, and whose PDO layouts are the
 *    config's rpdo/tpdo1/tpdo2 entries over the default layout. The two get separate sockets on a
 *    kernel interface, separate endpoints of an in-process simulated bus;
 *    transport unix has one socket (bound at socket_path, sending to
 *    socket_path + ".peer"), so it takes signals or canopen, not both.
 *    A kernel bus with a bitrate gets it (and restart_ms) through
 *    libsocketcan before its sockets open (px_can_iface_set_bitrate():
 *    needs CAP_NET_ADMIN unless the interface already runs at that
 *    bitrate; on a virtual interface it is skipped, see
 *    px_devcfg_notes()). The canopen master's own node id is node_id,
 *    else the highest id no drive uses.
 *  - faults: the sim device's faults go to the simulated device (haptic,
 *    pose, gpio); a simulated bus's (transport sim or unix) wrap each
 *    endpoint the device opens (px_can_fault_open(), seeded by the
 *    device index), so they hit what this device receives.
 *    Faults in the options (a runner's campaign) are added to a
 *    simulated device's own.
 *  - stuck_limit and min_report_interval_ns go to the device config.
 *
 * Errors: every failure leaves a one-line message naming the device, the
 * config key concerned and the back end's reason with its hint, e.g.
 * "device 'haptic' (hidapi, devices[0].hidapi.vid): no HID device
 * 1234:0001 found (...)".
 *
 * Memory: px_devcfg_open() allocates (setup time): the handle holds the
 * codec and signal tables the devices point into, so it must outlive
 * them (px_devcfg_free() frees everything it opened). Nothing here runs
 * in a cycle; the devices it returns follow their own RT rules.
 */
#ifndef PX_DEVCFG_H
#define PX_DEVCFG_H

#include <stddef.h>

#include "px_base.h"
#include "px_can.h"
#include "px_canopen.h"
#include "px_config.h"
#include "px_dev.h"

#ifdef __cplusplus
extern "C" {
#endif

struct px_devcfg;

struct px_devcfg_options {
	/* transport sim: the in-process bus to join (so a simulated arm or
	 * test can sit on it); NULL = the handle creates its own
	 * (px_devcfg_can_sim()). Not owned. */
	struct px_can_sim *can_sim;
	/* Loop clock at the start of the run: fault windows of the config
	 * (start_ns from the start of the run) are moved by it. 0 for a
	 * virtual clock starting at 0. */
	int64_t clock0_ns;
	/* More fault windows for a simulated device (sim haptic, pose or
	 * gpio), e.g. a runner's fault campaign, added after the config's
	 * own: on the loop clock already (not moved by clock0_ns), in the
	 * kinds that device takes (px_sim.h, px_gpio.h: an estop window
	 * presses a simulated e-stop line). Not owned; copied at open.
	 * Given for any other back end: PX_E_INVAL naming "faults". */
	const struct px_sim_fault *faults;
	size_t n_faults;
	/* Check only (a runner's --check): every test px_devcfg_open()
	 * makes of the config, without opening anything outside this
	 * process: no HID or USB device, no CAN socket or interface
	 * setting, no GPIO chip. Simulated back ends are created and freed
	 * again. On success *out is NULL; on failure msg says why as for an
	 * open. */
	int check_only;
};

/*
 * Open config device dc of cfg (dc must be one of cfg->devices; cfg
 * gives the safety line references and the default stale timeout).
 * opt may be NULL. On success *out holds the device(s); on failure *out
 * is NULL and msg (cap bytes, may be NULL) says which device, which key
 * and why. Returns PX_OK, PX_E_INVAL (a value the back end cannot
 * take), PX_E_NOMEM, or the back end's open error (PX_E_NOTFOUND,
 * PX_E_PERM, PX_E_UNSUPPORTED, PX_E_NODEV, PX_E_IO, ...).
 */
PX_API int px_devcfg_open(const struct px_config *cfg,
			  const struct px_config_device *dc,
			  const struct px_devcfg_options *opt,
			  struct px_devcfg **out, char *msg, size_t cap);

/* What was noted while opening without failing it (e.g. a bitrate
 * skipped on a virtual CAN interface), "" when nothing. Owned by h. */
PX_API const char *px_devcfg_notes(const struct px_devcfg *h);

/* How px_devcfg_safe_stop() stops a CANopen master's drives (see
 * px_canopen_safe_stop()). */
struct px_devcfg_safe_config {
	struct px_canopen_stop_config canopen;
};

/* px_devcfg_safe_config_default(): px_canopen_stop_config_default(). */
PX_API void px_devcfg_safe_config_default(struct px_devcfg_safe_config *c);

struct px_devcfg_safe_result {
	unsigned caps;        /* the device's (0 without one) */
	int dev_rc;           /* px_dev_safe()'s result (PX_OK without) */
	int canopen_rc;       /* px_canopen_safe_stop()'s (PX_OK without) */
	struct px_canopen_stop_result canopen;
};

/*
 * Put everything h opened in its safe state, in one call: the device's
 * safe output (px_dev_safe(): zero force/torque with enable off, enable
 * relay and timing line off), then the CANopen master's drives to quick
 * stop and disabled, confirmed by their statuswords within cfg's bound
 * (px_canopen_safe_stop(); its wait hook steps a simulated arm or a
 * virtual clock). now_ns on the loop clock. cfg NULL: defaults. res
 * (may be NULL) holds each part's outcome. Not for the cycle: call it
 * after the loop stops, before px_devcfg_free(). Returns PX_OK when all
 * confirmed, else the first error (PX_E_NODEV, PX_E_IO, PX_E_TIMEOUT,
 * ...); every part is tried whatever an earlier one returned.
 */
PX_API int px_devcfg_safe_stop(struct px_devcfg *h, int64_t now_ns,
			       const struct px_devcfg_safe_config *cfg,
			       struct px_devcfg_safe_result *res);

/* Free the devices, master, buses and tables. NULL is a no-op. A
 * device written to since its last safe output gets one (px_dev_free),
 * and a master whose drives were not confirmed disabled by
 * px_devcfg_safe_stop() sends one round of quick stop / disable voltage
 * (without waiting) before its bus closes. */
PX_API void px_devcfg_free(struct px_devcfg *h);

/* The pose/force/DIO device; NULL for a socketcan device with canopen
 * only. Owned by the handle. */
PX_API struct px_dev *px_devcfg_dev(const struct px_devcfg *h);
/* The CANopen master (NULL without canopen). Owned by the handle. */
PX_API struct px_canopen *px_devcfg_canopen(const struct px_devcfg *h);
/* The bus the master uses (NULL without canopen). Owned by the handle. */
PX_API struct px_can_bus *px_devcfg_canopen_bus(const struct px_devcfg *h);
/* The simulated bus of transport sim (given in the options or created);
 * NULL otherwise. */
PX_API struct px_can_sim *px_devcfg_can_sim(const struct px_devcfg *h);
/* The PDO layout the master uses (config rpdo/tpdo1/tpdo2 over the
 * default), e.g. for a simulated arm; NULL without canopen. */
PX_API const struct px_canopen_pdo_map *
px_devcfg_pdo(const struct px_devcfg *h);
/* Fill drives (cap entries) with the master's drive table as opened
 * (counts_per_unit etc.), e.g. for a simulated arm. Returns the count,
 * PX_E_NOSPC or PX_E_INVAL. */
PX_API int px_devcfg_drives(const struct px_devcfg *h,
			    struct px_canopen_drive_cfg *drives, size_t cap);

/*
 * The faults of a socketcan device's config that belong to the simulated
 * arm (entries with node_id: estop = that drive faults, unplug = it
 * falls silent), as px_canopen_sim faults (drive index in delay_ns),
 * start times moved by clock0_ns. Returns the count (0 none), PX_E_NOSPC
 * (cap too small), PX_E_INVAL.
 */
PX_API int px_devcfg_arm_faults(const struct px_config *cfg,
				const struct px_config_device *dc,
				int64_t clock0_ns, struct px_sim_fault *faults,
				size_t cap);

/*
 * The drive table and PDO layout a canopen device's master would use,
 * without opening anything: for the other side of the bus (a simulated
 * arm in its own process) to speak the same mapping. drives has cap
 * entries. Returns PX_OK, PX_E_NOTFOUND (no canopen drives on dc),
 * PX_E_NOSPC, PX_E_INVAL (a PDO entry the subset does not take; msg
 * names it), PX_E_NOMEM.
 */
PX_API int px_devcfg_canopen_layout(const struct px_config *cfg,
				    const struct px_config_device *dc,
				    struct px_canopen_drive_cfg *drives,
				    size_t cap, size_t *n_drives,
				    struct px_canopen_pdo_map *pdo, char *msg,
				    size_t mcap);

#ifdef __cplusplus
}
#endif

#endif
