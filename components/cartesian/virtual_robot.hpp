/// VirtualRobot: a 2-DOF prismatic (x, y) robot simulated in discrete steps, free of DDS and
/// clocks (times are passed in). The `virtual_cartesian` component and `dyad_fake_controller`
/// both run it, so the two drivers move the same robot the same way.
///
/// Each Advance(now) moves the robot over dt = now - previous Advance (capped at the watchdog
/// timeout) towards the latest target:
///   target clamped to the workspace box;  d = target - p
///   v_des = d/dt, shortened (vector norm) to min(max_velocity, braking bound), the braking
///           bound being the speed from which steps of max_acceleration*dt less speed each stop
///           within |d|: a*dt*(sqrt(1/4 + 2|d|/(a*dt^2)) - 1/2) (exact for whole multiples of a*dt)
///   v    += (v_des - v), shortened (norm) to max_acceleration*dt
///   p    += v*dt, clamped to the workspace (the velocity component into a wall is zeroed)
/// Limits are on the vector norm, not per axis: a diagonal move is as fast as an axis-aligned
/// one and the path keeps its direction. `v` is the mean velocity over the step.
/// Watchdog: when no command arrived for longer than `watchdog_ns` (or none ever), the robot
/// brakes at max_acceleration to rest and reports stopped = true; a fresh command clears it.
/// Without an initial position, the robot starts (at rest) at its first target, or, if a hold
/// comes first, at the centre of its workspace box: a hold never places or moves it anywhere
/// (the command contract, docs/components.md), whatever position the hold carries.
///
///   VirtualRobot robot(options);               // options.Validate() must be OK
///   robot.SetTarget({10, 0}, now);
///   const VirtualRobot::State& s = robot.Advance(now + 100'000'000);
#pragma once

#include <cstdint>
#include <optional>

#include <dyad/status.hpp>

namespace dyad::cartesian {

struct Vec2 {
  double x = 0, y = 0;
};

struct VirtualRobotOptions {
  // Defaults let the study's experiment run undistorted: a command <= 5 units from the robot
  // (the mixer's saturation) is reached within one 100 ms step whatever the previous velocity.
  double max_velocity = 100.0;       // workspace units/s (norm), > 0
  double max_acceleration = 2000.0;  // workspace units/s^2 (norm), > 0
  double x_min = -60, x_max = 60;    // workspace box, workspace units; min < max
  double y_min = -60, y_max = 60;
  int64_t watchdog_ns = 500'000'000; // stop when commands are older, > 0
  std::optional<Vec2> initial;       // start position; none: the first target

  // OK, or InvalidArgument naming the field, its value and the broken constraint.
  Status Validate() const;
};

class VirtualRobot {
 public:
  struct State {
    Vec2 position, velocity;
    bool stopped = true;    // watchdog stop active (also before the first command)
    bool clamped = false;   // the last target lay outside the workspace and was clamped
  };

  // REQUIRES: options.Validate().ok().
  explicit VirtualRobot(const VirtualRobotOptions& options);

  // A new target at runtime-clock time `now_ns`; feeds the watchdog. A target with a NaN or
  // infinite coordinate is rejected (returns false, changes nothing, does not feed the
  // watchdog): clamping cannot make it safe, and one would poison the position for good.
  bool SetTarget(Vec2 target, int64_t now_ns);
  // A hold: stay where you are. Keeps the current target (with none yet, the current position)
  // and feeds the watchdog. A robot without a position yet starts at rest at the centre of its
  // workspace box. The hold's own position is not an argument: a hold is never a goal.
  void Hold(int64_t now_ns);
  // Moves the robot to time `now_ns` (never decreasing) and returns its state.
  const State& Advance(int64_t now_ns);

  const State& state() const { return state_; }
  bool started() const { return started_; }

 private:
  Vec2 Clamp(Vec2 p, bool* clamped) const;

  VirtualRobotOptions o_;
  State state_;
  bool started_ = false;       // has a position (initial, or the first target)
  bool has_target_ = false;
  Vec2 target_;
  int64_t target_ns_ = -1;     // when the latest target arrived
  int64_t advanced_ns_ = -1;   // time of the previous Advance
};

}  // namespace dyad::cartesian
