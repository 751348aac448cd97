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
#   CAPACITY_FRONT=direct       direct: each client connects to its graph's own web component;
#                               serve: through ONE `dyad study serve` (below)
#   CAPACITY_ARRIVAL_S=3        serve: seconds allowed per participant's arrival (the trials' length
#                               is the window plus N times this plus 10 s)
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
#
# CAPACITY_FRONT=serve: the N participants are the N participants of one study generated per
# level (BUILD_DIR's copy of configs/interactive.yaml, as above; each running trial on a DDS domain
# of its own, from the graph's on, as study serve gives them; one condition; one trial each, the window plus the arrivals' allowance long; consent required, its
# text; `dyad study links` for their tokens), served by ONE `dyad study serve` on loopback (port
# 0, --port-file, --max-sessions N): each participant's trial is a `dyad run` child of the front
# (its own process group, its log beside its recording: DATA/P001/01-capacity.log) and their page
# is relayed by the front. One Node process (bench/capacity/online_clients.mjs: sim_participant.mjs's
# --online participants, the first K in Chromium as above) opens the links one after another:
# each once the previous participant's trial said hello (consent, Ready, their graph started and
# relayed). The window starts when all are in; the trials then end on their own (done, with the
# completion code) and the front is stopped. Reported beside the direct mode's columns: Ready ->
# the trial's hello (the page pressing Ready to the graph's first frame through the relay: the
# graph's start-up and the relay's connect), the front's RSS and CPU over the window and its CPU
# per participant (the relay's own cost); the clients' round trip is through the relay.
# Everything started (the front, every trial's graph, Node and its Chromium) is stopped on exit,
# Ctrl-C included. A trial's deadline misses include its start's: its graph waits for the page
# (wait_for_subject_s) in the web component's Activate, after the executor fixed its wall clock's
# start (SoloSession::AwaitStart), so the first step of web, human and mind is late by that wait
# (jitter_max_ms, 0.1-0.2 s) and each counts a miss: the row says how many fell in the trials'
# first second (each recording's first dyad/stats), and the knee counts the others. Ready -> hello
# moves in the front's relay retries (200 ms while the graph starts). A level also falls over when
# a participant ends without their completion code.
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
mode=${CAPACITY_FRONT:-direct}
arrival=${CAPACITY_ARRIVAL_S:-3}
[ -x "$dyad" ] || { echo "bench_capacity: $dyad not built" >&2; exit 2; }
[ -d "$node_dir/node_modules" ] || { echo "bench_capacity: needs tools/setup.sh (npm ci in $node_dir)" >&2; exit 2; }
for n in $ns; do [[ $n =~ ^[1-9][0-9]*$ ]] && [ "$n" -le 120 ] || { echo "bench_capacity: CAPACITY_NS: '$n' is not 1..120" >&2; exit 2; }; done
[[ $chromium =~ ^[0-9]+$ ]] || { echo "bench_capacity: CAPACITY_CHROMIUM: '$chromium' is not a whole number" >&2; exit 2; }
[ "$chromium" = 0 ] || [ -x /usr/bin/chromium ] || { echo "bench_capacity: CAPACITY_CHROMIUM=$chromium needs Debian's chromium (or CAPACITY_CHROMIUM=0)" >&2; exit 2; }
[[ $seconds =~ ^[1-9][0-9]*$ ]] || { echo "bench_capacity: CAPACITY_SECONDS: '$seconds' is not a whole number of seconds > 0" >&2; exit 2; }
[ "$mode" = direct ] || [ "$mode" = serve ] || { echo "bench_capacity: CAPACITY_FRONT: '$mode' is neither direct nor serve" >&2; exit 2; }
[[ $arrival =~ ^[1-9][0-9]*$ ]] || { echo "bench_capacity: CAPACITY_ARRIVAL_S: '$arrival' is not a whole number of seconds > 0" >&2; exit 2; }

