// Positions and problems as text (dyad/diagnostic.hpp).
#include "dyad/diagnostic.hpp"

namespace dyad {

SourceMark SourceMark::Of(const std::string& file, const YAML::Node& node) {
  if (!node.IsDefined()) return SourceMark{file, 0, 0};  // an absent key: Mark() would throw InvalidNode
  const YAML::Mark m = node.Mark();
  if (m.is_null()) return SourceMark{file, 0, 0};
  return SourceMark{file, m.line + 1, m.column + 1};
}

std::string SourceMark::ToString() const {
  if (line <= 0) return file;
  return file + ":" + std::to_string(line) + ":" + std::to_string(column);
}

bool SourceMark::FromCommandLine() const { return line <= 0 && file.rfind("--set ", 0) == 0; }

std::string Diagnostic::ToString() const {
  // "key = value: why" when the message starts with the offending value ("= 300: must be ...").
  const bool value_first = message.rfind("= ", 0) == 0;
  return mark.ToString() + ": " + (key.empty() ? "" : key + (value_first ? " " : ": ")) + message;
}

}  // namespace dyad
