// dyad/testing/csv.hpp — reads back the CSV files `dyad bag export --csv` writes (one per topic),
// independently of the exporter's code: RFC 4180 quoting ("a, b", "say ""hi"""), no line breaks
// inside cells.
//
//   for (const auto& row : dyad::testing::ReadCsv(dir / "robot_command.csv")) row.at("x");
#pragma once

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace dyad::testing {

// One CSV line's cells.
inline std::vector<std::string> CsvCells(const std::string& line) {
  std::vector<std::string> cells(1);
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted && c == '"' && i + 1 < line.size() && line[i + 1] == '"') cells.back() += '"', ++i;
    else if (c == '"') quoted = !quoted;
    else if (c == ',' && !quoted) cells.emplace_back();
    else cells.back() += c;
  }
  return cells;
}

// A CSV file with a header line as rows of column -> text (empty when it cannot be read).
inline std::vector<std::map<std::string, std::string>> ReadCsv(const std::filesystem::path& file) {
  std::ifstream lines(file);
  std::vector<std::string> columns;
  std::vector<std::map<std::string, std::string>> rows;
  for (std::string line; std::getline(lines, line);) {
    const std::vector<std::string> cells = CsvCells(line);
    if (columns.empty()) {
      columns = cells;
      continue;
    }
    std::map<std::string, std::string> row;
    for (size_t i = 0; i < columns.size() && i < cells.size(); ++i) row[columns[i]] = cells[i];
    rows.push_back(std::move(row));
  }
  return rows;
}

}  // namespace dyad::testing
