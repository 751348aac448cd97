// tools/study/attempt_end.hpp: the outcome of one attempt at a trial from how its graph ended and
// what it left: pure functions (RunAttempt calls them, test/attempt_end_test.cpp tables them), as
// dora's node_exit.rs classifies a node's exit.
//
// Contract:
//   - ClassifyGraphEnd(end): the graph's part, before its recording is read. A stop forwarded to
//     a timed trial before its time was up (or while nobody was asked afterwards) is kStopped,
//     however the graph ended. Otherwise the graph ended well (exited 0; or, after a stop, exited
//     130 or was killed by SIGINT, as dyad does on a Ctrl-C) gives kComplete, to be confirmed by
//     the recording; anything else (another code, another signal, never started) is kFailed.
//   - ClassifyRecording(whole, no_subject): an attempt whose graph ended well: kFailed when its
//     recording is cut short or missing (!whole), kIncomplete when nobody took part
//     (`no_subject`, NoSubject's reason, is not empty), else kComplete.
//   - FailedLine(ended, exit, seconds): what the runner prints for a failed attempt, from the
//     session log's "ended" (ExitStatus::ToString) and "exit": "failed: the graph exited with code
//     3 after 1.2 s", "failed: the graph was killed by signal 9 (Killed) after 9.0 s", "failed: the
//     graph never started: No such file or directory", "failed: the graph exited with code 0 after
//     1.2 s and left no whole recording"; a log without "ended" (written before it was kept): "failed:
//     the graph exited 137 after 9.0 s", as it was said then.
#pragma once

#include <string>

#include "attempt_outcome.hpp"
#include "child_process.hpp"

namespace dyad::study {

struct GraphEnd {
  tools::ExitStatus exit;     // how `dyad run` ended
  bool stopped = false;       // a stop (SIGINT, SIGTERM, the page's Stop) was forwarded to it
  bool timed = false;         // the study has a duration
  bool while_asking = false;  // the stop came after the duration, while the subject answered
};

AttemptOutcome ClassifyGraphEnd(const GraphEnd& end);
AttemptOutcome ClassifyRecording(bool whole, const std::string& no_subject);
std::string FailedLine(const std::string& ended, int exit, double seconds);

}  // namespace dyad::study
