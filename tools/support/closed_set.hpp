// tools/support/closed_set.hpp: a closed set of values (an enum class) and the words that name
// them in files, logs and on the command line, from one table per set, so the words written, the
// words read back and an error's list of the allowed words cannot disagree.
//
//   constexpr tools::Named<Mode> kModes[] = {{Mode::kOn, "on"}, {Mode::kOff, "off"}};
//   tools::NameOf(kModes, Mode::kOff)  -> "off"   (every value of the enum is in its table)
//   tools::ValueOf(kModes, "on")       -> Mode::kOn; nullopt for a word not in the table
//   tools::NamesOf(kModes)             -> "on or off" ("a, b or c"): what an error lists
// Each set's header declares its ToString/Parse pair; its .cpp holds the table and defines them
// with these (tools/study/attempt_outcome.cpp, self_reports.cpp; tools/sweep/run_status.cpp).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace dyad::tools {

template <typename E>
struct Named {
  E value;
  std::string_view name;
};

template <typename E, size_t N>
constexpr std::string_view NameOf(const Named<E> (&table)[N], E value) {
  for (const Named<E>& n : table)
    if (n.value == value) return n.name;
  return "?";  // a value missing from its table: the set's test catches it
}

template <typename E, size_t N>
constexpr std::optional<E> ValueOf(const Named<E> (&table)[N], std::string_view name) {
  for (const Named<E>& n : table)
    if (n.name == name) return n.value;
  return std::nullopt;
}

// The table's words in its order, "a, b or c"; a word that is empty is left out (an empty word
// means "none written", never something a person types).
template <typename E, size_t N>
std::string NamesOf(const Named<E> (&table)[N]) {
  std::string out;
  size_t shown = 0, total = 0;
  for (const Named<E>& n : table) total += n.name.empty() ? 0 : 1;
  for (const Named<E>& n : table) {
    if (n.name.empty()) continue;
    if (shown > 0) out += shown + 1 == total ? " or " : ", ";
    out += n.name;
    ++shown;
  }
  return out;
}

}  // namespace dyad::tools
