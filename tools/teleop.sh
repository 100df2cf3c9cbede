#!/bin/sh
# Teleoperation on loopback: the follower (config/examples/teleop_follower.yaml,
# the URDF arm on simulated CANopen drives) and the master
# (config/examples/teleop_master.yaml, a simulated haptic device) as two
# proxima-run processes linked by DDS. Each waits for the other's topics
# (connect_timeout_ns), runs DURATION seconds and prints its summary;
# the master's summary first, then the follower's.
#   tools/teleop.sh [--duration-s SECONDS] [BUILD_DIR]
# Exit status: 0 when both runs ended well, else 1.
set -u
dur=10
if [ "${1:-}" = --duration-s ]; then dur=$2; shift 2; fi
b=${1:-${BUILD:-build}}
bin="$b/bin/proxima-run"
ex=config/examples
if [ ! -x "$bin" ]; then
	echo "teleop.sh: $bin not built (make all)" >&2
	exit 1
fi
tmp=$(mktemp -d)
fpid=
trap '[ -n "$fpid" ] && kill "$fpid" 2>/dev/null; rm -rf "$tmp"' EXIT
# the follower one second longer: the master's end is not a link loss
# it reports, the follower's own end comes after
"$bin" "$ex/teleop_follower.yaml" --duration-s "$((dur + 1))" >"$tmp/follower.out" 2>&1 &
fpid=$!
"$bin" "$ex/teleop_master.yaml" --duration-s "$dur" >"$tmp/master.out" 2>&1
mrc=$?
wait "$fpid"
frc=$?
fpid=
echo "== master (exit $mrc)"
cat "$tmp/master.out"
echo "== follower (exit $frc)"
cat "$tmp/follower.out"
[ "$mrc" -eq 0 ] && [ "$frc" -eq 0 ]
