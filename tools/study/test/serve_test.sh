#!/usr/bin/env bash
# What goes wrong online (#45 item 3), through `dyad study serve` with scripted pages
# (serve_cases.mjs), and what it refuses to start with: unknown tokens (404, an address guessing
# 429), a session the lab holds (and `dyad study run` of a participant online), a link open twice
# (1008; a silent first page replaced), max_sessions (come back later), a page lost for less and
# more than reconnect_s mid-trial, the front restarted by SIGTERM and by SIGKILL mid-trial, and
# the page over HTTPS and WSS with a certificate, a graph that fails at every trial. Trials of 4 s
# on a small graph.
#   serve_test.sh REPO BUILD_DIR WORK_DIR
set -euo pipefail
repo=$1 build=$2 work=$3
source "$repo/tests/support/web_test.sh"
require_node
fresh_dir "$work"
ln -s "$node_modules" node_modules  # the script imports ws from beside itself
cp "$repo/tools/study/test/serve_cases.mjs" .
subject_graph g.yaml
echo "I agree to take part in this test study." > consent.txt
cat > s.yaml <<YAML
study: serve_test
graph: g.yaml
participants: [P01, P02, P03, P04]
conditions:
  low: {human.engage_timeout_s: 0.3}
  high: {human.engage_timeout_s: 0.4}
duration: 4
blind: true
online: {reconnect_s: 3, max_sessions: 2, consent: consent.txt}
YAML
"$build/bin/dyad" study links s.yaml --base-url http://127.0.0.1:8443 > /dev/null
# Refused before anything listens, naming the flag or key: off loopback without TLS; consent
# required without its text.
rc=0; "$build/bin/dyad" study serve s.yaml --address 0.0.0.0 --port 0 > refused.out 2>&1 || rc=$?
[ $rc = 2 ] && grep -q -- "--tls-certificate: required off loopback (--address 0.0.0.0)" refused.out ||
  fail "off loopback without TLS: exit $rc: $(cat refused.out)"
# Fewer trial domains than live sessions (each running trial has one of its own), or not a range.
rc=0; "$build/bin/dyad" study serve s.yaml --port 0 --domains 40-40 > refused.out 2>&1 || rc=$?
[ $rc = 2 ] && grep -q -- "--domains 40-40 holds 1 domain for max_sessions 2" refused.out ||
  fail "one domain for two sessions: exit $rc: $(cat refused.out)"
rc=0; "$build/bin/dyad" study serve s.yaml --port 0 --domains 40 > refused.out 2>&1 || rc=$?
[ $rc = 2 ] && grep -q -- "--domains '40': want FIRST-LAST" refused.out || fail "--domains 40: exit $rc: $(cat refused.out)"
sed 's/, consent: consent.txt//' s.yaml > no_consent.yaml
rc=0; "$build/bin/dyad" study serve no_consent.yaml --port 0 > refused.out 2>&1 || rc=$?
[ $rc = 2 ] && grep -q "no_consent.yaml: online.consent: required to serve a study with consent_required" refused.out ||
  fail "consent required without online.consent: exit $rc: $(cat refused.out)"
# A condition's own domain_id is replaced by each running trial's: said at start.
sed -e 's/^study: serve_test/study: serve_dom/' -e 's/high: {human.engage_timeout_s: 0.4}/high: {human.engage_timeout_s: 0.4, domain_id: 7}/' s.yaml > dom.yaml
"$build/bin/dyad" study serve dom.yaml --port 0 --port-file dom-port > dom.out 2>&1 &
dom=$!
wait_port_file dom-port $dom 10 dom.out
kill -TERM $dom; wait $dom || fail "dyad study serve dom.yaml exited $?: $(cat dom.out)"
grep -q "dom.yaml: condition 'high' sets domain_id=7, which serve replaces: each running trial has a DDS domain of its own, from" dom.out ||
  fail "a condition's domain_id replaced without a word: $(cat dom.out)"
