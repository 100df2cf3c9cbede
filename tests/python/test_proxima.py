"""Tests of the proxima Python package (python/): answers equal
proxima-query's to the last bit on the same files and points, array
handling, errors, lifetimes, memory over a million queries.

    PYTHONPATH=build/python python3 tests/python/test_proxima.py BUILD_DIR

Prints one line per check and "test_python: N passed, N failed, N
skipped" (tests/run.sh reads it).
"""

import gc
import math
import os
import subprocess
import sys
import tempfile
import threading
import traceback

import numpy as np

import proxima

BUILD = sys.argv[1] if len(sys.argv) > 1 else "build"
QUERY = os.path.join(BUILD, "bin", "proxima-query")
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DATA = os.path.join(ROOT, "tests", "data")
SEED = int(os.environ.get("PX_TEST_SEED", "1"))
rng = np.random.default_rng(SEED)
counts = [0, 0, 0]


def ok(cond, what):
    counts[0 if cond else 1] += 1
    print("%s %s" % ("ok  " if cond else "FAIL", what))
    return cond


def skip(what):
    counts[2] += 1
    print("skip %s" % what)


def raises(fn, exc, contains=(), what=""):
    try:
        fn()
    except exc as e:
        text = str(e)
        good = all(c in text for c in contains)
        return ok(good, "%s: %s" % (what, text if good else "message lacks %r: %r"
                                    % (contains, text)))
    except Exception as e:  # noqa: BLE001 - any other exception is the failure
        return ok(False, "%s: raised %s: %s" % (what, type(e).__name__, e))
    return ok(False, "%s: did not raise" % what)


def tool(model, pts, *flags):
    """proxima-query's rows for pts: (dist, cx, cy, cz, u, v) per point."""
    with tempfile.NamedTemporaryFile("w", suffix=".csv", delete=False) as f:
        for p in pts:
            f.write("%.17g,%.17g,%.17g\n" % tuple(p))
        name = f.name
    try:
        out = subprocess.run([QUERY] + list(flags) + [model, name], check=True,
                             capture_output=True, text=True).stdout
    finally:
        os.unlink(name)
    return np.array([[float(x) for x in line.split(",")] for line in out.splitlines()])


def box_points(m, n, grow=0.25):
    b = m.bounds()
    lo, hi = b[0], b[1]
    e = (hi - lo) * grow
    return lo - e + (hi - lo + 2 * e) * rng.random((n, 3))


def same_bits(a, b):
    return np.array_equal(np.asarray(a, dtype=np.float64).view(np.int64),
                          np.asarray(b, dtype=np.float64).view(np.int64))


# ---- answers equal the C tool's ------------------------------------------

def check_against_tool(path, signed, param):
    """param: 'uv' (curve/surface/face parameters), 'index' (mesh triangle
    or cloud point as u)."""
    name = os.path.basename(path)
    m = proxima.load(path)
    pts = box_points(m, 400)
    rows = tool(path, pts, *(["--signed"] if signed else []))
    a = m.query(pts, signed=signed)
    ok(rows.shape == (400, 6), "%s: the tool answered every point" % name)
    ok(same_bits(a.distance, rows[:, 0]), "%s: distances equal the tool's bit for bit" % name)
    ok(same_bits(a.point, rows[:, 1:4]), "%s: closest points equal the tool's" % name)
    if param == "uv":
        ok(same_bits(a.u, rows[:, 4]) and same_bits(a.v, rows[:, 5]),
           "%s: parameters (u, v) equal the tool's" % name)
    else:
        ok(np.array_equal(a.index.astype(np.float64), rows[:, 4]),
           "%s: feature index equals the tool's" % name)
    if signed:
        ok(bool(a.inside.any()) and bool((a.distance < 0).any()) == bool(a.inside.any()),
           "%s: some points inside, negative exactly there" % name)
    return m


