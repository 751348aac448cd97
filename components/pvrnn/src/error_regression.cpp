#include "dyad/pvrnn/error_regression.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "dyad/pvrnn/softmax_encoding.hpp"

namespace dyad::pvrnn {

std::optional<AInit> ParseAInit(std::string_view s) {
  if (s == "zero") return AInit::kZero;
  if (s == "copy") return AInit::kCopy;
  if (s == "prior") return AInit::kPrior;
  return std::nullopt;
}
std::optional<NoiseMode> ParseNoiseMode(std::string_view s) {
  if (s == "off") return NoiseMode::kOff;
  if (s == "fixed") return NoiseMode::kFixed;
  if (s == "resample") return NoiseMode::kResample;
  return std::nullopt;
}
std::optional<OptimizerKind> ParseOptimizerKind(std::string_view s) {
  if (s == "adam") return OptimizerKind::kAdam;
  if (s == "ceres") return OptimizerKind::kCeres;
  return std::nullopt;
}
std::optional<Engine> ParseEngine(std::string_view s) {
  if (s == "dyad") return Engine::kDyad;
  if (s == "nrl") return Engine::kNrl;
  return std::nullopt;
}
const char* ToString(Engine v) { return v == Engine::kDyad ? "dyad" : "nrl"; }
const char* ToString(AInit v) { return v == AInit::kZero ? "zero" : v == AInit::kCopy ? "copy" : "prior"; }
const char* ToString(NoiseMode v) {
  return v == NoiseMode::kOff ? "off" : v == NoiseMode::kFixed ? "fixed" : "resample";
}
const char* ToString(OptimizerKind v) { return v == OptimizerKind::kAdam ? "adam" : "ceres"; }

ErrorRegressionOptions ErrorRegressionOptions::Vcbot() { return ErrorRegressionOptions{}; }

ErrorRegressionOptions ErrorRegressionOptions::Reference() {
  ErrorRegressionOptions o;
  o.window = 15;
  o.iterations = 15;
  o.adam = AdamOptions{0.1, 0.9, 0.999, 1e-8};
  o.meta_prior.clear();  // the model's training w
  return o;
}

ErrorRegressionOptions ErrorRegressionOptions::Nrl() {
  ErrorRegressionOptions o;  // the VCBot settings
  o.engine = Engine::kNrl;
  o.adam.epsilon = 1e-20;  // NRL's NON_ZERO
  o.a_init = AInit::kZero;
  o.noise = NoiseMode::kResample;
  return o;
}

std::optional<ErrorRegressionOptions> ErrorRegressionOptions::Preset(std::string_view name) {
  if (name == "vcbot") return Vcbot();
  if (name == "reference") return Reference();
  if (name == "nrl") return Nrl();
  return std::nullopt;
}

std::vector<FieldProblem> ErrorRegressionOptions::Problems(int num_layers) const {
  std::vector<FieldProblem> out;
  auto add = [&out](const std::string& field, const std::string& msg) { out.push_back({field, msg}); };
  if (window < 1 || window > 1000) add("window", "must be in 1..1000, got " + std::to_string(window));
  if (iterations < 1 || iterations > 100000)
    add("iterations", "must be in 1..100000, got " + std::to_string(iterations));
  if (a_steps < 0) add("a_steps", "must be >= 0, got " + std::to_string(a_steps));
  if (num_layers >= 0 && !meta_prior.empty() && static_cast<int>(meta_prior.size()) != num_layers)
    add("meta_prior", "needs one value per layer (" + std::to_string(num_layers) + "), got " +
                          std::to_string(meta_prior.size()));
  for (size_t k = 0; k < meta_prior.size(); ++k)
    if (!std::isfinite(meta_prior[k]) || meta_prior[k] < 0) {
      std::ostringstream s;
      s << "must be finite and >= 0, got " << meta_prior[k];
      add("meta_prior[" + std::to_string(k) + "]", s.str());
    }
  if (engine == Engine::kNrl && optimizer != OptimizerKind::kAdam)
    add("optimizer", "the nrl engine is NRL's Adam: must be adam, got " + std::string(ToString(optimizer)));
  if (engine == Engine::kNrl && noise == NoiseMode::kFixed)
    add("noise", "the nrl engine draws NRL's noise anew in every pass: must be off or resample, got fixed");
  for (auto& p : adam.Problems()) out.push_back(p);
  for (auto& p : ceres.Problems()) out.push_back(p);
  return out;
}

Status ErrorRegressionOptions::Validate(int num_layers) const {
  const std::vector<FieldProblem> p = Problems(num_layers);
  return p.empty() ? Status::OK() : Status::InvalidArgument(p.front().ToString());
}

// The window loss as the optimisers see it; keeps the best evaluated point and its states.
template <typename Scalar>
class ErrorRegression<Scalar>::Function final : public WindowFunction<Scalar> {
 public:
  explicit Function(ErrorRegression* er) : er_(er) {}
  void Begin(int n) {
    n_ = n;
    evaluations_ = 0;
    best_loss_ = std::numeric_limits<double>::quiet_NaN();
  }
  double Evaluate(const AdaptiveVariables<Scalar>& a, AdaptiveVariables<Scalar>* grad) override {
    WindowObjective<Scalar>& obj = *er_->objectives_[n_ - 1];
    const LossTerms& l = obj.Evaluate(a, grad);
    if (evaluations_++ == 0) er_->result_.initial_loss = l.loss;
    if (evaluations_ == 1 || l.loss < best_loss_ || std::isnan(best_loss_)) {
      best_loss_ = l.loss;
      er_->best_a_[n_ - 1].flat() = a.flat();
      er_->best_first_.h = obj.pass().h_at(0);
      er_->best_first_.d = obj.pass().d_at(0);
      er_->best_end_.h = obj.pass().h_at(n_ - 1);
      er_->best_end_.d = obj.pass().d_at(n_ - 1);
      LossTerms& r = er_->result_.loss;
      r.loss = l.loss;
      r.reconstruction = l.reconstruction;
      r.regulation = l.regulation;
      std::copy(l.kl_per_layer.begin(), l.kl_per_layer.end(), r.kl_per_layer.begin());
    }
    return l.loss;
  }

