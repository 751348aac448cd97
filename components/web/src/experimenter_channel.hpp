/// ExperimenterChannel — the WebSocket behind the experimenter's page (`/experimenter/ws`).
///
/// Server -> page (JSON text, newest only per kind, at the web component's rate): {"op":"series",
/// "t":s, "nelbo":.., "congruence":.., "human":k, "robot":k} (the deliberator's N-ELBO, the
/// observer's P(C_t) and most likely primitives; null when not known yet), {"op":"stats","rows":
/// [{component, process, steps, mean_ms, p99_ms, max_ms, misses}]} once a second,
/// {"op":"events","items":[{t, text}]} once a second when any (RunEvents: restarts, failures,
/// endpoints renewed), {"op":"noted","t":s} when a note was published.
/// Page -> server: {"op":"note","text":".."} (the experimenter's token only; a viewer's page that
/// sends one is closed): published as an Annotation (author "experimenter")
/// on the web component's `notes` output, which the recorder keeps (stamped by the runtime clock,
/// so the analysis aligns it with everything else). Notes are capped at 4 KiB.
#pragma once

#include <atomic>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "web_server.hpp"

namespace dyad::web {

class ExperimenterChannel final : public ClientHandler {
 public:
  using NoteSink = std::function<void(const std::string& text)>;
  explicit ExperimenterChannel(NoteSink sink) : sink_(std::move(sink)) {}
  void SetServer(WebServer* server) { server_.store(server); }
  // Sends `json` to every page, replacing an unsent frame of the same kind (`channel`).
  void Broadcast(uint32_t channel, const std::string& json);

  void OnOpen(ClientId client, Role role) override;
  Status OnText(ClientId client, std::string_view text) override;
  Status OnBinary(ClientId client, std::span<const uint8_t> bytes) override;
  void OnClose(ClientId client) override;

 private:
  const NoteSink sink_;
  std::atomic<WebServer*> server_{nullptr};
  std::mutex mutex_;  // guards pages_, serialises sink_
  std::vector<ClientId> pages_;
  std::map<ClientId, Role> roles_;
};

}  // namespace dyad::web
