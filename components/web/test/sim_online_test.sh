#!/usr/bin/env bash
# sim_participant.mjs --online (the clients of dyad study serve's tests and capacity bench)
# against node/online_front.mjs, a stand-in for the front: three headless participants and one
# in the real page in Chromium go through consent, two trials each started with Ready, and done;
# a fourth headless one is refused; a fifth loses its connection 1 s into its first trial (no close
# frame) and is back 1 s later, in the same trial. Each must end with its code (or the refusal),
# have started both trials (a return is no new trial), answered every ping with its id, and sent
# pointer samples only during trials, some of them engaged (it drew).
#   sim_online_test.sh WORK_DIR
set -euo pipefail
work=$1
source "$(dirname "$0")/../../../tests/support/web_test.sh"
require_browser
fresh_dir "$work"
node "$node_dir/online_front.mjs" "$web_test_repo/components/web/pages/subject.html" front.port 2 3000 > front.json 2> front.err &
front=$!
trap 'kill $front 2> /dev/null || true' EXIT
wait_port_file front.port $front 10 front.err
url=http://127.0.0.1:$(cat front.port)
printf "%s chromium-one-token\n%s sim-two-token\n%s sim-three-token\n%s sim-four-token\n%s refused-five-token\n%s sim-six-token drop:1:1\n" \
  "$url" "$url" "$url" "$url" "$url" "$url" > sessions
node "$node_dir/sim_participant.mjs" --online --chromium 1 --speed 2 --seconds 60 sessions > clients.json || fail "the clients"
kill -TERM $front; wait $front || true
python3 - clients.json front.json <<'PY'
import json, sys
def fail(why): sys.exit("FAIL: " + why)
clients = [json.loads(l) for l in open(sys.argv[1]) if l.strip()][:-1]
front = {p["token"]: p for p in (json.loads(l) for l in open(sys.argv[2]) if l.strip())}
tokens = ["chromium-one-token", "sim-two-token", "sim-three-token", "sim-four-token", "refused-five-token", "sim-six-token"]
if len(clients) != 6: fail("%d client lines" % len(clients))
for token, c in zip(tokens, clients):
    f = front.get(token)
    if f is None: fail(token + ": never reached the front")
    if token.startswith("refused"):
        if c["refused"] != "This link is already open in another window." or c["code"] is not None: fail(token + ": %s" % c)
        if f["in_trial"] or f["between"]: fail(token + ": pointer samples after the refusal: %s" % f)
        continue
    if c["code"] != "CODE-" + token or c["refused"] is not None: fail(token + ": ended with %s" % c)
    if c["trials"] != 2 or f["trials"] != 2 or not f["done"]: fail(token + ": trials %s (client), %s (front)" % (c["trials"], f["trials"]))
    if f["pongs"] < 4 or f["bad_pongs"]: fail(token + ": %d pongs, %d not answering a ping" % (f["pongs"], f["bad_pongs"]))
    if c["errors"]: fail(token + ": errors %s" % c["errors"])
    if f["engaged"] < 10: fail(token + ": %d engaged pointer samples in its trials (it should draw)" % f["engaged"])
    # The headless client draws only in trials; the page may send a sample between them (a mouse
    # moving over it), but the Chromium participant's mouse rests then too.
    if f["between"]: fail(token + ": %d pointer samples between trials" % f["between"])
    lost = token == "sim-six-token"
    if (c.get("dropped") is not None) != lost or f["returns"] != int(lost): fail(token + ": dropped %s, came back %d times in a trial" % (c.get("dropped"), f["returns"]))
    # Measured at the front: from its socket's close event (a few ms after the client's end).
    if lost and not 900 <= f["away_ms"] <= 2000: fail(token + ": away %d ms (drop:1:1)" % f["away_ms"])
print("PASS: " + "; ".join("%s: %d trials, code %s, %d samples in trials (%d engaged), %d pongs"
                           % (t, front[t]["trials"], c["code"], front[t]["in_trial"], front[t]["engaged"], front[t]["pongs"])
                           for t, c in zip(tokens[:4], clients)) + "; sim-six-token away %d ms" % front["sim-six-token"]["away_ms"])
PY
