// OutputRelay (hosts/output_relay.hpp): lines a child writes on its stdout and stderr pipes reach
// the launcher's streams prefixed with the process's name and its log file unprefixed; a
// partial last line is passed on when the pipe closes; a restarted process appends to the same
// log after a header; a pipe held open by something the child left behind does not keep the
// relay from ending. Real pipes, written directly or by a forked child.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include "hosts/output_relay.hpp"

namespace dyad {
namespace {

namespace fs = std::filesystem;
using SteadyClock = std::chrono::steady_clock;

class OutputRelayTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("dyad_output_relay_" + std::to_string(getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  static std::string Read(const fs::path& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }
  // The relay writes each line to the streams, then to the log (flushed): once the log has it,
  // the relay has read it. Reading the file is safe while the relay thread writes it.
  static bool AwaitInFile(const fs::path& p, const std::string& text) {
    const auto deadline = SteadyClock::now() + std::chrono::seconds(30);
    while (SteadyClock::now() < deadline) {
      if (Read(p).find(text) != std::string::npos) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
  }
  static void Write(int fd, const std::string& s) { ASSERT_EQ(write(fd, s.data(), s.size()), static_cast<ssize_t>(s.size())); }

  fs::path dir_;
  std::ostringstream out_, err_;  // read only once the relay is destroyed (its thread joined)
};

TEST_F(OutputRelayTest, LinesArePrefixedOnTheStreamsAndPlainInTheLog) {
  const fs::path log = dir_ / "logs" / "mind.log";  // its folder is created
  {
    OutputRelay relay(out_, err_);
    auto pipes = relay.Add("mind", log.string(), "=== mind started");
    ASSERT_TRUE(pipes.ok()) << pipes.status().message();
    Write(pipes.value().out_write, "hello\nworld\n");
    Write(pipes.value().err_write, "oops\n");
    Write(pipes.value().out_write, "no newline yet");  // passed on when the pipe closes
    OutputRelay::CloseWriteEnds(pipes.value());
    relay.Say("dyad run: launcher says");
  }  // reads until the pipes closed
  EXPECT_EQ(out_.str(), "[mind] hello\n[mind] world\n[mind] no newline yet\n");
  const std::string err = err_.str();
  EXPECT_NE(err.find("[mind] oops\n"), std::string::npos) << err;
  EXPECT_NE(err.find("dyad run: launcher says\n"), std::string::npos) << err;  // unprefixed, a newline added
  const std::string file = Read(log);
  EXPECT_EQ(file.rfind("=== mind started\n", 0), 0u) << file;
  for (const char* line : {"\nhello\n", "\nworld\n", "\noops\n", "\nno newline yet\n"})
    EXPECT_NE(file.find(line), std::string::npos) << line << " in " << file;
  EXPECT_EQ(file.find("[mind]"), std::string::npos) << file;
  // A subject's session is in these lines: private to the user running the launcher.
  EXPECT_EQ(fs::status(log).permissions() & fs::perms::all, fs::perms::owner_read | fs::perms::owner_write);
  EXPECT_EQ(fs::status(log.parent_path()).permissions() & fs::perms::all, fs::perms::owner_all);
}

// A symlink planted where a process's log goes is refused (said on the launcher's stderr); its
// target is untouched, and the process's output still reaches the terminal.
TEST_F(OutputRelayTest, ALogPathThatIsASymlinkIsRefused) {
  const fs::path target = dir_ / "victim.txt", log = dir_ / "mind.log";
  fs::create_directories(dir_);
  std::ofstream(target) << "precious\n";
  fs::create_symlink(target, log);
  {
    OutputRelay relay(out_, err_);
    auto pipes = relay.Add("mind", log.string(), "=== mind");
    ASSERT_TRUE(pipes.ok()) << pipes.status().message();
    Write(pipes.value().out_write, "hello\n");
    OutputRelay::CloseWriteEnds(pipes.value());
  }
  EXPECT_EQ(Read(target), "precious\n");
  EXPECT_EQ(out_.str(), "[mind] hello\n");
  EXPECT_NE(err_.str().find("[mind] warning: cannot write its log: " + log.string() + ": is a symbolic link to '" +
                            target.string() + "': refused"),
            std::string::npos)
      << err_.str();
}

TEST_F(OutputRelayTest, EachChildKeepsItsOwnPrefixAndARestartAppendsToTheSameLog) {
  const fs::path log = dir_ / "mind.log";
  {
    OutputRelay relay(out_, err_);
    auto first = relay.Add("mind", log.string(), "=== run 1");
    auto human = relay.Add("human", "", "unused: no log");
    ASSERT_TRUE(first.ok() && human.ok());
    Write(first.value().out_write, "before the crash\n");
    Write(human.value().out_write, "still here\n");
    OutputRelay::CloseWriteEnds(first.value());
    ASSERT_TRUE(AwaitInFile(log, "before the crash\n"));
    auto second = relay.Add("mind", log.string(), "=== run 2 (restart 1)");
    ASSERT_TRUE(second.ok());
    Write(second.value().out_write, "after the restart\n");
    OutputRelay::CloseWriteEnds(second.value());
    OutputRelay::CloseWriteEnds(human.value());
  }
  EXPECT_EQ(Read(log), "=== run 1\nbefore the crash\n=== run 2 (restart 1)\nafter the restart\n");
  const std::string out = out_.str();
  EXPECT_NE(out.find("[mind] before the crash\n"), std::string::npos) << out;
  EXPECT_NE(out.find("[human] still here\n"), std::string::npos) << out;
  EXPECT_NE(out.find("[mind] after the restart\n"), std::string::npos) << out;
}

TEST_F(OutputRelayTest, AForkedChildsOutputArrives) {
  const fs::path log = dir_ / "child.log";
  {
    OutputRelay relay(out_, err_);
    auto pipes = relay.Add("child", log.string(), "=== child");
    ASSERT_TRUE(pipes.ok());
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {  // only async-signal-safe calls here
      dup2(pipes.value().out_write, 1);
      dup2(pipes.value().err_write, 2);
      static const char kOut[] = "to stdout\n", kErr[] = "to stderr\n";
      (void)!write(1, kOut, sizeof(kOut) - 1);
      (void)!write(2, kErr, sizeof(kErr) - 1);
      _exit(0);
    }
    OutputRelay::CloseWriteEnds(pipes.value());
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
  }
  EXPECT_EQ(out_.str(), "[child] to stdout\n");
  EXPECT_EQ(err_.str(), "[child] to stderr\n");
}

// A pipe held by a grandchild that outlives the child: the relay passes on what arrived, and
// ends about kCloseGraceMs after it was asked to, not when the grandchild lets go.
TEST_F(OutputRelayTest, APipeStillHeldOpenDoesNotKeepTheRelayFromEnding) {
  const fs::path log = dir_ / "mind.log";
  int held = -1;
  const auto destroyed = [&] {
    OutputRelay relay(out_, err_);
    auto pipes = relay.Add("mind", log.string(), "=== mind");
    EXPECT_TRUE(pipes.ok());
    if (!pipes.ok()) return SteadyClock::duration{};
    held = dup(pipes.value().out_write);  // the grandchild's copy
    Write(pipes.value().out_write, "said before\npartial");
    OutputRelay::CloseWriteEnds(pipes.value());
    EXPECT_TRUE(AwaitInFile(log, "said before\n"));
    const auto asked = SteadyClock::now();
    return asked.time_since_epoch();
  }();
  const auto ended = SteadyClock::now().time_since_epoch();
  ASSERT_GE(held, 0);
  close(held);
  EXPECT_GE(ended - destroyed, std::chrono::milliseconds(OutputRelay::kCloseGraceMs - 100));  // it waited
  EXPECT_LT(ended - destroyed, std::chrono::seconds(60));  // and it ended
  EXPECT_EQ(out_.str(), "[mind] said before\n[mind] partial\n");
}

}  // namespace
}  // namespace dyad
