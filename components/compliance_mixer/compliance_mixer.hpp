/// The compliance mixer: blends the human's hand and the robot's intention into the command sent
/// to the Cartesian driver, limits how fast the command may change, and holds it when its inputs
/// go stale. The math lives in MixerCore (mixer_core.hpp); this is its DDS shell.
///
/// @component compliance_mixer
/// trigger: robot (the demo: one command per intention), or rate_hz (periodic; same behaviour)
/// inputs:
///   human (HumanInput): the human's hand position and engaged flag
///   robot (Intention): the robot's intended position
///   state (CartesianState, optional): the measured position; needed by mode: pi. Bound, the
///     first command waits for it: until the arm's state arrives the mixer sends hold commands
///     (the driver stays where it is and reports it), then moves at most max_step from there.
///     Unbound, the first command is the target itself (a warning at Configure says so)
/// outputs:
///   command (CartesianCommand): target position; hold = true while inputs are stale (or a
///     position it needs is NaN or infinite) or while it waits for the arm's first state: the
///     driver keeps its target (x, y repeat the last command, or the intended start)
/// params:
///   gain (double, 0.9, [0, 1]): weight of the human while engaged
///   max_step (double, 5, >= 0, workspace units): max change of the command per step, vector
///     norm (0: no limit)
///   mode (string, blend | pi): plain blend, or a PI loop on the measured position
///   kp (double, 1, >= 0), ki (double, 0, >= 0, 1/s): PI gains (mode: pi)
///   integral_limit (double, 10, >= 0, workspace units * s): PI anti-windup clamp per axis
///   stale_timeout_s (double, 0.5, > 0, s): an input without a sample for longer is stale
///     (runtime clock)
///   z (double, 0, workspace units): z of every command (the study's robot is planar)
/// @endcomponent
///
/// Logs once when it starts holding (naming the stale input) and once when it resumes. An input
/// that has sent nothing yet is not reported during the first stale_timeout_s after the first
/// step (its writer may start after the mixer); after that it is, as "has sent nothing".
#pragma once

#include <dyad/component.hpp>
#include <dyad/msg/types.hpp>

#include "mixer_core.hpp"

namespace dyad::mixer {

class ComplianceMixer final : public Component {
 public:
  static void Describe(ComponentSpec& spec);
  // Reads and validates params, looks up ports; leaves the component inactive.
  Status Configure(Context& ctx) override;
  // Publishes at most one command per step.
  Status Step(const StepInfo& info) override;
  // Logs how many commands were published, held and saturated.
  Status Deactivate() override;

 private:
  Context* ctx_ = nullptr;
  Input<msg::HumanInput>* human_ = nullptr;     // owned by the runtime
  Input<msg::Intention>* robot_ = nullptr;      // owned by the runtime
  Input<msg::CartesianState>* state_ = nullptr; // owned by the runtime
  Output<msg::CartesianCommand>* command_ = nullptr;  // owned by the runtime
  std::optional<MixerCore> core_;
  double z_ = 0;
  msg::CartesianCommand out_;  // reused: no allocation per step
  bool holding_ = false;
  int64_t first_step_ns_ = -1;
  uint64_t published_ = 0, held_ = 0, saturated_ = 0;
};

}  // namespace dyad::mixer
