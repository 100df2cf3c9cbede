#!/bin/sh
# Run every program of examples/ (built by `make`, in $BUILD/examples):
# each checks its own answer and exits non-zero when it is wrong.
# Prints a harness-style summary line.
set -u
name=test_examples
dir=${BUILD:-build}/examples
pass=0 fail=0 skip=0
for src in examples/*.c; do
	ex=$(basename "$src" .c)
	# an example that needs an optional part says so as the tests do
	need=$(sed -n 's/.*PX_TEST_NEEDS:\([a-z0-9 ]*\).*/\1/p' "$src")
	missing=""
	for p in $need; do
		case " ${PX_WITHOUT:-} " in *" $p "*) missing=$p ;; esac
	done
	if [ -n "$missing" ]; then
		echo "skip $ex: built without $missing"; skip=$((skip + 1))
		continue
	fi
	if [ ! -x "$dir/$ex" ]; then
		echo "FAIL $ex: $dir/$ex not built"; fail=$((fail + 1))
		continue
	fi
	if out=$("$dir/$ex" 2>&1); then
		echo "ok   $ex: $out"; pass=$((pass + 1))
	else
		echo "FAIL $ex (exit $?):"; echo "$out" | sed 's/^/    /'
		fail=$((fail + 1))
	fi
done
echo "$name: $pass passed, $fail failed, $skip skipped"
[ "$fail" -eq 0 ]
