// The launcher: `dyad run GRAPH` for a graph of several processes, or with processes placed on
// hosts. See run.hpp for what it does; this file is how.
#include "hosts/launcher.hpp"

#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>

#include "dyad/interrupt.hpp"
#include "hosts/launcher_link.hpp"
#include "hosts/output_relay.hpp"
#include "hosts/run_arguments.hpp"

namespace dyad {
namespace {

std::string HostOf(const Graph& g, const std::string& process) {
  for (const auto& pc : g.processes)
    if (pc.name == process) return pc.host;
  return "";
}

// <logs>/<process>.log: --logs (relative to the working folder) or the graph's `logs:`; "" when neither.
std::string LogPathOf(const RunOptions& options, const Graph& graph, const std::string& process) {
  const std::string dir = !options.logs_dir.empty() ? std::filesystem::absolute(options.logs_dir).string() : graph.logs;
  if (dir.empty()) return "";
  return (std::filesystem::path(dir) / (process + ".log")).string();
}

std::string LocalTime() {
  char text[64];
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  localtime_r(&now, &tm);
  std::strftime(text, sizeof(text), "%Y-%m-%d %H:%M:%S", &tm);
  return text;
}

// Starts `args` (argv) as a child of the launcher (see LaunchChildren): `executable`, with its
// stdout and stderr on `pipes`.
pid_t StartChild(const std::string& executable, std::vector<std::string> args, const OutputRelay::Pipes& pipes) {
  // Everything the child needs is built before fork: after it, only exec.
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const std::string failed = "dyad: exec of " + executable + " failed\n";
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid == 0) {
    // Its own process group: a terminal's Ctrl-C reaches the launcher only, which forwards it
    // once (a child hit by both would take the second as "exit now" and skip its clean
    // shutdown). And it ends if the launcher dies (SIGKILL) instead of running on unwatched.
    setpgid(0, 0);
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(1);
    if (pipes.out_write >= 0) dup2(pipes.out_write, STDOUT_FILENO);
    if (pipes.err_write >= 0) dup2(pipes.err_write, STDERR_FILENO);
    // Nothing else of the launcher's: its DDS sockets (LauncherLink), other children's pipes.
    close_range(3, ~0U, 0);
    sigset_t none;
    sigemptyset(&none);
    pthread_sigmask(SIG_SETMASK, &none, nullptr);
    execve(executable.c_str(), argv.data(), environ);
    (void)!write(STDERR_FILENO, failed.data(), failed.size());  // no stdio after fork: its lock may be held
    _exit(127);
  }
  if (pid > 0) setpgid(pid, pid);  // also here: no window in which a Ctrl-C reaches the child directly
  return pid;
}

const ProcessConfig& ConfigOf(const Graph& g, const std::string& process) {
  static const ProcessConfig kDefault;
  for (const auto& pc : g.processes)
    if (pc.name == process) return pc;
  return kDefault;
}

std::string DescribeExit(int code) {
  if (code > 128 && code < 128 + 32) return std::to_string(code) + " (" + SignalName(code - 128) + ")";
  return std::to_string(code);
}

}  // namespace

std::string ThisHost(const RunOptions& options) {
  if (!options.host.empty()) return options.host;
  char host[256] = {0};
  gethostname(host, sizeof(host) - 1);
  return host;
}

// Whether the launcher (not a single in-process run) handles this graph here.
bool NeedsLauncher(const Graph& g, const RunOptions& options) {
  if (g.ProcessNames().size() > 1) return true;
  for (const auto& pc : g.processes)
    if (!pc.host.empty()) return true;
  return g.network.discovery == Discovery::kServer && !g.network.server_host.empty() && RunsHere(g.network.server_host, options);
}

bool RunsHere(const std::string& host, const RunOptions& options) {
  return host.empty() || host == ThisHost(options) || (options.host.empty() && host == "localhost");
}

