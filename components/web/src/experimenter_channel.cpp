#include "experimenter_channel.hpp"

#include <algorithm>

#include <nlohmann/json.hpp>

#include "json_limits.hpp"

namespace dyad::web {
namespace {
using json = nlohmann::json;
constexpr size_t kMaxNote = 4096;
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
  if (op == j.end() || *op != "note") return Status::InvalidArgument("unknown op (only \"note\")");
  auto t = j.find("text");
  if (t == j.end() || !t->is_string()) return Status::InvalidArgument("note: needs a \"text\" string");
  const std::string note = t->get<std::string>();
  if (note.size() > kMaxNote) return Status::InvalidArgument("note: longer than 4 KiB");
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (roles_[client] != Role::kExperimenter)
      return Status::FailedPrecondition(std::string("note: the ") + RoleName(roles_[client]) + "'s token may not write notes");
    sink_(note);
  }
  if (WebServer* server = server_.load()) server->SendText(client, json{{"op", "noted"}, {"length", note.size()}}.dump());
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
