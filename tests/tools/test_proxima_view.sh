#!/bin/sh
# proxima-view and proxima-run --view: the replay served (hello, scene,
# a track equal to the CSV), the report page (the data at the marker is
# valid JSON and holds every row), refused inputs named by file and line,
# and a live view whose port is taken leaving the run as it was. A
# WebSocket client in Python (the standard library only).
# PX_TEST_NEEDS: libwebsockets
set -u
name=test_proxima_view
b=${BUILD:-build}
view=$b/bin/proxima-view
run=$b/bin/proxima-run
pass=0 fail=0 skip=0
check() { # description, command...
	d=$1; shift
	if "$@" >"$tmp/out" 2>&1; then echo "ok   $d"; pass=$((pass + 1))
	else echo "FAIL $d"; sed 's/^/    /' "$tmp/out" | head -n 30; fail=$((fail + 1)); fi
}
tmp=$(mktemp -d)
pids=""
trap 'for p in $pids; do kill "$p" 2>/dev/null; done; rm -rf "$tmp"' EXIT
py=${PYTHON:-python3}
if ! command -v "$py" >/dev/null 2>&1; then
	echo "skip: no $py"
	echo "$name: 0 passed, 0 failed, 1 skipped"
	exit 0
fi
free_port() {
	"$py" -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'
}
mkdir -p "$tmp/web"
echo '<html><body>replay</body></html>' >"$tmp/web/index.html"
printf '<html><script>const D = /*PX_VIEW_DATA*/null;</script></html>\n' >"$tmp/tpl.html"
cfg=config/examples/haptic_sim.yaml
# two telemetry CSVs the same but for the compute time (the wall clock)
same_run() { cut -d, -f1-17,19- "$1" >"$1.cut"; cut -d, -f1-17,19- "$2" >"$2.cut"; cmp -s "$1.cut" "$2.cut"; }

# a run to replay
"$run" "$cfg" --virtual-time --duration-s 0.3 --telemetry "$tmp/t.csv" \
	--summary-json "$tmp/run-summary.json" >"$tmp/run.out" 2>&1
check "the run to replay" test -s "$tmp/t.csv"

cat >"$tmp/ws.py" <<'PY'
import csv, json, socket, struct, sys
port, csv_path = int(sys.argv[1]), sys.argv[2]
s = socket.create_connection(("127.0.0.1", port), timeout=10)
s.sendall(("GET /ws HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\n"
           "Connection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
           "Sec-WebSocket-Version: 13\r\nSec-WebSocket-Protocol: proxima-view.v1\r\n\r\n").encode())
buf = b""
while b"\r\n\r\n" not in buf:
    buf += s.recv(1)
assert buf.startswith(b"HTTP/1.1 101"), buf
def exact(n):
    out = b""
    while len(out) < n:
        k = s.recv(n - len(out))
        assert k, "closed"
        out += k
    return out
def message():
    data = b""
    while True:
        h = exact(2)
        n = h[1] & 0x7F
        if n == 126: n = struct.unpack(">H", exact(2))[0]
        elif n == 127: n = struct.unpack(">Q", exact(8))[0]
        data += exact(n)
        if h[0] & 0x80: return json.loads(data)
hello, scene, track = message(), message(), message()
assert hello["type"] == "hello" and hello["mode"] == "replay", hello
assert scene["type"] == "scene" and len(scene["models"]) == 3, scene.keys()
assert track["type"] == "track", track.keys()
rows = list(csv.DictReader(open(csv_path)))
assert len(track["frames"]) == len(rows), (len(track["frames"]), len(rows))
for f, r in zip(track["frames"], rows):
    assert abs(f["t_s"] - float(r["t_s"])) < 1e-9
    assert f["cycle"] == int(r["cycle"])
    for a, k in zip(f["tool"], ("x_m", "y_m", "z_m")):
        assert abs(a - float(r[k])) <= 1e-9 * max(1.0, abs(a)), (a, r[k])
assert track["summary"]["cycles"] == 300, track["summary"].get("cycles")
print("track of", len(rows), "frames")
PY

# served
port=$(free_port)
"$view" --port "$port" --config "$cfg" --web-root "$tmp/web" --rate 0 "$tmp/t.csv" >"$tmp/serve.out" 2>&1 &
vp=$!
pids="$pids $vp"
i=0
while [ $i -lt 50 ] && ! grep -q "http://127.0.0.1:$port/" "$tmp/serve.out"; do sleep 0.1; i=$((i + 1)); done
check "proxima-view says its URL" grep -q "300 frames at http://127.0.0.1:$port/" "$tmp/serve.out"
check "the page is served" sh -c "'$py' -c 'import urllib.request,sys; sys.exit(urllib.request.urlopen(\"http://127.0.0.1:$port/\").status != 200)'"
check "hello, scene, and a track equal to the CSV" "$py" "$tmp/ws.py" "$port" "$tmp/t.csv"
kill -TERM "$vp"
wait "$vp"; rc=$?
check "ends with status 0 on SIGTERM" test "$rc" -eq 0

