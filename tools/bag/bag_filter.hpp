// tools/bag/bag_filter.hpp: `dyad bag filter`: a recording cut down to some topics and a time
// window, as a new MCAP file the same tools read (ROS 2: `ros2 bag filter`/`convert`).
//
// Contract of FilterRecording:
//   - Copies into `out`, in log-time order, every message of `in` on one of `topics` (empty: all)
//     whose log time lies in [first + start_s, first + end_s], where `first` is the recording's
//     first message's log time (end_s < 0: to the end). Each message keeps its channel (topic,
//     encoding, metadata), schema, sequence, log and publish time, and bytes.
//   - Every Metadata record is copied (the graph's YAML: `dyad analyze` still reads the result),
//     with one more, "dyad.filter", saying what was kept and from which file.
//   - A topic named in `topics` that the recording does not have is an error (nothing written),
//     listing the ones it has. `out` equal to `in` is refused.
//   - A recording cut short is read as far as it is intact (its recovery said on `log`); a
//     damaged chunk fails the filter (DataLoss, naming it), and `out` is removed.
//   - The result is written to `out`.tmp and renamed: `out` is whole or absent.
#pragma once

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "dyad/status.hpp"

namespace dyad::bag {

struct FilterOptions {
  std::vector<std::string> topics;  // empty: all
  double start_s = 0, end_s = -1;   // from the first message; end_s < 0: to the end
};

struct FilterResult {
  std::uint64_t kept = 0, read = 0;
};

StatusOr<FilterResult> FilterRecording(const std::string& in, const std::string& out, const FilterOptions& options,
                                       std::ostream& log);

}  // namespace dyad::bag
