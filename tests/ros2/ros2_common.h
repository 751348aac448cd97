/* What the fake ROS 2 arm and the wire peer share: Cyclone DDS set up the way rmw_cyclonedds_cpp
 * puts ROS 2 on the wire (topic names, QoS profiles, XCDR1), loopback-only discovery so they meet
 * dyad's Fast DDS participants in their "local" scope, argument parsing and a small JSON writer. */
#ifndef DYAD_TESTS_ROS2_COMMON_H
#define DYAD_TESTS_ROS2_COMMON_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "dds/dds.h"

#include "builtin_interfaces/msg/Time.h"

/* Exit status for bad arguments (the usual for command-line misuse). */
#define ROS2_EXIT_USAGE 2

typedef enum { ROS2_QOS_DEFAULT, ROS2_QOS_SENSOR_DATA } ros2_qos_profile;

/* Sets CYCLONEDDS_URI to the loopback unicast configuration unless the user set it already. */
void ros2_use_loopback_config(void);
/* The participant on `domain` (after ros2_use_loopback_config), or exits 1 with Cyclone's error. */
dds_entity_t ros2_create_participant(uint32_t domain);
/* Reader/writer QoS of a ROS 2 profile: `default` reliable, volatile, keep last 10;
 * `sensor_data` best effort, volatile, keep last 5; both plain CDR (XCDR1). Free with dds_delete_qos. */
dds_qos_t *ros2_create_qos(ros2_qos_profile profile);
/* The topic of ROS name `ros_name` ("/a/b" -> DDS "rt/a/b"), or exits 1 with Cyclone's error. */
dds_entity_t ros2_create_topic(dds_entity_t participant, const dds_topic_descriptor_t *desc,
                               const char *ros_name);
/* Exits 1 naming `what` when `rc` is a Cyclone error (negative). */
dds_entity_t ros2_check(dds_entity_t rc, const char *what);

/* Wall-clock time in seconds, and as a ROS 2 stamp. */
double ros2_wall_time_s(void);
void ros2_stamp_now(builtin_interfaces_msg_dds__Time_ *stamp);
/* Monotonic time in seconds (for rates and timeouts). */
double ros2_monotonic_s(void);
void ros2_sleep_s(double seconds);

/* Argument parsing: each prints "<prog>: <option>: <why>" and exits 2 on a bad value. */
double ros2_arg_double(const char *option, const char *value, double min, double max);
uint32_t ros2_arg_domain(const char *option, const char *value);
void ros2_arg_xyz(const char *option, const char *value, double xyz[3]);
ros2_qos_profile ros2_arg_qos(const char *option, const char *value);
/* The value after argv[*i] (advancing *i), or exits 2 naming the option. */
const char *ros2_arg_value(int argc, char **argv, int *i);
/* Prints "<prog>: <fmt...>" to stderr and exits 2. */
void ros2_usage_error(const char *fmt, ...) __attribute__((format(printf, 1, 2), noreturn));
extern const char *ros2_program_name;

/* A growing string for one JSON line. */
typedef struct {
  char *text;
  size_t length;
  size_t capacity;
} ros2_json;

void ros2_json_init(ros2_json *json);
void ros2_json_free(ros2_json *json);
void ros2_json_raw(ros2_json *json, const char *text);
/* ,"key": before a member (no comma before the first: `first` tells). */
void ros2_json_key(ros2_json *json, const char *key, bool first);
void ros2_json_string(ros2_json *json, const char *value);
/* 17 significant digits (round-trips every double); null for NaN and infinities, which JSON lacks. */
void ros2_json_double(ros2_json *json, double value);
void ros2_json_int(ros2_json *json, int64_t value);
void ros2_json_uint(ros2_json *json, uint64_t value);
void ros2_json_doubles(ros2_json *json, const double *values, uint32_t count);
/* Prints the line and a newline to stdout, flushed (tests read it through a pipe). */
void ros2_json_print(const ros2_json *json);

#endif
