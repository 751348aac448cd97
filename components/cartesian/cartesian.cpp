#include "cartesian.hpp"
#include "ros2_cartesian.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <numbers>
#include <string>

namespace dyad::cartesian {

namespace {
int64_t SecondsToNs(double s) { return static_cast<int64_t>(std::llround(s * 1e9)); }
bool FiniteCommand(const msg::CartesianCommand& c) {
  return std::isfinite(c.x()) && std::isfinite(c.y()) && std::isfinite(c.z());
}
std::string NonFiniteMessage(const msg::CartesianCommand& c) {
  return "command (" + std::to_string(c.x()) + ", " + std::to_string(c.y()) + ", " + std::to_string(c.z()) +
         ") is not finite: rejected, the robot keeps its last target (logged once)";
}
}  // namespace

// ---------------------------------------------------------------------------------------------
// virtual_cartesian

void VirtualCartesian::Describe(ComponentSpec& spec) {
  spec.Summary("A simulated 2-DOF prismatic robot: workspace box, velocity and acceleration limits (vector norm), "
               "watchdog stop on stale commands.");
  spec.Param("max_velocity", 100.0).Min(1e-9).Unit("workspace units/s").Doc("speed limit, vector norm");
  spec.Param("max_acceleration", 2000.0).Min(1e-9).Unit("workspace units/s^2").Doc("acceleration limit, vector norm");
  spec.Param("x_limits", std::vector<double>{-60, 60}).Unit("workspace units").Doc("[min, max] of x; targets outside are clamped");
  spec.Param("y_limits", std::vector<double>{-60, 60}).Unit("workspace units").Doc("[min, max] of y; targets outside are clamped");
  spec.Param("watchdog_s", 0.5).Min(1e-6).Unit("s").Doc(
      "no command for longer (runtime clock): brake to rest and report stopped (acts when stepped periodically)");
  spec.Param("initial_position", std::vector<double>{}).Unit("workspace units").Doc(
      "[x, y] start position; []: start at rest at the first motion command (a hold first: the box's centre)");
  spec.Input<msg::CartesianCommand>("command").Doc("target position");
  spec.Output<msg::CartesianState>("state").Doc("simulated position and velocity; stopped = watchdog stop");
}

Status VirtualCartesian::Configure(Context& ctx) {
  ctx_ = &ctx;
  const Params& p = ctx.params();
  VirtualRobotOptions o;
  o.max_velocity = p.Double("max_velocity");
  o.max_acceleration = p.Double("max_acceleration");
  const auto& xl = p.DoubleList("x_limits");
  const auto& yl = p.DoubleList("y_limits");
  const auto& init = p.DoubleList("initial_position");
  const std::string prefix = "components." + ctx.name() + ".params.";
  if (xl.size() != 2) return Status::InvalidArgument(prefix + "x_limits: must be [min, max]");
  if (yl.size() != 2) return Status::InvalidArgument(prefix + "y_limits: must be [min, max]");
  if (!init.empty() && init.size() != 2) return Status::InvalidArgument(prefix + "initial_position: must be [] or [x, y]");
  o.x_min = xl[0], o.x_max = xl[1], o.y_min = yl[0], o.y_max = yl[1];
  o.watchdog_ns = SecondsToNs(p.Double("watchdog_s"));
  if (init.size() == 2) o.initial = Vec2{init[0], init[1]};
  if (Status s = o.Validate(); !s.ok()) return Status::InvalidArgument(prefix + s.message());
  robot_.emplace(o);
  command_ = &ctx.input<msg::CartesianCommand>("command");
  state_ = &ctx.output<msg::CartesianState>("state");
  return Status::OK();
}

Status VirtualCartesian::Step(const StepInfo& info) {
  if (command_->new_count() > 0) {
    const msg::CartesianCommand& c = command_->received().back();
    if (!FiniteCommand(c)) {
      if (!nonfinite_logged_) {
        nonfinite_logged_ = true;
        ctx_->log().Warn(NonFiniteMessage(c));
      }
    } else if (c.hold()) {  // stay where you are: the hold's x, y are never a goal
      robot_->Hold(info.now_ns);
    } else if (robot_->SetTarget({c.x(), c.y()}, info.now_ns)) {
      z_ = c.z();
    }
    if (robot_->state().clamped && !clamp_logged_) {
      clamp_logged_ = true;
      ctx_->log().Warn("target (" + std::to_string(c.x()) + ", " + std::to_string(c.y()) +
                       ") outside the workspace: clamped (logged once)");
    }
  }
  const VirtualRobot::State& s = robot_->Advance(info.now_ns);
  if (!robot_->started()) return Status::OK();  // no position yet: nothing to report
  if (s.stopped && !stopped_logged_ && command_->last_receive_ns() >= 0) {
    ctx_->log().Warn("watchdog: no command for more than the watchdog timeout: stopping");
    stopped_logged_ = true;
  } else if (!s.stopped && stopped_logged_) {
    ctx_->log().Info("commands again: watchdog stop cleared");
    stopped_logged_ = false;
  }
  out_.x(s.position.x);
  out_.y(s.position.y);
  out_.z(z_);
  out_.vx(s.velocity.x);
  out_.vy(s.velocity.y);
  out_.vz(0);
  out_.stopped(s.stopped);
  return state_->Publish(out_);
}

// ---------------------------------------------------------------------------------------------
// udp_cartesian

void UdpCartesian::Describe(ComponentSpec& spec) {
  spec.Summary("Drives an external Cartesian controller over UDP (docs/components.md): commands out, measured "
               "state in, sequence numbers, timeouts.");
  spec.Param("controller_host", "127.0.0.1").Doc("the controller's address (dotted quad or name)");
  spec.Param("controller_port", int64_t{47000}).Range(1, 65535).Doc("the controller's UDP port");
  spec.Param("local_port", int64_t{0}).Range(0, 65535).Doc("our UDP port; 0: any free port");
  spec.Param("timeout_s", 0.5).Min(1e-6).Unit("s").Doc(
      "no state for this long after a command (runtime clock): the step fails and the run ends");
  spec.Param("reply_wait_ms", int64_t{20}).Range(0, 1000).Unit("ms").Doc(
      "wall time to wait for the reply to this step's command before publishing");
  spec.Param("x_limits", std::vector<double>{-60, 60}).Unit("workspace units").Doc(
      "[min, max] of x; targets outside are clamped before they are sent (logged once, counted)");
  spec.Param("y_limits", std::vector<double>{-60, 60}).Unit("workspace units").Doc(
      "[min, max] of y; targets outside are clamped before they are sent (logged once, counted)");
  spec.Param("key_file", "").Path().Doc(
      "pre-shared key (>= 32 bytes, mode 600): protocol v2, every packet authenticated (HMAC-SHA256), sessions by "
      "handshake; empty: protocol v1, unauthenticated (warned at start)");
  spec.Input<msg::CartesianCommand>("command").Doc("target position, one packet per new sample");
  spec.Output<msg::CartesianState>("state").Doc("the controller's measured state, each published once");
}

Status UdpCartesian::Configure(Context& ctx) {
  ctx_ = &ctx;
  const Params& p = ctx.params();
  auto addr = UdpSocket::Resolve(p.String("controller_host"), static_cast<uint16_t>(p.Int("controller_port")));
  if (!addr.ok()) return Status::InvalidArgument("components." + ctx.name() + ".params.controller_host", addr.status().message());
  controller_ = *addr;
  local_port_ = static_cast<uint16_t>(p.Int("local_port"));
  timeout_ns_ = SecondsToNs(p.Double("timeout_s"));
  reply_wait_ms_ = static_cast<int>(p.Int("reply_wait_ms"));
  const std::string prefix = "components." + ctx.name() + ".params.";
  for (const char* key : {"x_limits", "y_limits"}) {
    const auto& l = p.DoubleList(key);
    if (l.size() != 2 || !std::isfinite(l[0]) || !std::isfinite(l[1]) || !(l[0] < l[1]))
      return Status::InvalidArgument(prefix + key + ": must be [min, max], finite, min < max");
  }
  x_limits_ = {p.DoubleList("x_limits")[0], p.DoubleList("x_limits")[1]};
  y_limits_ = {p.DoubleList("y_limits")[0], p.DoubleList("y_limits")[1]};
  if (const std::string& file = p.String("key_file"); !file.empty()) {
    auto key = udp::ReadKeyFile(file);
    if (!key.ok()) return Status::InvalidArgument(prefix + "key_file", key.status().message());
    key_ = std::move(*key);
  } else {
    ctx.log().Warn("protocol v1: packets to and from the controller are not authenticated (anyone on the network "
                   "can command the robot); give params.key_file for protocol v2");
  }
  command_ = &ctx.input<msg::CartesianCommand>("command");
  state_ = &ctx.output<msg::CartesianState>("state");
  return Status::OK();
}

Status UdpCartesian::Activate() {
  auto s = UdpSocket::Open(local_port_);
  if (!s.ok()) return s.status();
  socket_.emplace(std::move(*s));
  session_ = udp::NewSession();
  sent_seq_ = 0;
  welcomed_ = false;
  ctx_->log().Info("controller " + ToString(controller_) + ", local port " + std::to_string(socket_->local_port()) +
                   ", session " + std::to_string(session_));
  return Status::OK();
}

// One datagram from the controller's address: the state it carries, or why not (v2: a welcome
// completes the handshake and carries no state).
udp::Decode UdpCartesian::DecodeReply(size_t n, udp::StatePacket* s, bool* is_state) {
  *is_state = false;
  if (n > rx_.size()) return udp::Decode::kBadLength;
  if (key_.empty()) {
    *is_state = true;
    return udp::DecodeState(rx_.data(), n, s);
  }
  if (udp::SignedKind(rx_.data(), n) == udp::kKindWelcome) {
    udp::HandshakePacket w;
    const udp::Decode d = udp::DecodeSignedHandshake(rx_.data(), n, udp::kKindWelcome, key_, &w);
    if (d != udp::Decode::kOk) return d;
    if (w.peer != session_) return udp::Decode::kBadMac;  // authentic, but not for this session: a replay
    controller_session_ = w.session;
    welcomed_ = true;
    return udp::Decode::kOk;
  }
  uint32_t peer = 0;
  const udp::Decode d = udp::DecodeSignedState(rx_.data(), n, key_, s, &peer);
  if (d != udp::Decode::kOk) return d;
  if (!welcomed_ || s->session != controller_session_ || peer != session_) return udp::Decode::kBadMac;
  *is_state = true;
  return udp::Decode::kOk;
}

Status UdpCartesian::Drain() {
  sockaddr_in from{};
  for (;;) {
    const long n = socket_->Receive(rx_.data(), rx_.size(), &from);
    if (n == UdpSocket::kNothing) return Status::OK();
    if (n < 0) {  // e.g. ECONNREFUSED: nothing listens at the controller's port (yet)
      ++socket_errors_;
      if (!error_logged_) {
        error_logged_ = true;
        ctx_->log().Warn("udp receive: " + std::string(std::strerror(static_cast<int>(-n))) + " (logged once)");
      }
      continue;
    }
    if (from.sin_addr.s_addr != controller_.sin_addr.s_addr || from.sin_port != controller_.sin_port) {
      ++foreign_;
      continue;
    }
    udp::StatePacket s;
    bool is_state = false;
    const udp::Decode d = DecodeReply(static_cast<size_t>(n), &s, &is_state);
    if (d == udp::Decode::kBadMac) {  // never acted on: another key, modified, or replayed
      ++rejected_;
      if (!rejected_logged_) {
        rejected_logged_ = true;
        ctx_->log().Warn("packet from the controller's address rejected (bad MAC or not of this session): dropped "
                         "(logged once, counted)");
      }
      continue;
    }
    if (d != udp::Decode::kOk) {
      tracker_.Malformed();
      if (!malformed_logged_) {
        malformed_logged_ = true;
        ctx_->log().Warn("malformed packet from the controller (" + std::string(udp::ToString(d)) + ", " +
                         std::to_string(n) + " bytes): dropped (logged once)");
      }
      continue;
    }
    if (!is_state) continue;  // the welcome
    if (Status st = Accept(s); !st.ok()) return st;
  }
}

// A decoded state of the current session: in order, published once.
Status UdpCartesian::Accept(const udp::StatePacket& s) {
  const uint64_t sessions = tracker_.counts().sessions;
  if (tracker_.Offer(s, awaiting_) == udp::StateTracker::Verdict::kOutOfOrder) return Status::OK();
  if (sessions > 0 && tracker_.counts().sessions != sessions)
    ctx_->log().Warn("controller session changed to " + std::to_string(s.session) + " (controller restarted?)");
  newest_ = s;
  has_newest_ = true;
  waiting_since_ns_ = -1;
  unanswered_ = 0;
  out_.x(s.x);
  out_.y(s.y);
  out_.z(s.z);
  out_.vx(s.vx);
  out_.vy(s.vy);
  out_.vz(s.vz);
  out_.stopped(s.stopped);
  return state_->Publish(out_);
}

void UdpCartesian::Send(const uint8_t* data, size_t size) {
  if (size == 0) return;  // v2: not signed (OpenSSL failed): never sent unsigned
  if (Status s = socket_->SendTo(data, size, controller_); !s.ok()) {
    ++socket_errors_;
    if (!error_logged_) {
      error_logged_ = true;
      ctx_->log().Warn(s.message() + " (logged once)");
    }
  }
}

// Drains until `done` holds or reply_wait_ms (wall time) has passed; returns `done`.
template <class Done>
StatusOr<bool> UdpCartesian::AwaitReply(Done done) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(reply_wait_ms_);
  for (;;) {
    if (done()) return true;
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()).count();
    if (left <= 0 || !socket_->WaitReadable(static_cast<int>(left))) return false;
    if (Status s = Drain(); !s.ok()) return s;
  }
}

