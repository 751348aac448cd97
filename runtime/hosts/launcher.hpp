// The launcher of `dyad run` (internal to the runtime; the contract is in run.hpp): one child
// `dyad run --process P` per process placed on this host, supervised (restart policy, required),
// their output relayed with a "[process] " prefix and written to <logs>/<process>.log, and the
// graph's discovery server when this host is named to run it. The children are started by the
// spawner (spawner.hpp) with the flags of run_arguments.hpp; what an exit means is the
// supervisor's decision (supervisor.hpp).
#pragma once

#include <ostream>
#include <string>

#include <dyad/graph.hpp>
#include <dyad/run.hpp>

namespace dyad {

// This machine's name in the graph: --host, else gethostname().
std::string ThisHost(const RunOptions& options);
// Whether a process (or the discovery server) placed on `host` runs on this machine: no host,
// this machine's name (ThisHost), or "localhost" when no --host was given.
bool RunsHere(const std::string& host, const RunOptions& options);
// Whether `dyad run` without --process launches children here (several processes, processes
// placed on hosts, or the discovery server to run) rather than running the graph in-process.
bool NeedsLauncher(const Graph& graph, const RunOptions& options);
// Runs the children to the end; the exit code of the run (run.hpp).
int LaunchChildren(const RunOptions& options, const Graph& graph, std::ostream& out, std::ostream& err);

}  // namespace dyad