def test_tool_equal():
    check_against_tool(os.path.join(DATA, "bicubic.obj"), False, "uv")
    check_against_tool(os.path.join(DATA, "circle.obj"), False, "uv")
    check_against_tool(os.path.join(DATA, "sphere.obj"), False, "uv")
    check_against_tool(os.path.join(ROOT, "config/examples/scenes/terrain.obj"), False, "uv")
    check_against_tool(os.path.join(ROOT, "config/examples/scenes/knob.stl"), True, "index")
    tmp = tempfile.mkdtemp()
    xyz = os.path.join(tmp, "cloud.xyz")
    np.savetxt(xyz, rng.random((500, 3)), fmt="%.17g")
    check_against_tool(xyz, False, "index")
    step = os.path.join(ROOT, "config/examples/parts/filleted_block.step")
    if "occt" not in os.environ.get("PX_WITHOUT", "").split():
        check_against_tool(step, True, "uv")
    else:
        skip("STEP part: built without OpenCASCADE")


def test_tracked_equal():
    path = os.path.join(DATA, "bicubic.obj")
    m = proxima.load(path)
    t = np.linspace(0.0, 1.0, 2000)
    path_pts = np.stack([0.5 + 0.4 * np.cos(6 * t), 0.5 + 0.4 * np.sin(4 * t),
                         0.6 + 0.3 * np.sin(9 * t)], axis=1)
    s = m.stream()
    a = s.query(path_pts)
    g = m.query(path_pts)
    # (the tracked and the global search converge separately: equal to
    # rounding, not bit for bit)
    ok(np.allclose(a.distance, g.distance, rtol=0, atol=1e-11),
       "stream answers equal the global query's along a path (max diff %.3g)"
       % np.max(np.abs(a.distance - g.distance)))
    rows = tool(path, path_pts, "--track")
    ok(same_bits(a.distance, rows[:, 0]) and same_bits(a.point, rows[:, 1:4])
       and same_bits(a.u, rows[:, 4]) and same_bits(a.v, rows[:, 5]),
       "stream answers equal proxima-query --track's bit for bit")
    st = s.stats()
    ok(st["queries"] == 2000 and st["tracked"] > 1000,
       "stream counted 2000 answers, most tracked (%s)" % st)
    s.close()


# ---- models from arrays equal models from files --------------------------

def obj_surface(path):
    """The one surface of a simple OBJ file as arrays."""
    verts, deg, parm, idx = [], None, {}, None
    for line in open(path):
        w = line.split()
        if not w:
            continue
        if w[0] == "v":
            verts.append([float(x) for x in w[1:4]])
        elif w[0] == "deg":
            deg = (int(w[1]), int(w[2]))
        elif w[0] == "surf":
            idx = [int(x) - 1 for x in w[5:]]
        elif w[0] == "parm":
            parm[w[1]] = [float(x) for x in w[2:]]
    nu = len(parm["u"]) - deg[0] - 1
    nv = len(parm["v"]) - deg[1] - 1
    p = np.array([verts[i] for i in idx]).reshape(nv, nu, 3).transpose(1, 0, 2)
    return proxima.NurbsSurface(deg[0], deg[1], parm["u"], parm["v"], p)


def test_from_arrays():
    path = os.path.join(DATA, "bicubic.obj")
    a = proxima.nurbs(surfaces=[obj_surface(path)])
    b = proxima.load(path)
    pts = box_points(b, 300)
    qa, qb = a.query(pts), b.query(pts)
    ok(same_bits(qa.distance, qb.distance) and same_bits(qa.u, qb.u) and same_bits(qa.v, qb.v),
       "NURBS surface from arrays answers as the same OBJ file")
    # a rational quarter circle as a curve: every point at distance |r - 1|
    w = math.sqrt(0.5)
    c = proxima.nurbs(curves=[proxima.NurbsCurve(2, [0, 0, 0, 1, 1, 1],
                                                [[1, 0, 0], [1, 1, 0], [0, 1, 0]],
                                                [1, w, 1])])
    ang = rng.random(200) * math.pi / 2
    r = 0.2 + 1.5 * rng.random(200)
    q = np.stack([r * np.cos(ang), r * np.sin(ang), np.zeros(200)], axis=1)
    d = c.distance(q)
    ok(np.allclose(d, np.abs(r - 1.0), atol=1e-12),
       "rational curve from arrays: distance |r - 1| (max err %.3g)"
       % np.max(np.abs(d - np.abs(r - 1.0))))
    # mesh and cloud from arrays against the same data through files
    tmp = tempfile.mkdtemp()
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    t = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    mm = proxima.mesh(v, t)
    ok(mm.signed and mm.kind == "mesh", "tetrahedron from arrays is a closed mesh")
    objp = os.path.join(tmp, "tet.obj")
    with open(objp, "w") as f:
        for p in v:
            f.write("v %.17g %.17g %.17g\n" % tuple(p))
        for tri in t:
            f.write("f %d %d %d\n" % tuple(tri + 1))
    mf = proxima.load(objp)
    pts = rng.random((300, 3)) * 1.4 - 0.2
    ok(same_bits(mm.query(pts).distance, mf.query(pts).distance),
       "mesh from arrays answers as the same OBJ file")
    cp = rng.random((100, 3))
    cm = proxima.cloud(cp)
    qa = cm.query(pts)
    brute = np.sqrt(((pts[:, None, :] - cp[None, :, :]) ** 2).sum(-1))
    ok(np.array_equal(qa.index, brute.argmin(1)) and np.allclose(qa.distance, brute.min(1),
                                                                 rtol=1e-15),
       "cloud from arrays: nearest point and distance by brute force")


