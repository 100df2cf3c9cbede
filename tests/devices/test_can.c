/* CAN: signal codec against an independent DBC reference, error frames,
 * candump log lines, simulated buses (in-process with faults, UNIX
 * datagrams between two processes; what a socket path may take over
 * and remove), replay, the raw back end's open
 * path, and the CAN pose/force device. Where AF_CAN and vcan0 exist (the
 * VM suite) the raw back end is exercised on vcan0. */
#include <errno.h>
#include <math.h>
#include <net/if.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <linux/can/error.h>

#include "px_alloc_count.h"
#include "px_can.h"
#include "px_loop.h"
#include "px_test.h"
#include "px_test_dev.h"

/* Reference: Motorola signals as a big-endian bit stream. DBC's start
 * bit s (MSB) is stream position (s/8)*8 + 7 - s%8, and the signal's
 * bits follow in stream order. Intel: linear from the LSB. */
static uint64_t ref_get(const struct px_can_signal *s, const uint8_t *d)
{
	uint64_t v = 0;
	unsigned k;
	if (s->byte_order == PX_LITTLE_ENDIAN) {
		for (k = 0; k < s->length; k++) {
			unsigned p = s->start_bit + k;
			v |= (uint64_t)((d[p / 8] >> (p % 8)) & 1) << k;
		}
	} else {
		unsigned m0 = (s->start_bit / 8) * 8 + 7 - s->start_bit % 8;
		for (k = 0; k < s->length; k++) {
			unsigned q = m0 + k; /* stream position */
			v = (v << 1) | ((d[q / 8] >> (7 - q % 8)) & 1);
		}
	}
	return v;
}

static void random_signal(struct px_can_signal *s, size_t flen)
{
	memset(s, 0, sizeof *s);
	s->name = "sig";
	s->id = (uint32_t)px_rand_int(0, 0x7ff);
	s->length = (uint8_t)px_rand_int(1, 64);
	s->byte_order = (uint8_t)px_rand_int(0, 1);
	s->is_signed = px_rand_int(0, 1);
	s->scale = 1.0;
	s->axis = -1;
	for (;;) {
		s->start_bit = (uint16_t)px_rand_int(0, (int)flen * 8 - 1);
		if (px_can_signal_check(s, flen) == PX_OK)
			return;
	}
}

static void test_signal_bits_match_dbc_reference(void)
{
	int it;
	for (it = 0; it < 20000; it++) {
		struct px_can_signal s;
		uint8_t d[64], r[64];
		size_t flen = px_rand_int(0, 3) ? 8 : 64, i;
		int64_t raw;
		uint64_t want, val;
		random_signal(&s, flen);
		for (i = 0; i < flen; i++)
			d[i] = (uint8_t)px_rand_u64();
		PX_CHECK_INT_EQ(px_can_signal_get_raw(&s, d, flen, &raw), PX_OK);
		want = ref_get(&s, d);
		if (s.is_signed && s.length < 64 && ((want >> (s.length - 1)) & 1))
			want |= ~(((uint64_t)1 << s.length) - 1);
		PX_CHECK_MSG((uint64_t)raw == want, "start %u len %u order %d",
			     s.start_bit, s.length, s.byte_order);
		/* put then reference-get gives the value back; other bits kept */
		val = px_rand_u64();
		memcpy(r, d, flen);
		PX_CHECK_INT_EQ(px_can_signal_put_raw(&s, d, flen, val), PX_OK);
		PX_CHECK(ref_get(&s, d) ==
			 (s.length == 64 ? val
					 : val & (((uint64_t)1 << s.length) - 1)));
		{
			/* clear the signal's bits in both: rest must agree */
			uint8_t a[64], b[64];
			memcpy(a, d, flen);
			memcpy(b, r, flen);
			px_can_signal_put_raw(&s, a, flen, 0);
			px_can_signal_put_raw(&s, b, flen, 0);
			PX_CHECK(memcmp(a, b, flen) == 0);
		}
	}
}

static void test_signal_known_layouts_and_roundtrip(void)
{
	uint8_t d[8] = {0x12, 0x34, 0, 0, 0, 0, 0xAB, 0};
	struct px_can_signal be16 = {"be", 0x100, 0, 0, 7, 16, PX_BIG_ENDIAN, 0,
				     1.0, 0, 0, 0, 0, 0, -1, 0};
	struct px_can_signal le16 = {"le", 0x100, 0, 0, 0, 16, PX_LITTLE_ENDIAN,
				     0, 1.0, 0, 0, 0, 0, 0, -1, 0};
	struct px_can_signal st = {"ft_status", 0x1a0, 0, 0, 55, 8, PX_BIG_ENDIAN,
				   0, 1.0, 0, 0, 0, 0, 0, -1, 0};
	struct px_can_signal ph = {"fz", 0x1a0, 0, 1, 32, 16, PX_LITTLE_ENDIAN, 1,
				   0.02, 0.5, 1, 1, -500, 500, PX_WRENCH_FZ, 0};
	int64_t raw;
	double v;
	int cl, it;
	PX_CHECK_INT_EQ(px_can_signal_get_raw(&be16, d, 8, &raw), PX_OK);
	PX_CHECK_INT_EQ(raw, 0x1234);
	PX_CHECK_INT_EQ(px_can_signal_get_raw(&le16, d, 8, &raw), PX_OK);
	PX_CHECK_INT_EQ(raw, 0x3412);
	PX_CHECK_INT_EQ(px_can_signal_get_raw(&st, d, 8, &raw), PX_OK);
	PX_CHECK_INT_EQ(raw, 0xAB);
	PX_CHECK_INT_EQ((int)px_can_signal_bytes(&st), 7);
	/* physical round trips, clamping to [min, max] */
	for (it = 0; it < 2000; it++) {
		double x = px_rand_range(-499, 499);
		memset(d, 0, 8);
		PX_CHECK_INT_EQ(px_can_signal_encode(&ph, x, d, 8, &cl), PX_OK);
		PX_CHECK_INT_EQ(cl, 0);
		PX_CHECK_INT_EQ(px_can_signal_decode(&ph, d, 8, &v), PX_OK);
		PX_CHECK_NEAR(v, x, 0.01 + 1e-9);
	}
	PX_CHECK_INT_EQ(px_can_signal_encode(&ph, 900, d, 8, &cl), PX_OK);
	PX_CHECK_INT_EQ(cl, 1);
	PX_CHECK_INT_EQ(px_can_signal_decode(&ph, d, 8, &v), PX_OK);
	PX_CHECK_NEAR(v, 500, 1e-9);
	PX_CHECK_INT_EQ(px_can_signal_encode(&ph, NAN, d, 8, &cl), PX_E_NAN);
	/* implausible input: raw 60000 -> 1200.5 N */
	d[4] = 0x60;
	d[5] = 0xEA;
	ph.is_signed = 0;
	PX_CHECK_INT_EQ(px_can_signal_decode(&ph, d, 8, &v), PX_E_RANGE);
	/* short frame */
	PX_CHECK_INT_EQ(px_can_signal_decode(&ph, d, 5, &v), PX_E_PARSE);
	/* checks */
	st.start_bit = 60; /* big-endian running past byte 7 */
	PX_CHECK_INT_EQ(px_can_signal_check(&st, 8), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_can_signal_check(&st, 64), PX_OK);
	le16.id = 0x800;
	PX_CHECK_INT_EQ(px_can_signal_check(&le16, 8), PX_E_INVAL);
	le16.extended = 1;
	PX_CHECK_INT_EQ(px_can_signal_check(&le16, 8), PX_OK);
	le16.scale = 0;
	PX_CHECK_INT_EQ(px_can_signal_check(&le16, 8), PX_E_INVAL);
}

