// The child-process type: how a child ended, typed and said; the pid known at once; the one stop
// policy (the signal, then SIGKILL after the grace); waiting and stopping from two threads.
#include "child_process.hpp"

#include <errno.h>
#include <signal.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

namespace dyad::tools {
namespace {

namespace fs = std::filesystem;
using std::chrono::milliseconds;

class ChildProcessTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("dyad_child_" + std::to_string(::getpid()) + "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Read(const fs::path& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }

  // Until `file` exists (the child says it is ready); no deadline of ours: ctest's timeout.
  void AwaitFile(const fs::path& file) {
    while (!fs::exists(file)) std::this_thread::sleep_for(milliseconds(5));
  }

  fs::path dir_;
};

TEST(ExitStatus, SaysEachWayAChildEnds) {
  struct Case {
    ExitStatus status;
    std::string text;
    int shell_code;
  };
  const Case cases[] = {
      {ExitStatus::Exited(0), "exited with code 0", 0},
      {ExitStatus::Exited(3), "exited with code 3", 3},
      {ExitStatus::Exited(127), "exited with code 127", 127},
      {ExitStatus::Signaled(SIGKILL), "killed by signal 9 (Killed)", 137},
      {ExitStatus::Signaled(SIGSEGV, true), "killed by signal 11 (Segmentation fault), core dumped", 139},
      {ExitStatus::NeverStarted(ExitStatus::StartStep::kExec, ENOENT), "never started: No such file or directory", 127},
      {ExitStatus::NeverStarted(ExitStatus::StartStep::kLog, EACCES), "never started: cannot open its log: Permission denied",
       127},
      {ExitStatus::NeverStarted(ExitStatus::StartStep::kFolder, ENOTDIR),
       "never started: cannot enter its working folder: Not a directory", 127},
      {ExitStatus::NeverStarted(ExitStatus::StartStep::kCallerGone, 0),
       "never started: its caller ended before it could watch it", 127},
      {ExitStatus::WaitFailed(ECHILD), "wait failed: No child processes", 127},
  };
  for (const Case& c : cases) {
    EXPECT_EQ(c.status.ToString(), c.text);
    EXPECT_EQ(c.status.ShellCode(), c.shell_code) << c.text;
    EXPECT_EQ(c.status.ok(), c.text == "exited with code 0") << c.text;
  }
  // The four that used to be the same 127 are told apart.
  EXPECT_TRUE(ExitStatus::Exited(127).exited());
  EXPECT_TRUE(ExitStatus::NeverStarted(ExitStatus::StartStep::kExec, ENOENT).never_started());
  EXPECT_EQ(ExitStatus::WaitFailed(ECHILD).kind(), ExitStatus::Kind::kWaitFailed);
  EXPECT_TRUE(ExitStatus::Signaled(SIGINT).KilledBy(SIGINT));
  EXPECT_FALSE(ExitStatus::Exited(130).KilledBy(SIGINT));
}

TEST_F(ChildProcessTest, AMissingProgramNeverStartedAndSaysWhy) {
  ChildProcess path({(dir_ / "no-such-program").string()});
  EXPECT_EQ(path.pid(), -1);
  EXPECT_EQ(path.Wait().ToString(), "never started: No such file or directory");
  EXPECT_EQ(path.Wait().error(), ENOENT);
  EXPECT_EQ(RunChild({"dyad-no-such-program-on-path"}).ToString(), "never started: No such file or directory");
  // A program that exits 127 itself is not one that never started.
  EXPECT_EQ(RunChild({"/bin/sh", "-c", "exit 127"}).ToString(), "exited with code 127");
}

TEST_F(ChildProcessTest, ALogThatCannotBeOpenedOrAMissingFolderIsSaid) {
  ChildOptions o;
  o.log = (dir_ / "no-folder" / "run.log").string();
  EXPECT_EQ(RunChild({"/bin/true"}, o).ToString(), "never started: cannot open its log: No such file or directory");
  ChildOptions f;
  f.folder = (dir_ / "no-folder").string();
  EXPECT_EQ(RunChild({"/bin/true"}, f).ToString(), "never started: cannot enter its working folder: No such file or directory");
}

TEST_F(ChildProcessTest, ExitCodesAndSignalsAreTyped) {
  const ExitStatus three = RunChild({"/bin/sh", "-c", "exit 3"});
  EXPECT_TRUE(three.ExitedWith(3));
  EXPECT_EQ(three.ToString(), "exited with code 3");
  const ExitStatus killed = RunChild({"/bin/sh", "-c", "kill -9 $$"});
  EXPECT_TRUE(killed.KilledBy(SIGKILL)) << killed.ToString();
  EXPECT_EQ(killed.ToString(), "killed by signal 9 (Killed)");
}

TEST_F(ChildProcessTest, ItsLogFolderAndEnvironmentAreAsAsked) {
  ChildOptions o;
  o.log = (dir_ / "out.log").string();
  o.err_log = (dir_ / "err.log").string();
  o.folder = dir_.string();
  o.env = {"DYAD_CHILD_TEST=seen", "HOME=/elsewhere"};
  ASSERT_TRUE(RunChild({"/bin/sh", "-c", "echo \"$DYAD_CHILD_TEST $HOME $(pwd)\"; echo oops >&2"}, o).ok());
  EXPECT_EQ(Read(dir_ / "out.log"), "seen /elsewhere " + dir_.string() + "\n");
  EXPECT_EQ(Read(dir_ / "err.log"), "oops\n");
  EXPECT_EQ(fs::status(dir_ / "out.log").permissions() & fs::perms::all, fs::perms::owner_read | fs::perms::owner_write);
}

TEST_F(ChildProcessTest, ThePidAndItsGroupAreKnownWhenTheConstructorReturns) {
  ChildOptions o;
  o.own_group = true;
  ChildProcess child({"/bin/sleep", "60"}, o);
  ASSERT_GT(child.pid(), 0);
  EXPECT_EQ(::kill(child.pid(), 0), 0);
  EXPECT_EQ(::getpgid(child.pid()), child.pid());
  EXPECT_FALSE(child.Poll().has_value());
  // A child that ends on the signal is not killed.
  EXPECT_TRUE(child.Stop(std::chrono::seconds(30), SIGTERM).KilledBy(SIGTERM));
  EXPECT_FALSE(child.Signal(SIGTERM)) << "no signal after the reaping: the pid may be another's";
}

TEST_F(ChildProcessTest, StopEscalatesToSigkillForAChildThatIgnoresTheSignal) {
  const fs::path ready = dir_ / "ready";
  ChildOptions o;
  o.own_group = true;
  ChildProcess child({"/bin/sh", "-c", "trap '' TERM; touch '" + ready.string() + "'; exec sleep 60"}, o);
  AwaitFile(ready);
  const ExitStatus end = child.Stop(milliseconds(100), SIGTERM);
  EXPECT_TRUE(end.KilledBy(SIGKILL)) << end.ToString();
}

// The learner's way: one thread waits for the child while another stops it.
TEST_F(ChildProcessTest, OneThreadWaitsWhileAnotherStops) {
  ChildProcess child({"/bin/sleep", "60"});
  ExitStatus waited;
  std::thread waiter([&] { waited = child.Wait(); });
  const ExitStatus stopped = child.Stop(std::chrono::seconds(30), SIGINT);
  waiter.join();
  EXPECT_TRUE(stopped.KilledBy(SIGINT)) << stopped.ToString();
  EXPECT_EQ(waited, stopped);
}

TEST_F(ChildProcessTest, AChildStillRunningIsKilledWithTheObject) {
  pid_t pid = -1;
  {
    ChildProcess child({"/bin/sleep", "60"});
    pid = child.pid();
    ASSERT_GT(pid, 0);
  }
  EXPECT_NE(::kill(pid, 0), 0) << "reaped: no such process";
}

}  // namespace
}  // namespace dyad::tools
