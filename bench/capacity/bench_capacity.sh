#!/usr/bin/env bash
# Capacity: how many participants one machine hosts at once (#45 item 4). Not in CI.
#   bash bench/capacity/bench_capacity.sh [BUILD_DIR]
#   CAPACITY_NS="1 8 16 32 64"  the numbers of participants, in turn (the sweep stops after one
#                               that falls over: a session that does not start, or a deliberator
#                               step p99 past its 100 ms period)
#   CAPACITY_SECONDS=30         each level's measured window, all clients drawing
#   CAPACITY_CHROMIUM=2         of each level's participants (from 8 on), this many are the real
#                               subject's page in Debian's Chromium (the check that the simulated
#                               client is faithful: their pointer delays and rates beside the others')
#   CAPACITY_KEEP=1             keep each session's output (run.out, run.err, recording) and say where
#   CAPACITY_DATASET=DIR        the primitives the clients draw (default: the study's data set,
#                               ../shared/data/vcbot/dataset/Macaw, else the graph's analytic one)
# Each participant gets their own graph: configs/interactive.yaml on the wall clock (web component
# on loopback, web_human, the deliberator's PV-RNN, mixer, virtual robot, observer, learner,
# recorder), `dyad run` in its own process group, its own DDS domain and run id, its own tokens,
# recording and port; they are started one after another (each once its page answers, as
# participants arrive). Then one Node process drives N simulated participants
# (components/web/test/node/sim_participant.mjs: the subject page's protocol at its rates, the
# data set's primitives drawn with human timing and noise) for the window; then each graph is
# stopped by SIGINT and prints its timing table.
# Per level: the deliberator's (mind) step p99 against its 100 ms period, deadline misses of every
# component over each run's whole life (start-up and the other sessions' start-ups included), the
# pointer event (the client's wall-clock stamp) -> published on web/pointer p99 (the web
# component's measure, what web_human samples for human/input), the clients' ack round trip, each
# graph's RSS at the window's end, each graph's and the clients' CPU over the window, and the
# whole machine's busy share over the window (other users' load shows there).
# Models: build/models/demo.{dpvrnn,dobs} when tools/demo.sh made them, else trained here for a few
# epochs with the demo's settings into BUILD_DIR/bench-capacity (a step costs the same however long
# the model was trained).
set -euo pipefail
here=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:-$here/build}" && pwd)
dyad=$build/bin/dyad
node_dir=$here/components/web/test/node
ns=${CAPACITY_NS:-1 8 16 32 64}
seconds=${CAPACITY_SECONDS:-30}
chromium=${CAPACITY_CHROMIUM:-2}
[ -x "$dyad" ] || { echo "bench_capacity: $dyad not built" >&2; exit 2; }
[ -d "$node_dir/node_modules" ] || { echo "bench_capacity: needs tools/setup.sh (npm ci in $node_dir)" >&2; exit 2; }
for n in $ns; do [[ $n =~ ^[1-9][0-9]*$ ]] && [ "$n" -le 120 ] || { echo "bench_capacity: CAPACITY_NS: '$n' is not 1..120" >&2; exit 2; }; done
[[ $chromium =~ ^[0-9]+$ ]] || { echo "bench_capacity: CAPACITY_CHROMIUM: '$chromium' is not a whole number" >&2; exit 2; }
[ "$chromium" = 0 ] || [ -x /usr/bin/chromium ] || { echo "bench_capacity: CAPACITY_CHROMIUM=$chromium needs Debian's chromium (or CAPACITY_CHROMIUM=0)" >&2; exit 2; }
[[ $seconds =~ ^[1-9][0-9]*$ ]] || { echo "bench_capacity: CAPACITY_SECONDS: '$seconds' is not a whole number of seconds > 0" >&2; exit 2; }