 private:
  ErrorRegression* er_;
  int n_ = 1;
  int evaluations_ = 0;
  double best_loss_ = 0;
};

template <typename Scalar>
StatusOr<std::unique_ptr<ErrorRegression<Scalar>>> ErrorRegression<Scalar>::Create(
    const Model& model, const ErrorRegressionOptions& options) {
  if (Status s = model.spec.Validate(); !s.ok()) return Status::InvalidArgument("model: " + s.message());
  if (Status s = options.Validate(model.spec.num_layers()); !s.ok()) return s;
  if (model.adaptive.total_z() != model.spec.total_z())
    return Status::InvalidArgument("model: its A has " + std::to_string(model.adaptive.total_z()) +
                                   " rows, the spec " + std::to_string(model.spec.total_z()));
  return std::unique_ptr<ErrorRegression>(new ErrorRegression(model, options));
}

template <typename Scalar>
Status ErrorRegression<Scalar>::Retune(int iterations, const std::vector<double>& meta_prior) {
  ErrorRegressionOptions o = options_;
  o.iterations = iterations;
  o.meta_prior = meta_prior;
  if (Status s = o.Validate(spec_.num_layers()); !s.ok()) return s;
  options_ = o;
  meta_prior_ = meta_prior;
  if (meta_prior_.empty())
    for (const auto& layer : spec_.layers) meta_prior_.push_back(layer.w);
  if (nrl_) nrl_->Retune(iterations, meta_prior_);
  return Status::OK();
}

template <typename Scalar>
ErrorRegression<Scalar>::ErrorRegression(const Model& model, const ErrorRegressionOptions& options)
    : spec_(model.spec),
      options_(options),
      weights_(model.weights.Cast<Scalar>()),
      trained_a_(model.adaptive.Cast<Scalar>()),
      generator_(weights_, 1) {
  const NetworkLayout& l = weights_.layout();
  total_z_ = l.total_z();
  total_d_ = l.total_d();
  meta_prior_ = options.meta_prior;
  if (meta_prior_.empty())
    for (const auto& layer : spec_.layers) meta_prior_.push_back(layer.w);
  const int W = options.window;
  targets_ = MatrixT<Scalar>::Zero(l.output_units(), W);
  eps_ = MatrixT<Scalar>::Zero(total_z_, W);
  a_mu_ = MatrixT<Scalar>::Zero(total_z_, W);
  a_ls_ = MatrixT<Scalar>::Zero(total_z_, W);
  for (auto* s : {&start_, &end_, &best_first_, &best_end_}) *s = NetworkState<Scalar>::Zero(total_d_, 1);
  for (int n = 1; n <= W; ++n) {
    objectives_.push_back(std::make_unique<WindowObjective<Scalar>>(weights_, n));
    work_a_.emplace_back(total_z_, n, 1);
    best_a_.emplace_back(total_z_, n, 1);
    start_a_.emplace_back(total_z_, n, 1);
  }
  function_ = std::make_unique<Function>(this);
  if (options.optimizer == OptimizerKind::kCeres)
    optimizer_ = std::make_unique<CeresWindowOptimizer<Scalar>>(options.ceres);
  else
    optimizer_ = std::make_unique<AdamWindowOptimizer<Scalar>>(options.adam);
  gen_eps_ = MatrixT<Scalar>::Zero(total_z_, 1);
  gen_a_mu_ = MatrixT<Scalar>::Zero(total_z_, 1);
  gen_a_ls_ = MatrixT<Scalar>::Zero(total_z_, 1);
  pre_ = MatrixT<Scalar>::Zero(l.recurrent_rows(), 1);
  intention_ = Eigen::VectorXd::Zero(spec_.num_dofs());
  executed_code_d_ = Eigen::VectorXd::Zero(spec_.num_dofs());  // clamped position
  executed_code_ = VectorT<Scalar>::Zero(l.output_units());
  result_.loss.kl_per_layer.assign(spec_.num_layers(), 0.0);
  result_.intention = intention_.data();
  if (options.engine == Engine::kNrl) nrl_ = std::make_unique<NrlRegression>(model, options, meta_prior_);
}

template <typename Scalar>
ErrorRegression<Scalar>::~ErrorRegression() = default;

template <typename Scalar>
Status ErrorRegression<Scalar>::Reset(int start_primitive, uint64_t seed) {
  if (start_primitive < 0 || start_primitive >= trained_a_.sequences())
    return Status::InvalidArgument("start_primitive: must be in 0.." + std::to_string(trained_a_.sequences() - 1) +
                                   " (the model's primitives), got " + std::to_string(start_primitive));
  primitive_ = start_primitive;
  rng_.seed(seed);
  n01_.reset();
  t_ = 0;
  fill_ = 0;
  for (auto* m : {&targets_, &eps_, &a_mu_, &a_ls_}) m->setZero();
  for (auto* s : {&start_, &end_, &best_first_, &best_end_}) {
    s->h.setZero();
    s->d.setZero();
  }
  std::vector<double> kl = std::move(result_.loss.kl_per_layer);  // keep its storage
  result_ = StepResult{};
  result_.loss.kl_per_layer = std::move(kl);
  std::fill(result_.loss.kl_per_layer.begin(), result_.loss.kl_per_layer.end(), 0.0);
  result_.intention = intention_.data();
  if (nrl_) {
    nrl_->Reset(start_primitive, seed);
    for (int k = 0; k < spec_.num_dofs(); ++k) intention_[k] = nrl_->intention()[k];
    result_.regressed = false;
    return Status::OK();
  }
  GenerateIntention(0);
  return Status::OK();
}

template <typename Scalar>
void ErrorRegression<Scalar>::DrawNoise(Eigen::Ref<MatrixT<Scalar>> eps) {
  for (Eigen::Index j = 0; j < eps.cols(); ++j)
    for (Eigen::Index i = 0; i < eps.rows(); ++i) eps(i, j) = static_cast<Scalar>(n01_(rng_));
}

namespace {
template <typename M>
void ShiftLeft(M& m) {
  for (Eigen::Index j = 0; j + 1 < m.cols(); ++j) m.col(j) = m.col(j + 1);
}
}  // namespace

template <typename Scalar>
void ErrorRegression<Scalar>::InitNewColumn(int col, int64_t t) {
  if (t < options_.a_steps && t < trained_a_.steps()) {
    const int c = trained_a_.Column(static_cast<int>(t), primitive_);
    a_mu_.col(col) = trained_a_.mu().col(c);
    a_ls_.col(col) = trained_a_.log_sigma().col(c);
    return;
  }
  switch (options_.a_init) {
    case AInit::kZero:
      a_mu_.col(col).setZero();
      a_ls_.col(col).setZero();
      break;
    case AInit::kCopy:
      // With W = 1 the previous step's A is still in column 0 (nothing shifted).
      if (col > 0) {
        a_mu_.col(col) = a_mu_.col(col - 1);
        a_ls_.col(col) = a_ls_.col(col - 1);
      } else if (t == 0) {
        a_mu_.col(col).setZero();
        a_ls_.col(col).setZero();
      }
      break;
    case AInit::kPrior: {
      // The state before step t is the end state of the previous window's best iterate.
      const NetworkLayout& l = weights_.layout();
      pre_.noalias() = weights_.R() * best_end_.d;
      pre_ += weights_.RBias();
      a_mu_.col(col) = pre_.col(0).segment(l.row_mu_p(), total_z_) - pre_.col(0).segment(l.row_mu_q(), total_z_);
      a_ls_.col(col) = pre_.col(0).segment(l.row_ls_p(), total_z_) - pre_.col(0).segment(l.row_ls_q(), total_z_);
      break;
    }
  }
}

template <typename Scalar>
void ErrorRegression<Scalar>::GenerateIntention(int64_t t) {
  // From the posterior state after step t-1 (zero for t = 0).
  generator_.Reset(best_end_);
  if (options_.noise == NoiseMode::kOff)
    gen_eps_.setZero();
  else
    DrawNoise(gen_eps_);
  const bool use_a = t < options_.a_steps && t < trained_a_.steps();
  if (use_a) {
    const int c = trained_a_.Column(static_cast<int>(t), primitive_);
    gen_a_mu_.col(0) = trained_a_.mu().col(c);
    gen_a_ls_.col(0) = trained_a_.log_sigma().col(c);
  }
  const MatrixT<Scalar>& codes = generator_.Step(use_a ? &gen_a_mu_ : nullptr, use_a ? &gen_a_ls_ : nullptr, gen_eps_);
  DecodePosition<Scalar>(spec_.output, codes.data(), intention_.data());
}

template <typename Scalar>
const StepResult& ErrorRegression<Scalar>::Step(const double* executed, SteadyClock::time_point deadline) {
  if (nrl_) return NrlStep(executed, deadline);
  const auto t0 = SteadyClock::now();
  const int W = options_.window;
  if (fill_ == W) {
    start_.h = best_first_.h;
    start_.d = best_first_.d;
    ShiftLeft(targets_);
    ShiftLeft(eps_);
    ShiftLeft(a_mu_);
    ShiftLeft(a_ls_);
  } else {
    ++fill_;
  }
  const int n = fill_, col = n - 1;
  // Clamp to the encoding range widened by half its width (further out the code underflows).
  // A non-finite value (a bad reading) is replaced by the intention for this step: one NaN in
  // the targets would make every A, state and later intention NaN for good.
  for (int k = 0; k < spec_.num_dofs(); ++k) {
    const DofRange& r = spec_.output.dofs[k];
    const double half = 0.5 * (r.max - r.min);
    const double v = std::isfinite(executed[k]) ? executed[k] : intention_[k];
    executed_code_d_[k] = std::clamp(v, r.min - half, r.max + half);
  }
  EncodePosition<Scalar>(spec_.output, executed_code_d_.data(), targets_.col(col).data());
  switch (options_.noise) {
    case NoiseMode::kOff: eps_.col(col).setZero(); break;
    case NoiseMode::kFixed: eps_.col(col) = gen_eps_; break;  // the eps this step was generated with
    case NoiseMode::kResample: DrawNoise(eps_.leftCols(n)); break;
  }
  InitNewColumn(col, t_);
  WindowObjective<Scalar>& obj = *objectives_[n - 1];
  obj.SetWindow(targets_.leftCols(n), start_, eps_.leftCols(n), meta_prior_);
  AdaptiveVariables<Scalar>& a = work_a_[n - 1];
  a.mu() = a_mu_.leftCols(n);
  a.log_sigma() = a_ls_.leftCols(n);
  start_a_[n - 1].flat() = a.flat();
  function_->Begin(n);
  const SolveReport rep = optimizer_->Minimize(*function_, a, SolveBudget{options_.iterations, deadline});
  const AdaptiveVariables<Scalar>& best = best_a_[n - 1];
  a_mu_.leftCols(n) = best.mu();
  a_ls_.leftCols(n) = best.log_sigma();
  result_.step = t_;
  result_.window_fill = n;
  result_.iterations = rep.iterations;
  result_.evaluations = rep.evaluations;
  result_.stopped_by_deadline = rep.stopped_by_deadline;
  result_.optimisation_s = std::chrono::duration<double>(SteadyClock::now() - t0).count();
  ++t_;
  GenerateIntention(t_);
  return result_;
}

template <typename Scalar>
const StepResult& ErrorRegression<Scalar>::NrlStep(const double* executed, SteadyClock::time_point deadline) {
  const auto t0 = SteadyClock::now();
  const NrlRegression::Outcome& o = nrl_->Step(executed, deadline);
  for (int k = 0; k < spec_.num_dofs(); ++k) intention_[k] = nrl_->intention()[k];
  fill_ = nrl_->window_fill();
  result_.step = t_++;
  result_.window_fill = fill_;
  result_.regressed = o.regressed;
  result_.loss.loss = o.loss;
  result_.loss.reconstruction = o.reconstruction;
  result_.loss.regulation = o.regulation;
  for (size_t k = 0; k < o.kl_per_layer.size(); ++k) result_.loss.kl_per_layer[k] = o.kl_per_layer[k];
  result_.initial_loss = 0;
  result_.iterations = o.iterations;
  result_.evaluations = o.iterations;  // one forward and backward pass each
  result_.stopped_by_deadline = o.stopped_by_deadline;
  result_.optimisation_s = std::chrono::duration<double>(SteadyClock::now() - t0).count();
  return result_;
}

template class ErrorRegression<float>;
template class ErrorRegression<double>;

}  // namespace dyad::pvrnn
