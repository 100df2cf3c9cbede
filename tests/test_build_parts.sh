#!/bin/sh
# Each optional part left out alone (WITH_<PART>=0, every other part as
# this build has it), in its own build directory: the library, the tools
# and the examples build; px_features.h says PX_HAVE_<PART> 0 and nothing
# else changed; the tests of that part run and skip what needs it, saying
# "built without <library>"; the tool that uses it says so too. The parts
# are the Makefile's OPT_PARTS: a part this script has no list for is
# checked with the tests that name it (PX_NEEDS(<PART>) or a
# PX_TEST_NEEDS line). A part this build does not have is skipped (its
# build-without is this one). test_build_minimal.sh leaves every part
# out at once.
#
# Cost: each build starts from this build's library objects, so only the
# part's <file>_none.c, what includes px_features.h, the part's test
# programs and the links are compiled again.
# Prints a harness-style summary line.
set -u
name=test_build_parts
if [ "${SAN:-}" = 1 ]; then
	echo "skip part-off builds: the sanitizer build runs the full suite"
	echo "$name: 0 passed, 0 failed, 1 skipped"
	exit 0
fi
full=${BUILD:-build}
if [ ! -f "$full/gen/px_features.h" ] || [ ! -d "$full/obj" ]; then
	echo "skip: $full not built"
	echo "$name: 0 passed, 0 failed, 1 skipped"
	exit 0
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
pass=0 fail=0 skip=0
check() { # description, command...
	d=$1; shift
	if "$@" >"$tmp/out" 2>&1; then
		echo "ok   $d"; pass=$((pass + 1))
	else
		echo "FAIL $d"; sed 's/^/    /' "$tmp/out" | head -n 40; fail=$((fail + 1))
	fi
}
mkq() { env -u MAKEFLAGS -u MFLAGS ${MAKE:-make} -s --no-print-directory "$@"; }
# mk BUILD-DIR PART TARGET...: make in that directory with the part off
mk() {
	b=$1 p=$2; shift 2
	mkq "WITH_$p=0" BUILD="$b" "$@"
}
# runs_saying TEXT COMMAND...: exits 0 and prints TEXT (empty: anything)
runs_saying() {
	want=$1; shift
	out=$("$@" 2>&1); rc=$?
	echo "$out"
	[ "$rc" -eq 0 ] && { [ -z "$want" ] || echo "$out" | grep -qF -- "$want"; }
}
# runs_not_saying TEXT COMMAND...: exits 0 and does not print TEXT
runs_not_saying() {
	want=$1; shift
	out=$("$@" 2>&1); rc=$?
	echo "$out"
	[ "$rc" -eq 0 ] && ! echo "$out" | grep -qF -- "$want"
}
# fails_saying TEXT COMMAND...: exits non-zero and prints TEXT
fails_saying() {
	want=$1; shift
	out=$("$@" 2>&1) && { echo "$out"; echo "(exit 0)"; return 1; }
	echo "$out"
	echo "$out" | grep -qF -- "$want"
}
# the test source of a test name (tests/ mirrors the tree)
src_of() { find tests -name "$1.c" -not -path 'tests/support/*' | head -n 1; }
# the tests of a part: those named here, else those whose source names it
tests_of() { # PART TAG
	case $1 in
	HIDAPI) echo test_hid ;;
	LIBUSB) echo test_usb ;;
	SOCKETCAN) echo test_can ;;
	GPIOD) echo test_gpio ;;
	ASSIMP) echo test_cloud test_load ;;
	YAML) echo test_world test_config ;;
	*) find tests -name 'test_*.c' -not -path 'tests/support/*' |
		xargs grep -lE "PX_NEEDS\($1\)|PX_TEST_NEEDS:(.* )?$2( |\$)" |
		sed 's|.*/||; s|\.c$||' | sort | tr '\n' ' ' ;;
	esac
}
# a PLY point cloud and a query point for proxima-query
printf 'ply\nformat ascii 1.0\nelement vertex 2\nproperty double x\nproperty double y\nproperty double z\nend_header\n0 0 0\n1 0 0\n' >"$tmp/pts.ply"
printf '1,1,0\n' >"$tmp/q.csv"