# A snapshot of the build (dyad, its libraries and plugins, found beside libdyad_runtime.so): a
# shared build tree that someone rebuilds meanwhile would otherwise stop sessions from starting.
work=$(mktemp -d)
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill -INT "$p" 2> /dev/null || true; done
  wait 2> /dev/null || true
  if [ "${CAPACITY_KEEP:-0}" = 1 ]; then echo "kept: $work (nN/sI: each session's run.out, run.err, rec.mcap)"; else rm -rf "$work"; fi
}
trap cleanup EXIT
mkdir -p "$work/build/bin" "$work/build/lib"
cp "$dyad" "$work/build/bin/"
cp -a "$build"/lib/*.so* "$work/build/lib/" 2> /dev/null || true
cp -a "$build/plugins" "$build/share" "$work/build/" 2> /dev/null || true
dyad=$work/build/bin/dyad
export LD_LIBRARY_PATH=$work/build/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}

cache=$build/bench-capacity
mkdir -p "$cache"
dataset=$build/data/analytic model=$build/models/demo.dpvrnn observer=$build/models/demo.dobs
if [ ! -f "$model" ] || [ ! -f "$observer" ] || [ ! -d "$dataset" ]; then
  dataset=$cache/analytic model=$cache/demo.dpvrnn observer=$cache/demo.dobs
  [ -d "$dataset" ] || "$dyad" generate dataset --out "$dataset" > /dev/null
  [ -f "$model" ] || "$dyad" train "$here/configs/train/demo.yaml" --set "dataset=$dataset" --set "output=$model" \
    --set epochs=300 --set log_every=300 --set checkpoint_every=300 > "$cache/train.log" 2>&1
  [ -f "$observer" ] || "$dyad" train-observer "$model" -o "$observer" --epochs 20 > "$cache/observer.log" 2>&1
fi
drawn=${CAPACITY_DATASET:-$here/../shared/data/vcbot/dataset/Macaw}
[ -d "$drawn" ] || drawn=$dataset

base=$(( 100 + $$ % 60 ))  # domains base+1 .. base+N (<= 232)

start_session() {  # start_session DIR I
  local d=$1 i=$2
  mkdir -p "$d"
  setsid "$dyad" run "$here/configs/interactive.yaml" --run-id "s$i" --set "domain_id=$(( base + i ))" \
    --set web.port=0 --set "web.port_file=$d/web.port" --set "web.dataset=$dataset" \
    --set "web.token=$(printf 'experimenter-%08d' "$i")" --set "web.subject_token=$(printf 'subject-token-%08d' "$i")" \
    --set "web.viewer_token=$(printf 'viewer-token-%08d' "$i")" --set "mind.model=$model" --set "observer.model=$observer" \
    --set "recorder.file=$d/rec.mcap" --set "learner.out=$d/learned" > "$d/run.out" 2> "$d/run.err" &
  pids+=($!)
  for _ in $(seq 600); do [ -s "$d/web.port" ] && return 0; kill -0 "$!" 2> /dev/null || break; sleep 0.1; done
  echo "bench_capacity: session $i did not start:" >&2; tail -5 "$d/run.err" >&2
  return 1
}
# A process's user + system time in ticks; its RSS in MB ("nan": it has ended).
cpu_ticks() { awk '{ print $14 + $15 }' "/proc/$1/stat" 2> /dev/null || echo nan; }
rss_mb() { awk '/^VmRSS/ { print $2 / 1024 }' "/proc/$1/status" 2> /dev/null || echo nan; }
busy_ticks() { awk '/^cpu / { print $2 + $3 + $4 + $7 + $8, $2 + $3 + $4 + $5 + $6 + $7 + $8 }' /proc/stat; }
hz=$(getconf CLK_TCK)

echo "| participants | started | mind step p99, ms (median / worst session; period 100) | deadline misses (sessions with any) | pointer -> published p99, ms (median / worst) | clients' ack round trip p99, ms (median) | RSS per session, MB (mean) | CPU per session, % of a core (mean) | clients' CPU, % of a core | machine busy, % of 2 cores (load avg) | Chromium participants: pointer -> published p99, samples/s (simulated: median samples/s) |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
knee="" cost=""
for n in $ns; do
  level=$work/n$n
  mkdir -p "$level"
  pids=()
  : > "$level/sessions"
  started=0
  for i in $(seq "$n"); do
    start_session "$level/s$i" "$i" || break
    echo "http://127.0.0.1:$(cat "$level/s$i/web.port") $(printf 'subject-token-%08d' "$i")" >> "$level/sessions"
    started=$i
  done
  read -r busy0 all0 < <(busy_ticks)
  for i in $(seq "$started"); do cpu_ticks "${pids[$((i - 1))]}"; done > "$level/cpu0"
  clients_out=$level/clients.json
  k=0; [ "$n" -lt 8 ] || k=$(( chromium < n ? chromium : n ))
  node "$node_dir/sim_participant.mjs" --dataset "$drawn" --seconds "$seconds" --chromium "$k" "$level/sessions" > "$clients_out" &
  client=$!
  sleep "$seconds"
  for i in $(seq "$started"); do cpu_ticks "${pids[$((i - 1))]}"; done > "$level/cpu1"
  for i in $(seq "$started"); do rss_mb "${pids[$((i - 1))]}"; done > "$level/rss"
  read -r busy1 all1 < <(busy_ticks)
  load=$(cut -d' ' -f1 /proc/loadavg)
  wait "$client" || true
  for p in "${pids[@]}"; do kill -INT "$p" 2> /dev/null || true; done
  for p in "${pids[@]}"; do wait "$p" 2> /dev/null || true; done
  pids=()
  for i in $(seq "$started"); do
    d=$level/s$i
    awk '$1 == "mind" && NF >= 8 { print $4 }' "$d/run.out" > "$d/mind_p99"
    awk '/^timing/ { t = 1; next } t && NF >= 8 && $2 ~ /^[0-9]+$/ { m += $8 } END { print m + 0 }' "$d/run.out" > "$d/misses"
    { grep -o "pointer event -> published: .*" "$d/run.err" || true; } | sed -E 's/.*p99 ([0-9.]+) ms \(([0-9]+) samples.*/\1 \2/' > "$d/pointer"
  done
  python3 - "$level" "$started" "$n" "$seconds" "$hz" "$busy1" "$busy0" "$all1" "$all0" "$load" "$k" > "$level/row" <<'PY'
