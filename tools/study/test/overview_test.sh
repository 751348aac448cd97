#!/usr/bin/env bash
# The experimenter's overview of `dyad study serve` (#45 item 2, docs/study.md "The experimenter's
# overview"): two simulated participants (sim_participant.mjs --online) in a trial at once, the
# overview in Chromium (overview.mjs: their trial, condition label, engaged, recording, step p99,
# misses, round trip; a note to P01's log; P02's session stopped with a reason). Read back here:
#   - P01's log holds the note, with the trial under way;
#   - P02's log: {"event":"session_ended"} with the reason, then trial 1 ended incomplete
#     "stopped by the experimenter: REASON", no trial after it; P02's page was told (refused);
#   - DATA/serve-tokens is 0600 and read again at the next start (the same link), one readable by
#     others is refused naming it; after that restart P02's link is still refused (the log holds
#     the end) until the overview resumes it (then trial 1 again); a participant's token does not
#     open the overview.
#   overview_test.sh REPO BUILD_DIR WORK_DIR
set -euo pipefail
repo=$1 build=$2 work=$3
source "$(dirname "$0")/../../../tests/support/web_test.sh"
require_browser
dyad=$build/bin/dyad
fresh_dir "$work"
ln -s "$node_modules" node_modules  # the script imports playwright-core from beside itself
cp "$(dirname "$0")/overview.mjs" .
trap stop_started EXIT
port=$(free_port)

subject_graph g.yaml
cat > s.yaml <<YAML
study: overview_test
graph: g.yaml
data: sdata
participants: [P01, P02]
conditions:
  low: {human.engage_timeout_s: 0.3}
  high: {human.engage_timeout_s: 0.4}
duration: 8
blind: true
online: {reconnect_s: 5, consent: consent.txt}
YAML
echo "You agree to take part in a test." > consent.txt
"$dyad" study links s.yaml --base-url "http://127.0.0.1:$port" > /dev/null
serve() {
  "$dyad" study serve s.yaml --port "$port" > serve.out 2> serve.err &
  serve_pid=$!
  pids+=($serve_pid)
  for _ in $(seq 100); do grep -q "experimenter's overview: " serve.out 2> /dev/null && return 0; sleep 0.1; done
  cat serve.out serve.err; fail "no overview link printed"
}
serve
[ "$(stat -c %a sdata/serve-tokens)" = 600 ] || fail "sdata/serve-tokens is $(stat -c %a sdata/serve-tokens), not 600"
url=$(head -1 sdata/overview-link)
[ "$(stat -c %a sdata/overview-link)" = 600 ] || fail "sdata/overview-link is $(stat -c %a sdata/overview-link), not 600"
! grep -q "${url#*token=}" serve.out serve.err || fail "the overview's token printed: $(cat serve.out)"
token() { sed -n 's/^subject //p' "sdata/$1/web-tokens"; }
code=$(curl -s -o /dev/null -w '%{http_code}' "http://127.0.0.1:$port/overview?token=$(token P01)")
[ "$code" != 200 ] || fail "a participant's token opened the overview"
echo "http://127.0.0.1:$port $(token P01)" > p01.sessions
echo "http://127.0.0.1:$port $(token P02)" > p02.sessions
node "$node_dir/sim_participant.mjs" --online --speed 3 --seconds 40 p01.sessions > p01.json 2> p01.err &
pids+=($!)
node "$node_dir/sim_participant.mjs" --online --speed 3 --seconds 40 p02.sessions > p02.json 2> p02.err &
p02=$!
pids+=($p02)
reason="the participant asked to stop"
node overview.mjs "$url" "$work" P02 "$reason" P01 "P01 | sneezed" || { cat serve.out serve.err; fail "the overview"; }
wait $p02 || { cat p02.err; fail "P02's simulated participant"; }
grep -q '"refused":"The experimenter has ended this session. Thank you for your time."' p02.json ||
  { cat p02.json serve.out; fail "P02's page was not told the session ended"; }
