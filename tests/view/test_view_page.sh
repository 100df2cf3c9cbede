#!/bin/sh
# The view page in headless chromium against the fixture server: live
# frames, reconnect, run end, replay and the report (page.test.mjs).
set -u
. tests/view/common.sh
view_ready test_view_page || exit 0
exec node tests/view/page.test.mjs