/* Float signals (binary32/binary64) at random places and byte orders
 * round-trip bit-exactly through the reference bit reader; NaN and
 * infinity decode as PX_E_NAN; a bad length is refused. */
static void test_float_signals(void)
{
	int i;
	for (i = 0; i < 2000; i++) {
		struct px_can_signal s;
		uint8_t d[64];
		double v = px_rand_range(-1e6, 1e6), got;
		uint64_t bits;
		random_signal(&s, 64);
		s.length = px_rand_int(0, 1) ? 32 : 64;
		s.is_float = 1;
		s.is_signed = 0;
		while (px_can_signal_check(&s, 64) != PX_OK)
			s.start_bit = (uint16_t)px_rand_int(0, 511);
		memset(d, 0, sizeof d);
		PX_CHECK_INT_EQ(px_can_signal_encode(&s, v, d, 64, NULL), PX_OK);
		bits = ref_get(&s, d);
		if (s.length == 32) {
			float f = (float)v;
			uint32_t b;
			memcpy(&b, &f, sizeof b);
			PX_CHECK_INT_EQ(bits, b);
		} else {
			uint64_t b;
			memcpy(&b, &v, sizeof b);
			PX_CHECK_INT_EQ(bits, b);
		}
		PX_CHECK_INT_EQ(px_can_signal_decode(&s, d, 64, &got), PX_OK);
		PX_CHECK_CLOSE(got, s.length == 32 ? (double)(float)v : v, 0, 0);
		/* all ones: a NaN */
		memset(d, 0xFF, sizeof d);
		PX_CHECK_INT_EQ(px_can_signal_decode(&s, d, 64, &got), PX_E_NAN);
	}
	{
		struct px_can_signal s = {"f", 0x10, 0, 0, 0, 16, PX_LITTLE_ENDIAN,
					  0, 1.0, 0, 0, 0, 0, 0, -1, 1};
		uint8_t d[8] = {0};
		float inf = INFINITY;
		PX_CHECK_INT_EQ(px_can_signal_check(&s, 8), PX_E_INVAL);
		s.length = 32;
		PX_CHECK_INT_EQ(px_can_signal_check(&s, 8), PX_OK);
		memcpy(d, &inf, 4);
		PX_CHECK_INT_EQ(px_can_signal_decode(&s, d, 8, &(double){0}),
				PX_E_NAN);
		/* scale and offset apply to float payloads too */
		s.scale = 0.5;
		s.offset = 1.0;
		PX_CHECK_INT_EQ(px_can_signal_encode(&s, 2.0, d, 8, NULL), PX_OK);
		{
			float f;
			double got;
			memcpy(&f, d, 4);
			PX_CHECK_CLOSE(f, 2.0f, 0, 0);
			PX_CHECK_INT_EQ(px_can_signal_decode(&s, d, 8, &got),
					PX_OK);
			PX_CHECK_CLOSE(got, 2.0, 0, 0);
		}
	}
}

static void test_error_frames_decoded(void)
{
	struct canfd_frame f;
	struct px_can_err_info e;
	char buf[200];
	memset(&f, 0, sizeof f);
	f.can_id = CAN_ERR_FLAG | CAN_ERR_BUSOFF;
	f.len = CAN_ERR_DLC;
	PX_CHECK_INT_EQ(px_can_err_decode(&f, &e), PX_OK);
	PX_CHECK(e.bus_off);
	PX_CHECK_INT_EQ(e.state, PX_CAN_STATE_BUS_OFF);
	px_can_err_describe(&e, buf, sizeof buf);
	PX_CHECK(strcmp(buf, "bus-off") == 0);
	f.can_id = CAN_ERR_FLAG | CAN_ERR_CRTL | CAN_ERR_CNT | CAN_ERR_PROT;
	f.data[1] = CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_WARNING;
	f.data[6] = 130;
	f.data[7] = 7;
	PX_CHECK_INT_EQ(px_can_err_decode(&f, &e), PX_OK);
	PX_CHECK(e.error_passive && e.error_warning && e.protocol);
	PX_CHECK_INT_EQ(e.state, PX_CAN_STATE_PASSIVE);
	PX_CHECK_INT_EQ(e.tx_errors, 130);
	PX_CHECK_INT_EQ(e.rx_errors, 7);
	px_can_err_describe(&e, buf, sizeof buf);
	PX_CHECK_MSG(strcmp(buf, "error passive, error warning, protocol "
				 "violation") == 0, "%s", buf);
	f.can_id = CAN_ERR_FLAG | CAN_ERR_RESTARTED;
	PX_CHECK_INT_EQ(px_can_err_decode(&f, &e), PX_OK);
	PX_CHECK_INT_EQ(e.state, PX_CAN_STATE_ACTIVE);
	f.can_id = 0x123;
	PX_CHECK_INT_EQ(px_can_err_decode(&f, &e), PX_E_INVAL);
	PX_CHECK(strcmp(px_can_state_name(PX_CAN_STATE_PASSIVE),
			"error-passive") == 0);
}

