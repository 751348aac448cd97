// The launcher: `dyad run GRAPH` for a graph of several processes, or with processes placed on
// hosts. See run.hpp for what it does; this file is how: the children are started by the
// Spawner (spawner.hpp), what an exit means is decided by the supervisor (supervisor.hpp), and
// Supervision below carries it out in a loop of short steps.
#include "hosts/launcher.hpp"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <map>
#include <mutex>
#include <thread>

#include "dyad/interrupt.hpp"
#include "dyad/security.hpp"
#include "dyad/thread_annotations.hpp"
#include "hosts/launcher_link.hpp"
#include "hosts/output_relay.hpp"
#include "hosts/run_arguments.hpp"
#include "hosts/spawner.hpp"
#include "hosts/supervisor.hpp"

namespace dyad {
namespace {

using SteadyTime = std::chrono::steady_clock::time_point;

// How often the launcher looks for exited children, due restarts and the other hosts' news.
constexpr std::chrono::milliseconds kPollPeriod{20};
constexpr char kServerName[] = "discovery-server";

// A process's config; the defaults for one the graph's `processes:` does not list.
const ProcessConfig& ConfigOf(const Graph& g, const std::string& process) {
  static const ProcessConfig kDefault;
  const ProcessConfig* pc = g.FindProcess(process);
  return pc != nullptr ? *pc : kDefault;
}

// <logs>/<process>.log: --logs (relative to the working folder) or the graph's `logs:`; "" when neither.
std::string LogPathOf(const RunOptions& options, const Graph& graph, const std::string& process) {
  const std::string dir = !options.logs_dir.empty() ? std::filesystem::absolute(options.logs_dir).string() : graph.logs;
  if (dir.empty()) return "";
  return (std::filesystem::path(dir) / (process + ".log")).string();
}

// The processes of the graph placed on this host; says where each other one runs.
std::vector<std::string> ProcessesHere(const RunOptions& options, const Graph& graph, std::ostream& err) {
  std::vector<std::string> names;
  for (const auto& p : graph.ProcessNames()) {
    const std::string where = ConfigOf(graph, p).host;
    if (!RunsHere(where, options)) {
      err << "process '" << p << "' runs on host '" << where << "': start it there with `dyad run " << options.graph_path
          << " --host " << where << "`\n";
      continue;
    }
    names.push_back(p);
  }
  return names;
}

// In a secured graph, whether the keystore holds the identities of this host's launcher and of
// `names`: a subset exported for another machine does not (dyad/security.hpp); says each one
// missing, and the export that gives it, before anything starts.
bool IdentitiesHeld(const RunOptions& options, const Graph& graph, const std::vector<std::string>& names, std::ostream& err) {
  if (!graph.security.enabled()) return true;
  std::vector<std::string> needed;
  if (auto host = HostIdentityFor(graph, ThisHost(options)); host.ok()) needed.push_back(host.value());
  for (const std::string& p : names) needed.push_back(ProcessIdentity(p));
  bool ok = true;
  for (const std::string& identity : needed)
    if (Status s = CheckIdentityHeld(graph, identity); !s.ok()) {
      err << options.graph_path << ": " << s.message() << "\n";
      ok = false;
    }
  return ok;
}

bool RunsServerHere(const Graph& graph, const RunOptions& options) {
  const NetworkConfig& net = graph.network;
  return net.discovery == Discovery::kServer && !net.server_host.empty() && RunsHere(net.server_host, options);
}

// One launch: the children of this host (and the discovery server, first: the processes retry
// until it answers anyway), supervised until the last one exited. The signal thread (interrupt_)
// and the loop share children_ and stopping_ under mutex_ (GUARDED_BY: clang checks it); everything
// else is the loop's.
class Supervision {
 public:
  Supervision(const RunOptions& options, const Graph& graph, std::vector<std::string> names, bool runs_server,
              std::ostream& out, std::ostream& err);
  // The exit code of the run.
  int Run();

 private:
  struct Child {
    std::string name;
    int restarts = 0;
  };
  struct PendingRestart {
    std::string name;
    int restarts;
    SteadyTime due;
  };

