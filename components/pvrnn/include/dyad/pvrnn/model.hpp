// dyad/pvrnn/model.hpp: a complete PV-RNN model: shape, weights, trained A, provenance and (in
// checkpoints) the optimiser state needed to resume training bit-for-bit.
//
// Contract
// - Weights are stored in double; engines cast to their scalar (`weights.Cast<float>()`).
// - `adaptive` holds the A of every trained sequence (primitive) and step; generation selects a
//   primitive by using its A for the first steps.
// - `Initialize` is deterministic for a given seed.
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <string>

#include "dyad/pvrnn/parameters.hpp"

namespace dyad::pvrnn {

struct Provenance {
  std::string source;           // what produced it, e.g. "dyad train macaw.yaml" or "import-nrl ..."
  std::string dataset;          // training data set (path as given)
  int64_t epochs = 0;           // completed training epochs
  uint64_t seed = 0;            // training seed
  std::string scalar;           // "float" or "double": scalar type used in training
  double final_loss = std::numeric_limits<double>::quiet_NaN();            // NRL normalisation
  double final_reconstruction = std::numeric_limits<double>::quiet_NaN();  // RE_Q
  double final_regulation = std::numeric_limits<double>::quiet_NaN();
};

// Optimiser state, present in checkpoints only.
struct TrainingState {
  int64_t adam_step = 0;
  Eigen::VectorXd weights_m, weights_v, adaptive_m, adaptive_v;
  std::string rng_state;  // std::mt19937_64 state as text (operator<<)
};

struct Model {
  ModelSpec spec;
  Weights<double> weights;
  AdaptiveVariables<double> adaptive;  // total_z x steps*sequences
  Provenance provenance;
  std::optional<TrainingState> training;

  int sequences() const { return adaptive.sequences(); }
  int steps() const { return adaptive.steps(); }

  // Random weights (Kaiming-uniform as NRL) and A ~ U(-1/sqrt(z), 1/sqrt(z)) per layer.
  // REQUIRES spec.Validate().ok().
  static Model Initialize(const ModelSpec& spec, int steps, int sequences, uint64_t seed);
};

}  // namespace dyad::pvrnn
