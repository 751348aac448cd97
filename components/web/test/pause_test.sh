#!/usr/bin/env bash
# params.pause_without_subject (dyad study serve's trials): the subject's page leaves during the
# trial and comes back. The recording must hold the web component's two marks on experiment/notes
# (author web: "paused: the subject's page is gone", then "resumed: the subject's page is back"),
# hold commands from the mixer between them (web_human went silent after one release, so the
# mixer's human input went stale), motion commands before the pause and after the resume, and
# no human/input sample inside the pause but the release (web_human's step may also have taken
# the page's own last release just before the marker arrived: then two, both in the first 0.5 s).
#   pause_test.sh BUILD_DIR WORK_DIR TEST_PLUGIN
set -euo pipefail
build=$1
work=$2
plugin=$3
source "$(dirname "$0")/../../../tests/support/web_test.sh"
require_node
fresh_dir "$work"
cat > graph.yaml <<YAML
graph: pause_test
clock: wall
domain_id: $(test_domain)
plugins: [$plugin]
topics:
  web/pointer: {type: HumanInput, reliability: reliable, depth: 8}
components:
  web: {type: web, rate_hz: 30, params: {port: 0, port_file: web.port, token: experimenter-token-0001, subject_token: subject-token-000001,
        viewer_token: viewer-token-0000001, pause_without_subject: true, wait_for_subject_s: 30},
        inputs: {robot: robot/state}, outputs: {pointer: web/pointer, notes: experiment/notes}}
$(subject_robot)
  recorder: {type: recorder, rate_hz: 10, params: {file: rec.mcap, topics: [human/input, robot/command, experiment/notes]}}
YAML
"$build/bin/dyad" run graph.yaml --duration 60 > run.out 2> run.err &
pid=$!
wait_port_file web.port $pid 30  # a cold start on a loaded machine
node "$node_dir/pause_client.mjs" "ws://127.0.0.1:$(cat web.port)/subject/ws?token=subject-token-000001" 2500 > client.json \
  || { kill $pid; cat run.err; fail "the client"; }
kill -INT $pid
wait $pid || true
# The client's last close may come before the graph's end: a second pause then.
grep -qE "paused [12] times without the subject's page" run.err || { cat run.err; fail "no pause counted at the end"; }
"$build/bin/dyad" bag export rec.mcap --csv csv > /dev/null
python3 - csv <<'PY'
import csv, os, sys
def fail(why): sys.exit("FAIL: " + why)
def rows(name): return list(csv.DictReader(open(os.path.join(sys.argv[1], name))))
notes = [(int(r["header.stamp_ns"]), r["author"], r["text"]) for r in rows("experiment_notes.csv")]
want = [("web", "paused: the subject's page is gone"), ("web", "resumed: the subject's page is back")]
# A third mark, a pause, when the client's last close came before the graph's end.
if [n[1:] for n in notes[:2]] != want or [n[1:] for n in notes[2:]] not in ([], want[:1]):
    fail("experiment/notes holds %s, want %s (and maybe a last pause)" % (notes, want))
paused, resumed = notes[0][0], notes[1][0]
away = (resumed - paused) * 1e-9
if not 2.0 <= away <= 4.5: fail("paused for %.2f s; the page was away 2.5 s" % away)
truth = lambda v: v in ("1", "true")
commands = [(int(r["header.stamp_ns"]), truth(r["hold"])) for r in rows("robot_command.csv")]
# The mixer's human input goes stale 0.5 s (its stale_timeout_s) after web_human's last sample,
# which comes within its next step or two (10 Hz); margins for a loaded machine.
inside = [h for t, h in commands if paused + 1.0e9 <= t <= resumed]
before = [h for t, h in commands if paused - 1.5e9 <= t <= paused]
after = [h for t, h in commands if resumed + 0.8e9 <= t]
if len(inside) < 10 or not all(inside): fail("%d of the %d commands in the pause are holds" % (sum(inside), len(inside)))
if len(before) < 5 or any(before): fail("%d of the %d commands before the pause are holds" % (sum(before), len(before)))
if len(after) < 5 or any(after): fail("%d of the %d commands after the resume are holds" % (sum(after), len(after)))
human = [(int(r["header.stamp_ns"]), truth(r["engaged"])) for r in rows("human_input.csv")]
during = [(t - paused) * 1e-9 for t, e in human if paused < t < resumed]
engaged = [e for t, e in human if paused < t < resumed and e]
if not 1 <= len(during) <= 2 or engaged or max(during) > 0.5:
    fail("human/input in the pause at %s s (want a release in its first 0.5 s, then nothing)" % during)
print("PASS: paused %.2f s; %d hold commands inside, none in the %d before or the %d after" % (away, len(inside), len(before), len(after)))
PY
