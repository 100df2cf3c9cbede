#!/bin/sh
# proxima-run's command-line contract: --check on good and bad configs
# (exit status and message format), flag parsing; then every shipped
# config end to end in virtual time (summary JSON, no allocation after
# setup, force within the clamp, CSV and SVG files), reproducibility, the
# heap counter's self-check, safe state on a velocity limit, scene errors.
# Prints a harness-style summary line.
set -u
name=test_proxima_run
bin="${BUILD:-build}/bin/proxima-run"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
pass=0 fail=0 skip=0
ok() { echo "ok   $1"; pass=$((pass + 1)); }
skp() { echo "skip $1"; skip=$((skip + 1)); }
bad() { echo "FAIL $1"; sed 's/^/    /' "$tmp/out" "$tmp/err" 2>/dev/null; fail=$((fail + 1)); }
# expect DESCRIPTION STATUS COMMAND...: run, compare the exit status.
expect() {
	d=$1 want=$2; shift 2
	"$@" >"$tmp/out" 2>"$tmp/err"
	got=$?
	if [ "$got" -eq "$want" ]; then ok "$d (exit $got)"; else
		echo "    exit status $got, expected $want"; bad "$d"; fi
}
# has DESCRIPTION FILE FIXED-STRING: the file contains the exact line.
has() {
	if grep -qxF -- "$3" "$2"; then ok "$1"; else
		echo "    missing line: $3"; bad "$1"; fi
}
if [ ! -x "$bin" ]; then
	echo "skip: $bin not built"
	echo "$name: 0 passed, 0 failed, 1 skipped"
	exit 0
fi

