/* Digital I/O: debounce against a reference on random chatter, e-stop
 * and enable on simulated lines inside the loop (virtual clock), fault
 * injection, and the libgpiod open path. Where PX_TEST_GPIOCHIP names a
 * gpio-sim chip (the VM suite) the libgpiod back end runs on it. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "px_alloc_count.h"
#include "px_gpio.h"
#include "px_loop.h"
#include "px_test.h"
#include "px_test_dev.h"

/* Reference: runs of equal raw level; the debounced level becomes a run's
 * level when the run lasted at least db (up to the next run or to q). */
static int ref_debounce(const int64_t *t, const int *v, int n, int init,
			int64_t db, int64_t q)
{
	int stable = init, i = 0;
	while (i < n && t[i] <= q) {
		int j = i + 1;
		int64_t end;
		while (j < n && t[j] <= q && v[j] == v[i])
			j++; /* same level again: the run goes on */
		end = j < n && t[j] <= q ? t[j] : q;
		if (end - t[i] >= db)
			stable = v[i];
		i = j;
	}
	return stable;
}

static void test_debounce_matches_reference(void)
{
	int it;
	for (it = 0; it < 3000; it++) {
		int64_t t[40], db = px_rand_int(0, 3) * 1000 + px_rand_int(0, 1);
		int v[40], n = px_rand_int(1, 40), i, init = px_rand_int(0, 1);
		int64_t tt = 0;
		struct px_debounce d;
		int fed = 0;
		int64_t qprev = 0;
		for (i = 0; i < n; i++) {
			tt += px_rand_int(1, 4000);
			t[i] = tt;
			v[i] = px_rand_int(0, 1);
		}
		px_debounce_init(&d, init, db);
		/* query at random times, feeding edges as they pass */
		for (i = 0; i < 60; i++) {
			int64_t q = qprev + px_rand_int(0, (int)(tt / 20) + 500);
			int got, want;
			qprev = q; /* time never goes back */
			while (fed < n && t[fed] <= q) {
				px_debounce_feed(&d, v[fed], t[fed]);
				fed++;
			}
			got = px_debounce_get(&d, q);
			want = ref_debounce(t, v, n, init, db, q);
			PX_CHECK_MSG(got == want, "it %d query %lld: %d != %d", it,
				     (long long)q, got, want);
		}
	}
}

static struct px_gpio_config io_cfg(int active_low)
{
	struct px_gpio_config c;
	memset(&c, 0, sizeof c);
	c.chip = "sim";
	c.line[PX_GPIO_ESTOP].present = 1;
	c.line[PX_GPIO_ESTOP].offset = 17;
	c.line[PX_GPIO_ESTOP].active_low = active_low;
	c.line[PX_GPIO_ESTOP].debounce_ns = 5000000;
	c.line[PX_GPIO_ENABLE].present = 1;
	c.line[PX_GPIO_ENABLE].offset = 27;
	c.line[PX_GPIO_TIMING].present = 1;
	return c;
}

