#!/bin/sh
# The view end to end in headless chromium: proxima-run --view on a short
# simulated run (stopped and restarted: the page reconnects), then
# proxima-view's replay and HTML report of that run (e2e.test.mjs).
# PX_TEST_NEEDS: libwebsockets
set -u
. tests/view/common.sh
view_ready test_view_e2e || exit 0
view_tools test_view_e2e || exit 0
exec node tests/view/e2e.test.mjs
