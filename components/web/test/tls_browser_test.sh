#!/usr/bin/env bash
# The web component over TLS, in Debian's Chromium: `dyad security init --web-host` makes the
# certificate, the graph serves HTTPS and WSS with it; a browser that trusts the web CA (in its
# NSS database, as a lab machine would) opens the subject's page and steers over WSS; a browser
# that does not trust it refuses the page, and plain HTTP on the port gets no page (so the check
# can fail). components/web/test/node/tls_page.mjs does the browsing.
#   tls_browser_test.sh BUILD_DIR WORK_DIR
set -euo pipefail
build=$1
work=$2
source "$(dirname "$0")/../../../tests/support/web_test.sh"
require_browser
command -v certutil > /dev/null || { echo "SKIP: needs tools/setup.sh (libnss3-tools)"; exit 77; }
fresh_dir "$work"
cat > graph.yaml <<YAML
graph: tls_browser
clock: wall
domain_id: $(test_domain)
topics:
  web/pointer: {type: HumanInput, reliability: reliable, depth: 8}
components:
  web: {type: web, rate_hz: 30, params: {port: 0, port_file: web.port, tls_certificate: keys/web/tls.pem,
        token: experimenter-token-0001, subject_token: subject-token-000001, viewer_token: viewer-token-0000001},
        outputs: {pointer: web/pointer}}
  human: {type: web_human, rate_hz: 10, inputs: {pointer: web/pointer}, outputs: {input: human/input}}
  recorder: {type: recorder, rate_hz: 10, params: {file: rec.mcap, topics: [web/pointer]}}
YAML
"$build/bin/dyad" security init keys --graph graph.yaml --web-host 127.0.0.1 > init.out
# Off loopback without a certificate, or with one others can read: refused at validation, naming the key.
sed 's/port: 0, port_file: web.port, tls_certificate: keys\/web\/tls.pem,/port: 0, address: 0.0.0.0,/' graph.yaml > open.yaml
if "$build/bin/dyad" validate open.yaml > open.out 2>&1; then echo "FAIL: 0.0.0.0 without TLS validated"; exit 1; fi
grep -q "params.address = '0.0.0.0': off loopback .* give params.tls_certificate" open.out || { cat open.out; echo "FAIL: no clear error"; exit 1; }
cp -p keys/web/tls.pem leaky.pem && chmod 644 leaky.pem
sed 's/tls_certificate: keys\/web\/tls.pem/tls_certificate: leaky.pem/' graph.yaml > leaky.yaml
if "$build/bin/dyad" validate leaky.yaml > leaky.out 2>&1; then echo "FAIL: a 0644 certificate validated"; exit 1; fi
grep -q "params.tls_certificate = '$work/leaky.pem': holds a private key and is readable by others" leaky.out || { cat leaky.out; echo "FAIL: no clear error"; exit 1; }
# The lab machine's browser trusts the web CA: Chromium reads trust from the user's NSS database.
export HOME=$work/home
mkdir -p "$HOME/.pki/nssdb"
certutil -d "sql:$HOME/.pki/nssdb" -N --empty-password
certutil -d "sql:$HOME/.pki/nssdb" -A -t "C,," -n "dyad web CA" -i keys/web_ca.cert.pem
"$build/bin/dyad" run graph.yaml --duration 30 > run.out 2> run.err &
pid=$!
wait_port_file web.port $pid
port=$(cat web.port)
grep -q "subject's page: https://127.0.0.1:$port/subject?token=<params.subject_token>" run.err ||
  { cat run.err; kill $pid; echo "FAIL: the printed URLs are not https"; exit 1; }
status=0
node "$node_dir/tls_page.mjs" "127.0.0.1:$port" subject-token-000001 "$work/untrusted_home" || status=1
kill -INT $pid
wait $pid || true  # interrupted: exits non-zero
# What the page sent over WSS reached the graph.
"$build/bin/dyad" bag info rec.mcap > info.txt 2>&1 || true
grep -Eq "web/pointer +[1-9][0-9]* msgs" info.txt || { cat info.txt; echo "FAIL: no pointer sample recorded"; status=1; }
[ $status -eq 0 ] && echo PASS
exit $status
