#include "dyad/pvrnn/window_objective.hpp"

namespace dyad::pvrnn {

template <typename Scalar>
WindowObjective<Scalar>::WindowObjective(const Weights<Scalar>& weights, int window)
    : weights_(weights), window_(window), pass_(weights.layout(), window, 1) {
  pass_.AssumeWeightsFrozen();
  const auto& l = weights.layout();
  targets_ = MatrixT<Scalar>::Zero(l.output_units(), window);
  eps_ = MatrixT<Scalar>::Zero(l.total_z(), window);
  start_ = NetworkState<Scalar>::Zero(l.total_d(), 1);
  meta_prior_.assign(l.num_layers(), 0.0);
}

template <typename Scalar>
void WindowObjective<Scalar>::SetWindow(const Eigen::Ref<const MatrixT<Scalar>>& targets,
                                        const NetworkState<Scalar>& start,
                                        const Eigen::Ref<const MatrixT<Scalar>>& eps,
                                        const std::vector<double>& meta_prior) {
  targets_ = targets;
  start_.h = start.h;
  start_.d = start.d;
  eps_ = eps;
  meta_prior_ = meta_prior;
}

template <typename Scalar>
const LossTerms& WindowObjective<Scalar>::Evaluate(const AdaptiveVariables<Scalar>& a,
                                            AdaptiveVariables<Scalar>* grad) {
  const LossTerms& terms = pass_.Forward(weights_, a, eps_, targets_, start_, meta_prior_);
  if (grad != nullptr) pass_.Backward(nullptr, grad);
  return terms;
}

template class WindowObjective<float>;
template class WindowObjective<double>;

}  // namespace dyad::pvrnn