# A snapshot of the build (dyad, its libraries and plugins, found beside libdyad_runtime.so): a
# shared build tree that someone rebuilds meanwhile would otherwise stop sessions from starting.
work=$(mktemp -d)
pids=()     # direct: each session's `dyad run` (a process group of its own)
front=""    # serve: the level's `dyad study serve` (a process group of its own)
client=""   # the level's Node process (a process group of its own: Chromium is in it)
# Stops what runs: the clients (SIGINT: Node closes Chromium and exits; still there after 10 s:
# killed with its group), then the graphs (direct: SIGINT, they print their timing) or the front
# (SIGTERM: it stops each trial as `dyad study run` does, then exits; still there after 30 s:
# killed with its group, and each trial's group it had).
stop_all() {
  if [ -n "$client" ]; then
    kill -INT -- "-$client" 2> /dev/null || true
    for _ in $(seq 100); do kill -0 "$client" 2> /dev/null || break; sleep 0.1; done
    kill -KILL -- "-$client" 2> /dev/null || true
  fi
  for p in "${pids[@]}"; do kill -INT "$p" 2> /dev/null || true; done
  if [ -n "$front" ]; then
    local graphs
    graphs=$(ps -o pid= --ppid "$front" 2> /dev/null || true)
    kill -TERM "$front" 2> /dev/null || true
    for _ in $(seq 300); do kill -0 "$front" 2> /dev/null || break; sleep 0.1; done
    if kill -0 "$front" 2> /dev/null; then
      echo "bench_capacity: dyad study serve did not stop within 30 s: killed, with its trials" >&2
      kill -KILL -- "-$front" 2> /dev/null || true
      for g in $graphs; do kill -KILL -- "-$g" 2> /dev/null || true; done
    fi
  fi
  wait 2> /dev/null || true
  pids=() front="" client=""
}
cleanup() {
  stop_all
  if [ "${CAPACITY_KEEP:-0}" = 1 ]; then echo "kept: $work (nN/sI: each session's run.out, run.err, rec.mcap; serve: nN/study/data/P001/01-capacity.{log,mcap}, nN/front.out)"; else rm -rf "$work"; fi
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM HUP
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

base=$(( 1 + $$ % 60 ))  # domains base .. base+N (<= 232: N <= 171)

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

# direct_level LEVEL N K: N sessions started one after another, then the clients drive them for
# the window, then each graph is stopped (SIGINT: it prints its timing table). Sets started.
direct_level() {
  local level=$1 n=$2 k=$3 i
  : > "$level/sessions"
  started=0
  for i in $(seq "$n"); do
    start_session "$level/s$i" "$i" || break
    echo "http://127.0.0.1:$(cat "$level/s$i/web.port") $(printf 'subject-token-%08d' "$i")" >> "$level/sessions"
    started=$i
  done
  read -r busy0 all0 < <(busy_ticks)
  for i in $(seq "$started"); do cpu_ticks "${pids[$((i - 1))]}"; done > "$level/cpu0"
  setsid node "$node_dir/sim_participant.mjs" --dataset "$drawn" --seconds "$seconds" --chromium "$k" "$level/sessions" > "$level/clients.json" &
  client=$!
  sleep "$seconds"
  for i in $(seq "$started"); do cpu_ticks "${pids[$((i - 1))]}"; done > "$level/cpu1"
  for i in $(seq "$started"); do rss_mb "${pids[$((i - 1))]}"; done > "$level/rss"
  read -r busy1 all1 < <(busy_ticks)
  load=$(cut -d' ' -f1 /proc/loadavg)
  wait "$client" || true
  client=""
  for p in "${pids[@]}"; do kill -INT "$p" 2> /dev/null || true; done
  for p in "${pids[@]}"; do wait "$p" 2> /dev/null || true; done
  pids=()
}

# serve_study DIR N: the level's study in DIR: its graph (configs/interactive.yaml with the bench's
# models; its domain_id the first of the trials'), the consent text, N participants P001.., one condition, one trial of
# $duration s each; their links (tokens) by `dyad study links`.
serve_study() {
  local d=$1 n=$2 list="" i
  mkdir -p "$d"
  for i in $(seq "$n"); do list+="${list:+, }$(printf 'P%03d' "$i")"; done
  echo "I agree to take part in this capacity benchmark (a simulated participant)." > "$d/consent.txt"
  cat > "$d/graph.yaml" << YAML
# bench_capacity.sh, CAPACITY_FRONT=serve: configs/interactive.yaml with the bench's models.
extends: "$here/configs/interactive.yaml"
domain_id: $base
components:
  web: {params: {dataset: "$dataset"}}
  mind: {params: {model: "$model"}}
  observer: {params: {model: "$observer"}}
  learner: {params: {out: "$d/learned"}}
YAML
  cat > "$d/study.yaml" << YAML
study: capacity
graph: graph.yaml
data: data
participants: [$list]
conditions:
  capacity: {mixer.gain: 0.9}
trials: 1
duration: $duration
consent_required: true
online: {max_sessions: $n, consent: consent.txt}
YAML
  "$dyad" study links "$d/study.yaml" --base-url http://127.0.0.1:8443 > "$d/links.out"
}

# serve_level LEVEL N K: one `dyad study serve` of the level's study, the clients arriving one
# after another; the window starts once all are in; the trials end on their own, then the front
# is stopped. Each participant's trial log is linked as LEVEL/sI/run.out and run.err. Sets started.
serve_level() {
  local level=$1 n=$2 k=$3 d=$1/study i port in_ms
  serve_study "$d" "$n"
  setsid "$dyad" study serve "$d/study.yaml" --port 0 --port-file "$level/front.port" --max-sessions "$n" \
    > "$level/front.out" 2> "$level/front.err" &
  front=$!
  for _ in $(seq 300); do [ -s "$level/front.port" ] && break; kill -0 "$front" 2> /dev/null || break; sleep 0.1; done
  [ -s "$level/front.port" ] || { echo "bench_capacity: dyad study serve did not start:" >&2; tail -5 "$level/front.err" >&2; exit 1; }
  port=$(cat "$level/front.port")
  tail -n +2 "$d/data/links.csv" | sed -E "s|^[^,]*,.*[?&]token=([^&]*)\$|http://127.0.0.1:$port \\1|" > "$level/sessions"
  setsid node "$here/bench/capacity/online_clients.mjs" --dataset "$drawn" --chromium "$k" --in "$level/in" \
    --cap $(( 2 * n * arrival + duration + 60 )) --arrive-timeout $(( 2 * arrival + 30 )) "$level/sessions" \
    > "$level/clients.json" 2> "$level/clients.err" &
  client=$!
  for _ in $(seq $(( (n * (2 * arrival + 30) + 10) * 10 ))); do [ -s "$level/in" ] && break; kill -0 "$client" 2> /dev/null || break; sleep 0.1; done
  [ -s "$level/in" ] || { echo "bench_capacity: the clients ended before all arrived:" >&2; tail -5 "$level/clients.err" >&2; exit 1; }
  read -r in_ms started < "$level/in"
  ps -o pid= --ppid "$front" > "$level/graphs"  # the trials' `dyad run`s
  read -r busy0 all0 < <(busy_ticks)
  for p in $(cat "$level/graphs"); do cpu_ticks "$p"; done > "$level/cpu0"
  echo "$(cpu_ticks "$front") $(cpu_ticks "$client")" > "$level/own0"
  sleep "$seconds"
  for p in $(cat "$level/graphs"); do cpu_ticks "$p"; done > "$level/cpu1"
  for p in $(cat "$level/graphs"); do rss_mb "$p"; done > "$level/rss"
  echo "$(cpu_ticks "$front") $(cpu_ticks "$client") $(rss_mb "$front") $(( $(date +%s%3N) - in_ms ))" > "$level/own1"
  read -r busy1 all1 < <(busy_ticks)
  load=$(cut -d' ' -f1 /proc/loadavg)
  wait "$client" || true
  client=""
  kill -TERM "$front" 2> /dev/null || true
  wait "$front" || true
  front=""
  for i in $(seq "$n"); do  # a participant whose trial never started has no log
    local trial
    trial=$d/data/$(printf 'P%03d' "$i")/01-capacity
    mkdir -p "$level/s$i"
    [ -f "$trial.log" ] || continue
    ln -sf "$trial.log" "$level/s$i/run.out"
    ln -sf "$trial.log" "$level/s$i/run.err"
    "$dyad" bag export "$trial.mcap" --csv "$level/s$i/stats" --topic dyad/stats > /dev/null 2>&1 || true
  done
}

if [ "$mode" = serve ]; then
  echo "| participants | started | mind step p99, ms (median / worst session; period 100) | deadline misses (sessions with any; of them in the trials' first second) | pointer -> published p99, ms (median / worst) | clients' ack round trip p99 through the front, ms (median) | RSS per session, MB (mean) | CPU per session, % of a core (mean) | front: RSS, MB; CPU, % of a core (per participant) | Ready -> trial's hello, s (median / worst) | done with a code | clients' CPU, % of a core | machine busy, % of 2 cores (load avg) | Chromium participants: pointer -> published p99, samples/s (simulated: median samples/s) |"
  echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
else
  echo "| participants | started | mind step p99, ms (median / worst session; period 100) | deadline misses (sessions with any) | pointer -> published p99, ms (median / worst) | clients' ack round trip p99, ms (median) | RSS per session, MB (mean) | CPU per session, % of a core (mean) | clients' CPU, % of a core | machine busy, % of 2 cores (load avg) | Chromium participants: pointer -> published p99, samples/s (simulated: median samples/s) |"
  echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
fi
knee="" cost=""
for n in $ns; do
  level=$work/n$n
  mkdir -p "$level"
  k=0; [ "$n" -lt 8 ] || k=$(( chromium < n ? chromium : n ))
  duration=$(( seconds + n * arrival + 10 ))  # serve: each trial's length
  if [ "$mode" = serve ]; then serve_level "$level" "$n" "$k"; else direct_level "$level" "$n" "$k"; fi
  for i in $(seq "$([ "$mode" = serve ] && echo "$n" || echo "$started")"); do
    d=$level/s$i
    [ -e "$d/run.out" ] || continue
    awk '$1 == "mind" && NF >= 8 { print $4 }' "$d/run.out" > "$d/mind_p99"
    awk '/^timing/ { t = 1; next } t && NF >= 8 && $2 ~ /^[0-9]+$/ { m += $8 } END { print m + 0 }' "$d/run.out" > "$d/misses"
    { grep -o "pointer event -> published: .*" "$d/run.err" || true; } | sed -E 's/.*p99 ([0-9.]+) ms \(([0-9]+) samples.*/\1 \2/' > "$d/pointer"
  done
  python3 - "$level" "$started" "$n" "$seconds" "$hz" "$busy1" "$busy0" "$all1" "$all0" "$load" "$k" "$mode" "$duration" > "$level/row" <<'PY'
import json, math, statistics, sys
level, started, n, seconds, hz = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5])
busy1, busy0, all1, all0, load = map(float, sys.argv[6:11])
k = int(sys.argv[11])  # sessions 1..k: Chromium's
serve = sys.argv[12] == "serve"
lived = float(sys.argv[13]) if serve else seconds  # how long a session's pointer samples came in
def read(i, name, field=0):
    try:
        text = open(f"{level}/s{i}/{name}").read().split()
        return float(text[field]) if text else None
    except OSError:
        return None
