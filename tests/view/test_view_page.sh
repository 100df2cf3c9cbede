#!/bin/sh
# The view page in headless chromium against the fixture server: live
# frames, reconnect, run end, replay and the report (page.test.mjs).
set -u
# The page and the fixture have no C in them: the sanitizer build's run
# would repeat the plain one.
if [ "${SAN:-}" = 1 ]; then
	echo "skip: no C under test (runs in the plain build)"
	echo "test_view_page: 0 passed, 0 failed, 1 skipped"
	exit 0
fi
. tests/view/common.sh
view_ready test_view_page || exit 0
exec node tests/view/page.test.mjs
