// A third-party component publishing its own message type (distance.idl): each counter value,
// scaled, as a lab::msg::Distance.
#include <dyad/component.hpp>
#include <dyad/msg/types.hpp>
#include <gauge/msg/types.hpp>

class Gauge : public dyad::Component {
 public:
  static void Describe(dyad::ComponentSpec& spec) {
    spec.Summary("Publishes scale times each input value as a Distance.");
    spec.Param("scale", 0.5).Doc("workspace units per count");
    spec.Param("near_below", 2.0).Min(0).Doc("a distance below this is near");
    spec.Input<dyad::msg::Counter>("in");
    spec.Output<lab::msg::Distance>("out");
  }
  dyad::Status Configure(dyad::Context& ctx) override {
    scale_ = ctx.params().Double("scale");
    near_below_ = ctx.params().Double("near_below");
    in_ = &ctx.input<dyad::msg::Counter>("in");
    out_ = &ctx.output<lab::msg::Distance>("out");
    return dyad::Status::OK();
  }
  dyad::Status Step(const dyad::StepInfo&) override {
    for (const auto& s : in_->received()) {
      lab::msg::Distance d;
      d.value(scale_ * static_cast<double>(s.value()));
      d.near(d.value() < near_below_);
      if (auto st = out_->Publish(d); !st.ok()) return st;
    }
    return dyad::Status::OK();
  }

 private:
  double scale_ = 0.5, near_below_ = 2.0;
  dyad::Input<dyad::msg::Counter>* in_ = nullptr;
  dyad::Output<lab::msg::Distance>* out_ = nullptr;
};

DYAD_PLUGIN(registry) { registry.Add<Gauge>("gauge"); }
