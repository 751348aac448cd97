/* dyad_ros2_wire_peer: the Cyclone DDS side of the ROS 2 wire check, behaving as
 * rmw_cyclonedds_cpp would (ros2_common.h: topic names rt/..., QoS profiles, XCDR1, loopback).
 *
 *   listen  --count N [--timeout-s S=20] [--domain N]
 *     Reads (reliable, volatile, keep last 10) every type below on ROS topic
 *     /dyad_wire/<pkg>_<Type> (DDS rt/dyad_wire/<pkg>_<Type>); prints `ready` once all readers
 *     exist, then each sample as one JSON line (ros2_json.h):
 *       {"type":"geometry_msgs/msg/TwistStamped","sample":{...}}
 *     Exit 0 after N samples in total; 1 on timeout.
 *   publish [--wait-readers-s S=20] [--settle-s S=0.5] [--domain N]
 *     A writer per type on the same topics; waits until each has matched a reader (exit 1 naming
 *     the unmatched topics), then --settle-s more (a volatile reader that has not yet matched the
 *     writer from its side drops what arrives before), writes ONE sample of each type with the
 *     values below, prints the same JSON lines, waits for every reader's acknowledgement, exit 0.
 *   command --mode pose|twist --to X,Y,Z --for-s S [--topic NAME] [--qos default|sensor_data]
 *           [--rate HZ=50] [--frame ID=base_link] [--domain N]
 *     Publishes a target (pose: PoseStamped at X,Y,Z, identity orientation, default topic
 *     /target_pose; twist: TwistStamped with linear velocity X,Y,Z m/s, default topic
 *     /servo_node/delta_twist_cmds) at the rate for S seconds, header.stamp = wall time. Silent.
 *   poses   --for-s S [--topic NAME=/arm/pose] [--qos default|sensor_data] [--domain N]
 *     Prints `ready`, then each geometry_msgs/msg/PoseStamped heard as one JSON line for S
 *     seconds; exit 0, or 1 if none was heard.
 * Bad arguments: a message naming the option, exit 2.
 *
 * The fixed samples `publish` writes (header = Header below wherever a type has one):
 *   builtin_interfaces/msg/Time        {sec=1700000000, nanosec=123456789}
 *   std_msgs/msg/Header                {stamp=that Time, frame_id="base_link"}
 *   geometry_msgs/msg/Vector3          {1.5, -2.25, 3.125}
 *   geometry_msgs/msg/Point            {0.1, -0.2, 0.3}
 *   geometry_msgs/msg/Quaternion       {0, 0, 0.70710678118654757, 0.70710678118654757}
 *   geometry_msgs/msg/Pose             {position=Point, orientation=Quaternion}
 *   geometry_msgs/msg/PoseStamped      {header, pose=Pose}
 *   geometry_msgs/msg/Twist            {linear=Vector3, angular={0.01, -0.02, 6.2831853071795862}}
 *   geometry_msgs/msg/TwistStamped     {header, twist=Twist}
 *   sensor_msgs/msg/JointState         {header, name=["j1","j2","j3"], position=[0.1,0.2,0.3],
 *                                       velocity=[], effort=[1,2,3]}
 *   std_msgs/msg/MultiArrayDimension   {label="rows", size=2, stride=6}
 *   std_msgs/msg/MultiArrayLayout      {dim=[{"rows",2,6},{"cols",3,3}], data_offset=0}
 *   std_msgs/msg/Float64MultiArray     {layout=MultiArrayLayout, data=[1,2,3,4,5,6]} */
#define _POSIX_C_SOURCE 200809L
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ros2_common.h"
#include "ros2_json.h"

/* ---- the fixed samples (see the top of the file) ---- */