static void test_chatter_gives_one_press(void)
{
	struct px_gpio_config c = io_cfg(1);
	struct px_dev_config dc;
	struct px_dev *d;
	struct px_dev_status st;
	char msg[200];
	int p = -1, presses = 0, last = 0;
	int64_t t;
	px_dev_config_default(&dc);
	dc.name = "io";
	PX_CHECK_INT_EQ(px_gpio_sim_create(&dc, &c, NULL, 0, &d, msg, sizeof msg),
			PX_OK);
	/* active-low: released = 1, pressed = 0; chatter for 3 ms */
	px_gpio_sim_drive(d, PX_GPIO_ESTOP, 0, 10000000);
	px_gpio_sim_drive(d, PX_GPIO_ESTOP, 1, 10500000);
	px_gpio_sim_drive(d, PX_GPIO_ESTOP, 0, 11000000);
	px_gpio_sim_drive(d, PX_GPIO_ESTOP, 1, 12000000);
	px_gpio_sim_drive(d, PX_GPIO_ESTOP, 0, 13000000);
	/* a 2 ms glitch on release is ignored */
	px_gpio_sim_drive(d, PX_GPIO_ESTOP, 1, 40000000);
	px_gpio_sim_drive(d, PX_GPIO_ESTOP, 0, 42000000);
	px_gpio_sim_drive(d, PX_GPIO_ESTOP, 1, 60000000);
	for (t = 0; t < 100000000; t += 250000) {
		PX_CHECK_INT_EQ(px_dev_estop_read(d, t, &p), PX_OK);
		if (p && !last)
			presses++;
		if (t == 17750000)
			PX_CHECK_INT_EQ(p, 0); /* 4.75 ms after the last bounce */
		if (t == 18000000)
			PX_CHECK_INT_EQ(p, 1);
		if (t == 64750000)
			PX_CHECK_INT_EQ(p, 1);
		last = p;
	}
	PX_CHECK_INT_EQ(presses, 1);
	PX_CHECK_INT_EQ(p, 0);
	px_dev_status(d, &st);
	PX_CHECK_INT_EQ(st.last_kind, PX_DEV_ERR_ESTOP);
	PX_CHECK_MSG(strstr(st.last_msg, "io (sim-gpio)") &&
			     strstr(st.last_msg, "e-stop pressed") &&
			     strstr(st.last_msg, "[frame 0x11]"),
		     "%s", st.last_msg);
	/* outputs: logical to physical, timing toggles */
	PX_CHECK_INT_EQ(px_gpio_sim_output(d, PX_GPIO_ENABLE), 0);
	PX_CHECK_INT_EQ(px_dev_dio_write(d, PX_DIO_ENABLE, 1, t), PX_OK);
	PX_CHECK_INT_EQ(px_gpio_sim_output(d, PX_GPIO_ENABLE), 1);
	PX_CHECK_INT_EQ(px_dev_dio_write(d, PX_DIO_TIMING, 1, t), PX_OK);
	PX_CHECK_INT_EQ(px_gpio_sim_output(d, PX_GPIO_TIMING), 1);
	PX_CHECK_INT_EQ(px_dev_dio_write(d, PX_DIO_TIMING, 0, t), PX_OK);
	PX_CHECK_INT_EQ(px_gpio_sim_output(d, PX_GPIO_TIMING), 0);
	PX_CHECK_INT_EQ(px_dev_dio_write(d, 7, 0, t), PX_E_INVAL);
	px_dev_free(d);
}

struct app {
	struct px_dev *io;
	int enable;
	int pressed[1200];
	int out_enable[1200];
	int64_t read_ns[1200];
	int nodev;
	int write_errors;
	int trip_at;             /* cycle index at which the app trips; 0 none */
	struct px_loop *loop;
};

static int a_read(struct px_loop *l, const struct px_loop_cycle *c, void *u)
{
	struct app *a = u;
	int p = 0, rc;
	rc = px_dev_estop_read(a->io, c->read_ns, &p);
	if (c->index < 1200) {
		a->pressed[c->index] = p;
		a->read_ns[c->index] = c->read_ns;
	}
	if (rc == PX_E_NODEV)
		a->nodev++;
	if (a->trip_at && (int)c->index == a->trip_at)
		px_loop_trip(l); /* the application asks for safe state */
	return PX_OK; /* the e-stop trips the loop itself */
}

static int a_compute(struct px_loop *l, const struct px_loop_cycle *c, void *u)
{
	struct app *a = u;
	(void)l;
	(void)c;
	a->enable = 1;
	return PX_OK;
}

static int a_write(struct px_loop *l, const struct px_loop_cycle *c, void *u)
{
	struct app *a = u;
	int rc;
	(void)l;
	rc = px_dev_dio_write(a->io, PX_DIO_ENABLE, a->enable, c->write_ns);
	px_dev_dio_write(a->io, PX_DIO_TIMING, (int)(c->index & 1), c->write_ns);
	if (c->index < 1200)
		a->out_enable[c->index] = px_gpio_sim_output(a->io, PX_GPIO_ENABLE);
	if (rc == PX_E_IO) {
		a->write_errors++;
		return rc; /* the enable did not follow: a loop fault */
	}
	return PX_OK;
}

