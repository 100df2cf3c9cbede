/* CANopen-lite PDO mapping: checks, pack/unpack round trips against a
 * bit-by-bit reference, and master and simulated arm on a custom layout. */
#include <math.h>
#include <string.h>

#include "px_alloc_count.h"
#include "px_can.h"
#include "px_canopen.h"
#include "px_test.h"

struct obj {
	uint16_t index;
	uint8_t bits;
	int is_signed;
};

static const struct obj rpdo_objs[] = {
	{0x6040, 16, 0}, {0x6060, 8, 1}, {0x607A, 32, 1}};
static const struct obj tpdo_objs[] = {
	{0x6041, 16, 0}, {0x6064, 32, 1}, {0x606C, 32, 1}, {0x6077, 16, 1}};

/* Reference: bit k of the frame is bit (k - start) of entry's value. */
static int64_t ref_get(const uint8_t *d, unsigned start, unsigned bits,
		       int is_signed)
{
	uint64_t v = 0;
	unsigned k;
	for (k = 0; k < bits; k++)
		if (d[(start + k) / 8] >> ((start + k) % 8) & 1)
			v |= (uint64_t)1 << k;
	if (is_signed && bits < 64 && (v >> (bits - 1) & 1))
		v |= ~(uint64_t)0 << bits;
	return (int64_t)v;
}

static int64_t rand_val(unsigned bits, int is_signed)
{
	if (is_signed)
		return px_rand_int(-((int64_t)1 << (bits - 1)),
				   ((int64_t)1 << (bits - 1)) - 1);
	return px_rand_int(0, ((int64_t)1 << bits) - 1);
}

static void shuffle(struct obj *o, size_t n)
{
	size_t i;
	for (i = n; i > 1; i--) {
		size_t j = (size_t)px_rand_int(0, (int64_t)i - 1);
		struct obj t = o[i - 1];
		o[i - 1] = o[j];
		o[j] = t;
	}
}

static void test_pack_roundtrip(void)
{
	int it;
	for (it = 0; it < 500; it++) {
		struct obj o[4];
		struct px_canopen_pdo p;
		int64_t v[PX_CANOPEN_MAX_MAP], w[PX_CANOPEN_MAX_MAP];
		uint8_t d[8];
		size_t i, n;
		unsigned pos = 0;
		int tp = it & 1;
		n = tp ? 4 : 3;
		memcpy(o, tp ? tpdo_objs : rpdo_objs, n * sizeof(o[0]));
		shuffle(o, n);
		/* a random subset that fits 64 bits, at least one entry */
		n = (size_t)px_rand_int(1, (int64_t)n);
		memset(&p, 0, sizeof(p));
		for (i = 0; i < n; i++) {
			if (pos + o[i].bits > 64)
				break;
			p.e[p.n].index = o[i].index;
			p.e[p.n].bits = o[i].bits;
			v[p.n] = rand_val(o[i].bits, o[i].is_signed);
			p.n++;
			pos += o[i].bits;
		}
		PX_CHECK_INT_EQ(px_canopen_pdo_bytes(&p), (pos + 7) / 8);
		memset(d, 0xA5, sizeof d);
		PX_CHECK_INT_EQ(px_canopen_pdo_pack(&p, v, d, sizeof d), PX_OK);
		PX_CHECK_INT_EQ(px_canopen_pdo_unpack(&p, d, sizeof d, w), PX_OK);
		pos = 0;
		for (i = 0; i < p.n; i++) {
			size_t k;
			int sg = 0;
			for (k = 0; k < 4; k++)
				if (tpdo_objs[k].index == p.e[i].index)
					sg = tpdo_objs[k].is_signed;
			for (k = 0; k < 3; k++)
				if (rpdo_objs[k].index == p.e[i].index)
					sg = rpdo_objs[k].is_signed;
			PX_CHECK_INT_EQ(w[i], v[i]);
			PX_CHECK_INT_EQ(ref_get(d, pos, p.e[i].bits, sg), v[i]);
			pos += p.e[i].bits;
		}
		/* a frame one byte short is refused */
		PX_CHECK_INT_EQ(px_canopen_pdo_unpack(&p, d,
						      px_canopen_pdo_bytes(&p) - 1,
						      w),
				PX_E_PARSE);
	}
}

