#!/usr/bin/env bash
# The subject's task in Debian's Chromium: the experimenter's page sets a target primitive, a
# message, a countdown and practice on the subject's page (node/subject_task.mjs says what the
# browsers do); the recording's subject/task holds each change in order, the countdown once.
#   subject_task_test.sh BUILD_DIR WORK_DIR
set -euo pipefail
build=$1
work=$2
source "$(dirname "$0")/../../../tests/support/web_test.sh"
require_browser
fresh_dir "$work"
"$build/bin/dyad" generate dataset --out data > /dev/null
cat > graph.yaml <<YAML
graph: subject_task_test
clock: wall
domain_id: $(test_domain)
components:
  web: {type: web, rate_hz: 30, params: {port: 0, port_file: web.port, token: experimenter-token-0001, subject_token: subject-token-000001, viewer_token: viewer-token-0000001, dataset: data},
        outputs: {pointer: web/pointer, task: subject/task}}
  recorder: {type: recorder, rate_hz: 10, params: {file: rec.mcap, topics: [subject/task, dyad/params]}}
YAML
# A target the data set does not have: refused at the start, naming the param.
if "$build/bin/dyad" run graph.yaml --duration 1 --set web.task_target=7 > bad.out 2>&1; then fail "task_target 7 of 7 primitives was accepted"; fi
grep -q "params.task_target: the data set has 7 primitives (0..6), got 7" bad.out || { cat bad.out; fail "the refusal does not say why"; }
"$build/bin/dyad" run graph.yaml --duration 60 > run.out 2> run.err &
pid=$!
wait_port_file web.port $pid
node "$node_dir/subject_task.mjs" "http://127.0.0.1:$(cat web.port)" browser.json "$work" || { kill $pid; cat run.err; fail "the browser"; }
# ... and while it runs (the experimenter's page offers only the data set's primitives).
"$build/bin/dyad" param set web.task_target=9 --graph graph.yaml > param.out 2>&1 || true
grep -q "the data set has 7 primitives (0..6), got 9" param.out || { cat param.out; kill $pid; fail "a live target out of the data set was not refused"; }
kill -INT $pid
rc=0; wait $pid || rc=$?
[ $rc = 0 ] || [ $rc = 130 ] || { tail -20 run.err; fail "dyad run exited $rc"; }
"$build/bin/dyad" bag export rec.mcap --csv csv > /dev/null
python3 - browser.json csv/subject_task.csv <<'PY'
import csv, json, sys
b = json.load(open(sys.argv[1]))
rows = list(csv.DictReader(open(sys.argv[2])))
def fail(why): sys.exit("FAIL: " + why)
if b["before"] != {"target": -1, "message": "", "practice": False, "countdown": ""}: fail("the page before: %s" % b["before"])
if b["countdown"] != ["2", "1", "go", ""]: fail("the countdown the subject saw: %s (want 2, 1, go, then nothing)" % b["countdown"])
want = {"target": 3, "message": "Draw the yellow shape", "practice": True, "countdown": ""}
if b["after"] != want: fail("the page after: %s" % b["after"])
if b["late"] != want: fail("a page opened later: %s" % b["late"])
got = [(r["target"], r["message"], float(r["countdown_s"]), r["practice"] in ("1", "true")) for r in rows]
expect = [("-1", "", 0.0, False), ("3", "", 0.0, False), ("3", "Draw the yellow shape", 0.0, False),
          ("3", "Draw the yellow shape", 0.0, True), ("3", "Draw the yellow shape", 2.0, True), ("3", "Draw the yellow shape", 0.0, False)]
if got != expect: fail("subject/task recorded %s\nwant %s" % (got, expect))
print("PASS: target, message, countdown (2, 1, go) and practice on the subject's page; subject/task recorded each change")
PY
