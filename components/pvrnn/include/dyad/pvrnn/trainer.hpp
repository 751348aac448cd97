// dyad/pvrnn/trainer.hpp: Adam training of a PV-RNN over a whole data set, one batch per epoch
// (all sequences, as NRL does), deterministic for a given seed.
//
// Contract
// - `Create` checks the model against the data (DOFs, steps, sequences) and the options.
// - `Epoch()` samples eps (unless noise is off), runs the posterior pass and BPTT, and one Adam
//   step on weights and A, and returns the loss terms of the pass before the update. No
//   allocation.
// - The sequences are split into `chunks` fixed groups of consecutive sequences; each group's
//   pass (its sequences as the columns of one block) runs on any of `threads` threads, and the
//   groups' weight gradients and loss terms are summed in group order. The result depends on
//   `chunks` (rounding only: the mathematics is the same), never on `threads`: 1 and 2 threads
//   give identical bits.
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
#include <vector>

#include "dyad/pvrnn/adam.hpp"
#include "dyad/pvrnn/dataset.hpp"
#include "dyad/pvrnn/model.hpp"
#include "dyad/pvrnn/posterior_pass.hpp"

namespace dyad::pvrnn {

namespace internal {
class TaskPool;
}

struct TrainerOptions {
  AdamOptions adam;
  uint64_t seed = 1;          // noise seed (ignored when resuming: the checkpoint's RNG is used)
  bool sample_noise = true;   // false: eps = 0 (deterministic posterior means)
  // Groups of sequences with a pass each (at most one per sequence). Fixes the rounding of the
  // result; 2 keeps both cores of the study's machine busy with blocks of 3-4 sequences.
  int chunks = 2;             // REQUIRES >= 1
  // Threads that run the groups' passes (the calling one included); 0: the hardware's cores,
  // at most one per group. Does not change the result.
  int threads = 0;            // REQUIRES >= 0
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
  // Multiply-adds of one epoch's passes (for GFLOP/s reports).
  double MultiplyAddsPerEpoch() const;
  int chunks() const { return static_cast<int>(chunks_.size()); }
  int threads() const;

  ~Trainer();

 private:
  // One group of consecutive sequences with its own pass and copies of its columns.
  struct Chunk {
    Chunk(const NetworkLayout& layout, int first, int count, int steps);
    int first, count;  // sequences first .. first+count-1
    PosteriorPass<Scalar> pass;
    AdaptiveVariables<Scalar> a, grad_a;
    Weights<Scalar> grad_w;
    MatrixT<Scalar> targets, eps;
    NetworkState<Scalar> start;
    const LossTerms* terms = nullptr;
  };

  Trainer(const Model& model, const Dataset& data, const TrainerOptions& options);
  void MakeChunks(int sequences, int steps, const MatrixT<Scalar>& targets);
  void RunChunk(Chunk& c);
  void RunTask(int task);
  void SumChunks();
  void SampleNoise(MatrixT<Scalar>& eps);
  Model base_;  // spec and provenance
  TrainerOptions options_;
  NetworkLayout layout_;
  Weights<Scalar> w_, grad_w_;
  AdaptiveVariables<Scalar> a_, grad_a_;
  Adam<Scalar> adam_w_, adam_a_;
  std::vector<std::unique_ptr<Chunk>> chunks_;
  std::vector<int> by_size_;  // chunk indices, largest first: the order their passes start
  std::unique_ptr<internal::TaskPool> pool_;
  MatrixT<Scalar> targets_, eps_;
  MatrixT<Scalar> eps_next_;     // the next epoch's eps, drawn during this one
  bool eps_next_ready_ = false;
  LossTerms terms_;
  std::vector<double> meta_prior_;
  std::mt19937_64 rng_, rng_before_next_;  // the generator before eps_next_ was drawn
  std::normal_distribution<double> normal_, normal_before_next_;
};

}  // namespace dyad::pvrnn
