#!/bin/sh
# proxima-run's outputs against the golden ones recorded with the runner
# before it became a main over app/px_app.h (tests/data/run_golden/, made
# by run_golden_record.sh; cases and masked fields in
# run_golden_cases.sh): exit status, stdout, stderr, telemetry CSV,
# summary JSON and SVG plots of every shipped config in virtual time,
# byte for byte after masking the real-clock figures. Shows the diff of
# every case that differs.
# PX_TEST_NEEDS: libyaml hidapi libusb libsocketcan libgpiod assimp
set -u
name=test_run_golden
bin="${BUILD:-build}/bin/proxima-run"
gold=tests/data/run_golden
pass=0 fail=0 skip=0
if [ ! -x "$bin" ]; then
	echo "skip: $bin not built"
	echo "$name: 0 passed, 0 failed, 1 skipped"
	exit 0
fi
. tests/tools/run_golden_cases.sh
# the counter as the golden runner had it (sanitizer builds link theirs:
# another counter, other setup figures: the allocation lines are then
# left out of the comparison)
so="${BUILD:-build}/lib/libproxima-alloc-count.so"
if [ "${SAN:-}" != 1 ]; then
	if [ ! -f "$so" ]; then
		echo "FAIL $so not built"
		echo "$name: 0 passed, 1 failed, 0 skipped"
		exit 1
	fi
	export LD_PRELOAD="$(cd "$(dirname "$so")" && pwd)/$(basename "$so")${LD_PRELOAD:+:$LD_PRELOAD}"
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
alloc_filter() {
	if [ "${SAN:-}" = 1 ]; then
		sed -e '/^  allocations       /d' -e '/^  "allocation/d'
	else
		cat
	fi
}
golden_cases >"$tmp/cases"
while IFS= read -r line; do
	n=${line%%|*}
	golden_run "$bin" "$line" "$tmp/now"
	bad=0
	for f in $(cd "$gold" && ls | grep -E "^$n(\.|_time\.|_latency\.)"); do
		if [ ! -f "$tmp/now/$f" ]; then
			echo "    $f: not written"
			bad=1
		elif ! alloc_filter <"$gold/$f" >"$tmp/want" ||
			! alloc_filter <"$tmp/now/$f" >"$tmp/got" ||
			! diff -u --label "golden/$f" --label "now/$f" "$tmp/want" "$tmp/got" >"$tmp/diff"; then
			sed 's/^/    /' "$tmp/diff" | head -n 60
			bad=1
		fi
	done
	for f in $(cd "$tmp/now" && ls | grep -E "^$n(\.|_time\.|_latency\.)"); do
		[ -f "$gold/$f" ] || { echo "    $f: written, not in the golden set"; bad=1; }
	done
	if [ "$bad" -eq 0 ]; then
		echo "ok   $n"; pass=$((pass + 1))
	else
		echo "FAIL $n"; fail=$((fail + 1))
	fi
done <"$tmp/cases"
echo "$name: $pass passed, $fail failed, $skip skipped"
[ "$fail" -eq 0 ]
