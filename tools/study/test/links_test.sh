#!/usr/bin/env bash
# `dyad study links`: one private link per participant, in DATA/links.csv (0600), each carrying
# the participant's subject token from their token file (DATA/P/web-tokens, 0600, made once and
# kept: a second call gives the same links, a participant added later gets a new one); the graph's
# web component opens its subject's page to that token; bad base URLs, a token file readable by
# others and a graph whose web component has its own token file are refused, naming what is wrong.
#   links_test.sh REPO BUILD_DIR WORK_DIR
set -euo pipefail
repo=$1 build=$2 work=$3
source "$(dirname "$0")/../../../tests/support/web_test.sh"
dyad=$build/bin/dyad
fresh_dir "$work"
cat > graph.yaml <<YAML
graph: links_test
clock: wall
domain_id: $(test_domain)
components:
  web: {type: web, rate_hz: 10, params: {port: 0, port_file: web.port}, outputs: {pointer: web/pointer}}
  human: {type: web_human, rate_hz: 10, inputs: {pointer: web/pointer}, outputs: {input: human/input}}
  recorder: {type: recorder, rate_hz: 1, params: {file: rec.mcap}}
YAML
study() {  # study PARTICIPANTS
  cat > s.yaml <<YAML
study: links_test
graph: graph.yaml
data: data
participants: [$1]
conditions:
  wide: {web.half_width: 50}
  narrow: {web.half_width: 40}
YAML
}
study "P01, P02"
"$dyad" study links s.yaml --base-url https://study.example.org/dyad/ > out1 2> err1 || { cat out1 err1; fail "links refused a good study"; }
grep -q "links: 2 participants (2 new tokens, 0 kept)" out1 || { cat out1; fail "what links said"; }
for f in data/links.csv data/P01/web-tokens data/P02/web-tokens; do
  [ "$(stat -c %a "$f")" = 600 ] || fail "$f has mode $(stat -c %a "$f"), want 600"
done
python3 - data/links.csv data/P01/web-tokens data/P02/web-tokens <<'PY'
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))
def fail(why): sys.exit("FAIL: " + why)
if rows[0] != ["participant", "link"]: fail("header %s" % rows[0])
tok = lambda f: [l.split(" ", 1)[1].strip() for l in open(f) if l.startswith("subject ")][0]
want = [["P01", "https://study.example.org/dyad/subject?token=" + tok(sys.argv[2])],
        ["P02", "https://study.example.org/dyad/subject?token=" + tok(sys.argv[3])]]
if rows[1:] != want: fail("rows %s, want %s" % (rows[1:], want))
if tok(sys.argv[2]) == tok(sys.argv[3]) or len(tok(sys.argv[2])) < 16: fail("the tokens are not each participant's own")
PY
cp data/links.csv links1.csv
# Again, and with a participant added: the links sent stay valid.
study "P01, P02, P03"
"$dyad" study links s.yaml --base-url https://study.example.org/dyad > out2 2>&1 || { cat out2; fail "second links"; }
grep -q "links: 3 participants (1 new tokens, 2 kept)" out2 || { cat out2; fail "what the second links said"; }
[ "$(head -3 data/links.csv)" = "$(cat links1.csv)" ] || { diff links1.csv data/links.csv; fail "the links changed"; }
grep -q "^P03,https://study.example.org/dyad/subject?token=" data/links.csv || fail "P03 has no link"
# The graph, given P01's token file as dyad study run gives it, opens the subject's page to P01's link only.
"$dyad" run graph.yaml --set web.token_file=data/P01/web-tokens --set recorder.file=run.mcap --duration 20 > run.out 2> run.err &
pid=$!
wait_port_file web.port $pid 30
link=$(sed -n 's/^P01,https:\/\/study.example.org\/dyad//p' data/links.csv)
other=$(sed -n 's/^P02,https:\/\/study.example.org\/dyad//p' data/links.csv)
ok=$(curl -s -o /dev/null -w '%{http_code}' "http://127.0.0.1:$(cat web.port)$link")
no=$(curl -s -o /dev/null -w '%{http_code}' "http://127.0.0.1:$(cat web.port)$other")
kill -INT $pid; wait $pid || true
[ "$ok" = 200 ] && [ "$no" != 200 ] || fail "P01's link answered $ok, P02's $no on P01's graph (want 200, and a refusal)"
# Refusals, each naming what is wrong, nothing written.
refused() {  # refused WANT ARGS...
  local want=$1; shift
  if "$dyad" study links s.yaml "$@" > bad.out 2>&1; then fail "accepted: $*"; fi
  grep -qF -- "$want" bad.out || { cat bad.out; fail "the refusal of '$*' does not say '$want'"; }
}
refused "http:// only for a loopback host" --base-url http://study.example.org
refused "no query, fragment" --base-url "https://study.example.org/?a=b"
refused "must begin with https://" --base-url study.example.org
chmod 644 data/P02/web-tokens
cp data/links.csv links2.csv
refused "data/P02/web-tokens: holds a participant's tokens and is readable by others: chmod 600 it" --base-url https://other.example.org
cmp -s links2.csv data/links.csv || fail "a refused call changed links.csv"
chmod 600 data/P02/web-tokens
sed -i 's/port_file: web.port}/port_file: web.port, token_file: lab-tokens}/' graph.yaml  # one token file for all
refused "links need the graph's one web component without its own token_file" --base-url https://study.example.org
echo "PASS: links for 3 participants, kept across calls, P01's opens P01's graph only; 5 refusals"
