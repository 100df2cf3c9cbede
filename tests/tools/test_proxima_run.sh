#!/bin/sh
# proxima-run's command-line contract: --check on good and bad configs
# (exit status and message format), flag parsing; then every shipped
# config end to end in virtual time (summary JSON, no allocation after
# setup, force within the clamp, CSV and SVG files), reproducibility, the
# heap counter's self-check, safe state on a velocity limit, scene errors;
# outputs that never follow a symlink nor overwrite an input, --check
# running setup's checks, range-checked durations reported as loop and
# wall time, socket paths of which only a stale socket is removed.
# Prints a harness-style summary line.
# PX_TEST_NEEDS: libyaml (tests/run.sh skips it in builds without)
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
# proxima-run counts heap calls with the tests' counter, preloaded as a
# shared object (sanitizer builds link it into the tools instead).
counter_so="${BUILD:-build}/lib/libproxima-alloc-count.so"
if [ "${SAN:-}" != 1 ]; then
	[ -f "$counter_so" ] || { echo "FAIL $counter_so not built"; fail=$((fail + 1)); }
	counter_so="$(cd "$(dirname "$counter_so")" && pwd)/$(basename "$counter_so")"
	export LD_PRELOAD="$counter_so${LD_PRELOAD:+:$LD_PRELOAD}"
fi

# A config with a STEP/IGES part (kind cad) loads in builds with
# OpenCASCADE only, and not under ASan (the reader's global allocations
# show as leaks at exit), and one with a URDF robot needs libxml2 and the
# mesh importer: cad_skip CONFIG sets why and succeeds then.
cad_skip() {
	# a URDF robot with STL links needs libxml2 and the mesh importer
	if grep -qE '^ +urdf: ' "$1" &&
		! { grep -qx '#define PX_HAVE_XML 1' "${BUILD:-build}/gen/px_features.h" &&
		    grep -qx '#define PX_HAVE_ASSIMP 1' "${BUILD:-build}/gen/px_features.h"; }; then
		why="built without libxml2 or assimp (URDF robot)"
		return 0
	fi
	grep -q 'kind: cad' "$1" || return 1
	if ! grep -qx '#define PX_HAVE_OCCT 1' "${BUILD:-build}/gen/px_features.h"; then
		why="built without OpenCASCADE"
	elif [ "${SAN:-}" = 1 ]; then
		why="OpenCASCADE's global allocations show as leaks under ASan"
	else
		return 1
	fi
}