# the report
check "--html writes the report" "$view" --html "$tmp/r.html" --config "$cfg" --rate 0 \
	--template "$tmp/tpl.html" "$tmp/t.csv"
cat >"$tmp/report.py" <<'PY'
import csv, json, sys
s = open(sys.argv[1]).read()
data = s[s.index("const D = ") + 10:s.rindex(";</script>")]
d = json.loads(data)
rows = list(csv.DictReader(open(sys.argv[2])))
assert set(d) == {"scene", "track"}, d.keys()
assert len(d["track"]["frames"]) == len(rows)
assert d["track"]["summary"]["cycles"] == 300
assert [m["name"] for m in d["scene"]["models"]] == ["terrain", "knob", "post"]
assert all(len(m["positions"]) > 0 for m in d["scene"]["models"])
assert s.startswith("<html><script>const D = ") and s.endswith(";</script></html>\n")
PY
check "the data at the marker is valid JSON with every row" "$py" "$tmp/report.py" "$tmp/r.html" "$tmp/t.csv"

# the track thinned to 60 frames a second of loop time, every contact
# change kept, with the closest point on the scene
"$run" "$cfg" --virtual-time --duration-s 2 --telemetry "$tmp/long.csv" >/dev/null 2>&1
check "--html thins the track" "$view" --html "$tmp/thin.html" --config "$cfg" \
	--template "$tmp/tpl.html" "$tmp/long.csv"
# the report's data (the template above), the CSV's rows, the frames
cat >"$tmp/page.py" <<'PY'
import csv, json, sys
s = open(sys.argv[1]).read()
d = json.loads(s[s.index("const D = ") + 10:s.rindex(";</script>")])
rows = list(csv.DictReader(open(sys.argv[2])))
fr = d["track"]["frames"]
PY
cat >"$tmp/thin.py" <<'PY'
from page import d, rows, fr
assert len(rows) == 2000 and 110 <= len(fr) < 400, (len(rows), len(fr))
assert fr[0]["cycle"] == int(rows[0]["cycle"]) and fr[-1]["cycle"] == int(rows[-1]["cycle"])
ts = [f["t_s"] for f in fr]
assert ts == sorted(ts)
changes = [int(b["cycle"]) for a, b in zip(rows, rows[1:]) if a["contact"] != b["contact"]]
assert changes, "the run touches"
kept = {f["cycle"] for f in fr}
assert all(c in kept for c in changes), [c for c in changes if c not in kept]
gaps = [b - a for a, b in zip(ts, ts[1:])]
assert max(gaps) < 1 / 60 + 1.5e-3, max(gaps)
assert all(f["closest"] is not None and len(f["closest"]) == 3 for f in fr)
assert "links" not in fr[0] and d["scene"]["robot"] is None
print(len(rows), "rows,", len(fr), "frames,", len(changes), "contact changes")
PY
check "... to 60 Hz, every contact change and the last row kept, closest points" \
	"$py" "$tmp/thin.py" "$tmp/thin.html" "$tmp/long.csv"

# an arm: its links from the joint positions the CSV carries (the box
# comes within the influence distance after 5 s)
acfg=config/examples/can_avoid_urdf.yaml
if "$run" "$acfg" --check >/dev/null 2>&1; then
	"$run" "$acfg" --virtual-time --duration-s 7 --telemetry "$tmp/arm.csv" >/dev/null 2>&1
	check "--html of an arm run" "$view" --html "$tmp/arm.html" --config "$acfg" \
		--template "$tmp/tpl.html" "$tmp/arm.csv"
	cat >"$tmp/arm.py" <<'PY'