static void test_estop_trips_loop_and_holds_safe_state(void)
{
	struct px_gpio_config c = io_cfg(1);
	struct px_sim_fault f[2] = {
		{PX_SIM_FAULT_ESTOP, 100000000, 100000000, 1.0, 0},
		{PX_SIM_FAULT_UNPLUG, 600000000, 50000000, 1.0, 0},
	};
	struct px_dev_config dc;
	struct px_loop *l;
	struct px_loop_status ls;
	static struct app a;
	char msg[200];
	uint64_t r;
	int i;
	memset(&a, 0, sizeof a);
	px_dev_config_default(&dc);
	dc.name = "io";
	PX_CHECK_INT_EQ(px_gpio_sim_create(&dc, &c, f, 2, &a.io, msg, sizeof msg),
			PX_OK);
	l = px_test_virtual_loop(a_read, a_compute, a_write, &a);
	PX_CHECK_INT_EQ(px_loop_enable_add(l, "enable", &a.enable), 0);
	PX_CHECK_INT_EQ(px_dev_attach(a.io, l), 0);
	PX_CHECK_INT_EQ(px_loop_run(l, 1), PX_OK);
	r = px_alloc_region_begin();
	PX_CHECK_INT_EQ(px_loop_run(l, 149), PX_OK); /* to 150 ms */
	PX_CHECK_INT_EQ(px_alloc_region_end(r), 0);
	PX_CHECK(px_loop_is_safe(l));
	px_loop_status(l, &ls);
	PX_CHECK_INT_EQ(ls.safe_cause, PX_FAULT_ESTOP);
	/* pressed from the last bounce at 100.4 ms + 5 ms debounce; the
	 * trip applies from the next cycle on */
	{
		int first = -1;
		for (i = 0; i < 150; i++) {
			PX_CHECK_INT_EQ(a.pressed[i], a.read_ns[i] >= 105400000);
			if (a.pressed[i] && first < 0)
				first = i;
		}
		PX_CHECK(first > 0);
		PX_CHECK_INT_EQ(a.out_enable[first], 1);
		PX_CHECK_INT_EQ(a.out_enable[first + 1], 0);
	}
	/* re-arming while held does not stick */
	px_loop_rearm(l);
	PX_CHECK_INT_EQ(px_loop_run(l, 10), PX_OK);
	PX_CHECK(px_loop_is_safe(l));
	for (i = 120; i < 160; i++)
		PX_CHECK_INT_EQ(a.out_enable[i], 0);
	/* released at 200 ms (+5 ms debounce): re-arm works */
	PX_CHECK_INT_EQ(px_loop_run(l, 100), PX_OK);
	px_loop_rearm(l);
	PX_CHECK_INT_EQ(px_loop_run(l, 10), PX_OK);
	PX_CHECK(!px_loop_is_safe(l));
	PX_CHECK_INT_EQ(a.out_enable[265], 1);
	/* unplugged at 600 ms: fail-safe pressed, trip */
	PX_CHECK_INT_EQ(px_loop_run(l, 340), PX_OK);
	PX_CHECK(px_loop_is_safe(l));
	PX_CHECK(a.nodev >= 1);
	PX_CHECK_INT_EQ(a.pressed[601], 1);
	px_loop_free(l);
	px_dev_free(a.io);
}

/* One fault window at 50-250 ms; the e-stop is pressed at 100 ms and
 * released at 150 ms (active-low, 5 ms debounce). */
struct gfault_run {
	int64_t first_pressed, first_released; /* read times, -1 none */
	int safe_during, safe_at_end;
	struct px_loop_status during;
	struct px_dev_status ds;
	int write_errors;
	int enable_at_130;
};

