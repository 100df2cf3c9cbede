# Sourced by the browser tests: view_ready NAME prints why the test
# cannot run here (and a skipped summary line), or nothing when node 20+,
# chromium, the view page's npm packages and the built page are present.
view_ready() {
	why=""
	chromium=${PX_CHROMIUM:-/usr/bin/chromium}
	major=$(node -p 'process.versions.node.split(".")[0]' 2>/dev/null || echo 0)
	if [ "$major" -lt 20 ]; then why="node 20 or newer not found"
	elif [ ! -x "$chromium" ]; then why="$chromium not installed (make deps)"
	elif [ ! -f view/web/node_modules/playwright-core/package.json ] ||
	     [ ! -f view/web/node_modules/ws/package.json ]; then why="npm packages of view/web not installed (make deps)"
	elif [ ! -f "${BUILD:-build}/view/web/report-template.html" ]; then why="the page is not built (make view-web)"
	fi
	[ -z "$why" ] && return 0
	echo "skip: $why"
	echo "$1: 0 passed, 0 failed, 1 skipped"
	return 1
}

# view_tools NAME: the same for the project's tools the end-to-end tests
# run (proxima-run, proxima-view).
view_tools() {
	for tool in proxima-run proxima-view; do
		if [ ! -x "${PX_VIEW_BIN:-${BUILD:-build}/bin}/$tool" ]; then
			echo "skip: $tool not built"
			echo "$1: 0 passed, 0 failed, 1 skipped"
			return 1
		fi
	done
	return 0
}
