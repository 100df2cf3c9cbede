#!/bin/sh
# Inside the guest: proxima-probe lists each kernel device of the suite.
set -u
name=guest_probe
pass=0 fail=0 skip=0
check() { d=$1; shift
	if "$@"; then echo "ok   $d"; pass=$((pass + 1)); else echo "FAIL $d"; fail=$((fail + 1)); fi; }
# a test that failed half-way may have left the gadget unplugged
if [ -n "${PX_TEST_GADGET_DIR:-}" ] && [ -z "$(cat "$PX_TEST_GADGET_DIR/UDC")" ]; then
	echo "$PX_TEST_UDC" >"$PX_TEST_GADGET_DIR/UDC"
	sleep 2
fi
# a uhid device for as long as fd 3 stays open
uhid=0
if exec 3<>/dev/uhid && cat /px/vm/uhid_create.bin >&3; then
	uhid=1
	n=50
	while [ "$n" -gt 0 ] && ! grep -qs 'HID_ID=0003:00001234:00000002' /sys/class/hidraw/*/device/uevent; do
		sleep 0.1; n=$((n - 1))
	done
fi
out=$(/px/build/bin/proxima-probe --lines 2>&1); rc=$?
[ "$uhid" = 1 ] && exec 3>&-
echo "$out" | sed 's/^/    /'
has() { echo "$out" | grep -qE "$1"; }
check "exit status 0" test "$rc" -eq 0
check "can: vcan0 listed (virtual: no controller state)" has '^can:  vcan0 \(no controller state: virtual\)$'
check "hid: the uhid device 1234:0002" has '^hid: .*1234:0002.*"proxima uhid haptic"'
if [ -n "${PX_TEST_USB_VIDPID:-}" ]; then
	check "usb: the gadget $PX_TEST_USB_VIDPID" has "^usb: .* ${PX_TEST_USB_VIDPID}"
	check "hid: the gadget through usbhid/hidraw" has "^hid: .*${PX_TEST_USB_VIDPID}"
else
	echo "skip usb/hid: no USB gadget in this guest"; skip=$((skip + 1))
fi
if [ -n "${PX_TEST_GPIOCHIP:-}" ]; then
	check "gpio: the gpio-sim chip" has "^gpio: +${PX_TEST_GPIOCHIP} \[px-gpio\] 4 lines"
	check "gpio: named lines" has '^gpio: +line +0: "estop" input'
else
	echo "skip gpio: no gpio-sim in this guest"; skip=$((skip + 1))
fi
check "no line outside the four sections" sh -c "! echo \"\$1\" | grep -qvE '^(hid|usb|can|gpio):'" _ "$out"
echo "$name: $pass passed, $fail failed, $skip skipped"
[ "$fail" -eq 0 ]