node serve_cases.mjs "$build/bin/dyad" s.yaml serve_test-data
# The page lost for 1 s in P01's trial 1: the graph paused (study serve sets pause_without_subject)
# and the recording marks both ends.
"$build/bin/dyad" bag export serve_test-data/P01/01-*.mcap --csv notes > /dev/null
grep -q "paused: the subject's page is gone" notes/*notes*.csv && grep -q "resumed: the subject's page is back" notes/*notes*.csv ||
  fail "P01's trial 1 has no pause marks: $(cat notes/*notes*.csv)"
# With a certificate: HTTPS and WSS only (as off loopback, where it is required).
openssl req -x509 -newkey rsa:2048 -nodes -keyout key.pem -out cert.pem -days 1 -subj /CN=localhost 2> /dev/null
cat key.pem cert.pem > web.pem && chmod 600 web.pem
"$build/bin/dyad" study serve s.yaml --port 0 --port-file tls-port --tls-certificate web.pem > tls.out 2>&1 &
tls=$!
wait_port_file tls-port $tls 10 tls.out
p03=$(sed -n 's/^subject //p' serve_test-data/P03/web-tokens)
code=$(curl -sk -o /dev/null -w "%{http_code}" "https://127.0.0.1:$(cat tls-port)/subject?token=$p03")
[ "$code" = 200 ] || { kill $tls; fail "the page over HTTPS: $code: $(cat tls.out)"; }
# The page's first view, pings aside: the front pings every page every 2 s, and on a loaded machine
# (ASan, other builds) a ping can reach a page before the view its session log gives.
op=$(node -e '
  const WebSocket = require("ws");
  const ws = new WebSocket(process.argv[1], { rejectUnauthorized: false });
  ws.on("message", (d) => { const op = JSON.parse(String(d)).op; if (op !== "ping") { console.log(op); process.exit(0); } });
  ws.on("error", (e) => { console.log("error: " + e.message); process.exit(1); });
  setTimeout(() => { console.log("nothing"); process.exit(1); }, 5000);' "wss://127.0.0.1:$(cat tls-port)/subject/ws?token=$p03") ||
  { kill $tls; fail "the page's socket over WSS: $op: $(cat tls.out)"; }
[ "$op" = waiting ] || { kill $tls; fail "over WSS P03 (consent given in serve_cases.mjs) got '$op', not the waiting page"; }
kill -TERM $tls; wait $tls || fail "dyad study serve with TLS exited $?: $(cat tls.out)"
# Off loopback on --port 0: a page from the printed address (its origin carries the bound port) is admitted.
"$build/bin/dyad" study serve s.yaml --address 0.0.0.0 --port 0 --port-file any-port --tls-certificate web.pem > any.out 2>&1 &
any=$!
wait_port_file any-port $any 10 any.out
for _ in $(seq 50); do grep -q "/subject?token=" any.out && break; sleep 0.1; done
at=$(sed -n 's|^dyad study serve: serve_test at \(https://[^/]*\)/subject.*|\1|p' any.out | head -1)
op=$(node -e '
  const WebSocket = require("ws");
  const ws = new WebSocket(process.argv[1], { rejectUnauthorized: false, origin: process.argv[2] });
  ws.on("message", (d) => { const op = JSON.parse(String(d)).op; if (op !== "ping") { console.log(op); process.exit(0); } });
  ws.on("error", (e) => { console.log("error: " + e.message); process.exit(1); });
  setTimeout(() => { console.log("nothing"); process.exit(1); }, 5000);' "wss://127.0.0.1:$(cat any-port)/subject/ws?token=$p03" "$at") ||
  { kill $any; fail "off loopback on port 0, a page from $at: $op: $(cat any.out)"; }
kill -TERM $any; wait $any || fail "dyad study serve --address 0.0.0.0 --port 0 exited $?: $(cat any.out)"
[ "$op" = waiting ] || fail "off loopback on port 0, P03 from $at got '$op'"
# A graph that fails at every trial (its data set deleted once the front has started): three
# failed attempts, then the participant is asked to come back later.
"$build/bin/dyad" generate dataset --out ds > /dev/null
sed 's|params: {port: 0}|params: {port: 0, dataset: ds}|' g.yaml > g_broken.yaml
printf 'study: broken\ngraph: g_broken.yaml\nparticipants: [P01]\nconditions: {low: {human.engage_timeout_s: 0.3}}\nduration: 4\nconsent_required: false\n' > broken.yaml
"$build/bin/dyad" study links broken.yaml --base-url http://127.0.0.1:8443 > /dev/null
"$build/bin/dyad" study serve broken.yaml --port 0 --port-file broken-port > broken.out 2>&1 &
broken=$!
wait_port_file broken-port $broken 10 broken.out
rm -r ds
said=$(node -e '
  const WebSocket = require("ws");
  let presses = 0;
  const open = () => {
    const ws = new WebSocket(process.argv[1]);
    ws.on("message", (d) => {
      const m = JSON.parse(String(d));
      if (m.op === "ping") ws.send(JSON.stringify({ op: "pong", id: m.id }));
      if (m.op === "waiting" && m.ready) presses++, ws.send(JSON.stringify({ op: "ready" }));
      if (m.op === "refused") console.log(presses + " " + m.message), process.exit(0);
    });
    ws.on("close", (code) => { if (code !== 1008) setTimeout(open, 100); });
    ws.on("error", () => {});
  };
  open();
  setTimeout(() => { console.log("no refusal after " + presses + " presses"); process.exit(1); }, 30000);' \
  "ws://127.0.0.1:$(cat broken-port)/subject/ws?token=$(sed -n 's/^subject //p' broken-data/P01/web-tokens)") ||
  { kill $broken; fail "a broken graph: $said: $(cat broken.out)"; }
kill -TERM $broken; wait $broken || true
[[ "$said" == "3 Something went wrong on our side"* ]] || fail "a broken graph: '$said': $(cat broken.out)"
[ "$(grep -c '"outcome":"failed"' broken-data/P01/session.log)" = 3 ] || fail "not 3 failed attempts: $(cat broken-data/P01/session.log)"
grep -q "failed 3 times in a row" broken.out || fail "the front did not say why: $(cat broken.out)"
# Killed or stopped, the front leaves no trial's graph behind (each ends by its parent-death signal).
for _ in $(seq 50); do pgrep -f "$work/serve_test-data" > /dev/null || break; sleep 0.2; done
if pgrep -fa "$work/serve_test-data"; then fail "a trial's graph outlived dyad study serve"; fi
echo "serve_test: every case passed"
