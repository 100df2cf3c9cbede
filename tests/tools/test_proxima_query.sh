#!/bin/sh
# proxima-query's contract (issue: distance core): output format, exact
# distances on models with known geometry, header handling, and clear
# errors with their place. Prints a harness-style summary line.
# PX_TEST_NEEDS: assimp (tests/run.sh skips it in builds without)
set -u
name=test_proxima_query
bin="${BUILD:-build}/bin/proxima-query"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
pass=0 fail=0
ok() { echo "ok   $1"; pass=$((pass + 1)); }
bad() { echo "FAIL $1"; sed 's/^/    /' "$tmp/out" "$tmp/err" 2>/dev/null | head -20; fail=$((fail + 1)); }
expect() { # DESCRIPTION STATUS COMMAND...
	d=$1 want=$2; shift 2
	"$@" >"$tmp/out" 2>"$tmp/err"
	got=$?
	if [ "$got" -eq "$want" ]; then ok "$d (exit $got)"; else
		echo "    exit status $got, expected $want"; bad "$d"; fi
}
err_has() { # DESCRIPTION EXTENDED-REGEX on stderr
	if grep -qE -- "$2" "$tmp/err"; then ok "$1"; else
		echo "    stderr lacks /$2/"; bad "$1"; fi
}

# Query points: a deterministic spread, including the centres (every
# point of a circle or sphere is then a foot point), far points and
# points exactly on the models.
awk 'BEGIN { s = 12345; print "x,y,z";
	for (i = 0; i < 300; i++) {
		s = (s * 1103515245 + 12345) % 2147483648; x = s / 2147483648 * 12 - 5;
		s = (s * 1103515245 + 12345) % 2147483648; y = s / 2147483648 * 12 - 7;
		s = (s * 1103515245 + 12345) % 2147483648; z = s / 2147483648 * 6 - 3;
		printf "%.17g,%.17g,%.17g\n", x, y, z }
	print "1,-1,0.5"; print "0,0,0"; print "300,200,-100"; print "3,-1,0.5" }' >"$tmp/pts.csv"

# Circle: radius 2, centre (1, -1, 0.5) in the plane z = 0.5.
expect "circle model" 0 "$bin" tests/data/circle.obj "$tmp/pts.csv"
if [ "$(wc -l <"$tmp/out")" -eq 304 ]; then ok "one output line per point (header skipped)"; else bad "one output line per point"; fi
if awk -F, 'NF != 6 { exit 1 } $6 != 0 { exit 1 }' "$tmp/out"; then ok "six fields, v = 0 for curves"; else bad "six fields, v = 0 for curves"; fi
tail -n +2 "$tmp/pts.csv" | paste -d, - "$tmp/out" >"$tmp/joined"
if awk -F, 'function abs(a) { return a < 0 ? -a : a }
	{ rho = sqrt(($1 - 1)^2 + ($2 + 1)^2); want = sqrt((rho - 2)^2 + ($3 - 0.5)^2);
	  if (abs($4 - want) > 1e-9) { print "point " NR ": " $4 " vs " want; bad = 1 }
	  # the reported point is on the circle and at the reported distance
	  if (abs(sqrt(($5 - 1)^2 + ($6 + 1)^2) - 2) > 1e-9 || abs($7 - 0.5) > 1e-12) { print "point " NR " off the circle"; bad = 1 }
	  d = sqrt(($1 - $5)^2 + ($2 - $6)^2 + ($3 - $7)^2); if (abs(d - $4) > 1e-9) { print "point " NR ": dist mismatch"; bad = 1 } }
	END { exit bad }' "$tmp/joined" >"$tmp/err"; then ok "circle distances exact (1e-9)"; else bad "circle distances exact"; fi
# %.17g: irrational distances show 16-17 significant digits.
if grep -qE '^[0-9]\.[0-9]{15,16}(e[+-][0-9]+)?,' "$tmp/out"; then ok "numbers printed with %.17g"; else bad "numbers printed with %.17g"; fi

