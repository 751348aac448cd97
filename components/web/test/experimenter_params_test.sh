#!/usr/bin/env bash
# Live parameters from the experimenter's page, in Debian's Chromium (playwright-core): the page
# sets the mixer's gain (applied, 0.9 -> 0.25), asks for 7 (refused by the mixer's process), gets
# it, and a viewer's page that asks is closed (components/web/test/node/experimenter_params.mjs);
# the recording then holds the change, who made it, and the mixer's commands before and after it,
# and the recorder's status the page's header showed.
#   experimenter_params_test.sh BUILD_DIR WORK_DIR FIXED_INPUTS_PLUGIN
set -euo pipefail
build=$1
work=$2
plugin=$3
source "$(dirname "$0")/../../../tests/support/web_test.sh"
require_browser
fresh_dir "$work"
# The mixer between fixed inputs (human at x = 10, robot at x = 0): its command's x is 10 * gain.
cat > graph.yaml <<YAML
graph: experimenter_params
clock: wall
domain_id: $(test_domain)
plugins: [$plugin]
components:
  web: {type: web, rate_hz: 10, params: {port: 0, port_file: web.port, token: experimenter-token-0001, subject_token: subject-token-000001, viewer_token: viewer-token-0000001}, inputs: {recording: recorder/status}, outputs: {pointer: web/pointer}}
  inputs: {type: fixed_inputs, rate_hz: 10, outputs: {human: human/input, robot: robot/intention}}
  mixer: {type: compliance_mixer, rate_hz: 10, params: {max_step: 0, max_speed: 0}, inputs: {human: human/input, robot: robot/intention}, outputs: {command: robot/command}}
  rec: {type: recorder, rate_hz: 10, params: {file: rec.mcap}, outputs: {status: recorder/status}}
topics:
  recorder/status: {type: RecordingStatus}
YAML
"$build/bin/dyad" run graph.yaml --duration 30 > run.out 2> run.err &
pid=$!
wait_port_file web.port $pid
node "$node_dir/experimenter_params.mjs" "http://127.0.0.1:$(cat web.port)" "$work" || { kill -INT $pid; wait $pid || true; cat run.err; exit 1; }
kill -INT $pid
wait $pid || true
"$build/bin/dyad" bag export rec.mcap --csv csv > csv.out 2>&1 || { cat csv.out; echo "FAIL: dyad bag export"; exit 1; }
# The recording: the applied change (and the refusal, and the get), each from the page; the
# mixer's commands at 9 (gain 0.9), then at 2.5.
python3 - csv <<'PY'
import csv, sys
d = sys.argv[1]
rows = list(csv.DictReader(open(d + "/dyad_params.csv")))
got = [(r["op"], r["component_name"] + "." + r["param_name"], r["old_value"], r["value"], r["reason"], r["who"]) for r in rows]
want = [("applied", "mixer.gain", "0.9", "0.25", "", "experimenter page"),
        ("refused", "mixer.gain", "", "7", "must be <= 1, got 7", "experimenter page"),
        ("value", "mixer.gain", "", "0.25", "", "experimenter page")]
if got != want:
    sys.exit("FAIL: dyad_params.csv holds %s, expected %s" % (got, want))
xs = [float(r["x"]) for r in csv.DictReader(open(d + "/robot_command.csv"))]
if not xs or xs[0] != 9.0 or xs[-1] != 2.5:
    sys.exit("FAIL: the mixer's commands went from %s to %s, expected 9 then 2.5" % (xs[:1], xs[-1:]))
print("recorded: %s; commands %g -> %g" % (got[0], xs[0], xs[-1]))
# The recorder's own status, as recorded: its file, samples and bytes that only grow, 10 Hz of its
# run's seconds, no error; the last count within what the file holds.
status = list(csv.DictReader(open(d + "/recorder_status.csv")))
import glob, os
total = sum(len(list(csv.DictReader(open(f)))) for f in glob.glob(d + "/*.csv"))
samples = [int(r["samples"]) for r in status]
bytes_ = [int(r["bytes"]) for r in status]
elapsed = [float(r["elapsed_s"]) for r in status]
if len(status) < 50: sys.exit("FAIL: %d status samples in a 10 Hz run of more than 5 s" % len(status))
if {r["file"] for r in status} != {os.path.abspath("rec.mcap")}: sys.exit("FAIL: files %s" % {r["file"] for r in status})
if any(r["error"] for r in status) or {r["component_name"] for r in status} != {"rec"}: sys.exit("FAIL: status %s" % status[-1])
if samples != sorted(samples) or samples[-1] <= samples[0] or bytes_ != sorted(bytes_): sys.exit("FAIL: counts went back")
if not (total - 50 <= samples[-1] <= total): sys.exit("FAIL: the last status said %d samples, the file holds %d" % (samples[-1], total))
steps = sorted(b - a for a, b in zip(elapsed, elapsed[1:]))
if elapsed[0] != 0 or steps[0] <= 0 or not 0.09 < steps[len(steps) // 2] < 0.11: sys.exit("FAIL: elapsed %s" % elapsed[:5])
print("the recorder's status: %d samples, the last %d of the file's %d, %.1f s" % (len(status), samples[-1], total, elapsed[-1]))
PY
