#!/usr/bin/env bash
# Configures and builds dyad into ./build (Release, 2 jobs: the machines here have 2 cores).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$here/build"
cmake -S "$here" -B "$here/build" -DCMAKE_BUILD_TYPE=Release > "$here/build/configure.log" 2>&1 || {
  cat "$here/build/configure.log"; exit 1; }
cmake --build "$here/build" -j2
