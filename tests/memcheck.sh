#!/bin/sh
# valgrind memcheck over the tools on sample inputs: proxima-query on
# free-form OBJ, OBJ faces, STL, PLY (mesh and cloud) and XYZ models (also
# --track and --stats), proxima-run --check on every example config and a
# short --virtual-time run of the haptic and CAN examples, proxima-probe.
# Every run must report no error and no leak ("definitely", "indirectly"
# and "possibly" lost all zero; still-reachable memory of libraries is
# allowed). Run by `make memcheck` after `make`; prints one line per run
# and ends with "memcheck: N passed, N failed, 0 skipped".
# BUILD (default build) is where the tools are; MEMCHECK_SECONDS (default
# 0.5) is the simulated duration of the --virtual-time runs.
set -u
build=${BUILD:-build}
secs=${MEMCHECK_SECONDS:-0.5}
bin=$build/bin
if ! command -v valgrind >/dev/null 2>&1; then
	echo "memcheck: valgrind not installed (apt-get install valgrind)"
	echo "memcheck: 0 passed, 0 failed, 1 skipped"
	exit 0
fi
for t in proxima-query proxima-run proxima-probe; do
	if [ ! -x "$bin/$t" ]; then
		echo "memcheck: $bin/$t missing (run make first)"
		echo "memcheck: 0 passed, 1 failed, 0 skipped"
		exit 1
	fi
done
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
pass=0 fail=0

# Sample inputs written here: a tetrahedron as PLY mesh, a PLY cloud, an
# XYZ cloud, OBJ faces; query points around them.
cat >"$tmp/tet.ply" <<'EOF'
ply
format ascii 1.0
element vertex 4
property float x
property float y
property float z
element face 4
property list uchar int vertex_indices
end_header
0 0 0
1 0 0
0 1 0
0 0 1
3 0 2 1
3 0 1 3
3 0 3 2
3 1 2 3
EOF
cat >"$tmp/cloud.ply" <<'EOF'
ply
format ascii 1.0
element vertex 5
property double x
property double y
property double z
end_header
0 0 0
1 0 0
0 1 0
0 0 1
0.5 0.5 0.5
EOF
printf '# x y z\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n0.2 0.3 0.4\n' >"$tmp/cloud.xyz"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n' >"$tmp/tet.obj"
printf '0.1,0.2,0.3\n2,0,0\n-1,-1,-1\n0.25,0.25,0.25\n0,0,5\n' >"$tmp/points.csv"
i=0
while [ $i -lt 40 ]; do
	echo "$i" | awk '{ t = $1 / 40.0; printf "%.6f,%.6f,%.6f\n", 0.5 + cos(6.28 * t), sin(6.28 * t), 0.2 }'
	i=$((i + 1))
done >"$tmp/path.csv"

run() {
	name=$1
	shift
	log="$tmp/vg.log"
	valgrind --tool=memcheck --leak-check=full --show-leak-kinds=definite,indirect,possible \
		--errors-for-leak-kinds=definite,indirect,possible --error-exitcode=99 \
		--log-file="$log" "$@" >"$tmp/out.txt" 2>&1
	rc=$?
	errs=$(sed -n 's/.*ERROR SUMMARY: \([0-9]*\) errors.*/\1/p' "$log" | tail -n 1)
	lost=$(grep -E '(definitely|indirectly|possibly) lost: [1-9]' "$log" | head -n 1)
	if [ "$rc" = 99 ] || [ "${errs:-1}" != 0 ] || [ -n "$lost" ]; then
		echo "FAIL $name (exit $rc, errors ${errs:-?}) $lost"
		sed -n '1,60p' "$log"
		fail=$((fail + 1))
	else
		# the tool's own exit status is what it is (e.g. 2 for a refused
		# config); memcheck only judges memory
		heap=$(grep -E 'total heap usage' "$log" | sed 's/.*total heap usage: //')
		echo "ok   $name (exit $rc; $heap)"
		pass=$((pass + 1))
	fi
}

data=tests/data
run "query free-form OBJ" "$bin/proxima-query" "$data/bicubic.obj" "$tmp/points.csv"
run "query OBJ curves --track" "$bin/proxima-query" --track "$data/circle.obj" "$tmp/path.csv"
run "query OBJ multi --stats" "$bin/proxima-query" --stats "$data/multi.obj" "$tmp/points.csv"
run "query OBJ faces" "$bin/proxima-query" "$tmp/tet.obj" "$tmp/points.csv"
run "query STL" "$bin/proxima-query" config/examples/scenes/knob.stl "$tmp/points.csv"
run "query PLY mesh" "$bin/proxima-query" "$tmp/tet.ply" "$tmp/points.csv"
run "query PLY cloud" "$bin/proxima-query" "$tmp/cloud.ply" "$tmp/points.csv"
run "query XYZ cloud" "$bin/proxima-query" "$tmp/cloud.xyz" "$tmp/points.csv"
run "query missing file" "$bin/proxima-query" "$tmp/nothing.stl" "$tmp/points.csv"
for c in config/examples/*.yaml; do
	run "run --check $(basename "$c")" "$bin/proxima-run" --check "$c"
done
run "run --check bad config" "$bin/proxima-run" --check fuzz/corpus/config/errors.yaml
run "run --virtual-time haptic_sim" "$bin/proxima-run" config/examples/haptic_sim.yaml \
	--virtual-time --duration-s "$secs" --summary-json "$tmp/s.json" --telemetry "$tmp/t.csv"
run "run --virtual-time haptic_faults" "$bin/proxima-run" config/examples/haptic_faults.yaml \
	--virtual-time --duration-s "$secs"
run "run --virtual-time can_avoid_sim" "$bin/proxima-run" config/examples/can_avoid_sim.yaml \
	--virtual-time --duration-s "$secs"
run "probe" "$bin/proxima-probe"
run "probe --lines" "$bin/proxima-probe" --lines

echo "memcheck: $pass passed, $fail failed, 0 skipped"
[ "$fail" -eq 0 ]
