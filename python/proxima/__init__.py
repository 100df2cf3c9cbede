"""proxima: exact point-to-model distances from Python.

Models come from files (free-form OBJ, meshes, point clouds, STEP/IGES
parts) or from arrays (NURBS control points and knots, vertices and
triangles, points), or are primitives. Queries take an ``(..., 3)`` array
of points and return arrays of the same leading shape; the loop over the
points runs in C with the GIL released. Units are the model's (metres for
CAD parts).

    import numpy as np, proxima
    part = proxima.load("part.step")
    a = part.query(np.random.rand(10000, 3) * 0.1)
    print(a.distance.min(), a.point[0], a.inside.sum())

Lifetimes: a model used by a stream or a scene cannot be closed until
they are (closing it raises); objects are freed when garbage collected or
by ``close()`` (also as context managers).
"""

import math
import threading

import numpy as np

from ._proxima import ffi, lib

__all__ = [
    "Error", "Model", "Answers", "Stream", "Scene", "SceneTracking", "Pair",
    "NurbsCurve", "NurbsSurface", "load", "mesh", "cloud", "nurbs",
    "sphere", "box", "capsule", "cylinder", "cone", "torus", "halfspace",
    "pair", "version", "Robot", "load_urdf",
]

# px_model.h: enum px_model_kind, enum px_feature, capability bits
KIND_NAMES = {1: "primitive", 2: "mesh", 3: "cloud", 4: "nurbs", 5: "custom",
              6: "brep"}
FEATURE_NONE, FEATURE_FACE, FEATURE_EDGE, FEATURE_VERTEX = 0, 1, 2, 3
FEATURE_POINT, FEATURE_CURVE, FEATURE_SURFACE = 4, 5, 6
CAP_SIGNED, CAP_EXACT, CAP_COHERENT, CAP_CONVEX = 1, 2, 4, 8

_E_NAMES = {-1: "PX_E_INVAL", -2: "PX_E_NOMEM", -3: "PX_E_NOSPC",
            -4: "PX_E_RANGE", -5: "PX_E_NAN", -6: "PX_E_IO", -7: "PX_E_PARSE",
            -8: "PX_E_UNSUPPORTED", -9: "PX_E_NOTFOUND", -10: "PX_E_BUSY",
            -15: "PX_E_STATE", -16: "PX_E_DEGENERATE", -17: "PX_E_NOCONV"}

_MSG_CAP = 1024


class Error(Exception):
    """A refusal of the library: the message says what and where (the
    file and line where there is one); code is the library's negative
    error code (px_strerror), name its symbol (e.g. "PX_E_PARSE")."""

    def __init__(self, message, code=-1):
        super().__init__(message)
        self.code = code
        self.name = _E_NAMES.get(code, "PX_E_%d" % -code)


def _raise(rc, msg):
    text = ffi.string(msg).decode("utf-8", "replace") if msg is not None else ""
    if not text:
        text = ffi.string(lib.pxpy_strerror(rc)).decode()
    raise Error(text, rc)


def version():
    """The C library's version string."""
    return ffi.string(lib.pxpy_version()).decode()


def _points(p, name="points"):
    """p as a C-contiguous float64 array of shape (..., 3), and its
    leading shape. Integer and float32 inputs are converted, strided
    views copied; anything else is refused."""
    a = np.asarray(p)
    if a.dtype.kind not in "fiu":
        raise TypeError("%s: expected real numbers, got dtype %s" % (name, a.dtype))
    if a.ndim == 0 or a.shape[-1] != 3:
        raise ValueError("%s: expected an array of shape (..., 3), got shape %s"
                         % (name, a.shape))
    lead = a.shape[:-1]
    a = np.ascontiguousarray(a.reshape(-1, 3), dtype=np.float64)
    return a, lead


def _ptr(a, ctype="double *"):
    return ffi.cast(ctype, ffi.from_buffer(a)) if a.size else ffi.NULL


