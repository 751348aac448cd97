#!/usr/bin/env bash
# `dyad study run --page`: a participant's session driven from the experimenter's study page in
# Debian's Chromium (tools/study/test/study_page.mjs says what the browser does); then the session
# log and the recordings are read back here.
#   study_page_test.sh REPO BUILD_DIR WORK_DIR
set -euo pipefail
repo=$1 build=$2 work=$3
source "$(dirname "$0")/../../../tests/support/web_test.sh"
require_browser
fresh_dir "$work"
ln -s "$node_modules" node_modules  # the script imports playwright-core from beside itself
cp "$(dirname "$0")/study_page.mjs" .
cat > g.yaml <<YAML
graph: g
clock: wall
domain_id: $(test_domain)
components:
  src: {type: counter_source, rate_hz: 20, outputs: {out: c}}
  sink: {type: counter_sink, rate_hz: 20, inputs: {in: c}}
  recorder: {type: recorder, rate_hz: 1}
YAML
cat > s.yaml <<YAML
study: page_test
graph: g.yaml
participants: [P01]
conditions:
  low: {src.start: 1}
  high: {src.start: 3}
duration: 2
blind: true
YAML
"$build/bin/dyad" study run s.yaml --participant P01 --page --page-port 0 > runner.out 2> runner.err &
pid=$!
for _ in $(seq 100); do grep -q "study page: " runner.out && break; sleep 0.1; done
url=$(grep -o "http://[^ ]*" runner.out | head -1)
[ -n "$url" ] || { kill $pid; cat runner.out runner.err; fail "no study page URL"; }
# A note from another terminal once the page has withdrawn the participant: the open page shows it.
( for _ in $(seq 600); do grep -q '"withdrawn"' page_test-data/P01/session.log 2>/dev/null && break; sleep 0.1; done
  "$build/bin/dyad" study note s.yaml --participant P01 "from the terminal" > note.out 2>&1 ) &
node study_page.mjs "$url" "$work" || { kill $pid; cat runner.out runner.err; fail "the page"; }
kill -INT $pid
rc=0; wait $pid || rc=$?
[ $rc = 1 ] || fail "the runner exited $rc after SIGINT between trials (want 1: trials remain): $(cat runner.err)"
python3 - page_test-data/P01/session.log <<'PY'
import json, sys
lines = [json.loads(l) for l in open(sys.argv[1])]
def fail(why): sys.exit("FAIL: " + why + "\n" + "\n".join(map(str, lines)))
if lines[0].get("event") != "consent" or lines[0].get("how") != "marked on the study page": fail("consent first, from the page")
ends = [(l["trial"], l["attempt"], l["outcome"]) for l in lines if l["event"] == "end"]
if ends != [(1, 1, "complete"), (1, 2, "complete"), (2, 1, "stopped")]: fail("attempts %s" % ends)
reasons = [(l["trial"], l.get("reason")) for l in lines if l["event"] == "start" and l["attempt"] == 2]
if reasons != [(1, "the participant sneezed")]: fail("reasons %s" % reasons)
notes = [(l["text"], l["time"]) for l in lines if l["event"] == "note"]
if [n[0] for n in notes] != ["the participant | laughed", "from the terminal"]: fail("notes %s" % notes)
if (lines[-2]["event"], lines[-2].get("how"), lines[-2].get("data")) != ("withdrawn", "on the study page", "kept"): fail("the withdrawal is not before the terminal's note")
print("PASS: session log as the page drove it")
PY
n=$(ls page_test-data/P01/*.mcap | wc -l)
[ "$n" = 3 ] || fail "$n recordings (want 3: two attempts of trial 1, one of trial 2, kept after the withdrawal): $(ls page_test-data/P01)"
# Withdrawn: the analysis leaves P01 out and says so; a new session records nothing.
"$build/bin/dyad" study analyze s.yaml --no-plots > analyze.out 2>&1 || fail "analyze: $(cat analyze.out)"
grep -q "^- P01: withdrew consent on .*; their data is kept but not analysed$" page_test-data/analysis/report.md ||
  fail "the report does not say P01 withdrew: $(cat page_test-data/analysis/report.md)"
grep -q "0 trials analysed, 0 missing" analyze.out || fail "analyze: $(cat analyze.out)"
if "$build/bin/dyad" study run s.yaml --participant P01 --trial 1 --reason again > again.out 2>&1; then fail "a withdrawn participant's trial ran"; fi
grep -q "P01 withdrew consent" again.out || fail "the refusal: $(cat again.out)"
[ "$(ls page_test-data/P01/*.mcap | wc -l)" = 3 ] || fail "something recorded after the withdrawal"
echo "PASS: withdrawn: left out of the analysis, and refused a trial"
