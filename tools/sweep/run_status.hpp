// tools/sweep/run_status.hpp: a run's status in sweep.csv's `status` column (sweep_runner.hpp,
// WriteSweepCsv), which the plots read (plot_sweep.py draws the `ok` rows).
//
// ToString gives the table's word; ParseRunStatus reads it back, and for any other word says
// "must be ok, incomplete, failed or missing" (the words of the same table, in run_status.cpp).
#pragma once

#include <string_view>

#include "dyad/status.hpp"

namespace dyad::sweep {

enum class RunStatus {
  kOk,          // "ok": metrics.json is there, from a whole recording as long as planned
  kIncomplete,  // "incomplete": metrics.json is there, but the recording was cut short or shorter
                //   than planned (report/incomplete.txt): in the table, marked, out of the plots
  kFailed,      // "failed": no metrics, failed.txt says why
  kMissing,     // "missing": neither (not run yet, or stopped: a rerun runs it)
};

std::string_view ToString(RunStatus status);
StatusOr<RunStatus> ParseRunStatus(std::string_view word);

}  // namespace dyad::sweep
