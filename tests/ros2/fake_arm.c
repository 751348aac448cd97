/* dyad_ros2_fake_arm: a fake ROS 2 arm as MoveIt Servo or a Cartesian pose controller presents
 * itself, on Cyclone DDS the way rmw_cyclonedds_cpp puts it on the wire (ros2_common.h). The
 * other side of dyad's native ROS 2 driver tests.
 *
 *   dyad_ros2_fake_arm --mode twist|pose [options]
 *
 * twist: subscribes geometry_msgs/msg/TwistStamped on --command-topic (default
 *   /servo_node/delta_twist_cmds); the commanded linear velocity passes a first-order lag
 *   (--lag-s) and the position integrates the lagged velocity. No command for
 *   --command-timeout-s -> commanded velocity 0, as Servo does. Angular velocity is ignored.
 * pose: subscribes geometry_msgs/msg/PoseStamped on --command-topic (default /target_pose); the
 *   position follows the target through the first-order lag, the orientation is copied. Targets
 *   with a non-finite position are ignored (a controller would refuse them).
 * Both publish geometry_msgs/msg/PoseStamped on --pose-topic (default /arm/pose) at --rate Hz,
 * header.stamp = wall time, header.frame_id = --frame, orientation identity until commanded.
 *
 * Output: `ready` (flushed) once the reader and writer exist; with --verbose one line per
 * received command: `twist VX VY VZ` or `pose X Y Z QX QY QZ QW` (%.17g). --log FILE writes CSV
 * per published pose: t_s,cmd_vx,cmd_vy,cmd_vz,x,y,z (twist; the velocity in effect, 0 after
 * the timeout) or t_s,cmd_x,cmd_y,cmd_z,x,y,z (pose; the target), t_s since start, x,y,z as
 * published. Exit 0 on SIGINT/SIGTERM (participant deleted), 2 on bad arguments, 1 on DDS errors.
 * Faults for the driver's tests: --nan-after-s S publishes NaN positions from S s on;
 * --offset-after-s S,DX adds DX metres to the reported x from S s on; --no-pose never publishes
 * its pose (an arm that never answers: its writer exists, nothing is written; it still moves as
 * commanded and --verbose/--log still record it); --frame ID sends poses in another frame.
 * What it received: --verbose (every command, in order: the last line is the last command). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ros2_common.h"
#include "ros2_json.h"

typedef enum { MODE_TWIST, MODE_POSE } arm_mode;

typedef struct {
  arm_mode mode;
  const char *command_topic;
  const char *pose_topic;
  double rate_hz;
  double lag_s;
  double initial[3];
  const char *frame;
  ros2_qos_profile command_qos;
  ros2_qos_profile pose_qos;
  double command_timeout_s;
  uint32_t domain;
  const char *log_path;
  double nan_after_s;    /* < 0: never */
  double offset_after_s; /* < 0: never */
  double offset_dx;
  bool no_pose;
  bool verbose;
} arm_options;

typedef struct {
  double position[3];
  double velocity[3];       /* twist mode: the lagged velocity */
  double command[3];        /* twist: commanded linear velocity; pose: target position */
  double orientation[4];    /* x, y, z, w */
  double last_command_s;    /* monotonic time of the last command */
  bool have_command;
} arm_state;

typedef struct {
  dds_entity_t participant;
  dds_entity_t reader;
  dds_entity_t writer;
  dds_entity_t waitset;
  FILE *log;
} arm_dds;

static volatile sig_atomic_t stop_requested = 0;

static void on_signal(int signal_number) {
  (void)signal_number;
  stop_requested = 1;
}

static void usage(void) {
  printf(
      "usage: dyad_ros2_fake_arm --mode twist|pose [--command-topic NAME] [--pose-topic NAME]\n"
      "  [--rate HZ] [--lag-s S] [--initial X,Y,Z] [--frame ID] [--command-qos default|sensor_data]\n"
      "  [--pose-qos default|sensor_data] [--command-timeout-s S] [--domain N] [--log FILE]\n"
      "  [--nan-after-s S] [--offset-after-s S,DX] [--no-pose] [--verbose]\n");
}

