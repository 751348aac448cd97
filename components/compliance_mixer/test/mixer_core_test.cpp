// MixerCore: blend, saturation, stale hold, PI against closed forms.
#include "mixer_core.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace dyad::mixer {
namespace {

constexpr int64_t kStep = 100'000'000;  // 100 ms

MixerCore::Inputs Fresh(Vec2 robot, Vec2 human, bool engaged, int64_t now) {
  MixerCore::Inputs in;
  in.robot = {robot, now};
  in.human = {human, now};
  in.engaged = engaged;
  return in;
}

MixerOptions NoLimit() {
  MixerOptions o;
  o.max_step = 0;
  return o;
}

TEST(MixerOptions, DefaultsAreValidAndTheStudys) {
  MixerOptions o;
  EXPECT_TRUE(o.Validate().ok());
  EXPECT_EQ(o.gain, 0.9);
  EXPECT_EQ(o.max_step, 5.0);
  EXPECT_EQ(o.max_speed, 50.0);  // 5 units per 100 ms step
}

TEST(MixerOptions, ErrorsNameFieldValueAndConstraint) {
  MixerOptions o;
  o.gain = 1.5;
  EXPECT_EQ(o.Validate().message(), "gain = 1.5: must be in [0, 1]");
  o = MixerOptions();
  o.stale_timeout_ns = 0;
  EXPECT_EQ(o.Validate().message(), "stale_timeout_s = 0: must be > 0");
  o = MixerOptions();
  o.ki = -1;
  EXPECT_EQ(o.Validate().message(), "ki = -1: must be >= 0");
  o = MixerOptions();
  o.max_speed = -2;
  EXPECT_EQ(o.Validate().message(), "max_speed = -2: must be >= 0");
}

TEST(MixerCore, EngagedHumanBlendsWithGain) {
  MixerCore m(NoLimit());
  const auto r = m.Update(Fresh({10, -20}, {30, 40}, true, 0), 0);
  ASSERT_TRUE(r.has_command);
  EXPECT_FALSE(r.hold);
  EXPECT_DOUBLE_EQ(r.position.x, 0.9 * 30 + 0.1 * 10);
  EXPECT_DOUBLE_EQ(r.position.y, 0.9 * 40 + 0.1 * -20);
}

TEST(MixerCore, DisengagedHumanLeavesTheRobotsIntention) {
  MixerCore m(NoLimit());
  const auto r = m.Update(Fresh({10, -20}, {30, 40}, false, 0), 0);
  EXPECT_DOUBLE_EQ(r.position.x, 10);
  EXPECT_DOUBLE_EQ(r.position.y, -20);
}

TEST(SaturateNorm, KeepsDirectionAndShortensToTheLimit) {
  bool clipped = false;
  Vec2 d = SaturateNorm({30, 40}, 5, &clipped);  // norm 50
  EXPECT_TRUE(clipped);
  EXPECT_DOUBLE_EQ(d.x, 3);
  EXPECT_DOUBLE_EQ(d.y, 4);
  d = SaturateNorm({3, 4}, 5, &clipped);
  EXPECT_FALSE(clipped);
  EXPECT_DOUBLE_EQ(d.x, 3);
  d = SaturateNorm({300, 400}, 0, &clipped);  // 0: no limit
  EXPECT_FALSE(clipped);
  EXPECT_DOUBLE_EQ(d.x, 300);
}

TEST(MixerCore, ChangePerStepIsSaturatedToFiveUnitsByNorm) {
  MixerCore m{MixerOptions()};
  auto r = m.Update(Fresh({0, 0}, {0, 0}, false, 0), 0);  // first command: no reference, taken as is
  EXPECT_DOUBLE_EQ(r.position.x, 0);
  // The robot jumps to (30, 40): the command walks there 5 units per step along the line.
  for (int k = 1; k <= 10; ++k) {
    r = m.Update(Fresh({30, 40}, {0, 0}, false, k * kStep), k * kStep);
    EXPECT_EQ(r.saturated, k < 10) << k;  // the last step is exactly 5 units
    EXPECT_NEAR(r.position.x, 3.0 * k, 1e-12);
    EXPECT_NEAR(r.position.y, 4.0 * k, 1e-12);
  }
  r = m.Update(Fresh({30, 40}, {0, 0}, false, 11 * kStep), 11 * kStep);
  EXPECT_FALSE(r.saturated);
  EXPECT_DOUBLE_EQ(r.position.x, 30);
}

// A writer flooding the trigger input (a buggy or hostile one, spoofed UDP states): 50 updates
// in 100 ms used to allow 50 x 5 = 250 units; per second of the runtime clock it is 50 units/s,
// so 5 units in those 100 ms, whatever the number of updates.
TEST(MixerCore, AFloodOfUpdatesMovesTheCommandNoFasterThanMaxSpeed) {
  MixerCore m{MixerOptions()};
  auto r = m.Update(Fresh({0, 0}, {0, 0}, false, 0), 0);
  ASSERT_DOUBLE_EQ(r.position.x, 0);
  const int64_t every = 2'000'000;  // 2 ms
  double furthest = 0;
  for (int k = 1; k <= 50; ++k) {
    r = m.Update(Fresh({1000, 0}, {0, 0}, false, k * every), k * every);
    EXPECT_TRUE(r.saturated) << k;
    furthest = std::max(furthest, std::hypot(r.position.x, r.position.y));
  }
  EXPECT_NEAR(r.position.x, 50.0 * 0.1, 1e-9);  // max_speed x 100 ms
  EXPECT_LE(furthest, 5.0 + 1e-9);
  // Two updates at one instant: no time, no motion.
  const Vec2 at = r.position;
  r = m.Update(Fresh({1000, 0}, {0, 0}, false, 50 * every), 50 * every);
  EXPECT_DOUBLE_EQ(r.position.x, at.x);
  EXPECT_TRUE(r.saturated);
}

TEST(MixerCore, MaxSpeedZeroLimitsPerStepOnly) {
  MixerOptions o;
  o.max_speed = 0;
  MixerCore m(o);
  m.Update(Fresh({0, 0}, {0, 0}, false, 0), 0);
  MixerCore::Result r;
  for (int k = 1; k <= 50; ++k) r = m.Update(Fresh({1000, 0}, {0, 0}, false, k * 2'000'000), k * 2'000'000);
  EXPECT_NEAR(r.position.x, 250, 1e-9);  // 5 per update: what the flood got before max_speed
}

// After a hold, the time since the held command counts, not since the last moving one: max_step
// still caps the first move.
TEST(MixerCore, AfterAHoldTheCommandMovesAtMostMaxStep) {
  MixerOptions o;
  o.stale_timeout_ns = 50'000'000;
  MixerCore m(o);
  m.Update(Fresh({0, 0}, {0, 0}, false, 0), 0);
  MixerCore::Inputs stale = Fresh({1000, 0}, {0, 0}, false, 0);
  stale.robot.receive_ns = 0;
  for (int k = 1; k <= 20; ++k) EXPECT_TRUE(m.Update(stale, k * kStep).hold);
  const auto r = m.Update(Fresh({1000, 0}, {0, 0}, false, 21 * kStep), 21 * kStep);
  EXPECT_NEAR(r.position.x, 5, 1e-9);
}

TEST(MixerCore, FirstCommandIsSaturatedAgainstTheMeasuredState) {
  MixerCore m{MixerOptions()};
  auto in = Fresh({20, 0}, {0, 0}, false, 0);
  in.state = {{0, 0}, 0};
  const auto r = m.Update(in, 0);
  EXPECT_TRUE(r.saturated);
  EXPECT_DOUBLE_EQ(r.position.x, 5);
}

// wait_for_state: no motion before the arm's position is known. Holds (the driver stays where it
// is and reports), then the first command moves max_step from the state.
TEST(MixerCore, WaitsForTheArmsStateBeforeItsFirstCommand) {
  for (const Mode mode : {Mode::kBlend, Mode::kPi}) {
    SCOPED_TRACE(mode == Mode::kPi ? "pi" : "blend");
    MixerOptions o;
    o.wait_for_state = true;
    o.mode = mode;
    MixerCore m(o);
    for (int k = 0; k < 3; ++k) {
      const auto r = m.Update(Fresh({1000, 0}, {0, 0}, false, k * kStep), k * kStep);
      EXPECT_TRUE(r.has_command) << k;
      EXPECT_TRUE(r.hold) << k;
      EXPECT_TRUE(r.waiting_for_state) << k;
      EXPECT_EQ(r.stale, MixerCore::Stale::kState) << k;
      EXPECT_FALSE(r.non_finite) << k;
    }
    auto in = Fresh({1000, 0}, {0, 0}, false, 3 * kStep);
    in.state = {{-2, 0}, 3 * kStep};
    auto r = m.Update(in, 3 * kStep);
    EXPECT_FALSE(r.hold);
    EXPECT_FALSE(r.waiting_for_state);
    EXPECT_TRUE(r.saturated);
    EXPECT_DOUBLE_EQ(r.position.x, 3);  // -2 + max_step
    // From now on the previous command is the reference (the state, 100 ms old, is fresh).
    in = Fresh({1000, 0}, {0, 0}, false, 4 * kStep);
    in.state = {{-2, 0}, mode == Mode::kPi ? 4 * kStep : 3 * kStep};
    r = m.Update(in, 4 * kStep);
    EXPECT_FALSE(r.hold);
    EXPECT_DOUBLE_EQ(r.position.x, 8);  // pi too: its desired 1000 is saturated against the last command
  }
}

// A state that arrived long ago is not where the arm is now: the first command waits for a fresh one.
TEST(MixerCore, AStaleStateDoesNotStartTheFirstCommand) {
  MixerOptions o;
  o.wait_for_state = true;
  MixerCore m(o);
  auto in = Fresh({1000, 0}, {0, 0}, false, 10 * kStep);
  in.state = {{0, 0}, 0};
  EXPECT_TRUE(m.Update(in, 10 * kStep).waiting_for_state);
}

TEST(MixerCore, StaleHumanHoldsTheLastCommandThenResumes) {
  MixerOptions o = NoLimit();
  o.stale_timeout_ns = 250'000'000;
  MixerCore m(o);
  auto r = m.Update(Fresh({1, 2}, {0, 0}, false, 0), 0);
  ASSERT_FALSE(r.hold);
  // The robot keeps publishing; the human's last sample was at t = 0.
  MixerCore::Inputs in = Fresh({7, 8}, {0, 0}, false, 0);
  in.robot.receive_ns = 2 * kStep;
  r = m.Update(in, 2 * kStep);  // 200 ms old: still fresh
  EXPECT_FALSE(r.hold);
  EXPECT_DOUBLE_EQ(r.position.x, 7);
  in.robot.receive_ns = 3 * kStep;
  r = m.Update(in, 3 * kStep);  // 300 ms > 250 ms: stale
  EXPECT_TRUE(r.hold);
  EXPECT_EQ(r.stale, MixerCore::Stale::kHuman);
  EXPECT_TRUE(r.has_command);
  EXPECT_DOUBLE_EQ(r.position.x, 7);  // the last command, not the new intention
  EXPECT_DOUBLE_EQ(r.position.y, 8);
  in = Fresh({9, 9}, {0, 0}, false, 4 * kStep);
  r = m.Update(in, 4 * kStep);
  EXPECT_FALSE(r.hold);
  EXPECT_DOUBLE_EQ(r.position.x, 9);
}

// One NaN intention (a diverged deliberator) must not become the previous command: before the
// fix every later command was NaN, since each is saturated against the previous one.
TEST(MixerCore, NonFiniteInputHoldsTheLastCommandAndDoesNotPoisonLaterOnes) {
  MixerCore m{MixerOptions()};
  auto r = m.Update(Fresh({1, 2}, {0, 0}, false, 0), 0);
  ASSERT_FALSE(r.hold);
  r = m.Update(Fresh({std::nan(""), 2}, {0, 0}, false, kStep), kStep);
  EXPECT_TRUE(r.hold);
  EXPECT_TRUE(r.non_finite);
  EXPECT_EQ(r.stale, MixerCore::Stale::kRobot);
  EXPECT_DOUBLE_EQ(r.position.x, 1);
  r = m.Update(Fresh({3, 2}, {INFINITY, 0}, true, 2 * kStep), 2 * kStep);  // engaged human: used
  EXPECT_TRUE(r.hold);
  EXPECT_EQ(r.stale, MixerCore::Stale::kHuman);
  r = m.Update(Fresh({3, 2}, {INFINITY, 0}, false, 3 * kStep), 3 * kStep);  // disengaged: not used
  EXPECT_FALSE(r.hold);
  EXPECT_FALSE(r.non_finite);
  EXPECT_DOUBLE_EQ(r.position.x, 3);
  EXPECT_DOUBLE_EQ(r.position.y, 2);
}

// The command contract: a hold carries the position to hold, never the intention. Before the
// arm's first state the holds carried the target (x = 1000 with the arm at 0: a driver that took
// it as a goal drove off). Now: the placeholder (0, 0) before anything is known, the arm's
// measured position once it was known, the last motion command after one.
TEST(MixerCore, NoHoldCarriesTheIntention) {
  MixerOptions o;
  o.wait_for_state = true;
  MixerCore m(o);
  int64_t t = 0;
  for (; t < 3 * kStep; t += kStep) {
    const auto r = m.Update(Fresh({1000, 0}, {0, 0}, false, t), t);
    ASSERT_TRUE(r.has_command);
    ASSERT_TRUE(r.hold);
    EXPECT_EQ(r.position.x, 0) << "a hold before the arm's first state carried the intention";
    EXPECT_EQ(r.position.y, 0);
  }
  // A state that says stopped is not a position to start from: still holding, not at its x.
  auto in = Fresh({1000, 0}, {0, 0}, false, t);
  in.state = {{-7, 3}, t};
  in.stopped = true;
  auto r = m.Update(in, t);
  EXPECT_TRUE(r.waiting_for_state);
  EXPECT_EQ(r.position.x, 0);
  // Known once, then stale: the hold carries where the arm was measured.
  t += kStep;
  in = Fresh({1000, 0}, {0, 0}, false, t);
  in.state = {{-7, 3}, t};
  in.robot.receive_ns = -1;  // no intention: no motion, and no command before the first one
  r = m.Update(in, t);
  EXPECT_FALSE(r.has_command);
  t += 10 * kStep;
  in = Fresh({1000, 0}, {0, 0}, false, t);
  in.state = {{-7, 3}, t - 10 * kStep};  // 1 s old
  r = m.Update(in, t);
  ASSERT_TRUE(r.hold);
  EXPECT_EQ(r.position.x, -7);
  EXPECT_EQ(r.position.y, 3);
  // After motion: every hold (stale human, lost arm) is the last motion command.
  t += kStep;
  in = Fresh({1000, 0}, {0, 0}, false, t);
  in.state = {{-7, 3}, t};
  r = m.Update(in, t);
  ASSERT_FALSE(r.hold);
  Vec2 last = r.position;
  EXPECT_LE(std::hypot(last.x + 7, last.y - 3), 5 + 1e-9);
  for (int k = 1; k <= 3; ++k) {
    in = Fresh({1000, 0}, {0, 0}, false, t + k * kStep);
    in.human.receive_ns = k == 1 ? t + k * kStep : -1;  // the human never again
    in.state = {last, t + k * kStep};
    in.stopped = k == 3;
    r = m.Update(in, t + k * kStep);
    if (k == 1) {  // one more motion command
      ASSERT_FALSE(r.hold);
      last = r.position;
      continue;
    }
    ASSERT_TRUE(r.hold) << k;
    EXPECT_EQ(r.position.x, last.x) << k;
    EXPECT_EQ(r.position.y, last.y) << k;
  }
}

// A lost arm holds the experiment. Before, the mixer went on moving the command while the driver
// said stopped (84 commands, 159 units in one run), and the arm came back to a goal far away.
// Now: holds at the last command while stopped or stale, counted; the first motion after starts
// from where the arm is measured and moves at most max_step.
TEST(MixerCore, ALostArmHoldsAndTheFirstMotionAfterStartsFromItsMeasuredPosition) {
  for (const bool stale : {false, true}) {
    SCOPED_TRACE(stale ? "state stale" : "driver reports stopped");
    MixerOptions o;
    o.wait_for_state = true;
    o.state_timeout_ns = 300'000'000;
    MixerCore m(o);
    auto step = [&](int k, Vec2 arm, bool stopped, int64_t state_ns) {
      auto in = Fresh({1000.0 * (1 + k), 0}, {0, 0}, false, k * kStep);  // the intention runs on
      in.state = {arm, state_ns};
      in.stopped = stopped;
      return m.Update(in, k * kStep);
    };
    auto r = step(0, {0, 0}, false, 0);
    EXPECT_DOUBLE_EQ(r.position.x, 5);
    r = step(1, {5, 0}, false, kStep);
    EXPECT_DOUBLE_EQ(r.position.x, 10);
    // Lost from step 2: stopped states, or the last state (at step 1) older than 300 ms from step 5.
    const int first_lost = stale ? 5 : 2;
    for (int k = 2; k <= 8; ++k) {
      r = step(k, {10, 0}, !stale, stale ? kStep : k * kStep);
      ASSERT_TRUE(r.has_command) << k;
      if (k < first_lost) {  // stale but not yet 300 ms: moving on
        EXPECT_FALSE(r.hold) << k;
        continue;
      }
      EXPECT_TRUE(r.hold) << k;
      EXPECT_TRUE(r.arm_lost) << k;
      EXPECT_EQ(r.stopped, !stale) << k;
      EXPECT_EQ(r.stale, MixerCore::Stale::kState) << k;
      EXPECT_EQ(r.outage_started, k == first_lost) << k;
      EXPECT_DOUBLE_EQ(r.position.x, stale ? 25 : 10) << k;  // the last motion command
    }
    EXPECT_TRUE(m.arm_outages().ongoing);
    EXPECT_EQ(m.arm_outages().count, 1u);
    // Back at step 9, measured at 40 (pushed while it was away): 40 + max_step, not last + 5.
    r = step(9, {40, 0}, false, 9 * kStep);
    EXPECT_FALSE(r.hold);
    EXPECT_FALSE(r.arm_lost);
    EXPECT_TRUE(r.saturated);
    EXPECT_DOUBLE_EQ(r.position.x, 45);
    EXPECT_EQ(r.outage_ended_ns, (9 - first_lost) * kStep);
    r = step(10, {45, 0}, false, 10 * kStep);
    EXPECT_DOUBLE_EQ(r.position.x, 50);  // then from the last command, as usual
    const MixerCore::Outages& out = m.arm_outages();
    EXPECT_FALSE(out.ongoing);
    EXPECT_EQ(out.count, 1u);
    EXPECT_EQ(out.lost_ns, (9 - first_lost) * kStep);
    EXPECT_EQ(out.holds, static_cast<uint64_t>(9 - first_lost));
  }
}

// Back from an outage, the PI loop starts afresh: what it summed before is not about where the arm is.
TEST(MixerCore, PiIntegralIsResetWhenTheArmComesBack) {
  MixerOptions o;
  o.wait_for_state = true;
  o.mode = Mode::kPi;
  o.ki = 1;
  o.max_step = 0;
  o.max_speed = 0;
  MixerCore m(o);
  for (int k = 0; k < 5; ++k) {
    auto in = Fresh({10, 0}, {0, 0}, false, k * kStep);
    in.state = {{0, 0}, k * kStep};  // the arm does not follow: the integral grows
    m.Update(in, k * kStep);
  }
  ASSERT_GT(m.integral().x, 0);
  auto in = Fresh({10, 0}, {0, 0}, false, 5 * kStep);
  in.state = {{0, 0}, 5 * kStep};
  in.stopped = true;
  EXPECT_TRUE(m.Update(in, 5 * kStep).arm_lost);
  in = Fresh({10, 0}, {0, 0}, false, 6 * kStep);
  in.state = {{0, 0}, 6 * kStep};
  const auto r = m.Update(in, 6 * kStep);
  EXPECT_FALSE(r.hold);
  EXPECT_NEAR(m.integral().x, 10 * 0.1, 1e-9);  // one step's e*dt, from zero
  EXPECT_NEAR(r.position.x, 0 + 10 + 1.0, 1e-9);
}

TEST(MixerCore, NoCommandBeforeAnyInputArrived) {
  MixerCore m{MixerOptions()};
  MixerCore::Inputs in;  // nothing received
  const auto r = m.Update(in, 0);
  EXPECT_FALSE(r.has_command);
  EXPECT_TRUE(r.hold);
  EXPECT_EQ(r.stale, MixerCore::Stale::kRobot);
}

TEST(MixerCore, PiWithUnitProportionalGainIsThePlainBlend) {
  MixerOptions o = NoLimit();
  o.mode = Mode::kPi;
  MixerCore m(o);
  auto in = Fresh({10, 0}, {30, 40}, true, 0);
  in.state = {{-3, 7}, 0};
  const auto r = m.Update(in, 0);
  EXPECT_NEAR(r.position.x, 0.9 * 30 + 0.1 * 10, 1e-12);
  EXPECT_NEAR(r.position.y, 0.9 * 40, 1e-12);
}

TEST(MixerCore, PiWithStateHeldMatchesClosedFormRamp) {
  // State fixed at 0, target T: c_k = kp*T + ki*T*k*dt (the first update has dt = 0).
  MixerOptions o = NoLimit();
  o.mode = Mode::kPi;
  o.kp = 0.5;
  o.ki = 2.0;
  o.integral_limit = 1e9;
  MixerCore m(o);
  const double T = 4, dt = 0.1;
  for (int k = 0; k < 20; ++k) {
    auto in = Fresh({T, -T}, {0, 0}, false, k * kStep);
    in.state = {{0, 0}, k * kStep};
    const auto r = m.Update(in, k * kStep);
    EXPECT_NEAR(r.position.x, o.kp * T + o.ki * T * k * dt, 1e-9) << k;
    EXPECT_NEAR(r.position.y, -(o.kp * T + o.ki * T * k * dt), 1e-9) << k;
  }
}

TEST(MixerCore, PiProportionalLoopAroundAPerfectDriverConvergesGeometrically) {
  // Driver reaches each command: s_k = c_{k-1}. With ki = 0: T - c_k = (1 - kp)^(k+1) * (T - s_0).
  MixerOptions o = NoLimit();
  o.mode = Mode::kPi;
  o.kp = 0.3;
  MixerCore m(o);
  const double T = 10;
  Vec2 s{0, 0};
  for (int k = 0; k < 15; ++k) {
    auto in = Fresh({T, 0}, {0, 0}, false, k * kStep);
    in.state = {s, k * kStep};
    const auto r = m.Update(in, k * kStep);
    EXPECT_NEAR(T - r.position.x, std::pow(1 - o.kp, k + 1) * T, 1e-9) << k;
    s = r.position;
  }
}

TEST(MixerCore, PiIntegralIsClampedAndFrozenWhileSaturated) {
  MixerOptions o = NoLimit();
  o.mode = Mode::kPi;
  o.kp = 0;
  o.ki = 1;
  o.integral_limit = 0.5;
  MixerCore m(o);
  for (int k = 0; k < 30; ++k) {
    auto in = Fresh({2, 0}, {0, 0}, false, k * kStep);
    in.state = {{0, 0}, k * kStep};
    m.Update(in, k * kStep);
  }
  EXPECT_DOUBLE_EQ(m.integral().x, 0.5);  // 2 * 0.1 * 29 = 5.8 without the clamp

  // Saturated commands: the integral does not accumulate.
  o.integral_limit = 100;
  o.max_step = 0.01;
  MixerCore sat(o);
  for (int k = 0; k < 10; ++k) {
    auto in = Fresh({50, 0}, {0, 0}, false, k * kStep);
    in.state = {{0, 0}, k * kStep};
    sat.Update(in, k * kStep);
  }
  EXPECT_DOUBLE_EQ(sat.integral().x, 0.0);
}

TEST(MixerCore, PiHoldsWhenTheStateIsStale) {
  MixerOptions o = NoLimit();
  o.mode = Mode::kPi;
  MixerCore m(o);
  auto in = Fresh({1, 1}, {0, 0}, false, 0);  // no state ever
  const auto r = m.Update(in, 0);
  EXPECT_TRUE(r.hold);
  EXPECT_EQ(r.stale, MixerCore::Stale::kState);
}

}  // namespace
}  // namespace dyad::mixer
