// `dyad run` and `dyad validate`: load, validate, then run in this process or launch one child
// per process of the graph.
#include "dyad/run.hpp"
#include "dyad/join_list.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <mutex>
#include <random>
#include <set>
#include <sstream>
#include <thread>

#include "dyad/catalog.hpp"
#include "dyad/interrupt.hpp"
#include "dyad/security.hpp"
#include "dyad/validate.hpp"
#include "exec/executor.hpp"
#include "graph/run_partition.hpp"
#include "hosts/graph_session.hpp"
#include "hosts/launcher.hpp"
#include "hosts/process_run.hpp"

namespace dyad {
namespace {

struct Loaded {
  Graph graph;
  Catalog catalog;
  ResolvedGraph resolved;
};

// The processes whose components a run here dry-configures (DryConfigure; empty: all): --process
// P: P; a launcher of a graph placed on hosts: the processes of this host; else all.
std::set<std::string> ProcessesToCheck(const Graph& g, const RunOptions* run) {
  if (run == nullptr) return {};
  if (!run->process.empty()) return {run->process};
  if (!g.PlacedOnHosts()) return {};
  std::set<std::string> here;
  for (const auto& p : g.ProcessNames())
    if (const ProcessConfig* pc = g.FindProcess(p); pc != nullptr && RunsHere(pc->host, *run)) here.insert(p);
  return here.empty() ? std::set<std::string>{""} : here;  // {""}: none (only the discovery server)
}

// A keystore subset exported for host H (`dyad security export --host H`) says which host this
// machine is: without --host, `dyad run` runs H's processes with H's identity, as the watchers
// join as H; one line says so. The launcher gives --host H to its children. An explicit --host
// stays what it says (a host the subset does not hold is refused, naming the export that gives
// it). A guest's subset, a whole keystore, an unreadable subset.yaml (CheckKeystore says why) or
// the subset of a graph on one machine (host.local: any name gets that identity) change nothing.
void AdoptSubsetHost(const Graph& g, RunOptions* run, std::ostream& err) {
  if (run == nullptr || !run->host.empty() || !g.security.enabled()) return;
  auto subset = ReadKeystoreSubset(g.security.keystore);
  if (!subset.ok() || subset.value().whole || subset.value().host.empty() || subset.value().host == kLocalHost) return;
  run->host = subset.value().host;
  err << "dyad run: running as host '" << run->host << "', the host keystore " << g.security.keystore << " was exported for ("
      << (std::filesystem::path(g.security.keystore) / kSubsetFile).string() << ")\n";
}

// Returns false (after printing every problem) when the graph is invalid. `run`: what runs here
// (see ProcessesToCheck; its host is taken from a keystore subset when it names none:
// AdoptSubsetHost); null: everything is checked (`dyad validate`).
// kBuiltinOnly (validate --no-plugins): a component whose type no built-in plugin has cannot be
// checked; its "unknown component type" becomes a note, and the rest of the graph is validated.
void NoteUncheckedComponents(const Graph& g, std::vector<Diagnostic>* diags, std::ostream& err) {
  for (size_t i = 0; i < g.plugins.size(); ++i)
    err << g.plugin_marks[i].ToString() << ": note: plugin not loaded (--no-plugins): " << g.plugins[i] << "\n";
  std::vector<Diagnostic> kept;
  for (auto& d : *diags) {
    if (d.message.rfind("unknown component type", 0) == 0)
      err << d.mark.ToString() << ": " << d.key << ": note: not checked: its type is not built in (--no-plugins)\n";
    else
      kept.push_back(std::move(d));
  }
  *diags = std::move(kept);
}

bool LoadAndValidate(const std::string& path, const std::vector<Override>& overrides,
                     const std::vector<std::string>& plugin_paths, Loaded* l, std::ostream& err, RunOptions* run = nullptr,
                     PluginLoading loading = PluginLoading::kAll) {
  std::vector<Diagnostic> diags;
  l->graph = LoadGraph(path, overrides, &diags);
  if (diags.empty()) AdoptSubsetHost(l->graph, run, err);
  if (loading == PluginLoading::kBuiltinOnly) {
    if (Status s = l->catalog.Load(Catalog::BuiltinPluginDir()); !s.ok()) err << "warning: " << s.message() << "\n";
  } else {
    // Plugins the graph or the command line names must load: their problems are the graph's.
    for (size_t i = 0; i < l->graph.plugins.size(); ++i)
      if (Status s = l->catalog.Load(l->graph.plugins[i]); !s.ok()) diags.push_back({l->graph.plugin_marks[i], "plugins", s.message()});
    for (const auto& p : plugin_paths)
      if (Status s = l->catalog.Load(p); !s.ok()) diags.push_back({SourceMark{"--plugins " + p, 0, 0}, "", s.message()});
    // DYAD_PLUGIN_PATH and the built-in folder: a stray file there is worth a warning only.
    if (Status s = l->catalog.LoadDefault({}); !s.ok()) err << "warning: " << s.message() << "\n";
  }
  if (!l->graph.components.empty()) {
    l->resolved = ValidateGraph(l->graph, l->catalog, &diags);
    DryConfigure(l->graph, l->resolved, l->catalog, &diags, ProcessesToCheck(l->graph, run));
  }
  if (loading == PluginLoading::kBuiltinOnly) NoteUncheckedComponents(l->graph, &diags, err);
  // A launcher's children validate again: the warnings are said once, by the command a person ran.
  if (diags.empty() && (run == nullptr || run->process.empty()))
    for (const auto& w : l->resolved.warnings) err << "warning: " << w.ToString() << "\n";
  for (const auto& d : diags) err << d.ToString() << "\n";
  if (!diags.empty()) err << path << ": " << diags.size() << " problem" << (diags.size() == 1 ? "" : "s") << ", nothing was started\n";
  return diags.empty();
}

// A graph on one host gets a run of its own (two copies side by side do not mix); the launchers
// of a graph on several hosts cannot agree on a drawn id, so they share kSharedRun.
std::string DefaultRunId(const Graph& g) {
  std::set<std::string> hosts;
  for (const auto& p : g.processes) hosts.insert(p.host);
  if (hosts.size() > 1) return kSharedRun;
  std::random_device random;
  char id[16];
  std::snprintf(id, sizeof(id), "%08x", static_cast<unsigned>(random()));
  return id;
}

// A component that never stepped in a run that went to its end is a hole in the wiring (a trigger
// whose topic nobody wrote, a rate slower than the run): named, as a warning or (--strict) an
// error. Returns how many.
int ReportIdleComponents(const std::vector<Executor::Row>& rows, const Graph& g, const std::string& process, bool strict,
                         std::ostream& err) {
  int idle = 0;
  for (const auto& row : rows) {
    if (row.stats.steps > 0) continue;
    ++idle;
    const ComponentConfig* c = g.FindComponent(row.component);
    std::string why;
    if (c != nullptr && !c->trigger.empty()) {
      for (const auto& b : c->inputs)
        if (b.port == c->trigger) why = " (triggered by input '" + c->trigger + "': nothing arrived on '" + b.topic + "')";
    } else if (c != nullptr) {
      std::ostringstream rate;
      rate << c->rate_hz;
      why = " (rate_hz " + rate.str() + ": the run ended before its first step)";
    }
    err << (strict ? "error" : "warning") << ": process " << process << ": component '" << row.component << "' never stepped"
        << why << "\n";
  }
  return idle;
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

// The options RunGraph checks itself (the CLI checks the numbers' ranges); false after saying why.
bool CheckRunOptions(const RunOptions& options, std::ostream& err) {
  if (!options.run_id.empty() && !IsPartitionWord(options.run_id)) {
    err << "dyad run: --run-id '" << options.run_id << "': must be 1 to 64 of the characters A-Z a-z 0-9 _ . -\n";
    return false;
  }
  if (options.restart_count < 0 || (options.restart_count > 0 && options.process.empty())) {
    err << "dyad run: --restart-count " << options.restart_count
        << (options.restart_count < 0 ? ": must be >= 0" : ": only with --process (the launcher gives it to a process it restarts)")
        << "\n";
    return false;
  }
  return true;
}

// The timing table and what went wrong; the exit code of the run (run.hpp).
int ReportRun(const ProcessRun& run, const Graph& g, const std::string& process, const RunOptions& options,
              std::ostream& out, std::ostream& err) {
  // A run that failed before any step has no timing to show: a table of zeros would only push
  // the error it ends with out of sight.
  const bool stepped = std::any_of(run.rows.begin(), run.rows.end(), [](const Executor::Row& r) { return r.stats.steps > 0; });
  if (!options.quiet && (stepped || run.result.ok())) PrintReport(run.rows, process, out);
  if (run.signal != 0) {
    // A person stopped it: the run ended cleanly (recordings closed), but it did not finish.
    err << "dyad run: interrupted (" << SignalName(run.signal) << ")" << (run.result.ok() ? "" : ": " + run.result.message())
        << "\n";
    return ExitCodeForSignal(run.signal);
  }
  if (!run.result.ok()) {
    err << "dyad run: " << run.result.message() << "\n";
    return ExitCodeOf(run.result);
  }
  if (int idle = ReportIdleComponents(run.rows, g, process, options.strict, err); idle > 0 && options.strict) {
    err << "dyad run: " << idle << " component" << (idle == 1 ? "" : "s") << " never stepped (--strict)\n";
    return 1;
  }
  if (run.mismatches > 0) {
    err << "dyad run: " << run.mismatches << " type/QoS mismatch(es) with peers (see above)\n";
    return 1;
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
                      const std::vector<std::string>& plugin_paths, std::ostream& out, std::ostream& err,
                      PluginLoading plugins) {
  Loaded l;
  if (plugins == PluginLoading::kBuiltinOnly && !plugin_paths.empty()) {
    err << "dyad validate: --plugins and --no-plugins exclude each other\n";
    return 2;
  }
  if (!LoadAndValidate(path, overrides, plugin_paths, &l, err, nullptr, plugins)) return 2;
  out << path << ": OK (" << l.graph.components.size() << " components, " << l.resolved.topics.size() << " topics, "
      << l.graph.ProcessNames().size() << " process" << (l.graph.ProcessNames().size() == 1 ? "" : "es") << ")\n";
  return 0;
}

int RunGraph(const RunOptions& given, std::ostream& out, std::ostream& err) {
  RunOptions options = given;  // its host may come from the keystore (AdoptSubsetHost)
  Loaded l;
  // The launcher (no --process) checks the components of every process it starts before starting
  // any (all of them, unless the graph places processes on hosts); a child checks its own (the
  // others' files may already be open in their processes).
  if (!LoadAndValidate(options.graph_path, options.overrides, options.plugin_paths, &l, err, &options)) return 2;
  if (!CheckRunOptions(options, err)) return 2;
  std::string process = options.process;
  l.graph.run = options.run_id.empty() && process.empty() ? DefaultRunId(l.graph) : options.run_id;
  const std::set<std::string> procs = l.graph.ProcessNames();
  if (process.empty()) {
    if (NeedsLauncher(l.graph, options)) {
      RunOptions launched = options;
      launched.run_id = l.graph.run;  // every child joins the launcher's run
      return LaunchChildren(launched, l.graph, out, err);
    }
    process = *procs.begin();
  } else if (!procs.count(process)) {
    err << options.graph_path << ": --process " << process << ": no component is placed there (processes: " << JoinList(procs)
        << ")\n";
    return 2;
  }
  Executor::Options eo;
  eo.process = process;
  eo.host = ThisHost(options);
  eo.duration_s = options.duration_s;
  eo.steps = options.steps;
  eo.stats_period_s = options.stats_period_s;
  // The launcher tells a child how often it restarted it (announced on dyad/processes).
  const auto restarts = static_cast<uint32_t>(options.restart_count);
  eo.session = [&graph = l.graph, process, host = eo.host, restarts] { return MakeGraphSession(graph, process, host, restarts); };
  const ProcessRun run = RunProcess(l.graph, l.resolved, l.catalog, eo);
  return ReportRun(run, l.graph, process, options, out, err);
}

}  // namespace dyad