# Sphere: radius 1.5 about the origin.
expect "sphere model" 0 "$bin" tests/data/sphere.obj "$tmp/pts.csv"
tail -n +2 "$tmp/pts.csv" | paste -d, - "$tmp/out" >"$tmp/joined"
if awk -F, 'function abs(a) { return a < 0 ? -a : a }
	{ r = sqrt($1^2 + $2^2 + $3^2); want = abs(r - 1.5);
	  if (abs($4 - want) > 1e-9) { print "point " NR ": " $4 " vs " want; bad = 1 }
	  if (abs(sqrt($5^2 + $6^2 + $7^2) - 1.5) > 1e-9) { print "point " NR " off the sphere"; bad = 1 } }
	END { exit bad }' "$tmp/joined" >"$tmp/err"; then ok "sphere distances exact (1e-9)"; else bad "sphere distances exact"; fi

# Bicubic: S(u, v) = (u, v, u^2 + v/2); the parameters of the answer
# reproduce its point.
expect "bicubic model" 0 "$bin" tests/data/bicubic.obj "$tmp/pts.csv"
if awk -F, 'function abs(a) { return a < 0 ? -a : a }
	{ if (abs($2 - $5) > 1e-9 || abs($3 - $6) > 1e-9 || abs($4 - ($5 * $5 + $6 / 2)) > 1e-9) { print "line " NR; bad = 1 }
	  if ($5 < 0 || $5 > 1 || $6 < 0 || $6 > 1) { print "line " NR " outside the domain"; bad = 1 } }
	END { exit bad }' "$tmp/out" >"$tmp/err"; then ok "bicubic points match their parameters"; else bad "bicubic points match their parameters"; fi

# --stats goes to stderr with the documented fields.
expect "--stats" 0 "$bin" --stats tests/data/circle.obj "$tmp/pts.csv"
err_has "stats: setup time" '^setup_ms [0-9.]+$'
err_has "stats: model memory" '^model_bytes [0-9]+$'
err_has "stats: per-query ns" '^queries 304 query_ns min [0-9]+ median [0-9]+ p99 [0-9]+ max [0-9]+$'

# Errors: clear message with the place, non-zero exit.
# --track: the points as one moving point, answered by the tracker. A
# smooth path (small steps, crossing the circle's centre region and the
# curves' evolutes) and the scattered points above (large jumps, far
# points) must give the same distances as the global query.
awk 'BEGIN { print "x,y,z"; for (i = 0; i < 3000; i++) { t = i / 3000;
	printf "%.17g,%.17g,%.17g\n", 1 + 2.6 * sin(6.2832 * t * 3) * cos(6.2832 * t),
		-1 + 2.2 * sin(6.2832 * t * 2), 0.5 + 0.8 * sin(6.2832 * t * 5) } }' >"$tmp/path.csv"
for model in circle continuation; do
	for pts in path pts; do
		expect "--track $model ($pts)" 0 "$bin" --track tests/data/$model.obj "$tmp/$pts.csv"
		cp "$tmp/out" "$tmp/track.out"
		"$bin" tests/data/$model.obj "$tmp/$pts.csv" >"$tmp/global.out" 2>/dev/null
		if paste -d, "$tmp/track.out" "$tmp/global.out" | awk -F, 'function abs(a) { return a < 0 ? -a : a }
			NF != 12 { print "line " NR ": " NF " fields"; bad = 1; next }
			abs($1 - $7) > 1e-9 * (1 + $7) { print "line " NR ": tracked " $1 " global " $7; bad = 1 }
			$6 != 0 { print "line " NR ": v not 0"; bad = 1 }
			END { exit bad }' >"$tmp/err"; then
			ok "--track $model ($pts): same distances as the global query"
		else bad "--track $model ($pts): same distances as the global query"; fi
	done
done
expect "--track --stats" 0 "$bin" --track --stats tests/data/circle.obj "$tmp/path.csv"
err_has "--track stats: tracker counters" '^track_updates 3000 leaf_solves [0-9]+ created [0-9]+ annihilated [0-9]+ reinits [0-9]+ outside [0-9]+ fallbacks 0$'
err_has "--track stats: hot-path counters" '^track_hot [1-9][0-9]* rested [0-9]+ rested_entities [0-9]+$'
err_has "--track stats: cold-switch counters" '^track_cold [0-9]+ entered [0-9]+ left [0-9]+ tracked_ns [0-9]+ cold_ns [1-9][0-9]*$'
# Surfaces (px_strack): the bicubic patch and the rational sphere (poles,
# a closed seam) along the same paths; u and v must reproduce the point.
for model in bicubic sphere; do
	for pts in path pts; do
		expect "--track $model ($pts)" 0 "$bin" --track tests/data/$model.obj "$tmp/$pts.csv"
		cp "$tmp/out" "$tmp/track.out"
		"$bin" tests/data/$model.obj "$tmp/$pts.csv" >"$tmp/global.out" 2>/dev/null
		if paste -d, "$tmp/track.out" "$tmp/global.out" | awk -F, 'function abs(a) { return a < 0 ? -a : a }
			NF != 12 { print "line " NR ": " NF " fields"; bad = 1; next }
			abs($1 - $7) > 1e-9 * (1 + $7) { print "line " NR ": tracked " $1 " global " $7; bad = 1 }
			END { exit bad }' >"$tmp/err"; then
			ok "--track $model ($pts): same distances as the global query"
		else bad "--track $model ($pts): same distances as the global query"; fi
	done
