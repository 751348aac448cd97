// What a recording lost, read back from the samples themselves: every dyad sample carries its
// writer (header.source) and that writer's sequence number (1, 2, 3, ...), so a gap in one
// writer's numbers is samples the recorder never received, and a writer that falls silent long
// before the recording ends stopped reaching it. `dyad bag info` prints this section, with the
// runtime's own account of what it healed (dyad/health).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <dyad/status.hpp>

#include "dyad/mcap/reader.hpp"

namespace dyad::bag {

struct WriterLosses {
  std::string topic, writer;
  std::uint64_t samples = 0, first = 0, last = 0;  // sequence numbers
  struct Gap {
    std::uint64_t missing = 0;       // samples between two received ones
    std::int64_t from_ns = 0, to_ns = 0;  // stamps of the samples around the gap
  };
  std::vector<Gap> gaps;
  double silent_at_end_s = 0;  // > 0: its last sample is this long before the recording's end
};

// A driver's outages, from its recorded CartesianState: runs of samples with stopped = true (the
// arm could not be moved: the mixer held, docs/components.md "The command contract").
struct ArmStops {
  std::string topic;
  struct Stop {
    std::int64_t from_ns = 0, to_ns = 0;  // first stopped sample; first sample after (or the last stopped)
    bool until_end = false;               // still stopped at the recording's last sample
  };
  std::vector<Stop> stops;
  bool stopped_now = false;  // while reading
};

struct Losses {
  std::vector<ArmStops> arms;  // every CartesianState channel that reported stopped at some time
  std::vector<WriterLosses> writers;  // every writer of every channel with a dyad header
  std::vector<std::pair<std::int64_t, std::string>> health;  // dyad/health events: stamp, what
  std::int64_t start_ns = 0;  // the earliest stamp (times are printed from it)
};

// Reads every message once. Channels whose schema has no header.source/sequence_number are left
// out. A writer is "silent at the end" when its last sample is more than 2 s and 10 of its usual
// intervals before the last stamp of the recording.
StatusOr<Losses> FindLosses(const mcap::Reader& reader);

// The `losses:`, `arm:` (only when a driver reported stopped) and `health:` sections of
// `dyad bag info` (end with a newline).
std::string FormatLosses(const Losses& losses);

}  // namespace dyad::bag