static void test_map_check(void)
{
	struct px_canopen_pdo_map m, b;
	char msg[200];
	px_canopen_pdo_map_default(&m);
	PX_CHECK_INT_EQ(px_canopen_pdo_map_check(&m, msg, sizeof msg), PX_OK);
	PX_CHECK_INT_EQ(px_canopen_pdo_bytes(&m.rpdo), 7);
	PX_CHECK_INT_EQ(px_canopen_pdo_bytes(&m.tpdo1), 6);
	b = m;
	b.tpdo1.e[1].bits = 16;
	PX_CHECK_INT_EQ(px_canopen_pdo_map_check(&b, msg, sizeof msg),
			PX_E_INVAL);
	PX_CHECK_MSG(strstr(msg, "tpdo1[1]") && strstr(msg, "0x6064") &&
			     strstr(msg, "32 bits"),
		     "%s", msg);
	b = m;
	b.rpdo.e[0].index = 0x6041; /* a TPDO object in the RPDO */
	PX_CHECK_INT_EQ(px_canopen_pdo_map_check(&b, msg, sizeof msg),
			PX_E_INVAL);
	PX_CHECK_MSG(strstr(msg, "rpdo[0]"), "%s", msg);
	b = m;
	b.rpdo.e[2].index = 0x60FF; /* second target */
	b.rpdo.e[2].bits = 32;
	PX_CHECK_INT_EQ(px_canopen_pdo_map_check(&b, msg, sizeof msg),
			PX_E_INVAL);
	PX_CHECK_MSG(strstr(msg, "rpdo[2]"), "%s", msg);
	b = m;
	b.tpdo1.e[2] = b.tpdo2.e[0];
	b.tpdo1.e[3] = (struct px_canopen_map_entry){0x6077, 0, 16};
	b.tpdo1.n = 4; /* 16 + 32 + 32 + 16 = 96 bits */
	PX_CHECK_INT_EQ(px_canopen_pdo_map_check(&b, msg, sizeof msg),
			PX_E_INVAL);
	PX_CHECK_MSG(strstr(msg, "64"), "%s", msg);
	b = m;
	b.rpdo.n = 2;
	b.rpdo.e[0] = b.rpdo.e[2]; /* no controlword */
	PX_CHECK_INT_EQ(px_canopen_pdo_map_check(&b, msg, sizeof msg),
			PX_E_INVAL);
	PX_CHECK_MSG(strstr(msg, "0x6040"), "%s", msg);
	b = m;
	b.tpdo1.e[0].subindex = 1;
	PX_CHECK_INT_EQ(px_canopen_pdo_map_check(&b, msg, sizeof msg),
			PX_E_INVAL);
	b = m;
	b.tpdo2.n = 0; /* velocity feedback optional */
	PX_CHECK_INT_EQ(px_canopen_pdo_map_check(&b, msg, sizeof msg), PX_OK);
}

/* A custom layout: RPDO = modes, controlword, target velocity; TPDO1 =
 * position, statusword, velocity (8 + 16 + 32 / 32 + 16 + 16 would not
 * fit: velocity is 32 -> 80 bits; so velocity goes to TPDO2 alone). */
static void custom_map(struct px_canopen_pdo_map *m)
{
	memset(m, 0, sizeof(*m));
	m->rpdo.n = 3;
	m->rpdo.e[0] = (struct px_canopen_map_entry){0x6060, 0, 8};
	m->rpdo.e[1] = (struct px_canopen_map_entry){0x6040, 0, 16};
	m->rpdo.e[2] = (struct px_canopen_map_entry){0x60FF, 0, 32};
	m->tpdo1.n = 2;
	m->tpdo1.e[0] = (struct px_canopen_map_entry){0x6064, 0, 32};
	m->tpdo1.e[1] = (struct px_canopen_map_entry){0x6041, 0, 16};
	m->tpdo2.n = 1;
	m->tpdo2.e[0] = (struct px_canopen_map_entry){0x606C, 0, 32};
}

