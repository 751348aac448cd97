#!/usr/bin/env bash
# The subject's page between trials as `dyad study serve` drives it (consent, the Ready button,
# the completion code, refused, ping/pong, a new socket at once after a 1012 close), in Debian's
# Chromium against a node server speaking the front's side (node/subject_online.mjs says what is
# checked).
#   subject_online_test.sh WORK_DIR
set -euo pipefail
work=$1
here=$(cd "$(dirname "$0")" && pwd)
node_dir=$here/node
if [ ! -d "$node_dir/node_modules" ] || [ ! -x /usr/bin/chromium ]; then
  echo "SKIP: needs tools/setup.sh (npm ci in components/web/test/node, Debian chromium)"; exit 77
fi
rm -rf "$work"; mkdir -p "$work"
node "$node_dir/subject_online.mjs" "$here/../pages/subject.html" "$work"
