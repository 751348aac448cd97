#include "foxglove_bridge.hpp"

#include <variant>

namespace dyad::web {

FoxgloveBridge::FoxgloveBridge(std::string server_name, std::vector<foxglove::Channel> channels,
                               std::map<std::string, SerializedWriter*> writers)
    : server_name_(std::move(server_name)), channels_(std::move(channels)), writers_(std::move(writers)) {}

void FoxgloveBridge::SetSubscription(uint32_t channel_id, OnDemandSubscription* subscription) {
  std::lock_guard<std::mutex> demand(demand_mutex_);
  subscriptions_[channel_id] = subscription;
}

std::vector<std::string> FoxgloveBridge::SyncSubscriptions(const std::set<uint32_t>& channels) {
  std::vector<std::string> problems;
  std::lock_guard<std::mutex> demand(demand_mutex_);
  for (uint32_t channel : channels) {
    auto sub = subscriptions_.find(channel);
    if (sub == subscriptions_.end() || sub->second == nullptr) continue;
    bool wanted = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      auto r = routes_.find(channel);
      wanted = r != routes_.end() && !r->second.empty();
    }
    if (wanted == sub->second->started()) continue;
    if (!wanted) {
      sub->second->Stop();
    } else if (Status s = sub->second->Start(); !s.ok()) {
      problems.push_back("subscribe: channel " + std::to_string(channel) + ": " + s.message());
    }
  }
  return problems;
}

void FoxgloveBridge::OnSample(uint32_t channel_id, const SerializedSample& sample) {
  std::vector<std::pair<ClientId, uint32_t>> to;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = routes_.find(channel_id);
    if (it == routes_.end() || it->second.empty()) return;
    to = it->second;
    sent_ += to.size();
  }
  WebServer* server = server_.load();
  if (server == nullptr) return;
  const uint64_t stamp = sample.source_stamp_ns > 0 ? static_cast<uint64_t>(sample.source_stamp_ns) : 0;
  // One copy of the sample, shared by every client's frame (a 13-byte head each, no allocation).
  auto payload = std::make_shared<const std::string>(reinterpret_cast<const char*>(sample.cdr.data()), sample.cdr.size());
  for (const auto& [client, sub] : to) server->SendShared(client, channel_id, foxglove::MessageDataHead(sub, stamp), payload);
}

void FoxgloveBridge::ReportDrops() {
  WebServer* server = server_.load();
  if (server == nullptr) return;
  std::vector<ClientId> clients;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& [c, _] : clients_) clients.push_back(c);
  }
  for (ClientId c : clients) {
    const auto drops = server->TakeDrops(c);
    if (drops.empty()) continue;
    std::string msg = "client too slow: dropped";
    for (const auto& [channel, n] : drops) {
      const std::string topic = channel >= 1 && channel <= channels_.size() ? channels_[channel - 1].topic : "?";
      msg.append(" ").append(std::to_string(n)).append(" samples of '").append(topic).append("'");
    }
    SendStatus(c, foxglove::Level::kWarning, msg);
  }
}

void FoxgloveBridge::OnOpen(ClientId client, Role role) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    clients_[client].role = role;
  }
  WebServer* server = server_.load();
  if (server == nullptr) return;
  const bool may_publish = !writers_.empty() && role == Role::kExperimenter;
  server->SendText(client, foxglove::ServerInfo(server_name_, may_publish, std::to_string(client), {}));
  server->SendText(client, foxglove::Advertise(channels_));
}

void FoxgloveBridge::SendStatus(ClientId client, foxglove::Level level, const std::string& message) {
  if (WebServer* server = server_.load()) server->SendText(client, foxglove::StatusMessage(level, message));
}

