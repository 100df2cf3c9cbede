"""Build the proxima Python package's extension module with cffi.

    python3 python/build_ext.py OUTDIR --include DIR... --libdir DIR --rpath DIR

API mode: cffi is given _pxpy.h's own declarations and writes a C file
that includes it and the library's headers, so the C compiler checks
every call against them and the binding cannot drift from the library's
structs unnoticed (ABI mode would repeat their layouts here by hand). The
whole-array loops live in _pxpy.c, compiled into the same module, so a
batch of points costs one Python call. The module links libproxima.so
with an rpath to --rpath (the build tree, or the installed libdir).
"""

import argparse
import os
import shutil
import sys

import cffi

HERE = os.path.dirname(os.path.abspath(__file__))
PKG = os.path.join(HERE, "proxima")


def cdef_text():
    """The declarations of _pxpy.h as cffi reads them: the header
    without its preprocessor lines (cffi drops the comments itself)."""
    with open(os.path.join(PKG, "_pxpy.h")) as f:
        return "".join(line for line in f if not line.lstrip().startswith("#"))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("outdir")
    ap.add_argument("--include", action="append", default=[])
    ap.add_argument("--libdir", required=True)
    ap.add_argument("--rpath", required=True)
    ap.add_argument("--cflags", default="")
    a = ap.parse_args()

    ffi = cffi.FFI()
    ffi.cdef(cdef_text())
    with open(os.path.join(PKG, "_pxpy.c")) as f:
        src = f.read()
    ffi.set_source(
        "proxima._proxima",
        src,
        include_dirs=[PKG] + [os.path.abspath(d) for d in a.include],
        library_dirs=[os.path.abspath(a.libdir)],
        libraries=["proxima"],
        extra_compile_args=["-std=c11", "-D_GNU_SOURCE", "-O2"] + a.cflags.split(),
        extra_link_args=["-Wl,-rpath," + a.rpath],
    )
    out = os.path.abspath(a.outdir)
    tmp = os.path.join(out, ".cffi-build")
    os.makedirs(tmp, exist_ok=True)
    so = ffi.compile(tmpdir=tmp, verbose=False)
    pkg_out = os.path.join(out, "proxima")
    os.makedirs(pkg_out, exist_ok=True)
    shutil.copy(so, os.path.join(pkg_out, os.path.basename(so)))
    for name in sorted(os.listdir(PKG)):
        if name.endswith(".py"):
            shutil.copy(os.path.join(PKG, name), os.path.join(pkg_out, name))
    return 0


if __name__ == "__main__":
    sys.exit(main())
