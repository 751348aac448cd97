/// Limits on JSON from browsers and Foxglove clients, checked before parsing. nlohmann::json
/// parses recursively: a 1 MiB frame of '[' would need ~a million stack frames. A message nested
/// deeper than kMaxJsonDepth is refused (and the client closed) without being parsed.
#pragma once

#include <string_view>

namespace dyad::web {

inline constexpr int kMaxJsonDepth = 32;

// False when brackets/braces outside strings nest deeper than max_depth.
inline bool JsonDepthWithin(std::string_view text, int max_depth = kMaxJsonDepth) {
  int depth = 0;
  bool in_string = false, escaped = false;
  for (char c : text) {
    if (in_string) {
      if (escaped) escaped = false;
      else if (c == '\\') escaped = true;
      else if (c == '"') in_string = false;
      continue;
    }
    if (c == '"') in_string = true;
    else if (c == '[' || c == '{') {
      if (++depth > max_depth) return false;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return true;
}

}  // namespace dyad::web
