#include "experimenter_channel.hpp"

#include <algorithm>

#include <nlohmann/json.hpp>

#include "json_limits.hpp"

namespace dyad::web {
namespace {
using json = nlohmann::json;
constexpr size_t kMaxNote = 4096;
constexpr size_t kMaxParamName = 256;
constexpr size_t kMaxParamValue = 4096;
}  // namespace

void ExperimenterChannel::Broadcast(uint32_t channel, const std::string& text) {
  WebServer* server = server_.load();
  if (server == nullptr) return;
  std::vector<ClientId> pages;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pages = pages_;
  }
  for (ClientId c : pages) server->SendLatest(c, channel, text, /*binary=*/false);
}

void ExperimenterChannel::OnOpen(ClientId client, Role role) {
  std::lock_guard<std::mutex> lock(mutex_);
  pages_.push_back(client);
  roles_[client] = role;
}

Status ExperimenterChannel::OnText(ClientId client, std::string_view text) {
  if (!JsonDepthWithin(text)) return Status::InvalidArgument("nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
  const json j = json::parse(text.begin(), text.end(), nullptr, false);
  if (j.is_discarded() || !j.is_object()) return Status::InvalidArgument("not a JSON object");
  auto op = j.find("op");
  if (op != j.end() && *op == "note") return OnNote(client, j);
  if (op != j.end() && *op == "param") return OnParam(client, j);
  return Status::InvalidArgument("unknown op (only \"note\" and \"param\")");
}

// A viewer's page may watch, not act: refused (its page closed) as the other ops' shape errors.
Status ExperimenterChannel::CheckExperimenter(ClientId client, const std::string& what) {
  const Role role = roles_[client];
  if (role == Role::kExperimenter) return Status::OK();
  return Status::FailedPrecondition(what + ": the " + RoleName(role) + "'s token may not " +
                                    (what == "note" ? "write notes" : "change or read parameters"));
}

Status ExperimenterChannel::OnNote(ClientId client, const json& j) {
  auto t = j.find("text");
  if (t == j.end() || !t->is_string()) return Status::InvalidArgument("note: needs a \"text\" string");
  const std::string note = t->get<std::string>();
  if (note.size() > kMaxNote) return Status::InvalidArgument("note: longer than 4 KiB");
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (Status s = CheckExperimenter(client, "note"); !s.ok()) return s;
    sink_(note);
  }
  if (WebServer* server = server_.load()) server->SendText(client, json{{"op", "noted"}, {"length", note.size()}}.dump());
  return Status::OK();
}

Status ExperimenterChannel::OnParam(ClientId client, const json& j) {
  auto n = j.find("name");
  if (n == j.end() || !n->is_string()) return Status::InvalidArgument("param: needs a \"name\" string (COMPONENT.PARAM)");
  const std::string name = n->get<std::string>();
  const size_t dot = name.find('.');
  if (name.size() > kMaxParamName || dot == std::string::npos || dot == 0 || dot + 1 == name.size())
    return Status::InvalidArgument("param: \"name\" is COMPONENT.PARAM (e.g. mixer.gain), at most 256 bytes");
  ParamRequest request{name.substr(0, dot), name.substr(dot + 1), false, ""};
  if (auto v = j.find("value"); v != j.end()) {
    if (!v->is_string()) return Status::InvalidArgument("param: \"value\" is YAML text, a string (e.g. \"0.5\")");
    request.set = true;
    request.value = v->get<std::string>();
    if (request.value.size() > kMaxParamValue) return Status::InvalidArgument("param: \"value\" longer than 4 KiB");
  }
  StatusOr<std::string> id = Status::Unimplemented("param: this page cannot change parameters");
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (Status s = CheckExperimenter(client, "param"); !s.ok()) return s;
    if (!params_) return id.status();
    id = params_(request);
  }
  json reply{{"op", "param_sent"}, {"name", name}};
  if (id.ok()) reply["request_id"] = *id;
  else reply["error"] = id.status().message();
  if (WebServer* server = server_.load()) server->SendText(client, reply.dump(-1, ' ', false, json::error_handler_t::replace));
  return Status::OK();
}

Status ExperimenterChannel::OnBinary(ClientId, std::span<const uint8_t>) {
  return Status::InvalidArgument("binary frames are not part of this protocol");
}

void ExperimenterChannel::OnClose(ClientId client) {
  std::lock_guard<std::mutex> lock(mutex_);
  std::erase(pages_, client);
  roles_.erase(client);
}

}  // namespace dyad::web
