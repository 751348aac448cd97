#!/usr/bin/env bash
# The demo's data set, a briefly trained model and observer, for the sweep tests: WORK/data,
# WORK/demo.dpvrnn, WORK/demo.dobs (200 epochs each: enough for real, different metrics).
#   bash demo_models.sh REPO DYAD WORK
set -euo pipefail
repo=$1 dyad=$2 work=$3
cd "$work"
"$dyad" generate dataset --out data > /dev/null
"$dyad" train "$repo/configs/train/demo.yaml" --set dataset="$work/data" --set output="$work/demo.dpvrnn" \
  --set epochs=200 --set log_every=200 > train.log
"$dyad" train-observer demo.dpvrnn -o demo.dobs --epochs 200 > observer.log
