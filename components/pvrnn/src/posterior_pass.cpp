#include "dyad/pvrnn/posterior_pass.hpp"

#include <algorithm>
#include <cmath>
#include <type_traits>

#include "step_kernel.hpp"

namespace dyad::pvrnn {

using internal::SmallProduct;

using internal::Flat;
using internal::Source;

template <typename Scalar>
PosteriorPass<Scalar>::PosteriorPass(const NetworkLayout& layout, int steps, int sequences)
    : layout_(layout), steps_(steps), sequences_(sequences), cols_(steps * sequences) {
  const int td = layout.total_d(), tz = layout.total_z(), rr = layout.recurrent_rows();
  const int nx = layout.output_units(), d0 = layout.d0();
  internal::LeakRates(layout, &rate_, &keep_);
  kl_coef_.resize(tz);
  r_t_.resize(td, rr);
  wx_t_.resize(d0, nx);
  r_maskf_.resize(rr, td);
  for (int i = 0; i < rr * td; ++i) r_maskf_.data()[i] = layout.r_mask()[i];
  wz_maskf_.resize(td, tz);
  for (int i = 0; i < td * tz; ++i) wz_maskf_.data()[i] = layout.wz_mask()[i];
  h_.resize(td, (steps + 1) * sequences);
  d_.resize(td, (steps + 1) * sequences);
  for (auto* m : {&mu_p_, &ls_p_, &mu_q_, &ls_q_, &sig_p_, &sig_q_, &z_}) m->resize(tz, cols_);
  pre_.resize(rr, sequences);
  x_.resize(nx, cols_);
  log_x_.resize(nx, cols_);
  g_pre_.resize(rr, cols_);
  g_out_.resize(nx, cols_);
  g_d0_ = MatrixT<Scalar>::Zero(td, cols_);
  keep_tile_ = keep_.replicate(1, sequences);
  for (auto* m : {&g_h_, &g_h_next_, &g_start_h_, &g_start_d_}) m->resize(td, sequences);
  g_z_.resize(tz, sequences);
  terms_.kl_per_layer.assign(layout.num_layers(), 0.0);
}

template <typename Scalar>
const LossTerms& PosteriorPass<Scalar>::Forward(const Weights<Scalar>& weights,
                                         const AdaptiveVariables<Scalar>& a,
                                         const MatrixT<Scalar>& eps,
                                         const MatrixT<Scalar>& targets,
                                         const NetworkState<Scalar>& start,
                                         const std::vector<double>& meta_prior) {
  const int S = sequences_, td = layout_.total_d(), tz = layout_.total_z();
  w_ = &weights;
  eps_ = &eps;
  targets_ = &targets;
  for (int k = 0; k < layout_.num_layers(); ++k) {
    const Scalar c = static_cast<Scalar>(meta_prior[k] / tz);
    kl_coef_.segment(layout_.z_offset(k), layout_.spec().layers[k].z).setConstant(c);
  }
  const auto r = weights.R();
  const auto rbias = weights.RBias().col(0);
  const auto wz = weights.Wz();
  const auto a_mu = a.mu();
  const auto a_ls = a.log_sigma();
  h_.leftCols(S) = start.h;
  d_.leftCols(S) = start.d;
  for (int t = 0; t < steps_; ++t) {
    const int c0 = t * S;
    internal::StepForward<Scalar>(
        r, rbias, wz, rate_, keep_, td, tz, Source::kPosterior, d_.middleCols(c0, S),
        h_.middleCols(c0, S), a_mu.middleCols(c0, S), a_ls.middleCols(c0, S),
        eps.middleCols(c0, S), pre_, mu_p_.middleCols(c0, S), ls_p_.middleCols(c0, S),
        sig_p_.middleCols(c0, S), mu_q_.middleCols(c0, S), ls_q_.middleCols(c0, S),
        sig_q_.middleCols(c0, S), z_.middleCols(c0, S), h_.middleCols(c0 + S, S),
        d_.middleCols(c0 + S, S));
  }
  // Output layer for all steps at once (one large product).
  const int d0 = layout_.d0();
  x_.noalias() = weights.Wx() * d_.block(0, S, d0, cols_);
  x_.colwise() += weights.Bx().col(0);
  internal::SoftmaxPerDof(layout_, x_, &log_x_);
  LossTerms& terms = terms_;
  terms.regulation = 0;
  // KL(target || x); targets are strictly positive codes.
  terms.reconstruction = static_cast<double>(
      (targets.array() * (targets.array().log() - log_x_.array())).sum());
  for (int k = 0; k < layout_.num_layers(); ++k) {
    const int off = layout_.z_offset(k), n = layout_.spec().layers[k].z;
    const auto lp = ls_p_.middleRows(off, n).array();
    const auto lq = ls_q_.middleRows(off, n).array();
    const auto sp = sig_p_.middleRows(off, n).array();
    const auto sq = sig_q_.middleRows(off, n).array();
    const auto diff = mu_q_.middleRows(off, n).array() - mu_p_.middleRows(off, n).array();
    terms.kl_per_layer[k] = static_cast<double>(
        ((lp - lq) + (diff.square() + sq.square()) / (Scalar(2) * sp.square()) - Scalar(0.5))
            .sum());
    terms.regulation += meta_prior[k] * terms.kl_per_layer[k];
  }
  terms.loss = terms.reconstruction / layout_.spec().num_dofs() + terms.regulation / tz;
  return terms_;
}

template <typename Scalar>
void PosteriorPass<Scalar>::Backward(Weights<Scalar>* grad_w, AdaptiveVariables<Scalar>* grad_a) {
  const int S = sequences_, td = layout_.total_d(), tz = layout_.total_z(), d0 = layout_.d0();
  const Weights<Scalar>& w = *w_;
  if (!weights_frozen_ || transposed_ != &w) {
    r_t_ = w.R().transpose();
    wx_t_ = w.Wx().transpose();
    transposed_ = &w;
  }
  const Scalar inv_dofs = Scalar(1) / static_cast<Scalar>(layout_.spec().num_dofs());
  g_out_ = (x_ - *targets_) * inv_dofs;
  g_d0_.topRows(d0).noalias() = wx_t_ * g_out_;  // the rows below d0 stay zero
  g_h_next_.setZero();
  g_start_d_.setZero();  // holds dL/dd(t) coming from step t+1 through R
  auto a_mu_g = grad_a->mu();
  auto a_ls_g = grad_a->log_sigma();
  const int zp = td, zlp = td + tz, zq = td + 2 * tz, zlq = td + 3 * tz;
  for (int t = steps_ - 1; t >= 0; --t) {
    const int c0 = t * S;
    // Whole columns, so one flat loop: dL/dh = dL/dd (1 - d^2) + dL/dh(t+1) (1 - a).
    const auto d_t = Flat(d_.middleCols(c0 + S, S));
    Flat(g_h_) = (Flat(g_start_d_) + Flat(g_d0_.middleCols(c0, S))) * (Scalar(1) - d_t.square()) +
                 Flat(g_h_next_) * Flat(keep_tile_);
    auto gp = g_pre_.middleCols(c0, S);
    gp.topRows(td) = (g_h_.array().colwise() * rate_.array()).matrix();
    // total_z (5) rows: dot products of Wz's columns with g (lazy over the transposed view)
    // beat GEMM 3x and the lazy product of a transposed copy 7x (measured, 5x50 by 50x7).
    g_z_.noalias() = w.Wz().transpose().lazyProduct(gp.topRows(td));
    const auto mup = mu_p_.middleCols(c0, S).array();
    const auto muq = mu_q_.middleCols(c0, S).array();
    const auto sp = sig_p_.middleCols(c0, S).array();
    const auto sq = sig_q_.middleCols(c0, S).array();
    const auto ep = eps_->middleCols(c0, S).array();
    const auto diff = muq - mup;
    const auto inv_vp = sp.square().inverse();
    const auto c = kl_coef_.array();
    gp.middleRows(zq, tz) =
        ((g_z_.array() + (diff * inv_vp).colwise() * c) * (Scalar(1) - muq.square())).matrix();
    gp.middleRows(zlq, tz) =
        (g_z_.array() * sq * ep + (sq.square() * inv_vp - Scalar(1)).colwise() * c).matrix();
    gp.middleRows(zp, tz) = ((-(diff * inv_vp)).colwise() * c * (Scalar(1) - mup.square())).matrix();
    gp.middleRows(zlp, tz) =
        ((Scalar(1) - (diff.square() + sq.square()) * inv_vp).colwise() * c).matrix();
    a_mu_g.middleCols(c0, S) = gp.middleRows(zq, tz);
    a_ls_g.middleCols(c0, S) = gp.middleRows(zlq, tz);
    SmallProduct<Scalar>(r_t_, gp, g_start_d_);
    g_h_next_.swap(g_h_);
  }
  g_start_h_ = (g_h_next_.array().colwise() * keep_.array()).matrix();
  if (grad_w == nullptr) return;
  WeightGradients(grad_w);
}

// One product per piece over all steps and sequences, in slices of kSlice columns: Eigen
// packs a product's operands on the stack up to 128 KiB and on the heap beyond (70 x 504
// doubles is 282 KiB), and Backward must not allocate.
template <typename Scalar>
void PosteriorPass<Scalar>::WeightGradients(Weights<Scalar>* grad_w) const {
  constexpr int kSlice = 64;
  const int S = sequences_, td = layout_.total_d(), d0 = layout_.d0();
  auto gr = grad_w->R();
  auto gwz = grad_w->Wz();
  auto gwx = grad_w->Wx();
  gr.setZero();
  gwz.setZero();
  gwx.setZero();
  for (int c = 0; c < cols_; c += kSlice) {
    const int n = std::min(kSlice, cols_ - c);
    gr.noalias() += g_pre_.middleCols(c, n) * d_.middleCols(c, n).transpose();
    gwz.noalias() += g_pre_.block(0, c, td, n) * z_.middleCols(c, n).transpose();
    gwx.noalias() += g_out_.middleCols(c, n) * d_.block(0, S + c, d0, n).transpose();
  }
  gr.array() *= r_maskf_.array();
  gwz.array() *= wz_maskf_.array();
  grad_w->RBias().col(0) = g_pre_.rowwise().sum();
  grad_w->Bx().col(0) = g_out_.rowwise().sum();
}

template <typename Scalar>
std::vector<double> PosteriorPass<Scalar>::ReconstructionPerSequence() const {
  std::vector<double> out(sequences_, 0.0);
  for (int j = 0; j < cols_; ++j) {
    const auto y = targets_->col(j).array();
    out[j % sequences_] += static_cast<double>((y * (y.log() - log_x_.col(j).array())).sum());
  }
  return out;
}

template <typename Scalar>
double PosteriorPass<Scalar>::MultiplyAddsPerIteration() const {
  const double td = layout_.total_d(), tz = layout_.total_z(), rr = layout_.recurrent_rows();
  const double nx = layout_.output_units(), d0 = layout_.d0(), n = cols_;
  const double forward = n * (rr * td + td * tz + nx * d0);
  const double backward_inputs = n * (td * rr + tz * td + d0 * nx);
  const double backward_weights = n * (rr * td + td * tz + nx * d0);
  return forward + backward_inputs + backward_weights;
}

template class PosteriorPass<float>;
template class PosteriorPass<double>;

}  // namespace dyad::pvrnn
