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

}  // namespace

int main(int argc, char** argv) {
  long port = -1;
  double idle_exit_s = 0;
  std::vector<uint32_t> drop_list, malform_list;
  std::vector<std::string> delay_specs;
  std::vector<double> initial;
  std::string key_file;
  CLI::App app{"A stand-in robot controller for udp_cartesian (protocol v1, or v2 with --key-file; "
               "docs/components.md): a virtual robot behind a UDP port, with fault injection."};
  app.add_option("--port", port, "UDP port to listen on")->required()->check(CLI::Range(1, 65535));
  app.add_option("--drop", drop_list, "drop the reply to command N (1-based; repeatable)");
  app.add_option("--delay", delay_specs, "delay the reply to command N by MS milliseconds: N:MS (repeatable)");
  app.add_option("--malform", malform_list, "send a malformed reply to command N (repeatable)");
  app.add_option("--initial", initial, "initial position X,Y")->delimiter(',')->expected(2);
  app.add_option("--key-file", key_file, "pre-shared key file (>= 32 bytes, mode 600): speak protocol v2 only");
  app.add_option("--idle-exit", idle_exit_s, "exit after this many seconds without a command (0: never)")
      ->check(CLI::NonNegativeNumber);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);  // --help: usage on stdout, 0
    return code == 0 ? 0 : 2;
  }
  std::set<uint32_t> drop(drop_list.begin(), drop_list.end()), malform(malform_list.begin(), malform_list.end());
  std::vector<std::pair<uint32_t, int>> delay;
  for (const auto& spec : delay_specs) {
    unsigned n = 0;
    int ms = 0;
    char extra = 0;
    if (std::sscanf(spec.c_str(), "%u:%d%c", &n, &ms, &extra) != 2 || ms < 0) {
      std::fprintf(stderr, "dyad_fake_controller: --delay %s: wants N:MS\n", spec.c_str());
      return 2;
    }
    delay.emplace_back(n, ms);
  }
  dyad::cartesian::VirtualRobotOptions options;
  if (initial.size() == 2) options.initial = dyad::cartesian::Vec2{initial[0], initial[1]};
  if (auto s = options.Validate(); !s.ok()) {
    std::fprintf(stderr, "dyad_fake_controller: %s\n", s.message().c_str());
    return 2;
  }

  auto socket = dyad::cartesian::UdpSocket::Open(static_cast<uint16_t>(port));
  if (!socket.ok()) {
    std::fprintf(stderr, "dyad_fake_controller: %s\n", socket.status().ToString().c_str());
    return 1;
  }
  std::string key;  // empty: protocol v1
  if (!key_file.empty()) {
    auto k = udp::ReadKeyFile(key_file);
    if (!k.ok()) {
      std::fprintf(stderr, "dyad_fake_controller: --key-file %s\n", k.status().message().c_str());
      return 2;
    }
    key = std::move(*k);
  }
  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);
  std::printf("listening on port %ld\n", port);
  std::fflush(stdout);

  std::optional<dyad::cartesian::VirtualRobot> robot;
  const uint32_t session = udp::NewSession();
  uint32_t driver_session = 0;
  uint64_t sessions = 0;
  std::array<uint8_t, udp::kMaxPacket> rx{};
  std::array<uint8_t, udp::kStateSize> tx_v1{};
  std::array<uint8_t, udp::kMaxPacket> tx{};
  udp::ControllerSessions v2;  // protocol v2: which driver session is followed
  std::vector<Delayed> pending;
  bool has_applied = false;
  uint32_t applied = 0, state_seq = 0;
  uint64_t received = 0, malformed_in = 0, out_of_order = 0, dropped = 0, delayed = 0, malformed_out = 0, rejected = 0;
  auto last_packet = Clock::now();

  while (!g_stop) {
    // Send delayed replies that are due.
    const auto now = Clock::now();
    for (size_t i = 0; i < pending.size();) {
      if (pending[i].due <= now) {
        socket->SendTo(pending[i].bytes.data(), pending[i].size, pending[i].to).IgnoreError();  // UDP: the driver handles a lost reply
        pending.erase(pending.begin() + static_cast<long>(i));
      } else {
        ++i;
      }
    }
    if (idle_exit_s > 0 && now - last_packet > std::chrono::duration<double>(idle_exit_s)) break;
    if (!socket->WaitReadable(pending.empty() ? 50 : 1)) continue;
    sockaddr_in from{};
    const long n = socket->Receive(rx.data(), rx.size(), &from);
    if (n < 0) continue;
    last_packet = Clock::now();
    ++received;
    udp::CommandPacket c;
    bool new_session = false;
    const size_t size = static_cast<size_t>(n);
    if (!key.empty()) {
      // Protocol v2: a hello is welcomed with a fresh session; a command must carry a MAC with
      // the key and the pair the controller follows (or welcomed last), and a newer sequence.
      if (size <= rx.size() && udp::SignedKind(rx.data(), size) == udp::kKindHello) {
        udp::HandshakePacket hello;
        if (udp::DecodeSignedHandshake(rx.data(), size, udp::kKindHello, key, &hello) != udp::Decode::kOk) {
          ++rejected;
          continue;
        }
        const udp::HandshakePacket welcome{v2.Hello(hello.session), hello.session};
        socket->SendTo(tx.data(), udp::EncodeSigned(udp::kKindWelcome, welcome, key, tx), from).IgnoreError();
        continue;
      }
      uint32_t peer = 0;
      const udp::Decode d = size > rx.size() ? udp::Decode::kBadLength : udp::DecodeSignedCommand(rx.data(), size, key, &c, &peer);
      if (d == udp::Decode::kBadMac) {
        ++rejected;
        continue;
      }
      if (d != udp::Decode::kOk) {
        ++malformed_in;
        continue;
      }
      if (drop.count(c.sequence)) {
        ++dropped;
        continue;
      }
      const auto verdict = v2.Command(c.session, peer, c.sequence);
      if (verdict == udp::ControllerSessions::Verdict::kStaleSession) {
        ++rejected;
        continue;
      }
      if (verdict == udp::ControllerSessions::Verdict::kOld) {
        ++out_of_order;
        continue;
      }
      // A new driver starts a new robot; the same driver handshaking again (it missed replies)
      // keeps it.
      new_session = verdict == udp::ControllerSessions::Verdict::kApplyNewSession &&
                    (!has_applied || c.session != driver_session);
    } else {
      if (size > rx.size() || udp::DecodeCommand(rx.data(), size, &c) != udp::Decode::kOk) {
        ++malformed_in;
        continue;
      }
      if (drop.count(c.sequence)) {
        ++dropped;
        continue;
      }
      if (has_applied && c.session == driver_session && !udp::Newer(c.sequence, applied)) {
        ++out_of_order;
        continue;
      }
      new_session = !has_applied || c.session != driver_session;
    }
    if (new_session) {  // a (new) driver: start afresh
      driver_session = c.session;
      robot.emplace(options);
      ++sessions;
    }
    has_applied = true;
    applied = c.sequence;
    // A hold: stay where you are, never a goal (a robot not placed yet starts at the box's centre).
    if (c.hold) robot->Hold(c.stamp_ns);
    else robot->SetTarget({c.x, c.y}, c.stamp_ns);
    const auto& s = robot->Advance(c.stamp_ns);
    udp::StatePacket st;
    st.session = key.empty() ? session : v2.controller_session();
    st.sequence = ++state_seq;
    st.ack = c.sequence;
    st.stopped = s.stopped;
    st.stamp_ns = c.stamp_ns;
    st.x = s.position.x, st.y = s.position.y, st.z = c.z;
    st.vx = s.velocity.x, st.vy = s.velocity.y, st.vz = 0;
    size_t tx_size = 0;
    if (key.empty()) {
      udp::Encode(st, tx_v1);
      std::copy(tx_v1.begin(), tx_v1.end(), tx.begin());
      tx_size = tx_v1.size();
    } else {
      tx_size = udp::EncodeSigned(st, c.session, key, tx);
    }
    if (malform.count(c.sequence)) {
      tx[0] ^= 0xFF;  // bad magic
      ++malformed_out;
    }
    int delay_ms = -1;
    for (const auto& [seq, ms] : delay)
      if (seq == c.sequence) delay_ms = ms;
    if (delay_ms >= 0) {
      ++delayed;
      pending.push_back({Clock::now() + std::chrono::milliseconds(delay_ms), tx, tx_size, from});
    } else {
      socket->SendTo(tx.data(), tx_size, from).IgnoreError();  // as above
    }
  }
  std::printf("commands received %llu, driver sessions %llu, last applied sequence %u, dropped %llu, delayed %llu, "
              "malformed replies %llu, malformed commands %llu, out of order %llu, rejected %llu\n",
              static_cast<unsigned long long>(received), static_cast<unsigned long long>(sessions), applied, static_cast<unsigned long long>(dropped),
              static_cast<unsigned long long>(delayed), static_cast<unsigned long long>(malformed_out),
              static_cast<unsigned long long>(malformed_in), static_cast<unsigned long long>(out_of_order),
              static_cast<unsigned long long>(rejected));
  return 0;
}
