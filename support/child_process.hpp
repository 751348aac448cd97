// support/child_process.hpp: the one child-process type of the house (the learner's trainer, a
// sweep's runs, a study's trials, the CLI's helpers, the tests' processes). Below the components
// (support/CMakeLists.txt: library dyad_child_process, which needs nothing but libc, so the tests'
// support links it too); the namespace is dyad::tools, its first users'.
//
// ExitStatus: how a child ended, typed (a bare int made 127 mean four things):
//   - Exited(code): it called exit(code).
//   - Signaled(signal, core): a signal ended it.
//   - NeverStarted(step, errno): it was made but never ran its program; `step` says what failed
//     (exec, opening its log, entering its folder, its caller gone before it could watch it) and
//     the errno came back from the child over a close-on-exec pipe.
//   - WaitFailed(errno): waitpid failed (the child is not ours to know).
//   ToString() is what people read in logs: "exited with code 3", "killed by signal 9 (Killed)",
//   "never started: No such file or directory", "never started: cannot open its log: Permission
//   denied", "wait failed: No child processes". ShellCode() is the shell's number for it (code,
//   128 + signal, 127 never started or wait failed): for places that must keep one int (a CSV or
//   JSON field, a process's own exit code), never for telling the cases apart.
//
// ChildProcess(args, options): starts `args` (args[0] a path, or a name looked up in PATH; the
// caller's environment plus options.env) and returns once it runs its program or is known never
// to have started: pid() is valid (> 0) when the constructor returns, and with options.own_group
// it is the id of the child's process group too. Never throws; no start fails silently:
// never_started() / Wait() say why.
//   - options.log empty: the child writes to our stdout and stderr; else both go to that file
//     (created 0600 or truncated, never through a symbolic link); options.err_log: stderr alone
//     to that file.
//   - options.own_group: a process group of its own (a terminal's Ctrl-C reaches only the caller,
//     which decides what the child gets), and the child gets options.death_signal (SIGINT) when
//     the thread that started it ends (PR_SET_PDEATHSIG follows that thread, not the process: a
//     caller that needs the child to outlive a thread starts it on a thread that lives as long).
//   - options.nice > 0 lowers its priority (a graph's steps come first).
//   - Nothing of ours leaks into it: every descriptor but 0-2 is closed, SIGINT and SIGTERM are
//     back to their default handling (the caller's signal mask is kept).
// Poll() (without waiting), Wait() and Stop() may be called from any thread, also at once (one
// thread waits while another stops it): the child is reaped exactly once, and no signal is sent
// after that (its pid may name another process then).
// Stop(grace, signal): the one stop policy. Sends `signal` (SIGTERM; SIGINT for a child that ends
// gracefully on it, as dyad does; 0 for none: the caller has already asked) to the child's group
// (own_group) or to the child, waits up to `grace` for its end, then SIGKILLs the group (or the
// child) and waits. Returns how it ended.
// The destructor of a child still running SIGKILLs it (its group) and reaps it: nothing is left
// behind by an early return.
//
//   tools::ChildOptions o;
//   o.log = dir + "/run.log";
//   o.own_group = true;
//   tools::ChildProcess child({"dyad", "run", "graph.yaml"}, o);
//   while (!child.Poll()) { if (stop_asked) return child.Stop(std::chrono::seconds(20), SIGINT); ... }
//   if (!child.Wait().ok()) std::cerr << "dyad run " << child.Wait().ToString() << "\n";
#pragma once

#include <sys/types.h>

#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include <dyad/thread_annotations.hpp>

namespace dyad::tools {

class ExitStatus {
 public:
  enum class Kind { kExited, kSignaled, kNeverStarted, kWaitFailed };
  // What a child that never started failed at.
  enum class StartStep { kExec, kLog, kFolder, kCallerGone };

  ExitStatus() = default;  // exited with code 0
  static ExitStatus Exited(int code);
  static ExitStatus Signaled(int signal, bool core_dumped = false);
  static ExitStatus NeverStarted(StartStep step, int error);
  static ExitStatus WaitFailed(int error);
  static ExitStatus FromWaitStatus(int status);  // waitpid's

  Kind kind() const { return kind_; }
  bool ok() const { return kind_ == Kind::kExited && value_ == 0; }
  bool exited() const { return kind_ == Kind::kExited; }
  bool signaled() const { return kind_ == Kind::kSignaled; }
  bool never_started() const { return kind_ == Kind::kNeverStarted; }
  int code() const { return kind_ == Kind::kExited ? value_ : -1; }     // -1 unless exited
  int signal() const { return kind_ == Kind::kSignaled ? value_ : 0; }  // 0 unless signaled
  int error() const;                              // the errno of a child never started or of a failed wait; else 0
  StartStep start_step() const { return step_; }  // meaningful for kNeverStarted only
  bool ExitedWith(int c) const { return kind_ == Kind::kExited && value_ == c; }
  bool KilledBy(int s) const { return kind_ == Kind::kSignaled && value_ == s; }

  int ShellCode() const;
  std::string ToString() const;
  bool operator==(const ExitStatus& o) const = default;

 private:
  Kind kind_ = Kind::kExited;
  int value_ = 0;  // code, signal or errno
  bool core_ = false;
  StartStep step_ = StartStep::kExec;
};

struct ChildOptions {
  std::string log;               // stdout and stderr to this file ("" : ours)
  std::string err_log;           // stderr alone to this file ("" : as stdout)
  std::string folder;            // its working folder ("" : ours)
  std::vector<std::string> env;  // NAME=value entries added to (or replacing) our environment's
  bool own_group = false;        // a process group of its own, death_signal when its starter ends
  int death_signal = 0;          // 0: SIGINT (with own_group only)
  int nice = 0;                  // > 0: lower its priority by that much (a graph's steps come first)
};

class ChildProcess {
 public:
  explicit ChildProcess(const std::vector<std::string>& args, const ChildOptions& options = {});
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  pid_t pid() const { return pid_; }  // > 0 from the constructor's return; -1 when it never started
  bool own_group() const { return own_group_; }

  std::optional<ExitStatus> Poll();  // its end once it has ended (never waits)
  ExitStatus Wait();
  ExitStatus Stop(std::chrono::milliseconds grace, int signal);
  // Sends `signal` to the child alone (Signal) or to its group when it has one (SignalGroup);
  // false once it has been reaped or when kill fails.
  bool Signal(int signal);
  bool SignalGroup(int signal);

 private:
  std::optional<ExitStatus> Reap(bool wait) EXCLUDES(mutex_);
  bool Kill(pid_t target, int signal) EXCLUDES(mutex_);

  pid_t pid_ = -1;
  bool own_group_ = false;
  Mutex mutex_;                                         // the reaping, and the signals' check that it has not happened
  std::optional<ExitStatus> ended_ GUARDED_BY(mutex_);  // set once: never started, or reaped
};

// `args` started as above and waited for.
ExitStatus RunChild(const std::vector<std::string>& args, const ChildOptions& options = {});

}  // namespace dyad::tools