static int run_arm(const struct px_canopen_pdo_map *master_map,
		   const struct px_canopen_pdo_map *arm_map, double v_target,
		   double *pos_master, double *vel_master, double *pos_arm,
		   uint64_t *allocs)
{
	struct px_can_sim_config sc;
	struct px_can_sim *bus = NULL;
	struct px_can_bus *a = NULL, *b = NULL;
	struct px_canopen_drive_cfg dr = {5, PX_CIA402_CSV, 0, 4096.0, 1.0};
	struct px_canopen_config cc;
	struct px_canopen_sim_config ac;
	struct px_canopen *co = NULL;
	struct px_canopen_sim *arm = NULL;
	struct px_canopen_drive_status st;
	char msg[160];
	int k, enabled;
	uint64_t r = 0;
	px_can_sim_config_default(&sc);
	if (px_can_sim_create(&sc, &bus) || px_can_sim_endpoint(bus, &a) ||
	    px_can_sim_endpoint(bus, &b))
		return -1;
	px_canopen_config_default(&cc);
	cc.pdo = master_map;
	cc.drives = &dr;
	cc.n_drives = 1;
	cc.heartbeat_timeout_ns = 0;
	memset(&ac, 0, sizeof ac);
	ac.pdo = arm_map;
	ac.drives = &dr;
	ac.n_drives = 1;
	if (px_canopen_create(&cc, a, &co, msg, sizeof msg) ||
	    px_canopen_sim_create(&ac, b, &arm))
		return -1;
	for (k = 1; k <= 1000; k++) {
		int64_t t = k * 1000000LL;
		if (k == 100)
			r = px_alloc_region_begin();
		px_canopen_sim_step(arm, t);
		px_canopen_rx(co, t);
		px_canopen_tx(co, t, &v_target, 1, 1);
		if (k == 900)
			*allocs = px_alloc_region_end(r);
	}
	px_canopen_sim_step(arm, 1001000000LL);
	px_canopen_rx(co, 1001000000LL);
	enabled = px_canopen_all_enabled(co);
	px_canopen_drive_status(co, 0, &st);
	*pos_master = st.position;
	*vel_master = st.velocity;
	px_canopen_sim_joint(arm, 0, pos_arm, NULL);
	px_canopen_sim_free(arm);
	px_canopen_free(co);
	px_can_sim_free(bus);
	return enabled;
}

static void test_custom_layout_runs(void)
{
	struct px_canopen_pdo_map m;
	double pm = 0, vm = 0, pa = 0;
	double v = px_rand_range(-2.0, 2.0);
	uint64_t allocs = 99;
	custom_map(&m);
	PX_CHECK_INT_EQ(px_canopen_pdo_map_check(&m, NULL, 0), PX_OK);
	PX_CHECK_INT_EQ(run_arm(&m, &m, v, &pm, &vm, &pa, &allocs), 1);
	PX_CHECK_INT_EQ(allocs, 0);
	/* enabled within a few cycles, then moving at v for most of 1 s */
	PX_CHECK_NEAR(vm, v, 1.0 / 4096.0 + 1e-9);
	PX_CHECK_NEAR(pa, v * 1.0, fabs(v) * 0.02 + 1e-3);
	PX_CHECK_NEAR(pm, pa, 2.0 / 4096.0 + fabs(v) * 2e-3);
	/* the same with the default layout on both sides */
	PX_CHECK_INT_EQ(run_arm(NULL, NULL, v, &pm, &vm, &pa, &allocs), 1);
	PX_CHECK_NEAR(vm, v, 1.0 / 4096.0 + 1e-9);
	/* master and arm disagreeing on the layout: never enabled */
	PX_CHECK_INT_EQ(run_arm(&m, NULL, v, &pm, &vm, &pa, &allocs), 0);
	PX_CHECK_NEAR(pa, 0.0, 1e-12);
}

static void test_bad_map_refused(void)
{
	struct px_canopen_pdo_map m;
	struct px_canopen_config cc;
	struct px_canopen_drive_cfg dr = {5, PX_CIA402_CSV, 0, 4096.0, 1.0};
	struct px_can_sim_config sc;
	struct px_can_sim *bus = NULL;
	struct px_can_bus *a = NULL;
	struct px_canopen *co = NULL;
	char msg[160];
	custom_map(&m);
	m.rpdo.e[2].bits = 16;
	px_can_sim_config_default(&sc);
	PX_CHECK_INT_EQ(px_can_sim_create(&sc, &bus), PX_OK);
	PX_CHECK_INT_EQ(px_can_sim_endpoint(bus, &a), PX_OK);
	px_canopen_config_default(&cc);
	cc.pdo = &m;
	cc.drives = &dr;
	cc.n_drives = 1;
	PX_CHECK_INT_EQ(px_canopen_create(&cc, a, &co, msg, sizeof msg),
			PX_E_INVAL);
	PX_CHECK(co == NULL);
	PX_CHECK_MSG(strstr(msg, "rpdo[2]"), "%s", msg);
	px_can_sim_free(bus);
}

static const struct px_test tests[] = {
	PX_T(test_pack_roundtrip),
	PX_T(test_map_check),
	PX_T(test_custom_layout_runs),
	PX_T(test_bad_map_refused),
};
PX_TEST_MAIN(tests)
