#include "dyad/pvrnn/window_optimizer.hpp"

namespace dyad::pvrnn {

template <typename Scalar>
typename AdamWindowOptimizer<Scalar>::Workspace& AdamWindowOptimizer<Scalar>::WorkspaceFor(
    const AdaptiveVariables<Scalar>& a) {
  if (static_cast<int>(by_size_.size()) <= a.steps()) by_size_.resize(a.steps() + 1);
  Workspace& w = by_size_[a.steps()];
  if (!w.adam) {
    w.adam = std::make_unique<Adam<Scalar>>(static_cast<int>(a.flat().size()), options_);
    w.grad = AdaptiveVariables<Scalar>(a.total_z(), a.steps(), 1);
  }
  return w;
}

template <typename Scalar>
SolveReport AdamWindowOptimizer<Scalar>::Minimize(WindowFunction<Scalar>& f, AdaptiveVariables<Scalar>& a,
                                                  const SolveBudget& budget) {
  Workspace& w = WorkspaceFor(a);
  w.adam->m().setZero();
  w.adam->v().setZero();
  w.adam->set_step(0);
  SolveReport r;
  for (int it = 0; it < budget.max_iterations; ++it) {
    const auto t0 = SteadyClock::now();
    if (it > 0 && t0 + std::chrono::duration<double>(iteration_s_) > budget.deadline) {
      r.stopped_by_deadline = true;
      break;
    }
    f.Evaluate(a, &w.grad);
    ++r.evaluations;
    w.adam->Step(a.flat(), w.grad.flat());
    ++r.iterations;
    const double s = std::chrono::duration<double>(SteadyClock::now() - t0).count();
    iteration_s_ = iteration_s_ == 0 ? s : 0.9 * iteration_s_ + 0.1 * s;
  }
  f.Evaluate(a, nullptr);  // the last step's point is a candidate too
  ++r.evaluations;
  return r;
}

template class AdamWindowOptimizer<float>;
template class AdamWindowOptimizer<double>;

}  // namespace dyad::pvrnn