done
expect "--track --stats surface" 0 "$bin" --track --stats tests/data/bicubic.obj "$tmp/path.csv"
# (fallbacks: updates over the work budget are answered by the global query)
err_has "--track stats: surface tracker counters" '^strack_updates 3000 cell_solves [0-9]+ reinits [0-9]+ outside [0-9]+ fallbacks [0-9]+$'
err_has "--track stats: surface budget counters" '^strack_over_budget [0-9]+ catching_up [0-9]+ curve_skips [0-9]+$'
err_has "--track stats: surface hot-path counter" '^strack_hot [0-9]+$'
err_has "--track stats: surface cold-switch counters" '^strack_cold [0-9]+ entered [0-9]+ left [0-9]+ tracked_ns [0-9]+ cold_ns [1-9][0-9]*$'
expect "--track refuses faces clearly" 2 "$bin" --track tests/data/multi.obj "$tmp/pts.csv"
err_has "--track with faces says why" 'free-form curves and surfaces only'
printf '1,2,3\n4,nan,6\n' >"$tmp/nan.csv"
expect "NaN point" 1 "$bin" tests/data/circle.obj "$tmp/nan.csv"
err_has "NaN point: file:line" "nan.csv:2: field 2: not a finite number"
printf '1,2\n' >"$tmp/short.csv"
expect "two fields" 1 "$bin" tests/data/circle.obj "$tmp/short.csv"
err_has "two fields: file:line" "short.csv:1: "
expect "missing model" 1 "$bin" "$tmp/none.obj" "$tmp/pts.csv"
err_has "missing model named" "none.obj"
expect "missing points" 1 "$bin" tests/data/circle.obj "$tmp/none.csv"
err_has "missing points named" "none.csv"
printf 'v 0 0 0\nv 1 0 0\ncstype bspline\ndeg 3\ncurv 0 1 1 2\nparm u 0 0 0 0 1 1 1 1\nend\n' >"$tmp/bad.obj"
expect "malformed OBJ" 1 "$bin" "$tmp/bad.obj" "$tmp/pts.csv"
err_has "malformed OBJ: file:line:column" 'bad.obj:[0-9]+:[0-9]+: '
# Meshes and clouds: the unit cube [0,1]^3 as an ASCII STL (12
# triangles) and as OBJ faces, and its 8 corners as a point cloud.
awk 'function v(x, y, z) { printf "    vertex %d %d %d\n", x, y, z }
	function tri(a, b, c) { print "  facet normal 0 0 0"; print "   outer loop";
		v(X[a], Y[a], Z[a]); v(X[b], Y[b], Z[b]); v(X[c], Y[c], Z[c]);
		print "   endloop"; print "  endfacet" }
	BEGIN { for (i = 0; i < 8; i++) { X[i] = i % 2; Y[i] = int(i / 2) % 2; Z[i] = int(i / 4) }
		print "solid cube";
		tri(0, 2, 1); tri(1, 2, 3); tri(4, 5, 6); tri(5, 7, 6);
		tri(0, 1, 4); tri(1, 5, 4); tri(2, 6, 3); tri(3, 6, 7);
		tri(0, 4, 2); tri(2, 4, 6); tri(1, 3, 5); tri(3, 7, 5);
		print "endsolid cube" }' >"$tmp/cube.stl"
awk 'BEGIN { for (i = 0; i < 8; i++) printf "v %d %d %d\n", i % 2, int(i / 2) % 2, int(i / 4);
	print "f 1 3 2"; print "f 2 3 4"; print "f 5 6 7"; print "f 6 8 7";
	print "f 1 2 5"; print "f 2 6 5"; print "f 3 7 4"; print "f 4 7 8";
	print "f 1 5 3"; print "f 3 5 7"; print "f 2 4 6"; print "f 4 8 6" }' >"$tmp/cube.obj"
