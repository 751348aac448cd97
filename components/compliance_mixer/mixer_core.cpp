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
  if (state_timeout_ns <= 0) return Bad("state_timeout_s", state_timeout_ns * 1e-9, "must be > 0");
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

void MixerCore::TrackOutage(Result* r, bool lost, int64_t now_ns) {
  if (lost && !outages_.ongoing) {
    outages_.ongoing = true;
    ++outages_.count;
    lost_since_ns_ = now_ns;
    r->outage_started = true;
  } else if (!lost && outages_.ongoing) {
    outages_.ongoing = false;
    r->outage_ended_ns = now_ns - lost_since_ns_;
    lost_done_ns_ += r->outage_ended_ns;
  }
  if (outages_.ongoing) outages_.holds += r->has_command && r->hold;
  outages_.lost_ns = lost_done_ns_ + (outages_.ongoing ? now_ns - lost_since_ns_ : 0);
}

MixerCore::Result MixerCore::Update(const Inputs& in, int64_t now_ns) {
  Result r;
  const bool pi = options_.mode == Mode::kPi;
  auto finite = [](const Sample& s) { return std::isfinite(s.position.x) && std::isfinite(s.position.y); };
  const bool state_fresh = FreshState(in.state, now_ns);
  // The arm's position is known while its driver reports it (fresh) and can move it (not stopped).
  const bool tracked = options_.wait_for_state;
  const bool arm_unknown = tracked && (!state_fresh || in.stopped);
  if (tracked && !arm_unknown && finite(in.state)) {
    has_arm_ = true;
    arm_ = in.state.position;
  }
  const bool waiting = tracked && !has_last_ && arm_unknown;  // no motion before the arm is known
  const bool lost = tracked && has_last_ && arm_unknown;      // the arm went away after it
  if (lost) resync_ = true;
  if (!Fresh(in.robot, now_ns)) r.stale = Stale::kRobot;
  else if (!Fresh(in.human, now_ns)) r.stale = Stale::kHuman;
  else if ((pi && !state_fresh && !waiting) || lost) r.stale = Stale::kState;
  if (r.stale == Stale::kNone) {  // fresh, but a position it uses must be a number
    const bool from_state = !has_last_ || resync_;  // the reference of the saturation is the state
    const bool state_used = !waiting && (pi || (from_state && in.state.receive_ns >= 0));
    if (!finite(in.robot)) r.stale = Stale::kRobot;
    else if (in.engaged && !finite(in.human)) r.stale = Stale::kHuman;
    else if (state_used && !finite(in.state)) r.stale = Stale::kState;
    r.non_finite = r.stale != Stale::kNone;
  }
  r.arm_lost = lost;
  r.stopped = lost && in.stopped;
  const double dt = last_update_ns_ >= 0 ? (now_ns - last_update_ns_) * 1e-9 : 0.0;
  last_update_ns_ = now_ns;

  if (r.stale != Stale::kNone || waiting) {
    // A hold carries the position to hold: the previous motion command, else the arm's last
    // measured position, else the placeholder (0, 0); never the target (the command contract).
    r.hold = true;
    r.position = has_last_ ? last_ : has_arm_ ? arm_ : Vec2{};
    r.has_command = has_last_ || (waiting && r.stale == Stale::kNone);
    if (waiting && r.stale == Stale::kNone) {  // ask the driver to stay where it is (and report it)
      r.stale = Stale::kState;
      r.waiting_for_state = true;
    }
    if (r.has_command) last_command_ns_ = now_ns;
    if (tracked) TrackOutage(&r, lost, now_ns);
    return r;
  }
  Motion(in, now_ns, dt, &r);
  if (tracked) TrackOutage(&r, false, now_ns);
  return r;
}

void MixerCore::Motion(const Inputs& in, int64_t now_ns, double dt, Result* out) {
  Result& r = *out;
  const bool pi = options_.mode == Mode::kPi;
  const Vec2 robot = in.robot.position, human = in.human.position;
  const double g = options_.gain;
  // Not engaged: the robot alone (not a blend with g = 0, which would turn 0 * inf into NaN).
  const Vec2 target = in.engaged ? Vec2{g * human.x + (1 - g) * robot.x, g * human.y + (1 - g) * robot.y} : robot;

  // Saturate against the previous command, or against the measured state for the first one
  // (and the first after the arm was lost: it starts from where the arm is now).
  const bool from_state = (!has_last_ || resync_) && in.state.receive_ns >= 0;
  if (resync_) integral_ = {};  // what the PI loop summed before the outage is not about this arm position
  resync_ = false;
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
  const bool have_ref = has_last_ || from_state;
  const Vec2 ref = from_state ? in.state.position : last_;
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
}

}  // namespace dyad::mixer
