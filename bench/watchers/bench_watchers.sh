#!/usr/bin/env bash
# Do watchers disturb a running experiment? tests/watcher_stress_test.sh's scenario (a 100 Hz
# wall-clock graph; 20 `dyad echo`/`hz` watchers started and killed by SIGPIPE, SIGINT and
# SIGKILL beside it), timed: steps longer than two periods and the longest gap between robot
# states, watched vs the same graph alone for the same time, as ratios measured in one run
# (ratio ~1: watchers cost the graph nothing; the machine's own load shows in both columns).
#   bash bench/watchers/bench_watchers.sh [BUILD_DIR (default build)]
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:-$repo/build}" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
bash "$repo/tests/watcher_stress_test.sh" "$build/bin/dyad" "$work/run" --timing > "$work/out.txt" 2>&1 ||
  { cat "$work/out.txt"; echo "bench_watchers: the scenario's functional checks failed" >&2; exit 1; }
cat "$work/run/timing.txt"
