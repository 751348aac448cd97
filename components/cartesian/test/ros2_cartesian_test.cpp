// ros2_cartesian's safety rules, step by step in a fake runtime Context (no DDS; the fake arm of
// tests/ros2/ checks the same against Cyclone DDS in real processes): a hold is never a goal, a
// silent arm is an error (or fails the run with require_arm), Deactivate stays put, poses in
// another frame are refused unless pose_frame and pose_transform say how to take them.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "dyad/testing/fake_context.hpp"
#include "ros2_cartesian.hpp"

namespace dyad::cartesian {
namespace {

using geometry_msgs::msg::dds_::PoseStamped_;
using geometry_msgs::msg::dds_::TwistStamped_;
using dyad::testing::FakeContext;

constexpr int64_t kPeriodNs = 10'000'000;  // 100 Hz, as the configs step it

PoseStamped_ Pose(double x, double y, double z, const std::string& frame = "base_link") {
  PoseStamped_ p;
  p.header().frame_id(frame);
  p.pose().position().x(x);
  p.pose().position().y(y);
  p.pose().position().z(z);
  p.pose().orientation().w(1);
  return p;
}

msg::CartesianCommand Command(double x, bool hold) {
  msg::CartesianCommand c;
  c.x(x);
  c.hold(hold);
  return c;
}

double LinearNorm(const TwistStamped_& t) {
  return std::hypot(t.twist().linear().x(), t.twist().linear().y(), t.twist().linear().z());
}

std::array<double, 3> Position(const PoseStamped_& p) {
  return {p.pose().position().x(), p.pose().position().y(), p.pose().position().z()};
}

// The driver in its fake Context, every port bound.
struct Rig {
  explicit Rig(std::map<std::string, ParamValue> params)
      : ctx(&Ros2Cartesian::Describe, std::move(params)),
        commands(ctx.Feed<msg::CartesianCommand>("command")),
        poses(ctx.Feed<PoseStamped_>("arm_pose")),
        states(ctx.Capture<msg::CartesianState>("state")),
        twists(ctx.Capture<TwistStamped_>("twist")),
        targets(ctx.Capture<PoseStamped_>("pose_target")) {}
  Status Configure() {
    if (Status s = driver.Configure(ctx); !s.ok()) return s;
    return driver.Activate();
  }
  // One 100 Hz step: the arm's pose (if any) and the command (if any) arrive first.
  Status Step(const PoseStamped_* pose, const msg::CartesianCommand* command) {
    if (pose) poses.queue.push_back(*pose);
    if (command) commands.queue.push_back(*command);
    ctx.PollInputs();
    StepInfo info;
    info.now_ns = ctx.clock_.now;
    info.index = index++;
    info.period_ns = kPeriodNs;
    Status s = driver.Step(info);
    ctx.clock_.now += kPeriodNs;
    return s;
  }
  int Count(const std::string& text) const {
    int n = 0;
    for (const auto& l : ctx.log_.lines) n += l.find(text) != std::string::npos;
    return n;
  }
  std::string Log() const {
    std::string all;
    for (const auto& l : ctx.log_.lines) all += l + "\n";
    return all;
  }

