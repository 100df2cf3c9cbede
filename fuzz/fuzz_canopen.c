/*
 * libFuzzer target: CANopen-lite (devices/px_canopen.h). A master and
 * the simulated CiA 402 arm share a simulated CAN bus; a third endpoint
 * injects frames taken from the input (NMT, SYNC, PDOs, heartbeats,
 * EMCY, anything) between master and arm cycles, with targets from the
 * input (NaN included), and PDO mappings from the input go through
 * px_canopen_pdo_map_check() and pack/unpack.
 * Invariants: no crash or out-of-bounds access on any frame; drive
 * states stay within the CiA 402 enumeration; reported positions,
 * velocities and torques are finite; a non-finite target gives PX_E_NAN;
 * pack then unpack of a checked mapping returns the values packed
 * (truncated to each object's width and sign).
 */
#include "fuzz_util.h"

#include "px_can.h"
#include "px_canopen.h"

static const uint16_t known[] = {0x6040, 0x6060, 0x607A, 0x60FF, 0x6071,
				 0x6041, 0x6064, 0x606C, 0x6077, 0x1234};

static void read_pdo(struct fz *f, struct px_canopen_pdo *p)
{
	size_t i;
	p->n = fz_u8(f) % (PX_CANOPEN_MAX_MAP + 2);
	for (i = 0; i < p->n && i < PX_CANOPEN_MAX_MAP; i++) {
		unsigned k = fz_u8(f);
		p->e[i].index = known[k % (sizeof known / sizeof known[0])];
		p->e[i].subindex = (uint8_t)(k >> 7);
		p->e[i].bits = (uint8_t)(fz_u8(f) % 70u);
	}
}