int LaunchChildren(const RunOptions& options, const Graph& graph, std::ostream& out, std::ostream& err) {
  const std::string host = ThisHost(options);
  std::vector<std::string> names;
  for (const auto& p : graph.ProcessNames()) {
    const std::string where = HostOf(graph, p);
    if (!RunsHere(where, options)) {
      err << "process '" << p << "' runs on host '" << where << "': start it there with `dyad run " << options.graph_path
          << " --host " << where << "`\n";
      continue;
    }
    names.push_back(p);
  }
  const NetworkConfig& net = graph.network;
  const bool runs_server = net.discovery == Discovery::kServer && !net.server_host.empty() && RunsHere(net.server_host, options);
  if (names.empty() && !runs_server) {
    err << options.graph_path << ": no process of the graph is placed on host '" << host << "'\n";
    return 2;
  }
  // `dyad run GRAPH --process P`, with this launcher's options (the launcher alone writes the logs).
  auto child_args = [&](const std::string& p, int restarts) {
    RunOptions child = options;
    child.process = p;
    child.restart_count = restarts;
    child.logs_dir.clear();
    std::vector<std::string> args = RunArguments(child);
    args.insert(args.begin(), "dyad");
    return args;
  };

  // One child per process of this host (and the discovery server, first: the processes retry
  // until it answers anyway). The signal thread and this one share `children` and `stopping`.
  struct Supervised {
    std::string name;
    int restarts = 0;
  };
  std::map<pid_t, Supervised> children;
  struct Pending {
    std::string name;
    int restarts;
    std::chrono::steady_clock::time_point due;
  };
  std::vector<Pending> pending;  // restarts waiting for their back-off
  std::mutex mutex;
  bool stopping = false;
  pid_t server = 0;
  InterruptWatcher interrupt([&](int sig) {
    std::lock_guard<std::mutex> lock(mutex);
    if (stopping) return;  // already told to stop (SIGTERM): a second signal would mean "exit now"
    stopping = true;
    for (const auto& [pid, _] : children) kill(pid, sig);
  });
  // After the watcher: its thread must inherit the blocked signals. Destroyed first, once every
  // child has exited (it reads their pipes to the end).
  OutputRelay relay(out, err);
  auto say = [&](const std::string& line) { relay.Say(line); };
  // Graphs on several hosts: the launchers tell each other of a required process's failure.
  std::unique_ptr<LauncherLink> link;
  if (std::any_of(graph.processes.begin(), graph.processes.end(), [](const ProcessConfig& pc) { return !pc.host.empty(); })) {
    auto l = LauncherLink::Open(graph, host);
    if (l.ok()) link = std::move(l.value());
    else say("warning: " + l.status().message() + ": a failure on another host will not end this host's run");
  }
  auto start = [&](const std::string& name, std::vector<std::string> args, int restarts) {
    const std::string log = LogPathOf(options, graph, name);
    auto pipes = relay.Add(name, log,
                           "=== " + name + " started " + (restarts > 0 ? "(restart " + std::to_string(restarts) + ") " : "") +
                               "at " + LocalTime() + " on host '" + host + "'");
    if (!pipes.ok()) {
      say("cannot start process '" + name + "': " + pipes.status().message());
      return false;
    }
    const pid_t pid = StartChild(options.executable, std::move(args), pipes.value());
    OutputRelay::CloseWriteEnds(pipes.value());
    if (pid < 0) {
      say("cannot start process '" + name + "'");
      return false;
    }
    children[pid] = {name, restarts};
    return true;
  };
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (runs_server) {
      const std::string listen = net.server_address + ":" + std::to_string(net.server_port);
      if (!start("discovery-server", {"dyad", "discovery-server", "--listen", listen}, 0)) return 1;
      server = children.begin()->first;
    }
    for (const auto& p : names)
      if (!stopping) start(p, child_args(p, 0), 0);
  }

  int first_failure = 0;  // the exit code of the first required process that failed for good
  bool stopped_others = false, server_stopped = false;
  auto stop_all = [&](pid_t except) {  // REQUIRES: mutex held
    stopping = stopped_others = true;
    pending.clear();
    for (const auto& [other, _] : children)
      if (other != except) kill(other, SIGTERM);
    if (server != 0 && server != except) server_stopped = true;  // signalled once, here
  };
  for (;;) {
    int status = 0;
    // Reaped under the lock: the signal thread never kill()s a pid already reaped (and reused).
    std::unique_lock<std::mutex> lock(mutex);
    const pid_t pid = waitpid(-1, &status, WNOHANG);
    if (pid <= 0) {
      // Restarts that are due; the discovery server once the graph's processes here are done.
      const auto now = std::chrono::steady_clock::now();
      if (stopping) pending.clear();
      for (auto it = pending.begin(); it != pending.end();) {
        if (it->due > now) {
          ++it;
          continue;
        }
        say("process '" + it->name + "': restarting (restart " + std::to_string(it->restarts) + " of " +
            std::to_string(ConfigOf(graph, it->name).max_restarts) + "): " + ResetClause(graph, it->name));
        start(it->name, child_args(it->name, it->restarts), it->restarts);
        it = pending.erase(it);
      }
      if (server != 0 && !server_stopped && pending.empty() && children.size() == 1 && children.count(server) &&
          !names.empty()) {
        server_stopped = true;
        kill(server, SIGTERM);
      }
      if (children.empty() && pending.empty()) break;
      if (link != nullptr && !stopping) {
        for (const auto& notice : link->TakeRemoteRestarts()) say(notice);
        if (auto failure = link->TakeRemoteFailure()) {
          say(*failure + ": stopping the processes of host '" + host + "'");
          if (first_failure == 0) first_failure = 1;
          stop_all(0);
        }
      }
      lock.unlock();
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      continue;
    }
    const auto found = children.find(pid);
    if (found == children.end()) continue;  // not ours (a process a plugin started, reparented to us)
    const Supervised child = found->second;
    children.erase(found);
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    // Stopped by us (the user's signal forwarded, or SIGTERM after another child failed): not a failure.
    const bool stopped = (interrupt.signal() != 0 && code == ExitCodeForSignal(interrupt.signal())) ||
                         ((stopped_others || (pid == server && server_stopped)) && code == ExitCodeForSignal(SIGTERM));
    if (stopped || stopping) continue;
    const ProcessConfig& pc = ConfigOf(graph, child.name);
    // A clean exit of a run with an end (--steps, --duration) is that end, whatever the policy:
    // `always` restarts clean exits only in runs that go on until Ctrl-C.
    const bool run_has_end = options.steps > 0 || options.duration_s > 0;
    const bool restart = pid != server && ((pc.restart == RestartPolicy::kAlways && (code != 0 || !run_has_end)) ||
                                           (pc.restart == RestartPolicy::kOnFailure && code != 0));
    if (restart && child.restarts < pc.max_restarts) {
      const double backoff = std::min(10.0, pc.backoff_s * std::pow(2.0, child.restarts));
      std::ostringstream line;
      line << "process '" << child.name << "' exited with " << DescribeExit(code) << "; restarting in " << backoff << " s";
      say(line.str());
      pending.push_back({child.name, child.restarts + 1,
                         std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                                std::chrono::duration<double>(backoff))});
      continue;
    }
    if (code == 0) continue;
    const std::string given_up =
        restart ? " (after " + std::to_string(child.restarts) + (child.restarts == 1 ? " restart)" : " restarts)") : "";
    if (pid != server && !pc.required) {
      say("process '" + child.name + "' exited with " + DescribeExit(code) + given_up +
          "; it is not required: the experiment goes on without it");
      continue;
    }
    say("process '" + child.name + "' exited with " + DescribeExit(code) + given_up);
    if (first_failure == 0) first_failure = code;
    // One required process failing ends the experiment: on the other hosts (told first, while
    // this host's discovery server, if any, still runs), then here.
    if (link != nullptr && pid != server) {
      lock.unlock();
      link->AnnounceFailure(child.name, child.restarts);  // milliseconds; at most 2 s
      lock.lock();
      if (stopping) continue;  // a signal came meanwhile and was forwarded: no second one
    }
    stop_all(pid);
  }
  if (first_failure != 0) return first_failure;
  if (interrupt.signal() != 0) {
    say(std::string("dyad run: interrupted (") + SignalName(interrupt.signal()) + ")");
    return ExitCodeForSignal(interrupt.signal());
  }
  return 0;
}

}  // namespace dyad
