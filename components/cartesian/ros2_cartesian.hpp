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
/// once, counted).
/// Staying put: a hold command (`hold: true`) means "stay where you are", its position is never
/// a goal; so do the watchdog (no fresh command for watchdog_s), a stale pose (none for
/// pose_timeout_s: stopped) and Deactivate. Staying put, twist mode: braking at max_acceleration
/// to a zero twist while the arm's pose is fresh, a zero twist at once without a fresh pose and at
/// Deactivate. Pose mode: the measured pose (clamped into the box) taken once, when the stay
/// begins with a fresh pose, and re-sent unchanged after (a sagging or pushed arm does not creep
/// away; a stale pose never becomes the target); nothing before the first pose. Motion after it
/// starts from the measured pose, at rest.
/// A silent arm: no pose within pose_timeout_s of the run's first step is an error (logged once, stopped
/// states published every step from then on, named again by Deactivate); with require_arm it
/// fails the run instead. Poses whose header.frame_id is not pose_frame (default: frame_id) are
/// refused (counted, logged once); pose_frame other than frame_id needs pose_transform (a fixed
/// transform: dyad reads no TF).
/// @endcomponent
#pragma once

#include <array>
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
  // Reads and validates the plane, the box, the limits, the mode and the pose frame.
  Status Configure(Context& ctx) override;
  // Notes the time: the arm has pose_timeout_s from here to send its first pose.
  Status Activate() override;
  // Takes the newest arm poses and command, then sends one twist or pose target (moving, or
  // staying put: see the file comment) and publishes the state (once a pose was seen, or
  // stopped once the first pose is overdue). Fails only with require_arm and no first pose.
  Status Step(const StepInfo& info) override;
  // Stays put one last time (a zero twist, or the measured pose re-sent) and logs what was
  // rejected, clamped, refused and lost; an arm that never sent a pose is an error here too.
  Status Deactivate() override;

 private:
  // A fixed transform from pose_frame into frame_id: p' = t + R(q) p.
  struct PoseTransform {
    Vec3 t{0, 0, 0};
    std::array<double, 4> q{0, 0, 0, 1};  // x, y, z, w; unit
    Vec3 Apply(const Vec3& p) const;
  };
  Status ConfigurePoseFrame(const Params& p, const std::string& prefix);
  void TakePoses(int64_t now_ns);
  void TakeCommand(int64_t now_ns);
  // The silent arm (no first pose in time) and the pose outages; an error only with require_arm.
  Status WatchArm(int64_t now_ns, bool stale_pose);
  Status Move(double dt, int64_t now_ns);
  // A hold, the watchdog, a stale pose, the end (dt 0): see the .cpp for what each mode sends.
  Status StayPut(int64_t now_ns, double dt, bool stale_pose);
  Status SendTwist(const Vec3& v, int64_t now_ns);
  Status SendPose(const Vec3& p, int64_t now_ns);
  Status PublishState(int64_t now_ns, bool stopped);
  std::string NoPoseMessage() const;
  std::string WhyNoPose() const;  // "; N poses refused: ..." or a hint where to look
  // Logs message() at `level` the first time *logged is false; the text is built only then
  // (steps at 100 Hz allocate nothing while a warned condition lasts).
  template <class Message>
  void LogOnce(Logger::Level level, bool* logged, Message message) {
    if (*logged) return;
    *logged = true;
    ctx_->log().Write(level, message() + " (logged once)");
  }
  template <class Message>
  void WarnOnce(bool* logged, Message message) { LogOnce(Logger::Level::kWarn, logged, message); }

  Context* ctx_ = nullptr;
  Input<msg::CartesianCommand>* command_ = nullptr;                // owned by the runtime
  Input<geometry_msgs::msg::dds_::PoseStamped_>* arm_pose_ = nullptr;
  Output<msg::CartesianState>* state_ = nullptr;
  Output<geometry_msgs::msg::dds_::TwistStamped_>* twist_ = nullptr;
  Output<geometry_msgs::msg::dds_::PoseStamped_>* pose_target_ = nullptr;
  std::optional<ArmPlane> plane_;
  std::optional<ArmMotion> motion_;
  bool twist_mode_ = true, require_arm_ = false;
  std::string frame_id_, pose_frame_;  // what is sent; what poses must come in
  std::optional<PoseTransform> pose_transform_;
  std::array<double, 4> orientation_{0, 0, 0, 1};  // of pose targets: x, y, z, w
  int64_t watchdog_ns_ = 0, pose_timeout_ns_ = 0;
  int64_t activated_ns_ = -1, last_step_ns_ = -1, last_command_ns_ = -1, last_pose_ns_ = -1;
  std::optional<Vec3> goal_, pose_, setpoint_;
  bool holding_ = false;  // the newest command is a hold
  bool moving_ = false;   // the previous step moved (else the next motion starts at the pose)
  std::optional<ArmPlane::Workspace> last_ws_;
  int64_t last_ws_ns_ = -1;
  double vx_ = 0, vy_ = 0;  // workspace units/s, from the last two poses
  uint64_t nonfinite_commands_ = 0, nonfinite_poses_ = 0, clamped_ = 0, outside_poses_ = 0, wrong_frame_poses_ = 0;
  uint64_t outages_ = 0;                          // times the pose went stale after a first one
  int64_t outage_start_ns_ = -1, outage_ns_ = 0;  // the current outage's start; their total
  bool nonfinite_command_logged_ = false, nonfinite_pose_logged_ = false, clamp_logged_ = false,
       outside_logged_ = false, stale_logged_ = false, watchdog_logged_ = false, wrong_frame_logged_ = false,
       no_pose_logged_ = false;
  msg::CartesianState out_;
  geometry_msgs::msg::dds_::TwistStamped_ twist_out_;
  geometry_msgs::msg::dds_::PoseStamped_ pose_out_;
};

}  // namespace dyad::cartesian
