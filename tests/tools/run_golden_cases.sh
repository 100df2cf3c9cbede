# Sourced by test_run_golden.sh and run_golden_record.sh: the cases of
# proxima-run's golden outputs and the filter that masks what depends on
# the real clock. Run from the top of the tree (config paths are printed
# as given).
#
# Cases (each: exit status, stdout, stderr, and the files it wrote):
#   help                   --help
#   usage                  a refused --duration-s
#   check_<config>         --check on every config/examples/*.yaml but
#                          those with STEP/IGES parts (kind cad), a
#                          URDF robot (control.avoidance.urdf) or a dds
#                          device: the golden runner predates them and
#                          cannot read them (tests/tools/test_proxima_run.sh
#                          and tests/bridge/test_teleop.sh run them)
#   run_<config>           every config in virtual time for 0.2 s with
#                          --telemetry and --summary-json: the CSV, the
#                          JSON and both SVG plots (configs with hardware
#                          devices are refused: their refusal is recorded)
#   faults_long            haptic_faults for 3 s: the whole fault campaign
#                          (stdout, stderr, JSON; no CSV or plots, to stay
#                          small)
#   cli_faults             haptic_sim with two --fault windows: a safe
#                          state trip and its campaign lines
#   stop_signal            can_avoid_sim stopped by SIGINT at cycle 120
#                          (PX_RUN_STOP_AT): "ended by signal", shutdown
#                          after SIGINT
#
# The heap counter is there (preloaded as tests/tools/test_proxima_run.sh does,
# or linked in by an older build): allocations after setup and the
# counter's name are compared.
#
# Masked (golden_mask), each value replaced by '#':
#   - the output directory, everywhere: @OUT@
#   - the heap calls of setup ("setup made #", "allocations_setup"): a
#     preloaded counter also counts the dynamic loader's and the C++
#     runtime's calls before main, a linked one does not; and the app
#     object is one more heap call than the old runner's static state
#   - stdout: the wall time and cycles/s of "cycles", the wall time of
#     "time", every figure of "compute" (the compute phase is timed on
#     the real clock even in virtual time)
#   - stderr: cycles/s and compute p99 of the status line; a status line
#     is printed every wall-clock second, so only the last one is kept
#   - JSON: "wall_s", "wall_time_s" and the figures of "compute_ns"
#   - CSV: compute_ns (column 18) of every record
#   - latency SVG: the compute-time histogram (its grid lines, its bars
#     and its "+N beyond" label); the wake-up histogram is all zeros on
#     the virtual clock and stays
# Everything else must be byte for byte the same.

GOLDEN_DURATION=0.2

# golden_cases: one case a line, "NAME|ENV|ARGS" (ARGS word-split; @OUT@
# is the output directory).
golden_cases() {
	echo "help||--help"
	echo "usage||config/examples/haptic_sim.yaml --duration-s 0"
	for f in config/examples/*.yaml; do
		grep -q 'kind: cad' "$f" && continue
		grep -qE '^ +urdf: ' "$f" && continue
		grep -q 'backend: dds' "$f" && continue
		n=$(basename "$f" .yaml)
		echo "check_$n||--check $f"
		echo "run_$n||$f --virtual-time --duration-s $GOLDEN_DURATION --telemetry @OUT@/run_$n.csv --summary-json @OUT@/run_$n.json"
	done
	echo "faults_long||config/examples/haptic_faults.yaml --virtual-time --duration-s 3 --telemetry @OUT@/faults_long.csv --summary-json @OUT@/faults_long.json"
	echo "cli_faults||config/examples/haptic_sim.yaml --virtual-time --duration-s 0.3 --fault unplug,haptic,0.05,0.05 --fault nan,haptic,0.15,0.02 --telemetry @OUT@/cli_faults.csv --summary-json @OUT@/cli_faults.json"
	echo "stop_signal|PX_RUN_STOP_AT=120:INT|config/examples/can_avoid_sim.yaml --virtual-time --duration-s 0.3 --telemetry @OUT@/stop_signal.csv --summary-json @OUT@/stop_signal.json"
}

# Files a case keeps besides .rc, .out and .err.
golden_files() {
	case "$1" in
	faults_long) echo "$1.json" ;;
	*) echo "$1.csv $1.json $1_time.svg $1_latency.svg" ;;
	esac
}

# golden_mask KIND < raw > masked; KIND out, err, json, csv, latency_svg
# (anything else passes unchanged).
golden_mask() {
	case "$1" in
	out)
		sed -e 's/ s simulated, [0-9.]* s wall ([0-9]* cycles\/s)$/ s simulated, # s wall (# cycles\/s)/' \
		    -e 's/), wall [0-9.]* s; /), wall # s; /' \
		    -e 's/^\(  allocations       .*; setup made \)[0-9]*)$/\1#)/' \
		    -e 's/^\(  compute           \)p50 [0-9.]* us, p99 [0-9.]* us, p99.9 [0-9.]* us, max [0-9.]* us$/\1p50 # us, p99 # us, p99.9 # us, max # us/'
		;;
	err)
		awk '/^\[ *[0-9.]+ s\] / { last = $0; held = 1; next }
		     held { print last; held = 0 } { print }
		     END { if (held) print last }' |
		sed -e 's/^\(\[ *[0-9.]* s\] \) *[0-9]* cycles\/s | wake p99 \( *[0-9.]* us\) | compute p99 *[0-9.]* us | /\1# cycles\/s | wake p99 \2 | compute p99 # us | /'
		;;
	json)
		sed -e 's/^\(  "wall_s": \)[0-9.]*,$/\1#,/' \
		    -e 's/^\(  "wall_time_s": \)[0-9.]*,$/\1#,/' \
		    -e 's/^\(  "allocations_setup": \)[0-9]*,$/\1#,/' \
		    -e 's/^\(  "compute_ns": {"count": [0-9]*\), .*}\(,*\)$/\1, #}\2/'
		;;
	csv)
		awk -F, -v OFS=, 'NR > 1 { $18 = "#" } { print }'
		;;
	latency_svg)
		awk "/ stroke='#444'\\/>\$/ { panel++ }
		     panel >= 2 && /^<line / { next }
		     panel >= 2 && / beyond<\\/text>\$/ { next }
		     panel >= 2 && /^<path / { sub(/ d='[^']*'/, \" d='#'\") }
		     { print }"
		;;
	*) cat ;;
	esac
}

# golden_run BIN CASE-LINE OUTDIR: run one case, leave CASE.rc, .out,
# .err and its files, masked, in OUTDIR.
golden_run() {
	bin=$1 line=$2 dir=$3
	n=${line%%|*} rest=${line#*|}
	env_=${rest%%|*} args=${rest#*|}
	args=$(printf '%s' "$args" | sed "s#@OUT@#$dir/raw#g")
	mkdir -p "$dir/raw"
	# shellcheck disable=SC2086 # ARGS and ENV are word lists
	env $env_ "$bin" $args >"$dir/raw/$n.out" 2>"$dir/raw/$n.err"
	echo $? >"$dir/$n.rc"
	for k in out err; do
		sed "s#$dir/raw#@OUT@#g" "$dir/raw/$n.$k" | golden_mask $k >"$dir/$n.$k"
	done
	for f in $(golden_files "$n"); do
		[ -f "$dir/raw/$f" ] || continue
		case "$f" in *_latency.svg) k=latency_svg ;; *) k=${f##*.} ;; esac
		sed "s#$dir/raw#@OUT@#g" "$dir/raw/$f" | golden_mask $k >"$dir/$f"
	done
	rm -rf "$dir/raw"
}
