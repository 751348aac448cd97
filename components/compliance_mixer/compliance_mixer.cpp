#include "compliance_mixer.hpp"

#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include <dyad/encode_sample.hpp>

namespace dyad::mixer {

namespace {
std::string Fixed(double v, const char* format = "%.1f") {
  char buf[32];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}
std::string Point(Vec2 p) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "(%g, %g)", p.x, p.y);
  return buf;
}
}  // namespace

void ComplianceMixer::Describe(ComponentSpec& spec) {
  spec.Summary("Blends human and robot positions into the driver's command (g*human + (1-g)*robot while engaged), "
               "saturates its change per step and per second, holds it when inputs go stale.");
  spec.Param("gain", 0.9).Range(0, 1).Live().Doc("weight of the human while engaged (the study: 0.9)");
  spec.Param("max_step", 5.0).Min(0).Live().Unit("workspace units").Doc(
      "max change of the command per step, vector norm (the study: 5; 0: no limit)");
  spec.Param("max_speed", 50.0).Min(0).Unit("workspace units/s").Doc(
      "max speed of the command, vector norm, on the runtime clock's time between commands: a burst of "
      "trigger samples moves it no faster (the study: 5 per 100 ms step = 50; 0: no limit)");
  spec.Param("mode", "blend").OneOf({"blend", "pi"}).Doc(
      "blend: command = blend; pi: command = state + kp*e + ki*integral(e), e = blend - state");
  spec.Param("kp", 1.0).Min(0).Doc("mode pi: proportional gain (kp 1, ki 0 = plain blend)");
  spec.Param("ki", 0.0).Min(0).Unit("1/s").Doc("mode pi: integral gain");
  spec.Param("integral_limit", 10.0).Min(0).Unit("workspace units * s").Doc(
      "mode pi: anti-windup clamp of the integral per axis (also frozen while the command saturates)");
  spec.Param("stale_timeout_s", 0.5).Min(1e-6).Unit("s").Doc(
      "an input without a sample for longer is stale (runtime clock): hold the last command; one whose "
      "writers are gone (DDS liveliness, across processes) is stale at once");
  spec.Param("state_period_s", 0.1).Min(1e-6).Unit("s").Doc(
      "the period of the driver's state (input state): no state for 5 periods (runtime clock) and the arm is lost, "
      "as when the driver reports stopped: the mixer holds at its last command until the arm is back");
  spec.Param("z", 0.0).Unit("workspace units").Doc("z of every command (planar robot)");
  spec.Input<msg::HumanInput>("human").Doc("the human's hand position and engaged flag");
  spec.Input<msg::Intention>("robot").Doc("the robot's intended position");
  spec.Input<msg::CartesianState>("state").Optional().Doc(
      "measured position: required by mode pi; bound, the mixer moves only while the arm is known (its state fresh, "
      "not stopped): before its first state, and while it is lost, hold commands (the driver stays where it is); the "
      "first motion, and the first after an outage, moves at most max_step from it; unbound, the first command is "
      "not limited");
  spec.Output<msg::CartesianCommand>("command").Doc(
      "target position for the driver; hold = stay where you are (inputs stale, arm lost or not known yet), at the "
      "last motion command, never the target");
}

