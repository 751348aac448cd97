// ros2_cartesian against a fake ROS 2 arm on Eclipse Cyclone DDS (dyad_ros2_fake_arm, a different
// vendor exactly as rmw_cyclonedds_cpp would be): configs/drivers/ros2_servo.yaml and
// ros2_pose.yaml run in real `dyad run` processes with a recorder; the recording, read back with
// dyad's IDL-driven decoder, shows the arm following the commands, stopping when the arm dies and
// resuming when it returns; bad arms and bad wiring are reported by name; holds far away do not
// move the arm, a run ends on a zero twist, a silent arm and poses in another frame are named.
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <thread>

#include "dyad/testing/child_process.hpp"
#include "dyad/testing/dds_domain.hpp"
#include "recording_json.hpp"

namespace fs = std::filesystem;
using dyad::testing::ChildProcess;
using nlohmann::json;

namespace {

struct Sample {
  int64_t t_ns = 0;  // log time
  json value;
};

int64_t WallNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
}

class Ros2DriverTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(::testing::TempDir()) / ("ros2_driver_" + std::to_string(getpid()) + "_" +
                                            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    domain_ = dyad::testing::DomainForThisProcess();
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  // A graph extending configs/drivers/<base> with a recorder, on this test's domain.
  std::string Graph(const std::string& base, const std::string& extra = "") {
    const fs::path g = dir_ / "graph.yaml";
    std::ofstream(g) << "extends: " << DYAD_CONFIG_DIR << "/drivers/" << base << "\ndomain_id: " << domain_
                     << "\ncomponents:\n  rec:\n    type: recorder\n    rate_hz: 10\n    params: {file: run.mcap}\n"
                     << extra;
    return g.string();
  }
  std::vector<std::string> Arm(const std::string& mode, std::vector<std::string> more = {}) {
    std::vector<std::string> a = {DYAD_ROS2_FAKE_ARM, "--mode", mode, "--domain", std::to_string(domain_)};
    a.insert(a.end(), more.begin(), more.end());
    return a;
  }
  // Every message of `topic` in the run's recording, decoded.
  std::vector<Sample> Read(const std::string& topic) {
    std::vector<Sample> out;
    for (auto& m : dyad::testing::ReadRecordingJson((dir_ / "run.mcap").string(), {topic}))
      out.push_back({m.t_ns, std::move(m.value)});
    return out;
  }
  // The arm's commands as it printed them (--verbose), one "twist ..." or "pose ..." line each.
  static std::vector<std::string> Received(const std::string& out, const std::string& kind) {
    std::vector<std::string> lines;
    std::istringstream in(out);
    for (std::string line; std::getline(in, line);)
      if (line.rfind(kind + " ", 0) == 0) lines.push_back(line);
    return lines;
  }
  // The recorder of the previous run wrote run.mcap: a fresh one for the next.
  void ForgetRecording() { fs::remove(dir_ / "run.mcap"); }
  fs::path dir_;
  int domain_ = 0;
};

// The intention far away (x = 1000: beyond the box's wall) in hold commands for 2 s, then
// motion commands at x = -20 (0.04 m along +y): the arm, as its own pose stream shows, does not
// move before the first motion command, and follows that one. The driver used to take the first
// hold as its goal and drive towards the wall.
void ExpectNoMotionBeforeTheFirstMotionCommand(const std::vector<Sample>& commands, const std::vector<Sample>& poses) {
  size_t first_motion = 0;
  while (first_motion < commands.size() && commands[first_motion].value["hold"].get<bool>()) ++first_motion;
  ASSERT_GE(first_motion, 15u) << "holds before the first motion command";
  ASSERT_LT(first_motion, commands.size()) << "no motion command";
  const int64_t moved_at = commands[first_motion].t_ns;
  ASSERT_GT(poses.size(), 200u);
  const json start = poses.front().value["pose"]["position"];
  size_t before = 0;
  for (const Sample& p : poses) {
    if (p.t_ns >= moved_at) break;
    ++before;
    for (const char* axis : {"x", "y", "z"})
      ASSERT_NEAR(p.value["pose"]["position"][axis].get<double>(), start[axis].get<double>(), 1e-9)
          << axis << " of the arm's pose " << before << ", before the first motion command";
  }
  EXPECT_GT(before, 100u);
  EXPECT_NEAR(poses.back().value["pose"]["position"]["y"].get<double>(), 0.04, 0.005) << "followed x = -20";
}

