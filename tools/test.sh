#!/usr/bin/env bash
# Sets up, builds and runs every test (the README's test command; CI runs it too).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
bash "$here/tools/setup.sh"
bash "$here/tools/build.sh"
cd "$here/build"
ctest --output-on-failure -j2 --timeout 900