// v2: a hello with our session, and a bounded wait for its welcome.
Status UdpCartesian::Handshake(int64_t now_ns) {
  udp::HandshakePacket hello;
  hello.session = session_;
  Send(tx_.data(), udp::EncodeSigned(udp::kKindHello, hello, key_, tx_));
  if (waiting_since_ns_ < 0) waiting_since_ns_ = now_ns;
  auto welcomed = AwaitReply([this] { return welcomed_; });
  return welcomed.ok() ? Status::OK() : welcomed.status();
}

Status UdpCartesian::SendCommand(const msg::CartesianCommand& c, int64_t now_ns) {
  udp::CommandPacket packet;
  packet.session = session_;
  packet.sequence = ++sent_seq_;
  packet.stamp_ns = now_ns;
  // The controller is sent nothing outside the workspace box, whatever the mixer asked for.
  packet.x = std::clamp(c.x(), x_limits_[0], x_limits_[1]);
  packet.y = std::clamp(c.y(), y_limits_[0], y_limits_[1]);
  packet.z = c.z();
  packet.hold = c.hold();
  if (!c.hold() && (packet.x != c.x() || packet.y != c.y())) {  // a hold is no target
    ++clamped_;
    if (!clamp_logged_) {
      clamp_logged_ = true;
      ctx_->log().Warn("target (" + std::to_string(c.x()) + ", " + std::to_string(c.y()) +
                       ") outside the workspace: clamped to (" + std::to_string(packet.x) + ", " +
                       std::to_string(packet.y) + ") (logged once)");
    }
  }
  if (key_.empty()) {
    udp::Encode(packet, v1_tx_);
    Send(v1_tx_.data(), v1_tx_.size());
  } else {
    Send(tx_.data(), udp::EncodeSigned(packet, controller_session_, key_, tx_));
  }
  if (waiting_since_ns_ < 0) waiting_since_ns_ = now_ns;
  awaiting_ = sent_seq_;
  auto acked = AwaitReply([this] { return has_newest_ && newest_.ack == sent_seq_; });
  awaiting_ = 0;
  if (!acked.ok()) return acked.status();
  if (!*acked) {
    ++missed_replies_;
    // v2: a controller that stopped answering may have restarted and forgotten our session.
    if (!key_.empty() && ++unanswered_ >= kUnansweredBeforeHandshake) {
      welcomed_ = false;
      ctx_->log().Warn("no reply to " + std::to_string(unanswered_) + " commands: handshaking again");
      unanswered_ = 0;
    }
  }
  return Status::OK();
}