for f in config/examples/*.yaml; do
	if cad_skip "$f"; then
		if [ "$why" = "built without OpenCASCADE" ]; then
			expect "--check $f without OpenCASCADE" 1 "$bin" --check "$f"
			if grep -qF "built without OpenCASCADE" "$tmp/err"; then ok "--check $f says built without OpenCASCADE"
			else bad "--check $f says built without OpenCASCADE"; fi
		fi
		skp "$f: $why"
		continue
	fi
	expect "--check $f" 0 "$bin" --check "$f"
	if [ "$(wc -l <"$tmp/out")" -eq 1 ] &&
		grep -qE "^$f: OK \([0-9]+ devices?, loop period [0-9]+ ns\)\$" "$tmp/out"; then
		ok "one-line OK for $f"; else bad "one-line OK for $f"; fi
	if grep -qE '^ *auto_rearm: *true' "$f" && grep -qE '(name|line): estop' "$f"; then
		# auto re-arm never ends an e-stop's safe state: said, once,
		# at the auto_rearm key
		if [ "$(wc -l <"$tmp/err")" -eq 1 ] && grep -qE "^$f:[0-9]+:[0-9]+: warning: safety\.watchdog\.auto_rearm: true re-arms after other trips, never after the e-stop \(device '[a-z0-9_]+' line '[a-z0-9_]+'\)" "$tmp/err"; then
			ok "--check $f warns that the e-stop needs an explicit re-arm"
		else bad "--check $f warns that the e-stop needs an explicit re-arm"; fi
	elif [ -s "$tmp/err" ]; then echo "    unexpected stderr"; bad "--check $f is quiet on stderr"; else ok "--check $f is quiet on stderr"; fi
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
	"$tmp/bad.yaml:7:14: devices[0].backend: unknown value 'hidraw2' (expected one of: sim, hidapi, libusb, socketcan, gpiod, dds)"
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
	if cad_skip "$f"; then skp "$f runs: $why"; continue; fi
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
	if grep -q 'backend: dds' "$f"; then
		# a peer process over DDS: the real clock only, and its peer
		# (tests/bridge/test_teleop.sh runs the two teleop configs)
		expect "$f: no virtual time with a dds device" 2 "$bin" "$f" --virtual-time --duration-s 1
		expect "$f: --check" 0 "$bin" --check "$f"
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
if grep -q '"allocation_counter": "none"' "$tmp/probe.json"; then
	bad "the heap counter is loaded"; else ok "the heap counter is loaded"; fi
# Without the counter (as installed) the run works and says so.
if [ "${SAN:-}" != 1 ]; then
	expect "run without the heap counter" 0 env -u LD_PRELOAD "$bin" "$good" --virtual-time \
		--duration-s 0.1 --summary-json "$tmp/nocount.json"
	if grep -q '"allocation_counter": "none"' "$tmp/nocount.json" &&
	   grep -q '^  allocations       not counted' "$tmp/out"; then
		ok "without the counter: allocation_counter none, not counted"
	else bad "without the counter: allocation_counter none, not counted"; fi
fi

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

# CAD parts (kind cad, B-rep models) are tracked too: the shipped CAD
# example with the cold switch off (every answer from the stream) and
# every tracked answer checked against the global query.
cad=config/examples/haptic_cad.yaml
if cad_skip "$cad"; then skp "$cad tracked: $why"; else
	sed "s|file: parts/|file: $PWD/config/examples/parts/|; s/^  models:/  tracking: {cold_switch: false, verify_every: 1}\n  models:/" \
		"$cad" >"$tmp/cadtrack.yaml"
	expect "$cad tracked, every answer verified" 0 "$bin" "$tmp/cadtrack.yaml" --virtual-time \
		--duration-s 3 --summary-json "$tmp/cadtrack.json" --telemetry "$tmp/cadtrack.csv"
	check "$cad: a stream for the part" "$(sub "$tmp/cadtrack.json" tracking streams) == 1"
	check "$cad: mostly tracked ($(sub "$tmp/cadtrack.json" tracking tracked) of $(sub "$tmp/cadtrack.json" tracking queries))" \
		"$(sub "$tmp/cadtrack.json" tracking tracked) > $(sub "$tmp/cadtrack.json" tracking queries) / 2"
	check "$cad: verified ($(sub "$tmp/cadtrack.json" tracking verifications)), no disagreement" \
		"$(sub "$tmp/cadtrack.json" tracking verifications) > 1000 && $(sub "$tmp/cadtrack.json" tracking disagreements) == 0"
	check "$cad tracked: no allocation after setup" "$(num "$tmp/cadtrack.json" allocations_after_setup) == 0"
	if grep -qE '^  tracking          1 stream: [0-9]+ answers, [0-9.]+ % tracked' "$tmp/out"; then
		ok "$cad: summary has the tracking line"; else bad "$cad: summary has the tracking line"; fi
fi

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

# ---- outputs never follow a symlink nor overwrite an input -------------
# Every output (CSV, summary JSON, both plots) planted as a symbolic link
# to a victim file: the victim is unchanged, each output is a regular
# file with its content, and no temporary file is left behind.
mkdir -p "$tmp/sl"
printf 'victim\n' >"$tmp/sl/victim"
for o in t.csv t_time.svg t_latency.svg s.json; do ln -s "$tmp/sl/victim" "$tmp/sl/$o"; done
expect "run with every output a symlink to a victim" 0 "$bin" "$good" --virtual-time --duration-s 0.2 \
	--telemetry "$tmp/sl/t.csv" --summary-json "$tmp/sl/s.json"
if [ "$(cat "$tmp/sl/victim")" = victim ]; then ok "symlinked outputs: the victim is unchanged"; else bad "symlinked outputs: the victim is unchanged"; fi
for o in t.csv t_time.svg t_latency.svg s.json; do
	if [ -f "$tmp/sl/$o" ] && [ ! -L "$tmp/sl/$o" ]; then ok "output $o written as a regular file"
	else bad "output $o written as a regular file"; fi
done
if head -n 1 "$tmp/sl/t.csv" | grep -q '^t_s,cycle,' && [ "$(($(wc -l <"$tmp/sl/t.csv") - 1))" -eq 200 ]; then
	ok "symlinked CSV replaced by the telemetry"; else bad "symlinked CSV replaced by the telemetry"; fi
check "symlinked JSON replaced by the summary" "$(num "$tmp/sl/s.json" cycles) == 200"
svg "symlinked time plot replaced by a plot" "$tmp/sl/t_time.svg"
if ls -A "$tmp/sl" | grep -q '\.tmp$'; then bad "no temporary output file left"; else ok "no temporary output file left"; fi
# an output that is the config, or a link to it, or an input file: refused
# before the run, the file unchanged
absolute "$good" >"$tmp/in.yaml"
cp "$tmp/in.yaml" "$tmp/in.keep"
knob=config/examples/scenes/knob.stl
cksum <"$knob" >"$tmp/knob.sum"
expect "--telemetry the config refused" 2 "$bin" "$tmp/in.yaml" --virtual-time --duration-s 0.1 --telemetry "$tmp/in.yaml"
has "--telemetry the config named" "$tmp/err" \
	"proxima-run: --telemetry: $tmp/in.yaml is the config file $tmp/in.yaml (the same file): refusing to write an output over it"
expect "--summary-json the config refused" 2 "$bin" "$tmp/in.yaml" --virtual-time --duration-s 0.1 \
	--telemetry "$tmp/in.csv" --summary-json "$tmp/in.yaml"
expect "--check: --summary-json the config refused" 2 "$bin" --check "$tmp/in.yaml" --summary-json "$tmp/in.yaml"
ln -s "$tmp/in.yaml" "$tmp/in-link.json"
expect "--summary-json a symlink to the config refused" 2 "$bin" "$tmp/in.yaml" --virtual-time --duration-s 0.1 \
	--telemetry "$tmp/in.csv" --summary-json "$tmp/in-link.json"
if grep -qF "$tmp/in-link.json is a symbolic link to the config file $tmp/in.yaml" "$tmp/err"; then ok "symlink to the config named"; else bad "symlink to the config named"; fi
expect "--summary-json a scene file refused" 2 "$bin" "$tmp/in.yaml" --virtual-time --duration-s 0.1 \
	--telemetry "$tmp/in.csv" --summary-json "$PWD/$knob"
if grep -qF "is an input file of the config" "$tmp/err"; then ok "scene file named as an input"; else bad "scene file named as an input"; fi
mkdir -p "$tmp/adir.csv"
expect "--telemetry a directory refused" 2 "$bin" "$tmp/in.yaml" --virtual-time --duration-s 0.1 --telemetry "$tmp/adir.csv"
has "directory output named" "$tmp/err" \
	"proxima-run: --telemetry: $tmp/adir.csv exists and is a directory, not a regular file: refusing to replace it"
sed "s|file: build/telemetry.csv|file: $tmp/in2.yaml|" "$tmp/in.yaml" >"$tmp/in2.yaml"
cp "$tmp/in2.yaml" "$tmp/in2.keep"
expect "--check: telemetry.file the config itself" 1 "$bin" --check "$tmp/in2.yaml"
if grep -qE "^$tmp/in2.yaml:[0-9]+:[0-9]+: telemetry.file: $tmp/in2.yaml is the config file" "$tmp/err"; then
	ok "telemetry.file the config: placed"; else bad "telemetry.file the config: placed"; fi
expect "run: telemetry.file the config itself" 1 "$bin" "$tmp/in2.yaml" --virtual-time --duration-s 0.1
if cmp -s "$tmp/in.yaml" "$tmp/in.keep" && cmp -s "$tmp/in2.yaml" "$tmp/in2.keep" && cksum <"$knob" | cmp -s - "$tmp/knob.sum"; then
	ok "the config and the scene file are unchanged"; else bad "the config and the scene file are unchanged"; fi

# ---- --check runs setup's checks (without opening hardware) -----------
# each: non-zero status and a message with file:line:column
ck() { # DESCRIPTION FILE KEY-REGEX
	expect "--check: $1" 1 "$bin" --check "$2"
	if grep -qE "^$2:[0-9]+:[0-9]+: $3" "$tmp/err"; then ok "--check: $1: placed"; else bad "--check: $1: placed"; fi
	if [ -s "$tmp/out" ]; then bad "--check: $1: no OK line"; else ok "--check: $1: no OK line"; fi
}
absolute "$good" | sed 's/^  models:/  modles:/' >"$tmp/c1.yaml"
ck "misspelt key under scene" "$tmp/c1.yaml" "scene.modles: unknown key"
absolute "$good" | sed 's/pose: {xyz_m: \[-0.035, 0.0, 0.0\]/pose: {xyz_m: [.nan, 0.0, 0.0]/' >"$tmp/c2.yaml"
ck "NaN model pose" "$tmp/c2.yaml" "scene.models\[1\].pose"
absolute "$good" | sed 's|scenes/knob.stl|scenes/knob-missing.stl|' >"$tmp/c3.yaml"
ck "missing scene file" "$tmp/c3.yaml" "scene.models\[1\].file: .*knob-missing.stl"
absolute "$good" | sed 's/scale: 1.2/scale: 0/' >"$tmp/c4.yaml"
ck "zero scale" "$tmp/c4.yaml" "scene.models\[1\].scale"
absolute "$good" | sed 's/^  device: haptic$/  device: io/' >"$tmp/c5.yaml"
ck "control device not a pose device" "$tmp/c5.yaml" "control.device: 'io' \(sim\) is not a pose device"
absolute "$good" | sed 's/^      kind: haptic$/      kind: pose/' >"$tmp/c6.yaml"
ck "control device takes no force" "$tmp/c6.yaml" "control.device: 'haptic' takes no force"
absolute "$good" | sed 's|^  decimation: 1$|  decimation: 1\n  ring_records: 16777216|' >"$tmp/c7.yaml"
ck "ring_records of 16 million (3 GiB)" "$tmp/c7.yaml" "telemetry.ring_records: 16777216 records take 3.[0-9] GiB"
expect "run: ring_records of 16 million refused" 1 "$bin" "$tmp/c7.yaml" --virtual-time --duration-s 0.1
absolute "$good" | sed 's|^  decimation: 1$|  decimation: 1\n  ring_records: 1000000|' >"$tmp/c8.yaml"
expect "--check: ring_records of a million warned" 0 "$bin" --check "$tmp/c8.yaml"
if grep -qE "^$tmp/c8.yaml:[0-9]+:[0-9]+: telemetry.ring_records: warning: 1000000 records take [0-9]+ MiB at setup" "$tmp/err"; then
	ok "large ring_records warned with its place"; else bad "large ring_records warned with its place"; fi
# a simulated device's own refusal (a trajectory file that is not there)
absolute "$good" | sed 's/^        kind: sines$/        kind: csv\n        file: no-such-path.csv/; /^        sines:$/d; /^          - {axis:/d' >"$tmp/c9.yaml"
expect "--check: a simulated device's trajectory file missing" 1 "$bin" --check "$tmp/c9.yaml"
if grep -qE "^$tmp/c9.yaml:[0-9]+:[0-9]+: devices\[0\]\.sim\.trajectory\.file: .*no-such-path.csv" "$tmp/err"; then
	ok "--check: missing trajectory placed"; else bad "--check: missing trajectory placed"; fi
# a hardware device's config refused by px_devcfg without opening it (a
# GPIO line with no role); the chip is never opened
sed 's/name: timing, line_name/name: timer, line_name/' config/examples/can_arm.yaml >"$tmp/c10.yaml"
expect "--check: a gpiod line without a role" 1 "$bin" --check "$tmp/c10.yaml"
if grep -qE "^$tmp/c10.yaml:[0-9]+:[0-9]+: device 'io' \(gpiod, devices\[1\]\.gpiod\.lines\[2\]\): line 'timer' has no role" "$tmp/err"; then
	ok "--check: gpiod line refusal placed"; else bad "--check: gpiod line refusal placed"; fi

# a point cloud whose extent overflows double is refused at setup, by
# --check and by the run alike, at the model's place: it never reaches
# the cycle
printf '1e308 0 0\n-1e308 0 0\n0 1e308 0\n' >"$tmp/big.xyz"
printf 'version: 1\ndevices:\n  - {name: pen, backend: sim}\nscene:\n  models:\n    - {name: cloud, file: big.xyz, kind: cloud}\n' >"$tmp/c11.yaml"
ck "a cloud whose extent overflows" "$tmp/c11.yaml" "scene.models\[0\].file: "
expect "run: a cloud whose extent overflows is refused at setup" 1 "$bin" "$tmp/c11.yaml" --virtual-time \
	--duration-s 0.1 --telemetry "$tmp/c11.csv"
if grep -qE "^$tmp/c11.yaml:[0-9]+:[0-9]+: scene.models\[0\].file: " "$tmp/err" && [ ! -e "$tmp/c11.csv" ]; then
	ok "run: overflowing cloud placed, no telemetry written"; else bad "run: overflowing cloud placed, no telemetry written"; fi

# ---- numeric flags are range-checked; durations reported truthfully ---
for v in 1e300 -1 nan inf 1e9; do
	expect "--duration-s $v refused" 2 "$bin" "$good" --virtual-time --duration-s "$v"
	if grep -q "^usage: proxima-run" "$tmp/err" && grep -q "duration-s: '$v'" "$tmp/err"; then ok "--duration-s $v: usage error"; else bad "--duration-s $v: usage error"; fi
done
# virtual clock: --duration-s runs its cycles; injected slow computes
# make missed periods, so the loop clock covers more than was asked, and
# the summary says so
expect "virtual run with missed periods" 0 "$bin" "$good" --virtual-time --duration-s 1 \
	--fault overrun,loop,0.2,0.1,1,0.005 --summary-json "$tmp/dur.json" --telemetry "$tmp/dur.csv"
check "virtual: 1000 cycles" "$(num "$tmp/dur.json" cycles) == 1000"
check "virtual: periods were missed ($(num "$tmp/dur.json" missed_periods))" "$(num "$tmp/dur.json" missed_periods) > 10"
check "virtual: loop time $(num "$tmp/dur.json" loop_time_s) s = (cycles + missed) x period" \
	"$(num "$tmp/dur.json" loop_time_s) == (1000 + $(num "$tmp/dur.json" missed_periods)) * 0.001"
check "virtual: wall_time_s reported" "\"$(num "$tmp/dur.json" wall_time_s)\" != \"\""
if grep -q '"ended_by": "cycles"' "$tmp/dur.json"; then ok "virtual: ended by its cycles"; else bad "virtual: ended by its cycles"; fi
if grep -qE "^  time              loop clock 1\.[0-9]+ s \([1-9][0-9]* missed periods\), wall [0-9.]+ s; --duration-s 1: ended by cycles$" "$tmp/out"; then
	ok "summary has the time line"; else bad "summary has the time line"; fi
# real clock: the same run ends when its time is up, whatever was missed
absolute "$good" | sed 's/priority: 80/priority: 0/; s/lock_memory: true/lock_memory: false/' >"$tmp/real.yaml"
# (fault windows count from the start of setup, which a sanitizer build
# on a busy machine can stretch past 0.3 s: the window sits late)
expect "real-clock run with missed periods" 0 "$bin" "$tmp/real.yaml" --duration-s 1 \
	--fault overrun,loop,0.6,0.15,1,0.005 --summary-json "$tmp/real.json" --telemetry "$tmp/real.csv"
check "real: periods were missed ($(num "$tmp/real.json" missed_periods))" "$(num "$tmp/real.json" missed_periods) > 10"
check "real: fewer cycles than asked ($(num "$tmp/real.json" cycles))" "$(num "$tmp/real.json" cycles) < 1000"
# (the last cycle may itself skip a period or two on a busy machine; a
# run that counted cycles would end at 1 s + every missed period)
check "real: loop time $(num "$tmp/real.json" loop_time_s) s is the 1 s asked" \
	"$(num "$tmp/real.json" loop_time_s) >= 0.999 && $(num "$tmp/real.json" loop_time_s) < 1.0005 + $(num "$tmp/real.json" missed_periods) * 0.0005"
check "real: wall time $(num "$tmp/real.json" wall_time_s) s close to it" \
	"$(num "$tmp/real.json" wall_time_s) >= 0.99 && $(num "$tmp/real.json" wall_time_s) < 1.5"
if grep -q '"ended_by": "time"' "$tmp/real.json"; then ok "real: ended by its time"; else bad "real: ended by its time"; fi

# ---- socket paths: only a stale socket is ever removed ----------------
# can_avoid.yaml (the arm spawned as a second process, real clock) with
# its socket in $tmp; what is already at the path decides.
sock="$tmp/sk/bus.sock"
mkdir -p "$tmp/sk"
sed "s|socket_path: [^ ]*|socket_path: $sock|; s|device_timeout_ns: .*|device_timeout_ns: 500_000_000|; s|heartbeat_timeout_ns: .*|heartbeat_timeout_ns: 2_000_000_000|; s|file: build/|file: $tmp/sk/|" \
	config/examples/can_avoid.yaml >"$tmp/sk.yaml"
printf 'keep\n' >"$tmp/sk/victim"
for kind in file peer-file dir link; do
	rm -rf "$sock" "$sock.peer"
	case $kind in
	file) printf 'keep\n' >"$sock"; at=$sock what="a regular file" ;;
	peer-file) printf 'keep\n' >"$sock.peer"; at=$sock.peer what="a regular file" ;;
	dir) mkdir "$sock"; at=$sock what="a directory" ;;
	link) ln -s "$tmp/sk/victim" "$sock"; at=$sock what="a symbolic link" ;;
	esac
	expect "socket_path: $kind there: the run refuses" 1 "$bin" "$tmp/sk.yaml" --duration-s 1
	if grep -qF "$at exists and is $what, not a socket: refusing to remove it" "$tmp/err"; then
		ok "socket_path: $kind named"; else bad "socket_path: $kind named"; fi
	case $kind in
	file | peer-file) [ "$(cat "$at")" = keep ] ;;
	dir) [ -d "$sock" ] ;;
	link) [ -L "$sock" ] && [ "$(cat "$tmp/sk/victim")" = keep ] ;;
	esac && ok "socket_path: the $kind survives unchanged" || bad "socket_path: the $kind survives unchanged"
done
rm -rf "$sock" "$sock.peer"
# a stale socket (its process killed) is taken over
sab="$(dirname "$bin")/proxima-simarm"
"$sab" --unix "$sock" "$tmp/sk/nobody" --seconds 30 >/dev/null 2>&1 &
spid=$!
i=0; while [ ! -S "$sock" ] && [ $i -lt 100 ]; do sleep 0.05; i=$((i + 1)); done
kill -9 "$spid" 2>/dev/null; wait "$spid" 2>/dev/null
if [ -S "$sock" ]; then ok "a killed process left a stale socket"; else bad "a killed process left a stale socket"; fi
expect "stale socket taken over" 0 "$bin" "$tmp/sk.yaml" --duration-s 1 --summary-json "$tmp/sk1.json"
check "stale socket: the drives ran over it" "$(num "$tmp/sk1.json" drives_enabled_cycles) > 100"
if [ -e "$sock" ] || [ -e "$sock.peer" ]; then bad "both ends removed their own sockets at the end"; else ok "both ends removed their own sockets at the end"; fi
# two runs on one path: the second is refused, the first's socket
# survives the second's exit and the first runs to its end
"$bin" "$tmp/sk.yaml" --duration-s 4 --summary-json "$tmp/sk2.json" >"$tmp/sk-first.out" 2>"$tmp/sk-first.err" &
fpid=$!
i=0; while ! { [ -S "$sock" ] && [ -S "$sock.peer" ]; } && [ $i -lt 200 ]; do sleep 0.05; i=$((i + 1)); done
expect "a second run on the same socket_path refused" 1 "$bin" "$tmp/sk.yaml" --duration-s 1 --telemetry "$tmp/sk/second.csv"
if grep -qF "$sock is in use: another process is bound to it" "$tmp/err"; then ok "socket in use named"; else bad "socket in use named"; fi
if [ -S "$sock" ] && [ -S "$sock.peer" ]; then ok "the first run's sockets survive the second's exit"; else bad "the first run's sockets survive the second's exit"; fi
wait "$fpid"; frc=$?
check "the first run ends normally (exit $frc)" "$frc == 0"
check "the first run's drives kept running ($(num "$tmp/sk2.json" drives_enabled_cycles) cycles)" \
	"$(num "$tmp/sk2.json" drives_enabled_cycles) > 2000 && $(num "$tmp/sk2.json" drive_problem_cycles) == 0"
# proxima-simarm: the same rules for the .peer end it binds, and its
# numeric flags range-checked
printf 'keep\n' >"$tmp/sk/peerfile"
expect "proxima-simarm refuses a regular file as its socket" 1 "$sab" --unix "$tmp/sk/peerfile" "$tmp/sk/x" --seconds 1
if [ "$(cat "$tmp/sk/peerfile")" = keep ]; then ok "proxima-simarm: the file survives"; else bad "proxima-simarm: the file survives"; fi
for a in "--seconds 1e300" "--seconds nan" "--seconds -1" "--drives 0" "--drives 1x" "--drives 99999999999"; do
	expect "proxima-simarm $a refused" 2 "$sab" --unix "$tmp/sk/y" "$tmp/sk/x" $a
done

# Shutdown: every way a run ends goes through the safe state before the
# devices close. What the simulated devices last received is in the
# JSON's shutdown record: zero force and torque with enable off, the
# enable relay off; the force write that carried it is one more than the
# cycles; CANopen drives end in switch on disabled.
# shut_checks WHAT JSON REASON
shut_checks() {
	sj=$2
	check "$1: shutdown safe" "$(num "$sj" shutdown_safe) == 1"
	if grep -qF "\"shutdown_reason\": \"$3\"" "$sj"; then ok "$1: ended by $3"; else bad "$1: ended by $3"; fi
	w=$(sed -n 's/.*"name": "haptic", "backend": "[a-z-]*", "state": [0-9]*, "reports": [0-9]*, "samples": [0-9]*, "writes": \([0-9]*\).*/\1/p' "$sj")
	check "$1: haptic writes $w = cycles $(num "$sj" cycles) + 1 (the safe output last)" "$w == $(num "$sj" cycles) + 1"
	if grep -qF '{"name": "haptic", "last_force_n": [0, 0, 0], "last_torque_n_m": [0, 0, 0], "last_enable": 0, "outputs_safe": 1}' "$sj"; then
		ok "$1: the haptic device last received zero force, enable off"; else bad "$1: the haptic device last received zero force, enable off"; fi
	if grep -qF '{"name": "io", "enable_line": 0, ' "$sj"; then
		ok "$1: the enable relay is off"; else bad "$1: the enable relay is off"; fi
}
expect "shutdown: run ended by its duration" 0 "$bin" "$good" --virtual-time --duration-s 1 \
	--summary-json "$tmp/sd.json" --telemetry "$tmp/sd.csv"
