#include "dyad/human_input/human_track.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <utility>

namespace dyad::human_input {

std::vector<std::string> SplitCsvLine(const std::string& line) {
  std::vector<std::string> cells(1);
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        cells.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        cells.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      cells.emplace_back();
    } else if (c != '\r') {
      cells.back() += c;
    }
  }
  return cells;
}

StatusOr<std::vector<HumanTrackRow>> LoadHumanTrack(const std::string& path) {
  std::ifstream f(path);
  if (!f) return Status::NotFound(path + ": cannot open");
  std::string line;
  if (!std::getline(f, line)) return Status::InvalidArgument(path + ": empty file (expected a header with x,y,engaged)");
  const std::vector<std::string> header = SplitCsvLine(line);
  int cx = -1, cy = -1, ce = -1;
  for (size_t i = 0; i < header.size(); ++i) {
    if (header[i] == "x") cx = static_cast<int>(i);
    if (header[i] == "y") cy = static_cast<int>(i);
    if (header[i] == "engaged") ce = static_cast<int>(i);
  }
  for (auto [col, name] : {std::pair{cx, "x"}, std::pair{cy, "y"}, std::pair{ce, "engaged"}})
    if (col < 0) return Status::InvalidArgument(path + ": no column \"" + name + "\" in the header");
  std::vector<HumanTrackRow> rows;
  int line_no = 1;
  while (std::getline(f, line)) {
    ++line_no;
    if (line.empty() || line == "\r") continue;
    const std::vector<std::string> cells = SplitCsvLine(line);
    const std::string at = path + ":" + std::to_string(line_no) + ": ";
    auto cell = [&](int col, const char* name, std::string* out) -> Status {
      if (static_cast<size_t>(col) >= cells.size())
        return Status::InvalidArgument(at + name + ": missing (the row has " + std::to_string(cells.size()) + " cells)");
      *out = cells[static_cast<size_t>(col)];
      return Status::OK();
    };
    HumanTrackRow r;
    std::string text;
    struct Number {
      int col;
      const char* name;
      double* dst;
    };
    for (const Number& n : {Number{cx, "x", &r.x}, Number{cy, "y", &r.y}}) {
      const auto [col, name, dst] = n;
      if (Status s = cell(col, name, &text); !s.ok()) return s;
      const auto res = std::from_chars(text.data(), text.data() + text.size(), *dst);
      if (res.ec != std::errc() || res.ptr != text.data() + text.size() || !std::isfinite(*dst))
        return Status::InvalidArgument(at + name + ": not a finite number: \"" + text + "\"");
    }
    if (Status s = cell(ce, "engaged", &text); !s.ok()) return s;
    if (text == "true" || text == "1") r.engaged = true;
    else if (text == "false" || text == "0") r.engaged = false;
    else return Status::InvalidArgument(at + "engaged: must be true/false or 1/0, got \"" + text + "\"");
    rows.push_back(r);
  }
  if (rows.empty()) return Status::InvalidArgument(path + ": no data rows after the header");
  return rows;
}

}  // namespace dyad::human_input
