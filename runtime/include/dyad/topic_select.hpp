// dyad/topic_select.hpp — choosing topics by name or regular expression: the `topics` params of
// the recorder, replay and web components, so that one list reads the same in all three.
//
// Contract of SelectTopics(patterns, available, param, default_excluded):
//   - Each pattern is a topic name (an exact entry of `available`), or else an ECMAScript regular
//     expression that must match a whole name ("robot/.*" chooses "robot/state", not
//     "xrobot/state").
//   - Empty `patterns` chooses every name of `available` except those in `default_excluded`
//     (a pattern may still choose an excluded name explicitly).
//   - Returns the chosen names in the order of `available`, each once.
//   - Fails (InvalidArgument) when a pattern is neither a name nor a valid regular expression,
//     or matches nothing; the message names `param`, the entry's index and text, e.g.
//     "params.topics[1] = 'nope': matches no topic (topics: a, b)".
// Pure function: no state, callable from any thread.
#pragma once

#include <string>
#include <vector>

#include <dyad/status.hpp>

namespace dyad {

StatusOr<std::vector<std::string>> SelectTopics(const std::vector<std::string>& patterns,
                                                const std::vector<std::string>& available, const std::string& param,
                                                const std::vector<std::string>& default_excluded = {});

}  // namespace dyad
