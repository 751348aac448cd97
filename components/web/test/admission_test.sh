#!/usr/bin/env bash
# The web component's admission (a token per role, Origin) and steering role
# (components/web/test/node/admission.mjs says what is checked), against a running graph.
#   admission_test.sh BUILD_DIR WORK_DIR
set -euo pipefail
build=$1
work=$2
source "$(dirname "$0")/../../../tests/support/web_test.sh"
require_node
fresh_dir "$work"
experimenter=experimenter-s3cret-0001 subject=subject-s3cret-00001 viewer=viewer-s3cret-000001
cat > graph.yaml <<YAML
graph: admission
clock: wall
domain_id: $(test_domain)
components:
  web: {type: web, rate_hz: 10, params: {port: 0, port_file: web.port, token: $experimenter, subject_token: $subject, viewer_token: $viewer}, outputs: {pointer: web/pointer}}
  human: {type: web_human, rate_hz: 10, inputs: {pointer: web/pointer}, outputs: {input: human/input}}
topics:
  human/input: {type: HumanInput}
YAML
"$build/bin/dyad" run graph.yaml --duration 15 > run.out 2> run.err &
pid=$!
wait_port_file web.port $pid
status=0
node "$node_dir/admission.mjs" "ws://127.0.0.1:$(cat web.port)" $experimenter $subject $viewer || status=1
kill -INT $pid; wait $pid || true
[ $status -eq 0 ] || { echo "the graph's log:"; tail -30 run.err; }
grep -q "/subject?token=<params.subject_token>" run.err && grep -q "/experimenter?token=<params.token>" run.err &&
  ! grep -q s3cret run.err || { echo "FAIL: the URLs printed do not say where the tokens are, or print them"; status=1; }
exit $status
