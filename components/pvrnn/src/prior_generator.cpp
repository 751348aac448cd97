#include "dyad/pvrnn/prior_generator.hpp"

#include <random>

#include "dyad/pvrnn/softmax_encoding.hpp"
#include "step_kernel.hpp"

namespace dyad::pvrnn {

template <typename Scalar>
PriorGenerator<Scalar>::PriorGenerator(const Weights<Scalar>& weights, int columns)
    : w_(weights), columns_(columns) {
  const auto& layout = w_.layout();
  const int td = layout.total_d(), tz = layout.total_z();
  rate_.resize(td);
  keep_.resize(td);
  for (int i = 0; i < td; ++i) {
    rate_[i] = static_cast<Scalar>(layout.rate()[i]);
    keep_[i] = Scalar(1) - rate_[i];
  }
  state_ = NetworkState<Scalar>::Zero(td, columns);
  next_ = state_;
  pre_.resize(layout.recurrent_rows(), columns);
  for (auto* m : {&mu_p_, &ls_p_, &sig_p_, &mu_q_, &ls_q_, &sig_q_, &z_}) m->resize(tz, columns);
  zero_a_ = MatrixT<Scalar>::Zero(tz, columns);
  x_.resize(layout.output_units(), columns);
}

template <typename Scalar>
void PriorGenerator<Scalar>::Reset() {
  state_.h.setZero();
  state_.d.setZero();
}

template <typename Scalar>
void PriorGenerator<Scalar>::Reset(const NetworkState<Scalar>& state) {
  state_.h = state.h;
  state_.d = state.d;
}

template <typename Scalar>
const MatrixT<Scalar>& PriorGenerator<Scalar>::Step(const MatrixT<Scalar>* a_mu,
                                                    const MatrixT<Scalar>* a_ls,
                                                    const MatrixT<Scalar>& eps) {
  const auto& layout = w_.layout();
  const bool posterior = a_mu != nullptr && a_ls != nullptr;
  internal::StepForward<Scalar>(w_.R(), w_.RBias().col(0), w_.Wz(), rate_, keep_, layout.total_d(),
                                layout.total_z(),
                                posterior ? internal::Source::kPosterior : internal::Source::kPrior,
                                state_.d, state_.h, posterior ? *a_mu : zero_a_,
                                posterior ? *a_ls : zero_a_, eps, pre_, mu_p_, ls_p_, sig_p_, mu_q_,
                                ls_q_, sig_q_, z_, next_.h, next_.d);
  std::swap(state_, next_);
  x_.noalias() = w_.Wx() * state_.d.topRows(layout.d0());
  x_.colwise() += w_.Bx().col(0);
  for (int dof = 0; dof < layout.spec().num_dofs(); ++dof) {
    auto blk = x_.middleRows(layout.output_offset(dof), layout.output_units(dof));
    for (int j = 0; j < columns_; ++j) {
      auto c = blk.col(j);
      c.array() = (c.array() - c.maxCoeff()).exp();
      c /= c.sum();
    }
  }
  return x_;
}

Eigen::MatrixXd GeneratePrimitive(const Model& model, int primitive, int steps,
                                  const GenerateOptions& options) {
  PriorGenerator<double> gen(model.weights, 1);
  const int tz = model.adaptive.total_z();
  Eigen::MatrixXd eps = Eigen::MatrixXd::Zero(tz, 1), a_mu(tz, 1), a_ls(tz, 1);
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> n01;
  Eigen::MatrixXd codes(model.weights.layout().output_units(), steps);
  for (int t = 0; t < steps; ++t) {
    if (options.noise)
      for (int i = 0; i < tz; ++i) eps(i, 0) = n01(rng);
    const bool use_a = t < options.a_steps && t < model.steps();
    if (use_a) {
      a_mu = model.adaptive.mu().col(model.adaptive.Column(t, primitive));
      a_ls = model.adaptive.log_sigma().col(model.adaptive.Column(t, primitive));
    }
    codes.col(t) = gen.Step(use_a ? &a_mu : nullptr, use_a ? &a_ls : nullptr, eps);
  }
  return DecodePositions(model.spec.output, codes);
}

template class PriorGenerator<float>;
template class PriorGenerator<double>;

}  // namespace dyad::pvrnn
