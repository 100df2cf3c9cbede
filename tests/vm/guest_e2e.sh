#!/bin/sh
# Inside the guest: the end-to-end scenario. proxima-run on e2e.yaml drives
# the real back ends on the guest's kernel devices for a few seconds:
#  - HID pose and force: uhid_feed creates 1234:0001 on /dev/uhid and
#    moves the tool tip through a floor; the hidapi back end reads its
#    input reports and the proxy renderer's forces come back to it as
#    output reports;
#  - e-stop and enable relay: gpio-sim lines "estop" and "enable" through
#    libgpiod;
#  - two CiA 402 drives: proxima-simarm on vcan0, the CANopen master in
#    proxima-run.
# Half-way the e-stop is pressed through gpio-sim's "pull"; the summary JSON
# must show the press, safe state from the next cycle on (none before),
# the drives enabled before and stopped after, the enable relay dropped,
# and the device receiving only zero forces from then on.
set -u
name=guest_e2e
pass=0 fail=0 skip=0
ok() { echo "ok   $1"; pass=$((pass + 1)); }
bad() { echo "FAIL $1"; fail=$((fail + 1)); }
bin=/px/build/bin tmp=/tmp/e2e
run=$bin/proxima-run cfg=/px/vm/e2e.yaml
# proxima-run counts the loop's heap calls with the tests' counter.
export LD_PRELOAD=/px/build/lib/libproxima-alloc-count.so
mkdir -p "$tmp"
finish() { echo "$name: $pass passed, $fail failed, $skip skipped"; [ "$fail" -eq 0 ]; exit $?; }
# num KEY: the number after "KEY": in the summary JSON (first match)
num() { sed -n "s/.*\"$1\": \(-\{0,1\}[0-9][0-9.e+-]*\).*/\1/p" "$tmp/e2e.json" | head -n 1; }
# dev NAME KEY: KEY of device NAME in the JSON's device list
dev() { sed -n "s/.*{\"name\": \"$1\".*\"$2\": \([0-9]*\).*/\1/p" "$tmp/e2e.json" | head -n 1; }
check() { if awk "BEGIN { exit !($2) }"; then ok "$1"; else echo "    false: $2"; bad "$1"; fi; }

out=$("$run" --check "$cfg" 2>&1); rc=$?
echo "$out" | sed 's/^/    /'
if [ "$rc" -eq 0 ]; then ok "scenario config validates"; else bad "scenario config validates (exit $rc)"; fi
if [ -z "${PX_TEST_GPIOSIM_DIR:-}" ]; then
	echo "skip end-to-end run: no gpio-sim in this guest"
	skip=$((skip + 1))
	finish
fi
sim=$PX_TEST_GPIOSIM_DIR
echo pull-down >"$sim/sim_gpio0/pull" # e-stop released

