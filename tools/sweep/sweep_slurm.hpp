// tools/sweep/sweep_slurm.hpp: a sweep on a Slurm cluster, as an array job of chunks.
//
// The sweep's folder is on a file system every node shares (as on clusters); each array task
// runs its chunk of the plan's runs into it (`dyad sweep SWEEP --task i/N`, every run as on a
// laptop: resumable, a failed run recorded), and a last job merges the table (`--collect`).
//
// Contract of ParseTask: "i/N" with 0 <= i < N (Slurm's SLURM_ARRAY_TASK_ID counts from 0 in
// the array we submit); anything else is an error naming what was given.
// Contract of TaskChunk: chunk i of N of a plan's runs (or trainings), contiguous and in the
// plan's order; the chunks of 0..N-1 hold every item exactly once (sizes differ by at most
// one). It depends only on the plan and N, so a task computes its chunk alone.
// Contract of SubmitToSlurm:
//   - When a model of the sweep's trainings is not in OUT/models yet: OUT/slurm/train.sbatch,
//     an array of `dyad sweep SWEEP --train-only --task i/M` (one training per task), submitted
//     first; the runs' array then waits for it with `--dependency=afterany:TRAIN` (a run whose
//     model failed to train is recorded as failed, saying so, and the table still comes).
//   - Writes OUT/slurm/runs.sbatch (the array: min(tasks, runs) tasks, each `dyad sweep SWEEP
//     --task $SLURM_ARRAY_TASK_ID/N -j $SLURM_CPUS_PER_TASK`) and OUT/slurm/collect.sbatch
//     (`dyad sweep SWEEP --collect`), every path absolute; logs go to OUT/slurm/*.log.
//   - Submits the array with `sbatch --parsable`, then the collect job with
//     `--dependency=afterany:ARRAY` (it runs when every task has ended, however it ended).
//   - `sbatch` not on PATH, or refusing a job (no controller, a bad partition), is an error
//     with sbatch's own words; nothing is half-submitted silently (the array's id is said when
//     only the collect job was refused).
//   - Runs finished before are skipped by their task, so resubmitting after a lost task runs
//     only what is missing.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "dyad/status.hpp"
#include "sweep_plan.hpp"

namespace dyad::sweep {

struct TaskSlice {
  int index = 0, count = 1;
};

Status ParseTask(const std::string& text, TaskSlice* task);
template <class T>
std::vector<T> TaskChunk(const std::vector<T>& all, TaskSlice task) {
  const size_t n = all.size(), count = static_cast<size_t>(task.count), i = static_cast<size_t>(task.index);
  return {all.begin() + static_cast<std::ptrdiff_t>(n * i / count), all.begin() + static_cast<std::ptrdiff_t>(n * (i + 1) / count)};
}

struct SlurmOptions {
  std::string partition, time;           // sbatch --partition, --time (empty: the cluster's default)
  int tasks = 0;                         // array tasks (0: one per run, at most 100)
  int cpus_per_task = 1;                 // each task runs this many runs at once
  std::vector<std::string> sbatch_args;  // more #SBATCH lines (--account=..., --mem=...)
};

struct SlurmJob {
  std::string train_id;  // empty: every model was there
  std::string array_id, collect_id;
  int train_tasks = 0, tasks = 0;
};

// `sweep_file` and `out` absolute; `dyad` the executable the jobs run; `plugins` and `plots`
// passed on to them.
StatusOr<SlurmJob> SubmitToSlurm(const SweepPlan& plan, const std::string& sweep_file, const std::string& out,
                                 const std::string& dyad, const std::vector<std::string>& plugins, bool plots,
                                 const SlurmOptions& options);

}  // namespace dyad::sweep
