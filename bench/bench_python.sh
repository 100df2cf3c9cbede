#!/bin/sh
# bench_python: the Python package's batched query next to proxima-query
# on the same files and points (bench/bench_python.py). Run from the
# source tree after `make` (BUILD, PYTHON as in the Makefile).
BUILD=${BUILD:-build}
PYTHON=${PYTHON:-/usr/bin/python3}
PYTHONPATH="$BUILD/python" PYTHONDONTWRITEBYTECODE=1 exec "$PYTHON" bench/bench_python.py "$BUILD"
