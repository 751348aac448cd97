#!/usr/bin/env bash
# Sets up, builds and runs the demo experiment (the README's first command).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
bash "$here/tools/setup.sh"
bash "$here/tools/build.sh"
out="$here/out/demo"
mkdir -p "$out"
"$here/build/bin/dyad" validate "$here/configs/demo.yaml"
"$here/build/bin/dyad" run "$here/configs/demo.yaml" --steps 2000 --set "sink.file=$out/received.txt"
echo "demo: received samples written to $out/received.txt ($(wc -l < "$out/received.txt") lines)"
