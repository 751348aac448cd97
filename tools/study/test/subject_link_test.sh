#!/usr/bin/env bash
# The subject's link for a whole session (#46): a two-trial blind session run through
# `dyad study run --page` in Debian's Chromium, the subject's page opened from the study page's
# link before trial 1 and kept across both trials (tools/study/test/subject_link.mjs says what
# the browser does). Then, read back here: the runner ended by itself at "session complete"; both
# trials complete; each recording's human/input is engaged within its first second (the trial's
# clock waited for the page), and engaged for most of the trial.
#   subject_link_test.sh REPO BUILD_DIR WORK_DIR
set -euo pipefail
repo=$1 build=$2 work=$3
source "$(dirname "$0")/../../../tests/support/web_test.sh"
require_browser
fresh_dir "$work"
ln -s "$node_modules" node_modules  # the script imports playwright-core from beside itself
cp "$(dirname "$0")/subject_link.mjs" .
"$build/bin/dyad" generate dataset --out data > /dev/null
cat > g.yaml <<YAML
graph: g
clock: wall
domain_id: $(test_domain)
topics:
  web/pointer: {type: HumanInput, reliability: reliable, depth: 8}
components:
  web: {type: web, rate_hz: 30, params: {port: 0, dataset: data}, outputs: {pointer: web/pointer, task: subject/task}}
  human: {type: web_human, rate_hz: 20, inputs: {pointer: web/pointer}, outputs: {input: human/input}}
  recorder: {type: recorder, rate_hz: 10, params: {topics: [human/input, subject/task]}}
YAML
cat > s.yaml <<YAML
study: link_test
graph: g.yaml
participants: [P01]
conditions:
  low: {human.engage_timeout_s: 0.3}
  high: {human.engage_timeout_s: 0.4, task: {target: 5, practice: true}}
task: {message: Draw the yellow shape, target: 2}
duration: 3
blind: true
consent_required: false
YAML
"$build/bin/dyad" study run s.yaml --participant P01 --page --page-port 0 --subject-port 0 > runner.out 2> runner.err &
pid=$!
for _ in $(seq 100); do grep -q "study page: " runner.out && break; sleep 0.1; done
url=$(grep -o "http://[^ ]*/study[^ ]*" runner.out | head -1)
[ -n "$url" ] || { kill $pid; cat runner.out runner.err; fail "no study page URL"; }
# Blind: the runner prints no subject's link (the study page shows it).
if grep -q "subject's page: " runner.out; then kill $pid; fail "a blind runner printed the subject's link"; fi
node subject_link.mjs "$url" browser.json "$work" || { kill $pid; cat runner.out runner.err; fail "the pages"; }
# The runner ends by itself at "session complete" (a backstop: 20 s).
for _ in $(seq 200); do kill -0 $pid 2>/dev/null || break; sleep 0.1; done
if kill -0 $pid 2>/dev/null; then kill -INT $pid; fail "the runner did not exit at session complete: $(cat runner.out)"; fi
rc=0; wait $pid || rc=$?
[ $rc = 0 ] || fail "the runner exited $rc: $(cat runner.out runner.err)"
grep -q "^session complete$" runner.out || fail "the runner did not say session complete: $(cat runner.out)"
for f in link_test-data/P01/0[12]-*.mcap; do
  "$build/bin/dyad" bag export "$f" --csv "csv-$(basename "$f" .mcap)" > /dev/null
done
python3 - link_test-data/P01/session.log csv-0[12]-*/human_input.csv <<'PY'
import csv, json, sys, glob
lines = [json.loads(l) for l in open(sys.argv[1])]
def fail(why): sys.exit("FAIL: " + why + "\n" + "\n".join(map(str, lines)))
ends = [(l["trial"], l["attempt"], l["outcome"]) for l in lines if l["event"] == "end"]
if ends != [(1, 1, "complete"), (2, 1, "complete")]: fail("attempts %s (want both trials complete, once each)" % ends)
if any("start_anyway" in l for l in lines): fail("a start without the subject's page")
for path in sys.argv[2:]:
    rows = list(csv.DictReader(open(path)))
    t0 = int(rows[0]["log_time"])
    first = next((int(r["log_time"]) for r in rows if r["engaged"] in ("1", "true")), None)
    if first is None or first - t0 > 1e9:
        fail("%s: the subject is not engaged within the recording's first second (first engaged step %s s in)" %
             (path, None if first is None else (first - t0) / 1e9))
    engaged = sum(r["engaged"] in ("1", "true") for r in rows) / len(rows)
    if engaged < 0.7: fail("%s: engaged on %.0f%% of %d steps (the page held throughout)" % (path, 100 * engaged, len(rows)))
    print("%s: engaged %.2f s after the first step, on %.0f%% of %d steps" % (path, (first - t0) / 1e9, 100 * engaged, len(rows)))
# The study file's task, on subject/task: the file's for one condition, the condition's own for the other.
tasks = sorted(tuple((r["target"], r["message"], r["practice"] in ("1", "true")) for r in csv.DictReader(open(f)))
               for f in sorted(glob.glob("csv-0[12]-*/subject_task.csv")))
want = [(("2", "Draw the yellow shape", False),), (("5", "Draw the yellow shape", True),)]
if tasks != want: fail("subject/task recorded %s, want %s" % (tasks, want))
b = json.load(open("browser.json"))
if b["task"]["message"] != "Draw the yellow shape" or not b["task"]["time_left"].startswith("time left: "):
    fail("the subject's page during trial 1 showed %s" % b["task"])
print("PASS: two trials complete with the subject's page opened before trial 1 and kept across both; the study file's task on it")
PY
