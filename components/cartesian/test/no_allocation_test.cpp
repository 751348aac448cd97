// The drivers' steps promise no heap allocation (10 Hz hot path): both run here inside a fake
// runtime Context, with the global operator new replaced to count allocations. udp_cartesian
// talks to a controller played by the test on loopback. The driver tests that need that fake
// Context and controller live here too: non-finite commands, the udp workspace clamp.
#include <gtest/gtest.h>

#include "dyad/testing/allocation_counter.hpp"
#include "dyad/testing/fake_context.hpp"

#include <cmath>
#include <cstdlib>
#include <deque>

#include <dyad/component.hpp>
#include <dyad/msg/types.hpp>

#include "cartesian.hpp"
#include "ros2_cartesian.hpp"


namespace dyad::cartesian {
namespace {

class FakeClock final : public Clock {
 public:
  int64_t now_ns() const override { return now; }
  int64_t now = 0;
};

class FakeLogger final : public Logger {
 public:
  void Write(Level, std::string_view m) override { lines.emplace_back(m); }
  std::vector<std::string> lines;
};

class CountingWriter final : public detail::WriterEndpoint {
 public:
  Status Write(const void* sample) override {
    last = *static_cast<const msg::CartesianState*>(sample);
    ++written;
    return Status::OK();
  }
  msg::CartesianState last;
  int written = 0;
};

class FakeContext final : public Context {
 public:
  explicit FakeContext(std::map<std::string, ParamValue> params) : params_(std::move(params)) {
    command_.Bind("command", "robot/command", &commands);
    state_.Bind("state", "robot/state", "driver", &states, &time);
  }
  const std::string& name() const override { return name_; }
  const Params& params() const override { return params_; }
  const Clock& clock() const override { return time; }
  Logger& log() override { return logger; }
  uint64_t seed() const override { return 1; }
  int64_t period_ns() const override { return 0; }
  void RequestStop(std::string) override {}

  // One runtime step: poll the input at the clock's time, then step the component.
  Status StepOnce(Component& c, uint64_t index) {
    command_.Poll(time.now);
    StepInfo info;
    info.now_ns = time.now;
    info.index = index;
    return c.Step(info);
  }

  FakeClock time;
  FakeLogger logger;
  dyad::testing::QueueReader<msg::CartesianCommand> commands;  // copied into the runtime's scratch sample
  CountingWriter states;

 protected:
  InputBase* FindInput(std::string_view, const TypeInfo&) override { return &command_; }
  OutputBase* FindOutput(std::string_view, const TypeInfo&) override { return &state_; }