  void ForwardSignal(int sig) EXCLUDES(mutex_);
  void OpenLink();
  bool StartAll() EXCLUDES(mutex_);
  bool Spawn(const std::string& name, std::vector<std::string> args, int restarts) REQUIRES(mutex_);
  std::vector<std::string> ChildArguments(const std::string& process, int restarts) const;
  void OnExit(pid_t pid, int status) REQUIRES(mutex_);
  // Releases mutex_ while it tells the other hosts, and takes it again.
  void StopAfterFailure(const ExitDecision& d, pid_t pid, const Child& child) REQUIRES(mutex_);
  void StartDueRestarts(SteadyTime now) REQUIRES(mutex_);
  void StopServerWhenDone() REQUIRES(mutex_);
  void HearOtherHosts() REQUIRES(mutex_);
  void StopAll(pid_t except) REQUIRES(mutex_);
  int ExitCode();
  void Say(const std::string& line) { relay_.Say(line); }

  const RunOptions& options_;
  const Graph& graph_;
  const std::string host_;
  const std::vector<std::string> names_;  // the processes of this host
  const bool runs_server_;
  Mutex mutex_;
  std::map<pid_t, Child> children_ GUARDED_BY(mutex_);
  bool stopping_ GUARDED_BY(mutex_) = false;  // the user's signal was forwarded, or every child was told to stop
  std::vector<PendingRestart> pending_;  // restarts waiting for their back-off
  pid_t server_ = 0;
  int first_failure_ = 0;  // the exit code of the first required process that failed for good
  bool stopped_others_ = false, server_stopped_ = false;
  // After what its callback touches. The relay after the watcher: its thread must inherit the
  // blocked signals; destroyed before it, once every child has exited (it reads their pipes to
  // the end).
  InterruptWatcher interrupt_;
  OutputRelay relay_;
  Spawner spawner_;
  // Graphs on several hosts: the launchers tell each other of a required process's failure.
  std::unique_ptr<LauncherLink> link_;
};

Supervision::Supervision(const RunOptions& options, const Graph& graph, std::vector<std::string> names, bool runs_server,
                         std::ostream& out, std::ostream& err)
    : options_(options),
      graph_(graph),
      host_(ThisHost(options)),
      names_(std::move(names)),
      runs_server_(runs_server),
      interrupt_([this](int sig) { ForwardSignal(sig); }),
      relay_(out, err),
      spawner_(options.executable, &relay_, host_) {}

void Supervision::ForwardSignal(int sig) {
  MutexLock lock(mutex_);
  if (stopping_) return;  // already told to stop (SIGTERM): a second signal would mean "exit now"
  stopping_ = true;
  for (const auto& [pid, _] : children_) kill(pid, sig);
}

int Supervision::Run() {
  OpenLink();
  if (!StartAll()) return 1;
  for (;;) {
    // Reaped under the lock: the signal thread never kill()s a pid already reaped (and reused).
    UniqueLock lock(mutex_);
    int status = 0;
    if (const pid_t pid = waitpid(-1, &status, WNOHANG); pid > 0) {
      OnExit(pid, status);
      continue;
    }
    StartDueRestarts(std::chrono::steady_clock::now());
    StopServerWhenDone();
    if (children_.empty() && pending_.empty()) break;
    HearOtherHosts();
    lock.Unlock();
    std::this_thread::sleep_for(kPollPeriod);
  }
  return ExitCode();
}

void Supervision::OpenLink() {
  if (!graph_.PlacedOnHosts()) return;
  auto link = LauncherLink::Open(graph_, host_);
  if (link.ok()) link_ = std::move(link.value());
  else Say("warning: " + link.status().message() + ": a failure on another host will not end this host's run");
}

bool Supervision::StartAll() {
  MutexLock lock(mutex_);
  if (runs_server_) {
    const NetworkConfig& net = graph_.network;
    const std::string listen = net.server_address + ":" + std::to_string(net.server_port);
    if (!Spawn(kServerName, {"dyad", "discovery-server", "--listen", listen}, 0)) return false;
    server_ = children_.begin()->first;
  }
  for (const auto& p : names_)
    if (!stopping_) Spawn(p, ChildArguments(p, 0), 0);
  return true;
}

bool Supervision::Spawn(const std::string& name, std::vector<std::string> args, int restarts) {
  auto pid = spawner_.Start(name, std::move(args), restarts, LogPathOf(options_, graph_, name));
  if (!pid.ok()) {
    Say(pid.status().message());
    return false;
  }
  children_[pid.value()] = {name, restarts};
  return true;
}

// `dyad run GRAPH --process P`, with this launcher's options (the launcher alone writes the logs).
std::vector<std::string> Supervision::ChildArguments(const std::string& process, int restarts) const {
  RunOptions child = options_;
  child.process = process;
  child.restart_count = restarts;
  child.logs_dir.clear();
  std::vector<std::string> args = RunArguments(child);
  args.insert(args.begin(), "dyad");
  return args;
}

void Supervision::OnExit(pid_t pid, int status) {
  const auto found = children_.find(pid);
  if (found == children_.end()) return;  // not ours (a process a plugin started, reparented to us)
  const Child child = found->second;
  children_.erase(found);
  const ChildExit exit{child.name, child.restarts, WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status),
                       pid == server_};
  const LauncherState state{options_.steps > 0 || options_.duration_s > 0, stopping_, interrupt_.signal(), stopped_others_,
                            server_stopped_};
  const ExitDecision d = DecideExit(exit, ConfigOf(graph_, child.name), state);
  if (!d.message.empty()) Say(d.message);
  switch (d.action) {
    case ExitDecision::Action::kIgnore:
    case ExitDecision::Action::kGoOn: return;
    case ExitDecision::Action::kRestart:
      pending_.push_back({child.name, d.restart,
                          std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                                  std::chrono::duration<double>(d.backoff_s))});
      return;
    case ExitDecision::Action::kStopAll:
      StopAfterFailure(d, pid, child);
      return;
  }
}

