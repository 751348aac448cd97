// dyad/pvrnn/dataset.hpp: training sequences and the NRL/VCBot data set layout.
//
// Layout of a data set folder (read and written):
//   dataset.d                 key=value lines: samplingperiod (ms), numbertimes, numberprims
//   primitive_<id>_<sample>.csv   one row per step, comma-separated DOF values, no header
//   names.txt                 optional, dyad's own (NRL never reads it): the primitives' names,
//                             one per line in their order ("circle", "left eye"): what pages and
//                             reports call them; without it they are "primitive 5"
// Only sample 0 of each primitive is used (the study has one sample per primitive).
// names.txt must hold exactly numberprims names, each 1..40 bytes of printable text, no two the
// same; a bad one is an error naming the file and line.
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

  int size() const { return static_cast<int>(sequences.size()); }
  int steps() const { return sequences.empty() ? 0 : static_cast<int>(sequences[0].cols()); }
  int dofs() const { return sequences.empty() ? 0 : static_cast<int>(sequences[0].rows()); }
};

StatusOr<Dataset> LoadNrlDataset(const std::string& dir);
// Each sequence repeated `loops` times end to end (loops >= 1).
Dataset RepeatSequences(const Dataset& data, int loops);
Status WriteNrlDataset(const Dataset& data, const std::string& dir);

}  // namespace dyad::pvrnn
