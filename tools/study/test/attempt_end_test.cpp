// The outcome of an attempt at a trial from how its graph ended and what it left: the tables of
// ClassifyGraphEnd, ClassifyRecording and FailedLine (attempt_end.hpp), as dora tests
// node_exit.rs.
#include "attempt_end.hpp"

#include <errno.h>
#include <signal.h>

#include <gtest/gtest.h>

namespace dyad::study {
namespace {

using tools::ExitStatus;

TEST(AttemptEnd, TheGraphsEndIsClassified) {
  const ExitStatus ok = ExitStatus::Exited(0), three = ExitStatus::Exited(3), exited_130 = ExitStatus::Exited(130);
  const ExitStatus by_sigint = ExitStatus::Signaled(SIGINT), killed = ExitStatus::Signaled(SIGKILL);
  const ExitStatus never = ExitStatus::NeverStarted(ExitStatus::StartStep::kExec, ENOENT);
  struct Case {
    GraphEnd end;
    AttemptOutcome outcome;
  };
  const Case cases[] = {
      // Nobody stopped it: it ended well only by exiting 0.
      {{ok, false, true, false}, AttemptOutcome::kComplete},
      {{ok, false, false, false}, AttemptOutcome::kComplete},
      {{three, false, true, false}, AttemptOutcome::kFailed},
      {{exited_130, false, false, false}, AttemptOutcome::kFailed},  // a Ctrl-C of its own terminal, not ours
      {{by_sigint, false, false, false}, AttemptOutcome::kFailed},
      {{killed, false, false, false}, AttemptOutcome::kFailed},
      {{never, false, false, false}, AttemptOutcome::kFailed},
      // A timed trial stopped before its time: stopped, however the graph ended.
      {{ok, true, true, false}, AttemptOutcome::kStopped},
      {{exited_130, true, true, false}, AttemptOutcome::kStopped},
      {{killed, true, true, false}, AttemptOutcome::kStopped},
      // Stopped while the subject answered after a full trial, or an untimed trial ended by the
      // experimenter: complete when the graph ended as dyad does on a Ctrl-C.
      {{exited_130, true, true, true}, AttemptOutcome::kComplete},
      {{by_sigint, true, false, false}, AttemptOutcome::kComplete},
      {{ok, true, false, false}, AttemptOutcome::kComplete},
      {{three, true, false, false}, AttemptOutcome::kFailed},
      {{killed, true, true, true}, AttemptOutcome::kFailed},  // the second stop's kill: its recording is cut short
  };
  for (const Case& c : cases) {
    EXPECT_EQ(ClassifyGraphEnd(c.end), c.outcome)
        << c.end.exit.ToString() << (c.end.stopped ? ", stopped" : "") << (c.end.timed ? ", timed" : "")
        << (c.end.while_asking ? ", while asking" : "") << ": " << ToString(ClassifyGraphEnd(c.end));
  }
}

TEST(AttemptEnd, TheRecordingConfirmsAnAttemptThatEndedWell) {
  EXPECT_EQ(ClassifyRecording(true, ""), AttemptOutcome::kComplete);
  EXPECT_EQ(ClassifyRecording(false, ""), AttemptOutcome::kFailed);
  EXPECT_EQ(ClassifyRecording(true, "no subject: human/input never engaged"), AttemptOutcome::kIncomplete);
  EXPECT_EQ(ClassifyRecording(false, "no subject: human/input never engaged"), AttemptOutcome::kFailed);
}

TEST(AttemptEnd, AFailedAttemptSaysHowTheGraphEnded) {
  auto line = [](const ExitStatus& e, double secs) { return FailedLine(e.ToString(), e.ShellCode(), secs); };
  EXPECT_EQ(line(ExitStatus::Exited(3), 1.24), "failed: the graph exited with code 3 after 1.2 s");
  EXPECT_EQ(line(ExitStatus::Signaled(SIGKILL), 12), "failed: the graph was killed by signal 9 (Killed) after 12.0 s");
  EXPECT_EQ(line(ExitStatus::NeverStarted(ExitStatus::StartStep::kExec, ENOENT), 0),
            "failed: the graph never started: No such file or directory");
  EXPECT_EQ(line(ExitStatus::Exited(0), 30), "failed: the graph exited with code 0 after 30.0 s and left no whole recording");
  // A session log written before "ended" was kept: its number, as it was said then.
  EXPECT_EQ(FailedLine("", 137, 9), "failed: the graph exited 137 after 9.0 s");
  EXPECT_EQ(FailedLine("", 0, 9), "failed: the graph exited 0 after 9.0 s and left no whole recording");
}

}  // namespace
}  // namespace dyad::study
