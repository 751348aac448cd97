#!/usr/bin/env bash
# From the last demonstration to the new model steering, with the demo's model settings
# (configs/train/demo.yaml: Low 40 d / 4 z, High 10 d / 1 z, two loops), in Chromium: a person's
# three shapes drawn on the subject's page, all learnt with the learner's epochs of
# configs/interactive.yaml (10,000), swapped into the running deliberator. Prints the test's
# PASS line with the times (the page's and the learner's own), the training's time (one thread,
# nice 10, beside the graph and the browser) and the deliberator's deadline misses meanwhile.
#   bash bench/learn/bench_learn.sh [BUILD_DIR]   (default build; needs tools/setup.sh's Chromium)
set -euo pipefail
here=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$here/build}
LEARN_CONFIG=$here/configs/train/demo.yaml LEARN_EPOCHS=10000 LEARN_CHOICE=all \
  bash "$here/components/web/test/learn_test.sh" "$build" "$build/bench_learn"
grep -h -e "trained in" -e "mind: .* deadline misses" "$build/bench_learn/run.err" | sed 's/^/bench_learn: /'
