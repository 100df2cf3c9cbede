# Sourced by the bridge's end-to-end scripts (test_teleop.sh,
# test_scene_run.sh), which set $tmp first: the pass/fail counters and
# checks (check NAME AWK-CONDITION; a failure shows the tails of
# $tmp/*.out), the summary JSON's numbers and words (num FILE KEY, str
# FILE KEY), and $preload: the tests' allocation counter for
# LD_PRELOAD where it is built (not under sanitizers, which own malloc).
pass=0 fail=0 skip=0
ok() { echo "ok   $1"; pass=$((pass + 1)); }
bad() { echo "FAIL $1"; for f in "$tmp"/*.out; do echo "    -- $f"; sed 's/^/    /' "$f" | tail -n 25; done; fail=$((fail + 1)); }
check() { if awk "BEGIN { exit !($2) }"; then ok "$1"; else echo "    false: $2"; bad "$1"; fi; }
num() { sed -n "s/.*\"$2\": *\\([-0-9.eE+]*\\).*/\\1/p" "$1" | head -n 1; }
str() { sed -n "s/.*\"$2\": *\\([a-z]*\\).*/\\1/p" "$1" | head -n 1; }
counter_so="${BUILD:-build}/lib/libproxima-alloc-count.so"
preload=${LD_PRELOAD:-}
if [ "${SAN:-}" != 1 ] && [ -f "$counter_so" ]; then
	counter_so="$(cd "$(dirname "$counter_so")" && pwd)/$(basename "$counter_so")"
	preload="$counter_so${LD_PRELOAD:+:$LD_PRELOAD}"
fi
