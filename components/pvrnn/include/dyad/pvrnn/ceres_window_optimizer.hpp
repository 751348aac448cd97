// dyad/pvrnn/ceres_window_optimizer.hpp: Ceres' LBFGS (GradientProblemSolver, Wolfe line search)
// as a WindowOptimizer for online error regression (issue 4).
//
// Contract
// - The same objective and exact gradient as Adam (the WindowFunction), in double on Ceres' side
//   (A is converted to Scalar for each evaluation). Noise stays fixed during a solve.
// - At most `budget.max_iterations` LBFGS iterations (`max_num_iterations`); each iteration runs a
//   Wolfe line search and so costs one or more evaluations. Time is capped twice: Ceres'
//   `max_solver_time_in_seconds` (remaining time at the start) and an IterationCallback that
//   ends the solve when the moving average of past iteration times says the next one would end
//   after the deadline. An iteration in progress is not interrupted (one costs ~10-50 us here).
// - LBFGS with approximate-eigenvalue scaling of the initial Hessian (measured better here).
// - Logging silent (SILENT, and glog warnings off: see the constructor). Ceres allocates inside every Solve (its own vectors and summary); the
//   Adam path is the allocation-free one.
//
// Example:
//   CeresWindowOptimizer<float> lbfgs(CeresOptions{});
//   SolveReport r = lbfgs.Minimize(f, a, {.max_iterations = 15, .deadline = t0 + 1ms});
#pragma once

#include <string>
#include <vector>

#include "dyad/pvrnn/model_spec.hpp"
#include "dyad/pvrnn/window_optimizer.hpp"

namespace dyad::pvrnn {

// Defaults chosen by measurement (bench_regress): tolerances tight enough that a 15-iteration
// solve is not ended early by a tiny relative change (the window loss is ~1e-2..1).
struct CeresOptions {
  int lbfgs_rank = 20;               // LBFGS memory (max_lbfgs_rank); REQUIRES 1..100
  double function_tolerance = 1e-10; // stop when |df|/f falls below; REQUIRES >= 0
  double gradient_tolerance = 1e-10; // stop when max|grad| falls below; REQUIRES >= 0
  double parameter_tolerance = 1e-12; // stop when |dx|/(|x|+tol) falls below; REQUIRES >= 0
  int max_line_search_iterations = 20;  // evaluations per line search; REQUIRES >= 1
  // Every broken constraint, fields named "ceres.<name>"; Validate: the first.
  std::vector<FieldProblem> Problems() const;
  Status Validate() const;
};

template <typename Scalar>
class CeresWindowOptimizer final : public WindowOptimizer<Scalar> {
 public:
  // Also lowers glog's level to ERROR for the process (Ceres' line search warns through it).
  explicit CeresWindowOptimizer(const CeresOptions& options);
  SolveReport Minimize(WindowFunction<Scalar>& f, AdaptiveVariables<Scalar>& a,
                       const SolveBudget& budget) override;

 private:
  CeresOptions options_;
  double iteration_s_ = 0;  // moving average of one LBFGS iteration's wall time
};

}  // namespace dyad::pvrnn
