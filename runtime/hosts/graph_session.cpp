#include "hosts/graph_session.hpp"

#include <vector>

#include "exec/logger.hpp"
#include "exec/wall_clock.hpp"
#include "graph/runtime_topics.hpp"
#include "hosts/clock_sync.hpp"
#include "hosts/endpoint_health.hpp"
#include "hosts/start_barrier.hpp"

namespace dyad {

namespace {

class GraphSession final : public ProcessSession {
 public:
  GraphSession(const Graph& graph, const std::string& process, const std::string& host, uint32_t restarts)
      : barrier_(graph, process, host, restarts),
        clock_sync_(graph, process, host, [](const std::string& m) { StderrLogger("clock").Warn(m); }),
        health_(graph, process, EndpointHealth::kLostS, [this](msg::HealthEvent e) { Publish(std::move(e)); }),
        graph_name_(graph.name),
        process_(process),
        host_(host) {}
  ~GraphSession() override { Close(); }

  Status Open(Transport* transport) override {
    transport_ = transport;
    auto w = CreateRuntimeWriter(transport, runtime_topics::kHealth);
    if (!w.ok()) return w.status();
    health_writer_ = w.value();
    if (Status s = barrier_.Open(transport); !s.ok()) return s;
    return clock_sync_.Open(transport);
  }
  Status AwaitMatched(const std::function<bool()>& stopping) override { return barrier_.WaitMatched(stopping); }
  StatusOr<int64_t> AwaitStart(const std::function<bool()>& stopping) override { return barrier_.Wait(stopping); }
  int64_t graph_start_ns() const override { return barrier_.graph_start_ns(); }
  void Started() override {
    clock_sync_.Start(kClockSyncPeriodS);
    barrier_.Announce("running");
  }
  Status Heartbeat() override {
    barrier_.Announce("running");
    // Last check's events go out now: after a renewal, the new writer has had a period to match.
    for (auto& e : pending_) health_writer_->Write(&e).IgnoreError();  // the log has said them too
    pending_.clear();
    const StartBarrier::Peers peers = barrier_.Hear(EndpointHealth::kFreshS);
    return health_.Check(transport_, peers.running, peers.silence_s);
  }
  void Stopping() override {
    for (auto& e : pending_) health_writer_->Write(&e).IgnoreError();  // as above
    pending_.clear();
    barrier_.Announce("stopping");
  }
  void Close() override { clock_sync_.Stop(); }

 private:
  static constexpr double kClockSyncPeriodS = 2;
  StartBarrier barrier_;
  ClockSync clock_sync_;
  void Publish(msg::HealthEvent e) {
    e.header().source("dyad/" + process_);
    e.header().sequence_number(++health_sequence_);
    e.header().stamp_ns(WallNowNs());
    e.graph_name(graph_name_);
    e.process_name(process_);
    e.host(host_);
    if (e.action() == "renewed") barrier_.SetRenewals(++renewals_);
    pending_.push_back(std::move(e));
  }

  EndpointHealth health_;
  std::string graph_name_, process_, host_;
  Transport* transport_ = nullptr;
  TypedWriter* health_writer_ = nullptr;
  uint64_t health_sequence_ = 0;
  uint32_t renewals_ = 0;  // "renewed" health events so far
  std::vector<msg::HealthEvent> pending_;  // published with the next heartbeat
};

// A wall-clock graph of one process: nobody to wait for or to measure; its state is announced
// (RELIABLE, TRANSIENT_LOCAL, one sample) so that `dyad status` finds it as it finds the others.
class SoloSession final : public ProcessSession {
 public:
  SoloSession(const Graph& graph, const std::string& process, const std::string& host, uint32_t restarts)
      : announcer_(graph, process, host, restarts) {}
  Status Open(Transport* transport) override { return announcer_.Open(transport); }
  // After every component's Activate: a wait there (for the subject's page) delays the start.
  StatusOr<int64_t> AwaitStart(const std::function<bool()>&) override {
    announcer_.StartAlone(WallNowNs());
    return announcer_.graph_start_ns();
  }
  int64_t graph_start_ns() const override { return announcer_.graph_start_ns(); }
  void Started() override { announcer_.Announce("running"); }
  Status Heartbeat() override {
    announcer_.Announce("running");
    return Status::OK();
  }
  void Stopping() override { announcer_.Announce("stopping"); }
  void Close() override {}
  bool shared_start() const override { return false; }

 private:
  StartBarrier announcer_;  // its announcements only: StartAlone() instead of Wait()
};

}  // namespace

std::unique_ptr<ProcessSession> MakeGraphSession(const Graph& graph, const std::string& process, const std::string& host,
                                                 uint32_t restarts) {
  if (graph.clock != ClockMode::kWall) return nullptr;
  if (graph.ProcessNames().size() < 2) return std::make_unique<SoloSession>(graph, process, host, restarts);
  return std::make_unique<GraphSession>(graph, process, host, restarts);
}

}  // namespace dyad
