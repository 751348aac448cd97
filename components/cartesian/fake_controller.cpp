// dyad_fake_controller: a Cartesian robot controller speaking the dyad UDP protocol (version 1,
// docs/components.md), simulating the robot with VirtualRobot and its default limits. Used by
// the udp_cartesian tests and for trying the driver without hardware.
//
//   dyad_fake_controller --port 47000 [--drop N]... [--delay N:MS]... [--malform N]...
//                        [--initial X,Y] [--idle-exit S]
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
  std::array<uint8_t, udp::kStateSize> bytes;
  sockaddr_in to;
};

[[noreturn]] void Usage(const char* why) {
  std::fprintf(stderr, "dyad_fake_controller: %s\nusage: dyad_fake_controller --port P [--drop N]... "
                       "[--delay N:MS]... [--malform N]... [--initial X,Y] [--idle-exit S]\n", why);
  std::exit(2);
}

}  // namespace

int main(int argc, char** argv) {
  long port = -1;
  double idle_exit_s = 0;
  std::set<uint32_t> drop, malform;
  std::vector<std::pair<uint32_t, int>> delay;
  dyad::cartesian::VirtualRobotOptions options;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> const char* {
      if (i + 1 >= argc) Usage((a + " needs a value").c_str());
      return argv[++i];
    };
    if (a == "--port") port = std::strtol(next(), nullptr, 10);
    else if (a == "--drop") drop.insert(static_cast<uint32_t>(std::strtoul(next(), nullptr, 10)));
    else if (a == "--malform") malform.insert(static_cast<uint32_t>(std::strtoul(next(), nullptr, 10)));
    else if (a == "--delay") {
      unsigned n = 0;
      int ms = 0;
      if (std::sscanf(next(), "%u:%d", &n, &ms) != 2 || ms < 0) Usage("--delay wants N:MS");
      delay.emplace_back(n, ms);
    } else if (a == "--initial") {
      double x = 0, y = 0;
      if (std::sscanf(next(), "%lf,%lf", &x, &y) != 2) Usage("--initial wants X,Y");
      options.initial = dyad::cartesian::Vec2{x, y};
    } else if (a == "--idle-exit") idle_exit_s = std::strtod(next(), nullptr);
    else Usage(("unknown option " + a).c_str());
  }
  if (port <= 0 || port > 65535) Usage("--port 1..65535 is required");
  if (auto s = options.Validate(); !s.ok()) Usage(s.message().c_str());

  auto socket = dyad::cartesian::UdpSocket::Open(static_cast<uint16_t>(port));
  if (!socket.ok()) {
    std::fprintf(stderr, "dyad_fake_controller: %s\n", socket.status().ToString().c_str());
    return 1;
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
  std::array<uint8_t, udp::kStateSize> tx{};
  std::vector<Delayed> pending;
  bool has_applied = false;
  uint32_t applied = 0, state_seq = 0;
  uint64_t received = 0, malformed_in = 0, out_of_order = 0, dropped = 0, delayed = 0, malformed_out = 0;
  auto last_packet = Clock::now();

  while (!g_stop) {
    // Send delayed replies that are due.
    const auto now = Clock::now();
    for (size_t i = 0; i < pending.size();) {
      if (pending[i].due <= now) {
        (void)socket->SendTo(pending[i].bytes.data(), pending[i].bytes.size(), pending[i].to);
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
    if (static_cast<size_t>(n) > rx.size() || udp::DecodeCommand(rx.data(), static_cast<size_t>(n), &c) != udp::Decode::kOk) {
      ++malformed_in;
      continue;
    }
    if (drop.count(c.sequence)) {
      ++dropped;
      continue;
    }
    if (!has_applied || c.session != driver_session) {  // a (new) driver: start afresh
      driver_session = c.session;
      robot.emplace(options);
      ++sessions;
    } else if (!udp::Newer(c.sequence, applied)) {
      ++out_of_order;
      continue;
    }
    has_applied = true;
    applied = c.sequence;
    robot->SetTarget({c.x, c.y}, c.stamp_ns);
    const auto& s = robot->Advance(c.stamp_ns);
    udp::StatePacket st;
    st.session = session;
    st.sequence = ++state_seq;
    st.ack = c.sequence;
    st.stopped = s.stopped;
    st.stamp_ns = c.stamp_ns;
    st.x = s.position.x, st.y = s.position.y, st.z = c.z;
    st.vx = s.velocity.x, st.vy = s.velocity.y, st.vz = 0;
    udp::Encode(st, tx);
    if (malform.count(c.sequence)) {
      tx[0] ^= 0xFF;  // bad magic
      ++malformed_out;
    }
    int delay_ms = -1;
    for (const auto& [seq, ms] : delay)
      if (seq == c.sequence) delay_ms = ms;
    if (delay_ms >= 0) {
      ++delayed;
      pending.push_back({Clock::now() + std::chrono::milliseconds(delay_ms), tx, from});
    } else {
      (void)socket->SendTo(tx.data(), tx.size(), from);
    }
  }
  std::printf("commands received %llu, driver sessions %llu, last applied sequence %u, dropped %llu, delayed %llu, "
              "malformed replies %llu, malformed commands %llu, out of order %llu\n",
              static_cast<unsigned long long>(received), static_cast<unsigned long long>(sessions), applied, static_cast<unsigned long long>(dropped),
              static_cast<unsigned long long>(delayed), static_cast<unsigned long long>(malformed_out),
              static_cast<unsigned long long>(malformed_in), static_cast<unsigned long long>(out_of_order));
  return 0;
}