for f in config/examples/*.yaml; do
	expect "--check $f" 0 "$bin" --check "$f"
	if [ "$(wc -l <"$tmp/out")" -eq 1 ] &&
		grep -qE "^$f: OK \([0-9]+ devices?, loop period [0-9]+ ns\)\$" "$tmp/out"; then
		ok "one-line OK for $f"; else bad "one-line OK for $f"; fi
	if [ -s "$tmp/err" ]; then echo "    unexpected stderr"; bad "--check $f is quiet on stderr"; else ok "--check $f is quiet on stderr"; fi
done

cat >"$tmp/bad.yaml" <<'Y'
loop:
  period_ns: 0
  perod_ns: 1000
  priority: high
devices:
  - name: pad
    backend: hidraw2
Y
expect "--check on a bad config" 1 "$bin" --check "$tmp/bad.yaml"
has "range error with line:column" "$tmp/err" \
	"$tmp/bad.yaml:2:14: loop.period_ns: 0 is out of range [10000, 100000000]"
has "unknown key with suggestion" "$tmp/err" \
	"$tmp/bad.yaml:3:3: loop.perod_ns: unknown key (did you mean 'period_ns'?)"
has "wrong type" "$tmp/err" \
	"$tmp/bad.yaml:4:13: loop.priority: expected an integer, got 'high'"
has "unknown enum value" "$tmp/err" \
	"$tmp/bad.yaml:7:14: devices[0].backend: unknown value 'hidraw2' (expected one of: sim, hidapi, libusb, socketcan, gpiod)"
has "error count" "$tmp/err" "$tmp/bad.yaml: invalid configuration (4 errors)"
if [ -s "$tmp/out" ]; then echo "    stdout not empty"; bad "nothing on stdout for a bad config"; else ok "nothing on stdout for a bad config"; fi

printf 'loop: [1, 2\n' >"$tmp/syntax.yaml"
expect "--check on a YAML syntax error" 1 "$bin" --check "$tmp/syntax.yaml"
if grep -q "^$tmp/syntax.yaml:2:1: YAML syntax error: " "$tmp/err"; then ok "syntax error placed"; else bad "syntax error placed"; fi

expect "--check on a missing file" 1 "$bin" --check "$tmp/none.yaml"
has "missing file message" "$tmp/err" "$tmp/none.yaml: cannot open: No such file or directory"

good=config/examples/haptic_sim.yaml
expect "--check $good" 0 "$bin" --check "$good"
has "OK line of the default config" "$tmp/out" "$good: OK (2 devices, loop period 1000000 ns)"
expect "no CONFIG" 2 "$bin"
expect "unknown flag" 2 "$bin" --check --fast "$good"
if grep -q "unknown option '--fast'" "$tmp/err"; then ok "unknown flag named"; else bad "unknown flag named"; fi
expect "two CONFIGs" 2 "$bin" --check "$good" "$good"
expect "--duration-s needs a value" 2 "$bin" "$good" --duration-s
expect "--duration-s rejects junk" 2 "$bin" "$good" --duration-s 5x
expect "--duration-s rejects 0" 2 "$bin" "$good" --duration-s 0
expect "--summary-json needs a file" 2 "$bin" "$good" --summary-json
expect "flags accepted with --check" 0 "$bin" --check "$good" --duration-s 2.5 \
	--virtual-time --summary-json "$tmp/s.json"
expect "--flag=value form" 0 "$bin" --check --duration-s=3 --summary-json="$tmp/s.json" "$good"
expect "--help" 0 "$bin" --help
if grep -q "^usage: proxima-run CONFIG \[--duration-s N\] \[--virtual-time\] \[--summary-json FILE\]$" "$tmp/out"; then ok "usage line"; else bad "usage line"; fi

expect "runner on a bad config reports the config" 1 "$bin" "$tmp/bad.yaml"

# control section: errors fail --check; a stiffness beyond the passive
# limit is a warning on stderr with its place, and the file stays valid.
cat >"$tmp/ctl.yaml" <<'Y'
loop: {period_ns: 1000000}
devices:
  - {name: pen, backend: sim, sim: {kind: haptic, damping_n_s_per_m: 2.0}}
control:
  mode: haptic
  device: pen
  haptic:
    stiffness_n_per_m: 5000
    damping_n_s_per_m: 0.5
Y
expect "--check warns on a non-passive stiffness" 0 "$bin" --check "$tmp/ctl.yaml"
if grep -q "^$tmp/ctl.yaml:8:24: control.haptic.stiffness_n_per_m: warning: stiffness 5000 N/m is not passive .* allows K < 3000 N/m$" "$tmp/err"; then
	ok "stability warning placed"; else bad "stability warning placed"; fi
sed 's/stiffness_n_per_m: 5000/stiffness_n_per_m: 2500/' "$tmp/ctl.yaml" >"$tmp/ctl2.yaml"
expect "--check on a passive stiffness" 0 "$bin" --check "$tmp/ctl2.yaml"
if [ -s "$tmp/err" ]; then bad "no warning when passive"; else ok "no warning when passive"; fi
sed 's/device: pen$/device: pem/' "$tmp/ctl.yaml" >"$tmp/ctl3.yaml"
expect "--check on a bad control section" 1 "$bin" --check "$tmp/ctl3.yaml"
has "control error placed" "$tmp/err" \
	"$tmp/ctl3.yaml:6:11: control.device: no device named 'pem' in devices"


# ---- end-to-end runs in virtual time ---------------------------------
# num FILE KEY: the number after "KEY": on its line of a summary JSON.
num() { sed -n "s/.*\"$2\": \(-\{0,1\}[0-9][0-9.e+-]*\).*/\1/p" "$1" | head -n 1; }
# sub FILE OBJECT KEY: KEY inside the one-line object OBJECT.
sub() { sed -n "s/.*\"$2\": {.*\"$3\": \([0-9][0-9]*\).*/\1/p" "$1" | head -n 1; }
# check DESCRIPTION AWK-CONDITION: pass when awk says the condition holds.
check() { if awk "BEGIN { exit !($2) }"; then ok "$1"; else echo "    false: $2"; bad "$1"; fi; }
# svg DESCRIPTION FILE: a complete SVG document with at least one path.
svg() {
	if [ -s "$2" ] && head -n 1 "$2" | grep -q '^<?xml' && tail -n 1 "$2" | grep -qx '</svg>' &&
		grep -q "<path " "$2"; then ok "$1"; else echo "    bad SVG: $2"; bad "$1"; fi
}
# A config with its scene paths made absolute, so it runs from $tmp.
absolute() { sed "s|file: scenes/|file: $PWD/config/examples/scenes/|" "$1"; }

