// A third-party component publishing a ROS 2 type it brings (geometry_msgs/msg/WrenchStamped):
// each counter value as a force along x, in frame `frame_id`.
#include <dyad/component.hpp>
#include <dyad/msg/types.hpp>
#include <force_sensor/msg/types.hpp>

using geometry_msgs::msg::dds_::WrenchStamped_;

class ForceSensor : public dyad::Component {
 public:
  static void Describe(dyad::ComponentSpec& spec) {
    spec.Summary("Publishes each input value, scaled, as the force of a WrenchStamped.");
    spec.Param("newtons_per_count", 0.5).Doc("force per count");
    spec.Param("frame_id", "tool0").Doc("header.frame_id");
    spec.Input<dyad::msg::Counter>("in");
    spec.Output<WrenchStamped_>("out");
  }
  dyad::Status Configure(dyad::Context& ctx) override {
    scale_ = ctx.params().Double("newtons_per_count");
    frame_ = ctx.params().String("frame_id");
    in_ = &ctx.input<dyad::msg::Counter>("in");
    out_ = &ctx.output<WrenchStamped_>("out");
    return dyad::Status::OK();
  }
  dyad::Status Step(const dyad::StepInfo& info) override {
    for (const auto& s : in_->received()) {
      WrenchStamped_ w;  // a ROS 2 type: its header is ours to fill
      w.header().stamp().sec(static_cast<int32_t>(info.now_ns / 1'000'000'000));
      w.header().stamp().nanosec(static_cast<uint32_t>(info.now_ns % 1'000'000'000));
      w.header().frame_id(frame_);
      w.wrench().force().x(scale_ * static_cast<double>(s.value()));
      if (auto st = out_->Publish(w); !st.ok()) return st;
    }
    return dyad::Status::OK();
  }

 private:
  double scale_ = 0.5;
  std::string frame_;
  dyad::Input<dyad::msg::Counter>* in_ = nullptr;
  dyad::Output<WrenchStamped_>* out_ = nullptr;
};

DYAD_PLUGIN(registry) { registry.Add<ForceSensor>("force_sensor"); }
