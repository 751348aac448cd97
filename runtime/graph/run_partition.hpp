// The DDS partition of one run of a graph: "dyad/<graph>/<run>".
//
// Every endpoint of a run's processes, for its experiment topics and the runtime's own
// (dyad/processes, dyad/stats, ...), lives in this one partition, so two runs on one domain never
// match: two rigs side by side do not merge, a recorder records only its own run, and another
// run's "failed" announcement cannot stop this one. Watchers join with a pattern:
// WatchPartition("demo") sees every run of graph demo, WatchPartition("") every dyad run.
//
// The run id comes from `dyad run --run-id`; without it the launcher of a graph on one host
// draws a fresh one, and a graph on several hosts uses "shared" (each host's launcher must name
// the same run: give --run-id to run two copies of a multi-host graph on one domain).
// Graph names and run ids are limited to [A-Za-z0-9_.-] (IsPartitionWord), so a partition
// name is never a pattern.
#pragma once

#include <string>

#include <dyad/graph.hpp>

namespace dyad {

inline constexpr const char* kSharedRun = "shared";

inline bool IsPartitionWord(const std::string& s) {
  if (s.empty() || s.size() > 64) return false;
  for (char c : s)
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '.' || c == '-'))
      return false;
  return true;
}

inline std::string RunPartition(const std::string& graph, const std::string& run) {
  return "dyad/" + graph + "/" + (run.empty() ? std::string(kSharedRun) : run);
}
inline std::string RunPartition(const Graph& g) { return RunPartition(g.name, g.run); }

inline std::string WatchPartition(const std::string& graph) { return graph.empty() ? "dyad/*" : "dyad/" + graph + "/*"; }

}  // namespace dyad