ran=0
for f in config/examples/*.yaml; do
	base=$(basename "$f" .yaml)
	if grep -qE 'backend: (hidapi|libusb|gpiod)|transport: kernel' "$f"; then
		# real devices run on the real clock only
		expect "$f: no virtual time with hardware" 2 "$bin" "$f" --virtual-time --duration-s 1
		# this machine has none of them: a clear error naming the device
		"$bin" "$f" --duration-s 0.2 --telemetry "$tmp/hw.csv" >"$tmp/out" 2>"$tmp/err"
		rc=$?
		if [ "$rc" -eq 0 ]; then
			skp "$f: its hardware is present here (ran)"
		elif [ "$rc" -eq 1 ] && grep -qE "^proxima-run: device '[a-z0-9_]+' \((hidapi|libusb|socketcan|gpiod), devices\[[0-9]\]\.[a-z_.]+\): .*(errno|not found|no HID|no USB|found|no such network interface)" "$tmp/err"; then
			ok "$f: absent hardware named with its reason (exit 1)"
		else
			sed 's/^/    /' "$tmp/err" | head -n 5
			bad "$f: absent hardware named with its reason (exit $rc)"
		fi
		continue
	fi
	if grep -qE 'transport: unix' "$f"; then
		# two processes (sim.spawn_arm starts proxima-simarm) on the
		# real clock; the socket in $tmp so parallel runs never meet;
		# generous timeouts on a loaded machine (behaviour, not timing)
		expect "$f: no virtual time with a bus shared with another process" 2 \
			"$bin" "$f" --virtual-time --duration-s 1
		j="$tmp/$base.json"
		sed "s|socket_path: [^ ]*|socket_path: $tmp/$base.sock|; s|device_timeout_ns: .*|device_timeout_ns: 500_000_000|; s|heartbeat_timeout_ns: .*|heartbeat_timeout_ns: 2_000_000_000|" \
			"$f" >"$tmp/$base.yaml"
		expect "$f runs with its arm as a second process (3 s, real clock)" 0 \
			"$bin" "$tmp/$base.yaml" --duration-s 3 --summary-json "$j" --telemetry "$tmp/$base.csv"
		[ -s "$j" ] || { bad "$f: summary JSON written"; continue; }
		pid=$(sed -n 's/^proxima-run: spawned .*proxima-simarm (pid \([0-9]*\)).*/\1/p' "$tmp/err")
		check "$f: proxima-simarm spawned (pid $pid)" "\"$pid\" != \"\""
		if grep -qF "layout from $tmp/$base.yaml" "$tmp/err"; then ok "$f: proxima-simarm took the config (--config)"
		else bad "$f: proxima-simarm took the config (--config)"; fi
		if [ -n "$pid" ] && ! kill -0 "$pid" 2>/dev/null; then ok "$f: the arm process is gone after the run"
		else bad "$f: the arm process is gone after the run"; fi
		check "$f: drives enabled over the socket ($(num "$j" drives_enabled_cycles) cycles)" \
			"$(num "$j" drives_enabled_cycles) > 100"
		check "$f: no drive lost or in fault" "$(num "$j" drive_problem_cycles) == 0"
		check "$f: no allocation after setup" "$(num "$j" allocations_after_setup) == 0"
		if grep -q 'control:' "$f"; then
			check "$f: min clearance $(num "$j" min_clearance_m) >= protective $(num "$j" protective_distance_m)" \
				"$(num "$j" min_clearance_m) >= $(num "$j" protective_distance_m)"
			check "$f: the speed was scaled down" "$(num "$j" min_speed_scale) < 1"
		fi
		continue
	fi
	ran=$((ran + 1))
	j="$tmp/$base.json" c="$tmp/$base.csv"
	expect "$f runs in virtual time" 0 "$bin" "$f" --virtual-time --duration-s 3 \
		--summary-json "$j" --telemetry "$c"
	[ -s "$j" ] || { bad "$f: summary JSON written"; continue; }
	cycles=$(num "$j" cycles)
	check "$f: 3000 cycles" "$cycles == 3000"
	if grep -q 'kind: overrun' "$f"; then
		check "$f: overruns only from the injected slow computes" "$(num "$j" overruns) > 0 && $(num "$j" phase_error_ns) == 0"
	else
		check "$f: no overrun on the virtual clock" "$(num "$j" overruns) == 0"
	fi
	check "$f: no allocation after setup" "$(num "$j" allocations_after_setup) == 0"
	check "$f: the counter saw setup's allocations" "$(num "$j" allocations_setup) > 0"
	for o in wakeup_latency_ns compute_ns; do
		for k in p50 p99 p999 max; do
			v=$(sub "$j" "$o" "$k")
			check "$f: $o.$k present" "\"$v\" != \"\""
		done
	done
	check "$f: compute p50 <= p99 <= p999 <= max" \
		"$(sub "$j" compute_ns p50) <= $(sub "$j" compute_ns p99) && $(sub "$j" compute_ns p99) <= $(sub "$j" compute_ns p999) && $(sub "$j" compute_ns p999) <= $(sub "$j" compute_ns max)"
	clamp=$(num "$j" force_clamp_n)
	check "$f: force within the clamp ($(num "$j" max_force_n) <= $clamp)" \
		"$(num "$j" max_force_n) <= $clamp + 1e-9"
	check "$f: min_distance_m is a number" "\"$(num "$j" min_distance_m)\" != \"\""
	check "$f: proxy never inside a closed model" "$(num "$j" min_proxy_distance_m) >= 0"
	check "$f: safe_state_trips counted" "\"$(num "$j" safe_state_trips)\" != \"\""
	if grep -q '"faults": {"input_stale": [0-9]*, ' "$j"; then ok "$f: faults by kind"; else bad "$f: faults by kind"; fi
	# CSV: header plus one line per (decimated) cycle; force column within the clamp
	lines=$(($(wc -l <"$c") - 1))
	check "$f: telemetry rows ($lines)" "$lines == $(num "$j" telemetry_records) && $lines > 0"
	check "$f: CSV forces within the clamp" \
		"$(awk -F, 'NR > 1 && $12 > m { m = $12 } END { print m + 0 }' "$c") <= $clamp + 1e-6"
	svg "$f: time plot" "$tmp/${base}_time.svg"
	svg "$f: latency plot" "$tmp/${base}_latency.svg"
	if grep -qF "  plots             $tmp/${base}_time.svg" "$tmp/out"; then ok "$f: plot paths printed"; else bad "$f: plot paths printed"; fi
