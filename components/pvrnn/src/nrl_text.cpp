#include "nrl_text.hpp"

#include <charconv>
#include <cmath>

namespace dyad::pvrnn::internal {

std::string_view Trim(std::string_view s) {
  const size_t b = s.find_first_not_of(" \t\r\n");
  if (b == std::string_view::npos) return {};
  return s.substr(b, s.find_last_not_of(" \t\r\n") - b + 1);
}

bool ParseNumberList(std::string_view line, std::vector<double>* out, std::string* bad) {
  out->clear();
  line = Trim(line);
  if (!line.empty() && line.back() == ',') line.remove_suffix(1);
  size_t pos = 0;
  while (true) {
    const size_t end = std::min(line.find(',', pos), line.size());
    const std::string_view field = Trim(line.substr(pos, end - pos));
    double v = 0;
    const auto r = std::from_chars(field.data(), field.data() + field.size(), v);
    if (field.empty() || r.ec != std::errc() || r.ptr != field.data() + field.size() || !std::isfinite(v)) {
      if (bad != nullptr) *bad = std::string(field);
      return false;
    }
    out->push_back(v);
    if (end == line.size()) return true;
    pos = end + 1;
  }
}

bool ParseInteger(std::string_view s, int64_t lo, int64_t hi, int64_t* out) {
  s = Trim(s);
  int64_t v = 0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || r.ec != std::errc() || r.ptr != s.data() + s.size() || v < lo || v > hi) return false;
  *out = v;
  return true;
}

}  // namespace dyad::pvrnn::internal
