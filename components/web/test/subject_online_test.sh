#!/usr/bin/env bash
# The subject's page between trials as `dyad study serve` drives it (consent, the Ready button,
# the completion code, refused, ping/pong, a new socket at once after a 1012 close), in Debian's
# Chromium against a node server speaking the front's side (node/subject_online.mjs says what is
# checked).
#   subject_online_test.sh WORK_DIR
set -euo pipefail
work=$1
source "$(dirname "$0")/../../../tests/support/web_test.sh"
require_browser
fresh_dir "$work"
node "$node_dir/subject_online.mjs" "$web_test_repo/components/web/pages/subject.html" "$work"
