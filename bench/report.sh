#!/bin/sh
# bench/report.sh BENCH... - run the benchmark binaries in order and write
# docs/benchmarks.md from their output.
#
# Each benchmark's output also goes to the terminal as it runs. The report
# has the date, the machine (nproc, CPU model, kernel, load average at the
# start), a short paragraph per benchmark saying what it compares, and each
# benchmark's output verbatim. The report is written to a temporary file
# and renamed into place only when every benchmark succeeded; a failing
# benchmark leaves the previous report as it was and makes this script
# fail.
#
# Environment: BENCH_REPORT (output file, default docs/benchmarks.md);
# BENCH_SECTIONS=1 replaces only the named benchmarks' sections of the
# existing report, the rest of it (its header too) kept as it was; each
# new section then says when it ran (make bench-section BENCH=name).
# Run from the source tree: bench_scene reads config/examples/.

set -u

out=${BENCH_REPORT:-docs/benchmarks.md}
tmp=$(mktemp "${TMPDIR:-/tmp}/px-bench.XXXXXX") || exit 1
body=$(mktemp "${TMPDIR:-/tmp}/px-bench-body.XXXXXX") || { rm -f "$tmp"; exit 1; }
log=$(mktemp "${TMPDIR:-/tmp}/px-bench-log.XXXXXX") || { rm -f "$tmp" "$body"; exit 1; }
trap 'rm -f "$tmp" "$body" "$log"' EXIT INT TERM HUP

