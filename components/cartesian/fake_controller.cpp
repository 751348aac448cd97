// dyad_fake_controller: a Cartesian robot controller speaking the dyad UDP protocol (version 1,
// or version 2 with --key-file: docs/components.md), simulating the robot with VirtualRobot and
// its default limits. Used by the udp_cartesian tests and for trying the driver without hardware.
//
//   dyad_fake_controller --port 47000 [--drop N]... [--delay N:MS]... [--malform N]...
//                        [--initial X,Y] [--idle-exit S] [--key-file KEY]
//
// With --key-file it speaks protocol v2 only: hellos are welcomed with a fresh session, and a
// command is applied only with a valid MAC, the session pair it follows (or welcomed last) and a
// newer sequence; the others are counted as rejected (or out of order) and never acted on.
//
// Each valid command (sequence newer than the last applied) sets the robot's target and
// advances the simulation to the command's stamp_ns (so a stepped run stays deterministic);
// the reply is a state packet acknowledging it, sent to the command's sender. A command of a
// new driver session (a driver started again) restarts the simulation, as a new virtual robot.
// Fault injection, by the command's sequence number N:
//   --drop N      the command is lost: not applied, no reply
//   --delay N:MS  applied at once, the reply is sent MS milliseconds later (other replies are not held up)
// (N counts in every driver session.)
//   --malform N   applied, but the reply is garbage (bad magic)
// Prints "listening on port P" once bound, and its counts on SIGINT/SIGTERM or after
// --idle-exit seconds without a packet; exits 0.
#include <poll.h>
#include <signal.h>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "udp_auth.hpp"
#include "udp_protocol.hpp"
#include "udp_socket.hpp"
#include "virtual_robot.hpp"

namespace {

volatile std::sig_atomic_t g_stop = 0;
void OnSignal(int) { g_stop = 1; }

using Clock = std::chrono::steady_clock;
namespace udp = dyad::cartesian::udp;

struct Delayed {
  Clock::time_point due;
  std::array<uint8_t, udp::kMaxPacket> bytes;
  size_t size;
  sockaddr_in to;
};

// The command line, checked (the key file is read once the port is bound).
struct Options {
  long port = -1;
  double idle_exit_s = 0;
  std::set<uint32_t> drop, malform;
  std::vector<std::pair<uint32_t, int>> delay;  // (N, MS): command N's reply is sent MS ms later
  std::string key_file;
  dyad::cartesian::VirtualRobotOptions robot;
};

// Fills *o from the command line: -1 when the controller is to run, else the exit code (0 after
// --help, 2 for a bad option, having said why).
int ParseOptions(int argc, char** argv, Options* o) {
  std::vector<uint32_t> drop_list, malform_list;
  std::vector<std::string> delay_specs;
  std::vector<double> initial;
  CLI::App app{"A stand-in robot controller for udp_cartesian (protocol v1, or v2 with --key-file; "
               "docs/components.md): a virtual robot behind a UDP port, with fault injection."};
  app.add_option("--port", o->port, "UDP port to listen on")->required()->check(CLI::Range(1, 65535));
  app.add_option("--drop", drop_list, "drop the reply to command N (1-based; repeatable)");
  app.add_option("--delay", delay_specs, "delay the reply to command N by MS milliseconds: N:MS (repeatable)");
  app.add_option("--malform", malform_list, "send a malformed reply to command N (repeatable)");
  app.add_option("--initial", initial, "initial position X,Y")->delimiter(',')->expected(2);
  app.add_option("--key-file", o->key_file, "pre-shared key file (>= 32 bytes, mode 600): speak protocol v2 only");
  app.add_option("--idle-exit", o->idle_exit_s, "exit after this many seconds without a command (0: never)")
      ->check(CLI::NonNegativeNumber);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);  // --help: usage on stdout, 0
    return code == 0 ? 0 : 2;
  }
  o->drop = std::set<uint32_t>(drop_list.begin(), drop_list.end());
  o->malform = std::set<uint32_t>(malform_list.begin(), malform_list.end());
  for (const auto& spec : delay_specs) {
    unsigned n = 0;
    int ms = 0;
    char extra = 0;
    if (std::sscanf(spec.c_str(), "%u:%d%c", &n, &ms, &extra) != 2 || ms < 0) {
      std::fprintf(stderr, "dyad_fake_controller: --delay %s: wants N:MS\n", spec.c_str());
      return 2;
    }
    o->delay.emplace_back(n, ms);
  }
  if (initial.size() == 2) o->robot.initial = dyad::cartesian::Vec2{initial[0], initial[1]};
  if (auto s = o->robot.Validate(); !s.ok()) {
    std::fprintf(stderr, "dyad_fake_controller: %s\n", s.message().c_str());
    return 2;
  }
  return -1;
}

