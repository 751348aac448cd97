// VirtualRobot: workspace clamping, velocity and acceleration limits, watchdog.
#include "virtual_robot.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace dyad::cartesian {
namespace {

constexpr int64_t kStep = 100'000'000;  // 100 ms

double Norm(Vec2 v) { return std::hypot(v.x, v.y); }

TEST(VirtualRobotOptions, DefaultsAreValid) { EXPECT_TRUE(VirtualRobotOptions().Validate().ok()); }

TEST(VirtualRobotOptions, ErrorsNameTheField) {
  VirtualRobotOptions o;
  o.max_velocity = 0;
  EXPECT_EQ(o.Validate().message(), "max_velocity = 0: must be > 0");
  o = VirtualRobotOptions();
  o.x_min = 10, o.x_max = -10;
  EXPECT_EQ(o.Validate().message(), "x_limits = 10: min must be < max");
  o = VirtualRobotOptions();
  o.initial = Vec2{100, 0};
  EXPECT_EQ(o.Validate().message(), "initial_position = 100: must lie inside the workspace");
}

TEST(VirtualRobot, StartsAtRestAtItsFirstTargetWithoutInitialPosition) {
  VirtualRobot r{VirtualRobotOptions()};
  EXPECT_FALSE(r.started());
  r.SetTarget({12, -7}, 0);
  const auto& s = r.Advance(0);
  EXPECT_TRUE(r.started());
  EXPECT_FALSE(s.stopped);
  EXPECT_EQ(s.position.x, 12);
  EXPECT_EQ(s.position.y, -7);
  EXPECT_EQ(Norm(s.velocity), 0);
}

// The study's experiment: the mixer moves the command at most 5 units per 100 ms step; the
// default robot must follow without distortion, whatever the direction changes.
TEST(VirtualRobot, DefaultsReachEveryFiveUnitStepWithinTheStep) {
  VirtualRobot r{VirtualRobotOptions()};
  Vec2 c{0, 0};
  r.SetTarget(c, 0);
  r.Advance(0);
  for (int k = 1; k <= 200; ++k) {
    // Full 5-unit steps turning by 2.2 rad (126 degrees) each time: the walk stays near the origin.
    const double angle = k * 2.2;
    c = {c.x + 5 * std::cos(angle), c.y + 5 * std::sin(angle)};
    r.SetTarget(c, k * kStep);
    const auto& s = r.Advance(k * kStep);
    ASSERT_NEAR(s.position.x, c.x, 1e-9) << "step " << k;
    ASSERT_NEAR(s.position.y, c.y, 1e-9) << "step " << k;
  }
}

TEST(VirtualRobot, SpeedIsLimitedByNormKeepingDirection) {
  VirtualRobotOptions o;
  o.max_velocity = 10;
  o.max_acceleration = 1e6;
  o.initial = Vec2{0, 0};
  VirtualRobot r(o);
  r.Advance(0);
  r.SetTarget({30, 40}, 0);
  const auto& s = r.Advance(kStep);
  EXPECT_NEAR(Norm(s.velocity), 10, 1e-9);
  EXPECT_NEAR(s.position.x, 0.6, 1e-9);  // 1 unit along (3, 4)/5
  EXPECT_NEAR(s.position.y, 0.8, 1e-9);
}

TEST(VirtualRobot, AccelerationIsLimitedByNorm) {
  VirtualRobotOptions o;
  o.max_velocity = 1000;
  o.max_acceleration = 100;  // +10 units/s per 100 ms step
  o.initial = Vec2{0, 0};
  VirtualRobot r(o);
  r.Advance(0);
  r.SetTarget({50, 0}, 0);
  double v_prev = 0;
  for (int k = 1; k <= 5; ++k) {
    r.SetTarget({50, 0}, k * kStep);
    const auto& s = r.Advance(k * kStep);
    EXPECT_LE(Norm(s.velocity) - v_prev, 100 * 0.1 + 1e-9) << k;
    EXPECT_NEAR(s.velocity.x, 10.0 * k, 1e-9) << k;
    v_prev = Norm(s.velocity);
  }
}

TEST(VirtualRobot, BrakesInTimeInsteadOfOvershooting) {
  VirtualRobotOptions o;
  o.max_velocity = 50;
  o.max_acceleration = 100;
  o.initial = Vec2{0, 0};
  VirtualRobot r(o);
  r.Advance(0);
  double max_x = 0;
  for (int k = 1; k <= 100; ++k) {
    r.SetTarget({20, 0}, k * kStep);
    max_x = std::max(max_x, r.Advance(k * kStep).position.x);
  }
  EXPECT_LE(max_x, 20 + 1e-9);  // no overshoot
  EXPECT_NEAR(r.state().position.x, 20, 1e-6);
  EXPECT_NEAR(r.state().velocity.x, 0, 1e-6);
}

TEST(VirtualRobot, TargetsOutsideTheWorkspaceAreClamped) {
  VirtualRobotOptions o;
  o.initial = Vec2{55, 0};
  VirtualRobot r(o);
  r.Advance(0);
  for (int k = 1; k <= 20; ++k) {
    r.SetTarget({500, -500}, k * kStep);
    const auto& s = r.Advance(k * kStep);
    EXPECT_TRUE(s.clamped);
    EXPECT_LE(s.position.x, 60);
    EXPECT_GE(s.position.y, -60);
  }
  EXPECT_NEAR(r.state().position.x, 60, 1e-9);
  EXPECT_NEAR(r.state().position.y, -60, 1e-9);
  r.SetTarget({1, 2}, 21 * kStep);
  EXPECT_FALSE(r.state().clamped);
}

TEST(VirtualRobot, WatchdogBrakesToRestWhenCommandsGoStaleAndClearsOnTheNext) {
  VirtualRobotOptions o;
  o.watchdog_ns = 300'000'000;
  o.max_acceleration = 200;  // 20 units/s per step: braking from 50 takes 3 steps
  o.initial = Vec2{0, 0};
  VirtualRobot r(o);
  r.Advance(0);
  for (int k = 1; k <= 10; ++k) {
    r.SetTarget({5.0 * k, 0}, k * kStep);  // 50 units/s
    r.Advance(k * kStep);
  }
  const double v0 = r.state().velocity.x;
  ASSERT_GT(v0, 30);
  // Commands stop after t = 1.0 s. Still fresh at 1.3 s, stale from 1.4 s.
  EXPECT_FALSE(r.Advance(13 * kStep).stopped);
  double v = r.state().velocity.x;
  const auto& s = r.Advance(14 * kStep);
  EXPECT_TRUE(s.stopped);
  EXPECT_GE(s.velocity.x, v - 200 * 0.1 - 1e-9);  // braking within the acceleration limit, not jumping
  EXPECT_LT(s.velocity.x, v);
  for (int k = 15; k <= 20; ++k) r.Advance(k * kStep);
  EXPECT_TRUE(r.state().stopped);
  EXPECT_EQ(r.state().velocity.x, 0);
  const double x = r.state().position.x;
  r.Advance(30 * kStep);
  EXPECT_EQ(r.state().position.x, x);  // at rest
  r.SetTarget({x, 0}, 31 * kStep);
  EXPECT_FALSE(r.Advance(31 * kStep).stopped);
}

TEST(VirtualRobot, NoCommandEverMeansStopped) {
  VirtualRobotOptions o;
  o.initial = Vec2{1, 1};
  VirtualRobot r(o);
  EXPECT_TRUE(r.Advance(0).stopped);
  EXPECT_TRUE(r.Advance(kStep).stopped);
  EXPECT_EQ(r.state().position.x, 1);
}

TEST(VirtualRobot, ElapsedTimeIsCappedAtTheWatchdogTimeout) {
  // A driver that has not stepped for 10 s does not get 10 s of motion in one step.
  VirtualRobotOptions o;
  o.max_velocity = 10;
  o.watchdog_ns = 500'000'000;
  o.initial = Vec2{0, 0};
  VirtualRobot r(o);
  r.Advance(0);
  r.SetTarget({50, 0}, 100 * kStep);
  EXPECT_NEAR(r.Advance(100 * kStep).position.x, 5, 1e-9);  // 0.5 s at 10 units/s
}

// A NaN or infinite target (a diverged upstream, a corrupt packet) must not move the robot:
// std::clamp passes NaN through, and one NaN position never recovers.
TEST(VirtualRobot, NonFiniteTargetsAreRejectedAndDoNotFeedTheWatchdog) {
  VirtualRobot r{VirtualRobotOptions()};
  EXPECT_FALSE(r.SetTarget({std::nan(""), 0}, 0));
  EXPECT_FALSE(r.started());  // a rejected first target does not place the robot
  ASSERT_TRUE(r.SetTarget({10, 0}, 0));
  r.Advance(0);
  for (int64_t k = 1; k <= 10; ++k) {
    EXPECT_FALSE(r.SetTarget({k % 2 ? std::nan("") : 0.0, k % 2 ? 0.0 : INFINITY}, k * kStep));
    const auto& s = r.Advance(k * kStep);
    ASSERT_TRUE(std::isfinite(s.position.x) && std::isfinite(s.position.y)) << k;
    EXPECT_EQ(s.position.x, 10) << k;
    EXPECT_EQ(s.stopped, k * kStep > VirtualRobotOptions().watchdog_ns) << k;  // only the valid target fed it
  }
}


// A hold: the robot stays (on its target, or where it is) and the watchdog is fed. A robot with
// no position yet starts at rest at the centre of its box: a hold is never a goal (the command
// contract). Before, it started at the hold's x, y, so a hold far away placed the arm there.
TEST(VirtualRobot, HoldKeepsTheRobotWhereItIsAndFeedsTheWatchdog) {
  VirtualRobotOptions o;
  o.initial = Vec2{0, 0};
  VirtualRobot r(o);
  r.Advance(0);
  for (int64_t k = 1; k <= 10; ++k) {
    r.Hold(k * kStep);
    const auto& s = r.Advance(k * kStep);
    EXPECT_EQ(s.position.x, 0) << k;
    EXPECT_FALSE(s.stopped) << k;
  }
  ASSERT_TRUE(r.SetTarget({3, 0}, 11 * kStep));
  r.Advance(12 * kStep);
  r.Hold(13 * kStep);  // keeps the target it had
  EXPECT_NEAR(r.Advance(20 * kStep).position.x, 3, 1e-9);
}

// The driver test of the command contract on the model both drivers run: holds while the goal is
// far away (the mixer's intention), then the first motion command max_step (5) away.
TEST(VirtualRobot, WithoutAPositionAHoldStartsItAtTheBoxCentreAndTheFirstMotionMovesAtMostMaxStep) {
  VirtualRobotOptions o;
  o.x_min = -20, o.x_max = 60;  // centre (20, 10)
  o.y_min = -10, o.y_max = 30;
  VirtualRobot r(o);
  for (int64_t k = 0; k < 5; ++k) {
    r.Hold(k * kStep);
    const auto& s = r.Advance(k * kStep);
    EXPECT_TRUE(r.started());
    EXPECT_EQ(s.position.x, 20) << k;
    EXPECT_EQ(s.position.y, 10) << k;
    EXPECT_EQ(Norm(s.velocity), 0) << k;
    EXPECT_FALSE(s.stopped) << k;
  }
  ASSERT_TRUE(r.SetTarget({25, 10}, 5 * kStep));
  const auto& s = r.Advance(5 * kStep);
  EXPECT_LE(std::hypot(s.position.x - 20, s.position.y - 10), 5 + 1e-9);
  EXPECT_NEAR(s.position.x, 25, 1e-9);
}

// After the watchdog braked the robot short of its target, a hold keeps it where it stopped: the
// abandoned target is not taken up again (a hold is never a goal, not even an old one).
TEST(VirtualRobot, AHoldAfterTheWatchdogStopKeepsTheRobotWhereItStopped) {
  VirtualRobotOptions o;
  o.initial = Vec2{0, 0};
  o.max_velocity = 10;  // 1 unit per 100 ms step: the target 50 away is far from reached
  VirtualRobot r(o);
  ASSERT_TRUE(r.SetTarget({50, 0}, 0));
  for (int64_t k = 1; k <= 3; ++k) r.Advance(k * kStep);
  int64_t t = 3 * kStep;
  for (int k = 0; k < 10; ++k) r.Advance(t += kStep);  // no command for 1 s: the watchdog brakes it
  const VirtualRobot::State stopped = r.Advance(t += kStep);
  ASSERT_TRUE(stopped.stopped);
  ASSERT_LT(stopped.position.x, 45);
  for (int k = 0; k < 20; ++k) {
    r.Hold(t += kStep);
    const auto& s = r.Advance(t);
    ASSERT_FALSE(s.stopped);
    ASSERT_NEAR(s.position.x, stopped.position.x, 1e-9) << "step " << k;
  }
}

}  // namespace
}  // namespace dyad::cartesian
