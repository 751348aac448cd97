/// Cartesian drivers: two component types with the same ports, swapped by `type:` in the graph
/// (nothing recompiled), and a test-pattern command source for bringing a driver up.
///
/// @component virtual_cartesian
/// trigger: command (the demo), or rate_hz (periodic; needed for the watchdog to act on silence)
/// inputs:  command (CartesianCommand): target position
/// outputs: state (CartesianState): simulated position and velocity, stopped = watchdog stop
/// A command with a NaN or infinite coordinate is rejected (logged once): the robot keeps its
/// last target, and the watchdog is not fed. A command with hold = true means "stay where you
/// are" (the command contract, docs/components.md): the robot keeps its target (feeding the
/// watchdog) and never moves towards the hold's x, y; a robot with no position yet starts at rest
/// at the centre of its workspace box.
/// params:
///   max_velocity (double, 100, > 0, units/s): speed limit, vector norm
///   max_acceleration (double, 2000, > 0, units/s^2): acceleration limit, vector norm
///   x_limits, y_limits (double list [min, max], [-60, 60], units): workspace box; targets
///     outside are clamped (logged once)
///   watchdog_s (double, 0.5, > 0, s): no command for longer: brake to rest, stopped = true
///   initial_position (double list, [] or [x, y], units): start there; []: at the first command
/// @endcomponent
/// Integrates over the runtime clock's elapsed time between its steps (VirtualRobot), so it
/// behaves the same under `clock: stepped` and `clock: wall`. Triggered by `command`, it steps
/// only when commands arrive, so its watchdog acts only when it runs periodically.
///
/// @component udp_cartesian
/// trigger: command (the demo), or rate_hz
/// inputs:  command (CartesianCommand): sent to the controller, one packet per new sample
///          (never one with a NaN or infinite coordinate: dropped, logged once, counted)
/// outputs: state (CartesianState): the controller's measured state, each at most once
/// params:
///   controller_host (string, "127.0.0.1"), controller_port (int, 47000): the controller
///   local_port (int, 0): our UDP port (0: any free port; the controller replies to the sender)
///   timeout_s (double, 0.5, > 0, s): no state for this long after a command (runtime clock):
///     the step fails and the run ends
///   reply_wait_ms (int, 20, [0, 1000], ms, wall time): after sending, wait this long at most for
///     the reply, so that the state of this step's command is published in this step
///   x_limits, y_limits (double list [min, max], [-60, 60], units): workspace box; targets
///     outside are clamped before they are sent (logged once, counted)
///   key_file (string, "", path): a pre-shared key (>= 32 bytes, mode 600) for protocol v2:
///     every packet authenticated (HMAC-SHA256), the session set by a handshake, replays and
///     packets of other sessions rejected and counted; empty: protocol v1, unauthenticated
/// A command with hold = true goes out with the hold flag: the controller stays where it is (the
/// command contract; the fake controller never moves towards a hold's x, y, which are sent
/// clamped to the workspace box like any position, but not counted as clamped targets).
/// Every accepted state is published once, in order (a late one in the next step, before the
/// reply to that step's command); out-of-order, duplicate and malformed packets are dropped.
/// @endcomponent
/// Protocol: docs/components.md (## udp_cartesian) and udp_protocol.hpp.
///
/// @component cartesian_pattern
/// rate_hz: periodic
/// outputs: command (CartesianCommand): a circle or figure eight, for driver bring-up
/// params: shape (circle | figure8), center ([0, 0]), radius (30), period_s (8), z (0)
/// @endcomponent
#pragma once

#include <array>
#include <optional>
#include <string>

#include <dyad/component.hpp>
#include <dyad/msg/types.hpp>

#include "udp_auth.hpp"
#include "udp_protocol.hpp"
#include "udp_socket.hpp"
#include "virtual_robot.hpp"

namespace dyad::cartesian {

class VirtualCartesian final : public Component {
 public:
  static void Describe(ComponentSpec& spec);
  // Reads and validates params; inactive afterwards.
  Status Configure(Context& ctx) override;
  // Takes the newest command (if any), advances the robot to info.now_ns, publishes its state
  // (once it has a position).
  Status Step(const StepInfo& info) override;

