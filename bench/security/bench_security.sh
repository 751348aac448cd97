#!/usr/bin/env bash
# What DDS Security costs (docs/security.md), measured in one run of this script:
#   1. round trip between two processes, dyad without and with `security:` (and bare Fast DDS),
#      alternating (build/bin/bench_pingpong --processes --security), for a 0-byte and a
#      16 KiB payload: the median round trip of the large one gives the ping-pong throughput;
#   2. the demo as a 100 ms wall-clock run in two processes (two_processes.yaml: the mind apart),
#      RUNS times each without and with `security:`, alternating: each component's step p99 from
#      dyad's timing table (median over the runs), and the secured/open ratio.
# Needs the demo's data set and models (`bash tools/demo.sh` makes them).
# usage: bash bench/security/bench_security.sh [RUNS] [SECONDS]   (defaults 3 runs of 30 s)
set -euo pipefail
here=$(cd "$(dirname "$0")/../.." && pwd)
runs=${1:-3} seconds=${2:-30}
cd "$here"
dyad=build/bin/dyad
for f in build/data/analytic/dataset.d build/models/demo.dpvrnn build/models/demo.dobs build/bin/bench_pingpong; do
  [ -e "$f" ] || { echo "bench_security: $f missing: run \`bash tools/demo.sh\` (and build the benchmarks) first" >&2; exit 2; }
done
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

echo "== round trip between two processes (bench_pingpong --processes --security)"
for payload in 0 16384; do
  build/bin/bench_pingpong --processes --security --payload "$payload" --rounds 5000 --repeats 3 2> "$tmp/pingpong.err" |
    grep -v "^dyad run"
  echo
done

echo "== the demo, two processes, wall clock, $seconds s per run, $runs runs each, alternating"
sets=(--set human.dataset=build/data/analytic --set mind.model=build/models/demo.dpvrnn --set observer.model=build/models/demo.dobs)
"$dyad" security init "$tmp/keys" --graph bench/security/two_processes.yaml "${sets[@]}" --set "recorder.file=$tmp/init.mcap" > "$tmp/init.log"
for i in $(seq "$runs"); do
  for mode in open secured; do
    extra=()
    [ $mode = secured ] && extra=(--set "security.keystore=$tmp/keys")
    "$dyad" run bench/security/two_processes.yaml --duration "$seconds" "${sets[@]}" "${extra[@]}" \
      --set "recorder.file=$tmp/$mode$i.mcap" > "$tmp/$mode$i.out" 2> "$tmp/$mode$i.err" ||
      { cat "$tmp/$mode$i.err" >&2; exit 1; }
  done
done
# The timing table's rows: "[process] component steps mean_ms p99_ms ..." (columns by header).
python3 - "$tmp" "$runs" <<'PY'
import re, statistics, sys, pathlib
tmp, runs = pathlib.Path(sys.argv[1]), int(sys.argv[2])
def p99s(path):
    out, cols = {}, None
    for line in path.read_text().splitlines():
        line = re.sub(r'^\[[^]]*\] ', '', line)
        words = line.split()
        if words[:1] == ['component']:
            cols = words
            continue
        if cols and len(words) == len(cols) and words[0] not in out:
            try:
                out[words[0]] = float(words[cols.index('p99_ms')])
            except (ValueError, IndexError):
                pass
    return out
table = {}
for mode in ('open', 'secured'):
    for i in range(1, runs + 1):
        for comp, v in p99s(tmp / f'{mode}{i}.out').items():
            table.setdefault(comp, {}).setdefault(mode, []).append(v)
print(f"{'component':<12} {'p99 open ms':>12} {'p99 secured ms':>15} {'ratio':>7}")
for comp, m in sorted(table.items()):
    if 'open' in m and 'secured' in m:
        o, s = statistics.median(m['open']), statistics.median(m['secured'])
        print(f"{comp:<12} {o:12.3f} {s:15.3f} {s / o if o else float('nan'):7.2f}")
PY
