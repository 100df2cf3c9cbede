#!/bin/sh
# Record proxima-run's golden outputs (tests/data/run_golden/) with the
# runner built at COMMIT (default d427248, the last commit before the
# runner became a main over app/px_app.h):
#
#   sh tests/tools/run_golden_record.sh [COMMIT]
#
# Builds that commit's tools in a temporary git worktree (make -j2), then
# runs the cases of run_golden_cases.sh from this tree (its configs) and
# writes the masked outputs. The heap counter is the one that commit's
# tools use: linked in (before the counter became a preloaded object) or
# its libproxima-alloc-count.so, preloaded.
set -eu
commit=${1:-d427248}
top=$(git rev-parse --show-toplevel)
cd "$top"
. tests/tools/run_golden_cases.sh
wt=$(mktemp -d)/proxima-golden
trap 'git worktree remove --force "$wt" >/dev/null 2>&1 || true' EXIT
git worktree add --detach "$wt" "$commit" >/dev/null
so=build/lib/libproxima-alloc-count.so
if grep -q 'ALLOC_SO' "$wt/Makefile"; then
	make -C "$wt" -j2 tools "$so" >/dev/null
	export LD_PRELOAD="$wt/$so"
else
	make -C "$wt" -j2 tools >/dev/null
fi
dest=tests/data/run_golden
rm -rf "$dest"
mkdir -p "$dest"
dest=$(cd "$dest" && pwd)
set +e # a case's own exit status is recorded, not fatal
golden_cases | while IFS= read -r line; do
	golden_run "$wt/build/bin/proxima-run" "$line" "$dest"
done
echo "$commit" >"$dest/COMMIT"
echo "run_golden_record: $(ls "$dest" | wc -l) files from $commit in tests/data/run_golden"
