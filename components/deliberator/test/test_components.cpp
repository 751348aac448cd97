// Test-only components for the deliberator's graph test:
// - `executed_script`: publishes CartesianState on a circle of radius `radius` (x = r cos, y = r
//   sin, one revolution per `period_steps` steps), standing in for a driver;
// - `intention_file`: writes one line per received Intention: x y nelbo iterations missed.
#include <cmath>
#include <cstdio>

#include <dyad/component.hpp>
#include <dyad/msg/types.hpp>

namespace {

class ExecutedScript final : public dyad::Component {
 public:
  static void Describe(dyad::ComponentSpec& spec) {
    spec.Summary("test: CartesianState on a circle");
    spec.Param("radius", 20.0).Doc("circle radius");
    spec.Param("period_steps", 72.0).Doc("steps per revolution");
    spec.Output<dyad::msg::CartesianState>("state");
  }
  dyad::Status Configure(dyad::Context& ctx) override {
    radius_ = ctx.params().Double("radius");
    period_ = ctx.params().Double("period_steps");
    out_ = &ctx.output<dyad::msg::CartesianState>("state");
    return dyad::Status::OK();
  }
  dyad::Status Step(const dyad::StepInfo& info) override {
    dyad::msg::CartesianState s;
    const double a = 2 * M_PI * static_cast<double>(info.index) / period_;
    s.x(radius_ * std::cos(a));
    s.y(radius_ * std::sin(a));
    return out_->Publish(s);
  }

 private:
  double radius_ = 20, period_ = 72;
  dyad::Output<dyad::msg::CartesianState>* out_ = nullptr;  // owned by the runtime
};

class IntentionFile final : public dyad::Component {
 public:
  static void Describe(dyad::ComponentSpec& spec) {
    spec.Summary("test: writes intentions to a file");
    spec.RequiredParam("file", dyad::ParamType::kString).Doc("output file");
    spec.Input<dyad::msg::Intention>("in");
  }
  dyad::Status Configure(dyad::Context& ctx) override {
    path_ = ctx.params().String("file");
    in_ = &ctx.input<dyad::msg::Intention>("in");
    return dyad::Status::OK();
  }
  dyad::Status Activate() override {
    f_ = std::fopen(path_.c_str(), "w");
    return f_ ? dyad::Status::OK() : dyad::Status::IOError(path_ + ": cannot open");
  }
  dyad::Status Step(const dyad::StepInfo&) override {
    for (const auto& i : in_->received())
      std::fprintf(f_, "%.9g %.9g %.9g %u %d\n", i.x(), i.y(), i.nelbo(), static_cast<unsigned>(i.iterations()),
                   i.deadline_missed() ? 1 : 0);
    return dyad::Status::OK();
  }
  dyad::Status Deactivate() override {
    if (f_) std::fclose(f_);
    f_ = nullptr;
    return dyad::Status::OK();
  }

 private:
  std::string path_;
  std::FILE* f_ = nullptr;
  dyad::Input<dyad::msg::Intention>* in_ = nullptr;  // owned by the runtime
};

}  // namespace

DYAD_PLUGIN(registry) {
  registry.Add<ExecutedScript>("executed_script");
  registry.Add<IntentionFile>("intention_file");
}
