#!/bin/sh
# Inside the guest: load the modules, create the kernel devices (vcan0, a
# gpio-sim chip, a configfs USB HID gadget on dummy_hcd), then run the
# test programs with tests/run.sh. Every setup step is itself a check:
# a device that should be there and is not is a failure, never a skip.
set -u
cd /px
pass=0 fail=0 skip=0
log=/tmp/vm_setup.out
: >"$log"
ok() { echo "ok   $1" >>"$log"; pass=$((pass + 1)); }
bad() { echo "FAIL $1${2:+: $2}" >>"$log"; fail=$((fail + 1)); }
skp() { echo "skip $1" >>"$log"; skip=$((skip + 1)); }
check() { d=$1; shift; if out=$("$@" 2>&1); then ok "$d"; else bad "$d" "$out"; fi; }
wait_for() { # seconds, shell condition
	n=$(($1 * 10))
	while [ "$n" -gt 0 ]; do eval "$2" && return 0; sleep 0.1; n=$((n - 1)); done
	eval "$2" || { echo "not true after $1 s: $2"; return 1; }
}

# ---- modules ---------------------------------------------------------------
while read -r ko; do
	m=${ko%.ko}
	if out=$(insmod "/lib/modules/$ko" 2>&1) || [ -d "/sys/module/$(echo "$m" | tr - _)" ]; then
		ok "insmod $m"
	else
		bad "insmod $m" "$out"
	fi
done </lib/modules/load.list
mount -t configfs none /sys/kernel/config 2>/dev/null
check "configfs mounted" test -d /sys/kernel/config/usb_gadget

# ---- SocketCAN: vcan0 (CAN FD MTU) ---------------------------------------
check "vcan0 created" ip link add dev vcan0 type vcan
check "vcan0 CAN FD mtu" ip link set vcan0 mtu 72
check "vcan0 up" ip link set vcan0 up

# ---- uhid ----------------------------------------------------------------
check "/dev/uhid" wait_for 5 'test -c /dev/uhid'

# ---- gpio-sim: chip with named lines 0 estop, 1 enable -------------------
if [ -f /px/vm/no-gpio-sim ]; then
	skp "gpio-sim: not built on this host ($(cat /px/vm/no-gpio-sim))"
else
	g=/sys/kernel/config/gpio-sim/px
	if mkdir -p $g/bank0/line0 $g/bank0/line1 2>/dev/null &&
		echo 4 >$g/bank0/num_lines && echo px-gpio >$g/bank0/label &&
		echo estop >$g/bank0/line0/name && echo enable >$g/bank0/line1/name &&
		echo 1 >$g/live; then
		ok "gpio-sim chip live"
		chip=$(cat $g/bank0/chip_name) dev=$(cat $g/dev_name)
		export PX_TEST_GPIOCHIP=$chip PX_TEST_GPIO_LABEL=px-gpio
		export PX_TEST_GPIOSIM_DIR=/sys/devices/platform/$dev/$chip
		check "/dev/$chip" wait_for 5 'test -c /dev/$chip'
		check "gpio-sim pull attributes" test -w "$PX_TEST_GPIOSIM_DIR/sim_gpio0/pull"
	else
		bad "gpio-sim chip live" "configfs gpio-sim setup failed"
	fi
fi

# ---- USB HID gadget on dummy_hcd -----------------------------------------
u=/sys/kernel/config/usb_gadget/px
vidpid=1d6b:0104
if mkdir -p $u/strings/0x409 $u/configs/c.1/strings/0x409 $u/functions/hid.usb0 &&
	echo 0x1d6b >$u/idVendor && echo 0x0104 >$u/idProduct &&
	echo PX0001 >$u/strings/0x409/serialnumber &&
	echo proxima >$u/strings/0x409/manufacturer &&
	echo "proxima gadget haptic" >$u/strings/0x409/product &&
	echo 0 >$u/functions/hid.usb0/protocol &&
	echo 0 >$u/functions/hid.usb0/subclass &&
	echo 64 >$u/functions/hid.usb0/report_length &&
	cat /px/vm/haptic.rd >$u/functions/hid.usb0/report_desc &&
	ln -s $u/functions/hid.usb0 $u/configs/c.1/ &&
	udc=$(ls /sys/class/udc | head -n 1) && [ -n "$udc" ] &&
	echo "$udc" >$u/UDC; then
	ok "USB HID gadget bound to $udc"
	export PX_TEST_USB_VIDPID=$vidpid PX_TEST_HIDG=/dev/hidg0
	export PX_TEST_GADGET_DIR=$u PX_TEST_UDC=$udc
	check "/dev/hidg0" wait_for 5 'test -c /dev/hidg0'
	check "gadget enumerated on the host side" wait_for 10 'grep -qx 0104 /sys/bus/usb/devices/*/idProduct 2>/dev/null'
	check "usbhid made a hidraw node" wait_for 10 'ls /sys/class/hidraw/hidraw* >/dev/null 2>&1'
else
	bad "USB HID gadget" "configfs usb_gadget setup failed"
fi

echo "vm_setup: $pass passed, $fail failed, $skip skipped" >>"$log"

# ---- the tests -------------------------------------------------------------
export BUILD=/px/build
tests=$(cat /px/vm/tests.list)
echo "PXVM: running"
sh /px/tests/run.sh /px/vm/setup_report.sh $tests
echo "PXVM: status $?"