def test_primitives_pose_pair_scene():
    s = proxima.sphere(0.5)
    s.set_pose(translation=(1.0, 2.0, 3.0))
    p = np.array([[1.0, 2.0, 4.0], [1.0, 2.0, 3.1]])
    a = s.query(p)
    ok(np.allclose(a.distance, [0.5, -0.4], atol=1e-15) and list(a.inside) == [False, True],
       "posed sphere: signed distances")
    q, t = s.pose
    ok(np.allclose(t, [1, 2, 3]) and np.allclose(q, [1, 0, 0, 0]), "pose reads back")
    bx = proxima.box(0.1, 0.2, 0.3)
    rot = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    bx.set_pose(rotation=rot)
    ok(abs(bx.distance([[1.0, 0.0, 0.0]])[0] - 0.8) < 1e-12,
       "box rotated 90 degrees by a matrix: x now sees the half extent 0.2")
    s2 = proxima.sphere(0.25)
    s2.set_pose(translation=(1.0, 2.0, 5.0))
    pr = proxima.pair(s, s2)
    ok(abs(pr.distance - 1.25) < 1e-9 and not pr.intersecting,
       "pair of spheres: centre distance minus radii (%.12g)" % pr.distance)
    sc = proxima.Scene(8)
    sc.add(s)
    sc.add(s2)
    pts = rng.random((500, 3)) * 4 - 0.5 + np.array([0, 1, 2])
    h = sc.nearest(pts)
    both = np.stack([s.distance(pts), s2.distance(pts)], 1)
    ok(np.array_equal(h.model, both.argmin(1)) and np.allclose(h.distance, both.min(1),
                                                               rtol=1e-14, atol=1e-15),
       "scene nearest: the nearer of its two models")
    nb = proxima.nurbs(surfaces=[obj_surface(os.path.join(DATA, "bicubic.obj"))])
    nb.set_pose(translation=(0.0, 0.0, 4.0))
    sc.add(nb)
    tr = sc.tracking()
    tt = np.linspace(0, 1, 500)
    path = np.stack([0.5 + 0.3 * np.cos(5 * tt), 0.5 + 0.3 * np.sin(3 * tt),
                     4.2 + 0.2 * tt], 1)
    ht, hg = tr.nearest(path), sc.nearest(path)
    ok(np.array_equal(ht.model, hg.model) and np.allclose(ht.distance, hg.distance,
                                                          rtol=0, atol=1e-11),
       "tracked scene answers equal the global ones along a path")
    raises(sc.close, proxima.Error, ("tracking",), "a scene with a live tracking refuses to close")
    tr.close()
    raises(s.close, proxima.Error, ("used by",), "a model in a scene refuses to close")
    sc.close()
    s.close()
    ok(True, "after the scene closed, its models close")


# ---- array handling -------------------------------------------------------