std::string HoldThenMove() {
  return "  pattern: !reset\n"
         "  holder:\n    type: test_hold_then_move\n    rate_hz: 10\n"
         "    params: {hold_at: [1000, 0], hold_steps: 20, move_to: [-20, 0]}\n"
         "    outputs: {command: robot/command}\n";
}

TEST_F(Ros2DriverTest, TwistModeHoldsFarAwayDoNotMoveTheArm) {
  ChildProcess arm(Arm("twist"), dir_, "arm");
  ASSERT_TRUE(arm.WaitForOutput("ready", 10)) << arm.err();
  ChildProcess run({DYAD_EXE, "run", Graph("ros2_servo.yaml", HoldThenMove()), "--duration", "4", "--plugins",
                    DYAD_ROS2_TEST_PLUGIN},
                   dir_, "run");
  ASSERT_EQ(run.Wait(30), 0) << run.err();
  ExpectNoMotionBeforeTheFirstMotionCommand(Read("robot/command"), Read("arm/pose"));
}

TEST_F(Ros2DriverTest, PoseModeHoldsFarAwayDoNotMoveTheArm) {
  ChildProcess arm(Arm("pose", {"--command-topic", "/target_pose"}), dir_, "arm");
  ASSERT_TRUE(arm.WaitForOutput("ready", 10)) << arm.err();
  ChildProcess run({DYAD_EXE, "run", Graph("ros2_pose.yaml", HoldThenMove()), "--duration", "4", "--plugins",
                    DYAD_ROS2_TEST_PLUGIN},
                   dir_, "run");
  ASSERT_EQ(run.Wait(30), 0) << run.err();
  ExpectNoMotionBeforeTheFirstMotionCommand(Read("robot/command"), Read("arm/pose"));
}

// The test pattern is still moving when the run ends: the last twist the arm receives is zero
// (Deactivate), so Servo does not keep going until its own timeout.
TEST_F(Ros2DriverTest, TwistModeEndsOnAZeroTwist) {
  ChildProcess arm(Arm("twist", {"--verbose"}), dir_, "arm");
  ASSERT_TRUE(arm.WaitForOutput("ready", 10)) << arm.err();
  ChildProcess run({DYAD_EXE, "run", Graph("ros2_servo.yaml"), "--duration", "3"}, dir_, "run");
  ASSERT_EQ(run.Wait(30), 0) << run.err();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  arm.Signal(SIGINT);
  ASSERT_EQ(arm.Wait(10), 0) << arm.err();
  const std::vector<std::string> twists = Received(arm.out(), "twist");
  ASSERT_GT(twists.size(), 100u);
  EXPECT_NE(twists[twists.size() - 2], "twist 0 0 0") << "the pattern was still moving";
  EXPECT_EQ(twists.back(), "twist 0 0 0");
}

// Pose mode, the same: the last target the arm receives is a position it published itself (the
// driver re-sends the measured pose), not the setpoint that ran ahead of it.
TEST_F(Ros2DriverTest, PoseModeEndsOnTheMeasuredPose) {
  const std::string log = (dir_ / "arm.csv").string();
  ChildProcess arm(Arm("pose", {"--command-topic", "/target_pose", "--verbose", "--log", log}), dir_, "arm");
  ASSERT_TRUE(arm.WaitForOutput("ready", 10)) << arm.err();
  ChildProcess run({DYAD_EXE, "run", Graph("ros2_pose.yaml"), "--duration", "3"}, dir_, "run");
  ASSERT_EQ(run.Wait(30), 0) << run.err();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  arm.Signal(SIGINT);
  ASSERT_EQ(arm.Wait(10), 0) << arm.err();
  const std::vector<std::string> targets = Received(arm.out(), "pose");
  ASSERT_GT(targets.size(), 100u);
  std::istringstream last(targets.back());
  std::string kind, x, y, z;
  last >> kind >> x >> y >> z;
  // arm.csv: t_s,cmd_x,cmd_y,cmd_z,x,y,z, every position as published (%.17g, as --verbose prints).
  std::ifstream csv(log);
  const std::string position = "," + x + "," + y + "," + z;
  bool published = false;
  for (std::string row; std::getline(csv, row);)
    published |= row.size() > position.size() && row.compare(row.size() - position.size(), position.size(), position) == 0;
  EXPECT_TRUE(published) << "the last target " << targets.back() << " is not a pose the arm reported";
}