static void test_candump_lines(void)
{
	struct px_can_msg m, back;
	char line[256], ifn[32];
	int64_t t;
	int it;
	PX_CHECK_INT_EQ(px_can_log_parse("(1436509052.249713) vcan0 123#DEADBEEF",
					 &m, &t, ifn, sizeof ifn),
			PX_OK);
	PX_CHECK_INT_EQ(m.f.can_id, 0x123);
	PX_CHECK_INT_EQ(m.f.len, 4);
	PX_CHECK_INT_EQ(m.f.data[0], 0xDE);
	PX_CHECK(t == 1436509052249713000LL);
	PX_CHECK(strcmp(ifn, "vcan0") == 0);
	PX_CHECK_INT_EQ(px_can_log_parse("(0.5) can1 12345678#\n", &m, &t,
					 NULL, 0),
			PX_OK);
	PX_CHECK_INT_EQ(m.f.can_id, 0x12345678u | CAN_EFF_FLAG);
	PX_CHECK_INT_EQ(m.f.len, 0);
	PX_CHECK(t == 500000000);
	PX_CHECK_INT_EQ(px_can_log_parse("(1.000001) can0 321##1001122", &m, &t,
					 NULL, 0),
			PX_OK);
	PX_CHECK(m.fd && m.f.flags == 1 && m.f.len == 3);
	PX_CHECK_INT_EQ(px_can_log_parse("(1.0) can0 7FF#R", &m, &t, NULL, 0),
			PX_OK);
	PX_CHECK(m.f.can_id == (0x7FFu | CAN_RTR_FLAG));
	PX_CHECK_INT_EQ(px_can_log_parse("(1.0) can0 20000040#0000000000000000",
					 &m, &t, NULL, 0),
			PX_OK);
	PX_CHECK(m.f.can_id == (CAN_ERR_FLAG | CAN_ERR_BUSOFF));
	/* bad lines */
	PX_CHECK_INT_EQ(px_can_log_parse("1.0 can0 123#00", &m, &t, NULL, 0),
			PX_E_PARSE);
	PX_CHECK_INT_EQ(px_can_log_parse("(1.0) can0 1234#00", &m, &t, NULL, 0),
			PX_E_PARSE);
	PX_CHECK_INT_EQ(px_can_log_parse("(1.0) can0 123#0", &m, &t, NULL, 0),
			PX_E_PARSE);
	PX_CHECK_INT_EQ(px_can_log_parse("(1.0) can0 123#001122334455667788",
					 &m, &t, NULL, 0),
			PX_E_PARSE);
	PX_CHECK_INT_EQ(px_can_log_parse("(1.0) can0 800#00", &m, &t, NULL, 0),
			PX_E_PARSE);
	PX_CHECK_INT_EQ(px_can_log_parse("(1.0) can0 123##1" "00112233445566778899",
					 &m, &t, NULL, 0),
			PX_E_PARSE); /* 10 bytes is no FD length */
	/* random round trips */
	for (it = 0; it < 5000; it++) {
		static const uint8_t fdl[] = {0, 1, 5, 8, 12, 16, 20, 24, 32, 48, 64};
		int64_t tt = (int64_t)(px_rand_u64() % 4000000000ULL) * 1000000000LL /
				     1000 * 1000 +
			     (int64_t)px_rand_int(0, 999999) * 1000;
		size_t i;
		memset(&m, 0, sizeof m);
		m.fd = px_rand_int(0, 2) == 0;
		if (px_rand_int(0, 1))
			m.f.can_id = (uint32_t)px_rand_int(0, 0x7ff);
		else
			m.f.can_id = ((uint32_t)px_rand_u64() & CAN_EFF_MASK) |
				     CAN_EFF_FLAG;
		if (m.fd) {
			m.f.len = fdl[px_rand_int(0, 10)];
			m.f.flags = (uint8_t)px_rand_int(0, 15);
		} else {
			m.f.len = (uint8_t)px_rand_int(0, 8);
			if (px_rand_int(0, 9) == 0)
				m.f.can_id |= CAN_RTR_FLAG;
		}
		if (!(m.f.can_id & CAN_RTR_FLAG))
			for (i = 0; i < m.f.len; i++)
				m.f.data[i] = (uint8_t)px_rand_u64();
		PX_CHECK(px_can_log_format(&m, tt, "vcan0", line, sizeof line) > 0);
		PX_CHECK_MSG(px_can_log_parse(line, &back, &t, ifn, sizeof ifn) ==
				     PX_OK, "%s", line);
		PX_CHECK_MSG(back.f.can_id == m.f.can_id && back.f.len == m.f.len &&
				     back.fd == m.fd && back.f.flags == m.f.flags &&
				     memcmp(back.f.data, m.f.data, m.f.len) == 0 &&
				     t == tt, "%s", line);
	}
	PX_CHECK_INT_EQ(px_can_log_format(&m, 0, "vcan0", line, 10), PX_E_NOSPC);
}

static struct px_can_msg frame(uint32_t id, int len, uint8_t b0)
{
	struct px_can_msg m;
	memset(&m, 0, sizeof m);
	m.f.can_id = id;
	m.f.len = (uint8_t)len;
	m.f.data[0] = b0;
	return m;
}

static void test_sim_bus_order_faults_and_bus_off(void)
{
	struct px_can_sim_config c;
	struct px_can_sim *s;
	struct px_can_bus *a, *b, *x;
	struct px_can_msg m;
	struct px_can_bus_stats st;
	struct px_sim_fault f[3] = {
		{PX_SIM_FAULT_DROP, 1000, 1000, 1.0, 0},
		{PX_SIM_FAULT_DUPLICATE, 3000, 1000, 1.0, 0},
		{PX_SIM_FAULT_BUSOFF, 5000, 1000, 1.0, 0},
	};
	int i;
	px_can_sim_config_default(&c);
	c.queue = 8;
	c.faults = f;
	c.n_faults = 3;
	PX_CHECK_INT_EQ(px_can_sim_create(&c, &s), PX_OK);
	PX_CHECK_INT_EQ(px_can_sim_endpoint(s, &a), PX_OK);
	PX_CHECK_INT_EQ(px_can_sim_endpoint(s, &b), PX_OK);
	PX_CHECK_INT_EQ(px_can_sim_endpoint(s, &x), PX_OK);
	for (i = 0; i < 5; i++) {
		m = frame(0x100 + (uint32_t)i, 1, (uint8_t)i);
		PX_CHECK_INT_EQ(px_can_bus_send(a, &m, 10), PX_OK);
	}
	PX_CHECK_INT_EQ(px_can_bus_recv(a, 10, &m), PX_E_AGAIN); /* not own */
	for (i = 0; i < 5; i++) {
		PX_CHECK_INT_EQ(px_can_bus_recv(b, 10, &m), PX_OK);
		PX_CHECK_INT_EQ(m.f.can_id, 0x100 + i);
	}
	PX_CHECK_INT_EQ(px_can_bus_recv(b, 10, &m), PX_E_AGAIN);
	/* overflow is counted, the oldest kept */
	for (i = 0; i < 12; i++) {
		m = frame(0x200, 0, 0);
		px_can_bus_send(b, &m, 20);
	}
	px_can_bus_stats(a, &st);
	PX_CHECK_INT_EQ(st.rx_dropped, 4);
	while (px_can_bus_recv(a, 20, &m) == PX_OK)
		;
	while (px_can_bus_recv(x, 20, &m) == PX_OK)
		;
	/* drop window */
	m = frame(0x300, 0, 0);
	PX_CHECK_INT_EQ(px_can_bus_send(a, &m, 1500), PX_OK);
	PX_CHECK_INT_EQ(px_can_bus_recv(b, 1500, &m), PX_E_AGAIN);
	/* duplicate window */
	m = frame(0x301, 0, 0);
	px_can_bus_send(a, &m, 3500);
	PX_CHECK_INT_EQ(px_can_bus_recv(b, 3500, &m), PX_OK);
	PX_CHECK_INT_EQ(px_can_bus_recv(b, 3500, &m), PX_OK);
	PX_CHECK_INT_EQ(m.f.can_id, 0x301);
	PX_CHECK_INT_EQ(px_can_bus_recv(b, 3500, &m), PX_E_AGAIN);
	/* bus-off: sends fail, everyone hears the error frame, then restart */
	m = frame(0x302, 0, 0);
	PX_CHECK_INT_EQ(px_can_bus_send(a, &m, 5500), PX_E_IO);
	PX_CHECK_INT_EQ(px_can_bus_errno(a), ENETDOWN);
	PX_CHECK_INT_EQ(px_can_bus_recv(b, 5500, &m), PX_OK);
	PX_CHECK(m.f.can_id == (CAN_ERR_FLAG | CAN_ERR_BUSOFF));
	px_can_bus_stats(b, &st);
	PX_CHECK_INT_EQ(st.state, PX_CAN_STATE_BUS_OFF);
	PX_CHECK_INT_EQ(px_can_bus_recv(b, 6500, &m), PX_OK);
	PX_CHECK(m.f.can_id == (CAN_ERR_FLAG | CAN_ERR_RESTARTED));
	px_can_bus_stats(b, &st);
	PX_CHECK_INT_EQ(st.state, PX_CAN_STATE_ACTIVE);
	PX_CHECK_INT_EQ(st.err_frames, 2);
	px_can_bus_close(x); /* closing one endpoint early is fine */
	px_can_sim_free(s);
}