import json, statistics, sys
level, started, n, seconds, hz = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5])
busy1, busy0, all1, all0, load = map(float, sys.argv[6:11])
k = int(sys.argv[11])  # sessions 1..k: Chromium's
def read(i, name, field=0):
    try:
        text = open(f"{level}/s{i}/{name}").read().split()
        return float(text[field]) if text else None
    except OSError:
        return None
rows = range(1, started + 1)
mind = [v for v in (read(i, "mind_p99") for i in rows) if v is not None]
misses = [read(i, "misses") or 0 for i in rows]
pointer = [v for v in (read(i, "pointer") for i in rows) if v is not None]
sim_p99 = [v for v in (read(i, "pointer") for i in rows if i > k) if v is not None]
sim_rate = [v / seconds for v in (read(i, "pointer", 1) for i in rows if i > k) if v is not None]
chr_p99 = [v for v in (read(i, "pointer") for i in rows if i <= k) if v is not None]
chr_rate = [v / seconds for v in (read(i, "pointer", 1) for i in rows if i <= k) if v is not None]
cpu0 = [float(x) for x in open(f"{level}/cpu0").read().split()]
cpu1 = [float(x) for x in open(f"{level}/cpu1").read().split()]
cpu = [100 * (b - a) / hz / seconds for a, b in zip(cpu0, cpu1)]
rss = [float(x) for x in open(f"{level}/rss").read().split()]
clients = [json.loads(l) for l in open(f"{level}/clients.json") if l.strip()]
rtt = [c["rtt_p99_ms"] for c in clients if c.get("rtt_p99_ms") is not None]
client_cpu = next((100 * c["clients_cpu_s"] / c["seconds"] for c in clients if "clients_cpu_s" in c), float("nan"))
fmt = lambda v: "-" if v is None else f"{v:.1f}"
med = lambda a: statistics.median(a) if a else None
mean = lambda a: statistics.mean(a) if a else None
busy = 100 * (busy1 - busy0) / (all1 - all0) if all1 > all0 else float("nan")
print(f"| {n} | {started} | {fmt(med(mind))} / {fmt(max(mind) if mind else None)} | {int(sum(misses))} ({sum(1 for m in misses if m)}) | "
      f"{fmt(med(pointer))} / {fmt(max(pointer) if pointer else None)} | {fmt(med(rtt))} | {fmt(mean(rss))} | {fmt(mean(cpu))} | "
      f"{client_cpu:.1f} | {busy:.0f} ({load:.2f}) | "
      + (f"{k}: p99 {' '.join(fmt(v) for v in chr_p99)} ms, {' '.join(f'{v:.0f}' for v in chr_rate)}/s; simulated: {fmt(med(sim_rate))}/s |" if k else "- |"))
fell = started < n or not mind or max(mind) > 100 or len(pointer) < started
print("FELL" if fell else "UP", int(sum(misses)), fmt(mean(cpu)), fmt(mean(rss)))
PY
  head -1 "$level/row"
  read -r state misses c r < <(tail -1 "$level/row")
  if [ -z "$knee" ] && [ "$misses" -gt 0 ]; then knee=$n; fi
  if [ "$misses" = 0 ] && [ "$state" = UP ]; then cost="$c% of a core and $r MB per session (at N = $n)"; fi
  [ "$state" = UP ] || { echo; echo "stopped: $n participants fell over (a session did not start, or the deliberator's p99 passed its period)"; break; }
done
echo
echo "knee (the first N with a deadline miss): ${knee:-none up to the last level}"
echo "cost: ${cost:-no level without misses}"
echo "clients drew: $drawn; model: $model; each level's window: $seconds s; $(nproc) cores"
