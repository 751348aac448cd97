// dyad/run.hpp — running a graph: what `dyad run` and `dyad validate` do.
//
// RunGraph loads the graph, loads plugins, validates (including each component's own Configure()
// against a dry context: see validate.hpp's DryConfigure; printing every problem and returning 2
// if there is any: nothing is started), then either
//   - runs the components placed in `process` (one DDS participant for them), or
//   - with no `process` given and components in several processes (or processes placed on
//     hosts): starts one child `dyad run --process P` per process whose host is this machine
//     (`host`, else the host a keystore subset of a secured graph was exported for, said on
//     stderr, else the machine's host name; a graph naming no host runs all here), forwards
//     SIGINT/SIGTERM to them and waits. Children run in their own process group (a terminal's
//     Ctrl-C reaches them once, through the launcher) and get SIGTERM if the launcher dies. When
//     one child fails, the others are stopped and the exit code is the failed child's. When the
//     graph's `network.server` names this host, it first starts `dyad discovery-server` there
//     and stops it after the last child. Each child's output is relayed with a "[process] "
//     prefix and appended to <logs>/<process>.log (`logs:` of the graph or --logs). Processes
//     are supervised: `restart` (never | on-failure | always, max_restarts, backoff_s doubling
//     up to 10 s) and `required` (a required process that fails for good stops the others and
//     ends the run with its exit code; another one is reported and left out).
//     The children are the program `executable` (this one unless told otherwise).
// It returns when the run ends: SIGINT/SIGTERM, `duration_s`, `steps`, a component's
// RequestStop(), or a failed step. At exit it prints a timing table (per component: steps, step
// duration mean/p99/max, start jitter, deadline misses) and publishes the same as
// dyad::msg::ComponentStats on topic "dyad/stats" every `stats_period_s` while running.
//
// Exit codes: 0 clean end, 1 runtime failure (a component failed, DDS error, type mismatch with
// a peer), 2 invalid graph or options, 128 + signal when SIGINT/SIGTERM stopped it (130 for
// Ctrl-C; it still ends cleanly: components deactivated, recordings closed, timing printed, and
// "interrupted (SIGINT)" said on stderr; a process that has not ended 20 s after the signal
// exits anyway, saying so, rather than hang). A component's failure keeps its Status code through the
// runtime (context is added, the code is not rewritten) and the exit code follows it
// (ExitCodeOf): InvalidArgument, NotFound and DataLoss (a bad param, a missing or damaged file
// the graph names) exit 2, every other failure 1.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include <dyad/graph.hpp>
#include <dyad/status.hpp>

namespace dyad {

struct RunOptions {
  std::string graph_path;
  std::vector<Override> overrides;
  std::string process;             // empty: every process of the graph (see above)
  std::string host;                // this machine's name in the graph; empty: a subset's host, else gethostname()
  std::string logs_dir;            // the launcher's per-process logs (default: the graph's `logs:`)
  double duration_s = 0;           // > 0: stop after this much wall time
  uint64_t steps = 0;              // > 0: stop after the fastest periodic component ran this many steps
  double stats_period_s = 1.0;     // ComponentStats publication period (wall time)
  std::vector<std::string> plugin_paths;  // in addition to the graph's plugins:
  bool quiet = false;              // no timing table
  // With the graph's name, the run's DDS partition (graph/run_partition.hpp). Empty: the
  // launcher of a graph on one host draws a fresh one (8 hex digits) and gives it to its
  // children; a graph on several hosts, or a process started by hand, uses "shared".
  std::string run_id;
  // A component that never stepped during a run that went to its end is an error (exit 1), not
  // only a warning.
  bool strict = false;
  // With `process`: how often the launcher has restarted this process (`dyad run --process P
  // --restart-count N`, given by the launcher to a restarted child), announced with its state on
  // dyad/processes (`dyad status` shows it). >= 0; must be 0 without `process`.
  int restart_count = 0;
  // The dyad executable the launcher starts its children with (`dyad run --process P`, `dyad
  // discovery-server`). The default is this program, so a program other than dyad that calls
  // RunGraph for a graph of several processes names dyad here.
  std::string executable = "/proc/self/exe";
};

int RunGraph(const RunOptions& options, std::ostream& out, std::ostream& err);

// The exit code for a run that ended with `status` (see above).
int ExitCodeOf(const Status& status);

// Loads and validates only. Prints "<file>: OK (...)" or every problem; returns 0 or 2.
// A graph file is code: its `plugins:` are shared libraries, loaded (run) to validate it. With
// `plugins` = kBuiltinOnly only dyad's built-in plugin folder is loaded (not the graph's
// `plugins:`, not DYAD_PLUGIN_PATH; `plugin_paths` must be empty): a component of another type is
// reported as not checked, and the rest of the graph is validated.
enum class PluginLoading { kAll, kBuiltinOnly };
int ValidateGraphFile(const std::string& path, const std::vector<Override>& overrides,
                      const std::vector<std::string>& plugin_paths, std::ostream& out, std::ostream& err,
                      PluginLoading plugins = PluginLoading::kAll);

}  // namespace dyad
