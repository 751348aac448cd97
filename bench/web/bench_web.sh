#!/usr/bin/env bash
# The web component, one run, ratios (bash bench/web/bench_web.sh [BUILD_DIR]):
#   1. pointer: the subject's page (Chromium), 500 moves at 100 Hz: the event's wall-clock stamp
#      to its publication on the graph (same machine, same clock), per hop (page -> civetweb's
#      worker has the frame -> our one handler thread starts on it -> published), and the round
#      trip to the ack;
#   2. Foxglove bridge throughput to one client: bench_bridge feeds the bridge 100-byte samples as
#      fast as one thread can (no graph in the way); samples/s the client receives;
#   3. the experiment's step time p99 at 100 Hz (wall) with no client, with 4 Foxglove clients
#      subscribed to every topic, and under hostile clients: 5 alternating rounds of 15 s runs,
#      median p99 of each condition.
# Each run lasts as long as its client (see stop()).
set -euo pipefail
here=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$here/build}
node_dir=$here/components/web/test/node
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
graph() {  # graph CLOCK RATE
  cat <<YAML
graph: bench_web
clock: $1
domain_id: $(( 1 + $$ % 200 ))
topics:
  robot/command: {type: CartesianCommand, reliability: reliable, depth: 4}
  robot/state: {type: CartesianState, reliability: reliable, depth: 4}
  web/pointer: {type: HumanInput, depth: 8}
components:
  pattern: {type: cartesian_pattern, rate_hz: $2, params: {shape: figure8, radius: 30, period_s: 4}, outputs: {command: robot/command}}
  driver: {type: virtual_cartesian, trigger: command, params: {max_velocity: 1e6, max_acceleration: 1e9}, inputs: {command: robot/command}, outputs: {state: robot/state}}
  web: {type: web, rate_hz: 30, params: {port: 0, port_file: web.port, token: experimenter-token-0001, subject_token: subject-token-000001, viewer_token: viewer-token-0000001}, inputs: {robot: robot/state}, outputs: {pointer: web/pointer}}
  human: {type: web_human, rate_hz: 100, inputs: {pointer: web/pointer}, outputs: {input: human/input}}
YAML
}
# A run lasts as long as its client: started without an end, stopped (SIGINT: it still prints its
# timing table) once the client is done, however slow the machine (a fixed --duration cut a slow
# client off, and killing a run that had already ended aborted the script under set -e).
stop() { kill -INT "$pid" 2> /dev/null || true; wait "$pid" || true; }
start() {  # start GRAPH ARGS...: runs dyad in the background, waits for the port
  rm -f web.port
  "$build/bin/dyad" run "$@" > run.out 2> run.err &
  pid=$!
  for _ in $(seq 100); do [ -s web.port ] && break; sleep 0.1; done
  port=$(cat web.port)
}
p99() { awk -v c="$1" '$1 == c {print $4}' run.out; }

graph wall 100 > wall.yaml
start wall.yaml
pointer=$(node "$node_dir/bench_clients.mjs" pointer "http://127.0.0.1:$port" 500)
stop
arrival=$(grep -o "pointer event -> published: .*" run.err || echo "none")
hops=$(grep -o "pointer hops: .*" run.err | sed 's/^pointer hops: //' || echo "none")

coproc BRIDGE { "$build/bin/bench_bridge" 6 2> bridge.err; }
read -r port <&"${BRIDGE[0]}"
throughput=$(node "$node_dir/bench_clients.mjs" foxglove "ws://127.0.0.1:$port/?token=bench-viewer-token-01" bench/samples 5 1)
wait $BRIDGE_PID || true
throughput="$throughput; bridge: $(cat bridge.err)"

# Five alternating rounds of three runs (no clients, 4 Foxglove clients, hostile clients); the
# median p99 of each condition (one run's p99 of a 0.1 ms step on a shared 2-core machine moves
# by 2x from run to run). Hostile: components/web/test's 1,000 malformed or oversized messages
# over a reconnect storm, and a client that subscribes to everything and never reads.
median() { sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }
conditions="base four hostile"
for c in $conditions; do : > $c.pattern; : > $c.driver; done
for _ in 1 2 3 4 5; do
  for c in $conditions; do
    start wall.yaml
    case $c in
      base) sleep 13 ;;
      four) node "$node_dir/bench_clients.mjs" foxglove "ws://127.0.0.1:$port/?token=viewer-token-0000001" "" 13 4 > /dev/null ;;
      hostile) node "$node_dir/hostile_clients.mjs" "ws://127.0.0.1:$port/?token=viewer-token-0000001" 1000 10 > /dev/null ;;
    esac
    stop
    p99 pattern >> $c.pattern; p99 driver >> $c.driver
  done
done

echo "| what | result |"
echo "| --- | --- |"
echo "| pointer event (page's wall stamp) -> published on the graph | $arrival |"
echo "| ... of which, per hop | $hops |"
echo "| pointer round trip page -> component -> page (500 moves) | $pointer |"
echo "| bridge to one client, 100-byte samples | $throughput |"
for c in $conditions; do
  echo "| step p99 at 100 Hz, $c: median of 5 runs, pattern / driver | $(median < $c.pattern) / $(median < $c.driver) ms |"
  echo "| each run's p99, $c: pattern / driver | $(paste -sd' ' $c.pattern) / $(paste -sd' ' $c.driver) ms |"
done
for c in four hostile; do
  awk -v a="$(median < base.pattern)" -v b="$(median < $c.pattern)" -v c="$(median < base.driver)" -v d="$(median < $c.driver)" -v n=$c \
    'BEGIN { printf "| p99 ratio %s / no clients: pattern %.2f, driver %.2f |  |\n", n, b / a, d / c }'
done
