#!/bin/sh
# proxima-armgen writes the example arm (config/examples/robots/arm6: the
# URDF and its STL link meshes) byte for byte as shipped: the checked-in
# files are its output, and regenerating them changes nothing.
set -u
name=test_armgen
bin="${BUILD:-build}/bin/proxima-armgen"
ref=config/examples/robots/arm6
pass=0 fail=0
if [ ! -x "$bin" ]; then
	echo "skip: $bin not built"
	echo "$name: 0 passed, 0 failed, 1 skipped"
	exit 0
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
if "$bin" "$tmp/arm6"; then
	echo "ok   proxima-armgen ran"; pass=$((pass + 1))
else
	echo "FAIL proxima-armgen ran"; fail=$((fail + 1))
fi
for f in $(cd "$ref" && find . -type f | sort) $(cd "$tmp/arm6" && find . -type f | sort); do
	if cmp -s "$ref/$f" "$tmp/arm6/$f"; then
		echo "ok   $f as shipped"; pass=$((pass + 1))
	else
		echo "FAIL $f differs from $ref (or is missing on one side)"; fail=$((fail + 1))
	fi
done
"$bin" >/dev/null 2>&1
if [ $? -eq 2 ]; then echo "ok   usage: exit 2"; pass=$((pass + 1))
else echo "FAIL usage: exit 2"; fail=$((fail + 1)); fi
echo "$name: $pass passed, $fail failed, 0 skipped"
[ "$fail" -eq 0 ]