awk 'BEGIN { for (i = 0; i < 8; i++) printf "%d,%d,%d\n", i % 2, int(i / 2) % 2, int(i / 4) }' >"$tmp/corners.xyz"
boxcheck='function abs(a) { return a < 0 ? -a : a }
	function gap(v) { return v < 0 ? -v : (v > 1 ? v - 1 : 0) }
	{ dx = gap($1); dy = gap($2); dz = gap($3);
	  if (dx + dy + dz > 0) want = sqrt(dx * dx + dy * dy + dz * dz);
	  else { want = $1; if (1 - $1 < want) want = 1 - $1; if ($2 < want) want = $2;
		 if (1 - $2 < want) want = 1 - $2; if ($3 < want) want = $3; if (1 - $3 < want) want = 1 - $3 }
	  if (abs($4 - want) > 1e-6) { print "point " NR ": " $4 " vs " want; bad = 1 }
	  if ($8 != int($8) || $8 < 0 || $8 > 11 || $9 != 0) { print "point " NR ": triangle index " $8; bad = 1 } }
	END { exit bad }'
for m in cube.stl cube.obj; do
	expect "mesh model $m" 0 "$bin" "$tmp/$m" "$tmp/pts.csv"
	tail -n +2 "$tmp/pts.csv" | paste -d, - "$tmp/out" >"$tmp/joined"
	if awk -F, "$boxcheck" "$tmp/joined" >"$tmp/err"; then ok "$m: box distances, unsigned, triangle index as u"; else bad "$m: box distances"; fi
done
expect "point cloud" 0 "$bin" "$tmp/corners.xyz" "$tmp/pts.csv"
tail -n +2 "$tmp/pts.csv" | paste -d, - "$tmp/out" >"$tmp/joined"
if awk -F, 'function abs(a) { return a < 0 ? -a : a }
	{ best = 1e300; for (i = 0; i < 8; i++) { d = sqrt(($1 - i % 2)^2 + ($2 - int(i / 2) % 2)^2 + ($3 - int(i / 4))^2); if (d < best) { best = d; bi = i } }
	  if (abs($4 - best) > 1e-9) { print "point " NR ": " $4 " vs " best; bad = 1 }
	  if ($8 != bi && abs(sqrt(($1 - $5)^2 + ($2 - $6)^2 + ($3 - $7)^2) - best) > 1e-9) { print "point " NR ": index " $9; bad = 1 } }
	END { exit bad }' "$tmp/joined" >"$tmp/err"; then ok "cloud distances and point index"; else bad "cloud distances and point index"; fi
printf 'solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n' >"$tmp/broken.stl"
expect "truncated STL" 1 "$bin" "$tmp/broken.stl" "$tmp/pts.csv"
err_has "truncated STL named" 'broken.stl'
# Hostile points and models: NUL bytes end in an error with their place
# instead of a loop over "blank" lines, a first line NaN is a point (and
# an error), not a header, an empty field names itself, and a cloud whose
# extent overflows is refused at setup instead of crashing.
expect "points from /dev/zero" 1 timeout 20 "$bin" tests/data/circle.obj /dev/zero
err_has "points from /dev/zero: file:line:column" "/dev/zero:1:1: NUL byte"
printf '1,2,3\n4,5\0006\n' >"$tmp/nul.csv"
expect "NUL inside a points line" 1 "$bin" tests/data/circle.obj "$tmp/nul.csv"
err_has "NUL inside a points line: file:line:column" "nul.csv:2:4: NUL byte"
printf 'NaN,0,0\n1,2,3\n' >"$tmp/nanfirst.csv"
expect "NaN first line" 1 "$bin" tests/data/circle.obj "$tmp/nanfirst.csv"
err_has "NaN first line: file:line:field" "nanfirst.csv:1: field 1: not a finite number"
printf 'x,y,z\n1,,3\n' >"$tmp/emptyfield.csv"
expect "empty field" 1 "$bin" tests/data/circle.obj "$tmp/emptyfield.csv"
err_has "empty field: file:line:field" "emptyfield.csv:2: field 2 is empty"
printf '0 0 0\n1e308 0 0\n-1e308 1 1\n' >"$tmp/e308.xyz"
expect "cloud at 1e308" 1 "$bin" "$tmp/e308.xyz" "$tmp/pts.csv"
err_has "cloud at 1e308: file:line:field" 'e308.xyz:2: field 1: coordinate 1e\+308 beyond'
truncate -s $((64 * 1024 * 1024 + 1)) "$tmp/big.csv"
expect "points file over 64 MiB" 1 timeout 20 "$bin" tests/data/circle.obj "$tmp/big.csv"
err_has "points file over 64 MiB: named with the limit" "big.csv: larger than the 64 MiB limit for points files"
truncate -s $((1024 * 1024 * 1024 + 1)) "$tmp/big.stl"
expect "model over 1 GiB" 1 timeout 20 "$bin" "$tmp/big.stl" "$tmp/pts.csv"
err_has "model over 1 GiB: named with the limit" "big.stl: larger than the 1 GiB limit for model files"
rm -f "$tmp/big.csv" "$tmp/big.stl"
ln -s /dev/zero "$tmp/zero.xyz"
expect "model from /dev/zero as a cloud" 1 timeout 20 "$bin" "$tmp/zero.xyz" "$tmp/pts.csv"
err_has "model from /dev/zero: file:line:column" "zero.xyz:1:1: NUL byte"
expect "unknown option" 2 "$bin" --frobnicate tests/data/circle.obj "$tmp/pts.csv"
expect "missing arguments" 2 "$bin" tests/data/circle.obj

