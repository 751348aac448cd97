#!/usr/bin/env bash
# #45's done-when: a 4-participant study online, end to end through `dyad study serve`: three
# simulated participants and one in Chromium (components/web/test/node/sim_participant.mjs
# --online --chromium 1) open their links, consent, press Ready and steer two trials each (6 s,
# the demo's briefly trained model and observer); each gets a completion code. Then `dyad study
# analyze` gives the same tables as `dyad study rehearse` of the same plan: the same files, the
# same columns, one row per participant, condition and trial (the numbers come from people, so
# they differ).
#   online_study_test.sh REPO BUILD_DIR WORK_DIR
set -euo pipefail
repo=$1 build=$2 work=$3
source "$repo/tests/support/web_test.sh"
require_browser
dyad=$build/bin/dyad
fresh_dir "$work"
ln -s "$node_modules" node_modules
bash "$repo/tools/sweep/test/demo_models.sh" "$repo" "$dyad" "$work"
cat > online.yaml <<YAML
graph: online
clock: wall
seed: 1
domain_id: $(test_domain)
components:
  web:
    type: web
    rate_hz: 30
    params: {port: 0, show_primitives: true, dataset: $work/data}
    inputs: {robot: robot/state, intention: robot/intention, labels: observer/labels, recording: recorder/status}
    outputs: {pointer: web/pointer, notes: experiment/notes, self_report: human/self_report, task: subject/task}
  human: {type: web_human, rate_hz: 10, inputs: {pointer: web/pointer}, outputs: {input: human/input}}
  mind:
    type: deliberator
    rate_hz: 10
    params: {model: $work/demo.dpvrnn, start_primitive: 0, preset: vcbot, optimizer: adam}
    inputs: {executed: robot/state}
    outputs: {intention: robot/intention, model: robot/model}
  mixer:
    type: compliance_mixer
    trigger: robot
    params: {gain: 0.9, max_step: 5}
    inputs: {human: human/input, robot: robot/intention, state: robot/state}
    outputs: {command: robot/command}
  robot: {type: virtual_cartesian, trigger: command, outputs: {state: robot/state}, inputs: {command: robot/command}}
  observer:
    type: observer
    trigger: robot
    params: {model: $work/demo.dobs, window: 5, lowpass_steps: 10}
    inputs: {human: human/input, robot: robot/intention}
    outputs: {labels: observer/labels}
  recorder: {type: recorder, rate_hz: 1, outputs: {status: recorder/status}}
topics:
  web/pointer: {type: HumanInput, depth: 8}
  experiment/notes: {type: Annotation, depth: 8}
  human/input: {type: HumanInput}
  human/self_report: {type: SelfReport}
  robot/intention: {type: Intention}
  robot/command: {type: CartesianCommand}
  robot/state: {type: CartesianState}
  observer/labels: {type: IntentionLabel}
  subject/task: {type: SubjectTask}
  recorder/status: {type: RecordingStatus}
YAML
cat > rehearsal.yaml <<YAML
extends: $repo/configs/demo.yaml
components:
  human:                  # two holds within the 6 s trial (60 steps)
    params: {dataset: $work/data, events: [{start: 5, end: 28, primitive: 2}, {start: 33, end: 57, primitive: 4}]}
  mind: {params: {model: $work/demo.dpvrnn}}
  observer: {params: {model: $work/demo.dobs}}
YAML
echo "I agree to take part in this test study." > consent.txt
cat > s.yaml <<YAML
study: online_test
graph: online.yaml
participants: [P01, P02, P03, P04]
conditions:
  assist: {mixer.gain: 0.3}
  follow: {mixer.gain: 0.9}
duration: 6
blind: true
rehearsal: {graph: rehearsal.yaml}
online: {reconnect_s: 5, consent: consent.txt}
YAML
"$dyad" study links s.yaml --base-url http://127.0.0.1:8443 > /dev/null
"$dyad" study serve s.yaml --port 0 --port-file port > serve.out 2> serve.err &
pid=$!
wait_port_file port $pid 10 serve.err
tail -n +2 online_test-data/links.csv | while IFS=, read -r p link; do echo "http://127.0.0.1:$(cat port) ${link##*token=}"; done > sessions
# The first is the Chromium participant (the real page); all four until done, 60 s at most.
node "$node_dir/sim_participant.mjs" --online --chromium 1 --dataset data --speed 2 --seconds 60 sessions > clients.out 2> clients.err ||
  { kill $pid; cat clients.err serve.out serve.err; fail "sim_participant.mjs"; }
kill -TERM $pid
wait $pid || fail "dyad study serve exited $?: $(cat serve.err)"
python3 - clients.out online_test-data <<'PY'
import json, sys
people = [json.loads(l) for l in open(sys.argv[1])][:-1]
def fail(why): sys.exit("FAIL: " + why + "\n" + "\n".join(map(str, people)))
if len(people) != 4: fail("not 4 participants")
for i, p in enumerate(people):
    if not p.get("code") or p.get("trials") != 2 or p.get("refused"): fail(f"participant {i + 1} did not finish 2 trials with a code")
for i, pid in enumerate(["P01", "P02", "P03", "P04"]):
    log = [json.loads(l) for l in open(f"{sys.argv[2]}/{pid}/session.log")]
    ends = [e for e in log if e["event"] == "end"]
    if [e["outcome"] for e in ends] != ["complete", "complete"]: fail(f"{pid}: {ends}")
    codes = [e["code"] for e in log if e["event"] == "completed"]
    if codes != [people[i]["code"]]: fail(f"{pid}: logged codes {codes}, the page got {people[i]['code']}")
PY
"$dyad" study analyze s.yaml --no-plots > analyze.log 2>&1 || { cat analyze.log; fail "dyad study analyze"; }
"$dyad" study rehearse s.yaml --no-plots --unblind > rehearse.log 2>&1 || { cat rehearse.log; fail "dyad study rehearse"; }
python3 - online_test-data/analysis online_test-data/rehearsal/analysis <<'PY'
import csv, os, sys
online, lab = sys.argv[1], sys.argv[2]
def fail(why): sys.exit("FAIL: " + why)
# reports_vs_plan.csv: the synthetic people's self-reports against what they were told to draw
# (a rehearsal's own: a person's plan is not known).
files = sorted(f for f in os.listdir(lab) if f.endswith(".csv") and f != "reports_vs_plan.csv")
if sorted(f for f in os.listdir(online) if f.endswith(".csv")) != files: fail(f"other files: {os.listdir(online)} vs {files}")
def rows(d, f): return list(csv.DictReader(open(os.path.join(d, f))))
for f in files:
    a, b = open(os.path.join(online, f)).readline(), open(os.path.join(lab, f)).readline()
    if a != b: fail(f"{f}: other columns:\n  online {a}  lab    {b}")
key = lambda r: (r["participant"], r["condition"], r["trial"])
a, b = sorted(map(key, rows(online, "trials.csv"))), sorted(map(key, rows(lab, "trials.csv")))
if a != b or len(a) != 8: fail(f"trials.csv rows: online {a}, lab {b}")
key = lambda r: (r["condition"], r["measure"])
a, b = sorted(map(key, rows(online, "summary.csv"))), sorted(map(key, rows(lab, "summary.csv")))
if a != b: fail(f"summary.csv rows: online {a}, lab {b}")
print(f"online_study_test: {len(files)} tables alike ({', '.join(files)})")
PY
