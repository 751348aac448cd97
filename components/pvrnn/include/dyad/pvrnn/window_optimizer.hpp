// dyad/pvrnn/window_optimizer.hpp: the optimiser interface of online error regression (issue 4)
// and its Adam implementation. Ceres' LBFGS is the other implementation
// (ceres_window_optimizer.hpp); ErrorRegression picks one from its options.
//
// Contract
// - An optimiser minimises a `WindowFunction` (the window loss as a function of the window's A,
//   with its exact gradient) from the A it is given, for at most `budget.max_iterations`
//   iterations and never starting an iteration it expects to end after `budget.deadline`.
// - It does not track the best point: the function does (every point it evaluates is a
//   candidate; ErrorRegression keeps the lowest). The A left in `a` is the optimiser's last
//   iterate, not necessarily the best.
// - The noise (eps) of the window is part of the function and stays fixed during a solve.
// - AdamWindowOptimizer allocates nothing in Minimize once it has seen each window size.
//
// Example:
//   AdamWindowOptimizer<float> adam(AdamOptions{.lr = 0.3, .beta1 = 0.1, .beta2 = 0.95});
//   SolveReport r = adam.Minimize(f, a, {.max_iterations = 15, .deadline = t0 + 1ms});
#pragma once

#include <chrono>
#include <memory>
#include <vector>

#include "dyad/pvrnn/adam.hpp"
#include "dyad/pvrnn/parameters.hpp"

namespace dyad::pvrnn {

using SteadyClock = std::chrono::steady_clock;

// f(A) and dA. Implemented by ErrorRegression (and by tests).
template <typename Scalar>
class WindowFunction {
 public:
  virtual ~WindowFunction() = default;
  // Loss at `a`; writes dLoss/dA into `grad` unless it is null. `a` and `grad` have the shape
  // of the window (total_z x steps, one sequence).
  virtual double Evaluate(const AdaptiveVariables<Scalar>& a, AdaptiveVariables<Scalar>* grad) = 0;
};

struct SolveBudget {
  int max_iterations = 15;  // optimiser iterations (Adam: gradient steps; Ceres: LBFGS iterations)
  SteadyClock::time_point deadline = SteadyClock::time_point::max();
};

struct SolveReport {
  int iterations = 0;    // iterations completed
  int evaluations = 0;   // function (+gradient) evaluations
  bool stopped_by_deadline = false;  // fewer iterations than asked because time ran out
};

template <typename Scalar>
class WindowOptimizer {
 public:
  virtual ~WindowOptimizer() = default;
  // Minimises f from `a` (updated in place). REQUIRES a.sequences() == 1.
  virtual SolveReport Minimize(WindowFunction<Scalar>& f, AdaptiveVariables<Scalar>& a,
                               const SolveBudget& budget) = 0;
};

// Adam restarted for every solve (moments zero, bias correction from step 1), so each
// experiment step is an independent solve like Ceres'. Evaluates f at the start point and after
// each step: `max_iterations` steps cost max_iterations + 1 evaluations, the last without
// gradient. An iteration is skipped when the moving average of past iteration times says it
// would end after the deadline.
template <typename Scalar>
class AdamWindowOptimizer final : public WindowOptimizer<Scalar> {
 public:
  explicit AdamWindowOptimizer(const AdamOptions& options) : options_(options) {}
  SolveReport Minimize(WindowFunction<Scalar>& f, AdaptiveVariables<Scalar>& a,
                       const SolveBudget& budget) override;

 private:
  struct Workspace {
    std::unique_ptr<Adam<Scalar>> adam;
    AdaptiveVariables<Scalar> grad;
  };
  Workspace& WorkspaceFor(const AdaptiveVariables<Scalar>& a);
  AdamOptions options_;
  std::vector<Workspace> by_size_;  // indexed by steps; built on first use of a size
  double iteration_s_ = 0;          // moving average of one iteration's wall time
};

}  // namespace dyad::pvrnn