Status FoxgloveBridge::OnText(ClientId client, std::string_view text) {
  auto parsed = foxglove::ParseClientText(text);
  if (!parsed.ok()) return parsed.status();
  std::vector<std::string> problems;
  std::set<uint32_t> changed;  // channels whose routes changed
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ClientState& st = clients_[client];
    if (auto* s = std::get_if<foxglove::Subscribe>(&*parsed)) {
      for (const auto& [sub, channel] : s->subscriptions) {
        if (channel < 1 || channel > channels_.size()) {
          problems.push_back("subscribe: no channel " + std::to_string(channel));
          continue;
        }
        if (st.subscriptions.count(sub)) {
          problems.push_back("subscribe: subscription id " + std::to_string(sub) + " is already in use");
          continue;
        }
        if (st.subscriptions.size() >= kMaxSubscriptions) {
          problems.push_back("subscribe: a client holds at most " + std::to_string(kMaxSubscriptions) + " subscriptions");
          break;
        }
        st.subscriptions[sub] = channel;
        routes_[channel].emplace_back(client, sub);
        changed.insert(channel);
      }
    } else if (auto* u = std::get_if<foxglove::Unsubscribe>(&*parsed)) {
      for (uint32_t sub : u->subscription_ids) {
        auto it = st.subscriptions.find(sub);
        if (it == st.subscriptions.end()) continue;
        auto& r = routes_[it->second];
        std::erase(r, std::make_pair(client, sub));
        changed.insert(it->second);
        st.subscriptions.erase(it);
      }
    } else if (auto* a = std::get_if<foxglove::ClientAdvertise>(&*parsed)) {
      for (const auto& c : a->channels) {
        auto w = writers_.find(c.topic);
        if (st.role != Role::kExperimenter) {
          problems.push_back(std::string("advertise: the ") + RoleName(st.role) + "'s token may not publish");
          break;
        } else if (st.publishing.size() >= kMaxClientChannels && !st.publishing.count(c.id)) {
          problems.push_back("advertise: a client advertises at most " + std::to_string(kMaxClientChannels) + " channels");
          break;
        } else if (w == writers_.end()) {
          problems.push_back("advertise: topic '" + c.topic + "' is not writable" +
                             (writers_.empty() ? " (this server accepts no client publishing)" : ""));
        } else if (c.encoding != "cdr") {
          problems.push_back("advertise: topic '" + c.topic + "': encoding '" + c.encoding + "' is not supported (cdr)");
        } else {
          st.publishing[c.id] = w->second;
        }
      }
    } else if (auto* ua = std::get_if<foxglove::ClientUnadvertise>(&*parsed)) {
      for (uint32_t id : ua->channel_ids) st.publishing.erase(id);
    } else if (auto* other = std::get_if<foxglove::OtherOp>(&*parsed)) {
      problems.push_back("op '" + other->op + "' is not supported by this server");
    }
  }
  for (auto& p : SyncSubscriptions(changed)) problems.push_back(std::move(p));
  for (const auto& p : problems) SendStatus(client, foxglove::Level::kError, p);
  return Status::OK();
}

Status FoxgloveBridge::OnBinary(ClientId client, std::span<const uint8_t> bytes) {
  auto d = foxglove::ParseClientBinary(bytes);
  if (!d.ok()) return d.status();
  SerializedWriter* writer = nullptr;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ClientState& st = clients_[client];
    auto it = st.publishing.find(d->channel_id);
    if (it != st.publishing.end()) writer = it->second;
  }
  if (writer == nullptr) {
    SendStatus(client, foxglove::Level::kError,
           "message on client channel " + std::to_string(d->channel_id) + ", which is not advertised or not writable");
    return Status::OK();
  }
  dyad::Status s = writer->Write(d->payload);
  if (s.code() == dyad::Status::Code::kInvalidArgument) return s;  // not the topic's type: malformed
  if (!s.ok()) SendStatus(client, foxglove::Level::kError, s.message());
  return Status::OK();
}

void FoxgloveBridge::OnClose(ClientId client) {
  std::set<uint32_t> changed;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = clients_.find(client);
    if (it == clients_.end()) return;
    for (const auto& [sub, channel] : it->second.subscriptions) {
      std::erase(routes_[channel], std::make_pair(client, sub));
      changed.insert(channel);
    }
    clients_.erase(it);
  }
  SyncSubscriptions(changed);  // a stop cannot fail
}

uint64_t FoxgloveBridge::samples_sent() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return sent_;
}

}  // namespace dyad::web
