/* See ros2_common.h. */
#define _POSIX_C_SOURCE 200809L
#include "ros2_common.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

const char *ros2_program_name = "dyad_ros2";

/* Loopback only, unicast only: dyad's Fast DDS participants in their default "local" scope bind
 * to 127.0.0.1 with no multicast and look for peers by unicast at 127.0.0.1's well-known ports
 * for participant ids 0..31. An automatic participant index (first free of 0..31) puts this
 * participant's discovery port where they look; MaxAutoParticipantIndex also bounds the ports
 * Cyclone itself probes at the 127.0.0.1 peer. */
static const char loopback_config[] =
    "<CycloneDDS><Domain id=\"any\">"
    "<General><Interfaces><NetworkInterface address=\"127.0.0.1\"/></Interfaces>"
    "<AllowMulticast>false</AllowMulticast></General>"
    "<Discovery><ParticipantIndex>auto</ParticipantIndex>"
    "<MaxAutoParticipantIndex>31</MaxAutoParticipantIndex>"
    "<Peers><Peer address=\"127.0.0.1\"/></Peers></Discovery>"
    "</Domain></CycloneDDS>";

void ros2_use_loopback_config(void) {
  const char *user = getenv("CYCLONEDDS_URI");
  if (user == NULL || user[0] == '\0') setenv("CYCLONEDDS_URI", loopback_config, 1);
}

dds_entity_t ros2_check(dds_entity_t rc, const char *what) {
  if (rc < 0) {
    fprintf(stderr, "%s: %s: %s\n", ros2_program_name, what, dds_strretcode(rc));
    exit(1);
  }
  return rc;
}

dds_entity_t ros2_create_participant(uint32_t domain) {
  return ros2_check(dds_create_participant(domain, NULL, NULL), "creating the participant");
}

dds_qos_t *ros2_create_qos(ros2_qos_profile profile) {
  dds_qos_t *qos = dds_create_qos();
  bool sensor = profile == ROS2_QOS_SENSOR_DATA;
  dds_qset_reliability(qos, sensor ? DDS_RELIABILITY_BEST_EFFORT : DDS_RELIABILITY_RELIABLE,
                       DDS_MSECS(100));
  dds_qset_durability(qos, DDS_DURABILITY_VOLATILE);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, sensor ? 5 : 10);
  /* ROS 2 (rmw_cyclonedds, Fast DDS) speaks plain CDR. Cyclone would pick XCDR1 for these final
   * types anyway; pinned so an XTypes-minded default can't switch a writer to XCDR2. */
  dds_data_representation_id_t xcdr1 = DDS_DATA_REPRESENTATION_XCDR1;
  dds_qset_data_representation(qos, 1, &xcdr1);
  return qos;
}

dds_entity_t ros2_create_topic(dds_entity_t participant, const dds_topic_descriptor_t *desc,
                               const char *ros_name) {
  char name[512];
  const char *tail = ros_name[0] == '/' ? ros_name + 1 : ros_name;
  snprintf(name, sizeof name, "rt/%s", tail);
  return ros2_check(dds_create_topic(participant, desc, name, NULL, NULL), name);
}

