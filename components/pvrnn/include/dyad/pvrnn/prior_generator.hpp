// dyad/pvrnn/prior_generator.hpp: step-wise generation from the prior, keeping its state
// between calls (the robot's "intention" stream; issue 4 continues it from an inferred state).
//
// Each `Step` advances every column (independent generations side by side) by one step:
// with `a` given, z comes from the posterior with that A (NRL selects a primitive this way for
// the first 3 steps); without it, z comes from the prior. eps scales sigma (zeros = means only).
// Uses the same step kernel as training. No allocation after construction.
//
// Example: draw primitive 2 of a model for 72 steps, noise off:
//   Eigen::MatrixXd xy = GeneratePrimitive(model, 2, 72, GenerateOptions{});
#pragma once

#include <cstdint>
#include <vector>

#include "dyad/pvrnn/model.hpp"
#include "dyad/pvrnn/posterior_pass.hpp"

namespace dyad::pvrnn {

template <typename Scalar>
class PriorGenerator {
 public:
  // `weights` is copied. `columns` generations run side by side.
  PriorGenerator(const Weights<Scalar>& weights, int columns);

  // Sets the state (total_d x columns, stacked layers); default start is all zero (as NRL).
  void Reset();
  void Reset(const NetworkState<Scalar>& state);
  const NetworkState<Scalar>& state() const { return state_; }

  // a_mu/a_ls: total_z x columns, or nullptr for the prior. eps: total_z x columns.
  // Returns the softmax codes of the new step (output_units x columns).
  const MatrixT<Scalar>& Step(const MatrixT<Scalar>* a_mu, const MatrixT<Scalar>* a_ls,
                              const MatrixT<Scalar>& eps);
  const MatrixT<Scalar>& outputs() const { return x_; }
  // z sampled in the last step (from the posterior on A steps, else the prior).
  const MatrixT<Scalar>& z() const { return z_; }

 private:
  Weights<Scalar> w_;
  int columns_;
  VectorT<Scalar> rate_, keep_;
  NetworkState<Scalar> state_, next_;
  MatrixT<Scalar> pre_, mu_p_, ls_p_, sig_p_, mu_q_, ls_q_, sig_q_, z_, zero_a_, x_;
};

struct GenerateOptions {
  int a_steps = 3;        // steps that use the primitive's trained A (NRL: 3)
  bool noise = false;     // false: means only (reproducible); true: eps ~ N(0,1) from seed
  uint64_t seed = 1;
};

// Softmax codes generated from the prior for the listed sequences (primitives) side by side:
// output_units x (steps * sequences.size()), column t * sequences.size() + c. Step t < a_steps
// (and < a.steps()) uses sequence c's trained A, later steps the prior. With noise, each step
// draws total_z x sequences.size() values (column-major) from one generator seeded with `seed`.
// The one generation loop behind GeneratePrimitive and Trainer::PriorReconstruction.
// REQUIRES every entry of `sequences` in [0, a.sequences()).
template <typename Scalar>
MatrixT<Scalar> GenerateCodes(const Weights<Scalar>& weights, const AdaptiveVariables<Scalar>& a,
                              const std::vector<int>& sequences, int steps,
                              const GenerateOptions& options);

// Positions (num_dofs x steps) of primitive `primitive` generated from the prior in double.
// REQUIRES 0 <= primitive < model.sequences(); A steps beyond model.steps() are not used.
Eigen::MatrixXd GeneratePrimitive(const Model& model, int primitive, int steps,
                                  const GenerateOptions& options);

}  // namespace dyad::pvrnn
