// Test-only component for the ROS 2 driver tests (loaded with `dyad run --plugins`):
//   test_hold_then_move  CartesianCommand: `hold_steps` holds at `hold_at` (the far intention a
//                        mixer may carry in its holds), then motion commands at `move_to`
#include <dyad/component.hpp>
#include <dyad/msg/types.hpp>

namespace {

using namespace dyad;

class HoldThenMove final : public Component {
 public:
  static void Describe(ComponentSpec& spec) {
    spec.Summary("test: holds at a far position for hold_steps steps, then motion commands at move_to");
    spec.Param("hold_at", std::vector<double>{1000, 0});
    spec.Param("hold_steps", int64_t{20});
    spec.Param("move_to", std::vector<double>{0, 0});
    spec.Output<msg::CartesianCommand>("command");
  }
  Status Configure(Context& ctx) override {
    const auto& p = ctx.params();
    if (p.DoubleList("hold_at").size() != 2 || p.DoubleList("move_to").size() != 2)
      return Status::InvalidArgument("hold_at, move_to: must be [x, y]");
    hold_ = {p.DoubleList("hold_at")[0], p.DoubleList("hold_at")[1]};
    move_ = {p.DoubleList("move_to")[0], p.DoubleList("move_to")[1]};
    hold_steps_ = p.Int("hold_steps");
    out_ = &ctx.output<msg::CartesianCommand>("command");
    return Status::OK();
  }
  Status Step(const StepInfo& info) override {
    const bool hold = static_cast<int64_t>(info.index) < hold_steps_;
    msg::CartesianCommand c;
    c.x(hold ? hold_[0] : move_[0]);
    c.y(hold ? hold_[1] : move_[1]);
    c.hold(hold);
    return out_->Publish(c);
  }

 private:
  std::array<double, 2> hold_{}, move_{};
  int64_t hold_steps_ = 0;
  Output<msg::CartesianCommand>* out_ = nullptr;
};

}  // namespace

DYAD_PLUGIN(registry) { registry.Add<HoldThenMove>("test_hold_then_move"); }
