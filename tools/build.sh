#!/usr/bin/env bash
# Configures and builds dyad into ./build (Release, 2 jobs: the machines here have 2 cores).
# A failure ends with what went wrong in a few lines and where the whole log is, not CMake's
# pages: configure.log and build.log in build/.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$here/build"
if ! cmake -S "$here" -B "$here/build" -DCMAKE_BUILD_TYPE=Release > "$here/build/configure.log" 2>&1; then
  echo "build: configuring failed. CMake said:" >&2
  grep -A4 "CMake Error" "$here/build/configure.log" | head -30 >&2 || tail -20 "$here/build/configure.log" >&2
  echo "build: the whole log is build/configure.log. A missing package is the usual cause: run bash tools/setup.sh (Debian 12)" >&2
  exit 1
fi
if ! cmake --build "$here/build" -j2 2>&1 | tee "$here/build/build.log"; then
  echo "build: the build failed; its first errors:" >&2
  grep -m5 -E "error:|Error [0-9]+" "$here/build/build.log" >&2 || true
  echo "build: the whole log is build/build.log" >&2
  exit 1
fi
