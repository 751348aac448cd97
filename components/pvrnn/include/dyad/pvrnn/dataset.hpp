// dyad/pvrnn/dataset.hpp: training sequences and the NRL/VCBot data set layout.
//
// Layout of a data set folder (read and written):
//   dataset.d                 key=value lines: samplingperiod (ms), numbertimes, numberprims;
//                             optional: NRL's own data folders have none (below)
//   primitive_<p>_<s>.csv     sample s of primitive p: one row per step, comma-separated DOF
//                             values, no header
//   names.txt                 optional, dyad's own (NRL never reads it): the primitives' names,
//                             one per line in their order ("circle", "left eye"): what pages and
//                             reports call them; without it they are "primitive 5"
// Every sample is a training sequence (NRL's `nsamples`): primitive p's samples are read from
// primitive_<p>_0.csv up to the first missing s, sequences in primitive-major order. Without
// dataset.d (NRL's own layout; NRL takes the counts from its properties file) the primitives are
// read from 0 up to the first missing primitive_<p>_0.csv, the steps are the first file's rows
// and the sampling period is 100 ms. Any other file of the folder (a primitive beyond
// numberprims, a sample after a gap, a stray file) is not used and named in `warnings`.
// names.txt must hold exactly one name per primitive, each 1..40 bytes of printable text, no two
// the same; a bad one is an error naming the file and line. A primitive's later samples are
// named "<name> (sample s)".
//
// Contract: every sequence has the same number of steps and DOFs; loading checks that and
// reports the file (and line) at fault.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "dyad/status.hpp"

namespace dyad::pvrnn {

struct Dataset {
  std::string name;                       // folder name or "analytic"
  double sampling_period_ms = 100;
  std::vector<Eigen::MatrixXd> sequences;  // each num_dofs x steps (positions, workspace units)
  std::vector<std::string> names;          // empty, or one per sequence (names.txt)
  // Per sequence, the primitive and the sample it is (primitive_<p>_<s>.csv); empty: sequence k
  // is primitive k's only sample (a data set made in memory).
  std::vector<int> primitive, sample;
  std::vector<std::string> warnings;  // what loading left out: "<file>: not used (<why>)"

  int size() const { return static_cast<int>(sequences.size()); }
  int PrimitiveOf(int k) const { return primitive.empty() ? k : primitive[k]; }
  int SampleOf(int k) const { return sample.empty() ? 0 : sample[k]; }
  int primitives() const { return sequences.empty() ? 0 : PrimitiveOf(size() - 1) + 1; }
  // The number of sequences of each primitive, in primitive order.
  std::vector<int> SequencesPerPrimitive() const;
  int steps() const { return sequences.empty() ? 0 : static_cast<int>(sequences[0].cols()); }
  int dofs() const { return sequences.empty() ? 0 : static_cast<int>(sequences[0].rows()); }
};

StatusOr<Dataset> LoadNrlDataset(const std::string& dir);
// Each sequence repeated `loops` times end to end (loops >= 1).
Dataset RepeatSequences(const Dataset& data, int loops);
// Writes dataset.d, primitive_<p>_<s>.csv and names.txt (the names of the samples 0); removes the
// folder's other primitive_*.csv files (an earlier set's would be read as samples of this one).
Status WriteNrlDataset(const Dataset& data, const std::string& dir);

}  // namespace dyad::pvrnn