def test_arrays():
    m = proxima.sphere(1.0)
    one = m.query([2.0, 0.0, 0.0])
    ok(one.distance.shape == () and one.point.shape == (3,) and float(one.distance) == 1.0,
       "one point (3,) gives scalar-shaped answers")
    grid = rng.random((4, 5, 3))
    g = m.query(grid)
    ok(g.distance.shape == (4, 5) and g.point.shape == (4, 5, 3) and g.inside.dtype == bool,
       "a (4, 5, 3) grid gives (4, 5) and (4, 5, 3) answers")
    ok(np.array_equal(g.distance, m.query(grid.reshape(-1, 3)).distance.reshape(4, 5)),
       "grid answers equal the flat ones")
    big = rng.random((200, 6))
    strided = big[::2, 1:4]
    ok(not strided.flags.c_contiguous and np.array_equal(
        m.query(strided).distance, m.query(np.ascontiguousarray(strided)).distance),
       "non-contiguous input answered as its contiguous copy")
    f32 = grid.reshape(-1, 3).astype(np.float32)
    ok(np.array_equal(m.query(f32).distance, m.query(f32.astype(np.float64)).distance),
       "float32 input converted")
    ok(np.array_equal(m.query(np.asfortranarray(grid.reshape(-1, 3))).distance,
                      m.query(grid.reshape(-1, 3)).distance), "Fortran-ordered input")
    ok(m.query([[1, 2, 3]]).distance[0] == math.sqrt(14) - 1, "integer input converted")
    e = m.query(np.zeros((0, 3)))
    ok(e.distance.shape == (0,), "no points: empty answers")
    raises(lambda: m.query(np.zeros((5, 2))), ValueError, ("(..., 3)", "(5, 2)"),
           "shape (5, 2) refused")
    raises(lambda: m.query(np.zeros((5, 3), dtype=complex)), TypeError, ("complex",),
           "complex points refused")
    raises(lambda: m.query([["a", "b", "c"]]), TypeError, ("dtype",), "strings refused")
    raises(lambda: m.query(np.zeros(3), max_distance=-1), ValueError, ("max_distance",),
           "negative max_distance refused")
    far = m.query([[10.0, 0, 0], [1.5, 0, 0]], max_distance=1.0)
    ok(list(far.found) == [False, True] and math.isinf(far.distance[0]),
       "max_distance: nothing found beyond it")
    raises(lambda: proxima.mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 5]]),
           proxima.Error, ("vertex index 5",), "mesh with a bad index refused")
    raises(lambda: proxima.mesh([[0, 0, 0]], [[0.0, 1.0, 2.0]]), TypeError, ("integer",),
           "float triangle indices refused")
    raises(lambda: proxima.NurbsCurve(2, [0, 0, 1, 1], [[0, 0, 0], [1, 0, 0], [2, 0, 0]]),
           ValueError, ("knots",), "curve with the wrong knot count refused")
    raises(lambda: proxima.nurbs(curves=[proxima.NurbsCurve(
        2, [0, 0, 0, 1, 0.5, 1], [[0, 0, 0], [1, 0, 0], [2, 0, 0]])]),
        proxima.Error, ("curve 0", "knot"), "curve with decreasing knots refused with the knot")


# ---- errors -----------------------------------------------------------------