// What the controller counts, printed at exit.
struct Counts {
  uint64_t received = 0, sessions = 0, malformed_in = 0, out_of_order = 0, dropped = 0, delayed = 0,
           malformed_out = 0, rejected = 0;
};

// The virtual robot behind the port: the driver session it follows, the last command applied,
// the replies held back (--delay) and the counts. One packet at a time, on one thread.
class Controller {
 public:
  Controller(const Options& options, dyad::cartesian::UdpSocket* socket, std::string key)
      : o_(options), socket_(socket), key_(std::move(key)) {}

  // Sends the held-back replies due at `now`; true while some are still held back.
  bool SendDue(Clock::time_point now) {
    for (size_t i = 0; i < pending_.size();) {
      if (pending_[i].due <= now) {
        socket_->SendTo(pending_[i].bytes.data(), pending_[i].size, pending_[i].to).IgnoreError();  // UDP: the driver handles a lost reply
        pending_.erase(pending_.begin() + static_cast<long>(i));
      } else {
        ++i;
      }
    }
    return !pending_.empty();
  }

  // One packet of `size` bytes (in rx()) from `from`: a command applied and answered, a hello
  // welcomed (v2), or counted as refused and never acted on.
  void OnPacket(size_t size, const sockaddr_in& from) {
    ++counts_.received;
    udp::CommandPacket c;
    bool new_session = false;
    const bool accepted = key_.empty() ? AcceptPlain(size, &c, &new_session) : AcceptSigned(size, from, &c, &new_session);
    if (accepted) Apply(c, new_session, from);
  }

  std::array<uint8_t, udp::kMaxPacket>& rx() { return rx_; }

  void PrintCounts() const {
    const Counts& k = counts_;
    std::printf("commands received %llu, driver sessions %llu, last applied sequence %u, dropped %llu, delayed %llu, "
                "malformed replies %llu, malformed commands %llu, out of order %llu, rejected %llu\n",
                static_cast<unsigned long long>(k.received), static_cast<unsigned long long>(k.sessions), applied_,
                static_cast<unsigned long long>(k.dropped), static_cast<unsigned long long>(k.delayed),
                static_cast<unsigned long long>(k.malformed_out), static_cast<unsigned long long>(k.malformed_in),
                static_cast<unsigned long long>(k.out_of_order), static_cast<unsigned long long>(k.rejected));
  }

 private:
  // Protocol v2: a hello is welcomed with a fresh session (false: nothing to apply); a command
  // must carry a MAC with the key and the pair the controller follows (or welcomed last), and a
  // newer sequence. True with *c to apply; *new_session when it starts a new robot.
  bool AcceptSigned(size_t size, const sockaddr_in& from, udp::CommandPacket* c, bool* new_session) {
    if (size <= rx_.size() && udp::SignedKind(rx_.data(), size) == udp::kKindHello) {
      udp::HandshakePacket hello;
      if (udp::DecodeSignedHandshake(rx_.data(), size, udp::kKindHello, key_, &hello) != udp::Decode::kOk) {
        ++counts_.rejected;
        return false;
      }
      const udp::HandshakePacket welcome{v2_.Hello(hello.session), hello.session};
      socket_->SendTo(tx_.data(), udp::EncodeSigned(udp::kKindWelcome, welcome, key_, tx_), from).IgnoreError();
      return false;
    }
    uint32_t peer = 0;
    const udp::Decode d = size > rx_.size() ? udp::Decode::kBadLength : udp::DecodeSignedCommand(rx_.data(), size, key_, c, &peer);
    if (d == udp::Decode::kBadMac) return Count(&counts_.rejected);
    if (d != udp::Decode::kOk) return Count(&counts_.malformed_in);
    if (o_.drop.count(c->sequence)) return Count(&counts_.dropped);
    const auto verdict = v2_.Command(c->session, peer, c->sequence);
    if (verdict == udp::ControllerSessions::Verdict::kStaleSession) return Count(&counts_.rejected);
    if (verdict == udp::ControllerSessions::Verdict::kOld) return Count(&counts_.out_of_order);
    // A new driver starts a new robot; the same driver handshaking again (it missed replies)
    // keeps it.
    *new_session = verdict == udp::ControllerSessions::Verdict::kApplyNewSession &&
                   (!has_applied_ || c->session != driver_session_);
    return true;
  }

  // Protocol v1: a well-formed command, not dropped, newer than the last applied of its session.
  bool AcceptPlain(size_t size, udp::CommandPacket* c, bool* new_session) {
    if (size > rx_.size() || udp::DecodeCommand(rx_.data(), size, c) != udp::Decode::kOk) return Count(&counts_.malformed_in);
    if (o_.drop.count(c->sequence)) return Count(&counts_.dropped);
    if (has_applied_ && c->session == driver_session_ && !udp::Newer(c->sequence, applied_)) return Count(&counts_.out_of_order);
    *new_session = !has_applied_ || c->session != driver_session_;
    return true;
  }

