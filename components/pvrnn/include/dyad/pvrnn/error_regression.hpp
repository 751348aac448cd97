// dyad/pvrnn/error_regression.hpp: online posterior adaptation over a sliding window (issue 4),
// the robot's deliberation step.
//
// Each experiment step the robot (1) takes the executed position of the step it intended last,
// (2) re-infers its latent state by minimising the window loss (negative ELBO of the last W
// executed positions, weights frozen, only the window's A optimised, per-layer online
// meta-prior), (3) continues the generator from the inferred state to produce the next intended
// position.
//
// Timeline (t counts executed steps from 0):
//   Reset(p)        state 0; intention for step 0 (posterior on primitive p's trained A).
//   Step(s_t)       window <- s_t; optimise; intention for step t+1 from the posterior state
//                   after step t (the prior; the primitive's trained A while t+1 < a_steps).
// The window: W columns of targets (softmax codes of the executed positions), A (mu and
// log-sigma parts), eps, starting from `start` (the state before the window's first step).
// - Before the window is full (t + 1 < W) it grows: the window holds steps 0..t from the zero
//   initial state, so regression starts with the first executed step and the first steps of a
//   run match the trained primitive exactly when nothing disturbs it.
// - When full, a new step slides it by one: `start` becomes the posterior state after the
//   window's first step (of the best iterate), A, targets and eps shift left by one column.
// - The new step's A: the start primitive's trained A while t < a_steps (as generation),
//   otherwise `a_init`: zero; copy of the previous step's A; or prior (A such that the
//   posterior equals the prior given the previous state: A = pre_prior - pre_posterior).
// - Noise: off (eps = 0: means only); fixed (each step's eps drawn once, when that step is
//   generated, and kept while it is in the window); resample (new eps for the whole window
//   every step). Always fixed during one solve. The intention's own step uses the same eps rule.
// - Best iterate: every evaluated A is a candidate; the lowest loss wins (it may be the start
//   point). Its states feed the slide and the generator. Evaluation count, iterations and
//   time are reported per step.
// - Time: `Step(executed, deadline)` never starts an iteration expected to end after the
//   deadline (see window_optimizer.hpp); at least one evaluation always runs.
// - No allocation in Step with Adam once every window size up to W has been seen (tested);
//   Ceres allocates inside its solver.
//
// - Engine: `dyad` (the above) or `nrl`: NRL's own online ER, step by step (nrl_regression.hpp:
//   free generation until W positions are held, A from 0, Adam's state kept across steps, NRL's
//   prior path and gradient, its kept-A bug); for reproducing results published with NRL. With
//   `nrl` the options a_init and ceres are not used, optimizer must be adam and noise off or
//   resample (NRL's N(0,1) every pass); the StepResult's initial_loss is 0, evaluations = iterations.
//
// Example (VCBot settings, MacawBot, start on the head):
//   auto er = ErrorRegression<float>::Create(model, ErrorRegressionOptions::Vcbot()).value();
//   er->Reset(/*start_primitive=*/1, /*seed=*/1);
//   const double* r0 = er->intention();                    // num_dofs values
//   const StepResult& res = er->Step(executed_xy, deadline);  // res.intention: next position
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "dyad/pvrnn/adam.hpp"
#include "dyad/pvrnn/ceres_window_optimizer.hpp"
#include "dyad/pvrnn/model.hpp"
#include "dyad/pvrnn/nrl_regression.hpp"
#include "dyad/pvrnn/prior_generator.hpp"
#include "dyad/pvrnn/window_objective.hpp"
#include "dyad/pvrnn/window_optimizer.hpp"

namespace dyad::pvrnn {

enum class AInit { kZero, kCopy, kPrior };
enum class NoiseMode { kOff, kFixed, kResample };
enum class OptimizerKind { kAdam, kCeres };
enum class Engine { kDyad, kNrl };

// Parse/print the YAML spellings: "zero|copy|prior", "off|fixed|resample", "adam|ceres".
std::optional<AInit> ParseAInit(std::string_view s);
std::optional<NoiseMode> ParseNoiseMode(std::string_view s);
std::optional<OptimizerKind> ParseOptimizerKind(std::string_view s);
std::optional<Engine> ParseEngine(std::string_view s);  // "dyad|nrl"
const char* ToString(AInit v);
const char* ToString(NoiseMode v);
const char* ToString(OptimizerKind v);
const char* ToString(Engine v);

struct ErrorRegressionOptions {
  int window = 5;                  // W, steps; REQUIRES 1..1000
  int iterations = 15;             // optimiser iterations per step; REQUIRES 1..100000
  // Online meta-prior per layer (bottom first); empty = the model's training w.
  // REQUIRES empty or one finite value >= 0 per layer.
  std::vector<double> meta_prior = {1e-5, 1e-5};
  AInit a_init = AInit::kPrior;
  NoiseMode noise = NoiseMode::kOff;
  int a_steps = 3;                 // first steps on the start primitive's trained A; REQUIRES >= 0
  OptimizerKind optimizer = OptimizerKind::kAdam;
  AdamOptions adam{0.3, 0.1, 0.95, 1e-8};
  CeresOptions ceres;
  Engine engine = Engine::kDyad;

