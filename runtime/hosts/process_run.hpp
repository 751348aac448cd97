// RunProcess — runs the components of one process of a graph until its run ends, with the
// signal handling every run needs: SIGINT/SIGTERM stop it cleanly, and a process that cannot
// stop (a component or the DDS stack stuck) exits anyway kStopGraceS after the signal, saying so.
// `dyad run` (run.cpp) and the guests (guest.cpp) run their executors through it.
#pragma once

#include <vector>

#include <dyad/catalog.hpp>
#include <dyad/graph.hpp>
#include <dyad/status.hpp>
#include <dyad/validate.hpp>

#include "exec/executor.hpp"

namespace dyad {

// How long a stopping process may take to end cleanly after SIGINT/SIGTERM.
constexpr double kStopGraceS = 20;

// How one process's run ended.
struct ProcessRun {
  Status result;
  std::vector<Executor::Row> rows;
  int mismatches = 0;
  int signal = 0;  // the signal that stopped it; 0: none
};

ProcessRun RunProcess(const Graph& graph, const ResolvedGraph& resolved, const Catalog& catalog, const Executor::Options& eo);

}  // namespace dyad
