#!/bin/sh
# The fault campaign: every fault kind (drop, delay, duplicate, corrupt,
# stuck, nan, unplug/replug, bus_off, estop, overrun) injected with
# proxima-run --fault into every shipped scenario that runs in virtual
# time, where the scenario has a device that takes it. Each run is
# checked: exit 0; the commanded force never above the clamp; safe state
# within one cycle of every watchdog trip; no NaN or infinity reaching an
# output; telemetry records plus drops adding up to the cycles; the loop's
# phase kept (last deadline = first + (cycles - 1 + missed periods) x
# period). Prints a table of what the safety layer did. Then each run
# again, stopped by a signal at a seeded random cycle: every time zero
# force, relays off and drives disabled at the end.
# PX_TEST_NEEDS: libyaml (tests/run.sh skips it in builds without)
set -u
name=test_fault_campaign
bin="${BUILD:-build}/bin/proxima-run"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
pass=0 fail=0 skip=0
ok() { pass=$((pass + 1)); }
bad() { echo "FAIL $1"; sed 's/^/    /' "$tmp/err" 2>/dev/null | head -n 5; fail=$((fail + 1)); }
if [ ! -x "$bin" ]; then
	echo "skip: $bin not built"
	echo "$name: 0 passed, 0 failed, 1 skipped"
	exit 0
fi
num() { sed -n "s/.*\"$2\": \(-\{0,1\}[0-9][0-9.e+-]*\).*/\1/p" "$1" | head -n 1; }
check() { if awk "BEGIN { exit !($2) }"; then ok; else echo "    false: $2"; bad "$1"; fi; }

# target CONFIG KIND: the devices of the scenario that take the fault kind
# (none: not applicable). Faults start at 1 s and last 0.5 s (delay:
# reports held 30 ms; overrun: each compute 3 ms long).
target() {
	case "$(basename "$1" .yaml):$2" in
	can_avoid_sim:estop) echo "io arm" ;; # the e-stop; drive 0 faults
	haptic_*:drop | haptic_*:delay | haptic_*:duplicate | haptic_*:corrupt | \
		haptic_*:stuck | haptic_*:nan | haptic_*:unplug) echo haptic ;;
	can_avoid_sim:drop | can_avoid_sim:duplicate | can_avoid_sim:corrupt | \
		can_avoid_sim:bus_off | can_avoid_sim:unplug) echo arm ;;
	*:estop) echo io ;;
	*:overrun) echo loop ;;
	*) echo "" ;;
	esac
}

kinds="drop delay duplicate corrupt stuck nan unplug bus_off estop overrun"
scenarios=""
for f in config/examples/*.yaml; do
	# the scenarios that run in virtual time (no hardware, no second process)
	grep -qE 'backend: (hidapi|libusb|gpiod|dds)|transport: (kernel|unix)' "$f" && continue
	scenarios="$scenarios $f"
done
printf '%-16s %-9s %-7s %6s %7s %5s %7s %7s %9s %s\n' scenario kind device trips faults \
	"F max" "trip>safe" dropped "phase_ns" "reaction (loop faults by cause)"
runs=0
for f in $scenarios; do
	base=$(basename "$f" .yaml)
	for k in $kinds; do
		devs=$(target "$f" "$k")
		if [ -z "$devs" ]; then
			printf '%-16s %-9s %-7s %s\n' "$base" "$k" "-" "n/a (no device of this scenario takes it)"
			continue
		fi
		for dev in $devs; do
		extra=""
		[ "$k" = delay ] && extra=",1,0.03"
		[ "$k" = overrun ] && extra=",1,0.003"
		j="$tmp/$base-$k-$dev.json"
		"$bin" "$f" --virtual-time --duration-s 3 --fault "$k,$dev,1,0.5$extra" \
			--summary-json "$j" --telemetry "$tmp/$base-$k.csv" >"$tmp/out" 2>"$tmp/err"
		rc=$?
		runs=$((runs + 1))
		if [ "$rc" -ne 0 ] || [ ! -s "$j" ]; then bad "$base/$k@$dev: run (exit $rc)"; continue; fi
		ok
		trips=$(num "$j" safe_state_trips) fmax=$(num "$j" max_force_n)
		clamp=$(num "$j" force_clamp_n) t2s=$(num "$j" max_trip_to_safe_cycles)
		checked=$(num "$j" watchdog_trips_checked) nf=$(num "$j" nonfinite_outputs)
		rec=$(num "$j" telemetry_records) drop=$(num "$j" telemetry_dropped)
		cyc=$(num "$j" cycles) dec=$(num "$j" telemetry_decimation)
		phase=$(num "$j" phase_error_ns) injected=$(num "$j" faults_injected)
		react=$(sed -n 's/.*"faults": {\(.*\)},$/\1/p' "$j" | tr -d '"' | tr ',' '\n' |
			sed 's/^ *//' | grep -v ': 0$' | tr '\n' ' ')
		printf '%-16s %-9s %-7s %6s %7s %5.2f %7s %7s %9s %s\n' "$base" "$k" "$dev" "$trips" \
			"$(num "$j" faults_popped)" "$fmax" "$t2s" "$drop" "$phase" "$react"
		check "$base/$k@$dev: the fault was injected ($injected)" "$injected >= 1"
		if [ "$clamp" != "0" ]; then
			check "$base/$k@$dev: force $fmax within the clamp $clamp" "$fmax <= $clamp + 1e-9"
		fi
		check "$base/$k@$dev: safe state within one cycle of each of $checked trips ($t2s)" "$t2s <= 1"
		check "$base/$k@$dev: no NaN or infinity reached an output ($nf)" "$nf == 0"
		check "$base/$k@$dev: telemetry $rec records + $drop dropped = cycles $cyc / $dec" \
			"$rec + $drop == int(($cyc + $dec - 1) / $dec)"
		check "$base/$k@$dev: phase kept ($phase ns)" "$phase == 0"
		# faults that must end in safe state (the device goes silent,
		# frozen, non-finite, or the e-stop is pressed)
		case "$k:$dev" in
		delay:haptic | stuck:haptic | nan:haptic | unplug:haptic | estop:io | estop:arm | \
			unplug:arm | bus_off:arm | drop:arm | overrun:loop)
			check "$base/$k@$dev: safe state entered" "$trips >= 1" ;;
		esac
		done
	done
