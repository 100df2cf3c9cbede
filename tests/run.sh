#!/bin/sh
# Run test binaries and scripts, add up their summary lines and print the
# final "N passed, N failed, N skipped". A binary that dies or prints no
# summary counts as one failure.
set -u
timeout_s=${TEST_TIMEOUT:-900}
tp=0 tf=0 ts=0
log=$(mktemp)
trap 'rm -f "$log"' EXIT
# A test whose source names the optional parts it needs (a line
# "PX_TEST_NEEDS: libyaml libgpiod", tags as in the Makefile) skips when
# the build left one out (PX_WITHOUT, from make).
missing_part() { # test binary or script: prints the first part left out
	case "$1" in
	*.sh) src=$1 ;;
	*/fuzz-replay/*) src=fuzz/$(basename "$1").c ;;
	*) src=$(find tests -name "$(basename "$1").c" -not -path 'tests/support/*' 2>/dev/null | head -n 1) ;;
	esac
	[ -n "${PX_WITHOUT:-}" ] && [ -f "$src" ] || return 1
	for p in $(sed -n 's/.*PX_TEST_NEEDS:\([a-z0-9 ]*\).*/\1/p' "$src"); do
		for w in $PX_WITHOUT; do
			[ "$w" = "$p" ] && { echo "$p"; return 0; }
		done
	done
	return 1
}
for t in "$@"; do
	echo "== $t"
	if part=$(missing_part "$t"); then
		echo "$(basename "$t" .sh): skipped: built without $part"
		ts=$((ts + 1))
		continue
	fi
	case "$t" in
	*.sh) timeout "$timeout_s" sh "$t" >"$log" 2>&1 ;;
	*) timeout "$timeout_s" "$t" >"$log" 2>&1 ;;
	esac
	rc=$?
	cat "$log"
	line=$(grep -E '^[A-Za-z0-9_.-]+: [0-9]+ passed, [0-9]+ failed, [0-9]+ skipped$' "$log" | tail -n 1)
	if [ -z "$line" ]; then
		echo "   $t: no summary (exit status $rc): counted as 1 failed"
		tf=$((tf + 1))
		continue
	fi
	counts=$(echo "$line" | sed -E 's/^[^:]*: ([0-9]+) passed, ([0-9]+) failed, ([0-9]+) skipped$/\1 \2 \3/')
	p=${counts%% *} s=${counts##* } f=${counts#* } f=${f%% *}
	if [ "$rc" -ne 0 ] && [ "$f" -eq 0 ]; then
		echo "   $t: exit status $rc with no failed test: counted as 1 failed"
		f=1
	fi
	tp=$((tp + p)) tf=$((tf + f)) ts=$((ts + s))
done
echo "$tp passed, $tf failed, $ts skipped"
[ "$tf" -eq 0 ]