$bin/proxima-simarm --can vcan0 --drives 2 --mode csv --seconds 20 >"$tmp/arm.out" 2>&1 &
arm=$!
/px/build/tests/uhid_feed 15 "$tmp/uhid.txt" >"$tmp/uhid.out" 2>&1 &
feed=$!
n=50
while [ "$n" -gt 0 ] && ! grep -qs 'HID_ID=0003:00001234:00000001' /sys/class/hidraw/*/device/uevent; do
	sleep 0.1; n=$((n - 1))
done
if [ "$n" -gt 0 ]; then ok "uhid device 1234:0001 has a hidraw node"; else bad "uhid device 1234:0001 has a hidraw node"; fi

"$run" "$cfg" --duration-s 6 --summary-json "$tmp/e2e.json" --telemetry "$tmp/e2e.csv" \
	>"$tmp/run.out" 2>"$tmp/run.err" &
pr=$!
sleep 3
enable_before=$(cat "$sim/sim_gpio1/value")
echo pull-up >"$sim/sim_gpio0/pull" # press the e-stop
sleep 1
enable_after=$(cat "$sim/sim_gpio1/value")
wait "$pr"; rc=$?
kill "$arm" 2>/dev/null; wait "$arm" 2>/dev/null
wait "$feed"; frc=$?
echo pull-down >"$sim/sim_gpio0/pull"
sed 's/^/    /' "$tmp/run.out"
grep -v '^\[' "$tmp/run.err" | sed 's/^/    /'
if [ "$rc" -eq 0 ]; then ok "proxima-run on the real back ends (exit 0)"; else bad "proxima-run on the real back ends (exit $rc)"; fi
if [ ! -s "$tmp/e2e.json" ]; then bad "summary JSON written"; finish; fi
ok "summary JSON written"
sed -n '/"safe_at_end"/,/"fault_campaign"/p' "$tmp/e2e.json" | sed 's/^/    /'
check "cycles ran ($(num cycles))" "$(num cycles) > 1000"
check "HID samples from uhid ($(dev haptic samples))" "$(dev haptic samples) > 100"
check "force output reports written ($(dev haptic writes))" "$(dev haptic writes) > 100"
# (startup may trip the watchdog in a slow guest; auto re-arm recovers)
check "not in safe state when the e-stop was pressed" "$(num safe_at_estop) == 0"
check "the drives were enabled ($(num drives_enabled_cycles) cycles)" "$(num drives_enabled_cycles) > 0"
check "e-stop press seen ($(num estop_presses))" "$(num estop_presses) >= 1"
check "safe state within one cycle of the press ($(num estop_to_safe_cycles))" \
	"$(num estop_to_safe_cycles) >= 0 && $(num estop_to_safe_cycles) <= 1"
check "still in safe state at the end" "$(num safe_at_end) == 1"
if grep -q '"safe_cause": "estop"' "$tmp/e2e.json"; then ok "safe state caused by the e-stop"; else bad "safe state caused by the e-stop"; fi
# auto_rearm is on: the release at the end did not re-arm (checked above,
# safe_at_end), and --check said so
if echo "$out" | grep -q "warning: safety.watchdog.auto_rearm: true re-arms after other trips, never after the e-stop (device 'io' line 'estop')"; then
	ok "--check warns: auto_rearm with an e-stop"; else bad "--check warns: auto_rearm with an e-stop"; fi
check "contact force rendered before the press (max $(num max_force_n) N)" "$(num max_force_n) > 0.5"
check "force within the clamp" "$(num max_force_n) <= $(num force_clamp_n) + 1e-9"
if grep -q '"state": "operation enabled"' "$tmp/e2e.json"; then
	bad "no drive left in operation enabled"
else
	ok "no drive left in operation enabled"
fi
check "enable relay on before the press ($enable_before)" "$enable_before == 1"
check "enable relay off after the press ($enable_after)" "$enable_after == 0"
check "no allocation in the loop ($(num allocations_after_setup))" "$(num allocations_after_setup) == 0"
check "the heap counter saw setup's allocations" "$(num allocations_setup) > 0"
# the device's own view: forces arrived, none after the press
if [ "$frc" -eq 0 ] && [ -s "$tmp/uhid.txt" ]; then
	ok "uhid_feed ran"
	cat "$tmp/uhid.txt" | sed 's/^/    /'
	u() { sed -n "s/.* $1 \([0-9]*\).*/\1/p;s/^$1 \([0-9]*\).*/\1/p" "$tmp/uhid.txt" | head -n 1; }
	check "device received non-zero forces ($(u nonzero))" "$(u nonzero) > 0"
	check "device received only zero forces at the end ($(u tail_nonzero) of $(u tail_outputs))" \
		"$(u tail_outputs) > 0 && $(u tail_nonzero) == 0"
else
	sed 's/^/    /' "$tmp/uhid.out"
	bad "uhid_feed ran (exit $frc)"
fi

