// Test-only component for the web component's browser test: a robot "mind" that intends to stay
// at one point, so the loop human page -> web_human -> mixer -> virtual robot runs without a
// trained PV-RNN. Kept out of the plugin folder; the test graph names it under `plugins:`.
#include <dyad/component.hpp>
#include <dyad/msg/types.hpp>

namespace {

class IntentionHold final : public dyad::Component {
 public:
  static void Describe(dyad::ComponentSpec& spec) {
    spec.Summary("Test: intends one fixed position every step.");
    spec.Param("position", std::vector<double>{0, 0});
    spec.Output<dyad::msg::Intention>("intention");
  }
  dyad::Status Configure(dyad::Context& ctx) override {
    const auto p = ctx.params().DoubleList("position");
    if (p.size() != 2) return dyad::Status::InvalidArgument("params.position: needs [x, y]");
    sample_.x(p[0]);
    sample_.y(p[1]);
    out_ = &ctx.output<dyad::msg::Intention>("intention");
    return dyad::Status::OK();
  }
  dyad::Status Step(const dyad::StepInfo&) override { return out_->Publish(sample_); }

 private:
  dyad::msg::Intention sample_;
  dyad::Output<dyad::msg::Intention>* out_ = nullptr;
};

}  // namespace

DYAD_PLUGIN(registry) { registry.Add<IntentionHold>("intention_hold"); }
