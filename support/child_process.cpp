#include "child_process.hpp"

#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstring>
#include <thread>

extern char** environ;

namespace dyad::tools {
namespace {

// What a child that cannot run its program sends back before _exit(127).
struct StartFailure {
  int step;
  int error;
};

// Our environment with `extra` (NAME=value) added, an entry of the same NAME replaced.
std::vector<std::string> Environment(const std::vector<std::string>& extra) {
  std::vector<std::string> env;
  for (char** e = environ; *e != nullptr; ++e) {
    const std::string entry = *e;
    const std::string name = entry.substr(0, entry.find('='));
    bool replaced = false;
    for (const std::string& x : extra) replaced = replaced || x.substr(0, x.find('=')) == name;
    if (!replaced) env.push_back(entry);
  }
  env.insert(env.end(), extra.begin(), extra.end());
  return env;
}

// The child, from fork to exec: async-signal-safe calls only (everything it needs was made
// before the fork). On a failure it tells the parent over `report` (close-on-exec: an exec that
// works closes it, which the parent reads as "started").
[[noreturn]] void BecomeChild(char* const* argv, char* const* envp, const ChildOptions& o, const sigset_t& mask, pid_t parent,
                              int report) {
  auto fail = [report](ExitStatus::StartStep step, int error) {
    const StartFailure f{static_cast<int>(step), error};
    [[maybe_unused]] const ssize_t n = write(report, &f, sizeof f);
    _exit(127);
  };
  signal(SIGINT, SIG_DFL);
  signal(SIGTERM, SIG_DFL);
  pthread_sigmask(SIG_SETMASK, &mask, nullptr);
  const int flags = O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC | O_NOFOLLOW;
  if (!o.log.empty()) {
    const int fd = open(o.log.c_str(), flags, 0600);
    if (fd < 0 || dup2(fd, 1) < 0 || dup2(fd, 2) < 0) fail(ExitStatus::StartStep::kLog, errno);
  }
  if (!o.err_log.empty()) {
    const int fd = open(o.err_log.c_str(), flags, 0600);
    if (fd < 0 || dup2(fd, 2) < 0) fail(ExitStatus::StartStep::kLog, errno);
  }
  if (!o.folder.empty() && chdir(o.folder.c_str()) != 0) fail(ExitStatus::StartStep::kFolder, errno);
  // Nothing of ours (a log being read, a socket) leaks into the child; `report` closes on exec.
  if (report > 3) close_range(3, static_cast<unsigned>(report) - 1, 0);
  close_range(static_cast<unsigned>(report) + 1, ~0U, 0);
  if (o.own_group) {
    setpgid(0, 0);
    prctl(PR_SET_PDEATHSIG, o.death_signal != 0 ? o.death_signal : SIGINT);
    if (getppid() != parent) fail(ExitStatus::StartStep::kCallerGone, 0);  // it died before prctl
  }
  if (o.nice > 0) setpriority(PRIO_PROCESS, 0, o.nice);
  execvpe(argv[0], argv, envp);
  fail(ExitStatus::StartStep::kExec, errno);
  _exit(127);  // not reached
}

}  // namespace

ExitStatus ExitStatus::Exited(int code) {
  ExitStatus s;
  s.kind_ = Kind::kExited;
  s.value_ = code;
  return s;
}

ExitStatus ExitStatus::Signaled(int signal, bool core_dumped) {
  ExitStatus s;
  s.kind_ = Kind::kSignaled;
  s.value_ = signal;
  s.core_ = core_dumped;
  return s;
}

ExitStatus ExitStatus::NeverStarted(StartStep step, int error) {
  ExitStatus s;
  s.kind_ = Kind::kNeverStarted;
  s.value_ = error;
  s.step_ = step;
  return s;
}

ExitStatus ExitStatus::WaitFailed(int error) {
  ExitStatus s;
  s.kind_ = Kind::kWaitFailed;
  s.value_ = error;
  return s;
}

ExitStatus ExitStatus::FromWaitStatus(int status) {
  if (WIFSIGNALED(status)) return Signaled(WTERMSIG(status), WCOREDUMP(status));
  return Exited(WEXITSTATUS(status));
}

int ExitStatus::error() const { return kind_ == Kind::kNeverStarted || kind_ == Kind::kWaitFailed ? value_ : 0; }

int ExitStatus::ShellCode() const {
  switch (kind_) {
    case Kind::kExited:
      return value_;
    case Kind::kSignaled:
      return 128 + value_;
    case Kind::kNeverStarted:
    case Kind::kWaitFailed:
      return 127;
  }
  return 127;
}

std::string ExitStatus::ToString() const {
  switch (kind_) {
    case Kind::kExited:
      return "exited with code " + std::to_string(value_);
    case Kind::kSignaled: {
      const char* name = strsignal(value_);
      return "killed by signal " + std::to_string(value_) + (name ? std::string(" (") + name + ")" : "") +
             (core_ ? ", core dumped" : "");
    }
    case Kind::kNeverStarted:
      switch (step_) {
        case StartStep::kExec:
          return std::string("never started: ") + std::strerror(value_);
        case StartStep::kLog:
          return std::string("never started: cannot open its log: ") + std::strerror(value_);
        case StartStep::kFolder:
          return std::string("never started: cannot enter its working folder: ") + std::strerror(value_);
        case StartStep::kCallerGone:
          return "never started: its caller ended before it could watch it";
      }
      break;
    case Kind::kWaitFailed:
      return std::string("wait failed: ") + std::strerror(value_);
  }
  return "?";
}

ChildProcess::ChildProcess(const std::vector<std::string>& args, const ChildOptions& options) : own_group_(options.own_group) {
  MutexLock lock(mutex_);
  if (args.empty()) {
    ended_ = ExitStatus::NeverStarted(ExitStatus::StartStep::kExec, EINVAL);
    return;
  }
  std::vector<std::string> env = options.env.empty() ? std::vector<std::string>{} : Environment(options.env);
  std::vector<char*> argv, envp;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  for (std::string& e : env) envp.push_back(e.data());
  envp.push_back(nullptr);
  char* const* child_env = options.env.empty() ? environ : envp.data();
  int report[2];
  if (pipe2(report, O_CLOEXEC) != 0) {
    ended_ = ExitStatus::NeverStarted(ExitStatus::StartStep::kExec, errno);
    return;
  }
  const pid_t parent = getpid();
  // SIGINT/SIGTERM blocked across fork: one arriving meanwhile waits for the caller's handler
  // (the mask is restored below) instead of running that handler in the child, where it is lost.
  sigset_t stop_signals, old_mask;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGINT);
  sigaddset(&stop_signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &stop_signals, &old_mask);
  const pid_t pid = fork();
  if (pid == 0) BecomeChild(argv.data(), child_env, options, old_mask, parent, report[1]);
  const int fork_error = errno;
  // Also here: a kill(-pid) right after we return finds the group (the child may not have run
  // its own setpgid yet).
  if (pid > 0 && options.own_group) setpgid(pid, pid);
  pthread_sigmask(SIG_SETMASK, &old_mask, nullptr);
  close(report[1]);
  if (pid < 0) {
    close(report[0]);
    ended_ = ExitStatus::NeverStarted(ExitStatus::StartStep::kExec, fork_error);
    return;
  }
  StartFailure failure{};
  ssize_t n;
  while ((n = read(report[0], &failure, sizeof failure)) < 0 && errno == EINTR) {
  }
  close(report[0]);
  if (n != static_cast<ssize_t>(sizeof failure)) {  // 0: the exec closed the pipe
    pid_ = pid;
    return;
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  ended_ = ExitStatus::NeverStarted(static_cast<ExitStatus::StartStep>(failure.step), failure.error);
}

ChildProcess::~ChildProcess() {
  if (pid_ > 0 && !Poll()) {
    SignalGroup(SIGKILL);
    Wait();
  }
}

// waitid with WNOWAIT sees the end without reaping, so a thread that waits and one that polls
// (or stops) may run at once; the reaping itself happens once, under the lock.
std::optional<ExitStatus> ChildProcess::Reap(bool wait) {
  {
    MutexLock lock(mutex_);
    if (ended_) return ended_;
  }
  siginfo_t info{};
  int r;
  while ((r = waitid(P_PID, static_cast<id_t>(pid_), &info, WEXITED | WNOWAIT | (wait ? 0 : WNOHANG))) < 0 && errno == EINTR) {
  }
  const int wait_error = errno;
  MutexLock lock(mutex_);
  if (ended_) return ended_;  // another thread reaped it meanwhile
  if (r < 0) return ended_ = ExitStatus::WaitFailed(wait_error);
  if (info.si_pid == 0) return std::nullopt;  // WNOHANG: still running
  int status = 0;
  pid_t reaped;
  while ((reaped = waitpid(pid_, &status, 0)) < 0 && errno == EINTR) {
  }
  ended_ = reaped < 0 ? ExitStatus::WaitFailed(errno) : ExitStatus::FromWaitStatus(status);
  return ended_;
}

std::optional<ExitStatus> ChildProcess::Poll() { return Reap(false); }

ExitStatus ChildProcess::Wait() { return *Reap(true); }

bool ChildProcess::Kill(pid_t target, int signal) {
  MutexLock lock(mutex_);
  return !ended_ && ::kill(target, signal) == 0;  // not reaped: the pid is still the child's
}

bool ChildProcess::Signal(int signal) { return Kill(pid_, signal); }

bool ChildProcess::SignalGroup(int signal) { return Kill(own_group_ ? -pid_ : pid_, signal); }

ExitStatus ChildProcess::Stop(std::chrono::milliseconds grace, int signal) {
  if (signal != 0) SignalGroup(signal);
  const auto deadline = std::chrono::steady_clock::now() + grace;
  while (std::chrono::steady_clock::now() < deadline) {
    if (std::optional<ExitStatus> end = Poll()) return *end;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  SignalGroup(SIGKILL);
  return Wait();
}

ExitStatus RunChild(const std::vector<std::string>& args, const ChildOptions& options) {
  return ChildProcess(args, options).Wait();
}

}  // namespace dyad::tools