done
check "at least one shipped config ran end to end" "$ran >= 1"

# The virtual clock is deterministic: the same run twice gives the same
# telemetry (apart from the compute time, measured on the real clock).
expect "second identical run" 0 "$bin" "$good" --virtual-time --duration-s 3 \
	--telemetry "$tmp/det.csv"
cut -d, -f1-17,19 "$tmp/haptic_sim.csv" >"$tmp/a.cut"
cut -d, -f1-17,19 "$tmp/det.csv" >"$tmp/b.cut"
if [ -s "$tmp/a.cut" ] && cmp -s "$tmp/a.cut" "$tmp/b.cut"; then
	ok "virtual-time runs are reproducible"; else bad "virtual-time runs are reproducible"; fi

# The heap counter is live: a deliberate allocation in cycle 10 shows.
expect "allocation probe run" 0 env PX_RUN_ALLOC_PROBE=1 "$bin" "$good" --virtual-time \
	--duration-s 0.1 --summary-json "$tmp/probe.json" --telemetry "$tmp/probe.csv"
check "the probe's malloc and free are counted" "$(num "$tmp/probe.json" allocations_after_setup) == 2"

# Penalty renderer on the same scene: force still within the clamp.
absolute "$good" | sed 's/renderer: proxy /renderer: penalty/' >"$tmp/penalty.yaml"
expect "penalty renderer run" 0 "$bin" "$tmp/penalty.yaml" --virtual-time --duration-s 2 \
	--summary-json "$tmp/pen.json" --telemetry "$tmp/pen.csv"
check "penalty: force within the clamp" "$(num "$tmp/pen.json" max_force_n) <= $(num "$tmp/pen.json" force_clamp_n) + 1e-9"
check "penalty: contact happened" "$(num "$tmp/pen.json" contact_cycles) > 0"

# Tracked queries (scene.tracking, on by default in haptic mode) change
# the cost, not the answers: the same run with tracking off gives the same
# telemetry within rounding; the streams answered, mostly from their
# tracked sets, and checked against the global query at every answer
# (verify_every: 1) never disagreed.
check "tracking on by default: streams answered" \
	"$(sub "$tmp/haptic_sim.json" tracking streams) >= 1 && $(sub "$tmp/haptic_sim.json" tracking queries) > 3000"
check "tracking on by default: mostly tracked" \
	"$(sub "$tmp/haptic_sim.json" tracking tracked) > $(sub "$tmp/haptic_sim.json" tracking queries) / 2"
