// Process-level tests of the drivers: real `dyad run` processes, and dyad_fake_controller on
// loopback for udp_cartesian (lost, late, out-of-order and malformed packets).
#include <gtest/gtest.h>

#include "dyad/testing/dds_domain.hpp"

#include "dyad/testing/child_process.hpp"

#include "udp_auth.hpp"
#include "udp_socket.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace fs = std::filesystem;

namespace {

std::string Read(const fs::path& p) { return dyad::testing::ReadFile(p); }

using Child = dyad::testing::ChildProcess;

struct State {
  int64_t stamp;
  double x, y, vx, vy;
  int stopped;
};

std::vector<State> ReadStates(const fs::path& file) {
  std::istringstream in(Read(file));
  std::vector<State> out;
  State s{};
  while (in >> s.stamp >> s.x >> s.y >> s.vx >> s.vy >> s.stopped) out.push_back(s);
  return out;
}

class DriverProcessTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("dyad_driver_test_" + std::to_string(getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    domain_ = dyad::testing::DomainForThisProcess();
    // A port of its own per test process (and per test: the counter), so parallel runs don't collide.
    static int counter = 0;
    port_ = 40000 + static_cast<int>(getpid() % 5000) * 4 + (counter++ % 4);
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  // The driver config with this test's domain and a state log appended.
  // configs/drivers/NAME, run here: virtual.yaml on this test's domain with a state log into
  // `log`, and udp.yaml as it is (it extends virtual.yaml).
  fs::path Graph(const std::string& name, const fs::path& log) {
    std::ofstream(dir_ / "virtual.yaml") << "domain_id: " << domain_ << "\n"
                                         << Read(fs::path(DYAD_CONFIG_DIR) / "drivers/virtual.yaml")
                                         << "  log: {type: test_state_log, trigger: state, params: {file: " << log.string()
                                         << "}, inputs: {state: robot/state}}\n";
    if (name != "virtual.yaml")
      fs::copy_file(fs::path(DYAD_CONFIG_DIR) / "drivers" / name, dir_ / name, fs::copy_options::overwrite_existing);
    return dir_ / name;
  }
  std::vector<std::string> Dyad(std::vector<std::string> args) {
    args.insert(args.begin(), DYAD_EXE);
    args.push_back("--plugins");
    args.push_back(DYAD_CARTESIAN_TEST_PLUGIN);
    return args;
  }
  Child FakeController(std::vector<std::string> extra) {
    std::vector<std::string> args{DYAD_FAKE_CONTROLLER, "--port", std::to_string(port_), "--idle-exit", "60"};
    args.insert(args.end(), extra.begin(), extra.end());
    return Child(args, dir_, "fake");
  }
  std::string PortSet() { return "driver.controller_port=" + std::to_string(port_); }

  fs::path dir_;
  int domain_ = 1, port_ = 40000;
};

const std::string kVirtualLine = "    type: virtual_cartesian\n";

// udp.yaml is virtual.yaml with only the driver's type changed, and says nothing else.
TEST_F(DriverProcessTest, UdpConfigExtendsVirtualAndChangesOnlyTheDriversType) {
  std::istringstream u(Read(fs::path(DYAD_CONFIG_DIR) / "drivers/udp.yaml"));
  std::string keys;
  for (std::string line; std::getline(u, line);)
    if (!line.empty() && line[0] != '#') keys += line + "\n";
  EXPECT_EQ(keys, "extends: virtual.yaml\ncomponents:\n  driver: {type: udp_cartesian}\n");
  EXPECT_NE(Read(fs::path(DYAD_CONFIG_DIR) / "drivers/virtual.yaml").find(kVirtualLine), std::string::npos);
}

// The same graph, once with each driver: the robot's states are published every step, follow the
// pattern (reached within each step), and are bit-identical between the virtual robot and the
// fake controller (both run VirtualRobot on the runtime clock's stamps).
TEST_F(DriverProcessTest, SwappingTheDriverByTypeGivesTheSameRobotStates) {
  const fs::path vlog = dir_ / "virtual.txt", ulog = dir_ / "udp.txt";
  Child v(Dyad({"run", Graph("virtual.yaml", vlog).string(), "--steps", "100", "--quiet"}), dir_, "virtual");
  ASSERT_EQ(v.Wait(60), 0) << v.err();
  const fs::path ug = Graph("udp.yaml", ulog);

  Child fake = FakeController({});
  ASSERT_TRUE(fake.WaitForOutput("listening", 10)) << fake.err();
  // Port: this test's own; reply wait: generous, as a 2-core machine under a parallel ctest can be slow.
  Child u(Dyad({"run", ug.string(), "--steps", "100", "--quiet", "--set", PortSet(), "--set", "driver.reply_wait_ms=1000"}),
          dir_, "udp");
  ASSERT_EQ(u.Wait(120), 0) << u.err();
  fake.Signal(SIGTERM);
  EXPECT_EQ(fake.Wait(10), 0);

  const auto vs = ReadStates(vlog), us = ReadStates(ulog);
  ASSERT_EQ(vs.size(), 100u);
  ASSERT_EQ(us.size(), 100u);
  EXPECT_EQ(Read(vlog), Read(ulog));
  // The figure eight of radius 30 (period 8 s): 10 Hz commands are reached within their step.
  for (size_t k = 0; k < vs.size(); ++k) {
    const double phase = 2 * M_PI * (k * 0.1) / 8;
    EXPECT_NEAR(vs[k].x, 30 * std::cos(phase), 1e-9) << k;
    EXPECT_NEAR(vs[k].y, 15 * std::sin(2 * phase), 1e-9) << k;
    EXPECT_EQ(vs[k].stamp, static_cast<int64_t>(k) * 100'000'000);
    EXPECT_EQ(vs[k].stopped, 0);
  }
  EXPECT_NE(u.err().find("udp link: 100 commands sent, 100 states accepted, 0 late, 0 lost, 0 out of order, 0 malformed, 0 replies missed"),
            std::string::npos)
      << u.err();
}

// Stepped clock: command 10 is lost, the reply to 20 comes 150 ms late (after the driver's
// 100 ms wait and after the reply to 21: out of order; it arrives while the driver waits in vain
// for the reply to 30), the reply to 30 is garbage. The run goes on; exactly those three states
// are missing.
TEST_F(DriverProcessTest, UdpDriverSurvivesALostAnOutOfOrderAndAMalformedPacket) {
  const fs::path log = dir_ / "udp.txt";
  const fs::path g = Graph("udp.yaml", log);
  Child fake = FakeController({"--drop", "10", "--delay", "20:150", "--malform", "30"});
  ASSERT_TRUE(fake.WaitForOutput("listening", 10)) << fake.err();
  Child u(Dyad({"run", g.string(), "--steps", "50", "--quiet", "--set", PortSet(), "--set", "driver.reply_wait_ms=100"}),
          dir_, "udp");
  ASSERT_EQ(u.Wait(120), 0) << u.err();
  fake.Signal(SIGTERM);
  ASSERT_EQ(fake.Wait(10), 0);
  EXPECT_NE(fake.out().find("dropped 1, delayed 1, malformed replies 1"), std::string::npos) << fake.out();

  const auto states = ReadStates(log);
  ASSERT_EQ(states.size(), 47u) << u.err();
  for (const State& s : states) {
    const int64_t step = s.stamp / 100'000'000;  // command k (1-based) is sent at step k-1
    EXPECT_NE(step, 9);
    EXPECT_NE(step, 19);
    EXPECT_NE(step, 29);
  }
  // The state after the lost command: the robot still reaches command 11 (200 ms to get there).
  EXPECT_NE(u.err().find("malformed packet from the controller (bad magic, 80 bytes)"), std::string::npos) << u.err();
  EXPECT_NE(u.err().find("udp link: 50 commands sent, 47 states accepted, 0 late, 2 lost, 1 out of order, 1 malformed, 3 replies missed"),
            std::string::npos)
      << u.err();
}

// Wall clock, 10 Hz: the reply to command 5 is 70 ms late, after the driver's 40 ms wait; it is
// taken (and published, before the next reply) at the next step.
TEST_F(DriverProcessTest, UdpDriverPublishesALateReplyAtTheNextStep) {
  const fs::path log = dir_ / "udp.txt";
  const fs::path g = Graph("udp.yaml", log);
  Child fake = FakeController({"--delay", "5:70"});
  ASSERT_TRUE(fake.WaitForOutput("listening", 10)) << fake.err();
  Child u(Dyad({"run", g.string(), "--duration", "2.05", "--quiet", "--set", "clock=wall", "--set", PortSet(), "--set",
                "driver.reply_wait_ms=40"}),
          dir_, "udp");
  ASSERT_EQ(u.Wait(30), 0) << u.err();
  fake.Signal(SIGTERM);
  ASSERT_EQ(fake.Wait(10), 0);
  const auto states = ReadStates(log);
  ASSERT_GE(states.size(), 15u) << u.err();
  // Every command's state arrived, in order.
  for (size_t k = 1; k < states.size(); ++k) EXPECT_GT(states[k].stamp, states[k - 1].stamp);
  EXPECT_NE(u.err().find(" 1 late, 0 lost, 0 out of order, 0 malformed, 1 replies missed"), std::string::npos) << u.err();
}

// A driver started again against a controller that kept running: its sequence numbers restart
// at 1 in a new session, which the controller follows at once.
TEST_F(DriverProcessTest, UdpDriverRunTwiceAgainstOneControllerStartsANewSessionEachTime) {
  Child fake = FakeController({});
  ASSERT_TRUE(fake.WaitForOutput("listening", 10)) << fake.err();
  for (int run = 0; run < 2; ++run) {
    const fs::path log = dir_ / ("udp" + std::to_string(run) + ".txt");
    const fs::path g = Graph("udp.yaml", log);
    Child u(Dyad({"run", g.string(), "--steps", "30", "--quiet", "--set", PortSet(), "--set", "driver.reply_wait_ms=1000"}),
            dir_, "udp" + std::to_string(run));
    ASSERT_EQ(u.Wait(60), 0) << u.err();
    EXPECT_EQ(ReadStates(log).size(), 30u) << run;
  }
  fake.Signal(SIGTERM);
  ASSERT_EQ(fake.Wait(10), 0);
  EXPECT_NE(fake.out().find("commands received 60, driver sessions 2, last applied sequence 30"), std::string::npos)
      << fake.out();
}

TEST_F(DriverProcessTest, UdpDriverEndsTheRunWhenTheControllerIsSilent) {
  const fs::path log = dir_ / "udp.txt";
  const fs::path g = Graph("udp.yaml", log);
  Child u(Dyad({"run", g.string(), "--steps", "100", "--quiet", "--set", PortSet()}), dir_, "udp");  // no controller
  const int rc = u.Wait(60);
  EXPECT_NE(rc, 0);
  EXPECT_NE(rc, -1);
  EXPECT_NE(u.err().find("controller 127.0.0.1:" + std::to_string(port_) + ": no state for 600 ms after a command"),
            std::string::npos)
      << u.err();
}

// virtual_cartesian stepped periodically (20 Hz) while commands (10 Hz, 3 units per step =
// 30 units/s, above the 20 units/s speed limit: the robot never catches up, so it moves all the
// time) stop after 1 s: the watchdog
// (0.3 s) stops the robot, under both clocks.
TEST_F(DriverProcessTest, VirtualDriverWatchdogStopsTheRobotWhenCommandsStop) {
  for (const std::string clock : {"stepped", "wall"}) {
    SCOPED_TRACE(clock);
    const fs::path log = dir_ / (clock + ".txt");
    const fs::path g = dir_ / (clock + ".yaml");
    std::ofstream(g) << "graph: wd\nclock: " << clock << "\ndomain_id: " << domain_ << "\ncomponents:\n"
                     << "  cmd: {type: test_command, rate_hz: 10, params: {speed: 3, silent_from: 10}, outputs: {out: robot/command}}\n"
                     << "  driver: {type: virtual_cartesian, rate_hz: 20, params: {watchdog_s: 0.3, max_velocity: 20, initial_position: [0, 0]}, "
                        "inputs: {command: robot/command}, outputs: {state: robot/state}}\n"
                     << "  log: {type: test_state_log, trigger: state, params: {file: " << log.string()
                     << "}, inputs: {state: robot/state}}\n";
    Child c(Dyad(clock == "wall" ? std::vector<std::string>{"run", g.string(), "--duration", "2.2", "--quiet"}
                                 : std::vector<std::string>{"run", g.string(), "--steps", "40", "--quiet"}),
            dir_, clock);
    ASSERT_EQ(c.Wait(60), 0) << c.err();
    const auto states = ReadStates(log);
    ASSERT_GE(states.size(), 30u);
    const int64_t t0 = states.front().stamp;
    double moving_x = 0;
    for (const State& s : states) {
      const double t = (s.stamp - t0) * 1e-9;
      if (t > 0.2 && t < 0.9) {  // commands flowing: moving, not stopped
        EXPECT_EQ(s.stopped, 0) << t;
        EXPECT_GT(s.vx, 5) << t;
      }
      if (t < 1.0) moving_x = s.x;
      if (t > 1.5) {  // last command at 0.9 s, watchdog 0.3 s, braking within one step
        EXPECT_EQ(s.stopped, 1) << t;
        EXPECT_EQ(s.vx, 0) << t;
        EXPECT_GE(s.x, moving_x) << t;
        EXPECT_LE(s.x, 27 + 1e-9) << t;  // never past the last command (9 * 3)
      }
    }
    EXPECT_NE(c.err().find("watchdog: no command for more than the watchdog timeout: stopping"), std::string::npos) << c.err();
  }
}

// The mixer and the virtual driver together, stepped: blend while engaged, 5 units per step,
// hold when the human goes silent; the driver reaches every command within its step. The mixer
// triggered by `robot` (the demo) and the mixer at rate_hz 10 (after the robot in graph order)
// publish the same commands.
TEST_F(DriverProcessTest, MixerBlendsSaturatesAndHoldsWhenTheHumanGoesSilent) {
  std::string command_files[2];
  for (int periodic = 0; periodic < 2; ++periodic) {
    SCOPED_TRACE(periodic ? "mixer periodic" : "mixer triggered by robot");
    const std::string tag = periodic ? "periodic" : "triggered";
    const fs::path clog = dir_ / (tag + "_commands.txt"), slog = dir_ / (tag + "_states.txt");
    const fs::path g = dir_ / (tag + ".yaml");
    std::ofstream(g) << "graph: mix\nclock: stepped\ndomain_id: " << domain_ << "\ncomponents:\n"
                     << "  human: {type: test_human, rate_hz: 10, params: {position: [20, 0], engaged_from: 10, "
                        "engaged_to: 30, silent_from: 40}, outputs: {out: human/input}}\n"
                     << "  robot: {type: test_intention, rate_hz: 10, params: {start: [0, 0], speed: 0}, outputs: {out: robot/intention}}\n"
                     << "  mixer: {type: compliance_mixer, " << (periodic ? "rate_hz: 10" : "trigger: robot")
                     << ", params: {stale_timeout_s: 0.25}, "
                        "inputs: {human: human/input, robot: robot/intention, state: robot/state}, outputs: {command: robot/command}}\n"
                     << "  driver: {type: virtual_cartesian, trigger: command, inputs: {command: robot/command}, outputs: {state: robot/state}}\n"
                     << "  clog: {type: test_command_log, trigger: command, params: {file: " << clog.string()
                     << "}, inputs: {command: robot/command}}\n"
                     << "  slog: {type: test_state_log, trigger: state, params: {file: " << slog.string()
                     << "}, inputs: {state: robot/state}}\n";
    Child c(Dyad({"run", g.string(), "--steps", "60", "--quiet"}), dir_, tag);
    ASSERT_EQ(c.Wait(60), 0) << c.err();
    command_files[periodic] = Read(clog);
    std::istringstream in(command_files[periodic]);
    std::vector<std::array<double, 4>> cmds;  // stamp x y hold
    std::array<double, 4> r{};
    while (in >> r[0] >> r[1] >> r[2] >> r[3]) cmds.push_back(r);
    ASSERT_EQ(cmds.size(), 60u);
    EXPECT_EQ(cmds[9][1], 0);  // disengaged: the robot's intention (0, 0)
    // Engaged from step 10: target 0.9*20 + 0.1*0 = 18, reached in 5-unit steps: 5, 10, 15, 18.
    EXPECT_DOUBLE_EQ(cmds[10][1], 5);
    EXPECT_DOUBLE_EQ(cmds[11][1], 10);
    EXPECT_DOUBLE_EQ(cmds[12][1], 15);
    EXPECT_DOUBLE_EQ(cmds[13][1], 18);
    EXPECT_DOUBLE_EQ(cmds[29][1], 18);
    EXPECT_DOUBLE_EQ(cmds[30][1], 13);  // released: back towards 0, 5 per step
    EXPECT_DOUBLE_EQ(cmds[33][1], 0);
    // Human's last sample at step 39 (t = 3.9 s); stale after 0.25 s: from step 42 (4.2 s) on, hold.
    EXPECT_EQ(cmds[41][3], 0);
    EXPECT_EQ(cmds[42][3], 1);
    EXPECT_EQ(cmds[59][3], 1);
    EXPECT_DOUBLE_EQ(cmds[42][1], cmds[41][1]);
    EXPECT_NE(c.err().find("input 'human' stale (no sample for more than 250 ms): holding the last command"), std::string::npos)
        << c.err();
    EXPECT_EQ(cmds[0][3], 1);  // waiting for the arm's first state: hold
    EXPECT_EQ(cmds[1][3], 0);
    EXPECT_NE(c.err().find("60 commands published, 19 held, 6 saturated"), std::string::npos) << c.err();
    // The driver followed every command within its step.
    const auto states = ReadStates(slog);
    ASSERT_EQ(states.size(), 60u);
    for (size_t k = 0; k < 60; ++k) EXPECT_NEAR(states[k].x, cmds[k][1], 1e-9) << k;
  }
  EXPECT_EQ(command_files[0], command_files[1]);
}

// The arm at rest at 0, the robot's intention at 1000 from the first step. The mixer's first
// command used to be 1000 (no state yet, and a driver triggered by commands reports only after
// one): now it holds until the arm reports, then moves 5 per step from where the arm is. The
// same with each driver (the fake controller starts its robot at 0 too).
TEST_F(DriverProcessTest, TheFirstCommandStartsWhereTheArmIs) {
  for (const std::string driver : {"virtual_cartesian", "udp_cartesian"}) {
    SCOPED_TRACE(driver);
    const fs::path clog = dir_ / (driver + "_commands.txt"), slog = dir_ / (driver + "_states.txt");
    const fs::path g = dir_ / (driver + ".yaml");
    std::ofstream(g) << "graph: first\nclock: stepped\ndomain_id: " << domain_ << "\ncomponents:\n"
                     << "  human: {type: test_human, rate_hz: 10, outputs: {out: human/input}}\n"
                     << "  robot: {type: test_intention, rate_hz: 10, params: {start: [1000, 0], speed: 0}, outputs: {out: robot/intention}}\n"
                     << "  mixer: {type: compliance_mixer, trigger: robot, inputs: {human: human/input, robot: robot/intention, "
                        "state: robot/state}, outputs: {command: robot/command}}\n"
                     << "  driver: {type: " << driver << ", trigger: command, params: "
                     << (driver == "virtual_cartesian" ? "{initial_position: [0, 0]}"
                                                       : "{controller_port: " + std::to_string(port_) + ", reply_wait_ms: 1000}")
                     << ", inputs: {command: robot/command}, outputs: {state: robot/state}}\n"
                     << "  clog: {type: test_command_log, trigger: command, params: {file: " << clog.string()
                     << "}, inputs: {command: robot/command}}\n"
                     << "  slog: {type: test_state_log, trigger: state, params: {file: " << slog.string()
                     << "}, inputs: {state: robot/state}}\n";
    std::optional<Child> fake;
    if (driver == "udp_cartesian") {
      fake.emplace(std::vector<std::string>{DYAD_FAKE_CONTROLLER, "--port", std::to_string(port_), "--idle-exit", "60",
                                            "--initial", "0,0"},
                   dir_, "fake");
      ASSERT_TRUE(fake->WaitForOutput("listening", 10)) << fake->err();
    }
    Child c(Dyad({"run", g.string(), "--steps", "10", "--quiet"}), dir_, driver);
    ASSERT_EQ(c.Wait(60), 0) << c.err();
    if (fake) {
      fake->Signal(SIGTERM);
      EXPECT_EQ(fake->Wait(10), 0);
    }
    std::istringstream in(Read(clog));
    std::vector<std::array<double, 4>> cmds;  // stamp x y hold
    std::array<double, 4> r{};
    while (in >> r[0] >> r[1] >> r[2] >> r[3]) cmds.push_back(r);
    ASSERT_EQ(cmds.size(), 10u);
    EXPECT_EQ(cmds[0][3], 1) << "the first command must hold: the arm's position is not known yet";
    EXPECT_EQ(cmds[0][1], 0) << "a hold carries the position to hold (none known yet: the origin), never the "
                                "intention (1000)";
    const auto states = ReadStates(slog);
    ASSERT_EQ(states.size(), 10u);
    EXPECT_EQ(states[0].x, 0);  // the hold did not move the arm
    for (size_t k = 1; k < 10; ++k) {
      EXPECT_EQ(cmds[k][3], 0) << k;
      EXPECT_NEAR(cmds[k][1], 5.0 * k, 1e-9) << k;  // 5 units per step from the arm at 0
      EXPECT_LE(states[k].x, 5.0 * k + 1e-9) << k;
    }
  }
}

// The command contract, driver by driver: a hold is "stay where you are", never a goal. Five
// holds at (50, 40), far from the arm, then motion commands from x = 5 (max_step from the arm).
// Neither driver has a start position (the fake controller runs without --initial): before, each
// put its robot at the first hold's x, y, so the arm "was" at (50, 40) before any motion command;
// now it stays at the centre of its box until the first motion command, which moves it 5 units.
TEST_F(DriverProcessTest, NoDriverMovesOnAHold) {
  for (const std::string driver : {"virtual_cartesian", "udp_cartesian"}) {
    SCOPED_TRACE(driver);
    const fs::path slog = dir_ / (driver + "_states.txt");
    const fs::path g = dir_ / (driver + "_holds.yaml");
    std::ofstream(g) << "graph: holds\nclock: stepped\ndomain_id: " << domain_ << "\ncomponents:\n"
                     << "  script: {type: test_command, rate_hz: 10, params: {speed: 1, hold_until: 5, hold_at: [50, 40]}, "
                        "outputs: {out: robot/command}}\n"
                     << "  driver: {type: " << driver << ", trigger: command, params: "
                     << (driver == "virtual_cartesian" ? "{}"
                                                       : "{controller_port: " + std::to_string(port_) + ", reply_wait_ms: 1000}")
                     << ", inputs: {command: robot/command}, outputs: {state: robot/state}}\n"
                     << "  slog: {type: test_state_log, trigger: state, params: {file: " << slog.string()
                     << "}, inputs: {state: robot/state}}\n";
    std::optional<Child> fake;
    if (driver == "udp_cartesian") {
      fake.emplace(std::vector<std::string>{DYAD_FAKE_CONTROLLER, "--port", std::to_string(port_), "--idle-exit", "60"},
                   dir_, "fake");
      ASSERT_TRUE(fake->WaitForOutput("listening", 10)) << fake->err();
    }
    Child c(Dyad({"run", g.string(), "--steps", "8", "--quiet"}), dir_, driver);
    ASSERT_EQ(c.Wait(60), 0) << c.err();
    if (fake) {
      fake->Signal(SIGTERM);
      EXPECT_EQ(fake->Wait(10), 0);
    }
    const auto states = ReadStates(slog);
    ASSERT_EQ(states.size(), 8u);
    for (size_t k = 0; k < 5; ++k) {  // the holds: at rest where it is, not at (50, 40)
      EXPECT_EQ(states[k].x, 0) << k;
      EXPECT_EQ(states[k].y, 0) << k;
      EXPECT_EQ(states[k].vx, 0) << k;
      EXPECT_EQ(states[k].stopped, 0) << k;  // a hold feeds the watchdog
    }
    // The first motion command (x = 5): the arm moves at most max_step (5) from where it was.
    EXPECT_LE(std::hypot(states[5].x, states[5].y), 5 + 1e-9);
    EXPECT_NEAR(states[5].x, 5, 1e-9);
  }
}

// A lost arm holds the experiment, end to end: the arm reports stopped for its steps 10..19 (1 s)
// while the intention stays far away. Before, the mixer went on: 10 more motion commands of 5,
// and the arm came back to a goal 50 units on, without a word in the summary. Now: holds at the
// last motion command while it is lost, the first motion after it 5 from where the arm is, the
// outage in the log, the summary and `dyad bag info`.
TEST_F(DriverProcessTest, ALostArmHoldsTheMixerAndIsSaid) {
  const fs::path clog = dir_ / "commands.txt", bag = dir_ / "run.mcap";
  const fs::path g = dir_ / "lost.yaml";
  std::ofstream(g) << "graph: lost\nclock: stepped\ndomain_id: " << domain_ << "\ncomponents:\n"
                   << "  human: {type: test_human, rate_hz: 10, outputs: {out: human/input}}\n"
                   << "  robot: {type: test_intention, rate_hz: 10, params: {start: [1000, 0], speed: 0}, outputs: {out: robot/intention}}\n"
                   << "  mixer: {type: compliance_mixer, trigger: robot, inputs: {human: human/input, robot: robot/intention, "
                      "state: robot/state}, outputs: {command: robot/command}}\n"
                   << "  arm: {type: test_arm, trigger: command, params: {stopped_from: 10, stopped_to: 20}, "
                      "inputs: {command: robot/command}, outputs: {state: robot/state}}\n"
                   << "  clog: {type: test_command_log, trigger: command, params: {file: " << clog.string()
                   << "}, inputs: {command: robot/command}}\n"
                   << "  rec: {type: recorder, rate_hz: 1, params: {file: " << bag.string() << "}}\n";
  Child c(Dyad({"run", g.string(), "--steps", "30"}), dir_, "lost");
  ASSERT_EQ(c.Wait(60), 0) << c.err();
  std::istringstream in(Read(clog));
  std::vector<std::array<double, 4>> cmds;  // stamp x y hold
  std::array<double, 4> r{};
  while (in >> r[0] >> r[1] >> r[2] >> r[3]) cmds.push_back(r);
  ASSERT_EQ(cmds.size(), 30u);
  EXPECT_EQ(cmds[0][3], 1);  // waiting for the arm's first state
  for (size_t k = 1; k <= 10; ++k) EXPECT_DOUBLE_EQ(cmds[k][1], 5.0 * static_cast<double>(k)) << k;
  // The arm's answer to command 10 says stopped (it stayed at 45): commands 11..20 hold at 50.
  for (size_t k = 11; k <= 20; ++k) {
    EXPECT_EQ(cmds[k][3], 1) << k;
    EXPECT_DOUBLE_EQ(cmds[k][1], 50) << k;
  }
  EXPECT_EQ(cmds[21][3], 0);
  EXPECT_DOUBLE_EQ(cmds[21][1], 50);  // back at 45: 45 + max_step
  EXPECT_DOUBLE_EQ(cmds[22][1], 55);
  EXPECT_NE(c.err().find("arm lost (its driver reports stopped): holding at the last command (50, 0) until it is back"),
            std::string::npos)
      << c.err();
  EXPECT_NE(c.err().find("arm back after 1.0 s"), std::string::npos) << c.err();
  EXPECT_NE(c.err().find("30 commands published, 11 held, 19 saturated; arm lost 1 time, 1.0 s; 10 holds sent while "
                         "lost; 1 holds sent waiting for the arm's first state"),
            std::string::npos)
      << c.err();
  Child info({DYAD_EXE, "bag", "info", bag.string()}, dir_, "info");
  ASSERT_EQ(info.Wait(30), 0) << info.err();
  // From the recorded robot state (dyad/health is a graph topic, and so recorded, only in graphs of
  // several wall-clock processes; dyad analyze prints the same section in its report).
  EXPECT_NE(info.out().find("arm:         robot/state: stopped 1 time, 1.0 s (the driver could not move the arm; "
                            "the mixer holds meanwhile)\n  +1.0 s  for 1.0 s\n"),
            std::string::npos)
      << info.out();
}

// Without the state, the mixer cannot know where the arm is: it says so.
TEST_F(DriverProcessTest, MixerWithoutStateWarnsThatItsFirstCommandIsNotLimited) {
  const fs::path g = dir_ / "nostate.yaml";
  std::ofstream(g) << "graph: nostate\nclock: stepped\ndomain_id: " << domain_ << "\ncomponents:\n"
                   << "  human: {type: test_human, rate_hz: 10, outputs: {out: h}}\n"
                   << "  robot: {type: test_intention, rate_hz: 10, outputs: {out: r}}\n"
                   << "  mixer: {type: compliance_mixer, trigger: robot, inputs: {human: h, robot: r}, outputs: {command: c}}\n";
  Child c(Dyad({"run", g.string(), "--steps", "3"}), dir_, "nostate");
  EXPECT_EQ(c.Wait(30), 0) << c.err();
  EXPECT_NE(c.err().find("input 'state' is not bound: the first command cannot start from where the arm is"),
            std::string::npos)
      << c.err();
}

// A private key file of 32 random-looking bytes in the test's folder.
std::string WriteKey(const fs::path& dir, char fill = 'k') {
  const fs::path key = dir / (std::string("key_") + fill);
  std::ofstream(key) << std::string(32, fill);
  fs::permissions(key, fs::perms::owner_read | fs::perms::owner_write);
  return key.string();
}

// Protocol v2 end to end: the same robot states as the virtual driver, nothing rejected.
TEST_F(DriverProcessTest, UdpProtocolV2GivesTheSameRobotStates) {
  const fs::path vlog = dir_ / "virtual.txt", ulog = dir_ / "udp.txt";
  Child v(Dyad({"run", Graph("virtual.yaml", vlog).string(), "--steps", "100", "--quiet"}), dir_, "virtual");
  ASSERT_EQ(v.Wait(60), 0) << v.err();
  const fs::path ug = Graph("udp.yaml", ulog);
  const std::string key = WriteKey(dir_);
  Child fake = FakeController({"--key-file", key});
  ASSERT_TRUE(fake.WaitForOutput("listening", 10)) << fake.err();
  Child u(Dyad({"run", ug.string(), "--steps", "100", "--quiet", "--set", PortSet(), "--set", "driver.reply_wait_ms=1000",
                "--set", "driver.key_file=" + key}),
          dir_, "udp");
  ASSERT_EQ(u.Wait(120), 0) << u.err();
  fake.Signal(SIGTERM);
  EXPECT_EQ(fake.Wait(10), 0);
  EXPECT_EQ(Read(vlog), Read(ulog));
  EXPECT_EQ(ReadStates(ulog).size(), 100u);
  EXPECT_NE(u.err().find("udp link: 100 commands sent, 100 states accepted, 0 late, 0 lost"), std::string::npos) << u.err();
  EXPECT_NE(u.err().find("0 rejected (protocol v2)"), std::string::npos) << u.err();
  EXPECT_EQ(u.err().find("not authenticated"), std::string::npos) << u.err();
  EXPECT_NE(fake.out().find("rejected 0"), std::string::npos) << fake.out();
}

// The test plays the driver, then the attacker, against a v2 controller: only commands with the
// key, of the welcomed session and newer than the last applied are answered (applied).
TEST_F(DriverProcessTest, AV2ControllerRejectsSpoofedModifiedAndReplayedCommands) {
  namespace udp = dyad::cartesian::udp;
  const std::string key(32, 'k');
  Child fake = FakeController({"--key-file", WriteKey(dir_)});
  ASSERT_TRUE(fake.WaitForOutput("listening", 10)) << fake.err();
  auto sock = dyad::cartesian::UdpSocket::Open(0);
  ASSERT_TRUE(sock.ok());
  auto to = dyad::cartesian::UdpSocket::Resolve("127.0.0.1", static_cast<uint16_t>(port_));
  ASSERT_TRUE(to.ok());
  std::array<uint8_t, udp::kMaxPacket> tx{}, rx{};
  // The reply to what was just sent, if any within 300 ms: its kind and, for a state, its ack.
  auto reply = [&](uint32_t* ack_or_session) -> uint8_t {
    if (!sock->WaitReadable(300)) return 0;
    sockaddr_in from{};
    const long n = sock->Receive(rx.data(), rx.size(), &from);
    if (n <= 0) return 0;
    const uint8_t kind = udp::SignedKind(rx.data(), static_cast<size_t>(n));
    uint32_t peer = 0;
    if (kind == udp::kKindWelcome) {
      udp::HandshakePacket w;
      EXPECT_EQ(udp::DecodeSignedHandshake(rx.data(), static_cast<size_t>(n), kind, key, &w), udp::Decode::kOk);
      *ack_or_session = w.session;
    } else if (kind == udp::kKindState) {
      udp::StatePacket st;
      EXPECT_EQ(udp::DecodeSignedState(rx.data(), static_cast<size_t>(n), key, &st, &peer), udp::Decode::kOk);
      *ack_or_session = st.ack;
    }
    return kind;
  };
  auto command = [](uint32_t session, uint32_t seq, double x) {
    udp::CommandPacket c;
    c.session = session, c.sequence = seq, c.stamp_ns = seq * 100'000'000LL, c.x = x;
    return c;
  };
  auto send = [&](size_t n) { ASSERT_TRUE(sock->SendTo(tx.data(), n, *to).ok()); };
  uint32_t got = 0;
  const uint32_t driver = 77;
  send(udp::EncodeSigned(udp::kKindHello, udp::HandshakePacket{driver, 0}, key, tx));
  ASSERT_EQ(reply(&got), udp::kKindWelcome);
  const uint32_t controller = got;
  const size_t n = udp::EncodeSigned(command(driver, 1, 3), controller, key, tx);
  const auto first = tx;
  send(n);
  ASSERT_EQ(reply(&got), udp::kKindState);
  EXPECT_EQ(got, 1u);
  send(n);  // replayed as is
  EXPECT_EQ(reply(&got), 0);
  tx[udp::kHeader2Size + 8] ^= 0x40;  // x modified in flight
  send(n);
  EXPECT_EQ(reply(&got), 0);
  send(udp::EncodeSigned(command(driver, 2, 50), controller, std::string(32, 'x'), tx));  // spoofed: another key
  EXPECT_EQ(reply(&got), 0);
  // A new handshake (a restarted driver); then the first session's traffic is dead, even newer.
  send(udp::EncodeSigned(udp::kKindHello, udp::HandshakePacket{driver + 1, 0}, key, tx));
  ASSERT_EQ(reply(&got), udp::kKindWelcome);
  const uint32_t controller2 = got;
  send(udp::EncodeSigned(command(driver + 1, 1, 4), controller2, key, tx));
  ASSERT_EQ(reply(&got), udp::kKindState);
  tx = first;
  send(n);  // the first session's command, replayed into the new session
  EXPECT_EQ(reply(&got), 0);
  send(udp::EncodeSigned(command(driver, 5, 60), controller, key, tx));  // old pair, newer sequence
  EXPECT_EQ(reply(&got), 0);
  fake.Signal(SIGTERM);
  ASSERT_EQ(fake.Wait(10), 0);
  // Answered: 2 hellos and 2 commands; refused: the modified, spoofed and 2 old-session ones
  // (rejected) and the replay of the current session (out of order).
  EXPECT_NE(fake.out().find("driver sessions 2,"), std::string::npos) << fake.out();
  EXPECT_NE(fake.out().find("out of order 1, rejected 4"), std::string::npos) << fake.out();
}

// Three commands in a row lost (as after a controller restart): the v2 driver handshakes again
// and goes on; the controller keeps its robot (the same driver).
TEST_F(DriverProcessTest, AV2DriverHandshakesAgainAfterThreeUnansweredCommands) {
  const fs::path ulog = dir_ / "udp.txt";
  const fs::path ug = Graph("udp.yaml", ulog);
  const std::string key = WriteKey(dir_);
  Child fake = FakeController({"--key-file", key, "--drop", "10", "--drop", "11", "--drop", "12"});
  ASSERT_TRUE(fake.WaitForOutput("listening", 10)) << fake.err();
  Child u(Dyad({"run", ug.string(), "--steps", "30", "--quiet", "--set", PortSet(), "--set", "driver.reply_wait_ms=300",
                "--set", "driver.key_file=" + key}),
          dir_, "udp");
  ASSERT_EQ(u.Wait(60), 0) << u.err();
  fake.Signal(SIGTERM);
  ASSERT_EQ(fake.Wait(10), 0);
  EXPECT_NE(u.err().find("no reply to 3 commands: handshaking again"), std::string::npos) << u.err();
  EXPECT_NE(u.err().find("30 commands sent, 27 states accepted"), std::string::npos) << u.err();
  EXPECT_NE(fake.out().find("driver sessions 1,"), std::string::npos) << fake.out();
  const auto states = ReadStates(ulog);
  ASSERT_EQ(states.size(), 27u);
  EXPECT_EQ(states.back().stamp, 29 * 100'000'000LL);  // to the end of the run
}

// A driver given a key against a controller that speaks v1 only: no welcome, the run ends.
TEST_F(DriverProcessTest, AV2DriverEndsTheRunWhenTheControllerNeverWelcomesIt) {
  const fs::path ug = Graph("udp.yaml", dir_ / "udp.txt");
  Child fake = FakeController({});
  ASSERT_TRUE(fake.WaitForOutput("listening", 10)) << fake.err();
  Child u(Dyad({"run", ug.string(), "--steps", "100", "--quiet", "--set", PortSet(), "--set", "driver.timeout_s=0.5",
                "--set", "driver.key_file=" + WriteKey(dir_)}),
          dir_, "udp");
  EXPECT_NE(u.Wait(60), 0);
  EXPECT_NE(u.err().find("no welcome to our hello"), std::string::npos) << u.err();
  fake.Signal(SIGTERM);
  fake.Wait(10);
}

TEST_F(DriverProcessTest, MixerInPiModeWithoutStateIsAConfigurationError) {
  const fs::path g = dir_ / "pi.yaml";
  std::ofstream(g) << "graph: pi\nclock: stepped\ndomain_id: " << domain_ << "\ncomponents:\n"
                   << "  human: {type: test_human, rate_hz: 10, outputs: {out: h}}\n"
                   << "  robot: {type: test_intention, rate_hz: 10, outputs: {out: r}}\n"
                   << "  mixer: {type: compliance_mixer, trigger: robot, params: {mode: pi}, inputs: {human: h, robot: r}, "
                      "outputs: {command: c}}\n";
  Child c(Dyad({"run", g.string(), "--steps", "3", "--quiet"}), dir_, "pi");
  EXPECT_NE(c.Wait(30), 0);
  EXPECT_NE(c.err().find("components.mixer.params.mode = pi: needs input 'state' bound"), std::string::npos) << c.err();
}

}  // namespace

namespace dyad::cartesian {
namespace {

TEST(FakeControllerCli, HelpPrintsUsageAndBadArgumentsExitTwo) {
  const auto dir = std::filesystem::temp_directory_path();
  dyad::testing::ChildProcess help({DYAD_FAKE_CONTROLLER, "--help"}, dir, "fake_help");
  ASSERT_EQ(help.Wait(10), 0) << help.err();
  EXPECT_NE(help.out().find("--delay"), std::string::npos) << help.out();
  dyad::testing::ChildProcess bad({DYAD_FAKE_CONTROLLER, "--port", "70000"}, dir, "fake_bad");
  EXPECT_EQ(bad.Wait(10), 2);
  EXPECT_NE(bad.err().find("--port"), std::string::npos) << bad.err();
  dyad::testing::ChildProcess delay({DYAD_FAKE_CONTROLLER, "--port", "47999", "--delay", "3"}, dir, "fake_delay");
  EXPECT_EQ(delay.Wait(10), 2);
  EXPECT_NE(delay.err().find("--delay 3: wants N:MS"), std::string::npos) << delay.err();
}

}  // namespace
}  // namespace dyad::cartesian