// An arm whose pose topic never delivers: an error naming the topic, stopped states, nothing
// but zero twists; with require_arm the run fails. It used to run silently and exit 0.
TEST_F(Ros2DriverTest, AnArmThatNeverAnswersIsAnErrorAndWithRequireArmFailsTheRun) {
  ChildProcess arm(Arm("twist", {"--no-pose", "--verbose"}), dir_, "arm");
  ASSERT_TRUE(arm.WaitForOutput("ready", 10)) << arm.err();
  ChildProcess run({DYAD_EXE, "run", Graph("ros2_servo.yaml"), "--duration", "2"}, dir_, "run");
  ASSERT_EQ(run.Wait(30), 0) << run.err();
  EXPECT_NE(run.err().find("no pose from the arm on 'arm/pose' within pose_timeout_s (0.5 s) of the run's start"),
            std::string::npos)
      << run.err();
  EXPECT_NE(run.err().find("the arm was never driven"), std::string::npos) << run.err();
  const std::vector<Sample> states = Read("robot/state");
  ASSERT_GT(states.size(), 5u) << run.err();
  for (const Sample& s : states) EXPECT_TRUE(s.value["stopped"].get<bool>());
  const std::vector<std::string> twists = Received(arm.out(), "twist");
  ASSERT_GT(twists.size(), 50u);
  for (const std::string& t : twists) ASSERT_EQ(t, "twist 0 0 0");

  ForgetRecording();
  ChildProcess strict({DYAD_EXE, "run", Graph("ros2_servo.yaml"), "--duration", "2", "--set",
                       "driver.params.require_arm=true"},
                      dir_, "strict");
  EXPECT_EQ(strict.Wait(30), 1) << strict.err();
  EXPECT_NE(strict.err().find("failed: no pose from the arm on 'arm/pose' within pose_timeout_s (0.5 s) of the run's start"),
            std::string::npos)
      << strict.err();
  EXPECT_NE(strict.err().find("(require_arm)"), std::string::npos) << strict.err();
}

// Poses in 'world' while the driver works in base_link: refused, said once, stopped; with
// pose_frame and pose_transform saying how, taken (here the identity: the arm follows).
TEST_F(Ros2DriverTest, PosesInAnotherFrameAreRefusedUnlessPoseFrameSaysHow) {
  ChildProcess arm(Arm("twist", {"--frame", "world"}), dir_, "arm");
  ASSERT_TRUE(arm.WaitForOutput("ready", 10)) << arm.err();
  ChildProcess run({DYAD_EXE, "run", Graph("ros2_servo.yaml"), "--duration", "2"}, dir_, "run");
  ASSERT_EQ(run.Wait(30), 0) << run.err();
  EXPECT_NE(run.err().find("the arm reported a pose in frame 'world', not 'base_link': refused"), std::string::npos)
      << run.err();
  std::vector<Sample> states = Read("robot/state");
  ASSERT_GT(states.size(), 5u) << run.err();
  for (const Sample& s : states) EXPECT_TRUE(s.value["stopped"].get<bool>());

  ForgetRecording();
  ChildProcess taken({DYAD_EXE, "run",
                      Graph("ros2_servo.yaml",
                            "  driver:\n    params: {pose_frame: world, pose_transform: [0, 0, 0, 0, 0, 0, 1]}\n"),
                      "--duration", "2"},
                     dir_, "taken");
  ASSERT_EQ(taken.Wait(30), 0) << taken.err();
  EXPECT_EQ(taken.err().find("': refused"), std::string::npos) << taken.err();
  states = Read("robot/state");
  ASSERT_GT(states.size(), 5u) << taken.err();
  int following = 0;
  for (const Sample& s : states) following += !s.value["stopped"].get<bool>();
  EXPECT_GT(following, 10);
}