done
check "the campaign ran ($runs runs)" "$runs >= 20"

# "Stop now" at random cycles under every fault kind: the same runs ended
# by a signal (PX_RUN_STOP_AT=CYCLE:SIGNAL, the real signal path) at a
# seeded random cycle, half of them inside the fault window (1.0-1.5 s).
# Every time the machine must end with zero force and enable off on the
# force sink, the relay off and every drive disabled, confirmed.
# PX_CAMPAIGN_SEED repeats a campaign.
seed=${PX_CAMPAIGN_SEED:-$(date +%s)}
echo "stop now: seed $seed (PX_CAMPAIGN_SEED=$seed repeats it)"
sigs="INT TERM HUP QUIT USR1 USR2 PIPE ALRM"
stops=0
for f in $scenarios; do
	base=$(basename "$f" .yaml)
	for k in $kinds; do
		for dev in $(target "$f" "$k"); do
			extra=""
			[ "$k" = delay ] && extra=",1,0.03"
			[ "$k" = overrun ] && extra=",1,0.003"
			set -- $(awk -v s="$seed" -v n="$stops" -v ns="$(echo $sigs | wc -w)" 'BEGIN {
				srand(s + n * 7919)
				c = rand() < 0.5 ? 1000 + int(rand() * 500) : 1 + int(rand() * 2998)
				print c, 1 + int(rand() * ns) }')
			cyc=$1 sig=$(echo $sigs | cut -d' ' -f"$2")
			j="$tmp/stop-$base-$k-$dev.json"
			PX_RUN_STOP_AT="$cyc:$sig" "$bin" "$f" --virtual-time --duration-s 3 \
				--fault "$k,$dev,1,0.5$extra" --summary-json "$j" \
				--telemetry "$tmp/stop.csv" >"$tmp/out" 2>"$tmp/err"
			rc=$?
			stops=$((stops + 1))
			what="stop now $base/$k@$dev at cycle $cyc by SIG$sig"
			if [ "$rc" -ne 0 ] || [ ! -s "$j" ]; then bad "$what: run (exit $rc)"; continue; fi
			check "$what: stopped there ($(num "$j" cycles) cycles)" "$(num "$j" cycles) == $cyc"
			if grep -qF "\"shutdown_reason\": \"SIG$sig\"" "$j"; then ok; else bad "$what: ended by SIG$sig"; fi
			check "$what: shutdown confirmed safe" "$(num "$j" shutdown_safe) == 1"
			check "$what: force zeroed on $(num "$j" force_zeroed) of $(num "$j" force_devices)" \
				"$(num "$j" force_zeroed) == $(num "$j" force_devices)"
			check "$what: relays off on $(num "$j" relays_off) of $(num "$j" relay_devices)" \
				"$(num "$j" relays_off) == $(num "$j" relay_devices)"
			check "$what: $(num "$j" drives_disabled) of $(num "$j" shutdown_drives) drives disabled" \
				"$(num "$j" drives_disabled) == $(num "$j" shutdown_drives)"
			# what the simulated devices last received
			if grep -q '"last_force_n"' "$j"; then
				if grep -qE '"last_force_n": \[0, 0, 0\], "last_torque_n_m": \[0, 0, 0\], "last_enable": 0, "outputs_safe": 1' "$j"
				then ok; else bad "$what: the haptic device last received zero force"; fi
			fi
			if grep -q '"enable_line"' "$j" && grep -q '"enable_line": 1' "$j"; then
				bad "$what: an enable line left on"; else ok; fi
			if grep -q '"state": "operation enabled"' "$j"; then
				bad "$what: a drive left in operation enabled"; else ok; fi
		done
	done
done
check "stop now ran under every kind ($stops runs)" "$stops >= 20"
echo "$name: $pass passed, $fail failed, $skip skipped"
[ "$fail" -eq 0 ]
