// dyad/pvrnn/window_objective.hpp: the objective of online error regression (issue 4): the
// negative ELBO of a window of W executed steps, as a function of the window's A only.
//
// The posterior runs from a given start state (per-layer h and d before the window) over the W
// observed positions, with window-local A, eps held fixed (set per window) and a per-layer
// online meta-prior. Weights are frozen: the gradient is w.r.t. A only and the weight products
// are skipped. Same kernels as training (PosteriorPass with one column).
//
// Example (one optimiser iteration of issue 4):
//   WindowObjective<float> f(weights, /*window=*/15);
//   f.SetWindow(codes, start, eps, {1e-5, 1e-5});
//   LossTerms l = f.Evaluate(a, &grad_a);   // then adam.Step(a.flat(), grad_a.flat())
//   auto next_start_h = f.pass().h_at(0);   // slide: posterior state at window step 1
#pragma once

#include "dyad/pvrnn/posterior_pass.hpp"

namespace dyad::pvrnn {

template <typename Scalar>
class WindowObjective {
 public:
  // `weights` must outlive this object and stay unchanged (its transposes are cached).
  WindowObjective(const Weights<Scalar>& weights, int window);

  int window() const { return window_; }
  // targets: output_units x W softmax codes of the observed positions; start: total_d x 1;
  // eps: total_z x W (zeros = means only); meta_prior: one per layer. Blocks of larger
  // matrices (e.g. `m.leftCols(W)`) are accepted without a copy; no allocation.
  void SetWindow(const Eigen::Ref<const MatrixT<Scalar>>& targets, const NetworkState<Scalar>& start,
                 const Eigen::Ref<const MatrixT<Scalar>>& eps, const std::vector<double>& meta_prior);
  // a: total_z x W (one sequence). grad may be null (loss only). No allocation. The returned
  // terms live in this object until the next Evaluate.
  const LossTerms& Evaluate(const AdaptiveVariables<Scalar>& a, AdaptiveVariables<Scalar>* grad);
  const PosteriorPass<Scalar>& pass() const { return pass_; }
  // The window as last set (benchmarks rebuild the same problem from these).
  const Weights<Scalar>& weights() const { return weights_; }
  const MatrixT<Scalar>& targets() const { return targets_; }
  const MatrixT<Scalar>& eps() const { return eps_; }
  const NetworkState<Scalar>& start() const { return start_; }
  const std::vector<double>& meta_prior() const { return meta_prior_; }

 private:
  const Weights<Scalar>& weights_;
  int window_;
  PosteriorPass<Scalar> pass_;
  MatrixT<Scalar> targets_, eps_;
  NetworkState<Scalar> start_;
  std::vector<double> meta_prior_;
};

}  // namespace dyad::pvrnn
