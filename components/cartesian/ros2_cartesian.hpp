/// @component ros2_cartesian
/// trigger: rate_hz (a ROS 2 arm wants a steady stream: 50-100 Hz), never a topic
/// inputs:  command (CartesianCommand): target position, workspace units (virtual_cartesian's port)
///          arm_pose (geometry_msgs/msg/PoseStamped): the arm's measured pose (a ROS 2 topic)
/// outputs: state (CartesianState): the arm's pose projected onto the workspace plane;
///          z = distance off the plane, stopped = watchdog, stale or no pose
///          twist (geometry_msgs/msg/TwistStamped): mode twist (MoveIt Servo)
///          pose_target (geometry_msgs/msg/PoseStamped): mode pose (Cartesian/impedance controllers)
/// Drives a ROS 2 arm over DDS with no ROS installed (docs/ros2.md): the workspace maps onto a
/// plane of the robot's frame (ArmPlane, arm_plane.hpp); every point sent lies inside the
/// workspace box; the velocity (twist) or the setpoint's motion (pose) is limited in speed and
/// acceleration (ArmMotion); commands and poses with NaN or infinite values are rejected (logged
/// once, counted). Watchdog: no fresh command for watchdog_s -> zero twist / the setpoint held;
/// no pose for pose_timeout_s -> stopped, zero twist / setpoint held, until poses return.
/// @endcomponent
#pragma once

#include <optional>
#include <string>

#include <dyad/component.hpp>
#include <dyad/msg/ros2_types.hpp>
#include <dyad/msg/types.hpp>

#include "arm_plane.hpp"

namespace dyad::cartesian {

class Ros2Cartesian final : public Component {
 public:
  static void Describe(ComponentSpec& spec);
  // Reads and validates the plane, the box, the limits and the mode.
  Status Configure(Context& ctx) override;
  // Takes the newest arm poses and command, then sends one twist or pose target and publishes
  // the state (once a pose was seen).
  Status Step(const StepInfo& info) override;
  // Logs what was rejected or clamped.
  Status Deactivate() override;

 private:
  void TakePoses(int64_t now_ns);
  void TakeCommand(int64_t now_ns);
  Status SendTwist(const Vec3& v, int64_t now_ns);
  Status SendPose(const Vec3& p, int64_t now_ns);
  Status PublishState(int64_t now_ns, bool stopped);
  // Logs message() the first time *logged is false; the text is built only then (steps at
  // 100 Hz allocate nothing while a warned condition lasts).
  template <class Message>
  void WarnOnce(bool* logged, Message message) {
    if (*logged) return;
    *logged = true;
    ctx_->log().Warn(message() + " (logged once)");
  }

  Context* ctx_ = nullptr;
  Input<msg::CartesianCommand>* command_ = nullptr;                // owned by the runtime
  Input<geometry_msgs::msg::dds_::PoseStamped_>* arm_pose_ = nullptr;
  Output<msg::CartesianState>* state_ = nullptr;
  Output<geometry_msgs::msg::dds_::TwistStamped_>* twist_ = nullptr;
  Output<geometry_msgs::msg::dds_::PoseStamped_>* pose_target_ = nullptr;
  std::optional<ArmPlane> plane_;
  std::optional<ArmMotion> motion_;
  bool twist_mode_ = true;
  std::string frame_id_;
  std::array<double, 4> orientation_{0, 0, 0, 1};  // of pose targets: x, y, z, w
  int64_t watchdog_ns_ = 0, pose_timeout_ns_ = 0;
  int64_t last_step_ns_ = -1, last_command_ns_ = -1, last_pose_ns_ = -1;
  std::optional<Vec3> goal_, pose_, setpoint_;
  std::optional<ArmPlane::Workspace> last_ws_;
  int64_t last_ws_ns_ = -1;
  double vx_ = 0, vy_ = 0;  // workspace units/s, from the last two poses
  uint64_t nonfinite_commands_ = 0, nonfinite_poses_ = 0, clamped_ = 0, outside_poses_ = 0;
  bool nonfinite_command_logged_ = false, nonfinite_pose_logged_ = false, clamp_logged_ = false,
       outside_logged_ = false, stale_logged_ = false, watchdog_logged_ = false;
  msg::CartesianState out_;
  geometry_msgs::msg::dds_::TwistStamped_ twist_out_;
  geometry_msgs::msg::dds_::PoseStamped_ pose_out_;
};

}  // namespace dyad::cartesian