static void test_unix_bus_between_processes(void)
{
	char pa[64], pb[64];
	struct px_can_bus *a;
	struct px_can_msg m;
	char msg[200];
	pid_t pid;
	int got = 0, i, st;
	snprintf(pa, sizeof pa, "/tmp/pxcan-a-%d", (int)getpid());
	snprintf(pb, sizeof pb, "/tmp/pxcan-b-%d", (int)getpid());
	PX_CHECK_INT_EQ(px_can_unix_open(pa, pb, &a, msg, sizeof msg), PX_OK);
	pid = fork();
	PX_CHECK(pid >= 0);
	if (pid == 0) {
		/* the "robot": answers each frame with id + 1, same payload,
		 * classic or FD as it came */
		struct px_can_bus *b;
		int n = 0, k;
		if (px_can_unix_open(pb, pa, &b, NULL, 0) != PX_OK)
			_exit(2);
		for (k = 0; k < 4000 && n < 20; k++) {
			struct px_can_msg r;
			if (px_can_bus_recv(b, 0, &r) != PX_OK) {
				px_test_wait_ms(1);
				continue;
			}
			r.f.can_id += 1;
			while (px_can_bus_send(b, &r, 0) == PX_E_AGAIN)
				px_test_wait_ms(1);
			n++;
		}
		px_can_bus_close(b);
		_exit(n == 20 ? 0 : 3);
	}
	for (i = 0; i < 20; i++) {
		int tries;
		m = frame(0x100 + (uint32_t)(2 * i), 8, (uint8_t)i);
		m.fd = i % 2;
		if (m.fd)
			m.f.len = 64;
		m.f.data[m.f.len - 1] = 0x5A;
		/* the child may not be bound yet */
		for (tries = 0; tries < 2000; tries++) {
			if (px_can_bus_send(a, &m, 0) == PX_OK)
				break;
			px_test_wait_ms(1);
		}
		for (tries = 0; tries < 2000; tries++) {
			if (px_can_bus_recv(a, 0, &m) == PX_OK)
				break;
			px_test_wait_ms(1);
		}
		if (m.f.can_id == 0x101u + 2 * (uint32_t)i && m.fd == i % 2 &&
		    m.f.data[0] == i && m.f.data[m.f.len - 1] == 0x5A &&
		    m.f.len == (i % 2 ? 64 : 8))
			got++;
	}
	waitpid(pid, &st, 0);
	PX_CHECK_INT_EQ(got, 20);
	PX_CHECK(WIFEXITED(st) && WEXITSTATUS(st) == 0);
	px_can_bus_close(a);
	/* frames travel unchanged: a plain socket sees CAN_MTU bytes */
	{
		struct px_can_bus *c;
		int raw = socket(AF_UNIX, SOCK_DGRAM, 0);
		struct sockaddr_un ad;
		uint8_t buf[100];
		ssize_t n;
		memset(&ad, 0, sizeof ad);
		ad.sun_family = AF_UNIX;
		snprintf(ad.sun_path, sizeof ad.sun_path, "%s", pb);
		unlink(pb);
		PX_CHECK(bind(raw, (struct sockaddr *)&ad, sizeof ad) == 0);
		PX_CHECK_INT_EQ(px_can_unix_open(pa, pb, &c, msg, sizeof msg),
				PX_OK);
		m = frame(0x7ff, 3, 0xEE);
		PX_CHECK_INT_EQ(px_can_bus_send(c, &m, 0), PX_OK);
		n = recv(raw, buf, sizeof buf, 0);
		PX_CHECK_INT_EQ(n, CAN_MTU);
		PX_CHECK(memcmp(buf, &m.f, CAN_MTU) == 0);
		close(raw);
		unlink(pb);
		px_can_bus_close(c);
	}
}

/* A plain datagram socket bound at path (a stand-in for another
 * process's bus end), -1 on failure. */
static int bind_raw(const char *path)
{
	struct sockaddr_un ad;
	int s = socket(AF_UNIX, SOCK_DGRAM, 0);
	memset(&ad, 0, sizeof ad);
	ad.sun_family = AF_UNIX;
	snprintf(ad.sun_path, sizeof ad.sun_path, "%s", path);
	if (s >= 0 && bind(s, (struct sockaddr *)&ad, sizeof ad) != 0) {
		close(s);
		s = -1;
	}
	return s;
}

static int is_socket(const char *path)
{
	struct stat st;
	return lstat(path, &st) == 0 && S_ISSOCK(st.st_mode);
}

/* The file at path holds exactly text. */
static int holds(const char *path, const char *text)
{
	char buf[256];
	FILE *f = fopen(path, "r");
	size_t n;
	if (!f)
		return 0;
	n = fread(buf, 1, sizeof buf, f);
	fclose(f);
	return n == strlen(text) && memcmp(buf, text, n) == 0;
}

/* A socket path never costs the caller a file it did not mean: what is
 * not a socket is refused and left as it was, a live socket (another
 * bus bound there) is refused and keeps working, a stale one is taken
 * over, and close removes only the socket file its own open bound. */