static void parse_offset(const char *option, const char *value, arm_options *o) {
  char copy[128];
  if (strlen(value) >= sizeof copy) ros2_usage_error("%s: '%s' is too long", option, value);
  strcpy(copy, value);
  char *comma = strchr(copy, ',');
  if (comma == NULL) ros2_usage_error("%s: '%s' is not S,DX", option, value);
  *comma = '\0';
  o->offset_after_s = ros2_arg_double(option, copy, 0, 1e9);
  o->offset_dx = ros2_arg_double(option, comma + 1, -1e3, 1e3);
}

static void set_defaults(arm_options *o) {
  memset(o, 0, sizeof *o);
  o->mode = (arm_mode)-1;
  o->pose_topic = "/arm/pose";
  o->rate_hz = 100;
  o->lag_s = 0.1;
  o->initial[0] = 0.4;
  o->initial[2] = 0.3;
  o->frame = "base_link";
  o->command_timeout_s = 0.2;
  o->nan_after_s = -1;
  o->offset_after_s = -1;
}

/* One option at argv[*i] (and its value); false if it isn't one of ours. */
static bool parse_option(int argc, char **argv, int *i, arm_options *o) {
  const char *opt = argv[*i];
  if (strcmp(opt, "--verbose") == 0) { o->verbose = true; return true; }
  if (strcmp(opt, "--no-pose") == 0) { o->no_pose = true; return true; }
  if (strncmp(opt, "--", 2) != 0) return false;
  const char *known[] = {"--mode", "--command-topic", "--pose-topic", "--rate", "--lag-s",
                         "--initial", "--frame", "--command-qos", "--pose-qos",
                         "--command-timeout-s", "--domain", "--log", "--nan-after-s",
                         "--offset-after-s"};
  bool is_known = false;
  for (size_t k = 0; k < sizeof known / sizeof known[0]; ++k) is_known |= strcmp(opt, known[k]) == 0;
  if (!is_known) return false;
  const char *v = ros2_arg_value(argc, argv, i);
  if (strcmp(opt, "--mode") == 0) {
    if (strcmp(v, "twist") == 0) o->mode = MODE_TWIST;
    else if (strcmp(v, "pose") == 0) o->mode = MODE_POSE;
    else ros2_usage_error("--mode: '%s' is not twist or pose", v);
  } else if (strcmp(opt, "--command-topic") == 0) o->command_topic = v;
  else if (strcmp(opt, "--pose-topic") == 0) o->pose_topic = v;
  else if (strcmp(opt, "--rate") == 0) o->rate_hz = ros2_arg_double(opt, v, 0.1, 10000);
  else if (strcmp(opt, "--lag-s") == 0) o->lag_s = ros2_arg_double(opt, v, 0, 1e3);
  else if (strcmp(opt, "--initial") == 0) ros2_arg_xyz(opt, v, o->initial);
  else if (strcmp(opt, "--frame") == 0) o->frame = v;
  else if (strcmp(opt, "--command-qos") == 0) o->command_qos = ros2_arg_qos(opt, v);
  else if (strcmp(opt, "--pose-qos") == 0) o->pose_qos = ros2_arg_qos(opt, v);
  else if (strcmp(opt, "--command-timeout-s") == 0) o->command_timeout_s = ros2_arg_double(opt, v, 0, 1e6);
  else if (strcmp(opt, "--domain") == 0) o->domain = ros2_arg_domain(opt, v);
  else if (strcmp(opt, "--log") == 0) o->log_path = v;
  else if (strcmp(opt, "--nan-after-s") == 0) o->nan_after_s = ros2_arg_double(opt, v, 0, 1e9);
  else parse_offset(opt, v, o);
  return true;
}

static void parse_arguments(int argc, char **argv, arm_options *o) {
  set_defaults(o);
  for (int i = 1; i < argc; ++i) {
    if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
      usage();
      exit(0);
    }
    if (!parse_option(argc, argv, &i, o)) ros2_usage_error("%s: unknown option (--help lists them)", argv[i]);
  }
  if (o->mode != MODE_TWIST && o->mode != MODE_POSE) ros2_usage_error("--mode: required (twist or pose)");
  if (o->command_topic == NULL)
    o->command_topic = o->mode == MODE_TWIST ? "/servo_node/delta_twist_cmds" : "/target_pose";
}

