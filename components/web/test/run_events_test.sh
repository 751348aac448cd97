#!/usr/bin/env bash
# A restart is said on the experimenter's page: a graph of two processes, the `worker` killed
# once mid-run (its launcher restarts it), a client of /experimenter/ws must be told
# "process 'worker' ... restarted (restart 1)" (components/web/src/run_events.hpp), and its stats
# table must list each component under its own process (ui/web, worker/human), nothing else.
#   run_events_test.sh BUILD_DIR WORK_DIR
set -euo pipefail
build=$1
work=$2
source "$(dirname "$0")/../../../tests/support/web_test.sh"
require_node
fresh_dir "$work"
cat > graph.yaml <<YAML
graph: run_events
clock: wall
domain_id: $(test_domain)
processes:
  ui: {}
  worker: {restart: on-failure, backoff_s: 0.2}
components:
  web: {type: web, rate_hz: 10, process: ui, params: {port: 0, port_file: web.port, token: experimenter-token-0001, subject_token: subject-token-000001, viewer_token: viewer-token-0000001}, outputs: {pointer: web/pointer}}
  human: {type: web_human, rate_hz: 10, process: worker, inputs: {pointer: web/pointer}, outputs: {input: human/input}}
topics:
  human/input: {type: HumanInput}
YAML
"$build/bin/dyad" run graph.yaml --duration 40 > run.out 2> run.err &
pid=$!
wait_port_file web.port $pid 20
sleep 2  # the worker's process is up (the graph's processes start together)
worker=$(pgrep -f -- "run graph.yaml --process worker" | head -1)
[ -n "$worker" ] || { echo "no worker process"; cat run.err; kill $pid; exit 1; }
kill -KILL "$worker"
status=0
node -e '
const WebSocket = require(process.argv[1] + "/node_modules/ws");
const ws = new WebSocket(process.argv[2] + "/experimenter/ws?token=viewer-token-0000001");
const give_up = setTimeout(() => { console.log("FAIL: no restart event and stats of both processes within 20 s: " + seen); process.exit(1); }, 20000);
let told = false, seen = "";
ws.on("message", (d) => {
  const m = JSON.parse(d.toString());
  if (m.op === "events") {
    const e = m.items.find((i) => /^process .worker.* restarted \(restart 1\): its components started afresh/.test(i.text));
    if (e && !told) { console.log("told: " + e.text); told = true; }
  }
  // The stats table: each component of the graph under its own process, and nothing else.
  if (m.op === "stats") seen = m.rows.map((r) => r.process + "/" + r.component).sort().join(",");
  if (told && seen === "ui/web,worker/human") { console.log("stats: " + seen); clearTimeout(give_up); ws.close(); process.exit(0); }
});' "$node_dir" "ws://127.0.0.1:$(cat web.port)" || status=1
kill -INT $pid; wait $pid || true
[ $status -eq 0 ] || cat run.err
exit $status
