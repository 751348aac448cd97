#include "job_end.hpp"

namespace dyad::sweep {

JobEnd ClassifyRunChild(bool stopped, const tools::ExitStatus& exit) {
  if (stopped) return {JobOutcome::kStopped, ""};
  if (exit.ok()) return {JobOutcome::kOk, ""};
  return {JobOutcome::kFailed, exit.ToString()};
}

JobEnd ClassifyTraining(bool stopped, const tools::ExitStatus& exit, bool model_written) {
  if (stopped) return {JobOutcome::kStopped, ""};
  if (exit.ok() && model_written) return {JobOutcome::kOk, ""};
  return {JobOutcome::kFailed, exit.ok() ? exit.ToString() + " but wrote no model" : exit.ToString()};
}

const char* OutcomeName(JobOutcome outcome) {
  switch (outcome) {
    case JobOutcome::kOk:
      return "ok";
    case JobOutcome::kSkipped:
      return "done before";
    case JobOutcome::kFailed:
      return "FAILED";
    case JobOutcome::kStopped:
      return "stopped";
  }
  return "?";
}

}  // namespace dyad::sweep
