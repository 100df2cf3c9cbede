#!/bin/sh
# The VM suite (tests/vm/run.sh): the device back ends against real kernel
# drivers (vcan, uhid, gpio-sim, a USB HID gadget on dummy_hcd) inside a
# QEMU guest running Debian's kernel. Once per `make test`: the sanitizer
# build skips it (the guest runs the same back ends, and a second boot
# would double the time).
set -u
if [ "${SAN:-}" = 1 ]; then
	echo "skip VM suite: not repeated in the sanitizer build (make test runs it)"
	echo "test_vm: 0 passed, 0 failed, 1 skipped"
	exit 0
fi
if [ "${PX_VM:-1}" = 0 ]; then
	echo "skip VM suite: PX_VM=0"
	echo "test_vm: 0 passed, 0 failed, 1 skipped"
	exit 0
fi
exec sh "$(dirname "$0")/vm/run.sh"
