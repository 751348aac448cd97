#!/usr/bin/env bash
# The simulated participant (node/sim_participant.mjs, bench/capacity's client) against a real
# `dyad run`: it steers (engaged human/input, every engaged position on one of the data set's
# primitives, as drawn), its samples carry the page's stamps (the web component measures event ->
# published, the acks come back), and it answers "What were you drawing?" with the primitive its
# hold drew (report error 0), recorded with that hold's segment. At 3x its human pace (--speed).
#   sim_participant_test.sh BUILD_DIR WORK_DIR
set -euo pipefail
build=$1
work=$2
source "$(dirname "$0")/../../../tests/support/web_test.sh"
require_node
fresh_dir "$work"
"$build/bin/dyad" generate dataset --out data > /dev/null
cat > graph.yaml <<YAML
graph: sim_participant_test
clock: wall
domain_id: $(test_domain)
topics:
  web/pointer: {type: HumanInput, reliability: reliable, depth: 8}
components:
  web: {type: web, rate_hz: 30, params: {port: 0, port_file: web.port, token: experimenter-token-0001, subject_token: subject-token-000001, viewer_token: viewer-token-0000001, dataset: data},
        outputs: {pointer: web/pointer, self_report: human/self_report}}
  human: {type: web_human, rate_hz: 10, inputs: {pointer: web/pointer}, outputs: {input: human/input}}
  recorder: {type: recorder, rate_hz: 10, params: {file: rec.mcap, topics: [human/input, human/self_report]}}
YAML
"$build/bin/dyad" run graph.yaml --duration 60 > run.out 2> run.err &
pid=$!
wait_port_file web.port $pid 30
echo "http://127.0.0.1:$(cat web.port) subject-token-000001" > sessions
node "$node_dir/sim_participant.mjs" --dataset data --seconds 9 --speed 3 --report-error 0 sessions > client.json \
  || { kill $pid; cat run.err; fail "the client"; }
kill -INT $pid
wait $pid || true
grep -qE "pointer event -> published: median [0-9.]+ ms, p99 [0-9.]+ ms \([0-9]+ samples\)" run.err || { cat run.err; fail "no pointer delays measured"; }
"$build/bin/dyad" bag export rec.mcap --csv csv > /dev/null
python3 - client.json data csv/human_input.csv csv/human_self_report.csv <<'PY'
import csv, glob, json, math, os, sys
def fail(why): sys.exit("FAIL: " + why)
c = json.loads(open(sys.argv[1]).readline())
if c["errors"] or c["closes"] > 1: fail("the client's connection: %s" % c)
# Acks at most one per 100 ms to a page (9 s of pointer samples at about 60 Hz: about 90 of 540).
if c["sent"] < 100 or not 20 <= c["acks"] <= 9 * 10 + 5 or c["acks"] > c["sent"] / 3:
    fail("%d pointer samples sent, %d acknowledged (want at most one ack per 100 ms)" % (c["sent"], c["acks"]))
prims = []
for k in range(len(glob.glob(os.path.join(sys.argv[2], "primitive_*_0.csv")))):
    prims.append([tuple(map(float, r[:2])) for r in csv.reader(open(os.path.join(sys.argv[2], "primitive_%d_0.csv" % k)))])
rows = list(csv.DictReader(open(sys.argv[3])))
engaged = [(int(r["header.stamp_ns"]), float(r["x"]), float(r["y"])) for r in rows if r["engaged"] in ("1", "true")]
if len(engaged) < 10: fail("%d engaged human/input steps (want a hold of >= 1.9 s at 10 Hz)" % len(engaged))
# Each engaged position lies near the primitive drawn (a hold's rotation, scale and offset, and
# the tremor, stay within 12 units of the data set's shape).
def dist(p, prim): return min(math.hypot(p[0] - q[0], p[1] - q[1]) for q in prim)
reports = list(csv.DictReader(open(sys.argv[4])))
if not reports: fail("no self-report recorded (the client answers 1-3 s / 3 after a hold)")
for r in reports:
    k, s, e = int(r["choice"]), int(r["segment_start_ns"]), int(r["segment_end_ns"])
    if not 0 <= k < len(prims): fail("choice %d: not a primitive (report error 0)" % k)
    inside = [p for p in engaged if s - 150e6 <= p[0] <= e + 150e6]
    if len(inside) < 10: fail("%d engaged steps in the reported segment" % len(inside))
    far = [p for p in inside if dist(p[1:], prims[k]) > 12]
    if far: fail("the answer says primitive %d, but %d of the segment's %d steps are off it: %s" % (k, len(far), len(inside), far[:3]))
    best = min(range(len(prims)), key=lambda j: sum(dist(p[1:], prims[j]) for p in inside))
    if best != k: fail("the segment looks like primitive %d, the answer says %d" % (best, k))
print("PASS: %d samples sent, %d acked, rtt p99 %s ms; %d engaged steps; %d answers, each the primitive drawn"
      % (c["sent"], c["acks"], c["rtt_p99_ms"], len(engaged), len(reports)))
PY
