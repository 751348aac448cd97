/// The `web` component: one embedded web server per process (civetweb) with
///   - `/subject`: the subject's page (steer the robot with the mouse; see web_human.hpp),
///   - `/experimenter`: the experimenter's page,
///   - `/`: an index page, and the Foxglove WebSocket bridge over the graph's topics for
///     Foxglove ("Foxglove WebSocket" connection to ws://ADDRESS:PORT).
/// Pages are embedded in the plugin. The server binds 127.0.0.1 unless `address` says otherwise;
/// then a token is required (generated and printed when not given). Its Step (its own rate, the
/// pages' display rate, <= 60 Hz) sends the robot's newest position to the subject's pages and
/// reports dropped samples to Foxglove clients; samples reach the bridge through serialized
/// subscriptions and pointer samples leave on `pointer` as they come: nothing here ever waits
/// for a browser.
///
/// Why a component and not a runtime service: the runtime stays free of HTTP, a graph places the
/// server in the process the subject's browser should reach, and it is swapped or left out by
/// YAML like every other part.
#pragma once

#include <memory>

#include <dyad/component.hpp>
#include <dyad/msg/types.hpp>

#include "src/experimenter_channel.hpp"
#include "src/foxglove_bridge.hpp"
#include "src/run_events.hpp"
#include "src/subject_channel.hpp"
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
  void LogPointerDelays();
  Context* ctx_ = nullptr;
  WebServer::Options options_;
  std::string port_file_;
  std::string token_file_;          // params.token_file
  std::string token_shown_;         // what the printed URLs show for the token (see Configure)
  bool create_token_file_ = false;  // it did not exist at Configure: Activate creates it
  Input<msg::CartesianState>* robot_ = nullptr;   // owned by the runtime
  Output<msg::HumanInput>* pointer_ = nullptr;    // owned by the runtime
  Input<msg::Intention>* intention_ = nullptr;    // owned by the runtime
  Input<msg::IntentionLabel>* labels_ = nullptr;  // owned by the runtime
  Output<msg::Annotation>* notes_ = nullptr;      // owned by the runtime
  std::unique_ptr<ExperimenterChannel> experimenter_;
  struct StatsTable;
  std::shared_ptr<StatsTable> stats_;  // filled by the dyad/stats subscription
  std::shared_ptr<RunEvents> events_;  // filled by the dyad/processes and dyad/health subscriptions
  int64_t last_stats_ns_ = 0;
  msg::Annotation note_;
  std::unique_ptr<FoxgloveBridge> bridge_;
  std::unique_ptr<SubjectChannel> subject_;
  std::unique_ptr<WebServer> server_;
  msg::HumanInput pointer_sample_;
};

}  // namespace dyad::web