shut_checks "duration" "$tmp/sd.json" "end of run"
if grep -qE '^  shutdown          safe \(force zeroed on 1/1 device, relay off on 1/1\) after end of run in [0-9.]+ ms$' "$tmp/out"; then
	ok "shutdown line in the summary"; else bad "shutdown line in the summary"; fi
# the run's last telemetry row had force on: the zero came after it
check "the last cycle still commanded force ($(tail -n 1 "$tmp/sd.csv" | cut -d, -f12) N)" \
	"$(tail -n 1 "$tmp/sd.csv" | cut -d, -f12) > 0"
for sig in INT TERM HUP QUIT USR1; do
	PX_RUN_STOP_AT=555:$sig "$bin" "$good" --virtual-time --duration-s 5 --summary-json "$tmp/sd$sig.json" \
		--telemetry "$tmp/sd.csv" >"$tmp/out" 2>"$tmp/err"
	rc=$?
	check "SIG$sig at cycle 555 (virtual): exit $rc, summary and JSON written" \
		"$rc == 0 && $(num "$tmp/sd$sig.json" cycles) == 555"
	shut_checks "SIG$sig" "$tmp/sd$sig.json" "SIG$sig"
	if grep -q "^  shutdown          safe .* after SIG$sig in" "$tmp/out"; then ok "SIG$sig: summary printed"; else bad "SIG$sig: summary printed"; fi
