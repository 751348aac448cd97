// dyad/testing/child_process.hpp: a child process for process-level tests (test code only), on
// the house's child-process type (support/child_process.hpp, tools::ChildProcess).
//
// Starts `args[0]` (a path, or a name looked up in PATH) with stdout and stderr in DIR/TAG.out
// and DIR/TAG.err, optionally with extra environment entries ("NAME=value", added to the test's
// own) and another working directory. A child still running when the object dies is SIGKILLed
// and reaped, so a failing test never leaves processes behind.
//
//   dyad::testing::ChildProcess run({DYAD_EXE, "run", "g.yaml"}, dir, "run");
//   run.Signal(SIGINT);
//   ASSERT_EQ(run.Wait(30), 0) << run.err();
#pragma once

#include <sys/types.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <child_process.hpp>  // support/child_process.hpp (quoted, this file would include itself)

namespace dyad::testing {

// The whole file; empty when it cannot be read.
inline std::string ReadFile(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

class ChildProcess {
 public:
  ChildProcess(std::vector<std::string> args, const std::filesystem::path& dir, const std::string& tag,
               std::vector<std::string> env = {}, const std::filesystem::path& cwd = {})
      : out_(dir / (tag + ".out")), err_(dir / (tag + ".err")), child_(args, Options(out_, err_, std::move(env), cwd)) {}
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  pid_t pid() const { return child_.pid(); }
  void Signal(int sig) { child_.Signal(sig); }
  // Exit code (128 + signal if killed by one, 127 when it never started), or -1 if still running
  // after `timeout_s`.
  int Wait(double timeout_s) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (std::chrono::steady_clock::now() < end) {
      if (auto status = child_.Poll()) return status->ShellCode();
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return -1;
  }
  // True once stdout contains `text` (e.g. a server's "listening" line); false after `timeout_s`.
  bool WaitForOutput(const std::string& text, double timeout_s) const {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (std::chrono::steady_clock::now() < end) {
      if (out().find(text) != std::string::npos) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
  }
  std::string out() const { return ReadFile(out_); }
  std::string err() const { return ReadFile(err_); }

  // For a child that did not end in time: every thread's stack of it and of its descendants
  // (gdb in batch mode, when installed), so that a rare hang in CI says where it hangs.
  std::string Stacks() const {
    std::vector<pid_t> pids = {pid()};
    for (size_t i = 0; i < pids.size(); ++i) {  // descendants, breadth first, from /proc
      for (const auto& e : std::filesystem::directory_iterator("/proc")) {
        const std::string name = e.path().filename().string();
        if (name.find_first_not_of("0123456789") != std::string::npos) continue;
        std::ifstream stat(e.path() / "stat");
        std::string line;
        std::getline(stat, line);
        const size_t close = line.rfind(')');
        if (close == std::string::npos) continue;
        std::istringstream rest(line.substr(close + 2));
        char state = 0;
        pid_t parent = 0;
        if (rest >> state >> parent && parent == pids[i]) pids.push_back(std::stoi(name));
      }
    }
    if (!std::filesystem::exists("/usr/bin/gdb")) return "(no gdb: no stacks)";
    std::string out;
    for (pid_t p : pids) {
      const std::filesystem::path file = out_.string() + ".stacks";
      const std::string cmd = "timeout 60 /usr/bin/gdb -p " + std::to_string(p) +
                              " -batch -ex 'thread apply all bt 20' 2>&1 | grep -E '^Thread|^#' > " + file.string();
      std::string cmdline = ReadFile("/proc/" + std::to_string(p) + "/cmdline");
      for (char& c : cmdline) c = c == '\0' ? ' ' : c;
      out += "=== pid " + std::to_string(p) + ": " + cmdline + "\n";
      if (std::system(cmd.c_str()) == 0) out += ReadFile(file);
    }
    return out;
  }

 private:
  static tools::ChildOptions Options(const std::filesystem::path& out, const std::filesystem::path& err,
                                     std::vector<std::string> env, const std::filesystem::path& cwd) {
    tools::ChildOptions o;
    o.log = out.string();
    o.err_log = err.string();
    o.env = std::move(env);
    o.folder = cwd.string();
    return o;
  }

  std::filesystem::path out_, err_;  // before child_: its options are made of them
  tools::ChildProcess child_;
};

}  // namespace dyad::testing