 private:
  std::string name_ = "driver";
  Params params_;
  Input<msg::CartesianCommand> command_;
  Output<msg::CartesianState> state_;
};

msg::CartesianCommand Command(double x) {
  msg::CartesianCommand c;
  c.x(x);
  c.header().source("mixer");
  return c;
}

std::map<std::string, ParamValue> VirtualParams() {
  return {{"max_velocity", 100.0}, {"max_acceleration", 2000.0}, {"x_limits", std::vector<double>{-60, 60}},
          {"y_limits", std::vector<double>{-60, 60}}, {"watchdog_s", 0.5}, {"initial_position", std::vector<double>{}}};
}

std::map<std::string, ParamValue> UdpParams(uint16_t controller_port) {
  return {{"controller_host", std::string("127.0.0.1")}, {"controller_port", int64_t{controller_port}},
          {"local_port", int64_t{0}}, {"timeout_s", 5.0}, {"reply_wait_ms", int64_t{0}},
          {"x_limits", std::vector<double>{-60, 60}}, {"y_limits", std::vector<double>{-50, 40}},
          {"key_file", std::string()}};
}

TEST(NoAllocation, VirtualCartesianStepAllocatesNothing) {
  FakeContext ctx(VirtualParams());
  VirtualCartesian driver;
  ASSERT_TRUE(driver.Configure(ctx).ok());
  ASSERT_TRUE(driver.Activate().ok());
  for (uint64_t k = 0; k < 300; ++k) {
    ctx.time.now = static_cast<int64_t>(k) * 100'000'000;
    ctx.commands.queue.push_back(Command(static_cast<double>(k) * 0.1));  // one command per step
    const long before = dyad::testing::AllocationCount();
    ASSERT_TRUE(ctx.StepOnce(driver, k).ok());
    if (k >= 2) {  // after warm-up
      ASSERT_EQ(dyad::testing::AllocationCount() - before, 0) << "step " << k;
    }
  }
  EXPECT_TRUE(ctx.logger.lines.empty());
  EXPECT_EQ(ctx.states.written, 300);
  EXPECT_NEAR(ctx.states.last.x(), 29.9, 1e-9);
}

TEST(NoAllocation, UdpCartesianStepAllocatesNothing) {
  auto controller = UdpSocket::Open(0);
  ASSERT_TRUE(controller.ok()) << controller.status().ToString();
  FakeContext ctx(UdpParams(controller->local_port()));  // the test replies between steps
  UdpCartesian driver;
  ASSERT_TRUE(driver.Configure(ctx).ok());
  ASSERT_TRUE(driver.Activate().ok());
  std::array<uint8_t, udp::kMaxPacket> rx{};
  std::array<uint8_t, udp::kStateSize> tx{};
  uint32_t state_seq = 0;
  for (uint64_t k = 0; k < 300; ++k) {
    ctx.time.now = static_cast<int64_t>(k) * 100'000'000;
    ctx.commands.queue.push_back(Command(static_cast<double>(k) * 0.1));  // one command per step
    const long before = dyad::testing::AllocationCount();
    ASSERT_TRUE(ctx.StepOnce(driver, k).ok());
    if (k >= 2) {
      ASSERT_EQ(dyad::testing::AllocationCount() - before, 0) << "step " << k;
    }
    // The controller: answer the command just sent (taken by the driver at its next step).
    ASSERT_TRUE(controller->WaitReadable(1000));
    sockaddr_in from{};
    const long n = controller->Receive(rx.data(), rx.size(), &from);
    udp::CommandPacket c;
    ASSERT_EQ(udp::DecodeCommand(rx.data(), static_cast<size_t>(n), &c), udp::Decode::kOk);
    EXPECT_EQ(c.sequence, k + 1);
    udp::StatePacket s;
    s.session = 7;
    s.sequence = ++state_seq;
    s.ack = c.sequence;
    s.stamp_ns = c.stamp_ns;
    s.x = c.x;
    udp::Encode(s, tx);
    ASSERT_TRUE(controller->SendTo(tx.data(), tx.size(), from).ok());
  }
  EXPECT_EQ(ctx.states.written, 299);  // the last reply is still in flight
  EXPECT_NEAR(ctx.states.last.x(), 29.8, 1e-9);
  ASSERT_TRUE(driver.Deactivate().ok());
  driver.Shutdown();
}

// A command with a NaN coordinate (e.g. a diverged deliberator upstream) must neither reach the
// simulated robot nor go out to a real controller.
TEST(NonFiniteCommand, VirtualCartesianKeepsItsLastTargetAndSaysSo) {
  FakeContext ctx(VirtualParams());
  VirtualCartesian driver;
  ASSERT_TRUE(driver.Configure(ctx).ok());
  ctx.commands.queue.push_back(Command(10));
  ASSERT_TRUE(ctx.StepOnce(driver, 0).ok());
  for (uint64_t k = 1; k < 4; ++k) {
    ctx.time.now = static_cast<int64_t>(k) * 100'000'000;
    msg::CartesianCommand bad = Command(std::nan(""));
    ctx.commands.queue.push_back(bad);
    ASSERT_TRUE(ctx.StepOnce(driver, k).ok());
    EXPECT_EQ(ctx.states.last.x(), 10) << k;
    EXPECT_TRUE(std::isfinite(ctx.states.last.z())) << k;
  }
  ASSERT_EQ(ctx.logger.lines.size(), 1u);
  EXPECT_NE(ctx.logger.lines[0].find("not finite"), std::string::npos) << ctx.logger.lines[0];
}

// The next command the driver sent to the controller played by the test (v1), within 1 s.
bool ReceiveCommand(UdpSocket& controller, udp::CommandPacket* c) {
  if (!controller.WaitReadable(1000)) return false;
  std::array<uint8_t, udp::kMaxPacket> rx{};
  sockaddr_in from{};
  const long n = controller.Receive(rx.data(), rx.size(), &from);
  return n > 0 && udp::DecodeCommand(rx.data(), static_cast<size_t>(n), c) == udp::Decode::kOk;
}

TEST(NonFiniteCommand, UdpCartesianDoesNotSendIt) {
  auto controller = UdpSocket::Open(0);
  ASSERT_TRUE(controller.ok()) << controller.status().ToString();
  FakeContext ctx(UdpParams(controller->local_port()));
  UdpCartesian driver;
  ASSERT_TRUE(driver.Configure(ctx).ok());
  ASSERT_TRUE(driver.Activate().ok());
  msg::CartesianCommand bad = Command(1);
  bad.y(INFINITY);
  ctx.commands.queue.push_back(bad);
  ASSERT_TRUE(ctx.StepOnce(driver, 0).ok());
  EXPECT_FALSE(controller->WaitReadable(200)) << "a non-finite command was sent to the controller";
  ctx.commands.queue.push_back(Command(2));  // the next good one goes out as sequence 1
  ASSERT_TRUE(ctx.StepOnce(driver, 1).ok());
  udp::CommandPacket c;
  ASSERT_TRUE(ReceiveCommand(*controller, &c));
  EXPECT_EQ(c.sequence, 1u);
  EXPECT_EQ(c.x, 2);
  bool logged = false;
  for (const auto& l : ctx.logger.lines) logged |= l.find("not finite") != std::string::npos;
  EXPECT_TRUE(logged);
  driver.Shutdown();
}

// The controller is never sent a target outside the workspace box: clamped, logged once, counted.
TEST(UdpWorkspace, TargetsOutsideTheBoxAreClampedBeforeTheyAreSent) {
  auto controller = UdpSocket::Open(0);
  ASSERT_TRUE(controller.ok()) << controller.status().ToString();
  FakeContext ctx(UdpParams(controller->local_port()));
  UdpCartesian driver;
  ASSERT_TRUE(driver.Configure(ctx).ok());
  ASSERT_TRUE(driver.Activate().ok());
  const std::array<std::array<double, 2>, 3> sent{{{1000, -1000}, {-70, 10}, {5, 6}}};
  const std::array<std::array<double, 2>, 3> expected{{{60, -50}, {-60, 10}, {5, 6}}};
  for (size_t k = 0; k < sent.size(); ++k) {
    msg::CartesianCommand c = Command(sent[k][0]);
    c.y(sent[k][1]);
    ctx.commands.queue.push_back(c);
    ASSERT_TRUE(ctx.StepOnce(driver, k).ok());
    udp::CommandPacket p;
    ASSERT_TRUE(ReceiveCommand(*controller, &p)) << k;
    EXPECT_EQ(p.x, expected[k][0]) << k;
    EXPECT_EQ(p.y, expected[k][1]) << k;
  }
  int logged = 0;
  for (const auto& l : ctx.logger.lines) logged += l.find("outside the workspace: clamped") != std::string::npos;
  EXPECT_EQ(logged, 1);
  ASSERT_TRUE(driver.Deactivate().ok());
  EXPECT_NE(ctx.logger.lines.back().find("2 clamped to the workspace"), std::string::npos) << ctx.logger.lines.back();
  driver.Shutdown();
}

TEST(UdpWorkspace, LimitsMustBeAnOrderedFinitePair) {
  for (const auto& bad : {std::vector<double>{10, -10}, std::vector<double>{1}, std::vector<double>{0, INFINITY}}) {
    auto params = UdpParams(47000);
    params["y_limits"] = bad;
    FakeContext ctx(params);
    UdpCartesian driver;
    const Status s = driver.Configure(ctx);
    EXPECT_FALSE(s.ok());
    EXPECT_NE(s.message().find("params.y_limits: must be [min, max], finite, min < max"), std::string::npos) << s.message();
  }
}

// ros2_cartesian at 100 Hz: commands and arm poses in, a twist and the state out, through its
// own ports (two inputs, three outputs of three types). Its steps allocate nothing, also while
// its warnings' conditions last (targets clamped, poses outside the box: said once, built once).
class Ros2Context final : public Context {
 public:
  explicit Ros2Context(std::map<std::string, ParamValue> params) : params_(std::move(params)) {
    command_.Bind("command", "robot/command", &commands);
    pose_.Bind("arm_pose", "arm/pose", &poses);
    state_.Bind("state", "robot/state", "driver", &sink, &time);
    twist_.Bind("twist", "arm/twist", "driver", &sink, &time);
    target_.Bind("pose_target", "arm/target", "driver", &sink, &time);
  }
  const std::string& name() const override { return name_; }
  const Params& params() const override { return params_; }
  const Clock& clock() const override { return time; }
  Logger& log() override { return logger; }
  uint64_t seed() const override { return 1; }
  int64_t period_ns() const override { return 10'000'000; }
  void RequestStop(std::string) override {}
  Status StepOnce(Component& c, uint64_t index) {
    command_.Poll(time.now);
    pose_.Poll(time.now);
    StepInfo info;
    info.now_ns = time.now;
    info.index = index;
    return c.Step(info);
  }

