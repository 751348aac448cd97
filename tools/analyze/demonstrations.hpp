// tools/analyze/demonstrations.hpp: the study's data-collection step inside dyad. A person draws
// primitives on the subject's page while engaged; the recording's engaged segments become an
// NRL-layout data set (`dyad dataset from-recording`) that `dyad train` learns from.
//
// A segment is a run of consecutive samples of the human topic with `engaged` true. Each segment
// of at least `min_samples` samples becomes one primitive (in recording order, ids 0, 1, ...),
// resampled to `steps` points by linear interpolation over its samples (the first and last
// samples are kept exactly). Shorter segments are skipped and counted.
#pragma once

#include <string>

#include "dyad/pvrnn/dataset.hpp"
#include "dyad/status.hpp"
#include "recording_tables.hpp"

namespace dyad::analyze {

struct DemonstrationOptions {
  std::string topic = "human/input";
  int steps = 72;        // T of every primitive (the study's 72)
  int min_samples = 10;  // shorter engaged segments are not demonstrations
};

struct Demonstrations {
  pvrnn::Dataset dataset;  // 2 x steps per primitive; sampling period: the segments' mean
  int skipped = 0;         // engaged segments shorter than min_samples
};

// Fails InvalidArgument when `table` lacks x, y or engaged columns or when no segment qualifies.
StatusOr<Demonstrations> DemonstrationsFromTable(const TopicTable& table, const DemonstrationOptions& options);

}  // namespace dyad::analyze
