#include "mixer_core.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <limits>

namespace dyad::mixer {

namespace {
std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}
Status Bad(const char* field, double value, const char* constraint) {
  return Status::InvalidArgument(std::string(field) + " = " + Num(value) + ": " + constraint);
}
}  // namespace

Status MixerOptions::Validate() const {
  if (!(gain >= 0 && gain <= 1)) return Bad("gain", gain, "must be in [0, 1]");
  if (!(max_step >= 0)) return Bad("max_step", max_step, "must be >= 0");
  if (!(max_speed >= 0)) return Bad("max_speed", max_speed, "must be >= 0");
  if (!(kp >= 0)) return Bad("kp", kp, "must be >= 0");
  if (!(ki >= 0)) return Bad("ki", ki, "must be >= 0");
  if (!(integral_limit >= 0)) return Bad("integral_limit", integral_limit, "must be >= 0");
  if (stale_timeout_ns <= 0) return Bad("stale_timeout_s", stale_timeout_ns * 1e-9, "must be > 0");
  return Status::OK();
}

Vec2 SaturateNorm(Vec2 delta, double max_norm, bool* clipped) {
  *clipped = false;
  if (max_norm <= 0) return delta;
  const double n = std::hypot(delta.x, delta.y);
  if (n <= max_norm) return delta;
  *clipped = true;
  const double k = max_norm / n;
  return {delta.x * k, delta.y * k};
}

const char* ToString(MixerCore::Stale stale) {
  switch (stale) {
    case MixerCore::Stale::kNone: return "none";
    case MixerCore::Stale::kRobot: return "robot";
    case MixerCore::Stale::kHuman: return "human";
    case MixerCore::Stale::kState: return "state";
  }
  return "?";
}

MixerCore::MixerCore(const MixerOptions& options) : options_(options) {
  assert(options_.Validate().ok());
}

double MixerCore::StepLimit(int64_t now_ns) const {
  double limit = options_.max_step > 0 ? options_.max_step : std::numeric_limits<double>::infinity();
  if (options_.max_speed > 0 && has_last_)
    limit = std::min(limit, options_.max_speed * std::max<int64_t>(now_ns - last_command_ns_, 0) * 1e-9);
  return limit;
}

MixerCore::Result MixerCore::Update(const Inputs& in, int64_t now_ns) {
  Result r;
  const bool pi = options_.mode == Mode::kPi;
  // Before the first command the arm's position must be known (wait_for_state): until it is, hold.
  const bool waiting = options_.wait_for_state && !has_last_ && !Fresh(in.state, now_ns);
  if (!Fresh(in.robot, now_ns)) r.stale = Stale::kRobot;
  else if (!Fresh(in.human, now_ns)) r.stale = Stale::kHuman;
  else if (pi && !Fresh(in.state, now_ns) && !waiting) r.stale = Stale::kState;
  if (r.stale == Stale::kNone) {  // fresh, but a position it uses must be a number
    auto finite = [](const Sample& s) { return std::isfinite(s.position.x) && std::isfinite(s.position.y); };
    const bool state_used = !waiting && (pi || (!has_last_ && in.state.receive_ns >= 0));
    if (!finite(in.robot)) r.stale = Stale::kRobot;
    else if (in.engaged && !finite(in.human)) r.stale = Stale::kHuman;
    else if (state_used && !finite(in.state)) r.stale = Stale::kState;
    r.non_finite = r.stale != Stale::kNone;
  }
  const double dt = last_update_ns_ >= 0 ? (now_ns - last_update_ns_) * 1e-9 : 0.0;
  last_update_ns_ = now_ns;

  if (r.stale != Stale::kNone) {
    r.has_command = has_last_;
    r.position = last_;
    r.hold = true;
    if (has_last_) last_command_ns_ = now_ns;
    return r;
  }

  const Vec2 robot = in.robot.position, human = in.human.position;
  const double g = options_.gain;
  // Not engaged: the robot alone (not a blend with g = 0, which would turn 0 * inf into NaN).
  const Vec2 target = in.engaged ? Vec2{g * human.x + (1 - g) * robot.x, g * human.y + (1 - g) * robot.y} : robot;

  if (waiting) {  // ask the driver to stay where it is (and report it) rather than go to `target`
    r.has_command = true;
    r.hold = true;
    r.position = target;
    r.stale = Stale::kState;
    r.waiting_for_state = true;
    return r;
  }

  Vec2 desired = target;
  Vec2 next_integral = integral_;  // kPi: kept below only if the command does not saturate (anti-windup)
  if (pi) {
    const Vec2 s = in.state.position;
    const Vec2 e{target.x - s.x, target.y - s.y};
    const double lim = options_.integral_limit;
    next_integral = {std::clamp(integral_.x + e.x * dt, -lim, lim), std::clamp(integral_.y + e.y * dt, -lim, lim)};
    desired = {s.x + options_.kp * e.x + options_.ki * next_integral.x,
               s.y + options_.kp * e.y + options_.ki * next_integral.y};
  }

  // Saturate against the previous command, or against the measured state for the first one.
  const bool have_ref = has_last_ || in.state.receive_ns >= 0;
  const Vec2 ref = has_last_ ? last_ : in.state.position;
  Vec2 command = desired;
  if (have_ref) {
    const Vec2 delta{desired.x - ref.x, desired.y - ref.y};
    const double limit = StepLimit(now_ns);
    Vec2 step = delta;
    if (limit == 0) {  // no time since the previous command: no motion (SaturateNorm reads 0 as none)
      step = {0, 0};
      r.saturated = delta.x != 0 || delta.y != 0;
    } else if (std::isfinite(limit)) {
      step = SaturateNorm(delta, limit, &r.saturated);
    }
    command = {ref.x + step.x, ref.y + step.y};
  }
  if (pi && !r.saturated) integral_ = next_integral;

  has_last_ = true;
  last_ = command;
  last_command_ns_ = now_ns;
  r.has_command = true;
  r.position = command;
  return r;
}

}  // namespace dyad::mixer