rows = range(1, (n if serve else started) + 1)  # serve: a participant without a trial reads as none
mind = [v for v in (read(i, "mind_p99") for i in rows) if v is not None]
misses = [read(i, "misses") or 0 for i in rows]
pointer = [v for v in (read(i, "pointer") for i in rows) if v is not None]
sim_p99 = [v for v in (read(i, "pointer") for i in rows if i > k) if v is not None]
sim_rate = [v / lived for v in (read(i, "pointer", 1) for i in rows if i > k) if v is not None]
chr_p99 = [v for v in (read(i, "pointer") for i in rows if i <= k) if v is not None]
chr_rate = [v / lived for v in (read(i, "pointer", 1) for i in rows if i <= k) if v is not None]
numbers = lambda name: [float(x) for x in open(f"{level}/{name}").read().split()]
cpu = [100 * (b - a) / hz / seconds for a, b in zip(numbers("cpu0"), numbers("cpu1"))]
cpu = [c for c in cpu if not math.isnan(c)]  # a graph ended within the window: left out
rss = [r for r in numbers("rss") if not math.isnan(r)]
clients = [json.loads(l) for l in open(f"{level}/clients.json") if l.strip()]
rtt = [c["rtt_p99_ms"] for c in clients if c.get("rtt_p99_ms") is not None]
client_cpu = next((100 * c["clients_cpu_s"] / c["seconds"] for c in clients if "clients_cpu_s" in c), float("nan"))
fmt = lambda v: "-" if v is None or math.isnan(v) else f"{v:.1f}"
med = lambda a: statistics.median(a) if a else None
mean = lambda a: statistics.mean(a) if a else None
busy = 100 * (busy1 - busy0) / (all1 - all0) if all1 > all0 else float("nan")
front, notes = "", []
def start_misses(i):  # serve: a trial's misses in its first second (its first dyad/stats per component)
    first = {}
    try:
        with open(f"{level}/s{i}/stats/dyad_stats.csv") as f:
            header = f.readline().strip().split(",")
            name, count = header.index("component_name"), header.index("deadline_misses")
            for line in f:
                row = line.strip().split(",")
                first.setdefault(row[name], int(row[count]))
    except (OSError, ValueError, IndexError):
        return None
    return sum(first.values())