// The arm follows the test pattern through Servo-style twists; killed, the driver reports stopped
// within its pose timeout (0.5 s); restarted, it follows again.
TEST_F(Ros2DriverTest, TwistModeFollowsStopsWhenTheArmDiesAndResumes) {
  auto arm = std::make_unique<ChildProcess>(Arm("twist"), dir_, "arm1");
  ASSERT_TRUE(arm->WaitForOutput("ready", 10)) << arm->err();
  ChildProcess run({DYAD_EXE, "run", Graph("ros2_servo.yaml"), "--duration", "9"}, dir_, "run");
  std::this_thread::sleep_for(std::chrono::milliseconds(4000));
  const int64_t killed_ns = WallNs();
  arm->Signal(SIGKILL);
  arm->Wait(5);
  std::this_thread::sleep_for(std::chrono::milliseconds(2000));
  const int64_t restarted_ns = WallNs();
  arm = std::make_unique<ChildProcess>(Arm("twist"), dir_, "arm2");
  ASSERT_TRUE(arm->WaitForOutput("ready", 10)) << arm->err();
  ASSERT_EQ(run.Wait(30), 0) << run.err();

  const std::vector<Sample> states = Read("robot/state"), commands = Read("robot/command"), twists = Read("arm/twist");
  ASSERT_GT(states.size(), 300u) << run.err();
  ASSERT_GT(twists.size(), 600u);
  EXPECT_EQ(twists.front().value["header"]["frame_id"], "base_link");
  int following = 0, stopped_after_kill = 0, after_kill = 0, resumed = 0;
  double worst = 0;
  size_t c = 0;
  for (const Sample& s : states) {
    while (c + 1 < commands.size() && commands[c + 1].t_ns <= s.t_ns) ++c;
    const bool stopped = s.value["stopped"].get<bool>();
    if (s.t_ns > killed_ns - 2'000'000'000 && s.t_ns < killed_ns) {
      // Tracking a figure eight (30 units, 8 s: up to ~47 units/s) through a 0.1 s lag.
      const double dx = s.value["x"].get<double>() - commands[c].value["x"].get<double>();
      const double dy = s.value["y"].get<double>() - commands[c].value["y"].get<double>();
      worst = std::max(worst, std::hypot(dx, dy));
      following += !stopped;
    }
    if (s.t_ns > killed_ns + 800'000'000 && s.t_ns < restarted_ns) {
      ++after_kill;
      stopped_after_kill += stopped;
    }
    if (s.t_ns > restarted_ns + 1'500'000'000) resumed += !stopped;
  }
  EXPECT_GT(following, 150);
  EXPECT_LT(worst, 10.0) << "workspace units between the arm and its command";
  EXPECT_GT(after_kill, 0);
  EXPECT_EQ(stopped_after_kill, after_kill);
  EXPECT_GT(resumed, 100);
  EXPECT_NE(run.err().find("no pose from the arm"), std::string::npos) << run.err();
}

// Pose targets on a plane 10x too large for the box: every target sent and every pose of the arm
// stays inside the box; the clamp is said once.
TEST_F(Ros2DriverTest, PoseModeNeverCommandsOutsideTheBox) {
  ChildProcess arm(Arm("pose", {"--command-topic", "/target_pose"}), dir_, "arm");
  ASSERT_TRUE(arm.WaitForOutput("ready", 10)) << arm.err();
  ChildProcess run({DYAD_EXE, "run", Graph("ros2_pose.yaml"), "--duration", "5", "--set", "driver.params.scale=0.02"},
                   dir_, "run");
  ASSERT_EQ(run.Wait(30), 0) << run.err();
  const std::vector<Sample> targets = Read("arm/target"), poses = Read("arm/pose");
  ASSERT_GT(targets.size(), 300u);
  ASSERT_GT(poses.size(), 300u);
  const double lo[3] = {0.2, -0.3, 0.1}, hi[3] = {0.6, 0.3, 0.5};
  auto inside = [&](const json& p) {
    const double v[3] = {p["x"].get<double>(), p["y"].get<double>(), p["z"].get<double>()};
    for (int i = 0; i < 3; ++i)
      if (v[i] < lo[i] - 1e-9 || v[i] > hi[i] + 1e-9) return false;
    return true;
  };
  double reach = 0;
  for (const Sample& s : targets) {
    ASSERT_TRUE(inside(s.value["pose"]["position"])) << s.value.dump();
    reach = std::max(reach, std::abs(s.value["pose"]["position"]["y"].get<double>()));
  }
  for (const Sample& s : poses) ASSERT_TRUE(inside(s.value["pose"]["position"])) << s.value.dump();
  EXPECT_GT(reach, 0.25) << "the setpoint runs into the box's wall (0.3 m), at most 0.25 m/s";
  EXPECT_NE(run.err().find("outside the workspace box: clamped into it"), std::string::npos) << run.err();
}

// An arm that starts reporting NaN: said once, and the driver stops (no finite pose for its
// pose timeout) instead of steering on garbage.
TEST_F(Ros2DriverTest, NanPosesFromTheArmStopTheDriver) {
  ChildProcess arm(Arm("twist", {"--nan-after-s", "1.5"}), dir_, "arm");
  ASSERT_TRUE(arm.WaitForOutput("ready", 10)) << arm.err();
  ChildProcess run({DYAD_EXE, "run", Graph("ros2_servo.yaml"), "--duration", "4"}, dir_, "run");
  ASSERT_EQ(run.Wait(30), 0) << run.err();
  EXPECT_NE(run.err().find("NaN or infinite coordinates: ignored"), std::string::npos) << run.err();
  const std::vector<Sample> states = Read("robot/state");
  ASSERT_FALSE(states.empty());
  EXPECT_TRUE(states.back().value["stopped"].get<bool>());
  const std::vector<Sample> twists = Read("arm/twist");
  ASSERT_FALSE(twists.empty());
  EXPECT_EQ(twists.back().value["twist"]["linear"], (json{{"x", 0.0}, {"y", 0.0}, {"z", 0.0}}));
}

// A best-effort pose topic (sensor_data) against the graph's reliable reader, and a publisher of
// another type on the pose topic: each reported by topic and policy or type.
TEST_F(Ros2DriverTest, IncompatibleQosAndWrongTypesAreNamed) {
  ChildProcess arm(Arm("twist", {"--pose-qos", "sensor_data"}), dir_, "arm");
  ASSERT_TRUE(arm.WaitForOutput("ready", 10)) << arm.err();
  ChildProcess wrong({DYAD_ROS2_WIRE_PEER, "command", "--mode", "twist", "--to", "0,0,0", "--for-s", "6", "--topic",
                      "/arm/pose", "--domain", std::to_string(domain_)},
                     dir_, "wrong");
  // Up before the run: discovered before the run's participant has the topic, so the mismatch is
  // found when the topic is made (CheckDiscovered), not by the discovery callback.
  std::this_thread::sleep_for(std::chrono::seconds(1));
  ChildProcess run({DYAD_EXE, "run", Graph("ros2_servo.yaml"), "--duration", "3"}, dir_, "run");
  ASSERT_EQ(run.Wait(30), 1) << run.err();  // a run with mismatches fails, saying how many
  // The arm's best-effort writer, by its participant; not the wrong-typed one (Fast DDS matches
  // types before QoS).
  EXPECT_TRUE(std::regex_search(run.err(), std::regex("topic 'arm/pose' \\(ROS 2 topic /arm/pose\\): a writer of "
                                                      "[^\\n]* offers an incompatible reliability QoS; none of its")))
      << run.err();
  EXPECT_EQ(run.err().find("offers an incompatible", run.err().find("offers an incompatible") + 1), std::string::npos)
      << run.err();
  EXPECT_NE(run.err().find("type mismatch on topic 'arm/pose' (ROS 2 topic /arm/pose)"), std::string::npos) << run.err();
  EXPECT_NE(run.err().find("not a dyad process) uses geometry_msgs::msg::dds_::TwistStamped_"), std::string::npos) << run.err();
  EXPECT_NE(run.err().find("type/QoS mismatch(es) with peers"), std::string::npos) << run.err();
}

}  // namespace
