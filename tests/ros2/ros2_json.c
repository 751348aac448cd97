/* See ros2_json.h. */
#include "ros2_json.h"

static void xyz(ros2_json *j, double x, double y, double z) {
  ros2_json_key(j, "x", true);
  ros2_json_double(j, x);
  ros2_json_key(j, "y", false);
  ros2_json_double(j, y);
  ros2_json_key(j, "z", false);
  ros2_json_double(j, z);
}

void ros2_json_Time(ros2_json *j, const builtin_interfaces_msg_dds__Time_ *m) {
  ros2_json_key(j, "sec", true);
  ros2_json_int(j, m->sec);
  ros2_json_key(j, "nanosec", false);
  ros2_json_uint(j, m->nanosec);
}

/* Each nested-message printer writes its members only; these wrap them in braces. */
#define OBJECT(j, body) \
  do {                  \
    ros2_json_raw(j, "{"); \
    body;               \
    ros2_json_raw(j, "}"); \
  } while (0)

void ros2_json_Header(ros2_json *j, const std_msgs_msg_dds__Header_ *m) {
  ros2_json_key(j, "stamp", true);
  OBJECT(j, ros2_json_Time(j, &m->stamp));
  ros2_json_key(j, "frame_id", false);
  ros2_json_string(j, m->frame_id);
}

void ros2_json_Vector3(ros2_json *j, const geometry_msgs_msg_dds__Vector3_ *m) {
  xyz(j, m->x, m->y, m->z);
}

void ros2_json_Point(ros2_json *j, const geometry_msgs_msg_dds__Point_ *m) {
  xyz(j, m->x, m->y, m->z);
}

void ros2_json_Quaternion(ros2_json *j, const geometry_msgs_msg_dds__Quaternion_ *m) {
  xyz(j, m->x, m->y, m->z);
  ros2_json_key(j, "w", false);
  ros2_json_double(j, m->w);
}

void ros2_json_Pose(ros2_json *j, const geometry_msgs_msg_dds__Pose_ *m) {
  ros2_json_key(j, "position", true);
  OBJECT(j, ros2_json_Point(j, &m->position));
  ros2_json_key(j, "orientation", false);
  OBJECT(j, ros2_json_Quaternion(j, &m->orientation));
}

void ros2_json_PoseStamped(ros2_json *j, const geometry_msgs_msg_dds__PoseStamped_ *m) {
  ros2_json_key(j, "header", true);
  OBJECT(j, ros2_json_Header(j, &m->header));
  ros2_json_key(j, "pose", false);
  OBJECT(j, ros2_json_Pose(j, &m->pose));
}

void ros2_json_Twist(ros2_json *j, const geometry_msgs_msg_dds__Twist_ *m) {
  ros2_json_key(j, "linear", true);
  OBJECT(j, ros2_json_Vector3(j, &m->linear));
  ros2_json_key(j, "angular", false);
  OBJECT(j, ros2_json_Vector3(j, &m->angular));
}

void ros2_json_TwistStamped(ros2_json *j, const geometry_msgs_msg_dds__TwistStamped_ *m) {
  ros2_json_key(j, "header", true);
  OBJECT(j, ros2_json_Header(j, &m->header));
  ros2_json_key(j, "twist", false);
  OBJECT(j, ros2_json_Twist(j, &m->twist));
}

void ros2_json_JointState(ros2_json *j, const sensor_msgs_msg_dds__JointState_ *m) {
  ros2_json_key(j, "header", true);
  OBJECT(j, ros2_json_Header(j, &m->header));
  ros2_json_key(j, "name", false);
  ros2_json_raw(j, "[");
  for (uint32_t k = 0; k < m->name._length; ++k) {
    if (k > 0) ros2_json_raw(j, ",");
    ros2_json_string(j, m->name._buffer[k]);
  }
  ros2_json_raw(j, "]");
  ros2_json_key(j, "position", false);
  ros2_json_doubles(j, m->position._buffer, m->position._length);
  ros2_json_key(j, "velocity", false);
  ros2_json_doubles(j, m->velocity._buffer, m->velocity._length);
  ros2_json_key(j, "effort", false);
  ros2_json_doubles(j, m->effort._buffer, m->effort._length);
}

void ros2_json_MultiArrayDimension(ros2_json *j, const std_msgs_msg_dds__MultiArrayDimension_ *m) {
  ros2_json_key(j, "label", true);
  ros2_json_string(j, m->label);
  ros2_json_key(j, "size", false);
  ros2_json_uint(j, m->size);
  ros2_json_key(j, "stride", false);
  ros2_json_uint(j, m->stride);
}

void ros2_json_MultiArrayLayout(ros2_json *j, const std_msgs_msg_dds__MultiArrayLayout_ *m) {
  ros2_json_key(j, "dim", true);
  ros2_json_raw(j, "[");
  for (uint32_t k = 0; k < m->dim._length; ++k) {
    if (k > 0) ros2_json_raw(j, ",");
    OBJECT(j, ros2_json_MultiArrayDimension(j, &m->dim._buffer[k]));
  }
  ros2_json_raw(j, "]");
  ros2_json_key(j, "data_offset", false);
  ros2_json_uint(j, m->data_offset);
}

void ros2_json_Float64MultiArray(ros2_json *j, const std_msgs_msg_dds__Float64MultiArray_ *m) {
  ros2_json_key(j, "layout", true);
  OBJECT(j, ros2_json_MultiArrayLayout(j, &m->layout));
  ros2_json_key(j, "data", false);
  ros2_json_doubles(j, m->data._buffer, m->data._length);
}

void ros2_json_print_sample(const char *ros_type, ros2_json_printer print_sample, const void *sample) {
  ros2_json j;
  ros2_json_init(&j);
  ros2_json_raw(&j, "{");
  ros2_json_key(&j, "type", true);
  ros2_json_string(&j, ros_type);
  ros2_json_key(&j, "sample", false);
  OBJECT(&j, print_sample(&j, sample));
  ros2_json_raw(&j, "}");
  ros2_json_print(&j);
  ros2_json_free(&j);
}
