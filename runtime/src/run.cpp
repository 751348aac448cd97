// `dyad run` and `dyad validate`: load, validate, then run in this process or launch one child
// per process of the graph.
#include "dyad/run.hpp"

#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include "dyad/catalog.hpp"
#include "dyad/interrupt.hpp"
#include "dyad/validate.hpp"
#include "executor.hpp"

namespace dyad {
namespace {

struct Loaded {
  Graph graph;
  Catalog catalog;
  ResolvedGraph resolved;
};

// Returns false (after printing every problem) when the graph is invalid.
// `process`: dry-configure only the components of that process (see DryConfigure); empty: all.
bool LoadAndValidate(const std::string& path, const std::vector<Override>& overrides,
                     const std::vector<std::string>& plugin_paths, Loaded* l, std::ostream& err,
                     const std::string& process = "") {
  std::vector<Diagnostic> diags;
  l->graph = LoadGraph(path, overrides, &diags);
  // Plugins the graph or the command line names must load: their problems are the graph's.
  for (size_t i = 0; i < l->graph.plugins.size(); ++i)
    if (Status s = l->catalog.Load(l->graph.plugins[i]); !s.ok()) diags.push_back({l->graph.plugin_marks[i], "plugins", s.message()});
  for (const auto& p : plugin_paths)
    if (Status s = l->catalog.Load(p); !s.ok()) diags.push_back({SourceMark{"--plugins " + p, 0, 0}, "", s.message()});
  // DYAD_PLUGIN_PATH and the built-in folder: a stray file there is worth a warning only.
  if (Status s = l->catalog.LoadDefault({}); !s.ok()) err << "warning: " << s.message() << "\n";
  if (!l->graph.components.empty()) {
    l->resolved = ValidateGraph(l->graph, l->catalog, &diags);
    DryConfigure(l->graph, l->resolved, l->catalog, &diags, process);
  }
  for (const auto& d : diags) err << d.ToString() << "\n";
  if (!diags.empty()) err << path << ": " << diags.size() << " problem" << (diags.size() == 1 ? "" : "s") << ", nothing was started\n";
  return diags.empty();
}

std::set<std::string> ProcessesOf(const Graph& g) {
  std::set<std::string> out;
  for (const auto& c : g.components) out.insert(g.ProcessOf(c));
  return out;
}

void PrintReport(const std::vector<Executor::Row>& rows, const std::string& process, std::ostream& out) {
  out << "timing (process " << process << "):\n";
  out << std::left << std::setw(20) << "component" << std::right << std::setw(9) << "steps" << std::setw(12) << "mean_ms"
      << std::setw(12) << "p99_ms" << std::setw(12) << "max_ms" << std::setw(13) << "jitter_ms" << std::setw(15)
      << "jitter_max_ms" << std::setw(8) << "misses" << "\n";
  out << std::fixed << std::setprecision(3);
  for (const auto& r : rows)
    out << std::left << std::setw(20) << r.component << std::right << std::setw(9) << r.stats.steps << std::setw(12)
        << r.stats.mean_s * 1e3 << std::setw(12) << r.stats.p99_s * 1e3 << std::setw(12) << r.stats.max_s * 1e3
        << std::setw(13) << r.stats.jitter_mean_s * 1e3 << std::setw(15) << r.stats.jitter_max_s * 1e3 << std::setw(8)
        << r.stats.deadline_misses << "\n";
  for (const auto& r : rows)
    if (r.stats.deliveries > 0)
      out << "callbacks " << r.component << ": " << r.stats.deliveries << ", mean " << r.stats.delivery_mean_s * 1e3
          << " ms, max " << r.stats.delivery_max_s * 1e3 << " ms\n";
  out.unsetf(std::ios::fixed);
}

std::string ThisHost(const RunOptions& options) {
  if (!options.host.empty()) return options.host;
  char host[256] = {0};
  gethostname(host, sizeof(host) - 1);
  return host;
}

std::string HostOf(const Graph& g, const std::string& process) {
  for (const auto& pc : g.processes)
    if (pc.name == process) return pc.host;
  return "";
}

// Whether the launcher (not a single in-process run) handles this graph here.
bool NeedsLauncher(const Graph& g, const std::string& this_host) {
  if (ProcessesOf(g).size() > 1) return true;
  for (const auto& pc : g.processes)
    if (!pc.host.empty()) return true;
  return !g.network.server_host.empty() && g.network.server_host == this_host;
}

// Starts `args` as a child of the launcher (see LaunchChildren), with `restarts` in its
// environment (DYAD_RESTARTS: it announces the count on dyad/processes).
pid_t StartChild(std::vector<std::string> args, int restarts = 0) {
  // Everything the child needs is built before fork: after it, only exec.
  std::vector<std::string> env;
  for (char** e = environ; *e != nullptr; ++e)
    if (std::string(*e).rfind("DYAD_RESTARTS=", 0) != 0) env.emplace_back(*e);
  env.push_back("DYAD_RESTARTS=" + std::to_string(restarts));
  std::vector<char*> envp;
  for (auto& e : env) envp.push_back(e.data());
  envp.push_back(nullptr);
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid == 0) {
    // Its own process group: a terminal's Ctrl-C reaches the launcher only, which forwards it
    // once (a child hit by both would take the second as "exit now" and skip its clean
    // shutdown). And it ends if the launcher dies (SIGKILL) instead of running on unwatched.
    setpgid(0, 0);
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(1);
    sigset_t none;
    sigemptyset(&none);
    pthread_sigmask(SIG_SETMASK, &none, nullptr);
    execve("/proc/self/exe", argv.data(), envp.data());
    std::perror("dyad: exec");
    _exit(127);
  }
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

int LaunchChildren(const RunOptions& options, const Loaded& l, std::ostream& err) {
  const std::string host = ThisHost(options);
  std::vector<std::string> names;
  for (const auto& p : ProcessesOf(l.graph)) {
    const std::string where = HostOf(l.graph, p);
    if (!where.empty() && where != host && !(options.host.empty() && where == "localhost")) {
      err << "process '" << p << "' runs on host '" << where << "': start it there with `dyad run " << options.graph_path
          << " --host " << where << "`\n";
      continue;
    }
    names.push_back(p);
  }
  const NetworkConfig& net = l.graph.network;
  const bool runs_server = net.discovery == Discovery::kServer && !net.server_host.empty() && net.server_host == host;
  if (names.empty() && !runs_server) {
    err << options.graph_path << ": no process of the graph is placed on host '" << host << "'\n";
    return 2;
  }
  auto child_args = [&](const std::string& p) {
    std::vector<std::string> args = {"dyad", "run", options.graph_path, "--process", p};
    for (const auto& o : options.overrides) args.insert(args.end(), {"--set", o.text});
    for (const auto& pp : options.plugin_paths) args.insert(args.end(), {"--plugins", pp});
    if (options.duration_s > 0) args.insert(args.end(), {"--duration", std::to_string(options.duration_s)});
    if (options.steps > 0) args.insert(args.end(), {"--steps", std::to_string(options.steps)});
    if (options.quiet) args.push_back("--quiet");
    if (!options.host.empty()) args.insert(args.end(), {"--host", options.host});
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
    stopping = true;
    for (const auto& [pid, _] : children) kill(pid, sig);
  });
  auto start = [&](const std::string& name, std::vector<std::string> args, int restarts) {
    const pid_t pid = StartChild(std::move(args), restarts);
    if (pid < 0) {
      err << "cannot start process '" << name << "'\n";
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
      if (!stopping) start(p, child_args(p), 0);
  }

  int first_failure = 0;  // the exit code of the first required process that failed for good
  bool stopped_others = false, server_stopped = false;
  auto stop_all = [&](pid_t except) {  // REQUIRES: mutex held
    stopping = stopped_others = true;
    pending.clear();
    for (const auto& [other, _] : children)
      if (other != except) kill(other, SIGTERM);
  };
  for (;;) {
    int status = 0;
    const pid_t pid = waitpid(-1, &status, WNOHANG);
    std::lock_guard<std::mutex> lock(mutex);
    if (pid <= 0) {
      // Restarts that are due; the discovery server once the graph's processes here are done.
      const auto now = std::chrono::steady_clock::now();
      if (stopping) pending.clear();
      for (auto it = pending.begin(); it != pending.end();) {
        if (it->due > now) {
          ++it;
          continue;
        }
        err << "process '" << it->name << "': restarting (restart " << it->restarts << " of "
            << ConfigOf(l.graph, it->name).max_restarts << ")\n";
        start(it->name, child_args(it->name), it->restarts);
        it = pending.erase(it);
      }
      if (server != 0 && !server_stopped && pending.empty() && children.size() == 1 && children.count(server) &&
          !names.empty()) {
        server_stopped = true;
        kill(server, SIGTERM);
      }
      if (children.empty() && pending.empty()) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      continue;
    }
    const Supervised child = children[pid];
    children.erase(pid);
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    // Stopped by us (the user's signal forwarded, or SIGTERM after another child failed): not a failure.
    const bool stopped = (interrupt.signal() != 0 && code == ExitCodeForSignal(interrupt.signal())) ||
                         ((stopped_others || (pid == server && server_stopped)) && code == ExitCodeForSignal(SIGTERM));
    if (stopped || stopping) continue;
    const ProcessConfig& pc = ConfigOf(l.graph, child.name);
    const bool restart = pid != server && (pc.restart == RestartPolicy::kAlways ||
                                           (pc.restart == RestartPolicy::kOnFailure && code != 0));
    if (restart && child.restarts < pc.max_restarts) {
      const double backoff = std::min(10.0, pc.backoff_s * std::pow(2.0, child.restarts));
      err << "process '" << child.name << "' exited with " << DescribeExit(code) << "; restarting in " << backoff << " s\n";
      pending.push_back({child.name, child.restarts + 1,
                         std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                                std::chrono::duration<double>(backoff))});
      continue;
    }
    if (code == 0) continue;
    const std::string given_up = restart ? " (after " + std::to_string(child.restarts) + " restarts)" : "";
    if (pid != server && !pc.required) {
      err << "process '" << child.name << "' exited with " << DescribeExit(code) << given_up
          << "; it is not required: the experiment goes on without it\n";
      continue;
    }
    err << "process '" << child.name << "' exited with " << DescribeExit(code) << given_up << "\n";
    if (first_failure == 0) first_failure = code;
    stop_all(pid);  // one required process failing ends the experiment
  }
  if (first_failure != 0) return first_failure;
  if (interrupt.signal() != 0) {
    err << "dyad run: interrupted (" << SignalName(interrupt.signal()) << ")\n";
    return ExitCodeForSignal(interrupt.signal());
  }
  return 0;
}

}  // namespace

