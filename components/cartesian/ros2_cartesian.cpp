#include "ros2_cartesian.hpp"

#include <cmath>
#include <cstdio>

namespace dyad::cartesian {

namespace {
using geometry_msgs::msg::dds_::PoseStamped_;
using geometry_msgs::msg::dds_::TwistStamped_;

int64_t SecondsToNs(double s) { return static_cast<int64_t>(std::llround(s * 1e9)); }

std::string Seconds(int64_t ns) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g s", ns * 1e-9);
  return text;
}

StatusOr<Vec3> Vec3Param(const Params& p, const std::string& key, const std::string& prefix) {
  const auto& l = p.DoubleList(key);
  if (l.size() != 3) return Status::InvalidArgument(prefix + key + ": must be [x, y, z], got " + std::to_string(l.size()) + " values");
  return Vec3{l[0], l[1], l[2]};
}

Vec3 PositionOf(const PoseStamped_& s) {
  return {s.pose().position().x(), s.pose().position().y(), s.pose().position().z()};
}

void SetStamp(int64_t now_ns, std_msgs::msg::dds_::Header_& h, const std::string& frame_id) {
  // builtin_interfaces/Time: the runtime clock (wall time under clock: wall), as ROS time.
  const int64_t sec = now_ns >= 0 ? now_ns / 1'000'000'000 : 0;
  h.stamp().sec(static_cast<int32_t>(sec));
  h.stamp().nanosec(static_cast<uint32_t>(now_ns >= 0 ? now_ns % 1'000'000'000 : 0));
  h.frame_id(frame_id);
}
}  // namespace

void Ros2Cartesian::Describe(ComponentSpec& spec) {
  spec.Summary("Drives a ROS 2 arm over DDS (MoveIt Servo twists or Cartesian pose targets): the workspace on a plane "
               "of the robot's frame, a workspace box, speed and acceleration limits, watchdogs (docs/ros2.md).");
  spec.Param("mode", "twist").OneOf({"twist", "pose"}).Doc(
      "twist: TwistStamped velocities (MoveIt Servo); pose: PoseStamped setpoints (Cartesian/impedance controllers)");
  spec.Param("frame_id", "base_link").Doc("header.frame_id of what is sent, the frame of every vector below");
  spec.Param("origin", std::vector<double>{0.4, 0.0, 0.3}).Unit("m").Doc("[x, y, z]: where the workspace's (0, 0) lies");
  spec.Param("x_axis", std::vector<double>{0.0, -1.0, 0.0}).Doc("[x, y, z]: direction of the workspace's +x (normalised)");
  spec.Param("y_axis", std::vector<double>{0.0, 0.0, 1.0}).Doc("[x, y, z]: direction of the workspace's +y; not parallel to x_axis");
  spec.Param("scale", 0.002).Min(1e-9).Unit("m per workspace unit").Doc("workspace units -> metres");
  spec.Param("box_min", std::vector<double>{0.2, -0.3, 0.1}).Unit("m").Doc("[x, y, z]: workspace box, lower corner");
  spec.Param("box_max", std::vector<double>{0.6, 0.3, 0.5}).Unit("m").Doc(
      "[x, y, z]: upper corner; nothing outside the box is ever sent (targets clamped, logged once, counted)");
  spec.Param("orientation", std::vector<double>{0, 0, 0, 1}).Doc("[x, y, z, w]: the orientation of pose targets");
  spec.Param("max_velocity", 0.25).Min(1e-9).Unit("m/s").Doc("speed limit (norm) of the twist or the setpoint");
  spec.Param("max_acceleration", 2.0).Min(1e-9).Unit("m/s^2").Doc("acceleration limit (norm)");
  spec.Param("watchdog_s", 0.5).Min(1e-6).Unit("s").Doc("no command this long: zero twist / setpoint held");
  spec.Param("pose_timeout_s", 0.5)
      .Min(1e-6)
      .Unit("s")
      .Doc(
          "no arm pose this long: stopped = true, zero twist / the measured pose re-sent, until poses return; none "
          "this long after the run's start: an error (logged, stopped states published)");
  spec.Param("require_arm", false)
      .Doc("true: no pose within pose_timeout_s of the run's start fails the run (false: an error on the log and the state)");
  spec.Param("pose_frame", "").Doc(
      "header.frame_id of the arm's poses; empty: frame_id. Poses in any other frame are refused (counted, logged once)");
  spec.Param("pose_transform", std::vector<double>{}).Doc(
      "[x, y, z, qx, qy, qz, qw]: pose_frame's fixed pose in frame_id (p = t + R(q) p_pose_frame); required when "
      "pose_frame is not frame_id (dyad reads no TF)");
  spec.Input<msg::CartesianCommand>("command").Doc("target position, workspace units");
  spec.Input<PoseStamped_>("arm_pose").Doc("the arm's measured pose (a ROS 2 topic)");
  spec.Output<msg::CartesianState>("state").Doc(
      "the arm's pose on the workspace plane; z: off the plane; stopped: watchdog, stale or no pose");
  spec.Output<TwistStamped_>("twist").Optional().Doc("mode twist: linear velocity (angular 0), bind to Servo's command topic");
  spec.Output<PoseStamped_>("pose_target").Optional().Doc("mode pose: the limited setpoint, bind to the controller's target topic");
}

Status Ros2Cartesian::Configure(Context& ctx) {
  ctx_ = &ctx;
  const Params& p = ctx.params();
  const std::string prefix = "components." + ctx.name() + ".params.";
  ArmPlaneOptions o;
  for (auto [key, field] : {std::pair{"origin", &o.origin}, {"x_axis", &o.x_axis}, {"y_axis", &o.y_axis},
                            {"box_min", &o.box_min}, {"box_max", &o.box_max}}) {
    auto v = Vec3Param(p, key, prefix);
    if (!v.ok()) return v.status();
    *field = *v;
  }
  o.scale = p.Double("scale");
  if (Status s = o.Validate(); !s.ok()) return Status::InvalidArgument(prefix + s.message());
  const auto& q = p.DoubleList("orientation");
  if (q.size() != 4 || !std::isfinite(q[0] + q[1] + q[2] + q[3]) ||
      std::abs(std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]) - 1) > 1e-6)
    return Status::InvalidArgument(prefix + "orientation: must be a unit quaternion [x, y, z, w]");
  orientation_ = {q[0], q[1], q[2], q[3]};
  plane_.emplace(o);
  motion_.emplace(p.Double("max_velocity"), p.Double("max_acceleration"));
  twist_mode_ = p.String("mode") == "twist";
  frame_id_ = p.String("frame_id");
  if (Status s = ConfigurePoseFrame(p, prefix); !s.ok()) return s;
  require_arm_ = p.Bool("require_arm");
  watchdog_ns_ = SecondsToNs(p.Double("watchdog_s"));
  pose_timeout_ns_ = SecondsToNs(p.Double("pose_timeout_s"));
  command_ = &ctx.input<msg::CartesianCommand>("command");
  arm_pose_ = &ctx.input<PoseStamped_>("arm_pose");
  state_ = &ctx.output<msg::CartesianState>("state");
  twist_ = &ctx.output<TwistStamped_>("twist");
  pose_target_ = &ctx.output<PoseStamped_>("pose_target");
  return Status::OK();
}