done
# the same signals from outside, on the real clock
for sig in INT TERM HUP; do
	"$bin" "$good" --duration-s 30 --summary-json "$tmp/sr$sig.json" --telemetry "$tmp/sr.csv" \
		>"$tmp/out" 2>"$tmp/err" &
	pid=$!
	sleep 1
	kill -$sig $pid
	wait $pid
	rc=$?
	check "kill -$sig (real clock): exit $rc" "$rc == 0"
	[ -s "$tmp/sr$sig.json" ] || { bad "kill -$sig: summary JSON written"; continue; }
	shut_checks "kill -$sig" "$tmp/sr$sig.json" "SIG$sig"
done
# drives: quick stop, then disabled, confirmed
for how in duration TERM; do
	if [ $how = TERM ]; then export PX_RUN_STOP_AT=1234:TERM; fi
	expect "shutdown of the CANopen arm ($how)" 0 "$bin" config/examples/can_avoid_sim.yaml --virtual-time \
		--duration-s 2 --summary-json "$tmp/sdc.json" --telemetry "$tmp/sdc.csv"
	unset PX_RUN_STOP_AT
	check "CANopen arm ($how): 6 drives disabled" \
		"$(num "$tmp/sdc.json" shutdown_safe) == 1 && $(num "$tmp/sdc.json" drives_disabled) == 6 && $(num "$tmp/sdc.json" shutdown_drives) == 6"
	check "CANopen arm ($how): every drive reports switch on disabled" \
		"$(grep -c '"state": "switch on disabled"' "$tmp/sdc.json") == 6"
	if grep -q "^  drives            6 on 'arm', enabled in [0-9]* cycles, 0 in operation enabled at the end$" "$tmp/out"; then
		ok "CANopen arm ($how): none in operation enabled at the end"; else bad "CANopen arm ($how): none in operation enabled at the end"; fi
