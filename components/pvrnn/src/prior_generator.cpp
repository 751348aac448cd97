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
  internal::LeakRates(layout, &rate_, &keep_);
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
  internal::SoftmaxPerDof<Scalar>(layout, x_, nullptr);
  return x_;
}

template <typename Scalar>
MatrixT<Scalar> GenerateCodes(const Weights<Scalar>& weights, const AdaptiveVariables<Scalar>& a,
                              const std::vector<int>& sequences, int steps,
                              const GenerateOptions& options) {
  const int cols = static_cast<int>(sequences.size()), tz = a.total_z();
  PriorGenerator<Scalar> gen(weights, cols);
  MatrixT<Scalar> eps = MatrixT<Scalar>::Zero(tz, cols), a_mu(tz, cols), a_ls(tz, cols);
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> n01;
  MatrixT<Scalar> codes(weights.layout().output_units(), static_cast<Eigen::Index>(steps) * cols);
  for (int t = 0; t < steps; ++t) {
    if (options.noise)
      for (Eigen::Index i = 0; i < eps.size(); ++i) eps.data()[i] = static_cast<Scalar>(n01(rng));
    const bool use_a = t < options.a_steps && t < a.steps();
    if (use_a) {
      for (int c = 0; c < cols; ++c) {
        a_mu.col(c) = a.mu().col(a.Column(t, sequences[c]));
        a_ls.col(c) = a.log_sigma().col(a.Column(t, sequences[c]));
      }
    }
    codes.middleCols(static_cast<Eigen::Index>(t) * cols, cols) =
        gen.Step(use_a ? &a_mu : nullptr, use_a ? &a_ls : nullptr, eps);
  }
  return codes;
}

Eigen::MatrixXd GeneratePrimitive(const Model& model, int primitive, int steps,
                                  const GenerateOptions& options) {
  return DecodePositions(model.spec.output,
                         GenerateCodes(model.weights, model.adaptive, {primitive}, steps, options));
}

template class PriorGenerator<float>;
template class PriorGenerator<double>;
template MatrixT<float> GenerateCodes(const Weights<float>&, const AdaptiveVariables<float>&,
                                      const std::vector<int>&, int, const GenerateOptions&);
template MatrixT<double> GenerateCodes(const Weights<double>&, const AdaptiveVariables<double>&,
                                       const std::vector<int>&, int, const GenerateOptions&);

}  // namespace dyad::pvrnn