#define FIXED_TIME {1700000000, 123456789u}
#define FIXED_HEADER {FIXED_TIME, "base_link"}
#define FIXED_VECTOR3 {1.5, -2.25, 3.125}
#define FIXED_POINT {0.1, -0.2, 0.3}
#define FIXED_QUATERNION {0, 0, 0.70710678118654757, 0.70710678118654757}
#define FIXED_POSE {FIXED_POINT, FIXED_QUATERNION}
#define FIXED_TWIST {FIXED_VECTOR3, {0.01, -0.02, 6.2831853071795862}}

/* Sequences point at these (_release false: Cyclone never frees them). */
static char *joint_names[] = {"j1", "j2", "j3"};
static double joint_positions[] = {0.1, 0.2, 0.3};
static double joint_efforts[] = {1, 2, 3};
static std_msgs_msg_dds__MultiArrayDimension_ dims[] = {{"rows", 2, 6}, {"cols", 3, 3}};
static double array_data[] = {1, 2, 3, 4, 5, 6};
#define FIXED_LAYOUT {{2, 2, dims, false}, 0}

static builtin_interfaces_msg_dds__Time_ fixed_time = FIXED_TIME;
static std_msgs_msg_dds__Header_ fixed_header = FIXED_HEADER;
static geometry_msgs_msg_dds__Vector3_ fixed_vector3 = FIXED_VECTOR3;
static geometry_msgs_msg_dds__Point_ fixed_point = FIXED_POINT;
static geometry_msgs_msg_dds__Quaternion_ fixed_quaternion = FIXED_QUATERNION;
static geometry_msgs_msg_dds__Pose_ fixed_pose = FIXED_POSE;
static geometry_msgs_msg_dds__PoseStamped_ fixed_pose_stamped = {FIXED_HEADER, FIXED_POSE};
static geometry_msgs_msg_dds__Twist_ fixed_twist = FIXED_TWIST;
static geometry_msgs_msg_dds__TwistStamped_ fixed_twist_stamped = {FIXED_HEADER, FIXED_TWIST};
static sensor_msgs_msg_dds__JointState_ fixed_joint_state = {
    FIXED_HEADER, {3, 3, joint_names, false}, {3, 3, joint_positions, false},
    {0, 0, NULL, false}, {3, 3, joint_efforts, false}};
static std_msgs_msg_dds__MultiArrayDimension_ fixed_dimension = {"rows", 2, 6};
static std_msgs_msg_dds__MultiArrayLayout_ fixed_layout = FIXED_LAYOUT;
static std_msgs_msg_dds__Float64MultiArray_ fixed_array = {FIXED_LAYOUT, {6, 6, array_data, false}};

/* ---- the types on the wire ---- */

typedef struct {
  const char *ros_type;  /* e.g. geometry_msgs/msg/TwistStamped */
  const char *ros_topic; /* e.g. /dyad_wire/geometry_msgs_TwistStamped */
  const dds_topic_descriptor_t *desc;
  ros2_json_printer print;
  const void *fixed;
} wire_type;

