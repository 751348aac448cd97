#include "web_human.hpp"

#include <cmath>

namespace dyad::web {

void WebHuman::Describe(ComponentSpec& spec) {
  spec.Summary("The subject's pointer from the web page, sampled at the experiment's rate, as HumanInput.");
  spec.Param("engage_timeout_s", 0.3)
      .Min(1e-3)
      .Unit("s")
      .Doc(
          "an engaged pointer silent for longer counts as released (the page sends a sample at least every 50 ms "
          "while engaged)");
  spec.Input<msg::HumanInput>("pointer").Doc(
      "raw pointer samples from the web component (browser event rate); its pause marker (x = y = NaN): one released sample, "
      "then nothing until the page is back (the mixer holds)");
  spec.Output<msg::HumanInput>("input").Doc("the newest pointer at each step; engaged only while the subject holds");
}

Status WebHuman::Configure(Context& ctx) {
  timeout_ns_ = static_cast<int64_t>(std::llround(ctx.params().Double("engage_timeout_s") * 1e9));
  pointer_ = &ctx.input<msg::HumanInput>("pointer");
  out_ = &ctx.output<msg::HumanInput>("input");
  return Status::OK();
}

Status WebHuman::Step(const StepInfo& info) {
  const msg::HumanInput* p = pointer_->latest();
  // The web component's pause marker (pause_without_subject: no page steers): one release, then
  // nothing, so the mixer's human input goes stale and it holds the robot.
  if (p != nullptr && !(std::isfinite(p->x()) && std::isfinite(p->y()))) {
    if (paused_) return Status::OK();
    paused_ = true;
    sample_.engaged(false);
    return out_->Publish(sample_);
  }
  paused_ = false;
  if (p != nullptr) {
    sample_.x(p->x());
    sample_.y(p->y());
    const bool fresh = info.now_ns - pointer_->last_receive_ns() <= timeout_ns_;
    // The page sends nothing while released: a released sample stays valid however old.
    sample_.engaged(p->engaged() && fresh);
  }
  return out_->Publish(sample_);
}

}  // namespace dyad::web
