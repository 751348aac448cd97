// How a sweep's job ended, from how its child ended and what it left: the table of
// ClassifyRunChild and ClassifyTraining (job_end.hpp), as dora tests node_exit.rs.
#include "job_end.hpp"

#include <errno.h>
#include <signal.h>

#include <gtest/gtest.h>

namespace dyad::sweep {
namespace {

using tools::ExitStatus;

const ExitStatus kOk = ExitStatus::Exited(0);
const ExitStatus kThree = ExitStatus::Exited(3);
const ExitStatus kKilled = ExitStatus::Signaled(SIGKILL);
const ExitStatus kNoProgram = ExitStatus::NeverStarted(ExitStatus::StartStep::kExec, ENOENT);
const ExitStatus kNoLog = ExitStatus::NeverStarted(ExitStatus::StartStep::kLog, ENOSPC);

TEST(JobEnd, ARunsChildIsClassifiedByHowItEnded) {
  struct Case {
    bool stopped;
    ExitStatus exit;
    JobOutcome outcome;
    std::string why;
  };
  const Case cases[] = {
      {false, kOk, JobOutcome::kOk, ""},
      {false, kThree, JobOutcome::kFailed, "exited with code 3"},
      {false, ExitStatus::Exited(127), JobOutcome::kFailed, "exited with code 127"},
      {false, kKilled, JobOutcome::kFailed, "killed by signal 9 (Killed)"},
      {false, kNoProgram, JobOutcome::kFailed, "never started: No such file or directory"},
      {false, kNoLog, JobOutcome::kFailed, "never started: cannot open its log: No space left on device"},
      {false, ExitStatus::WaitFailed(ECHILD), JobOutcome::kFailed, "wait failed: No child processes"},
      // A stop before its end leaves the run to a rerun, however it ended.
      {true, kOk, JobOutcome::kStopped, ""},
      {true, ExitStatus::Exited(130), JobOutcome::kStopped, ""},
      {true, kKilled, JobOutcome::kStopped, ""},
  };
  for (const Case& c : cases) {
    const JobEnd end = ClassifyRunChild(c.stopped, c.exit);
    EXPECT_EQ(end.outcome, c.outcome) << c.exit.ToString() << (c.stopped ? " after a stop" : "");
    EXPECT_EQ(end.why, c.why);
  }
}

TEST(JobEnd, ATrainingIsOkOnlyWithItsModelWritten) {
  struct Case {
    bool stopped;
    ExitStatus exit;
    bool model;
    JobOutcome outcome;
    std::string why;
  };
  const Case cases[] = {
      {false, kOk, true, JobOutcome::kOk, ""},
      {false, kOk, false, JobOutcome::kFailed, "exited with code 0 but wrote no model"},
      {false, kThree, false, JobOutcome::kFailed, "exited with code 3"},
      {false, kThree, true, JobOutcome::kFailed, "exited with code 3"},  // a model of an earlier try is not this one's
      {false, kKilled, false, JobOutcome::kFailed, "killed by signal 9 (Killed)"},
      {false, kNoProgram, false, JobOutcome::kFailed, "never started: No such file or directory"},
      {true, kOk, true, JobOutcome::kStopped, ""},
      {true, ExitStatus::Signaled(SIGINT), false, JobOutcome::kStopped, ""},
  };
  for (const Case& c : cases) {
    const JobEnd end = ClassifyTraining(c.stopped, c.exit, c.model);
    EXPECT_EQ(end.outcome, c.outcome) << c.exit.ToString() << (c.model ? " with" : " without") << " its model";
    EXPECT_EQ(end.why, c.why);
  }
}

TEST(JobEnd, TheLogSaysEachOutcome) {
  EXPECT_STREQ(OutcomeName(JobOutcome::kOk), "ok");
  EXPECT_STREQ(OutcomeName(JobOutcome::kSkipped), "done before");
  EXPECT_STREQ(OutcomeName(JobOutcome::kFailed), "FAILED");
  EXPECT_STREQ(OutcomeName(JobOutcome::kStopped), "stopped");
}

}  // namespace
}  // namespace dyad::sweep