static void test_unix_path_claims(void)
{
	char dir[64], path[128], file[128], link_[128], peer[128];
	char msg[300];
	struct px_can_bus *a, *b;
	struct px_can_msg m;
	struct stat st;
	int raw;
	FILE *f;
	snprintf(dir, sizeof dir, "/tmp/pxcan-claim-%d", (int)getpid());
	PX_CHECK(mkdir(dir, 0700) == 0);
	snprintf(path, sizeof path, "%s/bus.sock", dir);
	snprintf(peer, sizeof peer, "%s/bus.sock.peer", dir);
	snprintf(file, sizeof file, "%s/victim.txt", dir);
	snprintf(link_, sizeof link_, "%s/link.sock", dir);

	/* a regular file: refused by name and kind, unchanged */
	f = fopen(path, "w");
	PX_CHECK(f != NULL);
	if (f) {
		fputs("precious\n", f);
		fclose(f);
	}
	PX_CHECK_INT_EQ(px_can_unix_open(path, peer, &a, msg, sizeof msg),
			PX_E_INVAL);
	PX_CHECK(a == NULL);
	PX_CHECK_MSG(strstr(msg, path) &&
			     strstr(msg, "exists and is a regular file, not a "
					 "socket: refusing to remove it"),
		     "message: %s", msg);
	PX_CHECK(holds(path, "precious\n"));
	unlink(path);

	/* a directory: refused, still there */
	PX_CHECK(mkdir(path, 0700) == 0);
	PX_CHECK_INT_EQ(px_can_unix_open(path, peer, &a, msg, sizeof msg),
			PX_E_INVAL);
	PX_CHECK_MSG(strstr(msg, "is a directory, not a socket"), "message: %s",
		     msg);
	PX_CHECK(stat(path, &st) == 0 && S_ISDIR(st.st_mode));
	rmdir(path);

	/* a symbolic link to a file: the link and its target survive */
	f = fopen(file, "w");
	if (f) {
		fputs("target\n", f);
		fclose(f);
	}
	PX_CHECK(symlink(file, link_) == 0);
	PX_CHECK_INT_EQ(px_can_unix_open(link_, peer, &a, msg, sizeof msg),
			PX_E_INVAL);
	PX_CHECK_MSG(strstr(msg, "is a symbolic link, not a socket"),
		     "message: %s", msg);
	PX_CHECK(lstat(link_, &st) == 0 && S_ISLNK(st.st_mode));
	PX_CHECK(holds(file, "target\n"));
	unlink(link_);
	unlink(file);

	/* a live socket: refused; its owner still bound and reachable */
	raw = bind_raw(path);
	PX_CHECK(raw >= 0);
	PX_CHECK_INT_EQ(px_can_unix_open(path, peer, &a, msg, sizeof msg),
			PX_E_BUSY);
	PX_CHECK_MSG(strstr(msg, path) && strstr(msg, "in use"), "message: %s",
		     msg);
	PX_CHECK(is_socket(path));
	PX_CHECK_INT_EQ(px_can_unix_open(peer, path, &b, msg, sizeof msg),
			PX_OK);
	m = frame(0x123, 2, 7);
	PX_CHECK_INT_EQ(px_can_bus_send(b, &m, 0), PX_OK);
	{
		uint8_t buf[100];
		PX_CHECK_INT_EQ(recv(raw, buf, sizeof buf, MSG_DONTWAIT), CAN_MTU);
	}
	px_can_bus_close(b);
	PX_CHECK(!is_socket(peer)); /* b removed its own file */

	/* a live socket connected to its own peer (as a running bus end
	 * is): refused the same way */
	{
		char other[96];
		struct sockaddr_un ad;
		int o;
		snprintf(other, sizeof other, "%.60s/other.sock", dir);
		o = bind_raw(other);
		memset(&ad, 0, sizeof ad);
		ad.sun_family = AF_UNIX;
		snprintf(ad.sun_path, sizeof ad.sun_path, "%s", other);
		PX_CHECK(o >= 0 &&
			 connect(raw, (struct sockaddr *)&ad, sizeof ad) == 0);
		PX_CHECK_INT_EQ(px_can_unix_open(path, peer, &a, msg,
						 sizeof msg),
				PX_E_BUSY);
		PX_CHECK_MSG(strstr(msg, "in use"), "message: %s", msg);
		PX_CHECK(is_socket(path));
		close(o);
		unlink(other);
	}

	/* stale (its owner gone, the file left): taken over */
	close(raw);
	PX_CHECK(is_socket(path));
	PX_CHECK_INT_EQ(px_can_unix_open(path, peer, &a, msg, sizeof msg),
			PX_OK);
	/* a second open on the same path is refused; the first's socket
	 * survives the refusal and the second's close */
	PX_CHECK_INT_EQ(px_can_unix_open(path, peer, &b, msg, sizeof msg),
			PX_E_BUSY);
	PX_CHECK(b == NULL);
	px_can_bus_close(b);
	PX_CHECK(is_socket(path));
	px_can_bus_close(a);
	PX_CHECK(!is_socket(path)); /* its own: removed at close */

	/* the path replaced behind a bus's back: close leaves the new one */
	PX_CHECK_INT_EQ(px_can_unix_open(path, peer, &a, msg, sizeof msg),
			PX_OK);
	unlink(path);
	raw = bind_raw(path);
	PX_CHECK(raw >= 0);
	px_can_bus_close(a);
	PX_CHECK(is_socket(path));
	close(raw);
	unlink(path);
	PX_CHECK(rmdir(dir) == 0);
}

static void test_raw_open_path(void)
{
	struct px_can_raw_config c;
	struct px_can_bus *b;
	char msg[400];
	int e, rc;
	memset(&c, 0, sizeof c);
	c.interface = "vcan0";
	c.error_frames = 1;
	rc = px_can_raw_open(&c, &b, &e, msg, sizeof msg);
	if (rc == PX_E_UNSUPPORTED) {
		/* this kernel: the exact errno and a hint */
		PX_CHECK_INT_EQ(e, EAFNOSUPPORT);
		PX_CHECK_MSG(strstr(msg, "vcan0: socket(PF_CAN, SOCK_RAW, CAN_RAW):"
					 " errno EAFNOSUPPORT (97)") &&
				     strstr(msg, "no AF_CAN support") &&
				     strstr(msg, "modprobe can can-raw"),
			     "%s", msg);
		PX_CHECK_INT_EQ(px_can_iface_state("vcan0", &e), PX_E_NODEV);
		return;
	}
	if (rc == PX_E_NODEV) {
		PX_CHECK_INT_EQ(e, ENODEV);
		PX_CHECK_MSG(strstr(msg, "vcan0: no such network interface") != NULL,
			     "%s", msg);
		return;
	}
	PX_CHECK_MSG(rc == PX_OK, "%s", msg);
	px_can_bus_close(b);
}

/* The bitrate path through the real libsocketcan/sysfs: vcan0 (the VM
 * suite) is virtual, so the bitrate is refused with a note and nothing
 * is changed; without vcan0 the interface is named as missing. */
static void test_bitrate_on_vcan_or_absent(void)
{
	PX_NEEDS(SOCKETCAN);
	char msg[400];
	int e = -1, rc;
	rc = px_can_iface_set_bitrate("vcan0", 500000, 0, &e, msg, sizeof msg);
	if (if_nametoindex("vcan0") == 0) {
		PX_CHECK_INT_EQ(rc, PX_E_NODEV);
		PX_CHECK_MSG(strstr(msg, "vcan0: no such network interface") !=
				     NULL,
			     "%s", msg);
		PX_CHECK_INT_EQ(e, ENODEV);
		return;
	}
	PX_CHECK_INT_EQ(rc, PX_E_UNSUPPORTED);
	PX_CHECK_INT_EQ(e, 0);
	PX_CHECK_MSG(strstr(msg, "vcan0: a virtual CAN interface (vcan, vxcan) "
				 "has no bitrate") != NULL,
		     "%s", msg);
}

