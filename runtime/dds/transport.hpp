// Transport — what the executor needs from the middleware: typed and serialized endpoints on
// named topics. Internal to the runtime. DdsParticipant implements it over Fast DDS; the
// executor's unit tests use an in-memory one (tests/memory_transport.hpp).
//
// Ownership is structural: a transport owns every endpoint it creates and hands out plain
// pointers, valid until the transport is destroyed. Its destructor first stops every callback
// (listeners detached, serialized subscriptions closed), then deletes the endpoints, then
// itself; so no destruction order of the callers (components, ports, executor) can leave an
// endpoint alive in the middleware or a callback running into freed memory. Callers that own
// objects a callback touches destroy the transport first.
//
// Delivery contract (both implementations): a sample written to a topic reaches every reader of
// that topic in this process synchronously inside the writer's Write() (so, under the stepped
// clock, samples flow deterministically); `on_data` and serialized callbacks run on the
// delivering thread and never concurrently for one endpoint.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include <dyad/component.hpp>
#include <dyad/graph.hpp>
#include <dyad/on_demand_subscription.hpp>
#include <dyad/status.hpp>

#include "graph/runtime_topics.hpp"
#include "graph/topic_qos.hpp"

namespace dyad {

// One endpoint of this transport and how many remote-or-local endpoints it is matched with.
struct EndpointMatch {
  std::string topic;
  bool writer = false;
  bool serialized = false;  // a Context::SubscribeSerialized/AdvertiseSerialized endpoint
  int matched = 0;
};

// A typed reader the executor polls (the port's endpoint).
class TypedReader : public detail::ReaderEndpoint {
 public:
  virtual uint64_t Unread() const = 0;
};

// The writer side of a port.
class TypedWriter : public detail::WriterEndpoint {
 public:
  virtual int matched() const = 0;  // readers currently matched (local and remote)
  // Waits up to `timeout_s` until every matched reliable reader acknowledged what was written;
  // false on timeout. A transport that delivers synchronously (the tests' in-memory one) has
  // nothing to wait for and returns true. (The launchers' link waits on it: launcher_link.cpp.)
  virtual bool AwaitAcknowledged(double timeout_s) = 0;
};

// A Context::SubscribeSerialized subscription.
class SerializedSubscription {
 public:
  virtual ~SerializedSubscription() = default;
  // Delivers what is still unread, then stops calling back. Idempotent; waits for a running callback.
  virtual void Close() = 0;
  virtual uint64_t delivered() const = 0;
};

// A SubscribeSerializedOnDemand subscription (dyad/on_demand_subscription.hpp): created
// stopped, reads only between Start() and Stop(); Close() ends it for good, as above.
class OnDemandReader : public SerializedSubscription, public OnDemandSubscription {};

class Transport {
 public:
  virtual ~Transport() = default;
  // Every endpoint created here with its current match count (the start barrier). A transport
  // that cannot tell returns none (every endpoint counts as matched).
  virtual std::vector<EndpointMatch> Matches() const { return {}; }
  // Healing (hosts/endpoint_health.hpp): replaces the middleware entity behind each endpoint of
  // this kind on `topic` matched with fewer than `expected` endpoints by a new one that
  // discovery learns afresh, keeping the endpoint objects; returns how many. Reap() finishes
  // earlier renewals. A transport that cannot lose a match (the tests' in-memory one) has none.
  virtual int Renew(const std::string& /*topic*/, bool /*writers*/, int /*expected*/) { return 0; }
  // The same for every endpoint at once, with a new participant (a new identity in discovery).
  virtual bool RenewParticipant() { return false; }
  virtual void Reap() {}

  // `on_data` (may be empty) is called on the delivering thread whenever samples arrive.
  virtual StatusOr<TypedReader*> CreateReader(const std::string& topic, const TypeInfo& type, const TopicQos& qos,
                                              std::function<void()> on_data) = 0;
  virtual StatusOr<TypedWriter*> CreateWriter(const std::string& topic, const TypeInfo& type, const TopicQos& qos) = 0;
  // `clock` stamps receive times; it must outlive the transport. The callback gets every sample
  // as CDR bytes (with encapsulation), on the delivering thread.
  virtual StatusOr<SerializedSubscription*> CreateSerializedReader(const std::string& topic, const TypeInfo& type,
                                                                   const TopicQos& qos, const Clock* clock,
                                                                   SerializedCallback callback) = 0;
  // The same, created stopped: no reader, no callback until Start(); `qos` should be KEEP_LAST.
  // A transport without it answers Unimplemented.
  virtual StatusOr<OnDemandReader*> CreateOnDemandReader(const std::string& topic, const TypeInfo&, const TopicQos&,
                                                         const Clock*, SerializedCallback) {
    return Status::Unimplemented("topic '" + topic + "': this transport has no on-demand subscriptions");
  }
  virtual StatusOr<SerializedWriter*> CreateSerializedWriter(const std::string& topic, const TypeInfo& type,
                                                             const TopicQos& qos, const Clock* clock) = 0;
};

// Endpoints of the runtime's own topics (graph/runtime_topics.hpp) with the table's QoS; errors
// name the topic. `watcher`: a guest's reader (may drop samples, never slows a writer).
inline StatusOr<TypedWriter*> CreateRuntimeWriter(Transport* transport, const RuntimeTopic& topic) {
  auto w = transport->CreateWriter(topic.name, topic.type(), topic.writer);
  if (!w.ok()) return w.status().WithContext(topic.name);
  return w;
}
inline StatusOr<TypedReader*> CreateRuntimeReader(Transport* transport, const RuntimeTopic& topic,
                                                  std::function<void()> on_data = nullptr, bool watcher = false) {
  auto r = transport->CreateReader(topic.name, topic.type(), watcher ? topic.watcher : topic.reader, std::move(on_data));
  if (!r.ok()) return r.status().WithContext(topic.name);
  return r;
}

}  // namespace dyad
