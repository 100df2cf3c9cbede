#!/bin/sh
# proxima-run with the DDS bridge on (real Cyclone DDS, loopback): the
# default haptic config plus a bridge section runs 3 s on the real clock
# while a second process (test_bridge as listener) waits for its tool
# pose, wrench and status; the loop's thread makes no heap call after
# setup with the bridge publishing beside it (the tests' allocation
# counter, preloaded), the bridge published and reported no write error;
# --check reports a bad bridge key at its line. Every wait is bounded.
# Prints a harness-style summary line.
# PX_TEST_NEEDS: libyaml cyclonedds (tests/run.sh skips it in builds without)
set -u
name=test_bridge_run
b=${BUILD:-build}
bin="$b/bin/proxima-run"
listener="$b/tests/test_bridge"
tmp=$(mktemp -d)
lpid=
trap '[ -n "$lpid" ] && kill "$lpid" 2>/dev/null; rm -rf "$tmp"' EXIT
pass=0 fail=0 skip=0
ok() { echo "ok   $1"; pass=$((pass + 1)); }
bad() { echo "FAIL $1"; sed 's/^/    /' "$tmp/out" "$tmp/err" 2>/dev/null | head -n 40; fail=$((fail + 1)); }
check() { if [ "$2" = 1 ]; then ok "$1"; else bad "$1"; fi; }
num() { sed -n "s/^ *\"$2\": *\\([-0-9.eE+]*\\).*/\\1/p" "$1" | head -n 1; }
if [ ! -x "$bin" ] || [ ! -x "$listener" ]; then
	echo "skip: $bin or $listener not built"
	echo "$name: 0 passed, 0 failed, 1 skipped"
	exit 0
fi
counter_so="$b/lib/libproxima-alloc-count.so"
if [ "${SAN:-}" != 1 ]; then
	counter_so="$(cd "$(dirname "$counter_so")" && pwd)/$(basename "$counter_so")"
	preload="$counter_so${LD_PRELOAD:+:$LD_PRELOAD}"
else
	preload=${LD_PRELOAD:-}
fi

# A domain and namespace of this run alone (other suites may run beside).
domain=$(( $$ % 200 + 1 ))
ns="pxrun_$$"
cfg="$tmp/bridge.yaml"
# the config's scene files are named relative to it
ln -s "$(pwd)/config/examples/scenes" "$tmp/scenes"
sed "s|^  file: build/telemetry.csv|  file: $tmp/run.csv|" config/examples/haptic_sim.yaml >"$cfg"
cat >>"$cfg" <<YAML

bridge:
  enable: true
  domain_id: $domain
  namespace: $ns
  interface: lo
  tool_pose_rate_hz: 200
  wrench_rate_hz: 200
  status_rate_hz: 20
YAML

if "$bin" --check "$cfg" >"$tmp/out" 2>"$tmp/err"; then ok "--check accepts the bridge section"
else bad "--check accepts the bridge section"; fi
sed 's|^  namespace: .*|  namespace: 9lives|' "$cfg" >"$tmp/bad.yaml"
"$bin" --check "$tmp/bad.yaml" >"$tmp/out" 2>"$tmp/err"
rc=$?
line=$(grep -n '^  namespace:' "$tmp/bad.yaml" | cut -d: -f1)
if [ "$rc" -eq 1 ] && grep -qE "^$tmp/bad.yaml:$line:[0-9]+: bridge\.namespace: '9lives' has a token starting with a digit" "$tmp/err"; then
	ok "--check names a bad bridge.namespace at line $line"
else bad "--check names a bad bridge.namespace at line $line (exit $rc)"; fi

# The listener first: it waits up to 20 s for the run's messages.
PX_BRIDGE_TEST_ROLE="listen:$domain:$ns:20" "$listener" >"$tmp/listen.out" 2>&1 &
lpid=$!
env LD_PRELOAD="$preload" timeout 60 "$bin" "$cfg" --duration-s 3 \
	--summary-json "$tmp/run.json" >"$tmp/out" 2>"$tmp/err"
rc=$?
check "proxima-run with the bridge runs 3 s (exit $rc)" "$([ "$rc" -eq 0 ] && echo 1)"
wait "$lpid"
lrc=$?
lpid=
cp "$tmp/listen.out" "$tmp/out"
check "a second process received tool_pose, wrench and status (exit $lrc)" "$([ "$lrc" -eq 0 ] && echo 1)"
if [ -s "$tmp/run.json" ]; then
	a=$(num "$tmp/run.json" allocations_after_setup)
	s=$(num "$tmp/run.json" allocations_setup)
	check "no heap call in the loop's thread after setup ($a)" "$([ "$a" = 0 ] && echo 1)"
	if grep -q '"allocation_counter": "none"' "$tmp/run.json"; then
		echo "skip the counter is not loaded here"; skip=$((skip + 1))
	else
		check "the counter saw setup's heap calls ($s)" "$([ "${s:-0}" -gt 0 ] && echo 1)"
	fi
else
	bad "summary JSON written"
fi
if grep -qE "^proxima-run: bridge: [1-9][0-9]* messages on rt/$ns/\.\.\. .*, 0 write errors$" "$tmp/err"; then
	ok "the bridge published, without write errors"
else bad "the bridge published, without write errors"; fi
# 200 Hz for 3 s is 600 tool poses; half of it allows for a loaded machine
n=$(sed -n 's/^proxima-run: bridge: .*(tool_pose \([0-9]*\),.*/\1/p' "$tmp/err")
check "tool_pose near its configured 200 Hz (${n:-none} in 3 s)" "$([ "${n:-0}" -ge 300 ] && [ "${n:-0}" -le 620 ] && echo 1)"
echo "$name: $pass passed, $fail failed, $skip skipped"
[ "$fail" -eq 0 ]