 private:
  Context* ctx_ = nullptr;
  Input<msg::CartesianCommand>* command_ = nullptr;  // owned by the runtime
  Output<msg::CartesianState>* state_ = nullptr;     // owned by the runtime
  std::optional<VirtualRobot> robot_;
  double z_ = 0;
  bool stopped_logged_ = false, clamp_logged_ = false, nonfinite_logged_ = false;
  msg::CartesianState out_;  // reused: no allocation per step
};

class UdpCartesian final : public Component {
 public:
  static void Describe(ComponentSpec& spec);
  // Reads params and resolves the controller's address; inactive afterwards.
  Status Configure(Context& ctx) override;
  // Opens the socket and starts a new session (sequence numbers from 1).
  Status Activate() override;
  // Receives (publishing what arrived), sends the newest command, waits for its reply (bounded)
  // and publishes it. Fails when the controller stays silent past timeout_s.
  Status Step(const StepInfo& info) override;
  // Logs the link's counts (sent, states, late, lost, out of order, malformed, missed replies).
  Status Deactivate() override;
  void Shutdown() override;

 private:
  // Takes every waiting datagram; publishes each accepted state at once, in order.
  Status Drain();
  udp::Decode DecodeReply(size_t n, udp::StatePacket* s, bool* is_state);
  Status Accept(const udp::StatePacket& s);
  void Send(const uint8_t* data, size_t size);
  template <class Done>
  StatusOr<bool> AwaitReply(Done done);
  Status Handshake(int64_t now_ns);
  Status SendCommand(const msg::CartesianCommand& c, int64_t now_ns);

  // v2: commands in a row without a reply before the driver handshakes again (the controller
  // may have restarted and forgotten our session).
  static constexpr int kUnansweredBeforeHandshake = 3;

  Context* ctx_ = nullptr;
  Input<msg::CartesianCommand>* command_ = nullptr;  // owned by the runtime
  Output<msg::CartesianState>* state_ = nullptr;     // owned by the runtime
  sockaddr_in controller_{};
  uint16_t local_port_ = 0;
  int64_t timeout_ns_ = 0;
  int reply_wait_ms_ = 0;
  std::optional<UdpSocket> socket_;
  std::array<uint8_t, udp::kCommandSize> v1_tx_{};
  std::array<uint8_t, udp::kMaxPacket> tx_{};  // v2 packets
  std::array<uint8_t, udp::kMaxPacket> rx_{};
  std::string key_;        // v2's pre-shared key; empty: protocol v1
  bool welcomed_ = false;  // v2: the handshake of this session is done
  uint32_t controller_session_ = 0;  // v2: the session the controller welcomed us with
  int unanswered_ = 0;     // v2: commands in a row without a reply
  uint64_t rejected_ = 0;  // packets from the controller's address with a bad MAC or of another session
  bool rejected_logged_ = false;
  uint32_t session_ = 0;   // ours, drawn at Activate
  uint32_t sent_seq_ = 0;
  uint32_t awaiting_ = 0;  // command whose reply is being waited for; 0: none
  udp::StateTracker tracker_;
  udp::StatePacket newest_{};
  bool has_newest_ = false;
  int64_t waiting_since_ns_ = -1;  // first command sent since the last accepted state
  std::array<double, 2> x_limits_{}, y_limits_{};  // workspace box: [min, max]
  uint64_t missed_replies_ = 0, foreign_ = 0, socket_errors_ = 0, nonfinite_ = 0, clamped_ = 0;
  bool malformed_logged_ = false, error_logged_ = false, nonfinite_logged_ = false, clamp_logged_ = false;
  msg::CartesianState out_;
};

class CartesianPattern final : public Component {
 public:
  static void Describe(ComponentSpec& spec);
  Status Configure(Context& ctx) override;
  Status Step(const StepInfo& info) override;

 private:
  Output<msg::CartesianCommand>* command_ = nullptr;  // owned by the runtime
  bool figure8_ = false;
  double cx_ = 0, cy_ = 0, radius_ = 30, period_s_ = 8, z_ = 0;
  int64_t t0_ = -1;
  msg::CartesianCommand out_;
};

}  // namespace dyad::cartesian
