// dyad/human_input/human_track.hpp: a recorded human track read from CSV, behind `human_replay`.
//
// The CSV has a header row; the columns `x`, `y` and `engaged` are found by name (others are
// ignored), as `dyad bag export --csv` writes a HumanInput topic:
//   log_time,publish_time,sequence,header.source,header.sequence_number,header.stamp_ns,x,y,engaged
// `engaged` is true/false or 1/0. Cells may be double-quoted ("" inside quotes is a quote).
// Errors name the file and line: "h.csv:12: x: not a number: \"abc\"", "h.csv: no column
// \"engaged\" in the header".
#pragma once

#include <string>
#include <vector>

#include "dyad/status.hpp"

namespace dyad::human_input {

struct HumanTrackRow {
  double x = 0, y = 0;
  bool engaged = false;
};

// Every data row in file order; fails on a missing file, a missing column, a bad cell, or a file
// without data rows.
StatusOr<std::vector<HumanTrackRow>> LoadHumanTrack(const std::string& path);

// Splits one CSV line into cells (RFC 4180 quoting; no line breaks inside quotes).
std::vector<std::string> SplitCsvLine(const std::string& line);

}  // namespace dyad::human_input
