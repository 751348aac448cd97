#!/usr/bin/env bash
# wait_for_subject_s ends when the run is asked to stop: a graph whose web component waits up to
# 60 s for the subject's page (a study's trial; no page comes here) is interrupted (SIGINT, as
# `dyad study serve` and `study run` stop a trial) 1 s after its server is up, and must be gone
# within 5 s (before: the wait ran out first), saying the wait ended for the stop.
#   wait_stop_test.sh BUILD_DIR WORK_DIR
set -euo pipefail
build=$1
work=$2
source "$(dirname "$0")/../../../tests/support/web_test.sh"
fresh_dir "$work"
cat > graph.yaml <<YAML
graph: wait_stop_test
clock: wall
domain_id: $(test_domain)
components:
  web: {type: web, rate_hz: 30, params: {port: 0, port_file: web.port, token: experimenter-token-0001, subject_token: subject-token-000001,
        viewer_token: viewer-token-0000001, wait_for_subject_s: 60}, outputs: {pointer: web/pointer, notes: experiment/notes}}
YAML
"$build/bin/dyad" run graph.yaml --duration 120 > run.out 2> run.err &
pid=$!
wait_port_file web.port $pid 30
sleep 1
kill -INT $pid
start=$(date +%s%N)
for _ in $(seq 50); do kill -0 $pid 2> /dev/null || break; sleep 0.1; done
if kill -0 $pid 2> /dev/null; then kill -KILL $pid; cat run.err; fail "still running 5 s after SIGINT (the wait for the subject's page went on)"; fi
wait $pid || true
grep -q "the run is stopping: no more waiting for the subject's page" run.err || { cat run.err; fail "the wait's end not said"; }
echo "PASS: the run ended $(( ($(date +%s%N) - start) / 1000000 )) ms after SIGINT, in its wait for the subject's page"