static void run_gpio_fault(int kind, int64_t delay_ns, int trip_at,
			   struct gfault_run *out)
{
	struct px_gpio_config c = io_cfg(1);
	struct px_sim_fault f = {kind, 50000000, 200000000, 1.0, delay_ns};
	struct px_dev_config dc;
	struct px_loop *l;
	static struct app a;
	char msg[300];
	uint64_t r;
	int i;
	memset(&a, 0, sizeof a);
	memset(out, 0, sizeof *out);
	px_dev_config_default(&dc);
	dc.name = "io";
	PX_CHECK_MSG(px_gpio_sim_create(&dc, &c, &f, 1, &a.io, msg, sizeof msg) ==
			     PX_OK,
		     "%s", msg);
	if (!a.io)
		return;
	px_gpio_sim_drive(a.io, PX_GPIO_ESTOP, 0, 100000000);
	px_gpio_sim_drive(a.io, PX_GPIO_ESTOP, 1, 150000000);
	a.trip_at = trip_at;
	l = px_test_virtual_loop(a_read, a_compute, a_write, &a);
	PX_CHECK_INT_EQ(px_loop_enable_add(l, "enable", &a.enable), 0);
	PX_CHECK_INT_EQ(px_dev_attach(a.io, l), 0);
	r = px_alloc_region_begin();
	PX_CHECK_INT_EQ(px_loop_run(l, 200), PX_OK); /* to 200 ms */
	PX_CHECK_INT_EQ(px_alloc_region_end(r), 0);
	out->safe_during = px_loop_is_safe(l);
	px_loop_status(l, &out->during);
	PX_CHECK_INT_EQ(px_loop_run(l, 100), PX_OK); /* window over */
	for (i = 0; i < 3; i++) {
		px_loop_rearm(l);
		px_loop_run(l, 20);
	}
	out->safe_at_end = px_loop_is_safe(l);
	out->first_pressed = out->first_released = -1;
	for (i = 0; i < 300; i++) {
		if (a.pressed[i] && out->first_pressed < 0)
			out->first_pressed = a.read_ns[i];
		if (out->first_pressed >= 0 && !a.pressed[i] &&
		    out->first_released < 0)
			out->first_released = a.read_ns[i];
	}
	out->write_errors = a.write_errors;
	out->enable_at_130 = a.out_enable[130];
	px_dev_status(a.io, &out->ds);
	px_loop_free(l);
	px_dev_free(a.io);
}

/* Lost, late and wrong edge events: the level check corrects them in the
 * same read, so the press is seen as without the fault (100 ms + 5 ms
 * debounce) and trips the loop; the correction is recorded. */
static void test_gpio_fault_lost_late_wrong_events(void)
{
	static const int kinds[] = {PX_SIM_FAULT_DROP, PX_SIM_FAULT_DELAY,
				    PX_SIM_FAULT_CORRUPT};
	struct gfault_run fr;
	size_t k;
	for (k = 0; k < 3; k++) {
		const char *nm = px_sim_fault_name(kinds[k]);
		run_gpio_fault(kinds[k], 20000000, 0, &fr);
		PX_CHECK_MSG(fr.first_pressed == 105000000, "%s: pressed at %lld",
			     nm, (long long)fr.first_pressed);
		PX_CHECK_MSG(fr.first_released == 155000000,
			     "%s: released at %lld", nm,
			     (long long)fr.first_released);
		PX_CHECK_MSG(fr.during.safe_entries >= 1 &&
				     fr.during.safe_cause == PX_FAULT_ESTOP,
			     "%s: cause %d", nm, (int)fr.during.safe_cause);
		PX_CHECK_MSG(!fr.safe_at_end, "%s: safe after re-arm", nm);
		PX_CHECK_MSG(strstr(fr.ds.last_msg, "io (sim-gpio): ") &&
				     strstr(fr.ds.last_msg,
					    "differs from its edge events"),
			     "%s: %s", nm, fr.ds.last_msg);
		PX_CHECK_MSG(fr.ds.io_errors == 2, "%s: %llu", nm,
			     (unsigned long long)fr.ds.io_errors);
	}
	/* events that arrive as they happened need no correction (an unplug
	 * window reads fail-safe pressed, and corrects nothing either) */
	run_gpio_fault(PX_SIM_FAULT_UNPLUG, 0, 0, &fr);
	PX_CHECK_INT_EQ(fr.ds.io_errors, 0);
	PX_CHECK_INT_EQ(fr.ds.unplugs, 1);
}

static void test_gpio_fault_duplicate_events(void)
{
	struct gfault_run fr;
	run_gpio_fault(PX_SIM_FAULT_DUPLICATE, 0, 0, &fr);
	PX_CHECK_INT_EQ(fr.first_pressed, 105000000);
	PX_CHECK_INT_EQ(fr.first_released, 155000000);
	PX_CHECK_INT_EQ(fr.ds.duplicates, 2);
	PX_CHECK_INT_EQ(fr.ds.io_errors, 0);
	PX_CHECK_MSG(strstr(fr.ds.last_msg, "e-stop edge event repeated") ||
			     fr.ds.last_kind == PX_DEV_ERR_ESTOP,
		     "%s", fr.ds.last_msg);
	PX_CHECK(fr.safe_during || fr.during.safe_entries >= 1);
	PX_CHECK(!fr.safe_at_end);
}

/* A welded contact: the e-stop line holds (one channel cannot see it:
 * the press at 100 ms is missed), and the enable relay holds too: when
 * the application trips at 120 ms the enable output does not drop, the
 * readback shows it, and the write phase fails every cycle. */
