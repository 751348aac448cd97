/// ArmPlane and ArmMotion: the pure parts of the `ros2_cartesian` driver (no DDS, no clock: times
/// are passed in), so they are tested on their own.
///
/// ArmPlane maps the experiment's 2-D workspace (x, y in workspace units) onto a plane of the
/// robot's frame (metres):   p = origin + scale * (x * u + y * v),   u, v the unit vectors of the
/// configured axes (not parallel; not necessarily orthogonal). Back from a measured point p, the
/// workspace coordinates are those of its orthogonal projection onto the plane (the 2x2 Gram
/// system of u, v), and `off_plane` the signed distance along u x v, in workspace units.
/// Every point sent to the arm first goes through Clamp() into the workspace box (metres, the
/// robot's frame): the arm is never commanded outside it.
///
/// ArmMotion shapes what the arm is told so that it never jumps: towards a goal, a velocity whose
/// norm is at most max_velocity and the braking bound (stops within the distance d at
/// max_acceleration a, in steps of dt: VirtualRobot's bound) and which changes by at most a*dt per step; twist mode sends it, pose
/// mode integrates it into the setpoint it sends.
#pragma once

#include <array>
#include <cmath>

#include <dyad/status.hpp>

namespace dyad::cartesian {

using Vec3 = std::array<double, 3>;

inline Vec3 operator+(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
inline Vec3 operator-(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline Vec3 operator*(double s, const Vec3& a) { return {s * a[0], s * a[1], s * a[2]}; }
inline double Dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline double Norm(const Vec3& a) { return std::sqrt(Dot(a, a)); }
inline bool Finite(const Vec3& a) { return std::isfinite(a[0]) && std::isfinite(a[1]) && std::isfinite(a[2]); }

struct ArmPlaneOptions {
  Vec3 origin{0.4, 0.0, 0.3};   // robot frame, m: where the workspace's (0, 0) lies
  Vec3 x_axis{0.0, -1.0, 0.0};  // robot-frame direction of the workspace's +x (normalised)
  Vec3 y_axis{0.0, 0.0, 1.0};   // ... of +y
  double scale = 0.002;         // metres per workspace unit, > 0
  Vec3 box_min{0.2, -0.3, 0.1}, box_max{0.6, 0.3, 0.5};  // workspace box, robot frame, m

  // OK, or InvalidArgument naming the field and the broken rule (finite, axes not parallel,
  // min < max, the plane's origin inside the box).
  Status Validate() const;
};

class ArmPlane {
 public:
  struct Workspace {
    double x = 0, y = 0, off_plane = 0;  // workspace units
  };
  // REQUIRES: options.Validate().ok().
  explicit ArmPlane(const ArmPlaneOptions& options);
  Vec3 ToRobot(double x, double y) const;
  Workspace ToWorkspace(const Vec3& p) const;
  // The point of the box nearest to p (per axis); *clamped: p was outside.
  Vec3 Clamp(const Vec3& p, bool* clamped) const;
  bool Inside(const Vec3& p) const;
  const ArmPlaneOptions& options() const { return o_; }

 private:
  ArmPlaneOptions o_;
  Vec3 u_{}, v_{}, n_{};
  double inv_det_ = 0, uv_ = 0;  // Gram system of u, v (both unit): [[1, uv], [uv, 1]]
};

class ArmMotion {
 public:
  // max_velocity m/s, max_acceleration m/s^2, both > 0.
  ArmMotion(double max_velocity, double max_acceleration) : vmax_(max_velocity), amax_(max_acceleration) {}
  // The velocity for the next dt seconds from `from` towards `goal` (limits above); remembers it.
  Vec3 Toward(const Vec3& from, const Vec3& goal, double dt);
  // Brakes to rest at max_acceleration (watchdog, stale pose): the velocity for the next dt.
  Vec3 Brake(double dt);
  void Reset() { v_ = {0, 0, 0}; }
  const Vec3& velocity() const { return v_; }

 private:
  Vec3 Limit(Vec3 desired, double dt);
  double vmax_, amax_;
  Vec3 v_{0, 0, 0};
};

}  // namespace dyad::cartesian
