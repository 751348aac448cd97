#!/usr/bin/env bash
# The web tokens kept private: params.token_file is created 0600 with a new token per role on
# the first run and read on the next (a bookmarked page keeps working), its tokens are never
# printed, a token file others can read is refused; tokens written in the graph are redacted from
# the graph the recorder keeps (the MCAP file read raw: their bytes are nowhere in it); with no
# token anywhere, even on loopback, tokens are generated, printed and required.
#   token_file_test.sh BUILD_DIR WORK_DIR
set -euo pipefail
build=$1
work=$2
source "$(dirname "$0")/../../../tests/support/web_test.sh"
require_node
fresh_dir "$work"
domain=$(test_domain)
graph() {  # graph NAME WEB_PARAMS
  cat > "$1" <<YAML
graph: tokens
clock: wall
domain_id: $domain
components:
  web: {type: web, rate_hz: 10, params: {port: 0, port_file: web.port, $2}, outputs: {pointer: web/pointer}}
  human: {type: web_human, rate_hz: 10, inputs: {pointer: web/pointer}, outputs: {input: human/input}}
  rec: {type: recorder, rate_hz: 1, params: {file: $work/${1%.yaml}.mcap}}
topics:
  human/input: {type: HumanInput}
YAML
}
# admitted WS_URL: whether a Foxglove client is let in
admitted() {
  (cd "$node_dir" && node -e '
    import("ws").then(({default: WebSocket}) => {
      const ws = new WebSocket(process.argv[1], ["foxglove.websocket.v1"]);
      ws.on("open", () => { ws.close(); process.exit(0); });
      ws.on("error", () => process.exit(1));
      ws.on("unexpected-response", () => process.exit(1));
    });' "$1")
}
run_and_probe() {  # run_and_probe GRAPH TOKEN_OR_EMPTY: runs 4 s; the token (if any) must be admitted
  rm -f web.port
  "$build/bin/dyad" run "$1" --duration 4 > "${1%.yaml}.out" 2> "${1%.yaml}.err" &
  local pid=$!
  wait_port_file web.port $pid 10 "${1%.yaml}.err"
  if [ -n "$2" ]; then
    admitted "ws://127.0.0.1:$(cat web.port)/?token=$2" || fail "the token of the file was refused"
    ! admitted "ws://127.0.0.1:$(cat web.port)/?token=wrong$2" || fail "a wrong token was admitted"
  fi
  wait $pid || { cat "${1%.yaml}.err"; fail "dyad run $1 failed"; }
}

# 1. token_file: created 0600 with a new token per role, not printed; the second run reads them.
graph first.yaml "token_file: keys/web.token"
mkdir -m 700 keys
run_and_probe first.yaml ""
[ -f keys/web.token ] || fail "token_file not created"
[ "$(stat -c %a keys/web.token)" = 600 ] || fail "token_file mode $(stat -c %a keys/web.token), not 600"
[ "$(cut -d' ' -f1 keys/web.token | tr '\n' ' ')" = "experimenter subject viewer " ] || fail "token_file roles: $(cat keys/web.token)"
grep -Evq '^[a-z]+ [0-9a-f]{32}$' keys/web.token && fail "token_file lines are not 'ROLE 32-hex-token': $(cat keys/web.token)"
viewer=$(awk '$1 == "viewer" {print $2}' keys/web.token)
grep -q "/subject?token=<the subject's token in $work/keys/web.token>" first.err || { cat first.err; fail "the URLs do not say where the token is"; }
for t in $(cut -d' ' -f2 keys/web.token); do ! grep -q "$t" first.err first.out || fail "a token was printed"; done
cp first.yaml second.yaml
sed -i 's/first.mcap/second.mcap/' second.yaml
run_and_probe second.yaml "$viewer"
[ "$(awk '$1 == "viewer" {print $2}' keys/web.token)" = "$viewer" ] || fail "the second run changed the token file"

# 2. A token file others can read is refused, naming it; so is one of the old one-token format.
chmod 644 keys/web.token
if "$build/bin/dyad" run second.yaml --duration 1 > bad.out 2> bad.err; then fail "a 0644 token file was accepted"; fi
grep -q "params.token_file = '$work/keys/web.token': readable by others: chmod 600 it" bad.err || { cat bad.err; fail "no clear error"; }
echo 0123456789abcdef0123456789abcdef > keys/web.token
chmod 600 keys/web.token
if "$build/bin/dyad" run second.yaml --duration 1 > old.out 2> old.err; then fail "a one-token file was accepted"; fi
grep -q "params.token_file = '$work/keys/web.token' line 1: expected 'experimenter TOKEN'" old.err || { cat old.err; fail "no clear error for the old format"; }

# 3. Tokens written in the graph are redacted from the recorded graph.
secret=VeryS3cretTokenValue4217
graph third.yaml "token: $secret, subject_token: ${secret}s, viewer_token: ${secret}v"
run_and_probe third.yaml "${secret}v"
[ -s third.mcap ] || fail "no recording"
! grep -a -q "$secret" third.mcap || fail "a token is in the recording"
grep -a -q "subject_token: <redacted>" third.mcap || fail "the recorded graph does not say the token was redacted"
! grep -q "$secret" third.out third.err || fail "a token was printed"

# 4. No token anywhere, on loopback: tokens are generated and printed (nobody could use them
# otherwise), and a client without one is refused.
graph fourth.yaml "max_clients: 8"
rm -f web.port
"$build/bin/dyad" run fourth.yaml --duration 4 > fourth.out 2> fourth.err &
pid=$!
for _ in $(seq 100); do [ -s web.port ] && break; sleep 0.1; done
sleep 0.5
printed=$(grep -o '/?token=[0-9a-f]\{32\} (viewer)' fourth.err | head -1 | cut -c9-40)
[ -n "$printed" ] || { cat fourth.err; kill $pid; fail "no generated viewer token printed"; }
admitted "ws://127.0.0.1:$(cat web.port)/?token=$printed" || fail "the printed token was refused"
! admitted "ws://127.0.0.1:$(cat web.port)/" || fail "a client without a token was admitted on loopback"
wait $pid || fail "dyad run fourth.yaml failed"
echo "PASS: token_file private, per role, kept across runs, not printed; a 0644 or old one refused; tokens redacted from the recording; none given: generated, printed, required"