done
# a setup error after the devices opened (a HID device after them is
# absent): safe outputs before closing
# the ghost goes last: the sim devices open first
{ absolute "$good" | sed -n '1,/^control:$/p' | sed '$d'
  printf '  - name: ghost\n    backend: hidapi\n    hidapi:\n      vid: 0x1234\n      pid: 0x0fed\n      inputs:\n        - {report_id: 1, byte_offset: 0, bit_width: 32, scale: 1.0e-6, axis: x}\n\n'
  absolute "$good" | sed -n '/^control:$/,$p'; } >"$tmp/late.yaml"
expect "setup error after the devices opened" 1 "$bin" "$tmp/late.yaml" --duration-s 1 \
	--telemetry "$tmp/late.csv"
if grep -qE '^proxima-run: shutdown: safe \(force zeroed on 1/1 device, relay off on 1/1\) after setup error' "$tmp/err"; then
	ok "setup error: outputs made safe before the devices closed"; else bad "setup error: outputs made safe before the devices closed"; fi
# outputs that cannot be confirmed safe: a welded relay at the end
sed '/^      kind: gpio$/a\      faults: [{kind: stuck, start_ns: 500_000_000, duration_ns: 5_000_000_000}]' \
	"$good" | sed "s|file: scenes/|file: $PWD/config/examples/scenes/|" >"$tmp/weld.yaml"
