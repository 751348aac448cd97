// dyad/pvrnn/trainer.hpp: Adam training of a PV-RNN over a whole data set, one batch per epoch
// (all sequences as columns, as NRL does), deterministic for a given seed.
//
// Contract
// - `Create` checks the model against the data (DOFs, steps, sequences) and the options.
// - `Epoch()` samples eps (unless noise is off), runs the posterior pass, BPTT and one Adam step
//   on weights and A, and returns the loss terms of the pass before the update. No allocation.
// - `Snapshot(true)` returns a checkpoint (weights, A, Adam moments, RNG state); a Trainer
//   created from it continues exactly as if never stopped.
// - Scalar float or double; the gradient is exact for the loss computed in that scalar.
//
// Example:
//   auto trainer = Trainer<float>::Create(Model::Initialize(spec, 72, 7, 1), data, {}).value();
//   for (int e = 0; e < 1000; ++e) const LossTerms& l = trainer->Epoch();
//   SaveModel(trainer->Snapshot(false), "out.dpvrnn");
#pragma once

#include <memory>
#include <random>

#include "dyad/pvrnn/adam.hpp"
#include "dyad/pvrnn/dataset.hpp"
#include "dyad/pvrnn/model.hpp"
#include "dyad/pvrnn/posterior_pass.hpp"

namespace dyad::pvrnn {

struct TrainerOptions {
  AdamOptions adam;
  uint64_t seed = 1;          // noise seed (ignored when resuming: the checkpoint's RNG is used)
  bool sample_noise = true;   // false: eps = 0 (deterministic posterior means)
};

template <typename Scalar>
class Trainer {
 public:
  static StatusOr<std::unique_ptr<Trainer>> Create(const Model& model, const Dataset& data,
                                                   const TrainerOptions& options);

  // The returned terms live in this trainer until the next Epoch.
  const LossTerms& Epoch();
  int64_t epoch() const { return adam_w_.step(); }

  // NRL's RE_P: sum over sequences of KL(target || x) when generating from the prior with the
  // first `a_steps` steps on each sequence's A; noise from `seed`, or means only.
  double PriorReconstruction(bool noise, uint64_t seed, int a_steps = 3) const;

  Model Snapshot(bool with_training_state) const;
  const PosteriorPass<Scalar>& pass() const { return pass_; }

 private:
  Trainer(const Model& model, const Dataset& data, const TrainerOptions& options);
  Model base_;  // spec and provenance
  TrainerOptions options_;
  NetworkLayout layout_;
  Weights<Scalar> w_, grad_w_;
  AdaptiveVariables<Scalar> a_, grad_a_;
  Adam<Scalar> adam_w_, adam_a_;
  PosteriorPass<Scalar> pass_;
  MatrixT<Scalar> targets_, eps_;
  NetworkState<Scalar> start_;
  std::vector<double> meta_prior_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_;
};

}  // namespace dyad::pvrnn
