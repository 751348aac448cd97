#!/usr/bin/env bash
# The subject's page in Debian's Chromium (playwright-core): the browser steers, the recording
# shows it (components/web/test/node/check_subject_run.mjs says exactly what is checked).
#   subject_page_test.sh BUILD_DIR WORK_DIR TEST_PLUGIN
set -euo pipefail
build=$1
work=$2
plugin=$3
source "$(dirname "$0")/../../../tests/support/web_test.sh"
require_browser
fresh_dir "$work"
cat > graph.yaml <<YAML
graph: subject_page_test
clock: wall
domain_id: $(test_domain)
plugins: [$plugin]
topics:
  web/pointer: {type: HumanInput, reliability: reliable, depth: 8}
components:
  web: {type: web, rate_hz: 30, params: {port: 0, port_file: web.port, token: experimenter-token-0001, subject_token: subject-token-000001, viewer_token: viewer-token-0000001}, inputs: {robot: robot/state}, outputs: {pointer: web/pointer, notes: experiment/notes}}
$(subject_robot)
  recorder: {type: recorder, rate_hz: 10, params: {file: rec.mcap, topics: [human/input, robot/state, web/pointer, experiment/notes]}}
YAML
"$build/bin/dyad" run graph.yaml --duration 20 > run.out 2> run.err &
pid=$!
wait_port_file web.port $pid
node "$node_dir/subject_page.mjs" "http://127.0.0.1:$(cat web.port)" browser.json "$work" || { kill $pid; exit 1; }
kill -INT $pid
wait $pid || true
cat run.out
node "$node_dir/check_subject_run.mjs" browser.json rec.mcap 100
# The page stamps its events: the web component says where their time went, hop by hop
# (bench/web/bench_web.sh prints the same line).
grep -E "pointer hops: page -> socket median -?[0-9.]+ ms, p99 -?[0-9.]+ ms; socket -> handler thread median -?[0-9.]+ ms, p99 -?[0-9.]+ ms; handler -> published median -?[0-9.]+ ms" run.err \
  || { echo "no per-hop line in run.err"; cat run.err; exit 1; }
