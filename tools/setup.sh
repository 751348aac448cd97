#!/usr/bin/env bash
# Installs what dyad needs on Debian 12 (as root, or with sudo). Idempotent; a second run that
# finds everything installed does nothing and takes well under a second.
#   bash tools/setup.sh            what building and testing need
#   bash tools/setup.sh sanitize   also clang 14 with its sanitizer and libFuzzer runtimes and
#                                  llvm-symbolizer (tools/check.sh, tools/fuzz.sh)
set -euo pipefail
packages=(
  build-essential cmake git pkg-config
  libfastrtps-dev libfastcdr-dev fastddsgen fastdds-tools default-jre-headless
  libeigen3-dev libceres-dev libyaml-cpp-dev libcli11-dev nlohmann-json3-dev libzstd-dev
  libgtest-dev libgmock-dev libbenchmark-dev libcivetweb-dev libssl-dev openssl
  python3 python3-matplotlib chromium libnss3-tools universal-ctags
  iproute2 nftables procps
  gdb  # the stacks of a process a test finds hung (tests' ChildProcess::Stacks, multihost_test.sh)
  slurm-wlm munge  # `dyad sweep --slurm` tested against a single-node Slurm (tools/sweep/test)
  graphviz  # `dyad graph --svg`
  haproxy  # two `dyad study serve` instances behind one address (tools/study/test/serve_haproxy_test.sh)
  clang-format-14  # tools/format_check.sh (.clang-format on changed lines, first in .ci/run)
  cyclonedds-dev cyclonedds-tools  # the fake ROS 2 arm and wire peer (tests/ros2), as rmw_cyclonedds speaks
)
if [ "${1:-}" = "sanitize" ]; then
  packages+=(clang-14 libclang-rt-14-dev llvm-14)
fi
# Node.js may come from elsewhere (with its own npm): only ask Debian when the command is missing.
command -v node > /dev/null || packages+=(nodejs)
command -v npm > /dev/null || packages+=(npm)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  sudo_cmd=""
  [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $sudo_cmd apt-get update -qq
  $sudo_cmd apt-get install -y -qq --no-install-recommends "${missing[@]}" > /dev/null
fi
# Node packages for the tests that read our files with independent readers.
here=$(cd "$(dirname "$0")/.." && pwd)
for dir in "$here"/components/*/test/node; do
  if [ -f "$dir/package-lock.json" ] && [ ! -d "$dir/node_modules" ]; then
    echo "setup: npm ci in ${dir#$here/}"
    (cd "$dir" && npm ci --no-audit --no-fund --silent)
  fi
done
