#!/bin/sh
# The view end to end in headless chromium: proxima-run --view on a short
# simulated run (stopped and restarted: the page reconnects), then
# proxima-view's replay and HTML report of that run (e2e.test.mjs).
# PX_TEST_NEEDS: libwebsockets
set -u
. tests/view/common.sh
view_ready test_view_e2e || exit 0
for tool in proxima-run proxima-view; do
	if [ ! -x "${PX_VIEW_BIN:-${BUILD:-build}/bin}/$tool" ]; then
		echo "skip: $tool not built"
		echo "test_view_e2e: 0 passed, 0 failed, 1 skipped"
		exit 0
	fi
done
exec node tests/view/e2e.test.mjs
