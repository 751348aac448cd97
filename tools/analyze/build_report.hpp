// tools/analyze/build_report.hpp: a recording read into the report `dyad analyze` writes.
//
// Contract of BuildReport(recording, warnings):
//   - Reads the MCAP file (a cut-short one too: what it recovers is said on `warnings`, and in
//     Report::incomplete, which IncompleteReason and the report's first lines say), the
//     graph recorded with it, the experiment's topics, the clock offsets between processes, the
//     live parameter changes applied (dyad/params; none recorded: an empty list, no warning) and
//     the transport's losses (a loss table that cannot be read is a warning, not a failure).
//   - Fails (InvalidArgument / IOError / DataLoss) naming the file: not an MCAP file, a graph
//     that does not parse, tables that do not decode.
//   - Thread-safe: nothing shared (a sweep analyses its runs on its worker threads).
#pragma once

#include <ostream>
#include <string>

#include "dyad/status.hpp"
#include "report_writer.hpp"

namespace dyad::analyze {

StatusOr<Report> BuildReport(const std::string& recording, std::ostream& warnings);

}  // namespace dyad::analyze