parts=$(mkq print-OPT_PARTS)
if [ -z "$parts" ]; then
	echo "FAIL make print-OPT_PARTS names no optional part"
	fail=$((fail + 1))
fi
for part in $parts; do
	lib=$(mkq print-TAG_$part)
	[ -n "$lib" ] || lib=$(echo "$part" | tr 'A-Z' 'a-z')
	if ! grep -qx "#define PX_HAVE_$part 1" "$full/gen/px_features.h"; then
		echo "skip WITH_$part=0: this build is without $lib already"
		skip=$((skip + 1))
		continue
	fi
	b="$tmp/b-$part"
	mkdir -p "$b"
	# the library's objects are the same code; whatever includes
	# px_features.h (tests, examples, a tool) is compiled again (its
	# dependency file names the full build's px_features.h)
	cp -a "$full/obj" "$b/"
	[ -d "$full/obj-hooks" ] && cp -a "$full/obj-hooks" "$b/"
	rm -rf "$b/obj/examples" "$b/obj/fuzz"
	[ -d "$b/obj/tests" ] && find "$b/obj/tests" -name 'test_*' -type f -delete
	grep -rl --include='*.d' 'px_features\.h' "$b/obj" | while read -r d; do
		rm -f "${d%.d}.o"
	done
	tests=$(tests_of "$part" "$lib")
	check "WITH_$part=0: library, tools and examples build" mk "$b" $part all
	check "WITH_$part=0: px_features.h says PX_HAVE_$part 0, the rest as before" \
		sh -c "sed 's/^#define PX_HAVE_$part 1\$/#define PX_HAVE_$part 0/' '$full/gen/px_features.h' |
		       cmp - '$b/gen/px_features.h'"
	for t in $tests; do
		check "WITH_$part=0: $t builds" mk "$b" $part "$b/tests/$t"
		# as the suite runs it (a test that needs the part as a whole
		# is skipped by tests/run.sh, a test function by PX_NEEDS)
		# (only this part is off: whatever says "built without" is it;
		# PX_NEEDS names the library as tests/support/px_test.c does)
		if grep -qE "PX_NEEDS\($part\)|PX_TEST_NEEDS:(.* )?$lib( |\$)" "$(src_of "$t")"; then
			check "WITH_$part=0: $t passes, what needs $part skipped" \
				runs_saying "skipped: built without " \
				env PX_WITHOUT="$lib" sh tests/run.sh "$b/tests/$t"
		else
			check "WITH_$part=0: $t passes, none of it skipped" \
				runs_not_saying "built without " \
				env PX_WITHOUT="$lib" sh tests/run.sh "$b/tests/$t"
		fi
	done
	case $part in
	HIDAPI | LIBUSB | GPIOD)
		# proxima-probe names the missing library on its subsystem's line
		check "WITH_$part=0: proxima-probe says built without $lib" \
			sh -c "'$b/bin/proxima-probe' 2>&1 | grep -F 'built without $lib'" ;;
	SOCKETCAN) ;; # no tool of its own: test_can's bitrate test says it
	ASSIMP)
		check "WITH_$part=0: proxima-query on an STL says built without assimp" \
			fails_saying "built without assimp" "$b/bin/proxima-query" \
			config/examples/scenes/knob.stl "$tmp/q.csv"
		check "WITH_$part=0: proxima-query reads a PLY point cloud" \
			sh -c "'$b/bin/proxima-query' '$tmp/pts.ply' '$tmp/q.csv' | grep -qx '1,1,0,0,1,0'" ;;
	YAML)
		check "WITH_$part=0: proxima-run --check says built without libyaml" \
			fails_saying "built without libyaml" "$b/bin/proxima-run" --check config/examples/haptic_sim.yaml ;;
	VIEW)
		check "WITH_$part=0: proxima-run --view says built without libwebsockets and runs" \
			runs_saying "built without libwebsockets" "$b/bin/proxima-run" \
			config/examples/haptic_sim.yaml --virtual-time --duration-s 0.1 \
			--telemetry "$tmp/view.csv" --view 1 ;;
	esac
	rm -rf "$b"
done
echo "$name: $pass passed, $fail failed, $skip skipped"
[ "$fail" -eq 0 ]