# --signed: closed meshes answer inside negative; free-form models stay
# unsigned and say so once.
printf '0.5,0.5,0.25\n2,0.5,0.5\n' >"$tmp/inout.csv"
expect "--signed closed mesh" 0 "$bin" --signed "$tmp/cube.stl" "$tmp/inout.csv"
if awk -F, 'NF != 6 { exit 1 } NR == 1 && $1 != -0.25 { exit 1 } NR == 2 && $1 != 1 { exit 1 }' "$tmp/out"; then
	ok "--signed closed mesh: -0.25 inside, 1 outside, six fields"; else bad "--signed closed mesh: signs"; fi
expect "--signed on curves" 0 "$bin" --signed tests/data/circle.obj "$tmp/inout.csv"
if [ "$(grep -c 'distances are unsigned' "$tmp/err")" -eq 1 ]; then ok "--signed on curves: unsigned, said once"; else bad "--signed on curves: said once"; fi
if awk -F, '$1 < 0 { exit 1 }' "$tmp/out"; then ok "--signed on curves: no negative distance"; else bad "--signed on curves: no negative distance"; fi
printf 'solid x\nendsolid x\n' >"$tmp/part.unknownext"
expect "unknown extension tried as a mesh" 1 "$bin" "$tmp/part.unknownext" "$tmp/inout.csv"
err_has "unknown extension: named" 'part\.unknownext'

# STEP parts (the shipped block: 60 x 40 x 20 mm from the origin, a 12 mm
# hole along z through (30, 20) mm, read in metres): inside, in the hole,
# outside; signed with --signed only.
skip=0
block=config/examples/parts/filleted_block.step
printf 'x,y,z\n0.01,0.02,0.01\n0.03,0.02,0.01\n0.015,0.02,0.05\n0.03,0.02,0.05\n' >"$tmp/block.csv"
if ! grep -qx '#define PX_HAVE_OCCT 1' "${BUILD:-build}/gen/px_features.h"; then
	expect "STEP without OpenCASCADE" 1 "$bin" "$block" "$tmp/block.csv"
	err_has "STEP without OpenCASCADE: says so, names the file" 'filleted_block\.step: .*built without OpenCASCADE'
	echo "skip STEP queries: built without OpenCASCADE"; skip=$((skip + 1))
elif [ "${SAN:-}" = 1 ]; then
	echo "skip STEP queries: OpenCASCADE's global allocations show as leaks under ASan"; skip=$((skip + 1))