static void init_state(const arm_options *o, arm_state *s) {
  memset(s, 0, sizeof *s);
  for (int k = 0; k < 3; ++k) {
    s->position[k] = o->initial[k];
    s->command[k] = o->mode == MODE_POSE ? o->initial[k] : 0;
  }
  s->orientation[3] = 1;
}

static void print_command(const char *kind, const double *values, int count) {
  printf("%s", kind);
  for (int k = 0; k < count; ++k) printf(" %.17g", values[k]);
  printf("\n");
  fflush(stdout);
}

static void apply_twist(const arm_options *o, arm_state *s, const geometry_msgs_msg_dds__TwistStamped_ *m) {
  const geometry_msgs_msg_dds__Vector3_ *v = &m->twist.linear;
  double cmd[3] = {v->x, v->y, v->z};
  if (o->verbose) print_command("twist", cmd, 3);
  if (!isfinite(cmd[0]) || !isfinite(cmd[1]) || !isfinite(cmd[2])) return;
  memcpy(s->command, cmd, sizeof cmd);
  s->last_command_s = ros2_monotonic_s();
  s->have_command = true;
}

static void apply_pose(const arm_options *o, arm_state *s, const geometry_msgs_msg_dds__PoseStamped_ *m) {
  const geometry_msgs_msg_dds__Pose_ *p = &m->pose;
  double cmd[7] = {p->position.x, p->position.y, p->position.z, p->orientation.x,
                   p->orientation.y, p->orientation.z, p->orientation.w};
  if (o->verbose) print_command("pose", cmd, 7);
  if (!isfinite(cmd[0]) || !isfinite(cmd[1]) || !isfinite(cmd[2])) return;
  memcpy(s->command, cmd, 3 * sizeof cmd[0]);
  memcpy(s->orientation, cmd + 3, 4 * sizeof cmd[0]);
  s->last_command_s = ros2_monotonic_s();
  s->have_command = true;
}

/* Takes every command waiting (loaned samples: no copies, no type-specific freeing). */
static void take_commands(const arm_options *o, const arm_dds *d, arm_state *s) {
  enum { BATCH = 16 };
  for (;;) {
    void *samples[BATCH] = {NULL};
    dds_sample_info_t infos[BATCH];
    int32_t n = dds_take(d->reader, samples, infos, BATCH, BATCH);
    if (n <= 0) return;
    for (int32_t k = 0; k < n; ++k) {
      if (!infos[k].valid_data) continue;
      if (o->mode == MODE_TWIST) apply_twist(o, s, samples[k]);
      else apply_pose(o, s, samples[k]);
    }
    dds_return_loan(d->reader, samples, n);
  }
}

/* One period of the first-order lag: exact for a command held over the period. */
static void step(const arm_options *o, arm_state *s, double dt, double now_s) {
  double alpha = o->lag_s > 0 ? 1 - exp(-dt / o->lag_s) : 1;
  if (o->mode == MODE_TWIST) {
    bool stale = !s->have_command || now_s - s->last_command_s > o->command_timeout_s;
    if (stale) memset(s->command, 0, sizeof s->command);
    for (int k = 0; k < 3; ++k) {
      s->velocity[k] += alpha * (s->command[k] - s->velocity[k]);
      s->position[k] += s->velocity[k] * dt;
    }
  } else {
    for (int k = 0; k < 3; ++k) s->position[k] += alpha * (s->command[k] - s->position[k]);
  }
}

/* The position as published: the true one, or the faults asked for. */
static void reported_position(const arm_options *o, const arm_state *s, double t_s, double out[3]) {
  for (int k = 0; k < 3; ++k) out[k] = s->position[k];
  if (o->offset_after_s >= 0 && t_s >= o->offset_after_s) out[0] += o->offset_dx;
  if (o->nan_after_s >= 0 && t_s >= o->nan_after_s) out[0] = out[1] = out[2] = NAN;
}