if "$bin" "$good" --virtual-time --duration-s 0.5 --telemetry "$tmp/tr.csv" 2>/dev/null |
	grep -qE '^  tracking          [0-9]+ streams?: [0-9]+ answers, [0-9.]+ % tracked'; then
	ok "summary has the tracking line"; else bad "summary has the tracking line"; fi
absolute "$good" | sed 's/^  primitives:/  tracking: {enabled: false}\n  primitives:/' >"$tmp/notrack.yaml"
absolute "$good" | sed 's/^  primitives:/  tracking: {verify_every: 1}\n  primitives:/' >"$tmp/verify.yaml"
expect "run with tracking off" 0 "$bin" "$tmp/notrack.yaml" --virtual-time --duration-s 3 \
	--summary-json "$tmp/notrack.json" --telemetry "$tmp/notrack.csv"
check "tracking off: no stream" "$(sub "$tmp/notrack.json" tracking streams) == 0"
# columns 3-14 (device, proxy, force, distance, penetration) agree to
# the CSV's six significant digits (a last digit may round either way)
if [ "$(wc -l <"$tmp/notrack.csv")" -eq "$(wc -l <"$tmp/haptic_sim.csv")" ] &&
	paste -d, "$tmp/haptic_sim.csv" "$tmp/notrack.csv" | awk -F, -v n=19 '
	NR > 1 { for (i = 3; i <= 14; i++) { d = $i - $(i + n); if (d < 0) d = -d
		a = $i < 0 ? -$i : $i
		if (d > 1e-9 + 1e-5 * a) { print "    line " NR " column " i ": " $i " vs " $(i + n); bad = 1; exit } } }
	END { exit bad }'; then
	ok "tracked and untracked runs give the same telemetry"; else bad "tracked and untracked runs give the same telemetry"; fi
expect "run verifying every tracked answer" 0 "$bin" "$tmp/verify.yaml" --virtual-time --duration-s 3 \
	--summary-json "$tmp/verify.json"
check "verify_every 1: verified ($(sub "$tmp/verify.json" tracking verifications)), no disagreement" \
	"$(sub "$tmp/verify.json" tracking verifications) > 1000 && $(sub "$tmp/verify.json" tracking disagreements) == 0"
check "verify_every 1: no allocation after setup" "$(num "$tmp/verify.json" allocations_after_setup) == 0"

# Safety: a velocity limit below the hand's speed trips safe state; from
# then on every force sent is zero (no auto re-arm).
absolute "$good" | sed 's/velocity_limit_m_per_s: .*/velocity_limit_m_per_s: 0.05/' >"$tmp/slow.yaml"
expect "velocity-limit run" 0 "$bin" "$tmp/slow.yaml" --virtual-time --duration-s 2 \
	--summary-json "$tmp/slow.json" --telemetry "$tmp/slow.csv"
check "velocity limit trips safe state" "$(num "$tmp/slow.json" safe_state_trips) >= 1"
if grep -q '"velocity_limit": [1-9]' "$tmp/slow.json"; then ok "velocity_limit fault counted"; else bad "velocity_limit fault counted"; fi
check "zero force after the trip" \
	"$(awk -F, 'NR > 1 && $16 == 1 { s = 1 } s && $12 != 0 { n++ } END { print n + 0 }' "$tmp/slow.csv") == 0"
if grep -q "SAFE STATE" "$tmp/err"; then ok "status line shows safe state"; else bad "status line shows safe state"; fi

# Scene errors are reported like config errors, with their place.
absolute "$good" | sed 's|scenes/knob.stl|scenes/knob-missing.stl|' >"$tmp/noscene.yaml"
expect "run with a missing scene file" 1 "$bin" "$tmp/noscene.yaml" --virtual-time --duration-s 1
if grep -q "^$tmp/noscene.yaml:[0-9]*:[0-9]*: scene.models\[1\].file: .*knob-missing.stl" "$tmp/err"; then
	ok "missing scene file placed"; else bad "missing scene file placed"; fi

