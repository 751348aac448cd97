/// The `web_human` component: the subject's steering as the experiment's human input. It takes
/// the newest pointer sample from the subject's page (the `web` component's `pointer` output, at
/// the browser's event rate) at each of its own steps (the experiment's rate) and publishes it
/// as HumanInput: never at the browser's rate, always one sample per step (disengaged while no
/// page steers, so the mixer does not take the human for stale). The one exception is the web
/// component's pause (its pause_without_subject: the subject's page is gone during a trial), a
/// pointer sample with x = y = NaN: it publishes one released sample, then nothing until a page's
/// sample comes, so the mixer's human input goes stale and it holds the robot.
///
/// @component web_human
/// Summary: the subject's pointer, sampled at the experiment's rate, as HumanInput.
/// Inputs: pointer (HumanInput): raw pointer samples from `web` (x = y = NaN: paused)
/// Outputs: input (HumanInput): one sample per step
/// Params:
///   engage_timeout_s (double, 0.3, > 0, s): an engaged pointer silent for longer counts as
///     released (the page sends a keepalive every 50 ms while engaged)
/// @endcomponent
#pragma once

#include <dyad/component.hpp>
#include <dyad/msg/types.hpp>

namespace dyad::web {

class WebHuman final : public Component {
 public:
  static void Describe(ComponentSpec& spec);
  Status Configure(Context& ctx) override;
  Status Step(const StepInfo& info) override;

 private:
  Input<msg::HumanInput>* pointer_ = nullptr;  // owned by the runtime
  Output<msg::HumanInput>* out_ = nullptr;     // owned by the runtime
  int64_t timeout_ns_ = 0;
  bool paused_ = false;  // the pause marker came and its release was published
  msg::HumanInput sample_;
};

}  // namespace dyad::web
