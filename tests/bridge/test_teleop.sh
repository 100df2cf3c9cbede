#!/bin/sh
# Teleoperation end to end on loopback (real Cyclone DDS, real clock):
# the two example configs (config/examples/teleop_master.yaml and
# teleop_follower.yaml) as two proxima-run processes, on a DDS domain and
# namespace of this run alone.
#  1. both run 2.5 s: the follower's tool tracks twice the master's
#     displacement within 50 mm (rms within 30 mm; the stated error of
#     docs/bridge.md), forces come back, both loops' threads make no heap
#     call after setup with the link running (the tests' allocation
#     counter, preloaded), the master never enters safe state; a flood of
#     200 non-finite or out-of-range parameter sets is refused and
#     counted, a valid one after it applied;
#  2. the master killed (SIGKILL) mid-run: the follower latches safe state
#     with its input silent for its 100 ms timeout (plus a cycle), and
#     stays there after the run;
#  3. the follower killed: the same on the master's remote force.
# Every wait is bounded. Prints a harness-style summary line.
# PX_TEST_NEEDS: libyaml cyclonedds libxml2 (tests/run.sh skips it in builds without)
set -u
name=test_teleop
b=${BUILD:-build}
bin="$b/bin/proxima-run"
tmp=$(mktemp -d)
pids=
trap 'for p in $pids; do kill "$p" 2>/dev/null; done; rm -rf "$tmp"' EXIT
. tests/bridge/common.sh
if [ ! -x "$bin" ]; then
	echo "skip: $bin not built"
	echo "$name: 0 passed, 0 failed, 1 skipped"
	exit 0
fi

domain=$(( $$ % 200 + 20 ))
ns="pxtele_$$"
# the configs with this run's domain, namespace, output files; relative
# paths (the URDF) resolve against the config's directory
for side in master follower; do
	sed -e "s|^  domain_id: 0|  domain_id: $domain|" \
	    -e "s|^      namespace: teleop|      namespace: $ns|" \
	    -e "s|^  namespace: teleop/|  namespace: $ns/|" \
	    -e "s|^  file: build/telemetry-teleop-$side.csv|  file: $tmp/$side.csv|" \
	    -e "s|connect_timeout_ns: .*|connect_timeout_ns: 20_000_000_000|" \
	    config/examples/teleop_$side.yaml >config/examples/.teleop_$side.$$.yaml
done
trap 'for p in $pids; do kill "$p" 2>/dev/null; done; rm -rf "$tmp" config/examples/.teleop_*.$$.yaml' EXIT
M=config/examples/.teleop_master.$$.yaml
F=config/examples/.teleop_follower.$$.yaml

# run SIDE DURATION: in the background, its pid in $last
run() {
	env LD_PRELOAD="$preload" "$bin" "$([ "$1" = master ] && echo "$M" || echo "$F")" \
		--duration-s "$2" --summary-json "$tmp/$1.json" >"$tmp/$1.out" 2>&1 &
	last=$!
	pids="$pids $last"
}

# 1. both sides, the master ending first; meanwhile a flood of bad
# parameter sets, then one good one, at the master
rm -f "$tmp"/*.json
run follower 3.5; fp=$last
run master 2.5; mp=$last
PX_BRIDGE_TEST_ROLE="params:$domain:$ns/master/params:200" "$b/tests/test_bridge" >"$tmp/flood.out" 2>&1
floodrc=$?
PX_BRIDGE_TEST_ROLE="params:$domain:$ns/master/params:0" "$b/tests/test_bridge" >"$tmp/good.out" 2>&1
goodrc=$?
wait "$mp"; mrc=$?
wait "$fp"; frc=$?
pids=
check "master and follower ran (exit $mrc, $frc)" "$mrc == 0 && $frc == 0"
if [ -s "$tmp/follower.json" ] && [ -s "$tmp/master.json" ]; then
	fj="$tmp/follower.json" mj="$tmp/master.json"
	e=$(num "$fj" follow_error_max_m) r=$(num "$fj" follow_error_rms_m) n=$(num "$fj" follow_cycles)
	check "the follower followed for over 1.5 s ($n cycles)" "$n > 1500"
	check "the follower's tool within 50 mm of its target (max $e m)" "$e < 0.05"
	check "... rms within 30 mm ($r m)" "$r < 0.03"
	check "the follower read the master's poses ($(num "$fj" samples_in))" "$(num "$fj" samples_in) > 1500"
	check "the master read the follower's forces ($(num "$mj" samples_in))" "$(num "$mj" samples_in) > 1500"
	check "a force came back (max $(num "$mj" max_force_n) N)" "$(num "$mj" max_force_n) > 0.1"
	check "the master never entered safe state" "$(num "$mj" safe_state_trips) == 0"
	check "200 bad parameter sets sent, one good one (exit $floodrc, $goodrc)" "$floodrc == 0 && $goodrc == 0"
	check "bad parameter sets refused and counted ($(num "$mj" params_refused) of 200)" \
		"$(num "$mj" params_refused) >= 100 && $(num "$mj" params_refused) <= 200"
	check "only the good set accepted and applied ($(num "$mj" params_accepted), $(num "$mj" params_applied))" \
		"$(num "$mj" params_accepted) == 1 && $(num "$mj" params_applied) == 1"
	check "no reliable-topic loss, best-effort loss counted ($(num "$fj" lost), $(num "$mj" lost))" \
		"$(num "$fj" lost) >= 0 && $(num "$mj" lost) >= 0"
	for j in "$mj" "$fj"; do
		a=$(num "$j" allocations_after_setup)
		check "$(basename "$j" .json): no heap call in the loop's thread with the link running ($a)" "$a == 0"
	done
	check "the master's end latched the follower's safe state ($(str "$fj" link_lost))" "\"$(str "$fj" link_lost)\" == \"true\""
else
	bad "summary JSONs written"
fi

# 2, 3. kill one side after 1.5 s: the other latches safe state with its
# remote input silent for its timeout (100 ms) and a cycle or two
for victim in master follower; do
	other=$([ $victim = master ] && echo follower || echo master)
	rm -f "$tmp"/*.json
	run follower 3; fp=$last
	run master 3; mp=$last
	sleep 1.5
	if [ $victim = master ]; then kill -KILL "$mp"; else kill -KILL "$fp"; fi
	wait "$mp"; wait "$fp"
	pids=
	j="$tmp/$other.json"
	if [ -s "$j" ]; then
		s=$(num "$j" link_silent_ns)
		check "$victim killed: the $other latched safe state ($(str "$j" link_lost))" "\"$(str "$j" link_lost)\" == \"true\" && $(num "$j" safe_state_trips) >= 1"
		check "... within its 100 ms timeout (input silent $s ns)" "$s >= 100000000 && $s <= 103000000"
		check "... and stayed there: in safe state at the end" "$(grep -c 'in safe state at the end' "$tmp/$other.out") == 1"
	else
		bad "$victim killed: the $other's summary JSON written"
	fi
done
echo "$name: $pass passed, $fail failed, $skip skipped"
[ "$fail" -eq 0 ]
