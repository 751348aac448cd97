// Executor — runs the components placed in one process: creates their ports on one DDS
// participant, drives the lifecycle, steps them on the graph's clock and keeps their timing.
// Internal to the runtime; RunGraph (run.hpp) is the public entry.
//
// Wall clock: one thread per periodic component, sleeping until each period's start (a late
// step is counted as a deadline miss and the schedule skips the missed periods instead of
// bursting). Triggered components are stepped on the thread that delivers the triggering
// sample (for a publisher in the same process, inside its Publish()), never concurrently with
// themselves: a delivery that finds the component busy leaves it a note to step again.
//
// Stepped clock: one thread, simulated time. At each instant the periodic components due then
// step in graph order; after each step, triggered components whose trigger input has unread
// samples step (in graph order, repeatedly until none has). Samples between components in one
// process are delivered inside write(), so the same graph and seed give the same samples.
//
// Serialized subscriptions (Context::SubscribeSerialized) call back on the delivering thread; each
// is closed (unread samples delivered first) just before its component's Deactivate(). The last
// stats are published before any component is deactivated, so a recorder sees them.
#pragma once

#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <dyad/catalog.hpp>
#include <dyad/graph.hpp>
#include <dyad/validate.hpp>

#include "dds_participant.hpp"
#include "step_stats.hpp"

namespace dyad {

class Executor {
 public:
  struct Options {
    std::string process;
    double duration_s = 0;
    uint64_t steps = 0;
    double stats_period_s = 1.0;
  };

  // `catalog` (may be null) answers Context::FindMessageType beyond the graph's own types.
  Executor(const Graph& graph, const ResolvedGraph& resolved, const Catalog* catalog, Options options);
  ~Executor();

  // Runs to the end. Returns OK, or the first failure.
  Status Run();
  // Thread-safe, async-signal-unsafe: call from a normal thread (the signal thread does).
  void RequestStop(const std::string& reason);

  struct Row {
    std::string component;
    StepStats::Snapshot stats;
  };
  std::vector<Row> Report() const;
  int type_mismatches() const { return problems_.load(); }

 private:
  struct Instance;
  class ContextImpl;
  class ClockImpl;

  Status Setup();
  void BuildTopicList();
  const TopicInfo* FindTopic(const std::string& name) const;
  Status StepOnce(Instance& inst, int64_t scheduled_ns, bool periodic);
  void TriggerStep(Instance& inst);
  void PeriodicLoop(Instance& inst);
  Status RunStepped();
  Status RunWall();
  void PublishStats();
  void Fail(const Status& status);
  bool stopping() const { return stop_.load(std::memory_order_acquire); }

  const Graph& graph_;
  const ResolvedGraph& resolved_;
  const Catalog* catalog_;
  Options options_;
  std::vector<TopicInfo> topics_;  // Context::graph_topics()
  std::unique_ptr<ClockImpl> clock_;
  std::unique_ptr<DdsParticipant> participant_;
  std::vector<std::unique_ptr<Instance>> instances_;
  std::unique_ptr<OutputBase> stats_output_;
  std::unique_ptr<DdsWriter> stats_writer_;

  std::atomic<bool> stop_{false};
  std::atomic<int> problems_{0};
  mutable std::mutex mutex_;  // guards stop_reason_, failure_; with cv_ wakes sleepers on stop
  std::condition_variable cv_;
  std::string stop_reason_;
  Status failure_;
};

}  // namespace dyad