Status ComplianceMixer::Configure(Context& ctx) {
  ctx_ = &ctx;
  const Params& p = ctx.params();
  MixerOptions o;
  o.gain = p.Double("gain");
  o.max_step = p.Double("max_step");
  o.max_speed = p.Double("max_speed");
  o.mode = p.String("mode") == "pi" ? Mode::kPi : Mode::kBlend;
  o.kp = p.Double("kp");
  o.ki = p.Double("ki");
  o.integral_limit = p.Double("integral_limit");
  o.stale_timeout_ns = static_cast<int64_t>(std::llround(p.Double("stale_timeout_s") * 1e9));
  o.state_timeout_ns = static_cast<int64_t>(std::llround(kStatePeriodsBeforeLost * p.Double("state_period_s") * 1e9));
  if (Status s = o.Validate(); !s.ok()) return Status::InvalidArgument("components." + ctx.name() + ".params." + s.message());
  z_ = p.Double("z");
  human_ = &ctx.input<msg::HumanInput>("human");
  robot_ = &ctx.input<msg::Intention>("robot");
  state_ = &ctx.input<msg::CartesianState>("state");
  command_ = &ctx.output<msg::CartesianCommand>("command");
  if (o.mode == Mode::kPi && !state_->bound())
    return Status::InvalidArgument("components." + ctx.name() + ".params.mode = pi: needs input 'state' bound to the driver's state topic");
  o.wait_for_state = state_->bound();
  if (!state_->bound() && (o.max_step > 0 || o.max_speed > 0))
    ctx.log().Warn("input 'state' is not bound: the first command cannot start from where the arm is, and is not "
                   "limited (bind it to the driver's state topic)");
  core_.emplace(o);
  if (state_->bound()) {  // the arm's outages go to the runtime's health topic too, when there is one
    auto w = ctx.AdvertiseSerialized("dyad/health", TypeInfoOf<msg::HealthEvent>());
    health_ = w.ok() ? *w : nullptr;
    if (!w.ok() && w.status().code() != Status::Code::kUnimplemented)  // unimplemented: a context without DDS
      ctx.log().Warn("dyad/health: " + w.status().ToString() + ": the arm's outages are only logged");
  }
  return Status::OK();
}

// An outage's edge on dyad/health (docs/components.md, compliance_mixer): action "arm lost" or
// "arm back", the state's topic, starved_s its length so far, renewals the outage's number.
void ComplianceMixer::ReportOutage(const char* action, int64_t lost_ns, int64_t now_ns) {
  if (health_ == nullptr) return;
  health_event_.header().source(ctx_->name());
  health_event_.header().sequence_number(health_event_.header().sequence_number() + 1);
  health_event_.header().stamp_ns(now_ns);
  health_event_.graph_name(ctx_->graph_name());
  health_event_.process_name("component '" + ctx_->name() + "'");
  health_event_.topic(state_->topic());
  health_event_.endpoint("reader");
  health_event_.action(action);
  health_event_.starved_s(lost_ns * 1e-9);
  health_event_.renewals(static_cast<uint32_t>(core_->arm_outages().count));
  const std::vector<uint8_t> cdr = EncodeSample(health_event_);
  if (cdr.empty() || !health_->Write(cdr, now_ns).ok()) ctx_->log().Warn(std::string("dyad/health: '") + action + "' not published");
}

// The arm's outages, said once each way (an outage is an event of the run, not a stale input).
void ComplianceMixer::LogArm(const MixerCore::Result& r, int64_t now_ns) {
  if (r.outage_started) {
    const std::string why = r.stopped ? "its driver reports stopped"
                                      : "no state on '" + state_->topic() + "' for more than " +
                                            std::to_string(core_->options().state_timeout_ns / 1'000'000) + " ms";
    ctx_->log().Warn("arm lost (" + why + "): holding at the last command " + Point(r.position) +
                     " until it is back");
    ReportOutage("arm lost", 0, now_ns);
  } else if (r.outage_ended_ns >= 0) {
    ctx_->log().Info("arm back after " + Fixed(r.outage_ended_ns * 1e-9) +
                     " s: moving again from its measured position, at most max_step per step");
    ReportOutage("arm back", r.outage_ended_ns, now_ns);
  }
}