Status Ros2Cartesian::ConfigurePoseFrame(const Params& p, const std::string& prefix) {
  pose_frame_ = p.String("pose_frame").empty() ? frame_id_ : p.String("pose_frame");
  const auto& t = p.DoubleList("pose_transform");
  if (pose_frame_ == frame_id_) {
    if (!t.empty())
      return Status::InvalidArgument(prefix + "pose_transform: only for poses in another frame: set " + prefix +
                                     "pose_frame to the frame they come in (it is frame_id, '" + frame_id_ + "')");
    return Status::OK();
  }
  if (t.empty())
    return Status::InvalidArgument(prefix + "pose_frame: poses in '" + pose_frame_ + "' need " + prefix +
                                   "pose_transform ([x, y, z, qx, qy, qz, qw]: '" + pose_frame_ + "' in '" + frame_id_ +
                                   "', e.g. from `ros2 run tf2_ros tf2_echo " + frame_id_ + " " + pose_frame_ +
                                   "`); dyad reads no TF");
  const double n = std::sqrt(t.size() == 7 ? t[3] * t[3] + t[4] * t[4] + t[5] * t[5] + t[6] * t[6] : 0.0);
  if (t.size() != 7 || !std::isfinite(t[0] + t[1] + t[2] + n) || std::abs(n - 1) > 1e-6)
    return Status::InvalidArgument(prefix + "pose_transform: must be [x, y, z, qx, qy, qz, qw], finite, a unit quaternion");
  pose_transform_ = PoseTransform{{t[0], t[1], t[2]}, {t[3], t[4], t[5], t[6]}};
  return Status::OK();
}