double ros2_wall_time_s(void) {
  struct timespec ts;
  clock_gettime(CLOCK_REALTIME, &ts);
  return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

void ros2_stamp_now(builtin_interfaces_msg_dds__Time_ *stamp) {
  struct timespec ts;
  clock_gettime(CLOCK_REALTIME, &ts);
  stamp->sec = (int32_t)ts.tv_sec;
  stamp->nanosec = (uint32_t)ts.tv_nsec;
}

double ros2_monotonic_s(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

void ros2_sleep_s(double seconds) {
  if (seconds > 0) dds_sleepfor((dds_duration_t)(seconds * 1e9));
}

void ros2_usage_error(const char *fmt, ...) {
  va_list args;
  va_start(args, fmt);
  fprintf(stderr, "%s: ", ros2_program_name);
  vfprintf(stderr, fmt, args);
  fputc('\n', stderr);
  va_end(args);
  exit(ROS2_EXIT_USAGE);
}

const char *ros2_arg_value(int argc, char **argv, int *i) {
  if (*i + 1 >= argc) ros2_usage_error("%s: needs a value", argv[*i]);
  ++*i;
  return argv[*i];
}

/* strtod over the whole string: "1.5x" or "" is an error, not 1.5 or 0. */
static bool parse_double(const char *text, double *value) {
  char *end = NULL;
  errno = 0;
  *value = strtod(text, &end);
  return end != text && *end == '\0' && errno == 0 && isfinite(*value);
}

double ros2_arg_double(const char *option, const char *value, double min, double max) {
  double v;
  if (!parse_double(value, &v)) ros2_usage_error("%s: '%s' is not a number", option, value);
  if (v < min || v > max) ros2_usage_error("%s: %s is outside [%g, %g]", option, value, min, max);
  return v;
}

/* Domain ids 0..232: beyond that the RTPS well-known ports leave the 16-bit range. */
uint32_t ros2_arg_domain(const char *option, const char *value) {
  double v = ros2_arg_double(option, value, 0, 232);
  if (v != floor(v)) ros2_usage_error("%s: '%s' is not a whole number", option, value);
  return (uint32_t)v;
}

void ros2_arg_xyz(const char *option, const char *value, double xyz[3]) {
  char copy[256];
  if (strlen(value) >= sizeof copy) ros2_usage_error("%s: '%s' is too long", option, value);
  strcpy(copy, value);
  char *save = NULL;
  char *part = strtok_r(copy, ",", &save);
  for (int k = 0; k < 3; ++k) {
    if (part == NULL || !parse_double(part, &xyz[k]))
      ros2_usage_error("%s: '%s' is not X,Y,Z (three numbers)", option, value);
    part = strtok_r(NULL, ",", &save);
  }
  if (part != NULL) ros2_usage_error("%s: '%s' is not X,Y,Z (three numbers)", option, value);
}

ros2_qos_profile ros2_arg_qos(const char *option, const char *value) {
  if (strcmp(value, "default") == 0) return ROS2_QOS_DEFAULT;
  if (strcmp(value, "sensor_data") == 0) return ROS2_QOS_SENSOR_DATA;
  ros2_usage_error("%s: '%s' is not default or sensor_data", option, value);
}

void ros2_json_init(ros2_json *json) {
  json->capacity = 256;
  json->length = 0;
  json->text = malloc(json->capacity);
  if (json->text == NULL) abort();
  json->text[0] = '\0';
}

void ros2_json_free(ros2_json *json) {
  free(json->text);
  json->text = NULL;
}

static void append(ros2_json *json, const char *text, size_t n) {
  if (json->length + n + 1 > json->capacity) {
    while (json->length + n + 1 > json->capacity) json->capacity *= 2;
    json->text = realloc(json->text, json->capacity);
    if (json->text == NULL) abort();
  }
  memcpy(json->text + json->length, text, n);
  json->length += n;
  json->text[json->length] = '\0';
}

void ros2_json_raw(ros2_json *json, const char *text) { append(json, text, strlen(text)); }

void ros2_json_key(ros2_json *json, const char *key, bool first) {
  if (!first) ros2_json_raw(json, ",");
  ros2_json_string(json, key);
  ros2_json_raw(json, ":");
}

/* RFC 8259 escaping: quote, backslash and control characters; other bytes pass as they are
 * (ROS 2 strings are UTF-8). */
void ros2_json_string(ros2_json *json, const char *value) {
  ros2_json_raw(json, "\"");
  for (const unsigned char *c = (const unsigned char *)value; *c != '\0'; ++c) {
    char escaped[8];
    switch (*c) {
      case '"': ros2_json_raw(json, "\\\""); break;
      case '\\': ros2_json_raw(json, "\\\\"); break;
      case '\n': ros2_json_raw(json, "\\n"); break;
      case '\r': ros2_json_raw(json, "\\r"); break;
      case '\t': ros2_json_raw(json, "\\t"); break;
      default:
        if (*c < 0x20) {
          snprintf(escaped, sizeof escaped, "\\u%04x", *c);
          ros2_json_raw(json, escaped);
        } else {
          append(json, (const char *)c, 1);
        }
    }
  }
  ros2_json_raw(json, "\"");
}

void ros2_json_double(ros2_json *json, double value) {
  char text[40];
  if (!isfinite(value)) {
    ros2_json_raw(json, "null");
    return;
  }
  snprintf(text, sizeof text, "%.17g", value);
  ros2_json_raw(json, text);
}

void ros2_json_int(ros2_json *json, int64_t value) {
  char text[24];
  snprintf(text, sizeof text, "%lld", (long long)value);
  ros2_json_raw(json, text);
}

void ros2_json_uint(ros2_json *json, uint64_t value) {
  char text[24];
  snprintf(text, sizeof text, "%llu", (unsigned long long)value);
  ros2_json_raw(json, text);
}

void ros2_json_doubles(ros2_json *json, const double *values, uint32_t count) {
  ros2_json_raw(json, "[");
  for (uint32_t k = 0; k < count; ++k) {
    if (k > 0) ros2_json_raw(json, ",");
    ros2_json_double(json, values[k]);
  }
  ros2_json_raw(json, "]");
}

void ros2_json_print(const ros2_json *json) {
  fputs(json->text, stdout);
  fputc('\n', stdout);
  fflush(stdout);
}