# What each benchmark compares (by binary name).
describe() {
	case "$1" in
	bench_arm) echo "Every link-obstacle clearance of the 6-joint URDF arm (\`config/examples/robots/arm6\`, 7 link meshes) per 1 ms cycle along a joint path, as exact model pairs: against a 100,000-point cloud (cold, coherent, and the first cycle after the cloud is replaced by a new frame), and against 20 mesh obstacles next to FCL 0.7's \`distance()\` (OBBRSS) on the same pairs at the same poses, with the ratio and the distances compared. Thread CPU time per cycle: median, p99, max." ;;
	bench_control) echo "Time per cycle and scene queries per cycle of the haptic proxy and penalty renderers and of the avoidance step (6 joints, 6 capsules) against a small analytic scene (sphere, thin plate, floor), so the figures are the control code's own cost." ;;
	bench_dist) echo "The global distance query (\`px_dist_query\`) on representative NURBS curves and patches: time per query (median, p99, max) for random points in the model's box enlarged by 25 % per side, root iterations, pieces solved per query and model memory." ;;
	bench_dist_occt) echo "The same models and points next to OpenCASCADE in one process, each query interleaved with OCCT's (so the figures here are cold-cache times): OCCT's correct set-up (surface projection plus boundary curves and corners) and its fastest (Extrema tree search, minimum only), with the ratios and how often either answer is on a wrong branch." ;;
	bench_models) echo "Point-to-model queries: a 70,490-triangle mesh (cold and coherent), a 100,000-point cloud, primitives, model pairs and scenes of 20 and 200 models; FCL 0.7 on the same mesh queries and mesh pairs where Debian's libfcl-dev is installed, with the ratio and a check that both give the same distances." ;;
	bench_nurbs) echo "Evaluation cost of NURBS curves and surfaces (the inner step of every Newton iteration of the distance core), best of several runs by thread CPU time." ;;
	bench_recog) echo "The knowledge step: recognition time at setup and closed-form closest-point time per query for a NURBS circle, a sphere and a torus patch built as surfaces of revolution." ;;
	bench_rt) echo "The real-time loop at 1 kHz against cyclictest (rt-tests) at the same priority and interval, alternating in 1 s chunks so that both see the same load, with both latency distributions and their ratios, after the cost of a ring push, a statistics record and read, and a virtual-clock cycle. \`PX_BENCH_RT_SECONDS\` (default 10 per side) and \`PX_BENCH_RT_PRIO\` (default 80) change the run." ;;
	bench_teleop) echo "The teleoperation link of \`config/examples/teleop_*.yaml\`: two processes at 1 kHz on loopback Cyclone DDS, the master's pose out through its \`dds\` device, the follower's wrench back from its cycle. Link round trip (both crossings with their thread hand-offs, the follower's wait for its next cycle taken out; target p99 <= 500 us) and cycle to cycle (what the loops see), p50/p99/p99.9/max; best-effort samples sent and received; a reliable 1 kHz parameter stream beside them (must lose nothing); the CPU share of each process's threads besides its loop. \`PX_BENCH_TELEOP_SECONDS\` (default 60) shortens the run." ;;
	bench_scene) echo "The loop's scene queries on the shipped example scene (\`config/examples/haptic_sim.yaml\`) three ways - plain global queries, coherent queries (hints) and tracked streams - along the same smooth paths at several speeds, with the answers compared; then the proxy renderer's whole step through the coherent and the tracked adapters." ;;
	bench_brep_occt) echo "The CAD parts of \`proxima-cadgen\` (filleted block, plate with holes and a pocket, bottle with 1 mm walls, trimmed free-form sheet, fused cylinder and sphere) written to STEP and read by \`px_cad\` + \`px_brep\` and by OpenCASCADE: proxima's cold query (signed for solids) next to \`BRepExtrema_DistShapeShape\` (the point as a vertex, the part loaded once) and, for the sign, that plus \`BRepClass3d_SolidClassifier\`, on the same points (random in the box enlarged by 25 % per side, and near the surface on both sides), each point's least time over three interleaved passes: median, p99, max, the ratios, and the wrong distances and signs of either side." ;;
	bench_brep) echo "Trimmed B-rep models built in C (a sheet with a round hole, a drilled cube, a free-form sheet trimmed by a spline loop with a hole, a closed box with 1 mm walls): the cold point query (signed where the part is closed) next to the untrimmed NURBS model of the same surfaces on the same points, per-query median, p99 and max and their ratio: what trimming costs." ;;
	bench_track) echo "Coherent tracking (\`px_track\`, \`px_strack\`) on moving-point paths (smooth random paths and sums of sinusoids, steps of 0.01 %, 0.1 %, 1 % and 5 % of the model size) next to the cold global query on the same points: per-update median, p99, p99.9 and max, the work's own worst case (\`max_min3\`: each update's least time over three replayed runs), ratios, transitions, cells solved and wrong answers (must be 0); for each surface, the tracked path's median and p99 over the cold query's per step size and where it is never slower." ;;
	bench_python) echo "The Python package (\`python/\`, cffi): one \`Model.query()\` call on 10,000 random points next to \`proxima-query --stats\` on the same file and points. C: the tool's mean per timed query (wall clock, each query timed alone); Python: the call's thread CPU time per point (best and median of 7 calls); the ratio is Python's median over C's mean, and the answers must be equal bit for bit." ;;
	bench_pair_nurbs) echo "A NURBS part (rational bicubic sheet, 0.2 m) against a link mesh (torus, 1,024 triangles) and against another NURBS part, by \`px_pair_distance\`: the certified descent of both hierarchies (\`geom/pair/pair_nurbs.c\`) next to the general search by alternating projections (its peer, run on the same poses in the same process), cold over random separated poses and coherent along a path of 1 mm steps: each pose's least time over three identical calls, median and p99, results flagged possibly local, and the poses where the peer stays above the certified distance (missed the global minimum)." ;;
	*) echo "" ;;
	esac
}

cpu=$(sed -n 's/^model name[[:space:]]*:[[:space:]]*//p' /proc/cpuinfo 2>/dev/null | head -n 1)
[ -n "$cpu" ] || cpu=unknown
load=$(cut -d ' ' -f 1-3 /proc/loadavg 2>/dev/null || echo unknown)

started=$(date -u '+%Y-%m-%d %H:%M UTC')
all0=$(date +%s)

