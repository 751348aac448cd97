// tools/sweep/sweep_runner.hpp: the runs of a sweep on this machine's cores, and their table.
//
// Contract of RunSweep:
//   - Each run gets OUT/runs/<id>/: `dyad run` (stepped, hermetic: a stepped run's DDS stays in
//     its process, so concurrent runs never see each other) recording rec.mcap, then what `dyad
//     analyze --no-plots` writes, into report/ (in this process), then metrics.json (the report's, copied last, by rename:
//     its presence means the run finished). run.log and analyze.log keep what they printed.
//   - A run whose folder has metrics.json is skipped (resuming a killed sweep). A run that fails
//     (a non-zero exit, a crash, no metrics) gets failed.txt (the command, how it ended, the end
//     of its log) and the sweep goes on; a later sweep tries it again. A run whose folder cannot
//     be made or cleaned (a file where it should be, EACCES, ENOSPC) fails with that reason in
//     its log line (there is no folder to hold failed.txt); nothing throws on a worker thread.
//   - Each `dyad run` (and `dyad train`) runs in a process group of its own with SIGINT as its
//     parent-death signal: when the sweep dies, even by SIGKILL, its runs stop too.
//   - While a StopOnSignals lives, SIGINT or SIGTERM stops the sweep: no run starts, the runs
//     under way get SIGINT (their whole group; SIGKILL after kStopGraceS), the finished ones are
//     kept. RunnerResult::not_done lists the runs that did not finish (no metrics.json, no
//     failed.txt: a rerun runs them).
//   - `workers` runs at once; each finished run prints a line to `log` with its count, its
//     status and the estimated time left.
//   - A run with a training gets `--set MODEL_KEY=OUT/models/<id>.dpvrnn`; when that model is
//     not there (its training failed, or has not run: a Slurm task does not train), the run
//     fails saying so.
// Contract of TrainModels: `dyad train CONFIG --set ... --set output=OUT/models/<id>.dpvrnn` for
// each of `trainings` whose model is not there yet (`workers` at once; its log beside it as
// <id>.log, and <id>.failed.txt when it failed). The model file appears whole or not at all
// (dyad train writes it by rename), so its presence means it trained.
// Contract of WriteSweepCsv: OUT/sweep.csv, one row per run in the plan's order (not the order
// they finished): run, status (RunStatus, run_status.hpp), each swept key, seed, then every metric of
// metrics.json in its order (empty where a run has none). The same runs give the same file
// whatever the workers, and after a resume.
#pragma once

#include <signal.h>

#include <ostream>
#include <string>
#include <vector>

#include "dyad/status.hpp"
#include "sweep_plan.hpp"

namespace dyad::sweep {

struct RunnerOptions {
  std::string out;   // the sweep's folder
  int workers = 1;
  std::string dyad;  // the dyad executable the runs use
};

struct RunnerResult {
  int ran = 0, skipped = 0, failed = 0;
  int signal = 0;                // the stop signal that came (SIGINT, SIGTERM); 0: none
  std::vector<size_t> not_done;  // with a signal: the jobs (indices, in order) that did not finish
};

// While one lives, SIGINT and SIGTERM stop RunSweep and TrainModels (see above), also when the
// sweep inherited SIGINT ignored (a script's background job). The previous handlers come back
// when it dies. One at a time.
class StopOnSignals {
 public:
  StopOnSignals();
  ~StopOnSignals();
  StopOnSignals(const StopOnSignals&) = delete;
  StopOnSignals& operator=(const StopOnSignals&) = delete;
  static int Received();  // the signal that came while one lived (0: none)

 private:
  struct sigaction old_int_ {}, old_term_ {};
};

constexpr double kStopGraceS = 10;  // a stopped run's time to end before SIGKILL

RunnerResult RunSweep(const SweepPlan& plan, const RunnerOptions& options, std::ostream& log);
RunnerResult TrainModels(const SweepPlan& plan, const std::vector<SweepTraining>& trainings, const RunnerOptions& options,
                         std::ostream& log);
Status WriteSweepCsv(const SweepPlan& plan, const std::string& out);

}  // namespace dyad::sweep