  // Counts a refused packet; false (nothing to apply).
  static bool Count(uint64_t* counter) {
    ++*counter;
    return false;
  }

  // Sets the robot's target, advances it to the command's stamp and answers with its state (held
  // back or malformed as the options say).
  void Apply(const udp::CommandPacket& c, bool new_session, const sockaddr_in& from) {
    if (new_session) {  // a (new) driver: start afresh
      driver_session_ = c.session;
      robot_.emplace(o_.robot);
      ++counts_.sessions;
    }
    has_applied_ = true;
    applied_ = c.sequence;
    // A hold: stay where you are, never a goal (a robot not placed yet starts at the box's centre).
    if (c.hold) robot_->Hold(c.stamp_ns);
    else robot_->SetTarget({c.x, c.y}, c.stamp_ns);
    const auto& s = robot_->Advance(c.stamp_ns);
    udp::StatePacket st;
    st.session = key_.empty() ? session_ : v2_.controller_session();
    st.sequence = ++state_seq_;
    st.ack = c.sequence;
    st.stopped = s.stopped;
    st.stamp_ns = c.stamp_ns;
    st.x = s.position.x, st.y = s.position.y, st.z = c.z;
    st.vx = s.velocity.x, st.vy = s.velocity.y, st.vz = 0;
    size_t tx_size = 0;
    if (key_.empty()) {
      udp::Encode(st, tx_v1_);
      std::copy(tx_v1_.begin(), tx_v1_.end(), tx_.begin());
      tx_size = tx_v1_.size();
    } else {
      tx_size = udp::EncodeSigned(st, c.session, key_, tx_);
    }
    if (o_.malform.count(c.sequence)) {
      tx_[0] ^= 0xFF;  // bad magic
      ++counts_.malformed_out;
    }
    int delay_ms = -1;
    for (const auto& [seq, ms] : o_.delay)
      if (seq == c.sequence) delay_ms = ms;
    if (delay_ms >= 0) {
      ++counts_.delayed;
      pending_.push_back({Clock::now() + std::chrono::milliseconds(delay_ms), tx_, tx_size, from});
    } else {
      socket_->SendTo(tx_.data(), tx_size, from).IgnoreError();  // as above
    }
  }

  const Options& o_;
  dyad::cartesian::UdpSocket* socket_;
  const std::string key_;  // empty: protocol v1
  std::optional<dyad::cartesian::VirtualRobot> robot_;
  const uint32_t session_ = udp::NewSession();
  uint32_t driver_session_ = 0;
  std::array<uint8_t, udp::kMaxPacket> rx_{};
  std::array<uint8_t, udp::kStateSize> tx_v1_{};
  std::array<uint8_t, udp::kMaxPacket> tx_{};
  udp::ControllerSessions v2_;  // protocol v2: which driver session is followed
  std::vector<Delayed> pending_;
  bool has_applied_ = false;
  uint32_t applied_ = 0, state_seq_ = 0;
  Counts counts_;
};

}  // namespace

int main(int argc, char** argv) {
  Options options;
  if (int code = ParseOptions(argc, argv, &options); code >= 0) return code;
  auto socket = dyad::cartesian::UdpSocket::Open(static_cast<uint16_t>(options.port));
  if (!socket.ok()) {
    std::fprintf(stderr, "dyad_fake_controller: %s\n", socket.status().ToString().c_str());
    return 1;
  }
  std::string key;  // empty: protocol v1
  if (!options.key_file.empty()) {
    auto k = udp::ReadKeyFile(options.key_file);
    if (!k.ok()) {
      std::fprintf(stderr, "dyad_fake_controller: --key-file %s\n", k.status().message().c_str());
      return 2;
    }
    key = std::move(*k);
  }
  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);
  std::printf("listening on port %ld\n", options.port);
  std::fflush(stdout);

  Controller controller(options, &socket.value(), std::move(key));
  auto last_packet = Clock::now();
  while (!g_stop) {
    const auto now = Clock::now();
    const bool held_back = controller.SendDue(now);
    if (options.idle_exit_s > 0 && now - last_packet > std::chrono::duration<double>(options.idle_exit_s)) break;
    if (!socket->WaitReadable(held_back ? 1 : 50)) continue;
    sockaddr_in from{};
    const long n = socket->Receive(controller.rx().data(), controller.rx().size(), &from);
    if (n < 0) continue;
    last_packet = Clock::now();
    controller.OnPacket(static_cast<size_t>(n), from);
  }
  controller.PrintCounts();
  return 0;
}
