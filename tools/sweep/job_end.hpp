// tools/sweep/job_end.hpp: how one job of a sweep (a run, or the training of a model) ended, from
// how its child ended and what it left: pure functions (sweep_runner.cpp calls them; the table
// tests in test/job_end_test.cpp read them), as dora's node_exit.rs does.
//
// Contract:
//   - ClassifyRunChild(stopped, exit): the run's `dyad run`. Stopped (a stop signal reached the
//     sweep before it ended): kStopped, whatever its status (the run is left to a rerun).
//     Exited 0: kOk (its recording goes on to the analysis). Anything else: kFailed, `why` is
//     how it ended ("exited with code 3", "killed by signal 9 (Killed)", "never started: No such
//     file or directory"), the line failed.txt gives after the command.
//   - ClassifyTraining(stopped, exit, model_written): a model's `dyad train`. Stopped: kStopped.
//     Exited 0 with its model written: kOk. Else kFailed with how it ended ("exited with code 0
//     but wrote no model" when that is all).
//   - OutcomeName: the word the sweep's log prints ("ok", "done before", "FAILED", "stopped").
#pragma once

#include <string>

#include "child_process.hpp"

namespace dyad::sweep {

enum class JobOutcome { kOk, kSkipped, kFailed, kStopped };

struct JobEnd {
  JobOutcome outcome;
  std::string why;  // kFailed: how it ended (or why failed.txt could not be written)
};

JobEnd ClassifyRunChild(bool stopped, const tools::ExitStatus& exit);
JobEnd ClassifyTraining(bool stopped, const tools::ExitStatus& exit, bool model_written);
const char* OutcomeName(JobOutcome outcome);

}  // namespace dyad::sweep
