#!/usr/bin/env bash
# "The clock waits for the page" (wait_for_subject_s, issue #45 item 4): a one-process wall-clock
# graph whose web component waits for the subject's page, and a page that comes 2 s after the
# server is up. The run's start must be fixed after that wait, not before: no component counts a
# deadline miss (before: web, human and recorder each counted one, their first steps late by the
# wait), the first step (web_human's first human/input sample) comes within a period (100 ms;
# 150 ms allowed on a loaded machine) of the page's arrival, and --duration 3 counts from there
# (before: from before the wait, so the run ended 1 s after the page came).
#   clock_wait_test.sh BUILD_DIR WORK_DIR
set -euo pipefail
build=$1
work=$2
source "$(dirname "$0")/../../../tests/support/web_test.sh"
require_node
fresh_dir "$work"
cat > graph.yaml <<YAML
graph: clock_wait_test
clock: wall
domain_id: $(test_domain)
topics:
  web/pointer: {type: HumanInput, reliability: reliable, depth: 8}
components:
  web: {type: web, rate_hz: 30, params: {port: 0, port_file: web.port, token: experimenter-token-0001, subject_token: subject-token-000001,
        viewer_token: viewer-token-0000001, wait_for_subject_s: 30}, outputs: {pointer: web/pointer}}
  human: {type: web_human, rate_hz: 10, inputs: {pointer: web/pointer}, outputs: {input: human/input}}
  recorder: {type: recorder, rate_hz: 10, params: {file: rec.mcap, topics: [human/input]}}
YAML
"$build/bin/dyad" run graph.yaml --duration 3 > run.out 2> run.err &
pid=$!
wait_port_file web.port $pid 30
node "$node_dir/late_page.mjs" "ws://127.0.0.1:$(cat web.port)/subject/ws?token=subject-token-000001" 2000 10000 > client.json \
  || { kill $pid; cat run.err; fail "the client"; }
wait $pid || { cat run.err; fail "dyad run failed"; }
grep -q "the subject's page is there: the run starts" run.err || { cat run.err; fail "the wait's end not said"; }
"$build/bin/dyad" bag export rec.mcap --csv csv > /dev/null
python3 - client.json run.out csv/human_input.csv <<'PY'
import csv, json, sys
def fail(why): sys.exit("FAIL: " + why)
c = json.loads(open(sys.argv[1]).readline())
if not c["steering"]: fail("the page never steered")
opened = c["opened"] * 1e-3
out = open(sys.argv[2]).read().splitlines()
rows = {l.split()[0]: l.split() for l in out[out.index(next(l for l in out if l.startswith("component"))) + 1:] if l.split() and l.split()[0] in ("web", "human", "recorder")}
if sorted(rows) != ["human", "recorder", "web"]: fail("no timing rows for web, human, recorder in:\n" + "\n".join(out))
missed = {k: int(v[7]) for k, v in rows.items() if int(v[7]) != 0}
if missed: fail("deadline misses %s (jitter_max_ms %s): the first steps were late by the wait for the page" % (missed, {k: rows[k][6] for k in missed}))
stamps = [int(r["header.stamp_ns"]) * 1e-9 for r in csv.DictReader(open(sys.argv[3]))]
if not stamps: fail("no human/input recorded")
first, last = stamps[0] - opened, stamps[-1] - opened
if not -0.15 <= first <= 0.15: fail("the first step %.3f s from the page's arrival (want within a period, 0.1 s)" % first)
if not 2.7 <= last <= 3.3: fail("the last step %.2f s after the page's arrival (--duration 3 counts from the start)" % last)
print("PASS: first step %+.0f ms from the page's arrival, last %.2f s after it; no deadline miss (web, human, recorder)" % (first * 1e3, last))
PY
