#include "virtual_robot.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <string>

namespace dyad::cartesian {

namespace {
Status Bad(const char* field, double value, const char* constraint) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "%s = %g: %s", field, value, constraint);
  return Status::InvalidArgument(buf);
}
double Norm(Vec2 v) { return std::hypot(v.x, v.y); }
Vec2 Shorten(Vec2 v, double max_norm) {
  const double n = Norm(v);
  if (n <= max_norm || n == 0) return v;
  const double k = max_norm / n;
  return {v.x * k, v.y * k};
}
}  // namespace

Status VirtualRobotOptions::Validate() const {
  if (!(max_velocity > 0)) return Bad("max_velocity", max_velocity, "must be > 0");
  if (!(max_acceleration > 0)) return Bad("max_acceleration", max_acceleration, "must be > 0");
  if (!(x_min < x_max)) return Bad("x_limits", x_min, "min must be < max");
  if (!(y_min < y_max)) return Bad("y_limits", y_min, "min must be < max");
  if (watchdog_ns <= 0) return Bad("watchdog_s", watchdog_ns * 1e-9, "must be > 0");
  if (initial && (initial->x < x_min || initial->x > x_max || initial->y < y_min || initial->y > y_max))
    return Bad("initial_position", initial->x, "must lie inside the workspace");
  return Status::OK();
}

VirtualRobot::VirtualRobot(const VirtualRobotOptions& options) : o_(options) {
  assert(o_.Validate().ok());
  if (o_.initial) {
    state_.position = *o_.initial;
    started_ = true;
  }
}

Vec2 VirtualRobot::Clamp(Vec2 p, bool* clamped) const {
  const Vec2 c{std::clamp(p.x, o_.x_min, o_.x_max), std::clamp(p.y, o_.y_min, o_.y_max)};
  *clamped = c.x != p.x || c.y != p.y;
  return c;
}

bool VirtualRobot::SetTarget(Vec2 target, int64_t now_ns) {
  if (!std::isfinite(target.x) || !std::isfinite(target.y)) return false;
  target_ = Clamp(target, &state_.clamped);
  has_target_ = true;
  target_ns_ = now_ns;
  if (!started_) {  // no initial position: appear at rest at the first target
    state_.position = target_;
    started_ = true;
  }
  return true;
}

void VirtualRobot::Hold(int64_t now_ns) {
  if (!started_) {  // no position yet: at rest at the centre of the box, not where the hold says
    state_.position = {(o_.x_min + o_.x_max) / 2, (o_.y_min + o_.y_max) / 2};
    started_ = true;
  }
  // Stay where it is: a target the watchdog abandoned (braked short of it) is not taken up again.
  if (!has_target_ || state_.stopped) target_ = state_.position;
  has_target_ = true;
  target_ns_ = now_ns;
  state_.clamped = false;
}

const VirtualRobot::State& VirtualRobot::Advance(int64_t now_ns) {
  const int64_t elapsed = advanced_ns_ >= 0 ? std::max<int64_t>(now_ns - advanced_ns_, 0) : 0;
  advanced_ns_ = now_ns;
  const double dt = std::min(elapsed, o_.watchdog_ns) * 1e-9;
  const bool fresh = has_target_ && now_ns - target_ns_ <= o_.watchdog_ns;
  state_.stopped = !fresh;
  if (dt <= 0) return state_;

  Vec2& p = state_.position;
  Vec2& v = state_.velocity;
  Vec2 v_des{0, 0};  // stale: brake to rest
  if (fresh) {
    const Vec2 d{target_.x - p.x, target_.y - p.y};
    const double dist = Norm(d);
    // Braking bound for discrete steps: from speed m*a*dt the robot stops after
    // a*dt^2*m(m+1)/2 units (exact for whole m), so m <= sqrt(1/4 + 2*dist/(a*dt^2)) - 1/2.
    const double adt = o_.max_acceleration * dt;
    const double brake = adt * (std::sqrt(0.25 + 2 * dist / (adt * dt)) - 0.5);
    const double speed = std::min({dist / dt, o_.max_velocity, brake});
    if (dist > 0) v_des = {d.x / dist * speed, d.y / dist * speed};
  }
  const Vec2 dv = Shorten({v_des.x - v.x, v_des.y - v.y}, o_.max_acceleration * dt);
  v = {v.x + dv.x, v.y + dv.y};
  p = {p.x + v.x * dt, p.y + v.y * dt};
  bool hit = false;
  const Vec2 inside = Clamp(p, &hit);
  if (hit) {
    if (inside.x != p.x) v.x = 0;
    if (inside.y != p.y) v.y = 0;
    p = inside;
  }
  return state_;
}

}  // namespace dyad::cartesian
