// dyad/pvrnn/posterior_pass.hpp: forward pass from the posterior over a batch of sequences,
// the negative ELBO, and its exact gradient (BPTT). The kernel of training and of online
// error regression (issue 4) alike.
//
// The model (per layer k, leak a_k = 1/tau_k, all sequences as columns):
//   mu_p = tanh(W_mu_p d_{t-1} + b),   log sigma_p = W_ls_p d_{t-1} + b
//   mu_q = tanh(W_mu_q d_{t-1} + A_mu,t + b),   log sigma_q = W_ls_q d_{t-1} + A_ls,t + b
//   z_t = mu_q + sigma_q * eps_t
//   h_t = (1 - a) h_{t-1} + a (W_dh d_{t-1} + W_below d^{k-1}_{t-1} + W_above d^{k+1}_{t-1}
//                              + W_zh z_t + b_h),   d_t = tanh(h_t)
//   x_t = softmax per DOF (W_x d^0_t + b_x)
// Loss (NRL's normalisation): L = rec / n_dof + sum_k w_k KL_k / total_z, where
//   rec = sum_{t,s,dof} KL(target || x) and KL_k = sum_{t,s,i in layer k} KL(q || p).
//
// Contract
// - Construct once per (layout, steps, sequences); all buffers are allocated then, so Forward
//   and Backward do not allocate.
// - `Forward` reads weights, A (total_z x steps*sequences, column t*sequences + s), eps of the
//   same shape (zeros = means only) and targets (output_units x steps*sequences, softmax codes),
//   starting from `start` (stacked h and d, total_d x sequences). The referenced objects must
//   stay alive and unchanged until `Backward` returns.
// - `Backward` (after Forward) writes dL/dA into `grad_a` (same layout as A) and, unless
//   `grad_w` is null, dL/dweights into `grad_w` (overwritten, not accumulated). With grad_w
//   null the weight products are skipped (the issue-4 case: weights frozen).
// - `meta_prior` has one entry per layer (training w or the online w).
#pragma once

#include <vector>

#include "dyad/pvrnn/parameters.hpp"

namespace dyad::pvrnn {

struct LossTerms {
  double reconstruction = 0;       // sum of KL(target || output): NRL's RE_Q
  double regulation = 0;           // sum_k w_k KL_k: NRL's "Regulation"
  double loss = 0;                 // reconstruction / n_dof + regulation / total_z
  std::vector<double> kl_per_layer;  // KL_k (unweighted)
};

template <typename Scalar>
struct NetworkState {
  MatrixT<Scalar> h;  // total_d x columns, stacked layers
  MatrixT<Scalar> d;  // tanh(h)
  static NetworkState Zero(int total_d, int columns) {
    return {MatrixT<Scalar>::Zero(total_d, columns), MatrixT<Scalar>::Zero(total_d, columns)};
  }
};

template <typename Scalar>
class PosteriorPass {
 public:
  PosteriorPass(const NetworkLayout& layout, int steps, int sequences);

  int steps() const { return steps_; }
  int sequences() const { return sequences_; }
  // Promise that the weights passed to Forward neither change nor move from now on (online
  // error regression: weights frozen). Backward then transposes them once instead of per call.
  void AssumeWeightsFrozen() { weights_frozen_ = true; }

  // The returned terms live in this pass until the next Forward.
  const LossTerms& Forward(const Weights<Scalar>& weights, const AdaptiveVariables<Scalar>& a,
                    const MatrixT<Scalar>& eps, const MatrixT<Scalar>& targets,
                    const NetworkState<Scalar>& start, const std::vector<double>& meta_prior);
  void Backward(Weights<Scalar>* grad_w, AdaptiveVariables<Scalar>* grad_a);

  // Results of the last Forward (columns t*sequences + s).
  const MatrixT<Scalar>& outputs() const { return x_; }  // softmax codes
  // State after step t (t = -1 is the start state), stacked layers, sequences as columns.
  auto h_at(int t) const { return h_.middleCols((t + 1) * sequences_, sequences_); }
  auto d_at(int t) const { return d_.middleCols((t + 1) * sequences_, sequences_); }
  // Per-sequence reconstruction term (sum over steps and DOFs of KL(target||x)).
  std::vector<double> ReconstructionPerSequence() const;
  // Gradient w.r.t. the start state, valid after Backward.
  const MatrixT<Scalar>& grad_start_h() const { return g_start_h_; }
  const MatrixT<Scalar>& grad_start_d() const { return g_start_d_; }

  // Multiply-adds of one Forward+Backward with weight gradients (for GFLOP/s reports).
  double MultiplyAddsPerIteration() const;

 private:
  void WeightGradients(Weights<Scalar>* grad_w) const;
  NetworkLayout layout_;
  int steps_, sequences_, cols_;
  // Inputs of the last Forward.
  const Weights<Scalar>* w_ = nullptr;
  const MatrixT<Scalar>* eps_ = nullptr;
  const MatrixT<Scalar>* targets_ = nullptr;
  LossTerms terms_;  // kl_per_layer sized once: Forward allocates nothing
  bool weights_frozen_ = false;
  const Weights<Scalar>* transposed_ = nullptr;  // weights whose transposes r_t_, wx_t_ hold
  VectorT<Scalar> rate_, keep_, kl_coef_;
  MatrixT<Scalar> r_t_, wx_t_;             // transposed copies for the backward products
  MatrixT<Scalar> r_maskf_, wz_maskf_;
  // Trajectory: h_, d_ have (steps+1)*sequences columns (block 0 = start).
  MatrixT<Scalar> h_, d_;
  MatrixT<Scalar> mu_p_, ls_p_, mu_q_, ls_q_, sig_p_, sig_q_, z_;  // total_z x cols
  MatrixT<Scalar> pre_;                                            // recurrent_rows x sequences
  MatrixT<Scalar> x_, log_x_;                                      // output_units x cols
  // Backward buffers.
  MatrixT<Scalar> g_pre_;          // recurrent_rows x cols
  MatrixT<Scalar> g_out_, g_d0_;   // output_units x cols; total_d x cols (rows below d0 zero)
  MatrixT<Scalar> g_h_, g_h_next_, g_z_;
  MatrixT<Scalar> keep_tile_;      // 1 - a for every row and sequence (total_d x sequences)
  MatrixT<Scalar> g_start_h_, g_start_d_;
};

}  // namespace dyad::pvrnn