# The fault campaign: every kind injected; the loop trips and re-arms.
fj="$tmp/haptic_faults.json"
if [ -s "$fj" ]; then
	check "faults: safe state entered" "$(num "$fj" safe_state_trips) >= 3"
	for k in drop delay duplicate corrupt stuck nan unplug; do
		if grep -q "{\"kind\": \"$k\", \"device\": \"haptic\"" "$fj"; then ok "faults: $k reported"; else bad "faults: $k reported"; fi
	done
	for k in estop:io overrun:loop; do
		if grep -q "{\"kind\": \"${k%%:*}\", \"device\": \"${k#*:}\"" "$fj"; then ok "faults: $k reported"; else bad "faults: $k reported"; fi
	done
	for k in delay stuck nan unplug estop overrun; do
		after=$(sed -n "s/.*\"kind\": \"$k\".*\"safe_after_ns\": \(-\{0,1\}[0-9]*\)}.*/\1/p" "$fj")
		check "faults: $k trips safe state within 100 ms ($after ns)" "$after >= 0 && $after <= 100000000"
	done
	check "faults: corrupt reports counted" "$(num "$fj" device_decode) > 0"
	check "faults: zero force whenever in safe state" \
		"$(awk -F, 'NR > 1 && $16 == 1 && $12 != 0 { n++ } END { print n + 0 }' "$tmp/haptic_faults.csv") == 0"
else
	bad "faults: the shipped fault campaign ran"
fi
printf 'devices:\n  - {name: pen, backend: sim}\nsim:\n  faults:\n    - {device: pem, kind: delay, start_ns: 0, duration_ns: 10}\n    - {device: pen, kind: jam, start_ns: 0, duration_ns: 10}\n' >"$tmp/badfault.yaml"
expect "--check on bad faults" 1 "$bin" --check "$tmp/badfault.yaml"
has "fault without delay_ns" "$tmp/err" "$tmp/badfault.yaml:5:7: sim.faults[0].delay_ns: missing or zero for kind 'delay'"
has "fault on an unknown device" "$tmp/err" "$tmp/badfault.yaml:5:16: sim.faults[0].device: no device named 'pem' in devices"
has "unknown fault kind" "$tmp/err" "$tmp/badfault.yaml:6:27: sim.faults[1].kind: unknown value 'jam' (expected one of: drop, delay, duplicate, corrupt, stuck, nan, unplug, bus_off, estop, overrun)"
expect "--fault on a device that cannot take it" 2 "$bin" "$good" --virtual-time --duration-s 1 --fault bus_off,haptic,1,1
has "--fault misfit named" "$tmp/err" "proxima-run: --fault bus_off,haptic,1,1: a simulated haptic or pose device takes drop, delay, duplicate, corrupt, stuck, nan or unplug"
expect "--fault malformed" 2 "$bin" "$good" --virtual-time --duration-s 1 --fault nan,haptic
expect "--fault delay without DELAY_S" 2 "$bin" "$good" --virtual-time --duration-s 1 --fault delay,haptic,1,1
for k in faults device kind start_ns duration_ns probability delay_ns drop delay duplicate corrupt stuck nan unplug bus_off estop overrun; do
	grep -qF "\`$k\`" docs/config.md || { echo "    docs/config.md lacks \`$k\`"; bad "sim keys documented"; }
done
ok "sim keys documented (checked above)"

# Collision avoidance over CANopen on the simulated bus: the arm is kept
# outside the protective distance, and the avoidance had to act.
aj="$tmp/can_avoid_sim.json"
if [ -s "$aj" ]; then
	check "avoidance: min clearance $(num "$aj" min_clearance_m) >= protective $(num "$aj" protective_distance_m)" \
		"$(num "$aj" min_clearance_m) >= $(num "$aj" protective_distance_m)"
	check "avoidance: the speed was scaled down" "$(num "$aj" min_speed_scale) < 1"
	check "avoidance: no safe state" "$(num "$aj" safe_state_trips) == 0"
	# telemetry and plot: clearance, speed scale, commanded velocities
	ac="$tmp/can_avoid_sim.csv"
	if head -n 1 "$ac" | grep -q ',queries,speed_scale,qdot0_rad_per_s,qdot1_rad_per_s,qdot2_rad_per_s,qdot3_rad_per_s,qdot4_rad_per_s,qdot5_rad_per_s$'; then
		ok "avoidance: CSV has speed scale and joint velocity columns"; else bad "avoidance: CSV has speed scale and joint velocity columns"; fi
	check "avoidance: CSV speed scale matches the summary's minimum" \
		"$(awk -F, 'NR > 1 && (m == "" || $20 < m) { m = $20 } END { print m + 0 }' "$ac") >= $(num "$aj" min_speed_scale) - 1e-6 && $(awk -F, 'NR > 1 && (m == "" || $20 < m) { m = $20 } END { print m + 0 }' "$ac") < 1"
	check "avoidance: the base joint was commanded" \
		"$(awk -F, 'NR > 1 { v = $21 < 0 ? -$21 : $21; if (v > m) m = v } END { print m + 0 }' "$ac") > 0.1"
	for w in "clearance (mm)" "speed scale" "commanded velocity (rad/s)" "joint 5"; do
		if grep -qF "$w" "$tmp/can_avoid_sim_time.svg"; then ok "avoidance plot: $w"; else bad "avoidance plot: $w"; fi
	done
