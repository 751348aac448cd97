// GraphSession — this process's part in a wall-clock graph of several processes (the executor's
// ProcessSession, exec/process_session.hpp): it waits for the others at the StartBarrier
// (start_barrier.hpp), measures their clocks (clock_sync.hpp) from the start on, and announces
// its state on dyad/processes ("running" with each heartbeat, then "stopping").
#pragma once

#include <memory>
#include <string>

#include <dyad/graph.hpp>

#include "exec/process_session.hpp"

namespace dyad {

// The session of `process` (on `host`), or null when it needs none: a stepped graph. A graph of
// one process gets a session that only announces its state on dyad/processes (`dyad status`
// finds it); it waits for nobody. `restarts`: how often the launcher has restarted this process.
std::unique_ptr<ProcessSession> MakeGraphSession(const Graph& graph, const std::string& process, const std::string& host,
                                                 uint32_t restarts);

}  // namespace dyad
