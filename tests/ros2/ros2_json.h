/* The ROS 2 messages as JSON objects: fields by their IDL names in IDL order, nested messages as
 * objects, sequences as arrays, doubles with 17 significant digits (see ros2_common.h). The wire
 * peer prints what it sends and what it hears with these, so the two can be compared as text. */
#ifndef DYAD_TESTS_ROS2_JSON_H
#define DYAD_TESTS_ROS2_JSON_H

#include "ros2_common.h"

#include "builtin_interfaces/msg/Time.h"
#include "geometry_msgs/msg/Point.h"
#include "geometry_msgs/msg/Pose.h"
#include "geometry_msgs/msg/PoseStamped.h"
#include "geometry_msgs/msg/Quaternion.h"
#include "geometry_msgs/msg/Twist.h"
#include "geometry_msgs/msg/TwistStamped.h"
#include "geometry_msgs/msg/Vector3.h"
#include "sensor_msgs/msg/JointState.h"
#include "std_msgs/msg/Float64MultiArray.h"
#include "std_msgs/msg/Header.h"
#include "std_msgs/msg/MultiArrayDimension.h"
#include "std_msgs/msg/MultiArrayLayout.h"

void ros2_json_Time(ros2_json *j, const builtin_interfaces_msg_dds__Time_ *m);
void ros2_json_Header(ros2_json *j, const std_msgs_msg_dds__Header_ *m);
void ros2_json_Vector3(ros2_json *j, const geometry_msgs_msg_dds__Vector3_ *m);
void ros2_json_Point(ros2_json *j, const geometry_msgs_msg_dds__Point_ *m);
void ros2_json_Quaternion(ros2_json *j, const geometry_msgs_msg_dds__Quaternion_ *m);
void ros2_json_Pose(ros2_json *j, const geometry_msgs_msg_dds__Pose_ *m);
void ros2_json_PoseStamped(ros2_json *j, const geometry_msgs_msg_dds__PoseStamped_ *m);
void ros2_json_Twist(ros2_json *j, const geometry_msgs_msg_dds__Twist_ *m);
void ros2_json_TwistStamped(ros2_json *j, const geometry_msgs_msg_dds__TwistStamped_ *m);
void ros2_json_JointState(ros2_json *j, const sensor_msgs_msg_dds__JointState_ *m);
void ros2_json_MultiArrayDimension(ros2_json *j, const std_msgs_msg_dds__MultiArrayDimension_ *m);
void ros2_json_MultiArrayLayout(ros2_json *j, const std_msgs_msg_dds__MultiArrayLayout_ *m);
void ros2_json_Float64MultiArray(ros2_json *j, const std_msgs_msg_dds__Float64MultiArray_ *m);

/* One line {"type":"<ros type>","sample":{...}} to stdout, `print_sample` writing the object. */
typedef void (*ros2_json_printer)(ros2_json *j, const void *sample);
void ros2_json_print_sample(const char *ros_type, ros2_json_printer print_sample, const void *sample);

#endif
