#!/usr/bin/env bash
# Asking after the trial (self_reports: after_trial) in Debian's Chromium, two runs of one graph
# (node/after_trial.mjs says what the browser does):
#   timed:  ask_after_s 12 and no --duration: at 12 s steering ends, the page asks about each of
#           the two holds (not the tap) in turn, each pictured by the person's own stroke (the
#           pointer's path while held) with the robot's path beside it, the answers land in the recording with each
#           hold's start and end, and the graph then ends by itself, exit 0, with its recording
#           whole; nothing the subject does after the trial is engaged on human/input.
#   button: the experimenter's page's "end the trial and ask the subject"; nobody answers; the
#           graph ends by itself after self_report_timeout_s (4 s), exit 0, no answer recorded.
#   after_trial_test.sh BUILD_DIR WORK_DIR TEST_PLUGIN
set -euo pipefail
build=$1
work=$2
plugin=$3
source "$(dirname "$0")/../../../tests/support/web_test.sh"
require_browser
fresh_dir "$work"
"$build/bin/dyad" generate dataset --out data > /dev/null

run() {  # run MODE ASK_AFTER_S: the graph and the browser; the graph must end by itself
  local mode=$1 ask_after=$2
  mkdir -p "$mode"
  cat > "$mode/graph.yaml" <<YAML
graph: after_trial_test
clock: wall
domain_id: $(test_domain)
plugins: [$plugin]
topics:
  web/pointer: {type: HumanInput, reliability: reliable, depth: 8}
components:
  web: {type: web, rate_hz: 30, params: {port: 0, port_file: web.port, token: experimenter-token-0001, subject_token: subject-token-000001,
        viewer_token: viewer-token-0000001, dataset: ../data, self_reports: after_trial, ask_after_s: $ask_after, self_report_timeout_s: 4},
        inputs: {robot: robot/state}, outputs: {pointer: web/pointer, notes: experiment/notes, self_report: human/self_report}}
$(subject_robot)
  recorder: {type: recorder, rate_hz: 10, params: {file: rec.mcap, topics: [human/input, human/self_report]}}
YAML
  cd "$mode"
  date +%s%3N > started_ms
  "$build/bin/dyad" run graph.yaml > run.out 2> run.err &
  local pid=$!
  wait_port_file web.port $pid
  # A backstop only: the graph ends by itself well before (if not, the test fails below).
  ( sleep 90; kill -INT $pid 2>/dev/null && echo "backstop" > backstop ) > /dev/null 2>&1 &
  local backstop=$!
  node "$node_dir/after_trial.mjs" "http://127.0.0.1:$(cat web.port)" browser.json "$work" "$mode" ||
    { kill $pid; cat run.err; fail "$mode: the browser"; }
  local rc=0
  wait $pid || rc=$?
  pkill -P $backstop 2>/dev/null || true  # its sleep
  kill $backstop 2>/dev/null || true
  [ ! -e backstop ] || fail "$mode: the graph did not end by itself (stopped by the test's backstop)"
  [ $rc -eq 0 ] || { cat run.err; fail "$mode: dyad run exited $rc"; }
  "$build/bin/dyad" bag export rec.mcap --csv csv > /dev/null
  cd ..
}

run timed 12
grep -q "2 of 2 holds answered" timed/run.err || { cat timed/run.err; fail "timed: the run's end does not say 2 of 2 holds answered"; }
python3 - timed/browser.json timed/csv/human_self_report.csv timed/csv/human_input.csv timed/started_ms <<'PY'
import csv, json, sys
b = json.load(open(sys.argv[1]))
started = int(open(sys.argv[4]).read())
rows = list(csv.DictReader(open(sys.argv[2])))
def fail(why): sys.exit("FAIL: timed: " + why)
if b["titles"] != ["What were you drawing here? (1 of 2)", "What were you drawing here? (2 of 2)", "Thank you. This trial is over."]:
    fail("the page's questions: %s" % b["titles"])