expect "a relay that does not drop: exit 1" 1 "$bin" "$tmp/weld.yaml" --virtual-time --duration-s 1 \
	--summary-json "$tmp/weld.json" --telemetry "$tmp/weld.csv"
if grep -qE "^proxima-run: shutdown: NOT SAFE \(force zeroed on 1/1 device, relay off on 0/1\) after end of run in [0-9.]+ ms: device 'io': relay off not confirmed" "$tmp/err"; then
	ok "the welded relay named"; else bad "the welded relay named"; fi
check "JSON: shutdown not safe" "$(num "$tmp/weld.json" shutdown_safe) == 0"
# e-stop released with auto_rearm: the loop stays in safe state, relay
# off, no force, until the end (an explicit re-arm is needed)
absolute "$good" | sed 's/auto_rearm: false/auto_rearm: true/' >"$tmp/rearm.yaml"
grep -q 'auto_rearm: true' "$tmp/rearm.yaml" || bad "auto_rearm set in the test config"
expect "--check warns: auto_rearm with an e-stop" 0 "$bin" --check "$tmp/rearm.yaml"
if grep -qE "^$tmp/rearm.yaml:[0-9]+:[0-9]+: warning: safety.watchdog.auto_rearm: true re-arms after other trips, never after the e-stop \(device 'io' line 'estop'\)" "$tmp/err"; then
	ok "--check names the auto_rearm key and the e-stop line"; else bad "--check names the auto_rearm key and the e-stop line"; fi
