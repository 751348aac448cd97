// tools/support/graph_check.hpp: a graph's own verdict on a set of overrides, as text to put
// under the line of the file that asked for them (a sweep's grid value, a study's condition).
//
// Contract of GraphProblems(graph, sets, plugins, replaced):
//   - Validates `graph` with `sets` as `dyad validate --set` would (the components' own
//     configuration checks included); empty when it passes.
//   - Otherwise every problem line the validator printed, without its closing "N problems,
//     nothing was started" (about a run the caller is not starting).
//   - Problems of the key `replaced` (as the validator names it, "components.mind.params.model")
//     do not count: the caller gives that key another value in every run.
#pragma once

#include <string>
#include <vector>

namespace dyad::tools {

std::string GraphProblems(const std::string& graph, const std::vector<std::string>& sets, const std::vector<std::string>& plugins,
                          const std::string& replaced = "");

// "mind.model" or "mind.params.model" as the validator names it: "components.mind.params.model".
std::string ValidatorKey(const std::string& key);

}  // namespace dyad::tools
