// The Foxglove bridge's throughput to one client, without a graph in the way: FoxgloveBridge and
// WebServer as the web component wires them, fed 100-byte CDR samples as fast as one thread can,
// while a Foxglove client (npm @foxglove/ws-protocol, started by bench_web.sh) counts what it
// receives (connecting with the viewer's token, `bench-viewer-token-01`). Prints the port, waits for a subscription, feeds for SECONDS, then prints the fed
// count and the drops reported.
//   bench_bridge SECONDS
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>
#include <vector>

#include <dyad/msg/types.hpp>

#include "foxglove_bridge.hpp"
#include "web_server.hpp"

int main(int argc, char** argv) {
  using namespace dyad::web;
  const double seconds = argc > 1 ? std::atof(argv[1]) : 5;
  const dyad::TypeInfo& type = dyad::TypeInfoOf<dyad::msg::CartesianState>();
  FoxgloveBridge bridge("bench", {foxglove::Channel{1, "bench/samples", type.name, type.idl}}, {});
  WebServer::Options o;
  o.port = 0;
  o.tokens = {{Role::kViewer, "bench-viewer-token-01"}};
  o.endpoints = {WebServer::Endpoint{"/", {foxglove::kSubprotocol}, &bridge, {Role::kViewer}}};
  auto server = WebServer::Start(o);
  if (!server.ok()) {
    std::fprintf(stderr, "%s\n", server.status().message().c_str());
    return 1;
  }
  bridge.SetServer(server->get());
  std::printf("%d\n", (*server)->port());
  std::fflush(stdout);
  std::vector<uint8_t> cdr(100, 0);
  cdr[1] = 1;  // CDR little-endian encapsulation
  dyad::SerializedSample s;
  s.cdr = cdr;
  // Wait until the client subscribed (samples start being routed).
  while (bridge.samples_sent() == 0) {
    bridge.OnSample(1, s);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  uint64_t fed = 0, dropped = 0;
  auto take_drops = [&] {  // while the client is connected: its counts go with it
    for (auto c : (*server)->clients())
      for (const auto& [ch, n] : (*server)->TakeDrops(c)) dropped += n;
  };
  while (std::chrono::steady_clock::now() < end) {
    for (int i = 0; i < 4096; ++i, ++fed) {
      s.source_stamp_ns = static_cast<int64_t>(fed);
      bridge.OnSample(1, s);
    }
    take_drops();
  }
  take_drops();
  std::fprintf(stderr, "fed %llu samples in %.1f s (%.0f/s), %llu while the client was subscribed, %llu of them dropped in its buffer\n",
               static_cast<unsigned long long>(fed), seconds, fed / seconds,
               static_cast<unsigned long long>(bridge.samples_sent()), static_cast<unsigned long long>(dropped));
  return 0;
}