else
	bad "avoidance: the shipped demo ran"
fi
# The same arm without the pillar's influence: a pillar in the sweep with
# protective distance 0.2 m; the arm still stays outside it.
sed 's/protective_distance_m: 0.05/protective_distance_m: 0.2/; s/influence_distance_m: 0.25/influence_distance_m: 0.4/' \
	config/examples/can_avoid_sim.yaml >"$tmp/avoid2.yaml"
expect "avoidance with a larger protective distance" 0 "$bin" "$tmp/avoid2.yaml" --virtual-time \
	--duration-s 3 --summary-json "$tmp/avoid2.json" --telemetry "$tmp/avoid2.csv"
check "avoidance: clearance $(num "$tmp/avoid2.json" min_clearance_m) >= 0.2 - 1 mm" \
	"$(num "$tmp/avoid2.json" min_clearance_m) >= 0.199"
# sim.spawn_arm must name a unix-socket CANopen device proxima-simarm can play
sed 's/spawn_arm: arm/spawn_arm: nope/' config/examples/can_avoid.yaml >"$tmp/spawn1.yaml"
expect "--check: spawn_arm on an unknown device" 1 "$bin" --check "$tmp/spawn1.yaml"
if grep -q "^$tmp/spawn1.yaml:[0-9]*:[0-9]*: sim.spawn_arm: no device named 'nope' in devices" "$tmp/err"; then
	ok "spawn_arm error placed"; else bad "spawn_arm error placed"; fi
# proxima-simarm takes the drive table from the config: any table the
# master takes is fine; an in-process bus (transport sim) is not reachable
sed 's/{node_id: 2, mode: csv, joint: 1, counts_per_unit: 100000}/{node_id: 9, mode: csv, joint: 1}/' \
	config/examples/can_avoid.yaml >"$tmp/spawn2.yaml"
expect "--check: spawn_arm on drives other than proxima-simarm's defaults" 0 "$bin" --check "$tmp/spawn2.yaml"
sed 's/transport: unix/transport: sim/; /socket_path:/d' config/examples/can_avoid.yaml >"$tmp/spawn3.yaml"
expect "--check: spawn_arm on an in-process bus" 1 "$bin" --check "$tmp/spawn3.yaml"
if grep -q "sim.spawn_arm: 'arm' is not a socketcan device with transport unix and canopen drives" "$tmp/err"; then
	ok "spawn_arm transport named"; else bad "spawn_arm transport named"; fi
# can_sim.yaml maps its PDOs and numbers its drives unlike proxima-simarm's
# defaults: its run above enabled the drives only because the arm read
# the same file (--config); the arm process was started that way.
if grep -q 'rpdo:' config/examples/can_sim.yaml && grep -q 'node_id: 11' config/examples/can_sim.yaml; then
	ok "can_sim.yaml has a non-default PDO mapping and drive table"; else bad "can_sim.yaml has a non-default PDO mapping and drive table"; fi
for k in nominal joint amplitude_rad_per_s frequency_hz phase_rad spawn_arm; do
	grep -qF "\`$k\`" docs/config.md || { echo "    docs/config.md lacks \`$k\`"; bad "nominal keys documented"; }
done

# Device-level keys (devices[]: sim.faults, socketcan.faults with
# node_id, stuck_limit) reach the devices proxima-run makes itself: each
# shows in the summary's fault counts without any sim.faults campaign.
absolute "$good" | sed '/^      kind: haptic$/a\      faults: [{kind: nan, start_ns: 1_000_000_000, duration_ns: 200_000_000}]' >"$tmp/dnan.yaml"
expect "device-level nan fault run" 0 "$bin" "$tmp/dnan.yaml" --virtual-time --duration-s 2 \
	--summary-json "$tmp/dnan.json" --telemetry "$tmp/d.csv"
