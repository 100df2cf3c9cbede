#!/bin/sh
# `make deps` (tools/install-deps.sh): quiet and successful when the
# packages are present; as non-root with a package missing, it prints the
# exact command to run and fails. Prints a harness-style summary line.
set -u
name=test_deps
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
pass=0 fail=0 skip=0
ok() { echo "ok   $1"; pass=$((pass + 1)); }
bad() { echo "FAIL $1"; sed 's/^/    /' "$tmp/out" "$tmp/err"; fail=$((fail + 1)); }

if sh tools/install-deps.sh make >"$tmp/out" 2>"$tmp/err" && [ ! -s "$tmp/out" ] && [ ! -s "$tmp/err" ]; then
	ok "present package: exit 0, no output"; else bad "present package: exit 0, no output"; fi

# A package name that cannot exist, checked as an unprivileged user.
missing=px-no-such-package-for-test
if [ "$(id -u)" = 0 ]; then
	if command -v setpriv >/dev/null 2>&1; then
		run() { setpriv --reuid=65534 --regid=65534 --clear-groups "$@"; }
	else
		run() { return 77; }
	fi
else
	run() { "$@"; }
fi
cp tools/install-deps.sh "$tmp/deps.sh"
chmod 755 "$tmp" "$tmp/deps.sh"
run sh "$tmp/deps.sh" make "$missing" >"$tmp/out" 2>"$tmp/err"
rc=$?
if [ "$rc" = 77 ]; then
	echo "skip non-root: no way to drop privileges here"; skip=$((skip + 1))
else
	if [ "$rc" -ne 0 ]; then ok "non-root with a missing package fails"; else bad "non-root with a missing package fails"; fi
	if grep -qF "apt-get update && apt-get install -y --no-install-recommends $missing" "$tmp/err"; then
		ok "prints the exact command"; else bad "prints the exact command"; fi
	if grep -qF "missing Debian packages: $missing" "$tmp/err"; then
		ok "names what is missing"; else bad "names what is missing"; fi
fi
echo "$name: $pass passed, $fail failed, $skip skipped"
[ "$fail" -eq 0 ]
