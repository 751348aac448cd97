/// FoxgloveBridge — the graph's topics over the Foxglove WebSocket protocol, for Foxglove (or
/// any `@foxglove/ws-protocol` client) watching a live experiment.
///
/// Every chosen graph topic is advertised as a channel (`encoding: cdr`, `schemaEncoding:
/// omgidl`, `schemaName` the scoped IDL name, `schema` the self-contained IDL text). A client's
/// subscriptions get binary Message Data frames: the sample's CDR bytes as they travel on DDS
/// (encapsulation header included) stamped with the sample's source time. Samples reach the
/// bridge through the runtime's serialized subscriptions and are only queued here (WebServer's
/// per-client SendQueue): the experiment never waits for a client.
///
/// Reading on demand, as foxglove_bridge does: each channel's subscription (an
/// OnDemandSubscription) is started when the first client subscribes to the channel and stopped
/// when the last one unsubscribes or closes; a topic nobody watches is neither read nor decoded
/// (no DDS reader at all until it is first watched). A subscription that cannot start is
/// reported to the subscribing client as a status error.
///
/// Client publishing: only a client with the experimenter's token, only on topics listed as
/// writable; anything else is refused with a status error (a viewer's serverInfo does not offer
/// it). Each client holds at most kMaxSubscriptions subscriptions and kMaxClientChannels
/// advertised channels; past that its requests are refused with a status error, so a client
/// cannot grow the server's tables. A malformed JSON or binary message closes that client with
/// the reason.
#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include <dyad/component.hpp>
#include <dyad/on_demand_subscription.hpp>

#include "foxglove_protocol.hpp"
#include "web_server.hpp"

namespace dyad::web {

class FoxgloveBridge final : public ClientHandler {
 public:
  // `channels`: the topics to advertise (ids 1..n in order); `writers`: topic -> writer for the
  // writable ones (owned by the runtime).
  FoxgloveBridge(std::string server_name, std::vector<foxglove::Channel> channels,
                 std::map<std::string, SerializedWriter*> writers);
  // Set once the server runs; null again before it stops. Samples and clients before that are ignored.
  void SetServer(WebServer* server) { server_.store(server); }
  // The subscription feeding channel `channel_id` (its samples go to OnSample), owned by the
  // runtime; started and stopped with the channel's client subscriptions. Set each before the
  // server starts; a channel without one is fed by whatever calls OnSample.
  void SetSubscription(uint32_t channel_id, OnDemandSubscription* subscription);

  // A sample of channel `channel_id` (called on the graph's delivering threads).
  void OnSample(uint32_t channel_id, const SerializedSample& sample);
  // Reports to each client what it lost since the last call (a status warning per client).
  void ReportDrops();

  void OnOpen(ClientId client, Role role) override;
  Status OnText(ClientId client, std::string_view text) override;
  Status OnBinary(ClientId client, std::span<const uint8_t> bytes) override;
  void OnClose(ClientId client) override;

  uint64_t samples_sent() const;

  static constexpr size_t kMaxSubscriptions = 1024, kMaxClientChannels = 64;

 private:
  struct ClientState {
    Role role = Role::kViewer;
    std::map<uint32_t, uint32_t> subscriptions;        // subscription id -> channel id
    std::map<uint32_t, SerializedWriter*> publishing;  // client channel id -> writer
  };
  void SendStatus(ClientId client, foxglove::Level level, const std::string& message);
  // Starts or stops each channel's subscription to match whether any client subscribes to it;
  // returns the problems of those that failed to start. Called without mutex_ held (Stop waits
  // for a running OnSample, which takes it).
  std::vector<std::string> SyncSubscriptions(const std::set<uint32_t>& channels);

  const std::string server_name_;
  const std::vector<foxglove::Channel> channels_;
  const std::map<std::string, SerializedWriter*> writers_;
  std::atomic<WebServer*> server_{nullptr};
  mutable std::mutex mutex_;
  std::map<ClientId, ClientState> clients_;
  // channel id -> (client, subscription id): what OnSample sends to.
  std::map<uint32_t, std::vector<std::pair<ClientId, uint32_t>>> routes_;
  uint64_t sent_ = 0;
  // Serializes SyncSubscriptions (client threads: the handler thread, civetweb's on close).
  std::mutex demand_mutex_;
  std::map<uint32_t, OnDemandSubscription*> subscriptions_;  // by channel id; set before the server
};

}  // namespace dyad::web
