#include "hosts/spawner.hpp"

#include <signal.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <ctime>

namespace dyad {
namespace {

std::string LocalTime() {
  char text[64];
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  localtime_r(&now, &tm);
  std::strftime(text, sizeof(text), "%Y-%m-%d %H:%M:%S", &tm);
  return text;
}

// In the child, between fork and exec: only async-signal-safe calls (no allocation, no stdio:
// their locks may be held by a thread of the launcher that the fork did not copy).
[[noreturn]] void ExecChild(pid_t parent, const char* executable, char* const* argv, const OutputRelay::Pipes& pipes,
                            const std::string& failed) {
  setpgid(0, 0);
  prctl(PR_SET_PDEATHSIG, SIGTERM);
  if (getppid() != parent) _exit(1);  // the launcher died before PDEATHSIG was set
  if (pipes.out_write >= 0) dup2(pipes.out_write, STDOUT_FILENO);
  if (pipes.err_write >= 0) dup2(pipes.err_write, STDERR_FILENO);
  close_range(3, ~0U, 0);
  sigset_t none;
  sigemptyset(&none);
  pthread_sigmask(SIG_SETMASK, &none, nullptr);
  execve(executable, argv, environ);
  (void)!write(STDERR_FILENO, failed.data(), failed.size());
  _exit(127);
}

// Starts `args` as a child with its output on `pipes`; its pid, or -1.
pid_t ForkExec(const std::string& executable, std::vector<std::string> args, const OutputRelay::Pipes& pipes) {
  // Everything the child needs is built before fork: after it, only exec.
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const std::string failed = "dyad: exec of " + executable + " failed\n";
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid == 0) ExecChild(parent, executable.c_str(), argv.data(), pipes, failed);
  if (pid > 0) setpgid(pid, pid);  // also here: no window in which a Ctrl-C reaches the child directly
  return pid;
}

}  // namespace

Spawner::Spawner(std::string executable, OutputRelay* relay, std::string host)
    : executable_(std::move(executable)), relay_(relay), host_(std::move(host)) {}

StatusOr<pid_t> Spawner::Start(const std::string& name, std::vector<std::string> args, int restarts,
                               const std::string& log_path) const {
  const std::string header = "=== " + name + " started " +
                             (restarts > 0 ? "(restart " + std::to_string(restarts) + ") " : "") + "at " + LocalTime() +
                             " on host '" + host_ + "'";
  auto pipes = relay_->Add(name, log_path, header);
  if (!pipes.ok()) return Status::Internal("cannot start process '" + name + "': " + pipes.status().message());
  const pid_t pid = ForkExec(executable_, std::move(args), pipes.value());
  OutputRelay::CloseWriteEnds(pipes.value());
  if (pid < 0) return Status::Internal("cannot start process '" + name + "'");
  return pid;
}

}  // namespace dyad