def test_errors():
    m = proxima.load(os.path.join(DATA, "bicubic.obj"))
    pts = np.array([[0.1, 0.2, 0.3], [math.nan, 0.0, 0.0], [0.0, 0.0, 0.0]])
    raises(lambda: m.query(pts), proxima.Error, ("point 1", "not finite"),
           "a NaN point raises, naming it")
    try:
        m.query(pts)
    except proxima.Error as e:
        ok(e.code == -5 and e.name == "PX_E_NAN", "NaN error carries PX_E_NAN")
    raises(lambda: m.query([[math.inf, 0, 0]]), proxima.Error, ("point 0",), "inf point raises")
    raises(lambda: proxima.load("/nonexistent/part.stl"), proxima.Error,
           ("/nonexistent/part.stl",), "missing file raises with its name")
    tmp = tempfile.mkdtemp()
    bad = os.path.join(tmp, "bad.obj")
    with open(bad, "w") as f:
        f.write("v 0 0 0\nv 1 0 0\ncstype bspline\ndeg 3 3\nsurf 0 1 0 1 1 2 99\nend\n")
    raises(lambda: proxima.load(bad), proxima.Error, (bad + ":5:",),
           "malformed OBJ raises with file:line")
    step = os.path.join(tmp, "bad.step")
    with open(step, "w") as f:
        f.write("ISO-10303-21;\nHEADER;\nENDSEC;\nDATA;\n#1=GARBAGE(;\nENDSEC;\nEND-ISO-10303-21;\n")
    raises(lambda: proxima.load(step), proxima.Error, ("bad.step",),
           "malformed STEP raises with the file's name")
    raises(lambda: proxima.sphere(-1.0), proxima.Error, ("primitive",), "negative radius refused")
    raises(lambda: proxima.sphere(1.0).set_pose(translation=(math.nan, 0, 0)), proxima.Error,
           ("pose",), "NaN pose refused")
    raises(lambda: proxima.sphere(1.0).stream(), proxima.Error, ("no tracked streams",),
           "a stream on a primitive refused")


# ---- lifetimes ------------------------------------------------------------

def test_lifetimes():
    m = proxima.load(os.path.join(DATA, "bicubic.obj"))
    s = m.stream()
    raises(m.close, proxima.Error, ("used by 1",), "a model under a stream refuses to close")
    ok(s.query([[0.5, 0.5, 1.0]]).distance.shape == (1,), "the stream still answers")
    s.close()
    raises(lambda: s.query([[0.5, 0.5, 1.0]]), proxima.Error, ("closed",),
           "a closed stream refuses queries")
    m.close()
    raises(lambda: m.query([[0, 0, 0]]), proxima.Error, ("closed",),
           "a closed model refuses queries")
    m.close()
    ok(True, "closing twice is harmless")
    # dropping the model's last name while a stream lives keeps it alive
    s2 = proxima.load(os.path.join(DATA, "bicubic.obj")).stream()
    gc.collect()
    ok(s2.query([[0.5, 0.5, 1.0]]).distance[0] > 0, "a stream keeps its model alive")
    with proxima.sphere(1.0) as sp:
        ok(sp.distance([[3, 0, 0]])[0] == 2.0, "a model as a context manager")
    raises(lambda: sp.query([[0, 0, 0]]), proxima.Error, ("closed",),
           "closed at the end of the with block")


def test_threads():
    m = proxima.load(os.path.join(DATA, "bicubic.obj"))
    pts = box_points(m, 4000)
    want = m.query(pts).distance
    got = [None, None]

    def work(i):
        got[i] = m.query(pts).distance

    th = [threading.Thread(target=work, args=(i,)) for i in range(2)]
    for x in th:
        x.start()
    for x in th:
        x.join()
    ok(all(g is not None and np.array_equal(g, want) for g in got),
       "two threads querying one model get the same answers")


def rss_kb():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") // 1024


def test_memory():
    m = proxima.load(os.path.join(DATA, "bicubic.obj"))
    pts = box_points(m, 1000)
    for _ in range(50):
        m.query(pts)
    gc.collect()
    before = rss_kb()
    for _ in range(1000):
        m.query(pts)
    one = pts[:1]
    for _ in range(20000):
        m.query(one)
    s = m.stream()
    for _ in range(100):
        s.query(pts)
    s.close()
    gc.collect()
    after = rss_kb()
    ok(after - before < 4096, "a million batched queries, 20k single ones and 100k tracked "
       "answers: resident size grew %d kB (< 4 MB)" % (after - before))


URDF = """<?xml version='1.0'?>
<robot name='two'>
  <link name='base'/>
  <link name='upper'><collision><origin xyz='0.25 0 0'/><geometry><box size='0.5 0.1 0.1'/></geometry></collision></link>
  <link name='lower'><collision><geometry><sphere radius='0.05'/></geometry></collision></link>
  <joint name='shoulder' type='revolute'><parent link='base'/><child link='upper'/>
    <axis xyz='0 0 1'/><limit lower='-2' upper='2' velocity='1.5'/></joint>
  <joint name='elbow' type='continuous'><parent link='upper'/><child link='lower'/>
    <origin xyz='0.5 0 0'/><axis xyz='0 0 1'/></joint>
</robot>
"""


