#include "deliberator.hpp"

#include <yaml-cpp/yaml.h>

#include <openssl/evp.h>

#include <chrono>
#include <cmath>
#include <sstream>

#include <dyad/join_list.hpp>

#include "dyad/pvrnn/checked_file.hpp"
#include "dyad/pvrnn/model_file.hpp"

namespace dyad::deliberator {
namespace {

using pvrnn::ErrorRegressionOptions;

// Applies the keys of a YAML map param to `fields` (name -> target); unknown keys, non-maps
// and non-numbers are errors naming "params.<param>.<key>".
template <typename T>
Status ApplyMap(const std::string& param, const std::string& yaml_text,
                const std::vector<std::pair<const char*, T*>>& fields) {
  YAML::Node node;
  try {
    node = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    return Status::InvalidArgument("params." + param + ": not YAML: " + e.what());
  }
  if (node.IsNull()) return Status::OK();
  if (!node.IsMap()) return Status::InvalidArgument("params." + param + ": must be a map, e.g. {lr: 0.3}");
  for (const auto& kv : node) {
    const std::string key = kv.first.as<std::string>();
    bool found = false;
    for (const auto& [name, target] : fields) {
      if (key != name) continue;
      found = true;
      try {
        *target = kv.second.as<T>();
      } catch (const YAML::Exception&) {
        return Status::InvalidArgument("params." + param + "." + key + ": must be a number, got '" +
                                       YAML::Dump(kv.second) + "'");
      }
    }
    if (!found) {
      const std::string known = JoinList(fields, [](const auto& f) -> const auto& { return f.first; });
      return Status::InvalidArgument("params." + param + "." + key + ": unknown key (known: " + known + ")");
    }
  }
  return Status::OK();
}

// The SHA-256 of a file's bytes in hex, as sha256sum prints it.
StatusOr<std::string> FileSha256(const std::string& path) {
  StatusOr<std::string> bytes = pvrnn::ReadWholeFile(path, "model file");
  if (!bytes.ok()) return bytes.status();
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  if (EVP_Digest(bytes->data(), bytes->size(), digest, &length, EVP_sha256(), nullptr) != 1)
    return Status::Internal("SHA-256 of " + path + " failed");
  static const char kHex[] = "0123456789abcdef";
  std::string hex;
  for (unsigned int i = 0; i < length; ++i) hex += {kHex[digest[i] >> 4], kHex[digest[i] & 15]};
  return hex;
}

// A model file loaded for the deliberator: 2 DOFs. Errors start with the path.
StatusOr<pvrnn::Model> LoadTwoDofModel(const std::string& path) {
  auto model = pvrnn::LoadModel(path);
  if (!model.ok()) return model.status();
  if (model->spec.num_dofs() != 2)
    return Status::InvalidArgument(path + " has " + std::to_string(model->spec.num_dofs()) + " DOFs; the deliberator needs 2 (x, y)");
  return model;
}

// The error regression's options: the preset's, overridden by the params (window, iterations,
// optimizer, adam, ceres, meta_prior, a_init, noise, a_steps) and checked for a model of
// `layers` layers. Errors name "params.<param>".
StatusOr<ErrorRegressionOptions> RegressionOptions(const Params& p, int layers) {
  ErrorRegressionOptions o = ErrorRegressionOptions::Preset(p.String("preset")).value();
  if (p.Int("window") > 0) o.window = static_cast<int>(p.Int("window"));
  if (p.Int("iterations") > 0) o.iterations = static_cast<int>(p.Int("iterations"));
  o.optimizer = pvrnn::ParseOptimizerKind(p.String("optimizer")).value();
  if (Status s = ApplyMap<double>("adam", p.String("adam"),
                                  {{"lr", &o.adam.lr}, {"beta1", &o.adam.beta1}, {"beta2", &o.adam.beta2},
                                   {"epsilon", &o.adam.epsilon}});
      !s.ok())
    return s;
  double rank = o.ceres.lbfgs_rank, ls = o.ceres.max_line_search_iterations;
  if (Status s = ApplyMap<double>("ceres", p.String("ceres"),
                                  {{"lbfgs_rank", &rank},
                                   {"function_tolerance", &o.ceres.function_tolerance},
                                   {"gradient_tolerance", &o.ceres.gradient_tolerance},
                                   {"parameter_tolerance", &o.ceres.parameter_tolerance},
                                   {"max_line_search_iterations", &ls}});
      !s.ok())
    return s;
  // Integer options: a fraction or a value beyond int is an error, not a silent truncation.
  for (const auto& [key, value] : {std::pair<const char*, double>{"lbfgs_rank", rank}, {"max_line_search_iterations", ls}}) {
    if (value != std::floor(value) || std::abs(value) > 1e9)  // ranges: ErrorRegressionOptions::Problems
      return Status::InvalidArgument(std::string("params.ceres.") + key + ": must be a whole number, got " +
                                     std::to_string(value));
  }
  o.ceres.lbfgs_rank = static_cast<int>(rank);
  o.ceres.max_line_search_iterations = static_cast<int>(ls);
  if (!p.DoubleList("meta_prior").empty()) o.meta_prior = p.DoubleList("meta_prior");
  o.a_init = pvrnn::ParseAInit(p.String("a_init")).value();
  o.noise = pvrnn::ParseNoiseMode(p.String("noise")).value();
  o.a_steps = static_cast<int>(p.Int("a_steps"));
  if (auto problems = o.Problems(layers); !problems.empty())
    return Status::InvalidArgument("params." + problems.front().ToString());
  return o;
}

}  // namespace

void Deliberator::Describe(ComponentSpec& spec) {
  spec.Summary("The robot's PV-RNN mind: online error regression over a sliding window of executed "
               "positions, publishing the next intended position each step.");
  spec.RequiredParam("model", ParamType::kString).Path().Live()
      .Doc(".dpvrnn model file (2 DOF: x, y); set live, swapped in at a step boundary once loaded and checked");
  spec.Param("start_primitive", int64_t{0}).Min(0).Doc("primitive the robot starts drawing");
  spec.Param("preset", "vcbot")
      .OneOf({"vcbot", "reference", "nrl"})
      .Doc(
          "vcbot: W 5, 15 it, Adam lr 0.3 b1 0.1 b2 0.95, w 1e-5; reference: W 15, 15 it, Adam lr 0.1; "
          "nrl: NRL's own error regression step by step with the vcbot numbers and Adam epsilon 1e-20 "
          "(reproduces results published with NRL; a_init and ceres unused, noise off or resample); "
          "the params below override it");
  spec.Param("window", int64_t{0}).Range(0, 1000).Unit("steps").Doc("sliding window W (0: the preset's)");
  spec.Param("iterations", int64_t{0}).Range(0, 100000).Live().Doc("optimiser iterations per step (0: the preset's)");
  spec.Param("optimizer", "adam").OneOf({"adam", "ceres"}).Doc("adam or ceres (LBFGS, Wolfe line search)");
  spec.YamlParam("adam", "{}").Doc("Adam settings overriding the preset: lr, beta1, beta2, epsilon");
  spec.YamlParam("ceres", "{}").Doc("Ceres settings: lbfgs_rank, function_tolerance, gradient_tolerance, "
                                     "parameter_tolerance, max_line_search_iterations");
  spec.Param("meta_prior", std::vector<double>{}).Min(0).Live().Doc("online meta-prior w per layer, bottom first ([]: the preset's)");
  spec.Param("a_init", "prior").OneOf({"zero", "copy", "prior"}).Doc("A of the newest window step");
  spec.Param("noise", "off").OneOf({"off", "fixed", "resample"}).Doc("eps of the window: off (means), fixed per step, resampled each step");
  spec.Param("a_steps", int64_t{3}).Range(0, 1000).Unit("steps").Doc("first steps on the start primitive's trained A");
  spec.Param("time_budget_ms", 0.0).Min(0).Unit("ms")
      .Doc("wall clock: optimisation cap per step (0: 20% of the period, 20 ms when triggered); stepped: none");
  spec.Param("seed", int64_t{-1}).Min(-1).Doc("noise seed (-1: the graph's seed for this instance)");
  spec.Input<msg::CartesianState>("executed").Optional().Doc("executed robot position s_{t-1}");
  spec.Output<msg::ModelInfo>("model").Optional().Doc("the model in force: at step 0 and at every swap (path, SHA-256, first step)");
  spec.Output<msg::Intention>("intention").Doc("intended position r_t and the window's N-ELBO");
}

Status Deliberator::Configure(Context& ctx) {
  ctx_ = &ctx;
  const Params& p = ctx.params();
  model_path_ = p.String("model");
  auto model = LoadTwoDofModel(model_path_);
  if (!model.ok()) return Status::InvalidArgument("params.model: " + model.status().message());
  const ErrorRegressionOptions preset = ErrorRegressionOptions::Preset(p.String("preset")).value();
  preset_iterations_ = preset.iterations;
  preset_meta_prior_ = preset.meta_prior;
  live_iterations_ = p.Int("iterations");
  live_meta_prior_ = p.DoubleList("meta_prior");
  layers_ = model->spec.num_layers();
  ctx.CheckLiveParam("meta_prior", [this](const ParamValue& v) {  // on the step thread: layers_ is the model's in force
    const auto& w = std::get<std::vector<double>>(v);
    if (!w.empty() && w.size() != static_cast<size_t>(layers_))
      return Status::InvalidArgument("needs " + std::to_string(layers_) + " values (one per layer of the model, bottom first), got " +
                                     std::to_string(w.size()));
    return Status::OK();
  });
  ctx.PrepareLiveParam(
      "model", [this](const ParamValue& v) { return PrepareModel(std::get<std::string>(v)); },
      [this](const ParamValue&) {
        if (Status s = SwapModel(); !s.ok()) ctx_->log().Error("model swap: " + s.message());
      });
  auto options = RegressionOptions(p, layers_);
  if (!options.ok()) return options.status();
  const ErrorRegressionOptions& o = *options;
  options_ = o;
  start_primitive_ = static_cast<int>(p.Int("start_primitive"));
  seed_ = p.Int("seed") >= 0 ? static_cast<uint64_t>(p.Int("seed")) : ctx.seed();
  if (start_primitive_ >= model->sequences())
    return Status::InvalidArgument("params.start_primitive: " + std::to_string(start_primitive_) + ": " + model_path_ +
                                   " has primitives 0.." + std::to_string(model->sequences() - 1));
  auto er = pvrnn::ErrorRegression<float>::Create(model.value(), o);
  if (!er.ok()) return Status::InvalidArgument("params." + er.status().message());
  er_ = std::move(er.value());
  if (Status s = er_->Reset(start_primitive_, seed_); !s.ok()) return Status::InvalidArgument("params." + s.message());
  history_.assign(static_cast<size_t>(o.window), {0.0, 0.0});
  auto hash = FileSha256(model_path_);
  if (!hash.ok()) return Status::InvalidArgument("params.model: " + hash.status().message());
  first_info_.path(model_path_);
  first_info_.sha256(*hash);
  first_info_.primitives(static_cast<uint32_t>(model->sequences()));
  first_info_.layers(static_cast<uint32_t>(layers_));
  first_info_.step(0);
  first_info_.prepare_s(0);
  const double budget_ms = p.Double("time_budget_ms");
  budget_s_ = budget_ms > 0 ? budget_ms * 1e-3 : (ctx.period_ns() > 0 ? 0.2 * ctx.period_ns() * 1e-9 : 0.02);
  stepped_ = ctx.stepped();
  executed_ = &ctx.input<msg::CartesianState>("executed");
  intention_ = &ctx.output<msg::Intention>("intention");
  model_info_ = &ctx.output<msg::ModelInfo>("model");
  std::ostringstream info;
  // The preset names the engine too (nrl: NRL's own regression), so a run's log says which ran.
  info << "model " << model_path_ << " (sha256 " << hash->substr(0, 12) << "), start primitive " << start_primitive_
       << ", preset " << p.String("preset") << ", window " << o.window << ", " << o.iterations << " iterations of "
       << pvrnn::ToString(o.optimizer);
  if (stepped_)
    info << ", no time cap (stepped clock: simulated time stands still during a step)";
  else
    info << ", budget " << budget_s_ * 1e3 << " ms";
  ctx.log().Info(info.str());
  return Status::OK();
}

// Off the step thread (LiveParams' preparer; at the boundary when stepped). The live params are
// stable meanwhile: the runtime holds this component's other changes until this returns.
Status Deliberator::PrepareModel(const std::string& path) {
  const auto start = std::chrono::steady_clock::now();
  auto model = LoadTwoDofModel(path);
  if (!model.ok()) return model.status();
  if (start_primitive_ >= model->sequences())
    return Status::InvalidArgument(path + " has primitives 0.." + std::to_string(model->sequences() - 1) +
                                   "; the run started on primitive " + std::to_string(start_primitive_));
  auto hash = FileSha256(path);
  if (!hash.ok()) return hash.status();
  ErrorRegressionOptions o = options_;  // as configured; then the live params in force
  o.meta_prior.clear();  // the model's own w unless given: checked against its layers below
  auto er = pvrnn::ErrorRegression<float>::Create(model.value(), o);
  if (!er.ok()) return er.status();
  const Params& p = ctx_->params();
  const int iterations = p.Int("iterations") > 0 ? static_cast<int>(p.Int("iterations")) : preset_iterations_;
  const std::vector<double>& meta_prior = p.DoubleList("meta_prior").empty() ? preset_meta_prior_ : p.DoubleList("meta_prior");
  if (!meta_prior.empty() && meta_prior.size() != static_cast<size_t>(model->spec.num_layers()))
    return Status::InvalidArgument(path + " has " + std::to_string(model->spec.num_layers()) + " layers; the meta_prior in force has " +
                                   std::to_string(meta_prior.size()) + " values (" +
                                   (p.DoubleList("meta_prior").empty() ? "the preset's" : "as set") +
                                   "): a model with another number of layers needs a restart");
  if (Status s = (*er)->Retune(iterations, meta_prior); !s.ok()) return s;
  if (Status s = (*er)->Reset(start_primitive_, seed_); !s.ok()) return s;
  // Warm it on the executed positions in the window: it starts where the robot is.
  std::vector<std::array<double, 2>> window;
  uint64_t fed = 0;
  {
    std::lock_guard<std::mutex> lock(swap_mutex_);
    fed = history_fed_;
    for (uint64_t k = fed > history_.size() ? fed - history_.size() : 0; k < fed; ++k) window.push_back(history_[k % history_.size()]);
  }
  for (const auto& xy : window) (*er)->Step(xy.data(), pvrnn::SteadyClock::time_point::max());
  Prepared prepared;
  prepared.er = std::move(er.value());
  prepared.fed = fed;
  prepared.info.path(path);
  prepared.info.sha256(*hash);
  prepared.info.primitives(static_cast<uint32_t>(model->sequences()));
  prepared.info.layers(static_cast<uint32_t>(model->spec.num_layers()));
  // Wall time, so none under the stepped clock: its recordings are the same in every run.
  prepared.info.prepare_s(stepped_ ? 0.0 : std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  std::lock_guard<std::mutex> lock(swap_mutex_);
  prepared_ = std::move(prepared);
  return Status::OK();
}

// The commit of a new `model`: at the step boundary where the runtime applied it, on the step
// thread, before Step(). The prepared regression takes over; the positions executed since it was
// warmed get one evaluation each (cheap: the step's own solve comes after), so its window
// matches the old one's.
Status Deliberator::SwapModel() {
  Prepared p;
  {
    std::lock_guard<std::mutex> lock(swap_mutex_);
    p = std::move(prepared_);
    prepared_ = Prepared{};
  }
  if (!p.er) return Status::Internal("model " + ctx_->params().String("model") + " applied without its preparation");
  const uint64_t from = std::max(p.fed, history_fed_ > history_.size() ? history_fed_ - history_.size() : 0);
  for (uint64_t k = from; k < history_fed_; ++k) p.er->Step(history_[k % history_.size()].data(), pvrnn::SteadyClock::now());
  er_ = std::move(p.er);
  layers_ = static_cast<int>(p.info.layers());
  std::ostringstream info;
  info << "step " << steps_ << ": model " << model_path_ << " -> " << p.info.path() << " (sha256 " << p.info.sha256().substr(0, 12);
  if (!stepped_) info << ", prepared in " << p.info.prepare_s() * 1e3 << " ms off the step thread";
  ctx_->log().Info(info.str() + ")");
  model_path_ = p.info.path();
  p.info.step(steps_);
  model_published_ = true;  // at step 0: the configured model never steered
  return model_info_->Publish(p.info);
}

// The live params (iterations, meta_prior) as they are now: the regression retuned when changed.
Status Deliberator::FollowLiveParams() {
  const Params& p = ctx_->params();
  if (p.Int("iterations") == live_iterations_ && p.DoubleList("meta_prior") == live_meta_prior_) return Status::OK();
  live_iterations_ = p.Int("iterations");
  live_meta_prior_ = p.DoubleList("meta_prior");
  Status s = er_->Retune(live_iterations_ > 0 ? static_cast<int>(live_iterations_) : preset_iterations_,
                         live_meta_prior_.empty() ? preset_meta_prior_ : live_meta_prior_);
  return s.ok() ? s : Status::InvalidArgument("live params: " + s.message());  // checked before applied: not expected
}

Status Deliberator::Step(const StepInfo&) {
  if (Status s = FollowLiveParams(); !s.ok()) return s;
  // Under the stepped clock the step takes no simulated time however long it runs: a wall-time
  // cap would only make the result depend on the machine's load, so the iteration cap alone
  // applies and a stepped run stays deterministic.
  const auto deadline = stepped_ ? pvrnn::SteadyClock::time_point::max()
                                 : pvrnn::SteadyClock::now() + std::chrono::duration_cast<pvrnn::SteadyClock::duration>(
                                                                   std::chrono::duration<double>(budget_s_));
  double optimisation_s = 0;
  bool missed = false;
  const pvrnn::StepResult* r = nullptr;
  if (!model_published_) {
    model_published_ = true;
    if (Status s = model_info_->Publish(first_info_); !s.ok()) return s;
  }
  if (steps_ > 0) {  // step 0 publishes r_0: nothing executed yet
    double xy[2];
    const msg::CartesianState* s = executed_->received().empty() ? nullptr : &executed_->received().back();
    if (s != nullptr && std::isfinite(s->x()) && std::isfinite(s->y())) {
      xy[0] = s->x();
      xy[1] = s->y();
    } else {  // none, or a bad reading: the robot's own last intention
      xy[0] = er_->intention()[0];
      xy[1] = er_->intention()[1];
      ++without_executed_;
    }
    r = &er_->Step(xy, deadline);
    {
      std::lock_guard<std::mutex> lock(swap_mutex_);  // uncontended but while a model is prepared
      history_[history_fed_++ % history_.size()] = {xy[0], xy[1]};
    }
    optimisation_s = r->optimisation_s;
    missed = !stepped_ && (r->stopped_by_deadline || optimisation_s > budget_s_);
    if (missed && (deadline_misses_++ % 100) == 0) {
      std::ostringstream w;
      w << "step " << steps_ << ": optimisation stopped at its time cap (" << budget_s_ * 1e3 << " ms) after "
        << r->iterations << " iterations; published the best iterate (" << deadline_misses_ << " so far)";
      ctx_->log().Warn(w.str());
    }
  }
  ++steps_;
  out_.x(er_->intention()[0]);
  out_.y(er_->intention()[1]);
  out_.nelbo(r ? r->loss.loss : 0.0);
  out_.reconstruction(r ? r->loss.reconstruction : 0.0);
  out_.regulation(r ? r->loss.regulation : 0.0);
  out_.optimisation_s(optimisation_s);
  out_.iterations(r ? static_cast<uint32_t>(r->iterations) : 0u);
  out_.deadline_missed(missed);
  return intention_->Publish(out_);
}

Status Deliberator::Deactivate() {
  std::ostringstream s;
  s << steps_ << " steps, " << deadline_misses_ << " deadline misses, " << without_executed_
    << " steps without an executed position";
  ctx_->log().Info(s.str());
  return Status::OK();
}

}  // namespace dyad::deliberator

DYAD_PLUGIN(registry) { registry.Add<dyad::deliberator::Deliberator>("deliberator"); }