  // The interactive VCBot settings: W 5, 15 iterations, Adam lr 0.3, beta1 0.1, beta2 0.95,
  // w 1e-5 (these are also the defaults above).
  static ErrorRegressionOptions Vcbot();
  // The reference implementation's defaults: W 15, 15 iterations, Adam lr 0.1 (beta1 0.9,
  // beta2 0.999), w = the model's training meta-prior (meta_prior empty; 0.01 for MacawBot).
  static ErrorRegressionOptions Reference();
  // NRL's own ER (engine nrl) with the study's VCBot settings as they were run on NRL: W 5, 15
  // iterations, Adam lr 0.3, beta1 0.1, beta2 0.95, NRL's epsilon 1e-20, w 1e-5, the first 3
  // intentions on the start primitive's trained A, NRL's noise (resample; off for a
  // deterministic run).
  static ErrorRegressionOptions Nrl();
  // "vcbot", "reference" or "nrl"; nullopt otherwise.
  static std::optional<ErrorRegressionOptions> Preset(std::string_view name);

  // Every broken constraint (fields as in YAML: "window", "meta_prior", "adam.lr", ...);
  // `num_layers` checks meta_prior's length (pass -1 to skip). Validate: the first.
  std::vector<FieldProblem> Problems(int num_layers) const;
  Status Validate(int num_layers) const;
};

// Outcome of one Step (also of Reset, with no optimisation).
struct StepResult {
  int64_t step = -1;          // index of the executed step just taken in (-1 after Reset)
  int window_fill = 0;        // steps in the window (grows to W)
  bool regressed = true;      // false while the nrl engine generates freely (window not yet full)
  LossTerms loss;             // of the best iterate (NRL normalisation; `loss` is the N-ELBO)
  double initial_loss = 0;    // at the start point of the solve
  int iterations = 0;
  int evaluations = 0;
  double optimisation_s = 0;  // wall time of the solve
  bool stopped_by_deadline = false;
  const double* intention = nullptr;  // num_dofs values: the intended position of step + 1
};

template <typename Scalar>
class ErrorRegression {
 public:
  // Errors name the option ("window: must be in 1..1000, got 0") or the model/primitive.
  static StatusOr<std::unique_ptr<ErrorRegression>> Create(const Model& model,
                                                           const ErrorRegressionOptions& options);
  ~ErrorRegression();
  ErrorRegression(const ErrorRegression&) = delete;
  ErrorRegression& operator=(const ErrorRegression&) = delete;

  // Starts a run on `start_primitive` (REQUIRES 0 <= p < model.sequences(); checked, error
  // names it). Computes the intention for step 0.
  Status Reset(int start_primitive, uint64_t seed);
  // Takes the executed position (num_dofs values) of the step last intended, optimises until
  // `deadline` at the latest, and computes the next intention. REQUIRES Reset() first.
  // A non-finite value is replaced by the intention for that step (it would poison the state).
  const StepResult& Step(const double* executed,
                         SteadyClock::time_point deadline = SteadyClock::time_point::max());

  // Changes the optimiser's iterations per step and the online meta-prior between two steps (a
  // deliberator's live parameters); empty `meta_prior`: the model's training w. Checked as
  // Create checks them (the error names the field); on error nothing changes.
  Status Retune(int iterations, const std::vector<double>& meta_prior);

  const double* intention() const { return intention_.data(); }
  const StepResult& last() const { return result_; }
  const ErrorRegressionOptions& options() const { return options_; }
  const ModelSpec& spec() const { return spec_; }
  int num_dofs() const { return spec_.num_dofs(); }
  int window_fill() const { return fill_; }
  // The window problem of the last Step (benchmarks, tests: to solve it again from the same
  // start): its objective (window data as set) and the A the optimiser started from.
  // REQUIRES at least one Step, engine dyad (the nrl engine has its own window).
  const WindowObjective<Scalar>& last_objective() const { return *objectives_[fill_ - 1]; }
  const AdaptiveVariables<Scalar>& last_start_a() const { return start_a_[fill_ - 1]; }

 private:
  class Function;
  const StepResult& NrlStep(const double* executed, SteadyClock::time_point deadline);
  ErrorRegression(const Model& model, const ErrorRegressionOptions& options);
  void DrawNoise(Eigen::Ref<MatrixT<Scalar>> eps);
  void InitNewColumn(int col, int64_t t);
  void GenerateIntention(int64_t t);

  ModelSpec spec_;
  ErrorRegressionOptions options_;
  Weights<Scalar> weights_;
  AdaptiveVariables<Scalar> trained_a_;  // the model's A, for the start primitive's first steps
  std::vector<double> meta_prior_;
  int total_z_ = 0, total_d_ = 0;
  int primitive_ = 0;
  int64_t t_ = 0;  // executed steps taken in
  int fill_ = 0;
  std::mt19937_64 rng_;
  std::normal_distribution<double> n01_;
  // Window (W columns; the first fill_ used).
  MatrixT<Scalar> targets_, eps_, a_mu_, a_ls_;
  NetworkState<Scalar> start_, end_, best_first_, best_end_;
  // Per window size n = 1..W (index n-1): objective and working A.
  std::vector<std::unique_ptr<WindowObjective<Scalar>>> objectives_;
  std::vector<AdaptiveVariables<Scalar>> work_a_, best_a_, start_a_;
  std::unique_ptr<Function> function_;
  std::unique_ptr<WindowOptimizer<Scalar>> optimizer_;
  PriorGenerator<Scalar> generator_;
  MatrixT<Scalar> gen_eps_, gen_a_mu_, gen_a_ls_, pre_;
  Eigen::VectorXd intention_, executed_code_d_;
  VectorT<Scalar> executed_code_;
  StepResult result_;
  std::unique_ptr<NrlRegression> nrl_;  // engine nrl only
};

}  // namespace dyad::pvrnn
