#include "arm_plane.hpp"

#include <algorithm>
#include <sstream>
#include <string>

namespace dyad::cartesian {

namespace {
std::string Text(const Vec3& a) {
  std::ostringstream out;
  out << '[' << a[0] << ", " << a[1] << ", " << a[2] << ']';
  return out.str();
}
Vec3 Cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
Vec3 Unit(const Vec3& a) { return (1.0 / Norm(a)) * a; }
// Axes closer than this (|cos| of their angle) would amplify a small measurement error off the
// plane into a large workspace error: refused as parallel.
constexpr double kMaxAxisCos = 0.99;
}  // namespace

Status ArmPlaneOptions::Validate() const {
  for (const auto& [name, v] : {std::pair{"origin", origin}, {"x_axis", x_axis}, {"y_axis", y_axis},
                                 {"box_min", box_min}, {"box_max", box_max}})
    if (!Finite(v)) return Status::InvalidArgument(std::string(name) + ": " + Text(v) + " is not finite");
  if (!(std::isfinite(scale) && scale > 0)) return Status::InvalidArgument("scale: must be > 0 and finite, got " + std::to_string(scale));
  if (Norm(x_axis) < 1e-9) return Status::InvalidArgument("x_axis: must not be zero");
  if (Norm(y_axis) < 1e-9) return Status::InvalidArgument("y_axis: must not be zero");
  if (std::abs(Dot(Unit(x_axis), Unit(y_axis))) > kMaxAxisCos)
    return Status::InvalidArgument("x_axis " + Text(x_axis) + " and y_axis " + Text(y_axis) +
                                   " are (nearly) parallel: they must span a plane");
  for (int i = 0; i < 3; ++i)
    if (!(box_min[i] < box_max[i]))
      return Status::InvalidArgument("box_min " + Text(box_min) + " must be below box_max " + Text(box_max) + " on every axis");
  bool outside = false;
  for (int i = 0; i < 3; ++i) outside = outside || origin[i] < box_min[i] || origin[i] > box_max[i];
  if (outside) return Status::InvalidArgument("origin " + Text(origin) + " lies outside the box");
  return Status::OK();
}

ArmPlane::ArmPlane(const ArmPlaneOptions& options) : o_(options) {
  u_ = Unit(o_.x_axis);
  v_ = Unit(o_.y_axis);
  n_ = Unit(Cross(u_, v_));
  uv_ = Dot(u_, v_);
  inv_det_ = 1.0 / (1.0 - uv_ * uv_);
}

Vec3 ArmPlane::ToRobot(double x, double y) const { return o_.origin + o_.scale * (x * u_ + y * v_); }

ArmPlane::Workspace ArmPlane::ToWorkspace(const Vec3& p) const {
  const Vec3 d = p - o_.origin;
  const double a = Dot(d, u_), b = Dot(d, v_);
  // Solve [[1, uv], [uv, 1]] [s, t] = [a, b]: the projection is s*u + t*v.
  const double s = (a - uv_ * b) * inv_det_, t = (b - uv_ * a) * inv_det_;
  return {s / o_.scale, t / o_.scale, Dot(d, n_) / o_.scale};
}

Vec3 ArmPlane::Clamp(const Vec3& p, bool* clamped) const {
  Vec3 q = p;
  for (int i = 0; i < 3; ++i) q[i] = std::clamp(p[i], o_.box_min[i], o_.box_max[i]);
  if (clamped != nullptr) *clamped = q != p;
  return q;
}

bool ArmPlane::Inside(const Vec3& p) const {
  for (int i = 0; i < 3; ++i)
    if (!(p[i] >= o_.box_min[i] && p[i] <= o_.box_max[i])) return false;
  return true;
}

Vec3 ArmMotion::Limit(Vec3 desired, double dt) {
  if (const double n = Norm(desired); n > vmax_) desired = (vmax_ / n) * desired;
  Vec3 dv = desired - v_;
  if (const double n = Norm(dv), max = amax_ * dt; n > max) dv = (max / n) * dv;
  v_ = v_ + dv;
  return v_;
}

Vec3 ArmMotion::Toward(const Vec3& from, const Vec3& goal, double dt) {
  if (!(dt > 0)) return v_;
  const Vec3 d = goal - from;
  const double dist = Norm(d);
  if (dist < 1e-12) return Limit({0, 0, 0}, dt);
  // Reach the goal in one step if the limits allow, else as fast as braking in time allows: the
  // speed from which steps of a*dt less speed each stop within dist (VirtualRobot's bound, exact
  // in discrete time where sqrt(2 a d) overshoots).
  const double adt = amax_ * dt;
  const double braking = adt * (std::sqrt(0.25 + 2 * dist / (adt * dt)) - 0.5);
  const double speed = std::min({dist / dt, vmax_, braking});
  return Limit((speed / dist) * d, dt);
}

Vec3 ArmMotion::Brake(double dt) { return dt > 0 ? Limit({0, 0, 0}, dt) : v_; }

}  // namespace dyad::cartesian
