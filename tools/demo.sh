#!/usr/bin/env bash
# Sets up, builds and runs the demo experiment (the README's first command).
#
#   bash tools/demo.sh          the demo: a model dyad trains itself, nothing needed beside the clone
#     1. the analytic 7-primitive data set  -> build/data/analytic         (dyad generate dataset)
#     2. the robot's PV-RNN, study settings -> build/models/demo.dpvrnn    (dyad train, ~20 s on 2 cores)
#     3. the intention observer             -> build/models/demo.dobs      (dyad train-observer)
#   bash tools/demo.sh interactive   the same models; a person steers from the browser
#     (configs/interactive.yaml, wall clock, until Ctrl-C; open the printed /subject address)
#   bash tools/demo.sh macaw    the same experiment with the study's MacawBot from ../shared/data
#     1-2. dyad import-nrl ../shared/data/vcbot/...  -> build/models/macawbot.dpvrnn
#     3.   the observer                              -> build/models/macawbot.dobs
#   then: 4. the experiment (configs/<name>.yaml), 2,000 steps of 100 ms, stepped -> out/<name>/<name>.mcap
#         5. the report (tables, plots)                                          -> out/<name>/report/
# Steps 1-3 are cached by a hash of their inputs: the data set reruns when the dyad binary
# changes, the model when its training config or the data set changes, the observer when the
# model changes. A change to the training code alone retrains nothing: delete the *.key files
# next to the models to force it.
#
# For tests: DEMO_STEPS=N shortens step 4; DEMO_EPOCHS=N shortens both trainings; DEMO_WORK=DIR
# puts data, models and outputs under DIR; DEMO_SKIP_SETUP=1 skips setup and build;
# DEMO_BUILD=DIR runs the dyad of another build folder (the sanitizer build's tests do).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
name="${1:-demo}"
case "$name" in
  demo | macaw | interactive) ;;
  *) echo "usage: bash tools/demo.sh [demo|macaw|interactive]" >&2; exit 2 ;;
esac
if [ "${DEMO_SKIP_SETUP:-0}" != 1 ]; then
  bash "$here/tools/setup.sh"
  bash "$here/tools/build.sh"
fi
cd "$here"
dyad="${DEMO_BUILD:-$here/build}/bin/dyad"
steps="${DEMO_STEPS:-2000}"
work="${DEMO_WORK:-$here/build}"
out="${DEMO_WORK:-$here/out}/$name"
train_sets=() observer_opts=()
if [ -n "${DEMO_EPOCHS:-}" ]; then
  train_sets=(--set "epochs=$DEMO_EPOCHS" --set "log_every=$DEMO_EPOCHS")
  observer_opts=(--epochs "$DEMO_EPOCHS")
fi
mkdir -p "$work/data" "$work/models" "$out"

# cached KEY_FILE KEY CMD...: runs CMD unless KEY_FILE holds KEY (a hash of CMD's inputs).
cached() {
  local key_file=$1 key=$2; shift 2
  if [ -f "$key_file" ] && [ "$(cat "$key_file")" = "$key" ]; then
    echo "demo: $(basename "${key_file%.key}") is up to date (cached)"
    return
  fi
  "$@"
  echo "$key" > "$key_file"
}
hash_of() { { cat "$@"; echo "${DEMO_EPOCHS:-}"; } | sha256sum | cut -d' ' -f1; }

if [ "$name" = demo ] || [ "$name" = interactive ]; then
  dataset="$work/data/analytic"
  model="$work/models/demo.dpvrnn"
  observer="$work/models/demo.dobs"
  cached "$dataset.key" "$(hash_of "$dyad")" "$dyad" generate dataset --out "$dataset"
  cached "$model.key" "$(hash_of configs/train/demo.yaml "$dataset"/*)" \
    "$dyad" train configs/train/demo.yaml --set "dataset=$dataset" --set "output=$model" "${train_sets[@]}"
else
  vcbot="$(cd "$here/.." && pwd)/shared/data/vcbot"
  if [ ! -d "$vcbot/model/MacawBot" ]; then
    echo "demo: the macaw experiment needs the study's data in $vcbot (not found)" >&2
    exit 2
  fi
  dataset="$vcbot/dataset/Macaw"
  model="$work/models/macawbot.dpvrnn"
  observer="$work/models/macawbot.dobs"
  cached "$model.key" "$(hash_of "$vcbot"/model/MacawBot/*_p.d "$dataset"/*)" \
    "$dyad" import-nrl "$vcbot/model/MacawBot" --properties "$vcbot/config/properties_MacawBot.d" \
    --dataset "$dataset" -o "$model"
fi
cached "$observer.key" "$(hash_of "$model")" "$dyad" train-observer "$model" -o "$observer" "${observer_opts[@]}"

graph="configs/$name.yaml"
if [ "$name" = interactive ]; then
  rec="$out/interactive-$(date +%Y%m%d-%H%M%S).mcap"
  sets=(--set "web.dataset=$dataset" --set "mind.model=$model" --set "observer.model=$observer" --set "recorder.file=$rec")
  "$dyad" validate "$graph" "${sets[@]}"
  echo "demo: a person steers: open the subject's page at the address printed below ('web: subject's page:"
  echo "demo: http://127.0.0.1:8765/subject?token=...'; hold the mouse button or Space), the experimenter's page or"
  echo "demo: Foxglove at the addresses beside it (each link carries its role's token); Ctrl-C ends the session"
  "$dyad" run "$graph" "${sets[@]}" ${DEMO_DURATION:+--duration "$DEMO_DURATION"} || true
  "$dyad" analyze "$rec" -o "$out/report-$(basename "${rec%.mcap}")" --dataset "$dataset"
  echo "demo: recording $rec"
  exit 0
fi
sets=(--set "human.dataset=$dataset" --set "mind.model=$model" --set "observer.model=$observer"
      --set "recorder.file=$out/$name.mcap" --set recorder.overwrite=true)  # the demo replaces its own recording
"$dyad" validate "$graph" "${sets[@]}"
start=$(date +%s%N)
"$dyad" run "$graph" --steps "$steps" "${sets[@]}"
ms=$(( ($(date +%s%N) - start) / 1000000 ))
echo "demo: $steps steps of 100 ms ran in $((ms / 1000)).$(printf %03d $((ms % 1000))) s wall time (stepped clock)"
"$dyad" analyze "$out/$name.mcap" -o "$out/report" --dataset "$dataset"
echo "demo: recording $out/$name.mcap"
echo "demo: report    $out/report/report.md (plots: $out/report/*.png)"
