// dyad/ros2_names.hpp — ROS 2's wire conventions for topics, so a graph topic can be a ROS 2 topic
// (docs/ros2.md) with no ROS installed.
//
// A graph declares `arm/twist: {ros2: /servo_node/delta_twist_cmds, type:
// geometry_msgs/msg/TwistStamped, qos: default}`; on the wire that is DDS topic
// "rt/servo_node/delta_twist_cmds" in the default partition (not the run's), with the type's
// plain DDS name (message_traits.hpp), plain CDR, and the QoS of the named ROS 2 profile, as
// rmw_fastrtps and rmw_cyclonedds put it.
//
// The names dyad accepts are fully qualified ROS 2 topic names (rcl's rules, as "Topic and Service
// name design" states them): dyad's components are not ROS nodes, so a relative or private name
// has no namespace to resolve against.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace dyad {

// "" when `name` is a valid fully qualified ROS 2 topic name; else which rule it breaks, in a
// sentence ("must start with '/' ...").
std::string Ros2TopicNameProblem(std::string_view name);

// The DDS topic of a ROS 2 topic: "/a/b" -> "rt/a/b".
std::string Ros2DdsTopic(std::string_view ros2_name);

// The ROS 2 topic a DDS topic stands for: "rt/a/b" -> "/a/b"; "" for any other DDS topic.
std::string Ros2NameOfDdsTopic(std::string_view dds_topic);

// The ROS 2 type a DDS type name stands for: "geometry_msgs::msg::dds_::Twist_" ->
// "geometry_msgs/msg/Twist"; "" for any other name.
std::string Ros2TypeOfDdsType(std::string_view dds_type);

// A ROS 2 QoS profile by its rclcpp name: reliable or not, KEEP_LAST depth (every profile here is
// volatile). False for a name not listed by Ros2QosProfiles().
struct Ros2Qos {
  bool reliable = true;
  int depth = 10;
};
bool Ros2QosProfile(std::string_view name, Ros2Qos* qos);
std::vector<std::string> Ros2QosProfiles();

}  // namespace dyad
