#!/bin/sh
# The Python package (python/) against the C tools: runs
# tests/python/test_proxima.py with Debian's interpreter on the package
# built in $BUILD/python.
# PX_TEST_NEEDS: python
set -u
BUILD=${BUILD:-build}
PYTHON=${PYTHON:-/usr/bin/python3}
if [ ! -f "$BUILD/python/proxima/__init__.py" ]; then
	echo "FAIL the package was not built ($BUILD/python/proxima)"
	echo "test_python: 0 passed, 1 failed, 0 skipped"
	exit 1
fi
PYTHONPATH="$BUILD/python" PYTHONDONTWRITEBYTECODE=1 exec "$PYTHON" tests/python/test_proxima.py "$BUILD"