static void test_raw_on_vcan(void)
{
	/* Runs where vcan0 exists (the VM suite). Two sockets on vcan0: the
	 * second sees the first's frames (classic and FD), filters apply,
	 * timestamps are on CLOCK_MONOTONIC. */
	struct px_can_raw_config c;
	struct px_can_filter flt = {0x120, 0x7f0, 0};
	struct px_can_bus *tx, *rx;
	struct px_can_msg m;
	struct timespec ts;
	char msg[400];
	int e, i, got = 0;
	int64_t now;
	memset(&c, 0, sizeof c);
	c.interface = "vcan0";
	c.fd = 1;
	c.error_frames = 1;
	if (px_can_raw_open(&c, &tx, &e, msg, sizeof msg) != PX_OK)
		PX_SKIP("no usable vcan0 here (%s)", msg);
	/* virtual: no controller, so no state (and nothing on stderr) */
	PX_CHECK_INT_EQ(px_can_iface_state("vcan0", &e), PX_E_UNSUPPORTED);
	c.filters = &flt;
	c.n_filters = 1;
	PX_CHECK_INT_EQ(px_can_raw_open(&c, &rx, &e, msg, sizeof msg), PX_OK);
	for (i = 0; i < 4; i++) {
		m = frame(i < 2 ? 0x123 : 0x321, 8, (uint8_t)i);
		m.fd = i % 2;
		if (m.fd)
			m.f.len = 32;
		PX_CHECK_INT_EQ(px_can_bus_send(tx, &m, 0), PX_OK);
	}
	for (i = 0; i < 200 && got < 2; i++) {
		if (px_can_bus_recv(rx, 0, &m) == PX_OK) {
			clock_gettime(CLOCK_MONOTONIC, &ts);
			now = (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
			PX_CHECK_INT_EQ(m.f.can_id, 0x123);
			PX_CHECK_INT_EQ(m.f.data[0], got);
			PX_CHECK_INT_EQ(m.fd, got);
			PX_CHECK(m.t_ns <= now + 1000000 && m.t_ns > now - 10000000000LL);
			got++;
		} else {
			px_test_wait_ms(5);
		}
	}
	PX_CHECK_INT_EQ(got, 2);
	px_test_wait_ms(20);
	PX_CHECK_INT_EQ(px_can_bus_recv(rx, 0, &m), PX_E_AGAIN); /* filtered */
	px_can_bus_close(tx);
	px_can_bus_close(rx);
}

static void test_error_frames_on_vcan(void)
{
	/* vcan has no controller, but error frames written to it by a raw
	 * socket reach the other sockets whose error mask takes them: the
	 * back end decodes them and follows the bus state. One without
	 * error_frames never sees them. */
	struct px_can_raw_config c;
	struct px_can_bus *rx, *plain;
	struct px_can_bus_stats st;
	struct px_can_msg m;
	struct sockaddr_can a;
	struct can_frame f[2];
	char msg[400];
	int e, i, s, got = 0;
	memset(&c, 0, sizeof c);
	c.interface = "vcan0";
	c.error_frames = 1;
	if (px_can_raw_open(&c, &rx, &e, msg, sizeof msg) != PX_OK)
		PX_SKIP("no usable vcan0 here (%s)", msg);
	c.error_frames = 0;
	PX_CHECK_INT_EQ(px_can_raw_open(&c, &plain, &e, msg, sizeof msg), PX_OK);
	s = socket(PF_CAN, SOCK_RAW, CAN_RAW);
	PX_CHECK(s >= 0);
	memset(&a, 0, sizeof a);
	a.can_family = AF_CAN;
	a.can_ifindex = (int)if_nametoindex("vcan0");
	PX_CHECK(bind(s, (struct sockaddr *)&a, sizeof a) == 0);
	memset(f, 0, sizeof f);
	f[0].can_id = CAN_ERR_FLAG | CAN_ERR_CRTL;
	f[0].len = CAN_ERR_DLC;
	f[0].data[1] = CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE;
	f[1].can_id = CAN_ERR_FLAG | CAN_ERR_BUSOFF;
	f[1].len = CAN_ERR_DLC;
	for (i = 0; i < 2; i++)
		PX_CHECK(write(s, &f[i], sizeof f[i]) == (ssize_t)sizeof f[i]);
	for (i = 0; i < 200 && got < 2; i++) {
		if (px_can_bus_recv(rx, 0, &m) != PX_OK) {
			px_test_wait_ms(5);
			continue;
		}
		PX_CHECK(m.f.can_id & CAN_ERR_FLAG);
		px_can_bus_stats(rx, &st);
		PX_CHECK_INT_EQ(st.state, got == 0 ? PX_CAN_STATE_PASSIVE
						   : PX_CAN_STATE_BUS_OFF);
		got++;
	}
	PX_CHECK_INT_EQ(got, 2);
	px_can_bus_stats(rx, &st);
	PX_CHECK_INT_EQ(st.err_frames, 2);
	PX_CHECK_INT_EQ(px_can_bus_recv(plain, 0, &m), PX_E_AGAIN);
	close(s);
	px_can_bus_close(rx);
	px_can_bus_close(plain);
}

static void test_replay_and_record(void)
{
	char path[] = "/tmp/px_candump_XXXXXX";
	int fd = mkstemp(path);
	FILE *f;
	struct px_can_bus *b;
	struct px_can_msg m;
	char msg[200], line[200];
	int64_t base = 1700000000LL * 1000000000LL;
	int i;
	PX_CHECK(fd >= 0);
	f = fdopen(fd, "w");
	/* record: three frames 10 ms apart, one on another interface */
	for (i = 0; i < 4; i++) {
		m = frame(0x180 + (uint32_t)i, 2, (uint8_t)(0x10 * i));
		px_can_log_format(&m, base + i * 10000000LL,
				  i == 2 ? "can1" : "can0", line, sizeof line);
		fprintf(f, "%s\n", line);
	}
	fclose(f);
	PX_CHECK_INT_EQ(px_can_replay_open(path, "can0", &b, msg, sizeof msg),
			PX_OK);
	PX_CHECK_INT_EQ(px_can_bus_recv(b, 5000, &m), PX_OK); /* t0 */
	PX_CHECK_INT_EQ(m.f.can_id, 0x180);
	PX_CHECK_INT_EQ(m.t_ns, 5000);
	PX_CHECK_INT_EQ(px_can_bus_recv(b, 5000 + 9999999, &m), PX_E_AGAIN);
	PX_CHECK_INT_EQ(px_can_bus_recv(b, 5000 + 10000000, &m), PX_OK);
	PX_CHECK_INT_EQ(m.f.can_id, 0x181);
	PX_CHECK_INT_EQ(m.f.data[0], 0x10);
	PX_CHECK_INT_EQ(px_can_bus_recv(b, 5000 + 30000000, &m), PX_OK);
	PX_CHECK_INT_EQ(m.f.can_id, 0x183); /* can1's frame skipped */
	PX_CHECK_INT_EQ(px_can_bus_recv(b, INT64_MAX / 2, &m), PX_E_AGAIN);
	px_can_bus_close(b);
	f = fopen(path, "a");
	fprintf(f, "garbage\n");
	fclose(f);
	PX_CHECK_INT_EQ(px_can_replay_open(path, NULL, &b, msg, sizeof msg),
			PX_E_PARSE);
	PX_CHECK_MSG(strstr(msg, ":5: not a candump -l line") != NULL, "%s", msg);
	unlink(path);
}

static const struct px_can_signal dev_sigs[] = {
	{"x", 0x100, 0, 0, 0, 16, PX_LITTLE_ENDIAN, 1, 1e-4, 0, 0, 0, 0, 0,
	 PX_AXIS_X, 0},
	{"y", 0x100, 0, 0, 16, 16, PX_LITTLE_ENDIAN, 1, 1e-4, 0, 0, 0, 0, 0,
	 PX_AXIS_Y, 0},
	{"z", 0x100, 0, 0, 39, 16, PX_BIG_ENDIAN, 1, 1e-4, 0, 1, 1, -1, 1,
	 PX_AXIS_Z, 0},
	{"fx", 0x200, 0, 1, 0, 16, PX_LITTLE_ENDIAN, 1, 1e-3, 0, 1, 1, -5, 5,
	 PX_WRENCH_FX, 0},
	{"fz", 0x200, 0, 1, 16, 16, PX_LITTLE_ENDIAN, 1, 1e-3, 0, 1, 1, -5, 5,
	 PX_WRENCH_FZ, 0},
};

/* The last frame on the bus after a CAN force sink stops or is freed is
 * zero force (belt and braces: px_dev_stop / px_dev_free send the safe
 * output of a device written to), and px_dev_safe() sends it too. */
static int last_force_frame(struct px_can_bus *robot, int64_t t, double *fx,
			    double *fz)
{
	struct px_can_msg m;
	int n = 0;
	while (px_can_bus_recv(robot, t, &m) == PX_OK)
		if (m.f.can_id == 0x200) {
			px_can_signal_decode(&dev_sigs[3], m.f.data, m.f.len, fx);
			px_can_signal_decode(&dev_sigs[4], m.f.data, m.f.len, fz);
			n++;
		}
	return n;
}

static void test_can_device_safe_output(void)
{
	struct px_can_sim_config c;
	struct px_can_sim *s;
	struct px_can_bus *robot, *ctl;
	struct px_dev_config dc;
	struct px_dev *d;
	struct px_dev_status st;
	struct px_force_cmd cmd = {{1.25, 0, -2.0}, {0, 0, 0}, 1};
	char msg[300];
	double fx = 0, fz = 0;
	px_can_sim_config_default(&c);
	PX_CHECK_INT_EQ(px_can_sim_create(&c, &s), PX_OK);
	PX_CHECK_INT_EQ(px_can_sim_endpoint(s, &robot), PX_OK);
	PX_CHECK_INT_EQ(px_can_sim_endpoint(s, &ctl), PX_OK);
	px_dev_config_default(&dc);
	dc.name = "arm";
	PX_CHECK_INT_EQ(px_can_dev_create(&dc, ctl, 0, dev_sigs, 5, &d, msg,
					  sizeof msg),
			PX_OK);
	PX_CHECK_INT_EQ(px_dev_start(d), PX_OK);
	PX_CHECK_INT_EQ(px_dev_force_write(d, &cmd, 1000000), PX_OK);
	PX_CHECK_INT_EQ(last_force_frame(robot, 1000000, &fx, &fz), 1);
	PX_CHECK_NEAR(fx, 1.25, 1e-12);
	PX_CHECK_NEAR(fz, -2.0, 1e-12);
	PX_CHECK_INT_EQ(px_dev_safe(d, 2000000), PX_OK);
	PX_CHECK_INT_EQ(last_force_frame(robot, 2000000, &fx, &fz), 1);
	PX_CHECK_NEAR(fx, 0, 0);
	PX_CHECK_NEAR(fz, 0, 0);
	/* written again, then stopped: the stop sends zero */
	PX_CHECK_INT_EQ(px_dev_force_write(d, &cmd, 3000000), PX_OK);
	px_dev_stop(d);
	PX_CHECK_INT_EQ(last_force_frame(robot, 4000000, &fx, &fz), 2);
	PX_CHECK_NEAR(fx, 0, 0);
	PX_CHECK_NEAR(fz, 0, 0);
	px_dev_status(d, &st);
	PX_CHECK_INT_EQ(st.writes, 4);
	PX_CHECK_INT_EQ(st.outputs_safe, 1);
	/* and freed after a write: the last frame is zero as well */
	PX_CHECK_INT_EQ(px_dev_force_write(d, &cmd, 5000000), PX_OK);
	px_dev_free(d); /* closes ctl */
	PX_CHECK_INT_EQ(last_force_frame(robot, 6000000, &fx, &fz), 2);
	PX_CHECK_NEAR(fx, 0, 0);
	PX_CHECK_NEAR(fz, 0, 0);
	px_can_sim_free(s);
}

static void test_can_device_on_sim_bus(void)
{
	struct px_can_sim_config c;
	struct px_can_sim *s;
	struct px_can_bus *robot, *ctl;
	struct px_dev_config dc;
	struct px_dev *d;
	struct px_pose_sample ps;
	struct px_dev_status st;
	struct px_force_cmd cmd = {{1.25, 0, 9.0}, {0, 0, 0}, 1};
	struct px_can_msg m;
	struct px_sim_fault fl[2] = {
		{PX_SIM_FAULT_CORRUPT, 2000000, 1000000, 1.0, 0},
		{PX_SIM_FAULT_BUSOFF, 5000000, 1000000, 1.0, 0},
	};
	char msg[300];
	double v;
	uint64_t r;
	int64_t t;
	px_can_sim_config_default(&c);
	c.faults = fl;
	c.n_faults = 2;
	PX_CHECK_INT_EQ(px_can_sim_create(&c, &s), PX_OK);
	PX_CHECK_INT_EQ(px_can_sim_endpoint(s, &robot), PX_OK);
	PX_CHECK_INT_EQ(px_can_sim_endpoint(s, &ctl), PX_OK);
	px_dev_config_default(&dc);
	dc.name = "arm";
	PX_CHECK_INT_EQ(px_can_dev_create(&dc, ctl, 0, dev_sigs, 5, &d, msg,
					  sizeof msg),
			PX_OK);
	PX_CHECK_INT_EQ(px_dev_start(d), PX_OK);
	r = px_alloc_region_begin();
	for (t = 0; t < 8000000; t += 1000000) {
		double z = 0.01 * (double)(t / 1000000);
		int rc;
		memset(&m, 0, sizeof m);
		m.f.can_id = 0x100;
		m.f.len = 8;
		px_can_signal_encode(&dev_sigs[0], 0.5, m.f.data, 8, NULL);
		px_can_signal_encode(&dev_sigs[1], -0.25, m.f.data, 8, NULL);
		px_can_signal_encode(&dev_sigs[2], z, m.f.data, 8, NULL);
		px_can_bus_send(robot, &m, t);
		rc = px_dev_pose_read(d, t, &ps);
		if (t < 2000000 || (t >= 3000000 && t < 5000000)) {
			PX_CHECK_INT_EQ(rc, 1);
			PX_CHECK_NEAR(ps.pos_m.x, 0.5, 1e-12);
			PX_CHECK_NEAR(ps.pos_m.y, -0.25, 1e-12);
			PX_CHECK_NEAR(ps.pos_m.z, z, 1e-12);
			PX_CHECK_INT_EQ(px_dev_force_write(d, &cmd, t), PX_OK);
			PX_CHECK_INT_EQ(px_can_bus_recv(robot, t, &m), PX_OK);
			PX_CHECK_INT_EQ(m.f.can_id, 0x200);
			PX_CHECK_INT_EQ(m.f.len, 4);
			px_can_signal_decode(&dev_sigs[3], m.f.data, 4, &v);
			PX_CHECK_NEAR(v, 1.25, 1e-12);
			px_can_signal_decode(&dev_sigs[4], m.f.data, 4, &v);
			PX_CHECK_NEAR(v, 5.0, 1e-12); /* clamped at max */
		} else if (t < 3000000) {
			PX_CHECK_INT_EQ(rc, 0); /* corrupted frame: rejected */
		} else if (t < 6000000) {
			PX_CHECK_INT_EQ(rc, PX_E_NODEV); /* bus-off */
		}
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(r), 0);
	px_dev_status(d, &st);
	PX_CHECK_INT_EQ(st.decode_errors, 1);
	PX_CHECK_INT_EQ(st.bus_errors, 2);
	PX_CHECK_INT_EQ(px_dev_state(d), PX_DEV_STATE_RUNNING); /* restarted */
	PX_CHECK_INT_EQ(px_can_dev_signal(d, 0, &v, &t), PX_OK);
	PX_CHECK_NEAR(v, 0.5, 1e-12);
	PX_CHECK_INT_EQ(px_can_dev_signal(d, 3, &v, &t), PX_E_AGAIN);
	/* the bus-off record names the device and the condition */
	PX_CHECK_MSG(strstr(st.last_msg, "arm (socketcan): bus error frame") &&
			     strstr(st.last_msg, "controller restarted"),
		     "%s", st.last_msg);
	px_dev_free(d); /* closes ctl */
	px_can_sim_free(s);
	/* a signal that does not fit is named */
	{
		struct px_can_signal bad = dev_sigs[0];
		struct px_can_bus *e1;
		PX_CHECK_INT_EQ(px_can_sim_create(&c, &s), PX_OK);
		PX_CHECK_INT_EQ(px_can_sim_endpoint(s, &e1), PX_OK);
		bad.start_bit = 60;
		PX_CHECK_INT_EQ(px_can_dev_create(&dc, e1, 0, &bad, 1, &d, msg,
						  sizeof msg),
				PX_E_INVAL);
		PX_CHECK_MSG(strstr(msg, "arm: signals[0] (x, id 0x100)") != NULL,
			     "%s", msg);
		px_can_sim_free(s);
	}
}

struct canapp {
	struct px_can_bus *robot;
	struct px_dev *dev;
	struct px_pose_sample s;
	int nodev;
};

static int can_read(struct px_loop *l, const struct px_loop_cycle *c, void *u)
{
	struct canapp *a = u;
	struct px_can_msg m;
	int rc;
	(void)l;
	memset(&m, 0, sizeof m);
	m.f.can_id = 0x100;
	m.f.len = 8;
	px_can_signal_encode(&dev_sigs[0], 0.1, m.f.data, 8, NULL);
	px_can_bus_send(a->robot, &m, c->read_ns);
	rc = px_dev_pose_read(a->dev, c->read_ns, &a->s);
	if (rc == PX_E_NODEV) {
		a->nodev++;
		return rc;
	}
	return PX_OK;
}

static void test_can_faults_reach_the_watchdog(void)
{
	struct px_sim_fault fl[2] = {
		{PX_SIM_FAULT_DROP, 100000000, 100000000, 1.0, 0},
		{PX_SIM_FAULT_BUSOFF, 400000000, 50000000, 1.0, 0},
	};
	struct px_can_sim_config c;
	struct px_can_sim *s;
	struct px_can_bus *ctl;
	struct px_dev_config dc;
	struct px_loop *l;
	struct px_loop_status ls;
	static struct canapp a;
	char msg[200];
	uint64_t r;
	memset(&a, 0, sizeof a);
	px_can_sim_config_default(&c);
	c.faults = fl;
	c.n_faults = 2;
	PX_CHECK_INT_EQ(px_can_sim_create(&c, &s), PX_OK);
	PX_CHECK_INT_EQ(px_can_sim_endpoint(s, &a.robot), PX_OK);
	PX_CHECK_INT_EQ(px_can_sim_endpoint(s, &ctl), PX_OK);
	px_dev_config_default(&dc);
	dc.name = "arm";
	PX_CHECK_INT_EQ(px_can_dev_create(&dc, ctl, 0, dev_sigs, 3, &a.dev,
					  msg, sizeof msg),
			PX_OK);
	l = px_test_virtual_loop(can_read, NULL, NULL, &a);
	PX_CHECK_INT_EQ(px_dev_attach(a.dev, l), 0);
	PX_CHECK_INT_EQ(px_loop_run(l, 1), PX_OK);
	r = px_alloc_region_begin();
	PX_CHECK_INT_EQ(px_loop_run(l, 149), PX_OK);
	PX_CHECK_INT_EQ(px_alloc_region_end(r), 0);
	/* frames dropped from 100 ms: stale after 20 ms */
	PX_CHECK(px_loop_is_safe(l));
	px_loop_status(l, &ls);
	PX_CHECK_INT_EQ(ls.safe_cause, PX_FAULT_INPUT_STALE);
	PX_CHECK_INT_EQ(px_loop_run(l, 100), PX_OK);
	px_loop_rearm(l);
	PX_CHECK_INT_EQ(px_loop_run(l, 100), PX_OK);
	PX_CHECK(!px_loop_is_safe(l));
	/* bus-off at 400 ms: the read phase sees PX_E_NODEV at once */
	PX_CHECK_INT_EQ(px_loop_run(l, 60), PX_OK);
	PX_CHECK(px_loop_is_safe(l));
	px_loop_status(l, &ls);
	PX_CHECK_INT_EQ(ls.safe_cause, PX_FAULT_CALLBACK);
	PX_CHECK(a.nodev >= 1);
	px_loop_free(l);
	px_dev_free(a.dev);
	px_can_sim_free(s);
}

static void test_record_then_replay(void)
{
	struct px_can_sim_config c;
	struct px_can_sim *s;
	struct px_can_bus *a_raw, *a, *b, *rp;
	struct px_can_msg m;
	char path[] = "/tmp/px_rec_XXXXXX";
	char msg[200];
	int fd = mkstemp(path), i, n;
	FILE *f;
	uint64_t dropped, r;
	PX_CHECK(fd >= 0);
	px_can_sim_config_default(&c);
	PX_CHECK_INT_EQ(px_can_sim_create(&c, &s), PX_OK);
	PX_CHECK_INT_EQ(px_can_sim_endpoint(s, &a_raw), PX_OK);
	PX_CHECK_INT_EQ(px_can_sim_endpoint(s, &b), PX_OK);
	PX_CHECK_INT_EQ(px_can_record_open(a_raw, 8, "vcan0", &a), PX_OK);
	r = px_alloc_region_begin();
	for (i = 0; i < 6; i++) {
		int64_t t = 1000000000LL + i * 2000000LL;
		m = frame(0x300 + (uint32_t)i, 3, (uint8_t)i);
		m.fd = i == 2;
		PX_CHECK_INT_EQ(px_can_bus_send(b, &m, t), PX_OK);
		PX_CHECK_INT_EQ(px_can_bus_recv(a, t, &m), PX_OK);
		m.f.can_id = 0x400 + (uint32_t)i;
		PX_CHECK_INT_EQ(px_can_bus_send(a, &m, t + 1000000), PX_OK);
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(r), 0);
	f = fdopen(fd, "w");
	n = px_can_record_flush(a, f, &dropped);
	fclose(f);
	PX_CHECK_INT_EQ(n, 8);       /* the ring holds 8 */
	PX_CHECK_INT_EQ(dropped, 4); /* 12 recorded, 4 lost and counted */
	PX_CHECK_INT_EQ(px_can_replay_open(path, "vcan0", &rp, msg, sizeof msg),
			PX_OK);
	for (i = 0; i < 8; i++) {
		int k = i / 2;
		/* the first receive sets the replay's time origin */
		PX_CHECK_INT_EQ(px_can_bus_recv(rp, i ? 1000000000000LL : 0, &m),
				PX_OK);
		PX_CHECK_INT_EQ(m.f.can_id, (i % 2 ? 0x400u : 0x300u) + (unsigned)k);
		PX_CHECK_INT_EQ(m.f.data[0], k);
		PX_CHECK_INT_EQ(m.fd, k == 2);
	}
	PX_CHECK_INT_EQ(px_can_bus_recv(rp, INT64_MAX / 4, &m), PX_E_AGAIN);
	px_can_bus_close(rp);
	px_can_bus_close(a); /* closes a_raw too */
	px_can_sim_free(s);
	unlink(path);
}

static const struct px_test tests[] = {
	PX_T(test_float_signals),
	PX_T(test_bitrate_on_vcan_or_absent),
	PX_T(test_record_then_replay),
	PX_T(test_can_faults_reach_the_watchdog),
	PX_T(test_signal_bits_match_dbc_reference),
	PX_T(test_signal_known_layouts_and_roundtrip),
	PX_T(test_error_frames_decoded),
	PX_T(test_candump_lines),
	PX_T(test_sim_bus_order_faults_and_bus_off),
	PX_T(test_unix_bus_between_processes),
	PX_T(test_unix_path_claims),
	PX_T(test_raw_open_path),
	PX_T(test_raw_on_vcan),
	PX_T(test_error_frames_on_vcan),
	PX_T(test_replay_and_record),
	PX_T(test_can_device_on_sim_bus),
	PX_T(test_can_device_safe_output),
};

PX_TEST_MAIN(tests)
