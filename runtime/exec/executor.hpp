// Executor — runs the components placed in one process: creates their ports on one DDS
// participant, drives the lifecycle, steps them on the graph's clock and keeps their timing.
// Internal to the runtime; RunGraph (run.hpp) is the public entry.
//
// Lifecycle: Configure (graph order), Activate (graph order), steps, Deactivate (reverse order),
// Shutdown (reverse order) all run on the thread that called Run(). A failure in Configure or
// Activate stops before any step: components already activated are deactivated, every configured
// one is shut down. A failed step or Deactivate keeps its Status code (context added).
//
// Wall clock: one thread per periodic component, sleeping until each period's start (a late
// step is counted as a deadline miss and the schedule skips the missed periods instead of
// bursting). Triggered components are stepped on the thread that delivers the triggering
// sample (for a publisher in the same process, inside its Publish()), never concurrently with
// themselves: a delivery that finds the component busy leaves it a note to step again.
//
// Stepped clock: one thread, simulated time. At each instant the periodic components due then
// step in graph order; after each step, triggered components whose trigger input has unread
// samples step (in graph order, repeatedly until none has; more than 1000 rounds in one instant
// is a failure: components triggering each other in a cycle). Samples between components in one
// process are delivered inside write(), so the same graph and seed give the same samples.
// `duration_s` and `steps` count simulated time there.
//
// Timing: each component is charged its own time. A step or serialized callback that runs nested
// inside another component's step (a triggered component or a recorder callback inside the
// upstream's Publish()) is measured on its own and subtracted from the enclosing step; a
// periodic step misses its deadline when its late start plus its own time exceed the period.
//
// Wall clock with a ProcessSession (exec/process_session.hpp, made by the hosts layer; every
// wall-clock `dyad run` has one): after Configure and before Activate it awaits the session's
// matching (several processes: nothing is published before this process's endpoints have matched
// their peers); after every Activate it awaits the session's start (one process: now; several:
// the instant agreed once every process has activated) and starts its periodic components then.
// So a component that waits in Activate (the web component's wait for the subject's page) delays
// the clock instead of making the first steps late by its wait (each a deadline miss). With
// `steps`, a process without the graph's fastest periodic component stops once that many of its
// periods have passed since the graph's start, plus a second for the last samples to arrive.
//
// Serialized subscriptions (Context::SubscribeSerialized, and SubscribeSerializedOnDemand's while
// started) call back on the delivering thread; each is closed (unread samples delivered first)
// just before its component's Deactivate(). The last
// stats are published before any component is deactivated, so a recorder sees them.
//
// Ownership: the transport owns every endpoint; it is destroyed before components and ports,
// so no callback can reach a destroyed component whatever happened before.
#pragma once

#include <atomic>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <dyad/catalog.hpp>
#include <dyad/graph.hpp>
#include <dyad/thread_annotations.hpp>
#include <dyad/validate.hpp>

#include "dds/transport.hpp"
#include "exec/live_params.hpp"
#include "exec/process_session.hpp"
#include "exec/step_stats.hpp"

namespace dyad {

class Executor {
 public:
  struct Options {
    std::string process;
    std::string host;       // this machine's name (announced to the other processes)
    double duration_s = 0;  // > 0: stop after this long (wall time, or simulated time when stepped)
    uint64_t steps = 0;     // > 0: stop after the fastest periodic component ran this many steps
    double stats_period_s = 1.0;
    // A stop that takes longer says, this often, what it waits for (a step, a Deactivate that
    // does not return would otherwise look like a process that ignores its stop).
    double stop_report_s = 10.0;
    // A guest (dyad/guest.hpp) is none of the graph's processes: no writer on dyad/stats (`dyad
    // status` must not list its components as the graph's), no answers to live parameter requests.
    bool guest = false;
    // Makes the transport (participant name, stepped). Empty: a Fast DDS participant on the
    // graph's domain (hermetic to this process when stepped). Tests pass an in-memory one.
    std::function<StatusOr<std::unique_ptr<Transport>>(const std::string& name, bool stepped)> transport;
    // This process's part in a graph of several processes (null or empty: none, it runs alone).
    std::function<std::unique_ptr<ProcessSession>()> session;
  };

  // `catalog` (may be null) answers Context::FindMessageType beyond the graph's own types.
  Executor(const Graph& graph, const ResolvedGraph& resolved, const Catalog* catalog, Options options);
  ~Executor();

  // Runs to the end. Returns OK, or the first failure.
  Status Run();
  // Thread-safe, async-signal-unsafe: call from a normal thread (the signal thread does).
  // Returns true for the first request (its reason is the run's).
  bool RequestStop(const std::string& reason);

  struct Row {
    std::string component;
    StepStats::Snapshot stats;
  };
  std::vector<Row> Report() const;
  // Type mismatches and incompatible QoS with peers (DdsParticipant::Options::on_problem): data
  // that cannot flow where the graph says it should.
  int wiring_problems() const { return problems_.load(); }
  // Writers of this process's topics seen in another run's partition (ignored; warned about).
  int foreign_writers() const { return foreign_writers_.load(); }

 private:
  struct Instance;
  class ContextImpl;
  class ClockImpl;

  Status Setup();
  Status CreateTransport();
  Status BindPorts(Instance& inst);
  Status ActivateAll();  // in graph order; stops at the first failure
  void BuildTopicList();
  const TopicInfo* FindTopic(const std::string& name) const;
  Status StepOnce(Instance& inst, int64_t scheduled_ns, bool periodic);
  void TriggerStep(Instance& inst);
  void PeriodicLoop(Instance& inst);
  Status RunStepped();
  Status RunWall();
  void PublishStats();
  int64_t FastestPeriodNs() const;     // of the whole graph's periodic components; 0: none
  bool HoldsFastestComponent() const;  // this process runs one of them
  void Fail(const Status& status);
  bool stopping() const { return stop_.load(std::memory_order_acquire); }

  const Graph& graph_;
  const ResolvedGraph& resolved_;
  const Catalog* catalog_;
  Options options_;
  std::string graph_yaml_;         // Context::graph_yaml(): secrets redacted
  std::vector<TopicInfo> topics_;  // Context::graph_topics()
  std::unique_ptr<ClockImpl> clock_;
  std::vector<std::unique_ptr<Instance>> instances_;
  std::unique_ptr<OutputBase> stats_output_;
  std::unique_ptr<LiveParams> live_params_;  // null in a guest
  // Graphs of several processes, wall clock: all start together. Closed before the transport goes.
  std::unique_ptr<ProcessSession> session_;
  int64_t start_steady_ns_ = 0;  // when periodic components take their first step
  int64_t start_wall_ns_ = 0;    // the agreed start (session); 0: stopped while waiting

  std::atomic<bool> stop_{false};
  std::atomic<int> problems_{0};
  std::atomic<int> foreign_writers_{0};
  mutable Mutex mutex_;  // guards stop_reason_, failure_; with cv_ wakes sleepers on stop
  std::condition_variable cv_;
  std::string stop_reason_ GUARDED_BY(mutex_);
  Status failure_ GUARDED_BY(mutex_);
  // Declared last, destroyed first (see Ownership above): owns every endpoint.
  std::unique_ptr<Transport> transport_;
};

}  // namespace dyad
