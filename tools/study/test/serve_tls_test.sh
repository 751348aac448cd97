#!/usr/bin/env bash
# `dyad study serve` over TLS (#45 item 1; docs/study.md, "A study online", TLS): the lab's
# certificate from `dyad security init --web-host 127.0.0.1` on the study's graph, served on
# 127.0.0.1 with --tls-certificate. Checked:
#   - one participant in Chromium that trusts the web CA (its NSS database, as a lab's or a
#     participant's browser once told to) opens its https link, consents, does its two trials
#     (the page's socket wss:// to the front, the front's relay to each trial's graph plain ws on
#     loopback) and gets the completion code; both trials complete in its session log;
#   - another participant's link at its own host (DATA/links.csv: https://study.test:PORT, a
#     name the certificate has, Chromium resolving it to 127.0.0.1) opens the consent page: the
#     front admits the links' origin for the page's WebSocket without --origin (before, only its
#     listen address's: the page waited forever, its socket closed before the handshake);
#   - Chromium without the web CA is refused the certificate; plain http to the port gets no page;
#   - the certificate refused before anything listens (exit 2, naming --tls-certificate): a PEM
#     without the private key (web/cert.pem), one readable by others, a key of another
#     certificate; one that does not name the links' host: a warning naming it.
#   serve_tls_test.sh REPO BUILD_DIR WORK_DIR
set -euo pipefail
repo=$1 build=$2 work=$3
source "$repo/tests/support/web_test.sh"
require_browser
command -v certutil > /dev/null || { echo "SKIP: needs tools/setup.sh (libnss3-tools)"; exit 77; }
dyad=$build/bin/dyad
fresh_dir "$work"
ln -s "$node_modules" node_modules  # serve_tls.mjs imports playwright-core from beside itself
cp "$repo/tools/study/test/serve_tls.mjs" .
trap stop_started EXIT

subject_graph g.yaml
echo "You agree to take part in a test." > consent.txt
cat > s.yaml <<YAML
study: tls_test
graph: g.yaml
data: sdata
participants: [P01, P02]
conditions:
  low: {human.engage_timeout_s: 0.3}
  high: {human.engage_timeout_s: 0.4}
duration: 3
online: {consent: consent.txt, reconnect_s: 10}
YAML
"$dyad" security init keys --graph g.yaml --web-host 127.0.0.1 --web-host study.test > init.out
port=$(free_port)
"$dyad" study links s.yaml --base-url "https://study.test:$port" > links.out

# What the certificate must be, told before anything listens.
refused() {  # refused PEM MESSAGE
  if "$dyad" study serve s.yaml --port 0 --tls-certificate "$1" > refused.out 2>&1; then fail "$1 served"; fi
  grep -qF "dyad study serve: --tls-certificate '$1': $2" refused.out || { cat refused.out; fail "$1: not '$2'"; }
}
refused keys/web/cert.pem "no private key in it"
cp -p keys/web/tls.pem leaky.pem && chmod 644 leaky.pem
refused leaky.pem "holds the private key and is readable by others: chmod 600 it"
"$dyad" security init other --graph g.yaml --web-host 127.0.0.1 > /dev/null  # names 127.0.0.1 only
(sed -n '/BEGIN PRIVATE KEY/,/END PRIVATE KEY/p' keys/web/tls.pem && cat other/web/cert.pem) > mixed.pem && chmod 600 mixed.pem
refused mixed.pem "its private key is not its certificate's"
"$dyad" study serve s.yaml --port 0 --tls-certificate other/web/tls.pem > other.out 2>&1 &
other=$!
for _ in $(seq 50); do grep -q "^TLS: " other.out && break; sleep 0.1; done
kill -TERM $other && wait $other || true
grep -qF "warning: $work/sdata/links.csv has links to https://study.test:$port, which the certificate does not name" other.out ||
  { cat other.out; fail "no warning for links to a host the certificate does not name"; }
token=$(sed -n 's|^P01,.*token=||p' sdata/links.csv) token2=$(sed -n 's|^P02,.*token=||p' sdata/links.csv)
[ -n "$token" ] && [ -n "$token2" ] || fail "no links: $(cat sdata/links.csv)"

# The participant's browser trusts the web CA: Chromium reads trust from the user's NSS database.
export HOME=$work/home
mkdir -p "$HOME/.pki/nssdb"
certutil -d "sql:$HOME/.pki/nssdb" -N --empty-password
certutil -d "sql:$HOME/.pki/nssdb" -A -t "C,," -n "dyad web CA" -i keys/web_ca.cert.pem
"$dyad" study serve s.yaml --port "$port" --port-file port --tls-certificate keys/web/tls.pem > serve.out 2> serve.err &
pid=$!
pids+=($pid)
wait_port_file port $pid 10 serve.err
grep -q "dyad study serve: tls_test at https://127.0.0.1:$port/subject?token=" serve.out || { cat serve.out; fail "the printed link is not https"; }
grep -q "^TLS: keys/web/tls.pem, a certificate for IP:127.0.0.1, DNS:study.test, valid until " serve.out || { cat serve.out; fail "the certificate's names"; }
! grep -q "^warning" serve.out || { cat serve.out; fail "a warning"; }
echo "https://127.0.0.1:$port $token" > sessions
node "$node_dir/sim_participant.mjs" --online --chromium 1 --speed 3 --seconds 40 sessions > clients.out 2> clients.err ||
  { cat clients.err serve.out serve.err; fail "the Chromium participant over https"; }
head -1 clients.out | grep -Eq '"acks":[1-9][0-9]*,.*"trials":2,"code":"[^"]' ||
  { cat clients.out serve.out serve.err; fail "no pointer sample acknowledged, or no completion code after two trials"; }
ends=$(grep -c '"event":"end".*"outcome":"complete"' sdata/P01/session.log || true)
[ "$ends" = 2 ] || { cat sdata/P01/session.log; fail "$ends of 2 trials complete"; }
node serve_tls.mjs "$port" "$token2" "$work/untrusted_home" || { cat serve.err; fail "serve_tls.mjs"; }
kill -0 $pid || fail "dyad study serve died: $(cat serve.err)"
kill -TERM $pid
wait $pid || fail "dyad study serve exited $?: $(cat serve.err)"
echo PASS
