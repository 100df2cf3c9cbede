#!/bin/sh
# The fault campaign: every fault kind (drop, delay, duplicate, corrupt,
# stuck, nan, unplug/replug, bus_off, estop, overrun) injected with
# proxima-run --fault into every shipped scenario that runs in virtual
# time, where the scenario has a device that takes it. Each run is
# checked: exit 0; the commanded force never above the clamp; safe state
# within one cycle of every watchdog trip; no NaN or infinity reaching an
# output; telemetry records plus drops adding up to the cycles; the loop's
# phase kept (last deadline = first + (cycles - 1 + missed periods) x
# period). Prints a table of what the safety layer did.
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
	grep -qE 'backend: (hidapi|libusb|gpiod)|transport: (kernel|unix)' "$f" && continue
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
echo "$name: $pass passed, $fail failed, $skip skipped"
[ "$fail" -eq 0 ]