# ---- stopped by a signal in contact: what each device last received ------
# No e-stop this time: SIGTERM while the renderer pushes on the device.
# The uhid device's last output report, the drives' own states on vcan0
# (proxima-simarm prints them when it ends) and the shutdown record (the
# gpiod back end reads the relay line back) must all show the safe state.
echo pull-down >"$sim/sim_gpio0/pull"
$bin/proxima-simarm --can vcan0 --drives 2 --mode csv --seconds 30 >"$tmp/arm2.out" 2>&1 &
arm=$!
/px/build/tests/uhid_feed 30 "$tmp/uhid2.txt" >"$tmp/uhid2.out" 2>&1 &
feed=$!
n=50
while [ "$n" -gt 0 ] && ! grep -qs 'HID_ID=0003:00001234:00000001' /sys/class/hidraw/*/device/uevent; do
	sleep 0.1; n=$((n - 1))
done
"$run" "$cfg" --duration-s 60 --summary-json "$tmp/sig.json" --telemetry "$tmp/sig.csv" \
	>"$tmp/sig.out" 2>"$tmp/sig.err" &
pr=$!
# stop while the device is pushed on (the floor at z = 0, the tool tip at
# 10 mm cos(pi t)): at the first status line (one a second) showing force
n=300
while [ "$n" -gt 0 ]; do
	sleep 0.05; n=$((n - 1))
	f=$(sed -n 's/.*| force *\([0-9.]*\) N.*/\1/p' "$tmp/sig.err" | tail -n 1)
	[ -n "$f" ] && awk "BEGIN { exit !($f > 0.2) }" && break
done
echo "    stopping at a status force of ${f:-?} N"
enable_on=$(cat "$sim/sim_gpio1/value")
kill -TERM "$pr"
wait "$pr"; rc=$?
kill "$arm" 2>/dev/null; wait "$arm" 2>/dev/null
wait "$feed"; frc=$?
sed 's/^/    /' "$tmp/sig.out"
grep -v '^\[' "$tmp/sig.err" | sed 's/^/    /'
sed 's/^/    /' "$tmp/arm2.out" "$tmp/uhid2.txt" 2>/dev/null
j() { sed -n "s/.*\"$1\": \(-\{0,1\}[0-9][0-9.e+-]*\).*/\1/p" "$tmp/sig.json" | head -n 1; }
if [ "$rc" -eq 0 ] && [ -s "$tmp/sig.json" ]; then ok "SIGTERM: exit 0, summary written"; else bad "SIGTERM: exit 0, summary written (exit $rc)"; fi
if grep -q '"shutdown_reason": "SIGTERM"' "$tmp/sig.json"; then ok "SIGTERM: the shutdown says so"; else bad "SIGTERM: the shutdown says so"; fi
check "SIGTERM: the relay was on during the run ($enable_on)" "$enable_on == 1"
check "SIGTERM: stopped while a force was rendered (${f:-none} N)" "${f:-0} > 0.2"
check "SIGTERM: shutdown safe ($(j shutdown_safe))" "$(j shutdown_safe) == 1"
check "SIGTERM: hidapi zero force confirmed ($(j force_zeroed) of $(j force_devices))" \
	"$(j force_zeroed) == 1 && $(j force_devices) == 1"
check "SIGTERM: gpiod relay read back off ($(j relays_off) of $(j relay_devices))" \
	"$(j relays_off) == 1 && $(j relay_devices) == 1"
check "SIGTERM: both drives confirmed disabled ($(j drives_disabled) of $(j shutdown_drives))" \
	"$(j drives_disabled) == 2 && $(j shutdown_drives) == 2"
for d in 0 1; do
	if grep -q "^proxima-simarm: drive $d (node $((d + 1))) at the end: switch on disabled" "$tmp/arm2.out"; then
		ok "SIGTERM: drive $d on vcan0 ended in switch on disabled"
	else bad "SIGTERM: drive $d on vcan0 ended in switch on disabled"; fi
done
if [ "$frc" -eq 0 ] && [ -s "$tmp/uhid2.txt" ]; then
	u2() { sed -n "s/.* $1 \(-\{0,1\}[0-9]*\).*/\1/p" "$tmp/uhid2.txt" | head -n 1; }
	check "SIGTERM: the device was pushed on ($(u2 nonzero) non-zero reports)" "$(u2 nonzero) > 0"
	check "SIGTERM: the uhid device's last output report is zero force ($(u2 last_fx), $(u2 last_fy), $(u2 last_fz) mN)" \
		"$(u2 last_fx) == 0 && $(u2 last_fy) == 0 && $(u2 last_fz) == 0"
else
	sed 's/^/    /' "$tmp/uhid2.out"
	bad "SIGTERM: uhid_feed ran (exit $frc)"
fi
finish
