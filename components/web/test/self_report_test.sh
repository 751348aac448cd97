#!/usr/bin/env bash
# The subject's question in Debian's Chromium: after a release the page asks "What were you
# drawing?"; the answer lands in the recording (human/self_report) with the hold's start and end
# on the run's clock, once; the question never covers the workspace: a press on it right after a
# release steers at once (node/self_report.mjs says what the browser does).
#   self_report_test.sh BUILD_DIR WORK_DIR TEST_PLUGIN
set -euo pipefail
build=$1
work=$2
plugin=$3
source "$(dirname "$0")/../../../tests/support/web_test.sh"
require_browser
fresh_dir "$work"
"$build/bin/dyad" generate dataset --out data > /dev/null
cat > graph.yaml <<YAML
graph: self_report_test
clock: wall
domain_id: $(test_domain)
plugins: [$plugin]
topics:
  web/pointer: {type: HumanInput, reliability: reliable, depth: 8}
components:
  web: {type: web, rate_hz: 30, params: {port: 0, port_file: web.port, token: experimenter-token-0001, subject_token: subject-token-000001, viewer_token: viewer-token-0000001, dataset: data},
        inputs: {robot: robot/state}, outputs: {pointer: web/pointer, notes: experiment/notes, self_report: human/self_report}}
$(subject_robot)
  recorder: {type: recorder, rate_hz: 10, params: {file: rec.mcap, topics: [human/input, human/self_report]}}
YAML
"$build/bin/dyad" run graph.yaml --duration 40 > run.out 2> run.err &
pid=$!
wait_port_file web.port $pid
start_ms=$(date +%s%3N)
node "$node_dir/self_report.mjs" "http://127.0.0.1:$(cat web.port)" browser.json "$work" || { kill $pid; cat run.err; fail "the browser"; }
kill -INT $pid
wait $pid || true
"$build/bin/dyad" bag export rec.mcap --csv csv > /dev/null
# One answer, choice 2, about the second hold: its start and end within 0.3 s of the browser's
# (the run's clock is the wall clock here), its response time the 0.7 s the subject took.
python3 - browser.json csv/human_self_report.csv csv/human_input.csv <<'PY'
import csv, json, sys
b = json.load(open(sys.argv[1]))
rows = list(csv.DictReader(open(sys.argv[2])))
def fail(why): sys.exit("FAIL: " + why)
n = len(b["choices"])
if b["choices"] != list(range(n - 1)) + [-1] or n != 8: fail("the question's choices: %s (want 7 primitives and -1)" % b["choices"])
want = ["circle", "square", "triangle", "figure eight", "star", "heart", "trefoil", "something else (0)"]
if b["captions"] != want: fail("the choices are captioned %s (want the data set's names: %s)" % (b["captions"], want))
if len(rows) != 1: fail("%d self-reports recorded (want 1): %s" % (len(rows), rows))
r = rows[0]
if r["choice"] != "2": fail("choice %s, want 2" % r["choice"])
start, end = int(r["segment_start_ns"]) / 1e6, int(r["segment_end_ns"]) / 1e6
if abs(start - b["second"]["start"]) > 300 or abs(end - b["second"]["end"]) > 300:
    fail("segment %.0f..%.0f ms, the browser held %d..%d" % (start, end, b["second"]["start"], b["second"]["end"]))
resp = float(r["response_s"])
if not 0.5 <= resp <= 2.0: fail("response %.3f s, the subject answered %.3f s after the release" % (resp, (b["answered_at"] - b["second"]["end"]) / 1e3))
# The segment is one that human/input (what dyad analyze reads) shows engaged.
engaged = [int(x["header.stamp_ns"]) / 1e6 for x in csv.DictReader(open(sys.argv[3])) if x["engaged"] in ("1", "true")]
inside = [t for t in engaged if start - 150 <= t <= end + 150]
if len(inside) < 8: fail("human/input has %d engaged steps in the reported segment" % len(inside))
# The press on the workspace right after the third hold's release (where the question used to
# be) steered: human/input engaged at the pressed point while it was held.
p = b["press"]
at_press = [x for x in csv.DictReader(open(sys.argv[3])) if p["start"] - 50 <= int(x["header.stamp_ns"]) / 1e6 <= p["end"] + 50
            and x["engaged"] in ("1", "true")]
near = [x for x in at_press if abs(float(x["x"]) - p["x"]) < 1.5 and abs(float(x["y"]) - p["y"]) < 1.5]
if len(near) < 3: fail("the press at (%.1f, %.1f) right after a release: %d engaged human/input steps there (want >= 3 in its 0.6 s): %s"
                       % (p["x"], p["y"], len(near), [(x["x"], x["y"]) for x in at_press][:5]))
print("PASS: one self-report, choice 2, segment %.2f s, response %.2f s; a press on the workspace after a release steered (%d steps)"
      % ((end - start) / 1e3, resp, len(near)))
PY
