#!/usr/bin/env bash
# The web component's Foxglove bridge against Foxglove's own client (npm @foxglove/ws-protocol)
# and omgidl decoder: a wall-clock graph (test pattern -> virtual robot, recorder, web) runs; the
# client lists channels, subscribes to robot/state and decodes every frame; every sample it got
# must be in the recording with the same values; publishing on a non-writable topic is refused.
#   bridge_test.sh BUILD_DIR WORK_DIR
set -euo pipefail
build=$1
work=$2
source "$(dirname "$0")/../../../tests/support/web_test.sh"
require_node
rm -rf "$work"; mkdir -p "$work"
cat > "$work/graph.yaml" <<YAML
graph: bridge_test
clock: wall
domain_id: $(test_domain)
topics:
  robot/command: {type: CartesianCommand, reliability: reliable, depth: 4}
  robot/state: {type: CartesianState, reliability: reliable, depth: 4}
components:
  pattern: {type: cartesian_pattern, rate_hz: 50, params: {shape: figure8, radius: 30, period_s: 4}, outputs: {command: robot/command}}
  driver: {type: virtual_cartesian, trigger: command, inputs: {command: robot/command}, outputs: {state: robot/state}}
  recorder: {type: recorder, rate_hz: 10, params: {file: rec.mcap, topics: [robot/state]}}
  web: {type: web, rate_hz: 10, params: {port: 0, port_file: web.port, token: experimenter-token-0001, subject_token: subject-token-000001, viewer_token: viewer-token-0000001}}
YAML
cd "$work"
"$build/bin/dyad" run graph.yaml --duration 6 > run.out 2> run.err &
pid=$!
wait_port_file web.port $pid
port=$(cat web.port)
# The experimenter's token: only it may try to publish (and be told robot/state is not writable).
node "$node_dir/foxglove_client.mjs" watch "ws://127.0.0.1:$port/?token=experimenter-token-0001" robot/state 3 client.json &
watcher=$!
# While the client is connected its sender thread is SCHED_BATCH (policy 3, field 41 of the
# thread's stat): it never preempts a graph thread when it wakes.
sleep 1.5
batch_threads=$(for t in /proc/$pid/task/*; do awk '{print $41}' "$t/stat" 2> /dev/null; done | grep -c '^3$' || true)
wait $watcher
[ "$batch_threads" -ge 1 ] || { echo "FAIL: no SCHED_BATCH sender thread while a Foxglove client was connected"; kill $pid; exit 1; }
wait $pid || { echo "dyad run failed"; cat run.err; exit 1; }
node -e '
const r = JSON.parse(require("fs").readFileSync("client.json", "utf8"));
const fail = (m) => { console.error("FAIL: " + m); process.exit(1); };
const topics = r.channels.map((c) => c.topic).sort().join(",");
if (topics !== "dyad/params,dyad/stats,robot/command,robot/state") fail("advertised " + topics);
for (const c of r.channels) if (c.encoding !== "cdr" || c.schemaEncoding !== "omgidl" || !c.schemaName.startsWith("dyad::msg::")) fail(JSON.stringify(c));
if (r.samples.length < 100) fail("only " + r.samples.length + " samples in 3 s at 50 Hz");
if (!r.statuses.some((s) => s.level === 2 && s.message.includes("not writable"))) fail("publish on robot/state was not refused: " + JSON.stringify(r.statuses));
if (r.errors.length) fail("client errors: " + r.errors.join("; "));
console.log("channels, samples and refusal OK");
'
node "$node_dir/foxglove_client.mjs" compare client.json rec.mcap robot/state
echo PASS