static void test_gpio_fault_stuck(void)
{
	struct gfault_run fr;
	run_gpio_fault(PX_SIM_FAULT_STUCK, 0, 120, &fr);
	PX_CHECK_INT_EQ(fr.first_pressed, -1);
	PX_CHECK_INT_EQ(fr.enable_at_130, 1); /* welded at 1 */
	PX_CHECK_MSG(fr.write_errors >= 120 && fr.write_errors <= 131, "%d",
		     fr.write_errors);
	PX_CHECK(fr.safe_during);
	PX_CHECK(fr.during.faults >= 2);
	PX_CHECK_MSG(strstr(fr.ds.last_msg, "enable output stuck: readback "
					   "differs from the command") != NULL,
		     "%s", fr.ds.last_msg);
	PX_CHECK(!fr.safe_at_end);
}

static void test_gpio_fault_kinds_refused(void)
{
	struct px_gpio_config c = io_cfg(1);
	struct px_sim_fault f = {PX_SIM_FAULT_NAN, 0, 1000, 1.0, 0};
	struct px_dev_config dc;
	struct px_dev *d = NULL;
	char msg[300];
	px_dev_config_default(&dc);
	dc.name = "io";
	PX_CHECK_INT_EQ(px_gpio_sim_create(&dc, &c, &f, 1, &d, msg, sizeof msg),
			PX_E_INVAL);
	PX_CHECK_MSG(strstr(msg, "io: faults[0] (nan)") &&
			     strstr(msg, "do not apply to digital lines"),
		     "%s", msg);
	f.kind = PX_SIM_FAULT_BUSOFF;
	PX_CHECK_INT_EQ(px_gpio_sim_create(&dc, &c, &f, 1, &d, msg, sizeof msg),
			PX_E_INVAL);
	f.kind = PX_SIM_FAULT_DELAY;
	PX_CHECK_INT_EQ(px_gpio_sim_create(&dc, &c, &f, 1, &d, msg, sizeof msg),
			PX_E_INVAL);
	f.delay_ns = 1000;
	PX_CHECK_INT_EQ(px_gpio_sim_create(&dc, &c, &f, 1, &d, msg, sizeof msg),
			PX_OK);
	px_dev_free(d);
}

static void test_gpiod_open_path(void)
{
	PX_NEEDS(GPIOD);
	struct px_gpio_config c = io_cfg(1);
	struct px_dev_config dc;
	struct px_dev *d;
	char msg[400];
	int e, rc;
	px_dev_config_default(&dc);
	dc.name = "io";
	c.chip = "gpiochip-proxima-absent";
	rc = px_gpiod_create(&dc, &c, &d, &e, msg, sizeof msg);
	PX_CHECK_INT_EQ(rc, PX_E_NOTFOUND);
	PX_CHECK_INT_EQ(e, ENOENT);
	PX_CHECK_MSG(strstr(msg, "io: gpiod_chip_open_lookup(\"gpiochip-proxima-"
				 "absent\"): errno ENOENT (2)") != NULL,
		     "%s", msg);
	if (access("/dev/gpiochip0", F_OK) != 0)
		PX_CHECK_MSG(strstr(msg, "no /dev/gpiochip*") != NULL, "%s", msg);
	PX_CHECK(px_gpiod_version() != NULL && px_gpiod_version()[0] == '1');
	c.chip = NULL;
	PX_CHECK_INT_EQ(px_gpiod_create(&dc, &c, &d, &e, msg, sizeof msg),
			PX_E_INVAL);
}

static int sysfs_read(const char *dir, const char *file)
{
	char p[512], b[16] = "";
	FILE *f;
	snprintf(p, sizeof p, "%s/%s", dir, file);
	f = fopen(p, "r");
	if (!f)
		return -1;
	if (!fgets(b, sizeof b, f))
		b[0] = 0;
	fclose(f);
	return atoi(b);
}