Status UdpCartesian::Step(const StepInfo& info) {
  if (Status s = Drain(); !s.ok()) return s;
  if (!key_.empty() && !welcomed_)
    if (Status s = Handshake(info.now_ns); !s.ok()) return s;
  if (command_->new_count() > 0 && !FiniteCommand(command_->received().back())) {
    ++nonfinite_;
    if (!nonfinite_logged_) {
      nonfinite_logged_ = true;
      ctx_->log().Warn(NonFiniteMessage(command_->received().back()) + "; not sent");
    }
  } else if (command_->new_count() > 0 && (key_.empty() || welcomed_)) {
    if (Status s = SendCommand(command_->received().back(), info.now_ns); !s.ok()) return s;
  }
  if (waiting_since_ns_ >= 0 && info.now_ns - waiting_since_ns_ > timeout_ns_)
    return Status::IOError("controller " + ToString(controller_),
                           std::string(key_.empty() || welcomed_ ? "no state" : "no welcome to our hello") + " for " +
                               std::to_string((info.now_ns - waiting_since_ns_) / 1'000'000) + " ms" +
                               (key_.empty() || welcomed_ ? " after a command" : "") + " (timeout_s)");
  return Status::OK();
}

Status UdpCartesian::Deactivate() {
  const auto& c = tracker_.counts();
  ctx_->log().Info("udp link: " + std::to_string(sent_seq_) + " commands sent, " + std::to_string(c.accepted) +
                   " states accepted, " + std::to_string(c.late) + " late, " + std::to_string(c.gaps) + " lost, " +
                   std::to_string(c.out_of_order) + " out of order, " + std::to_string(c.malformed) + " malformed, " +
                   std::to_string(missed_replies_) + " replies missed, " + std::to_string(foreign_) + " foreign, " +
                   std::to_string(socket_errors_) + " socket errors, " + std::to_string(c.sessions) +
                   " controller sessions, " + std::to_string(nonfinite_) + " non-finite commands not sent, " +
                   std::to_string(clamped_) + " clamped to the workspace, " + std::to_string(rejected_) +
                   " rejected (protocol " + (key_.empty() ? "v1, unauthenticated)" : "v2)"));
  return Status::OK();
}