expect "e-stop pressed 1.0-1.2 s with auto_rearm" 0 "$bin" "$tmp/rearm.yaml" --virtual-time --duration-s 3 \
	--fault estop,io,1,0.2 --summary-json "$tmp/rearm.json" --telemetry "$tmp/rearm.csv"
check "released e-stop: still in safe state at the end" "$(num "$tmp/rearm.json" safe_at_end) == 1"
check "released e-stop: every row from the press on safe with zero force" \
	"$(awk -F, 'NR > 1 && $1 >= 1.01 && ($16 != 1 || $12 != 0) { n++ } END { print n + 0 }' "$tmp/rearm.csv") == 0"
check "released e-stop: rows after the release exist ($(awk -F, 'NR > 1 && $1 >= 1.5' "$tmp/rearm.csv" | wc -l))" \
	"$(awk -F, 'NR > 1 && $1 >= 1.5' "$tmp/rearm.csv" | wc -l) > 1000"
# the same run with a velocity trip re-arms by itself (auto_rearm works)
absolute "$good" | sed 's/auto_rearm: false/auto_rearm: true/; s/velocity_limit_m_per_s: .*/velocity_limit_m_per_s: 0.05/' >"$tmp/rearm2.yaml"
expect "velocity trips with auto_rearm" 0 "$bin" "$tmp/rearm2.yaml" --virtual-time --duration-s 3 \
	--summary-json "$tmp/rearm2.json" --telemetry "$tmp/rearm2.csv"
check "velocity trips re-arm by themselves ($(num "$tmp/rearm2.json" safe_state_trips) trips)" \
	"$(num "$tmp/rearm2.json" safe_state_trips) >= 2"

echo "$name: $pass passed, $fail failed, $skip skipped"
[ "$fail" -eq 0 ]
