#!/usr/bin/env bash
# `dyad sweep` throughput: a 64-run sweep of the demo (8 compliance gains x 8 seeds, 2,000 steps
# each, models trained briefly here) with 2 workers against 1, measured in one run, and the
# per-run cost of the sweep (its `dyad analyze` and bookkeeping) against a bare `dyad run` of
# the same graph. Prints a table.
#   bash bench/sweep/bench_sweep.sh [BUILD_DIR]
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$repo/build}
dyad=$build/bin/dyad
work=$(mktemp -d /tmp/dyad_bench_sweep.XXXXXX)
trap 'rm -rf "$work"' EXIT
cd "$work"
"$dyad" generate dataset --out data > /dev/null
"$dyad" train "$repo/configs/train/demo.yaml" --set dataset="$work/data" --set output="$work/demo.dpvrnn" \
  --set epochs=200 --set log_every=200 > /dev/null
"$dyad" train-observer demo.dpvrnn -o demo.dobs --epochs 200 > /dev/null
sets="human.dataset: $work/data, mind.model: $work/demo.dpvrnn, observer.model: $work/demo.dobs"
cat > s.yaml <<YAML
sweep: bench
graph: $repo/configs/demo.yaml
duration: 200
set: {$sets}
grid:
  mixer.gain: [0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9]
seeds: [1, 2, 3, 4, 5, 6, 7, 8]
YAML
now() { date +%s.%N; }
t0=$(now); "$dyad" sweep s.yaml -o one -j 1 --no-plots > /dev/null; t1=$(now)
"$dyad" sweep s.yaml -o two -j 2 --no-plots > /dev/null; t2=$(now)
cmp -s one/sweep.csv two/sweep.csv || { echo "the tables differ"; exit 1; }
bare_runs=16
t3=$(now)
for i in $(seq $bare_runs); do
  "$dyad" run "$repo/configs/demo.yaml" --quiet --duration 200 --set clock=stepped --set seed=$i \
    --set human.dataset="$work/data" --set mind.model="$work/demo.dpvrnn" --set observer.model="$work/demo.dobs" \
    --set recorder.file="$work/bare.mcap" --set recorder.overwrite=true > /dev/null 2>&1
done
t4=$(now)
python3 - "$t0" "$t1" "$t2" "$t3" "$t4" "$bare_runs" <<'PY'
import sys
t0, t1, t2, t3, t4 = map(float, sys.argv[1:6]); bare = int(sys.argv[6])
one, two, b = t1 - t0, t2 - t1, (t4 - t3) / bare
print("| what | result |")
print("| --- | --- |")
print(f"| 64 runs, 1 worker | {one:.1f} s ({64 / one:.1f} runs/s) |")
print(f"| 64 runs, 2 workers | {two:.1f} s ({64 / two:.1f} runs/s) |")
print(f"| throughput, 2 workers / 1 | x{one / two:.2f} |")
print(f"| bare `dyad run` of one run (mean of {bare}) | {b * 1e3:.0f} ms |")
print(f"| sweep's cost per run over a bare run (1 worker: analysis, bookkeeping) | {(one / 64 - b) * 1e3:+.0f} ms |")
PY
