#include "run_process.hpp"

#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <sys/prctl.h>
#include <unistd.h>
#include <sys/wait.h>

#include <filesystem>


namespace dyad::tools {

int StartProcess(const std::vector<std::string>& args, const std::string& log, bool own_group) {
  if (args.empty()) return -1;
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const pid_t parent = getpid();
  // SIGINT/SIGTERM blocked across fork: one arriving meanwhile waits for the caller's handler
  // (restored below) instead of running that handler in the child, where it would be lost.
  sigset_t stop_signals, old_mask;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGINT);
  sigaddset(&stop_signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &stop_signals, &old_mask);
  const pid_t pid = fork();
  if (pid != 0) {
    // Also here: a kill(-pid) right after we return must find the group (the child may not
    // have run its own setpgid yet).
    if (pid > 0 && own_group) setpgid(pid, pid);
    pthread_sigmask(SIG_SETMASK, &old_mask, nullptr);
    return pid;  // -1: not started
  }
  // The child, until exec: async-signal-safe calls only.
  signal(SIGINT, SIG_DFL);
  signal(SIGTERM, SIG_DFL);
  pthread_sigmask(SIG_SETMASK, &old_mask, nullptr);
  if (!log.empty()) {
    const int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC | O_NOFOLLOW, 0600);
    if (fd < 0 || dup2(fd, 1) < 0 || dup2(fd, 2) < 0) _exit(127);
  }
  close_range(3, ~0U, 0);  // nothing of ours (a log being read, a socket) leaks into the child
  if (own_group) {
    setpgid(0, 0);
    // Its caller manages its end: when the caller dies, the child is stopped as by Ctrl-C.
    prctl(PR_SET_PDEATHSIG, SIGINT);
    if (getppid() != parent) _exit(127);  // the caller died before prctl
  }
  execvp(argv[0], argv.data());
  _exit(127);
}

int WaitProcess(int pid) {
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return 127;  // a signal handled meanwhile (a study's Ctrl-C) is not the child's end
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

bool ProcessEnded(int pid, int* code) {
  int status = 0;
  const pid_t r = waitpid(pid, &status, WNOHANG);
  if (r == 0 || (r < 0 && errno == EINTR)) return false;
  *code = r < 0 ? 127 : WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return true;
}

int RunProcess(const std::vector<std::string>& args, const std::string& log) {
  const int pid = StartProcess(args, log, false);
  return pid < 0 ? 127 : WaitProcess(pid);
}

std::string ThisExecutable() {
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::string() : exe.string();
}

std::string DyadScriptPath(const std::string& name) {
  const std::filesystem::path exe = ThisExecutable();
  if (exe.empty()) return "/nonexistent/share/dyad/" + name;  // never a script of the working folder
  return (exe.parent_path().parent_path() / "share" / "dyad" / name).string();
}

int RunDyadScript(const std::string& name, const std::vector<std::string>& args) {
  const std::string script = DyadScriptPath(name);
  if (!std::filesystem::exists(script)) return 127;
  // Debian's interpreter first: python3-matplotlib is installed for it, whatever else is on PATH.
  std::vector<std::string> all = {std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3", script};
  all.insert(all.end(), args.begin(), args.end());
  return RunProcess(all);
}

std::string ShellQuoted(const std::vector<std::string>& args) {
  std::string line;
  for (const std::string& a : args) {
    if (!line.empty()) line += ' ';
    const bool plain = !a.empty() && a.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz"
                                                         "0123456789_./=:,+@%-") == std::string::npos;
    if (plain) {
      line += a;
      continue;
    }
    line += '\'';
    for (char c : a) line += c == '\'' ? std::string("'\\''") : std::string(1, c);
    line += '\'';
  }
  return line;
}

}  // namespace dyad::tools