  FakeContext ctx;
  dyad::testing::QueueReader<msg::CartesianCommand>& commands;
  dyad::testing::QueueReader<PoseStamped_>& poses;
  dyad::testing::CapturingWriter<msg::CartesianState>& states;
  dyad::testing::CapturingWriter<TwistStamped_>& twists;
  dyad::testing::CapturingWriter<PoseStamped_>& targets;
  Ros2Cartesian driver;
  uint64_t index = 0;
};

// Twist mode: holds far away (x = 1000, clamped to the box's wall 0.3 m off) before the first
// motion command send zero twists, the arm measured at rest; the motion command then moves it.
// Today's code took the first hold as its goal and drove towards it.
TEST(Ros2CartesianHold, AHoldIsNeverAGoalInTwistMode) {
  Rig rig({{"mode", std::string("twist")}});
  ASSERT_TRUE(rig.Configure().ok());
  const PoseStamped_ rest = Pose(0.4, 0, 0.3);
  const msg::CartesianCommand hold = Command(1000, true);
  for (int k = 0; k < 100; ++k) ASSERT_TRUE(rig.Step(&rest, &hold).ok());
  ASSERT_EQ(rig.twists.samples.size(), 100u);
  for (const auto& t : rig.twists.samples) ASSERT_EQ(LinearNorm(t), 0.0);
  const msg::CartesianCommand go = Command(5, false);  // 5 units = 10 mm along -y
  for (int k = 0; k < 10; ++k) ASSERT_TRUE(rig.Step(&rest, &go).ok());
  EXPECT_LT(rig.twists.samples.back().twist().linear().y(), -0.01);
  // A hold in the middle of a motion brakes at max_acceleration (2 m/s^2: 0.02 m/s per 10 ms step)
  // to zero: no velocity step (an arm's reflexes may trip on one), never a step towards the hold.
  double speed = LinearNorm(rig.twists.samples.back());
  for (int k = 0; k < 100; ++k) {
    ASSERT_TRUE(rig.Step(&rest, &hold).ok());
    const double now = LinearNorm(rig.twists.samples.back());
    ASSERT_LE(now, speed + 1e-12) << "step " << k;
    ASSERT_GE(now, speed - 2.0 * 0.01 - 1e-12) << "step " << k;
    speed = now;
  }
  EXPECT_EQ(speed, 0.0);
  // Without a fresh pose a hold is a zero twist at once.
  for (int k = 0; k < 10; ++k) ASSERT_TRUE(rig.Step(&rest, &go).ok());
  ASSERT_GT(LinearNorm(rig.twists.samples.back()), 0.0);
  for (int k = 0; k < 60; ++k) ASSERT_TRUE(rig.Step(nullptr, &hold).ok());  // pose_timeout_s 0.5 s passes
  EXPECT_EQ(LinearNorm(rig.twists.samples.back()), 0.0);
}

// Pose mode: the target is the measured pose taken when the stay begins, then kept. A pose that
// drifts during the hold (an arm sagging, or pushed) does not drag the target along, and a stale
// pose (far behind the arm once the stream stops) never becomes the target.
TEST(Ros2CartesianHold, APoseModeHoldKeepsTheTargetItStoppedAt) {
  Rig rig({{"mode", std::string("pose")}});
  ASSERT_TRUE(rig.Configure().ok());
  const PoseStamped_ at = Pose(0.4, 0, 0.3);
  const msg::CartesianCommand go = Command(-40, false), hold = Command(1000, true);
  for (int k = 0; k < 30; ++k) ASSERT_TRUE(rig.Step(&at, &go).ok());
  ASSERT_TRUE(rig.Step(&at, &hold).ok());
  EXPECT_EQ(Position(rig.targets.samples.back()), Position(at)) << "the stay begins where the arm is";
  for (int k = 1; k <= 50; ++k) {
    const PoseStamped_ sagging = Pose(0.4, 0, 0.3 - 0.001 * k);
    ASSERT_TRUE(rig.Step(&sagging, &hold).ok());
    ASSERT_EQ(Position(rig.targets.samples.back()), Position(at)) << "step " << k;
  }
  // Moving again, then the poses stop: the target stays the last one sent, never the old pose.
  for (int k = 0; k < 30; ++k) ASSERT_TRUE(rig.Step(&at, &go).ok());
  const auto last = Position(rig.targets.samples.back());
  ASSERT_NE(last, Position(at));
  for (int k = 0; k < 80; ++k) ASSERT_TRUE(rig.Step(nullptr, &go).ok());
  EXPECT_TRUE(rig.states.samples.back().stopped());
  EXPECT_NE(Position(rig.targets.samples.back()), Position(at)) << "a stale pose became the target";
}

// Pose mode: nothing is sent before the first pose; then each hold re-sends the measured pose
// (clamped into the box), never a step towards the hold's position; the first motion starts
// from the measured pose at rest (at most max_acceleration * dt^2 away).
TEST(Ros2CartesianHold, AHoldInPoseModeResendsTheMeasuredPose) {
  Rig rig({{"mode", std::string("pose")}});
  ASSERT_TRUE(rig.Configure().ok());
  const msg::CartesianCommand hold = Command(1000, true);
  for (int k = 0; k < 20; ++k) ASSERT_TRUE(rig.Step(nullptr, &hold).ok());
  EXPECT_TRUE(rig.targets.samples.empty()) << "a target before the arm's first pose";
  const PoseStamped_ at = Pose(0.41, 0.02, 0.31);
  for (int k = 0; k < 100; ++k) ASSERT_TRUE(rig.Step(&at, &hold).ok());
  ASSERT_EQ(rig.targets.samples.size(), 100u);
  for (const auto& t : rig.targets.samples) ASSERT_EQ(Position(t), Position(at));
  const msg::CartesianCommand go = Command(-20, false);  // robot y = +0.04 m
  ASSERT_TRUE(rig.Step(&at, &go).ok());
  const auto first = Position(rig.targets.samples.back());
  EXPECT_LE(std::hypot(first[0] - 0.41, first[1] - 0.02, first[2] - 0.31), 2.0 * 0.01 * 0.01 + 1e-12);
  for (int k = 0; k < 20; ++k) ASSERT_TRUE(rig.Step(&at, &go).ok());
  EXPECT_GT(Position(rig.targets.samples.back())[1], 0.02) << "the motion command moves the setpoint (+y)";
}

// Pose mode, the watchdog (no command for watchdog_s): the measured pose is re-sent, not the
// setpoint that ran ahead of the arm.
TEST(Ros2CartesianHold, TheWatchdogInPoseModeResendsTheMeasuredPose) {
  Rig rig({{"mode", std::string("pose")}, {"watchdog_s", 0.1}});
  ASSERT_TRUE(rig.Configure().ok());
  const PoseStamped_ at = Pose(0.4, 0, 0.3);
  const msg::CartesianCommand go = Command(-40, false);
  for (int k = 0; k < 30; ++k) ASSERT_TRUE(rig.Step(&at, &go).ok());
  ASSERT_NE(Position(rig.targets.samples.back()), Position(at));
  for (int k = 0; k < 20; ++k) ASSERT_TRUE(rig.Step(&at, nullptr).ok());
  EXPECT_EQ(Position(rig.targets.samples.back()), Position(at));
  EXPECT_TRUE(rig.states.samples.back().stopped());
}

// No pose within pose_timeout_s of the run's start: an error on the log (once) and stopped states
// every step from then on; Deactivate names it again. Today: silence, no state at all.
TEST(Ros2CartesianSilentArm, NoFirstPoseIsAnErrorAndAStoppedState) {
  Rig rig({{"mode", std::string("twist")}, {"pose_timeout_s", 0.5}});
  ASSERT_TRUE(rig.Configure().ok());
  const msg::CartesianCommand go = Command(10, false);
  for (int k = 0; k <= 50; ++k) ASSERT_TRUE(rig.Step(nullptr, &go).ok());  // up to 0.5 s: in time
  EXPECT_TRUE(rig.states.samples.empty());
  EXPECT_TRUE(rig.ctx.log_.lines.empty()) << rig.Log();
  for (int k = 0; k < 50; ++k) ASSERT_TRUE(rig.Step(nullptr, &go).ok());
  ASSERT_EQ(rig.states.samples.size(), 50u);
  for (const auto& s : rig.states.samples) ASSERT_TRUE(s.stopped());
  for (const auto& t : rig.twists.samples) ASSERT_EQ(LinearNorm(t), 0.0);
  EXPECT_EQ(rig.Count("no pose from the arm on 'arm_pose' within pose_timeout_s (0.5 s) of the run's start"), 1) << rig.Log();
  ASSERT_TRUE(rig.driver.Deactivate().ok());
  EXPECT_EQ(rig.Count("the arm was never driven"), 1) << rig.Log();
}

// The arm's time to answer counts from the run's first step, not from Activate: a process
// activates before the start barrier, which may hold it for seconds (other processes starting, a
// subject's page on its way). 2 s at the barrier, then a pose 0.2 s into the run: no error, even
// with require_arm (before: the run failed at its first step, 1.5 s "overdue").
TEST(Ros2CartesianSilentArm, TheFirstPoseIsDueFromTheRunsStartNotFromActivation) {
  Rig rig({{"mode", std::string("twist")}, {"pose_timeout_s", 0.5}, {"require_arm", true}});
  ASSERT_TRUE(rig.Configure().ok());    // activated at t = 0
  rig.ctx.clock_.now += 2'000'000'000;  // the start barrier
  for (int k = 0; k < 20; ++k) ASSERT_TRUE(rig.Step(nullptr, nullptr).ok()) << "step " << k;
  const PoseStamped_ at = Pose(0.4, 0, 0.3);
  for (int k = 0; k < 60; ++k) ASSERT_TRUE(rig.Step(&at, nullptr).ok());
  EXPECT_EQ(rig.Count("no pose from the arm"), 0) << rig.Log();
}

// require_arm: the same silence fails the run, from the step where the first pose is overdue.
TEST(Ros2CartesianSilentArm, RequireArmFailsTheRun) {
  Rig rig({{"mode", std::string("twist")}, {"pose_timeout_s", 0.5}, {"require_arm", true}});
  ASSERT_TRUE(rig.Configure().ok());
  for (int k = 0; k <= 50; ++k) ASSERT_TRUE(rig.Step(nullptr, nullptr).ok());
  const Status s = rig.Step(nullptr, nullptr);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("no pose from the arm on 'arm_pose'"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("require_arm"), std::string::npos) << s.message();
}

// An arm lost mid-run: named in Deactivate's summary with how long it was gone.
TEST(Ros2CartesianSilentArm, AnOutageIsInTheSummary) {
  Rig rig({{"mode", std::string("twist")}, {"pose_timeout_s", 0.1}});
  ASSERT_TRUE(rig.Configure().ok());
  const PoseStamped_ at = Pose(0.4, 0, 0.3);
  for (int k = 0; k < 10; ++k) ASSERT_TRUE(rig.Step(&at, nullptr).ok());
  for (int k = 0; k < 100; ++k) ASSERT_TRUE(rig.Step(nullptr, nullptr).ok());  // 1 s without a pose
  for (int k = 0; k < 10; ++k) ASSERT_TRUE(rig.Step(&at, nullptr).ok());
  ASSERT_TRUE(rig.driver.Deactivate().ok());
  EXPECT_EQ(rig.Count("the arm's poses stopped 1 time(s), 1.01 s in all"), 1) << rig.Log();
}

// Deactivate stays put: a zero twist after a moving one (Servo would otherwise go on until its
// own timeout), or the measured pose re-sent after a setpoint that ran ahead.
TEST(Ros2CartesianDeactivate, TwistModeSendsAZeroTwist) {
  Rig rig({{"mode", std::string("twist")}});
  ASSERT_TRUE(rig.Configure().ok());
  const PoseStamped_ at = Pose(0.4, 0, 0.3);
  const msg::CartesianCommand go = Command(40, false);
  for (int k = 0; k < 20; ++k) ASSERT_TRUE(rig.Step(&at, &go).ok());
  ASSERT_GT(LinearNorm(rig.twists.samples.back()), 0.01);
  const size_t sent = rig.twists.samples.size();
  ASSERT_TRUE(rig.driver.Deactivate().ok());
  ASSERT_EQ(rig.twists.samples.size(), sent + 1);
  EXPECT_EQ(LinearNorm(rig.twists.samples.back()), 0.0);
}

TEST(Ros2CartesianDeactivate, PoseModeResendsTheMeasuredPose) {
  Rig rig({{"mode", std::string("pose")}});
  ASSERT_TRUE(rig.Configure().ok());
  const PoseStamped_ at = Pose(0.4, 0, 0.3);
  const msg::CartesianCommand go = Command(40, false);
  for (int k = 0; k < 20; ++k) ASSERT_TRUE(rig.Step(&at, &go).ok());
  ASSERT_NE(Position(rig.targets.samples.back()), Position(at));
  ASSERT_TRUE(rig.driver.Deactivate().ok());
  EXPECT_EQ(Position(rig.targets.samples.back()), Position(at));
}

// Poses in a frame other than frame_id are refused (counted, logged once): no state from them,
// and the missing first pose says why. Today they were taken as if in frame_id.
TEST(Ros2CartesianFrames, PosesInAnotherFrameAreRefused) {
  Rig rig({{"mode", std::string("twist")}, {"pose_timeout_s", 0.5}});
  ASSERT_TRUE(rig.Configure().ok());
  const PoseStamped_ world = Pose(0.4, 0, 0.3, "world");
  for (int k = 0; k < 60; ++k) ASSERT_TRUE(rig.Step(&world, nullptr).ok());
  EXPECT_EQ(rig.Count("the arm reported a pose in frame 'world', not 'base_link': refused"), 1) << rig.Log();
  EXPECT_EQ(rig.Count("poses refused: not in frame 'base_link'"), 1) << rig.Log();
  ASSERT_FALSE(rig.states.samples.empty());
  for (const auto& s : rig.states.samples) ASSERT_TRUE(s.stopped());
  ASSERT_TRUE(rig.driver.Deactivate().ok());
  EXPECT_EQ(rig.Count("refused 60 poses not in frame 'base_link'"), 1) << rig.Log();
}

// pose_frame with pose_transform: poses in 'world' are transformed into frame_id (here world
// is base_link turned 90 degrees about z and shifted 0.1 m along x); poses in frame_id are then
// the ones refused.
TEST(Ros2CartesianFrames, PoseFrameWithATransformIsTakenThroughIt) {
  const double h = std::sqrt(0.5);
  Rig rig({{"mode", std::string("twist")}, {"pose_frame", std::string("world")},
           {"pose_transform", std::vector<double>{0.1, 0, 0, 0, 0, h, h}}});
  ASSERT_TRUE(rig.Configure().ok());
  // world (0, -0.3, 0.3) -> rotated (0.3, 0, 0.3) -> shifted (0.4, 0, 0.3): the plane's origin.
  const PoseStamped_ world = Pose(0, -0.3, 0.3, "world");
  for (int k = 0; k < 5; ++k) ASSERT_TRUE(rig.Step(&world, nullptr).ok());
  ASSERT_EQ(rig.states.samples.size(), 5u);
  EXPECT_NEAR(rig.states.samples.back().x(), 0, 1e-9);
  EXPECT_NEAR(rig.states.samples.back().y(), 0, 1e-9);
  EXPECT_NEAR(rig.states.samples.back().z(), 0, 1e-9);
  const PoseStamped_ base = Pose(0.4, 0, 0.3, "base_link");
  ASSERT_TRUE(rig.Step(&base, nullptr).ok());
  EXPECT_EQ(rig.Count("in frame 'base_link', not 'world': refused"), 1) << rig.Log();
}

TEST(Ros2CartesianFrames, AnotherPoseFrameWithoutATransformIsRefusedNamingTheParam) {
  Rig rig({{"pose_frame", std::string("world")}});
  const Status s = rig.Configure();
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("params.pose_frame: poses in 'world' need components.under_test.params.pose_transform"),
            std::string::npos)
      << s.message();
  EXPECT_NE(s.message().find("dyad reads no TF"), std::string::npos) << s.message();

  Rig same({{"pose_transform", std::vector<double>{0, 0, 0, 0, 0, 0, 1}}});
  const Status t = same.Configure();
  ASSERT_FALSE(t.ok());
  EXPECT_NE(t.message().find("params.pose_transform: only for poses in another frame"), std::string::npos)
      << t.message();

  Rig bad({{"pose_frame", std::string("world")}, {"pose_transform", std::vector<double>{0, 0, 0, 0, 0, 0, 2}}});
  const Status u = bad.Configure();
  ASSERT_FALSE(u.ok());
  EXPECT_NE(u.message().find("a unit quaternion"), std::string::npos) << u.message();
}

}  // namespace
}  // namespace dyad::cartesian