kill -TERM "$serve_pid"
wait "$serve_pid" || fail "dyad study serve's SIGTERM exit: $?"
python3 - sdata "$reason" <<'PY'
import json, sys
data, reason = sys.argv[1:]
def log(p): return [json.loads(l) for l in open(f"{data}/{p}/session.log")]
def fail(why, lines): sys.exit("FAIL: " + why + "\n" + "\n".join(map(str, lines)))
p1, p2 = log("P01"), log("P02")
notes = [(l["text"], l.get("trial")) for l in p1 if l["event"] == "note"]
if notes != [("P01 | sneezed", 1)]: fail("P01's notes %s" % notes, p1)
events = [l["event"] for l in p2 if l["event"] in ("start", "end", "session_ended")]
if events != ["start", "session_ended", "end"]: fail("P02's events %s" % events, p2)
ended = next(l for l in p2 if l["event"] == "session_ended")
if ended["reason"] != reason: fail("the reason logged: %r" % ended["reason"], p2)
end = next(l for l in p2 if l["event"] == "end")
if (end["outcome"], end.get("incomplete")) != ("incomplete", "stopped by the experimenter: " + reason): fail("P02's trial ended %s" % end, p2)
print("PASS: the note in P01's log; P02's session ended with its reason, its trial incomplete")
PY
# The token file: refused when readable by others (naming it), read again after (the same link).
chmod 644 sdata/serve-tokens
rc=0; "$dyad" study serve s.yaml --port "$port" > bad.out 2> bad.err || rc=$?
[ $rc = 2 ] && grep -q "sdata/serve-tokens: holds the experimenter's overview token and is readable by others" bad.err ||
  { cat bad.out bad.err; fail "a serve-tokens readable by others: exit $rc"; }
chmod 600 sdata/serve-tokens
serve
[ "$(head -1 sdata/overview-link)" = "$url" ] || fail "a new overview token at the restart"
node "$node_dir/sim_participant.mjs" --online --seconds 10 p02.sessions > p02b.json 2> p02b.err || { cat p02b.err; fail "P02 again"; }
grep -q '"refused":"The experimenter has ended this session.' p02b.json || { cat p02b.json; fail "P02's session open again after a restart"; }
# Resumed from the overview's socket: P02's link opens the session again, the stopped trial next.
cat > resume.mjs <<'JS'
import WebSocket from "ws";
const [base, token, p02] = process.argv.slice(2);
const first = (url, send) => new Promise((resolve, reject) => {
  const ws = new WebSocket(url);
  ws.on("open", () => send && ws.send(JSON.stringify(send)));
  ws.on("message", (d) => { const m = JSON.parse(String(d)); if (m.op !== "state" && m.op !== "ping") { ws.close(); resolve(m); } });
  ws.on("error", reject);
});
console.log(JSON.stringify(await first(`${base}/overview/ws?token=${token}`, { op: "resume", participant: "P02" })));
console.log(JSON.stringify(await first(`${base}/subject/ws?token=${p02}`)));
JS
overview_token=$(sed -n 's/^experimenter //p' sdata/serve-tokens)
node resume.mjs "ws://127.0.0.1:$port" "$overview_token" "$(token P02)" > resume.out 2>&1 || { cat resume.out; fail "resume"; }
grep -q '"op":"done","participant":"P02","request":"resume"' resume.out && grep '"op":"waiting"' resume.out | grep -q 'Trial 1 of 2 starts again' ||
  { cat resume.out serve.out; fail "P02 resumed: not offered trial 1 again"; }
tail -1 sdata/P02/session.log | grep -q '"event":"session_resumed"' || fail "no session_resumed in P02's log"
kill -TERM "$serve_pid"
wait "$serve_pid" || fail "dyad study serve's second SIGTERM exit: $?"
echo "PASS: overview link kept across restarts; P02 still ended, then resumed"