check "devices[].sim.faults nan counted ($(num "$tmp/dnan.json" device_non-finite))" \
	"$(num "$tmp/dnan.json" device_non-finite) > 0 && $(num "$tmp/dnan.json" faults_injected) == 0"
check "devices[].sim.faults nan trips safe state" "$(num "$tmp/dnan.json" safe_state_trips) >= 1"
for sl in 0 20; do
	absolute "$good" | sed 's/position_noise_m: .*/position_noise_m: 0/' |
		sed '/^      kind: haptic$/a\      faults: [{kind: stuck, start_ns: 1_000_000_000, duration_ns: 200_000_000}]' |
		sed "/^  - name: haptic\$/a\    stuck_limit: $sl" >"$tmp/dst$sl.yaml"
	expect "device-level stuck fault, stuck_limit $sl" 0 "$bin" "$tmp/dst$sl.yaml" --virtual-time \
		--duration-s 2 --summary-json "$tmp/dst$sl.json" --telemetry "$tmp/d.csv"
done
check "stuck_limit 0: a noiseless frozen sensor goes unseen" "$(num "$tmp/dst0.json" device_stuck) == 0"
check "stuck_limit 20: the frozen sensor is caught" "$(num "$tmp/dst20.json" device_stuck) >= 1"
# min_report_interval_ns: a device at rest sends the same report every
# 1 ms; with the key above that period they count as duplicates.
for mi in 0 5_000_000; do
	absolute "$good" | sed 's/position_noise_m: .*/position_noise_m: 0/; s/amplitude_m: [0-9.]*/amplitude_m: 0/g' |
		sed "/^  - name: haptic\$/a\    min_report_interval_ns: $mi" >"$tmp/dmr.yaml"
	expect "device at rest, min_report_interval_ns $mi" 0 "$bin" "$tmp/dmr.yaml" --virtual-time \
		--duration-s 1 --summary-json "$tmp/dmr$mi.json" --telemetry "$tmp/d.csv"
done
check "min_report_interval_ns 0 (half the report period): no duplicate" "$(num "$tmp/dmr0.json" device_duplicate) == 0"
check "min_report_interval_ns 5 ms: the repeated reports are duplicates ($(num "$tmp/dmr5_000_000.json" device_duplicate))" \
	"$(num "$tmp/dmr5_000_000.json" device_duplicate) > 100"
sed '/^      kind: gpio$/a\      faults: [{kind: estop, start_ns: 1_000_000_000, duration_ns: 300_000_000}]' \
	config/examples/can_avoid_sim.yaml >"$tmp/dge.yaml"
expect "device-level e-stop on simulated lines" 0 "$bin" "$tmp/dge.yaml" --virtual-time --duration-s 2 \
	--summary-json "$tmp/dge.json" --telemetry "$tmp/d.csv"
check "devices[].sim.faults estop pressed ($(num "$tmp/dge.json" estop_presses))" \
	"$(num "$tmp/dge.json" estop_presses) == 1 && $(num "$tmp/dge.json" safe_state_trips) >= 1"
sed '/^      canopen:$/i\      faults: [{kind: estop, node_id: 2, start_ns: 1_000_000_000, duration_ns: 300_000_000}]' \
	config/examples/can_avoid_sim.yaml >"$tmp/ddr.yaml"
expect "device-level drive fault (node_id) on the in-process arm" 0 "$bin" "$tmp/ddr.yaml" --virtual-time \
	--duration-s 2 --summary-json "$tmp/ddr.json" --telemetry "$tmp/d.csv"
check "socketcan.faults node_id 2: the drive faulted ($(num "$tmp/ddr.json" drive_problem_cycles) cycles)" \
	"$(num "$tmp/ddr.json" drive_problem_cycles) > 0 && $(num "$tmp/ddr.json" safe_state_trips) >= 1"
check "the same run without it has no drive problem" "$(num "$tmp/can_avoid_sim.json" drive_problem_cycles) == 0"

echo "$name: $pass passed, $fail failed, $skip skipped"
[ "$fail" -eq 0 ]
