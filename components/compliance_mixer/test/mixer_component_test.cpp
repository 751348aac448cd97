// The compliance_mixer component around MixerCore: what it logs about missing and stale inputs.
#include "compliance_mixer.hpp"

#include <gtest/gtest.h>

#include <dyad/testing/fake_context.hpp>

namespace dyad::mixer {
namespace {

constexpr int64_t kStep = 100'000'000;

struct Mixer {
  testing::FakeContext ctx{&ComplianceMixer::Describe, {}};
  testing::QueueReader<msg::Intention>& robot = ctx.Feed<msg::Intention>("robot");
  testing::QueueReader<msg::HumanInput>& human = ctx.Feed<msg::HumanInput>("human");
  testing::QueueReader<msg::CartesianState>& state = ctx.Feed<msg::CartesianState>("state");  // the arm, at 0
  testing::CapturingWriter<msg::CartesianCommand>& out = ctx.Capture<msg::CartesianCommand>("command");
  ComplianceMixer mixer;
  uint64_t index = 0;
  msg::CartesianState arm;  // the state the driver reports at each step

  Mixer() { EXPECT_TRUE(mixer.Configure(ctx).ok()); }
  // One step at t = index * 100 ms; `robot`/`human` say whether a sample arrives before it.
  void Step(bool robot_sample, bool human_sample) {
    ctx.clock_.now = static_cast<int64_t>(index) * kStep;
    if (robot_sample) robot.queue.push_back(msg::Intention());
    if (human_sample) human.queue.push_back(msg::HumanInput());
    state.queue.push_back(arm);
    ctx.PollInputs();
    ASSERT_TRUE(mixer.Step(StepInfo{ctx.clock_.now, index++, kStep}).ok());
  }
  std::vector<std::string> Warnings() const { return ctx.log_.lines; }
};

// A wall-clock run starts every periodic component at once: the human's first sample may come
// after the mixer's first step. That is not a stale input (it used to warn at every start).
TEST(MixerComponent, NoWarningWhileAnInputHasNotStartedYet) {
  Mixer m;
  m.Step(true, false);
  m.Step(true, false);
  m.Step(true, true);
  for (int i = 0; i < 10; ++i) m.Step(true, true);
  EXPECT_TRUE(m.Warnings().empty()) << m.Warnings().front();
  EXPECT_FALSE(m.out.samples.empty());
}

TEST(MixerComponent, SaysSoWhenAnInputNeverStarts) {
  Mixer m;  // stale_timeout_s 0.5: silent up to 500 ms after the first step, then one warning
  for (int i = 0; i <= 5; ++i) m.Step(true, false);
  EXPECT_TRUE(m.Warnings().empty());
  m.Step(true, false);
  ASSERT_EQ(m.Warnings().size(), 1u);
  EXPECT_NE(m.Warnings()[0].find("input 'human' has sent nothing in the 500 ms since start: no command yet"),
            std::string::npos)
      << m.Warnings()[0];
}

TEST(MixerComponent, AnInputThatStopsIsStale) {
  Mixer m;
  m.Step(true, true);
  for (int i = 0; i < 7; ++i) m.Step(true, false);
  ASSERT_EQ(m.Warnings().size(), 1u);
  EXPECT_NE(m.Warnings()[0].find("input 'human' stale (no sample for more than 500 ms): holding the last command"),
            std::string::npos)
      << m.Warnings()[0];
}

// The trigger input flooded: 100 intentions far away, a step for each, 1 ms apart. The commands
// move max_speed (50 units/s) x the clock's 100 ms, not 100 x max_step.
TEST(MixerComponent, AFloodedTriggerMovesTheCommandsNoFasterThanMaxSpeed) {
  Mixer m;
  m.Step(true, true);  // the first command, at the origin
  msg::Intention far;
  far.x(1000);
  for (int i = 1; i <= 100; ++i) {
    m.ctx.clock_.now = i * 1'000'000;
    m.robot.queue.push_back(far);
    m.human.queue.push_back(msg::HumanInput());
    m.ctx.PollInputs();
    ASSERT_TRUE(m.mixer.Step(StepInfo{m.ctx.clock_.now, m.index++, kStep}).ok());
  }
  ASSERT_EQ(m.out.samples.size(), 101u);
  EXPECT_NEAR(m.out.samples.back().x(), 5.0, 1e-9);
  for (const auto& c : m.out.samples) EXPECT_LE(c.x(), 5.0 + 1e-9);
}

// A lost arm is said: once when it goes (why), once when it is back (after how long), and in the
// end-of-run summary with the holds sent meanwhile. Before, a driver reporting stopped changed
// nothing: the commands moved on, and the summary did not mention it.
TEST(MixerComponent, TheArmsOutageIsSaidAndSummarised) {
  Mixer m;
  msg::Intention far;
  far.x(1000);
  auto step = [&] {
    m.robot.queue.push_back(far);
    m.Step(false, true);
  };
  step();  // the first command: 5 from the arm at 0
  step();
  ASSERT_EQ(m.out.samples.size(), 2u);
  EXPECT_DOUBLE_EQ(m.out.samples[1].x(), 10);
  m.arm.stopped(true);
  for (int i = 0; i < 3; ++i) step();
  m.arm.stopped(false);
  m.arm.x(12);
  step();
  ASSERT_EQ(m.out.samples.size(), 6u);
  for (size_t k = 2; k < 5; ++k) {
    EXPECT_TRUE(m.out.samples[k].hold()) << k;
    EXPECT_DOUBLE_EQ(m.out.samples[k].x(), 10) << k;  // the last motion command, not the intention
  }
  EXPECT_FALSE(m.out.samples[5].hold());
  EXPECT_DOUBLE_EQ(m.out.samples[5].x(), 17);  // from the measured 12, max_step 5
  ASSERT_EQ(m.Warnings().size(), 2u);
  EXPECT_NE(m.Warnings()[0].find("arm lost (its driver reports stopped): holding at the last command (10, 0)"),
            std::string::npos)
      << m.Warnings()[0];
  EXPECT_NE(m.Warnings()[1].find("arm back after 0.3 s"), std::string::npos) << m.Warnings()[1];
  ASSERT_TRUE(m.mixer.Deactivate().ok());
  EXPECT_NE(m.Warnings().back().find("6 commands published, 3 held, 3 saturated; arm lost 1 time, 0.3 s; 3 holds "
                                     "sent while lost; 0 holds sent waiting for the arm's first state"),
            std::string::npos)
      << m.Warnings().back();
}

// A stop shorter than the mixer's step (the driver publishes faster): a stopped state between two
// steps is an outage even when the newest state moves again; the next motion starts from the arm.
TEST(MixerComponent, AStopBetweenTwoStepsIsAnOutage) {
  Mixer m;
  msg::Intention far;
  far.x(1000);
  auto step = [&] {
    m.robot.queue.push_back(far);
    m.Step(false, true);
  };
  step();
  step();
  ASSERT_DOUBLE_EQ(m.out.samples.back().x(), 10);
  msg::CartesianState blip;
  blip.stopped(true);
  m.state.queue.push_back(blip);  // then Step queues m.arm (moving, at 3): both arrive before one step
  m.arm.x(3);
  step();
  EXPECT_TRUE(m.out.samples.back().hold()) << "the stop between the steps was missed";
  EXPECT_DOUBLE_EQ(m.out.samples.back().x(), 10);
  step();
  EXPECT_FALSE(m.out.samples.back().hold());
  EXPECT_DOUBLE_EQ(m.out.samples.back().x(), 8) << "the first motion after it starts from the measured 3";
}

// An arm that never reports where it is: every command is a hold, and the summary says so.
TEST(MixerComponent, AnArmThatNeverReportsIsNotSilent) {
  Mixer m;
  m.arm.stopped(true);
  for (int i = 0; i < 3; ++i) m.Step(true, true);
  ASSERT_EQ(m.out.samples.size(), 3u);
  for (const auto& c : m.out.samples) EXPECT_TRUE(c.hold());
  ASSERT_TRUE(m.mixer.Deactivate().ok());
  EXPECT_NE(m.Warnings().back().find("3 holds sent waiting for the arm's first state: the arm never reported where "
                                     "it is"),
            std::string::npos)
      << m.Warnings().back();
}

// Unbound, the state cannot limit the first command: Configure says so, once.
TEST(MixerComponentWithoutState, WarnsThatTheFirstCommandIsNotLimited) {
  testing::FakeContext ctx{&ComplianceMixer::Describe, {}};
  ctx.Feed<msg::Intention>("robot");
  ctx.Feed<msg::HumanInput>("human");
  ctx.Capture<msg::CartesianCommand>("command");
  ComplianceMixer mixer;
  ASSERT_TRUE(mixer.Configure(ctx).ok());
  ASSERT_EQ(ctx.log_.lines.size(), 1u);
  EXPECT_NE(ctx.log_.lines[0].find("input 'state' is not bound"), std::string::npos) << ctx.log_.lines[0];
}

}  // namespace
}  // namespace dyad::mixer