static void publish(const arm_options *o, const arm_dds *d, const arm_state *s, double t_s) {
  double p[3];
  reported_position(o, s, t_s, p);
  geometry_msgs_msg_dds__PoseStamped_ m;
  memset(&m, 0, sizeof m);
  ros2_stamp_now(&m.header.stamp);
  m.header.frame_id = (char *)o->frame; /* only read by dds_write */
  m.pose.position.x = p[0];
  m.pose.position.y = p[1];
  m.pose.position.z = p[2];
  m.pose.orientation.x = s->orientation[0];
  m.pose.orientation.y = s->orientation[1];
  m.pose.orientation.z = s->orientation[2];
  m.pose.orientation.w = s->orientation[3];
  if (!o->no_pose) ros2_check(dds_write(d->writer, &m), "writing the pose");
  if (d->log != NULL)
    fprintf(d->log, "%.6f,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", t_s, s->command[0], s->command[1],
            s->command[2], p[0], p[1], p[2]);
}

static void open_log(const arm_options *o, arm_dds *d) {
  d->log = NULL;
  if (o->log_path == NULL) return;
  d->log = fopen(o->log_path, "w");
  if (d->log == NULL) ros2_usage_error("--log: cannot write '%s'", o->log_path);
  fprintf(d->log, o->mode == MODE_TWIST ? "t_s,cmd_vx,cmd_vy,cmd_vz,x,y,z\n" : "t_s,cmd_x,cmd_y,cmd_z,x,y,z\n");
}

static void create_entities(const arm_options *o, arm_dds *d) {
  d->participant = ros2_create_participant(o->domain);
  const dds_topic_descriptor_t *command_type = o->mode == MODE_TWIST
      ? &geometry_msgs_msg_dds__TwistStamped__desc : &geometry_msgs_msg_dds__PoseStamped__desc;
  dds_entity_t command_topic = ros2_create_topic(d->participant, command_type, o->command_topic);
  dds_entity_t pose_topic = ros2_create_topic(d->participant, &geometry_msgs_msg_dds__PoseStamped__desc, o->pose_topic);
  dds_qos_t *qos = ros2_create_qos(o->command_qos);
  d->reader = ros2_check(dds_create_reader(d->participant, command_topic, qos, NULL), "creating the command reader");
  dds_delete_qos(qos);
  qos = ros2_create_qos(o->pose_qos);
  d->writer = ros2_check(dds_create_writer(d->participant, pose_topic, qos, NULL), "creating the pose writer");
  dds_delete_qos(qos);
  d->waitset = ros2_check(dds_create_waitset(d->participant), "creating the waitset");
  dds_entity_t ready = ros2_check(dds_create_readcondition(d->reader, DDS_ANY_STATE), "creating the read condition");
  ros2_check(dds_waitset_attach(d->waitset, ready, 0), "attaching the read condition");
}

/* Ticks at the rate; between ticks waits for commands. Waits are capped at 50 ms so a signal
 * (which can't safely wake a waitset) ends the loop promptly. */
static void run(const arm_options *o, arm_dds *d) {
  arm_state s;
  init_state(o, &s);
  double period = 1.0 / o->rate_hz;
  double start = ros2_monotonic_s();
  double next = start;
  while (!stop_requested) {
    take_commands(o, d, &s);
    double now = ros2_monotonic_s();
    if (now >= next) {
      step(o, &s, period, now);
      publish(o, d, &s, now - start);
      next += period;
      if (next < now) next = now + period; /* fell behind (stopped process): don't burst */
    }
    double wait = fmin(next - ros2_monotonic_s(), 0.05);
    if (wait > 0) dds_waitset_wait(d->waitset, NULL, 0, (dds_duration_t)(wait * 1e9));
  }
}

int main(int argc, char **argv) {
  ros2_program_name = "dyad_ros2_fake_arm";
  arm_options o;
  parse_arguments(argc, argv, &o);
  struct sigaction action;
  memset(&action, 0, sizeof action);
  action.sa_handler = on_signal;
  sigaction(SIGINT, &action, NULL);
  sigaction(SIGTERM, &action, NULL);
  arm_dds d;
  open_log(&o, &d);
  ros2_use_loopback_config();
  create_entities(&o, &d);
  printf("ready\n");
  fflush(stdout);
  run(&o, &d);
  dds_delete(d.participant);
  if (d.log != NULL) fclose(d.log);
  return 0;
}