class Answers:
    """Answers for an array of points, each field an array whose leading
    shape is the points':

    distance   signed for closed models (inside negative) unless
               unsigned was asked; inf where nothing lies within max_distance
    point      closest point (..., 3), world frame
    direction  unit vector (..., 3): point + distance * direction = query
    u, v       surface/curve parameters (NURBS, B-rep faces and edges),
               barycentric weights (meshes), primitive coordinates
    index      triangle, point, entity or face index; -1 when none
    sub        detail within index (triangle edge/vertex, NURBS piece)
    feature    FEATURE_* (face, edge, vertex, point, curve, surface)
    inside     True where strictly inside a closed model
    certified  True where the answer is proven global
    gap        how much closer the true answer may be where not certified
    found      False where nothing lay within max_distance
    jumped     (streams, tracked scenes) the closest point jumped
    model      (scenes) index of the model answering, -1 when none
    """

    __slots__ = ("distance", "point", "direction", "u", "v", "gap", "index",
                 "sub", "feature", "inside", "certified", "found", "jumped",
                 "model", "_lead")

    def __init__(self, n, lead, jumped=False, model=False):
        self._lead = lead
        self.distance = np.empty(n)
        self.point = np.empty((n, 3))
        self.direction = np.empty((n, 3))
        self.u = np.empty(n)
        self.v = np.empty(n)
        self.gap = np.empty(n)
        self.index = np.empty(n, dtype=np.int32)
        self.sub = np.empty(n, dtype=np.int32)
        self.feature = np.empty(n, dtype=np.int32)
        self.inside = np.empty(n, dtype=np.int8)
        self.certified = np.empty(n, dtype=np.int8)
        self.found = np.empty(n, dtype=np.int8)
        self.jumped = np.zeros(n, dtype=np.int8) if jumped else None
        self.model = np.empty(n, dtype=np.int32) if model else None

    def _c(self):
        o = ffi.new("struct pxpy_out *")
        o.distance = _ptr(self.distance)
        o.point = _ptr(self.point)
        o.direction = _ptr(self.direction)
        o.u = _ptr(self.u)
        o.v = _ptr(self.v)
        o.gap = _ptr(self.gap)
        o.index = _ptr(self.index, "int32_t *")
        o.sub = _ptr(self.sub, "int32_t *")
        o.feature = _ptr(self.feature, "int32_t *")
        o.inside = _ptr(self.inside, "int8_t *")
        o.certified = _ptr(self.certified, "int8_t *")
        o.found = _ptr(self.found, "int8_t *")
        o.jumped = _ptr(self.jumped, "int8_t *") if self.jumped is not None else ffi.NULL
        o.model = _ptr(self.model, "int32_t *") if self.model is not None else ffi.NULL
        return o

    def _finish(self):
        lead = self._lead
        for f in ("distance", "u", "v", "gap", "index", "sub", "feature"):
            setattr(self, f, getattr(self, f).reshape(lead))
        for f in ("inside", "certified", "found"):
            setattr(self, f, getattr(self, f).reshape(lead).astype(bool))
        self.point = self.point.reshape(lead + (3,))
        self.direction = self.direction.reshape(lead + (3,))
        if self.jumped is not None:
            self.jumped = self.jumped.reshape(lead).astype(bool)
        if self.model is not None:
            self.model = self.model.reshape(lead)
        return self

    def __len__(self):
        return int(np.prod(self._lead)) if self._lead else 1

    def __repr__(self):
        return "<proxima.Answers shape=%s>" % (self._lead,)


def _max(max_distance):
    d = float(max_distance)
    if math.isnan(d) or d < 0:
        raise ValueError("max_distance: expected a number >= 0 (inf for no "
                         "bound), got %r" % (max_distance,))
    return d


def _run(fn, handle, pts, lead, max_distance, flags, jumped=False, model=False,
         with_flags=True):
    n = pts.shape[0]
    ans = Answers(n, lead, jumped=jumped, model=model)
    bad = ffi.new("size_t *")
    msg = ffi.new("char[]", _MSG_CAP)
    if with_flags:
        rc = fn(handle, _ptr(pts), n, _max(max_distance), flags, ans._c(), bad,
                msg, _MSG_CAP)
    else:
        rc = fn(handle, _ptr(pts), n, _max(max_distance), ans._c(), bad, msg,
                _MSG_CAP)
    if rc < 0:
        _raise(rc, msg)
    return ans._finish()


