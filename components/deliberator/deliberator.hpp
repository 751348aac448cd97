/// The robot's mind in an experiment graph: each step it takes the executed position into a
/// sliding window, re-infers its latent state by error regression (dyad::pvrnn::ErrorRegression,
/// Adam or Ceres LBFGS) and publishes the next intended position with the window's N-ELBO.
///
/// @component deliberator
/// rate_hz: periodic (the study: 10)
/// inputs:
///   executed (CartesianState, optional): the executed robot position s_{t-1}. The newest sample
///     received since the previous step is taken into the window; without one (unbound input,
///     late driver) or with a non-finite x or y, the robot's own last intention is taken
///     instead, and counted.
/// outputs:
///   model (ModelInfo, optional): the model in force: published at step 0 and at every swap, with
///     its path, SHA-256, first step and preparation time (the recording's account of the swaps)
///   intention (Intention): r_t with nelbo/reconstruction/regulation of the best iterate,
///     optimisation_s, iterations and deadline_missed. Published every step, on time: the solve
///     stops before `time_budget_ms` with the best iterate so far (deadline_missed = true).
///     Under the stepped clock there is no time cap (only `iterations`): simulated time does not
///     pass during a step, and a wall-time cap would make the run depend on the machine's load.
/// params:
///   model (string, required, live): .dpvrnn model file (2 DOF: x, y). Set while the graph runs
///     (`dyad param set mind.model=new.dpvrnn --graph G`, the experimenter's page) it is swapped in
///     without stopping: loaded, checked (2 DOFs, as many layers as a set meta_prior has values,
///     the start primitive) and warmed by replaying the window's executed positions off the step
///     thread, then switched at a step boundary; a bad file is refused and the old model steers on.
///   start_primitive (int, 0): the primitive the robot starts drawing
///   preset (string, vcbot): vcbot (W 5, 15 it, Adam 0.3/0.1/0.95, w 1e-5) | reference (W 15,
///     15 it, Adam 0.1/0.9/0.999, w = the model's training meta-prior) | nrl (NRL's own error
///     regression step by step with the vcbot numbers, docs/pvrnn.md "The NRL mode"); the params
///     below override it. The start log names it (a run's log says which regression ran).
///   window (int, 0 = preset), iterations (int, 0 = preset)
///   optimizer (string, adam): adam | ceres
///   adam (map, {}): lr, beta1, beta2, epsilon (keys override the preset)
///   ceres (map, {}): lbfgs_rank, function_tolerance, gradient_tolerance, parameter_tolerance,
///     max_line_search_iterations
///   meta_prior (list, [] = preset): online w per layer, bottom first
///   a_init (string, prior): zero | copy | prior: A of the newest window step
///   noise (string, off): off | fixed | resample
///   a_steps (int, 3): first steps on the start primitive's trained A
///   time_budget_ms (double, 0 = 20% of the period, 20 ms when triggered): optimisation cap per
///     step (wall clock only)
///   seed (int, -1 = the graph's seed for this instance)
/// @endcomponent
///
/// Example (configs): see components/deliberator/example.yaml.
#pragma once

#include <array>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <dyad/component.hpp>
#include <dyad/msg/types.hpp>

#include "dyad/pvrnn/error_regression.hpp"

namespace dyad::deliberator {

class Deliberator final : public Component {
 public:
  static void Describe(ComponentSpec& spec);
  // Loads the model and builds the regression; errors name the param ("params.model: ...").
  // Leaves the component inactive with the intention of step 0 ready.
  Status Configure(Context& ctx) override;
  Status Step(const StepInfo& info) override;
  Status Deactivate() override;

  // Counters (also logged at Deactivate).
  uint64_t deadline_misses() const { return deadline_misses_; }
  uint64_t steps_without_executed() const { return without_executed_; }

 private:
  Context* ctx_ = nullptr;
  Input<msg::CartesianState>* executed_ = nullptr;  // owned by the runtime
  Output<msg::Intention>* intention_ = nullptr;     // owned by the runtime
  Output<msg::ModelInfo>* model_info_ = nullptr;    // owned by the runtime
  std::unique_ptr<pvrnn::ErrorRegression<float>> er_;
  pvrnn::ErrorRegressionOptions options_;  // as configured (the live params: from ctx.params())
  int start_primitive_ = 0;
  uint64_t seed_ = 0;

  // Model swaps (the live `model`). PrepareModel runs off the step thread (Context::
  // PrepareLiveParam) and leaves the new regression in `prepared_`; SwapModel, the commit, swaps
  // it in at the step boundary where the runtime applies the value. ctx.params() does not change
  // while PrepareModel runs (the runtime holds this component's other live changes).
  Status PrepareModel(const std::string& path);
  Status SwapModel();
  struct Prepared {
    std::unique_ptr<pvrnn::ErrorRegression<float>> er;
    msg::ModelInfo info;
    uint64_t fed = 0;  // executed positions it was warmed with (history_fed_ when prepared)
  };
  std::mutex swap_mutex_;  // prepared_ and the history
  Prepared prepared_;
  std::string model_path_;  // in force
  // The last executed positions fed to er_ (a ring of the window's size), and how many were fed
  // since its Reset: a prepared model replays them, so it starts where the robot is.
  std::vector<std::array<double, 2>> history_;
  uint64_t history_fed_ = 0;
  int layers_ = 0;             // of the model in force
  msg::ModelInfo first_info_;  // published at step 0 (unless a swap came first)
  bool model_published_ = false;
  double budget_s_ = 0.02;
  bool stepped_ = false;  // stepped clock: no wall-time cap (see Step)
  uint64_t deadline_misses_ = 0, without_executed_ = 0, steps_ = 0;
  msg::Intention out_;
  // Live params (iterations, meta_prior) as last applied, and the preset's for their "0" / "[]".
  Status FollowLiveParams();
  int64_t live_iterations_ = 0;
  std::vector<double> live_meta_prior_, preset_meta_prior_;
  int preset_iterations_ = 15;
};

}  // namespace dyad::deliberator
