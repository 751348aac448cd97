// dyad/join_list.hpp — "a, b, c": the lists that messages name (known types, allowed keys, the
// processes not heard from). Header-only; components may use it.
//
//   JoinList(names)                                        "a, b, c"
//   JoinList(procs, [](const auto& p) { return "'" + p + "'"; })   "'a', 'b'"
//   JoinList(map, [](const auto& kv) { return kv.first; }, " | ")
#pragma once

#include <string>
#include <string_view>

namespace dyad {

// What `text(item)` gives for each item of `items`, in order, `separator` between.
template <class Range, class Text>
std::string JoinList(const Range& items, Text text, std::string_view separator = ", ") {
  std::string out;
  bool first = true;
  for (const auto& item : items) {
    if (!first) out += separator;
    out += text(item);
    first = false;
  }
  return out;
}

// The items themselves (strings or string_views).
template <class Range>
std::string JoinList(const Range& items) {
  return JoinList(items, [](const auto& item) -> const auto& { return item; });
}

}  // namespace dyad
