#!/usr/bin/env bash
# The web token kept private: params.token_file is created 0600 with a new token on the first run
# and read on the next (a bookmarked page keeps working), the token is then never printed, a
# token file others can read is refused; a token written in the graph is redacted from the graph
# the recorder keeps (the MCAP file read raw: the token's bytes are nowhere in it).
#   token_file_test.sh BUILD_DIR WORK_DIR
set -euo pipefail
build=$1
work=$2
node_dir=$(cd "$(dirname "$0")" && pwd)/node
[ -d "$node_dir/node_modules" ] || { echo "SKIP: run tools/setup.sh (npm ci in components/web/test/node)"; exit 77; }
rm -rf "$work"; mkdir -p "$work"; cd "$work"
fail() { echo "FAIL: $*"; exit 1; }
domain=$(( 1 + $$ % 200 ))
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
  for _ in $(seq 100); do [ -s web.port ] && break; sleep 0.1; done
  [ -s web.port ] || { cat "${1%.yaml}.err"; kill $pid; fail "web.port never written"; }
  if [ -n "$2" ]; then
    admitted "ws://127.0.0.1:$(cat web.port)/?token=$2" || fail "the token of the file was refused"
    ! admitted "ws://127.0.0.1:$(cat web.port)/?token=wrong$2" || fail "a wrong token was admitted"
  fi
  wait $pid || { cat "${1%.yaml}.err"; fail "dyad run $1 failed"; }
}

# 1. token_file: created 0600 with a new token, not printed; the second run reads the same one.
graph first.yaml "token_file: keys/web.token"
mkdir -m 700 keys
run_and_probe first.yaml ""
[ -f keys/web.token ] || fail "token_file not created"
[ "$(stat -c %a keys/web.token)" = 600 ] || fail "token_file mode $(stat -c %a keys/web.token), not 600"
token=$(cat keys/web.token)
[[ $token =~ ^[0-9a-f]{32}$ ]] || fail "token_file holds '$token', not a 32-hex token"
grep -q "?token=<the token in $work/keys/web.token>" first.err || { cat first.err; fail "the URLs do not say where the token is"; }
! grep -q "$token" first.err first.out || fail "the token was printed"
cp first.yaml second.yaml
sed -i 's/first.mcap/second.mcap/' second.yaml
run_and_probe second.yaml "$token"
[ "$(cat keys/web.token)" = "$token" ] || fail "the second run changed the token file"

# 2. A token file others can read is refused, naming it.
chmod 644 keys/web.token
if "$build/bin/dyad" run second.yaml --duration 1 > bad.out 2> bad.err; then fail "a 0644 token file was accepted"; fi
grep -q "params.token_file = '$work/keys/web.token': readable by others: chmod 600 it" bad.err || { cat bad.err; fail "no clear error"; }

# 3. A token written in the graph is redacted from the recorded graph.
secret=VeryS3cretTokenValue4217
graph third.yaml "token: $secret"
run_and_probe third.yaml "$secret"
[ -s third.mcap ] || fail "no recording"
! grep -a -q "$secret" third.mcap || fail "the token is in the recording"
grep -a -q "token: <redacted>" third.mcap || fail "the recorded graph does not say the token was redacted"
! grep -q "$secret" third.out third.err || fail "the token was printed"
echo "PASS: token_file private, kept across runs, not printed; a 0644 one refused; a graph's token redacted from the recording"
