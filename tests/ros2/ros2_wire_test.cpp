// The ROS 2 wire check, both ways, against another vendor's DDS: a Cyclone DDS peer
// (dyad_ros2_wire_peer, built from idl/ros2 with Cyclone's idlc, as rmw_cyclonedds_cpp would be)
// and dyad's Fast DDS side, on every ROS 2 type dyad ships.
//   Cyclone -> dyad: the peer publishes one sample of each type; `dyad run` records them; the
//     recording, decoded by dyad's IDL-driven decoder, holds the values the peer says it sent.
//   dyad -> Cyclone: `dyad pub` publishes those same values (the peer's JSON, given as YAML);
//     the peer decodes them with Cyclone's own generated code and prints what it received.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "dyad/testing/child_process.hpp"
#include "dyad/testing/dds_domain.hpp"
#include "recording_json.hpp"

namespace fs = std::filesystem;
using dyad::testing::ChildProcess;
using nlohmann::json;

namespace {

// The 13 ROS 2 types, by ROS 2 name; the graph's topic for each is its name with '/' -> '_'
// minus "msg" ("geometry_msgs_TwistStamped"), the peer's ROS 2 topic /dyad_wire/<that>.
const std::vector<std::string> kTypes = {
    "builtin_interfaces/msg/Time",         "std_msgs/msg/Header",          "geometry_msgs/msg/Vector3",
    "geometry_msgs/msg/Point",             "geometry_msgs/msg/Quaternion", "geometry_msgs/msg/Pose",
    "geometry_msgs/msg/PoseStamped",       "geometry_msgs/msg/Twist",      "geometry_msgs/msg/TwistStamped",
    "sensor_msgs/msg/JointState",          "std_msgs/msg/MultiArrayDimension",
    "std_msgs/msg/MultiArrayLayout",       "std_msgs/msg/Float64MultiArray"};

std::string TopicOf(const std::string& ros2_type) {
  const std::string pkg = ros2_type.substr(0, ros2_type.find('/'));
  return pkg + "_" + ros2_type.substr(ros2_type.rfind('/') + 1);
}

class Ros2WireTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(::testing::TempDir()) / ("ros2_wire_" + std::to_string(getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    domain_ = dyad::testing::DomainForThisProcess();
    std::ofstream g(dir_ / "wire.yaml");
    g << "graph: wire\nclock: wall\ndomain_id: " << domain_ << "\ntopics:\n";
    for (const auto& t : kTypes) g << "  " << TopicOf(t) << ": {ros2: /dyad_wire/" << TopicOf(t) << ", type: " << t << "}\n";
    g << "components:\n  rec:\n    type: recorder\n    rate_hz: 10\n    params: {file: wire.mcap}\n";
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  // The JSON lines of `text` by their "type".
  static std::map<std::string, json> ByType(const std::string& text) {
    std::map<std::string, json> out;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);)
      if (!line.empty() && line[0] == '{') {
        json j = json::parse(line);
        out[j.at("type").get<std::string>()] = j.at("sample");
      }
    return out;
  }
  fs::path dir_;
  int domain_ = 0;
};

TEST_F(Ros2WireTest, CycloneSamplesDecodeInDyadAndDyadSamplesDecodeInCyclone) {
  // Cyclone -> dyad.
  ChildProcess run({DYAD_EXE, "run", (dir_ / "wire.yaml").string(), "--duration", "8"}, dir_, "run");
  ChildProcess pub({DYAD_ROS2_WIRE_PEER, "publish", "--domain", std::to_string(domain_)}, dir_, "peer_publish");
  ASSERT_EQ(pub.Wait(30), 0) << pub.err();
  ASSERT_EQ(run.Wait(30), 0) << run.err();
  const std::map<std::string, json> sent = ByType(pub.out());
  ASSERT_EQ(sent.size(), kTypes.size()) << pub.out();

  std::map<std::string, json> recorded;  // by topic
  for (const auto& m : dyad::testing::ReadRecordingJson((dir_ / "wire.mcap").string())) recorded[m.topic] = m.value;
  for (const auto& t : kTypes) {
    SCOPED_TRACE(t);
    ASSERT_TRUE(recorded.count(TopicOf(t))) << "nothing recorded on " << TopicOf(t);
    EXPECT_EQ(recorded[TopicOf(t)], sent.at(t));
  }

  // dyad -> Cyclone: the same values, published by `dyad pub`.
  ChildProcess listen({DYAD_ROS2_WIRE_PEER, "listen", "--count", std::to_string(kTypes.size()), "--domain",
                       std::to_string(domain_), "--timeout-s", "60"},
                      dir_, "peer_listen");
  ASSERT_TRUE(listen.WaitForOutput("ready", 20)) << listen.err();
  // The graph has ended: `dyad pub --graph` waits --wait seconds for its recorder (a reader the
  // graph declares, dyad/topic_readers.hpp) and then publishes to the readers it has matched, the
  // Cyclone listener. 2 s each keeps the 13 publications well inside the listener's minute (at
  // the default 5 s they took 65 s).
  for (const auto& t : kTypes) {
    ChildProcess p({DYAD_EXE, "pub", "--graph", (dir_ / "wire.yaml").string(), TopicOf(t), sent.at(t).dump(), "--wait", "2"},
                   dir_, "pub_" + TopicOf(t));
    ASSERT_EQ(p.Wait(30), 0) << t << ": " << p.err();
  }
  ASSERT_EQ(listen.Wait(30), 0) << listen.err();
  const std::map<std::string, json> heard = ByType(listen.out());
  for (const auto& t : kTypes) {
    SCOPED_TRACE(t);
    ASSERT_TRUE(heard.count(t)) << listen.out();
    EXPECT_EQ(heard.at(t), sent.at(t));
  }
}

}  // namespace