#define WIRE_TYPE(pkg, type, fixed)                                                     \
  {#pkg "/msg/" #type, "/dyad_wire/" #pkg "_" #type, &pkg##_msg_dds__##type##__desc, \
   (ros2_json_printer)ros2_json_##type, &fixed}

static const wire_type wire_types[] = {
    WIRE_TYPE(builtin_interfaces, Time, fixed_time),
    WIRE_TYPE(std_msgs, Header, fixed_header),
    WIRE_TYPE(geometry_msgs, Vector3, fixed_vector3),
    WIRE_TYPE(geometry_msgs, Point, fixed_point),
    WIRE_TYPE(geometry_msgs, Quaternion, fixed_quaternion),
    WIRE_TYPE(geometry_msgs, Pose, fixed_pose),
    WIRE_TYPE(geometry_msgs, PoseStamped, fixed_pose_stamped),
    WIRE_TYPE(geometry_msgs, Twist, fixed_twist),
    WIRE_TYPE(geometry_msgs, TwistStamped, fixed_twist_stamped),
    WIRE_TYPE(sensor_msgs, JointState, fixed_joint_state),
    WIRE_TYPE(std_msgs, MultiArrayDimension, fixed_dimension),
    WIRE_TYPE(std_msgs, MultiArrayLayout, fixed_layout),
    WIRE_TYPE(std_msgs, Float64MultiArray, fixed_array),
};
/* 13 types, 13 topics: every message below is also a topic type of its own (MultiArrayLayout
 * included), so a nested type's encoding is checked alone as well as inside its parents. */
enum { WIRE_TYPE_COUNT = sizeof wire_types / sizeof wire_types[0] };

/* ---- options ---- */

typedef enum { MODE_LISTEN = 1, MODE_PUBLISH = 2, MODE_COMMAND = 4, MODE_POSES = 8 } peer_mode;

typedef struct {
  peer_mode mode;
  uint32_t domain;
  double count; /* listen: samples to print before exiting */
  double timeout_s;
  double wait_readers_s;
  double settle_s;
  bool command_pose; /* command --mode: pose (true) or twist */
  bool command_mode_set;
  double to[3];
  bool to_set;
  double for_s;
  const char *topic;
  ros2_qos_profile qos;
  double rate_hz;
  const char *frame;
} peer_options;

typedef struct {
  const char *name;
  int modes; /* peer_mode bits the option belongs to */
} option_spec;

static const option_spec option_specs[] = {
    {"--domain", MODE_LISTEN | MODE_PUBLISH | MODE_COMMAND | MODE_POSES},
    {"--count", MODE_LISTEN},
    {"--timeout-s", MODE_LISTEN},
    {"--wait-readers-s", MODE_PUBLISH},
    {"--settle-s", MODE_PUBLISH},
    {"--mode", MODE_COMMAND},
    {"--to", MODE_COMMAND},
    {"--for-s", MODE_COMMAND | MODE_POSES},
    {"--topic", MODE_COMMAND | MODE_POSES},
    {"--qos", MODE_COMMAND | MODE_POSES},
    {"--rate", MODE_COMMAND},
    {"--frame", MODE_COMMAND},
};

static void usage(FILE *out) {
  fprintf(out,
      "usage: dyad_ros2_wire_peer listen --count N [--timeout-s S] [--domain N]\n"
      "       dyad_ros2_wire_peer publish [--wait-readers-s S] [--settle-s S] [--domain N]\n"
      "       dyad_ros2_wire_peer command --mode pose|twist --to X,Y,Z --for-s S [--topic NAME]\n"
      "                                   [--qos default|sensor_data] [--rate HZ] [--frame ID] [--domain N]\n"
      "       dyad_ros2_wire_peer poses --for-s S [--topic NAME] [--qos default|sensor_data] [--domain N]\n");
}

static peer_mode parse_mode(const char *word) {
  if (strcmp(word, "listen") == 0) return MODE_LISTEN;
  if (strcmp(word, "publish") == 0) return MODE_PUBLISH;
  if (strcmp(word, "command") == 0) return MODE_COMMAND;
  if (strcmp(word, "poses") == 0) return MODE_POSES;
  ros2_usage_error("'%s' is not listen, publish, command or poses", word);
}

/* Rejects options that exist but belong to another mode, naming the option. */
static void check_option_mode(const char *opt, peer_mode mode) {
  for (size_t k = 0; k < sizeof option_specs / sizeof option_specs[0]; ++k) {
    if (strcmp(opt, option_specs[k].name) != 0) continue;
    if ((option_specs[k].modes & (int)mode) == 0) ros2_usage_error("%s: not an option of this mode", opt);
    return;
  }
  ros2_usage_error("%s: unknown option (--help lists them)", opt);
}

static void set_option(peer_options *o, const char *opt, const char *v) {
  if (strcmp(opt, "--domain") == 0) o->domain = ros2_arg_domain(opt, v);
  else if (strcmp(opt, "--count") == 0) o->count = ros2_arg_double(opt, v, 1, 1e9);
  else if (strcmp(opt, "--timeout-s") == 0) o->timeout_s = ros2_arg_double(opt, v, 0, 1e6);
  else if (strcmp(opt, "--wait-readers-s") == 0) o->wait_readers_s = ros2_arg_double(opt, v, 0, 1e6);
  else if (strcmp(opt, "--settle-s") == 0) o->settle_s = ros2_arg_double(opt, v, 0, 1e3);
  else if (strcmp(opt, "--to") == 0) { ros2_arg_xyz(opt, v, o->to); o->to_set = true; }
  else if (strcmp(opt, "--for-s") == 0) o->for_s = ros2_arg_double(opt, v, 0, 1e6);
  else if (strcmp(opt, "--topic") == 0) o->topic = v;
  else if (strcmp(opt, "--qos") == 0) o->qos = ros2_arg_qos(opt, v);
  else if (strcmp(opt, "--rate") == 0) o->rate_hz = ros2_arg_double(opt, v, 0.1, 10000);
  else if (strcmp(opt, "--frame") == 0) o->frame = v;
  else if (strcmp(v, "pose") == 0 || strcmp(v, "twist") == 0) {
    o->command_pose = strcmp(v, "pose") == 0;
    o->command_mode_set = true;
  } else ros2_usage_error("--mode: '%s' is not pose or twist", v);
}

static void check_required(const peer_options *o) {
  if (o->mode == MODE_LISTEN && o->count == 0) ros2_usage_error("--count: required by listen");
  if ((o->mode == MODE_COMMAND || o->mode == MODE_POSES) && o->for_s < 0)
    ros2_usage_error("--for-s: required by this mode");
  if (o->mode == MODE_COMMAND && !o->command_mode_set) ros2_usage_error("--mode: required by command (pose or twist)");
  if (o->mode == MODE_COMMAND && !o->to_set) ros2_usage_error("--to: required by command");
  if (o->count != floor(o->count)) ros2_usage_error("--count: not a whole number");
}

static void parse_arguments(int argc, char **argv, peer_options *o) {
  memset(o, 0, sizeof *o);
  o->timeout_s = 20;
  o->wait_readers_s = 20;
  o->settle_s = 0.5;
  o->for_s = -1;
  o->rate_hz = 50;
  o->frame = "base_link";
  if (argc < 2 || strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0) {
    usage(argc < 2 ? stderr : stdout);
    exit(argc < 2 ? ROS2_EXIT_USAGE : 0);
  }
  o->mode = parse_mode(argv[1]);
  for (int i = 2; i < argc; ++i) {
    check_option_mode(argv[i], o->mode);
    const char *opt = argv[i];
    set_option(o, opt, ros2_arg_value(argc, argv, &i));
  }
  check_required(o);
}

/* ---- listen / poses: readers, a waitset, JSON lines ---- */

/* Prints the samples waiting in `reader`, at most `limit`; returns how many. */
static int print_waiting(dds_entity_t reader, const char *ros_type, ros2_json_printer print, int limit) {
  enum { BATCH = 16 };
  int printed = 0;
  while (printed < limit) {
    void *samples[BATCH] = {NULL};
    dds_sample_info_t infos[BATCH];
    int32_t want = limit - printed < BATCH ? limit - printed : BATCH;
    int32_t n = dds_take(reader, samples, infos, (size_t)want, (uint32_t)want);
    if (n <= 0) return printed;
    for (int32_t k = 0; k < n; ++k) {
      if (!infos[k].valid_data) continue;
      ros2_json_print_sample(ros_type, print, samples[k]);
      ++printed;
    }
    dds_return_loan(reader, samples, n);
  }
  return printed;
}

static dds_entity_t create_reader(dds_entity_t participant, const dds_topic_descriptor_t *desc,
                                  const char *ros_topic, ros2_qos_profile profile, dds_entity_t waitset,
                                  dds_attach_t index) {
  dds_entity_t topic = ros2_create_topic(participant, desc, ros_topic);
  dds_qos_t *qos = ros2_create_qos(profile);
  dds_entity_t reader = ros2_check(dds_create_reader(participant, topic, qos, NULL), ros_topic);
  dds_delete_qos(qos);
  dds_entity_t condition = ros2_check(dds_create_readcondition(reader, DDS_ANY_STATE), ros_topic);
  ros2_check(dds_waitset_attach(waitset, condition, index), ros_topic);
  return reader;
}

static void print_ready(void) {
  printf("ready\n");
  fflush(stdout);
}

static int run_listen(const peer_options *o, dds_entity_t participant) {
  dds_entity_t waitset = ros2_check(dds_create_waitset(participant), "creating the waitset");
  dds_entity_t readers[WIRE_TYPE_COUNT];
  for (int k = 0; k < WIRE_TYPE_COUNT; ++k)
    readers[k] = create_reader(participant, wire_types[k].desc, wire_types[k].ros_topic, ROS2_QOS_DEFAULT, waitset, k);
  print_ready();
  double deadline = ros2_monotonic_s() + o->timeout_s;
  double received = 0;
  while (received < o->count) {
    double left = deadline - ros2_monotonic_s();
    if (left <= 0) {
      fprintf(stderr, "dyad_ros2_wire_peer: listen: %.0f of %.0f samples within %g s\n", received, o->count, o->timeout_s);
      return 1;
    }
    dds_waitset_wait(waitset, NULL, 0, (dds_duration_t)(left * 1e9));
    for (int k = 0; k < WIRE_TYPE_COUNT && received < o->count; ++k)
      received += print_waiting(readers[k], wire_types[k].ros_type, wire_types[k].print, (int)(o->count - received));
  }
  return 0;
}

static int run_poses(const peer_options *o, dds_entity_t participant) {
  const char *topic = o->topic != NULL ? o->topic : "/arm/pose";
  dds_entity_t waitset = ros2_check(dds_create_waitset(participant), "creating the waitset");
  dds_entity_t reader = create_reader(participant, &geometry_msgs_msg_dds__PoseStamped__desc, topic, o->qos, waitset, 0);
  print_ready();
  double deadline = ros2_monotonic_s() + o->for_s;
  int received = 0;
  for (double left = o->for_s; left > 0; left = deadline - ros2_monotonic_s()) {
    dds_waitset_wait(waitset, NULL, 0, (dds_duration_t)(left * 1e9));
    received += print_waiting(reader, "geometry_msgs/msg/PoseStamped", (ros2_json_printer)ros2_json_PoseStamped, INT_MAX);
  }
  if (received > 0) return 0;
  fprintf(stderr, "dyad_ros2_wire_peer: poses: no pose heard on %s within %g s\n", topic, o->for_s);
  return 1;
}

/* ---- publish ---- */

/* Waits until every writer has matched a reader; false (naming the others) at the deadline. */
static bool wait_for_readers(const dds_entity_t *writers, double wait_s) {
  double deadline = ros2_monotonic_s() + wait_s;
  for (;;) {
    int unmatched = 0;
    for (int k = 0; k < WIRE_TYPE_COUNT; ++k) {
      dds_publication_matched_status_t st;
      ros2_check(dds_get_publication_matched_status(writers[k], &st), "reading the match status");
      if (st.current_count > 0) continue;
      ++unmatched;
      if (ros2_monotonic_s() >= deadline)
        fprintf(stderr, "dyad_ros2_wire_peer: publish: no reader on rt%s within %g s\n", wire_types[k].ros_topic, wait_s);
    }
    if (unmatched == 0) return true;
    if (ros2_monotonic_s() >= deadline) return false;
    ros2_sleep_s(0.01);
  }
}

static int run_publish(const peer_options *o, dds_entity_t participant) {
  dds_entity_t writers[WIRE_TYPE_COUNT];
  dds_qos_t *qos = ros2_create_qos(ROS2_QOS_DEFAULT);
  for (int k = 0; k < WIRE_TYPE_COUNT; ++k) {
    dds_entity_t topic = ros2_create_topic(participant, wire_types[k].desc, wire_types[k].ros_topic);
    writers[k] = ros2_check(dds_create_writer(participant, topic, qos, NULL), wire_types[k].ros_topic);
  }
  dds_delete_qos(qos);
  if (!wait_for_readers(writers, o->wait_readers_s)) return 1;
  ros2_sleep_s(o->settle_s);
  for (int k = 0; k < WIRE_TYPE_COUNT; ++k) {
    ros2_check(dds_write(writers[k], wire_types[k].fixed), wire_types[k].ros_topic);
    ros2_json_print_sample(wire_types[k].ros_type, wire_types[k].print, wire_types[k].fixed);
  }
  for (int k = 0; k < WIRE_TYPE_COUNT; ++k) {
    if (dds_wait_for_acks(writers[k], DDS_SECS(10)) < 0) {
      fprintf(stderr, "dyad_ros2_wire_peer: publish: rt%s: not acknowledged within 10 s\n", wire_types[k].ros_topic);
      return 1;
    }
  }
  return 0;
}

/* ---- command ---- */

static void write_command(const peer_options *o, dds_entity_t writer) {
  if (o->command_pose) {
    geometry_msgs_msg_dds__PoseStamped_ m;
    memset(&m, 0, sizeof m);
    ros2_stamp_now(&m.header.stamp);
    m.header.frame_id = (char *)o->frame; /* only read by dds_write */
    m.pose.position = (geometry_msgs_msg_dds__Point_){o->to[0], o->to[1], o->to[2]};
    m.pose.orientation.w = 1;
    ros2_check(dds_write(writer, &m), "writing the target pose");
  } else {
    geometry_msgs_msg_dds__TwistStamped_ m;
    memset(&m, 0, sizeof m);
    ros2_stamp_now(&m.header.stamp);
    m.header.frame_id = (char *)o->frame;
    m.twist.linear = (geometry_msgs_msg_dds__Vector3_){o->to[0], o->to[1], o->to[2]};
    ros2_check(dds_write(writer, &m), "writing the twist");
  }
}

static int run_command(const peer_options *o, dds_entity_t participant) {
  const char *topic = o->topic != NULL ? o->topic : o->command_pose ? "/target_pose" : "/servo_node/delta_twist_cmds";
  const dds_topic_descriptor_t *desc = o->command_pose ? &geometry_msgs_msg_dds__PoseStamped__desc
                                                       : &geometry_msgs_msg_dds__TwistStamped__desc;
  dds_qos_t *qos = ros2_create_qos(o->qos);
  dds_entity_t writer = ros2_check(dds_create_writer(participant, ros2_create_topic(participant, desc, topic), qos, NULL), topic);
  dds_delete_qos(qos);
  double period = 1.0 / o->rate_hz;
  double start = ros2_monotonic_s();
  for (double next = start; next < start + o->for_s; next += period) {
    ros2_sleep_s(next - ros2_monotonic_s());
    write_command(o, writer);
  }
  return 0;
}

int main(int argc, char **argv) {
  ros2_program_name = "dyad_ros2_wire_peer";
  peer_options o;
  parse_arguments(argc, argv, &o);
  ros2_use_loopback_config();
  dds_entity_t participant = ros2_create_participant(o.domain);
  int rc = 0;
  switch (o.mode) {
    case MODE_LISTEN: rc = run_listen(&o, participant); break;
    case MODE_PUBLISH: rc = run_publish(&o, participant); break;
    case MODE_COMMAND: rc = run_command(&o, participant); break;
    case MODE_POSES: rc = run_poses(&o, participant); break;
  }
  dds_delete(participant);
  return rc;
}
