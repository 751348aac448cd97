#!/usr/bin/env bash
# `dyad sweep --slurm` through a real Slurm (one node, started here: single_node_slurm.sh): a
# 12-run sweep of the demo (the PV-RNN mind, the mixer, the observer) over two meta-priors the
# sweep trains models for: a training array job, the runs' array of 5 tasks after it, and a
# collect job give the same sweep.csv, byte for byte, as the same sweep run locally; a cluster
# that is down is said in sbatch's words. Skips (77) with the reason when Slurm cannot start.
#   slurm_sweep_test.sh REPO BUILD_DIR WORK_DIR
set -euo pipefail
repo=$1 build=$2 work=$3
dyad=$build/bin/dyad
here=$(cd "$(dirname "$0")" && pwd)
fail() { echo "FAIL: $*" >&2; exit 1; }
rm -rf "$work"; mkdir -p "$work"; cd "$work"
trap 'bash "$here/single_node_slurm.sh" stop "$work/slurm"' EXIT
eval "$(bash "$here/single_node_slurm.sh" start "$work/slurm")"
echo "Slurm up: $(sinfo -h -o '%P %D %c %t')"

bash "$here/demo_models.sh" "$repo" "$dyad" "$work"
cat > s.yaml <<YAML
sweep: slurm_test
graph: $repo/configs/demo.yaml
duration: 40
set: {human.dataset: $work/data, observer.model: $work/demo.dobs}
train:
  config: $repo/configs/train/demo.yaml
  set: {dataset: $work/data, epochs: 200, log_every: 100}
  grid: {layers.0.w: [0.001, 0.01]}
grid:
  mixer.gain: [0.3, 0.6, 0.9]
seeds: [1, 2]
YAML
"$dyad" sweep s.yaml -o local -j 2 --no-plots > local.log || { cat local.log; fail "the local sweep"; }

"$dyad" sweep s.yaml -o cluster --slurm --tasks 5 --cpus-per-task 1 --time 0:10:00 > submit.log ||
  { cat submit.log; fail "dyad sweep --slurm"; }
cat submit.log
# The collect job writes sweep.csv (by rename: whole) once every array task has ended.
for _ in $(seq 600); do [ -f cluster/sweep.csv ] && break; sleep 0.5; done
[ -f cluster/sweep.csv ] || { squeue; tail -n 20 cluster/slurm/*.log; fail "no sweep.csv from the collect job in 300 s"; }
grep -q "12 ok, 0 failed, 0 missing" cluster/slurm/collect.log || { cat cluster/slurm/collect.log; fail "collect"; }
[ "$(ls cluster/slurm/task-*.log | wc -l)" = 5 ] || fail "want 5 array tasks' logs: $(ls cluster/slurm)"
[ "$(ls cluster/slurm/train-*.log | wc -l)" = 2 ] || fail "want 2 training tasks' logs: $(ls cluster/slurm)"
grep -q "trains 2 models" submit.log || fail "no training job was submitted"
for m in local/models/*.dpvrnn; do
  cmp "$m" "cluster/models/$(basename "$m")" || fail "the cluster's model $(basename "$m") differs from the local one"
done
cmp local/sweep.csv cluster/sweep.csv || fail "Slurm's table differs from the local one: $(diff local/sweep.csv cluster/sweep.csv)"
awk -F, 'NR > 1 && ($2 != "ok" || $8 == "") { bad = 1 } END { exit bad }' cluster/sweep.csv ||
  fail "a run without a congruence: $(cat cluster/sweep.csv)"

# The controller down: sbatch's own words, exit 1, nothing claimed. Stopped, nothing of this
# Slurm is left (no daemon, no job step's slurmstepd, no job's process).
bash "$here/single_node_slurm.sh" stop "$work/slurm"
left=$(bash "$here/single_node_slurm.sh" leftovers "$work/slurm")
[ -z "$left" ] || fail "still running after the single-node Slurm stopped: $(ps -o pid,args -p "$(echo $left | tr ' ' ,)")"
if "$dyad" sweep s.yaml -o down --slurm > down.log 2>&1; then fail "submitted to a stopped Slurm: $(cat down.log)"; fi
grep -q "Unable to contact slurm controller" down.log || { cat down.log; fail "the stopped controller was not said"; }
echo "PASS: 2 models trained by a Slurm array, 12 runs in 5 array tasks after it, collected = the local sweep.csv; a stopped controller is said"
