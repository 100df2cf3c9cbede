"""Distance field of a model on a plane, as a PNG.

    PYTHONPATH=build/python python3 examples/distance_field.py [MODEL] [OUT.png]

Loads MODEL (default: the shipped filleted block, a STEP part; any file
proxima.load() reads works), samples a 400 x 300 grid on the plane
through the middle of its box (z constant), queries every grid point in
one call and draws the signed distance with matplotlib: blue inside,
red outside, the zero contour (the part's section) in black.
"""

import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import proxima  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))


def main():
    path = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        HERE, "..", "config", "examples", "parts", "filleted_block.step")
    out = sys.argv[2] if len(sys.argv) > 2 else "distance_field.png"
    model = proxima.load(path)
    lo, hi = model.bounds()
    pad = 0.15 * (hi - lo)
    xs = np.linspace(lo[0] - pad[0], hi[0] + pad[0], 400)
    ys = np.linspace(lo[1] - pad[1], hi[1] + pad[1], 300)
    z = 0.5 * (lo[2] + hi[2])
    gx, gy = np.meshgrid(xs, ys)
    grid = np.stack([gx, gy, np.full_like(gx, z)], axis=-1)   # (300, 400, 3)
    d = model.query(grid).distance                            # (300, 400)
    lim = np.abs(d).max()
    fig, ax = plt.subplots(figsize=(8, 6))
    im = ax.imshow(d, origin="lower", extent=(xs[0], xs[-1], ys[0], ys[-1]),
                   cmap="RdBu_r", vmin=-lim, vmax=lim)
    ax.contour(xs, ys, d, levels=[0.0], colors="k", linewidths=1.0)
    ax.set_title("%s: %s distance at z = %.4g" % (
        os.path.basename(path), "signed" if model.signed else "unsigned", z))
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    fig.colorbar(im, ax=ax, label="distance")
    fig.savefig(out, dpi=100)
    print("%s: %d points, min %.6g, max %.6g" % (out, d.size, d.min(), d.max()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
