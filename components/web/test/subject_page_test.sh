#!/usr/bin/env bash
# The subject's page in Debian's Chromium (playwright-core): the browser steers, the recording
# shows it (components/web/test/node/check_subject_run.mjs says exactly what is checked).
#   subject_page_test.sh BUILD_DIR WORK_DIR TEST_PLUGIN
set -euo pipefail
build=$1
work=$2
plugin=$3
node_dir=$(cd "$(dirname "$0")" && pwd)/node
if [ ! -d "$node_dir/node_modules" ] || [ ! -x /usr/bin/chromium ]; then
  echo "SKIP: needs tools/setup.sh (npm ci in components/web/test/node, Debian chromium)"; exit 77
fi
rm -rf "$work"; mkdir -p "$work"; cd "$work"
cat > graph.yaml <<YAML
graph: subject_page_test
clock: wall
domain_id: $(( 1 + $$ % 200 ))
plugins: [$plugin]
topics:
  web/pointer: {type: HumanInput, reliability: reliable, depth: 8}
components:
  web: {type: web, rate_hz: 30, params: {port: 0, port_file: web.port, token: experimenter-token-0001, subject_token: subject-token-000001, viewer_token: viewer-token-0000001}, inputs: {robot: robot/state}, outputs: {pointer: web/pointer, notes: experiment/notes}}
  human: {type: web_human, rate_hz: 10, inputs: {pointer: web/pointer}, outputs: {input: human/input}}
  mind: {type: intention_hold, rate_hz: 10, outputs: {intention: robot/intention}}
  mixer: {type: compliance_mixer, trigger: robot, params: {gain: 0.9, max_step: 5}, inputs: {human: human/input, robot: robot/intention}, outputs: {command: robot/command}}
  robot: {type: virtual_cartesian, trigger: command, inputs: {command: robot/command}, outputs: {state: robot/state}}
  recorder: {type: recorder, rate_hz: 10, params: {file: rec.mcap, topics: [human/input, robot/state, web/pointer, experiment/notes]}}
YAML
"$build/bin/dyad" run graph.yaml --duration 20 > run.out 2> run.err &
pid=$!
for _ in $(seq 100); do [ -s web.port ] && break; sleep 0.1; done
[ -s web.port ] || { echo "web.port never written"; cat run.err; kill $pid; exit 1; }
node "$node_dir/subject_page.mjs" "http://127.0.0.1:$(cat web.port)" browser.json "$work" || { kill $pid; exit 1; }
kill -INT $pid
wait $pid || true
cat run.out
node "$node_dir/check_subject_run.mjs" browser.json rec.mcap 100
# The page stamps its events: the web component says where their time went, hop by hop
# (bench/web/bench_web.sh prints the same line).
grep -E "pointer hops: page -> socket median -?[0-9.]+ ms, p99 -?[0-9.]+ ms; socket -> handler thread median -?[0-9.]+ ms, p99 -?[0-9.]+ ms; handler -> published median -?[0-9.]+ ms" run.err \
  || { echo "no per-hop line in run.err"; cat run.err; exit 1; }