static int64_t mono(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

static void test_gpiod_on_gpio_sim(void)
{
	/* PX_TEST_GPIOCHIP: the gpio-sim chip; PX_TEST_GPIOSIM_DIR: its
	 * sysfs directory with sim_gpio0 (e-stop, driven through "pull")
	 * and sim_gpio1 (enable, read from "value"). */
	const char *chip = getenv("PX_TEST_GPIOCHIP");
	const char *dir = getenv("PX_TEST_GPIOSIM_DIR");
	struct px_gpio_config c = io_cfg(0);
	struct px_dev_config dc;
	struct px_dev *d;
	char msg[400];
	int e, p = 0, i;
	if (!chip || !dir)
		PX_SKIP("PX_TEST_GPIOCHIP/PX_TEST_GPIOSIM_DIR not set: the VM "
			"suite runs this on gpio-sim");
	c.chip = chip;
	c.line[PX_GPIO_ESTOP].offset = 0;
	c.line[PX_GPIO_ESTOP].debounce_ns = 1000000;
	c.line[PX_GPIO_ENABLE].offset = 1;
	c.line[PX_GPIO_TIMING].present = 0;
	PX_CHECK_INT_EQ(
		px_test_write_file(dir, "sim_gpio0/pull", "pull-down"), 0);
	px_dev_config_default(&dc);
	dc.name = "io";
	PX_CHECK_MSG(px_gpiod_create(&dc, &c, &d, &e, msg, sizeof msg) == PX_OK,
		     "%s", msg);
	PX_CHECK_INT_EQ(px_dev_estop_read(d, mono(), &p), PX_OK);
	PX_CHECK_INT_EQ(p, 0);
	PX_CHECK_INT_EQ(px_dev_dio_write(d, PX_DIO_ENABLE, 1, mono()), PX_OK);
	PX_CHECK_INT_EQ(sysfs_read(dir, "sim_gpio1/value"), 1);
	PX_CHECK_INT_EQ(
		px_test_write_file(dir, "sim_gpio0/pull", "pull-up"), 0);
	for (i = 0; i < 500 && !p; i++) {
		struct timespec ts = {0, 2000000};
		nanosleep(&ts, NULL);
		px_dev_estop_read(d, mono(), &p);
	}
	PX_CHECK_INT_EQ(p, 1);
	PX_CHECK_INT_EQ(px_dev_dio_write(d, PX_DIO_ENABLE, 0, mono()), PX_OK);
	PX_CHECK_INT_EQ(sysfs_read(dir, "sim_gpio1/value"), 0);
	/* the safe output: on again, then px_dev_safe drops it, read
	 * back by the back end and seen on the simulated chip */
	PX_CHECK_INT_EQ(px_dev_dio_write(d, PX_DIO_ENABLE, 1, mono()), PX_OK);
	PX_CHECK_INT_EQ(sysfs_read(dir, "sim_gpio1/value"), 1);
	PX_CHECK_INT_EQ(px_dev_safe(d, mono()), PX_OK);
	PX_CHECK_INT_EQ(sysfs_read(dir, "sim_gpio1/value"), 0);
	{
		struct px_dev_status st;
		px_dev_status(d, &st);
		PX_CHECK_INT_EQ(st.outputs_safe, 1);
	}
	px_dev_free(d);
}

static void test_gpiod_by_name_on_gpio_sim(void)
{
	/* Lines found by their kernel names and the chip by its label (the
	 * VM suite names gpio-sim lines 0 and 1 "estop" and "enable" and
	 * labels the chip PX_TEST_GPIO_LABEL). Press, release and press
	 * again through "pull": each edge reaches the e-stop. */
	const char *label = getenv("PX_TEST_GPIO_LABEL");
	const char *dir = getenv("PX_TEST_GPIOSIM_DIR");
	struct px_gpio_config c = io_cfg(0);
	struct px_dev_config dc;
	struct px_dev *d;
	char msg[400];
	int e, p = -1, i, k;
	if (!label || !dir)
		PX_SKIP("PX_TEST_GPIO_LABEL/PX_TEST_GPIOSIM_DIR not set: the VM "
			"suite runs this on gpio-sim");
	c.chip = label;
	c.line[PX_GPIO_ESTOP].line_name = "estop";
	c.line[PX_GPIO_ESTOP].offset = 99; /* ignored: the name wins */
	c.line[PX_GPIO_ESTOP].debounce_ns = 1000000;
	c.line[PX_GPIO_ENABLE].line_name = "enable";
	c.line[PX_GPIO_ENABLE].offset = 98;
	c.line[PX_GPIO_TIMING].present = 0;
	PX_CHECK_INT_EQ(
		px_test_write_file(dir, "sim_gpio0/pull", "pull-down"), 0);
	px_dev_config_default(&dc);
	dc.name = "io";
	PX_CHECK_MSG(px_gpiod_create(&dc, &c, &d, &e, msg, sizeof msg) == PX_OK,
		     "%s", msg);
	PX_CHECK_INT_EQ(px_dev_dio_write(d, PX_DIO_ENABLE, 1, mono()), PX_OK);
	PX_CHECK_INT_EQ(sysfs_read(dir, "sim_gpio1/value"), 1);
	for (k = 0; k < 3; k++) {
		int want = k % 2 == 0;
		PX_CHECK_INT_EQ(px_test_write_file(dir, "sim_gpio0/pull",
						   want ? "pull-up"
							: "pull-down"),
				0);
		for (i = 0; i < 500 && p != want; i++) {
			struct timespec ts = {0, 2000000};
			nanosleep(&ts, NULL);
			px_dev_estop_read(d, mono(), &p);
		}
		PX_CHECK_MSG(p == want, "edge %d: e-stop %d", k, p);
	}
	PX_CHECK_INT_EQ(px_dev_dio_write(d, PX_DIO_ENABLE, 0, mono()), PX_OK);
	PX_CHECK_INT_EQ(sysfs_read(dir, "sim_gpio1/value"), 0);
	px_dev_free(d);
	/* a name the chip does not have is named in the error */
	c.line[PX_GPIO_ENABLE].line_name = "no-such-line";
	PX_CHECK(px_gpiod_create(&dc, &c, &d, &e, msg, sizeof msg) != PX_OK);
	PX_CHECK_MSG(strstr(msg, "no-such-line") != NULL, "%s", msg);
}

/* The safe output drops the enable relay and the timing line, whatever
 * their polarity, and px_dev_stop() of a device written to sends it; a
 * welded relay (stuck) is reported, not taken as safe. */
static void test_safe_output_drops_relay(void)
{
	struct px_sim_fault stuck = {PX_SIM_FAULT_STUCK, 10000000, 10000000,
				     1.0, 0};
	struct px_dev_config dc;
	struct px_dev_status st;
	struct px_dev *d;
	char msg[200];
	int al;
	px_dev_config_default(&dc);
	dc.name = "io";
	for (al = 0; al < 2; al++) {
		struct px_gpio_config c = io_cfg(1);
		c.line[PX_GPIO_ENABLE].active_low = al;
		c.line[PX_GPIO_TIMING].active_low = al;
		PX_CHECK_INT_EQ(px_gpio_sim_create(&dc, &c, NULL, 0, &d, msg,
						   sizeof msg),
				PX_OK);
		PX_CHECK_INT_EQ(px_dev_dio_write(d, PX_DIO_ENABLE, 1, 1000), PX_OK);
		PX_CHECK_INT_EQ(px_dev_dio_write(d, PX_DIO_TIMING, 1, 1000), PX_OK);
		PX_CHECK_INT_EQ(px_gpio_sim_output(d, PX_GPIO_ENABLE), !al);
		PX_CHECK_INT_EQ(px_dev_safe(d, 2000), PX_OK);
		PX_CHECK_INT_EQ(px_gpio_sim_output(d, PX_GPIO_ENABLE), al);
		PX_CHECK_INT_EQ(px_gpio_sim_output(d, PX_GPIO_TIMING), al);
		px_dev_status(d, &st);
		PX_CHECK_INT_EQ(st.outputs_safe, 1);
		PX_CHECK_INT_EQ(st.writes, 0); /* no force write counted */
		/* on again, then stopped: off again */
		PX_CHECK_INT_EQ(px_dev_start(d), PX_OK);
		PX_CHECK_INT_EQ(px_dev_dio_write(d, PX_DIO_ENABLE, 1, 3000), PX_OK);
		px_dev_status(d, &st);
		PX_CHECK_INT_EQ(st.outputs_safe, 0);
		px_dev_stop(d);
		PX_CHECK_INT_EQ(px_gpio_sim_output(d, PX_GPIO_ENABLE), al);
		px_dev_status(d, &st);
		PX_CHECK_INT_EQ(st.safe_writes, 2);
		px_dev_free(d);
	}
	{
		struct px_gpio_config c = io_cfg(1);
		PX_CHECK_INT_EQ(px_gpio_sim_create(&dc, &c, &stuck, 1, &d, msg,
						   sizeof msg),
				PX_OK);
		PX_CHECK_INT_EQ(px_dev_dio_write(d, PX_DIO_ENABLE, 1, 1000), PX_OK);
		PX_CHECK_INT_EQ(px_dev_safe(d, 15000000), PX_E_IO);
		PX_CHECK_INT_EQ(px_gpio_sim_output(d, PX_GPIO_ENABLE), 1);
		px_dev_status(d, &st);
		PX_CHECK_INT_EQ(st.outputs_safe, 0);
		PX_CHECK_INT_EQ(st.safe_errors, 1);
		/* the weld gone: it drops */
		PX_CHECK_INT_EQ(px_dev_safe(d, 25000000), PX_OK);
		PX_CHECK_INT_EQ(px_gpio_sim_output(d, PX_GPIO_ENABLE), 0);
		px_dev_free(d);
	}
}

/* Released e-stop with automatic re-arm: the loop stays in safe state
 * (PX_FAULT_ESTOP is latched) until px_loop_rearm(); a stale-free
 * application trip under the same setting re-arms by itself. */
static void test_estop_release_needs_rearm_despite_auto_rearm(void)
{
	struct px_gpio_config c = io_cfg(1);
	struct px_sim_fault f = {PX_SIM_FAULT_ESTOP, 100000000, 50000000, 1.0, 0};
	struct px_dev_config dc;
	struct px_loop_config lc;
	struct px_loop *l;
	struct px_loop_status ls;
	static struct app a;
	char msg[200];
	int i;
	memset(&a, 0, sizeof a);
	px_dev_config_default(&dc);
	dc.name = "io";
	PX_CHECK_INT_EQ(px_gpio_sim_create(&dc, &c, &f, 1, &a.io, msg, sizeof msg),
			PX_OK);
	px_loop_config_default(&lc);
	lc.clock = PX_LOOP_CLOCK_VIRTUAL;
	lc.read = a_read;
	lc.compute = a_compute;
	lc.write = a_write;
	lc.user = &a;
	lc.hist_bins = 100;
	lc.rearm_after_ok_cycles = 50; /* auto_rearm: 50 quiet cycles */
	PX_CHECK_INT_EQ(px_loop_create(&lc, &l), PX_OK);
	PX_CHECK_INT_EQ(px_loop_enable_add(l, "enable", &a.enable), 0);
	PX_CHECK_INT_EQ(px_dev_attach(a.io, l), 0);
	/* an application trip at cycle 20 re-arms by itself */
	a.trip_at = 20;
	PX_CHECK_INT_EQ(px_loop_run(l, 90), PX_OK);
	PX_CHECK(!px_loop_is_safe(l));
	PX_CHECK_INT_EQ(a.out_enable[30], 0);
	PX_CHECK_INT_EQ(a.out_enable[89], 1);
	/* pressed 100..150 ms, released: a second of quiet cycles later
	 * the relay is still off */
	PX_CHECK_INT_EQ(px_loop_run(l, 1110), PX_OK);
	PX_CHECK(px_loop_is_safe(l));
	px_loop_status(l, &ls);
	PX_CHECK_INT_EQ(ls.safe_cause, PX_FAULT_ESTOP);
	for (i = 110; i < 1200; i++)
		PX_CHECK_MSG(a.out_enable[i] == 0, "relay on at cycle %d", i);
	/* the deliberate reset */
	px_loop_rearm(l);
	PX_CHECK_INT_EQ(px_loop_run(l, 5), PX_OK);
	PX_CHECK(!px_loop_is_safe(l));
	px_loop_free(l);
	px_dev_free(a.io);
}

static const struct px_test tests[] = {
	PX_T(test_gpio_fault_lost_late_wrong_events),
	PX_T(test_gpio_fault_duplicate_events),
	PX_T(test_gpio_fault_stuck),
	PX_T(test_gpio_fault_kinds_refused),
	PX_T(test_debounce_matches_reference),
	PX_T(test_chatter_gives_one_press),
	PX_T(test_estop_trips_loop_and_holds_safe_state),
	PX_T(test_safe_output_drops_relay),
	PX_T(test_estop_release_needs_rearm_despite_auto_rearm),
	PX_T(test_gpiod_open_path),
	PX_T(test_gpiod_on_gpio_sim),
	PX_T(test_gpiod_by_name_on_gpio_sim),
};

PX_TEST_MAIN(tests)