void UdpCartesian::Shutdown() { socket_.reset(); }

// ---------------------------------------------------------------------------------------------
// cartesian_pattern

void CartesianPattern::Describe(ComponentSpec& spec) {
  spec.Summary("Commands a circle or figure eight: a test pattern for bringing up a Cartesian driver.");
  spec.Param("shape", "circle").OneOf({"circle", "figure8"}).Doc("the figure traced");
  spec.Param("center", std::vector<double>{0, 0}).Unit("workspace units").Doc("[x, y] centre");
  spec.Param("radius", 30.0).Min(0).Unit("workspace units").Doc("radius (figure8: half width)");
  spec.Param("period_s", 8.0).Min(1e-3).Unit("s").Doc("time for one lap");
  spec.Param("z", 0.0).Unit("workspace units").Doc("z of every command");
  spec.Output<msg::CartesianCommand>("command").Doc("the pattern's current point");
}

Status CartesianPattern::Configure(Context& ctx) {
  const Params& p = ctx.params();
  figure8_ = p.String("shape") == "figure8";
  const auto& c = p.DoubleList("center");
  if (c.size() != 2) return Status::InvalidArgument("components." + ctx.name() + ".params.center: must be [x, y]");
  cx_ = c[0], cy_ = c[1];
  radius_ = p.Double("radius");
  period_s_ = p.Double("period_s");
  z_ = p.Double("z");
  command_ = &ctx.output<msg::CartesianCommand>("command");
  return Status::OK();
}

Status CartesianPattern::Step(const StepInfo& info) {
  if (t0_ < 0) t0_ = info.now_ns;
  const double phase = 2 * std::numbers::pi * ((info.now_ns - t0_) * 1e-9) / period_s_;
  // Both shapes start at (cx + radius, cy).
  out_.x(cx_ + radius_ * std::cos(phase));
  out_.y(cy_ + radius_ * (figure8_ ? std::sin(2 * phase) / 2 : std::sin(phase)));
  out_.z(z_);
  out_.hold(false);
  return command_->Publish(out_);
}

}  // namespace dyad::cartesian

DYAD_PLUGIN(registry) {
  registry.Add<dyad::cartesian::VirtualCartesian>("virtual_cartesian");
  registry.Add<dyad::cartesian::UdpCartesian>("udp_cartesian");
  registry.Add<dyad::cartesian::CartesianPattern>("cartesian_pattern");
  registry.Add<dyad::cartesian::Ros2Cartesian>("ros2_cartesian");
}
