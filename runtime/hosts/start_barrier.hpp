// StartBarrier — the processes of a wall-clock graph start together (internal to the runtime;
// docs/runtime.md, "Several processes").
//
// A process started apart from the others used to run without them: a robot started 3 s before
// the human ran 30 steps with no input, and those samples were missing from the recording. Now
// every process of a graph with several processes, its components configured:
//   1. waits until each endpoint of its own has matched as many peers as the graph binds to its
//      topic (a reader: every writer of the topic; a writer: every reader; the runtime's own
//      dyad/ topics excepted; WaitMatched: nothing is published before that), activates its
//      components, and then announces its wall-clock `ready_ns` on dyad/processes;
//   2. waits until it has heard every process of the graph announce itself ready;
//   3. starts its clocks at max(ready_ns) + kStartMargin, an instant every process computes
//      alike from the same announcements (as exact as the hosts' clock sync, docs/distributed.md).
// Processes with `required: false` are not waited for. A process that hears another already
// "running" (it was restarted, or started late) joins at once instead. After
// `network.start_timeout_s` it gives up with a message naming every process not heard from and
// every endpoint of its own still short of matches (a process heard "activating" is named so:
// its Activate takes that long, and the others' timeout must cover it).
//
// Announcements (dyad::msg::ProcessState) are RELIABLE and TRANSIENT_LOCAL, so a process that
// starts last still hears the earlier ones. State changes after the start ("running",
// "stopping") go out through Announce() too; `dyad status` reads them.
#pragma once

#include <chrono>
#include <set>

#include <cstdint>
#include <functional>
#include <map>
#include <string>

#include <dyad/graph.hpp>
#include <dyad/msg/types.hpp>
#include <dyad/status.hpp>

#include "dds/transport.hpp"
#include "exec/wall_clock.hpp"

namespace dyad {

// Time between the last process becoming ready and the common start: enough for its
// announcement to reach every other process.
inline constexpr int64_t kStartMarginNs = 500'000'000;

class StartBarrier {
 public:
  // `restarts`: how often the launcher has restarted this process (announced with every state).
  StartBarrier(const Graph& graph, std::string process, std::string host, uint32_t restarts);

  // Creates this process's dyad/processes writer and reader on `transport` (which must outlive
  // the barrier). Call once, before Wait().
  Status Open(Transport* transport);

  // Before the components' Activate: blocks until each endpoint of this process has matched as
  // many peers as the graph binds to its topic (OK), `stopping()` becomes true (OK), or the
  // timeout (FailedPrecondition naming the endpoints short of matches); then announces
  // "activating" (another process's timeout message says so while this one activates).
  Status WaitMatched(const std::function<bool()>& stopping);

  // After Activate (ready means activated too: a component may wait there, as the web component
  // waits for the subject's page, and the common start waits with it).
  // Blocks until the common start instant is known (returned, wall-clock ns; it may already be
  // past), `stopping()` becomes true (returns 0), or the timeout (FailedPrecondition naming what
  // is missing).
  StatusOr<int64_t> Wait(const std::function<bool()>& stopping);

  // Instead of Wait(), for the only process of a graph: there is no one to wait for; it starts
  // at `start_ns` (and announces so).
  void StartAlone(int64_t start_ns) { ready_ns_ = start_ns_ = graph_start_ns_ = start_ns; }

  // When the graph started: the agreed instant, or for a process that joined a running graph,
  // the others' (valid after Wait()).
  int64_t graph_start_ns() const { return graph_start_ns_; }

  // Publishes this process's state ("running" with the start instant, "stopping").
  void Announce(const std::string& state);
  // The renewals this process's endpoint health check has made so far, announced from the next
  // Announce on (`dyad status` lists them).
  void SetRenewals(uint32_t renewals) { renewals_ = renewals; }

  // What this process hears of the others (takes what arrived first). On the thread that calls
  // Wait, after it.
  struct Peers {
    std::set<std::string> running;  // newest announcement "running", heard within `fresh_s`
    // Seconds since any other required process was last heard, when the newest word of one of
    // them is "running" (it should be talking); else 0.
    double silence_s = 0;
  };
  Peers Hear(double fresh_s);

 private:
  // Whether the barrier waits for `process`: itself and every required process (one that is not
  // required joins when it comes; its endpoints are not counted).
  bool Awaited(const std::string& process) const;
  bool Required(const std::string& process) const;  // `required:` of the process (default true)
  std::string MissingEndpoints(const std::vector<EndpointMatch>& matches) const;
  std::set<std::string> AwaitedProcesses() const;  // this one and every required process
  // The awaited processes not heard ready ("'mind' (not seen), ..."); raises *last_ready to the
  // latest ready time heard.
  std::string NotReady(int64_t* last_ready) const;
  // The timeout's error: who was not ready, which endpoints of this process lacked matches.
  Status TimedOut(const std::string& not_heard, const std::string& missing_endpoints) const;
  void TakeAnnouncements();

  const Graph& graph_;
  std::string process_, host_;
  std::map<std::string, int> writers_of_, readers_of_;  // topic -> endpoints the graph binds
  std::map<std::string, msg::ProcessState> heard_;      // process -> its newest announcement
  std::map<std::string, std::chrono::steady_clock::time_point> heard_at_;  // process -> when
  Transport* transport_ = nullptr;
  TypedWriter* writer_ = nullptr;
  TypedReader* reader_ = nullptr;
  uint64_t sequence_ = 0;
  uint32_t restarts_ = 0;
  uint32_t renewals_ = 0;
  int64_t ready_ns_ = 0, start_ns_ = 0, graph_start_ns_ = 0;
};

}  // namespace dyad