else
	expect "STEP --signed" 0 "$bin" --signed "$block" "$tmp/block.csv"
	if [ ! -s "$tmp/err" ]; then ok "STEP --signed: closed, nothing on stderr"; else bad "STEP --signed: quiet stderr"; fi
	if awk -F, 'function abs(a) { return a < 0 ? -a : a }
		NF != 6 { print "line " NR ": " NF " fields"; bad = 1 }
		NR == 1 && abs($1 + 0.01) > 1e-12 { print "inside: " $1; bad = 1 }
		NR == 2 && abs($1 - 0.006) > 1e-12 { print "in the hole: " $1; bad = 1 }
		NR == 3 && abs($1 - 0.03) > 1e-12 { print "above: " $1; bad = 1 }
		NR == 3 && (abs($2 - 0.015) > 1e-12 || abs($3 - 0.02) > 1e-12 || abs($4 - 0.02) > 1e-12) { print "above: foot " $2 "," $3 "," $4; bad = 1 }
		END { exit bad }' "$tmp/out" >"$tmp/err"; then
		ok "STEP --signed: -10 mm inside, +6 mm in the hole, +30 mm above"; else bad "STEP --signed: distances"; fi
	# above the hole: the nearest point is on its rim (radius 6 mm)
	if awk -F, 'function abs(a) { return a < 0 ? -a : a }
		NR == 4 { if (abs($1 - sqrt(0.006^2 + 0.03^2)) > 1e-12 || abs(sqrt(($2 - 0.03)^2 + ($3 - 0.02)^2) - 0.006) > 1e-12 || abs($4 - 0.02) > 1e-12) exit 1 }' "$tmp/out"; then
		ok "STEP: above the hole, the rim"; else bad "STEP: above the hole, the rim"; fi
	cp "$tmp/out" "$tmp/signed.out"
	expect "STEP unsigned" 0 "$bin" "$block" "$tmp/block.csv"
	if awk -F, 'NR == 1 && ($1 < 0.00999 || $1 > 0.01001) { exit 1 } $1 < 0 { exit 1 }' "$tmp/out"; then
		ok "STEP without --signed: unsigned"; else bad "STEP without --signed: unsigned"; fi
	# the same foot points and face parameters either way
	if [ "$(cut -d, -f2- "$tmp/out")" = "$(cut -d, -f2- "$tmp/signed.out")" ]; then
		ok "STEP: same points and (u, v) signed or not"; else bad "STEP: same points and (u, v)"; fi
	expect "STEP --track refused" 2 "$bin" --track "$block" "$tmp/block.csv"
	err_has "STEP --track says why" 'coherent tracking supports'
	printf 'ISO-10303-21;\nthis is not STEP\n' >"$tmp/bad.step"
	expect "malformed STEP" 1 "$bin" "$tmp/bad.step" "$tmp/block.csv"
	err_has "malformed STEP named" 'bad\.step'
	expect "missing STEP" 1 "$bin" "$tmp/none.stp" "$tmp/block.csv"
	err_has "missing STEP named" 'none\.stp'
fi

# Trimmed OBJ: a 2 x 2 plane sheet with a rational circular hole of
# radius 0.5 about (1, 1), read as a B-rep: exact distances.
cp fuzz/corpus/objtrim/hole_circle.obj "$tmp/hole.obj"
printf '1,1,0.3\n1.2,1,0\n0.5,0.5,0.2\n3,1,0\n' >"$tmp/hole.csv"
expect "trimmed OBJ" 0 "$bin" "$tmp/hole.obj" "$tmp/hole.csv"
if awk -F, 'function abs(a) { return a < 0 ? -a : a }
	NF != 6 { bad = 1 }
	NR == 1 && abs($1 - sqrt(0.25 + 0.09)) > 1e-12 { print "above the hole: " $1; bad = 1 }
	NR == 2 && abs($1 - 0.3) > 1e-12 { print "in the hole: " $1; bad = 1 }
	NR == 3 && abs($1 - 0.2) > 1e-12 { print "above the sheet: " $1; bad = 1 }
	NR == 4 && abs($1 - 1) > 1e-12 { print "beside: " $1; bad = 1 }
	END { exit bad }' "$tmp/out" >"$tmp/err"; then
	ok "trimmed OBJ: the hole's rim and the sheet, exact"; else bad "trimmed OBJ: distances"; fi
expect "trimmed OBJ --track refused" 2 "$bin" --track "$tmp/hole.obj" "$tmp/hole.csv"
err_has "trimmed OBJ --track says why" 'global queries only'
sed 's/^hole 0 4 1$/hole 0 2 1/' "$tmp/hole.obj" >"$tmp/half.obj"
expect "trimmed OBJ with an open loop" 1 "$bin" "$tmp/half.obj" "$tmp/hole.csv"
err_has "open loop named with its line" 'half\.obj:24:1: .*is open'

echo "$name: $pass passed, $fail failed, $skip skipped"
[ "$fail" -eq 0 ]
