// A third-party component: republishes each counter multiplied by `factor`.
#include <dyad/component.hpp>
#include <dyad/msg/types.hpp>

class Doubler : public dyad::Component {
 public:
  static void Describe(dyad::ComponentSpec& spec) {
    spec.Summary("Publishes factor times the input value.");
    spec.Param("factor", int64_t{2}).Doc("multiplier");
    spec.Input<dyad::msg::Counter>("in");
    spec.Output<dyad::msg::Counter>("out");
  }
  dyad::Status Configure(dyad::Context& ctx) override {
    factor_ = ctx.params().Int("factor");
    in_ = &ctx.input<dyad::msg::Counter>("in");
    out_ = &ctx.output<dyad::msg::Counter>("out");
    return dyad::Status::OK();
  }
  dyad::Status Step(const dyad::StepInfo&) override {
    for (const auto& s : in_->received()) {
      dyad::msg::Counter c;
      c.value(factor_ * s.value());
      if (auto st = out_->Publish(c); !st.ok()) return st;
    }
    return dyad::Status::OK();
  }

 private:
  int64_t factor_ = 2;
  dyad::Input<dyad::msg::Counter>* in_ = nullptr;
  dyad::Output<dyad::msg::Counter>* out_ = nullptr;
};

DYAD_PLUGIN(registry) { registry.Add<Doubler>("doubler"); }
