#!/bin/sh
# The view of an arm end to end in headless chromium: proxima-run --view
# on the URDF arm with the simulated depth sensor (links, clouds), then
# proxima-view's replay of that run (links from the joint positions, the
# closest pair) (arm.test.mjs).
# PX_TEST_NEEDS: libwebsockets
set -u
. tests/view/common.sh
view_ready test_view_arm || exit 0
view_tools test_view_arm || exit 0
if ! "${PX_VIEW_BIN:-${BUILD:-build}/bin}/proxima-run" --check config/examples/can_avoid_urdf.yaml >/dev/null 2>&1; then
	echo "skip: config/examples/can_avoid_urdf.yaml does not check here (a build without libxml2)"
	echo "test_view_arm: 0 passed, 0 failed, 1 skipped"
	exit 0
fi
exec node tests/view/arm.test.mjs