// One required process failing ends the experiment: on the other hosts (told first, while this
// host's discovery server, if any, still runs), then here.
void Supervision::StopAfterFailure(const ExitDecision& d, pid_t pid, const Child& child) {
  if (first_failure_ == 0) first_failure_ = d.exit_code;
  if (d.announce && link_ != nullptr) {
    // The caller's lock is released for the announcement and held again on return.
    mutex_.Unlock();
    link_->AnnounceFailure(child.name, child.restarts);  // milliseconds; at most 2 s
    mutex_.Lock();
    if (stopping_) return;  // a signal came meanwhile and was forwarded: no second one
  }
  StopAll(pid);
}

void Supervision::StartDueRestarts(SteadyTime now) {
  if (stopping_) pending_.clear();
  for (auto it = pending_.begin(); it != pending_.end();) {
    if (it->due > now) {
      ++it;
      continue;
    }
    Say("process '" + it->name + "': restarting (restart " + std::to_string(it->restarts) + " of " +
        std::to_string(ConfigOf(graph_, it->name).max_restarts) + "): " + ResetClause(graph_, it->name));
    Spawn(it->name, ChildArguments(it->name, it->restarts), it->restarts);
    it = pending_.erase(it);
  }
}

// The discovery server ends once the graph's processes here are done (none left, none due).
void Supervision::StopServerWhenDone() {
  if (server_ == 0 || server_stopped_ || names_.empty() || !pending_.empty()) return;
  if (children_.size() != 1 || children_.count(server_) == 0) return;
  server_stopped_ = true;
  kill(server_, SIGTERM);
}

void Supervision::HearOtherHosts() {
  if (link_ == nullptr || stopping_) return;
  for (const auto& notice : link_->TakeRemoteRestarts()) Say(notice);
  if (auto failure = link_->TakeRemoteFailure()) {
    const ExitDecision d = DecideRemoteFailure(*failure, host_);
    Say(d.message);
    if (first_failure_ == 0) first_failure_ = d.exit_code;
    StopAll(0);
  }
}

// SIGTERM to every child but `except` (the one that failed); no restart after it.
void Supervision::StopAll(pid_t except) {
  stopping_ = stopped_others_ = true;
  pending_.clear();
  for (const auto& [other, _] : children_)
    if (other != except) kill(other, SIGTERM);
  if (server_ != 0 && server_ != except) server_stopped_ = true;  // signalled once, here
}

int Supervision::ExitCode() {
  if (first_failure_ != 0) return first_failure_;
  if (interrupt_.signal() != 0) {
    Say(std::string("dyad run: interrupted (") + SignalName(interrupt_.signal()) + ")");
    return ExitCodeForSignal(interrupt_.signal());
  }
  return 0;
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
  return g.ProcessNames().size() > 1 || g.PlacedOnHosts() || RunsServerHere(g, options);
}

bool RunsHere(const std::string& host, const RunOptions& options) {
  return host.empty() || host == ThisHost(options) || (options.host.empty() && host == "localhost");
}

int LaunchChildren(const RunOptions& options, const Graph& graph, std::ostream& out, std::ostream& err) {
  std::vector<std::string> names = ProcessesHere(options, graph, err);
  const bool runs_server = RunsServerHere(graph, options);
  if (names.empty() && !runs_server) {
    err << options.graph_path << ": no process of the graph is placed on host '" << ThisHost(options) << "'\n";
    return 2;
  }
  if (!IdentitiesHeld(options, graph, names, err)) return 2;
  Supervision supervision(options, graph, std::move(names), runs_server, out, err);
  return supervision.Run();
}

}  // namespace dyad