starts = [start_misses(i) for i in rows] if serve else []
if serve:  # the front's own cost over the window, the arrivals, the codes
    (f0, c0), (f1, c1, front_rss, window_ms) = numbers("own0"), numbers("own1")
    front_cpu = 100 * (f1 - f0) / hz / seconds
    client_cpu = 100 * (c1 - c0) / hz / seconds  # Node's over the window (Chromium's own processes not in it)
    hello = [c["ready_to_hello_ms"] / 1000 for c in clients if c.get("ready_to_hello_ms") is not None]
    done = [c for c in clients if c.get("code")]
    in_ms = float(open(f"{level}/in").read().split()[0])
    first_end = min((c["done_ms"] for c in clients if c.get("done_ms")), default=None)
    if first_end is not None and first_end < in_ms + 1000 * seconds:
        notes.append(f"a trial ended {(first_end - in_ms) / 1000:.0f} s into the {seconds:.0f} s window: raise CAPACITY_ARRIVAL_S")
    if len(cpu) < started:
        notes.append(f"{len(cpu)} graphs measured of {started}")
    front = (f"{fmt(front_rss)}; {fmt(front_cpu)} ({front_cpu / max(1, started):.2f}) | {fmt(med(hello))} / {fmt(max(hello) if hello else None)} | "
             f"{len(done)} of {n} | ")
