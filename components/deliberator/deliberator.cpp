#include "deliberator.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <sstream>

#include <dyad/join_list.hpp>

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

}  // namespace

void Deliberator::Describe(ComponentSpec& spec) {
  spec.Summary("The robot's PV-RNN mind: online error regression over a sliding window of executed "
               "positions, publishing the next intended position each step.");
  spec.RequiredParam("model", ParamType::kString).Path().Doc(".dpvrnn model file (2 DOF: x, y)");
  spec.Param("start_primitive", int64_t{0}).Min(0).Doc("primitive the robot starts drawing");
  spec.Param("preset", "vcbot").OneOf({"vcbot", "reference"})
      .Doc("vcbot: W 5, 15 it, Adam lr 0.3 b1 0.1 b2 0.95, w 1e-5; reference: W 15, 15 it, Adam lr 0.1; "
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
  spec.Output<msg::Intention>("intention").Doc("intended position r_t and the window's N-ELBO");
}

Status Deliberator::Configure(Context& ctx) {
  ctx_ = &ctx;
  const Params& p = ctx.params();
  const std::string& path = p.String("model");
  auto model = pvrnn::LoadModel(path);
  if (!model.ok()) return Status::InvalidArgument("params.model: " + model.status().message());
  if (model->spec.num_dofs() != 2)
    return Status::InvalidArgument("params.model: " + path + " has " + std::to_string(model->spec.num_dofs()) +
                                   " DOFs; the deliberator needs 2 (x, y)");
  ErrorRegressionOptions o = ErrorRegressionOptions::Preset(p.String("preset")).value();
  preset_iterations_ = o.iterations;
  preset_meta_prior_ = o.meta_prior;
  live_iterations_ = p.Int("iterations");
  live_meta_prior_ = p.DoubleList("meta_prior");
  const size_t layers = static_cast<size_t>(model->spec.num_layers());
  ctx.CheckLiveParam("meta_prior", [layers](const ParamValue& v) {
    const auto& w = std::get<std::vector<double>>(v);
    if (!w.empty() && w.size() != layers)
      return Status::InvalidArgument("needs " + std::to_string(layers) + " values (one per layer of the model, bottom first), got " +
                                     std::to_string(w.size()));
    return Status::OK();
  });
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
  if (auto problems = o.Problems(model->spec.num_layers()); !problems.empty())
    return Status::InvalidArgument("params." + problems.front().ToString());
  auto er = pvrnn::ErrorRegression<float>::Create(model.value(), o);
  if (!er.ok()) return Status::InvalidArgument("params." + er.status().message());
  er_ = std::move(er.value());
  const int64_t start = p.Int("start_primitive");
  const uint64_t seed = p.Int("seed") >= 0 ? static_cast<uint64_t>(p.Int("seed")) : ctx.seed();
  if (start >= model->sequences())
    return Status::InvalidArgument("params.start_primitive: " + std::to_string(start) + ": " + path + " has primitives 0.." +
                                   std::to_string(model->sequences() - 1));
  if (Status s = er_->Reset(static_cast<int>(start), seed); !s.ok()) return Status::InvalidArgument("params." + s.message());
  const double budget_ms = p.Double("time_budget_ms");
  budget_s_ = budget_ms > 0 ? budget_ms * 1e-3 : (ctx.period_ns() > 0 ? 0.2 * ctx.period_ns() * 1e-9 : 0.02);
  stepped_ = ctx.stepped();
  executed_ = &ctx.input<msg::CartesianState>("executed");
  intention_ = &ctx.output<msg::Intention>("intention");
  std::ostringstream info;
  info << "model " << path << ", start primitive " << start << ", window " << o.window << ", " << o.iterations
       << " iterations of " << pvrnn::ToString(o.optimizer);
  if (stepped_)
    info << ", no time cap (stepped clock: simulated time stands still during a step)";
  else
    info << ", budget " << budget_s_ * 1e3 << " ms";
  ctx.log().Info(info.str());
  return Status::OK();
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
