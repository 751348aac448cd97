// ROS 2's wire conventions (dyad/ros2_names.hpp): names each way, the naming rules, QoS profiles.
#include "dyad/ros2_names.hpp"

#include <gtest/gtest.h>

namespace dyad {
namespace {

TEST(Ros2Names, TopicsMapOntoRtAndBack) {
  EXPECT_EQ(Ros2DdsTopic("/servo_node/delta_twist_cmds"), "rt/servo_node/delta_twist_cmds");
  EXPECT_EQ(Ros2NameOfDdsTopic("rt/servo_node/delta_twist_cmds"), "/servo_node/delta_twist_cmds");
  EXPECT_EQ(Ros2NameOfDdsTopic("robot/state"), "");
  EXPECT_EQ(Ros2NameOfDdsTopic("rq/add_two_intsRequest"), "");  // a service's, not a topic
  EXPECT_EQ(Ros2NameOfDdsTopic("rt/"), "");
}

TEST(Ros2Names, TypesByTheirRos2Names) {
  EXPECT_EQ(Ros2TypeOfDdsType("geometry_msgs::msg::dds_::TwistStamped_"), "geometry_msgs/msg/TwistStamped");
  EXPECT_EQ(Ros2TypeOfDdsType("dyad::msg::CartesianState#0123456789abcdef"), "");
  EXPECT_EQ(Ros2TypeOfDdsType("geometry_msgs::msg::dds_::Twist"), "");  // no trailing '_'
  EXPECT_EQ(Ros2TypeOfDdsType("a::b::msg::dds_::T_"), "");
  EXPECT_EQ(Ros2TypeOfDdsType("::msg::dds_::T_"), "");
}

TEST(Ros2Names, EveryValidNameIsAcceptedAndEachRuleIsNamed) {
  for (const char* ok : {"/a", "/servo_node/delta_twist_cmds", "/arm_1/pose", "/A/b_c/D9"})
    EXPECT_EQ(Ros2TopicNameProblem(ok), "") << ok;
  const std::pair<const char*, const char*> bad[] = {
      {"", "empty"},          {"arm/pose", "fully qualified"}, {"/", "root namespace"},
      {"/arm/", "end with '/'"}, {"/a//b", "repeated '/'"},   {"/a__b", "repeated '_'"},
      {"/2d", "digit ('2d')"}, {"/~/x", "'~'"},               {"/{ns}/x", "substitutions"},
      {"/a b", "not ' '"}};
  for (const auto& [name, rule] : bad)
    EXPECT_NE(Ros2TopicNameProblem(name).find(rule), std::string::npos) << name << ": " << Ros2TopicNameProblem(name);
  EXPECT_NE(Ros2TopicNameProblem("/" + std::string(253, 'a')).find("too long"), std::string::npos);
  EXPECT_EQ(Ros2TopicNameProblem("/" + std::string(252, 'a')), "");  // rt + 253 = 255
}

TEST(Ros2Names, QosProfilesAreRmwsOwn) {
  Ros2Qos q;
  ASSERT_TRUE(Ros2QosProfile("default", &q));
  EXPECT_TRUE(q.reliable);
  EXPECT_EQ(q.depth, 10);
  ASSERT_TRUE(Ros2QosProfile("sensor_data", &q));
  EXPECT_FALSE(q.reliable);
  EXPECT_EQ(q.depth, 5);
  EXPECT_FALSE(Ros2QosProfile("fast", &q));
  for (const auto& name : Ros2QosProfiles()) EXPECT_TRUE(Ros2QosProfile(name, &q)) << name;
}

}  // namespace
}  // namespace dyad
