// dyad/on_demand_subscription.hpp — a serialized subscription that reads only while someone
// watches: for viewers (the web component's Foxglove bridge), which forward a topic only while a
// client subscribes to it, as foxglove_bridge does. A recorder wants every sample: it uses
// Context::SubscribeSerialized.
//
// Contract:
//   - SubscribeSerializedOnDemand(ctx, topic, callback): call in Configure() only, on a graph
//     topic (NotFound otherwise; FailedPrecondition after Configure). The subscription starts
//     stopped: no reader exists, nothing is received, decoded or called back.
//   - Start(): from then on `callback` gets the topic's samples exactly as a SubscribeSerialized
//     callback would (same SerializedSample, same threads: the delivering one, never
//     concurrently for one subscription). The first Start() creates the reader; a remote writer's
//     samples flow once discovery has matched it (milliseconds). Samples the reader kept while
//     stopped (at most the topic's `depth`, the newest) are delivered first. OK when already
//     started. Fails: FailedPrecondition once the runtime has closed the subscription (just
//     before Deactivate()), Internal (DDS).
//   - Stop(): no callback runs after it returns, until the next Start(). The reader stays (Fast
//     DDS 2.9 cannot delete a reader safely while a writer of this process writes to it): it keeps
//     the newest `depth` samples as the middleware received them, neither decoded nor handed
//     over. Idempotent.
//   - Unlike SubscribeSerialized, the reader keeps only the topic's `depth` (KEEP_LAST): a viewer
//     may miss samples when its callback is slower than the topic, a recorder must not.
//   - Start() and Stop() may be called from any thread, between Configure() and Deactivate(), but
//     never from inside this subscription's callback, nor while holding a lock the callback
//     takes (Stop waits for a running callback).
//   - The subscription is owned by the runtime and valid until Shutdown() returns.
//
// Why a free function and not a Context method: adding a virtual to Context would change the
// plugin ABI (kPluginAbiVersion). The runtime's contexts implement it; another Context (a test
// fake) answers Unimplemented.
//
//   OnDemandSubscription* sub = nullptr;
//   if (auto s = dyad::SubscribeSerializedOnDemand(ctx, "robot/state", Forward); s.ok()) sub = *s;
//   ...  // first viewer: sub->Start();  last viewer gone: sub->Stop();
#pragma once

#include <string>

#include <dyad/component.hpp>
#include <dyad/status.hpp>

namespace dyad {

class OnDemandSubscription {
 public:
  virtual ~OnDemandSubscription() = default;
  virtual const std::string& topic() const = 0;
  virtual Status Start() = 0;
  virtual void Stop() = 0;
  virtual bool started() const = 0;
};

StatusOr<OnDemandSubscription*> SubscribeSerializedOnDemand(Context& ctx, const std::string& topic,
                                                            SerializedCallback callback);

namespace detail {
// Implemented by the runtime's own contexts (not for component code): what they offer beyond the
// virtuals of Context at this plugin ABI, reached through a dynamic_cast by the function above.
class ContextExtensions {
 public:
  virtual ~ContextExtensions() = default;
  virtual StatusOr<OnDemandSubscription*> SubscribeSerializedOnDemand(const std::string& topic,
                                                                      SerializedCallback callback) = 0;
};
}  // namespace detail

}  // namespace dyad
