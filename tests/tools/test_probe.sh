#!/bin/sh
# proxima-probe: runs, prints one or more lines per subsystem, each
# starting with its name, and an absent subsystem as exactly one line.
# PX_TEST_NEEDS: libgpiod (tests/run.sh skips it in builds without)
set -u
name=test_probe
bin=${BUILD:-build}/bin/proxima-probe
pass=0 fail=0
check() { # description, condition command...
	d=$1; shift
	if "$@"; then echo "ok   $d"; pass=$((pass + 1))
	else echo "FAIL $d"; fail=$((fail + 1)); fi
}
out=$("$bin" 2>&1); rc=$?
echo "$out" | sed 's/^/    /'
check "exit status 0" test "$rc" -eq 0
for s in hid usb can gpio; do
	check "a $s section" sh -c "echo \"\$1\" | grep -q \"^$s:\"" _ "$out"
done
check "every line names its subsystem" \
	sh -c "! echo \"\$1\" | grep -qvE '^(hid|usb|can|gpio):'" _ "$out"
if [ ! -e /dev/gpiochip0 ]; then
	check "no GPIO: one clear line" \
		sh -c "test \"\$(echo \"\$1\" | grep -c '^gpio:')\" -eq 1 &&
		       echo \"\$1\" | grep -q '^gpio: no GPIO chips'" _ "$out"
fi
if echo "$out" | grep -q 'no AF_CAN support'; then
	check "no AF_CAN: one clear line" \
		sh -c "test \"\$(echo \"\$1\" | grep -c '^can:')\" -eq 1 &&
		       echo \"\$1\" | grep -q 'no AF_CAN support'" _ "$out"
fi
"$bin" --bogus >/dev/null 2>&1; rc=$?
check "unknown option: status 2" test "$rc" -eq 2
echo "$name: $pass passed, $fail failed, 0 skipped"
[ "$fail" -eq 0 ]