def test_urdf():
    if "libxml2" in os.environ.get("PX_WITHOUT", "").split():
        skip("URDF: built without libxml2")
        return
    tmp = tempfile.mkdtemp()
    path = os.path.join(tmp, "two.urdf")
    with open(path, "w") as f:
        f.write(URDF)
    r = proxima.load_urdf(path, "lower")
    ok(r.dof == 2 and r.joint_names == ["shoulder", "elbow"] and len(r.bodies) == 2,
       "URDF robot: 2 joints, 2 bodies (%s)" % r.joint_names)
    ok(np.allclose(r.limits()[0], [-2, 2, 1.5]) and math.isinf(r.limits()[1][1]),
       "joint limits read")
    for q0 in (0.0, 0.7, -1.3):
        frames = r.set_q([q0, 0.4])
        ball = [b for b in r.bodies if b.link == "lower"][0]
        want = 0.5 * np.array([math.cos(q0), math.sin(q0), 0.0])
        ok(np.allclose(ball.pose[1], want, atol=1e-15) and np.allclose(frames[2][4:], want),
           "forward kinematics puts the elbow at 0.5 (cos q, sin q, 0) for q = %g" % q0)
        ok(abs(ball.distance([want + [0, 0, 0.2]])[0] - 0.15) < 1e-12,
           "the elbow's sphere answers queries where it is")
    ob = proxima.sphere(0.1)
    ob.set_pose(translation=(0.0, 0.0, 0.5))
    pr = proxima.pair(r.bodies[0], ob)
    # the arm's box reaches the z axis at its top face (z = 0.05): 0.45
    # below the obstacle's centre, minus its radius
    ok(abs(pr.distance - 0.35) < 1e-9,
       "a body in a model pair: box to sphere 0.35 (%.12g)" % pr.distance)
    sc = proxima.Scene(4)
    sc.add(r.bodies[1])
    raises(r.close, proxima.Error, ("used by",), "a robot whose body is in a scene refuses to close")
    sc.close()
    r.close()
    raises(lambda: r.bodies[0].query([[0, 0, 0]]), proxima.Error, ("closed",),
           "bodies are closed with their robot")
    bad = os.path.join(tmp, "bad.urdf")
    with open(bad, "w") as f:
        f.write(URDF.replace("continuous", "ball"))
    raises(lambda: proxima.load_urdf(bad, "lower"), proxima.Error,
           (bad + ":8: <joint name='elbow'>: unknown joint type 'ball'",),
           "a bad URDF raises with file, line and element")
    raises(lambda: proxima.load_urdf(path, "nowhere"), proxima.Error, ("no link named 'nowhere'",),
           "an unknown tip link raises")


def test_example():
    out = os.path.join(tempfile.mkdtemp(), "field.png")
    r = subprocess.run([sys.executable, os.path.join(ROOT, "examples", "distance_field.py"),
                        os.path.join(ROOT, "config/examples/scenes/knob.stl"), out],
                       capture_output=True, text=True)
    png = open(out, "rb").read(8) if os.path.exists(out) else b""
    ok(r.returncode == 0 and png == b"\x89PNG\r\n\x1a\n" and "120000 points" in r.stdout,
       "examples/distance_field.py writes a PNG (%s)" % (r.stdout.strip() or r.stderr.strip()))


def main():
    if not os.path.exists(QUERY):
        print("test_python: 0 passed, 1 failed, 0 skipped (no %s)" % QUERY)
        return 1
    for t in (test_tool_equal, test_tracked_equal, test_from_arrays,
              test_primitives_pose_pair_scene, test_arrays, test_errors,
              test_lifetimes, test_threads, test_memory, test_urdf, test_example):
        print("== %s" % t.__name__)
        try:
            t()
        except Exception:  # noqa: BLE001 - a crash in a test is one failure
            traceback.print_exc()
            ok(False, "%s raised" % t.__name__)
    print("test_python: %d passed, %d failed, %d skipped" % tuple(counts))
    return 1 if counts[1] else 0


if __name__ == "__main__":
    sys.exit(main())
