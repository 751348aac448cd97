/// The compliance mixer: blends the human's hand and the robot's intention into the command sent
/// to the Cartesian driver, limits how fast the command may change, and holds it when its inputs
/// go stale or the arm is lost. The math lives in MixerCore (mixer_core.hpp); this is its DDS shell.
///
/// @component compliance_mixer
/// trigger: robot (the demo: one command per intention), or rate_hz (periodic; same behaviour)
/// inputs:
///   human (HumanInput): the human's hand position and engaged flag
///   robot (Intention): the robot's intended position
///   state (CartesianState, optional): the measured position; needed by mode: pi. Bound, the
///     mixer moves only while the arm is known (its state fresh and not stopped): until the
///     arm's first state it sends hold commands (the driver stays where it is and reports it),
///     then moves at most max_step from there; when the arm is lost (its driver reports stopped,
///     or no state for 5 x state_period_s) it holds at its last command, and the first motion
///     after the outage moves at most max_step from the arm's measured position.
///     Unbound, the first command is the target itself (a warning at Configure says so)
/// outputs:
///   command (CartesianCommand): the command contract (docs/components.md): a position the arm
///     may go to. hold = true means "stay where you are" and carries the last motion command
///     (before any: the arm's last measured position, before that the placeholder (0, 0)),
///     never the target: while inputs are stale (or a position it needs is NaN or infinite),
///     while it waits for the arm's first state, and while the arm is lost
/// params:
///   gain (double, 0.9, [0, 1]): weight of the human while engaged
///   max_step (double, 5, >= 0, workspace units): max change of the command per step, vector
///     norm (0: no limit)
///   mode (string, blend | pi): plain blend, or a PI loop on the measured position
///   kp (double, 1, >= 0), ki (double, 0, >= 0, 1/s): PI gains (mode: pi)
///   integral_limit (double, 10, >= 0, workspace units * s): PI anti-windup clamp per axis
///   stale_timeout_s (double, 0.5, > 0, s): an input without a sample for longer is stale
///     (runtime clock)
///   state_period_s (double, 0.1, > 0, s): the driver's state period; 5 without a state: arm lost
///   z (double, 0, workspace units): z of every command (the study's robot is planar)
/// @endcomponent
///
/// Logs once when it starts holding (naming the stale input) and once when it resumes. An input
/// that has sent nothing yet is not reported during the first stale_timeout_s after the first
/// step (its writer may start after the mixer); after that it is, as "has sent nothing". Each
/// outage of the arm is logged when it begins ("arm lost (...)") and ends ("arm back after N s"),
/// and published on dyad/health (action "arm lost" / "arm back", topic: the state's). The
/// end-of-run summary counts them: "arm lost N times, S s; N holds sent while lost; N holds sent
/// waiting for the arm's first state" (a warning when the arm never reported at all).
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
  // Logs how many commands were published, held and saturated, and the arm's outages.
  Status Deactivate() override;

 private:
  Context* ctx_ = nullptr;
  Input<msg::HumanInput>* human_ = nullptr;     // owned by the runtime
  Input<msg::Intention>* robot_ = nullptr;      // owned by the runtime
  Input<msg::CartesianState>* state_ = nullptr; // owned by the runtime
  Output<msg::CartesianCommand>* command_ = nullptr;  // owned by the runtime
  // No state for this many state periods (param state_period_s): the arm is lost.
  static constexpr double kStatePeriodsBeforeLost = 5;

  void LogArm(const MixerCore::Result& r, int64_t now_ns);
  void ReportOutage(const char* action, int64_t lost_ns, int64_t now_ns);

  SerializedWriter* health_ = nullptr;  // dyad/health; null without one (a test's context); owned by the runtime
  msg::HealthEvent health_event_;
  std::optional<MixerCore> core_;
  double z_ = 0;
  msg::CartesianCommand out_;  // reused: no allocation per step
  bool holding_ = false;
  int64_t first_step_ns_ = -1;
  uint64_t published_ = 0, held_ = 0, saturated_ = 0, waiting_held_ = 0;
};

}  // namespace dyad::mixer
