// dyad/pvrnn/nrl_regression.hpp: NRL's online error regression, step by step (issue 44): the
// engine behind ErrorRegressionOptions::engine = nrl (preset "nrl"), for reproducing results
// published with NRL (github.com/oist-cnru/NRL, LibNRL::e_postdict / e_generate, read from
// commit 42395a2; docs/pvrnn.md, "NRL's error regression, read from its source").
//
// What it does, as NRL does (and unlike dyad's default engine):
// - Free generation until the window holds W executed positions; then, per step, one
//   postdiction over the last W (NRL's e_postdict), then the next intention (e_generate).
// - The window's A starts at 0; after a postdiction slot k takes the kept slot k+1, the newest
//   slot 0. The window's start state: 0, then the posterior state after the window's first step
//   of the kept iteration.
// - Adam per window slot with m, v zero at Reset and never reset or shifted while A slides under
//   them; the step count is global (bias correction fades across steps); epsilon as given
//   (NRL: 1e-20); m, v, bias correction and update in double as NRL's Utils::adam, stored float.
// - NRL's bug, kept: the loss is evaluated at A_i, Adam steps, and if that loss is the lowest so
//   far the copy is taken: the kept A is A_{i+1}, one Adam step past the best loss, with A_i's
//   states (window start, generator state).
// - The prior inside the window is a free-running trajectory from the window's start (own h, d,
//   fed by the neighbours' prior d); the KL compares it with the posterior. NRL's gradient: the
//   prior at t+1 is treated as a function of the posterior's d_t, and a layer's gradient from its
//   neighbours uses its own incoming weights (W_below^T of layer l for layer l-1's h, W_above^T
//   for l+1's) where the chain rule needs the neighbour's: neither is the gradient of the loss.
// - The first `a_steps` intentions (NRL: 3) use the posterior weights with the start primitive's
//   trained A, later ones the prior.
// - Float throughout (Eigen VectorXf, NRL's order of operations), softmax without max shift,
//   NRL's float encoding (no clamping, v + 1e-20) and decoding.
// - Noise: off (std 0, deterministic) or NRL's: N(0,1) for prior and posterior in every forward
//   pass and in generation, from std::normal_distribution<float> over std::default_random_engine
//   seeded with `seed` (NRL: seed 0 once per process; same draws only with the same standard
//   library and the same number of draws before).
// - Time: the iterations of a postdiction stop early only once `deadline` has passed (at least
//   one always runs). Allocates per step (it is NRL's code shape, not dyad's fast path).
//
// Example:
//   NrlRegression er(model, ErrorRegressionOptions::Preset("nrl").value(), meta_prior);
//   er.Reset(/*primitive=*/1, /*seed=*/0);
//   const NrlRegression::Outcome& o = er.Step(executed_xy);  // o.regressed false for W-1 steps
//   const double* next = er.intention();
#pragma once

#include <Eigen/Core>
#include <chrono>
#include <cstdint>
#include <memory>
#include <vector>

#include "dyad/pvrnn/model.hpp"

namespace dyad::pvrnn {

struct ErrorRegressionOptions;
namespace nrl {
class Noise;
}

class NrlRegression {
 public:
  struct Outcome {
    bool regressed = false;  // false while the window is not yet full (free generation)
    int iterations = 0;
    bool stopped_by_deadline = false;
    // e_postdict's output of the kept iteration: loss = rec / n_dof + reg / total_z.
    float loss = 0, reconstruction = 0, regulation = 0;
    std::vector<float> kl_per_layer;  // unweighted KL per layer of the kept iteration
  };

  // `options` must pass Validate (window, iterations, adam, a_steps, noise); `meta_prior` one w per
  // layer (the options' or the model's training w, resolved by the caller).
  NrlRegression(const Model& model, const ErrorRegressionOptions& options, const std::vector<double>& meta_prior);
  ~NrlRegression();
  NrlRegression(const NrlRegression&) = delete;
  NrlRegression& operator=(const NrlRegression&) = delete;

  // Fresh state (A, Adam, step count, states 0); the intention for step 0. REQUIRES
  // 0 <= primitive < model.sequences() (checked by the caller).
  void Reset(int primitive, uint64_t seed);
  // Takes the executed position (num_dofs values; NRL's float), postdicts once W are held, and
  // generates the next intention.
  const Outcome& Step(const double* executed,
                      std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max());
  void Retune(int iterations, const std::vector<double>& meta_prior);

  const double* intention() const { return intention_.data(); }
  const Outcome& last() const { return outcome_; }
  int window_fill() const { return static_cast<int>(buffer_.size()); }
  int64_t adam_step() const { return adam_step_; }
  // The window's A as kept at the last postdiction (NRL's e_au_copy / e_al_copy, before the
  // slide): layer k, slot s (0 oldest).
  const Eigen::VectorXf& kept_mu(int layer, int slot) const;
  const Eigen::VectorXf& kept_log_sigma(int layer, int slot) const;

  struct Layer;  // one NRL layer (nrl_network.hpp): weights and ER state (nrl_regression.cpp)

 private:
  void Encode(std::vector<std::vector<Eigen::VectorXf>>* y) const;
  void Forward();
  void Backward(const std::vector<std::vector<Eigen::VectorXf>>& y, float* rec, float* reg);
  void AdamStep();
  void CopyParam();
  void OverwriteParam();
  void Postdict(std::chrono::steady_clock::time_point deadline);
  void Generate();
  float Decode(const Eigen::VectorXf& x, int dof) const;

  int window_, iterations_, a_steps_, primitive_ = 0, total_z_ = 0;
  float lr_, beta1_, beta2_, epsilon_, sigma_;
  bool noise_on_;
  std::vector<Layer> layers_;
  AdaptiveVariables<float> trained_a_;
  std::vector<float> w_;                          // meta-prior per layer
  std::vector<Eigen::MatrixXf> w_out_, w_out_t_;  // per DOF, and its transpose (NRL keeps both)
  std::vector<Eigen::VectorXf> b_out_;
  std::vector<float> jmin_, jrange_;
  std::vector<std::vector<float>> ref_;
  float rec_coef_, reg_coef_;
  std::vector<std::vector<Eigen::VectorXf>> x_;  // outputs of the last forward pass, per step and DOF
  std::vector<std::vector<float>> buffer_;       // the last W executed positions (float), oldest first
  int64_t adam_step_ = 1;
  std::unique_ptr<nrl::Noise> noise_;  // NRL's N(0,1) or 0
  Eigen::VectorXd intention_;
  Outcome outcome_;
  std::vector<float> outcome_kl_;  // KL per layer of the last evaluation
};

}  // namespace dyad::pvrnn
