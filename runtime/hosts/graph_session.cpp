#include "hosts/graph_session.hpp"

#include "exec/logger.hpp"
#include "hosts/clock_sync.hpp"
#include "hosts/start_barrier.hpp"

namespace dyad {

namespace {

class GraphSession final : public ProcessSession {
 public:
  GraphSession(const Graph& graph, const std::string& process, const std::string& host, uint32_t restarts)
      : barrier_(graph, process, host, restarts),
        clock_sync_(graph, process, host, [](const std::string& m) { StderrLogger("clock").Warn(m); }) {}
  ~GraphSession() override { Close(); }

  Status Open(Transport* transport) override {
    if (Status s = barrier_.Open(transport); !s.ok()) return s;
    return clock_sync_.Open(transport);
  }
  StatusOr<int64_t> AwaitStart(const std::function<bool()>& stopping) override { return barrier_.Wait(stopping); }
  int64_t graph_start_ns() const override { return barrier_.graph_start_ns(); }
  void Started() override {
    clock_sync_.Start(kClockSyncPeriodS);
    barrier_.Announce("running");
  }
  void Heartbeat() override { barrier_.Announce("running"); }
  void Stopping() override { barrier_.Announce("stopping"); }
  void Close() override { clock_sync_.Stop(); }

 private:
  static constexpr double kClockSyncPeriodS = 2;
  StartBarrier barrier_;
  ClockSync clock_sync_;
};

}  // namespace

std::unique_ptr<ProcessSession> MakeGraphSession(const Graph& graph, const std::string& process, const std::string& host,
                                                 uint32_t restarts) {
  if (graph.clock != ClockMode::kWall || graph.ProcessNames().size() < 2) return nullptr;
  return std::make_unique<GraphSession>(graph, process, host, restarts);
}

}  // namespace dyad
