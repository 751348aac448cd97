#!/usr/bin/env bash
# Past one server (#45 item 5, docs/study.md "More than one server"): two `dyad study serve`
# instances on one study folder behind HAProxy, sticky by the participant's token. Four simulated
# participants (sim_participant.mjs --online) come through HAProxy; once both instances run
# trials, instance B is stopped (SIGTERM) and started again on its port 3 s later. Read back here:
#   - HAProxy spread the participants over both instances, each participant's trials on one;
#   - A's participants went on untouched: every trial complete at its first attempt;
#   - B's participants went over to A while B was down (their pages reconnect; HAProxy's check
#     saw B down and sent them on), A repeated the trial B stopped, with its reason, and kept them
#     after B came back; every session log has its completion code;
#   - `dyad study analyze` over the shared folder: all four participants, every trial complete.
#   serve_haproxy_test.sh REPO BUILD_DIR WORK_DIR
set -euo pipefail
repo=$1 build=$2 work=$3
source "$(dirname "$0")/../../../tests/support/web_test.sh"
require_node
command -v haproxy > /dev/null || { echo "SKIP: needs tools/setup.sh (Debian haproxy)"; exit 77; }
dyad=$build/bin/dyad
fresh_dir "$work"
trap stop_started EXIT

"$dyad" generate dataset --out data > /dev/null
subject_graph g.yaml "dataset: data"
echo "You agree to take part in a test." > consent.txt
cat > s.yaml <<YAML
study: haproxy_test
graph: g.yaml
data: sdata
participants: [P01, P02, P03, P04]
conditions:
  low: {human.engage_timeout_s: 0.3}
  high: {human.engage_timeout_s: 0.4}
duration: 4
online: {consent: consent.txt, reconnect_s: 10}
YAML
hp=$(free_port) pa=$(free_port) pb=$(free_port)
"$dyad" study links s.yaml --base-url "http://127.0.0.1:$hp" > links.out
serve() {  # serve NAME PORT DOMAINS: an instance, its output appended to NAME.out
  "$dyad" study serve s.yaml --port "$2" --domains "$3" --origin "http://127.0.0.1:$hp" >> "$1.out" 2>> "$1.err" &
  pids+=($!)
  eval "pid_$1=$!"
  for _ in $(seq 100); do grep -q "dyad study serve: haproxy_test at" "$1.out" 2> /dev/null && return 0; sleep 0.1; done
  cat "$1.err"; fail "instance $1 never listened"
}
# Two instances on one machine: their trials on disjoint domains (docs/study.md).
claim_test_domains 32 d
da="$d-$((d + 15))" db="$((d + 16))-$((d + 31))"
serve a "$pa" "$da"
serve b "$pb" "$db"
grep -q "trials on DDS domains $da (one each)" a.out && grep -q "trials on DDS domains $db (one each)" b.out ||
  { cat a.out b.out; fail "the instances do not say their trials' domains"; }
# Sticky by token: a participant's first request picks an instance (round robin), the table keeps
# it there; one whose instance is down is sent to the other (redispatch) and kept there.
cat > haproxy.cfg <<CFG
global
  maxconn 256
defaults
  mode http
  timeout connect 2s
  timeout client 1h
  timeout server 1h
  timeout tunnel 1h
  retries 3
  option redispatch
frontend participants
  bind 127.0.0.1:$hp
  default_backend fronts
backend fronts
  balance roundrobin
  stick-table type string len 64 size 10k expire 1h
  stick on url_param(token)
  server a 127.0.0.1:$pa check inter 300ms fall 1 rise 1
  server b 127.0.0.1:$pb check inter 300ms fall 1 rise 1
CFG
haproxy -c -q -f haproxy.cfg || fail "haproxy.cfg"
haproxy -f haproxy.cfg -db > haproxy.log 2>&1 &
pids+=($!)
for _ in $(seq 50); do curl -s -o /dev/null "http://127.0.0.1:$hp/" && break; sleep 0.1; done

sed -n 's|^\(P0[1-4]\),http://[^?]*?token=\(.*\)$|http://127.0.0.1:'"$hp"' \2|p' sdata/links.csv > sessions
[ "$(wc -l < sessions)" = 4 ] || fail "links.csv: $(cat sdata/links.csv)"
node "$node_dir/sim_participant.mjs" --online --speed 3 --seconds 120 sessions > clients.json 2> clients.err &
client=$!
pids+=($client)
# Both instances run a trial (each has a participant in it): restart B.
for _ in $(seq 300); do
  grep -q ": trial 1 of 2: " a.out && grep -q ": trial 1 of 2: " b.out && break; sleep 0.1
done
grep -q ": trial 1 of 2: " a.out && grep -q ": trial 1 of 2: " b.out ||
  { cat a.out b.out haproxy.log; fail "the participants did not reach both instances"; }
on_a=$(sed -n 's/^\(P0[1-4]\): trial 1 of 2: .*/\1/p' a.out | sort -u)
on_b=$(sed -n 's/^\(P0[1-4]\): trial 1 of 2: .*/\1/p' b.out | sort -u)
kill -TERM "$pid_b"
wait "$pid_b" || fail "instance b's SIGTERM exit: $?"
# Down for 3 s: HAProxy's check marks it down within 0.3 s, so its participants' pages, which
# reconnect every second, are sent to A, which takes their sessions on from the shared log.
sleep 3
echo "--- restarted" >> b.out
serve b "$pb" "$db"
wait $client || { cat clients.err; fail "the simulated participants"; }
grep -c '"code":"' clients.json | grep -qx 4 || { cat clients.json a.out b.out; fail "not every participant got a completion code"; }

for p in $on_a; do  # untouched by B's restart: each trial once, complete
  starts=$(grep -c '"event":"start"' "sdata/$p/session.log")
  [ "$starts" = 2 ] || { cat "sdata/$p/session.log"; fail "$p (instance a) started $starts attempts, not 2"; }
done
for p in P01 P02 P03 P04; do
  grep -q '"event":"completed"' "sdata/$p/session.log" || { cat "sdata/$p/session.log"; fail "$p: no completion"; }
done
for p in $on_b; do  # B's: their stopped trial repeated on A, with its reason, and kept there
  grep -q '"outcome":"stopped"' "sdata/$p/session.log" || { cat "sdata/$p/session.log"; fail "$p: B's SIGTERM did not stop its trial"; }
  grep -q "^$p: trial 1 of 2: .*attempt 2 (attempt 1 was stopped)" a.out || { cat a.out; fail "$p: not taken on by A"; }
  grep -q "^$p: trial 2 of 2: " a.out || { cat a.out; fail "$p: its next trial not on A"; }
  ! grep -q "^$p: trial" <(sed -n '/--- restarted/,$p' b.out) || { cat b.out; fail "$p: moved back to B after its restart"; }
done
"$dyad" study analyze s.yaml -o analysis --no-plots > analyze.out 2>&1 || { cat analyze.out; fail "dyad study analyze"; }
complete=$(awk -F, 'NR > 1 && $8 == "true"' analysis/trials.csv | wc -l)
[ "$complete" = 8 ] || { cat analysis/trials.csv; fail "$complete of 8 trials complete in the analysis"; }
echo "instance a: $(echo $on_a); instance b (restarted mid-trial): $(echo $on_b); 8 of 8 trials complete"
