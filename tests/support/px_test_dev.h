/*
 * px_test_dev.h - what the device tests share: pacing sleeps, writes to
 * sysfs/configfs attributes (unplugging a USB gadget), and deadlines on
 * the monotonic clock for waits that poll a device's state.
 *
 * A wait polls its condition until a deadline, not for a count of
 * sleeps: on a loaded machine (the QEMU guest of the VM suite) each sleep
 * runs long and the kernel needs the time, while the normal case still
 * ends at the first poll that sees the condition.
 */
#ifndef PX_TEST_DEV_H
#define PX_TEST_DEV_H

#include <stdint.h>

#include "px_loop.h"

/* Sleep ms milliseconds. */
void px_test_wait_ms(int ms);

/* Write v to the file dir/name; 0, or -1 when it cannot be written. */
int px_test_write_file(const char *dir, const char *name, const char *v);

/* The px_dev_mono_ns() time ms milliseconds from now. */
int64_t px_test_deadline_ms(int ms);

/* 1 once px_dev_mono_ns() is past deadline_ns, else 0. */
int px_test_past(int64_t deadline_ns);

/* A loop on the virtual clock with these phases (NULL: none) and user,
 * 100 histogram bins, the rest px_loop_config_default()'s; the test
 * fails when it cannot be made. */
struct px_loop *px_test_virtual_loop(px_loop_phase_fn read,
				     px_loop_phase_fn compute,
				     px_loop_phase_fn write, void *user);

#endif
