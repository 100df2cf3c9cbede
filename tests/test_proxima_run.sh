#!/bin/sh
# proxima-run's command-line contract: --check on good and bad configs
# (exit status and message format), flag parsing, and the honest "not
# built yet" answer without --check. Prints a harness-style summary line.
set -u
name=test_proxima_run
bin="${BUILD:-build}/bin/proxima-run"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
pass=0 fail=0 skip=0
ok() { echo "ok   $1"; pass=$((pass + 1)); }
bad() { echo "FAIL $1"; sed 's/^/    /' "$tmp/out" "$tmp/err" 2>/dev/null; fail=$((fail + 1)); }
# expect DESCRIPTION STATUS COMMAND...: run, compare the exit status.
expect() {
	d=$1 want=$2; shift 2
	"$@" >"$tmp/out" 2>"$tmp/err"
	got=$?
	if [ "$got" -eq "$want" ]; then ok "$d (exit $got)"; else
		echo "    exit status $got, expected $want"; bad "$d"; fi
}
# has DESCRIPTION FILE FIXED-STRING: the file contains the exact line.
has() {
	if grep -qxF -- "$3" "$2"; then ok "$1"; else
		echo "    missing line: $3"; bad "$1"; fi
}
if [ ! -x "$bin" ]; then
	echo "skip: $bin not built"
	echo "$name: 0 passed, 0 failed, 1 skipped"
	exit 0
fi

for f in config/examples/*.yaml; do
	expect "--check $f" 0 "$bin" --check "$f"
	if [ "$(wc -l <"$tmp/out")" -eq 1 ] &&
		grep -qE "^$f: OK \([0-9]+ devices?, loop period [0-9]+ ns\)\$" "$tmp/out"; then
		ok "one-line OK for $f"; else bad "one-line OK for $f"; fi
	if [ -s "$tmp/err" ]; then echo "    unexpected stderr"; bad "--check $f is quiet on stderr"; else ok "--check $f is quiet on stderr"; fi
done

cat >"$tmp/bad.yaml" <<'Y'
loop:
  period_ns: 0
  perod_ns: 1000
  priority: high
devices:
  - name: pad
    backend: hidraw2
Y
expect "--check on a bad config" 1 "$bin" --check "$tmp/bad.yaml"
has "range error with line:column" "$tmp/err" \
	"$tmp/bad.yaml:2:14: loop.period_ns: 0 is out of range [10000, 100000000]"
has "unknown key with suggestion" "$tmp/err" \
	"$tmp/bad.yaml:3:3: loop.perod_ns: unknown key (did you mean 'period_ns'?)"
has "wrong type" "$tmp/err" \
	"$tmp/bad.yaml:4:13: loop.priority: expected an integer, got 'high'"
has "unknown enum value" "$tmp/err" \
	"$tmp/bad.yaml:7:14: devices[0].backend: unknown value 'hidraw2' (expected one of: sim, hidapi, libusb, socketcan, gpiod)"
has "error count" "$tmp/err" "$tmp/bad.yaml: invalid configuration (4 errors)"
if [ -s "$tmp/out" ]; then echo "    stdout not empty"; bad "nothing on stdout for a bad config"; else ok "nothing on stdout for a bad config"; fi

printf 'loop: [1, 2\n' >"$tmp/syntax.yaml"
expect "--check on a YAML syntax error" 1 "$bin" --check "$tmp/syntax.yaml"
if grep -q "^$tmp/syntax.yaml:2:1: YAML syntax error: " "$tmp/err"; then ok "syntax error placed"; else bad "syntax error placed"; fi

expect "--check on a missing file" 1 "$bin" --check "$tmp/none.yaml"
has "missing file message" "$tmp/err" "$tmp/none.yaml: cannot open: No such file or directory"

good=config/examples/haptic_sim.yaml
expect "--check $good" 0 "$bin" --check "$good"
has "OK line of the default config" "$tmp/out" "$good: OK (1 device, loop period 1000000 ns)"
expect "no CONFIG" 2 "$bin"
expect "unknown flag" 2 "$bin" --check --fast "$good"
if grep -q "unknown option '--fast'" "$tmp/err"; then ok "unknown flag named"; else bad "unknown flag named"; fi
expect "two CONFIGs" 2 "$bin" --check "$good" "$good"
expect "--duration-s needs a value" 2 "$bin" "$good" --duration-s
expect "--duration-s rejects junk" 2 "$bin" "$good" --duration-s 5x
expect "--duration-s rejects 0" 2 "$bin" "$good" --duration-s 0
expect "--summary-json needs a file" 2 "$bin" "$good" --summary-json
expect "flags accepted with --check" 0 "$bin" --check "$good" --duration-s 2.5 \
	--virtual-time --summary-json "$tmp/s.json"
expect "--flag=value form" 0 "$bin" --check --duration-s=3 --summary-json="$tmp/s.json" "$good"
expect "--help" 0 "$bin" --help
if grep -q "^usage: proxima-run CONFIG \[--duration-s N\] \[--virtual-time\] \[--summary-json FILE\]$" "$tmp/out"; then ok "usage line"; else bad "usage line"; fi

expect "runner not built yet" 2 "$bin" "$good" --duration-s 1 --virtual-time
if grep -q "runner .* is not built yet" "$tmp/err"; then ok "says the runner is not built"; else bad "says the runner is not built"; fi
expect "runner on a bad config reports the config" 1 "$bin" "$tmp/bad.yaml"

# control section: errors fail --check; a stiffness beyond the passive
# limit is a warning on stderr with its place, and the file stays valid.
cat >"$tmp/ctl.yaml" <<'Y'
loop: {period_ns: 1000000}
devices:
  - {name: pen, backend: sim, sim: {kind: haptic, damping_n_s_per_m: 2.0}}
control:
  mode: haptic
  device: pen
  haptic:
    stiffness_n_per_m: 5000
    damping_n_s_per_m: 0.5
Y
expect "--check warns on a non-passive stiffness" 0 "$bin" --check "$tmp/ctl.yaml"
if grep -q "^$tmp/ctl.yaml:8:24: control.haptic.stiffness_n_per_m: warning: stiffness 5000 N/m is not passive .* allows K < 3000 N/m$" "$tmp/err"; then
	ok "stability warning placed"; else bad "stability warning placed"; fi
sed 's/stiffness_n_per_m: 5000/stiffness_n_per_m: 2500/' "$tmp/ctl.yaml" >"$tmp/ctl2.yaml"
expect "--check on a passive stiffness" 0 "$bin" --check "$tmp/ctl2.yaml"
if [ -s "$tmp/err" ]; then bad "no warning when passive"; else ok "no warning when passive"; fi
sed 's/device: pen$/device: pem/' "$tmp/ctl.yaml" >"$tmp/ctl3.yaml"
expect "--check on a bad control section" 1 "$bin" --check "$tmp/ctl3.yaml"
has "control error placed" "$tmp/err" \
	"$tmp/ctl3.yaml:6:11: control.device: no device named 'pem' in devices"

echo "$name: $pass passed, $fail failed, $skip skipped"
[ "$fail" -eq 0 ]
