# tests/support/web_test.sh: what the web and study test scripts share (source it; bash, set -e).
# They run a graph with a web component and drive its pages from node (components/web/test/node:
# `ws`, playwright-core over Debian's chromium). Each function says what it does when it cannot:
#   require_node           exit 77 (ctest's SKIP) unless tools/setup.sh installed the node modules
#   require_browser        the same, and Debian's chromium
#   fail MESSAGE...        "FAIL: MESSAGE" on stderr, exit 1
#   fresh_dir DIR          DIR emptied (made) and entered
#   test_domain            this test's DDS domain id, held while it runs (dds_domain.sh: tests
#                          running at once never share one)
#   wait_port_file FILE PID [SECONDS [LOG]]
#                          waits until FILE (a port_file) is written, by default 10 s; if not,
#                          shows LOG (default run.err), stops PID and fails naming FILE
#   stop_started           kills what the script started into pids (pids+=($!)): `trap stop_started EXIT`
#   free_port              a loopback TCP port free now (for a server the test places, e.g. HAProxy's)
#   subject_graph FILE [WEB_PARAMS]
#                          the smallest graph a subject steers (web on port 0 with WEB_PARAMS,
#                          web_human, a recorder of human/input and experiment/notes), for studies
#   subject_robot          the lines (under components:) of a subject steering a virtual robot:
#                          human (web_human on web/pointer), mind (intention_hold), mixer, robot
#                          (virtual_cartesian, robot/state); for the web component's page tests
# Sets node_dir (the node scripts and their node_modules) and node_modules.
web_test_repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
node_dir=$web_test_repo/components/web/test/node
node_modules=$node_dir/node_modules

fail() { echo "FAIL: $*" >&2; exit 1; }

require_node() {
  [ -d "$node_modules" ] || { echo "SKIP: needs tools/setup.sh (npm ci in components/web/test/node)"; exit 77; }
}

require_browser() {
  if [ ! -d "$node_modules" ] || [ ! -x /usr/bin/chromium ]; then
    echo "SKIP: needs tools/setup.sh (npm ci in components/web/test/node, Debian chromium)"; exit 77
  fi
}

fresh_dir() { rm -rf "$1"; mkdir -p "$1"; cd "$1"; }

source "$web_test_repo/tests/support/dds_domain.sh"
claim_test_domains 1 web_test_domain
test_domain() { echo "$web_test_domain"; }

wait_port_file() {
  local file=$1 pid=$2 seconds=${3:-10} log=${4:-run.err}
  for _ in $(seq $(( seconds * 10 ))); do [ -s "$file" ] && return 0; sleep 0.1; done
  [ -f "$log" ] && cat "$log" >&2
  kill "$pid" 2> /dev/null || true
  fail "$file never written (${seconds} s)"
}

pids=()
stop_started() { for p in "${pids[@]}"; do kill "$p" 2> /dev/null || true; done; wait 2> /dev/null || true; }

free_port() { python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'; }

subject_graph() {
  local web_params=${2:+, $2}
  cat > "$1" <<YAML
graph: g
clock: wall
domain_id: $(test_domain)
topics:
  web/pointer: {type: HumanInput, reliability: reliable, depth: 8}
  experiment/notes: {type: Annotation, depth: 8}
components:
  web: {type: web, rate_hz: 30, params: {port: 0$web_params}, outputs: {pointer: web/pointer, notes: experiment/notes}}
  human: {type: web_human, rate_hz: 20, inputs: {pointer: web/pointer}, outputs: {input: human/input}}
  recorder: {type: recorder, rate_hz: 10, params: {topics: [human/input, experiment/notes]}}
YAML
}

subject_robot() {
  cat <<'YAML'
  human: {type: web_human, rate_hz: 10, inputs: {pointer: web/pointer}, outputs: {input: human/input}}
  mind: {type: intention_hold, rate_hz: 10, outputs: {intention: robot/intention}}
  mixer: {type: compliance_mixer, trigger: robot, params: {gain: 0.9, max_step: 5}, inputs: {human: human/input, robot: robot/intention}, outputs: {command: robot/command}}
  robot: {type: virtual_cartesian, trigger: command, inputs: {command: robot/command}, outputs: {state: robot/state}}
YAML
}
