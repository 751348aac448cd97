#!/usr/bin/env bash
# The subject page's keepalive rule (pages/subject.html) and sim_participant.mjs's copy of it, on
# the test's own clock (node/keepalive.mjs): no server, no browser, under a second.
#   keepalive_test.sh
set -euo pipefail
source "$(dirname "$0")/../../../tests/support/web_test.sh"
require_node
cd "$node_dir"
node --test keepalive.mjs
