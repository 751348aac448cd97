/// The `param_script` component: changes live parameters of the graph's components on a schedule.
///
/// @component param_script
/// rate_hz: required (a change is sent at the first step at or after its time).
/// outputs: requests (ParamChange): bind it to dyad/param_requests.
/// params:
///   changes (yaml, required): a list of {at_s: S, set: {COMPONENT.PARAM: VALUE, ...}}: at S
///            seconds after this component's first step (simulated time when stepped), ask for
///            each change, as `dyad param set` does. S >= 0; the list need not be sorted.
/// @endcomponent
///
/// Each change is answered by the process that runs its component (applied at that component's
/// next step, or refused with the reason) on dyad/params, which the recorder keeps. In a stepped
/// run the same script gives the same changes at the same steps. The components named must be in
/// the graph (checked at configure); whether their params exist and are live, and whether the
/// values are valid, is their process's answer (a refusal is logged there and recorded).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <dyad/component.hpp>
#include <dyad/msg/types.hpp>

namespace dyad::param_script {

class ParamScript final : public Component {
 public:
  static void Describe(ComponentSpec& spec);
  Status Configure(Context& ctx) override;
  Status Step(const StepInfo& info) override;

  struct Change {
    int64_t at_ns = 0;
    std::string component, param, value;  // value: YAML flow text
  };

 private:
  Context* ctx_ = nullptr;
  Output<msg::ParamChange>* out_ = nullptr;  // owned by the runtime
  std::vector<Change> changes_;              // by time (stable: the file's order within one time)
  size_t next_ = 0;
  int64_t first_ns_ = -1;
};

}  // namespace dyad::param_script