  class Sink final : public detail::WriterEndpoint {
   public:
    Status Write(const void*) override {
      ++written;
      return Status::OK();
    }
    int written = 0;
  };
  FakeClock time;
  FakeLogger logger;
  dyad::testing::QueueReader<msg::CartesianCommand> commands;
  dyad::testing::QueueReader<geometry_msgs::msg::dds_::PoseStamped_> poses;
  Sink sink;

 protected:
  InputBase* FindInput(std::string_view port, const TypeInfo&) override {
    return port == "command" ? static_cast<InputBase*>(&command_) : &pose_;
  }
  OutputBase* FindOutput(std::string_view port, const TypeInfo&) override {
    if (port == "state") return &state_;
    return port == "twist" ? static_cast<OutputBase*>(&twist_) : &target_;
  }

 private:
  std::string name_ = "driver";
  Params params_;
  Input<msg::CartesianCommand> command_;
  Input<geometry_msgs::msg::dds_::PoseStamped_> pose_;
  Output<msg::CartesianState> state_;
  Output<geometry_msgs::msg::dds_::TwistStamped_> twist_;
  Output<geometry_msgs::msg::dds_::PoseStamped_> target_;
};

TEST(NoAllocation, Ros2CartesianStepAllocatesNothingWhileItsWarningsLast) {
  Ros2Context ctx({{"mode", std::string("twist")}, {"frame_id", std::string("base_link")},
                   {"origin", std::vector<double>{0.4, 0, 0.3}}, {"x_axis", std::vector<double>{0, -1, 0}},
                   {"y_axis", std::vector<double>{0, 0, 1}}, {"scale", 0.002},
                   {"box_min", std::vector<double>{0.2, -0.3, 0.1}}, {"box_max", std::vector<double>{0.6, 0.3, 0.5}},
                   {"orientation", std::vector<double>{0, 0, 0, 1}}, {"max_velocity", 0.25},
                   {"max_acceleration", 2.0}, {"watchdog_s", 0.5}, {"pose_timeout_s", 0.5},
                   {"require_arm", false}, {"pose_frame", std::string()}, {"pose_transform", std::vector<double>{}}});
  Ros2Cartesian driver;
  ASSERT_TRUE(driver.Configure(ctx).ok());
  ASSERT_TRUE(driver.Activate().ok());
  geometry_msgs::msg::dds_::PoseStamped_ pose;
  pose.header().frame_id("base_link");
  pose.pose().position().x(0.9);  // outside the box (x <= 0.6): warned once
  pose.pose().position().z(0.3);
  for (uint64_t k = 0; k < 300; ++k) {
    ctx.time.now = static_cast<int64_t>(k) * 10'000'000;
    ctx.commands.queue.push_back(Command(1000));  // far outside the box: clamped, warned once
    ctx.poses.queue.push_back(pose);
    const long before = dyad::testing::AllocationCount();
    ASSERT_TRUE(ctx.StepOnce(driver, k).ok());
    if (k >= 2) {
      ASSERT_EQ(dyad::testing::AllocationCount() - before, 0) << "step " << k;
    }
  }
  EXPECT_EQ(ctx.logger.lines.size(), 2u);  // the clamp and the pose outside the box, once each
  EXPECT_EQ(ctx.sink.written, 600);         // a twist and a state per step
}

}  // namespace
}  // namespace dyad::cartesian