from page import d, rows, fr
robot = d["scene"]["robot"]
n = len(robot["links"])
assert n == 7 and all(len(l["positions"]) and len(l["indices"]) for l in robot["links"]), n
assert robot["protective_distance_m"] == 0.05 and robot["influence_distance_m"] == 0.25
assert all(len(f["links"]) == n and all(len(p) == 7 for p in f["links"]) for f in fr)
assert "q5_rad" in rows[0]
# the shoulder turns: the upper arm's link moves
xs = {round(f["links"][2][4], 4) for f in fr}
assert len(xs) > 20, len(xs)
pairs = [f["clearances"][0] for f in fr if "clearances" in f]
assert pairs and all(len(p) == 7 and p[6] < 0.25 for p in pairs), len(pairs)
assert all(f["closest"] is None for f in fr)
print(len(fr), "frames, links of", n, "moving,", len(pairs), "with the closest pair")
PY
	check "... draws its links moving and the closest pairs" "$py" "$tmp/arm.py" "$tmp/arm.html" "$tmp/arm.csv"
	# without joint positions in the CSV the arm is not drawn
	cut -d, -f1-26 "$tmp/arm.csv" >"$tmp/arm-noq.csv"
	check "... not without joint positions" sh -c "'$view' --html '$tmp/arm-noq.html' --config '$acfg' \
		--template '$tmp/tpl.html' '$tmp/arm-noq.csv' >/dev/null && grep -qF '\"robot\":null' '$tmp/arm-noq.html' &&
		! grep -qF '\"links\":' '$tmp/arm-noq.html'"
else
	echo "skip: $acfg needs the URDF part (libxml2)"
	skip=$((skip + 1))
fi

# refused inputs
long=$("$py" -c 'print("1," * 3000)')
{ head -n 3 "$tmp/t.csv"; echo "$long"; } >"$tmp/long.csv"
check "a long line: file:line" sh -c "'$view' --html '$tmp/x.html' --template '$tmp/tpl.html' '$tmp/long.csv' 2>&1 |
	grep -qF '$tmp/long.csv:4: line longer than'"
{ head -n 2 "$tmp/t.csv"; echo "0.5,x,1,2,3"; } >"$tmp/bad.csv"
check "a bad number: file:line and status 1" sh -c "'$view' --html '$tmp/x.html' --template '$tmp/tpl.html' '$tmp/bad.csv' 2>&1 |
	grep -qF '$tmp/bad.csv:3: no number in column cycle'; test ! -e '$tmp/x.html'"
echo "a,b,c" >"$tmp/other.csv"
check "not a telemetry CSV: file:1" sh -c "'$view' --html '$tmp/x.html' --template '$tmp/tpl.html' '$tmp/other.csv' 2>&1 |
	grep -qF '$tmp/other.csv:1: no column'"
echo '{"cycles": 3,' >"$tmp/bad.json"
check "a summary that is not JSON is refused" sh -c "! '$view' --html '$tmp/x.html' --template '$tmp/tpl.html' \
	--summary '$tmp/bad.json' '$tmp/t.csv' 2>'$tmp/err'; grep -qF 'bad.json' '$tmp/err'"
echo '<html>no marker</html>' >"$tmp/nomark.html"
check "a template without the marker is refused" sh -c "! '$view' --html '$tmp/x.html' --template '$tmp/nomark.html' '$tmp/t.csv' 2>'$tmp/err';
	grep -qF 'no ' '$tmp/err'"
"$view" --bogus >/dev/null 2>&1; rc=$?
check "unknown option: status 2" test "$rc" -eq 2

# the live view: URL said; a port taken said, the run goes on unchanged
port=$(free_port)
"$run" "$cfg" --virtual-time --duration-s 0.3 --telemetry "$tmp/l.csv" \
	--view "$port" --view-root "$tmp/web" >"$tmp/live.out" 2>"$tmp/live.err"; rc=$?
check "proxima-run --view says the URL" grep -qF "proxima-run: view: http://127.0.0.1:$port/" "$tmp/live.err"
check "... and runs as without it" sh -c "test $rc -eq 0" && check "... the same telemetry" same_run "$tmp/t.csv" "$tmp/l.csv"
"$view" --port "$port" --web-root "$tmp/web" "$tmp/t.csv" >"$tmp/hold.out" 2>&1 &
hp=$!
pids="$pids $hp"
i=0
while [ $i -lt 50 ] && ! grep -q "http://" "$tmp/hold.out"; do sleep 0.1; i=$((i + 1)); done
"$run" "$cfg" --virtual-time --duration-s 0.3 --telemetry "$tmp/k.csv" \
	--view "$port" --view-root "$tmp/web" >"$tmp/taken.out" 2>"$tmp/taken.err"; rc=$?
check "a port taken: said, and the run goes on" sh -c "test $rc -eq 0 &&
	grep -qF 'cannot listen on 127.0.0.1:$port' '$tmp/taken.err' &&
	grep -qF 'running without the view' '$tmp/taken.err'"
check "... the same telemetry" same_run "$tmp/t.csv" "$tmp/k.csv"
kill -TERM "$hp"
wait "$hp"
echo "$name: $pass passed, $fail failed, $skip skipped"
[ "$fail" -eq 0 ]
