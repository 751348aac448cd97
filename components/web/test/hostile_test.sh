#!/usr/bin/env bash
# The bridge under hostile clients: 1,000 malformed or oversized messages over a reconnect storm
# (4 connections at a time) and a client that subscribes to everything and never reads, while a
# wall-clock graph runs at 100 Hz. Each bad client is closed with a reason, the server still
# answers afterwards, the process stays small, and the graph keeps its rate and exits 0.
# (Step-time p99 with and without these clients is compared in bench/web, not here: timing.)
#   hostile_test.sh BUILD_DIR WORK_DIR
set -euo pipefail
build=$1
work=$2
source "$(dirname "$0")/../../../tests/support/web_test.sh"
require_node
fresh_dir "$work"
cat > graph.yaml <<YAML
graph: hostile
clock: wall
domain_id: $(test_domain)
topics:
  robot/command: {type: CartesianCommand, reliability: reliable, depth: 4}
  robot/state: {type: CartesianState, reliability: reliable, depth: 4}
components:
  pattern: {type: cartesian_pattern, rate_hz: 100, params: {shape: figure8, radius: 30, period_s: 4}, outputs: {command: robot/command}}
  driver: {type: virtual_cartesian, trigger: command, inputs: {command: robot/command}, outputs: {state: robot/state}}
  web: {type: web, rate_hz: 10, params: {port: 0, port_file: web.port, client_buffer_kb: 64, token: experimenter-token-0001, subject_token: subject-token-000001, viewer_token: viewer-token-0000001}}
YAML
duration=20
"$build/bin/dyad" run graph.yaml --duration $duration > run.out 2> run.err &
pid=$!
wait_port_file web.port $pid
node "$node_dir/hostile_clients.mjs" "ws://127.0.0.1:$(cat web.port)/?token=viewer-token-0000001" 1000 3 | tee clients.json
rss_kb=$(ps -o rss= -p $pid)
wait $pid || { echo "FAIL: dyad run exited non-zero"; cat run.err; exit 1; }
cat run.out
echo "rss after the storm: $rss_kb KiB"
# 50 MiB here normally; under ASan its quarantine keeps up to 256 MiB of freed memory on top.
rss_limit=300000
[ -n "${ASAN_OPTIONS:-}" ] && rss_limit=700000
[ "$rss_kb" -lt $rss_limit ] || { echo "FAIL: RSS $rss_kb KiB (limit $rss_limit)"; exit 1; }
node -e '
const c = JSON.parse(require("fs").readFileSync("clients.json", "utf8"));
if (c.closed !== 1000) { console.error("FAIL: " + c.closed + " of 1000 bad clients closed by the server"); process.exit(1); }
'
steps=$(awk '$1 == "pattern" {print $2}' run.out)
# 100 Hz for the run (started before the clients): at least 95% of the periods stepped (85%
# under ASan, where node's storm and the instrumented process share 2 cores: 91% seen once). A
# step thread blocked by the web component would lose far more.
min_percent=95
[ -n "${ASAN_OPTIONS:-}" ] && min_percent=85
[ "$steps" -ge $(( duration * 100 * min_percent / 100 )) ] || { echo "FAIL: pattern stepped $steps times in $duration s at 100 Hz"; exit 1; }

echo PASS
