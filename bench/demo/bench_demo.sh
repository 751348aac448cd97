#!/usr/bin/env bash
# The whole demo experiment's wall time in stepped mode (issue 5's target: 2,000 steps < 10 s,
# training aside), and where the time goes: each component's mean step time from dyad's own
# timing table. Needs the data set, model and observer that `bash tools/demo.sh [name]` makes;
# runs the experiment RUNS times (default 5) with the recorder on, and prints a table.
# usage: bash bench/demo/bench_demo.sh [RUNS] [demo|macaw]
set -euo pipefail
here=$(cd "$(dirname "$0")/../.." && pwd)
runs=${1:-5} name=${2:-demo}
cd "$here"
if [ "$name" = demo ]; then
  sets=(--set human.dataset=build/data/analytic --set mind.model=build/models/demo.dpvrnn --set observer.model=build/models/demo.dobs)
  needs=(build/data/analytic/dataset.d build/models/demo.dpvrnn build/models/demo.dobs)
else
  sets=(--set mind.model=build/models/macawbot.dpvrnn --set observer.model=build/models/macawbot.dobs)
  needs=(build/models/macawbot.dpvrnn build/models/macawbot.dobs)
fi
for f in "${needs[@]}"; do
  [ -f "$f" ] || { echo "bench_demo: $f missing: run \`bash tools/demo.sh $name\` first" >&2; exit 2; }
done
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
times=()
for i in $(seq "$runs"); do
  start=$(date +%s%N)
  build/bin/dyad run "configs/$name.yaml" --steps 2000 "${sets[@]}" --set "recorder.file=$tmp/run$i.mcap" > "$tmp/run$i.log" 2> "$tmp/run$i.err"
  times+=($(( ($(date +%s%N) - start) / 1000 )))
done
sorted=($(printf '%s\n' "${times[@]}" | sort -n))
us() { printf '%d.%03d' $(($1 / 1000000)) $((($1 / 1000) % 1000)); }
echo "configs/$name.yaml, 2,000 steps of 100 ms (200 s simulated), stepped clock, recorder on, $runs runs"
echo "wall time (s):"
printf '  %-26s %10s\n' median "$(us "${sorted[$((runs / 2))]}")" min "$(us "${sorted[0]}")" max "$(us "${sorted[$((runs - 1))]}")"
printf '  %-26s %10s\n' "speed-up over real time" "$(( 200000000 / sorted[runs / 2] ))x"
echo "per component (last run; dyad's timing table, ms per step):"
sed -n '/^component/,$p' "$tmp/run$runs.log" | awk '{printf "  %-14s %8s %10s %10s\n", $1, $2, $3, $4}'
