/// Choosing topics by name or regular expression, for the recorder and replay `topics` params.
#pragma once

#include <string>
#include <vector>

#include <dyad/status.hpp>

namespace dyad::recorder {

// Each pattern is a topic name, or else an ECMAScript regular expression that must match a
// whole name. Empty `patterns` chooses every name in `available`, minus `default_excluded`.
// Returns the chosen names in the order of `available`. Fails (InvalidArgument, naming
// `param`, the entry's index and text) when a pattern is not a valid regex or matches nothing.
StatusOr<std::vector<std::string>> SelectTopics(const std::vector<std::string>& patterns,
                                                const std::vector<std::string>& available, const std::string& param,
                                                const std::vector<std::string>& default_excluded = {});

}  // namespace dyad::recorder