int ExitCodeOf(const Status& status) {
  switch (status.code()) {
    case Status::Code::kOk: return 0;
    case Status::Code::kInvalidArgument:
    case Status::Code::kNotFound:
    case Status::Code::kDataLoss: return 2;
    default: return 1;
  }
}

int ValidateGraphFile(const std::string& path, const std::vector<Override>& overrides,
                      const std::vector<std::string>& plugin_paths, std::ostream& out, std::ostream& err) {
  Loaded l;
  if (!LoadAndValidate(path, overrides, plugin_paths, &l, err)) return 2;
  out << path << ": OK (" << l.graph.components.size() << " components, " << l.resolved.topics.size() << " topics, "
      << ProcessesOf(l.graph).size() << " process" << (ProcessesOf(l.graph).size() == 1 ? "" : "es") << ")\n";
  return 0;
}

int RunGraph(const RunOptions& options, std::ostream& out, std::ostream& err) {
  Loaded l;
  // The launcher (no --process) checks every component before starting any child; a child checks
  // its own (the others' files may already be open in their processes).
  if (!LoadAndValidate(options.graph_path, options.overrides, options.plugin_paths, &l, err, options.process)) return 2;
  const std::set<std::string> procs = ProcessesOf(l.graph);
  std::string process = options.process;
  if (process.empty()) {
    if (NeedsLauncher(l.graph, ThisHost(options))) return LaunchChildren(options, l, err);
    process = *procs.begin();
  } else if (!procs.count(process)) {
    std::string list;
    for (const auto& p : procs) list += (list.empty() ? "" : ", ") + p;
    err << options.graph_path << ": --process " << process << ": no component is placed there (processes: " << list << ")\n";
    return 2;
  }
  Executor::Options eo;
  eo.process = process;
  eo.host = ThisHost(options);
  eo.duration_s = options.duration_s;
  eo.steps = options.steps;
  eo.stats_period_s = options.stats_period_s;
  std::atomic<Executor*> current{nullptr};
  Status result;
  std::vector<Executor::Row> rows;
  int mismatches = 0, signal = 0;
  {
    InterruptWatcher interrupt([&](int sig) {
      if (Executor* ex = current.load()) ex->RequestStop(SignalName(sig));
    });
    Executor ex(l.graph, l.resolved, &l.catalog, eo);
    current.store(&ex);
    if (interrupt.signal() != 0) ex.RequestStop(SignalName(interrupt.signal()));  // before `current` was set
    result = ex.Run();
    rows = ex.Report();
    mismatches = ex.type_mismatches();
    current.store(nullptr);
    signal = interrupt.signal();
  }
  if (!options.quiet) PrintReport(rows, process, out);
  if (signal != 0) {
    // A person stopped it: the run ended cleanly (recordings closed), but it did not finish.
    err << "dyad run: interrupted (" << SignalName(signal) << ")" << (result.ok() ? "" : ": " + result.message()) << "\n";
    return ExitCodeForSignal(signal);
  }
  if (!result.ok()) {
    err << "dyad run: " << result.message() << "\n";
    return ExitCodeOf(result);
  }
  if (mismatches > 0) {
    err << "dyad run: " << mismatches << " type/QoS mismatch(es) with peers (see above)\n";
    return 1;
  }
  return 0;
}

}  // namespace dyad