if b["thanks_after_end"] != "Thank you. This trial is over.": fail("after the graph ended the page says %r" % b["thanks_after_end"])
if b["trace_pixels"] < 200: fail("the question's picture has %d pixels drawn: no trace" % b["trace_pixels"])
# The picture is the person's stroke: the pointer's path while held, every position the browser
# moved to and no other (the robot's path, which lags and is pulled by the intention, is not it).
p = b["paths"]
if p["stroke_points"] < 10 or p["stroke_off"] > 0.3 or p["stroke_missed"] > 0:
    fail("the question's stroke is not the pointer's path while held: %s (want >= 10 points, each within 0.3 of where the browser's "
         "pointer was, none of its %d positions missed)" % (p, len(b["holds"][0]["points"])))
if p["robot_points"] < 2: fail("the question shows no robot path beside the stroke: %s" % p)
if b["choices"] != list(range(7)) + [-1]: fail("the choices: %s" % b["choices"])
if b["engaged_text"] != "released": fail("the engage key after the trial shows %r" % b["engaged_text"])
# Asked at ask_after_s on the run's clock: 12 s after the graph's first step, which follows the
# command's start by its start-up (a few seconds at most).
if not 12000 <= b["asked_at"] - started <= 20000: fail("asked %d ms after dyad run started (ask_after_s: 12)" % (b["asked_at"] - started))
if b["holds"][1]["end"] > b["asked_at"] - 500: fail("the browser's holds were not done before the trial ended (a slow start?)")
if b["watcher"] != {"title": "The subject is answering (1 of 2)", "choices_shown": False, "trace_shown": True}:
    fail("a second subject's page opened during the questions shows %s" % b["watcher"])
if len(rows) != 2: fail("%d self-reports recorded (want 2, one per hold; the tap is none): %s" % (len(rows), rows))
for r, h, choice, answered in zip(rows, b["holds"], ["2", "-1"], b["answers"]):
    start, end = int(r["segment_start_ns"]) / 1e6, int(r["segment_end_ns"]) / 1e6
    if r["choice"] != choice: fail("choice %s, want %s" % (r["choice"], choice))
    if abs(start - h["start"]) > 300 or abs(end - h["end"]) > 300:
        fail("segment %.0f..%.0f ms, the browser held %d..%d" % (start, end, h["start"], h["end"]))
# Response times from each question's showing: the second was answered 0.7 s after it appeared.
resp = float(rows[1]["response_s"])
if not 0.5 <= resp <= 2.0: fail("the second answer's response %.3f s (the subject took 0.7 s)" % resp)
# Nothing the subject did after the trial steered: no engaged human/input from the question on.
late = [x for x in csv.DictReader(open(sys.argv[3])) if int(x["header.stamp_ns"]) / 1e6 >= b["steer_tried_at"] and x["engaged"] in ("1", "true")]
if late: fail("%d engaged human/input samples after the trial ended" % len(late))
print("PASS: timed: 2 holds asked in turn and answered (2, something else), the tap not asked about; the graph ended by itself")
PY

run button 0
grep -q "the questions timed out" button/run.err || { cat button/run.err; fail "button: no timeout said"; }
grep -q "0 of 1 holds answered" button/run.err || fail "button: the run's end does not say 0 of 1 holds answered"
grep -q "experimenter page" button/run.err || fail "button: the ask did not come from the experimenter's page"
python3 - button/browser.json button/csv <<'PY'
import json, os, sys
b = json.load(open(sys.argv[1]))
def fail(why): sys.exit("FAIL: button: " + why)
if b["titles"] != ["What were you drawing here? (1 of 1)"]: fail("the page's questions: %s" % b["titles"])
if not b["button_disabled"]: fail("the experimenter's button stays enabled while the subject is asked")
if "questions: 0 of 1 answered" not in b["experimenter_says"]: fail("the experimenter's page says %r" % b["experimenter_says"])
if b["asking_after_end"]: fail("the unanswered question stayed after the graph ended")
if os.path.exists(os.path.join(sys.argv[2], "human_self_report.csv")):
    rows = open(os.path.join(sys.argv[2], "human_self_report.csv")).read().splitlines()
    if len(rows) > 1: fail("an unanswered question recorded an answer: %s" % rows)
print("PASS: button: the experimenter's page ended the trial; unanswered, the timeout ended the graph")
PY
