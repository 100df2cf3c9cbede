#!/bin/sh
# Scene updates over DDS end to end (real Cyclone DDS, real clock,
# loopback): config/examples/can_avoid_dds_cloud.yaml (the URDF arm with
# its obstacle clouds and the post's pose from a dds device) run by
# proxima-run for 3 s beside a second process (test_bridge_scene as the
# perception node, PX_SCENE_TEST_ROLE=cloud:...), on a DDS domain and
# namespace of this run alone:
#  1. a grid of points in the arm's path: it becomes the arm's obstacle
#     (frames swapped in, the clearance below 200 mm), the post's pose
#     is applied, the link holds;
#  2. the same grid far from the arm: the clearance is larger;
#  3. a flood of invalid clouds and poses (wrong frame, fields, sizes,
#     non-finite, outside the workspace, not a rotation) beside the far
#     grid: refused and counted, no pose applied, the clearance that of
#     the far grid, no safe state;
#  4. the node killed mid-run: safe state latched with the cloud silent
#     for the device's 200 ms timeout (plus a cycle or two), kept to
#     the end.
# In every run the loop's thread makes no heap call after setup while
# clouds arrive (the tests' allocation counter, preloaded). Every wait
# is bounded. Prints a harness-style summary line.
# PX_TEST_NEEDS: libyaml cyclonedds libxml2 (tests/run.sh skips it in builds without)
set -u
name=test_scene_run
b=${BUILD:-build}
bin="$b/bin/proxima-run"
node="$b/tests/test_bridge_scene"
tmp=$(mktemp -d)
pids=
. tests/bridge/common.sh
if [ ! -x "$bin" ] || [ ! -x "$node" ]; then
	echo "skip: $bin or $node not built"
	echo "$name: 0 passed, 0 failed, 1 skipped"
	exit 0
fi

domain=$(( $$ % 200 + 30 ))
ns="pxscene_$$"
# the config with this run's domain, namespace and output; relative
# paths (the URDF) resolve against the config's directory
C=config/examples/.can_avoid_dds_cloud.$$.yaml
trap 'for p in $pids; do kill "$p" 2>/dev/null; done; rm -rf "$tmp" "$C"' EXIT
sed -e "s|^  domain_id: 0|  domain_id: $domain|" \
    -e "s|^      namespace: cell|      namespace: $ns|" \
    -e "s|^  namespace: cell/|  namespace: $ns/|" \
    -e "s|^  file: build/telemetry-avoid-dds-cloud.csv|  file: $tmp/run.csv|" \
    -e "s|connect_timeout_ns: .*|connect_timeout_ns: 20_000_000_000|" \
    config/examples/can_avoid_dds_cloud.yaml >"$C"

# scene KIND: the node publishing KIND (until killed) beside a 3 s run;
# the run's summary in $tmp/KIND.json, the node's pid in $node_pid
scene() {
	PX_SCENE_TEST_ROLE="cloud:$domain:$ns:$1:60" "$node" >"$tmp/node-$1.out" 2>&1 &
	node_pid=$!
	pids="$pids $node_pid"
	env LD_PRELOAD="$preload" "$bin" "$C" --duration-s 3 \
		--summary-json "$tmp/$1.json" >"$tmp/run-$1.out" 2>&1 &
	run_pid=$!
	pids="$pids $run_pid"
}
finish() {
	wait "$run_pid"; rc=$?
	kill "$node_pid" 2>/dev/null; wait "$node_pid" 2>/dev/null
	pids=
}
common() {
	j="$tmp/$2.json"
	check "$1: no heap call in the loop's thread while clouds arrive ($(num "$j" allocations_after_setup))" \
		"$(num "$j" allocations_after_setup) == 0"
}

for kind in near far flood; do
	rm -f "$tmp"/*.out
	scene $kind
	finish
	j="$tmp/$kind.json"
	check "$kind: proxima-run ran 3 s (exit $rc)" "$rc == 0"
	[ -s "$j" ] || { bad "$kind: summary JSON written"; continue; }
	common $kind $kind
	check "$kind: the link held ($(str "$j" link_lost))" "\"$(str "$j" link_lost)\" == \"false\""
	check "$kind: clouds accepted and swapped in ($(num "$j" clouds_accepted), $(num "$j" cloud_swaps))" \
		"$(num "$j" clouds_accepted) > 50 && $(num "$j" cloud_swaps) > 50"
done
n="$tmp/near.json" f="$tmp/far.json" fl="$tmp/flood.json"
if [ -s "$n" ] && [ -s "$f" ] && [ -s "$fl" ]; then
	cn=$(num "$n" min_clearance_m) cf=$(num "$f" min_clearance_m) cl=$(num "$fl" min_clearance_m)
	check "near: the cloud is the arm's obstacle (min clearance $cn m)" "$cn < 0.2"
	check "near: the post's pose applied ($(num "$n" scene_poses_applied))" "$(num "$n" scene_poses_applied) >= 1"
	check "far: a larger clearance ($cf m > $cn m + 50 mm)" "$cf > $cn + 0.05"
	check "flood: invalid clouds refused and counted ($(num "$fl" clouds_refused))" "$(num "$fl" clouds_refused) >= 300"
	check "flood: invalid poses refused and counted ($(num "$fl" scene_poses_refused))" "$(num "$fl" scene_poses_refused) >= 50"
	check "flood: no pose accepted or applied ($(num "$fl" scene_poses_accepted), $(num "$fl" scene_poses_applied))" \
		"$(num "$fl" scene_poses_accepted) == 0 && $(num "$fl" scene_poses_applied) == 0"
	check "flood: the clearance is the far grid's ($cl m, $cf m)" "$cl > $cf - 0.01 && $cl < $cf + 0.01"
	check "flood: the cloud never stale in the flood (input_stale $(num "$fl" input_stale))" "$(num "$fl" input_stale) == 0"
fi

# 4. the node killed 2 s after the start (setup included)
rm -f "$tmp"/*.out
scene near
sleep 2
kill -KILL "$node_pid"
finish
j="$tmp/near.json"
if [ -s "$j" ]; then
	s=$(num "$j" link_silent_ns)
	check "killed: safe state latched ($(str "$j" link_lost), $(num "$j" safe_state_trips) trips)" \
		"\"$(str "$j" link_lost)\" == \"true\" && $(num "$j" safe_state_trips) >= 1"
	check "killed: within the 200 ms timeout (cloud silent $s ns)" "$s >= 200000000 && $s <= 203000000"
	check "killed: in safe state at the end" "$(grep -c 'in safe state at the end' "$tmp/run-near.out") == 1"
	common killed near
else
	bad "killed: summary JSON written"
fi
echo "$name: $pass passed, $fail failed, $skip skipped"
[ "$fail" -eq 0 ]
