"""Python batched queries next to the C tool, on the same files and points.

For each model, 10,000 random points in its box enlarged by 25 % per side
are written to a CSV file; proxima-query --stats answers them (each query
timed on its own: its mean per query is the C figure), then the Python
package answers the same array in one call (best and median of 7 calls,
divided by the points: the per-point figure). The ratio is Python over
C; the answers are compared too (they must be equal bit for bit).

    PYTHONPATH=build/python python3 bench/bench_python.py BUILD_DIR
"""

import os
import subprocess
import sys
import tempfile
import time

import numpy as np

import proxima

BUILD = sys.argv[1] if len(sys.argv) > 1 else "build"
QUERY = os.path.join(BUILD, "bin", "proxima-query")
N = 10000
RUNS = 7


def tool_stats(path, pts, signed):
    with tempfile.NamedTemporaryFile("w", suffix=".csv", delete=False) as f:
        np.savetxt(f, pts, delimiter=",", fmt="%.17g")
        name = f.name
    try:
        r = subprocess.run([QUERY, "--stats"] + (["--signed"] if signed else []) + [path, name],
                           check=True, capture_output=True, text=True)
    finally:
        os.unlink(name)
    mean = median = None
    for line in r.stderr.splitlines():
        w = line.split()
        if w[:1] == ["query_ns_total"]:
            mean = float(w[3])
        if w[:1] == ["queries"] and "median" in w:
            median = float(w[w.index("median") + 1])
    rows = np.array([[float(x) for x in line.split(",")] for line in r.stdout.splitlines()])
    return mean, median, rows


def main():
    rng = np.random.default_rng(7)
    models = [("tests/data/bicubic.obj", False, "NURBS patch"),
              ("tests/data/sphere.obj", False, "rational NURBS sphere"),
              ("config/examples/scenes/knob.stl", True, "mesh, signed"),
              ("config/examples/parts/filleted_block.step", True, "STEP part, signed")]
    print("per point, ns: C = proxima-query's mean per timed query, Python = one "
          "query() call of %d points / %d (best, median of %d calls)" % (N, N, RUNS))
    print("%-26s %-22s %9s %9s %9s %9s %7s %s" % ("model", "", "C mean", "C median",
                                                  "py best", "py med", "ratio", "answers"))
    for path, signed, what in models:
        try:
            m = proxima.load(path)
        except proxima.Error as e:
            print("%-26s %s: skipped (%s)" % (os.path.basename(path), what, e))
            continue
        b = m.bounds()
        e = (b[1] - b[0]) * 0.25
        pts = b[0] - e + (b[1] - b[0] + 2 * e) * rng.random((N, 3))
        mean, median, rows = tool_stats(path, pts, signed)
        times = []
        a = None
        for _ in range(RUNS):
            t0 = time.thread_time_ns()
            a = m.query(pts, signed=signed)
            times.append((time.thread_time_ns() - t0) / N)
        times.sort()
        same = np.array_equal(a.distance.view(np.int64), rows[:, 0].view(np.int64))
        print("%-26s %-22s %9.0f %9.0f %9.0f %9.0f %7.3f %s" % (
            os.path.basename(path), what, mean, median, times[0], times[RUNS // 2],
            times[RUNS // 2] / mean, "equal" if same else "DIFFERENT"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