def _quat_from(rotation):
    r = np.asarray(rotation, dtype=np.float64)
    if r.shape == (4,):
        return r
    if r.shape != (3, 3):
        raise ValueError("rotation: expected a quaternion (w, x, y, z) or a 3x3 "
                         "matrix, got shape %s" % (r.shape,))
    # Shepperd's method: the largest of the four squares first.
    t = np.trace(r)
    cands = [t, r[0, 0], r[1, 1], r[2, 2]]
    k = int(np.argmax(cands))
    if k == 0:
        s = math.sqrt(1.0 + t) * 2
        q = [0.25 * s, (r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s,
             (r[1, 0] - r[0, 1]) / s]
    elif k == 1:
        s = math.sqrt(1.0 + r[0, 0] - r[1, 1] - r[2, 2]) * 2
        q = [(r[2, 1] - r[1, 2]) / s, 0.25 * s, (r[0, 1] + r[1, 0]) / s,
             (r[0, 2] + r[2, 0]) / s]
    elif k == 2:
        s = math.sqrt(1.0 + r[1, 1] - r[0, 0] - r[2, 2]) * 2
        q = [(r[0, 2] - r[2, 0]) / s, (r[0, 1] + r[1, 0]) / s, 0.25 * s,
             (r[1, 2] + r[2, 1]) / s]
    else:
        s = math.sqrt(1.0 + r[2, 2] - r[0, 0] - r[1, 1]) * 2
        q = [(r[1, 0] - r[0, 1]) / s, (r[0, 2] + r[2, 0]) / s,
             (r[1, 2] + r[2, 1]) / s, 0.25 * s]
    return np.array(q)


class _Handle:
    """Owns one C handle; freed once, by close() or garbage collection."""

    _free = None

    def __init__(self, ptr):
        self._ptr = ptr

    def _live(self):
        if self._ptr is None:
            raise Error("%s is closed" % (self._what(),), -15)
        return self._ptr

    def _what(self):
        return type(self).__name__

    def close(self):
        p, self._ptr = getattr(self, "_ptr", None), None
        if p is not None:
            type(self)._free(p)

    def __del__(self):
        try:
            self.close()
        except Exception:
            pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


class Model(_Handle):
    """A model: one of load(), mesh(), cloud(), nurbs() or a primitive."""

    _free = lib.pxpy_model_free

    def __init__(self, ptr, source=""):
        super().__init__(ptr)
        self._users = 0
        self.source = source
        self.message = ""

    def _what(self):
        return "model %r" % (self.source or "",)

    def close(self):
        """Free the model now. Refused while a stream or scene uses it."""
        if getattr(self, "_users", 0) > 0:
            raise Error("%s is used by %d stream(s) or scene(s): close them "
                        "first" % (self._what(), self._users), -10)
        super().close()

    @property
    def kind(self):
        """"primitive", "mesh", "cloud", "nurbs" or "brep"."""
        return KIND_NAMES.get(lib.pxpy_model_kind(self._live()), "unknown")

    @property
    def name(self):
        return ffi.string(lib.pxpy_model_name(self._live())).decode()

    @property
    def signed(self):
        """True when queries answer inside negative (closed models)."""
        return bool(lib.pxpy_model_caps(self._live()) & CAP_SIGNED)

    @property
    def exact(self):
        return bool(lib.pxpy_model_caps(self._live()) & CAP_EXACT)

    @property
    def memory_bytes(self):
        return int(lib.pxpy_model_bytes(self._live()))

    def bounds(self, world=True):
        """Box as a (2, 3) array (min, max), world frame unless world=False."""
        b = np.empty(6)
        lib.pxpy_model_box(self._live(), 1 if world else 0, _ptr(b))
        return b.reshape(2, 3)

    @property
    def pose(self):
        """(quaternion (w, x, y, z), translation) of the model frame."""
        q, t = np.empty(4), np.empty(3)
        lib.pxpy_get_pose(self._live(), _ptr(q), _ptr(t))
        return q, t

    def set_pose(self, rotation=(1.0, 0.0, 0.0, 0.0), translation=(0.0, 0.0, 0.0)):
        """Place the model: rotation a unit quaternion (w, x, y, z) or a
        rotation matrix, translation a 3-vector."""
        q = np.ascontiguousarray(_quat_from(rotation), dtype=np.float64)
        t = np.ascontiguousarray(np.asarray(translation, dtype=np.float64))
        if t.shape != (3,):
            raise ValueError("translation: expected 3 numbers, got shape %s" % (t.shape,))
        msg = ffi.new("char[]", _MSG_CAP)
        rc = lib.pxpy_set_pose(self._live(), _ptr(q), _ptr(t), msg, _MSG_CAP)
        if rc < 0:
            _raise(rc, msg)

    def query(self, points, signed=True, max_distance=math.inf):
        """Closest points for every point of an (..., 3) array (one
        point: shape (3,)). signed=False skips the sign of closed models."""
        pts, lead = _points(points)
        return _run(lib.pxpy_query, self._live(), pts, lead, max_distance,
                    0 if signed else 1)

    def distance(self, points, signed=True):
        """Just the distances of query()."""
        return self.query(points, signed=signed).distance

    def stream(self, verify_every=0, max_solves=4, cold_switch=True):
        """A tracked stream following one moving point through this model
        (NURBS and B-rep models; others raise)."""
        return Stream(self, verify_every, max_solves, cold_switch)

    def __repr__(self):
        if self._ptr is None:
            return "<proxima.Model closed>"
        return "<proxima.Model %s %r%s>" % (self.kind, self.name,
                                            " signed" if self.signed else "")


def _new_model(fn, args, source):
    out = ffi.new("struct px_model **")
    msg = ffi.new("char[]", _MSG_CAP)
    rc = fn(*args, out, msg, _MSG_CAP)
    if rc < 0:
        _raise(rc, msg)
    m = Model(out[0], source)
    m.message = ffi.string(msg).decode("utf-8", "replace")
    return m


def load(path, cloud_radius=0.0, scale=1.0):
    """A model from a file: .obj (free-form curves and surfaces as one
    NURBS model, or faces as a mesh), .stl, .ply, .xyz/.csv/.pts (point
    clouds, balls of cloud_radius), .step/.stp/.iges/.igs (one B-rep in
    metres, times scale; needs the OpenCASCADE part). Model.message says
    why a model answers unsigned, where the library says so."""
    p = str(path)
    return _new_model(lib.pxpy_load, (p.encode(), float(cloud_radius), float(scale)), p)


def mesh(vertices, triangles):
    """A triangle mesh: vertices (N, 3) and triangles (M, 3) of 0-based
    indices. Signed when closed and consistently oriented."""
    v, _ = _points(vertices, "vertices")
    t = np.asarray(triangles)
    if t.dtype.kind not in "iu":
        raise TypeError("triangles: expected integer indices, got dtype %s" % t.dtype)
    if t.ndim != 2 or t.shape[1] != 3:
        raise ValueError("triangles: expected shape (M, 3), got %s" % (t.shape,))
    t = np.ascontiguousarray(t, dtype=np.int64)
    return _new_model(lib.pxpy_mesh, (_ptr(v), v.shape[0], _ptr(t, "int64_t *"),
                                      t.shape[0]), "mesh")


def cloud(points, radius=0.0):
    """A point cloud (N, 3), each point a ball of radius (0: points)."""
    p, _ = _points(points)
    return _new_model(lib.pxpy_cloud, (_ptr(p), p.shape[0], float(radius)), "cloud")


def _prim(t, a=0.0, b=0.0, c=0.0, name="primitive"):
    return _new_model(lib.pxpy_prim, (t, float(a), float(b), float(c)), name)


def sphere(radius):
    return _prim(1, radius, name="sphere")


def box(hx, hy, hz):
    """A box of half extents hx, hy, hz, centred on the origin."""
    return _prim(2, hx, hy, hz, name="box")


def capsule(radius, half_length):
    """A capsule around the z axis segment -half_length..half_length."""
    return _prim(3, radius, half_length, name="capsule")


def cylinder(radius, half_height):
    return _prim(4, radius, half_height, name="cylinder")


def cone(radius_bottom, half_height, radius_top=0.0):
    return _prim(5, radius_bottom, half_height, radius_top, name="cone")


def torus(major_radius, tube_radius):
    return _prim(6, major_radius, tube_radius, name="torus")


def halfspace():
    """The solid z <= 0."""
    return _prim(7, name="halfspace")


class NurbsCurve:
    """A NURBS curve: degree, knots (n + degree + 1), points (n, 3),
    weights (n,) or None."""

    def __init__(self, degree, knots, points, weights=None):
        self.degree = int(degree)
        self.knots = np.ascontiguousarray(np.asarray(knots, dtype=np.float64).ravel())
        self.points, _ = _points(points, "curve points")
        self.weights = None if weights is None else np.ascontiguousarray(
            np.asarray(weights, dtype=np.float64).ravel())
        n = self.points.shape[0]
        if self.weights is not None and self.weights.shape[0] != n:
            raise ValueError("curve weights: expected %d, got %d" % (n, self.weights.shape[0]))
        if self.knots.shape[0] != n + self.degree + 1:
            raise ValueError("curve knots: expected %d (points + degree + 1), got %d"
                             % (n + self.degree + 1, self.knots.shape[0]))


class NurbsSurface:
    """A NURBS surface: degrees (du, dv), knots_u, knots_v, points of
    shape (n_u, n_v, 3) indexed [i along u, j along v], weights (n_u, n_v)
    or None."""

    def __init__(self, degree_u, degree_v, knots_u, knots_v, points, weights=None):
        self.degree = (int(degree_u), int(degree_v))
        self.knots_u = np.asarray(knots_u, dtype=np.float64).ravel()
        self.knots_v = np.asarray(knots_v, dtype=np.float64).ravel()
        p = np.asarray(points, dtype=np.float64)
        if p.ndim != 3 or p.shape[2] != 3:
            raise ValueError("surface points: expected shape (n_u, n_v, 3), got %s"
                             % (p.shape,))
        self.n = (p.shape[0], p.shape[1])
        # the library stores u fastest: point (i, j) at j * n_u + i
        self.points = np.ascontiguousarray(p.transpose(1, 0, 2).reshape(-1, 3))
        if weights is None:
            self.weights = None
        else:
            w = np.asarray(weights, dtype=np.float64)
            if w.shape != self.n:
                raise ValueError("surface weights: expected shape %s, got %s"
                                 % (self.n, w.shape))
            self.weights = np.ascontiguousarray(w.T.ravel())
        for d, k in enumerate((self.knots_u, self.knots_v)):
            want = self.n[d] + self.degree[d] + 1
            if k.shape[0] != want:
                raise ValueError("surface knots_%s: expected %d (points + degree + 1), "
                                 "got %d" % ("uv"[d], want, k.shape[0]))


def nurbs(curves=(), surfaces=()):
    """One exact model of NURBS curves and surfaces (entity index: the
    curves first, then the surfaces). Signed when the surfaces form a
    closed, consistently oriented shell."""
    curves, surfaces = list(curves), list(surfaces)
    if not curves and not surfaces:
        raise ValueError("nurbs: no curve and no surface")
    c_deg = np.array([c.degree for c in curves] or [0], dtype=np.intc)
    c_n = np.array([c.points.shape[0] for c in curves] or [0], dtype=np.intc)
    c_k = np.concatenate([c.knots for c in curves] or [np.zeros(1)])
    c_p = np.ascontiguousarray(np.concatenate([c.points for c in curves] or [np.zeros((1, 3))]))
    c_rat = any(c.weights is not None for c in curves)
    c_w = np.concatenate([c.weights if c.weights is not None else np.ones(c.points.shape[0])
                          for c in curves]) if c_rat else None
    s_deg = np.array([d for s in surfaces for d in s.degree] or [0], dtype=np.intc)
    s_n = np.array([d for s in surfaces for d in s.n] or [0], dtype=np.intc)
    s_k = np.concatenate([np.concatenate([s.knots_u, s.knots_v]) for s in surfaces]
                         or [np.zeros(1)])
    s_p = np.ascontiguousarray(np.concatenate([s.points for s in surfaces] or [np.zeros((1, 3))]))
    s_rat = any(s.weights is not None for s in surfaces)
    s_w = np.concatenate([s.weights if s.weights is not None else np.ones(s.points.shape[0])
                          for s in surfaces]) if s_rat else None
    args = (len(curves), _ptr(c_deg, "int *"), _ptr(c_n, "int *"), _ptr(c_k), _ptr(c_p),
            _ptr(c_w) if c_w is not None else ffi.NULL,
            len(surfaces), _ptr(s_deg, "int *"), _ptr(s_n, "int *"), _ptr(s_k), _ptr(s_p),
            _ptr(s_w) if s_w is not None else ffi.NULL)
    return _new_model(lib.pxpy_nurbs, args, "nurbs")


class _User(_Handle):
    """A handle that uses models: they stay open while it lives."""

    def _use(self, models):
        self._models = list(models)
        for m in self._models:
            m._users += 1

    def close(self):
        super().close()
        for m in getattr(self, "_models", ()):
            m._users -= 1
        self._models = []


class Stream(_User):
    """One moving point through one model (Model.stream()): query() takes
    the points in order, each answer the exact global one, most of them
    at a fraction of a query's cost. One thread at a time."""

    _free = lib.pxpy_stream_free

    def __init__(self, model, verify_every=0, max_solves=4, cold_switch=True):
        out = ffi.new("struct px_model_stream **")
        msg = ffi.new("char[]", _MSG_CAP)
        rc = lib.pxpy_stream_create(model._live(), int(verify_every), int(max_solves),
                                    1 if cold_switch else 0, out, msg, _MSG_CAP)
        if rc < 0:
            _raise(rc, msg)
        super().__init__(out[0])
        self._use([model])
        self._lock = threading.Lock()

    def query(self, points, signed=True, max_distance=math.inf):
        """Answers along a trajectory (..., 3), in order."""
        pts, lead = _points(points)
        with self._lock:
            return _run(lib.pxpy_stream_query, self._live(), pts, lead, max_distance,
                        0 if signed else 1, jumped=True)

    def stats(self):
        """The stream's counters as a dict."""
        st = ffi.new("uint64_t[9]")
        lib.pxpy_stream_stats(self._live(), st)
        keys = ("queries", "tracked", "hot", "global", "cold", "jumps", "reinits",
                "verifications", "disagreements")
        return {k: int(st[i]) for i, k in enumerate(keys)}


class Pair:
    """Distance between two models (pair())."""

    __slots__ = ("distance", "point_a", "point_b", "normal", "depth", "index_a",
                 "index_b", "intersecting", "local_only", "converged", "iterations",
                 "witness_gap")

    def __repr__(self):
        return "<proxima.Pair distance=%.9g%s>" % (
            self.distance, " local" if self.local_only else "")


def pair(a, b, starts=0, max_iters=0):
    """Distance between models a and b at their poses (-depth when they
    intersect); local_only says when it may be a local minimum."""
    out, nrm, ints = ffi.new("double[9]"), ffi.new("double[3]"), ffi.new("int[6]")
    msg = ffi.new("char[]", _MSG_CAP)
    rc = lib.pxpy_pair(a._live(), b._live(), int(starts), int(max_iters), out, nrm, ints,
                       msg, _MSG_CAP)
    if rc < 0:
        _raise(rc, msg)
    r = Pair()
    r.distance = out[0]
    r.point_a = np.array([out[1], out[2], out[3]])
    r.point_b = np.array([out[4], out[5], out[6]])
    r.depth = out[7]
    r.witness_gap = out[8]
    r.normal = np.array([nrm[0], nrm[1], nrm[2]])
    r.index_a, r.index_b = ints[0], ints[1]
    r.intersecting, r.local_only, r.converged = bool(ints[2]), bool(ints[3]), bool(ints[4])
    r.iterations = ints[5]
    return r


class Scene(_User):
    """Posed models answering nearest queries together (px_scene.h).
    The scene keeps references to its models; set a model's pose, then
    call update() before querying."""

    _free = lib.pxpy_scene_free

    def __init__(self, capacity=64):
        out = ffi.new("struct px_scene **")
        msg = ffi.new("char[]", _MSG_CAP)
        rc = lib.pxpy_scene_create(int(capacity), out, msg, _MSG_CAP)
        if rc < 0:
            _raise(rc, msg)
        super().__init__(out[0])
        self._use([])
        self._trackings = 0

    def add(self, model):
        """Add a model; returns its index."""
        msg = ffi.new("char[]", _MSG_CAP)
        rc = lib.pxpy_scene_add(self._live(), model._live(), msg, _MSG_CAP)
        if rc < 0:
            _raise(rc, msg)
        self._models.append(model)
        model._users += 1
        return rc

    @property
    def models(self):
        return list(self._models)

    def update(self):
        """Take the models' current poses (after Model.set_pose())."""
        rc = lib.pxpy_scene_update(self._live())
        if rc < 0:
            _raise(rc, None)

    def nearest(self, points, max_distance=math.inf):
        """The nearest model to each point: Answers with .model."""
        pts, lead = _points(points)
        return _run(lib.pxpy_scene_nearest, self._live(), pts, lead, max_distance, 0,
                    model=True, with_flags=False)

    def tracking(self):
        """Tracked streams over the scene's current models, for one
        moving point."""
        return SceneTracking(self)

    def close(self):
        if getattr(self, "_trackings", 0) > 0:
            raise Error("scene is used by %d tracking(s): close them first"
                        % self._trackings, -10)
        super().close()


class SceneTracking(_Handle):
    """One moving point through a scene (Scene.tracking())."""

    _free = lib.pxpy_scene_tracking_free

    def __init__(self, scene):
        out = ffi.new("struct px_scene_tracking **")
        msg = ffi.new("char[]", _MSG_CAP)
        rc = lib.pxpy_scene_tracking_create(scene._live(), out, msg, _MSG_CAP)
        if rc < 0:
            _raise(rc, msg)
        super().__init__(out[0])
        self._scene = scene
        scene._trackings += 1
        self._lock = threading.Lock()

    def nearest(self, points, max_distance=math.inf):
        pts, lead = _points(points)
        scene = self._scene
        with self._lock:
            n = pts.shape[0]
            ans = Answers(n, lead, jumped=True, model=True)
            bad = ffi.new("size_t *")
            msg = ffi.new("char[]", _MSG_CAP)
            rc = lib.pxpy_scene_nearest_tracked(scene._live(), self._live(), _ptr(pts), n,
                                                _max(max_distance), ans._c(), bad, msg,
                                                _MSG_CAP)
            if rc < 0:
                _raise(rc, msg)
            return ans._finish()

    def close(self):
        live = getattr(self, "_ptr", None) is not None
        super().close()
        if live:
            self._scene._trackings -= 1


class _Body(Model):
    """A robot's collision shape: a model the robot owns and poses."""

    def __init__(self, ptr, robot, link, frame):
        super().__init__(ptr, "%s:%s" % (robot.source, link))
        self._robot = robot
        self.link = link
        self.frame = frame

    def close(self):
        if getattr(self, "_users", 0) > 0:
            raise Error("%s is used by %d stream(s) or scene(s): close them "
                        "first" % (self._what(), self._users), -10)
        self._ptr = None  # the robot frees it


class Robot(_Handle):
    """A URDF robot's chain from a base link to a tip link
    (load_urdf()): joints, limits, and one model per collision shape
    (bodies) posed by set_q()."""

    _free = lib.pxpy_robot_free

    def __init__(self, ptr, source):
        super().__init__(ptr)
        self.source = source
        self.joint_names = [ffi.string(lib.pxpy_robot_joint_name(ptr, j)).decode()
                            for j in range(lib.pxpy_robot_dof(ptr))]
        self.bodies = []
        link, frame = ffi.new("const char **"), ffi.new("int *")
        for i in range(lib.pxpy_robot_body_count(ptr)):
            m = lib.pxpy_robot_body(ptr, i, link, frame)
            self.bodies.append(_Body(m, self, ffi.string(link[0]).decode(), frame[0]))

    @property
    def dof(self):
        return len(self.joint_names)

    def limits(self):
        """(dof, 3) array: lower, upper, velocity of each movable joint."""
        out = np.empty((self.dof, 3))
        for j in range(self.dof):
            lib.pxpy_robot_limits(self._live(), j, _ptr(out[j]))
        return out

    def set_q(self, q):
        """Pose every body for joint positions q (dof values); returns the
        chain frames as a (dof + 1, 7) array (w, x, y, z, tx, ty, tz)."""
        a = np.ascontiguousarray(np.asarray(q, dtype=np.float64).ravel())
        if a.shape != (self.dof,):
            raise ValueError("q: expected %d joint positions, got shape %s"
                             % (self.dof, a.shape))
        frames = np.empty((self.dof + 1, 7))
        msg = ffi.new("char[]", _MSG_CAP)
        rc = lib.pxpy_robot_set_q(self._live(), _ptr(a) if a.size else ffi.NULL,
                                  _ptr(frames), msg, _MSG_CAP)
        if rc < 0:
            _raise(rc, msg)
        return frames

    def close(self):
        for b in getattr(self, "bodies", ()):
            b.close()
        super().close()


def load_urdf(path, tip_link, base_link=None, package_paths=()):
    """The chain base_link..tip_link (base: the root) of a URDF file;
    package:// meshes are looked up under each of package_paths."""
    out = ffi.new("struct px_urdf_robot **")
    msg = ffi.new("char[]", _MSG_CAP)
    p = str(path)
    pk = ":".join(str(x) for x in package_paths)
    rc = lib.pxpy_robot_load(p.encode(), base_link.encode() if base_link else ffi.NULL,
                             str(tip_link).encode(), pk.encode(), out, msg, _MSG_CAP)
    if rc < 0:
        _raise(rc, msg)
    return Robot(out[0], p)