static void check_pack(const struct px_canopen_pdo *p, struct fz *f)
{
	int64_t v[PX_CANOPEN_MAX_MAP], w[PX_CANOPEN_MAX_MAP];
	uint8_t d[8];
	size_t i, nb = px_canopen_pdo_bytes(p);
	unsigned pos = 0;
	if (nb > 8)
		abort();
	for (i = 0; i < p->n; i++)
		v[i] = (int64_t)fz_bits(f, 8);
	memset(d, 0, sizeof d);
	if (px_canopen_pdo_pack(p, v, d, nb) != PX_OK)
		abort();
	if (px_canopen_pdo_unpack(p, d, nb, w) != PX_OK)
		abort();
	for (i = 0; i < p->n; i++) {
		unsigned b = p->e[i].bits;
		uint64_t mask = b >= 64 ? ~(uint64_t)0 : (((uint64_t)1 << b) - 1u);
		if (((uint64_t)w[i] & mask) != ((uint64_t)v[i] & mask))
			abort();
		pos += b;
	}
	if (nb && px_canopen_pdo_unpack(p, d, nb - 1, w) != PX_E_PARSE)
		abort();
	(void)pos;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct fz f = {data, size};
	struct px_canopen_pdo_map map;
	struct px_canopen_drive_cfg drv[4];
	struct px_canopen_config cc;
	struct px_canopen_sim_config sc;
	struct px_can_sim_config bc;
	struct px_can_sim *bus = NULL;
	struct px_can_bus *ep_m = NULL, *ep_a = NULL, *ep_x = NULL;
	struct px_canopen *co = NULL;
	struct px_canopen_sim *arm = NULL;
	char msg[256];
	unsigned sel = fz_u8(&f);
	size_t nd = 1 + fz_u8(&f) % 4, i;
	int64_t now = 0;
	int steps = 0, use_map = 0;

	px_canopen_pdo_map_default(&map);
	if (sel & 1) {
		read_pdo(&f, &map.rpdo);
		read_pdo(&f, &map.tpdo1);
		read_pdo(&f, &map.tpdo2);
		if (px_canopen_pdo_map_check(&map, msg, sizeof msg) != PX_OK) {
			fz_check_msg(msg, sizeof msg);
			return 0;
		}
		check_pack(&map.rpdo, &f);
		check_pack(&map.tpdo1, &f);
		check_pack(&map.tpdo2, &f);
		use_map = 1;
	}
	for (i = 0; i < nd; i++) {
		static const int modes[] = {PX_CIA402_CSP, PX_CIA402_CSV,
					    PX_CIA402_CST};
		drv[i].node_id = (uint8_t)(1 + i * 7 + (fz_u8(&f) & 3u));
		drv[i].mode = modes[fz_u8(&f) % 3];
		drv[i].joint = (int)i;
		drv[i].counts_per_unit = 1000.0 * (1 + (fz_u8(&f) & 7u));
		drv[i].rated_torque_n_m = 2.0;
	}
	px_can_sim_config_default(&bc);
	if (px_can_sim_create(&bc, &bus) != PX_OK ||
	    px_can_sim_endpoint(bus, &ep_m) != PX_OK ||
	    px_can_sim_endpoint(bus, &ep_a) != PX_OK ||
	    px_can_sim_endpoint(bus, &ep_x) != PX_OK)
		abort();
	px_canopen_config_default(&cc);
	cc.pdo = use_map ? &map : NULL;
	cc.drives = drv;
	cc.n_drives = nd;
	cc.heartbeat_timeout_ns = (int64_t)(fz_u8(&f) & 3u) * 100000000;
	if (px_canopen_create(&cc, ep_m, &co, msg, sizeof msg) != PX_OK)
		abort();
	memset(&sc, 0, sizeof sc);
	sc.pdo = use_map ? &map : NULL;
	sc.drives = drv;
	sc.n_drives = nd;
	if (px_canopen_sim_create(&sc, ep_a, &arm) != PX_OK)
		abort();

	while (f.n && steps++ < 200) {
		unsigned op = fz_u8(&f);
		if (op < 160) {
			/* inject a frame */
			struct px_can_msg m;
			size_t k;
			memset(&m, 0, sizeof m);
			m.f.can_id = fz_u16(&f) & 0x7ffu;
			if (op & 1)
				m.f.can_id = (m.f.can_id & 0x780u) |
					     drv[fz_u8(&f) % nd].node_id;
			if (op >= 150)
				m.f.can_id |= op & 2 ? CAN_RTR_FLAG : CAN_EFF_FLAG;
			m.f.len = (uint8_t)(fz_u8(&f) % 9u);
			for (k = 0; k < m.f.len; k++)
				m.f.data[k] = (uint8_t)fz_u8(&f);
			px_can_bus_send(ep_x, &m, now);
		} else {
			/* a cycle */
			double tg[4];
			int rc;
			for (i = 0; i < 4; i++)
				tg[i] = op & 1 ? fz_double(&f) : 0.01 * (double)i;
			now += 1000000 * (int64_t)(1 + (op & 0x1e));
			if (px_canopen_rx(co, now) < 0)
				abort();
			rc = px_canopen_tx(co, now, tg, nd, (int)(op >> 6) & 1);
			if (rc != PX_OK) {
				int nonfinite = 0;
				for (i = 0; i < nd; i++)
					if (!isfinite(tg[i]))
						nonfinite = 1;
				if (rc != PX_E_NAN || !nonfinite)
					abort();
			}
			if (px_canopen_sim_step(arm, now) != PX_OK)
				abort();
			for (i = 0; i < nd; i++) {
				struct px_canopen_drive_status st;
				double pos;
				int state;
				if (px_canopen_drive_status(co, i, &st) != PX_OK)
					abort();
				if (st.state < PX_CIA402_NOT_READY ||
				    st.state > PX_CIA402_UNKNOWN ||
				    !px_cia402_state_name(st.state) ||
				    !isfinite(st.position) || !isfinite(st.velocity) ||
				    !isfinite(st.torque_n_m))
					abort();
				if (px_canopen_sim_joint(arm, i, &pos, &state) != PX_OK ||
				    state < PX_CIA402_NOT_READY ||
				    state > PX_CIA402_UNKNOWN)
					abort();
			}
			i = (size_t)px_canopen_first_problem(co);
			if ((int)i >= (int)nd)
				abort();
			(void)px_canopen_all_enabled(co);
		}
	}
	px_canopen_sim_free(arm);
	px_canopen_free(co);
	px_can_sim_free(bus);
	return 0;
}
