// tools/analyze/demonstrations.hpp: the study's data-collection step inside dyad. A person draws
// primitives on the subject's page while engaged; the recording's engaged segments become an
// NRL-layout data set (`dyad dataset from-recording`) that `dyad train` learns from.
//
// A segment is a run of consecutive samples of the human topic with `engaged` true; one of at
// least `min_samples` samples qualifies (shorter ones are counted and skipped), and qualifying
// segments are numbered 0, 1, ... in recording order. Each primitive is one segment, resampled
// to `steps` points by linear interpolation over its samples (the first and last samples are
// kept exactly): by default every qualifying segment in order; with `choose`, primitive k is
// segment choose[k] (the person meant those: a segment may be skipped, reordered or used twice).
//
// What the person may not have meant is said, per primitive, in `warnings`:
//   - a segment that holds several laps of a closed shape (it returned to its start, within 15%
//     of its extent, more than once after going at least 40% of its extent away): one primitive
//     of `steps` points then squeezes them all in;
//   - resampling that changes the pace: the segment's samples came every P ms, its primitive's
//     steps are its duration / (steps - 1) apart; more than 20% apart, the model learns the shape
//     faster or slower than it was drawn (the data set's samplingperiod says the latter).
#pragma once

#include <string>
#include <vector>

#include "dyad/pvrnn/dataset.hpp"
#include "dyad/status.hpp"
#include "recording_tables.hpp"

namespace dyad::analyze {

struct DemonstrationOptions {
  std::string topic = "human/input";
  int steps = 72;           // T of every primitive (the study's 72)
  int min_samples = 10;     // shorter engaged segments are not demonstrations
  std::vector<int> choose;  // primitive k <- segment choose[k]; empty: every segment in order
  // What messages call `choose`, `steps` and where the segments are (the learner's own words).
  std::string choose_name = "--segments", steps_name = "--steps", source_name = "the recording";
};

struct Segment {
  double start_s = 0, duration_s = 0;  // from the topic's first sample
  int samples = 0;
  double sample_period_ms = 0;  // median spacing of its samples
  int laps = 1;                 // returns to its start (see above); at least 1
};

struct Demonstrations {
  pvrnn::Dataset dataset;  // 2 x steps per primitive; sampling period: the primitives' mean
  std::vector<Segment> segments;  // every qualifying segment, in recording order
  std::vector<int> chosen;        // the segment of each primitive
  std::vector<std::string> warnings;
  int skipped = 0;  // engaged segments shorter than min_samples
};

// One sample of the human topic.
struct HumanSample {
  double stamp_ns = 0;  // header.stamp_ns
  double x = 0, y = 0;
  bool engaged = false;
};

// Fails InvalidArgument when no segment qualifies, or when `choose` names a segment that does not
// exist (the message lists the segments found). The learner component cuts a live session with it.
StatusOr<Demonstrations> DemonstrationsFromSamples(const std::vector<HumanSample>& samples, const DemonstrationOptions& options);

// The same from a recording's table; also fails when `table` lacks x, y or engaged columns.
StatusOr<Demonstrations> DemonstrationsFromTable(const TopicTable& table, const DemonstrationOptions& options);

}  // namespace dyad::analyze
