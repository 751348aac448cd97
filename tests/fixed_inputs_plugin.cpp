// A test plugin: `fixed_inputs` publishes the same engaged human position and robot intention
// every step, so that a compliance mixer's command is gain * human + (1 - gain) * robot and a
// live change of the gain shows at the step it takes effect (process_live_params_test.cpp).
// Kept out of the plugin folder.
#include <dyad/component.hpp>
#include <dyad/msg/types.hpp>

namespace {

class FixedInputs final : public dyad::Component {
 public:
  static void Describe(dyad::ComponentSpec& spec) {
    spec.Summary("test: a fixed engaged human position and robot intention every step");
    spec.Param("human_x", 10.0).Doc("the human's x");
    spec.Param("robot_x", 0.0).Doc("the robot's x");
    spec.Output<dyad::msg::HumanInput>("human");
    spec.Output<dyad::msg::Intention>("robot");
  }
  dyad::Status Configure(dyad::Context& ctx) override {
    human_.x(ctx.params().Double("human_x"));
    human_.engaged(true);
    robot_.x(ctx.params().Double("robot_x"));
    human_out_ = &ctx.output<dyad::msg::HumanInput>("human");
    robot_out_ = &ctx.output<dyad::msg::Intention>("robot");
    return dyad::Status::OK();
  }
  dyad::Status Step(const dyad::StepInfo&) override {
    if (dyad::Status s = human_out_->Publish(human_); !s.ok()) return s;
    return robot_out_->Publish(robot_);
  }

 private:
  dyad::msg::HumanInput human_;
  dyad::msg::Intention robot_;
  dyad::Output<dyad::msg::HumanInput>* human_out_ = nullptr;  // owned by the runtime
  dyad::Output<dyad::msg::Intention>* robot_out_ = nullptr;
};

}  // namespace

DYAD_PLUGIN(registry) { registry.Add<FixedInputs>("fixed_inputs"); }
