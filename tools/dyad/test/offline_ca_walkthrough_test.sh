#!/usr/bin/env bash
# docs/security.md's walk-through "Admitting a new machine with the CA on a USB key", run as
# written (the sh block after its marker), then what it promises checked from outside: the CA
# keys are off the keystore, the new host's identity verifies against the identity CA (openssl),
# an init with nothing to issue made no empty ca/, each machine's export holds its identities
# only and no CA key, and without --ca the same step is refused
# naming the key file and --ca, leaving nothing half made; a restored `mv` is not nested.
#   offline_ca_walkthrough_test.sh SOURCE_DIR BUILD_DIR
set -euo pipefail
src=$1
build=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export PATH="$build/bin:$PATH"
fail() { echo "FAIL: $*" >&2; exit 1; }

block=$(awk '/run by tools\/dyad\/test\/offline_ca_walkthrough_test.sh/ {m=1; next}
             m && /^```sh/ {on=1; next} on && /^```/ {exit} on {print}' "$src/docs/security.md")
[ -n "$block" ] || fail "the walk-through's block is not in docs/security.md"

graph() {  # graph FILE HOST...: one process per host, each writing a topic of its own
  local file=$1; shift
  {
    echo "graph: lab"
    echo "network:"
    echo "  hosts:"
    local i=1
    for h in "$@"; do echo "    $h: 10.77.0.$i"; i=$((i + 1)); done
    echo "processes:"
    for h in "$@"; do echo "  p_$h: {host: $h}"; done
    echo "components:"
    for h in "$@"; do echo "  c_$h: {type: counter_source, rate_hz: 10, process: p_$h, outputs: {out: t_$h}}"; done
  } > "$file"
}
cd "$work"
graph lab.yaml lab mind
graph lab-new.yaml lab mind rec
graph lab-newer.yaml lab mind rec arm
export USB=$work/usb
mkdir -p "$USB"

echo "--- the walk-through, as written"
echo "$block"
bash -euo pipefail -c "$block" > walk.out 2>&1 || { cat walk.out; fail "the walk-through failed"; }
cat walk.out
[ ! -e keys/lab/ca ] || fail "keys/lab/ca exists after the walk-through: an init made an empty CA folder"
[ -f "$USB/lab-ca/identity_ca.key.pem" ] || fail "the CA keys are not on the USB key"
for id in host.rec process.p_rec; do
  [ -f "keys/lab/identities/$id/cert.pem" ] && [ -f "keys/lab/identities/$id/key.pem" ] || fail "identity $id not issued"
  openssl verify -CAfile keys/lab/identity_ca.cert.pem "keys/lab/identities/$id/cert.pem" > /dev/null ||
    fail "$id's certificate does not verify against the identity CA"
done
! ls -a keys/lab/identities | grep -q '\.new-' || fail "a staging folder was left in keys/lab/identities"

echo "--- each machine's export holds its identities only, and no CA key"
[ "$(ls keys_lab/identities | tr '\n' ' ')" = "host.lab process.p_lab " ] || fail "keys_lab holds $(ls keys_lab/identities)"
[ "$(ls keys_rec/identities | tr '\n' ' ')" = "host.rec process.p_rec " ] || fail "keys_rec holds $(ls keys_rec/identities)"
! find keys_lab keys_rec -name '*.key.pem' | grep -q . || fail "an export holds a CA key"
grep -q "^host: rec$" keys_rec/subset.yaml || fail "keys_rec/subset.yaml does not say host: rec"
openssl verify -CAfile keys_rec/identity_ca.cert.pem keys_rec/identities/host.rec/cert.pem > /dev/null ||
  fail "the exported host.rec certificate does not verify against the exported identity CA"

echo "--- without --ca, a new machine is refused and nothing is made"
set +e
dyad security init keys/lab --graph lab-newer.yaml > refused.out 2> refused.err
code=$?
set -e
cat refused.err
[ "$code" = 1 ] || fail "exit $code, expected 1"
grep -q "keys/lab/ca/identity_ca.key.pem: the identity CA's key is not here" refused.err || fail "the key file is not named"
grep -q -- "--ca DIR" refused.err || fail "--ca is not named"
[ ! -e keys/lab/identities/host.arm ] || fail "a refused init left keys/lab/identities/host.arm"
[ ! -e keys/lab/ca ] || fail "a refused init made keys/lab/ca"

echo "--- the folder brought back with mv is found where it belongs"
mv "$USB/lab-ca" keys/lab/ca
dyad security init keys/lab --graph lab-newer.yaml > restored.out 2>&1 || { cat restored.out; fail "init after mv back failed"; }
grep -q "issued   host.arm" restored.out || { cat restored.out; fail "host.arm not issued"; }

echo "--- a keystore with an empty ca/ (older dyad) into which the folder was moved is told where its keys are"
mv keys/lab/ca "$USB/lab-ca" && mkdir -m 700 keys/lab/ca && mv "$USB/lab-ca" keys/lab/ca/lab-ca
graph lab-newest.yaml lab mind rec arm cam
set +e
dyad security init keys/lab --graph lab-newest.yaml 2> nested.err > /dev/null
set -e
grep -q "it is at keys/lab/ca/lab-ca/identity_ca.key.pem" nested.err || { cat nested.err; fail "the nested key is not pointed to"; }
echo "offline CA walk-through: 1 passed, 0 failed"