Status ComplianceMixer::Step(const StepInfo& info) {
  MixerCore::Inputs in;
  // An input whose writers are gone (DDS liveliness: their process died, their link is down) is
  // stale at once, not only after stale_timeout_s without a sample.
  auto received_at = [](const InputBase* input) {
    return input->writers_gone() ? std::numeric_limits<int64_t>::min() / 2 : input->last_receive_ns();
  };
  if (const msg::Intention* r = robot_->latest()) in.robot = {{r->x(), r->y()}, received_at(robot_)};
  if (const msg::HumanInput* h = human_->latest()) {
    in.human = {{h->x(), h->y()}, received_at(human_)};
    in.engaged = h->engaged();
  }
  if (const msg::CartesianState* s = state_->latest()) {
    in.state = {{s->x(), s->y()}, received_at(state_)};
    // A stop the driver reported between two of our steps counts, even if its newest state moves
    // again: the outage happened, and the first motion after it must start from where the arm is.
    // (It is seen when robot/state's depth keeps the states between two steps: docs/components.md.)
    in.stopped = false;
    for (const msg::CartesianState& each : state_->received()) in.stopped = in.stopped || each.stopped();
    in.stopped = in.stopped || (state_->new_count() == 0 && s->stopped());
  }

  const Params& p = ctx_->params();  // live: a change takes effect at this step
  core_->SetGainAndMaxStep(p.Double("gain"), p.Double("max_step"));
  const MixerCore::Result r = core_->Update(in, info.now_ns);
  if (first_step_ns_ < 0) first_step_ns_ = info.now_ns;
  const int64_t timeout = core_->options().stale_timeout_ns;
  // An input that has not sent its first sample yet is not stale while the graph starts (its
  // writer may simply step after us): hold silently for one stale timeout, then say so.
  const InputBase* input = r.stale == MixerCore::Stale::kHuman   ? static_cast<const InputBase*>(human_)
                           : r.stale == MixerCore::Stale::kRobot ? static_cast<const InputBase*>(robot_)
                                                                 : static_cast<const InputBase*>(state_);
  const bool never_received = r.hold && !r.non_finite && input->last_receive_ns() < 0;
  const bool starting = never_received && info.now_ns - first_step_ns_ <= timeout;
  LogArm(r, info.now_ns);
  if (r.arm_lost && r.stale == MixerCore::Stale::kState) {
    // said by LogArm
  } else if (r.hold && !holding_ && !starting) {
    holding_ = true;
    const bool state = r.stale == MixerCore::Stale::kState;
    const std::string ms = std::to_string(timeout / 1'000'000);
    const std::string stale_ms = std::to_string((state ? core_->options().state_timeout_ns : timeout) / 1'000'000);
    const std::string why = r.non_finite               ? "' not finite (NaN or infinite position)"
                            : never_received         ? "' has sent nothing in the " + ms + " ms since start"
                            : state && in.stopped    ? "' says stopped (its driver cannot move the arm)"
                            : input->writers_gone() ? "': its writer is gone (DDS liveliness)"
                                                     : "' stale (no sample for more than " + stale_ms + " ms)";
    ctx_->log().Warn(std::string("input '") + ToString(r.stale) + why + ": " +
                     (r.waiting_for_state ? "holding until the arm reports where it is"
                      : r.has_command     ? "holding the last command"
                                          : "no command yet"));
  } else if (!r.hold && holding_) {
    holding_ = false;
    ctx_->log().Info("inputs fresh again: mixing resumed");
  }
  if (!r.has_command) return Status::OK();
  held_ += r.hold;
  waiting_held_ += r.waiting_for_state;
  saturated_ += r.saturated;
  ++published_;
  out_.x(r.position.x);
  out_.y(r.position.y);
  out_.z(z_);
  out_.hold(r.hold);
  return command_->Publish(out_);
}

Status ComplianceMixer::Deactivate() {
  std::string summary = std::to_string(published_) + " commands published, " + std::to_string(held_) + " held, " +
                        std::to_string(saturated_) + " saturated";
  if (state_->bound()) {
    const MixerCore::Outages& o = core_->arm_outages();
    summary += "; arm lost " + std::to_string(o.count) + (o.count == 1 ? " time, " : " times, ") +
               Fixed(o.lost_ns * 1e-9) + " s" + (o.ongoing ? " (still lost at the end)" : "") + "; " +
               std::to_string(o.holds) + " holds sent while lost; " + std::to_string(waiting_held_) +
               " holds sent waiting for the arm's first state";
  }
  if (state_->bound() && published_ > 0 && waiting_held_ == published_) {
    ctx_->log().Warn(summary + ": the arm never reported where it is (no fresh state on '" + state_->topic() +
                     "' that is not stopped), so nothing moved");
  } else {
    ctx_->log().Info(summary);
  }
  return Status::OK();
}

}  // namespace dyad::mixer

DYAD_PLUGIN(registry) { registry.Add<dyad::mixer::ComplianceMixer>("compliance_mixer"); }
