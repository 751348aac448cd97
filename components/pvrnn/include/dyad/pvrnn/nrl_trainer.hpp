// dyad/pvrnn/nrl_trainer.hpp: NRL's training, epoch by epoch (issue 44, item 2): the engine behind
// `prior: nrl` of `dyad train`, for reproducing models and losses published with NRL
// (github.com/oist-cnru/NRL, LibNRL::t_background, read from commit 42395a2; docs/pvrnn.md,
// "The NRL mode", Training).
//
// What it does, as NRL does (and unlike `Trainer`):
// - Starts from NRL's own initial state (`InitialModel`: NRL's Kaiming-uniform weights and A as
//   its constructors draw them from glibc's rand() in its default state; NRL never seeds it, so
//   every NRL run starts there), or from any model of the data's shape.
// - Per epoch: every primitive's forward pass (the free-running prior path beside the posterior,
//   NRL's noise or 0), then every backward pass (NRL's gradient: the KL's prior side into the
//   prior's weights with the prior's d and into the posterior's d, neighbours through the layer's
//   own incoming weights), then one Adam step on every weight and A (NRL's Utils::adam: m, v
//   float, bias corrections and update in double, epsilon as given: NRL's NON_ZERO is 1e-20; the
//   step count is the epoch).
// - Float throughout, NRL's order of operations (per layer, per step), softmax without max
//   shift, targets encoded as NRL's Dataset::softmax (float, no clamping).
// - Noise: off (0: deterministic) or NRL's: N(0,1) for prior and posterior at every step of every
//   pass, std::normal_distribution<float> over std::default_random_engine seeded with `seed`
//   (NRL: 0, once per process), drawn in NRL's order; the same draws only with the same standard
//   library.
// - The returned loss terms are those of the epoch's pass before its Adam step, summed in float
//   as NRL sums them (training.txt's RE_Q, Regulation, loss).
// Not done: shuffling (NRL's shuffle=false, as the study's), several samples of a primitive (NRL
// shares one forward pass and A among them; `Create` refuses them), resuming from a checkpoint.
// Allocates per epoch (NRL's code shape; about 10x slower than `Trainer`).
//
// Example:
//   const Model start = NrlTrainer::InitialModel(spec, data.steps(), data.size());
//   auto trainer = NrlTrainer::Create(start, data, {}).value();
//   for (int e = 0; e < 200; ++e) const LossTerms& l = trainer->Epoch();
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "dyad/pvrnn/adam.hpp"
#include "dyad/pvrnn/dataset.hpp"
#include "dyad/pvrnn/model.hpp"
#include "dyad/pvrnn/posterior_pass.hpp"
#include "dyad/status.hpp"

namespace dyad::pvrnn {

struct NrlTrainerOptions {
  AdamOptions adam{0.001, 0.9, 0.999, 1.0e-20};  // NRL's properties file (MacawBot) and NON_ZERO
  bool noise = false;                            // NRL's N(0,1) draws, or 0
  uint64_t seed = 0;                             // the noise engine's seed (NRL: 0)
};

class NrlTrainer {
 public:
  // NRL's initial weights and A for this shape (`primitives` sequences of `steps`).
  // REQUIRES spec.Validate().ok().
  static Model InitialModel(const ModelSpec& spec, int steps, int primitives);
  // Checks the model against the data (DOFs, units, steps, sequences), one sample per primitive,
  // and the Adam options.
  static StatusOr<std::unique_ptr<NrlTrainer>> Create(const Model& start, const Dataset& data, const NrlTrainerOptions& options);
  ~NrlTrainer();
  NrlTrainer(const NrlTrainer&) = delete;
  NrlTrainer& operator=(const NrlTrainer&) = delete;

  // One epoch; the terms live until the next call.
  const LossTerms& Epoch();
  int64_t epoch() const { return step_ - 1; }
  // The current weights and A (no training state) with the start's spec and provenance.
  Model Snapshot() const;

  struct State;  // NRL's network: layers, outputs, A, gradients, Adam moments (nrl_trainer.cpp)

 private:
  NrlTrainer(const Model& start, const Dataset& data, const NrlTrainerOptions& options);
  void AdamStep();
  Model base_;
  NrlTrainerOptions options_;
  std::unique_ptr<State> s_;
  int64_t step_ = 1;
  LossTerms terms_;
};

}  // namespace dyad::pvrnn