known = [m for m in starts if m is not None]
at_start = f"; {sum(known)} in the trials' first second" + ("" if len(known) == len(starts) else f" of {len(known)}") if serve else ""
print(f"| {n} | {started} | {fmt(med(mind))} / {fmt(max(mind) if mind else None)} | {int(sum(misses))} ({sum(1 for m in misses if m)}{at_start}) | "
      f"{fmt(med(pointer))} / {fmt(max(pointer) if pointer else None)} | {fmt(med(rtt))} | {fmt(mean(rss))} | {fmt(mean(cpu))} | "
      f"{front}{client_cpu:.1f} | {busy:.0f} ({load:.2f}) | "
      + (f"{k}: p99 {' '.join(fmt(v) for v in chr_p99)} ms, {' '.join(f'{v:.0f}' for v in chr_rate)}/s; simulated: {fmt(med(sim_rate))}/s |" if k else "- |")
      + "".join(f"\n  note: {x}" for x in notes))
fell = started < n or not mind or max(mind) > 100 or len(pointer) < started or (serve and len(done) < n)
# The knee's misses; serve: after each trial's first second (its start's are not the load's: above)
relay = f"; the front {front_cpu / max(1, started):.2f}% of a core per participant, {fmt(front_rss)} MB in all" if serve else ""
print("FELL" if fell else "UP", int(sum(misses)) - sum(known), fmt(mean(cpu)), fmt(mean(rss)), relay)
PY
  sed '$d' "$level/row"
  read -r state misses c r relay < <(tail -1 "$level/row")
  if [ -z "$knee" ] && [ "$misses" -gt 0 ]; then knee=$n; fi
  if [ "$misses" = 0 ] && [ "$state" = UP ]; then cost="$c% of a core and $r MB per session$relay (at N = $n)"; fi
  [ "$state" = UP ] || { echo; echo "stopped: $n participants fell over (a session did not start$([ "$mode" = direct ] || echo " or end with its code"), or the deliberator's p99 passed its period)"; break; }
done
echo
echo "knee (the first N with a deadline miss$([ "$mode" = direct ] || echo " after a trial's first second")): ${knee:-none up to the last level}"
echo "cost: ${cost:-no level without misses}"
echo "clients drew: $drawn; model: $model; each level's window: $seconds s; $(nproc) cores$([ "$mode" = direct ] || echo "; through one dyad study serve (trials of the window + N x $arrival s + 10 s)")"
