/// ExperimenterChannel — the WebSocket behind the experimenter's page (`/experimenter/ws`).
///
/// Server -> page (JSON text, newest only per kind, at the web component's rate): {"op":"series",
/// "t":s, "nelbo":.., "congruence":.., "human":k, "robot":k} (the deliberator's N-ELBO, the
/// observer's P(C_t) and most likely primitives; null when not known yet), {"op":"stats","rows":
/// [{component, process, steps, mean_ms, p99_ms, max_ms, misses}]} once a second,
/// {"op":"events","items":[{t, text}]} once a second when any (RunEvents: restarts, failures,
/// endpoints renewed), {"op":"params","items":[{t, component, param, op, value, old_value,
/// reason, who, step, request_id}]} once a second when any (ParamAnswers: the last 20 answers on
/// dyad/params, newest last, whoever asked; op "applied", "refused" or "value"; t: wall seconds
/// when the web component heard it), {"op":"noted","length":n} when a note was published,
/// {"op":"param_sent","name":"C.P","request_id":".."} when a parameter request was published
/// (with "error" instead of "request_id" when it could not be: nothing was asked).
/// Page -> server, the experimenter's token only (a viewer's page that sends one is closed):
///   - {"op":"note","text":".."}: published as an Annotation (author "experimenter") on the web
///     component's `notes` output, which the recorder keeps (stamped by the runtime clock, so the
///     analysis aligns it with everything else). Notes are capped at 4 KiB.
///   - {"op":"param","name":"COMPONENT.PARAM","value":"0.5"}: a live parameter request
///     (docs/runtime.md, "Live parameters"): with "value" (YAML text, a string of at most 4 KiB)
///     it sets, without it gets. Only its shape is checked here (name: split at its first '.',
///     neither part empty, at most 256 bytes); the component's process checks the rest and
///     answers on dyad/params, which comes back in "params". The web component publishes it as
///     a ParamChange on dyad/param_requests (who "experimenter page").
/// A frame of any other shape closes the page.
#pragma once

#include <atomic>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "web_server.hpp"

namespace dyad::web {

// A live parameter request from the page, checked for its shape.
struct ParamRequest {
  std::string component, param;
  bool set = false;   // else get
  std::string value;  // YAML text (set)
  bool operator==(const ParamRequest&) const = default;
};

class ExperimenterChannel final : public ClientHandler {
 public:
  using NoteSink = std::function<void(const std::string& text)>;
  // Publishes the request; returns its request_id, or why it could not.
  using ParamSink = std::function<StatusOr<std::string>(const ParamRequest& request)>;
  // Both sinks are called one at a time (never two calls of either at once). Without a param
  // sink, "param" is refused (the page is closed).
  explicit ExperimenterChannel(NoteSink notes, ParamSink params = nullptr) : sink_(std::move(notes)), params_(std::move(params)) {}
  void SetServer(WebServer* server) { server_.store(server); }
  // Sends `json` to every page, replacing an unsent frame of the same kind (`channel`).
  void Broadcast(uint32_t channel, const std::string& json);

  void OnOpen(ClientId client, Role role) override;
  Status OnText(ClientId client, std::string_view text) override;
  Status OnBinary(ClientId client, std::span<const uint8_t> bytes) override;
  void OnClose(ClientId client) override;

 private:
  Status OnNote(ClientId client, const nlohmann::json& j);
  Status OnParam(ClientId client, const nlohmann::json& j);
  Status CheckExperimenter(ClientId client, const std::string& what);  // REQUIRES: mutex_ held

  const NoteSink sink_;
  const ParamSink params_;
  std::atomic<WebServer*> server_{nullptr};
  std::mutex mutex_;  // guards pages_ and roles_, serialises sink_ and params_
  std::vector<ClientId> pages_;
  std::map<ClientId, Role> roles_;
};

}  // namespace dyad::web