status=0
for b in "$@"; do
	n=$(basename "$b" .sh)
	echo "== $b"
	t0=$(date +%s)
	"$b" > "$log" 2>&1
	rc=$?
	t1=$(date +%s)
	cat "$log"
	if [ "$rc" -ne 0 ]; then
		echo "bench/report.sh: $b exited with status $rc" >&2
		status=1
		continue
	fi
	{
		echo
		echo "## $n"
		echo
		describe "$n"
		echo
		src=bench/$n.c
		[ -f "$src" ] || src=bench/$n.cpp
		if [ "${BENCH_SECTIONS:-0}" = 1 ]; then
			echo "\`$src\`, $((t1 - t0)) s, run alone on $(date -u '+%Y-%m-%d %H:%M UTC') (load average at its start: $(cut -d ' ' -f 1-3 /proc/loadavg 2>/dev/null || echo unknown)):"
		else
			echo "\`$src\`, $((t1 - t0)) s:"
		fi
		echo
		echo '```'
		cat "$log"
		echo '```'
	} >> "$body"
done
all1=$(date +%s)

if [ "${BENCH_SECTIONS:-0}" = 1 ]; then
	# each old section (from its "## name" line to the next "## ") is
	# replaced by the new one; names not in the report are appended
	if [ "$status" -ne 0 ] || [ ! -f "$out" ]; then
		echo "bench/report.sh: $out not written" >&2
		exit 1
	fi
	# and their rows of the header's table (a new benchmark's row after
	# the last one)
	for b in "$@"; do
		n=$(basename "$b" .sh)
		echo "| [\`$n\`](#$n) | $(describe "$n") |"
	done > "$log"
	awk -v newf="$body" -v rowf="$log" '
		BEGIN {
			while ((getline l < newf) > 0) {
				if (l ~ /^## /) { cur = substr(l, 4); order[++n] = cur }
				if (cur != "") sec[cur] = sec[cur] l "\n"
			}
			for (k in sec) sub(/\n+$/, "\n", sec[k])
			while ((getline l < rowf) > 0) {
				k = l; sub(/^\| \[`/, "", k); sub(/`.*/, "", k); row[k] = l
			}
		}
		/^\| \[`/ { k = $0; sub(/^\| \[`/, "", k); sub(/`.*/, "", k); intable = 1
			     if (k in row) { print row[k]; had[k] = 1; next } }
		intable && !/^\|/ { for (k in row) if (!(k in had)) print row[k]; intable = 0 }
		/^## / { if (skip) print ""
			 name = substr($0, 4); skip = (name in sec)
			 if (skip) { printf "%s", sec[name]; done[name] = 1 } }
		!skip { print }
		END { for (i = 1; i <= n; i++) if (!(order[i] in done)) printf "\n%s", sec[order[i]] }
	' "$out" > "$tmp" || exit 1
	mkdir -p "$(dirname "$out")" && cp "$tmp" "$out.tmp" && mv "$out.tmp" "$out" || exit 1
	echo "bench/report.sh: replaced sections of $out"
	exit 0
fi

{
	echo "# Benchmarks"
	echo
	echo "Current figures of every benchmark under \`bench/\`, written by"
	echo "\`make bench\` (\`bench/report.sh\`): each benchmark's output as it"
	echo "printed it. Timings depend on the machine and its load; ratios"
	echo "measured in one run move less than absolute times. Do not edit"
	echo "by hand: run \`make bench\` again."
	echo
	echo "- date: $started"
	echo "- machine: $(nproc) CPUs, $cpu"
	echo "- kernel: $(uname -sr)"
	echo "- load average at the start: $load"
	echo "- run time of all benchmarks: $((all1 - all0)) s"
	echo
	echo "| benchmark | what it compares |"
	echo "|---|---|"
	for b in "$@"; do
		n=$(basename "$b" .sh)
		echo "| [\`$n\`](#$n) | $(describe "$n") |"
	done
} > "$tmp"
cat "$body" >> "$tmp"

if [ "$status" -ne 0 ]; then
	echo "bench/report.sh: $out not written" >&2
	exit 1
fi
mkdir -p "$(dirname "$out")" && cp "$tmp" "$out.tmp" && mv "$out.tmp" "$out" || exit 1
echo "bench/report.sh: wrote $out"
