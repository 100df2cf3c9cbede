#!/bin/sh
# The VM suite: prepare (once per machine, cached in BUILD/vm), build the
# initramfs from this build's device test programs, boot Debian's kernel
# in QEMU under a hard time limit, and turn the guest's results into one
# summary line "test_vm: N passed, N failed, N skipped".
# Environment: BUILD (default build), MAKE, PX_VM_TIMEOUT (seconds, 480),
# PX_VM_ACCEL (kvm or tcg; default kvm only where the CPU has vmx/svm).
set -u
name=test_vm
build=${BUILD:-build}
mkdir -p "$build/vm" || exit 1
build=$(cd "$build" && pwd)
vmdir=$build/vm
here=$(cd "$(dirname "$0")" && pwd)
top=$(cd "$here/../.." && pwd)
limit=${PX_VM_TIMEOUT:-480}
summary() { echo "$name: $1 passed, $2 failed, $3 skipped"; }
t0=$(date +%s)

sh "$here/prepare.sh" "$vmdir"
rc=$?
if [ "$rc" -eq 77 ]; then
	echo "skip VM suite: $(cat "$vmdir/skip-reason" 2>/dev/null)"
	summary 0 0 1
	exit 0
elif [ "$rc" -ne 0 ]; then
	echo "FAIL VM suite: preparing the guest kernel failed (see above)"
	summary 0 1 0
	exit 1
fi
t1=$(date +%s)

# test_hid once more, linked with hidapi-libusb instead of hidapi-hidraw:
# the other objects of this build are reused, only px_hidapi.o differs.
alt=$vmdir/hidapi-libusb
mkdir -p "$alt"
rm -rf "$alt/obj"
cp -pR "$build/obj" "$alt/obj"
rm -f "$alt/obj/devices/backends/px_hidapi.o" "$alt/obj/devices/backends/px_hidapi.d"
if ! env -u MAKEFLAGS -u MFLAGS ${MAKE:-make} -s --no-print-directory -C "$top" \
	BUILD="$alt" HIDAPI=libusb "$alt/tests/test_hid" >"$vmdir/alt.log" 2>&1; then
	cat "$vmdir/alt.log"
	echo "FAIL VM suite: building test_hid with hidapi-libusb failed"
	summary 0 1 0
	exit 1
fi

# The end-to-end scenario's HID device (guest_e2e.sh): a helper program
# of the suite, not part of the library.
if ! ${CC:-cc} -std=c11 -D_GNU_SOURCE -Wall -Wextra -Werror -O2 \
	-o "$vmdir/uhid_feed" "$here/uhid_feed.c" -lm >"$vmdir/uhid_feed.log" 2>&1; then
	cat "$vmdir/uhid_feed.log"
	echo "FAIL VM suite: building tests/vm/uhid_feed.c failed"
	summary 0 1 0
	exit 1
fi

# What the guest runs, in order (paths in the guest).
g=/px/build
files="$build/tests/test_can=$g/tests/test_can
$build/tests/test_canopen=$g/tests/test_canopen
$build/tests/test_hid=$g/tests/test_hid
$alt/tests/test_hid=$g/tests/test_hid_libusb
$build/tests/test_usb=$g/tests/test_usb
$build/tests/test_gpio=$g/tests/test_gpio
$build/bin/proxima-probe=$g/bin/proxima-probe
$build/bin/proxima-simarm=$g/bin/proxima-simarm
$build/bin/proxima-run=$g/bin/proxima-run
$build/lib/libproxima-alloc-count.so=$g/lib/libproxima-alloc-count.so
$vmdir/uhid_feed=$g/tests/uhid_feed
$top/tests/run.sh=/px/tests/run.sh
$top/tests/tools/test_probe.sh=/px/tests/test_probe.sh"
for a in $files; do
	f=${a%%=*}
	[ -f "$f" ] || { echo "FAIL VM suite: $f is not built"; summary 0 1 0; exit 1; }
done
# PX_VM_TESTS (guest paths) runs only those, e.g. "/px/build/tests/test_usb"
[ -n "${PX_VM_TESTS:-}" ] && printf '%s\n' $PX_VM_TESTS >"$vmdir/tests.list" ||
printf '%s\n' $g/tests/test_can $g/tests/test_canopen $g/tests/test_hid \
	$g/tests/test_hid_libusb $g/tests/test_usb $g/tests/test_gpio \
	/px/tests/test_probe.sh /px/vm/guest_probe.sh /px/vm/guest_e2e.sh \
	>"$vmdir/tests.list"
# shellcheck disable=SC2086
if ! sh "$here/mkinitrd.sh" "$vmdir" "$vmdir/initramfs.cpio" $files; then
	echo "FAIL VM suite: building the initramfs failed"
	summary 0 1 0
	exit 1
fi
t2=$(date +%s)

accel=${PX_VM_ACCEL:-}
if [ -z "$accel" ]; then
	accel=tcg
	grep -qwE 'vmx|svm' /proc/cpuinfo && [ -w /dev/kvm ] && accel=kvm
fi
echo "booting $(cat "$vmdir/kernel/ready") ($accel, limit ${limit} s)"
timeout -k 5 "$limit" qemu-system-x86_64 -accel "$accel" -m 1024 -smp 2 \
	-nodefaults -display none -no-reboot -serial stdio \
	-kernel "$vmdir/kernel/vmlinuz" -initrd "$vmdir/initramfs.cpio" \
	-append "console=ttyS0 quiet loglevel=3 panic=-1 rdinit=/init" \
	</dev/null >"$vmdir/guest.log" 2>&1
qrc=$?
t3=$(date +%s)
tr -d '\r' <"$vmdir/guest.log" >"$vmdir/guest.txt"
# the guest's output, indented so that its summary lines stay its own
sed 's/^/    /' "$vmdir/guest.txt"
echo "times: prepare $((t1 - t0)) s, initramfs $((t2 - t1)) s, guest $((t3 - t2)) s"
total=$(sed -n '/^PXVM: running$/,/^PXVM: status/p' "$vmdir/guest.txt" |
	grep -E '^[0-9]+ passed, [0-9]+ failed, [0-9]+ skipped$' | tail -n 1)
status=$(sed -n 's/^PXVM: status \([0-9]*\)$/\1/p' "$vmdir/guest.txt" | tail -n 1)
if [ "$qrc" -eq 124 ] || [ "$qrc" -eq 137 ]; then
	echo "FAIL VM suite: the guest did not finish within $limit s"
elif [ -z "$total" ] || [ -z "$status" ]; then
	echo "FAIL VM suite: no result from the guest (qemu exit status $qrc)"
fi
if [ -z "$total" ] || [ -z "$status" ]; then
	set -- 0 1 0
else
	set -- $(echo "$total" | sed -E 's/([0-9]+) passed, ([0-9]+) failed, ([0-9]+) skipped/\1 \2 \3/')
	[ "$status" -ne 0 ] && [ "$2" -eq 0 ] && set -- "$1" 1 "$3"
fi
summary "$1" "$2" "$3"
[ "$2" -eq 0 ]