Vec3 Ros2Cartesian::PoseTransform::Apply(const Vec3& p) const {
  // v' = v + 2w (u x v) + 2 u x (u x v), u the quaternion's vector part.
  const Vec3 u{q[0], q[1], q[2]};
  auto cross = [](const Vec3& a, const Vec3& b) {
    return Vec3{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
  };
  const Vec3 uv = cross(u, p);
  return t + p + (2 * q[3]) * uv + 2.0 * cross(u, uv);
}

// The first pose is awaited from the run's first step, not from here: a process activates before
// the start barrier (every process of the graph, and a subject's page, may still be on their way),
// which would spend the arm's time to answer on the others'.
Status Ros2Cartesian::Activate() {
  activated_ns_ = -1;
  return Status::OK();
}

void Ros2Cartesian::TakePoses(int64_t now_ns) {
  for (size_t i = arm_pose_->received().size() - arm_pose_->new_count(); i < arm_pose_->received().size(); ++i) {
    const PoseStamped_& m = arm_pose_->received()[i];
    if (m.header().frame_id() != pose_frame_) {
      ++wrong_frame_poses_;
      WarnOnce(&wrong_frame_logged_, [&] {
        return "the arm reported a pose in frame '" + m.header().frame_id() + "', not '" + pose_frame_ +
               "': refused (poses must come in frame_id; another frame: set pose_frame and pose_transform)";
      });
      continue;
    }
    const Vec3 p = pose_transform_ ? pose_transform_->Apply(PositionOf(m)) : PositionOf(m);
    if (!Finite(p)) {
      ++nonfinite_poses_;
      WarnOnce(&nonfinite_pose_logged_,
               [] { return std::string("the arm reported a pose with NaN or infinite coordinates: ignored"); });
      continue;
    }
    if (!plane_->Inside(p)) {
      ++outside_poses_;
      WarnOnce(&outside_logged_, [&] {
        return "the arm reported a pose outside the workspace box (" + std::to_string(p[0]) + ", " +
               std::to_string(p[1]) + ", " + std::to_string(p[2]) + "): it is only ever sent back into the box";
      });
    }
    pose_ = p;
    last_pose_ns_ = now_ns;
  }
}

void Ros2Cartesian::TakeCommand(int64_t now_ns) {
  if (command_->new_count() == 0) return;
  const msg::CartesianCommand& c = command_->received().back();
  if (!std::isfinite(c.x()) || !std::isfinite(c.y())) {
    ++nonfinite_commands_;
    WarnOnce(&nonfinite_command_logged_,
             [] { return std::string("a command with NaN or infinite coordinates: rejected, the goal is kept"); });
    return;
  }
  last_command_ns_ = now_ns;  // a hold feeds the watchdog
  holding_ = c.hold();
  if (holding_) return;       // "stay where you are": its position is never a goal
  bool clamped = false;
  goal_ = plane_->Clamp(plane_->ToRobot(c.x(), c.y()), &clamped);
  if (clamped) {
    ++clamped_;
    WarnOnce(&clamp_logged_, [&] {
      return "target (" + std::to_string(c.x()) + ", " + std::to_string(c.y()) +
             ") lies outside the workspace box: clamped into it";
    });
  }
}

Status Ros2Cartesian::Step(const StepInfo& info) {
  const int64_t now = info.now_ns;
  const double dt = last_step_ns_ < 0 ? 0 : (now - last_step_ns_) * 1e-9;
  last_step_ns_ = now;
  if (activated_ns_ < 0) activated_ns_ = now;  // the run's first step: the first pose is due pose_timeout_s after it
  TakePoses(now);
  TakeCommand(now);
  const bool stale_pose = last_pose_ns_ < 0 || now - last_pose_ns_ > pose_timeout_ns_;
  const bool stale_command = last_command_ns_ < 0 || now - last_command_ns_ > watchdog_ns_;
  if (Status s = WatchArm(now, stale_pose); !s.ok()) return s;
  if (stale_command && last_command_ns_ >= 0)
    WarnOnce(&watchdog_logged_, [] { return std::string("no command for watchdog_s: holding"); });
  if (!stale_command) watchdog_logged_ = false;
  const bool move = !stale_pose && !stale_command && !holding_ && goal_.has_value();
  if (Status s = move ? Move(dt, now) : StayPut(now, dt, stale_pose); !s.ok()) return s;
  moving_ = move;
  if (pose_) return PublishState(now, stale_pose || stale_command);
  return no_pose_logged_ ? PublishState(now, true) : Status::OK();
}

Status Ros2Cartesian::WatchArm(int64_t now_ns, bool stale_pose) {
  if (last_pose_ns_ < 0) {
    if (now_ns - activated_ns_ <= pose_timeout_ns_ || no_pose_logged_) return Status::OK();
    no_pose_logged_ = true;
    if (require_arm_) return Status::FailedPrecondition(NoPoseMessage() + " (require_arm)");
    ctx_->log().Error(NoPoseMessage() + ": stopped until one arrives (logged once)");
    return Status::OK();
  }
  if (stale_pose && outage_start_ns_ < 0) {
    outage_start_ns_ = last_pose_ns_;
    ++outages_;
    WarnOnce(&stale_logged_, [] { return std::string("no pose from the arm for pose_timeout_s: stopped"); });
  } else if (!stale_pose && outage_start_ns_ >= 0) {
    outage_ns_ += now_ns - outage_start_ns_;
    outage_start_ns_ = -1;
    stale_logged_ = false;
    ctx_->log().Info("poses from the arm again: moving");
  }
  return Status::OK();
}

std::string Ros2Cartesian::NoPoseMessage() const {
  return "no pose from the arm on '" + arm_pose_->topic() + "' within pose_timeout_s (" + Seconds(pose_timeout_ns_) +
         ") of the run's start" + WhyNoPose();
}

std::string Ros2Cartesian::WhyNoPose() const {
  std::string m;
  if (wrong_frame_poses_ > 0)
    m += "; " + std::to_string(wrong_frame_poses_) + " poses refused: not in frame '" + pose_frame_ + "'";
  else if (nonfinite_poses_ > 0)
    m += "; " + std::to_string(nonfinite_poses_) + " poses refused: NaN or infinite";
  else
    m += " (check the arm's pose topic name, domain_id, QoS and network)";
  return m;
}

Status Ros2Cartesian::Move(double dt, int64_t now_ns) {
  if (twist_mode_) return SendTwist(motion_->Toward(*pose_, *goal_, dt), now_ns);
  if (!moving_ || !setpoint_) setpoint_ = plane_->Clamp(*pose_, nullptr);  // starts where the arm is: no jump
  setpoint_ = plane_->Clamp(*setpoint_ + dt * motion_->Toward(*setpoint_, *goal_, dt), nullptr);
  return SendPose(*setpoint_, now_ns);
}

Status Ros2Cartesian::StayPut(int64_t now_ns, double dt, bool stale_pose) {
  if (twist_mode_) {
    // A hold or the watchdog with the arm in view brakes at max_acceleration (a velocity step can
    // trip an arm's reflexes); without a fresh pose, and at the end (dt 0), the twist is zero at once.
    const bool brake = !stale_pose && dt > 0;
    const Vec3 v = brake ? motion_->Brake(dt) : Vec3{0, 0, 0};
    if (!brake) motion_->Reset();
    return SendTwist(v, now_ns);
  }
  motion_->Reset();  // the next motion starts at rest, from where the arm is
  // Pose mode: the target becomes the measured pose once, when the stay begins with a fresh pose
  // (the arm stops where it is, not where the setpoint ran ahead to); then it is kept. Taking the
  // measured pose every step would let a sagging or pushed arm creep away, and a stale pose can be
  // far behind the arm: with no fresh pose the last target is kept, or nothing is sent.
  if (!stale_pose && pose_ && (moving_ || !setpoint_)) setpoint_ = plane_->Clamp(*pose_, nullptr);
  if (!setpoint_) return Status::OK();  // nothing to stay at yet: nothing is sent
  return SendPose(*setpoint_, now_ns);
}

Status Ros2Cartesian::SendTwist(const Vec3& v, int64_t now_ns) {
  SetStamp(now_ns, twist_out_.header(), frame_id_);
  twist_out_.twist().linear().x(v[0]);
  twist_out_.twist().linear().y(v[1]);
  twist_out_.twist().linear().z(v[2]);
  return twist_->Publish(twist_out_);
}

Status Ros2Cartesian::SendPose(const Vec3& p, int64_t now_ns) {
  SetStamp(now_ns, pose_out_.header(), frame_id_);
  auto& pos = pose_out_.pose().position();
  pos.x(p[0]);
  pos.y(p[1]);
  pos.z(p[2]);
  auto& o = pose_out_.pose().orientation();
  o.x(orientation_[0]);
  o.y(orientation_[1]);
  o.z(orientation_[2]);
  o.w(orientation_[3]);
  return pose_target_->Publish(pose_out_);
}

Status Ros2Cartesian::PublishState(int64_t now_ns, bool stopped) {
  const ArmPlane::Workspace ws = pose_ ? plane_->ToWorkspace(*pose_) : ArmPlane::Workspace{};  // no pose: 0, stopped
  if (last_pose_ns_ == now_ns && last_ws_ && now_ns > last_ws_ns_) {
    const double span = (now_ns - last_ws_ns_) * 1e-9;
    vx_ = (ws.x - last_ws_->x) / span;
    vy_ = (ws.y - last_ws_->y) / span;
  }
  if (last_pose_ns_ == now_ns) {
    last_ws_ = ws;
    last_ws_ns_ = now_ns;
  }
  out_.x(ws.x);
  out_.y(ws.y);
  out_.z(ws.off_plane);
  out_.vx(stopped ? 0 : vx_);
  out_.vy(stopped ? 0 : vy_);
  out_.vz(0);
  out_.stopped(stopped);
  return state_->Publish(out_);
}

Status Ros2Cartesian::Deactivate() {
  const int64_t end_ns = ctx_->clock().now_ns();
  const bool stale_at_end = last_pose_ns_ < 0 || end_ns - last_pose_ns_ > pose_timeout_ns_;
  const Status last = last_step_ns_ >= 0 ? StayPut(end_ns, 0, stale_at_end) : Status::OK();
  if (last_pose_ns_ < 0 && last_step_ns_ >= 0) {
    ctx_->log().Error("no pose from the arm on '" + arm_pose_->topic() + "' in the whole run: the arm was never driven" +
                      WhyNoPose());
  } else if (outages_ > 0) {
    const int64_t total = outage_ns_ + (outage_start_ns_ >= 0 ? ctx_->clock().now_ns() - outage_start_ns_ : 0);
    ctx_->log().Warn("the arm's poses stopped " + std::to_string(outages_) + " time(s), " + Seconds(total) +
                     " in all: stopped meanwhile");
  }
  if (nonfinite_commands_ + nonfinite_poses_ + clamped_ + outside_poses_ + wrong_frame_poses_ > 0)
    ctx_->log().Info("rejected " + std::to_string(nonfinite_commands_) + " non-finite commands and " +
                     std::to_string(nonfinite_poses_) + " non-finite poses; clamped " + std::to_string(clamped_) +
                     " targets into the box; the arm reported " + std::to_string(outside_poses_) +
                     " poses outside it; refused " + std::to_string(wrong_frame_poses_) + " poses not in frame '" +
                     pose_frame_ + "'");
  return last.ok() ? Status::OK() : last.WithContext("the last zero twist / pose");
}

}  // namespace dyad::cartesian
