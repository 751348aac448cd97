#include "attempt_end.hpp"

#include <signal.h>

#include <cstdio>

namespace dyad::study {

AttemptOutcome ClassifyGraphEnd(const GraphEnd& end) {
  if (end.stopped && end.timed && !end.while_asking) return AttemptOutcome::kStopped;
  const bool ended_well = end.exit.ok() || (end.stopped && (end.exit.ExitedWith(128 + SIGINT) || end.exit.KilledBy(SIGINT)));
  return ended_well ? AttemptOutcome::kComplete : AttemptOutcome::kFailed;
}

AttemptOutcome ClassifyRecording(bool whole, const std::string& no_subject) {
  if (!whole) return AttemptOutcome::kFailed;
  return no_subject.empty() ? AttemptOutcome::kComplete : AttemptOutcome::kIncomplete;
}

std::string FailedLine(const std::string& ended, int exit, double seconds) {
  char secs[32];
  std::snprintf(secs, sizeof secs, "%.1f s", seconds);
  if (ended.empty())  // a log written before the end was kept in words: its number
    return "failed: the graph exited " + std::to_string(exit) + " after " + secs +
           (exit == 0 ? " and left no whole recording" : "");
  if (ended.rfind("never started", 0) == 0) return "failed: the graph " + ended;
  return "failed: the graph " + std::string(ended.rfind("killed", 0) == 0 ? "was " : "") + ended + " after " + secs +
         (ended == tools::ExitStatus::Exited(0).ToString() ? " and left no whole recording" : "");
}

}  // namespace dyad::study
