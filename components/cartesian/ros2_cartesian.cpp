#include "ros2_cartesian.hpp"

#include <cmath>

namespace dyad::cartesian {

namespace {
using geometry_msgs::msg::dds_::PoseStamped_;
using geometry_msgs::msg::dds_::TwistStamped_;

int64_t SecondsToNs(double s) { return static_cast<int64_t>(std::llround(s * 1e9)); }

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
  spec.Param("pose_timeout_s", 0.5).Min(1e-6).Unit("s").Doc(
      "no arm pose this long: stopped = true, zero twist / setpoint held, until poses return");
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
  watchdog_ns_ = SecondsToNs(p.Double("watchdog_s"));
  pose_timeout_ns_ = SecondsToNs(p.Double("pose_timeout_s"));
  command_ = &ctx.input<msg::CartesianCommand>("command");
  arm_pose_ = &ctx.input<PoseStamped_>("arm_pose");
  state_ = &ctx.output<msg::CartesianState>("state");
  twist_ = &ctx.output<TwistStamped_>("twist");
  pose_target_ = &ctx.output<PoseStamped_>("pose_target");
  return Status::OK();
}

void Ros2Cartesian::TakePoses(int64_t now_ns) {
  for (size_t i = arm_pose_->received().size() - arm_pose_->new_count(); i < arm_pose_->received().size(); ++i) {
    const Vec3 p = PositionOf(arm_pose_->received()[i]);
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
    if (!setpoint_) setpoint_ = plane_->Clamp(p, nullptr);  // pose mode starts where the arm is: no jump
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
  last_command_ns_ = now_ns;  // a hold feeds the watchdog and keeps the goal
  if (c.hold() && goal_) return;
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
  TakePoses(now);
  TakeCommand(now);
  const bool stale_pose = last_pose_ns_ < 0 || now - last_pose_ns_ > pose_timeout_ns_;
  const bool stale_command = last_command_ns_ < 0 || now - last_command_ns_ > watchdog_ns_;
  if (stale_pose && last_pose_ns_ >= 0)
    WarnOnce(&stale_logged_, [] { return std::string("no pose from the arm for pose_timeout_s: stopped"); });
  if (!stale_pose) stale_logged_ = false;
  if (stale_command && last_command_ns_ >= 0)
    WarnOnce(&watchdog_logged_, [] { return std::string("no command for watchdog_s: holding"); });
  if (!stale_command) watchdog_logged_ = false;
  const bool move = !stale_pose && !stale_command && goal_.has_value();
  Status s;
  if (twist_mode_) {
    if (!move) motion_->Reset();  // Servo stops on a zero twist
    s = SendTwist(move ? motion_->Toward(*pose_, *goal_, dt) : Vec3{0, 0, 0}, now);
  } else if (setpoint_) {
    if (move) setpoint_ = plane_->Clamp(*setpoint_ + dt * motion_->Toward(*setpoint_, *goal_, dt), nullptr);
    else motion_->Reset();
    s = SendPose(*setpoint_, now);
  }
  if (!s.ok()) return s;
  return pose_ ? PublishState(now, stale_pose || stale_command) : Status::OK();
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
  const ArmPlane::Workspace ws = plane_->ToWorkspace(*pose_);
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
  if (nonfinite_commands_ + nonfinite_poses_ + clamped_ + outside_poses_ > 0)
    ctx_->log().Info("rejected " + std::to_string(nonfinite_commands_) + " non-finite commands and " +
                     std::to_string(nonfinite_poses_) + " non-finite poses; clamped " + std::to_string(clamped_) +
                     " targets into the box; the arm reported " + std::to_string(outside_poses_) + " poses outside it");
  return Status::OK();
}

}  // namespace dyad::cartesian
