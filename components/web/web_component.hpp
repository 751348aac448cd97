/// The `web` component: one embedded web server per process (civetweb) carrying the Foxglove
/// WebSocket bridge over the graph's topics, so an experimenter can watch a live (wall-clock)
/// experiment in Foxglove: open a "Foxglove WebSocket" connection to ws://ADDRESS:PORT.
///
/// @component web
/// Summary: embedded web server with a live Foxglove WebSocket bridge over the graph's topics.
/// Params:
///   address (string, 127.0.0.1): address to bind; anything but loopback requires a token
///   port (int, 8765, 0..65535): TCP port; 0 picks a free one (see port_file)
///   topics (string list, all): topics to advertise, by name or regular expression
///   writable (string list, none): topics Foxglove clients may publish on
///   token (string, ""): required as ?token= by clients; empty: none on loopback, generated
///     and printed otherwise (or from DYAD_WEB_TOKEN)
///   allowed_origins (string list): browser origins allowed besides localhost
///   max_clients (int, 8), client_buffer_kb (int, 4096), max_frame_kb (int, 1024)
///   port_file (string, ""): write the bound port there (tests, scripts)
/// @endcomponent
///
/// A component is stepped at its rate only to report each client's dropped samples as a status
/// message; samples reach clients through serialized subscriptions, never through Step().
/// Why a component and not a runtime service: the runtime stays free of HTTP, a graph places the
/// server where it wants it (the process the subject's browser reaches), and it is swapped or
/// left out by YAML like every other part.
#pragma once

#include <memory>

#include <dyad/component.hpp>

#include "src/foxglove_bridge.hpp"
#include "src/web_server.hpp"

namespace dyad::web {

class WebComponent final : public Component {
 public:
  static void Describe(ComponentSpec& spec);
  Status Configure(Context& ctx) override;
  Status Activate() override;  // starts the server
  Status Step(const StepInfo& info) override;
  Status Deactivate() override;  // stops it (every client closed)

 private:
  Context* ctx_ = nullptr;
  WebServer::Options options_;
  std::string port_file_;
  std::unique_ptr<FoxgloveBridge> bridge_;
  std::unique_ptr<WebServer> server_;
};

}  // namespace dyad::web
